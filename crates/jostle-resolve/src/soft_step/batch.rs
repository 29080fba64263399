//! Preparing and packing contacts into eight-lane batches of independent manifolds.
//!
//! The soft-step kernels solve eight contact manifolds at once, one per SIMD lane
//! ([`super::lanes`]). Eight manifolds can share a batch only if no two of them write the same
//! body, so the manifolds are first coloured (Box2D v3's graph colouring): each non-static
//! body keeps a 64-bit mask of the colours its manifolds already use, and a manifold takes the
//! lowest colour free in both of its bodies' masks. Manifolds of one colour touch disjoint
//! bodies; they are packed eight to a batch in colour order, then input order, so the result is
//! deterministic. The static entry (index 0) is never written and never coloured. A body has
//! room for 64 colours in its mask; the manifolds that find all 64 taken (a body with more
//! than 64 manifolds) are coloured again in a second round with the next 64 colours and fresh
//! masks, and so on for up to 16 rounds (1,024 colours). Only a manifold left after those goes
//! to a batch of its own, solved after the coloured ones. With one round, 200 boxes started
//! at one point (19,900 manifolds, 199 per box) put most of their manifolds into batches of
//! one, each a stage of its own, and the soft step's resolve stage took 371 ms a step; with
//! the rounds 35 ms (benches/RESULTS.md, "Colours beyond 64").
//!
//! Solving colour by colour is still Gauss-Seidel (each batch sees the velocities the previous
//! batches left), only in a different order than the input's.
//!
//! A manifold here is a run of consecutive contacts between the same two bodies, at
//! most [`MAX_POINTS`] long (the narrow phase emits a manifold's points together; a longer run
//! is split). Lanes with fewer points than the batch's longest, and lanes without a manifold,
//! hold zero points: zero normal, zero effective mass, zero friction, bodies at the static
//! entry, so every impulse they compute is exactly zero.

use super::lanes::{F8, Lane, V3x8, WIDTH};
use super::prepare::{PrepareParams, prepare_batches};
use crate::{Contact, STATIC_BODY, SolverBody};
use jostle_math::Vec3;

/// Manifolds per batch: the lane count of [`super::lanes`].
pub const LANES: usize = WIDTH;

/// Most contact points per manifold lane.
pub const MAX_POINTS: usize = 4;

/// A manifold whose normal makes an angle of more than 60° with gravity is packed with the
/// others like it ([`Batches::pack`]).
const SIDE_COSINE: f32 = 0.5;

/// Bodies per block within which [`Batches::pack`] groups the manifolds near horizontal into
/// batches of their own (the batches are then ordered by body across the whole colour, as the
/// team's threads want it).
const SIDE_BLOCK: u32 = 256;

/// A batch being packed: its colour, the lowest movable body it writes, its runs
/// (`lanes` entries of [`Batches::order`] from `first`) and whether it is a side batch.
#[derive(Clone, Copy, Debug)]
struct BatchPlace {
    colour: u32,
    body: u32,
    first: u32,
    lanes: u32,
    side: bool,
}

/// The bit of a run's packing key that is clear for a manifold near horizontal
/// ([`Batches::pack`]).
const SIDE_BIT: u32 = 71;

/// Colours of one round of colouring (one bit each in a body's mask).
const ROUND_COLOURS: u32 = 64;

/// Rounds of colouring: the manifolds a round could not colour (a body with more than 64
/// manifolds) are coloured again with the next 64 colours and fresh masks.
const ROUNDS: u32 = 16;

/// Colours available before a manifold overflows into a batch of its own.
const COLOURS: u32 = ROUND_COLOURS * ROUNDS;

/// Marks a lane-point that holds no contact.
pub const NO_SOURCE: u32 = u32::MAX;

