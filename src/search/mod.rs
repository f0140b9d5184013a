//! The layout search: from voxels to an ordered build, every piece added by
//! a rule of the Lego rewriting system (paper, sections 3 and 4).
//!
//! [`build`] takes the voxels and a [`RuleSet`] and returns the pieces in
//! build order, in four stages:
//!
//! 1. `prepare`: islands are joined to the body (a support column or the
//!    shortest bridge, never dropped), one-layer sheets thickened, flat tops
//!    evened to whole courses;
//! 2. `layout`: a forward derivation, course by course from the bottom: over
//!    the first voxel not yet covered, every piece of the alphabet that fits
//!    is scored (size, stagger over the seams below, resting on and joining
//!    the pieces below through a rule of the file, whose weight counts,
//!    fidelity to the surface) and the best one laid; complex rules are
//!    tested first once every [`SearchOptions::complex_every`] nodes;
//! 3. `join`: local repair instead of backtracking: a body of pieces that
//!    rests on nothing the rules join is joined to another by growing one of
//!    its pieces or laying a piece across, with the fewest cells outside;
//!    `merge` then makes neighbours whose union is a piece of the alphabet
//!    one piece: never a seam more, always a piece fewer; a brick's side
//!    row outside the model with nothing over it is trimmed off
//!    (`cap::trim`: no step on a roof with a row standing up); and
//!    `cap`, where
//!    the alphabet has slopes, swaps the row of a brick that stands a step
//!    above its neighbours (below, underneath) for slopes facing down the
//!    step, so a slanted roof is capped rather than a staircase;
//! 4. `derive`: the pieces ordered as a derivation: a starting rule, then
//!    each piece added by the heaviest rule joining it to a piece already
//!    there, lowest course first.
//!
//! The cost is near-linear in the voxels: each voxel is scanned once, each
//! piece scored against a fixed set of candidates over it, and bodies are
//! tracked with a union-find.

mod backward;
mod cap;
mod complex;
mod derive;
mod join;
mod layout;
mod merge;
mod prepare;
mod rulebook;
mod sequence;
mod written;

use std::time::{Duration, Instant};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use thiserror::Error;

use crate::assembly::Placement;
use crate::grammar::{RuleRef, RuleSet};
use crate::voxel::{Slant, VoxelGrid, Wall};
pub use backward::{parts as hierarchy_parts, CUT_RATIO};
pub use prepare::{components, LeftOut, Repairs};
pub use written::{piece_rules, total_variation, Derivation};

/// The most voxels a model may have: a 96-stud cube in plates (2.2
/// million voxels, 63,000 pieces) builds in 40 s in 450 MiB; twice that
/// stays under 1 GiB.
pub const MAX_VOXELS: usize = 4_000_000;

/// Tuning of the search.
#[derive(Debug, Clone, Serialize)]
pub struct SearchOptions {
    /// Seed of the Gumbel noise that draws among near-equal candidates and
    /// of the complex rule picks. Default 1.
    pub seed: u64,
    /// Wall-clock budget for the whole search. Default 300 s.
    pub time_budget: Duration,
    /// How often a complex rule is tested: once every this many nodes, one
    /// complex rule picked with equal probability is tried before the
    /// scored basic rules (paper, section 4: "once every fifth node to
    /// once every node", so 5 to 1). 0, the default, never tries them.
    pub complex_every: u32,
    /// Build a shell with walls this thick and the inside empty (see
    /// [`crate::voxel::hollow()`]); `None`, the default, builds solid.
    pub hollow: Option<Wall>,
    /// Which search: the layout (the default) or the paper's backward
    /// tracing.
    pub method: Method,
    /// Backward tracing: the branching factor `b`, from its first value
    /// at the root to its second as the voxels run out (paper: 10-30
    /// rising to 100-200): how many rules that match a node are drawn
    /// there. Default (20, 150).
    pub branching: (u32, u32),
    /// Backward tracing: a pass of the tree that makes this many nodes
    /// for each voxel of the part it traces (times the Luby sequence's
    /// next term: 1, 1, 2, 1, 1, 2, 4, ...; at least 100) without an
    /// answer starts again from the root with new draws; 0 never.
    /// Default 2.
    pub restart: u64,
    /// Backward tracing: the most tree nodes before it gives up. Default
    /// 1,000,000.
    pub node_budget: u64,
    /// Backward tracing: cut the voxels into parts at horizontal planes
    /// (the paper's hierarchical approach). Default true.
    pub cut: bool,
    /// Cap stair edges with slopes after the layout, where the rules have
    /// slopes. Default `true`.
    pub cap_stairs: bool,
    /// Leave out the pieces no order can put in place (shut in a cavity,
    /// with no gap under them to fill), as what nothing joins is left out,
    /// rather than hand on a layout that fails verification. Default
    /// `false`: a build tries other layouts first, and this is its last
    /// resort.
    pub leave_unplaceable: bool,
    /// Lay no inverted slope in the lowest course, which stands on the
    /// table: it would stand on its back row only. Default `false` (a
    /// rounded underside meets the table in inverted slopes); the
    /// stability stage's other layouts set it, since a keel of them can
    /// tip a build over (the glider at 48 studs with `--slopes`).
    pub flat_base: bool,
}

