//! The soft-step resolver: substepped sequential impulses with soft contacts, relax and
//! restitution (Catto, "Solver2D", 2024; the solver of Box2D v3), in 3D.
//!
//! One step of length dt with n substeps of h = dt/n is a linear pipeline:
//! 1. [`prepare`](prepare::prepare_point) every contact once on the step-start poses:
//!    anchors, basis, effective masses, the angular response to unit impulses, softness
//!    (static or dynamic stiffness, from [`Softness::new`] at h), the approach velocity, the
//!    chord term with which friction follows a turning kinematic body's point
//!    ([`batch::PointLanes::chord`]), and the previous step's impulse as the warm start;
//!    contacts with a gap above the speculative margin, or between two immovable bodies, take
//!    no part. The contacts are packed eight
//!    manifolds to a batch of independent bodies ([`batch`]) and every kernel below works on
//!    eight manifolds at once ([`lanes`]). Small islands where a heavy body rests on light
//!    ones, and chains of bodies (columns), are picked out and their springs sized by their
//!    load ([`direct`]).
//! 2. per substep: integrate gravity into velocities;
//!    warm start (apply the accumulated impulses: point by point in the first substep, then
//!    as each body's sum carried from substep to substep, [`integrate::Carried`], except for
//!    bodies touching one [`EXACT_WARM_RATIO`] times heavier or lighter); solve every contact
//!    once with its soft bias (a manifold's normal rows [`SoftStepSettings::normal_sweeps`]
//!    times where a point approached faster than gravity can make it within the step: an
//!    impact),
//!    the separation recomputed from the bodies' motion since the start of the step, the
//!    push-out of deep or unloaded overlap going to pseudo velocities; integrate velocities
//!    (and the pseudo velocities, which are then cleared) into position and rotation deltas,
//!    each body's angular momentum carried through its turn ([`gyroscopic`]);
//!    relax (solve again without bias; each manifold's normal rows as one system,
//!    [`SoftStepSettings::block_relax`]). Friction is solved in the relax pass only, unless
//!    [`SoftStepSettings::friction_in_bias_pass`] is set. After each pass the islands of
//!    [`direct`] are solved exactly ([`direct::DirectIslands::correct`]), where Gauss-Seidel
//!    would need about as many sweeps as their mass ratio, or passes a column's load and lean
//!    on one joint per sweep. With [`PARALLEL_MIN_BATCHES`]
//!    batches or more the preparation of the batches' points and the substeps may run on a
//!    team of threads, with the same result bit for bit ([`team`]), whenever the team's
//!    substeps have measured faster than one thread's (`ThreadChoice`).
//! 3. restitution, skipped when no contact bounces: Newton's law at every point that approached
//!    faster than the threshold, swept to convergence with the rest of the contacts, through
//!    each body's inertia as it has turned since the start of the step
//!    ([`solve::restitution_response`]), leaving alone points that were separating at the start
//!    of the step, and bounded: its change to a body bouncing only off immovable bodies is
//!    scaled back until that body has no more mechanical energy than at the start of the step
//!    (to nothing, where the substeps alone already exceeded it; `bound_bounce_energy`);
//! 4. store the impulses, the remaining penetration and each manifold's next preload
//!    ([`SoftStepSettings::preload_rate`]) in the contacts, the poses and velocities in the
//!    bodies.
//!
//! With [`SoftStepSettings::rigid_contacts`] there is no spring: the biased pass solves each
//! manifold's normal rows rigidly, [`SoftStepSettings::normal_sweeps`] times, then friction,
//! and all overlap beyond [`SoftStepSettings::rigid_slop`] goes to the pseudo velocities at
//! [`SoftStepSettings::push_out_rate`] ([`solve::solve`]); the relax pass sweeps the normal
//! rows as often. A loaded contact then sinks no deeper than the slop, whatever its load.
//!
//! Unlike the Millington resolver there is no position projection: a resting contact's
//! overlap (its spring's compression under its load less its learned preload
//! ([`SoftStepSettings::preload_rate`]), plus [`SoftStepSettings::push_out_slop`] and one
//! substep of gravity) is removed by the soft constraint's bias velocity, which the relax
//! pass then takes back out; deeper overlap, and
//! the overlap of bodies that start overlapping or hit fast, is pushed out by split impulses,
//! pseudo velocities that move the bodies within the substep and are then discarded
//! ([`solve::solve`], [`integrate::integrate_positions`]). So resolving overlap neither makes
//! things bounce nor adds kinetic energy. The contacts are solved simultaneously (in a fixed
//! order, colour by colour, to convergence over the substeps), so a Newton's cradle of
//! touching balls does not give the textbook one-ball-out answer; momentum and energy are
//! still conserved.
//!
//! In: solver bodies and contacts. Out: moved bodies, each contact's impulse and remaining
//! penetration. Depends on `jostle-math` alone.

// `!(x > 0.0)` is deliberate: it is true for NaN, which must take the "do nothing" branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

/// Calls the `#[inline(always)]` generic `$imp::<F>(manifolds, points, args…)` with the lane
/// type the CPU runs best, and returns its result: on x86-64 CPUs with AVX, [`lanes_avx`]'s
/// 256-bit `W8` on the same storage read in place, inside a function compiled for AVX-512VL
/// (its 32 vector registers hold a batch's velocities and a point's data without spills) or for
/// AVX; elsewhere [`lanes::F8`] (two 128-bit halves). The lane operations are the same IEEE
/// operations in every case (no fused multiply-add is introduced), so on x86-64 the results are
/// bit-identical whichever lanes run. Used by the kernels of [`solve`] and by
/// [`prepare::prepare_batches`].
macro_rules! with_best_lanes {
    ($imp:ident($manifolds:expr, $points:expr $(, $arg:ident: $ty:ty)*) -> $ret:ty) => {{
        let manifolds: &mut [$crate::soft_step::batch::ManifoldLanes] = $manifolds;
        let points: &mut [$crate::soft_step::batch::PointLanes] = $points;
        #[cfg(target_arch = "x86_64")]
        {
            use $crate::soft_step::batch::{ManifoldLanes, PointLanes};
            use $crate::soft_step::lanes_avx::{AvxLevel, W8, as_wide, avx_level};
            #[target_feature(enable = "avx512f,avx512vl")]
            fn avx512(
                manifolds: &mut [ManifoldLanes<W8>],
                points: &mut [PointLanes<W8>]
                $(, $arg: $ty)*
            ) -> $ret {
                $imp(manifolds, points $(, $arg)*)
            }
            #[target_feature(enable = "avx")]
            fn avx(
                manifolds: &mut [ManifoldLanes<W8>],
                points: &mut [PointLanes<W8>]
                $(, $arg: $ty)*
            ) -> $ret {
                $imp(manifolds, points $(, $arg)*)
            }
            match avx_level() {
                AvxLevel::Avx512 => {
                    // SAFETY: the CPU has been detected to support the enabled features, and
                    // the `W8` view is only used inside the function compiled for them.
                    let (manifolds, points) = unsafe { as_wide(manifolds, points) };
                    // SAFETY: as above.
                    return unsafe { avx512(manifolds, points $(, $arg)*) };
                }
                AvxLevel::Avx => {
                    // SAFETY: as above, for AVX.
                    let (manifolds, points) = unsafe { as_wide(manifolds, points) };
                    // SAFETY: as above.
                    return unsafe { avx(manifolds, points $(, $arg)*) };
                }
                AvxLevel::None => {}
            }
        }
        $imp::<$crate::soft_step::lanes::F8>(manifolds, points $(, $arg)*)
    }};
}

pub mod batch;
pub mod body_state;
pub mod direct;
pub mod gyroscopic;
pub mod integrate;
pub mod lanes;
#[cfg(target_arch = "x86_64")]
mod lanes_avx;
pub mod prepare;
pub mod settings;
pub mod shared;
pub mod softness;
pub mod solve;
pub mod team;

pub use batch::Batches;
pub use body_state::{BodyState, PseudoRow};
pub use prepare::PrepareParams;
pub use settings::SoftStepSettings;
pub use softness::Softness;

use crate::clock::Stopwatch;
use crate::energy::Inverse64;
use crate::{Contact, ResolveStats, Resolver, STATIC_BODY, SolverBody, StepContext};
use batch::{ManifoldLanes, PointLanes};
use jostle_math::{Mat3, Vec3};
use shared::{Shared, share, share_one, slice_mut};
use std::cell::Cell;
use std::time::Duration;
use team::{Crew, Plan, Solo, Team};

