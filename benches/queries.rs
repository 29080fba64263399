//! Scene queries among many colliders: a ray cast (first hit) and a point projection in a
//! level of n fixed boxes on a grid (n = 100, 1,000, 10,000), through the broad phase's tree
//! (after `World::update_queries`) and by brute force (the same world without it). Through the
//! tree the cost should grow like log n, by brute force like n (benches/RESULTS.md, "Scene
//! queries through the tree"). Run: `cargo bench --bench queries`.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use jostle::{BodyDesc, QueryFilter, ShapeDesc, Vec3, World, WorldSettings};
use std::hint::black_box;

/// n fixed 1 m boxes on a square grid 3 m apart at y 0.5, with a ground below.
fn level(n: usize) -> World {
    let mut w = World::new(WorldSettings::default());
    w.add_body(BodyDesc::fixed(
        "ground",
        ShapeDesc::HalfSpace { normal: Vec3::Y },
    ))
    .expect("ground");
    let side = (n as f32).sqrt().ceil() as usize;
    for i in 0..n {
        let (x, z) = ((i % side) as f32 * 3.0, (i / side) as f32 * 3.0);
        w.add_body(
            BodyDesc::fixed(
                format!("box {i}"),
                ShapeDesc::Cuboid {
                    half_extents: Vec3::splat(0.5),
                },
            )
            .at(Vec3::new(x, 0.5, z)),
        )
        .expect("box");
    }
    w
}

/// Rays from above the level's middle, slanting down across it, and points beside boxes.
fn probes(n: usize) -> Vec<(Vec3, Vec3)> {
    let extent = (n as f32).sqrt().ceil() * 3.0;
    (0..64)
        .map(|k| {
            let t = k as f32 / 64.0;
            let origin = Vec3::new(extent * t, 3.0, extent * (1.0 - t));
            let dir = Vec3::new((t * 7.0).sin(), -0.4, (t * 5.0).cos());
            (origin, dir)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let all = QueryFilter::default();
    let mut group = c.benchmark_group("queries");
    for n in [100usize, 1_000, 10_000] {
        let stale = level(n);
        let mut fresh = level(n);
        fresh.update_queries();
        assert!(fresh.queries_use_tree() && !stale.queries_use_tree());
        let rays = probes(n);
        for (label, w) in [("tree", &fresh), ("brute_force", &stale)] {
            group.bench_with_input(
                BenchmarkId::new(format!("ray_cast/{label}"), n),
                &rays,
                |b, rays| {
                    b.iter(|| {
                        for &(o, d) in rays {
                            black_box(w.queries().ray_cast(o, d, 50.0, &all));
                        }
                    })
                },
            );
            group.bench_with_input(
                BenchmarkId::new(format!("project_point/{label}"), n),
                &rays,
                |b, rays| {
                    b.iter(|| {
                        for &(o, _) in rays {
                            black_box(w.queries().project_point(o, 50.0, &all));
                        }
                    })
                },
            );
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
