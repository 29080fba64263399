//! Scene queries: rays (first hit and all hits), shape casts, point projection and shape
//! overlap, each with a [`QueryFilter`].
//!
//! In: the colliders and bodies at their current poses and, optionally, a broad phase whose
//! tree is current for those poses ([`crate::BroadPhase::refresh`]). Out: hits in a
//! deterministic order (ties between equal distances go to the lower collider handle).
//!
//! [`Queries`] runs each query through the broad phase's tree when it has one: a ray descends
//! only into boxes it enters before the best hit so far, a point projection only into boxes
//! nearer than the nearest surface so far, an overlap or a shape cast only into boxes its
//! (swept) box touches; half-spaces, which the tree does not hold, are tested directly.
//! Without a tree ([`Queries::brute_force`]) every collider is tested, with a bounding-box
//! rejection first: the same results (tested), at O(colliders) per query. The tree holds the
//! boxes of the last update or refresh, so it may only be used while nothing moved since:
//! `jostle::World` keeps track of that and falls back to the brute force when it is stale.

use crate::broad_phase::BroadPhase;
use crate::collider::{Collider, ColliderHandle, ColliderSet};
use crate::groups::CollisionGroups;
use jostle_body::{BodyHandle, BodySet, RigidBody};
use jostle_math::Vec3;
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::query::{PointQuery, Ray, RayCast, ShapeCastOptions};
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

/// The nearest surface point to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointHit {
    /// The body whose collider holds the nearest point.
    pub body: BodyHandle,
    /// That collider.
    pub collider: ColliderHandle,
    /// The nearest point on the collider's surface (m, world).
    pub point: Vec3,
    /// Distance from the query point to `point` (m); 0 when `inside`.
    pub distance: f32,
    /// Whether the query point is inside the collider (solid shapes).
    pub inside: bool,
}

/// Where a cast shape first touches a collider.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeHit {
    /// The body whose collider was hit.
    pub body: BodyHandle,
    /// The collider hit.
    pub collider: ColliderHandle,
    /// Distance travelled along the (normalized) direction before touching (m); 0 when the
    /// shape starts overlapping the collider.
    pub distance: f32,
    /// The contact point on the collider at that time (m, world).
    pub point: Vec3,
    /// The collider's outward unit normal there (m, world): the direction a character
    /// controller slides along.
    pub normal: Vec3,
}

/// Which colliders a query considers. The default considers all.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueryFilter {
    /// Skip this body's colliders (the querying character itself).
    pub exclude_body: Option<BodyHandle>,
    /// Skip colliders of fixed bodies.
    pub skip_fixed: bool,
    /// Skip colliders of bodies that can move (awake or asleep).
    pub skip_dynamic: bool,
    /// Also report sensors ([`crate::Collider::sensor`]); skipped by default.
    pub include_sensors: bool,
    /// Only colliders whose groups meet these ([`CollisionGroups::meets`]); `None`: any.
    pub groups: Option<CollisionGroups>,
}

impl QueryFilter {
    /// A filter that skips `body`'s colliders and keeps every other.
    pub fn excluding(body: BodyHandle) -> Self {
        Self {
            exclude_body: Some(body),
            ..Self::default()
        }
    }

    /// Whether `collider`, on `body`, passes.
    pub fn accepts_collider(&self, collider: &Collider, body: &RigidBody) -> bool {
        (self.include_sensors || !collider.sensor)
            && self.groups.is_none_or(|g| g.meets(&collider.groups))
            && self.accepts(collider.body, body)
    }

    /// Whether a collider of `handle`'s `body` passes (the body tests only).
    pub fn accepts(&self, handle: BodyHandle, body: &RigidBody) -> bool {
        let skipped = if body.is_fixed() {
            self.skip_fixed
        } else {
            self.skip_dynamic
        };
        self.exclude_body != Some(handle) && !skipped
    }
}

/// The scene queries over `colliders` and `bodies`, through a broad phase's tree or by brute
/// force (module docs).
#[derive(Clone, Copy)]
pub struct Queries<'a> {
    colliders: &'a ColliderSet,
    bodies: &'a BodySet,
    tree: Option<&'a BroadPhase>,
}

impl std::fmt::Debug for Queries<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Queries")
            .field("colliders", &self.colliders.len())
            .field("tree", &self.tree.is_some())
            .finish()
    }
}

/// A collider that passed the filter, at its current world pose.
struct Candidate<'a> {
    handle: ColliderHandle,
    collider: &'a Collider,
    pose: Pose,
}

impl<'a> Queries<'a> {
    /// Queries through `broad`'s tree, which must be current for the colliders' poses: last
    /// [`BroadPhase::update`]d or [`BroadPhase::refresh`]ed with nothing moved or added since.
    pub fn with_tree(
        colliders: &'a ColliderSet,
        bodies: &'a BodySet,
        broad: &'a BroadPhase,
    ) -> Self {
        Self {
            colliders,
            bodies,
            tree: Some(broad),
        }
    }

