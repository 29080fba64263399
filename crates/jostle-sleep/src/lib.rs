//! jostle-sleep groups bodies into islands and puts resting islands to sleep.
//!
//! In: the body set and the pairs of bodies that touch this step. Out: island ids, bodies put
//! to sleep (velocities zeroed, `awake = false`) and woken. The rules are the seed lecture's
//! ("Sleep") as the engine fixes them: a recency-weighted motion average per body, a threshold,
//! islands that sleep as a unit, and wake-ups that wake a whole sleeping island. It depends on
//! `jostle-body` and `jostle-math` only: no shapes, no contacts beyond body pairs.
#![deny(missing_docs)]

pub mod islands;
pub mod motion;
pub mod settings;

pub use islands::{IslandSet, UnionFind};
pub use motion::update_motion;
pub use settings::SleepSettings;
