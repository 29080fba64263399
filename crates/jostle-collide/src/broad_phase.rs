//! Broad phase: candidate collider pairs from bounding boxes, with parry's [`Bvh`].
//!
//! In: the colliders and the bodies' poses and sleep states. Out: the sorted list of
//! [`ColliderPair`]s whose bounding boxes, each enlarged by a margin, overlap.
//!
//! Invariants of the output: at least one of the two bodies is awake (never static–static,
//! sleeping–sleeping or sleeping–static) and one is dynamic (never between fixed and kinematic
//! bodies), never two colliders of the same body, each pair once
//! with the lower handle first, sorted by handle pair — so the result is deterministic and is
//! exactly the set a brute-force all-pairs test of the enlarged boxes gives.
//!
//! How: every bounded collider is a leaf of one BVH holding a *fat* box (the enlarged box grown
//! by a further `slack`), rewritten only when the enlarged box escapes it, so slowly moving
//! bodies leave the tree untouched; the tree is refitted and incrementally optimized when a
//! leaf changed. The pairs of leaves whose fat boxes overlap are kept from update to update and
//! repaired only around the leaves that changed (each changed leaf queries the tree once); the
//! reported pairs are those of them with an awake side whose exact enlarged boxes overlap. A
//! body resting in a pile changes no leaf for many steps, so a settled scene costs a linear
//! filter instead of a tree query per body (the 20-row pyramid's broad phase: 0.035 → 0.015 ms
//! a step). When fewer than a quarter of the leaves are awake, each awake collider queries the
//! tree with its exact enlarged box instead, so sleeping or fixed colliders are visited only to
//! check that their pose did not change; the cached pairs are then repaired when next used.
//! Unbounded shapes (half-spaces) never enter the tree: each is tested directly against every
//! awake collider's box (or against every box if it is itself awake).

use crate::collider::{Collider, ColliderHandle, ColliderSet};
use jostle_body::{BodyHandle, BodySet};
use jostle_math::Vec3;
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::partitioning::{Bvh, BvhBuildStrategy, BvhWorkspace};

/// Two colliders whose enlarged bounding boxes overlap; the lower handle first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ColliderPair(pub ColliderHandle, pub ColliderHandle);

impl ColliderPair {
    /// The pair with the lower handle first.
    pub fn new(a: ColliderHandle, b: ColliderHandle) -> Self {
        if a <= b { Self(a, b) } else { Self(b, a) }
    }
}

/// Whether neither collider can move nor is a sensor: such a pair never makes a contact
/// (a sensor still reports a kinematic body passing through it).
fn both_static(a: &Proxy, b: &Proxy) -> bool {
    a.immovable && b.immovable && !a.sensor && !b.sensor
}

/// What the broad phase remembers of one collider slot.
#[derive(Clone, Debug)]
struct Proxy {
    generation: u32,
    body: BodyHandle,
    awake: bool,
    /// Its body is fixed or kinematic: no pair of two such colliders is a candidate, unless
    /// one is a sensor ([`both_static`]).
    immovable: bool,
    /// The collider is a sensor.
    sensor: bool,
    unbounded: bool,
    /// World outward normal of an unbounded (half-space) collider; zero otherwise.
    normal: Vec3,
    /// World pose and shape identity the boxes were computed for.
    pose: Pose,
    shape_id: usize,
    /// The step's motion the box was swept over ([`BroadPhase::update_swept`]): the body's
    /// displacement at its velocity, and how far its turn moves a point (m); zero unswept.
    sweep: (Vec3, f32),
    /// The shape's box at `pose`, enlarged by the margin: what pairs are decided on.
    aabb: Aabb,
    /// The box stored in the tree: contains `aabb`, grown by `slack` when last rewritten.
    fat: Option<Aabb>,
}

