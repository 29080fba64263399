//! The stability family of issue 15 side by side with rapier3d 0.36 at its defaults, in one
//! run: the scenes of `tests/common/family.rs` (columns, planar and 3D pyramids, a wall, heavy
//! boxes on light ones; several sizes, frictions and seeded starts), each built in both
//! engines from the same body descriptions (positions, rotations, half extents, densities,
//! frictions; jostle's ground half-space is a fixed 4,000 m cuboid in rapier3d with its top
//! face at y = 0; friction combines as the mean in rapier3d and both sides carry the case's
//! value). Sleeping is off in both. jostle runs its default resolver, the soft step, at its
//! defaults (Millington lets even a 10-box column fall). Each run is 20 s at 60 Hz; the table
//! prints the lateral drift between 2 s and 20 s, the sink per contact layer, the largest
//! penetration after 2 s, the bodies that moved more than half a box sideways, and the median
//! ms per step, for both engines.
//!
//! Run: `cargo bench -p jostle-compare --bench stability_family` (several minutes; `FAMILY=base` runs only the
//! base family, `FAMILY=variations` only the variations, `FAMILY=heavy` the sweep of heavy
//! boxes on light ones (`family::heavy_sweep`), `FAMILY=heavy_seeds` the same from many more
//! seeds (`family::heavy_seeds`), `FAMILY=tall` the tall members' variations
//! (`family::tall_variations`), `FAMILY=large` the members with 10 m boxes from perturbed
//! starts (`family::large_perturbed`), `FAMILY=small` the members of 5 mm to 5 cm boxes
//! (`family::small`), `FAMILY=unseen` `FAMILY_UNSEEN` members (default 40) drawn at
//! random from the seed `FAMILY_UNSEEN_SEED` (default 1; `family::unseen`); `FAMILY_ONLY` keeps the cases whose
//! name contains one of its `|`-separated parts, or begins with a part written `^part`, as in
//! `family_table`). With `--test` (`cargo
//! test -p jostle-compare --benches`) only a short smoke run is made.

#[path = "../../../tests/common/family.rs"]
mod family;
#[path = "rapier_scene.rs"]
mod rapier_scene;

use family::Subject;
use jostle::{ResolverChoice, SoftStepSettings, Vec3};
use rapier3d::prelude as rp;

/// A case in rapier3d, for [`family::measure`].
struct Rapier {
    world: rp::PhysicsWorld,
    boxes: Vec<rp::RigidBodyHandle>,
}

impl Subject for Rapier {
    fn step(&mut self) {
        self.world.step();
    }
    fn positions(&self) -> Vec<Vec3> {
        self.boxes
            .iter()
            .map(|&h| {
                let t = self.world.bodies[h].translation();
                Vec3::new(t.x, t.y, t.z)
            })
            .collect()
    }
    fn penetration(&self) -> f32 {
        let mut deepest = 0.0f32;
        for pair in self.world.narrow_phase.contact_pairs() {
            for m in pair.manifolds() {
                for p in &m.points {
                    deepest = deepest.max(-p.dist);
                }
            }
        }
        deepest
    }
}

fn main() {
    let smoke = std::env::args().any(|a| a == "--test");
    let which = std::env::var("FAMILY").unwrap_or_default();
    let mut cases = Vec::new();
    if which == "heavy" {
        cases.extend(family::heavy_sweep());
    } else if which == "heavy_seeds" {
        cases.extend(family::heavy_seeds());
    } else if which == "tall" {
        cases.extend(family::tall_variations());
    } else if which == "large" {
        cases.extend(family::large_perturbed());
    } else if which == "small" {
        cases.extend(family::small());
    } else if which == "unseen" {
        cases.extend(family::unseen_from_env());
    } else {
        if which != "variations" {
            cases.extend(family::base());
        }
        if which != "base" {
            cases.extend(family::variations());
        }
    }
    let only = std::env::var("FAMILY_ONLY").unwrap_or_default();
    cases.retain(|c| family::selected(&c.name, &only));
    let seconds = if smoke { 0.5 } else { 20.0 };
    if smoke {
        cases.truncate(2);
    }
    println!(
        "| case | engine | lateral drift 2–20 s (mm) | sink per layer (mm) | largest penetration (mm) | bodies moved | ms/step | meets the criterion |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---|");
    for case in &cases {
        let j = family::run(
            case,
            seconds,
            Some(ResolverChoice::SoftStep(SoftStepSettings::default())),
        );
        let (world, boxes) = rapier_scene::rapier_world(&family::parse(case));
        let r = family::measure(
            &mut Rapier { world, boxes },
            &family::nominal(case),
            case.layers,
            seconds,
        );
        println!("| {} | jostle | {} |", case.name, j.cells());
        println!("| {} | rapier3d | {} |", case.name, r.cells());
    }
}
