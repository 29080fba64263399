//! Property-based tests (proptest): random scenes of random shapes, sizes, masses, velocities
//! and overlaps. After the steps, no value is non-finite, nothing panicked, and — with no
//! gravity and no restitution, so no external work and no elastic rebound — the total kinetic
//! energy never grows above its start.
//!
//! Cases: `PROPTEST_CASES` (default 256 here); the heavier run is
//! `PROPTEST_CASES=1000 cargo test --release --test properties`.

use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};
use proptest::prelude::*;

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
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_scenes_stay_finite_and_never_gain_kinetic_energy(
        bodies in proptest::collection::vec(body(), 1..8),
        floor in any::<bool>(),
    ) {
        check(bodies, floor, jostle::ResolverChoice::default())?;
    }

    /// Open: the soft-step resolver's push-out of initially overlapping bodies feeds the real
    /// velocity, so the kinetic energy can grow (≈ 0.01%: 694,778 J → 694,854 J for two
    /// overlapping capsules). Finiteness holds; run with `--ignored` to see the case.
    #[test]
    #[ignore = "open: soft-step push-out of initial overlaps adds ~0.01% kinetic energy"]
    fn soft_step_random_scenes_never_gain_kinetic_energy(
        bodies in proptest::collection::vec(body(), 1..8),
        floor in any::<bool>(),
    ) {
        check(bodies, floor, jostle::ResolverChoice::SoftStep(Default::default()))?;
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