/// The broad phase. Keep one per world and call [`BroadPhase::update`] once per step.
#[derive(Clone)]
pub struct BroadPhase {
    tree: Bvh,
    workspace: BvhWorkspace,
    proxies: Vec<Option<Proxy>>,
    margin: f32,
    /// The step the boxes are swept over ([`BroadPhase::update_swept`]); 0: not swept.
    dt: f32,
    slack: f32,
    pairs: Vec<ColliderPair>,
    awake_bounded: Vec<u32>,
    unbounded: Vec<u32>,
    new_leaves: Vec<u32>,
    /// Every pair of tree leaves (slots, lower first, sorted, unique) whose fat boxes overlap,
    /// whatever their bodies' states: a superset of the bounded pairs reported, kept from
    /// update to update and repaired only around leaves whose fat box changed.
    fat_pairs: Vec<(u32, u32)>,
    /// Whether `fat_pairs` is up to date with the tree but for the slots in `changed`.
    fat_pairs_valid: bool,
    /// Slots whose leaf was added, rewritten or removed since `fat_pairs` was last repaired.
    changed: Vec<u32>,
    /// Scratch: `changed` as a mask over slots.
    changed_mask: Vec<bool>,
    /// Scratch: the fat pairs found again around changed leaves, before they are merged.
    fresh_fat_pairs: Vec<(u32, u32)>,
    /// Scratch: the kept and the fresh fat pairs merged, then swapped with `fat_pairs`.
    merged_fat_pairs: Vec<(u32, u32)>,
    /// Scratch: the reported pairs while two sorted runs of them are merged.
    merged_pairs: Vec<ColliderPair>,
}

impl std::fmt::Debug for BroadPhase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BroadPhase")
            .field("leaves", &self.tree.leaf_count())
            .field("margin", &self.margin)
            .field("slack", &self.slack)
            .field("pairs", &self.pairs.len())
            .finish()
    }
}

impl Default for BroadPhase {
    fn default() -> Self {
        Self::new()
    }
}

/// Default fattening of the boxes stored in the tree (m): a body may move this far before its
/// leaf is rewritten. Larger means fewer tree updates but more candidates to filter.
pub const DEFAULT_SLACK: f32 = 0.05;

/// Above this many new leaves (and half the tree), the tree is rebuilt rather than grown.
const REBUILD_MIN_NEW_LEAVES: usize = 64;

impl BroadPhase {
    /// An empty broad phase with the default slack ([`DEFAULT_SLACK`]).
    pub fn new() -> Self {
        Self::with_slack(DEFAULT_SLACK)
    }

    /// An empty broad phase whose tree boxes are fattened by `slack` metres (≥ 0; a bad value
    /// falls back to the default). Slack changes cost, never the pairs reported.
    pub fn with_slack(slack: f32) -> Self {
        let slack = if slack.is_finite() && slack >= 0.0 {
            slack
        } else {
            DEFAULT_SLACK
        };
        Self {
            tree: Bvh::new(),
            workspace: BvhWorkspace::default(),
            proxies: Vec::new(),
            margin: f32::NAN,
            dt: 0.0,
            slack,
            pairs: Vec::new(),
            awake_bounded: Vec::new(),
            unbounded: Vec::new(),
            new_leaves: Vec::new(),
            fat_pairs: Vec::new(),
            fat_pairs_valid: false,
            changed: Vec::new(),
            changed_mask: Vec::new(),
            fresh_fat_pairs: Vec::new(),
            merged_fat_pairs: Vec::new(),
            merged_pairs: Vec::new(),
        }
    }

    /// The pairs of the last update.
    pub fn pairs(&self) -> &[ColliderPair] {
        &self.pairs
    }

    /// The enlarged box of `collider` as of the last update (`None` for an unknown or
    /// unbounded collider).
    pub fn aabb(&self, collider: ColliderHandle) -> Option<Aabb> {
        let p = self.proxies.get(collider.index() as usize)?.as_ref()?;
        (p.generation == collider.generation() && !p.unbounded).then_some(p.aabb)
    }

