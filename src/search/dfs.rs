//! Backward tracing for one part: depth-first, rules applied in reverse.
//!
//! Each node samples `b` rules from the categorical distribution of the
//! rules' weights (`b` grows as the voxels left go to zero), then scans the
//! grid for matches lazily, in each rule's direction: rules that add a piece
//! on top (`up`) match from the top layer down, rules that add a piece
//! underneath (`down`) from the bottom layer up. A match must connect to the
//! pieces matched so far (the first match excepted; a match that does not is
//! only tried once no connected match is left), must leave a piece that can
//! be pressed into place (the flood-fill check), and must leave voxels that
//! can still form one connected build. A node with no applicable rule is
//! backtracked. Starting rules are always tried: when the voxels left are
//! exactly one piece, or a piece rests on the structure built before. Once
//! every `complex_every` nodes, one complex rule picked with equal
//! probability is tested first: the node scans every cell for it before
//! its sampled rules (module `complex`).

use std::time::Instant;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::complex::{self, Reverse};
use super::state::{Anchor, Change, Model, Removal, State};
use super::{Dice, SearchOptions, SearchStats};
use crate::assembly::Placement;
use crate::catalog::PartKind;
use crate::geom::{Body, Cell, CellBox, Rot};
use crate::grammar::{Dir, RuleRef, RuleSet};
use crate::voxel::VoxelGrid;

/// Matches the backward tracing of a part may look at per voxel of the
/// part before it is generated forward instead.
const MAX_TRIES_PER_VOXEL: u64 = 4_000;

/// What one node may try at a cell.
#[derive(Debug, Clone, Copy)]
enum Slot {
    /// A basic rule's rotated variant, by index.
    Rule(u32),
    /// A starting rule's piece resting on the built structure.
    OnBuilt(PartKind, Rot),
    /// A complex rule's rotated variant, by index, with its new piece of
    /// this index matched at the cell.
    Complex(u32, u8),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Scanning the up order for the complex rule picked for this node,
    /// before any basic rule (every cell, as the paper tests each rule
    /// over the whole grid).
    Complex,
    /// Scanning top-down for up rules and pieces on the built structure
    /// (with nothing built: up and down rules together, outside in).
    Up,
    /// Scanning bottom-up for down rules.
    Down,
    /// Matches that do not touch the matched pieces, held back.
    Deferred,
    /// Once every rule has been tried: the up scan again, from the top,
    /// taking matches that do not touch the matched pieces (more may exist
    /// than were held back).
    Loose,
    Done,
}

struct Frame {
    /// The change that led here from the parent (None at the root).
    applied: Option<Change>,
    /// The variants of the complex rule picked for this node, if any.
    complex: Vec<Slot>,
    up: Vec<Slot>,
    down: Vec<Slot>,
    phase: Phase,
    /// Scan position: index into the phase's cell order, and the slot.
    pos: usize,
    /// Where the up scan starts in its cell order: where the parent's match
    /// was, so the cells peeled already are not walked again; the scan wraps
    /// around to the cells before it.
    start: usize,
    slot: usize,
    deferred: Vec<Candidate>,
    /// Whether the node has widened to every rule after its sample ran dry.
    widened: bool,
}

/// A match that passed the structural checks.
// Candidates are made for every structural match in the hot scan: boxing
// the bigger basic variant would allocate for each.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
enum Candidate {
    Basic(Basic),
    Complex(Reverse),
}

/// A basic rule's (or a starting piece's) match.
#[derive(Debug, Clone, Copy)]
struct Basic {
    piece: Placement,
    b: Body,
    committed: Option<u32>,
    anchor: Anchor,
    anchor_box: Option<(Body, Option<u32>)>,
    rule: Option<RuleRef>,
}

/// How a part's search ended.
pub(crate) enum PartResult {
    /// The removals from first peeled to last: reverse for the build order.
    Built(Vec<Removal>),
    /// The search space was exhausted: these voxels cannot be built by R.
    Unbuildable,
    /// The node or time budget ran out.
    OutOfBudget,
}

