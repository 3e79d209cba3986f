//! The progress display of `seqsmooth filter` on standard error.
//!
//! Shown only when standard error is a terminal and `--no-progress` is not given, and only
//! once the input turns out larger than one chunk of rows, so a small input never flashes a
//! bar. A file input shows the bytes read of the file's size; standard input a spinner with
//! the rows read and their rate. It is updated once per chunk (tens of thousands of rows), so
//! it costs nothing measurable, and it is cleared when the command ends.

use indicatif::{HumanCount, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::Instant;

/// Whether a progress display may be shown: stderr is a terminal and it is not turned off.
pub fn wanted(no_progress: bool) -> bool {
    !no_progress && std::io::stderr().is_terminal()
}

/// A progress bar or spinner, or nothing.
pub struct Progress {
    bar: Option<ProgressBar>,
    start: Instant,
}

impl Progress {
    /// No display.
    pub fn hidden() -> Self {
        Self {
            bar: None,
            start: Instant::now(),
        }
    }

    /// A bar of `total` bytes (a file of known size) or a spinner counting rows; rates are
    /// counted from `start`.
    pub fn new(total: Option<u64>, start: Instant) -> Self {
        let (bar, template) = match total {
            Some(len) => (
                ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr()),
                "{bytes}/{total_bytes} [{wide_bar}] {percent}%  {msg}  eta {eta}",
            ),
            None => (
                ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr()),
                "{spinner} {msg}",
            ),
        };
        let style = ProgressStyle::with_template(template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        Self {
            bar: Some(bar.with_style(style)),
            start,
        }
    }

    /// Reports `bytes` read and `rows` done.
    pub fn update(&self, bytes: u64, rows: u64) {
        let Some(bar) = &self.bar else { return };
        let secs = self.start.elapsed().as_secs_f64().max(1e-3);
        bar.set_message(format!(
            "{} rows, {} rows/s",
            HumanCount(rows),
            HumanCount((rows as f64 / secs) as u64)
        ));
        if bar.length().is_some() {
            bar.set_position(bytes);
        } else {
            bar.tick();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
