//! Snapshots: the complete state of a [`crate::World`] — bodies, sleep state, the narrow phase's
//! persistent manifolds with their warm-start impulses, settings and the clock — serialised
//! with serde so that a run can stop and continue **bit for bit**: N steps, a snapshot, then M
//! steps give exactly the trace of N + M steps in one run.
//!
//! Files are RON (`Snapshot(format: 3, ...)`); floats are written in Rust's shortest
//! round-trip form, so nothing is lost. The broad phase is not stored: its pairs are a pure
//! function of the poses (sorted, filtered exactly), so it is rebuilt on the first step.
//!
//! A body's mass and inertia are stored with the body (`mass`, `inertia_body` and their
//! inverses), not worked out again from its colliders on load: a body may have been given a
//! mass of its own. Editing a collider's shape in a snapshot file therefore keeps the body's
//! mass; edit those fields too.

use jostle_body::BodyHandle;
use jostle_collide::{Material, Pose, ShapeDesc};

/// How one collider was made: enough to rebuild it, with the same handle, from a snapshot.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ColliderRecord {
    /// The shape description.
    pub shape: ShapeDesc,
    /// Pose relative to the body's centre-of-mass frame.
    pub local_pose: Pose,
    /// Surface material.
    pub material: Material,
    /// The body it is attached to.
    pub body: BodyHandle,
    /// Collision groups (default: all).
    #[cfg_attr(feature = "serde", serde(default))]
    pub groups: jostle_collide::CollisionGroups,
    /// Whether it is a sensor (default: no).
    #[cfg_attr(feature = "serde", serde(default))]
    pub sensor: bool,
    /// Contact force event threshold (N; default none).
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Option::is_none")
    )]
    pub force_event_threshold: Option<f32>,
}

#[cfg(feature = "scene")]
pub use file::{OLDEST_SNAPSHOT_FORMAT, SNAPSHOT_FORMAT, Snapshot, SnapshotError};

#[cfg(feature = "scene")]
mod file {
    use super::ColliderRecord;
    use crate::settings::WorldSettings;
    use crate::world::World;
    use jostle_body::{Arena, BodySet, RigidBody};
    use jostle_collide::{Collider, ColliderSet, NarrowPhase};
    use jostle_sleep::IslandSet;
    use serde::{Deserialize, Serialize};
    use std::path::Path;
    use thiserror::Error;

    /// Version of the snapshot format this build writes; it reads this one and
    /// [`OLDEST_SNAPSHOT_FORMAT`] onwards.
    /// Format 2 (2026-12-03): bodies carry their names, and the colliders are stored with
    /// their slots, generations and free list, so handles stay valid across removals.
    /// Format 3 (2026-12-05): the resolver's impulses and preloads of the last step are in the
    /// narrow phase's contact list, and each pair records where its contacts are (its
    /// persistent points take them at the next step); a build that reads only format 2 would
    /// warm start from the step before and not continue the run bit for bit, so it refuses
    /// format 3. A format 2 snapshot, whose points hold the impulses themselves, restores as
    /// before.
    pub const SNAPSHOT_FORMAT: u32 = 3;

    /// The oldest snapshot format this build reads ([`SNAPSHOT_FORMAT`]).
    pub const OLDEST_SNAPSHOT_FORMAT: u32 = 2;

    /// The complete state of a world. Make one with [`World::snapshot`], restore it with
    /// [`World::from_snapshot`], store it with [`Snapshot::save`] / [`Snapshot::load`].
    #[derive(Clone, Serialize, Deserialize)]
    #[serde(rename = "Snapshot", deny_unknown_fields)]
    pub struct Snapshot {
        /// Format version ([`SNAPSHOT_FORMAT`]).
        pub format: u32,
        /// Name of the scene the run came from.
        pub scene: String,
        /// The time step the run was using (s); `jostle run SNAPSHOT` continues with it.
        pub dt: f32,
        pub(crate) settings: WorldSettings,
        pub(crate) bodies: BodySet,
        pub(crate) colliders: Arena<ColliderRecord>,
        pub(crate) narrow: NarrowPhase,
        pub(crate) islands: IslandSet,
        pub(crate) time: f64,
        pub(crate) steps: u64,
    }

    /// Why a snapshot could not be read, written or restored.
    #[derive(Clone, Debug, Error, PartialEq)]
    pub enum SnapshotError {
        /// The file could not be read or written.
        #[error("{file}: {message}")]
        Io {
            /// The file.
            file: String,
            /// What went wrong.
            message: String,
        },
        /// The file is not a valid snapshot.
        #[error("{file}:{line}:{column}: {message}")]
        Parse {
            /// The file.
            file: String,
            /// Line, from 1.
            line: usize,
            /// Column, from 1.
            column: usize,
            /// What ron reported.
            message: String,
        },
        /// The snapshot is well-formed but cannot be restored.
        #[error("{file}: {message}")]
        Invalid {
            /// The file.
            file: String,
            /// What is wrong.
            message: String,
        },
    }

