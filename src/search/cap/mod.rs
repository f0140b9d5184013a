//! Capping stair edges with slopes, after the layout.
//!
//! The layout lays bricks two half-brick layers tall, and where a roof
//! slants, a brick's cells outscore a slope's: the roof comes out as a
//! staircase. This pass looks at the finished layout the way a builder looks
//! at a stepped roof: at each brick on top of the build (nothing rests on
//! it) whose side stands two layers (a brick) above the neighbouring
//! columns, it swaps the row of the brick along that side for slopes whose
//! back row takes the brick's place and whose front row, one layer high,
//! lies on the lower neighbours, facing down the step. Underneath, a brick
//! at the bottom of the build (nothing under it) hanging two layers below
//! its neighbours becomes inverted slopes the same way.
//!
//! The slopes are 45° ones (two rows deep: the back row takes the brick's
//! side row) or 33° ones (three rows deep: the back two take the brick's
//! two rows along the side), whichever leaves the fewest pieces: a 2x8
//! brick capped at its short end becomes a 33° 2x3 slope and a 2x6 brick
//! rather than a 45° 2x2 slope, a 2x4 and a 2x3. What is left of the brick
//! is laid as few bricks of the alphabet as fill it (no 1x1s), and those
//! are capped again where they stand a step above their neighbours too (a
//! ridge brick gets slopes on both sides). A brick with something on part
//! of its side's row (half under the next course, as on the rounded tops
//! of organic models) has the longest bare run of that row capped instead,
//! the rest of the row laid as bricks beside the slopes. Roofs are capped from the eaves
//! up, so that a slope's front row lies on the back row of the slope
//! capped just below it.
//!
//! A swap keeps the build whole: the slopes and bricks laid each rest on,
//! or hold, a piece the rules join them to, the pieces the brick joined
//! still meet through them (a short walk over the joints), and the slopes
//! fit where the layout's own candidates must (their cells free, inside
//! the model or where the surface passes, the open face clear and
//! slanting the way the mesh does, one colour). A swap that does not fit
//! every part is undone. The swaps together add at most one piece in
//! `BUDGET_SHARE` of the layout's (and one swap at most `MAX_ADDED`),
//! so that the build keeps its voxels a piece within about a tenth. The
//! swaps are made in three orders and the build that caps the larger
//! share of its stair edges is kept: the swaps that add one piece at most
//! first, then those that add two (where the budget lasts, on organic
//! models: one brick's swap can take the room of another's); the swaps
//! that cap the most stair columns for each piece they add first (where
//! it runs out, on long roofs: a 2x8 brick along the run, capped with two
//! 2x4 slopes, adds two pieces for eight columns; a brick across it,
//! capped at its end, one piece for two); or lines of bricks across a
//! roof's run capped together first, then the best yield (see
//! [`line`](mod@line): the line's slopes run across the bricks' seams,
//! 2x4s where each brick took a 2x2). After them, neighbouring bricks
//! merge into longer ones and neighbouring slopes facing the same
//! way into wider ones (two 2x2 slopes into a 2x4), each merge undone
//! with the swaps if they are.

mod corner;
mod line;
mod trim;

use super::layout::{Layout, Reach};
use crate::assembly::{stairs, Assembly, Placement};
use crate::catalog::{Color, PartKind, Shape};
use crate::geom::{Body, Cell, CellBox, Rot};
use crate::grammar::Dir;

/// Layers into the model, from a slope's open face, in which the mesh must
/// slant the slope's way: a brick's height.
const SLANT_DEPTH: i32 = 2;

/// One brick swapped for slopes (and a shorter brick).
#[derive(Debug, Clone)]
pub(crate) struct Swap {
    /// The pieces taken out: the brick (two pieces for a merge after the
    /// swaps).
    taken: Vec<u32>,
    /// The pieces laid in its place.
    laid: std::ops::Range<u32>,
    /// How many of them are slopes.
    pub slopes: usize,
}

/// A piece about to be laid: where, and the cells it fills.
type Part = (Placement, Body);

/// What is left of brick box `b` when its `rows` rows along its side
/// facing `d` become slopes: `Some(None)` when nothing is, `None` if the
/// brick is not `rows` deep.
fn rest_box(b: &CellBox, d: (i32, i32), rows: i32) -> Option<Option<CellBox>> {
    let depth = if d.0 != 0 { b.sx } else { b.sy };
    if depth < rows {
        return None;
    }
    if depth == rows {
        return Some(None);
    }
    Some(Some(match d {
        (1, 0) => CellBox {
            sx: b.sx - rows,
            ..*b
        },
        (-1, 0) => CellBox {
            min: b.min.offset(rows, 0, 0),
            sx: b.sx - rows,
            ..*b
        },
        (0, 1) => CellBox {
            sy: b.sy - rows,
            ..*b
        },
        _ => CellBox {
            min: b.min.offset(0, rows, 0),
            sy: b.sy - rows,
            ..*b
        },
    }))
}

