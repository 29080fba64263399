//! jostle-resolve turns solver bodies and contacts into velocity and pose corrections.
//!
//! In: a dense slice of [`SolverBody`] (index 0 is the shared static entry, never written), a
//! slice of [`Contact`] referring to them by index, gravity and the time step. Out: the bodies'
//! new poses and velocities after one step, and the contacts' accumulated impulses (for warm
//! starting the next step). It knows nothing of shapes, parry or body storage, and depends on
//! `jostle-math` alone, so a resolver can be benchmarked on synthetic contacts and swapped
//! without the rest of the engine.
//!
//! Resolvers implement [`Resolver`]; the facade calls the same trait method whatever the
//! resolver, with no special case.
#![deny(missing_docs)]

pub mod clock;
pub mod contact;
mod energy;
pub mod integrate;
pub mod millington;
pub mod resolver;
pub mod soft_step;
pub mod solver_body;
pub mod synthetic;
mod union_find;

pub use contact::Contact;
pub use millington::{MillingtonResolver, MillingtonSettings};
pub use resolver::{ResolveStats, Resolver, StepContext};
pub use soft_step::{SoftStepResolver, SoftStepSettings};
pub use solver_body::{STATIC_BODY, SolverBody};
