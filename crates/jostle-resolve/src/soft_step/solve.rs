//! The soft-step contact kernels: warm start, the biased solve, relax and restitution, each
//! over eight manifolds at once ([`super::batch`], [`super::lanes`]).
//!
//! Sequential impulses with accumulated, clamped impulses (Catto, GDC 2006 "Fast and Simple
//! Physics using Sequential Impulses"; soft step: Catto, "Solver2D", 2024, and Box2D v3's
//! `contact_solver.c`, here in 3D and written from the equations):
//! - normal: λ ← max(λ + Δλ, 0) with Δλ = −m_n·s_m·(v_n + bias) − s_i·λ, where the bias and
//!   the mass and impulse scales s_m, s_i come from the contact's [`super::Softness`] when it
//!   overlaps, and a speculative contact (separation s > 0) targets v_n ≥ −s/h rigidly, so it
//!   stops the gap from closing within the substep and nothing more;
//! - friction: both tangents at once with the inverse 2×2 effective mass, the accumulated
//!   tangent impulse clamped to the disk of radius μ·λ_n (isotropic, unlike a pyramid of two
//!   independent clamps which lets a box slide √2 times further along a diagonal). Where the
//!   biased pass solves no friction, its first sweep after the warm start still scales each
//!   point's carried tangent impulse back into the disk of the normal impulse it leaves.
//!
//! Each batch loads its bodies' velocities (and for the passes that need the separation, the
//! motion since the start of the step) into lanes once, solves its points in order, and
//! writes the velocities back; lanes at the static entry (index 0) are read but never
//! written. Every branch on a contact's state is a lane-wise select, so a lane's result does
//! not depend on its neighbours.

use super::batch::{BLOCK_ENTRIES, Batches, LANES, MAX_POINTS, ManifoldLanes, PointLanes};
use super::body_state::{BodyState, PseudoRow};
use super::lanes::{F8, Lane, LaneMask, Q8, V3x8};
use super::shared::{Shared, share};
use crate::STATIC_BODY;
use jostle_math::Mat3;

/// The velocities of eight bodies, by lane.
#[derive(Clone, Copy)]
struct Velocities<F> {
    linear: V3x8<F>,
    angular: V3x8<F>,
}

/// The motion of eight bodies since the start of the step, by lane.
#[derive(Clone, Copy)]
struct Motion<F> {
    position: V3x8<F>,
    rotation: Q8<F>,
}

/// One 8-float row of each lane's body: `motion` picks [`BodyState::motion_row`], else
/// [`BodyState::velocity_row`].
///
/// Every kernel reads and writes the body states through [`Shared`] elements: the batches of
/// one colour write disjoint bodies ([`super::batch`]), so the threads of a colour
/// ([`super::team`]) never touch one body at once, except the static entry, which is only
/// read. That is the contract of each access below.
#[inline(always)]
fn lane_rows(states: &[Shared<BodyState>], idx: [u32; LANES], motion: bool) -> [&[f32; 8]; LANES] {
    rows_of(idx, |i: u32| {
        // SAFETY: the colouring (above): no other thread writes this body meanwhile.
        let s = unsafe { states[i as usize].get() };
        if motion {
            s.motion_row()
        } else {
            s.velocity_row()
        }
    })
}

/// `row(i)` for each lane's body index.
#[inline(always)]
fn rows_of<'a>(idx: [u32; LANES], row: impl Fn(u32) -> &'a [f32; 8]) -> [&'a [f32; 8]; LANES] {
    // Written out: an array `map` would not be inlined into the kernel. The closure holds no
    // lane operations, so it needs none of the kernel's target features.
    [
        row(idx[0]),
        row(idx[1]),
        row(idx[2]),
        row(idx[3]),
        row(idx[4]),
        row(idx[5]),
        row(idx[6]),
        row(idx[7]),
    ]
}

impl<F: Lane> Velocities<F> {
    /// From the transposed rows of [`BodyState::velocity_row`]'s layout: linear in 0–2,
    /// angular in 4–6.
    #[inline(always)]
    fn from_columns([lx, ly, lz, _, ax, ay, az, _]: [F; 8]) -> Self {
        Self {
            linear: V3x8 {
                x: lx,
                y: ly,
                z: lz,
            },
            angular: V3x8 {
                x: ax,
                y: ay,
                z: az,
            },
        }
    }

    /// Stores each lane's velocities into `row(&mut bodies[i])` of its body i in the same
    /// layout, leaving lanes 3 and 7 of each row alone (a body's 1/m and flags in
    /// [`BodyState`]); the static entry is never written.
    #[inline(always)]
    fn store<B>(
        &self,
        idx: [u32; LANES],
        bodies: &[Shared<B>],
        row: impl Fn(&mut B) -> &mut [f32; 8],
    ) {
        let rows = F::transpose([
            self.linear.x,
            self.linear.y,
            self.linear.z,
            F::ZERO,
            self.angular.x,
            self.angular.y,
            self.angular.z,
            F::ZERO,
        ]);
        for (lane, &i) in idx.iter().enumerate() {
            if i != STATIC_BODY {
                // SAFETY: the colouring (`lane_rows`): this batch is the only one of its
                // colour that touches body i, and the rows it read were copied into lanes.
                let body = unsafe { bodies[i as usize].get_mut() };
                rows[lane].store_skipping_3_and_7(row(body));
            }
        }
    }
}

#[inline(always)]
fn gather_velocities<F: Lane>(states: &[Shared<BodyState>], idx: [u32; LANES]) -> Velocities<F> {
    Velocities::from_columns(F::load_transposed(lane_rows(states, idx, false)))
}

#[inline(always)]
fn gather_motion<F: Lane>(states: &[Shared<BodyState>], idx: [u32; LANES]) -> Motion<F> {
    let [qx, qy, qz, qw, px, py, pz, _] = F::load_transposed(lane_rows(states, idx, true));
    Motion {
        position: V3x8 {
            x: px,
            y: py,
            z: pz,
        },
        rotation: Q8 {
            v: V3x8 {
                x: qx,
                y: qy,
                z: qz,
            },
            w: qw,
        },
    }
}

#[inline(always)]
fn scatter_velocities<F: Lane>(states: &[Shared<BodyState>], idx: [u32; LANES], v: &Velocities<F>) {
    v.store(idx, states, BodyState::velocity_row_mut);
}

/// Whether any of the eight bodies moves with pseudo velocities in this substep (its
/// [`PseudoRow`] is marked in lane 3 by [`scatter_pseudo`]).
#[inline(always)]
fn any_pseudo(pseudo: &[Shared<PseudoRow>], idx: [u32; LANES]) -> bool {
    // SAFETY: the colouring (`lane_rows`).
    idx.iter()
        .any(|&i| unsafe { pseudo[i as usize].get() }[3] != 0.0)
}

/// The pseudo velocities of eight bodies, by lane: rows of [`PseudoRow`] (see
/// [`solve`]).
#[inline(always)]
fn gather_pseudo<F: Lane>(pseudo: &[Shared<PseudoRow>], idx: [u32; LANES]) -> Velocities<F> {
    // SAFETY: the colouring (`lane_rows`).
    Velocities::from_columns(F::load_transposed(rows_of(idx, |i| unsafe {
        pseudo[i as usize].get()
    })))
}

/// Stores the pseudo velocities of eight bodies and marks their rows (lane 3) as moving.
#[inline(always)]
fn scatter_pseudo<F: Lane>(pseudo: &[Shared<PseudoRow>], idx: [u32; LANES], v: &Velocities<F>) {
    v.store(idx, pseudo, |row| row);
    for &i in &idx {
        if i != STATIC_BODY {
            // SAFETY: the colouring (`lane_rows`).
            let row = unsafe { pseudo[i as usize].get_mut() };
            row[3] = 1.0;
        }
    }
}

/// How an impulse changes a body's linear velocity: by 1/m (`F`, a batch without
/// translation locks, [`ManifoldLanes::locked`]) or by 1/m along each world axis
/// (`V3x8<F>`). The kernels are generic over it, so that batches without locks keep one
/// register per side for it.
trait LinearResponse<F: Lane>: Copy {
    /// From a batch's per-axis inverse masses ([`ManifoldLanes::inv_mass_a`]).
    fn from_axes(axes: V3x8<F>) -> Self;
    /// The velocity change of the impulse `impulse`.
    fn times(self, impulse: V3x8<F>) -> V3x8<F>;
}

impl<F: Lane> LinearResponse<F> for F {
    #[inline(always)]
    fn from_axes(axes: V3x8<F>) -> Self {
        axes.x
    }
    #[inline(always)]
    fn times(self, impulse: V3x8<F>) -> V3x8<F> {
        impulse * self
    }
}

impl<F: Lane> LinearResponse<F> for V3x8<F> {
    #[inline(always)]
    fn from_axes(axes: V3x8<F>) -> Self {
        axes
    }
    #[inline(always)]
    fn times(self, impulse: V3x8<F>) -> V3x8<F> {
        impulse.scale(self)
    }
}

/// A batch's two sides during a kernel: velocities loaded, written back by [`Pair::store`].
struct Pair<F, L = F> {
    a: Velocities<F>,
    b: Velocities<F>,
    /// 1/m, or 1/m along each world axis ([`LinearResponse`]).
    inv_mass_a: L,
    inv_mass_b: L,
}

impl<F: Lane> Pair<F, F> {
    /// [`Pair::load`] for a batch without translation locks.
    #[inline(always)]
    fn load_plain(m: &ManifoldLanes<F>, states: &[Shared<BodyState>]) -> Self {
        Self::load(m, states)
    }
}

impl<F: Lane> Pair<F, V3x8<F>> {
    /// [`Pair::load`] for a batch with a translation lock.
    #[inline(always)]
    fn load_axes(m: &ManifoldLanes<F>, states: &[Shared<BodyState>]) -> Self {
        Self::load(m, states)
    }
}

impl<F: Lane, L: LinearResponse<F>> Pair<F, L> {
    #[inline(always)]
    fn load(m: &ManifoldLanes<F>, states: &[Shared<BodyState>]) -> Self {
        Self {
            a: gather_velocities(states, m.a),
            b: gather_velocities(states, m.b),
            inv_mass_a: L::from_axes(m.inv_mass_a),
            inv_mass_b: L::from_axes(m.inv_mass_b),
        }
    }

    #[inline(always)]
    fn store(&self, m: &ManifoldLanes<F>, states: &[Shared<BodyState>]) {
        scatter_velocities(states, m.a, &self.a);
        scatter_velocities(states, m.b, &self.b);
    }

    /// Velocity of A's material point relative to B's at the contact (m/s).
    #[inline(always)]
    fn relative_velocity(&self, p: &PointLanes<F>) -> V3x8<F> {
        (self.a.linear + self.a.angular.cross(p.r_a))
            - (self.b.linear + self.b.angular.cross(p.r_b))
    }

    /// Applies the normal impulse `lambda` (on A along n, on B opposite).
    #[inline(always)]
    fn apply_normal(&mut self, p: &PointLanes<F>, lambda: F) {
        let impulse = p.normal * lambda;
        self.a.linear += self.inv_mass_a.times(impulse);
        self.a.angular += p.ang_a_normal * lambda;
        self.b.linear -= self.inv_mass_b.times(impulse);
        self.b.angular -= p.ang_b_normal * lambda;
    }

    /// Applies the tangent impulse (`l1` along t₁, `l2` along t₂; on A, opposite on B).
    #[inline(always)]
    fn apply_tangent(&mut self, p: &PointLanes<F>, l1: F, l2: F) {
        let impulse = p.tangent1 * l1 + p.tangent2 * l2;
        self.a.linear += self.inv_mass_a.times(impulse);
        self.a.angular += p.ang_a_tangent1 * l1 + p.ang_a_tangent2 * l2;
        self.b.linear -= self.inv_mass_b.times(impulse);
        self.b.angular -= p.ang_b_tangent1 * l1 + p.ang_b_tangent2 * l2;
    }
}

