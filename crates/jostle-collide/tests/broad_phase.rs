//! The broad phase against brute force, and its pair filters.

mod common;

use common::*;
use jostle_body::{BodyHandle, BodySet, RigidBody};
use jostle_collide::parry3d::bounding_volume::{Aabb, BoundingVolume};
use jostle_collide::{BroadPhase, Collider, ColliderPair, ColliderSet, Pose, ShapeDesc};
use jostle_math::{Mat3, Quat, Vec3};

struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    fn vec(&mut self) -> Vec3 {
        Vec3::new(self.unit(), self.unit(), self.unit())
    }
}

/// Every pair of colliders whose enlarged boxes overlap (half-spaces by their plane),
/// filtered as the broad phase promises, by testing all n² pairs.
fn brute_force(colliders: &ColliderSet, bodies: &BodySet, margin: f32) -> Vec<ColliderPair> {
    let items: Vec<_> = colliders
        .iter()
        .filter_map(|(h, c)| {
            let body = bodies.get(c.body)?;
            let pose = c.world_pose(body);
            let plane = c
                .shape()
                .as_halfspace()
                .map(|hs| (pose, pose.rotation * hs.normal));
            Some((
                h,
                c.body,
                body.is_awake(),
                plane,
                c.shape().compute_aabb(&pose).loosened(margin),
            ))
        })
        .collect();
    let overlap = |plane: Option<(Pose, Vec3)>, aabb: &Aabb| {
        let (pose, n) = plane.unwrap();
        n.dot(aabb.center() - pose.translation) - n.abs().dot(aabb.half_extents()) <= margin
    };
    let mut pairs = Vec::new();
    for (i, a) in items.iter().enumerate() {
        for b in &items[i + 1..] {
            if a.1 == b.1 || !(a.2 || b.2) {
                continue;
            }
            let hit = match (a.3, b.3) {
                (Some(_), Some(_)) => true,
                (Some(_), None) => overlap(a.3, &b.4),
                (None, Some(_)) => overlap(b.3, &a.4),
                (None, None) => a.4.intersects(&b.4),
            };
            if hit {
                pairs.push(ColliderPair::new(a.0, b.0));
            }
        }
    }
    pairs.sort();
    pairs
}

#[test]
fn agrees_with_brute_force_on_random_scenes() {
    let mut rng = Rng(42);
    let mut bodies = BodySet::new();
    let mut colliders = ColliderSet::new();
    let mut handles: Vec<BodyHandle> = Vec::new();
    let side = 2.0 * 1000f32.cbrt();
    for i in 0..1000 {
        let fixed = i % 10 == 0;
        let body = if fixed {
            RigidBody::fixed()
        } else {
            RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap()
        };
        let q = Quat::from_rotation_y(rng.unit() * 6.0) * Quat::from_rotation_x(rng.unit() * 6.0);
        let mut body = body.with_pose(rng.vec() * side, q);
        body.sleep.awake = i % 5 != 1; // 20 % sleeping
        let h = bodies.insert(body);
        handles.push(h);
        let desc = match i % 4 {
            0 => ShapeDesc::Cuboid {
                half_extents: rng.vec() * 0.5 + 0.1,
            },
            1 => ShapeDesc::Ball {
                radius: rng.unit() * 0.5 + 0.1,
            },
            2 => ShapeDesc::Capsule {
                half_height: rng.unit() * 0.5 + 0.1,
                radius: 0.2,
            },
            _ => ShapeDesc::Cylinder {
                half_height: rng.unit() * 0.5 + 0.1,
                radius: 0.3,
            },
        };
        colliders.insert(Collider::new(desc.build().unwrap(), h));
        if i % 50 == 3 {
            // A second collider on the same body, overlapping the first: never a pair.
            colliders.insert(Collider::new(SharedShapeBall::make(0.4), h));
        }
    }
    // A fixed ground through the bottom of the volume, and a tilted fixed wall.
    let ground_body =
        bodies.insert(RigidBody::fixed().with_pose(Vec3::new(0.0, 1.0, 0.0), Quat::IDENTITY));
    colliders.insert(Collider::new(ground().build().unwrap(), ground_body));
    let wall = bodies
        .insert(RigidBody::fixed().with_pose(Vec3::new(1.5, 0.0, 0.0), Quat::from_rotation_z(1.2)));
    colliders.insert(Collider::new(
        ShapeDesc::HalfSpace { normal: Vec3::X }.build().unwrap(),
        wall,
    ));

    let margin = 0.05;
    let mut bp = BroadPhase::new();
    let mut total = 0;
    // Twelve updates: the broad phase keeps its candidate pairs between updates and repairs
    // them around the leaves that changed, so later steps check that repair.
    for step in 0..12 {
        let pairs = bp.update(&colliders, &bodies, margin).to_vec();
        let expected = brute_force(&colliders, &bodies, margin);
        assert_eq!(pairs.len(), expected.len(), "step {step}");
        assert_eq!(pairs, expected, "step {step}");
        total += pairs.len();
        // Move the awake bodies (some far, past the fat boxes), wake and put some to sleep,
        // remove a few colliders and add new ones.
        for (k, &h) in handles.iter().enumerate() {
            let b = bodies.get_mut(h).unwrap();
            if b.is_awake() {
                let scale = if k % 7 == 0 { 1.0 } else { 0.03 };
                b.position += (rng.vec() - 0.5) * scale;
                b.orientation = (b.orientation * Quat::from_rotation_z(0.05)).normalize();
            }
            if k % 97 == step {
                b.sleep.awake = !b.sleep.awake;
            }
        }
        let victims: Vec<_> = colliders
            .iter()
            .filter(|(h, _)| h.index() as usize % 131 == step)
            .map(|(h, _)| h)
            .collect();
        for v in victims {
            colliders.remove(v);
        }
        // Steps 4–7 run mostly asleep (the broad phase then queries from the awake bodies and
        // lets its cached pairs go stale); step 8 wakes everything, so the cache is repaired
        // after the changes that piled up.
        if step == 3 {
            for (k, &h) in handles.iter().enumerate() {
                bodies.get_mut(h).unwrap().sleep.awake = k % 10 == 0;
            }
        }
        if step == 7 {
            for &h in &handles {
                bodies.get_mut(h).unwrap().sleep.awake = true;
            }
        }
        let h = handles[step * 7 % handles.len()];
        colliders.insert(Collider::new(SharedShapeBall::make(0.3), h));
    }
    assert!(
        total > 1000,
        "the scene must have plenty of pairs, got {total}"
    );
}

