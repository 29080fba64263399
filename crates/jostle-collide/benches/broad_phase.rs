//! Broad-phase update cost for n moving boxes, n = 1,000 … 16,000.
//!
//! The boxes (half extents 0.2–0.5 m) are scattered in a cube whose volume grows with n, so
//! the density, and so the number of pairs per body, stays constant: a broad phase that scales
//! as n log n shows a per-body time that grows only slowly with n. Every iteration moves every
//! body a little (a random walk of up to 2 cm per axis) and updates the broad phase once.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use jostle_body::{BodyHandle, BodySet, RigidBody};
use jostle_collide::{BroadPhase, Collider, ColliderSet, SharedShape};
use jostle_math::{Mat3, Quat, Vec3};
use std::hint::black_box;

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn scene(n: usize) -> (BodySet, ColliderSet, Vec<BodyHandle>) {
    let mut rng = Rng(n as u64);
    // About one body per 8 m³: side = 2·n^(1/3).
    let side = 2.0 * (n as f32).cbrt();
    let mut bodies = BodySet::new();
    let mut colliders = ColliderSet::new();
    let mut handles = Vec::with_capacity(n);
    for _ in 0..n {
        let p = Vec3::new(rng.next(), rng.next(), rng.next()) * side;
        let q = Quat::from_rotation_y(rng.next() * std::f32::consts::TAU)
            * Quat::from_rotation_x(rng.next() * std::f32::consts::TAU);
        let h = Vec3::new(rng.next(), rng.next(), rng.next()) * 0.3 + 0.2;
        let body = RigidBody::dynamic(1.0, Mat3::IDENTITY)
            .expect("valid mass")
            .with_pose(p, q);
        let handle = bodies.insert(body);
        colliders.insert(Collider::new(SharedShape::cuboid(h.x, h.y, h.z), handle));
        handles.push(handle);
    }
    (bodies, colliders, handles)
}

fn broad_phase(c: &mut Criterion) {
    let mut group = c.benchmark_group("broad_phase_update");
    group.sample_size(10);
    for n in [1_000usize, 2_000, 4_000, 8_000, 16_000] {
        let (mut bodies, colliders, handles) = scene(n);
        let mut bp = BroadPhase::new();
        bp.update(&colliders, &bodies, 0.01);
        let mut rng = Rng(7);
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                for &h in &handles {
                    if let Some(body) = bodies.get_mut(h) {
                        body.position +=
                            (Vec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * 0.04;
                    }
                }
                black_box(bp.update(&colliders, &bodies, 0.01).len())
            })
        });
        eprintln!("n = {n}: {} pairs", bp.pairs().len());
    }
    group.finish();
}

criterion_group!(benches, broad_phase);
criterion_main!(benches);