/// What is left of brick box `b` when a run of its side facing `d` (the
/// side cells from `lo`, `len` of them along the side) has its `rows` rows
/// made slopes: the rows behind the side, and the side's rows on either
/// side of the run; `None` if the brick is not `rows` deep.
fn rest_boxes(b: &CellBox, d: (i32, i32), rows: i32, lo: Cell, len: i32) -> Option<Vec<CellBox>> {
    let mut out: Vec<CellBox> = rest_box(b, d, rows)?.into_iter().collect();
    // The side's rows: the brick less the rows behind them.
    let strip = match d {
        (1, 0) => CellBox {
            min: b.min.offset(b.sx - rows, 0, 0),
            sx: rows,
            ..*b
        },
        (-1, 0) => CellBox { sx: rows, ..*b },
        (0, 1) => CellBox {
            min: b.min.offset(0, b.sy - rows, 0),
            sy: rows,
            ..*b
        },
        _ => CellBox { sy: rows, ..*b },
    };
    // Along the side (y when it faces x, x otherwise): the side's rows
    // before the run and after it.
    let along_y = d.0 != 0;
    let (start, size, at) = if along_y {
        (strip.min.y, strip.sy, lo.y)
    } else {
        (strip.min.x, strip.sx, lo.x)
    };
    let part = |from: i32, n: i32| {
        if along_y {
            CellBox {
                min: Cell::new(strip.min.x, from, strip.min.z),
                sy: n,
                ..strip
            }
        } else {
            CellBox {
                min: Cell::new(from, strip.min.y, strip.min.z),
                sx: n,
                ..strip
            }
        }
    };
    for (from, n) in [(start, at - start), (at + len, start + size - (at + len))] {
        if n > 0 {
            out.push(part(from, n));
        }
    }
    Some(out)
}

/// How many pieces the walk that checks a swap keeps the build joined
/// may pass through (see `Layout::still_joined`).
const JOIN_WALK: usize = 400;

/// The pieces the swaps may add to the build, at most: one in this many
/// of the layout's pieces (the build keeps its voxels a piece within about
/// a tenth).
const BUDGET_SHARE: usize = 9;

/// The pieces one swap may add (slopes and bricks laid, less the brick
/// taken out).
const MAX_ADDED: usize = 2;

/// What the swaps may still add.
#[derive(Debug, Clone, Copy)]
struct Budget {
    /// Pieces, over all the swaps.
    pieces: usize,
    /// Pieces, in one swap.
    per_swap: usize,
    /// Stair columns a swap must cap for each piece it adds.
    min_yield: usize,
}

/// What an order of the swaps made: the stair edges capped, of how many,
/// and the pieces added.
#[derive(Debug, Clone, Copy)]
struct Capped {
    edges: (usize, usize),
    added: usize,
}

impl Capped {
    /// Whether this caps a larger share of its stair edges than `other`,
    /// or the same share with fewer pieces added (or as few, if `ties`).
    fn better(&self, other: &Capped, ties: bool) -> bool {
        let ((k, n), (ko, no)) = (self.edges, other.edges);
        let (mine, theirs) = (k * no.max(1), ko * n.max(1));
        mine > theirs
            || (mine == theirs && (self.added < other.added || (ties && self.added == other.added)))
    }
}

/// The order in which bricks are capped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Order {
    /// The swaps that add one piece at most first, then two.
    Cheap,
    /// The swaps that cap the most stair columns for each piece they add
    /// first (see [`YIELDS`]).
    Yield,
    /// Lines of bricks first (see [`line`](mod@line)), then as [`Order::Yield`].
    Lines,
}

/// The passes of swaps, by the stair columns a swap must cap for each
/// piece it adds: the swaps that cap the most for their pieces go first,
/// so that the budget caps the most edges (a 2x8 brick along a roof's
/// run capped with two 2x4 slopes adds two pieces for eight columns; a
/// brick across it, capped at its end, one piece for two); the last pass
/// takes any swap the budget still allows.
const YIELDS: [usize; 5] = [4, 3, 2, 1, 0];

/// Passes of merging after the swaps.
const MERGE_ROUNDS: usize = 4;

/// How many times the bricks left of a swap are capped again.
const MAX_DEPTH: u32 = 2;

/// The four horizontal directions a step can fall.
const DIRS: [(i32, i32); 4] = [(1, 0), (-1, 0), (0, 1), (0, -1)];

