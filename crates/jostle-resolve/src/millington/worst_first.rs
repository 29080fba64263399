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
use super::priority_queue::IndexedMaxHeap;

/// One pass (position or velocity) as the worst-first loop drives it.
pub(crate) trait Pass {
    /// The contact's badness: penetration or desired velocity change; −∞ (or NaN) when the
    /// contact cannot be resolved, so it is never picked.
    fn key(&self, contact: u32) -> f32;
    /// Resolves the contact, moving its bodies; `None` if nothing could move.
    fn resolve(&mut self, contact: u32) -> Option<BodyChange>;
    /// Updates the contact after `change` (a no-op if it shares no body with it).
    fn update(&mut self, contact: u32, change: &BodyChange);
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

/// Worst-first over one island with the indexed heap. Returns the number of picks made.
pub(crate) fn run_heap<P: Pass>(
    pass: &mut P,
    island: &[u32],
    islands: &Islands,
    heap: &mut IndexedMaxHeap,
    stamps: &mut Stamps,
    epsilon: f32,
    budget: u32,
) -> u32 {
    heap.build(island, |c| pass.key(c));
    let mut picks = 0;
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
        stamps.next();
        for body in change.body {
            for &c in islands.contacts_of(body) {
                if stamps.mark(c) {
                    pass.update(c, &change);
                    heap.set_key(c, pass.key(c));
                }
            }
        }
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
    picks
}

/// Runs one pass over every island with the chosen pick strategy, each island with its own
/// budget; returns the picks made.
pub(crate) fn run_islands<P: Pass>(
    pass: &mut P,
    islands: &Islands,
    heap: &mut IndexedMaxHeap,
    stamps: &mut Stamps,
    pick: super::settings::PickStrategy,
    budget: &super::settings::IterationBudget,
    epsilon: f32,
) -> u32 {
    let mut picks = 0;
    for i in 0..islands.len() {
        let island = islands.island(i);
        let budget = budget.for_contacts(island.len());
        picks += match pick {
            super::settings::PickStrategy::Heap => {
                run_heap(pass, island, islands, heap, stamps, epsilon, budget)
            }
            super::settings::PickStrategy::LinearScan => {
                run_linear_scan(pass, island, epsilon, budget)
            }
        };
    }
    picks
}
