//! Shared builders for the physics validation tests: small worlds with closed-form answers, and
//! the stability family ([`family`]).
#![allow(dead_code)]

pub mod family;

use jostle::{
    BodyDesc, BodyHandle, MillingtonSettings, Quat, ResolverChoice, ShapeDesc, SoftStepSettings,
    Vec3, World, WorldSettings,
};

/// The time steps every analytic test runs at: 60 Hz and a finer 240 Hz.
pub const STEPS: [f32; 2] = [1.0 / 60.0, 1.0 / 240.0];

/// Both resolvers with their default settings: every physical test runs with each.
pub fn resolvers() -> [ResolverChoice; 2] {
    [
        ResolverChoice::Millington(MillingtonSettings::default()),
        ResolverChoice::SoftStep(SoftStepSettings::default()),
    ]
}

/// A world with the default resolver.
pub fn world(gravity: Vec3) -> World {
    World::new(WorldSettings {
        gravity,
        ..Default::default()
    })
}

/// A world with the given resolver.
pub fn world_with(gravity: Vec3, resolver: &ResolverChoice) -> World {
    World::new(WorldSettings {
        gravity,
        resolver: resolver.clone(),
        ..Default::default()
    })
}

pub fn ground(world: &mut World, friction: f32, restitution: f32) -> BodyHandle {
    world
        .add_body(
            BodyDesc::fixed("ground", ShapeDesc::HalfSpace { normal: Vec3::Y })
                .with_material(friction, restitution),
        )
        .unwrap()
}

pub fn ball(world: &mut World, name: &str, radius: f32, mass: f32, at: Vec3) -> BodyHandle {
    world
        .add_body(
            BodyDesc::dynamic(name, ShapeDesc::Ball { radius })
                .with_mass(mass)
                .at(at),
        )
        .unwrap()
}

pub fn set_material(desc: BodyDesc, friction: f32, restitution: f32) -> BodyDesc {
    desc.with_material(friction, restitution)
}

/// Steps `world` for `seconds` at `dt`, calling `f` after each step.
pub fn run(world: &mut World, dt: f32, seconds: f32, mut f: impl FnMut(&World)) {
    let n = (seconds / dt).round() as u32;
    for _ in 0..n {
        world.step(dt).unwrap();
        f(world);
    }
}

/// A fixed slope through the origin tilted by `theta` about Z (descending toward +X).
pub fn slope(world: &mut World, theta: f32, friction: f32) -> BodyHandle {
    let normal = Quat::from_rotation_z(-theta) * Vec3::Y;
    world
        .add_body(
            BodyDesc::fixed("slope", ShapeDesc::HalfSpace { normal }).with_material(friction, 0.0),
        )
        .unwrap()
}

pub fn momentum(world: &World) -> Vec3 {
    world
        .bodies()
        .filter(|(_, _, b)| !b.is_fixed())
        .map(|(_, _, b)| b.linear_velocity * b.mass())
        .sum()
}

/// proptest's seeded generator (ChaCha), so that every run of a test sees the same draws.
pub struct SeededRng(proptest::test_runner::TestRng);

impl SeededRng {
    /// The generator of `seed`.
    pub fn new(seed: u64) -> Self {
        let mut bytes = [0u8; 32];
        bytes[..8].copy_from_slice(&seed.to_le_bytes());
        Self(proptest::test_runner::TestRng::from_seed(
            proptest::test_runner::RngAlgorithm::ChaCha,
            &bytes,
        ))
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f32, hi: f32) -> f32 {
        use proptest::prelude::Rng as _;
        lo + (hi - lo) * ((self.0.next_u64() >> 40) as f32 / (1u64 << 24) as f32)
    }

    /// One of `items`, uniformly.
    pub fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        use proptest::prelude::Rng as _;
        items[(self.0.next_u64() % items.len() as u64) as usize]
    }
}
