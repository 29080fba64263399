//! Velocity changes bounded by kinetic energy: the largest fraction of a change to a body's
//! velocities that keeps its kinetic energy within a bound. Both resolvers bound their
//! bounces with it (a body bouncing only off immovable bodies never leaves with more energy
//! than it brought).

// `!(x > y)` is deliberate: it is true for NaN, so a non-finite energy takes the safe branch
// (no change, or the whole change taken back) instead of comparing as a number.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use jostle_math::{Mat3, Vec3};

/// The largest s ∈ [0, 1] for which a body of `mass` (kg) and world `inertia` at the velocities
/// `(v, ω)` plus s times the change `(dv, dω)` has a kinetic energy of at most `allowed` (J),
/// when the whole change exceeds it by more than `tolerance` (J); `None` when it does not.
/// Along the change the energy is K(s) = k + b·s + a·s² with k the energy before, a that of
/// the change and b their cross term; s is its larger root of K(s) = `allowed`, or 0 when the
/// energy before already exceeds the bound.
pub(crate) fn bounded_fraction(
    mass: f32,
    inertia: Mat3,
    (v, w): (Vec3, Vec3),
    (dv, dw): (Vec3, Vec3),
    allowed: f32,
    tolerance: f32,
) -> Option<f32> {
    let energy = |v: Vec3, w: Vec3| 0.5 * mass * v.length_squared() + 0.5 * w.dot(inertia * w);
    let k = energy(v, w);
    let a = energy(dv, dw);
    let b = mass * v.dot(dv) + w.dot(inertia * dw);
    if !(k + b + a > allowed + tolerance) {
        return None;
    }
    Some(if !(k <= allowed) || !(a > 0.0) {
        0.0
    } else {
        ((-b + (b * b - 4.0 * a * (k - allowed)).max(0.0).sqrt()) / (2.0 * a)).clamp(0.0, 1.0)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bounce_that_would_add_energy_is_scaled_back_to_the_energy_it_had() {
        // A 2 kg body at 3 m/s whose change would leave it at 4 m/s: bounded at 3 m/s.
        let (v, dv) = (Vec3::new(0.0, -3.0, 0.0), Vec3::new(0.0, 7.0, 0.0));
        let k = 0.5 * 2.0 * 9.0;
        let s = bounded_fraction(2.0, Mat3::ZERO, (v, Vec3::ZERO), (dv, Vec3::ZERO), k, 0.0)
            .expect("exceeds");
        assert!(((v + dv * s).length() - 3.0).abs() < 1e-5, "s {s}");
        // A change within the bound is left alone.
        let dv = Vec3::new(0.0, 5.0, 0.0);
        assert!(
            bounded_fraction(2.0, Mat3::ZERO, (v, Vec3::ZERO), (dv, Vec3::ZERO), k, 0.0).is_none()
        );
    }
}