/// The soft-step resolver (see the module docs). Holds its settings and scratch buffers
/// reused from step to step; its only memory between steps that changes a result is the
/// contacts' impulses, which the caller carries, so swapping resolvers mid-simulation is
/// safe (it also keeps the batches' layout while the contacts stay the same, which a fresh
/// packing would give again: [`Batches::arrange`]).
#[derive(Clone, Debug, Default)]
pub struct SoftStepResolver {
    /// The settings used by the next step; change them freely between steps.
    pub settings: SoftStepSettings,
    states: Vec<BodyState>,
    /// Each body's share per substep of its applied forces' velocity change (linear,
    /// angular; [`SolverBody::force_velocity`]); empty when no body has any.
    pushes: Vec<[jostle_math::Vec3; 2]>,
    inertia: Vec<Mat3>,
    /// The f64 inverse of each body's `inertia` (`None` for a zero one), taken once a step for
    /// its turns (`gyroscopic::turn_inverted`).
    inertia_inverse: Vec<Option<Inverse64>>,
    /// Each body's `inertia` as an axisymmetric one where it is (`gyroscopic::Axisymmetric`)
    /// and the body has no contact rows this step: such a body turns exactly.
    axisymmetric: Vec<Option<gyroscopic::Axisymmetric>>,
    /// With the gyroscopic term: each body's step-start world inverse inertia if some contact
    /// of the step involves it, else zero (`gyroscopic::turn_against`).
    rows_inverse: Vec<Mat3>,
    /// With the gyroscopic term: whether some contact of the step joins the body to a body
    /// that can move.
    touches_moving: Vec<bool>,
    /// Scratch of `mark_free`: whether some batch holds the body.
    bound: Vec<bool>,
    /// The prepared contacts packed eight manifolds to a batch for the kernels.
    batches: Batches,
    /// Normal impulses before the restitution pass, restored after it.
    saved_impulse: Vec<lanes::F8>,
    /// Each body's pseudo velocities of the current substep ([`PseudoRow`]).
    pseudo: Vec<PseudoRow>,
    /// Each body's warm start carried between substeps ([`integrate::Carried`]).
    carried: Vec<integrate::Carried>,
    /// [`EXACT_WARM_RATIO`] unless a test sets another (1 keeps every warm start point by
    /// point).
    exact_warm_ratio: Option<f32>,
    /// Each body's velocities before the restitution pass (linear, angular).
    before_restitution: Vec<(jostle_math::Vec3, jostle_math::Vec3)>,
    /// Which bodies bounce in the restitution pass, and against what ([`solve::bounce_marks`]).
    bounce_marks: Vec<u8>,
    /// Each body's world inverse inertia after the substeps, for the restitution pass.
    inv_inertia_now: Vec<Mat3>,
    /// Each point's response in the restitution pass ([`solve::restitution_response`]).
    response: Vec<solve::Response>,
    /// The islands whose contact rows are solved directly this step ([`direct`]).
    direct: direct::DirectIslands,
    /// The threads of the substeps ([`team`]) and the stages they run.
    team: Team,
    plan: Vec<team::Parts>,
    /// The team of the substeps.
    substeps: SubstepsTeam,
    /// Whether the team or one thread runs the substeps faster here ([`ThreadChoice`]).
    choice: ThreadChoice,
}

/// The team of the substeps, whose items wait only for the items they depend on
/// ([`Team::reset_flowing`]), with what its waits were worked out for. A clone starts afresh.
#[derive(Debug, Default)]
struct SubstepsTeam {
    team: Team,
    plan: Vec<team::Parts>,
    /// The plan and the layout (its [`Batches::generation`], the body count) for which the
    /// team's waits were last worked out, and the bodies its items touch.
    flow_plan: Vec<team::Parts>,
    flow_layout: Option<(u64, usize)>,
    touches: team::Touches,
    /// The layout of the last step on the team.
    last_layout: Option<(u64, usize)>,
}

impl Clone for SubstepsTeam {
    fn clone(&self) -> Self {
        Self::default()
    }
}

/// Steps between two trials of the mode not in use ([`ThreadChoice`]).
const PROBE_INTERVAL: u32 = 32;

/// Team runs after a run on one thread that are not counted ([`ThreadChoice`]): the team
/// is still warming up (its helpers woken, each core's part of the states brought back into
/// its cache).
const TEAM_WARMUP: u32 = 2;

/// Counted runs of each mode whose least cost is the mode's cost ([`ThreadChoice`]).
const RECENT_RUNS: usize = 4;

/// Which runs a large step's substeps faster on this machine: the team of threads or the
/// calling thread alone (the choice takes the step's preparation of the points with it,
/// [`SoftStepResolver::prepare_points`]; its clock measures the substeps). Both give the
/// same results bit for bit (`tests/threads.rs` of the `jostle` crate), so the choice is
/// free to follow the clock: each mode's cost per contact
/// point is the least of its last [`RECENT_RUNS`] measured substep times (a run is only ever
/// slowed by what else the machine does, most of all a team whose second core was taken for a
/// while: with a running average instead, a few slow team runs on a busy virtual machine kept
/// the 3D pyramid of 10 layers on one thread for most of its steps, 1.84–1.95 ms a step, where
/// the team takes 1.61–1.62), the cheaper one runs, and every
/// [`PROBE_INTERVAL`] steps the other runs once to keep its figure current (the first run of
/// each is not counted: it starts the helper threads or warms the caches). Nor is a team run
/// that follows a step on one thread, nor the one after it ([`TEAM_WARMUP`]): its helpers had
/// parked and are woken cold (on the 20-row pyramid such probes took 0.87–0.95 ms where the
/// team's next steps take 0.47–0.49 and one thread 0.60–0.66), and the team's second step
/// still cost 1,070–1,300 ns a point where its steady steps cost 730–830 and one thread
/// 960–1,000 (benches/RESULTS.md, "A team judged warm"), so the team is tried for three
/// steps and judged on the third.
/// Measured why: on
/// one two-core virtual machine the team took the 3D pyramid of 10 layers (315 batches) from
/// 2.39 to 1.95 ms per step, on another from 2.29 to 2.7 (benches/RESULTS.md, "Interleaved
/// relax, threads chosen by the clock, and six substeps measured").
#[derive(Clone, Copy, Debug, Default)]
struct ThreadChoice {
    /// The last [`RECENT_RUNS`] counted costs per point (ns) of each mode, one thread and the
    /// team (0: none yet), in a ring.
    recent: [[f64; RECENT_RUNS]; 2],
    /// Runs of each mode so far (saturating).
    runs: [u32; 2],
    /// Steps since the mode not in use last ran.
    since_probe: u32,
    /// Team runs in a row up to the last recorded one (saturating).
    team_streak: u32,
    /// Steps of a trial of the team still to run after this one.
    trial_left: u32,
}

impl ThreadChoice {
    const SOLO: usize = 0;
    const TEAM: usize = 1;

    /// Whether the next step's substeps run on the team.
    fn use_team(&mut self) -> bool {
        match self.cost() {
            [None, _] => false,
            [_, None] => true,
            [Some(solo), Some(team)] => {
                if self.trial_left > 0 {
                    self.trial_left -= 1;
                    return true;
                }
                let best = team < solo;
                self.since_probe += 1;
                if self.since_probe >= PROBE_INTERVAL {
                    self.since_probe = 0;
                    if !best {
                        // A trial of the team: its first steps are not counted (`record`).
                        self.trial_left = TEAM_WARMUP;
                    }
                    !best
                } else {
                    best
                }
            }
        }
    }

    /// Records a run of the substeps: `team` or not, its wall time, over `points` points.
    fn record(&mut self, team: bool, time: Duration, points: usize) {
        let mode = if team { Self::TEAM } else { Self::SOLO };
        self.team_streak = if team {
            self.team_streak.saturating_add(1)
        } else {
            0
        };
        let cold = team && self.team_streak <= TEAM_WARMUP;
        self.runs[mode] = self.runs[mode].saturating_add(1);
        if self.runs[mode] < 2 || points == 0 || cold {
            return;
        }
        let cost = time.as_nanos() as f64 / points as f64;
        self.recent[mode][self.runs[mode] as usize % RECENT_RUNS] = cost;
    }

    /// Each mode's cost per point (ns): the least of its recent runs, `None` before any.
    fn cost(&self) -> [Option<f64>; 2] {
        self.recent.map(|recent| {
            recent
                .into_iter()
                .filter(|&c| c > 0.0)
                .min_by(f64::total_cmp)
        })
    }
}

impl SoftStepResolver {
    /// A resolver with the given settings.
    pub fn new(settings: SoftStepSettings) -> Self {
        Self {
            settings,
            ..Self::default()
        }
    }

    /// The contacts of the last step as packed for the kernels (only those that took part),
    /// with their impulses as the step left them: for diagnostics.
    pub fn batches(&self) -> &Batches {
        &self.batches
    }

    /// Loads the body states and, with the gyroscopic term on, the step-start inertia tensors
    /// (zero for a body whose inertia is the same about every axis: a ball or a cube keeps
    /// L = I·ω with ω itself, and its turns need no term, `gyroscopic::is_isotropic`; zero too
    /// for a body whose moments differ more than f32 world tensors hold,
    /// `gyroscopic::within_f32`).
    fn load_bodies(&mut self, bodies: &[SolverBody], dt: f32) {
        self.states.clear();
        self.states.extend(bodies.iter().map(BodyState::from_body));
        self.pushes.clear();
        let zero = jostle_math::Vec3::ZERO;
        // The acceleration of an immovable body on a curved path
        // (`SolverBody::path_acceleration`).
        let path = |b: &SolverBody| {
            if b.inv_mass == 0.0 {
                b.path_acceleration
            } else {
                zero
            }
        };
        if bodies
            .iter()
            .any(|b| b.force_velocity != zero || b.torque_velocity != zero || path(b) != zero)
        {
            let share = 1.0 / self.settings.substeps.max(1) as f32;
            let h = dt * share;
            self.pushes.extend(bodies.iter().map(|b| {
                [
                    b.force_velocity * b.linear_freedom() * share + path(b) * h,
                    b.torque_velocity * share,
                ]
            }));
            // A body on a curved path starts half a step and half a substep back along its
            // acceleration: each substep's push then brings it to its velocity in the middle
            // of that substep, and over the step it moves by its mean velocity. With the step's
            // mean velocity throughout, a load on a table turning about an axis off the
            // table's centre was held to the table's velocity in the middle of the step, and
            // the table's point turned away from it on either side (benches/RESULTS.md, "A
            // turn about an axis off the table").
            for (state, b) in self.states.iter_mut().zip(bodies) {
                let a = path(b);
                if a != zero {
                    state.linear_velocity -= a * (0.5 * (dt + h));
                }
            }
        }
        self.pseudo.clear();
        self.pseudo.resize(bodies.len(), [0.0; 8]);
        self.carried.clear();
        self.carried
            .resize(bodies.len(), integrate::Carried::default());
        if let Some(s) = self.states.get_mut(STATIC_BODY as usize) {
            *s = BodyState::STATIC;
        }
        self.inertia.clear();
        if self.settings.gyroscopic {
            self.inertia.extend(bodies.iter().map(|b| {
                if b.rotates() && !gyroscopic::is_isotropic(b.inv_inertia) {
                    gyroscopic::inertia_of(b.inv_inertia)
                        .filter(|&i| gyroscopic::within_f32(i, b.inv_inertia))
                        .unwrap_or(Mat3::ZERO)
                } else {
                    Mat3::ZERO
                }
            }));
            if let Some(i) = self.inertia.get_mut(STATIC_BODY as usize) {
                *i = Mat3::ZERO;
            }
        }
        self.inertia_inverse.clear();
        self.inertia_inverse.extend(
            self.inertia
                .iter()
                .map(|&i| (i != Mat3::ZERO).then(|| Inverse64::of(i)).flatten()),
        );
    }

