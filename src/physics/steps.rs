//! The step check: the groups of touching pieces that grew at each step
//! (see [`groups`](super::groups)), each certified by an equilibrium
//! changed from the step before near the new pieces (see
//! [`certify`](super::certify)); a group with none is solved.

use std::sync::mpsc::{Receiver, TryRecvError};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::assembly::Assembly;

use super::certify::{Certifier, Verdict};
use super::compression;
use super::groups::{jobs_for_step, Groups, Job, JobWindow};
use super::model::{past, solve_until, Contact, First, Structure};
use super::{
    weakest, Analysis, Params, Pending, PhysicsError, PieceStress, StepCheck, StepsAnalysis,
    StressMap,
};

/// How a job's answer was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Found {
    /// The group does not reach the ground: it falls, no program needed.
    Falls,
    /// Every weight passes down in compression ([`compression::holds`]).
    Certified,
    /// The program was solved.
    Solved,
}

/// A job's stress per piece, how it was found, and the seconds it took.
type Answer = (Vec<PieceStress>, Found, f64);

/// How the cost of a force program grows with its pieces: about as their
/// number to this power (interior-point iterations on a 3D-like structure,
/// each a sparse factorization: measured on bunny builds of 623 to 3,625
/// pieces).
pub const PROGRAM_GROWTH: f64 = 2.3;

/// How long past its deadline a check cut short waits for the finished
/// model's analysis (made, or made then): a small model's takes a few
/// milliseconds and is always had; a big one's (the bunny at 72 studs
/// with its columns: 152 s) is not waited for, and the check says the
/// finished model was not analysed ([`StressMap::Checked`]).
pub const GRACE: std::time::Duration = std::time::Duration::from_secs(1);

/// The time to keep, before a deadline, for the analysis of the finished
/// model that a check cut short leaves to make (by the deadline less that
/// time it is started alongside the steps, or the check stops for it),
/// estimated from the biggest program solved so far. Programs of less than a quarter of the model
/// tell nothing (their time is mostly overhead): until one of them is
/// solved, nothing is kept.
struct Reserve {
    /// Pieces of the finished model.
    total: usize,
    /// The biggest program solved: its pieces and seconds.
    biggest: Option<(usize, f64)>,
}

impl Reserve {
    fn note(&mut self, pieces: usize, found: Found, secs: f64) {
        if found == Found::Solved && self.biggest.is_none_or(|(n, _)| pieces > n) {
            self.biggest = Some((pieces, secs));
        }
    }

    /// `deadline`, less the time kept: for an analysis that runs `After`
    /// the check, all of it; for one running `Alongside` since `start`,
    /// what is left of it.
    fn cut(&self, deadline: Option<Instant>, start: Instant, when: Finishing) -> Option<Instant> {
        let (n, secs) = match self.biggest {
            Some((n, secs)) if 4 * n >= self.total => (n, secs),
            _ => return deadline,
        };
        let mut keep = secs * (self.total as f64 / n as f64).powf(PROGRAM_GROWTH);
        if when == Finishing::Alongside {
            keep = (keep - start.elapsed().as_secs_f64()).max(0.0);
        }
        let keep = Duration::try_from_secs_f64(keep).unwrap_or(Duration::MAX);
        deadline.map(|d| d.checked_sub(keep).unwrap_or(start).max(start))
    }
}

/// When the finished model's analysis is made, for [`Reserve::cut`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Finishing {
    /// Not started: after the step check, or once due.
    After,
    /// Alongside it, since the time given.
    Alongside,
}

/// Solves the jobs in parallel, in order: each job's stress per piece,
/// how it was found and the seconds its solve took. Programs stop at
/// `until` (then [`PhysicsError::Solver`]).
fn run_refs(
    s: &Structure,
    jobs: &[&Job],
    params: &Params,
    first: First,
    until: Option<Instant>,
) -> Result<Vec<Answer>, PhysicsError> {
    jobs.par_iter()
        .map(|job| {
            if !job.grounded {
                return Ok((
                    vec![PieceStress::falling(); job.pieces.len()],
                    Found::Falls,
                    0.0,
                ));
            }
            if compression::holds(s, &job.pieces) {
                return Ok((
                    vec![PieceStress::resting(); job.pieces.len()],
                    Found::Certified,
                    0.0,
                ));
            }
            let contacts: Vec<&Contact> = job.contacts.iter().map(|&k| &s.contacts[k]).collect();
            let start = Instant::now();
            solve_until(s, &job.pieces, &contacts, params, first, until)
                .map(|r| (r.stress, Found::Solved, start.elapsed().as_secs_f64()))
        })
        .collect()
}

/// Every piece of the first `n` pieces, all groups solved (in parallel),
/// each expected to stand ([`First::Within`]).
pub(super) fn solve_all(
    s: &Structure,
    n: usize,
    params: &Params,
) -> Result<Vec<PieceStress>, PhysicsError> {
    solve_all_first(s, n, params, First::Within, None)
}

/// [`solve_all`], each group's programs in the order `first`, stopped at
/// `until` (then [`PhysicsError::Solver`]).
pub(super) fn solve_all_first(
    s: &Structure,
    n: usize,
    params: &Params,
    first: First,
    until: Option<Instant>,
) -> Result<Vec<PieceStress>, PhysicsError> {
    solve_all_but(s, n, params, None, first, until).map(|(out, _)| out)
}

/// [`solve_all`], taking from `known` (stress, and whether it is exact)
/// the answer of every group whose pieces are all exact there: a group's
/// answer is exact when it was found for that very group (the same
/// pieces, so the same program). Also says whether any group was run.
fn solve_all_but(
    s: &Structure,
    n: usize,
    params: &Params,
    known: Option<(&[PieceStress], &[bool])>,
    first: First,
    until: Option<Instant>,
) -> Result<(Vec<PieceStress>, bool), PhysicsError> {
    let mut g = Groups::new();
    let (mut next, mut reused) = (0, 0);
    let jobs = jobs_for_step(s, &mut g, &mut next, n, &mut reused);
    let mut out = vec![PieceStress::falling(); n];
    let mut todo = Vec::with_capacity(jobs.len());
    for job in &jobs {
        match known {
            Some((stress, exact)) if job.pieces.iter().all(|&p| exact[p]) => {
                for &p in &job.pieces {
                    out[p] = stress[p];
                }
            }
            _ => todo.push(job),
        }
    }
    let results = run_refs(s, &todo, params, first, until)?;
    for (job, (r, _, _)) in todo.iter().zip(results) {
        for (&p, st) in job.pieces.iter().zip(r) {
            out[p] = st;
        }
    }
    Ok((out, !todo.is_empty()))
}

