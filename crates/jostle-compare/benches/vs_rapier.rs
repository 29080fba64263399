//! The side-by-side with rapier3d 0.36 (issue 6's last acceptance item, issue 7;
//! benches/RESULTS.md): stacking scenes of boxes on the ground (μ 0.6, density 1000 kg/m³, sleeping
//! disabled) built in rapier3d with its defaults (dt 1/60, 4 solver iterations, 1 substep) and
//! in jostle, measured in the same run:
//!
//! - the 20-row pyramid of `assets/pyramid_20.ron` (210 boxes of 1 m), with each jostle
//!   resolver; its rapier3d layout is written out here (`pyramid_boxes`), as it always was;
//! - the 3D pyramid `assets/pyramid3d_10.ron` (385 boxes of 1 m), the wall
//!   `assets/wall_20x10.ron` (running bond of 1 × 0.5 × 0.5 m bricks and half bricks) and the 15-box stack
//!   `assets/stack_15.ron`: rapier3d builds the very boxes jostle's scene generates (same
//!   centres, half extents, density and friction, read from the scene's body descriptions);
//!   jostle runs the soft step, and the Millington resolver too on the stack (on the two large
//!   scenes it costs about 80× the soft step per step and would dominate the run time).
//!
//! Two measurements per engine:
//! - **accuracy and a first time**, before criterion starts: a fresh world runs 10 s; drift is
//!   the largest displacement of any box between 2 s and 10 s (the stability test's
//!   criterion), and every step after 2 s is timed, giving a median over 480 steps;
//! - **criterion**: the world settled for 120 steps (2 s), then one step per iteration.
//!
//! After criterion, one markdown table per scene is printed to stderr: engine, criterion's
//! median ms/step, the drift run's median ms/step, drift (m) and the ratios jostle / rapier3d.
//! Run: `cargo bench -p jostle-compare --bench vs_rapier` (about 2.5 minutes, most of it the Millington
//! resolver's 10 s of the 20-row pyramid); `VS_RAPIER_SCENES=wall_20x10,stack_15 cargo bench -p
//! jostle-compare --bench vs_rapier` runs only the named scenes (keys: `pyramid20`, `pyramid3d_10`, `wall_20x10`,
//! `stack_15`). The ground is a fixed 200 × 1 × 200 m cuboid in rapier3d
//! (its top face at y = 0) and a half-space in jostle; friction combines as the mean in
//! rapier3d and both sides use 0.6, so the pair's coefficient is 0.6 in both engines.
//!
//! With `--test` (`cargo test -p jostle-compare --benches`), only a short smoke run is made.

#[path = "../../../benches/common/mod.rs"]
mod common;

use criterion::Criterion;
use jostle::scene::Scene;
use jostle::{ResolverChoice, World};
use rapier3d::prelude as rp;
use std::hint::black_box;
use std::time::{Duration, Instant};

const DT: f32 = 1.0 / 60.0;
const ROWS: u32 = 20;
const HALF: f32 = 0.5;
const FRICTION: f32 = 0.6;
const DENSITY: f32 = 1000.0;
const SETTLE_STEPS: usize = 120;
const END_STEPS: usize = 600;

/// One dynamic box: half extents and centre (m), axis-aligned.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BoxSpec {
    half: [f32; 3],
    centre: [f32; 3],
}

/// The 20-row pyramid's layout, as this bench has always built it in rapier3d: the same
/// layout as jostle's `Pyramid` generator: row `r` holds `ROWS − r` boxes centred on x = 0,
/// resting exactly on the row below.
fn pyramid_boxes() -> Vec<BoxSpec> {
    let mut boxes = Vec::new();
    for row in 0..ROWS {
        let n = ROWS - row;
        for i in 0..n {
            let x = (i as f32 - (n - 1) as f32 / 2.0) * 2.0 * HALF;
            let y = HALF + 2.0 * HALF * row as f32;
            boxes.push(BoxSpec {
                half: [HALF; 3],
                centre: [x, y, 0.0],
            });
        }
    }
    boxes
}

/// The boxes of a jostle scene: every dynamic body must be an axis-aligned cuboid of density
/// `DENSITY` and friction `FRICTION`, every fixed body the ground half-space y ≥ 0 with friction
/// `FRICTION` (so both engines see the same materials); anything else is a bench bug.
fn scene_boxes(scene: &Scene) -> Vec<BoxSpec> {
    let mut boxes = Vec::new();
    for desc in scene.body_descs().expect("scene bodies") {
        assert_eq!(desc.material.friction, FRICTION, "{}: friction", desc.name);
        if desc.fixed {
            assert_eq!(
                desc.shape,
                jostle::ShapeDesc::HalfSpace {
                    normal: jostle::Vec3::Y
                },
                "{}: the only fixed body must be the ground",
                desc.name
            );
            assert_eq!(
                desc.position,
                jostle::Vec3::ZERO,
                "{}: ground at y = 0",
                desc.name
            );
            continue;
        }
        let jostle::ShapeDesc::Cuboid { half_extents } = desc.shape else {
            panic!("{}: only cuboids are built in rapier3d", desc.name);
        };
        assert_eq!(
            desc.rotation,
            jostle::Quat::IDENTITY,
            "{}: rotation",
            desc.name
        );
        assert_eq!(
            desc.mass,
            jostle::MassSpec::Density(DENSITY),
            "{}: density",
            desc.name
        );
        boxes.push(BoxSpec {
            half: half_extents.to_array(),
            centre: desc.position.to_array(),
        });
    }
    boxes
}

