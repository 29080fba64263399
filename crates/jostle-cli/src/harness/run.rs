//! Running a scene headless: the loop the `jostle` command, the tests and the benchmarks share,
//! with a per-step observer, the CSV trace and the summary of a run.

use jostle::{StepError, World};
use std::io::Write;
use std::time::Duration;

/// The header of a trace file, exactly.
pub const TRACE_HEADER: &str = "step,time,body,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz,awake";

/// Writes one CSV row per body that is not fixed (dynamic and kinematic): the state of `world` now, labelled with the world's own
/// step count and simulated time, so a run continued from a snapshot numbers its rows as the
/// uninterrupted run does. Numbers are printed in Rust's shortest round-trip form, so a trace
/// is bit-exact.
pub fn write_trace_rows(out: &mut impl Write, world: &World) -> std::io::Result<()> {
    let (time, step) = world.time();
    for (_, name, b) in world.bodies() {
        if b.is_fixed() {
            continue;
        }
        let (p, q, v, w) = (
            b.position,
            b.orientation,
            b.linear_velocity,
            b.angular_velocity,
        );
        writeln!(
            out,
            "{step},{time},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            csv_field(name),
            p.x,
            p.y,
            p.z,
            q.x,
            q.y,
            q.z,
            q.w,
            v.x,
            v.y,
            v.z,
            w.x,
            w.y,
            w.z,
            u8::from(b.sleep.awake)
        )?;
    }
    Ok(())
}

/// Quotes a CSV field when it holds a comma, quote or newline.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Most values a [`Sampled`] series keeps.
pub const SAMPLE_CAP: usize = 1 << 16;

/// A long series kept in bounded memory: every value while there are at most [`SAMPLE_CAP`],
/// then every second one, every fourth, and so on (a uniform subsample in order), so that a
/// run's memory does not grow with its steps (`--steps 6000000` held 990 MB of per-step
/// times). Medians over it are those of the subsample.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sampled<T> {
    values: Vec<T>,
    /// Every `stride`-th value is kept (a power of two; 0 before the first value).
    stride: u64,
    /// Values offered so far.
    seen: u64,
}

impl<T: Copy> Sampled<T> {
    /// Offers the next value of the series.
    pub fn push(&mut self, value: T) {
        self.stride = self.stride.max(1);
        let index = self.seen;
        self.seen += 1;
        if !index.is_multiple_of(self.stride) {
            return;
        }
        if self.values.len() >= SAMPLE_CAP {
            // Keep every second value: those at the doubled stride.
            let mut kept = 0;
            for i in (0..self.values.len()).step_by(2) {
                self.values[kept] = self.values[i];
                kept += 1;
            }
            self.values.truncate(kept);
            self.stride *= 2;
            if !index.is_multiple_of(self.stride) {
                return;
            }
        }
        self.values.push(value);
    }

    /// The values kept, in order.
    pub fn values(&self) -> &[T] {
        &self.values
    }
}

/// What a run measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunSummary {
    /// Steps taken.
    pub steps: u64,
    /// Wall time of each step; beyond [`SAMPLE_CAP`] steps, of a uniform subsample of them
    /// ([`Sampled`]).
    pub step_times: Vec<Duration>,
    /// Median wall time of each stage over the run, in pipeline order.
    pub stage_medians: Vec<(&'static str, Duration)>,
    /// Kinetic energy before the first step (J).
    pub kinetic_energy_initial: f64,
    /// Kinetic energy after the last step (J).
    pub kinetic_energy_final: f64,
    /// Largest penetration among the last step's contacts (m).
    pub max_penetration_final: f32,
    /// Largest penetration seen in any step (m).
    pub max_penetration_run: f32,
    /// Awake dynamic bodies after the last step.
    pub awake_final: usize,
    /// First step after which every dynamic body was asleep (and stayed so to the end).
    pub all_asleep_step: Option<u64>,
    /// Bodies quarantined for non-finite state, with the step.
    pub quarantined: Vec<(u64, String)>,
    /// Pairs of touching bodies beyond [`jostle::MAX_CONTACT_MASS_RATIO`]
    /// ([`jostle::StepReport::beyond_mass_ratio`]), each once: the first step, the lighter
    /// body's name, the heavier's and their mass ratio.
    pub beyond_mass_ratio: Vec<(u64, String, String, f32)>,
    /// Resolver passes per step, position then velocity (the step profile's `resolve_stats`): picks
    /// (the Millington resolver) or contact sweeps (the soft step), mean over the run.
    pub picks_per_step: [f64; 2],
    /// What each pass left unresolved, position (m) then velocity (m/s): the median and the
    /// largest over the run of the profile's `position_residual` and
    /// `velocity_residual` (zero for the soft step, which has no such measure).
    pub residual_median: [f32; 2],
    /// See [`RunSummary::residual_median`].
    pub residual_max: [f32; 2],
    /// Contact rows the soft step solved directly per step (the step profile's
    /// `resolve_stats.direct_rows`), mean over the run.
    pub direct_rows_per_step: f64,
    /// Steps whose resolve stage ran on more than one thread (the soft step's team; the
    /// step profile's `resolve_stats.threads` above 1).
    pub team_steps: u64,
}

