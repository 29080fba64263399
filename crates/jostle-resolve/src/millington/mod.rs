//! The Millington resolver: the seed lecture's contact resolution (Millington, *Game Physics
//! Engine Development*, ch. 14–16), faithful to Cyclone where Cyclone is right and fixed where it
//! is wrong.
//!
//! One step is a linear pipeline:
//! 0. integrate gravity into velocities ([`crate::integrate::integrate_velocities`]);
//! 1. [`prepare`](mod@prepare) every contact once: contact basis, lever arms, closing velocity in contact
//!    space (its tangential part with the chord term of turning bodies, see [`prepare()`]),
//!    desired velocity change (micro-collision rule);
//! 2. split the contacts into independent islands ([`islands`]);
//! 3. the **position pass**: per island, worst penetration first, nonlinear (or linear)
//!    projection ([`position`]), updating the penetration of every contact sharing a body;
//! 4. the **velocity pass**: per island, worst velocity change first (the desired normal
//!    change, or the sliding speed of a contact whose friction can still act), an impulse per
//!    pick ([`velocity`]), updating the closing velocity of every contact sharing a body,
//!    warm started from the impulses the contacts carried from the last step; a pick for a
//!    normal velocity resolves the normal velocities of the picked contact's whole manifold
//!    together ([`velocity::resolve_manifold_normals`],
//!    [`MillingtonSettings::manifold_picks`]);
//! 5. integrate the resolved velocities into poses
//!    ([`crate::integrate::integrate_positions`]).
//!
//! After each of the two passes, in islands that hold a mass ratio of 10 or more, the **shock
//! sweep** ([`shock`]) resolves what the picks left, from the ground up with each lower body
//! held still.
//!
//! Speculative contacts (negative penetration, within the collision layer's prediction margin)
//! take part only when their gap closes within the step (see [`desired_delta_velocity`]), so
//! resting contacts are found before they overlap and nothing bounces before it touches.
//!
//! Fixes of the original (Cyclone / the lecture), each behind a regression test in
//! `tests/fixes.rs` (the contact-basis one in `jostle-math`):
//! - both bodies immovable (total inertia 0): no division by zero ([`velocity`],
//!   [`position`]);
//! - the dynamic-friction denominator is guarded and the normal impulse clamped to a push
//!   ([`velocity::coulomb_accumulated`]);
//! - **friction creep**: the lecture tests Coulomb against each pick's own normal impulse and
//!   picks contacts by their normal velocity change alone, so a resting box's sliding was
//!   never fully removed (a box on a 10° slope with μ = 0.5 crept 0.136 m in 5 s, ≈ g·sinθ·dt
//!   per step; on flat ground it drifted ~6 mm in 10 s). Here Coulomb is tested against the
//!   contact's impulse accumulated over the step ([`velocity::coulomb_accumulated`]) and a
//!   contact whose friction can still act is also picked for its sliding speed
//!   ([`velocity::velocity_key`]). μ = 0 contacts keep the frictionless path.
//! - **restitution that gained energy** (tests in `tests/restitution.rs` and `tests/physics.rs`):
//!   the lecture recomputes a contact's desired change from its velocity after every pick, so
//!   the closing speed one point's pick drives into its neighbour was bounced too (the
//!   lecture's own cube edge, as two points, ended at v_y 0.5821 with a spin about x instead
//!   of 0.6234), and a box landing on an edge gained energy at every impact. Here a contact's
//!   target velocity is decided once and kept while picks of the same two bodies change its
//!   velocity, and a pick may take back part of what the contact pushed (accumulated
//!   clamping), so the points of one impact are resolved together; a pick of another pair
//!   decides it again, so an impact still travels through touching bodies pair by pair
//!   (Newton's cradle) ([`PreparedContact::target_velocity`], [`velocity::normal_key`]). And a
//!   contact found overlapping bounces at the speed its surfaces met at, not the faster one it
//!   has after overlapping, because the position pass then puts it back where they met
//!   ([`impact_speed_gain`]).
//!
//! The worst contact is found with an indexed max-heap and a body → contacts adjacency
//! ([`PickStrategy::Heap`], O(degree · log n) per pick) or by Cyclone's rescan
//! ([`PickStrategy::LinearScan`], O(n) per pick); both give bit-identical results.
//!
//! In: solver bodies and contacts. Out: moved bodies, and each contact's applied impulse and
//! remaining penetration. Depends on `jostle-math` alone.

