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
}

impl Default for CollideSettings {
    fn default() -> Self {
        Self {
            prediction: 0.02,
            reuse_linear: 1e-4,
            reuse_angular: 1e-4,
        }
    }
}
