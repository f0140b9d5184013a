//! Static force analysis: does the build stand, at every step, and how
//! hard are its stud joints working?
//!
//! This follows the formulation of StableLego (R. Liu, K. Deng, Z. Wang,
//! C. Liu, "StableLego: Stability Analysis of Block Stacking Assembly",
//! arXiv:2402.10711, 2024), which BrickGPT (A. Pun et al., "Generating
//! Physically Stable and Buildable Brick Structures from Text",
//! arXiv:2505.05469, 2025) uses to check its generated builds: every piece
//! must be in static equilibrium under gravity with the forces its contacts
//! can give, and the tension a stud joint must carry is compared with the
//! clutch friction a stud can hold.
//!
//! # The model
//!
//! Lengths are in studs (8 mm), forces are counted in clutch capacities of
//! one stud ([`Params::clutch_n`] newtons), so the numbers the solver sees
//! are all of order one.
//!
//! - **Gravity**: each piece weighs its catalog mass ([`PartSpec::mass_g`])
//!   times [`Params::gravity`], at the centre of its filled boxes.
//! - **Compression**: where a piece's bottom face rests on another's top
//!   face, the lower piece may push the upper one up anywhere in the
//!   overlap of the two faces, taken at the pieces' real outer edges (not
//!   at stud centres). A force anywhere in a rectangle is a sum of forces
//!   at its four corners, so there are four variables `c >= 0`.
//! - **Clutch**: at each stud of the lower piece held in the upper piece's
//!   tubes (the connection rule of [`verify`](crate::assembly::verify),
//!   shared with it through [`stacked_pairs`](crate::assembly::verify::stacked_pairs)
//!   and [`Body::holds`](crate::geom::Body::holds)), the clutch may pull
//!   the two together with a tension `t >= 0` at the stud's centre, and
//!   `t <= m_j` for the joint's usage `m_j` (the share of a stud's clutch
//!   capacity the joint's most loaded stud uses).
//! - **Ground**: a piece on layer 0 stands on a table ([`Ground::Table`],
//!   the default): compression only, at the corners of its bottom face.
//!   [`Ground::Baseplate`] adds clutch to the ground as StableLego has it.
//! - **Side contacts** carry no force. Under gravity alone all contact
//!   forces are vertical, so horizontal equilibrium holds trivially and a
//!   side neighbour could only help (by friction); leaving it out is
//!   conservative.
//! - **Equilibrium**: for every piece, the vertical forces sum to zero and
//!   so do their moments about the two horizontal axes through its centre
//!   of mass (three equations a piece).
//! - **Soft equilibrium**: StableLego minimises the equilibrium violation,
//!   so its program always has an answer. Here every piece may also be held
//!   by a "hand": an upward force anywhere under its bounding footprint
//!   (four corner variables), priced far above any clutch usage. Since the
//!   centre of mass lies inside the footprint, a hand can always hold a
//!   piece, so the program is always feasible, and its equations stay
//!   exact. A piece the hand has to hold (more than
//!   [`Params::fall_tolerance`] of its weight) **falls**. (This needs four
//!   variables a piece where residuals `r+ - r-` on three equations need
//!   six.)
//! - **Objective**: minimise `HAND_COST * sum(hand) + sum_j m_j +
//!   1/2 * sum_j m_j^2 + 1e-3 * sum(t)`: StableLego's sum of per-piece
//!   largest pull, plus a little tension cost so that no tension is used
//!   where compression does, plus the usages' squares. The linear part
//!   alone has many optima wherever a load can be shared among joints in
//!   several ways at the same total, and an interior-point solver's answer
//!   among them moves with its tolerance and its path (on the arch fixture
//!   by 5.7e-5 with each Newton step refined). With the squares the cost is
//!   strictly convex in the usages, so every joint's usage has one answer,
//!   the program's and not the solver's (the same arch's usages within
//!   6e-8 whether refined or at a tolerance of 1e-10; the bunny at 48
//!   studs, 1,661 pieces in one program, within 1.3e-5, where the sum
//!   alone moved by 3e-3: its faces' compression is still shared in many
//!   ways, which the solver's path feels a little); the squares also
//!   spread a shared load over the joints that can take it, as clutch
//!   does, rather than load one joint to spare another.
//!
//! A piece's **usage** is the largest `m_j` over its joints; at 1 or more
//! the joint **breaks** (the piece would come off). Its **score** is
//! StableLego's stability score read the other way round, `1 - usage`,
//! clamped to `[0, 1]`: 1 for a piece that needs no clutch, 0 for one that
//! breaks off or falls. The model's minimum and mean score summarise it.
//!
//! - **Within capacity**: the least sum may load one joint past its
//!   capacity to spare others, where another equilibrium holds every
//!   joint within it (the bunny at 72 studs: a joint at 1.34 in a model
//!   that stands). So a group whose answer breaks a joint and needs no
//!   hand is solved again with `m_j <= 1 - 1e-6` for every joint: if no
//!   hand is needed then either, the group stands (the safe theorem) and
//!   that answer, the least usage within capacity, is its stress; else the
//!   first answer stands, naming the overloaded joints and by how much.
//!
//! Pieces that touch nowhere form separate groups (connected components,
//! compression contacts included); each is its own program. A group that
//! does not reach the ground falls as a whole.
//!
//! # The clutch capacity
//!
//! StableLego's `config.json` sets `T = 100` (grams-force, so 0.98 N) on
//! each of the three or four contact points it puts in every stud, with
//! compression at the same points. Our studs are one point each and our
//! compression acts at the pieces' edges, which gives a longer lever; the
//! default [`CLUTCH_N`] = 1.8 N a stud is the value that makes this model
//! give StableLego's published verdicts on its staircase examples (a
//! 19-step stair of 2 x 4 bricks on a baseplate stands, a 20-step one
//! breaks: with our masses any value between 1.75 and 1.94 N does). It
//! lies within the range of measured pull-off forces of a stud (about 1 to
//! 3 N); set [`Params::clutch_n`] for other bricks.
//!
//! # Steps
//!
//! A step **stands** when the pieces placed so far have an equilibrium
//! under gravity with no hand force and every stud joint within its
//! capacity (usage below 1). This is the safe theorem of rigid-block
//! analysis: if the contacts can carry the loads in some way, the
//! structure stands, whatever way the real forces choose. Any method may
//! find such an equilibrium; a found one is checked against every
//! equation and bound of its group, and that check is what says
//! "stands".
//!
//! [`analyze_steps`] checks every intermediate build (the pieces of steps
//! `1..=k`). It keeps a union-find of the groups as pieces are added; a
//! group no piece of step `k` joined keeps its result from an earlier step.
//! A group that stood and grew only by pieces whose weight goes straight
//! down to the ground in compression (each point under the centre of mass
//! lies on a face of the piece below, down to the ground) needs nothing
//! more: that compression is added to the kept forces. For every other
//! group the kept equilibrium is changed near the new pieces: a small
//! program over the new pieces, a way down from each to the ground and
//! ways to the group's outermost grounded pieces, widened (by rings of
//! contacts around the pieces the solver's proof that none exists moves)
//! up to the whole group, where the program is exact: none found there,
//! the step fails, and the group's force program below says which pieces
//! fall or break off. The
//! last step is certified as the others are (the finished model's program
//! is used there only when it is given, made already: waiting for it
//! took 150 s on a 5,000-piece build whose steps took 45 s, and a verdict
//! taken from whichever ended first would move with the machine's load).
//! A check begun at a later step certifies each group there whole first.
//! A long check (48 steps and 800 pieces or more, its later half begun
//! under 1,500 pieces) runs in two halves on two cores, the later one
//! begun afresh with the structure at its first step certified whole:
//! each verdict is its step's, whatever equilibrium certified the step
//! before, so the halves give one check's verdicts (their kept equilibria
//! differ, the same on every run: the split is a function of the steps).
//! The finished build is solved afresh with the force program, for the
//! usage of every piece: one answer, the same from [`analyze`] and from a
//! step check given it, within 1e-6 (the program within capacity first,
//! as a finished model is expected to stand). A check cut short by its
//! deadline waits for that analysis at most [`GRACE`]; past it, its
//! `last` is the steps checked ([`StressMap::Checked`]).
//!
//! A step that fails is proved to: the whole group's program that finds
//! no equilibrium ends with the solver's proof, a virtual motion of its
//! pieces (a lift and two tilts each) in which the weights do more work
//! than every joint can resist (Farkas' lemma: pushes may only open, a
//! stud's pull resists at most its clutch, and a hand under a piece at
//! most what the program tolerates before the piece falls, so the proof
//! says what the program says). When a check goes on past the failure,
//! that proof is found again among the pieces it moves and the new ones,
//! as a program of its own with the work held to one, and used where it
//! checks: in time linear in the group's contacts, with every push
//! bounded by the group's weight and all its studs' clutch (a push carries
//! the pieces above it, and the pulls at their joints, at most), so the
//! solver's tolerance does not decide it.
//! At the steps after, each new piece stays still or moves with a piece it
//! touches, whichever resists less, and the motion is checked again over
//! the whole group (found again among the moving and the new pieces where
//! it no longer holds): where it holds, the step fails with no program,
//! and its pieces that failed before are named again (never at the last
//! step, whose answers may be the map). A prop, a
//! counterweight or a new joint that resists the motion ends it: that step
//! goes to the programs. (The engine at 64 studs, failing from step 85 of
//! 255 after its repairs: the check of the steps after took 96 s of whole
//! groups' programs; now 154 groups are carried and the whole stage takes
//! 13 s, every step's verdict the program's.)
//!
//! Before any program is solved, the group gets a second, exact
//! certificate: when every piece's weight can be passed down to the ground
//! through the faces pieces rest on, spread over several supports where
//! need be, the group stands on compression alone, and since no cost is
//! negative that answer (no clutch, no hand) is the program's optimum
//! (`compression` module). Solid builds need no solve at all this way,
//! their finished model included.
//!
//! # Example
//!
//! ```
//! use brickwright::assembly::{Assembly, Placement};
//! use brickwright::catalog::{Color, PartKind};
//! use brickwright::geom::{Cell, Rot};
//! use brickwright::physics::{analyze, Params};
//!
//! let brick = PartKind::from_id("3001").unwrap();
//! let order = [
//!     Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
//!     Placement::new(brick, Cell::new(3, 0, 1), Rot::R0),
//! ];
//! let asm = Assembly::from_order(&order, 24, Color::RED);
//! let a = analyze(&asm, &Params::default()).unwrap();
//! assert!(a.stands());
//! // The upper brick's centre is past the lower one's edge: its clutch
//! // holds it.
//! assert!(a.pieces[1].usage > 0.0 && a.pieces[1].usage < 1.0);
//! ```