/// One contact point of each of eight manifolds, stored by lane, as
/// [`prepare_point`](super::prepare::prepare_point) computes it; a padding lane holds zeros.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct PointLanes<F = F8> {
    /// Unit normal from B toward A.
    pub normal: V3x8<F>,
    /// Anchor relative to A's centre of mass at the start of the step (m).
    pub r_a: V3x8<F>,
    /// Anchor relative to B's centre of mass at the start of the step (m).
    pub r_b: V3x8<F>,
    /// I_A⁻¹·(r_A × n).
    pub ang_a_normal: V3x8<F>,
    /// I_B⁻¹·(r_B × n).
    pub ang_b_normal: V3x8<F>,
    /// Adjusted separation at the start of the step (m).
    pub base_separation: F,
    /// Normal effective mass (kg).
    pub normal_mass: F,
    /// Accumulated normal impulse (N·s).
    pub normal_impulse: F,
    /// Largest normal impulse increment of the step (N·s).
    pub max_normal_impulse: F,
    /// Soft bias rate (1/s).
    pub bias_rate: F,
    /// Soft mass scale.
    pub mass_scale: F,
    /// Soft impulse scale.
    pub impulse_scale: F,
    /// Friction coefficient μ.
    pub friction: F,
    /// First tangent.
    pub tangent1: V3x8<F>,
    /// Second tangent.
    pub tangent2: V3x8<F>,
    /// I_A⁻¹·(r_A × t₁).
    pub ang_a_tangent1: V3x8<F>,
    /// I_A⁻¹·(r_A × t₂).
    pub ang_a_tangent2: V3x8<F>,
    /// I_B⁻¹·(r_B × t₁).
    pub ang_b_tangent1: V3x8<F>,
    /// I_B⁻¹·(r_B × t₂).
    pub ang_b_tangent2: V3x8<F>,
    /// Inverse 2×2 tangent effective mass (symmetric: \[0,0\], \[0,1\], \[1,1\]).
    pub tangent_mass: [F; 3],
    /// Accumulated friction impulse along t₁, t₂ (N·s).
    pub tangent_impulse: [F; 2],
    /// What a unit normal impulse changes the relative velocity along t₁, t₂ by (m/s per
    /// N·s): t·(M_A⁻¹ + M_B⁻¹)·n + (r_A × t)·I_A⁻¹·(r_A × n) + (r_B × t)·I_B⁻¹·(r_B × n).
    /// The relax pass takes friction's velocity from its normal row's with it instead of
    /// computing the relative velocity again.
    pub normal_tangent: [F; 2],
    /// The chord term of friction along t₁, t₂ (m/s²): how the relative velocity of A's
    /// point and B's turns within the step while they stick, ω × (ω × (r_A − r_B)) for the
    /// turn ω of the immovable body of the pair (both points turn with it). The anchors stay as they were at the start of the step, so
    /// friction would otherwise hold a sticking point to the other's velocity there all
    /// step long, and carry it straight along the tangent while the point it sticks to
    /// turns (a box on a turntable moved outward by r·(ω·Δt)²/2 every step). Friction
    /// holds the relative velocity plus this times the time into the step at zero
    /// ([`super::solve::BiasedPass::chord_time`]). Zero unless one body is immovable and
    /// turning (a kinematic one), whose turn is sure to last the step: a dynamic body's spin
    /// at the start of a step is often what the step's own contacts take out (a box's first
    /// step under 10⁵ m/s² spun it at 15 rad/s), and a chord term from it sent such runs on
    /// other courses (benches/RESULTS.md, "Loads on a turntable"). Taking the dynamic body's
    /// own spin for its point, as a first form did, gave a body landing on a turntable a
    /// target from a spin the landing takes out.
    pub chord: [F; 2],
    /// Restitution e.
    pub restitution: F,
    /// Normal relative velocity at the start of the step (m/s).
    pub relative_velocity: F,
    /// The compression the spring takes as already carried ([`crate::Contact::preload`], m).
    pub preload: F,
    /// How fast the preload grows in with the overlap (dimensionless): the spring is
    /// compressed by min(preload, slope · overlap) more ([`super::prepare::prepare_point`]).
    pub preload_slope: F,
    /// The separation (m) at the bodies' poses when a pass last computed it: the relax pass
    /// keeps it for the next substep's biased pass ([`super::solve::BiasedPass`]).
    pub separation: F,
}

// 220 bytes per contact point: 11 vectors and 22 scalars, each eight lanes wide.
const _: () = assert!(size_of::<PointLanes>() <= 220 * LANES);

/// Eight manifolds (one per lane) with disjoint non-static bodies; their points are
/// `points[first .. first + count]` of the [`Batches`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct ManifoldLanes<F = F8> {
    /// Solver index of body A per lane ([`STATIC_BODY`] for a padding lane).
    pub a: [u32; LANES],
    /// Solver index of body B per lane.
    pub b: [u32; LANES],
    /// 1/m of A per lane along each world axis (1/kg; zero along a locked axis:
    /// [`crate::SolverBody::inv_mass_axes`]).
    pub inv_mass_a: V3x8<F>,
    /// 1/m of B per lane along each world axis (1/kg).
    pub inv_mass_b: V3x8<F>,
    /// Index of the first [`PointLanes`] of this batch.
    pub first: u32,
    /// Number of [`PointLanes`]: the most points of any lane.
    pub count: u32,
    /// Whether any point of any lane has friction (μ > 0): otherwise friction is skipped.
    pub friction: bool,
    /// Whether the body of some lane has an inverse mass that differs between axes (a
    /// translation lock on some but not all axes): the kernels then apply impulses through
    /// [`ManifoldLanes::inv_mass_a`] axis by axis, otherwise through its x component alone
    /// (which is 0 for a body locked along every axis, as its other components are).
    pub locked: bool,
    /// Whether every lane's normal lies within 60° of horizontal under gravity
    /// ([`Batches::pack`] groups such manifolds): they carry little load, the block solution
    /// would pull in most of them, so the relax pass solves their points one by one
    /// ([`super::solve::relax`]) and no block is factored for them.
    pub side: bool,
    /// Lanes (bit l for lane l) whose body A keeps its warm start point by point in every
    /// substep ([`super::body_state::EXACT_WARM`]); set after packing.
    pub exact_a: u8,
    /// The same for body B.
    pub exact_b: u8,
    /// Lanes (bit l for lane l) whose manifold a direct island solves this step
    /// ([`super::direct::DirectIslands::mark`]); set after packing.
    pub direct: u8,
    /// The Cholesky factor L of the batch's block system K + ε·diag(K) over its points
    /// ([`super::solve::factor_blocks`], for the block relax): L's entries below the
    /// diagonal row by row (l₁₀, l₂₀, l₂₁, l₃₀, l₃₁, l₃₂), then 1/lᵢᵢ for i = 0..4.
    pub block: [F; BLOCK_ENTRIES],
}

