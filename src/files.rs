//! The files lumen keeps beside an output image: the names derived from the
//! output's (checkpoint, temporaries, lock file), which must fit in a file
//! name however long the output's is; the rule that lumen replaces only
//! regular files; and the removal of temporaries that killed processes left.

use std::ffi::{OsStr, OsString};
use std::fs;
use std::path::{Path, PathBuf};

/// Longest file name, in bytes, that lumen derives: 255, the limit of the
/// common file systems (ext4, XFS, Btrfs, APFS, NTFS).
pub const NAME_MAX: usize = 255;

/// Room a temporary name keeps for the process id: `u32::MAX` has 10 digits.
const PID_DIGITS: usize = 10;

/// `name` if it has at most `max` bytes; otherwise as much of it as fits
/// with `~` and 16 hex digits of a hash of the whole name, so that the
/// shortened names of different outputs stay different, and one output's
/// is the same in every run (a resumed render finds its checkpoint).
pub fn fit_name(name: &OsStr, max: usize) -> OsString {
    let bytes = name.as_encoded_bytes();
    if bytes.len() <= max {
        return name.to_owned();
    }
    let tag = format!("~{:016x}", fnv1a(bytes));
    // The readable part is cut at a character boundary of the lossy text:
    // only the hash has to tell names apart.
    let lossy = name.to_string_lossy();
    let mut keep = max.saturating_sub(tag.len());
    while !lossy.is_char_boundary(keep) {
        keep -= 1;
    }
    OsString::from(format!("{}{tag}", &lossy[..keep]))
}

/// The FNV-1a hash: stable across runs and platforms, unlike std's hasher.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// `path`'s file name followed by `suffix`, in the same directory,
/// shortened (see [`fit_name`]) to fit in [`NAME_MAX`] bytes.
pub fn sibling(path: &Path, prefix: &str, suffix: &str) -> PathBuf {
    let name = path.file_name().unwrap_or_default();
    let mut derived = OsString::from(prefix);
    derived.push(fit_name(name, NAME_MAX - prefix.len() - suffix.len()));
    derived.push(suffix);
    crate::output::parent_dir(path).join(derived)
}

/// The part of the temporary names of `path` before the process id:
/// `.NAME.`, shortened to leave room for any process id, so that it is the
/// same for every process (stale temporaries are found by it).
fn temp_prefix(path: &Path) -> OsString {
    let name = path.file_name().unwrap_or_default();
    let mut prefix = OsString::from(".");
    prefix.push(fit_name(name, NAME_MAX - 2 - PID_DIGITS - 4));
    prefix.push(".");
    prefix
}

/// The temporary name an atomic write of `path` by process `pid` uses:
/// `.NAME.PID.tmp`, hidden, in the same directory.
pub fn temp_path_of(path: &Path, pid: u32) -> PathBuf {
    let mut name = temp_prefix(path);
    name.push(format!("{pid}.tmp"));
    crate::output::parent_dir(path).join(name)
}

/// What a path that exists but is not a regular file is, in words.
pub fn kind(meta: &fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a named pipe (FIFO)";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a regular file"
}

/// Checks that lumen may replace or read `path` as one of its files: it does
/// not exist (a dangling link is replaced, not followed), or it is a regular
/// file or a link to one. Anything else, such as `/dev/null`, a named pipe
/// or a directory, is refused: replacing it would destroy it (renaming over
/// `/dev/null` removes the device), and reading it may never end. The error
/// says what is there.
pub fn check_regular(path: &Path) -> Result<(), String> {
    match fs::metadata(path) {
        Ok(meta) if meta.is_file() => Ok(()),
        Ok(meta) => Err(format!(
            "is {}, not a regular file; lumen reads and writes its images and checkpoints only as regular files",
            kind(&meta)
        )),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e.to_string()),
    }
}

/// Whether process `pid` is running. Known on Linux only, through `/proc`;
/// elsewhere, or without `/proc` mounted, every process is taken to be
/// running, so that nothing of a live process is ever removed.
pub fn process_is_running(pid: u32) -> bool {
    if !Path::new("/proc/self").exists() {
        return true;
    }
    Path::new(&format!("/proc/{pid}")).exists()
}

/// Removes the temporaries of `path` (see [`temp_path_of`]) that processes
/// killed while writing it left (SIGKILL gives no chance to clean up, and a
/// checkpoint's temporary is as large as the checkpoint). Only regular files
/// named for a process that is no longer running are removed; returns their
/// paths.
pub fn remove_stale_temps(path: &Path) -> Vec<PathBuf> {
    let prefix = temp_prefix(path);
    let prefix = prefix.as_encoded_bytes();
    let dir = crate::output::parent_dir(path);
    let Ok(entries) = fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut removed = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .as_encoded_bytes()
            .strip_prefix(prefix)
            .and_then(|rest| rest.strip_suffix(b".tmp"))
            .and_then(|digits| std::str::from_utf8(digits).ok())
            .filter(|d| d.bytes().all(|b| b.is_ascii_digit()))
            .and_then(|d| d.parse::<u32>().ok())
        else {
            continue;
        };
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        if pid == std::process::id() || !regular || process_is_running(pid) {
            continue;
        }
        let stale = dir.join(&name);
        if fs::remove_file(&stale).is_ok() {
            removed.push(stale);
        }
    }
    removed.sort();
    removed
}

/// Whether `a` and `b` are the same existing file: on Unix the same device
/// and inode (which also sees hard links), elsewhere the same path once
/// symbolic links and `.`/`..` are resolved. A path that does not exist is
/// no existing file's.
pub fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        same_inode(&ma, &mb)
    }
    #[cfg(not(unix))]
    {
        let _ = (ma, mb);
        match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        }
    }
}

/// Whether two files' metadata are of one file: the same device and inode.
#[cfg(unix)]
pub fn same_inode(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_names_stay_readable_and_long_ones_fit() {
        let p = Path::new("dir/out.png");
        assert_eq!(
            sibling(p, "", ".lumen-ckpt"),
            Path::new("dir/out.png.lumen-ckpt")
        );
        assert_eq!(temp_path_of(p, 42), Path::new("dir/.out.png.42.tmp"));
        for len in [200, 234, 240, 250, 255] {
            let name = format!("{}.png", "é".repeat(len / 2 - 2));
            let long = Path::new(&name);
            for derived in [
                sibling(long, "", ".lumen-ckpt"),
                sibling(long, ".", ".lumen-lock"),
                temp_path_of(long, u32::MAX),
                temp_path_of(&sibling(long, "", ".lumen-ckpt"), 7),
            ] {
                let n = derived.file_name().unwrap().len();
                assert!(n <= NAME_MAX, "{len}: {n} bytes: {derived:?}");
            }
        }
        // Two long names that differ only at the end stay apart.
        let a = format!("{}a.png", "x".repeat(250));
        let b = format!("{}b.png", "x".repeat(250));
        assert_ne!(
            sibling(Path::new(&a), "", ".lumen-ckpt"),
            sibling(Path::new(&b), "", ".lumen-ckpt")
        );
    }

    #[test]
    fn only_regular_files_or_nothing_pass() {
        assert!(check_regular(Path::new("/nonexistent/x")).is_ok());
        assert!(check_regular(Path::new(file!()).parent().unwrap())
            .unwrap_err()
            .contains("a directory"));
        if Path::new("/dev/null").exists() {
            let e = check_regular(Path::new("/dev/null")).unwrap_err();
            assert!(e.contains("a character device"), "{e}");
        }
    }
}
