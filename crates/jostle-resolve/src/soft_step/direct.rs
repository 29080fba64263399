//! Direct solve of the contact rows of small islands whose bodies' masses differ widely: a
//! heavy body resting on light ones.
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
//! So for an island of at most [`super::SoftStepSettings::direct_rows`] contact points that
//! holds a contact between two movable bodies whose masses differ by
//! [`super::SoftStepSettings::direct_mass_ratio`] or more:
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
//!    was not positive semi-definite: `Row::coupling`), and a solution is summed per body in
//!    f64 and applied through the same inverse inertia (`Solver::apply`). The system is
//!    factorised
//!    by Cholesky in f64 (rows that depend on others, as the four points of a face do, get no
//!    impulse of their own), once per step and free set, and the result goes to the bodies
//!    and to the accumulated impulses; in the relax pass only if it takes kinetic energy out
//!    (friction fixed on its cone is no projection and can put energy in). The pseudo
//!    velocities of the push-out stay with Gauss-Seidel (solving them directly too measured
//!    worse, same section).
//!
//! Islands of bodies of similar mass keep the plain soft step: there Gauss-Seidel converges,
//! and springs stiffened by their load made tall columns sway by decimetres (same section).
//! The cost is the factorisation, cubic in the island's rows (three per point), and sixteen
//! solves a step: 0.046 ms a step for a pair, 0.14 ms for a light column of five under a box
//! ten times heavier (0.01 ms each without).

use super::batch::{Batches, LANES, ManifoldLanes, NO_SOURCE, PointLanes};
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
    /// A friction row's least compliance ([`FRICTION_REGULARISATION`]); set once the
    /// inverse inertia is known.
    floor: f64,
}

/// A point's normal row.
const NORMAL: u8 = 0;
/// A point's friction row along its first tangent.
const TANGENT_1: u8 = 1;
/// A point's friction row along its second tangent.
const TANGENT_2: u8 = 2;

impl Row {
    /// [`FRICTION_REGULARISATION`] times the smaller of the two bodies' parts of the row's
    /// diagonal of J·M⁻¹·Jᵀ (a fixed body has none): the heavier body's, where the masses
    /// differ, so that its motion still converges at that rate.
    fn friction_floor(&self, inv_inertia: &impl Fn(u32) -> Mat3) -> f64 {
        let part = |one: Row| one.coupling(&one, inv_inertia);
        let sides = [
            (self.a != STATIC_BODY).then(|| {
                part(Row {
                    b: STATIC_BODY,
                    ..*self
                })
            }),
            (self.b != STATIC_BODY).then(|| {
                part(Row {
                    a: STATIC_BODY,
                    ..*self
                })
            }),
        ];
        let smaller = sides.into_iter().flatten().fold(f64::INFINITY, f64::min);
        if smaller.is_finite() {
            f64::from(FRICTION_REGULARISATION) * smaller
        } else {
            0.0
        }
    }

    /// The change of this row's normal velocity per unit impulse on `other`: (J·M⁻¹·Jᵀ)ᵢⱼ,
    /// in f64 from each shared body's inverse mass and world inverse inertia
    /// (`inv_inertia`), so that the island's matrix is a Gram matrix, symmetric and positive
    /// semi-definite to f64's rounding. Built in f32 from the rows' angular responses
    /// I⁻¹·(r × n), whose rounding makes it neither, a 1 kg box under a 10⁶ kg one gave the
    /// matrix an eigenvalue of −1.0·10⁻⁷ beside the heavy box's own, about 10⁻⁶: its
    /// contributions are the size of the f32 rounding of the light box's.
    fn coupling(&self, other: &Row, inv_inertia: &impl Fn(u32) -> Mat3) -> f64 {
        let mine = [(self.a, 1.0, self.rn_a), (self.b, -1.0, self.rn_b)];
        let theirs = [
            (other.a, 1.0, other.rn_a, other.inv_mass_a),
            (other.b, -1.0, other.rn_b, other.inv_mass_b),
        ];
        let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let mut sum = 0.0f64;
        for (body, sign, rn) in mine {
            if body == STATIC_BODY {
                continue;
            }
            for &(other_body, other_sign, other_rn, inv_mass) in &theirs {
                if other_body != body {
                    continue;
                }
                let m = inv_inertia(body);
                let cols = [wide(m.x_axis), wide(m.y_axis), wide(m.z_axis)];
                // I⁻¹ symmetric: (I⁻¹)ᵢⱼ as the mean of its two stored entries.
                let entry = |i: usize, j: usize| 0.5 * (cols[j][i] + cols[i][j]);
                let (u, v) = (wide(rn), wide(other_rn));
                // uᵀ·I⁻¹·v summed so that swapping u and v changes no bit.
                let cross = |i: usize, j: usize| entry(i, j) * (u[i] * v[j] + u[j] * v[i]);
                let angular = entry(0, 0) * (u[0] * v[0])
                    + entry(1, 1) * (u[1] * v[1])
                    + entry(2, 2) * (u[2] * v[2])
                    + cross(0, 1)
                    + cross(0, 2)
                    + cross(1, 2);
                let (n, m) = (wide(self.normal), wide(other.normal));
                let linear = if inv_mass.x == inv_mass.y && inv_mass.y == inv_mass.z {
                    f64::from(inv_mass.x) * dot(n, m)
                } else {
                    // A translation lock: M⁻¹ diagonal.
                    let w = wide(inv_mass);
                    w[0] * n[0] * m[0] + w[1] * n[1] * m[1] + w[2] * n[2] * m[2]
                };
                sum += sign * other_sign * (linear + angular);
            }
        }
        sum
    }
}