/// Entries of [`ManifoldLanes::block`]: the six below the diagonal of a 4 × 4 factor and
/// the four reciprocals of its diagonal.
pub const BLOCK_ENTRIES: usize = 10;

/// The prepared contacts of one step, packed for the kernels.
#[derive(Clone, Debug, Default)]
pub struct Batches {
    /// The batches, coloured ones first, in colour order.
    pub manifolds: Vec<ManifoldLanes>,
    /// The points of all batches.
    pub points: Vec<PointLanes>,
    /// For each [`PointLanes`], the input contact index of each lane, or [`NO_SOURCE`].
    pub sources: Vec<[u32; LANES]>,
    /// Number of colours used (batches of a colour never share a written body).
    pub colours: u32,
    /// Manifolds that found no free colour and were given a batch of their own.
    pub overflow: u32,
    /// Where each group of batches that write disjoint bodies starts in `manifolds` (one
    /// group per colour, then one per overflow batch), and `manifolds.len()` last: group g is
    /// `groups[g]..groups[g + 1]`. The batches of a group may be solved in any order, or at
    /// once, with the same result.
    pub groups: Vec<u32>,
    /// Contact points packed (lanes holding a contact).
    pub contacts: u32,
    /// Whether any packed contact has restitution (e > 0).
    pub any_restitution: bool,
    // Scratch reused from step to step.
    colour_mask: Vec<u64>,
    counts: Vec<u32>,
    runs: Vec<Run>,
    order: Vec<u32>,
    /// Each run's place within its colour (`Batches::pack`).
    keys: Vec<u128>,
    /// The batches of the packing before they are laid out (`Batches::pack`).
    places: Vec<BatchPlace>,
    /// The contacts that take part, in input order, with what the layout depends on
    /// ([`Batches::pack`]); the layout's input when it was last decided.
    layout: Vec<Kept>,
    /// `manifolds`, `sources` and `groups` lengths that the last full packing left, or
    /// `None` before the first one: a layout is reused only if they are unchanged.
    layout_lengths: Option<[usize; 3]>,
    /// Counts the layouts made afresh ([`Batches::generation`]).
    generation: u64,
}

/// A contact that takes part in the step, as [`Batches::pack`]'s layout sees it: everything
/// the layout depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Kept {
    /// Its index in the step's contacts.
    index: u32,
    /// Its bodies.
    a: u32,
    b: u32,
    /// Whether its normal lies within 60° of horizontal under gravity (`down`).
    side: bool,
    /// Whether it has friction.
    friction: bool,
}

impl Kept {
    fn new(index: usize, c: &Contact, down: Vec3) -> Self {
        Self {
            index: index as u32,
            a: c.a,
            b: c.b,
            side: down != Vec3::ZERO && c.normal.dot(down).abs() < SIDE_COSINE,
            friction: c.friction > 0.0,
        }
    }
}

/// How fast the bodies of `c` close its gap at its points (m/s; 0 when they do not): the
/// relative velocity of A's point toward B's along the normal.
fn closing(c: &Contact, a: &SolverBody, b: &SolverBody) -> f32 {
    let va = a.linear_velocity + a.angular_velocity.cross(c.point - a.position);
    let vb = b.linear_velocity + b.angular_velocity.cross(c.point_b - b.position);
    (vb - va).dot(c.normal).max(0.0)
}

/// A manifold before packing: a run of prepared contacts and its colour.
#[derive(Clone, Copy, Debug)]
struct Run {
    start: u32,
    len: u32,
    colour: u32,
}

impl Run {
    const EMPTY: Run = Run {
        start: 0,
        len: 0,
        colour: 0,
    };
}

impl Batches {
    /// Prepares and packs the contacts of one step: those between two bodies of which at
    /// least one can move, with a gap of at most `speculative_margin` (m), or of at most
    /// the margin plus what the bodies close within [`PrepareParams::step`] at their
    /// velocities (a speculative contact ahead of a fast body); the others take no part.
    ///
    /// The layout (which manifold goes to which batch and lane) depends only on which
    /// contacts take part, their bodies, whether each has friction and whether its normal
    /// lies within 60° of horizontal. When all of these are as at the last packing (a
    /// resting pile: the same pairs step after step) the batches keep that layout and only
    /// their contents are prepared again: the same result as packing afresh, without the
    /// colouring and sorting. A caller that edits `manifolds`, `sources`, `groups` or
    /// `points` by hand between two packings must call [`Batches::forget_layout`].
    pub fn pack(
        &mut self,
        contacts: &[Contact],
        bodies: &[SolverBody],
        speculative_margin: f32,
        params: &PrepareParams,
    ) {
        self.arrange(contacts, bodies, speculative_margin, params);
        prepare_batches(
            &mut self.manifolds,
            &mut self.points,
            &self.sources,
            contacts,
            bodies,
            params,
        );
    }

    /// [`Batches::pack`] without preparing the points: the batches, their bodies and their
    /// points' sources, to be prepared by [`prepare_batches`] or, a run of batches at a
    /// time, by [`super::prepare::prepare_batch_range`].
    pub fn arrange(
        &mut self,
        contacts: &[Contact],
        bodies: &[SolverBody],
        speculative_margin: f32,
        params: &PrepareParams,
    ) {
        self.arrange_with(contacts, bodies, speculative_margin, params, |_| {});
    }

