//! `RigidBody`: one body's mass properties, state, forces and sleep state.

use crate::KinematicPath;
use jostle_math::{Mat3, Quat, Vec3, world_inverse_inertia};
use thiserror::Error;

/// Why mass properties were rejected.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum MassError {
    /// Mass must be finite and > 0.
    #[error("mass must be finite and > 0, got {0}")]
    Mass(f32),
    /// Inertia must be a finite symmetric tensor with positive principal moments.
    #[error("inertia must be finite with principal moments > 0, got {0:?}")]
    Inertia(Vec3),
}

/// Sleep bookkeeping of a body (the `jostle-sleep` crate).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SleepState {
    /// Whether the body is simulated this step.
    pub awake: bool,
    /// Whether the body may be put to sleep at all.
    pub can_sleep: bool,
    /// Recency-weighted average of |v|² + |ω|² (m²/s², rad²/s² treated alike).
    pub motion: f32,
    /// Recency-weighted average of the linear velocity (m/s), with the same bias as
    /// `motion`: a body moving steadily keeps it, one jittering in place averages it away.
    #[cfg_attr(feature = "serde", serde(default))]
    pub mean_linear: Vec3,
    /// Recency-weighted average of the angular velocity (rad/s), as `mean_linear`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub mean_angular: Vec3,
}

impl Default for SleepState {
    fn default() -> Self {
        Self {
            awake: true,
            can_sleep: true,
            motion: f32::MAX,
            mean_linear: Vec3::ZERO,
            mean_angular: Vec3::ZERO,
        }
    }
}

/// Whether a body is swept for continuous collision detection (CCD) each step.
///
/// CCD stops a fast body at its first contact with static, fixed or sleeping geometry instead
/// of letting it pass through (tunnel) between two steps. In a scene file: `ccd: Auto`,
/// `ccd: On` or `ccd: Off`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum CcdMode {
    /// Swept only in steps where its motion (linear, plus angular times its extent) exceeds
    /// the world's fraction of its smallest dimension: slow bodies cost nothing. The default.
    #[default]
    Auto,
    /// Swept in every step in which it moves at all.
    On,
    /// Never swept: it may tunnel through geometry thinner than one step's motion.
    Off,
}

/// What moves a body.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum BodyType {
    /// Moved by gravity, forces and contacts.
    #[default]
    Dynamic,
    /// Never moves (the ground, walls).
    Fixed,
    /// Moves with the velocity the user sets; pushes dynamic bodies, is pushed by nothing.
    KinematicVelocity,
    /// Moves to the pose the user sets for the end of each step
    /// ([`RigidBody::set_next_pose`], the velocity derived from it); pushes dynamic bodies, is
    /// pushed by nothing. Without a next pose it stays where it is.
    KinematicPosition,
}

