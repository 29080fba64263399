//! Narrow phase: persistent contact manifolds for the broad phase's candidate pairs.
//!
//! In: the sorted candidate pairs, the colliders, the bodies' poses and the settings. Out:
//! [`BodyContact`]s in jostle's convention (normal from body B toward body A, penetration
//! positive on overlap), [`CollisionEvent`]s and [`NarrowStats`].
//!
//! Each pair keeps its parry manifolds and workspace from step to step, so parry's coherence
//! (and its feature ids) carries over, except where a shape's support point shows that a
//! manifold misses overlap (`misses_a_deeper_point`: a box turning about an edge); each
//! manifold is reduced to at most four points ([`crate::reduce`]; boxes, cylinders, capsules,
//! hulls and compounds smaller than 5 cm are clipped scaled up, see `clip_scale`); each point
//! carries the resolver's accumulated impulse, matched by (sub-shapes, feature ids) when the
//! manifold is recomputed. A pair whose relative pose moved
//! less than the reuse tolerances since its manifold was computed is not recomputed: only its
//! separations are refreshed, and its world points are rebuilt from the local points, so they
//! follow the bodies. A pair whose query found no contact keeps a direction along which its
//! shapes lay further apart than the prediction distance; while two support points show that
//! they still do, the query is skipped (the two support points prove it would find nothing).
//! Pairs that left the candidate list are dropped.

use crate::broad_phase::ColliderPair;
use crate::collider::{Collider, ColliderHandle, ColliderSet};
use crate::material::Material;
use crate::polytope;
use crate::reduce::reduce_manifold;
use crate::settings::CollideSettings;
use crate::shape::MAX_EXTENT;
use jostle_body::{BodyHandle, BodySet, CcdMode};
use jostle_math::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::query::{
    ContactManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher, PersistentQueryDispatcher,
};
use parry3d::shape::{Capsule, Cuboid, Cylinder, PackedFeatureId, Shape, SharedShape};
use std::borrow::Cow;

/// One contact point between two bodies, ready for the resolver.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodyContact {
    /// Body A: the normal points toward it. The dynamic body when the other is fixed.
    pub a: BodyHandle,
    /// Body B.
    pub b: BodyHandle,
    /// World contact point on A's surface (m), where the contact acts on A; while the point's
    /// frame is held ([`CollideSettings::frame_tolerance`]), A's centre plus the held lever
    /// arm.
    pub point: Vec3,
    /// World contact point on B's surface (m), where the contact acts on B; held the same way.
    /// `point − point_b` is about `normal · −penetration`.
    pub point_b: Vec3,
    /// Unit world normal from B toward A: the direction A must move to separate.
    pub normal: Vec3,
    /// Penetration depth along the normal (m): positive on overlap, negative (the separation)
    /// for a speculative contact within the prediction distance.
    pub penetration: f32,
    /// Mixed friction coefficient ([`Material::mix`]): the static one, μs.
    pub friction: f32,
    /// Mixed dynamic friction coefficient μd when the materials have one of their own
    /// ([`Material::dynamic_friction`]); `None`: the same as `friction`.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub dynamic_friction: Option<f32>,
    /// Mixed restitution ([`Material::mix`]).
    pub restitution: f32,
    /// The resolver's accumulated impulse of the last step for this point, in contact space
    /// (x along the normal), for warm starting; zero for a new point.
    pub impulse: Vec3,
    /// The compression (m) the resolver's soft spring at this point took as already carried
    /// at the end of the last step (the soft step's load compensation), carried like the
    /// impulse; zero for a new point.
    pub preload: f32,
}

/// Two bodies started or stopped touching (some contact point with penetration ≥ 0) during an
/// update. The lower body handle comes first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum CollisionEvent {
    /// The bodies touch now and did not at the previous update.
    Started(BodyHandle, BodyHandle),
    /// The bodies touched at the previous update and no longer do (or one was removed).
    Stopped(BodyHandle, BodyHandle),
}

/// A collider started or stopped overlapping a sensor during an update
/// ([`crate::Collider::sensor`]). When both are sensors, `sensor` is the lower handle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum SensorEvent {
    /// `other` overlaps `sensor` now and did not at the previous update.
    Entered {
        /// The sensor.
        sensor: ColliderHandle,
        /// The collider that came in.
        other: ColliderHandle,
    },
    /// `other` overlapped `sensor` at the previous update and no longer does (or one of
    /// them was removed, or stopped being a sensor or meeting the other's groups).
    Exited {
        /// The sensor.
        sensor: ColliderHandle,
        /// The collider that left.
        other: ColliderHandle,
    },
}

/// The contacts of a collider pair pushed harder than a threshold in a step
/// ([`crate::Collider::force_event_threshold`], the smaller of the pair's when both have one).
/// The force is what the contacts carry at the end of the step (a substepping resolver's last
/// substep, over the step), not the peak of an impact inside it; a sleeping pair is not solved
/// and reports nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ContactForceEvent {
    /// The collider on body `a`.
    pub collider_a: ColliderHandle,
    /// The collider on body `b`.
    pub collider_b: ColliderHandle,
    /// The body the impulses act on ([`BodyContact::a`]).
    pub a: BodyHandle,
    /// The other body.
    pub b: BodyHandle,
    /// The step's total contact impulse on `a` (N·s, world space: normal and friction).
    pub total_impulse: Vec3,
    /// The total normal force over the step (N): the normal impulses summed, over the step.
    pub total_force: f32,
    /// The contact point that carried the largest normal impulse (world, on `a`'s surface).
    pub strongest_point: Vec3,
    /// Its normal force (N).
    pub strongest_force: f32,
}

/// A user's say on which collider pairs may make contact (or report sensor events), asked
/// after their groups meet: `false` skips the pair. It must answer the same for the same
/// pair until told otherwise, or contacts flicker. It may be asked from several threads at
/// once, in any order (the parts of [`NarrowPhase::update_with`]).
pub type PairFilter = dyn Fn(&Collider, &Collider) -> bool + Send + Sync;

/// Counts of one narrow-phase update.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NarrowStats {
    /// Candidate pairs received from the broad phase.
    pub candidate_pairs: usize,
    /// Manifolds with at least one point.
    pub manifolds: usize,
    /// Contact points produced (the length of [`NarrowPhase::contacts`]).
    pub contact_points: usize,
    /// Manifolds (with at least one point) reused without recomputation because their pair's
    /// relative pose moved less than the reuse tolerances.
    pub manifolds_reused: usize,
    /// Parts the pairs were split into ([`NarrowPhase::update_with`]; 1 on one thread).
    pub parts: usize,
    /// Pairs without contacts left uncomputed because the direction that last kept their
    /// shapes apart still keeps them further apart than the prediction distance (each such
    /// pair costs two support points instead of a contact query).
    pub kept_apart: usize,
}

/// Per-point data kept in parry's manifolds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct PointData {
    impulse: Vec3,
    /// The resolver's preload of the point ([`BodyContact::preload`]).
    #[cfg_attr(feature = "serde", serde(default))]
    preload: f32,
    /// The point's held contact frame ([`CollideSettings::frame_tolerance`]); `None` until
    /// first taken, or with the tolerance 0.
    #[cfg_attr(feature = "serde", serde(default))]
    frame: Option<Frame>,
}

/// A contact point's frame as the resolver sees it: the normal and the lever arms from each
/// body's centre of mass, all in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Frame {
    normal: Vec3,
    r_a: Vec3,
    r_b: Vec3,
}

impl Frame {
    /// The frame to use now, given the fresh one: the held frame while both lever arms are
    /// within `tolerance` (m) of it and the normal within `min_cos` (the cosine of the
    /// angular tolerance), else the fresh one (which is then held; nothing is held with a
    /// `tolerance` of 0).
    fn hold(held: &mut Option<Frame>, fresh: Frame, tolerance: f32, min_cos: f32) -> Frame {
        match *held {
            Some(f)
                if f.r_a.distance_squared(fresh.r_a) < tolerance * tolerance
                    && f.r_b.distance_squared(fresh.r_b) < tolerance * tolerance
                    && f.normal.dot(fresh.normal) > min_cos =>
            {
                f
            }
            _ => {
                *held = (tolerance > 0.0).then_some(fresh);
                fresh
            }
        }
    }
}

type Manifold = ContactManifold<(), PointData>;

/// What a pair's manifolds were last computed for.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Computed {
    pos12: Pose,
    prediction: f32,
    /// Identities (addresses) of the two shapes, so a replaced shape forces a recompute.
    /// Not serialised (an address would make the snapshots of two identical runs differ, and
    /// means nothing in another process): [`NarrowPhase::rebind_shapes`] sets them on
    /// restore.
    #[cfg_attr(feature = "serde", serde(skip))]
    shapes: (usize, usize),
}

#[derive(Clone)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct PairState {
    pair: ColliderPair,
    manifolds: Vec<Manifold>,
    workspace: Option<ContactManifoldsWorkspace>,
    computed: Option<Computed>,
    /// The two colliders' world poses when every point's held frame was last checked
    /// against a fresh one, and whether collider 2's body was A then; `None` until then
    /// ([`frames_still_held`]).
    #[cfg_attr(feature = "serde", serde(default))]
    checked: Option<(Pose, Pose, bool)>,
    /// Where the pair's points are in [`NarrowPhase::contacts`] since the last update, whose
    /// impulses and preloads the points take back at the start of the next ([`Emitted`]).
    #[cfg_attr(feature = "serde", serde(default))]
    emitted: Option<Emitted>,
    /// A unit direction in collider 1's frame along which the two shapes lay further apart
    /// than the prediction distance when the pair last had no contact ([`separating_axis`]);
    /// `None` while the pair has contacts, or none was found.
    #[cfg_attr(feature = "serde", serde(default))]
    apart: Option<Vec3>,
    /// The pair's shapes scaled for clipping, when they are small and not both boxes,
    /// cylinders or capsules ([`ScaledShapes`]); rebuilt after a restore.
    #[cfg_attr(feature = "serde", serde(skip))]
    scaled: Option<Box<ScaledShapes>>,
}

/// Copies of a pair's shapes scaled for clipping ([`clip_scale`], a function of the shapes
/// alone), kept while the pair lives: a convex hull or a compound is rebuilt to be scaled,
/// once, not every query.
#[derive(Clone)]
struct ScaledShapes {
    /// The shapes scaled ([`shape_id`]).
    ids: (usize, usize),
    shapes: (SharedShape, SharedShape),
}

/// A pair's run of [`NarrowPhase::contacts`] at the last update: `count` contacts from
/// `first`, counted from the start of its part ([`NarrowPhase::bases`]).
///
/// The resolver's impulse and preload of a contact are written into the contact list alone
/// ([`NarrowPhase::store_point`]), in its order; each persistent point takes them back when
/// its pair is next updated, while its manifolds are being read anyway. Written straight
/// into the points, as before, they cost a cache miss per manifold once a scene's points no
/// longer fit the cache (6.5% of a step of the 3D pyramid of 20 layers, 80,000 points).
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct Emitted {
    part: u32,
    first: u32,
    count: u32,
}

impl Emitted {
    /// The pair's contacts in the list whose parts start at `bases`; `None` for a part that
    /// is not there.
    fn range(&self, bases: &[u32]) -> Option<std::ops::Range<usize>> {
        let at = *bases.get(self.part as usize)? as usize + self.first as usize;
        Some(at..at.checked_add(self.count as usize)?)
    }
}

