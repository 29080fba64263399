//! An indexed max-heap: items are dense `u32` ids (contact indices), each with an `f32`
//! key that can be raised or lowered in O(log n) because the heap keeps every item's position.
//!
//! This is what turns Cyclone's O(n) "find the worst contact" rescan into an O(log n) pick
//! (benches/RESULTS.md, "Resolver picks"). The order is total and stable: a larger key wins, and on equal
//! keys the **lower id** wins, which is exactly the choice a front-to-back linear scan with a
//! strict `>` makes; that is what lets [`super::PickStrategy::Heap`] and
//! [`super::PickStrategy::LinearScan`] give bit-identical results. NaN keys are stored as −∞, so
//! a non-finite contact is never picked and never breaks the heap order.
//!
//! The heap is 4-ary and stores each key next to its item: half the depth of a binary heap,
//! and a sift reads one contiguous array (issue 4's measurement: heap entries moved per pick
//! on a 16,384-contact random pile fell from 24.5 to 14.1, L1 misses per pick from 10.0 to
//! 5.9). The shape changes only the work, never which item is on top, since the order is
//! total.
//!
//! It depends on nothing but `std`.

const ABSENT: u32 = u32::MAX;

/// Children per node. A 4-ary heap is half as deep as a binary one, and a node's four
/// children (8 bytes each) are adjacent, so a level of a sift down reads at most two cache
/// lines.
const ARITY: usize = 4;

/// One heap slot: the key stored next to its item, so comparisons along a sift read the heap
/// array alone (no indirection through a per-item key array).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    key: f32,
    item: u32,
}

impl Entry {
    /// Whether `self` belongs above `other`: larger key, then lower id.
    #[inline]
    fn above(self, other: Entry) -> bool {
        self.key > other.key || (self.key == other.key && self.item < other.item)
    }
}

/// Indexed max-heap over item ids `0..capacity` (see the module docs for the order).
#[derive(Clone, Debug, Default)]
pub struct IndexedMaxHeap {
    /// Heap array of (key, item); `heap[0]` is the maximum, the children of slot i are
    /// `ARITY·i + 1 ..= ARITY·i + ARITY`.
    heap: Vec<Entry>,
    /// Position of each item in `heap`, or `ABSENT`.
    pos: Vec<u32>,
    /// Entries moved by sifts since the heap was created (a cheap work counter for tests and
    /// benchmarks: it is what grows with log n).
    moves: u64,
}

impl IndexedMaxHeap {
    /// An empty heap.
    pub fn new() -> Self {
        Self::default()
    }

    /// Empties the heap and makes room for ids `0..capacity`. O(capacity) only when growing;
    /// clearing touches just the items that were present.
    pub fn reset(&mut self, capacity: usize) {
        for e in &self.heap {
            self.pos[e.item as usize] = ABSENT;
        }
        self.heap.clear();
        if self.pos.len() < capacity {
            self.pos.resize(capacity, ABSENT);
        }
    }

    /// Replaces the contents with `items` (distinct ids below the capacity given to
    /// [`Self::reset`]), keyed by `key`, in O(n) (bottom-up heapify).
    pub fn build(&mut self, items: &[u32], mut key: impl FnMut(u32) -> f32) {
        let capacity = self.pos.len();
        self.reset(capacity);
        for &item in items {
            let i = item as usize;
            debug_assert!(i < self.pos.len(), "heap item {item} beyond capacity");
            debug_assert!(self.pos[i] == ABSENT, "heap item {item} inserted twice");
            self.pos[i] = self.heap.len() as u32;
            self.heap.push(Entry {
                key: sanitize(key(item)),
                item,
            });
        }
        if self.heap.len() > 1 {
            for i in (0..=(self.heap.len() - 2) / ARITY).rev() {
                self.sift_down(i);
            }
        }
    }

