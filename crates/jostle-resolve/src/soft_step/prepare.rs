//! Preparing contact points eight lanes at a time, on the step-start poses.
//!
//! Everything the substep loop needs is computed here once per step, so the kernels touch
//! only a [`PointLanes`] and the bodies' velocities and motion: the anchors, the normal and
//! tangents (of [`contact_basis`], the convention of the stored impulses), the angular
//! response of each body to a unit impulse along each direction (I⁻¹·(r × d), so no inertia
//! matrix is loaded in the loop), the normal effective mass 1/(n·K·n), the inverse 2×2
//! tangent effective mass (so one friction solve is exact for both tangents together), the
//! softness that applies (static or dynamic stiffness), the approach velocity restitution
//! reflects, and the warm-start impulse (the stored step impulse × 1/substeps).
//!
//! The adjusted separation −penetration − (r_A − r_B)·n is stored so that the separation
//! during the step is that plus (Δx_A + Δq_A·r_A − Δx_B − Δq_B·r_B)·n (Box2D's "adjusted
//! separation"; see [`super::solve`]).

use super::batch::PointLanes;
use super::lanes::{F8, V3x8, WIDTH};
use super::softness::Softness;
use crate::{Contact, SolverBody};
use jostle_math::{Mat3, contact_basis};

/// What [`prepare_point`] needs besides the contact and its bodies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrepareParams {
    /// Softness of a contact against a body that cannot move linearly.
    pub static_softness: Softness,
    /// Softness of a contact between two bodies that can.
    pub dynamic_softness: Softness,
    /// Scale from the stored step impulse to one substep's warm start (1/substeps, or 0).
    pub warm_scale: f32,
}

/// The step-start state of eight bodies, by lane, as preparation reads it.
#[derive(Clone, Copy, Debug)]
pub struct BodyLanes {
    position: V3x8,
    linear_velocity: V3x8,
    angular_velocity: V3x8,
    /// Columns of the world inverse inertia (zero for a body that does not rotate).
    inv_inertia: [V3x8; 3],
    /// 1/m (1/kg).
    pub inv_mass: F8,
}

impl BodyLanes {
    /// Loads `bodies[idx[lane]]` into each lane.
    pub fn gather(bodies: &[SolverBody], idx: [u32; WIDTH]) -> Self {
        let b = idx.map(|i| &bodies[i as usize]);
        let inertia = b.map(|b| {
            if b.rotates() {
                b.inv_inertia
            } else {
                Mat3::ZERO
            }
        });
        Self {
            position: V3x8::from_lanes(b.map(|b| b.position)),
            linear_velocity: V3x8::from_lanes(b.map(|b| b.linear_velocity)),
            angular_velocity: V3x8::from_lanes(b.map(|b| b.angular_velocity)),
            inv_inertia: [
                V3x8::from_lanes(inertia.map(|m| m.x_axis)),
                V3x8::from_lanes(inertia.map(|m| m.y_axis)),
                V3x8::from_lanes(inertia.map(|m| m.z_axis)),
            ],
            inv_mass: F8::from_array(b.map(|b| b.inv_mass)),
        }
    }

    /// I⁻¹·v per lane.
    #[inline]
    fn inv_inertia_times(&self, v: V3x8) -> V3x8 {
        let [x, y, z] = self.inv_inertia;
        x * v.x + y * v.y + z * v.z
    }

    /// Velocity of each lane's material point at offset `r` from its centre of mass.
    #[inline]
    fn velocity_at(&self, r: V3x8) -> V3x8 {
        self.linear_velocity + self.angular_velocity.cross(r)
    }
}

