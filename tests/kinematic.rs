//! Kinematic bodies (issue 19 item 3), with both resolvers: moved by their velocity or sent
//! to a pose, they carry and push dynamic bodies, nothing pushes them, gravity does not act on
//! them, and a body's type changes at run time.

mod common;

use jostle::snapshot::Snapshot;
use jostle::{
    BodyDesc, BodyType, CollisionEvent, Quat, ResolverChoice, ShapeDesc, Vec3, World, WorldSettings,
};

const DT: f32 = 1.0 / 60.0;

fn world(resolver: ResolverChoice) -> World {
    World::new(WorldSettings {
        resolver,
        ..Default::default()
    })
}

fn boxed(name: &str, half: Vec3, at: Vec3) -> BodyDesc {
    BodyDesc::dynamic(name, ShapeDesc::Cuboid { half_extents: half })
        .at(at)
        .with_density(1000.0)
}

fn kinematic(
    world: &mut World,
    name: &str,
    half: Vec3,
    at: Vec3,
    kind: BodyType,
) -> jostle::BodyHandle {
    let h = world.add_body(boxed(name, half, at)).unwrap();
    world.set_body_type(h, kind).unwrap();
    h
}

fn steps(world: &mut World, n: usize) {
    for _ in 0..n {
        world.step(DT).unwrap();
    }
}

/// A platform moving at 1 m/s carries the box resting on it by friction; it moves exactly as
/// its velocity says, and stays at its height without gravity acting on it.
#[test]
fn a_moving_platform_carries_a_box() {
    for resolver in common::resolvers() {
        let name = resolver.name();
        let mut w = world(resolver);
        let platform = kinematic(
            &mut w,
            "platform",
            Vec3::new(3.0, 0.25, 3.0),
            Vec3::new(0.0, 1.0, 0.0),
            BodyType::KinematicVelocity,
        );
        let cargo = w
            .add_body(
                boxed("cargo", Vec3::splat(0.25), Vec3::new(0.0, 1.5, 0.0)).with_material(0.8, 0.0),
            )
            .unwrap();
        steps(&mut w, 60);
        w.set_velocity(platform, Vec3::new(1.0, 0.0, 0.0), Vec3::ZERO)
            .unwrap();
        steps(&mut w, 120);
        let p = w.body(platform).unwrap();
        assert!(
            (p.position - Vec3::new(2.0, 1.0, 0.0)).length() < 1e-4,
            "{name}: the platform moved by its velocity alone: {}",
            p.position
        );
        assert_eq!(
            p.linear_velocity,
            Vec3::new(1.0, 0.0, 0.0),
            "{name}: nothing slowed it"
        );
        // The platform starts at once; the cargo slides until friction (μ = sqrt(0.8·0.5),
        // the materials' geometric mean) has brought it to 1 m/s: v²/(2μg) behind.
        let lag = 1.0 / (2.0 * (0.8f32 * 0.5).sqrt() * 9.81);
        let c = w.body(cargo).unwrap();
        assert!(
            (c.position.x - (2.0 - lag)).abs() < 0.02 && (c.position.y - 1.5).abs() < 0.01,
            "{name}: the cargo rode along, {lag} m behind: {}",
            c.position
        );
        assert!(
            (c.linear_velocity.x - 1.0).abs() < 0.01,
            "{name}: {}",
            c.linear_velocity
        );
    }
}

