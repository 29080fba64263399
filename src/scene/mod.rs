//! Scene files: RON loaded through serde into plain description types, validated, then built
//! into a [`World`].
//!
//! ```ron
//! Scene(
//!     name: "box drop",
//!     gravity: (0.0, -9.81, 0.0),
//!     dt: 0.016666668,
//!     steps: 300,
//!     bodies: [
//!         Body(name: "ground", shape: HalfSpace(normal: (0.0, 1.0, 0.0)), fixed: true),
//!         Body(name: "box", shape: Cuboid(half_extents: (1.0, 1.0, 1.0)), position: (0.0, 3.0, 0.0), mass: 8.0),
//!     ],
//! )
//! ```
//!
//! Every field but a body's `shape` has a default: scene `name` "unnamed", `gravity`
//! (0, −9.81, 0), `dt` 1/60 s, `steps` 600, `resolver` the soft step at its defaults, `sleep` enabled with
//! threshold 0.3; body `name` "", `position` origin, `rotation` identity (x, y, z, w), zero
//! velocities, `density` 1000 kg/m³ unless `mass` (kg) is given, `friction` 0.5 (static;
//! `dynamic_friction`, at most that, defaults to it), `restitution` 0, `friction_combine` and
//! `restitution_combine` none (geometric mean and max), damping 0, `can_sleep` true, `fixed` false, `ccd` Auto. `generators` add many bodies
//! from a few parameters (pyramids, stacks, walls, grids of piles); an optional `perturb`
//! ([`Perturb`]) shifts and turns them a little from a seed, so a file gives a reproducible
//! perturbed start. An optional `camera`
//! ([`Camera`]) fixes the view of renderers; without one they frame the scene themselves. An
//! optional `analytic` ([`Analytic`]) declares the scene's closed form, which
//! `jostle bench` compares the run against.
//!
//! Errors never panic and lose nothing: a malformed file names the file, line and column (and
//! the body around that position when there is one); a bad value names the body and the field.

mod analytic;
mod error;
mod generators;
mod perturb;

pub use analytic::Analytic;
pub use error::SceneError;
pub use generators::Generator;
pub use perturb::Perturb;

use crate::body_desc::{BodyDesc, BodyError, MassSpec};
use crate::settings::{ResolverChoice, WorldSettings};
use crate::world::World;
use jostle_collide::{Material, ShapeDesc};
use jostle_math::{Quat, Vec3};
use jostle_sleep::SleepSettings;
use serde::{Deserialize, Serialize};
use std::path::Path;

fn default_name() -> String {
    "unnamed".into()
}
fn default_gravity() -> Vec3 {
    Vec3::new(0.0, -9.81, 0.0)
}
fn default_dt() -> f32 {
    1.0 / 60.0
}
fn default_steps() -> u32 {
    600
}
fn default_friction() -> f32 {
    0.5
}
fn yes() -> bool {
    true
}

/// A scene file's contents.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Scene", deny_unknown_fields)]
pub struct Scene {
    /// Name, shown in summaries and benchmark tables.
    #[serde(default = "default_name")]
    pub name: String,
    /// Gravity (m/s²). Default (0, −9.81, 0).
    #[serde(default = "default_gravity")]
    pub gravity: Vec3,
    /// Time step (s). Default 1/60.
    #[serde(default = "default_dt")]
    pub dt: f32,
    /// Steps to run. Default 600.
    #[serde(default = "default_steps")]
    pub steps: u32,
    /// The resolver and its settings. Default: the soft step at its defaults
    /// ([`crate::ResolverChoice::default`]).
    #[serde(default)]
    pub resolver: Option<ResolverChoice>,
    /// Sleep settings. Default: enabled, threshold 0.3, bias base 0.5.
    #[serde(default)]
    pub sleep: Option<SleepSettings>,
    /// Bodies, in order.
    #[serde(default)]
    pub bodies: Vec<BodySpec>,
    /// Generated bodies, added after `bodies`.
    #[serde(default)]
    pub generators: Vec<Generator>,
    /// A seeded perturbation of the generated bodies' start ([`Perturb`]): each is shifted
    /// sideways and turned a little, and lifted so that none overlaps. Default: none, the
    /// generators' exact layout.
    #[serde(default)]
    pub perturb: Option<Perturb>,
    /// The camera renderers use (`jostle run --render`). Default: none, the renderer frames
    /// the scene itself.
    #[serde(default)]
    pub camera: Option<Camera>,
    /// The closed form `jostle bench` compares the run against, for its analytic error
    /// ([`Analytic`], e.g. `analytic: FreeFall(body: "ball")`). Default: none.
    #[serde(default)]
    pub analytic: Option<Analytic>,
}

