//! `jostle bench`: runs each scene under each resolver and each setting of a sweep, prints a
//! table of cost against error, and writes `results.csv` and one frontier plot per scene
//! (error against ms per 1/60 s step, one curve per resolver) as SVG and PNG.
//!
//! The measuring is `harness::bench::run_case`; this file only loops, prints and draws. Plots are
//! drawn with plotters; text uses the DejaVu Sans bytes of the `dejavu` crate through plotters'
//! ab_glyph renderer, so it works headless with no system fonts.

use crate::harness::bench::{Metrics, Setting, Sweep, run_case};
use crate::harness::run::{Overrides, load};
use crate::staged::Staged;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use jostle::ResolverChoice;
use jostle::scene::Analytic;
use jostle::scene::Scene;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The scenes benchmarked when none are named: the stacking set, relative to the working
/// directory (the repository root).
const DEFAULT_SCENES: [&str; 3] = [
    "assets/pyramid_20.ron",
    "assets/stack_15.ron",
    "assets/pyramid_heavy_top.ron",
];

/// The CSV header of `results.csv`, exactly. Empty fields are metrics that do not apply
/// (energy error of an open system, time to sleep of a scene that never sleeps, analytic
/// error of a scene that declares no closed form).
pub const CSV_HEADER: &str = "scene,resolver,setting,dt,frames,ms_per_step,ms_per_60hz_step,drift_m,max_penetration_m,mean_penetration_m,energy_error,time_to_sleep_s,analytic_error,quarantined";

/// Arguments of `jostle bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scene files (.ron). Default: the stacking scenes in ./assets.
    scenes: Vec<PathBuf>,
    /// Resolver to run (repeatable): millington, soft-step. Default: both.
    #[arg(long = "resolver", value_name = "NAME")]
    resolvers: Vec<String>,
    /// Vary one setting: iterations, substeps or dt. Default: each scene's own settings only.
    /// A resolver the scene declares runs with the scene's settings (labelled "scene" when they
    /// differ from the defaults), and a sweep starts from them; the other resolver runs with its
    /// defaults.
    #[arg(long)]
    sweep: Option<String>,
    /// Output directory for results.csv and the plots (created if missing).
    #[arg(long, default_value = "bench-out", value_name = "DIR")]
    out: PathBuf,
    /// Simulated time per run (s). Default: the scene's steps × dt.
    #[arg(long, value_name = "SECONDS")]
    duration: Option<f64>,
    /// Measure drift and penetration from this time on (s); at most half the duration.
    #[arg(long, default_value_t = 2.0, value_name = "SECONDS")]
    settle: f64,
    /// Disable sleeping (every body simulated every step).
    #[arg(long)]
    no_sleep: bool,
}

/// One row of the results.
struct Row {
    scene: String,
    resolver: &'static str,
    setting: Setting,
    metrics: Metrics,
}

