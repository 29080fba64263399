//! Regression tests for the defects of Cyclone's contact resolution that jostle fixes
//! (the known defects of the original code). Each test first shows that Cyclone's
//! formula, evaluated on the same data, misbehaves, then that the resolver does not.
//! (The contact-basis defect is tested in jostle-math.)

use jostle_math::{Mat3, Quat, Vec3};
use jostle_resolve::millington::{
    MillingtonResolver, MillingtonSettings, PreparedContact, coulomb, friction_impulse,
    frictionless_impulse, impulse_matrix, nonlinear_moves, prepare, resolve_velocity,
};
use jostle_resolve::{Contact, STATIC_BODY, SolverBody, synthetic};

const DT: f32 = 1.0 / 60.0;

/// Cyclone's `calculateFrictionImpulse` after the 3×3 solve, verbatim in structure: static if
/// |g_planar| ≤ μ·g_x, else re-solve g_x with the raw denominator; no clamp.
fn cyclone_friction(k: Mat3, desired: f32, velocity: Vec3, mu: f32) -> Vec3 {
    let g = k.inverse() * Vec3::new(desired, -velocity.y, -velocity.z);
    let planar = (g.y * g.y + g.z * g.z).sqrt();
    if planar > g.x * mu {
        let (dy, dz) = (g.y / planar, g.z / planar);
        let gx = desired / (k.x_axis.x + k.y_axis.x * mu * dy + k.z_axis.x * mu * dz);
        Vec3::new(gx, dy * mu * gx, dz * mu * gx)
    } else {
        g
    }
}

#[test]
fn both_bodies_immovable_gives_no_nan_and_writes_nothing() {
    // Cause: Cyclone divides the desired velocity change (and the penetration) by the total
    // inertia, which is zero when neither body can move: inf/NaN then spreads to the bodies.
    let mut pinned = SolverBody::new(Vec3::new(0.0, 0.5, 0.0), Quat::IDENTITY, 0.0, Mat3::ZERO);
    pinned.linear_velocity = Vec3::new(0.0, -1.0, 0.0);
    let mut bodies = vec![SolverBody::STATIC, pinned];
    let mut contacts = vec![
        Contact::new(1, STATIC_BODY, Vec3::ZERO, Vec3::Y, 0.1),
        Contact::new(1, STATIC_BODY, Vec3::X, Vec3::Y, 0.1).with_friction(0.5),
        Contact::new(STATIC_BODY, STATIC_BODY, Vec3::X, Vec3::Y, 0.2),
    ];
    for c in &mut contacts {
        c.impulse = Vec3::splat(7.0); // stale impulse from an earlier step: must be overwritten
    }

    let p = prepare(&contacts[0], &bodies, DT, 0.25).expect("valid");
    assert!(p.desired_delta_velocity > 0.0 && p.normal_inertia == 0.0);
    assert!(
        !(p.desired_delta_velocity / p.normal_inertia).is_finite(),
        "Cyclone's impulse"
    );
    assert_eq!(frictionless_impulse(&p), Vec3::ZERO);
    let mut pf = p;
    pf.friction = 0.5;
    assert_eq!(friction_impulse(&pf, &bodies), Vec3::ZERO);
    assert_eq!(nonlinear_moves(&p, &bodies, 0.2, 1.0), None);

    let before = bodies.clone();
    let mut resolver = MillingtonResolver::default();
    let stats = resolver.resolve_contacts(&mut bodies, &mut contacts, DT);
    assert_eq!(bodies, before, "nothing may be written");
    assert_eq!(
        stats.islands, 0,
        "contacts without a moving body form no island"
    );
    assert_eq!(stats.position_iterations + stats.velocity_iterations, 0);
    for c in &contacts {
        assert_eq!(c.impulse, Vec3::ZERO);
        assert!(c.penetration.is_finite());
    }
}

