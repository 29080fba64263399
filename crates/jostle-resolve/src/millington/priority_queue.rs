//! An indexed binary max-heap: items are dense `u32` ids (contact indices), each with an `f32`
//! key that can be raised or lowered in O(log n) because the heap keeps every item's position.
//!
//! This is what turns Cyclone's O(n) "find the worst contact" rescan into an O(log n) pick
//! (DESIGN.md, "Make it scale"). The order is total and stable: a larger key wins, and on equal
//! keys the **lower id** wins, which is exactly the choice a front-to-back linear scan with a
//! strict `>` makes; that is what lets [`super::PickStrategy::Heap`] and
//! [`super::PickStrategy::LinearScan`] give bit-identical results. NaN keys are stored as −∞, so
//! a non-finite contact is never picked and never breaks the heap order.
//!
//! It depends on nothing but `std`.

const ABSENT: u32 = u32::MAX;

/// Indexed max-heap over item ids `0..capacity` (see the module docs for the order).
#[derive(Clone, Debug, Default)]
pub struct IndexedMaxHeap {
    /// Heap array of item ids; `heap[0]` is the maximum.
    heap: Vec<u32>,
    /// Position of each item in `heap`, or `ABSENT`.
    pos: Vec<u32>,
    /// Key of each item (meaningful only while the item is present).
    keys: Vec<f32>,
}

impl IndexedMaxHeap {
    /// An empty heap.
    pub fn new() -> Self {
        Self::default()
    }

    /// Empties the heap and makes room for ids `0..capacity`. O(capacity) only when growing;
    /// clearing touches just the items that were present.
    pub fn reset(&mut self, capacity: usize) {
        for &item in &self.heap {
            self.pos[item as usize] = ABSENT;
        }
        self.heap.clear();
        if self.pos.len() < capacity {
            self.pos.resize(capacity, ABSENT);
            self.keys.resize(capacity, f32::NEG_INFINITY);
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
            self.keys[i] = sanitize(key(item));
            self.pos[i] = self.heap.len() as u32;
            self.heap.push(item);
        }
        for i in (0..self.heap.len() / 2).rev() {
            self.sift_down(i);
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
    pub fn peek(&self) -> Option<(u32, f32)> {
        self.heap
            .first()
            .map(|&item| (item, self.keys[item as usize]))
    }

    /// Changes the key of a present item and restores the heap order; absent items are
    /// ignored (debug-asserted).
    pub fn set_key(&mut self, item: u32, key: f32) {
        let Some(&p) = self.pos.get(item as usize) else {
            debug_assert!(false, "heap item {item} beyond capacity");
            return;
        };
        if p == ABSENT {
            debug_assert!(false, "heap item {item} is not present");
            return;
        }
        let old = self.keys[item as usize];
        let new = sanitize(key);
        self.keys[item as usize] = new;
        if new > old {
            self.sift_up(p as usize);
        } else if new < old {
            self.sift_down(p as usize);
        }
    }

    /// Whether item `a` belongs above item `b`: larger key, then lower id.
    #[inline]
    fn above(&self, a: u32, b: u32) -> bool {
        let (ka, kb) = (self.keys[a as usize], self.keys[b as usize]);
        ka > kb || (ka == kb && a < b)
    }

    #[inline]
    fn place(&mut self, i: usize, item: u32) {
        self.heap[i] = item;
        self.pos[item as usize] = i as u32;
    }

    fn sift_up(&mut self, mut i: usize) {
        let item = self.heap[i];
        while i > 0 {
            let parent = (i - 1) / 2;
            let p = self.heap[parent];
            if !self.above(item, p) {
                break;
            }
            self.place(i, p);
            i = parent;
        }
        self.place(i, item);
    }

    fn sift_down(&mut self, mut i: usize) {
        let n = self.heap.len();
        let item = self.heap[i];
        loop {
            let left = 2 * i + 1;
            if left >= n {
                break;
            }
            let right = left + 1;
            let mut child = left;
            if right < n && self.above(self.heap[right], self.heap[left]) {
                child = right;
            }
            let c = self.heap[child];
            if !self.above(c, item) {
                break;
            }
            self.place(i, c);
            i = child;
        }
        self.place(i, item);
    }

    /// Checks the heap order and the position index (tests and debug builds).
    #[cfg(test)]
    fn is_valid(&self) -> bool {
        (0..self.heap.len()).all(|i| {
            let item = self.heap[i];
            let parent_ok = i == 0 || !self.above(item, self.heap[(i - 1) / 2]);
            parent_ok && self.pos[item as usize] == i as u32
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