/// Which search builds the voxels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum Method {
    /// The forward layout, course by course ([`build`]'s stages).
    #[default]
    Layout,
    /// The paper's backward tracing (module `backward`).
    Backward,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            seed: 1,
            time_budget: Duration::from_secs(300),
            complex_every: 0,
            hollow: None,
            method: Method::Layout,
            branching: (20, 150),
            restart: 2,
            node_budget: 1_000_000,
            cut: true,
            cap_stairs: true,
            leave_unplaceable: false,
            flat_base: false,
        }
    }
}

impl SearchOptions {
    /// Sets the seed.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Sets the time budget.
    pub fn with_time_budget(mut self, t: Duration) -> Self {
        self.time_budget = t;
        self
    }

    /// Builds hollow with walls `wall` thick (`None`: solid).
    pub fn with_hollow(mut self, wall: Option<Wall>) -> Self {
        self.hollow = wall;
        self
    }

    /// Sets the search method.
    pub fn with_method(mut self, m: Method) -> Self {
        self.method = m;
        self
    }

    /// Sets the backward tracing's node budget.
    pub fn with_node_budget(mut self, n: u64) -> Self {
        self.node_budget = n;
        self
    }

    /// Sets the backward tracing's branching factor, first and last.
    pub fn with_branching(mut self, first: u32, last: u32) -> Self {
        self.branching = (first, last);
        self
    }

    /// Sets the backward tracing's restart length, in nodes a voxel (0:
    /// never restart).
    pub fn with_restart(mut self, nodes: u64) -> Self {
        self.restart = nodes;
        self
    }

    /// Sets whether stair edges are capped with slopes after the layout.
    pub fn with_cap_stairs(mut self, cap: bool) -> Self {
        self.cap_stairs = cap;
        self
    }

    /// Sets [`SearchOptions::flat_base`].
    pub fn with_flat_base(mut self, flat: bool) -> Self {
        self.flat_base = flat;
        self
    }

    /// Sets [`SearchOptions::leave_unplaceable`].
    pub fn with_leave_unplaceable(mut self, leave: bool) -> Self {
        self.leave_unplaceable = leave;
        self
    }

    /// Sets how often a complex rule is tested (0: never).
    pub fn with_complex_every(mut self, k: u32) -> Self {
        self.complex_every = k;
        self
    }
}

