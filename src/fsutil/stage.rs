//! A run's outputs put in place all or none, even when the run is
//! interrupted (Ctrl-C, a kill, a crash).
//!
//! Every output is first written into one staging folder inside the output
//! folder, `DIR/.brickwright-stage-XXXXXX/new/...`, mirroring where it goes.
//! Once all are written, a `commit` mark is made in the staging folder and
//! the files are renamed into place, each file already there moved aside
//! into the staging folder's `old/` (put back if a rename fails). Last, the
//! staging folder goes.
//!
//! So at any moment the outputs are the old ones, or the new ones, or a
//! staging folder says which to finish with: without a mark, nothing has
//! moved and the folder is simply removed (the old outputs stand); with
//! one, the rest of the new files are renamed into place (the new outputs
//! stand). The next run into the same folder does that before its own
//! write ([`recover`]), and the binary's Ctrl-C handler calls
//! [`interrupted`], which removes the folders of writes not yet committing
//! and waits for a commit under way to end.
//!
//! Each staging folder holds a `lock` file locked by the process writing
//! it, so [`recover`] leaves alone the staging folders of a build that is
//! still running (the lock goes when its process ends, however it ends);
//! commits into one output folder take turns on a lock of the folder.

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::{Mutex, MutexGuard, RwLock, RwLockReadGuard};

/// The start of a staging folder's name.
const PREFIX: &str = ".brickwright-stage-";
/// The mark that the renames have begun.
const MARK: &str = "commit";
/// The lock file of a staging folder.
const LOCK: &str = "lock";

/// What this process must clean up if it is interrupted.
enum Pending {
    /// A staging folder not yet committing: removed whole.
    Stage(PathBuf),
    /// A folder a run created for its outputs: removed if empty.
    Dir(PathBuf),
    /// A temporary file being written: removed.
    File(PathBuf),
}

/// The process's pending clean-ups. Signals are process-wide, so this is
/// one list for the process: the one global of the crate, and only the
/// Ctrl-C handler reads it. A commit holds its lock while it renames.
static PENDING: Mutex<Vec<Pending>> = Mutex::new(Vec::new());

fn pending() -> MutexGuard<'static, Vec<Pending>> {
    PENDING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Whether the process is interrupted, under a lock that every thread
/// making a file or folder for an output holds while it makes it: the
/// Ctrl-C handler sets it (waiting for the makings under way) before it
/// cleans up, so no thread makes a file or folder behind the clean-up (a
/// step picture's staged file, written on another thread, recreated the
/// staging folder after it was removed).
static STOPPING: RwLock<bool> = RwLock::new(false);

/// Leave to make an output's file or folder (held while making it), or
/// an `Interrupted` error once the process is interrupted.
pub(super) fn making() -> io::Result<RwLockReadGuard<'static, bool>> {
    let stopping = STOPPING.read().unwrap_or_else(|e| e.into_inner());
    if *stopping {
        return Err(io::Error::new(io::ErrorKind::Interrupted, "interrupted"));
    }
    Ok(stopping)
}

/// Cleans up after an interrupted process: removes every staging folder
/// whose renames have not begun (the old outputs stand), the empty folders
/// made for them and any temporary file being written; waits for a commit
/// under way to finish first. For the binary's Ctrl-C handler, which then
/// exits; the list is left empty.
pub fn interrupted() {
    *STOPPING.write().unwrap_or_else(|e| e.into_inner()) = true;
    let mut list = pending();
    for p in list.drain(..) {
        let _ = match p {
            Pending::Stage(d) => fs::remove_dir_all(d),
            Pending::Dir(d) => fs::remove_dir(d),
            Pending::File(f) => fs::remove_file(f),
        };
    }
}

/// Registers a folder a run created, removed (if empty) on interruption.
pub(super) fn created_dir(dir: &Path) {
    pending().push(Pending::Dir(dir.to_path_buf()));
}

/// Registers a temporary file, removed on interruption.
pub(super) fn temp_file(path: &Path) {
    pending().push(Pending::File(path.to_path_buf()));
}

/// Drops the registration of `path`, whatever its kind.
pub(super) fn forget(path: &Path) {
    forget_in(&mut pending(), path);
}

fn forget_in(list: &mut Vec<Pending>, path: &Path) {
    list.retain(|p| match p {
        Pending::Stage(d) | Pending::Dir(d) | Pending::File(d) => d != path,
    });
}

/// An exclusive lock on the folder `dir` for one commit (released when
/// dropped), so that two builds into one folder do not interleave their
/// renames. Where a folder cannot be opened to lock (not Unix), none.
fn lock_folder(dir: &Path) -> Option<File> {
    let f = File::open(dir).ok()?;
    f.lock().ok()?;
    Some(f)
}

