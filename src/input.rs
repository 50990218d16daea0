//! Reading the files a scene names: the scene file itself, meshes, MTL
//! files, glTF buffers, images and skies all go through [`read`] (or
//! [`read_prefix`]), which reads only regular files and never more than a
//! documented maximum, so that a named pipe cannot hang a render, a device
//! such as `/dev/zero` cannot take the machine's memory, and a file much
//! larger than what it is declared to hold is not read whole.
//!
//! The maximum sizes are in `docs/scene-format.md` ("Limits").

use std::fmt;
use std::fs::File;
use std::io::Read;
use std::path::Path;

/// Largest scene file (TOML or JSON) read: 1 GiB.
pub const MAX_SCENE_BYTES: u64 = 1 << 30;
/// Largest mesh file (OBJ, PLY, glTF, GLB, or a glTF buffer) read: 16 GiB.
pub const MAX_MESH_BYTES: u64 = 16 << 30;
/// Largest MTL file read: 64 MiB (a material library is text of a few
/// lines per material).
pub const MAX_MTL_BYTES: u64 = 64 << 20;
/// Largest image file (texture or sky) read: 2 GiB.
pub const MAX_IMAGE_BYTES: u64 = 2 << 30;

/// Why a file could not be read. Its message does not name the file: the
/// caller's error does, with what the file was for.
#[derive(Debug)]
pub enum ReadError {
    /// Nothing is at the path.
    NotFound,
    /// Something other than a regular file is there; says what.
    NotRegular(&'static str),
    /// The file is larger than the maximum for its kind.
    TooLarge {
        /// The file's bytes (or those it must hold).
        len: u64,
        /// The most read.
        max: u64,
    },
    /// The file is shorter than the bytes it must hold.
    TooShort {
        /// The file's bytes.
        len: u64,
        /// The bytes it must hold.
        want: u64,
    },
    /// This machine's memory cannot hold the file.
    Memory(crate::memory::MemoryError),
    /// The system refused to open or read it.
    Io(std::io::Error),
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReadError::NotFound => write!(f, "no such file"),
            ReadError::NotRegular(kind) => write!(
                f,
                "is {kind}, not a regular file; lumen reads its inputs only from regular files"
            ),
            ReadError::TooLarge { len, max } => write!(
                f,
                "is {len} bytes, more than the {max} bytes lumen reads from a file of this kind"
            ),
            ReadError::TooShort { len, want } => write!(
                f,
                "is {len} bytes, shorter than the {want} bytes it must hold"
            ),
            ReadError::Memory(e) => write!(f, "{e}"),
            ReadError::Io(e) => write!(f, "cannot read: {e}"),
        }
    }
}

impl std::error::Error for ReadError {}

/// The whole of the regular file at `path`, if it has at most `max` bytes.
pub fn read(path: &Path, max: u64) -> Result<Vec<u8>, ReadError> {
    let (file, len) = open(path)?;
    if len > max {
        return Err(ReadError::TooLarge { len, max });
    }
    read_len(file, len)
}

/// The first `want` bytes of the regular file at `path` (a glTF buffer's
/// declared `byteLength`): what lies past them is not read, and a file
/// shorter than `want` is refused. `want` is bounded by `max` first.
pub fn read_prefix(path: &Path, want: u64, max: u64) -> Result<Vec<u8>, ReadError> {
    if want > max {
        return Err(ReadError::TooLarge { len: want, max });
    }
    let (file, len) = open(path)?;
    if len < want {
        return Err(ReadError::TooShort { len, want });
    }
    read_len(file, want)
}

/// Checks, without opening it, that `path` is a regular file (or a link to
/// one) that exists.
pub fn check(path: &Path) -> Result<(), ReadError> {
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => ReadError::NotFound,
        _ => ReadError::Io(e),
    })?;
    if !meta.is_file() {
        return Err(ReadError::NotRegular(crate::files::kind(&meta)));
    }
    Ok(())
}

/// Opens `path` for reading if it is a regular file (or a link to one), and
/// gives its length. What is there is looked at before opening, because
/// opening a named pipe waits for a writer; and again on the open file, so
/// that a file swapped in between is caught too.
fn open(path: &Path) -> Result<(File, u64), ReadError> {
    check(path)?;
    let file = File::open(path).map_err(ReadError::Io)?;
    let opened = file.metadata().map_err(ReadError::Io)?;
    if !opened.is_file() {
        return Err(ReadError::NotRegular(crate::files::kind(&opened)));
    }
    Ok((file, opened.len()))
}

/// Reads `len` bytes of `file` into memory taken without aborting; a file
/// that shrank meanwhile gives what it has, one that grew no more than `len`.
fn read_len(file: File, len: u64) -> Result<Vec<u8>, ReadError> {
    let mut bytes = crate::memory::vec_for::<u8>(len, "the file").map_err(ReadError::Memory)?;
    file.take(len)
        .read_to_end(&mut bytes)
        .map_err(ReadError::Io)?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("lumen-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn regular_files_are_read_within_their_maximum() {
        let path = scratch("ten");
        std::fs::File::create(&path)
            .unwrap()
            .write_all(b"0123456789")
            .unwrap();
        assert_eq!(read(&path, 10).unwrap(), b"0123456789");
        let e = read(&path, 9).unwrap_err();
        assert!(matches!(e, ReadError::TooLarge { len: 10, max: 9 }), "{e}");
        assert_eq!(read_prefix(&path, 4, 100).unwrap(), b"0123");
        let e = read_prefix(&path, 11, 100).unwrap_err();
        assert!(e.to_string().contains("shorter than the 11 bytes"), "{e}");
        assert!(read_prefix(&path, 101, 100).is_err());
        assert!(matches!(
            read(&scratch("absent"), 10),
            Err(ReadError::NotFound)
        ));
        let _ = std::fs::remove_dir_all(path.parent().unwrap());
    }

    #[test]
    fn devices_and_directories_are_refused_without_reading() {
        let e = read(Path::new(env!("CARGO_MANIFEST_DIR")), 1 << 20).unwrap_err();
        assert!(e.to_string().starts_with("is a directory"), "{e}");
        if Path::new("/dev/zero").exists() {
            let e = read(Path::new("/dev/zero"), u64::MAX).unwrap_err();
            assert!(e.to_string().contains("a character device"), "{e}");
        }
    }
}
