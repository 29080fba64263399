//! Velocity changes bounded by kinetic energy: the largest fraction of a change to a body's
//! velocities that keeps its kinetic energy within a bound. Both resolvers bound their
//! bounces with it (a body bouncing only off immovable bodies never leaves with more energy
//! than it brought).

// `!(x > y)` is deliberate: it is true for NaN, so a non-finite energy takes the safe branch
// (no change, or the whole change taken back) instead of comparing as a number.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use jostle_math::{Mat3, Vec3};

/// The inertia tensor I = (world inverse inertia)⁻¹, inverted in f64 ([`Inverse64`]) and
/// rounded to f32 once, when the inverse is positive definite, else `None`. Inverted in f32,
/// the inertia of a needle's world inverse inertia (principal moments 1 : 1250) was off by
/// about 10⁻³ of its energy, which the bounds below then let a bounce gain.
pub(crate) fn inertia_of(inv_inertia: Mat3) -> Option<Mat3> {
    let inverse = Inverse64::of(inv_inertia).filter(|i| i.det > 0.0)?;
    let inertia = Mat3::from_cols(
        inverse.times(Vec3::X),
        inverse.times(Vec3::Y),
        inverse.times(Vec3::Z),
    );
    inertia.is_finite().then_some(inertia)
}

/// The inverse of a 3 × 3 matrix in f64 (the gyroscopic turn's `turned`, [`inertia_of`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Inverse64 {
    rows: [[f64; 3]; 3],
    /// The determinant of the matrix inverted.
    pub(crate) det: f64,
}

impl Inverse64 {
    /// The inverse of `m` (rows of the adjugate over the determinant), `None` when `m` is
    /// singular or not finite.
    pub(crate) fn of(m: Mat3) -> Option<Self> {
        let c = m.to_cols_array().map(f64::from);
        // Column-major: a[row][col] = c[col * 3 + row].
        let a = |r: usize, k: usize| c[k * 3 + r];
        let cof = |r: usize, k: usize| {
            let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
            let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
            a(r1, k1) * a(r2, k2) - a(r1, k2) * a(r2, k1)
        };
        let det = a(0, 0) * cof(0, 0) + a(0, 1) * cof(0, 1) + a(0, 2) * cof(0, 2);
        if !(det.is_finite() && det != 0.0) {
            return None;
        }
        // inverse[row][col] = cofactor(col, row) / det.
        let inv_det = 1.0 / det;
        Some(Self {
            rows: std::array::from_fn(|r| std::array::from_fn(|k| cof(k, r) * inv_det)),
            det,
        })
    }

    /// The inverse times `v`, rounded to f32 once.
    pub(crate) fn times(&self, v: Vec3) -> Vec3 {
        let v = [f64::from(v.x), f64::from(v.y), f64::from(v.z)];
        let row = |r: usize| {
            let m = &self.rows[r];
            (m[0] * v[0] + m[1] * v[1] + m[2] * v[2]) as f32
        };
        Vec3::new(row(0), row(1), row(2))
    }
}

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
    fn the_inertia_of_a_needle_keeps_its_energy() {
        // A 1 × 0.02 × 0.02 m needle of 1 kg, turned about an oblique axis.
        let moments = Vec3::new(0.0000667, 0.0833667, 0.0833667);
        let turn = jostle_math::Quat::from_axis_angle(Vec3::new(0.3, -0.8, 0.5).normalize(), 1.1);
        let r = Mat3::from_quat(turn);
        let inertia = r * Mat3::from_diagonal(moments) * r.transpose();
        let inv = r * Mat3::from_diagonal(moments.recip()) * r.transpose();
        let w = Vec3::new(5.0, -50.0, 94.0);
        let exact = 0.5 * f64::from(w.dot(inertia * w));
        let of = inertia_of(inv).expect("invertible");
        let error = |i: Mat3| (0.5 * f64::from(w.dot(i * w)) - exact).abs() / exact;
        // (What is left is the rounding of the f32 inverse inertia itself; `inv.inverse()`,
        // in f32, is off by 2.3·10⁻³.)
        assert!(error(of) < 1e-4, "{}", error(of));
    }

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