// `!(x > 0.0)` is deliberate throughout: it is true for NaN, so a non-finite inertia or key
// takes the "do nothing" branch instead of dividing by it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod change;
pub mod islands;
mod passes;
pub mod position;
pub mod prepare;
pub mod priority_queue;
pub mod settings;
pub mod shock;
pub mod velocity;
mod worst_first;

pub use change::{BodyChange, NO_BODY};
pub use position::{
    PenetrationMoves, apply_moves, linear_moves, nonlinear_moves, position_key, projection_depth,
    resolve_penetration, update_penetration,
};
pub use prepare::{PreparedContact, desired_delta_velocity, impact_speed_gain, prepare};
pub use priority_queue::IndexedMaxHeap;
pub use settings::{IterationBudget, MillingtonSettings, PickStrategy, Projection};
pub use velocity::{
    DYNAMIC_FRICTION_MIN_RESPONSE, FRICTION_CAPACITY_TOLERANCE, FrictionPick, apply_impulse,
    contact_impulse, coulomb, coulomb_accumulated, friction_impulse, friction_pick,
    frictionless_impulse, has_friction_capacity, impulse_matrix, reopen_friction,
    resolve_manifold_normals, resolve_velocity, share_manifold_friction, update_velocity,
    velocity_change_per_unit_impulse, velocity_key,
};

use crate::clock::Stopwatch;
use crate::integrate::{integrate_positions, integrate_velocities};
use crate::{Contact, ResolveStats, Resolver, SolverBody, StepContext};
use islands::Islands;
use passes::{PositionPass, VelocityPass};
use shock::Shock;
pub use worst_first::PickWork;
use worst_first::{PickScratch, run_islands};

/// The Millington resolver (see the module docs). Holds its settings and scratch buffers that
/// are reused from step to step; it keeps no physical state between steps (with
/// [`MillingtonSettings::warm_start`] it reads the impulses the contacts carry, as any
/// resolver may), so swapping it in or out mid-simulation is safe.
///
/// Warm starting is on by default: on resting stacks it makes the velocity pass converge
/// within its budget (the 20-row pyramid: 52.8 → 0.83 ms per step, the 3D pyramid of 10:
/// 221 → 3.48 ms, both drifting less). The shock sweep ([`shock`]) holds what the picks cannot:
/// a box under one 10 or more times heavier, which warm started alone was pushed through the
/// floor at 1:10⁶ (benches/RESULTS.md, "The shock sweep, and the Millington resolver warm
/// started by default").
#[derive(Clone, Debug, Default)]
pub struct MillingtonResolver {
    /// The settings used by the next step; change them freely between steps.
    pub settings: MillingtonSettings,
    prepared: Vec<PreparedContact>,
    islands: Islands,
    scratch: PickScratch,
    /// Work of the last step's position and velocity passes.
    work: [PickWork; 2],
    /// Angular velocities before the position pass (scratch, reused between steps).
    spins: Vec<jostle_math::Vec3>,
    /// Velocities before the velocity pass, and which bodies bounce only off immovable
    /// bodies this step (scratch for `bound_bounce_energy`).
    before_velocity: Vec<(jostle_math::Vec3, jostle_math::Vec3)>,
    bounce_marks: Vec<u8>,
    /// The shock sweep's levels and order ([`shock`]).
    shock: Shock,
    /// Each contact's manifold, `start..end` (scratch, with
    /// [`MillingtonSettings::manifold_picks`]).
    manifolds: Vec<[u32; 2]>,
}

/// [`MillingtonResolver`]'s bounce marks: the body bounces off an immovable body.
const BOUNCES_ON_FIXED: u8 = 1;
/// The body touches a body that can move (energy may pass between them).
const TOUCHES_MOVING: u8 = 2;