/// Finishes or undoes the writes into `root` that a process left when it
/// was interrupted: each staging folder no live process holds is rolled
/// forward (its renames had begun) or removed (they had not). A staging
/// folder of a build still running is left alone.
pub fn recover(root: &Path) -> io::Result<()> {
    let Ok(entries) = fs::read_dir(root) else {
        return Ok(());
    };
    let mut stages: Vec<PathBuf> = entries
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with(PREFIX))
        .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
        .map(|e| e.path())
        .collect();
    stages.sort();
    let _turn = lock_folder(root);
    for stage in stages {
        // A lock we can take is no live process's.
        if let Ok(lock) = File::open(stage.join(LOCK)) {
            match lock.try_lock() {
                Ok(()) => {}
                Err(fs::TryLockError::WouldBlock) => continue,
                Err(fs::TryLockError::Error(_)) => {}
            }
        }
        if stage.join(MARK).is_file() {
            roll_forward(root, &stage.join("new"), Path::new(""))?;
        }
        fs::remove_dir_all(&stage)?;
    }
    Ok(())
}

/// Renames every regular file under `new/rel` to `root/rel` (links and
/// other kinds are left, and go with the staging folder).
fn roll_forward(root: &Path, new: &Path, rel: &Path) -> io::Result<()> {
    let Ok(entries) = fs::read_dir(new.join(rel)) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let rel = rel.join(e.file_name());
        let Ok(kind) = e.file_type() else { continue };
        if kind.is_dir() {
            roll_forward(root, new, &rel)?;
        } else if kind.is_file() {
            let target = root.join(&rel);
            if let Some(dir) = target.parent() {
                if super::refuse_link(dir).is_err() {
                    continue;
                }
                fs::create_dir_all(dir)?;
            }
            replace(&new.join(&rel), &target)?;
        }
    }
    Ok(())
}

/// Renames `from` over `to` (replacing a file there).
fn replace(from: &Path, to: &Path) -> io::Result<()> {
    if cfg!(windows) && fs::symlink_metadata(to).is_ok() {
        fs::remove_file(to)?;
    }
    fs::rename(from, to)
}

/// Several outputs in one folder, written all or none: each is filled into
/// the run's staging folder as it is [added](Outputs::add), and only
/// [`commit`](Outputs::commit) puts them in place (see the module docs).
/// Dropped without a commit (an error on the way), it leaves nothing.
pub struct Outputs {
    root: PathBuf,
    stage: PathBuf,
    /// Held for the staging folder's life: see [`recover`].
    _lock: File,
    files: Vec<PathBuf>,
    done: bool,
}

impl Outputs {
    /// Outputs into the folder `root` (which must exist): first finishes or
    /// undoes what an interrupted run left there ([`recover`]), then makes
    /// this run's staging folder.
    pub fn new(root: &Path) -> io::Result<Outputs> {
        recover(root)?;
        let _made = making()?;
        let mut list = pending();
        let stage = tempfile::Builder::new()
            .prefix(PREFIX)
            .tempdir_in(root)?
            .keep();
        list.push(Pending::Stage(stage.clone()));
        let lock = File::create(stage.join(LOCK))?;
        lock.lock()?;
        Ok(Outputs {
            root: root.to_path_buf(),
            stage,
            _lock: lock,
            files: Vec::new(),
            done: false,
        })
    }

    /// Fills the content of `path` (inside the output folder); the file
    /// appears at commit.
    pub fn add<F>(&mut self, path: &Path, fill: F) -> io::Result<()>
    where
        F: FnOnce(&mut dyn Write) -> io::Result<()>,
    {
        let staged = self.staged(path)?;
        let made = making()?;
        if let Some(dir) = staged.parent() {
            fs::create_dir_all(dir)?;
        }
        let file = File::create(&staged);
        drop(made);
        let result = file.and_then(|f| {
            let mut w = BufWriter::new(f);
            fill(&mut w)?;
            w.flush()
        });
        if let Err(e) = result {
            let _ = fs::remove_file(&staged);
            return Err(e);
        }
        self.files.push(path.to_path_buf());
        Ok(())
    }

