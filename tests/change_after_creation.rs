//! Changing a body after it was added (issue 19 item 4): material and its combine rule,
//! damping, mass, fixed or dynamic, gravity scale, CCD mode, sleep permission, world gravity
//! and resolver settings. Each change acts at the next step, wakes what it must, and a bad
//! value is refused with its field named, changing nothing.

mod common;

use jostle::snapshot::Snapshot;
use jostle::{
    BodyDesc, CcdMode, Combine, MassSpec, Material, ResolverChoice, ShapeDesc, SoftStepSettings,
    StepError, Vec3, World, WorldSettings,
};

const DT: f32 = 1.0 / 60.0;

fn ground(world: &mut World, friction: f32) -> jostle::BodyHandle {
    world
        .add_body(
            BodyDesc::fixed("ground", ShapeDesc::HalfSpace { normal: Vec3::Y })
                .with_material(friction, 0.0),
        )
        .unwrap()
}

fn cube(name: &str, at: Vec3) -> BodyDesc {
    BodyDesc::dynamic(
        name,
        ShapeDesc::Cuboid {
            half_extents: Vec3::splat(0.5),
        },
    )
    .at(at)
    .with_density(1000.0)
}

fn steps(world: &mut World, n: usize) {
    for _ in 0..n {
        world.step(DT).unwrap();
    }
}

fn field_of(e: StepError) -> String {
    match e {
        StepError::Invalid { field, .. } => field,
        other => panic!("expected an invalid field, got {other:?}"),
    }
}

/// A box sliding at 4 m/s: with μ 0.5 it decelerates at μ·g; after its material changes to
/// one that combines by `Min` with μ 0 it slides on at constant speed.
#[test]
fn a_material_change_acts_at_the_next_step_with_its_combine_rule() {
    let mut world = World::new(WorldSettings::default());
    ground(&mut world, 0.5);
    let b = world
        .add_body(
            cube("box", Vec3::new(0.0, 0.5, 0.0))
                .moving(Vec3::new(4.0, 0.0, 0.0), Vec3::ZERO)
                .with_material(0.5, 0.0),
        )
        .unwrap();
    steps(&mut world, 6);
    let v0 = world.body(b).unwrap().linear_velocity.x;
    steps(&mut world, 12);
    let v1 = world.body(b).unwrap().linear_velocity.x;
    let deceleration = (v0 - v1) / (12.0 * DT);
    assert!(
        (deceleration - 0.5 * 9.81).abs() < 0.3,
        "μ 0.5 decelerates at {deceleration} m/s²"
    );
    // The geometric mean with the ground's 0.5 would still give friction; `Min` with μ 0
    // gives none.
    world
        .set_material(
            b,
            Material::new(0.0, 0.0).with_combine(Combine::Min, Combine::Max),
        )
        .unwrap();
    let v2 = world.body(b).unwrap().linear_velocity.x;
    steps(&mut world, 30);
    let v3 = world.body(b).unwrap().linear_velocity.x;
    assert!((v3 - v2).abs() < 1e-3, "frictionless: {v2} → {v3} m/s");
    assert_eq!(
        field_of(world.set_material(b, Material::new(0.5, 2.0)).unwrap_err()),
        "restitution"
    );
    assert_eq!(
        field_of(
            world
                .set_material(b, Material::new(0.3, 0.0).with_dynamic_friction(0.4))
                .unwrap_err()
        ),
        "dynamic_friction"
    );
}

#[test]
fn damping_set_later_slows_a_free_body() {
    let mut world = World::new(WorldSettings {
        gravity: Vec3::ZERO,
        ..Default::default()
    });
    let b = world
        .add_body(cube("box", Vec3::ZERO).moving(Vec3::X * 2.0, Vec3::Y))
        .unwrap();
    steps(&mut world, 10);
    assert_eq!(world.body(b).unwrap().linear_velocity.x, 2.0);
    world.set_damping(b, 1.0, 2.0).unwrap();
    steps(&mut world, 60);
    let body = world.body(b).unwrap();
    // v ← v/(1 + dt·c) per step: 2/(1 + 1/60)^60 and 1/(1 + 2/60)^60.
    let expected = 2.0 / (1.0 + DT).powi(60);
    assert!((body.linear_velocity.x - expected).abs() < 1e-4);
    let spin = 1.0 / (1.0 + 2.0 * DT).powi(60);
    assert!((body.angular_velocity.y - spin).abs() < 1e-4);
    assert_eq!(
        field_of(world.set_damping(b, -1.0, 0.0).unwrap_err()),
        "linear_damping"
    );
    assert_eq!(
        field_of(world.set_damping(b, 0.0, f32::NAN).unwrap_err()),
        "angular_damping"
    );
    assert_eq!(world.body(b).unwrap().linear_damping, 1.0, "unchanged");
}