impl MillingtonResolver {
    /// A resolver with the given settings.
    pub fn new(settings: MillingtonSettings) -> Self {
        Self {
            settings,
            ..Self::default()
        }
    }

    /// The contacts as the last step prepared and resolved them (same order as its input):
    /// final closing velocities, desired velocity changes and penetrations, for diagnostics.
    pub fn prepared(&self) -> &[PreparedContact] {
        &self.prepared
    }

    /// The islands and body → contacts adjacency of the last step (contact indices as given
    /// to it), for diagnostics.
    pub fn islands(&self) -> &Islands {
        &self.islands
    }

    /// What the worst-first loops of the last step did, position pass then velocity pass:
    /// picks, neighbour updates, keys read and heap moves. Deterministic, unlike times, so
    /// tests and benches can check how the work of a pick grows with the number of contacts.
    pub fn last_work(&self) -> [PickWork; 2] {
        self.work
    }

    /// Steps 1–4 of the module docs without integration: prepares the contacts, runs the
    /// position and velocity passes island by island, and writes each contact's applied
    /// impulse (contact space, on A) and remaining penetration. [`Resolver::step`] is this
    /// followed by integration. `dt` is the step length the bodies' `last_acceleration` was
    /// integrated over.
    pub fn resolve_contacts(
        &mut self,
        bodies: &mut [SolverBody],
        contacts: &mut [Contact],
        dt: f32,
    ) -> ResolveStats {
        let mut stats = ResolveStats::default();
        let settings = &self.settings;

        let start = Stopwatch::start();
        self.prepared.clear();
        self.prepared.extend(contacts.iter().map(|c| {
            prepare(c, bodies, dt, settings.velocity_limit)
                .unwrap_or_else(|| PreparedContact::inert(c.penetration))
        }));
        self.islands.build(&self.prepared, bodies.len());
        self.scratch.reset(contacts.len());
        stats.islands = self.islands.len() as u32;
        stats.prepare_time = start.elapsed();

        let start = Stopwatch::start();
        self.spins.clear();
        self.spins.extend(bodies.iter().map(|b| b.angular_velocity));
        let mut pass = PositionPass {
            contacts: &mut self.prepared,
            bodies,
            settings,
        };
        self.shock.reset();
        stats.position_iterations = run_pass(
            &mut pass,
            &self.islands,
            &mut self.scratch,
            &mut self.shock,
            settings,
            &settings.position_iterations,
            settings.position_epsilon,
        );
        stats.position_residual = self.scratch.residual;
        self.work[0] = std::mem::take(&mut self.scratch.work);
        stats.position_time = start.elapsed();

        let start = Stopwatch::start();
        // Projection turns a rotated body's spin with it (position.rs, `apply_moves`), so the
        // closing velocities prepared before the position pass are refreshed by the change of
        // spin of their bodies; without this the velocity pass resolved stale velocities and a
        // spinning body pushed out of a deep overlap could gain energy (tests/properties.rs).
        // Speculative contacts: the gap left after the position pass decides how much closing
        // speed the contact tolerates this step.
        for p in &mut self.prepared {
            for side in 0..2 {
                let index = p.body[side] as usize;
                if p.body[side] == change::NO_BODY {
                    continue;
                }
                let turned = bodies[index].angular_velocity - self.spins[index];
                if turned != jostle_math::Vec3::ZERO {
                    let d = p.basis.transpose() * turned.cross(p.r[side]);
                    p.velocity += if side == 0 { d } else { -d };
                }
            }
            p.gap_velocity = (-p.penetration).max(0.0) / dt;
            p.desired_delta_velocity = desired_delta_velocity(
                p.velocity.x,
                p.acc_velocity,
                p.impact_speed_gain,
                p.restitution,
                settings.velocity_limit,
                p.gap_velocity,
            );
            p.target_velocity = p.velocity.x + p.desired_delta_velocity;
        }
        mark_bounces(
            &self.prepared,
            bodies.len(),
            settings.velocity_limit,
            &mut self.bounce_marks,
        );
        self.before_velocity.clear();
        self.before_velocity.extend(
            bodies
                .iter()
                .map(|b| (b.linear_velocity, b.angular_velocity)),
        );
        if settings.warm_start {
            warm_start(
                &mut self.prepared,
                contacts,
                bodies,
                &self.before_velocity,
                settings.velocity_limit,
                settings.velocity_epsilon,
            );
        }
        self.manifolds.clear();
        if settings.manifold_picks {
            manifold_ranges(&self.prepared, &self.islands, bodies, &mut self.manifolds);
        }
        let mut pass = VelocityPass {
            contacts: &mut self.prepared,
            bodies,
            velocity_limit: settings.velocity_limit,
            velocity_epsilon: settings.velocity_epsilon,
            picked: u32::MAX,
            picked_pair: [change::NO_BODY; 2],
            manifolds: &self.manifolds,
        };
        stats.velocity_iterations = run_pass(
            &mut pass,
            &self.islands,
            &mut self.scratch,
            &mut self.shock,
            settings,
            &settings.velocity_iterations,
            settings.velocity_epsilon,
        );
        stats.velocity_residual = self.scratch.residual;
        self.work[1] = std::mem::take(&mut self.scratch.work);
        bound_bounce_energy(&self.bounce_marks, &self.before_velocity, bodies, dt);
        for (c, p) in contacts.iter_mut().zip(&self.prepared) {
            c.impulse = p.impulse;
            c.penetration = p.penetration;
        }
        stats.velocity_time = start.elapsed();
        stats
    }
}

