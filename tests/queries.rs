//! Scene queries through `World::queries`: rays (first and all hits), shape casts, point
//! projection and shape overlap, with filters; through the broad phase's tree after
//! `World::update_queries`, by brute force otherwise, with the same results either way.

use jostle::{
    BodyDesc, BodyHandle, Pose, Quat, QueryFilter, ShapeDesc, Vec3, World, WorldSettings,
};
mod common;

use common::SeededRng as Rng;

/// A ground and `n` mixed bodies dropped onto it in a loose pile, stepped `steps` times so
/// that some move, some rest and some sleep.
fn pile(n: usize, steps: usize, seed: u64) -> World {
    let mut rng = Rng::new(seed);
    let mut w = World::new(WorldSettings::default());
    w.add_body(BodyDesc::fixed(
        "ground",
        ShapeDesc::HalfSpace { normal: Vec3::Y },
    ))
    .unwrap();
    w.add_body(
        BodyDesc::fixed(
            "wall",
            ShapeDesc::Cuboid {
                half_extents: Vec3::new(0.2, 2.0, 6.0),
            },
        )
        .at(Vec3::new(6.0, 2.0, 0.0)),
    )
    .unwrap();
    for i in 0..n {
        let shape = match i % 4 {
            0 => ShapeDesc::Ball {
                radius: rng.uniform(0.1, 0.6),
            },
            1 => ShapeDesc::Cuboid {
                half_extents: Vec3::new(
                    rng.uniform(0.1, 0.6),
                    rng.uniform(0.1, 0.6),
                    rng.uniform(0.1, 0.6),
                ),
            },
            2 => ShapeDesc::Capsule {
                half_height: rng.uniform(0.1, 0.5),
                radius: rng.uniform(0.1, 0.4),
            },
            _ => ShapeDesc::Cylinder {
                half_height: rng.uniform(0.1, 0.5),
                radius: rng.uniform(0.1, 0.4),
            },
        };
        let at = Vec3::new(
            rng.uniform(-5.0, 5.0),
            rng.uniform(0.5, 8.0),
            rng.uniform(-5.0, 5.0),
        );
        let turn = Quat::from_rotation_y(rng.uniform(0.0, 6.0))
            * Quat::from_rotation_x(rng.uniform(0.0, 1.0));
        w.add_body(
            BodyDesc::dynamic(format!("b{i}"), shape)
                .at(at)
                .rotated(turn),
        )
        .unwrap();
    }
    for _ in 0..steps {
        w.step(1.0 / 60.0).unwrap();
    }
    w
}

/// Every query of `w` with a few filters, as a printable record (bit-exact floats).
fn all_answers(w: &World, rng: &mut Rng, player: BodyHandle) -> Vec<String> {
    let q = w.queries();
    let filters = [
        QueryFilter::default(),
        QueryFilter::excluding(player),
        QueryFilter {
            skip_fixed: true,
            ..QueryFilter::default()
        },
        QueryFilter {
            skip_dynamic: true,
            ..QueryFilter::default()
        },
    ];
    let ball = ShapeDesc::Ball { radius: 0.3 }.build().unwrap();
    let brick = ShapeDesc::Cuboid {
        half_extents: Vec3::new(0.4, 0.2, 0.3),
    }
    .build()
    .unwrap();
    let mut out = Vec::new();
    for k in 0..60 {
        let f = &filters[k % filters.len()];
        let origin = Vec3::new(
            rng.uniform(-7.0, 7.0),
            rng.uniform(-1.0, 9.0),
            rng.uniform(-7.0, 7.0),
        );
        let dir = Vec3::new(
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        );
        let reach = rng.uniform(0.0, 20.0);
        out.push(format!("ray {:?}", q.ray_cast(origin, dir, reach, f)));
        out.push(format!("all {:?}", q.ray_cast_all(origin, dir, reach, f)));
        out.push(format!("point {:?}", q.project_point(origin, reach, f)));
        let pose = Pose::from_parts(origin, Quat::from_rotation_z(rng.uniform(0.0, 3.0)));
        let shape = if k % 2 == 0 { &ball } else { &brick };
        out.push(format!("overlap {:?}", q.intersect_shape(shape, pose, f)));
        out.push(format!(
            "cast {:?}",
            q.cast_shape(shape, pose, dir, reach, f)
        ));
    }
    out
}

