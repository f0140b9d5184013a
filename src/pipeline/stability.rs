//! The build's stability stage: check every step with the force analysis
//! of [`crate::physics`], repair what fails, and report.
//!
//! `--stability repair` (the default) fixes weak spots in three ways, each
//! checked again before it is kept:
//! - **order**: when the finished model stands but a step before the end
//!   does not, the pieces that fail are deferred until the structure holds
//!   them ([`crate::physics::repair::reorder`]);
//! - **supports**: where the model still fails, support columns (2 x 2
//!   where there is room, else narrower) in a colour of their own go under
//!   what it cannot hold itself, one failing step at a time in build
//!   order ([`crate::physics::support::shore_up`]); `--no-supports` leaves
//!   them out;
//! - **layout**: when it still fails, the search runs again with other
//!   seeds (another layout of the same voxels) and the layout that stands
//!   longest is kept; where that one still fails, it gets support columns
//!   of its own (the fandisk at 32 studs with `--plates`: kept seed 3's
//!   layout, failing at step 4 without, standing at every step with one
//!   support piece).
//!
//! What still fails is reported, with whether the build would stand on a
//! baseplate. `--stability check` reports and fails the build;
//! `--stability off` skips the stage.

use std::time::{Duration, Instant};

use serde::Serialize;

use crate::assembly::verify::verify;
use crate::assembly::{Assembly, Placement};
use crate::catalog::Color;
use crate::physics::repair::{reorder_while, Moved, MAX_REPAIRED_STEP};
use crate::physics::support::{shore_up, steps_of, support_color, Column, Upto, MAX_COLUMNS};
use crate::physics::{
    analyze, analyze_if_stands, analyze_steps_verdicts, Analysis, Finish, Ground, Params, Pending,
    PhysicsError, StepsAnalysis, StressMap, GRACE,
};
use crate::search::SearchOutcome;

/// How often the wait for the finished model's map looks at how far its
/// program is (see [`Pending::may_end_by`]).
const LOOK: Duration = Duration::from_millis(250);

/// What the stability stage does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stability {
    /// Check every step and fix what fails (the default).
    #[default]
    Repair,
    /// Check every step; a build that fails is an error.
    Check,
    /// No check.
    Off,
}

impl Stability {
    /// The option's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Stability::Repair => "repair",
            Stability::Check => "check",
            Stability::Off => "off",
        }
    }
}

/// The order repair may take at most this share (one over it) of the
/// time left.
const ORDER_SHARE: u32 = 4;

/// Other layouts the repair tries when the finished model fails.
pub const RESEEDS: u64 = 3;

/// Weak pieces listed in the report.
const WEAKEST: usize = 10;

/// A piece in the report: where it is and how hard its clutch works.
#[derive(Debug, Clone, Serialize)]
pub struct WeakPiece {
    /// Its place in the build order, from 1 (its line among the `.ldr`'s
    /// pieces).
    pub piece: usize,
    /// The step that adds it.
    pub step: u32,
    /// LDraw part.
    pub part: &'static str,
    /// The part's name.
    pub name: &'static str,
    /// Stud column, stud row and layer of its minimum corner.
    pub at: [i32; 3],
    /// Share of its clutch capacity used (1 or more breaks off).
    pub usage: f64,
    /// It cannot be held at all (it would fall or tip over).
    pub falls: bool,
}

/// One step's check.
#[derive(Debug, Clone, Serialize)]
pub struct StepRow {
    /// The step.
    pub step: u32,
    /// The lowest score of the structure after this step (1 − usage).
    pub min_score: f64,
    /// Everything holds.
    pub stands: bool,
}

/// How a build stood before repairs.
#[derive(Debug, Clone, Serialize)]
pub struct Before {
    /// The first step at which something would fall or break off.
    pub first_failure: Option<u32>,
    /// The finished model's lowest score; `None` when it was not
    /// analysed: support columns went in first (the analysis of the model
    /// without them, made on a core of its own, is stopped then).
    pub min_score: Option<f64>,
    /// The finished model stands (`None`: not analysed, as above).
    pub final_stands: Option<bool>,
}

/// The `stability` section of `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct StabilityReport {
    /// `repair` or `check`.
    pub mode: &'static str,
    /// Clutch capacity a stud, newtons.
    pub clutch_n_per_stud: f64,
    /// Every step stands, the finished model included.
    pub stands: bool,
    /// The first step at which something would fall or break off.
    pub first_failure: Option<u32>,
    /// That step and its weak pieces, in one line.
    pub failure: Option<String>,
    /// The finished model's lowest score (1 − the highest share of clutch
    /// capacity used).
    pub min_score: f64,
    /// The finished model's mean score.
    pub mean_score: f64,
    /// The finished model's highest share of clutch capacity used.
    pub max_usage: f64,
    /// The finished model's weakest pieces, weakest first.
    pub weakest: Vec<WeakPiece>,
    /// The check of every step.
    pub steps: Vec<StepRow>,
    /// What the repair changed, in words; empty when nothing did.
    pub repairs: Vec<String>,
    /// Pieces the repair moved to a later step.
    pub moved: Vec<Moved>,
    /// Support columns the repair added, in build order.
    pub supports: Vec<Column>,
    /// Pieces the support columns are made of.
    pub support_pieces: usize,
    /// The seed of the layout kept, when the repair searched again.
    pub reseeded: Option<u64>,
    /// Whether the layout kept was laid again with no inverted slope in
    /// its lowest course (see [`crate::search::SearchOptions::flat_base`]).
    pub flat_base: bool,
    /// How the build stood before repairs, when it was repaired.
    pub before: Option<Before>,
    /// When the build still fails on a table: whether it would stand at
    /// every step on a baseplate (which holds the bottom course's studs).
    pub stands_on_baseplate: Option<bool>,
    /// Every step was checked; false when the stage's time budget
    /// (`--stability-budget`) ran out first (the finished model is always
    /// analysed).
    pub complete: bool,
    /// Steps checked.
    pub steps_checked: usize,
    /// Force programs solved (whole groups).
    pub solves: usize,
    /// Groups whose answer was reused from the step before, or whose new
    /// pieces' weight drops straight to the table.
    pub reused: usize,
    /// Groups certified standing by a change to the equilibrium of the
    /// step before (see docs/stability.md).
    pub certified: usize,
    /// Of those, the groups whose change took the program of the whole
    /// group (no region near the new pieces had one).
    pub whole_certified: usize,
    /// Groups found still failing after a failed step by the proof made
    /// there, without a program (see docs/stability.md).
    pub failures_carried: usize,
    /// Where the finished model's usages (`min_score`, `max_usage`,
    /// `weakest`, the stress picture) come from: `program`, the force
    /// program with one answer; `certificates`, the equilibria that
    /// certified its groups at the last step, when that program would not
    /// have ended within the budget.
    pub stress_map: StressMap,
}

