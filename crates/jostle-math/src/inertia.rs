//! Inertia tensors of the primitive shapes, and the world-space inverse inertia.
//!
//! Closed forms for solid bodies of uniform density, about the centre of mass, in body space
//! (capsules and cylinders along +Y, as jostle's shapes are). The collision layer computes mass
//! properties of arbitrary shapes through parry; these are the references those are tested
//! against, and what synthetic resolver benchmarks use.

use glam::{Mat3, Quat, Vec3};
use std::f32::consts::PI;

/// A primitive shape whose inertia tensor has a closed form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InertiaShape {
    /// Solid sphere of the given radius (m): I = 2/5·m·r².
    Sphere {
        /// Radius in metres.
        radius: f32,
    },
    /// Thin hollow sphere shell: I = 2/3·m·r².
    HollowSphere {
        /// Radius in metres.
        radius: f32,
    },
    /// Solid cuboid with the given half extents (m): I_x = m/3·(h_y² + h_z²), and so on.
    Cuboid {
        /// Half the size along each body axis, in metres.
        half_extents: Vec3,
    },
    /// Solid cylinder along +Y: I_y = m·r²/2, I_x = I_z = m·(3r² + 4h²)/12 with h the half height.
    Cylinder {
        /// Half the height along Y, in metres.
        half_height: f32,
        /// Radius in metres.
        radius: f32,
    },
    /// Solid capsule along +Y (a cylinder of half height `half_height` capped by two hemispheres).
    Capsule {
        /// Half the height of the cylindrical part along Y, in metres.
        half_height: f32,
        /// Radius in metres.
        radius: f32,
    },
}

impl InertiaShape {
    /// Volume in m³.
    pub fn volume(self) -> f32 {
        match self {
            Self::Sphere { radius } | Self::HollowSphere { radius } => {
                4.0 / 3.0 * PI * radius.powi(3)
            }
            Self::Cuboid { half_extents: h } => 8.0 * h.x * h.y * h.z,
            Self::Cylinder {
                half_height,
                radius,
            } => PI * radius * radius * 2.0 * half_height,
            Self::Capsule {
                half_height,
                radius,
            } => PI * radius * radius * 2.0 * half_height + 4.0 / 3.0 * PI * radius.powi(3),
        }
    }

    /// Principal moments of inertia (kg·m²) about the body axes for a body of `mass` kg.
    pub fn principal_inertia(self, mass: f32) -> Vec3 {
        match self {
            Self::Sphere { radius } => Vec3::splat(0.4 * mass * radius * radius),
            Self::HollowSphere { radius } => Vec3::splat(2.0 / 3.0 * mass * radius * radius),
            Self::Cuboid { half_extents: h } => {
                let s = h * h;
                Vec3::new(s.y + s.z, s.x + s.z, s.x + s.y) * (mass / 3.0)
            }
            Self::Cylinder {
                half_height: h,
                radius: r,
            } => {
                let side = mass * (3.0 * r * r + 4.0 * h * h) / 12.0;
                Vec3::new(side, 0.5 * mass * r * r, side)
            }
            Self::Capsule {
                half_height: h,
                radius: r,
            } => {
                // Split the mass by volume between the cylinder and the two caps (one sphere),
                // then move each hemisphere's inertia to the capsule centre (parallel axes).
                let v_cyl = PI * r * r * 2.0 * h;
                let v_sph = 4.0 / 3.0 * PI * r * r * r;
                let m_cyl = mass * v_cyl / (v_cyl + v_sph);
                let m_sph = mass - m_cyl;
                let axial = 0.5 * m_cyl * r * r + 0.4 * m_sph * r * r;
                // Hemisphere centroid sits 3r/8 from its flat face; its own transverse inertia
                // about its centroid is (83/320)·m·r² (per hemisphere of mass m).
                let side_cyl = m_cyl * (3.0 * r * r + 4.0 * h * h) / 12.0;
                let d = h + 3.0 * r / 8.0;
                let side_caps = m_sph * (83.0 / 320.0 * r * r + d * d);
                Vec3::new(side_cyl + side_caps, axial, side_cyl + side_caps)
            }
        }
    }

