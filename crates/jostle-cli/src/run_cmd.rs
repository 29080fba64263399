//! `jostle run`: step a scene, show progress, print the summary, write the trace.

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use jostle::ResolverChoice;
use jostle::run::{RunSummary, TRACE_HEADER, run as run_world, write_trace_rows};
use jostle::scene::Scene;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::time::Duration;

/// Arguments of `jostle run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// The scene file (.ron).
    scene: PathBuf,
    /// Steps to run (default: the scene's `steps`).
    #[arg(long)]
    steps: Option<u64>,
    /// Time step in seconds (default: the scene's `dt`).
    #[arg(long)]
    dt: Option<f32>,
    /// Resolver: millington or soft-step (default: the scene's, else the engine's best).
    #[arg(long)]
    resolver: Option<String>,
    /// Write a CSV trace of every dynamic body to this file.
    #[arg(long, value_name = "FILE.csv")]
    trace: Option<PathBuf>,
    /// Trace every K-th step (steps 0 and the last are always written).
    #[arg(long, default_value_t = 1, value_name = "K")]
    every: u64,
    /// Disable sleeping (every body simulated every step).
    #[arg(long)]
    no_sleep: bool,
    /// Print one JSON object on stdout instead of the table (everything else goes to stderr).
    #[arg(long)]
    json: bool,
}

pub fn run(args: RunArgs) -> Result<(), String> {
    let scene = Scene::load(&args.scene).map_err(|e| e.to_string())?;
    let mut settings = scene.settings();
    if let Some(name) = &args.resolver {
        settings.resolver = ResolverChoice::from_name(name)?;
    }
    if args.no_sleep {
        settings.sleep.enabled = false;
    }
    let dt = args.dt.unwrap_or(scene.dt);
    if !(dt.is_finite() && dt > 0.0) {
        return Err(format!("--dt must be finite and > 0, got {dt}"));
    }
    if args.every == 0 {
        return Err("--every must be at least 1".into());
    }
    let steps = args.steps.unwrap_or(scene.steps as u64);
    let resolver_name = settings.resolver.name();
    let mut world = scene.build_with(settings).map_err(|e| e.to_string())?;

    let mut trace = match &args.trace {
        Some(path) => {
            let file = File::create(path)
                .map_err(|e| format!("{}: cannot create: {e}", path.display()))?;
            let mut w = BufWriter::new(file);
            writeln!(w, "{TRACE_HEADER}")
                .and_then(|_| write_trace_rows(&mut w, &world, 0, dt))
                .map_err(|e| e.to_string())?;
            Some(w)
        }
        None => None,
    };

    let bar = ProgressBar::new(steps);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} {msg} [{bar:30}] {pos}/{len} steps, {per_sec}, eta {eta}",
        )
        .map_err(|e| e.to_string())?
        .progress_chars("=> "),
    );
    bar.set_message(scene.name.clone());
    if steps < 200 {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let every = args.every;
    let summary = run_world(&mut world, steps, dt, |w, step| {
        bar.inc(1);
        match trace.as_mut() {
            Some(out) if step % every == 0 || step == steps => write_trace_rows(out, w, step, dt),
            _ => Ok(()),
        }
    })
    .map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    if let Some(mut w) = trace {
        w.flush().map_err(|e| e.to_string())?;
    }
    for (step, name) in &summary.quarantined {
        eprintln!("warning: step {step}: body \"{name}\" went non-finite and was frozen");
    }

    let bodies = world.body_count();
    if args.json {
        println!(
            "{}",
            json_summary(&scene.name, resolver_name, dt, bodies, &summary)
        );
    } else {
        print_table(&scene.name, resolver_name, dt, bodies, &summary);
    }
    Ok(())
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn json_summary(scene: &str, resolver: &str, dt: f32, bodies: usize, s: &RunSummary) -> String {
    let stages: serde_json::Map<String, serde_json::Value> = s
        .stage_medians
        .iter()
        .map(|(n, t)| (n.to_string(), ms(*t).into()))
        .collect();
    serde_json::json!({
        "scene": scene,
        "resolver": resolver,
        "steps": s.steps,
        "dt": dt,
        "bodies": bodies,
        "ms_per_step": ms(s.median_step()),
        "stage_ms": stages,
        "max_penetration": s.max_penetration_final,
        "max_penetration_run": s.max_penetration_run,
        "kinetic_energy_initial": s.kinetic_energy_initial,
        "kinetic_energy_final": s.kinetic_energy_final,
        "awake_final": s.awake_final,
        "all_asleep_step": s.all_asleep_step,
        "quarantined": s.quarantined.len(),
    })
    .to_string()
}

fn print_table(scene: &str, resolver: &str, dt: f32, bodies: usize, s: &RunSummary) {
    let rows: Vec<(String, String)> = vec![
        ("scene".into(), scene.into()),
        ("resolver".into(), resolver.into()),
        ("bodies".into(), bodies.to_string()),
        ("steps".into(), format!("{} x {dt} s", s.steps)),
        (
            "ms/step (median)".into(),
            format!("{:.3}", ms(s.median_step())),
        ),
    ]
    .into_iter()
    .chain(
        s.stage_medians
            .iter()
            .map(|(n, t)| (format!("  {n} (median ms)"), format!("{:.3}", ms(*t)))),
    )
    .chain([
        (
            "kinetic energy start (J)".into(),
            format!("{:.6}", s.kinetic_energy_initial),
        ),
        (
            "kinetic energy end (J)".into(),
            format!("{:.6}", s.kinetic_energy_final),
        ),
        (
            "largest penetration, last step (m)".into(),
            format!("{:.5}", s.max_penetration_final),
        ),
        (
            "largest penetration, whole run (m)".into(),
            format!("{:.5}", s.max_penetration_run),
        ),
        ("bodies awake at end".into(), s.awake_final.to_string()),
        (
            "all asleep from step".into(),
            s.all_asleep_step.map_or("-".into(), |n| n.to_string()),
        ),
    ])
    .collect();
    let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    for (k, v) in rows {
        println!("{k:<width$}  {v}");
    }
}
