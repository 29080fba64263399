//! `BodyDesc`: everything needed to add a body with its shape to a world, with documented
//! defaults, and the errors that name the offending field.

use jostle_body::{BodyType, CcdMode, KinematicPath};
use jostle_collide::{CollisionGroups, Material, ShapeDesc, ShapeError};
use jostle_math::{Quat, Vec3};
use thiserror::Error;

/// Default density (kg/m³) of a body that gives neither mass nor density: water's.
pub const DEFAULT_DENSITY: f32 = 1000.0;

/// The fastest a body may start (m/s): 100 km/s, well beyond any projectile, and far enough
/// below f32's range that its kinetic energy and the impulses that stop it stay finite at
/// [`MAX_MASS`] (above it, `linear_velocity: (3e38, 0, 0)` made the energy infinite).
pub const MAX_SPEED: f32 = 1.0e5;

/// The fastest a body may start spinning (rad/s): at 10,000 rad/s one step at 60 Hz already
/// turns a body 167 rad; faster spins went non-finite in the first step.
pub const MAX_ANGULAR_SPEED: f32 = 1.0e4;

/// The fastest a body may come to spin in a step (rad/s): beyond it the body is quarantined
/// ([`crate::StepReport::quarantined`]), and a snapshot may hold up to it. Above
/// [`MAX_ANGULAR_SPEED`], since contacts spin thin and tiny bodies faster than anyone would
/// start them (a 1 mm cube hit at 10⁵ m/s: 2.4·10⁵ rad/s; needles hit at 1,000 m/s pass 10⁴);
/// at it, the kinetic energy ½·I·ω² stays finite in f32 for a moment of inertia below about
/// 6·10²⁶ kg·m² (a cube of water about 80 km wide).
pub const MAX_REACHED_ANGULAR_SPEED: f32 = 1.0e6;

/// The heaviest body (kg), given as `mass` or reached through `density` × volume: 10²⁴ kg (a
/// moon), so that its momentum and kinetic energy at [`MAX_SPEED`] (10²⁹ N·s, 5·10³³ J) and
/// the impulses that stop it stay finite in f32 (at most 3.4·10³⁸).
pub const MAX_MASS: f32 = 1.0e24;

/// The farthest a body may be from the origin on any axis (m): 10⁶, where f32 still
/// resolves 6 cm (the reach of shapes is bounded alike: `jostle_collide::shape::MAX_EXTENT`).
pub const MAX_POSITION: f32 = 1.0e6;

/// The largest ratio of two touching dynamic bodies' masses whose contacts the soft step
/// holds (`jostle_resolve::soft_step::MAX_MASS_RATIO`, 10⁶: a 1 kg box under 1,000 t,
/// `tests/stress.rs`). Beyond it a 1 kg box under 10⁷ kg or more is pressed 0.17–0.95 m into
/// its neighbour or thrown out, f32 rounding away what holds it; the Millington resolver holds
/// it (0.3–0.4 mm up to 10¹²). Such pairs are not refused (what touches what is not known in
/// advance) but reported every step they touch awake, under a resolver that declares the bound
/// ([`crate::StepReport::beyond_mass_ratio`], `Resolver::max_mass_ratio`).
pub const MAX_CONTACT_MASS_RATIO: f32 = jostle_resolve::soft_step::MAX_MASS_RATIO;

/// The strongest gravity a scene or snapshot may set (m/s²): 10⁵, ten thousand g (a
/// scene's `gravity: (0, -1e30, 0)` made its bodies non-finite at the second step).
pub const MAX_GRAVITY: f32 = 1.0e5;

/// The longest time step (s): 10. A step of 10³⁰ s put every body out of f32's range.
pub const MAX_DT: f32 = 10.0;

/// The densest material (kg/m³): 10¹², far beyond any solid (osmium: 2.26·10⁴; the stability
/// tests' 1:10,000 loads use 10⁷), so that `density` × volume stays finite; the mass it gives
/// is then held to [`MAX_MASS`] (`density: 1e38` made the mass infinite).
pub const MAX_DENSITY: f32 = 1.0e12;

