//! The layout and order stages: the search lays the pieces, the verifier
//! checks them, and they are put in steps a builder can follow.

use std::cell::{Cell, RefCell};
use std::time::Instant;

use super::error::cover_error;
use super::input::Voxels;
use super::stability::Plan;
use super::{secs, BuildError, BuildOptions, Progress};
use crate::assembly::order::by_course_placeable;
use crate::assembly::verify::verify;
use crate::assembly::Assembly;
use crate::catalog::Color;
use crate::grammar::RuleSet;
use crate::search::{self, SearchOutcome};

/// Plans builds of one model: the first with the options' seed, and
/// others with other seeds when the stability repair asks for them.
pub(super) struct Planner<'a> {
    opts: &'a BuildOptions,
    voxels: &'a Voxels,
    rules: &'a RuleSet,
    progress: &'a dyn Progress,
    file: String,
    /// Time spent verifying, across plans.
    verify_secs: Cell<f64>,
    /// Notes for the report's warnings.
    notes: RefCell<Vec<String>>,
    /// The layouts being made are the last resort: they leave out what no
    /// order can put in place ([`search::SearchOptions::leave_unplaceable`]).
    last_resort: Cell<bool>,
    /// Lay no inverted slope in the lowest course (see
    /// [`crate::search::SearchOptions::flat_base`]): the stability
    /// stage's other layouts.
    pub(super) flat_base: Cell<bool>,
    /// When the search must end, if sooner than its own budget: the
    /// stability stage's other layouts are searched within its deadline.
    pub(super) until: Cell<Option<Instant>>,
}

/// Layouts made again with other seeds when one fails verification.
const RELAYOUTS: u64 = 4;

/// How far apart the seeds of layouts made again are.
const RELAYOUT_STRIDE: u64 = 1_000_003;

impl<'a> Planner<'a> {
    pub(super) fn new(
        opts: &'a BuildOptions,
        voxels: &'a Voxels,
        rules: &'a RuleSet,
        progress: &'a dyn Progress,
    ) -> Self {
        Planner {
            opts,
            voxels,
            rules,
            progress,
            file: opts.input.display().to_string(),
            verify_secs: Cell::new(0.0),
            notes: RefCell::new(Vec::new()),
            last_resort: Cell::new(false),
            flat_base: Cell::new(false),
            until: Cell::new(None),
        }
    }

    /// Seconds spent verifying so far (part of every plan's time).
    pub(super) fn verify_secs(&self) -> f64 {
        self.verify_secs.get()
    }

    /// The plan with the options' own seed. A rule file that cannot cover
    /// the shape is an error naming what it lacks, not a build of a
    /// fragment; with `--strict`, so is any voxel left out.
    pub(super) fn first(&self) -> Result<Plan, BuildError> {
        let (rules, opts) = (self.rules, self.opts);
        let first = self
            .plan_told(opts.search.seed, true)
            .map_err(|e| match e {
                BuildError::Search { .. } => cover_error(rules, opts, None).unwrap_or(e),
                e => e,
            })?;
        let rep = &first.0.repairs;
        if rep.left_out > 0 {
            if let Some(e) = cover_error(rules, opts, Some(rep.left_out)) {
                return Err(e);
            }
        }
        if opts.strict {
            if let Some(p) = rep.left_out_places.first() {
                return Err(BuildError::LeftOut {
                    file: self.file.clone(),
                    voxels: rep.left_out + rep.budget_left_out,
                    layer: p.layer,
                    x: p.x,
                    y: p.y,
                    reason: p.reason.clone(),
                });
            }
        }
        Ok(first)
    }

    /// With `--hollow`, the hollow build `settled` beside the solid build it
    /// replaces, laid out by the same search with the same seed.
    pub(super) fn solid_report(
        &self,
        settled: &super::stability::Settled,
    ) -> Result<Option<super::hollow::HollowReport>, BuildError> {
        super::hollow::report(
            &settled.assembly,
            &settled.outcome,
            &self.voxels.model.grid,
            self.guide(None),
            self.rules,
            &self.opts.search,
        )
        .map_err(|reason| BuildError::Search {
            file: self.file.clone(),
            reason,
        })
    }

    /// What the voxelizer knows of the model, for the search; `progress`
    /// hears how far it is.
    fn guide<'g>(&'g self, progress: Option<&'g dyn Fn(u64, u64)>) -> search::Guide<'g> {
        let model = &self.voxels.model;
        search::Guide {
            slant: Some(&model.slant),
            surface: Some(&model.surface),
            colors: self.voxels.labels.as_deref(),
            progress,
        }
    }

    /// A verified, grouped build from the layout with `seed`.
    pub(super) fn plan(&self, seed: u64) -> Result<Plan, BuildError> {
        self.plan_told(seed, false)
    }

    /// [`Self::plan`]; `told`: the layout's progress is shown. A layout
    /// that fails verification is never handed on: the layout is made
    /// again with other seeds ([`RELAYOUTS`] at most), and the notes say
    /// so; if none verifies, the same seeds are laid out again leaving out
    /// what no order can put in place, and if none of those verifies
    /// either, the first failure is the error (a bug). No layout is begun
    /// again once the search's time budget is spent.
    fn plan_told(&self, seed: u64, told: bool) -> Result<Plan, BuildError> {
        let started = Instant::now();
        let planned = self.plan_tries(seed, told, started);
        if !matches!(planned, Err(BuildError::Unverified { .. })) || self.spent(started) {
            return planned;
        }
        self.last_resort.set(true);
        let last = self.plan_tries(seed, false, started);
        self.last_resort.set(false);
        match last {
            Ok(p) => {
                self.notes.borrow_mut().push(format!(
                    "{}: no layout passed verification with every piece; the build leaves out the pieces no order could put in place",
                    self.file
                ));
                Ok(p)
            }
            Err(BuildError::Unverified { .. }) => planned,
            Err(e) => Err(e),
        }
    }

