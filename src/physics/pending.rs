//! The finished model's analysis on a thread of its own: started as soon
//! as the model is known, waited for only where its answer is needed, and
//! stopped when the model it was made for is given up (a repair changed
//! it). The step check certifies its last step without it
//! ([`Finish::Pending`](super::Finish::Pending)) and waits for it only when
//! cut short by its deadline; a check that stops at an earlier failure
//! leaves it running.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Instant;

use crate::assembly::Assembly;

use super::model::{Progress, Structure};
use super::{steps, Analysis, Params, PhysicsError};

/// The answer's slot, and the signal that it is filled.
type Slot = (Mutex<Option<Result<Analysis, PhysicsError>>>, Condvar);

/// Puts `r` in `slot` and says so to whoever waits.
fn fill(slot: &Slot, r: Result<Analysis, PhysicsError>) {
    let (lock, signal) = slot;
    *lock
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner) = Some(r);
    signal.notify_all();
}

/// An [`analyze`](super::analyze) of one assembly, running on its own
/// thread (with a pool of one worker, so that it never holds a worker of
/// the shared pool the step check needs). Its clones share it; dropping
/// the last one stops the solver at its next iteration.
#[derive(Debug, Clone)]
pub struct Pending(Arc<Inner>);

#[derive(Debug)]
struct Inner {
    pieces: usize,
    since: Instant,
    stop: Arc<AtomicBool>,
    progress: Arc<Progress>,
    answer: Arc<Slot>,
}

/// The interior-point iterations a program of a finished model is taken
/// to need, at least, when judging whether it can end in time (the
/// bunny's and suzanne's at 48-72 studs took 55-83; one whose model needs
/// a hand, 192).
const ITERATIONS: u32 = 60;

impl Pending {
    /// Starts the analysis of `assembly` (a copy of it is taken).
    pub fn start(assembly: &Assembly, params: &Params) -> Pending {
        let stop = Arc::new(AtomicBool::new(false));
        let progress = Arc::new(Progress::default());
        let answer: Arc<Slot> = Arc::new((Mutex::new(None), Condvar::new()));
        let (asm, params) = (assembly.clone(), *params);
        let (flag, slot) = (Arc::clone(&stop), Arc::clone(&answer));
        let told = Arc::clone(&progress);
        let spawned = std::thread::Builder::new()
            .name("finished model".into())
            .spawn(move || {
                let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    analyze_stopping(&asm, &params, flag, told)
                }))
                .unwrap_or_else(|_| {
                    Err(PhysicsError::Bug(
                        "the finished model's analysis panicked".into(),
                    ))
                });
                fill(&slot, r);
            });
        if let Err(e) = spawned {
            let why = format!("no thread for the finished model's analysis: {e}");
            fill(&answer, Err(PhysicsError::Bug(why)));
        }
        Pending(Arc::new(Inner {
            pieces: assembly.pieces.len(),
            since: Instant::now(),
            stop,
            progress,
            answer,
        }))
    }

    /// Whether it may still end by `deadline`: made, or not far enough
    /// along to tell, or its program's iterations so far, at the pace of
    /// every iteration since it started, leave time for the rest of at
    /// least `ITERATIONS`, 60 (and a few more). False when it cannot: its
    /// answer is then not worth waiting for.
    pub fn may_end_by(&self, deadline: Instant) -> bool {
        use std::sync::atomic::Ordering::Relaxed;
        let total = self.0.progress.total.load(Relaxed);
        let current = self.0.progress.current.load(Relaxed);
        if total < 5 || self.stands().is_some() {
            return true;
        }
        let pace = self.0.since.elapsed().as_secs_f64() / f64::from(total);
        let left = f64::from(ITERATIONS.saturating_sub(current).max(5)) * pace;
        Instant::now() + std::time::Duration::from_secs_f64(left.min(1e9)) < deadline
    }

    /// The pieces of the assembly analysed.
    pub fn pieces(&self) -> usize {
        self.0.pieces
    }

    /// When it started.
    pub fn since(&self) -> Instant {
        self.0.since
    }

    /// Whether the model stands, once its analysis is made (`None` until
    /// then, or when it failed: [`Pending::wait`] says why).
    pub fn stands(&self) -> Option<bool> {
        let (lock, _) = &*self.0.answer;
        let slot = lock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        slot.as_ref()
            .and_then(|r| r.as_ref().ok())
            .map(Analysis::stands)
    }

    /// Whether the model is known to fail: its analysis made and failing,
    /// or one of its groups' programs within capacity answered that it has
    /// no equilibrium (the program of least usage, which says what fails,
    /// may run a while longer: suzanne at 60 studs, 0.9 s then 2.8 s).
    pub fn known_to_fail(&self) -> bool {
        self.stands() == Some(false) || self.0.progress.fails.load(Ordering::Relaxed)
    }

    /// Its answer, once made (blocking until then).
    pub fn wait(&self) -> Result<Analysis, PhysicsError> {
        self.wait_until(None)
            .expect("no deadline: the answer comes")
    }

    /// Its answer, if made by `deadline` (`None`: waits until it is).
    pub fn wait_until(&self, deadline: Option<Instant>) -> Option<Result<Analysis, PhysicsError>> {
        let (lock, signal) = &*self.0.answer;
        let mut slot = lock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        loop {
            if let Some(r) = slot.as_ref() {
                return Some(r.clone());
            }
            slot = match deadline {
                None => signal
                    .wait(slot)
                    .unwrap_or_else(std::sync::PoisonError::into_inner),
                Some(d) => {
                    let left = d.saturating_duration_since(Instant::now());
                    if left.is_zero() {
                        return None;
                    }
                    signal
                        .wait_timeout(slot, left)
                        .unwrap_or_else(std::sync::PoisonError::into_inner)
                        .0
                }
            };
        }
    }
}

