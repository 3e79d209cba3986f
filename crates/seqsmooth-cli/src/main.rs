//! The `seqsmooth` command: polynomial smoothing and prediction filters (Morrison 1969;
//! Reyneke et al. 2012) on CSV time series — expanding, fading and fixed memory, the automatic
//! filter, and whole-series (Savitzky–Golay) smoothing — their gains and variance-reduction
//! matrices, and a demo on built-in data. A thin layer over the `seqsmooth` library: argument
//! parsing ([`args`]), files ([`io`]), one module per subcommand, and messages ([`error`]).

mod args;
mod chart;
mod demo;
mod error;
mod filter;
mod gains;
mod io;
mod plot;
mod progress;
mod smooth;
mod vrf;

use args::{Cli, Command};
use clap::Parser;
use error::CliError;
use std::process::ExitCode;

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Command::Filter(a) => filter::run(&a),
        Command::Smooth(a) => smooth::run(&a),
        Command::Gains(a) => gains::run(&a),
        Command::Vrf(a) => vrf::run(&a),
        Command::Demo(a) => demo::run(&a),
        Command::Plot(a) => plot::run(&a),
    };
    match result {
        Ok(()) | Err(CliError::BrokenPipe) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            if matches!(e, CliError::Usage(_)) {
                eprintln!("\nFor more information, try '--help'.");
            }
            ExitCode::from(e.exit_code())
        }
    }
}
