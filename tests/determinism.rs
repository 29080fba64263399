//! Determinism is a tested contract: the same scene and settings give
//! bit-identical results across runs, a golden hash pins the final state of a 500-step scene,
//! and a snapshot continues a run bit for bit.
//!
//! The golden hash changes whenever the physics intentionally changes. To update it, run
//!
//! ```sh
//! JOSTLE_UPDATE_GOLDEN=1 cargo test --test determinism
//! ```
//!
//! and commit `tests/golden/determinism_500.hash` with the change that explains it. The hash is
//! for x86-64 with SSE2 (glam's default there); other targets may round differently.

use jostle::World;
use jostle::scene::Scene;
use jostle::snapshot::Snapshot;

const DT: f32 = 1.0 / 60.0;

fn scene(name: &str) -> Scene {
    Scene::load(format!("{}/assets/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

fn hashes(world: &mut World, steps: u32) -> Vec<u64> {
    (0..steps)
        .map(|_| {
            world.step(DT).unwrap();
            world.state_hash()
        })
        .collect()
}

#[test]
fn the_same_scene_gives_bit_identical_runs() {
    let s = scene("determinism.ron");
    let a = hashes(&mut s.build().unwrap(), 200);
    let b = hashes(&mut s.build().unwrap(), 200);
    assert_eq!(a, b);
    assert!(
        a.windows(2).any(|w| w[0] != w[1]),
        "the scene must actually move"
    );
}

#[test]
fn golden_hash_after_500_steps_of_the_determinism_scene() {
    let mut world = scene("determinism.ron").build().unwrap();
    let hash = *hashes(&mut world, 500).last().unwrap();
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/golden/determinism_500.hash"
    );
    if std::env::var_os("JOSTLE_UPDATE_GOLDEN").is_some() {
        std::fs::write(path, format!("{hash:016x}\n")).unwrap();
        return;
    }
    let golden =
        std::fs::read_to_string(path).expect("golden file; see this file's docs to create it");
    assert_eq!(
        format!("{hash:016x}"),
        golden.trim(),
        "the final state changed; if intended, update the golden hash (see the module docs)"
    );
}

/// N steps, snapshot through a file, M steps == N + M steps, bit for bit, every step.
fn snapshot_continues_exactly(scene_file: &str, n: u32, m: u32) {
    let s = scene(scene_file);
    let mut straight = s.build().unwrap();
    let expected = hashes(&mut straight, n + m);

    let mut first = s.build().unwrap();
    hashes(&mut first, n);
    let path = std::env::temp_dir().join(format!(
        "jostle-snapshot-{}-{scene_file}",
        std::process::id()
    ));
    first.snapshot(&s.name, DT).save(&path).unwrap();
    let mut resumed = World::from_snapshot(Snapshot::load(&path).unwrap()).unwrap();
    assert_eq!(
        resumed.state_hash(),
        expected[n as usize - 1],
        "restored state differs"
    );
    let continued = hashes(&mut resumed, m);
    assert_eq!(
        continued,
        expected[n as usize..],
        "{scene_file}: the continued run diverged"
    );
    std::fs::remove_file(path).ok();
}

#[test]
fn a_snapshot_continues_a_run_bit_for_bit() {
    // Mixed shapes, a mesh and a pyramid in motion, manifolds reused across the snapshot.
    snapshot_continues_exactly("determinism.ron", 150, 150);
    // Sleep state: the box falls asleep after the snapshot (step ≈ 323) exactly as it would.
    snapshot_continues_exactly("box_drop.ron", 200, 200);
}

/// Two runs of the same scene write the same snapshot, byte for byte (issue 16: the narrow
/// phase's reuse records wrote the shapes' heap addresses, which differ from run to run).
#[test]
fn identical_runs_write_identical_snapshots() {
    let s = scene("determinism.ron");
    let text = || {
        let mut world = s.build().unwrap();
        hashes(&mut world, 60);
        world.snapshot(&s.name, DT).to_ron().unwrap()
    };
    let (first, second) = (text(), text());
    assert!(
        first.contains("computed: Some("),
        "no reuse record was written"
    );
    assert!(
        first == second,
        "two identical runs wrote different snapshots"
    );
}

/// Snapshots name their format: this build writes `SNAPSHOT_FORMAT`, reads formats from
/// `OLDEST_SNAPSHOT_FORMAT` on (a format 2 snapshot has no record of where each pair's
/// contacts are, and restores from its points), and refuses a later one by number.
#[test]
fn snapshot_formats_are_read_from_the_oldest_supported_and_later_ones_refused() {
    use jostle::snapshot::{OLDEST_SNAPSHOT_FORMAT, SNAPSHOT_FORMAT};
    let s = scene("box_drop.ron");
    let mut world = s.build().unwrap();
    hashes(&mut world, 30);
    let text = world.snapshot(&s.name, DT).to_ron().unwrap();
    let current = format!("format: {SNAPSHOT_FORMAT},");
    assert!(
        text.contains(&current),
        "written as format {SNAPSHOT_FORMAT}"
    );
    let dir = std::env::temp_dir();
    for (format, readable) in [
        (OLDEST_SNAPSHOT_FORMAT, true),
        (SNAPSHOT_FORMAT, true),
        (SNAPSHOT_FORMAT + 1, false),
        (OLDEST_SNAPSHOT_FORMAT - 1, false),
    ] {
        let path = dir.join(format!("jostle-format-{format}-{}", std::process::id()));
        std::fs::write(
            &path,
            text.replacen(&current, &format!("format: {format},"), 1),
        )
        .unwrap();
        match Snapshot::load(&path) {
            Ok(snapshot) => {
                assert!(readable, "format {format} was read");
                World::from_snapshot(snapshot).unwrap();
            }
            Err(e) => {
                assert!(!readable, "format {format}: {e}");
                assert!(e.to_string().contains(&format!("format {format}")), "{e}");
            }
        }
        std::fs::remove_file(path).ok();
    }
}

/// The snapshot text of the asset `file` after `steps` steps, written to a temporary file
/// (named with `tag`) and read back.
fn snapshot_text(file: &str, steps: usize, tag: &str) -> String {
    let s = scene(file);
    let mut world = s.build().unwrap();
    for _ in 0..steps {
        world.step(DT).unwrap();
    }
    let path = std::env::temp_dir().join(format!("jostle-{tag}-snapshot-{}", std::process::id()));
    world.snapshot(&s.name, DT).save(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_file(&path).ok();
    text
}

/// A snapshot edited by hand into settings a scene file would refuse is refused too, naming
/// the setting, instead of running with them (`substeps: 0`, NaN gravity) or stopping the
/// process on an assertion in parry (a negative `collide.prediction`) (issue 16).
#[test]
fn a_snapshot_with_invalid_settings_is_refused_by_name() {
    let text = snapshot_text("box_drop.ron", 1, "bad");
    assert!(World::from_snapshot(Snapshot::parse(&text, "good").unwrap()).is_ok());
    let edits = [
        ("substeps: 8", "substeps: 0", "settings.resolver.substeps"),
        (
            "prediction: 0.02",
            "prediction: -1.0",
            "settings.collide.prediction",
        ),
        (
            "frame_angle_tolerance: 0.05",
            "frame_angle_tolerance: 7.0",
            "settings.collide.frame_angle_tolerance",
        ),
        (
            "gravity: Vec3(0.0, -9.81, 0.0)",
            "gravity: Vec3(NaN, -9.81, 0.0)",
            "settings.gravity",
        ),
        // A threshold of −1 put every body to sleep at its first step.
        (
            "threshold: 0.3",
            "threshold: -1.0",
            "settings.sleep.threshold",
        ),
        (
            "bias_base: 0.5",
            "bias_base: 5.0",
            "settings.sleep.bias_base",
        ),
        // A step count at u64's end wrapped the trace's step numbers to 0.
        (
            "\n    steps: 1,",
            "\n    steps: 18446744073709551614,",
            "steps: must be at most",
        ),
    ];
    for (from, to, field) in edits {
        assert!(
            text.contains(from),
            "the snapshot text has no `{from}`:\n{text}"
        );
        let bad = text.replacen(from, to, 1);
        let err = match World::from_snapshot(Snapshot::parse(&bad, "bad").unwrap()) {
            Ok(_) => panic!("`{to}` was accepted"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains(field), "`{to}`: {err}");
    }
}

/// A snapshot whose sleeping islands were edited into references that do not exist is
/// refused with what is wrong, instead of panicking on an index when a body wakes (issue 16:
/// `crates/jostle-sleep/src/islands.rs` indexed the island list unchecked).
#[test]
fn a_snapshot_with_broken_islands_is_refused() {
    let text = snapshot_text("pyramid20.ron", 100, "islands");
    let at = text.find("sleeping_of: [").expect("an islands section");
    let (head, tail) = text.split_at(at);
    assert!(tail.contains("Some(0)"), "nothing asleep after 100 steps");
    let bad = format!("{head}{}", tail.replacen("Some(0)", "Some(7)", 1));
    let err = match World::from_snapshot(Snapshot::parse(&bad, "bad").unwrap()) {
        Ok(_) => panic!("a snapshot naming a missing island was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("islands") && err.contains("island 7"), "{err}");
    assert!(World::from_snapshot(Snapshot::parse(&text, "good").unwrap()).is_ok());
}

/// A snapshot whose pair with contact points claims a direction that keeps it apart (which
/// would skip its contact query and leave its points unrefreshed) is refused, naming the pair.
#[test]
fn a_snapshot_keeping_a_touching_pair_apart_is_refused() {
    let text = snapshot_text("pyramid20.ron", 1, "apart");
    // Every pair of the resting pyramid touches: the first pair's record gets a direction.
    assert!(
        text.contains("apart: None"),
        "no pair records its direction"
    );
    let bad = text.replacen("apart: None", "apart: Some((0.0, 1.0, 0.0))", 1);
    let err = match World::from_snapshot(Snapshot::parse(&bad, "bad").unwrap()) {
        Ok(_) => panic!("a touching pair kept apart was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("apart") && err.contains("contact points"),
        "{err}"
    );
    assert!(World::from_snapshot(Snapshot::parse(&text, "good").unwrap()).is_ok());
}
