//! jostle-body stores the user's rigid bodies: the cold, handle-addressed tier of the engine.
//!
//! In: mass properties, poses, velocities, forces and impulses from the user. Out: bodies that
//! the collision layer reads poses from and that the facade copies into the resolver's dense
//! `SolverBody` array and back. It also holds semi-implicit Euler integration and force
//! application, so that an engine author who swaps the resolver keeps the same integrator.
//! It depends on `jostle-math` only: no shapes, no parry, no contacts.
#![deny(missing_docs)]

pub mod arena;
pub mod body;
pub mod integrate;
pub mod path;
pub mod set;

pub use arena::{Arena, ArenaIndex};
pub use body::{BodyType, CcdMode, MassError, RigidBody, SleepState};
pub use integrate::{apply_forces, integrate_body};
pub use path::KinematicPath;
pub use set::{BodyHandle, BodySet};
