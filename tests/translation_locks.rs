//! Per-axis translation locks (issue 19 item 4): a body locked along some world axes moves
//! along the others only, in both resolvers, through contacts, impulses, gravity, snapshots
//! and scene files.

mod common;

use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};

const DT: f32 = 1.0 / 60.0;

#[test]
fn a_body_locked_along_the_vertical_floats_and_slides() {
    for resolver in common::resolvers() {
        let mut world = common::world_with(Vec3::new(0.0, -9.81, 0.0), &resolver);
        let puck = world
            .add_body(
                BodyDesc::dynamic(
                    "puck",
                    ShapeDesc::Cuboid {
                        half_extents: Vec3::splat(0.5),
                    },
                )
                .at(Vec3::new(0.0, 2.0, 0.0))
                .with_translation_locks([false, true, false]),
            )
            .unwrap();
        world
            .apply_impulse_at_point(
                puck,
                Vec3::new(1000.0, 1000.0, 0.0),
                Vec3::new(0.0, 2.0, 0.0),
            )
            .unwrap();
        for _ in 0..60 {
            world.step(DT).unwrap();
        }
        let b = world.body(puck).unwrap();
        assert_eq!(b.position.y, 2.0, "{}", resolver.name());
        assert_eq!(b.linear_velocity.y, 0.0, "{}", resolver.name());
        assert!(
            (b.position.x - 1.0).abs() < 1e-4,
            "{}: x = {}",
            resolver.name(),
            b.position.x
        );
    }
}

/// Boxes kept in the x-y plane (translation along z and rotation about x and y locked), as a
/// 2D game keeps its bodies, knocked by a ball that comes in along z as well: they stack,
/// fall and tumble without ever leaving their plane, and the ball (free) is deflected.
#[test]
fn boxes_kept_in_a_plane_never_leave_it_whatever_hits_them() {
    for resolver in common::resolvers() {
        let mut world = common::world_with(Vec3::new(0.0, -9.81, 0.0), &resolver);
        common::ground(&mut world, 0.5, 0.0);
        let mut boxes = Vec::new();
        for i in 0..4 {
            let b = world
                .add_body(
                    BodyDesc::dynamic(
                        format!("box{i}"),
                        ShapeDesc::Cuboid {
                            half_extents: Vec3::new(0.5, 0.25, 0.5),
                        },
                    )
                    // Offset so that the column is unstable and topples.
                    .at(Vec3::new(0.15 * i as f32, 0.3 + 0.55 * i as f32, 0.0))
                    .with_translation_locks([false, false, true])
                    .with_rotation_locks([true, true, false]),
                )
                .unwrap();
            boxes.push(b);
        }
        let ball = world
            .add_body(
                BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.3 })
                    .at(Vec3::new(-2.0, 1.5, -2.0))
                    .moving(Vec3::new(6.0, 0.0, 6.0), Vec3::ZERO),
            )
            .unwrap();
        let mut moved = 0.0f32;
        for _ in 0..180 {
            world.step(DT).unwrap();
            for &h in &boxes {
                let b = world.body(h).unwrap();
                assert_eq!(b.position.z, 0.0, "{}: {}", resolver.name(), b.name);
                assert_eq!(b.linear_velocity.z, 0.0, "{}: {}", resolver.name(), b.name);
                let tipped = b.orientation * Vec3::Z;
                assert!(
                    (tipped - Vec3::Z).length() < 1e-5,
                    "{}: {} turned out of its plane",
                    resolver.name(),
                    b.name
                );
                moved = moved.max((b.position.x).abs());
            }
        }
        let top = world.body(boxes[3]).unwrap();
        println!(
            "{}: top box at ({:.3}, {:.3}), farthest box x {moved:.3}, ball velocity {}",
            resolver.name(),
            top.position.x,
            top.position.y,
            world.body(ball).unwrap().linear_velocity
        );
        // Something happened in the plane: the column fell or was pushed.
        assert!(moved > 0.3, "{}: the boxes stayed put", resolver.name());
    }
}

