//! Preparing contact points eight lanes at a time, on the step-start poses.
//!
//! Everything the substep loop needs is computed here once per step, so the kernels touch only
//! a [`PointLanes`] and the bodies' velocities and motion: the anchors, the normal and tangents
//! (of [`jostle_math::contact_basis`], computed lane-wise; the convention of the stored
//! impulses), the angular response of each body to a unit impulse along each direction
//! (I⁻¹·(r × d), so no inertia matrix is loaded in the loop), the normal effective mass 1/(n·K·n), the
//! inverse 2×2 tangent effective mass (so one friction solve is exact for both tangents
//! together), the softness that applies (static or dynamic stiffness), the approach velocity
//! restitution reflects, and the warm-start impulse (the stored step impulse × 1/substeps).
//!
//! The adjusted separation −penetration − (r_A − r_B)·n is stored so that the separation
//! during the step is that plus (Δx_A + Δq_A·r_A − Δx_B − Δq_B·r_B)·n (Box2D's "adjusted
//! separation"; see [`super::solve`]).

use super::batch::{LANES, ManifoldLanes, NO_SOURCE, PointLanes};
use super::lanes::{F8, Lane, V3x8, WIDTH};
use super::softness::Softness;
use crate::{Contact, SolverBody};
use jostle_math::{Mat3, Vec3};

/// Trace (s/kg) of a contact's tangent response K below which [`prepare_point`] inverts K
/// scaled to unit trace: bodies of about 10¹⁵ kg and more.
const SMALL_TANGENT_TRACE: f32 = 1e-15;

/// What [`prepare_point`] needs besides the contact and its bodies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrepareParams {
    /// Softness of a contact against a body that cannot move linearly.
    pub static_softness: Softness,
    /// Softness of a contact between two bodies that can.
    pub dynamic_softness: Softness,
    /// Scale from the stored step impulse to one substep's warm start (1/substeps, or 0).
    pub warm_scale: f32,
    /// 1 / [`super::SoftStepSettings::preload_target`] (1/m; `f32::MAX` for a target of 0):
    /// a point's preload grows in over that much overlap.
    pub preload_ramp: f32,
    /// (ζ / [`super::PRELOAD_MIN_DAMPING`])²·|g|·h (m/s), ζ the damping ratio: bounds how
    /// much the preload may stiffen a point under its load ([`prepare_point`]); 0 turns the
    /// preload off.
    pub preload_bound: f32,
    /// The step (s) within which a contact beyond the speculative margin may still close its
    /// gap: such a contact takes part when its bodies, at their velocities at the start of
    /// the step, close the gap beyond the margin within it ([`super::Batches::pack`]); 0:
    /// none beyond the margin.
    pub step: f32,
    /// Gravity's direction (unit), or zero without gravity: [`super::Batches::pack`] groups
    /// the manifolds whose normal lies within 60° of horizontal into batches of their own.
    pub down: Vec3,
}

/// The step-start state of eight bodies, by lane, as preparation reads it.
#[derive(Clone, Copy, Debug)]
pub struct BodyLanes<F = F8> {
    position: V3x8<F>,
    linear_velocity: V3x8<F>,
    angular_velocity: V3x8<F>,
    /// Columns of the world inverse inertia (zero for a body that does not rotate).
    inv_inertia: [V3x8<F>; 3],
    /// 1/m (1/kg).
    pub inv_mass: F,
    /// 1/m along each world axis (1/kg; zero along a locked axis).
    pub inv_mass_axes: V3x8<F>,
}

impl<F: Lane> BodyLanes<F> {
    /// Loads `bodies[idx[lane]]` into each lane.
    #[inline(always)]
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
            inv_mass: F::from_array(b.map(|b| b.inv_mass)),
            inv_mass_axes: V3x8::from_lanes(b.map(|b| b.inv_mass_axes())),
        }
    }

    /// I⁻¹·v per lane.
    #[inline(always)]
    fn inv_inertia_times(&self, v: V3x8<F>) -> V3x8<F> {
        let [x, y, z] = self.inv_inertia;
        x * v.x + y * v.y + z * v.z
    }

    /// Velocity of each lane's material point at offset `r` from its centre of mass.
    #[inline(always)]
    fn velocity_at(&self, r: V3x8<F>) -> V3x8<F> {
        self.linear_velocity + self.angular_velocity.cross(r)
    }
}

