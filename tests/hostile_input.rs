//! Hostile input (issue 16): scene and snapshot text with numbers replaced by NaN, infinities,
//! huge, tiny, negative and out-of-range values, or cut short, never panics and never yields a
//! world that goes non-finite. Either loading refuses it with an error, or the world it builds
//! steps with every body finite and none quarantined.
//!
//! Cases: `PROPTEST_CASES` (default 128 per test here), drawn from a fixed seed unless
//! `PROPTEST_RNG_SEED` names one. `jostle run` reads files through the same calls
//! (`Scene::parse` and `build`, `Snapshot::parse` and `World::from_snapshot`).

use jostle::World;
use jostle::scene::Scene;
use jostle::snapshot::Snapshot;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::sync::OnceLock;

/// What may replace a number.
const REPLACEMENTS: [&str; 14] = [
    "NaN",
    "inf",
    "-inf",
    "-1",
    "0",
    "1e30",
    "-1e30",
    "1e-30",
    "4294967295",
    "18446744073709551615",
    "99",
    "3",
    "-0.5",
    "1e38",
];

fn config(cases: u32) -> ProptestConfig {
    let base = ProptestConfig::default();
    let rng_seed = match base.rng_seed {
        RngSeed::Random => RngSeed::Fixed(0x686f_7374_696c),
        seed => seed,
    };
    ProptestConfig {
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|c| c.parse().ok())
            .unwrap_or(cases),
        rng_seed,
        ..base
    }
}

/// Byte ranges of the numbers in `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            || (bytes[i] == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
        let in_word = i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        if starts && !in_word {
            let start = i;
            i += 1;
            while i < bytes.len()
                && (bytes[i].is_ascii_digit() || matches!(bytes[i], b'.' | b'e' | b'-'))
            {
                i += 1;
            }
            out.push((start, i));
        } else {
            i += 1;
        }
    }
    out
}

/// `text` with the numbers picked by `picks` (fractions of the list) replaced, or, when
/// `cut` is below 1, cut at that fraction of its length.
fn mutate(text: &str, picks: &[(f64, usize)], cut: f64) -> String {
    if cut < 1.0 {
        let mut end = (text.len() as f64 * cut) as usize;
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        return text[..end].to_string();
    }
    let spans = numbers(text);
    let mut chosen: Vec<(usize, usize, &str)> = picks
        .iter()
        .map(|&(at, r)| {
            let (s, e) = spans[((at * spans.len() as f64) as usize).min(spans.len() - 1)];
            (s, e, REPLACEMENTS[r % REPLACEMENTS.len()])
        })
        .collect();
    chosen.sort_by_key(|c| std::cmp::Reverse(c.0));
    chosen.dedup_by_key(|c| c.0);
    let mut out = text.to_string();
    for (s, e, r) in chosen {
        out.replace_range(s..e, r);
    }
    out
}

/// Steps `world` a few times: every step either refuses (a bad time step) or leaves every
/// body finite, none quarantined.
fn steps_stay_finite(mut world: World, dt: f32, text: &str) {
    for _ in 0..4 {
        match world.step(dt) {
            Ok(report) => assert!(
                report.quarantined.is_empty(),
                "{:?} went non-finite from:\n{text}",
                report.quarantined
            ),
            Err(_) => return,
        }
    }
    for (_, name, body) in world.bodies() {
        assert!(body.is_finite(), "{name} is not finite, from:\n{text}");
    }
}

const SCENE: &str = include_str!("../assets/stack_15.ron");

/// A snapshot of the 15-box stack after 30 steps, with contacts and carried impulses.
fn snapshot_text() -> &'static str {
    static TEXT: OnceLock<String> = OnceLock::new();
    TEXT.get_or_init(|| {
        let scene = Scene::parse(SCENE, "stack_15.ron").expect("the asset loads");
        let mut world = scene.build().expect("builds");
        for _ in 0..30 {
            world.step(scene.dt).expect("steps");
        }
        let config = ron::ser::PrettyConfig::default().struct_names(true);
        ron::ser::to_string_pretty(&world.snapshot("stack 15", scene.dt), config)
            .expect("serialises")
    })
}

fn mutation() -> impl Strategy<Value = (Vec<(f64, usize)>, f64)> {
    (
        prop::collection::vec((0.0f64..1.0, 0usize..REPLACEMENTS.len()), 1..4),
        prop_oneof![4 => Just(1.0f64), 1 => 0.0f64..1.0],
    )
}

proptest! {
    #![proptest_config(config(128))]

    #[test]
    fn mutated_scene_files_are_refused_or_run_finite((picks, cut) in mutation()) {
        let text = mutate(SCENE, &picks, cut);
        if let Ok(scene) = Scene::parse(&text, "mutated.ron")
            && let Ok(world) = scene.build()
        {
            steps_stay_finite(world, scene.dt, &text);
        }
    }

    #[test]
    fn mutated_snapshots_are_refused_or_run_finite((picks, cut) in mutation()) {
        let text = mutate(snapshot_text(), &picks, cut);
        if let Ok(snapshot) = Snapshot::parse(&text, "mutated.ron") {
            let dt = snapshot.dt;
            if let Ok(world) = World::from_snapshot(snapshot) {
                steps_stay_finite(world, dt, &text);
            }
        }
    }
}