/// What the search did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct SearchStats {
    /// Nodes: voxels the layout laid a piece (or a complex rule) over.
    pub nodes: u64,
    /// Candidate pieces scored.
    pub candidates: u64,
    /// Nodes where no candidate rested on the course below and pieces
    /// reaching across empty cells were scored too.
    pub widened: u64,
    /// Local repairs that joined a loose body to the rest.
    pub joins: u64,
    /// Pairs of neighbouring pieces merged into one bigger piece.
    pub merges: u64,
    /// Pieces laid in a gap under a piece that could not be put in place
    /// otherwise.
    pub fills: u64,
    /// Starting rules applied: a piece put on the ground that no piece
    /// before it joins.
    pub starts: u64,
    /// Nodes at which a complex rule was picked and tested.
    pub complex_tried: u64,
    /// Complex rules applied (each one node adding all its new pieces).
    pub complex_applied: u64,
    /// Slopes laid after the layout to cap stair edges (inverted slopes
    /// underneath), each in place of a brick's row along the step.
    pub caps: u64,
    /// Whether the time budget ran out before every layer was laid.
    pub budget_hit: bool,
    /// Backward tracing: times it went back up the tree from a node with
    /// no rule left to try.
    pub backtracks: u64,
    /// Backward tracing: parts the voxels were cut into.
    pub parts: u64,
}

/// A search that could not produce a build.
#[derive(Debug, Error)]
pub enum SearchError {
    /// No voxels to build.
    #[error("nothing to build: the voxel model is empty")]
    Empty,
    /// More voxels than a build of bricks can sensibly have.
    #[error("the model is too big to build: {voxels} voxels, more than the limit of {limit}; use a smaller --studs or --height")]
    TooBig {
        /// Voxels in the model.
        voxels: usize,
        /// The limit, [`MAX_VOXELS`].
        limit: usize,
    },
    /// Budgets ran out before a single piece.
    #[error("the search ran out of its budget ({secs:.1} s) with {left} of {total} voxels unbuilt; raise --time-budget or use a smaller size")]
    Budget {
        /// Seconds spent.
        secs: f64,
        /// Voxels left.
        left: usize,
        /// Voxels in all.
        total: usize,
    },
    /// The rules cannot build the shape.
    #[error("the rules cannot build this shape: {0}")]
    Rules(String),
    /// The backward tracing found no derivation.
    #[error("the backward search found no derivation: {why} ({nodes} nodes, {backtracks} backtracks, {secs:.1} s)")]
    Backward {
        /// Why it stopped.
        why: String,
        /// Tree nodes made.
        nodes: u64,
        /// Times it went back up the tree.
        backtracks: u64,
        /// Seconds spent.
        secs: f64,
    },
}

/// What a piece is attached to in the derivation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// A piece added before it, the rule's `A`.
    Piece(Placement),
    /// Nothing: a starting rule `ε -> P`.
    Start,
}

/// One rule application of the derivation: the piece it adds.
#[derive(Debug, Clone, Copy)]
pub struct Removal {
    /// The piece added.
    pub piece: Placement,
    /// What it is attached to.
    pub anchor: Anchor,
    /// The rule that added it: a basic or complex rule, or `None` for a
    /// starting rule.
    pub rule: Option<RuleRef>,
}

impl Removal {
    /// A piece added by `rule` to `anchor`.
    pub(crate) fn forward(piece: Placement, anchor: Anchor, rule: Option<RuleRef>) -> Removal {
        Removal {
            piece,
            anchor,
            rule,
        }
    }

    /// The starting rule `ε -> p`.
    pub(crate) fn new_start(piece: Placement) -> Removal {
        Removal {
            piece,
            anchor: Anchor::Start,
            rule: None,
        }
    }
}

/// The result of [`build`].
#[derive(Debug, Clone)]
pub struct SearchOutcome {
    /// Pieces in build order, each with the rule that adds it.
    pub order: Vec<Removal>,
    /// The cells the pieces fill: the voxels after repairs, less what was
    /// left out, plus the cells outside the model that join features.
    pub voxels: VoxelGrid,
    /// What the repairs changed.
    pub repairs: Repairs,
    /// In a hollow build, the cells of the model left empty inside its
    /// shell; `None` for a solid build.
    pub emptied: Option<VoxelGrid>,
    /// Counters.
    pub stats: SearchStats,
}