/// A kinematic pusher at 2 m/s pushes a heavy box across frictionless ground and keeps its
/// speed; a heavy box thrown at a resting kinematic wall does not move it.
#[test]
fn kinematic_bodies_push_and_nothing_pushes_them() {
    for resolver in common::resolvers() {
        let name = resolver.name();
        let mut w = world(resolver);
        w.add_body(
            BodyDesc::fixed("ground", ShapeDesc::HalfSpace { normal: Vec3::Y })
                .with_material(0.0, 0.0),
        )
        .unwrap();
        let pusher = kinematic(
            &mut w,
            "pusher",
            Vec3::new(0.5, 0.5, 1.0),
            Vec3::new(-2.0, 0.5, 0.0),
            BodyType::KinematicVelocity,
        );
        w.set_velocity(pusher, Vec3::new(2.0, 0.0, 0.0), Vec3::ZERO)
            .unwrap();
        let crate_ = w
            .add_body(
                boxed("crate", Vec3::splat(0.5), Vec3::new(0.5, 0.5, 0.0))
                    .with_density(10_000.0)
                    .with_material(0.0, 0.0),
            )
            .unwrap();
        steps(&mut w, 120);
        let p = w.body(pusher).unwrap();
        assert!(
            (p.position.x - 2.0).abs() < 1e-4,
            "{name}: pusher at {}",
            p.position
        );
        let c = w.body(crate_).unwrap();
        assert!(
            c.position.x > p.position.x + 0.95,
            "{name}: the crate is ahead of the pusher: {} vs {}",
            c.position.x,
            p.position.x
        );

        let wall = kinematic(
            &mut w,
            "wall",
            Vec3::new(0.2, 2.0, 2.0),
            Vec3::new(20.0, 2.0, 0.0),
            BodyType::KinematicVelocity,
        );
        let ram = w
            .add_body(
                boxed("ram", Vec3::splat(0.5), Vec3::new(17.0, 0.5, 0.0))
                    .with_density(100_000.0)
                    .moving(Vec3::new(8.0, 0.0, 0.0), Vec3::ZERO),
            )
            .unwrap();
        steps(&mut w, 60);
        let wall_now = w.body(wall).unwrap();
        assert_eq!(
            wall_now.position,
            Vec3::new(20.0, 2.0, 0.0),
            "{name}: the wall held"
        );
        assert!(
            w.body(ram).unwrap().position.x < 19.5,
            "{name}: the ram stopped at the wall"
        );
    }
}

/// A position-based lift sent up 1 cm per step reaches each pose exactly and lifts its load.
#[test]
fn a_position_based_lift_reaches_each_pose_and_lifts_its_load() {
    for resolver in common::resolvers() {
        let name = resolver.name();
        let mut w = world(resolver);
        let lift = kinematic(
            &mut w,
            "lift",
            Vec3::new(1.0, 0.1, 1.0),
            Vec3::new(0.0, 0.1, 0.0),
            BodyType::KinematicPosition,
        );
        let load = w
            .add_body(boxed("load", Vec3::splat(0.3), Vec3::new(0.0, 0.5, 0.0)))
            .unwrap();
        steps(&mut w, 60);
        assert_eq!(
            w.body(lift).unwrap().position.y,
            0.1,
            "{name}: it stays without a pose"
        );
        for k in 1..=120 {
            let y = 0.1 + 0.01 * k as f32;
            let turn = Quat::from_rotation_y(0.005 * k as f32);
            w.set_next_pose(lift, Vec3::new(0.0, y, 0.0), turn).unwrap();
            w.step(DT).unwrap();
            let b = w.body(lift).unwrap();
            assert_eq!(b.position, Vec3::new(0.0, y, 0.0), "{name}: step {k}");
            assert!(b.orientation.dot(turn).abs() > 1.0 - 1e-6);
        }
        let rest = w.body(load).unwrap().position.y;
        assert!(
            (rest - (1.3 + 0.1 + 0.3)).abs() < 0.01,
            "{name}: load at {rest}"
        );
        assert!(w.set_next_pose(load, Vec3::ZERO, Quat::IDENTITY).is_err());
    }
}

/// Dynamic to kinematic mid-fall: it keeps its velocity and stops accelerating; back to
/// dynamic: it falls again with the mass it had.
#[test]
fn the_type_changes_at_run_time() {
    for resolver in common::resolvers() {
        let name = resolver.name();
        let mut w = world(resolver);
        let b = w
            .add_body(boxed("b", Vec3::splat(0.5), Vec3::new(0.0, 100.0, 0.0)))
            .unwrap();
        steps(&mut w, 30);
        let v = w.body(b).unwrap().linear_velocity;
        w.set_body_type(b, BodyType::KinematicVelocity).unwrap();
        steps(&mut w, 30);
        assert_eq!(
            w.body(b).unwrap().linear_velocity,
            v,
            "{name}: no gravity on it"
        );
        w.apply_force(b, Vec3::new(1e6, 0.0, 0.0)).unwrap();
        steps(&mut w, 1);
        assert_eq!(
            w.body(b).unwrap().linear_velocity,
            v,
            "{name}: no force either"
        );
        w.set_body_type(b, BodyType::Dynamic).unwrap();
        assert!((w.body(b).unwrap().mass() - 1000.0).abs() < 0.01);
        steps(&mut w, 30);
        assert!(
            w.body(b).unwrap().linear_velocity.y < v.y - 4.0,
            "{name}: falls again"
        );
    }
}

