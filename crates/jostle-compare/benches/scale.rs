//! Scenes of thousands of bodies side by side with rapier3d 0.36 (issue 18, items 1 and 5):
//! piles, rains of mixed shapes and pyramids at about 1,000, 4,000, 10,000 and 20,000 bodies,
//! built from the same jostle scene in both engines (`rapier_scene`), each engine at its
//! defaults, in the same run.
//!
//! - `piles_N`: 5-box piles of unit boxes on a 3 m grid (`Piles`), sleeping off;
//! - `rain_N`: boxes, balls, capsules and cylinders (a quarter each, 0.3–0.7 m long) in ten
//!   layers 0.8 m apart, jittered and tilted from a fixed seed, raining into a walled square,
//!   sleeping off;
//! - `pyramid_40` (820 boxes), `pyramid3d_20` (2,870), `pyramid3d_30` (9,455), sleeping off;
//!   and the two smaller pyramids whose time issue 15 compares with rapier3d's, `pyramid_20`
//!   (210 boxes) and `pyramid3d_10` (385), so that their stages stand beside rapier3d's too;
//! - `lattice_4000` (`assets/lattice_4000.ron`), sleeping on as the scene declares it.
//!
//! Each scene first runs its steps in both engines (the rains 300, the rest 120) with every
//! step timed: the mean per stage (jostle's `StepProfile`, rapier3d's profiler counters), the
//! contact pairs and points at the end, the time per pair of the narrow phase and per point of
//! the solver, and the deepest overlap seen; then criterion times one more step per iteration
//! of each engine's world as that run left it (`scale/<scene>/jostle`, `.../rapier3d`). The
//! tables are printed after criterion, with the ratio of the criterion medians.
//!
//! Run: `cargo bench -p jostle-compare --bench scale` (about 6 minutes on two cores);
//! `SCALE_SCENES=piles_1000,rain_4000` runs only the named scenes. rapier3d's fastest
//! configuration on this machine (issue 18) is its `simd8` feature built for the native CPU;
//! the same run with both engines built that way:
//! `RUSTFLAGS="-C target-cpu=native" CARGO_TARGET_DIR=target/native cargo bench -p
//! jostle-compare --bench scale --features rapier-simd8` (a separate target directory keeps
//! the default build's artefacts). rapier3d is built with its `profiler` feature for the stage
//! figures (two clock reads per stage and step). With `--test` (`cargo test -p jostle-compare
//! --benches`) only a few steps of the smallest pile run.

#[path = "../../../benches/common/mod.rs"]
mod common;
#[path = "rapier_scene.rs"]
mod rapier_scene;

use criterion::{Criterion, SamplingMode};
use jostle::World;
use jostle::scene::Scene;
use rapier3d::prelude as rp;
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// rapier3d's configuration in this build, for the tables.
const RAPIER: &str = if cfg!(feature = "rapier-simd8") {
    "rapier3d 0.36 simd8"
} else {
    "rapier3d 0.36"
};

/// One scene of the set.
struct Case {
    key: String,
    scene: Scene,
    steps: u32,
}

/// `nx` × `nz` piles of five unit boxes, 3 m apart.
fn piles(nx: u32, nz: u32) -> Case {
    let text = format!(
        "Scene(name: \"piles\", sleep: (enabled: false),
           bodies: [Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true,
                         friction: 0.6)],
           generators: [Piles(nx: {nx}, nz: {nz}, height: 5, spacing: 3.0)])"
    );
    case(format!("piles_{}", nx * nz * 5), &text, 120)
}

/// A pseudo-random number in [0, 1) from `state` (a 64-bit LCG, fixed seed: the same scene in
/// every run).
fn next(state: &mut u64) -> f32 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*state >> 40) as f32 / (1u64 << 24) as f32
}

