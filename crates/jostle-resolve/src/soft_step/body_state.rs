//! The soft-step resolver's per-body working state: velocities and the motion since the
//! start of the step.
//!
//! Box2D v3's `b2BodyState` in 3D. The contact solver reads and writes only this (64 bytes,
//! one cache line per body): the velocities it changes, the inverse mass it scales by, and
//! the position and rotation deltas from which it recomputes each contact's separation
//! without touching the poses. Poses themselves are only written back at the end of the
//! step: pose = start pose moved by the deltas.

use crate::SolverBody;
use jostle_math::{Quat, Vec3};

/// Hot state of one body during a soft step.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct BodyState {
    /// Linear velocity (m/s).
    pub linear_velocity: Vec3,
    /// 1/mass (1/kg); zero for the static entry.
    pub inv_mass: f32,
    /// Angular velocity (rad/s), world space.
    pub angular_velocity: Vec3,
    /// [`SolverBody`] flags ([`SolverBody::ROTATES`]).
    pub flags: u32,
    /// Rotation since the start of the step, in world space: orientation = Δq · q₀.
    pub delta_rotation: Quat,
    /// Displacement of the centre of mass since the start of the step (m).
    pub delta_position: Vec3,
}

const _: () = assert!(size_of::<BodyState>() <= 64);

impl BodyState {
    /// The state of the static entry: no motion, no mass.
    pub const STATIC: BodyState = BodyState {
        linear_velocity: Vec3::ZERO,
        inv_mass: 0.0,
        angular_velocity: Vec3::ZERO,
        flags: 0,
        delta_rotation: Quat::IDENTITY,
        delta_position: Vec3::ZERO,
    };

    /// The state of `body` at the start of the step.
    pub fn from_body(body: &SolverBody) -> Self {
        Self {
            linear_velocity: body.linear_velocity,
            inv_mass: body.inv_mass,
            angular_velocity: body.angular_velocity,
            flags: body.flags,
            delta_rotation: Quat::IDENTITY,
            delta_position: Vec3::ZERO,
        }
    }

    /// Whether angular terms apply to this body.
    #[inline]
    pub fn rotates(&self) -> bool {
        self.flags & SolverBody::ROTATES != 0
    }

    /// Writes the state back into `body`: velocities, and the pose moved by the deltas.
    pub fn store(&self, body: &mut SolverBody) {
        body.linear_velocity = self.linear_velocity;
        body.angular_velocity = self.angular_velocity;
        body.position += self.delta_position;
        if self.rotates() {
            body.orientation = (self.delta_rotation * body.orientation).normalize();
        }
    }
}
