//! The step's stages that belong to the facade: wake-up, gather, CCD, scatter and sleep. Each is a
//! small function over exactly the data it touches; `World::step` strings them together.

use crate::StepReport;
use crate::profile::StepProfile;
use jostle_body::{BodySet, CcdMode, apply_forces};
use jostle_collide::{
    BodyContact, BroadPhase, CcdSettings, CcdShape, ColliderHandle, ColliderSet, MAX_PARTS,
    Material, NarrowPhase, Pose, Runner, run_parts,
};
use jostle_math::{Mat3, Vec3, skew};
use jostle_resolve::{Contact, STATIC_BODY, SolverBody};
use jostle_sleep::{IslandSet, SleepSettings, update_motion};

/// Marks a body slot that has no solver entry (sleeping, or not a body).
const NO_SOLVER: u32 = u32::MAX;

/// Per-step working arrays, kept between steps only to reuse their allocations.
#[derive(Default)]
pub(crate) struct Scratch {
    /// Dense solver bodies; index 0 is the static entry.
    pub bodies: Vec<SolverBody>,
    /// Runs the narrow phase's parts on the helper threads ([`crate::threads`]).
    pub narrow_runner: crate::threads::TeamRunner,
    /// By body slot: how fast the step changed the body's pose, (|Δx|² + (2·sin(Δθ/2))²)/dt²
    /// (for sleep, [`jostle_sleep::update_motion`]).
    pub moved: Vec<f32>,
    /// By body slot: whether the body qualifies for sleep this step.
    pub qualifies: Vec<bool>,
    /// Solver contacts.
    pub contacts: Vec<Contact>,
    /// For each solver contact, its index in the narrow phase's contact list.
    pub contact_source: Vec<u32>,
    /// For each body slot, its solver index or `NO_SOLVER`.
    pub solver_index: Vec<u32>,
    /// For each solver body (index ≥ 1), its body slot.
    pub body_slot: Vec<u32>,
    /// CCD: candidate colliders of one sweep.
    pub ccd_candidates: Vec<ColliderHandle>,
    /// CCD: every body stopped this step, by its solver index.
    pub ccd_stops: Vec<CcdStop>,
    /// CCD: whether each collider (by slot) is swept this step.
    pub ccd_fast: Vec<bool>,
    /// CCD: (body slot, collider hit) of every stop of the previous step, sorted.
    pub ccd_previous: Vec<(u32, ColliderHandle)>,
    /// For each narrow-phase contact whose materials have a dynamic friction coefficient of
    /// their own, whether it is sliding ([`sliding`]); empty when none has.
    pub sliding: Vec<bool>,
    /// Position-based kinematic bodies and the pose each reaches at the end of this step.
    pub kinematic_targets: Vec<(jostle_body::BodyHandle, Vec3, jostle_math::Quat)>,
}

/// Relative tangential speed (m/s) at a contact, at the end of the last step, above which the
/// contact is sliding: its friction this step is the materials' dynamic coefficient
/// ([`jostle_collide::Material::dynamic_friction`]), at or below it the static one holds it.
/// 1 cm/s: far above the residual speeds of a resting stack (below 10⁻⁴ m/s), far below any
/// sliding one cares to see decelerate.
pub const SLIDING_SPEED: f32 = 0.01;

/// Whether contact `c` is sliding: the relative velocity of its two surface points, less its
/// normal part, is faster than [`SLIDING_SPEED`]. Read from the bodies' velocities before this
/// step's forces (which a resolver's friction answers, not a sliding contact) and gravity.
fn sliding(bodies: &BodySet, c: &BodyContact) -> bool {
    let at = |h, p: Vec3| {
        bodies.get(h).map_or(Vec3::ZERO, |b| {
            b.linear_velocity + b.angular_velocity.cross(p - b.position)
        })
    };
    let v = at(c.a, c.point) - at(c.b, c.point_b);
    let tangential = v - c.normal * v.dot(c.normal);
    tangential.length_squared() > SLIDING_SPEED * SLIDING_SPEED
}

/// A body CCD stops: where, and on what.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CcdStop {
    /// The body's solver index.
    solver: u32,
    /// Fraction of the step's motion kept.
    fraction: f32,
    /// The body's collider that hit.
    collider: ColliderHandle,
    /// The resting collider it hit.
    target: ColliderHandle,
    /// The body's pose at the stop.
    stop: Pose,
    /// The body's pose at the impact.
    impact: Pose,
    /// The contact the cast found at the impact.
    contact: Option<jostle_collide::ccd::CcdContact>,
    /// The centre of mass reached the surface ([`jostle_collide::CcdHit::core`]).
    core: bool,
}

