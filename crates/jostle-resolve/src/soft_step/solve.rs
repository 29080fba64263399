//! The soft-step contact kernels: warm start, the biased solve, relax and restitution.
//!
//! Sequential impulses with accumulated, clamped impulses (Catto, GDC 2006 "Fast and Simple
//! Physics using Sequential Impulses"; soft step: Catto, "Solver2D", 2024, and Box2D v3's
//! `contact_solver.c`, here in 3D and written from the equations):
//! - normal: λ ← max(λ + Δλ, 0) with Δλ = −m_n·s_m·(v_n + bias) − s_i·λ, where the bias and
//!   the mass and impulse scales s_m, s_i come from the contact's [`Softness`] when it
//!   overlaps, and a speculative contact (separation s > 0) targets v_n ≥ −s/h rigidly, so it
//!   stops the gap from closing within the substep and nothing more;
//! - friction: both tangents at once with the inverse 2×2 effective mass, the accumulated
//!   tangent impulse clamped to the disk of radius μ·λ_n (isotropic, unlike a pyramid of two
//!   independent clamps which lets a box slide √2 times further along a diagonal).
//!
//! The static entry (index 0) is read but never written.

use super::body_state::BodyState;
use super::constraint::SoftContact;
use super::softness::Softness;
use crate::STATIC_BODY;
use jostle_math::Vec3;

/// Runs `kernel` on every contact with copies of its two body states, writing back every
/// body but the static entry.
#[inline]
fn for_each_pair(
    contacts: &mut [SoftContact],
    states: &mut [BodyState],
    mut kernel: impl FnMut(&mut SoftContact, &mut BodyState, &mut BodyState),
) {
    for c in contacts {
        let (ia, ib) = (c.a as usize, c.b as usize);
        debug_assert_ne!(ia, ib, "a contact needs two different bodies");
        let (mut a, mut b) = (states[ia], states[ib]);
        kernel(c, &mut a, &mut b);
        if c.a != STATIC_BODY {
            states[ia] = a;
        }
        if c.b != STATIC_BODY {
            states[ib] = b;
        }
    }
}

/// Applies the normal impulse `lambda` (N·s, on A along n, on B opposite).
#[inline]
fn apply_normal(c: &SoftContact, a: &mut BodyState, b: &mut BodyState, lambda: f32) {
    let p = c.normal * lambda;
    a.linear_velocity += p * a.inv_mass;
    a.angular_velocity += c.ang_a_normal * lambda;
    b.linear_velocity -= p * b.inv_mass;
    b.angular_velocity -= c.ang_b_normal * lambda;
}

/// Applies the tangent impulse `lambda` (N·s along t₁, t₂; on A, and opposite on B).
#[inline]
fn apply_tangent(c: &SoftContact, a: &mut BodyState, b: &mut BodyState, lambda: [f32; 2]) {
    let p = c.tangent1 * lambda[0] + c.tangent2 * lambda[1];
    a.linear_velocity += p * a.inv_mass;
    a.angular_velocity += c.ang_a_tangent[0] * lambda[0] + c.ang_a_tangent[1] * lambda[1];
    b.linear_velocity -= p * b.inv_mass;
    b.angular_velocity -= c.ang_b_tangent[0] * lambda[0] + c.ang_b_tangent[1] * lambda[1];
}

/// Applies every contact's accumulated impulse (the previous substep's, or on the first
/// substep the previous step's): the solver then only corrects what changed.
pub fn warm_start(contacts: &mut [SoftContact], states: &mut [BodyState]) {
    for_each_pair(contacts, states, |c, a, b| {
        apply_normal(c, a, b, c.normal_impulse);
        if c.friction > 0.0 {
            apply_tangent(c, a, b, c.tangent_impulse);
        }
    });
}

