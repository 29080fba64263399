//! The side-by-side with rapier3d 0.36 (issue 6's last acceptance item, DESIGN.md "Benchmarks"):
//! the 20-row pyramid of `assets/pyramid_20.ron` (210 boxes of 1 m, μ 0.6, density 1000 kg/m³,
//! on the ground, sleeping disabled) built in rapier3d with its defaults (dt 1/60, 4 solver
//! iterations, 1 substep) and in jostle with each resolver, measured in the same run.
//!
//! Two measurements per engine:
//! - **accuracy and a first time**, before criterion starts: a fresh world runs 10 s; drift is
//!   the largest displacement of any box between 2 s and 10 s (the stability test's
//!   criterion), and every step after 2 s is timed, giving a median over 480 steps;
//! - **criterion**: the world settled for 120 steps (2 s), then one step per iteration.
//!
//! After criterion, a markdown table is printed to stderr: engine, criterion's median ms/step,
//! the drift run's median ms/step, drift (m) and the ratios jostle / rapier3d. Run:
//! `cargo bench --bench vs_rapier`. The ground is a fixed 200 × 1 × 200 m cuboid in rapier3d
//! (its top face at y = 0) and a half-space in jostle; friction combines as the mean in
//! rapier3d and both sides use 0.6, so the pair's coefficient is 0.6 in both engines.
//!
//! With `--test` (`cargo test --benches`), only a short smoke run is made.

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

/// One engine under test: a way to step and to read every dynamic body's position.
trait Engine {
    fn step(&mut self);
    fn positions(&self) -> Vec<[f32; 3]>;
}

/// The pyramid in rapier3d, with its defaults but sleeping disabled.
struct Rapier {
    world: rp::PhysicsWorld,
    boxes: Vec<rp::RigidBodyHandle>,
}

impl Rapier {
    /// The same layout as jostle's `Pyramid` generator: row `r` holds `ROWS − r` boxes centred
    /// on x = 0, resting exactly on the row below.
    fn new() -> Self {
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
        for row in 0..ROWS {
            let n = ROWS - row;
            for i in 0..n {
                let x = (i as f32 - (n - 1) as f32 / 2.0) * 2.0 * HALF;
                let y = HALF + 2.0 * HALF * row as f32;
                let (h, _) = world.insert(
                    rp::RigidBodyBuilder::dynamic()
                        .translation(rp::Vector::new(x, y, 0.0))
                        .can_sleep(false),
                    rp::ColliderBuilder::cuboid(HALF, HALF, HALF)
                        .density(DENSITY)
                        .friction(FRICTION),
                );
                boxes.push(h);
            }
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

/// The pyramid in jostle, from the scene file, with the given resolver and sleeping disabled.
struct Jostle(World);

impl Jostle {
    fn new(resolver: ResolverChoice) -> Self {
        let scene = Scene::load(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/assets/pyramid_20.ron"
        ))
        .expect("asset loads");
        let mut settings = scene.settings();
        settings.resolver = resolver;
        settings.sleep.enabled = false;
        let world = scene.build_with(settings).expect("scene builds");
        assert_eq!(
            world.bodies().filter(|(_, _, b)| !b.is_fixed()).count(),
            (ROWS * (ROWS + 1) / 2) as usize
        );
        Self(world)
    }
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

/// Builds one engine's world.
type Make = fn() -> Box<dyn Engine>;

/// The engines, in table order: (name, constructor).
fn engines() -> Vec<(&'static str, Make)> {
    vec![
        ("rapier3d", || Box::new(Rapier::new())),
        ("jostle soft-step", || {
            Box::new(Jostle::new(
                ResolverChoice::from_name("soft-step").expect("name"),
            ))
        }),
        ("jostle millington", || {
            Box::new(Jostle::new(
                ResolverChoice::from_name("millington").expect("name"),
            ))
        }),
    ]
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

/// Criterion's median for `group/id` (ns), read back from its report directory, if present.
fn criterion_median_ns(group: &str, id: &str) -> Option<f64> {
    let base = std::env::var_os("CRITERION_HOME")
        .map(std::path::PathBuf::from)
        .or_else(|| {
            std::env::var_os("CARGO_TARGET_DIR")
                .map(|d| std::path::PathBuf::from(d).join("criterion"))
        })
        .unwrap_or_else(|| {
            std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/target/criterion"))
        });
    let text =
        std::fs::read_to_string(base.join(group).join(id).join("new/estimates.json")).ok()?;
    // `{"mean":{...},"median":{"confidence_interval":{...},"point_estimate":X,...},...}`
    let after = &text[text.find("\"median\"")?..];
    let after = &after[after.find("\"point_estimate\":")? + "\"point_estimate\":".len()..];
    let end = after.find([',', '}'])?;
    after[..end].trim().parse().ok()
}

/// Criterion's report id for an engine name ("jostle soft-step" → "jostle_soft-step").
fn criterion_id(name: &str) -> String {
    name.replace(' ', "_")
}

const GROUP: &str = "vs_rapier_pyramid20";

fn main() {
    let smoke = std::env::args().any(|a| a == "--test");
    let end = if smoke { SETTLE_STEPS + 2 } else { END_STEPS };

    let mut accuracy = Vec::new();
    for (name, make) in engines() {
        let mut engine = make();
        let a = drift_run(engine.as_mut(), end);
        eprintln!(
            "{name}: drift {:.5} m (2 s → {} s), median {:.3} ms/step",
            a.drift,
            end as f32 * DT,
            a.median_step.as_secs_f64() * 1e3
        );
        accuracy.push((name, a));
    }

    let mut c = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .configure_from_args();
    {
        let mut group = c.benchmark_group(GROUP);
        for (name, make) in engines() {
            let mut engine = make();
            for _ in 0..SETTLE_STEPS {
                engine.step();
            }
            group.bench_function(criterion_id(name), |b| {
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

    let crit: Vec<Option<f64>> = accuracy
        .iter()
        .map(|(name, _)| criterion_median_ns(GROUP, &criterion_id(name)).map(|ns| ns / 1e6))
        .collect();
    let (rapier_crit, rapier_acc) = (crit[0], &accuracy[0].1);
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let fmt = |x: Option<f64>| x.map_or("n/a".to_string(), |v| format!("{v:.3}"));
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