mod certify;
mod compression;
mod groups;
mod model;
mod pending;
pub mod repair;
mod steps;
pub mod support;

/// Builds for the unit tests of the physics and the stages that use it.
#[cfg(test)]
pub(crate) mod fixtures {
    use crate::assembly::{Assembly, Placement};
    use crate::catalog::{Color, PartKind};
    use crate::geom::{Cell, Rot};

    /// A 1x4 base, a 1x2 counterweight on its one end and a 1x6 clutched
    /// to its other end, hanging past it: it stands, on clutch (only a
    /// program finds its forces).
    pub(crate) fn counterweighted() -> Assembly {
        let at = |id: &str, x, z| {
            Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0)
        };
        let order = [at("3010", 0, 0), at("3004", 0, 1), at("3009", 3, 1)];
        Assembly::from_order(&order, 24, Color::RED)
    }
}

use serde::Serialize;

#[cfg(doc)]
use crate::catalog::PartSpec;

use crate::assembly::Assembly;

pub use pending::Pending;
pub use steps::{
    analyze_steps, analyze_steps_from, analyze_steps_told, analyze_steps_verdicts,
    analyze_steps_with_finished, analyze_steps_within, Finish, GRACE, PROGRAM_GROWTH,
};

/// Default clutch capacity of one stud, in newtons (see the module docs
/// for where it comes from).
pub const CLUTCH_N: f64 = 1.8;