/// Wakes every sleeping island touched by an awake body. Contacts with fixed bodies never
/// wake anything. Returns whether anything woke.
pub(crate) fn wake_touching(
    bodies: &mut BodySet,
    islands: &mut IslandSet,
    contacts: &[BodyContact],
    settings: &SleepSettings,
) -> bool {
    // Only a dynamic body can be woken: with none asleep the contacts are not walked (on the
    // 3D pyramid of 20 layers, sleeping off, its 80,000 contacts took 0.4 ms a step).
    if bodies
        .iter()
        .all(|(_, b)| b.is_immovable() || b.sleep.awake)
    {
        return false;
    }
    let mut woke = false;
    // A pair's points are listed together: the first decides for the rest.
    let mut last = None;
    for c in contacts {
        if last.replace((c.a, c.b)) == Some((c.a, c.b)) {
            continue;
        }
        let (Some(a), Some(b)) = (bodies.get(c.a), bodies.get(c.b)) else {
            continue;
        };
        if a.is_immovable() || b.is_immovable() {
            // Only a moving kinematic body wakes what it touches.
            let sleeper = match (a.kinematic_moves(), b.kinematic_moves()) {
                (true, false) if !b.is_immovable() && !b.sleep.awake => c.b,
                (false, true) if !a.is_immovable() && !a.sleep.awake => c.a,
                _ => continue,
            };
            woke |= islands.wake(bodies, sleeper, settings);
            continue;
        }
        if a.sleep.awake == b.sleep.awake {
            continue;
        }
        let sleeper = if a.sleep.awake { c.b } else { c.a };
        woke |= islands.wake(bodies, sleeper, settings);
    }
    woke
}

/// Copies the awake bodies into the dense solver array (after applying their forces and
/// damping) and the contacts between solver bodies into solver contacts. Bodies whose state is
/// not finite are frozen here, before they can spread NaN to their neighbours.
pub(crate) fn gather(
    bodies: &mut BodySet,
    colliders: &ColliderSet,
    contacts: &[BodyContact],
    dt: f32,
    gravity: Vec3,
    scratch: &mut Scratch,
    report: &mut StepReport,
) {
    // Which contacts slide, before the forces change the velocities; only where a dynamic
    // coefficient differs from the static one (every other scene skips this).
    scratch.sliding.clear();
    // (Only a collider's material can give a contact a dynamic coefficient: without one the
    // contacts are not walked.)
    if colliders
        .iter()
        .any(|(_, c)| c.material.dynamic_friction.is_some())
        && contacts
            .iter()
            .any(|c| c.dynamic_friction.is_some_and(|d| d != c.friction))
    {
        scratch
            .sliding
            .extend(contacts.iter().map(|c| sliding(bodies, c)));
    }
    scratch.bodies.clear();
    scratch.bodies.push(SolverBody::STATIC);
    scratch.body_slot.clear();
    scratch.body_slot.push(NO_SOLVER);
    scratch.solver_index.clear();
    scratch
        .solver_index
        .resize(bodies.capacity_index(), NO_SOLVER);
    scratch.kinematic_targets.clear();
    for (handle, body) in bodies.iter_mut() {
        if body.is_kinematic() {
            if let Some((position, orientation)) = body.take_next_pose(dt) {
                scratch
                    .kinematic_targets
                    .push((handle, position, orientation));
            }
            if !body.kinematic_moves() {
                // At rest this step: it acts as a fixed body.
                continue;
            }
            // Moved by its velocity alone: no mass, no inertia, no gravity, no forces.
            scratch.solver_index[handle.index() as usize] = scratch.bodies.len() as u32;
            scratch.body_slot.push(handle.index());
            let mut sb = SolverBody::new(body.position, body.orientation, 0.0, Mat3::ZERO);
            sb.linear_velocity = body.linear_velocity;
            sb.angular_velocity = body.angular_velocity;
            sb.path_acceleration = body.path_acceleration();
            if body.angular_velocity != Vec3::ZERO {
                // Its angular terms are zero (no inverse inertia), but its pose turns.
                sb.flags |= SolverBody::ROTATES;
            }
            scratch.bodies.push(sb);
            continue;
        }
        if !body.is_awake() {
            continue;
        }
        let (v0, w0) = (body.linear_velocity, body.angular_velocity);
        apply_forces(body, dt);
        if !body.is_finite() {
            body.freeze();
            report.quarantined.push((handle, body.name.clone()));
            continue;
        }
        scratch.solver_index[handle.index() as usize] = scratch.bodies.len() as u32;
        scratch.body_slot.push(handle.index());
        let mut sb = SolverBody::new(
            body.position,
            body.orientation,
            body.inv_mass(),
            body.inv_inertia_world(),
        );
        // Translation locks hold dynamic bodies; a kinematic body goes where it is sent.
        if !body.is_kinematic() {
            for (axis, bit) in [SolverBody::LOCK_X, SolverBody::LOCK_Y, SolverBody::LOCK_Z]
                .into_iter()
                .enumerate()
            {
                if body.translation_locks()[axis] {
                    sb.flags |= bit;
                }
            }
        }
        // The forces' velocity change goes to the resolver to add over the step, not at once.
        // (Along a locked axis neither the velocity nor the forces act: a body turned from
        // kinematic to dynamic, or read from a snapshot, may come with such a velocity.)
        let free = sb.linear_freedom();
        sb.linear_velocity = v0 * free;
        sb.angular_velocity = w0;
        sb.force_velocity = (body.linear_velocity - v0) * free;
        if body.gravity_scale != 1.0 {
            // The resolver adds the world's gravity to every body; the rest of a scaled one's
            // is one more force, spread over the step like the others.
            sb.force_velocity += gravity * ((body.gravity_scale - 1.0) * dt) * free;
        }
        sb.torque_velocity = body.angular_velocity - w0;
        sb.last_acceleration = body.last_acceleration;
        scratch.bodies.push(sb);
    }
    gather_contacts(bodies, contacts, scratch);
}