    /// [`Batches::arrange`], calling `each` on every contact, in order, as it is looked at
    /// (whether it takes part or not): a caller with its own pass over the contacts saves
    /// reading them twice, which at scale streams them from memory twice.
    pub fn arrange_with(
        &mut self,
        contacts: &[Contact],
        bodies: &[SolverBody],
        speculative_margin: f32,
        params: &PrepareParams,
        mut each: impl FnMut(&Contact),
    ) {
        self.any_restitution = false;
        // Which contacts take part, compared entry by entry with the last layout's as they
        // are found.
        let mut same = self.layout_lengths.is_some();
        let mut kept = 0;
        for (i, c) in contacts.iter().enumerate() {
            each(c);
            let (ba, bb) = (&bodies[c.a as usize], &bodies[c.b as usize]);
            let gap = -c.penetration;
            let within = gap <= speculative_margin
                || (params.step > 0.0
                    && gap <= speculative_margin + closing(c, ba, bb) * params.step);
            if within && (ba.is_movable() || bb.is_movable()) {
                debug_assert_ne!(c.a, c.b, "a contact needs two different bodies");
                debug_assert!(
                    (c.normal.length_squared() - 1.0).abs() < 1e-3,
                    "contact normal must be unit, got {}",
                    c.normal
                );
                let entry = Kept::new(i, c, params.down);
                match self.layout.get_mut(kept) {
                    Some(old) => {
                        same &= *old == entry;
                        *old = entry;
                    }
                    None => {
                        same = false;
                        self.layout.push(entry);
                    }
                }
                kept += 1;
                self.any_restitution |= c.restitution > 0.0;
            }
        }
        same &= self.layout.len() == kept
            && self.layout_lengths
                == Some([self.manifolds.len(), self.sources.len(), self.groups.len()]);
        self.layout.truncate(kept);
        self.contacts = kept as u32;
        if same {
            for m in &mut self.manifolds {
                // Set again by the resolver where it applies (`mark_exact_warm`,
                // `DirectIslands::mark`).
                (m.exact_a, m.exact_b, m.direct) = (0, 0, 0);
            }
        } else {
            self.lay_out(bodies.len());
            self.layout_lengths =
                Some([self.manifolds.len(), self.sources.len(), self.groups.len()]);
        }
    }

    /// How many times the batches have been laid out afresh: while it stays the same, every
    /// batch writes the same bodies as before.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Makes the next [`Batches::pack`] lay the batches out afresh.
    pub fn forget_layout(&mut self) {
        self.layout_lengths = None;
    }