    /// Marks [`body_state::FREE`] the bodies in no batch, not turning and without forces:
    /// their substeps are integrated at once after the others' (`rain_1000`'s bodies in
    /// flight, a dropped lattice before it lands).
    fn mark_free(&mut self) {
        self.bound.clear();
        self.bound.resize(self.states.len(), false);
        for m in &self.batches.manifolds {
            for i in m.a.iter().chain(&m.b) {
                if let Some(b) = self.bound.get_mut(*i as usize) {
                    *b = true;
                }
            }
        }
        for (i, s) in self.states.iter_mut().enumerate().skip(1) {
            let pushed = self
                .pushes
                .get(i)
                .is_some_and(|[v, w]| *v != Vec3::ZERO || *w != Vec3::ZERO);
            if !self.bound[i] && s.angular_velocity == Vec3::ZERO && !pushed {
                s.flags |= body_state::FREE;
            }
        }
    }

    /// Marks [`body_state::EXACT_WARM`] both bodies of every manifold whose masses differ by
    /// [`EXACT_WARM_RATIO`] or more, and the lanes of the batches that hold them
    /// ([`ManifoldLanes::exact_a`]); whether there is any.
    fn mark_exact_warm(&mut self) -> bool {
        let ratio = self.exact_warm_ratio.unwrap_or(EXACT_WARM_RATIO);
        let mut any = false;
        for m in &self.batches.manifolds {
            for (&a, &b) in m.a.iter().zip(&m.b) {
                let (Some(sa), Some(sb)) =
                    (self.states.get(a as usize), self.states.get(b as usize))
                else {
                    continue;
                };
                let (ia, ib) = (sa.inv_mass, sb.inv_mass);
                if a == STATIC_BODY || b == STATIC_BODY || ia <= 0.0 || ib <= 0.0 {
                    continue;
                }
                if masses_apart(ia, ib, ratio) {
                    self.states[a as usize].flags |= body_state::EXACT_WARM;
                    self.states[b as usize].flags |= body_state::EXACT_WARM;
                    any = true;
                }
            }
        }
        if !any {
            return false;
        }
        let exact = |i: u32| {
            i != STATIC_BODY
                && self
                    .states
                    .get(i as usize)
                    .is_some_and(|s| s.flags & body_state::EXACT_WARM != 0)
        };
        for m in &mut self.batches.manifolds {
            let (mut bits_a, mut bits_b) = (0u8, 0u8);
            for lane in 0..batch::LANES {
                bits_a |= u8::from(exact(m.a[lane])) << lane;
                bits_b |= u8::from(exact(m.b[lane])) << lane;
            }
            m.exact_a = bits_a;
            m.exact_b = bits_b;
        }
        true
    }

    /// The energy bound of a body that turned away from its contact rows: a body whose
    /// inertia has turned within the step so far from the step-start inertia its contact rows
    /// use that its turns fell back to ω alone (`gyroscopic::turn_against`), and that touches
    /// only bodies that cannot move, ends the step with no more mechanical energy than it
    /// began with, K_end ≤ K_start + m·g·Δx, measured with its inertia at each end; where it
    /// would have more, its velocities are scaled down to meet the bound.
    ///
    /// Why: neither the rows nor the turn are right for such a body. The rows respond
    /// through an inertia the body no longer has, and ω kept through a turn of the inertia
    /// does not keep the energy ½·ωᵀ·I·ω: a needle spun by its impact on a floor at 50 m/s,
    /// its long axis swinging 7 rad within the step, left the step with 36% more energy than
    /// it came with (benches/RESULTS.md, "CCD: no freeze, no tunnel"). Contacts with what
    /// cannot move can only take energy (e ≤ 1), so the bound is exact physics, and a body
    /// that turns with its inertia (a top about its axis) or slowly never meets it.
    fn bound_turned_energy(&mut self, bodies: &[SolverBody], gravity: jostle_math::Vec3) {
        for (i, rows) in self.rows_inverse.iter().enumerate() {
            if *rows == Mat3::ZERO || self.touches_moving[i] {
                continue;
            }
            let (Some(start), Some(state), Some(&inertia)) =
                (bodies.get(i), self.states.get_mut(i), self.inertia.get(i))
            else {
                continue;
            };
            if !(start.inv_mass > 0.0) || inertia == Mat3::ZERO {
                continue;
            }
            if !gyroscopic::turned_off_rows(inertia, *rows, state.delta_rotation) {
                continue;
            }
            let inertia_now = gyroscopic::rotate_inertia(inertia, state.delta_rotation);
            let mass = 1.0 / start.inv_mass;
            let energy = |v: jostle_math::Vec3, w: jostle_math::Vec3, i: Mat3| {
                0.5 * mass * v.length_squared() + 0.5 * w.dot(i * w)
            };
            let allowed = allowed_energy(start, inertia, state.delta_position, gravity);
            let now = energy(state.linear_velocity, state.angular_velocity, inertia_now);
            if now > allowed {
                let scale = (allowed.max(0.0) / now).sqrt();
                state.linear_velocity *= scale;
                state.angular_velocity *= scale;
            }
        }
    }

    /// The energy bound of the restitution pass: a body that bounced this step only off
    /// bodies that cannot move should end the step with no more mechanical energy than it
    /// began with, K_end ≤ K_start + m·g·Δx (e ≤ 1 returns at most what the impact took, and
    /// the substeps' symplectic integration of gravity alone never exceeds this). Where the
    /// pass gave more, the velocity change it made to that body is scaled back to the largest
    /// fraction that meets the bound, or to nothing where the substeps alone already exceeded
    /// it (the bound limits this pass, not the substeps).
    ///
    /// Why: the pass reflects each point's approach velocity at the start of the step, at the
    /// poses the substeps left. A body that turned a large angle within the step (a 0.1 m
    /// plank at 70 rad/s turns 1.2 rad in a 60 Hz step) meets the floor with other corners, at
    /// other speeds, than the step-start velocities describe, and reflecting those tripled the
    /// plank's energy in one bounce (benches/RESULTS.md, "Restitution 1 never raises a bounce").
    /// Bodies that bounce off other moving bodies are left alone: energy may pass between
    /// them (a Newton's cradle).
    fn bound_bounce_energy(&mut self, bodies: &[SolverBody], gravity: jostle_math::Vec3) {
        for (i, &mark) in self.bounce_marks.iter().enumerate() {
            if mark != solve::BOUNCES_ON_FIXED {
                continue;
            }
            let (Some(start), Some(state), Some(&(v_s, w_s))) = (
                bodies.get(i),
                self.states.get_mut(i),
                self.before_restitution.get(i),
            ) else {
                continue;
            };
            if !(start.inv_mass > 0.0) {
                continue;
            }
            let mass = 1.0 / start.inv_mass;
            let inertia = if start.rotates() {
                gyroscopic::inertia_of(start.inv_inertia).unwrap_or(Mat3::ZERO)
            } else {
                Mat3::ZERO
            };
            let inertia_now = gyroscopic::rotate_inertia(inertia, state.delta_rotation);
            let allowed = allowed_energy(start, inertia, state.delta_position, gravity);
            let (dv, dw) = (state.linear_velocity - v_s, state.angular_velocity - w_s);
            let Some(s) = crate::energy::bounded_fraction(
                mass,
                inertia_now,
                (v_s, w_s),
                (dv, dw),
                allowed,
                0.0,
            ) else {
                continue;
            };
            state.linear_velocity = v_s + dv * s;
            state.angular_velocity = w_s + dw * s;
        }
    }