/// A rigid body: mass properties, pose, velocities, damping, accumulated force and torque,
/// the acceleration of the last step, and sleep state.
///
/// A fixed body has zero inverse mass and inverse inertia, never moves, and is represented by
/// the solver's single static entry. Poses are the centre of mass: `position` is where the
/// centre of mass is, `orientation` rotates body space to world space.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RigidBody {
    /// The body's name, as given by the user (scene files require one; may be empty). Kept
    /// with the body, so that removing it leaves nothing behind.
    #[cfg_attr(feature = "serde", serde(default))]
    pub name: String,
    /// Position of the centre of mass (m).
    pub position: Vec3,
    /// Orientation, body to world (unit quaternion).
    pub orientation: Quat,
    /// Linear velocity (m/s).
    pub linear_velocity: Vec3,
    /// Angular velocity (rad/s, world space).
    pub angular_velocity: Vec3,
    /// Linear damping (1/s): each step v ← v / (1 + dt·c). 0 = none (default).
    pub linear_damping: f32,
    /// Angular damping (1/s): each step ω ← ω / (1 + dt·c). 0 = none (default).
    pub angular_damping: f32,
    /// Linear acceleration of the last step (m/s²), see `SolverBody::last_acceleration`.
    pub last_acceleration: Vec3,
    /// Sleep state.
    pub sleep: SleepState,
    /// Continuous collision detection: automatic (default), forced on or off.
    #[cfg_attr(feature = "serde", serde(default))]
    pub ccd: CcdMode,
    mass: f32,
    inv_mass: f32,
    /// Body-space inertia tensor, kept alongside its inverse so energy is computed without
    /// inverting a (possibly badly conditioned) matrix in f32.
    #[cfg_attr(feature = "serde", serde(default))]
    inertia_body: Mat3,
    inv_inertia_body: Mat3,
    inv_inertia_world: Mat3,
    force: Vec3,
    torque: Vec3,
    body_type: BodyType,
    /// Whether the body's rotation was locked when it stopped being dynamic
    /// ([`RigidBody::set_body_type`]), so that it is locked again when it becomes dynamic.
    #[cfg_attr(feature = "serde", serde(default))]
    locked_while_fixed: bool,
    /// The pose a position-based kinematic body is to reach at the end of the next step
    /// ([`RigidBody::set_next_pose`]).
    #[cfg_attr(feature = "serde", serde(default))]
    next_pose: Option<(Vec3, Quat)>,
    /// The acceleration of a body sent along its path for the next step, at the middle of
    /// the step ([`RigidBody::follow_path_over`]; zero otherwise).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "is_zero"))]
    path_acceleration: Vec3,
    /// The scripted motion of a position-based kinematic body ([`RigidBody::set_path`]).
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    path: Option<KinematicPath>,
    /// Scale of the world's gravity on this body (dimensionless; 1 by default, 0 floats, −1
    /// falls up).
    #[cfg_attr(feature = "serde", serde(default = "one"))]
    pub gravity_scale: f32,
    /// Where the body's own frame has its origin, relative to its centre of mass along the
    /// body's axes (m): the point its description placed it at, which stays put on the body
    /// when colliders added later move the centre of mass ([`RigidBody::origin`]).
    #[cfg_attr(feature = "serde", serde(default))]
    origin_offset: Vec3,
    /// Rotation about each world axis (x, y, z) locked ([`RigidBody::set_rotation_locks`]).
    #[cfg_attr(feature = "serde", serde(default))]
    rotation_locks: [bool; 3],
    /// Translation along each world axis (x, y, z) locked
    /// ([`RigidBody::set_translation_locks`]).
    #[cfg_attr(feature = "serde", serde(default))]
    translation_locks: [bool; 3],
}

#[cfg(feature = "serde")]
fn one() -> f32 {
    1.0
}

#[cfg(feature = "serde")]
fn is_zero(v: &Vec3) -> bool {
    *v == Vec3::ZERO
}

impl RigidBody {
    /// A dynamic body of `mass` kg with body-space inertia tensor `inertia` (kg·m²), at the
    /// origin, at rest. Errors on a non-finite or non-positive mass or inertia.
    pub fn dynamic(mass: f32, inertia: Mat3) -> Result<Self, MassError> {
        let mut body = Self::fixed();
        body.body_type = BodyType::Dynamic;
        body.set_mass_properties(mass, inertia)?;
        Ok(body)
    }

    /// Gives a dynamic body a new mass (kg) and body-space inertia tensor (kg·m²), keeping its
    /// pose, velocities and a rotation lock; a fixed body keeps them for when it becomes
    /// dynamic again ([`RigidBody::set_fixed`]). Errors, changing nothing, on a non-finite or
    /// non-positive mass or inertia.
    pub fn set_mass_properties(&mut self, mass: f32, inertia: Mat3) -> Result<(), MassError> {
        if !(mass.is_finite() && mass > 0.0) {
            return Err(MassError::Mass(mass));
        }
        let diag = Vec3::new(inertia.x_axis.x, inertia.y_axis.y, inertia.z_axis.z);
        let finite = inertia.to_cols_array().iter().all(|x| x.is_finite());
        if !finite || diag.min_element() <= 0.0 {
            return Err(MassError::Inertia(diag));
        }
        let finite_inverse = |m: &Mat3| m.to_cols_array().iter().all(|x| x.is_finite());
        let det = inertia.determinant();
        let mut inv_inertia = inertia.inverse();
        if !(det.is_finite() && det > 0.0 && finite_inverse(&inv_inertia)) {
            // Inverted at unit scale instead: the determinant of a heavy body's tensor
            // overflows f32 (a 1 m cube of 10²² kg: (1.7·10²¹)³) and a light one's underflows,
            // so the plain inverse is NaN or infinite where the scaled one is exact.
            let scale = diag.max_element();
            let unit = inertia * (1.0 / scale);
            inv_inertia = unit.inverse() * (1.0 / scale);
            if !(unit.determinant() > 0.0 && finite_inverse(&inv_inertia)) {
                return Err(MassError::Inertia(diag));
            }
        }
        self.mass = mass;
        self.inertia_body = inertia;
        if self.body_type != BodyType::Dynamic {
            return Ok(());
        }
        let locked = self.is_rotation_locked() && self.inv_mass > 0.0;
        self.inv_mass = 1.0 / mass;
        self.inv_inertia_body = if locked { Mat3::ZERO } else { inv_inertia };
        self.update_world_inertia();
        Ok(())
    }