/// Adds to `report` each pair of dynamic bodies among the solver contacts whose masses differ
/// by more than `ratio` (the resolver's `max_mass_ratio`; nothing without one), lighter first,
/// each pair once. A body locked along every axis of translation counts as immovable.
pub(crate) fn report_mass_ratios(
    contacts: &[BodyContact],
    scratch: &Scratch,
    ratio: Option<f32>,
    report: &mut StepReport,
) {
    let Some(ratio) = ratio else {
        return;
    };
    let movable = |b: &SolverBody| b.flags & SolverBody::LOCKS != SolverBody::LOCKS;
    let inv_mass = |i: u32| {
        scratch
            .bodies
            .get(i as usize)
            .filter(|b| movable(b))
            .map_or(0.0, |b| b.inv_mass)
    };
    // Where no two movable bodies' masses are that far apart, no contact is: the contacts are
    // not walked (on the 20-row pyramid the walk was 1% of the step). The lightest body has
    // the largest inverse mass; with no movable body the smallest stays infinite.
    let (lightest, heaviest) = scratch
        .bodies
        .iter()
        .filter(|b| b.inv_mass > 0.0 && movable(b))
        .fold((0.0f32, f32::INFINITY), |(most, least), b| {
            (most.max(b.inv_mass), least.min(b.inv_mass))
        });
    if lightest <= ratio * heaviest {
        return;
    }
    debug_assert!(report.beyond_mass_ratio.is_empty());
    let mut last = None;
    for (c, &source) in scratch.contacts.iter().zip(&scratch.contact_source) {
        // (A pair's contacts are listed together: its bodies are looked at once per run.)
        if last == Some((c.a, c.b)) {
            continue;
        }
        last = Some((c.a, c.b));
        let (ia, ib) = (inv_mass(c.a), inv_mass(c.b));
        // (Compared as inverse masses: a body that cannot move has none.)
        if ia > 0.0
            && ib > 0.0
            && ia.max(ib) > ratio * ia.min(ib)
            && let Some(bc) = contacts.get(source as usize)
        {
            // The lighter body has the larger inverse mass.
            report
                .beyond_mass_ratio
                .push(if ia > ib { (bc.a, bc.b) } else { (bc.b, bc.a) });
        }
    }
    // A pair of compound bodies may have several runs of contacts (one per pair of colliders).
    let found = &mut report.beyond_mass_ratio;
    if found.len() > 1 {
        found.sort_unstable();
        found.dedup();
    }
}

/// The read-only inputs of [`convert_contacts`].
struct ContactInputs<'a> {
    bodies: &'a BodySet,
    contacts: &'a [BodyContact],
    solver_index: &'a [u32],
    solver_bodies: &'a [SolverBody],
    sliding: &'a [bool],
}

/// Converts the narrow phase's contacts between solver bodies into solver contacts
/// (`scratch.contacts`, with `scratch.contact_source`). On the narrow phase's threads a run
/// of the contacts each, converted into the same places of the output; where a run keeps
/// fewer contacts than it has, the runs after it move down to close the gap (the contacts
/// between solver bodies are usually all of them, and then nothing moves). On the 3D pyramid
/// of 20 layers (80,000 contacts, two threads) the conversion took 1.2 ms a step on one.
fn gather_contacts(bodies: &BodySet, contacts: &[BodyContact], scratch: &mut Scratch) {
    let Scratch {
        bodies: solver_bodies,
        narrow_runner,
        contacts: out,
        contact_source: sources,
        solver_index,
        sliding,
        ..
    } = scratch;
    let input = ContactInputs {
        bodies,
        contacts,
        solver_index,
        solver_bodies,
        sliding,
    };
    convert_all(&input, out, sources, narrow_runner);
}

/// [`convert_contacts`] over all of `input.contacts` into `out` and `sources`, in as many
/// parts as `runner` asks for ([`gather_contacts`]).
fn convert_all(
    input: &ContactInputs<'_>,
    out: &mut Vec<Contact>,
    sources: &mut Vec<u32>,
    runner: &dyn Runner,
) {
    let n = input.contacts.len();
    let parts = runner.parts(n).clamp(1, MAX_PARTS).min(n.max(1));
    if parts == 1 {
        out.clear();
        sources.clear();
        out.reserve(n);
        sources.reserve(n);
        convert_contacts(input, 0..n, |c, i| {
            out.push(c);
            sources.push(i);
        });
        return;
    }
    // Part k converts the contacts from ⌊k·n/parts⌋ into the same places of the output.
    out.resize(
        n,
        Contact::new(STATIC_BODY, STATIC_BODY, Vec3::ZERO, Vec3::Y, 0.0),
    );
    sources.resize(n, 0);
    let first = |k: usize| k * n / parts;
    // Each part's runs of the outputs, and how many contacts it kept.
    let (mut rest_out, mut rest_sources) = (out.as_mut_slice(), sources.as_mut_slice());
    let mut runs: [_; MAX_PARTS] = std::array::from_fn(|k| {
        let len = if k < parts {
            first(k + 1) - first(k)
        } else {
            0
        };
        let (own_out, tail_out) = std::mem::take(&mut rest_out).split_at_mut(len);
        let (own_sources, tail_sources) = std::mem::take(&mut rest_sources).split_at_mut(len);
        (rest_out, rest_sources) = (tail_out, tail_sources);
        (own_out, own_sources, 0usize)
    });
    run_parts(runner, &mut runs[..parts], &|k,
                                            (
        own_out,
        own_sources,
        kept,
    )| {
        convert_contacts(input, first(k)..first(k + 1), |c, i| {
            own_out[*kept] = c;
            own_sources[*kept] = i;
            *kept += 1;
        });
    });
    let kept = runs.map(|(_, _, kept)| kept);
    let mut end = 0;
    for (k, &kept) in kept.iter().take(parts).enumerate() {
        let from = first(k);
        if from != end {
            out.copy_within(from..from + kept, end);
            sources.copy_within(from..from + kept, end);
        }
        end += kept;
    }
    out.truncate(end);
    sources.truncate(end);
}