    impl Snapshot {
        /// The world settings the snapshot carries.
        pub fn settings(&self) -> &WorldSettings {
            &self.settings
        }

        /// The world settings, to change before [`World::from_snapshot`] (which validates
        /// them as strictly as a scene file's): for example another resolver, or sleeping off.
        pub fn settings_mut(&mut self) -> &mut WorldSettings {
            &mut self.settings
        }

        /// The snapshot as RON text, as [`Snapshot::save`] writes it.
        pub fn to_ron(&self) -> Result<String, ron::Error> {
            ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default().struct_names(true))
        }

        /// Writes the snapshot as RON.
        pub fn save(&self, path: impl AsRef<Path>) -> Result<(), SnapshotError> {
            let path = path.as_ref();
            let io = |message: String| SnapshotError::Io {
                file: path.display().to_string(),
                message,
            };
            let text = self.to_ron().map_err(|e| io(e.to_string()))?;
            std::fs::write(path, text).map_err(|e| io(e.to_string()))
        }

        /// Reads a snapshot written by [`Snapshot::save`].
        pub fn load(path: impl AsRef<Path>) -> Result<Snapshot, SnapshotError> {
            let path = path.as_ref();
            let file = path.display().to_string();
            let text = std::fs::read_to_string(path).map_err(|e| SnapshotError::Io {
                file: file.clone(),
                message: format!("cannot read: {e}"),
            })?;
            Self::parse(&text, &file)
        }

        /// Parses snapshot text; `file` names its origin in errors.
        pub fn parse(text: &str, file: &str) -> Result<Snapshot, SnapshotError> {
            // A byte-order mark is not RON (as in `Scene::parse`).
            let text = text.strip_prefix('\u{feff}').unwrap_or(text);
            let snapshot: Snapshot = ron::from_str(text).map_err(|e| SnapshotError::Parse {
                file: file.into(),
                line: e.span.start.line,
                column: e.span.start.col,
                message: e.code.to_string(),
            })?;
            if !(OLDEST_SNAPSHOT_FORMAT..=SNAPSHOT_FORMAT).contains(&snapshot.format) {
                return Err(SnapshotError::Invalid {
                    file: file.into(),
                    message: format!(
                        "snapshot format {} is not supported (this build reads formats \
                         {OLDEST_SNAPSHOT_FORMAT} to {SNAPSHOT_FORMAT})",
                        snapshot.format
                    ),
                });
            }
            Ok(snapshot)
        }

