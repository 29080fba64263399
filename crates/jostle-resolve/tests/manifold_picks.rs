//! Picks by manifold ([`MillingtonSettings::manifold_picks`]): one pick resolves the normal
//! velocities of all the points a face or an edge touches with, keeps every point's total a
//! push, and leaves to a pick of the point alone what the block cannot resolve.

use jostle_math::{Quat, Vec3};
use jostle_resolve::millington::{
    MillingtonSettings, PreparedContact, prepare, resolve_manifold_normals,
    share_manifold_friction, update_velocity,
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

/// [`face_down`] with μ = 0.5 and the given normal impulses (N·s) at its four corners, in their
/// order: (−½, −½), (½, −½), (½, ½), (−½, ½).
fn loaded_face(v: Vec3, loads: [f32; 4]) -> (Vec<SolverBody>, Vec<PreparedContact>) {
    let (bodies, mut points) = face_down(v, Vec3::ZERO);
    for (p, load) in points.iter_mut().zip(loads) {
        p.friction = 0.5;
        p.impulse = Vec3::new(load, 0.0, 0.0);
    }
    (bodies, points)
}

/// A point's friction impulse in world space.
fn world_friction(p: &PreparedContact) -> Vec3 {
    p.basis * Vec3::new(0.0, p.impulse.y, p.impulse.z)
}

#[test]
fn friction_that_cancels_across_a_face_is_shared_by_load_without_moving_anything() {
    // The pattern corner picks leave (issue 17 item 5): every corner on its cone, the loaded
    // pair and the light pair pushing against each other across the push (±0.9 and ±0.4 N·s
    // along z), 3 of the 4 N·s the cones allow acting along x. The body is at rest.
    let (mut bodies, mut points) = loaded_face(Vec3::ZERO, [1.0, 3.0, 3.0, 1.0]);
    let friction = [
        Vec3::new(0.3, 0.0, 0.4),
        Vec3::new(1.2, 0.0, 0.9),
        Vec3::new(1.2, 0.0, -0.9),
        Vec3::new(0.3, 0.0, -0.4),
    ];
    for (p, t) in points.iter_mut().zip(friction) {
        let local = p.basis.transpose() * t;
        p.impulse.y = local.y;
        p.impulse.z = local.z;
        p.friction_saturated = true;
    }
    let before = bodies[1];
    // (An epsilon of 0: the body is at rest, and the sharing alone is what is tested.)
    let change = share_manifold_friction(&mut points, &mut bodies, 0.0).expect("shared");
    let total: Vec3 = points.iter().map(world_friction).sum();
    assert!(
        (total - Vec3::new(3.0, 0.0, 0.0)).length() < 1e-5,
        "{total}"
    );
    for p in &points {
        let ratio = world_friction(p).length() / p.impulse.x;
        assert!((ratio - 0.375).abs() < 1e-5, "{ratio}");
        assert!(world_friction(p).z.abs() < 1e-5, "{}", world_friction(p));
        // Left as it was: a point reopens when its neighbours' picks change its sliding.
        assert!(p.friction_saturated);
    }
    // Moved between the corners only: the body's motion is unchanged.
    for d in change.linear.iter().chain(&change.angular) {
        assert!(d.length() < 1e-6, "{change:?}");
    }
    assert!((bodies[1].linear_velocity - before.linear_velocity).length() < 1e-6);
    assert!((bodies[1].angular_velocity - before.angular_velocity).length() < 1e-6);
}

#[test]
fn a_face_that_can_hold_stops_its_centre_of_load_sliding() {
    // Sliding at 5 cm/s with no friction yet: the shared friction stops the centre of load
    // within the cones (needed: about 0.1 N·s of the 4 N·s they allow).
    let (mut bodies, mut points) = loaded_face(Vec3::new(0.05, 0.0, 0.0), [1.0, 3.0, 3.0, 1.0]);
    share_manifold_friction(&mut points, &mut bodies, 1e-4).expect("shared");
    let b = &bodies[1];
    // The centre of load, from the body's centre: x = (−½ + 3·½ + 3·½ − ½)/8, on the floor.
    let r = Vec3::new(0.25, -0.5, 0.0);
    let v = b.linear_velocity + b.angular_velocity.cross(r);
    assert!(
        v.x.hypot(v.z) < 1e-5,
        "the centre of load still slides at {v}"
    );
    for p in &points {
        assert!(
            world_friction(p).length() <= 0.5 * p.impulse.x,
            "outside its cone"
        );
        assert!(!p.friction_saturated);
    }
    // Sliding at 10 m/s the cones cannot stop it: as much as fits, the points saturated.
    let (mut bodies, mut points) = loaded_face(Vec3::new(10.0, 0.0, 0.0), [1.0, 3.0, 3.0, 1.0]);
    share_manifold_friction(&mut points, &mut bodies, 1e-4).expect("shared");
    let total: Vec3 = points.iter().map(world_friction).sum();
    assert!(
        total.x < -0.99 * 0.5 * 8.0 && total.x >= -0.5 * 8.0,
        "{total}"
    );
    assert!(points.iter().all(|p| p.friction_saturated));
    // 2 kg: the friction's 4 N·s take 2 m/s off, no more.
    let v = bodies[1].linear_velocity.x;
    assert!((v - (10.0 + total.x / 2.0)).abs() < 1e-4 && v > 7.99, "{v}");
}
