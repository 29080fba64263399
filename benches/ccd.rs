//! CCD costs nothing for bodies that are slow for their size (benches/RESULTS.md, "Skip what a
//! scene does not need"; issue 10): ms/step of the 20-row pyramid (210 boxes, no fast body) with continuous
//! collision detection enabled against the same scene with it disabled. Sleeping is off in this
//! scene, so every step runs the CCD motion test of all 210 boxes. Both worlds are settled for
//! 10 s first, so the two measure the same resting state. Run: `cargo bench --bench ccd`.

use criterion::{Criterion, criterion_group, criterion_main};
use jostle::World;
use jostle::scene::Scene;
use std::hint::black_box;

const DT: f32 = 1.0 / 60.0;

fn world(ccd: bool) -> World {
    let scene = Scene::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/pyramid_20.ron"
    ))
    .expect("asset loads");
    let mut settings = scene.settings();
    settings.collide.ccd.enabled = ccd;
    let mut world = scene.build_with(settings).expect("scene builds");
    for _ in 0..600 {
        world.step(DT).expect("step");
    }
    world
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("pyramid_20");
    group.sample_size(30);
    let mut on = world(true);
    let mut off = world(false);
    group.bench_function("ccd_enabled", |b| {
        b.iter(|| {
            black_box(on.step(DT).expect("step"));
            assert_eq!(on.profile().ccd_bodies, 0, "no body is fast in this scene");
        })
    });
    group.bench_function("ccd_disabled", |b| {
        b.iter(|| black_box(off.step(DT).expect("step")))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
