//! The build order found by taking the model apart.
//!
//! [`derive`](super::derive) orders the laid pieces as a derivation, lowest
//! course first. That order can hand a piece a turn at which the pieces
//! before it shut it in: a piece wedged under a piece that went in first,
//! or one inside a cavity that earlier pieces closed. A person checks the
//! order the other way round, as the paper's backward tracing does: from
//! the finished model, a piece can be the last one put in only if it can be
//! lifted out of what is left, and what is left still holds it by a rule.
//!
//! So the order is found backward. The finished model is taken apart one
//! piece at a time (a complex rule's new pieces together), the latest in
//! the derivation's order first, as long as the piece
//!
//! - touches the space around the build through free cells (never through
//!   the table under the lowest layer),
//! - travels out of the bounding box of the pieces left, by the moves a
//!   person makes (straight up or down, sideways one stud at a time with
//!   its studs clear),
//! - is joined by a rule of the file to a piece left (or stands on the
//!   ground where a starting rule puts it), and
//! - leaves every piece it joins still held, through the pieces left, by a
//!   chain of rules down to the ground.
//!
//! A piece that cannot go yet waits, and is tried again as pieces around it
//! go; it then comes earlier in the build. These are the rules the
//! verifier (`crate::assembly::verify`) checks forward, computed here on a
//! grid, with the free space only growing as pieces go. If nothing left can
//! go, the latest piece is taken out anyway and named, for the search to
//! repair (a pillar under it) and order again.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::layout::Layout;
use super::{Anchor, Removal};
use crate::assembly::verify::{escape, Escape};
use crate::geom::{Cell, CellBox, FACES};
use crate::grammar::{Dir, RuleRef};

/// Positions a piece's escape search visits at most before the piece is
/// taken to be stuck for now (it waits, and is tried again later).
const ESCAPE_LIMIT: usize = 2_048;

/// Pieces visited at most when checking that a piece is still held by a
/// chain of rules down to the ground; past it, the piece is taken as held.
const HOLD_LIMIT: usize = 4_096;

