//! Atomic file output: write to a temporary file beside the target, then
//! rename, so a failed run never leaves a half-written file behind.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

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

    /// Renames every staged file into place. On an error, the path that
    /// failed comes with it.
    pub fn commit(self) -> Result<(), (PathBuf, io::Error)> {
        for (path, tmp) in self.staged {
            tmp.persist(&path).map_err(|e| (path.clone(), e.error))?;
        }
        Ok(())
    }
}

/// A temporary file beside `path`, filled and synced, not yet renamed.
fn staged<F>(path: &Path, fill: F) -> io::Result<NamedTempFile>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
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
}