/// The islands of one step that are solved directly, and the scratch to solve them.
#[derive(Clone, Debug, Default)]
pub struct DirectIslands {
    /// The rows of every direct island, island by island.
    rows: Vec<Row>,
    /// Each direct island's range in `rows`.
    islands: Vec<(u32, u32)>,
    /// Each island's (J·M⁻¹·Jᵀ)ᵢⱼ over all its rows (row-major), one island after another:
    /// the rows do not change within a step.
    couplings: Vec<f64>,
    /// Each island's last factorisation for each pass kind (biased, relax), reused while its
    /// free rows stay the same: within a step the couplings and the compliances do not change.
    factors: Vec<[Factor; 2]>,
    // Scratch reused from step to step.
    sets: UnionFind,
    row_count: Vec<u32>,
    mixed: Vec<bool>,
    island_of: Vec<u32>,
    /// The world inverse inertia of each body with rows in an island (by body index; zero
    /// elsewhere), as the rows' angular responses were prepared.
    inv_inertia: Vec<Mat3>,
    solver: Solver,
}

/// A Cholesky factor of an island's system over the free rows `index` (empty: none yet).
#[derive(Clone, Debug, Default)]
struct Factor {
    index: Vec<usize>,
    matrix: Vec<f64>,
}

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
    /// The impulses of a solution summed per body ([`Solver::apply`]).
    sums: Vec<BodySum>,
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

    /// Finds this step's direct islands in the packed `batches`: bodies joined by manifolds
    /// between two movable bodies, kept when they have at most `max_rows` normal rows and
    /// some manifold joins two movable bodies whose inverse masses differ by `mass_ratio` or
    /// more. Deterministic: islands and rows in the batches' order. `bodies` are the solver
    /// bodies `states` were loaded from (their world inverse inertia builds the couplings).
    pub fn build(
        &mut self,
        batches: &Batches,
        states: &[BodyState],
        bodies: &[SolverBody],
        max_rows: u32,
        mass_ratio: f32,
    ) {
        self.rows.clear();
        self.islands.clear();
        if max_rows == 0 || batches.manifolds.is_empty() {
            return;
        }
        let movable = |i: u32| i != STATIC_BODY && states[i as usize].inv_mass > 0.0;
        let mixed = |a: u32, b: u32| {
            let (ia, ib) = (states[a as usize].inv_mass, states[b as usize].inv_mass);
            movable(a) && movable(b) && super::masses_apart(ia, ib, mass_ratio)
        };
        // Most scenes have no manifold between bodies of such different masses, and then no
        // island: one pass over the lanes instead of the union-find (1.4% of a 20-row
        // pyramid's step).
        let any_mixed = batches
            .manifolds
            .iter()
            .any(|m| (0..LANES).any(|l| mixed(m.a[l], m.b[l])));
        if !any_mixed {
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
                self.row_count[root as usize] += rows;
                if mixed(m.a[l], m.b[l]) {
                    self.mixed[root as usize] = true;
                }
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
                if !self.mixed[r] || self.row_count[r] > max_rows {
                    continue;
                }
                if self.island_of[r] == NONE {
                    self.island_of[r] = islands;
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
        // Rows island by island, each island's in the batches' order.
        self.rows.sort_unstable_by_key(|r| (r.island, r.order));
        let mut start = 0usize;
        for i in 1..=self.rows.len() {
            if i == self.rows.len() || self.rows[i].island != self.rows[start].island {
                self.islands.push((start as u32, i as u32));
                start = i;
            }
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
        for row in &mut self.rows {
            if row.kind != NORMAL {
                row.floor = row.friction_floor(&inv_inertia);
            }
        }
        for &(start, end) in &self.islands {
            let rows = &self.rows[start as usize..end as usize];
            let (base, n) = (self.couplings.len(), rows.len());
            self.couplings.resize(base + n * n, 0.0);
            let matrix = &mut self.couplings[base..];
            // Symmetric to the bit (`Row::coupling`): the lower triangle, mirrored.
            for (i, a) in rows.iter().enumerate() {
                for (j, b) in rows.iter().enumerate().take(i + 1) {
                    let k = a.coupling(b, &inv_inertia);
                    matrix[i * n + j] = k;
                    matrix[j * n + i] = k;
                }
            }
        }
        self.factors
            .resize_with(self.islands.len(), Default::default);
        for factors in &mut self.factors {
            for factor in factors {
                factor.index.clear();
            }
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
        let mut offset = 0;
        for (island, &(start, end)) in self.islands.iter().enumerate() {
            let rows = &self.rows[start as usize..end as usize];
            let couplings = &self.couplings[offset..offset + rows.len() * rows.len()];
            offset += rows.len() * rows.len();
            let factor = &mut self.factors[island][kind];
            let island = Island {
                rows,
                couplings,
                inv_inertia: &self.inv_inertia,
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
        } = island;
        let relax = matches!(pass, RowPass::Relax { .. });
        self.residual.clear();
        self.impulse.clear();
        self.role.clear();
        self.change.clear();
        for (i, row) in rows.iter().enumerate() {
            let l = row.lane as usize;
            let p = &points[row.point as usize];
            let (residual, impulse, role) = match row.kind {
                NORMAL => {
                    let row = row_residuals(
                        manifolds,
                        points,
                        share(states),
                        row.batch as usize,
                        row.point as usize,
                        pass,
                    )[l];
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
                        r: -row.velocity(states),
                        compliance: self.residual[normal].compliance.max(row.floor as f32),
                    };
                    (state, impulse, role)
                }
            };
            self.residual.push(residual);
            self.impulse.push(impulse);
            self.role.push(role);
            self.change.push(0.0);
        }
        for _ in 0..ACTIVE_SET_ROUNDS {
            if !self.solve_free(couplings, factor) {
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
    fn solve_free(&mut self, couplings: &[f64], factor: &mut Factor) -> bool {
        let all = self.role.len();
        self.index.clear();
        self.index
            .extend((0..all).filter(|&i| self.role[i] == Role::Free));
        let n = self.index.len();
        if n == 0 {
            return self.role.contains(&Role::Fixed);
        }
        if factor.index != self.index {
            factor.index.clone_from(&self.index);
            factor.matrix.clear();
            factor.matrix.resize(n * n, 0.0);
            for (i, &ri) in self.index.iter().enumerate() {
                for (j, &rj) in self.index.iter().enumerate().take(i + 1) {
                    factor.matrix[i * n + j] = couplings[ri * all + rj];
                }
                factor.matrix[i * n + i] += f64::from(self.residual[ri].compliance);
            }
            if !cholesky_factor(&mut factor.matrix, n) {
                factor.index.clear();
                return false;
            }
        }
        self.rhs.clear();
        self.rhs
            .extend(self.index.iter().map(|&ri| f64::from(self.residual[ri].r)));
        for k in (0..all).filter(|&k| self.role[k] == Role::Fixed) {
            for (rhs, &ri) in self.rhs.iter_mut().zip(&self.index) {
                *rhs -= couplings[ri * all + k] * self.change[k];
            }
        }
        cholesky_substitute(&factor.matrix, &mut self.rhs, n);
        for (i, &ri) in self.index.iter().enumerate() {
            self.change[ri] = self.rhs[i];
        }
        true
    }

    /// The change of the bodies' kinetic energy (J) that the solution found would make:
    /// xᵀ·J·v + ½·xᵀ·J·M⁻¹·Jᵀ·x over the rows that change.
    fn energy_change(&self, rows: &[Row], couplings: &[f64], states: &[BodyState]) -> f64 {
        let all = rows.len();
        let mut change = 0.0;
        // A row left out has no change, so the couplings need not skip it.
        debug_assert!((0..all).all(|k| self.role[k] != Role::Out || self.change[k] == 0.0));
        for (i, row) in rows.iter().enumerate() {
            if self.role[i] == Role::Out {
                continue;
            }
            let x = self.change[i];
            let coupled = dot(&couplings[i * all..(i + 1) * all], &self.change);
            change += x * (f64::from(row.velocity(states)) + 0.5 * coupled);
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
                let at = match self.sums.iter().position(|s| s.body == body) {
                    Some(at) => at,
                    None => {
                        self.sums.push(BodySum {
                            body,
                            inv_mass: wide(inv_mass),
                            linear: [0.0; 3],
                            angular: [0.0; 3],
                        });
                        self.sums.len() - 1
                    }
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
            let state = &mut states[sum.body as usize];
            let m = inv_inertia
                .get(sum.body as usize)
                .copied()
                .unwrap_or(Mat3::ZERO);
            let cols = [wide(m.x_axis), wide(m.y_axis), wide(m.z_axis)];
            let l: [f32; 3] = std::array::from_fn(|i| (sum.linear[i] * sum.inv_mass[i]) as f32);
            let a: [f32; 3] = std::array::from_fn(|i| {
                (0..3)
                    .map(|k| 0.5 * (cols[k][i] + cols[i][k]) * sum.angular[k])
                    .sum::<f64>() as f32
            });
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
    couplings: &'a [f64],
    inv_inertia: &'a [Mat3],
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

/// Factorises the symmetric positive semi-definite `a` (n × n, row-major, the lower
/// triangle read) in place as L·Lᵀ, L's diagonal stored as its reciprocals 1/lᵢᵢ (the
/// substitution then multiplies where it would divide). A row whose pivot falls below
/// [`DEPENDENT`] times its diagonal depends on the rows before it (the rows of a face span
/// fewer motions than it has points): its column of L is zero, and [`cholesky_substitute`]
/// gives it no impulse while the others meet it as far as it is consistent with them. False
/// when a pivot is not finite.
fn cholesky_factor(a: &mut [f64], n: usize) -> bool {
    debug_assert!(a.len() >= n * n);
    for j in 0..n {
        let row_j = &mut a[j * n..(j + 1) * n];
        let diagonal = row_j[j];
        let d = diagonal - dot(&row_j[..j], &row_j[..j]);
        if !d.is_finite() {
            return false;
        }
        if !(d > DEPENDENT * diagonal) {
            for i in j..n {
                a[i * n + j] = 0.0;
            }
            continue;
        }
        let inv_d = 1.0 / d.sqrt();
        row_j[j] = inv_d;
        let (upto_j, rest) = a.split_at_mut((j + 1) * n);
        let row_j = &upto_j[j * n..j * n + j];
        for row_i in rest.chunks_exact_mut(n).take(n - j - 1) {
            let s = row_i[j] - dot(&row_i[..j], row_j);
            row_i[j] = s * inv_d;
        }
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

/// Solves L·Lᵀ·x = b in place (`b` becomes x) with the factor of [`cholesky_factor`]; a
/// dependent row's x is 0.
fn cholesky_substitute(l: &[f64], b: &mut [f64], n: usize) {
    for i in 0..n {
        let row = &l[i * n..i * n + i + 1];
        let s = b[i] - dot(&row[..i], &b[..i]);
        b[i] = if row[i] > 0.0 { s * row[i] } else { 0.0 };
    }
    for i in (0..n).rev() {
        let inv_d = l[i * n + i];
        if !(inv_d > 0.0) {
            b[i] = 0.0;
            continue;
        }
        let x = b[i] * inv_d;
        b[i] = x;
        // Lᵀ column by column: subtract this unknown from the rows above it.
        for (k, bk) in b[..i].iter_mut().enumerate() {
            *bk -= l[i * n + k] * x;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dependent_row_gets_no_impulse_and_the_others_meet_it() {
        // Rows along x, y and x + y of one unit mass: J·Jᵀ has rank 2, like the rows of a face.
        let mut a = [1.0, 0.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 2.0];
        assert!(cholesky_factor(&mut a, 3));
        // Targets a motion can meet: the velocity (1, 2) gives 1, 2 and 3.
        let mut b = [1.0, 2.0, 3.0];
        cholesky_substitute(&a, &mut b, 3);
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
        let mut a = [light, -light, -light, light + heavy];
        let x = [3.0, 2.0];
        let mut b = [a[0] * x[0] + a[1] * x[1], a[2] * x[0] + a[3] * x[1]];
        assert!(cholesky_factor(&mut a, 2));
        cholesky_substitute(&a, &mut b, 2);
        assert!(
            (b[0] - x[0]).abs() < 1e-9 && (b[1] - x[1]).abs() < 1e-9,
            "{b:?}"
        );
    }

    #[test]
    fn couplings_are_the_gram_matrix_of_the_rows_in_f64() {
        // A light box between the ground and a 10⁶ times heavier box, turned so that no arm
        // or inertia entry is exact in f32: the couplings must be J·M⁻¹·Jᵀ computed in f64
        // from the rows' f32 data, symmetric to the last bit (the heavy box's part, 10⁻⁶ of the
        // light box's, is lost in f32 rounding otherwise).
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
                let k = ri.coupling(rj, &inv_inertia);
                assert_eq!(k.to_bits(), rj.coupling(ri, &inv_inertia).to_bits());
                assert!(
                    (k - reference).abs() <= 1e-15 * (1.0 + reference.abs()),
                    "{k} {reference}"
                );
            }
        }
    }

    #[test]
    fn a_non_finite_pivot_is_refused() {
        let mut a = [f64::NAN, 0.0, 0.0, 1.0];
        assert!(!cholesky_factor(&mut a, 2));
    }
}