/// Prepares one point of eight lanes into `out`: `contacts[lane]` between the bodies of lane `lane` in
/// `a` and `b`. Lanes whose contact is `None` are padding and get zeros (zero normal, zero
/// masses), so every impulse they compute is zero.
pub fn prepare_point(
    out: &mut PointLanes,
    contacts: [Option<&Contact>; WIDTH],
    a: &BodyLanes,
    b: &BodyLanes,
    params: &PrepareParams,
) {
    let mut n = V3x8::ZERO;
    let mut t1 = V3x8::ZERO;
    let mut t2 = V3x8::ZERO;
    let mut point = V3x8::ZERO;
    let mut stored = V3x8::ZERO;
    let mut penetration = [0.0; WIDTH];
    let mut friction = [0.0; WIDTH];
    let mut restitution = [0.0; WIDTH];
    for (lane, c) in contacts.iter().enumerate() {
        if let Some(c) = c {
            let basis = contact_basis(c.normal);
            n.set_lane(lane, basis.x_axis);
            t1.set_lane(lane, basis.y_axis);
            t2.set_lane(lane, basis.z_axis);
            point.set_lane(lane, c.point);
            stored.set_lane(lane, c.impulse);
            penetration[lane] = c.penetration;
            friction[lane] = c.friction;
            restitution[lane] = c.restitution;
        }
    }
    let r_a = point - a.position;
    let r_b = point - b.position;
    let m = a.inv_mass + b.inv_mass;

    let (rn_a, rn_b) = (r_a.cross(n), r_b.cross(n));
    let ang_a_normal = a.inv_inertia_times(rn_a);
    let ang_b_normal = b.inv_inertia_times(rn_b);
    let k_normal = m + rn_a.dot(ang_a_normal) + rn_b.dot(ang_b_normal);
    let normal_mass = F8::select(k_normal.cmpgt(F8::ZERO), k_normal.recip(), F8::ZERO);

    let rt_a = [r_a.cross(t1), r_a.cross(t2)];
    let rt_b = [r_b.cross(t1), r_b.cross(t2)];
    let ang_a_tangent = rt_a.map(|v| a.inv_inertia_times(v));
    let ang_b_tangent = rt_b.map(|v| b.inv_inertia_times(v));
    let k = |i: usize, j: usize| {
        let diag = if i == j { m } else { F8::ZERO };
        diag + rt_a[i].dot(ang_a_tangent[j]) + rt_b[i].dot(ang_b_tangent[j])
    };
    let (k11, k12, k22) = (k(0, 0), k(0, 1), k(1, 1));
    let det = k11 * k22 - k12 * k12;
    let invertible = det.cmpgt(F8::splat(f32::EPSILON) * k11 * k22) & det.is_finite_mask();
    let inv_det = F8::select(invertible, det.recip(), F8::ZERO);
    let tangent_mass = [k22 * inv_det, -k12 * inv_det, k11 * inv_det];

    let fixed = a.inv_mass.cmpeq(F8::ZERO) | b.inv_mass.cmpeq(F8::ZERO);
    let (s, d) = (params.static_softness, params.dynamic_softness);
    let soft = |fs: f32, fd: f32| F8::select(fixed, F8::splat(fs), F8::splat(fd));

    let friction = F8::from_array(friction).max(F8::ZERO);
    let warm = stored * F8::splat(params.warm_scale);
    let has_friction = friction.cmpgt(F8::ZERO);
    let dv = a.velocity_at(r_a) - b.velocity_at(r_b);
    *out = PointLanes {
        normal: n,
        r_a,
        r_b,
        ang_a_normal,
        ang_b_normal,
        base_separation: -F8::from_array(penetration) - (r_a - r_b).dot(n),
        normal_mass,
        normal_impulse: warm.x.max(F8::ZERO),
        max_normal_impulse: F8::ZERO,
        bias_rate: soft(s.bias_rate, d.bias_rate),
        mass_scale: soft(s.mass_scale, d.mass_scale),
        impulse_scale: soft(s.impulse_scale, d.impulse_scale),
        friction,
        tangent1: t1,
        tangent2: t2,
        ang_a_tangent1: ang_a_tangent[0],
        ang_a_tangent2: ang_a_tangent[1],
        ang_b_tangent1: ang_b_tangent[0],
        ang_b_tangent2: ang_b_tangent[1],
        tangent_mass,
        tangent_impulse: [
            F8::select(has_friction, warm.y, F8::ZERO),
            F8::select(has_friction, warm.z, F8::ZERO),
        ],
        restitution: F8::from_array(restitution),
        relative_velocity: dv.dot(n),
    };
}
