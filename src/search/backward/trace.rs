//! The backward trace of one part: a depth-first tree of voxel grids.
//!
//! The root holds the part's voxels. A node's children are rules applied
//! in reverse: a match of a rule's `v` (the anchor `A` and the new piece
//! `B`, or a complex rule's pieces) in the voxels left, replaced by its `u`:
//! `B`'s cells are taken away and `A` stays, now *matched* (pending): a
//! piece of the answer whose cells are still there, to be taken away by a
//! later match. Above the first part, `A` may also be a piece of the parts
//! below, which stays. Each node stores only its local change ([`Change`]);
//! going back up the tree undoes it. The first part's trace succeeds when
//! one piece is left and a starting rule can put it down, a part above
//! when every piece is taken away: read backwards, the matches are the
//! derivation.
//!
//! At each node, rules are drawn from their weights' categorical
//! distribution (without replacement, [`super::draw`]) as the node needs
//! them, and each that matches is tried in the order drawn, up to `b` of
//! them; `b` grows from `b_min` to `b_max` as fewer voxels are left. Where
//! draws keep missing, the node lists the rules that match it and draws
//! among those ([`Trace::draw_next`]). Once every `complex_every` nodes, a
//! complex rule picked with equal probability is tried first. A rule
//! labelled `up` is matched scanning from the top of the grid down, a
//! `down` rule from the bottom up, and each match the scan finds is a
//! child, the first match first. A match must join the pieces matched so
//! far (its new piece or its anchor is a matched piece, or stud-connects
//! to one), except the first, and its new piece must be able to reach its
//! place past what is built before it ([`super::fit`]). A node whose voxels
//! fall apart or leave a voxel no piece can hold, or that was met before
//! and failed with every rule tried, is cut off, and so is a node this
//! pass has searched already, reached again by taking the same pieces in
//! another order (it stays open to the next pass); a node with no child
//! left is backtracked from. Passes restart from the root on the Luby
//! sequence ([`Trace::run`]).

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::rc::Rc;
use std::time::Instant;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::draw::{Drawn, Draws};
use super::fit::{air, placeable_in};
use crate::assembly::Placement;
use crate::catalog::PartKind;
use crate::geom::{Body, Cell, CellBox, Rot};
use crate::grammar::{Dir, Link, RuleRef, RuleSet, Variant};
use crate::keyhash::{KeyMap, KeySet};
use crate::search::rulebook::RuleBook;
use crate::search::{Anchor, Removal};
use crate::voxel::VoxelGrid;

/// How the trace is tuned (from [`crate::search::SearchOptions`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Tuning {
    pub b_min: u32,
    pub b_max: u32,
    pub complex_every: u32,
    pub node_budget: u64,
    /// Nodes a pass makes for each voxel of the part (times the Luby
    /// sequence's term, and at least [`MIN_RESTART`]) before the tree is
    /// searched again from its root; 0 never.
    pub restart: u64,
    pub deadline: Instant,
    /// The height pieces stack by, in layers ([`super::courses::step`]),
    /// and the lowest layer of the whole shape: every piece of a build
    /// has its bottom a whole number of steps above it.
    pub step: i32,
    pub base: i32,
}

/// Counters shared by every part's trace.
#[derive(Debug, Clone, Default)]
pub(super) struct Counters {
    pub nodes: u64,
    pub backtracks: u64,
    pub complex_tried: u64,
    pub complex_applied: u64,
}

/// Why a trace found no derivation.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Stop {
    /// Every branch was tried: (Σ, R) cannot build the part.
    Exhausted,
    /// The part's voxels cannot be one shape held by studs: no piece of
    /// the alphabet covering this voxel holds on to the rest (a wing one
    /// voxel thin, say, touching the body only at its side).
    Apart(Cell),
    /// The node budget ran out.
    Nodes,
    /// The time budget ran out.
    Time,
}

/// A piece's shape: its part and turn.
type Shape = (PartKind, Rot);

/// The fewest nodes a pass makes before it restarts (times the Luby
/// sequence's term): a small part's pass gets at least this many.
const MIN_RESTART: u64 = 100;

/// Draws in a row that match nowhere before a node lists the rules that
/// match it ([`Trace::draw_next`]).
const MISSES: u32 = 256;

/// The rule variants by the shape of their new piece and of their anchor.
struct VariantIndex {
    /// The shapes the rules' pieces take.
    shapes: Vec<Shape>,
    /// The variants (of weight above 0, only those joined where they put
    /// their pieces) by the shape of their new piece, and of their anchor:
    /// each with the other piece's shape and where it lies.
    by_added: Vec<(usize, Arms)>,
    by_anchor: Vec<(usize, Arms)>,
}

/// A rule variant as a list of [`VariantIndex`] holds it, from one of its
/// pieces: the other piece's shape, and the other's origin less this one's.
#[derive(Debug, Clone, Copy)]
struct Arm {
    variant: u32,
    other: u32,
    offset: (i32, i32, i32),
    /// The rule's direction: [`UP`] or [`DOWN`].
    dir: u8,
}

/// The variants of one shape of piece ([`Arm`]s), in runs of the same
/// other shape and direction, each run with the box its offsets span: a
/// run whose other pieces could lie nowhere in that box is passed over
/// whole.
#[derive(Debug, Clone, Default)]
struct Arms {
    arms: Vec<Arm>,
    runs: Vec<Run>,
}

#[derive(Debug, Clone, Copy)]
struct Run {
    other: u32,
    dir: u8,
    from: u32,
    to: u32,
    /// The least and the greatest offset, on each axis.
    lo: Cell,
    hi: Cell,
}

impl Arms {
    fn new(mut arms: Vec<Arm>) -> Arms {
        arms.sort_by_key(|a| (a.other, a.dir, a.variant));
        let mut runs: Vec<Run> = Vec::new();
        for (i, a) in arms.iter().enumerate() {
            let c = Cell::new(a.offset.0, a.offset.1, a.offset.2);
            match runs.last_mut() {
                Some(r) if r.other == a.other && r.dir == a.dir => {
                    r.to = i as u32 + 1;
                    r.lo = Cell::new(r.lo.x.min(c.x), r.lo.y.min(c.y), r.lo.z.min(c.z));
                    r.hi = Cell::new(r.hi.x.max(c.x), r.hi.y.max(c.y), r.hi.z.max(c.z));
                }
                _ => runs.push(Run {
                    other: a.other,
                    dir: a.dir,
                    from: i as u32,
                    to: i as u32 + 1,
                    lo: c,
                    hi: c,
                }),
            }
        }
        Arms { arms, runs }
    }

    fn len(&self) -> usize {
        self.arms.len()
    }

    fn run(&self, r: &Run) -> &[Arm] {
        &self.arms[r.from as usize..r.to as usize]
    }

    /// Marks in `found` each variant of run `r` not `hit` yet whose other
    /// piece, at its offset from `at`, lies where `there` says it may (and
    /// in `hit`, so it is looked at once).
    fn mark(
        &self,
        r: &Run,
        at: Cell,
        there: impl Fn(&Arm, Cell) -> bool,
        hit: &mut [bool],
        found: &mut [bool],
    ) {
        for arm in self.run(r) {
            let v = arm.variant as usize;
            let (ox, oy, oz) = arm.offset;
            if !hit[v] && there(arm, at.offset(ox, oy, oz)) {
                hit[v] = true;
                found[v] = true;
            }
        }
    }
}

