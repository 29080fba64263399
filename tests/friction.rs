//! Static and dynamic friction, against their closed forms, in both resolvers, for cubes of
//! 0.1, 1 and 10 m (1 kg to 10⁶ kg) and two pairs of coefficients: a box sliding on the ground
//! decelerates at μd·g, one pushed with a force between μd·m·g and μs·m·g from rest stays put
//! (also at 0.95 and 0.98 of μs·m·g), and one pushed harder accelerates at F/m − μd·g. The materials' dynamic
//! coefficient (`BodyDesc::with_dynamic_friction`, scene field `dynamic_friction`) defaults to
//! the static one, so every scene keeps its meaning.

mod common;

use common::resolvers;
use jostle::scene::Scene;
use jostle::{BodyDesc, BodyHandle, ResolverChoice, ShapeDesc, Vec3, World, WorldSettings};

const G: f32 = 9.81;
const DT: f32 = 1.0 / 60.0;

/// One case of the family: a cube of side `size` (m) at 1,000 kg/m³ (1 kg to 10⁶ kg) on the
/// ground, both surfaces with static `mu_s` and dynamic `mu_d`.
#[derive(Clone, Copy, Debug)]
struct Case {
    size: f32,
    mu_s: f32,
    mu_d: f32,
}

/// Cubes of 0.1, 1 and 10 m, each with two pairs of coefficients.
fn family() -> Vec<Case> {
    let mut cases = Vec::new();
    for size in [0.1, 1.0, 10.0] {
        for (mu_s, mu_d) in [(0.8, 0.4), (0.5, 0.3)] {
            cases.push(Case { size, mu_s, mu_d });
        }
    }
    cases
}

/// Cubes of 0.1, 1 and 10 m at μs 0.9, μd 0.85, sliding (a push between these coefficients
/// is in `a_push_just_below_static_friction_moves_nothing`). The Millington resolver's box slid
/// 4–10% too far here (0.96–1.02 m against 0.93) before its friction was made to oppose a fast
/// slide whatever the normal impulse of the stop-dead solve.
fn high_friction() -> Vec<Case> {
    [0.1, 1.0, 10.0]
        .into_iter()
        .map(|size| Case {
            size,
            mu_s: 0.9,
            mu_d: 0.85,
        })
        .collect()
}

/// The case's cube resting on the ground, moving at `speed` along x; sleeping off.
fn cube_on_ground(resolver: &ResolverChoice, case: Case, speed: f32) -> (World, BodyHandle, f32) {
    let mut settings = WorldSettings {
        resolver: resolver.clone(),
        ..WorldSettings::default()
    };
    settings.sleep.enabled = false;
    let mut w = World::new(settings);
    w.add_body(
        BodyDesc::fixed("ground", ShapeDesc::HalfSpace { normal: Vec3::Y })
            .with_material(case.mu_s, 0.0)
            .with_dynamic_friction(case.mu_d),
    )
    .unwrap();
    let half = 0.5 * case.size;
    let cube = w
        .add_body(
            BodyDesc::dynamic(
                "cube",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(half),
                },
            )
            .at(Vec3::new(0.0, half, 0.0))
            .with_material(case.mu_s, 0.0)
            .with_dynamic_friction(case.mu_d)
            .moving(Vec3::new(speed, 0.0, 0.0), Vec3::ZERO),
        )
        .unwrap();
    let mass = w.body(cube).unwrap().mass();
    (w, cube, mass)
}

/// Steps `w` for `seconds`, pushing `cube` with `force` (N) every step; returns the cube's
/// x position and x velocity after each step.
fn run(w: &mut World, cube: BodyHandle, force: Vec3, seconds: f32) -> Vec<(f32, f32)> {
    let steps = (seconds / DT).round() as usize;
    (0..steps)
        .map(|_| {
            if force != Vec3::ZERO {
                w.apply_force(cube, force).unwrap();
            }
            w.step(DT).unwrap();
            let b = w.body(cube).unwrap();
            (b.position.x, b.linear_velocity.x)
        })
        .collect()
}

/// The x acceleration between steps `i` and `j` of a run, from the velocities.
fn acceleration(track: &[(f32, f32)], i: usize, j: usize) -> f32 {
    (track[j].1 - track[i].1) / ((j - i) as f32 * DT)
}

