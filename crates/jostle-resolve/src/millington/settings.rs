//! The Millington resolver's tunables, in one place: tolerances, iteration
//! budgets, the projection method and the pick strategy.
//!
//! Every default is the value of the seed lecture / Cyclone unless its rustdoc says otherwise.

/// How the position pass moves two bodies out of penetration (seed lecture, "Choosing a
/// Resolution Method").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Projection {
    /// Method 3, nonlinear projection: the penetration is shared between linear and angular
    /// motion of both bodies in proportion to their linear (1/m) and angular inertia along the
    /// normal, with the angular share limited by `angular_limit`. The default.
    #[default]
    Nonlinear,
    /// Method 1, linear projection: both bodies are translated along the normal in proportion
    /// to their inverse masses; orientations are never touched. Cheaper, but moves a box
    /// resting on one corner sideways instead of letting it tip.
    Linear,
}

/// How each pass finds the worst contact. Both give bit-identical results (a tested
/// contract); they differ only in cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum PickStrategy {
    /// An indexed binary max-heap over the island's contacts plus a body → contacts adjacency
    /// list: a pick re-keys only the contacts that share a body with the resolved one, so it
    /// costs O(degree · log n). The default.
    #[default]
    Heap,
    /// Cyclone's original: rescan every contact of the island for every pick and update every
    /// contact that shares a body, O(n) per pick. Kept as the benchmark reference.
    LinearScan,
}

/// An iteration (pick) budget for one pass over one island: `max(fixed, per_contact × n)`
/// picks for an island of `n` contacts.
///
/// Cyclone's demos use `4 × contacts` for both passes; per-contact scaling keeps that
/// behaviour, and `fixed` stops tiny islands (a single contact that needs several picks after
/// its neighbours move it) from starving.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct IterationBudget {
    /// Minimum picks per island, whatever its size. Default 8.
    pub fixed: u32,
    /// Picks allowed per contact of the island. Default 4 (Cyclone's `4 × contacts`).
    pub per_contact: u32,
}

impl Default for IterationBudget {
    fn default() -> Self {
        Self {
            fixed: 8,
            per_contact: 4,
        }
    }
}

/// A scene file may write a budget as a plain number N (exactly N picks per island,
/// `velocity_iterations: 64`) or in full, `(fixed: 8, per_contact: 4)` (missing fields take the
/// defaults, unknown fields are errors). Written by hand rather than as an untagged enum:
/// serde's untagged buffering lost the fields of the named form `IterationBudget(fixed: ..)`
/// and silently fell back to the defaults.
#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for IterationBudget {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Budget;
        impl<'de> serde::de::Visitor<'de> for Budget {
            type Value = IterationBudget;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a number of picks or (fixed: N, per_contact: N)")
            }
            fn visit_u64<E: serde::de::Error>(self, n: u64) -> Result<Self::Value, E> {
                let fixed =
                    u32::try_from(n).map_err(|_| E::custom(format!("{n} picks is too many")))?;
                Ok(IterationBudget {
                    fixed,
                    per_contact: 0,
                })
            }
            fn visit_i64<E: serde::de::Error>(self, n: i64) -> Result<Self::Value, E> {
                u64::try_from(n)
                    .map_err(|_| E::custom(format!("a budget cannot be negative, got {n}")))
                    .and_then(|n| self.visit_u64(n))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut map: A,
            ) -> Result<Self::Value, A::Error> {
                let mut out = IterationBudget::default();
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "fixed" => out.fixed = map.next_value()?,
                        "per_contact" => out.per_contact = map.next_value()?,
                        other => {
                            return Err(serde::de::Error::unknown_field(
                                other,
                                &["fixed", "per_contact"],
                            ));
                        }
                    }
                }
                Ok(out)
            }
        }
        deserializer.deserialize_any(Budget)
    }
}

impl IterationBudget {
    /// The number of picks allowed for an island of `contacts` contacts (saturating).
    pub fn for_contacts(&self, contacts: usize) -> u32 {
        let n = u32::try_from(contacts).unwrap_or(u32::MAX);
        self.fixed.max(self.per_contact.saturating_mul(n))
    }
}

