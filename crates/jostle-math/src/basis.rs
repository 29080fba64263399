//! Contact bases and skew-symmetric matrices.
//!
//! A contact basis is the orthonormal frame of the seed lecture's "contact coordinates": its
//! x column is the contact normal, y and z span the contact plane. Millington's original
//! `calculateContactBasis` builds the second tangent wrongly when |n.x| > |n.y| (it is neither
//! unit nor orthogonal in general); here the second tangent is always `n × t1`.

use glam::{Mat3, Vec3};

/// The contact basis of a unit normal `n`: a rotation matrix whose columns are
/// `(n, t1, t2)` with `t2 = n × t1`, so contact space is right-handed and
/// `basis * v_contact` maps a contact-space vector to world space.
///
/// `t1` is `n × X` normalised while |n.x| < 0.6 (then |n × X| ≥ 0.8), else `n × Y` (then
/// |n.y| ≤ 0.8 and |n × Y| ≥ 0.6): well conditioned for every normal, and **continuous** over
/// the whole region |n.x| < 0.6, which holds the normals of ground, stacks and ±Z walls. An
/// earlier rule (cross with the least-aligned axis) switched between X and Z under the tiniest
/// tilt of a vertical normal, turning the tangents by 90° from one step to the next and
/// garbling warm-started friction. The basis is a pure function of `n`: the same normal always
/// gives the same tangents, which is what lets a contact's tangent impulses be carried from one
/// step to the next.
///
/// `n` must be unit length (debug-asserted).
pub fn contact_basis(n: Vec3) -> Mat3 {
    debug_assert!(
        (n.length_squared() - 1.0).abs() < 1e-3,
        "contact normal must be unit, got {n}"
    );
    let axis = if n.x.abs() < 0.6 { Vec3::X } else { Vec3::Y };
    let t1 = n.cross(axis).normalize();
    let t2 = n.cross(t1);
    Mat3::from_cols(n, t1, t2)
}

/// The skew-symmetric matrix `[v]×` of `v`, such that `skew(v) * x == v.cross(x)`.
///
/// The lecture's "computing impulse" slide writes it as
/// `[[0, -c, b], [c, 0, -a], [-b, a, 0]]` for `v = (a, b, c)`.
pub fn skew(v: Vec3) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(0.0, v.z, -v.y),
        Vec3::new(-v.z, 0.0, v.x),
        Vec3::new(v.y, -v.x, 0.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_orthonormal(b: Mat3, n: Vec3) {
        let (x, y, z) = (b.x_axis, b.y_axis, b.z_axis);
        assert!((x - n).length() < 1e-6, "x column must be the normal");
        for (name, v) in [("x", x), ("y", y), ("z", z)] {
            assert!(
                (v.length() - 1.0).abs() < 1e-5,
                "{name} not unit for n = {n}: {v}"
            );
        }
        assert!(x.dot(y).abs() < 1e-5 && x.dot(z).abs() < 1e-5 && y.dot(z).abs() < 1e-5);
        assert!(
            (x.cross(y) - z).length() < 1e-5,
            "basis must be right-handed for n = {n}"
        );
    }

    #[test]
    fn basis_is_orthonormal_near_every_axis() {
        let eps = [0.0f32, 1e-4, 1e-2, 0.3];
        for axis in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
            for &e in &eps {
                for tilt in [
                    Vec3::new(e, e, 0.0),
                    Vec3::new(0.0, e, -e),
                    Vec3::new(-e, 0.0, e),
                ] {
                    let n = (axis + tilt).normalize();
                    assert_orthonormal(contact_basis(n), n);
                }
            }
        }
    }

    #[test]
    fn basis_is_orthonormal_where_the_original_fails() {
        // Regression: Cyclone's calculateContactBasis computes the second tangent for the
        // |n.x| > |n.y| branch from the wrong components, giving a non-unit, non-orthogonal
        // vector for a normal such as this one (x dominant, y and z both non-zero).
        let n = Vec3::new(0.8, 0.36, 0.48).normalize();
        let original_t1 = {
            let s = 1.0 / (n.z * n.z + n.x * n.x).sqrt();
            Vec3::new(n.z * s, 0.0, -n.x * s)
        };
        let original_t2 = Vec3::new(
            n.y * original_t1.x,
            n.z * original_t1.x - n.x * original_t1.z,
            -n.y * original_t1.x,
        );
        assert!(original_t2.dot(n).abs() > 1e-2 || (original_t2.length() - 1.0).abs() > 1e-2);
        assert_orthonormal(contact_basis(n), n);
    }

    #[test]
    fn basis_on_random_directions() {
        let mut seed = 12345u32;
        let mut rnd = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
        };
        for _ in 0..1000 {
            let v = Vec3::new(rnd(), rnd(), rnd());
            if let Some(n) = v.try_normalize() {
                assert_orthonormal(contact_basis(n), n);
            }
        }
    }

    #[test]
    fn tangents_do_not_jump_when_a_vertical_normal_wobbles() {
        // Regression: the least-aligned-axis rule picked X or Z depending on which of two tiny
        // components was smaller, so these two normals got tangents 90° apart.
        for up in [Vec3::Y, -Vec3::Y, Vec3::Z] {
            let a = contact_basis((up + Vec3::new(1e-4, 0.0, 2e-4)).normalize());
            let b = contact_basis((up + Vec3::new(2e-4, 0.0, 1e-4)).normalize());
            assert!(
                (a.y_axis - b.y_axis).length() < 1e-3,
                "{up}: {} vs {}",
                a.y_axis,
                b.y_axis
            );
            assert!((a.z_axis - b.z_axis).length() < 1e-3);
        }
    }

    #[test]
    fn skew_is_the_cross_product() {
        let v = Vec3::new(1.5, -2.0, 0.25);
        let x = Vec3::new(-0.3, 4.0, 2.0);
        assert!((skew(v) * x - v.cross(x)).length() < 1e-6);
        assert_eq!(skew(v).transpose(), -skew(v));
    }
}
