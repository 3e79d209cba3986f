//! A filter saved and resumed, bit for bit: the one saved form of every filter a user holds
//! (the Python package's `pickle`, `copy` and `deepcopy`, and any program that keeps a
//! filter's state between runs).
//!
//! The saved form is an envelope around the filter's serde form:
//!
//! | bytes | what |
//! |---|---|
//! | 8 | the magic tag `SEQSMST\0` |
//! | 2 | the format version, little-endian ([`FORMAT_VERSION`]) |
//! | 1 + k | the type's name ([`Persist::name`]), its length then its UTF-8 bytes |
//! | 8 | the body's length, little-endian |
//! | 4 | the CRC-32 (IEEE) of everything before it and the body, little-endian |
//! | … | the body: the filter in CBOR (RFC 8949), every `f64` its exact bits |
//!
//! [`from_bytes`] refuses, as [`Error::DamagedState`] naming what is wrong, an input that is
//! truncated, has a byte changed (the checksum), is another type's, or is of a newer format;
//! then, after decoding, the type's invariants ([`Persist::check`]: dimensions agree, numbers
//! finite where the filter needs them so, covariances symmetric and positive semi-definite),
//! so that a body crafted with a valid checksum cannot make a later call panic.
//!
//! A restored filter runs on with what it was saved with: its settings and its parts as they
//! were. Where a later version changed how a new filter is built, a saved state keeps the old
//! construction: an [`AutomaticFilter`](crate::polynomial::automatic::AutomaticFilter) restored
//! from a state saved before 2026-12-07 keeps the memories it was saved with (the adaptive
//! memory's ladder `θ², θ⁴, θ⁸` of then, not today's `θ⁴`; see
//! [`AutoConfig::memory_levels`](crate::polynomial::automatic::AutoConfig::memory_levels)), while
//! a new filter gets today's; a state saved with a setting since out of range (such as
//! `memory_levels` 9 to 16) is refused as damaged, naming it.
//!
//! ```
//! use seqsmooth::persist::{from_bytes, to_bytes};
//! use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
//! let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Exact).unwrap();
//! f.update(0.0, 1.0).unwrap();
//! f.update(1.5, 2.0).unwrap();
//! let bytes = to_bytes(&f).unwrap();
//! let mut g: FadingMemory = from_bytes(&bytes).unwrap();
//! f.update(2.0, 2.5).unwrap();
//! g.update(2.0, 2.5).unwrap();
//! assert_eq!(f.estimate().unwrap(), g.estimate().unwrap()); // bit for bit
//! assert!(from_bytes::<FadingMemory>(&bytes[..bytes.len() - 1]).is_err());
//! ```

use crate::error::Error;
use serde::de::DeserializeOwned;
use serde::Serialize;

mod impls;
mod left_out;
pub mod stream;

pub use impls::{Beside, SavedModel};
pub use left_out::{DynamicsLeftOut, ObservationLeftOut};

/// The envelope's magic tag.
pub const MAGIC: [u8; 8] = *b"SEQSMST\0";

/// The version of the saved form this library writes; a saved state of a later version is
/// refused, every earlier one read.
///
/// - 1: the first.
/// - 2 (2026-12-07): an automatic filter's shorter memory may hold its degree-`m` filter behind
///   its companion's samples, brought up to them from the companion's leading block when the
///   memory is compared or used; a reader of version 1 would take the lagging filter as
///   current, so it refuses these states instead. Version 1's states read as before (their
///   filters never lag).
pub const FORMAT_VERSION: u16 = 2;

/// A type with a saved form: its name in the envelope and the invariants a decoded value must
/// hold before it is handed out.
pub trait Persist: Serialize + DeserializeOwned {
    /// The type's name (with its models' names), written in the envelope and checked on
    /// reading.
    fn name() -> String;

    /// The invariants of a decoded value (dimensions, finite numbers, covariances): why it
    /// cannot be used, or nothing. It may rebuild the value's scratch buffers.
    fn check(&mut self) -> Result<(), String>;
}