/// A box resting on a still platform falls asleep; the platform starting to move wakes it.
/// A kinematic body overlapping the ground makes no contact and no event.
#[test]
fn a_still_platform_lets_its_load_sleep_and_a_moving_one_wakes_it() {
    let mut w = world(ResolverChoice::default());
    let ground = w
        .add_body(BodyDesc::fixed(
            "ground",
            ShapeDesc::HalfSpace { normal: Vec3::Y },
        ))
        .unwrap();
    let platform = kinematic(
        &mut w,
        "platform",
        Vec3::new(2.0, 0.25, 2.0),
        Vec3::new(0.0, 0.0, 0.0),
        BodyType::KinematicVelocity,
    );
    let load = w
        .add_body(boxed("load", Vec3::splat(0.25), Vec3::new(0.0, 0.5, 0.0)))
        .unwrap();
    let mut slept = false;
    for _ in 0..300 {
        w.step(DT).unwrap();
        slept |= !w.body(load).unwrap().sleep.awake;
        let touches_ground = w.events().iter().any(|e| match *e {
            CollisionEvent::Started(a, b) | CollisionEvent::Stopped(a, b) => {
                (a, b) == (ground, platform) || (a, b) == (platform, ground)
            }
        });
        assert!(!touches_ground);
    }
    assert!(slept, "the load sleeps on a still platform");
    w.set_velocity(platform, Vec3::new(0.0, 0.5, 0.0), Vec3::ZERO)
        .unwrap();
    steps(&mut w, 2);
    assert!(w.body(load).unwrap().sleep.awake, "and wakes when it moves");
    steps(&mut w, 60);
    assert!(
        w.body(load).unwrap().position.y > 0.9,
        "{}",
        w.body(load).unwrap().position.y
    );
}

#[test]
fn kinematic_bodies_round_trip_through_snapshots() {
    let mut w = world(ResolverChoice::default());
    let platform = kinematic(
        &mut w,
        "platform",
        Vec3::new(2.0, 0.25, 2.0),
        Vec3::ZERO,
        BodyType::KinematicVelocity,
    );
    w.set_velocity(platform, Vec3::new(0.3, 0.0, 0.0), Vec3::new(0.0, 0.2, 0.0))
        .unwrap();
    let lift = kinematic(
        &mut w,
        "lift",
        Vec3::splat(0.5),
        Vec3::new(6.0, 0.0, 0.0),
        BodyType::KinematicPosition,
    );
    w.add_body(boxed("load", Vec3::splat(0.25), Vec3::new(0.0, 0.5, 0.0)))
        .unwrap();
    steps(&mut w, 20);
    w.set_next_pose(lift, Vec3::new(6.0, 0.5, 0.0), Quat::IDENTITY)
        .unwrap();
    let text = w.snapshot("kinematic", DT).to_ron().unwrap();
    let mut restored = World::from_snapshot(Snapshot::parse(&text, "kinematic").unwrap()).unwrap();
    for _ in 0..60 {
        w.step(DT).unwrap();
        restored.step(DT).unwrap();
    }
    assert_eq!(restored.state_hash(), w.state_hash());
    assert_eq!(
        restored.body(lift).unwrap().position,
        Vec3::new(6.0, 0.5, 0.0)
    );
}

