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
fn run(threads: usize, steps: u32) -> (Vec<u64>, u32, usize) {
    jostle::set_threads(threads);
    let scene = Scene::load(format!(
        "{}/assets/rain_1000.ron",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
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
    // 90 steps: the rain lands and piles up, with more than a thousand manifolds.
    let (one, teams, parts) = run(1, 90);
    assert_eq!((teams, parts), (1, 1));
    for threads in [2, 3] {
        let (hashes, teams, parts) = run(threads, 90);
        assert_eq!(
            teams, threads as u32,
            "{threads} threads: no step ran on a team of that size"
        );
        assert_eq!(
            parts, threads,
            "{threads} threads: no step split the narrow phase's pairs that many ways"
        );
        let first = one.iter().zip(&hashes).position(|(a, b)| a != b);
        assert_eq!(
            first, None,
            "{threads} threads differ from one from that step on"
        );
    }
    jostle::set_threads(0);
}
