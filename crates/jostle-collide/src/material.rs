//! Surface materials and how two of them combine at a contact.
//!
//! In: per-collider friction and restitution. Out: the pair's mixed values, which every
//! contact between the two colliders carries to the resolver.

/// Surface properties of a collider.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Material {
    /// Coulomb friction coefficient μ (dimensionless, ≥ 0). Default 0.5.
    pub friction: f32,
    /// Coefficient of restitution e (dimensionless, 0 = no bounce, 1 = elastic). Default 0.
    pub restitution: f32,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            friction: 0.5,
            restitution: 0.0,
        }
    }
}

impl Material {
    /// A material with the given friction and restitution.
    pub fn new(friction: f32, restitution: f32) -> Self {
        Self {
            friction,
            restitution,
        }
    }

    /// The material of a contact between `a` and `b` (ARCHITECTURE.md, "Conventions"):
    ///
    /// - friction = sqrt(μa·μb), the geometric mean: a frictionless surface (μ = 0) makes the
    ///   contact frictionless whatever the other is, and equal materials keep their μ;
    /// - restitution = max(ea, eb): the bouncier surface wins, so a rubber ball bounces on a
    ///   dead floor.
    ///
    /// The rule is symmetric: `mix(a, b) == mix(b, a)`.
    pub fn mix(a: Material, b: Material) -> Material {
        Material {
            friction: (a.friction * b.friction).max(0.0).sqrt(),
            restitution: a.restitution.max(b.restitution),
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
    }
}