    /// [`add`](Self::add) for each of `paths`, file `k` filled by
    /// `fill(k, ..)`, the files made side by side on rayon's threads (a
    /// build's step pictures: encoding and writing them one at a time
    /// left a core idle). They are added in order; the first of them to
    /// fail, in order, is the error, and none of them is then added.
    pub fn add_all<F>(&mut self, paths: &[PathBuf], fill: F) -> io::Result<()>
    where
        F: Fn(usize, &mut dyn Write) -> io::Result<()> + Sync,
    {
        use rayon::prelude::*;
        let staged = paths
            .iter()
            .map(|p| self.staged(p))
            .collect::<io::Result<Vec<_>>>()?;
        {
            let _made = making()?;
            for dir in staged.iter().filter_map(|s| s.parent()) {
                fs::create_dir_all(dir)?;
            }
        }
        let results: Vec<io::Result<()>> = staged
            .par_iter()
            .enumerate()
            .map(|(k, staged)| {
                let file = making().and_then(|_made| File::create(staged));
                file.and_then(|f| {
                    let mut w = BufWriter::new(f);
                    fill(k, &mut w)?;
                    w.flush()
                })
            })
            .collect();
        if let Some(k) = results.iter().position(Result::is_err) {
            for s in &staged {
                let _ = fs::remove_file(s);
            }
            return results.into_iter().nth(k).unwrap_or(Ok(()));
        }
        self.files.extend(paths.iter().cloned());
        Ok(())
    }

    /// Where `path` is staged: `new/` plus its place under the folder.
    fn staged(&self, path: &Path) -> io::Result<PathBuf> {
        let rel = path
            .strip_prefix(&self.root)
            .ok()
            .filter(|r| {
                r.components().count() > 0
                    && r.components().all(|c| matches!(c, Component::Normal(_)))
            })
            .ok_or_else(|| io::Error::other("not a file inside the output folder"))?;
        Ok(self.stage.join("new").join(rel))
    }

    /// The paths added so far, in order.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.iter().map(PathBuf::as_path)
    }

    /// Renames every staged file into place, all or none: a target that
    /// is a directory fails before anything moves, each file already there
    /// is moved aside first, and on any failure the new files are taken
    /// away and the old ones put back. On an error, the path that failed
    /// comes with it.
    pub fn commit(self) -> Result<(), (PathBuf, io::Error)> {
        self.commit_with(replace)
    }

    /// [`Outputs::commit`], each file put in place by `place` (a test
    /// makes it fail halfway).
    pub(super) fn commit_with(
        mut self,
        mut place: impl FnMut(&Path, &Path) -> io::Result<()>,
    ) -> Result<(), (PathBuf, io::Error)> {
        // A Ctrl-C now waits until the files are all in place or none is.
        let mut list = pending();
        let _turn = lock_folder(&self.root);
        let result = self.place_all(&mut place);
        forget_in(&mut list, &self.stage);
        let _ = fs::remove_dir_all(&self.stage);
        self.done = true;
        result
    }

    /// The renames of [`Outputs::commit_with`], undone on a failure.
    fn place_all(
        &self,
        place: &mut impl FnMut(&Path, &Path) -> io::Result<()>,
    ) -> Result<(), (PathBuf, io::Error)> {
        for path in &self.files {
            if fs::symlink_metadata(path).is_ok_and(|m| m.is_dir()) {
                return Err((
                    path.clone(),
                    io::Error::new(io::ErrorKind::IsADirectory, "a directory is in the way"),
                ));
            }
        }
        let mark = self.stage.join(MARK);
        File::create(&mark).map_err(|e| (self.root.clone(), e))?;
        let old_dir = self.stage.join("old");
        // What was done, to undo: (target, where the old file went).
        let mut placed: Vec<(&Path, Option<PathBuf>)> = Vec::new();
        for path in &self.files {
            let staged = self.staged(path).map_err(|e| (path.clone(), e))?;
            let step = (|| {
                let mut old = None;
                if fs::symlink_metadata(path).is_ok() {
                    let aside = old_dir.join(
                        staged
                            .strip_prefix(self.stage.join("new"))
                            .unwrap_or(&staged),
                    );
                    if let Some(d) = aside.parent() {
                        fs::create_dir_all(d)?;
                    }
                    fs::rename(path, &aside)?;
                    old = Some(aside);
                }
                match place(&staged, path) {
                    Ok(()) => Ok(old),
                    Err(e) => {
                        if let Some(old) = &old {
                            let _ = fs::rename(old, path);
                        }
                        Err(e)
                    }
                }
            })();
            match step {
                Ok(old) => placed.push((path, old)),
                Err(e) => {
                    for (done, old) in placed.into_iter().rev() {
                        let _ = match old {
                            Some(old) => fs::rename(&old, done),
                            None => fs::remove_file(done),
                        };
                    }
                    let _ = fs::remove_file(&mark);
                    return Err((path.clone(), e));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
impl Outputs {
    /// What a kill leaves: the staging folder as it is, its lock released.
    pub(super) fn kill(mut self) -> PathBuf {
        self.done = true;
        forget(&self.stage);
        self.stage.clone()
    }
}

impl Drop for Outputs {
    fn drop(&mut self) {
        if !self.done {
            let mut list = pending();
            forget_in(&mut list, &self.stage);
            let _ = fs::remove_dir_all(&self.stage);
        }
    }
}
