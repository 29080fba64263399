//! The solver's hot, dense view of a rigid body.

use jostle_math::{Mat3, Quat, Vec3};

/// Index of the shared static entry in every solver-body slice: an immovable body at the
/// origin with zero velocity, zero inverse mass and zero inverse inertia. Contacts against
/// any fixed body (ground, walls, meshes) name this index. Resolvers never write it, which is
/// what lets independent islands be solved in parallel.
pub const STATIC_BODY: u32 = 0;

/// What a resolver reads and writes of one body, and nothing more: pose, velocities, inverse
/// mass, world-space inverse inertia, the acceleration of the last integration, and flags.
///
/// Fields are ordered hot to cold and sized to two cache lines. The facade copies the awake
/// bodies of the world into a `Vec<SolverBody>` at the start of the step (index 0 is
/// [`SolverBody::STATIC`]) and copies poses and velocities back at the end; the user's
/// `RigidBody` is never touched by a resolver.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct SolverBody {
    /// Orientation (unit quaternion, x y z w).
    pub orientation: Quat,
    /// Position of the centre of mass in world space (m).
    pub position: Vec3,
    /// 1/mass (1/kg); zero for an immovable body.
    pub inv_mass: f32,
    /// Linear velocity of the centre of mass (m/s).
    pub linear_velocity: Vec3,
    /// Flags, see [`SolverBody::ROTATES`] and [`SolverBody::LOCK_X`].
    pub flags: u32,
    /// Angular velocity (rad/s), world space.
    pub angular_velocity: Vec3,
    /// World-space inverse inertia tensor R·I⁻¹·Rᵀ (1/(kg·m²)); zero for a body that cannot
    /// rotate. Resolvers that rotate a body within the step keep it as given (first order), and
    /// the facade recomputes it from the new orientation at the next step.
    pub inv_inertia: Mat3,
    /// Linear acceleration applied by the last integration (m/s²): the velocity it added
    /// was `last_acceleration * dt`. The Millington resolver's micro-collision rule removes it
    /// from closing velocities. jostle records gravity here (forces are applied as impulses
    /// before the resolver runs; the lecture allows "ignoring any force except gravity").
    pub last_acceleration: Vec3,
    /// The change of linear velocity this step's applied forces (and damping) make over the
    /// whole step (m/s), not yet in `linear_velocity`. A resolver adds it over the step as it
    /// adds gravity: Millington at once before resolving, the soft step in equal parts per
    /// substep, so that a force which static friction holds is answered within each substep
    /// instead of moving the body between its substeps.
    pub force_velocity: Vec3,
    /// The change of angular velocity this step's applied torques (and damping) make over the
    /// whole step (rad/s), added the same way.
    pub torque_velocity: Vec3,
    /// A kinematic body's acceleration at the middle of the step (m/s²), when it follows a
    /// curved path: `linear_velocity` is then its mean velocity over the step, and a resolver
    /// may move it through the step at `linear_velocity + path_acceleration·(t − dt/2)`. Zero
    /// for every other body.
    pub path_acceleration: Vec3,
}

const _: () = assert!(size_of::<SolverBody>() <= 144);

impl SolverBody {
    /// Flag: the body's inverse inertia is non-zero, so resolvers do angular work for it.
    /// Clear it to skip every angular term of a body that cannot rotate.
    pub const ROTATES: u32 = 1;
    /// Flag: the body cannot move along world x (its translation is locked on that axis):
    /// its inverse mass along x is zero ([`SolverBody::inv_mass_axes`]), and gravity and
    /// forces do not act along x. [`SolverBody::LOCK_Y`] and [`SolverBody::LOCK_Z`] likewise.
    pub const LOCK_X: u32 = 2;
    /// Flag: translation along world y locked (see [`SolverBody::LOCK_X`]).
    pub const LOCK_Y: u32 = 4;
    /// Flag: translation along world z locked (see [`SolverBody::LOCK_X`]).
    pub const LOCK_Z: u32 = 8;
    /// All three translation-lock flags.
    pub const LOCKS: u32 = Self::LOCK_X | Self::LOCK_Y | Self::LOCK_Z;

