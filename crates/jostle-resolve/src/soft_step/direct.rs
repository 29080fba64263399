//! Direct solve of the contact rows of islands Gauss-Seidel cannot converge on within a step:
//! a heavy body resting on light ones, and chains of bodies (a column of boxes).
//!
//! Gauss-Seidel converges on a light body squeezed between a heavy one and the ground at a
//! rate of about 1 − m/M per sweep: the heavy body's weight must reach the ground through
//! rows whose effective mass is the light body's, and each sweep passes on only about m/M of
//! what is missing (a 1:1,000 pair needs thousands of sweeps where a step has sixteen); the
//! friction rows that hold the heavy body sideways are conditioned the same way. The soft
//! springs add a second limit: a spring sized by the light body's effective mass
//! (k = m·ω²) settles at a compression of M·g/(m·ω²) under the heavy load, and load
//! compensation may take only part of it back before the load rides on the spring
//! under-damped ([`super::PRELOAD_MIN_DAMPING`]). Measured on the stability family (the
//! `jostle` crate's benches/RESULTS.md, "Heavy on light: a direct solve"): springs sized by
//! their load with 300 Gauss-Seidel sweeps per pass hold a light box under 1,000 times its
//! mass with 0.1 mm of sink but not a column of five such boxes, and either change alone
//! lets both fall.
//!
//! A chain of bodies of similar mass (each touching at most two others: a column) has the
//! same two limits in another form. The load of the boxes above reaches the ground through
//! every joint below, and the column's slowest patterns (leaning and bending as a whole) are
//! passed on by one joint per sweep: perturbed columns of 40 and 60 boxes leaned and swayed by
//! 3–36 cm with a period of about 10 s ("What the perturbed tall columns' drift is"). Solved
//! exactly with springs sized by their load, the same columns stand within 6 mm
//! (benches/RESULTS.md, "Chains of bodies solved directly").
//!
//! So for an island of at most [`super::SoftStepSettings::direct_rows`] contact points that
//! holds a contact between two movable bodies whose masses differ by
//! [`super::SoftStepSettings::direct_mass_ratio`] or more, and for a chain whose load path is
//! at least a step's sweeps ([`Limits::min_chain`]), or half of them for a chain whose bodies'
//! sizes add up to [`TALL_CHAIN`] or more, the longest chains first while they hold at most
//! [`CHAIN_ROWS`] times as many points together:
//! 1. [`DirectIslands::stiffen`], once per step: each manifold's springs are sized by the
//!    mass its load stands for, Λ/(|g|·h) for the per-substep impulse Λ its points start the
//!    step with, where that exceeds their effective mass (the same ω and ζ, so a loaded
//!    manifold settles at about g/ω² whatever its load);
//! 2. after the first substep's warm start (the last step's impulses on this step's
//!    contacts, whose error a light body between heavy ones feels as a velocity M/m times
//!    larger), and after each biased and each relax pass, [`DirectIslands::correct`] solves
//!    the island's rows exactly as the pass states them ([`super::solve::row_residuals`]):
//!    (J·M⁻¹·Jᵀ + C)·x = r, with C the springs' compliance, over the normal rows that push
//!    or want to and their friction rows, as sticking (in the biased pass too, where the
//!    plain soft step solves no friction: friction the last relax pass left on a light body
//!    is balanced by the normal load's distribution, and a biased solve that moves the load
//!    without it spun a light box at 80 rad/s; each friction row with at least a small
//!    compliance of its own, `FRICTION_REGULARISATION`, as a face's friction rows are more
//!    than the motions they span). An active set: normal rows whose total would
//!    pull are fixed at no impulse, friction that would leave its cone is fixed on it, and
//!    the rest is solved again. J·M⁻¹·Jᵀ is built in f64 from the rows and the bodies'
//!    inverse inertia (built in f32 it lost the heavy body of a 1:10⁶ pair in rounding and
//!    was not positive semi-definite: `Response::coupling`), and a solution is summed per body in
//!    f64 and applied through the same inverse inertia (`Solver::apply`). The system is
//!    factorised by Cholesky in f64 over its profile (rows that depend on others get no
//!    impulse of their own; `profile_factor`), with the rows ordered outward from one end
//!    of the island so that a chain's profile is a band and its cost grows linearly with its
//!    length; a factorisation is kept for the step and serves later solves that leave a few
//!    of its rows out (`Factor`). The result goes to the bodies and to the accumulated
//!    impulses; in the relax pass only if it takes kinetic energy out (friction fixed on its
//!    cone is no projection and can put energy in). In the relax pass of a chain, the points
//!    of a face are rigid but for the pattern that moves nothing (`FaceModes`); in an island
//!    with a mass ratio every row keeps its spring's compliance there too, which the light
//!    bodies' nearly dependent rows need (rigid, 3 of the 72 heavy cases fell). The pseudo
//!    velocities of the push-out stay with Gauss-Seidel (solving them directly too measured
//!    worse, same section).
//!
//! Other islands of bodies of similar mass keep the plain soft step: there Gauss-Seidel
//! converges, and their profile (a pyramid's, a wall's) is too wide to factorise every step.
//! The cost: 0.046 ms a step for a heavy-on-light pair, 0.09 ms for a light column of five
//! under a box ten times heavier (0.01 ms each without); a column of 20 unit boxes 0.3 ms,
//! of 60 about 1 ms (Gauss-Seidel alone: 0.03 and 0.05 ms).

use super::batch::{Batches, LANES, MAX_POINTS, ManifoldLanes, NO_SOURCE, PointLanes};
use super::body_state::BodyState;
use super::shared::share;
use super::solve::{RowPass, RowState, row_residuals};
use crate::STATIC_BODY;
use crate::SolverBody;
use crate::union_find::UnionFind;
use jostle_math::{Mat3, Vec3};

/// A pivot below this fraction of its row's diagonal marks the row as depending on the rows
/// before it ([`cholesky_factor`]). Rows built from f32 data are dependent to about 1e-14 of
/// their diagonal; a light body under a 10,000 times heavier one leaves about 1e-5.
const DEPENDENT: f64 = 1e-9;

/// Least compliance of a friction row in the direct solve, as a fraction of the smaller of
/// its two bodies' parts of the row's diagonal of J·M⁻¹·Jᵀ (the heavier body's): each solve
/// brings a sticking row to at least 1/(1 + this) of its target, and what is left goes to
/// the next pass (sixteen passes a step).
///
/// Why: a face's four points give eight friction rows that span three motions, and the
/// springs a heavy load stiffens gave them a compliance of about 2·10⁻⁶ of their diagonal, so
/// whatever part of the targets no rigid motion meets was met with impulses half a million
/// times that part, which the active set's clamps then turned into net pushes. Measured on a
/// light column of five under a box 10,000 times heavier, started perturbed (the stability
/// family's heavy set, seed 3): in the step where it fell, one biased pass's solve answered
/// targets of 0.1–2.4 m/s with 5·10⁶–2·10⁷ N·s (the heavy box weighs 2·10⁵ N·s a substep);
/// the light boxes left it at 1,000 m/s and moved 2 m within the substep.
///
/// Why the heavier body's part: a floor sized by the whole diagonal (the light body's part)
/// leaves the heavy body's own friction converging at 1/(1 + this·M/m) per solve, and a 0.1 m
/// box under one 10⁶ times heavier was pushed through the floor (`tests/stress.rs`). Cases
/// meeting the stability criterion, the heavy set's 72 and 216 more from seeds no other set
/// uses, measured with contact frames held to 2 mm (`frame_tolerance` then): no floor 68 and
/// 185; this at 0.03 72 and 213 (one 1:10,000 column falls), 0.1 72 and 213 (none falls;
/// three 10 m columns at μ 0.3 drift 11–25 mm), 0.3 72 and 212 (three fall)
/// (benches/RESULTS.md, "Friction rows regularised in the direct solve").
const FRICTION_REGULARISATION: f32 = 0.1;

/// Rounds of fixing rows that would pull or slide before the island is left to Gauss-Seidel
/// alone.
const ACTIVE_SET_ROUNDS: usize = 8;

/// How many times [`super::SoftStepSettings::direct_rows`] contact points the chains of bodies
/// (columns) solved directly in one step may hold together: a chain's cost grows linearly with
/// its length (`profile_factor`), where a general island's grows with the cube of its size,
/// but it is ten to twenty times what Gauss-Seidel costs the same chain, so the budget bounds
/// what a scene of many columns pays.
pub const CHAIN_ROWS: u32 = 16;

/// Length (m) of a chain, the sum of its bodies' sizes (each the side of the cube with the
/// body's mass and inverse inertia's trace), from which it is solved directly from half the
/// load path ([`Limits::min_chain`] / 2): Gauss-Seidel leaves a perturbed column's joints
/// tilted by about as much whatever its boxes' size, so its top sways in proportion to its
/// height. A sum of sizes, not the span of the bodies' centres: a column's span moves with its
/// sink, and a chain whose span sat at the bound went between the two solves, which kicks it
/// (13 unit boxes with a bound of 12 m: 20 of 24 perturbed starts swayed more than 1 cm, up to
/// 38 mm, where solved directly throughout none does). Measured on perturbed columns
/// (seeds 21–28, μ 0.3, 0.6 and 0.9, 20 s) left to Gauss-Seidel, starts that sway more than
/// 1 cm of 24: 12 boxes of 1 m (12 m) none, 13 of 1 m 3, 15 of 1 m 2, 15 of 1.26 m 6, 13 of
/// 1.5 m 3, 10 of 2 m (20 m) none, 10 of 4, 6 and 10 m 7, 4 and 10, 12 of 10 m 23
/// (benches/RESULTS.md, "Tall columns of large boxes solved directly"). Between whole
/// metres, so that no column of unit boxes sits on it (the world inverse inertia's trace
/// moves in its last bits as a box turns).
pub const TALL_CHAIN: f32 = 12.5;

/// A body's size (m) for [`TALL_CHAIN`]: the side of the cube with its mass and the trace of
/// its inverse inertia, √(18·m⁻¹ / tr I⁻¹) (a cube of side s has I⁻¹ = 6/(m·s²) about
/// every axis; a rotation keeps the trace of the world inverse inertia); 0 for a body that
/// cannot turn.
fn body_size(body: &SolverBody) -> f32 {
    let i = &body.inv_inertia;
    let trace = i.x_axis.x + i.y_axis.y + i.z_axis.z;
    if trace > 0.0 {
        (18.0 * body.inv_mass / trace).sqrt()
    } else {
        0.0
    }
}