/// `q` scaled to unit length, for any finite non-zero quaternion however large or small its
/// components (`Quat::normalize` squares them first: `(0, 0, 0, 1e30)` overflowed to NaN);
/// `None` when it has no direction.
pub(crate) fn unit_rotation(q: Quat) -> Option<Quat> {
    let largest = q.to_array().into_iter().fold(0.0f32, |m, x| m.max(x.abs()));
    if !(largest.is_finite() && largest > 0.0 && q.is_finite()) {
        return None;
    }
    // Scaled first only when the squares would overflow or lose precision, so that ordinary
    // rotations normalise exactly as before (the golden hash of `tests/determinism.rs`).
    let unit = if (1e-12..1e12).contains(&q.length_squared()) {
        q.normalize()
    } else {
        (q / largest).normalize()
    };
    unit.is_finite().then_some(unit)
}

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
    /// Lock rotation about some world axes (x, y, z) only
    /// ([`jostle_body::RigidBody::set_rotation_locks`]). Default: none. `angular_velocity`
    /// must be zero about each locked axis. Ignored for fixed bodies.
    pub rotation_locks: [bool; 3],
    /// Lock translation along some world axes (x, y, z)
    /// ([`jostle_body::RigidBody::set_translation_locks`]). Default: none. `linear_velocity`
    /// must be zero along each locked axis. Ignored for fixed bodies.
    pub translation_locks: [bool; 3],
    /// Makes the body kinematic: moved by its velocity, to the poses it is sent to, or along
    /// a path; it pushes dynamic bodies and nothing pushes it. `None` (the default): dynamic,
    /// or fixed with `fixed`.
    pub kinematic: Option<Kinematic>,
    /// A sensor: no contacts, only the colliders that enter and leave it
    /// ([`crate::World::sensor_events`]). Default false.
    pub sensor: bool,
    /// Which colliders it meets ([`CollisionGroups`]). Default: all.
    pub groups: CollisionGroups,
    /// Report contact force events when its contacts with another collider push with more
    /// than this total normal force in a step (N; [`crate::World::contact_force_events`]).
    /// Default: none.
    pub force_event_threshold: Option<f32>,
    /// Further colliders, attached in order as [`crate::World::add_collider`] attaches them
    /// (their poses in the body's own frame, their mass summed with the shape's). Default:
    /// none.
    pub colliders: Vec<crate::ColliderDesc>,
}

/// How a kinematic body moves ([`BodyDesc::kinematic`], scene field `kinematic`). Its mass
/// properties are those of a dynamic body of its shape and `mass`, kept for when it is made
/// dynamic ([`crate::World::set_body_type`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Kinematic {
    /// Moved by its velocity (`linear_velocity`, `angular_velocity`) until told otherwise
    /// ([`crate::World::set_velocity`]).
    Velocity,
    /// Moved to the poses it is sent to ([`crate::World::set_next_pose`]); at rest otherwise.
    /// Its velocity follows from those poses: `linear_velocity` and `angular_velocity` must
    /// be zero (so too for `Line` and `Turn`).
    Position,
    /// Back and forth along `offset` (m) from where it starts, smoothly, there and back once
    /// per `period` (s, > 0) ([`KinematicPath::Line`]).
    Line {
        /// From the start to the far end (m).
        offset: Vec3,
        /// Time for the way there and back (s).
        period: f32,
    },
    /// A rigid turn about the axis through `center` along `axis`, once per `period` (s,
    /// non-zero; negative turns the other way) ([`KinematicPath::Turn`]); with the centre at
    /// the body it spins in place.
    Turn {
        /// A point on the axis (m).
        center: Vec3,
        /// The axis's direction (right-handed turns for a positive period).
        axis: Vec3,
        /// Time for one turn (s).
        period: f32,
    },
}

/// `Ok` when `value` is at most `limit`, else `field` with a message: "`what` `value`
/// `unit`, above the limit of `limit` `unit`" (the limits of scene bodies and of snapshot
/// bodies read the same way).
pub(crate) fn at_most(
    field: &'static str,
    what: &str,
    value: impl Into<f64>,
    limit: f32,
    unit: &str,
) -> Result<(), (&'static str, String)> {
    let value = value.into();
    if value <= f64::from(limit) {
        Ok(())
    } else {
        Err((
            field,
            format!("{what} {value:.3e} {unit}, above the limit of {limit:e} {unit}"),
        ))
    }
}

