//! The Millington resolver's shock sweep (`MillingtonSettings::shock_sweep`): a load the
//! worst-first picks cannot pass on (a light box under one a million times heavier) reaches
//! the ground, and a lower body held still never gives an upper one energy.

use jostle_math::{Quat, Vec3};
use jostle_resolve::millington::{MillingtonResolver, MillingtonSettings};
use jostle_resolve::synthetic::{DT, GRAVITY, box_body};
use jostle_resolve::{Contact, Resolver, STATIC_BODY, SolverBody, StepContext};

/// A unit box of `light` kg on the ground under one of `heavy` kg, both at rest: the four
/// corners of each face as contact points, touching.
fn pair(light: f32, heavy: f32) -> (Vec<SolverBody>, Vec<Contact>) {
    let bodies = vec![
        SolverBody::STATIC,
        box_body(
            Vec3::new(0.0, 0.5, 0.0),
            Quat::IDENTITY,
            light,
            Vec3::splat(0.5),
        ),
        box_body(
            Vec3::new(0.0, 1.5, 0.0),
            Quat::IDENTITY,
            heavy,
            Vec3::splat(0.5),
        ),
    ];
    let mut contacts = Vec::new();
    for (a, b, y) in [(1, STATIC_BODY, 0.0), (2, 1, 1.0)] {
        for (x, z) in [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)] {
            let mut c = Contact::new(a, b, Vec3::new(x, y, z), Vec3::Y, 0.0);
            c.friction = 0.6;
            contacts.push(c);
        }
    }
    (bodies, contacts)
}

/// The vertical velocities of the light and the heavy box after one step from rest.
fn one_step(settings: MillingtonSettings, heavy: f32) -> (f32, f32) {
    let (mut bodies, mut contacts) = pair(1.0, heavy);
    let mut resolver = MillingtonResolver::new(settings);
    let ctx = StepContext {
        gravity: GRAVITY,
        dt: DT,
    };
    resolver.step(&mut bodies, &mut contacts, &ctx);
    (bodies[1].linear_velocity.y, bodies[2].linear_velocity.y)
}

#[test]
fn a_million_times_heavier_box_is_held_up_by_a_light_one_in_one_step() {
    let (light, heavy) = one_step(MillingtonSettings::default(), 1e6);
    assert!(heavy.abs() < 1e-3, "the heavy box moves at {heavy} m/s");
    assert!(light.abs() < 1e-3, "the light box moves at {light} m/s");
}

#[test]
fn without_the_sweep_the_picks_let_the_heavy_box_fall() {
    // What the sweep is for: the worst-first picks alone pass on about m/M of the load per
    // pick, so the heavy box keeps almost all of a step of gravity.
    let settings = MillingtonSettings {
        shock_sweep: false,
        ..Default::default()
    };
    let (_, heavy) = one_step(settings, 1e6);
    let g_dt = GRAVITY.length() * DT;
    assert!(heavy < -0.5 * g_dt, "the heavy box moves at {heavy} m/s");
}

#[test]
fn a_lower_body_held_still_gives_no_energy() {
    // A box on the ground moving up at 2 m/s into one 100 times heavier falling at 1 m/s,
    // with a single pick: the rest is left to the sweep, which may not throw the heavy box
    // upwards by the light one's speed (it would create energy), so it leaves that contact
    // alone.
    let settings = MillingtonSettings {
        velocity_iterations: jostle_resolve::millington::IterationBudget {
            fixed: 1,
            per_contact: 0,
        },
        ..Default::default()
    };
    let (mut bodies, mut contacts) = pair(1.0, 100.0);
    bodies[1].linear_velocity = Vec3::new(0.0, 2.0, 0.0);
    bodies[2].linear_velocity = Vec3::new(0.0, -1.0, 0.0);
    let energy = |b: &[SolverBody]| {
        b[1..]
            .iter()
            .map(|b| 0.5 * b.linear_velocity.length_squared() / b.inv_mass)
            .sum::<f32>()
    };
    let before = energy(&bodies);
    let mut resolver = MillingtonResolver::new(settings);
    resolver.resolve_contacts(&mut bodies, &mut contacts, DT);
    let after = energy(&bodies);
    assert!(after <= before * (1.0 + 1e-5), "{before} J -> {after} J");
}
