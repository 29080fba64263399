//! Fast piles side by side with rapier3d 0.36 at its defaults (issue 18 item 4): the box
//! lattices `assets/lattice_4000.ron` and `assets/lattice_4000_offset.ron` dropped in both
//! engines (jostle's ground half-space is a fixed 4,000 m cuboid in rapier3d with its top face at
//! y = 0; μ 0.6 on both sides; sleeping on in both, as the scenes declare), one run each of the
//! scene's 300 steps; the table gives the deepest overlap of any contact over the run and the
//! mean wall time per step (the penetration measuring included in neither).
//!
//! Run: `cargo bench -p jostle-compare --bench penetration` (about a minute). With `--test`
//! (`cargo test -p jostle-compare --benches`) only 20 steps of the first scene run.

#[path = "../../../benches/common/mod.rs"]
mod common;

use jostle::scene::Scene;
use rapier3d::prelude as rp;
use std::time::{Duration, Instant};

/// The scene's boxes in rapier3d at its defaults (dt 1/60).
fn rapier_world(scene: &Scene) -> rp::PhysicsWorld {
    let mut world = rp::PhysicsWorld {
        gravity: rp::Vector::new(0.0, -9.81, 0.0),
        ..Default::default()
    };
    world.integration_parameters.dt = scene.dt;
    for desc in scene.body_descs().expect("scene bodies") {
        let friction = desc.material.friction;
        if desc.fixed {
            world.insert(
                rp::RigidBodyBuilder::fixed().translation(rp::Vector::new(0.0, -1.0, 0.0)),
                rp::ColliderBuilder::cuboid(2000.0, 1.0, 2000.0).friction(friction),
            );
            continue;
        }
        let jostle::ShapeDesc::Cuboid { half_extents: h } = desc.shape else {
            panic!("{}: only cuboids", scene.name);
        };
        let jostle::MassSpec::Density(density) = desc.mass else {
            panic!("{}: densities only", scene.name);
        };
        let (p, q) = (desc.position, desc.rotation);
        world.insert(
            rp::RigidBodyBuilder::dynamic()
                .translation(rp::Vector::new(p.x, p.y, p.z))
                .rotation(rp::Rotation::from_xyzw(q.x, q.y, q.z, q.w).to_scaled_axis()),
            rp::ColliderBuilder::cuboid(h.x, h.y, h.z)
                .density(density)
                .friction(friction),
        );
    }
    world
}

/// Deepest overlap (m) and mean time per step (ms) of `steps` steps of jostle at the scene's
/// settings.
fn jostle_run(scene: &Scene, steps: u32) -> (f32, f64) {
    let mut world = scene.build().expect("scene builds");
    let (mut deepest, mut time) = (0.0f32, Duration::ZERO);
    for _ in 0..steps {
        let t = Instant::now();
        world.step(scene.dt).expect("step");
        time += t.elapsed();
        deepest = deepest.max(world.max_penetration());
    }
    (deepest, time.as_secs_f64() * 1e3 / f64::from(steps))
}

/// The same for rapier3d.
fn rapier_run(scene: &Scene, steps: u32) -> (f32, f64) {
    let mut world = rapier_world(scene);
    let (mut deepest, mut time) = (0.0f32, Duration::ZERO);
    for _ in 0..steps {
        let t = Instant::now();
        world.step();
        time += t.elapsed();
        for pair in world.narrow_phase.contact_pairs() {
            for m in pair.manifolds() {
                for p in &m.points {
                    deepest = deepest.max(-p.dist);
                }
            }
        }
    }
    (deepest, time.as_secs_f64() * 1e3 / f64::from(steps))
}

fn main() {
    let smoke = common::smoke();
    let scenes: &[&str] = if smoke {
        &["lattice_4000"]
    } else {
        &["lattice_4000", "lattice_4000_offset"]
    };
    println!("| scene | engine | deepest overlap (m) | ms/step |");
    println!("|---|---|---:|---:|");
    for name in scenes {
        let scene = common::scene(name);
        let steps = if smoke { 20 } else { scene.steps };
        let (jd, jt) = jostle_run(&scene, steps);
        println!("| {name} | jostle | {jd:.3} | {jt:.2} |");
        let (rd, rt) = rapier_run(&scene, steps);
        println!("| {name} | rapier3d 0.36 | {rd:.3} | {rt:.2} |");
    }
}