/// A kinematic path held to the limits a body is held to: every pose within
/// [`MAX_POSITION`] of the origin on each axis, its speed within [`MAX_SPEED`] and its spin
/// within [`MAX_ANGULAR_SPEED`] (`Line(offset: (1e30, 0, 0), period: 1.0)` was accepted and
/// moved its body at 2.8·10³⁰ m/s). Call after [`KinematicPath::check`]; the error is (field,
/// message).
pub(crate) fn path_within_limits(path: &KinematicPath) -> Result<(), (&'static str, String)> {
    match *path {
        KinematicPath::Line {
            start,
            offset,
            period,
            ..
        } => {
            let far = start.abs().max((start + offset).abs()).max_element();
            at_most(
                "offset",
                "takes the body",
                far,
                MAX_POSITION,
                "m from the origin",
            )?;
            // start + offset·(1 − cos(2πt/T))/2: the fastest at π·|offset|/T.
            let speed = std::f32::consts::PI * offset.length() / period;
            at_most("period", "moves the body at up to", speed, MAX_SPEED, "m/s")
        }
        KinematicPath::Turn {
            start,
            center,
            axis,
            period,
            ..
        } => {
            let axis = axis.normalize_or_zero();
            let arm = (start - center) - axis * (start - center).dot(axis);
            let far = (center + axis * (start - center).dot(axis))
                .abs()
                .max_element()
                + arm.length();
            at_most(
                "center",
                "takes the body",
                far,
                MAX_POSITION,
                "m from the origin",
            )?;
            let spin = std::f32::consts::TAU / period.abs();
            at_most(
                "period",
                "turns the body at",
                spin,
                MAX_ANGULAR_SPEED,
                "rad/s",
            )?;
            at_most(
                "period",
                "moves the body at",
                spin * arm.length(),
                MAX_SPEED,
                "m/s",
            )
        }
    }
}

