//! Each pipeline stage on its own (issue 7, "criterion benches: each pipeline stage"): broad
//! phase, narrow phase, islands, gather, resolve, CCD, scatter and sleep, each with its own
//! criterion figure, without exposing the stages: every iteration runs a whole
//! `World::step`, and criterion's `iter_custom` is handed the stage's own time from the
//! world's step profile (`StepProfile::stages`), summed over the iterations. Criterion still
//! schedules iterations by wall time, so a stage costs as long to measure as the whole step.
//!
//! Three scenes with different bottlenecks, each with its own settings and settled for 2 s
//! first: `pyramid_20` (soft step, 210 boxes, sleep off), `wall_20x10` (the default Millington
//! resolver, 200 bricks, sleep off) and `rain_1000` (Millington, 1,000 mixed shapes still
//! landing, sleep on). One group per scene (`stages_<scene>`), one benchmark per stage.
//!
//! Run: `cargo bench --bench stages` (about 2 minutes: 24 benchmarks of 10 samples, 0.5 s
//! warm-up, 1.5 s measurement, flat sampling). After criterion, a markdown table is printed to
//! stderr: each stage's criterion median (ms) per scene and its share of the stages' sum.

mod common;

use common::DT;
use criterion::SamplingMode;
use jostle::StepProfile;
use std::time::Duration;

/// The scenes whose stages are measured.
const SCENES: [&str; 3] = ["pyramid_20", "wall_20x10", "rain_1000"];

/// Steps run before measuring.
const SETTLE_STEPS: usize = 120;

fn group(scene: &str) -> String {
    format!("stages_{scene}")
}

fn main() {
    let smoke = common::smoke();
    let settle = if smoke { 2 } else { SETTLE_STEPS };
    let names: Vec<&str> = StepProfile::default()
        .stages()
        .iter()
        .map(|(n, _)| *n)
        .collect();
    let mut c = common::criterion();
    for scene in SCENES {
        let mut world = common::settled(scene, settle);
        let mut g = c.benchmark_group(group(scene));
        g.sampling_mode(SamplingMode::Flat);
        for (i, &stage) in names.iter().enumerate() {
            g.bench_function(stage, |b| {
                b.iter_custom(|iters| {
                    let mut sum = Duration::ZERO;
                    for _ in 0..iters {
                        world.step(DT).expect("step");
                        sum += world.profile().stages()[i].1;
                    }
                    sum
                })
            });
        }
        g.finish();
    }
    c.final_summary();
    if smoke {
        return;
    }
    let medians: Vec<Vec<Option<f64>>> = SCENES
        .iter()
        .map(|s| {
            names
                .iter()
                .map(|n| common::criterion_median_ns(&group(s), n))
                .collect()
        })
        .collect();
    eprintln!();
    let header: Vec<String> = SCENES.iter().map(|s| format!("{s} ms (share)")).collect();
    eprintln!("| stage | {} |", header.join(" | "));
    eprintln!("|---|{}", "---:|".repeat(SCENES.len()));
    for (i, stage) in names.iter().enumerate() {
        let cells: Vec<String> = medians
            .iter()
            .map(|m| {
                let total: f64 = m.iter().flatten().sum();
                match m[i] {
                    Some(ns) if total > 0.0 => {
                        format!("{:.4} ({:.0}%)", ns / 1e6, 100.0 * ns / total)
                    }
                    _ => "n/a".into(),
                }
            })
            .collect();
        eprintln!("| {stage} | {} |", cells.join(" | "));
    }
    let sums: Vec<String> = medians
        .iter()
        .map(|m| format!("{:.3}", m.iter().flatten().sum::<f64>() / 1e6))
        .collect();
    eprintln!("| sum of stages | {} |", sums.join(" | "));
}