fn default_camera_position() -> Vec3 {
    Vec3::new(0.0, 5.0, 15.0)
}
fn default_fov() -> f32 {
    45.0
}

/// A scene's camera (`camera: Camera(position: (8.0, 6.0, 12.0), target: (0.0, 1.0, 0.0))`):
/// a perspective view from `position` toward `target`, +Y up.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Camera", deny_unknown_fields)]
pub struct Camera {
    /// Where the eye is (m). Default (0, 5, 15).
    #[serde(default = "default_camera_position")]
    pub position: Vec3,
    /// The point looked at, drawn at the image's centre (m). Default the origin.
    #[serde(default)]
    pub target: Vec3,
    /// Vertical field of view (degrees), in (1, 179). Default 45.
    #[serde(default = "default_fov")]
    pub fov: f32,
}

impl Camera {
    /// Checks the camera: finite numbers, `fov` in (1, 179) degrees, `position` ≠ `target`.
    /// The error is the offending field (`camera.position`, ...) and what is wrong with it.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let field = |f: &str| format!("camera.{f}");
        if !self.position.is_finite() {
            return Err((
                field("position"),
                format!("must be finite, got {}", self.position),
            ));
        }
        if !self.target.is_finite() {
            return Err((
                field("target"),
                format!("must be finite, got {}", self.target),
            ));
        }
        if !(self.fov.is_finite() && self.fov > 1.0 && self.fov < 179.0) {
            return Err((
                field("fov"),
                format!("must be in (1, 179) degrees, got {}", self.fov),
            ));
        }
        if self.position.distance(self.target) <= 1e-4 {
            return Err((
                field("target"),
                format!("must differ from `position` ({})", self.position),
            ));
        }
        Ok(())
    }
}

/// One body of a scene file (`Body(...)`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Body", deny_unknown_fields)]
pub struct BodySpec {
    /// Name, used in traces and error messages.
    #[serde(default)]
    pub name: String,
    /// Shape (required).
    pub shape: ShapeDesc,
    /// Position (m) of the shape's origin.
    #[serde(default)]
    pub position: Vec3,
    /// Orientation as (x, y, z, w).
    #[serde(default = "identity")]
    pub rotation: Quat,
    /// Linear velocity (m/s).
    #[serde(default)]
    pub linear_velocity: Vec3,
    /// Angular velocity (rad/s).
    #[serde(default)]
    pub angular_velocity: Vec3,
    /// Mass (kg); give this or `density`, not both.
    #[serde(default)]
    pub mass: Option<f32>,
    /// Density (kg/m³); default 1000 when `mass` is not given.
    #[serde(default)]
    pub density: Option<f32>,
    /// Friction coefficient μ: the static one, holding a contact that is not sliding.
    /// Default 0.5.
    #[serde(default = "default_friction")]
    pub friction: f32,
    /// Dynamic friction coefficient μd, acting on a sliding contact; at most `friction`.
    /// Default: the same as `friction`.
    #[serde(default)]
    pub dynamic_friction: Option<f32>,
    /// Restitution e in [0, 1]. Default 0.
    #[serde(default)]
    pub restitution: f32,
    /// How this body's friction combines with another's at a contact (`GeometricMean`,
    /// `Average`, `Min`, `Multiply`, `Max`). Default: the geometric mean, unless the other
    /// body names a rule ([`jostle_collide::Combine::of_pair`]).
    #[serde(default)]
    pub friction_combine: Option<jostle_collide::Combine>,
    /// How this body's restitution combines with another's. Default: the larger, unless the
    /// other body names a rule.
    #[serde(default)]
    pub restitution_combine: Option<jostle_collide::Combine>,
    /// Linear damping (1/s). Default 0.
    #[serde(default)]
    pub linear_damping: f32,
    /// Angular damping (1/s). Default 0.
    #[serde(default)]
    pub angular_damping: f32,
    /// Whether the body may sleep. Default true.
    #[serde(default = "yes")]
    pub can_sleep: bool,
    /// Whether the body is immovable. Default false.
    #[serde(default)]
    pub fixed: bool,
    /// Continuous collision detection: `Auto`, `On` or `Off`. Default `Auto`.
    #[serde(default)]
    pub ccd: jostle_body::CcdMode,
    /// Lock the rotation (the body translates but never turns). Default false.
    #[serde(default)]
    pub lock_rotation: bool,
    /// Lock rotation about some world axes only, `(x, y, z)`: `(true, false, true)` turns
    /// about the vertical alone. Default: none.
    #[serde(default)]
    pub rotation_locks: [bool; 3],
    /// Lock translation along some world axes, `(x, y, z)`: `(false, false, true)` keeps the
    /// body in its x-y plane. Default: none.
    #[serde(default)]
    pub translation_locks: [bool; 3],
    /// Makes the body kinematic (pushes dynamic bodies, pushed by nothing): `Velocity` (moved
    /// by `linear_velocity` and `angular_velocity`), `Position` (moved by the program),
    /// `Line(offset: (x, y, z), period: s)` (back and forth) or `Turn(center: (x, y, z),
    /// axis: (x, y, z), period: s)` (round an axis). Default: none.
    #[serde(default)]
    pub kinematic: Option<crate::Kinematic>,
    /// A sensor: makes no contacts, reports what enters and leaves it. Default false.
    #[serde(default)]
    pub sensor: bool,
    /// Collision groups, `(memberships: bits, filter: bits)`: the body's collider meets
    /// another when each one's memberships share a bit with the other's filter. Default: all.
    #[serde(default)]
    pub groups: jostle_collide::CollisionGroups,
    /// Report contact force events above this total normal force (N). Default: none.
    #[serde(default)]
    pub force_event_threshold: Option<f32>,
    /// Further colliders of the body (`colliders: [Collider(shape: Ball(radius: 0.2),
    /// position: (0.0, 0.6, 0.0))]`), placed in the body's own frame, their mass summed with
    /// the shape's ([`crate::World::add_collider`]). Default: none.
    #[serde(default)]
    pub colliders: Vec<ColliderSpec>,
}

