//! Sensors, collision groups and events: balls rolling along the ground pass a sensor gate
//! that counts them; "ghost" balls, in a group the bumper does not meet, pass through the
//! bumper that stops the others. Prints each event as it happens.
//!
//! Run: `cargo run --release --example sensors_and_events`

use jostle::{
    BodyDesc, CollisionEvent, CollisionGroups, SensorEvent, ShapeDesc, Vec3, World, WorldSettings,
};

const SOLID: u32 = 1;
const GHOST: u32 = 2;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new(WorldSettings::default());
    world.add_body(BodyDesc::fixed(
        "ground",
        ShapeDesc::HalfSpace { normal: Vec3::Y },
    ))?;
    // A sensor gate the balls roll through, and a bumper behind it that meets solid balls only.
    let gate = world.add_body(
        BodyDesc::fixed(
            "gate",
            ShapeDesc::Cuboid {
                half_extents: Vec3::new(0.2, 1.0, 1.5),
            },
        )
        .at(Vec3::new(2.0, 1.0, 0.0))
        .as_sensor(),
    )?;
    world.add_body(
        BodyDesc::fixed(
            "bumper",
            ShapeDesc::Cuboid {
                half_extents: Vec3::new(0.2, 0.5, 1.5),
            },
        )
        .at(Vec3::new(5.0, 0.5, 0.0))
        .with_groups(CollisionGroups::new(SOLID, SOLID)),
    )?;
    let gate_collider = world.colliders_of(gate)[0];

    let dt = 1.0 / 60.0;
    let mut through_gate = 0;
    for step in 0..360 {
        if step % 60 == 0 && step < 240 {
            // Every second a ball; every other one a ghost.
            let ghost = (step / 60) % 2 == 1;
            let name = format!("{} {}", if ghost { "ghost" } else { "ball" }, step / 60);
            // Ghosts meet only ghosts (and the ground and the gate, which meet every group).
            let groups = if ghost {
                CollisionGroups::new(GHOST, GHOST)
            } else {
                CollisionGroups::new(SOLID, u32::MAX)
            };
            world.add_body(
                BodyDesc::dynamic(name, ShapeDesc::Ball { radius: 0.2 })
                    .at(Vec3::new(-2.0, 0.2, 0.6 * (step / 60) as f32 - 0.9))
                    .moving(Vec3::new(3.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -15.0))
                    .with_groups(groups),
            )?;
        }
        world.step(dt)?;
        let name = |w: &World, c| {
            w.collider(c)
                .and_then(|c| w.body_name(c.body))
                .unwrap_or("?")
                .to_string()
        };
        for event in world.sensor_events() {
            match *event {
                SensorEvent::Entered { sensor, other } if sensor == gate_collider => {
                    through_gate += 1;
                    println!("step {step:3}: {} enters the gate", name(&world, other));
                }
                SensorEvent::Exited { sensor, other } if sensor == gate_collider => {
                    println!("step {step:3}: {} leaves the gate", name(&world, other));
                }
                _ => {}
            }
        }
        for event in world.events() {
            if let CollisionEvent::Started(a, b) = *event {
                let named = |h| world.body_name(h).unwrap_or("?");
                if named(a) == "bumper" || named(b) == "bumper" {
                    println!("step {step:3}: {} hits {}", named(a), named(b));
                }
            }
        }
    }
    println!("{through_gate} balls passed the gate");
    for (_, name, body) in world.bodies() {
        if name.starts_with("ball") || name.starts_with("ghost") {
            let side = if body.position.x > 5.2 {
                "beyond the bumper"
            } else {
                "before the bumper"
            };
            println!("  {name}: x = {:5.2}, {side}", body.position.x);
        }
    }
    Ok(())
}

#[test]
fn runs() {
    main().expect("the example runs");
}
