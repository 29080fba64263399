//! A kinematic paddle knocks down a stack: the program sends the paddle to a new pose every
//! step (`World::set_next_pose`), the world gives it the velocity that gets it there, and the
//! paddle pushes the boxes while nothing pushes it back.
//!
//! Run: `cargo run --release --example kinematic_paddle`

use jostle::{BodyDesc, BodyType, Quat, ShapeDesc, Vec3, World, WorldSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new(WorldSettings::default());
    world.add_body(BodyDesc::fixed(
        "ground",
        ShapeDesc::HalfSpace { normal: Vec3::Y },
    ))?;
    // A column of eight 0.5 m boxes at the origin.
    let half = Vec3::splat(0.25);
    let boxes = (0..8)
        .map(|i| {
            world.add_body(
                BodyDesc::dynamic(format!("box {i}"), ShapeDesc::Cuboid { half_extents: half })
                    .at(Vec3::new(0.0, 0.25 + 0.5 * i as f32, 0.0)),
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    // A paddle of 1 × 0.6 × 0.2 m, 2 m to the left at the column's middle height, made
    // kinematic: sent to poses by the program.
    let start = Vec3::new(-2.0, 2.0, 0.0);
    let paddle = world.add_body(
        BodyDesc::dynamic(
            "paddle",
            ShapeDesc::Cuboid {
                half_extents: Vec3::new(0.1, 0.3, 0.5),
            },
        )
        .at(start),
    )?;
    world.set_body_type(paddle, BodyType::KinematicPosition)?;

    let dt = 1.0 / 60.0;
    for step in 1..=240 {
        // Rest for half a second, then swing through the column at 3 m/s, tilting forward.
        let t = (step as f32 * dt - 0.5).max(0.0);
        let position = start + Vec3::new(3.0 * t.min(1.5), 0.0, 0.0);
        let rotation = Quat::from_rotation_z(-0.3 * t.min(1.0));
        world.set_next_pose(paddle, position, rotation)?;
        world.step(dt)?;
        if step % 60 == 0 {
            let p = world.body(paddle).ok_or("the paddle went missing")?;
            let fallen = boxes
                .iter()
                .filter_map(|&h| world.body(h))
                .filter(|b| b.position.x.abs() > 0.25)
                .count();
            println!(
                "{:.0} s: paddle at ({:5.2}, {:4.2}) moving {:4.2} m/s, {fallen} of 8 boxes moved off the column",
                step as f32 * dt,
                p.position.x,
                p.position.y,
                p.linear_velocity.length(),
            );
        }
    }
    Ok(())
}

#[test]
fn runs() {
    main().expect("the example runs");
}