/// Relative slack of the friction cone in [`Solver::fix_sliding_points`]: a point is sliding
/// when its sticking friction exceeds μ times its normal impulse by more than this.
const CONE_TOLERANCE: f64 = 1e-6;

/// One normal row of a direct island: where it lives in the batches, and its Jacobian.
#[derive(Clone, Copy, Debug)]
struct Row {
    /// The direct island's number, then the row's place in the batches: the sort key.
    island: u32,
    order: u32,
    /// Which impulse of the point the row is: [`NORMAL`], [`TANGENT_1`] or [`TANGENT_2`].
    kind: u8,
    batch: u32,
    point: u32,
    lane: u8,
    a: u32,
    b: u32,
    /// 1/m of A and B along each world axis (zero along a locked axis).
    inv_mass_a: Vec3,
    inv_mass_b: Vec3,
    /// The row's direction d: the normal or a tangent.
    normal: Vec3,
    /// r_A × d and r_B × d.
    rn_a: Vec3,
    rn_b: Vec3,
    /// A friction row's least compliance (`Response::friction_floor`); set once the
    /// inverse inertia is known.
    floor: f64,
}

/// A row's Jacobian and M⁻¹·Jᵀ on each of its two bodies, in f64, so that the couplings
/// (`Response::coupling`) are dot products, with the inverse inertia applied once per row
/// instead of once per pair of rows (building a column's couplings that way was a fifth of
/// its direct solve).
#[derive(Clone, Copy, Debug)]
struct Response {
    sides: [Side; 2],
}

/// One body's part of a [`Response`].
#[derive(Clone, Copy, Debug)]
struct Side {
    /// The body ([`STATIC_BODY`] for none).
    body: u32,
    /// The row's direction d and r × d, signed for this side (+ on A, − on B).
    linear: [f64; 3],
    angular: [f64; 3],
    /// M⁻¹ times them: 1/m along each axis, and the inverse inertia (its symmetric part).
    inv_linear: [f64; 3],
    inv_angular: [f64; 3],
}

impl Response {
    fn of(row: &Row, inv_inertia: &impl Fn(u32) -> Mat3) -> Self {
        let side = |body: u32, sign: f64, rn: Vec3, inv_mass: Vec3| {
            if body == STATIC_BODY {
                return Side {
                    body,
                    linear: [0.0; 3],
                    angular: [0.0; 3],
                    inv_linear: [0.0; 3],
                    inv_angular: [0.0; 3],
                };
            }
            let (n, rn, w) = (wide(row.normal), wide(rn), wide(inv_mass));
            let linear = n.map(|x| sign * x);
            let angular = rn.map(|x| sign * x);
            Side {
                body,
                linear,
                angular,
                inv_linear: std::array::from_fn(|i| w[i] * linear[i]),
                inv_angular: symmetric_times(inv_inertia(body), angular),
            }
        };
        Self {
            sides: [
                side(row.a, 1.0, row.rn_a, row.inv_mass_a),
                side(row.b, -1.0, row.rn_b, row.inv_mass_b),
            ],
        }
    }

    /// (J·M⁻¹·Jᵀ)ᵢⱼ: the change of this row's velocity per unit impulse on `other`, in f64
    /// from each shared body's inverse mass and world inverse inertia, so that the island's
    /// matrix is a Gram matrix, positive semi-definite to f64's rounding (only its lower
    /// triangle is built). Built in f32 from the rows' angular responses I⁻¹·(r × n), whose
    /// rounding makes it neither, a 1 kg box under a 10⁶ kg one gave the matrix an eigenvalue
    /// of −1.0·10⁻⁷ beside the heavy box's own, about 10⁻⁶: its contributions are the size of
    /// the f32 rounding of the light box's.
    fn coupling(&self, other: &Response) -> f64 {
        let dot = |u: &[f64; 3], v: &[f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let mut sum = 0.0;
        for mine in &self.sides {
            if mine.body == STATIC_BODY {
                continue;
            }
            for theirs in &other.sides {
                if theirs.body == mine.body {
                    sum += dot(&mine.linear, &theirs.inv_linear)
                        + dot(&mine.angular, &theirs.inv_angular);
                }
            }
        }
        sum
    }

    /// A friction row's least compliance: [`FRICTION_REGULARISATION`] times the smaller of
    /// its two bodies' parts of its diagonal of J·M⁻¹·Jᵀ (a fixed body has none), the heavier
    /// body's where the masses differ, so that its motion still converges at that rate.
    fn friction_floor(&self) -> f64 {
        let dot = |u: &[f64; 3], v: &[f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let smaller = self
            .sides
            .iter()
            .filter(|side| side.body != STATIC_BODY)
            .map(|side| dot(&side.linear, &side.inv_linear) + dot(&side.angular, &side.inv_angular))
            .fold(f64::INFINITY, f64::min);
        if smaller.is_finite() {
            f64::from(FRICTION_REGULARISATION) * smaller
        } else {
            0.0
        }
    }
}

/// Which islands [`DirectIslands::build`] solves directly.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Most contact points of an island with a mass ratio
    /// ([`super::SoftStepSettings::direct_rows`]); a chain may have [`CHAIN_ROWS`] times as
    /// many; 0 solves nothing directly.
    pub max_rows: u32,
    /// Mass ratio between two movable bodies in contact from which their island is solved
    /// directly ([`super::SoftStepSettings::direct_mass_ratio`]).
    pub mass_ratio: f32,
    /// Shortest load path of a chain solved directly, in bodies (its bodies that rest on
    /// nothing immovable, plus one): a chain whose load Gauss-Seidel can pass down within a
    /// step's sweeps (one joint per sweep) is left to it. At the defaults (8 substeps of one
    /// biased and one relax sweep) 16: Gauss-Seidel holds perturbed columns of up to 14 boxes
    /// of 0.1 and 1 m within 1 cm, where at 16 they sway 1.0–1.6 cm. Taller columns of larger
    /// boxes sway more under it (their tops in proportion to their height), so a chain at
    /// least [`TALL_CHAIN`] long is solved directly from half this load path; piles and
    /// lattices of columns of up to 12 unit boxes stay at Gauss-Seidel's cost
    /// (benches/RESULTS.md, "Chains solved directly within a budget" and "Tall columns of
    /// large boxes solved directly").
    pub min_chain: u32,
}

/// A point's normal row.
const NORMAL: u8 = 0;
/// A point's friction row along its first tangent.
const TANGENT_1: u8 = 1;
/// A point's friction row along its second tangent.
const TANGENT_2: u8 = 2;

/// The islands of one step that are solved directly, and the scratch to solve them.
#[derive(Clone, Debug, Default)]
pub struct DirectIslands {
    /// The rows of every direct island, island by island.
    rows: Vec<Row>,
    /// Each direct island's range in `rows`.
    islands: Vec<(u32, u32)>,
    /// Each island's (J·M⁻¹·Jᵀ)ᵢⱼ over its rows by profile, one island after another (the
    /// rows do not change within a step): row i holds columns `first[i]` to i, from `start[i]`
    /// on in its island's range ([`DirectIslands::coupling_ranges`]); every entry left of
    /// `first[i]` is zero (the rows share no movable body).
    couplings: Vec<f64>,
    /// Each row's first column in the profile, within its island.
    first: Vec<u32>,
    /// Where each row's profile starts in its island's couplings.
    start: Vec<usize>,
    /// Each island's range in `couplings`.
    coupling_ranges: Vec<(usize, usize)>,
    /// The manifolds whose normal rows span fewer motions than they are rows (a face's
    /// points), island by island: where the relax pass gives them compliance
    /// ([`FaceModes`]).
    faces: Vec<FaceModes>,
    /// Each island's range in `faces`: empty for an island whose bodies' masses differ
    /// widely, whose relax pass keeps every row's compliance.
    face_ranges: Vec<(usize, usize)>,
    /// Whether each island holds bodies whose masses differ widely.
    island_mixed: Vec<bool>,
    /// Each island's normal rows (within the island) by batch, then point, then lane; and
    /// each island's range in it.
    by_point: Vec<u32>,
    by_point_ranges: Vec<(usize, usize)>,
    /// Each island's last factorisation for each pass kind (biased, relax), reused while its
    /// free rows stay the same: within a step the couplings and the compliances do not change.
    factors: Vec<[Factor; 2]>,
    // Scratch reused from step to step.
    sets: UnionFind,
    row_count: Vec<u32>,
    mixed: Vec<bool>,
    island_of: Vec<u32>,
    degree: Vec<u32>,
    supported: Vec<bool>,
    chain: Vec<bool>,
    unsupported: Vec<u32>,
    /// Per root: the sum of its bodies' sizes ([`body_size`]).
    length: Vec<f32>,
    /// The chains that may be solved directly, as (load path less one, root).
    chain_roots: Vec<(u32, u32)>,
    seen: Vec<bool>,
    first_row: Vec<u32>,
    manifold_runs: Vec<(u32, u32, u32, u32)>,
    edges: Vec<(u32, u32)>,
    queue: Vec<u32>,
    rank: Vec<u32>,
    scratch_rows: Vec<Row>,
    /// Each row's Jacobian and M⁻¹·Jᵀ, in f64 (`Response`), as `rows` are.
    responses: Vec<Response>,
    /// The world inverse inertia of each body with rows in an island (by body index; zero
    /// elsewhere), as the rows' angular responses were prepared.
    inv_inertia: Vec<Mat3>,
    solver: Solver,
}

/// A Cholesky factor of an island's system over the free rows `index` (empty: none yet), by
/// profile as the couplings are (`profile_factor`).
///
/// A later solve whose free rows are these but for a few ([`MAX_HELD`]) reuses it: the rows
/// left out (`excluded`, their places in `index`) are held at no impulse change by the
/// capacitance method, x = y + G·Eᵀ·μ with y = G·b, G = (J·M⁻¹·Jᵀ + C)⁻¹ over `index` and
/// (E·G·Eᵀ)·μ = −E·y, which solves exactly the system over the remaining rows: one
/// substitution per row left out (kept while the same rows are left out) instead of a
/// factorisation per change of the free rows. A column's friction and its lightly loaded
/// points change their roles a few at a time, and factorising again for each change was
/// two thirds of a column's direct solve.
#[derive(Clone, Debug, Default)]
struct Factor {
    index: Vec<usize>,
    first: Vec<u32>,
    start: Vec<usize>,
    matrix: Vec<f64>,
    /// The places in `index` of the rows the present free rows leave out.
    excluded: Vec<usize>,
    /// G·eⱼ for each place j in `excluded`, one after another.
    columns: Vec<f64>,
    /// E·G·Eᵀ, factorised (a full profile).
    capacitance: Vec<f64>,
    capacitance_first: Vec<u32>,
    capacitance_start: Vec<usize>,
}

/// The most rows a factorisation leaves out of a later solve (`Factor`) before the free
/// rows are factorised again.
const MAX_HELD: usize = 16;

impl Factor {
    /// Whether this factor solves a system over the free rows `free` (sorted), as it is or
    /// with a few of its rows left out; prepares the capacitance for them. False when it
    /// must be factorised again.
    fn serves(&mut self, free: &[usize]) -> bool {
        if self.index.is_empty() || free.len() > self.index.len() {
            return false;
        }
        if self.index.len() - free.len() > MAX_HELD {
            return false;
        }
        // `free` ⊂ `index`, and the places left out.
        let mut excluded = [0usize; MAX_HELD];
        let mut count = 0;
        let mut k = 0;
        for (p, &ri) in self.index.iter().enumerate() {
            if free.get(k) == Some(&ri) {
                k += 1;
            } else if count == MAX_HELD {
                // `free` holds a row `index` does not: more left out than counted above.
                return false;
            } else {
                excluded[count] = p;
                count += 1;
            }
        }
        if k != free.len() {
            return false;
        }
        let excluded = &excluded[..count];
        if excluded == self.excluded.as_slice() {
            return true;
        }
        self.excluded.clear();
        self.excluded.extend_from_slice(excluded);
        let n = self.index.len();
        self.columns.clear();
        self.columns.resize(count * n, 0.0);
        let factor = Profile {
            first: &self.first,
            start: &self.start,
            values: &self.matrix,
        };
        for (j, &p) in excluded.iter().enumerate() {
            let column = &mut self.columns[j * n..(j + 1) * n];
            column[p] = 1.0;
            factor.substitute(column);
        }
        self.capacitance.clear();
        self.capacitance_first.clear();
        self.capacitance_start.clear();
        for (i, &p) in excluded.iter().enumerate() {
            self.capacitance_first.push(0);
            self.capacitance_start.push(self.capacitance.len());
            for j in 0..=i {
                self.capacitance.push(self.columns[j * n + p]);
            }
        }
        if !profile_factor(
            &self.capacitance_first,
            &self.capacitance_start,
            &mut self.capacitance,
        ) {
            self.excluded.clear();
            return false;
        }
        true
    }