/// Standard gravity, m/s².
pub const GRAVITY: f64 = 9.81;

/// What the lowest layer stands on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Ground {
    /// A table: it pushes up, never pulls (the default).
    Table,
    /// A baseplate: it pushes up and holds the studs it takes, as
    /// StableLego's ground does.
    Baseplate,
}

/// The physical constants of the analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Params {
    /// Clutch capacity of one stud, in newtons (default [`CLUTCH_N`]).
    pub clutch_n: f64,
    /// Gravity, m/s² (default [`GRAVITY`]).
    pub gravity: f64,
    /// What the lowest layer stands on (default [`Ground::Table`]).
    pub ground: Ground,
    /// A piece falls when more than this share of its weight must be held
    /// by hand (default 1e-3).
    pub fall_tolerance: f64,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            clutch_n: CLUTCH_N,
            gravity: GRAVITY,
            ground: Ground::Table,
            fall_tolerance: 1e-3,
        }
    }
}

impl Params {
    /// These parameters with a clutch capacity of `n` newtons a stud.
    pub fn with_clutch_n(self, n: f64) -> Self {
        Params {
            clutch_n: n,
            ..self
        }
    }

    /// These parameters with the build standing on `ground`.
    pub fn with_ground(self, ground: Ground) -> Self {
        Params { ground, ..self }
    }

