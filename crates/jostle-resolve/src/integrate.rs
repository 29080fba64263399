//! Semi-implicit Euler integration of solver bodies, shared by every resolver.
//!
//! v ← v + g·dt, then x ← x + v·dt and q ← q + ½·dt·(0, ω)·q (normalised). Integrating the
//! velocity first is what makes free fall follow y(n) = y0 + v0·n·dt − g·dt²·n(n+1)/2 exactly.

use crate::{STATIC_BODY, SolverBody};
use jostle_math::{Vec3, integrate_orientation};

/// Adds gravity and the step's applied forces ([`SolverBody::force_velocity`],
/// [`SolverBody::torque_velocity`], which are then cleared) to the velocity of every movable
/// body (index 0, the static entry, is skipped) and records gravity as the body's
/// `last_acceleration`. Neither acts along an axis the body's translation is locked on
/// ([`SolverBody::LOCK_X`]).
pub fn integrate_velocities(bodies: &mut [SolverBody], gravity: Vec3, dt: f32) {
    for body in bodies.iter_mut().skip(STATIC_BODY as usize + 1) {
        let free = body.linear_freedom();
        body.linear_velocity += std::mem::take(&mut body.force_velocity) * free;
        body.angular_velocity += std::mem::take(&mut body.torque_velocity);
        if body.inv_mass > 0.0 {
            body.linear_velocity += gravity * free * dt;
            body.last_acceleration = gravity * free;
        } else {
            body.last_acceleration = Vec3::ZERO;
        }
    }
}

/// Moves every body by its velocity over `dt` (the static entry is skipped).
pub fn integrate_positions(bodies: &mut [SolverBody], dt: f32) {
    for body in bodies.iter_mut().skip(STATIC_BODY as usize + 1) {
        body.position += body.linear_velocity * dt;
        if body.rotates() {
            body.orientation = integrate_orientation(body.orientation, body.angular_velocity * dt);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jostle_math::{Mat3, Quat};

    #[test]
    fn free_fall_is_exact_for_semi_implicit_euler() {
        let g = Vec3::new(0.0, -9.81, 0.0);
        let dt = 1.0 / 60.0;
        let mut bodies = vec![
            SolverBody::STATIC,
            SolverBody::new(
                Vec3::new(0.0, 10.0, 0.0),
                Quat::IDENTITY,
                1.0,
                Mat3::IDENTITY,
            ),
        ];
        bodies[1].linear_velocity = Vec3::new(0.0, 2.0, 0.0);
        let n = 120;
        for _ in 0..n {
            integrate_velocities(&mut bodies, g, dt);
            integrate_positions(&mut bodies, dt);
        }
        let nf = n as f64;
        let (dt64, g64) = (dt as f64, 9.81f64);
        let y = 10.0 + 2.0 * nf * dt64 - g64 * dt64 * dt64 * nf * (nf + 1.0) / 2.0;
        assert!(
            (bodies[1].position.y as f64 - y).abs() < 1e-4,
            "{} vs {y}",
            bodies[1].position.y
        );
        assert_eq!(bodies[0], SolverBody::STATIC);
    }
}