    /// Makes the body fixed (immovable: at rest, no inverse mass or inertia, its forces
    /// cleared) or dynamic again: [`RigidBody::set_body_type`] with [`BodyType::Fixed`] or
    /// [`BodyType::Dynamic`].
    pub fn set_fixed(&mut self, fixed: bool) -> Result<(), MassError> {
        self.set_body_type(if fixed {
            BodyType::Fixed
        } else {
            BodyType::Dynamic
        })
    }

    /// Changes the body's type. A body that stops being dynamic keeps its mass properties (and
    /// rotation lock) for when it becomes dynamic again; a fixed body comes to rest, a
    /// kinematic one keeps its velocities (and moves with them until told otherwise). Forces
    /// are cleared. Errors, changing nothing, when a body that was never dynamic has no mass
    /// properties to become dynamic with: give them first with
    /// [`RigidBody::set_mass_properties`].
    pub fn set_body_type(&mut self, body_type: BodyType) -> Result<(), MassError> {
        if body_type == self.body_type {
            return Ok(());
        }
        if body_type != BodyType::Dynamic {
            if self.body_type == BodyType::Dynamic {
                self.locked_while_fixed = self.is_rotation_locked();
            }
            self.body_type = body_type;
            self.inv_mass = 0.0;
            self.inv_inertia_body = Mat3::ZERO;
            if body_type == BodyType::Fixed {
                self.linear_velocity = Vec3::ZERO;
                self.angular_velocity = Vec3::ZERO;
            }
            self.next_pose = None;
            self.path_acceleration = Vec3::ZERO;
            if body_type != BodyType::KinematicPosition {
                self.path = None;
            }
            self.last_acceleration = Vec3::ZERO;
            self.clear_forces();
            self.update_world_inertia();
            return Ok(());
        }
        let (mass, inertia) = (self.mass, self.inertia_body);
        let mut dynamic = self.clone();
        dynamic.body_type = BodyType::Dynamic;
        dynamic.inv_mass = 0.0;
        dynamic.set_mass_properties(mass, inertia)?;
        if self.locked_while_fixed {
            dynamic.lock_rotation();
        }
        dynamic.locked_while_fixed = false;
        dynamic.next_pose = None;
        dynamic.path_acceleration = Vec3::ZERO;
        dynamic.path = None;
        dynamic.sleep.awake = true;
        *self = dynamic;
        Ok(())
    }

    /// The body's type.
    #[inline]
    pub fn body_type(&self) -> BodyType {
        self.body_type
    }

    /// Whether the body is kinematic (moved by its velocity or its next pose, pushed by
    /// nothing).
    #[inline]
    pub fn is_kinematic(&self) -> bool {
        matches!(
            self.body_type,
            BodyType::KinematicVelocity | BodyType::KinematicPosition
        )
    }

    /// Whether nothing can push the body: it is fixed or kinematic.
    #[inline]
    pub fn is_immovable(&self) -> bool {
        self.body_type != BodyType::Dynamic
    }

    /// Whether a kinematic body moves in the next step (a velocity, or a next pose to reach).
    #[inline]
    pub fn kinematic_moves(&self) -> bool {
        self.is_kinematic()
            && (self.next_pose.is_some()
                || self.linear_velocity != Vec3::ZERO
                || self.angular_velocity != Vec3::ZERO)
    }

    /// For a position-based kinematic body: the pose to reach at the end of the next step
    /// (its velocities for the step are derived from it). Does nothing to other bodies.
    pub fn set_next_pose(&mut self, position: Vec3, orientation: Quat) {
        if self.body_type == BodyType::KinematicPosition {
            self.next_pose = Some((position, orientation.normalize()));
            self.path_acceleration = Vec3::ZERO;
        }
    }

    /// The scripted motion of a position-based kinematic body, if it has one.
    pub fn path(&self) -> Option<&KinematicPath> {
        self.path.as_ref()
    }

    /// Gives a position-based kinematic body a scripted motion (or takes it away with
    /// `None`): [`RigidBody::follow_path`] then sends it along. Does nothing to other bodies;
    /// changing the body's type to any other takes the path away.
    pub fn set_path(&mut self, path: Option<KinematicPath>) {
        if self.body_type == BodyType::KinematicPosition {
            self.path = path;
        }
    }

