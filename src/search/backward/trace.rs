//! The backward trace of one part: a depth-first tree of voxel grids.
//!
//! The root holds the part's voxels. A node's children are rules applied
//! in reverse: a match of a rule's `v` (the anchor `A` and the new piece
//! `B`, or a complex rule's pieces) in the voxels left, replaced by its `u`:
//! `B`'s cells are taken away and `A` stays, now *matched* (pending): a
//! piece of the answer whose cells are still there, to be taken away by a
//! later match. Each node stores only its local change ([`Change`]); going
//! back up the tree undoes it. The trace succeeds when one piece is left
//! and a starting rule can put it down (for a part above the first, when a
//! rule joins it to the parts below): read backwards, the matches are the
//! derivation.
//!
//! At each node, `b` rules are drawn from their weights' categorical
//! distribution (without replacement, among rules whose new piece fits
//! somewhere it may go) and tried in the order drawn; `b` grows from
//! `b_min` to `b_max` as fewer voxels are left. Once every `complex_every`
//! nodes, a complex rule picked with equal probability is tried first. A
//! rule labelled `up` is matched scanning from the top of the grid down, a
//! `down` rule from the bottom up, and each match the scan finds is
//! a child, the first match first. A match must join the pieces matched so
//! far (its new piece or its anchor is a matched piece, or stud-connects
//! to one), except the first,
//! and its new piece must be able to reach its place past what is built
//! before it ([`super::fit`]). A node whose voxels fall apart, or that was
//! met before and failed with every rule tried, is cut off, and so is a
//! node this pass has searched already, reached again by taking the same
//! pieces in another order (it stays open to the next pass); a node with
//! no child left is backtracked from.

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::hash::{Hash, Hasher};
use std::time::Instant;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::fit::placeable;
use crate::assembly::Placement;
use crate::catalog::PartKind;
use crate::geom::{Body, Cell, Rot};
use crate::grammar::{Dir, Link, RuleRef, RuleSet};
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
    pub deadline: Instant,
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
    /// The node budget ran out.
    Nodes,
    /// The time budget ran out.
    Time,
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
    next: usize,
    /// Where the scan of the rule being tried goes on: each match of a
    /// rule, in scan order, is a child.
    cursor: usize,
    /// (B, A) pairs already tried here.
    tried: HashSet<(Placement, Placement)>,
    /// Where each shape of new piece may be taken away at this node.
    spots: HashMap<(PartKind, Rot), Vec<Placement>>,
    /// The change that made this node from its parent.
    change: Option<Change>,
    /// Whether every rule that could match is among `tries` (`b` was no
    /// smaller than their number).
    complete: bool,
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
    pending: Vec<Placement>,
    /// Pieces taken away, in backward order, with the rule and anchor.
    taken: Vec<Placement>,
    /// The pieces of the parts below, built before this part.
    below_pieces: &'a [Placement],
    /// Whether this is the first part (its last piece needs a starting
    /// rule; the others' a rule joining it to the parts below).
    first: bool,
    /// What is built when a piece of this part goes in: what is left of
    /// it, and the parts below (a scratch copy the flood fill empties a
    /// piece's cells in, and fills again).
    built: RefCell<VoxelGrid>,
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
}