    /// Packs the contacts into batches ([`Batches::arrange`]); returns the parameters their
    /// points are prepared with ([`SoftStepResolver::prepare_points`]).
    fn arrange_contacts(
        &mut self,
        bodies: &[SolverBody],
        contacts: &[Contact],
        h: f32,
        gravity: jostle_math::Vec3,
    ) -> PrepareParams {
        let s = &self.settings;
        // A spring stiffer than a quarter of the substep rate is not resolved by the substep
        // and turns into jitter; Box2D v3 caps its contact hertz the same way.
        let cap = 0.25 / h;
        let dynamic = Softness::new(s.contact_hertz.min(cap), s.damping_ratio, h);
        let fixed = Softness::new(s.static_hertz.min(cap), s.damping_ratio, h);
        // The stored impulse is the step's (per-substep impulse × substeps); one substep's
        // share is the warm start.
        let warm = if s.warm_start {
            1.0 / s.substeps.max(1) as f32
        } else {
            0.0
        };
        let (fixed, dynamic) = if s.rigid_contacts {
            (Softness::RIGID, Softness::RIGID)
        } else {
            (fixed, dynamic)
        };
        let params = PrepareParams {
            static_softness: fixed,
            dynamic_softness: dynamic,
            warm_scale: warm,
            preload_ramp: if s.preload_target > 0.0 {
                1.0 / s.preload_target
            } else {
                f32::MAX
            },
            preload_bound: if s.preload_rate > 0.0 && !s.rigid_contacts {
                // Finite for any settings, so that padding lanes (zero mass) stay at 0.
                ((s.damping_ratio / PRELOAD_MIN_DAMPING).powi(2) * gravity.length() * h)
                    .min(f32::MAX)
            } else {
                0.0
            },
            step: h * s.substeps.max(1) as f32,
            down: gravity.normalize_or_zero(),
        };
        // The bodies that have contact rows this step (`rows_inverse`), for the gyroscopic
        // term, and which of them touch a body that can move (`touches_moving`), marked in
        // the same pass over the contacts.
        self.rows_inverse.clear();
        self.touches_moving.clear();
        let gyroscopic = s.gyroscopic;
        if gyroscopic {
            self.rows_inverse.resize(bodies.len(), Mat3::ZERO);
            self.touches_moving.resize(bodies.len(), false);
        }
        let (rows_inverse, touches_moving) = (&mut self.rows_inverse, &mut self.touches_moving);
        let moves = |k: u32| bodies.get(k as usize).is_some_and(|b| b.inv_mass > 0.0);
        let mut last = None;
        let mark_rows = |c: &Contact| {
            // A manifold's points come one after another and mark the same two bodies.
            if !gyroscopic || last == Some((c.a, c.b)) {
                return;
            }
            last = Some((c.a, c.b));
            let both = moves(c.a) && moves(c.b);
            for k in [c.a, c.b] {
                if k != STATIC_BODY
                    && let (Some(r), Some(b)) =
                        (rows_inverse.get_mut(k as usize), bodies.get(k as usize))
                {
                    *r = b.inv_inertia;
                    touches_moving[k as usize] |= both;
                }
            }
        };
        self.batches
            .arrange_with(contacts, bodies, s.speculative_margin, &params, mark_rows);
        // Only a body without contact rows turns exactly as an axisymmetric one, so only such
        // a body's inertia is looked at (both lists are empty without the gyroscopic term).
        debug_assert_eq!(self.inertia.len(), self.rows_inverse.len());
        self.axisymmetric.clear();
        self.axisymmetric.extend(
            self.inertia
                .iter()
                .zip(&self.rows_inverse)
                .map(|(&i, &rows)| {
                    (i != Mat3::ZERO && rows == Mat3::ZERO)
                        .then(|| gyroscopic::Axisymmetric::of(i))
                        .flatten()
                }),
        );
        params
    }

    /// Prepares the points of the arranged batches ([`prepare::prepare_batches`]) and, with
    /// the block relax, factors their blocks ([`solve::factor_blocks`]): on the team of
    /// `threads` when there is more than one (each batch by the thread that will solve it,
    /// so its points are in that thread's core's cache; [`Preparation`]), else in order on
    /// this thread. Each batch is prepared and factored on its own: the same result either
    /// way, bit for bit.
    fn prepare_points(
        &mut self,
        contacts: &[Contact],
        bodies: &[SolverBody],
        params: &PrepareParams,
        threads: usize,
    ) {
        let factor = self.settings.block_relax && !self.settings.rigid_contacts;
        if threads <= 1 {
            let b = &mut self.batches;
            prepare::prepare_batches(
                &mut b.manifolds,
                &mut b.points,
                &b.sources,
                contacts,
                bodies,
                params,
            );
            if factor {
                solve::factor_blocks(b);
            }
            return;
        }
        let Batches {
            manifolds,
            points,
            sources,
            groups,
            ..
        } = &mut self.batches;
        let work = Preparation {
            manifolds: share(manifolds),
            points: share(points),
            groups,
            sources,
            contacts,
            bodies,
            params,
            factor,
        };
        run_on_team(&mut self.team, &mut self.plan, threads, &work);
    }
}

/// Work that runs as a fixed sequence of stages on any [`Crew`].
trait Staged: Sync {
    /// The stages, in order, on `crew`.
    fn run(&self, crew: &impl Crew);
}

/// Runs `work` on `team` with `threads` threads: first on a [`Plan`], which learns its
/// stages into `plan`, then on the team reset for them.
fn run_on_team(team: &mut Team, plan: &mut Vec<team::Parts>, threads: usize, work: &impl Staged) {
    learn_plan(plan, threads, |planned| work.run(planned));
    team.reset(threads, plan);
    team::run(team, |member| work.run(member));
}

/// Runs `run` on a [`Plan`] for `threads` threads whose stages it learns into `plan` (its own
/// storage, reused: no allocation once it has grown; a new `Vec` each step made 9 allocations
/// a step on the 20-row pyramid).
fn learn_plan(plan: &mut Vec<team::Parts>, threads: usize, run: impl FnOnce(&Plan)) {
    learn_plan_touching(plan, None, threads, run);
}

/// [`learn_plan`], recording into `touches`, when given, the bodies each item touches
/// ([`team::Crew::stage_on_bodies`]).
fn learn_plan_touching(
    plan: &mut Vec<team::Parts>,
    touches: Option<&mut team::Touches>,
    threads: usize,
    run: impl FnOnce(&Plan),
) {
    let mut stages = std::mem::take(plan);
    stages.clear();
    let mut touches = touches;
    let record = touches.as_mut().map(|t| {
        t.clear();
        std::cell::RefCell::new(std::mem::take(&mut **t))
    });
    let planned = Plan {
        threads,
        stages: std::cell::RefCell::new(stages),
        touches: record,
    };
    run(&planned);
    *plan = planned.stages.into_inner();
    if let (Some(record), Some(t)) = (planned.touches, touches) {
        *t = record.into_inner();
    }
}

/// Batches per item of the team's stage that writes the step's results ([`Results`]).
const RESULTS_CHUNK: usize = 16;

/// The step's results written into its contacts on a team ([`solve::results`]): one stage
/// whose items are runs of [`RESULTS_CHUNK`] batches.
struct Results<'a, W> {
    batches: &'a Batches,
    states: &'a [Shared<BodyState>],
    contacts: &'a [Shared<Contact>],
    stored: bool,
    /// Writes a point's impulse, separation and manifold end into its contact.
    write: &'a W,
}

impl<W: Fn(&mut Contact, jostle_math::Vec3, f32, solve::ManifoldEnd) + Sync> Staged
    for Results<'_, W>
{
    fn run(&self, crew: &impl Crew) {
        let n = self.batches.manifolds.len();
        let items = n.div_ceil(RESULTS_CHUNK) as u32;
        crew.stage(items, |i| {
            let first = i as usize * RESULTS_CHUNK;
            let range = first..(first + RESULTS_CHUNK).min(n);
            solve::results_range(
                self.batches,
                self.states,
                self.stored,
                range,
                |source, impulse, separation, manifold| {
                    if let Some(c) = self.contacts.get(source as usize) {
                        // SAFETY: every contact is the source of one lane of one point of
                        // one batch ([`Batches::sources`]), and each batch is in one item.
                        (self.write)(unsafe { c.get_mut() }, impulse, separation, manifold);
                    }
                },
            );
        });
    }
}

/// The preparation of a step's batches on a team ([`SoftStepResolver::prepare_points`]):
/// each batch's points prepared from its contacts and, with `factor`, its block factored; one
/// stage per group of batches, split among the threads as the substeps' stages are.
struct Preparation<'a> {
    manifolds: &'a [Shared<ManifoldLanes>],
    points: &'a [Shared<PointLanes>],
    /// [`Batches::groups`].
    groups: &'a [u32],
    /// [`Batches::sources`].
    sources: &'a [[u32; batch::LANES]],
    contacts: &'a [Contact],
    bodies: &'a [SolverBody],
    params: &'a PrepareParams,
    factor: bool,
}

impl Staged for Preparation<'_> {
    /// The preparation, stage by stage on `crew`.
    fn run(&self, crew: &impl Crew) {
        let (manifolds, points) = (self.manifolds, self.points);
        each_batch_range(
            crew,
            manifolds,
            points,
            self.groups,
            TEAM_BATCH_CHUNK,
            |m, p, base| {
                prepare::prepare_batch_range(
                    m,
                    p,
                    base,
                    self.sources,
                    self.contacts,
                    self.bodies,
                    self.params,
                );
                if self.factor {
                    solve::factor_block_range(m, p, base);
                }
            },
        );
    }
}

/// The least damping ratio the preload leaves the load riding on a point's spring
/// ([`prepare::prepare_point`]; the bound is [`PrepareParams::preload_bound`]). Measured on a
/// box under one 1,000 times heavier (the stability family's 1:1,000 pair, 60 s): at 0.25 it
/// settles with 60 mm of sink (86 mm without preload), at 0.18 with 28 mm and 0.6 J left, at
/// 0.125 it keeps a kilojoule of oscillation; unbounded, it falls at 22 s.
pub const PRELOAD_MIN_DAMPING: f32 = 0.25;

/// A manifold counts as at rest for its preload ([`preload_update`]) while none of its points
/// moves more than this fraction of [`SoftStepSettings::preload_target`] per step.
const PRELOAD_REST: f32 = 0.1;