/// Calls `keep(contact, index)` in order for each contact of `input.contacts[range]` between
/// solver bodies that something can push, as a solver contact.
fn convert_contacts(
    input: &ContactInputs<'_>,
    range: std::ops::Range<usize>,
    mut keep: impl FnMut(Contact, u32),
) {
    let index_of = |h: jostle_body::BodyHandle| -> Option<u32> {
        let body = input.bodies.get(h)?;
        let solver = input
            .solver_index
            .get(h.index() as usize)
            .copied()
            .unwrap_or(NO_SOLVER);
        let resting_kinematic = body.is_kinematic() && solver == NO_SOLVER;
        if body.is_fixed() || resting_kinematic {
            Some(STATIC_BODY)
        } else {
            (solver != NO_SOLVER).then_some(solver)
        }
    };
    let inv_mass = |i: u32| {
        input
            .solver_bodies
            .get(i as usize)
            .map_or(0.0, |b| b.inv_mass)
    };
    // A pair's points are listed together: their bodies are looked up once.
    type Pair = (jostle_body::BodyHandle, jostle_body::BodyHandle);
    let mut last: Option<(Pair, Option<(u32, u32)>)> = None;
    for i in range {
        let c = &input.contacts[i];
        let indices = match last {
            Some((pair, indices)) if pair == (c.a, c.b) => indices,
            _ => {
                let indices = index_of(c.a).zip(index_of(c.b));
                last = Some(((c.a, c.b), indices));
                indices
            }
        };
        let Some((a, b)) = indices else {
            continue;
        };
        if a == STATIC_BODY && b == STATIC_BODY {
            continue;
        }
        // Nothing to resolve between two bodies that nothing can push (kinematic ones).
        if inv_mass(a) == 0.0 && inv_mass(b) == 0.0 {
            continue;
        }
        // Static friction holds a contact that is not sliding; a sliding one feels the
        // dynamic coefficient for this step.
        let friction = match c.dynamic_friction {
            Some(d) if input.sliding.get(i).copied().unwrap_or(false) => d,
            _ => c.friction,
        };
        let mut contact = Contact::new(a, b, c.point, c.normal, c.penetration)
            .with_friction(friction)
            .with_restitution(c.restitution);
        contact.impulse = c.impulse;
        contact.point_b = c.point_b;
        contact.preload = c.preload;
        keep(contact, i as u32);
    }
}