/// The separation now (m, negative on overlap) from the bodies' motion since the start of
/// the step: s₀ + ((Δx_A + Δq_A·r_A) − (Δx_B + Δq_B·r_B))·n with r the step-start anchors
/// (exact for rigid motion of the anchors; the normal is kept fixed, as in Box2D).
#[inline(always)]
fn separation<F: Lane>(p: &PointLanes<F>, a: &Motion<F>, b: &Motion<F>) -> F {
    let pa = a.position + a.rotation.rotate(p.r_a);
    let pb = b.position + b.rotation.rotate(p.r_b);
    p.base_separation + (pa - pb).dot(p.normal)
}

/// Defines `pub fn $name(batches, …)` running the `#[inline(always)]` generic body
/// `$imp::<F>(manifolds, points, …)` with the best lanes the CPU has (`with_best_lanes!`).
/// Measured on the 20-row pyramid (`jostle run assets/pyramid_20.ron --no-sleep`, AMD EPYC with
/// AVX-512, resolve stage median): 0.245 ms per step with 128-bit halves, 0.200 ms with 256-bit
/// lanes (RESULTS.md, "What changed on 2026-11-22, afternoon").
///
/// The function runs over the batches `manifolds` (one colour's, or all), whose points are
/// `points`, the first of them at index `base` of [`Batches::points`], with the body states
/// shared ([`Shared`]): the threads of [`super::team`] each run it on their own batches of a
/// colour at once.
macro_rules! wide_kernel {
    ($(#[$doc:meta])* pub(crate) fn $name:ident($($arg:ident: $ty:ty),*) = $imp:ident;) => {
        $(#[$doc])*
        pub(crate) fn $name(
            manifolds: &mut [ManifoldLanes],
            points: &mut [PointLanes],
            base: u32,
            states: &[Shared<BodyState>]
            $(, $arg: $ty)*
        ) {
            with_best_lanes!($imp(
                manifolds,
                points,
                base: u32,
                states: &[Shared<BodyState>]
                $(, $arg: $ty)*
            ) -> ())
        }
    };
}

/// Runs `$body` for every batch in order, with `$m` the batch, `$pair` its loaded bodies
/// (stored back after the body), `$points` its points and `$st` the body states. `$points`
/// holds the points of `$manifolds` only, the first at index `$base` of the whole
/// [`Batches::points`]. A macro rather than a closure so the body is compiled inline, with the
/// caller's target features.
macro_rules! for_each_batch {
    ($manifolds:expr, $points:expr, $base:expr, $states:expr, |$m:ident, $pair:ident, $pts:ident, $st:ident| $body:block) => {{
        let states: &[Shared<BodyState>] = $states;
        let all_points = $points;
        let base: u32 = $base;
        for $m in $manifolds.iter() {
            let first = ($m.first - base) as usize;
            let range = first..first + $m.count as usize;
            // The body twice: batches with a translation lock apply impulses through
            // per-axis inverse masses, the others through one.
            if $m.locked {
                let mut pair = Pair::load_axes($m, states);
                {
                    let $pair = &mut pair;
                    let $pts = &mut all_points[range];
                    let $st: &[Shared<BodyState>] = states;
                    $body
                }
                pair.store($m, states);
            } else {
                let mut pair = Pair::load_plain($m, states);
                {
                    let $pair = &mut pair;
                    let $pts = &mut all_points[range];
                    let $st: &[Shared<BodyState>] = states;
                    $body
                }
                pair.store($m, states);
            }
        }
    }};
}

#[inline(always)]
fn warm_start_impl<F: Lane>(
    manifolds: &[ManifoldLanes<F>],
    points: &mut [PointLanes<F>],
    base: u32,
    states: &[Shared<BodyState>],
) {
    for_each_batch!(
        manifolds,
        points,
        base,
        states,
        |m, pair, points, _states| {
            for p in points.iter() {
                pair.apply_normal(p, p.normal_impulse);
                if m.friction {
                    pair.apply_tangent(p, p.tangent_impulse[0], p.tangent_impulse[1]);
                }
            }
        }
    );
}

/// The warm start of a substep after the first for the bodies that keep it point by point
/// ([`super::body_state::EXACT_WARM`]): in each batch with such a lane, every point's
/// accumulated impulse applied to the flagged side of each lane only (the other bodies carry
/// theirs: [`super::integrate::Carried`]).
#[inline(always)]
fn warm_start_exact_impl<F: Lane>(
    manifolds: &[ManifoldLanes<F>],
    points: &mut [PointLanes<F>],
    base: u32,
    states: &[Shared<BodyState>],
) {
    for m in manifolds.iter() {
        if m.exact_a | m.exact_b == 0 {
            continue;
        }
        let first = (m.first - base) as usize;
        let points = &points[first..first + m.count as usize];
        if m.locked {
            let mut pair = Pair::load_axes(m, states);
            warm_start_sides(m, &mut pair, points);
            pair.store(m, states);
        } else {
            let mut pair = Pair::load_plain(m, states);
            warm_start_sides(m, &mut pair, points);
            pair.store(m, states);
        }
    }
}

/// 1 in the lanes whose bit is set in `bits`, else 0.
#[inline(always)]
fn lane_ones<F: Lane>(bits: u8) -> F {
    let mut ones = [0.0; LANES];
    for (lane, one) in ones.iter_mut().enumerate() {
        if bits >> lane & 1 == 1 {
            *one = 1.0;
        }
    }
    F::from_array(ones)
}

/// [`warm_start_exact_impl`] for one batch: each point's accumulated impulse on side A in
/// the lanes of [`ManifoldLanes::exact_a`], on side B in those of
/// [`ManifoldLanes::exact_b`].
#[inline(always)]
fn warm_start_sides<F: Lane, L: LinearResponse<F>>(
    m: &ManifoldLanes<F>,
    pair: &mut Pair<F, L>,
    points: &[PointLanes<F>],
) {
    let (on_a, on_b) = (lane_ones::<F>(m.exact_a), lane_ones::<F>(m.exact_b));
    // The operations of `warm_start_impl`, lane-masked by side.
    for p in points {
        let (na, nb) = (p.normal_impulse * on_a, p.normal_impulse * on_b);
        pair.a.linear += pair.inv_mass_a.times(p.normal * na);
        pair.a.angular += p.ang_a_normal * na;
        pair.b.linear -= pair.inv_mass_b.times(p.normal * nb);
        pair.b.angular -= p.ang_b_normal * nb;
        if m.friction {
            let [t1, t2] = p.tangent_impulse;
            let (t1a, t2a, t1b, t2b) = (t1 * on_a, t2 * on_a, t1 * on_b, t2 * on_b);
            pair.a.linear += pair.inv_mass_a.times(p.tangent1 * t1a + p.tangent2 * t2a);
            pair.a.angular += p.ang_a_tangent1 * t1a + p.ang_a_tangent2 * t2a;
            pair.b.linear -= pair.inv_mass_b.times(p.tangent1 * t1b + p.tangent2 * t2b);
            pair.b.angular -= p.ang_b_tangent1 * t1b + p.ang_b_tangent2 * t2b;
        }
    }
}

wide_kernel! {
    /// [`warm_start_exact_impl`] over some batches.
    pub(crate) fn warm_start_exact_range() = warm_start_exact_impl;
}

/// Applies every contact's accumulated impulse (the previous substep's, or on the first
/// substep the previous step's): the solver then only corrects what changed.
pub fn warm_start(batches: &mut Batches, states: &mut [BodyState]) {
    let Batches {
        manifolds, points, ..
    } = batches;
    warm_start_range(manifolds, points, 0, share(states));
}

wide_kernel! {
    /// [`warm_start`] over some batches.
    pub(crate) fn warm_start_range() = warm_start_impl;
}

/// Newton iterations of the friction disk projection (see [`solve_friction`]), started from
/// a lower bound of the root that is exact for an isotropic K. Two leave the impulse within
/// 10⁻⁴·r of the exact projection while K's eigenvalues differ by up to five times (a box's
/// corner: about 2.2) and within 3·10⁻²·r at thirty times (unit test
/// `disk_projection_matches_the_exact_one`). Each further iteration cost about 2.5% of a
/// resting pyramid's resolve stage in the form with three divisions per step
/// (benches/RESULTS.md, "A cheaper relax pass"); the present form takes one and was not
/// measured per iteration.
const DISK_PROJECTION_ITERATIONS: usize = 2;

/// Friction for one point of eight lanes: both tangents at once with the 2×2 effective mass
/// K (the unconstrained impulse λ* = λ_old − K⁻¹·v_t stops the sliding dead, v_t the relative
/// tangential velocity plus [`PointLanes::chord`]), accumulated and
/// kept in the disk |λ| ≤ r = μ·λ_n.
///
/// Over the limit, the accumulated impulse is the point of the disk closest to λ* in K's
/// metric, the impulse that leaves the least tangential kinetic energy (maximal dissipation):
/// λ = (K + νI)⁻¹·K·λ* with ν ≥ 0 such that |λ| = r, found by Newton's method on
/// 1/|λ(ν)| − 1/r. For fast sliding this is r along −v_t, dynamic friction opposing the
/// sliding velocity; for a contact only just over the limit it is next to λ*. Scaling λ*
/// back onto the disk instead, as is common, is the projection in the wrong metric: wherever
/// the rotational terms make K anisotropic (at a box's corners) it turns the friction away from
/// −v_t, and a box sliding on the ground felt only 0.936·μ.
#[inline(always)]
fn solve_friction<F: Lane, L: LinearResponse<F>>(
    pair: &mut Pair<F, L>,
    p: &mut PointLanes<F>,
    chord_time: F,
) {
    let dv = pair.relative_velocity(p);
    let [d1, d2] = friction_change(p, dv.dot(p.tangent1), dv.dot(p.tangent2), chord_time);
    pair.apply_tangent(p, d1, d2);
}

/// The friction row of [`solve_friction`] at tangential velocities `vt1`, `vt2`: updates
/// the point's accumulated tangent impulse and returns its change, to be applied.
#[inline(always)]
fn friction_change<F: Lane>(p: &mut PointLanes<F>, vt1: F, vt2: F, chord_time: F) -> [F; 2] {
    let [k0, k1, k2] = p.tangent_mass;
    let vt1 = vt1 + p.chord[0] * chord_time;
    let vt2 = vt2 + p.chord[1] * chord_time;
    let [old1, old2] = p.tangent_impulse;
    let mut new1 = old1 - (k0 * vt1 + k1 * vt2);
    let mut new2 = old2 - (k1 * vt1 + k2 * vt2);
    let limit = p.friction * p.normal_impulse;
    // Compared in units of the limit where squares of impulses would leave f32's range
    // (bodies of about 10²⁰ kg and more); elsewhere exactly as before.
    let large = limit.cmpgt(F::splat(LARGE_TANGENT_MASS));
    let per_limit = F::select(large, limit.recip(), F::ONE);
    let (s1, s2, scaled_limit) = (new1 * per_limit, new2 * per_limit, limit * per_limit);
    let len_sq = s1 * s1 + s2 * s2;
    let over = len_sq.cmpgt(scaled_limit * scaled_limit);
    if over.any() {
        // Most lanes over the limit have none (no normal impulse: a speculative contact, an
        // unloaded corner) and simply get no friction; the projection is for the others.
        if (over & limit.cmpgt(F::ZERO)).any() {
            [new1, new2] = project_to_disk(p.tangent_mass, [new1, new2], limit, over);
        } else {
            new1 = F::select(over, F::ZERO, new1);
            new2 = F::select(over, F::ZERO, new2);
        }
    }
    p.tangent_impulse = [new1, new2];
    [new1 - old1, new2 - old2]
}

/// Trace of K⁻¹ (kg), or friction limit (N·s), above which the friction row's cone test and
/// [`project_to_disk`] work in scaled units, so that no square leaves f32's range.
const LARGE_TANGENT_MASS: f32 = 1e12;

/// The point of the disk of radius `r` closest to `target` in the metric of K, where
/// `inv_k` = K⁻¹ (symmetric: \[0,0\], \[0,1\], \[1,1\]), for the lanes in `over` (|target| > r ≥ 0);
/// other lanes keep `target`. Lanes whose K⁻¹ is singular fall back to scaling `target` onto
/// the disk. The result is scaled onto the circle exactly, so |λ| ≤ r holds to rounding.
#[inline(always)]
fn project_to_disk<F: Lane>(inv_k: [F; 3], target: [F; 2], r: F, over: F::Mask) -> [F; 2] {
    // The closest point does not change when K is scaled, and scales with the disk: solved for
    // K⁻¹ of unit trace and the unit disk where K⁻¹ (masses) or the disk exceed
    // [`LARGE_TANGENT_MASS`], so that no product leaves f32's range (for a box of 8·10¹⁹ kg on
    // the ground det K⁻¹ overflowed); elsewhere exactly as before.
    let [a, b, c] = inv_k;
    let trace = a + c;
    let large = trace.cmpgt(F::splat(LARGE_TANGENT_MASS)) | r.cmpgt(F::splat(LARGE_TANGENT_MASS));
    let unit = F::select(large & trace.cmpgt(F::ZERO), trace.recip(), F::ONE);
    let (a, b, c) = (a * unit, b * unit, c * unit);
    let (full_target, full_r) = (target, r);
    let to_unit = F::select(large & r.cmpgt(F::ZERO), r.recip(), F::ONE);
    let target = [target[0] * to_unit, target[1] * to_unit];
    let r = r * to_unit;
    let det_inv = a * c - b * b;
    let invertible = det_inv.cmpgt(F::ZERO);
    let scale = F::select(invertible, det_inv.recip(), F::ZERO);
    // K = (K⁻¹)⁻¹.
    let (k11, k12, k22) = (c * scale, -b * scale, a * scale);
    // b = K·target: the right-hand side of (K + νI)·λ = K·target.
    let rhs1 = k11 * target[0] + k12 * target[1];
    let rhs2 = k12 * target[0] + k22 * target[1];
    let inv_r = r.recip();
    // Newton's method from below converges monotonically. A lower bound of the root: with
    // k_min the smaller eigenvalue of K, |λ(ν)| ≥ k_min/(k_min + ν)·|target|, which is r at
    // ν = k_min·(|target|/r − 1); exact when K is isotropic.
    let half_trace = (k11 + k22) * F::splat(0.5);
    let half_diff = (k11 - k22) * F::splat(0.5);
    let k_min = half_trace - (half_diff * half_diff + k12 * k12).sqrt();
    let target_len = (target[0] * target[0] + target[1] * target[1]).sqrt();
    let start = k_min * (target_len * inv_r - F::ONE);
    let mut nu = F::select(start.is_finite_mask(), start.max(F::ZERO), F::ZERO);
    // Newton on ψ(ν) = 1/|λ(ν)| − 1/r, ψ'(ν) = −(λ·dλ/dν)/|λ|³ with dλ/dν = −(K + νI)⁻¹·λ,
    // written in u = adj(K + νI)·b = det·λ (det = det(K + νI) > 0), where the determinant
    // cancels: ν ← ν − |u|²·(det − |u|/r) / (uᵀ·adj(K + νI)·u). One division and one square
    // root per step (the same step as in λ, which takes three divisions), and the point on
    // the circle is u·r/|u|.
    for _ in 0..DISK_PROJECTION_ITERATIONS {
        let (m11, m22) = (k11 + nu, k22 + nu);
        let det = m11 * m22 - k12 * k12;
        let u = [m22 * rhs1 - k12 * rhs2, m11 * rhs2 - k12 * rhs1];
        let u_sq = u[0] * u[0] + u[1] * u[1];
        let adj_u = [m22 * u[0] - k12 * u[1], m11 * u[1] - k12 * u[0]];
        let w = u[0] * adj_u[0] + u[1] * adj_u[1];
        // |u|²/w (about 1/K) before the product, which keeps it within f32's range.
        nu = (nu - u_sq / w * (det - u_sq.sqrt() * inv_r)).max(F::ZERO);
    }
    let (m11, m22) = (k11 + nu, k22 + nu);
    let u = [m22 * rhs1 - k12 * rhs2, m11 * rhs2 - k12 * rhs1];
    // Exactly onto the circle; the Newton result is already there to rounding.
    let len = (u[0] * u[0] + u[1] * u[1]).sqrt();
    let projected = [u[0] * (full_r / len), u[1] * (full_r / len)];
    let scaled = [
        target[0] * (full_r / target_len),
        target[1] * (full_r / target_len),
    ];
    let usable = invertible
        & len.cmpgt(F::ZERO)
        & projected[0].is_finite_mask()
        & projected[1].is_finite_mask();
    // Not a closure: it would not be compiled with the kernel's target features.
    [
        F::select(
            over,
            F::select(usable, projected[0], scaled[0]),
            full_target[0],
        ),
        F::select(
            over,
            F::select(usable, projected[1], scaled[1]),
            full_target[1],
        ),
    ]
}

/// Adds `delta` to the point's accumulated normal impulse, clamped so that the total never
/// pulls (≥ 0), and applies the change that remains to the pair.
#[inline(always)]
fn accumulate_normal<F: Lane, L: LinearResponse<F>>(
    pair: &mut Pair<F, L>,
    p: &mut PointLanes<F>,
    delta: F,
) {
    let delta = clamp_normal(p, delta);
    pair.apply_normal(p, delta);
}

/// Adds `delta` to the point's accumulated normal impulse, clamped so that the total never
/// pulls (≥ 0); returns the change that remains, for the caller to apply.
#[inline(always)]
fn clamp_normal<F: Lane>(p: &mut PointLanes<F>, delta: F) -> F {
    let total = (p.normal_impulse + delta).max(F::ZERO);
    let delta = total - p.normal_impulse;
    p.normal_impulse = total;
    p.max_normal_impulse = p.max_normal_impulse.max(delta);
    delta
}

/// A speculative point's gap rule as a bias (m/s): it may close at most its gap `s` (> 0)
/// within the substep; zero for a touching or overlapping point.
#[inline(always)]
fn gap_bias<F: Lane>(s: F, inv_h: F) -> F {
    F::select(s.cmpgt(F::ZERO), s * inv_h, F::ZERO)
}

/// One rigid, unbiased normal row (a speculative point keeps its gap rule: it may close at
/// most its gap within the substep), as the relax pass and rigid contacts solve it; `s` is
/// the point's separation now ([`separation`]).
#[inline(always)]
fn solve_normal_rigid<F: Lane, L: LinearResponse<F>>(
    pair: &mut Pair<F, L>,
    p: &mut PointLanes<F>,
    s: F,
    inv_h: F,
) {
    accumulate_normal(pair, p, rigid_row(pair, p, s, inv_h));
}

/// The increment of one rigid, unbiased normal row before the clamp ([`solve_normal_rigid`]).
#[inline(always)]
fn rigid_row<F: Lane, L: LinearResponse<F>>(
    pair: &Pair<F, L>,
    p: &PointLanes<F>,
    s: F,
    inv_h: F,
) -> F {
    -p.normal_mass * rigid_residual(pair, p, s, inv_h)
}

/// What a rigid row asks to remove: the normal velocity, plus a speculative point's gap
/// rule s/h (it may close at most its gap `s` within the substep).
#[inline(always)]
fn rigid_residual<F: Lane, L: LinearResponse<F>>(
    pair: &Pair<F, L>,
    p: &PointLanes<F>,
    s: F,
    inv_h: F,
) -> F {
    let vn = pair.relative_velocity(p).dot(p.normal);
    vn + gap_bias(s, inv_h)
}

/// Which pass a row of [`row_residuals`] is taken in.
#[derive(Clone, Copy, Debug)]
pub enum RowPass {
    /// The biased pass ([`solve`]) with these parameters.
    Biased(BiasedPass),
    /// The relax pass ([`relax`]) at 1/substep `inv_h` (1/s).
    Relax {
        /// 1/substep (1/s).
        inv_h: f32,
        /// [`BiasedPass::chord_time`].
        chord_time: f32,
    },
}

/// A point's row as a pass would solve it next ([`row_residuals`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RowState {
    /// The velocity change the row asks for (m/s): the impulse change x it wants meets
    /// (J·M⁻¹·Jᵀ·x) + compliance·x = r, before its clamp.
    pub r: f32,
    /// The row's compliance (m/s per N·s).
    pub compliance: f32,
}

/// The row of point `point` (an index into `batches.points`) of every lane of batch `batch`
/// at the bodies' current velocities, as the pass would solve it next, lane by lane;
/// [`super::direct`] solves these rows of a whole island at once. The same arithmetic as
/// the pass's own kernels.
pub fn row_residuals(
    manifolds: &[ManifoldLanes],
    points: &[PointLanes],
    states: &[Shared<BodyState>],
    batch: usize,
    point: usize,
    pass: RowPass,
) -> [RowState; LANES] {
    let m = &manifolds[batch];
    let p = &points[point];
    let pair = Pair::<F8>::load(m, states);
    let s = separation(p, &gather_motion(states, m.a), &gather_motion(states, m.b));
    let soft_mass = p.normal_mass * p.mass_scale;
    let (delta, mass, compliance) = match pass {
        RowPass::Biased(pass) => {
            let row = biased_row(&pair, p, s, &BiasedConsts::new(&pass));
            (row.delta, row.mass, row.compliance)
        }
        RowPass::Relax { inv_h, .. } => {
            // The rigid row, with its spring's compliance all the same: the rows of a face
            // span fewer motions than it has points, and a speculative row's gap rule need
            // not agree with any rigid motion at all; the compliance shares the impulse among
            // them as the springs do, where a rigid solve would put it on some points only.
            let spring = F8::select(
                soft_mass.cmpgt(F8::ZERO),
                p.impulse_scale / soft_mass,
                F8::ZERO,
            );
            (
                rigid_row(&pair, p, s, F8::splat(inv_h)),
                p.normal_mass,
                spring,
            )
        }
    };
    std::array::from_fn(|l| RowState {
        r: if mass[l] > 0.0 {
            delta[l] / mass[l]
        } else {
            0.0
        },
        compliance: compliance[l],
    })
}

/// The normal velocity of A's point relative to B's under the pseudo velocities (m/s).
#[inline(always)]
fn pseudo_normal_velocity<F: Lane>(
    pseudo: &(Velocities<F>, Velocities<F>),
    p: &PointLanes<F>,
) -> F {
    let (pa, pb) = (&pseudo.0, &pseudo.1);
    ((pa.linear + pa.angular.cross(p.r_a)) - (pb.linear + pb.angular.cross(p.r_b))).dot(p.normal)
}

/// Applies the pseudo impulse `push` (on A along n, on B opposite) to the pseudo velocities.
#[inline(always)]
fn apply_pseudo<F: Lane, L: LinearResponse<F>>(
    pseudo: &mut (Velocities<F>, Velocities<F>),
    pair: &Pair<F, L>,
    p: &PointLanes<F>,
    push: F,
) {
    let impulse = p.normal * push;
    pseudo.0.linear += pair.inv_mass_a.times(impulse);
    pseudo.0.angular += p.ang_a_normal * push;
    pseudo.1.linear -= pair.inv_mass_b.times(impulse);
    pseudo.1.angular -= p.ang_b_normal * push;
}

/// The relax pass over one batch: every point's normal row rigid and unbiased (a
/// speculative point keeps its gap rule), then its friction; with `sweeps` > 1 (rigid
/// contacts) all the normal rows `sweeps` times first, then the friction.
#[inline(always)]
fn relax_batch<F: Lane, L: LinearResponse<F>>(
    m: &ManifoldLanes<F>,
    pair: &mut Pair<F, L>,
    points: &mut [PointLanes<F>],
    states: &[Shared<BodyState>],
    inv_h: f32,
    chord_time: f32,
    sweeps: u32,
) {
    let inv_h = F::splat(inv_h);
    let chord_time = F::splat(chord_time);
    // The separations at the poses this substep reached: kept for the next substep's biased
    // pass, which starts from the same poses (`BiasedPass::stored_separation`).
    store_separations(m, points, states);
    if sweeps > 1 {
        // Rigid contacts: the normal rows first, `sweeps` times, then friction.
        for _ in 0..sweeps {
            for p in points.iter_mut() {
                solve_normal_rigid(pair, p, p.separation, inv_h);
            }
        }
        if m.friction {
            for p in points.iter_mut() {
                solve_friction(pair, p, chord_time);
            }
        }
        return;
    }
    for p in points.iter_mut() {
        relax_point(m, pair, p, inv_h, chord_time);
    }
}

/// Relative regularisation of the block system of [`relax_block`]: K + ε·diag(K). A face's
/// four rows span three motions, so K alone is singular, and the part of the right-hand side
/// K cannot produce (the bias of a speculative corner, a face's points at slightly different
/// depths) would be amplified by 1/ε. At 10⁻⁴, with each point's total clamped on its own,
/// that made impulses of ±2,000 N·s on a resting 1,000 kg box and threw it up at 3.9 m/s; at
/// 0.1 the block is an under-relaxed exact solve (each row reaches 1/1.1 of its target in one
/// pass, the rest in the next substeps), with which every case of the stability family meets
/// its criterion (benches/RESULTS.md, "Each manifold's normal rows solved together").
const BLOCK_REGULARISATION: f32 = 0.1;

/// The index in [`ManifoldLanes::block`] of L's entry (i, j), i > j.
#[inline(always)]
const fn below(i: usize, j: usize) -> usize {
    i * (i - 1) / 2 + j
}

/// Factors each batch's block system for `relax_block`, once per step: K = J·M⁻¹·Jᵀ over
/// the batch's points (lane by lane), plus ε·diag(K) (`BLOCK_REGULARISATION`), as L·Lᵀ into
/// [`ManifoldLanes::block`]. A padding point (no row) gets an identity row. The Jacobians and
/// masses are the step's, fixed through its substeps.
pub fn factor_blocks(batches: &mut Batches) {
    let Batches {
        manifolds, points, ..
    } = batches;
    factor_block_range(manifolds, points, 0);
}

/// [`factor_blocks`] for a run of the batches whose points are `points`, the first being
/// point `base` of all batches. Each batch is factored on its own, so runs may be factored in
/// any order, or at once on several threads, with the same result.
pub fn factor_block_range(manifolds: &mut [ManifoldLanes], points: &mut [PointLanes], base: u32) {
    with_best_lanes!(factor_blocks_impl(manifolds, points, base: u32) -> ())
}

#[inline(always)]
fn factor_blocks_impl<F: Lane>(
    manifolds: &mut [ManifoldLanes<F>],
    points: &mut [PointLanes<F>],
    base: u32,
) {
    for m in manifolds.iter_mut().filter(|m| !m.side) {
        let first = (m.first - base) as usize;
        let pts = &points[first..first + m.count as usize];
        m.block = factor_block::<F>(m, pts);
    }
}

// Index loops: the factorisation reads L by row and column, as the formulas do.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn factor_block<F: Lane>(m: &ManifoldLanes<F>, points: &[PointLanes<F>]) -> [F; BLOCK_ENTRIES] {
    let n = points.len().min(MAX_POINTS);
    let zero = V3x8 {
        x: F::ZERO,
        y: F::ZERO,
        z: F::ZERO,
    };
    let mut rn_a = [zero; MAX_POINTS];
    let mut rn_b = [zero; MAX_POINTS];
    for (i, p) in points.iter().take(n).enumerate() {
        rn_a[i] = p.r_a.cross(p.normal);
        rn_b[i] = p.r_b.cross(p.normal);
    }
    let m_axes = m.inv_mass_a + m.inv_mass_b;
    let (m_sum, uniform) = (m_axes.x, m.inv_mass_a.uniform() & m.inv_mass_b.uniform());
    let mut k = [[F::ZERO; MAX_POINTS]; MAX_POINTS];
    for i in 0..n {
        for j in 0..=i {
            let (pi, pj) = (&points[i], &points[j]);
            let linear = F::select(
                uniform,
                pi.normal.dot(pj.normal) * m_sum,
                m_axes.scale(pi.normal).dot(pj.normal),
            );
            let kij = linear + rn_a[i].dot(pj.ang_a_normal) + rn_b[i].dot(pj.ang_b_normal);
            k[i][j] = kij;
            k[j][i] = kij;
        }
    }
    for (i, p) in points.iter().take(n).enumerate() {
        let live = p.normal_mass.cmpgt(F::ZERO);
        k[i][i] = F::select(live, k[i][i] * F::splat(1.0 + BLOCK_REGULARISATION), F::ONE);
    }
    let mut block = [F::ZERO; BLOCK_ENTRIES];
    let mut l = [[F::ZERO; MAX_POINTS]; MAX_POINTS];
    for j in 0..n {
        let mut d = k[j][j];
        for q in 0..j {
            d = d - l[j][q] * l[j][q];
        }
        let root = d.max(F::splat(f32::MIN_POSITIVE)).sqrt();
        l[j][j] = root;
        let inv = root.recip();
        block[6 + j] = inv;
        for i in j + 1..n {
            let mut s = k[i][j];
            for q in 0..j {
                s = s - l[i][q] * l[j][q];
            }
            l[i][j] = s * inv;
            block[below(i, j)] = l[i][j];
        }
    }
    block
}