impl Resolver for MillingtonResolver {
    fn name(&self) -> &'static str {
        "millington"
    }

    /// Integrates gravity into velocities, resolves contacts
    /// ([`MillingtonResolver::resolve_contacts`]), then integrates the resolved velocities into
    /// poses. Cyclone's frame is integrate (velocity then pose), detect, resolve; here detection
    /// comes first and the pose integration last, so a body is moved by the velocity the
    /// resolver left it, never by one that still drives it into a contact, and the micro-
    /// collision rule's v_acc is the velocity this step's integration just added, as in Cyclone.
    /// Contacts' `impulse` is read as the previous step's (only with
    /// [`MillingtonSettings::warm_start`]) and overwritten with the impulse of this step, and
    /// `penetration` with the penetration the position pass left.
    fn step(
        &mut self,
        bodies: &mut [SolverBody],
        contacts: &mut [Contact],
        ctx: &StepContext,
    ) -> ResolveStats {
        let start = Stopwatch::start();
        integrate_velocities(bodies, ctx.gravity, ctx.dt);
        let velocities_time = start.elapsed();
        let mut stats = self.resolve_contacts(bodies, contacts, ctx.dt);
        let start = Stopwatch::start();
        integrate_positions(bodies, ctx.dt);
        stats.integrate_time = velocities_time + start.elapsed();
        stats.threads = 1;
        stats
    }
}

/// One pass: the worst-first picks over every island ([`run_islands`]), then the shock
/// sweep ([`shock`]) when it is on and the picks left a key above `epsilon`. Returns the
/// picks and the sweep's resolutions together.
fn run_pass<P: worst_first::Pass>(
    pass: &mut P,
    islands: &Islands,
    scratch: &mut PickScratch,
    shock: &mut Shock,
    settings: &MillingtonSettings,
    budget: &settings::IterationBudget,
    epsilon: f32,
) -> u32 {
    let mut picks = run_islands(
        pass,
        islands,
        scratch,
        settings.pick,
        budget,
        epsilon,
        settings.first_sweep,
    );
    if settings.shock_sweep && scratch.residual > epsilon {
        shock.prepare(pass.contacts(), islands, pass.bodies());
        if !shock.is_empty() {
            picks += shock.sweep(pass, islands, scratch, epsilon);
        }
    }
    picks
}

