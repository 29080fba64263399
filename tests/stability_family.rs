//! The stability family of issue 15 (sleeping off): columns, planar and 3D pyramids, a wall,
//! heavy boxes on light ones, at several sizes, frictions and perturbed starts
//! (`tests/common/family.rs`). The criterion: every body's lateral drift between 2 s and 20 s
//! under 1 cm, and a sink under 1 mm per contact layer.
//!
//! `family_table` prints every case's figures with the soft-step resolver at its defaults, or
//! with the resolver named by `FAMILY_RESOLVER` (`millington`, `soft-step`, or `rigid` for
//! the soft step with [`SoftStepSettings::rigid_contacts`]): `cargo test
//! --release --test stability_family -- --ignored --nocapture family_table`; the same scenes
//! run side by side with rapier3d in `cargo bench -p jostle-compare --bench stability_family`. The Millington
//! resolver, warm started with its shock sweep (its defaults), meets the criterion on the
//! 10-box column, the 3D pyramid of 10 and 61 of the 72 heavy-on-light cases, but lets taller
//! columns and larger pyramids fall (benches/RESULTS.md, "The shock sweep, and the Millington
//! resolver warm started by default"); the cases below run the engine's default, the soft step
//! at its defaults, except the Millington tests at the end: those that meet the criterion are
//! tests of their own, the others are listed with their figures in benches/RESULTS.md ("Load
//! compensation") until a resolver meets them.

mod common;

use common::family::{self, Case, Variant};
use jostle::{IterationBudget, MillingtonSettings, ResolverChoice, SoftStepSettings};

fn soft_step() -> Option<ResolverChoice> {
    Some(ResolverChoice::SoftStep(SoftStepSettings::default()))
}

fn assert_stands(case: &Case, seconds: f32) {
    assert_stands_with(case, seconds, soft_step());
}

fn assert_stands_with(case: &Case, seconds: f32, resolver: Option<ResolverChoice>) {
    let o = family::run(case, seconds, resolver);
    assert!(o.stands(), "{}: {o}", case.name);
}

#[test]
fn a_3d_pyramid_of_10_layers_stands() {
    assert_stands(&family::pyramid3d(10, Variant::default()), 20.0);
}

#[test]
fn a_perturbed_3d_pyramid_of_10_layers_stands() {
    assert_stands(&family::pyramid3d(10, family::seeded(1)), 20.0);
}

#[test]
fn a_planar_pyramid_of_40_rows_stands() {
    // 4 substeps at 30 Hz (the defaults until 2026-12-02): drift 6.8 mm, sink 2.9 mm per row.
    assert_stands(&family::pyramid(40, Variant::default()), 20.0);
}

#[test]
fn a_running_bond_wall_stands() {
    // 4 substeps at 30 Hz: sink 1.5 mm per row.
    assert_stands(&family::wall(20, 10, Variant::default()), 20.0);
}

#[test]
fn a_planar_pyramid_of_small_boxes_stands() {
    // 0.1 m boxes; 4 substeps at 30 Hz: 105 of the 210 boxes fall.
    let v = Variant {
        half: 0.05,
        ..Variant::default()
    };
    assert_stands(&family::pyramid(20, v), 20.0);
}

#[test]
fn a_column_of_small_boxes_stands() {
    // 0.1 m boxes. With the contact normals held to 0.002 rad instead of their own angular
    // tolerance it falls at 3 s (13 boxes move): the first steps' millimetre of sway tilts
    // these boxes by 0.2°, past that tolerance, and fresh frames bring the buckling back.
    let v = Variant {
        half: 0.05,
        ..Variant::default()
    };
    assert_stands(&family::column(20, v), 20.0);
}

#[test]
fn a_column_of_40_stands() {
    // Without load compensation (`preload_rate: 0`) it stands but sinks 2.7 mm per layer; at 4
    // substeps and 30 Hz it falls.
    assert_stands(&family::column(40, Variant::default()), 20.0);
}

#[test]
fn a_column_of_60_stands() {
    // 7.1 mm. Each manifold's normal rows solved point by point (`block_relax: false`, the
    // default before 2026-12-05): 13.3 mm (benches/RESULTS.md, "Drift measured at every step").
    assert_stands(&family::column(60, Variant::default()), 20.0);
}