impl PairState {
    fn new(pair: ColliderPair) -> Self {
        Self {
            pair,
            manifolds: Vec::new(),
            workspace: None,
            computed: None,
            checked: None,
            emitted: None,
            apart: None,
            scaled: None,
        }
    }

    /// The pair's points take back the impulses and preloads of their contacts in the last
    /// update's `contacts` (`slots` locates them in the pair's manifolds, `bases` are the
    /// parts' starts; [`Emitted`]); the record is cleared.
    fn take_back(&mut self, contacts: &[BodyContact], slots: &[PointSlot], bases: &[u32]) {
        let Some(e) = self.emitted.take() else {
            return;
        };
        let range = e.range(bases);
        let (Some(contacts), Some(slots)) = (
            range.clone().and_then(|r| contacts.get(r)),
            range.and_then(|r| slots.get(r)),
        ) else {
            debug_assert!(false, "a pair's contacts past the list");
            return;
        };
        for (c, slot) in contacts.iter().zip(slots) {
            if let Some(p) = self
                .manifolds
                .get_mut(slot.manifold as usize)
                .and_then(|m| m.points.get_mut(slot.point as usize))
            {
                p.data.impulse = c.impulse;
                p.data.preload = c.preload;
            }
        }
    }
}

/// Where a contact of `contacts()` lives: pair, manifold and point indices.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct PointSlot {
    pair: u32,
    manifold: u32,
    point: u32,
}

/// The narrow phase. Keep one per world and call [`NarrowPhase::update`] once per step.
#[derive(Clone, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct NarrowPhase {
    pairs: Vec<PairState>,
    /// The previous update's pair list, kept empty between updates so its allocation is
    /// reused instead of the list growing from nothing every step.
    #[cfg_attr(feature = "serde", serde(skip))]
    spare: Vec<PairState>,
    /// Scratch for the touching pairs of an update.
    #[cfg_attr(feature = "serde", serde(skip))]
    touching_scratch: Vec<(BodyHandle, BodyHandle)>,
    contacts: Vec<BodyContact>,
    slots: Vec<PointSlot>,
    /// Where each part of the last update starts in `contacts` ([`Emitted`]).
    #[cfg_attr(feature = "serde", serde(default))]
    bases: Vec<u32>,
    /// Scratch: the last update's `contacts`, `slots` and `bases` during an update.
    #[cfg_attr(feature = "serde", serde(skip))]
    previous: (Vec<BodyContact>, Vec<PointSlot>, Vec<u32>),
    touching: Vec<(BodyHandle, BodyHandle)>,
    events: Vec<CollisionEvent>,
    /// Collider pairs (sensor first) overlapping at the last update, sorted.
    #[cfg_attr(feature = "serde", serde(default))]
    overlaps: Vec<(ColliderHandle, ColliderHandle)>,
    #[cfg_attr(feature = "serde", serde(default))]
    sensor_events: Vec<SensorEvent>,
    /// Scratch for the overlapping pairs of an update.
    #[cfg_attr(feature = "serde", serde(skip))]
    overlaps_scratch: Vec<(ColliderHandle, ColliderHandle)>,
    /// The contact force events of the last step ([`NarrowPhase::find_force_events`]).
    #[cfg_attr(feature = "serde", serde(skip))]
    force_events: Vec<ContactForceEvent>,
    /// Whether a collider of the last update's contact pairs has a force event threshold:
    /// otherwise [`NarrowPhase::find_force_events`] has nothing to look at.
    #[cfg_attr(feature = "serde", serde(skip))]
    any_threshold: bool,
    /// Scratch: each part's outputs of an update ([`Part`]); the first part's lists are
    /// the narrow phase's own, moved in and out.
    #[cfg_attr(feature = "serde", serde(skip))]
    parts: Vec<Part>,
}

/// Most parts an update's pairs are split into ([`Runner::parts`]).
pub const MAX_PARTS: usize = 8;

/// Runs an update's parts ([`NarrowPhase::update_with`]): a contiguous run of pairs each, with
/// the same results whichever thread runs which part, and in whatever order.
pub trait Runner: Sync {
    /// How many parts to split an update of `pairs` pairs into (1 to [`MAX_PARTS`]; 1 runs
    /// them on the calling thread alone).
    fn parts(&self, pairs: usize) -> usize;
    /// Calls `f(i)` once for every `i` in `0..n`, on any threads, and returns when every
    /// call has returned.
    fn run(&self, n: usize, f: &(dyn Fn(usize) + Sync));
}

/// Runs `f(k, &mut parts[k])` for every part (at most [`MAX_PARTS`]) on `runner`, any part
/// on any thread, and returns when all have run: each part reaches only its own state (the
/// outputs it writes, disjoint from the others').
pub fn run_parts<S: Send>(
    runner: &dyn Runner,
    parts: &mut [S],
    f: &(dyn Fn(usize, &mut S) + Sync),
) {
    debug_assert!(parts.len() <= MAX_PARTS, "{} parts", parts.len());
    let n = parts.len().min(MAX_PARTS);
    let mut each = parts.iter_mut();
    let cells: [std::sync::Mutex<Option<&mut S>>; MAX_PARTS] =
        std::array::from_fn(|_| std::sync::Mutex::new(each.next()));
    runner.run(n, &|k| {
        if let Some(cell) = cells.get(k) {
            let mut part = cell.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(part) = part.as_mut() {
                f(k, part);
            }
        }
    });
}

/// A [`Runner`] that runs everything on the calling thread, in one part.
#[derive(Clone, Copy, Debug, Default)]
pub struct OneThread;

impl Runner for OneThread {
    fn parts(&self, _pairs: usize) -> usize {
        1
    }
    fn run(&self, n: usize, f: &(dyn Fn(usize) + Sync)) {
        (0..n).for_each(f);
    }
}

/// One part's outputs of an update: what [`PairOutputs`] writes, with the pair indices of
/// its slots counted from the part's first kept pair, and whether each of its pairs is kept.
#[derive(Clone, Debug, Default)]
struct Part {
    contacts: Vec<BodyContact>,
    slots: Vec<PointSlot>,
    touching: Vec<(BodyHandle, BodyHandle)>,
    overlaps: Vec<(ColliderHandle, ColliderHandle)>,
    any_threshold: bool,
    stats: NarrowStats,
    /// Scratch: a recomputed pair's points before the update ([`compute`]).
    old_points: Vec<(PointKey, PointData)>,
    /// Whether each pair of the part is kept.
    keep: Vec<bool>,
    /// Pairs kept.
    kept: u32,
}

impl Part {
    fn clear(&mut self) {
        self.contacts.clear();
        self.slots.clear();
        self.touching.clear();
        self.overlaps.clear();
        self.any_threshold = false;
        self.stats = NarrowStats::default();
        self.keep.clear();
        self.kept = 0;
    }

    /// Updates `states`, the part's pairs, in order.
    fn update(
        &mut self,
        part: u32,
        states: &mut [PairState],
        input: &PairInputs<'_>,
        min_cos: f32,
    ) {
        let mut out = PairOutputs {
            part,
            contacts: &mut self.contacts,
            slots: &mut self.slots,
            touching: &mut self.touching,
            overlaps: &mut self.overlaps,
            any_threshold: &mut self.any_threshold,
            stats: &mut self.stats,
            old_points: &mut self.old_points,
            min_cos,
        };
        let mut kept = 0u32;
        for state in states {
            let keep = update_pair(state, kept, input, &mut out);
            kept += u32::from(keep);
            self.keep.push(keep);
        }
        self.kept = kept;
    }
}

impl std::fmt::Debug for NarrowPhase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NarrowPhase")
            .field("pairs", &self.pairs.len())
            .field("contacts", &self.contacts.len())
            .field("touching", &self.touching.len())
            .finish()
    }
}

impl NarrowPhase {
    /// After a restore (a snapshot, or colliders rebuilt from the same descriptions), points
    /// the reuse records at the current shapes. The reuse test compares shape identities to
    /// notice a replaced shape; addresses do not survive serialisation, and without this every
    /// pair would be recomputed instead of reused on the first step, so a restored run would
    /// not continue bit for bit. Pairs whose colliders are gone are left to be dropped.
    pub fn rebind_shapes(&mut self, colliders: &ColliderSet) {
        for state in &mut self.pairs {
            let (Some(c1), Some(c2)) = (colliders.get(state.pair.0), colliders.get(state.pair.1))
            else {
                continue;
            };
            if let Some(computed) = state.computed.as_mut() {
                computed.shapes = (shape_id(c1), shape_id(c2));
            }
        }
    }