/// Reorders `order` (a derivation of the pieces of `l`) so that every piece
/// can be put in place at its turn (those that still cannot were taken out
/// by force: the verifier names them).
pub(crate) fn sequence(l: &Layout, order: Vec<Removal>) -> Vec<Removal> {
    let n = order.len();
    if n < 2 {
        return order;
    }
    let u = l.layer_ldu;
    let boxes: Vec<CellBox> = order.iter().map(|r| r.piece.body(u).bbox).collect();
    let Some(ids) = order
        .iter()
        .map(|r| l.owner_of(r.piece.body(u).key()))
        .collect::<Option<Vec<u32>>>()
    else {
        return order;
    };
    let mut pos_of = vec![u32::MAX; l.pieces.len()];
    for (k, &id) in ids.iter().enumerate() {
        pos_of[id as usize] = k as u32;
    }
    // For each piece, the pieces a rule can add it to: (position, weight,
    // rule).
    let mut holds: Vec<Vec<(u32, f64, RuleRef)>> = vec![Vec::new(); n];
    let mut held: Vec<Vec<u32>> = vec![Vec::new(); n];
    for k in 0..n {
        let body = l.pieces[ids[k] as usize].body;
        for o in l.below(&body) {
            let j = pos_of[o as usize];
            if j == u32::MAX {
                continue;
            }
            let (lower, upper) = (&order[j as usize].piece, &order[k].piece);
            if let Some((w, r)) = l.book.joint(lower, upper, Dir::Up, u) {
                holds[k].push((j, w, RuleRef::Basic(r)));
                held[j as usize].push(k as u32);
            }
            if let Some((w, r)) = l.book.joint(upper, lower, Dir::Down, u) {
                holds[j as usize].push((k as u32, w, RuleRef::Basic(r)));
                held[k].push(j);
            }
        }
    }
    let ground = boxes.iter().map(|b| b.min.z).min().unwrap_or(0);
    let starts: Vec<bool> = (0..n)
        .map(|k| boxes[k].min.z == ground && l.rules.can_start(order[k].piece.part))
        .collect();
    // Units: a basic piece alone, a complex rule's new pieces together.
    let mut units: Vec<Vec<usize>> = Vec::new();
    for k in 0..n {
        let joined = matches!(order[k].rule, Some(RuleRef::Complex(_)))
            && k > 0
            && matches!(order[k - 1].rule, Some(RuleRef::Complex(_)))
            && l.pieces[ids[k] as usize].group.is_some()
            && l.pieces[ids[k] as usize].group == l.pieces[ids[k - 1] as usize].group;
        match units.last_mut() {
            Some(last) if joined => last.push(k),
            _ => units.push(vec![k]),
        }
    }

    let mut unit_len = vec![1; n];
    for unit in &units {
        for &k in unit {
            unit_len[k] = unit.len();
        }
    }
    // A complex rule's piece is added to the piece its rule names.
    let complex_anchor: Vec<Option<u32>> = (0..n)
        .map(|k| match order[k].anchor {
            Anchor::Piece(a) if unit_len[k] > 1 => l
                .owner_of(a.body(u).key())
                .map(|o| pos_of[o as usize])
                .filter(|&j| j != u32::MAX),
            _ => None,
        })
        .collect();
    let graph = Graph {
        holds: &holds,
        held: &held,
        starts: &starts,
        boxes: &boxes,
        complex_anchor: &complex_anchor,
        z: &boxes.iter().map(|b| b.min.z).collect::<Vec<i32>>(),
    };
    let mut state = State {
        present: vec![true; n],
        space: Space::new(&boxes),
        hold: Hold::new(n),
        anchors: vec![None; n],
        opened_cavity: false,
    };
    let mut taken_out: Vec<usize> = Vec::with_capacity(units.len());
    // Units not yet tried (latest last), and units waiting, latest first.
    let mut fresh: Vec<usize> = (0..units.len()).collect();

    let mut waiting: Vec<usize> = Vec::new();
    // Per waiting unit: whether what it waits for may have changed since
    // it last tried, and what that is.
    let mut dirty: Vec<bool> = vec![false; units.len()];
    let mut watch: Vec<Watch> = vec![Watch::Never; units.len()];
    let near: Vec<CellBox> = units.iter().map(|u| around(u, &boxes)).collect();
    let mut bounds = state.space.bounds();
    loop {
        // The latest waiting unit whose watch fired and that can go now.
        let mut went = None;
        for (i, &w) in waiting.iter().enumerate() {
            if std::mem::take(&mut dirty[w]) {
                match state.take_out(&units[w], &graph) {
                    Ok(()) => {
                        went = Some(i);
                        break;
                    }
                    Err(why) => watch[w] = why,
                }
            }
        }
        let unit = if let Some(i) = went {
            waiting.remove(i)
        } else if let Some(f) = fresh.pop() {
            if let Err(why) = state.take_out(&units[f], &graph) {
                // `waiting` stays latest first: `f` is earlier than all.
                watch[f] = why;
                waiting.push(f);
                continue;
            }
            f
        } else if waiting.is_empty() {
            break;
        } else {
            // Nothing left can go (every watch is exact: a unit whose
            // watch did not fire would fail again): the latest waiting
            // unit goes by force.
            let w = waiting.remove(0);
            for &k in units[w].iter().rev() {
                state.present[k] = false;
                let opened = state.space.remove(&boxes[k]);
                state.opened_cavity |= opened.len() > boxes[k].cells().count();
                state.anchors[k] = best_anchor(&holds[k], &state.present);
            }
            w
        };
        taken_out.push(unit);
        let cavity = std::mem::take(&mut state.opened_cavity);
        let now = state.space.bounds();
        let shrunk = now != bounds;
        bounds = now;
        for &w in &waiting {
            dirty[w] |= match watch[w] {
                Watch::Never => false,
                Watch::Piece(q) => units[unit].contains(&(q as usize)),
                Watch::Cavity => cavity || units[unit].iter().any(|&k| meets(&near[w], &boxes[k])),
                Watch::Region(r) => shrunk || units[unit].iter().any(|&k| meets(&r, &boxes[k])),
            };
        }
    }
    let anchors = state.anchors;

    // Forward: the units in the reverse of the order they were taken out.
    let mut out: Vec<Removal> = Vec::with_capacity(n);
    for &w in taken_out.iter().rev() {
        for &k in &units[w] {
            let mut r = order[k];
            if units[w].len() == 1 {
                match anchors[k] {
                    Some((j, rule)) => {
                        r.anchor = Anchor::Piece(order[j as usize].piece);
                        r.rule = Some(rule);
                    }
                    None if starts[k] => {
                        r.anchor = Anchor::Start;
                        r.rule = None;
                    }
                    None => {}
                }
            }
            out.push(r);
        }
    }
    out
}