    /// Sends a body with a path to the path's pose at time `t` (s; the end of the coming
    /// step), as [`RigidBody::set_next_pose`] would. Returns whether it had a path.
    pub fn follow_path(&mut self, t: f64) -> bool {
        let Some(path) = self.path else {
            return false;
        };
        let (position, orientation) = path.pose_at(t);
        self.set_next_pose(position, orientation);
        true
    }

    /// [`RigidBody::follow_path`] for a step from time `start` to `end` (s), which also
    /// records the path's acceleration at the middle of the step
    /// ([`RigidBody::path_acceleration`]): the step's velocity is the mean one, and a
    /// resolver can move the body through the step at the velocity of each instant.
    pub fn follow_path_over(&mut self, start: f64, end: f64) -> bool {
        let Some(path) = self.path else {
            return false;
        };
        self.follow_path(end);
        self.path_acceleration = path.acceleration_at(0.5 * (start + end));
        true
    }

    /// The acceleration at the middle of the coming step of a body sent along its path by
    /// [`RigidBody::follow_path_over`] (m/s²); zero for a body sent anywhere else, or
    /// nowhere.
    pub fn path_acceleration(&self) -> Vec3 {
        self.path_acceleration
    }

    /// The next pose of a position-based kinematic body, taken for the step: sets the
    /// velocities that reach it in `dt` (zero without one) and returns it, so that the pose
    /// can be set exactly at the end of the step.
    pub fn take_next_pose(&mut self, dt: f32) -> Option<(Vec3, Quat)> {
        if self.body_type != BodyType::KinematicPosition {
            return None;
        }
        let Some((position, orientation)) = self.next_pose.take() else {
            self.linear_velocity = Vec3::ZERO;
            self.angular_velocity = Vec3::ZERO;
            self.path_acceleration = Vec3::ZERO;
            return None;
        };
        self.linear_velocity = (position - self.position) / dt;
        // The rotation from the current orientation to the target, the shorter way round.
        let mut turn = orientation * self.orientation.inverse();
        if turn.w < 0.0 {
            turn = -turn;
        }
        let (axis, angle) = turn.to_axis_angle();
        self.angular_velocity = if angle.is_finite() && angle > 0.0 {
            axis * (angle / dt)
        } else {
            Vec3::ZERO
        };
        Some((position, orientation))
    }

    /// An immovable body (infinite mass and inertia) at the origin.
    pub fn fixed() -> Self {
        Self {
            name: String::new(),
            position: Vec3::ZERO,
            orientation: Quat::IDENTITY,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            linear_damping: 0.0,
            angular_damping: 0.0,
            last_acceleration: Vec3::ZERO,
            sleep: SleepState::default(),
            ccd: CcdMode::Auto,
            mass: f32::INFINITY,
            inv_mass: 0.0,
            inertia_body: Mat3::ZERO,
            inv_inertia_body: Mat3::ZERO,
            inv_inertia_world: Mat3::ZERO,
            force: Vec3::ZERO,
            torque: Vec3::ZERO,
            body_type: BodyType::Fixed,
            locked_while_fixed: false,
            next_pose: None,
            path_acceleration: Vec3::ZERO,
            path: None,
            gravity_scale: 1.0,
            origin_offset: Vec3::ZERO,
            rotation_locks: [false; 3],
            translation_locks: [false; 3],
        }
    }

    /// Sets the pose (builder style) and refreshes the world inverse inertia.
    pub fn with_pose(mut self, position: Vec3, orientation: Quat) -> Self {
        self.position = position;
        self.orientation = orientation.normalize();
        self.update_world_inertia();
        self
    }

    /// Sets the name (builder style).
    pub fn with_name(mut self, name: impl Into<String>) -> Self {
        self.name = name.into();
        self
    }

    /// Sets the velocities (builder style).
    pub fn with_velocity(mut self, linear: Vec3, angular: Vec3) -> Self {
        self.linear_velocity = linear;
        self.angular_velocity = angular;
        self
    }

    /// Whether the body is immovable.
    #[inline]
    pub fn is_fixed(&self) -> bool {
        self.body_type == BodyType::Fixed
    }

    /// Whether the body is awake (fixed bodies report `false`: they are never simulated).
    #[inline]
    pub fn is_awake(&self) -> bool {
        !self.is_fixed() && self.sleep.awake
    }