/// The relax pass over one batch with each manifold's normal rows solved together: the
/// impulses x of all its points at once from (K + ε·diag K)·x = −(vₙ + bias), K = J·M⁻¹·Jᵀ
/// over the manifold's points (factored once per step, [`factor_blocks`]), then each point's
/// friction in order ([`super::SoftStepSettings::block_relax`]).
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn relax_block<F: Lane, L: LinearResponse<F>>(
    m: &ManifoldLanes<F>,
    pair: &mut Pair<F, L>,
    points: &mut [PointLanes<F>],
    states: &[Shared<BodyState>],
    inv_h: F,
    chord_time: F,
) {
    store_separations(m, points, states);
    if m.side {
        // Near horizontal: point by point, as a lane whose block solution pulls.
        for p in points.iter_mut() {
            relax_point(m, pair, p, inv_h, chord_time);
        }
        return;
    }
    let mut b = [F::ZERO; MAX_POINTS];
    // The block serves lanes with two or more points (a single point's row is exact point by
    // point, and the regularisation would only under-relax it). A speculative point keeps its
    // gap rule in the block: its bias s/h, which K need not be able to produce; excluding such
    // lanes instead (solved point by point) let the column of 10 m boxes sway 1.4 m.
    for (i, p) in points.iter().take(MAX_POINTS).enumerate() {
        // A padding point's row is zero: its right-hand side too.
        b[i] = F::select(
            p.normal_mass.cmpgt(F::ZERO),
            rigid_residual(pair, p, p.separation, inv_h),
            F::ZERO,
        );
    }
    // A lane of one point; not a padding lane (no point at all), which takes no impulse
    // either way, so that a batch with one does not fall back point by point for it.
    let single = match (points.first(), points.get(1)) {
        (Some(first), Some(second)) => {
            second.normal_mass.cmple(F::ZERO) & first.normal_mass.cmpgt(F::ZERO)
        }
        _ => F::ZERO.cmple(F::ZERO),
    };
    // L·y = −b, then Lᵀ·x = y, over all MAX_POINTS rows: a row past the batch's points has
    // b = 0 and a zero factor (`factor_block` leaves it so), hence x = 0, and fixed bounds let
    // the loops unroll into registers.
    let l = &m.block;
    let mut y = [F::ZERO; MAX_POINTS];
    for i in 0..MAX_POINTS {
        let mut s = F::ZERO - b[i];
        for q in 0..i {
            s = s - l[below(i, q)] * y[q];
        }
        y[i] = s * l[6 + i];
    }
    let mut x = [F::ZERO; MAX_POINTS];
    for i in (0..MAX_POINTS).rev() {
        let mut s = y[i];
        for q in i + 1..MAX_POINTS {
            s = s - l[below(q, i)] * x[q];
        }
        x[i] = s * l[6 + i];
    }
    // `pulls` marks the lanes solved point by point instead: a lane the block does not serve,
    // or one where some point's total would pull. Clamping that point alone would turn the
    // opposite impulses of a face's twist (which the system leaves nearly free) into a net
    // push, so such a lane takes none of the block's impulses.
    let mut pulls = single;
    for (p, &dx) in points.iter().zip(&x) {
        pulls = pulls | (p.normal_impulse + dx).cmplt(F::ZERO);
    }
    for (p, &dx) in points.iter_mut().zip(&x) {
        accumulate_normal(pair, p, F::select(pulls, F::ZERO, dx));
    }
    let fallback = pulls.any();
    for p in points.iter_mut() {
        if fallback {
            let gs = rigid_row(pair, p, p.separation, inv_h);
            accumulate_normal(pair, p, F::select(pulls, gs, F::ZERO));
        }
        if m.friction {
            solve_friction(pair, p, chord_time);
        }
    }
}

