//! The arguments of `seqsmooth plot`.

use super::{parse_derivative, parse_lead};
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct PlotArgs {
    /// The output of 'seqsmooth filter' (CSV with header t,y,d0..dM[,s0..sM][,...]); omitted
    /// or '-' reads standard input
    // The brackets are --help text, not links.
    #[allow(rustdoc::broken_intra_doc_links)]
    #[arg(value_name = "FILTER_OUTPUT")]
    pub source: Option<PathBuf>,
    /// Image file to write, PNG or SVG by its extension (.png, .svg); repeat for both
    #[arg(short = 'o', long, value_name = "IMAGE", required = true)]
    pub output: Vec<PathBuf>,
    /// Derivative to plot, one panel each, in the order given (0 the value, 1 the rate, ...);
    /// repeat for several
    #[arg(long, value_name = "K", default_value = "0", value_parser = parse_derivative,
          allow_hyphen_values = true)]
    pub derivative: Vec<usize>,
    /// Leave out the residual panel
    #[arg(long)]
    pub no_residuals: bool,
    /// Title [default: the filter kind and the file name]
    #[arg(long, value_name = "TEXT")]
    pub title: Option<String>,
    /// Image width in pixels
    #[arg(long, value_name = "PX", default_value_t = 1200,
          value_parser = clap::value_parser!(u32).range(300..=10000))]
    pub width: u32,
    /// Image height in pixels [default: 330 per derivative panel, 250 for the residuals, 120
    /// for the title and legend]
    #[arg(long, value_name = "PX", value_parser = clap::value_parser!(u32).range(300..=10000))]
    pub height: Option<u32>,
    /// Unit of the times, for the axis labels (e.g. s)
    #[arg(long, value_name = "UNIT")]
    pub time_unit: Option<String>,
    /// Unit of the values, for the axis labels (e.g. m)
    #[arg(long, value_name = "UNIT")]
    pub value_unit: Option<String>,
    /// The --lead H the output was made with, for an output without a lead column (one with
    /// it must agree): the estimates are drawn at t+H and compared with the samples at t+H
    #[arg(long, value_name = "H", default_value = "0", value_parser = parse_lead,
          allow_hyphen_values = true)]
    pub lead: f64,
    /// The filter's input file, to draw its truth column (--truth-col)
    #[arg(long, value_name = "FILE")]
    pub input: Option<PathBuf>,
    /// Name of the input's time column
    #[arg(long, value_name = "NAME", default_value = "t")]
    pub time_col: String,
    /// Name of the input's value column
    #[arg(long, value_name = "NAME", default_value = "y")]
    pub value_col: String,
    /// Column of the input holding the true values, drawn as a line (needs --input)
    #[arg(long, value_name = "NAME", requires = "input")]
    pub truth_col: Option<String>,
}