    /// The factorisation.
    fn profile(&self) -> Profile<'_> {
        Profile {
            first: &self.first,
            start: &self.start,
            values: &self.matrix,
        }
    }

    /// Solves the system over the free rows in place: `b` over `index`, its entries at the
    /// rows left out ignored, becomes x, zero there.
    fn solve(&self, b: &mut [f64]) {
        self.profile().substitute(b);
        let count = self.excluded.len();
        if count == 0 {
            return;
        }
        let n = self.index.len();
        let mut mu = [0.0f64; MAX_HELD];
        for (j, &p) in self.excluded.iter().enumerate() {
            mu[j] = -b[p];
        }
        Profile {
            first: &self.capacitance_first,
            start: &self.capacitance_start,
            values: &self.capacitance,
        }
        .substitute(&mut mu[..count]);
        for (j, &m) in mu[..count].iter().enumerate() {
            for (x, &g) in b.iter_mut().zip(&self.columns[j * n..(j + 1) * n]) {
                *x += g * m;
            }
        }
        for &p in &self.excluded {
            b[p] = 0.0;
        }
    }
}

/// The normal rows of one manifold that span fewer motions than they are rows (a face's four
/// points span three: compression and two tilts), and the projector onto the impulse patterns
/// that move nothing (the face's saddle). The relax pass solves its rows rigidly except in
/// those patterns, which take the points' spring compliance: the impulse is shared among the
/// points as the springs share it, where a rigid solve would leave it undetermined, and the
/// motions the rows do span are stopped outright.
///
/// Why not the compliance on every row, as the biased pass has it: in a column of boxes the
/// rows' compliance, the same at every joint, adds up along the column like springs in series,
/// and in the system's slowest patterns (the column bending as a whole, whose eigenvalues of
/// J·M⁻¹·Jᵀ fall with the square of its length) it outweighs J·M⁻¹·Jᵀ itself: each relax pass
/// then took out a few per cent of the bending velocity, and perturbed columns of 60 boxes
/// swayed ±18 mm with a period of 5 s that decayed by a quarter per period (benches/RESULTS.md,
/// "Chains of bodies solved directly").
#[derive(Clone, Copy, Debug)]
struct FaceModes {
    /// The normal rows, within the island.
    rows: [u32; MAX_POINTS],
    count: u8,
    /// The projector onto the patterns that move nothing, row-major over `rows`.
    saddle: [[f64; MAX_POINTS]; MAX_POINTS],
}

/// A pattern of a face's normal impulses whose eigenvalue of J·M⁻¹·Jᵀ is below this fraction
/// of the largest moves nothing ([`FaceModes`]): exact faces leave about 10⁻¹⁴ (f32 data), the
/// rigid modes of a box's face are within a factor of ten of one another.
const SADDLE: f64 = 1e-3;

/// The dense solve of one island at a time, with its scratch.
#[derive(Clone, Debug, Default)]
struct Solver {
    /// The right-hand side over the free rows, then their impulse changes.
    rhs: Vec<f64>,
    /// Each row as the pass states it.
    residual: Vec<RowState>,
    /// Each row's accumulated impulse at the start of the solve.
    impulse: Vec<f32>,
    /// Each row's part in the solve.
    role: Vec<Role>,
    /// Each row's impulse change: solved for free rows, given for fixed ones.
    change: Vec<f64>,
    /// The free rows, in order.
    index: Vec<usize>,
    /// The impulses of a solution summed per body ([`Solver::apply`]), and each body's place
    /// in `sums` (`NONE` outside a solve).
    sums: Vec<BodySum>,
    slot: Vec<u32>,
    /// Whether each row's compliance is a face's ([`FaceModes`]) in this solve.
    on_face: Vec<bool>,
    /// The fixed rows' changes (zero for the others), and a product of the couplings.
    given: Vec<f64>,
    product: Vec<f64>,
}

/// The linear and angular impulse (about the centre of mass) a solution gives one body, in
/// f64.
#[derive(Clone, Copy, Debug)]
struct BodySum {
    body: u32,
    /// 1/m along each world axis.
    inv_mass: [f64; 3],
    linear: [f64; 3],
    angular: [f64; 3],
}

/// A row's part in an island's solve.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    /// Takes no part: its impulse stays as it is.
    Out,
    /// Solved for.
    Free,
    /// Its impulse change is given ([`Solver::change`]): a normal row that would pull (set
    /// to no impulse) and its friction, or friction that would leave its cone (set on it).
    Fixed,
}

/// No island (a root that is not solved directly).
const NONE: u32 = u32::MAX;

impl DirectIslands {
    /// Whether no island is solved directly this step.
    pub fn is_empty(&self) -> bool {
        self.islands.is_empty()
    }

    /// The contact rows (normal and friction) solved directly this step.
    pub fn rows(&self) -> usize {
        self.rows.len()
    }

    /// Marks the lanes of `batches` whose manifolds these islands solve
    /// ([`ManifoldLanes::direct`], clear before).
    pub fn mark(&self, batches: &mut Batches) {
        for r in &self.rows {
            if let Some(m) = batches.manifolds.get_mut(r.batch as usize) {
                m.direct |= 1 << r.lane;
            }
        }
    }