/// Continuous collision detection, between the resolver and the copy back: every awake body
/// whose motion in the step (from its pose in `bodies`, where contacts were detected, to the
/// pose the resolver left in `scratch.bodies`) exceeds `settings.motion_fraction` of its
/// thickness, or whose mode is `On`, is swept against resting geometry ([`jostle_collide::sweep`]);
/// on a hit it is moved back along its motion to the time of impact, velocities kept (the
/// angular one in the body's frame) less the acceleration of the dropped part of the step, so the
/// next step's contact resolves the impact (the seed lecture's "move them back to the point
/// of first collision"). A slow body costs one motion test: a few multiplies and two square
/// roots.
#[allow(clippy::too_many_arguments)]
pub(crate) fn ccd(
    bodies: &BodySet,
    colliders: &ColliderSet,
    broad: &BroadPhase,
    settings: &CcdSettings,
    dt: f32,
    scratch: &mut Scratch,
    p: &mut StepProfile,
) {
    if !settings.enabled {
        return;
    }
    scratch.ccd_stops.clear();
    if scratch.bodies.len() <= 1 {
        // Only the static entry: no body moved this step (all asleep, fixed or resting
        // kinematic), so none is swept; the colliders are not walked.
        p.ccd_hits = 0;
        return;
    }
    // First which colliders are fast (swept); those of other awake bodies are slow targets,
    // taken at their start poses (a bullet into a stack of awake boxes).
    scratch.ccd_fast.clear();
    scratch.ccd_fast.resize(colliders.capacity_index(), false);
    for (handle, collider) in colliders.iter() {
        // A sensor stops nothing and is stopped by nothing.
        if !collider.sensor
            && sweep_motion(
                bodies,
                collider,
                collider.ccd_shape(),
                settings,
                dt,
                scratch,
            )
            .is_some()
        {
            scratch.ccd_fast[handle.index() as usize] = true;
        }
    }
    for (handle, collider) in colliders.iter() {
        if !scratch.ccd_fast[handle.index() as usize] {
            continue;
        }
        let shape = collider.ccd_shape();
        let (Some(body), Some((solver, motion))) = (
            bodies.get(collider.body),
            sweep_motion(bodies, collider, shape, settings, dt, scratch),
        ) else {
            continue;
        };
        let end = &scratch.bodies[solver as usize];
        p.ccd_bodies += 1;
        let fast = &scratch.ccd_fast;
        // Against moving bodies only a bullet, a body that moves more than its own thickness
        // in the step, or one in `CcdMode::On`: stopping every fast body of a rain of boxes
        // at the boxes below rewound it into the ones behind it (`assets/rain_1000.ron`'s
        // largest penetration rose from 0.20 to 0.47 m).
        let bullet = motion > shape.thickness || body.ccd == CcdMode::On;
        let slow = |target: ColliderHandle| {
            bullet
                && !fast.get(target.index() as usize).copied().unwrap_or(true)
                && colliders
                    .get(target)
                    .and_then(|c| bodies.get(c.body))
                    .is_some_and(|b| !b.is_fixed())
        };
        let hit = jostle_collide::sweep(
            collider,
            shape,
            Pose::from_parts(body.position, body.orientation),
            Pose::from_parts(end.position, end.orientation),
            end.angular_velocity * dt,
            slow,
            colliders,
            bodies,
            broad,
            settings,
            &mut scratch.ccd_candidates,
        );
        if let Some(hit) = hit {
            scratch.ccd_stops.push(CcdStop {
                solver,
                fraction: hit.fraction,
                collider: handle,
                target: hit.collider,
                stop: hit.stop,
                impact: hit.impact,
                contact: hit.contact,
                core: hit.core,
            });
        }
    }
    // A body with several colliders stops at the earliest of their hits.
    scratch
        .ccd_stops
        .sort_unstable_by(|a, b| (a.solver.cmp(&b.solver)).then(a.fraction.total_cmp(&b.fraction)));
    scratch.ccd_stops.dedup_by_key(|s| s.solver);
    p.ccd_hits = scratch.ccd_stops.len();
    for stop in &scratch.ccd_stops {
        let (solver, t) = (stop.solver, stop.fraction);
        let slot = scratch.body_slot[solver as usize];
        let Some((_, start)) = bodies.by_index(slot) else {
            continue;
        };
        let end = &mut scratch.bodies[solver as usize];
        let end_position = end.position;
        end.position = stop.stop.translation;
        end.linear_velocity = rewound_velocity(
            end.linear_velocity,
            end.last_acceleration,
            end.position - end_position,
            (1.0 - t) * dt,
        );
        // Turned back with the body, the angular velocity keeps its body-frame value, so the
        // rotational energy ½ωᵀIω is unchanged; kept in world frame it would meet a different
        // world inertia and change the energy (found by tests/properties.rs).
        let orientation = stop.stop.rotation;
        end.angular_velocity = (orientation * end.orientation.inverse()) * end.angular_velocity;
        end.orientation = orientation;

        // The impact itself, resolved here against what the body hit (issue 16): kept
        // approaching, a body whose resolver could not stop it (a needle spun up by its first
        // bounce, whose far end then swings through a thin floor) was stopped at the same pose
        // step after step while the resolver's impulses at that pose pumped its spin.
        let (Some(collider), Some(target)) =
            (colliders.get(stop.collider), colliders.get(stop.target))
        else {
            continue;
        };
        let repeated = (scratch.ccd_previous)
            .binary_search(&(slot, stop.target))
            .is_ok();
        // Only a body stopped on the same collider in the step before: after a first stop the
        // next step's contacts resolve the impact, all its points together and with the
        // resolver's restitution; resolving every first stop here as well measured worse
        // (soft step, the CCD sweep of benches/RESULTS.md: 10 of 360 shots frozen against 6).
        // A sleeping target is left to the next step's contact, which wakes it and shares the
        // impact.
        // A body whose centre reached the surface is half into it already: resolved at once.
        if !(repeated || stop.core) || !bodies.get(target.body).is_some_and(|b| b.is_fixed()) {
            continue;
        }
        // At the impact pose, where the point that hits is found; the impulse is applied there
        // (the velocities are those of the stop, the same but for the backed-off turn).
        let at = stop.impact;
        let reach = CCD_CONTACT_REACH * settings.slop;
        let contact = stop
            .contact
            .or_else(|| jostle_collide::ccd::stop_contact(collider, at, target, bodies, reach));
        if let Some(c) = contact {
            let turn = at.rotation * end.orientation.inverse();
            let w = turn * end.angular_velocity;
            let inv_inertia = start.inv_inertia_world_at(at.rotation);
            let (v, w) = impact_velocity(
                (end.linear_velocity, w),
                end.inv_mass_axes(),
                inv_inertia,
                c.point - at.translation,
                c.normal,
                c.material,
            );
            end.linear_velocity = v;
            end.angular_velocity = turn.inverse() * w;
        }
    }
    scratch.ccd_previous.clear();
    for stop in &scratch.ccd_stops {
        let slot = scratch.body_slot[stop.solver as usize];
        scratch.ccd_previous.push((slot, stop.target));
    }
    scratch.ccd_previous.sort_unstable();
}