pub fn run(args: BenchArgs) -> Result<(), String> {
    // Each scene and resolver once, in the order given: named twice, they ran twice and gave
    // duplicate rows.
    let mut scenes: Vec<PathBuf> = Vec::new();
    let given: Vec<PathBuf> = if args.scenes.is_empty() {
        DEFAULT_SCENES.iter().map(PathBuf::from).collect()
    } else {
        args.scenes.clone()
    };
    for path in given {
        if !scenes.contains(&path) {
            scenes.push(path);
        }
    }
    let mut resolvers: Vec<ResolverChoice> = Vec::new();
    let names: Vec<&str> = if args.resolvers.is_empty() {
        ResolverChoice::NAMES.to_vec()
    } else {
        args.resolvers.iter().map(String::as_str).collect()
    };
    for name in names {
        let resolver = ResolverChoice::from_name(name)?;
        if !resolvers.iter().any(|r| r.name() == resolver.name()) {
            resolvers.push(resolver);
        }
    }
    let sweep = args.sweep.as_deref().map(Sweep::from_name).transpose()?;
    if let Some(d) = args.duration
        && !(d.is_finite() && d > 0.0)
    {
        return Err(format!("--duration must be finite and > 0, got {d}"));
    }
    if !(args.settle.is_finite() && args.settle >= 0.0) {
        return Err(format!(
            "--settle must be finite and >= 0, got {}",
            args.settle
        ));
    }

    // The output directory first: an `--out` that names a file failed only after every run.
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("--out {}: cannot create: {e}", args.out.display()))?;
    // Every case up front, so the progress bar knows the total and bad files fail early.
    struct Case {
        path: PathBuf,
        scene: String,
        setting: Setting,
        duration: f64,
        analytic: Option<Analytic>,
    }
    let mut cases = Vec::new();
    for path in &scenes {
        let probe = load(path, &Overrides::default()).map_err(|e| e.to_string())?;
        // The closed form, if the file is a scene that declares one (a snapshot declares none;
        // `load` above has already parsed and validated the file, so this cannot fail on a
        // scene file).
        let analytic = Scene::load(path).ok().and_then(|s| s.analytic);
        let duration = args
            .duration
            .unwrap_or(probe.steps as f64 * probe.dt as f64);
        let own = &probe.world.settings().resolver;
        for resolver in &resolvers {
            // The scene's own settings when it declares this resolver, else the defaults.
            let (base, label) = if own.name() == resolver.name() && own != resolver {
                (own, "scene")
            } else {
                (resolver, "default")
            };
            let settings = match sweep {
                Some(s) => s.settings(base, probe.dt),
                None => vec![Setting {
                    label: label.into(),
                    resolver: base.clone(),
                    dt: probe.dt,
                    world_substeps: 1,
                }],
            };
            for setting in settings {
                cases.push(Case {
                    path: path.clone(),
                    scene: probe.name.clone(),
                    setting,
                    duration,
                    analytic: analytic.clone(),
                });
            }
        }
    }

    // Two files whose scenes have the same name would share one plot and be told apart nowhere
    // in results.csv or the table: each is then named with its file as well.
    let shared: Vec<String> = cases
        .iter()
        .filter(|c| cases.iter().any(|o| o.scene == c.scene && o.path != c.path))
        .map(|c| c.scene.clone())
        .collect();
    for case in &mut cases {
        if shared.contains(&case.scene) {
            case.scene = format!("{} ({})", case.scene, case.path.display());
        }
    }

    // Every output's path before any run: one file per scene's plot (scene names that make the
    // same file name, "a b" and "a/b", get numbered files: the second plot overwrote the
    // first), and none may be a scene being read (a scene file named `results.csv` in the
    // output directory was replaced by the results and the run exited 0) or unwritable (known
    // only after every run before).
    let mut stems: Vec<(String, String)> = Vec::new();
    for case in &cases {
        if stems.iter().any(|(scene, _)| *scene == case.scene) {
            continue;
        }
        let mut stem = slug(&case.scene);
        let mut n = 2;
        while stems.iter().any(|(_, s)| *s == stem) {
            stem = format!("{}_{n}", slug(&case.scene));
            n += 1;
        }
        stems.push((case.scene.clone(), stem));
    }
    let csv_path = args.out.join("results.csv");
    let mut outputs = vec![csv_path.clone()];
    for (_, stem) in &stems {
        outputs.extend(plot_paths(&args.out, stem));
    }
    let inputs: Vec<PathBuf> = scenes.iter().map(|p| crate::run_cmd::identity(p)).collect();
    for path in &outputs {
        let id = crate::run_cmd::identity(path);
        if let Some(scene) = scenes.iter().zip(&inputs).find(|(_, input)| **input == id) {
            return Err(format!(
                "--out {}: {} is the scene {} being run; choose another output directory",
                args.out.display(),
                path.display(),
                scene.0.display()
            ));
        }
        crate::run_cmd::writable(path)
            .map_err(|e| format!("--out {}: cannot write: {e}", path.display()))?;
    }

    let bar = ProgressBar::new(cases.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs, {elapsed} {msg}")
            .map_err(|e| e.to_string())?,
    );
    let mut rows = Vec::new();
    for case in cases {
        bar.set_message(format!(
            "{} / {} / {}",
            case.scene,
            case.setting.resolver.name(),
            case.setting.label
        ));
        let overrides = Overrides {
            resolver: None,
            sleep: args.no_sleep.then_some(false),
        };
        let mut setup = load(&case.path, &overrides).map_err(|e| e.to_string())?;
        // The case's resolver exactly as the sweep set it (it starts from the scene's own
        // settings where the scene names the same resolver). As an override it was dropped
        // wherever the scene named the same resolver, so a sweep of the default soft step's
        // substeps or relax iterations ran its defaults at every level.
        setup
            .world
            .set_resolver_choice(case.setting.resolver.clone())
            .map_err(|e| format!("{}: {e}", case.path.display()))?;
        let settle = args.settle.min(case.duration / 2.0);
        let metrics = run_case(
            &mut setup.world,
            &case.setting,
            case.duration,
            settle,
            case.analytic.as_ref(),
        )
        .map_err(|e| format!("{}: {e}", case.path.display()))?;
        rows.push(Row {
            scene: case.scene,
            resolver: case.setting.resolver.name(),
            setting: case.setting,
            metrics,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();

    let staged = Staged::new(&csv_path);
    std::fs::write(staged.path(), csv(&rows))
        .map_err(|e| format!("{}: cannot write: {e}", csv_path.display()))?;
    staged.commit()?;
    let mut written = vec![csv_path];
    for (name, stem) in &stems {
        let scene_rows: Vec<&Row> = rows.iter().filter(|r| r.scene == *name).collect();
        written.extend(plot_scene(&args.out, name, stem, &scene_rows)?);
    }
    // The table last: an unwritable standard output loses no file.
    crate::print_out(&table(&rows))?;
    for p in written {
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// An optional metric as a CSV field: empty when it does not apply.
fn opt(x: Option<f64>, fmt: fn(f64) -> String) -> String {
    x.map_or(String::new(), fmt)
}

fn csv(rows: &[Row]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for r in rows {
        let m = &r.metrics;
        let _ = writeln!(
            out,
            "{},{},{},{},{},{:.6},{:.6},{:e},{:e},{:e},{},{},{},{}",
            r.scene.replace(',', ";"),
            r.resolver,
            r.setting.label,
            r.setting.dt,
            m.frames,
            m.ms_per_step,
            m.ms_per_60hz_step,
            m.drift,
            m.max_penetration,
            m.mean_penetration,
            opt(m.energy_error, |v| format!("{v:e}")),
            opt(m.time_to_sleep, |v| format!("{v:.4}")),
            opt(m.analytic_error, |v| format!("{v:e}")),
            m.quarantined,
        );
    }
    out
}

fn table(rows: &[Row]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<22} {:<10} {:<14} {:>9} {:>11} {:>10} {:>10} {:>10} {:>10} {:>8} {:>10} {:>5}",
        "scene",
        "resolver",
        "setting",
        "ms/step",
        "ms/60Hz st",
        "drift m",
        "max pen m",
        "mean pen m",
        "energy err",
        "sleep s",
        "analyt err",
        "quar"
    );
    let dash = |x: Option<f64>, prec: usize| x.map_or("-".to_string(), |v| format!("{v:.prec$}"));
    for r in rows {
        let m = &r.metrics;
        let _ = writeln!(
            out,
            "{:<22} {:<10} {:<14} {:>9.3} {:>11.3} {:>10.2e} {:>10.2e} {:>10.2e} {:>10} {:>8} {:>10} {:>5}",
            r.scene,
            r.resolver,
            r.setting.label,
            m.ms_per_step,
            m.ms_per_60hz_step,
            m.drift,
            m.max_penetration,
            m.mean_penetration,
            m.energy_error.map_or("-".into(), |e| format!("{e:.2e}")),
            dash(m.time_to_sleep, 2),
            m.analytic_error.map_or("-".into(), |e| format!("{e:.2e}")),
            m.quarantined,
        );
    }
    out
}

/// A file-name-safe form of a scene name ("pyramid 20" → "pyramid_20"; "unnamed" for an empty
/// name, whose plots were written beside the output directory as `OUT.svg` and `OUT.png`).
fn slug(name: &str) -> String {
    if name.is_empty() {
        return "unnamed".to_string();
    }
    name.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// The two files of a scene's plot: `<out>/<stem>.svg` and `.png`.
fn plot_paths(out: &Path, stem: &str) -> [PathBuf; 2] {
    let base = out.join(stem);
    [base.with_extension("svg"), base.with_extension("png")]
}

/// Which error a scene's plot shows on its y axis.
#[derive(Clone, Copy, PartialEq)]
enum Plotted {
    /// The analytic error, for a scene that declares its closed form.
    Analytic,
    /// The energy error of a closed system.
    Energy,
    /// Drift, for everything else.
    Drift,
}

impl Plotted {
    /// The error shown for rows of one scene: analytic if every row has it, else energy if
    /// every row has it, else drift.
    fn of(rows: &[&Row]) -> Self {
        if rows.iter().all(|r| r.metrics.analytic_error.is_some()) {
            Self::Analytic
        } else if rows.iter().all(|r| r.metrics.energy_error.is_some()) {
            Self::Energy
        } else {
            Self::Drift
        }
    }

    fn label(self) -> &'static str {
        match self {
            Self::Analytic => "analytic error",
            Self::Energy => "relative energy error",
            Self::Drift => "drift (m)",
        }
    }
}

/// The plotted error of one row.
fn error_of(m: &Metrics, plotted: Plotted) -> f64 {
    match plotted {
        Plotted::Analytic => m.analytic_error.unwrap_or(0.0),
        Plotted::Energy => m.energy_error.unwrap_or(0.0),
        Plotted::Drift => m.drift as f64,
    }
}

/// Errors and costs are drawn on log axes; exact zeros are drawn at this floor.
const FLOOR: f64 = 1e-7;

/// Writes `<out>/<stem>.svg` and `.png`: the scene's error against ms per 1/60 s step, one
/// curve per resolver, points in sweep order.
fn plot_scene(out: &Path, name: &str, stem: &str, rows: &[&Row]) -> Result<Vec<PathBuf>, String> {
    register_font();
    let plotted = Plotted::of(rows);
    let [svg, png] = plot_paths(out, stem);
    let (svg_staged, png_staged) = (Staged::new(&svg), Staged::new(&png));
    const SIZE: (u32, u32) = (800, 560);
    draw(
        SVGBackend::new(svg_staged.path(), SIZE).into_drawing_area(),
        name,
        rows,
        plotted,
    )?;
    let mut buf = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    draw(
        BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area(),
        name,
        rows,
        plotted,
    )?;
    image::save_buffer(
        png_staged.path(),
        &buf,
        SIZE.0,
        SIZE.1,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| format!("{}: cannot write: {e}", png.display()))?;
    svg_staged.commit()?;
    png_staged.commit()?;
    Ok(vec![svg, png])
}

fn register_font() {
    // Registering twice is harmless (the later registration replaces the earlier).
    let _ =
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    name: &str,
    rows: &[&Row],
    plotted: Plotted,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plot of {name}: {e}");
    root.fill(&WHITE).map_err(err)?;
    // A run with a quarantined body has no finite error to draw (its row says so).
    let rows: Vec<&Row> = rows
        .iter()
        .copied()
        .filter(|r| error_of(&r.metrics, plotted).is_finite())
        .collect();
    if rows.is_empty() {
        return root.present().map_err(err);
    }
    let rows = &rows[..];
    // Costs span orders of magnitude between resolvers, so both axes are logarithmic.
    let xs = rows.iter().map(|r| r.metrics.ms_per_60hz_step.max(FLOOR));
    let ys = rows
        .iter()
        .map(|r| error_of(&r.metrics, plotted).max(FLOOR));
    let (x_min, x_max) = xs.fold((f64::MAX, 0.0f64), |(lo, hi), x| (lo.min(x), hi.max(x)));
    // Room on the right for the legend, clear of every point.
    let (x_min, x_max) = (x_min / 1.5, (x_max * 6.0).max(x_min * 40.0));
    let (y_min, y_max) = ys.fold((f64::MAX, 0.0f64), |(lo, hi), y| (lo.min(y), hi.max(y)));
    let (y_min, y_max) = (y_min / 2.0, (y_max * 2.0).max(y_min * 10.0));
    let metric = plotted.label();
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{name}: {metric} against cost"), ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d((x_min..x_max).log_scale(), (y_min..y_max).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("ms per 1/60 s of simulated time (median)")
        .y_desc(metric)
        .x_label_formatter(&|x| format!("{x:.2}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    let mut resolvers: Vec<&str> = rows.iter().map(|r| r.resolver).collect();
    resolvers.dedup();
    for (i, resolver) in resolvers.into_iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let points: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.resolver == resolver)
            .map(|r| {
                (
                    r.metrics.ms_per_60hz_step.max(FLOOR),
                    error_of(&r.metrics, plotted).max(FLOOR),
                )
            })
            .collect();
        chart
            .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
            .map_err(err)?
            .label(resolver)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 4, color.filled())))
            .map_err(err)?;
        // Each point is labelled with its setting, so a curve reads as its sweep.
        let labels = rows
            .iter()
            .filter(|r| r.resolver == resolver)
            .zip(&points)
            .map(|(r, &p)| {
                EmptyElement::at(p)
                    + Text::new(
                        r.setting.label.clone(),
                        (6, -14),
                        ("sans-serif", 11).into_font().color(&color),
                    )
            });
        chart.draw_series(labels).map_err(err)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::MiddleRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}
