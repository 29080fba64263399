//! The worst-first loop shared by both passes (seed lecture, "Resolving Penetration": "at each
//! iteration, we search through the contacts to find the [worst]"), in two strategies that
//! give bit-identical results:
//! - [`run_heap`]: the worst contact is the top of an [`IndexedMaxHeap`]; after a pick only the
//!   contacts adjacent to the two changed bodies are updated and re-keyed, O(degree · log n).
//! - [`run_linear_scan`]: Cyclone's rescan of the whole island per pick, O(n).
//!
//! Both pick the largest key above epsilon with ties going to the lower contact index, and both
//! update exactly the contacts that share a changed body, each through the same
//! [`Pass::update`], so the floating-point operations are the same ones in the same order per
//! contact.

use super::change::BodyChange;
use super::islands::Islands;
use super::prepare::PreparedContact;
use super::priority_queue::IndexedMaxHeap;
use crate::SolverBody;

/// What the worst-first loops did, counted as they run (a few integer additions per pick, so
/// always on): the evidence that a heap pick costs O(degree · log n) and a rescan O(n),
/// without timing anything. Summed over both passes of a step by
/// [`super::MillingtonResolver::last_work`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PickWork {
    /// Picks made.
    pub picks: u64,
    /// Contacts updated after picks: with the heap, each contact sharing a changed body, once
    /// per pick; with the linear scan, every contact of the island per pick.
    pub updates: u64,
    /// Contacts whose key was read to choose a pick: with the heap, the updated contacts
    /// (re-keyed); with the linear scan, every contact of the island per pick.
    pub keys_read: u64,
    /// Heap entries moved by sifts during picks (the initial heapify of each island, O(n),
    /// is not counted); zero for the linear scan.
    pub heap_moves: u64,
}

impl std::ops::AddAssign for PickWork {
    fn add_assign(&mut self, other: Self) {
        self.picks += other.picks;
        self.updates += other.updates;
        self.keys_read += other.keys_read;
        self.heap_moves += other.heap_moves;
    }
}

/// One pass (position or velocity) as the worst-first loop drives it.
pub(crate) trait Pass {
    /// The contact's badness: penetration or desired velocity change; −∞ (or NaN) when the
    /// contact cannot be resolved, so it is never picked.
    fn key(&self, contact: u32) -> f32;
    /// Resolves the contact, moving its bodies; `None` if nothing could move.
    fn resolve(&mut self, contact: u32) -> Option<BodyChange>;
    /// Resolves the contact with the body on `side` held still
    /// ([`super::prepare::PreparedContact::with_side_held`]): only the other body moves.
    fn resolve_held(&mut self, contact: u32, side: usize) -> Option<BodyChange>;
    /// Updates the contact after `change` (a no-op if it shares no body with it).
    fn update(&mut self, contact: u32, change: &BodyChange);
    /// Whether the shock sweep may resolve the contact ([`super::shock`]).
    fn sweeps_held(&self, _contact: u32) -> bool {
        true
    }
    /// The contacts the pass resolves.
    fn contacts(&self) -> &[PreparedContact];
    /// The bodies the pass moves.
    fn bodies(&self) -> &[SolverBody];
}

/// Per-contact marks so a contact adjacent to both changed bodies is updated once per pick.
#[derive(Clone, Debug, Default)]
pub(crate) struct Stamps {
    marks: Vec<u32>,
    current: u32,
}

impl Stamps {
    /// Clears all marks for `contacts` contacts.
    pub(crate) fn reset(&mut self, contacts: usize) {
        self.marks.clear();
        self.marks.resize(contacts, 0);
        self.current = 0;
    }

    /// Starts a new pick: every contact becomes unmarked.
    fn next(&mut self) {
        self.current = self.current.wrapping_add(1);
        if self.current == 0 {
            self.marks.fill(0);
            self.current = 1;
        }
    }

    /// Marks `contact`; returns whether it was unmarked in this pick.
    fn mark(&mut self, contact: u32) -> bool {
        let m = &mut self.marks[contact as usize];
        let fresh = *m != self.current;
        *m = self.current;
        fresh
    }
}

/// The worst-first loops' reusable state: the heap, the update marks and the work counters.
#[derive(Clone, Debug, Default)]
pub(crate) struct PickScratch {
    pub(crate) heap: IndexedMaxHeap,
    pub(crate) stamps: Stamps,
    pub(crate) work: PickWork,
    /// The largest key any island was left with by the last [`run_islands`] (0 when none
    /// was left above 0): what the pass did not resolve, in the pass's own units.
    pub(crate) residual: f32,
}

impl PickScratch {
    /// Prepares for a step over `contacts` contacts: empties the heap, clears the marks and
    /// the counters.
    pub(crate) fn reset(&mut self, contacts: usize) {
        self.heap.reset(contacts);
        self.stamps.reset(contacts);
        self.work = PickWork::default();
    }
}