/// One engine under test: a way to step and to read every dynamic body's position.
trait Engine {
    fn step(&mut self);
    fn positions(&self) -> Vec<[f32; 3]>;
}

/// A scene in rapier3d, with its defaults but sleeping disabled.
struct Rapier {
    world: rp::PhysicsWorld,
    boxes: Vec<rp::RigidBodyHandle>,
}

impl Rapier {
    /// The boxes on a fixed ground whose top face is y = 0, all with `FRICTION` and `DENSITY`.
    fn new(specs: &[BoxSpec]) -> Self {
        let mut world = rp::PhysicsWorld {
            gravity: rp::Vector::new(0.0, -9.81, 0.0),
            ..Default::default()
        };
        // rapier3d's default already; stated so the comparison's dt is visible here.
        world.integration_parameters.dt = DT;
        world.insert(
            rp::RigidBodyBuilder::fixed().translation(rp::Vector::new(0.0, -0.5, 0.0)),
            rp::ColliderBuilder::cuboid(100.0, 0.5, 100.0).friction(FRICTION),
        );
        let mut boxes = Vec::new();
        for spec in specs {
            let ([x, y, z], [hx, hy, hz]) = (spec.centre, spec.half);
            let (h, _) = world.insert(
                rp::RigidBodyBuilder::dynamic()
                    .translation(rp::Vector::new(x, y, z))
                    .can_sleep(false),
                rp::ColliderBuilder::cuboid(hx, hy, hz)
                    .density(DENSITY)
                    .friction(FRICTION),
            );
            boxes.push(h);
        }
        Self { world, boxes }
    }
}

impl Engine for Rapier {
    fn step(&mut self) {
        self.world.step();
    }
    fn positions(&self) -> Vec<[f32; 3]> {
        self.boxes
            .iter()
            .map(|&h| {
                let t = self.world.bodies[h].translation();
                [t.x, t.y, t.z]
            })
            .collect()
    }
}

/// A scene in jostle, from its file, with the given resolver and sleeping disabled.
struct Jostle(World);

impl Jostle {
    /// `assets/<asset>.ron` with `resolver`; it must have `boxes` dynamic bodies.
    fn new(asset: &str, resolver: ResolverChoice, boxes: usize) -> Self {
        let scene = load(asset);
        let mut settings = scene.settings();
        settings.resolver = resolver;
        settings.sleep.enabled = false;
        let world = scene.build_with(settings).expect("scene builds");
        assert_eq!(
            world.bodies().filter(|(_, _, b)| !b.is_fixed()).count(),
            boxes
        );
        Self(world)
    }
}

fn load(asset: &str) -> Scene {
    common::scene(asset)
}

impl Engine for Jostle {
    fn step(&mut self) {
        self.0.step(DT).expect("step");
    }
    fn positions(&self) -> Vec<[f32; 3]> {
        self.0
            .bodies()
            .filter(|(_, _, b)| !b.is_fixed())
            .map(|(_, _, b)| b.position.to_array())
            .collect()
    }
}

/// One scene of the side-by-side.
struct SceneCase {
    /// Key for `VS_RAPIER_SCENES` and the criterion group `vs_rapier_<key>`.
    key: &'static str,
    /// `assets/<asset>.ron`.
    asset: &'static str,
    /// The boxes rapier3d builds.
    boxes: fn() -> Vec<BoxSpec>,
    /// The jostle resolvers run, in table order.
    resolvers: &'static [&'static str],
}

/// The scenes, in table order. The pyramid keeps its historical criterion group name.
const CASES: [SceneCase; 4] = [
    SceneCase {
        key: "pyramid20",
        asset: "pyramid_20",
        boxes: pyramid_boxes,
        resolvers: &["soft-step", "millington"],
    },
    SceneCase {
        key: "pyramid3d_10",
        asset: "pyramid3d_10",
        boxes: || scene_boxes(&load("pyramid3d_10")),
        resolvers: &["soft-step"],
    },
    SceneCase {
        key: "wall_20x10",
        asset: "wall_20x10",
        boxes: || scene_boxes(&load("wall_20x10")),
        resolvers: &["soft-step"],
    },
    SceneCase {
        key: "stack_15",
        asset: "stack_15",
        boxes: || scene_boxes(&load("stack_15")),
        resolvers: &["soft-step", "millington"],
    },
];

/// Builds one engine's world.
type Make = Box<dyn Fn() -> Box<dyn Engine>>;

