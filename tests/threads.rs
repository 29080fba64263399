//! The soft step's substeps and the narrow phase's pairs on several threads
//! (`jostle::set_threads`, the `parallel` feature) give bit-identical results for any number
//! of threads: within a stage the threads solve batches that write disjoint bodies, and the
//! narrow phase's parts write lists of their own, joined in order, so the order they run in
//! cannot matter. Its own test binary, so that no other test's world holds the helper threads
//! while this one steps.

use jostle::scene::Scene;

const DT: f32 = 1.0 / 60.0;

/// The state hash after each step of `steps`, and the most threads any step's team had
/// (the resolver's, and the parts of the narrow phase's pairs).
fn run(scene: &str, threads: usize, steps: u32) -> (Vec<u64>, u32, usize) {
    jostle::set_threads(threads);
    let scene = Scene::load(format!("{}/assets/{scene}", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let mut world = scene.build().unwrap();
    let (mut most, mut parts) = (0, 0);
    let hashes = (0..steps)
        .map(|_| {
            world.step(DT).unwrap();
            most = most.max(world.profile().resolve_stats.threads);
            parts = parts.max(world.profile().narrow_parts);
            world.state_hash()
        })
        .collect();
    (hashes, most, parts)
}

#[test]
fn any_number_of_threads_gives_bit_identical_steps() {
    // 90 steps: the rain lands and piles up, with more than a thousand manifolds whose
    // batches change from step to step; 20-row pyramid: batches kept from step to step, whose
    // items on a team wait only for the items before them on their bodies.
    for (scene, steps) in [("rain_1000.ron", 90), ("pyramid_20.ron", 120)] {
        same_for_any_threads(scene, steps);
    }
}

/// The state hashes of `steps` steps of `scene` on one, two and three threads agree.
fn same_for_any_threads(scene: &str, steps: u32) {
    let (one, teams, parts) = run(scene, 1, steps);
    assert_eq!((teams, parts), (1, 1));
    for threads in [2, 3] {
        let (hashes, teams, parts) = run(scene, threads, steps);
        assert_eq!(
            teams, threads as u32,
            "{scene}, {threads} threads: no step ran on a team of that size"
        );
        assert_eq!(
            parts, threads,
            "{scene}, {threads} threads: no step split the narrow phase's pairs that many ways"
        );
        let first = one.iter().zip(&hashes).position(|(a, b)| a != b);
        assert_eq!(
            first, None,
            "{scene}, {threads} threads differ from one from that step on"
        );
    }
    jostle::set_threads(0);
}