/// Analyses every intermediate build (the pieces of steps `1..=k`, for
/// each step `k`) and finds the first step at which something falls or
/// breaks off; with `stop_at_first_failure`, stops there.
///
/// Each step reuses what it can of the step before: a group of pieces the
/// step did not touch keeps its result; a group that stood and gained
/// only pieces whose weight goes straight down to the ground in
/// compression (each point under its centre of mass on a face of the piece
/// below, down to the ground) still stands with the same
/// clutch usage, the new pieces using none. Every other group is
/// certified (see the module docs, "Steps"): the equilibrium kept from
/// the step before, changed near the new pieces, checked against every
/// equation and bound; its pieces' usage is that equilibrium's. A group for
/// which none exists fails; it is solved, and its program's answer says
/// which pieces fall or break off. The finished build's groups are solved afresh, but for those whose program the last
/// step solved already, so [`StepsAnalysis::last`] is what
/// [`analyze`](super::analyze) gives (and the last step's check agrees
/// with it); with `stop_at_first_failure` and a failure, `last` is the
/// failing step's structure instead.
pub fn analyze_steps(
    assembly: &Assembly,
    params: &Params,
    stop_at_first_failure: bool,
) -> Result<StepsAnalysis, PhysicsError> {
    analyze_steps_within(assembly, params, stop_at_first_failure, None)
}

/// [`analyze_steps`] with a deadline: once it has passed, no further step
/// is checked ([`StepsAnalysis::complete`] is false and `steps` ends at the
/// last step checked), but the finished build is still analysed whole,
/// if that is done within [`GRACE`] of the deadline (else `last` is the
/// steps checked, [`StressMap::Checked`]); when it fails and no checked
/// step did, `first_failure` is the last step. That analysis starts, alongside the steps, at the deadline less
/// the time it is expected to take (from the biggest program solved, once
/// one has a quarter of the pieces), so that it ends near the deadline
/// while the steps go on up to it with the cores it leaves: it is then
/// [`StepsAnalysis::finished`] as well (a check that stops at a failure
/// after that point waits for it).
pub fn analyze_steps_within(
    assembly: &Assembly,
    params: &Params,
    stop_at_first_failure: bool,
    deadline: Option<Instant>,
) -> Result<StepsAnalysis, PhysicsError> {
    analyze_steps_from(assembly, params, stop_at_first_failure, deadline, 1)
}

/// [`analyze_steps_within`] for a build whose steps before `from` are
/// known to stand (checked before a change that left them as they were):
/// those steps are neither solved nor listed in
/// [`StepsAnalysis::steps`]; step `from` is solved whole, and the later
/// ones step by step as usual.
pub fn analyze_steps_from(
    assembly: &Assembly,
    params: &Params,
    stop_at_first_failure: bool,
    deadline: Option<Instant>,
    from: u32,
) -> Result<StepsAnalysis, PhysicsError> {
    analyze_steps_told(
        assembly,
        params,
        stop_at_first_failure,
        deadline,
        from,
        None,
    )
}

/// [`analyze_steps_from`], telling `tell` the steps checked so far and all
/// there are as it goes, for a progress display.
pub fn analyze_steps_told(
    assembly: &Assembly,
    params: &Params,
    stop_at_first_failure: bool,
    deadline: Option<Instant>,
    from: u32,
    tell: Option<&dyn Fn(u64, u64)>,
) -> Result<StepsAnalysis, PhysicsError> {
    let ask = Ask {
        assembly,
        params,
        stop_at_first_failure,
        deadline,
        from,
        tell,
        map: true,
        before: None,
        cancel: None,
        go: None,
    };
    check_steps(&ask, Finish::WhenDue)
}

/// [`analyze_steps_told`], with the finished model's analysis as well
/// ([`StepsAnalysis::finished`]), even when the check stops at a failure
/// before the end: for a caller that needs both, as the repairs do.
/// `known` is that analysis when the caller has it already (of this very
/// assembly, pieces in this order: what [`analyze`](super::analyze) gave).
///
/// Otherwise the finished model's programs are solved from the start,
/// alongside the steps' (so that no core waits while the biggest program
/// runs alone at the end). Either way the last step takes their answers,
/// and a check cut short by the deadline does not solve the finished
/// model again: nothing is solved twice, and the step check keeps for the
/// finished model's analysis only what is left of it (estimated as for
/// [`analyze_steps_within`]).
pub fn analyze_steps_with_finished(
    assembly: &Assembly,
    params: &Params,
    stop_at_first_failure: bool,
    deadline: Option<Instant>,
    from: u32,
    tell: Option<&dyn Fn(u64, u64)>,
    known: Option<&Analysis>,
) -> Result<StepsAnalysis, PhysicsError> {
    let finish = known.map_or(Finish::Alongside, Finish::Known);
    let ask = (stop_at_first_failure, deadline, from, tell);
    check_asked(assembly, params, ask, finish, true)
}

/// The verdict of every step, as [`analyze_steps_told`] gives it, for a
/// caller that makes the finished model's map itself (once, where a
/// repair checks a build several times): a complete check solves no
/// structure for its map, and its [`StepsAnalysis::last`] is drawn from
/// the equilibria that certified each group at its last step (the
/// programs' answers for groups that failed), as [`StepsAnalysis::map`]
/// says. A check cut short by the deadline still has the finished
/// model's program (no certificate covers it), and one that has the
/// finished model's analysis from `finish` takes it.
///
/// With `stop_at_first_failure`, a step before the last whose group the
/// certifier's whole program proves to have no equilibrium is not solved
/// again to name what fails: the pieces its proof moves are given as
/// falling (the others as they were), and the check that goes on from
/// that step (from it, whole) names them. A repair's check stops there,
/// and the repair changes the build or the rest is checked so: the
/// fandisk at 64 studs, 1,558 pieces at its failing step, spent 4.4 s
/// naming what fails there, which no repair used.
pub fn analyze_steps_verdicts(
    assembly: &Assembly,
    params: &Params,
    stop_at_first_failure: bool,
    deadline: Option<Instant>,
    from: u32,
    tell: Option<&dyn Fn(u64, u64)>,
    finish: Finish,
) -> Result<StepsAnalysis, PhysicsError> {
    let ask = (stop_at_first_failure, deadline, from, tell);
    check_asked(assembly, params, ask, finish, false)
}

/// What the step checks' public functions are asked besides the build:
/// stop at the first failure, the deadline, the first step, the progress
/// callback.
type Asked<'a> = (bool, Option<Instant>, u32, Option<&'a dyn Fn(u64, u64)>);

/// The check of [`analyze_steps_with_finished`] and
/// [`analyze_steps_verdicts`]; `map` whether the finished model's map
/// comes from its program.
fn check_asked(
    assembly: &Assembly,
    params: &Params,
    (stop_at_first_failure, deadline, from, tell): Asked<'_>,
    finish: Finish,
    map: bool,
) -> Result<StepsAnalysis, PhysicsError> {
    if let Finish::Known(a) = finish {
        if a.pieces.len() != assembly.pieces.len() {
            return Err(PhysicsError::Bug(
                "the finished model's analysis given is of another assembly".into(),
            ));
        }
    }
    let ask = Ask {
        assembly,
        params,
        stop_at_first_failure,
        deadline,
        from,
        tell,
        map,
        before: None,
        cancel: None,
        go: None,
    };
    check_steps(&ask, finish)
}