    /// Checks a narrow phase read back from a snapshot against `colliders`: every pair's
    /// colliders exist, every contact index is in range, and every number a step reads back
    /// (points, depths, carried impulses and preloads, held frames) is finite and in its
    /// domain. A snapshot's `impulse: (526, NaN, -3.7)` made a body non-finite at the first
    /// step. The error names the pair, manifold and point, and the field.
    pub fn check(
        &self,
        colliders: &ColliderSet,
        max_impulse: impl Fn(&Collider, &Collider) -> f32,
    ) -> Result<(), String> {
        // Finite and within the reach of any shape (`shape::MAX_EXTENT`).
        let vector = |v: Vec3| v.is_finite() && v.abs().max_element() <= 2.0 * MAX_EXTENT;
        for (i, state) in self.pairs.iter().enumerate() {
            let (Some(c1), Some(c2)) = (colliders.get(state.pair.0), colliders.get(state.pair.1))
            else {
                return Err(format!(
                    "pairs[{i}]: collider {} or {} does not exist",
                    state.pair.0, state.pair.1
                ));
            };
            let limit = max_impulse(c1, c2);
            if let Some(axis) = state.apart {
                if !(axis.is_finite() && (axis.length() - 1.0).abs() < 1e-3) {
                    return Err(format!(
                        "pairs[{i}].apart: must be a unit vector, got {axis}"
                    ));
                }
                // Only a pair without points keeps a direction (`update_pair` relies on it).
                if state.manifolds.iter().any(|m| !m.points.is_empty()) {
                    return Err(format!(
                        "pairs[{i}].apart: a pair with contact points keeps no direction"
                    ));
                }
            }
            for (j, manifold) in state.manifolds.iter().enumerate() {
                let at = |k: usize, field: &str| {
                    format!("pairs[{i}].manifolds[{j}].points[{k}].{field}")
                };
                if !(vector(manifold.local_n1) && vector(manifold.local_n2)) {
                    return Err(format!("pairs[{i}].manifolds[{j}]: normals must be finite"));
                }
                for (k, p) in manifold.points.iter().enumerate() {
                    let depth = p.dist.abs() <= 2.0 * MAX_EXTENT;
                    if !(vector(p.local_p1) && vector(p.local_p2) && depth) {
                        return Err(format!(
                            "{}: must be finite",
                            at(k, "local_p1/local_p2/dist")
                        ));
                    }
                    let d = &p.data;
                    if !(d.impulse.is_finite() && d.impulse.length() <= limit) {
                        return Err(format!(
                            "{}: must be finite and at most {limit:e} N·s (what stops the pair at \
                             the speed limit), got {}",
                            at(k, "data.impulse"),
                            d.impulse
                        ));
                    }
                    if !(d.preload.is_finite() && d.preload >= 0.0) {
                        return Err(format!(
                            "{}: must be finite and >= 0, got {}",
                            at(k, "data.preload"),
                            d.preload
                        ));
                    }
                    if let Some(f) = &d.frame {
                        let unit = f.normal.is_finite() && (f.normal.length() - 1.0).abs() < 1e-3;
                        if !(unit && vector(f.r_a) && vector(f.r_b)) {
                            return Err(format!(
                                "{}: must be a unit normal and finite lever arms",
                                at(k, "data.frame")
                            ));
                        }
                    }
                }
            }
        }
        for (i, slot) in self.slots.iter().enumerate() {
            let point = self
                .pairs
                .get(slot.pair as usize)
                .and_then(|s| s.manifolds.get(slot.manifold as usize))
                .and_then(|m| m.points.get(slot.point as usize));
            if point.is_none() {
                return Err(format!(
                    "slots[{i}]: no point at pair {}, manifold {}, point {}",
                    slot.pair, slot.manifold, slot.point
                ));
            }
        }
        if self.slots.len() != self.contacts.len() {
            return Err(format!(
                "{} slots for {} contacts",
                self.slots.len(),
                self.contacts.len()
            ));
        }
        // Each pair's record of its contacts ([`Emitted`]): in range, and those contacts its
        // own, with impulses its points accept.
        for (i, state) in self.pairs.iter().enumerate() {
            let Some(e) = state.emitted else {
                continue;
            };
            let Some(range) = e
                .range(&self.bases)
                .filter(|r| r.end <= self.slots.len().min(self.contacts.len()))
            else {
                return Err(format!(
                    "pairs[{i}].emitted: contacts {} + {} of part {} are not in the list",
                    e.first, e.count, e.part
                ));
            };
            let limit = match (colliders.get(state.pair.0), colliders.get(state.pair.1)) {
                (Some(c1), Some(c2)) => max_impulse(c1, c2),
                _ => 0.0,
            };
            for k in range {
                if self.slots[k].pair as usize != i {
                    return Err(format!(
                        "pairs[{i}].emitted: contacts[{k}] is another pair's"
                    ));
                }
                let impulse = self.contacts[k].impulse;
                if !(impulse.is_finite() && impulse.length() <= limit) {
                    return Err(format!(
                        "contacts[{k}].impulse: must be at most {limit:e} N·s (what stops the \
                         pair at the speed limit), got {impulse}"
                    ));
                }
            }
        }
        for (i, c) in self.contacts.iter().enumerate() {
            let finite = c.point.is_finite()
                && c.point_b.is_finite()
                && c.impulse.is_finite()
                && c.penetration.is_finite()
                && c.preload.is_finite()
                && c.preload >= 0.0;
            let unit = c.normal.is_finite() && (c.normal.length() - 1.0).abs() < 1e-3;
            let material = c.friction.is_finite()
                && c.friction >= 0.0
                && c.dynamic_friction
                    .is_none_or(|d| (0.0..=c.friction).contains(&d))
                && (0.0..=1.0).contains(&c.restitution);
            if !(finite && unit && material) {
                return Err(format!(
                    "contacts[{i}]: a number is not finite or out of its domain"
                ));
            }
        }
        Ok(())
    }

    /// An empty narrow phase.
    pub fn new() -> Self {
        Self::default()
    }

    /// The contacts of the last update: pairs in pair order, points in manifold order.
    pub fn contacts(&self) -> &[BodyContact] {
        &self.contacts
    }

    /// The touching events of the last update, sorted.
    pub fn events(&self) -> &[CollisionEvent] {
        &self.events
    }

    /// Takes the last update's events (contact and sensor), leaving none: for a caller that
    /// updates twice in one step and gives them back with [`NarrowPhase::restore_events`].
    pub fn take_events(&mut self) -> (Vec<CollisionEvent>, Vec<SensorEvent>) {
        (
            std::mem::take(&mut self.events),
            std::mem::take(&mut self.sensor_events),
        )
    }

    /// Forgets the last update's events (collision, sensor and contact force events), keeping
    /// every pair and contact: for a step in which nothing can change, which reports none.
    pub fn clear_events(&mut self) {
        self.events.clear();
        self.sensor_events.clear();
        self.force_events.clear();
    }

    /// Puts events taken with [`NarrowPhase::take_events`] before the last update's, so that a
    /// second update in one step (after bodies woke) loses none of the first's.
    pub fn restore_events(
        &mut self,
        (events, sensor_events): (Vec<CollisionEvent>, Vec<SensorEvent>),
    ) {
        let later = std::mem::replace(&mut self.events, events);
        self.events.extend(later);
        let later = std::mem::replace(&mut self.sensor_events, sensor_events);
        self.sensor_events.extend(later);
    }

    /// The contact force events of the last step.
    pub fn force_events(&self) -> &[ContactForceEvent] {
        &self.force_events
    }

    /// After the contacts' impulses of a step of `dt` are stored ([`NarrowPhase::store_point`]):
    /// an event for each collider pair with a threshold whose contacts pushed harder.
    pub fn find_force_events(&mut self, colliders: &ColliderSet, dt: f32) {
        self.force_events.clear();
        if !self.any_threshold {
            return;
        }
        let mut start = 0;
        while start < self.contacts.len() {
            let pair_index = self.slots[start].pair;
            let mut end = start + 1;
            while end < self.contacts.len() && self.slots[end].pair == pair_index {
                end += 1;
            }
            let group = start..end;
            start = end;
            let Some(state) = self.pairs.get(pair_index as usize) else {
                continue;
            };
            let (Some(c1), Some(c2)) = (colliders.get(state.pair.0), colliders.get(state.pair.1))
            else {
                continue;
            };
            let threshold = match (c1.force_event_threshold, c2.force_event_threshold) {
                (Some(x), Some(y)) => x.min(y),
                (Some(x), None) | (None, Some(x)) => x,
                (None, None) => continue,
            };
            let contacts = &self.contacts[group];
            let normal_impulse: f32 = contacts.iter().map(|c| c.impulse.x.max(0.0)).sum();
            let total_force = normal_impulse / dt;
            if total_force.is_nan() || total_force <= threshold {
                continue;
            }
            let total_impulse = contacts
                .iter()
                .map(|c| jostle_math::contact_basis(c.normal) * c.impulse)
                .fold(Vec3::ZERO, |sum, i| sum + i);
            let strongest = contacts
                .iter()
                .max_by(|x, y| x.impulse.x.total_cmp(&y.impulse.x))
                .expect("a group has a contact");
            let first = contacts[0];
            let (collider_a, collider_b) = if c1.body == first.a {
                (state.pair.0, state.pair.1)
            } else {
                (state.pair.1, state.pair.0)
            };
            self.force_events.push(ContactForceEvent {
                collider_a,
                collider_b,
                a: first.a,
                b: first.b,
                total_impulse,
                total_force,
                strongest_point: strongest.point,
                strongest_force: strongest.impulse.x.max(0.0) / dt,
            });
        }
    }

    /// The sensor events of the last update.
    pub fn sensor_events(&self) -> &[SensorEvent] {
        &self.sensor_events
    }

    /// The colliders overlapping each sensor at the last update: (sensor, other), sorted.
    pub fn sensor_overlaps(&self) -> &[(ColliderHandle, ColliderHandle)] {
        &self.overlaps
    }

    /// Number of pairs with persistent state.
    pub fn pair_count(&self) -> usize {
        self.pairs.len()
    }

    /// Forgets every pair (the next update starts cold: no warm start, no events carried).
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Forgets every pair that involves a collider `gone` says is removed, with its contacts
    /// (the remaining contacts keep their order). The touching list is left alone, so the next
    /// update reports the removed bodies' contacts as [`CollisionEvent::Stopped`].
    pub fn remove_colliders(&mut self, gone: impl Fn(ColliderHandle) -> bool) {
        let mut new_index = Vec::with_capacity(self.pairs.len());
        let mut kept = 0u32;
        for state in &self.pairs {
            if gone(state.pair.0) || gone(state.pair.1) {
                new_index.push(None);
            } else {
                new_index.push(Some(kept));
                kept += 1;
            }
        }
        if kept as usize == self.pairs.len() {
            return;
        }
        let mut i = 0;
        self.pairs.retain(|_| {
            i += 1;
            new_index[i - 1].is_some()
        });
        let mut contacts = Vec::with_capacity(self.contacts.len());
        let mut slots = Vec::with_capacity(self.slots.len());
        for (contact, slot) in self.contacts.iter().zip(&self.slots) {
            if let Some(pair) = new_index[slot.pair as usize] {
                contacts.push(*contact);
                slots.push(PointSlot { pair, ..*slot });
            }
        }
        self.contacts = contacts;
        self.slots = slots;
        // Each remaining pair's record of its contacts, which kept their values, in the new
        // list (one part).
        for state in &mut self.pairs {
            state.emitted = None;
        }
        let mut first = 0;
        for run in self.slots.chunk_by(|x, y| x.pair == y.pair) {
            if let Some(state) = run
                .first()
                .and_then(|s| self.pairs.get_mut(s.pair as usize))
            {
                state.emitted = Some(Emitted {
                    part: 0,
                    first,
                    count: run.len() as u32,
                });
            }
            first += run.len() as u32;
        }
        self.bases.clear();
        self.bases.push(0);
    }

    /// Writes the resolver's accumulated impulses back, one per contact of
    /// [`NarrowPhase::contacts`], in the same order ([`NarrowPhase::store_impulse`]). Extra
    /// impulses are ignored; contacts without one keep theirs.
    pub fn store_impulses(&mut self, impulses: &[Vec3]) {
        let n = impulses.len().min(self.contacts.len());
        for (i, &impulse) in impulses[..n].iter().enumerate() {
            self.store_impulse(i, impulse);
        }
    }

    /// Writes the resolver's accumulated impulse for contact `index` of
    /// [`NarrowPhase::contacts`] back: the contact shows it, and its persistent point takes
    /// it at the start of the next update, to warm start the contact found there.
    /// An index past the contacts is a caller's bug: ignored in release builds, a failed debug
    /// assertion otherwise.
    #[inline]
    pub fn store_impulse(&mut self, index: usize, impulse: Vec3) {
        if let Some(contact) = self.contact_mut(index) {
            contact.impulse = impulse;
        }
    }

    /// Writes the resolver's impulse and preload ([`BodyContact::preload`]) for contact
    /// `index` back, as [`NarrowPhase::store_impulse`].
    #[inline]
    pub fn store_point(&mut self, index: usize, impulse: Vec3, preload: f32) {
        if let Some(contact) = self.contact_mut(index) {
            contact.impulse = impulse;
            contact.preload = preload;
        }
    }

