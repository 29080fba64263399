//! `World`: bodies, colliders, the resolver and the step pipeline.
//!
//! Start reading at [`World::step`]: one linear pipeline of named, timed stages (ARCHITECTURE.md,
//! "The step"); each stage is a small function in `stages.rs` over exactly the data it
//! touches.

use crate::body_desc::{
    BodyDesc, BodyError, DEFAULT_DENSITY, MAX_GRAVITY, MassSpec, check_force_threshold,
    check_material, shape_error, shape_mass, unit_rotation,
};
use crate::collider_desc::{ColliderDesc, LocalMass};
use crate::profile::StepProfile;
use crate::settings::{ResolverChoice, WorldSettings};
use crate::stages::{self, Scratch};
use jostle_body::{BodyHandle, BodySet, BodyType, CcdMode, KinematicPath, RigidBody};
use jostle_collide::{
    BodyContact, BroadPhase, Collider, ColliderHandle, ColliderSet, CollisionEvent,
    CollisionGroups, ContactForceEvent, Material, NarrowPhase, PairFilter, Queries, QueryFilter,
    RayHit, SensorEvent,
};
use jostle_math::{Mat3, Quat, Vec3};
use jostle_resolve::clock::Stopwatch;
use jostle_resolve::{Resolver, StepContext};
use jostle_sleep::IslandSet;
use thiserror::Error;

/// Why a step or an API call was refused.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum StepError {
    /// The time step must be finite, > 0 and at most [`crate::MAX_DT`].
    #[error("time step must be in (0, 10] s, got {0}")]
    InvalidDt(f32),
    /// The handle is stale (its body was removed) or was never issued by this world.
    #[error("invalid or stale body handle {0}")]
    InvalidHandle(BodyHandle),
    /// The handle is stale (its collider was removed) or was never issued by this world.
    #[error("invalid or stale collider handle {0}")]
    InvalidCollider(ColliderHandle),
    /// A value given through the API is not finite.
    #[error("{what} must be finite, got {value}")]
    NonFinite {
        /// What was given (`force`, `impulse`, `position`, ...).
        what: &'static str,
        /// The value, formatted.
        value: String,
    },
    /// A value given through the API is out of its domain; `field` names it as a scene file
    /// would.
    #[error("{field}: {message}")]
    Invalid {
        /// The field (`friction`, `linear_damping`, `mass`, `resolver.substeps`, ...).
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A value given through the API is beyond what the engine holds
    /// ([`crate::MAX_SPEED`], [`crate::MAX_ANGULAR_SPEED`]).
    #[error("{what} {value} is above the limit of {limit}")]
    OutOfRange {
        /// What was given (`linear velocity`, `angular velocity`).
        what: &'static str,
        /// The value's magnitude, formatted.
        value: String,
        /// The limit, with its unit.
        limit: String,
    },
}

/// An API value refused with the field it is for.
fn invalid((field, message): (&str, String)) -> StepError {
    StepError::Invalid {
        field: field.to_string(),
        message,
    }
}

/// What a step reports besides the profile.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepReport {
    /// Bodies whose state went non-finite during this step, or beyond the limits a scene's body
    /// is held to ([`crate::MAX_POSITION`] from the origin on an axis, [`crate::MAX_SPEED`]) or
    /// a spin beyond [`crate::MAX_REACHED_ANGULAR_SPEED`]: each is frozen where it last had a
    /// pose within them (it becomes a fixed body) and named here. The rest of the world steps
    /// on.
    pub quarantined: Vec<(BodyHandle, String)>,
    /// Pairs of awake dynamic bodies in contact this step whose masses differ by more than the
    /// resolver's bound (`Resolver::max_mass_ratio`; the soft step's is
    /// [`crate::MAX_CONTACT_MASS_RATIO`]), lighter first, each once, in handle order: their
    /// contacts cannot hold the light body in f32 arithmetic, so it may be pressed deep into
    /// its neighbours or thrown out. Empty under a resolver without such a bound.
    pub beyond_mass_ratio: Vec<(BodyHandle, BodyHandle)>,
}

/// A physics world: add bodies, call [`World::step`].
pub struct World {
    pub(crate) settings: WorldSettings,
    pub(crate) bodies: BodySet,
    pub(crate) colliders: ColliderSet,
    broad: BroadPhase,
    pub(crate) narrow: NarrowPhase,
    pub(crate) islands: IslandSet,
    resolver: Box<dyn Resolver>,
    profile: StepProfile,
    pub(crate) time: f64,
    pub(crate) steps: u64,
    scratch: Scratch,
    /// Counts the changes that can move, add or remove a collider (steps, added or removed
    /// bodies and colliders, poses set, bodies made fixed or dynamic);
    /// the broad phase's tree serves queries while `query_stamp` equals it.
    stamp: u64,
    query_stamp: u64,
    /// Whether any body was given a path ([`World::set_path`]): then each step sends the
    /// bodies that have one along it.
    pub(crate) paths: bool,
    /// The user's pair filter ([`World::set_pair_filter`]); not kept in snapshots.
    pair_filter: Option<Box<PairFilter>>,
    /// The last step was a rest step (no body awake or moving, no candidate pair, no body
    /// woken, no path), and nothing has changed the world since: every `&mut self` method
    /// but [`World::step`] and [`World::update_queries`] clears it. The next step would
    /// change nothing but the clock (each stage finds nothing to do, as in the rest step
    /// before it), so it only advances the clock ([`World::step`]).
    settled: bool,
}

impl World {
    /// An empty world.
    pub fn new(settings: WorldSettings) -> Self {
        let resolver = settings.resolver.build();
        Self {
            settings,
            bodies: BodySet::new(),
            colliders: ColliderSet::default(),
            broad: BroadPhase::default(),
            narrow: NarrowPhase::default(),
            islands: IslandSet::new(),
            resolver,
            profile: StepProfile::default(),
            time: 0.0,
            steps: 0,
            scratch: Scratch::default(),
            stamp: 1,
            query_stamp: 0,
            paths: false,
            pair_filter: None,
            settled: false,
        }
    }

    /// The settings the world was built with.
    pub fn settings(&self) -> &WorldSettings {
        &self.settings
    }

    /// Replaces the resolver (any implementation of [`Resolver`]).
    pub fn set_resolver(&mut self, resolver: Box<dyn Resolver>) {
        self.settled = false;
        self.resolver = resolver;
    }