/// A manifold's preload is held while its mean overlap lies between `target` and this
/// fraction of `target` below it ([`preload_update`]).
///
/// Integrated every step, the preload follows the noise of its manifold's overlap around the
/// target for as long as the manifold rests, and a box resting on two supports then gets two
/// preloads that wander apart: integral action on the pile's slow lateral modes. Measured on
/// the 60-row pyramid over 60 s (`FAMILY_SECONDS=60`, the exact start and four perturbed ones):
/// integrated every step it creeps 9.4–11.9 mm, steadily; held in this band 3.7–8.2 mm (and
/// 7.5 and 10.2 mm from the family's two seeded starts); with no preload at all 2.9–4.9 mm,
/// but sinking 1.03–1.12 mm per layer. A band on both sides of
/// the target (±0.5 × `target`) stopped the creep as well (3.7–5.1 mm) but let the springs rest
/// up to half a target deeper, softer under load: the 60-box column swayed 16.4 mm in 20 s
/// instead of 8.5 (benches/RESULTS.md, "The preload held at rest").
const PRELOAD_HOLD: f32 = 0.5;

/// The next preload of a manifold's points ([`SoftStepSettings::preload_rate`]).
///
/// While the manifold carries a load and is at rest (no point closing or opening faster than
/// [`PRELOAD_REST`] × `target` per step at the start of the step), `rate` times its mean
/// overlap beyond `target` at the end of the step is added to its mean preload, never below 0,
/// unless that overlap is within [`PRELOAD_HOLD`] × `target` below `target`: there, as while
/// it moves, the preload is held. Never above the static compression of its springs under
/// its load (`compression`), so the preload never asks more of a spring than its load does.
/// Unloaded, or with the rate 0, the preload is 0.
///
/// One value for the whole manifold: a preload that differed between the points of a face
/// would act on its tilt, and integral action on a tall column's slow sway destabilises it (a
/// 20-box column fell with a preload per point even at a rate of 0.01). Held while moving:
/// integrated through the bounces of a heavy box landing on a light one, the preload grows
/// with overlaps that are not its load (a 1:1,000 pair fell at a rate of 0.02).
fn preload_update(manifold: solve::ManifoldEnd, rate: f32, target: f32, dt: f32) -> f32 {
    if !(rate > 0.0 && manifold.normal_impulse > 0.0) {
        return 0.0;
    }
    let error = manifold.penetration - target;
    let held = error <= 0.0 && error >= -PRELOAD_HOLD * target;
    let preload = if manifold.speed * dt > PRELOAD_REST * target || held {
        manifold.preload
    } else {
        manifold.preload + rate * error
    };
    preload.min(manifold.compression).max(0.0)
}

/// Fewest batches for which a step's substeps may run on more than one thread: below, the
/// stages are too short for the threads' hand-overs to pay. From there the clock decides
/// (`ThreadChoice`). Measured on two cores with planar pyramids of 12 to 28 rows (29 to 149
/// batches), the best of five runs at two threads against one: the same time at 29–50
/// batches, a fifth less from 77 (the 20-row pyramid) on (benches/RESULTS.md, "The team from
/// 32 batches"; it was 128 while the team's stages cost more).
pub const PARALLEL_MIN_BATCHES: usize = 32;

/// The largest ratio of two touching dynamic bodies' masses whose contacts the soft step
/// holds ([`Resolver::max_mass_ratio`]): 10⁶, a 1 kg box under 1,000 t (the `jostle` crate's
/// tests/stress.rs). Beyond it the impulse that holds the heavy body is so much larger than
/// what the light body's own motion needs that f32 rounds away what holds the light one: a
/// 1 kg box under 10⁷ kg or more is pressed 0.17–0.95 m into its neighbour, or thrown out.
/// (The Millington resolver's shock sweep holds such a box: 0.3–0.4 mm up to 10¹².)
pub const MAX_MASS_RATIO: f32 = 1.0e6;

/// Gravity (m/s², standard gravity) up to which [`SoftStepSettings::max_push_out`] is the
/// push-out speed as set; beyond it the speed grows in proportion to |g| ([`push_out_speed`]).
pub const PUSH_OUT_GRAVITY: f32 = 9.81;

/// The push-out speed (m/s) of a step under gravity of magnitude `gravity` (m/s²):
/// `max_push_out` up to [`PUSH_OUT_GRAVITY`], `max_push_out`·|g|/[`PUSH_OUT_GRAVITY`] beyond.
///
/// The bias that holds a resting contact against its load grows with gravity (a unit box on
/// the ground needs about 0.041·|g|·h of it at the default substeps: 8.6 m/s at 10⁵ m/s²),
/// and the push-out cap bounds it too: at a fixed 3 m/s such a box sank 38 m in 10 s under
/// 10⁵ m/s². Scaled, a contact carries the same number of boxes' weight under any gravity
/// as under Earth's. Capping only the push beyond the load instead held the box but let a box
/// crushed between two closing kinematic walls ratchet its load up and leave at 31 m/s.
pub fn push_out_speed(max_push_out: f32, gravity: f32) -> f32 {
    if gravity > PUSH_OUT_GRAVITY {
        max_push_out * (gravity / PUSH_OUT_GRAVITY)
    } else {
        max_push_out
    }
}

/// Mass ratio of a manifold's two movable bodies from which both keep their warm start
/// point by point in every substep ([`body_state::EXACT_WARM`]) instead of carrying it
/// ([`integrate::Carried`]). At 1:100 the light body's velocity swings by about 100·|g|·h
/// (2 m/s at the default substep) within a pass, whose rounding (2·10⁻⁷ m/s) is far below
/// anything the contacts resolve; carried at 1:10⁶ it pushed a 0.1 m box under its heavy load
/// 6 mm into the floor within 13 steps (`tests/stress.rs` of the `jostle` crate).
pub const EXACT_WARM_RATIO: f32 = 100.0;

/// Whether two movable bodies' inverse masses (both > 0) differ by `ratio` or more.
fn masses_apart(inv_mass_a: f32, inv_mass_b: f32, ratio: f32) -> bool {
    inv_mass_a.max(inv_mass_b) >= ratio * inv_mass_a.min(inv_mass_b)
}

/// Batches per item of a team's stage ([`team`]).
const TEAM_BATCH_CHUNK: u32 = 2;

/// Bodies per item of a team's integration stages.
const TEAM_BODY_CHUNK: u32 = 16;

/// Wall time per kind of stage, as one thread saw it: integration, the biased pass (with
/// the warm start and its direct solve), the relax pass (with its direct solve).
#[derive(Default)]
struct Timing([Cell<Duration>; 3]);

impl Timing {
    const INTEGRATE: usize = 0;
    const SOLVE: usize = 1;
    const RELAX: usize = 2;

    /// Runs `f`, adding its wall time to `kind`.
    fn time(&self, kind: usize, f: impl FnOnce()) {
        let t = Stopwatch::start();
        f();
        let cell = &self.0[kind];
        cell.set(cell.get() + t.elapsed());
    }

    fn get(&self) -> [Duration; 3] {
        [self.0[0].get(), self.0[1].get(), self.0[2].get()]
    }
}

/// Everything the substeps of one step read and write, shared by the threads that run them
/// ([`team`]); every access to a shared element follows the contract of [`shared`]: within a
/// stage, items write disjoint batches and bodies.
struct Substeps<'a> {
    manifolds: &'a [Shared<ManifoldLanes>],
    points: &'a [Shared<PointLanes>],
    /// [`Batches::groups`].
    groups: &'a [u32],
    states: &'a [Shared<BodyState>],
    pseudo: &'a [Shared<PseudoRow>],
    /// [`SoftStepResolver::carried`].
    carried: &'a [Shared<integrate::Carried>],
    /// Whether some body keeps its warm start point by point ([`body_state::EXACT_WARM`]).
    exact_warm: bool,
    /// [`SoftStepResolver::pushes`].
    pushes: &'a [[Vec3; 2]],
    inertia: &'a [Mat3],
    /// [`SoftStepResolver::inertia_inverse`].
    inertia_inverse: &'a [Option<Inverse64>],
    /// [`SoftStepResolver::axisymmetric`].
    axisymmetric: &'a [Option<gyroscopic::Axisymmetric>],
    /// [`SoftStepResolver::rows_inverse`].
    rows_inverse: &'a [Mat3],
    gyroscopic: bool,
    direct: &'a Shared<direct::DirectIslands>,
    direct_live: bool,
    gravity: Vec3,
    h: f32,
    inv_h: f32,
    substeps: u32,
    relax_iterations: u32,
    pass: solve::BiasedPass,
    sweeps: u32,
    /// [`SoftStepSettings::block_relax`] (soft contacts only).
    block_relax: bool,
    /// Batches per stage item (`u32::MAX`: a whole group).
    batch_chunk: u32,
    /// Bodies per stage item (`u32::MAX`: all).
    body_chunk: u32,
}

