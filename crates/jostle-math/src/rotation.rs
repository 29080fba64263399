//! The quaternion update of the seed lecture: θ' = θ + ½·[0, Δθ]·θ, then normalised.

use glam::{Quat, Vec3};

/// Rotates `q` by the rotation vector `rotation` (rad; for a step, ω·dt) with the first-order
/// update q' = q + ½·(0, rotation)·q followed by normalisation, as the seed lecture and
/// Millington's `Quaternion::addScaledVector` do.
///
/// First order: for |rotation| of 0.1 rad the result differs from the exact rotation by about
/// 0.03%. Used both by integration (rotation = ω·dt) and by nonlinear projection.
#[inline]
pub fn integrate_orientation(q: Quat, rotation: Vec3) -> Quat {
    advance_orientation(q, rotation).normalize()
}

/// [`integrate_orientation`] before its normalisation: q + ½·(0, rotation)·q, whose length
/// is 1 + O(|rotation|²) for a unit `q`. For a caller that reads the result only through
/// products that divide its length out.
#[inline]
pub fn advance_orientation(q: Quat, rotation: Vec3) -> Quat {
    let spin = Quat::from_xyzw(rotation.x, rotation.y, rotation.z, 0.0) * q;
    Quat::from_xyzw(
        q.x + 0.5 * spin.x,
        q.y + 0.5 * spin.y,
        q.z + 0.5 * spin.z,
        q.w + 0.5 * spin.w,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lecture_projection_quaternion() {
        // Seed lecture, nonlinear projection example: rotating the identity by (0, 0, -0.1378)
        // gives [1, 0, 0, -0.0689] (w first) before normalisation.
        let q = integrate_orientation(Quat::IDENTITY, Vec3::new(0.0, 0.0, -0.1378));
        let expected = Quat::from_xyzw(0.0, 0.0, -0.0689, 1.0).normalize();
        assert!(q.abs_diff_eq(expected, 1e-6), "{q:?}");
    }

    #[test]
    fn small_steps_converge_to_the_exact_rotation() {
        let omega = Vec3::new(0.3, -1.2, 2.0);
        let mut q = Quat::IDENTITY;
        let n = 10_000;
        let dt = 1.0 / n as f32;
        for _ in 0..n {
            q = integrate_orientation(q, omega * dt);
        }
        let exact = Quat::from_scaled_axis(omega);
        assert!(
            q.abs_diff_eq(exact, 1e-3) || q.abs_diff_eq(-exact, 1e-3),
            "{q:?} vs {exact:?}"
        );
        assert!((q.length() - 1.0).abs() < 1e-5);
    }

    #[test]
    fn zero_rotation_is_identity() {
        let q = Quat::from_rotation_y(0.7);
        assert!(integrate_orientation(q, Vec3::ZERO).abs_diff_eq(q, 1e-7));
    }
}