    /// These parameters with gravity `g` m/s².
    pub fn with_gravity(self, g: f64) -> Self {
        Params { gravity: g, ..self }
    }

    fn check(&self) -> Result<(), PhysicsError> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if ok(self.clutch_n) && ok(self.gravity) && ok(self.fall_tolerance) {
            Ok(())
        } else {
            Err(PhysicsError::Params(format!(
                "clutch {} N, gravity {}, fall tolerance {}: each must be a positive number",
                self.clutch_n, self.gravity, self.fall_tolerance
            )))
        }
    }
}

/// How one piece fares.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PieceStress {
    /// The share of a stud's clutch capacity its most loaded joint uses
    /// (0 when it needs no clutch; 1 or more breaks).
    pub usage: f64,
    /// `1 - usage` clamped to `[0, 1]`; 0 when it falls or breaks off.
    pub score: f64,
    /// No force it can get holds it: it would fall (or tip over).
    pub falls: bool,
    /// A joint of it needs more clutch than the studs hold: it would break
    /// off.
    pub breaks: bool,
}

impl PieceStress {
    /// A piece that falls with its group (no ground under the group).
    fn falling() -> PieceStress {
        PieceStress {
            usage: 0.0,
            score: 0.0,
            falls: true,
            breaks: false,
        }
    }

    /// A piece resting in compression only.
    fn resting() -> PieceStress {
        PieceStress {
            usage: 0.0,
            score: 1.0,
            falls: false,
            breaks: false,
        }
    }

    /// Whether it falls or breaks off.
    pub fn fails(&self) -> bool {
        self.falls || self.breaks
    }

    /// Sets `breaks` and `score` from `usage` and `falls`.
    fn finish(&mut self) {
        // Interior-point answers are exact to about 1e-8: snap the noise.
        if self.usage < 1e-7 {
            self.usage = 0.0;
        }
        self.breaks = self.usage >= 1.0;
        self.score = if self.fails() {
            0.0
        } else {
            (1.0 - self.usage).clamp(0.0, 1.0)
        };
    }
}

