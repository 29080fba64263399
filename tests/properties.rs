//! Property-based tests (proptest): random scenes of random shapes, sizes, masses, velocities
//! and overlaps. After the steps, no value is non-finite, nothing panicked, and — with no
//! gravity and no restitution, so no external work and no elastic rebound — the total kinetic
//! energy never grows above its start.
//!
//! Cases: `PROPTEST_CASES` (default 256 here); the heavier run is
//! `PROPTEST_CASES=1000 cargo test --release --test properties`. The cases come from a fixed
//! seed, so every run (CI's included) tests the same scenes; `PROPTEST_RNG_SEED=n` draws
//! others. With random seeds the Millington property fails now and then: it has known
//! energy gains in rare collisions (two boxes in zero gravity, 2.6%), open in the issues.

use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

/// `cases` cases drawn from a fixed seed unless `PROPTEST_RNG_SEED` names one.
fn config(cases: u32) -> ProptestConfig {
    let base = ProptestConfig::default();
    let rng_seed = match base.rng_seed {
        RngSeed::Random => RngSeed::Fixed(0x6a6f_7374_6c65),
        seed => seed,
    };
    ProptestConfig {
        cases,
        rng_seed,
        ..base
    }
}

fn shape() -> impl Strategy<Value = ShapeDesc> {
    let size = 0.05f32..2.0;
    prop_oneof![
        size.clone().prop_map(|radius| ShapeDesc::Ball { radius }),
        (size.clone(), size.clone(), size.clone()).prop_map(|(x, y, z)| ShapeDesc::Cuboid {
            half_extents: Vec3::new(x, y, z)
        }),
        (size.clone(), size.clone()).prop_map(|(half_height, radius)| ShapeDesc::Capsule {
            half_height,
            radius
        }),
        (size.clone(), size.clone()).prop_map(|(half_height, radius)| ShapeDesc::Cylinder {
            half_height,
            radius
        }),
        proptest::collection::vec((-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0), 4..10).prop_map(
            |pts| {
                // A tetrahedron's worth of spread plus random points: always a solid hull.
                let mut points = vec![
                    Vec3::new(0.5, 0.0, 0.0),
                    Vec3::new(-0.5, 0.0, 0.0),
                    Vec3::new(0.0, 0.5, 0.0),
                    Vec3::new(0.0, 0.0, 0.5),
                ];
                points.extend(pts.into_iter().map(|(x, y, z)| Vec3::new(x, y, z)));
                ShapeDesc::ConvexHull { points }
            }
        ),
    ]
}

fn v3(r: f32) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn body() -> impl Strategy<Value = BodyDesc> {
    (
        shape(),
        v3(3.0),
        v3(10.0),
        v3(10.0),
        10.0f32..10_000.0,
        0.0f32..1.5,
        (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0),
    )
        .prop_map(|(shape, at, v, w, density, mu, (qx, qy, qz, qw))| {
            let q = jostle::Quat::from_xyzw(qx, qy, qz, qw + 1.5).normalize();
            BodyDesc::dynamic("b", shape)
                .at(at)
                .rotated(q)
                .moving(v, w)
                .with_density(density)
                .with_material(mu, 0.0)
        })
}

/// A closed room (no gravity): a floor, and optionally bodies only, so some bodies collide
/// with static geometry too.
fn world(bodies: Vec<BodyDesc>, floor: bool, resolver: jostle::ResolverChoice) -> World {
    let mut w = World::new(WorldSettings {
        gravity: Vec3::ZERO,
        resolver,
        ..Default::default()
    });
    if floor {
        w.add_body(
            BodyDesc::fixed("floor", ShapeDesc::HalfSpace { normal: Vec3::Y })
                .at(Vec3::new(0.0, -4.0, 0.0)),
        )
        .unwrap();
    }
    for (i, mut b) in bodies.into_iter().enumerate() {
        b.name = format!("b{i}");
        w.add_body(b).unwrap();
    }
    w
}

