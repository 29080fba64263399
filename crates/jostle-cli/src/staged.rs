//! Outputs written whole or not at all: each is written to a hidden temporary file beside its
//! target and renamed over the target only once complete. A run that fails part-way (a
//! non-finite body, a disk that fills, an interrupt) leaves the target as it was and removes
//! the temporary file; a reader never sees a half-written trace, image or results table.

use std::path::{Path, PathBuf};

/// An output being written to [`Staged::path`], renamed to its target by [`Staged::commit`];
/// dropped without a commit, the temporary file is removed.
#[derive(Debug)]
pub struct Staged {
    temp: PathBuf,
    target: PathBuf,
    committed: bool,
}

impl Staged {
    /// Stages `target`: the temporary file is `.NAME.jostle-partial.EXT` in the same directory
    /// (same file system, so the rename is atomic; the extension kept for writers that pick
    /// the format from it).
    pub fn new(target: &Path) -> Self {
        let stem = target
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let name = match target.extension() {
            Some(ext) => format!(".{stem}.jostle-partial.{}", ext.to_string_lossy()),
            None => format!(".{stem}.jostle-partial"),
        };
        Self {
            temp: target.with_file_name(name),
            target: target.to_path_buf(),
            committed: false,
        }
    }

    /// Where to write.
    pub fn path(&self) -> &Path {
        &self.temp
    }

    /// Moves the finished file over the target.
    pub fn commit(mut self) -> Result<(), String> {
        std::fs::rename(&self.temp, &self.target)
            .map_err(|e| format!("{}: cannot write: {e}", self.target.display()))?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("jostle-staged-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_commit_replaces_the_target_and_leaves_nothing_else() {
        let d = dir("commit");
        let target = d.join("out.csv");
        std::fs::write(&target, "old").unwrap();
        let staged = Staged::new(&target);
        assert_eq!(staged.path().extension().unwrap(), "csv");
        std::fs::write(staged.path(), "new").unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old");
        staged.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn without_a_commit_the_target_is_untouched_and_the_partial_file_removed() {
        let d = dir("drop");
        let target = d.join("keep.png");
        std::fs::write(&target, "keep").unwrap();
        {
            let staged = Staged::new(&target);
            std::fs::write(staged.path(), "half a frame").unwrap();
        }
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