/// The warm start of the velocity pass ([`MillingtonSettings::warm_start`]): each resting
/// contact of `prepared` (closing, slower than `velocity_limit`, so no bounce is decided for
/// it) applies the impulse its `contacts` entry carried from the previous step, clamped to a
/// push and to the static friction cone, and is marked held; then every contact's closing
/// velocity is brought up to date with what the bodies gained since `before` (their
/// velocities before the warm start), and its desired change with it.
fn warm_start(
    prepared: &mut [PreparedContact],
    contacts: &[Contact],
    bodies: &mut [SolverBody],
    before: &[(jostle_math::Vec3, jostle_math::Vec3)],
    velocity_limit: f32,
    velocity_epsilon: f32,
) {
    let mut any = false;
    for (p, c) in prepared.iter_mut().zip(contacts) {
        let carried = c.impulse;
        // Resting contacts only: one moving faster than the limit along the normal is an
        // impact (closing) or a bounce (separating), decided afresh. Only an impulse that
        // changes the velocity by more than the epsilon: no pick can take back what a
        // smaller one overshoots by, and re-applied step after step such an impulse pushed
        // two balls moving together apart by 9·10⁻⁵ m/s more at every step. And only one
        // whose change f32 can resolve to the epsilon, or the picks could not take back its
        // overshoot: a 1 kg box under 10⁶ kg carries impulses that change its velocity by
        // 10⁵ m/s, whose rounding alone is 0.01 m/s.
        let change = carried.x * p.normal_inertia;
        let resting = p.velocity.x.abs() < velocity_limit;
        let resolvable = change > velocity_epsilon && change * f32::EPSILON < velocity_epsilon;
        if !(p.normal_inertia > 0.0 && carried.is_finite() && resting && resolvable) {
            continue;
        }
        let planar = jostle_math::Vec3::new(0.0, carried.y, carried.z);
        let planar = if p.friction > 0.0 {
            planar.clamp_length_max(p.friction * carried.x)
        } else {
            jostle_math::Vec3::ZERO
        };
        let g = jostle_math::Vec3::new(carried.x, planar.y, planar.z);
        apply_impulse(p, g, bodies);
        p.impulse = g;
        p.held = true;
        any = true;
    }
    if !any {
        return;
    }
    for p in prepared.iter_mut() {
        let mut changed = false;
        for side in 0..2 {
            let index = p.body[side];
            if index == change::NO_BODY {
                continue;
            }
            let (Some(b), Some(&(v0, w0))) =
                (bodies.get(index as usize), before.get(index as usize))
            else {
                continue;
            };
            let d = (b.linear_velocity - v0) + (b.angular_velocity - w0).cross(p.r[side]);
            let d = p.basis.transpose() * d;
            p.velocity += if side == 0 { d } else { -d };
            changed = true;
        }
        if changed {
            p.desired_delta_velocity = p.target_velocity - p.velocity.x;
        }
    }
}

/// Each contact's manifold as `start..end` into `prepared`: runs of consecutive contacts
/// between the same two moving bodies (in the same order), at most
/// [`velocity::MANIFOLD_POINTS`] long. A contact with no moving body, and every contact of an
/// island that holds a mass ratio of [`shock::SHOCK_MASS_RATIO`] or more, is a run of its own:
/// there a pick that takes back a loaded point's push moves a light body by the heavy one's
/// load, and with blocks there the heavy-on-light set fell from 64 to 56 of 72 cases
/// (benches/RESULTS.md, "Picks by manifold"); the shock sweep holds such islands point by
/// point.
fn manifold_ranges(
    prepared: &[PreparedContact],
    islands: &Islands,
    bodies: &[SolverBody],
    out: &mut Vec<[u32; 2]>,
) {
    let mut start = 0;
    while start < prepared.len() {
        let body = prepared[start].body;
        let mut end = start + 1;
        if body != [change::NO_BODY; 2] {
            while end < prepared.len()
                && end - start < velocity::MANIFOLD_POINTS
                && prepared[end].body == body
            {
                end += 1;
            }
        }
        out.extend(std::iter::repeat_n([start as u32, end as u32], end - start));
        start = end;
    }
    for i in 0..islands.len() {
        let island = islands.island(i);
        if shock::holds_mass_ratio(island, prepared, bodies) {
            for &c in island {
                out[c as usize] = [c, c + 1];
            }
        }
    }
}

