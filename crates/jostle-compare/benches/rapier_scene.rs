//! A jostle scene's bodies built in rapier3d 0.36 at its defaults, for the benches that run
//! both engines on the same scene (`mod rapier_scene;` by path).
//!
//! Every dynamic body becomes a rapier3d body of the same shape, pose, density and friction
//! (balls, cuboids, capsules and cylinders along +Y, convex hulls); a fixed cuboid becomes a
//! fixed cuboid; the ground half-space y ≥ 0 becomes a fixed cuboid 4,000 m wide whose top face
//! is at y = 0 (rapier3d's friction is the mean of the two sides', jostle's scenes give both
//! sides the same coefficient, so the pair's coefficient agrees). Anything else panics: the
//! bench would not be comparing the same scene.
//!
//! Not every bench uses every helper, hence the `dead_code` allowance.
#![allow(dead_code)]

use jostle::scene::Scene;
use jostle::{MassSpec, ShapeDesc};
use rapier3d::prelude as rp;

/// The scene's bodies in a rapier3d world at its defaults, with the scene's time step and
/// sleeping as the scene declares it; and the handles of its dynamic bodies, in the scene's
/// order.
pub fn rapier_world(scene: &Scene) -> (rp::PhysicsWorld, Vec<rp::RigidBodyHandle>) {
    let mut world = rp::PhysicsWorld {
        gravity: rp::Vector::new(0.0, -9.81, 0.0),
        ..Default::default()
    };
    world.integration_parameters.dt = scene.dt;
    let sleeping = scene.settings().sleep.enabled;
    let mut dynamic = Vec::new();
    for desc in scene.body_descs().expect("scene bodies") {
        let friction = desc.material.friction;
        let (p, q) = (desc.position, desc.rotation);
        let shape = match &desc.shape {
            ShapeDesc::HalfSpace { normal } if desc.fixed => {
                assert!(
                    normal.y > 0.999 && p.length() == 0.0,
                    "{}: only the ground y ≥ 0 as a half-space",
                    scene.name
                );
                world.insert(
                    rp::RigidBodyBuilder::fixed().translation(rp::Vector::new(0.0, -1.0, 0.0)),
                    rp::ColliderBuilder::cuboid(2000.0, 1.0, 2000.0).friction(friction),
                );
                continue;
            }
            ShapeDesc::Cuboid { half_extents: h } => rp::ColliderBuilder::cuboid(h.x, h.y, h.z),
            ShapeDesc::Ball { radius } => rp::ColliderBuilder::ball(*radius),
            ShapeDesc::Capsule {
                half_height,
                radius,
            } => rp::ColliderBuilder::capsule_y(*half_height, *radius),
            ShapeDesc::Cylinder {
                half_height,
                radius,
            } => rp::ColliderBuilder::cylinder(*half_height, *radius),
            ShapeDesc::ConvexHull { points } => {
                let points: Vec<_> = points
                    .iter()
                    .map(|v| rp::Vector::new(v.x, v.y, v.z))
                    .collect();
                rp::ColliderBuilder::convex_hull(&points).expect("a convex hull")
            }
            other => panic!("{}: no rapier3d counterpart for {other:?}", scene.name),
        };
        let body = if desc.fixed {
            rp::RigidBodyBuilder::fixed()
        } else {
            rp::RigidBodyBuilder::dynamic().can_sleep(sleeping)
        };
        let collider = if desc.fixed {
            shape.friction(friction)
        } else {
            let MassSpec::Density(density) = desc.mass else {
                panic!("{}: densities only", scene.name);
            };
            shape.density(density).friction(friction)
        };
        let (handle, _) = world.insert(
            body.translation(rp::Vector::new(p.x, p.y, p.z))
                .rotation(rp::Rotation::from_xyzw(q.x, q.y, q.z, q.w).to_scaled_axis()),
            collider,
        );
        if !desc.fixed {
            dynamic.push(handle);
        }
    }
    (world, dynamic)
}

/// Contact pairs with at least one point, and contact points, in rapier3d's narrow phase now.
pub fn rapier_contacts(world: &rp::PhysicsWorld) -> (usize, usize) {
    let (mut pairs, mut points) = (0, 0);
    for pair in world.narrow_phase.contact_pairs() {
        let n: usize = pair.manifolds().iter().map(|m| m.points.len()).sum();
        if n > 0 {
            pairs += 1;
            points += n;
        }
    }
    (pairs, points)
}

/// Deepest overlap (m) of any contact point in rapier3d's narrow phase now.
pub fn rapier_deepest(world: &rp::PhysicsWorld) -> f32 {
    world
        .narrow_phase
        .contact_pairs()
        .flat_map(|pair| pair.manifolds().iter())
        .flat_map(|m| m.points.iter())
        .fold(0.0f32, |d, p| d.max(-p.dist))
}

/// Dynamic bodies rapier3d has awake.
pub fn rapier_awake(world: &rp::PhysicsWorld) -> usize {
    world
        .bodies
        .iter()
        .filter(|(_, b)| b.is_dynamic() && !b.is_sleeping())
        .count()
}