    /// [`NarrowPhase::store_point`] for the `count` points `point(0)`, `point(1)`, ... (each
    /// a contact index, impulse and preload), whose indices should increase: the points are
    /// split into as many parts as `runner` asks for, each writing its own run of the
    /// contacts, possibly on several threads (a scene's contacts outgrow the cache, and each
    /// write is then a miss: on the 3D pyramid of 20 layers, 80,000 contacts, the copy took
    /// 0.8 ms a step on one thread). Indices out of order are stored one after the other
    /// instead, with the same result.
    pub fn store_points_with(
        &mut self,
        count: usize,
        point: &(dyn Fn(usize) -> (usize, Vec3, f32) + Sync),
        runner: &dyn Runner,
    ) {
        let parts = runner.parts(count).clamp(1, MAX_PARTS).min(count.max(1));
        let sequential = |narrow: &mut Self| {
            for i in 0..count {
                let (index, impulse, preload) = point(i);
                narrow.store_point(index, impulse, preload);
            }
        };
        if parts == 1 {
            return sequential(self);
        }
        // Part k stores the points from ⌊k·count/parts⌋ into the contacts from its first
        // point's index on, which are its own if the indices increase.
        let first = |k: usize| k * count / parts;
        let mut starts = [0usize; MAX_PARTS + 1];
        for (k, start) in starts.iter_mut().enumerate().take(parts) {
            *start = point(first(k)).0;
        }
        starts[parts] = self.contacts.len();
        if starts[..=parts].windows(2).any(|w| w[0] > w[1]) {
            return sequential(self);
        }
        let mut rest = self.contacts.as_mut_slice();
        let mut runs: [&mut [BodyContact]; MAX_PARTS] = std::array::from_fn(|k| {
            let len = if k < parts {
                starts[k + 1] - starts[k]
            } else {
                0
            };
            let (own, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            own
        });
        let in_order = std::sync::atomic::AtomicBool::new(true);
        run_parts(runner, &mut runs[..parts], &|k, own| {
            for i in first(k)..first(k + 1) {
                let (index, impulse, preload) = point(i);
                match index.checked_sub(starts[k]).and_then(|at| own.get_mut(at)) {
                    Some(c) => {
                        c.impulse = impulse;
                        c.preload = preload;
                    }
                    None => in_order.store(false, std::sync::atomic::Ordering::Relaxed),
                }
            }
        });
        if !in_order.into_inner() {
            sequential(self);
        }
    }

    /// Contact `index`; `None` with a failed debug assertion for an index past the contacts.
    #[inline]
    fn contact_mut(&mut self, index: usize) -> Option<&mut BodyContact> {
        let n = self.contacts.len();
        let contact = self.contacts.get_mut(index);
        debug_assert!(contact.is_some(), "impulse for contact {index} of {n}");
        contact
    }

    /// Updates the manifolds of `pairs` (as the broad phase gives them: sorted, unique; other
    /// input is sorted first) and rebuilds the contacts and events.
    pub fn update(
        &mut self,
        pairs: &[ColliderPair],
        colliders: &ColliderSet,
        bodies: &BodySet,
        settings: &CollideSettings,
    ) -> NarrowStats {
        self.update_filtered(pairs, colliders, bodies, settings, None)
    }

    /// [`NarrowPhase::update`], skipping the pairs `filter` refuses ([`PairFilter`]).
    pub fn update_filtered(
        &mut self,
        pairs: &[ColliderPair],
        colliders: &ColliderSet,
        bodies: &BodySet,
        settings: &CollideSettings,
        filter: Option<&PairFilter>,
    ) -> NarrowStats {
        self.update_swept(pairs, colliders, bodies, settings, filter, 0.0)
    }

    /// [`NarrowPhase::update_filtered`] ahead of a step of `dt` seconds, with speculative
    /// contacts that grow with speed: a pair whose bodies can close more than the prediction
    /// distance within the step at their current velocities (`pair_prediction`) is
    /// looked at that much further, and of the points found beyond the prediction distance
    /// those are kept whose gap the bodies close within the step: gap ≤ prediction +
    /// max(0, closing speed along the normal at the point)·dt. A body falling onto a pile
    /// is then stopped at the surface instead of found a step later inside it, and a body
    /// passing a face sideways makes no contact with it. Pairs that bounce, and bodies
    /// whose CCD is off, keep the plain prediction distance (`pair_prediction`). `dt` = 0 is
    /// [`NarrowPhase::update_filtered`]. Pass the broad phase's pairs of
    /// [`crate::BroadPhase::update_swept`] with the same `dt`, so that such pairs are
    /// candidates at all.
    pub fn update_swept(
        &mut self,
        pairs: &[ColliderPair],
        colliders: &ColliderSet,
        bodies: &BodySet,
        settings: &CollideSettings,
        filter: Option<&PairFilter>,
        dt: f32,
    ) -> NarrowStats {
        self.update_with(pairs, colliders, bodies, settings, filter, dt, &OneThread)
    }

    /// [`NarrowPhase::update_swept`] with the pairs split into parts that `runner` may run on
    /// several threads ([`Runner`]): each part updates a contiguous run of the pairs into its
    /// own lists, which are then joined in order, so the results are bit for bit those of one
    /// thread, however many parts and threads.
    #[allow(clippy::too_many_arguments)]
    pub fn update_with(
        &mut self,
        pairs: &[ColliderPair],
        colliders: &ColliderSet,
        bodies: &BodySet,
        settings: &CollideSettings,
        filter: Option<&PairFilter>,
        dt: f32,
        runner: &dyn Runner,
    ) -> NarrowStats {
        let dt = if dt.is_finite() { dt.max(0.0) } else { 0.0 };
        let pairs: Cow<[ColliderPair]> = if pairs.windows(2).all(|w| w[0] < w[1]) {
            Cow::Borrowed(pairs)
        } else {
            let mut sorted = pairs.to_vec();
            sorted.sort_unstable();
            sorted.dedup();
            Cow::Owned(sorted)
        };
        let same_pairs = self.pairs.len() == pairs.len()
            && self
                .pairs
                .iter()
                .zip(pairs.iter())
                .all(|(s, p)| s.pair == *p);
        if !same_pairs {
            // A state for each of the broad phase's pairs, in its order: the last update's
            // where the pair is not new. (Where the pairs are the last update's, each state
            // is updated where it is: moving every state into a new list cost a memmove per
            // pair.)
            //
            // Runs of states that stay are moved in one `extend` each, each state read once and
            // written once; through a peeking iterator it was copied more often, and a rain's
            // pair list changes every step (5,800 states of 240 bytes for 1,000 bodies: replayed,
            // 1.51 → 1.39–1.41 ms an update).
            let mut old_pairs = std::mem::replace(&mut self.pairs, std::mem::take(&mut self.spare));
            self.pairs.clear();
            self.pairs.reserve(pairs.len());
            let mut old = old_pairs.drain(..);
            let mut next = 0;
            while let Some(&pair) = pairs.get(next) {
                // Pairs no longer listed are dropped.
                let gone = old.as_slice().iter().take_while(|s| s.pair < pair).count();
                old.by_ref().take(gone).for_each(drop);
                // The run of listed pairs that were listed before, in order.
                let kept = old
                    .as_slice()
                    .iter()
                    .zip(&pairs[next..])
                    .take_while(|(s, p)| s.pair == **p)
                    .count();
                if kept > 0 {
                    self.pairs.extend(old.by_ref().take(kept));
                    next += kept;
                } else {
                    self.pairs.push(PairState::new(pair));
                    next += 1;
                }
            }
            drop(old);
            self.spare = old_pairs;
        }

        // The last update's lists are read while the new ones are written (their buffers
        // taken over from the update before).
        std::mem::swap(&mut self.contacts, &mut self.previous.0);
        std::mem::swap(&mut self.slots, &mut self.previous.1);
        std::mem::swap(&mut self.bases, &mut self.previous.2);
        let input = PairInputs {
            colliders,
            bodies,
            settings,
            filter,
            dt,
            turn: TurnBound::new(settings.reuse_angular),
            previous: (&self.previous.0, &self.previous.1, &self.previous.2),
        };
        let min_cos = settings.frame_angle_tolerance.cos();
        let n = self.pairs.len();
        let per_part = n.div_ceil(runner.parts(n).clamp(1, MAX_PARTS)).max(1);
        let count = n.div_ceil(per_part).max(1);
        if self.parts.len() < count {
            self.parts.resize_with(count, Part::default);
        }
        // The first part writes into the narrow phase's own lists (no copy for one part).
        let first = &mut self.parts[0];
        std::mem::swap(&mut first.contacts, &mut self.contacts);
        std::mem::swap(&mut first.slots, &mut self.slots);
        std::mem::swap(&mut first.touching, &mut self.touching_scratch);
        std::mem::swap(&mut first.overlaps, &mut self.overlaps_scratch);
        for part in &mut self.parts[..count] {
            part.clear();
        }
        if count == 1 {
            self.parts[0].update(0, &mut self.pairs, &input, min_cos);
        } else {
            // Each part's pairs and outputs.
            let mut each = self.pairs.chunks_mut(per_part).zip(self.parts.iter_mut());
            let mut work: [_; MAX_PARTS] = std::array::from_fn(|_| each.next());
            run_parts(runner, &mut work[..count], &|i, work| {
                if let Some((states, part)) = work {
                    part.update(i as u32, states, &input, min_cos);
                }
            });
        }

        // Join the parts in order: the slots of later parts count pairs from the first kept
        // pair of all.
        let (first, rest) = self.parts.split_at_mut(1);
        let first = &mut first[0];
        std::mem::swap(&mut first.contacts, &mut self.contacts);
        std::mem::swap(&mut first.slots, &mut self.slots);
        let mut touching = std::mem::take(&mut first.touching);
        let mut overlaps = std::mem::take(&mut first.overlaps);
        let mut stats = NarrowStats {
            candidate_pairs: pairs.len(),
            parts: count,
            ..first.stats
        };
        self.any_threshold = first.any_threshold;
        self.bases.clear();
        self.bases.push(0);
        let mut offset = first.kept;
        let mut all_kept = first.kept as usize == first.keep.len();
        for part in &rest[..count - 1] {
            self.bases.push(self.contacts.len() as u32);
            self.contacts.extend_from_slice(&part.contacts);
            self.slots.extend(part.slots.iter().map(|s| PointSlot {
                pair: s.pair + offset,
                ..*s
            }));
            touching.extend_from_slice(&part.touching);
            overlaps.extend_from_slice(&part.overlaps);
            self.any_threshold |= part.any_threshold;
            stats.manifolds += part.stats.manifolds;
            stats.manifolds_reused += part.stats.manifolds_reused;
            stats.kept_apart += part.stats.kept_apart;
            offset += part.kept;
            all_kept &= part.kept as usize == part.keep.len();
        }
        if !all_kept {
            let mut keep = self.parts[..count]
                .iter()
                .flat_map(|p| p.keep.iter().copied());
            self.pairs.retain(|_| keep.next().unwrap_or(false));
        }
        stats.contact_points = self.contacts.len();
        self.update_events(touching, bodies);
        self.update_sensor_events(overlaps, colliders, bodies);
        stats
    }

    /// Diffs the overlapping sensor pairs against the previous update's; as for contacts, a
    /// pair whose bodies are both at rest (asleep or fixed) keeps overlapping.
    fn update_sensor_events(
        &mut self,
        mut overlaps: Vec<(ColliderHandle, ColliderHandle)>,
        colliders: &ColliderSet,
        bodies: &BodySet,
    ) {
        let frozen = |&(a, b): &(ColliderHandle, ColliderHandle)| {
            let (Some(ca), Some(cb)) = (colliders.get(a), colliders.get(b)) else {
                return false;
            };
            let still = (ca.sensor || cb.sensor) && ca.groups.meets(&cb.groups);
            match (bodies.get(ca.body), bodies.get(cb.body)) {
                (Some(x), Some(y)) => still && !x.is_awake() && !y.is_awake(),
                _ => false,
            }
        };
        overlaps.extend(self.overlaps.iter().copied().filter(frozen));
        overlaps.sort_unstable();
        overlaps.dedup();
        self.sensor_events.clear();
        let events = &mut self.sensor_events;
        diff_sorted(&self.overlaps, &overlaps, |&(sensor, other), now| {
            events.push(if now {
                SensorEvent::Entered { sensor, other }
            } else {
                SensorEvent::Exited { sensor, other }
            });
        });
        self.overlaps_scratch = std::mem::replace(&mut self.overlaps, overlaps);
    }

    /// Diffs the touching body pairs against the previous update's. A pair that left the
    /// candidate list because neither body is awake any more (it fell asleep on the other, or
    /// on a fixed body) still counts as touching: sleeping does not stop a contact.
    fn update_events(&mut self, mut touching: Vec<(BodyHandle, BodyHandle)>, bodies: &BodySet) {
        let frozen = |&(a, b): &(BodyHandle, BodyHandle)| match (bodies.get(a), bodies.get(b)) {
            (Some(a), Some(b)) => !a.is_awake() && !b.is_awake(),
            _ => false,
        };
        touching.extend(self.touching.iter().copied().filter(frozen));
        touching.sort_unstable();
        touching.dedup();

        self.events.clear();
        let events = &mut self.events;
        diff_sorted(&self.touching, &touching, |&(a, b), now| {
            events.push(if now {
                CollisionEvent::Started(a, b)
            } else {
                CollisionEvent::Stopped(a, b)
            });
        });
        self.touching_scratch = std::mem::replace(&mut self.touching, touching);
    }
}

/// What [`update_pair`] reads: the world and the update's settings.
#[derive(Clone, Copy)]
struct PairInputs<'a> {
    colliders: &'a ColliderSet,
    bodies: &'a BodySet,
    settings: &'a CollideSettings,
    filter: Option<&'a PairFilter>,
    /// The step (s), finite and ≥ 0.
    dt: f32,
    /// [`CollideSettings::reuse_angular`] as a bound for [`turned_less`].
    turn: TurnBound,
    /// The last update's contacts, slots and part bases, whose impulses and preloads the
    /// points take back ([`Emitted`]).
    previous: (&'a [BodyContact], &'a [PointSlot], &'a [u32]),
}

/// Where [`update_pair`] writes: the update's outputs and scratch.
struct PairOutputs<'a> {
    /// The part's index ([`Emitted::part`]).
    part: u32,
    contacts: &'a mut Vec<BodyContact>,
    slots: &'a mut Vec<PointSlot>,
    touching: &'a mut Vec<(BodyHandle, BodyHandle)>,
    overlaps: &'a mut Vec<(ColliderHandle, ColliderHandle)>,
    any_threshold: &'a mut bool,
    stats: &'a mut NarrowStats,
    old_points: &'a mut Vec<(PointKey, PointData)>,
    /// Cosine of [`CollideSettings::frame_angle_tolerance`].
    min_cos: f32,
}

