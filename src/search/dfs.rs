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
//! exactly one piece, or a piece rests on the structure built before.

use std::time::Instant;

use rand_chacha::ChaCha8Rng;

use super::state::{Anchor, Model, Removal, State};
use super::{SearchOptions, SearchStats};
use crate::assembly::Placement;
use crate::catalog::PartKind;
use crate::geom::{Body, Cell, Rot};
use crate::grammar::{Dir, RuleSet};
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
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Scanning top-down for up rules and pieces on the built structure
    /// (with nothing built: up and down rules together, outside in).
    Up,
    /// Scanning bottom-up for down rules.
    Down,
    /// Matches that do not touch the matched pieces, held back.
    Deferred,
    Done,
}

struct Frame {
    /// The change that led here from the parent (None at the root).
    applied: Option<Removal>,
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

#[derive(Debug, Clone, Copy)]
struct Candidate {
    piece: Placement,
    b: Body,
    committed: Option<u32>,
    anchor: Anchor,
    anchor_box: Option<(Body, Option<u32>)>,
    rule: Option<crate::grammar::RuleId>,
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
        PartSearch {
            rules,
            opts,
            starts,
            footprints,
            wide_up,
            wide_down,
            wide_all,
            weights,
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

    fn frame(
        &self,
        st: &State,
        total: usize,
        rng: &mut ChaCha8Rng,
        applied: Option<Removal>,
        start: usize,
    ) -> Frame {
        let b = self.branching(st.v.count(), total);
        let (mut up, mut down) = self.sample(b, rng);
        if st.has_built() {
            up.extend(self.starts.iter().map(|&(p, r)| Slot::OnBuilt(p, r)));
        } else {
            up.append(&mut down);
        }
        Frame {
            applied,
            up,
            down,
            phase: Phase::Up,
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
        rng: &mut ChaCha8Rng,
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
        let mut stack: Vec<Frame> = vec![self.frame(&st, total, rng, None, 0)];
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
                    let removal = apply(&mut st, &c);
                    nodes_here += 1;
                    stats.nodes += 1;
                    let start = if top.phase == Phase::Up && !orders.0.is_empty() {
                        (top.start + top.pos) % orders.0.len()
                    } else {
                        0
                    };
                    let f = self.frame(&st, total, rng, Some(removal), start);
                    stack.push(f);
                    stats.max_depth = stats.max_depth.max(stack.len() as u64);
                }
                None => {
                    let f = stack.pop().expect("frame");
                    match f.applied {
                        Some(r) => {
                            st.undo(&r);
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
        stack.iter().filter_map(|f| f.applied).collect()
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
                    f.phase = Phase::Done;
                }
                Phase::Up | Phase::Down => {
                    let order = if f.phase == Phase::Up {
                        &orders.0
                    } else {
                        &orders.1
                    };
                    let (slots, ends): (&[Slot], &[u32]) = match (f.widened, f.phase == Phase::Up) {
                        (false, true) => (&f.up, &[]),
                        (false, false) => (&f.down, &[]),
                        (true, true) if built => (&self.wide_up.0, &self.wide_up.1),
                        (true, true) => (&self.wide_all.0, &self.wide_all.1),
                        (true, false) => (&self.wide_down.0, &self.wide_down.1),
                    };
                    let shift = if f.phase == Phase::Up { f.start } else { 0 };
                    let at = |pos: usize| order[(shift + pos) % order.len()];
                    while f.pos < order.len() && !st.v.get(at(f.pos)) {
                        f.pos += 1;
                        f.slot = 0;
                    }
                    if f.pos >= order.len() {
                        if f.phase == Phase::Up && built {
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
                            if !built && !st.on_side_boundary(&c.b.bbox) {
                                continue;
                            }
                            // With nothing built, the matched piece to continue
                            // from is a committed anchor: peel it next, so the
                            // peel follows the chain of staggered joints.
                            let connected = if !built {
                                c.committed.is_some() || !st.has_committed()
                            } else {
                                !st.any_matched
                                    || c.committed.is_some()
                                    || matches!(c.anchor_box, Some((_, Some(_))))
                                    || st.touches_matched(&c.b)
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
                Some(Candidate {
                    piece,
                    b,
                    committed,
                    anchor: Anchor::Piece(anchor),
                    anchor_box: Some((a, a_committed)),
                    rule: Some(v.rule),
                })
            }
            Slot::OnBuilt(part, rot) => {
                let (piece, b) = self.at_key(part, rot, cell);
                if !st.v.all_set_body(&b) || !st.touches_built(&b) || !st.face_clear(&piece, &b) {
                    return None;
                }
                let committed = st.commitment(&b, &piece)?;
                Some(Candidate {
                    piece,
                    b,
                    committed,
                    anchor: Anchor::Built,
                    anchor_box: None,
                    rule: None,
                })
            }
        }
    }

    /// The checks that need the removal applied: placeability and
    /// connectivity. Leaves the state unchanged.
    fn passes(&self, st: &mut State, c: &Candidate, stats: &mut SearchStats) -> bool {
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

/// Applies a candidate's reverse rule application to the state.
fn apply(st: &mut State, c: &Candidate) -> Removal {
    st.apply(
        c.piece,
        &c.b,
        c.committed,
        c.anchor,
        c.anchor_box.as_ref().map(|(b, id)| (b, *id)),
        c.rule,
    )
}
