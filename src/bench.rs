//! The benchmark harness: runs a world for a given simulated time under one setting and
//! measures its cost (median wall time per step) beside its error metrics. `jostle bench` is
//! built on it; benches/vs_rapier.rs measures drift by the same definition, so that a figure
//! means the same thing in every table of benches/RESULTS.md.
//!
//! The metrics, each computed over the run of [`run_case`]:
//!
//! - **drift** (m): the largest displacement of any dynamic body between the settle time and
//!   the end. For a scene that should come to rest (stacks, pyramids, walls) it is the error:
//!   an exact solver gives 0. This is the stability tests' criterion (tests/stability.rs).
//! - **largest penetration** (m): the deepest overlap of any contact in any step after the
//!   settle time (negative separations of speculative contacts count as 0).
//! - **mean penetration** (m): the mean, over the steps after the settle time that have
//!   overlapping contacts, of the mean overlap of those contacts.
//! - **energy error**: for a closed system only (no fixed body, so nothing outside the world
//!   does work but gravity), the largest |E(t) − E(0)| over the run divided by |E(0)|, where E
//!   is kinetic plus gravitational potential energy (potential measured from the origin), and
//!   by 1 J instead when |E(0)| < 1 J. `None` for scenes with fixed bodies, where contacts
//!   with the ground legitimately remove energy.
//! - **time to sleep** (s): the simulated time after which every dynamic body was asleep and
//!   stayed so to the end; `None` if that never happened (or sleeping is disabled).
//!
//! Cost is the median wall time of one step (the world's own profile total, so the harness's
//! bookkeeping is not counted), and the median of one *frame* when a frame is several world
//! steps ([`Setting::world_substeps`]). Because a sweep over `dt` changes how many steps make a
//! second, [`Metrics::ms_per_60hz_step`] normalizes cost to 1/60 s of simulated time, the unit
//! the frontier plots use.

use crate::settings::ResolverChoice;
use crate::world::{StepError, World};
use jostle_math::Vec3;
use std::time::Duration;

/// One setting of a sweep: a resolver with its settings and a time step.
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    /// Short label for tables and plots ("default", "substeps=4", "dt=1/120", ...).
    pub label: String,
    /// The resolver and its settings.
    pub resolver: ResolverChoice,
    /// The frame time step (s).
    pub dt: f32,
    /// World steps per frame (each of `dt / world_substeps`): substepping for a resolver that
    /// has no substeps of its own (Millington). 1 otherwise.
    pub world_substeps: u32,
}

/// What a sweep varies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sweep {
    /// Solver effort per step: Millington's picks per contact at 1/4, 1/2, 1 and 2 times the
    /// base settings' (position and velocity budgets alike; labelled `picks=P/V`, the defaults
    /// are 4/16), or the soft step's relax iterations (1, 2, 4, 8).
    Iterations,
    /// Substeps per 1/60 s frame (1, 2, 4, 8): the soft step's own substeps, or world steps of
    /// `dt / n` for Millington.
    Substeps,
    /// The time step: 1/30, 1/60, 1/120, 1/240 s, over the same simulated time.
    Dt,
}

impl Sweep {
    /// The names accepted on the command line.
    pub const NAMES: [&'static str; 3] = ["iterations", "substeps", "dt"];

    /// The sweep for a command-line name, or an error naming the accepted ones.
    pub fn from_name(name: &str) -> Result<Self, String> {
        match name {
            "iterations" => Ok(Self::Iterations),
            "substeps" => Ok(Self::Substeps),
            "dt" => Ok(Self::Dt),
            other => Err(format!(
                "unknown sweep `{other}`; expected one of: {}",
                Self::NAMES.join(", ")
            )),
        }
    }

    /// The settings of this sweep for `base` (a resolver with its settings), at frame step `dt`.
    pub fn settings(self, base: &ResolverChoice, dt: f32) -> Vec<Setting> {
        const LEVELS: [u32; 4] = [1, 2, 4, 8];
        let setting =
            |label: String, resolver: ResolverChoice, dt: f32, world_substeps: u32| Setting {
                label,
                resolver,
                dt,
                world_substeps,
            };
        match self {
            Self::Iterations => LEVELS
                .iter()
                .map(|&n| match base {
                    ResolverChoice::Millington(s) => {
                        // n/4 of the base budgets, so the sweep passes through them (n = 4).
                        let mut s = s.clone();
                        let scale = |k: u32| (k * n / 4).max(1);
                        s.position_iterations.per_contact =
                            scale(s.position_iterations.per_contact);
                        s.velocity_iterations.per_contact =
                            scale(s.velocity_iterations.per_contact);
                        setting(
                            format!(
                                "picks={}/{}",
                                s.position_iterations.per_contact,
                                s.velocity_iterations.per_contact
                            ),
                            ResolverChoice::Millington(s),
                            dt,
                            1,
                        )
                    }
                    ResolverChoice::SoftStep(s) => {
                        let mut s = s.clone();
                        s.relax_iterations = n;
                        setting(format!("relax={n}"), ResolverChoice::SoftStep(s), dt, 1)
                    }
                })
                .collect(),
            Self::Substeps => LEVELS
                .iter()
                .map(|&n| match base {
                    ResolverChoice::Millington(_) => {
                        setting(format!("substeps={n}"), base.clone(), dt, n)
                    }
                    ResolverChoice::SoftStep(s) => {
                        let mut s = s.clone();
                        s.substeps = n;
                        setting(format!("substeps={n}"), ResolverChoice::SoftStep(s), dt, 1)
                    }
                })
                .collect(),
            Self::Dt => [30u32, 60, 120, 240]
                .iter()
                .map(|&hz| setting(format!("dt=1/{hz}"), base.clone(), 1.0 / hz as f32, 1))
                .collect(),
        }
    }
}

/// Cost and error of one run. Every field's unit and meaning is in the module documentation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Metrics {
    /// Frames run.
    pub frames: u64,
    /// Median wall time of one frame (ms).
    pub ms_per_step: f64,
    /// `ms_per_step` scaled to 1/60 s of simulated time (ms).
    pub ms_per_60hz_step: f64,
    /// Largest displacement of any dynamic body between the settle time and the end (m).
    pub drift: f32,
    /// Largest contact penetration after the settle time (m).
    pub max_penetration: f32,
    /// Mean contact penetration after the settle time (m).
    pub mean_penetration: f32,
    /// Relative energy error of a closed system (`None` when the world has fixed bodies).
    pub energy_error: Option<f64>,
    /// Simulated time until every dynamic body slept for good (s).
    pub time_to_sleep: Option<f64>,
}

