//! Loads a scene file, runs it with both resolvers, and prints what each did: the same
//! summary `jostle run` prints, from the library.
//!
//! Run: `cargo run --release --example scene_file -- assets/stack_15.ron` (default:
//! `assets/box_drop.ron`).

use jostle::scene::Scene;
use jostle::{MillingtonSettings, ResolverChoice, SoftStepSettings, WorldSettings};
use std::time::Instant;

const DEFAULT_SCENE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/box_drop.ron");

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| DEFAULT_SCENE.into());
    run(&path)
}

fn run(path: &str) -> Result<(), Box<dyn std::error::Error>> {
    // A bad file is an error naming the file and line:column, or the body and the field.
    let scene = Scene::load(path)?;
    println!("{} ({} steps of {} s)", scene.name, scene.steps, scene.dt);

    for resolver in [
        ResolverChoice::SoftStep(SoftStepSettings::default()),
        ResolverChoice::Millington(MillingtonSettings::default()),
    ] {
        // The scene's own settings (gravity, sleep, collision), with this resolver.
        let settings = WorldSettings {
            resolver,
            ..scene.settings()
        };
        let mut world = scene.build_with(settings)?;
        let start = Instant::now();
        let mut deepest = 0.0f32;
        for _ in 0..scene.steps {
            world.step(scene.dt)?;
            deepest = deepest.max(world.max_penetration());
        }
        let ms = start.elapsed().as_secs_f64() * 1e3 / f64::from(scene.steps.max(1));
        println!(
            "  {:10} {:8.3} ms/step, kinetic energy at the end {:10.4} J, deepest overlap {:.4} m",
            world.resolver_name(),
            ms,
            world.kinetic_energy(),
            deepest
        );
    }
    Ok(())
}

#[test]
fn runs() {
    run(DEFAULT_SCENE).expect("the example runs");
}