pub(crate) struct PartSearch<'a> {
    rules: &'a RuleSet,
    opts: &'a SearchOptions,
    starts: Vec<(PartKind, Rot)>,
    footprints: Vec<(i32, i32)>,
    /// Every rule (up rules and pieces on the built part; down rules; all
    /// rules) grouped by the new piece's shape, with the index where each
    /// slot's shape group ends.
    wide_up: (Vec<Slot>, Vec<u32>),
    wide_down: (Vec<Slot>, Vec<u32>),
    wide_all: (Vec<Slot>, Vec<u32>),
    weights: Vec<f64>,
    /// Each complex rule's variants, as the slots that try them.
    complex: Vec<Vec<Slot>>,
    deadline: Instant,
}

impl<'a> PartSearch<'a> {
    pub fn new(rules: &'a RuleSet, opts: &'a SearchOptions, deadline: Instant) -> Self {
        let starts = super::start_shapes(rules);
        let weights = rules.variants().iter().map(|v| v.weight).collect();
        let footprints = super::footprints(rules);
        let mut by_shape: Vec<u32> = (0..rules.variants().len() as u32).collect();
        // Big new pieces first, then big anchors: fewer, bigger bricks.
        by_shape.sort_by_key(|&i| {
            let v = &rules.variants()[i as usize];
            let studs = |p: PartKind| std::cmp::Reverse(p.spec().studs());
            (studs(v.added), v.added, v.added_rot, studs(v.anchor), i)
        });
        let group = |keep: &dyn Fn(Dir) -> bool| {
            let slots: Vec<Slot> = by_shape
                .iter()
                .filter(|&&i| keep(rules.variants()[i as usize].dir))
                .map(|&i| Slot::Rule(i))
                .collect();
            let shape = |s: &Slot| match *s {
                Slot::Rule(i) => {
                    let v = &rules.variants()[i as usize];
                    (v.added, v.added_rot)
                }
                Slot::OnBuilt(p, r) => (p, r),
                Slot::Complex(i, j) => {
                    let n = &rules.complex_variants()[i as usize].v[j as usize];
                    (n.piece.part, n.piece.rot)
                }
            };
            let mut ends = vec![slots.len() as u32; slots.len()];
            for k in (0..slots.len().saturating_sub(1)).rev() {
                ends[k] = if shape(&slots[k]) == shape(&slots[k + 1]) {
                    ends[k + 1]
                } else {
                    k as u32 + 1
                };
            }
            (slots, ends)
        };
        let mut wide_up = group(&|d| d == Dir::Up);
        for &(p, r) in &starts {
            wide_up.0.push(Slot::OnBuilt(p, r));
            wide_up.1.push(wide_up.0.len() as u32);
        }
        let wide_down = group(&|d| d == Dir::Down);
        let wide_all = group(&|_| true);
        let mut complex: Vec<Vec<Slot>> = Vec::new();
        let mut last = None;
        for (i, var) in rules.complex_variants().iter().enumerate() {
            if last != Some(var.rule) {
                complex.push(Vec::new());
                last = Some(var.rule);
            }
            let slots = complex.last_mut().expect("a group");
            slots.extend((0..var.v.len()).map(|j| Slot::Complex(i as u32, j as u8)));
        }
        PartSearch {
            rules,
            opts,
            starts,
            footprints,
            wide_up,
            wide_down,
            wide_all,
            weights,
            complex,
            deadline,
        }
    }

    /// Samples `b` distinct variants, weighted (Efraimidis–Spirakis keys),
    /// in the order drawn; split by direction.
    fn sample(&self, b: usize, rng: &mut ChaCha8Rng) -> (Vec<Slot>, Vec<Slot>) {
        let mut keyed = super::grow::sample(&self.weights, b, rng);
        // The drawn rules are tried bigger new piece first (in the order
        // drawn among equals): fewer, bigger bricks.
        let studs = |i: u32| self.rules.variants()[i as usize].added.spec().studs();
        keyed.sort_by_key(|&i| std::cmp::Reverse(studs(i)));
        let mut up = Vec::new();
        let mut down = Vec::new();
        for i in keyed {
            match self.rules.variants()[i as usize].dir {
                Dir::Up => up.push(Slot::Rule(i)),
                Dir::Down => down.push(Slot::Rule(i)),
            }
        }
        (up, down)
    }