/// Settings of [`crate::millington::MillingtonResolver`].
///
/// Budgets apply **per island**: contacts are split into independent islands (bodies
/// connected through contacts, the static body connecting nothing) and each island gets its
/// own position and velocity budget sized by its own contact count. With the defaults this
/// is Cyclone's `4 × contacts` overall, but one badly-conditioned island can no longer
/// consume the picks another needs.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct MillingtonSettings {
    /// Pick budget of the position pass, per island. Default `max(8, 4 × contacts)`.
    pub position_iterations: IterationBudget,
    /// Pick budget of the velocity pass, per island. Default `max(8, 16 × contacts)`
    /// ([`MillingtonSettings::VELOCITY_PICKS_PER_CONTACT`]); Cyclone's is 4 × contacts.
    pub velocity_iterations: IterationBudget,
    /// Penetration (m) at or below which a contact is left alone by the position pass.
    /// Default 0.01 (Cyclone). Larger values leave resting bodies sunk deeper but pick less.
    pub position_epsilon: f32,
    /// Desired velocity change (m/s) at or below which a contact is left alone by the
    /// velocity pass. Default 1e-4 ([`MillingtonSettings::VELOCITY_EPSILON`]); Cyclone's is
    /// 0.01, see [`MillingtonSettings::cyclone`] for why jostle does not use it.
    ///
    /// What the pass leaves under it stays: a tall stack started slightly off its exact layout
    /// has every joint left turning at about this rate, and its height adds them up (20-box
    /// columns perturbed by 3 mm and 0.3° sway 4–18 cm at the default; with 1e-6 and
    /// `velocity_iterations` of 512 per contact they stay within 1 mm, at 30–45 times the
    /// cost). And at a long step it becomes height: a 1,000 kg box left rising at 4.4e-5 m/s
    /// over a 1 s step gains 0.43 J (the `jostle` crate's benches/RESULTS.md, "Why the
    /// Millington resolver's perturbed columns sway").
    pub velocity_epsilon: f32,
    /// Closing speed along the normal (m/s) below which restitution is ignored (the lecture's
    /// "lower the restitution" rule for micro-collisions): e′ = 0 when |v·n| < this.
    /// Default 0.25 (Cyclone).
    pub velocity_limit: f32,
    /// Largest angular share of a nonlinear projection, as a fraction of the contact's lever
    /// arm perpendicular to the normal, |r − (r·n)n| (dimensionless; the excess goes to the
    /// linear share). Default 0.2 (Cyclone). Ignored by [`Projection::Linear`].
    pub angular_limit: f32,
    /// Fraction of a contact's penetration resolved per pick (dimensionless, (0, 1]); the
    /// lecture's "relaxation". Default 1.0 (full resolution, Cyclone's behaviour).
    pub relaxation: f32,
    /// How penetration is resolved. Default [`Projection::Nonlinear`].
    pub projection: Projection,
    /// How the worst contact is found. Default [`PickStrategy::Heap`]; results are identical.
    pub pick: PickStrategy,
    /// Start the velocity pass from the impulses the contacts carried from the previous step
    /// (the narrow phase matches them by feature id): every resting contact (closing slower
    /// than `velocity_limit`) applies its carried impulse, clamped to a push and to its
    /// friction cone, before the first pick, and keeps its target (touching, or closing its
    /// gap) for the whole step, taking back what its neighbours' picks make too much.
    /// Default true (see [`MillingtonResolver`](super::MillingtonResolver)).
    pub warm_start: bool,
    /// Both passes first resolve every contact once, in order, before they pick worst-first
    /// (the lecture: "run through the entire list once, then prioritise"), out of the same
    /// budget. Default false.
    pub first_sweep: bool,
    /// After each pass's worst-first picks, when a contact is still above the pass's
    /// epsilon, resolve what is left from the ground up with each lower body held still, in
    /// islands that hold a mass ratio of [`super::shock::SHOCK_MASS_RATIO`] or more (shock
    /// propagation, [`super::shock`]). Default true: without it a light body under a much
    /// heavier one is squeezed out or pushed through the floor (a 1 kg box under 10⁶ kg),
    /// because each pick passes on only about m/M of the load.
    pub shock_sweep: bool,
    /// A velocity pick of a contact that wants a change of its normal velocity resolves the
    /// normal velocities of its whole manifold (its points with the same two bodies, at most
    /// four) together ([`super::velocity::resolve_manifold_normals`]); picks for sliding,
    /// and every pick in an island that holds a mass ratio of 10 or more (where the shock
    /// sweep works point by point), stay point by point. Default true: one point at a time,
    /// each corner's push tilts the box onto the others, and the picks run out before a
    /// stack settles. Measured at the defaults (benches/RESULTS.md, "Picks by manifold"):
    /// the 20-box column sways 1.9 mm instead of 96, the 20-row pyramid 6.1 mm instead of 54,
    /// and 30 of 38 members of the stability family meet its criterion instead of 21.
    pub manifold_picks: bool,
}

