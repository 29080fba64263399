//! "Skip what a scene does not need", measured (benches/RESULTS.md; issue 7): bench pairs that run the
//! same work with and without the need for a piece of it. Sleeping islands and CCD have their
//! own benches (benches/sleep.rs, benches/ccd.rs); this one holds the rest.
//!
//! - **μ = 0** (no friction work), world level: `assets/piles_1000.ron` (1,000 boxes in 200
//!   piles of 5, resting on the ground, friction irrelevant to the outcome), sleeping off,
//!   settled 2 s, with μ = 0.6 against μ = 0 on every body; each resolver.
//! - **μ = 0**, resolver only: the synthetic stacks of `jostle_resolve::synthetic` (1,024
//!   contacts, 128 columns of 8 boxes, no parry) with their μ = 0.5 against μ = 0.
//! - **e = 0** (the soft step's restitution pass skipped when no contact has e > 0; the
//!   Millington resolver has no separate pass, e only changes each contact's desired velocity
//!   change): the synthetic stacks with every box falling 2 m/s faster than the one below it
//!   (so every contact closes at 2 m/s, above the soft step's 1 m/s restitution threshold), with
//!   e = 0.5 against e = 0.
//! - **zero inverse inertia** (`SolverBody::ROTATES` clear: every angular term skipped): the
//!   synthetic stacks as built against the same bodies with zero inverse inertia and the flag
//!   cleared; and at world level, `piles_1000` settled with every box free to rotate against
//!   every box with `lock_rotation` set (`BodyDesc::lock_rotation`), each resolver.
//! - **unmoved pairs** (narrow-phase manifold reuse when a pair's relative pose moved less than
//!   `CollideSettings::reuse_linear` / `reuse_angular`, 1e-4 m / 1e-4 rad), world level: the
//!   settled scene with the default tolerances against the same scene with both set to 0
//!   (reuse disabled: every manifold recomputed by parry each step), on `piles_1000` and
//!   `pyramid_20`, soft step, sleeping off: the whole step, and the narrow phase's own time
//!   (`narrow_phase/…`, from the step profile through `iter_custom`), where the skip acts.
//!
//! Resolver-only benchmarks step a fresh clone of the synthetic scene each iteration (the clone
//! is not timed). The work differs between the two halves of a pair only by what is skipped for
//! the soft step (fixed iteration counts); the Millington resolver's worst-first picks can
//! differ, so the table printed after criterion gives each case's picks beside its time.
//!
//! Run: `cargo bench --bench skips` (about 1.5 minutes: 24 benchmarks of 10 samples, 0.5 s
//! warm-up, 1.5 s measurement, flat sampling, plus settling). The markdown table goes to
//! stderr.

mod common;

use common::DT;
use criterion::{BatchSize, Criterion, SamplingMode};
use jostle::layers::resolve::synthetic::{self, GRAVITY, SyntheticScene};
use jostle::layers::resolve::{ResolveStats, Resolver, SolverBody, StepContext};
use jostle::{Mat3, ResolverChoice, World};
use std::fmt::Write as _;
use std::hint::black_box;

const SETTLE_STEPS: usize = 120;
const RESOLVERS: [&str; 2] = ["soft-step", "millington"];

/// One row of the final table: group, benchmark id, what the work counter says.
struct Row {
    group: String,
    id: String,
    work: String,
}

/// A settled world of `asset` with the given resolver, sleeping off, every body description
/// changed by `edit` (friction, locked rotation) and the collide settings by `collide`.
fn world(
    asset: &str,
    resolver: &str,
    edit: impl Fn(&mut jostle::BodyDesc),
    collide: impl Fn(&mut jostle::CollideSettings),
    settle: usize,
) -> World {
    let scene = common::scene(asset);
    let mut settings = scene.settings();
    settings.resolver = ResolverChoice::from_name(resolver).expect("resolver name");
    settings.sleep.enabled = false;
    collide(&mut settings.collide);
    let mut world = World::new(settings);
    for mut desc in scene.body_descs().expect("scene bodies") {
        edit(&mut desc);
        world.add_body(desc).expect("body");
    }
    for _ in 0..settle {
        world.step(DT).expect("step");
    }
    world
}