    /// Queries that test every collider (a bounding-box rejection first).
    pub fn brute_force(colliders: &'a ColliderSet, bodies: &'a BodySet) -> Self {
        Self {
            colliders,
            bodies,
            tree: None,
        }
    }

    /// The collider `handle` if it is live and passes `filter`, at its world pose.
    fn candidate(&self, handle: ColliderHandle, filter: &QueryFilter) -> Option<Candidate<'a>> {
        let collider = self.colliders.get(handle)?;
        let body = self.bodies.get(collider.body)?;
        filter.accepts_collider(collider, body).then(|| Candidate {
            handle,
            collider,
            pose: collider.world_pose(body),
        })
    }

    /// Calls `f` on every collider passing `filter` that `node_test` cannot rule out: through
    /// the tree, descending into the boxes `node_test` accepts (half-spaces always tested,
    /// first);
    /// by brute force, on every collider whose own box `node_test` accepts (half-spaces
    /// always). `node_test` may read state that `f` changes (a best distance): both are
    /// given the same `&mut S`.
    fn walk<S>(
        &self,
        filter: &QueryFilter,
        state: &mut S,
        node_test: impl Fn(&S, &Aabb) -> bool,
        mut f: impl FnMut(&mut S, Candidate<'a>),
    ) {
        match self.tree {
            Some(broad) => {
                // Half-spaces first: a ground found early bounds the search in the tree.
                for h in broad.unbounded_colliders() {
                    if let Some(c) = self.candidate(h, filter) {
                        f(state, c);
                    }
                }
                broad.traverse(|aabb, leaf| {
                    if !node_test(state, aabb) {
                        return false;
                    }
                    if let Some(c) = leaf.and_then(|h| self.candidate(h, filter)) {
                        f(state, c);
                    }
                    true
                });
            }
            None => {
                for (h, _) in self.colliders.iter() {
                    let Some(c) = self.candidate(h, filter) else {
                        continue;
                    };
                    if !c.collider.is_unbounded()
                        && !node_test(state, &c.collider.shape.compute_aabb(&c.pose))
                    {
                        continue;
                    }
                    f(state, c);
                }
            }
        }
    }

    /// The nearest surface a ray from `origin` along `dir` (any non-zero length; it is
    /// normalized) meets within `max_distance` metres. A ray starting inside a solid shape hits
    /// it at distance 0. `None` for a zero or non-finite direction, a non-finite origin or a
    /// negative distance.
    pub fn ray_cast(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_distance: f32,
        filter: &QueryFilter,
    ) -> Option<RayHit> {
        let ray = checked_ray(origin, dir, max_distance)?;
        let mut best: (f32, Option<RayHit>) = (max_distance, None);
        self.walk(
            filter,
            &mut best,
            |best, aabb| aabb.intersects_local_ray(&ray, best.0),
            |best, c| {
                if let Some(hit) = ray_hit(&c, &ray, best.0)
                    && best.1.is_none_or(|b| {
                        hit.distance < b.distance
                            || (hit.distance == b.distance && hit.collider < b.collider)
                    })
                {
                    *best = (hit.distance, Some(hit));
                }
            },
        );
        best.1
    }

    /// Every collider a ray meets within `max_distance` metres (its first surface point each),
    /// nearest first (ties by collider handle). Same conventions as [`Queries::ray_cast`].
    pub fn ray_cast_all(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_distance: f32,
        filter: &QueryFilter,
    ) -> Vec<RayHit> {
        let Some(ray) = checked_ray(origin, dir, max_distance) else {
            return Vec::new();
        };
        let mut hits = Vec::new();
        self.walk(
            filter,
            &mut hits,
            |_, aabb| aabb.intersects_local_ray(&ray, max_distance),
            |hits, c| hits.extend(ray_hit(&c, &ray, max_distance)),
        );
        hits.sort_by(|a, b| {
            a.distance
                .total_cmp(&b.distance)
                .then(a.collider.cmp(&b.collider))
        });
        hits
    }

    /// The surface point nearest to `point` within `max_distance` metres. A point inside a
    /// solid shape is its own projection (`inside`, distance 0). `None` for a non-finite point
    /// or a negative distance, or when nothing is that near.
    pub fn project_point(
        &self,
        point: Vec3,
        max_distance: f32,
        filter: &QueryFilter,
    ) -> Option<PointHit> {
        if !point.is_finite() || max_distance.is_nan() || max_distance < 0.0 {
            return None;
        }
        let mut best: (f32, Option<PointHit>) = (max_distance, None);
        self.walk(
            filter,
            &mut best,
            |best, aabb| aabb.distance_to_local_point(point, true) <= best.0,
            |best, c| {
                let proj = c.collider.shape.project_point(&c.pose, point, true);
                let distance = if proj.is_inside {
                    0.0
                } else {
                    proj.point.distance(point)
                };
                let better = best.1.is_none_or(|b| {
                    distance < b.distance || (distance == b.distance && c.handle < b.collider)
                });
                if distance <= best.0 && better {
                    *best = (
                        distance,
                        Some(PointHit {
                            body: c.collider.body,
                            collider: c.handle,
                            point: proj.point,
                            distance,
                            inside: proj.is_inside,
                        }),
                    );
                }
            },
        );
        best.1
    }

    /// The bodies with a collider overlapping `shape` placed at `pose`, sorted by handle, each
    /// once. Pairs parry cannot test (two half-spaces) count as not overlapping.
    pub fn intersect_shape(
        &self,
        shape: &SharedShape,
        pose: Pose,
        filter: &QueryFilter,
    ) -> Vec<BodyHandle> {
        let unbounded = shape.as_halfspace().is_some();
        let query_aabb = shape.compute_aabb(&pose);
        let mut hits = Vec::new();
        self.walk(
            filter,
            &mut hits,
            |_, aabb| unbounded || query_aabb.intersects(aabb),
            |hits, c| {
                let hit = parry3d::query::intersection_test(
                    &pose,
                    &*shape.0,
                    &c.pose,
                    &*c.collider.shape.0,
                );
                if hit.is_ok_and(|h| h.intersecting) {
                    hits.push(c.collider.body);
                }
            },
        );
        hits.sort_unstable();
        hits.dedup();
        hits
    }

    /// Moves `shape` from `pose` along `dir` (any non-zero length; it is normalized) up to
    /// `max_distance` metres without turning, and returns the first collider it touches. A
    /// shape that starts overlapping a collider hits it at distance 0. `None` for a zero or
    /// non-finite direction, a non-finite pose, a negative distance or an unbounded shape.
    pub fn cast_shape(
        &self,
        shape: &SharedShape,
        pose: Pose,
        dir: Vec3,
        max_distance: f32,
        filter: &QueryFilter,
    ) -> Option<ShapeHit> {
        let dir = dir.try_normalize()?;
        if !(pose.translation.is_finite() && pose.rotation.is_finite())
            || max_distance.is_nan()
            || max_distance < 0.0
            || shape.as_halfspace().is_some()
        {
            return None;
        }
        let start = shape.compute_aabb(&pose);
        let swept = start.merged(&Aabb::new(
            start.mins + dir * max_distance,
            start.maxs + dir * max_distance,
        ));
        let mut best: Option<ShapeHit> = None;
        self.walk(
            filter,
            &mut best,
            |_, aabb| swept.intersects(aabb),
            |best, c| {
                let limit = best.map_or(max_distance, |b| b.distance);
                let options = ShapeCastOptions {
                    max_time_of_impact: limit,
                    stop_at_penetration: true,
                    compute_impact_geometry_on_penetration: true,
                    ..ShapeCastOptions::default()
                };
                let Ok(Some(hit)) = parry3d::query::cast_shapes(
                    &pose,
                    dir,
                    &*shape.0,
                    &c.pose,
                    Vec3::ZERO,
                    &*c.collider.shape.0,
                    options,
                ) else {
                    return;
                };
                let distance = hit.time_of_impact;
                let better = best.is_none_or(|b| {
                    distance < b.distance || (distance == b.distance && c.handle < b.collider)
                });
                if distance <= limit && better {
                    *best = Some(ShapeHit {
                        body: c.collider.body,
                        collider: c.handle,
                        distance,
                        // The witnesses are in each shape's local frame.
                        point: c.pose * hit.witness2,
                        normal: (c.pose.rotation * hit.normal2).normalize_or_zero(),
                    });
                }
            },
        );
        best
    }
}