fn piece_hash(p: &Placement, salt: u64) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (p, salt).hash(&mut h);
    h.finish()
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
        Trace {
            rules,
            book,
            layer: rules.layer_ldu(),
            tuning,
            left: cells,
            left_count: n,
            total: n,
            held: VoxelGrid::new(nx, ny, nz),
            pending: Vec::new(),
            taken: Vec::new(),
            below_pieces,
            first,
            built: RefCell::new(built),
            shapes: coverers(rules),
            widen: 1,
            hash: 0,
            failed: HashSet::new(),
            last_pass_whole: false,
            were_log: Vec::new(),
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
    pub fn run(
        &mut self,
        rng: &mut ChaCha8Rng,
        count: &mut Counters,
    ) -> Result<Vec<Removal>, Stop> {
        if let Some(r) = self.single_piece() {
            return Ok(vec![r]);
        }
        let all = self.rules.variants().len() as u32;
        loop {
            if let Some(d) = self.pass(rng, count)? {
                return Ok(d);
            }
            if self.last_pass_whole || self.tuning.b_min.max(1) * self.widen > all {
                return Err(Stop::Exhausted);
            }
            self.widen *= 2;
        }
    }

    /// One pass of the depth-first tree: a derivation, or `None` when the
    /// root has no child left (`last_pass_whole` says whether for good).
    fn pass(
        &mut self,
        rng: &mut ChaCha8Rng,
        count: &mut Counters,
    ) -> Result<Option<Vec<Removal>>, Stop> {
        let mut log: Vec<Change> = Vec::new();
        // The nodes whose subtrees this pass searched to the end, by state.
        let mut exhausted: HashSet<u64> = HashSet::new();
        let root = self.frame(rng, count, None);
        let mut stack = vec![root];
        loop {
            if let Some(last) = self.finished() {
                return Ok(Some(self.derivation(&log, last)));
            }
            if count.nodes >= self.tuning.node_budget {
                return Err(Stop::Nodes);
            }
            if count.nodes.is_multiple_of(64) && Instant::now() >= self.tuning.deadline {
                return Err(Stop::Time);
            }
            let Some(top) = stack.last_mut() else {
                return Ok(None);
            };
            let mut child = None;
            while top.next < top.tries.len() && child.is_none() {
                let t = top.tries[top.next];
                let found = match t {
                    Ok(v) => self.match_basic(v, top, top.cursor),
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

    /// A node's rules to try: `b` basic rule variants drawn from the
    /// weights, a complex one first every `complex_every` nodes.
    fn frame(&self, rng: &mut ChaCha8Rng, count: &Counters, change: Option<Change>) -> Frame {
        let t = &self.tuning;
        let done = 1.0 - self.left_count as f64 / self.total.max(1) as f64;
        let b = t.b_min as f64 + (t.b_max.saturating_sub(t.b_min)) as f64 * done;
        let b = (b.round() as usize).saturating_mul(self.widen as usize);
        // Only rules whose new piece fits somewhere it may go can match.
        let mut shapes: Vec<(PartKind, Rot)> = self
            .rules
            .variants()
            .iter()
            .flat_map(|v| [(v.added, v.added_rot), (v.anchor, v.anchor_rot)])
            .chain(
                self.rules
                    .complex_variants()
                    .iter()
                    .filter_map(|c| c.v.first().map(|n| (n.piece.part, n.piece.rot))),
            )
            .collect();
        shapes.sort();
        shapes.dedup();
        let spots: HashMap<(PartKind, Rot), Vec<Placement>> = shapes
            .into_iter()
            .map(|(p, r)| ((p, r), self.spots(p, r)))
            .filter(|(_, s)| !s.is_empty())
            .collect();
        let fits = |v: &crate::grammar::Variant| {
            spots.contains_key(&(v.added, v.added_rot))
                || spots.contains_key(&(v.anchor, v.anchor_rot))
        };
        // Weighted sampling without replacement: the largest u^(1/w).
        let mut keyed: Vec<(f64, u32)> = self
            .rules
            .variants()
            .iter()
            .enumerate()
            .filter(|(_, v)| v.weight > 0.0 && fits(v))
            .map(|(i, v)| {
                let u: f64 = rng.gen_range(f64::MIN_POSITIVE..1.0);
                (u.ln() / v.weight, i as u32)
            })
            .collect();
        keyed.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let complete = keyed.len() <= b.max(1);
        keyed.truncate(b.max(1));
        let mut tries: Vec<Result<u32, u32>> = keyed.into_iter().map(|(_, i)| Ok(i)).collect();
        let nc = self.rules.complex_variants().len();
        if t.complex_every > 0 && nc > 0 && count.nodes.is_multiple_of(u64::from(t.complex_every)) {
            let pick = rng.gen_range(0..nc) as u32;
            tries.insert(0, Err(pick));
        }
        Frame {
            tries,
            next: 0,
            cursor: 0,
            tried: HashSet::new(),
            spots,
            change,
            complete,
            whole: true,
        }
    }

    fn body(&self, p: &Placement) -> Body {
        p.body(self.layer)
    }

    /// Whether every cell of `b` is left and not held by a pending piece.
    fn free(&self, b: &Body) -> bool {
        b.cells()
            .all(|c| self.left.in_bounds(c) && self.left.get(c) && !self.held.get(c))
    }

    fn is_pending(&self, p: &Placement) -> bool {
        self.pending.contains(p)
    }

    /// Where a piece of `part` turned `rot` may be taken away: the pending
    /// pieces of that shape, and free places stud-connected to a matched
    /// piece (anywhere free for the first match). Sorted bottom to top.
    fn spots(&self, part: PartKind, rot: Rot) -> Vec<Placement> {
        let mut out: Vec<Placement> = self
            .pending
            .iter()
            .filter(|p| p.part == part && p.rot == rot)
            .copied()
            .collect();
        let probe = Placement::new(part, Cell::new(0, 0, 0), rot);
        let shape = self.body(&probe).bbox;
        if self.pending.is_empty() && self.taken.is_empty() {
            let (nx, ny, nz) = self.left.dims();
            for z in 0..nz {
                for y in 0..ny {
                    for x in 0..nx {
                        let p = Placement::new(part, Cell::new(x, y, z), rot);
                        if self.free(&self.body(&p)) {
                            out.push(p);
                        }
                    }
                }
            }
        } else {
            let mut seen: HashSet<Cell> = HashSet::new();
            for m in self.pending.iter().chain(&self.taken) {
                let mb = self.body(m);
                let bb = mb.bbox;
                for z in [bb.min.z + bb.sz, bb.min.z - shape.sz] {
                    for y in bb.min.y - shape.sy + 1..bb.min.y + bb.sy {
                        for x in bb.min.x - shape.sx + 1..bb.min.x + bb.sx {
                            let at = Cell::new(x, y, z);
                            if !seen.insert(at) {
                                continue;
                            }
                            let p = Placement::new(part, at, rot);
                            let b = self.body(&p);
                            if self.free(&b) && (mb.holds(&b) || b.holds(&mb)) {
                                out.push(p);
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
        let mut solid = self.built.borrow_mut();
        solid.set_body(b, false);
        for g in also_gone {
            solid.set_body(g, false);
        }
        let ok = placeable(&b.bbox, &solid, from_above);
        solid.set_body(b, true);
        for g in also_gone {
            solid.set_body(g, true);
        }
        ok
    }

    /// The first match of basic variant `v` in its scan direction.
    fn match_basic(&self, v: u32, node: &Frame, from: usize) -> Option<(Change, usize)> {
        let var = self.rules.variants()[v as usize];
        let (ox, oy, oz) = var.offset;
        // The new piece where it joins what is matched, or where its
        // anchor does.
        let mut spots: Vec<Placement> = node
            .spots
            .get(&(var.added, var.added_rot))
            .into_iter()
            .flatten()
            .copied()
            .chain(
                node.spots
                    .get(&(var.anchor, var.anchor_rot))
                    .into_iter()
                    .flatten()
                    .map(|a| Placement::new(var.added, a.origin.offset(ox, oy, oz), var.added_rot)),
            )
            .collect();
        spots.sort_by_key(|p| (p.origin.z, p.origin.y, p.origin.x));
        spots.dedup();
        let tried = &node.tried;
        let n = spots.len();
        for k in from..n {
            let b = match var.dir {
                Dir::Up => &spots[n - 1 - k],
                Dir::Down => &spots[k],
            };
            let at = b.origin.offset(-ox, -oy, -oz);
            let a = Placement::new(var.anchor, at, var.anchor_rot);
            if tried.contains(&(*b, a)) {
                continue;
            }
            let bb = self.body(b);
            let ab = self.body(&a);
            let a_pending = self.is_pending(&a);
            if !a_pending && !self.free(&ab) {
                continue;
            }
            if !self.is_pending(b) && !self.free(&bb) {
                continue;
            }
            // The rule's joint, as the grid has it.
            let joined = match var.dir {
                Dir::Up => ab.holds(&bb),
                Dir::Down => bb.holds(&ab),
            };
            if !joined || !self.can_place(&bb, &[], var.dir == Dir::Up) {
                continue;
            }
            let c = Change {
                rule: RuleRef::Basic(var.rule),
                taken: vec![(*b, a)],
                new_pending: if a_pending { vec![] } else { vec![a] },
            };
            return Some((c, k));
        }
        None
    }

    /// The first match of complex variant `v`: its new pieces free or
    /// pending, its `u` pieces pending or free, joined to what is matched.
    fn match_complex(&self, v: u32, node: &Frame, from: usize) -> Option<(Change, usize)> {
        let var = &self.rules.complex_variants()[v as usize];
        let first = var.v.first()?;
        let spots = node.spots.get(&(first.piece.part, first.piece.rot))?;
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
                        || self.pending.iter().chain(&self.taken).any(|m| {
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
        let c_taken = c.taken.clone();
        let mut were = Vec::with_capacity(c_taken.len());
        for a in &c.new_pending {
            let b = self.body(a);
            self.held.set_body(&b, true);
            self.pending.push(*a);
            self.hash ^= piece_hash(a, 1);
        }
        for (p, _) in &c_taken {
            let b = self.body(p);
            let was = self.is_pending(p);
            if was {
                self.pending.retain(|q| q != p);
                self.held.set_body(&b, false);
                self.hash ^= piece_hash(p, 1);
            }
            were.push(was);
            self.left.set_body(&b, false);
            self.built.get_mut().set_body(&b, false);
            self.left_count -= b.volume() as usize;
            self.taken.push(*p);
            self.hash ^= piece_hash(p, 2);
        }
        // Remember which were pending, for the undo.
        self.were_log.push(were);
    }

    fn undo(&mut self, c: &Change) {
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
                self.held.set_body(&b, true);
                self.hash ^= piece_hash(p, 1);
            }
        }
        for a in c.new_pending.iter().rev() {
            let b = self.body(a);
            self.held.set_body(&b, false);
            self.pending.retain(|q| q != a);
            self.hash ^= piece_hash(a, 1);
        }
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
        let owner = |c: Cell| -> Option<usize> {
            if !self.held.get(c) {
                return None;
            }
            self.pending.iter().position(|p| self.body(p).contains(c))
        };
        let (nx, ny, nz) = self.left.dims();
        let mut seen = VoxelGrid::new(nx, ny, nz);
        let mut stack = vec![start];
        seen.set(start, true);
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
    /// some piece of the alphabet whose cells are all free: the piece that
    /// will be taken away with it. A cell no piece can cover is a dead end.
    fn coverable(&self) -> bool {
        if self.shapes.iter().any(|s| s.volume() == 1) {
            return true;
        }
        self.left.cells().filter(|&c| !self.held.get(c)).all(|c| {
            self.shapes.iter().any(|s| {
                let k = s.cells().collect::<Vec<_>>();
                k.iter().any(|q| {
                    let b = s.moved(c.x - q.x, c.y - q.y, c.z - q.z);
                    self.free(&b)
                })
            })
        })
    }

    /// The last piece, if the trace is done: one pending piece is all that
    /// is left, and a starting rule puts it down (or, above the first
    /// part, a rule joins it to a piece below).
    fn finished(&self) -> Option<Removal> {
        if self.pending.len() != 1 {
            return None;
        }
        let p = self.pending[0];
        if self.body(&p).volume() as usize != self.left_count {
            return None;
        }
        self.closing(p)
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
    fn derivation(&self, log: &[Change], last: Removal) -> Vec<Removal> {
        let mut out = vec![last];
        for c in log.iter().rev() {
            for &(p, a) in &c.taken {
                out.push(Removal::forward(p, Anchor::Piece(a), Some(c.rule)));
            }
        }
        out
    }
}

/// The bodies of the alphabet's pieces at the origin, every distinct turn.
fn coverers(rules: &RuleSet) -> Vec<Body> {
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
