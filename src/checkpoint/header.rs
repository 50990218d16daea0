//! The checkpoint file before its payload: what is at a checkpoint path (a
//! checkpoint, a damaged one, someone else's file, or no regular file at
//! all), and the header's check.

use super::{CheckpointError, HEADER_LEN, MAGIC, VERSION};
use std::fs::File;
use std::io::Read;
use std::path::Path;

/// What is at a checkpoint path that a new render is about to replace.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Existing {
    /// Nothing.
    Nothing,
    /// A lumen checkpoint (whose payload is not checked: it is replaced).
    Checkpoint,
    /// A lumen checkpoint whose magic bytes are damaged.
    Damaged,
}

/// What is at `path`, a checkpoint path, before a render starts: a render
/// may replace a checkpoint, damaged or not, but nothing else. The error
/// says what is there instead (someone's file, a device, a pipe) and what
/// to do. Only the header is read.
pub fn inspect(path: &Path) -> Result<Existing, CheckpointError> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Existing::Nothing),
        _ => {}
    }
    let (file, len) = open_regular(path)?;
    let mut head = Vec::with_capacity(HEADER_LEN);
    file.take(HEADER_LEN as u64)
        .read_to_end(&mut head)
        .map_err(|e| CheckpointError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    match check(&head, len, path) {
        Ok(_) | Err(CheckpointError::Version { .. } | CheckpointError::Truncated { .. }) => {
            Ok(Existing::Checkpoint)
        }
        Err(CheckpointError::Damaged { .. }) => Ok(Existing::Damaged),
        Err(e) => Err(e),
    }
}

