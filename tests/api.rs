//! The facade's API: bad calls get precise errors, never panics; forces at points make the
//! torque they should; non-finite state is quarantined while the rest of the world steps on.

use jostle::{BodyDesc, ShapeDesc, StepError, Vec3, World, WorldSettings};

fn world_with_ball() -> (World, jostle::BodyHandle) {
    let mut world = World::new(WorldSettings {
        gravity: Vec3::ZERO,
        ..Default::default()
    });
    let h = world
        .add_body(BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 }))
        .unwrap();
    (world, h)
}

#[test]
fn bad_dt_is_refused() {
    let (mut world, _) = world_with_ball();
    assert_eq!(world.step(-0.1), Err(StepError::InvalidDt(-0.1)));
    assert_eq!(world.step(0.0), Err(StepError::InvalidDt(0.0)));
    assert!(matches!(world.step(f32::NAN), Err(StepError::InvalidDt(_))));
    assert_eq!(world.time().1, 0, "a refused step does not count");
}

#[test]
fn stale_handles_are_refused() {
    let (mut world, h) = world_with_ball();
    let mut other = World::new(WorldSettings::default());
    other
        .add_body(BodyDesc::dynamic("a", ShapeDesc::Ball { radius: 0.5 }))
        .unwrap();
    let foreign = other
        .add_body(BodyDesc::dynamic("b", ShapeDesc::Ball { radius: 0.5 }))
        .unwrap();
    assert_eq!(
        world.apply_force(foreign, Vec3::X),
        Err(StepError::InvalidHandle(foreign))
    );
    assert!(world.body(foreign).is_none());
    assert!(world.apply_force(h, Vec3::X).is_ok());
}

#[test]
fn non_finite_api_values_are_refused() {
    let (mut world, h) = world_with_ball();
    assert!(matches!(
        world.apply_force(h, Vec3::new(f32::NAN, 0.0, 0.0)),
        Err(StepError::NonFinite { what: "force", .. })
    ));
    assert!(matches!(
        world.apply_impulse_at_point(h, Vec3::INFINITY, Vec3::ZERO),
        Err(StepError::NonFinite { .. })
    ));
    assert!(matches!(
        world.set_velocity(h, Vec3::ZERO, Vec3::NAN),
        Err(StepError::NonFinite { .. })
    ));
    world.step(1.0 / 60.0).unwrap();
    assert!(world.body(h).unwrap().is_finite());
}

#[test]
fn force_at_an_off_centre_point_spins_the_body() {
    let (mut world, h) = world_with_ball();
    // 1 N along +Y at 1 m along +X from the centre: torque (0, 0, 1) N·m for one step.
    world.apply_force_at_point(h, Vec3::Y, Vec3::X).unwrap();
    let dt = 0.01;
    world.step(dt).unwrap();
    let b = world.body(h).unwrap();
    let inertia = 0.4 * b.mass() * 0.25;
    assert!(
        (b.angular_velocity.z - dt / inertia).abs() < 1e-6 * (dt / inertia).max(1.0),
        "{}",
        b.angular_velocity
    );
    assert!((b.linear_velocity.y - dt / b.mass()).abs() < 1e-9);
}

#[test]
fn a_body_that_goes_non_finite_is_quarantined_and_the_rest_steps_on() {
    let mut world = World::new(WorldSettings::default());
    world
        .add_body(BodyDesc::fixed(
            "ground",
            ShapeDesc::HalfSpace { normal: Vec3::Y },
        ))
        .unwrap();
    let good = world
        .add_body(
            BodyDesc::dynamic("good", ShapeDesc::Ball { radius: 0.5 }).at(Vec3::new(5.0, 3.0, 0.0)),
        )
        .unwrap();
    let bad = world
        .add_body(
            BodyDesc::dynamic("bad", ShapeDesc::Ball { radius: 0.5 }).at(Vec3::new(-5.0, 3.0, 0.0)),
        )
        .unwrap();
    // A finite but overflowing force: F/m·dt is finite, the velocity it produces overflows.
    world
        .apply_force(bad, Vec3::new(0.0, f32::MAX, 0.0))
        .unwrap();
    world
        .apply_force(bad, Vec3::new(0.0, f32::MAX, 0.0))
        .unwrap();
    let report = world.step(1.0 / 60.0).unwrap();
    assert_eq!(report.quarantined, vec![(bad, "bad".to_string())]);
    let frozen = world.body(bad).unwrap();
    assert!(frozen.is_fixed() && frozen.is_finite());
    assert_eq!(
        frozen.position,
        Vec3::new(-5.0, 3.0, 0.0),
        "frozen at its last finite pose"
    );
    for _ in 0..60 {
        let r = world.step(1.0 / 60.0).unwrap();
        assert!(r.quarantined.is_empty());
    }
    let g = world.body(good).unwrap();
    assert!(
        g.is_finite() && g.position.y < 3.0,
        "the rest of the world keeps stepping"
    );
}

