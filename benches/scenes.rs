//! The full step per scene (issue 7, "criterion benches: the full step per scene"): one
//! criterion group, `scenes`, with one benchmark per scene of the benchmark set in `assets/`.
//! Each scene runs with its own settings (its resolver, or the engine's default; sleeping as
//! the scene says), is settled for 2 s (120 steps of 1/60 s) first, and is then stepped once per
//! iteration, so the figure is the cost of one step of the settled (or, for the rain, still
//! falling) scene.
//!
//! Run: `cargo bench --bench scenes` (about 1.5 minutes: 10 samples, 0.5 s warm-up, 1.5 s
//! measurement per scene, flat sampling; settling the nine scenes takes most of the rest).
//! One scene: `cargo bench --bench scenes -- wall_20x10`. After criterion, a markdown table is
//! printed to stderr: scene, resolver, dynamic bodies, bodies awake and contact points after
//! settling, and criterion's median ms/step.

mod common;

use common::{DT, SCENES};
use criterion::SamplingMode;
use std::hint::black_box;

/// Steps run before measuring.
const SETTLE_STEPS: usize = 120;

const GROUP: &str = "scenes";

fn main() {
    let smoke = common::smoke();
    let settle = if smoke { 2 } else { SETTLE_STEPS };
    let mut c = common::criterion();
    let mut rows = Vec::new();
    {
        let mut group = c.benchmark_group(GROUP);
        group.sampling_mode(SamplingMode::Flat);
        for name in SCENES {
            let mut world = common::settled(name, settle);
            let p = world.profile();
            rows.push((
                name,
                world.resolver_name(),
                common::dynamic_bodies(&world),
                p.awake_bodies,
                p.contact_points,
            ));
            group.bench_function(name, |b| {
                b.iter(|| {
                    black_box(world.step(DT).expect("step"));
                })
            });
        }
        group.finish();
    }
    c.final_summary();
    if smoke {
        return;
    }
    eprintln!();
    eprintln!(
        "| scene | resolver | dynamic bodies | awake after 2 s | contact points | ms/step (criterion median) |"
    );
    eprintln!("|---|---|---:|---:|---:|---:|");
    for (name, resolver, bodies, awake, contacts) in rows {
        eprintln!(
            "| {name} | {resolver} | {bodies} | {awake} | {contacts} | {} |",
            common::ms_cell(common::criterion_median_ns(GROUP, name))
        );
    }
}