/// One point of a single relax sweep: its normal row, then its friction. Friction's
/// tangential velocity is the normal row's, plus what the normal impulse just changed
/// ([`PointLanes::normal_tangent`]), and both impulses are applied at once: no second
/// relative velocity waits between the normal impulse and friction's.
#[inline(always)]
fn relax_point<F: Lane, L: LinearResponse<F>>(
    m: &ManifoldLanes<F>,
    pair: &mut Pair<F, L>,
    p: &mut PointLanes<F>,
    inv_h: F,
    chord_time: F,
) {
    if !m.friction {
        solve_normal_rigid(pair, p, p.separation, inv_h);
        return;
    }
    let dv = pair.relative_velocity(p);
    let delta = -p.normal_mass * (dv.dot(p.normal) + gap_bias(p.separation, inv_h));
    let dn = clamp_normal(p, delta);
    let [c1, c2] = p.normal_tangent;
    let vt1 = dv.dot(p.tangent1) + dn * c1;
    let vt2 = dv.dot(p.tangent2) + dn * c2;
    let [d1, d2] = friction_change(p, vt1, vt2, chord_time);
    let impulse = p.normal * dn + p.tangent1 * d1 + p.tangent2 * d2;
    pair.a.linear += pair.inv_mass_a.times(impulse);
    pair.a.angular += p.ang_a_normal * dn + p.ang_a_tangent1 * d1 + p.ang_a_tangent2 * d2;
    pair.b.linear -= pair.inv_mass_b.times(impulse);
    pair.b.angular -= p.ang_b_normal * dn + p.ang_b_tangent1 * d1 + p.ang_b_tangent2 * d2;
}

/// The parameters of one biased pass ([`solve`]).
#[derive(Clone, Copy, Debug)]
pub struct BiasedPass {
    /// 1/substep (1/s).
    pub inv_h: f32,
    /// Largest push-out speed of the soft bias (m/s): [`super::SoftStepSettings::max_push_out`]
    /// scaled by gravity beyond [`super::PUSH_OUT_GRAVITY`] ([`super::push_out_speed`]).
    pub max_push_out: f32,
    /// Overlap (m) beyond a resting contact's static compression still pushed out through
    /// real velocity ([`super::SoftStepSettings::push_out_slop`]); with `rigid`, the overlap
    /// left alone ([`super::SoftStepSettings::rigid_slop`]).
    pub slop: f32,
    /// Approach speed (m/s) at the start of the step below which a loaded contact is resting.
    pub resting_speed: f32,
    /// Speed (m/s) gravity adds in one substep, |g|·h: a resting spring's equilibrium sits
    /// that much bias speed beyond its static compression.
    pub gravity_speed: f32,
    /// Solve friction too ([`super::SoftStepSettings::friction_in_bias_pass`]).
    pub friction: bool,
    /// Rigid contacts ([`super::SoftStepSettings::rigid_contacts`]): `solve_batch_rigid`
    /// instead of `solve_batch_split`, with `slop` the overlap left alone.
    pub rigid: bool,
    /// Sweeps over a manifold's normal rows ([`super::SoftStepSettings::normal_sweeps`]):
    /// every manifold's with rigid contacts; with soft ones, those of a manifold (a lane of
    /// its batch) that no direct island solves and where some point approached faster than
    /// `impact_speed` at the start of the step, or the bodies approach that fast now or part
    /// that fast under load (`solve_batch_split`, `impacts_now`).
    pub sweeps: u32,
    /// Approach speed (m/s) at the start of the step beyond which a contact is an impact:
    /// |g|·dt, the most that gravity adds in a step (a resting contact approaches at a
    /// fraction of it); 0 without gravity.
    pub impact_speed: f32,
    /// Push-out rate of rigid contacts (1/s):
    /// [`super::SoftStepSettings::push_out_rate`] / h.
    pub rate: f32,
    /// Every point's [`PointLanes::separation`] holds its separation at the bodies' poses
    /// now: the relax pass of the substep before stored it, at the same poses (the velocity
    /// integration between moves no body). The split pass then takes it instead of
    /// computing it again; rigid contacts compute it always.
    pub stored_separation: bool,
    /// The pass follows the warm start (the first substep's): where it solves no friction, each
    /// point's carried friction impulse is kept within the cone of its normal impulse as the
    /// pass leaves it ([`keep_in_cone`]).
    pub after_warm_start: bool,
    /// Time (s) from the start of the step to the middle of this substep, (k + ½)·h: friction
    /// holds the relative velocity plus [`PointLanes::chord`] times this at zero, so that a
    /// sticking point's velocity turns through the step as the point it sticks to does.
    pub chord_time: f32,
}