/// One pair's part of [`NarrowPhase::update_swept`]: its manifolds reused or recomputed and
/// its contacts appended to `out`, as the pair at `pair_index` of the new pair list. Returns
/// whether the pair's state is kept (false for a pair whose colliders or bodies are gone,
/// whose state is not finite, or that its groups or the filter exclude, and for a sensor
/// pair, which only records whether it overlaps).
fn update_pair(
    state: &mut PairState,
    pair_index: u32,
    input: &PairInputs<'_>,
    out: &mut PairOutputs<'_>,
) -> bool {
    let PairInputs {
        colliders,
        bodies,
        settings,
        filter,
        dt,
        ..
    } = *input;
    let (contacts, slots, bases) = input.previous;
    state.take_back(contacts, slots, bases);
    let start = out.contacts.len();
    let (Some(c1), Some(c2)) = (colliders.get(state.pair.0), colliders.get(state.pair.1)) else {
        return false;
    };
    let (Some(b1), Some(b2)) = (bodies.get(c1.body), bodies.get(c2.body)) else {
        return false;
    };
    let pose1 = c1.world_pose(b1);
    let pose2 = c2.world_pose(b2);
    // (Read from the bodies where the colliders sit at their centres of mass: the poses just
    // built are written to memory in pieces, and reading them back whole stalls the store
    // forward; `perf` put 17% of a resting pyramid's narrow phase on it, and in a loop of
    // updates alone reading the bodies took 3–6% off each.)
    let at_centres = c1.local_pose() == Pose::IDENTITY && c2.local_pose() == Pose::IDENTITY;
    let finite = if at_centres {
        b1.position.is_finite()
            && b1.orientation.is_finite()
            && b2.position.is_finite()
            && b2.orientation.is_finite()
    } else {
        pose1.is_finite() && pose2.is_finite()
    };
    if !finite {
        // Non-finite state is the facade's to report; it must not reach parry.
        return false;
    }
    if !c1.groups.meets(&c2.groups) || filter.is_some_and(|f| !f(c1, c2)) {
        return false;
    }
    let pos12 = if at_centres {
        relative_pose((b1.position, b1.orientation), (b2.position, b2.orientation))
    } else {
        relative_pose(
            (pose1.translation, pose1.rotation),
            (pose2.translation, pose2.rotation),
        )
    };
    if c1.sensor || c2.sensor {
        // No contact: only whether they overlap (an unsupported pair of shapes never
        // does).
        let overlapping = parry3d::query::intersection_test(
            &Pose::IDENTITY,
            c1.shape.as_ref(),
            &pos12,
            c2.shape.as_ref(),
        )
        .is_ok_and(|i| i.intersecting);
        if overlapping {
            out.overlaps.push(if c1.sensor {
                (state.pair.0, state.pair.1)
            } else {
                (state.pair.1, state.pair.0)
            });
        }
        return false;
    }
    let material = Material::mix(c1.material, c2.material);
    let prediction = pair_prediction(
        c1,
        b1,
        c2,
        b2,
        settings.prediction,
        dt,
        material.restitution,
    );
    let reused = reusable(
        state,
        &pos12,
        (shape_id(c1), shape_id(c2)),
        settings,
        input.turn,
        prediction,
    );
    if reused {
        for m in &mut state.manifolds {
            m.update_separations(&manifold_pos12(m, &pos12));
        }
        out.stats.manifolds_reused += state
            .manifolds
            .iter()
            .filter(|m| !m.points.is_empty())
            .count();
    } else if state.apart.is_some_and(|axis| {
        gap_along(c1, c2, &pos12, axis).is_some_and(|gap| gap > prediction + APART_SLACK)
    }) {
        // Still apart along the same direction, by more than the prediction distance: no
        // contact query can find a point. The pair keeps its empty manifolds (a kept direction
        // is only set by a query that found no point, and only a query adds points), and with
        // nothing to emit they are not even read (in a rain, the read was a cache miss a pair).
        debug_assert!(
            state.manifolds.iter().all(|m| m.points.is_empty()),
            "a pair kept apart with contact points"
        );
        out.stats.kept_apart += 1;
        *out.any_threshold |=
            c1.force_event_threshold.is_some() || c2.force_event_threshold.is_some();
        state.emitted = None;
        return true;
    } else {
        compute(state, c1, c2, &pos12, prediction, out.old_points);
    }
    *out.any_threshold |= c1.force_event_threshold.is_some() || c2.force_event_threshold.is_some();
    // A is the dynamic body when the other is fixed or kinematic; else collider 1's body.
    let flip = b1.is_immovable() && !b2.is_immovable();
    // Where the manifolds were kept and neither collider turned since every point's frame was
    // last checked, the held frames stand and no fresh one is built; else they are checked
    // now.
    let held_only =
        reused && frames_still_held(state, (&pose1, &pose2, flip), settings, input.turn);
    if !held_only {
        state.checked = Some((pose1, pose2, flip));
    }
    let (a, b) = if flip {
        (c2.body, c1.body)
    } else {
        (c1.body, c2.body)
    };
    let (body_a, body_b) = if flip { (b2, b1) } else { (b1, b2) };
    let tolerance = frame_tolerance(settings.frame_tolerance, c1, c2);
    let mut touches = false;
    for (mi, m) in state.manifolds.iter_mut().enumerate() {
        // (A normal that cannot be normalised gives no contact: the path below.)
        if held_only && !m.points.is_empty() && m.local_n1.try_normalize().is_some() {
            out.stats.manifolds += 1;
            // Every point has a held frame and lies within the prediction distance
            // (`frames_still_held`): all are emitted, each list extended once per manifold
            // (a resting 3D pyramid's narrow phase: about 7% less than a push per point).
            touches |= m.points.iter().any(|pt| pt.dist <= 0.0);
            let (at_a, at_b) = (body_a.position, body_b.position);
            out.contacts.extend(m.points.iter().map(|pt| {
                debug_assert!(pt.data.frame.is_some(), "a held-only point without a frame");
                let frame = pt.data.frame.unwrap_or(Frame {
                    normal: Vec3::Y,
                    r_a: Vec3::ZERO,
                    r_b: Vec3::ZERO,
                });
                body_contact((a, b), (at_a, at_b), frame, pt, &material)
            }));
            out.slots
                .extend((0..m.points.len() as u32).map(|point| PointSlot {
                    pair: pair_index,
                    manifold: mi as u32,
                    point,
                }));
            continue;
        }
        let w1 = m.subshape_pos1().map_or(pose1, |sub| pose1 * sub);
        let w2 = m.subshape_pos2().map_or(pose2, |sub| pose2 * sub);
        // parry's normal points out of shape 1, toward shape 2.
        let Some(n1) = (w1.rotation * m.local_n1).try_normalize() else {
            continue;
        };
        if m.points.is_empty() {
            continue;
        }
        out.stats.manifolds += 1;
        let normal = if flip { n1 } else { -n1 };
        for (pi, pt) in m.points.iter_mut().enumerate() {
            let p1 = w1 * pt.local_p1;
            let p2 = w2 * pt.local_p2;
            touches |= pt.dist <= 0.0;
            // Each body's lever arm ends on its own surface: from the midpoint, a deep
            // contact's lever arm could reach outside a thin body and spin it about
            // its axis (a 0.09 m cylinder 1 m inside a capsule gained 42% of its
            // energy in one step).
            let (on_a, on_b) = if flip { (p2, p1) } else { (p1, p2) };
            if pt.dist > settings.prediction {
                // Beyond the prediction distance only what closes within the step.
                let closing = (body_b.linear_velocity
                    + body_b.angular_velocity.cross(on_b - body_b.position)
                    - body_a.linear_velocity
                    - body_a.angular_velocity.cross(on_a - body_a.position))
                .dot(normal);
                if pt.dist > settings.prediction + closing.max(0.0) * dt {
                    continue;
                }
            }
            let fresh = Frame {
                normal,
                r_a: on_a - body_a.position,
                r_b: on_b - body_b.position,
            };
            let frame = Frame::hold(&mut pt.data.frame, fresh, tolerance, out.min_cos);
            let slot = PointSlot {
                pair: pair_index,
                manifold: mi as u32,
                point: pi as u32,
            };
            push_contact(out, slot, (a, b), (body_a, body_b), frame, pt, &material);
        }
    }
    if touches {
        out.touching.push(ordered(c1.body, c2.body));
    }
    let count = out.contacts.len() - start;
    state.emitted = (count > 0).then_some(Emitted {
        part: out.part,
        first: start as u32,
        count: count as u32,
    });
    true
}