impl Substeps<'_> {
    /// The substeps, stage by stage on `crew`.
    fn run(&self, crew: &impl Crew, timing: &Timing) {
        for substep in 0..self.substeps {
            // The middle of this substep, from the start of the step.
            let chord_time = (substep as f32 + 0.5) / self.inv_h;
            // After the first substep the relax pass has stored every point's separation at
            // the poses the biased pass starts from.
            let pass = solve::BiasedPass {
                stored_separation: substep > 0 && self.relax_iterations > 0 && !self.pass.rigid,
                after_warm_start: substep == 0,
                chord_time,
                ..self.pass
            };
            timing.time(Timing::INTEGRATE, || {
                self.each_body_range(crew, |states, first| {
                    // SAFETY: the body ranges of a stage are disjoint (as for `states`).
                    let carried = unsafe { slice_mut(self.carried, first..first + states.len()) };
                    if substep > 0 {
                        // What the last relax pass changed.
                        integrate::collect(states, carried);
                    }
                    let pushes = self
                        .pushes
                        .get(first..first + states.len())
                        .unwrap_or_default();
                    integrate::integrate_velocities(states, pushes, self.gravity, self.h);
                    if substep > 0 {
                        integrate::apply_carried(states, carried);
                    }
                    integrate::mark(states, carried);
                });
            });
            timing.time(Timing::SOLVE, || {
                if substep == 0 {
                    self.each_batch_range(crew, |m, p, base| {
                        solve::warm_start_range(m, p, base, self.states);
                    });
                    self.each_body_range(crew, |states, first| {
                        // SAFETY: as above.
                        let carried =
                            unsafe { slice_mut(self.carried, first..first + states.len()) };
                        integrate::start_carrying(states, carried);
                    });
                    // The warm start is the last step's impulses on this step's contacts: where
                    // a light body lies between heavy ones, an error ε in that guess is a
                    // velocity of ε·M/m (a landing cascade threw 1 kg boxes under 10,000 kg at
                    // 90–190 m/s, more than the biased pass could take back). The direct solve
                    // corrects the guess before Gauss-Seidel starts from it.
                    self.direct_correct(crew, solve::RowPass::Biased(pass));
                } else if self.exact_warm {
                    self.each_batch_range(crew, |m, p, base| {
                        solve::warm_start_exact_range(m, p, base, self.states);
                    });
                }
                self.each_batch_range(crew, |m, p, base| {
                    solve::solve_range(m, p, base, self.states, self.pseudo, pass);
                });
                self.direct_correct(crew, solve::RowPass::Biased(pass));
            });
            timing.time(Timing::INTEGRATE, || {
                self.each_body_range(crew, |states, first| {
                    // SAFETY: the body ranges of a stage are disjoint (as for `states`).
                    let pseudo = unsafe { slice_mut(self.pseudo, first..first + states.len()) };
                    let range = first..first + states.len();
                    // SAFETY: as for `pseudo`.
                    let carried = unsafe { slice_mut(self.carried, range.clone()) };
                    // What the biased pass changed.
                    integrate::collect(states, carried);
                    let gyro = self.gyroscopic.then(|| integrate::Gyro {
                        inertia: &self.inertia[range.clone()],
                        inverse: &self.inertia_inverse[range.clone()],
                        axisymmetric: &self.axisymmetric[range.clone()],
                        rows_inverse: &self.rows_inverse[range.clone()],
                    });
                    integrate::integrate_positions(states, pseudo, gyro, self.h);
                    integrate::mark(states, carried);
                });
            });
            timing.time(Timing::RELAX, || {
                for _ in 0..self.relax_iterations {
                    self.each_batch_range(crew, |m, p, base| {
                        solve::relax_range(
                            m,
                            p,
                            base,
                            self.states,
                            solve::RelaxPass {
                                inv_h: self.inv_h,
                                chord_time,
                                sweeps: self.sweeps,
                                block: self.block_relax,
                            },
                        );
                    });
                    self.direct_correct(
                        crew,
                        solve::RowPass::Relax {
                            inv_h: self.inv_h,
                            chord_time,
                        },
                    );
                }
            });
        }
    }

    /// [`each_batch_range`] over the substeps' batches.
    fn each_batch_range(
        &self,
        crew: &impl Crew,
        f: impl Fn(&mut [ManifoldLanes], &mut [PointLanes], u32),
    ) {
        each_batch_range(
            crew,
            self.manifolds,
            self.points,
            self.groups,
            self.batch_chunk,
            f,
        );
    }

    /// One stage over the bodies (the static entry left out), each item `f(states, first)`
    /// on a run of body states, `first` the index of the run's first.
    fn each_body_range(&self, crew: &impl Crew, f: impl Fn(&mut [BodyState], usize)) {
        let start = (STATIC_BODY as usize + 1).min(self.states.len()) as u32;
        let end = self.states.len() as u32;
        let items = (end - start).div_ceil(self.body_chunk);
        let chunk = self.body_chunk;
        let touches = |i: u32, push: &mut dyn FnMut(u32)| {
            let first = start + i * chunk;
            (first..first.saturating_add(chunk).min(end)).for_each(&mut *push);
        };
        crew.stage_on_bodies(items, touches, |i| {
            let first = start + i * self.body_chunk;
            let last = first.saturating_add(self.body_chunk).min(end);
            // SAFETY: the items of a stage are disjoint runs of bodies.
            let states = unsafe { slice_mut(self.states, first as usize..last as usize) };
            f(states, first as usize);
        });
    }

    /// The direct solve ([`direct`]) after a pass, as a stage of one item.
    fn direct_correct(&self, crew: &impl Crew, pass: solve::RowPass) {
        if !self.direct_live {
            return;
        }
        crew.stage(1, |_| {
            // SAFETY: a stage of one item: no other thread touches anything meanwhile.
            let (direct, manifolds, points, states) = unsafe {
                (
                    self.direct.get_mut(),
                    slice_mut(self.manifolds, 0..self.manifolds.len()),
                    slice_mut(self.points, 0..self.points.len()),
                    slice_mut(self.states, 0..self.states.len()),
                )
            };
            direct.correct(manifolds, points, states, pass);
        });
    }
}

/// One stage per group of batches ([`Batches::groups`]), each item `f(manifolds, points,
/// base)` on a run of at most `chunk` of the group's batches, their points and the index of
/// the first.
fn each_batch_range(
    crew: &impl Crew,
    manifolds: &[Shared<ManifoldLanes>],
    points: &[Shared<PointLanes>],
    groups: &[u32],
    chunk: u32,
    f: impl Fn(&mut [ManifoldLanes], &mut [PointLanes], u32),
) {
    for group in groups.windows(2) {
        let (start, end) = (group[0], group[1]);
        let items = (end - start).div_ceil(chunk);
        let touches = |i: u32, push: &mut dyn FnMut(u32)| {
            let first = start + i * chunk;
            let last = first.saturating_add(chunk).min(end);
            for m in &manifolds[first as usize..last as usize] {
                // SAFETY: asked while the stages are planned, when nothing writes batches.
                let m = unsafe { m.get() };
                for body in m.a.iter().chain(&m.b) {
                    if *body != STATIC_BODY {
                        push(*body);
                    }
                }
            }
        };
        crew.stage_on_bodies(items, touches, |i| {
            let first = start + i * chunk;
            let last = first.saturating_add(chunk).min(end);
            // SAFETY: the items of a stage are disjoint runs of one group's batches, whose
            // points are disjoint too; the batches of a group write disjoint bodies.
            let manifolds = unsafe { slice_mut(manifolds, first as usize..last as usize) };
            let (Some(m0), Some(m1)) = (manifolds.first(), manifolds.last()) else {
                return;
            };
            let (p0, p1) = (m0.first, m1.first + m1.count);
            // SAFETY: as above.
            let points = unsafe { slice_mut(points, p0 as usize..p1 as usize) };
            f(manifolds, points, p0);
        });
    }
}

/// The mechanical energy a body of step-start state `start` (world inertia `inertia`) may end
/// the step with when only immovable bodies touched it: its kinetic energy at the start, with
/// the step's applied forces' velocity change ([`SolverBody::force_velocity`]) added, plus
/// what gravity did over its displacement `moved`.
fn allowed_energy(
    start: &SolverBody,
    inertia: Mat3,
    moved: jostle_math::Vec3,
    gravity: jostle_math::Vec3,
) -> f32 {
    let mass = 1.0 / start.inv_mass;
    let free = start.linear_freedom();
    let (v, w) = (
        start.linear_velocity + start.force_velocity * free,
        start.angular_velocity + start.torque_velocity,
    );
    0.5 * mass * v.length_squared() + 0.5 * w.dot(inertia * w) + mass * (gravity * free).dot(moved)
}