    /// The shared static entry: immovable, at rest, never written.
    pub const STATIC: SolverBody = SolverBody {
        orientation: Quat::IDENTITY,
        position: Vec3::ZERO,
        inv_mass: 0.0,
        linear_velocity: Vec3::ZERO,
        flags: 0,
        angular_velocity: Vec3::ZERO,
        inv_inertia: Mat3::ZERO,
        last_acceleration: Vec3::ZERO,
        force_velocity: Vec3::ZERO,
        torque_velocity: Vec3::ZERO,
        path_acceleration: Vec3::ZERO,
    };

    /// A dynamic body at `position` with the given inverse mass and world inverse inertia,
    /// at rest, with [`SolverBody::ROTATES`] set when the inverse inertia is non-zero.
    pub fn new(position: Vec3, orientation: Quat, inv_mass: f32, inv_inertia: Mat3) -> Self {
        let rotates = inv_inertia != Mat3::ZERO;
        Self {
            orientation,
            position,
            inv_mass,
            linear_velocity: Vec3::ZERO,
            flags: if rotates { Self::ROTATES } else { 0 },
            angular_velocity: Vec3::ZERO,
            inv_inertia,
            last_acceleration: Vec3::ZERO,
            force_velocity: Vec3::ZERO,
            torque_velocity: Vec3::ZERO,
            path_acceleration: Vec3::ZERO,
        }
    }

    /// Whether angular terms apply to this body.
    #[inline]
    pub fn rotates(&self) -> bool {
        self.flags & Self::ROTATES != 0
    }

    /// 1 along each world axis the body may move along, 0 along a locked one
    /// ([`SolverBody::LOCK_X`]).
    #[inline]
    pub fn linear_freedom(&self) -> Vec3 {
        Self::freedom_of(self.flags)
    }

    /// [`SolverBody::linear_freedom`] of a body with the flags `flags` (also read from a
    /// resolver's own copy of them).
    #[inline]
    pub fn freedom_of(flags: u32) -> Vec3 {
        if flags & Self::LOCKS == 0 {
            return Vec3::ONE;
        }
        let free = |bit: u32| if flags & bit == 0 { 1.0 } else { 0.0 };
        Vec3::new(free(Self::LOCK_X), free(Self::LOCK_Y), free(Self::LOCK_Z))
    }

    /// The inverse mass along each world axis (1/kg): [`SolverBody::inv_mass`], zero along a
    /// locked axis. An impulse J changes the velocity by `inv_mass_axes() * J`, component by
    /// component.
    #[inline]
    pub fn inv_mass_axes(&self) -> Vec3 {
        self.linear_freedom() * self.inv_mass
    }

    /// The inverse mass the body shows to an impulse along the unit vector `n` (1/kg):
    /// n·(M⁻¹·n), [`SolverBody::inv_mass`] without translation locks.
    #[inline]
    pub fn inv_mass_along(&self, n: Vec3) -> f32 {
        if self.flags & Self::LOCKS == 0 {
            self.inv_mass
        } else {
            n.dot(self.inv_mass_axes() * n)
        }
    }

    /// The direction the centre of mass moves in when the body is pushed along the unit
    /// vector `n`, scaled to advance 1 along `n`: M⁻¹·n / (n·M⁻¹·n); `n` itself without
    /// translation locks, zero when the body cannot move along `n` at all.
    #[inline]
    pub fn linear_direction(&self, n: Vec3) -> Vec3 {
        if self.flags & Self::LOCKS == 0 {
            return n;
        }
        let along = self.inv_mass_axes() * n;
        let k = n.dot(along);
        if k > 0.0 { along / k } else { Vec3::ZERO }
    }

    /// Whether the body can move at all (non-zero inverse mass or inverse inertia).
    #[inline]
    pub fn is_movable(&self) -> bool {
        self.inv_mass > 0.0 || self.rotates()
    }

    /// Velocity of the body's material point at world position `point` (m/s): v + ω × r.
    #[inline]
    pub fn velocity_at(&self, point: Vec3) -> Vec3 {
        self.linear_velocity + self.angular_velocity.cross(point - self.position)
    }
}
