//! Sensors and collision groups (issue 19 item 5), with both resolvers: a sensor makes no
//! contact and reports what enters and leaves it; colliders whose groups do not meet pass
//! through each other; both can change at run time, survive snapshots, and are read from
//! scene files; queries skip sensors unless asked.

mod common;

use jostle::snapshot::Snapshot;
use jostle::{
    BodyDesc, CollisionEvent, CollisionGroups, QueryFilter, ResolverChoice, SensorEvent, ShapeDesc,
    Vec3, World, WorldSettings,
};

const DT: f32 = 1.0 / 60.0;

fn world(resolver: ResolverChoice) -> World {
    World::new(WorldSettings {
        resolver,
        ..Default::default()
    })
}

fn slab(name: &str, y: f32) -> BodyDesc {
    BodyDesc::fixed(
        name,
        ShapeDesc::Cuboid {
            half_extents: Vec3::new(2.0, 0.5, 2.0),
        },
    )
    .at(Vec3::new(0.0, y, 0.0))
}

/// A ball falls through a fixed sensor slab in free fall (the sensor pushes nothing: the
/// ball's height is the closed form ½·g·t² to the integrator's error), entering when its
/// bottom reaches the slab's top and leaving when its top passes the slab's bottom, each
/// reported once. A step reports what its detection found at the poses it started from, so
/// the ball is up to two steps' fall past each face when the step that reports it ends.
#[test]
fn a_ball_falls_through_a_sensor_and_is_seen_entering_and_leaving() {
    for resolver in common::resolvers() {
        let name = resolver.name();
        let mut w = world(resolver);
        let gate = w.add_body(slab("gate", 0.0).as_sensor()).unwrap();
        let gate_collider = w.colliders_of(gate)[0];
        let ball = w
            .add_body(
                BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.2 })
                    .at(Vec3::new(0.0, 2.0, 0.0)),
            )
            .unwrap();
        let ball_collider = w.colliders_of(ball)[0];
        let (mut entered, mut exited) = (Vec::new(), Vec::new());
        for step in 1..=60 {
            w.step(DT).unwrap();
            assert!(w.events().is_empty(), "{name}: a sensor makes no contact");
            for e in w.sensor_events() {
                match *e {
                    SensorEvent::Entered { sensor, other } => {
                        assert_eq!((sensor, other), (gate_collider, ball_collider));
                        entered.push((step, w.body(ball).unwrap().position.y));
                    }
                    SensorEvent::Exited { sensor, other } => {
                        assert_eq!((sensor, other), (gate_collider, ball_collider));
                        exited.push((step, w.body(ball).unwrap().position.y));
                    }
                }
            }
        }
        assert_eq!(entered.len(), 1, "{name}: {entered:?}");
        assert_eq!(exited.len(), 1, "{name}: {exited:?}");
        // The bottom reached the top face (y 0.5 + 0.2) within two steps' fall (each at most
        // 0.14 m here); the top left the bottom face (y −0.5 − 0.2) within two steps.
        let (_, y_in) = entered[0];
        assert!(
            y_in <= 0.7 && y_in > 0.7 - 0.28,
            "{name}: entered at y = {y_in}"
        );
        let (_, y_out) = exited[0];
        assert!(
            y_out < -0.7 && y_out > -0.7 - 0.28,
            "{name}: left at y = {y_out}"
        );
        let t = 60.0 * DT;
        let y = w.body(ball).unwrap().position.y;
        let free_fall = 2.0 - 0.5 * 9.81 * t * t;
        assert!(
            (y - free_fall).abs() < 0.1,
            "{name}: the ball fell freely: {y} against {free_fall}"
        );
        assert!(w.sensor_overlaps().is_empty());
    }
}

