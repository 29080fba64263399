//! Colliders: a parry shape and a material attached to a body at a local pose, stored in a
//! [`ColliderSet`] (an [`Arena`], the same as bodies') addressed by generational
//! [`ColliderHandle`]s.
//!
//! In: shapes built from [`crate::ShapeDesc`], the body they belong to. Out: world poses
//! (body pose × local pose) for the broad phase, narrow phase and queries. Iteration is in slot
//! order, deterministic for a given sequence of inserts and removals.

use crate::ccd::CcdShape;
use crate::display::DisplayMesh;
use crate::groups::CollisionGroups;
use crate::material::Material;
use crate::shape::{ShapeDesc, ShapeError};
use jostle_body::{Arena, ArenaIndex, BodyHandle, RigidBody};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use std::sync::OnceLock;

/// A collision shape attached to a body, with what is derived from it (CCD's thickness and
/// reach, the display mesh) and, when it was built from one, its description: everything a
/// collider needs travels with it, so removing it leaves no table behind.
#[derive(Clone)]
pub struct Collider {
    /// The shape, in the collider's frame ([`Collider::set_shape`] keeps the derived data).
    pub(crate) shape: SharedShape,
    /// Pose of the collider's frame relative to the body's centre-of-mass frame.
    pub(crate) local_pose: Pose,
    /// Surface material.
    pub material: Material,
    /// The body the collider moves with.
    pub body: BodyHandle,
    /// Which colliders it meets ([`CollisionGroups`]; default: all).
    pub groups: CollisionGroups,
    /// A sensor makes no contacts: it reports the colliders that start and stop overlapping
    /// it ([`crate::SensorEvent`]) and lets them pass. CCD and, unless they ask for them,
    /// queries ignore it.
    pub sensor: bool,
    /// Report a [`crate::ContactForceEvent`] for a step in which this collider's contacts
    /// with another push with a total normal force above this (N); `None`: never.
    pub force_event_threshold: Option<f32>,
    /// What CCD needs of the shape, computed whenever the shape or local pose is set.
    pub(crate) ccd: CcdShape,
    /// [`Collider::reach_radius`], computed whenever the shape or local pose is set.
    reach: f32,
    /// The size that decides whether the narrow phase clips the shape scaled up
    /// (`narrow_phase::clip_size`), computed whenever the shape is set.
    pub(crate) clip_size: Option<f32>,
    /// The description the shape was built from ([`Collider::from_desc`]), for snapshots.
    desc: Option<ShapeDesc>,
    /// The display mesh, built on first use.
    display: OnceLock<Option<DisplayMesh>>,
}

impl std::fmt::Debug for Collider {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Collider")
            .field("shape", &self.shape.shape_type())
            .field("local_pose", &self.local_pose)
            .field("material", &self.material)
            .field("body", &self.body)
            .field("groups", &self.groups)
            .field("sensor", &self.sensor)
            .finish()
    }
}

impl Collider {
    /// A collider of `shape` on `body`, at the body's centre of mass, default material.
    pub fn new(shape: SharedShape, body: BodyHandle) -> Self {
        let mut collider = Self {
            shape,
            local_pose: Pose::IDENTITY,
            material: Material::default(),
            body,
            groups: CollisionGroups::ALL,
            sensor: false,
            force_event_threshold: None,
            ccd: CcdShape {
                thickness: 0.0,
                extent: 0.0,
            },
            reach: 0.0,
            clip_size: None,
            desc: None,
            display: OnceLock::new(),
        };
        collider.derive();
        collider
    }

    /// A collider built from a shape description, which it keeps (snapshots rebuild it).
    pub fn from_desc(desc: &ShapeDesc, body: BodyHandle) -> Result<Self, ShapeError> {
        Ok(Self::new(desc.build()?, body).with_desc(desc.clone()))
    }

    /// Records the description the shape was built from (builder style), for snapshots.
    pub fn with_desc(mut self, desc: ShapeDesc) -> Self {
        self.desc = Some(desc);
        self
    }

    /// Sets the pose relative to the body's centre-of-mass frame (builder style).
    pub fn with_local_pose(mut self, local_pose: Pose) -> Self {
        self.set_local_pose(local_pose);
        self
    }

    /// Sets the collision groups.
    pub fn with_groups(mut self, groups: CollisionGroups) -> Self {
        self.groups = groups;
        self
    }

    /// Makes the collider a sensor (or not).
    pub fn with_sensor(mut self, sensor: bool) -> Self {
        self.sensor = sensor;
        self
    }

    /// Sets the contact force event threshold ([`Collider::force_event_threshold`]).
    pub fn with_force_event_threshold(mut self, threshold: Option<f32>) -> Self {
        self.force_event_threshold = threshold;
        self
    }

