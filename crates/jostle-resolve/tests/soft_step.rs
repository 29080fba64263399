//! The soft-step resolver alone, on hand-made contact sets.

use jostle_math::{Quat, Vec3};
use jostle_resolve::synthetic::{box_body, box_plane_contacts};
use jostle_resolve::{
    Contact, Resolver, SoftStepResolver, SoftStepSettings, SolverBody, StepContext,
};

/// A 0.5 m box sliding at 5 m/s on the ground (μ 0.3, four corner contacts, re-generated and
/// warm started every step) decelerates at μ·g, for any substep count. Fails on a friction
/// clamp that keeps the stop-dead impulse's direction: the coupled 2×2 solve turns it away
/// from the sliding velocity at the corners, and the box decelerated at 0.936·μ·g.
#[test]
fn a_sliding_box_decelerates_at_mu_g() {
    let half = Vec3::splat(0.25);
    let (mu, g, dt) = (0.3, 9.81, 1.0 / 60.0);
    for substeps in [1, 4] {
        let mut bodies = vec![
            SolverBody::STATIC,
            box_body(Vec3::new(0.0, 0.25, 0.0), Quat::IDENTITY, 1.0, half),
        ];
        bodies[1].linear_velocity = Vec3::new(5.0, 0.0, 0.0);
        let settings = SoftStepSettings {
            substeps,
            ..Default::default()
        };
        let mut resolver = SoftStepResolver::new(settings);
        let ctx = StepContext {
            gravity: Vec3::new(0.0, -g, 0.0),
            dt,
        };
        let mut previous: Vec<Contact> = Vec::new();
        let steps = 30;
        let mut v_after_first = 0.0;
        for step in 0..steps {
            let mut contacts = Vec::new();
            let b = &bodies[1];
            box_plane_contacts(
                1,
                b.position,
                b.orientation,
                half,
                Vec3::Y,
                0.0,
                &mut contacts,
            );
            for (c, p) in contacts.iter_mut().zip(&previous) {
                c.impulse = p.impulse;
            }
            for c in &mut contacts {
                c.friction = mu;
            }
            resolver.step(&mut bodies, &mut contacts, &ctx);
            previous = contacts;
            if step == 0 {
                v_after_first = bodies[1].linear_velocity.x;
            }
        }
        let v = bodies[1].linear_velocity;
        let decel = (v_after_first - v.x) / ((steps - 1) as f32 * dt);
        let expected = mu * g;
        assert!(
            (decel - expected).abs() < 0.005 * expected,
            "{substeps} substeps: deceleration {decel} m/s², expected μg = {expected}"
        );
        // The old clamp also pushed the box sideways, by 3 mm/s per step.
        assert!(v.z.abs() < 1e-3, "{substeps} substeps: sideways drift {v}");
    }
}
