//! `jostle run`: step a scene, show progress, print the summary, write the trace, and render
//! the run to an image or an animation (`--render`, see `render_out`).

use crate::harness::run::{
    Overrides, RunSetup, RunSummary, TRACE_HEADER, load, run as run_world, write_trace_rows,
};
use crate::render_out::{self, RenderFlags};
use crate::staged::Staged;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use jostle::ResolverChoice;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Arguments of `jostle run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// The scene file (.ron), or a snapshot written by `--snapshot` to continue from.
    scene: PathBuf,
    /// Steps to run (default: the scene's `steps`).
    #[arg(long)]
    steps: Option<u64>,
    /// Time step in seconds (default: the scene's `dt`).
    #[arg(long)]
    dt: Option<f32>,
    /// Resolver: millington or soft-step (default: the scene's, else soft-step). A scene that
    /// names the same resolver keeps its settings for it.
    #[arg(long)]
    resolver: Option<String>,
    /// Write a CSV trace of every body that is not fixed (dynamic and kinematic) to this file.
    #[arg(long, value_name = "FILE.csv")]
    trace: Option<PathBuf>,
    /// Trace every K-th step (steps 0 and the last are always written). Only with --trace.
    #[arg(long, default_value_t = 1, value_name = "K", requires = "trace")]
    every: u64,
    /// Disable sleeping (every body simulated every step).
    #[arg(long)]
    no_sleep: bool,
    /// Print one JSON object on stdout instead of the table (everything else goes to stderr).
    #[arg(long)]
    json: bool,
    /// Render the run: FILE.png draws the last frame, FILE.gif animates the run.
    #[arg(long, value_name = "FILE.png|FILE.gif")]
    render: Option<PathBuf>,
    /// GIF: draw every K-th step (default: round(1 / (fps·dt)), so the GIF plays in real time).
    #[arg(long, value_name = "K", requires = "render")]
    frame_every: Option<u64>,
    /// GIF: frames per second of playback (1 to 50).
    #[arg(
        long,
        default_value_t = 30,
        value_name = "N",
        requires = "render",
        value_parser = clap::value_parser!(u32).range(1..=50)
    )]
    fps: u32,
    /// Image size in pixels.
    #[arg(
        long,
        default_value = "640x480",
        value_name = "WxH",
        requires = "render"
    )]
    size: String,
    /// Draw contact points (red) and normals (yellow).
    #[arg(long, requires = "render")]
    contacts: bool,
    /// After the run, write the world's complete state to this file; `jostle run FILE`
    /// continues from it bit for bit (trace rows keep counting steps from where it stopped).
    #[arg(long, value_name = "FILE.ron")]
    snapshot: Option<PathBuf>,
}

pub fn run(args: RunArgs) -> Result<(), String> {
    let overrides = Overrides {
        resolver: args
            .resolver
            .as_deref()
            .map(ResolverChoice::from_name)
            .transpose()?,
        sleep: args.no_sleep.then_some(false),
    };
    let RunSetup {
        mut world,
        name: scene_name,
        dt: scene_dt,
        steps: scene_steps,
        camera,
    } = load(&args.scene, &overrides).map_err(|e| e.to_string())?;
    let dt = args.dt.unwrap_or(scene_dt);
    if !(dt.is_finite() && dt > 0.0 && dt <= jostle::MAX_DT) {
        // Named by where it came from: a snapshot's own `dt` was reported as `--dt`.
        let source = match args.dt {
            Some(_) => "--dt".to_string(),
            None => format!("{}: dt", args.scene.display()),
        };
        return Err(format!(
            "{source} must be in (0, {}] s, got {dt}",
            jostle::MAX_DT
        ));
    }
    if args.every == 0 {
        return Err("--every must be at least 1".into());
    }
    let steps = args.steps.unwrap_or(scene_steps);
    let resolver_name = world.resolver_name();
    let last_step = world.time().1.saturating_add(steps);
    check_outputs(
        &args.scene,
        &[
            ("--trace", args.trace.as_deref()),
            ("--render", args.render.as_deref()),
            ("--snapshot", args.snapshot.as_deref()),
        ],
    )?;

    let mut render = match &args.render {
        Some(path) => {
            let flags = RenderFlags {
                path: path.clone(),
                frame_every: args.frame_every,
                fps: args.fps,
                size: args.size.clone(),
                contacts: args.contacts,
            };
            let mut job = render_out::start(&flags, camera.as_ref(), dt)?;
            job.observe(&world, 0)?;
            Some(job)
        }
        None => None,
    };

    let mut trace = match &args.trace {
        Some(path) => {
            let staged = Staged::new(path);
            let file = File::create(staged.path())
                .map_err(|e| format!("{}: cannot create: {e}", path.display()))?;
            let mut w = BufWriter::new(file);
            writeln!(w, "{TRACE_HEADER}")
                .and_then(|_| write_trace_rows(&mut w, &world))
                .map_err(|e| e.to_string())?;
            Some((w, staged))
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
    bar.set_message(scene_name.clone());
    if steps < 200 {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let every = args.every;
    let summary = run_world(&mut world, steps, dt, |w, step| {
        bar.inc(1);
        if let Some(job) = render.as_mut() {
            job.observe(w, step).map_err(std::io::Error::other)?;
        }
        match trace.as_mut() {
            Some((out, _)) if step % every == 0 || step == last_step => write_trace_rows(out, w),
            _ => Ok(()),
        }
    })
    .map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    // Every output is complete before any replaces its target.
    let trace = match trace {
        Some((w, staged)) => {
            w.into_inner()
                .map_err(|e| e.to_string())
                .and_then(|f| f.sync_all().map_err(|e| e.to_string()))?;
            Some(staged)
        }
        None => None,
    };
    let render = match render {
        Some(job) => Some(job.finish(&world)?),
        None => None,
    };
    let snapshot = match &args.snapshot {
        Some(path) => {
            let staged = Staged::new(path);
            world
                .snapshot(&scene_name, dt)
                .save(staged.path())
                .map_err(|e| e.to_string())?;
            Some(staged)
        }
        None => None,
    };
    for staged in [trace, snapshot].into_iter().flatten() {
        staged.commit()?;
    }
    if let Some((staged, message)) = render {
        staged.commit()?;
        eprintln!("{message}");
    }
    for (step, light, heavy, ratio) in &summary.beyond_mass_ratio {
        eprintln!(
            "warning: step {step}: body \"{light}\" touches \"{heavy}\", {ratio:.1e} times as \
             heavy: beyond the mass ratio of {:e} that the soft step's contacts hold, the \
             lighter body may be pressed into its neighbours or thrown out (the Millington \
             resolver holds it)",
            jostle::MAX_CONTACT_MASS_RATIO
        );
    }
    for (step, name) in &summary.quarantined {
        eprintln!(
            "warning: step {step}: body \"{name}\" went non-finite or out of range (beyond \
             {:e} m, {:e} m/s or {:e} rad/s) and was frozen",
            jostle::MAX_POSITION,
            jostle::MAX_SPEED,
            jostle::MAX_REACHED_ANGULAR_SPEED
        );
    }

    let bodies = world.body_count();
    let text = if args.json {
        format!(
            "{}\n",
            json_summary(&scene_name, resolver_name, dt, bodies, &summary)
        )
    } else {
        table_text(&scene_name, resolver_name, dt, bodies, &summary)
    };
    crate::print_out(&text)
}

/// Checks the output files before anything is written, so that a bad one loses nothing: none
/// may be the scene being read or another output (an output named like the input used to
/// overwrite the scene with CSV and exit 0), and each must be writable (a trace into a missing
/// directory used to fail after the PNG had been truncated, and a snapshot was tried only after
/// the whole run), and none may be named for another output's format (`--trace out.png`). The
/// check opens an existing file without truncating it and removes a file it had to create.
fn check_outputs(scene: &Path, outputs: &[(&str, Option<&Path>)]) -> Result<(), String> {
    let scene_id = identity(scene);
    let mut seen: Vec<(&str, PathBuf)> = Vec::new();
    for &(flag, path) in outputs {
        let Some(path) = path else { continue };
        let id = identity(path);
        if id == scene_id {
            return Err(format!(
                "{flag} {}: that is the scene being run; choose another file",
                path.display()
            ));
        }
        if let Some((other, _)) = seen.iter().find(|(_, p)| *p == id) {
            return Err(format!(
                "{flag} {}: {other} writes the same file; choose another",
                path.display()
            ));
        }
        // An extension that names another of the outputs' formats is a mix-up (`--trace
        // out.png --snapshot snap.csv` wrote CSV into the PNG and RON into the CSV); any other,
        // or none (`/dev/stdout`), is taken as asked.
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        let foreign: &[&str] = match flag {
            "--trace" => &["png", "gif", "ron", "svg", "jpg", "jpeg"],
            "--snapshot" => &["csv", "png", "gif", "svg", "jpg", "jpeg"],
            _ => &[],
        };
        if let Some(ext) = ext.filter(|e| foreign.contains(&e.as_str())) {
            let writes = if flag == "--trace" {
                "CSV"
            } else {
                "a RON snapshot"
            };
            return Err(format!(
                "{flag} {}: {flag} writes {writes}, not a .{ext} file; choose another name",
                path.display()
            ));
        }
        writable(path).map_err(|e| format!("{flag} {}: cannot write: {e}", path.display()))?;
        seen.push((flag, id));
    }
    Ok(())
}