/// The biased pass over one batch with rigid contacts
/// ([`super::SoftStepSettings::rigid_contacts`]): the normal rows rigid and unbiased (a
/// speculative point keeps its gap rule) in `pass.sweeps` Gauss-Seidel sweeps over the
/// manifold, then friction; then the overlap beyond `pass.slop` is pushed out at `pass.rate`
/// (at most `max_push_out`) through the pseudo velocities, again in `pass.sweeps` sweeps with
/// each point's pseudo impulse accumulated and kept ≥ 0. Nothing of the push-out reaches
/// real velocity, and no spring lets a loaded contact sink: the overlap a step leaves is the
/// slop plus what the unconverged solve let through.
#[inline(always)]
fn solve_batch_rigid<F: Lane, L: LinearResponse<F>>(
    m: &ManifoldLanes<F>,
    pair: &mut Pair<F, L>,
    pseudo: &mut (Velocities<F>, Velocities<F>),
    live: &mut bool,
    points: &mut [PointLanes<F>],
    states: &[Shared<BodyState>],
    pass: BiasedPass,
) {
    let (motion_a, motion_b) = (gather_motion(states, m.a), gather_motion(states, m.b));
    let inv_h = F::splat(pass.inv_h);
    let push_out = F::splat(pass.max_push_out);
    let slop = F::splat(pass.slop);
    let rate = F::splat(pass.rate);
    debug_assert!(points.len() <= MAX_POINTS);
    let mut now = [F::ZERO; MAX_POINTS];
    for (p, s) in points.iter().zip(now.iter_mut()) {
        *s = separation(p, &motion_a, &motion_b);
    }
    for _ in 0..pass.sweeps {
        for (p, &s) in points.iter_mut().zip(&now) {
            solve_normal_rigid(pair, p, s, inv_h);
        }
    }
    if pass.friction && m.friction {
        for p in points.iter_mut() {
            solve_friction(pair, p, F::splat(pass.chord_time));
        }
    }
    let mut any = *live;
    let mut targets = [F::ZERO; MAX_POINTS];
    for (p, t) in points.iter().zip(targets.iter_mut()) {
        let s = separation(p, &motion_a, &motion_b);
        let x = ((-s - slop) * rate).max(F::ZERO);
        *t = F::select(x.cmpgt(push_out), push_out, x);
        any |= t.cmpgt(F::ZERO).any();
    }
    if !any {
        return;
    }
    *live = true;
    let mut acc = [F::ZERO; MAX_POINTS];
    for _ in 0..pass.sweeps {
        for ((p, &t), acc) in points.iter().zip(targets.iter()).zip(acc.iter_mut()) {
            let vpn = pseudo_normal_velocity(pseudo, p);
            let total = (*acc + p.normal_mass * (t - vpn)).max(F::ZERO);
            apply_pseudo(pseudo, pair, p, total - *acc);
            *acc = total;
        }
    }
}

/// [`BiasedPass`]'s numbers as lanes, splatted once per batch.
struct BiasedConsts<F> {
    inv_h: F,
    push_out: F,
    resting_speed: F,
    slop: F,
    gravity_speed: F,
}

impl<F: Lane> BiasedConsts<F> {
    #[inline(always)]
    fn new(pass: &BiasedPass) -> Self {
        Self {
            inv_h: F::splat(pass.inv_h),
            push_out: F::splat(-pass.max_push_out),
            resting_speed: F::splat(-pass.resting_speed),
            slop: F::splat(pass.slop),
            gravity_speed: F::splat(pass.gravity_speed),
        }
    }
}

/// One point's row in the biased pass at the pair's current velocities
/// ([`solve_batch_split`]): the increment of its normal impulse before the clamp, the
/// overlap's excess for the pseudo velocities, and the row as a linear equation in the
/// impulse, `delta = −mass·(vₙ + c + compliance·λ)` (for [`super::direct`]).
struct BiasedRow<F> {
    delta: F,
    excess: F,
    mass: F,
    compliance: F,
}

/// `s` is the point's separation now ([`separation`]).
#[inline(always)]
fn biased_row<F: Lane, L: LinearResponse<F>>(
    pair: &Pair<F, L>,
    p: &PointLanes<F>,
    s: F,
    c: &BiasedConsts<F>,
) -> BiasedRow<F> {
    let speculative = s.cmpgt(F::ZERO);
    let soft_mass = p.normal_mass * p.mass_scale;
    let bleed = p.impulse_scale * p.normal_impulse;
    // The bias as an impulse (≤ 0 on overlap), with the spring compressed by its preload
    // too (in proportion to the overlap up to the full preload: a preload that set in at
    // first touch would pump the bounces of a rocking box), and the part of it the load
    // explains.
    let extra = (-s * p.preload_slope).max(F::ZERO);
    let extra = F::select(extra.cmpgt(p.preload), p.preload, extra);
    let spring = F::select(speculative, s, s - extra);
    // The whole bias is capped at the push-out speed (scaled with gravity beyond Earth's,
    // `BiasedPass::max_push_out`): a cap on only the push beyond the load let a box crushed
    // between two closing kinematic walls ratchet its springs' load up step after step, and it
    // left at 31 m/s (benches/RESULTS.md, "A crushed box thrown out, and rods spun up").
    let bias = soft_mass * (p.bias_rate * spring).max(c.push_out);
    let resting = p.normal_impulse.cmpgt(F::ZERO) & c.resting_speed.cmplt(p.relative_velocity);
    let allowance = F::select(resting, p.bias_rate * c.slop + c.gravity_speed, F::ZERO);
    let vn = pair.relative_velocity(p).dot(p.normal);
    let carried = bias.max(-bleed - soft_mass * allowance);
    let excess = F::select(speculative, F::ZERO, bias - carried);

    let rigid = -p.normal_mass * (vn + s * c.inv_h);
    let soft = -soft_mass * vn - carried - bleed;
    BiasedRow {
        delta: F::select(speculative, rigid, soft),
        excess,
        mass: F::select(speculative, p.normal_mass, soft_mass),
        // Exact where the bias is carried (the bleed stays in the row: a spring). Where the
        // allowance holds, or the point is speculative, the row is rigid; its spring's
        // compliance is kept all the same, so that the rows of a face, whose targets need
        // not agree with any rigid motion there, stay a well-posed system.
        compliance: F::select(
            soft_mass.cmpgt(F::ZERO),
            p.impulse_scale / soft_mass,
            F::ZERO,
        ),
    }
}

/// The biased pass over one batch, with split impulses for overlap beyond what the load
/// explains.
///
/// The soft constraint's impulse is Δλ = −m·s_m·v_n − b − s_i·λ, with b = m·s_m·β·s the bias
/// (s < 0 on overlap, b clamped to the push-out speed) and s_i·λ the bleed that makes it a
/// spring. Under a steady load λ the spring settles where the two balance, b = −s_i·λ (s_i·λ
/// is exactly the bias of the spring's static compression λ/(h·k)): that much bias is the
/// spring carrying its load and stays in the real impulse, as in the plain soft step. On a
/// resting contact (one that carries a load, λ > 0, and approached slower than
/// `resting_speed` at the start of the step) so does an allowance of m·s_m·(β·`slop` + |g|·h):
/// the discrete equilibrium sits one substep of gravity's speed deeper (|g|·h/β: 1.1 mm between
/// bodies at the defaults, 4.5 mm at 4 substeps and 30 Hz, where the figures that follow were
/// measured), and a loaded spring must keep reacting to changes of its load through real
/// velocity. With every bias beyond the static compression in pseudo velocities the 20-row
/// pyramid drifts 34 mm in 10 s instead of 1 mm; with the slop alone (5 mm) and no gravity
/// term the 1:100 pair drifts 18 mm instead of 0.5 mm.
///
/// Any overlap deeper than that, and all overlap of a contact that carries no load or hit
/// fast (bodies that start overlapping, an impact), would be pushed out by the excess bias as
/// real velocity, which the single relax pass only partly takes back: that is how overlapping
/// starts gained kinetic energy (200 balls started at one point in zero gravity: 1.5 MJ). The
/// excess goes to the pseudo velocities v̂ instead (Δλ̂ = −m·s_m·v̂_n − excess, at least 0),
/// which move the bodies in this substep and are then discarded
/// ([`super::integrate::integrate_positions`]). Speculative points (a gap) keep the rigid gap
/// rule on the real velocity and get no pseudo impulse.
#[inline(always)]
fn solve_batch_split<F: Lane, L: LinearResponse<F>>(
    m: &ManifoldLanes<F>,
    pair: &mut Pair<F, L>,
    pseudo: &mut (Velocities<F>, Velocities<F>),
    live: &mut bool,
    points: &mut [PointLanes<F>],
    states: &[Shared<BodyState>],
    pass: BiasedPass,
) {
    let friction = pass.friction;
    if !pass.stored_separation {
        let (motion_a, motion_b) = (gather_motion(states, m.a), gather_motion(states, m.b));
        for p in points.iter_mut() {
            p.separation = separation(p, &motion_a, &motion_b);
        }
    }
    let consts = BiasedConsts::new(&pass);
    // The lanes of an impact that no direct island solves (lanes hold different manifolds:
    // a resting one beside a landing one keeps its single sweep).
    let none = F::ZERO.cmplt(F::ZERO);
    let impacts = if pass.sweeps > 1 {
        let below = F::splat(-pass.impact_speed);
        impacts(points, below) | impacts_now(pair, points, below)
    } else {
        none
    };
    let swept = if impacts.any() {
        impacts & lane_ones::<F>(m.direct).cmple(F::ZERO)
    } else {
        none
    };
    if swept.any() {
        // An impact: the manifold's normal rows swept `sweeps` times in all (these, then the
        // sweep below). One sweep leaves the rows solved in order: the first point takes the
        // impact, turns the body and leaves the others a different approach, and the face's
        // uneven impulses spin the body, which friction then turns into sliding (a unit box
        // landing flat at 50 m/s left the step at 0.83 m/s sideways and 1.7 rad/s;
        // benches/RESULTS.md, "A flat landing lands flat").
        // Not in the lanes a direct island solves: its solve after the pass solves their rows
        // together anyway, and sweeping them first changed how the perturbed columns of 60
        // landed (from 2.1 and 4.7 mm of drift to 19.0 and 10.8).
        for _ in 1..pass.sweeps {
            for p in points.iter_mut() {
                let row = biased_row(pair, p, p.separation, &consts);
                accumulate_normal(pair, p, F::select(swept, row.delta, F::ZERO));
            }
        }
    }
    for p in points.iter_mut() {
        let row = biased_row(pair, p, p.separation, &consts);
        accumulate_normal(pair, p, row.delta);

        // Pseudo velocities can only change where some lane has excess overlap or the
        // bodies already move with pseudo velocities (`live`); elsewhere push would be 0.
        let excess = row.excess;
        if *live || excess.cmplt(F::ZERO).any() {
            let soft_mass = p.normal_mass * p.mass_scale;
            let vpn = pseudo_normal_velocity(pseudo, p);
            let push = (-soft_mass * vpn - excess).max(F::ZERO);
            apply_pseudo(pseudo, pair, p, push);
            *live = true;
        }

        if m.friction && friction {
            solve_friction(pair, p, F::splat(pass.chord_time));
        } else if m.friction && pass.after_warm_start {
            keep_in_cone(pair, p);
        }
    }
}

