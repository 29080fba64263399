//! [`ColliderDesc`]: a further collider for an existing body ([`crate::World::add_collider`]),
//! with its own pose on the body, material, density, filter and sensor flag.

use crate::body_desc::{
    DEFAULT_DENSITY, MAX_DENSITY, MAX_POSITION, check_force_threshold, check_material,
};
use jostle_collide::{CollisionGroups, MassProps, Material, ShapeDesc};
use jostle_math::{Mat3, Quat, Vec3};

/// A collider to attach to a body that already exists ([`crate::World::add_collider`]).
///
/// Its pose is given in the body's own frame: about the point the body's description placed it
/// at ([`jostle_body::RigidBody::origin`]; the first shape's origin), along the body's axes,
/// whatever colliders were added before. On a dynamic body the collider's mass (its shape at
/// `density`) is added to the body's: mass, centre of mass and inertia are summed, the body's
/// centre moves to the new centre of mass (its other colliders keep their place in the world)
/// and its velocity is that of the point it moved to. A density of 0 adds a collider without
/// mass (a sensor, a shell). Defaults: at the body's origin, unrotated, friction 0.5,
/// restitution 0, density 1000 kg/m³, every group, not a sensor, no force events.
#[derive(Clone, Debug, PartialEq)]
pub struct ColliderDesc {
    /// The shape (not a half-space: those belong to fixed bodies of their own).
    pub shape: ShapeDesc,
    /// Position of the shape's origin in the body's own frame (m).
    pub position: Vec3,
    /// Orientation of the shape in the body's frame.
    pub rotation: Quat,
    /// Surface material.
    pub material: Material,
    /// Density (kg/m³) of the mass it adds to a dynamic body; 0 adds none.
    pub density: f32,
    /// Collision groups ([`CollisionGroups`]).
    pub groups: CollisionGroups,
    /// A sensor reports overlaps and makes no contact.
    pub sensor: bool,
    /// Contact force events above this force (N), as [`crate::BodyDesc::with_force_events`].
    pub force_event_threshold: Option<f32>,
}

impl ColliderDesc {
    /// A collider of `shape` at the body's centre of mass, with the defaults of the type.
    pub fn new(shape: ShapeDesc) -> Self {
        Self {
            shape,
            position: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            material: Material::new(0.5, 0.0),
            density: DEFAULT_DENSITY,
            groups: CollisionGroups::ALL,
            sensor: false,
            force_event_threshold: None,
        }
    }

    /// At `position` in the body's own frame (m).
    pub fn at(mut self, position: Vec3) -> Self {
        self.position = position;
        self
    }

    /// Rotated by `rotation` in the body's frame.
    pub fn rotated(mut self, rotation: Quat) -> Self {
        self.rotation = rotation;
        self
    }

    /// With friction μ and restitution e.
    pub fn with_material(mut self, friction: f32, restitution: f32) -> Self {
        self.material = Material::new(friction, restitution);
        self
    }

    /// With density (kg/m³); 0 adds no mass.
    pub fn with_density(mut self, density: f32) -> Self {
        self.density = density;
        self
    }

    /// A sensor: reports overlaps, makes no contact.
    pub fn as_sensor(mut self) -> Self {
        self.sensor = true;
        self
    }

    /// In these collision groups.
    pub fn with_groups(mut self, groups: CollisionGroups) -> Self {
        self.groups = groups;
        self
    }

    /// With contact force events above `threshold` (N).
    pub fn with_force_events(mut self, threshold: f32) -> Self {
        self.force_event_threshold = Some(threshold);
        self
    }

    /// Checks every field; the error is (field, message).
    pub fn validate(&self) -> Result<(), (String, String)> {
        let err = |field: &str, message: String| Err((field.to_string(), message));
        if matches!(self.shape, ShapeDesc::HalfSpace { .. }) {
            return err(
                "shape",
                "a half-space cannot be added to a body: give it a fixed body of its own".into(),
            );
        }
        let far = self.position.abs().max_element();
        if !self.position.is_finite() || far > MAX_POSITION {
            return err(
                "position",
                format!(
                    "must be finite and within {MAX_POSITION:e} m, got {}",
                    self.position
                ),
            );
        }
        if crate::body_desc::unit_rotation(self.rotation).is_none() {
            return err(
                "rotation",
                format!(
                    "must be a finite non-zero quaternion, got {:?}",
                    self.rotation
                ),
            );
        }
        if !self.density.is_finite() || self.density < 0.0 || self.density > MAX_DENSITY {
            return err(
                "density",
                format!(
                    "must be in [0, {MAX_DENSITY:e}] kg/m³, got {}",
                    self.density
                ),
            );
        }
        check_material(&self.material).map_err(|(f, m)| (f.to_string(), m))?;
        check_force_threshold(self.force_event_threshold).map_err(|(f, m)| (f.to_string(), m))
    }
}

/// Mass properties in a body's frame: mass (kg), centre of mass (m) and the inertia tensor
/// about it along the body's axes (kg·m²), for summing the parts of a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LocalMass {
    pub mass: f32,
    pub com: Vec3,
    pub inertia: Mat3,
}

impl LocalMass {
    /// A shape's mass properties placed at `position`, turned by `rotation`.
    pub fn of_part(part: &MassProps, position: Vec3, rotation: Quat) -> Self {
        let r = Mat3::from_quat(rotation);
        Self {
            mass: part.mass,
            com: position + rotation * part.local_com,
            inertia: r * part.inertia * r.transpose(),
        }
    }

    /// The sum of two parts: masses add, the centre of mass is their weighted mean, and each
    /// inertia moves to it by the parallel-axis theorem, m·(|d|²·E − d·dᵀ).
    pub fn plus(&self, other: &Self) -> Self {
        let mass = self.mass + other.mass;
        let com = (self.com * self.mass + other.com * other.mass) / mass;
        let moved = |p: &Self| {
            let d = p.com - com;
            let outer = Mat3::from_cols(d * d.x, d * d.y, d * d.z);
            p.inertia + (Mat3::from_diagonal(Vec3::splat(d.dot(d))) - outer) * p.mass
        };
        Self {
            mass,
            com,
            inertia: moved(self) + moved(other),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit-mass points 2 m apart: the sum sits between them, with inertia 2 kg·m²
    /// about the axes across the line and none along it.
    #[test]
    fn two_points_sum_by_the_parallel_axis_theorem() {
        let point = |x: f32| LocalMass {
            mass: 1.0,
            com: Vec3::new(x, 0.0, 0.0),
            inertia: Mat3::ZERO,
        };
        let sum = point(-1.0).plus(&point(1.0));
        assert_eq!(sum.mass, 2.0);
        assert_eq!(sum.com, Vec3::ZERO);
        assert_eq!(sum.inertia, Mat3::from_diagonal(Vec3::new(0.0, 2.0, 2.0)));
    }

    /// A part rotated a quarter turn about z swaps its inertia's x and y entries.
    #[test]
    fn a_turned_part_turns_its_inertia() {
        let part = MassProps {
            mass: 1.0,
            local_com: Vec3::X,
            inertia: Mat3::from_diagonal(Vec3::new(1.0, 2.0, 3.0)),
        };
        let placed = LocalMass::of_part(
            &part,
            Vec3::ZERO,
            Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
        );
        assert!(placed.com.abs_diff_eq(Vec3::Y, 1e-6));
        assert!(
            placed
                .inertia
                .abs_diff_eq(Mat3::from_diagonal(Vec3::new(2.0, 1.0, 3.0)), 1e-5)
        );
    }
}