/// Total mechanical energy (J): kinetic plus gravitational potential, measured from the origin.
pub fn mechanical_energy(world: &World) -> f64 {
    let g = world.settings().gravity;
    let potential: f64 = world
        .bodies()
        .filter(|(_, _, b)| !b.is_fixed())
        .map(|(_, _, b)| -(b.mass() as f64) * g.dot(b.position) as f64)
        .sum();
    world.kinetic_energy() + potential
}

/// Positions of the dynamic bodies, in handle order.
fn dynamic_positions(world: &World) -> Vec<Vec3> {
    world
        .bodies()
        .filter(|(_, _, b)| !b.is_fixed())
        .map(|(_, _, b)| b.position)
        .collect()
}

/// Runs `world` for `duration` seconds of simulated time in frames of `setting.dt` (each
/// `setting.world_substeps` world steps), measuring from `settle` seconds on, and returns the
/// metrics. The world is expected to have been built with `setting.resolver`.
pub fn run_case(
    world: &mut World,
    setting: &Setting,
    duration: f64,
    settle: f64,
) -> Result<Metrics, StepError> {
    let dt = setting.dt as f64;
    let frames = (duration / dt).round().max(1.0) as u64;
    let settle_frame = ((settle / dt).round() as u64).min(frames - 1);
    let substeps = setting.world_substeps.max(1);
    let step_dt = setting.dt / substeps as f32;
    let closed = world.bodies().all(|(_, _, b)| !b.is_fixed());
    let dynamic = world.bodies().filter(|(_, _, b)| !b.is_fixed()).count();
    let e0 = mechanical_energy(world);
    let mut energy_error = 0.0f64;
    let mut settled = dynamic_positions(world);
    let mut frame_times = Vec::with_capacity(frames as usize);
    let (mut max_pen, mut pen_sum, mut pen_steps) = (0.0f32, 0.0f64, 0u64);
    let mut asleep_since: Option<u64> = None;

    for frame in 1..=frames {
        let mut t = Duration::ZERO;
        for _ in 0..substeps {
            world.step(step_dt)?;
            t += world.profile().total;
        }
        frame_times.push(t);
        if closed {
            energy_error = energy_error.max((mechanical_energy(world) - e0).abs());
        }
        if frame == settle_frame {
            settled = dynamic_positions(world);
        }
        if frame > settle_frame {
            let overlaps = world
                .contacts()
                .iter()
                .map(|c| c.penetration)
                .filter(|&p| p > 0.0);
            let (n, sum, max) = overlaps.fold((0u32, 0.0f64, 0.0f32), |(n, s, m), p| {
                (n + 1, s + p as f64, m.max(p))
            });
            max_pen = max_pen.max(max);
            if n > 0 {
                pen_sum += sum / n as f64;
                pen_steps += 1;
            }
        }
        let all_asleep = dynamic > 0 && world.profile().awake_bodies == 0;
        match (all_asleep, asleep_since) {
            (true, None) => asleep_since = Some(frame),
            (false, Some(_)) => asleep_since = None,
            _ => {}
        }
    }

    let drift = dynamic_positions(world)
        .iter()
        .zip(&settled)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max);
    let ms_per_step = crate::run::median(&frame_times).as_secs_f64() * 1e3;
    Ok(Metrics {
        frames,
        ms_per_step,
        ms_per_60hz_step: ms_per_step / (dt * 60.0),
        drift,
        max_penetration: max_pen,
        mean_penetration: if pen_steps > 0 {
            (pen_sum / pen_steps as f64) as f32
        } else {
            0.0
        },
        energy_error: closed.then(|| energy_error / e0.abs().max(1.0)),
        time_to_sleep: asleep_since.map(|f| f as f64 * dt),
    })
}
