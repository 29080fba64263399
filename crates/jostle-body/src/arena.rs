//! `Arena`: the one generational slot store behind every handle-addressed set of the engine
//! (bodies here, colliders in `jostle-collide`).
//!
//! Items live in a `Vec` of slots; a removed item's slot is freed and its generation bumped, so
//! a handle to it (index and generation) never reaches the item that later reuses the slot:
//! look-ups with a stale handle return `None`. Iteration is in slot order, deterministic for a
//! given sequence of inserts and removals. Per-item data belongs in the item, not in a side
//! table indexed by slot, so that removal cannot leave a table behind.

/// The raw position of an item in an [`Arena`]: its slot and the slot's generation when the
/// item was inserted. Typed handles (`BodyHandle`, `ColliderHandle`) wrap it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ArenaIndex {
    /// The slot.
    pub index: u32,
    /// The slot's generation when the item was inserted.
    pub generation: u32,
}

#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Slot<T> {
    generation: u32,
    item: Option<T>,
}

/// Items in generational slots.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Arena<T> {
    slots: Vec<Slot<T>>,
    /// Freed slots, the most recently freed last (reused first).
    free: Vec<u32>,
    len: usize,
}

impl<T> Default for Arena<T> {
    fn default() -> Self {
        Self {
            slots: Vec::new(),
            free: Vec::new(),
            len: 0,
        }
    }
}

impl<T> Arena<T> {
    /// An empty arena.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds an item and returns where it is. Reuses the most recently freed slot.
    ///
    /// # Panics
    /// With more than `u32::MAX` slots.
    pub fn insert(&mut self, item: T) -> ArenaIndex {
        self.len += 1;
        if let Some(index) = self.free.pop() {
            let slot = &mut self.slots[index as usize];
            debug_assert!(slot.item.is_none(), "a free slot is empty");
            slot.item = Some(item);
            ArenaIndex {
                index,
                generation: slot.generation,
            }
        } else {
            let index = u32::try_from(self.slots.len()).expect("more than u32::MAX items");
            self.slots.push(Slot {
                generation: 0,
                item: Some(item),
            });
            ArenaIndex {
                index,
                generation: 0,
            }
        }
    }

    /// Removes the item at `at`; `None` if `at` is stale or was never issued.
    pub fn remove(&mut self, at: ArenaIndex) -> Option<T> {
        let slot = self.slots.get_mut(at.index as usize)?;
        if slot.generation != at.generation {
            return None;
        }
        let item = slot.item.take()?;
        slot.generation = slot.generation.wrapping_add(1);
        self.free.push(at.index);
        self.len -= 1;
        Some(item)
    }

    /// The item at `at`, or `None` if `at` is stale or was never issued.
    pub fn get(&self, at: ArenaIndex) -> Option<&T> {
        let slot = self.slots.get(at.index as usize)?;
        (slot.generation == at.generation)
            .then_some(slot.item.as_ref())
            .flatten()
    }

    /// The item at `at`, mutably, or `None` if `at` is stale or was never issued.
    pub fn get_mut(&mut self, at: ArenaIndex) -> Option<&mut T> {
        let slot = self.slots.get_mut(at.index as usize)?;
        (slot.generation == at.generation)
            .then_some(slot.item.as_mut())
            .flatten()
    }

    /// The live item in slot `index`, with where it is.
    pub fn by_index(&self, index: u32) -> Option<(ArenaIndex, &T)> {
        let slot = self.slots.get(index as usize)?;
        slot.item.as_ref().map(|item| {
            (
                ArenaIndex {
                    index,
                    generation: slot.generation,
                },
                item,
            )
        })
    }

    /// Number of live items.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are no live items.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// One past the largest slot index ever used: the size of a dense per-slot scratch table.
    pub fn capacity_index(&self) -> usize {
        self.slots.len()
    }

    /// Live items with where they are, in slot order.
    pub fn iter(&self) -> impl Iterator<Item = (ArenaIndex, &T)> {
        self.slots.iter().enumerate().filter_map(|(i, slot)| {
            slot.item.as_ref().map(|item| {
                (
                    ArenaIndex {
                        index: i as u32,
                        generation: slot.generation,
                    },
                    item,
                )
            })
        })
    }

