//! Removing bodies and colliders (issue 19 item 1): handles go stale, what rested on a removed
//! body wakes and falls, contacts end with events, queries stop seeing it, and snapshots
//! round-trip bit for bit after removals and re-insertions.

use jostle::snapshot::Snapshot;
use jostle::{
    BodyDesc, CollisionEvent, QueryFilter, ShapeDesc, StepError, Vec3, World, WorldSettings,
};

const DT: f32 = 1.0 / 60.0;

fn cube(name: &str, y: f32) -> BodyDesc {
    BodyDesc::dynamic(
        name,
        ShapeDesc::Cuboid {
            half_extents: Vec3::splat(0.5),
        },
    )
    .at(Vec3::new(0.0, y, 0.0))
    .with_density(1000.0)
}

/// A ground and a column of `n` unit cubes resting on it.
fn column(n: usize) -> (World, Vec<jostle::BodyHandle>) {
    let mut world = World::new(WorldSettings::default());
    world
        .add_body(BodyDesc::fixed(
            "ground",
            ShapeDesc::HalfSpace { normal: Vec3::Y },
        ))
        .unwrap();
    let boxes = (0..n)
        .map(|i| {
            world
                .add_body(cube(&format!("box{i}"), 0.5 + i as f32))
                .unwrap()
        })
        .collect();
    (world, boxes)
}

#[test]
fn a_removed_body_is_gone_and_its_handles_are_stale() {
    let (mut world, boxes) = column(2);
    let colliders = world.colliders_of(boxes[0]);
    assert_eq!(colliders.len(), 1);
    let removed = world.remove_body(boxes[0]).unwrap();
    assert_eq!(removed.name, "box0");
    assert_eq!(world.body_count(), 2);
    assert!(world.body(boxes[0]).is_none());
    assert!(world.collider(colliders[0]).is_none());
    assert!(world.colliders_of(boxes[0]).is_empty());
    assert_eq!(
        world.remove_body(boxes[0]).unwrap_err(),
        StepError::InvalidHandle(boxes[0])
    );
    assert_eq!(
        world.apply_force(boxes[0], Vec3::X),
        Err(StepError::InvalidHandle(boxes[0]))
    );
    assert_eq!(
        world.remove_collider(colliders[0]).unwrap_err(),
        StepError::InvalidCollider(colliders[0])
    );
    assert!(world.find_body("box0").is_none());
    // The slot is reused by the next body, under a new generation.
    let again = world.add_body(cube("again", 5.0)).unwrap();
    assert_eq!(again.index(), boxes[0].index());
    assert_ne!(again, boxes[0]);
    assert!(world.body(boxes[0]).is_none());
    assert_eq!(world.body_name(again), Some("again"));
    assert_eq!(world.colliders_of(again).len(), 1);
    world.step(DT).unwrap();
}

#[test]
fn what_rested_on_a_removed_body_wakes_and_falls() {
    let (mut world, boxes) = column(3);
    let mut asleep_at = None;
    for step in 0..600 {
        world.step(DT).unwrap();
        if boxes.iter().all(|&b| !world.body(b).unwrap().sleep.awake) {
            asleep_at = Some(step);
            break;
        }
    }
    assert!(asleep_at.is_some(), "the column falls asleep");
    let top_before = world.body(boxes[2]).unwrap().position.y;
    world.remove_body(boxes[0]).unwrap();
    assert!(
        world.body(boxes[1]).unwrap().sleep.awake && world.body(boxes[2]).unwrap().sleep.awake,
        "the boxes above wake at once"
    );
    for _ in 0..120 {
        world.step(DT).unwrap();
    }
    let top_after = world.body(boxes[2]).unwrap().position.y;
    let fell = top_before - top_after;
    assert!(
        (fell - 1.0).abs() < 0.02,
        "the top box falls by the removed box's height: {fell} m"
    );
}

#[test]
fn contacts_of_a_removed_body_end_with_stopped_events() {
    let (mut world, boxes) = column(1);
    let ground = world.find_body("ground").unwrap();
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    assert!(
        world
            .contacts()
            .iter()
            .any(|c| c.a == boxes[0] || c.b == boxes[0])
    );
    world.remove_body(boxes[0]).unwrap();
    assert!(
        world
            .contacts()
            .iter()
            .all(|c| c.a != boxes[0] && c.b != boxes[0]),
        "its contacts leave the narrow phase at once"
    );
    world.step(DT).unwrap();
    let stopped = world.events().iter().any(|e| {
        matches!(e, CollisionEvent::Stopped(a, b)
            if (*a == ground && *b == boxes[0]) || (*a == boxes[0] && *b == ground))
    });
    assert!(stopped, "events: {:?}", world.events());
}

#[test]
fn queries_stop_seeing_a_removed_body() {
    let (mut world, boxes) = column(2);
    world.update_queries();
    let down = |w: &World| {
        w.queries()
            .ray_cast(
                Vec3::new(0.0, 10.0, 0.0),
                -Vec3::Y,
                20.0,
                &QueryFilter::default(),
            )
            .map(|h| h.body)
    };
    assert_eq!(down(&world), Some(boxes[1]));
    world.remove_body(boxes[1]).unwrap();
    assert!(!world.queries_use_tree(), "a removal makes the tree stale");
    assert_eq!(down(&world), Some(boxes[0]));
    world.update_queries();
    assert_eq!(down(&world), Some(boxes[0]), "through the tree as well");
}

#[test]
fn removing_a_collider_keeps_its_body() {
    let (mut world, boxes) = column(2);
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    let collider = world.colliders_of(boxes[1])[0];
    world.remove_collider(collider).unwrap();
    assert!(world.body(boxes[1]).is_some());
    assert!(world.colliders_of(boxes[1]).is_empty());
    // Without a collider it touches nothing: it falls through the box below.
    for _ in 0..60 {
        world.step(DT).unwrap();
    }
    assert!(world.body(boxes[1]).unwrap().position.y < 0.0);
}

/// Removals and re-insertions, then a snapshot through text: the restored world continues
/// bit for bit as the original does, and a removed handle stays stale in it.
#[test]
fn snapshots_round_trip_after_removals_and_reinsertions() {
    let (mut world, boxes) = column(6);
    for _ in 0..30 {
        world.step(DT).unwrap();
    }
    world.remove_body(boxes[1]).unwrap();
    world.remove_body(boxes[4]).unwrap();
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    let reinserted = world.add_body(cube("late", 9.0)).unwrap();
    assert_eq!(
        reinserted.index(),
        boxes[4].index(),
        "the freed slot is reused"
    );
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    // A snapshot straight after a removal, before any step, holds none of its contacts.
    world.remove_body(boxes[2]).unwrap();
    let text = world.snapshot("removal", DT).to_ron().unwrap();
    let mut restored = World::from_snapshot(Snapshot::parse(&text, "removal").unwrap()).unwrap();
    assert_eq!(restored.state_hash(), world.state_hash());
    assert!(restored.body(boxes[4]).is_none() && restored.body(reinserted).is_some());
    assert_eq!(restored.body_name(reinserted), Some("late"));
    for _ in 0..60 {
        world.step(DT).unwrap();
        restored.step(DT).unwrap();
    }
    assert_eq!(restored.state_hash(), world.state_hash());
    // And both keep reusing slots the same way.
    let a = world.add_body(cube("next", 12.0)).unwrap();
    let b = restored.add_body(cube("next", 12.0)).unwrap();
    assert_eq!(a, b);
}