    fn branching(&self, left: usize, total: usize) -> usize {
        let done = 1.0 - left as f64 / total.max(1) as f64;
        let (lo, hi) = (self.opts.b_min as f64, self.opts.b_max as f64);
        (lo + (hi - lo) * done * done).round() as usize
    }

    /// A node's frame; the `nth` node of the part (from 1) scans for a
    /// complex rule, picked with equal probability, before its sampled
    /// rules if `nth` is a multiple of `complex_every`.
    #[allow(clippy::too_many_arguments)]
    fn frame(
        &self,
        st: &State,
        total: usize,
        rng: &mut Dice,
        applied: Option<Change>,
        start: usize,
        nth: u64,
        stats: &mut SearchStats,
    ) -> Frame {
        let b = self.branching(st.v.count(), total);
        let k = u64::from(self.opts.complex_every);
        let mut complex: Vec<Slot> = Vec::new();
        if k > 0 && !self.complex.is_empty() && nth % k == 0 {
            complex = self.complex[rng.complex.gen_range(0..self.complex.len())].clone();
            stats.complex_tried += 1;
        }
        let (mut up, mut down) = self.sample(b, &mut rng.rules);
        if st.has_built() {
            up.extend(self.starts.iter().map(|&(p, r)| Slot::OnBuilt(p, r)));
        } else {
            up.append(&mut down);
        }
        let phase = if complex.is_empty() {
            Phase::Up
        } else {
            Phase::Complex
        };
        Frame {
            applied,
            complex,
            up,
            down,
            phase,
            pos: 0,
            start,
            slot: 0,
            deferred: Vec::new(),
            widened: false,
        }
    }

