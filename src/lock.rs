//! Render locks: a render holds an advisory lock on each file it writes (its
//! image and its checkpoint) for as long as it runs, so that a second render
//! to the same files is refused instead of overwriting the first one's image
//! and deleting its live checkpoint.
//!
//! The lock is taken on a lock file beside the target, `.NAME.lumen-lock`
//! (see [`lock_path`]), not on the target itself: the target is replaced by
//! renaming after every save, which would drop a lock held on it. The lock
//! file holds the locking process's id, for the message of the render that
//! is refused, and is removed when the lock is released. The lock is the
//! operating system's (`flock` on Unix): it is released when the process
//! ends, however it ends, so a lock file that a killed render left behind
//! blocks nothing.

use std::fs::{self, File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Suffix of lock file names.
pub const EXTENSION: &str = "lumen-lock";

/// The lock file of `target`: `.NAME.lumen-lock` in the same directory
/// (shortened if need be to fit in a file name, see
/// [`crate::files::fit_name`]).
pub fn lock_path(target: &Path) -> PathBuf {
    crate::files::sibling(target, ".", &format!(".{EXTENSION}"))
}

/// A lock that cannot be taken.
#[derive(Debug, Error)]
pub enum LockError {
    /// Another process holds it.
    #[error("{target} is in use by another lumen render ({holder}); wait for it to finish or stop it, or choose another file (lock file {lock})")]
    Busy {
        /// The file the lock is for.
        target: PathBuf,
        /// The lock file.
        lock: PathBuf,
        /// Who holds it, e.g. `process 1234`.
        holder: String,
    },
    /// The lock file cannot be made or locked.
    #[error("{target}: cannot lock {lock}: {message}")]
    Io {
        /// The file the lock is for.
        target: PathBuf,
        /// The lock file.
        lock: PathBuf,
        /// Why.
        message: String,
    },
}

/// An exclusive lock on a file a render writes, held until dropped; dropping
/// it removes the lock file.
#[derive(Debug)]
pub struct RenderLock {
    file: File,
    path: PathBuf,
}

impl RenderLock {
    /// Locks `target` for this process, or fails naming the process that
    /// holds it.
    pub fn acquire(target: &Path) -> Result<Self, LockError> {
        let lock = lock_path(target);
        let io = |message: String| LockError::Io {
            target: target.to_path_buf(),
            lock: lock.clone(),
            message,
        };
        check_lock_file(&lock).map_err(&io)?;
        // A holder that finishes removes the file, possibly between our
        // opening it and locking it: the lock would then be on a file nobody
        // else sees, so it is taken again on the file now at the path.
        for _ in 0..100 {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&lock)
                .map_err(|e| io(e.to_string()))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(fs::TryLockError::WouldBlock) => {
                    let mut text = String::new();
                    let _ = file.read_to_string(&mut text);
                    let holder = match text.trim().parse::<u32>() {
                        Ok(pid) => format!("process {pid}"),
                        Err(_) => "a process that is starting".to_string(),
                    };
                    return Err(LockError::Busy {
                        target: target.to_path_buf(),
                        lock,
                        holder,
                    });
                }
                Err(fs::TryLockError::Error(e)) => return Err(io(e.to_string())),
            }
            if !same_file(&file, &lock) {
                continue;
            }
            file.set_len(0)
                .and_then(|()| file.rewind())
                .and_then(|()| write!(file, "{}", std::process::id()))
                .and_then(|()| file.flush())
                .map_err(|e| io(e.to_string()))?;
            return Ok(Self { file, path: lock });
        }
        Err(io("the lock file keeps being replaced".into()))
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for RenderLock {
    fn drop(&mut self) {
        // Removed while still locked, so that no other render can have
        // locked the file being removed.
        let _ = fs::remove_file(&self.path);
        let _ = self.file.unlock();
    }
}

/// Checks that what is at `lock`, if anything, is a lock file lumen made:
/// a regular file, not a link (writing the process id through a link would
/// overwrite the file it points to), holding a process id or nothing.
fn check_lock_file(lock: &Path) -> Result<(), String> {
    match fs::symlink_metadata(lock) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e.to_string()),
        Ok(meta) if meta.file_type().is_symlink() => {
            return Err("is a symbolic link, not a lock file of lumen's; remove it".into())
        }
        Ok(_) => crate::files::check_regular(lock)?,
    }
    let mut text = Vec::new();
    File::open(lock)
        .and_then(|f| f.take(64).read_to_end(&mut text))
        .map_err(|e| e.to_string())?;
    let ours = text.len() <= 20 && text.iter().all(u8::is_ascii_digit);
    if ours {
        Ok(())
    } else {
        Err("exists and is not a lock file of lumen's (it holds something other than a process id); move or remove it".into())
    }
}

/// Whether the open `file` is the file now at `path`.
fn same_file(file: &File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        match (file.metadata(), fs::metadata(path)) {
            (Ok(a), Ok(b)) => crate::files::same_inode(&a, &b),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (file, path);
        path.exists()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_is_refused_naming_the_holder_and_released_on_drop() {
        let dir = std::env::temp_dir().join(format!("lumen-lock-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let target = dir.join("out.png");
        let held = RenderLock::acquire(&target).unwrap();
        assert_eq!(held.path(), dir.join(".out.png.lumen-lock"));
        // flock locks belong to the open file, so a second open in the same
        // process conflicts like another process would.
        let e = RenderLock::acquire(&target).unwrap_err().to_string();
        assert!(
            e.contains(&format!("process {}", std::process::id())),
            "{e}"
        );
        drop(held);
        assert!(!dir.join(".out.png.lumen-lock").exists());
        drop(RenderLock::acquire(&target).unwrap());
        // Someone's file, or a link to one, at the lock path is left alone.
        let lock = dir.join(".out.png.lumen-lock");
        fs::write(&lock, "my notes").unwrap();
        let e = RenderLock::acquire(&target).unwrap_err().to_string();
        assert!(e.contains("not a lock file"), "{e}");
        assert_eq!(fs::read_to_string(&lock).unwrap(), "my notes");
        fs::remove_file(&lock).unwrap();
        #[cfg(unix)]
        {
            let notes = dir.join("notes");
            fs::write(&notes, "12").unwrap();
            std::os::unix::fs::symlink(&notes, &lock).unwrap();
            let e = RenderLock::acquire(&target).unwrap_err().to_string();
            assert!(e.contains("symbolic link"), "{e}");
            assert_eq!(fs::read_to_string(&notes).unwrap(), "12");
        }
        fs::remove_dir_all(&dir).unwrap();
    }
}