#[test]
fn the_tree_and_the_brute_force_give_the_same_answers() {
    // Early steps catch bodies in flight (a stale tree would miss them), late ones settled.
    for (seed, steps) in [(0, 25), (1, 50), (2, 90)] {
        let mut w = pile(150, steps, seed);
        let player = w.find_body("b0").unwrap();
        // A few bodies put elsewhere since the last step, as a game would: the tree's boxes
        // of the step's start no longer hold them.
        let mut rng = Rng::new(seed + 100);
        for i in (1..150).step_by(10) {
            let b = w.find_body(&format!("b{i}")).unwrap();
            let at = Vec3::new(
                rng.uniform(-7.0, 7.0),
                rng.uniform(0.0, 8.0),
                rng.uniform(-7.0, 7.0),
            );
            w.set_pose(b, at, Quat::from_rotation_y(rng.uniform(0.0, 6.0)))
                .unwrap();
        }
        // Stepped and changed since the tree was last updated: brute force.
        assert!(!w.queries_use_tree());
        let brute = all_answers(&w, &mut Rng::new(99), player);
        w.update_queries();
        assert!(w.queries_use_tree());
        let tree = all_answers(&w, &mut Rng::new(99), player);
        assert_eq!(brute.len(), tree.len());
        for (b, t) in brute.iter().zip(&tree) {
            assert_eq!(b, t, "seed {seed}");
        }
        // The queries found things: not a comparison of empty answers.
        for kind in ["ray Some", "point Some", "cast Some", "overlap [B"] {
            let found = tree.iter().filter(|a| a.starts_with(kind)).count();
            assert!(
                found >= 5,
                "seed {seed}: only {found} of 60 answers are {kind}"
            );
        }
    }
}

#[test]
fn a_body_moved_after_the_update_is_found_where_it_is() {
    let mut w = pile(40, 30, 7);
    w.update_queries();
    let b = w.find_body("b1").unwrap();
    // Far from everything, where the tree holds no box.
    w.set_pose(b, Vec3::new(40.0, 5.0, 0.0), Quat::IDENTITY)
        .unwrap();
    assert!(!w.queries_use_tree(), "a pose set makes the tree stale");
    let hit = w
        .queries()
        .ray_cast(
            Vec3::new(40.0, 20.0, 0.0),
            -Vec3::Y,
            30.0,
            &QueryFilter::default(),
        )
        .unwrap();
    assert_eq!(hit.body, b);
    w.update_queries();
    let again = w
        .queries()
        .ray_cast(
            Vec3::new(40.0, 20.0, 0.0),
            -Vec3::Y,
            30.0,
            &QueryFilter::default(),
        )
        .unwrap();
    assert_eq!(again, hit);
}

#[test]
fn updating_the_queries_changes_no_step() {
    let run = |update: bool| {
        let mut w = pile(120, 0, 3);
        for _ in 0..120 {
            w.step(1.0 / 60.0).unwrap();
            if update {
                w.update_queries();
            }
        }
        w.state_hash()
    };
    assert_eq!(run(false), run(true));
}

