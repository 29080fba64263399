//! Surface materials and how two of them combine at a contact.
//!
//! In: per-collider friction (static and dynamic) and restitution. Out: the pair's mixed
//! values, which every contact between the two colliders carries to the resolver.

/// How two materials' coefficients combine at a contact ([`Material::mix`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Combine {
    /// sqrt(a·b): zero if either is zero, equal values kept. The default rule for friction.
    GeometricMean,
    /// (a + b) / 2.
    Average,
    /// min(a, b).
    Min,
    /// a·b.
    Multiply,
    /// max(a, b). The default rule for restitution.
    Max,
}

impl Combine {
    /// The two coefficients combined by this rule.
    pub fn apply(self, a: f32, b: f32) -> f32 {
        match self {
            Self::GeometricMean => (a * b).max(0.0).sqrt(),
            Self::Average => 0.5 * (a + b),
            Self::Min => a.min(b),
            Self::Multiply => a * b,
            Self::Max => a.max(b),
        }
    }

    /// The rule of a pair whose materials ask for `a` and `b` (`None`: the default rule): an
    /// explicit rule wins over none; of two explicit rules the later in the order
    /// `GeometricMean`, `Average`, `Min`, `Multiply`, `Max` wins, so the result does not
    /// depend on which collider is first.
    pub fn of_pair(a: Option<Combine>, b: Option<Combine>, default: Combine) -> Combine {
        a.max(b).unwrap_or(default)
    }
}

/// Surface properties of a collider.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Material {
    /// Coulomb friction coefficient μ (dimensionless, ≥ 0): the static coefficient μs, which
    /// holds a contact that is not sliding. Default 0.5.
    pub friction: f32,
    /// Coefficient of restitution e (dimensionless, 0 = no bounce, 1 = elastic). Default 0.
    pub restitution: f32,
    /// Dynamic friction coefficient μd (0 ≤ μd ≤ μs), acting on a contact that is sliding.
    /// Default `None`: the same as `friction`, so a material with one coefficient keeps its
    /// meaning. [`Material::dynamic`] gives the value either way.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub dynamic_friction: Option<f32>,
    /// How friction (static and dynamic) combines with the other material's. Default `None`:
    /// [`Combine::GeometricMean`], unless the other material names a rule.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub friction_combine: Option<Combine>,
    /// How restitution combines with the other material's. Default `None`: [`Combine::Max`],
    /// unless the other material names a rule.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub restitution_combine: Option<Combine>,
}

impl Default for Material {
    fn default() -> Self {
        Self::new(0.5, 0.0)
    }
}

impl Material {
    /// A material with the given friction (static and dynamic alike) and restitution.
    pub fn new(friction: f32, restitution: f32) -> Self {
        Self {
            friction,
            restitution,
            dynamic_friction: None,
            friction_combine: None,
            restitution_combine: None,
        }
    }

    /// This material with combine rules of its own for friction and restitution ([`Combine`]).
    pub fn with_combine(mut self, friction: Combine, restitution: Combine) -> Self {
        self.friction_combine = Some(friction);
        self.restitution_combine = Some(restitution);
        self
    }

    /// This material with a dynamic friction coefficient of its own (μd ≤ `friction`).
    pub fn with_dynamic_friction(mut self, dynamic: f32) -> Self {
        self.dynamic_friction = Some(dynamic);
        self
    }

    /// The dynamic friction coefficient μd: [`Material::dynamic_friction`], else `friction`.
    pub fn dynamic(&self) -> f32 {
        self.dynamic_friction.unwrap_or(self.friction)
    }

    /// The material of a contact between `a` and `b` (ARCHITECTURE.md, "Conventions"). By
    /// default:
    ///
    /// - friction = sqrt(μa·μb), the geometric mean: a frictionless surface (μ = 0) makes the
    ///   contact frictionless whatever the other is, and equal materials keep their μ; the
    ///   dynamic coefficients mix the same way (`None` when neither material has its own, so
    ///   μd ≤ μs holds for the mix when it holds for both: every rule is monotonic);
    /// - restitution = max(ea, eb): the bouncier surface wins, so a rubber ball bounces on a
    ///   dead floor.
    ///
    /// A material may name another rule ([`Material::friction_combine`],
    /// [`Material::restitution_combine`]); the pair's rule is [`Combine::of_pair`]. The result
    /// is symmetric: `mix(a, b) == mix(b, a)`, and carries no rule of its own.
    pub fn mix(a: Material, b: Material) -> Material {
        let friction = Combine::of_pair(
            a.friction_combine,
            b.friction_combine,
            Combine::GeometricMean,
        );
        let restitution =
            Combine::of_pair(a.restitution_combine, b.restitution_combine, Combine::Max);
        Material {
            friction: friction.apply(a.friction, b.friction),
            restitution: restitution.apply(a.restitution, b.restitution),
            dynamic_friction: (a.dynamic_friction.is_some() || b.dynamic_friction.is_some())
                .then(|| friction.apply(a.dynamic(), b.dynamic())),
            friction_combine: None,
            restitution_combine: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mixing_rules() {
        let a = Material::new(0.25, 0.2);
        let b = Material::new(1.0, 0.8);
        let m = Material::mix(a, b);
        assert!((m.friction - 0.5).abs() < 1e-6);
        assert_eq!(m.restitution, 0.8);
        assert_eq!(Material::mix(b, a), m);
        assert_eq!(Material::mix(Material::new(0.0, 0.0), b).friction, 0.0);
        assert!((Material::mix(a, a).friction - 0.25).abs() < 1e-6);
        assert_eq!(m.dynamic_friction, None);
        // A dynamic coefficient of its own mixes with the other's (its static one).
        let c = Material::new(0.64, 0.0).with_dynamic_friction(0.36);
        let m = Material::mix(c, Material::new(1.0, 0.0));
        assert!((m.friction - 0.8).abs() < 1e-6 && (m.dynamic() - 0.6).abs() < 1e-6);
        assert_eq!(Material::mix(Material::new(1.0, 0.0), c), m);
    }

    #[test]
    fn a_named_combine_rule_wins_over_the_default_whichever_side_names_it() {
        let ice = Material::new(0.1, 0.9).with_combine(Combine::Min, Combine::Min);
        let rubber = Material::new(0.9, 0.2);
        for m in [Material::mix(ice, rubber), Material::mix(rubber, ice)] {
            assert_eq!(m.friction, 0.1);
            assert_eq!(m.restitution, 0.2);
        }
        // Two named rules: the later in the order wins (Max over Multiply over Min ...).
        let a = Material::new(0.4, 0.5).with_combine(Combine::Multiply, Combine::Average);
        let b = Material::new(0.5, 0.1).with_combine(Combine::Average, Combine::Max);
        for m in [Material::mix(a, b), Material::mix(b, a)] {
            assert!((m.friction - 0.2).abs() < 1e-6, "multiply: {}", m.friction);
            assert_eq!(m.restitution, 0.5);
        }
        // Every rule keeps μd ≤ μs.
        for rule in [
            Combine::GeometricMean,
            Combine::Average,
            Combine::Min,
            Combine::Multiply,
            Combine::Max,
        ] {
            let a = Material::new(0.8, 0.0)
                .with_dynamic_friction(0.3)
                .with_combine(rule, rule);
            let m = Material::mix(a, Material::new(0.6, 0.0).with_dynamic_friction(0.5));
            assert!(m.dynamic() <= m.friction, "{rule:?}: {m:?}");
        }
    }
}