/// A body resting on the static ground through a contact at lever arm `r` (from the body),
/// with the given inverse inertia, and a prepared contact whose closing velocity and desired
/// change are overridden to the case under test.
fn lever_case(
    r: Vec3,
    inv_inertia: Vec3,
    velocity: Vec3,
    desired: f32,
    mu: f32,
) -> (Vec<SolverBody>, PreparedContact) {
    let body = SolverBody::new(-r, Quat::IDENTITY, 1.0, Mat3::from_diagonal(inv_inertia));
    let bodies = vec![SolverBody::STATIC, body];
    let contact = Contact::new(1, STATIC_BODY, Vec3::ZERO, Vec3::Y, 0.0).with_friction(mu);
    let mut p = prepare(&contact, &bodies, DT, 0.25).expect("valid");
    p.velocity = velocity;
    // Moving so before the step too (no acceleration this step).
    p.sliding_before = velocity.y.hypot(velocity.z);
    p.desired_delta_velocity = desired;
    (bodies, p)
}

#[test]
fn separating_contact_never_pulls_frictionless() {
    // Cause: Cyclone's frictionless impulse is desired / K₀₀ with no clamp; for a separating
    // contact (desired < 0) that is a pull.
    let (mut bodies, mut p) = lever_case(
        Vec3::new(0.0, -0.5, 0.0),
        Vec3::ONE,
        Vec3::new(1.0, 0.0, 0.0),
        -1.0,
        0.0,
    );
    assert!(
        p.desired_delta_velocity / p.normal_inertia < 0.0,
        "Cyclone pulls"
    );
    let before = bodies.clone();
    resolve_velocity(&mut p, &mut bodies);
    assert_eq!(p.impulse, Vec3::ZERO);
    assert_eq!(bodies, before);
}

#[test]
fn separating_sliding_contact_is_not_pushed_by_dynamic_friction() {
    // Cause: for a separating contact the dynamic-friction denominator
    // K₀₀ + μ(K₀₁ŷ + K₀₂ẑ) can be negative, so Cyclone's g_x = desired / denominator is a
    // *push* of about 5 N·s (with friction) on a contact that is moving apart.
    let (mut bodies, mut p) = lever_case(
        Vec3::new(1.0, -2.0, -1.0),
        Vec3::new(4.0, 0.5, 2.0),
        Vec3::new(0.0, 0.0, -3.0),
        -0.5,
        1.0,
    );
    let k = impulse_matrix(&p, &bodies);
    let cyclone = cyclone_friction(k, p.desired_delta_velocity, p.velocity, p.friction);
    assert!(
        cyclone.x > 4.0,
        "Cyclone pushes a separating contact: {cyclone}"
    );
    let before = bodies.clone();
    resolve_velocity(&mut p, &mut bodies);
    assert_eq!(p.impulse, Vec3::ZERO);
    assert_eq!(bodies, before);
}

#[test]
fn dynamic_friction_denominator_near_zero_is_guarded() {
    // Cause: when the slide is fast compared with the desired normal change and friction
    // coupling reduces the normal response, the denominator approaches zero and Cyclone's normal
    // impulse is ten times the frictionless one here (the body is thrown off the ground).
    let (mut bodies, mut p) = lever_case(
        Vec3::new(-0.5, -2.0, -1.0),
        Vec3::new(1.0, 4.0, 1.0),
        Vec3::new(0.0, 3.0, -2.0),
        0.1,
        1.0,
    );
    let k = impulse_matrix(&p, &bodies);
    let frictionless = p.desired_delta_velocity / k.x_axis.x;
    let cyclone = cyclone_friction(k, p.desired_delta_velocity, p.velocity, p.friction);
    assert!(
        cyclone.x > 8.0 * frictionless,
        "Cyclone: {cyclone}, frictionless {frictionless}"
    );

    // The lecture-form test (friction along the stop-dead impulse's planar direction) and the
    // resolver's (friction against the sliding velocity) are both bounded: at most
    // 1 / DYNAMIC_FRICTION_MIN_RESPONSE = 4 times the frictionless impulse.
    let lecture = coulomb(k.inverse() * Vec3::new(0.1, -3.0, 2.0), k, 0.1, 1.0);
    assert!(
        lecture.x > 0.0 && lecture.x <= 4.0 * frictionless * (1.0 + 1e-5),
        "{lecture} vs {frictionless}"
    );
    let g = friction_impulse(&p, &bodies);
    assert!(
        g.x > 0.0 && g.x <= 4.0 * frictionless * (1.0 + 1e-5),
        "{g} vs {frictionless}"
    );

    // Inside the friction cone, and still exactly the desired normal velocity change.
    assert!((g.y * g.y + g.z * g.z).sqrt() <= p.friction * g.x * (1.0 + 1e-5));
    assert!(
        ((k * g).x - 0.1).abs() < 1e-5,
        "normal change {}",
        (k * g).x
    );

    let v_before = bodies[1].velocity_at(Vec3::ZERO);
    resolve_velocity(&mut p, &mut bodies);
    let v_after = bodies[1].velocity_at(Vec3::ZERO);
    assert!(((v_after - v_before).y - 0.1).abs() < 1e-5);
    assert!(
        bodies
            .iter()
            .all(|b| b.linear_velocity.is_finite() && b.angular_velocity.is_finite())
    );
}

