//! The command's outputs: a CSV file written whole to a temporary file and renamed onto its
//! name when complete (or standard output, or a device written in place), and the [`Table`] an
//! output in another format (Parquet) takes the CSV rows through.

use super::{csv_field, csv_only, is_parquet, named};
use crate::error::CliError;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Rows written in another format than CSV text (a Parquet file): given the rows as the CSV
/// output would hold them, whole rows (and the header first) at a time.
pub trait Table {
    /// Takes whole CSV rows (`\n`-terminated; the first call's first row is the header).
    fn write_rows(&mut self, csv: &[u8]) -> Result<(), CliError>;

    /// Writes what is still buffered and the file's end; the file is complete after it.
    fn close(self: Box<Self>) -> Result<(), CliError>;
}

/// Where an [`Output`]'s bytes go.
enum Sink {
    /// CSV text, buffered.
    Text(Box<dyn Write>),
    /// A table that takes whole CSV rows ([`Output::table`]); `None` once closed.
    Table(Option<Box<dyn Table>>),
}

/// An output: a buffered file or buffered standard output, with its name for messages.
pub struct Output {
    sink: Sink,
    /// `'path'` or `standard output`.
    pub name: String,
    /// For a file: the temporary file beside it and the file it becomes at [`Output::finish`].
    file: Option<(tempfile::TempPath, PathBuf)>,
}

impl Output {
    /// Creates the output file `path` (standard output for `None` or `-`). The rows go to a
    /// temporary file in the same directory, renamed onto `path` by [`Output::finish`]: until
    /// then an existing `path` is untouched, and if the command fails (the `Output` is dropped
    /// unfinished) the temporary file is removed. Standard output streams: what was written
    /// stays written (flushed when dropped). So does a `path` that is not a regular file (a
    /// device such as `/dev/null`, a named pipe): it is written in place ([`Destination`]).
    /// A `.parquet` path is refused: this output is CSV text (`filter` writes Parquet through
    /// [`Output::table`]).
    pub fn create(path: Option<&Path>) -> Result<Self, CliError> {
        match named(path) {
            Some(p) if is_parquet(Some(p)) => Err(csv_only(p)),
            Some(p) => {
                let (file, name, rename) = Self::open(p)?;
                Ok(Self {
                    sink: Sink::Text(Box::new(BufWriter::new(file))),
                    name,
                    file: rename,
                })
            }
            None => Ok(Self::stdout()),
        }
    }

    /// Creates the output file `path` as [`Output::create`] does (a temporary file beside it,
    /// renamed onto it by [`Output::finish`]), written by the [`Table`] that `make` returns for
    /// the open file and its name for messages (`'path'`).
    pub fn table(
        path: &Path,
        make: impl FnOnce(File, &str) -> Result<Box<dyn Table>, CliError>,
    ) -> Result<Self, CliError> {
        let (file, name, rename) = Self::open(path)?;
        let table = make(file, &name)?;
        Ok(Self {
            sink: Sink::Table(Some(table)),
            name,
            file: rename,
        })
    }

    /// Opens the file an output named `path` is written to: the file itself when written in
    /// place, else a temporary file beside it (with the temporary path and the target to
    /// rename it onto); and its name for messages.
    #[allow(clippy::type_complexity)]
    fn open(
        path: &Path,
    ) -> Result<(File, String, Option<(tempfile::TempPath, PathBuf)>), CliError> {
        let name = format!("'{}'", path.display());
        let fail = |e: io::Error| CliError::Data(format!("cannot create output file {name}: {e}"));
        match Destination::of(path) {
            Destination::InPlace(target) => {
                let file = std::fs::OpenOptions::new()
                    .write(true)
                    .open(target)
                    .map_err(fail)?;
                Ok((file, name, None))
            }
            Destination::Replace(target) => {
                let (file, temp) = temp_beside(&target, "").map_err(fail)?.into_parts();
                Ok((file, name, Some((temp, target))))
            }
        }
    }

    /// Buffered standard output.
    pub fn stdout() -> Self {
        let sink = Sink::Text(Box::new(BufWriter::new(io::stdout().lock())));
        Self {
            sink,
            name: "standard output".to_string(),
            file: None,
        }
    }