/// What a step check is asked to do (see [`analyze_steps_told`]).
struct Ask<'a> {
    assembly: &'a Assembly,
    params: &'a Params,
    stop_at_first_failure: bool,
    deadline: Option<Instant>,
    from: u32,
    tell: Option<&'a dyn Fn(u64, u64)>,
    /// A complete check solves the structure it ends at for its map
    /// (else the map is the certificates', see [`analyze_steps_verdicts`]).
    map: bool,
    /// The first half of a split check (see [`check_split`]): the steps
    /// before this one (an index into the steps) only, with nothing of
    /// the finished model's.
    before: Option<usize>,
    /// Set when the other half of a split check has found what this half
    /// would not change: this half stops at its next step.
    /// Its programs stop too (it is the check's structure's stop flag).
    cancel: Option<&'a std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Set by the first half of a split check once it has checked
    /// [`SPLIT_STEPS`] steps; the later half begins then (see
    /// [`check_split`]).
    go: Option<&'a std::sync::atomic::AtomicBool>,
}

/// When a step check makes the finished model's analysis
/// ([`StepsAnalysis::finished`]; see [`analyze_steps_verdicts`]).
#[derive(Debug, Clone, Copy)]
pub enum Finish<'a> {
    /// Alongside the steps, from the start.
    Alongside,
    /// Alongside the steps once it is due: when the check would otherwise
    /// stop to keep time for it (estimated from the biggest program solved
    /// so far, as [`analyze_steps_within`] does), which gives the check
    /// the cores the analysis leaves idle; else (a check that ends in
    /// time) after them, of the groups the last step did not solve, unless
    /// the check asks for verdicts only ([`analyze_steps_verdicts`]).
    WhenDue,
    /// Known already.
    Known(&'a Analysis),
    /// Being made on a thread of its own, since before the check: the
    /// last step is certified without it, and only a check cut short by
    /// its deadline waits for it; otherwise it is left running (and
    /// [`StepsAnalysis::finished`] empty).
    Pending(&'a Pending),
}

/// The finished model's groups, solved: each piece's stress and the
/// seconds it took.
type Finished = (Vec<PieceStress>, f64);

/// Where the finished model's analysis is.
enum State<'p> {
    /// Not started: it starts once due.
    Due,
    /// Running since `since`, its answer to come on `answer`; `due`: it
    /// was started when due, to end near the deadline.
    Running {
        answer: Receiver<Result<Finished, PhysicsError>>,
        since: Instant,
        due: bool,
    },
    /// Made, or given.
    Done(Finished),
    /// Being made outside the check ([`Finish::Pending`]).
    Pending(&'p Pending),
}

/// The finished model's analysis as the step check goes: its programs
/// are spawned on the rayon pool, from outside it ahead of the steps'
/// next programs, so that one worker takes them while the others go on
/// with the steps.
struct Finisher<'a, 'scope> {
    scope: &'a rayon::Scope<'scope>,
    s: &'scope Structure,
    params: &'scope Params,
    /// Pieces of the finished model.
    n: usize,
    state: State<'a>,
    /// Whether its programs were solved here.
    made: bool,
    /// Whether it was given made ([`Finish::Known`]): the last step's
    /// groups take its answers, exact and at no cost. Else the last step
    /// is certified as every other step is, without waiting for it: the
    /// finished model's program can take far longer than the rest of the
    /// check (the bunny at 72 studs with its support columns, 4,998
    /// pieces: 152 s, the steps' certificates 45 s), and a verdict that
    /// came from whichever of the two ended first would change with the
    /// machine's load.
    given: bool,
    /// Whether programs spawned now run beside the check: it is not on a
    /// worker of the pool (whose own queue would hold them until the
    /// check waits), and the pool has more than one worker. Else the
    /// analysis is not started when due: the check stops for it.
    overlaps: bool,
    /// Whether the check makes room for it at all (not the first half of
    /// a split check): else [`Finisher::cut`] is the deadline.
    wanted: bool,
}

impl<'a, 'scope> Finisher<'a, 'scope> {
    fn new(
        scope: &'a rayon::Scope<'scope>,
        s: &'scope Structure,
        params: &'scope Params,
        n: usize,
        finish: Finish<'a>,
    ) -> Self {
        let given = matches!(finish, Finish::Known(_));
        let state = match finish {
            Finish::Known(a) => State::Done((a.pieces.clone(), a.solve_seconds)),
            Finish::Alongside | Finish::WhenDue => State::Due,
            Finish::Pending(p) => State::Pending(p),
        };
        let mut f = Finisher {
            scope,
            s,
            params,
            n,
            state,
            made: false,
            given,
            overlaps: rayon::current_thread_index().is_none() && rayon::current_num_threads() > 1,
            wanted: true,
        };
        if matches!(finish, Finish::Alongside) {
            f.start(false);
        }
        f
    }

    fn start(&mut self, due: bool) {
        let (tx, answer) = std::sync::mpsc::channel();
        let (s, params, n) = (self.s, self.params, self.n);
        self.scope.spawn(move |_| {
            let begun = Instant::now();
            let r = solve_all(s, n, params).map(|r| (r, begun.elapsed().as_secs_f64()));
            // The check waits for it, unless it failed first.
            let _ = tx.send(r);
        });
        self.made = true;
        self.state = State::Running {
            answer,
            since: Instant::now(),
            due,
        };
    }

    /// Whether the last step takes its answers: it is made, or being made.
    fn covers_last(&self) -> bool {
        !matches!(self.state, State::Due)
    }

    /// The time by which the check stops (see [`Reserve::cut`]): when the
    /// analysis is not started, `start_when_due` starts it instead of
    /// stopping for it, and the check may then go on to the deadline.
    fn cut(
        &mut self,
        reserve: &Reserve,
        deadline: Option<Instant>,
        start: Instant,
        start_when_due: bool,
    ) -> Result<Option<Instant>, PhysicsError> {
        if !self.wanted {
            return Ok(deadline);
        }
        if let State::Running { answer, .. } = &self.state {
            match answer.try_recv() {
                Ok(r) => self.state = State::Done(r?),
                Err(TryRecvError::Empty) => {}
                Err(TryRecvError::Disconnected) => return Err(lost()),
            }
        }
        Ok(match &self.state {
            State::Due => {
                let cut = reserve.cut(deadline, start, Finishing::After);
                if start_when_due && self.overlaps && past(cut) {
                    self.start(true);
                    deadline
                } else {
                    cut
                }
            }
            State::Running {
                since, due: false, ..
            } => reserve.cut(deadline, *since, Finishing::Alongside),
            State::Pending(p) => reserve.cut(deadline, p.since(), Finishing::Alongside),
            State::Running { due: true, .. } | State::Done(_) => deadline,
        })
    }

    /// Waits for the analysis if it runs here: its answer, once made. One
    /// made outside the check ([`State::Pending`]) is not waited for: the
    /// check stopped before its last step, which did not need it.
    fn answer(&mut self) -> Result<Option<&Finished>, PhysicsError> {
        if matches!(self.state, State::Pending(_)) {
            return Ok(None);
        }
        self.wait()
    }

    /// The analysis if made by `until` (or given): made here when not
    /// started; one made here and not done by then is stopped (its solver
    /// at its next iteration), one made outside the check is left to its
    /// owner. Once `until` has passed, one made here is neither made nor
    /// looked at.
    fn made_by(&mut self, until: Instant) -> Result<Option<&Finished>, PhysicsError> {
        let stop = |flag: &Option<std::sync::Arc<std::sync::atomic::AtomicBool>>| {
            if let Some(flag) = flag {
                flag.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        };
        let late = Instant::now() >= until;
        match &self.state {
            // Too late to make it or wait for it.
            State::Due if late => {}
            State::Running { .. } if late => stop(&self.s.stop),
            State::Due => {
                // Solved here, a watchdog stopping it at `until`.
                let (done, watch) = std::sync::mpsc::channel::<()>();
                let flag = self.s.stop.clone();
                let watchdog = std::thread::spawn(move || {
                    let left = until.saturating_duration_since(Instant::now());
                    if watch.recv_timeout(left).is_err() {
                        stop(&flag);
                    }
                });
                let begun = Instant::now();
                let r = solve_all(self.s, self.n, self.params);
                let _ = done.send(());
                let _ = watchdog.join();
                self.made = true;
                match r {
                    Ok(whole) => self.state = State::Done((whole, begun.elapsed().as_secs_f64())),
                    Err(PhysicsError::Solver { .. }) if Instant::now() >= until => {}
                    Err(e) => return Err(e),
                }
            }
            State::Pending(p) => {
                if let Some(a) = p.wait_until(Some(until)).transpose()? {
                    self.state = State::Done((a.pieces, a.solve_seconds));
                }
            }
            State::Running { answer, .. } => {
                let left = until.saturating_duration_since(Instant::now());
                match answer.recv_timeout(left) {
                    Ok(r) => self.state = State::Done(r?),
                    Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => return Err(lost()),
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => stop(&self.s.stop),
                }
            }
            State::Done(_) => {}
        }
        Ok(match &self.state {
            State::Done(f) => Some(f),
            _ => None,
        })
    }

    /// Waits for the analysis if it runs: its answer, once made.
    fn wait(&mut self) -> Result<Option<&Finished>, PhysicsError> {
        if let State::Pending(p) = self.state {
            let a = p.wait()?;
            self.state = State::Done((a.pieces, a.solve_seconds));
        }
        if let State::Running { answer, .. } = &self.state {
            let r = loop {
                match answer.try_recv() {
                    Ok(r) => break r,
                    Err(TryRecvError::Disconnected) => return Err(lost()),
                    // Called from a worker of the pool, the check helps
                    // with what is queued there (the analysis itself, it
                    // may be) rather than block it.
                    Err(TryRecvError::Empty) => {
                        if rayon::yield_now() != Some(rayon::Yield::Executed) {
                            break answer.recv().map_err(|_| lost())?;
                        }
                    }
                }
            };
            self.state = State::Done(r?);
        }
        Ok(match &self.state {
            State::Done(f) => Some(f),
            _ => None,
        })
    }
}

/// The error when the finished model's analysis ended without an answer
/// (it panicked: the scope passes the panic on).
fn lost() -> PhysicsError {
    PhysicsError::Bug("the finished model's analysis ended without an answer".into())
}

/// [`analyze_steps_told`], and with `finish` [`analyze_steps_with_finished`].
fn check_steps(ask: &Ask, finish: Finish) -> Result<StepsAnalysis, PhysicsError> {
    if let Some(mid) = split_at(ask) {
        return check_split(ask, finish, mid);
    }
    check_whole(ask, finish)
}

/// Pieces a check must have past its first step for [`check_split`].
const SPLIT_PIECES: usize = 800;

/// How a step's cost in a split check is taken to grow with the pieces
/// placed (see [`split_at`]): suzanne at 60 studs (its support round's
/// check of 1,513 pieces from step 26), split at half its pieces, took 4.4
/// s for its first half and 7.9 s for its later one (which begins with a
/// program of everything before it, and shares its core with the finished
/// model's analysis for a while); at a split for a cost growing as the
/// pieces (power 2), 6.6 s and 4.9 s.
const SPLIT_POWER: f64 = 1.5;

/// Pieces the later half of a split check begins with at most, else the
/// check is not split (see [`split_at`]): its first program, of every
/// group of the structure at its first step, grows as about the 2.4th
/// power of their pieces (the bunny at 72 studs, 5,025 pieces, split at
/// 3,300: 22.1 s where one check took 19.5; at 1,500, 20.4 s).
const SPLIT_MOST: usize = 1_500;

/// Steps each half of a split check has at least.
const SPLIT_STEPS: usize = 24;

/// Where [`check_split`] splits `ask`'s check (an index into its steps),
/// if it does: a check of many steps whose later half, begun afresh, can
/// go on beside the first on a core of its own.
fn split_at(ask: &Ask) -> Option<(usize, u32)> {
    // Not for how many cores there are: the later half's equilibria
    // (the certificates' map, each step's lowest score) differ from one
    // check's, and a build gives the same report on every machine.
    if ask.before.is_some() || rayon::current_thread_index().is_some() {
        return None;
    }
    let pieces = &ask.assembly.pieces;
    // Each step's end, in build order.
    let mut ends: Vec<(u32, usize)> = Vec::new();
    for (i, p) in pieces.iter().enumerate() {
        match ends.last_mut() {
            Some((step, end)) if *step == p.step.0 => *end = i + 1,
            _ => ends.push((p.step.0, i + 1)),
        }
    }
    let k0 = ends.iter().position(|e| e.0 >= ask.from)?;
    let first = if k0 == 0 { 0 } else { ends[k0 - 1].1 };
    let n = pieces.len();
    if n - first < SPLIT_PIECES || ends.len() - k0 < 2 * SPLIT_STEPS {
        return None;
    }
    // A step's programs grow with the pieces placed: with the cost of a
    // step taken as its pieces so far to the power SPLIT_POWER, each half
    // has as much (see [`SPLIT_POWER`]).
    let weight = |x: usize| (x as f64).powf(SPLIT_POWER);
    let half = ((weight(first) + weight(n)) / 2.0).powf(1.0 / SPLIT_POWER) as usize;
    // Not past SPLIT_MOST: the later half's first program grows faster
    // than the steps it saves.
    if half > SPLIT_MOST {
        return None;
    }
    let mid = ends.iter().position(|e| e.1 >= half)?;
    (mid >= k0 + SPLIT_STEPS && ends.len() - mid >= SPLIT_STEPS).then_some((mid, ends[mid].0))
}

/// `ask`'s check in two halves, on two cores: the steps before `mid`
/// (an index into the steps; its step number `mid_step`) as [`check_whole`] checks them, and beside
/// them the steps from `mid` on, begun with every group of the structure
/// at `mid` certified whole (or solved, where it fails) and going on as
/// any check does. The two give the same verdicts as one check (each is
/// a verdict of its step, whatever equilibrium certified the step
/// before); the equilibria the later half keeps differ from one check's,
/// the same on every run. Where the first half fails and the check stops
/// at its first failure, the later half is stopped and dropped. Such a
/// check begins its later half only once the first has checked
/// [`SPLIT_STEPS`] steps without failing: a check that fails soon after
/// its start (a build's first check, or a support round's) would
/// otherwise take a core from the finished model's analysis for nothing
/// (the bunny at 48 studs: 3.4 s -> 4.4 s).
fn check_split(
    ask: &Ask,
    finish: Finish,
    (mid, mid_step): (usize, u32),
) -> Result<StepsAnalysis, PhysicsError> {
    use std::sync::atomic::{AtomicBool, Ordering};
    let start = Instant::now();
    let cancel = std::sync::Arc::new(AtomicBool::new(false));
    // Gone at once where the check goes on past a failure.
    let go = AtomicBool::new(!ask.stop_at_first_failure);
    let (assembly, params, stop, deadline, map) = (
        ask.assembly,
        ask.params,
        ask.stop_at_first_failure,
        ask.deadline,
        ask.map,
    );
    let (cancel_ref, go_ref) = (&cancel, &go);
    let (first, later) = std::thread::scope(|scope| {
        let later = scope.spawn(move || {
            let ask = Ask {
                assembly,
                params,
                stop_at_first_failure: stop,
                deadline,
                from: mid_step,
                tell: None,
                map,
                before: None,
                cancel: Some(cancel_ref),
                go: Some(go_ref),
            };
            check_whole(&ask, finish)
        });
        // A panic in the first half releases the later half, which would
        // otherwise wait for it for ever.
        let release = Release(&cancel, &go);
        let first = check_whole(
            &Ask {
                before: Some(mid),
                map: false,
                go: Some(go_ref),
                ..*ask
            },
            Finish::WhenDue,
        );
        drop(release);
        // Its failure is the check's: the later half is not wanted.
        if stop && first.as_ref().map_or(true, |a| a.first_failure.is_some()) {
            cancel.store(true, Ordering::Relaxed);
        }
        go.store(true, Ordering::Relaxed);
        let later = later.join().unwrap_or_else(|_| {
            Err(PhysicsError::Bug(
                "a half of the step check panicked".into(),
            ))
        });
        (first, later)
    });
    let a = first?;
    if !a.complete || (stop && a.first_failure.is_some()) {
        // Stopped in the first half: its check, the later half's work
        // dropped (stopped, its programs may have ended in errors), but
        // for the finished model's analysis when it made it. Cut short by
        // the deadline, the check is the finished model's where that was
        // made, as one check's would be (see `check_whole`).
        let finished = later.ok().and_then(|b| b.finished);
        let mut a = StepsAnalysis {
            seconds: start.elapsed().as_secs_f64(),
            finished,
            ..a
        };
        if !a.complete {
            if let Some(f) = &a.finished {
                a.last = f.clone();
                a.map = StressMap::Program;
                if a.first_failure.is_none() && !f.stands() {
                    a.first_failure = assembly.pieces.last().map(|p| p.step.0);
                }
            }
        }
        return Ok(a);
    }
    let b = later?;
    let mut steps = a.steps;
    steps.extend(b.steps);
    Ok(StepsAnalysis {
        steps,
        first_failure: a.first_failure.or(b.first_failure),
        last: b.last,
        seconds: start.elapsed().as_secs_f64(),
        solves: a.solves + b.solves,
        reused: a.reused + b.reused,
        certified: a.certified + b.certified,
        whole_certified: a.whole_certified + b.whole_certified,
        failures_carried: a.failures_carried + b.failures_carried,
        complete: b.complete,
        finished: b.finished,
        map: b.map,
    })
}

/// Sets both flags (a split check's `cancel` and `go`) when dropped while
/// its thread panics.
struct Release<'f>(
    &'f std::sync::atomic::AtomicBool,
    &'f std::sync::atomic::AtomicBool,
);

impl Drop for Release<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.store(true, std::sync::atomic::Ordering::Relaxed);
            self.1.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    }
}