    /// Mass (kg); infinite for a fixed body.
    #[inline]
    pub fn mass(&self) -> f32 {
        if self.is_immovable() {
            f32::INFINITY
        } else {
            self.mass
        }
    }

    /// The world position of the body's own origin (m): the point its description placed it
    /// at, which need not be its centre of mass ([`RigidBody::position`]) and does not move
    /// on the body when colliders are added.
    pub fn origin(&self) -> Vec3 {
        self.position + self.orientation * self.origin_offset
    }

    /// The body's origin relative to its centre of mass, along the body's axes (m).
    pub fn origin_offset(&self) -> Vec3 {
        self.origin_offset
    }

    /// Sets [`RigidBody::origin_offset`] (the centre of mass moved on the body by `−offset`
    /// from the origin; the pose is unchanged).
    pub fn set_origin_offset(&mut self, offset: Vec3) {
        self.origin_offset = offset;
    }

    /// The mass (kg) and body-space inertia tensor (kg·m², about the centre of mass) the
    /// body has, or keeps while fixed or kinematic; `None` for a body that was never dynamic
    /// ([`RigidBody::fixed`]).
    pub fn mass_properties(&self) -> Option<(f32, Mat3)> {
        self.has_mass_properties()
            .then_some((self.mass, self.inertia_body))
    }

    /// Whether the body has (or, fixed, keeps) finite mass properties: false for a body that
    /// was never dynamic ([`RigidBody::fixed`]).
    pub fn has_mass_properties(&self) -> bool {
        self.mass.is_finite() && self.inertia_body != Mat3::ZERO
    }

    /// 1/mass (1/kg); zero for a fixed body.
    #[inline]
    pub fn inv_mass(&self) -> f32 {
        self.inv_mass
    }

    /// Body-space inverse inertia tensor.
    #[inline]
    pub fn inv_inertia_body(&self) -> Mat3 {
        self.inv_inertia_body
    }

    /// World-space inverse inertia R·I⁻¹·Rᵀ at the current orientation.
    #[inline]
    pub fn inv_inertia_world(&self) -> Mat3 {
        self.inv_inertia_world
    }

    /// Locks the body's rotation: its inverse inertia becomes zero, so no contact, impulse or
    /// torque turns it, and resolvers skip its angular terms altogether; its angular velocity
    /// is set to zero. The mass and the stored inertia (for [`RigidBody::kinetic_energy`]) are
    /// kept. Does nothing to a fixed body.
    pub fn lock_rotation(&mut self) {
        if self.is_immovable() {
            return;
        }
        self.inv_inertia_body = Mat3::ZERO;
        self.angular_velocity = Vec3::ZERO;
        self.update_world_inertia();
    }

    /// Whether the body's rotation is locked ([`RigidBody::lock_rotation`]).
    #[inline]
    pub fn is_rotation_locked(&self) -> bool {
        self.body_type == BodyType::Dynamic && self.inv_inertia_body == Mat3::ZERO
    }

    /// Recomputes the world inverse inertia from the orientation; call after changing
    /// `orientation` directly.
    #[inline]
    pub fn update_world_inertia(&mut self) {
        self.inv_inertia_world = self.inv_inertia_world_at(self.orientation);
    }

    /// The world inverse inertia the body would have at `orientation`: R·I⁻¹·Rᵀ, with the
    /// rows and columns of locked world axes zeroed ([`RigidBody::set_rotation_locks`]).
    #[inline]
    pub fn inv_inertia_world_at(&self, orientation: Quat) -> Mat3 {
        let inv = world_inverse_inertia(orientation, self.inv_inertia_body);
        if self.rotation_locks == [false; 3] {
            inv
        } else {
            let p = Mat3::from_diagonal(self.unlocked_axes());
            p * inv * p
        }
    }

    /// 1 for each world axis the body may turn about, 0 for a locked one.
    fn unlocked_axes(&self) -> Vec3 {
        let free = |locked: bool| if locked { 0.0 } else { 1.0 };
        Vec3::new(
            free(self.rotation_locks[0]),
            free(self.rotation_locks[1]),
            free(self.rotation_locks[2]),
        )
    }