/// Why a unit could not go yet: what must change before it can. Each is
/// exact (pieces only go): a unit is tried again only when what it
/// watches changed, and one whose watch did not fire would fail again.
#[derive(Debug, Clone, Copy)]
enum Watch {
    /// No rule joins it to a piece left, and none ever will (a piece's
    /// anchors only go).
    Never,
    /// Taking it out leaves this piece without a chain of rules to the
    /// ground, and so will taking it out later (chains only break): the
    /// piece must go first.
    Piece(u32),
    /// Its cells are shut off from the outside: free space beside it must
    /// join the outside (a piece beside it goes, or a cavity opens).
    Cavity,
    /// Its way out is blocked within this box (or by the bounding box of
    /// the pieces left): a piece there must go, or the bounding box
    /// shrink.
    Region(CellBox),
}

/// What the pieces are to each other, fixed while the model is taken
/// apart.
struct Graph<'a> {
    /// Per piece: the pieces a rule can add it to (position, weight,
    /// rule).
    holds: &'a [Vec<(u32, f64, RuleRef)>],
    /// Per piece: the pieces a rule can add to it.
    held: &'a [Vec<u32>],
    /// Per piece: a starting rule puts it on the ground.
    starts: &'a [bool],
    boxes: &'a [CellBox],
    /// Per piece of a complex rule: the piece its rule adds it to.
    complex_anchor: &'a [Option<u32>],
    /// Per piece: its lowest layer.
    z: &'a [i32],
}

/// The model as it is taken apart.
struct State {
    present: Vec<bool>,
    space: Space,
    hold: Hold,
    /// Per piece taken out: the piece left that a rule adds it to.
    anchors: Vec<Option<(u32, RuleRef)>>,
    /// Whether taking a piece out opened free space beyond its own cells
    /// to the outside (a cavity).
    opened_cavity: bool,
}

impl State {
    /// Takes the unit `unit` out of the pieces present if every rule of
    /// the module docs lets it (its pieces latest first); returns whether
    /// it went.
    fn take_out(&mut self, unit: &[usize], g: &Graph<'_>) -> Result<(), Watch> {
        let mut gone: Vec<(usize, Vec<usize>)> = Vec::with_capacity(unit.len());
        let mut ok = Ok(());
        for &k in unit.iter().rev() {
            self.present[k] = false;
            let anchor = best_anchor(&g.holds[k], &self.present);
            let joined = match g.complex_anchor[k] {
                Some(j) => self.present[j as usize],
                None => anchor.is_some() || g.starts[k],
            };
            // What it holds (but its own unit) still hangs on the ground
            // through the pieces left.
            let (present, hold) = (&self.present, &mut self.hold);
            let mut dropped = || {
                g.held[k].iter().copied().find(|&q| {
                    present[q as usize]
                        && !unit.contains(&(q as usize))
                        && !hold.reaches_start(q, g.holds, g.starts, present, g.z)
                })
            };
            // The cheap tests first: the way out (straight ways tried
            // first) before the search down to a start, which may visit
            // thousands of pieces.
            let leaves = if !joined {
                Err(Watch::Never)
            } else {
                self.space
                    .can_leave(&g.boxes[k])
                    .and_then(|()| match dropped() {
                        Some(q) => Err(Watch::Piece(q)),
                        None => Ok(()),
                    })
            };
            if let Err(w) = leaves {
                self.present[k] = true;
                ok = Err(w);
                break;
            }
            let opened = self.space.remove(&g.boxes[k]);
            let b = g.boxes[k];
            self.opened_cavity |= opened.len() > (b.sx * b.sy * b.sz) as usize;
            self.anchors[k] = anchor;
            gone.push((k, opened));
        }
        if ok.is_err() {
            for (k, opened) in gone.into_iter().rev() {
                self.space.put_back(&g.boxes[k], &opened);
                self.present[k] = true;
                self.anchors[k] = None;
            }
        }
        ok
    }
}