    /// Writes `bytes` of CSV text (for a [`Table`] output: whole rows).
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), CliError> {
        match &mut self.sink {
            Sink::Text(sink) => sink
                .write_all(bytes)
                .map_err(|e| CliError::write(&self.name, e)),
            Sink::Table(Some(table)) => table.write_rows(bytes),
            Sink::Table(None) => Err(CliError::Data(format!(
                "internal error: {} is closed",
                self.name
            ))),
        }
    }

    /// Writes a CSV row of `cells` (each quoted where needed).
    pub fn row<S: AsRef<str>>(&mut self, cells: &[S]) -> Result<(), CliError> {
        let fields: Vec<Vec<u8>> = cells
            .iter()
            .map(|c| csv_field(c.as_ref().as_bytes()))
            .collect();
        let mut line = fields.join(&b","[..]);
        line.push(b'\n');
        self.write(&line)
    }

    /// Writes rows of cells right-aligned in columns two spaces apart (`left` columns first,
    /// left-aligned).
    pub fn aligned(&mut self, rows: &[Vec<String>], left: usize) -> Result<(), CliError> {
        let cols = rows.iter().map(Vec::len).max().unwrap_or(0);
        let width = |c: usize| {
            rows.iter()
                .filter_map(move |r| r.get(c))
                .map(|s| s.chars().count())
        };
        let widths: Vec<usize> = (0..cols).map(|c| width(c).max().unwrap_or(0)).collect();
        for r in rows {
            let cells: Vec<String> = r
                .iter()
                .zip(&widths)
                .enumerate()
                .map(|(c, (s, &w))| {
                    if c < left {
                        format!("{s:<w$}")
                    } else {
                        format!("{s:>w$}")
                    }
                })
                .collect();
            self.write(format!("{}\n", cells.join("  ").trim_end()).as_bytes())?;
        }
        Ok(())
    }

    /// Flushes everything to the sink; for a file, renames the temporary file onto it.
    pub fn finish(mut self) -> Result<(), CliError> {
        match &mut self.sink {
            Sink::Text(sink) => sink.flush().map_err(|e| CliError::write(&self.name, e))?,
            Sink::Table(table) => {
                if let Some(table) = table.take() {
                    table.close()?;
                }
            }
        }
        // Close the file before it is renamed.
        self.sink = Sink::Text(Box::new(io::sink()));
        match self.file.take() {
            Some((temp, path)) => temp
                .persist(&path)
                .map_err(|e| CliError::write(&self.name, e.error)),
            None => Ok(()),
        }
    }
}

/// How an output file named by the user is written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Destination {
    /// A regular file, or a new one: written whole to a temporary file beside it and renamed
    /// onto it when complete. The path is the file itself, through any symbolic link, so that
    /// the link stays a link and the file it names gets the rows.
    Replace(PathBuf),
    /// An existing file that is not a regular one (a device such as `/dev/null`, a named
    /// pipe): written in place, as it goes, since a rename would put a regular file where the
    /// device was.
    InPlace(PathBuf),
}

impl Destination {
    /// Where the output `path` goes.
    ///
    /// ```
    /// use seqsmooth_cli::io::Destination;
    /// use std::path::Path;
    /// let null = Path::new("/dev/null");
    /// assert_eq!(Destination::of(null), Destination::InPlace(null.to_path_buf()));
    /// let new = Path::new("no-such-dir/out.csv");
    /// assert_eq!(Destination::of(new), Destination::Replace(new.to_path_buf()));
    /// ```
    pub fn of(path: &Path) -> Self {
        match std::fs::metadata(path) {
            // Follows symbolic links: what the path names in the end.
            Ok(meta) if !meta.is_file() && !meta.is_dir() => Self::InPlace(path.to_path_buf()),
            Ok(_) => Self::Replace(path.canonicalize().unwrap_or_else(|_| path.to_path_buf())),
            // New, or a symbolic link to a file not there yet: the file it names.
            Err(_) => Self::Replace(match std::fs::read_link(path) {
                Ok(target) => path.parent().unwrap_or(Path::new("")).join(target),
                Err(_) => path.to_path_buf(),
            }),
        }
    }
}

/// A new temporary file in the directory of `path`, named after it and ending in `suffix`,
/// with the permissions `path` has (a new file's default, `0o666` less the umask, if it does
/// not exist yet): what [`Output`] and the plots write before renaming it onto `path`.
pub fn temp_beside(path: &Path, suffix: &str) -> io::Result<tempfile::NamedTempFile> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let stem = path
        .file_name()
        .map_or("out".into(), |n| n.to_string_lossy());
    let prefix = format!(".{stem}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(suffix);
    #[cfg(unix)]
    let permissions = {
        use std::os::unix::fs::PermissionsExt;
        std::fs::metadata(path).map_or(std::fs::Permissions::from_mode(0o666), |m| m.permissions())
    };
    #[cfg(unix)]
    builder.permissions(permissions);
    builder.tempfile_in(dir).map_err(|e| {
        // The message names the file asked for, not the hidden temporary one: drop the
        // crate's "at path ..." suffix.
        let text = e.to_string();
        let own = text
            .split(" at path \"")
            .next()
            .unwrap_or(&text)
            .to_string();
        io::Error::new(e.kind(), own)
    })
}

/// Refuses an output file that is the input file.
pub fn check_distinct(input: Option<&Path>, output: Option<&Path>) -> Result<(), CliError> {
    if let (Some(i), Some(o)) = (input, output) {
        // Creating the output would truncate the input while it is still being read.
        if let (Ok(a), Ok(b)) = (i.canonicalize(), o.canonicalize()) {
            if a == b {
                return Err(CliError::Usage(format!(
                    "the output file '{}' is the input file; write to another file",
                    o.display()
                )));
            }
        }
    }
    Ok(())
}
