//! Colliders: a parry shape and a material attached to a body at a local pose, stored in a
//! [`ColliderSet`] addressed by generational [`ColliderHandle`]s.
//!
//! In: shapes built from [`crate::ShapeDesc`], the body they belong to. Out: world poses
//! (body pose × local pose) for the broad phase, narrow phase and queries. Iteration is in slot
//! order, deterministic for a given sequence of inserts and removals.

use crate::material::Material;
use jostle_body::{BodyHandle, RigidBody};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

/// A collision shape attached to a body.
#[derive(Clone)]
pub struct Collider {
    /// The shape, in the collider's frame.
    pub shape: SharedShape,
    /// Pose of the collider's frame relative to the body's centre-of-mass frame.
    pub local_pose: Pose,
    /// Surface material.
    pub material: Material,
    /// The body the collider moves with.
    pub body: BodyHandle,
}

impl std::fmt::Debug for Collider {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Collider")
            .field("shape", &self.shape.shape_type())
            .field("local_pose", &self.local_pose)
            .field("material", &self.material)
            .field("body", &self.body)
            .finish()
    }
}

impl Collider {
    /// A collider of `shape` on `body`, at the body's centre of mass, default material.
    pub fn new(shape: SharedShape, body: BodyHandle) -> Self {
        Self {
            shape,
            local_pose: Pose::IDENTITY,
            material: Material::default(),
            body,
        }
    }

    /// Sets the pose relative to the body's centre-of-mass frame (builder style).
    pub fn with_local_pose(mut self, local_pose: Pose) -> Self {
        self.local_pose = local_pose;
        self
    }

    /// Sets the material (builder style).
    pub fn with_material(mut self, material: Material) -> Self {
        self.material = material;
        self
    }

    /// The collider's world pose on `body`: body pose (centre of mass, orientation) × local pose.
    pub fn world_pose(&self, body: &RigidBody) -> Pose {
        // Most colliders sit at their body's centre of mass: skip the composition.
        if self.local_pose == Pose::IDENTITY {
            body_pose(body)
        } else {
            body_pose(body) * self.local_pose
        }
    }

    /// Whether the shape is unbounded (a half-space): it has no finite bounding box.
    pub fn is_unbounded(&self) -> bool {
        self.shape.as_halfspace().is_some()
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
    pub fn index(self) -> u32 {
        self.index
    }

    /// The generation of the slot when the handle was issued.
    pub fn generation(self) -> u32 {
        self.generation
    }
}

impl std::fmt::Display for ColliderHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "collider#{}v{}", self.index, self.generation)
    }
}

#[derive(Clone, Debug)]
struct Slot {
    generation: u32,
    collider: Option<Collider>,
}

/// The colliders of a world, in a Vec of generational slots.
#[derive(Clone, Debug, Default)]
pub struct ColliderSet {
    slots: Vec<Slot>,
    free: Vec<u32>,
    len: usize,
}

impl ColliderSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a collider and returns its handle. Reuses the most recently freed slot.
    pub fn insert(&mut self, collider: Collider) -> ColliderHandle {
        self.len += 1;
        if let Some(index) = self.free.pop() {
            let slot = &mut self.slots[index as usize];
            slot.collider = Some(collider);
            ColliderHandle {
                index,
                generation: slot.generation,
            }
        } else {
            let index = u32::try_from(self.slots.len()).expect("more than u32::MAX colliders");
            self.slots.push(Slot {
                generation: 0,
                collider: Some(collider),
            });
            ColliderHandle {
                index,
                generation: 0,
            }
        }
    }

    /// Removes a collider; `None` if the handle is stale or invalid.
    pub fn remove(&mut self, handle: ColliderHandle) -> Option<Collider> {
        let slot = self.slots.get_mut(handle.index as usize)?;
        if slot.generation != handle.generation {
            return None;
        }
        let collider = slot.collider.take()?;
        slot.generation = slot.generation.wrapping_add(1);
        self.free.push(handle.index);
        self.len -= 1;
        Some(collider)
    }

    /// Removes every collider attached to `body` (when the body is removed); returns how many.
    pub fn remove_attached(&mut self, body: BodyHandle) -> usize {
        let attached: Vec<ColliderHandle> = self
            .iter()
            .filter(|(_, c)| c.body == body)
            .map(|(h, _)| h)
            .collect();
        attached
            .iter()
            .filter(|&&h| self.remove(h).is_some())
            .count()
    }

    /// The collider behind `handle`, or `None` if it is stale or invalid.
    pub fn get(&self, handle: ColliderHandle) -> Option<&Collider> {
        let slot = self.slots.get(handle.index as usize)?;
        (slot.generation == handle.generation)
            .then_some(slot.collider.as_ref())
            .flatten()
    }

    /// The collider behind `handle`, mutably. Changing its shape or local pose is picked up by
    /// the next broad- and narrow-phase update.
    pub fn get_mut(&mut self, handle: ColliderHandle) -> Option<&mut Collider> {
        let slot = self.slots.get_mut(handle.index as usize)?;
        (slot.generation == handle.generation)
            .then_some(slot.collider.as_mut())
            .flatten()
    }

    /// The live collider in slot `index`, with its handle.
    pub fn by_index(&self, index: u32) -> Option<(ColliderHandle, &Collider)> {
        let s = self.slots.get(index as usize)?;
        s.collider.as_ref().map(|c| {
            (
                ColliderHandle {
                    index,
                    generation: s.generation,
                },
                c,
            )
        })
    }

    /// Number of live colliders.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are no colliders.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// One past the largest slot index ever used: the size of a dense per-slot table.
    pub fn capacity_index(&self) -> usize {
        self.slots.len()
    }

    /// Live colliders with their handles, in slot order.
    pub fn iter(&self) -> impl Iterator<Item = (ColliderHandle, &Collider)> {
        self.slots.iter().enumerate().filter_map(|(i, s)| {
            s.collider.as_ref().map(|c| {
                (
                    ColliderHandle {
                        index: i as u32,
                        generation: s.generation,
                    },
                    c,
                )
            })
        })
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
