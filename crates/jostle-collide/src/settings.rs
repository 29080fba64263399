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
    /// Angular reuse tolerance (rad). Default 1e-4. See `reuse_linear`. Also how far a reused
    /// pair's colliders may turn before its held contact frames (`frame_tolerance`) are
    /// checked against fresh ones again.
    pub reuse_angular: f32,
    /// Contact-frame tolerance (m). Default 0.004.
    ///
    /// A contact point that persists (same features) keeps the normal and the two lever arms
    /// (its offsets from each body's centre of mass, in world space) it had when they were
    /// last taken, until either lever arm has moved more than this, or more than 5% of the
    /// smaller collider's reach radius ([`crate::Collider::reach_radius`]: bodies smaller than
    /// about 0.1 m hold their frames in proportion to their size), or the normal has turned
    /// more than `frame_angle_tolerance`; then they are taken again. Contact forces that do
    /// not turn with small sways of the bodies do not feed those sways (a tall column whose
    /// contacts follow every tilt leans further under its own weight, see the `jostle`
    /// crate's ARCHITECTURE.md). 0 takes them fresh every update. At 0.002 four perturbed or
    /// 0.1 m columns of 40 and 60 boxes fell in the stability family's tall set; at 0.004,
    /// 0.008 and 0.016 none falls and the family meets its criterion as before, but at 0.008 a
    /// light box under a box ten times heavier drifts past 1 cm with the Millington resolver
    /// (the `jostle` crate's benches/RESULTS.md, "Lever arms held up to 4 mm").
    #[cfg_attr(feature = "serde", serde(default = "default_frame_tolerance"))]
    pub frame_tolerance: f32,
    /// Contact-frame angular tolerance (rad). Default 0.05 (about 3°).
    ///
    /// How far a held contact normal may lag the fresh one (`frame_tolerance`). An angle of
    /// its own, so that holding does not depend on the bodies' size: a sway of a few
    /// millimetres tilts a column of 0.1 m boxes ten times further than one of 1 m boxes
    /// (with the normal held to 0.002 rad, a column of twenty 0.1 m boxes fell where the same
    /// column of 1 m boxes stood). A held normal is at most this far from the true one, so a
    /// contact force may lean by as much (a tangential share of sin 0.05 = 5%).
    #[cfg_attr(feature = "serde", serde(default = "default_frame_angle_tolerance"))]
    pub frame_angle_tolerance: f32,
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
    /// Whether CCD runs at all. Default true. When false the CCD stage returns at once, the
    /// speculative contacts that grow with speed are not looked for (the broad and narrow
    /// phase use the plain prediction distance: `NarrowPhase::update_swept` with no step),
    /// and every body may tunnel through geometry thinner than one step's motion.
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

impl CollideSettings {
    /// Checks every field against its domain; the error names the field (`ccd.slop`) and
    /// what it must be.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let non_negative = |name, v: f32| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err((name, format!("must be finite and >= 0, got {v}")))
            }
        };
        non_negative("prediction", self.prediction)?;
        non_negative("reuse_linear", self.reuse_linear)?;
        non_negative("reuse_angular", self.reuse_angular)?;
        non_negative("frame_tolerance", self.frame_tolerance)?;
        let angle = self.frame_angle_tolerance;
        if !(angle.is_finite() && (0.0..=std::f32::consts::PI).contains(&angle)) {
            return Err((
                "frame_angle_tolerance",
                format!("must be between 0 and pi (rad), got {angle}"),
            ));
        }
        let fraction = self.ccd.motion_fraction;
        if !(fraction.is_finite() && fraction > 0.0) {
            return Err((
                "ccd.motion_fraction",
                format!("must be finite and > 0, got {fraction}"),
            ));
        }
        non_negative("ccd.slop", self.ccd.slop)
    }
}

impl Default for CollideSettings {
    fn default() -> Self {
        Self {
            prediction: 0.02,
            reuse_linear: 1e-4,
            reuse_angular: 1e-4,
            frame_tolerance: default_frame_tolerance(),
            frame_angle_tolerance: default_frame_angle_tolerance(),
            ccd: CcdSettings::default(),
        }
    }
}

/// [`CollideSettings::frame_tolerance`]'s default (m).
fn default_frame_tolerance() -> f32 {
    0.004
}

/// [`CollideSettings::frame_angle_tolerance`]'s default (rad).
fn default_frame_angle_tolerance() -> f32 {
    0.05
}