/// One further collider of a scene body (`Collider(...)` in a body's `colliders`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Collider", deny_unknown_fields)]
pub struct ColliderSpec {
    /// Shape (required; not a half-space).
    pub shape: ShapeDesc,
    /// Position (m) of the shape's origin in the body's own frame (about the body's
    /// `position`, along its rotated axes). Default: the body's position.
    #[serde(default)]
    pub position: Vec3,
    /// Orientation in the body's frame, as (x, y, z, w). Default: none.
    #[serde(default = "identity")]
    pub rotation: Quat,
    /// Friction μ. Default: the body's.
    #[serde(default)]
    pub friction: Option<f32>,
    /// Restitution e. Default: the body's.
    #[serde(default)]
    pub restitution: Option<f32>,
    /// Density (kg/m³) of the mass it adds; 0 adds none. Default: the body's density, or
    /// 1000 when the body gives a mass instead.
    #[serde(default)]
    pub density: Option<f32>,
    /// A sensor. Default false.
    #[serde(default)]
    pub sensor: bool,
    /// Collision groups. Default: the body's.
    #[serde(default)]
    pub groups: Option<jostle_collide::CollisionGroups>,
}

fn identity() -> Quat {
    Quat::IDENTITY
}

impl BodySpec {
    /// The body description, or an error naming the body and field.
    pub fn to_desc(&self) -> Result<BodyDesc, crate::BodyError> {
        let mass = match (self.mass, self.density) {
            (Some(_), Some(_)) => {
                return Err(crate::BodyError::Field {
                    body: self.name.clone(),
                    field: "mass".into(),
                    message: "give `mass` or `density`, not both".into(),
                });
            }
            (Some(m), None) => MassSpec::Mass(m),
            (None, Some(d)) => MassSpec::Density(d),
            (None, None) => MassSpec::Density(crate::body_desc::DEFAULT_DENSITY),
        };
        let desc = BodyDesc {
            name: self.name.clone(),
            shape: self.shape.clone(),
            position: self.position,
            rotation: self.rotation,
            linear_velocity: self.linear_velocity,
            angular_velocity: self.angular_velocity,
            mass,
            material: Material {
                friction: self.friction,
                restitution: self.restitution,
                dynamic_friction: self.dynamic_friction,
                friction_combine: self.friction_combine,
                restitution_combine: self.restitution_combine,
            },
            linear_damping: self.linear_damping,
            angular_damping: self.angular_damping,
            can_sleep: self.can_sleep,
            fixed: self.fixed,
            ccd: self.ccd,
            lock_rotation: self.lock_rotation,
            rotation_locks: self.rotation_locks,
            translation_locks: self.translation_locks,
            kinematic: self.kinematic,
            sensor: self.sensor,
            groups: self.groups,
            force_event_threshold: self.force_event_threshold,
            colliders: Vec::new(),
        };
        let body_density = match mass {
            MassSpec::Density(d) => d,
            MassSpec::Mass(_) => crate::body_desc::DEFAULT_DENSITY,
        };
        let desc = BodyDesc {
            colliders: self
                .colliders
                .iter()
                .map(|c| crate::ColliderDesc {
                    shape: c.shape.clone(),
                    position: c.position,
                    rotation: c.rotation,
                    material: Material {
                        friction: c.friction.unwrap_or(desc.material.friction),
                        restitution: c.restitution.unwrap_or(desc.material.restitution),
                        // A friction of its own has its own dynamic coefficient (the same).
                        dynamic_friction: match c.friction {
                            Some(_) => None,
                            None => desc.material.dynamic_friction,
                        },
                        ..desc.material
                    },
                    density: c.density.unwrap_or(body_density),
                    groups: c.groups.unwrap_or(desc.groups),
                    sensor: c.sensor,
                    force_event_threshold: None,
                })
                .collect(),
            ..desc
        };
        desc.validate()?;
        Ok(desc)
    }
}

