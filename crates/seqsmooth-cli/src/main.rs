//! The `seqsmooth` command's entry point: parses the command line and runs the subcommand
//! (the work is in the `seqsmooth_cli` library).

use clap::Parser;
use seqsmooth_cli::args::{Cli, Command};
use seqsmooth_cli::commands::{demo, filter, fit, gains, paml, plot, smooth, track, vrf};
use seqsmooth_cli::error::CliError;
use std::process::ExitCode;

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Command::Filter(a) => filter::run(&a),
        Command::Smooth(a) => smooth::run(&a),
        Command::Gains(a) => gains::run(&a),
        Command::Vrf(a) => vrf::run(&a),
        Command::Demo(a) => demo::run(&a),
        Command::Plot(a) => plot::run(&a),
        Command::Fit(a) => fit::run(&a),
        Command::Track(a) => track::run(&a),
        Command::Paml(a) => paml::run(&a),
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