struct SharedShapeBall;
impl SharedShapeBall {
    fn make(r: f32) -> jostle_collide::SharedShape {
        jostle_collide::SharedShape::ball(r)
    }
}

#[test]
fn pair_filters() {
    let mut scene = Scene::new();
    let cube = unit_cube();
    // Overlapping fixed bodies: never a pair.
    scene.fixed(&cube, Vec3::ZERO);
    scene.fixed(&cube, Vec3::new(0.5, 0.0, 0.0));
    // Two sleeping bodies overlapping each other and a fixed one.
    let s1 = scene.dynamic(&cube, Vec3::new(10.0, 0.0, 0.0));
    let s2 = scene.dynamic(&cube, Vec3::new(10.5, 0.0, 0.0));
    scene.fixed(&cube, Vec3::new(10.0, -1.5, 0.0));
    for s in [s1, s2] {
        scene.bodies.get_mut(s).unwrap().sleep.awake = false;
    }
    assert!(
        scene
            .broad
            .update(&scene.colliders, &scene.bodies, 0.0)
            .is_empty()
    );
    // An awake body touching both sleeping ones and the fixed one: three pairs.
    let awake = scene.dynamic(&cube, Vec3::new(11.5, -1.0, 0.0));
    let pairs = scene
        .broad
        .update(&scene.colliders, &scene.bodies, 0.0)
        .to_vec();
    assert_eq!(pairs.len(), 3, "{pairs:?}");
    let bodies_of = |colliders: &ColliderSet, p: &ColliderPair| {
        (
            colliders.get(p.0).unwrap().body,
            colliders.get(p.1).unwrap().body,
        )
    };
    for p in &pairs {
        assert!(p.0 < p.1);
        let (a, b) = bodies_of(&scene.colliders, p);
        assert!(a == awake || b == awake);
    }
    // A second collider on the awake body: no pair with itself.
    scene
        .colliders
        .insert(jostle_collide::Collider::new(cube.build().unwrap(), awake));
    let pairs = scene
        .broad
        .update(&scene.colliders, &scene.bodies, 0.0)
        .to_vec();
    assert_eq!(pairs.len(), 6, "{pairs:?}");
    for p in &pairs {
        let (a, b) = bodies_of(&scene.colliders, p);
        assert_ne!(a, b);
    }
}

#[test]
fn margin_widens_the_test() {
    let mut scene = Scene::new();
    scene.dynamic(&ShapeDesc::Ball { radius: 0.5 }, Vec3::ZERO);
    scene.dynamic(&ShapeDesc::Ball { radius: 0.5 }, Vec3::new(1.1, 0.0, 0.0));
    assert!(
        scene
            .broad
            .update(&scene.colliders, &scene.bodies, 0.04)
            .is_empty()
    );
    assert_eq!(
        scene
            .broad
            .update(&scene.colliders, &scene.bodies, 0.06)
            .len(),
        1
    );
}