    /// The resolver's name.
    pub fn resolver_name(&self) -> &'static str {
        self.resolver.name()
    }

    /// Adds a body and its collider. The body's position is its centre of mass: for shapes
    /// whose centre of mass is not their origin (convex hulls, compounds), it differs from
    /// `desc.position` by the rotated centre-of-mass offset.
    pub fn add_body(&mut self, desc: BodyDesc) -> Result<BodyHandle, BodyError> {
        self.settled = false;
        desc.validate()?;
        self.stamp += 1;
        let shape = desc.shape.build().map_err(|e| shape_error(&desc.name, e))?;
        let rotation = unit_rotation(desc.rotation).unwrap_or(Quat::IDENTITY);
        let (body, local_pose) = if desc.fixed {
            (
                RigidBody::fixed().with_pose(desc.position, rotation),
                jostle_collide::Pose::IDENTITY,
            )
        } else {
            let props = shape_mass(&desc.shape, desc.mass).map_err(|(field, message)| {
                BodyError::Field {
                    body: desc.name.clone(),
                    field,
                    message,
                }
            })?;
            let body =
                RigidBody::dynamic(props.mass, props.inertia).map_err(|e| BodyError::Field {
                    body: desc.name.clone(),
                    field: "shape".into(),
                    message: format!("mass properties are degenerate: {e}"),
                })?;
            let com = desc.position + rotation * props.local_com;
            let mut body = body
                .with_pose(com, rotation)
                .with_velocity(desc.linear_velocity, desc.angular_velocity);
            body.set_origin_offset(-props.local_com);
            if desc.lock_rotation {
                body.lock_rotation();
            } else if desc.rotation_locks != [false; 3] {
                body.set_rotation_locks(desc.rotation_locks);
            }
            if desc.translation_locks != [false; 3] {
                body.set_translation_locks(desc.translation_locks);
            }
            (
                body,
                jostle_collide::Pose::from_translation(-props.local_com),
            )
        };
        let mut body = body;
        body.linear_damping = desc.linear_damping;
        body.angular_damping = desc.angular_damping;
        body.sleep.can_sleep = desc.can_sleep;
        jostle_sleep::motion::restart(&mut body, &self.settings.sleep);
        body.ccd = desc.ccd;
        body.name = desc.name;
        if let Some(kinematic) = desc.kinematic {
            let (body_type, path) = kinematic.start(body.position, body.orientation);
            body.set_body_type(body_type)
                .map_err(|e| BodyError::Field {
                    body: body.name.clone(),
                    field: "kinematic".into(),
                    message: e.to_string(),
                })?;
            self.paths |= path.is_some();
            body.set_path(path);
        }
        let handle = self.bodies.insert(body);
        let extra = desc.colliders;
        self.colliders.insert(
            Collider::new(shape, handle)
                .with_desc(desc.shape)
                .with_local_pose(local_pose)
                .with_material(desc.material)
                .with_groups(desc.groups)
                .with_sensor(desc.sensor)
                .with_force_event_threshold(desc.force_event_threshold),
        );
        for (i, c) in extra.into_iter().enumerate() {
            // Validated with the description; should one still fail, nothing is left behind.
            if let Err(e) = self.add_collider(handle, c) {
                let name = self.bodies.get(handle).map(|b| b.name.clone());
                let _ = self.remove_body(handle);
                return Err(BodyError::Field {
                    body: name.unwrap_or_default(),
                    field: format!("colliders[{i}]"),
                    message: e.to_string(),
                });
            }
        }
        Ok(handle)
    }

    /// Removes a body and its colliders, and returns the body. Its handle, and its
    /// colliders', go stale: every later call with them is refused with
    /// [`StepError::InvalidHandle`] (or `None`), even once a new body reuses the slot.
    ///
    /// What the body touched or rested on wakes, so that a stack loses its support rather than
    /// float: the body's sleeping island wakes, and every body it had a contact with. Its
    /// contacts are gone at once from the narrow phase (a snapshot taken now holds none of
    /// them); the next step reports each pair it touched as [`CollisionEvent::Stopped`].
    ///
    /// ```
    /// use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings::default());
    /// let ball = world.add_body(BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 })).unwrap();
    /// let removed = world.remove_body(ball).unwrap();
    /// assert_eq!(removed.name, "ball");
    /// assert!(world.body(ball).is_none());
    /// // A new body may take the slot; the old handle still names nothing.
    /// let other = world.add_body(BodyDesc::dynamic("other", ShapeDesc::Ball { radius: 0.5 })).unwrap();
    /// assert_eq!(other.index(), ball.index());
    /// assert!(world.body(ball).is_none() && world.remove_body(ball).is_err());
    /// ```
    pub fn remove_body(&mut self, handle: BodyHandle) -> Result<RigidBody, StepError> {
        self.settled = false;
        if !self.bodies.contains(handle) {
            return Err(StepError::InvalidHandle(handle));
        }
        self.wake_around(handle);
        let attached = self.colliders.attached(handle);
        for &collider in &attached {
            self.colliders.remove(collider);
        }
        self.narrow.remove_colliders(|c| attached.contains(&c));
        self.stamp += 1;
        self.bodies
            .remove(handle)
            .ok_or(StepError::InvalidHandle(handle))
    }

    /// Wakes `body`'s sleeping island and every body it has a contact with.
    fn wake_around(&mut self, body: BodyHandle) {
        let sleep = &self.settings.sleep;
        self.islands.wake(&mut self.bodies, body, sleep);
        let touched: Vec<BodyHandle> = self
            .narrow
            .contacts()
            .iter()
            .filter_map(|c| match (c.a == body, c.b == body) {
                (true, _) => Some(c.b),
                (_, true) => Some(c.a),
                _ => None,
            })
            .collect();
        for other in touched {
            self.islands.wake(&mut self.bodies, other, sleep);
        }
    }

    /// The colliders attached to a body, in slot order (one per body added with
    /// [`World::add_body`]); empty for a stale handle.
    pub fn colliders_of(&self, body: BodyHandle) -> Vec<ColliderHandle> {
        self.colliders.attached(body)
    }

    /// The collider behind `handle`, or `None` if the handle is stale or invalid.
    pub fn collider(&self, handle: ColliderHandle) -> Option<&Collider> {
        self.colliders.get(handle)
    }

    /// Attaches a further collider to `body` ([`ColliderDesc`]: its own shape, pose in the
    /// body's own frame — about [`RigidBody::origin`], the point the body's description placed
    /// it at — material, density, groups, sensor flag) and returns its handle. On a dynamic
    /// body its mass is added: the body's mass, centre of mass and inertia become the sums
    /// over its colliders, its centre moves to the new centre of mass (every collider keeps
    /// its place in the world) and its linear velocity becomes that of the point it moved to,
    /// so momentum and angular momentum about any point are kept. On a fixed or kinematic
    /// body the collider only moves with it. What the body touches wakes.
    ///
    /// ```
    /// use jostle::{BodyDesc, ColliderDesc, ShapeDesc, Vec3, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings::default());
    /// // A dumbbell: a bar with a ball at each end.
    /// let bar = world
    ///     .add_body(BodyDesc::dynamic("bar", ShapeDesc::Capsule { half_height: 0.5, radius: 0.05 })
    ///         .rotated(jostle::Quat::from_rotation_z(std::f32::consts::FRAC_PI_2)))
    ///     .unwrap();
    /// for y in [-0.6, 0.6] {
    ///     world
    ///         .add_collider(bar, ColliderDesc::new(ShapeDesc::Ball { radius: 0.2 }).at(Vec3::new(0.0, y, 0.0)))
    ///         .unwrap();
    /// }
    /// assert_eq!(world.colliders_of(bar).len(), 3);
    /// // Symmetric: the centre of mass stays at the bar's middle.
    /// assert!(world.body(bar).unwrap().position.length() < 1e-5);
    /// ```
    pub fn add_collider(
        &mut self,
        body: BodyHandle,
        desc: ColliderDesc,
    ) -> Result<ColliderHandle, StepError> {
        self.settled = false;
        let b = self
            .bodies
            .get(body)
            .ok_or(StepError::InvalidHandle(body))?;
        desc.validate()
            .map_err(|(field, message)| StepError::Invalid {
                field: format!("collider.{field}"),
                message,
            })?;
        let shape = desc.shape.build().map_err(|e| StepError::Invalid {
            field: format!("collider.shape.{}", e.field()),
            message: e.to_string(),
        })?;
        let rotation = unit_rotation(desc.rotation).unwrap_or(Quat::IDENTITY);
        // The description's position is on the body's own frame, whose origin sits at
        // `origin_offset` from the centre of mass.
        let at = b.origin_offset() + desc.position;
        let mut local = jostle_collide::Pose::from_parts(at, rotation);
        let adds_mass =
            b.body_type() == BodyType::Dynamic && desc.density > 0.0 && desc.shape.can_be_dynamic();
        if adds_mass {
            let part = shape_mass(&desc.shape, MassSpec::Density(desc.density)).map_err(
                |(field, message)| StepError::Invalid {
                    field: format!("collider.{field}"),
                    message,
                },
            )?;
            let (mass, inertia) = b
                .mass_properties()
                .ok_or_else(|| invalid(("collider", "the body has no mass properties".into())))?;
            let whole = LocalMass {
                mass,
                com: Vec3::ZERO,
                inertia,
            }
            .plus(&LocalMass::of_part(&part, at, rotation));
            let shift = whole.com;
            self.move_centre_of_mass(body, shift, whole.mass, whole.inertia)?;
            local = jostle_collide::Pose::from_parts(at - shift, rotation);
        }
        self.wake_around(body);
        self.stamp += 1;
        Ok(self.colliders.insert(
            Collider::new(shape, body)
                .with_desc(desc.shape)
                .with_local_pose(local)
                .with_material(desc.material)
                .with_groups(desc.groups)
                .with_sensor(desc.sensor)
                .with_force_event_threshold(desc.force_event_threshold),
        ))
    }

    /// Moves `body`'s centre of mass by `shift` (body frame) without moving its colliders in
    /// the world, and gives it `mass` and the body-space `inertia` about the new centre; the
    /// linear velocity becomes that of the new centre.
    fn move_centre_of_mass(
        &mut self,
        body: BodyHandle,
        shift: Vec3,
        mass: f32,
        inertia: Mat3,
    ) -> Result<(), StepError> {
        let b = self
            .bodies
            .get_mut(body)
            .ok_or(StepError::InvalidHandle(body))?;
        // First what can fail, which then changes nothing.
        b.set_mass_properties(mass, inertia)
            .map_err(|e| invalid(("mass", e.to_string())))?;
        let world_shift = b.orientation * shift;
        b.position += world_shift;
        b.set_origin_offset(b.origin_offset() - shift);
        b.linear_velocity =
            b.without_locked_motion(b.linear_velocity + b.angular_velocity.cross(world_shift));
        for c in self.colliders.attached(body) {
            if let Some(collider) = self.colliders.get_mut(c) {
                let pose = collider.local_pose();
                collider.set_local_pose(jostle_collide::Pose::from_parts(
                    pose.translation - shift,
                    pose.rotation,
                ));
            }
        }
        Ok(())
    }

    /// Removes one collider and returns it; its body stays, with the mass it had (a body
    /// without colliders touches nothing). The body and what the collider touched wake, as for
    /// [`World::remove_body`].
    pub fn remove_collider(&mut self, handle: ColliderHandle) -> Result<Collider, StepError> {
        self.settled = false;
        let body = self
            .colliders
            .get(handle)
            .ok_or(StepError::InvalidCollider(handle))?
            .body;
        self.wake_around(body);
        self.narrow.remove_colliders(|c| c == handle);
        self.stamp += 1;
        self.colliders
            .remove(handle)
            .ok_or(StepError::InvalidCollider(handle))
    }

    /// The body behind `handle`, or `None` if the handle is stale or invalid.
    pub fn body(&self, handle: BodyHandle) -> Option<&RigidBody> {
        self.bodies.get(handle)
    }

    /// The name the body was added with.
    pub fn body_name(&self, handle: BodyHandle) -> Option<&str> {
        self.bodies.get(handle).map(|b| b.name.as_str())
    }

    /// The first body with this name, in slot order.
    pub fn find_body(&self, name: &str) -> Option<BodyHandle> {
        self.bodies
            .iter()
            .find(|(_, b)| b.name == name)
            .map(|(h, _)| h)
    }

    /// All bodies with their handles and names, in a deterministic order (slot order).
    pub fn bodies(&self) -> impl Iterator<Item = (BodyHandle, &str, &RigidBody)> {
        self.bodies.iter().map(|(h, b)| (h, b.name.as_str(), b))
    }

    /// Number of bodies (fixed ones included).
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    fn body_mut_awake(&mut self, handle: BodyHandle) -> Result<&mut RigidBody, StepError> {
        if !self.bodies.contains(handle) {
            return Err(StepError::InvalidHandle(handle));
        }
        self.islands
            .wake(&mut self.bodies, handle, &self.settings.sleep);
        self.bodies
            .get_mut(handle)
            .ok_or(StepError::InvalidHandle(handle))
    }

    /// Refuses velocities beyond [`crate::MAX_SPEED`] and [`crate::MAX_ANGULAR_SPEED`].
    fn within_speed_limits(linear: Vec3, angular: Vec3) -> Result<(), StepError> {
        let limit = |what, v: Vec3, limit: f32, unit| {
            if v.length() <= limit {
                Ok(())
            } else {
                Err(StepError::OutOfRange {
                    what,
                    value: format!("{:.3e} {unit}", v.length()),
                    limit: format!("{limit:e} {unit}"),
                })
            }
        };
        limit("linear velocity", linear, crate::MAX_SPEED, "m/s")?;
        limit(
            "angular velocity",
            angular,
            crate::MAX_ANGULAR_SPEED,
            "rad/s",
        )
    }

    fn finite(what: &'static str, v: Vec3) -> Result<(), StepError> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(StepError::NonFinite {
                what,
                value: v.to_string(),
            })
        }
    }

    /// Adds a force (N) through the centre of mass for the next step; wakes the body's island.
    pub fn apply_force(&mut self, handle: BodyHandle, force: Vec3) -> Result<(), StepError> {
        self.settled = false;
        Self::finite("force", force)?;
        self.body_mut_awake(handle)?.add_force(force);
        Ok(())
    }

    /// Adds a force (N) at a world point for the next step; wakes the body's island.
    pub fn apply_force_at_point(
        &mut self,
        handle: BodyHandle,
        force: Vec3,
        point: Vec3,
    ) -> Result<(), StepError> {
        self.settled = false;
        Self::finite("force", force)?;
        Self::finite("point", point)?;
        self.body_mut_awake(handle)?
            .add_force_at_point(force, point);
        Ok(())
    }

    /// Adds a torque (N·m) for the next step; wakes the body's island.
    pub fn apply_torque(&mut self, handle: BodyHandle, torque: Vec3) -> Result<(), StepError> {
        self.settled = false;
        Self::finite("torque", torque)?;
        self.body_mut_awake(handle)?.add_torque(torque);
        Ok(())
    }

    /// Applies an impulse (N·s) at a world point now; wakes the body's island. Refused with
    /// [`StepError::OutOfRange`], changing nothing, when the body's velocities after it would
    /// exceed [`crate::MAX_SPEED`] or [`crate::MAX_ANGULAR_SPEED`].
    pub fn apply_impulse_at_point(
        &mut self,
        handle: BodyHandle,
        impulse: Vec3,
        point: Vec3,
    ) -> Result<(), StepError> {
        self.settled = false;
        Self::finite("impulse", impulse)?;
        Self::finite("point", point)?;
        // Refused, changing nothing, when the velocities it would give are beyond the limits
        // (a finite impulse of 1e30 N·s made the body non-finite in the next step).
        let mut after = self
            .bodies
            .get(handle)
            .ok_or(StepError::InvalidHandle(handle))?
            .clone();
        after.apply_impulse_at_point(impulse, point);
        Self::within_speed_limits(after.linear_velocity, after.angular_velocity)?;
        self.body_mut_awake(handle)?
            .apply_impulse_at_point(impulse, point);
        Ok(())
    }

    /// A finite position and the unit rotation of a finite non-zero quaternion, or the error
    /// naming which is not.
    fn checked_pose(position: Vec3, rotation: Quat) -> Result<Quat, StepError> {
        Self::finite("position", position)?;
        unit_rotation(rotation).ok_or_else(|| StepError::NonFinite {
            what: "rotation",
            value: format!("{rotation:?}"),
        })
    }

    /// Sets the pose of the centre of mass; wakes the body's island.
    pub fn set_pose(
        &mut self,
        handle: BodyHandle,
        position: Vec3,
        rotation: Quat,
    ) -> Result<(), StepError> {
        self.settled = false;
        let unit = Self::checked_pose(position, rotation)?;
        let body = self.body_mut_awake(handle)?;
        body.position = position;
        body.orientation = unit;
        body.update_world_inertia();
        self.stamp += 1;
        Ok(())
    }

    /// Sets the velocities; wakes the body's island. The angular velocity of a body whose
    /// rotation is locked stays zero.
    pub fn set_velocity(
        &mut self,
        handle: BodyHandle,
        linear: Vec3,
        angular: Vec3,
    ) -> Result<(), StepError> {
        self.settled = false;
        Self::finite("linear velocity", linear)?;
        Self::finite("angular velocity", angular)?;
        Self::within_speed_limits(linear, angular)?;
        let body = self.body_mut_awake(handle)?;
        body.linear_velocity = body.without_locked_motion(linear);
        if !body.is_rotation_locked() {
            body.angular_velocity = body.without_locked_turn(angular);
        }
        body.sleep.mean_linear = body.linear_velocity;
        body.sleep.mean_angular = body.angular_velocity;
        Ok(())
    }

    /// Wakes the body and its sleeping island.
    pub fn wake(&mut self, handle: BodyHandle) -> Result<(), StepError> {
        self.settled = false;
        self.body_mut_awake(handle).map(|_| ())
    }

    /// Puts the body to sleep now (zero velocity); it wakes on contact with an awake body, a
    /// force, an impulse or a pose set, like any sleeping body.
    pub fn sleep(&mut self, handle: BodyHandle) -> Result<(), StepError> {
        self.settled = false;
        let body = self
            .bodies
            .get_mut(handle)
            .ok_or(StepError::InvalidHandle(handle))?;
        jostle_sleep::motion::sleep(body);
        Ok(())
    }

    // Changes after creation. Each is checked as a scene file's field would be (refused with
    // the field named, changing nothing) and wakes what it must.

    /// Sets the material of one collider (friction, dynamic friction, restitution and their
    /// combine rules); picked up by its contacts at the next step. Wakes its body.
    pub fn set_collider_material(
        &mut self,
        handle: ColliderHandle,
        material: Material,
    ) -> Result<(), StepError> {
        self.settled = false;
        check_material(&material).map_err(invalid)?;
        let body = self.change_collider(handle, |c| c.material = material)?;
        self.islands
            .wake(&mut self.bodies, body, &self.settings.sleep);
        Ok(())
    }

    /// Makes a collider a sensor, or a solid collider again ([`Collider::sensor`]): a sensor
    /// makes no contacts and reports what enters and leaves it ([`World::sensor_events`]).
    /// What its body touched wakes.
    ///
    /// ```
    /// use jostle::{BodyDesc, SensorEvent, ShapeDesc, Vec3, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings::default());
    /// let gate = world
    ///     .add_body(BodyDesc::fixed("gate", ShapeDesc::Cuboid { half_extents: Vec3::new(2.0, 0.1, 2.0) }))
    ///     .unwrap();
    /// world.set_sensor(world.colliders_of(gate)[0], true).unwrap();
    /// world
    ///     .add_body(BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.2 }).at(Vec3::new(0.0, 1.0, 0.0)))
    ///     .unwrap();
    /// let mut entered = false;
    /// for _ in 0..60 {
    ///     world.step(1.0 / 60.0).unwrap();
    ///     entered |= world.sensor_events().iter().any(|e| matches!(e, SensorEvent::Entered { .. }));
    /// }
    /// // The ball fell through the gate and was seen.
    /// assert!(entered);
    /// ```
    pub fn set_sensor(&mut self, handle: ColliderHandle, sensor: bool) -> Result<(), StepError> {
        self.settled = false;
        let body = self.change_collider(handle, |c| c.sensor = sensor)?;
        self.wake_around(body);
        Ok(())
    }

    /// Applies `change` to a collider; returns its body.
    fn change_collider(
        &mut self,
        handle: ColliderHandle,
        change: impl FnOnce(&mut Collider),
    ) -> Result<BodyHandle, StepError> {
        let collider = self
            .colliders
            .get_mut(handle)
            .ok_or(StepError::InvalidCollider(handle))?;
        change(collider);
        Ok(collider.body)
    }

    /// Asks `filter` which collider pairs may make contact (or report sensor events), after
    /// their groups ([`PairFilter`]); `None` removes it. Every body wakes, so that pairs the
    /// new filter refuses part and pairs it admits meet. A snapshot does not keep the filter:
    /// set it again on the restored world. In a large step it is asked from the narrow phase's
    /// helper threads too, in any order ([`PairFilter`]).
    ///
    /// ```
    /// use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings::default());
    /// world.add_body(BodyDesc::fixed("ground", ShapeDesc::HalfSpace { normal: Vec3::Y })).unwrap();
    /// let ghost = world
    ///     .add_body(BodyDesc::dynamic("ghost", ShapeDesc::Ball { radius: 0.5 }).at(Vec3::new(0.0, 0.5, 0.0)))
    ///     .unwrap();
    /// // The ghost's collider makes no contact with anything.
    /// world.set_pair_filter(Some(Box::new(move |a: &jostle::Collider, b: &jostle::Collider| {
    ///     a.body != ghost && b.body != ghost
    /// })));
    /// for _ in 0..60 {
    ///     world.step(1.0 / 60.0).unwrap();
    /// }
    /// assert!(world.body(ghost).unwrap().position.y < -1.0, "it fell through the ground");
    /// ```
    pub fn set_pair_filter(&mut self, filter: Option<Box<PairFilter>>) {
        self.settled = false;
        self.pair_filter = filter;
        self.wake_all();
    }

    /// Sets the normal force (N) above which a collider's contacts with another in a step are
    /// reported ([`World::contact_force_events`]); `None` stops them. Refused unless finite
    /// and ≥ 0.
    pub fn set_force_event_threshold(
        &mut self,
        handle: ColliderHandle,
        threshold: Option<f32>,
    ) -> Result<(), StepError> {
        self.settled = false;
        check_force_threshold(threshold).map_err(invalid)?;
        self.change_collider(handle, |c| c.force_event_threshold = threshold)?;
        Ok(())
    }

    /// Sets a collider's collision groups ([`CollisionGroups`]): which colliders it makes
    /// contacts with (or, for a sensor, reports). What its body touched wakes.
    pub fn set_collision_groups(
        &mut self,
        handle: ColliderHandle,
        groups: CollisionGroups,
    ) -> Result<(), StepError> {
        self.settled = false;
        let body = self.change_collider(handle, |c| c.groups = groups)?;
        self.wake_around(body);
        Ok(())
    }

    /// Sets the material of every collider of a body ([`World::set_collider_material`]).
    ///
    /// ```
    /// use jostle::{BodyDesc, Combine, Material, ShapeDesc, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings::default());
    /// let puck = world.add_body(BodyDesc::dynamic("puck", ShapeDesc::Ball { radius: 0.1 })).unwrap();
    /// // Ice: whatever it slides on, the smaller friction holds.
    /// let ice = Material::new(0.02, 0.1).with_combine(Combine::Min, Combine::Max);
    /// world.set_material(puck, ice).unwrap();
    /// assert!(world.set_material(puck, Material::new(-1.0, 0.0)).is_err());
    /// ```
    pub fn set_material(&mut self, body: BodyHandle, material: Material) -> Result<(), StepError> {
        self.settled = false;
        check_material(&material).map_err(invalid)?;
        if !self.bodies.contains(body) {
            return Err(StepError::InvalidHandle(body));
        }
        for collider in self.colliders.attached(body) {
            self.set_collider_material(collider, material)?;
        }
        self.islands
            .wake(&mut self.bodies, body, &self.settings.sleep);
        Ok(())
    }

    /// Sets a body's linear and angular damping (1/s, finite and ≥ 0); wakes it.
    pub fn set_damping(
        &mut self,
        handle: BodyHandle,
        linear: f32,
        angular: f32,
    ) -> Result<(), StepError> {
        self.settled = false;
        for (field, x) in [("linear_damping", linear), ("angular_damping", angular)] {
            if !(x.is_finite() && x >= 0.0) {
                return Err(invalid((
                    field,
                    format!("must be finite and >= 0, got {x}"),
                )));
            }
        }
        let body = self.body_mut_awake(handle)?;
        body.linear_damping = linear;
        body.angular_damping = angular;
        Ok(())
    }

    /// Gives a dynamic body new mass properties from its colliders' shapes: a total mass
    /// (inertia scaled from the shapes' at one uniform density) or a density for all of them,
    /// as [`BodyDesc`] takes them; with several colliders the parts are summed and the body's
    /// centre moves to their centre of mass as in [`World::add_collider`]. The orientation
    /// and angular velocity are kept (momentum is not: a heavier body moves as fast as
    /// before).
    /// Refused for a fixed body ([`World::set_fixed`] makes it dynamic) and for limits a scene
    /// file refuses; wakes the body.
    pub fn set_mass(&mut self, handle: BodyHandle, mass: MassSpec) -> Result<(), StepError> {
        self.settled = false;
        let body = self
            .bodies
            .get(handle)
            .ok_or(StepError::InvalidHandle(handle))?;
        if body.is_fixed() {
            return Err(invalid((
                "fixed",
                "a fixed body has no mass: make it dynamic first (World::set_fixed)".into(),
            )));
        }
        crate::body_desc::check_mass(mass).map_err(|(f, m)| invalid((f, m)))?;
        let sum = self.summed_mass(handle, mass)?;
        self.body_mut_awake(handle)?;
        self.move_centre_of_mass(handle, sum.com, sum.mass, sum.inertia)
    }

    /// Makes a body fixed (immovable, at rest) or dynamic again:
    /// [`World::set_body_type`] with [`BodyType::Fixed`] or [`BodyType::Dynamic`].
    ///
    /// ```
    /// use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings::default());
    /// let shelf = world
    ///     .add_body(BodyDesc::fixed("shelf", ShapeDesc::Cuboid { half_extents: Vec3::new(1.0, 0.1, 1.0) })
    ///         .at(Vec3::new(0.0, 2.0, 0.0)))
    ///     .unwrap();
    /// world.set_fixed(shelf, false).unwrap(); // the shelf breaks loose and falls
    /// for _ in 0..30 {
    ///     world.step(1.0 / 60.0).unwrap();
    /// }
    /// assert!(world.body(shelf).unwrap().position.y < 1.0);
    /// ```
    pub fn set_fixed(&mut self, handle: BodyHandle, fixed: bool) -> Result<(), StepError> {
        self.settled = false;
        self.set_body_type(
            handle,
            if fixed {
                BodyType::Fixed
            } else {
                BodyType::Dynamic
            },
        )
    }

    /// Changes what moves a body ([`BodyType`]): dynamic, fixed, or kinematic, moved by the
    /// velocity it is given ([`World::set_velocity`]) or to the pose it is sent to
    /// ([`World::set_next_pose`]), pushing dynamic bodies and pushed by nothing (forces and
    /// impulses on it are ignored, and gravity does not act on it). A body that was dynamic
    /// becomes dynamic again with the mass properties (and rotation lock) it had; one added
    /// fixed gets its shape's at [`crate::body_desc::DEFAULT_DENSITY`] (change them with
    /// [`World::set_mass`]), its centre of mass where its shape's is. A kinematic body keeps
    /// its velocity, a fixed one comes to rest. What it touched wakes; a half-space stays
    /// fixed.
    ///
    /// ```
    /// use jostle::{BodyDesc, BodyType, ShapeDesc, Vec3, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings::default());
    /// let half = Vec3::new(2.0, 0.1, 2.0);
    /// let lift = world.add_body(BodyDesc::dynamic("lift", ShapeDesc::Cuboid { half_extents: half })).unwrap();
    /// world.set_body_type(lift, BodyType::KinematicVelocity).unwrap();
    /// world.set_velocity(lift, Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO).unwrap();
    /// for _ in 0..60 {
    ///     world.step(1.0 / 60.0).unwrap();
    /// }
    /// // Gravity does not act on it: one second at 1 m/s up.
    /// assert!((world.body(lift).unwrap().position.y - 1.0).abs() < 1e-4);
    /// ```
    pub fn set_body_type(
        &mut self,
        handle: BodyHandle,
        body_type: BodyType,
    ) -> Result<(), StepError> {
        self.settled = false;
        let body = self
            .bodies
            .get(handle)
            .ok_or(StepError::InvalidHandle(handle))?;
        if body.body_type() == body_type {
            return Ok(());
        }
        let needs_mass = body_type == BodyType::Dynamic && !body.has_mass_properties();
        let colliders = self.colliders.attached(handle);
        let unbounded = colliders
            .iter()
            .any(|&c| self.colliders.get(c).is_some_and(|c| c.is_unbounded()));
        if body_type != BodyType::Fixed && unbounded {
            return Err(invalid((
                "body_type",
                "a half-space has no finite mass or bounds: it must stay fixed".into(),
            )));
        }
        let first_mass = if needs_mass {
            Some(self.summed_mass(handle, MassSpec::Density(DEFAULT_DENSITY))?)
        } else {
            None
        };
        self.wake_around(handle);
        if let Some(sum) = first_mass {
            // The body's origin becomes its centre of mass; its colliders stay where they are.
            self.move_centre_of_mass(handle, sum.com, sum.mass, sum.inertia)?;
        }
        let body = self
            .bodies
            .get_mut(handle)
            .ok_or(StepError::InvalidHandle(handle))?;
        body.set_body_type(body_type)
            .map_err(|e| invalid(("body_type", e.to_string())))?;
        if body_type == BodyType::Dynamic {
            jostle_sleep::motion::restart(body, &self.settings.sleep);
        }
        body.sleep.awake = match body_type {
            BodyType::Fixed => false,
            BodyType::Dynamic => true,
            _ => body.kinematic_moves(),
        };
        self.stamp += 1;
        Ok(())
    }

    /// Gives a body a scripted motion ([`KinematicPath`]: back and forth along a line, or a
    /// turn about an axis) that every step follows from then on, the path's time being the
    /// world's ([`World::time`]); the body becomes position-based kinematic if it was not.
    /// `None` takes the path away (the body stays kinematic, at rest). The path's numbers are
    /// checked ([`StepError::Invalid`] names the field, nothing changes).
    ///
    /// ```
    /// use jostle::{BodyDesc, KinematicPath, Quat, ShapeDesc, Vec3, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings::default());
    /// let arm = world
    ///     .add_body(BodyDesc::dynamic("arm", ShapeDesc::Cuboid { half_extents: Vec3::new(1.0, 0.1, 0.1) })
    ///         .at(Vec3::new(1.0, 0.5, 0.0)))
    ///     .unwrap();
    /// // Round the vertical axis through the origin, once every 4 s.
    /// let path = KinematicPath::Turn {
    ///     start: Vec3::new(1.0, 0.5, 0.0),
    ///     rotation: Quat::IDENTITY,
    ///     center: Vec3::ZERO,
    ///     axis: Vec3::Y,
    ///     period: 4.0,
    /// };
    /// world.set_path(arm, Some(path)).unwrap();
    /// for _ in 0..60 {
    ///     world.step(1.0 / 60.0).unwrap();
    /// }
    /// // A quarter turn in one second: +x went to −z.
    /// let p = world.body(arm).unwrap().position;
    /// assert!((p - Vec3::new(0.0, 0.5, -1.0)).length() < 1e-3, "{p}");
    /// ```
    pub fn set_path(
        &mut self,
        handle: BodyHandle,
        path: Option<KinematicPath>,
    ) -> Result<(), StepError> {
        self.settled = false;
        if let Some(path) = &path {
            path.check()
                .and_then(|()| crate::body_desc::path_within_limits(path))
                .map_err(|(field, message)| invalid((&format!("path.{field}"), message)))?;
        }
        let body_type = self
            .bodies
            .get(handle)
            .ok_or(StepError::InvalidHandle(handle))?
            .body_type();
        if path.is_some() && body_type != BodyType::KinematicPosition {
            self.set_body_type(handle, BodyType::KinematicPosition)?;
        }
        let body = self
            .bodies
            .get_mut(handle)
            .ok_or(StepError::InvalidHandle(handle))?;
        body.set_path(path);
        self.paths |= path.is_some();
        Ok(())
    }

    /// Sends a position-based kinematic body ([`BodyType::KinematicPosition`]) to a pose,
    /// which it reaches at the end of the next step, moving at the velocity that takes it
    /// there (so that what it pushes or carries moves with it). Without a new pose it stays
    /// where it is. Refused for other bodies; wakes what it touches.
    pub fn set_next_pose(
        &mut self,
        handle: BodyHandle,
        position: Vec3,
        rotation: Quat,
    ) -> Result<(), StepError> {
        self.settled = false;
        let unit = Self::checked_pose(position, rotation)?;
        let body = self
            .bodies
            .get_mut(handle)
            .ok_or(StepError::InvalidHandle(handle))?;
        if body.body_type() != BodyType::KinematicPosition {
            return Err(invalid((
                "body_type",
                format!(
                    "a next pose is for a KinematicPosition body, this one is {:?}",
                    body.body_type()
                ),
            )));
        }
        body.set_next_pose(position, unit);
        body.sleep.awake = true;
        Ok(())
    }

    /// Scales the world's gravity on one body (finite: 0 floats, 1 is the default, −1 falls up);
    /// wakes it.
    pub fn set_gravity_scale(&mut self, handle: BodyHandle, scale: f32) -> Result<(), StepError> {
        self.settled = false;
        if !(scale.is_finite() && (scale.abs() * self.settings.gravity.length()) <= MAX_GRAVITY) {
            return Err(invalid((
                "gravity_scale",
                format!("must be finite and give at most {MAX_GRAVITY:e} m/s², got {scale}"),
            )));
        }
        self.body_mut_awake(handle)?.gravity_scale = scale;
        Ok(())
    }

    /// Sets a body's continuous collision detection mode; wakes it.
    pub fn set_ccd(&mut self, handle: BodyHandle, mode: CcdMode) -> Result<(), StepError> {
        self.settled = false;
        self.body_mut_awake(handle)?.ccd = mode;
        Ok(())
    }

    /// Locks (or, with `false`, unlocks) a body's rotation about each world axis (x, y, z)
    /// ([`RigidBody::set_rotation_locks`]): its angular velocity loses the locked components
    /// and nothing turns it about them any more. Wakes the body. Refused for a fixed body.
    ///
    /// ```
    /// use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings { gravity: Vec3::ZERO, ..Default::default() });
    /// let top = world.add_body(BodyDesc::dynamic("top", ShapeDesc::Cuboid { half_extents: Vec3::splat(0.5) })).unwrap();
    /// world.set_rotation_locks(top, [true, false, true]).unwrap();
    /// // A push at a corner: it turns about the vertical only.
    /// world.apply_impulse_at_point(top, Vec3::new(0.0, 0.0, 100.0), Vec3::new(0.5, 0.5, 0.0)).unwrap();
    /// let w = world.body(top).unwrap().angular_velocity;
    /// assert!(w.x == 0.0 && w.z == 0.0 && w.y != 0.0);
    /// ```
    pub fn set_rotation_locks(
        &mut self,
        handle: BodyHandle,
        locks: [bool; 3],
    ) -> Result<(), StepError> {
        self.settled = false;
        self.unfixed_body_mut(handle, "rotation_locks", "a fixed body does not turn")?
            .set_rotation_locks(locks);
        Ok(())
    }

    /// Locks (or, with `false`, unlocks) a body's translation along each world axis (x, y,
    /// z) ([`RigidBody::set_translation_locks`]): its linear velocity loses the locked
    /// components and nothing (contacts, impulses, forces, gravity) moves its centre of mass
    /// along them any more, in either resolver. Wakes the body. Refused for a fixed body.
    ///
    /// ```
    /// use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings::default());
    /// let puck = world.add_body(BodyDesc::dynamic("puck", ShapeDesc::Ball { radius: 0.5 })).unwrap();
    /// // Gravity pulls along y: locked along y, the puck floats where it is.
    /// world.set_translation_locks(puck, [false, true, false]).unwrap();
    /// world.apply_impulse_at_point(puck, Vec3::new(3.0, 3.0, 0.0), Vec3::ZERO).unwrap();
    /// for _ in 0..60 {
    ///     world.step(1.0 / 60.0).unwrap();
    /// }
    /// let b = world.body(puck).unwrap();
    /// assert_eq!(b.position.y, 0.0);
    /// assert!(b.position.x > 0.0);
    /// ```
    pub fn set_translation_locks(
        &mut self,
        handle: BodyHandle,
        locks: [bool; 3],
    ) -> Result<(), StepError> {
        self.settled = false;
        self.unfixed_body_mut(handle, "translation_locks", "a fixed body does not move")?
            .set_translation_locks(locks);
        Ok(())
    }

    /// The body of `handle`, woken, unless it is fixed: then an error naming `field` says
    /// `why` and to make it dynamic first.
    fn unfixed_body_mut(
        &mut self,
        handle: BodyHandle,
        field: &'static str,
        why: &str,
    ) -> Result<&mut RigidBody, StepError> {
        if self
            .bodies
            .get(handle)
            .ok_or(StepError::InvalidHandle(handle))?
            .is_fixed()
        {
            return Err(invalid((field, format!("{why}: make it dynamic first"))));
        }
        self.body_mut_awake(handle)
    }

    /// Allows or forbids a body to sleep; forbidding wakes it (and its island).
    pub fn set_can_sleep(&mut self, handle: BodyHandle, can_sleep: bool) -> Result<(), StepError> {
        self.settled = false;
        let body = if can_sleep {
            self.bodies
                .get_mut(handle)
                .ok_or(StepError::InvalidHandle(handle))?
        } else {
            self.body_mut_awake(handle)?
        };
        body.sleep.can_sleep = can_sleep;
        Ok(())
    }

    /// Sets the world's gravity (m/s², finite, at most [`crate::MAX_GRAVITY`]); every
    /// sleeping body wakes, since what held it may no longer.
    pub fn set_gravity(&mut self, gravity: Vec3) -> Result<(), StepError> {
        self.settled = false;
        if !(gravity.is_finite() && gravity.length() <= MAX_GRAVITY) {
            return Err(invalid((
                "gravity",
                format!("must be finite and at most {MAX_GRAVITY:e} m/s², got {gravity}"),
            )));
        }
        self.settings.gravity = gravity;
        self.wake_all();
        Ok(())
    }

    /// Replaces the resolver by a validated choice with its settings (its state, the warm
    /// start included, starts afresh; the contacts keep their carried impulses). Unlike
    /// [`World::set_resolver`], the choice is recorded in the settings, so snapshots carry it.
    /// Every body wakes.
    pub fn set_resolver_choice(&mut self, choice: ResolverChoice) -> Result<(), StepError> {
        self.settled = false;
        choice
            .validate()
            .map_err(|(field, message)| StepError::Invalid {
                field: format!("resolver.{field}"),
                message,
            })?;
        self.resolver = choice.build();
        self.settings.resolver = choice;
        self.wake_all();
        Ok(())
    }

    /// Wakes every sleeping body.
    fn wake_all(&mut self) {
        let handles: Vec<BodyHandle> = self.bodies.iter().map(|(h, _)| h).collect();
        for h in handles {
            self.islands.wake(&mut self.bodies, h, &self.settings.sleep);
        }
    }

    /// The mass properties of a body's shape given as `mass` (its one collider's
    /// description).
    /// The mass properties of `handle`'s colliders summed in the body's frame, each at the
    /// density of `mass` (`MassSpec::Density`), or all at one density scaled so that they
    /// weigh `MassSpec::Mass` together. Colliders whose shape has no volume (half-spaces)
    /// add nothing; a body with no collider that has one is refused.
    fn summed_mass(&self, handle: BodyHandle, mass: MassSpec) -> Result<LocalMass, StepError> {
        let density = match mass {
            MassSpec::Density(d) => MassSpec::Density(d),
            MassSpec::Mass(_) => MassSpec::Density(1.0),
        };
        let mut sum: Option<LocalMass> = None;
        for c in self.colliders.attached(handle) {
            let collider = self.colliders.get(c).ok_or(StepError::InvalidCollider(c))?;
            let Some(desc) = collider.desc() else {
                continue;
            };
            if !desc.can_be_dynamic() {
                continue;
            }
            let part = shape_mass(desc, density)
                .map_err(|(field, message)| StepError::Invalid { field, message })?;
            let pose = collider.local_pose();
            let part = LocalMass::of_part(&part, pose.translation, pose.rotation);
            sum = Some(match sum {
                Some(s) => s.plus(&part),
                None => part,
            });
        }
        let mut sum = sum.ok_or_else(|| {
            invalid((
                "shape",
                "the body has no collider with a volume to take mass from".into(),
            ))
        })?;
        if let MassSpec::Mass(m) = mass {
            let scale = m / sum.mass;
            sum.mass = m;
            sum.inertia *= scale;
        }
        Ok(sum)
    }

    /// Simulated time (s) and steps taken.
    pub fn time(&self) -> (f64, u64) {
        (self.time, self.steps)
    }

    /// The profile of the last step.
    pub fn profile(&self) -> &StepProfile {
        &self.profile
    }

    /// The contacts of the last step (detected at its start), with the impulses the resolver
    /// applied.
    pub fn contacts(&self) -> &[BodyContact] {
        self.narrow.contacts()
    }

    /// Pairs of bodies that started or stopped touching in the last step.
    pub fn events(&self) -> &[CollisionEvent] {
        self.narrow.events()
    }

    /// Collider pairs whose contacts pushed harder than their threshold in the last step
    /// ([`World::set_force_event_threshold`]).
    pub fn contact_force_events(&self) -> &[ContactForceEvent] {
        self.narrow.force_events()
    }

    /// Colliders that started or stopped overlapping a sensor in the last step.
    pub fn sensor_events(&self) -> &[SensorEvent] {
        self.narrow.sensor_events()
    }

    /// The colliders overlapping each sensor now: (sensor, other), sorted.
    pub fn sensor_overlaps(&self) -> &[(ColliderHandle, ColliderHandle)] {
        self.narrow.sensor_overlaps()
    }

    /// Largest penetration (m) among the last step's contacts, 0 if none overlap.
    pub fn max_penetration(&self) -> f32 {
        self.narrow
            .contacts()
            .iter()
            .map(|c| c.penetration)
            .fold(0.0, f32::max)
    }

    /// A 64-bit hash (FNV-1a) of the exact bits of every body's pose, velocities and sleep
    /// state, in handle order, and of the step count: two worlds with the same hash are, for
    /// practical purposes, bit-identical. Used by the determinism tests; handy for users who
    /// check replays or lockstep networking.
    pub fn state_hash(&self) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |bits: u32| {
            for byte in bits.to_le_bytes() {
                h = (h ^ byte as u64).wrapping_mul(0x0000_0100_0000_01b3);
            }
        };
        eat(self.steps as u32);
        for (handle, b) in self.bodies.iter() {
            eat(handle.index());
            let floats = [
                b.position.to_array(),
                b.linear_velocity.to_array(),
                b.angular_velocity.to_array(),
            ];
            for x in floats
                .iter()
                .flatten()
                .chain(b.orientation.to_array().iter())
            {
                eat(x.to_bits());
            }
            eat(b.sleep.motion.to_bits());
            eat(u32::from(b.sleep.awake));
        }
        h
    }

    /// Total kinetic energy of the dynamic bodies (J).
    pub fn kinetic_energy(&self) -> f64 {
        self.bodies
            .iter()
            .map(|(_, b)| b.kinetic_energy() as f64)
            .sum()
    }

    /// The first body hit by a ray from `origin` along `dir` within `max_distance` (m), of
    /// every body: [`World::queries`]'s [`Queries::ray_cast`] with no filter.
    pub fn ray_cast(&self, origin: Vec3, dir: Vec3, max_distance: f32) -> Option<RayHit> {
        self.queries()
            .ray_cast(origin, dir, max_distance, &QueryFilter::default())
    }

    /// The scene queries at the bodies' current poses: rays (first hit and all hits), shape
    /// casts, point projection and shape overlap, each with a [`QueryFilter`].
    ///
    /// After [`World::update_queries`], and until the next step, added or removed body or pose set, they run
    /// through the broad phase's tree: a ray among 10,000 colliders costs about what it costs
    /// among 100 (`cargo bench --bench queries`). Otherwise every collider is tested: the same
    /// results, at a cost that grows with the collider count. So call `update_queries` once
    /// after each step when a step is followed by many queries.
    ///
    /// ```
    /// use jostle::{BodyDesc, QueryFilter, ShapeDesc, Vec3, World, WorldSettings};
    ///
    /// let mut world = World::new(WorldSettings::default());
    /// world.add_body(BodyDesc::fixed("ground", ShapeDesc::HalfSpace { normal: Vec3::Y })).unwrap();
    /// let player = world
    ///     .add_body(BodyDesc::dynamic("player", ShapeDesc::Ball { radius: 0.5 }).at(Vec3::new(0.0, 3.0, 0.0)))
    ///     .unwrap();
    /// world.update_queries();
    /// // How far below the player is the ground? Its own collider is skipped.
    /// let down = world
    ///     .queries()
    ///     .ray_cast(Vec3::new(0.0, 3.0, 0.0), -Vec3::Y, 10.0, &QueryFilter::excluding(player))
    ///     .unwrap();
    /// assert!((down.distance - 3.0).abs() < 1e-5);
    /// ```
    pub fn queries(&self) -> Queries<'_> {
        if self.query_stamp == self.stamp {
            Queries::with_tree(&self.colliders, &self.bodies, &self.broad)
        } else {
            Queries::brute_force(&self.colliders, &self.bodies)
        }
    }

    /// Brings the broad phase's tree up to the bodies' current poses, so that
    /// [`World::queries`] run through it until the next step, added or removed body or pose set. Costs about
    /// what the broad phase's own pose check costs at the start of a step (one comparison per
    /// collider, a tree update per collider that moved out of its box); changes no result of
    /// any later step (tested).
    pub fn update_queries(&mut self) {
        if self.query_stamp != self.stamp {
            self.broad.refresh(&self.colliders, &self.bodies);
            self.query_stamp = self.stamp;
        }
    }

    /// Whether [`World::queries`] run through the tree now ([`World::update_queries`] was
    /// called since the last step, added or removed body or pose set).
    pub fn queries_use_tree(&self) -> bool {
        self.query_stamp == self.stamp
    }

    /// Advances the world by `dt` seconds: the pipeline of ARCHITECTURE.md ("The step"), each stage timed into
    /// [`World::profile`].
    ///
    /// 1. broad phase — candidate pairs (never static–static, sleeping–sleeping or
    ///    sleeping–static);
    /// 2. narrow phase — persistent manifolds, contacts B→A;
    /// 3. islands and wake-up — a sleeping island touched by an awake body wakes (and, if any
    ///    did, detection runs again so its contacts are in this step);
    /// 4. gather — awake bodies into the dense solver array (forces and damping applied),
    ///    contacts into solver contacts; bodies with non-finite state are quarantined here;
    /// 5. resolve — the resolver resolves contacts and integrates;
    /// 6. ccd — bodies fast for their size are swept from their start pose to their new one
    ///    against resting geometry and, on a hit, moved back to the time of impact;
    /// 7. scatter — results back to the bodies, impulses back to the manifolds, quarantine;
    /// 8. sleep — motion averages, islands, resting islands go to sleep.
    ///
    /// A step after a rest step (nothing awake or moving, no candidate pair, nothing woken)
    /// with no change to the world since (any `&mut self` method but this one and
    /// [`World::update_queries`] counts as a change) would repeat it stage by stage: it only
    /// advances the clock, reports no events and profiles no stage time.
    pub fn step(&mut self, dt: f32) -> Result<StepReport, StepError> {
        if !(dt.is_finite() && dt > 0.0 && dt <= crate::MAX_DT) {
            return Err(StepError::InvalidDt(dt));
        }
        let start = Stopwatch::start();
        if self.settled {
            // Nothing is awake or moving and nothing changed since the last step, which found
            // nothing to do: this one would find the same. Only the clock moves on.
            self.narrow.clear_events();
            self.profile = StepProfile {
                awake_bodies: self.profile.awake_bodies,
                sleeping_bodies: self.profile.sleeping_bodies,
                islands_count: self.profile.islands_count,
                total: start.elapsed(),
                ..StepProfile::default()
            };
            self.time += dt as f64;
            self.steps += 1;
            self.stamp += 1;
            return Ok(StepReport::default());
        }
        let mut p = StepProfile::default();
        let mut report = StepReport::default();
        if self.paths {
            let end = self.time + f64::from(dt);
            for (_, body) in self.bodies.iter_mut() {
                body.follow_path_over(self.time, end);
            }
        }

        self.detect(&mut p, dt);

        let t = Stopwatch::start();
        let woke = stages::wake_touching(
            &mut self.bodies,
            &mut self.islands,
            self.narrow.contacts(),
            &self.settings.sleep,
        );
        p.islands += t.elapsed();
        if woke {
            // Again with the bodies that woke; the first update's events are kept (the
            // second sees its touching pairs as old ones).
            let events = self.narrow.take_events();
            self.detect(&mut p, dt);
            self.narrow.restore_events(events);
        }

        let t = Stopwatch::start();
        stages::gather(
            &mut self.bodies,
            &self.colliders,
            self.narrow.contacts(),
            dt,
            self.settings.gravity,
            &mut self.scratch,
            &mut report,
        );
        stages::report_mass_ratios(
            self.narrow.contacts(),
            &self.scratch,
            self.resolver.max_mass_ratio(),
            &mut report,
        );
        p.gather = t.elapsed();

        let t = Stopwatch::start();
        let ctx = StepContext {
            gravity: self.settings.gravity,
            dt,
        };
        p.resolve_stats =
            self.resolver
                .step(&mut self.scratch.bodies, &mut self.scratch.contacts, &ctx);
        p.resolve = t.elapsed();

        let t = Stopwatch::start();
        stages::ccd(
            &self.bodies,
            &self.colliders,
            &self.broad,
            &self.settings.collide.ccd,
            dt,
            &mut self.scratch,
            &mut p,
        );
        p.ccd = t.elapsed();

        let t = Stopwatch::start();
        stages::scatter(
            &mut self.bodies,
            &mut self.narrow,
            &mut self.scratch,
            &mut report,
            dt,
        );
        self.narrow.find_force_events(&self.colliders, dt);
        p.scatter = t.elapsed();

        let t = Stopwatch::start();
        stages::sleep(
            &mut self.bodies,
            &mut self.islands,
            self.narrow.contacts(),
            &self.settings.sleep,
            dt,
            &mut self.scratch,
            &mut p,
        );
        p.sleep = t.elapsed();

        p.contact_points = self.scratch.contacts.len();
        // A rest step: no candidate pair, nothing woke, no body in the solve (the static
        // entry only) and no kinematic target or quarantine; the next one, if nothing changes
        // the world meanwhile, would repeat it.
        self.settled = p.candidate_pairs == 0
            && !woke
            && self.scratch.bodies.len() <= 1
            && self.scratch.kinematic_targets.is_empty()
            && report.quarantined.is_empty()
            && p.awake_bodies == 0
            && !self.paths;
        p.total = start.elapsed();
        self.profile = p;
        self.time += dt as f64;
        self.steps += 1;
        self.stamp += 1;
        Ok(report)
    }

    /// Broad and narrow phase ahead of a step of `dt`, accumulated into the profile; fast
    /// pairs get speculative contacts as far as they can close within the step
    /// ([`NarrowPhase::update_swept`]).
    fn detect(&mut self, p: &mut StepProfile, dt: f32) {
        // Speculative contacts ahead of fast bodies are part of continuous collision.
        let dt = if self.settings.collide.ccd.enabled {
            dt
        } else {
            0.0
        };
        let t = Stopwatch::start();
        let pairs = self.broad.update_swept(
            &self.colliders,
            &self.bodies,
            self.settings.collide.prediction,
            dt,
        );
        p.broad_phase += t.elapsed();
        p.candidate_pairs = pairs.len();
        let t = Stopwatch::start();
        self.scratch
            .narrow_runner
            .follow(self.profile.resolve_stats.threads);
        let stats = self.narrow.update_with(
            pairs,
            &self.colliders,
            &self.bodies,
            &self.settings.collide,
            self.pair_filter.as_deref(),
            dt,
            &self.scratch.narrow_runner,
        );
        p.narrow_phase += t.elapsed();
        p.manifolds = stats.manifolds;
        p.manifolds_reused = stats.manifolds_reused;
        p.pairs_kept_apart = stats.kept_apart;
        p.narrow_parts = stats.parts;
    }
}
