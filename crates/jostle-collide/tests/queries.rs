//! Ray casts and shape overlap queries.

mod common;

use common::*;
use jostle_collide::{Pose, ShapeDesc, intersect_shape, ray_cast};
use jostle_math::Vec3;

fn scene() -> (
    Scene,
    jostle_body::BodyHandle,
    jostle_body::BodyHandle,
    jostle_body::BodyHandle,
) {
    let mut scene = Scene::new();
    let g = scene.fixed(&ground(), Vec3::ZERO);
    let ball = scene.dynamic(&ShapeDesc::Ball { radius: 0.5 }, Vec3::new(0.0, 2.0, 0.0));
    let cube = scene.dynamic(&unit_cube(), Vec3::new(5.0, 1.0, 0.0));
    (scene, g, ball, cube)
}

#[test]
fn ray_hits_the_nearest_surface() {
    let (s, g, ball, cube) = scene();
    let hit = ray_cast(
        &s.colliders,
        &s.bodies,
        Vec3::new(0.0, 10.0, 0.0),
        -Vec3::Y,
        100.0,
    )
    .unwrap();
    assert_eq!(hit.body, ball);
    assert!((hit.distance - 7.5).abs() < 1e-4);
    assert!((hit.point - Vec3::new(0.0, 2.5, 0.0)).length() < 1e-4);
    assert!((hit.normal - Vec3::Y).length() < 1e-4);

    // The direction need not be unit; distances are in metres along it.
    let hit = ray_cast(
        &s.colliders,
        &s.bodies,
        Vec3::new(3.0, 10.0, 0.0),
        -Vec3::Y * 4.0,
        100.0,
    )
    .unwrap();
    assert_eq!(hit.body, g);
    assert!((hit.distance - 10.0).abs() < 1e-4);

    let hit = ray_cast(
        &s.colliders,
        &s.bodies,
        Vec3::new(-5.0, 1.0, 0.0),
        Vec3::X,
        100.0,
    )
    .unwrap();
    assert_eq!(hit.body, cube);
    assert!((hit.point.x - 4.0).abs() < 1e-4);
    assert!((hit.normal + Vec3::X).length() < 1e-4);
}

#[test]
fn ray_misses_beyond_its_length_and_rejects_bad_input() {
    let (s, ..) = scene();
    assert!(
        ray_cast(
            &s.colliders,
            &s.bodies,
            Vec3::new(0.0, 10.0, 0.0),
            -Vec3::Y,
            7.0
        )
        .is_none()
    );
    assert!(
        ray_cast(
            &s.colliders,
            &s.bodies,
            Vec3::new(0.0, 10.0, 0.0),
            Vec3::Y,
            100.0
        )
        .is_none()
    );
    assert!(ray_cast(&s.colliders, &s.bodies, Vec3::ZERO, Vec3::ZERO, 1.0).is_none());
    assert!(
        ray_cast(
            &s.colliders,
            &s.bodies,
            Vec3::ZERO,
            Vec3::new(f32::NAN, 0.0, 0.0),
            1.0
        )
        .is_none()
    );
}

#[test]
fn ray_from_inside_a_solid_hits_at_zero() {
    let (s, g, ..) = scene();
    let hit = ray_cast(
        &s.colliders,
        &s.bodies,
        Vec3::new(3.0, -1.0, 0.0),
        Vec3::X,
        10.0,
    )
    .unwrap();
    assert_eq!(hit.body, g);
    assert_eq!(hit.distance, 0.0);
}

#[test]
fn overlap_lists_each_body_once_in_order() {
    let (mut s, g, ball, cube) = scene();
    let probe = ShapeDesc::Ball { radius: 1.0 }.build().unwrap();
    assert_eq!(
        intersect_shape(
            &s.colliders,
            &s.bodies,
            &probe,
            Pose::from_translation(Vec3::new(0.0, 3.0, 0.0))
        ),
        vec![ball]
    );
    assert!(
        intersect_shape(
            &s.colliders,
            &s.bodies,
            &probe,
            Pose::from_translation(Vec3::new(0.0, 4.0, 0.0))
        )
        .is_empty()
    );
    let big = ShapeDesc::Cuboid {
        half_extents: Vec3::new(10.0, 1.0, 1.0),
    }
    .build()
    .unwrap();
    let all = intersect_shape(
        &s.colliders,
        &s.bodies,
        &big,
        Pose::from_translation(Vec3::new(0.0, 1.0, 0.0)),
    );
    let mut expected = vec![g, ball, cube];
    expected.sort();
    assert_eq!(all, expected);
    // A second collider on the ball's body is still one body.
    s.colliders.insert(jostle_collide::Collider::new(
        ShapeDesc::Ball { radius: 0.3 }.build().unwrap(),
        ball,
    ));
    let all = intersect_shape(
        &s.colliders,
        &s.bodies,
        &big,
        Pose::from_translation(Vec3::new(0.0, 1.0, 0.0)),
    );
    assert_eq!(all, expected);
}