impl MillingtonSettings {
    /// jostle's default velocity epsilon (m/s).
    pub const VELOCITY_EPSILON: f32 = 1e-4;
    /// jostle's default velocity budget per contact.
    pub const VELOCITY_PICKS_PER_CONTACT: u32 = 16;
    /// Largest accepted `fixed` part of an iteration budget (picks per island and pass).
    pub const MAX_FIXED_PICKS: u32 = 1 << 16;
    /// Largest accepted `per_contact` part of an iteration budget: 1,024 picks per contact,
    /// 64 times the default velocity budget. Beyond it a step of a few thousand contacts
    /// could run for minutes (`velocity_iterations: 4294967295` made a first step that never
    /// finished).
    pub const MAX_PICKS_PER_CONTACT: u32 = 1024;

    /// Cyclone's settings: velocity epsilon 0.01 m/s, 4 velocity picks per contact, and
    /// neither warm start, shock sweep nor picks by manifold (Cyclone has none of them), the
    /// rest as the defaults.
    /// Cheaper than the defaults were without a warm start, but residual velocities below
    /// 0.01 m/s are left in every resting contact and a resting box walks: measured through
    /// the whole engine with sleep off, a unit box with μ = 0.5 on a 20° slope moves 69 mm
    /// between 1 s and 10 s at 60 Hz (0.58 mm with the defaults then), and a 10-row pyramid
    /// drifts 0.29 m between 2 s and 10 s (0.028 m) at about a fifth of the cost.
    pub fn cyclone() -> Self {
        Self {
            velocity_iterations: IterationBudget {
                fixed: 8,
                per_contact: 4,
            },
            velocity_epsilon: 0.01,
            warm_start: false,
            shock_sweep: false,
            manifold_picks: false,
            ..Self::default()
        }
    }
}

impl MillingtonSettings {
    /// Checks every field: the error is (field, message). The resolver does not panic on
    /// invalid settings, but these make its results meaningless (a zero velocity budget lets
    /// bodies fall through the ground, a negative angular limit created 48 kJ from rest, a
    /// negative relaxation gave penetrations of 10³⁸), so scene loading refuses them.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        for (field, budget) in [
            ("position_iterations", self.position_iterations),
            ("velocity_iterations", self.velocity_iterations),
        ] {
            if budget.for_contacts(1) == 0 {
                return Err((field, "must allow at least one pick".into()));
            }
            if budget.fixed > Self::MAX_FIXED_PICKS
                || budget.per_contact > Self::MAX_PICKS_PER_CONTACT
            {
                return Err((
                    field,
                    format!(
                        "at most {} fixed picks and {} per contact, got (fixed: {}, per_contact: {})",
                        Self::MAX_FIXED_PICKS,
                        Self::MAX_PICKS_PER_CONTACT,
                        budget.fixed,
                        budget.per_contact
                    ),
                ));
            }
        }
        let non_negative = |field: &'static str, x: f32| {
            if x.is_finite() && x >= 0.0 {
                Ok(())
            } else {
                Err((field, format!("must be finite and >= 0, got {x}")))
            }
        };
        non_negative("position_epsilon", self.position_epsilon)?;
        non_negative("velocity_epsilon", self.velocity_epsilon)?;
        non_negative("velocity_limit", self.velocity_limit)?;
        non_negative("angular_limit", self.angular_limit)?;
        if !(self.relaxation.is_finite() && self.relaxation > 0.0 && self.relaxation <= 1.0) {
            return Err((
                "relaxation",
                format!("must be in (0, 1], got {}", self.relaxation),
            ));
        }
        Ok(())
    }
}

