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

/// Rotation per substep (rad) below which the gyroscopic term is skipped: its change to ω
/// is about h·|ω| times the inertia's anisotropy, relative, so at 10⁻⁵ rad per substep
/// (|ω| < 2.4·10⁻³ rad/s at 240 substeps per second) it is below what a stack's contacts
/// change every substep, and a body that slow turns less than 2.4 mrad per second.
pub const GYROSCOPIC_CUTOFF: f32 = 1e-5;

/// [`integrate_velocities`] plus the implicit gyroscopic term for every rotating body whose
/// step-start world inertia `inertia[i]` is known (non-zero) and which turns by at least
/// [`GYROSCOPIC_CUTOFF`] per substep, the inertia rotated by the body's motion since the
/// start of the step ([`rotate_inertia`]).
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
        // Below GYROSCOPIC_CUTOFF rad per substep the term changes ω by a relative 10⁻⁵ or
        // less per substep; a settled stack's bodies sit there and skip the 3×3 solve.
        let turn_sq = s.angular_velocity.length_squared() * (h * h);
        if s.rotates() && i0 != Mat3::ZERO && turn_sq >= GYROSCOPIC_CUTOFF * GYROSCOPIC_CUTOFF {
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