    /// Colours the manifolds of the contacts in `layout` and packs them into batches:
    /// `manifolds` (their bodies and points, not yet prepared), `sources`, `groups`,
    /// `colours` and `overflow`. `bodies`: how many bodies there are.
    fn lay_out(&mut self, bodies: usize) {
        self.generation = self.generation.wrapping_add(1);
        self.manifolds.clear();
        // `points` is resized below, not cleared: every point is overwritten by the
        // preparation, so only a growth needs filling (a step's 1.5 kB per point is otherwise
        // written twice).
        self.sources.clear();
        self.runs.clear();
        self.colour_mask.clear();
        self.colour_mask.resize(bodies, 0);
        self.colours = 0;
        self.overflow = 0;

        // Manifolds: runs of the same body pair, coloured by the colour masks: first all with
        // colours 0..64, then again those left with colours 64..128 and fresh masks, and so on.
        let mut start = 0;
        let kept = &self.layout;
        while start < kept.len() {
            let (a, b) = (kept[start].a, kept[start].b);
            let mut len = 1;
            while start + len < kept.len() && len < MAX_POINTS && {
                let c = &kept[start + len];
                c.a == a && c.b == b
            } {
                len += 1;
            }
            let mask = |i: u32| {
                if i == STATIC_BODY {
                    0
                } else {
                    self.colour_mask[i as usize]
                }
            };
            let free = !(mask(a) | mask(b));
            let colour = if free == 0 {
                COLOURS
            } else {
                free.trailing_zeros()
            };
            if colour < ROUND_COLOURS {
                for i in [a, b] {
                    if i != STATIC_BODY {
                        self.colour_mask[i as usize] |= 1 << colour;
                    }
                }
                self.colours = self.colours.max(colour + 1);
            }
            self.runs.push(Run {
                start: start as u32,
                len: len as u32,
                colour,
            });
            start += len;
        }

        // The later rounds, over the runs the one before left uncoloured (in input order).
        for round in 1..ROUNDS {
            let left = self.runs.iter().filter(|r| r.colour == COLOURS).count();
            if left == 0 {
                break;
            }
            self.colour_mask.fill(0);
            let base = round * ROUND_COLOURS;
            for r in self.runs.iter_mut().filter(|r| r.colour == COLOURS) {
                let c = &kept[r.start as usize];
                let mask = |i: u32| {
                    if i == STATIC_BODY {
                        0
                    } else {
                        self.colour_mask[i as usize]
                    }
                };
                let free = !(mask(c.a) | mask(c.b));
                if free != 0 {
                    let colour = free.trailing_zeros();
                    for i in [c.a, c.b] {
                        if i != STATIC_BODY {
                            self.colour_mask[i as usize] |= 1 << colour;
                        }
                    }
                    r.colour = base + colour;
                    self.colours = self.colours.max(base + colour + 1);
                }
            }
        }
        self.overflow = self.runs.iter().filter(|r| r.colour == COLOURS).count() as u32;

        // Colour order, stable: a counting sort of run indices by colour.
        self.counts.clear();
        self.counts.resize(COLOURS as usize + 2, 0);
        let counts = &mut self.counts;
        for r in &self.runs {
            counts[r.colour as usize + 1] += 1;
        }
        for c in 1..counts.len() {
            counts[c] += counts[c - 1];
        }
        self.order.clear();
        self.order.resize(self.runs.len(), 0);
        for (i, r) in self.runs.iter().enumerate() {
            let slot = &mut counts[r.colour as usize];
            self.order[*slot as usize] = i as u32;
            *slot += 1;
        }

        // Within a colour, by body: the lower movable body's index, then input order. The
        // threads of a step's team each take a contiguous part of every colour
        // ([`super::team`]), so each keeps touching about the same bodies from colour to
        // colour, and the body states stay in its core's cache. Within each block of
        // `SIDE_BLOCK` bodies the manifolds whose normal lies within 60° of horizontal come
        // first: under gravity they carry little load, and the relax pass's block solution
        // pulls in most of them, which sends the whole batch back point by point
        // (`solve::relax_block`); grouped, they fill batches of their own, which the relax
        // pass solves point by point (`ManifoldLanes::side`; a side manifold packed with
        // others is solved by the block as they are). Within those, by the manifold's point
        // count: a batch runs as many point rows as its longest lane has points, so balls
        // (one point) packed with boxes (four) ran four rows for every lane (a rain of boxes,
        // balls, capsules and cylinders filled 53% of its lane-points, 80% sorted; the
        // 20-row pyramid's 96% is unchanged). Each lane is solved on its own, so beyond
        // deciding which batches are side batches the order changes no result.
        self.keys.clear();
        self.keys.extend(self.runs.iter().map(|r| {
            let c = &kept[r.start as usize];
            let body = match (c.a, c.b) {
                (STATIC_BODY, b) => b,
                (a, STATIC_BODY) => a,
                (a, b) => a.min(b),
            };
            let side = c.side;
            (u128::from(body / SIDE_BLOCK) << 72)
                | (u128::from(!side) << SIDE_BIT)
                | (u128::from(r.len) << 64)
                | (u128::from(body) << 32)
                | u128::from(r.start)
        }));
        // (`counts[c]` now ends colour c.)
        let mut begin = 0;
        for &end in counts.iter().take(COLOURS as usize) {
            let keys = &self.keys;
            self.order[begin as usize..end as usize].sort_unstable_by_key(|&i| keys[i as usize]);
            begin = end;
        }

        // Pack: eight runs of one colour per batch; an overflow run alone. A colour's batches
        // are then ordered by the lowest movable body they write (`BatchPlace`): the side
        // batches of a block of bodies come first within the colour, and without this order
        // a team's first thread took every side batch of a small scene (all its bodies) while
        // the second took the rest, so body states crossed between the cores at almost every
        // colour (the 20-row pyramid: 440 of 1,370 body visits in a pass). The order of a
        // group's batches changes no result.
        self.groups.clear();
        self.places.clear();
        let mut k = 0;
        while k < self.order.len() {
            let colour = self.runs[self.order[k] as usize].colour;
            let mut lanes = 1;
            if colour < COLOURS {
                while lanes < LANES
                    && k + lanes < self.order.len()
                    && self.runs[self.order[k + lanes] as usize].colour == colour
                {
                    lanes += 1;
                }
            }
            // The lowest movable body of the batch's runs (the key's bits 32..64).
            let body = (0..lanes)
                .map(|l| (self.keys[self.order[k + l] as usize] >> 32) as u32)
                .min()
                .unwrap_or(0);
            // Near horizontal: the key's `SIDE_BIT` (`!side`) is clear.
            let side =
                (0..lanes).all(|l| self.keys[self.order[k + l] as usize] & (1 << SIDE_BIT) == 0);
            self.places.push(BatchPlace {
                colour,
                body,
                first: k as u32,
                lanes: lanes as u32,
                side,
            });
            k += lanes;
        }
        let mut start = 0;
        while start < self.places.len() {
            let colour = self.places[start].colour;
            let mut end = start + 1;
            if colour < COLOURS {
                while end < self.places.len() && self.places[end].colour == colour {
                    end += 1;
                }
            }
            // (`first` breaks ties: the order is the same on every machine.)
            self.places[start..end].sort_unstable_by_key(|p| (p.body, p.first));
            self.groups.push(self.manifolds.len() as u32);
            for i in start..end {
                let place = self.places[i];
                let mut batch_runs = [Run::EMPTY; LANES];
                for (l, run) in batch_runs.iter_mut().enumerate().take(place.lanes as usize) {
                    *run = self.runs[self.order[place.first as usize + l] as usize];
                }
                self.push_batch(&batch_runs[..place.lanes as usize], place.side);
            }
            start = end;
        }
        self.groups.push(self.manifolds.len() as u32);
        self.points
            .resize(self.sources.len(), PointLanes::default());
    }

