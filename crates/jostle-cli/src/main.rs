//! The `jostle` command: runs a scene headless with a progress bar, prints a summary table or
//! one JSON object, can write a per-step CSV trace, and can render the run to a PNG or GIF;
//! `jostle bench` sweeps resolvers and settings over scenes and writes cost against error.
//!
//! Scene files and snapshots are the engine's (`jostle::scene`, `jostle::snapshot`); the run
//! loop, the trace format and the benchmark measurements are this crate's [`harness`].

mod bench_cmd;
mod harness;
mod render_out;
mod run_cmd;
mod staged;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// jostle: a 3D rigid-body contact physics engine.
#[derive(Parser, Debug)]
#[command(name = "jostle", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene headless and print a summary.
    Run(run_cmd::RunArgs),
    /// Run scenes under each resolver and sweep setting; write run time against error.
    Bench(bench_cmd::BenchArgs),
}

/// Writes `text` to standard output. A reader that has gone (`jostle run … | head`) is no
/// error: the rest is not wanted (`println!` panicked on the closed pipe).
pub(crate) fn print_out(text: &str) -> Result<(), String> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(format!("standard output: {e}"))
        }
        _ => Ok(()),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => run_cmd::run(args),
        Command::Bench(args) => bench_cmd::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
