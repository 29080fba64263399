//! The `Resolver` trait: the one contract every contact resolver meets.

use crate::{Contact, SolverBody};
use jostle_math::Vec3;
use std::time::Duration;

/// What a resolver needs to know about the step besides bodies and contacts.
/// Built fresh for every step, never stored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepContext {
    /// Gravity (m/s²), applied to every body with non-zero inverse mass.
    pub gravity: Vec3,
    /// Step length (s), finite and > 0.
    pub dt: f32,
}

/// What one resolver step did, for the step profile. Resolvers fill what applies to them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ResolveStats {
    /// Time spent integrating velocities and poses.
    pub integrate_time: Duration,
    /// Time spent preparing contacts (bases, lever arms, desired velocity changes).
    pub prepare_time: Duration,
    /// Time spent resolving interpenetration (position pass or soft-constraint bias).
    pub position_time: Duration,
    /// Time spent resolving velocities (impulses).
    pub velocity_time: Duration,
    /// Position iterations (picks) performed.
    pub position_iterations: u32,
    /// Velocity iterations (picks) performed.
    pub velocity_iterations: u32,
    /// What the position pass left unresolved: the largest key of any contact when it
    /// stopped (the Millington resolver: the deepest penetration, m), at its epsilon or below
    /// when it converged, above it when its budget ran out. 0 for resolvers without such a
    /// pass.
    pub position_residual: f32,
    /// What the velocity pass left unresolved: the largest key of any contact when it
    /// stopped (the Millington resolver: the largest velocity change still wanted, the
    /// normal one or the sliding speed friction can still take, m/s). 0 for resolvers
    /// without such a pass.
    pub velocity_residual: f32,
    /// Independent contact islands solved.
    pub islands: u32,
    /// Contact rows (normal and friction) solved directly this step, over all the islands
    /// the soft step solves exactly (heavy bodies on light ones, chains of bodies: its
    /// `direct` module); 0 for the Millington resolver. A column's cost follows it.
    pub direct_rows: u32,
    /// Threads that could take part in the step (the soft step's team, 1 when it ran alone;
    /// helpers busy with another world's step may have joined late or not at all).
    pub threads: u32,
}

/// A contact resolver: advances the awake bodies by one step of `dt`, resolving the given
/// contacts.
///
/// # Contract
/// - `bodies[STATIC_BODY]` is [`SolverBody::STATIC`] and must not be written. Every other
///   entry is an awake dynamic body; the resolver **owns its integration**: it applies gravity
///   to velocities, integrates velocities into poses (semi-implicit Euler, orientation by
///   [`jostle_math::integrate_orientation`]) and records `last_acceleration`. The velocity
///   change of the step's applied forces and damping comes separately
///   ([`SolverBody::force_velocity`], [`SolverBody::torque_velocity`]) and the resolver adds
///   it over the step as it adds gravity ([`crate::integrate::integrate_velocities`] does
///   both), so that what friction holds is held within each substep.
/// - `contacts` were detected on the poses the bodies have on entry. The resolver may reorder
///   nothing and must write each contact's `impulse` (contact space, on A); it may update
///   `penetration` to the value it believes remains.
/// - Units are SI; the normal points from B toward A; penetration is positive on overlap.
/// - No panics on finite input. Non-finite input may produce non-finite output, which the
///   caller detects and quarantines.
/// - Deterministic: the same inputs give bit-identical outputs.
///
/// The Millington resolver integrates velocities, resolves, then integrates poses; a
/// substepping resolver integrates inside its substeps. Both fit this one method.
pub trait Resolver: Send {
    /// Short stable name (`"millington"`, `"soft-step"`), as used on the command line.
    fn name(&self) -> &'static str;

    /// The largest ratio of two touching dynamic bodies' masses whose contacts this resolver
    /// holds, where it has such a bound (the caller reports pairs beyond it); `None` (the
    /// default) where none is known.
    fn max_mass_ratio(&self) -> Option<f32> {
        None
    }

    /// Advances `bodies` by one step, resolving `contacts`. See the trait's contract.
    fn step(
        &mut self,
        bodies: &mut [SolverBody],
        contacts: &mut [Contact],
        ctx: &StepContext,
    ) -> ResolveStats;
}
