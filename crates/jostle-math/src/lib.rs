//! jostle-math: the small set of vector, matrix and quaternion operations the rest of jostle
//! shares, on top of the exact glam that parry3d 0.31 uses (0.33, through glamx), re-exported
//! here so that one `Vec3` type runs through the whole tree with zero conversions.
//!
//! In: glam vectors, quaternions and matrices. Out: contact bases, skew matrices, inertia
//! tensors, world-space inverse inertia and the quaternion update of the seed lecture.
//! It depends on glam alone: no parry, no body storage, no physics state.
//!
//! Conventions (ARCHITECTURE.md, "Conventions"): f32, SI units, right-handed, +Y up. Quaternions as glam stores them
//! (x, y, z, w).
#![deny(missing_docs)]

pub mod basis;
pub mod inertia;
pub mod rotation;

pub use basis::{contact_basis, skew};
pub use glam;
pub use glam::{Mat3, Quat, Vec3};
pub use inertia::{InertiaShape, inverse_principal, world_inverse_inertia};
pub use rotation::{advance_orientation, integrate_orientation};