/// About `n` mixed shapes in ten layers over a square, raining into four walls.
fn rain(n: u32) -> Case {
    let per_layer = n / 10;
    let side = (per_layer as f32).sqrt().round() as u32;
    let spacing = 0.8;
    let half_area = side as f32 * spacing / 2.0;
    let mut bodies = String::new();
    let wall = |name: &str, half: (f32, f32, f32), at: (f32, f32, f32)| {
        format!(
            "Body(name: \"{name}\", shape: Cuboid(half_extents: ({}, {}, {})), \
             position: ({}, {}, {}), fixed: true, friction: 0.6),\n",
            half.0, half.1, half.2, at.0, at.1, at.2
        )
    };
    let (h, t) = (4.0, 0.2);
    let reach = half_area + t;
    bodies += &wall("wall-x-", (t, h, reach + t), (-reach, h, 0.0));
    bodies += &wall("wall-x+", (t, h, reach + t), (reach, h, 0.0));
    bodies += &wall("wall-z-", (reach, h, t), (0.0, h, -reach));
    bodies += &wall("wall-z+", (reach, h, t), (0.0, h, reach));
    let mut state = 0x5eed_u64;
    let mut count = 0;
    for layer in 0..10 {
        for i in 0..side {
            for k in 0..side {
                let jitter = |s: &mut u64| (next(s) - 0.5) * 0.1;
                let x = -half_area + (i as f32 + 0.5) * spacing + jitter(&mut state);
                let z = -half_area + (k as f32 + 0.5) * spacing + jitter(&mut state);
                let y = 0.6 + layer as f32 * spacing;
                // A tilt of up to about 0.2 rad about a horizontal axis.
                let (ax, az) = (next(&mut state) - 0.5, next(&mut state) - 0.5);
                let norm = (1.0 + (ax * ax + az * az) * 0.04).sqrt();
                let (qx, qz, qw) = (ax * 0.2 / norm, az * 0.2 / norm, 1.0 / norm);
                let shape = match count % 4 {
                    0 => "Cuboid(half_extents: (0.25, 0.2, 0.15))".to_string(),
                    1 => "Ball(radius: 0.25)".to_string(),
                    2 => "Capsule(half_height: 0.2, radius: 0.15)".to_string(),
                    _ => "Cylinder(half_height: 0.15, radius: 0.25)".to_string(),
                };
                let _ = writeln!(
                    bodies,
                    "Body(name: \"rain-{count}\", shape: {shape}, position: ({x}, {y}, {z}), \
                     rotation: ({qx}, 0.0, {qz}, {qw}), friction: 0.6),"
                );
                count += 1;
            }
        }
    }
    let text = format!(
        "Scene(name: \"rain {count}\", sleep: (enabled: false),
           bodies: [Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true,
                         friction: 0.6),
                    {bodies}])"
    );
    case(format!("rain_{count}"), &text, 300)
}

/// A planar pyramid of `rows` rows of unit boxes.
fn pyramid(rows: u32) -> Case {
    let text = format!(
        "Scene(name: \"pyramid {rows}\", sleep: (enabled: false),
           bodies: [Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true,
                         friction: 0.6)],
           generators: [Pyramid(rows: {rows}, half_extent: 0.5, friction: 0.6)])"
    );
    case(format!("pyramid_{rows}"), &text, 120)
}

/// A 3D pyramid of `layers` square layers of unit boxes.
fn pyramid3d(layers: u32) -> Case {
    let text = format!(
        "Scene(name: \"3D pyramid {layers}\", sleep: (enabled: false),
           bodies: [Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true,
                         friction: 0.6)],
           generators: [Pyramid3D(layers: {layers}, half_extent: 0.5, friction: 0.6)])"
    );
    case(format!("pyramid3d_{layers}"), &text, 120)
}

fn case(key: String, text: &str, steps: u32) -> Case {
    let scene = Scene::parse(text, &key).unwrap_or_else(|e| panic!("{key}: {e}"));
    Case { key, scene, steps }
}

/// The scenes in table order.
fn cases(smoke: bool) -> Vec<Case> {
    if smoke {
        return vec![piles(20, 10)];
    }
    let mut out = Vec::new();
    for (nx, nz) in [(20, 10), (40, 20), (50, 40), (80, 50)] {
        out.push(piles(nx, nz));
    }
    for n in [1000, 4000, 10_000, 20_000] {
        out.push(rain(n));
    }
    out.push(pyramid(20));
    out.push(pyramid3d(10));
    out.push(pyramid(40));
    out.push(pyramid3d(20));
    out.push(pyramid3d(30));
    let lattice = common::scene("lattice_4000");
    out.push(Case {
        key: "lattice_4000".into(),
        steps: lattice.steps,
        scene: lattice,
    });
    let only = std::env::var("SCALE_SCENES").unwrap_or_default();
    if !only.is_empty() {
        out.retain(|c| only.split(',').any(|k| k.trim() == c.key));
    }
    out
}