/// The box around a unit's pieces, one cell wider on every side.
fn around(unit: &[usize], boxes: &[CellBox]) -> CellBox {
    let (mut lo, mut hi) = (boxes[unit[0]].min, boxes[unit[0]].max_excl());
    for &k in unit {
        let (a, b) = (boxes[k].min, boxes[k].max_excl());
        lo = Cell::new(lo.x.min(a.x), lo.y.min(a.y), lo.z.min(a.z));
        hi = Cell::new(hi.x.max(b.x), hi.y.max(b.y), hi.z.max(b.z));
    }
    CellBox {
        min: lo.offset(-1, -1, -1),
        sx: hi.x - lo.x + 2,
        sy: hi.y - lo.y + 2,
        sz: hi.z - lo.z + 2,
    }
}

/// Whether boxes `a` and `b` share a cell.
fn meets(a: &CellBox, b: &CellBox) -> bool {
    let (am, bm) = (a.max_excl(), b.max_excl());
    a.min.x < bm.x
        && b.min.x < am.x
        && a.min.y < bm.y
        && b.min.y < am.y
        && a.min.z < bm.z
        && b.min.z < am.z
}

/// The heaviest rule adding the piece to a piece present: (its position,
/// the rule).
fn best_anchor(holds: &[(u32, f64, RuleRef)], present: &[bool]) -> Option<(u32, RuleRef)> {
    holds
        .iter()
        .filter(|(j, ..)| present[*j as usize])
        .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
        .map(|&(j, _, r)| (j, r))
}

/// The search for a chain of rules from a piece down to a starting piece
/// through the pieces present, with its scratch space, and the last chain
/// found from each piece (tried first: taking a piece out seldom breaks
/// it, and walking it costs its length where a search costs thousands).
struct Hold {
    seen: Vec<u32>,
    stamp: u32,
    /// Per piece searched from or passed on a chain found: the next piece
    /// toward a start, `u32::MAX` for none.
    next: Vec<u32>,
    /// Per piece seen in the current search: the piece it was reached
    /// from.
    from: Vec<u32>,
}

impl Hold {
    fn new(n: usize) -> Hold {
        Hold {
            seen: vec![0; n],
            stamp: 0,
            next: vec![u32::MAX; n],
            from: vec![u32::MAX; n],
        }
    }

    /// Whether piece `q` is added, through a chain of rules over pieces
    /// present, to a starting piece; optimistic past [`HOLD_LIMIT`].
    fn reaches_start(
        &mut self,
        q: u32,
        holds: &[Vec<(u32, f64, RuleRef)>],
        starts: &[bool],
        present: &[bool],
        z: &[i32],
    ) -> bool {
        // The chain found last time, if every piece of it is still there
        // (a real chain: the search below would say yes too). Where it
        // breaks, its pieces up to the break are still joined to `q`: the
        // search goes on from all of them, and mends the chain.
        self.stamp += 1;
        let stamp = self.stamp;
        let mut queue = BinaryHeap::new();
        let mut p = q;
        for _ in 0..HOLD_LIMIT {
            if !present[p as usize] || self.seen[p as usize] == stamp {
                break;
            }
            if starts[p as usize] {
                return true;
            }
            self.seen[p as usize] = stamp;
            self.from[p as usize] = u32::MAX;
            queue.push(Reverse((z[p as usize], p)));
            p = self.next[p as usize];
            if p == u32::MAX {
                break;
            }
        }
        // Lowest first: a chain down to the ground is found in about as
        // many steps as the piece stands high.
        let mut visited = 0;
        while let Some(Reverse((_, p))) = queue.pop() {
            if starts[p as usize] {
                // Keep the chain for next time.
                let mut c = p;
                while self.from[c as usize] != u32::MAX {
                    let f = self.from[c as usize];
                    self.next[f as usize] = c;
                    c = f;
                }
                return true;
            }
            visited += 1;
            if visited > HOLD_LIMIT {
                return true;
            }
            for &(j, ..) in &holds[p as usize] {
                if present[j as usize] && self.seen[j as usize] != stamp {
                    self.seen[j as usize] = stamp;
                    self.from[j as usize] = p;
                    queue.push(Reverse((z[j as usize], j)));
                }
            }
        }
        false
    }
}

