//! Several colliders per body (issue 19 item 2): `World::add_collider` sums mass, centre of
//! mass and inertia, keeps every collider where it is in the world, and the added shapes make
//! contacts of their own; `World::set_mass` sums over all of a body's colliders.

mod common;

use jostle::{
    BodyDesc, ColliderDesc, MassSpec, Quat, ShapeDesc, StepError, Vec3, World, WorldSettings,
};
use std::f32::consts::PI;

fn ball(radius: f32) -> ShapeDesc {
    ShapeDesc::Ball { radius }
}

fn cube(half: f32) -> ShapeDesc {
    ShapeDesc::Cuboid {
        half_extents: Vec3::splat(half),
    }
}

/// Mass (kg) of a ball of `radius` at 1000 kg/m³.
fn ball_mass(radius: f32) -> f32 {
    1000.0 * 4.0 / 3.0 * PI * radius.powi(3)
}

#[test]
fn two_balls_sum_to_the_textbook_mass_centre_and_inertia() {
    let mut world = World::new(WorldSettings::default());
    let body = world
        .add_body(BodyDesc::dynamic("pair", ball(0.5)).at(Vec3::new(1.0, 2.0, 3.0)))
        .unwrap();
    world
        .add_collider(
            body,
            ColliderDesc::new(ball(0.5)).at(Vec3::new(2.0, 0.0, 0.0)),
        )
        .unwrap();
    let b = world.body(body).unwrap();
    let m = ball_mass(0.5);
    assert!((b.mass() - 2.0 * m).abs() < 1e-3 * m, "{}", b.mass());
    // Halfway between the two centres.
    assert!(
        b.position.abs_diff_eq(Vec3::new(2.0, 2.0, 3.0), 1e-5),
        "{}",
        b.position
    );
    // Each ball: 2/5·m·r² about its centre, plus m·1² about the axes across the pair.
    let (_, inertia) = b.mass_properties().unwrap();
    let own = 0.4 * m * 0.25;
    let expected = Vec3::new(2.0 * own, 2.0 * (own + m), 2.0 * (own + m));
    let diagonal = Vec3::new(inertia.x_axis.x, inertia.y_axis.y, inertia.z_axis.z);
    assert!(
        diagonal.abs_diff_eq(expected, 1e-3 * expected.max_element()),
        "{diagonal} against {expected}"
    );
    // The colliders kept their places in the world: centres at x = 1 and x = 3.
    let mut centres: Vec<f32> = world
        .colliders_of(body)
        .iter()
        .map(|&c| world.collider(c).unwrap().world_pose(b).translation.x)
        .collect();
    centres.sort_by(f32::total_cmp);
    assert!(
        (centres[0] - 1.0).abs() < 1e-5 && (centres[1] - 3.0).abs() < 1e-5,
        "{centres:?}"
    );
}

#[test]
fn a_turning_body_keeps_its_motion_when_its_centre_moves() {
    let mut world = World::new(WorldSettings {
        gravity: Vec3::ZERO,
        ..Default::default()
    });
    let body = world
        .add_body(
            BodyDesc::dynamic("spinner", cube(0.5))
                .moving(Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 2.0)),
        )
        .unwrap();
    let before = world.body(body).unwrap().clone();
    world
        .add_collider(
            body,
            ColliderDesc::new(cube(0.5)).at(Vec3::new(0.0, 1.0, 0.0)),
        )
        .unwrap();
    let after = world.body(body).unwrap();
    // The new centre (0, 0.5, 0) moved with the body's old motion: v + ω × r.
    let r = after.position - before.position;
    assert!(r.abs_diff_eq(Vec3::new(0.0, 0.5, 0.0), 1e-6), "{r}");
    let expected = before.linear_velocity + before.angular_velocity.cross(r);
    assert!(
        after.linear_velocity.abs_diff_eq(expected, 1e-6),
        "{} against {expected}",
        after.linear_velocity
    );
    assert_eq!(after.angular_velocity, before.angular_velocity);
}