#[test]
fn columns_of_heights_sizes_and_frictions_the_family_does_not_hold_stand() {
    // Found by scanning columns of 5 to 60 boxes of 0.1, 1 and 10 m at μ 0.3, 0.6 and 0.9
    // started at rest, with each manifold's normal rows solved point by point: these swayed
    // 77 mm, or fell (benches/RESULTS.md, "Each manifold's normal rows solved together, the
    // default"). Solved together, each stayed within 6 mm; now chains are solved directly.
    for (n, half, friction) in [(24, 0.5, 0.3), (21, 5.0, 0.9), (43, 5.0, 0.6)] {
        let v = Variant {
            half,
            friction,
            seed: None,
        };
        assert_stands(&family::column(n, v), 20.0);
    }
}

#[test]
fn a_perturbed_column_of_20_stands() {
    // Without load compensation: 1.3 mm of sink per layer; at 4 substeps and 30 Hz it falls.
    assert_stands(&family::column(20, family::seeded(1)), 20.0);
}

#[test]
fn another_perturbed_column_of_20_stands() {
    // Solved by Gauss-Seidel the landing left the top 13 mm out and it swayed about there,
    // ±6 mm with a period of about 3.3 s, 12.7 mm from where it stood at 2 s; solved directly
    // as a chain, 0.13 mm.
    assert_stands(&family::column(20, family::seeded(2)), 20.0);
}

#[test]
fn perturbed_tall_columns_stand() {
    // The tall set's perturbed columns of 40 and 60 boxes swayed 28–365 mm while Gauss-Seidel
    // solved them; solved directly as chains, with springs sized by their load and faces rigid
    // in the relax pass, 0.26–4.74 mm (benches/RESULTS.md, "Chains of bodies solved directly").
    let mixed = Variant {
        half: 1.0,
        friction: 0.4,
        seed: Some(11),
    };
    for (n, v) in [
        (40, family::seeded(8)),
        (60, family::seeded(9)),
        (60, mixed),
    ] {
        assert_stands(&family::column(n, v), 20.0);
    }
}

#[test]
fn without_the_direct_solve_a_perturbed_column_of_40_sways() {
    // What `perturbed_tall_columns_stand` would see without it: the column leans and sways
    // with a period of about 10 s, the top 62 mm from where it stood at 2 s.
    let case = family::column(40, family::seeded(8));
    let off = Some(ResolverChoice::SoftStep(SoftStepSettings {
        direct_rows: 0,
        ..SoftStepSettings::default()
    }));
    let o = family::run(&case, 20.0, off);
    assert!(o.drift > family::MAX_DRIFT, "{o}");
}

#[test]
fn a_light_box_under_a_100_times_heavier_one_stands() {
    // Without load compensation: 4.4 mm of sink per layer. (The 5-box column under the same box
    // sinks 1.3 mm per layer with it, 10 mm without; the preload's stiffening is bounded there.)
    assert_stands(&family::heavy_on_light(100.0, 2, Variant::default()), 20.0);
}

#[test]
fn heavy_boxes_on_light_ones_stand() {
    // The direct solve of heavy-on-light islands (`SoftStepSettings::direct_rows`): each
    // sinks 0.04-0.06 mm per layer with no drift. Without it the 1:1,000 pair sank 30 mm per
    // layer and the others fell.
    for ratio in [1000.0, 10000.0] {
        for n in [2, 5] {
            assert_stands(&family::heavy_on_light(ratio, n, Variant::default()), 20.0);
        }
    }
}