/// `assets/paddle.ron`: a paddle turning about a vertical axis (scene field `kinematic:
/// Turn(...)`) is where its path says at every step, reaches the tower after a quarter turn
/// and knocks it down; a pusher sliding back and forth (`Line(...)`) pushes a crate 3 m along
/// and leaves it there.
#[test]
fn the_paddle_scene_follows_its_paths_and_knocks_the_tower_down() {
    let scene =
        jostle::scene::Scene::load(format!("{}/assets/paddle.ron", env!("CARGO_MANIFEST_DIR")))
            .unwrap();
    let mut w = scene.build().unwrap();
    let find = |w: &World, name: &str| w.find_body(name).unwrap();
    let (paddle, pusher, crate_) = (find(&w, "paddle"), find(&w, "pusher"), find(&w, "crate"));
    let tower: Vec<_> = w
        .bodies()
        .filter(|(_, name, _)| name.starts_with("tower"))
        .map(|(h, _, b)| (h, b.position))
        .collect();
    assert_eq!(tower.len(), 36);
    let moved = |w: &World| {
        tower
            .iter()
            .filter(|(h, start)| (w.body(*h).unwrap().position - *start).length() > 0.5)
            .count()
    };
    for step in 1..=360 {
        w.step(scene.dt).unwrap();
        let t = step as f32 * scene.dt;
        let angle = std::f32::consts::TAU * t / 8.0;
        let expected = Vec3::new(3.0 * angle.sin(), 0.6, 3.0 * angle.cos());
        let p = w.body(paddle).unwrap();
        assert!(
            (p.position - expected).length() < 1e-3,
            "step {step}: paddle at {} instead of {expected}",
            p.position
        );
        assert!(p.is_kinematic());
        if step == 60 {
            assert_eq!(moved(&w), 0, "the paddle has not reached the tower at 1 s");
        }
        if step == 120 {
            // The pusher's far end: 3 m on; the crate ahead of its face.
            let x = w.body(pusher).unwrap().position.x;
            assert!((x + 3.0).abs() < 1e-3, "pusher at x = {x}");
            let c = w.body(crate_).unwrap().position.x;
            assert!((c + 2.5).abs() < 0.02, "crate at x = {c}");
        }
    }
    assert!(
        moved(&w) >= 30,
        "{} of 36 tower boxes knocked over",
        moved(&w)
    );
}

/// `World::set_path` checks the path, makes the body position-based kinematic, and the path
/// survives a snapshot: the restored world goes on exactly like the original.
#[test]
fn paths_are_checked_made_kinematic_and_kept_in_snapshots() {
    use jostle::{KinematicPath, StepError};
    let mut w = world(ResolverChoice::default());
    let arm = w
        .add_body(boxed(
            "arm",
            Vec3::new(1.0, 0.1, 0.1),
            Vec3::new(2.0, 0.5, 0.0),
        ))
        .unwrap();
    w.add_body(boxed("box", Vec3::splat(0.25), Vec3::new(0.0, 0.25, 2.0)))
        .unwrap();
    let turn = KinematicPath::Turn {
        start: Vec3::new(2.0, 0.5, 0.0),
        rotation: Quat::IDENTITY,
        center: Vec3::new(0.0, 0.5, 0.0),
        axis: Vec3::ZERO,
        period: 4.0,
    };
    let field = |e: StepError| match e {
        StepError::Invalid { field, .. } => field,
        other => panic!("expected an invalid field, got {other:?}"),
    };
    assert_eq!(field(w.set_path(arm, Some(turn)).unwrap_err()), "path.axis");
    let line = KinematicPath::Line {
        start: Vec3::new(2.0, 0.5, 0.0),
        rotation: Quat::IDENTITY,
        offset: Vec3::X,
        period: -1.0,
    };
    assert_eq!(
        field(w.set_path(arm, Some(line)).unwrap_err()),
        "path.period"
    );
    assert_eq!(w.body(arm).unwrap().body_type(), BodyType::Dynamic);
    let turn = KinematicPath::Turn {
        start: Vec3::new(2.0, 0.5, 0.0),
        rotation: Quat::IDENTITY,
        center: Vec3::new(0.0, 0.5, 0.0),
        axis: Vec3::Y,
        period: 4.0,
    };
    w.set_path(arm, Some(turn)).unwrap();
    assert_eq!(
        w.body(arm).unwrap().body_type(),
        BodyType::KinematicPosition
    );
    steps(&mut w, 30);
    let text = w.snapshot("path", DT).to_ron().unwrap();
    let mut restored = World::from_snapshot(Snapshot::parse(&text, "path").unwrap()).unwrap();
    for _ in 0..90 {
        w.step(DT).unwrap();
        restored.step(DT).unwrap();
    }
    assert_eq!(restored.state_hash(), w.state_hash());
    // Two seconds: half a turn, from +x to −x.
    let p = restored.body(arm).unwrap().position;
    assert!((p - Vec3::new(-2.0, 0.5, 0.0)).length() < 1e-3, "{p}");
    // Taken away, the arm stops where it is.
    w.set_path(arm, None).unwrap();
    steps(&mut w, 10);
    assert!((w.body(arm).unwrap().position - p).length() < 1e-6);
}