/// The largest fraction of the smaller collider's [`Collider::reach_radius`] by which a held
/// lever arm may lag the fresh one ([`frame_tolerance`]).
const FRAME_TOLERANCE_REACH: f32 = 0.05;

/// How far a pair's held lever arms may lag the fresh ones (m): `tolerance`
/// ([`CollideSettings::frame_tolerance`]), but at most [`FRAME_TOLERANCE_REACH`] of the smaller
/// collider's reach radius, so that holding means the same at every size.
///
/// A held point keeps its lever arms while its depth is the fresh point's, so the contact
/// pushes at one place with the depth of another up to the tolerance away. On a face that
/// tilts by θ the two depths differ by up to θ·tolerance, while what rights the face, the
/// difference of its points' depths, is θ times its width: with the tolerance a small fraction
/// of the body the error is a small fraction of the restoring push, but with 4 mm held on a
/// cylinder of 2 mm radius (whose parry face points turn around its rim with the direction of
/// a tilt of 10⁻⁵ rad, keeping their feature ids) the push landed at the points' old places
/// with the depths of the new, and the cylinder resting flat on the ground began to spin at
/// step 1, its tilt growing 1.5 times a step until it rolled away (`tests/stability.rs`,
/// `small_shapes_resting_flat_stay_put`). Bodies of 0.1 m and larger keep the full 4 mm
/// (0.05 × 0.087 m for a 0.1 m cube).
fn frame_tolerance(tolerance: f32, c1: &Collider, c2: &Collider) -> f32 {
    tolerance.min(FRAME_TOLERANCE_REACH * c1.reach_radius().min(c2.reach_radius()))
}

/// Whether every point's held frame of `state` still stands without a fresh one being built:
/// the frames were checked at poses (`PairState::checked`) from which neither collider has
/// turned by `settings.reuse_angular` or more, with the same body as A, and every point has a
/// held frame and lies within the prediction distance (a point beyond it is decided by its
/// closing speed at its fresh position). Only the turns matter: a fresh lever arm runs from
/// the body's centre of mass to a point fixed on the body, and the normal turns with collider
/// 1, so a frame built now would differ from the checked one by at most the turn times the
/// lever arm (0.07 mm for a 0.7 m arm at 10⁻⁴ rad, where frames are held within 4 mm).
fn frames_still_held(
    state: &PairState,
    (pose1, pose2, flip): (&Pose, &Pose, bool),
    settings: &CollideSettings,
    turn: TurnBound,
) -> bool {
    let Some((checked1, checked2, checked_flip)) = &state.checked else {
        return false;
    };
    *checked_flip == flip
        && settings.frame_tolerance > 0.0
        && turned_less(checked1.rotation, pose1.rotation, turn)
        && turned_less(checked2.rotation, pose2.rotation, turn)
        && state.manifolds.iter().all(|m| {
            m.points
                .iter()
                .all(|p| p.data.frame.is_some() && p.dist <= settings.prediction)
        })
}

/// A bound on a turn for [`turned_less`]: sin²(angle/2) of its angle, worked out once per
/// update rather than three times per pair.
#[derive(Clone, Copy, Debug)]
struct TurnBound(f32);

impl TurnBound {
    fn new(angle: f32) -> Self {
        let s = (0.5 * angle).sin();
        Self(s * s)
    }
}

/// Whether the unit rotation `now` is less than the bound's angle from `before`: compared
/// through the sine of half the turn, the vector part of the relative rotation, which f32
/// resolves down to about 10⁻⁷ rad; through the cosine (`Quat::angle_between`) it reads any
/// turn below about 5·10⁻⁴ rad as none.
fn turned_less(before: Quat, now: Quat, bound: TurnBound) -> bool {
    (before.conjugate() * now).xyz().length_squared() < bound.0
}

/// Appends the contact of point `pt` with frame `frame` between bodies A and B, and where
/// it lives (`slot`).
fn push_contact(
    out: &mut PairOutputs<'_>,
    slot: PointSlot,
    (a, b): (BodyHandle, BodyHandle),
    (body_a, body_b): (&jostle_body::RigidBody, &jostle_body::RigidBody),
    frame: Frame,
    pt: &parry3d::query::TrackedContact<PointData>,
    material: &Material,
) {
    out.contacts.push(body_contact(
        (a, b),
        (body_a.position, body_b.position),
        frame,
        pt,
        material,
    ));
    out.slots.push(slot);
}

/// The contact of point `pt` with frame `frame` between bodies A and B, whose centres are at
/// `at_a` and `at_b`.
#[inline(always)]
fn body_contact(
    (a, b): (BodyHandle, BodyHandle),
    (at_a, at_b): (Vec3, Vec3),
    frame: Frame,
    pt: &parry3d::query::TrackedContact<PointData>,
    material: &Material,
) -> BodyContact {
    BodyContact {
        a,
        b,
        point: at_a + frame.r_a,
        point_b: at_b + frame.r_b,
        normal: frame.normal,
        penetration: -pt.dist,
        friction: material.friction,
        dynamic_friction: material.dynamic_friction,
        restitution: material.restitution,
        impulse: pt.data.impulse,
        preload: pt.data.preload,
    }
}

/// Walks two sorted, deduplicated lists together: `f(item, false)` for each item only in
/// `old`, `f(item, true)` for each only in `new`, in order.
fn diff_sorted<T: Ord>(old: &[T], new: &[T], mut f: impl FnMut(&T, bool)) {
    let (mut i, mut j) = (0, 0);
    loop {
        match (old.get(i), new.get(j)) {
            (Some(o), Some(n)) if o == n => {
                i += 1;
                j += 1;
            }
            (Some(o), Some(n)) if o < n => {
                f(o, false);
                i += 1;
            }
            (Some(o), None) => {
                f(o, false);
                i += 1;
            }
            (_, Some(n)) => {
                f(n, true);
                j += 1;
            }
            (None, None) => break,
        }
    }
}

fn ordered(a: BodyHandle, b: BodyHandle) -> (BodyHandle, BodyHandle) {
    if a <= b { (a, b) } else { (b, a) }
}

fn shape_id(collider: &Collider) -> usize {
    std::sync::Arc::as_ptr(&collider.shape.0) as *const () as usize
}

/// Whether the pair's manifolds can be kept: computed before, for the same shapes and
/// prediction, and the relative pose moved less than the reuse tolerances since.
fn reusable(
    state: &PairState,
    pos12: &Pose,
    shapes: (usize, usize),
    settings: &CollideSettings,
    turn: TurnBound,
    prediction: f32,
) -> bool {
    state.computed.as_ref().is_some_and(|c| {
        c.prediction == prediction
            && c.shapes == shapes
            && c.pos12.translation.distance(pos12.translation) < settings.reuse_linear
            && turned_less(c.pos12.rotation, pos12.rotation, turn)
    })
}

/// The distance up to which a pair's contacts are looked for ahead of a step of `dt`: the
/// prediction distance, grown by how far the two bodies can close within the step at their
/// current velocities (|v₁ − v₂|·dt, plus [`Collider::turn_reach`] of each) when that is more
/// than half the prediction distance (slower pairs keep the plain distance, and with it their
/// reusable manifolds).
///
/// The growth is at most the smaller collider's [`Collider::reach_radius`]. Two kinds of
/// pair keep the plain distance whatever their speed:
/// - a pair with a body whose CCD is off ([`CcdMode::Off`]: it may tunnel, by request);
/// - a pair that bounces (combined restitution above 0). A speculative contact stops the
///   bodies where they meet and the bounce is applied at the end of the step, so the time
///   left after the impact is lost: on `assets/analytic_bounce.ron` the apexes fell from
///   3.696, 2.550, 1.797 m to 3.631, 2.420, 1.658 (closed form 3.700, 2.548, 1.811).
fn pair_prediction(
    c1: &Collider,
    b1: &jostle_body::RigidBody,
    c2: &Collider,
    b2: &jostle_body::RigidBody,
    prediction: f32,
    dt: f32,
    restitution: f32,
) -> f32 {
    if dt == 0.0 || restitution > 0.0 || b1.ccd == CcdMode::Off || b2.ccd == CcdMode::Off {
        return prediction;
    }
    let reach = (b1.linear_velocity - b2.linear_velocity).length() * dt
        + c1.turn_reach(b1, dt)
        + c2.turn_reach(b2, dt);
    if reach.is_finite() && reach > 0.5 * prediction {
        // At most the smaller collider's own radius: a body faster than that per step is
        // CCD's to sweep, and a contact with a gap larger than the body can stop it in front
        // of a face it would have passed beside.
        prediction + reach.min(c1.reach_radius().min(c2.reach_radius()))
    } else {
        prediction
    }
}

/// `pose1.inv_mul(pose2)` from the poses' parts: the pose of frame 2 in frame 1, inlined (out
/// of line, `inv_mul` read its arguments back from memory just after they were written in
/// narrower pieces, a stalled store forward).
#[inline(always)]
fn relative_pose((t1, r1): (Vec3, Quat), (t2, r2): (Vec3, Quat)) -> Pose {
    let inv_rot1 = r1.inverse();
    Pose::from_parts(inv_rot1 * (t2 - t1), inv_rot1 * r2)
}

/// The relative pose of a manifold's two sub-shapes (compound parts carry their own frames).
pub(crate) fn manifold_pos12<D>(m: &ContactManifold<(), D>, pos12: &Pose) -> Pose {
    if m.subshape_pos1().is_none() && m.subshape_pos2().is_none() {
        return *pos12;
    }
    let sub1 = m.subshape_pos1().copied().unwrap_or(Pose::IDENTITY);
    let sub2 = m.subshape_pos2().copied().unwrap_or(Pose::IDENTITY);
    sub1.inv_mul(&(pos12 * sub2))
}

/// A contact point's identity across recomputations: its sub-shapes and feature ids.
type PointKey = (u32, u32, PackedFeatureId, PackedFeatureId);

/// Recomputes a pair's manifolds with parry, reduces each to four points and carries the
/// impulses over by feature id.
/// `old` is scratch for the pair's points before the update, kept by the caller so that no
/// recomputed pair allocates.
fn compute(
    state: &mut PairState,
    c1: &Collider,
    c2: &Collider,
    pos12: &Pose,
    prediction: f32,
    old: &mut Vec<(PointKey, PointData)>,
) {
    old.clear();
    old.extend(state.manifolds.iter().flat_map(|m| {
        m.points
            .iter()
            .map(move |p| ((m.subshape1, m.subshape2, p.fid1, p.fid2), p.data))
    }));
    let PairState {
        manifolds,
        workspace,
        scaled,
        ..
    } = state;
    let mut result = query(pos12, c1, c2, prediction, manifolds, workspace, scaled);
    if result.is_ok()
        && manifolds
            .iter()
            .any(|m| misses_a_deeper_point(m, c1, c2, pos12))
    {
        for m in manifolds.iter_mut() {
            m.mark_shapes_deformed();
        }
        result = query(pos12, c1, c2, prediction, manifolds, workspace, scaled);
    }
    if result.is_err() {
        // An unsupported pair (two half-spaces): no contact, by definition of the shapes.
        state.manifolds.clear();
    }
    cross_check_depth(state, c1, c2, pos12, prediction);
    for m in &mut state.manifolds {
        // parry's polygonal clipping can return points of a feature far beyond the prediction
        // distance (a capsule's far end under a box face, for one); they are no contacts.
        m.points.retain(|p| p.dist <= prediction);
        reduce_manifold(&mut m.points, m.local_n1);
        let (s1, s2) = (m.subshape1, m.subshape2);
        for p in &mut m.points {
            let key = (s1, s2, p.fid1, p.fid2);
            // The impulse and the held frame follow the point's features.
            p.data = old
                .iter()
                .find(|(k, _)| *k == key)
                .map_or(PointData::default(), |(_, d)| *d);
        }
    }
    state.computed = Some(Computed {
        pos12: *pos12,
        prediction,
        shapes: (shape_id(c1), shape_id(c2)),
    });
    state.apart = if state.manifolds.iter().all(|m| m.points.is_empty()) {
        separating_axis(state, c1, c2, pos12, prediction)
    } else {
        None
    };
}

