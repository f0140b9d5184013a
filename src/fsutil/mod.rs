//! Atomic file output: write to a temporary file beside the target, then
//! rename, so a failed run never leaves a half-written file behind; and a
//! run's many outputs put in place all or none, even when interrupted
//! ([`Outputs`], see [`stage`]).

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

pub mod stage;

pub use stage::{interrupted, recover, Outputs};

/// Writes `path` atomically: `fill` writes the whole content into a temporary
/// file in the same directory, which is renamed over `path` only on success.
pub fn write_atomic<F>(path: &Path, fill: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let tmp = staged(path, fill)?;
    let at = tmp.path().to_path_buf();
    let placed = tmp.persist(path).map(drop).map_err(|e| e.error);
    stage::forget(&at);
    placed
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
        // Removed on Ctrl-C too, innermost first.
        for d in missing.iter().rev() {
            stage::created_dir(d);
        }
        // Innermost first, the order they are removed in.
        self.dirs.extend(missing);
        Ok(())
    }

    /// The run succeeded: keep them.
    pub fn keep(mut self) {
        for d in self.dirs.drain(..) {
            stage::forget(&d);
        }
    }
}

impl Drop for CreatedDirs {
    fn drop(&mut self) {
        for d in &self.dirs {
            stage::forget(d);
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
    let made = stage::making()?;
    let tmp = tempfile::Builder::new()
        .prefix(".brickwright-")
        .suffix(".part")
        .tempfile_in(dir)?;
    // Removed on Ctrl-C; dropped on an error, it goes by itself.
    stage::temp_file(tmp.path());
    drop(made);
    let filled = (|| {
        let mut w = BufWriter::new(tmp.as_file());
        fill(&mut w)?;
        w.flush()
    })();
    if let Err(e) = filled {
        stage::forget(tmp.path());
        return Err(e);
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
        let mut out = Outputs::new(dir.path()).unwrap();
        out.add(&a, |w| w.write_all(b"a")).unwrap();
        assert!(!a.exists());
        assert!(out.add(&b, |_| Err(io::Error::other("boom"))).is_err());
        drop(out);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let mut out = Outputs::new(dir.path()).unwrap();
        out.add(&a, |w| w.write_all(b"a")).unwrap();
        out.add(&b, |w| w.write_all(b"b")).unwrap();
        assert_eq!(out.paths().count(), 2);
        out.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "b");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn files_added_side_by_side_come_in_order_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let paths: Vec<_> = (0..40)
            .map(|k| dir.path().join("steps").join(format!("{k}.txt")))
            .collect();
        let mut out = Outputs::new(dir.path()).unwrap();
        let e = out
            .add_all(&paths, |k, w| match k {
                7 | 30 => Err(io::Error::other(format!("boom {k}"))),
                _ => w.write_all(k.to_string().as_bytes()),
            })
            .unwrap_err();
        assert_eq!(e.to_string(), "boom 7", "the first in order");
        assert_eq!(out.paths().count(), 0);
        out.add_all(&paths, |k, w| w.write_all(k.to_string().as_bytes()))
            .unwrap();
        assert!(out.paths().eq(paths.iter().map(PathBuf::as_path)));
        // The build makes the pictures' folder itself, as here.
        std::fs::create_dir(dir.path().join("steps")).unwrap();
        out.commit().unwrap();
        for (k, p) in paths.iter().enumerate() {
            assert_eq!(std::fs::read_to_string(p).unwrap(), k.to_string());
        }
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
        let mut out = Outputs::new(dir.path()).unwrap();
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
        let mut out = Outputs::new(dir.path()).unwrap();
        for p in [&a, &b, &c] {
            out.add(p, |w| w.write_all(b"new")).unwrap();
        }
        // The third file fails to go in place, after two have.
        let mut n = 0;
        let (at, _) = out
            .commit_with(|from, to| {
                n += 1;
                if n == 3 {
                    return Err(io::Error::other("disk full"));
                }
                std::fs::rename(from, to)
            })
            .unwrap_err();
        assert_eq!(at, c);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert!(!b.exists());
        assert_eq!(std::fs::read_to_string(&c).unwrap(), "old c");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    /// Interrupted before its renames began, a write leaves the old
    /// outputs; after, the next run finishes it. Either way no staging
    /// folder stays.
    #[test]
    fn an_interrupted_write_is_undone_or_finished_by_the_next_run() {
        let dir = tempfile::tempdir().unwrap();
        let [a, b] = ["a.txt", "steps/b.txt"].map(|n| dir.path().join(n));
        std::fs::create_dir(dir.path().join("steps")).unwrap();
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&b, "old b").unwrap();
        let leftovers = |d: &Path| {
            std::fs::read_dir(d)
                .unwrap()
                .filter(|e| {
                    e.as_ref()
                        .unwrap()
                        .file_name()
                        .to_string_lossy()
                        .starts_with(".brickwright")
                })
                .count()
        };
        // Killed while staging: the folder is there, no mark.
        let mut out = Outputs::new(dir.path()).unwrap();
        out.add(&a, |w| w.write_all(b"new a")).unwrap();
        out.add(&b, |w| w.write_all(b"new b")).unwrap();
        out.kill();
        assert_eq!(leftovers(dir.path()), 1);
        recover(dir.path()).unwrap();
        assert_eq!(leftovers(dir.path()), 0);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
        // Killed after the first rename: the mark is there.
        let mut out = Outputs::new(dir.path()).unwrap();
        out.add(&a, |w| w.write_all(b"new a")).unwrap();
        out.add(&b, |w| w.write_all(b"new b")).unwrap();
        let stage = out.kill();
        std::fs::write(stage.join("commit"), "").unwrap();
        std::fs::rename(&a, stage.join("old-a")).unwrap();
        std::fs::rename(stage.join("new/a.txt"), &a).unwrap();
        recover(dir.path()).unwrap();
        assert_eq!(leftovers(dir.path()), 0);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new b");
        assert_eq!(leftovers(&dir.path().join("steps")), 0);
    }

    #[test]
    fn a_running_writers_stage_is_left_alone() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.txt");
        let mut out = Outputs::new(dir.path()).unwrap();
        out.add(&a, |w| w.write_all(b"a")).unwrap();
        // Another run into the same folder, meanwhile.
        let mut other = Outputs::new(dir.path()).unwrap();
        other.add(&a, |w| w.write_all(b"b")).unwrap();
        other.commit().unwrap();
        out.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "a");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
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