    /// The body-space inertia tensor (kg·m²), diagonal because the body axes are principal.
    pub fn inertia_tensor(self, mass: f32) -> Mat3 {
        Mat3::from_diagonal(self.principal_inertia(mass))
    }
}

/// The inverse of a diagonal tensor given by its principal moments, with zero where a moment is
/// zero or not finite (an axis about which the body cannot rotate).
pub fn inverse_principal(principal: Vec3) -> Vec3 {
    let inv = |x: f32| {
        if x > 0.0 && x.is_finite() {
            1.0 / x
        } else {
            0.0
        }
    };
    Vec3::new(inv(principal.x), inv(principal.y), inv(principal.z))
}

/// The world-space inverse inertia R·I⁻¹·Rᵀ of a body whose body-space inverse inertia is
/// `inv_inertia_body` and whose orientation is `rotation` (unit).
pub fn world_inverse_inertia(rotation: Quat, inv_inertia_body: Mat3) -> Mat3 {
    let r = Mat3::from_quat(rotation);
    r * inv_inertia_body * r.transpose()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
        (a - b).abs().max_element() <= tol * b.abs().max_element().max(1.0)
    }

    #[test]
    fn lecture_cube_and_spheres() {
        // The seed's worked examples: a solid cube of side 12 and mass 10 has I = 240;
        // a solid sphere of radius 6 and mass 100 has I = 1440.
        let cube = InertiaShape::Cuboid {
            half_extents: Vec3::splat(6.0),
        };
        assert!(close(
            cube.principal_inertia(10.0),
            Vec3::splat(240.0),
            1e-6
        ));
        let ball = InertiaShape::Sphere { radius: 6.0 };
        assert!(close(
            ball.principal_inertia(100.0),
            Vec3::splat(1440.0),
            1e-6
        ));
        let shell = InertiaShape::HollowSphere { radius: 3.0 };
        assert!(close(shell.principal_inertia(3.0), Vec3::splat(18.0), 1e-6));
    }

    #[test]
    fn cylinder_and_capsule_closed_forms() {
        let cyl = InertiaShape::Cylinder {
            half_height: 1.0,
            radius: 0.5,
        };
        let i = cyl.principal_inertia(2.0);
        assert!(close(
            i,
            Vec3::new(2.0 * (0.75 + 4.0) / 12.0, 0.25, 2.0 * (0.75 + 4.0) / 12.0),
            1e-6
        ));
        // A capsule with no cylinder is a sphere.
        let cap = InertiaShape::Capsule {
            half_height: 0.0,
            radius: 2.0,
        };
        assert!(close(
            cap.principal_inertia(5.0),
            Vec3::splat(0.4 * 5.0 * 4.0),
            1e-5
        ));
        // A capsule with vanishing radius is a thin rod: I = m·L²/12 transverse.
        let rod = InertiaShape::Capsule {
            half_height: 1.0,
            radius: 1e-4,
        };
        let i = rod.principal_inertia(3.0);
        assert!((i.x - 3.0 * 4.0 / 12.0).abs() < 1e-3 && i.y < 1e-6);
    }

    #[test]
    fn world_inverse_inertia_rotates_the_axes() {
        let inv = Mat3::from_diagonal(Vec3::new(1.0, 2.0, 3.0));
        let q = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let w = world_inverse_inertia(q, inv);
        // Body x maps to world y, so the world y moment is the body x one.
        assert!(close(w * Vec3::Y, Vec3::new(0.0, 1.0, 0.0), 1e-6));
        assert!(close(w * Vec3::X, Vec3::new(2.0, 0.0, 0.0), 1e-6));
        assert!(close(w * Vec3::Z, Vec3::new(0.0, 0.0, 3.0), 1e-6));
    }

    #[test]
    fn inverse_principal_handles_infinite_and_zero() {
        assert_eq!(
            inverse_principal(Vec3::new(2.0, 0.0, f32::INFINITY)),
            Vec3::new(0.5, 0.0, 0.0)
        );
    }
}