/// The engines of a scene, in table order: (name, constructor).
fn engines(case: &SceneCase) -> Vec<(String, Make)> {
    let boxes = (case.boxes)();
    let n = boxes.len();
    let mut out: Vec<(String, Make)> = vec![(
        "rapier3d".into(),
        Box::new(move || Box::new(Rapier::new(&boxes)) as Box<dyn Engine>),
    )];
    for &resolver in case.resolvers {
        let asset = case.asset;
        out.push((
            format!("jostle {resolver}"),
            Box::new(move || {
                Box::new(Jostle::new(
                    asset,
                    ResolverChoice::from_name(resolver).expect("name"),
                    n,
                )) as Box<dyn Engine>
            }),
        ));
    }
    out
}

/// What the drift run measured for one engine.
struct Accuracy {
    /// Largest displacement of any box between `SETTLE_STEPS` and `end` steps (m).
    drift: f32,
    /// Median wall time of the steps after `SETTLE_STEPS`.
    median_step: Duration,
}

fn drift_run(engine: &mut dyn Engine, end: usize) -> Accuracy {
    for _ in 0..SETTLE_STEPS {
        engine.step();
    }
    let settled = engine.positions();
    let mut times = Vec::with_capacity(end - SETTLE_STEPS);
    for _ in SETTLE_STEPS..end {
        let t = Instant::now();
        engine.step();
        times.push(t.elapsed());
    }
    let drift = engine
        .positions()
        .iter()
        .zip(&settled)
        .map(|(p, q)| {
            let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        })
        .fold(0.0, f32::max);
    times.sort_unstable();
    Accuracy {
        drift,
        median_step: times[times.len() / 2],
    }
}

/// Criterion's report id for an engine name ("jostle soft-step" → "jostle_soft-step").
fn criterion_id(name: &str) -> String {
    name.replace(' ', "_")
}

fn main() {
    let smoke = std::env::args().any(|a| a == "--test");
    let end = if smoke { SETTLE_STEPS + 2 } else { END_STEPS };
    let only = std::env::var("VS_RAPIER_SCENES").ok();
    let cases: Vec<&SceneCase> = CASES
        .iter()
        .filter(|c| {
            only.as_deref()
                .is_none_or(|o| o.split(',').any(|k| k.trim() == c.key))
        })
        .collect();
    if cases.is_empty() {
        eprintln!(
            "VS_RAPIER_SCENES names no scene; keys: {}",
            CASES.map(|c| c.key).join(", ")
        );
        return;
    }

    let mut accuracy = Vec::new();
    for case in &cases {
        let mut per_scene = Vec::new();
        for (name, make) in engines(case) {
            let mut engine = make();
            let a = drift_run(engine.as_mut(), end);
            eprintln!(
                "{}: {name}: drift {:.5} m (2 s → {} s), median {:.3} ms/step",
                case.key,
                a.drift,
                end as f32 * DT,
                a.median_step.as_secs_f64() * 1e3
            );
            per_scene.push((name, a));
        }
        accuracy.push(per_scene);
    }

    let mut c = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .configure_from_args();
    for case in &cases {
        let mut group = c.benchmark_group(group(case));
        for (name, make) in engines(case) {
            let mut engine = make();
            for _ in 0..SETTLE_STEPS {
                engine.step();
            }
            group.bench_function(criterion_id(&name), |b| {
                b.iter(|| {
                    engine.step();
                    black_box(&engine);
                })
            });
        }
        group.finish();
    }
    c.final_summary();
    if smoke {
        return;
    }

    for (case, accuracy) in cases.iter().zip(&accuracy) {
        table(case, accuracy);
    }
}

/// The criterion group of a scene.
fn group(case: &SceneCase) -> String {
    format!("vs_rapier_{}", case.key)
}

/// The markdown table of one scene, on stderr.
fn table(case: &SceneCase, accuracy: &[(String, Accuracy)]) {
    let crit: Vec<Option<f64>> = accuracy
        .iter()
        .map(|(name, _)| {
            common::criterion_median_ns(&group(case), &criterion_id(name)).map(|ns| ns / 1e6)
        })
        .collect();
    let (rapier_crit, rapier_acc) = (crit[0], &accuracy[0].1);
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let fmt = |x: Option<f64>| x.map_or("n/a".to_string(), |v| format!("{v:.3}"));
    eprintln!();
    eprintln!("{} (assets/{}.ron)", case.key, case.asset);
    eprintln!();
    eprintln!(
        "| engine | ms/step (criterion median) | ms/step (drift run median) | drift 2 s → 10 s (m) | time ratio / rapier3d | drift ratio / rapier3d |"
    );
    eprintln!("|---|---:|---:|---:|---:|---:|");
    for ((name, a), c) in accuracy.iter().zip(&crit) {
        let time_ratio = match (c, rapier_crit) {
            (Some(c), Some(r)) => c / r,
            _ => ms(a.median_step) / ms(rapier_acc.median_step),
        };
        let drift_ratio = if rapier_acc.drift > 0.0 {
            format!("{:.2}", a.drift / rapier_acc.drift)
        } else {
            "n/a".into()
        };
        eprintln!(
            "| {name} | {} | {:.3} | {:.5} | {time_ratio:.2} | {drift_ratio} |",
            fmt(*c),
            ms(a.median_step),
            a.drift,
        );
    }
}