/// The analysis of one structure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Analysis {
    /// Per piece, in the order of `assembly.pieces`.
    pub pieces: Vec<PieceStress>,
    /// The lowest score (1 for no pieces).
    pub min_score: f64,
    /// The mean score (1 for no pieces).
    pub mean_score: f64,
    /// The highest usage (0 for no pieces).
    pub max_usage: f64,
    /// Wall-clock seconds spent (building and solving).
    pub solve_seconds: f64,
}

impl Analysis {
    fn new(pieces: Vec<PieceStress>, solve_seconds: f64) -> Analysis {
        let n = pieces.len();
        let min_score = pieces.iter().map(|p| p.score).fold(1.0, f64::min);
        let mean_score = if n == 0 {
            1.0
        } else {
            pieces.iter().map(|p| p.score).sum::<f64>() / n as f64
        };
        let max_usage = pieces.iter().map(|p| p.usage).fold(0.0, f64::max);
        Analysis {
            pieces,
            min_score,
            mean_score,
            max_usage,
            solve_seconds,
        }
    }

    /// Whether nothing falls or breaks off.
    pub fn stands(&self) -> bool {
        !self.pieces.iter().any(PieceStress::fails)
    }

    /// The indices of the `n` weakest pieces: lowest score first, then
    /// highest usage, then build order.
    pub fn weakest(&self, n: usize) -> Vec<usize> {
        weakest(&self.pieces, n)
    }
}

fn weakest(pieces: &[PieceStress], n: usize) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..pieces.len()).collect();
    idx.sort_by(|&a, &b| {
        let (p, q) = (&pieces[a], &pieces[b]);
        p.score
            .total_cmp(&q.score)
            .then(q.usage.total_cmp(&p.usage))
            .then(a.cmp(&b))
    });
    idx.truncate(n);
    idx
}

/// One intermediate build: the pieces of steps `1..=step`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StepCheck {
    /// The step number.
    pub step: u32,
    /// The lowest score of the pieces placed so far.
    pub min_score: f64,
    /// Whether nothing placed so far falls or breaks off.
    pub stands: bool,
    /// Up to [`WEAKEST`] weakest pieces so far (indices into
    /// `assembly.pieces`), weakest first.
    pub weakest: Vec<usize>,
}

/// How many weakest pieces each [`StepCheck`] lists.
pub const WEAKEST: usize = 5;

/// The analysis of every step of a build.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StepsAnalysis {
    /// One check per step, in order (up to the first failure when asked
    /// to stop there).
    pub steps: Vec<StepCheck>,
    /// The first step at which something falls or breaks off.
    pub first_failure: Option<u32>,
    /// The finished build's analysis (of the last step checked). Its
    /// `solve_seconds` are its programs' (the biggest of them, when the
    /// last step's answers are carried over), not the whole check's. A
    /// check cut short by its deadline has the finished model's if it was
    /// made by then, else only the steps checked (fewer pieces than the
    /// build; `map` is [`StressMap::Checked`]): nothing past the deadline
    /// is waited for.
    pub last: Analysis,
    /// Wall-clock seconds for everything.
    pub seconds: f64,
    /// Programs solved (the finished build's groups count as one, and as
    /// none when the last step checked had solved them all).
    pub solves: usize,
    /// Groups whose result was carried over from the step before instead:
    /// untouched, or grown only by pieces resting straight on the ground
    /// through compression.
    pub reused: usize,
    /// Groups found to stand on compression alone without a solve: every
    /// weight passes down to the ground through the faces pieces rest on
    /// (exact: no clutch is used, see the module docs).
    pub certified: usize,
    /// Of the groups certified by a change to the kept equilibrium, those
    /// whose change took the whole group's program (no region near the
    /// new pieces had one).
    pub whole_certified: usize,
    /// Groups found still failing, without a program, by the proof that
    /// they had no equilibrium at a step before (a virtual motion the new
    /// pieces do not stop; see the module docs).
    pub failures_carried: usize,
    /// Every step up to the end (or the first failure, when asked to stop
    /// there) was checked; false when the deadline of
    /// [`analyze_steps_within`] cut the check short.
    pub complete: bool,
    /// The finished model's analysis, when it was asked for alongside the
    /// steps ([`analyze_steps_with_finished`]) or made alongside them near
    /// the deadline ([`analyze_steps_within`]): `last` too, unless the
    /// check stopped at a failure before the end.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finished: Option<Analysis>,
    /// Where `last`'s usages come from.
    pub map: StressMap,
}