#[test]
fn coupled_solve_with_a_negative_normal_never_pulls() {
    // The 3×3 solve asks for a pull (g_x < 0) to kill a fast slide with a tiny desired change;
    // the result must still push (or do nothing) and respect the cone.
    let (bodies, p) = lever_case(
        Vec3::new(1.0, -2.0, 0.0),
        Vec3::ONE,
        Vec3::new(0.0, 0.0, 1.0),
        0.1,
        0.5,
    );
    let k = impulse_matrix(&p, &bodies);
    let solved = k.inverse() * Vec3::new(0.1, 0.0, -1.0);
    assert!(
        solved.x < 0.0,
        "the case must produce a negative normal: {solved}"
    );
    let g = friction_impulse(&p, &bodies);
    assert!(
        g.x >= 0.0 && (g.y * g.y + g.z * g.z).sqrt() <= 0.5 * g.x * (1.0 + 1e-5),
        "{g}"
    );
    // Direct Coulomb test of the clamp: a static-branch impulse with a pulling normal is zeroed.
    assert_eq!(
        coulomb(Vec3::new(-1.0, 0.0, 0.0), Mat3::IDENTITY, -1.0, 0.5),
        Vec3::ZERO
    );
}

#[test]
fn resolver_step_never_writes_the_static_entry() {
    let mut bodies = vec![
        SolverBody::STATIC,
        SolverBody::new(
            Vec3::new(0.0, 0.4, 0.0),
            Quat::IDENTITY,
            1.0,
            Mat3::IDENTITY,
        ),
    ];
    bodies[1].linear_velocity = Vec3::new(0.3, -2.0, 0.0);
    // Static on either side.
    let mut contacts = vec![
        Contact::new(1, STATIC_BODY, Vec3::new(0.1, -0.05, 0.0), Vec3::Y, 0.05).with_friction(0.5),
        Contact::new(STATIC_BODY, 1, Vec3::new(-0.1, -0.05, 0.0), -Vec3::Y, 0.05)
            .with_friction(0.5),
    ];
    let mut resolver = MillingtonResolver::new(MillingtonSettings::default());
    resolver.resolve_contacts(&mut bodies, &mut contacts, DT);
    assert_eq!(bodies[0], SolverBody::STATIC);
    assert!(
        bodies[1].linear_velocity.y > -1e-3,
        "approach removed: {}",
        bodies[1].linear_velocity
    );
    // B = body 1 in the second contact: the impulse on A (static) pushes along the normal, so
    // the body moved up, and the normal impulse component is still non-negative.
    assert!(contacts.iter().all(|c| c.impulse.x >= 0.0));
    assert!(contacts[0].impulse.x + contacts[1].impulse.x > 0.0);
}

