//! Per-axis rotation locks (issue 19 item 4): a body locked about some world axes turns about
//! the others only, in both resolvers, through contacts, impulses, snapshots and scene files.

mod common;

use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};

/// A tall box on the ground knocked at its top corner: returns its largest angular speed
/// about the horizontal axes and its largest tilt (rad) over 90 steps.
fn knocked(resolver: &jostle::ResolverChoice, locks: [bool; 3]) -> (f32, f32) {
    let mut world = common::world_with(Vec3::new(0.0, -9.81, 0.0), resolver);
    common::ground(&mut world, 0.5, 0.0);
    let post = world
        .add_body(
            BodyDesc::dynamic(
                "post",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::new(0.25, 1.0, 0.25),
                },
            )
            .at(Vec3::new(0.0, 1.0, 0.0))
            .with_rotation_locks(locks),
        )
        .unwrap();
    // 500 kg; a push of 1,000 N·s at a top corner, sideways and around.
    world
        .apply_impulse_at_point(
            post,
            Vec3::new(700.0, 0.0, 700.0),
            Vec3::new(0.25, 2.0, -0.25),
        )
        .unwrap();
    let (mut spin, mut tilt) = (0.0f32, 0.0f32);
    for _ in 0..90 {
        world.step(1.0 / 60.0).unwrap();
        let b = world.body(post).unwrap();
        spin = spin.max(Vec3::new(b.angular_velocity.x, 0.0, b.angular_velocity.z).length());
        let up = b.orientation * Vec3::Y;
        tilt = tilt.max(up.angle_between(Vec3::Y));
    }
    (spin, tilt)
}

#[test]
fn a_post_locked_about_the_horizontal_axes_never_tips() {
    for resolver in common::resolvers() {
        let (free_spin, free_tilt) = knocked(&resolver, [false; 3]);
        let (spin, tilt) = knocked(&resolver, [true, false, true]);
        println!(
            "{}: free tilt {free_tilt} rad (spin {free_spin}); locked tilt {tilt} (spin {spin})",
            resolver.name()
        );
        assert!(
            free_tilt > 0.3,
            "{}: the knock must tip a free post",
            resolver.name()
        );
        assert_eq!(spin, 0.0, "{}", resolver.name());
        assert!(tilt < 1e-5, "{}: tilted {tilt} rad", resolver.name());
    }
}

#[test]
fn locks_come_from_scene_files_and_survive_snapshots() {
    use jostle::scene::Scene;
    let scene = |w: &str| {
        Scene::parse(
            &format!(
                "Scene(bodies: [Body(name: \"g\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), \
                 fixed: true), Body(name: \"wheel\", shape: Cylinder(half_height: 0.1, radius: \
                 0.5), position: (0.0, 0.6, 0.0), rotation_locks: (true, false, true), \
                 angular_velocity: {w})])"
            ),
            "w.ron",
        )
    };
    let mut world = scene("(0.0, 3.0, 0.0)").unwrap().build().unwrap();
    let wheel = world.find_body("wheel").unwrap();
    assert_eq!(
        world.body(wheel).unwrap().rotation_locks(),
        [true, false, true]
    );
    for _ in 0..20 {
        world.step(1.0 / 60.0).unwrap();
    }
    let mut restored = World::from_snapshot(world.snapshot("w", 1.0 / 60.0)).unwrap();
    for _ in 0..20 {
        world.step(1.0 / 60.0).unwrap();
        restored.step(1.0 / 60.0).unwrap();
    }
    assert_eq!(world.state_hash(), restored.state_hash());
    assert_eq!(
        restored.body(wheel).unwrap().rotation_locks(),
        [true, false, true]
    );
    // A spin about a locked axis is refused, naming the field.
    let Err(e) = scene("(1.0, 3.0, 0.0)") else {
        panic!("a spin about a locked axis must be refused");
    };
    assert!(e.to_string().contains("angular_velocity"), "{e}");
}

#[test]
fn locking_at_run_time_drops_the_locked_spin() {
    let mut world = World::new(WorldSettings {
        gravity: Vec3::ZERO,
        ..Default::default()
    });
    let body = world
        .add_body(
            BodyDesc::dynamic("b", ShapeDesc::Ball { radius: 0.5 })
                .moving(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)),
        )
        .unwrap();
    world
        .set_rotation_locks(body, [false, true, false])
        .unwrap();
    assert_eq!(
        world.body(body).unwrap().angular_velocity,
        Vec3::new(1.0, 0.0, 3.0)
    );
    for _ in 0..10 {
        world.step(1.0 / 60.0).unwrap();
    }
    let b = world.body(body).unwrap();
    assert_eq!(b.angular_velocity.y, 0.0);
    // Unlocked again, a turn about y is possible.
    world.set_rotation_locks(body, [false; 3]).unwrap();
    world
        .apply_impulse_at_point(body, Vec3::new(0.0, 0.0, 10.0), Vec3::new(0.5, 0.0, 0.0))
        .unwrap();
    assert!(world.body(body).unwrap().angular_velocity.y != 0.0);
    let ground = world
        .add_body(BodyDesc::fixed(
            "ground",
            ShapeDesc::HalfSpace { normal: Vec3::Y },
        ))
        .unwrap();
    assert!(world.set_rotation_locks(ground, [true; 3]).is_err());
}