/// [`check_steps`] in one go.
fn check_whole(ask: &Ask, finish: Finish) -> Result<StepsAnalysis, PhysicsError> {
    let start = Instant::now();
    ask.params.check()?;
    let mut s = Structure::new(ask.assembly, ask.params);
    // Set once a check cut short by its deadline gives up the finished
    // model's programs still running (the steps' own are done by then).
    s.stop = Some(ask.cancel.cloned().unwrap_or_default());
    rayon::in_place_scope(|scope| {
        let mut fin = Finisher::new(scope, &s, ask.params, ask.assembly.pieces.len(), finish);
        // The first half of a split check has nothing of the finished
        // model's to make room for.
        fin.wanted = ask.before.is_none();
        check_steps_in(ask, &s, start, &mut fin)
    })
}

/// [`check_steps`] once the structure is built, with the finished
/// model's analysis in `fin`.
fn check_steps_in(
    ask: &Ask,
    s: &Structure,
    start: Instant,
    fin: &mut Finisher,
) -> Result<StepsAnalysis, PhysicsError> {
    let Ask {
        assembly,
        params,
        stop_at_first_failure,
        deadline,
        from,
        tell,
        map,
        before,
        cancel,
        go,
    } = *ask;
    let n = assembly.pieces.len();
    let half = before.is_some();
    // A check for the verdicts that stops at its first failure leaves
    // what fails there unnamed (see [`analyze_steps_verdicts`]).
    let names = !stop_at_first_failure || map;
    // Stopped by the other half (see [`Ask::cancel`]): nothing more made.
    let mut cancelled = false;
    let stopped = || cancel.is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed));
    // (step number, end of its pieces in build order).
    let mut bounds: Vec<(u32, usize)> = Vec::new();
    for (i, p) in assembly.pieces.iter().enumerate() {
        match bounds.last_mut() {
            Some((step, end)) if *step == p.step.0 => *end = i + 1,
            _ => bounds.push((p.step.0, i + 1)),
        }
    }
    let (mut reused, mut solves, mut certified, mut carried) = (0, 0, 0, 0);
    let mut current = vec![PieceStress::falling(); n];
    // Whether each piece's entry in `current` is exact: found for the
    // group it is in now (see `solve_all_but`).
    let mut exact = vec![false; n];
    let mut steps = Vec::with_capacity(bounds.len());
    let mut first_failure = None;
    // The first step checked (the last one when `from` is past it): solved
    // whole, with every group.
    let k0 = bounds
        .iter()
        .position(|b| b.0 >= from)
        .unwrap_or(bounds.len().saturating_sub(1));
    let last_k = bounds.len().saturating_sub(1);
    // The steps' groups are made as the check reaches them, a batch ahead
    // at most: a group lists all its pieces, so keeping every step's at
    // once took memory growing with the square of the steps (a column of
    // 10,000 bricks, one a step: 1.35 GB).
    let mut window = JobWindow::new(s, &bounds, k0);
    // The seconds of the biggest program of the step checked last.
    let mut step_seconds = 0.0;
    let mut reserve = Reserve {
        total: n,
        biggest: None,
    };
    let mut begin = 0;
    let mut cert = Certifier::new(s, params).until(deadline);
    let mut complete = true;
    let total = bounds.len() as u64;
    // The later half of a split check waits for the first to get going
    // (see [`check_split`]).
    if let (Some(go), false) = (go, half) {
        while !go.load(std::sync::atomic::Ordering::Relaxed) && !stopped() {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    for (k, &(step, end)) in bounds.iter().enumerate() {
        if let (Some(go), true) = (go, half) {
            if k >= k0 + SPLIT_STEPS {
                go.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        }
        if let Some(tell) = tell {
            tell(k as u64, total);
        }
        if before.is_some_and(|b| k >= b) {
            break;
        }
        if stopped() {
            complete = false;
            cancelled = true;
            break;
        }
        if k < k0 {
            begin = end;
            continue;
        }
        if k == k0 && k0 > 0 {
            window.skip_to(k + 1);
            if past(fin.cut(&reserve, deadline, start, true)?) {
                complete = false;
                break;
            }
            // The last step, whole: the finished model, made alongside.
            let made = if k == last_k && fin.covers_last() {
                fin.wait()?.cloned()
            } else {
                None
            };
            match made {
                Some((whole, secs)) => {
                    step_seconds = secs;
                    current[..end].copy_from_slice(&whole);
                    exact[..end].fill(true);
                }
                None => {
                    // Each group of it certified whole (the kept forces
                    // the steps after change); the programs name what
                    // fails in the others.
                    let begun = Instant::now();
                    let (mut g, mut next, mut none) = (Groups::new(), 0, 0);
                    let jobs = jobs_for_step(s, &mut g, &mut next, end, &mut none);
                    cert.place_to(end);
                    let mut late = Vec::new();
                    for job in &jobs {
                        // A group off the ground is not asked: the
                        // program names what falls.
                        let took = if job.grounded {
                            take_certificate(&mut cert, job, 0, &mut current, &mut exact)
                        } else {
                            Took::Unknown
                        };
                        match took {
                            Took::Stands => certified += 1,
                            Took::Fails
                                if !names
                                    && k != last_k
                                    && mark_proved(&cert, job, 0, &mut current, &mut exact) => {}
                            _ => late.push(job),
                        }
                    }
                    let Some(done) = solve_late(
                        s,
                        &late,
                        (params, deadline, cancel),
                        &mut current,
                        &mut exact,
                        &mut reserve,
                    )?
                    else {
                        complete = false;
                        cancelled = stopped();
                        break;
                    };
                    solves += done.solves;
                    certified += done.certified;
                    step_seconds = begun.elapsed().as_secs_f64();
                }
            }
            steps.push(check(step, &current[..end]));
            begin = end;
            if !steps[steps.len() - 1].stands {
                first_failure = Some(step);
                if stop_at_first_failure {
                    break;
                }
            }
            continue;
        }
        // The finished model's analysis, if not made yet, starts by the
        // time it takes before the deadline, so that the two end near it.
        if past(fin.cut(&reserve, deadline, start, true)?) {
            complete = false;
            break;
        }
        window.make_to(k + 1);
        let jobs = window.take(k);
        cert.place_to(end);
        step_seconds = 0.0;
        let mut late = Vec::new();
        for job in &jobs {
            let stood = job
                .pieces
                .iter()
                .all(|&p| p >= begin || !current[p].fails());
            let fresh: Vec<usize> = job.pieces.iter().copied().filter(|&p| p >= begin).collect();
            if job.grounded && stood && cert.spread_down(&fresh, true).is_some() {
                // Straight down in pushes alone: no clutch used anew.
                for &p in &fresh {
                    current[p] = PieceStress::resting();
                }
                // It stands, but its answer need not be the program's.
                for &p in &job.pieces {
                    exact[p] = false;
                }
                reused += 1;
            } else if !job.grounded || k == last_k && fin.given {
                late.push(job);
            } else if !stood && k != last_k && cert.still_fails(job, &fresh) {
                // Still failing by the proof kept from a step before: its
                // pieces that failed then are named again, the new ones
                // not. (Not at the last step, whose answers are the map
                // of a check that draws it from its own: there the
                // program names what fails.)
                for &p in &fresh {
                    current[p] = PieceStress::resting();
                }
                for &p in &job.pieces {
                    exact[p] = false;
                }
                carried += 1;
            } else {
                match take_certificate(&mut cert, job, begin, &mut current, &mut exact) {
                    Took::Stands => certified += 1,
                    // Where the check stops here, what fails is named
                    // by the check that goes on from this step.
                    Took::Fails
                        if !names
                            && k != last_k
                            && mark_proved(&cert, job, begin, &mut current, &mut exact) => {}
                    // The program's answer says which pieces fail.
                    _ => late.push(job),
                }
            }
        }
        if k == last_k && fin.given {
            if let Some((whole, secs)) = fin.wait()? {
                // The finished model's groups: its answers, exact.
                if !late.is_empty() {
                    step_seconds = *secs;
                }
                for job in late.drain(..) {
                    // Exact: a group the program fails has no equilibrium
                    // within capacity (see `model::solve_until`).
                    for &p in &job.pieces {
                        current[p] = whole[p];
                        exact[p] = true;
                    }
                }
            }
        }
        // Not started once the last step's programs are solved or about
        // to be: it would solve them again.
        let due = k != last_k;
        if !late.is_empty() && past(fin.cut(&reserve, deadline, start, due)?) {
            complete = false;
            break;
        }
        // No certificate found: expected to fail. Its programs stop at
        // the deadline (the fandisk at 96 studs: a group of thousands of
        // pieces at step 189 took its check 28 s past it), and the check
        // is then cut there.
        let Some(done) = solve_late(
            s,
            &late,
            (params, deadline, cancel),
            &mut current,
            &mut exact,
            &mut reserve,
        )?
        else {
            complete = false;
            cancelled = stopped();
            break;
        };
        solves += done.solves;
        certified += done.certified;
        step_seconds = step_seconds.max(done.seconds);
        steps.push(check(step, &current[..end]));
        begin = end;
        if first_failure.is_none() && !steps[steps.len() - 1].stands {
            first_failure = Some(step);
            if stop_at_first_failure {
                break;
            }
        }
    }
    if half || cancelled {
        // The first half, or a later half stopped: its steps, and the
        // structure it ended at.
        return Ok(StepsAnalysis {
            steps,
            first_failure,
            last: Analysis::new(current[..begin].to_vec(), step_seconds),
            seconds: start.elapsed().as_secs_f64(),
            solves,
            reused,
            certified,
            whole_certified: cert.found[cert.found.len() - 1],
            failures_carried: carried,
            complete,
            finished: None,
            map: StressMap::Checked,
        });
    }
    // The steps not reached still count their groups that did not grow.
    let reused = reused + window.finish();
    // The finished build (or the failing step) afresh; past the deadline,
    // the finished build.
    let end = if complete { begin } else { n };
    // One being made outside the check is waited for only when the check
    // needs the finished model at its last step; a check cut short by its
    // deadline takes it if made within [`GRACE`] of it.
    let finished = match (complete, deadline) {
        (false, Some(d)) => fin.made_by(d + GRACE)?.cloned(),
        _ => fin.answer()?.cloned(),
    };
    solves += usize::from(fin.made);
    // A complete check has found the last step's groups already, most of
    // them exactly: only the others are solved again.
    let (last, last_seconds, drawn) = match &finished {
        Some((whole, secs)) if end == n => (whole.clone(), *secs, StressMap::Program),
        // The verdicts only: the map of the certificates that gave them.
        _ if complete && !map => (
            current[..end].to_vec(),
            step_seconds,
            StressMap::Certificates,
        ),
        // Cut short, the finished model not analysed by the deadline: the
        // steps checked, as their certificates and programs left them.
        _ if !complete => (current[..begin].to_vec(), step_seconds, StressMap::Checked),
        _ => {
            let known = complete.then_some((&current[..end], &exact[..end]));
            let begun = Instant::now();
            let (last, ran) = solve_all_but(s, end, params, known, First::Within, None)?;
            solves += usize::from(ran);
            // What the finished build's programs take: as solved now, or
            // as the last step checked solved them.
            let secs = if ran {
                begun.elapsed().as_secs_f64()
            } else {
                step_seconds
            };
            (last, secs, StressMap::Program)
        }
    };
    if !complete && first_failure.is_none() && last.iter().any(PieceStress::fails) {
        // Unchecked steps in between: the finished build is known to fail.
        first_failure = assembly.pieces.last().map(|p| p.step.0);
    }
    if complete {
        if let Some(c) = steps.last_mut() {
            *c = check(c.step, &last);
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    Ok(StepsAnalysis {
        steps,
        first_failure,
        last: Analysis::new(last, last_seconds),
        seconds,
        solves,
        reused,
        certified,
        whole_certified: cert.found[cert.found.len() - 1],
        failures_carried: carried,
        complete,
        finished: finished.map(|(whole, secs)| Analysis::new(whole, secs)),
        map: drawn,
    })
}

/// What [`solve_late`] ran: programs solved, answers found without one,
/// and the seconds of the longest.
struct Late {
    solves: usize,
    certified: usize,
    seconds: f64,
}

/// The programs of the groups `late` of a step (no certificate holds
/// them: expected to fail), whose answers name what fails: each piece's
/// stress into `current`, exact. `None` when they were cut short by the
/// deadline, or stopped with the other half of a split check (`cancel`).
fn solve_late(
    s: &Structure,
    late: &[&Job],
    (params, deadline, cancel): (
        &Params,
        Option<Instant>,
        Option<&std::sync::Arc<std::sync::atomic::AtomicBool>>,
    ),
    current: &mut [PieceStress],
    exact: &mut [bool],
    reserve: &mut Reserve,
) -> Result<Option<Late>, PhysicsError> {
    let stopped = || cancel.is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed));
    let results = match run_refs(s, late, params, First::Least, deadline) {
        Err(PhysicsError::Solver { .. }) if past(deadline) || stopped() => return Ok(None),
        r => r?,
    };
    let mut done = Late {
        solves: results.iter().filter(|r| r.1 == Found::Solved).count(),
        certified: results.iter().filter(|r| r.1 == Found::Certified).count(),
        seconds: 0.0,
    };
    for (job, (r, found, secs)) in late.iter().zip(results) {
        reserve.note(job.pieces.len(), found, secs);
        done.seconds = done.seconds.max(secs);
        for (&p, st) in job.pieces.iter().zip(r) {
            current[p] = st;
            exact[p] = true;
        }
    }
    Ok(Some(done))
}

/// What [`take_certificate`] found for a group.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Took {
    /// It stands: its pieces' stress taken.
    Stands,
    /// The whole group's program proved it has no equilibrium.
    Fails,
    /// Neither: the solver gave no answer.
    Unknown,
}

/// Certifies `job` (its pieces from `begin` on are new) by the kept
/// equilibrium changed near the new pieces: when one is found, its
/// pieces' stress goes into `current`, not exact (one equilibrium of
/// many).
fn take_certificate(
    cert: &mut Certifier,
    job: &Job,
    begin: usize,
    current: &mut [PieceStress],
    exact: &mut [bool],
) -> Took {
    let new: Vec<usize> = job.pieces.iter().copied().filter(|&p| p >= begin).collect();
    let stress = match cert.certify(job, &new) {
        Verdict::Stands(stress) => stress,
        Verdict::Fails => return Took::Fails,
        Verdict::Unknown => return Took::Unknown,
    };
    for (&p, st) in job.pieces.iter().zip(stress) {
        current[p] = st;
        exact[p] = false;
    }
    Took::Stands
}

/// For a check that stops at its first failure and only says where (see
/// [`analyze_steps_verdicts`]): group `job`, which the certifier's whole
/// program has just proved to have no equilibrium, is marked failing
/// without the program that would name what fails in it. The pieces its proof moves
/// fall; its new pieces (from `begin` on) that stay still rest; the rest
/// keep their stress of the step before. False, with nothing marked,
/// where the proof moves none of them.
fn mark_proved(
    cert: &Certifier,
    job: &Job,
    begin: usize,
    current: &mut [PieceStress],
    exact: &mut [bool],
) -> bool {
    if !job.pieces.iter().any(|&p| cert.moves(p)) {
        return false;
    }
    for &p in &job.pieces {
        if cert.moves(p) {
            current[p] = PieceStress::falling();
        } else if p >= begin {
            current[p] = PieceStress::resting();
        }
        exact[p] = false;
    }
    true
}

/// The check of one intermediate build from its pieces' stress.
pub(super) fn check(step: u32, placed: &[PieceStress]) -> StepCheck {
    StepCheck {
        step,
        min_score: placed.iter().map(|p| p.score).fold(1.0, f64::min),
        stands: !placed.iter().any(PieceStress::fails),
        weakest: weakest(placed, super::WEAKEST),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::{Placed, Placement, Step};
    use crate::catalog::{Color, PartKind};
    use crate::geom::{Cell, Rot};

    /// A wall one stud deep and 32 long, of 1 x 4 bricks in running bond,
    /// `courses` high, a course a step; and a 1 x 1 brick in the air, with
    /// nothing under or over it, at step `floating` (it falls there and
    /// at every step after).
    fn wall(courses: i32, floating: Option<u32>) -> Assembly {
        let brick = |id: &str, x: i32, z: i32, step: u32| Placed {
            placement: Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0),
            step: Step(step),
            color: Color::RED,
        };
        let mut pieces = Vec::new();
        for z in 0..courses {
            let step = z as u32 + 1;
            let xs: Vec<i32> = if z % 2 == 0 {
                (0..8).map(|i| 4 * i).collect()
            } else {
                (0..7).map(|i| 4 * i + 2).collect()
            };
            pieces.extend(xs.into_iter().map(|x| brick("3010", x, z, step)));
            if floating == Some(step) {
                pieces.push(brick("3005", 40, z + 3, step));
            }
        }
        Assembly {
            pieces,
            layer_ldu: 24,
        }
    }

    fn ask(asm: &Assembly, params: &Params, stop: bool, from: u32) -> Ask<'static> {
        // Leaked for the test: an `Ask` borrows what it checks.
        let asm: &'static Assembly = Box::leak(Box::new(asm.clone()));
        let params: &'static Params = Box::leak(Box::new(*params));
        Ask {
            assembly: asm,
            params,
            stop_at_first_failure: stop,
            deadline: None,
            from,
            tell: None,
            map: false,
            before: None,
            cancel: None,
            go: None,
        }
    }

    #[test]
    fn a_check_split_in_two_halves_gives_the_verdicts_of_one() {
        let params = Params::default();
        let verdicts = |c: &StepsAnalysis| {
            c.steps
                .iter()
                .map(|c| (c.step, c.stands))
                .collect::<Vec<_>>()
        };
        for (floating, stop, from) in [
            (None, false, 1),
            (None, true, 12),
            (Some(20), true, 1),
            (Some(20), false, 1),
            (Some(90), true, 1),
            (Some(90), false, 5),
        ] {
            let asm = wall(130, floating);
            assert!(asm.pieces.len() >= SPLIT_PIECES);
            let a = ask(&asm, &params, stop, from);
            let (mid, mid_step) = split_at(&a).expect("split");
            assert!(mid > 40 && mid < 110, "{mid}");
            let one = check_whole(&a, Finish::WhenDue).unwrap();
            let two = check_split(&a, Finish::WhenDue, (mid, mid_step)).unwrap();
            let case = (floating, stop, from);
            assert_eq!(two.first_failure, one.first_failure, "{case:?}");
            assert_eq!(one.first_failure, floating, "{case:?}");
            assert_eq!(verdicts(&two), verdicts(&one), "{case:?}");
            assert!(two.complete && one.complete, "{case:?}");
            assert_eq!(two.last.pieces.len(), one.last.pieces.len(), "{case:?}");
            assert_eq!(two.last.stands(), one.last.stands(), "{case:?}");
        }
    }

    #[test]
    fn a_verdicts_check_stopping_at_a_proved_failure_marks_it_without_naming_it() {
        // A 1 x 6 held by one stud at the end of a 1 x 4, with almost no
        // clutch: it breaks off at step 2; a 1 x 2 on the base follows.
        let params = Params::default().with_clutch_n(1e-4);
        let at = |id: &str, x, z| {
            Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0)
        };
        let order = [at("3010", 0, 0), at("3009", 3, 1), at("3004", 0, 1)];
        let asm = Assembly::from_order(&order, 24, Color::RED);
        let exact = analyze_steps(&asm, &params, true).unwrap();
        let verdicts =
            analyze_steps_verdicts(&asm, &params, true, None, 1, None, Finish::WhenDue).unwrap();
        assert_eq!(exact.first_failure, Some(2));
        assert_eq!(verdicts.first_failure, Some(2));
        // The exact check names what fails with a program; the verdicts'
        // takes the certifier's proof, which moves the overhang.
        assert!(exact.solves > 0);
        assert_eq!(verdicts.solves, 0);
        let failing = &verdicts.steps.last().unwrap();
        assert!(!failing.stands && failing.weakest.contains(&1));
        // Going on from there names it as the exact check does.
        let rest =
            analyze_steps_verdicts(&asm, &params, false, None, 2, None, Finish::WhenDue).unwrap();
        assert_eq!(rest.steps[0], exact.steps[1]);
    }

    #[test]
    fn the_reserve_grows_with_the_model_from_the_biggest_program_solved() {
        let start = Instant::now();
        let end = start + Duration::from_secs(100);
        let deadline = Some(end);
        let mut r = Reserve {
            total: 1000,
            biggest: None,
        };
        // Nothing solved yet, or only programs too small to tell: the
        // deadline as it is.
        assert_eq!(r.cut(deadline, start, Finishing::After), deadline);
        r.note(200, Found::Solved, 0.5);
        assert_eq!(r.cut(deadline, start, Finishing::After), deadline);
        // Neither answers found without a solve nor smaller programs count.
        r.note(900, Found::Certified, 0.0);
        r.note(500, Found::Solved, 2.0);
        r.note(400, Found::Solved, 9.0);
        assert_eq!(r.biggest, Some((500, 2.0)));
        // Twice the pieces: 2 s * 2^2.3 = 9.85 s kept.
        let cut = r.cut(deadline, start, Finishing::After).unwrap();
        let kept = (end - cut).as_secs_f64();
        assert!(
            (kept - 2.0 * 2f64.powf(PROGRAM_GROWTH)).abs() < 1e-6,
            "{kept}"
        );
        // Made alongside the check, started 5 s ago: what is left of it is
        // kept.
        let earlier = start.checked_sub(Duration::from_secs(5)).unwrap();
        let cut = r.cut(deadline, earlier, Finishing::Alongside).unwrap();
        let kept = (end - cut).as_secs_f64();
        assert!(
            (kept - (2.0 * 2f64.powf(PROGRAM_GROWTH) - 5.0)).abs() < 0.5,
            "{kept}"
        );
        // More than the time there is: the check stops at once.
        r.note(600, Found::Solved, 500.0);
        assert_eq!(r.cut(deadline, start, Finishing::After), Some(start));
        assert_eq!(r.cut(None, start, Finishing::After), None);
    }
}