    /// Finds this step's direct islands in the packed `batches`: bodies joined by manifolds
    /// between two movable bodies, kept when some manifold joins two movable bodies whose
    /// inverse masses differ by [`Limits::mass_ratio`] or more and they have at most
    /// [`Limits::max_rows`] contact points, or when they form a chain (every body touching at
    /// most two others: a column) whose load path is at least [`Limits::min_chain`] bodies
    /// (half that if its bodies' sizes add up to [`TALL_CHAIN`] or more), of at most
    /// [`CHAIN_ROWS`] times `max_rows` points. Each island's rows are ordered manifold by
    /// manifold outward from one end (`DirectIslands::order_island`), so that its system is
    /// banded; `bodies` are the solver bodies `states` were loaded from (their world
    /// inverse inertia builds the couplings). Deterministic: islands in the batches' order.
    pub fn build(
        &mut self,
        batches: &Batches,
        states: &[BodyState],
        bodies: &[SolverBody],
        limits: Limits,
    ) {
        let Limits {
            max_rows,
            mass_ratio,
            min_chain,
        } = limits;
        self.rows.clear();
        self.islands.clear();
        self.first.clear();
        self.start.clear();
        self.coupling_ranges.clear();
        self.faces.clear();
        self.face_ranges.clear();
        self.island_mixed.clear();
        self.by_point.clear();
        self.by_point_ranges.clear();
        if max_rows == 0 || batches.manifolds.is_empty() {
            return;
        }
        let movable = |i: u32| i != STATIC_BODY && states[i as usize].inv_mass > 0.0;
        let mixed = |a: u32, b: u32| {
            let (ia, ib) = (states[a as usize].inv_mass, states[b as usize].inv_mass);
            movable(a) && movable(b) && super::masses_apart(ia, ib, mass_ratio)
        };
        // Each movable body's count of manifolds with other movable bodies; most scenes have
        // no manifold between bodies of such different masses and no pair of bodies that
        // could be part of a chain, and then no island: one pass over the lanes instead of
        // the union-find (1.4% of a 20-row pyramid's step).
        self.degree.clear();
        self.degree.resize(states.len(), 0);
        // And whether each rests on something immovable.
        self.supported.clear();
        self.supported.resize(states.len(), false);
        let mut any_mixed = false;
        for m in &batches.manifolds {
            for l in 0..LANES {
                let (a, b) = (m.a[l], m.b[l]);
                match (movable(a), movable(b)) {
                    (true, true) => {
                        self.degree[a as usize] += 1;
                        self.degree[b as usize] += 1;
                        any_mixed |= mixed(a, b);
                    }
                    (true, false) => self.supported[a as usize] = true,
                    (false, true) => self.supported[b as usize] = true,
                    (false, false) => {}
                }
            }
        }
        let chain_pair = |a: u32, b: u32, degree: &[u32]| {
            movable(a) && movable(b) && degree[a as usize] <= 2 && degree[b as usize] <= 2
        };
        let any_chain = batches
            .manifolds
            .iter()
            .any(|m| (0..LANES).any(|l| chain_pair(m.a[l], m.b[l], &self.degree)));
        if !any_mixed && !any_chain {
            return;
        }
        self.sets.reset(states.len());
        for m in &batches.manifolds {
            for l in 0..LANES {
                if movable(m.a[l]) && movable(m.b[l]) {
                    self.sets.union(m.a[l], m.b[l]);
                }
            }
        }
        self.row_count.clear();
        self.row_count.resize(states.len(), 0);
        self.mixed.clear();
        self.mixed.resize(states.len(), false);
        // Per root: whether every member touches at most two others, and its members that
        // rest on nothing immovable (`seen` marks those counted): a chain's load path is
        // one longer (a column's bottom box rests on the ground; a row of boxes side by
        // side on the ground has a load path of one box, which Gauss-Seidel settles).
        self.chain.clear();
        self.chain.resize(states.len(), true);
        self.unsupported.clear();
        self.unsupported.resize(states.len(), 0);
        self.seen.clear();
        self.seen.resize(states.len(), false);
        self.length.clear();
        self.length.resize(states.len(), 0.0);
        let root_of = |sets: &mut UnionFind, a: u32, b: u32| {
            let body = if movable(a) { a } else { b };
            movable(body).then(|| sets.find(body))
        };
        for m in &batches.manifolds {
            let points = &batches.sources[m.first as usize..(m.first + m.count) as usize];
            for l in 0..LANES {
                let Some(root) = root_of(&mut self.sets, m.a[l], m.b[l]) else {
                    continue;
                };
                let rows = points.iter().filter(|s| s[l] != NO_SOURCE).count() as u32;
                let r = root as usize;
                self.row_count[r] += rows;
                if mixed(m.a[l], m.b[l]) {
                    self.mixed[r] = true;
                }
                for body in [m.a[l], m.b[l]] {
                    if movable(body) && !self.seen[body as usize] {
                        self.seen[body as usize] = true;
                        self.length[r] += body_size(&bodies[body as usize]);
                        if self.degree[body as usize] > 0 && !self.supported[body as usize] {
                            self.unsupported[r] += 1;
                        }
                        if self.degree[body as usize] > 2 {
                            self.chain[r] = false;
                        }
                    }
                }
            }
        }
        // The chains solved directly: those with a load path of at least `min_chain` (half of
        // it for a chain at least `TALL_CHAIN` long), the longest first (then by root),
        // while their points together stay within the budget
        // of `CHAIN_ROWS` times `max_rows`; the others stay with Gauss-Seidel. A chain costs
        // ten to twenty times what Gauss-Seidel costs it, so the budget bounds what a scene
        // of many columns pays: 4,000 boxes landing as 400 columns of ten, each solved
        // directly when chains started at a load path of nine, took 140 ms a step, 5.6 ms
        // with none (benches/RESULTS.md, "Chains solved directly within a budget").
        let chain_rows = max_rows.saturating_mul(CHAIN_ROWS);
        self.chain_roots.clear();
        for b in 0..states.len() as u32 {
            let r = b as usize;
            // Rows are counted at their island's root only.
            if self.row_count[r] == 0 {
                continue;
            }
            let heavy = self.mixed[r] && self.row_count[r] <= max_rows;
            let path = self.unsupported[r] + 1;
            let tall = path >= (min_chain / 2).max(2) && self.length[r] >= TALL_CHAIN;
            if self.chain[r] && !heavy && (path >= min_chain.max(2) || tall) {
                self.chain_roots.push((self.unsupported[r], b));
            }
            self.chain[r] = false;
        }
        self.chain_roots
            .sort_unstable_by_key(|&(path, root)| (std::cmp::Reverse(path), root));
        let mut budget = chain_rows;
        for &(_, root) in &self.chain_roots {
            let rows = self.row_count[root as usize];
            if rows <= budget {
                budget -= rows;
                self.chain[root as usize] = true;
            }
        }
        self.island_of.clear();
        self.island_of.resize(states.len(), NONE);
        let mut islands = 0u32;
        for (bi, m) in batches.manifolds.iter().enumerate() {
            for l in 0..LANES {
                let Some(root) = root_of(&mut self.sets, m.a[l], m.b[l]) else {
                    continue;
                };
                let r = root as usize;
                let heavy = self.mixed[r] && self.row_count[r] <= max_rows;
                let chain = self.chain[r];
                if !heavy && !chain {
                    continue;
                }
                if self.island_of[r] == NONE {
                    self.island_of[r] = islands;
                    self.island_mixed.push(self.mixed[r]);
                    islands += 1;
                }
                for k in m.first..m.first + m.count {
                    if batches.sources[k as usize][l] == NO_SOURCE {
                        continue;
                    }
                    let p = &batches.points[k as usize];
                    let (r_a, r_b) = (p.r_a.lane(l), p.r_b.lane(l));
                    let rows = [
                        (NORMAL, p.normal),
                        (TANGENT_1, p.tangent1),
                        (TANGENT_2, p.tangent2),
                    ];
                    let kinds = if p.friction[l] > 0.0 { 3 } else { 1 };
                    for (kind, d) in rows.into_iter().take(kinds) {
                        let d = d.lane(l);
                        self.rows.push(Row {
                            island: self.island_of[r],
                            order: self.rows.len() as u32,
                            kind,
                            batch: bi as u32,
                            point: k,
                            lane: l as u8,
                            a: m.a[l],
                            b: m.b[l],
                            inv_mass_a: m.inv_mass_a.lane(l),
                            inv_mass_b: m.inv_mass_b.lane(l),
                            normal: d,
                            rn_a: r_a.cross(d),
                            rn_b: r_b.cross(d),
                            floor: 0.0,
                        });
                    }
                }
            }
        }
        // Rows island by island, each island's in the batches' order, then its manifolds
        // outward from one end.
        self.rows.sort_unstable_by_key(|r| (r.island, r.order));
        let mut start = 0usize;
        for i in 1..=self.rows.len() {
            if i == self.rows.len() || self.rows[i].island != self.rows[start].island {
                self.islands.push((start as u32, i as u32));
                start = i;
            }
        }
        for k in 0..self.islands.len() {
            let (start, end) = self.islands[k];
            self.order_island(start as usize..end as usize, &movable);
        }
        self.couplings.clear();
        // As the rows' angular responses were prepared ([`super::prepare`]).
        let inv_inertia = |k: u32| {
            bodies
                .get(k as usize)
                .filter(|b| b.rotates())
                .map_or(Mat3::ZERO, |b| b.inv_inertia)
        };
        self.inv_inertia.clear();
        if !self.islands.is_empty() {
            self.inv_inertia.resize(states.len(), Mat3::ZERO);
            for row in &self.rows {
                for k in [row.a, row.b] {
                    if let Some(m) = self.inv_inertia.get_mut(k as usize) {
                        *m = inv_inertia(k);
                    }
                }
            }
        }
        self.responses.clear();
        self.responses
            .extend(self.rows.iter().map(|row| Response::of(row, &inv_inertia)));
        for (row, response) in self.rows.iter_mut().zip(&self.responses) {
            if row.kind != NORMAL {
                row.floor = response.friction_floor();
            }
        }
        // Each island's J·M⁻¹·Jᵀ by its profile: row i from the first row that shares a
        // movable body with it (`first_row` of each body), to its diagonal.
        self.first_row.clear();
        self.first_row.resize(states.len(), NONE);
        for &(start, end) in &self.islands {
            let rows = &self.rows[start as usize..end as usize];
            let base = self.couplings.len();
            for (i, row) in rows.iter().enumerate() {
                let mut first = i as u32;
                for body in [row.a, row.b] {
                    if movable(body) {
                        let f = &mut self.first_row[body as usize];
                        if *f == NONE {
                            *f = i as u32;
                        }
                        first = first.min(*f);
                    }
                }
                self.first.push(first);
                self.start.push(self.couplings.len() - base);
                let responses = &self.responses[start as usize..end as usize];
                for other in &responses[first as usize..=i] {
                    self.couplings.push(responses[i].coupling(other));
                }
            }
            for row in rows {
                for body in [row.a, row.b] {
                    if let Some(f) = self.first_row.get_mut(body as usize) {
                        *f = NONE;
                    }
                }
            }
            self.coupling_ranges.push((base, self.couplings.len()));
            let profile = Profile {
                first: &self.first[start as usize..end as usize],
                start: &self.start[start as usize..end as usize],
                values: &self.couplings[base..],
            };
            let faces_from = self.faces.len();
            if !self.island_mixed[self.coupling_ranges.len() - 1] {
                find_faces(rows, profile, &mut self.faces);
            }
            self.face_ranges.push((faces_from, self.faces.len()));
            let from = self.by_point.len();
            self.by_point
                .extend((0..rows.len() as u32).filter(|&i| rows[i as usize].kind == NORMAL));
            self.by_point[from..].sort_unstable_by_key(|&i| {
                let r = &rows[i as usize];
                (r.batch, r.point, r.lane)
            });
            self.by_point_ranges.push((from, self.by_point.len()));
        }
        self.factors
            .resize_with(self.islands.len(), Default::default);
        for factors in &mut self.factors {
            for factor in factors {
                factor.index.clear();
            }
        }
    }