/// The solver index of `collider`'s body and its motion in the step (m: how far a point of
/// it moves at most) when CCD sweeps the collider this step: its body is
/// awake, in the step, with a finite end pose, and its motion in the step (from its pose in
/// `bodies` to the one the resolver left in `scratch.bodies`) exceeds
/// `settings.motion_fraction` of its thickness (`CcdMode::Auto`) or is not zero
/// (`CcdMode::On`). A slow body costs one motion test: a few multiplies and two square roots.
fn sweep_motion(
    bodies: &BodySet,
    collider: &jostle_collide::Collider,
    shape: &CcdShape,
    settings: &CcdSettings,
    dt: f32,
    scratch: &Scratch,
) -> Option<(u32, f32)> {
    let body = bodies.get(collider.body)?;
    if !body.is_awake() || body.is_immovable() || body.ccd == CcdMode::Off {
        return None;
    }
    let solver = scratch.solver_index[collider.body.index() as usize];
    if solver == NO_SOLVER {
        return None;
    }
    let end = &scratch.bodies[solver as usize];
    let distance = (end.position - body.position).length();
    let motion = shape.motion(distance, end.angular_velocity.length() * dt);
    let fast = match body.ccd {
        CcdMode::Auto => motion > settings.motion_fraction * shape.thickness,
        CcdMode::On => motion > 0.0,
        CcdMode::Off => false,
    };
    // A non-finite motion fails both tests above; a non-finite pose is quarantined by
    // `scatter`, never swept.
    (fast && end.position.is_finite() && end.orientation.is_finite()).then_some((solver, motion))
}

/// How far from what it hit (in CCD slops) a stopped body's contact is looked for: it stops
/// one slop short, or deeper when its core was cast from an overlapping start.
const CCD_CONTACT_REACH: f32 = 4.0;

/// The velocity `(v, ω)` of a body of inverse mass `inv_mass` (along each world axis: zero
/// along a locked one) and world inverse inertia
/// `inv_inertia` after an impact at the lever arm `r` (from its centre of mass) on a fixed
/// surface of normal `n` (toward the body), with the contact's `material`, as the seed
/// lecture's contact-space impulse: unchanged unless the point approaches; then the impulse
/// that leaves the point moving at −e·vₙ along n with no sliding, if it lies in the friction
/// cone; else dynamic friction, an impulse along n − μ·t̂ (t̂ the sliding direction) that
/// gives the same normal velocity; else (a lever arm that would turn that impulse into a
/// push along the surface) a frictionless one along n. Each is used only if it does not add
/// kinetic energy (ΔE = j·v_p + ½·jᵀ·K·j for the impulse j and the point velocity v_p), which
/// the frictionless one never does for e ≤ 1.
fn impact_velocity(
    (v, w): (Vec3, Vec3),
    inv_mass: Vec3,
    inv_inertia: Mat3,
    r: Vec3,
    n: Vec3,
    material: Material,
) -> (Vec3, Vec3) {
    let vp = v + w.cross(r);
    let vn = vp.dot(n);
    if vn.is_nan() || vn >= 0.0 {
        return (v, w);
    }
    let e = material.restitution.clamp(0.0, 1.0);
    let rx = skew(r);
    // K = m⁻¹·1 − [r]×·I⁻¹·[r]×: the point's velocity change per unit impulse.
    let k = Mat3::from_diagonal(inv_mass) - rx * inv_inertia * rx;
    let adds_energy = |j: Vec3| j.dot(vp) + 0.5 * j.dot(k * j) > 0.0;
    let apply = |j: Vec3| (v + j * inv_mass, w + inv_inertia * r.cross(j));
    let usable = |j: Vec3| j.is_finite() && j.dot(n) >= 0.0 && !adds_energy(j);

    let target = n * (-e * vn);
    let stick = k.inverse() * (target - vp);
    let jn = stick.dot(n);
    if usable(stick) && (stick - n * jn).length() <= material.friction * jn {
        return apply(stick);
    }
    let slide = vp - n * vn;
    if slide.length_squared() > 0.0 {
        let direction = n - slide.normalize() * material.friction;
        let lambda = -(1.0 + e) * vn / n.dot(k * direction);
        let j = direction * lambda;
        if lambda > 0.0 && usable(j) {
            return apply(j);
        }
    }
    let lambda = -(1.0 + e) * vn / n.dot(k * n);
    if lambda.is_finite() && lambda > 0.0 {
        apply(n * lambda)
    } else {
        (v, w)
    }
}

