//! World settings: gravity, the resolver and its settings, collision and sleep settings.
//! Plain structs; every field documents its unit, default and effect.

use jostle_collide::CollideSettings;
use jostle_math::Vec3;
use jostle_resolve::{
    MillingtonResolver, MillingtonSettings, Resolver, SoftStepResolver, SoftStepSettings,
};
use jostle_sleep::SleepSettings;

/// Which resolver a world uses, with its settings. In a scene file:
/// `resolver: Millington(velocity_iterations: 64)` or `resolver: SoftStep(substeps: 8)`.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum ResolverChoice {
    /// The seed lecture's resolver: worst-first position pass by nonlinear projection, then
    /// worst-first velocity pass with micro-collisions and 3×3 friction impulses.
    Millington(#[cfg_attr(feature = "serde", serde(default))] MillingtonSettings),
    /// Catto's soft step (Box2D v3's solver): substepped sequential impulses with soft
    /// contacts, warm starting, relax and restitution passes, and an implicit gyroscopic term.
    SoftStep(#[cfg_attr(feature = "serde", serde(default))] SoftStepSettings),
}

impl Default for ResolverChoice {
    /// The soft-step resolver: the one that measures best on the stability family and the
    /// analytic set (benches/RESULTS.md). Release, 60 Hz, sleep off: the 20-row pyramid costs
    /// 0.42 ms in its resolve stage and drifts 0.4 mm between 2 s and 20 s, where Millington
    /// costs 44–56 ms and lets it creep 0.21 m; a 10-box column stays up (Millington's falls);
    /// overlapping starts are separated without kinetic energy (split impulses). Millington
    /// stays one setting away: `ResolverChoice::Millington(Default::default())`, `resolver:
    /// Millington()` in a scene, `--resolver millington` on the command line.
    fn default() -> Self {
        Self::SoftStep(SoftStepSettings::default())
    }
}

impl ResolverChoice {
    /// The resolver names accepted on the command line, in order.
    pub const NAMES: [&'static str; 2] = ["millington", "soft-step"];

    /// The choice for a command-line resolver name with default settings, or an error message
    /// naming the accepted names.
    pub fn from_name(name: &str) -> Result<Self, String> {
        match name {
            "millington" => Ok(Self::Millington(MillingtonSettings::default())),
            "soft-step" => Ok(Self::SoftStep(SoftStepSettings::default())),
            other => Err(format!(
                "unknown resolver `{other}`; expected one of: {}",
                Self::NAMES.join(", ")
            )),
        }
    }

    /// The command-line name of this choice.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Millington(_) => "millington",
            Self::SoftStep(_) => "soft-step",
        }
    }

    /// Checks every setting of the chosen resolver; the error names the field.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        match self {
            Self::Millington(m) => m.validate(),
            Self::SoftStep(s) => s.validate(),
        }
    }

    /// Builds the resolver.
    pub fn build(&self) -> Box<dyn Resolver> {
        match self {
            Self::Millington(s) => Box::new(MillingtonResolver::new(s.clone())),
            Self::SoftStep(s) => Box::new(SoftStepResolver::new(s.clone())),
        }
    }
}

/// Everything a [`crate::World`] is configured with.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct WorldSettings {
    /// Gravity (m/s²). Default (0, −9.81, 0).
    pub gravity: Vec3,
    /// The resolver. Default: [`ResolverChoice::default`].
    pub resolver: ResolverChoice,
    /// Collision detection: prediction margin and manifold reuse tolerances.
    pub collide: CollideSettings,
    /// Sleep: threshold, bias, and whether sleeping is enabled at all.
    pub sleep: SleepSettings,
}

impl Default for WorldSettings {
    fn default() -> Self {
        Self {
            gravity: Vec3::new(0.0, -9.81, 0.0),
            resolver: ResolverChoice::default(),
            collide: CollideSettings::default(),
            sleep: SleepSettings::default(),
        }
    }
}
