//! Speculative contacts that grow with speed (issue 18 item 4): a body closing on another
//! faster than the prediction distance per step gets a contact as far ahead as it closes
//! within the step, so it stops at the surface instead of being found inside it a step later;
//! a body passing a face sideways gets none.

mod common;

use jostle::{BodyDesc, ResolverChoice, ShapeDesc, Vec3, World, WorldSettings};

/// Drops a box of half extent `h` at `speed` (m/s, downward, from 3h above the top) onto a box
/// of the same size resting on the ground, in zero gravity so that only the impact matters;
/// returns the deepest penetration of any contact over 60 steps (m).
fn drop_onto_box(resolver: &ResolverChoice, h: f32, speed: f32, speculative: bool) -> f32 {
    let mut settings = WorldSettings {
        gravity: Vec3::ZERO,
        resolver: resolver.clone(),
        ..Default::default()
    };
    settings.sleep.enabled = false;
    // CCD off also turns the speculative growth off (it is part of continuous collision).
    settings.collide.ccd.enabled = speculative;
    let mut world = World::new(settings);
    world
        .add_body(BodyDesc::fixed(
            "ground",
            ShapeDesc::HalfSpace { normal: Vec3::Y },
        ))
        .unwrap();
    let cube = ShapeDesc::Cuboid {
        half_extents: Vec3::splat(h),
    };
    world
        .add_body(BodyDesc::dynamic("lower", cube.clone()).at(Vec3::new(0.0, h, 0.0)))
        .unwrap();
    world
        .add_body(
            BodyDesc::dynamic("upper", cube)
                .at(Vec3::new(0.0, 6.0 * h, 0.0))
                .moving(Vec3::new(0.0, -speed, 0.0), Vec3::ZERO),
        )
        .unwrap();
    let mut deepest = 0.0f32;
    for _ in 0..60 {
        world.step(1.0 / 60.0).unwrap();
        deepest = deepest.max(world.max_penetration());
    }
    deepest
}

#[test]
fn a_fast_box_stops_at_the_surface_of_a_dynamic_box_at_any_size() {
    for resolver in common::resolvers() {
        for h in [0.25f32, 1.0, 5.0] {
            // A fifth of the box's size per step (0.1 to 2 m, beyond the 0.02 m prediction
            // distance): below CCD's sweep threshold (a quarter), so without speculative
            // growth nothing sees the impact before the boxes overlap.
            let speed = 0.2 * 2.0 * h * 60.0;
            let with = drop_onto_box(&resolver, h, speed, true);
            let without = drop_onto_box(&resolver, h, speed, false);
            println!(
                "{} h = {h} m at {speed} m/s: deepest {with:.5} m with, {without:.5} m without",
                resolver.name()
            );
            // Without, the box is found up to a step's travel (0.4·h) inside the other.
            assert!(
                without > 0.1 * h,
                "{} h = {h}: the setup must overlap without speculative contacts ({without})",
                resolver.name()
            );
            assert!(
                with < 0.02 * h + 0.005,
                "{} h = {h}: {with} m deep with speculative contacts",
                resolver.name()
            );
        }
    }
}

#[test]
fn a_fast_box_passing_beside_a_face_gets_no_contact_and_keeps_its_speed() {
    for resolver in common::resolvers() {
        let mut world = World::new(WorldSettings {
            gravity: Vec3::ZERO,
            resolver: resolver.clone(),
            ..Default::default()
        });
        let cube = ShapeDesc::Cuboid {
            half_extents: Vec3::splat(0.5),
        };
        world
            .add_body(BodyDesc::dynamic("still", cube.clone()))
            .unwrap();
        // 0.1 m beside the face x = 0.5, moving along y at 15 m/s (0.25 m per step): within
        // the grown prediction distance, but not closing.
        let passer = world
            .add_body(
                BodyDesc::dynamic("passer", cube)
                    .at(Vec3::new(1.1, -2.0, 0.0))
                    .moving(Vec3::new(0.0, 15.0, 0.0), Vec3::ZERO),
            )
            .unwrap();
        for _ in 0..20 {
            world.step(1.0 / 60.0).unwrap();
            assert!(
                world.contacts().is_empty(),
                "{}: a contact with a body not closing: {:?}",
                resolver.name(),
                world.contacts()
            );
        }
        let v = world.body(passer).unwrap().linear_velocity;
        assert_eq!(v, Vec3::new(0.0, 15.0, 0.0), "{}", resolver.name());
    }
}
