//! Mass properties of shape descriptions, computed by parry.
//!
//! In: a [`ShapeDesc`] and a density. Out: [`MassProps`] (mass, centre of mass and inertia
//! tensor about it, in the shape's frame), which the facade turns into a `RigidBody`.
//! Shapes without a finite volume (half-spaces, triangle meshes) have no mass properties: they
//! are rejected with [`ShapeError::NotDynamic`], since they may only sit on fixed bodies.

use crate::shape::{ShapeDesc, ShapeError};
use jostle_math::{Mat3, Vec3};
use parry3d::mass_properties::MassProperties;
use parry3d::math::Pose;

/// Mass, centre of mass and inertia of a solid shape of uniform density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProps {
    /// Mass (kg).
    pub mass: f32,
    /// Centre of mass in the shape's frame (m).
    pub local_com: Vec3,
    /// Inertia tensor (kg·m²) about the centre of mass, axes of the shape's frame.
    pub inertia: Mat3,
}

impl MassProps {
    /// The same shape with its density changed so that it weighs `mass` kg: mass and inertia
    /// scale by `mass / self.mass`, the centre of mass stays. The result is not validated
    /// (a non-positive `mass` gives a non-positive inertia, which `RigidBody::dynamic` rejects).
    pub fn scaled_to_mass(&self, mass: f32) -> MassProps {
        let s = mass / self.mass;
        MassProps {
            mass,
            local_com: self.local_com,
            inertia: self.inertia * s,
        }
    }

    /// These properties seen from a frame in which the shape sits at `pose`
    /// (a collider's local pose): the centre of mass moves, the inertia rotates.
    pub fn transformed(&self, pose: &Pose) -> MassProps {
        from_parry(&to_parry(self).transform_by(pose))
    }

    /// The mass properties of several parts rigidly joined (all in one frame): masses add,
    /// the centre of mass is the mass-weighted mean, inertias are moved to it by the
    /// parallel-axis theorem. `None` for an empty slice.
    pub fn combine(parts: &[MassProps]) -> Option<MassProps> {
        let mut it = parts.iter();
        let first = to_parry(it.next()?);
        Some(from_parry(&it.fold(first, |acc, p| acc + to_parry(p))))
    }
}

fn to_parry(m: &MassProps) -> MassProperties {
    MassProperties::with_inertia_matrix(m.local_com, m.mass, m.inertia)
}

fn from_parry(m: &MassProperties) -> MassProps {
    MassProps {
        mass: m.mass(),
        local_com: m.local_com,
        inertia: m.reconstruct_inertia_matrix(),
    }
}