/// What one engine's timed run measured: mean ms per step of the whole step and of each
/// stage, the contact pairs and points at the end, the deepest overlap seen.
struct Run {
    step_ms: f64,
    stages: Vec<(&'static str, f64)>,
    pairs: usize,
    points: usize,
    deepest: f32,
    /// Mean ms per step of the narrow phase and of the solver (for the per pair and per point
    /// figures).
    narrow_ms: f64,
    solve_ms: f64,
}

fn mean_ms(total: Duration, steps: u32) -> f64 {
    total.as_secs_f64() * 1e3 / f64::from(steps.max(1))
}

fn jostle_run(case: &Case, steps: u32) -> (World, Run) {
    let mut world = case
        .scene
        .build()
        .unwrap_or_else(|e| panic!("{}: {e}", case.key));
    let names = world.profile().stages().map(|(name, _)| name);
    let mut stages = [Duration::ZERO; jostle::StepProfile::STAGES];
    let (mut total, mut deepest) = (Duration::ZERO, 0.0f32);
    for _ in 0..steps {
        let t = Instant::now();
        world
            .step(case.scene.dt)
            .unwrap_or_else(|e| panic!("{}: {e}", case.key));
        total += t.elapsed();
        let p = world.profile();
        for (sum, (_, d)) in stages.iter_mut().zip(p.stages()) {
            *sum += d;
        }
        deepest = deepest.max(world.max_penetration());
    }
    let p = world.profile();
    let table: Vec<_> = names
        .iter()
        .zip(&stages)
        .map(|(&name, &d)| (name, mean_ms(d, steps)))
        .collect();
    let find = |key: &str| {
        table
            .iter()
            .find(|(n, _)| n.contains(key))
            .map_or(0.0, |(_, ms)| *ms)
    };
    let run = Run {
        step_ms: mean_ms(total, steps),
        narrow_ms: find("narrow"),
        solve_ms: find("resolve"),
        stages: table,
        pairs: p.manifolds,
        points: p.contact_points,
        deepest,
    };
    (world, run)
}

fn rapier_run(case: &Case, steps: u32) -> (rp::PhysicsWorld, Run) {
    let (mut world, _) = rapier_scene::rapier_world(&case.scene);
    let mut sums = [Duration::ZERO; 6];
    let (mut total, mut deepest) = (Duration::ZERO, 0.0f32);
    for _ in 0..steps {
        let t = Instant::now();
        world.step();
        total += t.elapsed();
        let c = &world.physics_pipeline.counters;
        let times = [
            c.cd.broad_phase_time.time(),
            c.cd.narrow_phase_time.time(),
            c.stages.island_construction_time.time(),
            c.stages.solver_time.time(),
            c.stages.ccd_time.time(),
            c.stages.update_time.time(),
        ];
        for (sum, d) in sums.iter_mut().zip(times) {
            *sum += d;
        }
        deepest = deepest.max(rapier_scene::rapier_deepest(&world));
    }
    let names = ["broad", "narrow", "islands", "solver", "ccd", "update"];
    let stages: Vec<_> = names
        .iter()
        .zip(&sums)
        .map(|(&name, &d)| (name, mean_ms(d, steps)))
        .collect();
    let (pairs, points) = rapier_scene::rapier_contacts(&world);
    let run = Run {
        step_ms: mean_ms(total, steps),
        narrow_ms: stages[1].1,
        solve_ms: stages[3].1,
        stages,
        pairs,
        points,
        deepest,
    };
    (world, run)
}

/// One engine's row of a scene's table.
fn row(engine: &str, criterion_ms: String, run: &Run) -> String {
    let stages: Vec<String> = run
        .stages
        .iter()
        .map(|(name, ms)| format!("{name} {ms:.3}"))
        .collect();
    let per = |ms: f64, n: usize| {
        if n == 0 {
            "—".to_string()
        } else {
            format!("{:.0}", ms * 1e6 / n as f64)
        }
    };
    format!(
        "| {engine} | {criterion_ms} | {:.3} | {} | {} / {} | {} | {} | {:.3} |",
        run.step_ms,
        stages.join(", "),
        run.pairs,
        run.points,
        per(run.narrow_ms, run.pairs),
        per(run.solve_ms, run.points),
        run.deepest,
    )
}

fn main() {
    let smoke = common::smoke();
    let mut c: Criterion = common::criterion();
    let mut tables = Vec::new();
    for case in cases(smoke) {
        let steps = if smoke { 5 } else { case.steps };
        eprintln!("{}: {steps} steps in each engine", case.key);
        let (mut jw, j) = jostle_run(&case, steps);
        let (mut rw, r) = rapier_run(&case, steps);
        let group_name = format!("scale/{}", case.key);
        if !smoke {
            let mut group = c.benchmark_group(&group_name);
            group.sampling_mode(SamplingMode::Flat);
            let dt = case.scene.dt;
            group.bench_function("jostle", |b| {
                b.iter(|| black_box(jw.step(dt).expect("step")));
            });
            group.bench_function("rapier3d", |b| b.iter(|| rw.step()));
            group.finish();
        }
        tables.push((case.key, steps, group_name, j, r));
    }
    println!();
    println!(
        "Per scene: criterion's median ms per step after the timed run, then the timed run's \
         mean ms per step and per stage, contact pairs / points at its end, ns per pair of \
         the narrow phase and per point of the solver, deepest overlap (m). jostle threads: \
         {}.",
        std::env::var("JOSTLE_THREADS").unwrap_or_else(|_| "default".into())
    );
    println!();
    println!(
        "| scene | engine | criterion ms/step | run ms/step | stages (ms/step) | pairs / points | ns per pair (narrow) | ns per point (solver) | deepest (m) |"
    );
    println!("|---|---|---:|---:|---|---:|---:|---:|---:|");
    let mut ratios = Vec::new();
    for (key, steps, group, j, r) in &tables {
        let jm = common::criterion_median_ns(group, "jostle");
        let rm = common::criterion_median_ns(group, "rapier3d");
        println!(
            "| {key} ({steps} steps) {}",
            row("jostle", common::ms_cell(jm), j)
        );
        println!("| {key} {}", row(RAPIER, common::ms_cell(rm), r));
        ratios.push((key, jm.zip(rm).map(|(a, b)| a / b), j.step_ms / r.step_ms));
    }
    println!();
    println!("| scene | jostle / {RAPIER}, criterion | jostle / {RAPIER}, timed run |");
    println!("|---|---:|---:|");
    for (key, criterion, run) in ratios {
        let c = criterion.map_or("n/a".into(), |x| format!("{x:.2}"));
        println!("| {key} | {c} | {run:.2} |");
    }
}