impl Kinematic {
    /// The body type and, for a scripted motion, the path starting from the pose given.
    pub fn start(self, position: Vec3, rotation: Quat) -> (BodyType, Option<KinematicPath>) {
        match self {
            Self::Velocity => (BodyType::KinematicVelocity, None),
            Self::Position => (BodyType::KinematicPosition, None),
            Self::Line { offset, period } => (
                BodyType::KinematicPosition,
                Some(KinematicPath::Line {
                    start: position,
                    rotation,
                    offset,
                    period,
                }),
            ),
            Self::Turn {
                center,
                axis,
                period,
            } => (
                BodyType::KinematicPosition,
                Some(KinematicPath::Turn {
                    start: position,
                    rotation,
                    center,
                    axis,
                    period,
                }),
            ),
        }
    }
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
            material: Material::new(0.5, 0.0),
            linear_damping: 0.0,
            angular_damping: 0.0,
            can_sleep: true,
            fixed: false,
            ccd: CcdMode::Auto,
            lock_rotation: false,
            rotation_locks: [false; 3],
            translation_locks: [false; 3],
            kinematic: None,
            sensor: false,
            groups: CollisionGroups::ALL,
            force_event_threshold: None,
            colliders: Vec::new(),
        }
    }

    /// A kinematic body moving as `kinematic` says, with the defaults above.
    pub fn kinematic(name: impl Into<String>, shape: ShapeDesc, kinematic: Kinematic) -> Self {
        Self {
            kinematic: Some(kinematic),
            ..Self::dynamic(name, shape)
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

    /// Makes the body's collider a sensor ([`BodyDesc::sensor`]).
    pub fn as_sensor(mut self) -> Self {
        self.sensor = true;
        self
    }

    /// Sets the collision groups ([`BodyDesc::groups`]).
    pub fn with_groups(mut self, groups: CollisionGroups) -> Self {
        self.groups = groups;
        self
    }

    /// Reports contact force events above `threshold` (N) ([`BodyDesc::force_event_threshold`]).
    pub fn with_force_events(mut self, threshold: f32) -> Self {
        self.force_event_threshold = Some(threshold);
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

    /// Sets friction (static and dynamic alike) and restitution.
    pub fn with_material(mut self, friction: f32, restitution: f32) -> Self {
        self.material = Material::new(friction, restitution);
        self
    }

    /// Sets a dynamic friction coefficient of its own, μd ≤ the static `friction`: a
    /// contact that is sliding feels μd, one that is not is held by up to `friction`.
    pub fn with_dynamic_friction(mut self, dynamic: f32) -> Self {
        self.material.dynamic_friction = Some(dynamic);
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
        // A vector's length in f64, where its square cannot overflow (a velocity of 3·10³⁸).
        let length = |v: Vec3| {
            v.to_array()
                .map(|x| f64::from(x).powi(2))
                .iter()
                .sum::<f64>()
                .sqrt()
        };
        let far = self.position.abs().max_element();
        [
            at_most("position", "lies", far, MAX_POSITION, "m from the origin"),
            at_most(
                "linear_velocity",
                "has a length of",
                length(self.linear_velocity),
                MAX_SPEED,
                "m/s",
            ),
            at_most(
                "angular_velocity",
                "has a length of",
                length(self.angular_velocity),
                MAX_ANGULAR_SPEED,
                "rad/s",
            ),
        ]
        .into_iter()
        .collect::<Result<(), _>>()
        .map_err(|(field, message)| err(field, message))?;
        // A body moved to given poses takes its velocity from them: one set here was shown at
        // step 0 and dropped at the first step.
        if let Some(
            kind @ (Kinematic::Position | Kinematic::Line { .. } | Kinematic::Turn { .. }),
        ) = &self.kinematic
        {
            let driven = match kind {
                Kinematic::Position => "to the poses it is sent",
                _ => "along its path",
            };
            for (field, v) in [
                ("linear_velocity", self.linear_velocity),
                ("angular_velocity", self.angular_velocity),
            ] {
                if v != Vec3::ZERO {
                    return Err(err(
                        field,
                        format!(
                            "must be zero for a kinematic body moved {driven}, whose velocity \
                             follows from its motion (`kinematic: Velocity` moves a body by \
                             its velocity), got {v}"
                        ),
                    ));
                }
            }
        }
        if self.lock_rotation && !self.fixed && self.angular_velocity != Vec3::ZERO {
            return Err(err(
                "angular_velocity",
                format!(
                    "must be zero when lock_rotation is set, got {}",
                    self.angular_velocity
                ),
            ));
        }
        for (axis, name) in ["x", "y", "z"].iter().enumerate() {
            if self.translation_locks[axis] && !self.fixed && self.linear_velocity[axis] != 0.0 {
                return Err(err(
                    "linear_velocity",
                    format!(
                        "must have no {name} component when translation along {name} is \
                         locked, got {}",
                        self.linear_velocity
                    ),
                ));
            }
        }
        for (axis, name) in ["x", "y", "z"].iter().enumerate() {
            if self.rotation_locks[axis] && !self.fixed && self.angular_velocity[axis] != 0.0 {
                return Err(err(
                    "angular_velocity",
                    format!(
                        "must have no {name} component when rotation about {name} is locked, \
                         got {}",
                        self.angular_velocity
                    ),
                ));
            }
        }
        if unit_rotation(self.rotation).is_none() {
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
        check_material(&self.material).map_err(|(field, message)| err(field, message))?;
        non_negative("linear_damping", self.linear_damping)?;
        non_negative("angular_damping", self.angular_damping)?;
        check_force_threshold(self.force_event_threshold)
            .map_err(|(field, message)| err(field, message))?;
        if !self.fixed {
            check_mass(self.mass).map_err(|(field, message)| err(field, message))?;
        }
        self.shape.build().map_err(|e| shape_error(&self.name, e))?;
        if !self.fixed && self.shape.is_unbounded() {
            return Err(err(
                "fixed",
                "a half-space has no finite mass: it must be `fixed: true`".into(),
            ));
        }
        if let Some(kinematic) = self.kinematic {
            if self.fixed {
                return Err(err(
                    "kinematic",
                    "a body is `fixed` or `kinematic`, not both".into(),
                ));
            }
            let rotation = unit_rotation(self.rotation).unwrap_or(Quat::IDENTITY);
            if let (_, Some(path)) = kinematic.start(self.position, rotation) {
                path.check()
                    .and_then(|()| path_within_limits(&path))
                    .map_err(|(field, message)| err(&format!("kinematic.{field}"), message))?;
            }
        }
        for (i, c) in self.colliders.iter().enumerate() {
            let field = |f: &str| format!("colliders[{i}].{f}");
            c.validate()
                .map_err(|(f, message)| err(&field(&f), message))?;
            c.shape
                .build()
                .map_err(|e| err(&field(&format!("shape.{}", e.field())), e.to_string()))?;
            if !self.fixed && c.density > 0.0 && c.shape.can_be_dynamic() {
                shape_mass(&c.shape, MassSpec::Density(c.density))
                    .map_err(|(f, message)| err(&field(&f), message))?;
            }
        }
        Ok(())
    }

    /// With rotation about the world axes marked `true` (x, y, z) locked
    /// ([`BodyDesc::rotation_locks`]).
    pub fn with_rotation_locks(mut self, locks: [bool; 3]) -> Self {
        self.rotation_locks = locks;
        self
    }

    /// With translation along the world axes marked `true` (x, y, z) locked
    /// ([`BodyDesc::translation_locks`]).
    pub fn with_translation_locks(mut self, locks: [bool; 3]) -> Self {
        self.translation_locks = locks;
        self
    }

    /// With a further collider ([`BodyDesc::colliders`]).
    pub fn with_collider(mut self, collider: crate::ColliderDesc) -> Self {
        self.colliders.push(collider);
        self
    }
}

/// Checks a contact force event threshold: none, or finite and ≥ 0 (N).
pub(crate) fn check_force_threshold(t: Option<f32>) -> Result<(), (&'static str, String)> {
    match t {
        Some(t) if !(t.is_finite() && t >= 0.0) => Err((
            "force_event_threshold",
            format!("must be finite and >= 0, got {t}"),
        )),
        _ => Ok(()),
    }
}

/// Checks a material: friction finite and ≥ 0, dynamic friction in [0, friction], restitution
/// in [0, 1]. The error names the field.
pub(crate) fn check_material(m: &Material) -> Result<(), (&'static str, String)> {
    let non_negative = |field: &'static str, x: f32| {
        if x.is_finite() && x >= 0.0 {
            Ok(())
        } else {
            Err((field, format!("must be finite and >= 0, got {x}")))
        }
    };
    non_negative("friction", m.friction)?;
    if let Some(d) = m.dynamic_friction {
        non_negative("dynamic_friction", d)?;
        if d > m.friction {
            return Err((
                "dynamic_friction",
                format!(
                    "must be <= friction (the static coefficient, {}), got {d}",
                    m.friction
                ),
            ));
        }
    }
    let e = m.restitution;
    if !(e.is_finite() && (0.0..=1.0).contains(&e)) {
        return Err(("restitution", format!("must be in [0, 1], got {e}")));
    }
    Ok(())
}

/// Checks how a dynamic body's mass is given: finite, > 0 and within [`MAX_MASS`] or
/// [`MAX_DENSITY`]. The error names the field (`mass` or `density`).
pub(crate) fn check_mass(spec: MassSpec) -> Result<(), (&'static str, String)> {
    match spec {
        MassSpec::Mass(m) if !(m.is_finite() && m > 0.0) => {
            Err(("mass", format!("must be finite and > 0, got {m}")))
        }
        MassSpec::Density(d) if !(d.is_finite() && d > 0.0) => {
            Err(("density", format!("must be finite and > 0, got {d}")))
        }
        MassSpec::Mass(m) if m > MAX_MASS => Err((
            "mass",
            format!("{m:e} kg is above the limit of {MAX_MASS:e} kg"),
        )),
        MassSpec::Density(d) if d > MAX_DENSITY => Err((
            "density",
            format!("{d:e} kg/m³ is above the limit of {MAX_DENSITY:e} kg/m³"),
        )),
        _ => Ok(()),
    }
}

/// The mass properties of `shape` given as `spec`: total mass, body-space inertia tensor and
/// the centre of mass in the shape's frame. The error names the field.
pub(crate) fn shape_mass(
    shape: &ShapeDesc,
    spec: MassSpec,
) -> Result<jostle_collide::MassProps, (String, String)> {
    check_mass(spec).map_err(|(f, m)| (f.to_string(), m))?;
    let density = match spec {
        MassSpec::Density(d) => d,
        MassSpec::Mass(_) => 1.0,
    };
    let mut props = jostle_collide::mass_properties(shape, density)
        .map_err(|e| (format!("shape.{}", e.field()), e.to_string()))?;
    if let MassSpec::Mass(m) = spec {
        props = props.scaled_to_mass(m);
    } else if props.mass > MAX_MASS {
        return Err((
            "density".into(),
            format!(
                "gives the shape a mass of {:e} kg, above the limit of {MAX_MASS:e} kg",
                props.mass
            ),
        ));
    }
    Ok(props)
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