    /// Locks rotation about some world axes (x, y, z): the world inverse inertia loses their
    /// rows and columns, so no contact, impulse or torque turns the body about them, and the
    /// angular velocity loses its components along them (a body locked about x and z turns
    /// about the vertical only, a wheel that cannot tip). The stored inertia is kept; `[false;
    /// 3]` unlocks. [`RigidBody::lock_rotation`] locks every axis the cheaper way.
    pub fn set_rotation_locks(&mut self, locks: [bool; 3]) {
        self.rotation_locks = locks;
        self.angular_velocity = self.without_locked_turn(self.angular_velocity);
        self.update_world_inertia();
    }

    /// Which world axes' rotation is locked ([`RigidBody::set_rotation_locks`]).
    pub fn rotation_locks(&self) -> [bool; 3] {
        self.rotation_locks
    }

    /// `omega` without its components about locked world axes.
    #[inline]
    pub fn without_locked_turn(&self, omega: Vec3) -> Vec3 {
        if self.rotation_locks == [false; 3] {
            omega
        } else {
            omega * self.unlocked_axes()
        }
    }

    /// Locks translation along some world axes (x, y, z): the body's inverse mass along them
    /// is zero, so no contact, impulse, force or gravity moves its centre of mass along them,
    /// and its linear velocity loses its components along them (a body locked along z moves
    /// in its x-y plane only: a 2D game's body, with [`RigidBody::set_rotation_locks`] about x
    /// and y). The mass is kept; `[false; 3]` unlocks.
    pub fn set_translation_locks(&mut self, locks: [bool; 3]) {
        self.translation_locks = locks;
        self.linear_velocity = self.without_locked_motion(self.linear_velocity);
    }

    /// Which world axes' translation is locked ([`RigidBody::set_translation_locks`]).
    pub fn translation_locks(&self) -> [bool; 3] {
        self.translation_locks
    }

    /// `v` without its components along world axes the body's translation is locked on.
    #[inline]
    pub fn without_locked_motion(&self, v: Vec3) -> Vec3 {
        if self.translation_locks == [false; 3] {
            v
        } else {
            let free = |locked: bool| if locked { 0.0 } else { 1.0 };
            v * Vec3::new(
                free(self.translation_locks[0]),
                free(self.translation_locks[1]),
                free(self.translation_locks[2]),
            )
        }
    }

