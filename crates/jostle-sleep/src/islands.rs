//! Islands: bodies joined by touching contacts, never through fixed bodies.
//!
//! Found afresh each step with a union-find over the awake bodies' slot indices, so island
//! ids are deterministic (an island's id is the smallest slot index in it). Sleeping islands
//! are remembered as member lists so that waking one body wakes all of them.

use crate::{SleepSettings, motion};
use jostle_body::{BodyHandle, BodySet};

/// Union-find over dense indices with path halving and union by smaller root (deterministic:
/// the root of a set is always its smallest index).
#[derive(Clone, Debug, Default)]
pub struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` singleton sets.
    pub fn new(n: usize) -> Self {
        let mut uf = Self::default();
        uf.reset(n);
        uf
    }

    /// Back to `n` singleton sets, keeping the allocation.
    pub fn reset(&mut self, n: usize) {
        self.parent.clear();
        self.parent.extend(0..n as u32);
    }

    /// The root (smallest index) of `i`'s set.
    pub fn find(&mut self, mut i: u32) -> u32 {
        while self.parent[i as usize] != i {
            let p = self.parent[i as usize];
            self.parent[i as usize] = self.parent[p as usize];
            i = p;
        }
        i
    }

    /// Joins the sets of `a` and `b`.
    pub fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.parent[hi as usize] = lo;
        }
    }
}

/// Islands of the current step and the sleeping islands of earlier steps.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct IslandSet {
    /// For each body slot: the sleeping island it belongs to (index into `sleeping`), if any.
    sleeping_of: Vec<Option<u32>>,
    /// Member lists of sleeping islands; `None` once woken (ids are reused after compaction).
    sleeping: Vec<Option<Vec<BodyHandle>>>,
    /// Number of awake islands found by the last [`IslandSet::update`].
    awake_islands: usize,
    /// Working arrays of [`IslandSet::update`], kept only to reuse their allocations.
    #[cfg_attr(feature = "serde", serde(skip))]
    scratch: Scratch,
}

/// The working arrays of one [`IslandSet::update`].
#[derive(Clone, Debug, Default)]
struct Scratch {
    uf: UnionFind,
    /// By root slot: every member qualifies.
    all_qualify: Vec<bool>,
    /// By slot: a root of an awake island.
    is_root: Vec<bool>,
    /// The awake bodies and their roots, in slot order.
    awake: Vec<(BodyHandle, u32)>,
    /// By root slot: its index in `new_islands`.
    island_of_root: Vec<Option<usize>>,
    /// The islands going to sleep: root and members.
    new_islands: Vec<(u32, Vec<BodyHandle>)>,
}

/// `v` as `n` copies of `value`, keeping its allocation.
fn refill<T: Clone>(v: &mut Vec<T>, n: usize, value: T) {
    v.clear();
    v.resize(n, value);
}

impl IslandSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Islands of awake bodies found by the last update.
    pub fn awake_islands(&self) -> usize {
        self.awake_islands
    }

    /// Sleeping islands currently remembered.
    pub fn sleeping_islands(&self) -> usize {
        self.sleeping.iter().filter(|s| s.is_some()).count()
    }

    /// Wakes `handle` and, if it sleeps in an island, every body of that island. Returns
    /// whether anything woke.
    pub fn wake(
        &mut self,
        bodies: &mut BodySet,
        handle: BodyHandle,
        settings: &SleepSettings,
    ) -> bool {
        let Some(body) = bodies.get_mut(handle) else {
            return false;
        };
        if body.is_fixed() || body.sleep.awake {
            return false;
        }
        let island = self
            .sleeping_of
            .get(handle.index() as usize)
            .copied()
            .flatten();
        match island.and_then(|i| self.sleeping.get_mut(i as usize).and_then(Option::take)) {
            Some(members) => {
                for m in members {
                    if let Some(b) = bodies.get_mut(m) {
                        motion::wake(b, settings);
                    }
                    if let Some(slot) = self.sleeping_of.get_mut(m.index() as usize) {
                        *slot = None;
                    }
                }
            }
            None => motion::wake(body, settings),
        }
        true
    }

    /// Checks the set's references, as a snapshot file may break them: every body slot's
    /// sleeping island exists, lies within `body_slots` slots, and lists that body; every
    /// member of a sleeping island is a slot below `body_slots`. The error says what is
    /// wrong, by slot and island.
    pub fn check(&self, body_slots: usize) -> Result<(), String> {
        if self.sleeping_of.len() > body_slots {
            return Err(format!(
                "sleeping_of has {} entries for {body_slots} body slots",
                self.sleeping_of.len()
            ));
        }
        for (slot, island) in self.sleeping_of.iter().enumerate() {
            let Some(i) = *island else { continue };
            match self.sleeping.get(i as usize) {
                Some(Some(members)) if members.iter().any(|m| m.index() as usize == slot) => {}
                Some(Some(_)) => {
                    return Err(format!("body slot {slot}: island {i} does not list it"));
                }
                _ => return Err(format!("body slot {slot}: no sleeping island {i}")),
            }
        }
        for (i, members) in self.sleeping.iter().enumerate() {
            for m in members.iter().flatten() {
                if m.index() as usize >= body_slots {
                    return Err(format!(
                        "island {i}: member slot {} of {body_slots}",
                        m.index()
                    ));
                }
            }
        }
        Ok(())
    }

    /// Forgets everything about sleeping islands except per-body membership of sleeping bodies
    /// (for a body removed from the world).
    pub fn forget(&mut self, handle: BodyHandle) {
        if let Some(slot) = self.sleeping_of.get_mut(handle.index() as usize)
            && let Some(i) = slot.take()
            && let Some(Some(members)) = self.sleeping.get_mut(i as usize)
        {
            members.retain(|&m| m != handle);
        }
    }

    /// After a step: finds the islands of awake bodies joined by `touching` pairs (pairs that
    /// involve a fixed or kinematic body are ignored: islands never join through static
    /// geometry or a moving platform, and such bodies are never put to sleep here), and puts
    /// to sleep every island whose bodies all `qualifies` (a slot-indexed table, typically from
    /// [`crate::update_motion`]). Returns the number of bodies put to sleep.
    pub fn update(
        &mut self,
        bodies: &mut BodySet,
        touching: impl IntoIterator<Item = (BodyHandle, BodyHandle)>,
        qualifies: &[bool],
    ) -> usize {
        let n = bodies.capacity_index();
        self.sleeping_of.resize(n, None);
        let Scratch {
            uf,
            all_qualify,
            is_root,
            awake,
            island_of_root,
            new_islands,
        } = &mut self.scratch;
        uf.reset(n);
        for (a, b) in touching {
            // Fixed and kinematic bodies never join islands.
            let awake = |h: BodyHandle| {
                bodies
                    .get(h)
                    .is_some_and(|b| b.is_awake() && !b.is_immovable())
            };
            if awake(a) && awake(b) {
                uf.union(a.index(), b.index());
            }
        }
        // all_qualify[root] = every member qualifies.
        refill(all_qualify, n, true);
        refill(is_root, n, false);
        awake.clear();
        awake.extend(
            bodies
                .iter()
                .filter(|(_, b)| b.is_awake() && !b.is_immovable())
                .map(|(h, _)| (h, uf.find(h.index()))),
        );
        for &(h, root) in awake.iter() {
            is_root[root as usize] = true;
            if !qualifies.get(h.index() as usize).copied().unwrap_or(false) {
                all_qualify[root as usize] = false;
            }
        }
        self.awake_islands = is_root.iter().filter(|&&r| r).count();
        // Group sleeping islands in slot order (deterministic).
        new_islands.clear();
        refill(island_of_root, n, None);
        for &(h, root) in awake.iter() {
            if all_qualify[root as usize] {
                let idx = *island_of_root[root as usize].get_or_insert_with(|| {
                    new_islands.push((root, Vec::new()));
                    new_islands.len() - 1
                });
                new_islands[idx].1.push(h);
            }
        }
        let mut slept = 0;
        for (_, members) in new_islands.drain(..) {
            let id = match self.sleeping.iter().position(|s| s.is_none()) {
                Some(free) => free,
                None => {
                    self.sleeping.push(None);
                    self.sleeping.len() - 1
                }
            };
            for &m in &members {
                if let Some(b) = bodies.get_mut(m) {
                    motion::sleep(b);
                }
                self.sleeping_of[m.index() as usize] = Some(id as u32);
            }
            slept += members.len();
            self.sleeping[id] = Some(members);
        }
        slept
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jostle_body::RigidBody;
    use jostle_math::Mat3;

    fn dynamic() -> RigidBody {
        RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap()
    }

    #[test]
    fn union_find_roots_are_smallest_indices() {
        let mut uf = UnionFind::new(6);
        uf.union(5, 3);
        uf.union(3, 4);
        uf.union(1, 2);
        assert_eq!(uf.find(5), 3);
        assert_eq!(uf.find(4), 3);
        assert_eq!(uf.find(2), 1);
        assert_eq!(uf.find(0), 0);
    }

    #[test]
    fn islands_sleep_as_a_unit_and_never_join_through_fixed_bodies() {
        let mut bodies = BodySet::new();
        let ground = bodies.insert(RigidBody::fixed());
        let a = bodies.insert(dynamic());
        let b = bodies.insert(dynamic());
        let c = bodies.insert(dynamic());
        let mut islands = IslandSet::new();
        // a–b touch; both touch the ground; c touches only the ground. a and c qualify, b not.
        let touching = [(a, b), (a, ground), (b, ground), (c, ground)];
        let mut q = vec![false; bodies.capacity_index()];
        q[a.index() as usize] = true;
        q[c.index() as usize] = true;
        let slept = islands.update(&mut bodies, touching, &q);
        assert_eq!(slept, 1, "only c's island sleeps");
        assert_eq!(islands.awake_islands(), 2);
        assert!(!bodies.get(c).unwrap().sleep.awake);
        assert!(bodies.get(a).unwrap().sleep.awake && bodies.get(b).unwrap().sleep.awake);

        q[b.index() as usize] = true;
        assert_eq!(islands.update(&mut bodies, touching, &q), 2);
        // Waking a wakes b (same island) but not c.
        let s = SleepSettings::default();
        assert!(islands.wake(&mut bodies, a, &s));
        assert!(bodies.get(b).unwrap().sleep.awake);
        assert!(!bodies.get(c).unwrap().sleep.awake);
        assert_eq!(bodies.get(b).unwrap().sleep.motion, 2.0 * s.threshold);
        assert_eq!(islands.sleeping_islands(), 1);
    }
}