/// A ball that comes to rest on the floor inside a sensor volume stays reported as inside
/// while it sleeps (no `Exited` for sleeping), and leaves when the sensor is removed.
#[test]
fn a_sleeping_body_stays_inside_and_removal_ends_the_overlap() {
    let mut w = world(ResolverChoice::default());
    w.add_body(BodyDesc::fixed(
        "ground",
        ShapeDesc::HalfSpace { normal: Vec3::Y },
    ))
    .unwrap();
    let zone = w.add_body(slab("zone", 0.5).as_sensor()).unwrap();
    let ball = w
        .add_body(
            BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.2 }).at(Vec3::new(0.0, 0.3, 0.0)),
        )
        .unwrap();
    let mut events = Vec::new();
    for _ in 0..300 {
        w.step(DT).unwrap();
        events.extend_from_slice(w.sensor_events());
    }
    assert!(!w.body(ball).unwrap().is_awake(), "the ball fell asleep");
    assert_eq!(events.len(), 1, "{events:?}");
    assert!(matches!(events[0], SensorEvent::Entered { .. }));
    assert_eq!(w.sensor_overlaps().len(), 1);
    let zone_collider = w.colliders_of(zone)[0];
    w.remove_body(zone).unwrap();
    w.step(DT).unwrap();
    assert!(
        w.sensor_events()
            .iter()
            .any(|e| matches!(e, SensorEvent::Exited { sensor, .. } if *sensor == zone_collider)),
        "{:?}",
        w.sensor_events()
    );
    assert!(w.sensor_overlaps().is_empty());
}

/// Boxes whose groups do not meet fall through each other onto the ground; a box whose
/// groups meet lands on the other. Changing the groups at run time takes effect at once: a
/// box whose support stops meeting it drops through the support onto the ground (which, in
/// every group by default, meets both).
#[test]
fn groups_that_do_not_meet_pass_through_each_other() {
    const A: u32 = 1;
    const B: u32 = 2;
    for resolver in common::resolvers() {
        let name = resolver.name();
        let mut w = world(resolver);
        w.add_body(BodyDesc::fixed(
            "ground",
            ShapeDesc::HalfSpace { normal: Vec3::Y },
        ))
        .unwrap();
        let cube = |n: &str, y: f32, g: CollisionGroups| {
            BodyDesc::dynamic(
                n,
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.5),
                },
            )
            .at(Vec3::new(0.0, y, 0.0))
            .with_groups(g)
        };
        // `low` is in A and meets all; `ghost` is in B and meets only B; `lander` meets all.
        let low = w
            .add_body(cube("low", 0.5, CollisionGroups::new(A, u32::MAX)))
            .unwrap();
        let ghost = w
            .add_body(cube("ghost", 2.0, CollisionGroups::new(B, B | 4)))
            .unwrap();
        let lander = w
            .add_body(cube("lander", 4.0, CollisionGroups::ALL).at(Vec3::new(3.0, 4.0, 0.0)))
            .unwrap();
        w.add_body(cube("base", 0.5, CollisionGroups::ALL).at(Vec3::new(3.0, 0.5, 0.0)))
            .unwrap();
        let mut touched = false;
        for _ in 0..120 {
            w.step(DT).unwrap();
            touched |= w.events().iter().any(|e| match *e {
                CollisionEvent::Started(a, b) => (a, b) == (low.min(ghost), low.max(ghost)),
                _ => false,
            });
        }
        let y = |w: &World, h| w.body(h).unwrap().position.y;
        // The ghost does not meet `low` (A is not in its filter) but meets the ground (a
        // member of every group): it passes through `low` and lands on the ground inside it.
        assert!(!touched, "{name}: the ghost never touched `low`");
        assert!(
            (y(&w, ghost) - 0.5).abs() < 0.02,
            "{name}: ghost at {}",
            y(&w, ghost)
        );
        assert!(
            (y(&w, low) - 0.5).abs() < 0.02,
            "{name}: low at {}",
            y(&w, low)
        );
        assert!(
            (y(&w, lander) - 1.5).abs() < 0.02,
            "{name}: lander at {}",
            y(&w, lander)
        );
        // Now `lander`'s support stops meeting it: the lander drops through to the ground.
        let base = w.find_body("base").unwrap();
        w.set_collision_groups(w.colliders_of(base)[0], CollisionGroups::new(A, A))
            .unwrap();
        w.set_collision_groups(w.colliders_of(lander)[0], CollisionGroups::new(B, B | 4))
            .unwrap();
        for _ in 0..120 {
            w.step(DT).unwrap();
        }
        assert!(
            (y(&w, lander) - 0.5).abs() < 0.02,
            "{name}: the lander fell through its old support: {}",
            y(&w, lander)
        );
    }
}