#[test]
fn a_new_mass_changes_the_response_to_an_impulse() {
    let mut world = World::new(WorldSettings {
        gravity: Vec3::ZERO,
        ..Default::default()
    });
    let b = world.add_body(cube("box", Vec3::ZERO)).unwrap();
    assert!((world.body(b).unwrap().mass() - 1000.0).abs() < 1e-2);
    world.set_mass(b, MassSpec::Mass(10.0)).unwrap();
    assert!((world.body(b).unwrap().mass() - 10.0).abs() < 1e-5);
    world
        .apply_impulse_at_point(b, Vec3::new(5.0, 0.0, 0.0), Vec3::ZERO)
        .unwrap();
    assert!((world.body(b).unwrap().linear_velocity.x - 0.5).abs() < 1e-6);
    world.set_mass(b, MassSpec::Density(500.0)).unwrap();
    assert!((world.body(b).unwrap().mass() - 500.0).abs() < 1e-2);
    // The inertia follows: a unit cube of 500 kg has I = m/6 about every axis.
    let inv = world.body(b).unwrap().inv_inertia_body();
    assert!((inv.x_axis.x - 6.0 / 500.0).abs() < 1e-6);
    assert_eq!(
        field_of(world.set_mass(b, MassSpec::Mass(0.0)).unwrap_err()),
        "mass"
    );
    assert_eq!(
        field_of(world.set_mass(b, MassSpec::Density(1e13)).unwrap_err()),
        "density"
    );
    assert!(
        (world.body(b).unwrap().mass() - 500.0).abs() < 1e-2,
        "unchanged"
    );
}

/// A falling box made fixed stops where it is and holds another box; made dynamic again it
/// falls with the mass it had. A shelf added fixed falls once it is made dynamic.
#[test]
fn bodies_switch_between_fixed_and_dynamic() {
    let mut world = World::new(WorldSettings::default());
    ground(&mut world, 0.5);
    let shelf = world
        .add_body(cube("shelf", Vec3::new(0.0, 3.0, 0.0)))
        .unwrap();
    steps(&mut world, 5);
    world.set_fixed(shelf, true).unwrap();
    let held = world.body(shelf).unwrap().position;
    let top = world
        .add_body(cube("top", Vec3::new(0.0, held.y + 1.5, 0.0)))
        .unwrap();
    steps(&mut world, 120);
    assert_eq!(world.body(shelf).unwrap().position, held, "fixed: it holds");
    let rest = world.body(top).unwrap().position.y;
    assert!(
        (rest - (held.y + 1.0)).abs() < 0.01,
        "the top box rests on it: {rest}"
    );
    world.set_fixed(shelf, false).unwrap();
    assert!((world.body(shelf).unwrap().mass() - 1000.0).abs() < 1e-2);
    assert!(world.body(top).unwrap().sleep.awake, "what it held wakes");
    steps(&mut world, 120);
    let fallen = world.body(shelf).unwrap().position.y;
    assert!(
        (fallen - 0.5).abs() < 0.01,
        "it fell to the ground: {fallen}"
    );

    // Added fixed: it becomes dynamic with its shape's mass at the default density.
    let beam = world
        .add_body(
            BodyDesc::fixed(
                "beam",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::new(1.0, 0.1, 0.5),
                },
            )
            .at(Vec3::new(5.0, 2.0, 0.0)),
        )
        .unwrap();
    world.set_fixed(beam, false).unwrap();
    assert!((world.body(beam).unwrap().mass() - 1000.0 * 2.0 * 0.2 * 1.0).abs() < 0.1);
    steps(&mut world, 120);
    assert!((world.body(beam).unwrap().position.y - 0.1).abs() < 0.01);

    // A half-space stays fixed.
    let g = world.find_body("ground").unwrap();
    assert_eq!(
        field_of(world.set_fixed(g, false).unwrap_err()),
        "body_type"
    );
}

/// Positions after one second of free fall under gravity scaled by s: s times the fall of
/// the unscaled body (the gravity that is not the world's is spread over the step's substeps
/// like the world's), which falls within the integrator's ½·g·t² error.
#[test]
fn gravity_scale_scales_the_fall() {
    for resolver in common::resolvers() {
        gravity_scale_scales_the_fall_with(resolver);
    }
}

fn gravity_scale_scales_the_fall_with(resolver: ResolverChoice) {
    let name = resolver.name();
    let mut world = World::new(WorldSettings {
        resolver,
        ..Default::default()
    });
    let scales = [0.0, 0.5, 1.0, -1.0, 2.0];
    let bodies: Vec<_> = scales
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let b = world
                .add_body(cube(
                    &format!("b{i}"),
                    Vec3::new(3.0 * i as f32, 100.0, 0.0),
                ))
                .unwrap();
            world.set_gravity_scale(b, s).unwrap();
            b
        })
        .collect();
    steps(&mut world, 60);
    let fall = |b| world.body(b).unwrap().position.y - 100.0;
    let unscaled = fall(bodies[2]);
    assert!((unscaled + 0.5 * 9.81).abs() < 0.1, "{unscaled}");
    for (&b, &s) in bodies.iter().zip(&scales) {
        let dy = fall(b);
        assert!(
            (dy - s * unscaled).abs() < 1e-4 * (1.0 + s.abs()),
            "{name}, scale {s}: fell {dy} m, expected {}",
            s * unscaled
        );
    }
    assert_eq!(
        field_of(world.set_gravity_scale(bodies[0], f32::NAN).unwrap_err()),
        "gravity_scale"
    );
}