#[test]
fn a_sliding_box_decelerates_at_the_dynamic_coefficient() {
    for r in resolvers() {
        for case in family().into_iter().chain(high_friction()) {
            let (mut w, cube, _) = cube_on_ground(&r, case, 4.0);
            let track = run(&mut w, cube, Vec3::ZERO, 2.0);
            // From 0.1 s to 0.8 s or 80% of its time to stop, whichever is first, it is
            // sliding all along: −μd·g (μs would be far more).
            let stop = 4.0 / (case.mu_d * G);
            let end = ((0.8 * stop).min(0.8) / DT) as usize;
            let a = acceleration(&track, 6, end);
            let expected = -case.mu_d * G;
            assert!(
                (a - expected).abs() < 0.02 * expected.abs(),
                "{} {case:?}: deceleration {a} m/s², expected {expected}",
                r.name()
            );
            // It stops after v₀²/(2·μd·g), and stays stopped. (Less up to v₀·dt/2 for a
            // step's poses integrated with its velocity after the change, as both resolvers
            // integrate: the Millington resolver once a step, the soft step once a substep.)
            let (x, v) = *track.last().unwrap();
            let distance = 16.0 / (2.0 * case.mu_d * G);
            let lag = 0.5 * 4.0 * DT;
            assert!(
                x > distance - lag - 0.03 * distance && x < distance + 0.03 * distance,
                "{} {case:?}: slid {x} m, expected {distance}",
                r.name()
            );
            assert!(
                v.abs() < 1e-3,
                "{} {case:?}: still moving at {v} m/s",
                r.name()
            );
        }
    }
}

#[test]
fn a_push_below_static_friction_moves_nothing_and_above_it_slides_at_the_dynamic_rate() {
    for r in resolvers() {
        for case in family() {
            // Halfway between μd·m·g and μs·m·g: static friction holds it.
            let (mut w, cube, mass) = cube_on_ground(&r, case, 0.0);
            let hold = 0.5 * (case.mu_s + case.mu_d);
            let track = run(&mut w, cube, Vec3::new(hold * mass * G, 0.0, 0.0), 2.0);
            let (x, v) = *track.last().unwrap();
            assert!(
                x.abs() < 1e-3 && v.abs() < 1e-3,
                "{} {case:?}: pushed at {hold}·m·g it moved {x} m ({v} m/s)",
                r.name()
            );
            // 0.1·m·g above μs·m·g: it breaks free and accelerates at F/m − μd·g.
            let (mut w, cube, mass) = cube_on_ground(&r, case, 0.0);
            let push = case.mu_s + 0.1;
            let track = run(&mut w, cube, Vec3::new(push * mass * G, 0.0, 0.0), 1.0);
            let a = acceleration(&track, 12, 59);
            let expected = (push - case.mu_d) * G;
            assert!(
                (a - expected).abs() < 0.02 * expected,
                "{} {case:?}: pushed at {push}·m·g it accelerated at {a} m/s², expected {expected}",
                r.name()
            );
        }
    }
}

/// Pushed at 0.95 and 0.98 of μs·m·g from rest, a cube of 0.1, 1 or 10 m stays put for 2 s in
/// both resolvers (μs 0.3 to 0.9, μd up to μs). The push acts at the centre, so the leading
/// corners carry most of the load and the trailing ones hold little friction: static friction
/// holds only if the corners share it by their load. The Millington resolver's corner picks
/// did not (each tilted its friction across the face) and the cube slid 0.05–1.05 m in 2 s at
/// 0.95·μs; it now moves less than 0.02 mm.
#[test]
fn a_push_just_below_static_friction_moves_nothing() {
    let mut wrong = Vec::new();
    for r in resolvers() {
        for size in [0.1, 1.0, 10.0] {
            for (mu_s, mu_d) in [(0.3, 0.3), (0.5, 0.45), (0.9, 0.85)] {
                for fraction in [0.95, 0.98] {
                    let case = Case { size, mu_s, mu_d };
                    let (mut w, cube, mass) = cube_on_ground(&r, case, 0.0);
                    let push = Vec3::new(fraction * mu_s * mass * G, 0.0, 0.0);
                    let (x, v) = *run(&mut w, cube, push, 2.0).last().unwrap();
                    if !(x.abs() < 1e-3 && v.abs() < 1e-3) {
                        wrong.push(format!(
                            "{} {case:?} pushed at {fraction}·μs·m·g: moved {x} m ({v} m/s)",
                            r.name()
                        ));
                    }
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

#[test]
fn dynamic_friction_defaults_to_the_static_one_and_must_not_exceed_it() {
    let scene = Scene::parse(
        "Scene(bodies: [Body(name: \"a\", shape: Ball(radius: 0.5), friction: 0.7), \
         Body(name: \"b\", shape: Ball(radius: 0.5), friction: 0.7, dynamic_friction: 0.3)])",
        "f.ron",
    )
    .unwrap();
    let descs = scene.body_descs().unwrap();
    assert_eq!(descs[0].material.dynamic(), 0.7);
    assert_eq!(descs[1].material.dynamic(), 0.3);
    let e = Scene::parse(
        "Scene(bodies: [Body(name: \"b\", shape: Ball(radius: 0.5), friction: 0.3, dynamic_friction: 0.7)])",
        "f.ron",
    )
    .and_then(|s| s.build().map(|_| ()))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("dynamic_friction") && e.contains("<= friction"),
        "{e}"
    );
}