    /// Orders the island's rows in `range` manifold by manifold, outward from one end: its
    /// movable bodies are ranked breadth first from one that touches the fewest others
    /// (preferring one that rests on something immovable), and each manifold is keyed by its
    /// bodies' lower and higher rank. A chain's manifolds then follow it from one end to the
    /// other, and each row of its system couples only with the rows of the manifolds beside
    /// its own: the profile's cost grows linearly with the chain's length. A manifold's rows
    /// keep their order (a point's normal row, then its friction rows).
    fn order_island(&mut self, range: std::ops::Range<usize>, movable: &impl Fn(u32) -> bool) {
        let rows = &self.rows[range.clone()];
        // The manifolds: runs of rows of one batch lane.
        self.manifold_runs.clear();
        let mut s = 0;
        while s < rows.len() {
            let key = (rows[s].batch, rows[s].lane);
            let e = s + rows[s..]
                .iter()
                .take_while(|r| (r.batch, r.lane) == key)
                .count();
            self.manifold_runs
                .push((s as u32, e as u32, rows[s].a, rows[s].b));
            s = e;
        }
        // Edges between movable bodies, both ways, for the breadth-first ranking.
        self.edges.clear();
        let mut start_body = (u32::MAX, true, u32::MAX);
        for &(_, _, a, b) in &self.manifold_runs {
            if movable(a) && movable(b) {
                self.edges.push((a, b));
                self.edges.push((b, a));
            }
            let rests = !movable(a) || !movable(b);
            for body in [a, b] {
                if movable(body) {
                    let candidate = (self.degree[body as usize], !rests, body);
                    if (candidate.0, candidate.1) < (start_body.0, start_body.1) {
                        start_body = candidate;
                    }
                }
            }
        }
        self.edges.sort_unstable();
        self.queue.clear();
        self.rank.resize(self.degree.len(), NONE);
        let root = start_body.2;
        // Every island holds a movable body (its rows are those of one); none: keep the order.
        debug_assert!(root != u32::MAX, "an island without a movable body");
        if root == u32::MAX {
            return;
        }
        self.rank[root as usize] = 0;
        self.queue.push(root);
        let mut head = 0;
        while head < self.queue.len() {
            let body = self.queue[head];
            head += 1;
            let from = self.edges.partition_point(|&(b, _)| b < body);
            for k in from..self.edges.len() {
                let (b, other) = self.edges[k];
                if b != body {
                    break;
                }
                if self.rank[other as usize] == NONE {
                    self.rank[other as usize] = self.queue.len() as u32;
                    self.queue.push(other);
                }
            }
        }
        let rank = &self.rank;
        let key = |&(s, _, a, b): &(u32, u32, u32, u32)| {
            let r = |body: u32| {
                if movable(body) {
                    rank[body as usize]
                } else {
                    NONE
                }
            };
            let (ra, rb) = (r(a), r(b));
            (
                ra.min(rb),
                if ra == NONE || rb == NONE {
                    ra.min(rb)
                } else {
                    ra.max(rb)
                },
                s,
            )
        };
        self.manifold_runs.sort_unstable_by_key(key);
        self.scratch_rows.clear();
        for &(s, e, _, _) in &self.manifold_runs {
            self.scratch_rows
                .extend_from_slice(&self.rows[range.start + s as usize..range.start + e as usize]);
        }
        self.rows[range].copy_from_slice(&self.scratch_rows);
        for &body in &self.queue {
            self.rank[body as usize] = NONE;
        }
    }

    /// Sizes each direct manifold's springs by the mass its load stands for: where the
    /// per-substep impulse Λ its points start with (summed) exceeds what their effective
    /// masses M (summed) weigh in one substep (M·|g|·h, `weight_impulse` = |g|·h), each of its
    /// springs has the stiffness and damping of Λ/(M·|g|·h) times its own mass at the same
    /// frequency and damping ratio: the mass scale s and impulse scale 1 − s of
    /// [`super::Softness`] with hω(2ζ + hω) multiplied by that ratio. One ratio for the whole
    /// manifold: sized point by point, a point the narrow phase has just found (no impulse to
    /// start from) stays soft while its neighbours are stiff, and they take its load.
    pub fn stiffen(&self, batches: &mut Batches, weight_impulse: f32) {
        if !(weight_impulse > 0.0) {
            return;
        }
        let mut start = 0;
        while start < self.rows.len() {
            let manifold = (self.rows[start].batch, self.rows[start].lane);
            let end = start
                + self.rows[start..]
                    .iter()
                    .take_while(|r| (r.batch, r.lane) == manifold)
                    .count();
            let rows = &self.rows[start..end];
            start = end;
            let (mut load, mut mass) = (0.0f32, 0.0f32);
            for row in rows.iter().filter(|r| r.kind == NORMAL) {
                let p = &batches.points[row.point as usize];
                load += p.normal_impulse[row.lane as usize];
                mass += p.normal_mass[row.lane as usize];
            }
            let ratio = load / (mass * weight_impulse);
            if !(ratio > 1.0 && ratio.is_finite()) {
                continue;
            }
            for row in rows.iter().filter(|r| r.kind == NORMAL) {
                let p = &mut batches.points[row.point as usize];
                let l = row.lane as usize;
                let (mass_scale, impulse_scale) = (p.mass_scale[l], p.impulse_scale[l]);
                if impulse_scale > 0.0 {
                    let a = mass_scale / impulse_scale * ratio;
                    p.mass_scale[l] = a / (1.0 + a);
                    p.impulse_scale[l] = 1.0 / (1.0 + a);
                }
            }
        }
    }

    /// Solves every direct island's rows (normal and friction) as `pass` states them, and
    /// applies the result to `states` and to the accumulated impulses in `points`, the points
    /// of the batches `manifolds` ([`Batches::points`], [`Batches::manifolds`]).
    pub fn correct(
        &mut self,
        manifolds: &[ManifoldLanes],
        points: &mut [PointLanes],
        states: &mut [BodyState],
        pass: RowPass,
    ) {
        let kind = match pass {
            RowPass::Biased(_) => 0,
            RowPass::Relax { .. } => 1,
        };
        for (island, &(start, end)) in self.islands.iter().enumerate() {
            let range = start as usize..end as usize;
            let (from, to) = self.coupling_ranges[island];
            let factor = &mut self.factors[island][kind];
            let island = Island {
                rows: &self.rows[range.clone()],
                couplings: Profile {
                    first: &self.first[range.clone()],
                    start: &self.start[range],
                    values: &self.couplings[from..to],
                },
                inv_inertia: &self.inv_inertia,
                faces: &self.faces[self.face_ranges[island].0..self.face_ranges[island].1],
                by_point: &self.by_point
                    [self.by_point_ranges[island].0..self.by_point_ranges[island].1],
            };
            self.solver
                .solve_island(manifolds, points, states, island, factor, pass);
        }
    }
}

impl Solver {
    /// Solves the island's rows as `pass` states them and applies the result: the normal
    /// rows, and the friction rows as sticking, with every normal impulse
    /// at least 0 and every point's friction within μ times its normal impulse. An active set:
    /// a normal row whose total would pull is fixed at no impulse (with its friction), a
    /// point whose friction would leave its disk has it fixed on the disk, and the rest is
    /// solved again, for at most [`ACTIVE_SET_ROUNDS`] rounds; an island whose rounds run out
    /// is left to Gauss-Seidel.
    fn solve_island(
        &mut self,
        manifolds: &[ManifoldLanes],
        points: &mut [PointLanes],
        states: &mut [BodyState],
        island: Island,
        factor: &mut Factor,
        pass: RowPass,
    ) {
        let Island {
            rows,
            couplings,
            inv_inertia,
            faces,
            by_point,
        } = island;
        let relax = matches!(pass, RowPass::Relax { .. });
        let chord_time = match pass {
            RowPass::Biased(pass) => pass.chord_time,
            RowPass::Relax { chord_time, .. } => chord_time,
        };
        self.residual.clear();
        self.residual.resize(rows.len(), RowState::default());
        self.impulse.clear();
        self.role.clear();
        self.change.clear();
        // The normal rows by batch point: one evaluation of a batch point's eight lanes
        // serves every row of the island among them.
        let mut last = (u32::MAX, u32::MAX);
        let mut lanes = [RowState::default(); LANES];
        for &i in by_point {
            let row = &rows[i as usize];
            if (row.batch, row.point) != last {
                last = (row.batch, row.point);
                lanes = row_residuals(
                    manifolds,
                    points,
                    share(states),
                    row.batch as usize,
                    row.point as usize,
                    pass,
                );
            }
            self.residual[i as usize] = lanes[row.lane as usize];
        }
        for (i, row) in rows.iter().enumerate() {
            let l = row.lane as usize;
            let p = &points[row.point as usize];
            let (residual, impulse, role) = match row.kind {
                NORMAL => {
                    let row = self.residual[i];
                    let impulse = p.normal_impulse[l];
                    let role = if impulse > 0.0 || row.r > 0.0 {
                        Role::Free
                    } else {
                        Role::Out
                    };
                    (row, impulse, role)
                }
                kind => {
                    // Sticking: no sliding at the point, with the compliance of its normal
                    // row (the row before the first tangent's, two before the second's), so
                    // the friction of a face's points, which span fewer motions than they are
                    // rows, is shared as the normal load is; at least the row's floor
                    // (FRICTION_REGULARISATION).
                    let normal = i - kind as usize;
                    let impulse = p.tangent_impulse[kind as usize - 1][l];
                    let role = self.role[normal];
                    let state = RowState {
                        r: -(row.velocity(states) + p.chord[kind as usize - 1][l] * chord_time),
                        compliance: self.residual[normal].compliance.max(row.floor as f32),
                    };
                    (state, impulse, role)
                }
            };
            self.residual[i] = residual;
            self.impulse.push(impulse);
            self.role.push(role);
            self.change.push(0.0);
        }
        for _ in 0..ACTIVE_SET_ROUNDS {
            let faces = if relax { faces } else { &[] };
            if !self.solve_free(couplings, faces, factor) {
                return;
            }
            if !self.fix_pulling_rows(rows) && !self.fix_sliding_points(rows, points) {
                // The relax pass only takes velocity out; a solution whose fixed rows (the
                // friction cone's, above all) would put kinetic energy in is not applied.
                if relax && self.energy_change(rows, couplings, states) > 0.0 {
                    return;
                }
                self.apply(rows, points, states, inv_inertia);
                return;
            }
        }
    }

    /// Solves (J·M⁻¹·Jᵀ + C)·x = r over the free rows, the fixed rows' changes moved to the
    /// right-hand side; the changes go to [`Solver::change`]. `couplings` is J·M⁻¹·Jᵀ over
    /// all the island's rows; `factor` is factorised again only when the free rows changed.
    /// False when there is nothing to solve or the factorisation fails.
    fn solve_free(&mut self, couplings: Profile, faces: &[FaceModes], factor: &mut Factor) -> bool {
        let all = self.role.len();
        self.index.clear();
        self.index
            .extend((0..all).filter(|&i| self.role[i] == Role::Free));
        let n = self.index.len();
        if n == 0 {
            return self.role.contains(&Role::Fixed);
        }
        if !factor.serves(&self.index) && !self.refactor(couplings, faces, factor) {
            return false;
        }
        // The right-hand side over the factorised rows; a row the factor holds but this solve
        // leaves out gets none (its impulse is held by the capacitance below).
        self.rhs.clear();
        self.rhs.resize(factor.index.len(), 0.0);
        let mut k = 0;
        for (p, &ri) in factor.index.iter().enumerate() {
            if self.index.get(k) == Some(&ri) {
                self.rhs[p] = f64::from(self.residual[ri].r);
                k += 1;
            }
        }
        if self.role.contains(&Role::Fixed) {
            self.given.clear();
            self.given.extend((0..all).map(|k| {
                if self.role[k] == Role::Fixed {
                    self.change[k]
                } else {
                    0.0
                }
            }));
            couplings.times(&self.given, &mut self.product);
            for (rhs, &ri) in self.rhs.iter_mut().zip(&factor.index) {
                if self.role[ri] == Role::Free {
                    *rhs -= self.product[ri];
                }
            }
        }
        factor.solve(&mut self.rhs);
        for (p, &ri) in factor.index.iter().enumerate() {
            if self.role[ri] == Role::Free {
                self.change[ri] = self.rhs[p];
            }
        }
        true
    }