    /// Appends to `out` the colliders of awake bodies that may touch `aabb` (enlarged boxes of
    /// the last update, as [`BroadPhase::resting_near`] for the resting ones). Continuous
    /// collision detection sweeps a fast body against those of them that move slowly.
    pub fn awake_near(&self, aabb: &Aabb, out: &mut Vec<ColliderHandle>) {
        for j in self.tree.intersect_aabb(aabb) {
            if let Some(p) = &self.proxies[j as usize]
                && p.awake
                && p.aabb.intersects(aabb)
            {
                out.push(ColliderHandle::new(j, p.generation));
            }
        }
    }

    /// Appends to `out` the colliders of resting bodies (fixed or sleeping: they do not move
    /// during a step) that may touch `aabb`: those whose enlarged box overlaps it and the
    /// half-spaces it reaches. Boxes are those of the last update, the poses resting bodies
    /// keep through the step. Continuous collision detection sweeps a fast body against these.
    pub fn resting_near(&self, aabb: &Aabb, out: &mut Vec<ColliderHandle>) {
        for j in self.tree.intersect_aabb(aabb) {
            if let Some(p) = &self.proxies[j as usize]
                && !p.awake
                && p.aabb.intersects(aabb)
            {
                out.push(ColliderHandle::new(j, p.generation));
            }
        }
        for &u in &self.unbounded {
            if let Some(p) = &self.proxies[u as usize]
                && !p.awake
                && aabb_halfspace_distance(&p.pose, p.normal, aabb) <= 0.0
            {
                out.push(ColliderHandle::new(u, p.generation));
            }
        }
    }

    /// Recomputes the candidate pairs: every pair of colliders whose bounding boxes, each
    /// enlarged by `margin` metres on every side, overlap, and that passes the filters of the
    /// module docs. Pass at least half the narrow phase's prediction distance as `margin`.
    ///
    /// Colliders whose body handle is stale are ignored (and forgotten).
    pub fn update(
        &mut self,
        colliders: &ColliderSet,
        bodies: &BodySet,
        margin: f32,
    ) -> &[ColliderPair] {
        self.update_swept(colliders, bodies, margin, 0.0)
    }

    /// [`BroadPhase::update`] ahead of a step of `dt` seconds: the enlarged box of a collider
    /// whose body (awake, not fixed, CCD not off) moves more than half the margin within the step at its current velocity
    /// also covers the box moved by that displacement, grown by how far the body's turn
    /// moves a point of it ([`Collider::turn_reach`]), so that the pairs a fast body can meet
    /// within the step are candidates (for the speculative contacts of
    /// [`crate::NarrowPhase::update_swept`]). `dt` = 0 is [`BroadPhase::update`].
    pub fn update_swept(
        &mut self,
        colliders: &ColliderSet,
        bodies: &BodySet,
        margin: f32,
        dt: f32,
    ) -> &[ColliderPair] {
        let margin = if margin.is_finite() {
            margin.max(0.0)
        } else {
            0.0
        };
        self.dt = if dt.is_finite() { dt.max(0.0) } else { 0.0 };
        let margin_changed = margin != self.margin;
        self.margin = margin;
        let tree_changed = self.update_proxies(colliders, bodies, margin_changed);
        if tree_changed {
            self.tree.refit(&mut self.workspace);
            self.tree.optimize_incremental(&mut self.workspace);
        }
        self.find_pairs();
        &self.pairs
    }

    /// Brings the tree up to the colliders' current poses without looking for pairs: after
    /// it, every live collider's box in the tree contains its shape at its current pose, so
    /// the scene queries ([`crate::query::Queries`]) can prune with the tree. Costs what the
    /// proxy pass of [`BroadPhase::update`] costs (a pose comparison per collider, a leaf
    /// rewrite per collider that left its fat box); the next update then finds those leaves
    /// current. Never changes the pairs any update reports.
    pub fn refresh(&mut self, colliders: &ColliderSet, bodies: &BodySet) {
        // Before any update there is no margin yet: boxes are exact, and the first update
        // (its margin differing) recomputes them all.
        if self.margin.is_nan() {
            self.margin = 0.0;
        }
        if self.update_proxies(colliders, bodies, false) {
            self.tree.refit(&mut self.workspace);
            self.tree.optimize_incremental(&mut self.workspace);
        }
    }