fn damaged(reason: impl Into<String>) -> Error {
    Error::DamagedState {
        reason: reason.into(),
    }
}

/// The saved form of `value`: the envelope above around its CBOR body.
///
/// Refused (as [`Error::DamagedState`]) only for a filter holding a part that has no saved
/// form (a process-noise model of the caller's own type).
pub fn to_bytes<T: Persist>(value: &T) -> Result<Vec<u8>, Error> {
    let mut body = Vec::new();
    ciborium::into_writer(value, &mut body).map_err(|e| damaged(format!("cannot save: {e}")))?;
    let name = T::name();
    let name = &name.as_bytes()[..name.len().min(255)];
    let mut out = Vec::with_capacity(body.len() + name.len() + 32);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.push(name.len() as u8);
    out.extend_from_slice(name);
    out.extend_from_slice(&(body.len() as u64).to_le_bytes());
    let mut crc = crc32fast::Hasher::new();
    crc.update(&out);
    crc.update(&body);
    out.extend_from_slice(&crc.finalize().to_le_bytes());
    out.extend_from_slice(&body);
    Ok(out)
}

/// Reads `n` bytes at `*at`, naming `what` if they are not there.
fn take<'a>(bytes: &'a [u8], at: &mut usize, n: usize, what: &str) -> Result<&'a [u8], Error> {
    let end = at.checked_add(n).filter(|&e| e <= bytes.len());
    let Some(end) = end else {
        return Err(damaged(format!(
            "truncated: {} bytes, ended in the {what}",
            bytes.len()
        )));
    };
    let s = &bytes[*at..end];
    *at = end;
    Ok(s)
}

/// The value [`to_bytes`] saved, checked: the envelope (tag, version, type, length, checksum),
/// then the body, then [`Persist::check`]. Every refusal is [`Error::DamagedState`].
pub fn from_bytes<T: Persist>(bytes: &[u8]) -> Result<T, Error> {
    let mut at = 0;
    if take(bytes, &mut at, MAGIC.len(), "tag")? != MAGIC {
        return Err(damaged("not a seqsmooth saved state (no SEQSMST tag)"));
    }
    let version = u16::from_le_bytes(take(bytes, &mut at, 2, "version")?.try_into().unwrap());
    if version == 0 || version > FORMAT_VERSION {
        return Err(damaged(format!(
            "format version {version}: this library reads versions 1 to {FORMAT_VERSION}"
        )));
    }
    let len = take(bytes, &mut at, 1, "type name")?[0] as usize;
    let name = take(bytes, &mut at, len, "type name")?;
    let want = T::name();
    if name != &want.as_bytes()[..want.len().min(255)] {
        return Err(damaged(format!(
            "the state of a {}, not of a {want}",
            String::from_utf8_lossy(name),
        )));
    }
    let body_len = u64::from_le_bytes(take(bytes, &mut at, 8, "length")?.try_into().unwrap());
    let header = at;
    let stored = u32::from_le_bytes(take(bytes, &mut at, 4, "checksum")?.try_into().unwrap());
    let rest = bytes.len() - at;
    if body_len != rest as u64 {
        return Err(damaged(format!(
            "{}: the body is {body_len} bytes, {rest} given",
            if (rest as u64) < body_len {
                "truncated"
            } else {
                "trailing bytes"
            }
        )));
    }
    let body = &bytes[at..];
    let mut crc = crc32fast::Hasher::new();
    crc.update(&bytes[..header]);
    crc.update(body);
    if crc.finalize() != stored {
        return Err(damaged("checksum mismatch: a byte has changed"));
    }
    let mut value: T = ciborium::from_reader(body)
        .map_err(|e| damaged(format!("cannot decode the {want}: {e}")))?;
    value
        .check()
        .map_err(|why| damaged(format!("the {want}'s {why}")))?;
    Ok(value)
}