/// One step of a settled world per iteration; with `narrow`, also the narrow phase's own time
/// per step (from the step profile, through `iter_custom`), as `narrow_phase/<id>`.
fn bench_world(
    c: &mut Criterion,
    rows: &mut Vec<Row>,
    group: &str,
    cases: Vec<(String, World)>,
    narrow: bool,
) {
    let mut g = c.benchmark_group(group);
    g.sampling_mode(SamplingMode::Flat);
    for (id, mut world) in cases {
        let p = world.profile();
        let work = format!(
            "{} contact points, {} of {} manifolds reused",
            p.contact_points, p.manifolds_reused, p.manifolds
        );
        g.bench_function(&id, |b| {
            b.iter(|| {
                black_box(world.step(DT).expect("step"));
            })
        });
        if narrow {
            let narrow_id = format!("narrow_phase/{id}");
            g.bench_function(&narrow_id, |b| {
                b.iter_custom(|iters| {
                    let mut sum = std::time::Duration::ZERO;
                    for _ in 0..iters {
                        world.step(DT).expect("step");
                        sum += world.profile().narrow_phase;
                    }
                    sum
                })
            });
            rows.push(Row {
                group: group.into(),
                id: narrow_id,
                work: work.clone(),
            });
        }
        rows.push(Row {
            group: group.into(),
            id,
            work,
        });
    }
    g.finish();
}

fn resolver(name: &str) -> Box<dyn Resolver> {
    ResolverChoice::from_name(name)
        .expect("resolver name")
        .build()
}

fn resolve_once(r: &mut dyn Resolver, scene: &SyntheticScene) -> ResolveStats {
    let (mut bodies, mut contacts) = (scene.bodies.clone(), scene.contacts.clone());
    r.step(
        &mut bodies,
        &mut contacts,
        &StepContext {
            gravity: GRAVITY,
            dt: DT,
        },
    )
}

/// One resolver step on a fresh clone of each synthetic scene per iteration, both resolvers.
fn bench_synthetic(
    c: &mut Criterion,
    rows: &mut Vec<Row>,
    group: &str,
    cases: &[(&str, SyntheticScene)],
) {
    let mut g = c.benchmark_group(group);
    g.sampling_mode(SamplingMode::Flat);
    for name in RESOLVERS {
        for (case, scene) in cases {
            let id = format!("{name}/{case}");
            let mut r = resolver(name);
            let stats = resolve_once(r.as_mut(), scene);
            let work = format!(
                "{} contacts, picks {}+{}",
                scene.contacts.len(),
                stats.position_iterations,
                stats.velocity_iterations
            );
            g.bench_function(&id, |b| {
                b.iter_batched(
                    || (scene.bodies.clone(), scene.contacts.clone()),
                    |(mut bodies, mut contacts)| {
                        black_box(r.step(
                            &mut bodies,
                            &mut contacts,
                            &StepContext {
                                gravity: GRAVITY,
                                dt: DT,
                            },
                        ))
                    },
                    BatchSize::SmallInput,
                )
            });
            rows.push(Row {
                group: group.into(),
                id,
                work,
            });
        }
    }
    g.finish();
}

/// The synthetic stacks every resolver-level pair starts from.
fn stacks() -> SyntheticScene {
    synthetic::stacks(1024, 8, 1)
}

fn with_friction(mut s: SyntheticScene, mu: f32) -> SyntheticScene {
    for c in &mut s.contacts {
        c.friction = mu;
    }
    s
}

/// Every box falls 2 m/s faster than the one below it (the bottom one at 2 m/s onto the
/// ground), so every contact closes at 2 m/s; restitution `e` on every contact.
fn impacting(e: f32) -> SyntheticScene {
    let mut s = stacks();
    // Columns are generated bottom to top, 8 boxes each, after the static entry.
    for (i, body) in s.bodies.iter_mut().enumerate().skip(1) {
        let level = ((i - 1) % 8) as f32;
        body.linear_velocity.y = -2.0 * (level + 1.0);
    }
    for c in &mut s.contacts {
        c.restitution = e;
    }
    s
}