/// A planned build: the search's outcome and its verified, grouped
/// assembly, with the name of its order.
pub type Plan = (SearchOutcome, Assembly, &'static str);

/// Runs the stage on `plan`. `supports`: the repair may add support
/// columns. `replan(seed, flat, until)` searches again with another seed,
/// with no inverted slope in the lowest course if `flat` (see
/// [`crate::search::SearchOptions::flat_base`]); a backward trace there
/// ends by `until` (a layout's search keeps its own budget). `tell` hears
/// how many of the plan's steps the first check has covered, for a
/// progress display. Returns the plan to write, possibly repaired, and the
/// report.
#[allow(clippy::too_many_arguments)]
pub fn settle(
    mode: Stability,
    plan: Plan,
    seed: u64,
    params: &Params,
    budget: Duration,
    supports: bool,
    replan: &dyn Fn(u64, bool, Instant) -> Result<Plan, crate::pipeline::BuildError>,
    tell: Option<&dyn Fn(u64, u64)>,
) -> Result<(Plan, StabilityReport, Analysis), crate::pipeline::BuildError> {
    // A budget too large for the clock is no budget (about 31 years).
    let deadline = Instant::now() + budget.min(Duration::from_secs(1_000_000_000));
    let mut counts = Counts::default();
    let first = attempt(
        plan,
        params,
        mode == Stability::Repair,
        deadline,
        &mut counts,
        tell,
        None,
    )?;
    // Before any repair: an order repair kept in the first attempt has
    // made its check stand where the first failed.
    let unrepaired_failure = first
        .check
        .first_failure
        .or(first.order_fix.as_ref().and(first.order_tried));
    let mut before = Before {
        first_failure: unrepaired_failure,
        min_score: None,
        // The order repair kept in the first attempt certified its last
        // step, the finished model (the same pieces in another order).
        final_stands: (first.order_fix.is_some() && first.check.first_failure.is_none())
            .then_some(true),
    };
    // A first check that failed at the last step has checked the finished
    // model: it fails, and its analysis there is the check's last.
    let last_step = first.plan.1.pieces.last().map(|p| p.step.0);
    if before.first_failure.is_some()
        && before.first_failure == last_step
        && first.check.last.pieces.len() == first.plan.1.pieces.len()
    {
        before.min_score = Some(first.check.last.min_score);
        before.final_stands = Some(false);
    }
    let mut best = first;
    // How the finished model stood before repairs, for the report: its
    // analysis may still be being made (on a core of its own, while the
    // repairs go on), and a repair drops the attempt it was made for.
    let mut unrepaired = if before.first_failure.is_some() {
        best.finished
            .clone()
            .map(Ok)
            .or_else(|| best.pending.clone().map(Err))
    } else {
        None
    };
    let mut reseeded = None;
    let mut flat_base = false;
    let mut repairs = Vec::new();
    // Support columns first: they keep the model's own layout.
    let mut shored = Shoring::default();
    if supports && mode == Stability::Repair && best.check.first_failure.is_some() {
        // The model without columns, if not analysed yet, is not: one
        // program at a time beside the check.
        unrepaired = unrepaired.filter(Result::is_ok);
        shored = support(
            &mut best,
            params,
            deadline,
            &mut counts,
            Shoring::default(),
            false,
        )?;
    }
    if mode == Stability::Repair && best.check.first_failure.is_some() {
        // Other layouts of the same voxels; the first that stands at every
        // step (after its own order repair) is kept, else the best tried.
        let mut tried = 0;
        // Another layout is worth its search only if its finished model
        // can be analysed by the deadline (about as long as this one's,
        // which must be made by then: while it is being made, how long it
        // takes is not known).
        let analysis = best.analysis_time_by(params, deadline, &mut counts)?;
        // Last, where the lowest course has inverted slopes, the same seed
        // with none there: a keel of them stands on their back rows only
        // (the glider at 48 studs with `--slopes` tipped over at step 6 on
        // one, and stands on a flat one). After the other seeds, which
        // may stand with no column (the bunny at 48 studs, seed 2).
        let keeled = keel(&best.plan.1);
        let layouts = (1..=RESEEDS)
            .map(|k| (seed.wrapping_add(k), false))
            .chain(keeled.then_some((seed, true)));
        for (other, flat) in layouts {
            if analysis.is_none_or(|a| Instant::now() + a >= deadline) {
                break;
            }
            tried += 1;
            // A layout that cannot be verified is not a candidate, nor a
            // backward trace that found no derivation: it searches until
            // there is time left to analyse what it finds.
            let until = analysis
                .and_then(|a| deadline.checked_sub(a))
                .unwrap_or(deadline);
            let planned = match replan(other, flat, until) {
                Ok(p) => p,
                Err(
                    crate::pipeline::BuildError::Unverified { .. }
                    | crate::pipeline::BuildError::Search {
                        reason: crate::search::SearchError::Backward { .. },
                        ..
                    },
                ) => continue,
                Err(e) => return Err(e),
            };
            // The finished model first: one analysis rules most layouts
            // out. One that fails scores none (its lowest score 0), no
            // more than the layout kept: the program within capacity
            // alone says so (the one naming what fails took as long
            // again: the cow at 64 studs, 0.5 s a layout). The same voxels
            // on a flat base are kept for what their columns do: the
            // finished model may need them too.
            counts.solves += 1;
            let last = if flat {
                analyze(&planned.1, params)?
            } else {
                match analyze_if_stands(&planned.1, params)? {
                    Some(last) => last,
                    None => continue,
                }
            };
            let mut candidate = attempt(
                planned,
                params,
                true,
                deadline,
                &mut counts,
                None,
                Some(last),
            )?;
            // Compared with the first layout as shored up, the flat one is
            // shored up first too.
            let mut own = Shoring::default();
            if flat && supports && candidate.check.first_failure.is_some() {
                own = support(&mut candidate, params, deadline, &mut counts, own, false)?;
            }
            if candidate.better_than(&mut best, params, &mut counts)? {
                best = candidate;
                reseeded = Some(other);
                flat_base = flat;
                shored = own;
            }
            if best.check.first_failure.is_none() {
                break;
            }
        }
        // The layout kept in place of the shored one gets its own
        // columns where it still fails. Last, columns under pieces hung
        // from others, which move to stand on them: they change the steps
        // around them, so they come only where neither the other columns
        // nor another layout made every step stand (the bunny at 32 studs
        // stands on seed 2's layout with no column rather than on seed
        // 1's with three).
        for moves in [false, true] {
            if supports && best.check.first_failure.is_some() && (moves || reseeded.is_some()) {
                shored = support(
                    &mut best,
                    params,
                    deadline,
                    &mut counts,
                    std::mem::take(&mut shored),
                    moves,
                )?;
            }
        }
        let outcome = if best.check.first_failure.is_none() {
            "it stands at every step"
        } else {
            "it fails later or less"
        };
        if flat_base {
            repairs.push(format!(
                "layout: the search laid the same voxels again with no inverted slope in the lowest course, which stands on the table, and kept that ({outcome})"
            ));
        } else if let Some(other) = reseeded {
            repairs.push(format!(
                "layout: the search tried other layouts of the same voxels and kept seed {other}'s ({outcome})"
            ));
        } else if tried == 0 {
            repairs.push(
                "layout: the stability budget ran out before other layouts of the same voxels could be tried"
                    .to_string(),
            );
        } else {
            repairs.push(format!(
                "layout: none of {tried} other layout{} of the same voxels did better",
                if tried == 1 { "" } else { "s" }
            ));
        }
    }
    if let Some(first) = unrepaired.take() {
        // Not made by the deadline, it is left out of the report.
        let f = match first {
            Ok(known) => Some(known),
            Err(pending) => {
                let made = pending.wait_until(Some(deadline)).transpose()?;
                counts.solves += usize::from(made.is_some());
                made
            }
        };
        if let Some(f) = f {
            before.min_score = Some(f.min_score);
            before.final_stands = Some(f.stands());
        }
    }
    // The order repair was tried on the first layout while its finished
    // model's analysis was being made: only one that stands has an order
    // to repair (another layout's was known before its repair).
    let order_tried = best
        .order_tried
        .filter(|_| reseeded.is_some() || before.final_stands == Some(true));
    if mode == Stability::Repair && before.first_failure.is_some() {
        match (&best.order_fix, order_tried) {
            (Some(moved), _) => repairs.push(format!(
                "order: {} pieces moved to later steps, where the structure holds them",
                moved.len()
            )),
            (None, Some(step)) if best.check.first_failure.is_some() => repairs.push(format!(
                "order: step {step} would not stand, and deferring its weak pieces (at most {MAX_REPAIRED_STEP} pieces a step) did not help"
            )),
            _ => {}
        }
        if !shored.columns.is_empty() {
            let color = shored
                .color
                .and_then(Color::spec)
                .map_or("a colour of their own", |c| c.name);
            repairs.push(format!(
                "supports: {} column{} ({}; {} pieces, {}) under what the model cannot hold itself{}",
                shored.columns.len(),
                if shored.columns.len() == 1 { "" } else { "s" },
                sizes(&shored.columns),
                best.supports.len(),
                color.to_lowercase(),
                if best.check.first_failure.is_none() {
                    ""
                } else {
                    "; not enough to make every step stand"
                }
            ));
        }
    }
    // A check that stopped at its first failure: the rest of it.
    check_the_rest(&mut best, params, deadline, &mut counts)?;
    // The finished model's map, once: its program's, unless that would not
    // end by the deadline.
    let stress_map = map_finished(
        &mut best.check,
        (&mut best.finished, &mut best.pending),
        (&best.plan.1, MAP_PIECES),
        params,
        deadline,
        &mut counts,
    )?;
    let mut on_baseplate = None;
    if best.check.first_failure.is_some()
        && params.ground == Ground::Table
        && Instant::now() < deadline
    {
        // What a person can still do: build on a baseplate, whose studs
        // hold the bottom course.
        let base = Params {
            ground: Ground::Baseplate,
            ..*params
        };
        let c = analyze_steps_verdicts(
            &best.plan.1,
            &base,
            true,
            Some(deadline),
            1,
            None,
            Finish::WhenDue,
        )?;
        counts.add(&c);
        on_baseplate = c.complete.then_some(c.first_failure.is_none());
    }
    let Attempt {
        plan,
        check,
        order_fix,
        supports,
        ..
    } = best;
    let repaired = mode == Stability::Repair && before.first_failure.is_some();
    let report = report(
        mode,
        params,
        &plan.1,
        &check,
        repairs,
        order_fix.unwrap_or_default(),
        (shored.columns, supports.len()),
        (reseeded, flat_base),
        repaired.then_some(before),
        on_baseplate,
        counts,
        stress_map,
    );
    Ok((plan, report, check.last))
}

/// Analyses run, and results reused.
#[derive(Default)]
struct Counts {
    solves: usize,
    reused: usize,
    certified: usize,
    whole_certified: usize,
    failures_carried: usize,
}

impl Counts {
    fn add(&mut self, c: &StepsAnalysis) {
        self.solves += c.solves;
        self.reused += c.reused;
        self.certified += c.certified;
        self.whole_certified += c.whole_certified;
        self.failures_carried += c.failures_carried;
    }
}

/// One layout, checked and, when `repair`, its order repaired.
struct Attempt {
    plan: Plan,
    check: StepsAnalysis,
    /// `check` stopped at its first failure before the end: its `last` is
    /// the failing structure.
    partial: bool,
    /// The finished model's analysis, once made.
    finished: Option<Analysis>,
    /// The finished model's analysis, while it is being made (on a
    /// thread of its own, see [`Pending`]); `None` once `finished` is.
    pending: Option<Pending>,
    /// The pieces the order repair moved, when it was kept.
    order_fix: Option<Vec<Moved>>,
    /// The step the order repair tried and could not fix.
    order_tried: Option<u32>,
    /// The support columns' pieces in it.
    supports: Vec<Placement>,
}

impl Attempt {
    /// How long the finished model's analysis took (zero when not made;
    /// while it is being made, how long it has taken so far).
    fn analysis_time(&self) -> Duration {
        // Capped at about 31 years, so that adding it to a time is safe.
        let secs = match (&self.finished, &self.pending) {
            (Some(f), _) => f.solve_seconds,
            (None, Some(p)) => p.since().elapsed().as_secs_f64(),
            (None, None) => 0.0,
        };
        Duration::from_secs_f64(secs.clamp(0.0, 1e9))
    }

    /// How long the finished model's analysis took, once it is made by
    /// `deadline` (started if it is not being made, and waited for until
    /// then); `None` if it is not made by then.
    fn analysis_time_by(
        &mut self,
        params: &Params,
        deadline: Instant,
        counts: &mut Counts,
    ) -> Result<Option<Duration>, crate::pipeline::BuildError> {
        let made = self.finished_by(params, deadline, counts)?.is_some();
        Ok(made.then(|| self.analysis_time()))
    }

    /// The finished model's analysis for a step check: known, or being
    /// made.
    fn finish(&self) -> Finish<'_> {
        finish_of(self.finished.as_ref(), self.pending.as_ref())
    }

    /// Takes the finished model's analysis from a check of it (`check`,
    /// or its own when `None`), when that made it or waited for it.
    fn take_finished(&mut self, check: Option<&mut StepsAnalysis>, counts: &mut Counts) {
        let made = check.unwrap_or(&mut self.check).finished.take();
        if let Some(f) = made {
            if self.finished.is_none() {
                self.finished = Some(f);
                if self.pending.take().is_some() {
                    counts.solves += 1;
                }
            }
        }
    }

    /// Stands at more steps: the finished model first, then more of the
    /// model's own pieces built before the first failure (counted in
    /// pieces, not steps: support columns add steps), then a higher lowest
    /// score.
    fn better_than(
        &mut self,
        other: &mut Attempt,
        params: &Params,
        counts: &mut Counts,
    ) -> Result<bool, crate::pipeline::BuildError> {
        let mut key = |a: &mut Attempt| -> Result<_, crate::pipeline::BuildError> {
            let progress = a.progress();
            let f = a.finished(params, counts)?;
            Ok((f.stands(), progress, f.min_score))
        };
        let (a, b) = (key(self)?, key(other)?);
        Ok(a.partial_cmp(&b) == Some(std::cmp::Ordering::Greater))
    }

    /// The finished model's analysis if made by `until` (being made, or
    /// started now if it is not).
    fn finished_by(
        &mut self,
        params: &Params,
        until: Instant,
        counts: &mut Counts,
    ) -> Result<Option<&Analysis>, crate::pipeline::BuildError> {
        if self.finished.is_none() {
            let pending = self
                .pending
                .get_or_insert_with(|| Pending::start(&self.plan.1, params));
            if let Some(made) = made_in_time(pending, until) {
                counts.solves += 1;
                self.finished = Some(made?);
                self.pending = None;
            }
        }
        Ok(self.finished.as_ref())
    }

    /// The finished model's analysis, made if not yet.
    fn finished(
        &mut self,
        params: &Params,
        counts: &mut Counts,
    ) -> Result<&Analysis, crate::pipeline::BuildError> {
        if self.finished.is_none() {
            counts.solves += 1;
            self.finished = Some(match self.pending.take() {
                Some(p) => p.wait()?,
                None => analyze(&self.plan.1, params)?,
            });
        }
        Ok(self.finished.as_ref().expect("just made"))
    }

    /// The model's own pieces (not support columns) in the steps before
    /// the first failure (or the first step not checked); all of them when
    /// none fails.
    fn progress(&self) -> usize {
        let supports: std::collections::HashSet<&Placement> = self.supports.iter().collect();
        // Past the budget, the steps not checked count as not standing.
        let fails = match (self.check.first_failure, self.check.complete) {
            (Some(step), _) => step,
            (None, true) => u32::MAX,
            (None, false) => self.check.steps.last().map_or(0, |s| s.step + 1),
        };
        self.plan
            .1
            .pieces
            .iter()
            .filter(|p| p.step.0 < fails && !supports.contains(&p.placement))
            .count()
    }
}