/// The ray of a query, or `None` for a zero or non-finite direction, a non-finite origin or
/// a negative (or NaN) distance.
fn checked_ray(origin: Vec3, dir: Vec3, max_distance: f32) -> Option<Ray> {
    let dir = dir.try_normalize()?;
    if !origin.is_finite() || max_distance.is_nan() || max_distance < 0.0 {
        return None;
    }
    Some(Ray::new(origin, dir))
}

/// `c`'s first surface point along `ray` within `limit`.
fn ray_hit(c: &Candidate<'_>, ray: &Ray, limit: f32) -> Option<RayHit> {
    let hit = c
        .collider
        .shape
        .cast_ray_and_get_normal(&c.pose, ray, limit, true)?;
    Some(RayHit {
        body: c.collider.body,
        collider: c.handle,
        point: ray.point_at(hit.time_of_impact),
        normal: hit.normal.normalize_or_zero(),
        distance: hit.time_of_impact,
    })
}

/// The first collider hit by a ray, by brute force ([`Queries::ray_cast`] with no filter).
pub fn ray_cast(
    colliders: &ColliderSet,
    bodies: &BodySet,
    origin: Vec3,
    dir: Vec3,
    max_distance: f32,
) -> Option<RayHit> {
    Queries::brute_force(colliders, bodies).ray_cast(
        origin,
        dir,
        max_distance,
        &QueryFilter::default(),
    )
}

/// The bodies overlapping `shape` at `pose`, by brute force ([`Queries::intersect_shape`]
/// with no filter).
pub fn intersect_shape(
    colliders: &ColliderSet,
    bodies: &BodySet,
    shape: &SharedShape,
    pose: Pose,
) -> Vec<BodyHandle> {
    Queries::brute_force(colliders, bodies).intersect_shape(shape, pose, &QueryFilter::default())
}