    /// Factorises the system over the free rows `self.index` into `factor`, with each row's
    /// compliance (a face's in its saddle only, [`FaceModes`]). False when it fails.
    fn refactor(&mut self, couplings: Profile, faces: &[FaceModes], factor: &mut Factor) -> bool {
        self.on_face.clear();
        self.on_face.resize(self.role.len(), false);
        for face in faces {
            for &r in &face.rows[..face.count as usize] {
                self.on_face[r as usize] = true;
            }
        }
        factor.index.clone_from(&self.index);
        factor.first.clear();
        factor.start.clear();
        factor.matrix.clear();
        // The free rows' profile: free row k from the first free row at or after its
        // row's first column.
        for (k, &ri) in self.index.iter().enumerate() {
            let first = couplings.first[ri] as usize;
            let from = self.index.partition_point(|&r| r < first);
            factor.first.push(from as u32);
            factor.start.push(factor.matrix.len());
            for &rj in &self.index[from..=k] {
                factor.matrix.push(couplings.entry(ri, rj));
            }
            if let Some(diagonal) = factor.matrix.last_mut()
                && !self.on_face[ri]
            {
                *diagonal += f64::from(self.residual[ri].compliance);
            }
        }
        // A face's rows: compliance in its saddle only, C = D^½·P·D^½ with D the points'
        // spring compliances, over the rows that are free.
        for face in faces {
            let rows = &face.rows[..face.count as usize];
            for (a, &ra) in rows.iter().enumerate() {
                let Ok(ka) = self.index.binary_search(&(ra as usize)) else {
                    continue;
                };
                for (b, &rb) in rows.iter().enumerate().take(a + 1) {
                    let Ok(kb) = self.index.binary_search(&(rb as usize)) else {
                        continue;
                    };
                    let (hi, lo) = (ka.max(kb), ka.min(kb));
                    let (ca, cb) = (
                        f64::from(self.residual[ra as usize].compliance),
                        f64::from(self.residual[rb as usize].compliance),
                    );
                    let at = factor.start[hi] + lo - factor.first[hi] as usize;
                    factor.matrix[at] += (ca * cb).sqrt() * face.saddle[a][b];
                }
            }
        }
        if !profile_factor(&factor.first, &factor.start, &mut factor.matrix) {
            factor.index.clear();
            return false;
        }
        factor.excluded.clear();
        factor.columns.clear();
        true
    }

    /// The change of the bodies' kinetic energy (J) that the solution found would make:
    /// xᵀ·J·v + ½·xᵀ·J·M⁻¹·Jᵀ·x over the rows that change.
    fn energy_change(&mut self, rows: &[Row], couplings: Profile, states: &[BodyState]) -> f64 {
        // A row left out has no change, so the couplings need not skip it.
        debug_assert!((0..rows.len()).all(|k| self.role[k] != Role::Out || self.change[k] == 0.0));
        couplings.times(&self.change, &mut self.product);
        let mut change = 0.0;
        for (i, row) in rows.iter().enumerate() {
            if self.role[i] == Role::Out {
                continue;
            }
            let x = self.change[i];
            change += x * (f64::from(row.velocity(states)) + 0.5 * self.product[i]);
        }
        change
    }

    /// The total impulse of row `i` with its change.
    fn total(&self, i: usize) -> f64 {
        f64::from(self.impulse[i]) + self.change[i]
    }

    /// Fixes every free normal row whose total would pull at no impulse, with its friction;
    /// true when any was.
    fn fix_pulling_rows(&mut self, rows: &[Row]) -> bool {
        let mut any = false;
        for (i, row) in rows.iter().enumerate() {
            if row.kind != NORMAL || self.role[i] != Role::Free || self.total(i) >= 0.0 {
                continue;
            }
            any = true;
            // The normal row and the friction rows that follow it.
            let point = 1 + rows[i + 1..]
                .iter()
                .take_while(|r| r.kind != NORMAL)
                .count();
            for k in i..i + point {
                if self.role[k] != Role::Out {
                    self.role[k] = Role::Fixed;
                    self.change[k] = -f64::from(self.impulse[k]);
                }
            }
        }
        any
    }

    /// Fixes the friction of every point whose sticking friction would leave its disk (μ
    /// times its normal impulse) on the disk, in the direction it asked for; true when any was.
    fn fix_sliding_points(&mut self, rows: &[Row], points: &[PointLanes]) -> bool {
        let mut any = false;
        for (i, row) in rows.iter().enumerate() {
            if row.kind != TANGENT_1 || self.role[i] != Role::Free {
                continue;
            }
            let mu = f64::from(points[row.point as usize].friction[row.lane as usize]);
            let limit = mu * self.total(i - 1).max(0.0);
            let (t1, t2) = (self.total(i), self.total(i + 1));
            let length = (t1 * t1 + t2 * t2).sqrt();
            if length > limit * (1.0 + CONE_TOLERANCE) {
                let scale = limit / length;
                for (k, t) in [(i, t1), (i + 1, t2)] {
                    self.role[k] = Role::Fixed;
                    self.change[k] = t * scale - f64::from(self.impulse[k]);
                }
                any = true;
            }
        }
        any
    }

    /// Applies the changes of the free and fixed rows to the accumulated impulses and to the
    /// bodies.
    fn apply(
        &mut self,
        rows: &[Row],
        points: &mut [PointLanes],
        states: &mut [BodyState],
        inv_inertia: &[Mat3],
    ) {
        // Each body's impulse is summed in f64 and applied once, through the inverse inertia
        // the couplings were built with: applied row by row in f32, a light box between a
        // heavy one and the ground kept the rounding of each face's 10⁴ N·s (velocity noise of
        // 0.004 m/s and 0.02 rad/s for a 0.1 m box of 1 kg under 10⁶ kg), which rocked the
        // heavy box off it.
        self.sums.clear();
        for (i, row) in rows.iter().enumerate() {
            if self.role[i] == Role::Out {
                continue;
            }
            let l = row.lane as usize;
            let p = &mut points[row.point as usize];
            let total = self.total(i) as f32;
            let slot = match row.kind {
                NORMAL => &mut p.normal_impulse[l],
                kind => &mut p.tangent_impulse[kind as usize - 1][l],
            };
            let total = if row.kind == NORMAL {
                total.max(0.0)
            } else {
                total
            };
            let delta = total - *slot;
            if !delta.is_finite() {
                continue;
            }
            *slot = total;
            if row.kind == NORMAL {
                p.max_normal_impulse[l] = p.max_normal_impulse[l].max(delta);
            }
            let delta = f64::from(delta);
            for (body, sign, rn, inv_mass) in [
                (row.a, 1.0, row.rn_a, row.inv_mass_a),
                (row.b, -1.0, row.rn_b, row.inv_mass_b),
            ] {
                if body == STATIC_BODY {
                    continue;
                }
                if self.slot.len() <= body as usize {
                    self.slot.resize(body as usize + 1, NONE);
                }
                let at = match self.slot[body as usize] {
                    NONE => {
                        self.slot[body as usize] = self.sums.len() as u32;
                        self.sums.push(BodySum {
                            body,
                            inv_mass: wide(inv_mass),
                            linear: [0.0; 3],
                            angular: [0.0; 3],
                        });
                        self.sums.len() - 1
                    }
                    at => at as usize,
                };
                let sum = &mut self.sums[at];
                let (n, rn) = (wide(row.normal), wide(rn));
                for k in 0..3 {
                    sum.linear[k] += sign * n[k] * delta;
                    sum.angular[k] += sign * rn[k] * delta;
                }
            }
        }
        for sum in &self.sums {
            self.slot[sum.body as usize] = NONE;
            let state = &mut states[sum.body as usize];
            let m = inv_inertia
                .get(sum.body as usize)
                .copied()
                .unwrap_or(Mat3::ZERO);
            let l: [f32; 3] = std::array::from_fn(|i| (sum.linear[i] * sum.inv_mass[i]) as f32);
            let a = symmetric_times(m, sum.angular).map(|x| x as f32);
            state.linear_velocity += Vec3::from_array(l);
            state.angular_velocity += Vec3::from_array(a);
        }
    }
}

/// One island's rows, their couplings, and the bodies' inverse inertia
/// ([`DirectIslands::inv_inertia`]).
#[derive(Clone, Copy)]
struct Island<'a> {
    rows: &'a [Row],
    couplings: Profile<'a>,
    faces: &'a [FaceModes],
    /// The normal rows (within the island) by batch, then point.
    by_point: &'a [u32],
    inv_inertia: &'a [Mat3],
}

/// The symmetric part of `m` (an inverse inertia, symmetric but for rounding) times `v`, in
/// f64.
fn symmetric_times(m: Mat3, v: [f64; 3]) -> [f64; 3] {
    let cols = [wide(m.x_axis), wide(m.y_axis), wide(m.z_axis)];
    std::array::from_fn(|i| {
        (0..3)
            .map(|k| 0.5 * (cols[k][i] + cols[i][k]) * v[k])
            .sum::<f64>()
    })
}

/// A vector in f64.
fn wide(v: Vec3) -> [f64; 3] {
    [f64::from(v.x), f64::from(v.y), f64::from(v.z)]
}

impl Row {
    /// The velocity of A's point relative to B's along the row's direction (m/s).
    fn velocity(&self, states: &[BodyState]) -> f32 {
        let (a, b) = (&states[self.a as usize], &states[self.b as usize]);
        self.normal.dot(a.linear_velocity - b.linear_velocity) + self.rn_a.dot(a.angular_velocity)
            - self.rn_b.dot(b.angular_velocity)
    }
}