    /// [`Self::plan_told`]'s layouts with `seed` and the seeds after it,
    /// none begun once the search's time budget since `started` is spent.
    fn plan_tries(&self, seed: u64, told: bool, started: Instant) -> Result<Plan, BuildError> {
        let mut first_failure = None;
        // The slopes capping the stairs are the one late change to the
        // layout: a build they leave unverified is laid without them too.
        let caps: &[bool] = if self.opts.search.cap_stairs && self.opts.slopes {
            &[true, false]
        } else {
            &[true]
        };
        for k in 0..=RELAYOUTS {
            for &cap in caps {
                if first_failure.is_some() && self.spent(started) {
                    break;
                }
                let s = seed.wrapping_add(k * RELAYOUT_STRIDE);
                let (outcome, assembly) = self.layout(s, told && k == 0 && cap, cap)?;
                let t = Instant::now();
                let ordered = self.order(&outcome, assembly);
                self.verify_secs.set(self.verify_secs.get() + secs(t));
                match ordered {
                    Ok((assembly, order)) => {
                        if let Some(BuildError::Unverified { report, .. }) = &first_failure {
                            self.notes.borrow_mut().push(format!(
                                "{}: the layout with seed {seed} failed verification ({}); the build is the layout with seed {s}{}, which passed",
                                self.file,
                                report.lines().nth(1).unwrap_or(report).trim_start_matches(['-', ' ']),
                                if cap { "" } else { " without the slopes capping its stairs" }
                            ));
                        }
                        return Ok((outcome, assembly, order));
                    }
                    Err(e @ BuildError::Unverified { .. }) => {
                        first_failure.get_or_insert(e);
                    }
                    Err(e) => return Err(e),
                }
            }
        }
        Err(first_failure.expect("a failure was kept"))
    }

    /// What a user should know about the plans made: layouts that failed
    /// verification and were made again.
    pub(super) fn notes(&self) -> Vec<String> {
        self.notes.borrow().clone()
    }

    /// Whether no layout may be begun: the search's time budget since
    /// `started` is spent, or [`Self::until`] has passed.
    fn spent(&self, started: Instant) -> bool {
        started.elapsed() >= self.opts.search.time_budget
            || self.until.get().is_some_and(|u| Instant::now() >= u)
    }

    /// The search's pieces for `seed`, painted; `told`: how far it is
    /// goes to the progress display; `cap`: stair edges are capped with
    /// slopes (see [`SearchOptions::cap_stairs`]).
    pub(super) fn layout(
        &self,
        seed: u64,
        told: bool,
        cap: bool,
    ) -> Result<(SearchOutcome, Assembly), BuildError> {
        let opts = self.opts;
        let model = &self.voxels.model;
        let tell = |done, total| self.progress.advance(done, total);
        let guide = self.guide(told.then_some(&tell as &dyn Fn(u64, u64)));
        let budget = match self.until.get() {
            Some(until) => opts
                .search
                .time_budget
                .min(until.saturating_duration_since(Instant::now())),
            None => opts.search.time_budget,
        };
        let search_opts = opts
            .search
            .clone()
            .with_time_budget(budget)
            .with_seed(seed)
            .with_cap_stairs(cap && opts.search.cap_stairs)
            .with_leave_unplaceable(self.last_resort.get())
            .with_flat_base(self.flat_base.get() || opts.search.flat_base);
        let outcome = search::build_guided(&model.grid, guide, self.rules, &search_opts).map_err(
            |reason| BuildError::Search {
                file: self.file.clone(),
                reason,
            },
        )?;
        let order = search::placements(&outcome);
        let mut assembly = Assembly::from_order(&order, self.rules.layer_ldu(), Color::RED);
        assembly.paint(opts.palette, seed);
        if let Some(c) = &self.voxels.colors {
            assembly.paint_voxels(&model.grid, c);
        }
        Ok((outcome, assembly))
    }

    /// `assembly` verified against the voxels `outcome` built, then
    /// re-sequenced course by course so steps read like instructions (the
    /// search's order is kept if the re-sequenced one does not verify),
    /// and grouped in steps. Also the order's name, for the report.
    pub(super) fn order(
        &self,
        outcome: &SearchOutcome,
        assembly: Assembly,
    ) -> Result<(Assembly, &'static str), BuildError> {
        let check = verify(&assembly, Some(&outcome.voxels));
        if !check.is_ok() {
            return Err(BuildError::Unverified {
                file: self.file.clone(),
                report: check.to_string(),
            });
        }
        // Course by course (held to the trace's ways in where that shuts a
        // hung piece in), else the trace as it is.
        let (mut assembly, name) = match by_course_placeable(&assembly) {
            Some(ordered) if verify(&ordered, Some(&outcome.voxels)).is_ok() => {
                (ordered, "by course")
            }
            _ => (assembly, "search trace"),
        };
        assembly.regroup(self.opts.steps);
        Ok((assembly, name))
    }
}