#[test]
fn the_mutations_reach_the_numbers() {
    let text = snapshot_text();
    // Unmutated, the snapshot and the scene load and run.
    let snapshot = Snapshot::parse(text, "stack.ron").expect("the snapshot parses");
    let dt = snapshot.dt;
    steps_stay_finite(World::from_snapshot(snapshot).expect("restores"), dt, text);
    let scene = Scene::parse(SCENE, "stack_15.ron").expect("the scene parses");
    steps_stay_finite(scene.build().expect("builds"), scene.dt, SCENE);
    assert!(numbers(text).len() > 1000);
    let mutated = mutate(text, &[(0.5, 0)], 1.0);
    assert_ne!(mutated, text);
    assert!(mutated.contains("NaN"));
}

/// The error `World::from_snapshot` gives for the snapshot text with the first number after
/// `field` (itself the first after `after`) replaced by `to`.
fn snapshot_error(after: &str, field: &str, to: &str) -> String {
    let text = snapshot_text();
    let start = text.find(after).expect("anchor present");
    let at = start + text[start..].find(field).expect("field present");
    let (s, e) = numbers(text)
        .into_iter()
        .find(|&(s, _)| s >= at)
        .expect("a number follows");
    let mut edited = text.to_string();
    edited.replace_range(s..e, to);
    let snapshot = Snapshot::parse(&edited, "edited.ron").expect("still parses");
    match World::from_snapshot(snapshot) {
        Ok(_) => panic!("accepted {field} {to}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_snapshot_names_the_body_or_collider_and_the_field_it_refuses() {
    // After `mass: 999` come a box's own fields; after the fixed ground's last field comes the
    // first box.
    let cases = [
        ("mass: 999", "inv_mass: ", "-0.5", "`inv_mass`"),
        (
            "body_type: Fixed",
            "linear_velocity: ",
            "1e30",
            "`linear_velocity`",
        ),
        (
            "mass: 999",
            "inv_inertia_body: ",
            "99.0",
            "`inv_inertia_body`",
        ),
        ("bodies:", "inv_mass: ", "1.0", "`body_type`"),
        ("colliders:", "restitution: ", "5.0", "restitution"),
        // Finite, but a gravity of 10³⁰ m/s² put the body out of f32's range at once.
        ("mass: 999", "gravity_scale: ", "1e30", "`gravity_scale`"),
        ("mass: 999", "gravity_scale: ", "-1e30", "`gravity_scale`"),
        ("resolver:", "substeps: ", "4294967", "substeps"),
        ("narrow:", "impulse: ", "NaN", "impulse"),
        ("narrow:", "local_p2: ", "1e30", "local_p"),
        // A pair's record of where its contacts are, and a contact's impulse, which the
        // pair's points take back at the next step.
        ("emitted:", "first: ", "99999", "emitted"),
        ("emitted:", "count: ", "6", "another pair's"),
        (
            "contacts: [\n            BodyContact(",
            "impulse: ",
            "1e30",
            "impulse",
        ),
    ];
    for (after, field, to, named) in cases {
        let e = snapshot_error(after, field, to);
        assert!(e.contains(named), "{field} {to}: {e}");
    }
}

/// A snapshot whose bodies share a name is refused naming the body and the field, as a scene
/// file is: it was accepted, and its trace had two indistinguishable rows a step.
#[test]
fn a_snapshot_with_two_bodies_of_one_name_is_refused() {
    let text = snapshot_text();
    let names: Vec<&str> = text
        .match_indices("name: \"")
        .map(|(at, m)| {
            let rest = &text[at + m.len()..];
            &rest[..rest.find('"').expect("closed")]
        })
        .filter(|n| !n.is_empty())
        .collect();
    let (first, second) = (names[1], names[2]);
    assert_ne!(first, second);
    let edited = text.replacen(
        &format!("name: \"{second}\""),
        &format!("name: \"{first}\""),
        1,
    );
    let snapshot = Snapshot::parse(&edited, "edited.ron").expect("still parses");
    let e = match World::from_snapshot(snapshot) {
        Ok(_) => panic!("accepted two bodies of one name"),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("`name`") && e.contains(first), "{e}");
}

#[test]
fn api_values_beyond_the_limits_are_refused() {
    use jostle::{BodyDesc, ShapeDesc, StepError, Vec3, WorldSettings};
    let mut world = World::new(WorldSettings::default());
    let h = world
        .add_body(BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 }))
        .expect("adds");
    assert!(matches!(
        world.set_velocity(h, Vec3::new(0.0, 2.0e5, 0.0), Vec3::ZERO),
        Err(StepError::OutOfRange { .. })
    ));
    assert!(matches!(
        world.set_velocity(h, Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0e4)),
        Err(StepError::OutOfRange { .. })
    ));
    assert!(
        world
            .set_velocity(h, Vec3::new(0.0, 9.0e4, 0.0), Vec3::ZERO)
            .is_ok()
    );
    // An impulse that would take the body past the limits is refused and changes nothing.
    let before = world.body(h).expect("ball").linear_velocity;
    assert!(matches!(
        world.apply_impulse_at_point(h, Vec3::new(1.0e30, 0.0, 0.0), Vec3::ZERO),
        Err(StepError::OutOfRange { .. })
    ));
    assert_eq!(world.body(h).expect("ball").linear_velocity, before);
    assert!(
        world
            .apply_impulse_at_point(h, Vec3::new(1.0, 0.0, 0.0), Vec3::ZERO)
            .is_ok()
    );
    assert!(matches!(world.step(11.0), Err(StepError::InvalidDt(_))));
    assert!(world.step(10.0).is_ok());
}

