//! Scene queries as a game uses them: a character probes the ground below it with a ray, finds
//! how far it can walk before a wall with a shape cast, and lists what lies within reach, each
//! query skipping the character's own body.
//!
//! Run: `cargo run --release --example queries`

use jostle::{BodyDesc, Pose, QueryFilter, ShapeDesc, Vec3, World, WorldSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new(WorldSettings::default());
    world.add_body(BodyDesc::fixed(
        "ground",
        ShapeDesc::HalfSpace { normal: Vec3::Y },
    ))?;
    world.add_body(
        BodyDesc::fixed(
            "wall",
            ShapeDesc::Cuboid {
                half_extents: Vec3::new(0.2, 2.0, 5.0),
            },
        )
        .at(Vec3::new(6.0, 2.0, 0.0)),
    )?;
    for i in 0..5 {
        world.add_body(
            BodyDesc::dynamic(
                format!("crate {i}"),
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.3),
                },
            )
            .at(Vec3::new(1.0 + i as f32, 0.3, 1.5)),
        )?;
    }
    let player = world.add_body(
        BodyDesc::dynamic(
            "player",
            ShapeDesc::Capsule {
                half_height: 0.5,
                radius: 0.3,
            },
        )
        .at(Vec3::new(0.0, 0.8, 0.0))
        .with_locked_rotation(),
    )?;
    for _ in 0..60 {
        world.step(1.0 / 60.0)?;
    }
    // Once per step, before the queries: they then run through the broad phase's tree.
    world.update_queries();
    let queries = world.queries();
    let not_me = QueryFilter::excluding(player);
    let at = world.body(player).ok_or("no player")?.position;

    // Ground below the player's feet.
    if let Some(hit) = queries.ray_cast(at, -Vec3::Y, 10.0, &not_me) {
        let name = world.body_name(hit.body).unwrap_or("?");
        println!(
            "ground: {name} {:.3} m below the centre, normal {}",
            hit.distance, hit.normal
        );
    }

    // How far can the player's capsule move along +x before it touches something?
    let capsule = ShapeDesc::Capsule {
        half_height: 0.5,
        radius: 0.3,
    }
    .build()?;
    let pose = Pose::from_translation(at + Vec3::new(0.0, 0.05, 0.0));
    match queries.cast_shape(&capsule, pose, Vec3::X, 20.0, &not_me) {
        Some(hit) => println!(
            "walking +x: stops after {:.3} m at {} (slide along {})",
            hit.distance,
            world.body_name(hit.body).unwrap_or("?"),
            hit.normal
        ),
        None => println!("walking +x: free for 20 m"),
    }

    // Everything a ray along +z at crate height passes through, nearest first.
    for hit in queries.ray_cast_all(Vec3::new(3.0, 0.3, -5.0), Vec3::Z, 20.0, &not_me) {
        println!(
            "ray along z meets {} at {:.2} m",
            world.body_name(hit.body).unwrap_or("?"),
            hit.distance
        );
    }

    // What lies within 2 m of the player (a sphere overlap), and the nearest surface.
    let reach = ShapeDesc::Ball { radius: 2.0 }.build()?;
    let near: Vec<_> = queries
        .intersect_shape(&reach, Pose::from_translation(at), &not_me)
        .into_iter()
        .filter_map(|b| world.body_name(b))
        .collect();
    println!("within 2 m: {near:?}");
    if let Some(p) = queries.project_point(
        at,
        5.0,
        &QueryFilter {
            skip_fixed: true,
            ..not_me
        },
    ) {
        println!(
            "nearest movable surface: {} at {:.3} m",
            world.body_name(p.body).unwrap_or("?"),
            p.distance
        );
    }
    Ok(())
}

#[test]
fn runs() {
    main().expect("the example runs");
}