/// Checks every step of `plan` and, when `repair` and only the steps
/// before the end fail, tries the order repair on it. A check for a
/// repair stops at the first failure, which is what the repairs work on
/// (the rest is checked at the end, see [`check_the_rest`]); the finished
/// model is analysed alongside the steps, unless its analysis is
/// `finished` already.
fn attempt(
    plan: Plan,
    params: &Params,
    repair: bool,
    deadline: Instant,
    counts: &mut Counts,
    tell: Option<&dyn Fn(u64, u64)>,
    finished: Option<Analysis>,
) -> Result<Attempt, crate::pipeline::BuildError> {
    // The finished model is analysed on a core of its own from the start,
    // unless known: the check certifies its last step without it (the map
    // and the repairs wait for it, within the deadline), and a check that
    // stops at an earlier failure goes on to the repairs while it is made.
    let pending = finished.is_none().then(|| Pending::start(&plan.1, params));
    let mut at = Attempt {
        check: analyze_steps_verdicts(
            &plan.1,
            params,
            repair,
            Some(deadline),
            1,
            tell,
            finish_of(finished.as_ref(), pending.as_ref()),
        )?,
        plan,
        partial: false,
        finished,
        pending,
        order_fix: None,
        order_tried: None,
        supports: Vec::new(),
    };
    counts.add(&at.check);
    at.take_finished(None, counts);
    at.partial = stopped_early(&at.plan.1, &at.check);
    let in_time = Instant::now() < deadline;
    // The order repair, unless the finished model is known to fail (no
    // order makes every step stand then); while its analysis is still
    // being made, the repair is tried, and kept only if it stands.
    let known_to_fail = at.finished.as_ref().is_some_and(|f| !f.stands());
    if let (true, true, false, Some(step)) =
        (repair, in_time, known_to_fail, at.check.first_failure)
    {
        at.order_tried = Some(step);
        // The order repair walks the later steps with an analysis each:
        // on a big build it may not finish, and must leave time for the
        // support columns.
        // While the finished model's analysis is being made, the repair
        // goes on beside it, and gives up once it knows the model fails
        // (a group's program within capacity has no answer: the repair is
        // kept only if the model stands).
        let now = Instant::now();
        let share = now + deadline.saturating_duration_since(now) / ORDER_SHARE;
        let pending = at.pending.clone();
        let go = || Instant::now() < share && pending.as_ref().is_none_or(|p| !p.known_to_fail());
        if let Some(r) = reorder_while(&at.plan.1, params, step, &go)? {
            counts.solves += r.solves;
            counts.certified += r.certified;
            if verify(&r.assembly, Some(&at.plan.0.voxels)).is_ok() {
                // The walk's certificates, where it certified every step
                // it kept; else every step checked again.
                let c = match walked(&at.check, step, &r) {
                    Some(c) => c,
                    None => {
                        let c = analyze_steps_verdicts(
                            &r.assembly,
                            params,
                            true,
                            Some(deadline),
                            1,
                            None,
                            Finish::WhenDue,
                        )?;
                        counts.add(&c);
                        c
                    }
                };
                if c.complete && later(c.first_failure, at.check.first_failure) {
                    // Kept only if the finished model stands: certified at
                    // the last step, or known within the grace after the
                    // deadline, or not kept. A model too big for its map
                    // to be the program's does not wait for that program
                    // once its last step is certified (the bunny at 60
                    // studs, 3,061 pieces: the program of its pieces in
                    // the order before is dropped).
                    let until = deadline + GRACE;
                    let certified = c.first_failure.is_none()
                        && at.finished.is_none()
                        && at.plan.1.pieces.len() > MAP_PIECES;
                    if certified {
                        at.pending = None;
                        order_kept(&mut at, r, c)?;
                    } else if at
                        .finished_by(params, until, counts)?
                        .is_some_and(Analysis::stands)
                    {
                        order_kept(&mut at, r, c)?;
                    } else {
                        at.order_tried = None;
                    }
                }
            }
        }
    }
    Ok(at)
}