/// Marks in `marks` the bodies with a contact of `prepared` that bounces this step
/// (restitution above the velocity limit) against an immovable body, and those touching a body
/// that can move.
fn mark_bounces(
    prepared: &[PreparedContact],
    bodies: usize,
    velocity_limit: f32,
    marks: &mut Vec<u8>,
) {
    marks.clear();
    marks.resize(bodies, 0);
    for p in prepared {
        let [a, b] = p.body;
        let bounces = p.restitution > 0.0 && p.velocity.x <= -velocity_limit;
        let mark = match (a == change::NO_BODY, b == change::NO_BODY) {
            (false, false) => TOUCHES_MOVING,
            (true, true) => continue,
            _ if bounces => BOUNCES_ON_FIXED,
            _ => continue,
        };
        for k in [a, b] {
            if let Some(m) = marks.get_mut(k as usize) {
                *m |= mark;
            }
        }
    }
}

/// The energy bound of a bounce off immovable bodies: a body whose contacts this step are
/// all with bodies that cannot move, one of them bouncing, leaves the step with no more
/// energy than it brought into it; where it would leave with more, the pass's change to its
/// velocities is scaled back to the largest fraction that meets the bound.
///
/// Why: each point bounces at −e times its own closing speed (Newton's rule, point by
/// point). For a body striking with several points at once at different speeds (a
/// spinning plate landing on an edge) those targets together can ask for more energy
/// than the body brought: a 1 × 0.04 × 1 m plate hitting a wall at 20 m/s with e = 1
/// left with 28% more (benches/RESULTS.md, "CCD: no freeze, no tunnel"). The soft step
/// bounds its restitution pass the same way.
///
/// The energy is the one semi-implicit Euler keeps in free flight: with h the step,
/// E = ½m|v|² + ½ωᵀIω − m·g·x + ½m·h·g·v, which stays constant step after step under
/// gravity alone (the plain ½m|v|² − m·g·x falls by ½m|g·h|² a step, and its value at the
/// end of a step swings by m·|g|·h·|v_y| between the way down and the way up, so a ball
/// bouncing at e = 1 back to the same apex seems to gain that much at every bounce). This
/// resolver adds the step's gravity g·h to the velocities before the pass (`before` holds
/// them) and then moves the bodies by what the pass leaves, and over such a step E does not
/// grow exactly when the kinetic energy of the velocities less half the step's gravity,
/// ½m|v − ½g·h|² + ½ωᵀIω, does not grow across the pass: that is the bound. A ball bouncing
/// straight at e = 1 meets it exactly (the micro-collision rule's −e·(v − v_acc) is its
/// mirror image); a plate landing on a corner, bounded on its kinetic energy alone, kept
/// nearly all of the kinetic energy the step's gravity had added (the corner's impulse takes
/// out only the part its small effective mass carries) and gained up to 2.2% of its energy in
/// a bounce (benches/RESULTS.md, "Bounces bounded by the energy the integrator keeps").
fn bound_bounce_energy(
    marks: &[u8],
    before: &[(jostle_math::Vec3, jostle_math::Vec3)],
    bodies: &mut [SolverBody],
    dt: f32,
) {
    for (i, &mark) in marks.iter().enumerate() {
        if mark != BOUNCES_ON_FIXED {
            continue;
        }
        let (Some(body), Some(&(v0, w0))) = (bodies.get_mut(i), before.get(i)) else {
            continue;
        };
        if !(body.inv_mass > 0.0) {
            continue;
        }
        let mass = 1.0 / body.inv_mass;
        let inertia =
            crate::energy::inertia_of(body.inv_inertia).unwrap_or(jostle_math::Mat3::ZERO);
        let (dv, dw) = (body.linear_velocity - v0, body.angular_velocity - w0);
        // The velocities before the pass less half the step's gravity (see above).
        let start = v0 - 0.5 * dt * body.last_acceleration;
        let allowed = 0.5 * mass * start.length_squared() + 0.5 * w0.dot(inertia * w0);
        let Some(s) = crate::energy::bounded_fraction(
            mass,
            inertia,
            (start, w0),
            (dv, dw),
            allowed,
            allowed * 1e-6,
        ) else {
            continue;
        };
        body.linear_velocity = v0 + dv * s;
        body.angular_velocity = w0 + dw * s;
    }
}