    /// Live items with where they are, mutably, in slot order.
    pub fn iter_mut(&mut self) -> impl Iterator<Item = (ArenaIndex, &mut T)> {
        self.slots.iter_mut().enumerate().filter_map(|(i, slot)| {
            let generation = slot.generation;
            slot.item.as_mut().map(|item| {
                (
                    ArenaIndex {
                        index: i as u32,
                        generation,
                    },
                    item,
                )
            })
        })
    }

    /// The same slots, generations and free list holding `f(item)`: what a snapshot stores
    /// (descriptions) turned back into what a world holds, every handle still valid. Stops at
    /// the first error, with the slot it came from.
    pub fn try_map<U, E>(
        &self,
        mut f: impl FnMut(ArenaIndex, &T) -> Result<U, E>,
    ) -> Result<Arena<U>, E> {
        let mut slots = Vec::with_capacity(self.slots.len());
        for (i, slot) in self.slots.iter().enumerate() {
            let item = match &slot.item {
                Some(item) => Some(f(
                    ArenaIndex {
                        index: i as u32,
                        generation: slot.generation,
                    },
                    item,
                )?),
                None => None,
            };
            slots.push(Slot {
                generation: slot.generation,
                item,
            });
        }
        Ok(Arena {
            slots,
            free: self.free.clone(),
            len: self.len,
        })
    }

    /// Checks an arena read back from a file: every free slot index in range, listed once and
    /// empty, every empty slot listed as free, and `len` the count of live items. A snapshot's
    /// free list naming slot 99 of 3 made the next insert panic.
    pub fn check(&self) -> Result<(), String> {
        let mut listed = vec![false; self.slots.len()];
        for (k, &index) in self.free.iter().enumerate() {
            let Some(slot) = self.slots.get(index as usize) else {
                return Err(format!(
                    "free[{k}]: slot {index} is out of range ({} slots)",
                    self.slots.len()
                ));
            };
            if slot.item.is_some() {
                return Err(format!("free[{k}]: slot {index} holds a live item"));
            }
            if std::mem::replace(&mut listed[index as usize], true) {
                return Err(format!("free[{k}]: slot {index} is listed twice"));
            }
        }
        if let Some(i) = (0..self.slots.len()).find(|&i| self.slots[i].item.is_none() && !listed[i])
        {
            return Err(format!("slots[{i}]: empty but not in the free list"));
        }
        let live = self.slots.iter().filter(|s| s.item.is_some()).count();
        if live != self.len {
            return Err(format!("len is {} but {live} slots are live", self.len));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_indices_find_nothing_and_slots_are_reused() {
        let mut arena = Arena::new();
        let a = arena.insert("a");
        let b = arena.insert("b");
        assert_eq!(arena.remove(a), Some("a"));
        assert!(arena.get(a).is_none() && arena.remove(a).is_none());
        let c = arena.insert("c");
        assert_eq!(c.index, a.index);
        assert_ne!(c, a);
        assert_eq!(arena.get(c), Some(&"c"));
        assert_eq!(arena.len(), 2);
        assert_eq!(
            arena.iter().map(|(at, s)| (at, *s)).collect::<Vec<_>>(),
            vec![(c, "c"), (b, "b")]
        );
        assert!(arena.check().is_ok());
    }

    #[test]
    fn try_map_keeps_every_index() {
        let mut arena = Arena::new();
        let a = arena.insert(1);
        let b = arena.insert(2);
        arena.remove(a);
        let mapped = arena.try_map(|_, x| Ok::<_, ()>(x * 10)).unwrap();
        assert_eq!(mapped.get(b), Some(&20));
        assert!(mapped.get(a).is_none());
        let mut mapped = mapped;
        // The freed slot is reused with the bumped generation, as in the original.
        let c = mapped.insert(30);
        assert_eq!(
            c,
            ArenaIndex {
                index: a.index,
                generation: a.generation + 1
            }
        );
    }

    #[test]
    fn check_finds_a_broken_free_list() {
        let mut arena = Arena::new();
        let a = arena.insert(1);
        arena.insert(2);
        arena.remove(a);
        let mut bad = arena.clone();
        bad.free.push(99);
        assert!(bad.check().unwrap_err().contains("out of range"));
        let mut bad = arena.clone();
        bad.free.clear();
        assert!(bad.check().unwrap_err().contains("not in the free list"));
        let mut bad = arena.clone();
        bad.free.push(1);
        assert!(bad.check().unwrap_err().contains("live item"));
        let mut bad = arena;
        bad.len = 5;
        assert!(bad.check().unwrap_err().contains("len"));
    }
}