#[test]
fn a_swept_box_covers_the_step_of_a_fast_body() {
    let mut scene = Scene::new();
    scene.dynamic(&ShapeDesc::Ball { radius: 0.5 }, Vec3::ZERO);
    let fast = scene.dynamic(&ShapeDesc::Ball { radius: 0.5 }, Vec3::new(2.0, 0.0, 0.0));
    // 30 m/s toward the other ball: 0.5 m per step of 1/60 s, enough to close the 1 m gap
    // only over two steps; at 90 m/s (1.5 m) within one.
    for (speed, pairs) in [(30.0, 0), (90.0, 1)] {
        scene.bodies.get_mut(fast).unwrap().linear_velocity = Vec3::new(-speed, 0.0, 0.0);
        let swept = scene
            .broad
            .update_swept(&scene.colliders, &scene.bodies, 0.02, 1.0 / 60.0)
            .len();
        assert_eq!(swept, pairs, "{speed} m/s");
        // Unswept, the boxes are apart.
        let plain = scene
            .broad
            .update(&scene.colliders, &scene.bodies, 0.02)
            .len();
        assert_eq!(plain, 0, "{speed} m/s");
    }
    // Moving away, the swept box grows away from the other ball: no pair.
    scene.bodies.get_mut(fast).unwrap().linear_velocity = Vec3::new(90.0, 0.0, 0.0);
    let away = scene
        .broad
        .update_swept(&scene.colliders, &scene.bodies, 0.02, 1.0 / 60.0)
        .len();
    assert_eq!(away, 0);
}

#[test]
fn a_sleeping_body_costs_no_pair_with_the_ground() {
    let mut scene = Scene::new();
    scene.fixed(&ground(), Vec3::ZERO);
    let ball = scene.dynamic(&ShapeDesc::Ball { radius: 0.5 }, Vec3::new(0.0, 0.49, 0.0));
    assert_eq!(
        scene
            .broad
            .update(&scene.colliders, &scene.bodies, 0.02)
            .len(),
        1
    );
    scene.bodies.get_mut(ball).unwrap().sleep.awake = false;
    assert!(
        scene
            .broad
            .update(&scene.colliders, &scene.bodies, 0.02)
            .is_empty()
    );
}

/// A packed grid of resting (awake, unmoving) boxes that three boxes sweep through, one small
/// step at a time: the broad phase repairs its cached pairs only around the leaves that
/// changed, and must still agree with brute force at every step; then most of the grid falls
/// asleep for a while (the broad phase queries from the awake boxes and its cache goes stale)
/// and wakes again.
#[test]
fn cached_pairs_follow_a_few_moving_bodies() {
    let mut bodies = BodySet::new();
    let mut colliders = ColliderSet::new();
    let cube = ShapeDesc::Cuboid {
        half_extents: Vec3::splat(0.5),
    };
    let mut grid = Vec::new();
    for x in 0..12 {
        for z in 0..12 {
            let body = RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap().with_pose(
                Vec3::new(x as f32 * 1.01, 0.0, z as f32 * 1.01),
                Quat::IDENTITY,
            );
            let h = bodies.insert(body);
            colliders.insert(Collider::new(cube.build().unwrap(), h));
            grid.push(h);
        }
    }
    let movers: Vec<BodyHandle> = (0..3)
        .map(|k| {
            let body = RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap().with_pose(
                Vec3::new(-1.0, 0.3 * k as f32, 2.0 + 3.5 * k as f32),
                Quat::IDENTITY,
            );
            let h = bodies.insert(body);
            colliders.insert(Collider::new(cube.build().unwrap(), h));
            h
        })
        .collect();
    let margin = 0.02;
    let mut bp = BroadPhase::new();
    let mut moving_pairs = 0;
    for step in 0..160 {
        let pairs = bp.update(&colliders, &bodies, margin).to_vec();
        assert_eq!(
            pairs,
            brute_force(&colliders, &bodies, margin),
            "step {step}"
        );
        moving_pairs += pairs.len();
        for (k, &h) in movers.iter().enumerate() {
            let b = bodies.get_mut(h).unwrap();
            b.position += Vec3::new(0.09, 0.0, 0.01 * k as f32);
        }
        if step == 60 || step == 100 {
            let awake = step == 100;
            for (k, &h) in grid.iter().enumerate() {
                bodies.get_mut(h).unwrap().sleep.awake = awake || k % 17 == 0;
            }
        }
    }
    assert!(moving_pairs > 160 * 200, "{moving_pairs}");
}