    /// Appends one batch holding `runs` (at most [`LANES`]) in lanes 0, 1, ...: its bodies,
    /// its points' sources; [`prepare_batches`] then writes the points.
    /// `side`: every run's normal lies within 60° of horizontal ([`ManifoldLanes::side`]).
    fn push_batch(&mut self, runs: &[Run], side: bool) {
        debug_assert!(!runs.is_empty() && runs.len() <= LANES);
        let count = runs.iter().map(|r| r.len).max().unwrap_or(0);
        let first = self.sources.len() as u32;
        let mut a = [STATIC_BODY; LANES];
        let mut b = [STATIC_BODY; LANES];
        for (lane, r) in runs.iter().enumerate() {
            let c0 = &self.layout[r.start as usize];
            (a[lane], b[lane]) = (c0.a, c0.b);
        }
        let mut friction = false;
        for p in 0..count {
            let mut source = [NO_SOURCE; LANES];
            for (lane, r) in runs.iter().enumerate() {
                if p < r.len {
                    let c = &self.layout[(r.start + p) as usize];
                    source[lane] = c.index;
                    friction |= c.friction;
                }
            }
            self.sources.push(source);
        }
        self.manifolds.push(ManifoldLanes {
            a,
            b,
            inv_mass_a: V3x8::ZERO,
            inv_mass_b: V3x8::ZERO,
            first,
            count,
            friction,
            locked: false,
            side,
            exact_a: 0,
            exact_b: 0,
            direct: 0,
            block: [F8::ZERO; BLOCK_ENTRIES],
        });
    }

    /// Every (batch, point) pair with a contact in `lane`, for tests and diagnostics: yields
    /// (point index, lane, input contact index).
    pub fn lanes(&self) -> impl Iterator<Item = (usize, usize, u32)> + '_ {
        self.sources.iter().enumerate().flat_map(|(p, s)| {
            s.iter()
                .enumerate()
                .filter(|(_, src)| **src != NO_SOURCE)
                .map(move |(lane, src)| (p, lane, *src))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soft_step::Softness;
    use jostle_math::{Mat3, Quat, Vec3};

    fn params() -> PrepareParams {
        let s = Softness::new(30.0, 10.0, 1.0 / 240.0);
        PrepareParams {
            static_softness: s,
            dynamic_softness: s,
            warm_scale: 0.25,
            preload_ramp: 0.0,
            preload_bound: 0.0,
            step: 0.0,
            down: Vec3::ZERO,
        }
    }

    fn bodies(n: u32) -> Vec<SolverBody> {
        let mut bodies = vec![SolverBody::STATIC];
        for i in 0..n {
            bodies.push(SolverBody::new(
                Vec3::new(0.0, i as f32 + 0.5, 0.0),
                Quat::IDENTITY,
                1.0,
                Mat3::IDENTITY,
            ));
        }
        bodies
    }

    /// A chain of `n` bodies, each touching the next with a `points`-point manifold, the first
    /// also touching the ground (static entry).
    fn chain(n: u32, points: usize) -> Vec<Contact> {
        let mut contacts = Vec::new();
        for i in 0..n {
            for p in 0..points {
                let point = Vec3::new(p as f32 * 0.1, i as f32, 0.0);
                contacts.push(Contact::new(i + 1, i, point, Vec3::Y, 0.001).with_friction(0.5));
            }
        }
        contacts
    }

    #[test]
    fn batches_never_share_a_written_body_and_keep_every_contact_once() {
        let contacts = chain(21, 4);
        let mut batches = Batches::default();
        batches.pack(&contacts, &bodies(21), 0.02, &params());
        for m in &batches.manifolds {
            let mut written: Vec<u32> =
                m.a.iter()
                    .chain(&m.b)
                    .copied()
                    .filter(|&i| i != 0)
                    .collect();
            let before = written.len();
            written.sort_unstable();
            written.dedup();
            assert_eq!(written.len(), before, "a body twice in {m:?}");
        }
        let mut seen: Vec<u32> = batches.lanes().map(|(_, _, s)| s).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..contacts.len() as u32).collect::<Vec<_>>());
        // A chain needs two colours; 21 manifolds in 2 colours fill ⌈11/8⌉ + ⌈10/8⌉ batches.
        assert_eq!(batches.colours, 2);
        assert_eq!(batches.manifolds.len(), 2 + 2);
        assert_eq!(batches.overflow, 0);
    }