impl Drop for Inner {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

/// [`analyze`](super::analyze), its solver stopped once `stop` is set,
/// on a pool of one worker of its own.
fn analyze_stopping(
    assembly: &Assembly,
    params: &Params,
    stop: Arc<AtomicBool>,
    progress: Arc<Progress>,
) -> Result<Analysis, PhysicsError> {
    let start = Instant::now();
    params.check()?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| PhysicsError::Bug(format!("a thread for the finished model: {e}")))?;
    let mut s = Structure::new(assembly, params);
    s.stop = Some(stop);
    s.progress = Some(progress);
    let pieces = pool.install(|| steps::solve_all(&s, assembly.pieces.len(), params))?;
    Ok(Analysis::new(pieces, start.elapsed().as_secs_f64()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Placement;
    use crate::catalog::{Color, PartKind};
    use crate::geom::{Cell, Rot};

    /// A 1x4 on the table, and a 1x6 clutched to its end, hanging past
    /// it with nothing to balance it: it breaks off.
    fn overhang() -> Assembly {
        let at = |id: &str, x, z| {
            Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0)
        };
        Assembly::from_order(&[at("3010", 0, 0), at("3009", 3, 1)], 24, Color::RED)
    }

    #[test]
    fn a_pending_analysis_is_the_analysis_and_its_clones_share_it() {
        let (asm, params) = (overhang(), Params::default());
        let whole = super::super::analyze(&asm, &params).unwrap();
        let p = Pending::start(&asm, &params);
        let q = p.clone();
        assert_eq!(p.pieces(), 2);
        let made = p.wait().unwrap();
        assert_eq!(made.pieces, whole.pieces);
        assert_eq!(q.stands(), Some(whole.stands()));
        assert!(!whole.stands(), "{whole:?}");
        assert!(q.known_to_fail());
        // Made: a deadline passed long ago still gets it.
        let again = q.wait_until(Some(p.since())).unwrap().unwrap();
        assert_eq!(again.pieces, whole.pieces);
    }

    #[test]
    fn a_model_is_known_to_fail_once_its_program_within_capacity_has_no_answer() {
        // The overhang: its program within capacity has none (the flag is
        // set before the program of least usage names what fails).
        let progress = Arc::new(Progress::default());
        let stop = Arc::new(AtomicBool::new(false));
        let made = analyze_stopping(&overhang(), &Params::default(), stop, Arc::clone(&progress));
        assert!(!made.unwrap().stands());
        assert!(progress.fails.load(Ordering::Relaxed));
        // The 1x4 alone stands: never set.
        let base = Assembly {
            pieces: overhang().pieces[..1].to_vec(),
            ..overhang()
        };
        let progress = Arc::new(Progress::default());
        let stop = Arc::new(AtomicBool::new(false));
        let made = analyze_stopping(&base, &Params::default(), stop, Arc::clone(&progress));
        assert!(made.unwrap().stands());
        assert!(!progress.fails.load(Ordering::Relaxed));
        let p = Pending::start(&base, &Params::default());
        p.wait().unwrap();
        assert!(!p.known_to_fail());
    }

    #[test]
    fn a_dropped_pending_analysis_stops() {
        let stop = Arc::new(AtomicBool::new(true));
        // Stopped before it starts: the solver gives up at its first
        // iteration, and says so.
        let r = analyze_stopping(&overhang(), &Params::default(), stop, Default::default());
        assert!(matches!(r, Err(PhysicsError::Solver { .. })), "{r:?}");
        let p = Pending::start(&overhang(), &Params::default());
        let flag = Arc::clone(&p.0.stop);
        drop(p);
        assert!(flag.load(Ordering::Relaxed));
    }
}
