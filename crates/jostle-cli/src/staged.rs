//! Outputs written whole or not at all: each is written to a hidden temporary file beside its
//! target and renamed over the target only once complete. A run that fails part-way (a
//! non-finite body, a disk that fills, an interrupt) leaves the target as it was and removes
//! the temporary file; a reader never sees a half-written trace, image or results table.
//!
//! A target that is a symbolic link is followed: the file it names is replaced and the link
//! kept. A target that exists and is not a regular file (a device such as `/dev/null`, a named
//! pipe), or that lies under `/dev` or `/proc` (`/dev/stdout`), cannot be replaced: the output
//! is staged in the temporary directory and written into it once complete (renamed over,
//! `/dev/null` became a regular file, and `/dev/stdout` redirected to a file replaced the
//! file). Such an output is not written whole or not at all: a reader of a pipe sees it as it
//! is copied.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// An output being written to [`Staged::path`], moved to its target by [`Staged::commit`];
/// dropped without a commit, the temporary file is removed.
#[derive(Debug)]
pub struct Staged {
    temp: PathBuf,
    target: PathBuf,
    /// The target is not a regular file: copied into, not renamed over.
    stream: bool,
    committed: bool,
}

impl Staged {
    /// Stages `target`: the temporary file is `.NAME.jostle-partial.EXT` in the same directory
    /// as the file it replaces (same file system, so the rename is atomic; the extension kept
    /// for writers that pick the format from it), or a new file of the temporary directory,
    /// with the extension too, for a target that is not a regular file ([`resolve`]).
    pub fn new(target: &Path) -> Self {
        let (replaced, stream) = resolve(target);
        let stem = replaced
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let ext = replaced
            .extension()
            .map_or(String::new(), |e| format!(".{}", e.to_string_lossy()));
        let temp = if stream {
            temp_file(&stem, &ext)
        } else {
            replaced.with_file_name(format!(".{stem}.jostle-partial{ext}"))
        };
        Self {
            temp,
            target: replaced,
            stream,
            committed: false,
        }
    }

    /// Where to write.
    pub fn path(&self) -> &Path {
        &self.temp
    }

    /// Moves the finished file over the target, or copies it into a target that is not a
    /// regular file (appending: `/dev/stdout` redirected to a file keeps what it holds).
    pub fn commit(mut self) -> Result<(), String> {
        let failed = |e: std::io::Error| format!("{}: cannot write: {e}", self.target.display());
        if self.stream {
            let mut from = std::fs::File::open(&self.temp).map_err(failed)?;
            let mut into = std::fs::OpenOptions::new()
                .append(true)
                .open(&self.target)
                .map_err(failed)?;
            std::io::copy(&mut from, &mut into)
                .and_then(|_| into.flush())
                .map_err(failed)?;
            // The temporary copy is removed on drop.
            return Ok(());
        }
        std::fs::rename(&self.temp, &self.target).map_err(failed)?;
        self.committed = true;
        Ok(())
    }
}

/// Where an output for `target` goes, and whether it is written into rather than replaced. A
/// target that exists and is not a regular file (a device, a named pipe), or that is or
/// leads through a link to a path under `/dev` or `/proc` (`/dev/stdout` is a link to
/// `/proc/self/fd/1`, which names whatever standard output is, perhaps a file the shell
/// appends to), is written into as given. Otherwise a chain of symbolic links is followed to
/// the file it names, existing or not (at most 40 links, as the kernel does), which is
/// replaced; the links stay.
pub fn resolve(target: &Path) -> (PathBuf, bool) {
    if std::fs::metadata(target).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        return (target.to_path_buf(), true);
    }
    let mut path = target.to_path_buf();
    for _ in 0..40 {
        if path.starts_with("/dev") || path.starts_with("/proc") {
            return (target.to_path_buf(), true);
        }
        let Ok(next) = std::fs::read_link(&path) else {
            break;
        };
        path = match path.parent() {
            Some(dir) if next.is_relative() => dir.join(next),
            _ => next,
        };
    }
    (path, false)
}

/// A new, empty file of the temporary directory named after the output, with its extension
/// last (`.trace.jostle-partial-PID-N.csv`): created exclusively, so that nothing placed there
/// beforehand is written through.
fn temp_file(stem: &str, ext: &str) -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir();
    loop {
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let path = dir.join(format!(
            ".{stem}.jostle-partial-{}-{n}{ext}",
            std::process::id()
        ));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
        {
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            // Any other failure shows when the output is written there.
            _ => return path,
        }
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

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_is_followed_and_kept() {
        let d = dir("link");
        let (file, link) = (d.join("real.csv"), d.join("link.csv"));
        std::fs::write(&file, "old").unwrap();
        std::os::unix::fs::symlink("real.csv", &link).unwrap();
        let staged = Staged::new(&link);
        std::fs::write(staged.path(), "new").unwrap();
        staged.commit().unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "new");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 2);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_named_pipe_is_written_into_not_replaced() {
        use std::os::unix::fs::FileTypeExt as _;
        let d = dir("fifo");
        let fifo = d.join("out.csv");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !made.is_ok_and(|s| s.success()) {
            eprintln!("no mkfifo here; skipped");
            return;
        }
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
        };
        let staged = Staged::new(&fifo);
        assert!(!staged.path().starts_with(&d), "staged beside a pipe");
        std::fs::write(staged.path(), "through the pipe").unwrap();
        let temp = staged.path().to_path_buf();
        staged.commit().unwrap();
        assert_eq!(reader.join().unwrap(), "through the pipe");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        assert!(!temp.exists(), "the temporary copy is left behind");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