/// Prepares one point of eight lanes into `out`: `contacts[lane]` between the bodies of lane `lane` in
/// `a` and `b`. Lanes whose contact is `None` are padding and get zeros (zero normal, zero
/// masses), so every impulse they compute is zero.
#[inline(always)]
pub fn prepare_point<F: Lane>(
    out: &mut PointLanes<F>,
    contacts: [Option<&Contact>; WIDTH],
    a: &BodyLanes<F>,
    b: &BodyLanes<F>,
    params: &PrepareParams,
) {
    // Lane by lane into arrays, then one load per component (writing lanes of a vector one
    // at a time would stall the load that follows on every store).
    let mut vectors = [[Vec3::ZERO; WIDTH]; 4];
    let mut present = [0.0; WIDTH];
    let mut penetration = [0.0; WIDTH];
    let mut friction = [0.0; WIDTH];
    let mut restitution = [0.0; WIDTH];
    let mut preload = [0.0; WIDTH];
    for (lane, c) in contacts.iter().enumerate() {
        if let Some(c) = c {
            vectors[0][lane] = c.normal;
            vectors[1][lane] = c.point;
            vectors[2][lane] = c.impulse;
            vectors[3][lane] = c.point_b;
            present[lane] = 1.0;
            penetration[lane] = c.penetration;
            friction[lane] = c.friction;
            restitution[lane] = c.restitution;
            preload[lane] = c.preload;
        }
    }
    // No closures over lanes here or below: a closure is not compiled with the target
    // features of the kernel it sits in, so every lane operation in it would be a call.
    let [n, point, stored, point_b] = [
        V3x8::<F>::from_lanes(vectors[0]),
        V3x8::from_lanes(vectors[1]),
        V3x8::from_lanes(vectors[2]),
        V3x8::from_lanes(vectors[3]),
    ];
    // `contact_basis` lane by lane, the same operations in the same order: t₁ = n × a
    // normalised, with a = x̂ unless |n.x| ≥ 0.6 (then ŷ), and t₂ = n × t₁. Padding lanes
    // (zero normal) get zero tangents instead of the NaN the normalisation gives them.
    let use_x = n.x.abs().cmplt(F::splat(0.6));
    let axis = V3x8 {
        x: F::select(use_x, F::ONE, F::ZERO),
        y: F::select(use_x, F::ZERO, F::ONE),
        z: F::ZERO,
    };
    let present = F::from_array(present).cmpgt(F::ZERO);
    let t1 = n.cross(axis);
    let t1 = t1 * t1.dot(t1).sqrt().recip();
    let t2 = n.cross(t1);
    let (t1, t2) = (zero_unless(present, t1), zero_unless(present, t2));
    let r_a = point - a.position;
    let r_b = point_b - b.position;
    // 1/m as the kernels apply it (x of the per-axis inverse mass: the same as 1/m unless the
    // body is locked along every axis, where it is 0).
    let m = a.inv_mass_axes.x + b.inv_mass_axes.x;
    // Where a body's translation is locked on some axis, its inverse mass is a diagonal
    // matrix M: the rows' linear parts are u·(M_A + M_B)·v; elsewhere m·(u·v), with u·u
    // taken as 1 and t₁·t₂ as 0 as before.
    let m_axes = a.inv_mass_axes + b.inv_mass_axes;
    let uniform = a.inv_mass_axes.uniform() & b.inv_mass_axes.uniform();
    let linear = |u: V3x8<F>, v: V3x8<F>, same: bool| {
        let plain = if same { m } else { F::ZERO };
        F::select(uniform, plain, m_axes.scale(u).dot(v))
    };

    let (rn_a, rn_b) = (r_a.cross(n), r_b.cross(n));
    let ang_a_normal = a.inv_inertia_times(rn_a);
    let ang_b_normal = b.inv_inertia_times(rn_b);
    let k_normal = linear(n, n, true) + rn_a.dot(ang_a_normal) + rn_b.dot(ang_b_normal);
    let normal_mass = F::select(k_normal.cmpgt(F::ZERO), k_normal.recip(), F::ZERO);

    let rt_a = [r_a.cross(t1), r_a.cross(t2)];
    let rt_b = [r_b.cross(t1), r_b.cross(t2)];
    let ang_a_tangent = [a.inv_inertia_times(rt_a[0]), a.inv_inertia_times(rt_a[1])];
    let ang_b_tangent = [b.inv_inertia_times(rt_b[0]), b.inv_inertia_times(rt_b[1])];
    // K = m·I + Σ (r × tᵢ)·I⁻¹·(r × tⱼ) over both bodies, symmetric.
    let k11 = linear(t1, t1, true) + rt_a[0].dot(ang_a_tangent[0]) + rt_b[0].dot(ang_b_tangent[0]);
    let k12 = linear(t1, t2, false) + rt_a[0].dot(ang_a_tangent[1]) + rt_b[0].dot(ang_b_tangent[1]);
    let k22 = linear(t2, t2, true) + rt_a[1].dot(ang_a_tangent[1]) + rt_b[1].dot(ang_b_tangent[1]);
    // K's entries are inverse masses: for bodies of about 10²⁰ kg its determinant fell below
    // f32's normal range and its inverse overflowed (a box of 8·10¹⁹ kg at rest on the ground
    // went NaN at its first step). Where K is that small it is inverted scaled to unit trace
    // (K⁻¹ = adj(uK)·u / det(uK), u = 1/tr K); elsewhere exactly as before.
    let trace = k11 + k22;
    let small = trace.cmpgt(F::ZERO) & trace.cmplt(F::splat(SMALL_TANGENT_TRACE));
    let u = F::select(small, trace.recip(), F::ONE);
    let (k11, k12, k22) = (k11 * u, k12 * u, k22 * u);
    let det = k11 * k22 - k12 * k12;
    let invertible = det.cmpgt(F::splat(f32::EPSILON) * k11 * k22) & det.is_finite_mask();
    let inv_det = F::select(invertible, det.recip() * u, F::ZERO);
    // A singular K (rank 1: the bodies cannot move along one tangent direction, as bodies
    // kept in a plane by their locks cannot leave it) takes its pseudo-inverse K/tr(K)²:
    // friction along the direction that moves, none along the other. (Zero for padding.)
    // What a normal impulse does along each tangent (the relax pass's friction reads it).
    let normal_tangent = [
        linear(n, t1, false) + rt_a[0].dot(ang_a_normal) + rt_b[0].dot(ang_b_normal),
        linear(n, t2, false) + rt_a[1].dot(ang_a_normal) + rt_b[1].dot(ang_b_normal),
    ];
    // The pseudo-inverse K/tr(K)²: of the scaled K, uK·u.
    let pseudo = F::select(
        small,
        u,
        F::select(trace.cmpgt(F::ZERO), (trace * trace).recip(), F::ZERO),
    );
    let tangent_mass = [
        F::select(invertible, k22 * inv_det, k11 * pseudo),
        F::select(invertible, -k12 * inv_det, k12 * pseudo),
        F::select(invertible, k11 * inv_det, k22 * pseudo),
    ];

    let fixed = a.inv_mass.cmpeq(F::ZERO) | b.inv_mass.cmpeq(F::ZERO);
    let (s, d) = (params.static_softness, params.dynamic_softness);

    let friction = F::from_array(friction).max(F::ZERO);
    let warm = stored * F::splat(params.warm_scale);
    let has_friction = friction.cmpgt(F::ZERO);
    let dv = a.velocity_at(r_a) - b.velocity_at(r_b);
    // The chord term ([`PointLanes::chord`]) at the turn of the immovable body of the pair (a
    // turning kinematic one; a fixed one has none, and two immovable bodies take no part), on
    // the tangents only (the normal rows see the separation itself).
    let turn = select(
        a.inv_mass.cmpeq(F::ZERO),
        a.angular_velocity,
        zero_unless(b.inv_mass.cmpeq(F::ZERO), b.angular_velocity),
    );
    let chord = turn.cross(turn.cross(r_a - r_b));
    // The preload acts in proportion to the overlap up to its full value, reached at the
    // target overlap: slope p / target. The spring is then 1 + slope times stiffer there, and
    // the load λ it carries rides on it like a mass of λ/(|g|·h); its damping ratio falls as
    // ζ·√(m / (mass · (1 + slope))), so the slope is bounded to keep it at
    // PRELOAD_MIN_DAMPING or more: 1 + slope ≤ (ζ / PRELOAD_MIN_DAMPING)²·m·|g|·h / λ.
    let preload = F::from_array(preload).max(F::ZERO);
    let loaded = warm.x.cmpgt(F::ZERO);
    let bound =
        F::splat(params.preload_bound) * normal_mass / F::select(loaded, warm.x, F::ONE) - F::ONE;
    let slope = preload * F::splat(params.preload_ramp);
    let slope = F::select(slope.cmpgt(bound), bound, slope).max(F::ZERO);
    let preload_slope = F::select(loaded, slope, F::ZERO);
    *out = PointLanes {
        normal: n,
        r_a,
        r_b,
        ang_a_normal,
        ang_b_normal,
        base_separation: -F::from_array(penetration) - (r_a - r_b).dot(n),
        normal_mass,
        normal_impulse: warm.x.max(F::ZERO),
        max_normal_impulse: F::ZERO,
        bias_rate: F::select(fixed, F::splat(s.bias_rate), F::splat(d.bias_rate)),
        mass_scale: F::select(fixed, F::splat(s.mass_scale), F::splat(d.mass_scale)),
        impulse_scale: F::select(fixed, F::splat(s.impulse_scale), F::splat(d.impulse_scale)),
        friction,
        tangent1: t1,
        tangent2: t2,
        ang_a_tangent1: ang_a_tangent[0],
        ang_a_tangent2: ang_a_tangent[1],
        ang_b_tangent1: ang_b_tangent[0],
        ang_b_tangent2: ang_b_tangent[1],
        tangent_mass,
        tangent_impulse: [
            F::select(has_friction, warm.y, F::ZERO),
            F::select(has_friction, warm.z, F::ZERO),
        ],
        normal_tangent,
        chord: [chord.dot(t1), chord.dot(t2)],
        restitution: F::from_array(restitution),
        relative_velocity: dv.dot(n),
        preload,
        preload_slope,
        // Computed by the first pass that needs it.
        separation: F::ZERO,
    };
}

