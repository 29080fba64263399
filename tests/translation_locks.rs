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
                    .at(Vec3::new(0.3 * i as f32, 0.3 + 0.55 * i as f32, 0.0))
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
        let start: Vec<Vec3> = boxes
            .iter()
            .map(|&h| world.body(h).unwrap().position)
            .collect();
        let mut moved = 0.0f32;
        for _ in 0..180 {
            world.step(DT).unwrap();
            for &h in &boxes {
                let b = world.body(h).unwrap();
                assert_eq!(b.position.z, 0.0, "{}: {}", resolver.name(), b.name);
                let tipped = b.orientation * Vec3::Z;
                assert!(
                    (tipped - Vec3::Z).length() < 1e-5,
                    "{}: {} turned out of its plane",
                    resolver.name(),
                    b.name
                );
                let i = boxes.iter().position(|&x| x == h).unwrap();
                moved = moved.max((b.position - start[i]).length());
            }
        }
        let top = world.body(boxes[3]).unwrap();
        println!(
            "{}: top box at ({:.3}, {:.3}), largest displacement {moved:.3}, ball velocity {}",
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

/// A box kept in the x-y plane slides to a stop on the ground as a free one does: friction
/// acts along the plane. (Locked along z and about x and y, nothing responds along z, the
/// contacts' tangent matrix is singular, and both resolvers once gave such contacts no
/// friction at all: the box slid on for ever.)
#[test]
fn a_box_kept_in_a_plane_slides_to_a_stop_like_a_free_one() {
    let (speed, mu) = (3.0f32, 0.5f32);
    let expected = speed * speed / (2.0 * mu * 9.81);
    for resolver in common::resolvers() {
        for locked in [false, true] {
            let mut world = common::world_with(Vec3::new(0.0, -9.81, 0.0), &resolver);
            common::ground(&mut world, mu, 0.0);
            let mut desc = BodyDesc::dynamic(
                "slider",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::new(0.5, 0.25, 0.5),
                },
            )
            .at(Vec3::new(0.0, 0.25, 0.0))
            .with_material(mu, 0.0)
            .moving(Vec3::new(speed, 0.0, 0.0), Vec3::ZERO);
            if locked {
                desc = desc
                    .with_translation_locks([false, false, true])
                    .with_rotation_locks([true, true, false]);
            }
            let slider = world.add_body(desc).unwrap();
            for _ in 0..120 {
                world.step(DT).unwrap();
            }
            let b = world.body(slider).unwrap();
            println!(
                "{}, locked {locked}: stopped after {:.4} m (μ·g gives {expected:.4}), v {:.5}",
                resolver.name(),
                b.position.x,
                b.linear_velocity.x
            );
            assert!(
                b.linear_velocity.x.abs() < 1e-3,
                "{}: still sliding",
                resolver.name()
            );
            assert!(
                (b.position.x - expected).abs() < 0.05 * expected,
                "{}, locked {locked}: slid {} m, expected {expected}",
                resolver.name(),
                b.position.x
            );
        }
    }
}

/// A box locked along every axis but free to turn, struck off-centre by a ball: it turns in
/// place, its centre exactly where it was, and the impact makes no energy.
#[test]
fn a_box_locked_along_every_axis_turns_in_place() {
    for resolver in common::resolvers() {
        let mut world = common::world_with(Vec3::ZERO, &resolver);
        let wheel = world
            .add_body(
                BodyDesc::dynamic(
                    "wheel",
                    ShapeDesc::Cuboid {
                        half_extents: Vec3::new(1.0, 0.2, 0.2),
                    },
                )
                .with_translation_locks([true; 3]),
            )
            .unwrap();
        let ball = world
            .add_body(
                BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.2 })
                    .at(Vec3::new(0.7, 2.0, 0.0))
                    .moving(Vec3::new(0.0, -5.0, 0.0), Vec3::ZERO)
                    .with_material(0.5, 0.5),
            )
            .unwrap();
        let energy = |w: &World| w.kinetic_energy();
        let before = energy(&world);
        for _ in 0..90 {
            world.step(DT).unwrap();
            let b = world.body(wheel).unwrap();
            assert_eq!(b.position, Vec3::ZERO, "{}", resolver.name());
            assert!(
                energy(&world) <= before * 1.0001,
                "{}: energy {} > {before}",
                resolver.name(),
                energy(&world)
            );
        }
        let spin = world.body(wheel).unwrap().angular_velocity;
        let back = world.body(ball).unwrap().linear_velocity;
        println!("{}: wheel spin {spin}, ball {back}", resolver.name());
        assert!(
            spin.z.abs() > 0.1,
            "{}: the strike must turn it",
            resolver.name()
        );
        assert!(back.y > 0.0, "{}: the ball must come back", resolver.name());
    }
}

/// A light box kept in a plane under a box 1,000 times heavier (the soft step solves such an
/// island directly, with the locked body's per-axis inverse mass): it carries the load, stays
/// in its plane, and the pair stands. Soft step only: the Millington resolver lets a 1:1,000
/// pair go with or without locks (`assets/mass_ratio_1000.ron --resolver millington`: the
/// light box is squeezed out and the heavy one ends on the ground).
#[test]
fn a_locked_light_box_under_a_heavy_one_holds_it_in_its_plane() {
    for resolver in &common::resolvers()[1..] {
        let mut world = common::world_with(Vec3::new(0.0, -9.81, 0.0), resolver);
        common::ground(&mut world, 0.6, 0.0);
        let cube = |name: &str, y: f32, mass: f32| {
            BodyDesc::dynamic(
                name,
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.5),
                },
            )
            .at(Vec3::new(0.0, y, 0.0))
            .with_mass(mass)
            .with_material(0.6, 0.0)
        };
        let light = world
            .add_body(
                cube("light", 0.5, 1.0)
                    .with_translation_locks([false, false, true])
                    .with_rotation_locks([true, true, false]),
            )
            .unwrap();
        let heavy = world.add_body(cube("heavy", 1.5, 1000.0)).unwrap();
        // A sideways shove of the heavy box along z, which the light box must not follow.
        world
            .apply_impulse_at_point(heavy, Vec3::new(0.0, 0.0, 200.0), Vec3::new(0.0, 1.5, 0.0))
            .unwrap();
        for _ in 0..300 {
            world.step(DT).unwrap();
            assert_eq!(
                world.body(light).unwrap().position.z,
                0.0,
                "{}",
                resolver.name()
            );
        }
        let (l, h) = (world.body(light).unwrap(), world.body(heavy).unwrap());
        println!(
            "{}: light at {}, heavy at {}",
            resolver.name(),
            l.position,
            h.position
        );
        assert!(
            (l.position.y - 0.5).abs() < 0.01,
            "{}: light y {}",
            resolver.name(),
            l.position.y
        );
        assert!(
            (h.position.y - 1.5).abs() < 0.02,
            "{}: heavy y {}",
            resolver.name(),
            h.position.y
        );
        assert!(
            l.position.x.abs() < 0.01,
            "{}: light x {}",
            resolver.name(),
            l.position.x
        );
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