/// Adds cell `o` to a set of cells kept as a grid of `dims` and its span,
/// made at its first cell.
fn add_cell(set: &mut Option<(VoxelGrid, Span)>, o: Cell, (nx, ny, nz): (i32, i32, i32)) {
    match set {
        Some((g, span)) => {
            g.set(o, true);
            span.grow(o);
        }
        none => {
            let mut g = VoxelGrid::new(nx, ny, nz);
            g.set(o, true);
            *none = Some((g, Span::of(o)));
        }
    }
}

/// The least and greatest cell of a set of cells, on each axis.
#[derive(Debug, Clone, Copy)]
struct Span {
    lo: Cell,
    hi: Cell,
}

impl Span {
    fn of(c: Cell) -> Span {
        Span { lo: c, hi: c }
    }

    fn grow(&mut self, c: Cell) {
        self.lo = Cell::new(self.lo.x.min(c.x), self.lo.y.min(c.y), self.lo.z.min(c.z));
        self.hi = Cell::new(self.hi.x.max(c.x), self.hi.y.max(c.y), self.hi.z.max(c.z));
    }

    /// Whether a place `at` plus an offset of `run` can fall in the span.
    fn meets(&self, at: Cell, run: &Run) -> bool {
        at.x + run.hi.x >= self.lo.x
            && at.x + run.lo.x <= self.hi.x
            && at.y + run.hi.y >= self.lo.y
            && at.y + run.lo.y <= self.hi.y
            && at.z + run.hi.z >= self.lo.z
            && at.z + run.lo.z <= self.hi.z
    }
}

/// A new piece's ways in ([`Trace::matching`]): from above, from below.
const UP: u8 = 1;
const DOWN: u8 = 2;

impl VariantIndex {
    fn new(rules: &RuleSet) -> VariantIndex {
        let vars = rules.variants();
        let mut shapes: Vec<Shape> = vars
            .iter()
            .flat_map(|v| [(v.added, v.added_rot), (v.anchor, v.anchor_rot)])
            .collect();
        shapes.sort();
        shapes.dedup();
        let at = |s: Shape| shapes.binary_search(&s).expect("every shape is listed");
        let anchor_shape: Vec<usize> = vars.iter().map(|v| at((v.anchor, v.anchor_rot))).collect();
        let added_shape: Vec<usize> = vars.iter().map(|v| at((v.added, v.added_rot))).collect();
        let layer = rules.layer_ldu();
        // Whether each variant's two pieces are stud-joined where it puts
        // them (so wherever it matches: the joint moves with them).
        let joined: Vec<bool> = vars
            .iter()
            .map(|v| {
                let a = Placement::new(v.anchor, Cell::new(0, 0, 0), v.anchor_rot).body(layer);
                let (ox, oy, oz) = v.offset;
                let b = Placement::new(v.added, Cell::new(ox, oy, oz), v.added_rot).body(layer);
                if v.dir == Dir::Up {
                    a.holds(&b)
                } else {
                    b.holds(&a)
                }
            })
            .collect();
        // From the new piece (`from_added`) or from the anchor.
        let group = |from_added: bool| {
            let mut m: Vec<(usize, Vec<Arm>)> =
                (0..shapes.len()).map(|s| (s, Vec::new())).collect();
            for (i, v) in vars.iter().enumerate() {
                if v.weight > 0.0 && joined[i] {
                    let (ox, oy, oz) = v.offset;
                    let (this, other, offset) = if from_added {
                        (added_shape[i], anchor_shape[i], (-ox, -oy, -oz))
                    } else {
                        (anchor_shape[i], added_shape[i], (ox, oy, oz))
                    };
                    m[this].1.push(Arm {
                        variant: i as u32,
                        other: other as u32,
                        offset,
                        dir: if v.dir == Dir::Up { UP } else { DOWN },
                    });
                }
            }
            m.retain(|(_, l)| !l.is_empty());
            m.into_iter()
                .map(|(s, l)| (s, Arms::new(l)))
                .collect::<Vec<_>>()
        };
        VariantIndex {
            by_added: group(true),
            by_anchor: group(false),
            shapes: shapes.clone(),
        }
    }

    /// The index of a shape in `shapes`, if a rule's piece takes it.
    fn shape_index(&self, part: PartKind, rot: Rot) -> Option<usize> {
        self.shapes.binary_search(&(part, rot)).ok()
    }
}

/// How a pass ends (when it does not stop the trace).
enum Pass {
    /// With a derivation.
    Found(Vec<Removal>),
    /// With no child left at the root.
    Ended,
    /// At its share of nodes: the next pass starts again at the root.
    CutShort,
}

/// The `i`-th term (from 1) of the Luby sequence: 1, 1, 2, 1, 1, 2, 4, 1,
/// 1, 2, 1, 1, 2, 4, 8, ...
fn luby(i: u32) -> u64 {
    let mut i = u64::from(i.max(1));
    loop {
        // The smallest k with 2^k - 1 >= i.
        let k = 64 - i.leading_zeros();
        if i == (1u64 << k) - 1 {
            return 1u64 << (k - 1);
        }
        i -= (1u64 << (k - 1)) - 1;
    }
}

/// A node's local change: the pieces a reverse match took away (each with
/// the piece it joins), and the pieces it left matched.
#[derive(Debug, Clone)]
struct Change {
    rule: RuleRef,
    /// Taken away, in forward order, each with its anchor.
    taken: Vec<(Placement, Placement)>,
    /// Anchors that became pending with this match.
    new_pending: Vec<Placement>,
}

/// One node of the depth-first tree: the rules still to try at it.
struct Frame {
    /// Rules to try, in order: `Ok(variant)` a basic rule variant,
    /// `Err(variant)` a complex one.
    tries: Vec<Result<u32, u32>>,
    /// The first match of each basic variant in `tries`, found when it
    /// was drawn.
    first: Vec<Option<(Change, usize)>>,
    next: usize,
    /// Where the scan of the rule being tried goes on: each match of a
    /// rule, in scan order, is a child.
    cursor: usize,
    /// (B, A) pairs already tried here.
    tried: KeySet<(Placement, Placement)>,
    /// Where each shape of new piece may be taken away at this node.
    spots: RefCell<KeyMap<Shape, Rc<[Placement]>>>,
    /// The matched pieces something left touches (see [`Trace::frontier`]).
    frontier: Vec<Placement>,
    /// The change that made this node from its parent.
    change: Option<Change>,
    /// Whether every rule that could match is among `tries` (`b` was no
    /// smaller than their number).
    complete: bool,
    /// How many basic variants the node may try: `b`.
    b: usize,
    /// The variants drawn here so far, and draws whose groups were shut.
    drawn: Vec<Drawn>,
    shut: Vec<Drawn>,
    /// Draws in a row that matched nowhere.
    misses: u32,
    /// Once drawing misses too often: every variant not drawn yet that
    /// matches here, in the order of a draw from their weights.
    listed: Option<std::collections::VecDeque<u32>>,
    /// Whether every child's subtree was searched whole (each of its nodes
    /// `complete`): only a node complete and whole has failed for good.
    whole: bool,
}