impl Resolver for SoftStepResolver {
    fn name(&self) -> &'static str {
        "soft-step"
    }

    /// [`MAX_MASS_RATIO`].
    fn max_mass_ratio(&self) -> Option<f32> {
        Some(MAX_MASS_RATIO)
    }

    /// The pipeline of the module docs. Each contact's `impulse` is overwritten with the
    /// impulse of the step in contact space on A, taken as the final per-substep accumulated
    /// impulse × substeps (≈ force·dt, the same meaning as the Millington resolver's, so the
    /// warm start survives a change of substep count or resolver); `penetration` with the
    /// overlap left at the end of the step. Contacts that took no part get a zero impulse.
    fn step(
        &mut self,
        bodies: &mut [SolverBody],
        contacts: &mut [Contact],
        ctx: &StepContext,
    ) -> ResolveStats {
        let mut stats = ResolveStats::default();
        let substeps = self.settings.substeps.max(1);
        let h = ctx.dt / substeps as f32;
        let inv_h = if h > 0.0 { 1.0 / h } else { 0.0 };

        let start = Stopwatch::start();
        self.load_bodies(bodies, ctx.dt);
        let params = self.arrange_contacts(bodies, contacts, h, ctx.gravity);
        let any_restitution = self.batches.any_restitution;
        self.mark_free();
        let exact_warm = self.mark_exact_warm();
        let threads = if self.batches.manifolds.len() >= PARALLEL_MIN_BATCHES {
            team::available_threads()
        } else {
            1
        };
        let threads = if threads > 1 && self.choice.use_team() {
            threads
        } else {
            1
        };
        self.prepare_points(contacts, bodies, &params, threads);
        // Rigid contacts have their own push-out and no spring to size: no direct solve.
        let direct_rows = if self.settings.rigid_contacts {
            0
        } else {
            self.settings.direct_rows
        };
        // A chain is solved directly when its load cannot go down it within the step's
        // sweeps (one joint per sweep).
        let sweeps = substeps.saturating_mul(1 + self.settings.relax_iterations);
        self.direct.build(
            &self.batches,
            &self.states,
            bodies,
            direct::Limits {
                max_rows: direct_rows,
                mass_ratio: self.settings.direct_mass_ratio,
                min_chain: sweeps,
            },
        );
        self.direct.mark(&mut self.batches);
        self.direct
            .stiffen(&mut self.batches, ctx.gravity.length() * h);
        stats.direct_rows = u32::try_from(self.direct.rows()).unwrap_or(u32::MAX);
        stats.prepare_time = start.elapsed();

        let push_out = push_out_speed(self.settings.max_push_out, ctx.gravity.length());
        let rigid = self.settings.rigid_contacts;
        // The relax pass sweeps a manifold's normal rows several times with rigid contacts
        // only; the biased pass also sweeps them at an impact (`solve::BiasedPass::sweeps`).
        let normal_sweeps = self.settings.normal_sweeps.max(1);
        let sweeps = if rigid { normal_sweeps } else { 1 };
        let pass = solve::BiasedPass {
            inv_h,
            max_push_out: push_out,
            slop: if rigid {
                self.settings.rigid_slop
            } else {
                self.settings.push_out_slop
            },
            resting_speed: self.settings.restitution_threshold,
            gravity_speed: ctx.gravity.length() * h,
            impact_speed: ctx.gravity.length() * ctx.dt,
            friction: self.settings.friction_in_bias_pass
                || self.settings.relax_iterations == 0
                || rigid,
            rigid,
            sweeps: normal_sweeps,
            rate: self.settings.push_out_rate * inv_h,
            stored_separation: false,
            after_warm_start: false,
            // Each substep's own (`Substeps::run`).
            chord_time: 0.0,
        };
        let substeps_start = Stopwatch::start();
        let direct_live = !self.direct.is_empty();
        let (generation, body_count) = (self.batches.generation(), self.states.len());
        let times = {
            let Batches {
                manifolds,
                points,
                groups,
                ..
            } = &mut self.batches;
            let work = Substeps {
                manifolds: share(manifolds),
                points: share(points),
                groups,
                states: share(&mut self.states),
                pseudo: share(&mut self.pseudo),
                carried: share(&mut self.carried),
                exact_warm,
                pushes: &self.pushes,
                inertia: &self.inertia,
                inertia_inverse: &self.inertia_inverse,
                axisymmetric: &self.axisymmetric,
                rows_inverse: &self.rows_inverse,
                gyroscopic: self.settings.gyroscopic,
                direct: share_one(&mut self.direct),
                direct_live,
                gravity: ctx.gravity,
                h,
                inv_h,
                substeps,
                relax_iterations: self.settings.relax_iterations,
                pass,
                sweeps,
                block_relax: self.settings.block_relax && !rigid,
                batch_chunk: if threads > 1 {
                    TEAM_BATCH_CHUNK
                } else {
                    u32::MAX
                },
                body_chunk: if threads > 1 {
                    TEAM_BODY_CHUNK
                } else {
                    u32::MAX
                },
            };
            if threads > 1 {
                let team = &mut self.substeps;
                learn_plan(&mut team.plan, threads, |plan| {
                    work.run(plan, &Timing::default());
                });
                // The waits between items depend on the stages and on the bodies each item
                // touches: worked out when a layout is kept a second step (contacts that
                // change every step pay no more than before), and kept with it.
                let layout = (generation, body_count);
                if team.flow_layout == Some(layout) && team.flow_plan == team.plan {
                    team.team.reset_flowing(threads, &team.plan, None);
                } else if team.last_layout == Some(layout) {
                    learn_plan_touching(&mut team.plan, Some(&mut team.touches), threads, |plan| {
                        work.run(plan, &Timing::default());
                    });
                    team.team
                        .reset_flowing(threads, &team.plan, Some(&team.touches));
                    team.flow_plan.clone_from(&team.plan);
                    team.flow_layout = Some(layout);
                } else {
                    team.team.reset(threads, &team.plan);
                }
                team.last_layout = Some(layout);
                // The first thread's times: each stage's wall time, waits included (in a
                // flow, a stage's waits fall in the later stages whose items wait).
                let times = std::sync::Mutex::new([Duration::ZERO; 3]);
                team::run(&self.substeps.team, |member| {
                    let timing = Timing::default();
                    work.run(member, &timing);
                    if member.id() == 0
                        && let Ok(mut t) = times.lock()
                    {
                        *t = timing.get();
                    }
                });
                times.into_inner().unwrap_or_default()
            } else {
                let timing = Timing::default();
                work.run(&Solo, &timing);
                timing.get()
            }
        };
        if self.batches.manifolds.len() >= PARALLEL_MIN_BATCHES && team::available_threads() > 1 {
            let points = self.batches.points.len();
            self.choice
                .record(threads > 1, substeps_start.elapsed(), points);
        }
        integrate::integrate_free(&mut self.states, ctx.gravity, h, substeps);
        let [integrate_time, solve_time, mut relax_time] = times;
        stats.threads = threads as u32;
        let t = Stopwatch::start();
        let threshold = self.settings.restitution_threshold;
        if any_restitution && solve::any_bounces(&self.batches, threshold) {
            // The bounce is an impulse of this step only: what the next step warm starts
            // from is the substeps' impulse, not the impact's (carried over, the impact
            // passed through a row of touching bodies is re-applied next step as a push).
            self.saved_impulse.clear();
            self.saved_impulse
                .extend(self.batches.points.iter().map(|p| p.normal_impulse));
            self.before_restitution.clear();
            self.before_restitution.extend(
                self.states
                    .iter()
                    .map(|s| (s.linear_velocity, s.angular_velocity)),
            );
            solve::bounce_marks(
                &self.batches,
                threshold,
                self.states.len(),
                &mut self.bounce_marks,
            );
            self.inv_inertia_now.clear();
            self.inv_inertia_now
                .extend(bodies.iter().zip(&self.states).map(|(b, s)| {
                    if b.rotates() {
                        gyroscopic::rotate_inertia(b.inv_inertia, s.delta_rotation)
                    } else {
                        Mat3::ZERO
                    }
                }));
            solve::restitution_response(&self.batches, &self.inv_inertia_now, &mut self.response);
            for _ in 0..self.settings.restitution_iterations {
                let correction = solve::restitution(
                    &mut self.batches,
                    &mut self.states,
                    &self.response,
                    threshold,
                    inv_h,
                );
                if !(correction > SoftStepSettings::RESTITUTION_TOLERANCE) {
                    break;
                }
            }
            self.bound_bounce_energy(bodies, ctx.gravity);
            for (p, &saved) in self.batches.points.iter_mut().zip(&self.saved_impulse) {
                p.normal_impulse = saved;
            }
        }
        if self.settings.gyroscopic {
            self.bound_turned_energy(bodies, ctx.gravity);
        }
        relax_time += t.elapsed();

        let t = Stopwatch::start();
        // Contacts that took no part get a zero impulse; every other gets its own below (when
        // all took part, as usually, the contacts are not walked an extra time).
        if self.batches.contacts as usize != contacts.len() {
            for c in contacts.iter_mut() {
                c.impulse = jostle_math::Vec3::ZERO;
            }
        }
        let (rate, target) = (self.settings.preload_rate, self.settings.preload_target);
        // The relax pass of the last substep stored every point's separation at the poses
        // the step ends with (nothing after it moves a body that has contacts).
        let stored = substeps > 0 && self.settings.relax_iterations > 0;
        let write = |c: &mut Contact, impulse: jostle_math::Vec3, separation: f32, manifold| {
            c.impulse = impulse * substeps as f32;
            c.penetration = -separation;
            c.preload = preload_update(manifold, rate, target, ctx.dt);
        };
        if threads > 1 {
            // On the team: written in the batches' order, the contacts are scattered over
            // the list, and each write is a cache miss once the contacts outgrow the cache
            // (the 3D pyramid of 20 layers, 80,000 points: 1.55 -> 0.98 ms a step).
            let work = Results {
                batches: &self.batches,
                states: share(&mut self.states),
                contacts: share(contacts),
                stored,
                write: &write,
            };
            run_on_team(&mut self.team, &mut self.plan, threads, &work);
        } else {
            solve::results(
                &self.batches,
                &mut self.states,
                stored,
                |i, impulse, separation, manifold| {
                    if let Some(c) = contacts.get_mut(i as usize) {
                        write(c, impulse, separation, manifold);
                    }
                },
            );
        }
        for (body, state) in bodies.iter_mut().zip(&self.states).skip(1) {
            let mean = body.linear_velocity;
            state.store(body);
            if body.path_acceleration != jostle_math::Vec3::ZERO && body.inv_mass == 0.0 {
                // A body on a curved path leaves the step with the step's mean velocity, as
                // it came (`load_bodies`).
                body.linear_velocity = mean;
            }
            body.last_acceleration = if body.inv_mass > 0.0 {
                ctx.gravity * body.linear_freedom()
            } else {
                jostle_math::Vec3::ZERO
            };
        }
        stats.integrate_time = integrate_time + t.elapsed();
        // The biased solve resolves overlap (the "position" work); relax and restitution are
        // pure velocity work.
        stats.position_time = solve_time;
        stats.velocity_time = relax_time;
        let n = self.batches.contacts;
        stats.position_iterations = n.saturating_mul(substeps);
        stats.velocity_iterations = n.saturating_mul(substeps * self.settings.relax_iterations);
        stats
    }
}