/// What the voxelizer knows of the mesh besides its voxels, and whom to
/// tell how far the search is.
#[derive(Clone, Copy, Default)]
pub struct Guide<'a> {
    /// Where the surface slants: slopes go only there.
    pub slant: Option<&'a Slant>,
    /// The cells the surface passes through: pieces may fill those outside
    /// the voxels to join a thin feature (without it, any empty cell
    /// touching a voxel).
    pub surface: Option<&'a VoxelGrid>,
    /// Per cell (by [`VoxelGrid::index`]): a surface voxel's colour label,
    /// 0 for none. No piece covers surface voxels of two labels, so pieces
    /// split where the model's colours change (inner pieces may span them).
    pub colors: Option<&'a [u16]>,
    /// Called as the layout goes up the model with the voxels laid so far
    /// and all there are, for a progress display.
    pub progress: Option<&'a dyn Fn(u64, u64)>,
}

impl std::fmt::Debug for Guide<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Guide")
            .field("slant", &self.slant)
            .field("surface", &self.surface)
            .field("colors", &self.colors.map(<[u16]>::len))
            .field("progress", &self.progress.is_some())
            .finish()
    }
}

/// Finds an ordered, connected build of `voxels` with the rules `rules`;
/// slopes go wherever their cells fit.
pub fn build(
    voxels: &VoxelGrid,
    rules: &RuleSet,
    opts: &SearchOptions,
) -> Result<SearchOutcome, SearchError> {
    build_guided(voxels, Guide::default(), rules, opts)
}