impl Layout<'_> {
    /// Caps stair edges with slopes (on top) and inverted slopes
    /// (underneath) where the alphabet has them; returns the swaps made.
    pub fn cap_stairs(&mut self) -> Vec<Swap> {
        let has = |s: Shape| self.shapes.iter().any(|p| p.part.spec().shape == s);
        let (top, under) = (has(Shape::Slope), has(Shape::Inverted));
        if !top && !under {
            return Vec::new();
        }
        // Half-brick layers only: bricks two layers tall.
        let bricks: Vec<u32> = (0..self.pieces.len() as u32)
            .filter(|&id| self.cappable(id))
            .collect();
        let live = self.pieces.iter().filter(|p| !p.gone).count();
        let pieces = live / BUDGET_SHARE;
        // Each order, and the one whose build caps the larger share of
        // its stair edges (the fewer pieces if equal): the cheap swaps
        // first cap more where the budget lasts (the swaps of one brick
        // can take the room of another's), the best yield first where it
        // runs out (a long roof), lines of bricks first where a roof's
        // courses are laid across its run.
        let extra = self.repairs.extra_cells;
        let mut swaps: Vec<Swap> = Vec::new();
        let mut best: Option<(Order, Capped)> = None;
        let mut last = None;
        for order in [Order::Yield, Order::Cheap, Order::Lines] {
            if last.is_some() {
                self.uncap(&swaps);
                self.repairs.extra_cells = extra;
            }
            let (made, budget) = self.cap_in_order(&bricks, order, top, under, pieces);
            swaps = made;
            last = Some(order);
            let got = Capped {
                edges: self.capped_edges(),
                added: pieces - budget.pieces,
            };
            // Ties go to the cheap order over the best yield's, as before
            // lines were tried, and to either over the lines'.
            if best.is_none_or(|(_, b)| got.better(&b, order == Order::Cheap)) {
                best = Some((order, got));
            }
        }
        if let (Some((order, _)), Some(l)) = (best, last) {
            if order != l {
                self.uncap(&swaps);
                self.repairs.extra_cells = extra;
                swaps = self.cap_in_order(&bricks, order, top, under, pieces).0;
            }
        }
        if swaps.iter().any(|s| s.slopes > 0) {
            self.merge_after(&mut swaps);
            self.rebuild_bodies();
        }
        swaps
    }

    /// The stair edges of the build as laid, top and underside together
    /// (see [`stairs`]): how many are capped, of how many.
    fn capped_edges(&self) -> (usize, usize) {
        let order: Vec<Placement> = self
            .pieces
            .iter()
            .filter(|p| !p.gone)
            .map(|p| p.placement)
            .collect();
        let s = stairs::stair_edges(&Assembly::from_order(&order, self.layer_ldu, Color::RED));
        (
            s.capped.top + s.capped.underside,
            s.edges.top + s.edges.underside,
        )
    }

    /// Caps the stair edges of `bricks` in `order`, on top if `top`,
    /// underneath if `under`, adding at most `pieces` pieces; the swaps
    /// made and what is left of the budget.
    fn cap_in_order(
        &mut self,
        bricks: &[u32],
        order: Order,
        top: bool,
        under: bool,
        pieces: usize,
    ) -> (Vec<Swap>, Budget) {
        let mut budget = Budget {
            pieces,
            per_swap: MAX_ADDED,
            min_yield: 0,
        };
        let passes: Vec<(usize, usize)> = match order {
            Order::Cheap => (1..=MAX_ADDED).map(|k| (k, 0)).collect(),
            Order::Yield | Order::Lines => YIELDS.iter().map(|&y| (MAX_ADDED, y)).collect(),
        };
        let mut swaps = Vec::new();
        if order == Order::Lines {
            // Capped together, a line of bricks across a roof's run costs
            // a piece for several stair columns.
            for (kind, wanted) in [(Shape::Slope, top), (Shape::Inverted, under)] {
                let mut tried = std::collections::HashSet::new();
                for id in self.eaves_up(bricks, kind) {
                    if wanted && !self.pieces[id as usize].gone {
                        swaps.extend(self.cap_line(id, kind, &mut budget, &mut tried));
                    }
                }
            }
        }
        for (per_swap, min_yield) in passes {
            for (kind, wanted) in [(Shape::Slope, top), (Shape::Inverted, under)] {
                if !wanted {
                    continue;
                }
                (budget.per_swap, budget.min_yield) = (per_swap, min_yield);
                for id in self.eaves_up(bricks, kind) {
                    if self.pieces[id as usize].gone {
                        continue;
                    }
                    let first = self.pieces.len() as u32;
                    if let Some(k) = self.cap_piece(id, kind, 0, &mut budget) {
                        swaps.push(Swap {
                            taken: vec![id],
                            laid: first..self.pieces.len() as u32,
                            slopes: k,
                        });
                    }
                }
            }
        }
        // Then the corners where the rows of slopes end.
        (budget.per_swap, budget.min_yield) = (MAX_ADDED, 0);
        for (kind, wanted) in [(Shape::Slope, top), (Shape::Inverted, under)] {
            if wanted {
                swaps.extend(self.cap_corners(kind, &mut budget));
            }
        }
        (swaps, budget)
    }

    /// `bricks` from the eaves up for slopes of `kind` (a slope's front
    /// row may lie on the back row of the slope capped just below it),
    /// from the top down for inverted slopes.
    fn eaves_up(&self, bricks: &[u32], kind: Shape) -> Vec<u32> {
        let mut ids = bricks.to_vec();
        ids.sort_by_key(|&id| {
            let z = self.pieces[id as usize].body.bbox.min.z;
            (if kind == Shape::Slope { z } else { -z }, id)
        });
        ids
    }

    /// Merges the bricks the swaps left with their neighbours where the
    /// union is a brick of the alphabet (see [`Layout::merge`]), each
    /// merge kept as a swap of its own so that [`Layout::uncap`] undoes it.
    fn merge_after(&mut self, swaps: &mut Vec<Swap>) {
        for _ in 0..MERGE_ROUNDS {
            let mut merged = 0;
            for a in 0..self.pieces.len() as u32 {
                if self.pieces[a as usize].gone {
                    continue;
                }
                let first = self.pieces.len() as u32;
                let merge = self
                    .merge_with_neighbour(a)
                    .or_else(|| self.merge_slopes(a));
                if let Some(b) = merge {
                    swaps.push(Swap {
                        taken: vec![a, b],
                        laid: first..self.pieces.len() as u32,
                        slopes: 0,
                    });
                    merged += 1;
                }
            }
            self.stats.merges += merged;
            if merged == 0 {
                break;
            }
        }
    }

    /// Merges slope `a` with the slope past its +x or +y side if they face
    /// the same way in the same layers and the alphabet has a slope as
    /// wide as both (two 2x2 slopes become a 2x4): a roof's slopes in rows
    /// as long as the parts allow. The neighbour merged, if any.
    fn merge_slopes(&mut self, a: u32) -> Option<u32> {
        let pa = self.pieces[a as usize];
        let sa = pa.placement.part.spec();
        if !matches!(sa.shape, Shape::Slope | Shape::Inverted) || pa.group.is_some() {
            return None;
        }
        let ba = pa.body.bbox;
        let back = sa.back(pa.placement.rot);
        // Side by side across the slope's width: along x when it faces y.
        let (dx, dy) = if back.0 == 0 { (ba.sx, 0) } else { (0, ba.sy) };
        let b = self.owner_of(ba.min.offset(dx, dy, 0))?;
        let pb = self.pieces[b as usize];
        let sb = pb.placement.part.spec();
        let bb = pb.body.bbox;
        let aligned = b != a
            && pb.group.is_none()
            && sb.shape == sa.shape
            && sb.studs_y == sa.studs_y
            && sb.back(pb.placement.rot) == back
            && super::merge::continues(&ba, &bb, dx > 0);
        if !aligned {
            return None;
        }
        let width = (sa.studs_x + sb.studs_x) as i32;
        let shape = self.shapes.iter().find(|s| {
            let sp = s.part.spec();
            sp.shape == sa.shape
                && sp.studs_y == sa.studs_y
                && sp.studs_x as i32 == width
                && sp.back(s.rot) == back
        })?;
        let (part, rot) = (shape.part, shape.rot);
        let placement = Placement::new(part, ba.min, rot);
        let body = part.body(rot, ba.min, self.layer_ldu);
        let around: Vec<u32> = self
            .below(&pa.body)
            .into_iter()
            .chain(self.below(&pb.body))
            .chain(self.above(&pa.body))
            .chain(self.above(&pb.body))
            .collect();
        self.remove(a);
        self.remove(b);
        let u = self.layer_ldu;
        let joins = |l: &Self, o: u32| {
            let other = &l.pieces[o as usize].placement;
            l.book.joint(other, &placement, Dir::Up, u).is_some()
                || l.book.joint(&placement, other, Dir::Down, u).is_some()
                || l.book.joint(&placement, other, Dir::Up, u).is_some()
                || l.book.joint(other, &placement, Dir::Down, u).is_some()
        };
        let fits = self
            .fits_within(&placement, &body, Reach::Far, SLANT_DEPTH)
            .is_some();
        if fits && around.iter().all(|&o| joins(self, o)) {
            self.place(placement, body, None);
            return Some(b);
        }
        self.restore(a);
        self.restore(b);
        None
    }

    /// Undoes `swaps` (the bricks back, the slopes out), last first.
    pub fn uncap(&mut self, swaps: &[Swap]) {
        for s in swaps.iter().rev() {
            for id in s.laid.clone() {
                self.remove(id);
            }
            for &id in s.taken.iter().rev() {
                self.restore(id);
            }
        }
        if !swaps.is_empty() {
            self.rebuild_bodies();
        }
    }

    /// Swaps a run of the row of piece `id` along its side that falls most
    /// for slopes of `kind`, then the bricks left of it the same way (a
    /// ridge brick gets slopes on both sides); the slopes laid, or `None`
    /// when no side fits.
    fn cap_piece(
        &mut self,
        id: u32,
        kind: Shape,
        depth: u32,
        budget: &mut Budget,
    ) -> Option<usize> {
        let p = self.pieces[id as usize];
        let b = p.body.bbox;
        let up = kind == Shape::Slope;
        // The sides by how many columns beside them step by a brick, with
        // nothing over (under) the run of the row capped.
        let mut sides: Vec<(usize, (i32, i32))> = DIRS
            .iter()
            .filter(|&&d| self.side_bare(&b, d, up))
            .map(|&d| (self.side_steps(&b, d, up), d))
            .filter(|&(k, _)| k > 0)
            .collect();
        sides.sort_by_key(|&(k, d)| (std::cmp::Reverse(k), d));
        let mut runs: Vec<(usize, (i32, i32), Vec<Cell>)> = sides
            .iter()
            .map(|&(k, d)| (k, d, self.side_cells(&b, d).collect()))
            .collect();
        // Then the bare runs of the sides with something on part of their
        // row (a brick half under the next course): the run's rows become
        // slopes, the rest of the side's rows bricks.
        let mut part: Vec<(usize, (i32, i32), Vec<Cell>)> = DIRS
            .iter()
            .filter(|&&d| !self.side_bare(&b, d, up))
            .filter_map(|&d| {
                let run = self.best_bare_run(&b, d, up)?;
                Some((self.steps_of(&run, d, &b, up), d, run))
            })
            .filter(|(k, _, _)| *k > 0)
            .collect();
        part.sort_by_key(|(k, d, _)| (std::cmp::Reverse(*k), *d));
        runs.extend(part);
        for (steps, d, side) in runs {
            if let Some((k, rest)) = self.swap_side(id, d, &side, kind, steps, budget) {
                let mut more = 0;
                if depth < MAX_DEPTH {
                    for r in rest {
                        if self.pieces[r as usize].body.bbox.sz == 2 {
                            more += self.cap_piece(r, kind, depth + 1, budget).unwrap_or(0);
                        }
                    }
                }
                return Some(k + more);
            }
        }
        None
    }

    /// Whether nothing lies on the row of `b` along its side facing `d`
    /// (under it, underneath when `up` is false), nor is any voxel of the
    /// model left there uncovered.
    fn side_bare(&self, b: &CellBox, d: (i32, i32), up: bool) -> bool {
        self.side_cells(b, d).all(|a| self.bare_over(a, b, up))
    }

    /// Whether nothing lies on side cell `a` of brick box `b` (under it
    /// when `up` is false), nor any voxel of the model left uncovered.
    fn bare_over(&self, a: Cell, b: &CellBox, up: bool) -> bool {
        let dz = if up { b.sz } else { -1 };
        let q = a.offset(0, 0, dz);
        // With a flat base, the table under the lowest course is
        // something (see `SearchOptions::flat_base`).
        if !up && q.z < 0 && self.flat_base {
            return false;
        }
        !self.must.in_bounds(q) || (self.owner_of(q).is_none() && !self.must.get(q))
    }

    /// The longest run of the side of `b` facing `d` with nothing over
    /// (under) it, at least two cells and not the whole side; the first of
    /// the longest.
    fn best_bare_run(&self, b: &CellBox, d: (i32, i32), up: bool) -> Option<Vec<Cell>> {
        let side: Vec<Cell> = self.side_cells(b, d).collect();
        let mut best: Option<(usize, usize)> = None;
        let mut at = 0;
        while at < side.len() {
            if !self.bare_over(side[at], b, up) {
                at += 1;
                continue;
            }
            let start = at;
            while at < side.len() && self.bare_over(side[at], b, up) {
                at += 1;
            }
            let len = at - start;
            if len >= 2 && len < side.len() && best.is_none_or(|(_, l)| len > l) {
                best = Some((start, len));
            }
        }
        let (start, len) = best?;
        Some(side[start..start + len].to_vec())
    }

    /// How many of the side cells `run` of brick box `b` have a neighbour
    /// facing `d` that steps a brick down, with room for a slope's front
    /// row (see [`Layout::side_steps`]).
    fn steps_of(&self, run: &[Cell], d: (i32, i32), b: &CellBox, up: bool) -> usize {
        run.iter()
            .filter(|&&a| self.steps_down(a, d, b, up))
            .count()
    }

    /// How many columns of the side of `b` facing `d` have a neighbour
    /// beyond it that steps a brick (two layers) down, with room for a
    /// slope's front row on it: on top, the neighbour's cells in `b`'s two
    /// layers are free and a piece is under them; underneath (`up` false),
    /// the same upside down.
    fn side_steps(&self, b: &CellBox, d: (i32, i32), up: bool) -> usize {
        self.side_cells(b, d)
            .filter(|&a| self.steps_down(a, d, b, up))
            .count()
    }

    /// Whether side cell `a` of brick box `b` has a neighbour facing `d`
    /// that steps a brick down, with room for a slope's front row (see
    /// [`Layout::side_steps`]).
    fn steps_down(&self, a: Cell, d: (i32, i32), b: &CellBox, up: bool) -> bool {
        let n = a.offset(d.0, d.1, 0);
        if up {
            // Front row at the brick's bottom layer, open above,
            // resting on a piece.
            let f = Cell::new(n.x, n.y, b.min.z);
            self.free(f) && self.clear_column(f, 1) && self.owner_of(f.offset(0, 0, -1)).is_some()
        } else {
            // Front row at the brick's top layer, open below,
            // holding a piece above.
            let f = Cell::new(n.x, n.y, b.min.z + b.sz - 1);
            self.free(f) && self.clear_column(f, -1) && self.owner_of(f.offset(0, 0, 1)).is_some()
        }
    }

    /// The bottom-layer cells of `b` along its side facing `d`.
    fn side_cells(&self, b: &CellBox, d: (i32, i32)) -> impl Iterator<Item = Cell> {
        let x = match d.0 {
            1 => Some(b.min.x + b.sx - 1),
            -1 => Some(b.min.x),
            _ => None,
        };
        let y = match d.1 {
            1 => Some(b.min.y + b.sy - 1),
            -1 => Some(b.min.y),
            _ => None,
        };
        let side = CellBox {
            min: Cell::new(x.unwrap_or(b.min.x), y.unwrap_or(b.min.y), b.min.z),
            sx: if x.is_some() { 1 } else { b.sx },
            sy: if y.is_some() { 1 } else { b.sy },
            sz: 1,
        };
        side.cells().collect::<Vec<_>>().into_iter()
    }

    /// Whether the cells from `f` up (`dz` 1) or down (-1) are free of
    /// pieces and of the model's voxels to the grid's end: a slope's front
    /// row must be open to the outside over its face, or the pieces around
    /// it would enclose it and it could not be put in place.
    fn clear_column(&self, f: Cell, dz: i32) -> bool {
        let mut q = f.offset(0, 0, dz);
        while self.must.in_bounds(q) {
            if !self.free(q) || self.must.get(q) {
                return false;
            }
            q = q.offset(0, 0, dz);
        }
        true
    }

    /// Takes piece `id` out and lays, in its place, slopes of `kind` along
    /// a run of its side facing `d` (back rows on that side, front rows
    /// beyond it) and bricks for the rest of it; puts it back if any part
    /// does not fit, joins nothing through a rule, or the pieces the brick
    /// joined would no longer be joined through the new ones. Returns the
    /// slopes laid and the bricks laid for the rest.
    fn swap_side(
        &mut self,
        id: u32,
        d: (i32, i32),
        side: &[Cell],
        kind: Shape,
        steps: usize,
        budget: &mut Budget,
    ) -> Option<(usize, Vec<u32>)> {
        let p = self.pieces[id as usize];
        let b = p.body.bbox;
        // 45° slopes (their back row on the side row) and 33° ones (their
        // back two rows in the brick): the plan that adds the fewest pieces
        // first, then the 45° one.
        let mut plans: Vec<(usize, i32, Vec<Part>, usize)> = [2, 3]
            .into_iter()
            .filter_map(|deep| {
                let (slopes, rest) = self.plan_swap(&b, d, kind, side, deep)?;
                let n = slopes.len();
                let all: Vec<(Placement, Body)> = slopes.into_iter().chain(rest).collect();
                Some((all.len(), deep, all, n))
            })
            .collect();
        plans.sort_by_key(|&(n, deep, _, _)| (n, deep));
        if plans.is_empty() {
            return None;
        }
        // The pieces the brick joined, which the new ones must still join.
        let joined = self.joined_with(id);
        self.remove(id);
        for (n, _, all, slopes) in plans {
            // Pieces it adds to the build: within the swap's and the whole
            // pass's budget.
            let added = n.saturating_sub(1);
            if added > budget.per_swap || added > budget.pieces || steps < budget.min_yield * added
            {
                continue;
            }
            let fits = all.iter().all(|(pl, body)| self.swap_fits(pl, body));
            if !fits || !self.still_joined(&all, &joined) {
                continue;
            }

            budget.pieces -= added;
            let mut rest = Vec::new();
            for (placement, body) in all {
                self.repairs.extra_cells += body.cells().filter(|&q| !self.must.get(q)).count();
                let n = self.place(placement, body, None);
                if body.is_box() {
                    rest.push(n);
                }
            }
            return Some((slopes, rest));
        }
        self.restore(id);
        None
    }

    /// The pieces piece `id` joins through the rules, under it and over it.
    fn joined_with(&self, id: u32) -> Vec<u32> {
        let body = self.pieces[id as usize].body;
        let mut v: Vec<u32> = self
            .below(&body)
            .into_iter()
            .filter(|&o| self.joined_by_rule(o, id))
            .collect();
        v.extend(
            self.above(&body)
                .into_iter()
                .filter(|&o| self.joined_by_rule(id, o)),
        );
        v
    }

    /// The slopes (`deep` rows deep, `deep - 1` of them in brick box `b`)
    /// along `side`, the row of `b` facing `d`, and
    /// the bricks for the rest of `b`; `None` if the alphabet has no such
    /// slopes or no bricks for the rest.
    fn plan_swap(
        &self,
        b: &CellBox,
        d: (i32, i32),
        kind: Shape,
        side: &[Cell],
        deep: i32,
    ) -> Option<(Vec<Part>, Vec<Part>)> {
        let whole = side.len() as i32 == if d.0 != 0 { b.sy } else { b.sx };
        let rest = if whole {
            match rest_box(b, d, deep - 1)? {
                Some(r) => self.bricks_for(&r)?,
                None => Vec::new(),
            }
        } else {
            let boxes = rest_boxes(b, d, deep - 1, *side.first()?, side.len() as i32)?;
            let mut v = Vec::new();
            for r in boxes {
                v.extend(self.bricks_for(&r)?);
            }
            v
        };
        Some((self.slope_row(side, d, kind, deep)?, rest))
    }

    /// Slopes of `kind`, `deep` rows deep, along `side` (a row of cells
    /// facing `d`, their row behind the front row on it), longest first;
    /// `None` if the alphabet has none that fit.
    fn slope_row(&self, side: &[Cell], d: (i32, i32), kind: Shape, deep: i32) -> Option<Vec<Part>> {
        let step = if d.0 != 0 { (0, 1) } else { (1, 0) };
        let mut slopes: Vec<Part> = Vec::new();
        let width = side.len() as i32;
        let mut at = 0;
        while at < width {
            let left = width - at;
            let (w, placed) = self.slope_for(side[at as usize], step, left, d, kind, deep)?;
            slopes.push(placed);
            at += w;
        }
        Some(slopes)
    }

    /// Whether the pieces `joined` (which a brick just taken out joined)
    /// are still one through the pieces `new` about to be laid in its
    /// place: every new piece and every one of `joined` meet through the
    /// rules' joints of the new pieces.
    fn still_joined(&self, new: &[(Placement, Body)], joined: &[u32]) -> bool {
        let u = self.layer_ldu;
        // The old pieces each new piece meets through a joint.
        let met: Vec<Vec<u32>> = new
            .iter()
            .map(|(pl, body)| {
                let mut v: Vec<u32> = Vec::new();
                for o in self.below(body) {
                    let a = &self.pieces[o as usize].placement;
                    if self.book.joint(a, pl, Dir::Up, u).is_some()
                        || self.book.joint(pl, a, Dir::Down, u).is_some()
                    {
                        v.push(o);
                    }
                }
                for o in self.above(body) {
                    let a = &self.pieces[o as usize].placement;
                    if self.book.joint(pl, a, Dir::Up, u).is_some()
                        || self.book.joint(a, pl, Dir::Down, u).is_some()
                    {
                        v.push(o);
                    }
                }
                v
            })
            .collect();
        // A walk over the joints from the first new piece, through old
        // pieces as far as `JOIN_WALK` of them, must meet every new piece
        // and every one of `joined`.
        let mut seen_new = vec![false; new.len()];
        let mut seen: std::collections::HashSet<u32> = std::collections::HashSet::new();
        let mut queue: std::collections::VecDeque<u32> = std::collections::VecDeque::new();
        seen_new[0] = true;
        let reach_new = |i: usize,
                         seen: &mut std::collections::HashSet<u32>,
                         queue: &mut std::collections::VecDeque<u32>| {
            for &o in &met[i] {
                if seen.insert(o) {
                    queue.push_back(o);
                }
            }
        };
        reach_new(0, &mut seen, &mut queue);
        let done = |seen_new: &[bool], seen: &std::collections::HashSet<u32>| {
            seen_new.iter().all(|&s| s) && joined.iter().all(|o| seen.contains(o))
        };
        while let Some(o) = queue.pop_front() {
            if done(&seen_new, &seen) {
                return true;
            }
            if seen.len() > JOIN_WALK {
                return false;
            }
            for (i, m) in met.iter().enumerate() {
                if !seen_new[i] && m.contains(&o) {
                    seen_new[i] = true;
                    reach_new(i, &mut seen, &mut queue);
                }
            }
            let body = self.pieces[o as usize].body;
            let next: Vec<u32> = self
                .below(&body)
                .into_iter()
                .filter(|&b| self.joined_by_rule(b, o))
                .chain(
                    self.above(&body)
                        .into_iter()
                        .filter(|&a| self.joined_by_rule(o, a)),
                )
                .collect();
            for q in next {
                if seen.insert(q) {
                    queue.push_back(q);
                }
            }
        }
        done(&seen_new, &seen)
    }

    /// Bricks of the alphabet, none 1x1, that fill `r` (one or two studs
    /// wide) end to end, as few as can, longest first.
    fn bricks_for(&self, r: &CellBox) -> Option<Vec<(Placement, Body)>> {
        if let Some(one) = self.brick_for(r) {
            return (r.sx * r.sy > 1).then(|| vec![one]);
        }
        let along_x = r.sx >= r.sy;
        let (len, wide) = if along_x { (r.sx, r.sy) } else { (r.sy, r.sx) };
        // The lengths of bricks `wide` studs wide, none 1x1.
        let mut lengths: Vec<i32> = (1..=len)
            .filter(|&l| wide * l > 1)
            .filter(|&l| {
                let (fx, fy) = if along_x { (l, wide) } else { (wide, l) };
                self.shapes.iter().any(|s| {
                    let spec = s.part.spec();
                    spec.shape == Shape::Rect
                        && spec.footprint(s.rot) == (fx, fy)
                        && s.body_at(r.min).bbox.sz == r.sz
                })
            })
            .collect();
        lengths.sort_unstable_by(|a, b| b.cmp(a));
        // Fewest pieces for each length, by the longest first piece.
        let mut best: Vec<Option<Vec<i32>>> = vec![None; len as usize + 1];
        best[0] = Some(Vec::new());
        for l in 1..=len {
            for &p in &lengths {
                if p > l {
                    continue;
                }
                if let Some(prev) = &best[(l - p) as usize] {
                    if best[l as usize]
                        .as_ref()
                        .is_none_or(|cur| prev.len() + 1 < cur.len())
                    {
                        let mut v = vec![p];
                        v.extend(prev);
                        best[l as usize] = Some(v);
                    }
                }
            }
        }
        let parts = best[len as usize].clone()?;
        let mut out = Vec::new();
        let mut at = 0;
        for l in parts {
            let piece = if along_x {
                CellBox {
                    min: r.min.offset(at, 0, 0),
                    sx: l,
                    ..*r
                }
            } else {
                CellBox {
                    min: r.min.offset(0, at, 0),
                    sy: l,
                    ..*r
                }
            };
            out.push(self.brick_for(&piece)?);
            at += l;
        }
        Some(out)
    }

    /// Whether a piece of a swap fits where the layout's own candidates
    /// must, and rests on (or holds) a piece the rules join it to.
    fn swap_fits(&self, placement: &Placement, body: &Body) -> bool {
        // The front row may reach past the cells the surface passes
        // through (it lies on a piece, see `side_steps`): a slope's face
        // stands over the surface it stands for. Its slant is looked for
        // a course into the model.
        if self
            .fits_within(placement, body, Reach::Far, SLANT_DEPTH)
            .is_none()
        {
            return false;
        }
        let u = self.layer_ldu;
        let below = self.below(body).into_iter().any(|o| {
            let a = &self.pieces[o as usize].placement;
            self.book.joint(a, placement, Dir::Up, u).is_some()
                || self.book.joint(placement, a, Dir::Down, u).is_some()
        });
        below
            || self.above(body).into_iter().any(|o| {
                let a = &self.pieces[o as usize].placement;
                self.book.joint(placement, a, Dir::Up, u).is_some()
                    || self.book.joint(a, placement, Dir::Down, u).is_some()
            })
    }

    /// The rectangular piece of the alphabet that fills `r` exactly.
    fn brick_for(&self, r: &CellBox) -> Option<(Placement, Body)> {
        self.shapes.iter().find_map(|s| {
            let spec = s.part.spec();
            if spec.shape != Shape::Rect || spec.footprint(s.rot) != (r.sx, r.sy) {
                return None;
            }
            let body = s.body_at(r.min);
            (body.bbox == *r).then(|| (Placement::new(s.part, r.min, s.rot), body))
        })
    }

    /// The widest slope of `kind`, `deep` rows deep, of the alphabet, at
    /// most `left` studs wide, whose row behind the front row starts at
    /// `start` (its bottom layer) and runs `step`-wise, facing `d`; its
    /// width and placement.
    fn slope_for(
        &self,
        start: Cell,
        step: (i32, i32),
        left: i32,
        d: (i32, i32),
        kind: Shape,
        deep: i32,
    ) -> Option<(i32, Part)> {
        let mut best: Option<(i32, PartKind, Rot)> = None;
        for s in &self.shapes {
            let spec = s.part.spec();
            if spec.shape != kind || spec.studs_y as i32 != deep || spec.back(s.rot) != (-d.0, -d.1)
            {
                continue;
            }
            let w = spec.studs_x as i32;
            if w <= left && best.is_none_or(|(bw, _, _)| w > bw) {
                best = Some((w, s.part, s.rot));
            }
        }
        let (w, part, rot) = best?;
        // The slope's box: its front row one stud beyond the side, the row
        // behind it along the side, any other rows further into the brick.
        let end = start.offset(step.0 * (w - 1), step.1 * (w - 1), 0);
        let back = -(deep - 2);
        let corners = [
            start.offset(d.0, d.1, 0),
            end.offset(d.0, d.1, 0),
            start.offset(d.0 * back, d.1 * back, 0),
            end.offset(d.0 * back, d.1 * back, 0),
        ];
        let min = Cell::new(
            corners.iter().map(|c| c.x).min().unwrap_or(start.x),
            corners.iter().map(|c| c.y).min().unwrap_or(start.y),
            start.z,
        );
        let body = part.body(rot, min, self.layer_ldu);
        Some((w, (Placement::new(part, min, rot), body)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brick(sx: i32, sy: i32) -> CellBox {
        CellBox {
            min: Cell::new(10, 20, 4),
            sx,
            sy,
            sz: 2,
        }
    }

    #[test]
    fn the_rest_of_a_brick_is_the_rows_behind_the_side() {
        // A 2x8 brick along x capped at its +x end by a 45° slope (one row
        // in the brick): 7x2 left, at the brick's corner.
        let b = brick(8, 2);
        assert_eq!(rest_box(&b, (1, 0), 1), Some(Some(CellBox { sx: 7, ..b })));
        // At its -x end by a 33° slope (two rows): 6x2 left, two studs in.
        let r = CellBox {
            min: Cell::new(12, 20, 4),
            sx: 6,
            ..b
        };
        assert_eq!(rest_box(&b, (-1, 0), 2), Some(Some(r)));
        // Along its long side: one row left; both rows: none; three: the
        // brick is too shallow.
        assert_eq!(
            rest_box(&b, (0, -1), 1),
            Some(Some(CellBox {
                min: Cell::new(10, 21, 4),
                sy: 1,
                ..b
            }))
        );
        assert_eq!(rest_box(&b, (0, 1), 2), Some(None));
        assert_eq!(rest_box(&b, (0, 1), 3), None);
    }

    #[test]
    fn the_rest_of_a_brick_capped_along_a_run_of_its_side() {
        // A 1x6 brick along x whose +y side is capped on x 12..14 only (a
        // brick lies on the rest of its row): no rows behind the side,
        // 1x2 before the run and 1x2 after it.
        let b = brick(6, 1);
        let at = |x| Cell::new(x, 20, 4);
        assert_eq!(
            rest_boxes(&b, (0, 1), 1, at(12), 2),
            Some(vec![
                CellBox { sx: 2, ..b },
                CellBox {
                    min: at(14),
                    sx: 2,
                    ..b
                },
            ])
        );
        // A 2x4 brick along x, its -y side capped on x 10..12: the row
        // behind (4 long), then the side row past the run (2 long).
        let b = brick(4, 2);
        assert_eq!(
            rest_boxes(&b, (0, -1), 1, at(10), 2),
            Some(vec![
                CellBox {
                    min: Cell::new(10, 21, 4),
                    sy: 1,
                    ..b
                },
                CellBox {
                    min: at(12),
                    sx: 2,
                    sy: 1,
                    ..b
                },
            ])
        );
    }
}
