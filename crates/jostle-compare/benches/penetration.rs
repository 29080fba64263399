//! Fast piles side by side with rapier3d 0.36 at its defaults (issue 18 item 4): the box
//! lattices `assets/lattice_4000.ron` and `assets/lattice_4000_offset.ron` dropped in both
//! engines (jostle's ground half-space is a fixed 4,000 m cuboid in rapier3d with its top face at
//! y = 0; μ 0.6 on both sides; sleeping on in both, as the scenes declare), one run each of the
//! scene's 300 steps; the table gives the deepest overlap of any contact over the run and the
//! mean wall time per step (the penetration measuring included in neither), then per 30 steps
//! each engine's mean time per step and how many bodies are awake.
//!
//! Run: `cargo bench -p jostle-compare --bench penetration` (about a minute). With `--test`
//! (`cargo test -p jostle-compare --benches`) only 20 steps of the first scene run.

#[path = "../../../benches/common/mod.rs"]
mod common;
#[path = "rapier_scene.rs"]
mod rapier_scene;

use jostle::scene::Scene;
use std::time::{Duration, Instant};

/// Steps per row of the time series ([`Run::series`]).
const WINDOW: usize = 30;

/// What one engine's run of a scene measured.
struct Run {
    /// Deepest overlap of any contact over the run (m).
    deepest: f32,
    /// Mean wall time per step (ms).
    ms_per_step: f64,
    /// Per window of [`WINDOW`] steps: mean ms per step, and the bodies awake at its end.
    series: Vec<(f64, usize)>,
}

/// Adds one step's time and awake count to `series` (a row per [`WINDOW`] steps).
fn record(series: &mut Vec<(f64, usize)>, window: &mut Duration, step: usize, awake: usize) {
    if (step + 1).is_multiple_of(WINDOW) {
        series.push((window.as_secs_f64() * 1e3 / WINDOW as f64, awake));
        *window = Duration::ZERO;
    }
}

/// `steps` steps of `world` by `step`, each timed; after each, `look` gives the deepest
/// overlap of any contact now and the bodies awake (neither timed).
fn timed<W>(
    world: &mut W,
    steps: u32,
    step: impl Fn(&mut W),
    look: impl Fn(&W) -> (f32, usize),
) -> Run {
    let (mut deepest, mut time, mut window) = (0.0f32, Duration::ZERO, Duration::ZERO);
    let mut series = Vec::new();
    for k in 0..steps as usize {
        let t = Instant::now();
        step(world);
        let spent = t.elapsed();
        time += spent;
        window += spent;
        let (depth, awake) = look(world);
        deepest = deepest.max(depth);
        record(&mut series, &mut window, k, awake);
    }
    Run {
        deepest,
        ms_per_step: time.as_secs_f64() * 1e3 / f64::from(steps),
        series,
    }
}

/// `steps` steps of jostle at the scene's settings.
fn jostle_run(scene: &Scene, steps: u32) -> Run {
    let mut world = scene.build().expect("scene builds");
    timed(
        &mut world,
        steps,
        |w| {
            w.step(scene.dt).expect("step");
        },
        |w| {
            let awake = w
                .bodies()
                .filter(|(_, _, b)| !b.is_fixed() && b.is_awake())
                .count();
            (w.max_penetration(), awake)
        },
    )
}

/// The same for rapier3d.
fn rapier_run(scene: &Scene, steps: u32) -> Run {
    let (mut world, _) = rapier_scene::rapier_world(scene);
    timed(
        &mut world,
        steps,
        |w| w.step(),
        |w| {
            (
                rapier_scene::rapier_deepest(w),
                rapier_scene::rapier_awake(w),
            )
        },
    )
}

fn main() {
    let smoke = common::smoke();
    let scenes: &[&str] = if smoke {
        &["lattice_4000"]
    } else {
        &["lattice_4000", "lattice_4000_offset"]
    };
    let mut runs = Vec::new();
    println!("| scene | engine | deepest overlap (m) | ms/step |");
    println!("|---|---|---:|---:|");
    for name in scenes {
        let scene = common::scene(name);
        let steps = if smoke { 20 } else { scene.steps };
        let j = jostle_run(&scene, steps);
        println!(
            "| {name} | jostle | {:.3} | {:.2} |",
            j.deepest, j.ms_per_step
        );
        let r = rapier_run(&scene, steps);
        println!(
            "| {name} | rapier3d 0.36 | {:.3} | {:.2} |",
            r.deepest, r.ms_per_step
        );
        runs.push((name, j, r));
    }
    // Where the time goes over the run: the falling, the landing, the resting and the sleeping.
    for (name, j, r) in &runs {
        println!();
        println!("{name}, per {WINDOW} steps: ms per step (bodies awake at the window's end)");
        println!();
        println!("| steps | jostle | rapier3d 0.36 |");
        println!("|---|---:|---:|");
        for (k, ((jt, ja), (rt, ra))) in j.series.iter().zip(&r.series).enumerate() {
            println!(
                "| {}–{} | {jt:.2} ({ja}) | {rt:.2} ({ra}) |",
                k * WINDOW + 1,
                (k + 1) * WINDOW
            );
        }
    }
}
