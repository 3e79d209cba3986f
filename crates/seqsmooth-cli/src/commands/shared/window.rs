//! The error of a sliding fit's window (`seqsmooth fit`, and `seqsmooth track`'s start-up
//! fit), with the file lines of the rows it is about.

use crate::args::FitModel;
use crate::error::CliError;
use seqsmooth::Error;
use std::collections::VecDeque;

/// A window's error with the file lines of its rows (or of the one row it is about).
pub(crate) fn window_error(
    e: Error,
    lines: &VecDeque<u64>,
    window: usize,
    model: FitModel,
) -> CliError {
    let (first, last) = (
        lines.front().copied().unwrap_or(0),
        lines.back().copied().unwrap_or(0),
    );
    match e {
        Error::InBatch { index, source } => {
            let line = lines.get(index).copied().unwrap_or(last);
            CliError::Data(format!("line {line}: {source}"))
        }
        Error::Unobservable { .. } | Error::TooFewSamples { .. } => CliError::Data(format!(
            "lines {first}-{last}: the window of {} rows does not determine the state: {e}{}",
            lines.len().min(window),
            if model == FitModel::Radar {
                " (a radar window needs at least as many measured components as states, and \
                 its first fit two rows with range, azimuth and elevation)"
            } else {
                ""
            }
        )),
        e @ (Error::NotConverged { .. } | Error::Diverged { .. }) => CliError::Data(format!(
            "lines {first}-{last} (the window): {e} (with this command: --max-iterations N \
             allows more iterations, a shorter --window W fits fewer rows)"
        )),
        e => CliError::Data(format!("lines {first}-{last} (the window): {e}")),
    }
}
