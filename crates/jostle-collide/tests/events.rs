//! Started / stopped touching events.

mod common;

use common::*;
use jostle_collide::{CollisionEvent, ShapeDesc};
use jostle_math::Vec3;

#[test]
fn started_and_stopped() {
    let mut scene = Scene::new();
    let ground_body = scene.fixed(&ground(), Vec3::ZERO);
    let ball = scene.dynamic(&ShapeDesc::Ball { radius: 0.5 }, Vec3::new(0.0, 0.6, 0.0));
    let pair = (ground_body.min(ball), ground_body.max(ball));
    scene.step();
    assert!(scene.narrow.events().is_empty(), "10 cm apart: no contact");

    scene.move_by(ball, Vec3::new(0.0, -0.11, 0.0));
    scene.step();
    assert_eq!(
        scene.narrow.events(),
        &[CollisionEvent::Started(pair.0, pair.1)]
    );

    scene.step();
    assert!(
        scene.narrow.events().is_empty(),
        "still touching: no new event"
    );

    // 1 cm above: a speculative contact (negative penetration) is not touching.
    scene.move_by(ball, Vec3::new(0.0, 0.02, 0.0));
    scene.step();
    assert_eq!(scene.contacts().len(), 1);
    assert!(scene.contacts()[0].penetration < 0.0);
    assert_eq!(
        scene.narrow.events(),
        &[CollisionEvent::Stopped(pair.0, pair.1)]
    );

    scene.move_by(ball, Vec3::new(0.0, 3.0, 0.0));
    scene.step();
    assert!(scene.narrow.events().is_empty());
}

#[test]
fn falling_asleep_does_not_stop_a_contact_but_removal_does() {
    let mut scene = Scene::new();
    let ground_body = scene.fixed(&ground(), Vec3::ZERO);
    let ball = scene.dynamic(&ShapeDesc::Ball { radius: 0.5 }, Vec3::new(0.0, 0.49, 0.0));
    let pair = (ground_body.min(ball), ground_body.max(ball));
    scene.step();
    assert_eq!(
        scene.narrow.events(),
        &[CollisionEvent::Started(pair.0, pair.1)]
    );
    scene.bodies.get_mut(ball).unwrap().sleep.awake = false;
    let stats = scene.step();
    assert_eq!(
        stats.candidate_pairs, 0,
        "sleeping–static pairs are not candidates"
    );
    assert!(
        scene.narrow.events().is_empty(),
        "sleeping is not separating"
    );
    scene.bodies.get_mut(ball).unwrap().sleep.awake = true;
    scene.step();
    assert!(
        scene.narrow.events().is_empty(),
        "waking up in contact is not a new contact"
    );
    scene.bodies.remove(ball);
    scene.step();
    assert_eq!(
        scene.narrow.events(),
        &[CollisionEvent::Stopped(pair.0, pair.1)]
    );
}

#[test]
fn several_colliders_of_one_body_pair_give_one_event() {
    let mut scene = Scene::new();
    let ground_body = scene.fixed(&ground(), Vec3::ZERO);
    let ball = scene.dynamic(&ShapeDesc::Ball { radius: 0.5 }, Vec3::new(0.0, 0.49, 0.0));
    let second =
        jostle_collide::Collider::new(ShapeDesc::Ball { radius: 0.5 }.build().unwrap(), ball)
            .with_local_pose(jostle_collide::Pose::from_translation(Vec3::X));
    scene.colliders.insert(second);
    scene.step();
    assert_eq!(scene.contacts().len(), 2);
    assert_eq!(
        scene.narrow.events(),
        &[CollisionEvent::Started(
            ground_body.min(ball),
            ground_body.max(ball)
        )]
    );
}