/// A scene's `kinematic` field is checked like the others: the error names the body and the
/// field.
#[test]
fn scene_kinematic_fields_are_checked() {
    let bad = [
        (
            "kinematic: Line(offset: (1.0, 0.0, 0.0), period: 0.0)",
            "kinematic.period",
        ),
        (
            "kinematic: Turn(center: (0.0, 0.0, 0.0), axis: (0.0, 0.0, 0.0), period: 2.0)",
            "kinematic.axis",
        ),
        ("fixed: true, kinematic: Velocity", "kinematic"),
    ];
    for (field, named) in bad {
        let text = format!("Scene(bodies: [Body(name: \"k\", shape: Ball(radius: 0.5), {field})])");
        let e = jostle::scene::Scene::parse(&text, "k.ron")
            .unwrap_err()
            .to_string();
        assert!(e.contains(named) && e.contains("\"k\""), "{field}: {e}");
    }
    let good = "Scene(bodies: [Body(name: \"k\", shape: Ball(radius: 0.5), \
                linear_velocity: (1.0, 0.0, 0.0), kinematic: Velocity)])";
    let scene = jostle::scene::Scene::parse(good, "k.ron").unwrap();
    let mut w = scene.build().unwrap();
    for _ in 0..60 {
        w.step(scene.dt).unwrap();
    }
    let b = w.body(w.find_body("k").unwrap()).unwrap();
    assert_eq!(b.body_type(), BodyType::KinematicVelocity);
    assert!(
        (b.position.x - 60.0 * scene.dt).abs() < 1e-4,
        "{}",
        b.position
    );
}

/// Loads on a turntable keep their radius. Within a step a contact's anchors stay where they
/// were at its start, and friction held a sticking box to the table's velocity there, so the
/// box went along the tangent while the table's point turned under it: r·(ω·Δt)²/2 outward
/// every step (a box at 1 m on a table turning every 4 s reached 1.33 m in 10 s in the soft
/// step, 1.24 m in the Millington resolver). Friction in both resolvers, against a turning
/// kinematic body, now holds the point to the other's chord through the step. Over box sizes,
/// radii, turn rates (the centripetal acceleration a fraction of μ·g), friction and time
/// steps, at each resolver's defaults, on tables turning about their own centre: the box is
/// carried round (at 10 s its speed is the table's there to 1%, and at 2 s it is within 5% of
/// its starting radius, where the spin-up left it), and from 2 s (after the box has caught up
/// with the table) to 10 s the radius changes by less than 1 mm, and in the Millington
/// resolver by less than that plus its velocity epsilon times the 8 s: its velocity pass
/// leaves a contact sliding slower than the epsilon alone, and the box creeps outward at about
/// that speed (ε 10⁻⁴ m/s: 2.6 mm from 2 s to 20 s; ε 10⁻⁵: 0.7 mm; ε 10⁻⁶: 0.2 mm).
#[test]
fn loads_on_a_turntable_keep_their_radius() {
    let drifted = turntables_that_drift(0.0);
    assert!(drifted.is_empty(), "{drifted:#?}");
}

/// [`loads_on_a_turntable_keep_their_radius`] on tables whose centre lies off the axis they
/// turn about, by 1 to 4 times the load's radius, on the far side of the axis: the table's
/// centre goes round a circle, and the soft step held a load to the table's mean velocity over
/// the step (from 2 s to 10 s the soft step's loads moved 0.6–672 mm outward; a 0.1 m box at
/// 1 m, the table's centre 4 m from the axis, 262 mm at 60 Hz). It now moves a kinematic body
/// on a path through each substep at that substep's velocity
/// (`SolverBody::path_acceleration`): 0.0–4.8 mm. Ignored: 7 of the 42 cases still creep
/// outward, steadily (0.2–0.6 mm/s): in the soft step 5 cases by 2.2–4.8 mm, all at 60 Hz
/// with the table's centre moving at 4 m/s or more (at 120 Hz the same 0.2 m box at 3 m
/// holds); in the Millington resolver, whose friction this does not change, 2 by 2.1 mm
/// (its bound here 1.8 mm). benches/RESULTS.md ("A turn about an axis off the table")
/// leaves it open. Run with `cargo test --release --test kinematic -- --ignored
/// off_its_centre --nocapture`.
#[test]
#[ignore = "loads on tables turning off their centre still creep 0.2-0.6 mm/s in 7 of 42 cases"]
fn loads_on_a_table_turning_off_its_centre_keep_their_radius() {
    let drifted: Vec<String> = [1.0, 2.0, 4.0]
        .into_iter()
        .flat_map(turntables_that_drift)
        .collect();
    assert!(drifted.is_empty(), "{drifted:#?}");
}