/// Queries skip sensors unless the filter includes them, and honour the filter's groups.
#[test]
fn queries_skip_sensors_unless_asked_and_honour_groups() {
    let mut w = world(ResolverChoice::default());
    w.add_body(slab("zone", 2.0).as_sensor()).unwrap();
    w.add_body(slab("floor", 0.0).with_groups(CollisionGroups::new(2, u32::MAX)))
        .unwrap();
    w.update_queries();
    let q = w.queries();
    let down = |filter: &QueryFilter| {
        q.ray_cast(Vec3::new(0.0, 5.0, 0.0), Vec3::NEG_Y, 10.0, filter)
            .map(|hit| hit.distance)
    };
    let toi = down(&QueryFilter::default()).unwrap();
    assert!(
        (toi - 4.5).abs() < 1e-4,
        "the floor's top, not the sensor: {toi}"
    );
    let with_sensors = QueryFilter {
        include_sensors: true,
        ..QueryFilter::default()
    };
    let toi = down(&with_sensors).unwrap();
    assert!((toi - 2.5).abs() < 1e-4, "the sensor's top: {toi}");
    let only_group_1 = QueryFilter {
        groups: Some(CollisionGroups::new(u32::MAX, 1)),
        ..QueryFilter::default()
    };
    assert_eq!(down(&only_group_1), None, "the floor is in group 2 only");
}

/// Sensors and groups survive a snapshot, and the restored world continues exactly.
#[test]
fn sensors_and_groups_round_trip_through_snapshots() {
    let mut w = world(ResolverChoice::default());
    w.add_body(slab("gate", 0.0).as_sensor()).unwrap();
    w.add_body(
        BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.2 })
            .at(Vec3::new(0.0, 1.0, 0.0))
            .with_groups(CollisionGroups::new(4, 5)),
    )
    .unwrap();
    for _ in 0..22 {
        w.step(DT).unwrap();
    }
    assert_eq!(w.sensor_overlaps().len(), 1, "the ball is inside the gate");
    let text = w.snapshot("sensors", DT).to_ron().unwrap();
    let mut r = World::from_snapshot(Snapshot::parse(&text, "sensors").unwrap()).unwrap();
    assert_eq!(r.sensor_overlaps(), w.sensor_overlaps());
    let ball = r.find_body("ball").unwrap();
    assert_eq!(
        r.collider(r.colliders_of(ball)[0]).unwrap().groups,
        CollisionGroups::new(4, 5)
    );
    let mut events = (Vec::new(), Vec::new());
    for _ in 0..60 {
        w.step(DT).unwrap();
        r.step(DT).unwrap();
        events.0.extend_from_slice(w.sensor_events());
        events.1.extend_from_slice(r.sensor_events());
    }
    assert_eq!(r.state_hash(), w.state_hash());
    assert_eq!(events.0, events.1);
    assert_eq!(
        events.0.len(),
        1,
        "one exit, no second entry: {:?}",
        events.0
    );
}

/// Scene files carry `sensor` and `groups`.
#[test]
fn scene_files_declare_sensors_and_groups() {
    let text = "Scene(bodies: [\
        Body(name: \"zone\", shape: Cuboid(half_extents: (1.0, 1.0, 1.0)), fixed: true, sensor: true),\
        Body(name: \"ball\", shape: Ball(radius: 0.25), position: (0.0, 3.0, 0.0), \
             groups: (memberships: 2, filter: 3))])";
    let scene = jostle::scene::Scene::parse(text, "s.ron").unwrap();
    let mut w = scene.build().unwrap();
    let zone = w.find_body("zone").unwrap();
    assert!(w.collider(w.colliders_of(zone)[0]).unwrap().sensor);
    let ball = w.find_body("ball").unwrap();
    assert_eq!(
        w.collider(w.colliders_of(ball)[0]).unwrap().groups,
        CollisionGroups::new(2, 3)
    );
    let mut entered = 0;
    for _ in 0..120 {
        w.step(scene.dt).unwrap();
        entered += w
            .sensor_events()
            .iter()
            .filter(|e| matches!(e, SensorEvent::Entered { .. }))
            .count();
    }
    assert_eq!(entered, 1);
}