/// The normal row and then friction for one contact; `softness` applies to overlap.
#[inline]
fn solve_contact(
    c: &mut SoftContact,
    a: &mut BodyState,
    b: &mut BodyState,
    softness: Softness,
    inv_h: f32,
    max_push_out: f32,
) {
    let s = c.separation(a, b);
    let (bias, mass_scale, impulse_scale) = if s > 0.0 {
        (s * inv_h, 1.0, 0.0)
    } else {
        (
            (softness.bias_rate * s).max(-max_push_out),
            softness.mass_scale,
            softness.impulse_scale,
        )
    };
    let vn = c.relative_velocity(a, b).dot(c.normal);
    let delta = -c.normal_mass * mass_scale * (vn + bias) - impulse_scale * c.normal_impulse;
    let total = (c.normal_impulse + delta).max(0.0);
    let delta = total - c.normal_impulse;
    c.normal_impulse = total;
    c.max_normal_impulse = c.max_normal_impulse.max(delta);
    apply_normal(c, a, b, delta);

    if c.friction > 0.0 {
        let dv = c.relative_velocity(a, b);
        let (vt1, vt2) = (dv.dot(c.tangent1), dv.dot(c.tangent2));
        let k = c.tangent_mass;
        let old = c.tangent_impulse;
        let mut new = [
            old[0] - (k[0] * vt1 + k[1] * vt2),
            old[1] - (k[1] * vt1 + k[2] * vt2),
        ];
        let limit = c.friction * c.normal_impulse;
        let len_sq = new[0] * new[0] + new[1] * new[1];
        if len_sq > limit * limit {
            // len_sq > 0 here since limit ≥ 0.
            let scale = limit / len_sq.sqrt();
            new = [new[0] * scale, new[1] * scale];
        }
        c.tangent_impulse = new;
        apply_tangent(c, a, b, [new[0] - old[0], new[1] - old[1]]);
    }
}

/// One biased pass: every contact with its own soft bias, pushing overlap out at most at
/// `max_push_out` (m/s). `inv_h` is 1/substep (1/s).
pub fn solve(
    contacts: &mut [SoftContact],
    states: &mut [BodyState],
    inv_h: f32,
    max_push_out: f32,
) {
    for_each_pair(contacts, states, |c, a, b| {
        let softness = c.softness;
        solve_contact(c, a, b, softness, inv_h, max_push_out);
    });
}

/// One relax pass: rigid, without bias, so the velocity the bias added to resolve overlap is
/// removed again once the positions moved (speculative contacts keep their gap rule).
pub fn relax(contacts: &mut [SoftContact], states: &mut [BodyState], inv_h: f32) {
    for_each_pair(contacts, states, |c, a, b| {
        solve_contact(c, a, b, Softness::RIGID, inv_h, 0.0);
    });
}

/// Whether `c` bounces in the restitution pass: it has e > 0, approached faster than
/// `threshold` (m/s) at the start of the step, and pushed during the step (Box2D's rule: a
/// speculative contact that never engaged does not bounce).
#[inline]
pub fn bounces(c: &SoftContact, threshold: f32) -> bool {
    c.restitution > 0.0 && c.relative_velocity < -threshold && c.max_normal_impulse > 0.0
}

/// One sweep of the restitution pass, after the substeps: every contact that
/// [`bounces`] gets the normal velocity −e·v₀ (v₀ its approach velocity at the start of the
/// step); every other contact is solved rigidly without bias, as in [`relax`] (normal only).
/// Accumulated impulses stay ≥ 0. Returns the largest normal impulse change of the sweep
/// times the contact's inverse effective mass, i.e. the largest normal velocity correction
/// (m/s), for the caller's convergence test.
///
/// Box2D v3 solves only the bouncing contacts, once. That is exact for one contact, but where
/// an impact is passed through touching bodies (a Newton's cradle) it leaves the contacts
/// behind the bouncing one overlapping in velocity, and the next step resolves them
/// inelastically: the cradle loses 40% of its energy in one step. Sweeping every contact
/// until the velocities agree gives the simultaneous (LCP) answer with Newton's restitution
/// law, which conserves the energy of an elastic chain.
pub fn restitution(
    contacts: &mut [SoftContact],
    states: &mut [BodyState],
    threshold: f32,
    inv_h: f32,
) -> f32 {
    let mut largest = 0.0f32;
    for_each_pair(contacts, states, |c, a, b| {
        let vn = c.relative_velocity(a, b).dot(c.normal);
        let target = if bounces(c, threshold) {
            -c.restitution * c.relative_velocity
        } else {
            let s = c.separation(a, b);
            if s > 0.0 { -s * inv_h } else { 0.0 }
        };
        let delta = -c.normal_mass * (vn - target);
        let total = (c.normal_impulse + delta).max(0.0);
        let delta = total - c.normal_impulse;
        c.normal_impulse = total;
        if c.normal_mass > 0.0 {
            largest = largest.max(delta.abs() / c.normal_mass);
        }
        apply_normal(c, a, b, delta);
    });
    largest
}

/// The accumulated impulse of `c` in contact space (normal, t₁, t₂), per substep (N·s).
#[inline]
pub fn accumulated(c: &SoftContact) -> Vec3 {
    Vec3::new(c.normal_impulse, c.tangent_impulse[0], c.tangent_impulse[1])
}
