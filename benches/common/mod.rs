//! Helpers shared by the criterion benches of the facade (`mod common;` in each) and of
//! `jostle-compare` (included by path): finding the workspace, loading the
//! benchmark scenes of `assets/`, settling a world, a short criterion configuration, and
//! reading criterion's median back for the tables the benches print after their groups.
//!
//! Not every bench uses every helper, hence the `dead_code` allowance.
#![allow(dead_code)]

use criterion::Criterion;
use jostle::World;
use jostle::scene::Scene;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The time step of every facade bench (s).
pub const DT: f32 = 1.0 / 60.0;

/// The benchmark set of issue 7, by asset name (`assets/<name>.ron`), in table order.
pub const SCENES: [&str; 9] = [
    "pyramid_20",
    "pyramid3d_10",
    "wall_20x10",
    "stack_15",
    "pyramid_heavy_top",
    "mass_ratio_1000",
    "card_house",
    "rain_1000",
    "piles_4000",
];

/// The workspace's root directory: the nearest ancestor of the bench's crate that holds
/// `assets/` (the facade's crate is the root; `jostle-compare` sits two levels below it).
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .find(|dir| dir.join("assets").is_dir())
        .expect("the workspace's assets/ directory")
}

/// Loads `assets/<name>.ron`.
pub fn scene(name: &str) -> Scene {
    Scene::load(root().join(format!("assets/{name}.ron"))).unwrap_or_else(|e| panic!("{e}"))
}

/// The scene with its own settings (resolver, sleep), stepped `steps` times at [`DT`].
pub fn settled(name: &str, steps: usize) -> World {
    let mut world = scene(name)
        .build()
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    for _ in 0..steps {
        world.step(DT).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    world
}

/// Dynamic bodies of a world.
pub fn dynamic_bodies(world: &World) -> usize {
    world.bodies().filter(|(_, _, b)| !b.is_fixed()).count()
}

/// The short configuration every facade bench starts from: 10 samples, 0.5 s of warm-up and
/// 1.5 s of measurement per benchmark, overridable on the command line (`-- --sample-size 20
/// --measurement-time 5`).
pub fn criterion() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_millis(1500))
        .configure_from_args()
}

/// Whether the bench runs as a smoke test (`cargo test --benches` passes `--test`).
pub fn smoke() -> bool {
    std::env::args().any(|a| a == "--test")
}

/// Criterion's report directory.
fn criterion_home() -> PathBuf {
    std::env::var_os("CRITERION_HOME")
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("CARGO_TARGET_DIR").map(|d| PathBuf::from(d).join("criterion"))
        })
        .unwrap_or_else(|| root().join("target/criterion"))
}

/// Criterion's median for `group/id` (ns), read back from its report directory, if present.
/// Criterion writes the directory names with `?"/\*<>:|^` replaced by `_`.
pub fn criterion_median_ns(group: &str, id: &str) -> Option<f64> {
    let clean = |s: &str| s.replace(['?', '"', '/', '\\', '*', '<', '>', ':', '|', '^'], "_");
    let path = criterion_home()
        .join(clean(group))
        .join(clean(id))
        .join("new/estimates.json");
    let text = std::fs::read_to_string(path).ok()?;
    // `{"mean":{...},"median":{"confidence_interval":{...},"point_estimate":X,...},...}`
    let after = &text[text.find("\"median\"")?..];
    let after = &after[after.find("\"point_estimate\":")? + "\"point_estimate\":".len()..];
    let end = after.find([',', '}'])?;
    after[..end].trim().parse().ok()
}

/// A median in ms for a table cell, or "n/a" when criterion wrote none.
pub fn ms_cell(ns: Option<f64>) -> String {
    ns.map_or("n/a".into(), |ns| format!("{:.3}", ns / 1e6))
}
