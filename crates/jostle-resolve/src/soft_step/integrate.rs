//! Substep integration of the soft-step body states: gravity into velocities, velocities into
//! the step's position and rotation deltas (with the gyroscopic term: the angular momentum
//! carried through each turn).
//!
//! Semi-implicit Euler at the substep length h, as Box2D v3's `b2IntegrateVelocitiesTask` and
//! `b2IntegratePositionsTask`. Each function takes a run of body states after index 0 (the
//! static entry, which is never touched), so that threads can integrate runs of their own.

use super::body_state::{BodyState, EXACT_WARM, FREE, PseudoRow};
use super::gyroscopic::turn_inverted;
use crate::SolverBody;
use crate::energy::Inverse64;
use jostle_math::{Mat3, Quat, Vec3, integrate_orientation};

/// v ← v + g·h for every body of `states` with mass, and each body's share of its applied
/// forces, `pushes` (linear and angular velocity change per substep, parallel to `states`;
/// empty when no body has any).
pub fn integrate_velocities(states: &mut [BodyState], pushes: &[[Vec3; 2]], gravity: Vec3, h: f32) {
    debug_assert!(pushes.is_empty() || pushes.len() == states.len());
    let dv = gravity * h;
    for s in states.iter_mut() {
        if s.inv_mass > 0.0 && s.flags & FREE == 0 {
            // Not along a locked axis (a rare flag: one test of the common case).
            s.linear_velocity += if s.flags & SolverBody::LOCKS == 0 {
                dv
            } else {
                dv * s.linear_freedom()
            };
        }
    }
    for (s, [linear, angular]) in states.iter_mut().zip(pushes) {
        s.linear_velocity += *linear;
        s.angular_velocity += *angular;
    }
}

/// One body's warm start, carried from substep to substep as a velocity change instead of
/// being applied point by point ([`super::solve::warm_start`] runs on the first substep
/// only).
///
/// A substep's warm start adds M⁻¹·Jᵀ·λ of every contact's accumulated impulse λ to the
/// velocities. Every contact row that changes λ by δ adds M⁻¹·Jᵀ·δ, through the same
/// step-start Jacobian and inverse inertia, and nothing else between the warm start and the
/// end of the relax pass changes the velocities but the integration of the positions (the
/// gyroscopic term, the pseudo rotation). So the sum a body's warm start adds is what the
/// warm start before added plus what the contact passes since changed its velocities: the
/// velocities are marked when a pass starts and the difference is collected when it ends.
/// The same in exact arithmetic as applying every point's λ; in floats it differs by
/// rounding. A resting 20-row pyramid has 2,360 points and 210 bodies, so the seven warm
/// starts after the first pass over bodies instead of points (benches/RESULTS.md, "The warm
/// start carried by the bodies").
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Carried {
    /// The velocity change (linear m/s, angular rad/s) the accumulated contact impulses make.
    pub change: [Vec3; 2],
    /// The body's velocities when the contact pass under way started.
    pub before: [Vec3; 2],
}

/// Adds to each body's carried change what the contact passes since [`mark`] did to its
/// velocities (`carried` runs along `states`; free bodies and those whose warm start stays
/// point by point, [`EXACT_WARM`], are left alone).
pub fn collect(states: &[BodyState], carried: &mut [Carried]) {
    debug_assert_eq!(states.len(), carried.len());
    for (s, c) in states.iter().zip(carried.iter_mut()) {
        if s.flags & (FREE | EXACT_WARM) == 0 {
            c.change[0] += s.linear_velocity - c.before[0];
            c.change[1] += s.angular_velocity - c.before[1];
        }
    }
}

/// Marks each body's velocities as those a contact pass starts from.
pub fn mark(states: &[BodyState], carried: &mut [Carried]) {
    debug_assert_eq!(states.len(), carried.len());
    for (s, c) in states.iter().zip(carried.iter_mut()) {
        c.before = [s.linear_velocity, s.angular_velocity];
    }
}

/// The first substep's point-by-point warm start taken as each body's carried change
/// (velocities now less those [`mark`]ed before it), then marked.
pub fn start_carrying(states: &[BodyState], carried: &mut [Carried]) {
    debug_assert_eq!(states.len(), carried.len());
    for (s, c) in states.iter().zip(carried.iter_mut()) {
        c.change = [
            s.linear_velocity - c.before[0],
            s.angular_velocity - c.before[1],
        ];
        c.before = [s.linear_velocity, s.angular_velocity];
    }
}

/// The warm start of a substep after the first: each body's carried change added to its
/// velocities (free bodies have none; [`EXACT_WARM`] bodies get theirs point by point).
pub fn apply_carried(states: &mut [BodyState], carried: &[Carried]) {
    debug_assert_eq!(states.len(), carried.len());
    for (s, c) in states.iter_mut().zip(carried) {
        if s.flags & (FREE | EXACT_WARM) == 0 {
            s.linear_velocity += c.change[0];
            s.angular_velocity += c.change[1];
        }
    }
}

/// Rotation per substep (rad) below which the gyroscopic term is skipped: its change to ω
/// is about h·|ω| times the inertia's anisotropy, relative, so at 10⁻⁵ rad per substep
/// (|ω| < 2.4·10⁻³ rad/s at 240 substeps per second) it is below what a stack's contacts
/// change every substep, and a body that slow turns less than 2.4 mrad per second.
pub const GYROSCOPIC_CUTOFF: f32 = 1e-5;