    /// Walks the tree: `visit(aabb, leaf)` is called for each node reached, with `leaf` the
    /// collider of a leaf node (`None` for an inner node), and the walk descends below a node
    /// only when `visit` returns true. The boxes contain each collider's enlarged box of the
    /// last [`BroadPhase::update`] or [`BroadPhase::refresh`]. Unbounded colliders
    /// (half-spaces) are not in the tree: see [`BroadPhase::unbounded_colliders`].
    pub fn traverse(&self, mut visit: impl FnMut(&Aabb, Option<ColliderHandle>) -> bool) {
        use parry3d::partitioning::TraversalAction;
        self.tree.traverse(|node| {
            let leaf = node.leaf_data().map(|i| self.handle(i));
            if visit(&node.aabb(), leaf) {
                TraversalAction::Continue
            } else {
                TraversalAction::Prune
            }
        });
    }

    /// The unbounded colliders (half-spaces) as of the last update or refresh.
    pub fn unbounded_colliders(&self) -> impl Iterator<Item = ColliderHandle> + '_ {
        self.unbounded.iter().map(|&u| self.handle(u))
    }

    /// Brings every proxy up to date with its collider; returns whether the tree changed.
    fn update_proxies(&mut self, colliders: &ColliderSet, bodies: &BodySet, force: bool) -> bool {
        let n = colliders.capacity_index();
        let mut tree_changed = false;
        if self.proxies.len() > n {
            for i in n..self.proxies.len() {
                tree_changed |= self.forget(i as u32);
            }
            self.proxies.truncate(n);
        }
        self.proxies.resize(n, None);
        self.awake_bounded.clear();
        self.unbounded.clear();
        self.new_leaves.clear();

        for i in 0..n as u32 {
            let live = colliders
                .by_index(i)
                .and_then(|(h, c)| bodies.get(c.body).map(|b| (h, c, b)));
            let Some((handle, collider, body)) = live else {
                tree_changed |= self.forget(i);
                continue;
            };
            let pose = collider.world_pose(body);
            let shape_id = shape_id(collider);
            let awake = body.is_awake();
            let immovable = body.is_immovable();
            let unbounded = collider.is_unbounded();
            let sweep = if self.dt > 0.0
                && awake
                && !unbounded
                && !body.is_fixed()
                && body.ccd != jostle_body::CcdMode::Off
            {
                let shift = body.linear_velocity * self.dt;
                let turn = collider.turn_reach(body, self.dt);
                if shift.length() + turn > 0.5 * self.margin
                    && shift.is_finite()
                    && turn.is_finite()
                {
                    (shift, turn)
                } else {
                    (Vec3::ZERO, 0.0)
                }
            } else {
                (Vec3::ZERO, 0.0)
            };
            let proxy = &mut self.proxies[i as usize];
            let fresh = match proxy {
                Some(p) => {
                    force
                        || p.generation != handle.generation()
                        || p.pose != pose
                        || p.shape_id != shape_id
                        || p.sweep != sweep
                }
                None => true,
            };
            if fresh {
                let aabb = if unbounded {
                    Aabb::new_invalid()
                } else {
                    let at_pose = collider.shape.compute_aabb(&pose).loosened(self.margin);
                    if sweep == (Vec3::ZERO, 0.0) {
                        at_pose
                    } else {
                        let (shift, turn) = sweep;
                        let moved = Aabb::new(at_pose.mins + shift, at_pose.maxs + shift);
                        at_pose.merged(&moved).loosened(turn)
                    }
                };
                let normal = collider
                    .shape
                    .as_halfspace()
                    .map_or(Vec3::ZERO, |h| pose.rotation * h.normal);
                let fat = proxy.as_ref().and_then(|p| p.fat);
                *proxy = Some(Proxy {
                    generation: handle.generation(),
                    body: collider.body,
                    awake,
                    immovable,
                    sensor: collider.sensor,
                    unbounded,
                    normal,
                    pose,
                    shape_id,
                    sweep,
                    aabb,
                    fat,
                });
                tree_changed |= self.refresh_leaf(i);
            }
            let Some(p) = &mut self.proxies[i as usize] else {
                continue;
            };
            p.awake = awake;
            p.immovable = immovable;
            p.sensor = collider.sensor;
            p.body = collider.body;
            if p.unbounded {
                self.unbounded.push(i);
            } else if awake {
                self.awake_bounded.push(i);
            }
        }

        if !self.new_leaves.is_empty() {
            tree_changed = true;
            let total = self.tree.leaf_count() as usize + self.new_leaves.len();
            if self.new_leaves.len() >= REBUILD_MIN_NEW_LEAVES && 2 * self.new_leaves.len() >= total
            {
                self.rebuild_tree();
            } else {
                for k in 0..self.new_leaves.len() {
                    let i = self.new_leaves[k];
                    if let Some(fat) = self.proxies[i as usize].as_ref().and_then(|p| p.fat) {
                        self.tree.insert_or_update_partially(fat, i, 0.0);
                    }
                }
            }
        }
        tree_changed
    }

    /// Rewrites slot `i`'s leaf if its enlarged box left the fat box (or it has none yet);
    /// new leaves are queued in `new_leaves`. Returns whether an existing leaf changed.
    fn refresh_leaf(&mut self, i: u32) -> bool {
        let Some(p) = self.proxies[i as usize].as_mut() else {
            return false;
        };
        if p.unbounded {
            return p.fat.take().is_some() && {
                self.tree.remove(i);
                self.changed.push(i);
                true
            };
        }
        match p.fat {
            Some(fat) if fat.contains(&p.aabb) => false,
            Some(_) => {
                let fat = p.aabb.loosened(self.slack);
                p.fat = Some(fat);
                self.tree.insert_or_update_partially(fat, i, 0.0);
                self.changed.push(i);
                true
            }
            None => {
                p.fat = Some(p.aabb.loosened(self.slack));
                self.new_leaves.push(i);
                self.changed.push(i);
                false
            }
        }
    }

    /// Drops slot `i`'s proxy and leaf; returns whether the tree changed.
    fn forget(&mut self, i: u32) -> bool {
        match self.proxies.get_mut(i as usize).and_then(Option::take) {
            Some(Proxy { fat: Some(_), .. }) => {
                self.tree.remove(i);
                self.changed.push(i);
                true
            }
            _ => false,
        }
    }

    fn rebuild_tree(&mut self) {
        let leaves = self
            .proxies
            .iter()
            .enumerate()
            .filter_map(|(i, p)| p.as_ref().and_then(|p| p.fat).map(|fat| (i, fat)));
        self.tree = Bvh::from_iter(BvhBuildStrategy::Binned, leaves);
    }

    fn handle(&self, i: u32) -> ColliderHandle {
        let generation = self.proxies[i as usize]
            .as_ref()
            .map_or(0, |p| p.generation);
        ColliderHandle::new(i, generation)
    }

    /// Brings `fat_pairs` up to date with the tree: rebuilt from every leaf the first time,
    /// afterwards only the pairs of the leaves in `changed` are dropped and queried again.
    fn repair_fat_pairs(&mut self) {
        let leaf = |proxies: &[Option<Proxy>], i: u32| {
            proxies
                .get(i as usize)
                .and_then(|p| p.as_ref())
                .and_then(|p| p.fat)
        };
        if !self.fat_pairs_valid {
            self.fat_pairs.clear();
            for i in 0..self.proxies.len() as u32 {
                if let Some(fat) = leaf(&self.proxies, i) {
                    for j in self.tree.intersect_aabb(&fat) {
                        if j > i {
                            self.fat_pairs.push((i, j));
                        }
                    }
                }
            }
            self.fat_pairs_valid = true;
        } else if !self.changed.is_empty() {
            self.changed_mask.clear();
            self.changed_mask.resize(self.proxies.len(), false);
            for &c in &self.changed {
                if let Some(m) = self.changed_mask.get_mut(c as usize) {
                    *m = true;
                }
            }
            let mask = &self.changed_mask;
            let touched = |i: u32| mask.get(i as usize).copied().unwrap_or(true);
            // What is kept stays sorted and unique; the pairs found again are sorted on their
            // own and merged in (a full sort of every pair took a third of a falling rain's
            // broad phase).
            self.fat_pairs.retain(|&(i, j)| !touched(i) && !touched(j));
            self.fresh_fat_pairs.clear();
            for &c in &self.changed {
                // A slot may be listed several times: query its leaf once (clearing its bit).
                let first = self
                    .changed_mask
                    .get_mut(c as usize)
                    .is_some_and(|m| std::mem::replace(m, false));
                if !first {
                    continue;
                }
                if let Some(fat) = leaf(&self.proxies, c) {
                    for j in self.tree.intersect_aabb(&fat) {
                        if j != c {
                            self.fresh_fat_pairs.push((c.min(j), c.max(j)));
                        }
                    }
                }
            }
            self.fresh_fat_pairs.sort_unstable();
            self.fresh_fat_pairs.dedup();
            merge_sorted(
                &self.fat_pairs,
                &self.fresh_fat_pairs,
                &mut self.merged_fat_pairs,
            );
            std::mem::swap(&mut self.fat_pairs, &mut self.merged_fat_pairs);
            self.changed.clear();
            return;
        } else {
            return;
        }
        self.changed.clear();
        self.fat_pairs.sort_unstable();
        self.fat_pairs.dedup();
    }

    fn find_pairs(&mut self) {
        self.pairs.clear();
        let leaves = self.tree.leaf_count() as usize;
        if 4 * self.awake_bounded.len() < leaves {
            // Mostly resting: query the tree from the few awake colliders, so sleeping and
            // fixed ones cost nothing. The fat pairs are repaired when next used; if too many
            // changes pile up meanwhile, they are rebuilt instead.
            if self.changed.len() > leaves {
                self.fat_pairs_valid = false;
                self.changed.clear();
            }
            self.find_pairs_from_awake();
            self.find_unbounded_pairs();
            self.pairs.sort_unstable();
            self.pairs.dedup();
        } else {
            self.repair_fat_pairs();
            // Every reported bounded pair has overlapping fat boxes (each enlarged box lies in
            // its fat box), so filtering the fat pairs finds them all.
            for &(i, j) in &self.fat_pairs {
                let (Some(pi), Some(pj)) = (&self.proxies[i as usize], &self.proxies[j as usize])
                else {
                    continue;
                };
                if !(pi.awake || pj.awake)
                    || both_static(pi, pj)
                    || pi.body == pj.body
                    || !pi.aabb.intersects(&pj.aabb)
                {
                    continue;
                }
                self.pairs.push(ColliderPair::new(
                    ColliderHandle::new(i, pi.generation),
                    ColliderHandle::new(j, pj.generation),
                ));
            }
            // The fat pairs are sorted by slot and unique, so these are sorted and unique
            // (handles order by slot first); the half-space pairs, never in the tree, are
            // sorted on their own and merged in.
            let bounded = self.pairs.len();
            self.find_unbounded_pairs();
            self.pairs[bounded..].sort_unstable();
            debug_assert!(self.pairs[..bounded].is_sorted());
            merge_sorted(
                &self.pairs[..bounded],
                &self.pairs[bounded..],
                &mut self.merged_pairs,
            );
            std::mem::swap(&mut self.pairs, &mut self.merged_pairs);
        }
    }

    /// The bounded pairs found by querying the tree with each awake collider's enlarged box.
    fn find_pairs_from_awake(&mut self) {
        for &i in &self.awake_bounded {
            let Some(pi) = &self.proxies[i as usize] else {
                continue;
            };
            for j in self.tree.intersect_aabb(&pi.aabb) {
                if j == i {
                    continue;
                }
                let Some(pj) = &self.proxies[j as usize] else {
                    continue;
                };
                // Awake–awake pairs are found from both sides: keep the one from the lower slot.
                if (pj.awake && j < i)
                    || both_static(pi, pj)
                    || pj.body == pi.body
                    || !pi.aabb.intersects(&pj.aabb)
                {
                    continue;
                }
                self.pairs.push(ColliderPair::new(
                    ColliderHandle::new(i, pi.generation),
                    ColliderHandle::new(j, pj.generation),
                ));
            }
        }
    }

    fn find_unbounded_pairs(&mut self) {
        for (k, &u) in self.unbounded.iter().enumerate() {
            let Some(pu) = &self.proxies[u as usize] else {
                continue;
            };
            let hu = self.handle(u);
            let test = |_j: u32, pj: &Proxy| {
                pj.body != pu.body
                    && !pj.unbounded
                    && !both_static(pu, pj)
                    && halfspace_overlaps(pu, &pj.aabb, self.margin)
            };
            if pu.awake {
                for (j, pj) in self.proxies.iter().enumerate() {
                    if let Some(pj) = pj.as_ref().filter(|pj| test(j as u32, pj)) {
                        self.pairs.push(ColliderPair::new(
                            hu,
                            ColliderHandle::new(j as u32, pj.generation),
                        ));
                    }
                }
            } else {
                for &j in &self.awake_bounded {
                    if let Some(pj) = self.proxies[j as usize].as_ref().filter(|pj| test(j, pj)) {
                        self.pairs
                            .push(ColliderPair::new(hu, ColliderHandle::new(j, pj.generation)));
                    }
                }
            }
            // Two unbounded shapes: a candidate whenever one of them is awake.
            for &v in &self.unbounded[k + 1..] {
                if let Some(pv) = &self.proxies[v as usize]
                    && (pu.awake || pv.awake)
                    && !both_static(pu, pv)
                    && pu.body != pv.body
                {
                    self.pairs
                        .push(ColliderPair::new(hu, ColliderHandle::new(v, pv.generation)));
                }
            }
        }
    }
}

