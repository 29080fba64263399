//! One full Millington resolver step on synthetic contact sets of growing size, heap pick
//! against Cyclone's linear-scan pick (DESIGN.md, "Make it scale").
//!
//! Before the criterion groups run, a table is printed to stderr: picks per step (position +
//! velocity) and the median time per pick of each strategy. Criterion measures the whole step
//! (prepare, both passes, integration) on a fresh clone of the scene each iteration.
//!
//! `cargo bench -p jostle-resolve --bench picks`. Sample sizes are small so the run takes a
//! few minutes; the linear scan of the largest random pile is timed only in the table.

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use jostle_resolve::millington::{MillingtonResolver, MillingtonSettings, PickStrategy};
use jostle_resolve::synthetic::{self, DT, GRAVITY, SyntheticScene};
use jostle_resolve::{ResolveStats, Resolver, StepContext};
use std::time::{Duration, Instant};

const SIZES: [usize; 4] = [256, 1024, 4096, 16384];
const STACK_HEIGHT: usize = 8;

fn scenes() -> Vec<(&'static str, usize, SyntheticScene)> {
    let mut out = Vec::new();
    for &n in &SIZES {
        out.push(("stacks", n, synthetic::stacks(n, STACK_HEIGHT, 1)));
        out.push(("random_pile", n, synthetic::random_pile(n, 2)));
    }
    out
}

fn resolver(pick: PickStrategy) -> MillingtonResolver {
    MillingtonResolver::new(MillingtonSettings {
        pick,
        ..MillingtonSettings::default()
    })
}

fn step(resolver: &mut MillingtonResolver, scene: &SyntheticScene) -> (Duration, ResolveStats) {
    let mut bodies = scene.bodies.clone();
    let mut contacts = scene.contacts.clone();
    let ctx = StepContext {
        gravity: GRAVITY,
        dt: DT,
    };
    let start = Instant::now();
    let stats = resolver.step(&mut bodies, &mut contacts, &ctx);
    (start.elapsed(), stats)
}

/// Median step time over a few runs (fewer for slow configurations).
fn median_step(pick: PickStrategy, scene: &SyntheticScene) -> (Duration, ResolveStats) {
    let mut r = resolver(pick);
    let (first, stats) = step(&mut r, scene);
    let runs = if first > Duration::from_millis(500) {
        1
    } else {
        9
    };
    let mut times = vec![first];
    for _ in 1..runs {
        times.push(step(&mut r, scene).0);
    }
    times.sort();
    (times[times.len() / 2], stats)
}

fn table(_: &mut Criterion) {
    eprintln!();
    eprintln!(
        "| scene | contacts | islands | picks/step (pos+vel) | heap µs/step | heap µs/pick | scan µs/step | scan µs/pick | scan/heap |"
    );
    eprintln!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (name, n, scene) in scenes() {
        let (heap_t, stats) = median_step(PickStrategy::Heap, &scene);
        let (scan_t, scan_stats) = median_step(PickStrategy::LinearScan, &scene);
        let picks = stats.position_iterations + stats.velocity_iterations;
        assert_eq!(
            (stats.position_iterations, stats.velocity_iterations),
            (
                scan_stats.position_iterations,
                scan_stats.velocity_iterations
            ),
            "strategies must make the same picks"
        );
        let us = |d: Duration| d.as_secs_f64() * 1e6;
        let per_pick = |d: Duration| us(d) / f64::from(picks.max(1));
        eprintln!(
            "| {name} | {n} | {} | {picks} ({}+{}) | {:.0} | {:.3} | {:.0} | {:.3} | {:.1} |",
            stats.islands,
            stats.position_iterations,
            stats.velocity_iterations,
            us(heap_t),
            per_pick(heap_t),
            us(scan_t),
            per_pick(scan_t),
            us(scan_t) / us(heap_t),
        );
    }
    eprintln!();
}

fn bench_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("millington_step");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for (name, n, scene) in scenes() {
        for (label, pick) in [
            ("heap", PickStrategy::Heap),
            ("linear_scan", PickStrategy::LinearScan),
        ] {
            // One linear-scan step of the largest pile takes seconds; the table above has it.
            if pick == PickStrategy::LinearScan && name == "random_pile" && n > 4096 {
                continue;
            }
            let mut r = resolver(pick);
            let ctx = StepContext {
                gravity: GRAVITY,
                dt: DT,
            };
            group.bench_with_input(
                BenchmarkId::new(format!("{name}/{label}"), n),
                &scene,
                |b, scene| {
                    b.iter_batched(
                        || (scene.bodies.clone(), scene.contacts.clone()),
                        |(mut bodies, mut contacts)| r.step(&mut bodies, &mut contacts, &ctx),
                        BatchSize::LargeInput,
                    );
                },
            );
        }
    }
    group.finish();
}

criterion_group!(benches, table, bench_step);
criterion_main!(benches);
