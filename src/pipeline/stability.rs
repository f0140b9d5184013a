//! The build's stability stage: check every step with the force analysis
//! of [`crate::physics`], repair what fails, and report.
//!
//! `--stability repair` (the default) fixes weak spots in two ways, each
//! checked again before it is kept:
//! - **layout**: when the finished model itself would break or fall, the
//!   search runs again with other seeds (another layout of the same
//!   voxels) and the first layout that stands is kept;
//! - **order**: when the finished model stands but a step before the end
//!   does not, the pieces that fail are deferred until the structure holds
//!   them ([`crate::physics::repair::reorder`]).
//!
//! `--stability check` reports and fails the build; `--stability off`
//! skips the stage.

use std::time::Instant;

use serde::Serialize;

use crate::assembly::verify::verify;
use crate::assembly::Assembly;
use crate::physics::repair::{reorder, Moved};
use crate::physics::{analyze_steps, Analysis, Params, PhysicsError, StepsAnalysis};
use crate::search::SearchOutcome;

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
    /// The finished model's lowest score.
    pub min_score: f64,
    /// The finished model stands.
    pub final_stands: bool,
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
    /// The seed of the layout kept, when the repair searched again.
    pub reseeded: Option<u64>,
    /// How the build stood before repairs, when it was repaired.
    pub before: Option<Before>,
    /// Force analyses solved, and reused from the step before.
    pub solves: usize,
    /// Analyses reused.
    pub reused: usize,
}

/// A planned build: the search's outcome and its verified, grouped
/// assembly, with the name of its order.
pub type Plan = (SearchOutcome, Assembly, &'static str);

/// Runs the stage on `plan`. `replan(seed)` searches again with another
/// seed. Returns the plan to write, possibly repaired, and the report.
pub fn settle(
    mode: Stability,
    plan: Plan,
    seed: u64,
    params: &Params,
    replan: &dyn Fn(u64) -> Result<Plan, crate::pipeline::BuildError>,
) -> Result<(Plan, StabilityReport, Analysis), crate::pipeline::BuildError> {
    let mut plan = plan;
    let mut check = analyze_steps(&plan.1, params, false)?;
    let mut repairs = Vec::new();
    let mut moved = Vec::new();
    let mut reseeded = None;
    let mut before = None;
    let mut solves = check.solves;
    let mut reused = check.reused;
    if mode == Stability::Repair && check.first_failure.is_some() {
        before = Some(Before {
            first_failure: check.first_failure,
            min_score: check.last.min_score,
            final_stands: check.last.stands(),
        });
        if !check.last.stands() {
            let weak = check.last.pieces.iter().filter(|p| p.fails()).count();
            for k in 1..=RESEEDS {
                let other = seed.wrapping_add(k);
                let candidate = replan(other)?;
                let c = analyze_steps(&candidate.1, params, false)?;
                solves += c.solves;
                reused += c.reused;
                if c.last.stands() {
                    repairs.push(format!(
                        "layout: {weak} pieces of the finished model would break off or fall; the search tried another layout (seed {other}) whose finished model stands (lowest score {:.2} -> {:.2})",
                        check.last.min_score, c.last.min_score
                    ));
                    plan = candidate;
                    check = c;
                    reseeded = Some(other);
                    break;
                }
            }
            if reseeded.is_none() {
                repairs.push(format!(
                    "layout: {weak} pieces of the finished model would break off or fall, and none of {RESEEDS} other layouts stood; the weak spots are listed"
                ));
            }
        }
        if let (true, Some(step)) = (check.last.stands(), check.first_failure) {
            if let Some(r) = reorder(&plan.1, params, step)? {
                solves += r.solves;
                if verify(&r.assembly, Some(&plan.0.voxels)).is_ok() {
                    let c = analyze_steps(&r.assembly, params, false)?;
                    solves += c.solves;
                    reused += c.reused;
                    if later(c.first_failure, check.first_failure) {
                        repairs.push(format!(
                            "order: step {step} would not stand; {} pieces were moved to later steps, where the structure holds them{}",
                            r.moved.len(),
                            match c.first_failure {
                                None => ", and every step stands".to_string(),
                                Some(s) => format!(", but step {s} still fails"),
                            }
                        ));
                        moved = r.moved;
                        plan.1 = r.assembly;
                        check = c;
                    }
                }
            }
            if moved.is_empty() {
                repairs.push(format!(
                    "order: step {step} would not stand, and no order that defers its weak pieces did better"
                ));
            }
        }
    }
    let report = report(
        mode, params, &plan.1, &check, repairs, moved, reseeded, before, solves, reused,
    );
    Ok((plan, report, check.last))
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
    reseeded: Option<u64>,
    before: Option<Before>,
    solves: usize,
    reused: usize,
) -> StabilityReport {
    let finished = &check.last;
    StabilityReport {
        mode: mode.name(),
        clutch_n_per_stud: params.clutch_n,
        stands: check.first_failure.is_none(),
        first_failure: check.first_failure,
        failure: check
            .first_failure
            .map(|_| failure_line(assembly, check)),
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
        reseeded,
        before,
        solves,
        reused,
    }
}

/// The listed pieces of `assembly`, as the report shows them.
pub fn weak_pieces(assembly: &Assembly, analysis: &Analysis, pieces: &[usize]) -> Vec<WeakPiece> {
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
                at: [p.placement.origin.x, p.placement.origin.y, p.placement.origin.z],
                usage: round(s.usage),
                falls: s.falls,
            }
        })
        .collect()
}

/// The one-line reason a build fails `--stability check`.
pub fn failure_line(assembly: &Assembly, check: &StepsAnalysis) -> String {
    let Some(step) = check.first_failure else {
        return String::new();
    };
    let at = check.steps.iter().find(|s| s.step == step);
    let weak = at.map(|s| s.weakest.clone()).unwrap_or_default();
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
        if more > 0 { format!(" and {more} more") } else { String::new() }
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

/// Seconds since `t`, for the report.
pub fn since(t: Instant) -> f64 {
    (t.elapsed().as_secs_f64() * 1000.0).round() / 1000.0
}
