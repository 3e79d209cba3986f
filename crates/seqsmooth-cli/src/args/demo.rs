//! The arguments of `seqsmooth demo`.

use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Also write the plain fading-memory (exact engine) filter's CSV output
    /// (t,y,d0..d2,s0..s2) here
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Path prefix of the plot: writes PREFIX.png and PREFIX.svg
    #[arg(long, value_name = "PREFIX", default_value = "seqsmooth-demo")]
    pub plot: PathBuf,
    /// Write no plot
    #[arg(long, conflicts_with = "plot")]
    pub no_plot: bool,
}