/// The path a file is known by: canonical when it exists, else its directory's canonical path
/// joined with its name (so `./a.csv` and `a.csv` are one file).
pub(crate) fn identity(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match (std::fs::canonicalize(dir), path.file_name()) {
        (Ok(d), Some(name)) => d.join(name),
        _ => path.to_path_buf(),
    }
}

/// Whether `path` can be written, without truncating it if it exists. An existing target
/// that is not a regular file (a device, a named pipe) is not opened: a pipe without a reader
/// would block here; it is written at the end ([`Staged`]). Such a target must exist (a
/// misspelt `/dev/stdot` failed only after the whole run).
pub(crate) fn writable(path: &Path) -> std::io::Result<()> {
    if path.is_dir() {
        return Err(std::io::Error::other("it is a directory"));
    }
    // The file that will be replaced: a link's target (a dangling link was refused here as
    // "File exists"), or nothing to check for a target written into.
    let (path, stream) = crate::staged::resolve(path);
    if stream {
        return std::fs::metadata(&path).map(|_| ());
    }
    let path = path.as_path();
    if path.exists() {
        std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .map(|_| ())
    } else {
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)?;
        std::fs::remove_file(path)
    }
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
        "beyond_mass_ratio": s.beyond_mass_ratio.len(),
        "picks_per_step": {
            "position": s.picks_per_step[0],
            "velocity": s.picks_per_step[1],
        },
        "direct_rows_per_step": s.direct_rows_per_step,
        "team_steps": s.team_steps,
        "residual": {
            "position_median_m": s.residual_median[0],
            "position_max_m": s.residual_max[0],
            "velocity_median_m_per_s": s.residual_median[1],
            "velocity_max_m_per_s": s.residual_max[1],
        },
    })
    .to_string()
}

