//! Substep integration of the soft-step body states: gravity into velocities, velocities into
//! the step's position and rotation deltas (with the gyroscopic term: the angular momentum
//! carried through each turn).
//!
//! Semi-implicit Euler at the substep length h, as Box2D v3's `b2IntegrateVelocitiesTask` and
//! `b2IntegratePositionsTask`. Each function takes a run of body states after index 0 (the
//! static entry, which is never touched), so that threads can integrate runs of their own.

use super::body_state::{BodyState, PseudoRow};
use super::gyroscopic::turn_against;
use jostle_math::{Mat3, Quat, Vec3, integrate_orientation};

/// v ← v + g·h for every body of `states` with mass, and each body's share of its applied
/// forces, `pushes` (linear and angular velocity change per substep, parallel to `states`;
/// empty when no body has any).
pub fn integrate_velocities(states: &mut [BodyState], pushes: &[[Vec3; 2]], gravity: Vec3, h: f32) {
    debug_assert!(pushes.is_empty() || pushes.len() == states.len());
    let dv = gravity * h;
    for s in states.iter_mut() {
        if s.inv_mass > 0.0 {
            s.linear_velocity += dv;
        }
    }
    for (s, [linear, angular]) in states.iter_mut().zip(pushes) {
        s.linear_velocity += *linear;
        s.angular_velocity += *angular;
    }
}

/// Rotation per substep (rad) below which the gyroscopic term is skipped: its change to ω
/// is about h·|ω| times the inertia's anisotropy, relative, so at 10⁻⁵ rad per substep
/// (|ω| < 2.4·10⁻³ rad/s at 240 substeps per second) it is below what a stack's contacts
/// change every substep, and a body that slow turns less than 2.4 mrad per second.
pub const GYROSCOPIC_CUTOFF: f32 = 1e-5;

/// For every body of `states`, `pseudo` theirs: Δx ← Δx + (v + v̂)·h and Δq ← Δq rotated by
/// ω·h ([`integrate_orientation`], which acts in world space, so Δq·q₀ is exactly the orientation integrated directly), then by the pseudo
/// rotation ω̂·h, with v̂, ω̂ the pseudo velocities of `pseudo` ([`PseudoRow`]), which are then
/// cleared.
///
/// The pseudo rotation is a correction of the pose, not motion: ω turns with it, so the body
/// keeps its angular velocity in its own frame and its kinetic energy ½ωᵀIω is unchanged.
/// Left in world space, ω would meet an inertia tensor turned under it (a box spinning at
/// 10 rad/s pushed out of the floor gained 2.8% of its energy that way).
///
/// With `gyro` (each body's world inertia at the start of the step, zero for a body without
/// one; and the step-start world inverse inertia its contact rows use, zero for a body
/// without contact rows) this is also where the gyroscopic term acts
/// (`gyroscopic::turn_against`): a body that turns by at least
/// [`GYROSCOPIC_CUTOFF`] keeps its world angular momentum L = I·ω through the turn, its ω
/// recomputed from L at the new orientation, unless its inertia has turned too far from the
/// one its contact rows use.
pub fn integrate_positions(
    states: &mut [BodyState],
    pseudo: &mut [PseudoRow],
    gyro: Option<(&[Mat3], &[Mat3])>,
    h: f32,
) {
    debug_assert_eq!(states.len(), pseudo.len());
    debug_assert!(gyro.is_none_or(|(i, r)| i.len() == states.len() && r.len() == states.len()));
    for (k, (s, p)) in states.iter_mut().zip(pseudo.iter_mut()).enumerate() {
        let linear = Vec3::new(p[0], p[1], p[2]);
        let angular = Vec3::new(p[4], p[5], p[6]);
        *p = [0.0; 8];
        s.delta_position += (s.linear_velocity + linear) * h;
        if s.rotates() {
            let (i0, rows) = gyro.map_or((Mat3::ZERO, Mat3::ZERO), |(i, r)| (i[k], r[k]));
            let turn_sq = s.angular_velocity.length_squared() * (h * h);
            let carried = (i0 != Mat3::ZERO && turn_sq >= GYROSCOPIC_CUTOFF * GYROSCOPIC_CUTOFF)
                .then(|| turn_against(i0, rows, s.delta_rotation, s.angular_velocity, h))
                .flatten();
            let moved = match carried {
                Some((after, omega)) => {
                    s.angular_velocity = omega;
                    after
                }
                None => integrate_orientation(s.delta_rotation, s.angular_velocity * h),
            };
            if angular == Vec3::ZERO {
                s.delta_rotation = moved;
            } else {
                let turn = integrate_orientation(Quat::IDENTITY, angular * h);
                s.delta_rotation = (turn * moved).normalize();
                s.angular_velocity = turn * s.angular_velocity;
            }
        }
    }
}