/// A box locked along x is a wall along x to a box that slides into it: the slider stops
/// (no restitution) and the locked box does not move along x at all, while gravity still
/// holds both on the ground.
#[test]
fn a_box_locked_along_x_stops_a_box_that_slides_into_it() {
    for resolver in common::resolvers() {
        let mut world = common::world_with(Vec3::new(0.0, -9.81, 0.0), &resolver);
        common::ground(&mut world, 0.0, 0.0);
        let cube = |name: &str, x: f32| {
            BodyDesc::dynamic(
                name,
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.5),
                },
            )
            .at(Vec3::new(x, 0.5, 0.0))
            .with_material(0.0, 0.0)
        };
        let post = world
            .add_body(cube("post", 0.0).with_translation_locks([true, false, false]))
            .unwrap();
        let slider = world
            .add_body(cube("slider", -3.0).moving(Vec3::new(4.0, 0.0, 0.0), Vec3::ZERO))
            .unwrap();
        for _ in 0..120 {
            world.step(DT).unwrap();
            let p = world.body(post).unwrap();
            assert_eq!(p.position.x, 0.0, "{}", resolver.name());
        }
        let s = world.body(slider).unwrap();
        println!(
            "{}: slider at x {:.4}, v {:.4}",
            resolver.name(),
            s.position.x,
            s.linear_velocity.x
        );
        assert!(
            s.position.x < -0.99,
            "{}: slider at {}",
            resolver.name(),
            s.position.x
        );
        assert!(s.linear_velocity.x.abs() < 0.05, "{}", resolver.name());
        // Both rest on the ground.
        for h in [post, slider] {
            let y = world.body(h).unwrap().position.y;
            assert!((y - 0.5).abs() < 0.01, "{}: y = {y}", resolver.name());
        }
    }
}

#[test]
fn locks_come_from_scene_files_survive_snapshots_and_change_at_run_time() {
    use jostle::scene::Scene;
    let scene = |v: &str| {
        Scene::parse(
            &format!(
                "Scene(bodies: [Body(name: \"g\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), \
                 fixed: true), Body(name: \"b\", shape: Cuboid(half_extents: (0.5, 0.5, 0.5)), \
                 position: (0.0, 0.5, 0.0), translation_locks: (false, false, true), \
                 linear_velocity: {v})])"
            ),
            "t.ron",
        )
    };
    let mut world = scene("(2.0, 0.0, 0.0)").unwrap().build().unwrap();
    let b = world.find_body("b").unwrap();
    assert_eq!(
        world.body(b).unwrap().translation_locks(),
        [false, false, true]
    );
    world
        .apply_impulse_at_point(b, Vec3::new(0.0, 0.0, 500.0), Vec3::new(0.0, 0.5, 0.0))
        .unwrap();
    for _ in 0..20 {
        world.step(DT).unwrap();
    }
    let mut restored = World::from_snapshot(world.snapshot("t", DT)).unwrap();
    for _ in 0..20 {
        world.step(DT).unwrap();
        restored.step(DT).unwrap();
    }
    assert_eq!(world.state_hash(), restored.state_hash());
    assert_eq!(
        restored.body(b).unwrap().translation_locks(),
        [false, false, true]
    );
    assert_eq!(world.body(b).unwrap().position.z, 0.0);
    // A velocity along a locked axis is refused, naming the field.
    let Err(e) = scene("(2.0, 0.0, 1.0)") else {
        panic!("a velocity along a locked axis must be refused");
    };
    assert!(e.to_string().contains("linear_velocity"), "{e}");

    // At run time: locking drops the locked velocity, unlocking frees the axis again.
    let mut world = World::new(WorldSettings {
        gravity: Vec3::ZERO,
        ..Default::default()
    });
    let ball = world
        .add_body(
            BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 })
                .moving(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO),
        )
        .unwrap();
    world
        .set_translation_locks(ball, [true, false, false])
        .unwrap();
    assert_eq!(
        world.body(ball).unwrap().linear_velocity,
        Vec3::new(0.0, 2.0, 3.0)
    );
    world
        .set_velocity(ball, Vec3::new(5.0, 2.0, 3.0), Vec3::ZERO)
        .unwrap();
    assert_eq!(world.body(ball).unwrap().linear_velocity.x, 0.0);
    world.set_translation_locks(ball, [false; 3]).unwrap();
    world
        .set_velocity(ball, Vec3::new(5.0, 2.0, 3.0), Vec3::ZERO)
        .unwrap();
    assert_eq!(world.body(ball).unwrap().linear_velocity.x, 5.0);
    let ground = world
        .add_body(BodyDesc::fixed(
            "ground",
            ShapeDesc::HalfSpace { normal: Vec3::Y },
        ))
        .unwrap();
    assert!(world.set_translation_locks(ground, [true; 3]).is_err());
}