#[test]
fn perturbed_heavy_boxes_on_light_ones_stand() {
    // Starts perturbed from seeds the family table does not use, the heavy box landing on an
    // edge of a light one: with friction left out of the biased pass's direct solve the first
    // four fell (the light box spun under the friction the relax pass had left on it); the
    // last three fell while the direct solve's friction rows had no compliance of their own;
    // the 0.1 m column fell in its landing cascade while the step's first warm start went
    // uncorrected (benches/RESULTS.md, "Heavy on light: a direct solve", "Friction rows
    // regularised in the direct solve" and "The first warm start corrected in heavy islands").
    for (ratio, n, seed, half, friction) in [
        (1000.0, 2, 4, 0.5, 0.5),
        (1000.0, 5, 3, 0.5, 0.5),
        (10000.0, 2, 4, 0.5, 0.5),
        (10000.0, 5, 4, 0.5, 0.5),
        (10000.0, 5, 3, 0.5, 0.5),
        (10000.0, 5, 5, 0.5, 0.5),
        (10000.0, 5, 7, 5.0, 0.3),
        (10000.0, 5, 11, 0.05, 0.9),
    ] {
        let v = Variant {
            seed: Some(seed),
            half,
            friction,
        };
        assert_stands(&family::heavy_on_light(ratio, n, v), 20.0);
    }
}

#[test]
fn perturbed_heavy_topped_columns_of_10_m_boxes_that_rocked_stand() {
    // `1:100 column 5 10m μ0.3` from seeds 7, 8, 10 and 16 missed the criterion by 10–47 mm
    // (rapier3d 0.36 misses all twelve such columns of the heavy seeds): each landing set the
    // whole column rocking on the edges of its base, measured as rigid-body rocking to 0.1%
    // (benches/RESULTS.md, "Heavy-topped columns of 10 m boxes rock on their base"). What
    // started it was the landing's impact solved in one sweep, unevenly over a face; with the
    // impact's rows swept to convergence they stand ("A flat landing lands flat"). Seeds 9,
    // 12, 14 and 17 still rock after 2 s (10.1–22.1 mm; not traced since).
    for seed in [7, 8, 10, 16] {
        let case = family::heavy_on_light(
            100.0,
            5,
            Variant {
                half: 5.0,
                friction: 0.3,
                seed: Some(seed),
            },
        );
        assert_stands(&case, 20.0);
    }
}

#[test]
fn without_the_direct_solve_a_light_column_under_a_heavy_box_falls() {
    // What `heavy_boxes_on_light_ones_stand` would see if the direct solve did nothing.
    let case = family::heavy_on_light(1000.0, 5, Variant::default());
    let off = Some(ResolverChoice::SoftStep(SoftStepSettings {
        direct_rows: 0,
        ..SoftStepSettings::default()
    }));
    let o = family::run(&case, 20.0, off);
    assert!(o.moved > 0, "{o}");
}

#[test]
fn the_millington_resolver_holds_heavy_boxes_on_light_ones() {
    // Its shock sweep (`MillingtonSettings::shock_sweep`): 0.06-5.9 mm of drift and at most
    // 0.3 mm of sink per layer (with four sweeps per level instead of eight, the 1:10,000
    // column drifted 484 mm).
    let millington = Some(ResolverChoice::Millington(MillingtonSettings::default()));
    for ratio in [10.0, 100.0, 1000.0, 10000.0] {
        for n in [2, 5] {
            let case = family::heavy_on_light(ratio, n, Variant::default());
            assert_stands_with(&case, 20.0, millington.clone());
        }
    }
}

#[test]
fn without_the_shock_sweep_the_millington_resolver_lets_a_heavy_box_down() {
    // What `the_millington_resolver_holds_heavy_boxes_on_light_ones` would see without the
    // sweep: the picks pass on about m/M of the load each, the heavy box comes down and the
    // light boxes are squeezed out (sink 800 mm per layer, 4 bodies moved).
    let case = family::heavy_on_light(1000.0, 5, Variant::default());
    let off = Some(ResolverChoice::Millington(MillingtonSettings {
        shock_sweep: false,
        ..MillingtonSettings::default()
    }));
    let o = family::run(&case, 20.0, off);
    assert!(o.moved > 0, "{o}");
}