/// The finished model's analysis for a step check: `finished` when known,
/// else `pending` when it is being made, else made when due.
fn finish_of<'a>(finished: Option<&'a Analysis>, pending: Option<&'a Pending>) -> Finish<'a> {
    match (finished, pending) {
        (Some(f), _) => Finish::Known(f),
        (None, Some(p)) => Finish::Pending(p),
        (None, None) => Finish::WhenDue,
    }
}

/// Keeps the order repair `r` in `at`, whose check of it is `c`.
fn order_kept(
    at: &mut Attempt,
    r: crate::physics::repair::Reordered,
    c: StepsAnalysis,
) -> Result<(), crate::pipeline::BuildError> {
    // The same pieces in another order: the finished model's analysis
    // follows it (when made: else the check certified it).
    if let Some(f) = &at.finished {
        let finished = reindexed(f, &at.plan.1, &r.assembly)
            .ok_or_else(|| PhysicsError::Bug("the order repair lost a piece".into()))?;
        at.finished = Some(finished);
    }
    at.order_fix = Some(r.moved);
    at.plan.1 = r.assembly;
    at.partial = stopped_early(&at.plan.1, &c);
    at.check = c;
    Ok(())
}

/// The check of the order repair `r` of a build whose check `first`
/// stopped at its first failure, `step`, made of the walk's certificates
/// (see [`crate::physics::repair::Reordered::walked`]): the first
/// check's steps before `step` (the same pieces in the same steps), then
/// the walk's. `None` where the walk did not certify every step it kept.
fn walked(
    first: &StepsAnalysis,
    step: u32,
    r: &crate::physics::repair::Reordered,
) -> Option<StepsAnalysis> {
    let w = r.walked.as_ref()?;
    let mut steps: Vec<_> = first
        .steps
        .iter()
        .take_while(|c| c.step < step)
        .cloned()
        .collect();
    steps.extend(w.steps.iter().cloned());
    // Numbered 1, 2, ... as the new order's steps are.
    let numbered = steps.iter().zip(1..).all(|(c, k)| c.step == k && c.stands)
        && r.assembly.pieces.last().map(|p| p.step.0) == Some(steps.len() as u32)
        && w.last.pieces.len() == r.assembly.pieces.len();
    numbered.then(|| StepsAnalysis {
        steps,
        first_failure: None,
        last: w.last.clone(),
        seconds: 0.0,
        solves: 0,
        reused: 0,
        certified: 0,
        whole_certified: 0,
        failures_carried: 0,
        complete: true,
        finished: None,
        map: StressMap::Certificates,
    })
}