/// The gyroscopic term's inputs of [`integrate_positions`], each running along the body
/// states.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Gyro<'a> {
    /// Each body's world inertia at the start of the step, zero for a body without one, whose
    /// inertia is the same about every axis, or whose moments f32 cannot hold
    /// (`gyroscopic::within_f32`).
    pub(crate) inertia: &'a [Mat3],
    /// The f64 inverse of each body's `inertia`, taken once for the step; `None` where the
    /// inertia is zero or cannot be inverted (the body then turns by ω alone).
    pub(crate) inverse: &'a [Option<Inverse64>],
    /// Each body's `inertia` as an axisymmetric one ([`super::gyroscopic::Axisymmetric::of`])
    /// where it is and the body has no contact rows, `None` otherwise: such a body turns
    /// exactly.
    pub(crate) axisymmetric: &'a [Option<super::gyroscopic::Axisymmetric>],
    /// The step-start world inverse inertia each body's contact rows use, zero for a body
    /// without contact rows.
    pub(crate) rows_inverse: &'a [Mat3],
}

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
/// With `gyro` ([`Gyro`]) this is also where the gyroscopic term acts
/// (`gyroscopic::turn_against`): a body that turns by at least
/// [`GYROSCOPIC_CUTOFF`] keeps its world angular momentum L = I·ω through the turn, its ω
/// recomputed from L at the new orientation, unless its inertia has turned too far from the
/// one its contact rows use.
pub(crate) fn integrate_positions(
    states: &mut [BodyState],
    pseudo: &mut [PseudoRow],
    gyro: Option<Gyro<'_>>,
    h: f32,
) {
    debug_assert_eq!(states.len(), pseudo.len());
    debug_assert!(gyro.is_none_or(|g| g.inertia.len() == states.len()
        && g.inverse.len() == states.len()
        && g.axisymmetric.len() == states.len()
        && g.rows_inverse.len() == states.len()));
    for (k, (s, p)) in states.iter_mut().zip(pseudo.iter_mut()).enumerate() {
        if s.flags & FREE != 0 {
            // No contact row writes its pseudo velocities: the row stays zero.
            continue;
        }
        let linear = Vec3::new(p[0], p[1], p[2]);
        let angular = Vec3::new(p[4], p[5], p[6]);
        *p = [0.0; 8];
        s.delta_position += (s.linear_velocity + linear) * h;
        if s.rotates() {
            let turn_sq = s.angular_velocity.length_squared() * (h * h);
            // (A body without an inertia has no inverse either.)
            let carried = gyro
                .filter(|_| turn_sq >= GYROSCOPIC_CUTOFF * GYROSCOPIC_CUTOFF)
                .and_then(|g| {
                    let inverse = g.inverse[k].as_ref()?;
                    let (i0, rows) = (g.inertia[k], g.rows_inverse[k]);
                    turn_inverted(
                        i0,
                        inverse,
                        g.axisymmetric[k].as_ref(),
                        rows,
                        s.delta_rotation,
                        s.angular_velocity,
                        h,
                    )
                });
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

/// The substeps of the bodies marked [`FREE`], all at once after the others' (and the mark
/// cleared): `substeps` rounds of v ← v + g·h, Δx ← Δx + v·h sum to
/// Δx = n·h·v₀ + g·h²·n(n + 1)/2 and v = v₀ + n·g·h, the same semi-implicit Euler
/// trajectory as stepping them one by one (to rounding), at the cost of one.
pub fn integrate_free(states: &mut [BodyState], gravity: Vec3, h: f32, substeps: u32) {
    let n = substeps as f32;
    let dv = gravity * h;
    for s in states.iter_mut().filter(|s| s.flags & FREE != 0) {
        let g = if s.inv_mass > 0.0 {
            dv * s.linear_freedom()
        } else {
            Vec3::ZERO
        };
        s.delta_position += (s.linear_velocity * n + g * (n * (n + 1.0) * 0.5)) * h;
        s.linear_velocity += g * n;
        s.flags &= !FREE;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A free body's substeps at once land where stepping them one by one does.
    #[test]
    fn free_flight_at_once_matches_substep_by_substep() {
        let mut body = SolverBody::STATIC;
        body.inv_mass = 0.5;
        body.linear_velocity = Vec3::new(3.0, 4.0, -1.0);
        let (g, h, n) = (Vec3::new(0.0, -9.81, 0.0), 1.0 / 480.0, 8);
        let mut one_by_one = [BodyState::from_body(&body)];
        let mut pseudo = [[0.0; 8]];
        for _ in 0..n {
            integrate_velocities(&mut one_by_one, &[], g, h);
            integrate_positions(&mut one_by_one, &mut pseudo, None, h);
        }
        let mut at_once = [BodyState::from_body(&body)];
        at_once[0].flags |= FREE;
        for _ in 0..n {
            integrate_velocities(&mut at_once, &[], g, h);
            integrate_positions(&mut at_once, &mut pseudo, None, h);
        }
        integrate_free(&mut at_once, g, h, n);
        let (a, b) = (one_by_one[0], at_once[0]);
        assert!(
            a.delta_position.abs_diff_eq(b.delta_position, 1e-6),
            "{a:?} {b:?}"
        );
        assert!(
            a.linear_velocity.abs_diff_eq(b.linear_velocity, 1e-5),
            "{a:?} {b:?}"
        );
        assert_eq!(b.flags & FREE, 0);
    }
}
