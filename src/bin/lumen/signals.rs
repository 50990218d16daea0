//! Ctrl-C and SIGTERM: the first stops the render gracefully, the second at once.

use anyhow::{Context, Result};
use lumen::{lock, output};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, OnceLock, TryLockError};
use std::time::{Duration, Instant};

/// Exit status of a render stopped by Ctrl-C or SIGTERM (128 + SIGINT).
pub(crate) const EXIT_INTERRUPTED: u8 = 130;
/// Held while the image and the checkpoint are saved.
static SAVING: Mutex<()> = Mutex::new(());
/// Set by a second interrupt.
static QUIT: AtomicBool = AtomicBool::new(false);
/// The render's lock files, removed when it quits at once: the process
/// exits without unwinding, so their guards never run.
static LOCK_FILES: OnceLock<Vec<PathBuf>> = OnceLock::new();

pub(crate) fn saving() -> MutexGuard<'static, ()> {
    SAVING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Ends the process at once if a second interrupt came; called by the saver
/// at the end of a save, while it holds [`SAVING`].
pub(crate) fn quit_if_asked() {
    if QUIT.load(Ordering::SeqCst) {
        quit_now();
    }
}

fn quit_now() -> ! {
    for lock in LOCK_FILES.get().into_iter().flatten() {
        let _ = std::fs::remove_file(lock);
    }
    errln!("lumen: stopped at once; the files on disk are those of the last save");
    std::process::exit(i32::from(EXIT_INTERRUPTED))
}

/// On the first Ctrl-C or SIGTERM, sets `stop`: the render abandons the pass
/// in flight and saves what it has. On the second, exits at once, leaving
/// the files of the last save, complete, since every file is renamed into
/// place only once written. A save in progress is let finish, so as not to
/// leave its temporary files behind (the saver exits after it); should it
/// take more than two seconds, its temporary files are removed and the
/// process exits anyway. Quitting at once removes the lock files of the
/// render's `targets` (the files it writes).
pub(crate) fn install_stop_handler(stop: &Arc<AtomicBool>, targets: &[&Path]) -> Result<()> {
    let temps: Vec<PathBuf> = targets.iter().map(|t| output::temp_path(t)).collect();
    let _ = LOCK_FILES.set(targets.iter().map(|t| lock::lock_path(t)).collect());
    let stop = Arc::clone(stop);
    ctrlc::set_handler(move || {
        if !stop.swap(true, Ordering::SeqCst) {
            errln!(
                "lumen: stopping: saving the image and a checkpoint (interrupt again to quit at once)"
            );
            return;
        }
        QUIT.store(true, Ordering::SeqCst);
        let give_up = Instant::now() + Duration::from_secs(2);
        loop {
            match SAVING.try_lock() {
                // No save in progress; none starts again: the lock is kept.
                Ok(_gate) => quit_now(),
                Err(TryLockError::Poisoned(_gate)) => quit_now(),
                Err(TryLockError::WouldBlock) if Instant::now() < give_up => {
                    std::thread::sleep(Duration::from_millis(5))
                }
                Err(TryLockError::WouldBlock) => {
                    for t in &temps {
                        let _ = std::fs::remove_file(t);
                    }
                    quit_now()
                }
            }
        }
    })
    .context("cannot install the interrupt handler")
}
