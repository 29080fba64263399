//! `BodySet`: bodies addressed by opaque generational handles, in an [`Arena`].
//!
//! Handles are `Copy` and carry a generation, so a handle to a removed body never reaches the
//! body that later reuses its slot: look-ups with a stale handle return `None`.
//! Iteration is in slot order, which is deterministic for a given sequence of inserts and
//! removals.

use crate::RigidBody;
use crate::arena::{Arena, ArenaIndex};

/// An opaque, generational, `Copy` handle to a body in a [`BodySet`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodyHandle {
    index: u32,
    generation: u32,
}

impl BodyHandle {
    /// The dense slot index (stable while the body lives); for inner loops and tables.
    #[inline]
    pub fn index(self) -> u32 {
        self.index
    }

    /// The generation of the slot when the handle was issued.
    #[inline]
    pub fn generation(self) -> u32 {
        self.generation
    }
}

impl std::fmt::Display for BodyHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "body#{}v{}", self.index, self.generation)
    }
}

/// The bodies of a world: an [`Arena`] of [`RigidBody`]s behind typed handles.
#[derive(Clone, Debug, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(transparent)
)]
pub struct BodySet {
    arena: Arena<RigidBody>,
}

impl BodyHandle {
    fn at(self) -> ArenaIndex {
        ArenaIndex {
            index: self.index,
            generation: self.generation,
        }
    }

    fn from_at(at: ArenaIndex) -> Self {
        Self {
            index: at.index,
            generation: at.generation,
        }
    }
}

impl BodySet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a body and returns its handle. Reuses the most recently freed slot.
    pub fn insert(&mut self, body: RigidBody) -> BodyHandle {
        BodyHandle::from_at(self.arena.insert(body))
    }

    /// Removes a body; `None` if the handle is stale or invalid.
    pub fn remove(&mut self, handle: BodyHandle) -> Option<RigidBody> {
        self.arena.remove(handle.at())
    }

    /// The body behind `handle`, or `None` if it is stale or invalid.
    #[inline]
    pub fn get(&self, handle: BodyHandle) -> Option<&RigidBody> {
        self.arena.get(handle.at())
    }

    /// The body behind `handle`, mutably, or `None` if it is stale or invalid.
    #[inline]
    pub fn get_mut(&mut self, handle: BodyHandle) -> Option<&mut RigidBody> {
        self.arena.get_mut(handle.at())
    }

    /// Whether `handle` names a live body.
    #[inline]
    pub fn contains(&self, handle: BodyHandle) -> bool {
        self.get(handle).is_some()
    }

    /// Number of live bodies.
    #[inline]
    pub fn len(&self) -> usize {
        self.arena.len()
    }

    /// Whether there are no bodies.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.arena.is_empty()
    }

    /// One past the largest slot index ever used: the size of a dense per-slot table.
    #[inline]
    pub fn capacity_index(&self) -> usize {
        self.arena.capacity_index()
    }

    /// Live bodies with their handles, in slot order.
    #[inline]
    pub fn iter(&self) -> impl Iterator<Item = (BodyHandle, &RigidBody)> {
        self.arena
            .iter()
            .map(|(at, b)| (BodyHandle::from_at(at), b))
    }

    /// Live bodies with their handles, mutably, in slot order.
    #[inline]
    pub fn iter_mut(&mut self) -> impl Iterator<Item = (BodyHandle, &mut RigidBody)> {
        self.arena
            .iter_mut()
            .map(|(at, b)| (BodyHandle::from_at(at), b))
    }

    /// The live body in slot `index`, with its handle.
    #[inline]
    pub fn by_index(&self, index: u32) -> Option<(BodyHandle, &RigidBody)> {
        self.arena
            .by_index(index)
            .map(|(at, b)| (BodyHandle::from_at(at), b))
    }

    /// Checks a set read back from a file (its free list and count: [`Arena::check`]).
    pub fn check(&self) -> Result<(), String> {
        self.arena.check()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_handles_find_nothing() {
        let mut set = BodySet::new();
        let a = set.insert(RigidBody::fixed());
        let b = set.insert(RigidBody::fixed());
        assert!(set.remove(a).is_some());
        assert!(set.get(a).is_none());
        assert!(set.remove(a).is_none());
        let c = set.insert(RigidBody::fixed());
        assert_eq!(c.index(), a.index());
        assert_ne!(c, a);
        assert!(set.get(a).is_none() && set.get(c).is_some() && set.get(b).is_some());
        assert_eq!(set.len(), 2);
        assert_eq!(set.iter().map(|(h, _)| h).collect::<Vec<_>>(), vec![c, b]);
    }
}