/// `t` in the lanes of `mask`, `f` in the others.
#[inline(always)]
fn select<F: Lane>(mask: F::Mask, t: V3x8<F>, f: V3x8<F>) -> V3x8<F> {
    V3x8 {
        x: F::select(mask, t.x, f.x),
        y: F::select(mask, t.y, f.y),
        z: F::select(mask, t.z, f.z),
    }
}

/// `v` in the lanes of `mask`, zero in the others.
#[inline(always)]
fn zero_unless<F: Lane>(mask: F::Mask, v: V3x8<F>) -> V3x8<F> {
    select(mask, v, V3x8::ZERO)
}

/// Prepares every point of the packed batches: for each batch, its bodies are gathered once
/// (and their inverse masses stored in the batch), then each point is prepared from the
/// contacts `sources` names ([`prepare_point`]). On x86-64 CPUs with AVX this runs with
/// 256-bit lanes, as the kernels do (see [`super::solve`]); the results are the same.
pub fn prepare_batches(
    manifolds: &mut [ManifoldLanes],
    points: &mut [PointLanes],
    sources: &[[u32; LANES]],
    contacts: &[Contact],
    bodies: &[SolverBody],
    params: &PrepareParams,
) {
    prepare_batch_range(manifolds, points, 0, sources, contacts, bodies, params);
}