/// A post with a heavy ball held out beside its top (the summed centre of mass beyond the
/// post's foot) tips over; without the ball it stands. Returns the post's tilt (rad) after
/// 2 s.
fn post_tips(resolver: &jostle::ResolverChoice, with_ball: bool) -> f32 {
    let mut world = common::world_with(Vec3::new(0.0, -9.81, 0.0), resolver);
    common::ground(&mut world, 0.5, 0.0);
    let post = world
        .add_body(
            BodyDesc::dynamic(
                "post",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::new(0.2, 1.0, 0.2),
                },
            )
            .at(Vec3::new(0.0, 1.0, 0.0)),
        )
        .unwrap();
    if with_ball {
        world
            .add_collider(
                post,
                ColliderDesc::new(ball(0.3)).at(Vec3::new(1.5, 0.7, 0.0)),
            )
            .unwrap();
    }
    // Post 320 kg, ball 113 kg: the centre sits 0.39 m from the post's axis, its foot 0.2.
    for _ in 0..120 {
        world.step(1.0 / 60.0).unwrap();
    }
    world
        .body(post)
        .unwrap()
        .orientation
        .angle_between(Quat::IDENTITY)
}

#[test]
fn an_off_centre_collider_tips_its_body_over() {
    for resolver in common::resolvers() {
        let standing = post_tips(&resolver, false);
        let tipped = post_tips(&resolver, true);
        println!(
            "{}: tilt {standing} rad alone, {tipped} rad with the ball",
            resolver.name()
        );
        assert!(standing < 1e-3, "{}: {standing}", resolver.name());
        assert!(
            tipped > 0.5,
            "{}: the post did not tip: {tipped}",
            resolver.name()
        );
    }
}

#[test]
fn an_added_collider_rests_on_the_ground() {
    for resolver in common::resolvers() {
        let mut world = common::world_with(Vec3::new(0.0, -9.81, 0.0), &resolver);
        common::ground(&mut world, 0.5, 0.0);
        // A ball with a flat foot fixed 1 m below it: the foot lands first and holds it up.
        let body = world
            .add_body(BodyDesc::dynamic("top", ball(0.3)).at(Vec3::new(0.0, 3.0, 0.0)))
            .unwrap();
        world
            .add_collider(
                body,
                ColliderDesc::new(ShapeDesc::Cuboid {
                    half_extents: Vec3::new(0.5, 0.05, 0.5),
                })
                .at(Vec3::new(0.0, -1.0, 0.0)),
            )
            .unwrap();
        for _ in 0..180 {
            world.step(1.0 / 60.0).unwrap();
        }
        let b = world.body(body).unwrap();
        let lowest = world
            .colliders_of(body)
            .iter()
            .map(|&c| world.collider(c).unwrap().world_pose(b).translation.y)
            .fold(f32::INFINITY, f32::min);
        assert!(
            (lowest - 0.05).abs() < 0.01,
            "{}: the foot rests at {lowest}, not on the ground",
            resolver.name()
        );
    }
}

#[test]
fn set_mass_sums_over_every_collider() {
    let mut world = World::new(WorldSettings::default());
    let body = world
        .add_body(BodyDesc::dynamic("pair", ball(0.5)))
        .unwrap();
    world
        .add_collider(
            body,
            ColliderDesc::new(ball(0.5))
                .at(Vec3::new(2.0, 0.0, 0.0))
                .with_density(3000.0),
        )
        .unwrap();
    // Density 3000 on one side: the centre sits three quarters of the way to it.
    let centre = world.body(body).unwrap().position;
    assert!(
        centre.abs_diff_eq(Vec3::new(1.5, 0.0, 0.0), 1e-5),
        "{centre}"
    );
    // One density for both: back to the middle, twice one ball.
    world.set_mass(body, MassSpec::Density(1000.0)).unwrap();
    let b = world.body(body).unwrap();
    assert!(
        b.position.abs_diff_eq(Vec3::new(1.0, 0.0, 0.0), 1e-5),
        "{}",
        b.position
    );
    assert!((b.mass() - 2.0 * ball_mass(0.5)).abs() < 1e-2);
    world.set_mass(body, MassSpec::Mass(10.0)).unwrap();
    assert!((world.body(body).unwrap().mass() - 10.0).abs() < 1e-5);
}

