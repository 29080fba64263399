//! The soft-step solver contact: one contact point prepared once per step, laid out for the
//! inner loop.
//!
//! Everything the substep loop needs is precomputed here so the loop touches only this struct
//! and two [`BodyState`]s: the anchors, the normal and tangents, the angular response of each
//! body to a unit impulse along each direction (I⁻¹·(r × d), so no inertia matrix is loaded in
//! the loop), the effective masses, and the softness that applies (static or dynamic).
//! Fields are ordered by use: the normal row first (solved every iteration), then friction,
//! then what only restitution and the final store read.

use super::body_state::BodyState;
use super::softness::Softness;
use crate::{Contact, SolverBody};
use jostle_math::{Mat3, Vec3, contact_basis};

/// One prepared contact point (Box2D v3's `b2ContactConstraintPoint` and the manifold data it
/// needs, in 3D with one normal per point).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct SoftContact {
    /// Solver index of body A.
    pub a: u32,
    /// Solver index of body B.
    pub b: u32,
    /// Unit normal from B toward A.
    pub normal: Vec3,
    /// Separation at the start of the step minus the anchors' normal offset,
    /// −penetration − (r_A − r_B)·n, so that the current separation is this plus
    /// (Δx_A + Δq_A·r_A − Δx_B − Δq_B·r_B)·n (Box2D's "adjusted separation").
    pub base_separation: f32,
    /// Contact point relative to A's centre of mass at the start of the step (m).
    pub r_a: Vec3,
    /// Normal effective mass 1/(n·K·n) (kg), 0 when neither body can respond.
    pub normal_mass: f32,
    /// Contact point relative to B's centre of mass at the start of the step (m).
    pub r_b: Vec3,
    /// Accumulated normal impulse of the current substep (N·s), ≥ 0.
    pub normal_impulse: f32,
    /// I_A⁻¹·(r_A × n): A's angular velocity change per unit normal impulse.
    pub ang_a_normal: Vec3,
    /// Friction coefficient μ; 0 skips all friction work.
    pub friction: f32,
    /// I_B⁻¹·(r_B × n).
    pub ang_b_normal: Vec3,
    /// Soft-constraint coefficients for this pair (static or dynamic stiffness).
    pub softness: Softness,
    /// First tangent of [`contact_basis`].
    pub tangent1: Vec3,
    /// Second tangent of [`contact_basis`].
    pub tangent2: Vec3,
    /// I_A⁻¹·(r_A × t₁), I_A⁻¹·(r_A × t₂).
    pub ang_a_tangent: [Vec3; 2],
    /// I_B⁻¹·(r_B × t₁), I_B⁻¹·(r_B × t₂).
    pub ang_b_tangent: [Vec3; 2],
    /// Inverse of the 2×2 tangent effective-mass matrix K_t (symmetric: [0,0], [0,1], [1,1]),
    /// so one friction solve is exact for both tangents together; zeros when singular.
    pub tangent_mass: [f32; 3],
    /// Accumulated friction impulse along t₁, t₂ (N·s), within the disk |λ_t| ≤ μ·λ_n.
    pub tangent_impulse: [f32; 2],
    /// Restitution e.
    pub restitution: f32,
    /// Normal relative velocity at the start of the step (m/s), negative when approaching:
    /// the velocity restitution reflects.
    pub relative_velocity: f32,
    /// Largest normal impulse increment of the step (N·s): restitution only applies to
    /// contacts that actually pushed (Box2D's `maxNormalImpulse`).
    pub max_normal_impulse: f32,
}

const _: () = assert!(size_of::<SoftContact>() <= 208);