/// A part being traced.
pub(super) struct Trace<'a> {
    rules: &'a RuleSet,
    book: &'a RuleBook,
    layer: i32,
    tuning: Tuning,
    /// The part's voxels still there.
    left: VoxelGrid,
    left_count: usize,
    total: usize,
    /// Cells of pending pieces.
    held: VoxelGrid,
    /// The free cells: left, and no pending piece's.
    open: VoxelGrid,
    pending: Vec<Placement>,
    pending_set: KeySet<Placement>,
    /// Pieces taken away, in backward order, with the rule and anchor.
    taken: Vec<Placement>,
    /// The pieces of the parts below, built before this part.
    below_pieces: &'a [Placement],
    /// The cells of the parts below.
    below: &'a VoxelGrid,
    /// The pieces below that this part's cells sit on: matched from the
    /// start, anchors a match may join (never taken away).
    ground: Vec<Placement>,
    ground_set: KeySet<Placement>,
    /// The pieces a match may join that stay: pending ones and the ones
    /// below.
    stay: KeySet<Placement>,
    /// Whether this is the first part (its last piece needs a starting
    /// rule; the others' a rule joining it to the parts below).
    first: bool,
    /// What is built when a piece of this part goes in: what is left of
    /// it, and the parts below (a scratch copy the flood fill empties a
    /// piece's cells in, and fills again).
    built: RefCell<VoxelGrid>,
    /// The empty cells beside what is built that reach the space beside
    /// the grid or above it ([`air`]), once found at this node.
    air: RefCell<Option<VoxelGrid>>,
    /// Shapes of the alphabet's pieces, each turn: what can cover a cell.
    shapes: Vec<Body>,
    /// How many times wider `b` is than tuned: doubled each time a pass
    /// of the tree that tried only `b` rules at some node comes back with
    /// nothing, until every rule is tried at every node.
    widen: u32,
    hash: u64,
    failed: HashSet<u64>,
    /// Whether the last pass's root was complete and whole.
    last_pass_whole: bool,
    /// For each applied change, which of its taken pieces were pending.
    were_log: Vec<Vec<bool>>,
    /// Each free cell's last piece found by [`Trace::coverable`].
    witness: RefCell<HashMap<Cell, Body>>,
    /// The rules' draws.
    draws: RefCell<Draws>,
    /// The rules by shape.
    index: VariantIndex,
    /// The shape's voxels: this part's and the parts' below.
    model: VoxelGrid,
}

/// A piece's share of a state's hash (`salt` 1: matched, 2: taken).
fn piece_hash(p: &Placement, salt: u64) -> u64 {
    let o = p.origin;
    let key = u64::from(p.part.0)
        | u64::from(o.x as u16) << 16
        | u64::from(o.y as u16) << 32
        | u64::from(o.z as u16) << 48;
    mix(key ^ mix((p.rot as u64) << 2 | salt))
}

