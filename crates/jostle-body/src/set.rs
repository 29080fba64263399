//! `BodySet`: bodies addressed by opaque generational handles.
//!
//! Handles are `Copy` and carry a generation, so a handle to a removed body never reaches the
//! body that later reuses its slot: look-ups with a stale handle return `None`.
//! Iteration is in slot order, which is deterministic for a given sequence of inserts and
//! removals.

use crate::RigidBody;

/// An opaque, generational, `Copy` handle to a body in a [`BodySet`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodyHandle {
    index: u32,
    generation: u32,
}

impl BodyHandle {
    /// The dense slot index (stable while the body lives); for inner loops and tables.
    pub fn index(self) -> u32 {
        self.index
    }

    /// The generation of the slot when the handle was issued.
    pub fn generation(self) -> u32 {
        self.generation
    }
}

impl std::fmt::Display for BodyHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "body#{}v{}", self.index, self.generation)
    }
}

#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Slot {
    generation: u32,
    body: Option<RigidBody>,
}

/// The bodies of a world.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodySet {
    slots: Vec<Slot>,
    free: Vec<u32>,
    len: usize,
}

impl BodySet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a body and returns its handle. Reuses the most recently freed slot.
    pub fn insert(&mut self, body: RigidBody) -> BodyHandle {
        self.len += 1;
        if let Some(index) = self.free.pop() {
            let slot = &mut self.slots[index as usize];
            slot.body = Some(body);
            BodyHandle {
                index,
                generation: slot.generation,
            }
        } else {
            let index = u32::try_from(self.slots.len()).expect("more than u32::MAX bodies");
            self.slots.push(Slot {
                generation: 0,
                body: Some(body),
            });
            BodyHandle {
                index,
                generation: 0,
            }
        }
    }

    /// Removes a body; `None` if the handle is stale or invalid.
    pub fn remove(&mut self, handle: BodyHandle) -> Option<RigidBody> {
        let slot = self.slots.get_mut(handle.index as usize)?;
        if slot.generation != handle.generation {
            return None;
        }
        let body = slot.body.take()?;
        slot.generation = slot.generation.wrapping_add(1);
        self.free.push(handle.index);
        self.len -= 1;
        Some(body)
    }

    /// The body behind `handle`, or `None` if it is stale or invalid.
    pub fn get(&self, handle: BodyHandle) -> Option<&RigidBody> {
        let slot = self.slots.get(handle.index as usize)?;
        (slot.generation == handle.generation)
            .then_some(slot.body.as_ref())
            .flatten()
    }

    /// The body behind `handle`, mutably, or `None` if it is stale or invalid.
    pub fn get_mut(&mut self, handle: BodyHandle) -> Option<&mut RigidBody> {
        let slot = self.slots.get_mut(handle.index as usize)?;
        (slot.generation == handle.generation)
            .then_some(slot.body.as_mut())
            .flatten()
    }

    /// Whether `handle` names a live body.
    pub fn contains(&self, handle: BodyHandle) -> bool {
        self.get(handle).is_some()
    }

    /// Number of live bodies.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are no bodies.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// One past the largest slot index ever used: the size of a dense per-slot table.
    pub fn capacity_index(&self) -> usize {
        self.slots.len()
    }

    /// Live bodies with their handles, in slot order.
    pub fn iter(&self) -> impl Iterator<Item = (BodyHandle, &RigidBody)> {
        self.slots.iter().enumerate().filter_map(|(i, s)| {
            s.body.as_ref().map(|b| {
                (
                    BodyHandle {
                        index: i as u32,
                        generation: s.generation,
                    },
                    b,
                )
            })
        })
    }

    /// Live bodies with their handles, mutably, in slot order.
    pub fn iter_mut(&mut self) -> impl Iterator<Item = (BodyHandle, &mut RigidBody)> {
        self.slots.iter_mut().enumerate().filter_map(|(i, s)| {
            let generation = s.generation;
            s.body.as_mut().map(|b| {
                (
                    BodyHandle {
                        index: i as u32,
                        generation,
                    },
                    b,
                )
            })
        })
    }

    /// The live body in slot `index`, with its handle.
    pub fn by_index(&self, index: u32) -> Option<(BodyHandle, &RigidBody)> {
        let s = self.slots.get(index as usize)?;
        s.body.as_ref().map(|b| {
            (
                BodyHandle {
                    index,
                    generation: s.generation,
                },
                b,
            )
        })
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
