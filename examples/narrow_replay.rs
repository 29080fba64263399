//! The narrow phase alone over a recorded trajectory: a scene is stepped to `FROM`, then its
//! bodies' states are recorded for `STEPS` steps, and the broad and narrow phases are run
//! again over the recorded states (five rounds, each from an empty narrow phase; the best
//! round's time per update is printed, with the contact points found). Every build replays
//! the same states, so two commits' narrow phases compare on the same pairs, which a chaotic
//! scene run through the whole pipeline would not give them (its trajectory follows the
//! rounding of every change).
//!
//! Run: `cargo run --release --example narrow_replay -- SCENE.ron FROM STEPS`, for example
//! `cargo run --release --example narrow_replay -- assets/rain_1000.ron 60 120`.

use jostle::scene::Scene;
use jostle_body::BodySet;
use jostle_collide::{BroadPhase, CollideSettings, ColliderSet, NarrowPhase};
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// The step of the replayed run (s).
const DT: f32 = 1.0 / 60.0;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: narrow_replay SCENE.ron FROM STEPS";
    let (Some(path), Some(Ok(from)), Some(Ok(steps))) = (
        args.get(1),
        args.get(2).map(|s| s.parse::<usize>()),
        args.get(3).map(|s| s.parse::<usize>()),
    ) else {
        eprintln!("{usage}");
        return ExitCode::FAILURE;
    };
    match replay(path, from, steps) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

fn replay(path: &str, from: usize, steps: usize) -> Result<(), Box<dyn std::error::Error>> {
    let mut world = Scene::load(path)?.build()?;
    for _ in 0..from {
        world.step(DT)?;
    }
    let handles: Vec<_> = world.bodies().map(|(h, _, _)| h).collect();
    let mut frames = Vec::with_capacity(steps);
    for _ in 0..steps {
        frames.push(
            handles
                .iter()
                .filter_map(|&h| world.body(h).cloned())
                .collect::<Vec<_>>(),
        );
        world.step(DT)?;
    }
    // The same bodies and colliders in sets of their own.
    let mut bodies = BodySet::new();
    let mut colliders = ColliderSet::new();
    let mut copies = Vec::with_capacity(handles.len());
    for &h in &handles {
        let Some(body) = world.body(h) else { continue };
        let copy = bodies.insert(body.clone());
        copies.push(copy);
        for c in world.colliders_of(h) {
            if let Some(collider) = world.collider(c) {
                let mut collider = collider.clone();
                collider.body = copy;
                colliders.insert(collider);
            }
        }
    }
    let settings = CollideSettings::default();
    let mut best = Duration::MAX;
    let mut points = 0;
    for _ in 0..5 {
        let mut broad = BroadPhase::new();
        let mut narrow = NarrowPhase::new();
        let mut total = Duration::ZERO;
        points = 0;
        for frame in &frames {
            for (&copy, state) in copies.iter().zip(frame) {
                if let Some(body) = bodies.get_mut(copy) {
                    *body = state.clone();
                }
            }
            let pairs = broad
                .update_swept(&colliders, &bodies, settings.prediction, DT)
                .to_vec();
            let t = Instant::now();
            let stats = narrow.update_swept(&pairs, &colliders, &bodies, &settings, None, DT);
            total += t.elapsed();
            points += stats.contact_points;
        }
        best = best.min(total);
    }
    println!(
        "{path}: {} updates from step {from}, {points} contact points, narrow phase {:.3} ms an update (best of 5)",
        frames.len(),
        best.as_secs_f64() * 1e3 / frames.len().max(1) as f64
    );
    Ok(())
}