/// [`prepare_batches`] for a run of the batches: `points` holds their points, the first
/// being point `base` of all batches (`sources` and each batch's
/// [`ManifoldLanes::first`] count from the first point of all). Each batch is prepared on
/// its own, so runs may be prepared in any order, or at once on several threads, with the
/// same result.
pub fn prepare_batch_range(
    manifolds: &mut [ManifoldLanes],
    points: &mut [PointLanes],
    base: u32,
    sources: &[[u32; LANES]],
    contacts: &[Contact],
    bodies: &[SolverBody],
    params: &PrepareParams,
) {
    with_best_lanes!(prepare_batches_impl(
        manifolds,
        points,
        base: u32,
        sources: &[[u32; LANES]],
        contacts: &[Contact],
        bodies: &[SolverBody],
        params: &PrepareParams
    ) -> ())
}

#[inline(always)]
fn prepare_batches_impl<F: Lane>(
    manifolds: &mut [ManifoldLanes<F>],
    points: &mut [PointLanes<F>],
    base: u32,
    sources: &[[u32; LANES]],
    contacts: &[Contact],
    bodies: &[SolverBody],
    params: &PrepareParams,
) {
    for m in manifolds.iter_mut() {
        let a = BodyLanes::<F>::gather(bodies, m.a);
        let b = BodyLanes::<F>::gather(bodies, m.b);
        m.inv_mass_a = a.inv_mass_axes;
        m.inv_mass_b = b.inv_mass_axes;
        let differs = |v: V3x8<F>| (0..WIDTH).any(|l| v.x[l] != v.y[l] || v.y[l] != v.z[l]);
        m.locked = differs(a.inv_mass_axes) || differs(b.inv_mass_axes);
        let range = m.first as usize..(m.first + m.count) as usize;
        let local = (m.first - base) as usize..(m.first - base + m.count) as usize;
        for (out, source) in points[local].iter_mut().zip(&sources[range]) {
            let lane_contacts = source.map(|i| (i != NO_SOURCE).then(|| &contacts[i as usize]));
            prepare_point(out, lane_contacts, &a, &b, params);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soft_step::{Batches, Softness};
    use crate::synthetic;

    /// `prepare_batches` takes the 256-bit path on CPUs with AVX; what it prepares must equal
    /// the 128-bit preparation exactly (Debug prints every float in shortest round-trip form,
    /// signed zeros included).
    #[test]
    fn wide_preparation_matches_the_128_bit_one() {
        let scene = synthetic::random_pile(2000, 11);
        let h = synthetic::DT / 4.0;
        let params = PrepareParams {
            static_softness: Softness::new(60.0, 10.0, h),
            dynamic_softness: Softness::new(30.0, 10.0, h),
            warm_scale: 0.25,
            preload_ramp: 0.0,
            preload_bound: 0.0,
            step: 0.0,
            down: Vec3::ZERO,
        };
        let mut batches = Batches::default();
        batches.pack(&scene.contacts, &scene.bodies, 0.02, &params);
        assert!(batches.contacts > 1000);
        let mut manifolds = batches.manifolds.clone();
        let mut points = vec![PointLanes::default(); batches.points.len()];
        prepare_batches_impl::<F8>(
            &mut manifolds,
            &mut points,
            0,
            &batches.sources,
            &scene.contacts,
            &scene.bodies,
            &params,
        );
        let (expected_points, expected_manifolds) =
            (format!("{points:?}"), format!("{manifolds:?}"));
        // The detected level (used by `pack` above), then at most AVX, then 128-bit lanes.
        for cap in [0, 2, 1] {
            #[cfg(target_arch = "x86_64")]
            super::super::lanes_avx::CAP.store(cap, std::sync::atomic::Ordering::Relaxed);
            let mut again = Batches::default();
            again.pack(&scene.contacts, &scene.bodies, 0.02, &params);
            assert_eq!(format!("{:?}", again.points), expected_points, "cap {cap}");
            assert_eq!(
                format!("{:?}", again.manifolds),
                expected_manifolds,
                "cap {cap}"
            );
        }
        #[cfg(target_arch = "x86_64")]
        super::super::lanes_avx::CAP.store(0, std::sync::atomic::Ordering::Relaxed);
    }

    /// Prepared (and factored) a run of batches at a time, as the team's threads do, the
    /// batches come out exactly as prepared all at once.
    #[test]
    fn runs_of_batches_are_prepared_as_all_at_once() {
        let scene = synthetic::random_pile(2000, 12);
        let params = PrepareParams {
            static_softness: Softness::new(120.0, 7.0, synthetic::DT / 8.0),
            dynamic_softness: Softness::new(60.0, 7.0, synthetic::DT / 8.0),
            warm_scale: 0.125,
            preload_ramp: 2000.0,
            preload_bound: 1.0,
            step: synthetic::DT,
            down: Vec3::NEG_Y,
        };
        let mut whole = Batches::default();
        whole.pack(&scene.contacts, &scene.bodies, 0.02, &params);
        crate::soft_step::solve::factor_blocks(&mut whole);
        let mut runs = Batches::default();
        runs.arrange(&scene.contacts, &scene.bodies, 0.02, &params);
        assert!(runs.manifolds.len() > 10);
        let Batches {
            manifolds,
            points,
            sources,
            ..
        } = &mut runs;
        let mut rest = &mut manifolds[..];
        // Runs of 1, 2, 3, ... batches, each with its own points.
        for len in 1.. {
            if rest.is_empty() {
                break;
            }
            let (run, after) = rest.split_at_mut(len.min(rest.len()));
            let (p0, p1) = (
                run[0].first,
                run[run.len() - 1].first + run[run.len() - 1].count,
            );
            let pts = &mut points[p0 as usize..p1 as usize];
            prepare_batch_range(
                run,
                pts,
                p0,
                sources,
                &scene.contacts,
                &scene.bodies,
                &params,
            );
            crate::soft_step::solve::factor_block_range(run, pts, p0);
            rest = after;
        }
        assert_eq!(format!("{:?}", runs.points), format!("{:?}", whole.points));
        assert_eq!(
            format!("{:?}", runs.manifolds),
            format!("{:?}", whole.manifolds)
        );
    }

    /// The lane-wise basis is `contact_basis`, bit for bit, for normals on both sides of the
    /// |n.x| = 0.6 switch; padding lanes get zero tangents.
    #[test]
    fn tangents_are_those_of_contact_basis() {
        let mut rng = synthetic::Rng::new(5);
        let bodies = [
            SolverBody::STATIC,
            synthetic::box_body(
                Vec3::new(0.0, 1.0, 0.0),
                jostle_math::Quat::IDENTITY,
                1.0,
                Vec3::splat(0.5),
            ),
        ];
        let lanes = BodyLanes::<F8>::gather(&bodies, [1, 1, 1, 1, 1, 1, 1, 0]);
        let statics = BodyLanes::<F8>::gather(&bodies, [0; WIDTH]);
        let params = PrepareParams {
            static_softness: Softness::new(60.0, 10.0, 0.01),
            dynamic_softness: Softness::new(30.0, 10.0, 0.01),
            warm_scale: 0.25,
            preload_ramp: 0.0,
            preload_bound: 0.0,
            step: 0.0,
            down: Vec3::ZERO,
        };
        for _ in 0..50 {
            let contacts: Vec<Contact> = (0..WIDTH - 1)
                .map(|_| {
                    let n = rng.vec(1.0).try_normalize().unwrap_or(Vec3::Y);
                    Contact::new(1, 0, rng.vec(1.0), n, 0.01)
                })
                .collect();
            let mut lane_contacts = [None; WIDTH];
            for (slot, c) in lane_contacts.iter_mut().zip(&contacts) {
                *slot = Some(c);
            }
            let mut out = PointLanes::default();
            prepare_point(&mut out, lane_contacts, &lanes, &statics, &params);
            for (lane, c) in contacts.iter().enumerate() {
                let basis = jostle_math::contact_basis(c.normal);
                assert_eq!(
                    out.tangent1.lane(lane).to_array().map(f32::to_bits),
                    basis.y_axis.to_array().map(f32::to_bits)
                );
                assert_eq!(
                    out.tangent2.lane(lane).to_array().map(f32::to_bits),
                    basis.z_axis.to_array().map(f32::to_bits)
                );
            }
            assert_eq!(out.tangent1.lane(WIDTH - 1), Vec3::ZERO);
            assert_eq!(out.tangent2.lane(WIDTH - 1), Vec3::ZERO);
        }
    }
}