/// The cells the pieces present take, the free space joined to the
/// outside, and how full each slab is (for the bounding box).
struct Space {
    origin: Cell,
    dims: (i32, i32, i32),
    taken: Vec<u16>,
    outside: Vec<bool>,
    /// Taken cells per x, y and z slab of the grid.
    slabs: [Vec<u32>; 3],
}

impl Space {
    /// Every box taken; the outside as the verifier has it: one free cell
    /// around the sides and over the top, none under the lowest layer.
    fn new(boxes: &[CellBox]) -> Space {
        let first = boxes[0];
        let (mut lo, mut hi) = (first.min, first.max_excl());
        for b in boxes {
            let m = b.max_excl();
            lo = Cell::new(lo.x.min(b.min.x), lo.y.min(b.min.y), lo.z.min(b.min.z));
            hi = Cell::new(hi.x.max(m.x), hi.y.max(m.y), hi.z.max(m.z));
        }
        let origin = lo.offset(-1, -1, 0);
        let dims = (hi.x - lo.x + 2, hi.y - lo.y + 2, hi.z - lo.z + 1);
        let len = (dims.0 * dims.1 * dims.2) as usize;
        let mut s = Space {
            origin,
            dims,
            taken: vec![0; len],
            outside: vec![false; len],
            slabs: [
                vec![0; dims.0 as usize],
                vec![0; dims.1 as usize],
                vec![0; dims.2 as usize],
            ],
        };
        for b in boxes {
            s.count(b, true);
        }
        let mut queue = Vec::new();
        for z in 0..dims.2 {
            for y in 0..dims.1 {
                for x in 0..dims.0 {
                    let border =
                        x == 0 || y == 0 || x == dims.0 - 1 || y == dims.1 - 1 || z == dims.2 - 1;
                    let c = origin.offset(x, y, z);
                    if border {
                        if let Some(i) = s.index(c) {
                            s.outside[i] = true;
                            queue.push(c);
                        }
                    }
                }
            }
        }
        s.flood(&mut queue, &mut Vec::new());
        s
    }

    fn index(&self, c: Cell) -> Option<usize> {
        let (x, y, z) = (
            c.x - self.origin.x,
            c.y - self.origin.y,
            c.z - self.origin.z,
        );
        let (nx, ny, nz) = self.dims;
        (x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz)
            .then(|| ((z * ny + y) * nx + x) as usize)
    }

    fn is_taken(&self, c: Cell) -> bool {
        self.index(c).is_some_and(|i| self.taken[i] > 0)
    }

    fn any_taken(&self, b: &CellBox) -> bool {
        b.sx > 0 && b.sy > 0 && b.sz > 0 && b.cells().any(|c| self.is_taken(c))
    }

    fn count(&mut self, b: &CellBox, add: bool) {
        for c in b.cells() {
            let Some(i) = self.index(c) else { continue };
            if add {
                self.taken[i] += 1;
            } else {
                self.taken[i] -= 1;
            }
            let o = self.origin;
            for (axis, v) in [(0, c.x - o.x), (1, c.y - o.y), (2, c.z - o.z)] {
                let slab = &mut self.slabs[axis][v as usize];
                if add {
                    *slab += 1;
                } else {
                    *slab -= 1;
                }
            }
        }
    }