    /// Whether the collider can make contacts with `other`: neither is a sensor and their
    /// groups meet.
    #[inline]
    pub fn touches(&self, other: &Collider) -> bool {
        !self.sensor && !other.sensor && self.groups.meets(&other.groups)
    }

    /// Sets the material (builder style).
    pub fn with_material(mut self, material: Material) -> Self {
        self.material = material;
        self
    }

    /// The shape, in the collider's frame.
    #[inline]
    pub fn shape(&self) -> &SharedShape {
        &self.shape
    }

    /// The pose relative to the body's centre-of-mass frame.
    #[inline]
    pub fn local_pose(&self) -> Pose {
        self.local_pose
    }

    /// The description the shape was built from, if it was built from one.
    pub fn desc(&self) -> Option<&ShapeDesc> {
        self.desc.as_ref()
    }

    /// What CCD needs of the shape (thickness and reach about the centre of mass).
    #[inline]
    pub fn ccd_shape(&self) -> &CcdShape {
        &self.ccd
    }

    /// Replaces the shape (its description is forgotten); picked up by the next broad- and
    /// narrow-phase update.
    pub fn set_shape(&mut self, shape: SharedShape) {
        self.shape = shape;
        self.desc = None;
        self.derive();
    }

    /// Moves the collider on its body; picked up by the next broad- and narrow-phase update.
    pub fn set_local_pose(&mut self, local_pose: Pose) {
        self.local_pose = local_pose;
        self.derive();
    }

    /// The display mesh in the body's frame (built once, on first use); `None` for shapes
    /// without one (half-spaces).
    pub fn display(&self) -> Option<&DisplayMesh> {
        self.display.get_or_init(|| self.display_mesh()).as_ref()
    }

    /// Recomputes what is derived from the shape and local pose.
    fn derive(&mut self) {
        self.ccd = CcdShape::of(self);
        self.reach = if self.is_unbounded() {
            f32::INFINITY
        } else {
            let sphere = self.shape.compute_bounding_sphere(&self.local_pose);
            sphere.center.length() + sphere.radius
        };
        self.clip_size = crate::narrow_phase::clip_size(&*self.shape.0);
        self.display = OnceLock::new();
    }

    /// The collider's world pose on `body`: body pose (centre of mass, orientation) × local pose.
    #[inline]
    pub fn world_pose(&self, body: &RigidBody) -> Pose {
        // Most colliders sit at their body's centre of mass: skip the composition.
        if self.local_pose == Pose::IDENTITY {
            body_pose(body)
        } else {
            body_pose(body) * self.local_pose
        }
    }

    /// Whether the shape is unbounded (a half-space): it has no finite bounding box.
    #[inline]
    pub fn is_unbounded(&self) -> bool {
        self.shape.as_halfspace().is_some()
    }

    /// The farthest any point of the shape lies from its body's centre of mass (m): how far
    /// a turn of one radian can move a point of it. Infinite for an unbounded shape.
    #[inline]
    pub fn reach_radius(&self) -> f32 {
        self.reach
    }

    /// How far a turn of `body` at its current angular velocity can move a point of this
    /// collider in `dt` seconds (m): |ω|·[`Collider::reach_radius`]·dt; zero for a body that
    /// does not turn (an unbounded collider is always on a fixed body).
    #[inline]
    pub fn turn_reach(&self, body: &RigidBody, dt: f32) -> f32 {
        let spin = body.angular_velocity.length();
        if spin > 0.0 {
            spin * self.reach_radius() * dt
        } else {
            0.0
        }
    }
}

/// The pose of a body's centre-of-mass frame.
pub fn body_pose(body: &RigidBody) -> Pose {
    Pose::from_parts(body.position, body.orientation)
}

/// An opaque, generational, `Copy` handle to a collider in a [`ColliderSet`].
/// Ordered by slot index, then generation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ColliderHandle {
    index: u32,
    generation: u32,
}

impl ColliderHandle {
    pub(crate) fn new(index: u32, generation: u32) -> Self {
        Self { index, generation }
    }

    /// The dense slot index (stable while the collider lives).
    #[inline]
    pub fn index(self) -> u32 {
        self.index
    }

    /// The generation of the slot when the handle was issued.
    #[inline]
    pub fn generation(self) -> u32 {
        self.generation
    }

    /// Where the collider is in its set's [`Arena`].
    #[inline]
    pub fn arena_index(self) -> ArenaIndex {
        ArenaIndex {
            index: self.index,
            generation: self.generation,
        }
    }

    /// The handle of the collider at `at` of a set's [`Arena`].
    #[inline]
    pub fn from_arena_index(at: ArenaIndex) -> Self {
        Self::new(at.index, at.generation)
    }
}