fn check(
    bodies: Vec<BodyDesc>,
    floor: bool,
    resolver: jostle::ResolverChoice,
) -> Result<(), TestCaseError> {
    let mut w = world(bodies, floor, resolver);
    let e0 = w.kinetic_energy();
    let mut worst = e0;
    for _ in 0..90 {
        let report = w.step(1.0 / 60.0).unwrap();
        prop_assert!(
            report.quarantined.is_empty(),
            "quarantined {:?}",
            report.quarantined
        );
        worst = worst.max(w.kinetic_energy());
    }
    for (_, name, b) in w.bodies() {
        prop_assert!(b.is_finite(), "{} went non-finite", name);
    }
    // f32 round-off allowance only: 1e-4 relative.
    prop_assert!(
        worst <= e0 * (1.0 + 1e-4) + 1e-6,
        "kinetic energy grew from {} to {}",
        e0,
        worst
    );
    Ok(())
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn millington_random_scenes_stay_finite_and_never_gain_kinetic_energy(
        bodies in proptest::collection::vec(body(), 1..8),
        floor in any::<bool>(),
    ) {
        check(
            bodies,
            floor,
            jostle::ResolverChoice::Millington(Default::default()),
        )?;
    }

    /// Whatever the energy, the soft-step resolver stays finite and never quarantines.
    #[test]
    fn soft_step_random_scenes_stay_finite(
        bodies in proptest::collection::vec(body(), 1..8),
        floor in any::<bool>(),
    ) {
        let mut w = world(bodies, floor, jostle::ResolverChoice::SoftStep(Default::default()));
        for _ in 0..90 {
            prop_assert!(w.step(1.0 / 60.0).unwrap().quarantined.is_empty());
        }
        for (_, name, b) in w.bodies() {
            prop_assert!(b.is_finite(), "{} went non-finite", name);
        }
    }
}

proptest! {
    #![proptest_config(config(1024))]

    /// The soft step pushes overlap out through pseudo velocities that never become motion
    /// (split impulses, `SoftStepSettings::push_out_slop`), so random overlapping starts never
    /// gain kinetic energy. Four times the cases of the other properties: this one failed
    /// before (two overlapping capsules: 694,778 J → 694,854 J).
    #[test]
    fn soft_step_random_scenes_never_gain_kinetic_energy(
        bodies in proptest::collection::vec(body(), 1..8),
        floor in any::<bool>(),
    ) {
        check(bodies, floor, jostle::ResolverChoice::SoftStep(Default::default()))?;
    }
}

/// Bodies of every shape started at one point, at rest and without gravity: the soft step
/// separates them without giving them any speed (before the split push-out these 60 reached
/// 1.07 MJ, and 200 balls 8.6 m/s and 1.5 MJ).
#[test]
fn soft_step_separates_a_pile_started_at_one_point_without_speed() {
    let shapes = [
        ShapeDesc::Ball { radius: 0.5 },
        ShapeDesc::Cuboid {
            half_extents: Vec3::new(0.5, 0.3, 0.4),
        },
        ShapeDesc::Capsule {
            half_height: 0.4,
            radius: 0.3,
        },
        ShapeDesc::Cylinder {
            half_height: 0.3,
            radius: 0.5,
        },
    ];
    let bodies = (0..60)
        .map(|i| {
            let f = i as f32;
            // A spread of a few millimetres, so the push directions are defined.
            let at = Vec3::new(
                (f * 0.618).fract() - 0.5,
                (f * 0.414).fract() - 0.5,
                (f * 0.732).fract() - 0.5,
            ) * 0.01;
            BodyDesc::dynamic("b", shapes[i % shapes.len()].clone())
                .at(at)
                .rotated(jostle::Quat::from_rotation_y(f) * jostle::Quat::from_rotation_x(0.7 * f))
                .with_density(1000.0)
                .with_material(0.5, 0.0)
        })
        .collect();
    let mut w = world(
        bodies,
        false,
        jostle::ResolverChoice::SoftStep(Default::default()),
    );
    let mut start = 0.0f32;
    let mut worst = 0.0f64;
    for step in 0..240 {
        w.step(1.0 / 60.0).unwrap();
        if step == 0 {
            // The contacts are those detected at the start of the step.
            start = w.max_penetration();
        }
        worst = worst.max(w.kinetic_energy());
    }
    assert!(start > 0.5, "the pile starts overlapping: {start}");
    assert!(worst <= 1e-6, "kinetic energy reached {worst} J");
    assert!(
        w.max_penetration() < 0.01,
        "overlap left after 4 s: {} m",
        w.max_penetration()
    );
}