/// Removes the checkpoint at `path` if it is a regular file (a render
/// removes its checkpoint when it completes; whatever else was put at the
/// path meanwhile is left alone). Nothing there is not an error.
pub fn remove(path: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.is_file() => std::fs::remove_file(path),
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

/// Opens `path` for reading if it is a regular file; returns it with its
/// length. The type is checked before opening: opening a named pipe waits
/// for a writer, and a device may never end.
pub(super) fn open_regular(path: &Path) -> Result<(File, u64), CheckpointError> {
    let not_regular = |message: String| CheckpointError::NotRegular {
        path: path.to_path_buf(),
        message,
    };
    crate::files::check_regular(path).map_err(not_regular)?;
    let file = File::open(path).map_err(|e| CheckpointError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    match file.metadata() {
        Ok(meta) if meta.is_file() => Ok((file, meta.len())),
        Ok(_) => Err(not_regular("is no longer a regular file".into())),
        Err(e) => Err(CheckpointError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        }),
    }
}

/// Checks a checkpoint's first bytes `head` (up to [`HEADER_LEN`]) against
/// the file's length `len`; returns the payload length.
pub(super) fn check(head: &[u8], len: u64, path: &Path) -> Result<u64, CheckpointError> {
    let path_buf = || path.to_path_buf();
    let truncated = |expected: u64| CheckpointError::Truncated {
        path: path_buf(),
        expected,
        found: len,
    };
    if !head.starts_with(MAGIC) {
        if head.len() >= 4 && head.len() < MAGIC.len() && MAGIC.starts_with(head) {
            return Err(truncated(HEADER_LEN as u64));
        }
        if looks_damaged(head, len) {
            return Err(CheckpointError::Damaged { path: path_buf() });
        }
        return Err(CheckpointError::NotACheckpoint {
            path: path_buf(),
            what: what_it_is(head, len),
        });
    }
    if head.len() < HEADER_LEN {
        return Err(truncated(HEADER_LEN as u64));
    }
    let field = |at: usize, n: usize| {
        let mut v = [0u8; 8];
        v[..n].copy_from_slice(&head[at..at + n]);
        u64::from_le_bytes(v)
    };
    let version = field(8, 4) as u32;
    if version != VERSION {
        return Err(CheckpointError::Version {
            path: path_buf(),
            found: version,
        });
    }
    let payload = field(12, 8);
    match payload.checked_add(HEADER_LEN as u64) {
        Some(total) if total == len => Ok(payload),
        total => Err(truncated(total.unwrap_or(u64::MAX))),
    }
}

/// Whether a file whose magic bytes are wrong is a damaged checkpoint: its
/// magic differs in at most two bytes, or its version and payload length
/// are a checkpoint's and match the file's length. Someone's file passes
/// neither test but by an extraordinary coincidence.
fn looks_damaged(head: &[u8], len: u64) -> bool {
    if head.len() < HEADER_LEN {
        return false;
    }
    let wrong = head[..MAGIC.len()]
        .iter()
        .zip(MAGIC)
        .filter(|(a, b)| a != b)
        .count();
    let version = u32::from_le_bytes(head[8..12].try_into().expect("4 bytes"));
    let payload = u64::from_le_bytes(head[12..20].try_into().expect("8 bytes"));
    wrong <= 2
        || ((1..=VERSION).contains(&version) && payload.checked_add(HEADER_LEN as u64) == Some(len))
}

/// What a file that is not a checkpoint seems to be, from its first bytes.
fn what_it_is(head: &[u8], len: u64) -> String {
    if len == 0 {
        return "an empty file".into();
    }
    const KNOWN: &[(&[u8], &str)] = &[
        (b"\x89PNG", "a PNG image"),
        (b"\xff\xd8\xff", "a JPEG image"),
        (b"P3", "a PPM image"),
        (b"P6", "a PPM image"),
        (b"PF\n", "a PFM image"),
        (b"Pf\n", "a PFM image"),
        (b"v/1\x01", "an OpenEXR image"),
        (b"#?RADIANCE", "a Radiance HDR image"),
    ];
    let bytes = if len == 1 { "1 byte" } else { "bytes" };
    if let Some((_, name)) = KNOWN.iter().find(|(m, _)| head.starts_with(m)) {
        return format!("{name} of {len} {bytes}");
    }
    // Text, possibly cut in the middle of a character.
    let valid = match std::str::from_utf8(head) {
        Ok(text) => text,
        Err(e) if e.error_len().is_none() => {
            std::str::from_utf8(&head[..e.valid_up_to()]).unwrap_or_default()
        }
        Err(_) => "\0",
    };
    let text = !valid
        .chars()
        .any(|c| c.is_control() && !matches!(c, '\n' | '\r' | '\t'));
    if text {
        format!("a text file of {len} {bytes}")
    } else {
        format!("a file of {len} {bytes} that is not lumen's")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_damaged_magic_is_told_from_someones_file() {
        let p = Path::new("x");
        let mut head = MAGIC.to_vec();
        head.extend_from_slice(&VERSION.to_le_bytes());
        head.extend_from_slice(&100u64.to_le_bytes());
        head.extend_from_slice(&[0; 4]);
        assert_eq!(check(&head, 124, p).unwrap(), 100);
        let mut damaged = head.clone();
        damaged[..8].copy_from_slice(b"\0\0\0\0\0\0\0\0");
        let e = check(&damaged, 124, p).unwrap_err();
        assert!(matches!(e, CheckpointError::Damaged { .. }), "{e}");
        let e = check(&damaged, 125, p).unwrap_err().to_string();
        assert!(
            e.contains("not a lumen checkpoint but a file of 125 bytes"),
            "{e}"
        );
        let e = check(b"hello, world", 12, p).unwrap_err().to_string();
        assert!(e.contains("a text file of 12 bytes"), "{e}");
        let e = check(b"\x89PNG\r\n", 3000, p).unwrap_err().to_string();
        assert!(e.contains("a PNG image of 3000 bytes"), "{e}");
        let e = check(b"", 0, p).unwrap_err().to_string();
        assert!(e.contains("an empty file"), "{e}");
    }
}