#[test]
fn a_body_that_leaves_the_limits_is_frozen_and_its_snapshot_reads_back() {
    // A ball thrown at 99,999 m/s with steps of 1 s: 1.1·10⁶ m out after 11 steps, beyond the
    // 10⁶ m a scene's body is held to. It went on to 10⁸ m unreported, and the snapshot
    // written of it was refused on loading ("position: is 1.100e6 m, above the limit").
    use jostle::{BodyDesc, ShapeDesc, Vec3, WorldSettings};
    let mut world = World::new(WorldSettings {
        gravity: Vec3::ZERO,
        ..WorldSettings::default()
    });
    let h = world
        .add_body(
            BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 })
                .moving(Vec3::new(99_999.0, 0.0, 0.0), Vec3::ZERO),
        )
        .expect("adds");
    let mut frozen_at = None;
    for step in 1..=20 {
        let report = world.step(1.0).expect("steps");
        if report.quarantined.iter().any(|(q, _)| *q == h) {
            frozen_at = Some(step);
            break;
        }
    }
    // Frozen at the step that would have taken it past 10⁶ m, where it last was within.
    assert_eq!(frozen_at, Some(11));
    let ball = world.body(h).expect("ball");
    assert!(
        ball.position.x <= 1.0e6 && ball.position.x > 9.9e5,
        "{}",
        ball.position
    );
    let text = world.snapshot("far", 1.0).to_ron().expect("writes");
    let back = World::from_snapshot(Snapshot::parse(&text, "far").expect("parses"));
    assert!(back.is_ok(), "{:?}", back.err());
}

#[test]
fn a_spin_an_impact_gives_past_the_scene_limit_reads_back_from_a_snapshot() {
    // A 1 mm cube thrown edge first onto the ground at 141 m/s spins up to 3.6·10⁴ rad/s, past
    // the 10⁴ a scene may start with; a snapshot of such a spin was refused on loading. A
    // snapshot holds spins up to `MAX_REACHED_ANGULAR_SPEED`, beyond which the step
    // quarantines the body.
    let scene = Scene::parse(
        "Scene(name: \"tiny\", bodies: [
            Body(name: \"ground\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true),
            Body(name: \"b\", shape: Cuboid(half_extents: (0.001, 0.001, 0.001)),
                 position: (0.0, 0.01, 0.0), rotation: (0.3, 0.0, 0.1, 0.95),
                 linear_velocity: (100.0, -100.0, 0.0))])",
        "tiny.ron",
    )
    .expect("parses");
    let mut world = scene.build().expect("builds");
    let b = world.find_body("b").expect("b");
    let mut fastest = 0.0f32;
    for _ in 0..2 {
        let report = world.step(1.0 / 60.0).expect("steps");
        assert!(report.quarantined.is_empty(), "{:?}", report.quarantined);
        fastest = fastest.max(world.body(b).expect("b").angular_velocity.length());
    }
    assert!(
        fastest > jostle::MAX_ANGULAR_SPEED && fastest <= jostle::MAX_REACHED_ANGULAR_SPEED,
        "{fastest} rad/s"
    );
    let text = world.snapshot("tiny", 1.0 / 60.0).to_ron().expect("writes");
    let back = World::from_snapshot(Snapshot::parse(&text, "tiny").expect("parses"));
    assert!(back.is_ok(), "{:?}", back.err());
}

#[test]
fn a_snapshot_is_told_from_a_scene_past_comments_and_attributes() {
    // A snapshot opening with a block comment was read as a scene ("Expected struct Scene but
    // found Snapshot").
    assert!(Snapshot::is_snapshot_text(
        "// a note\n/* a block\n   comment */ #![enable(implicit_some)]\n  Snapshot(format: 3)"
    ));
    assert!(Snapshot::is_snapshot_text("Snapshot("));
    assert!(!Snapshot::is_snapshot_text("/* Snapshot( */ Scene()"));
    assert!(!Snapshot::is_snapshot_text("Scene(name: \"Snapshot(\")"));
    assert!(!Snapshot::is_snapshot_text("/* never closed Snapshot("));
}