/// A body touching a sleeping box wakes it; the contact that woke it is still reported as
/// started in that step (the world detects contacts a second time after waking bodies, and
/// keeps the first detection's events: before, the second detection found the pair already
/// touching and the event was lost).
#[test]
fn the_contact_that_wakes_a_sleeper_is_reported() {
    let mut w = world(ResolverChoice::default());
    w.add_body(BodyDesc::fixed(
        "ground",
        ShapeDesc::HalfSpace { normal: Vec3::Y },
    ))
    .unwrap();
    let sleeper = w
        .add_body(
            BodyDesc::dynamic(
                "sleeper",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.5),
                },
            )
            .at(Vec3::new(0.0, 0.5, 0.0)),
        )
        .unwrap();
    for _ in 0..240 {
        w.step(DT).unwrap();
    }
    assert!(!w.body(sleeper).unwrap().is_awake());
    // Placed already touching the sleeper (1 cm deep): the step's first detection finds the
    // contact and wakes the sleeper, the second runs with it awake.
    let ball = w
        .add_body(
            BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.2 })
                .at(Vec3::new(0.0, 1.19, 0.0)),
        )
        .unwrap();
    let pair = (sleeper.min(ball), sleeper.max(ball));
    let mut started = 0;
    for _ in 0..60 {
        w.step(DT).unwrap();
        started += w
            .events()
            .iter()
            .filter(|e| **e == CollisionEvent::Started(pair.0, pair.1))
            .count();
    }
    assert_eq!(
        started, 1,
        "the ball's landing on the sleeper is reported once"
    );
}

/// Contact force events: a 10 kg box resting on the ground pushes with m·g each step; with a
/// threshold below that every step reports it (the total impulse m·g·dt up on the box, the
/// strongest point on its bottom face), with one above it nothing does until a 30 kg box is
/// set on top, after which the pair carries (10 + 30)·g. The force is the one the contacts
/// carry at the end of the step (for the soft step, its last substep's impulse over the
/// substep), not the peak of an impact inside the step.
#[test]
fn contact_force_events_report_what_pushes_harder_than_the_threshold() {
    for resolver in common::resolvers() {
        let name = resolver.name();
        for threshold in [50.0, 200.0] {
            // Sleeping pairs are not solved and report nothing: sleep off.
            let mut settings = WorldSettings {
                resolver: resolver.clone(),
                ..Default::default()
            };
            settings.sleep.enabled = false;
            let mut w = World::new(settings);
            let ground = w
                .add_body(BodyDesc::fixed(
                    "ground",
                    ShapeDesc::HalfSpace { normal: Vec3::Y },
                ))
                .unwrap();
            let half = Vec3::new(0.25, 0.1, 0.2);
            let cuboid = ShapeDesc::Cuboid { half_extents: half };
            let boxed = w
                .add_body(
                    BodyDesc::dynamic("box", cuboid.clone())
                        .at(Vec3::new(0.0, 0.1, 0.0))
                        .with_mass(10.0)
                        .with_force_events(threshold),
                )
                .unwrap();
            // Steps 61–119 against the ground, 181–239 against the ground and the load.
            let mut reported = [0u32; 4];
            for step in 1..=240 {
                if step == 121 {
                    w.add_body(
                        BodyDesc::dynamic("load", cuboid.clone())
                            .at(Vec3::new(0.0, 0.3, 0.0))
                            .with_mass(30.0),
                    )
                    .unwrap();
                }
                w.step(DT).unwrap();
                let carried: f32 = if step <= 120 { 10.0 } else { 40.0 } * 9.81;
                for e in w.contact_force_events() {
                    assert!(e.total_force > threshold, "{name}: {e:?}");
                    assert_eq!(e.a, boxed, "{name}: the box has the threshold: {e:?}");
                    // The ground pushes the box up with what it carries; the load pushes it
                    // down with its own weight.
                    let (pushed, which): (f32, usize) = if e.b == ground {
                        (carried, 0)
                    } else {
                        (-30.0 * 9.81, 2)
                    };
                    if step % 120 > 60 {
                        assert!(
                            (e.total_force - pushed.abs()).abs() < 0.05 * pushed.abs(),
                            "{name}, step {step}: force {} against {pushed}",
                            e.total_force
                        );
                        let on_box = e.total_impulse / DT;
                        assert!(
                            (on_box - Vec3::new(0.0, pushed, 0.0)).length() < 0.05 * pushed.abs(),
                            "{name}: {on_box}"
                        );
                        let face = if which == 0 { 0.0 } else { 0.2 };
                        assert!((e.strongest_point.y - face).abs() < 0.01, "{name}: {e:?}");
                        assert!(e.strongest_force <= e.total_force + 1e-3);
                        reported[which + (step > 120) as usize] += 1;
                    }
                }
            }
            // The ground carries 98 N, then 392 N; the load weighs 294 N on the box: each
            // reported when above the threshold.
            let expected = [if threshold < 98.1 { 59 } else { 0 }, 59, 0, 59];
            assert_eq!(reported, expected, "{name}, threshold {threshold}");
        }
    }
}