impl RunSummary {
    /// Median wall time of one step.
    pub fn median_step(&self) -> Duration {
        median(&self.step_times)
    }
}

/// The median of a list of durations (zero for an empty list).
pub fn median(times: &[Duration]) -> Duration {
    if times.is_empty() {
        return Duration::ZERO;
    }
    let mut v = times.to_vec();
    v.sort_unstable();
    v[v.len() / 2]
}

/// Steps `world` `steps` times with `dt`, calling `observe(world, step)` after every step
/// (`step` is the world's step count, so it continues from a restored snapshot), and
/// summarises.
pub fn run(
    world: &mut World,
    steps: u64,
    dt: f32,
    mut observe: impl FnMut(&World, u64) -> std::io::Result<()>,
) -> Result<RunSummary, RunError> {
    let mut s = RunSummary {
        kinetic_energy_initial: world.kinetic_energy(),
        ..Default::default()
    };
    // Bounded series: reserving `steps` up front made `--steps 4000000000` abort on a 64 GB
    // allocation before the first step, and growing with the steps held 165 bytes a step.
    let mut step_times = Sampled::default();
    let mut stage_times: Vec<Sampled<Duration>> = (0..jostle::StepProfile::STAGES)
        .map(|_| Sampled::default())
        .collect();
    let dynamic = world.bodies().filter(|(_, _, b)| !b.is_fixed()).count();
    let mut residuals: [Sampled<f32>; 2] = [Sampled::default(), Sampled::default()];
    let mut residual_max = [0.0f32; 2];
    let mut picks = [0u64; 2];
    let mut direct_rows = 0u64;
    let mut seen_ratios = std::collections::HashSet::new();
    for step in 1..=steps {
        let report = world.step(dt)?;
        s.quarantined
            .extend(report.quarantined.into_iter().map(|(_, name)| (step, name)));
        for (light, heavy) in report.beyond_mass_ratio {
            if seen_ratios.insert((light, heavy)) {
                let name = |h| world.body_name(h).unwrap_or_default().to_string();
                let mass = |h| world.body(h).map_or(0.0, |b| b.mass());
                let ratio = mass(heavy) / mass(light);
                s.beyond_mass_ratio
                    .push((step, name(light), name(heavy), ratio));
            }
        }
        let p = world.profile();
        step_times.push(p.total);
        let r = &p.resolve_stats;
        picks[0] += u64::from(r.position_iterations);
        picks[1] += u64::from(r.velocity_iterations);
        direct_rows += u64::from(r.direct_rows);
        s.team_steps += u64::from(r.threads > 1);
        for (pass, residual) in [r.position_residual, r.velocity_residual]
            .into_iter()
            .enumerate()
        {
            residuals[pass].push(residual);
            residual_max[pass] = residual_max[pass].max(residual);
        }
        for (i, (_, t)) in p.stages().iter().enumerate() {
            stage_times[i].push(*t);
        }
        s.max_penetration_run = s.max_penetration_run.max(world.max_penetration());
        let all_asleep = dynamic > 0 && p.awake_bodies == 0;
        match (all_asleep, s.all_asleep_step) {
            (true, None) => s.all_asleep_step = Some(step),
            (false, Some(_)) => s.all_asleep_step = None,
            _ => {}
        }
        observe(world, world.time().1).map_err(|e| RunError::Io(e.to_string()))?;
    }
    s.steps = steps;
    s.direct_rows_per_step = direct_rows as f64 / steps.max(1) as f64;
    for pass in 0..2 {
        s.picks_per_step[pass] = picks[pass] as f64 / steps.max(1) as f64;
        let mut v = residuals[pass].values().to_vec();
        v.sort_unstable_by(f32::total_cmp);
        s.residual_median[pass] = v.get(v.len() / 2).copied().unwrap_or(0.0);
        s.residual_max[pass] = residual_max[pass];
    }
    s.step_times = step_times.values().to_vec();
    let names = world.profile().stages().map(|(n, _)| n);
    s.stage_medians = names
        .iter()
        .zip(&stage_times)
        .map(|(n, t)| (*n, median(t.values())))
        .collect();
    s.kinetic_energy_final = world.kinetic_energy();
    s.max_penetration_final = world.max_penetration();
    s.awake_final = world.bodies().filter(|(_, _, b)| b.is_awake()).count();
    Ok(s)
}

