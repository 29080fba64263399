//! A resolver on its own, without the world: the `jostle-resolve` layer takes solver bodies
//! and contacts and returns corrected velocities and poses, so it can be driven (and timed)
//! with contacts from anywhere. Here a 1 m box rests on the static entry (index 0) on its four
//! bottom corners, and each resolver holds it up for two seconds.
//!
//! Run: `cargo run --release --example resolver_alone`

use jostle::layers::resolve::{Contact, STATIC_BODY, SolverBody, StepContext};
use jostle::{
    Mat3, MillingtonResolver, MillingtonSettings, Quat, Resolver, SoftStepResolver,
    SoftStepSettings, Vec3,
};

/// The box's four bottom corners as contacts with the ground below it (y = 0), overlap
/// included: the narrow phase's part, written out by hand.
fn corner_contacts(bodies: &[SolverBody], previous: &[Contact]) -> Vec<Contact> {
    let b = &bodies[1];
    [(-0.5, -0.5), (-0.5, 0.5), (0.5, -0.5), (0.5, 0.5)]
        .iter()
        .enumerate()
        .filter_map(|(k, &(x, z))| {
            let corner = b.position + b.orientation * Vec3::new(x, -0.5, z);
            let depth = -corner.y;
            (depth > -0.01).then(|| {
                let mut c = Contact::new(1, STATIC_BODY, corner, Vec3::Y, depth).with_friction(0.5);
                // Warm start: the narrow phase carries each point's impulse to the next step.
                c.impulse = previous.get(k).map_or(Vec3::ZERO, |p| p.impulse);
                c
            })
        })
        .collect()
}

fn run(resolver: &mut dyn Resolver) {
    // A 1 m cube of 1,000 kg: I = m·s²/6 about every axis.
    let (mass, inertia) = (1000.0f32, 1000.0f32 / 6.0);
    let cube = SolverBody::new(
        Vec3::new(0.0, 0.5, 0.0),
        Quat::IDENTITY,
        1.0 / mass,
        Mat3::from_diagonal(Vec3::splat(1.0 / inertia)),
    );
    let mut bodies = vec![SolverBody::STATIC, cube];
    let ctx = StepContext {
        gravity: Vec3::new(0.0, -9.81, 0.0),
        dt: 1.0 / 60.0,
    };
    let mut contacts = Vec::new();
    let mut time = std::time::Duration::ZERO;
    for _ in 0..120 {
        contacts = corner_contacts(&bodies, &contacts);
        let stats = resolver.step(&mut bodies, &mut contacts, &ctx);
        time +=
            stats.integrate_time + stats.prepare_time + stats.position_time + stats.velocity_time;
    }
    let b = &bodies[1];
    println!(
        "{:10}: after 2 s the box's centre is at y = {:.5} m (overlap {:.2} mm), speed {:.2e} m/s, resolver time {:.1} µs/step",
        resolver.name(),
        b.position.y,
        (0.5 - b.position.y) * 1e3,
        b.linear_velocity.length(),
        time.as_secs_f64() * 1e6 / 120.0
    );
}

fn main() {
    run(&mut SoftStepResolver::new(SoftStepSettings::default()));
    run(&mut MillingtonResolver::new(MillingtonSettings::default()));
}

#[test]
fn runs() {
    main();
}
