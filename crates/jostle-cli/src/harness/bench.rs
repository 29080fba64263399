//! The benchmark harness: runs a world for a given simulated time under one setting and
//! measures its cost (median wall time per step) beside its error metrics. `jostle bench` is
//! built on it; crates/jostle-compare/benches/vs_rapier.rs measures drift by the same definition, so that a figure
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
//! - **analytic error**: for a scene that declares its closed form (`analytic:` in the scene
//!   file, an [`Analytic`]), the largest difference between the run and that closed form,
//!   sampled after every frame; its unit is the declaration's (metres for trajectories and
//!   apex heights, m/s for the velocities after a collision). `None` for scenes without one.
//!   It is measured over the whole run, not only after the settle time.
//! - **quarantined**: bodies whose state went non-finite or out of range during the run and were frozen
//!   ([`jostle::StepReport::quarantined`]). A run with any reports an infinite drift and no time
//!   to sleep, since the frozen body neither stayed put nor slept.
//!
//! Cost is the median wall time of one step (the world's own profile total, so the harness's
//! bookkeeping is not counted), and the median of one *frame* when a frame is several world
//! steps ([`Setting::world_substeps`]). Because a sweep over `dt` changes how many steps make a
//! second, [`Metrics::ms_per_60hz_step`] normalizes cost to 1/60 s of simulated time, the unit
//! the frontier plots use.

use super::run::median;
use jostle::scene::Analytic;
use jostle::{BodyHandle, ResolverChoice, StepError, Vec3, World};
use std::time::Duration;

/// The state of one body at the start of a run, for the closed forms.
#[derive(Clone, Copy, Debug)]
struct Start {
    handle: BodyHandle,
    position: Vec3,
    velocity: Vec3,
    mass: f32,
}

/// Follows a run against an [`Analytic`] closed form, frame by frame.
#[derive(Clone, Debug)]
struct AnalyticTracker {
    spec: Analytic,
    g: Vec3,
    start: Vec<Start>,
    /// Largest error seen so far (trajectory kinds).
    error: f64,
    /// Bounce: apex heights measured so far, and the last frame's vertical velocity.
    apexes: Vec<f32>,
    last_vy: f32,
    last_y: f32,
}

impl AnalyticTracker {
    /// Records the start state; an error names a body the world does not have (or a fixed one).
    fn new(spec: &Analytic, world: &World) -> Result<Self, String> {
        let mut start = Vec::new();
        for name in spec.bodies() {
            let handle = world
                .find_body(name)
                .ok_or_else(|| format!("analytic: no body named \"{name}\""))?;
            let body = world
                .body(handle)
                .ok_or_else(|| format!("analytic: no body named \"{name}\""))?;
            if body.is_fixed() {
                return Err(format!(
                    "analytic: body \"{name}\" is fixed; the closed form needs a dynamic body"
                ));
            }
            start.push(Start {
                handle,
                position: body.position,
                velocity: body.linear_velocity,
                mass: body.mass(),
            });
        }
        Ok(Self {
            spec: spec.clone(),
            g: world.settings().gravity,
            last_vy: start[0].velocity.y,
            last_y: start[0].position.y,
            start,
            error: 0.0,
            apexes: Vec::new(),
        })
    }

    /// Compares the world at simulated time `t` with the closed form.
    fn observe(&mut self, world: &World, t: f64) {
        let s = self.start[0];
        let Some(body) = world.body(s.handle) else {
            return;
        };
        let (p, v) = (body.position, body.linear_velocity);
        let g = self.g.length() as f64;
        let err = match &self.spec {
            Analytic::FreeFall { .. } => {
                let t = t as f32;
                let expected = s.position + s.velocity * t + 0.5 * self.g * t * t;
                Some(p.distance(expected) as f64)
            }
            Analytic::Incline {
                angle, friction, ..
            } => {
                let theta = (*angle as f64).to_radians();
                let a = (g * (theta.sin() - *friction as f64 * theta.cos())).max(0.0);
                Some((p.distance(s.position) as f64 - 0.5 * a * t * t).abs())
            }
            Analytic::SlidingToRolling { friction, .. } => {
                let up = -self.g.normalize_or(Vec3::NEG_Y);
                let flat = |x: Vec3| x - up * x.dot(up);
                let v0 = flat(s.velocity).length() as f64;
                let mu_g = *friction as f64 * g;
                let t_roll = if mu_g > 0.0 {
                    2.0 * v0 / (7.0 * mu_g)
                } else {
                    f64::INFINITY
                };
                let x = if t < t_roll {
                    v0 * t - 0.5 * mu_g * t * t
                } else {
                    v0 * t_roll - 0.5 * mu_g * t_roll * t_roll + 5.0 / 7.0 * v0 * (t - t_roll)
                };
                Some((flat(p - s.position).length() as f64 - x).abs())
            }
            Analytic::Bounce { rest_height, .. } => {
                let top = p.y.max(self.last_y);
                if self.last_vy > 0.0 && v.y <= 0.0 && top > rest_height + 0.01 {
                    self.apexes.push(top);
                }
                (self.last_vy, self.last_y) = (v.y, p.y);
                None
            }
            Analytic::Collision { .. } => None,
        };
        if let Some(e) = err {
            self.error = self.error.max(e);
        }
    }