    /// Runs the backward tracing on `v` given the structure built before
    /// and the whole `model`.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        v: VoxelGrid,
        built: &VoxelGrid,
        model: Model,
        max_nodes: u64,
        rng: &mut Dice,
        stats: &mut SearchStats,
    ) -> PartResult {
        let total = v.count();
        let orders = scan_orders(&v, !built.is_empty());
        let mut st = State::new(
            v,
            built,
            model,
            self.rules.layer_ldu(),
            self.footprints.clone(),
        );
        let mut stack: Vec<Frame> = vec![self.frame(&st, total, rng, None, 0, 1, stats)];
        let mut nodes_here = 0u64;
        // Matches looked at before the part is handed to forward growth: a
        // big rule set (slopes, unseen rules) can make widened nodes slow.
        let max_tries = stats.match_tries + MAX_TRIES_PER_VOXEL * total as u64 + 1_000_000;
        loop {
            if st.v.is_empty() {
                return PartResult::Built(self.trace(&stack));
            }
            if let Some(last) = self.start_rule(&st) {
                let mut t = self.trace(&stack);
                t.push(last);
                stats.starts += 1;
                return PartResult::Built(t);
            }
            if nodes_here >= max_nodes
                || stats.match_tries >= max_tries
                || Instant::now() >= self.deadline
            {
                return PartResult::OutOfBudget;
            }
            let top = stack.last_mut().expect("root frame");
            match self.next_candidate(&mut st, top, &orders, stats) {
                Some(c) => {
                    let change = self.apply(&mut st, &c);
                    if let Candidate::Complex(_) = c {
                        stats.complex_applied += 1;
                    }
                    nodes_here += 1;
                    stats.nodes += 1;
                    let scan_up = matches!(top.phase, Phase::Up | Phase::Complex);
                    let start = if scan_up && !orders.0.is_empty() {
                        (top.start + top.pos) % orders.0.len()
                    } else {
                        0
                    };
                    let f = self.frame(&st, total, rng, Some(change), start, nodes_here + 1, stats);
                    stack.push(f);
                    stats.max_depth = stats.max_depth.max(stack.len() as u64);
                }
                None => {
                    let f = stack.pop().expect("frame");
                    match f.applied {
                        Some(ch) => {
                            st.undo_change(&ch);
                            stats.backtracks += 1;
                        }
                        None => {
                            return PartResult::Unbuildable;
                        }
                    }
                }
            }
        }
    }

    fn trace(&self, stack: &[Frame]) -> Vec<Removal> {
        stack
            .iter()
            .filter_map(|f| f.applied.as_ref())
            .flat_map(|ch| ch.removals.iter().copied())
            .collect()
    }

    /// The starting rule `ε -> P`, reversed: the voxels left are one piece.
    fn start_rule(&self, st: &State) -> Option<Removal> {
        if st.has_built() {
            return None;
        }
        let bounds = st.v.bounds()?;
        for &(part, rot) in &self.starts {
            let p = Placement::new(part, bounds.min, rot);
            let b = p.body(st.layer_ldu);
            if b.bbox != bounds {
                continue;
            }
            if st.is_single_piece(&p) && st.commitment(&b, &p).is_some() && st.face_clear(&p, &b) {
                return Some(Removal::new_start(p));
            }
        }
        None
    }

    /// The next applicable match of the node, in scan order; `None` when the
    /// node is exhausted. The returned match has passed every check.
    fn next_candidate(
        &self,
        st: &mut State,
        f: &mut Frame,
        orders: &(Vec<Cell>, Vec<Cell>),
        stats: &mut SearchStats,
    ) -> Option<Candidate> {
        let built = st.has_built();
        loop {
            match f.phase {
                Phase::Done if f.widened => return None,
                Phase::Done => {
                    // The sampled rules found nothing: b reaches its maximum,
                    // every rule, grouped by the new piece's shape.
                    f.up.clear();
                    f.down.clear();
                    f.widened = true;
                    f.phase = Phase::Up;
                    f.pos = 0;
                    f.slot = 0;
                    stats.widened += 1;
                }
                Phase::Deferred => {
                    while let Some(c) = f.deferred.pop() {
                        if self.passes(st, &c, stats) {
                            return Some(c);
                        }
                    }
                    f.phase = if f.widened { Phase::Loose } else { Phase::Done };
                    f.pos = 0;
                    f.slot = 0;
                }
                Phase::Complex | Phase::Up | Phase::Down | Phase::Loose => {
                    let loose = f.phase == Phase::Loose;
                    let up = f.phase != Phase::Down;
                    let order = if up { &orders.0 } else { &orders.1 };
                    let (slots, ends): (&[Slot], &[u32]) = match (f.widened, up) {
                        _ if f.phase == Phase::Complex => (&f.complex, &[]),
                        (false, true) => (&f.up, &[]),
                        (false, false) => (&f.down, &[]),
                        (true, true) if built => (&self.wide_up.0, &self.wide_up.1),
                        (true, true) => (&self.wide_all.0, &self.wide_all.1),
                        (true, false) => (&self.wide_down.0, &self.wide_down.1),
                    };
                    let shift = if matches!(f.phase, Phase::Up | Phase::Complex) {
                        f.start
                    } else {
                        0
                    };
                    let at = |pos: usize| order[(shift + pos) % order.len()];
                    while f.pos < order.len() && !st.v.get(at(f.pos)) {
                        f.pos += 1;
                        f.slot = 0;
                    }
                    if f.pos >= order.len() {
                        if f.phase == Phase::Complex {
                            f.phase = Phase::Up;
                        } else if loose {
                            f.phase = Phase::Done;
                        } else if f.phase == Phase::Up && built {
                            f.phase = Phase::Down;
                        } else {
                            f.deferred.reverse();
                            f.phase = Phase::Deferred;
                        }
                        f.pos = 0;
                        f.slot = 0;
                        continue;
                    }
                    let cell = at(f.pos);
                    let mut fit: Option<(PartKind, Rot, Option<Option<u32>>)> = None;
                    while f.slot < slots.len() {
                        let slot = slots[f.slot];
                        f.slot += 1;
                        stats.match_tries += 1;
                        if stats.match_tries % 65_536 == 0 && Instant::now() >= self.deadline {
                            return None;
                        }
                        if let (Slot::Rule(i), Some((p, r, None))) = (slot, fit) {
                            // The new piece's shape does not fit here: skip
                            // the other rules adding the same shape.
                            let v = &self.rules.variants()[i as usize];
                            if (v.added, v.added_rot) == (p, r) {
                                if let Some(&end) = ends.get(f.slot - 1) {
                                    f.slot = end as usize;
                                }
                                continue;
                            }
                        }
                        if let Some(c) = self.match_at(st, slot, cell, &mut fit) {
                            if !built && !st.on_side_boundary(&c.bbox()) {
                                continue;
                            }
                            // With nothing built, the matched piece to continue
                            // from is a committed anchor: peel it next, so the
                            // peel follows the chain of staggered joints.
                            let connected = match &c {
                                _ if loose => true,
                                Candidate::Basic(c) if !built => {
                                    c.committed.is_some() || !st.has_committed()
                                }
                                Candidate::Basic(c) => {
                                    !st.any_matched
                                        || c.committed.is_some()
                                        || matches!(c.anchor_box, Some((_, Some(_))))
                                        || st.touches_matched(&c.b)
                                }
                                Candidate::Complex(m) if !built => {
                                    m.committed || !st.has_committed()
                                }
                                Candidate::Complex(m) => {
                                    !st.any_matched
                                        || m.committed
                                        || complex::touches_matched(st, self.rules, m)
                                }
                            };
                            if !connected {
                                if f.deferred.len() < 256 {
                                    f.deferred.push(c);
                                }
                                continue;
                            }
                            if self.passes(st, &c, stats) {
                                return Some(c);
                            }
                        }
                    }
                    f.pos += 1;
                    f.slot = 0;
                }
            }
        }
    }

    /// The piece `part` turned `rot` placed with its key cell (see
    /// [`Body::key`]) at `cell`, and its body.
    fn at_key(&self, part: PartKind, rot: Rot, cell: Cell) -> (Placement, Body) {
        let u = self.rules.layer_ldu();
        let k = part.body(rot, Cell::new(0, 0, 0), u).key();
        let p = Placement::new(part, cell.offset(-k.x, -k.y, -k.z), rot);
        (p, p.body(u))
    }

    /// The structural match of `slot` with its new piece's key cell at
    /// `cell`: pieces inside the voxels, consistent with matched pieces.
    fn match_at(
        &self,
        st: &State,
        slot: Slot,
        cell: Cell,
        fit: &mut Option<(PartKind, Rot, Option<Option<u32>>)>,
    ) -> Option<Candidate> {
        match slot {
            Slot::Complex(i, j) => {
                complex::match_at(st, self.rules, i, j as usize, cell).map(Candidate::Complex)
            }
            Slot::Rule(i) => {
                let v = &self.rules.variants()[i as usize];
                let (piece, b) = self.at_key(v.added, v.added_rot, cell);
                let committed = match *fit {
                    Some((p, r, c)) if (p, r) == (v.added, v.added_rot) => c,
                    _ => {
                        let c = if st.v.all_set_body(&b) && st.face_clear(&piece, &b) {
                            st.commitment(&b, &piece)
                        } else {
                            None
                        };
                        *fit = Some((v.added, v.added_rot, c));
                        c
                    }
                }?;
                let (dx, dy, dz) = v.offset;
                let a_at = piece.origin.offset(-dx, -dy, -dz);
                let anchor = Placement::new(v.anchor, a_at, v.anchor_rot);
                let a = anchor.body(st.layer_ldu);
                if !st.v.all_set_body(&a) || !st.face_clear(&anchor, &a) {
                    return None;
                }
                let a_committed = st.commitment(&a, &anchor)?;
                Some(Candidate::Basic(Basic {
                    piece,
                    b,
                    committed,
                    anchor: Anchor::Piece(anchor),
                    anchor_box: Some((a, a_committed)),
                    rule: Some(RuleRef::Basic(v.rule)),
                }))
            }
            Slot::OnBuilt(part, rot) => {
                let (piece, b) = self.at_key(part, rot, cell);
                if !st.v.all_set_body(&b) || !st.touches_built(&b) || !st.face_clear(&piece, &b) {
                    return None;
                }
                let committed = st.commitment(&b, &piece)?;
                Some(Candidate::Basic(Basic {
                    piece,
                    b,
                    committed,
                    anchor: Anchor::Built,
                    anchor_box: None,
                    rule: None,
                }))
            }
        }
    }

    /// The checks that need the removal applied: placeability and
    /// connectivity. Leaves the state unchanged.
    fn passes(&self, st: &mut State, c: &Candidate, stats: &mut SearchStats) -> bool {
        let c = match c {
            Candidate::Basic(c) => c,
            Candidate::Complex(m) => return self.passes_complex(st, m, stats),
        };
        let r = apply(st, c);
        let new_anchor = match c.anchor_box {
            Some((ab, None)) => Some(ab),
            _ => None,
        };
        let anchor_bbox = new_anchor.map(|a| a.bbox);
        let ok_place = st.placeable(&c.b);
        let ok_conn = ok_place && st.still_connected(&c.b.bbox, anchor_bbox.as_ref());
        let ok = ok_conn && st.still_reachable(&c.b.bbox, anchor_bbox.as_ref());
        if !ok_place {
            stats.rejected_placeable += 1;
        } else if !ok_conn {
            stats.rejected_connect += 1;
        } else if !ok {
            stats.rejected_reach += 1;
        }
        st.undo(&r);
        ok
    }
}