/// Mass properties of `desc` filled with material of `density` kg/m³.
///
/// Errors: [`ShapeError::NotDynamic`] for a half-space or a triangle mesh (also inside a
/// compound, which [`ShapeDesc::build`] already forbids); [`ShapeError::Invalid`] for an
/// invalid shape, or with field `density` for a non-finite or non-positive density.
pub fn mass_properties(desc: &ShapeDesc, density: f32) -> Result<MassProps, ShapeError> {
    if !desc.can_be_dynamic() {
        return Err(ShapeError::NotDynamic { shape: desc.kind() });
    }
    if !(density.is_finite() && density > 0.0) {
        return Err(ShapeError::invalid(
            "density",
            format!("must be finite and > 0, got {density}"),
        ));
    }
    let shape = desc.build()?;
    let finite = |props: &MassProps| {
        props.local_com.is_finite() && props.inertia.to_cols_array().iter().all(|x| x.is_finite())
    };
    let mut props = from_parry(&shape.mass_properties(density));
    if !finite(&props) {
        // parry combines a compound's parts through its inertia's eigenvectors, whose
        // products of inertias leave f32's range for heavy compounds (a 100 m box with a ball
        // on it at 10¹² kg/m³, 1.07·10¹⁸ kg, came out with a NaN inertia, while the same parts
        // given as colliders loaded). Mass and inertia are proportional to the density: worked
        // out at 1 kg/m³ and scaled.
        let unit = from_parry(&shape.mass_properties(1.0));
        if unit.mass > 0.0 && finite(&unit) {
            props = unit.scaled_to_mass(unit.mass * density);
        }
    }
    let finite = finite(&props);
    if !(props.mass.is_finite() && props.mass > 0.0 && finite) {
        // Name the field that made it degenerate: a flat hull's points, otherwise the size.
        let field = match desc {
            ShapeDesc::ConvexHull { .. } => "points",
            ShapeDesc::Compound { .. } => "parts",
            ShapeDesc::Ball { .. } => "radius",
            ShapeDesc::Cuboid { .. } => "half_extents",
            _ => "radius",
        };
        return Err(ShapeError::invalid(
            field,
            format!(
                "the {} has no usable mass at density {density} kg/m³ (mass {}, inertia {}): \
                 too small, too thin or too large for f32",
                desc.kind(),
                props.mass,
                props.inertia.diagonal()
            ),
        ));
    }
    Ok(props)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::CompoundPart;
    use jostle_math::{InertiaShape, Quat};

    fn diag(m: Mat3) -> Vec3 {
        Vec3::new(m.x_axis.x, m.y_axis.y, m.z_axis.z)
    }

    fn assert_close(a: Vec3, b: Vec3, rel: f32) {
        assert!(
            (a - b).abs().max_element() <= rel * b.abs().max_element(),
            "{a} vs {b}"
        );
    }

    #[test]
    fn primitives_match_the_closed_forms() {
        let density = 700.0;
        let cases = [
            (
                ShapeDesc::Ball { radius: 0.5 },
                InertiaShape::Sphere { radius: 0.5 },
            ),
            (
                ShapeDesc::Cuboid {
                    half_extents: Vec3::new(1.0, 0.5, 0.25),
                },
                InertiaShape::Cuboid {
                    half_extents: Vec3::new(1.0, 0.5, 0.25),
                },
            ),
            (
                ShapeDesc::Cylinder {
                    half_height: 0.7,
                    radius: 0.3,
                },
                InertiaShape::Cylinder {
                    half_height: 0.7,
                    radius: 0.3,
                },
            ),
            (
                ShapeDesc::Capsule {
                    half_height: 0.7,
                    radius: 0.3,
                },
                InertiaShape::Capsule {
                    half_height: 0.7,
                    radius: 0.3,
                },
            ),
        ];
        for (desc, reference) in cases {
            let m = mass_properties(&desc, density).unwrap();
            let mass = density * reference.volume();
            assert!(
                (m.mass - mass).abs() < 1e-4 * mass,
                "{desc:?}: {} vs {mass}",
                m.mass
            );
            assert!(m.local_com.length() < 1e-5);
            assert_close(diag(m.inertia), reference.principal_inertia(mass), 1e-3);
        }
    }

    #[test]
    fn hull_of_a_box_weighs_like_the_box() {
        let pts: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    (i & 1) as f32 * 2.0,
                    ((i >> 1) & 1) as f32,
                    ((i >> 2) & 1) as f32,
                )
            })
            .collect();
        let m = mass_properties(&ShapeDesc::ConvexHull { points: pts }, 1.0).unwrap();
        assert!((m.mass - 2.0).abs() < 1e-4);
        assert_close(m.local_com, Vec3::new(1.0, 0.5, 0.5), 1e-4);
        let reference = InertiaShape::Cuboid {
            half_extents: Vec3::new(1.0, 0.5, 0.5),
        };
        assert_close(diag(m.inertia), reference.principal_inertia(2.0), 1e-3);
    }

    #[test]
    fn compound_com_follows_its_parts() {
        let part = |x: f32| CompoundPart {
            shape: ShapeDesc::Ball { radius: 0.5 },
            position: Vec3::new(x, 0.0, 0.0),
            rotation: Quat::IDENTITY,
        };
        let desc = ShapeDesc::Compound {
            parts: vec![part(-1.0), part(1.0), part(1.0)],
        };
        let m = mass_properties(&desc, 1.0).unwrap();
        assert!((m.local_com.x - 1.0 / 3.0).abs() < 1e-5);
    }

    #[test]
    fn a_heavy_compound_has_the_mass_and_inertia_of_its_parts() {
        let parts = vec![
            CompoundPart {
                shape: ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(50.0),
                },
                position: Vec3::ZERO,
                rotation: jostle_math::Quat::IDENTITY,
            },
            CompoundPart {
                shape: ShapeDesc::Ball { radius: 25.0 },
                position: Vec3::new(0.0, 50.0, 0.0),
                rotation: jostle_math::Quat::IDENTITY,
            },
        ];
        let desc = ShapeDesc::Compound { parts };
        let light = mass_properties(&desc, 1.0).unwrap();
        let heavy = mass_properties(&desc, 1e12).unwrap();
        assert!(
            (heavy.mass / light.mass / 1e12 - 1.0).abs() < 1e-5,
            "{heavy:?}"
        );
        assert_close(diag(heavy.inertia) / 1e12, diag(light.inertia), 1e-5);
    }

    #[test]
    fn unbounded_shapes_cannot_be_dynamic() {
        let plane = ShapeDesc::HalfSpace { normal: Vec3::Y };
        assert_eq!(
            mass_properties(&plane, 1.0),
            Err(ShapeError::NotDynamic {
                shape: "half-space"
            })
        );
        let mesh = ShapeDesc::TriMesh {
            vertices: vec![Vec3::ZERO, Vec3::X, Vec3::Z],
            indices: vec![[0, 2, 1]],
        };
        assert!(matches!(
            mass_properties(&mesh, 1.0),
            Err(ShapeError::NotDynamic { .. })
        ));
        let ball = ShapeDesc::Ball { radius: 1.0 };
        assert_eq!(mass_properties(&ball, 0.0).unwrap_err().field(), "density");
        assert_eq!(
            mass_properties(&ShapeDesc::Ball { radius: -1.0 }, 1.0)
                .unwrap_err()
                .field(),
            "radius"
        );
    }

    #[test]
    fn scaling_and_combining() {
        let m = mass_properties(&ShapeDesc::Ball { radius: 1.0 }, 1.0).unwrap();
        let s = m.scaled_to_mass(10.0);
        assert_eq!(s.mass, 10.0);
        assert_close(diag(s.inertia), Vec3::splat(0.4 * 10.0), 1e-4);
        let left = s.transformed(&Pose::from_translation(Vec3::new(-1.0, 0.0, 0.0)));
        let right = s.transformed(&Pose::from_translation(Vec3::new(1.0, 0.0, 0.0)));
        let both = MassProps::combine(&[left, right]).unwrap();
        assert!((both.mass - 20.0).abs() < 1e-4);
        assert!(both.local_com.length() < 1e-5);
        // Parallel axis: I_y = 2·(0.4·10 + 10·1²) = 28; I_x = 2·0.4·10 = 8.
        assert_close(diag(both.inertia), Vec3::new(8.0, 28.0, 28.0), 1e-4);
        assert!(MassProps::combine(&[]).is_none());
    }
}