/// Where a structure's usages (its stress map) come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StressMap {
    /// The force program of every group (one answer: see the module docs).
    Program,
    /// The equilibria that certified each group at its last step (see
    /// [`analyze_steps_verdicts`]), and the program's answer for a group
    /// that failed: within every capacity where the structure stands, but
    /// one of many.
    Certificates,
    /// The steps checked, as [`StressMap::Certificates`]: the check was
    /// cut short by its deadline before the finished model was analysed,
    /// so `last` holds only the pieces of the steps checked.
    Checked,
}

impl StepsAnalysis {
    /// Takes `finished`, the force program's analysis of the finished
    /// model, as the map of a check that went to its end (`last`, and the
    /// last step's row, as [`analyze_steps`] has them); a check that
    /// stopped before the end is left as it is. False when not taken.
    pub fn take_map(&mut self, finished: &Analysis) -> bool {
        if !self.complete || finished.pieces.len() != self.last.pieces.len() {
            return false;
        }
        if let Some(row) = self.steps.last_mut() {
            *row = steps::check(row.step, &finished.pieces);
        }
        self.last = finished.clone();
        self.map = StressMap::Program;
        true
    }
}

/// Why an analysis failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum PhysicsError {
    /// The solver gave up on a group of pieces.
    #[error(
        "the force solver failed on a group of {pieces} pieces ({status}); \
         the model may be too large or badly conditioned"
    )]
    Solver {
        /// Pieces in the group.
        pieces: usize,
        /// The solver's status.
        status: String,
    },
    /// Parameters out of range.
    #[error("bad physics parameters: {0}")]
    Params(String),
    /// A bug: the program was built wrong.
    #[error("internal error in the force analysis (a bug): {0}")]
    Bug(String),
}

/// Analyses the finished build.
pub fn analyze(assembly: &Assembly, params: &Params) -> Result<Analysis, PhysicsError> {
    analyze_expecting(assembly, params, model::First::Within)
}

/// Whether the finished build stands, and its analysis when it does
/// (then [`analyze`]'s): the program within capacity alone; where it has
/// no answer, the program naming what fails is not solved.
pub(crate) fn analyze_if_stands(
    assembly: &Assembly,
    params: &Params,
) -> Result<Option<Analysis>, PhysicsError> {
    let a = analyze_expecting(assembly, params, model::First::Verdict)?;
    Ok(a.stands().then_some(a))
}

/// [`analyze`] of a build expected to stand ([`model::First::Within`]) or
/// to fail ([`model::First::Least`]: no certificate was found for it): the
/// same answer, in one program where the guess is right.
pub(crate) fn analyze_expecting(
    assembly: &Assembly,
    params: &Params,
    first: model::First,
) -> Result<Analysis, PhysicsError> {
    analyze_by(assembly, params, first, None)
}

/// [`analyze_expecting`], whose programs stop at `deadline`: past it, a
/// program not solved gives [`PhysicsError::Solver`].
pub(crate) fn analyze_by(
    assembly: &Assembly,
    params: &Params,
    first: model::First,
    deadline: Option<std::time::Instant>,
) -> Result<Analysis, PhysicsError> {
    let start = std::time::Instant::now();
    params.check()?;
    let s = model::Structure::new(assembly, params);
    let pieces = steps::solve_all_first(&s, assembly.pieces.len(), params, first, deadline)?;
    Ok(Analysis::new(pieces, start.elapsed().as_secs_f64()))
}