/// A pair filter refuses the pairs it is asked about: a box it keeps from the ground falls
/// through; the other box lands. A snapshot does not keep the filter.
#[test]
fn a_pair_filter_refuses_pairs() {
    use jostle::Collider;
    let mut w = world(ResolverChoice::default());
    w.add_body(BodyDesc::fixed(
        "ground",
        ShapeDesc::HalfSpace { normal: Vec3::Y },
    ))
    .unwrap();
    let cube = |name: &str, x: f32| {
        BodyDesc::dynamic(
            name,
            ShapeDesc::Cuboid {
                half_extents: Vec3::splat(0.5),
            },
        )
        .at(Vec3::new(x, 1.0, 0.0))
    };
    let sinker = w.add_body(cube("sinker", 0.0)).unwrap();
    let lander = w.add_body(cube("lander", 3.0)).unwrap();
    w.set_pair_filter(Some(Box::new(move |a: &Collider, b: &Collider| {
        a.body != sinker && b.body != sinker
    })));
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    assert!(w.body(sinker).unwrap().position.y < -1.0);
    assert!((w.body(lander).unwrap().position.y - 0.5).abs() < 0.01);
    w.set_pair_filter(None);
    let text = w.snapshot("filter", DT).to_ron().unwrap();
    assert!(World::from_snapshot(Snapshot::parse(&text, "filter").unwrap()).is_ok());
}

/// A kinematic body moving through a fixed sensor is reported entering and leaving it (two
/// immovable colliders make no contact, but a sensor still sees them).
#[test]
fn a_fixed_sensor_sees_a_kinematic_body_pass() {
    use jostle::BodyType;
    let mut w = world(ResolverChoice::default());
    let zone = w.add_body(slab("zone", 0.0).as_sensor()).unwrap();
    let platform = w
        .add_body(
            BodyDesc::dynamic(
                "platform",
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.25),
                },
            )
            .at(Vec3::new(-4.0, 0.0, 0.0)),
        )
        .unwrap();
    w.set_body_type(platform, BodyType::KinematicVelocity)
        .unwrap();
    w.set_velocity(platform, Vec3::new(2.0, 0.0, 0.0), Vec3::ZERO)
        .unwrap();
    let zone_collider = w.colliders_of(zone)[0];
    let mut seen = Vec::new();
    for step in 1..=240 {
        w.step(DT).unwrap();
        for e in w.sensor_events() {
            seen.push((step, *e));
        }
    }
    let platform_collider = w.colliders_of(platform)[0];
    assert_eq!(seen.len(), 2, "{seen:?}");
    assert_eq!(
        seen[0].1,
        SensorEvent::Entered {
            sensor: zone_collider,
            other: platform_collider
        }
    );
    assert!(matches!(seen[1].1, SensorEvent::Exited { .. }));
    // It enters when its front face (x + 0.25) reaches −2 (t = 0.875 s, after 52.5 steps)
    // and leaves when its back face passes +2 (t = 3.125 s, after 187.5 steps); a step
    // reports what it found at the poses it started from.
    assert!((53..=55).contains(&seen[0].0), "{seen:?}");
    assert!((188..=190).contains(&seen[1].0), "{seen:?}");
}

/// A force event threshold is none, or finite and ≥ 0: the API and scene files refuse others,
/// naming the field.
#[test]
fn bad_force_thresholds_are_refused() {
    use jostle::StepError;
    let mut w = world(ResolverChoice::default());
    let ball = w
        .add_body(BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 }))
        .unwrap();
    let c = w.colliders_of(ball)[0];
    for bad in [f32::NAN, -1.0, f32::INFINITY] {
        match w.set_force_event_threshold(c, Some(bad)) {
            Err(StepError::Invalid { field, .. }) => assert_eq!(field, "force_event_threshold"),
            other => panic!("{bad}: {other:?}"),
        }
    }
    assert!(w.set_force_event_threshold(c, Some(0.0)).is_ok());
    let text =
        "Scene(bodies: [Body(name: \"b\", shape: Ball(radius: 0.5), force_event_threshold: -2.0)])";
    let e = jostle::scene::Scene::parse(text, "b.ron")
        .unwrap_err()
        .to_string();
    assert!(e.contains("force_event_threshold"), "{e}");
}