#[cfg(test)]
mod thread_choice_tests {
    use super::*;

    /// Runs `steps` steps where the team costs `team` and one thread `solo` (ns per point),
    /// returning how many ran on the team.
    fn team_steps(choice: &mut ThreadChoice, steps: u32, solo: u64, team: u64) -> u32 {
        let mut on_team = 0;
        for _ in 0..steps {
            let use_team = choice.use_team();
            let cost = if use_team { team } else { solo };
            choice.record(use_team, Duration::from_nanos(cost * 100), 100);
            on_team += u32::from(use_team);
        }
        on_team
    }

    #[test]
    fn the_faster_mode_runs_and_the_other_is_tried_now_and_then() {
        let mut choice = ThreadChoice::default();
        // Both measured within the first five steps, then the faster (the team) runs.
        let on_team = team_steps(&mut choice, 5 + 10 * PROBE_INTERVAL, 2000, 1000);
        let probes = 10;
        assert_eq!(
            on_team,
            3 + 10 * PROBE_INTERVAL - probes,
            "the team runs but for probes"
        );
        // The machine changes: one thread becomes faster, and the probes notice within a few
        // of them (a mode's cost is the least of its last few runs).
        team_steps(&mut choice, 6 * PROBE_INTERVAL, 500, 1000);
        let on_team = team_steps(&mut choice, 4 * PROBE_INTERVAL, 500, 1000);
        // (Each trial of the team is three steps, the first two not counted.)
        assert!(
            on_team <= 4 * (1 + TEAM_WARMUP),
            "{on_team} of {} steps on the slower team",
            4 * PROBE_INTERVAL
        );
    }

    #[test]
    fn occasional_slow_team_runs_do_not_hide_a_faster_team() {
        // A fifth of the team's runs, at random, are slowed threefold (its second core taken
        // for a while): the team is still the faster on average (1,400 against 1,500), and it
        // keeps running. (Slowed at a fixed period, a period that divides the trial's length
        // meets a slow run at every counted step of every trial.)
        let mut choice = ThreadChoice::default();
        let (mut on_team, mut seed) = (0, 0x9e37_79b9_u32);
        for step in 0..20 * PROBE_INTERVAL {
            let use_team = choice.use_team();
            let cost = if use_team {
                // xorshift32: a fixed sequence, the same on every run.
                seed ^= seed << 13;
                seed ^= seed >> 17;
                seed ^= seed << 5;
                if seed % 5 == 0 { 3000 } else { 1000 }
            } else {
                1500
            };
            choice.record(use_team, Duration::from_nanos(cost * 100), 100);
            if step >= 4 * PROBE_INTERVAL {
                on_team += u32::from(use_team);
            }
        }
        let steps = 16 * PROBE_INTERVAL;
        assert!(
            on_team * 10 >= steps * 9,
            "{on_team} of {steps} steps on the team"
        );
    }

    #[test]
    fn a_team_woken_cold_after_steps_on_one_thread_is_judged_warm() {
        // One thread costs 1500, the team 1000 warm but 3000 on its first step after steps on
        // one thread (its helpers parked) and 1600 on its second (its caches still cold).
        // Once on one thread (the machine was busy), the team's trials must bring it back.
        let mut choice = ThreadChoice::default();
        team_steps(&mut choice, 4 + 4 * PROBE_INTERVAL, 500, 3000);
        let mut on_team = 0;
        let mut streak = 0;
        for _ in 0..8 * PROBE_INTERVAL {
            let use_team = choice.use_team();
            streak = if use_team { streak + 1 } else { 0 };
            let cost = match streak {
                0 => 1500,
                1 => 3000,
                2 => 1600,
                _ => 1000,
            };
            choice.record(use_team, Duration::from_nanos(cost * 100), 100);
            on_team += u32::from(use_team);
        }
        assert!(
            on_team >= 6 * PROBE_INTERVAL,
            "{on_team} of {} steps on the faster team",
            8 * PROBE_INTERVAL
        );
    }

    #[test]
    fn the_first_run_of_each_mode_is_not_counted() {
        let mut choice = ThreadChoice::default();
        // A first team run paying for starting its threads does not condemn the team.
        assert!(!choice.use_team());
        choice.record(false, Duration::from_nanos(2000 * 100), 100);
        assert!(!choice.use_team());
        choice.record(false, Duration::from_nanos(2000 * 100), 100);
        assert!(choice.use_team());
        choice.record(true, Duration::from_millis(50), 100);
        assert!(choice.use_team());
        choice.record(true, Duration::from_nanos(1000 * 100), 100);
        assert!(choice.use_team());
    }
}

#[cfg(test)]
mod carried_warm_start_tests {
    use super::*;
    use crate::synthetic;

    /// One step of a random pile (2,000 contacts) with the warm start carried by the bodies
    /// and with every body's kept point by point (every body marked
    /// [`body_state::EXACT_WARM`]): the same in exact arithmetic, so every velocity agrees to
    /// rounding (measured: 2.6·10⁻⁶ m/s at speeds of 2.5 m/s). With the carried change left
    /// out of the later substeps (the warm start of the first substep only) they differ by
    /// 1.5 m/s.
    #[test]
    fn the_carried_warm_start_matches_the_point_by_point_one() {
        let scene = synthetic::random_pile(2000, 3);
        let ctx = StepContext {
            gravity: Vec3::new(0.0, -9.81, 0.0),
            dt: synthetic::DT,
        };
        let run = |exact: Option<f32>| {
            let mut resolver = SoftStepResolver {
                exact_warm_ratio: exact,
                ..SoftStepResolver::default()
            };
            // One sweep at impacts too: with several, a point's clamp at zero can fall one way
            // in one run and the other way in the other on a rounding difference, and the
            // runs then differ by that point's impulse (1.5·10⁻⁴ m/s at 2 and 8 sweeps, not
            // at 4 or 16), which says nothing about the warm start.
            resolver.settings.normal_sweeps = 1;
            let mut bodies = scene.bodies.clone();
            let mut contacts = scene.contacts.clone();
            resolver.step(&mut bodies, &mut contacts, &ctx);
            bodies
        };
        let (carried, exact) = (run(None), run(Some(1.0)));
        let scale = exact
            .iter()
            .map(|b| b.linear_velocity.length().max(b.angular_velocity.length()))
            .fold(0.0f32, f32::max);
        assert!(scale > 0.1, "the pile moves: {scale}");
        let mut worst = 0.0f32;
        for (c, e) in carried.iter().zip(&exact) {
            worst = worst
                .max((c.linear_velocity - e.linear_velocity).length())
                .max((c.angular_velocity - e.angular_velocity).length());
        }
        assert!(
            worst <= 1e-5 * scale,
            "differs by {worst} at a scale of {scale}"
        );
    }
}

#[cfg(test)]
mod path_acceleration_tests {
    use super::*;
    use jostle_math::{Quat, Vec3};

    /// A platform on a path (immovable, its mean velocity over the step and its acceleration
    /// given) with a box sticking on it: the platform ends the step where its mean velocity
    /// takes it and leaves with that velocity, and the box, held by friction to the platform
    /// through the substeps from the platform's velocity at the start of the step, leaves with
    /// the platform's velocity in the middle of the last substep, v + a·(dt/2 − h/2): with the
    /// mean velocity throughout, friction took it to v.
    #[test]
    fn a_platform_on_a_path_moves_at_each_substeps_velocity() {
        let (dt, substeps) = (1.0 / 60.0, 8u32);
        let h = dt / substeps as f32;
        let (v, a) = (Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 1.0));
        let mut platform = SolverBody::new(Vec3::ZERO, Quat::IDENTITY, 0.0, Mat3::ZERO);
        platform.linear_velocity = v;
        platform.path_acceleration = a;
        let mut load = SolverBody::new(
            Vec3::new(0.0, 0.5, 0.0),
            Quat::IDENTITY,
            1.0,
            Mat3::from_diagonal(Vec3::splat(6.0)),
        );
        // Sticking: at the start of the step it moves as the platform does then.
        load.linear_velocity = v - a * (0.5 * dt);
        let mut bodies = vec![SolverBody::STATIC, platform, load];
        let mut contacts: Vec<Contact> = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
            .map(|(x, z)| Contact::new(2, 1, Vec3::new(x, 0.0, z), Vec3::Y, 0.0).with_friction(1.0))
            .to_vec();
        let mut resolver = SoftStepResolver::new(SoftStepSettings {
            substeps,
            ..SoftStepSettings::default()
        });
        let ctx = StepContext {
            gravity: Vec3::new(0.0, -9.81, 0.0),
            dt,
        };
        resolver.step(&mut bodies, &mut contacts, &ctx);
        let (platform, load) = (&bodies[1], &bodies[2]);
        assert!(
            (platform.position - v * dt).length() < 1e-6,
            "{}",
            platform.position
        );
        assert_eq!(platform.linear_velocity, v);
        let expected = v + a * (0.5 * (dt - h));
        let horizontal = |w: Vec3| Vec3::new(w.x, 0.0, w.z);
        assert!(
            (horizontal(load.linear_velocity) - horizontal(expected)).length() < 1e-3,
            "{} against {expected}",
            load.linear_velocity
        );
    }
}
