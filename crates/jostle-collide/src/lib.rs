//! jostle-collide finds where bodies touch: colliders (parry shapes with a material, attached
//! to bodies), the broad phase, the persistent narrow phase and scene queries.
//!
//! In: a [`ColliderSet`] and the `BodySet` whose poses (centre of mass, orientation) and sleep
//! states it reads. Out: candidate [`ColliderPair`]s, [`BodyContact`]s in jostle's convention
//! (normal from body B toward body A, penetration positive on overlap, at most four points per
//! manifold, warm-start impulses carried by feature id), touching [`CollisionEvent`]s, ray and
//! overlap queries, mass properties of shape descriptions, and display meshes of colliders.
//! It is the only jostle crate that names parry types (re-exported as [`parry3d`]); it depends
//! on `jostle-math` and `jostle-body` and knows nothing of the resolver or of sleep islands.
//!
//! Per step: [`BroadPhase::update`] → [`NarrowPhase::update`] → (resolver) → [`ccd::sweep`]
//! for fast bodies → [`NarrowPhase::store_impulses`].
#![deny(missing_docs)]

pub mod broad_phase;
pub mod ccd;
pub mod collider;
pub mod display;
pub mod groups;
pub mod mass;
pub mod material;
mod mesh_patch;
pub mod narrow_phase;
mod polytope;
pub mod query;
pub mod reduce;
pub mod settings;
pub mod shape;

pub use broad_phase::{BroadPhase, ColliderPair};
pub use ccd::{CcdHit, CcdShape, sweep};
pub use collider::{Collider, ColliderHandle, ColliderSet, body_pose};
pub use display::DisplayMesh;
pub use groups::CollisionGroups;
pub use mass::{MassProps, mass_properties};
pub use material::{Combine, Material};
pub use narrow_phase::{
    BodyContact, CollisionEvent, ContactForceEvent, MAX_PARTS, NarrowPhase, NarrowStats, OneThread,
    PairFilter, Runner, SensorEvent, run_parts,
};
pub use parry3d;
pub use parry3d::math::Pose;
pub use parry3d::shape::SharedShape;
pub use query::{PointHit, Queries, QueryFilter, RayHit, ShapeHit, intersect_shape, ray_cast};
pub use settings::{CcdSettings, CollideSettings};
pub use shape::{CompoundPart, ShapeDesc, ShapeError};
