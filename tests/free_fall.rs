//! Free fall through the facade follows semi-implicit Euler exactly at each resolver's
//! integration step h (dt for Millington, dt / substeps for the soft step): after N = n·dt/h
//! integration steps, y = y0 + v0·N·h − g·h²·N(N+1)/2, at 60 Hz and at a finer step.

use jostle::{BodyDesc, MillingtonSettings, ResolverChoice, ShapeDesc, SoftStepSettings, Vec3};
use jostle::{World, WorldSettings};

fn check_free_fall(dt: f32, steps: u32) {
    for resolver in [
        ResolverChoice::default(),
        ResolverChoice::Millington(MillingtonSettings::default()),
        ResolverChoice::SoftStep(SoftStepSettings::default()),
    ] {
        check_free_fall_with(resolver, dt, steps);
    }
}

fn check_free_fall_with(resolver: ResolverChoice, dt: f32, steps: u32) {
    let substeps = match &resolver {
        ResolverChoice::Millington(_) => 1,
        ResolverChoice::SoftStep(s) => s.substeps.max(1),
    };
    let name = resolver.name();
    let mut world = World::new(WorldSettings {
        resolver,
        ..WorldSettings::default()
    });
    let (y0, v0) = (100.0f32, 3.0f32);
    let h = world
        .add_body(
            BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 })
                .at(Vec3::new(0.0, y0, 0.0))
                .moving(Vec3::new(0.0, v0, 0.0), Vec3::ZERO),
        )
        .unwrap();
    let g = 9.81f64;
    let mut worst = 0.0f64;
    for n in 1..=steps {
        world.step(dt).unwrap();
        let n = (n * substeps) as f64;
        let d = dt as f64 / substeps as f64;
        let expected = y0 as f64 + v0 as f64 * n * d - g * d * d * n * (n + 1.0) / 2.0;
        let y = world.body(h).unwrap().position.y as f64;
        worst = worst.max((y - expected).abs());
    }
    // f32 round-off only: positions near 100 m carry ~1e-5 m of representation error per step.
    assert!(
        worst < 2e-4 * steps as f64 / 60.0 + 1e-4,
        "{name}, dt {dt}: worst deviation {worst} m"
    );
    let b = world.body(h).unwrap();
    assert_eq!(b.position.x, 0.0);
    assert_eq!(b.angular_velocity, Vec3::ZERO);
}

#[test]
fn free_fall_at_60_hz() {
    check_free_fall(1.0 / 60.0, 120);
}

#[test]
fn free_fall_at_240_hz() {
    check_free_fall(1.0 / 240.0, 480);
}