    /// Checks a body that did not come from [`RigidBody::dynamic`] or [`RigidBody::fixed`] (a
    /// snapshot read back): every number finite and in its domain, a unit orientation, mass
    /// and inverse mass that agree, a fixed body with no inverse mass or inertia, and
    /// refreshes the world inverse inertia from the body-space one rather than trusting it.
    /// The error names the field and what is wrong.
    pub fn check(&mut self) -> Result<(), (&'static str, String)> {
        let vector = |field: &'static str, v: Vec3| {
            if v.is_finite() {
                Ok(())
            } else {
                Err((field, format!("must be finite, got {v}")))
            }
        };
        vector("position", self.position)?;
        vector("linear_velocity", self.linear_velocity)?;
        vector("angular_velocity", self.angular_velocity)?;
        vector("last_acceleration", self.last_acceleration)?;
        vector("force", self.force)?;
        vector("origin_offset", self.origin_offset)?;
        if let Some(path) = &self.path {
            path.check()
                .map_err(|(field, message)| ("path", format!("{field} {message}")))?;
            if self.body_type != BodyType::KinematicPosition {
                return Err((
                    "path",
                    "only a position-based kinematic body follows a path".into(),
                ));
            }
        }
        vector("torque", self.torque)?;
        let length = self.orientation.length();
        if !(self.orientation.is_finite() && (length - 1.0).abs() < 1e-3) {
            return Err((
                "orientation",
                format!("must be a unit quaternion, got {:?}", self.orientation),
            ));
        }
        let non_negative = |field: &'static str, x: f32| {
            if x.is_finite() && x >= 0.0 {
                Ok(())
            } else {
                Err((field, format!("must be finite and >= 0, got {x}")))
            }
        };
        non_negative("linear_damping", self.linear_damping)?;
        non_negative("angular_damping", self.angular_damping)?;
        non_negative("sleep.motion", self.sleep.motion)?;
        vector("sleep.mean_linear", self.sleep.mean_linear)?;
        vector("sleep.mean_angular", self.sleep.mean_angular)?;
        if !self.gravity_scale.is_finite() {
            return Err((
                "gravity_scale",
                format!("must be finite, got {}", self.gravity_scale),
            ));
        }
        let finite = |m: &Mat3| m.to_cols_array().iter().all(|x| x.is_finite());
        if self.is_immovable() {
            if self.inv_mass != 0.0 || self.inv_inertia_body != Mat3::ZERO {
                return Err((
                    "body_type",
                    format!(
                        "a fixed or kinematic body has no inverse mass or inertia, got inv_mass {}",
                        self.inv_mass
                    ),
                ));
            }
        } else {
            if !(self.mass.is_finite() && self.mass > 0.0) {
                return Err(("mass", format!("must be finite and > 0, got {}", self.mass)));
            }
            let agree = (self.inv_mass * self.mass - 1.0).abs() < 1e-3;
            if !(self.inv_mass.is_finite() && self.inv_mass > 0.0 && agree) {
                return Err((
                    "inv_mass",
                    format!(
                        "must be 1/mass = {}, got {}",
                        1.0 / self.mass,
                        self.inv_mass
                    ),
                ));
            }
            let diagonal = |m: &Mat3| Vec3::new(m.x_axis.x, m.y_axis.y, m.z_axis.z);
            if !(finite(&self.inertia_body) && diagonal(&self.inertia_body).min_element() >= 0.0) {
                return Err((
                    "inertia_body",
                    format!(
                        "must be finite with a diagonal >= 0, got {}",
                        self.inertia_body
                    ),
                ));
            }
            let inverse = &self.inv_inertia_body;
            // The inverse is the tensor's (to f32 rounding), or zero for a rotation-locked
            // body (or a tensor not recorded, in older snapshots).
            let identity = self.inertia_body * *inverse;
            let inverts = *inverse == Mat3::ZERO
                || self.inertia_body == Mat3::ZERO
                || (identity - Mat3::IDENTITY)
                    .to_cols_array()
                    .iter()
                    .all(|x| x.abs() < 1e-3);
            if !inverts {
                return Err((
                    "inv_inertia_body",
                    format!("must be the inverse of inertia_body, got {inverse}"),
                ));
            }
            if !(finite(inverse) && symmetric_semi_definite(inverse)) {
                return Err((
                    "inv_inertia_body",
                    format!("must be finite, symmetric and positive semi-definite, got {inverse}"),
                ));
            }
        }
        self.update_world_inertia();
        Ok(())
    }

    /// Force accumulated for the next step (N).
    #[inline]
    pub fn force(&self) -> Vec3 {
        self.force
    }

    /// Torque accumulated for the next step (N·m).
    #[inline]
    pub fn torque(&self) -> Vec3 {
        self.torque
    }

    /// Adds a force through the centre of mass for the next step.
    pub fn add_force(&mut self, force: Vec3) {
        self.force += force;
    }

    /// Adds a torque for the next step.
    pub fn add_torque(&mut self, torque: Vec3) {
        self.torque += torque;
    }

    /// Adds a force applied at world point `point`: the force, plus the torque
    /// (point − centre of mass) × force.
    pub fn add_force_at_point(&mut self, force: Vec3, point: Vec3) {
        self.force += force;
        self.torque += (point - self.position).cross(force);
    }

    /// Applies an impulse (N·s) at world point `point` now: Δv = J/m, Δω = I⁻¹·(r × J).
    /// No effect on a fixed body, none along locked axes
    /// ([`RigidBody::set_translation_locks`], [`RigidBody::set_rotation_locks`]).
    pub fn apply_impulse_at_point(&mut self, impulse: Vec3, point: Vec3) {
        self.linear_velocity += self.without_locked_motion(impulse * self.inv_mass);
        self.angular_velocity += self.inv_inertia_world * (point - self.position).cross(impulse);
    }

    /// Clears the force and torque accumulators (done after every step).
    #[inline]
    pub fn clear_forces(&mut self) {
        self.force = Vec3::ZERO;
        self.torque = Vec3::ZERO;
    }

    /// Kinetic energy ½·m·|v|² + ½·ω·I·ω (J); zero for a fixed body. The rotational part is
    /// evaluated in body space with the stored inertia (no matrix inversion): inverting the
    /// world inverse inertia of a needle-like body in f32 lost about 0.1% of its energy, which
    /// the property tests mistook for energy drift.
    pub fn kinetic_energy(&self) -> f32 {
        if self.is_immovable() {
            return 0.0;
        }
        let w = self.orientation.inverse() * self.angular_velocity;
        0.5 * self.mass * self.linear_velocity.length_squared() + 0.5 * w.dot(self.inertia_body * w)
    }

    /// Freezes the body where it is: it becomes fixed (immovable, zero velocity, no forces).
    /// Used to quarantine a body whose state went non-finite, so it cannot spread NaN.
    pub fn freeze(&mut self) {
        let (position, orientation, sleep) = (self.position, self.orientation, self.sleep);
        let name = std::mem::take(&mut self.name);
        *self = Self::fixed()
            .with_pose(position, orientation)
            .with_name(name);
        self.sleep = SleepState {
            awake: false,
            ..sleep
        };
    }

    /// Whether every number in the body's state is finite.
    pub fn is_finite(&self) -> bool {
        self.position.is_finite()
            && self.orientation.is_finite()
            && self.linear_velocity.is_finite()
            && self.angular_velocity.is_finite()
            && self.force.is_finite()
            && self.torque.is_finite()
    }
}

