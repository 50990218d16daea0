//! Writing a description out as a scene file, and the checks that keep an
//! export from destroying its own input.

use std::fmt;
use std::path::{Path, PathBuf};

/// An export would write over the scene file it reads: refused, since the
/// file would lose everything a description does not keep (its comments,
/// its layout) and, should the write fail half-way, the scene itself.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OverwritesSource {
    /// The output asked for.
    pub output: PathBuf,
    /// The scene file it is.
    pub source: PathBuf,
}

impl fmt::Display for OverwritesSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: is the scene file being exported ({}); writing over it would lose its comments and layout, so choose another output",
            self.output.display(),
            self.source.display()
        )
    }
}

impl std::error::Error for OverwritesSource {}

/// Refuses to export the scene file `source` to `output` when both name the
/// same file, however written: `s.toml` and `./dir/../s.toml`, a symbolic
/// link to it, or a hard link (see [`same_file`]).
pub fn check_not_source(source: &Path, output: &Path) -> Result<(), OverwritesSource> {
    if same_file(source, output) {
        return Err(OverwritesSource {
            output: output.to_path_buf(),
            source: source.to_path_buf(),
        });
    }
    Ok(())
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
        use std::os::unix::fs::MetadataExt;
        ma.dev() == mb.dev() && ma.ino() == mb.ino()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_is_the_same_by_any_name_and_not_another() {
        let dir = std::env::temp_dir().join(format!("lumen-same-file-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let a = dir.join("a.toml");
        let b = dir.join("b.toml");
        std::fs::write(&a, "").unwrap();
        std::fs::write(&b, "").unwrap();
        assert!(same_file(&a, &a));
        assert!(same_file(&a, &dir.join("sub/../a.toml")));
        assert!(!same_file(&a, &b));
        assert!(!same_file(&a, &dir.join("missing.toml")));
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&a, dir.join("link.toml")).unwrap();
            std::fs::hard_link(&a, dir.join("hard.toml")).unwrap();
            assert!(same_file(&a, &dir.join("link.toml")));
            assert!(same_file(&dir.join("hard.toml"), &a));
        }
        let err = check_not_source(&a, &a).unwrap_err().to_string();
        assert!(err.contains("choose another output"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
