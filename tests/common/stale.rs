//! Scratch directories of test processes that have ended.

/// Removes the directories `PREFIX<pid>` that earlier test processes, now
/// ended, left in the temporary directory (tests keep theirs to be looked
/// at after a failure, until the next run).
pub fn remove_stale_dirs(prefix: &str) {
    let Ok(entries) = std::fs::read_dir(std::env::temp_dir()) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|n| n.strip_prefix(prefix))
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !lumen::files::process_is_running(pid) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}