/// Appends the island's faces ([`FaceModes`]): each manifold's normal rows (its rows are
/// consecutive, a point's normal row first), where J·M⁻¹·Jᵀ over them has patterns that move
/// nothing.
// Index loops: the block's entries by row and column, as the formulas read.
#[allow(clippy::needless_range_loop)]
fn find_faces(rows: &[Row], couplings: Profile, faces: &mut Vec<FaceModes>) {
    let mut s = 0;
    while s < rows.len() {
        let key = (rows[s].batch, rows[s].lane);
        let e = s + rows[s..]
            .iter()
            .take_while(|r| (r.batch, r.lane) == key)
            .count();
        let mut face = FaceModes {
            rows: [0; MAX_POINTS],
            count: 0,
            saddle: [[0.0; MAX_POINTS]; MAX_POINTS],
        };
        for (i, row) in rows[s..e].iter().enumerate() {
            if row.kind == NORMAL && (face.count as usize) < MAX_POINTS {
                face.rows[face.count as usize] = (s + i) as u32;
                face.count += 1;
            }
        }
        s = e;
        let n = face.count as usize;
        if n < 2 {
            continue;
        }
        let mut a = [[0.0f64; MAX_POINTS]; MAX_POINTS];
        for i in 0..n {
            for j in 0..n {
                a[i][j] = couplings.entry(face.rows[i] as usize, face.rows[j] as usize);
            }
        }
        let (values, vectors) = symmetric_eigen(a, n);
        let largest = values[..n].iter().fold(0.0f64, |m, &v| m.max(v));
        let mut any = false;
        for k in 0..n {
            if values[k] <= SADDLE * largest {
                any = true;
                for i in 0..n {
                    for j in 0..n {
                        face.saddle[i][j] += vectors[i][k] * vectors[j][k];
                    }
                }
            }
        }
        if any {
            faces.push(face);
        }
    }
}

/// The eigenvalues and eigenvectors (columns) of the symmetric n × n top-left block of `a`,
/// by cyclic Jacobi rotations.
#[allow(clippy::needless_range_loop)]
fn symmetric_eigen(
    mut a: [[f64; MAX_POINTS]; MAX_POINTS],
    n: usize,
) -> ([f64; MAX_POINTS], [[f64; MAX_POINTS]; MAX_POINTS]) {
    let mut v = [[0.0f64; MAX_POINTS]; MAX_POINTS];
    for i in 0..n {
        v[i][i] = 1.0;
    }
    for _ in 0..32 {
        let mut off = 0.0;
        let mut scale = 0.0;
        for i in 0..n {
            scale += a[i][i] * a[i][i];
            for j in 0..i {
                off += a[i][j] * a[i][j];
            }
        }
        if !(off > 1e-30 * scale) {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if a[p][q] == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let sn = t * c;
                for k in 0..n {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - sn * akq;
                    a[k][q] = sn * akp + c * akq;
                }
                for k in 0..n {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - sn * aqk;
                    a[q][k] = sn * apk + c * aqk;
                }
                for k in 0..n {
                    let (vkp, vkq) = (v[k][p], v[k][q]);
                    v[k][p] = c * vkp - sn * vkq;
                    v[k][q] = sn * vkp + c * vkq;
                }
            }
        }
    }
    let mut values = [0.0; MAX_POINTS];
    for i in 0..n {
        values[i] = a[i][i];
    }
    (values, v)
}

/// A symmetric matrix by its lower profile: row i holds its entries from column `first[i]`
/// to its diagonal, at `values[start[i]..]`; the entries left of `first[i]` are zero.
#[derive(Clone, Copy, Debug)]
struct Profile<'a> {
    first: &'a [u32],
    start: &'a [usize],
    values: &'a [f64],
}

impl Profile<'_> {
    /// Entry (i, j), either side of the diagonal.
    fn entry(&self, i: usize, j: usize) -> f64 {
        let (i, j) = (i.max(j), i.min(j));
        let first = self.first[i] as usize;
        if j < first {
            0.0
        } else {
            self.values[self.start[i] + j - first]
        }
    }

    /// Row i's entries from its first column to its diagonal.
    fn row(&self, i: usize) -> &[f64] {
        let first = self.first[i] as usize;
        &self.values[self.start[i]..self.start[i] + i + 1 - first]
    }

    /// y = A·x.
    fn times(&self, x: &[f64], y: &mut Vec<f64>) {
        y.clear();
        y.resize(x.len(), 0.0);
        for i in 0..x.len() {
            let first = self.first[i] as usize;
            let row = self.row(i);
            let (below, diagonal) = row.split_at(row.len() - 1);
            y[i] += dot(below, &x[first..i]) + diagonal[0] * x[i];
            for (yj, &a) in y[first..i].iter_mut().zip(below) {
                *yj += a * x[i];
            }
        }
    }

    /// Solves L·Lᵀ·x = b in place (`b` becomes x) with a factor of [`profile_factor`]; a
    /// dependent row's x is 0.
    fn substitute(&self, b: &mut [f64]) {
        for i in 0..b.len() {
            let first = self.first[i] as usize;
            let row = self.row(i);
            let (below, inv_d) = (&row[..row.len() - 1], row[row.len() - 1]);
            let s = b[i] - dot(below, &b[first..i]);
            b[i] = if inv_d > 0.0 { s * inv_d } else { 0.0 };
        }
        for i in (0..b.len()).rev() {
            let first = self.first[i] as usize;
            let row = self.row(i);
            let (below, inv_d) = (&row[..row.len() - 1], row[row.len() - 1]);
            if !(inv_d > 0.0) {
                b[i] = 0.0;
                continue;
            }
            let x = b[i] * inv_d;
            b[i] = x;
            // Lᵀ column by column: subtract this unknown from the rows above it.
            for (bk, &l) in b[first..i].iter_mut().zip(below) {
                *bk -= l * x;
            }
        }
    }
}

/// Factorises the symmetric positive semi-definite matrix whose lower profile is `values`
/// ([`Profile`]) in place as L·Lᵀ, which has the same profile, L's diagonal stored as its
/// reciprocals 1/lᵢᵢ (the substitution then multiplies where it would divide). A row whose
/// pivot falls below [`DEPENDENT`] times its diagonal depends on the rows before it (the rows
/// of a face span fewer motions than it has points): its column of L is zero, and
/// [`Profile::substitute`] gives it no impulse while the others meet it as far as it is
/// consistent with them. False when a pivot is not finite. The cost is the sum over the rows
/// of their profile's width squared: linear in a chain's length
/// ([`DirectIslands::order_island`]).
fn profile_factor(first: &[u32], start: &[usize], values: &mut [f64]) -> bool {
    let n = first.len();
    for i in 0..n {
        let fi = first[i] as usize;
        let si = start[i];
        // L's row i left of the diagonal, column by column: lᵢⱼ = (aᵢⱼ − Σ lᵢq·lⱼq)/lⱼⱼ over
        // the columns q both rows hold.
        for j in fi..i {
            let fj = first[j] as usize;
            let from = fi.max(fj);
            let (done, rest) = values.split_at_mut(si);
            let row_j = &done[start[j] + from - fj..start[j] + j - fj];
            let inv_dj = done[start[j] + j - fj];
            let row_i = &mut rest[..i + 1 - fi];
            let s = row_i[j - fi] - dot(&row_i[from - fi..j - fi], row_j);
            row_i[j - fi] = s * inv_dj;
        }
        let row_i = &mut values[si..si + i + 1 - fi];
        let (below, diagonal) = row_i.split_at_mut(i - fi);
        let a = diagonal[0];
        let d = a - dot(below, below);
        if !d.is_finite() {
            return false;
        }
        // A dependent row: a zero reciprocal, so the rows below take nothing from its
        // column and the substitution gives it no impulse.
        diagonal[0] = if d > DEPENDENT * a {
            1.0 / d.sqrt()
        } else {
            0.0
        };
    }
    true
}