#[test]
fn each_query_answers_a_simple_scene() {
    let mut w = World::new(WorldSettings::default());
    let ground = w
        .add_body(BodyDesc::fixed(
            "ground",
            ShapeDesc::HalfSpace { normal: Vec3::Y },
        ))
        .unwrap();
    let cube = w
        .add_body(
            BodyDesc::dynamic(
                "cube",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.5),
                },
            )
            .at(Vec3::new(0.0, 0.5, 0.0)),
        )
        .unwrap();
    let ball = w
        .add_body(
            BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 }).at(Vec3::new(3.0, 0.5, 0.0)),
        )
        .unwrap();
    w.update_queries();
    let q = w.queries();
    let all = QueryFilter::default();

    // A ray along x at y 0.5 meets the cube's face, then the ball.
    let hits = q.ray_cast_all(Vec3::new(-5.0, 0.5, 0.0), Vec3::X, 20.0, &all);
    let bodies: Vec<_> = hits.iter().map(|h| h.body).collect();
    assert_eq!(bodies, vec![cube, ball]);
    assert!((hits[0].distance - 4.5).abs() < 1e-5 && (hits[1].distance - 7.5).abs() < 1e-5);
    assert!((hits[0].normal + Vec3::X).length() < 1e-5);
    // Excluding the cube, the first hit is the ball.
    let h = q
        .ray_cast(
            Vec3::new(-5.0, 0.5, 0.0),
            Vec3::X,
            20.0,
            &QueryFilter::excluding(cube),
        )
        .unwrap();
    assert_eq!(h.body, ball);
    // Straight down from above the ball, skipping what moves: the ground.
    let skip_dynamic = QueryFilter {
        skip_dynamic: true,
        ..all
    };
    let h = q
        .ray_cast(Vec3::new(3.0, 5.0, 0.0), -Vec3::Y, 20.0, &skip_dynamic)
        .unwrap();
    assert_eq!(h.body, ground);
    assert!((h.distance - 5.0).abs() < 1e-5);

    // A 0.25 m ball cast down from 4 m above the cube's top stops touching it.
    let probe = ShapeDesc::Ball { radius: 0.25 }.build().unwrap();
    let hit = q
        .cast_shape(
            &probe,
            Pose::from_translation(Vec3::new(0.0, 5.0, 0.0)),
            -Vec3::Y,
            10.0,
            &all,
        )
        .unwrap();
    assert_eq!(hit.body, cube);
    assert!((hit.distance - 3.75).abs() < 1e-3, "{hit:?}");
    assert!((hit.normal - Vec3::Y).length() < 1e-3, "{hit:?}");
    assert!((hit.point.y - 1.0).abs() < 1e-3, "{hit:?}");
    // Cast beside the cube and the ball it reaches the ground.
    let hit = q
        .cast_shape(
            &probe,
            Pose::from_translation(Vec3::new(-3.0, 5.0, 0.0)),
            -Vec3::Y,
            10.0,
            &all,
        )
        .unwrap();
    assert_eq!(hit.body, ground);
    assert!((hit.distance - 4.75).abs() < 1e-3, "{hit:?}");
    // Too short a cast reaches nothing.
    assert!(
        q.cast_shape(
            &probe,
            Pose::from_translation(Vec3::new(-3.0, 5.0, 0.0)),
            -Vec3::Y,
            4.0,
            &all
        )
        .is_none()
    );

    // The nearest surface to a point 2 m above the cube is its top face; inside it, itself.
    let p = q
        .project_point(Vec3::new(0.0, 3.0, 0.0), 10.0, &all)
        .unwrap();
    assert_eq!(p.body, cube);
    assert!((p.distance - 2.0).abs() < 1e-5 && !p.inside, "{p:?}");
    let p = q
        .project_point(Vec3::new(0.1, 0.5, 0.0), 10.0, &all)
        .unwrap();
    assert!(p.inside && p.distance == 0.0 && p.body == cube, "{p:?}");
    assert!(
        q.project_point(Vec3::new(0.0, 3.0, 0.0), 1.0, &all)
            .is_none()
    );

    // A box overlapping the cube and the ball, and the ground below them.
    let slab = ShapeDesc::Cuboid {
        half_extents: Vec3::new(2.0, 0.2, 0.2),
    }
    .build()
    .unwrap();
    let over = q.intersect_shape(
        &slab,
        Pose::from_translation(Vec3::new(1.5, 0.5, 0.0)),
        &all,
    );
    assert_eq!(over, vec![cube, ball]);
    let skip_fixed = QueryFilter {
        skip_fixed: true,
        ..all
    };
    let low = q.intersect_shape(
        &slab,
        Pose::from_translation(Vec3::new(1.5, 0.1, 0.0)),
        &skip_fixed,
    );
    assert_eq!(low, vec![cube, ball]);
    let low = q.intersect_shape(
        &slab,
        Pose::from_translation(Vec3::new(1.5, 0.1, 0.0)),
        &all,
    );
    assert_eq!(low, vec![ground, cube, ball]);

    // Bad input is no hit, not a panic.
    assert!(q.ray_cast(Vec3::ZERO, Vec3::ZERO, 1.0, &all).is_none());
    assert!(q.ray_cast(Vec3::NAN, Vec3::X, 1.0, &all).is_none());
    assert!(q.ray_cast_all(Vec3::ZERO, Vec3::X, -1.0, &all).is_empty());
    assert!(q.project_point(Vec3::NAN, 1.0, &all).is_none());
    assert!(
        q.cast_shape(
            &probe,
            Pose::from_translation(Vec3::ZERO),
            Vec3::ZERO,
            1.0,
            &all
        )
        .is_none()
    );
}