#[test]
fn per_pick_coulomb_limit_made_resting_boxes_creep() {
    // Cause: the lecture's Coulomb test limited each pick's tangential impulse by μ times *that
    // pick's* normal impulse, and contacts were picked by their normal velocity change alone.
    // Once the four corners' normal velocities were resolved, the remaining sliding velocity
    // was never removed,
    // and a resting box on a 10° slope with μ = 0.5 crept by ≈ g·sinθ·dt per step. The fix tests
    // Coulomb against the contact's accumulated impulse of the step and picks contacts that can
    // still remove sliding (velocity.rs, passes.rs).
    let theta = 10f32.to_radians();
    let normal = Vec3::new(-theta.sin(), theta.cos(), 0.0);
    let down_slope = Vec3::new(-theta.cos(), -theta.sin(), 0.0);
    let half = Vec3::splat(0.5);
    let orientation = Quat::from_rotation_arc(Vec3::Y, normal);
    let g = Vec3::new(0.0, -9.81, 0.0);
    // A box at rest on the slope (1 mm deep, below the position epsilon) after this step's
    // velocity integration added g·dt.
    let mut body = synthetic::box_body(normal * (half.y - 1e-3), orientation, 1.0, half);
    body.linear_velocity = g * DT;
    body.last_acceleration = g;
    let mut bodies = vec![SolverBody::STATIC, body];
    let mut contacts = Vec::new();
    synthetic::box_plane_contacts(
        1,
        body.position,
        orientation,
        half,
        normal,
        0.0,
        &mut contacts,
    );
    for c in &mut contacts {
        c.friction = 0.5;
    }
    assert_eq!(contacts.len(), 4);
    let mut resolver = MillingtonResolver::default();
    let stats = resolver.resolve_contacts(&mut bodies, &mut contacts, DT);
    // The resolver integrates poses with the velocity the pass leaves (velocities were
    // integrated before resolution), so that velocity is the creep.
    let slide = bodies[1].linear_velocity.dot(down_slope);
    // Per step the old behaviour left 0.025 m/s ≈ 0.9·g·sinθ·dt (0.136 m of creep in 5 s); the
    // fix leaves about 0.001 m/s with the default settings, under a tenth of g·sinθ·dt.
    let per_step = 9.81 * theta.sin() * DT;
    assert!(
        slide.abs() < 0.1 * per_step,
        "slides at {slide} m/s after one step (g·sinθ·dt = {per_step})"
    );
    assert!(
        bodies[1].angular_velocity.length() < 1e-2,
        "spins at {}",
        bodies[1].angular_velocity
    );
    // Static friction: every corner stays inside its cone of the step's accumulated impulse.
    for c in &contacts {
        let planar = (c.impulse.y * c.impulse.y + c.impulse.z * c.impulse.z).sqrt();
        assert!(c.impulse.x >= 0.0 && planar <= 0.5 * c.impulse.x * (1.0 + 1e-5) + 1e-7);
    }
    // The pass ends because nothing is left to resolve, not because the budget ran out.
    let budget = MillingtonSettings::default()
        .velocity_iterations
        .for_contacts(contacts.len());
    assert!(stats.velocity_iterations < budget, "{stats:?}");
}

#[test]
fn dynamic_friction_opposes_the_sliding_velocity() {
    // Cause: Cyclone's dynamic branch directs the tangential impulse along the planar part of
    // the stop-dead impulse K⁻¹·Δv, which rotational coupling tilts away from the sliding
    // direction (≈ 31° at a unit cube's corner), so a sliding box felt only ≈ 0.86·μ·N and slid
    // 10–14% too fast down a slope. The lecture's own law is f = −v̂_planar·μ·|r|.
    let inv_inertia = Vec3::splat(6.0); // unit cube, 1 kg: I = 1/6
    let (bodies, p) = lever_case(
        Vec3::new(0.5, -0.5, 0.5),
        inv_inertia,
        // Sliding fast along contact-space y (a world tangent), closing slowly.
        Vec3::new(-0.05, 3.0, 0.0),
        0.05,
        0.3,
    );
    let k = impulse_matrix(&p, &bodies);
    let stop_dead = k.inverse() * Vec3::new(p.desired_delta_velocity, -p.velocity.y, -p.velocity.z);
    let cyclone = cyclone_friction(k, p.desired_delta_velocity, p.velocity, p.friction);
    let angle = |g: Vec3| (-g.y / (g.y * g.y + g.z * g.z).sqrt()).acos().to_degrees();
    assert!(
        angle(stop_dead) > 20.0,
        "the case must tilt the stop-dead impulse"
    );
    assert!(
        angle(cyclone) > 20.0,
        "Cyclone's friction is tilted by {}°",
        angle(cyclone)
    );
    let g = friction_impulse(&p, &bodies);
    assert!(
        angle(g) < 1e-2,
        "friction must oppose the sliding velocity, tilted by {}°",
        angle(g)
    );
    assert!(
        ((g.y * g.y + g.z * g.z).sqrt() - p.friction * g.x).abs() < 1e-5 * g.x,
        "dynamic: on the cone"
    );
    assert!(
        ((k * g).x - p.desired_delta_velocity).abs() < 1e-5,
        "normal change still exact"
    );
}
