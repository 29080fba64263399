//! jostle side by side with rapier3d 0.36 at its defaults, in one run: the comparison benches
//! (`cargo bench -p jostle-compare --bench vs_rapier`, `--bench stability_family`, `--bench
//! penetration` and `--bench scale`; see
//! each bench's header and the workspace's `benches/RESULTS.md`).
//!
//! The crate holds no code of its own. It exists so that rapier3d is a dependency of these
//! benches only: a user's `cargo test` of the `jostle` crate never builds it. The benches
//! share the scene helpers of the facade's benches (`benches/common`) and the stability
//! family's cases (`tests/common/family.rs`) by path.
#![deny(missing_docs)]