impl PartSearch<'_> {
    /// [`PartSearch::passes`] for a complex rule: each new piece placeable
    /// once peeled, the voxels left still connected and coverable.
    fn passes_complex(&self, st: &mut State, m: &Reverse, stats: &mut SearchStats) -> bool {
        let Some(ch) = complex::apply(st, self.rules, m, true) else {
            stats.rejected_placeable += 1;
            return false;
        };
        let ok_conn = st.still_connected(&m.bbox, Some(&m.u_bbox));
        let ok = ok_conn && st.still_reachable(&m.bbox, Some(&m.u_bbox));
        if !ok_conn {
            stats.rejected_connect += 1;
        } else if !ok {
            stats.rejected_reach += 1;
        }
        st.undo_change(&ch);
        ok
    }

    /// Applies a candidate's reverse rule application to the state.
    fn apply(&self, st: &mut State, c: &Candidate) -> Change {
        match c {
            Candidate::Basic(c) => Change {
                removals: vec![apply(st, c)],
                commits: Vec::new(),
            },
            Candidate::Complex(m) => {
                complex::apply(st, self.rules, m, false).expect("a match that passed its checks")
            }
        }
    }
}

impl Candidate {
    /// The box the new pieces take.
    fn bbox(&self) -> CellBox {
        match self {
            Candidate::Basic(c) => c.b.bbox,
            Candidate::Complex(m) => m.bbox,
        }
    }
}