/// Scales a point's accumulated friction impulse back into its cone, |λ_t| ≤ μ·λ_n, applying
/// the change: where the first biased pass (which solves no friction) took back the normal
/// impulse the warm start carried, the friction carried with it may no longer be there, and
/// until the relax pass it moved the body with the positions. A box crushed between two
/// closing walls carries impulses of a hundred times its momentum a step; when one wall passes
/// through it and its normal flips, the other's are taken back, and their friction threw a
/// 0.2 m box out at 10 m/s between walls moving at 0.13 m/s (benches/RESULTS.md, "Carried
/// friction kept in the cone"). Only after the warm start: clipped in every substep's biased
/// pass instead, 12 of the 28 crushes of that section's table still threw the box, against 7.
#[inline(always)]
fn keep_in_cone<F: Lane, L: LinearResponse<F>>(pair: &mut Pair<F, L>, p: &mut PointLanes<F>) {
    let [old1, old2] = p.tangent_impulse;
    let limit = p.friction * p.normal_impulse;
    let len_sq = old1 * old1 + old2 * old2;
    let over = len_sq.cmpgt(limit * limit);
    if over.any() {
        let scale = F::select(over, limit * len_sq.sqrt().recip(), F::ONE);
        let (new1, new2) = (old1 * scale, old2 * scale);
        p.tangent_impulse = [new1, new2];
        pair.apply_tangent(p, new1 - old1, new2 - old2);
    }
}

/// The lanes of `points` where some point approached faster than `-below` (m/s; `below` ≤ 0)
/// at the start of the step ([`PointLanes::relative_velocity`]; padding lanes hold 0).
#[inline(always)]
fn impacts<F: Lane>(points: &[PointLanes<F>], below: F) -> F::Mask {
    let none = F::ZERO.cmplt(F::ZERO);
    points
        .iter()
        .fold(none, |any, p| any | p.relative_velocity.cmplt(below))
}

/// The lanes of `points` whose bodies approach faster than `-below` (m/s; `below` ≤ 0) now,
/// along the first point's normal, or part that fast while some point carries an impulse:
/// an impact that began within the step (a box landing on one that rests passes its momentum
/// on to the ground in a later substep), or the one before it carried on by the warm start,
/// which applies every substep's accumulated impulses again (the biased pass then takes most
/// of them back). Either asks for more than one sweep of the rows as the start-of-step
/// approach does ([`impacts`]): solved once, in order, the first point takes the change, turns
/// the bodies and leaves a face's other points a different one (benches/RESULTS.md, "A
/// landing passed on lands flat"). Bodies' linear velocities only: this is for the pair's
/// whole approach, which the start-of-step test already catches for a turning body.
#[inline(always)]
fn impacts_now<F: Lane, L: LinearResponse<F>>(
    pair: &Pair<F, L>,
    points: &[PointLanes<F>],
    below: F,
) -> F::Mask {
    let none = F::ZERO.cmplt(F::ZERO);
    let Some(first) = points.first() else {
        return none;
    };
    let approach = (pair.a.linear - pair.b.linear).dot(first.normal);
    let loaded = points
        .iter()
        .fold(none, |any, p| any | p.normal_impulse.cmpgt(F::ZERO));
    approach.cmplt(below) | (loaded & (F::ZERO - approach).cmplt(below))
}

#[inline(always)]
fn solve_impl<F: Lane>(
    manifolds: &[ManifoldLanes<F>],
    points: &mut [PointLanes<F>],
    base: u32,
    states: &[Shared<BodyState>],
    pseudo: &[Shared<PseudoRow>],
    pass: BiasedPass,
) {
    // A batch loads and stores pseudo velocities only when one of its bodies already moves
    // with them or one of its points pushes: a settled scene's bodies never do (loading and
    // storing them for every batch costs the 20-row pyramid's resolve stage 13%).
    for_each_batch!(
        manifolds,
        points,
        base,
        states,
        |m, pair, points, states| {
            let mut live = any_pseudo(pseudo, m.a) || any_pseudo(pseudo, m.b);
            let mut split = if live {
                (gather_pseudo(pseudo, m.a), gather_pseudo(pseudo, m.b))
            } else {
                let zero = Velocities::from_columns([F::ZERO; 8]);
                (zero, zero)
            };
            if pass.rigid {
                solve_batch_rigid(m, pair, &mut split, &mut live, points, states, pass);
            } else {
                solve_batch_split(m, pair, &mut split, &mut live, points, states, pass);
            }
            if live {
                scatter_pseudo(pseudo, m.a, &split.0);
                scatter_pseudo(pseudo, m.b, &split.1);
            }
        }
    );
}

/// One biased pass with split impulses (`solve_batch_split`): every contact with its own
/// softness, the push-out of overlap beyond the load's (and beyond the allowance of resting
/// contacts; at most `max_push_out`, m/s) in the pseudo velocities `pseudo` (one
/// [`PseudoRow`] per body, zero at the start of the pass), with friction when
/// [`BiasedPass::friction`] is set; with [`BiasedPass::rigid`], rigid rows and the push-out
/// of all overlap beyond the slop (`solve_batch_rigid`).
pub fn solve(
    batches: &mut Batches,
    states: &mut [BodyState],
    pseudo: &mut [PseudoRow],
    pass: BiasedPass,
) {
    let Batches {
        manifolds, points, ..
    } = batches;
    solve_range(manifolds, points, 0, share(states), share(pseudo), pass);
}

wide_kernel! {
    /// [`solve`] over some batches.
    pub(crate) fn solve_range(pseudo: &[Shared<PseudoRow>], pass: BiasedPass) = solve_impl;
}

#[inline(always)]
fn relax_impl<F: Lane>(
    manifolds: &[ManifoldLanes<F>],
    points: &mut [PointLanes<F>],
    base: u32,
    states: &[Shared<BodyState>],
    pass: RelaxPass,
) {
    let RelaxPass {
        inv_h,
        chord_time,
        sweeps,
        block,
    } = pass;
    let mut rest = manifolds;
    if block {
        // Block relax (`SoftStepSettings::block_relax`). (Two block batches interleaved, as
        // below, measured no faster here.) Two side batches, solved point by point, are
        // interleaved as the plain relax's are.
        let inv_h_lanes = F::splat(inv_h);
        let chord_lanes = F::splat(chord_time);
        let mut i = 0;
        while i < manifolds.len() {
            let m0 = &manifolds[i];
            if let Some(m1) = manifolds.get(i + 1)
                && m0.side
                && m1.side
                && !m0.locked
                && !m1.locked
            {
                relax_two(m0, m1, points, base, states, inv_h_lanes, chord_lanes);
                i += 2;
                continue;
            }
            for_each_batch!(
                std::slice::from_ref(m0),
                &mut *points,
                base,
                states,
                |m, pair, points, states| {
                    relax_block(m, pair, points, states, inv_h_lanes, chord_lanes);
                }
            );
            i += 1;
        }
        return;
    }
    if sweeps == 1 {
        // Two batches at a time, their points interleaved (`relax_two`; 20-row pyramid,
        // resolve stage on one thread: 0.399 → 0.379 ms; the same interleave in the biased
        // pass gained nothing).
        let inv_h_lanes = F::splat(inv_h);
        let chord_lanes = F::splat(chord_time);
        let mut twos = manifolds.chunks_exact(2);
        for two in &mut twos {
            let (m0, m1) = (&two[0], &two[1]);
            if m0.locked || m1.locked {
                // A translation lock: one batch after the other (the same results).
                for_each_batch!(
                    two,
                    &mut *points,
                    base,
                    states,
                    |m, pair, points, states| {
                        relax_batch(m, pair, points, states, inv_h, chord_time, sweeps);
                    }
                );
                continue;
            }
            relax_two(m0, m1, points, base, states, inv_h_lanes, chord_lanes);
        }
        rest = twos.remainder();
    }
    for_each_batch!(rest, points, base, states, |m, pair, points, states| {
        relax_batch(m, pair, points, states, inv_h, chord_time, sweeps);
    });
}

/// The single relax sweep over two batches of one colour (neither with a translation lock),
/// their points interleaved: each point's rows depend on the velocities the point before
/// left, so one batch is a single chain of dependent operations; two independent chains keep
/// the CPU busier. Same arithmetic per lane as one batch after the other, and the batches of
/// one colour share no body: the same results bit for bit.
#[inline(always)]
fn relax_two<F: Lane>(
    m0: &ManifoldLanes<F>,
    m1: &ManifoldLanes<F>,
    points: &mut [PointLanes<F>],
    base: u32,
    states: &[Shared<BodyState>],
    inv_h: F,
    chord_time: F,
) {
    let (p0, p1) = two_batches(points, base, m0, m1);
    let mut pair0 = Pair::load_plain(m0, states);
    let mut pair1 = Pair::load_plain(m1, states);
    store_separations(m0, p0, states);
    store_separations(m1, p1, states);
    for k in 0..p0.len().max(p1.len()) {
        if let Some(p) = p0.get_mut(k) {
            relax_point(m0, &mut pair0, p, inv_h, chord_time);
        }
        if let Some(p) = p1.get_mut(k) {
            relax_point(m1, &mut pair1, p, inv_h, chord_time);
        }
    }
    pair0.store(m0, states);
    pair1.store(m1, states);
}

/// Stores each point's separation at the bodies' poses now ([`separation`]).
#[inline(always)]
fn store_separations<F: Lane>(
    m: &ManifoldLanes<F>,
    points: &mut [PointLanes<F>],
    states: &[Shared<BodyState>],
) {
    let (motion_a, motion_b) = (gather_motion(states, m.a), gather_motion(states, m.b));
    // Each body's turn as a matrix, once for all the batch's points: a matrix product per
    // lever arm costs half a quaternion rotation.
    let (turn_a, turn_b) = (
        rows_of_turn(&motion_a.rotation),
        rows_of_turn(&motion_b.rotation),
    );
    for p in points.iter_mut() {
        let pa = motion_a.position + turned(&turn_a, p.r_a);
        let pb = motion_b.position + turned(&turn_b, p.r_b);
        p.separation = p.base_separation + (pa - pb).dot(p.normal);
    }
}

/// The rows of the rotation matrix of the unit quaternions `q`, by lane.
#[inline(always)]
fn rows_of_turn<F: Lane>(q: &Q8<F>) -> [V3x8<F>; 3] {
    let (x, y, z, w) = (q.v.x, q.v.y, q.v.z, q.w);
    let two = F::splat(2.0);
    let (x2, y2, z2) = (x * two, y * two, z * two);
    let (xx, yy, zz) = (x * x2, y * y2, z * z2);
    let (xy, xz, yz) = (x * y2, x * z2, y * z2);
    let (wx, wy, wz) = (w * x2, w * y2, w * z2);
    [
        V3x8 {
            x: F::ONE - (yy + zz),
            y: xy - wz,
            z: xz + wy,
        },
        V3x8 {
            x: xy + wz,
            y: F::ONE - (xx + zz),
            z: yz - wx,
        },
        V3x8 {
            x: xz - wy,
            y: yz + wx,
            z: F::ONE - (xx + yy),
        },
    ]
}

/// `r` turned by the matrix of rows `rows`.
#[inline(always)]
fn turned<F: Lane>(rows: &[V3x8<F>; 3], r: V3x8<F>) -> V3x8<F> {
    V3x8 {
        x: rows[0].dot(r),
        y: rows[1].dot(r),
        z: rows[2].dot(r),
    }
}

/// The points of two batches `m0` and `m1` of one colour, in that order (`points` starts at
/// index `base` of [`Batches::points`]).
#[inline(always)]
fn two_batches<'a, F>(
    points: &'a mut [PointLanes<F>],
    base: u32,
    m0: &ManifoldLanes<F>,
    m1: &ManifoldLanes<F>,
) -> (&'a mut [PointLanes<F>], &'a mut [PointLanes<F>]) {
    let (f0, f1) = ((m0.first - base) as usize, (m1.first - base) as usize);
    let (c0, c1) = (m0.count as usize, m1.count as usize);
    debug_assert!(
        f0 + c0 <= f1,
        "a colour's batches keep their points in order"
    );
    let (head, tail) = points.split_at_mut(f1);
    (&mut head[f0..f0 + c0], &mut tail[..c1])
}

