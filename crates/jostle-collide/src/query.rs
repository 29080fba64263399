//! Scene queries: the first collider hit by a ray, and the bodies overlapping a shape.
//!
//! In: the colliders and bodies at their current poses. Out: hits and body lists, in a
//! deterministic order. These run by brute force over the colliders (with a bounding-box
//! rejection before the exact test) rather than through the broad phase's tree: the tree holds
//! the boxes of the last broad-phase update, and a query made after the resolver moved the
//! bodies must see the current poses. Cost O(colliders) per query: fine for gameplay queries,
//! not for thousands per step.

use crate::collider::{ColliderHandle, ColliderSet};
use jostle_body::{BodyHandle, BodySet};
use jostle_math::Vec3;
use parry3d::bounding_volume::BoundingVolume;
use parry3d::math::Pose;
use parry3d::query::{Ray, RayCast};
use parry3d::shape::SharedShape;

/// The first surface a ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The body whose collider was hit.
    pub body: BodyHandle,
    /// The collider hit.
    pub collider: ColliderHandle,
    /// World hit point (m).
    pub point: Vec3,
    /// Unit world surface normal at the hit, facing the ray's origin side.
    pub normal: Vec3,
    /// Distance from the origin along the (normalized) direction (m).
    pub distance: f32,
}

/// Casts a ray from `origin` along `dir` (any non-zero length; it is normalized) up to
/// `max_distance` metres and returns the nearest hit. A ray starting inside a shape hits it at
/// distance 0. Ties break on the lower collider handle. `None` for a zero or non-finite
/// direction, a non-finite origin or a negative distance.
pub fn ray_cast(
    colliders: &ColliderSet,
    bodies: &BodySet,
    origin: Vec3,
    dir: Vec3,
    max_distance: f32,
) -> Option<RayHit> {
    let dir = dir.try_normalize()?;
    if !origin.is_finite() || max_distance.is_nan() || max_distance < 0.0 {
        return None;
    }
    let ray = Ray::new(origin, dir);
    let mut best: Option<RayHit> = None;
    for (handle, collider) in colliders.iter() {
        let Some(body) = bodies.get(collider.body) else {
            continue;
        };
        let pose = collider.world_pose(body);
        let limit = best.map_or(max_distance, |b| b.distance);
        if !collider.is_unbounded() {
            let aabb = collider.shape.compute_aabb(&pose);
            if !aabb.intersects_ray(&Pose::IDENTITY, &ray, limit) {
                continue;
            }
        }
        let Some(hit) = collider
            .shape
            .cast_ray_and_get_normal(&pose, &ray, limit, true)
        else {
            continue;
        };
        if best.is_none_or(|b| hit.time_of_impact < b.distance) {
            best = Some(RayHit {
                body: collider.body,
                collider: handle,
                point: ray.point_at(hit.time_of_impact),
                normal: hit.normal.normalize_or_zero(),
                distance: hit.time_of_impact,
            });
        }
    }
    best
}

/// The bodies with a collider overlapping `shape` placed at `pose`, sorted by handle, each
/// once. Pairs parry cannot test (two half-spaces) count as not overlapping.
pub fn intersect_shape(
    colliders: &ColliderSet,
    bodies: &BodySet,
    shape: &SharedShape,
    pose: Pose,
) -> Vec<BodyHandle> {
    let query_unbounded = shape.as_halfspace().is_some();
    let query_aabb = shape.compute_aabb(&pose);
    let mut hits: Vec<BodyHandle> = colliders
        .iter()
        .filter_map(|(_, collider)| {
            let body = bodies.get(collider.body)?;
            let world = collider.world_pose(body);
            if !query_unbounded
                && !collider.is_unbounded()
                && !query_aabb.intersects(&collider.shape.compute_aabb(&world))
            {
                return None;
            }
            let hit =
                parry3d::query::intersection_test(&pose, &*shape.0, &world, &*collider.shape.0)
                    .ok()?;
            hit.intersecting.then_some(collider.body)
        })
        .collect();
    hits.sort_unstable();
    hits.dedup();
    hits
}
