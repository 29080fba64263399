//! The harness the `jostle` command is built on: the run loop with its trace and summary
//! ([`run`]) and the benchmark measurements ([`bench`](mod@bench)). It lives here, not in the engine
//! library, so a game that depends on `jostle` carries no benchmark code.

pub mod bench;
pub mod run;