#[test]
fn the_millington_resolvers_perturbed_columns_sway_by_its_velocity_epsilon() {
    // Why the Millington resolver lets perturbed 20-box columns sway by 4-18 cm at its
    // defaults (benches/RESULTS.md, "Why the Millington resolver's perturbed columns sway"):
    // its velocity pass stops when every contact is within `velocity_epsilon` (1e-4 m/s) of its
    // target, and a perturbed column's joints are each left turning at about that rate, which
    // its height adds up. With the epsilon at 1e-6 and a budget that lets the pass reach it, the
    // same columns stand: over 18 perturbed columns (seeds 3-5, 0.1, 1 and 10 m boxes, μ 0.3
    // and 0.9) 38.8-177 mm of drift at the defaults, 0.18-0.76 mm so; 128 picks a contact
    // left one of the cases below at 8.9 mm. The price is why it is not the default: 13-27 ms
    // a step on average over these runs' 10 s (their settling steps spend the whole budget)
    // against 0.3-0.75 ms, and a 20-row pyramid cannot reach even 1e-5 within 64 picks a
    // contact (244 ms a step). (The 10 m boxes still sink 4-7 mm a layer: the position pass
    // leaves overlaps below its absolute `position_epsilon` of 10 mm alone.)
    let tight = Some(ResolverChoice::Millington(MillingtonSettings {
        velocity_epsilon: 1e-6,
        velocity_iterations: IterationBudget {
            fixed: 8,
            per_contact: 512,
        },
        ..MillingtonSettings::default()
    }));
    let defaults = Some(ResolverChoice::Millington(MillingtonSettings::default()));
    for (seed, half, friction) in [(3, 0.05, 0.3), (4, 0.5, 0.9), (5, 5.0, 0.3)] {
        let case = family::column(
            20,
            Variant {
                seed: Some(seed),
                half,
                friction,
            },
        );
        let swaying = family::run(&case, 10.0, defaults.clone());
        assert!(
            swaying.drift > family::MAX_DRIFT,
            "{}: {swaying}",
            case.name
        );
        let held = family::run(&case, 10.0, tight.clone());
        assert!(
            held.drift < family::MAX_DRIFT && held.moved == 0,
            "{}: {held}",
            case.name
        );
    }
}

#[test]
fn load_compensation_removes_the_load_proportional_sink() {
    // A column solved by Gauss-Seidel alone (the direct solve off, as an island too large for
    // it is): with the preload off it sinks by its springs' compression under the load. (Solved
    // directly, a column's springs are sized by their load and sink 0.07 mm per layer either
    // way.)
    let case = family::column(20, Variant::default());
    let settings = |preload_rate| {
        Some(ResolverChoice::SoftStep(SoftStepSettings {
            preload_rate,
            direct_rows: 0,
            ..SoftStepSettings::default()
        }))
    };
    let without = family::run(&case, 10.0, settings(0.0));
    let with = family::run(
        &case,
        10.0,
        settings(SoftStepSettings::default().preload_rate),
    );
    assert!(
        without.sink_per_layer > family::MAX_SINK_PER_LAYER,
        "{without}"
    );
    assert!(with.sink_per_layer < family::MAX_SINK_PER_LAYER, "{with}");
    assert!(with.moved == 0 && with.drift < family::MAX_DRIFT, "{with}");
}

