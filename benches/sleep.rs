//! Sleeping islands cost nothing: ms/step of 1,000 boxes in 200 separate piles once every
//! island sleeps, against the same settled scene with sleeping disabled (benches/RESULTS.md, "Sleeping
//! islands cost nothing"). Run: `cargo bench --bench sleep`.

use criterion::{Criterion, criterion_group, criterion_main};
use jostle::World;
use jostle::scene::Scene;
use std::hint::black_box;

const DT: f32 = 1.0 / 60.0;

fn scene() -> Scene {
    Scene::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/piles_1000.ron"
    ))
    .expect("asset loads")
}

/// The scene after it has settled: every island asleep (sleeping on) or simply at rest.
fn settled(sleep: bool) -> World {
    let scene = scene();
    let mut settings = scene.settings();
    settings.sleep.enabled = sleep;
    let mut world = scene.build_with(settings).expect("scene builds");
    for _ in 0..1200 {
        world.step(DT).expect("step");
        if sleep && world.profile().awake_bodies == 0 {
            break;
        }
    }
    if sleep {
        assert_eq!(
            world.profile().awake_bodies,
            0,
            "every pile must be asleep before measuring"
        );
    }
    world
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("piles_1000");
    group.sample_size(20);
    let mut asleep = settled(true);
    group.bench_function("all_asleep", |b| {
        b.iter(|| black_box(asleep.step(DT).expect("step")))
    });
    let mut awake = settled(false);
    group.bench_function("sleep_disabled", |b| {
        b.iter(|| black_box(awake.step(DT).expect("step")))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