    /// The analytic error of the run that ended at simulated time `end`.
    fn finish(&self, world: &World, end: f64) -> f64 {
        match &self.spec {
            Analytic::Bounce {
                restitution,
                rest_height,
                ..
            } => {
                let (e, rest) = (*restitution as f64, *rest_height as f64);
                let g = self.g.length() as f64;
                let h0 = (self.start[0].position.y as f64 - rest).max(0.0);
                // Closed-form apexes: the fall takes √(2h₀/g); after the k-th impact the body
                // leaves at eᵏ·√(2gh₀) and spends 2eᵏ√(2h₀/g) in the air.
                let fall = if g > 0.0 { (2.0 * h0 / g).sqrt() } else { 0.0 };
                let mut expected = Vec::new();
                let mut impact = fall;
                let mut k = 1;
                while g > 0.0 && h0 > 0.0 && e > 0.0 && k < 64 {
                    let flight = 2.0 * e.powi(k) * fall;
                    let apex_time = impact + flight / 2.0;
                    let height = e.powi(2 * k) * h0;
                    if apex_time >= end || height <= 0.01 {
                        break;
                    }
                    expected.push(rest + height);
                    impact += flight;
                    k += 1;
                }
                expected
                    .iter()
                    .enumerate()
                    .map(|(i, &h)| match self.apexes.get(i) {
                        Some(&y) => (y as f64 - h).abs(),
                        None => h - rest,
                    })
                    .fold(0.0, f64::max)
            }
            Analytic::Collision { restitution, .. } => {
                let (a, b) = (self.start[0], self.start[1]);
                let d = (b.position - a.position).normalize_or_zero();
                let (ua, ub) = (a.velocity.dot(d) as f64, b.velocity.dot(d) as f64);
                let (ma, mb) = (a.mass as f64, b.mass as f64);
                let e = *restitution as f64;
                let (ua2, ub2) = if ua - ub > 0.0 {
                    let p = ma * ua + mb * ub;
                    (
                        (p - mb * e * (ua - ub)) / (ma + mb),
                        (p + ma * e * (ua - ub)) / (ma + mb),
                    )
                } else {
                    (ua, ub)
                };
                let expected = |s: Start, u: f64, u2: f64| s.velocity + d * (u2 - u) as f32;
                let error = |s: Start, u: f64, u2: f64| {
                    world.body(s.handle).map_or(f64::INFINITY, |body| {
                        body.linear_velocity.distance(expected(s, u, u2)) as f64
                    })
                };
                error(a, ua, ua2).max(error(b, ub, ub2))
            }
            _ => self.error,
        }
    }
}

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
    /// The run against the scene's closed form (`None` when the scene declares none); unit
    /// per [`Analytic`] kind.
    pub analytic_error: Option<f64>,
    /// Bodies quarantined during the run (their state went non-finite or out of range and they were frozen,
    /// [`jostle::StepReport::quarantined`]). A run with any has an infinite `drift` and no
    /// `time_to_sleep`: a frozen body neither stays put nor sleeps.
    pub quarantined: usize,
}