/// The cell orders the scans follow. With a structure built below, up rules
/// scan from the top layer down and down rules from the bottom up, each layer
/// in raster order. With nothing built (the bottom part), the scan goes
/// from the outside in over all layers together, top first, so the pieces
/// peeled last, the first ones built, sit in the middle.
fn scan_orders(v: &VoxelGrid, built: bool) -> (Vec<Cell>, Vec<Cell>) {
    let cells: Vec<Cell> = v.cells().collect();
    let Some(b) = v.bounds() else {
        return (Vec::new(), Vec::new());
    };
    // Twice the centre, to stay in integers.
    let (cx, cy) = (2 * b.min.x + b.sx - 1, 2 * b.min.y + b.sy - 1);
    let dist = |c: &Cell| {
        let (dx, dy) = (2 * c.x - cx, 2 * c.y - cy);
        dx * dx + dy * dy
    };
    let mut down = cells.clone();
    let mut up = cells;
    if built {
        // Raster order within a layer: the new piece's minimum corner sits
        // on the scanned cell, so the first free cell in raster order leaves
        // room for the biggest pieces.
        up.sort_by_key(|c| (std::cmp::Reverse(c.z), c.y, c.x));
        down.sort_by_key(|c| (c.z, c.y, c.x));
    } else {
        up.sort_by_key(|c| (std::cmp::Reverse(dist(c)), std::cmp::Reverse(c.z), c.y, c.x));
        down.clear();
    }
    (up, down)
}

/// Applies a basic match's reverse rule application to the state.
fn apply(st: &mut State, c: &Basic) -> Removal {
    st.apply(
        c.piece,
        &c.b,
        c.committed,
        c.anchor,
        c.anchor_box.as_ref().map(|(b, id)| (b, *id)),
        c.rule,
    )
}
