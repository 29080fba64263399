//! Bodies removed and added while the world steps: a spawner drops a ball every half second,
//! balls that leave the floor's area are removed, and the stack's base block is pulled out
//! once, waking what rested on it. Handles of removed bodies go stale.
//!
//! Run: `cargo run --release --example removal`

use jostle::{BodyDesc, CollisionEvent, ShapeDesc, Vec3, World, WorldSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new(WorldSettings::default());
    // A floor of 6 × 6 m on a fixed block, slightly tilted so that balls roll off.
    world.add_body(
        BodyDesc::fixed(
            "floor",
            ShapeDesc::Cuboid {
                half_extents: Vec3::new(3.0, 0.1, 3.0),
            },
        )
        .rotated(jostle::Quat::from_rotation_z(0.15)),
    )?;
    // A base block with two boxes on it.
    let base = world.add_body(
        BodyDesc::dynamic(
            "base",
            ShapeDesc::Cuboid {
                half_extents: Vec3::splat(0.3),
            },
        )
        .at(Vec3::new(0.0, 0.6, 0.0)),
    )?;
    for i in 0..2 {
        world.add_body(
            BodyDesc::dynamic(
                format!("box {i}"),
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.3),
                },
            )
            .at(Vec3::new(0.0, 1.2 + 0.6 * i as f32, 0.0)),
        )?;
    }

    let dt = 1.0 / 60.0;
    let mut balls = Vec::new();
    let (mut spawned, mut removed) = (0, 0);
    for step in 1..=600 {
        if step % 30 == 0 {
            let ball = world.add_body(
                BodyDesc::dynamic(format!("ball {spawned}"), ShapeDesc::Ball { radius: 0.2 })
                    .at(Vec3::new(-1.5, 3.0, 0.5 * (spawned % 5) as f32 - 1.0)),
            )?;
            balls.push(ball);
            spawned += 1;
        }
        if step == 240 {
            // Pull the base out: the boxes above wake and fall.
            world.remove_body(base)?;
            assert!(
                world.body(base).is_none(),
                "a removed body's handle is stale"
            );
            println!("4 s: base removed");
        }
        world.step(dt)?;
        // Balls that fell below the floor are removed; their handles go stale.
        let gone: Vec<_> = balls
            .iter()
            .copied()
            .filter(|&h| world.body(h).is_some_and(|b| b.position.y < -2.0))
            .collect();
        for h in gone {
            world.remove_body(h)?;
            balls.retain(|&b| b != h);
            removed += 1;
        }
        let ended = world
            .events()
            .iter()
            .filter(|e| matches!(e, CollisionEvent::Stopped(..)))
            .count();
        if step % 120 == 0 {
            println!(
                "{:.0} s: {} bodies, {spawned} balls dropped, {removed} removed, {ended} contacts ended this step",
                step as f32 * dt,
                world.bodies().count(),
            );
        }
    }
    Ok(())
}

#[test]
fn runs() {
    main().expect("the example runs");
}