/// Why [`run_case`] failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BenchError {
    /// A step failed.
    #[error(transparent)]
    Step(#[from] StepError),
    /// The closed form names a body the world does not have, or a fixed one.
    #[error("{0}")]
    Analytic(String),
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

/// Positions of `bodies` (the run's dynamic bodies at its start, in handle order; a body
/// quarantined since keeps its frozen position).
fn positions(world: &World, bodies: &[BodyHandle]) -> Vec<Vec3> {
    bodies
        .iter()
        .filter_map(|&h| world.body(h).map(|b| b.position))
        .collect()
}

/// Runs `world` for `duration` seconds of simulated time in frames of `setting.dt` (each
/// `setting.world_substeps` world steps), measuring from `settle` seconds on, and returns the
/// metrics; `analytic` is the scene's closed form, if it declares one. The world is expected
/// to have been built with `setting.resolver`.
pub fn run_case(
    world: &mut World,
    setting: &Setting,
    duration: f64,
    settle: f64,
    analytic: Option<&Analytic>,
) -> Result<Metrics, BenchError> {
    let mut tracker = analytic
        .map(|a| AnalyticTracker::new(a, world))
        .transpose()
        .map_err(BenchError::Analytic)?;
    let dt = setting.dt as f64;
    let frames = (duration / dt).round().max(1.0) as u64;
    let settle_frame = ((settle / dt).round() as u64).min(frames - 1);
    let substeps = setting.world_substeps.max(1);
    let step_dt = setting.dt / substeps as f32;
    let closed = world.bodies().all(|(_, _, b)| !b.is_fixed());
    let dynamic: Vec<BodyHandle> = world
        .bodies()
        .filter(|(_, _, b)| !b.is_fixed())
        .map(|(h, _, _)| h)
        .collect();
    let e0 = mechanical_energy(world);
    let mut energy_error = 0.0f64;
    let mut settled = positions(world, &dynamic);
    let mut quarantined = 0usize;
    // Bounded as `run` bounds its steps ([`super::run::Sampled`]): `--duration 1e8` made a
    // reservation of every frame a 96 GB allocation (the process aborted), and growing with
    // the frames held 1.9 GB within 8 s of `--duration 1e6`.
    let mut frame_times = super::run::Sampled::default();
    let (mut max_pen, mut pen_sum, mut pen_steps) = (0.0f32, 0.0f64, 0u64);
    let mut asleep_since: Option<u64> = None;

    for frame in 1..=frames {
        let mut t = Duration::ZERO;
        for _ in 0..substeps {
            quarantined += world.step(step_dt)?.quarantined.len();
            t += world.profile().total;
        }
        frame_times.push(t);
        if let Some(tracker) = &mut tracker {
            tracker.observe(world, frame as f64 * dt);
        }
        if closed {
            energy_error = energy_error.max((mechanical_energy(world) - e0).abs());
        }
        if frame == settle_frame {
            settled = positions(world, &dynamic);
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
        let all_asleep =
            !dynamic.is_empty() && quarantined == 0 && world.profile().awake_bodies == 0;
        match (all_asleep, asleep_since) {
            (true, None) => asleep_since = Some(frame),
            (false, Some(_)) => asleep_since = None,
            _ => {}
        }
    }

    let drift = if quarantined > 0 {
        f32::INFINITY
    } else {
        positions(world, &dynamic)
            .iter()
            .zip(&settled)
            .map(|(p, q)| p.distance(*q))
            .fold(0.0, f32::max)
    };
    let ms_per_step = median(frame_times.values()).as_secs_f64() * 1e3;
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
        // `all_asleep` is false from the frame of a quarantine on, so a run with one has none.
        time_to_sleep: asleep_since.map(|f| f as f64 * dt),
        analytic_error: tracker.map(|t| t.finish(world, frames as f64 * dt)),
        quarantined,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use jostle::scene::{Scene, SceneError};

    fn default_setting(world: &World, dt: f32) -> Setting {
        Setting {
            label: "default".into(),
            resolver: world.settings().resolver.clone(),
            dt,
            world_substeps: 1,
        }
    }

    fn setting_error(text: &str) -> (String, String) {
        match Scene::parse(text, "t.ron") {
            Err(SceneError::Setting { field, message, .. }) => (field, message),
            other => panic!("expected a setting error, got {other:?}"),
        }
    }

    #[test]
    fn a_quarantined_body_is_reported_not_counted_as_still_and_asleep() {
        use jostle::{BodyDesc, ShapeDesc, WorldSettings};
        let mut world = World::new(WorldSettings::default());
        world
            .add_body(BodyDesc::fixed(
                "ground",
                ShapeDesc::HalfSpace { normal: Vec3::Y },
            ))
            .unwrap();
        let bad = world
            .add_body(BodyDesc::dynamic("bad", ShapeDesc::Ball { radius: 0.5 }).at(Vec3::Y * 3.0))
            .unwrap();
        world
            .add_body(BodyDesc::dynamic("good", ShapeDesc::Ball { radius: 0.5 }).at(Vec3::X * 5.0))
            .unwrap();
        // A finite force whose velocity overflows: the body is quarantined in the first step
        // (frozen, as a fixed body) while the good ball falls and comes to rest.
        world.apply_force(bad, Vec3::Y * f32::MAX).unwrap();
        world.apply_force(bad, Vec3::Y * f32::MAX).unwrap();
        let setting = default_setting(&world, 1.0 / 60.0);
        let m = run_case(&mut world, &setting, 4.0, 1.0, None).unwrap();
        assert_eq!(m.quarantined, 1);
        // Before: the frozen body left the position lists, the drift compared other bodies'
        // positions, and the run reported every body asleep.
        assert!(m.drift.is_infinite(), "{m:?}");
        assert_eq!(m.time_to_sleep, None);
    }

    #[test]
    fn analytic_declarations_are_validated_naming_the_field() {
        let (field, message) = setting_error(
            "Scene(analytic: FreeFall(body: \"rock\"), bodies: [Body(name: \"ball\", shape: Ball(radius: 0.5))])",
        );
        assert_eq!(field, "analytic");
        assert!(message.contains("rock"), "{message}");
        let (field, _) = setting_error(
            "Scene(analytic: FreeFall(body: \"g\"), bodies: [Body(name: \"g\", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true)])",
        );
        assert_eq!(field, "analytic");
        let (field, message) = setting_error(
            "Scene(analytic: Bounce(body: \"b\", restitution: 1.5, rest_height: 0.5), bodies: [Body(name: \"b\", shape: Ball(radius: 0.5))])",
        );
        assert_eq!(field, "analytic.restitution");
        assert!(message.contains("1.5"), "{message}");
        let (field, _) = setting_error(
            "Scene(analytic: Incline(body: \"b\", angle: 90.0, friction: 0.1), bodies: [Body(name: \"b\", shape: Ball(radius: 0.5))])",
        );
        assert_eq!(field, "analytic.angle");
        let (field, _) = setting_error(
            "Scene(analytic: Collision(a: \"b\", b: \"b\", restitution: 1.0), bodies: [Body(name: \"b\", shape: Ball(radius: 0.5))])",
        );
        assert_eq!(field, "analytic.b");
    }

    #[test]
    fn unknown_analytic_fields_and_kinds_report_line_and_column() {
        for text in [
            "Scene(\n  analytic: FreeFall(body: \"b\", height: 3.0),\n  bodies: [Body(name: \"b\", shape: Ball(radius: 0.5))])",
            "Scene(\n  analytic: Orbit(body: \"b\"),\n  bodies: [Body(name: \"b\", shape: Ball(radius: 0.5))])",
        ] {
            match Scene::parse(text, "t.ron") {
                Err(SceneError::Parse { line, column, .. }) => {
                    assert_eq!(line, 2, "{text}");
                    assert!(column > 1, "{text}");
                }
                other => panic!("expected a parse error, got {other:?}"),
            }
        }
    }

    #[test]
    fn free_fall_error_is_the_integrators_half_g_t_h() {
        // h is the integration step: dt for Millington, dt / 8 for the soft step's substeps.
        for (resolver, h) in [("Millington()", 1.0 / 60.0), ("SoftStep()", 1.0 / 480.0)] {
            let scene = Scene::parse(
                &format!(
                    "Scene(analytic: FreeFall(body: \"b\"), resolver: {resolver}, bodies: [Body(name: \"b\", shape: Ball(radius: 0.5), position: (0.0, 10.0, 0.0), can_sleep: false)])"
                ),
                "t.ron",
            )
            .unwrap();
            let mut world = scene.build().unwrap();
            let setting = default_setting(&world, 1.0 / 60.0);
            let m = run_case(&mut world, &setting, 1.0, 0.5, scene.analytic.as_ref()).unwrap();
            let expected = 0.5 * 9.81 * 1.0 * h;
            let e = m.analytic_error.unwrap();
            assert!(
                (e - expected).abs() < 1e-3 * expected,
                "{resolver}: {e} vs {expected}"
            );
        }
        let scene = Scene::parse(
            "Scene(analytic: FreeFall(body: \"b\"), bodies: [Body(name: \"b\", shape: Ball(radius: 0.5), position: (0.0, 10.0, 0.0), can_sleep: false)])",
            "t.ron",
        )
        .unwrap();
        let setting = default_setting(&scene.build().unwrap(), 1.0 / 60.0);
        // No declaration, no analytic error.
        let mut world = scene.build().unwrap();
        assert_eq!(
            run_case(&mut world, &setting, 1.0, 0.5, None)
                .unwrap()
                .analytic_error,
            None
        );
    }

    #[test]
    fn bodies_that_never_meet_have_no_collision_error_and_a_wrong_closed_form_shows() {
        // Two balls receding in zero gravity: the closed form is "unchanged", which they are.
        let text = |vb: f32| {
            format!(
                "Scene(gravity: (0.0, 0.0, 0.0), analytic: Collision(a: \"a\", b: \"b\", restitution: 1.0), bodies: [\
                 Body(name: \"a\", shape: Ball(radius: 0.5), linear_velocity: (-1.0, 0.0, 0.0), can_sleep: false),\
                 Body(name: \"b\", shape: Ball(radius: 0.5), position: (3.0, 0.0, 0.0), linear_velocity: ({vb}, 0.0, 0.0), can_sleep: false)])"
            )
        };
        let scene = Scene::parse(&text(1.0), "t.ron").unwrap();
        let mut world = scene.build().unwrap();
        let setting = default_setting(&world, 1.0 / 60.0);
        let m = run_case(&mut world, &setting, 0.5, 0.1, scene.analytic.as_ref()).unwrap();
        assert!(m.analytic_error.unwrap() < 1e-6, "{m:?}");
        // B flying at A at 10 m/s with no time to meet in 0.05 s: the closed form expects the
        // collision's outcome, the run has not had it, so the error is large.
        let scene = Scene::parse(&text(-10.0), "t.ron").unwrap();
        let mut world = scene.build().unwrap();
        let m = run_case(&mut world, &setting, 0.05, 0.0, scene.analytic.as_ref()).unwrap();
        assert!(m.analytic_error.unwrap() > 1.0, "{m:?}");
    }

    #[test]
    fn the_analytic_set_meets_its_closed_forms_roughly() {
        // Loose bounds (both resolvers at their defaults, dt 1/60): the point is that each
        // declared closed form is the scene's, so a wrong sign, unit or parameter would show.
        // Measured when written: free fall 0.163 (Millington) / 0.041 m (soft step, whose
        // substeps integrate at dt/4); incline 0.045 / 0.335 m (the soft step slides 7% off
        // the closed form over 4.7 m); sliding to rolling 0.012 / 0.006 m; bounce 0.027 /
        // 0.057 m; elastic pair 0 / 0 m/s.
        for (file, bound) in [
            ("analytic_free_fall.ron", 0.17),
            ("analytic_incline.ron", 0.4),
            ("analytic_sliding_to_rolling.ron", 0.05),
            ("analytic_bounce.ron", 0.1),
            ("analytic_elastic_pair.ron", 0.01),
        ] {
            let path = format!("{}/../../assets/{file}", env!("CARGO_MANIFEST_DIR"));
            let scene = Scene::load(&path).unwrap();
            assert!(scene.analytic.is_some(), "{file} declares no closed form");
            for resolver in ResolverChoice::NAMES {
                let mut settings = scene.settings();
                settings.resolver = ResolverChoice::from_name(resolver).unwrap();
                let mut world = scene.build_with(settings).unwrap();
                let setting = default_setting(&world, scene.dt);
                let duration = scene.steps as f64 * scene.dt as f64;
                let m =
                    run_case(&mut world, &setting, duration, 0.0, scene.analytic.as_ref()).unwrap();
                let e = m.analytic_error.unwrap();
                assert!(e.is_finite() && e < bound, "{file} / {resolver}: {e}");
            }
        }
    }
}
