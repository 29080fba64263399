//! The stability family of issue 15 (sleeping off): columns, planar and 3D pyramids, a wall,
//! heavy boxes on light ones, at several sizes, frictions and perturbed starts
//! (`tests/common/family.rs`). The criterion: every body's lateral drift between 2 s and 20 s
//! under 1 cm, and a sink under 1 mm per contact layer.
//!
//! `family_table` prints every case's figures with the soft-step resolver at its defaults, or
//! with the resolver named by `FAMILY_RESOLVER` (`millington`, `soft-step`, or `rigid` for
//! the soft step with [`SoftStepSettings::rigid_contacts`]): `cargo test
//! --release --test stability_family -- --ignored --nocapture family_table`; the same scenes
//! run side by side with rapier3d in `cargo bench --bench stability_family`. The Millington
//! resolver meets the criterion on none of the family (a 10-box column falls); the cases below
//! run the engine's default, the soft step at its defaults: those that meet the criterion are
//! tests of their own, the others are listed with their figures in benches/RESULTS.md ("The
//! stability family") until a resolver meets them.

mod common;

use common::family::{self, Case, Variant};
use jostle::{ResolverChoice, SoftStepSettings};

fn soft_step() -> Option<ResolverChoice> {
    Some(ResolverChoice::SoftStep(SoftStepSettings::default()))
}

fn assert_stands(case: &Case, seconds: f32) {
    assert_stands_with(case, seconds, soft_step());
}

fn assert_stands_with(case: &Case, seconds: f32, resolver: Option<ResolverChoice>) {
    let o = family::run(case, seconds, resolver);
    assert!(
        o.stands(),
        "{}: drift {:.2} mm, sink {:.3} mm per layer, {} bodies moved",
        case.name,
        o.drift * 1e3,
        o.sink_per_layer * 1e3,
        o.moved
    );
}

#[test]
fn a_3d_pyramid_of_10_layers_stands() {
    assert_stands(&family::pyramid3d(10, Variant::default()), 20.0);
}

#[test]
fn a_perturbed_3d_pyramid_of_10_layers_stands() {
    let v = Variant {
        seed: Some(1),
        ..Variant::default()
    };
    assert_stands(&family::pyramid3d(10, v), 20.0);
}

/// The whole family's figures at the defaults, as a markdown table (a measurement: asserts
/// only that every run stays finite).
#[test]
#[ignore = "a measurement of several minutes in release; run with --ignored --nocapture"]
fn family_table() {
    let resolver = match std::env::var("FAMILY_RESOLVER") {
        Ok(name) if name == "rigid" => rigid(),
        Ok(name) => Some(ResolverChoice::from_name(&name).unwrap()),
        Err(_) => soft_step(),
    };
    println!(
        "| case | lateral drift 2–20 s (mm) | sink per layer (mm) | largest penetration (mm) | bodies moved | ms/step | meets the criterion |"
    );
    println!("|---|---:|---:|---:|---:|---:|---|");
    for case in family::base().iter().chain(&family::variations()) {
        let o = family::run(case, 20.0, resolver.clone());
        assert!(o.drift.is_finite() && o.sink_per_layer.is_finite());
        println!("| {} | {} |", case.name, o.cells());
    }
}

/// The soft step with rigid contacts ([`SoftStepSettings::rigid_contacts`]).
fn rigid() -> Option<ResolverChoice> {
    Some(ResolverChoice::SoftStep(SoftStepSettings {
        rigid_contacts: true,
        ..SoftStepSettings::default()
    }))
}

#[test]
fn rigid_contacts_hold_a_column_of_40_with_a_sink_under_1_mm_per_layer() {
    // Soft contacts: the column falls (and a soft 40-column sinks 0.43 m in rapier3d too).
    assert_stands_with(&family::column(40, Variant::default()), 20.0, rigid());
}

#[test]
fn rigid_contacts_hold_a_light_column_under_a_100_times_heavier_box() {
    // Soft contacts: the 5-box column under the heavy box falls. Rigid ones hold it without
    // drift but do not meet the sink criterion: 1.2 mm per layer at the 1 mm slop (0.93 mm
    // at a 0.5 mm slop, which jitters on pyramids), so this asserts the stand only.
    let case = family::heavy_on_light(100.0, 5, Variant::default());
    let o = family::run(&case, 20.0, rigid());
    assert!(
        o.moved == 0 && o.drift < 0.01 && o.sink_per_layer < 0.002,
        "drift {:.2} mm, sink {:.3} mm per layer, {} bodies moved",
        o.drift * 1e3,
        o.sink_per_layer * 1e3,
        o.moved
    );
}

#[test]
fn rigid_contacts_hold_a_column_of_20_small_boxes() {
    // 0.1 m boxes; soft contacts: 19 of the 20 fall.
    let v = Variant {
        half: 0.05,
        ..Variant::default()
    };
    assert_stands_with(&family::column(20, v), 20.0, rigid());
}