/// `a`, an analysis of the pieces of `before`, in the order of `after`
/// (the same pieces, reordered); `None` when they are not the same.
fn reindexed(a: &Analysis, before: &Assembly, after: &Assembly) -> Option<Analysis> {
    let at: std::collections::HashMap<&Placement, usize> = before
        .pieces
        .iter()
        .enumerate()
        .map(|(i, p)| (&p.placement, i))
        .collect();
    if after.pieces.len() != before.pieces.len() || a.pieces.len() != before.pieces.len() {
        return None;
    }
    let pieces = after
        .pieces
        .iter()
        .map(|p| at.get(&p.placement).map(|&i| a.pieces[i]))
        .collect::<Option<Vec<_>>>()?;
    Some(Analysis {
        pieces,
        ..a.clone()
    })
}

/// Whether `check` stopped at a failure before the last step of `asm`
/// (its `last` is then the failing structure, not the finished model).
fn stopped_early(asm: &Assembly, check: &StepsAnalysis) -> bool {
    let last_step = asm.pieces.last().map_or(0, |p| p.step.0);
    check.complete && check.first_failure.is_some_and(|f| f < last_step)
}

/// Completes a check that stopped at its first failure: the steps after
/// it, and the finished model as its `last`; past the deadline, only the
/// finished model's analysis takes `last`'s place, if made within
/// [`GRACE`] of it (else `last` stays the failing structure).
fn check_the_rest(
    best: &mut Attempt,
    params: &Params,
    deadline: Instant,
    counts: &mut Counts,
) -> Result<(), crate::pipeline::BuildError> {
    if !best.partial {
        return Ok(());
    }
    let Some(from) = best.check.first_failure else {
        return Ok(());
    };
    if Instant::now() < deadline {
        // The finished model's analysis: known, or being made on a core
        // of its own (started now if it is not): a check cut short by the
        // deadline does not make it again.
        if best.finished.is_none() && best.pending.is_none() {
            best.pending = Some(Pending::start(&best.plan.1, params));
        }
        let mut c = analyze_steps_verdicts(
            &best.plan.1,
            params,
            false,
            Some(deadline),
            from,
            None,
            best.finish(),
        )?;
        counts.add(&c);
        best.take_finished(Some(&mut c), counts);
        if c.first_failure.is_some() {
            best.check = spliced(&best.check, from, c);
            best.partial = false;
            return Ok(());
        }
    }
    // Past the deadline: the finished model's analysis if made within
    // the grace, else the failing structure stays the check's last.
    if let Some(f) = best.finished_by(params, deadline + GRACE, counts)? {
        best.check.last = f.clone();
        best.check.map = StressMap::Program;
    } else {
        best.check.map = StressMap::Checked;
    }
    best.check.complete = false;
    best.partial = false;
    Ok(())
}

/// Gives `check`, complete, of `assembly`, the finished model's map from
/// the force program, once: `finished` when made already, else the one
/// `pending` (started now if none is), if it ends by `deadline` (then
/// kept in `finished`); else the map stays the certificates', and so it
/// does for a model of more than `most` pieces (see [`MAP_PIECES`]: the
/// program being made is dropped). Returns where the map comes from.
fn map_finished(
    check: &mut StepsAnalysis,
    (finished, pending): (&mut Option<Analysis>, &mut Option<Pending>),
    (assembly, most): (&Assembly, usize),
    params: &Params,
    deadline: Instant,
    counts: &mut Counts,
) -> Result<StressMap, crate::pipeline::BuildError> {
    let n = assembly.pieces.len();
    if check.map == StressMap::Program || check.last.pieces.len() != n {
        return Ok(check.map);
    }
    if n > most {
        *pending = None;
        return Ok(StressMap::Certificates);
    }
    let made = match finished {
        Some(f) => f,
        // Past the deadline, none is started.
        None if pending.is_none() && Instant::now() >= deadline => {
            return Ok(StressMap::Certificates);
        }
        None => {
            let job = pending
                .take()
                .unwrap_or_else(|| Pending::start(assembly, params));
            // Not made by the deadline, or seen not to end by then (at
            // the pace of its iterations so far): dropped, it stops.
            let Some(made) = made_in_time(&job, deadline) else {
                return Ok(StressMap::Certificates);
            };
            counts.solves += 1;
            finished.insert(made?)
        }
    };
    if !check.take_map(made) {
        return Err(
            PhysicsError::Bug("the finished model's map is of another build".into()).into(),
        );
    }
    Ok(StressMap::Program)
}