/// SplitMix64's finaliser: every bit of the key stirs every bit out.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl<'a> Trace<'a> {
    /// A trace of the voxels `cells`, with `below` (and its pieces) built
    /// before it.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        rules: &'a RuleSet,
        book: &'a RuleBook,
        tuning: Tuning,
        cells: VoxelGrid,
        below: &'a VoxelGrid,
        below_pieces: &'a [Placement],
        first: bool,
    ) -> Trace<'a> {
        let (nx, ny, nz) = cells.dims();
        let n = cells.count();
        let mut built = below.clone();
        for c in cells.cells() {
            built.set(c, true);
        }
        let layer = rules.layer_ldu();
        let model = built.clone();
        let ground: Vec<Placement> = below_pieces
            .iter()
            .filter(|p| {
                let top = p.body(layer).over_studs();
                let on = top.cells().any(|c| cells.in_bounds(c) && cells.get(c));
                on
            })
            .copied()
            .collect();
        Trace {
            rules,
            book,
            layer: rules.layer_ldu(),
            tuning,
            left: cells.clone(),
            left_count: n,
            total: n,
            held: VoxelGrid::new(nx, ny, nz),
            open: cells,
            pending: Vec::new(),
            pending_set: KeySet::default(),
            taken: Vec::new(),
            below_pieces,
            below,
            ground_set: ground.iter().copied().collect(),
            stay: ground.iter().copied().collect(),
            ground,
            first,
            built: RefCell::new(built),
            air: RefCell::new(None),
            shapes: coverers(rules),
            model,
            widen: 1,
            hash: 0,
            failed: HashSet::new(),
            last_pass_whole: false,
            were_log: Vec::new(),
            witness: RefCell::new(HashMap::new()),
            draws: RefCell::new(Draws::new(rules.variants())),
            index: VariantIndex::new(rules),
        }
    }

    /// Traces the part; its derivation in forward order.
    ///
    /// The tree is searched in passes. A node tries the `b` rules drawn
    /// first; when a pass comes back to the root with nothing and some
    /// node tried fewer than all its rules, `b` is doubled and the tree
    /// searched again (what failed for good is remembered, so a pass
    /// repeats little). Only a pass in which every node tried every rule
    /// proves the rules cannot build the part.
    ///
    /// A pass also ends when it has made `restart` nodes a voxel times
    /// the next term of the Luby sequence (1, 1, 2, 1, 1, 2, 4, ...) without an
    /// answer: the tree is searched again from its root with new draws.
    /// A depth-first search whose draws fix a wrong piece near the root
    /// can spend its whole budget under it; the draws of another pass
    /// seldom make the same mistake, and the growing terms leave room for
    /// a pass as long as the part needs.
    pub fn run(
        &mut self,
        rng: &mut ChaCha8Rng,
        count: &mut Counters,
    ) -> Result<Vec<Removal>, Stop> {
        if let Some(r) = self.single_piece() {
            return Ok(vec![r]);
        }
        if let Some(c) = self.uncoverable() {
            return Err(Stop::Apart(c));
        }
        let all = self.rules.variants().len() as u32;
        for i in 1u32.. {
            let limit = match self.tuning.restart {
                0 => u64::MAX,
                r => {
                    let base = r.saturating_mul(self.total as u64).max(MIN_RESTART);
                    count.nodes.saturating_add(base.saturating_mul(luby(i)))
                }
            };
            match self.pass(rng, count, limit)? {
                Pass::Found(d) => return Ok(d),
                Pass::CutShort => continue,
                Pass::Ended => {}
            }
            if self.last_pass_whole || self.tuning.b_min.max(1) * self.widen > all {
                return Err(Stop::Exhausted);
            }
            self.widen *= 2;
        }
        unreachable!("a pass ends the loop")
    }

    /// One pass of the depth-first tree, until it finds a derivation, the
    /// root has no child left (`last_pass_whole` says whether for good),
    /// or the count of nodes reaches `limit`.
    fn pass(
        &mut self,
        rng: &mut ChaCha8Rng,
        count: &mut Counters,
        limit: u64,
    ) -> Result<Pass, Stop> {
        let mut log: Vec<Change> = Vec::new();
        // The nodes whose subtrees this pass searched to the end, by state.
        let mut exhausted: HashSet<u64> = HashSet::new();
        let root = self.frame(rng, count, None);
        let mut stack = vec![root];
        let mut ticks = 0u64;
        loop {
            if let Some(last) = self.finished() {
                return Ok(Pass::Found(self.derivation(&log, last)));
            }
            if count.nodes >= self.tuning.node_budget {
                return Err(Stop::Nodes);
            }
            if count.nodes >= limit {
                // Back to the root, undoing every change on the way.
                while let Some(f) = stack.pop() {
                    if let Some(c) = f.change {
                        self.undo(&c);
                    }
                }
                return Ok(Pass::CutShort);
            }
            // Counted in turns of this loop, not in nodes: where most
            // children are cut at once, nodes come slowly.
            ticks += 1;
            if ticks.is_multiple_of(64) && Instant::now() >= self.tuning.deadline {
                return Err(Stop::Time);
            }
            let Some(top) = stack.last_mut() else {
                return Ok(Pass::Ended);
            };
            let mut child = None;
            while child.is_none() {
                // A node may go through many rules before one matches.
                ticks += 1;
                if ticks.is_multiple_of(64) && Instant::now() >= self.tuning.deadline {
                    return Err(Stop::Time);
                }
                if top.next == top.tries.len() && !self.draw_next(top, rng) {
                    break;
                }
                let t = top.tries[top.next];
                let found = match t {
                    Ok(v) => match top.first[top.next].take() {
                        Some(m) if top.cursor == 0 => Some(m),
                        _ => self.match_basic(v, top, top.cursor),
                    },
                    Err(v) => {
                        if top.cursor == 0 {
                            count.complex_tried += 1;
                        }
                        self.match_complex(v, top, top.cursor)
                    }
                };
                match found {
                    Some((c, at)) => {
                        top.cursor = at + 1;
                        top.tried.insert((c.taken[0].0, c.taken[0].1));
                        child = Some(c);
                    }
                    None => {
                        top.next += 1;
                        top.cursor = 0;
                    }
                }
            }
            match child {
                Some(c) => {
                    count.nodes += 1;
                    // A match that leaves a matched piece held by nothing
                    // splits the build: cut before it is applied.
                    if self.strands(&c) {
                        continue;
                    }
                    self.apply(&c);
                    if self.failed.contains(&self.hash) || !self.connected() || !self.coverable() {
                        self.undo(&c);
                        continue;
                    }
                    // The same pieces taken and matched, reached before in
                    // another order: searched already in this pass (with
                    // the rules drawn there), so not again; the node stays
                    // open to the next pass.
                    if exhausted.contains(&self.hash) {
                        self.undo(&c);
                        if let Some(top) = stack.last_mut() {
                            top.whole = false;
                        }
                        continue;
                    }
                    if matches!(c.rule, RuleRef::Complex(_)) {
                        count.complex_applied += 1;
                    }
                    log.push(c.clone());
                    let f = self.frame(rng, count, Some(c));
                    stack.push(f);
                }
                None => {
                    // Every rule tried: back up.
                    let done = stack.pop().expect("a frame is on the stack");
                    // A node that tried only `b` of its rules, or under
                    // which one did, may succeed when met again.
                    let whole = done.complete && done.whole;
                    if whole {
                        self.failed.insert(self.hash);
                    } else {
                        exhausted.insert(self.hash);
                    }
                    match stack.last_mut() {
                        Some(parent) => parent.whole &= whole,
                        None => self.last_pass_whole = whole,
                    }
                    if let Some(c) = done.change {
                        count.backtracks += 1;
                        self.undo(&c);
                        log.pop();
                    }
                }
            }
        }
    }

    /// A node: its `b` (its rules to try are drawn as they are needed,
    /// [`Trace::draw_next`]), and a complex rule to try first every
    /// `complex_every` nodes.
    fn frame(&self, rng: &mut ChaCha8Rng, count: &Counters, change: Option<Change>) -> Frame {
        let t = &self.tuning;
        let done = 1.0 - self.left_count as f64 / self.total.max(1) as f64;
        let b = t.b_min as f64 + (t.b_max.saturating_sub(t.b_min)) as f64 * done;
        let b = (b.round() as usize)
            .saturating_mul(self.widen as usize)
            .max(1);
        let mut frame = Frame {
            tries: Vec::new(),
            first: Vec::new(),
            next: 0,
            cursor: 0,
            tried: KeySet::default(),
            spots: RefCell::new(KeyMap::default()),
            frontier: self.frontier(),
            change,
            complete: false,
            whole: true,
            b,
            drawn: Vec::new(),
            shut: Vec::new(),
            misses: 0,
            listed: None,
        };
        let nc = self.rules.complex_variants().len();
        if t.complex_every > 0 && nc > 0 && count.nodes.is_multiple_of(u64::from(t.complex_every)) {
            let pick = rng.gen_range(0..nc) as u32;
            frame.tries.insert(0, Err(pick));
            frame.first.insert(0, None);
        }
        frame
    }

    /// Draws the node's next rule to try: a basic rule variant that
    /// matches here, drawn from the weights among those not drawn yet
    /// (without replacement; the rules drawn before at this node stay
    /// out). `false` when the node has tried `b` of them, or every one
    /// that matches (then it is `complete`).
    ///
    /// Most draws match at once. Where few rules match (near the end of a
    /// part, where a last piece can only join the parts below), drawing
    /// would go through nearly every rule: after [`MISSES`] misses in a
    /// row the node finds every variant that matches instead, going over
    /// its places rather than its rules, and draws among those. Both
    /// give the same order of rules, in law: each next rule is drawn in
    /// proportion to its weight among the ones left that match.
    fn draw_next(&self, frame: &mut Frame, rng: &mut ChaCha8Rng) -> bool {
        let basics = frame.tries.iter().filter(|t| t.is_ok()).count();
        if basics >= frame.b {
            return false;
        }
        if let Some(list) = &mut frame.listed {
            let Some(v) = list.pop_front() else {
                frame.complete = true;
                return false;
            };
            frame.tries.push(Ok(v));
            frame.first.push(None);
            return true;
        }
        let mut draws = self.draws.borrow_mut();
        draws.reopen(&frame.drawn, &frame.shut);
        let mut found = false;
        while !found {
            let Some(d) = draws.draw(rng) else {
                frame.complete = true;
                break;
            };
            frame.drawn.push(d);
            let var = &self.rules.variants()[d.variant as usize];
            if self.spots_at(frame, (var.added, var.added_rot)).is_empty()
                && self
                    .spots_at(frame, (var.anchor, var.anchor_rot))
                    .is_empty()
            {
                draws.shut(d);
                frame.shut.push(d);
                continue;
            }
            if let Some(m) = self.match_basic(d.variant, frame, 0) {
                frame.tries.push(Ok(d.variant));
                frame.first.push(Some(m));
                frame.misses = 0;
                found = true;
            } else {
                frame.misses += 1;
                if frame.misses >= MISSES {
                    break;
                }
            }
        }
        draws.close();
        drop(draws);
        if !found && !frame.complete {
            let drawn: KeySet<u32> = frame.drawn.iter().map(|d| d.variant).collect();
            let mut keyed: Vec<(f64, u32)> = self
                .matching(frame, &drawn)
                .into_iter()
                .map(|v| {
                    let w = self.rules.variants()[v as usize].weight;
                    let u: f64 = rng.gen_range(f64::MIN_POSITIVE..1.0);
                    (u.ln() / w, v)
                })
                .collect();
            keyed.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            frame.listed = Some(keyed.into_iter().map(|(_, v)| v).collect());
            return self.draw_next(frame, rng);
        }
        found
    }

    /// Every basic variant not in `drawn` that matches somewhere at
    /// `node`, in the rule file's order: found from the places (each
    /// place a new piece may be taken away, with each variant of its
    /// shape; each free place an anchor may stay, with each variant of
    /// its shape), not by trying each rule.
    ///
    /// Where a new piece of each shape has a way in is found first, once
    /// a place (few places do: most are shut in by the voxels left above
    /// and below), so each rule tried at a place costs a look-up.
    fn matching(&self, node: &Frame, drawn: &KeySet<u32>) -> Vec<u32> {
        let vars = self.rules.variants();
        let ix = &self.index;
        let mut hit: Vec<bool> = vec![false; vars.len()];
        for &v in drawn {
            // Drawn already: not listed again.
            hit[v as usize] = true;
        }
        let mut found = vec![false; vars.len()];
        // For each shape, where it is free (from each free cell) and where
        // a piece of it stays (pending, or below the part): by origin.
        let (nx, ny, nz) = self.left.dims();
        let probes: Vec<Body> = ix
            .shapes
            .iter()
            .map(|&(part, rot)| self.body(&Placement::new(part, Cell::new(0, 0, 0), rot)))
            .collect();
        let free_at: Vec<VoxelGrid> = probes
            .iter()
            .map(|p| {
                let mut g = self.open.fits(p.boxes());
                if !p.is_box() {
                    for o in g.clone().cells() {
                        if !self.clear_face(&p.moved(o.x, o.y, o.z)) {
                            g.set(o, false);
                        }
                    }
                }
                g
            })
            .collect();
        let mut stay_at: Vec<Option<VoxelGrid>> = vec![None; ix.shapes.len()];
        let mut pending_at: Vec<Option<VoxelGrid>> = vec![None; ix.shapes.len()];
        for (set, of) in [
            (&mut stay_at, &self.stay),
            (&mut pending_at, &self.pending_set),
        ] {
            for p in of {
                if let Some(i) = ix.shape_index(p.part, p.rot) {
                    if self.left.in_bounds(p.origin) {
                        set[i]
                            .get_or_insert_with(|| VoxelGrid::new(nx, ny, nz))
                            .set(p.origin, true);
                    }
                }
            }
        }
        let ok_at = |shape: usize, o: Cell| {
            free_at[shape].get(o) || stay_at[shape].as_ref().is_some_and(|m| m.get(o))
        };
        // Where a new piece of each shape has a way in (its cells free or
        // it is matched, not a piece below): from above in `ways[s][0]`,
        // from below in `ways[s][1]`, with the span of those places, and
        // the places as a list.
        type Ways = [Option<(VoxelGrid, Span)>; 2];
        let mut ways: Vec<Ways> = vec![[None, None]; ix.shapes.len()];
        let mut entries: Vec<Vec<(Cell, u8)>> = vec![Vec::new(); ix.shapes.len()];
        // A piece goes in from above only where the layer over its box is
        // empty, from below where the one under it is (as [`fit`] has it):
        // the places where neither is are passed over at once.
        let (over, under) = {
            let built = self.built.borrow();
            (built.empty_beside(1), built.empty_beside(-1))
        };
        for (shape, _) in &ix.by_added {
            let s = *shape;
            let bx = probes[s].bbox;
            let mut may = if bx.min.x < 0 || bx.min.y < 0 || bx.min.z < 0 {
                free_at[s].clone()
            } else {
                let layer = |z: i32| CellBox {
                    min: Cell::new(bx.min.x, bx.min.y, z),
                    sz: 1,
                    ..bx
                };
                let mut m = over.fits(&[layer(bx.min.z + bx.sz - 1)]);
                m.unite(&under.fits(&[layer(bx.min.z)]));
                m.intersect(&free_at[s]);
                m
            };
            if let Some(p) = &pending_at[s] {
                may.unite(p);
            }
            for o in may.cells() {
                let b = probes[s].moved(o.x, o.y, o.z);
                let mut w = 0;
                for (k, (dir, up)) in [(UP, true), (DOWN, false)].into_iter().enumerate() {
                    if self.can_place(&b, &[], up) {
                        w |= dir;
                        add_cell(&mut ways[s][k], o, (nx, ny, nz));
                    }
                }
                if w != 0 {
                    entries[s].push((o, w));
                }
            }
        }
        let dir_index = |dir: u8| usize::from(dir == DOWN);
        for (shape, arms) in &ix.by_added {
            for b in self.spots_at(node, ix.shapes[*shape]).iter() {
                // A place no piece can reach is no rule's.
                if self.ground_set.contains(b) {
                    continue;
                }
                let w = [UP, DOWN]
                    .into_iter()
                    .filter(|&d| {
                        ways[*shape][dir_index(d)]
                            .as_ref()
                            .is_some_and(|(g, _)| g.get(b.origin))
                    })
                    .fold(0, |w, d| w | d);
                if w == 0 {
                    continue;
                }
                for run in &arms.runs {
                    if w & run.dir == 0 {
                        continue;
                    }
                    let there = |arm: &Arm, c: Cell| ok_at(arm.other as usize, c);
                    arms.mark(run, b.origin, there, &mut hit, &mut found);
                }
            }
        }
        // Anchors at free places where they may join what is matched, with
        // a new piece that has a way in: gone over from the anchors' side
        // or from the new pieces', whichever has fewer pairs to look at.
        let mut free_spots: Vec<Option<(VoxelGrid, Span)>> = vec![None; ix.shapes.len()];
        let mut from_anchors = 0usize;
        for (shape, arms) in &ix.by_anchor {
            for a in self.spots_at(node, ix.shapes[*shape]).iter() {
                if !self.stay.contains(a) && self.left.in_bounds(a.origin) {
                    let o = a.origin;
                    add_cell(&mut free_spots[*shape], o, (nx, ny, nz));
                    from_anchors += arms.len();
                }
            }
        }
        let from_added: usize = ix
            .by_added
            .iter()
            .map(|(s, arms)| entries[*s].len() * arms.len())
            .sum();
        if from_added < from_anchors {
            for (shape, arms) in &ix.by_added {
                for &(o, w) in &entries[*shape] {
                    for run in &arms.runs {
                        if w & run.dir == 0 {
                            continue;
                        }
                        let Some((spots, span)) = &free_spots[run.other as usize] else {
                            continue;
                        };
                        if !span.meets(o, run) {
                            continue;
                        }
                        arms.mark(run, o, |_, c| spots.get(c), &mut hit, &mut found);
                    }
                }
            }
        } else {
            for (shape, arms) in &ix.by_anchor {
                let Some((spots, _)) = &free_spots[*shape] else {
                    continue;
                };
                for a in spots.cells() {
                    for run in &arms.runs {
                        let Some((way, span)) = &ways[run.other as usize][dir_index(run.dir)]
                        else {
                            continue;
                        };
                        if !span.meets(a, run) {
                            continue;
                        }
                        arms.mark(run, a, |_, c| way.get(c), &mut hit, &mut found);
                    }
                }
            }
        }
        (0..vars.len() as u32)
            .filter(|&v| found[v as usize])
            .collect()
    }

    /// Where a piece of `shape` may be taken away at `node` (or stay, as
    /// an anchor): [`Trace::spots`], found once a node.
    fn spots_at(&self, node: &Frame, shape: (PartKind, Rot)) -> Rc<[Placement]> {
        if let Some(s) = node.spots.borrow().get(&shape) {
            return Rc::clone(s);
        }
        let s: Rc<[Placement]> = self.spots(shape.0, shape.1, &node.frontier).into();
        node.spots.borrow_mut().insert(shape, Rc::clone(&s));
        s
    }

    /// The matched pieces (and the pieces below the part) that something
    /// left touches above or below: where a match may join them.
    fn frontier(&self) -> Vec<Placement> {
        let near = |bx: CellBox| {
            bx.cells()
                .any(|d| self.left.in_bounds(d) && self.left.get(d))
        };
        self.pending
            .iter()
            .chain(&self.taken)
            .chain(&self.ground)
            .filter(|m| {
                let b = self.body(m);
                near(b.over_studs()) || near(b.under_tubes())
            })
            .copied()
            .collect()
    }

    fn body(&self, p: &Placement) -> Body {
        p.body(self.layer)
    }

    /// Whether every cell of `b` is left and not held by a pending piece.
    fn free(&self, b: &Body) -> bool {
        b.boxes().iter().all(|bx| self.open.all_set(bx)) && self.clear_face(b)
    }

    /// Whether no voxel of the shape lies in the cells of `b`'s box that
    /// it does not fill (a slope's sloping face passes through them): a
    /// piece there would meet the face, and the verifier refuses pieces
    /// whose boxes overlap. Every voxel is some piece's, so a slope stands
    /// only where the shape is empty over its low rows.
    fn clear_face(&self, b: &Body) -> bool {
        b.is_box() || face_cells(b).all(|c| !self.model.get(c))
    }

    /// Sets [`Trace::open`] again over the cells of `b`, from `left` and
    /// `held`.
    fn reopen(&mut self, b: &Body) {
        for c in b.cells() {
            let on = self.left.get(c) && !self.held.get(c);
            self.open.set(c, on);
        }
    }

    fn is_pending(&self, p: &Placement) -> bool {
        self.pending_set.contains(p)
    }

    /// Where a piece of `part` turned `rot` may be taken away: the pending
    /// pieces of that shape, and free places stud-connected to a matched
    /// piece (anywhere free for the first match). Sorted bottom to top.
    fn spots(&self, part: PartKind, rot: Rot, frontier: &[Placement]) -> Vec<Placement> {
        let mut out: Vec<Placement> = self
            .pending
            .iter()
            .chain(&self.ground)
            .filter(|p| p.part == part && p.rot == rot)
            .copied()
            .collect();
        let probe = self.body(&Placement::new(part, Cell::new(0, 0, 0), rot));
        let shape = probe.bbox;
        if self.pending.is_empty() && self.taken.is_empty() {
            let (nx, ny, nz) = self.left.dims();
            for z in 0..nz {
                for y in 0..ny {
                    for x in 0..nx {
                        let p = Placement::new(part, Cell::new(x, y, z), rot);
                        let b = self.body(&p);
                        if self.on_step(&b) && self.free(&b) {
                            out.push(p);
                        }
                    }
                }
            }
        } else {
            for m in frontier {
                let mb = self.body(m);
                let bb = mb.bbox;
                for z in [bb.min.z + bb.sz, bb.min.z - shape.sz] {
                    for y in bb.min.y - shape.sy + 1..bb.min.y + bb.sy {
                        for x in bb.min.x - shape.sx + 1..bb.min.x + bb.sx {
                            let at = Cell::new(x, y, z);
                            let b = probe.moved(at.x, at.y, at.z);
                            if (mb.holds(&b) || b.holds(&mb)) && self.free(&b) {
                                out.push(Placement::new(part, at, rot));
                            }
                        }
                    }
                }
            }
        }
        out.sort_by_key(|p| (p.origin.z, p.origin.y, p.origin.x));
        out.dedup();
        out
    }

    /// Whether a piece taken away at `b` could have been put in place:
    /// what is left of the part besides `b`, and the parts below, leave it
    /// a way in.
    fn can_place(&self, b: &Body, also_gone: &[Body], from_above: bool) -> bool {
        // The layer beside its box that way must be empty (it passes
        // through it whether it goes straight or moves about).
        let bx = b.bbox;
        let z = if from_above {
            bx.min.z + bx.sz
        } else {
            bx.min.z - 1
        };
        let side = CellBox {
            min: Cell::new(bx.min.x, bx.min.y, z),
            sz: 1,
            ..bx
        };
        if also_gone.is_empty() && self.built.borrow().any_set(&side) {
            return false;
        }
        // The air outside what is built, found once a node.
        let mut air_now = self.air.borrow_mut();
        if also_gone.is_empty() && air_now.is_none() {
            *air_now = Some(air(&self.built.borrow()));
        }
        let air_now = air_now.as_ref().filter(|_| also_gone.is_empty());
        let mut solid = self.built.borrow_mut();
        solid.set_body(b, false);
        for g in also_gone {
            solid.set_body(g, false);
        }
        let ok = placeable_in(&b.bbox, &solid, from_above, air_now);
        solid.set_body(b, true);
        for g in also_gone {
            solid.set_body(g, true);
        }
        ok
    }

    /// The first match of basic variant `v` in its scan direction, from
    /// the `from`-th place the scan looks at.
    fn match_basic(&self, v: u32, node: &Frame, from: usize) -> Option<(Change, usize)> {
        let var = self.rules.variants()[v as usize];
        let (ox, oy, oz) = var.offset;
        // The new piece where it joins what is matched, or where its
        // anchor does: the two lists of places merged in scan order (a
        // `down` rule from the bottom up, an `up` rule from the top down).
        let bs = self.spots_at(node, (var.added, var.added_rot));
        let anchors = self.spots_at(node, (var.anchor, var.anchor_rot));
        let up = var.dir == Dir::Up;
        let (n, m) = (bs.len(), anchors.len());
        let nth_b = |i: usize| if up { bs[n - 1 - i] } else { bs[i] };
        let nth_a = |j: usize| {
            let a = if up { anchors[m - 1 - j] } else { anchors[j] };
            Placement::new(var.added, a.origin.offset(ox, oy, oz), var.added_rot)
        };
        let key = |p: &Placement| (p.origin.z, p.origin.y, p.origin.x);
        let (mut i, mut j, mut k) = (0usize, 0usize, 0usize);
        let mut last: Option<Placement> = None;
        let tried = &node.tried;
        loop {
            // `of_b`: the place comes from the new piece's list (so it is
            // free, pending or below), else from the anchor's.
            let (b, of_b) = match (i < n, j < m) {
                (false, false) => return None,
                (true, false) => {
                    i += 1;
                    (nth_b(i - 1), true)
                }
                (false, true) => {
                    j += 1;
                    (nth_a(j - 1), false)
                }
                (true, true) => {
                    let (x, y) = (nth_b(i), nth_a(j));
                    let x_first = if up {
                        key(&x) >= key(&y)
                    } else {
                        key(&x) <= key(&y)
                    };
                    if x_first {
                        i += 1;
                        (x, true)
                    } else {
                        j += 1;
                        (y, false)
                    }
                }
            };
            // A place in both lists is looked at once.
            if last == Some(b) {
                continue;
            }
            last = Some(b);
            k += 1;
            if k - 1 < from {
                continue;
            }
            let at = b.origin.offset(-ox, -oy, -oz);
            let a = Placement::new(var.anchor, at, var.anchor_rot);
            if tried.contains(&(b, a)) {
                continue;
            }
            let way_in = |_: &Placement, bb: &Body, up: bool| self.can_place(bb, &[], up);
            if let Some(c) = self.match_at(&var, b, of_b, &way_in) {
                return Some((c, k - 1));
            }
        }
    }

    /// Whether variant `var` matches with its new piece at `b` (a place
    /// from the new piece's list of places if `of_b`, else one its anchor
    /// makes from the anchor's list): its change.
    /// `way_in` says whether a piece can go in at its place from above
    /// (or below).
    fn match_at(
        &self,
        var: &Variant,
        b: Placement,
        of_b: bool,
        way_in: &dyn Fn(&Placement, &Body, bool) -> bool,
    ) -> Option<Change> {
        let (ox, oy, oz) = var.offset;
        let up = var.dir == Dir::Up;
        let a = Placement::new(var.anchor, b.origin.offset(-ox, -oy, -oz), var.anchor_rot);
        // The new piece free or matched (a place from its own list is
        // one of those, or a piece below); the anchor free, matched or
        // below (one from its list is).
        let a_pending = self.is_pending(&a) || self.ground_set.contains(&a);
        if of_b && self.ground_set.contains(&b) {
            return None;
        }
        let bb = self.body(&b);
        if !of_b && !self.is_pending(&b) && !self.free(&bb) {
            return None;
        }
        let ab = self.body(&a);
        if of_b && !a_pending && !self.free(&ab) {
            return None;
        }
        // The rule's joint, as the grid has it.
        let joined = if up { ab.holds(&bb) } else { bb.holds(&ab) };
        if !joined || !way_in(&b, &bb, up) {
            return None;
        }
        Some(Change {
            rule: RuleRef::Basic(var.rule),
            taken: vec![(b, a)],
            new_pending: if a_pending { vec![] } else { vec![a] },
        })
    }

    /// The first match of complex variant `v`: its new pieces free or
    /// pending, its `u` pieces pending or free, joined to what is matched.
    fn match_complex(&self, v: u32, node: &Frame, from: usize) -> Option<(Change, usize)> {
        let var = &self.rules.complex_variants()[v as usize];
        let first = var.v.first()?;
        let spots = self.spots_at(node, (first.piece.part, first.piece.rot));
        for (k, s) in spots.iter().rev().enumerate().skip(from) {
            let at = first.piece.at;
            let origin = s.origin.offset(-at.x, -at.y, -at.z);
            let place = |p: &crate::grammar::complex::VariantPiece| {
                Placement::new(p.part, origin.offset(p.at.x, p.at.y, p.at.z), p.rot)
            };
            let news: Vec<Placement> = var.v.iter().map(|n| place(&n.piece)).collect();
            let olds: Vec<Placement> = var.u.iter().map(place).collect();
            let ok_new = news
                .iter()
                .all(|p| self.is_pending(p) || self.free(&self.body(p)));
            let ok_old = olds
                .iter()
                .all(|p| self.is_pending(p) || self.free(&self.body(p)));
            if !ok_new || !ok_old {
                continue;
            }
            let matched = self.pending.is_empty() && self.taken.is_empty()
                || news.iter().chain(&olds).any(|p| {
                    self.is_pending(p)
                        || self
                            .pending
                            .iter()
                            .chain(&self.taken)
                            .chain(&self.ground)
                            .any(|m| {
                                let (a, b) = (self.body(m), self.body(p));
                                a.holds(&b) || b.holds(&a)
                            })
                });
            if !matched {
                continue;
            }
            // Each new piece goes in past the ones before it and what is
            // left; the later ones are not there yet.
            let bodies: Vec<Body> = news.iter().map(|p| self.body(p)).collect();
            let placeable = (0..bodies.len()).all(|i| {
                let anchor = match var.v[i].anchor {
                    Link::U(j) => self.body(&olds[j]),
                    Link::V(j) => bodies[j],
                };
                self.can_place(&bodies[i], &bodies[i + 1..], anchor.holds(&bodies[i]))
            });
            if !placeable {
                continue;
            }
            let taken = var
                .v
                .iter()
                .zip(&news)
                .map(|(n, p)| {
                    let anchor = match n.anchor {
                        Link::U(i) => olds[i],
                        Link::V(i) => news[i],
                    };
                    (*p, anchor)
                })
                .collect();
            let new_pending = olds
                .iter()
                .filter(|p| !self.is_pending(p))
                .copied()
                .collect();
            let c = Change {
                rule: RuleRef::Complex(var.rule),
                taken,
                new_pending,
            };
            return Some((c, k));
        }
        None
    }

    fn apply(&mut self, c: &Change) {
        *self.air.get_mut() = None;
        let c_taken = c.taken.clone();
        let mut were = Vec::with_capacity(c_taken.len());
        for a in &c.new_pending {
            let b = self.body(a);
            self.held.set_body(&b, true);
            self.pending.push(*a);
            self.pending_set.insert(*a);
            self.stay.insert(*a);
            self.hash ^= piece_hash(a, 1);
            self.open.set_body(&b, false);
        }
        for (p, _) in &c_taken {
            let b = self.body(p);
            let was = self.is_pending(p);
            if was {
                self.pending.retain(|q| q != p);
                self.pending_set.remove(p);
                self.stay.remove(p);
                self.held.set_body(&b, false);
                self.hash ^= piece_hash(p, 1);
            }
            were.push(was);
            self.left.set_body(&b, false);
            self.open.set_body(&b, false);
            self.built.get_mut().set_body(&b, false);
            self.left_count -= b.volume() as usize;
            self.taken.push(*p);
            self.hash ^= piece_hash(p, 2);
        }
        // Remember which were pending, for the undo.
        self.were_log.push(were);
    }

    fn undo(&mut self, c: &Change) {
        *self.air.get_mut() = None;
        let were = self.were_log.pop().unwrap_or_default();
        for ((p, _), was) in c.taken.iter().zip(were).rev() {
            let b = self.body(p);
            self.taken.pop();
            self.hash ^= piece_hash(p, 2);
            self.left.set_body(&b, true);
            self.built.get_mut().set_body(&b, true);
            self.left_count += b.volume() as usize;
            if was {
                self.pending.push(*p);
                self.pending_set.insert(*p);
                self.stay.insert(*p);
                self.held.set_body(&b, true);
                self.hash ^= piece_hash(p, 1);
            }
            self.reopen(&b);
        }
        for a in c.new_pending.iter().rev() {
            let b = self.body(a);
            self.held.set_body(&b, false);
            self.pending.retain(|q| q != a);
            self.pending_set.remove(a);
            self.stay.remove(a);
            self.hash ^= piece_hash(a, 1);
            self.reopen(&b);
        }
    }

    /// Whether the match `c` would leave a matched piece (pending, or an
    /// anchor it matches) with nothing left above or below it outside it,
    /// and not on the parts below, while more than that piece is left: a
    /// build split apart, as [`Trace::connected`] would find after it. Only
    /// the pieces whose studs or tubes meet a piece taken away can lose
    /// their hold.
    fn strands(&self, c: &Change) -> bool {
        let gone: Vec<Body> = c.taken.iter().map(|(p, _)| self.body(p)).collect();
        let volume: usize = gone.iter().map(|g| g.volume() as usize).sum();
        let left = self.left_count - volume;
        let is_gone = |d: Cell| gone.iter().any(|g| g.contains(d));
        let meets = |bx: CellBox| gone.iter().any(|g| g.bbox.intersects(&bx));
        self.pending
            .iter()
            .chain(&c.new_pending)
            .filter(|p| !c.taken.iter().any(|(t, _)| t == *p))
            .any(|p| {
                let b = self.body(p);
                let (over, under) = (b.over_studs(), b.under_tubes());
                if (b.volume() as usize) == left || !(meets(over) || meets(under)) {
                    return false;
                }
                let held = |bx: CellBox| {
                    bx.cells().any(|d| {
                        self.left.in_bounds(d) && self.left.get(d) && !is_gone(d) && !b.contains(d)
                    })
                };
                let grounded = under
                    .cells()
                    .any(|d| self.below.in_bounds(d) && self.below.get(d));
                !(grounded || held(over) || held(under))
            })
    }

    /// Whether what is left can still be one shape held together by
    /// studs, as every shape of a derivation is: its cells joined through
    /// cells above or below one another (a stud joint, or a tall piece),
    /// or side by side where one piece may hold both (two free cells, or
    /// two cells of the same matched piece). Side by side cells of two
    /// pieces do not hold each other.
    fn connected(&self) -> bool {
        let Some(start) = self.left.cells().next() else {
            return true;
        };
        // Above the first part, every cell must reach the parts below.
        let mut stack: Vec<Cell> = if self.first {
            vec![start]
        } else {
            self.left
                .cells()
                .filter(|c| {
                    let d = c.offset(0, 0, -1);
                    self.below.in_bounds(d) && self.below.get(d)
                })
                .collect()
        };
        let owner = |c: Cell| -> Option<usize> {
            if !self.held.get(c) {
                return None;
            }
            self.pending.iter().position(|p| self.body(p).contains(c))
        };
        let (nx, ny, nz) = self.left.dims();
        let mut seen = VoxelGrid::new(nx, ny, nz);
        for &c in &stack {
            seen.set(c, true);
        }
        let mut n = 0usize;
        while let Some(c) = stack.pop() {
            n += 1;
            let mine = owner(c);
            for (dx, dy, dz) in crate::geom::FACES {
                let d = c.offset(dx, dy, dz);
                if !self.left.in_bounds(d) || !self.left.get(d) || seen.get(d) {
                    continue;
                }
                if dz == 0 && owner(d) != mine {
                    continue;
                }
                seen.set(d, true);
                stack.push(d);
            }
        }
        n == self.left_count
    }

    /// Whether every free cell (left, and no matched piece's) is a cell of
    /// some piece of the alphabet whose cells are all free and which can
    /// hold on to what is left: the piece that will be taken away with it.
    /// In a shape a derivation can still build, every piece is stud-joined
    /// to another (unless it is all that is left), so the piece's studs or
    /// tubes meet a cell left outside it. A cell no such piece can cover is
    /// a dead end: a free cell on a roof's edge with nothing above or
    /// below, say, whose neighbour toward the middle is held by a matched
    /// piece already. Each cell's last cover is kept and tried first.
    fn coverable(&self) -> bool {
        self.uncoverable().is_none()
    }

    /// A free cell no piece can be taken away with ([`Trace::coverable`]).
    fn uncoverable(&self) -> Option<Cell> {
        let mut witness = self.witness.borrow_mut();
        for c in self.left.cells() {
            if self.held.get(c) {
                continue;
            }
            if let Some(w) = witness.get(&c) {
                if self.covers(w) {
                    continue;
                }
            }
            let found = self.shapes.iter().find_map(|s| {
                s.cells().find_map(|q| {
                    let b = s.moved(c.x - q.x, c.y - q.y, c.z - q.z);
                    (self.on_step(&b) && self.covers(&b)).then_some(b)
                })
            });
            match found {
                Some(b) => {
                    witness.insert(c, b);
                }
                None => return Some(c),
            }
        }
        None
    }

    /// Whether the piece `b` stands a whole number of steps above the
    /// shape's lowest layer, as every piece of a build does (pieces join
    /// only by studs): with slopes, a brick half a course off is in no
    /// derivation, and a cell only such a brick could cover is a dead end.
    fn on_step(&self, b: &Body) -> bool {
        let t = &self.tuning;
        (b.bbox.min.z - t.base).rem_euclid(t.step.max(1)) == 0
    }

    /// Whether the piece `b` could be taken away as it stands: its cells
    /// are free, and it holds on to a cell left outside it (or is all that
    /// is left).
    fn covers(&self, b: &Body) -> bool {
        if !self.free(b) {
            return false;
        }
        let v = b.volume() as usize;
        if v == self.left_count {
            return true;
        }
        let touches = |bx: CellBox| {
            bx.cells()
                .any(|d| self.left.in_bounds(d) && self.left.get(d) && !b.contains(d))
        };
        let grounded = b
            .under_tubes()
            .cells()
            .any(|d| self.below.in_bounds(d) && self.below.get(d));
        grounded || touches(b.over_studs()) || touches(b.under_tubes())
    }

    /// Whether the trace is done, and its last piece: in the first part,
    /// one pending piece is all that is left and a starting rule puts it
    /// down; above it, every piece is taken away (each joined to a piece
    /// of the part or of the parts below), and there is no last piece.
    fn finished(&self) -> Option<Option<Removal>> {
        if !self.first {
            return (self.left_count == 0).then_some(None);
        }
        if self.pending.len() != 1 {
            return None;
        }
        let p = self.pending[0];
        if self.body(&p).volume() as usize != self.left_count {
            return None;
        }
        self.closing(p).map(Some)
    }

    /// How the last piece `p` comes in: a starting rule for the first
    /// part, else the heaviest rule joining it to a piece below.
    fn closing(&self, p: Placement) -> Option<Removal> {
        if self.first {
            return self.rules.can_start(p.part).then(|| Removal::new_start(p));
        }
        let pb = self.body(&p);
        self.below_pieces
            .iter()
            .filter_map(|m| {
                let mb = self.body(m);
                let dir = if mb.holds(&pb) {
                    Dir::Up
                } else if pb.holds(&mb) {
                    Dir::Down
                } else {
                    return None;
                };
                self.book
                    .joint(m, &p, dir, self.layer)
                    .map(|(w, id)| (w, *m, id))
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, m, id)| Removal::forward(p, Anchor::Piece(m), Some(RuleRef::Basic(id))))
    }

    /// A part that is one piece: a starting rule (or a joining rule) alone.
    fn single_piece(&self) -> Option<Removal> {
        let bb = self.left.bounds()?;
        for &part in self.rules.alphabet() {
            for rot in Rot::ALL {
                let p = Placement::new(part, bb.min, rot);
                let b = self.body(&p);
                if b.volume() as usize == self.left_count && self.free(&b) {
                    if let Some(r) = self.closing(p) {
                        return Some(r);
                    }
                }
            }
        }
        None
    }

    /// The derivation, forward: the last piece first, then the pieces
    /// taken away, last taken first.
    fn derivation(&self, log: &[Change], last: Option<Removal>) -> Vec<Removal> {
        let mut out: Vec<Removal> = last.into_iter().collect();
        for c in log.iter().rev() {
            for &(p, a) in &c.taken {
                out.push(Removal::forward(p, Anchor::Piece(a), Some(c.rule)));
            }
        }
        out
    }
}

/// The cells of `b`'s box it does not fill: where a slope's face passes.
fn face_cells(b: &Body) -> impl Iterator<Item = Cell> + '_ {
    b.bbox.cells().filter(|&c| !b.contains(c))
}

/// The bodies of the alphabet's pieces at the origin, every distinct turn.
pub(super) fn coverers(rules: &RuleSet) -> Vec<Body> {
    let mut out: Vec<Body> = Vec::new();
    for &part in rules.alphabet() {
        for rot in Rot::ALL {
            let b = Placement::new(part, Cell::new(0, 0, 0), rot).body(rules.layer_ldu());
            if !out.contains(&b) {
                out.push(b);
            }
        }
    }
    out
}

/// The pieces of a derivation, by placement: for the parts above.
pub(super) fn pieces(order: &[Removal]) -> Vec<Placement> {
    order.iter().map(|r| r.piece).collect()
}

#[cfg(test)]
#[path = "trace_tests.rs"]
mod tests;