#[test]
fn bad_colliders_are_refused_by_field() {
    let mut world = World::new(WorldSettings::default());
    let body = world.add_body(BodyDesc::dynamic("b", ball(0.5))).unwrap();
    let field = |r: Result<_, StepError>| match r {
        Err(StepError::Invalid { field, .. }) => field,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        field(world.add_collider(
            body,
            ColliderDesc::new(ShapeDesc::HalfSpace { normal: Vec3::Y })
        )),
        "collider.shape"
    );
    assert_eq!(
        field(world.add_collider(body, ColliderDesc::new(ball(0.1)).with_density(f32::NAN))),
        "collider.density"
    );
    assert_eq!(
        field(world.add_collider(body, ColliderDesc::new(ball(0.1)).at(Vec3::NAN))),
        "collider.position"
    );
    assert_eq!(
        field(world.add_collider(body, ColliderDesc::new(ball(-1.0)))),
        "collider.shape.radius"
    );
    assert_eq!(
        field(world.add_collider(
            body,
            ColliderDesc::new(ball(0.1)).rotated(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0))
        )),
        "collider.rotation"
    );
    assert_eq!(world.colliders_of(body).len(), 1, "nothing was added");
    world.remove_body(body).unwrap();
    assert!(matches!(
        world.add_collider(body, ColliderDesc::new(ball(0.1))),
        Err(StepError::InvalidHandle(_))
    ));
}

#[test]
fn a_body_of_several_colliders_continues_bit_for_bit_from_a_snapshot() {
    let mut world = World::new(WorldSettings::default());
    world
        .add_body(BodyDesc::fixed(
            "ground",
            ShapeDesc::HalfSpace { normal: Vec3::Y },
        ))
        .unwrap();
    let body = world
        .add_body(BodyDesc::dynamic("l", cube(0.5)).at(Vec3::new(0.0, 2.0, 0.0)))
        .unwrap();
    world
        .add_collider(
            body,
            ColliderDesc::new(cube(0.5)).at(Vec3::new(1.0, 0.0, 0.0)),
        )
        .unwrap();
    for _ in 0..30 {
        world.step(1.0 / 60.0).unwrap();
    }
    let mut restored = World::from_snapshot(world.snapshot("l", 1.0 / 60.0)).unwrap();
    for _ in 0..30 {
        world.step(1.0 / 60.0).unwrap();
        restored.step(1.0 / 60.0).unwrap();
    }
    assert_eq!(restored.state_hash(), world.state_hash());
    assert_eq!(restored.colliders_of(body).len(), 2);
}

#[test]
fn scene_bodies_take_further_colliders_and_name_a_bad_one() {
    use jostle::scene::{Scene, SceneError};
    let text = |density: &str| {
        format!(
            "Scene(bodies: [Body(name: \"bell\", shape: Capsule(half_height: 0.4, radius: 0.04), \
             density: 500.0, friction: 0.9, colliders: [\
             Collider(shape: Ball(radius: 0.15), position: (0.0, 0.5, 0.0), density: {density}), \
             Collider(shape: Ball(radius: 0.15), position: (0.0, -0.5, 0.0), friction: 0.2)])])"
        )
    };
    let scene = Scene::parse(&text("7800.0"), "bell.ron").unwrap();
    let world = scene.build().unwrap();
    let body = world.find_body("bell").unwrap();
    let colliders = world.colliders_of(body);
    assert_eq!(colliders.len(), 3);
    // The second ball takes the body's density (500) and its own friction; the first keeps
    // the body's friction.
    let frictions: Vec<f32> = colliders
        .iter()
        .map(|&c| world.collider(c).unwrap().material.friction)
        .collect();
    assert_eq!(frictions, vec![0.9, 0.9, 0.2]);
    // Heavier at +y: the centre of mass lies above the bar's middle.
    assert!(world.body(body).unwrap().position.y > 0.2);
    let Err(SceneError::Body { error, .. }) = Scene::parse(&text("-1.0"), "bell.ron") else {
        panic!("a negative density must be refused");
    };
    assert!(
        error.to_string().contains("colliders[0].density"),
        "{error}"
    );
}
