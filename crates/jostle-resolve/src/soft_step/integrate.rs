//! Substep integration of the soft-step body states: gravity (and the gyroscopic torque)
//! into velocities, velocities into the step's position and rotation deltas.
//!
//! Semi-implicit Euler at the substep length h, as Box2D v3's `b2IntegrateVelocitiesTask` and
//! `b2IntegratePositionsTask`. Index 0 (the static entry) is never touched.

use super::body_state::BodyState;
use super::gyroscopic::{gyroscopic_step, rotate_inertia};
use crate::STATIC_BODY;
use jostle_math::{Mat3, Vec3, integrate_orientation};

/// v ← v + g·h for every body with mass; no angular change.
pub fn integrate_velocities(states: &mut [BodyState], gravity: Vec3, h: f32) {
    let dv = gravity * h;
    for s in states.iter_mut().skip(STATIC_BODY as usize + 1) {
        if s.inv_mass > 0.0 {
            s.linear_velocity += dv;
        }
    }
}

/// [`integrate_velocities`] plus the implicit gyroscopic term for every rotating body whose
/// step-start world inertia `inertia[i]` is known (non-zero), rotated by the body's motion
/// since the start of the step ([`rotate_inertia`]).
pub fn integrate_velocities_gyroscopic(
    states: &mut [BodyState],
    inertia: &[Mat3],
    gravity: Vec3,
    h: f32,
) {
    debug_assert_eq!(states.len(), inertia.len());
    let dv = gravity * h;
    let start = STATIC_BODY as usize + 1;
    for (s, &i0) in states.iter_mut().zip(inertia).skip(start) {
        if s.inv_mass > 0.0 {
            s.linear_velocity += dv;
        }
        if s.rotates() && i0 != Mat3::ZERO {
            let i = rotate_inertia(i0, s.delta_rotation);
            s.angular_velocity = gyroscopic_step(i, s.angular_velocity, h);
        }
    }
}

/// Δx ← Δx + v·h, Δq ← Δq rotated by ω·h ([`integrate_orientation`], which acts in world
/// space, so Δq·q₀ is exactly the orientation integrated directly).
pub fn integrate_positions(states: &mut [BodyState], h: f32) {
    for s in states.iter_mut().skip(STATIC_BODY as usize + 1) {
        s.delta_position += s.linear_velocity * h;
        if s.rotates() {
            s.delta_rotation = integrate_orientation(s.delta_rotation, s.angular_velocity * h);
        }
    }
}