fn without_rotation(mut s: SyntheticScene) -> SyntheticScene {
    for body in s.bodies.iter_mut().skip(1) {
        body.inv_inertia = Mat3::ZERO;
        body.angular_velocity = jostle::Vec3::ZERO;
        body.flags &= !SolverBody::ROTATES;
    }
    s
}

fn main() {
    let smoke = common::smoke();
    let settle = if smoke { 2 } else { SETTLE_STEPS };
    let mut c = common::criterion();
    let mut rows = Vec::new();

    // μ = 0, world level.
    let mut cases = Vec::new();
    for name in RESOLVERS {
        for (case, mu) in [("mu_0.6", 0.6), ("mu_0", 0.0)] {
            cases.push((
                format!("{name}/{case}"),
                world(
                    "piles_1000",
                    name,
                    |d| d.material.friction = mu,
                    |_| {},
                    settle,
                ),
            ));
        }
    }
    bench_world(&mut c, &mut rows, "skip_friction_piles_1000", cases, false);

    // Zero inverse inertia, world level: every box of the piles with its rotation locked.
    let mut cases = Vec::new();
    for name in RESOLVERS {
        for (case, lock) in [("rotates", false), ("lock_rotation", true)] {
            cases.push((
                format!("{name}/{case}"),
                world(
                    "piles_1000",
                    name,
                    |d| d.lock_rotation = lock && !d.fixed,
                    |_| {},
                    settle,
                ),
            ));
        }
    }
    bench_world(&mut c, &mut rows, "skip_rotation_piles_1000", cases, false);

    // μ = 0, e = 0 and zero inverse inertia, resolver only.
    bench_synthetic(
        &mut c,
        &mut rows,
        "skip_friction_synthetic",
        &[("mu_0.5", stacks()), ("mu_0", with_friction(stacks(), 0.0))],
    );
    bench_synthetic(
        &mut c,
        &mut rows,
        "skip_restitution_synthetic",
        &[("e_0.5", impacting(0.5)), ("e_0", impacting(0.0))],
    );
    bench_synthetic(
        &mut c,
        &mut rows,
        "skip_rotation_synthetic",
        &[
            ("rotates", stacks()),
            ("zero_inverse_inertia", without_rotation(stacks())),
        ],
    );

    // Unmoved pairs: manifold reuse on against off.
    for asset in ["piles_1000", "pyramid_20"] {
        let cases = vec![
            (
                "reuse_on".to_string(),
                world(asset, "soft-step", |_| {}, |_| {}, settle),
            ),
            (
                "reuse_off".to_string(),
                world(
                    asset,
                    "soft-step",
                    |_| {},
                    |s| {
                        s.reuse_linear = 0.0;
                        s.reuse_angular = 0.0;
                    },
                    settle,
                ),
            ),
        ];
        bench_world(
            &mut c,
            &mut rows,
            &format!("skip_unmoved_{asset}"),
            cases,
            true,
        );
    }

    c.final_summary();
    if smoke {
        return;
    }
    // Ratios within each group: each case against the group's first case with the same
    // resolver prefix (the case *with* the need).
    let mut out = String::new();
    let _ = writeln!(
        out,
        "\n| group | case | ms/step (criterion median) | ratio to the case with the need | work |"
    );
    let _ = writeln!(out, "|---|---|---:|---:|---|");
    for row in &rows {
        let median = common::criterion_median_ns(&row.group, &row.id);
        let prefix = row.id.rsplit_once('/').map_or("", |(p, _)| p);
        let base = rows
            .iter()
            .find(|r| {
                r.group == row.group && r.id.rsplit_once('/').map_or("", |(p, _)| p) == prefix
            })
            .and_then(|r| common::criterion_median_ns(&r.group, &r.id));
        let ratio = match (median, base) {
            (Some(m), Some(b)) if b > 0.0 => format!("{:.2}", m / b),
            _ => "n/a".into(),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {ratio} | {} |",
            row.group,
            row.id,
            common::ms_cell(median),
            row.work
        );
    }
    eprint!("{out}");
}
