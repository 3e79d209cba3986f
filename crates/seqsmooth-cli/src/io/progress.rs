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

/// A progress bar or spinner, or a hidden one.
pub struct Progress {
    bar: ProgressBar,
    start: Instant,
}

impl Progress {
    pub fn hidden() -> Self {
        Self {
            bar: ProgressBar::hidden(),
            start: Instant::now(),
        }
    }

    /// A bar of `total` bytes (a file of known size) or a spinner counting rows; rates are
    /// counted from `start`.
    pub fn new(total: Option<u64>, start: Instant) -> Self {
        let template = match total {
            Some(_) => "{bytes}/{total_bytes} [{wide_bar}] {percent}%  {msg}  eta {eta}",
            None => "{spinner} {msg}",
        };
        let style = ProgressStyle::with_template(template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        let bar = ProgressBar::with_draw_target(total, ProgressDrawTarget::stderr());
        Self {
            bar: bar.with_style(style),
            start,
        }
    }

    /// Reports `bytes` read and `rows` done.
    pub fn update(&self, bytes: u64, rows: u64) {
        if self.bar.is_hidden() {
            return;
        }
        let secs = self.start.elapsed().as_secs_f64().max(1e-3);
        self.bar.set_message(format!(
            "{} rows, {} rows/s",
            HumanCount(rows),
            HumanCount((rows as f64 / secs) as u64)
        ));
        if self.bar.length().is_some() {
            self.bar.set_position(bytes);
        } else {
            self.bar.tick();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