impl std::fmt::Display for ColliderHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "collider#{}v{}", self.index, self.generation)
    }
}

/// The colliders of a world: an [`Arena`] of [`Collider`]s behind typed handles.
#[derive(Clone, Debug, Default)]
pub struct ColliderSet {
    arena: Arena<Collider>,
}

impl ColliderSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// The colliders of an arena (a snapshot's, rebuilt), every handle kept.
    pub fn from_arena(arena: Arena<Collider>) -> Self {
        Self { arena }
    }

    /// The colliders' arena, read-only (to store or map it whole).
    pub fn arena(&self) -> &Arena<Collider> {
        &self.arena
    }

    /// Adds a collider and returns its handle. Reuses the most recently freed slot.
    pub fn insert(&mut self, collider: Collider) -> ColliderHandle {
        ColliderHandle::from_arena_index(self.arena.insert(collider))
    }

    /// Removes a collider; `None` if the handle is stale or invalid.
    pub fn remove(&mut self, handle: ColliderHandle) -> Option<Collider> {
        self.arena.remove(handle.arena_index())
    }

    /// The colliders attached to `body`, in slot order.
    pub fn attached(&self, body: BodyHandle) -> Vec<ColliderHandle> {
        self.iter()
            .filter(|(_, c)| c.body == body)
            .map(|(h, _)| h)
            .collect()
    }

    /// Removes every collider attached to `body` (when the body is removed); returns how many.
    pub fn remove_attached(&mut self, body: BodyHandle) -> usize {
        self.attached(body)
            .into_iter()
            .filter(|&h| self.remove(h).is_some())
            .count()
    }

    /// The collider behind `handle`, or `None` if it is stale or invalid.
    #[inline]
    pub fn get(&self, handle: ColliderHandle) -> Option<&Collider> {
        self.arena.get(handle.arena_index())
    }

    /// The collider behind `handle`, mutably. Changing its shape or local pose (through its
    /// setters) is picked up by the next broad- and narrow-phase update.
    #[inline]
    pub fn get_mut(&mut self, handle: ColliderHandle) -> Option<&mut Collider> {
        self.arena.get_mut(handle.arena_index())
    }

    /// The live collider in slot `index`, with its handle.
    #[inline]
    pub fn by_index(&self, index: u32) -> Option<(ColliderHandle, &Collider)> {
        self.arena
            .by_index(index)
            .map(|(at, c)| (ColliderHandle::from_arena_index(at), c))
    }

    /// Number of live colliders.
    #[inline]
    pub fn len(&self) -> usize {
        self.arena.len()
    }

    /// Whether there are no colliders.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.arena.is_empty()
    }

    /// One past the largest slot index ever used: the size of a dense per-slot table.
    #[inline]
    pub fn capacity_index(&self) -> usize {
        self.arena.capacity_index()
    }

    /// Live colliders with their handles, in slot order.
    #[inline]
    pub fn iter(&self) -> impl Iterator<Item = (ColliderHandle, &Collider)> {
        self.arena
            .iter()
            .map(|(at, c)| (ColliderHandle::from_arena_index(at), c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jostle_body::BodySet;
    use jostle_math::{Quat, Vec3};

    #[test]
    fn handles_are_generational_and_order_is_slot_order() {
        let mut bodies = BodySet::new();
        let b = bodies.insert(RigidBody::fixed());
        let mut set = ColliderSet::new();
        let c0 = set.insert(Collider::new(SharedShape::ball(1.0), b));
        let c1 = set.insert(Collider::new(SharedShape::ball(2.0), b));
        assert!(set.remove(c0).is_some());
        assert!(set.get(c0).is_none() && set.remove(c0).is_none());
        let c2 = set.insert(Collider::new(SharedShape::ball(3.0), b));
        assert_eq!(c2.index(), c0.index());
        assert_ne!(c2, c0);
        assert_eq!(set.iter().map(|(h, _)| h).collect::<Vec<_>>(), vec![c2, c1]);
        assert_eq!(set.remove_attached(b), 2);
        assert!(set.is_empty());
    }

    #[test]
    fn world_pose_is_body_pose_times_local_pose() {
        let body = RigidBody::fixed().with_pose(
            Vec3::new(1.0, 2.0, 3.0),
            Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
        );
        let mut bodies = BodySet::new();
        let h = bodies.insert(body.clone());
        let c = Collider::new(SharedShape::ball(1.0), h)
            .with_local_pose(Pose::from_translation(Vec3::X));
        // The local +X offset is rotated to +Y by the body's quarter turn about Z.
        let p = c.world_pose(&body).translation;
        assert!((p - Vec3::new(1.0, 3.0, 3.0)).length() < 1e-6, "{p}");
    }
}
