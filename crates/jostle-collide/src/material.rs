//! Surface materials and how two of them combine at a contact.
//!
//! In: per-collider friction (static and dynamic) and restitution. Out: the pair's mixed
//! values, which every contact between the two colliders carries to the resolver.

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
}

impl Default for Material {
    fn default() -> Self {
        Self {
            friction: 0.5,
            restitution: 0.0,
            dynamic_friction: None,
        }
    }
}

impl Material {
    /// A material with the given friction (static and dynamic alike) and restitution.
    pub fn new(friction: f32, restitution: f32) -> Self {
        Self {
            friction,
            restitution,
            dynamic_friction: None,
        }
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

    /// The material of a contact between `a` and `b` (ARCHITECTURE.md, "Conventions"):
    ///
    /// - friction = sqrt(μa·μb), the geometric mean: a frictionless surface (μ = 0) makes the
    ///   contact frictionless whatever the other is, and equal materials keep their μ; the
    ///   dynamic coefficients mix the same way (`None` when neither material has its own, so
    ///   μd ≤ μs holds for the mix when it holds for both);
    /// - restitution = max(ea, eb): the bouncier surface wins, so a rubber ball bounces on a
    ///   dead floor.
    ///
    /// The rule is symmetric: `mix(a, b) == mix(b, a)`.
    pub fn mix(a: Material, b: Material) -> Material {
        let mean = |x: f32, y: f32| (x * y).max(0.0).sqrt();
        Material {
            friction: mean(a.friction, b.friction),
            restitution: a.restitution.max(b.restitution),
            dynamic_friction: (a.dynamic_friction.is_some() || b.dynamic_friction.is_some())
                .then(|| mean(a.dynamic(), b.dynamic())),
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
}