/// Prepares `contact` on the step-start `bodies`, or `None` when it takes no part: its gap is
/// larger than `speculative_margin`, or neither body can move. `impulse_scale` scales the
/// stored impulse into the warm-start impulse of one substep (1/substeps, or 0 without warm
/// starting).
pub fn prepare(
    contact: &Contact,
    bodies: &[SolverBody],
    speculative_margin: f32,
    static_softness: Softness,
    dynamic_softness: Softness,
    impulse_scale: f32,
) -> Option<SoftContact> {
    if -contact.penetration > speculative_margin {
        return None;
    }
    let (ba, bb) = (&bodies[contact.a as usize], &bodies[contact.b as usize]);
    if !ba.is_movable() && !bb.is_movable() {
        return None;
    }
    debug_assert!(
        (contact.normal.length_squared() - 1.0).abs() < 1e-3,
        "contact normal must be unit, got {}",
        contact.normal
    );
    let n = contact.normal;
    let basis = contact_basis(n);
    let (t1, t2) = (basis.y_axis, basis.z_axis);
    let r_a = contact.point - ba.position;
    let r_b = contact.point - bb.position;
    let inv_i_a = if ba.rotates() {
        ba.inv_inertia
    } else {
        Mat3::ZERO
    };
    let inv_i_b = if bb.rotates() {
        bb.inv_inertia
    } else {
        Mat3::ZERO
    };
    let m = ba.inv_mass + bb.inv_mass;

    let (rn_a, rn_b) = (r_a.cross(n), r_b.cross(n));
    let ang_a_normal = inv_i_a * rn_a;
    let ang_b_normal = inv_i_b * rn_b;
    let k_normal = m + rn_a.dot(ang_a_normal) + rn_b.dot(ang_b_normal);
    let normal_mass = if k_normal > 0.0 { 1.0 / k_normal } else { 0.0 };

    let (rt_a, rt_b) = (
        [r_a.cross(t1), r_a.cross(t2)],
        [r_b.cross(t1), r_b.cross(t2)],
    );
    let ang_a_tangent = [inv_i_a * rt_a[0], inv_i_a * rt_a[1]];
    let ang_b_tangent = [inv_i_b * rt_b[0], inv_i_b * rt_b[1]];
    let k = |i: usize, j: usize| {
        let diag = if i == j { m } else { 0.0 };
        diag + rt_a[i].dot(ang_a_tangent[j]) + rt_b[i].dot(ang_b_tangent[j])
    };
    let (k11, k12, k22) = (k(0, 0), k(0, 1), k(1, 1));
    let det = k11 * k22 - k12 * k12;
    let tangent_mass = if det > f32::EPSILON * k11 * k22 && det.is_finite() {
        let inv = 1.0 / det;
        [k22 * inv, -k12 * inv, k11 * inv]
    } else {
        [0.0; 3]
    };

    let softness = if ba.inv_mass == 0.0 || bb.inv_mass == 0.0 {
        static_softness
    } else {
        dynamic_softness
    };
    let dv = ba.velocity_at(contact.point) - bb.velocity_at(contact.point);
    let friction = contact.friction.max(0.0);
    let warm = contact.impulse * impulse_scale;
    Some(SoftContact {
        a: contact.a,
        b: contact.b,
        normal: n,
        base_separation: -contact.penetration - (r_a - r_b).dot(n),
        r_a,
        normal_mass,
        r_b,
        normal_impulse: warm.x.max(0.0),
        ang_a_normal,
        friction,
        ang_b_normal,
        softness,
        tangent1: t1,
        tangent2: t2,
        ang_a_tangent,
        ang_b_tangent,
        tangent_mass,
        tangent_impulse: if friction > 0.0 {
            [warm.y, warm.z]
        } else {
            [0.0; 2]
        },
        restitution: contact.restitution,
        relative_velocity: dv.dot(n),
        max_normal_impulse: 0.0,
    })
}

impl SoftContact {
    /// The separation now (m, negative on overlap), from the bodies' motion since the start of
    /// the step: s₀ + ((Δx_A + Δq_A·r_A) − (Δx_B + Δq_B·r_B))·n with r the step-start anchors.
    /// Exact for rigid motion of the anchors (the normal itself is kept fixed, as in Box2D).
    #[inline]
    pub fn separation(&self, a: &BodyState, b: &BodyState) -> f32 {
        let pa = a.delta_position + a.delta_rotation * self.r_a;
        let pb = b.delta_position + b.delta_rotation * self.r_b;
        self.base_separation + (pa - pb).dot(self.normal)
    }

    /// Velocity of A's material point relative to B's at the contact (m/s).
    #[inline]
    pub fn relative_velocity(&self, a: &BodyState, b: &BodyState) -> Vec3 {
        (a.linear_velocity + a.angular_velocity.cross(self.r_a))
            - (b.linear_velocity + b.angular_velocity.cross(self.r_b))
    }
}
