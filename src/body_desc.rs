//! `BodyDesc`: everything needed to add a body with its shape to a world, with documented
//! defaults, and the errors that name the offending field.

use jostle_body::CcdMode;
use jostle_collide::{Material, ShapeDesc, ShapeError};
use jostle_math::{Quat, Vec3};
use thiserror::Error;

/// Default density (kg/m³) of a body that gives neither mass nor density: water's.
pub const DEFAULT_DENSITY: f32 = 1000.0;

/// How a dynamic body's mass is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MassSpec {
    /// Uniform density (kg/m³); mass and inertia follow from the shape.
    Density(f32),
    /// Total mass (kg); inertia is the shape's at uniform density, scaled to this mass.
    Mass(f32),
}

/// A body to add to a [`crate::World`]. Construct with [`BodyDesc::dynamic`] or
/// [`BodyDesc::fixed`] and adjust with the builder methods or the public fields.
///
/// Defaults: position at the origin, identity rotation, zero velocities, density 1000 kg/m³,
/// friction 0.5, restitution 0, damping 0, `can_sleep` true, `ccd` [`CcdMode::Auto`].
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDesc {
    /// Name, used in traces and error messages.
    pub name: String,
    /// The collision shape (its frame is the body's frame).
    pub shape: ShapeDesc,
    /// Position of the shape's origin (m).
    pub position: Vec3,
    /// Orientation (unit quaternion).
    pub rotation: Quat,
    /// Initial linear velocity (m/s).
    pub linear_velocity: Vec3,
    /// Initial angular velocity (rad/s).
    pub angular_velocity: Vec3,
    /// Mass or density; ignored for fixed bodies.
    pub mass: MassSpec,
    /// Surface material.
    pub material: Material,
    /// Linear damping (1/s).
    pub linear_damping: f32,
    /// Angular damping (1/s).
    pub angular_damping: f32,
    /// Whether the body may sleep.
    pub can_sleep: bool,
    /// Whether the body is immovable.
    pub fixed: bool,
    /// Continuous collision detection: `Auto` (swept only when fast for its size), `On` or
    /// `Off`. Ignored for fixed bodies.
    pub ccd: CcdMode,
    /// Lock the rotation: the body translates but never turns (zero inverse inertia; the
    /// resolvers skip its angular terms). Default false. `angular_velocity` must then be zero.
    /// Ignored for fixed bodies.
    pub lock_rotation: bool,
}

impl BodyDesc {
    /// A dynamic body with the defaults above.
    pub fn dynamic(name: impl Into<String>, shape: ShapeDesc) -> Self {
        Self {
            name: name.into(),
            shape,
            position: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            mass: MassSpec::Density(DEFAULT_DENSITY),
            material: Material {
                friction: 0.5,
                restitution: 0.0,
            },
            linear_damping: 0.0,
            angular_damping: 0.0,
            can_sleep: true,
            fixed: false,
            ccd: CcdMode::Auto,
            lock_rotation: false,
        }
    }

    /// A fixed (immovable) body with the defaults above.
    pub fn fixed(name: impl Into<String>, shape: ShapeDesc) -> Self {
        Self {
            fixed: true,
            ..Self::dynamic(name, shape)
        }
    }

    /// Sets the position.
    pub fn at(mut self, position: Vec3) -> Self {
        self.position = position;
        self
    }

    /// Sets the rotation.
    pub fn rotated(mut self, rotation: Quat) -> Self {
        self.rotation = rotation;
        self
    }

    /// Sets the initial velocities.
    pub fn moving(mut self, linear: Vec3, angular: Vec3) -> Self {
        self.linear_velocity = linear;
        self.angular_velocity = angular;
        self
    }

    /// Locks the rotation (see [`BodyDesc::lock_rotation`]).
    pub fn with_locked_rotation(mut self) -> Self {
        self.lock_rotation = true;
        self
    }

    /// Sets the mass (kg).
    pub fn with_mass(mut self, mass: f32) -> Self {
        self.mass = MassSpec::Mass(mass);
        self
    }

    /// Sets the density (kg/m³).
    pub fn with_density(mut self, density: f32) -> Self {
        self.mass = MassSpec::Density(density);
        self
    }

    /// Sets the continuous-collision-detection mode.
    pub fn with_ccd(mut self, ccd: CcdMode) -> Self {
        self.ccd = ccd;
        self
    }

    /// Sets friction and restitution.
    pub fn with_material(mut self, friction: f32, restitution: f32) -> Self {
        self.material = Material {
            friction,
            restitution,
        };
        self
    }

    /// Checks every field; the error names the body and the field.
    pub fn validate(&self) -> Result<(), BodyError> {
        let err = |field: &str, message: String| BodyError::Field {
            body: self.name.clone(),
            field: field.to_string(),
            message,
        };
        let vec = |field: &str, v: Vec3| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(err(field, format!("must be finite, got {v}")))
            }
        };
        vec("position", self.position)?;
        vec("linear_velocity", self.linear_velocity)?;
        vec("angular_velocity", self.angular_velocity)?;
        if self.lock_rotation && !self.fixed && self.angular_velocity != Vec3::ZERO {
            return Err(err(
                "angular_velocity",
                format!(
                    "must be zero when lock_rotation is set, got {}",
                    self.angular_velocity
                ),
            ));
        }
        if !self.rotation.is_finite() || self.rotation.length_squared() < 1e-12 {
            return Err(err(
                "rotation",
                format!(
                    "must be a finite non-zero quaternion, got {:?}",
                    self.rotation
                ),
            ));
        }
        let non_negative = |field: &str, x: f32| {
            if x.is_finite() && x >= 0.0 {
                Ok(())
            } else {
                Err(err(field, format!("must be finite and >= 0, got {x}")))
            }
        };
        non_negative("friction", self.material.friction)?;
        non_negative("linear_damping", self.linear_damping)?;
        non_negative("angular_damping", self.angular_damping)?;
        let e = self.material.restitution;
        if !(e.is_finite() && (0.0..=1.0).contains(&e)) {
            return Err(err("restitution", format!("must be in [0, 1], got {e}")));
        }
        if !self.fixed {
            match self.mass {
                MassSpec::Mass(m) if !(m.is_finite() && m > 0.0) => {
                    return Err(err("mass", format!("must be finite and > 0, got {m}")));
                }
                MassSpec::Density(d) if !(d.is_finite() && d > 0.0) => {
                    return Err(err("density", format!("must be finite and > 0, got {d}")));
                }
                _ => {}
            }
        }
        self.shape.build().map_err(|e| shape_error(&self.name, e))?;
        if !self.fixed && self.shape.is_unbounded() {
            return Err(err(
                "fixed",
                "a half-space has no finite mass: it must be `fixed: true`".into(),
            ));
        }
        Ok(())
    }
}

pub(crate) fn shape_error(body: &str, e: ShapeError) -> BodyError {
    BodyError::Field {
        body: body.to_string(),
        field: format!("shape.{}", e.field()),
        message: e.to_string(),
    }
}

/// Why a body could not be added.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum BodyError {
    /// A field is invalid.
    #[error("body \"{body}\": field `{field}`: {message}")]
    Field {
        /// The body's name.
        body: String,
        /// The field, dotted for nested fields (`shape.radius`).
        field: String,
        /// What is wrong.
        message: String,
    },
}