impl Default for MillingtonSettings {
    fn default() -> Self {
        Self {
            position_iterations: IterationBudget::default(),
            velocity_iterations: IterationBudget {
                fixed: 8,
                per_contact: Self::VELOCITY_PICKS_PER_CONTACT,
            },
            position_epsilon: 0.01,
            velocity_epsilon: Self::VELOCITY_EPSILON,
            velocity_limit: 0.25,
            angular_limit: 0.2,
            relaxation: 1.0,
            projection: Projection::Nonlinear,
            pick: PickStrategy::Heap,
            warm_start: true,
            first_sweep: false,
            shock_sweep: true,
            manifold_picks: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_name_their_field() {
        assert_eq!(MillingtonSettings::default().validate(), Ok(()));
        assert_eq!(MillingtonSettings::cyclone().validate(), Ok(()));
        let zero = IterationBudget {
            fixed: 0,
            per_contact: 0,
        };
        let cases = [
            (
                MillingtonSettings {
                    velocity_iterations: zero,
                    ..Default::default()
                },
                "velocity_iterations",
            ),
            (
                MillingtonSettings {
                    position_iterations: IterationBudget {
                        fixed: 8,
                        per_contact: u32::MAX,
                    },
                    ..Default::default()
                },
                "position_iterations",
            ),
            (
                MillingtonSettings {
                    velocity_iterations: IterationBudget {
                        fixed: u32::MAX,
                        per_contact: 4,
                    },
                    ..Default::default()
                },
                "velocity_iterations",
            ),
            (
                MillingtonSettings {
                    velocity_epsilon: f32::NAN,
                    ..Default::default()
                },
                "velocity_epsilon",
            ),
            (
                MillingtonSettings {
                    angular_limit: -1.0,
                    ..Default::default()
                },
                "angular_limit",
            ),
            (
                MillingtonSettings {
                    relaxation: -1.0,
                    ..Default::default()
                },
                "relaxation",
            ),
            (
                MillingtonSettings {
                    relaxation: 1.5,
                    ..Default::default()
                },
                "relaxation",
            ),
        ];
        for (settings, field) in cases {
            assert_eq!(settings.validate().unwrap_err().0, field);
        }
    }

    #[test]
    fn budget_is_the_larger_of_fixed_and_per_contact() {
        let b = IterationBudget {
            fixed: 8,
            per_contact: 4,
        };
        assert_eq!(b.for_contacts(1), 8);
        assert_eq!(b.for_contacts(100), 400);
        assert_eq!(b.for_contacts(usize::MAX), u32::MAX);
    }
}

#[cfg(all(test, feature = "serde"))]
mod serde_tests {
    use super::*;

    #[test]
    fn budgets_round_trip_in_every_form() {
        let s = MillingtonSettings::default();
        for cfg in [
            ron::ser::PrettyConfig::default(),
            ron::ser::PrettyConfig::default().struct_names(true),
        ] {
            let text = ron::ser::to_string_pretty(&s, cfg).unwrap();
            let back: MillingtonSettings = ron::from_str(&text).unwrap();
            assert_eq!(back, s, "{text}");
        }
        let b: IterationBudget = ron::from_str("64").unwrap();
        assert_eq!(
            b,
            IterationBudget {
                fixed: 64,
                per_contact: 0
            }
        );
        let b: IterationBudget = ron::from_str("(per_contact: 2)").unwrap();
        assert_eq!(
            b,
            IterationBudget {
                fixed: 8,
                per_contact: 2
            }
        );
        assert!(ron::from_str::<IterationBudget>("(per_contct: 2)").is_err());
        assert!(ron::from_str::<IterationBudget>("-3").is_err());
    }
}