/// parry's contact manifolds of `c1` and `c2` at `pos12` (`c2`'s pose in `c1`'s frame),
/// updated in `manifolds` from what they hold: small shapes clipped scaled up
/// ([`clip_scale`]), with the pair's scaled copies of hulls and compounds kept in `scaled`;
/// a pair of flat-faced shapes' answer checked against their separating axes
/// ([`polytope::check`]). An error for an unsupported pair of shapes.
fn query(
    pos12: &Pose,
    c1: &Collider,
    c2: &Collider,
    prediction: f32,
    manifolds: &mut Vec<Manifold>,
    workspace: &mut Option<ContactManifoldsWorkspace>,
    scaled: &mut Option<Box<ScaledShapes>>,
) -> Result<(), parry3d::query::Unsupported> {
    let (shape1, shape2) = (&*c1.shape.0, &*c2.shape.0);
    let mut scale = c1
        .clip_size
        .zip(c2.clip_size)
        .map_or(1.0, |(size1, size2)| clip_scale(size1.min(size2)));
    let boxes = if scale == 1.0 {
        None
    } else {
        ClipShape::of(shape1).zip(ClipShape::of(shape2))
    };
    if scale != 1.0 && boxes.is_none() {
        // Hulls and compounds are scaled once for the pair, not at every query.
        let ids = (shape_id(c1), shape_id(c2));
        if scaled.as_ref().is_none_or(|s| s.ids != ids) {
            *scaled = scaled_shape(shape1, scale)
                .zip(scaled_shape(shape2, scale))
                .map(|shapes| Box::new(ScaledShapes { ids, shapes }));
        }
        if scaled.is_none() {
            scale = 1.0;
        }
    }
    if scale == 1.0 {
        DefaultQueryDispatcher
            .contact_manifolds(pos12, shape1, shape2, prediction, manifolds, workspace)?;
        polytope::check(pos12, shape1, shape2, prediction, manifolds);
        crate::mesh_patch::refine(pos12, shape1, shape2, prediction, manifolds);
        Ok(())
    } else {
        // Small shapes are clipped scaled up, their points scaled back.
        let scaled_pose = Pose::from_parts(pos12.translation * scale, pos12.rotation);
        scale_manifolds(manifolds, scale);
        // Boxes, cylinders and capsules are copied scaled on the stack.
        let copies = boxes.map(|(s1, s2)| (s1.scaled(scale), s2.scaled(scale)));
        let (scaled1, scaled2) = match (&copies, &*scaled) {
            (Some((s1, s2)), _) => (s1.shape(), s2.shape()),
            (None, Some(s)) => (&*s.shapes.0.0, &*s.shapes.1.0),
            (None, None) => unreachable!("scale is 1 without scaled copies"),
        };
        let result = DefaultQueryDispatcher.contact_manifolds(
            &scaled_pose,
            scaled1,
            scaled2,
            prediction * scale,
            manifolds,
            workspace,
        );
        if result.is_ok() {
            polytope::check(
                &scaled_pose,
                scaled1,
                scaled2,
                prediction * scale,
                manifolds,
            );
        }
        scale_manifolds(manifolds, scale.recip());
        result
    }
}

/// How much deeper (m) than a manifold's deepest point either shape's deepest point along
/// its normal may reach before the manifold is computed again ([`misses_a_deeper_point`]):
/// half the default prediction distance. At 1 mm the check also overruled parry's coherence
/// wherever a kept normal had turned a milliradian across a unit box, and the collapse of
/// `assets/pyramid_heavy_top.ron` stepped at 1 s under the Millington resolver took another
/// course, one that gained 38% of its energy (benches/RESULTS.md, "parry's coherence and a
/// box turning about an edge").
const MISSED_DEPTH: f32 = 1e-2;

/// Whether the manifold `m` of `c1` and `c2` at `pos12` misses overlap: either shape's (or,
/// for a composite shape, the manifold's part's) support point along the manifold's normal
/// lies more than [`MISSED_DEPTH`] deeper past the other's contact plane than the manifold's
/// deepest point. A shape with no support map (a half-space, a part that is no convex shape)
/// is not checked.
///
/// parry keeps a manifold's points (refreshing their separations only) while its normal turns
/// less than 1° and no point moves 1 mm. Turning about an edge, the points on the edge do not
/// move, and the far side comes into contact unseen: a 10 m box of a column rocking on an
/// edge of the box below had its far edge 146 mm deep before parry looked again, and the
/// push-out then threw the column over (benches/RESULTS.md, "parry's coherence and a box
/// turning about an edge"). Computing every moved pair's manifold afresh instead loses the
/// points' persistence, and with it four cases of the stability family. A support point
/// beyond the other shape's face (a large box on a small one) is no overlap; such a pair is
/// computed afresh, which costs time only.
///
/// The check runs on parry's fresh answers too: for hulls and cylinders stacked exactly
/// touching, parry answered with one point and a sideways normal (a 7.5 mm hull cube on
/// another, normal along z; coins the same), and checked only where parry kept a manifold, a
/// column of five such cubes moved 1.8 mm before it was caught. Computed again (from the
/// manifold's points, `mark_shapes_deformed`), the answer is the face's four points.
/// ([`polytope::check`] now catches such answers first, in [`query`].)
fn misses_a_deeper_point(m: &Manifold, c1: &Collider, c2: &Collider, pos12: &Pose) -> bool {
    if m.points.is_empty() {
        return false;
    }
    let pos = manifold_pos12(m, pos12);
    with_part(&*c1.shape.0, m.subshape1, |s1| {
        with_part(&*c2.shape.0, m.subshape2, |s2| {
            let n = m.local_n1;
            // Shape 1's contact plane (its points' highest level along n) and shape 2's (its
            // points' lowest), in shape 1's (part's) frame.
            let plane1 = m
                .points
                .iter()
                .map(|p| p.local_p1.dot(n))
                .fold(f32::MIN, f32::max);
            let plane2 = m
                .points
                .iter()
                .map(|p| (pos * p.local_p2).dot(n))
                .fold(f32::MAX, f32::min);
            let reach2 = plane1 - s2.support_point(&pos, -n).dot(n);
            let reach1 = s1.local_support_point(n).dot(n) - plane2;
            reach1.max(reach2) > max_penetration(std::slice::from_ref(m)) + MISSED_DEPTH
        })
    })
}

/// `f` of `shape`'s support map, or of its part `part`'s for a composite shape; false where
/// there is none.
fn with_part(
    shape: &dyn Shape,
    part: u32,
    f: impl FnOnce(&dyn parry3d::shape::SupportMap) -> bool,
) -> bool {
    match shape.as_composite_shape() {
        Some(composite) => {
            let mut f = Some(f);
            let mut answer = false;
            composite.map_part_at(part, &mut |_, shape, _| {
                if let (Some(support), Some(f)) = (shape.as_support_map(), f.take()) {
                    answer = f(support);
                }
            });
            answer
        }
        None => shape.as_support_map().is_some_and(f),
    }
}

/// The size (largest half dimension, m; [`clip_size`]) at or above which a pair of shapes
/// is clipped at its own size ([`clip_scale`]).
const CLIP_SIZE: f32 = 0.05;

/// The factor by which a pair of boxes, cylinders, capsules, convex hulls or compounds is
/// scaled for parry's clipping of their faces, from the smaller of their sizes
/// ([`clip_size`]): 1 at [`CLIP_SIZE`] or above, else the least power of four that brings it
/// there. A power of four scales every operation exactly in f32 (square roots included), so
/// the scaled result is the exact scaling of one at the shapes' own size but for parry's
/// absolute tolerances.
///
/// Those tolerances are why: parry's 2D edge intersection takes two edges as parallel when
/// |d₁|²·|d₂|²·sin²θ falls below f32's epsilon, so edges shorter than about 1.9 cm never
/// cross, and its test of a corner inside the other face loses corners on shared edges. Two
/// equal boxes of 1 cm stacked a little apart then touched at two diagonal corners only,
/// about which the upper one turned freely and toppled (and parry's coherence kept that
/// manifold until a point moved 1 mm); two coins of 1 cm radius fell over. At 5 cm (edges of
/// 0.1 m, the smallest boxes of the stability family) edges within about 2° count as
/// parallel: for clipping that is wanted, since where two nearly parallel edges cross moves
/// along them by their offset over their angle. Scaled further, to 0.5 m, such crossings
/// jumped along the edges of swaying boxes, and a column of ten 2 cm cubes fell.
fn clip_scale(size: f32) -> f32 {
    let mut scale = 1.0;
    // At most 4²⁰ (10¹²), so that the scaled extents of a degenerate shape stay finite.
    for _ in 0..20 {
        if size * scale >= CLIP_SIZE {
            break;
        }
        scale *= 4.0;
    }
    scale
}

/// A shape whose contacts parry finds by clipping polygonal features (a box; a cylinder, whose
/// caps it clips as squares; a capsule, whose segment it clips against a face), copied so
/// that it can be scaled ([`clip_scale`]).
#[derive(Clone, Copy)]
enum ClipShape {
    Cuboid(Cuboid),
    Cylinder(Cylinder),
    Capsule(Capsule),
}

impl ClipShape {
    fn of(shape: &dyn Shape) -> Option<Self> {
        shape
            .as_cuboid()
            .map(|c| Self::Cuboid(*c))
            .or_else(|| shape.as_cylinder().map(|c| Self::Cylinder(*c)))
            .or_else(|| shape.as_capsule().map(|c| Self::Capsule(*c)))
    }

    /// The largest half dimension (m): the largest half extent of a box, the larger of a
    /// cylinder's half height and radius, a capsule's half length with its radius. The
    /// largest, not the smallest: a coin's caps are clipped by edges of its radius's length,
    /// whatever its thickness.
    fn size(&self) -> f32 {
        match self {
            Self::Cuboid(c) => c.half_extents.max_element(),
            Self::Cylinder(c) => c.half_height.max(c.radius),
            Self::Capsule(c) => c.half_height() + c.radius,
        }
    }

    fn scaled(self, scale: f32) -> Self {
        match self {
            Self::Cuboid(c) => Self::Cuboid(Cuboid::new(c.half_extents * scale)),
            Self::Cylinder(c) => {
                Self::Cylinder(Cylinder::new(c.half_height * scale, c.radius * scale))
            }
            Self::Capsule(c) => Self::Capsule(Capsule::new(
                c.segment.a * scale,
                c.segment.b * scale,
                c.radius * scale,
            )),
        }
    }

