//! A world built in code: a column of ten boxes on the ground, hit by a ball thrown at it.
//! Prints the collision events as they happen and where the boxes end up.
//!
//! Run: `cargo run --release --example stack_and_ball`

use jostle::{BodyDesc, CollisionEvent, ShapeDesc, Vec3, World, WorldSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The defaults: gravity −9.81 m/s² along y, the soft-step resolver, sleep on.
    let mut world = World::new(WorldSettings::default());
    world.add_body(BodyDesc::fixed(
        "ground",
        ShapeDesc::HalfSpace { normal: Vec3::Y },
    ))?;
    let half = Vec3::splat(0.25);
    let boxes = (0..10)
        .map(|i| {
            let y = half.y * (2 * i + 1) as f32;
            world.add_body(
                BodyDesc::dynamic(format!("box {i}"), ShapeDesc::Cuboid { half_extents: half })
                    .at(Vec3::new(0.0, y, 0.0)),
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    // A 200 kg ball (the boxes are 125 kg each) thrown at the column's upper half at 12 m/s.
    world.add_body(
        BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.2 })
            .at(Vec3::new(-6.0, 3.0, 0.0))
            .moving(Vec3::new(12.0, 2.0, 0.0), Vec3::ZERO)
            .with_mass(200.0),
    )?;

    let dt = 1.0 / 60.0;
    for step in 0..300 {
        let report = world.step(dt)?;
        for (body, why) in &report.quarantined {
            eprintln!(
                "step {step}: {:?} quarantined: {why}",
                world.body_name(*body)
            );
        }
        for event in world.events() {
            if let CollisionEvent::Started(a, b) = event {
                let name = |h| world.body_name(h).unwrap_or("?");
                println!("step {step:3}: {} touches {}", name(*a), name(*b));
            }
        }
    }

    println!("after {:.1} s:", world.time().0);
    for (i, &h) in boxes.iter().enumerate() {
        let b = world.body(h).ok_or("a box went missing")?;
        println!(
            "  box {i}: at ({:6.2}, {:5.2}, {:5.2}), {}",
            b.position.x,
            b.position.y,
            b.position.z,
            if b.is_awake() { "awake" } else { "asleep" }
        );
    }
    Ok(())
}

#[test]
fn runs() {
    main().expect("the example runs");
}