/// `a` and `b`, each sorted, merged into `out` (cleared first), sorted, without the
/// duplicates of equal items (each list's own must be unique already).
fn merge_sorted<T: Ord + Copy>(a: &[T], b: &[T], out: &mut Vec<T>) {
    out.clear();
    out.reserve(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => {
                out.push(a[i]);
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                out.push(b[j]);
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                out.push(a[i]);
                i += 1;
                j += 1;
            }
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
}

/// Identity of a collider's shape (the address of its shared allocation), so that replacing
/// the shape of a resting collider is noticed.
fn shape_id(collider: &Collider) -> usize {
    std::sync::Arc::as_ptr(&collider.shape.0) as *const () as usize
}

/// Whether `aabb` (already enlarged by the margin) reaches the half-space of `plane`, itself
/// enlarged by `margin`: the box's lowest point along the outward normal is within `margin`
/// of the plane or below it.
fn halfspace_overlaps(plane: &Proxy, aabb: &Aabb, margin: f32) -> bool {
    aabb_halfspace_distance(&plane.pose, plane.normal, aabb) <= margin
}

/// Signed distance from a half-space (plane through `pose.translation`, world outward normal
/// `n`) to the lowest point of `aabb` along `n`: ≤ 0 when the box touches the half-space.
pub fn aabb_halfspace_distance(pose: &Pose, n: Vec3, aabb: &Aabb) -> f32 {
    let c = aabb.center();
    let h = aabb.half_extents();
    n.dot(c - pose.translation) - n.abs().dot(h)
}
