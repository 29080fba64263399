//! Collision-detection settings: the tolerances of the narrow phase, in one place.

/// Settings of the narrow phase. Plain data; every field has a unit, a default and an effect.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CollideSettings {
    /// Contact prediction distance (m). Default 0.02.
    ///
    /// Contact points are produced for surfaces up to this far apart; their penetration is then
    /// negative (the separation). Speculative contacts let the resolver stop an approach before
    /// it becomes an overlap. The broad-phase margin should be at least half of it.
    pub prediction: f32,
    /// Linear reuse tolerance (m). Default 1e-4.
    ///
    /// When the relative translation of a pair's two colliders has changed by less than this
    /// since its manifold was last computed (and the rotation by less than `reuse_angular`),
    /// the manifold is reused: only the separations are refreshed from the stored local points.
    /// 0 disables reuse.
    pub reuse_linear: f32,
    /// Angular reuse tolerance (rad). Default 1e-4. See `reuse_linear`.
    pub reuse_angular: f32,
    /// Continuous collision detection ([`crate::ccd`]). Default: enabled.
    #[cfg_attr(feature = "serde", serde(default))]
    pub ccd: CcdSettings,
}

/// Settings of continuous collision detection ([`crate::ccd`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct CcdSettings {
    /// Whether CCD runs at all. Default true. When false the CCD stage returns at once and
    /// every body may tunnel through geometry thinner than one step's motion.
    pub enabled: bool,
    /// Motion fraction (dimensionless). Default 0.25.
    ///
    /// A body in `CcdMode::Auto` is swept when its motion in the step, |Δx| + |ω|·dt·extent,
    /// exceeds this fraction of its smallest dimension (its thickness). Below it the narrow
    /// phase cannot miss a wall: the body cannot cross more than a quarter of itself between two
    /// detections. Larger is cheaper and less safe.
    pub motion_fraction: f32,
    /// Stopping distance (m). Default 0.005.
    ///
    /// A swept body is stopped this far short of the first surface it would hit, so the next
    /// step's narrow phase finds a speculative contact (keep it below `prediction`) and the
    /// resolver handles the impact with the body's full velocity.
    pub slop: f32,
}

impl Default for CcdSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            motion_fraction: 0.25,
            slop: 0.005,
        }
    }
}

impl Default for CollideSettings {
    fn default() -> Self {
        Self {
            prediction: 0.02,
            reuse_linear: 1e-4,
            reuse_angular: 1e-4,
            ccd: CcdSettings::default(),
        }
    }
}