/// [`build`], with what the voxelizer knows of the surface (`guide`).
pub fn build_guided(
    voxels: &VoxelGrid,
    guide: Guide<'_>,
    rules: &RuleSet,
    opts: &SearchOptions,
) -> Result<SearchOutcome, SearchError> {
    if voxels.is_empty() {
        return Err(SearchError::Empty);
    }
    let n = voxels.count();
    if n > MAX_VOXELS {
        return Err(SearchError::TooBig {
            voxels: n,
            limit: MAX_VOXELS,
        });
    }
    let started = Instant::now();
    let deadline = started + opts.time_budget;
    let (mut fixed, mut repairs) = prepare::repair_islands(voxels);
    // The backward search traces the voxels as they are (islands joined
    // only): thickening sheets would add voxels no rule may need.
    if opts.method == Method::Backward {
        return backward::build(fixed, repairs, None, rules, opts, started);
    }
    // A course is a brick's height in layers; a sheet one course thick is
    // pieces side by side that cannot hold together, except plates, which
    // two layers laminate.
    let course = 24 / rules.layer_ldu();
    let plates = rules.layer_ldu() == 8;
    let min_thick = crate::voxel::voxelize::sheet_layers(rules.layer_ldu());
    prepare::thicken_sheets(&mut fixed, &mut repairs, min_thick);
    if !plates {
        prepare::even_courses(&mut fixed, guide.slant, course, &mut repairs);
    }
    // The shell is taken of the repaired voxels, so that thickened sheets
    // and joined islands are measured as the model they are.
    let phase = layout::phase(rules);
    let emptied = opts.hollow.map(|wall| {
        let h = crate::voxel::hollow(&fixed, wall, course, min_thick);
        let (shell, emptied) = whole_courses(h.shell, h.emptied, phase);
        fixed = shell;
        emptied
    });

    let mut layout = layout::Layout::new(rules, &fixed, guide.surface, guide.slant);
    layout.repairs = repairs;
    layout.colors = guide.colors.filter(|c| c.len() == fixed.len());
    layout.keep_empty = emptied.as_ref();
    layout.flat_base = opts.flat_base;
    let mut dice = Dice::new(opts.seed);
    layout.lay(opts, &mut dice, deadline, guide.progress);
    layout.join(&mut dice.rules);
    layout.merge();
    // The cells outside the model as laid, for when the swaps are undone.
    let extra = layout.repairs.extra_cells;
    let mut swaps = layout.trim_outside();
    if opts.cap_stairs {
        swaps.extend(layout.cap_stairs());
    }
    // Nor may they split the build: a swap keeps its own joints, but two
    // swaps side by side can take both ends of the one piece that joined
    // two parts.
    if !swaps.is_empty() && layout.bodies().len() > 1 {
        layout.uncap(&swaps);
        layout.repairs.extra_cells = extra;
        swaps.clear();
    }
    let (mut order, mut unreached) = derive(&layout);
    let mut blocked = unplaceable(&order, rules.layer_ldu());
    // Slopes capping the stairs must not cost the build its order: if a
    // piece cannot be put in place or reached with them, they are undone.
    if !swaps.is_empty() && (!unreached.is_empty() || !blocked.is_empty()) {
        layout.uncap(&swaps);
        layout.repairs.extra_cells = extra;
        (order, unreached) = derive(&layout);
        blocked = unplaceable(&order, rules.layer_ldu());
    } else {
        layout.stats.caps = swaps.iter().map(|s| s.slopes as u64).sum();
    }
    // A piece that no order can put in place (one hanging in a cavity from
    // the piece that closes it) gets the gap under it filled, so that it
    // rests on the pieces there (inside a hollow build, a pillar), and the
    // pieces are ordered again.
    for _ in 0..PLACE_ROUNDS {
        if blocked.is_empty() || Instant::now() >= deadline {
            break;
        }
        let mut changed = false;
        for &k in &blocked {
            changed |= layout.fill_under(&order[k].piece, &mut dice.rules);
        }
        if !changed {
            break;
        }
        layout.join(&mut dice.rules);
        (order, unreached) = derive(&layout);
        blocked = unplaceable(&order, rules.layer_ldu());
    }
    // As a last resort (`leave_unplaceable`), what no fill under it lets an
    // order put in place (a piece shut in a cavity with pieces right over
    // and under it) is left out, as what nothing joins is: the rest is
    // built, and the report says where (fandisk at 48 studs, `--hollow
    // --plates`, seeds 2 and 3: every layout failed verification, with 3-7
    // such pieces). What it held is joined again, and no piece goes where
    // it was.
    for _ in 0..PLACE_ROUNDS {
        if blocked.is_empty() || !opts.leave_unplaceable {
            break;
        }
        for &k in &blocked {
            let body = order[k].piece.body(rules.layer_ldu());
            let Some(id) = layout.owner_of(body.key()) else {
                continue;
            };
            let cells = body.cells().filter(|&q| fixed.get(q)).count();
            layout.remove(id);
            layout.refused.extend(body.cells());
            layout
                .repairs
                .leave_out(body.bbox.min, cells, "no order can put it in place");
        }
        layout.join(&mut dice.rules);
        (order, unreached) = derive(&layout);
        blocked = unplaceable(&order, rules.layer_ldu());
    }
    if order.is_empty() {
        if layout.stats.budget_hit {
            return Err(SearchError::Budget {
                secs: started.elapsed().as_secs_f64(),
                left: fixed.count(),
                total: fixed.count(),
            });
        }
        let can_start: Vec<&str> = rules.starts().iter().map(|s| s.part.spec().id.0).collect();
        return Err(SearchError::Rules(format!(
            "no piece on the ground has a starting rule (the file starts with {}); add a `start` line for a part that fits",
            can_start.join(", ")
        )));
    }
    for i in unreached {
        let b = layout.pieces[i as usize].body;
        let cells = b.cells().filter(|&q| fixed.get(q)).count();
        layout.remove(i);
        layout.repairs.leave_out(
            b.bbox.min,
            cells,
            "no rule of the file joins it to the build",
        );
    }
    let (nx, ny, nz) = fixed.dims();
    let mut target = VoxelGrid::new(nx, ny, nz);
    for r in &order {
        target.set_body(&r.piece.body(rules.layer_ldu()), true);
    }
    let mut stats = layout.stats.clone();
    stats.starts = order.iter().filter(|r| r.anchor == Anchor::Start).count() as u64;
    Ok(SearchOutcome {
        order,
        voxels: target,
        repairs: layout.repairs,
        emptied,
        stats,
    })
}