        /// Whether `text` looks like a snapshot rather than a scene (its first item, after
        /// comments of either kind and RON's `#![enable(...)]` attributes, is `Snapshot(`), so
        /// one command can take either (a snapshot opening with a block comment was read as a
        /// scene: "Expected struct Scene but found Snapshot").
        pub fn is_snapshot_text(text: &str) -> bool {
            let mut rest = text;
            loop {
                rest = rest.trim_start();
                rest = if let Some(r) = rest.strip_prefix("//") {
                    r.split_once('\n').map_or("", |(_, r)| r)
                } else if let Some(r) = rest.strip_prefix("/*") {
                    r.split_once("*/").map_or("", |(_, r)| r)
                } else if let Some(r) = rest.strip_prefix("#![") {
                    r.split_once(']').map_or("", |(_, r)| r)
                } else {
                    return rest.starts_with("Snapshot(");
                };
            }
        }
    }

    /// The settings a snapshot may carry: what a scene file would refuse, a snapshot refuses
    /// too (a hand-edited `substeps: 0` or NaN gravity used to be accepted silently, and a
    /// negative or NaN `collide.prediction` stopped the process on an assertion in parry).
    fn validate_settings(settings: &WorldSettings) -> Result<(), String> {
        settings
            .resolver
            .validate()
            .map_err(|(field, message)| format!("settings.resolver.{field}: {message}"))?;
        if !(settings.gravity.is_finite() && settings.gravity.length() <= crate::MAX_GRAVITY) {
            return Err(format!(
                "settings.gravity: must be finite and at most {:e} m/s², got {}",
                crate::MAX_GRAVITY,
                settings.gravity
            ));
        }
        settings
            .collide
            .validate()
            .map_err(|(field, message)| format!("settings.collide.{field}: {message}"))?;
        settings
            .sleep
            .validate()
            .map_err(|(field, message)| format!("settings.sleep.{field}: {message}"))?;
        Ok(())
    }

    /// A snapshot's body held to the limits a scene file's body is held to
    /// ([`crate::MAX_SPEED`] and its neighbours; its spin to what a step may reach,
    /// [`crate::MAX_REACHED_ANGULAR_SPEED`]), its pending force and torque to a change of
    /// speed or spin within them over one step of `dt` (a hand-edited `force: (0, -1e30, 0)` or
    /// `angular_velocity: (0, 1e30, 0)` went non-finite at the first step).
    fn within_limits(
        body: &RigidBody,
        dt: f32,
        gravity: f32,
    ) -> Result<(), (&'static str, String)> {
        use crate::{MAX_ANGULAR_SPEED, MAX_MASS, MAX_POSITION, MAX_SPEED};
        let check = |field, magnitude: f32, limit: f32, unit| {
            crate::body_desc::at_most(field, "is", magnitude, limit, unit)
        };
        check(
            "position",
            body.position.abs().max_element(),
            MAX_POSITION,
            "m",
        )?;
        check(
            "linear_velocity",
            body.linear_velocity.length(),
            MAX_SPEED,
            "m/s",
        )?;
        // Spin up to what a step may reach, which is more than a scene may start with: a
        // snapshot of a tiny cube spun to 2.4·10⁵ rad/s by an impact was refused.
        check(
            "angular_velocity",
            body.angular_velocity.length(),
            crate::MAX_REACHED_ANGULAR_SPEED,
            "rad/s",
        )?;
        // The gravity the body feels, as `World::set_gravity_scale` bounds it (a hand-edited
        // `gravity_scale: 1e30` went non-finite at the first step).
        check(
            "gravity_scale",
            body.gravity_scale.abs() * gravity,
            crate::MAX_GRAVITY,
            "m/s² of gravity",
        )?;
        if let Some(path) = body.path() {
            crate::body_desc::path_within_limits(path).map_err(|(_, message)| ("path", message))?;
        }
        if !body.is_immovable() {
            check("mass", body.mass(), MAX_MASS, "kg")?;
            let dt = if dt.is_finite() && dt > 0.0 { dt } else { 1.0 };
            let speed_change = body.force().length() * body.inv_mass() * dt;
            check("force", speed_change, MAX_SPEED, "m/s of speed in one step")?;
            let spin_change = (body.inv_inertia_world() * body.torque()).length() * dt;
            check(
                "torque",
                spin_change,
                MAX_ANGULAR_SPEED,
                "rad/s of spin in one step",
            )?;
        }
        Ok(())
    }

    /// The most steps a snapshot may have counted: 2⁵³.
    const MAX_STEPS: u64 = 1 << 53;

    impl World {
        /// The complete state of the world, for [`World::from_snapshot`]. `scene` and `dt` are
        /// recorded so that a command-line run can continue where it stopped.
        pub fn snapshot(&self, scene: &str, dt: f32) -> Snapshot {
            Snapshot {
                format: SNAPSHOT_FORMAT,
                scene: scene.to_string(),
                dt,
                settings: self.settings.clone(),
                bodies: self.bodies.clone(),
                colliders: self
                    .colliders
                    .arena()
                    .try_map(|_, c| {
                        Ok::<_, std::convert::Infallible>(ColliderRecord {
                            shape: c
                                .desc()
                                .expect("every collider of a World is built from a description")
                                .clone(),
                            local_pose: c.local_pose(),
                            material: c.material,
                            body: c.body,
                            groups: c.groups,
                            sensor: c.sensor,
                            force_event_threshold: c.force_event_threshold,
                        })
                    })
                    .unwrap_or_else(|never| match never {}),
                narrow: self.narrow.clone(),
                islands: self.islands.clone(),
                time: self.time,
                steps: self.steps,
            }
        }

        /// Restores a world from a snapshot; stepping it continues bit for bit.
        pub fn from_snapshot(snapshot: Snapshot) -> Result<World, SnapshotError> {
            let invalid = |message: String| SnapshotError::Invalid {
                file: String::new(),
                message,
            };
            validate_settings(&snapshot.settings).map_err(invalid)?;
            let mut world = World::new(snapshot.settings);
            snapshot
                .bodies
                .check()
                .map_err(|e| invalid(format!("bodies: {e}")))?;
            snapshot
                .colliders
                .check()
                .map_err(|e| invalid(format!("colliders: {e}")))?;
            world.bodies = snapshot.bodies;
            // Names tell bodies apart in errors, traces and `analytic` as in a scene file,
            // which refuses a repeated one (a snapshot's was accepted, and its trace had two
            // indistinguishable rows a step). Unnamed bodies are known by their place.
            let mut seen = std::collections::HashMap::new();
            for (handle, body) in world.bodies.iter() {
                if body.name.is_empty() {
                    continue;
                }
                if let Some(first) = seen.insert(body.name.as_str(), handle.index()) {
                    return Err(invalid(format!(
                        "body {} \"{}\": field `name`: the same name as body {first}; names must \
                         be unique",
                        handle.index(),
                        body.name
                    )));
                }
            }
            let gravity = world.settings.gravity.length();
            let slots: Vec<_> = world.bodies.iter().map(|(h, _)| h).collect();
            for handle in slots {
                if let Some(body) = world.bodies.get_mut(handle)
                    && let Err((field, message)) = body
                        .check()
                        .and_then(|()| within_limits(body, snapshot.dt, gravity))
                {
                    return Err(invalid(format!(
                        "body {} \"{}\": field `{field}`: {message}",
                        handle.index(),
                        body.name
                    )));
                }
            }
            for (at, record) in snapshot.colliders.iter() {
                let i = at.index;
                if !world.bodies.contains(record.body) {
                    return Err(invalid(format!(
                        "collider {i} is attached to {}, which the snapshot does not hold",
                        record.body
                    )));
                }
                let m = record.material;
                if !(m.friction.is_finite() && m.friction >= 0.0) {
                    return Err(invalid(format!(
                        "collider {i}: material.friction: must be finite and >= 0, got {}",
                        m.friction
                    )));
                }
                if let Some(d) = m.dynamic_friction
                    && !(0.0..=m.friction).contains(&d)
                {
                    return Err(invalid(format!(
                        "collider {i}: material.dynamic_friction: must be in [0, friction = {}], got {d}",
                        m.friction
                    )));
                }
                if !(m.restitution.is_finite() && (0.0..=1.0).contains(&m.restitution)) {
                    return Err(invalid(format!(
                        "collider {i}: material.restitution: must be in [0, 1], got {}",
                        m.restitution
                    )));
                }
                if let Err((field, message)) =
                    crate::body_desc::check_force_threshold(record.force_event_threshold)
                {
                    return Err(invalid(format!("collider {i}: {field}: {message}")));
                }
                let pose = record.local_pose;
                let reach = pose.translation.abs().max_element();
                let within = reach <= jostle_collide::shape::MAX_EXTENT;
                let unit = (pose.rotation.length() - 1.0).abs() < 1e-3;
                if !(within && pose.rotation.is_finite() && unit) {
                    return Err(invalid(format!(
                        "collider {i}: local_pose: must be within {:e} m and turn by a unit quaternion",
                        jostle_collide::shape::MAX_EXTENT
                    )));
                }
                let fixed = world.bodies.get(record.body).is_some_and(|b| b.is_fixed());
                if record.shape.is_unbounded() && !fixed {
                    return Err(invalid(format!(
                        "collider {i}: a half-space has no finite mass: its body {} must be fixed",
                        record.body
                    )));
                }
            }
            let colliders = snapshot.colliders.try_map(|at, record| {
                let collider = Collider::from_desc(&record.shape, record.body)
                    .map_err(|e| invalid(format!("collider {}: {e}", at.index)))?;
                Ok(collider
                    .with_local_pose(record.local_pose)
                    .with_material(record.material)
                    .with_groups(record.groups)
                    .with_sensor(record.sensor)
                    .with_force_event_threshold(record.force_event_threshold))
            })?;
            world.colliders = ColliderSet::from_arena(colliders);
            let inv_mass = |c: &Collider| world.bodies.get(c.body).map_or(0.0, |b| b.inv_mass());
            snapshot
                .narrow
                .check(&world.colliders, |c1, c2| {
                    crate::MAX_SPEED / (inv_mass(c1) + inv_mass(c2))
                })
                .map_err(|e| invalid(format!("narrow: {e}")))?;
            world.narrow = snapshot.narrow;
            world.narrow.rebind_shapes(&world.colliders);
            snapshot
                .islands
                .check(world.bodies.capacity_index())
                .map_err(|e| invalid(format!("islands: {e}")))?;
            world.islands = snapshot.islands;
            if !(snapshot.time.is_finite() && snapshot.time >= 0.0) {
                return Err(invalid(format!(
                    "time: must be finite and >= 0, got {}",
                    snapshot.time
                )));
            }
            // A step count no run reaches (2⁵³ steps, 4.8 million years at 60 Hz): beyond it
            // the counter's steps lose their f64 time, and at u64's end the trace's step
            // numbers wrapped to 0.
            if snapshot.steps > MAX_STEPS {
                return Err(invalid(format!(
                    "steps: must be at most {MAX_STEPS}, got {}",
                    snapshot.steps
                )));
            }
            world.time = snapshot.time;
            world.steps = snapshot.steps;
            world.paths = world.bodies.iter().any(|(_, b)| b.path().is_some());
            Ok(world)
        }
    }
}