/// The velocity of a body moved back by `moved` (m) to a time `dropped` seconds before the end
/// of the step, from its end-of-step velocity `v` under the acceleration `a` it was integrated
/// with: v − a·λ with λ = `dropped` (the velocity at that time, for a body in free flight),
/// unless that would raise its mechanical energy ½v² − a·x, in which case λ is the value
/// nearest to `dropped` that keeps it (it may be negative: a body put back higher still rising
/// pays for the height with the part of its speed along a, never with the rest).
///
/// Why: kept at `v`, a body stopped early carried a whole step of gravity's speed for part of
/// the fall that pays for it (m·g·|v|·dt·(1 − t) of energy per stop: a restitution-1 box's
/// bounces rose, and a body stopped step after step piled speed up in the air); interpolated
/// back to the step's start instead, the contacts' work was undone too, and a plate the
/// resolver had already stopped on a floor was sent down again and stopped again, every step;
/// and a body that bounced at the end of the step, put back higher, gained the height
/// (benches/RESULTS.md, "Restitution 1 never raises a bounce").
fn rewound_velocity(v: Vec3, a: Vec3, moved: Vec3, dropped: f32) -> Vec3 {
    let aa = a.length_squared();
    if aa.is_nan() || aa <= 0.0 {
        return v;
    }
    // Energy change per unit mass against the end: f(λ) = ½|a|²λ² − (a·v)λ + lift.
    let lift = -a.dot(moved);
    let av = a.dot(v);
    let change = |l: f32| 0.5 * aa * l * l - av * l + lift;
    let free_flight = change(dropped);
    if free_flight.is_nan() || free_flight <= 0.0 {
        return v - a * dropped;
    }
    let discriminant = av * av - 2.0 * aa * lift;
    if discriminant >= 0.0 {
        // f ≤ 0 between its roots: the λ there nearest to `dropped`.
        let (low, high) = (
            (av - discriminant.sqrt()) / aa,
            (av + discriminant.sqrt()) / aa,
        );
        return v - a * dropped.clamp(low, high);
    }
    // Not even all of its speed along a pays for the height: that part goes, and the rest
    // of the speed is lowered to what is left.
    let along = a * (av / aa);
    let rest = v - along;
    let budget = rest.length_squared() - 2.0 * change(av / aa);
    rest * (budget.max(0.0) / rest.length_squared().max(f32::MIN_POSITIVE)).sqrt()
}

/// Copies poses and velocities back into the bodies, the contacts' impulses and preloads back
/// into the narrow phase's contact list (its persistent points take them at its next update),
/// and quarantines bodies whose new state is not finite or beyond the limits (a position
/// beyond [`crate::MAX_POSITION`], a speed beyond [`crate::MAX_SPEED`], a spin beyond
/// [`crate::MAX_REACHED_ANGULAR_SPEED`]).
pub(crate) fn scatter(
    bodies: &mut BodySet,
    narrow: &mut NarrowPhase,
    scratch: &mut Scratch,
    report: &mut StepReport,
    dt: f32,
) {
    scratch.moved.clear();
    scratch.moved.resize(bodies.capacity_index(), 0.0);
    let inv_dt = 1.0 / dt;
    for (solver, &slot) in scratch.bodies.iter().zip(&scratch.body_slot).skip(1) {
        let Some((handle, _)) = bodies.by_index(slot) else {
            continue;
        };
        let Some(body) = bodies.get_mut(handle) else {
            continue;
        };
        let finite = solver.position.is_finite()
            && solver.orientation.is_finite()
            && solver.linear_velocity.is_finite()
            && solver.angular_velocity.is_finite();
        // Beyond the limits a scene's body is held to, the state is no longer one the engine
        // holds (f32 resolves 6 cm at 10⁶ m), and a snapshot of it would be refused on loading
        // (a ball thrown at 99,999 m/s with `--dt 1` was 1.1·10⁶ m out after 11 steps and went
        // on to 10⁸ m; its snapshot could not be read back).
        let in_range = solver.position.abs().max_element() <= crate::MAX_POSITION
            && solver.linear_velocity.length() <= crate::MAX_SPEED
            && solver.angular_velocity.length() <= crate::MAX_REACHED_ANGULAR_SPEED;
        if !(finite && in_range) {
            body.freeze();
            report.quarantined.push((handle, body.name.clone()));
            continue;
        }
        // (2·sin(Δθ/2))² = 4·(1 − cos²(Δθ/2)), Δθ² to second order, without an acos.
        let cos_half = solver.orientation.dot(body.orientation);
        let turned_sq = 4.0 * (1.0 - cos_half * cos_half).max(0.0);
        scratch.moved[slot as usize] =
            (solver.position - body.position).length_squared() * inv_dt * inv_dt
                + turned_sq * inv_dt * inv_dt;
        body.position = solver.position;
        body.orientation = solver.orientation;
        body.linear_velocity = if body.is_kinematic() {
            solver.linear_velocity
        } else {
            body.without_locked_motion(solver.linear_velocity)
        };
        // (A locked axis gains no turn in the solve but for rounding, which is dropped.)
        body.angular_velocity = body.without_locked_turn(solver.angular_velocity);
        body.last_acceleration = solver.last_acceleration;
        body.update_world_inertia();
    }
    // Position-based kinematic bodies end exactly where they were sent.
    for &(handle, position, orientation) in &scratch.kinematic_targets {
        if let Some(body) = bodies.get_mut(handle) {
            body.position = position;
            body.orientation = orientation;
            body.update_world_inertia();
        }
    }
    for (_, body) in bodies.iter_mut() {
        body.clear_forces();
    }
    // Contacts the resolver did not see (between two fixed or sleeping bodies) keep theirs.
    let (contacts, sources) = (&scratch.contacts, &scratch.contact_source);
    narrow.store_points_with(
        contacts.len().min(sources.len()),
        &|i| {
            let c = &contacts[i];
            (sources[i] as usize, c.impulse, c.preload)
        },
        &scratch.narrow_runner,
    );
}