/// The analysis `job` once made by `deadline`; `None` if it is not, or as
/// soon as it is seen not to end by then at the pace of its iterations so
/// far ([`Pending::may_end_by`]): the bunny at 96 studs (11,696 pieces)
/// waited out the whole budget for a program of several times that.
fn made_in_time(
    job: &Pending,
    deadline: Instant,
) -> Option<Result<Analysis, crate::physics::PhysicsError>> {
    loop {
        let soon = deadline.min(Instant::now() + LOOK);
        if let Some(made) = job.wait_until(Some(soon)) {
            return Some(made);
        }
        if Instant::now() >= deadline || !job.may_end_by(deadline) {
            return None;
        }
    }
}

/// Pieces past which the finished model's map is drawn from the
/// certificates, its program not solved for it: the program grows as
/// about the 2.4th power of the pieces of its biggest group (on one core,
/// the bunny at 48 studs, 1,681 pieces, 2.9 s; at 64, 3,621 pieces, 21 s;
/// at 72, 5,025 pieces, 83 s), past what the whole stage's check takes
/// (the bunny at 72 studs about 30 s), for a picture. A size, not a
/// clock, so that the same build always draws the same map.
const MAP_PIECES: usize = 3_000;

/// The columns' footprints in words: "3 of 2 x 2, 1 of 1 x 1".
fn sizes(columns: &[Column]) -> String {
    let mut counts: std::collections::BTreeMap<std::cmp::Reverse<[i32; 2]>, usize> =
        Default::default();
    for c in columns {
        *counts.entry(std::cmp::Reverse(c.size)).or_default() += 1;
    }
    counts
        .iter()
        .map(|(std::cmp::Reverse([x, y]), n)| format!("{n} of {x} x {y}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The support columns kept (their pieces are [`Attempt::supports`]), and
/// their colour.
#[derive(Default)]
struct Shoring {
    columns: Vec<Column>,
    color: Option<Color>,
}

/// Adds support columns to `best` where it still fails, one failing step
/// at a time in build order (the finished model being the last step):
/// columns under the step's structure, then a check from the first step
/// they change on to the next failure only, which the next round props.
/// A round is kept only if more of the model's own pieces stand; at the
/// end, the steps not yet checked are, so that the report has them all.
/// `kept`: the columns `best` has already (and their colour); `moves`:
/// columns may go under hung pieces, which move onto them (see
/// [`shore_up`]).
fn support(
    best: &mut Attempt,
    params: &Params,
    deadline: Instant,
    counts: &mut Counts,
    mut kept: Shoring,
    moves: bool,
) -> Result<Shoring, crate::pipeline::BuildError> {
    let color = kept.color.unwrap_or_else(|| support_color(&best.plan.1));
    kept.color = Some(color);
    // A round analyses the model at least twice (before and with its
    // columns): one that cannot end by the deadline does not start.
    let round = 2 * best.analysis_time();
    while Instant::now() + round < deadline && kept.columns.len() < MAX_COLUMNS {
        let Some(target) = best.check.first_failure else {
            break;
        };
        let asm = &best.plan.1;
        let Some(shored) = shore_up(
            asm,
            params,
            Upto::Failing(target),
            kept.columns.len(),
            color,
            Some(deadline),
            moves,
        )?
        else {
            break;
        };
        counts.solves += shored.solves;
        // The model's voxels and the columns' cells: the cover to verify.
        let mut cover = best.plan.0.voxels.clone();
        let bodies: Vec<_> = best
            .supports
            .iter()
            .chain(&shored.pieces)
            .map(|p| p.body(asm.layer_ldu))
            .collect();
        if !bodies.iter().all(|b| b.cells().all(|c| cover.in_bounds(c))) {
            break;
        }
        for b in &bodies {
            cover.set_body(b, true);
        }
        if !verify(&shored.assembly, Some(&cover)).is_ok() {
            break;
        }
        // Steps before the first column stand as they did. The finished
        // model with the columns is analysed on a core of its own from
        // now, for its map if the round is the last (the model without
        // them needs no more of its own).
        let from = first_change(asm, &shored.assembly);
        best.pending = None;
        let job = (shored.assembly.pieces.len() <= MAP_PIECES)
            .then(|| Pending::start(&shored.assembly, params));
        let mut c = analyze_steps_verdicts(
            &shored.assembly,
            params,
            true,
            Some(deadline),
            from,
            None,
            job.as_ref().map_or(Finish::WhenDue, Finish::Pending),
        )?;
        counts.add(&c);
        // Out of time part way: the columns are still kept if the steps
        // checked stand further than before (the report then says the
        // check is incomplete), and no round follows.
        let out_of_time = !c.complete;
        let supports: Vec<Placement> = best
            .supports
            .iter()
            .chain(&shored.pieces)
            .copied()
            .collect();
        let order_fix = best
            .order_fix
            .as_ref()
            .map(|m| renumbered(m, asm, &shored.assembly, &supports));
        let partial = stopped_early(&shored.assembly, &c);
        // The finished model's analysis, when the check made it: `last`
        // is its program's (a check cut short), or it was made alongside
        // the steps.
        let whole = c.last.pieces.len() == shored.assembly.pieces.len();
        let program = whole && c.map == StressMap::Program;
        let made = c.finished.take();
        counts.solves += usize::from(made.is_some());
        let finished = made.or_else(|| program.then(|| c.last.clone()));
        let candidate = Attempt {
            plan: (best.plan.0.clone(), shored.assembly, best.plan.2),
            check: spliced(&best.check, from, c),
            partial,
            pending: job.filter(|_| finished.is_none()),
            finished,
            order_fix,
            order_tried: best.order_tried,
            supports,
        };
        if candidate.progress() <= best.progress() {
            break;
        }
        *best = candidate;
        kept.columns.extend(shored.columns);
        if out_of_time {
            break;
        }
    }
    steps_of(&best.plan.1, &mut kept.columns);
    Ok(kept)
}

/// Whether the lowest course of `asm` has an inverted slope in it (see
/// [`crate::search::SearchOptions::flat_base`]).
fn keel(asm: &Assembly) -> bool {
    let bottom = asm.pieces.iter().map(|p| p.placement.origin.z).min();
    asm.pieces.iter().any(|p| {
        Some(p.placement.origin.z) == bottom && p.placement.part.spec().shape.is_inverted()
    })
}

/// The first step of `after` that differs from `before` (1 when none
/// does).
fn first_change(before: &Assembly, after: &Assembly) -> u32 {
    after
        .pieces
        .iter()
        .zip(&before.pieces)
        .find(|(a, b)| a != b)
        .map_or(1, |(a, _)| a.step.0)
}

/// The check `c` from step `from` on, after the rows of `old` before it
/// (which all stand: `from` is at or before `old`'s first failure).
fn spliced(old: &StepsAnalysis, from: u32, c: StepsAnalysis) -> StepsAnalysis {
    let mut steps: Vec<_> = old
        .steps
        .iter()
        .filter(|s| s.step < from)
        .cloned()
        .collect();
    steps.extend(c.steps);
    StepsAnalysis { steps, ..c }
}

/// `moved` with its target steps as numbered in `after`, which is `before`
/// with support columns (`supports`) added.
fn renumbered(
    moved: &[Moved],
    before: &Assembly,
    after: &Assembly,
    supports: &[Placement],
) -> Vec<Moved> {
    let supports: std::collections::HashSet<&Placement> = supports.iter().collect();
    let mut step_map = std::collections::HashMap::new();
    let own = |a: &'_ Assembly| {
        a.pieces
            .iter()
            .filter(|p| !supports.contains(&p.placement))
            .map(|p| p.step.0)
            .collect::<Vec<_>>()
    };
    for (old, new) in own(before).into_iter().zip(own(after)) {
        step_map.entry(old).or_insert(new);
    }
    moved
        .iter()
        .map(|m| Moved {
            to_step: step_map.get(&m.to_step).copied().unwrap_or(m.to_step),
            ..m.clone()
        })
        .collect()
}

/// `a` fails later than `b` (`None`: never).
fn later(a: Option<u32>, b: Option<u32>) -> bool {
    match (a, b) {
        (None, Some(_)) => true,
        (Some(x), Some(y)) => x > y,
        _ => false,
    }
}

#[allow(clippy::too_many_arguments)]
fn report(
    mode: Stability,
    params: &Params,
    assembly: &Assembly,
    check: &StepsAnalysis,
    repairs: Vec<String>,
    moved: Vec<Moved>,
    (supports, support_pieces): (Vec<Column>, usize),
    (reseeded, flat_base): (Option<u64>, bool),
    before: Option<Before>,
    stands_on_baseplate: Option<bool>,
    counts: Counts,
    stress_map: StressMap,
) -> StabilityReport {
    let finished = &check.last;
    StabilityReport {
        mode: mode.name(),
        clutch_n_per_stud: params.clutch_n,
        stands: check.first_failure.is_none() && check.complete,
        first_failure: check.first_failure,
        failure: check.first_failure.map(|_| failure_line(assembly, check)),
        min_score: round(finished.min_score),
        mean_score: round(finished.mean_score),
        max_usage: round(finished.max_usage),
        weakest: weak_pieces(assembly, finished, &finished.weakest(WEAKEST)),
        steps: check
            .steps
            .iter()
            .map(|s| StepRow {
                step: s.step,
                min_score: round(s.min_score),
                stands: s.stands,
            })
            .collect(),
        repairs,
        moved,
        support_pieces,
        supports,
        reseeded,
        flat_base,
        before,
        stands_on_baseplate,
        complete: check.complete,
        steps_checked: check.steps.len(),
        solves: counts.solves,
        reused: counts.reused,
        certified: counts.certified,
        whole_certified: counts.whole_certified,
        failures_carried: counts.failures_carried,
        stress_map,
    }
}

/// The listed pieces of `assembly`, as the report shows them.
fn weak_pieces(assembly: &Assembly, analysis: &Analysis, pieces: &[usize]) -> Vec<WeakPiece> {
    pieces
        .iter()
        .map(|&i| {
            let p = &assembly.pieces[i];
            let spec = p.placement.part.spec();
            let s = &analysis.pieces[i];
            WeakPiece {
                piece: i + 1,
                step: p.step.0,
                part: spec.id.0,
                name: spec.name,
                at: [
                    p.placement.origin.x,
                    p.placement.origin.y,
                    p.placement.origin.z,
                ],
                usage: round(s.usage),
                falls: s.falls,
            }
        })
        .collect()
}

/// The one-line reason a build fails `--stability check`.
fn failure_line(assembly: &Assembly, check: &StepsAnalysis) -> String {
    let Some(step) = check.first_failure else {
        return String::new();
    };
    let at = check.steps.iter().find(|s| s.step == step);
    // A step not checked (past the budget) is the finished model, known
    // to fail: its weakest pieces.
    let weak = at.map_or_else(
        || check.last.weakest(crate::physics::WEAKEST),
        |s| s.weakest.clone(),
    );
    let listed: Vec<String> = weak
        .iter()
        .take(3)
        .map(|&i| {
            let p = &assembly.pieces[i];
            format!(
                "piece {} ({} {} at stud {},{} layer {}, step {})",
                i + 1,
                p.placement.part.spec().id.0,
                p.placement.part.spec().name,
                p.placement.origin.x,
                p.placement.origin.y,
                p.placement.origin.z,
                p.step.0
            )
        })
        .collect();
    let more = weak.len().saturating_sub(listed.len());
    format!(
        "at step {step} the build would not stand: {}{}",
        listed.join(", "),
        if more > 0 {
            format!(" and {more} more")
        } else {
            String::new()
        }
    )
}

fn round(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

impl From<PhysicsError> for crate::pipeline::BuildError {
    fn from(e: PhysicsError) -> Self {
        crate::pipeline::BuildError::Physics(e)
    }
}

/// A build after the stability stage: the plan to write and, unless the
/// stage was off, its report and the finished model's analysis.
pub(super) struct Settled {
    pub outcome: SearchOutcome,
    pub assembly: Assembly,
    /// The order's name, for the report.
    pub order: &'static str,
    pub stability: Option<(StabilityReport, Analysis)>,
}

impl Settled {
    /// `plan` as it is, with `--stability off`.
    pub(super) fn unchecked((outcome, assembly, order): Plan) -> Self {
        Settled {
            outcome,
            assembly,
            order,
            stability: None,
        }
    }

    /// What the booklet and the `.ldr` say of a step that adds a support
    /// column or, in a hollow build, an inner pillar.
    pub(super) fn step_notes(&self) -> std::collections::BTreeMap<u32, String> {
        self.stability
            .iter()
            .flat_map(|(r, _)| &r.supports)
            .flat_map(|c| {
                // Every step of a column taller than a step holds.
                let note = super::hollow::note(c, self.outcome.emptied.as_ref());
                (c.step..=c.last_step.max(c.step)).map(move |s| (s, note.to_string()))
            })
            .collect()
    }

    /// Pieces of support columns (they fill no voxel of the model).
    pub(super) fn support_pieces(&self) -> usize {
        self.stability.as_ref().map_or(0, |(r, _)| r.support_pieces)
    }
}

/// The stage: checks, and with [`Stability::Repair`] repairs, the first
/// plan, asking `planner` for other layouts when the repair needs them.
/// With [`Stability::Check`], a step that would not stand is an error.
pub(super) fn stage(
    opts: &crate::pipeline::BuildOptions,
    first: Plan,
    planner: &super::plan::Planner<'_>,
    progress: &dyn crate::pipeline::Progress,
) -> Result<Settled, crate::pipeline::BuildError> {
    let tell = |done, total| progress.advance(done, total);
    // A backward trace for another layout may take the whole search budget
    // (minutes): it ends by the stage's deadline. The layout's searches
    // take seconds at most and keep their own budget, so that none is cut
    // short and leaves voxels out.
    let backward = opts.search.method == crate::search::Method::Backward;
    let ((outcome, assembly, order), report, finished) = settle(
        opts.stability,
        first,
        opts.search.seed,
        &Params::default(),
        opts.stability_budget,
        opts.supports,
        &|seed, flat, until| {
            planner.flat_base.set(flat);
            planner.until.set(backward.then_some(until));
            let planned = planner.plan(seed);
            planner.flat_base.set(false);
            planner.until.set(None);
            planned
        },
        Some(&tell),
    )?;
    if opts.stability == Stability::Check && report.first_failure.is_some() {
        return Err(crate::pipeline::BuildError::Unstable {
            file: opts.input.display().to_string(),
            reason: report.failure.clone().unwrap_or_default(),
        });
    }
    Ok(Settled {
        outcome,
        assembly,
        order,
        stability: Some((report, finished)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::PartKind;
    use crate::geom::{Cell, Rot};
    use crate::physics::fixtures::counterweighted;

    #[test]
    fn the_finished_models_map_is_the_programs_once_or_the_certificates_past_the_budget_or_size() {
        let params = Params::default();
        let asm = counterweighted();
        let whole = analyze(&asm, &params).unwrap();
        assert!(whole.stands() && whole.max_usage > 0.0, "{whole:?}");
        let verdicts = || {
            analyze_steps_verdicts(&asm, &params, false, None, 1, None, Finish::WhenDue).unwrap()
        };
        let certified = verdicts();
        assert_eq!(certified.map, StressMap::Certificates);
        assert!(certified.complete && certified.first_failure.is_none());
        // The certificates hold the overhang within its clutch, by some
        // equilibrium of their own.
        assert!(certified.last.stands() && certified.last.max_usage > 0.0);
        let later = Instant::now() + Duration::from_secs(60);
        let draw = |check: &mut StepsAnalysis,
                    finished: &mut Option<Analysis>,
                    pending: &mut Option<Pending>,
                    deadline: Instant,
                    counts: &mut Counts| {
            map_finished(
                check,
                (finished, pending),
                (&asm, 100),
                &params,
                deadline,
                counts,
            )
        };
        // Past the deadline, with no program being made: the map stays
        // the certificates', and no program is solved.
        let (mut check, mut finished, mut counts) = (verdicts(), None, Counts::default());
        let drawn = draw(
            &mut check,
            &mut finished,
            &mut None,
            Instant::now(),
            &mut counts,
        );
        assert_eq!(drawn.unwrap(), StressMap::Certificates);
        assert_eq!(
            (check.last.pieces, counts.solves),
            (certified.last.pieces, 0)
        );
        assert!(finished.is_none());
        // A model past the size given: the certificates' map, the program
        // being made dropped, even in time.
        let mut pending = Some(Pending::start(&asm, &params));
        let (mut check, mut counts) = (verdicts(), Counts::default());
        let drawn = map_finished(
            &mut check,
            (&mut None, &mut pending),
            (&asm, asm.pieces.len() - 1),
            &params,
            later,
            &mut counts,
        );
        assert_eq!(drawn.unwrap(), StressMap::Certificates);
        assert!(pending.is_none() && counts.solves == 0);
        assert_eq!(check.last.pieces.len(), asm.pieces.len());
        // In time: the program's map, solved once (on a thread of its own,
        // started here or before), kept for the next asker.
        for mut pending in [None, Some(Pending::start(&asm, &params))] {
            let (mut check, mut finished, mut counts) = (verdicts(), None, Counts::default());
            let drawn = draw(&mut check, &mut finished, &mut pending, later, &mut counts);
            assert_eq!(drawn.unwrap(), StressMap::Program);
            assert_eq!(counts.solves, 1);
            assert_eq!(check.last.pieces, whole.pieces);
            assert_eq!(finished.as_ref().map(|f| &f.pieces), Some(&whole.pieces));
            assert!(pending.is_none());
            // Known already: taken as it is, nothing solved again, even
            // past the deadline.
            let mut again = verdicts();
            let drawn = draw(
                &mut again,
                &mut finished,
                &mut None,
                Instant::now(),
                &mut counts,
            );
            assert_eq!((drawn.unwrap(), counts.solves), (StressMap::Program, 1));
            assert_eq!(again.last.pieces, whole.pieces);
            assert_eq!(again.steps.last().unwrap().min_score, whole.min_score);
        }
    }

    #[test]
    fn an_analysis_follows_its_pieces_into_another_order() {
        let brick = PartKind::from_id("3001").expect("a 2 x 4 brick");
        let at = |x, z| Placement::new(brick, Cell::new(x, 0, z), Rot::R0);
        // A base, a brick hanging three studs past it, and one on the base.
        let order = [at(0, 0), at(3, 1), at(0, 1)];
        let before = Assembly::from_order(&order, 24, Color::RED);
        let after = Assembly::from_order(&[order[0], order[2], order[1]], 24, Color::RED);
        let a = analyze(&before, &Params::default()).unwrap();
        assert_ne!(a.pieces[1], a.pieces[2], "{a:?}");
        let b = reindexed(&a, &before, &after).unwrap();
        assert_eq!(b.pieces, [a.pieces[0], a.pieces[2], a.pieces[1]]);
        // What the new order's own analysis says (its program lists the
        // same forces in another order: the same answer but for round-off).
        let fresh = analyze(&after, &Params::default()).unwrap();
        for (p, q) in b.pieces.iter().zip(&fresh.pieces) {
            assert!((p.usage - q.usage).abs() < 1e-9, "{p:?} {q:?}");
            assert_eq!((p.falls, p.breaks), (q.falls, q.breaks));
        }
        assert_eq!(b.min_score, a.min_score);
        // Not the same pieces: no answer.
        let fewer = Assembly::from_order(&order[..2], 24, Color::RED);
        assert!(reindexed(&a, &before, &fewer).is_none());
        let moved = Assembly::from_order(&[order[0], order[1], at(1, 1)], 24, Color::RED);
        assert!(reindexed(&a, &before, &moved).is_none());
    }
}