    /// Balls (one point) and boxes (four) resting on the ground side by side, listed
    /// alternately: one colour, and each batch holds manifolds of one point count, so no lane
    /// runs point rows it does not have (mixed in input order, every batch ran four rows for
    /// its balls too: 64 lane-points for 40 contacts).
    #[test]
    fn manifolds_of_one_point_count_share_a_batch() {
        let mut contacts = Vec::new();
        for i in 1..17u32 {
            let points = if i % 2 == 0 { 4 } else { 1 };
            for p in 0..points {
                let point = Vec3::new(i as f32 + 0.1 * p as f32, 0.0, 0.0);
                contacts.push(Contact::new(i, 0, point, Vec3::Y, 0.001).with_friction(0.5));
            }
        }
        let mut batches = Batches::default();
        batches.pack(&contacts, &bodies(16), 0.02, &params());
        assert_eq!(batches.colours, 1);
        let lane_points: usize = batches
            .manifolds
            .iter()
            .map(|m| m.count as usize * LANES)
            .sum();
        assert_eq!(lane_points, contacts.len());
        let mut seen: Vec<u32> = batches.lanes().map(|(_, _, s)| s).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..contacts.len() as u32).collect::<Vec<_>>());
    }

    #[test]
    fn manifolds_near_horizontal_get_batches_of_their_own_under_gravity() {
        // 40 boxes on the ground (4-point manifolds, normal up), each also touching its
        // neighbour side by side (4-point manifolds, normal along x): the side manifolds
        // alternate with the others in the input.
        let mut contacts = Vec::new();
        for i in 1..41u32 {
            for p in 0..4 {
                let point = Vec3::new(i as f32 + 0.1 * p as f32, 0.0, 0.0);
                contacts.push(Contact::new(i, 0, point, Vec3::Y, 0.001).with_friction(0.5));
            }
            if i < 40 {
                for p in 0..4 {
                    let point = Vec3::new(i as f32 + 0.5, 0.5, 0.1 * p as f32);
                    contacts.push(Contact::new(i, i + 1, point, Vec3::X, 0.0).with_friction(0.5));
                }
            }
        }
        let lanes_of = |batches: &Batches, side: bool| {
            batches
                .manifolds
                .iter()
                .filter(|m| m.side == side)
                .map(|m| m.a.iter().filter(|&&a| a != STATIC_BODY).count())
                .sum::<usize>()
        };
        let down = PrepareParams {
            down: Vec3::NEG_Y,
            ..params()
        };
        let mut batches = Batches::default();
        batches.pack(&contacts, &bodies(40), 0.02, &down);
        // All 39 side manifolds in side batches (the ground's 40 in the others), and no more
        // side batches than their lanes need in each colour.
        assert_eq!(lanes_of(&batches, true), 39);
        assert_eq!(lanes_of(&batches, false), 40);
        for m in batches.manifolds.iter().filter(|m| m.side) {
            let first = m.first as usize;
            for p in &batches.sources[first..first + m.count as usize] {
                for &i in p.iter().filter(|&&i| i != NO_SOURCE) {
                    assert_eq!(contacts[i as usize].normal, Vec3::X);
                }
            }
        }
        let mut seen: Vec<u32> = batches.lanes().map(|(_, _, s)| s).collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..contacts.len() as u32).collect::<Vec<_>>());
        // A second row on the first, side by side too.
        for i in 1..41u32 {
            for p in 0..4 {
                let point = Vec3::new(i as f32 + 0.1 * p as f32, 1.0, 0.0);
                contacts.push(Contact::new(i + 40, i, point, Vec3::Y, 0.001).with_friction(0.5));
            }
            if i < 40 {
                for p in 0..4 {
                    let point = Vec3::new(i as f32 + 0.5, 1.5, 0.1 * p as f32);
                    contacts
                        .push(Contact::new(i + 40, i + 41, point, Vec3::X, 0.0).with_friction(0.5));
                }
            }
        }
        batches.pack(&contacts, &bodies(80), 0.02, &down);
        // Each colour's batches, side batches or not, in the order of the lowest body they
        // write: a team thread's part of a colour touches the bodies its part of the next does.
        let lowest = |m: &ManifoldLanes| {
            m.a.iter()
                .chain(&m.b)
                .filter(|&&i| i != STATIC_BODY)
                .min()
                .copied()
                .unwrap_or(STATIC_BODY)
        };
        for group in batches.groups.windows(2) {
            let colour = &batches.manifolds[group[0] as usize..group[1] as usize];
            let bodies: Vec<u32> = colour.iter().map(lowest).collect();
            assert!(bodies.is_sorted(), "a colour out of body order: {bodies:?}");
        }
        // Side batches are not all at the front of their colour.
        // (Packed in body order within a block of 256 bodies, the side batches came first in
        // their colour.)
        assert!(batches.groups.windows(2).any(|g| {
            let colour = &batches.manifolds[g[0] as usize..g[1] as usize];
            colour.windows(2).any(|w| !w[0].side && w[1].side)
        }));
        // Without gravity there is no horizontal: no batch is a side batch.
        batches.pack(&contacts, &bodies(80), 0.02, &params());
        assert_eq!(lanes_of(&batches, true), 0);
    }

    /// What `pack` decides: the batches, their points' sources and the groups.
    fn layout_of(b: &Batches) -> (Vec<ManifoldLanes>, Vec<[u32; LANES]>, Vec<u32>, u32) {
        (
            b.manifolds.clone(),
            b.sources.clone(),
            b.groups.clone(),
            b.colours,
        )
    }

    #[test]
    fn a_repacking_keeps_the_layout_only_while_it_would_be_the_same() {
        let down = PrepareParams {
            down: Vec3::NEG_Y,
            ..params()
        };
        let fresh = |contacts: &[Contact]| {
            let mut b = Batches::default();
            b.pack(contacts, &bodies(21), 0.02, &down);
            layout_of(&b)
        };
        let mut contacts = chain(21, 4);
        let mut batches = Batches::default();
        batches.pack(&contacts, &bodies(21), 0.02, &down);
        // The same contacts, slightly moved: the layout is kept, and equals a fresh one.
        for c in &mut contacts {
            c.penetration += 0.0001;
        }
        batches.pack(&contacts, &bodies(21), 0.02, &down);
        assert_eq!(layout_of(&batches), fresh(&contacts));
        // Each change the layout depends on lays it out again, as a fresh packing would.
        let changes: [fn(&mut Vec<Contact>); 5] = [
            |c| c[4..8].iter_mut().for_each(|c| c.friction = 0.0),
            |c| c[8..12].iter_mut().for_each(|c| c.normal = Vec3::X),
            |c| c[13].penetration = -1.0,
            |c| c.truncate(30),
            |c| c.push(Contact::new(3, 0, Vec3::ZERO, Vec3::Y, 0.001)),
        ];
        for change in changes {
            change(&mut contacts);
            batches.pack(&contacts, &bodies(21), 0.02, &down);
            assert_eq!(layout_of(&batches), fresh(&contacts));
        }
        // Edited by hand and forgotten: laid out again.
        batches.manifolds.clear();
        batches.forget_layout();
        batches.pack(&contacts, &bodies(21), 0.02, &down);
        assert_eq!(layout_of(&batches), fresh(&contacts));
    }

    #[test]
    fn far_and_immovable_contacts_take_no_part() {
        let mut contacts = chain(2, 1);
        contacts[1].penetration = -0.5; // gap beyond the margin
        contacts.push(Contact::new(0, 0, Vec3::ZERO, Vec3::Y, 0.1)); // static against static
        let mut batches = Batches::default();
        batches.pack(&contacts, &bodies(2), 0.02, &params());
        assert_eq!(batches.contacts, 1);
        assert_eq!(batches.lanes().map(|(_, _, s)| s).collect::<Vec<_>>(), [0]);
    }

    #[test]
    fn a_body_with_more_than_64_manifolds_takes_colours_of_later_rounds() {
        // 70 one-point manifolds all on body 1: 64 colours in the first round, 6 in the
        // second, one manifold each (they all share body 1).
        let contacts: Vec<Contact> = (2..72)
            .map(|b| Contact::new(1, b, Vec3::ZERO, Vec3::X, 0.0))
            .collect();
        let mut batches = Batches::default();
        batches.pack(&contacts, &bodies(71), 0.02, &params());
        assert_eq!(batches.colours, 70);
        assert_eq!(batches.overflow, 0);
        assert_eq!(batches.manifolds.len(), 70);
        assert_eq!(batches.lanes().count(), 70);
    }

    #[test]
    fn manifolds_of_a_dense_cluster_share_batches_beyond_64_colours() {
        // 40 bodies all touching each other (780 one-point manifolds, 39 per body): one round
        // of 64 colours holds them, eight to a batch where they do not share bodies.
        let mut contacts = Vec::new();
        for a in 1..41u32 {
            for b in a + 1..41 {
                contacts.push(Contact::new(a, b, Vec3::ZERO, Vec3::X, 0.0));
            }
        }
        let mut batches = Batches::default();
        batches.pack(&contacts, &bodies(40), 0.02, &params());
        assert_eq!(batches.overflow, 0);
        assert!(
            batches.manifolds.len() < 780 / 4,
            "{}",
            batches.manifolds.len()
        );
        // 200 bodies: 199 manifolds per body need several rounds; none overflows.
        let mut contacts = Vec::new();
        for a in 1..201u32 {
            for b in a + 1..201 {
                contacts.push(Contact::new(a, b, Vec3::ZERO, Vec3::X, 0.0));
            }
        }
        batches.pack(&contacts, &bodies(200), 0.02, &params());
        assert_eq!(batches.overflow, 0);
        assert!(batches.colours > 64);
        assert!(
            batches.manifolds.len() < 19_900 / 4,
            "{}",
            batches.manifolds.len()
        );
        // The manifolds of one group (one colour) never share a body.
        for g in batches.groups.windows(2) {
            let mut seen = std::collections::HashSet::new();
            for m in &batches.manifolds[g[0] as usize..g[1] as usize] {
                for lane in 0..LANES {
                    for body in [m.a[lane], m.b[lane]] {
                        if body != STATIC_BODY {
                            assert!(seen.insert(body), "body {body} twice in a group");
                        }
                    }
                }
            }
        }
    }

    /// The lane-wise preparation gives what the formulas give for one contact: effective
    /// mass, angular response, adjusted separation and approach velocity.
    #[test]
    fn a_prepared_lane_matches_the_scalar_formulas() {
        let mut bodies = bodies(1);
        let inv_i = Mat3::from_diagonal(Vec3::new(2.0, 3.0, 4.0));
        bodies[1] = SolverBody::new(Vec3::new(0.0, 0.5, 0.0), Quat::IDENTITY, 0.5, inv_i);
        bodies[1].linear_velocity = Vec3::new(0.0, -1.0, 0.0);
        let c = Contact::new(1, 0, Vec3::new(0.3, 0.0, -0.2), Vec3::Y, 0.01);
        let mut batches = Batches::default();
        batches.pack(&[c], &bodies, 0.02, &params());
        let p = &batches.points[0];
        let r = c.point - bodies[1].position;
        let rn = r.cross(Vec3::Y);
        let k = 0.5 + rn.dot(inv_i * rn);
        assert!((p.normal_mass[0] - 1.0 / k).abs() < 1e-6);
        assert!((p.ang_a_normal.lane(0) - inv_i * rn).length() < 1e-6);
        assert!((p.base_separation[0] - (-0.01 - r.y)).abs() < 1e-6);
        assert_eq!(p.relative_velocity[0], -1.0);
        for lane in 1..LANES {
            assert_eq!(p.normal_mass[lane], 0.0, "padding lane {lane}");
        }
    }
}