/// When sleeping is enabled: updates motion averages, finds islands and puts resting islands to
/// sleep. Always: fills the profile's body counters (and the island count when enabled).
pub(crate) fn sleep(
    bodies: &mut BodySet,
    islands: &mut IslandSet,
    contacts: &[BodyContact],
    settings: &SleepSettings,
    dt: f32,
    scratch: &mut Scratch,
    p: &mut StepProfile,
) {
    let Scratch {
        moved, qualifies, ..
    } = scratch;
    // With sleeping disabled no island can go to sleep, so none is looked for (bodies that
    // fell asleep before it was disabled keep their islands, which still wake together).
    // A kinematic body is awake while it moves; it never joins an island.
    for (_, body) in bodies.iter_mut() {
        if body.is_kinematic() {
            body.sleep.awake = body.kinematic_moves();
        }
    }
    if settings.enabled {
        qualifies.clear();
        qualifies.resize(bodies.capacity_index(), false);
        for (h, body) in bodies.iter_mut() {
            if body.is_awake() && !body.is_kinematic() {
                let i = h.index() as usize;
                qualifies[i] =
                    update_motion(body, settings, dt, moved.get(i).copied().unwrap_or(0.0));
            }
        }
        islands.update(bodies, contacts.iter().map(|c| (c.a, c.b)), qualifies);
        p.islands_count = islands.awake_islands();
    }
    for (_, body) in bodies.iter() {
        if !body.is_immovable() {
            if body.sleep.awake {
                p.awake_bodies += 1;
            } else {
                p.sleeping_bodies += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jostle_body::RigidBody;
    use jostle_math::Quat;

    /// Splits into `.0` parts, run last first on the calling thread.
    struct Parts(usize);

    impl Runner for Parts {
        fn parts(&self, _items: usize) -> usize {
            self.0
        }
        fn run(&self, n: usize, f: &(dyn Fn(usize) + Sync)) {
            (0..n).rev().for_each(f);
        }
    }

    #[test]
    fn contacts_converted_in_parts_are_those_converted_in_one() {
        // A ground, three awake dynamic bodies and a sleeping one; the contacts with the
        // sleeper and between two fixed bodies are not converted, so runs of the output keep
        // fewer contacts than they have and the runs after them move down.
        let mut bodies = BodySet::new();
        let ground = bodies.insert(RigidBody::fixed());
        let ground_2 = bodies.insert(RigidBody::fixed());
        let body = |bodies: &mut BodySet, x: f32| {
            let b = RigidBody::dynamic(1.0, Mat3::IDENTITY).expect("a valid mass");
            bodies.insert(b.with_pose(Vec3::new(x, 0.5, 0.0), Quat::IDENTITY))
        };
        let awake = [
            body(&mut bodies, 0.0),
            body(&mut bodies, 2.0),
            body(&mut bodies, 4.0),
        ];
        let asleep = body(&mut bodies, 6.0);
        let mut solver_index = vec![NO_SOLVER; bodies.capacity_index()];
        let mut solver_bodies = vec![SolverBody::STATIC];
        for h in awake {
            solver_index[h.index() as usize] = solver_bodies.len() as u32;
            let b = bodies.get(h).expect("inserted");
            solver_bodies.push(SolverBody::new(
                b.position,
                b.orientation,
                1.0,
                Mat3::IDENTITY,
            ));
        }
        let pairs = [
            (awake[0], ground),
            (asleep, ground),
            (awake[1], awake[0]),
            (ground_2, ground),
            (awake[2], asleep),
            (awake[2], awake[1]),
        ];
        let contacts: Vec<BodyContact> = (0..61)
            .map(|i| {
                let (a, b) = pairs[(i / 3) % pairs.len()];
                BodyContact {
                    a,
                    b,
                    point: Vec3::new(i as f32, 0.0, 0.0),
                    point_b: Vec3::new(i as f32, -0.01, 0.0),
                    normal: Vec3::Y,
                    penetration: 0.01,
                    friction: 0.5,
                    dynamic_friction: None,
                    restitution: 0.0,
                    impulse: Vec3::new(1.0, 0.0, i as f32),
                    preload: 1e-4 * i as f32,
                }
            })
            .collect();
        let input = ContactInputs {
            bodies: &bodies,
            contacts: &contacts,
            solver_index: &solver_index,
            solver_bodies: &solver_bodies,
            sliding: &[],
        };
        let (mut one, mut one_sources) = (Vec::new(), Vec::new());
        convert_all(&input, &mut one, &mut one_sources, &Parts(1));
        assert!(
            one.len() > 20 && one.len() < contacts.len(),
            "{}",
            one.len()
        );
        assert!(one_sources.windows(2).all(|w| w[0] < w[1]));
        for parts in [2, 3, 7, 8] {
            // Outputs left over from a longer list, as between steps.
            let mut out = vec![one[0]; 100];
            let mut sources = vec![7; 100];
            convert_all(&input, &mut out, &mut sources, &Parts(parts));
            assert_eq!((&out, &sources), (&one, &one_sources), "{parts} parts");
        }
    }
}