/// A hollow's `emptied` cells cut to whole courses of `phase` layers
/// (every piece starts on a course, see [`layout::phase`]): a cell is left
/// empty only with its whole course's column empty, else it goes back to
/// the `shell`, so that no voxel of the shell lies alone in a course with
/// the hollow over or under it, where no piece could cover it.
fn whole_courses(
    mut shell: VoxelGrid,
    mut emptied: VoxelGrid,
    phase: i32,
) -> (VoxelGrid, VoxelGrid) {
    if phase <= 1 {
        return (shell, emptied);
    }
    let partial: Vec<_> = emptied
        .cells()
        .filter(|c| {
            let base = c.z - c.z.rem_euclid(phase);
            (0..phase).any(|k| !emptied.get(crate::geom::Cell::new(c.x, c.y, base + k)))
        })
        .collect();
    for c in partial {
        emptied.set(c, false);
        shell.set(c, true);
    }
    (shell, emptied)
}

/// Rounds of repairs of pieces that no order puts in place: fills of the
/// gap under them.
const PLACE_ROUNDS: usize = 6;

/// The laid pieces as a derivation, in an order that puts each piece in
/// place at its turn where one exists (`sequence`), and the pieces no rule
/// reaches.
fn derive(layout: &layout::Layout) -> (Vec<Removal>, Vec<u32>) {
    let (order, unreached) = derive::derive(layout);
    // The derivation's own order stands where the verifier finds every
    // piece placeable; else the model is taken apart to find one, kept
    // when it shuts in fewer pieces and breaks nothing else.
    let (blocked, others) = unplaceable_and_others(&order, layout.layer_ldu);
    if blocked.is_empty() {
        return (order, unreached);
    }
    let found = sequence::sequence(layout, order.clone());
    let (left, broken) = unplaceable_and_others(&found, layout.layer_ldu);
    if broken <= others && left.len() < blocked.len() {
        return (found, unreached);
    }
    (order, unreached)
}

/// The positions in `order` of the pieces the verifier finds cannot be put
/// in place at their turn.
fn unplaceable(order: &[Removal], layer_ldu: i32) -> Vec<usize> {
    unplaceable_and_others(order, layer_ldu).0
}

/// [`unplaceable`], and how many other failures the verifier finds (but
/// a build in more than one part, which the derivation leaves to its
/// caller).
fn unplaceable_and_others(order: &[Removal], layer_ldu: i32) -> (Vec<usize>, usize) {
    use crate::assembly::verify::Failure;
    let pieces: Vec<Placement> = order.iter().map(|r| r.piece).collect();
    let asm = crate::assembly::Assembly::from_order(&pieces, layer_ldu, crate::catalog::Color::RED);
    let mut others = 0;
    let blocked = crate::assembly::verify::verify(&asm, None)
        .failures
        .iter()
        .filter_map(|f| match f {
            Failure::NotPlaceable { piece, .. } | Failure::Enclosed { piece, .. } => Some(*piece),
            Failure::Disconnected { .. } => None,
            _ => {
                others += 1;
                None
            }
        })
        .collect();
    (blocked, others)
}

/// The search's seeded random streams: one draws among scored candidates,
/// the other picks the complex rule to test, so that testing a complex
/// rule that does not apply leaves the rest of the search as it was.
pub(crate) struct Dice {
    /// Draws among candidates.
    pub rules: ChaCha8Rng,
    /// Picks complex rules.
    pub complex: ChaCha8Rng,
}

impl Dice {
    /// Both streams from one seed.
    pub fn new(seed: u64) -> Dice {
        let rules = ChaCha8Rng::seed_from_u64(seed);
        let mut complex = rules.clone();
        complex.set_stream(1);
        Dice { rules, complex }
    }
}

/// The pieces of an outcome in build order.
pub fn placements(outcome: &SearchOutcome) -> Vec<Placement> {
    outcome.order.iter().map(|r| r.piece).collect()
}
