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

/// The pseudo velocities of one body during a substep, as one row of eight floats: linear
/// (m/s) in 0–2, angular (rad/s) in 4–6, in 3 a mark (1) that the row was written this
/// substep, 0 in 7. They carry the push-out of overlap
/// ([`super::solve::solve`]): the bodies move with them in the substep, then they are cleared,
/// so pushing overlap out never becomes real velocity (split impulses, Catto 2006; Box2D
/// v2.1's and Bullet's position correction).
pub type PseudoRow = [f32; 8];

/// Flag of a [`BodyState`] (beside [`SolverBody::ROTATES`]): the body has no contact row this
/// step, does not turn and has no force on it, so its substeps are nothing but free flight;
/// the substep stages skip it and [`super::integrate::integrate_free`] integrates all of its
/// substeps at once after them.
pub const FREE: u32 = 1 << 8;

/// Flag of a [`BodyState`]: the body touches a body whose mass differs from its own by
/// [`super::EXACT_WARM_RATIO`] or more, so its warm start is applied point by point in every
/// substep instead of carried ([`super::integrate::Carried`]). Its velocity passes through
/// values far larger than its own change while the rows of the heavy side act on it (at
/// 1:10⁶, 10⁴ m/s for a change of 10⁻² m/s), and the rounding of those values would enter the
/// carried change and be applied again in every later substep.
pub const EXACT_WARM: u32 = 1 << 9;

/// Hot state of one body during a soft step.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
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
    /// Zero: makes the last of the 64 bytes a field, so the state reads as sixteen floats
    /// with no padding ([`BodyState::motion_row`]).
    pub pad: f32,
}

// Sixteen four-byte fields and no padding: the rows below cover the whole struct.
const _: () = assert!(size_of::<BodyState>() == 64 && align_of::<BodyState>() >= 4);

impl BodyState {
    /// The state of the static entry: no motion, no mass.
    pub const STATIC: BodyState = BodyState {
        linear_velocity: Vec3::ZERO,
        inv_mass: 0.0,
        angular_velocity: Vec3::ZERO,
        flags: 0,
        delta_rotation: Quat::IDENTITY,
        delta_position: Vec3::ZERO,
        pad: 0.0,
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
            pad: 0.0,
        }
    }

    /// 1 along each world axis the body may move along, 0 along a locked one
    /// ([`SolverBody::LOCK_X`]; the flags are the solver body's).
    #[inline(always)]
    pub fn linear_freedom(&self) -> Vec3 {
        SolverBody::freedom_of(self.flags)
    }

    /// The first eight floats: linear velocity, 1/m, angular velocity, and the flags' bits.
    #[inline(always)]
    pub fn velocity_row(&self) -> &[f32; 8] {
        // SAFETY: `BodyState` is `repr(C)`, 64 bytes of sixteen 4-byte fields with no padding
        // (asserted above), aligned to at least 4; its first 32 bytes are the fields named
        // above, and every bit pattern is a valid `f32` (the flags are read as their bits).
        unsafe { &*(self as *const BodyState).cast::<[f32; 8]>() }
    }

    /// [`BodyState::velocity_row`], writable. Whatever is written to lane 7 becomes the
    /// flags' bits, so callers write back what they read there.
    #[inline(always)]
    pub fn velocity_row_mut(&mut self) -> &mut [f32; 8] {
        // SAFETY: as for `velocity_row`; every bit pattern is also a valid `u32`.
        unsafe { &mut *(self as *mut BodyState).cast::<[f32; 8]>() }
    }

    /// The last eight floats: the rotation since the start of the step (x, y, z, w), the
    /// displacement, and the zero pad.
    #[inline(always)]
    pub fn motion_row(&self) -> &[f32; 8] {
        // SAFETY: as for `velocity_row`; bytes 32..64 are `delta_rotation`, `delta_position`
        // and `pad`.
        unsafe { &*(self as *const BodyState).cast::<[f32; 8]>().add(1) }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rows_are_the_fields_in_order() {
        let s = BodyState {
            linear_velocity: Vec3::new(1.0, 2.0, 3.0),
            inv_mass: 4.0,
            angular_velocity: Vec3::new(5.0, 6.0, 7.0),
            flags: 8.0f32.to_bits(),
            delta_rotation: Quat::from_xyzw(9.0, 10.0, 11.0, 12.0),
            delta_position: Vec3::new(13.0, 14.0, 15.0),
            pad: 0.0,
        };
        assert_eq!(s.velocity_row(), &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
        assert_eq!(
            s.motion_row(),
            &[9.0, 10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 0.0]
        );
        let mut t = s;
        t.velocity_row_mut()[4] = -5.0;
        assert_eq!(t.angular_velocity, Vec3::new(-5.0, 6.0, 7.0));
        assert_eq!(t.flags, s.flags);
    }
}