fn table_text(scene: &str, resolver: &str, dt: f32, bodies: usize, s: &RunSummary) -> String {
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
        // (`+ 0.0` prints an empty scene's negative-zero sum as 0.)
        (
            "kinetic energy start (J)".into(),
            format!("{:.6}", s.kinetic_energy_initial + 0.0),
        ),
        (
            "kinetic energy end (J)".into(),
            format!("{:.6}", s.kinetic_energy_final + 0.0),
        ),
        (
            "largest penetration, last step (m)".into(),
            format!("{:.5}", s.max_penetration_final),
        ),
        (
            "largest penetration, whole run (m)".into(),
            format!("{:.5}", s.max_penetration_run),
        ),
        (
            "picks per step, position / velocity".into(),
            format!("{:.1} / {:.1}", s.picks_per_step[0], s.picks_per_step[1]),
        ),
        (
            "contact rows solved directly per step".into(),
            format!("{:.1}", s.direct_rows_per_step),
        ),
        (
            "steps resolved on more than one thread".into(),
            format!("{} of {}", s.team_steps, s.steps),
        ),
        (
            "left unresolved, median / max: position (m)".into(),
            format!("{:.2e} / {:.2e}", s.residual_median[0], s.residual_max[0]),
        ),
        (
            "left unresolved, median / max: velocity (m/s)".into(),
            format!("{:.2e} / {:.2e}", s.residual_median[1], s.residual_max[1]),
        ),
        ("bodies awake at end".into(), s.awake_final.to_string()),
        (
            "all asleep from step".into(),
            s.all_asleep_step.map_or("-".into(), |n| n.to_string()),
        ),
    ])
    .collect();
    let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    rows.iter()
        .map(|(k, v)| format!("{k:<width$}  {v}\n"))
        .collect()
}