/// Why a run stopped.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum RunError {
    /// A step was refused.
    #[error(transparent)]
    Step(#[from] StepError),
    /// The observer failed to write.
    #[error("write failed: {0}")]
    Io(String),
}

/// A world ready to run, from a scene file or a snapshot.
pub struct RunSetup {
    /// The world.
    pub world: World,
    /// The scene's name (for a snapshot: the scene it was taken from).
    pub name: String,
    /// The time step: the scene's `dt`, or the snapshot's.
    pub dt: f32,
    /// The scene's `steps` (for a snapshot: 600, the scene default).
    pub steps: u64,
    /// The scene's camera, if it sets one (snapshots carry none).
    pub camera: Option<jostle::scene::Camera>,
}

/// Overrides a command line applies on top of a scene's or snapshot's settings.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// Another resolver. A scene or snapshot that already names the same resolver keeps its
    /// own settings for it ([`Overrides::apply_resolver`]).
    pub resolver: Option<jostle::ResolverChoice>,
    /// Sleeping on or off.
    pub sleep: Option<bool>,
}

impl Overrides {
    /// Applies the resolver override to `own`, the resolver a scene or snapshot names: a
    /// different resolver replaces it (with the override's settings), the same one leaves
    /// `own` and its settings as they are. `--resolver millington` on a scene that declares
    /// `Millington(velocity_iterations: 64)` runs those 64 iterations.
    pub fn apply_resolver(&self, own: &mut jostle::ResolverChoice) {
        if let Some(r) = &self.resolver
            && r.name() != own.name()
        {
            *own = r.clone();
        }
    }
}

/// Loads a scene file, or a snapshot written by `jostle run --snapshot` (recognised by its
/// first item, `Snapshot(`), applies the overrides and builds the world.
pub fn load(path: &std::path::Path, overrides: &Overrides) -> Result<RunSetup, LoadError> {
    use jostle::scene::Scene;
    use jostle::snapshot::Snapshot;
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| LoadError::Io(format!("{file}: cannot read: {e}")))?;
    if Snapshot::is_snapshot_text(&text) {
        let mut snapshot = Snapshot::parse(&text, &file)?;
        overrides.apply_resolver(&mut snapshot.settings_mut().resolver);
        if let Some(on) = overrides.sleep {
            snapshot.settings_mut().sleep.enabled = on;
        }
        let (name, dt) = (snapshot.scene.clone(), snapshot.dt);
        let world = World::from_snapshot(snapshot).map_err(|e| match e {
            jostle::snapshot::SnapshotError::Invalid { message, .. } => {
                jostle::snapshot::SnapshotError::Invalid {
                    file: file.clone(),
                    message,
                }
            }
            other => other,
        })?;
        return Ok(RunSetup {
            world,
            name,
            dt,
            steps: 600,
            camera: None,
        });
    }
    let scene = Scene::parse(&text, &file)?;
    let mut settings = scene.settings();
    overrides.apply_resolver(&mut settings.resolver);
    if let Some(on) = overrides.sleep {
        settings.sleep.enabled = on;
    }
    let world = scene
        .build_with(settings)
        .map_err(|e| e.in_file(&file, &text))?;
    Ok(RunSetup {
        world,
        name: scene.name,
        dt: scene.dt,
        steps: scene.steps as u64,
        camera: scene.camera,
    })
}

/// Why a scene or snapshot could not be loaded.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum LoadError {
    /// The file could not be read.
    #[error("{0}")]
    Io(String),
    /// A bad scene (boxed: a scene error carries the file, the place and the message).
    #[error(transparent)]
    Scene(Box<jostle::scene::SceneError>),
    /// A bad snapshot.
    #[error(transparent)]
    Snapshot(#[from] jostle::snapshot::SnapshotError),
}

