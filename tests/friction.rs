//! Static and dynamic friction, against their closed forms, in both resolvers: a box sliding on
//! the ground decelerates at μd·g, one pushed with a force between μd·m·g and μs·m·g from rest
//! stays put, and one pushed harder accelerates at F/m − μd·g. The materials' dynamic
//! coefficient (`BodyDesc::with_dynamic_friction`, scene field `dynamic_friction`) defaults to
//! the static one, so every scene keeps its meaning.

mod common;

use common::resolvers;
use jostle::scene::Scene;
use jostle::{BodyDesc, BodyHandle, ResolverChoice, ShapeDesc, Vec3, World, WorldSettings};

const G: f32 = 9.81;
const DT: f32 = 1.0 / 60.0;
const STATIC: f32 = 0.8;
const DYNAMIC: f32 = 0.4;

/// A 1 m cube of `mass` kg resting on the ground, both with μs 0.8 and μd 0.4, moving at
/// `speed` along x; sleeping off.
fn cube_on_ground(resolver: &ResolverChoice, speed: f32, mass: f32) -> (World, BodyHandle) {
    let mut settings = WorldSettings {
        resolver: resolver.clone(),
        ..WorldSettings::default()
    };
    settings.sleep.enabled = false;
    let mut w = World::new(settings);
    w.add_body(
        BodyDesc::fixed("ground", ShapeDesc::HalfSpace { normal: Vec3::Y })
            .with_material(STATIC, 0.0)
            .with_dynamic_friction(DYNAMIC),
    )
    .unwrap();
    let cube = w
        .add_body(
            BodyDesc::dynamic(
                "cube",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.5),
                },
            )
            .at(Vec3::new(0.0, 0.5, 0.0))
            .with_mass(mass)
            .with_material(STATIC, 0.0)
            .with_dynamic_friction(DYNAMIC)
            .moving(Vec3::new(speed, 0.0, 0.0), Vec3::ZERO),
        )
        .unwrap();
    (w, cube)
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
        let (mut w, cube) = cube_on_ground(&r, 4.0, 10.0);
        let track = run(&mut w, cube, Vec3::ZERO, 2.0);
        // Between 0.1 s and 0.8 s it is sliding all along: −μd·g = −3.92 m/s² (μs would give
        // −7.85).
        let a = acceleration(&track, 6, 48);
        assert!(
            (a + DYNAMIC * G).abs() < 0.02 * DYNAMIC * G,
            "{}: deceleration {a} m/s², expected {}",
            r.name(),
            -DYNAMIC * G
        );
        // It stops after v₀²/(2·μd·g) = 2.04 m, and stays stopped.
        let (x, v) = *track.last().unwrap();
        let expected = 16.0 / (2.0 * DYNAMIC * G);
        assert!(
            (x - expected).abs() < 0.03 * expected,
            "{}: slid {x} m, expected {expected}",
            r.name()
        );
        assert!(v.abs() < 1e-3, "{}: still moving at {v} m/s", r.name());
    }
}

#[test]
fn a_push_below_static_friction_moves_nothing_and_above_it_slides_at_the_dynamic_rate() {
    let mass = 10.0;
    for r in resolvers() {
        // 0.6·m·g: above μd·m·g, below μs·m·g. Static friction holds it.
        let (mut w, cube) = cube_on_ground(&r, 0.0, mass);
        let track = run(&mut w, cube, Vec3::new(0.6 * mass * G, 0.0, 0.0), 2.0);
        let (x, v) = *track.last().unwrap();
        assert!(
            x.abs() < 1e-3 && v.abs() < 1e-3,
            "{}: pushed at 0.6·m·g it moved {x} m ({v} m/s)",
            r.name()
        );
        // 0.9·m·g: it breaks free and accelerates at F/m − μd·g = 0.5·g.
        let (mut w, cube) = cube_on_ground(&r, 0.0, mass);
        let track = run(&mut w, cube, Vec3::new(0.9 * mass * G, 0.0, 0.0), 1.0);
        let a = acceleration(&track, 12, 59);
        let expected = (0.9 - DYNAMIC) * G;
        assert!(
            (a - expected).abs() < 0.02 * expected,
            "{}: pushed at 0.9·m·g it accelerated at {a} m/s², expected {expected}",
            r.name()
        );
    }
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