/// Whether `m` is symmetric and positive semi-definite, to f32 rounding (Sylvester's
/// criterion on the leading minors, each allowed a relative error; a rotation-locked body's
/// zero matrix passes).
fn symmetric_semi_definite(m: &Mat3) -> bool {
    let scale = m.to_cols_array().iter().fold(0.0f32, |a, x| a.max(x.abs()));
    if scale == 0.0 {
        return true;
    }
    let a = *m * (1.0 / scale);
    let tolerance = 1e-4;
    let symmetric = (a.x_axis.y - a.y_axis.x).abs() <= tolerance
        && (a.x_axis.z - a.z_axis.x).abs() <= tolerance
        && (a.y_axis.z - a.z_axis.y).abs() <= tolerance;
    let minor2 = a.x_axis.x * a.y_axis.y - a.x_axis.y * a.y_axis.x;
    let diagonal = a.x_axis.x.min(a.y_axis.y).min(a.z_axis.z);
    symmetric && diagonal >= -tolerance && minor2 >= -tolerance && a.determinant() >= -tolerance
}

#[cfg(test)]
mod tests {
    #[test]
    fn heavy_and_light_bodies_invert_their_inertia() {
        // A 1 m cube's tensor is m/6 on the diagonal; its determinant overflows f32 at 10²² kg
        // and underflows at 10⁻¹⁵ kg.
        for mass in [1e22f32, 1e30, 1e-15] {
            let inertia = Mat3::from_diagonal(Vec3::splat(mass / 6.0));
            let body = RigidBody::dynamic(mass, inertia).unwrap();
            let product = body.inv_inertia_body * inertia;
            assert!(
                product.abs_diff_eq(Mat3::IDENTITY, 1e-5),
                "mass {mass}: I⁻¹·I = {product}"
            );
        }
    }

    use super::*;

    #[test]
    fn force_at_an_off_centre_point_produces_its_torque() {
        let mut b = RigidBody::dynamic(2.0, Mat3::IDENTITY).unwrap();
        b.position = Vec3::new(1.0, 0.0, 0.0);
        // Push +Y at a point 1 m further along +X: torque r × F = (1,0,0) × (0,3,0) = (0,0,3).
        b.add_force_at_point(Vec3::new(0.0, 3.0, 0.0), Vec3::new(2.0, 0.0, 0.0));
        assert_eq!(b.force(), Vec3::new(0.0, 3.0, 0.0));
        assert_eq!(b.torque(), Vec3::new(0.0, 0.0, 3.0));
    }

    #[test]
    fn impulse_at_a_point_changes_both_velocities() {
        let mut b = RigidBody::dynamic(10.0, Mat3::from_diagonal(Vec3::splat(240.0))).unwrap();
        b.position = Vec3::new(20.1966, 16.1966, 0.0);
        // The seed's cube-on-floor impulse: Δv = (0, 1.8734, 0), Δω = (0, 0, 0.1715).
        b.apply_impulse_at_point(Vec3::new(0.0, 18.7337, 0.0), Vec3::new(22.3932, 8.0, 0.0));
        assert!((b.linear_velocity.y - 1.87337).abs() < 1e-4);
        assert!((b.angular_velocity.z - 0.1715).abs() < 1e-4);
    }

    #[test]
    fn bad_mass_is_rejected() {
        assert_eq!(
            RigidBody::dynamic(0.0, Mat3::IDENTITY),
            Err(MassError::Mass(0.0))
        );
        assert!(RigidBody::dynamic(f32::NAN, Mat3::IDENTITY).is_err());
        assert!(RigidBody::dynamic(1.0, Mat3::ZERO).is_err());
        assert!(
            RigidBody::dynamic(1.0, Mat3::from_diagonal(Vec3::new(1.0, f32::INFINITY, 1.0)))
                .is_err()
        );
    }
}
