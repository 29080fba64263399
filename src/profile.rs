//! The per-step profile: the time of every pipeline stage and the counters that explain it.

use std::time::Duration;

/// What the last [`crate::World::step`] did and how long each stage took. Built fresh by every
/// step; read it with [`crate::World::profile`]. The times are wall-clock times, zero where the
/// platform has no clock (`wasm32-unknown-unknown`, [`jostle_resolve::clock`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepProfile {
    /// Whole step.
    pub total: Duration,
    /// Broad phase: candidate pairs from AABBs.
    pub broad_phase: Duration,
    /// Narrow phase: persistent contact manifolds.
    pub narrow_phase: Duration,
    /// Islands and wake-up.
    pub islands: Duration,
    /// Copying awake bodies and contacts into the solver arrays, applying forces.
    pub gather: Duration,
    /// The resolver (integration included; see `resolve_stats` for its parts).
    pub resolve: Duration,
    /// Continuous collision detection: the motion test of every awake body and the sweeps of
    /// the fast ones (between the resolver and the copy back).
    pub ccd: Duration,
    /// Copying results back, finiteness checks.
    pub scatter: Duration,
    /// Sleep update.
    pub sleep: Duration,
    /// The resolver's own breakdown.
    pub resolve_stats: jostle_resolve::ResolveStats,
    /// Candidate pairs from the broad phase.
    pub candidate_pairs: usize,
    /// Contact manifolds with at least one point.
    pub manifolds: usize,
    /// Contact points handed to the resolver.
    pub contact_points: usize,
    /// Manifolds reused because their pair's relative pose did not change.
    pub manifolds_reused: usize,
    /// Candidate pairs without contacts whose contact query was skipped: the direction that
    /// last kept their shapes apart still keeps them further apart than the prediction
    /// distance ([`jostle_collide::NarrowStats::kept_apart`]).
    pub pairs_kept_apart: usize,
    /// Parts the narrow phase's pairs were split into, one per thread that may run them (1
    /// below 256 pairs, on one thread, or when the last step's substeps ran on one thread;
    /// [`jostle_collide::NarrowPhase::update_with`]).
    pub narrow_parts: usize,
    /// Awake dynamic bodies at the end of the step.
    pub awake_bodies: usize,
    /// Sleeping dynamic bodies at the end of the step.
    pub sleeping_bodies: usize,
    /// Islands of touching awake bodies this step; 0 when sleeping is disabled (islands are
    /// only looked for to put them to sleep).
    pub islands_count: usize,
    /// Bodies swept by continuous collision detection this step (fast ones, or forced on).
    pub ccd_bodies: usize,
    /// Swept bodies stopped at a time of impact this step.
    pub ccd_hits: usize,
}

impl StepProfile {
    /// The stages in pipeline order with their times, for tables. The `ccd` stage is not listed
    /// yet (`run.rs` sizes its table for these seven); read [`StepProfile::ccd`].
    pub fn stages(&self) -> [(&'static str, Duration); Self::STAGES] {
        [
            ("broad", self.broad_phase),
            ("narrow", self.narrow_phase),
            ("islands", self.islands),
            ("gather", self.gather),
            ("resolve", self.resolve),
            ("ccd", self.ccd),
            ("scatter", self.scatter),
            ("sleep", self.sleep),
        ]
    }

    /// Number of timed stages in [`StepProfile::stages`].
    pub const STAGES: usize = 8;
}