/// A body with locked rotation takes an off-centre impulse as pure translation, keeps a
/// tilted pose while it lands on a corner (an unlocked box topples), and refuses an initial
/// spin by name and field; with both resolvers.
#[test]
fn a_body_with_locked_rotation_never_turns() {
    let (mut world, _) = world_with_ball();
    let locked = world
        .add_body(
            BodyDesc::dynamic("locked", ShapeDesc::Ball { radius: 0.5 })
                .at(Vec3::new(5.0, 0.0, 0.0))
                .with_mass(2.0)
                .with_locked_rotation(),
        )
        .unwrap();
    world
        .apply_impulse_at_point(locked, Vec3::new(0.0, 0.0, 4.0), Vec3::new(5.5, 0.0, 0.0))
        .unwrap();
    world.step(1.0 / 60.0).unwrap();
    let b = world.body(locked).unwrap();
    assert!(b.is_rotation_locked());
    assert_eq!(b.angular_velocity, Vec3::ZERO);
    assert!((b.linear_velocity - Vec3::new(0.0, 0.0, 2.0)).length() < 1e-6);

    for resolver in [
        jostle::ResolverChoice::Millington(Default::default()),
        jostle::ResolverChoice::SoftStep(Default::default()),
    ] {
        // A cube tilted 30° about z, dropped onto the ground on one edge.
        let mut world = World::new(WorldSettings {
            resolver: resolver.clone(),
            ..Default::default()
        });
        world
            .add_body(BodyDesc::fixed(
                "ground",
                ShapeDesc::HalfSpace { normal: Vec3::Y },
            ))
            .unwrap();
        let tilt = jostle::Quat::from_rotation_z(std::f32::consts::FRAC_PI_6);
        let half = Vec3::splat(0.5);
        let drop = |name: &str| {
            BodyDesc::dynamic(name, ShapeDesc::Cuboid { half_extents: half })
                .at(Vec3::new(0.0, 1.0, 0.0))
                .rotated(tilt)
        };
        let locked = world
            .add_body(drop("locked").with_locked_rotation())
            .unwrap();
        let free = world
            .add_body(drop("free").at(Vec3::new(5.0, 1.0, 0.0)))
            .unwrap();
        for _ in 0..120 {
            world.step(1.0 / 60.0).unwrap();
        }
        let angle = |h| {
            let q: jostle::Quat = world.body(h).unwrap().orientation;
            q.angle_between(tilt)
        };
        assert_eq!(angle(locked), 0.0, "{resolver:?}: the locked cube turned");
        assert!(
            angle(free) > 0.3,
            "{resolver:?}: the free cube should topple"
        );
        let rest = world.body(locked).unwrap().position.y;
        // Resting on its lowest edge: the centre is half a diagonal of the tilted face above.
        let edge = 0.5 * (std::f32::consts::FRAC_PI_6.cos() + std::f32::consts::FRAC_PI_6.sin());
        assert!(
            (rest - edge).abs() < 0.01,
            "{resolver:?}: locked cube at {rest}, edge {edge}"
        );
    }

    let mut world = World::new(WorldSettings::default());
    let err = world
        .add_body(
            BodyDesc::dynamic("spinner", ShapeDesc::Ball { radius: 0.5 })
                .moving(Vec3::ZERO, Vec3::new(0.0, 1.0, 0.0))
                .with_locked_rotation(),
        )
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("spinner") && err.contains("angular_velocity"),
        "{err}"
    );
}
