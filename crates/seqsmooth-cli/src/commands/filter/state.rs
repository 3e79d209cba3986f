//! `--state FILE`: the saved state of `seqsmooth filter` (the library's
//! [`seqsmooth::persist::stream::StreamState`] in its checked envelope), read at the start if
//! the file exists and written at the end of a run that succeeds, atomically: a new file in
//! the same directory, flushed to disk, then renamed over the old one, so that the file holds
//! either the old state or the new one, never part of either.

use crate::error::CliError;
use seqsmooth::persist::stream::StreamState;
use seqsmooth::persist::{from_bytes, to_bytes};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The state saved in `path`, `None` if there is no such file; a damaged one is refused
/// (the library's `DamagedState`), naming the file.
pub fn read(path: &Path) -> Result<Option<StreamState>, CliError> {
    let bytes = match std::fs::read(path) {
        Ok(bytes) => bytes,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => {
            return Err(CliError::Data(format!(
                "cannot read the state file {}: {e}",
                path.display()
            )))
        }
    };
    let state = from_bytes::<StreamState>(&bytes)
        .map_err(|e| CliError::from(e).reworded(|m| in_file(path, &m)))?;
    Ok(Some(state))
}

/// A message about the state file `path`.
pub fn in_file(path: &Path, message: &str) -> String {
    format!("state file {}: {message}", path.display())
}

/// Writes `state` to `path` atomically (see the module doc).
pub fn write(path: &Path, state: &StreamState) -> Result<(), CliError> {
    let bytes = to_bytes(state).map_err(|e| CliError::from(e).reworded(|m| in_file(path, &m)))?;
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".tmp{}", std::process::id()));
    let tmp: PathBuf = path.with_file_name(name);
    let failed = |e: std::io::Error| {
        let _ = std::fs::remove_file(&tmp);
        CliError::Data(in_file(path, &format!("cannot write it: {e}")))
    };
    let mut file = std::fs::File::create(&tmp).map_err(failed)?;
    file.write_all(&bytes).map_err(failed)?;
    file.sync_all().map_err(failed)?;
    drop(file);
    std::fs::rename(&tmp, path).map_err(failed)
}