impl Scene {
    /// Reads and parses a scene file; the error names the file (and line and column).
    pub fn load(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError::Io {
            file: path.display().to_string(),
            message: e.to_string(),
        })?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Parses scene text; `file` names its origin in errors. Validates the whole scene.
    pub fn parse(text: &str, file: &str) -> Result<Scene, SceneError> {
        // A byte-order mark (editors on Windows write one) is not RON: it was refused as
        // "Expected opening `(`" at 1:1.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        // IMPLICIT_SOME: `mass: 8.0` for an optional field; UNWRAP_VARIANT_NEWTYPES:
        // `resolver: Millington(velocity_iterations: 64)` without doubled parentheses.
        let options = ron::Options::default().with_default_extension(
            ron::extensions::Extensions::IMPLICIT_SOME
                | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES,
        );
        let scene: Scene = options
            .from_str(text)
            .map_err(|e| SceneError::from_ron(file, text, e))?;
        scene.validate().map_err(|e| e.in_file(file, text))?;
        Ok(scene)
    }

    /// Checks settings and every body; the error names the body and field.
    pub fn validate(&self) -> Result<(), SceneError> {
        let setting = |field: &str, message: String| SceneError::Setting {
            file: String::new(),
            at: None,
            field: field.into(),
            message,
        };
        if !(self.gravity.is_finite() && self.gravity.length() <= crate::MAX_GRAVITY) {
            return Err(setting(
                "gravity",
                format!(
                    "must be finite and at most {:e} m/s², got {}",
                    crate::MAX_GRAVITY,
                    self.gravity
                ),
            ));
        }
        if !(self.dt.is_finite() && self.dt > 0.0 && self.dt <= crate::MAX_DT) {
            return Err(setting(
                "dt",
                format!("must be in (0, {}] s, got {}", crate::MAX_DT, self.dt),
            ));
        }
        if let Some(s) = &self.sleep {
            s.validate()
                .map_err(|(field, message)| setting(&format!("sleep.{field}"), message))?;
        }
        if let Some(camera) = &self.camera {
            camera
                .validate()
                .map_err(|(field, message)| setting(&field, message))?;
        }
        match &self.resolver {
            Some(ResolverChoice::SoftStep(soft)) => soft
                .validate()
                .map_err(|(field, message)| setting(&format!("resolver.{field}"), message))?,
            Some(ResolverChoice::Millington(m)) => m
                .validate()
                .map_err(|(field, message)| setting(&format!("resolver.{field}"), message))?,
            None => {}
        }
        for (i, body) in self.bodies.iter().enumerate() {
            body.to_desc().map_err(|e| SceneError::Body {
                file: String::new(),
                at: None,
                index: Some(i as u32),
                error: e,
            })?;
        }
        let names: Vec<&str> = self.bodies.iter().map(|b| b.name.as_str()).collect();
        unique_names(&names, names.len())?;
        for (i, g) in self.generators.iter().enumerate() {
            g.validate().map_err(|(field, message)| {
                setting(&format!("generators[{i}].{field}"), message)
            })?;
        }
        // The bound holds for the scene as a whole: 40 generators of a million boxes each
        // passed one by one and exhausted memory before the first step.
        let total = self
            .generators
            .iter()
            .fold(self.bodies.len() as u64, |n, g| {
                n.saturating_add(g.body_count())
            });
        if total > Generator::MAX_BODIES {
            return Err(setting(
                "generators",
                format!(
                    "make {total} bodies with the scene's own, more than the {} a scene may have",
                    Generator::MAX_BODIES
                ),
            ));
        }
        if let Some(p) = &self.perturb {
            p.validate()
                .map_err(|(field, message)| setting(&field, message))?;
        }
        if let Some(analytic) = &self.analytic {
            analytic
                .validate()
                .map_err(|(field, message)| setting(&field, message))?;
            for name in analytic.bodies() {
                match self.bodies.iter().find(|b| b.name == name) {
                    Some(b) if !b.fixed => {}
                    Some(_) => {
                        return Err(setting(
                            "analytic",
                            format!(
                                "body \"{name}\" is fixed; the closed form needs a dynamic body"
                            ),
                        ));
                    }
                    None => {
                        return Err(setting(
                            "analytic",
                            format!("no body named \"{name}\" in `bodies`"),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// World settings of this scene.
    pub fn settings(&self) -> WorldSettings {
        WorldSettings {
            gravity: self.gravity,
            resolver: self.resolver.clone().unwrap_or_default(),
            sleep: self.sleep.clone().unwrap_or_default(),
            ..WorldSettings::default()
        }
    }

    /// Every body of the scene, generated ones last.
    pub fn body_descs(&self) -> Result<Vec<BodyDesc>, SceneError> {
        let mut out = Vec::with_capacity(self.bodies.len());
        for (i, b) in self.bodies.iter().enumerate() {
            out.push(b.to_desc().map_err(|e| SceneError::Body {
                file: String::new(),
                at: None,
                index: Some(i as u32),
                error: e,
            })?);
        }
        let first_generated = out.len();
        for g in &self.generators {
            out.extend(g.bodies());
        }
        if let Some(p) = &self.perturb {
            p.apply(&mut out[first_generated..]);
        }
        let names: Vec<&str> = out.iter().map(|d| d.name.as_str()).collect();
        unique_names(&names, first_generated)?;
        Ok(out)
    }

    /// Builds the world with the scene's settings (overridden by `settings` when given).
    pub fn build_with(&self, settings: WorldSettings) -> Result<World, SceneError> {
        let mut world = World::new(settings);
        for (i, desc) in self.body_descs()?.into_iter().enumerate() {
            world.add_body(desc).map_err(|e| SceneError::Body {
                file: String::new(),
                at: None,
                index: (i < self.bodies.len()).then_some(i as u32),
                error: e,
            })?;
        }
        Ok(world)
    }

    /// Builds the world with the scene's own settings.
    pub fn build(&self) -> Result<World, SceneError> {
        self.build_with(self.settings())
    }
}

/// Refuses two bodies of one name: names are how errors, traces and snapshots tell bodies
/// apart, and a repeated one would make each of those ambiguous.
/// Bodies from `first_generated` on were made by generators: a clash among them names the
/// generators' `name` field, which sets the prefix of the bodies' names.
fn unique_names(names: &[&str], first_generated: usize) -> Result<(), SceneError> {
    let mut seen = std::collections::HashMap::with_capacity(names.len());
    // Bodies without a name (the default) are known by their place, not by name: several may
    // go unnamed (two were refused as having the same name "").
    for (i, &name) in names.iter().enumerate().filter(|(_, n)| !n.is_empty()) {
        if let Some(first) = seen.insert(name, i) {
            return Err(SceneError::Body {
                file: String::new(),
                at: None,
                index: None,
                error: BodyError::Field {
                    body: name.to_string(),
                    field: "name".into(),
                    message: if first >= first_generated {
                        format!(
                            "body {i} has the same name as body {first}; names must be unique \
                             (both are generated: give each generator of the same kind its own \
                             `name:`)"
                        )
                    } else {
                        format!("body {i} has the same name as body {first}; names must be unique")
                    },
                },
            });
        }
    }
    Ok(())
}
