//! Picks by manifold ([`MillingtonSettings::manifold_picks`]): one pick resolves the normal
//! velocities of all the points a face or an edge touches with, keeps every point's total a
//! push, and leaves to a pick of the point alone what the block cannot resolve.

use jostle_math::{Quat, Vec3};
use jostle_resolve::millington::{
    MillingtonSettings, PreparedContact, prepare, resolve_manifold_normals, update_velocity,
};
use jostle_resolve::synthetic::{DT, box_body};
use jostle_resolve::{Contact, STATIC_BODY, SolverBody};

/// A unit box of 2 kg just touching the floor face down, moving at `v` and turning at `w`,
/// and its four corner contacts, prepared.
fn face_down(v: Vec3, w: Vec3) -> (Vec<SolverBody>, Vec<PreparedContact>) {
    let mut bodies = vec![
        SolverBody::STATIC,
        box_body(
            Vec3::new(0.0, 0.5, 0.0),
            Quat::IDENTITY,
            2.0,
            Vec3::splat(0.5),
        ),
    ];
    bodies[1].linear_velocity = v;
    bodies[1].angular_velocity = w;
    let contacts: Vec<_> = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
        .iter()
        .map(|&(x, z)| Contact::new(1, STATIC_BODY, Vec3::new(x, 0.0, z), Vec3::Y, 0.0))
        .collect();
    let prepared = contacts
        .iter()
        .map(|c| prepare(c, &bodies, DT, 0.25).expect("a valid contact"))
        .collect();
    (bodies, prepared)
}

#[test]
fn one_pick_stops_a_face_landing_while_it_turns() {
    // Closing at 1 m/s and turning: the corners close at 0.7 to 1.3 m/s, each wanting its own
    // change; picked one at a time, each corner's push turns the box onto the others.
    let (mut bodies, mut points) = face_down(Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.3, 0.0, 0.3));
    let wanted: Vec<f32> = points.iter().map(|p| p.desired_delta_velocity).collect();
    assert!(wanted.iter().all(|&d| d > 0.5), "{wanted:?}");
    let spread =
        wanted.iter().fold(0.0f32, |m, &d| m.max(d)) - wanted.iter().fold(9.0f32, |m, &d| m.min(d));
    assert!(
        spread > 0.4,
        "the corners want different changes: {wanted:?}"
    );
    let change = resolve_manifold_normals(&mut points, 2, &mut bodies).expect("a block pick");
    for p in &mut points {
        update_velocity(p, &change, 0.25);
    }
    for p in &points {
        assert!(
            p.desired_delta_velocity.abs() < 1e-4,
            "{}",
            p.desired_delta_velocity
        );
        assert!(p.impulse.x >= 0.0);
    }
    // No target asks for a bounce: the box ends at rest along the normal, and not turning about
    // a horizontal axis.
    let b = &bodies[1];
    assert!(b.linear_velocity.y.abs() < 1e-4, "{}", b.linear_velocity);
    assert!(
        b.angular_velocity.x.abs() < 1e-4 && b.angular_velocity.z.abs() < 1e-4,
        "{}",
        b.angular_velocity
    );
}

#[test]
fn a_point_whose_total_would_pull_takes_nothing_and_the_others_are_resolved() {
    // Two corners carry a push from earlier picks and now separate fast (they want to give
    // back more than they pushed); the other two close. Solved freely the separating ones
    // would pull: they are set to zero and the closing ones resolved without them.
    let (mut bodies, mut points) = face_down(Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0));
    for p in &mut points {
        p.impulse.x = 0.05;
    }
    let pulls: Vec<usize> = (0..4)
        .filter(|&i| points[i].desired_delta_velocity < -0.5)
        .collect();
    let pushes: Vec<usize> = (0..4)
        .filter(|&i| points[i].desired_delta_velocity > 0.5)
        .collect();
    assert_eq!((pulls.len(), pushes.len()), (2, 2), "{points:?}");
    let change =
        resolve_manifold_normals(&mut points, pushes[0], &mut bodies).expect("a block pick");
    for p in &mut points {
        update_velocity(p, &change, 0.25);
    }
    for &i in &pulls {
        assert_eq!(
            points[i].impulse.x, 0.0,
            "it gave back all it had pushed, no more"
        );
        assert!(
            points[i].desired_delta_velocity < 0.0,
            "and still separates"
        );
    }
    for &i in &pushes {
        assert!(points[i].impulse.x > 0.05);
        assert!(
            points[i].desired_delta_velocity.abs() < 1e-4,
            "{}",
            points[i].desired_delta_velocity
        );
    }
}

#[test]
fn a_manifold_with_one_point_to_resolve_is_left_to_a_single_pick() {
    // Only one corner closes (the box turning about the edge through two others, the fourth
    // separating with nothing pushed): no block to solve.
    let (mut bodies, mut points) = face_down(Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0));
    let closing: Vec<usize> = (0..4)
        .filter(|&i| points[i].desired_delta_velocity > 0.0)
        .collect();
    assert_eq!(
        closing,
        [0, 3],
        "turning about z, the two corners at x = −0.5 close"
    );
    points[3].desired_delta_velocity = -1.0;
    let before = bodies.clone();
    assert!(resolve_manifold_normals(&mut points, 0, &mut bodies).is_none());
    assert_eq!(bodies[1].linear_velocity, before[1].linear_velocity);
}

#[test]
fn picks_by_manifold_are_on_by_default() {
    assert!(MillingtonSettings::default().manifold_picks);
}