    /// Takes the box's cells again, and closes what taking them out
    /// opened to the outside (`opened`, from [`Space::remove`]).
    fn put_back(&mut self, b: &CellBox, opened: &[usize]) {
        for &i in opened {
            self.outside[i] = false;
        }
        self.count(b, true);
    }

    /// Frees the box's cells; free cells that touch the outside join it,
    /// and so does what they open onto: the cells that joined it.
    fn remove(&mut self, b: &CellBox) -> Vec<usize> {
        self.count(b, false);
        let mut queue = Vec::new();
        let mut opened = Vec::new();
        for c in b.cells() {
            let Some(i) = self.index(c) else { continue };
            if self.taken[i] > 0 || self.outside[i] {
                continue;
            }
            if self.touches_outside(c) {
                self.outside[i] = true;
                opened.push(i);
                queue.push(c);
                self.flood(&mut queue, &mut opened);
            }
        }
        opened
    }

    fn touches_outside(&self, c: Cell) -> bool {
        FACES.iter().any(|&(dx, dy, dz)| {
            self.index(c.offset(dx, dy, dz))
                .is_some_and(|j| self.outside[j])
        })
    }

    fn flood(&mut self, queue: &mut Vec<Cell>, opened: &mut Vec<usize>) {
        while let Some(c) = queue.pop() {
            for (dx, dy, dz) in FACES {
                let n = c.offset(dx, dy, dz);
                if let Some(i) = self.index(n) {
                    if self.taken[i] == 0 && !self.outside[i] {
                        self.outside[i] = true;
                        opened.push(i);
                        queue.push(n);
                    }
                }
            }
        }
    }

    /// The inclusive bounding box of the taken cells, `None` if none.
    fn bounds(&self) -> Option<(Cell, Cell)> {
        let span = |s: &[u32]| {
            let a = s.iter().position(|&v| v > 0)?;
            let b = s.iter().rposition(|&v| v > 0)?;
            Some((a as i32, b as i32))
        };
        let (x0, x1) = span(&self.slabs[0])?;
        let (y0, y1) = span(&self.slabs[1])?;
        let (z0, z1) = span(&self.slabs[2])?;
        let o = self.origin;
        Some((o.offset(x0, y0, z0), o.offset(x1, y1, z1)))
    }

    /// Whether the piece in box `b` (taken) can be the last one put in:
    /// its cells join the outside, and it travels out of the bounding box
    /// of the other cells taken; if not, what to watch for a change.
    fn can_leave(&mut self, b: &CellBox) -> Result<(), Watch> {
        if !self.joins_outside(b) {
            return Err(Watch::Cavity);
        }
        self.count(b, false);
        let out = self.escapes(b);
        self.count(b, true);
        out
    }

    /// Whether a cell of box `b` has a face on the free space joined to
    /// the outside.
    fn joins_outside(&self, b: &CellBox) -> bool {
        b.cells().any(|c| {
            FACES.iter().any(|&(dx, dy, dz)| {
                let n = c.offset(dx, dy, dz);
                !b.contains(n) && self.index(n).is_some_and(|j| self.outside[j])
            })
        })
    }

    /// The verifier's placeability rule on the taken cells; if the piece
    /// cannot leave, the box its search explored.
    fn escapes(&self, b: &CellBox) -> Result<(), Watch> {
        let Some((lo, hi)) = self.bounds() else {
            return Ok(());
        };
        match escape(b, lo, hi, |x| self.any_taken(x), ESCAPE_LIMIT) {
            Escape::Out => Ok(()),
            // What blocks it lies within a cell of the positions explored
            // (the layers over and under them for the studs' clearance),
            // or in the columns over and under it, up to the bounding box.
            Escape::Stuck(plo, phi) => {
                let (zlo, zhi) = ((plo.z - 2).min(lo.z), (phi.z + b.sz + 2).max(hi.z + 1));
                Err(Watch::Region(CellBox {
                    min: Cell::new(plo.x - 1, plo.y - 1, zlo),
                    sx: phi.x - plo.x + b.sx + 2,
                    sy: phi.y - plo.y + b.sy + 2,
                    sz: zhi - zlo,
                }))
            }
        }
    }
}