/// The parameters of one relax pass ([`relax`]).
#[derive(Clone, Copy, Debug)]
pub struct RelaxPass {
    /// 1/substep (1/s).
    pub inv_h: f32,
    /// [`BiasedPass::chord_time`].
    pub chord_time: f32,
    /// Sweeps over each manifold's normal rows before its friction (more than 1 with rigid
    /// contacts only).
    pub sweeps: u32,
    /// Each manifold's normal rows solved together (`relax_block`, after
    /// [`factor_blocks`]; [`super::SoftStepSettings::block_relax`]).
    pub block: bool,
}

/// One relax pass: rigid, without bias, so the velocity the soft constraints' bleed let
/// through is removed again once the positions moved (speculative contacts keep their gap
/// rule); [`RelaxPass::sweeps`] > 1 sweeps each manifold's normal rows that often before its
/// friction (rigid contacts); with [`RelaxPass::block`], each manifold's normal rows are
/// solved together (`relax_block`, after [`factor_blocks`]).
pub fn relax(batches: &mut Batches, states: &mut [BodyState], pass: RelaxPass) {
    let states = share(states);
    by_group(batches, |m, p, base| relax_range(m, p, base, states, pass));
}

wide_kernel! {
    /// [`relax`] over some batches of one group ([`Batches::groups`]).
    pub(crate) fn relax_range(pass: RelaxPass) = relax_impl;
}

/// Runs `f(manifolds, points, base)` on each group of batches ([`Batches::groups`]) in
/// order, with the group's points and the index of the first.
fn by_group(
    batches: &mut Batches,
    mut f: impl FnMut(&mut [ManifoldLanes], &mut [PointLanes], u32),
) {
    let Batches {
        manifolds,
        points,
        groups,
        ..
    } = batches;
    for g in groups.windows(2) {
        let manifolds = &mut manifolds[g[0] as usize..g[1] as usize];
        let (Some(first), Some(last)) = (manifolds.first(), manifolds.last()) else {
            continue;
        };
        let (base, end) = (first.first, last.first + last.count);
        f(manifolds, &mut points[base as usize..end as usize], base);
    }
}

/// Lanes of `p` that bounce in the restitution pass: e > 0, approached faster than
/// `threshold` (m/s) at the start of the step, and pushed during the step (Box2D's rule: a
/// speculative contact that never engaged does not bounce).
#[inline]
fn bounces(p: &PointLanes, threshold: F8) -> super::lanes::M8 {
    p.restitution.cmpgt(F8::ZERO)
        & p.relative_velocity.cmplt(-threshold)
        & p.max_normal_impulse.cmpgt(F8::ZERO)
}

/// [`bounce_marks`]: the body bounces this step off a body that cannot move.
pub const BOUNCES_ON_FIXED: u8 = 1;
/// [`bounce_marks`]: the body bounces this step off a body that can move (energy may pass
/// between them).
pub const BOUNCES_ON_MOVING: u8 = 2;

/// Marks in `marks` (one per body, cleared and sized to `bodies` here) which bodies take part
/// in a bounce of the restitution pass, and against what ([`BOUNCES_ON_FIXED`],
/// [`BOUNCES_ON_MOVING`]).
pub fn bounce_marks(batches: &Batches, threshold: f32, bodies: usize, marks: &mut Vec<u8>) {
    marks.clear();
    marks.resize(bodies, 0);
    let threshold = F8::splat(threshold);
    for m in &batches.manifolds {
        let range = m.first as usize..(m.first + m.count) as usize;
        let lanes = batches.points[range]
            .iter()
            .fold(0, |acc, p| acc | bounces(p, threshold).bitmask());
        for lane in (0..LANES).filter(|&l| lanes & (1 << l) != 0) {
            let (a, b) = (m.a[lane] as usize, m.b[lane] as usize);
            // (A body locked along every axis counts as not moving here.)
            let moves = |v: &V3x8| v.lane(lane).max_element() > 0.0;
            let (moves_a, moves_b) = (moves(&m.inv_mass_a), moves(&m.inv_mass_b));
            let mark = if moves_a && moves_b {
                BOUNCES_ON_MOVING
            } else {
                BOUNCES_ON_FIXED
            };
            for (body, moves) in [(a, moves_a), (b, moves_b)] {
                if moves && let Some(slot) = marks.get_mut(body) {
                    *slot |= mark;
                }
            }
        }
    }
}

/// Whether any contact bounces (see [`restitution`]); the pass is skipped otherwise.
pub fn any_bounces(batches: &Batches, threshold: f32) -> bool {
    let threshold = F8::splat(threshold);
    batches.points.iter().any(|p| bounces(p, threshold).any())
}

/// One sweep of the restitution pass, after the substeps: every contact that bounces gets
/// the normal velocity −e·v₀ (v₀ its approach velocity at the start of the step); every
/// other contact is solved rigidly without bias (normal only), as touching if it pushed
/// during the step and with the speculative gap rule of [`relax`] if it did not, except
/// contacts that were separating at the start of the step, which the pass leaves alone. Accumulated
/// impulses stay ≥ 0. Returns the largest normal velocity correction of the sweep (m/s),
/// for the caller's convergence test.
///
/// Box2D v3 solves only the bouncing contacts, once. That is exact for one contact, but where
/// an impact is passed through touching bodies (a Newton's cradle) it leaves the contacts
/// behind the bouncing one overlapping in velocity, and the next step resolves them
/// inelastically: the cradle loses 40% of its energy in one step. Sweeping every contact
/// until the velocities agree gives the simultaneous (LCP) answer with Newton's restitution
/// law, which conserves the energy of an elastic chain.
///
/// `response` is [`restitution_response`] of `batches`.
pub fn restitution(
    batches: &mut Batches,
    states: &mut [BodyState],
    response: &[Response],
    threshold: f32,
    inv_h: f32,
) -> f32 {
    let mut largest = F8::ZERO;
    let threshold = F8::splat(threshold);
    let inv_h = F8::splat(inv_h);
    let Batches {
        manifolds, points, ..
    } = batches;
    for_each_batch!(
        manifolds,
        points,
        0,
        share(states),
        |m, pair, points, states| {
            let (motion_a, motion_b) = (gather_motion(states, m.a), gather_motion(states, m.b));
            let first = m.first as usize;
            for (p, now) in points
                .iter_mut()
                .zip(&response[first..first + m.count as usize])
            {
                let vn = pair.relative_velocity(p).dot(p.normal);
                let s = separation(p, &motion_a, &motion_b);
                // A contact that pushed during the step is treated as touching even if a gap
                // opened: it is part of the impact and must not be allowed to close that gap
                // (which would turn the rest of an elastic impact into an inelastic one next
                // step). Only contacts that never engaged keep the speculative allowance.
                let free_gap = s.cmpgt(F8::ZERO) & p.max_normal_impulse.cmple(F8::ZERO);
                let separated = p.relative_velocity.cmpgt(F8::ZERO);
                let resting = F8::select(free_gap, -s * inv_h, F8::ZERO);
                let target = F8::select(
                    bounces(p, threshold),
                    -p.restitution * p.relative_velocity,
                    resting,
                );
                let delta = -now.mass * (vn - target);
                let total = (p.normal_impulse + delta).max(F8::ZERO);
                // A point that was separating at the start of the step is no part of the impact,
                // even if the body turned onto it within the step and it pushed: its elastic
                // answer is the reversed motion, which drives it back into the surface, where the
                // next step bounces it. Held at zero closing speed here instead, it forced the
                // impact's other points above their bounce: a flat box landing on one edge while
                // its other edge rose gained 60% of its energy in one step (benches/RESULTS.md,
                // "Restitution 1 never raises a bounce").
                let total = F8::select(separated, p.normal_impulse, total);
                let delta = total - p.normal_impulse;
                p.normal_impulse = total;
                let correction =
                    F8::select(now.mass.cmpgt(F8::ZERO), delta.abs() / now.mass, F8::ZERO);
                largest = largest.max(correction);
                let impulse = p.normal * delta;
                pair.a.linear += pair.inv_mass_a.times(impulse);
                pair.a.angular += now.ang_a * delta;
                pair.b.linear -= pair.inv_mass_b.times(impulse);
                pair.b.angular -= now.ang_b * delta;
            }
        }
    );
    largest.max_element()
}

/// A contact point's response to a normal impulse after the substeps, for the restitution
/// pass: the angular response I⁻¹·(r × n) through each body's world inverse inertia turned with
/// the body since the start of the step (Δq·I⁻¹·Δqᵀ), and the normal effective mass it gives.
/// The lever arms stay the step-start ones, as in every other pass (for a ball the contact
/// point stays under the centre however it rolls).
///
/// Why: the pass runs after the substeps, when a fast spinner may have turned a third of a
/// radian. With the step-start inertia its impulses changed the spin through a tensor the body
/// no longer has, so a single elastic contact on a spinning plank changed the plank's kinetic
/// energy (measured with its inertia now) by several per cent (benches/RESULTS.md,
/// "Restitution 1 never raises a bounce"). Any lever arm with the inertia the energy is
/// measured with makes an elastic single contact exact.
#[derive(Clone, Copy, Debug, Default)]
pub struct Response {
    ang_a: V3x8<F8>,
    ang_b: V3x8<F8>,
    /// 1/(n·K·n), zero where K is not positive.
    mass: F8,
}

/// Fills `out` with the [`Response`] of every point of `batches`, with `inv_inertia_now` each
/// body's world inverse inertia at the end of the substeps (zero for bodies that do not turn).
pub fn restitution_response(batches: &Batches, inv_inertia_now: &[Mat3], out: &mut Vec<Response>) {
    out.clear();
    out.resize(batches.points.len(), Response::default());
    let inertia = |body: u32| {
        inv_inertia_now
            .get(body as usize)
            .copied()
            .unwrap_or(Mat3::ZERO)
    };
    for m in &batches.manifolds {
        let range = m.first as usize..(m.first + m.count) as usize;
        for (p, r) in batches.points[range.clone()].iter().zip(&mut out[range]) {
            let mass: [f32; LANES] = std::array::from_fn(|lane| {
                let n = p.normal.lane(lane);
                let rn_a = p.r_a.lane(lane).cross(n);
                let rn_b = p.r_b.lane(lane).cross(n);
                let ang_a = inertia(m.a[lane]) * rn_a;
                let ang_b = inertia(m.b[lane]) * rn_b;
                r.ang_a.set_lane(lane, ang_a);
                r.ang_b.set_lane(lane, ang_b);
                let (ma, mb) = (m.inv_mass_a.lane(lane), m.inv_mass_b.lane(lane));
                let linear = if ma.x == ma.y && ma.y == ma.z && mb.x == mb.y && mb.y == mb.z {
                    ma.x + mb.x
                } else {
                    n.dot((ma + mb) * n)
                };
                let k = linear + rn_a.dot(ang_a) + rn_b.dot(ang_b);
                if k > 0.0 && k.is_finite() {
                    1.0 / k
                } else {
                    0.0
                }
            });
            r.mass = F8::from_array(mass);
        }
    }
}

/// A manifold's state at the end of the step, as [`results`] gives it with each of its points:
/// the mean over its points of their overlap (−separation, m) and of their preload
/// ([`crate::Contact::preload`], m), its total normal impulse per substep (N·s), and the
/// fastest normal relative speed of its points at the start of the step (m/s).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ManifoldEnd {
    /// Mean overlap of the manifold's points (m; negative for a mean gap).
    pub penetration: f32,
    /// Mean preload of the manifold's points (m).
    pub preload: f32,
    /// Sum of the points' accumulated normal impulses (N·s, per substep).
    pub normal_impulse: f32,
    /// Largest |normal relative velocity| of its points at the start of the step (m/s).
    pub speed: f32,
    /// Mean static compression of its points' springs under their accumulated impulses
    /// (m): s_i·λ / (m·s_m·β), where the bias balances the bleed.
    pub compression: f32,
}

