//! The arguments of `seqsmooth gains`.

use super::{Format, MemoryArgs, TableKind};
use clap::Args;

#[derive(Debug, Args)]
pub struct GainsArgs {
    /// Filter kind
    #[arg(long, value_enum)]
    pub kind: TableKind,
    #[command(flatten)]
    pub memory: MemoryArgs,
    /// Print exact rationals in lowest terms, p/q (an integer as p), instead of doubles.
    /// Without it θ is rounded to the nearest double before the computation
    #[arg(long)]
    pub exact: bool,
    /// Output format
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
}
