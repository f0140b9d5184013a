//! Atomic file output: write to a temporary file beside the target, then
//! rename, so a failed run never leaves a half-written file behind.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use tempfile::{NamedTempFile, TempPath};

/// Writes `path` atomically: `fill` writes the whole content into a temporary
/// file in the same directory, which is renamed over `path` only on success.
pub fn write_atomic<F>(path: &Path, fill: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let tmp = staged(path, fill)?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Several outputs written all or none: each is filled into a temporary
/// file beside its target as it is [added](Outputs::add), and only
/// [`commit`](Outputs::commit) renames them into place. Dropped without a
/// commit (an error on the way), it leaves nothing behind.
#[derive(Default)]
pub struct Outputs {
    staged: Vec<(PathBuf, NamedTempFile)>,
}

impl Outputs {
    /// No outputs yet.
    pub fn new() -> Self {
        Outputs::default()
    }

    /// Fills the content of `path`; the file appears at commit.
    pub fn add<F>(&mut self, path: &Path, fill: F) -> io::Result<()>
    where
        F: FnOnce(&mut dyn Write) -> io::Result<()>,
    {
        let tmp = staged(path, fill)?;
        self.staged.push((path.to_path_buf(), tmp));
        Ok(())
    }

    /// The paths added so far, in order.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.staged.iter().map(|(p, _)| p.as_path())
    }

    /// Renames every staged file into place, all or none: a target that
    /// is a directory fails before anything moves, each file already there
    /// is moved aside first, and on any failure the new files are taken
    /// away and the old ones put back. On an error, the path that failed
    /// comes with it.
    pub fn commit(self) -> Result<(), (PathBuf, io::Error)> {
        self.commit_with(|tmp, path| tmp.persist(path).map(drop).map_err(|e| e.error))
    }

    /// [`Outputs::commit`], each file put in place by `place` (a test
    /// makes it fail halfway).
    fn commit_with(
        self,
        mut place: impl FnMut(NamedTempFile, &Path) -> io::Result<()>,
    ) -> Result<(), (PathBuf, io::Error)> {
        for (path, _) in &self.staged {
            if std::fs::symlink_metadata(path).is_ok_and(|m| m.is_dir()) {
                return Err((
                    path.clone(),
                    io::Error::new(io::ErrorKind::IsADirectory, "a directory is in the way"),
                ));
            }
        }
        // What was done, to undo: (target, the old file moved aside).
        let mut placed: Vec<(PathBuf, Option<TempPath>)> = Vec::new();
        for (path, tmp) in self.staged {
            let step = move_aside(&path).and_then(|old| match place(tmp, &path) {
                Ok(()) => Ok(old),
                Err(e) => {
                    if let Some(old) = &old {
                        let _ = std::fs::rename(old, &path);
                    }
                    Err(e)
                }
            });
            match step {
                Ok(old) => placed.push((path, old)),
                Err(e) => {
                    for (done, old) in placed.into_iter().rev() {
                        match old {
                            Some(old) => {
                                let _ = std::fs::rename(&old, &done);
                            }
                            None => {
                                let _ = std::fs::remove_file(&done);
                            }
                        }
                    }
                    return Err((path, e));
                }
            }
        }
        // Success: the old files moved aside are deleted as they drop.
        Ok(())
    }
}

/// Moves the file at `path`, if any, to a fresh temporary name beside it
/// (deleted when the returned path drops).
fn move_aside(path: &Path) -> io::Result<Option<TempPath>> {
    if std::fs::symlink_metadata(path).is_err() {
        return Ok(None);
    }
    let old = tempfile::Builder::new()
        .prefix(".brickwright-")
        .suffix(".old")
        .tempfile_in(parent_dir(path))?
        .into_temp_path();
    std::fs::rename(path, &old)?;
    Ok(Some(old))
}

/// The directory `path` is in (`.` for a bare file name).
fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Directories created for a run's outputs, removed again (when still
/// empty) if the run fails before [`CreatedDirs::keep`].
#[derive(Default)]
pub struct CreatedDirs {
    dirs: Vec<PathBuf>,
}

impl CreatedDirs {
    /// None yet.
    pub fn new() -> Self {
        CreatedDirs::default()
    }

    /// Creates `dir` and any missing parents, remembering the ones made.
    pub fn create(&mut self, dir: &Path) -> io::Result<()> {
        let mut missing = Vec::new();
        let mut d = dir;
        while !d.as_os_str().is_empty() && std::fs::symlink_metadata(d).is_err() {
            missing.push(d.to_path_buf());
            match d.parent() {
                Some(p) => d = p,
                None => break,
            }
        }
        std::fs::create_dir_all(dir)?;
        // Innermost first, the order they are removed in.
        self.dirs.extend(missing);
        Ok(())
    }

