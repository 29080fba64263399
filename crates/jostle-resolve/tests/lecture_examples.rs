//! The seed lecture's three worked examples (seed/contact-physics-lecture.md), reproduced
//! through the resolver's own functions to the digits the lecture prints.
//!
//! All three use μ = 0 and last_acceleration = 0, and their closing speeds (2.2173 and
//! 1.25 m/s) are far above `velocity_limit` (0.25 m/s), so restitution applies unmodified.
//! Integration is not run: the lecture's numbers are the state right after the impulse or the
//! projection.

use jostle_math::{Mat3, Quat, Vec3};
use jostle_resolve::millington::{
    MillingtonSettings, apply_moves, nonlinear_moves, prepare, resolve_velocity,
    velocity_change_per_unit_impulse,
};
use jostle_resolve::{Contact, STATIC_BODY, SolverBody};

/// |actual − printed| within half a unit of the printed last digit (`unit`), plus f32 slack.
fn printed(actual: f32, printed: f32, unit: f32) {
    let tol = 0.5 * unit + 1e-6 * printed.abs();
    assert!(
        (actual - printed).abs() <= tol,
        "{actual} is not {printed} to ±{tol}"
    );
}

fn printed_vec(actual: Vec3, expected: [f32; 3], unit: f32) {
    for (a, e) in actual.to_array().into_iter().zip(expected) {
        printed(a, e, unit);
    }
}

fn body(position: Vec3, mass: f32, inertia: f32) -> SolverBody {
    SolverBody::new(
        position,
        Quat::IDENTITY,
        1.0 / mass,
        Mat3::from_diagonal(Vec3::splat(1.0 / inertia)),
    )
}

const DT: f32 = 1.0 / 60.0;
const LIMIT: f32 = 0.25;

#[test]
fn example_1_two_spheres() {
    // Sphere 1: hollow, mass 10, I = 240 (the lecture's table); sphere 2: solid, mass 20, I = 288.
    let mut s1 = body(Vec3::new(21.7832, 26.3132, 0.0), 10.0, 240.0);
    s1.linear_velocity = Vec3::new(3.9124, 3.1134, 0.0);
    let mut s2 = body(Vec3::new(32.0, 20.0, 0.0), 20.0, 288.0);
    s2.linear_velocity = Vec3::new(0.0, 1.0, 0.0);
    let mut bodies = vec![SolverBody::STATIC, s1, s2];
    let contact = Contact::new(
        1,
        2,
        Vec3::new(26.8916, 23.1566, 0.0),
        Vec3::new(-0.8507, 0.5257, 0.0),
        0.0,
    )
    .with_restitution(0.8);

    let mut p = prepare(&contact, &bodies, DT, LIMIT).expect("valid contact");
    // Separating velocity v_s ≈ −2.2173 (−1.6916 − 0.5257), Δv_s ≈ 3.9911.
    printed(p.velocity.x, -2.2173, 1e-4);
    printed(p.desired_delta_velocity, 3.9911, 1e-4);
    // Δq̇_t = 0.15 + 0: both lever arms are parallel to the normal (to the data's rounding).
    printed(velocity_change_per_unit_impulse(&p), 0.15, 1e-4);

    resolve_velocity(&mut p, &mut bodies);
    printed(p.impulse.x, 26.61, 1e-2);
    assert_eq!(
        (p.impulse.y, p.impulse.z),
        (0.0, 0.0),
        "frictionless: no tangential impulse"
    );
    printed_vec(bodies[1].linear_velocity, [1.649, 4.512, 0.0], 1e-3);
    // The lecture prints 0.3007 (1 − 0.6993); the unrounded impulse gives 1 − 0.69937 = 0.30063,
    // which rounds to 0.3006, so the last digit is checked to ±1 instead of ±0.5.
    printed(bodies[2].linear_velocity.x, 1.132, 1e-3);
    printed(bodies[2].linear_velocity.y, 0.3007, 2e-4);
    // "Recall that there are no changes to angular velocities" (to the data's rounding).
    assert!(
        bodies[1].angular_velocity.length() < 1e-4 && bodies[2].angular_velocity.length() < 1e-4
    );
    assert_eq!(bodies[0], SolverBody::STATIC);
}