    fn shape(&self) -> &dyn Shape {
        match self {
            Self::Cuboid(c) => c,
            Self::Cylinder(c) => c,
            Self::Capsule(c) => c,
        }
    }
}

/// Scales every point of `manifolds` (both local points and the separation), and the
/// positions of composite shapes' parts, by `scale`.
fn scale_manifolds(manifolds: &mut [Manifold], scale: f32) {
    for m in manifolds {
        for p in &mut m.points {
            p.local_p1 *= scale;
            p.local_p2 *= scale;
            p.dist *= scale;
        }
        if let Some(poses) = &mut m.subshape_poses {
            for pose in [&mut poses.pos1, &mut poses.pos2].into_iter().flatten() {
                pose.translation *= scale;
            }
        }
    }
}

/// The size that decides how a shape is clipped ([`clip_scale`]): a box's, a cylinder's or a
/// capsule's ([`ClipShape::size`]), half the largest side of a convex hull's bounding box, the
/// smallest of a compound's parts; `None` for shapes parry does not clip by features (balls,
/// half-spaces, meshes), or which `scaled_shape` cannot scale. Each collider keeps its own
/// (`Collider::clip_size`).
pub(crate) fn clip_size(shape: &dyn Shape) -> Option<f32> {
    if let Some(s) = ClipShape::of(shape) {
        return Some(s.size());
    }
    if shape.as_convex_polyhedron().is_some() {
        return Some(shape.compute_local_aabb().half_extents().max_element());
    }
    let parts = shape.as_compound()?.shapes();
    if !parts.iter().all(|(_, part)| scalable(&*part.0)) {
        return None;
    }
    parts
        .iter()
        .filter_map(|(_, part)| clip_size(&*part.0))
        .min_by(f32::total_cmp)
}

/// Whether [`scaled_shape`] can scale `shape`.
fn scalable(shape: &dyn Shape) -> bool {
    ClipShape::of(shape).is_some()
        || shape.as_ball().is_some()
        || shape.as_convex_polyhedron().is_some()
        || shape
            .as_compound()
            .is_some_and(|c| c.shapes().iter().all(|(_, part)| scalable(&*part.0)))
}

/// A copy of `shape` scaled by `scale`: balls, boxes, capsules, cylinders, convex hulls and
/// compounds of them; `None` for any other shape.
fn scaled_shape(shape: &dyn Shape, scale: f32) -> Option<SharedShape> {
    if let Some(s) = ClipShape::of(shape) {
        return Some(match s.scaled(scale) {
            ClipShape::Cuboid(c) => SharedShape::new(c),
            ClipShape::Cylinder(c) => SharedShape::new(c),
            ClipShape::Capsule(c) => SharedShape::new(c),
        });
    }
    if let Some(ball) = shape.as_ball() {
        return Some(SharedShape::ball(ball.radius * scale));
    }
    if let Some(hull) = shape.as_convex_polyhedron() {
        return hull
            .clone()
            .scaled(Vec3::splat(scale))
            .map(SharedShape::new);
    }
    let parts = shape.as_compound()?.shapes();
    let scaled = parts
        .iter()
        .map(|(pose, part)| {
            let pose = Pose::from_parts(pose.translation * scale, pose.rotation);
            scaled_shape(&*part.0, scale).map(|part| (pose, part))
        })
        .collect::<Option<Vec<_>>>()?;
    Some(SharedShape::compound(scaled))
}

/// The gap (m) between two convex shapes along the unit direction `axis` of collider 1's
/// frame: how far the nearest point of shape 2 lies beyond the farthest of shape 1 along it,
/// at the relative pose `pos12`. Every point of shape 2 is at least that far from every point
/// of shape 1 (their distance is at least its projection on the axis), so a gap above the
/// prediction distance proves that the pair has no contact. `None` unless both shapes have a
/// support map (half-spaces and compounds do not).
fn gap_along(c1: &Collider, c2: &Collider, pos12: &Pose, axis: Vec3) -> Option<f32> {
    let s1 = c1.shape.as_support_map()?;
    let s2 = c2.shape.as_support_map()?;
    Some(polytope::separation(s1, s2, pos12, axis))
}

/// How much further apart than the prediction distance a pair's shapes must lie along its
/// kept direction for its contact query to be skipped (m): the rounding of two support points
/// a few metres from the origin, so that the skip never depends on it.
const APART_SLACK: f32 = 1e-5;

/// For a pair whose contact query found nothing: a direction of collider 1's frame along
/// which the shapes lie further apart than `prediction`, to skip the query in the next
/// updates while they still do ([`gap_along`]). Two candidates are tried: the normal the
/// query left in the manifold (parry keeps the last separating direction of its GJK there)
/// and the line from collider 1's origin to collider 2's. `None` when neither separates the
/// shapes by more than `prediction` (or the shapes have no support maps).
///
/// In a rain of 1,000 mixed shapes about half of the pairs whose query runs in a step find
/// nothing, at about 400 ns each; two support points cost a fraction of that.
fn separating_axis(
    state: &PairState,
    c1: &Collider,
    c2: &Collider,
    pos12: &Pose,
    prediction: f32,
) -> Option<Vec3> {
    let cached = state
        .manifolds
        .first()
        .and_then(|m| m.local_n1.try_normalize());
    let centres = pos12.translation.try_normalize();
    [cached, centres]
        .into_iter()
        .flatten()
        .filter_map(|axis| Some((axis, gap_along(c1, c2, pos12, axis)?)))
        .filter(|&(_, gap)| gap > prediction + APART_SLACK)
        .max_by(|x, y| x.1.total_cmp(&y.1))
        .map(|(axis, _)| axis)
}

/// The deepest penetration a manifold list reports (−∞ when it has no point).
fn max_penetration(manifolds: &[Manifold]) -> f32 {
    manifolds
        .iter()
        .flat_map(|m| &m.points)
        .map(|p| -p.dist)
        .fold(f32::NEG_INFINITY, f32::max)
}

/// An upper bound of the penetration depth of two convex shapes: their overlap along the line
/// joining their origins, and along the normal of the deepest manifold (the depth is the
/// overlap along the *best* axis, so along any axis the overlap bounds it from above; a
/// reported normal through which the shapes overlap less than the reported depth is wrong).
/// `None` when a shape has no support map.
fn depth_bound(c1: &Collider, c2: &Collider, pos12: &Pose, manifolds: &[Manifold]) -> Option<f32> {
    // The overlap along either direction of a line is minus the gap along it.
    let overlap = |u: Vec3| -> Option<f32> {
        let along = -gap_along(c1, c2, pos12, u)?;
        let against = -gap_along(c1, c2, pos12, -u)?;
        Some(along.min(against))
    };
    let deepest = manifolds
        .iter()
        .map(|m| (m, max_penetration(std::slice::from_ref(m))))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .and_then(|(m, _)| m.local_n1.try_normalize());
    let along_normal = match deepest {
        Some(n) => Some(overlap(n)?),
        None => None,
    };
    let along_centres = match pos12.translation.try_normalize() {
        Some(u) => Some(overlap(u)?),
        None => None,
    };
    match (along_centres, along_normal) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// How far (m) a reported depth may exceed its bound ([`depth_bound`]) before
/// [`cross_check_depth`] repeats the query (besides 1% of the bound).
const DEPTH_CHECK_TOLERANCE: f32 = 1e-3;

/// Works around parry 0.31's GJK/EPA on exactly aligned convex polytopes and cylinders (a stack
/// of identical hulls or cylinders): in one argument order it returns a diagonal normal and a
/// depth of ~0.7 m for a 1 cm overlap, in the other the right answer. And on manifolds
/// computed again from the pair's last ones: a tetrahedron touching the bottom edge of a wall
/// (a box 0.4 m thick) got the edge's normal reversed and a depth of 0.92 m through the wall,
/// where the same query from no manifold, and parry's `contact`, gave 7 µm of separation
/// (`tests/contacts.rs`, seen in a rain of mixed shapes); in `assets/rain_1000.ron` a
/// tetrahedron touching a wall's face was reported 0.955 m deep along a tilted normal
/// (`tests/stress.rs`). The reported depth is checked against the shapes' overlap along the
/// line of centres and along the reported normal, upper bounds of the true depth; only
/// when it exceeds it is the query repeated from no manifold, then with the shapes exchanged,
/// and the shallowest answer kept (the depth is the *smallest* separating translation).
///
/// A depth within the check's absolute tolerance ([`DEPTH_CHECK_TOLERANCE`]) is not checked:
/// it passes for any bound of 0 or more, that is whenever the shapes overlap along the line of
/// centres at all, and the errors the check is for are tenths of a metre. In two rains of
/// 1,000 bodies, 85% of the checks were of such depths and none of them failed (960,000
/// checks); each took four support points, 6% of the rains' narrow phase.
fn cross_check_depth(
    state: &mut PairState,
    c1: &Collider,
    c2: &Collider,
    pos12: &Pose,
    prediction: f32,
) {
    let depth = max_penetration(&state.manifolds);
    if depth <= DEPTH_CHECK_TOLERANCE {
        return;
    }
    let Some(bound) = depth_bound(c1, c2, pos12, &state.manifolds) else {
        return;
    };
    let plausible = |depth: f32| depth <= bound + DEPTH_CHECK_TOLERANCE + 0.01 * bound.abs();
    if plausible(depth) {
        return;
    }
    // The shallower of a (non-empty) answer from no manifold and the one reported.
    let shallower = |answer: Option<(Vec<Manifold>, _)>, depth: f32| {
        answer.filter(|(m, _)| !m.is_empty() && max_penetration(m) < depth)
    };
    let mut depth = depth;
    if let Some((fresh, workspace)) = shallower(afresh(pos12, c1, c2, prediction), depth) {
        depth = max_penetration(&fresh);
        state.manifolds = fresh;
        state.workspace = workspace;
        if plausible(depth) {
            return;
        }
    }
    if let Some((flipped, _)) = shallower(afresh(&pos12.inverse(), c2, c1, prediction), depth) {
        state.manifolds = flipped.into_iter().map(swap_shapes).collect();
    }
}

/// The manifolds of `c1` and `c2` at `pos12` (`c2`'s pose in `c1`'s frame) computed from none,
/// with their workspace; `None` for an unsupported pair.
fn afresh(
    pos12: &Pose,
    c1: &Collider,
    c2: &Collider,
    prediction: f32,
) -> Option<(Vec<Manifold>, Option<ContactManifoldsWorkspace>)> {
    let mut manifolds = Vec::new();
    let mut workspace = None;
    query(
        pos12,
        c1,
        c2,
        prediction,
        &mut manifolds,
        &mut workspace,
        &mut None,
    )
    .ok()?;
    Some((manifolds, workspace))
}

/// The same manifold seen with its two shapes exchanged.
fn swap_shapes(mut m: Manifold) -> Manifold {
    std::mem::swap(&mut m.local_n1, &mut m.local_n2);
    std::mem::swap(&mut m.subshape1, &mut m.subshape2);
    if let Some(poses) = m.subshape_poses.as_mut() {
        std::mem::swap(&mut poses.pos1, &mut poses.pos2);
    }
    for p in &mut m.points {
        std::mem::swap(&mut p.local_p1, &mut p.local_p2);
        std::mem::swap(&mut p.fid1, &mut p.fid2);
    }
    m
}