/// Calls `f` once for every contact that shares a body with `change`, in the adjacency's
/// order (a contact on both changed bodies once).
#[inline]
pub(crate) fn for_each_neighbour(
    islands: &Islands,
    stamps: &mut Stamps,
    change: &BodyChange,
    mut f: impl FnMut(u32),
) {
    stamps.next();
    for body in change.body {
        for &c in islands.contacts_of(body) {
            if stamps.mark(c) {
                f(c);
            }
        }
    }
}

/// Worst-first over one island with the indexed heap. Returns the number of picks made.
pub(crate) fn run_heap<P: Pass>(
    pass: &mut P,
    island: &[u32],
    islands: &Islands,
    scratch: &mut PickScratch,
    epsilon: f32,
    budget: u32,
) -> u32 {
    let PickScratch {
        heap,
        stamps,
        work,
        residual,
    } = scratch;
    heap.build(island, |c| pass.key(c));
    let moves_before = heap.moves();
    let mut picks = 0;
    let mut updates = 0;
    while picks < budget {
        let Some((worst, key)) = heap.peek() else {
            break;
        };
        if !(key > epsilon) {
            break;
        }
        picks += 1;
        let Some(change) = pass.resolve(worst) else {
            debug_assert!(false, "a contact with a finite key must be resolvable");
            break;
        };
        for_each_neighbour(islands, stamps, &change, |c| {
            pass.update(c, &change);
            heap.set_key(c, pass.key(c));
            updates += 1;
        });
    }
    *work += PickWork {
        picks: u64::from(picks),
        updates,
        keys_read: updates,
        heap_moves: heap.moves() - moves_before,
    };
    if let Some((_, key)) = heap.peek()
        && key > *residual
    {
        *residual = key;
    }
    picks
}

/// Worst-first over one island by rescanning it for every pick (Cyclone). Returns the number
/// of picks made.
pub(crate) fn run_linear_scan<P: Pass>(
    pass: &mut P,
    island: &[u32],
    epsilon: f32,
    budget: u32,
    work: &mut PickWork,
    residual: &mut f32,
) -> u32 {
    let mut picks = 0;
    while picks < budget {
        let mut worst = None;
        let mut max = epsilon;
        for &c in island {
            let key = pass.key(c);
            // Strict `>` over ascending indices: ties go to the lower index, as in the heap.
            if key > max {
                max = key;
                worst = Some(c);
            }
        }
        let Some(worst) = worst else { break };
        picks += 1;
        let Some(change) = pass.resolve(worst) else {
            debug_assert!(false, "a contact with a finite key must be resolvable");
            break;
        };
        for &c in island {
            pass.update(c, &change);
        }
    }
    for &c in island {
        let key = pass.key(c);
        if key > *residual {
            *residual = key;
        }
    }
    let scanned = island.len() as u64 * u64::from(picks);
    *work += PickWork {
        picks: u64::from(picks),
        updates: scanned,
        keys_read: scanned,
        heap_moves: 0,
    };
    picks
}

/// The lecture's first pass ("run through the entire list once, then prioritise"): every
/// contact of the island whose key is above `epsilon` when its turn comes is resolved once,
/// in index order, and its neighbours updated, within `budget` picks. Returns the picks made.
pub(crate) fn sweep<P: Pass>(
    pass: &mut P,
    island: &[u32],
    islands: &Islands,
    scratch: &mut PickScratch,
    epsilon: f32,
    budget: u32,
) -> u32 {
    let mut picks = 0;
    let mut updates = 0;
    for &c in island {
        if picks >= budget {
            break;
        }
        if !(pass.key(c) > epsilon) {
            continue;
        }
        picks += 1;
        let Some(change) = pass.resolve(c) else {
            continue;
        };
        for_each_neighbour(islands, &mut scratch.stamps, &change, |n| {
            pass.update(n, &change);
            updates += 1;
        });
    }
    scratch.work += PickWork {
        picks: u64::from(picks),
        updates,
        keys_read: island.len() as u64,
        heap_moves: 0,
    };
    picks
}

/// Runs one pass over every island with the chosen pick strategy, each island with its own
/// budget (with `first_sweep`, the lecture's first pass over every contact, [`sweep`],
/// before the worst-first picks, out of the same budget); returns the picks made, and leaves
/// the largest key left in [`PickScratch::residual`].
pub(crate) fn run_islands<P: Pass>(
    pass: &mut P,
    islands: &Islands,
    scratch: &mut PickScratch,
    pick: super::settings::PickStrategy,
    budget: &super::settings::IterationBudget,
    epsilon: f32,
    first_sweep: bool,
) -> u32 {
    let mut picks = 0;
    scratch.residual = 0.0;
    for i in 0..islands.len() {
        let island = islands.island(i);
        let mut budget = budget.for_contacts(island.len());
        if first_sweep {
            let swept = sweep(pass, island, islands, scratch, epsilon, budget);
            picks += swept;
            budget -= swept;
        }
        picks += match pick {
            super::settings::PickStrategy::Heap => {
                run_heap(pass, island, islands, scratch, epsilon, budget)
            }
            super::settings::PickStrategy::LinearScan => run_linear_scan(
                pass,
                island,
                epsilon,
                budget,
                &mut scratch.work,
                &mut scratch.residual,
            ),
        };
    }
    picks
}