/// The cases of [`loads_on_a_turntable_keep_their_radius`], each table centred `off` times
/// the load's radius from the axis, on the far side: those whose load drifted.
fn turntables_that_drift(off: f32) -> Vec<String> {
    use jostle::KinematicPath;
    let mut drifted = Vec::new();
    for (resolver, (half, radius, share, mu, rate)) in
        common::resolvers().into_iter().flat_map(|r| {
            [
                (0.05, 0.5, 0.3, 0.5, 60.0),
                (0.1, 1.0, 0.5, 0.5, 60.0),
                (0.1, 1.0, 0.5, 0.5, 240.0),
                (0.2, 2.0, 0.6, 0.3, 60.0),
                (0.2, 3.0, 0.6, 0.9, 60.0),
                (0.5, 3.0, 0.4, 0.9, 120.0),
                (1.0, 5.0, 0.5, 0.7, 60.0),
            ]
            .map(|case| (r.clone(), case))
        })
    {
        let dt = 1.0 / rate;
        let g = 9.81f32;
        // ω²·r = share·μ·g: friction holds the box with room to spare.
        let omega = (share * mu * g / radius).sqrt();
        let period = std::f32::consts::TAU / omega;
        let name = resolver.name();
        let creep = match &resolver {
            ResolverChoice::Millington(s) => s.velocity_epsilon * 8.0,
            _ => 0.0,
        };
        let mut w = world(resolver);
        // The table reaches past the load and past the axis on the other side.
        let centre = Vec3::new(-off * radius, 0.1, 0.0);
        let reach = radius + 2.0 * half + 1.0;
        let table_half = Vec3::new(off * radius + reach, 0.1, reach);
        let table = w
            .add_body(boxed("table", table_half, centre).with_material(mu, 0.0))
            .unwrap();
        w.set_path(
            table,
            Some(KinematicPath::Turn {
                start: centre,
                rotation: Quat::IDENTITY,
                center: Vec3::ZERO,
                axis: Vec3::Y,
                period,
            }),
        )
        .unwrap();
        let load = w
            .add_body(
                boxed(
                    "load",
                    Vec3::splat(half),
                    Vec3::new(radius, 0.2 + half, 0.0),
                )
                .with_material(mu, 0.0),
            )
            .unwrap();
        let radius_at = |w: &World| {
            let p = w.body(load).unwrap().position;
            Vec3::new(p.x, 0.0, p.z).length()
        };
        for _ in 0..(2.0 * rate) as usize {
            w.step(dt).unwrap();
        }
        let settled = radius_at(&w);
        for _ in 0..(8.0 * rate) as usize {
            w.step(dt).unwrap();
        }
        let end = radius_at(&w);
        // Carried round with the table: its speed is the table's there.
        let v = w.body(load).unwrap().linear_velocity;
        let carried = Vec3::new(v.x, 0.0, v.z).length() / (omega * end);
        let case = format!(
            "{name}: {half} m box at {radius} m, table centred {:.1} m off the axis, period {period:.2} s, μ {mu}, {rate} Hz: radius {settled:.4} m at 2 s, {end:.4} m at 10 s, speed {carried:.4} of the table's",
            off * radius
        );
        println!("{case}");
        // False for a NaN radius too.
        let held = (end - settled).abs() < 1e-3 + creep
            && (settled - radius).abs() < 0.05 * radius
            && (carried - 1.0).abs() < 0.01;
        if !held {
            drifted.push(case);
        }
    }
    drifted
}