/// The whole family's figures at the defaults, as a markdown table (a measurement: asserts
/// only that every run stays finite). `FAMILY_RESOLVER` names the resolver (see the module
/// docs) or gives it in RON (`SoftStep((substeps: 8))`); `FAMILY_ONLY` keeps the cases whose
/// name contains one of its `|`-separated parts (`column 20|pyramid 40`; a part that starts
/// with `^` must begin the name: `^pyramid 20` leaves out `3D pyramid 20`); `FAMILY_SECONDS`
/// sets the simulated time (default 20; the long runs use 60); `FAMILY_SET=heavy` runs the
/// sweep of heavy boxes on light ones (`family::heavy_sweep`) instead of the family,
/// `FAMILY_SET=heavy_seeds` the same from many more seeds (`family::heavy_seeds`),
/// `FAMILY_SET=tall` the tall members' variations (`family::tall_variations`),
/// `FAMILY_SET=small` the members of 5 mm to 5 cm boxes (`family::small`), and
/// `FAMILY_SET=large` the 10 m members from perturbed starts (`family::large_perturbed`), from
/// seeds 31 and 32 or from those listed in `FAMILY_LARGE_SEEDS` (`33,34,35`).
#[test]
#[ignore = "a measurement of several minutes in release; run with --ignored --nocapture"]
fn family_table() {
    let resolver = match std::env::var("FAMILY_RESOLVER") {
        Ok(name) if name == "rigid" => rigid(),
        Ok(name) if name.contains('(') => Some(
            ron::from_str::<ResolverChoice>(&name)
                .unwrap_or_else(|e| panic!("FAMILY_RESOLVER {name:?}: {e}")),
        ),
        Ok(name) => Some(ResolverChoice::from_name(&name).unwrap()),
        Err(_) => soft_step(),
    };
    let only = std::env::var("FAMILY_ONLY").unwrap_or_default();
    let seconds: f32 = std::env::var("FAMILY_SECONDS")
        .map(|s| s.parse().expect("FAMILY_SECONDS: seconds"))
        .unwrap_or(20.0);
    println!(
        "| case | lateral drift 2–{seconds} s (mm) | sink per layer (mm) | largest penetration (mm) | bodies moved | ms/step | meets the criterion |"
    );
    println!("|---|---:|---:|---:|---:|---:|---|");
    let cases: Vec<Case> = match std::env::var("FAMILY_SET").as_deref() {
        Ok("heavy") => family::heavy_sweep(),
        Ok("heavy_seeds") => family::heavy_seeds(),
        Ok("tall") => family::tall_variations(),
        Ok("large") => family::large_perturbed(),
        Ok("small") => family::small(),
        Ok("unseen") => family::unseen_from_env(),
        _ => family::base()
            .into_iter()
            .chain(family::variations())
            .collect(),
    };
    for case in cases.iter().filter(|c| family::selected(&c.name, &only)) {
        let o = family::run(case, seconds, resolver.clone());
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
    // Soft contacts: the column stands but sinks 2.7 mm per layer (4 substeps at 30 Hz: it
    // falls; rapier3d's sinks 0.43 m).
    assert_stands_with(&family::column(40, Variant::default()), 20.0, rigid());
}

#[test]
fn rigid_contacts_hold_a_light_column_under_a_100_times_heavier_box() {
    // Soft contacts: the 5-box column under the heavy box sinks 10 mm per layer (4 substeps at
    // 30 Hz: it falls). Rigid ones hold it without drift but do not meet the sink criterion
    // (measured at 4 substeps: 1.2 mm per layer at the 1 mm slop, 0.93 mm at a 0.5 mm slop,
    // which jitters on pyramids), so this asserts the stand only.
    let case = family::heavy_on_light(100.0, 5, Variant::default());
    let o = family::run(&case, 20.0, rigid());
    assert!(
        o.moved == 0 && o.drift < 0.01 && o.sink_per_layer < 0.002,
        "{o}"
    );
}

#[test]
fn rigid_contacts_hold_a_column_of_20_small_boxes() {
    // 0.1 m boxes; soft contacts: 13 of the 20 fall (4 substeps at 30 Hz: 18).
    let v = Variant {
        half: 0.05,
        ..Variant::default()
    };
    assert_stands_with(&family::column(20, v), 20.0, rigid());
}

/// The most contact rows the soft step solved directly in any of the first 30 steps of
/// `generator` (a generator's RON text) on the ground, sleeping off.
fn most_direct_rows(generator: &str) -> u32 {
    let ron = format!(
        "Scene(sleep: (enabled: false), bodies: [Body(name: \"ground\", \
         shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true)], generators: [{generator}])"
    );
    let scene = jostle::scene::Scene::parse(&ron, "chain").unwrap();
    let mut world = scene.build_with(scene.settings()).unwrap();
    let mut most = 0;
    for _ in 0..30 {
        world.step(1.0 / 60.0).unwrap();
        most = most.max(world.profile().resolve_stats.direct_rows);
    }
    most
}

#[test]
fn tall_chains_of_large_boxes_are_solved_directly_from_a_load_path_of_eight() {
    // A chain whose bodies' sizes add up to 12.5 m or more (`direct::TALL_CHAIN`) is solved
    // directly from half the load path of other chains: columns of 8 and 10 boxes of 10 m
    // are, one of 7 is not; 13 unit boxes are, 12 are not (nor a lattice's columns of ten).
    let direct_rows = |n: u32, half: f32| {
        most_direct_rows(&format!(
            "Stack(count: {n}, half_extents: ({half}, {half}, {half}), friction: 0.5)"
        ))
    };
    // n manifolds of 4 points, each a normal and two friction rows.
    assert_eq!(direct_rows(10, 5.0), 10 * 4 * 3);
    assert_eq!(direct_rows(8, 5.0), 8 * 4 * 3);
    assert_eq!(direct_rows(7, 5.0), 0);
    assert_eq!(direct_rows(13, 0.5), 13 * 4 * 3);
    assert_eq!(direct_rows(12, 0.5), 0);
    assert_eq!(direct_rows(10, 0.5), 0);
}

#[test]
fn perturbed_columns_of_10_to_15_boxes_of_1_to_10_m_stand() {
    // Left to Gauss-Seidel (their load path is under 16), perturbed columns swayed more than
    // 1 cm from some of 24 starts (seeds 21-28, μ 0.3, 0.6, 0.9): 10 boxes of 10 m from 10, 12
    // of 10 m from 23, 13 of 1 m from 3, 15 of 1.26 m from 6; solved directly as tall chains,
    // 1, 2, 0 and 0, the misses rocking on their base as one body (benches/RESULTS.md, "Tall
    // columns of large boxes solved directly"). These failed before: 15.2, 11.4, 10.3, 16.6,
    // 22.8, 12.0 and 12.4 mm.
    for (n, half, friction, seed) in [
        (10, 5.0, 0.3, 22),
        (10, 5.0, 0.3, 25),
        (10, 5.0, 0.6, 26),
        (12, 5.0, 0.3, 23),
        (12, 5.0, 0.9, 28),
        (13, 0.5, 0.6, 22),
        (15, 0.63, 0.3, 21),
    ] {
        let v = Variant {
            half,
            friction,
            seed: Some(seed),
        };
        assert_stands(&family::column(n, v), 20.0);
    }
}

#[test]
fn chains_are_solved_directly_from_a_load_path_of_sixteen_within_a_budget() {
    // At the defaults (8 substeps of a biased and a relax sweep: 16 sweeps) a chain whose load
    // path (its bodies resting on nothing immovable, plus one) is 16 or more is solved
    // directly: a column of 16 is, one of 15 is not (boxes of 0.5 m, so that neither is a tall
    // chain), and neither is a row of 30 boxes side by side on the ground. Together the chains solved directly hold at most
    // `direct_rows` × `CHAIN_ROWS` = 1,024 contact points: of 25 columns of 16 (64 points
    // each) 16 are, the longest first.
    let direct_rows = most_direct_rows;
    let column = |n| format!("Stack(count: {n}, half_extents: (0.25, 0.25, 0.25), friction: 0.5)");
    // A column of 16 boxes: 16 manifolds of 4 points, each a normal and two friction rows.
    assert_eq!(direct_rows(&column(16)), 16 * 4 * 3);
    assert_eq!(direct_rows(&column(15)), 0);
    let piles = "Piles(nx: 5, nz: 5, height: 16, spacing: 1.5, friction: 0.5)";
    assert_eq!(direct_rows(piles), 16 * (16 * 4 * 3));
    let row = (0..30)
        .map(|i| {
            format!(
                "Body(name: \"b{i}\", shape: Cuboid(half_extents: (0.5, 0.5, 0.5)), \
                 position: ({}, 0.5, 0.0))",
                i as f32 * 0.999
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    let ron = format!(
        "Scene(sleep: (enabled: false), bodies: [Body(name: \"ground\", \
         shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true), {row}])"
    );
    let scene = jostle::scene::Scene::parse(&ron, "row").unwrap();
    let mut world = scene.build_with(scene.settings()).unwrap();
    for _ in 0..30 {
        world.step(1.0 / 60.0).unwrap();
        assert_eq!(world.profile().resolve_stats.direct_rows, 0);
    }
    assert!(
        world.contacts().len() > 4 * 30,
        "the boxes touch their neighbours as well as the ground"
    );
}