#[test]
fn example_2_cube_on_floor() {
    // Cube of side 12, mass 10, I = 240; the floor is the static entry.
    let mut cube = body(Vec3::new(20.1966, 16.1966, 0.0), 10.0, 240.0);
    cube.linear_velocity = Vec3::new(2.165, -1.25, 0.0);
    let mut bodies = vec![SolverBody::STATIC, cube];
    let contact = Contact::new(1, STATIC_BODY, Vec3::new(22.3932, 8.0, 0.0), Vec3::Y, 0.0)
        .with_restitution(0.8);

    let mut p = prepare(&contact, &bodies, DT, LIMIT).expect("valid contact");
    printed(p.velocity.x, -1.25, 1e-2);
    printed(p.desired_delta_velocity, 2.25, 1e-2);
    // Δq̇_t = 0.1 + 0.0201.
    printed(velocity_change_per_unit_impulse(&p), 0.1201, 1e-4);

    resolve_velocity(&mut p, &mut bodies);
    printed(p.impulse.x, 18.7337, 1e-4);
    printed_vec(bodies[1].linear_velocity, [2.165, 0.6234, 0.0], 1e-4);
    printed_vec(bodies[1].angular_velocity, [0.0, 0.0, 0.1715], 1e-4);
    assert_eq!(bodies[0], SolverBody::STATIC);
}

#[test]
fn example_3_nonlinear_projection_cube_and_sphere() {
    // Cube: side 12, mass 10, I = 240. Sphere: solid, r = 6, mass 100, I = 1440.
    let cube = body(Vec3::new(24.6392, 30.2575, 0.0), 10.0, 240.0);
    let sphere = body(Vec3::new(32.0, 20.0, 0.0), 100.0, 1440.0);
    let mut bodies = vec![SolverBody::STATIC, cube, sphere];
    let contact = Contact::new(
        1,
        2,
        Vec3::new(28.2268, 22.5668, 0.0),
        Vec3::new(-0.8268, 0.5625, 0.0),
        1.4365,
    );
    let settings = MillingtonSettings::default();
    let p = prepare(&contact, &bodies, DT, LIMIT).expect("valid contact");

    // The cube's angular inertia: (Δθ)₁ × q_rel = (−0.1391, −0.0649, 0). The lecture prints
    // (−0.1391, −0.6489, 0), a slip: −0.01809 · 3.5876 = −0.0649, and only −0.0649 gives the
    // 0.07852 it then uses. Checked through the total inertia 0.1 + 0.01 + 0.07852 = 0.1885.
    printed(velocity_change_per_unit_impulse(&p), 0.1885, 1e-4);

    let moves =
        nonlinear_moves(&p, &bodies, settings.angular_limit, settings.relaxation).expect("movable");
    // The angular limit does not trigger: 0.5983 < 0.2 · |r − (r·n)n| = 0.2 · 4.34.
    printed(moves.linear[0], 0.762, 1e-3);
    printed(moves.linear[1], -0.0762, 1e-4);
    // The lecture prints 0.5983 = 1.4365 · 0.07852 / 0.1885, from its rounded intermediates;
    // unrounded, (I_a)₁ = 0.078502 and I_t = 0.188502 give 0.59825, so the exact 0.5982 is used.
    printed(moves.angular[0], 0.5982, 1e-4);
    assert!(moves.angular[1].abs() < 1e-4, "no rotation for the sphere");
    printed_vec(moves.rotation[0], [0.0, 0.0, -0.1378], 1e-4);

    apply_moves(&p, &moves, &mut bodies);
    // p₁ + 0.762·d̂ = (22.6934, 31.5812, 0) in the lecture, which adds (−0.63, 0.4268): a slip
    // for 24.6392 − 0.63 = 24.0092. The exact move is 0.762·d̂ = (−0.6300, 0.4287, 0).
    printed_vec(bodies[1].position, [24.0092, 30.6862, 0.0], 1e-3);
    printed_vec(bodies[2].position, [32.063, 19.9571, 0.0], 1e-3);
    // Orientation [1, 0, 0, −0.0689] (w first) before normalisation: 7.88° about −z.
    let expected = Quat::from_xyzw(0.0, 0.0, -0.0689, 1.0).normalize();
    assert!(
        bodies[1].orientation.abs_diff_eq(expected, 1e-4),
        "{:?}",
        bodies[1].orientation
    );
    assert!(bodies[2].orientation.abs_diff_eq(Quat::IDENTITY, 1e-4));
}
