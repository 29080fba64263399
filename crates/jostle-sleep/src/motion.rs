//! The per-body motion average of the seed lecture and Cyclone's `RigidBody::integrate`.

use crate::SleepSettings;
use jostle_body::RigidBody;

/// Updates `body`'s motion average after a step of `dt` and returns whether it now qualifies
/// for sleep: motion ← bias·motion + (1 − bias)·max(|v|² + |ω|², moved) with bias = base^dt,
/// capped at 10·ε; qualifies when motion < ε and the body may sleep. `moved` is the square of
/// how fast the step changed the body's pose, (|Δx|² + Δθ²)/dt² (the world uses
/// (2·sin(Δθ/2))² for Δθ²): a body that a resolver
/// pushes out of overlap without giving it velocity (split impulses, projection) is moving,
/// and must not fall asleep still overlapping.
pub fn update_motion(body: &mut RigidBody, settings: &SleepSettings, dt: f32, moved: f32) -> bool {
    let speed = body.linear_velocity.length_squared() + body.angular_velocity.length_squared();
    let current = speed.max(moved);
    let bias = settings.bias_base.powf(dt);
    let motion = bias * body.sleep.motion + (1.0 - bias) * current;
    body.sleep.motion = motion.min(10.0 * settings.threshold);
    body.sleep.can_sleep && body.sleep.motion < settings.threshold
}

/// Wakes `body`: awake, with motion at 2·ε so it cannot fall straight back asleep.
pub fn wake(body: &mut RigidBody, settings: &SleepSettings) {
    if !body.is_fixed() {
        body.sleep.awake = true;
        body.sleep.motion = 2.0 * settings.threshold;
    }
}

/// Puts `body` to sleep: not awake, zero velocities.
pub fn sleep(body: &mut RigidBody) {
    body.sleep.awake = false;
    body.linear_velocity = jostle_math::Vec3::ZERO;
    body.angular_velocity = jostle_math::Vec3::ZERO;
}

#[cfg(test)]
mod tests {
    use super::*;
    use jostle_math::{Mat3, Vec3};

    /// Updates until the body qualifies; returns on which update it did.
    fn updates_until_sleepy(dt: f32) -> u32 {
        let s = SleepSettings::default();
        let mut b = RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap();
        wake(&mut b, &s);
        (1..10_000)
            .find(|_| update_motion(&mut b, &s, dt, 0.0))
            .unwrap()
    }

    #[test]
    fn a_woken_motionless_body_qualifies_after_the_bias_halves_its_motion() {
        // Motion starts at 2ε and decays as 2ε·0.5^(n·dt): it drops below ε once n·dt > 1.
        // dt = 0.015: n > 66.7, so the 67th update, and not one earlier.
        assert_eq!(updates_until_sleepy(0.015), 67);
        // At 60 Hz n·dt = 1 exactly on the 60th update, the boundary: f32 rounding of
        // 0.5^(1/60) makes bias^60 fall just below 0.5, so the 60th update qualifies.
        assert_eq!(updates_until_sleepy(1.0 / 60.0), 60);
    }

    #[test]
    fn motion_is_capped() {
        let s = SleepSettings::default();
        let mut b = RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap();
        b.linear_velocity = Vec3::new(100.0, 0.0, 0.0);
        update_motion(&mut b, &s, 1.0, 0.0);
        assert_eq!(b.sleep.motion, 10.0 * s.threshold);
    }

    #[test]
    fn can_sleep_false_never_qualifies() {
        let s = SleepSettings::default();
        let mut b = RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap();
        b.sleep.can_sleep = false;
        b.sleep.motion = 0.0;
        assert!(!update_motion(&mut b, &s, 1.0 / 60.0, 0.0));
    }
}