    /// Number of items present.
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    /// Whether the heap is empty.
    pub fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }

    /// Whether `item` is present.
    pub fn contains(&self, item: u32) -> bool {
        self.pos.get(item as usize).is_some_and(|&p| p != ABSENT)
    }

    /// The maximum item and its key, without removing it.
    #[inline]
    pub fn peek(&self) -> Option<(u32, f32)> {
        self.heap.first().map(|e| (e.item, e.key))
    }

    /// Entries moved by sift operations since the heap was created: a work counter (each
    /// move is one level of a sift), for tests and benchmarks.
    pub fn moves(&self) -> u64 {
        self.moves
    }

    /// Changes the key of a present item and restores the heap order; absent items are
    /// ignored (debug-asserted).
    #[inline]
    pub fn set_key(&mut self, item: u32, key: f32) {
        let Some(&p) = self.pos.get(item as usize) else {
            debug_assert!(false, "heap item {item} beyond capacity");
            return;
        };
        if p == ABSENT {
            debug_assert!(false, "heap item {item} is not present");
            return;
        }
        let p = p as usize;
        let old = self.heap[p].key;
        let new = sanitize(key);
        self.heap[p].key = new;
        if new > old {
            self.sift_up(p);
        } else if new < old {
            self.sift_down(p);
        }
    }

    #[inline]
    fn place(&mut self, i: usize, e: Entry) {
        self.heap[i] = e;
        self.pos[e.item as usize] = i as u32;
    }

    fn sift_up(&mut self, mut i: usize) {
        let e = self.heap[i];
        let start = i;
        while i > 0 {
            let parent = (i - 1) / ARITY;
            let p = self.heap[parent];
            if !e.above(p) {
                break;
            }
            self.place(i, p);
            self.moves += 1;
            i = parent;
        }
        if i != start {
            self.place(i, e);
        }
    }

    fn sift_down(&mut self, mut i: usize) {
        let n = self.heap.len();
        let e = self.heap[i];
        let start = i;
        loop {
            let first = ARITY * i + 1;
            if first >= n {
                break;
            }
            let mut child = first;
            let mut best = self.heap[first];
            for c in first + 1..(first + ARITY).min(n) {
                let candidate = self.heap[c];
                if candidate.above(best) {
                    child = c;
                    best = candidate;
                }
            }
            if !best.above(e) {
                break;
            }
            self.place(i, best);
            self.moves += 1;
            i = child;
        }
        if i != start {
            self.place(i, e);
        }
    }

    /// Checks the heap order and the position index (tests and debug builds).
    #[cfg(test)]
    fn is_valid(&self) -> bool {
        (0..self.heap.len()).all(|i| {
            let e = self.heap[i];
            let parent_ok = i == 0 || !e.above(self.heap[(i - 1) / ARITY]);
            parent_ok && self.pos[e.item as usize] == i as u32
        })
    }
}

/// NaN sorts as −∞ so the order stays total.
#[inline]
fn sanitize(key: f32) -> f32 {
    if key.is_nan() { f32::NEG_INFINITY } else { key }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The maximum by (key desc, id asc), found the slow way.
    fn naive_max(keys: &[f32], present: &[u32]) -> Option<(u32, f32)> {
        let mut best: Option<(u32, f32)> = None;
        for &i in present {
            let k = sanitize(keys[i as usize]);
            if best.is_none_or(|(bi, bk)| k > bk || (k == bk && i < bi)) {
                best = Some((i, k));
            }
        }
        best
    }

    #[test]
    fn matches_a_naive_scan_under_random_updates() {
        let mut seed = 7u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let n = 200usize;
        let mut keys: Vec<f32> = (0..n).map(|_| (rnd() % 16) as f32).collect();
        let present: Vec<u32> = (0..n as u32).filter(|i| i % 3 != 1).collect();
        let mut heap = IndexedMaxHeap::new();
        heap.reset(n);
        heap.build(&present, |i| keys[i as usize]);
        assert!(heap.is_valid());
        for step in 0..5000 {
            let item = present[(rnd() % present.len() as u64) as usize];
            // Few distinct keys, so ties are frequent and the id tie-break is exercised.
            let key = match rnd() % 20 {
                0 => f32::NAN,
                1 => f32::NEG_INFINITY,
                r => (r % 16) as f32,
            };
            keys[item as usize] = key;
            heap.set_key(item, key);
            assert!(heap.is_valid(), "heap order broken at step {step}");
            assert_eq!(heap.peek(), naive_max(&keys, &present), "step {step}");
        }
    }

    #[test]
    fn equal_keys_pick_the_lowest_id() {
        let mut heap = IndexedMaxHeap::new();
        heap.reset(10);
        heap.build(&[9, 4, 7, 5], |_| 1.0);
        assert_eq!(heap.peek(), Some((4, 1.0)));
        heap.set_key(4, 0.5);
        assert_eq!(heap.peek(), Some((5, 1.0)));
        heap.set_key(9, 2.0);
        assert_eq!(heap.peek(), Some((9, 2.0)));
        assert!(heap.contains(7) && !heap.contains(3));
    }

    #[test]
    fn rebuild_reuses_storage() {
        let mut heap = IndexedMaxHeap::new();
        heap.reset(5);
        heap.build(&[0, 1, 2], |i| i as f32);
        heap.build(&[3, 4], |i| -(i as f32));
        assert_eq!(heap.len(), 2);
        assert!(!heap.contains(0) && heap.contains(3));
        assert_eq!(heap.peek(), Some((3, -3.0)));
    }
}
