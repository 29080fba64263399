//! The per-body motion average of the seed lecture and Cyclone's `RigidBody::integrate`, and
//! the mean velocities that keep a body moving steadily awake.

use crate::SleepSettings;
use jostle_body::RigidBody;

/// Updates `body`'s motion average after a step of `dt` and returns whether it now qualifies
/// for sleep: motion ← bias·motion + (1 − bias)·max(|v|² + |ω|², moved) with bias = base^dt,
/// capped at 10·ε, and the mean velocities v̄ ← bias·v̄ + (1 − bias)·v (ω̄ the same), capped
/// at |v̄|² ≤ 10·`drift_threshold` (and r²·|ω̄|², r the radius of gyration);
/// qualifies when motion < ε, both |v̄|² + r²·|ω̄|² and |v|² are
/// below `drift_threshold`, and the body may sleep (a body moving or spinning steadily has a
/// mean velocity, one speeding up from rest a velocity ahead of its mean; one at rest jitters
/// or rocks about its place, slowly, and its mean is none). `moved` is the square of how fast
/// the step changed the body's pose, (|Δx|² + Δθ²)/dt² (the world uses (2·sin(Δθ/2))² for
/// Δθ²): a body that a resolver pushes out of overlap without giving it velocity (split
/// impulses, projection) is moving,
/// and must not fall asleep still overlapping.
pub fn update_motion(body: &mut RigidBody, settings: &SleepSettings, dt: f32, moved: f32) -> bool {
    let speed = body.linear_velocity.length_squared() + body.angular_velocity.length_squared();
    let current = speed.max(moved);
    let bias = settings.bias_base.powf(dt);
    let motion = bias * body.sleep.motion + (1.0 - bias) * current;
    body.sleep.motion = motion.min(10.0 * settings.threshold);
    let mean = |old: jostle_math::Vec3, now: jostle_math::Vec3| bias * old + (1.0 - bias) * now;
    // Each mean is capped, as the motion is, at ten times its threshold: a mean that remembered
    // a fall kept a box dropped 5 m awake 5.8 s after it landed (its mean velocity, 2.8 m/s at
    // the landing, halving each second), and every box of a dropped lattice until 8.1 s.
    let cap = 10.0 * settings.drift_threshold;
    let capped = |m: jostle_math::Vec3, scale: f32| {
        let size = m.length_squared() * scale;
        if size > cap {
            m * (cap / size).sqrt()
        } else {
            m
        }
    };
    // The mean turn counts as the speed it gives the body's mass at its radius of gyration, so
    // that a small body rocking or turning slowly in place (a ball spinning about its contact
    // normal, which point contacts never stop) is at rest, and a large one turning at the same
    // rate is not.
    let gyration = gyration_squared(body);
    body.sleep.mean_linear = capped(mean(body.sleep.mean_linear, body.linear_velocity), 1.0);
    body.sleep.mean_angular = capped(
        mean(body.sleep.mean_angular, body.angular_velocity),
        gyration,
    );
    let drift = body.sleep.mean_linear.length_squared()
        + body.sleep.mean_angular.length_squared() * gyration;
    body.sleep.can_sleep
        && body.sleep.motion < settings.threshold
        && drift < settings.drift_threshold
        && body.linear_velocity.length_squared() < settings.drift_threshold
}

/// The square of `body`'s radius of gyration about its widest axis, largest moment / mass
/// (m²); 0 for a body without finite mass properties.
fn gyration_squared(body: &RigidBody) -> f32 {
    body.mass_properties()
        .map(|(mass, inertia)| {
            let largest = inertia.x_axis.x.max(inertia.y_axis.y).max(inertia.z_axis.z);
            largest / mass
        })
        .filter(|r| r.is_finite() && *r >= 0.0)
        .unwrap_or(0.0)
}

/// Wakes `body`: awake, and its averages restarted ([`restart`]).
pub fn wake(body: &mut RigidBody, settings: &SleepSettings) {
    if !body.is_fixed() {
        body.sleep.awake = true;
        restart(body, settings);
    }
}

/// Restarts `body`'s averages, as for a body just added, woken or made dynamic: motion at 2·ε
/// so it cannot fall straight back asleep, and the mean velocities at its velocities (zero for
/// a body that slept; a body given a velocity has been moving so).
pub fn restart(body: &mut RigidBody, settings: &SleepSettings) {
    body.sleep.motion = 2.0 * settings.threshold;
    body.sleep.mean_linear = body.linear_velocity;
    body.sleep.mean_angular = body.angular_velocity;
}

/// Puts `body` to sleep: not awake, zero velocities (and mean velocities).
pub fn sleep(body: &mut RigidBody) {
    body.sleep.awake = false;
    body.linear_velocity = jostle_math::Vec3::ZERO;
    body.angular_velocity = jostle_math::Vec3::ZERO;
    body.sleep.mean_linear = jostle_math::Vec3::ZERO;
    body.sleep.mean_angular = jostle_math::Vec3::ZERO;
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
    fn a_body_moving_steadily_never_qualifies_and_one_rocking_in_place_does() {
        let s = SleepSettings::default();
        // 0.2 m/s: |v|² = 0.04, below the motion threshold 0.3, but a steady mean velocity.
        let mut gliding = RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap();
        gliding.linear_velocity = Vec3::new(0.2, 0.0, 0.0);
        wake(&mut gliding, &s);
        assert!((0..600).all(|_| !update_motion(&mut gliding, &s, 1.0 / 60.0, 0.0)));
        // The same speed back and forth every step: no mean, and at rest within 2 s.
        let mut rocking = RigidBody::dynamic(1.0, Mat3::IDENTITY).unwrap();
        wake(&mut rocking, &s);
        let slept = (0..600).position(|i| {
            rocking.linear_velocity = Vec3::new(if i % 2 == 0 { 0.04 } else { -0.04 }, 0.0, 0.0);
            update_motion(&mut rocking, &s, 1.0 / 60.0, 0.0)
        });
        assert!(slept.is_some_and(|i| i < 120), "{slept:?}");
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
