//! One full Millington resolver step on synthetic contact sets of growing size, heap pick
//! against Cyclone's linear-scan pick (benches/RESULTS.md, "Resolver picks").
//!
//! Before the criterion groups run, tables are printed to stderr, one per scene family and
//! pick strategy: contacts, islands, the largest island, picks per step (position +
//! velocity), the deterministic work per pick ([`MillingtonResolver::last_work`]: contacts
//! updated and heap entries moved), and the time per pick of the fastest of up to 9 runs of
//! one step, sizes interleaved (see [`ROUNDS`]), both of the two passes alone
//! (`position_time + velocity_time`: the picks, the per-island heap builds and the refresh
//! between the passes) and of the whole step (with preparation and integration). Each table ends with the ratio of µs per pick at the largest and smallest
//! size against log2 16384 / log2 256 = 1.75, the bound of the acceptance criterion.
//! Criterion then measures the whole step on a fresh clone of the scene each iteration.
//!
//! `cargo bench -p jostle-resolve --bench picks` (the tables alone:
//! `cargo bench -p jostle-resolve --bench picks -- tables-only`, a filter no criterion group
//! matches). Sample sizes are small so the run takes a few minutes; the linear scan of the
//! largest random pile (about 30 s a step) is timed only once, in the table.

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use jostle_resolve::millington::{MillingtonResolver, MillingtonSettings, PickStrategy, PickWork};
use jostle_resolve::synthetic::{self, DT, GRAVITY, SyntheticScene};
use jostle_resolve::{ResolveStats, Resolver, StepContext};
use std::time::{Duration, Instant};

const SIZES: [usize; 4] = [256, 1024, 4096, 16384];
const STACK_HEIGHT: usize = 8;
const FAMILIES: [&str; 2] = ["stacks", "random_pile"];

fn scene(family: &str, n: usize) -> SyntheticScene {
    match family {
        "stacks" => synthetic::stacks(n, STACK_HEIGHT, 1),
        _ => synthetic::random_pile(n, 2),
    }
}

fn scenes() -> Vec<(&'static str, usize, SyntheticScene)> {
    let mut out = Vec::new();
    for &n in &SIZES {
        for family in FAMILIES {
            out.push((family, n, scene(family, n)));
        }
    }
    out
}

fn resolver(pick: PickStrategy) -> MillingtonResolver {
    MillingtonResolver::new(MillingtonSettings {
        pick,
        ..MillingtonSettings::default()
    })
}

/// One measured step: whole-step time, the resolver's stats and work.
struct Run {
    step: Duration,
    passes: Duration,
    stats: ResolveStats,
    work: [PickWork; 2],
    largest_island: usize,
}

fn step(resolver: &mut MillingtonResolver, scene: &SyntheticScene) -> Run {
    let mut bodies = scene.bodies.clone();
    let mut contacts = scene.contacts.clone();
    let ctx = StepContext {
        gravity: GRAVITY,
        dt: DT,
    };
    let start = Instant::now();
    let stats = resolver.step(&mut bodies, &mut contacts, &ctx);
    let step = start.elapsed();
    let islands = resolver.islands();
    Run {
        step,
        passes: stats.position_time + stats.velocity_time,
        stats,
        work: resolver.last_work(),
        largest_island: (0..islands.len())
            .map(|i| islands.island(i).len())
            .max()
            .unwrap_or(0),
    }
}

/// Rounds of the table: every size is stepped once per round, sizes interleaved, so a burst of
/// load from elsewhere on the machine slows one round of every size rather than every run of
/// one size; each cell keeps its fastest run (steps slower than half a second run once).
const ROUNDS: usize = 9;

/// The fastest step and fastest passes of each size over [`ROUNDS`] interleaved rounds.
fn fastest_steps(pick: PickStrategy, scenes: &[(usize, SyntheticScene)]) -> Vec<(usize, Run)> {
    let mut resolvers: Vec<_> = scenes.iter().map(|_| resolver(pick)).collect();
    let mut best: Vec<Option<Run>> = scenes.iter().map(|_| None).collect();
    for round in 0..ROUNDS {
        for ((_, scene), (r, best)) in scenes.iter().zip(resolvers.iter_mut().zip(&mut best)) {
            if round > 0
                && best
                    .as_ref()
                    .is_some_and(|b| b.step > Duration::from_millis(500))
            {
                continue;
            }
            let run = step(r, scene);
            *best = Some(match best.take() {
                None => run,
                Some(b) => Run {
                    step: b.step.min(run.step),
                    passes: b.passes.min(run.passes),
                    ..b
                },
            });
        }
    }
    scenes
        .iter()
        .zip(best)
        .map(|((n, _), run)| (*n, run.expect("at least one round")))
        .collect()
}

fn us_per_pick(d: Duration, picks: u64) -> f64 {
    d.as_secs_f64() * 1e6 / picks.max(1) as f64
}

fn print_table(family: &str, label: &str, rows: &[(usize, Run)]) {
    eprintln!();
    eprintln!("{family}, {label} pick:");
    eprintln!();
    eprintln!(
        "| contacts | islands | largest island | picks (pos+vel) | updates/pick | heap moves/pick | µs/pick (passes) | µs/pick (step) |"
    );
    eprintln!("|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (n, run) in rows {
        let w = run.work;
        let picks = w[0].picks + w[1].picks;
        eprintln!(
            "| {n} | {} | {} | {picks} ({}+{}) | {:.2} | {:.2} | {:.3} | {:.3} |",
            run.stats.islands,
            run.largest_island,
            w[0].picks,
            w[1].picks,
            (w[0].updates + w[1].updates) as f64 / picks.max(1) as f64,
            (w[0].heap_moves + w[1].heap_moves) as f64 / picks.max(1) as f64,
            us_per_pick(run.passes, picks),
            us_per_pick(run.step, picks),
        );
    }
    let per_pick = |run: &Run| us_per_pick(run.passes, run.work[0].picks + run.work[1].picks);
    if let (Some((n0, first)), Some((n1, last))) = (rows.first(), rows.last()) {
        let ratio = per_pick(last) / per_pick(first);
        let bound = (*n1 as f64).log2() / (*n0 as f64).log2();
        eprintln!();
        eprintln!(
            "µs/pick (passes) {n1} / {n0}: {ratio:.2} against log2 ratio {bound:.2}: {} \
             (largest island x{:.0})",
            if ratio <= bound {
                "grows no faster than log n"
            } else {
                "grows FASTER than log n"
            },
            last.largest_island as f64 / first.largest_island.max(1) as f64,
        );
    }
}

fn table(_: &mut Criterion) {
    for family in FAMILIES {
        let scenes: Vec<_> = SIZES.iter().map(|&n| (n, scene(family, n))).collect();
        let heap = fastest_steps(PickStrategy::Heap, &scenes);
        let scan = fastest_steps(PickStrategy::LinearScan, &scenes);
        for ((n, h), (_, s)) in heap.iter().zip(&scan) {
            assert_eq!(
                h.work.map(|w| w.picks),
                s.work.map(|w| w.picks),
                "{family} {n}: strategies must make the same picks"
            );
        }
        print_table(family, "heap", &heap);
        print_table(family, "linear-scan", &scan);
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
