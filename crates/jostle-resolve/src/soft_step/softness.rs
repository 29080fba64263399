//! Soft-constraint coefficients: a contact as a damped spring solved implicitly.
//!
//! Catto, "Solver2D" (2024) and GDC 2011 "Soft Constraints": with ω = 2π·hz, damping ratio ζ
//! and substep h, an implicit (backward Euler) spring gives
//! - bias rate β = ω / (2ζ + hω): the velocity per metre of overlap the constraint targets;
//! - mass scale = hω(2ζ + hω) / (1 + hω(2ζ + hω)): the fraction of the rigid impulse applied;
//! - impulse scale = 1 / (1 + hω(2ζ + hω)): how much of the accumulated impulse is bled off,
//!   which is what makes the constraint a spring rather than a rigid rod.
//!
//! The coefficients depend on the stiffness and the substep only, not on the masses (the
//! point of specifying stiffness in Hz), so they are computed once per step.

/// The three coefficients of a soft constraint for one substep length.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Softness {
    /// β (1/s): target separation velocity per metre of separation.
    pub bias_rate: f32,
    /// Fraction of the rigid impulse applied (dimensionless, in [0, 1]).
    pub mass_scale: f32,
    /// Fraction of the accumulated impulse removed per solve (dimensionless, in [0, 1]).
    pub impulse_scale: f32,
}

impl Softness {
    /// A rigid constraint without bias: what the relax and restitution passes use.
    pub const RIGID: Softness = Softness {
        bias_rate: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    /// The coefficients for stiffness `hertz` (Hz), damping ratio `zeta` and substep `h` (s).
    /// `hertz` = 0 (or a non-positive or non-finite input) gives [`Softness::RIGID`]: no
    /// positional correction at all, never a division by zero.
    // `!(x > 0.0)` is deliberate: it is true for NaN, which must give the rigid fallback.
    #[allow(clippy::nonminimal_bool)]
    pub fn new(hertz: f32, zeta: f32, h: f32) -> Self {
        if !(hertz > 0.0 && zeta >= 0.0 && h > 0.0) || !(hertz * h).is_finite() {
            return Self::RIGID;
        }
        let omega = std::f32::consts::TAU * hertz;
        let a1 = 2.0 * zeta + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Self {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mass_and_impulse_scales_sum_to_one() {
        // 1 − a3 = a2·a3: the soft impulse interpolates between rigid and nothing.
        for hz in [1.0, 30.0, 60.0, 1000.0] {
            let s = Softness::new(hz, 10.0, 1.0 / 240.0);
            assert!((s.mass_scale + s.impulse_scale - 1.0).abs() < 1e-6, "{s:?}");
            assert!(s.bias_rate > 0.0 && s.mass_scale > 0.0 && s.mass_scale < 1.0);
        }
    }

    #[test]
    fn matches_the_closed_form_for_box2d_defaults() {
        // 30 Hz, ζ = 10, h = 1/240: ω = 188.5, hω = 0.7854, a1 = 20.785, a2 = 16.325.
        let s = Softness::new(30.0, 10.0, 1.0 / 240.0);
        assert!((s.bias_rate - 9.069).abs() < 1e-2, "{s:?}");
        assert!((s.impulse_scale - 1.0 / 17.325).abs() < 1e-4, "{s:?}");
    }

    #[test]
    fn zero_or_bad_stiffness_is_rigid() {
        assert_eq!(Softness::new(0.0, 10.0, 0.01), Softness::RIGID);
        assert_eq!(Softness::new(f32::NAN, 10.0, 0.01), Softness::RIGID);
        assert_eq!(Softness::new(30.0, 10.0, 0.0), Softness::RIGID);
    }
}