/// Σ aₖ·bₖ over the shorter of the two, in four interleaved partial sums (one chain of
/// dependent additions would leave the factorisation waiting on each: it was most of a light
/// column's direct solve).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut sums = [0.0f64; 4];
    let (chunks_a, chunks_b) = (a.chunks_exact(4), b.chunks_exact(4));
    let (rest_a, rest_b) = (chunks_a.remainder(), chunks_b.remainder());
    for (x, y) in chunks_a.zip(chunks_b) {
        for k in 0..4 {
            sums[k] += x[k] * y[k];
        }
    }
    let mut total = (sums[0] + sums[1]) + (sums[2] + sums[3]);
    for (x, y) in rest_a.iter().zip(rest_b) {
        total += x * y;
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dense lower triangle (row-major n × n) as a full profile, factorised.
    fn factor_dense(a: &[f64], n: usize) -> Option<(Vec<u32>, Vec<usize>, Vec<f64>)> {
        let first = vec![0u32; n];
        let start: Vec<usize> = (0..n).map(|i| i * (i + 1) / 2).collect();
        let mut values: Vec<f64> = (0..n)
            .flat_map(|i| (0..=i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * n + j])
            .collect();
        profile_factor(&first, &start, &mut values).then_some((first, start, values))
    }

    fn substitute((first, start, values): &(Vec<u32>, Vec<usize>, Vec<f64>), b: &mut [f64]) {
        Profile {
            first,
            start,
            values,
        }
        .substitute(b);
    }

    #[test]
    fn a_dependent_row_gets_no_impulse_and_the_others_meet_it() {
        // Rows along x, y and x + y of one unit mass: J·Jᵀ has rank 2, like the rows of a face.
        let a = [1.0, 0.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 2.0];
        let factor = factor_dense(&a, 3).unwrap();
        // Targets a motion can meet: the velocity (1, 2) gives 1, 2 and 3.
        let mut b = [1.0, 2.0, 3.0];
        substitute(&factor, &mut b);
        assert_eq!(b[2], 0.0);
        assert!(
            (b[0] - 1.0).abs() < 1e-12 && (b[1] - 2.0).abs() < 1e-12,
            "{b:?}"
        );
    }

    #[test]
    fn a_positive_definite_system_is_solved_exactly() {
        // A light body between a heavy one and the ground, 1:10,000: the ill-conditioned pair of
        // rows Gauss-Seidel needs thousands of sweeps for.
        let (light, heavy) = (1.0, 1e-4);
        let a = [light, -light, -light, light + heavy];
        let x = [3.0, 2.0];
        let mut b = [a[0] * x[0] + a[1] * x[1], a[2] * x[0] + a[3] * x[1]];
        let factor = factor_dense(&a, 2).unwrap();
        substitute(&factor, &mut b);
        assert!(
            (b[0] - x[0]).abs() < 1e-9 && (b[1] - x[1]).abs() < 1e-9,
            "{b:?}"
        );
    }

    #[test]
    fn couplings_are_the_gram_matrix_of_the_rows_in_f64() {
        // A light box between the ground and a 10⁶ times heavier box, turned so that no arm
        // or inertia entry is exact in f32: the couplings must be J·M⁻¹·Jᵀ computed in f64
        // from the rows' f32 data (the heavy box's part, 10⁻⁶ of the light box's, is lost in
        // f32 rounding otherwise), symmetric to f64's rounding.
        let turn =
            jostle_math::Quat::from_rotation_y(0.3) * jostle_math::Quat::from_rotation_x(0.01);
        let inertia = |scale: f32| {
            let m = Mat3::from_quat(turn);
            m * Mat3::from_diagonal(Vec3::new(6.0, 5.0, 7.0) * scale) * m.transpose()
        };
        let (light_inertia, heavy_inertia) = (inertia(1.0), inertia(1e-6));
        let inv_inertia = |k: u32| match k {
            1 => light_inertia,
            2 => heavy_inertia,
            _ => Mat3::ZERO,
        };
        let up = turn * Vec3::Y;
        let side = turn * Vec3::X;
        let row = |a: u32, b: u32, normal: Vec3, arm_a: Vec3, arm_b: Vec3| Row {
            island: 0,
            order: 0,
            kind: NORMAL,
            batch: 0,
            point: 0,
            lane: 0,
            a,
            b,
            inv_mass_a: Vec3::splat(if a == 2 { 1e-6 } else { 1.0 }),
            inv_mass_b: Vec3::splat(if b == 2 {
                1e-6
            } else if b == 1 {
                1.0
            } else {
                0.0
            }),
            normal,
            rn_a: arm_a.cross(normal),
            rn_b: arm_b.cross(normal),
            floor: 0.0,
        };
        let corner = |x: f32, y: f32, z: f32| turn * Vec3::new(x, y, z) * 0.5;
        let rows = [
            row(1, STATIC_BODY, up, corner(1.0, -1.0, 1.0), Vec3::ZERO),
            row(1, STATIC_BODY, side, corner(-1.0, -1.0, 1.0), Vec3::ZERO),
            row(2, 1, up, corner(1.0, -1.0, -1.0), corner(1.0, 1.0, -1.0)),
            row(
                2,
                1,
                side,
                corner(-1.0, -1.0, -1.0),
                corner(-1.0, 1.0, -1.0),
            ),
        ];
        // J as 12-vectors (light's six, heavy's six), M⁻¹ in f64.
        let wide = |v: Vec3| [f64::from(v.x), f64::from(v.y), f64::from(v.z)];
        let jacobian = |r: &Row| {
            let mut j = [0.0f64; 12];
            for (body, sign, rn) in [(r.a, 1.0, r.rn_a), (r.b, -1.0, r.rn_b)] {
                if body == STATIC_BODY {
                    continue;
                }
                let at = if body == 1 { 0 } else { 6 };
                for i in 0..3 {
                    j[at + i] = sign * wide(r.normal)[i];
                    j[at + 3 + i] = sign * wide(rn)[i];
                }
            }
            j
        };
        let apply_inverse_mass = |j: [f64; 12]| {
            let mut out = [0.0f64; 12];
            for (at, inv_mass, m) in [(0, 1.0f64, light_inertia), (6, 1e-6f64, heavy_inertia)] {
                let cols = [wide(m.x_axis), wide(m.y_axis), wide(m.z_axis)];
                for i in 0..3 {
                    out[at + i] = inv_mass * j[at + i];
                    out[at + 3 + i] = (0..3)
                        .map(|k| 0.5 * (cols[k][i] + cols[i][k]) * j[at + 3 + k])
                        .sum::<f64>();
                }
            }
            out
        };
        for ri in &rows {
            for rj in &rows {
                let (ji, jj) = (jacobian(ri), apply_inverse_mass(jacobian(rj)));
                let reference: f64 = ji.iter().zip(&jj).map(|(a, b)| a * b).sum();
                let (a, b) = (
                    Response::of(ri, &inv_inertia),
                    Response::of(rj, &inv_inertia),
                );
                let k = a.coupling(&b);
                for value in [k, b.coupling(&a)] {
                    assert!(
                        (value - reference).abs() <= 1e-15 * (1.0 + reference.abs()),
                        "{value} {reference}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_non_finite_pivot_is_refused() {
        assert!(factor_dense(&[f64::NAN, 0.0, 0.0, 1.0], 2).is_none());
    }

    #[test]
    fn a_square_face_has_one_saddle_and_three_motions() {
        // A unit cube's bottom face on the ground: four points at (±½, −½, ±½), normal up,
        // 1/m = 1 and I⁻¹ = 6 (a unit cube of 1 kg).
        let inv_inertia = |k: u32| {
            if k == 1 {
                Mat3::from_diagonal(Vec3::splat(6.0))
            } else {
                Mat3::ZERO
            }
        };
        let rows: Vec<Row> = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
            .into_iter()
            .enumerate()
            .map(|(i, (x, z))| Row {
                island: 0,
                order: i as u32,
                kind: NORMAL,
                batch: 0,
                point: i as u32,
                lane: 0,
                a: 1,
                b: STATIC_BODY,
                inv_mass_a: Vec3::ONE,
                inv_mass_b: Vec3::ZERO,
                normal: Vec3::Y,
                rn_a: Vec3::new(x, -0.5, z).cross(Vec3::Y),
                rn_b: Vec3::ZERO,
                floor: 0.0,
            })
            .collect();
        let first = vec![0u32; 4];
        let start: Vec<usize> = (0..4).map(|i| i * (i + 1) / 2).collect();
        let values: Vec<f64> = (0..4)
            .flat_map(|i| (0..=i).map(move |j| (i, j)))
            .map(|(i, j)| {
                Response::of(&rows[i], &inv_inertia).coupling(&Response::of(&rows[j], &inv_inertia))
            })
            .collect();
        let profile = Profile {
            first: &first,
            start: &start,
            values: &values,
        };
        let mut faces = Vec::new();
        find_faces(&rows, profile, &mut faces);
        assert_eq!(faces.len(), 1);
        // The saddle: corners alternately pushed and pulled, (1, −1, 1, −1)/2.
        let saddle = [0.5, -0.5, 0.5, -0.5];
        for i in 0..4 {
            for j in 0..4 {
                let p = faces[0].saddle[i][j];
                assert!((p - saddle[i] * saddle[j]).abs() < 1e-9, "P{i}{j} = {p}");
            }
        }
    }

    #[test]
    fn jacobi_rotations_give_the_eigenpairs() {
        let mut a = [[0.0; MAX_POINTS]; MAX_POINTS];
        let m = [
            [4.0, 1.0, -2.0, 0.5],
            [1.0, 3.0, 0.0, 1.0],
            [-2.0, 0.0, 5.0, -1.0],
            [0.5, 1.0, -1.0, 2.0],
        ];
        a[..4].copy_from_slice(&m);
        let (values, vectors) = symmetric_eigen(a, 4);
        for k in 0..4 {
            for i in 0..4 {
                let av: f64 = (0..4).map(|j| m[i][j] * vectors[j][k]).sum();
                assert!((av - values[k] * vectors[i][k]).abs() < 1e-10, "{k} {i}");
            }
        }
    }

    #[test]
    fn a_factor_with_rows_left_out_solves_the_system_over_the_rest() {
        // A banded SPD system of 12 rows; leaving rows 3, 4 and 9 out must solve the system
        // over the other nine exactly, as a factorisation of those nine would.
        let n = 12;
        let entry = |i: usize, j: usize| -> f64 {
            if i == j {
                5.0 + (i % 4) as f64
            } else if i.abs_diff(j) <= 3 {
                0.7 - 0.1 * (i + j) as f64 / n as f64
            } else {
                0.0
            }
        };
        let profile_of = |rows: &[usize]| {
            let mut f = Factor {
                index: rows.to_vec(),
                ..Factor::default()
            };
            for (k, &ri) in rows.iter().enumerate() {
                f.first.push(0);
                f.start.push(f.matrix.len());
                for &rj in &rows[..=k] {
                    f.matrix.push(entry(ri, rj));
                }
            }
            assert!(profile_factor(&f.first, &f.start, &mut f.matrix));
            f
        };
        let all: Vec<usize> = (0..n).collect();
        let kept: Vec<usize> = all
            .iter()
            .copied()
            .filter(|i| ![3, 4, 9].contains(i))
            .collect();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.61).cos()).collect();
        let mut reference: Vec<f64> = kept.iter().map(|&i| b[i]).collect();
        profile_of(&kept).solve(&mut reference);
        let mut full = profile_of(&all);
        assert!(full.serves(&kept));
        assert_eq!(full.excluded, vec![3, 4, 9]);
        let mut x = b.clone();
        full.solve(&mut x);
        for (k, &i) in kept.iter().enumerate() {
            assert!(
                (x[i] - reference[k]).abs() < 1e-12,
                "row {i}: {} {}",
                x[i],
                reference[k]
            );
        }
        assert!([3, 4, 9].iter().all(|&i| x[i] == 0.0));
        // A row the factor does not hold needs a new factorisation.
        let mut part = profile_of(&kept);
        assert!(!part.serves(&all));
        // Nor does a set as large as the factor's but for MAX_HELD rows, one of them new: the
        // rows left out then outnumber MAX_HELD.
        let wide: Vec<usize> = (0..40).collect();
        let mut shifted: Vec<usize> = (MAX_HELD + 1..40).collect();
        shifted.push(100);
        assert!(!profile_of(&wide).serves(&shifted));
    }

    #[test]
    fn a_banded_profile_solves_as_the_dense_system_does() {
        // A chain of 30 rows, each coupled with the two before it (a column's manifolds each
        // coupled with the ones beside it), with a zero band entry inside the profile.
        let n = 30;
        let mut dense = vec![0.0f64; n * n];
        for i in 0..n {
            for j in i.saturating_sub(2)..=i {
                let v = if i == j {
                    4.0 + (i % 3) as f64
                } else if (i + j) % 7 == 0 {
                    0.0
                } else {
                    -1.0 + 0.1 * j as f64 / n as f64
                };
                dense[i * n + j] = v;
                dense[j * n + i] = v;
            }
        }
        let first: Vec<u32> = (0..n).map(|i| i.saturating_sub(2) as u32).collect();
        let mut start = Vec::new();
        let mut values = Vec::new();
        for i in 0..n {
            start.push(values.len());
            for j in first[i] as usize..=i {
                values.push(dense[i * n + j]);
            }
        }
        let profile = Profile {
            first: &first,
            start: &start,
            values: &values,
        };
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut b = Vec::new();
        profile.times(&x, &mut b);
        for i in 0..n {
            let reference: f64 = (0..n).map(|j| dense[i * n + j] * x[j]).sum();
            assert!(
                (b[i] - reference).abs() < 1e-12,
                "row {i}: {} {reference}",
                b[i]
            );
        }
        assert!(profile_factor(&first, &start, &mut values));
        Profile {
            first: &first,
            start: &start,
            values: &values,
        }
        .substitute(&mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-12, "x{i}: {} {}", b[i], x[i]);
        }
    }
}
