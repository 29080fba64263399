//! Force application and semi-implicit Euler integration of a `RigidBody`.
//!
//! The step applies accumulated forces and damping to velocities ([`apply_forces`]) before the
//! resolver runs; the resolver then adds gravity and integrates poses. [`integrate_body`] is the
//! whole semi-implicit Euler step for one body, for users who drive bodies without a resolver
//! and as the reference the resolvers' integration is tested against.

use crate::RigidBody;
use jostle_math::{Vec3, integrate_orientation};

/// Applies the accumulated force and torque over `dt` as an impulse (Δv = F/m·dt,
/// Δω = I⁻¹_world·τ·dt), then damping v ← v/(1 + dt·c). Does not clear the accumulators.
pub fn apply_forces(body: &mut RigidBody, dt: f32) {
    if body.is_immovable() {
        return;
    }
    body.linear_velocity += body.force() * (body.inv_mass() * dt);
    body.angular_velocity += body.inv_inertia_world() * body.torque() * dt;
    if body.linear_damping > 0.0 {
        body.linear_velocity /= 1.0 + dt * body.linear_damping;
    }
    if body.angular_damping > 0.0 {
        body.angular_velocity /= 1.0 + dt * body.angular_damping;
    }
}

/// One semi-implicit Euler step of a free body: forces and damping, then gravity (times the
/// body's `gravity_scale`) into the
/// velocity, then the velocity into the pose; records `last_acceleration` and refreshes the
/// world inverse inertia. Fixed bodies are left alone; kinematic ones move by their velocity
/// (or to their next pose) only.
pub fn integrate_body(body: &mut RigidBody, gravity: Vec3, dt: f32) {
    if body.is_fixed() {
        return;
    }
    if body.is_kinematic() {
        // Its velocity alone (derived from its next pose, if it has one) moves it.
        let target = body.take_next_pose(dt);
        body.position += body.linear_velocity * dt;
        body.orientation = integrate_orientation(body.orientation, body.angular_velocity * dt);
        if let Some((position, orientation)) = target {
            body.position = position;
            body.orientation = orientation;
        }
        body.update_world_inertia();
        return;
    }
    apply_forces(body, dt);
    let gravity = gravity * body.gravity_scale;
    body.linear_velocity += gravity * dt;
    body.last_acceleration = gravity + body.force() * body.inv_mass();
    body.position += body.linear_velocity * dt;
    body.orientation = integrate_orientation(body.orientation, body.angular_velocity * dt);
    body.update_world_inertia();
}

#[cfg(test)]
mod tests {
    use super::*;
    use jostle_math::Mat3;

    #[test]
    fn free_fall_follows_the_closed_form() {
        let g = Vec3::new(0.0, -9.81, 0.0);
        let dt = 1.0 / 60.0;
        let mut b = RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap();
        b.position.y = 3.0;
        for n in 1..=200u32 {
            integrate_body(&mut b, g, dt);
            let nf = n as f64;
            let y = 3.0 - 9.81 * (dt as f64).powi(2) * nf * (nf + 1.0) / 2.0;
            assert!(
                (b.position.y as f64 - y).abs() < 2e-4 * (1.0 + y.abs()),
                "step {n}"
            );
        }
    }

    #[test]
    fn torque_spins_the_body() {
        let mut b = RigidBody::dynamic(1.0, Mat3::from_diagonal(Vec3::splat(2.0))).unwrap();
        b.add_torque(Vec3::new(0.0, 4.0, 0.0));
        apply_forces(&mut b, 0.5);
        assert!((b.angular_velocity - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-6);
    }

    #[test]
    fn fixed_bodies_never_move() {
        let mut b = RigidBody::fixed();
        b.add_force(Vec3::ONE);
        integrate_body(&mut b, Vec3::new(0.0, -9.81, 0.0), 0.1);
        assert_eq!(b.position, Vec3::ZERO);
        assert_eq!(b.linear_velocity, Vec3::ZERO);
    }
}