/// Calls `f(source, impulse, separation, manifold)` for every prepared contact point: its index
/// in the contacts given to the step, its accumulated impulse in contact space (per substep),
/// its separation at the end of the step (m) and its manifold's [`ManifoldEnd`]. With
/// `stored`, every point's [`PointLanes::separation`] already holds its separation at the
/// end of the step (a relax pass ran last: nothing moves a body after it) and is taken as
/// it is; else it is computed from the bodies' motion.
pub fn results(
    batches: &Batches,
    states: &mut [BodyState],
    stored: bool,
    f: impl FnMut(u32, jostle_math::Vec3, f32, ManifoldEnd),
) {
    let all = 0..batches.manifolds.len();
    results_range(batches, share(states), stored, all, f);
}

/// [`results`] for the batches `range` of `batches.manifolds`, with the body states shared
/// (only read), so that several threads may each take a range.
pub fn results_range(
    batches: &Batches,
    states: &[Shared<BodyState>],
    stored: bool,
    range: std::ops::Range<usize>,
    mut f: impl FnMut(u32, jostle_math::Vec3, f32, ManifoldEnd),
) {
    let mut separations = [F8::ZERO; MAX_POINTS];
    for m in batches.manifolds.get(range).unwrap_or_default() {
        let motion = (!stored).then(|| (gather_motion(states, m.a), gather_motion(states, m.b)));
        let range = m.first as usize..(m.first + m.count) as usize;
        let mut ends = [ManifoldEnd::default(); LANES];
        let mut counts = [0u32; LANES];
        for (k, i) in range.clone().enumerate() {
            let p = &batches.points[i];
            separations[k] = match &motion {
                Some((motion_a, motion_b)) => separation(p, motion_a, motion_b),
                None => p.separation,
            };
            for (lane, &source) in batches.sources[i].iter().enumerate() {
                if source != super::batch::NO_SOURCE {
                    let end = &mut ends[lane];
                    end.penetration -= separations[k][lane];
                    end.preload += p.preload[lane];
                    end.normal_impulse += p.normal_impulse[lane];
                    end.speed = end.speed.max(p.relative_velocity[lane].abs());
                    let stiffness = p.normal_mass[lane] * p.mass_scale[lane] * p.bias_rate[lane];
                    if stiffness > 0.0 {
                        end.compression +=
                            p.impulse_scale[lane] * p.normal_impulse[lane] / stiffness;
                    }
                    counts[lane] += 1;
                }
            }
        }
        for (end, &n) in ends.iter_mut().zip(&counts) {
            if n > 0 {
                end.penetration /= n as f32;
                end.preload /= n as f32;
                end.compression /= n as f32;
            }
        }
        for (k, i) in range.enumerate() {
            let p = &batches.points[i];
            for (lane, &source) in batches.sources[i].iter().enumerate() {
                if source != super::batch::NO_SOURCE {
                    let impulse = jostle_math::Vec3::new(
                        p.normal_impulse[lane],
                        p.tangent_impulse[0][lane],
                        p.tangent_impulse[1][lane],
                    );
                    f(source, impulse, separations[k][lane], ends[lane]);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soft_step::{PrepareParams, Softness};
    use crate::synthetic::{self, DT, GRAVITY};

    /// The exact projection in f64: bisection on ν of |(K + νI)⁻¹·K·t| = r.
    fn exact_projection(k: [f64; 3], t: [f64; 2], r: f64) -> [f64; 2] {
        let [k11, k12, k22] = k;
        let rhs = [k11 * t[0] + k12 * t[1], k12 * t[0] + k22 * t[1]];
        let at = |nu: f64| {
            let (m11, m22) = (k11 + nu, k22 + nu);
            let inv_det = 1.0 / (m11 * m22 - k12 * k12);
            [
                (m22 * rhs[0] - k12 * rhs[1]) * inv_det,
                (m11 * rhs[1] - k12 * rhs[0]) * inv_det,
            ]
        };
        let (mut lo, mut hi) = (0.0, 1.0);
        while at(hi)[0].hypot(at(hi)[1]) > r {
            hi *= 2.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if at(mid)[0].hypot(at(mid)[1]) > r {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        at(0.5 * (lo + hi))
    }

    #[test]
    fn disk_projection_matches_the_exact_one() {
        // A small deterministic generator: K with eigenvalues 1 and κ (scaled, rotated), a
        // target 1.001 to 100 times the radius in any direction.
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for (max_kappa, bound) in [(5.0, 1e-4), (30.0, 3e-2)] {
            let mut worst = 0.0f64;
            for _ in 0..2000 {
                let kappa = 1.0 + uniform() * (max_kappa - 1.0);
                let scale = 10f64.powf(-3.0 + 4.0 * uniform());
                let angle = std::f64::consts::PI * uniform();
                let (c, s) = (angle.cos(), angle.sin());
                let k = [
                    scale * (c * c + kappa * s * s),
                    scale * (c * s * (1.0 - kappa)),
                    scale * (s * s + kappa * c * c),
                ];
                let det = k[0] * k[2] - k[1] * k[1];
                let inv_k = [k[2] / det, -k[1] / det, k[0] / det];
                let r = 0.5 + uniform();
                let heading = 2.0 * std::f64::consts::PI * uniform();
                let len = r * 10f64.powf(0.0005 + 2.0 * uniform());
                let t = [len * heading.cos(), len * heading.sin()];
                let exact = exact_projection(k, t, r);
                let lanes = |v: f64| F8::splat(v as f32);
                let got = project_to_disk(
                    inv_k.map(lanes),
                    t.map(lanes),
                    lanes(r),
                    F8::splat(1.0).cmpgt(F8::ZERO),
                );
                let (g0, g1) = (f64::from(got[0][0]), f64::from(got[1][0]));
                // On the circle always; next to the exact point within the bound.
                assert!((g0.hypot(g1) - r).abs() <= 1e-5 * r, "off the circle");
                worst = worst.max((g0 - exact[0]).hypot(g1 - exact[1]) / r);
            }
            assert!(
                worst <= bound,
                "κ ≤ {max_kappa}: worst {worst:e} > {bound:e}"
            );
        }
    }

    /// A random pile packed for the kernels, and its body states after a substep of gravity.
    fn pile() -> (Batches, Vec<BodyState>) {
        let scene = synthetic::random_pile(2000, 7);
        let h = DT / 4.0;
        let s = Softness::new(30.0, 10.0, h);
        let params = PrepareParams {
            static_softness: Softness::new(60.0, 10.0, h),
            dynamic_softness: s,
            warm_scale: 0.25,
            preload_ramp: 2000.0,
            preload_bound: 1600.0 * 9.81 * h,
            step: 0.0,
            down: jostle_math::Vec3::ZERO,
        };
        let mut batches = Batches::default();
        // Preloads on every contact, so the kernels' preload path is exercised too.
        let contacts: Vec<_> = (scene.contacts.iter().enumerate())
            .map(|(i, c)| crate::Contact {
                preload: 0.001 * (i % 3) as f32,
                ..*c
            })
            .collect();
        batches.pack(&contacts, &scene.bodies, 0.02, &params);
        let mut states: Vec<BodyState> = scene.bodies.iter().map(BodyState::from_body).collect();
        states[0] = BodyState::STATIC;
        for s in states.iter_mut().skip(1) {
            s.linear_velocity += GRAVITY * h;
            s.delta_position = s.linear_velocity * h;
        }
        (batches, states)
    }

    fn bits(states: &[BodyState], batches: &Batches) -> Vec<u32> {
        let mut out = Vec::new();
        for s in states {
            for v in [s.linear_velocity, s.angular_velocity] {
                out.extend(v.to_array().map(f32::to_bits));
            }
        }
        for p in &batches.points {
            for l in 0..LANES {
                out.push(p.normal_impulse[l].to_bits());
                out.push(p.tangent_impulse[0][l].to_bits());
                out.push(p.tangent_impulse[1][l].to_bits());
            }
        }
        out
    }

    /// The public kernels take the 256-bit path on CPUs with AVX (compiled for AVX-512VL where
    /// the CPU has it); their results must equal the 128-bit kernels' bit for bit. Each level
    /// the CPU supports is run: the detected one, at most AVX, and the 128-bit dispatch.
    #[test]
    fn the_wide_kernels_match_the_128_bit_ones_bit_for_bit() {
        const SOFT: BiasedPass = BiasedPass {
            inv_h: 4.0 / DT,
            max_push_out: 3.0,
            slop: 0.005,
            resting_speed: 1.0,
            gravity_speed: 9.81 / 240.0,
            friction: false,
            rigid: false,
            sweeps: 1,
            impact_speed: 9.81 / 60.0,
            rate: 0.2 * 4.0 / DT,
            stored_separation: false,
            after_warm_start: false,
            chord_time: 1.5 * DT / 4.0,
        };
        // Rigid contacts: other kernels, several sweeps, friction in the biased pass.
        const RIGID: BiasedPass = BiasedPass {
            slop: 0.001,
            friction: true,
            rigid: true,
            sweeps: 3,
            ..SOFT
        };
        // Soft contacts whose approaching manifolds sweep their normal rows (every manifold
        // with a point approaching at all, but the lanes marked as solved directly).
        const IMPACT: BiasedPass = BiasedPass {
            sweeps: 3,
            impact_speed: 0.0,
            ..SOFT
        };
        for (pass, block) in [(SOFT, false), (RIGID, false), (SOFT, true), (IMPACT, true)] {
            kernels_match(pass, block);
        }
    }

    fn kernels_match(pass: BiasedPass, block: bool) {
        let (mut batches, states) = pile();
        if block {
            factor_blocks(&mut batches);
        }
        // Every other lane as if a direct island solved it: the impact sweeps leave it out.
        for m in &mut batches.manifolds {
            m.direct = 0b0101_0101;
        }
        assert!(batches.contacts > 1000);
        let inv_h = 4.0 / DT;
        let relax_pass = RelaxPass {
            inv_h,
            chord_time: pass.chord_time,
            sweeps: pass.sweeps,
            block,
        };

        let (mut narrow_batches, mut narrow_states) = (batches.clone(), states.clone());
        let Batches {
            manifolds, points, ..
        } = &mut narrow_batches;
        let mut narrow_pseudo: Vec<PseudoRow> = vec![[0.0; 8]; narrow_states.len()];
        warm_start_impl::<F8>(manifolds, points, 0, share(&mut narrow_states));
        solve_impl::<F8>(
            manifolds,
            points,
            0,
            share(&mut narrow_states),
            share(&mut narrow_pseudo),
            pass,
        );
        let narrow_shared = share(&mut narrow_states);
        by_group(&mut narrow_batches, |m, p, base| {
            relax_impl::<F8>(m, p, base, narrow_shared, relax_pass)
        });
        // The pile starts overlapping, so the split push-out did work too.
        assert!(narrow_pseudo.iter().flatten().any(|&x| x != 0.0));
        let mut narrow = bits(&narrow_states, &narrow_batches);
        narrow.extend(narrow_pseudo.iter().flatten().map(|x| x.to_bits()));
        // The passes did real work.
        assert!(
            narrow_batches
                .points
                .iter()
                .any(|p| p.normal_impulse.max_element() > 0.0)
        );

        for cap in [0, 2, 1] {
            #[cfg(target_arch = "x86_64")]
            super::super::lanes_avx::CAP.store(cap, std::sync::atomic::Ordering::Relaxed);
            let (mut batches, mut states) = (batches.clone(), states.clone());
            let mut pseudo = vec![[0.0; 8]; states.len()];
            warm_start(&mut batches, &mut states);
            solve(&mut batches, &mut states, &mut pseudo, pass);
            relax(&mut batches, &mut states, relax_pass);
            let mut wide = bits(&states, &batches);
            wide.extend(pseudo.iter().flatten().map(|x| x.to_bits()));
            assert_eq!(wide.len(), narrow.len());
            let differing = wide.iter().zip(&narrow).filter(|(a, b)| a != b).count();
            assert_eq!(
                differing,
                0,
                "cap {cap}: {differing} of {} values differ",
                wide.len()
            );
        }
        #[cfg(target_arch = "x86_64")]
        super::super::lanes_avx::CAP.store(0, std::sync::atomic::Ordering::Relaxed);
    }
}