    /// The run succeeded: keep them.
    pub fn keep(mut self) {
        self.dirs.clear();
    }
}

impl Drop for CreatedDirs {
    fn drop(&mut self) {
        for d in &self.dirs {
            // Only an empty directory goes; anything else stays.
            let _ = std::fs::remove_dir(d);
        }
    }
}

/// Fails when `path` is a symbolic link: a folder the outputs go into
/// (`DIR/steps`) must be inside the output folder, not lead elsewhere.
pub fn refuse_link(path: &Path) -> io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => Err(io::Error::other(
            "a symbolic link; brickwright writes only inside the output folder, remove the link",
        )),
        _ => Ok(()),
    }
}

/// A temporary file beside `path`, filled and synced, not yet renamed.
fn staged<F>(path: &Path, fill: F) -> io::Result<NamedTempFile>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let dir = parent_dir(path);
    let tmp = tempfile::Builder::new()
        .prefix(".brickwright-")
        .suffix(".part")
        .tempfile_in(dir)?;
    {
        let mut w = BufWriter::new(tmp.as_file());
        fill(&mut w)?;
        w.flush()?;
    }
    // No fsync: the rename makes the file appear whole or not at all if
    // the process fails; syncing every file (hundreds of step images)
    // would cost more than the whole render.
    // Temporary files are private (0600); outputs are ordinary files.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))?;
    }
    Ok(tmp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_write_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        let r = write_atomic(&p, |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        write_atomic(&p, |w| w.write_all(b"whole")).unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "whole");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&p).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o644);
        }
    }

    #[test]
    fn outputs_appear_all_together_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.txt"), dir.path().join("b.txt"));
        let mut out = Outputs::new();
        out.add(&a, |w| w.write_all(b"a")).unwrap();
        assert!(!a.exists());
        assert!(out.add(&b, |_| Err(io::Error::other("boom"))).is_err());
        drop(out);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let mut out = Outputs::new();
        out.add(&a, |w| w.write_all(b"a")).unwrap();
        out.add(&b, |w| w.write_all(b"b")).unwrap();
        assert_eq!(out.paths().count(), 2);
        out.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "b");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn a_blocked_target_leaves_the_old_outputs_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b, c) = (
            dir.path().join("house.ldr"),
            dir.path().join("house.pdf"),
            dir.path().join("report.json"),
        );
        std::fs::write(&a, "old ldr").unwrap();
        std::fs::write(&c, "old report").unwrap();
        std::fs::create_dir(&b).unwrap();
        let mut out = Outputs::new();
        for p in [&a, &b, &c] {
            out.add(p, |w| w.write_all(b"new")).unwrap();
        }
        let (at, e) = out.commit().unwrap_err();
        assert_eq!(at, b);
        assert_eq!(e.kind(), io::ErrorKind::IsADirectory);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old ldr");
        assert_eq!(std::fs::read_to_string(&c).unwrap(), "old report");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
    }

    #[test]
    fn a_failure_halfway_rolls_back_what_was_renamed() {
        let dir = tempfile::tempdir().unwrap();
        let [a, b, c] = ["a.txt", "b.txt", "c.txt"].map(|n| dir.path().join(n));
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&c, "old c").unwrap();
        let mut out = Outputs::new();
        for p in [&a, &b, &c] {
            out.add(p, |w| w.write_all(b"new")).unwrap();
        }
        // The third file fails to go in place, after two have.
        let mut n = 0;
        let (at, _) = out
            .commit_with(|tmp, path| {
                n += 1;
                if n == 3 {
                    return Err(io::Error::other("disk full"));
                }
                tmp.persist(path).map(drop).map_err(|e| e.error)
            })
            .unwrap_err();
        assert_eq!(at, c);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert!(!b.exists());
        assert_eq!(std::fs::read_to_string(&c).unwrap(), "old c");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn created_dirs_go_again_unless_kept() {
        let dir = tempfile::tempdir().unwrap();
        let deep = dir.path().join("a/b/c");
        let mut made = CreatedDirs::new();
        made.create(&deep).unwrap();
        assert!(deep.is_dir());
        drop(made);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let mut made = CreatedDirs::new();
        made.create(&deep).unwrap();
        made.keep();
        assert!(deep.is_dir());
    }
}