/// A new world gravity wakes a sleeping pile, which then slides down the new "down".
#[test]
fn world_gravity_changes_wake_sleepers() {
    let mut world = World::new(WorldSettings::default());
    ground(&mut world, 0.0);
    let b = world
        .add_body(cube("box", Vec3::new(0.0, 0.5, 0.0)))
        .unwrap();
    steps(&mut world, 200);
    assert!(!world.body(b).unwrap().sleep.awake, "asleep");
    world.set_gravity(Vec3::new(2.0, -9.81, 0.0)).unwrap();
    assert!(world.body(b).unwrap().sleep.awake);
    steps(&mut world, 60);
    assert!(world.body(b).unwrap().position.x > 0.9, "slides along x");
    assert_eq!(
        field_of(world.set_gravity(Vec3::new(0.0, -1e6, 0.0)).unwrap_err()),
        "gravity"
    );
}

#[test]
fn sleep_permission_and_ccd_mode_change() {
    let mut world = World::new(WorldSettings::default());
    ground(&mut world, 0.5);
    let b = world
        .add_body(cube("box", Vec3::new(0.0, 0.5, 0.0)))
        .unwrap();
    steps(&mut world, 200);
    assert!(!world.body(b).unwrap().sleep.awake);
    world.set_can_sleep(b, false).unwrap();
    assert!(
        world.body(b).unwrap().sleep.awake,
        "forbidding sleep wakes it"
    );
    steps(&mut world, 300);
    assert!(
        world.body(b).unwrap().sleep.awake,
        "and it never sleeps again"
    );
    world.set_can_sleep(b, true).unwrap();
    steps(&mut world, 300);
    assert!(!world.body(b).unwrap().sleep.awake);
    world.set_ccd(b, CcdMode::Off).unwrap();
    assert_eq!(world.body(b).unwrap().ccd, CcdMode::Off);
}

#[test]
fn resolver_settings_change_validated() {
    let mut world = World::new(WorldSettings::default());
    ground(&mut world, 0.5);
    world
        .add_body(cube("box", Vec3::new(0.0, 0.5, 0.0)))
        .unwrap();
    let bad = ResolverChoice::SoftStep(SoftStepSettings {
        contact_hertz: -1.0,
        ..Default::default()
    });
    assert_eq!(
        field_of(world.set_resolver_choice(bad).unwrap_err()),
        "resolver.contact_hertz"
    );
    assert_eq!(world.resolver_name(), "soft-step");
    world
        .set_resolver_choice(ResolverChoice::Millington(Default::default()))
        .unwrap();
    assert_eq!(world.resolver_name(), "millington");
    assert_eq!(world.settings().resolver.name(), "millington");
    steps(&mut world, 60);
}

/// Every change is part of the state a snapshot carries: a world changed in every way
/// continues bit for bit from its snapshot.
#[test]
fn changed_bodies_round_trip_through_snapshots() {
    let mut world = World::new(WorldSettings::default());
    ground(&mut world, 0.5);
    let a = world.add_body(cube("a", Vec3::new(0.0, 0.5, 0.0))).unwrap();
    let b = world.add_body(cube("b", Vec3::new(0.2, 1.6, 0.0))).unwrap();
    let c = world.add_body(cube("c", Vec3::new(3.0, 4.0, 0.0))).unwrap();
    steps(&mut world, 10);
    world
        .set_material(
            b,
            Material::new(0.9, 0.3).with_combine(Combine::Max, Combine::Min),
        )
        .unwrap();
    world.set_damping(a, 0.1, 0.2).unwrap();
    world.set_mass(b, MassSpec::Mass(50.0)).unwrap();
    world.set_gravity_scale(c, 0.3).unwrap();
    world.set_fixed(a, true).unwrap();
    world.set_gravity(Vec3::new(0.5, -9.0, 0.0)).unwrap();
    steps(&mut world, 10);
    let text = world.snapshot("changed", DT).to_ron().unwrap();
    let mut restored = World::from_snapshot(Snapshot::parse(&text, "changed").unwrap()).unwrap();
    for _ in 0..60 {
        world.step(DT).unwrap();
        restored.step(DT).unwrap();
    }
    assert_eq!(restored.state_hash(), world.state_hash());
    assert!(restored.body(a).unwrap().is_fixed());
}