impl From<jostle::scene::SceneError> for LoadError {
    fn from(e: jostle::scene::SceneError) -> Self {
        Self::Scene(Box::new(e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jostle::{MillingtonSettings, ResolverChoice, SoftStepSettings};

    fn resolver_after(scene: &str, name: &str) -> ResolverChoice {
        let path = std::env::temp_dir().join(format!(
            "jostle-run-override-{}-{name}.ron",
            std::process::id()
        ));
        std::fs::write(&path, scene).unwrap();
        let overrides = Overrides {
            resolver: Some(ResolverChoice::from_name(name).unwrap()),
            sleep: None,
        };
        let setup = load(&path, &overrides);
        let _ = std::fs::remove_file(&path);
        setup.unwrap().world.settings().resolver.clone()
    }

    /// The summary reports what the Millington resolver's passes left unresolved: a column of
    /// ten boxes with a budget of one velocity pick per contact leaves more than the epsilon
    /// (the stack is not resolved), the default budget on one box leaves nothing above it.
    /// A long series keeps at most `SAMPLE_CAP` values, evenly spaced over all of it.
    #[test]
    fn a_sampled_series_stays_bounded_and_uniform() {
        let mut series = Sampled::default();
        let n = 5 * SAMPLE_CAP as u64 + 3;
        for i in 0..n {
            series.push(i);
        }
        let kept = series.values();
        assert!(
            kept.len() <= SAMPLE_CAP && kept.len() > SAMPLE_CAP / 2,
            "{}",
            kept.len()
        );
        let stride = kept[1] - kept[0];
        assert!(stride.is_power_of_two() && stride > 1);
        assert!(
            kept.iter()
                .enumerate()
                .all(|(k, &v)| v == k as u64 * stride)
        );
        assert!(
            n - 1 - kept[kept.len() - 1] < stride,
            "the last kept is within a stride of the end"
        );
        // Short series keep every value.
        let mut short = Sampled::default();
        (0..10u64).for_each(|i| short.push(i));
        assert_eq!(short.values(), (0..10).collect::<Vec<_>>().as_slice());
    }

    #[test]
    fn the_summary_reports_picks_and_what_the_passes_left() {
        let run_scene = |text: &str| {
            let scene = jostle::scene::Scene::parse(text, "t.ron").unwrap();
            let mut world = scene.build().unwrap();
            run(&mut world, 60, 1.0 / 60.0, |_, _| Ok(())).unwrap()
        };
        let starved = run_scene(
            "Scene(resolver: Millington(velocity_iterations: (fixed: 0, per_contact: 1)), \
             sleep: (enabled: false), \
             bodies: [Body(name: \"g\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true)], \
             generators: [Stack(count: 10, half_extents: (0.5, 0.5, 0.5))])",
        );
        let epsilon = MillingtonSettings::default().velocity_epsilon;
        assert!(
            starved.picks_per_step[1] > 0.0,
            "{:?}",
            starved.picks_per_step
        );
        assert!(
            starved.residual_max[1] > epsilon,
            "velocity left {:?}",
            starved.residual_max
        );
        let one = run_scene(
            "Scene(resolver: Millington(), sleep: (enabled: false), \
             bodies: [Body(name: \"g\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true), \
             Body(name: \"b\", shape: Cuboid(half_extents: (0.5, 0.5, 0.5)), position: (0.0, 0.5, 0.0))])",
        );
        assert!(
            one.residual_max[1] <= epsilon,
            "velocity left {:?}",
            one.residual_max
        );
    }

    #[test]
    fn naming_the_scenes_own_resolver_keeps_its_settings() {
        let scene = "Scene(resolver: Millington(velocity_iterations: 64, relaxation: 0.5))";
        let Some(own) = jostle::scene::Scene::parse(scene, "t.ron")
            .unwrap()
            .resolver
        else {
            panic!("the scene names a resolver")
        };
        assert_eq!(resolver_after(scene, "millington"), own);
        assert_ne!(
            own,
            ResolverChoice::Millington(MillingtonSettings::default())
        );
        // Another resolver replaces it, at its defaults.
        assert_eq!(
            resolver_after(scene, "soft-step"),
            ResolverChoice::SoftStep(SoftStepSettings::default())
        );
        let scene = "Scene(resolver: SoftStep(substeps: 3))";
        assert!(matches!(
            resolver_after(scene, "soft-step"),
            ResolverChoice::SoftStep(s) if s.substeps == 3
        ));
    }
}
