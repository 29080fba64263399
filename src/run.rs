//! Running a scene headless: the loop the `jostle` command, the tests and the benchmarks share,
//! with a per-step observer, the CSV trace and the summary of a run.

use crate::world::{StepError, World};
use std::io::Write;
use std::time::Duration;

/// The header of a trace file, exactly.
pub const TRACE_HEADER: &str = "step,time,body,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz,awake";

/// Writes one CSV row per dynamic body: the state of `world` after `step` steps.
/// Numbers are printed in Rust's shortest round-trip form, so a trace is bit-exact.
pub fn write_trace_rows(
    out: &mut impl Write,
    world: &World,
    step: u64,
    dt: f32,
) -> std::io::Result<()> {
    let time = step as f64 * dt as f64;
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

/// What a run measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunSummary {
    /// Steps taken.
    pub steps: u64,
    /// Wall time of each step.
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
/// (step counts from 1), and summarises.
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
    let mut stage_times: Vec<Vec<Duration>> =
        (0..7).map(|_| Vec::with_capacity(steps as usize)).collect();
    let dynamic = world.bodies().filter(|(_, _, b)| !b.is_fixed()).count();
    for step in 1..=steps {
        let report = world.step(dt)?;
        s.quarantined
            .extend(report.quarantined.into_iter().map(|(_, name)| (step, name)));
        let p = world.profile();
        s.step_times.push(p.total);
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
        observe(world, step).map_err(|e| RunError::Io(e.to_string()))?;
    }
    s.steps = steps;
    let names = world.profile().stages().map(|(n, _)| n);
    s.stage_medians = names
        .iter()
        .zip(&stage_times)
        .map(|(n, t)| (*n, median(t)))
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
