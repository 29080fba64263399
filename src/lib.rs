//! jostle: a 3D rigid-body contact physics engine implementing the contact physics of
//! Millington's *Game Physics Engine Development* (ch. 14–16): impulse collision resolution with
//! rotation, nonlinear-projection interpenetration resolution, resting contacts as
//! micro-collisions, static and dynamic friction through a 3×3 contact-space impulse, and sleep.
//!
//! This is the facade crate. It composes the layers — `jostle-math` (glam), `jostle-body`
//! (rigid bodies), `jostle-collide` (parry3d narrow and broad phase), `jostle-resolve` (the
//! resolvers) and `jostle-sleep` (islands and sleep) — into a [`World`] whose [`World::step`]
//! runs one linear pipeline of timed stages, and loads scenes from RON files ([`scene`]).
//!
//! ```
//! use jostle::{BodyDesc, ShapeDesc, Vec3, World, WorldSettings};
//!
//! let mut world = World::new(WorldSettings::default());
//! world.add_body(BodyDesc::fixed("ground", ShapeDesc::HalfSpace { normal: Vec3::Y })).unwrap();
//! let ball = world
//!     .add_body(BodyDesc::dynamic("ball", ShapeDesc::Ball { radius: 0.5 }).at(Vec3::new(0.0, 2.0, 0.0)))
//!     .unwrap();
//! for _ in 0..120 {
//!     world.step(1.0 / 60.0).unwrap();
//! }
//! let y = world.body(ball).unwrap().position.y;
//! assert!((y - 0.5).abs() < 0.02, "the ball rests on the ground, y = {y}");
//! ```
#![deny(missing_docs)]

pub mod body_desc;
pub mod collider_desc;
pub mod profile;
#[cfg(feature = "scene")]
pub mod scene;
pub mod settings;
pub mod snapshot;
mod stages;
mod threads;
pub mod view;
pub mod world;

pub use body_desc::{
    BodyDesc, BodyError, Kinematic, MAX_ANGULAR_SPEED, MAX_CONTACT_MASS_RATIO, MAX_DENSITY, MAX_DT,
    MAX_GRAVITY, MAX_MASS, MAX_POSITION, MAX_REACHED_ANGULAR_SPEED, MAX_SPEED, MassSpec,
};
pub use collider_desc::ColliderDesc;
pub use jostle_body::{BodyHandle, BodyType, CcdMode, KinematicPath, RigidBody};
pub use jostle_collide::{
    BodyContact, CollideSettings, Collider, CollisionEvent, CollisionGroups, Combine,
    ContactForceEvent, DisplayMesh, Material, PairFilter, PointHit, Pose, Queries, QueryFilter,
    RayHit, SensorEvent, ShapeDesc, ShapeHit, SharedShape,
};
pub use jostle_math::{Mat3, Quat, Vec3};
pub use jostle_resolve::millington::{IterationBudget, PickStrategy, Projection};
pub use jostle_resolve::soft_step::team::set_threads;
pub use jostle_resolve::{
    MillingtonResolver, MillingtonSettings, Resolver, SoftStepResolver, SoftStepSettings,
};
pub use profile::StepProfile;
pub use settings::{ResolverChoice, WorldSettings};
pub use view::{BodyView, PlaneView};
pub use world::{StepError, StepReport, World};

/// The engine's layers, re-exported for users who swap or extend one of them.
pub mod layers {
    pub use jostle_body as body;
    pub use jostle_collide as collide;
    pub use jostle_math as math;
    pub use jostle_resolve as resolve;
    pub use jostle_sleep as sleep;
}
