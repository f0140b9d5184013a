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
//! A swap keeps every joint: the slopes (and what is left of the brick, a
//! shorter brick) each rest on, or hold, a piece the rules join them to,
//! and the slopes must fit where the layout's own candidates must (their
//! cells free, inside the model or where the surface passes, the open face
//! clear and slanting the way the mesh does, one colour). A swap that does
//! not fit every part is undone. Brick count grows by at most one a swap
//! (the shorter brick), and only where the brick was more than one stud
//! deep.

use super::layout::{Layout, Reach};
use crate::assembly::Placement;
use crate::catalog::{PartKind, Shape};
use crate::geom::{Body, Cell, CellBox, Rot};
use crate::grammar::Dir;

/// Layers into the model, from a slope's open face, in which the mesh must
/// slant the slope's way: a brick's height.
const SLANT_DEPTH: i32 = 2;

/// One brick swapped for slopes (and a shorter brick).
#[derive(Debug, Clone)]
pub(crate) struct Swap {
    /// The brick taken out.
    brick: u32,
    /// The pieces laid in its place.
    laid: std::ops::Range<u32>,
    /// How many of them are slopes.
    pub slopes: usize,
}

/// The four horizontal directions a step can fall.
const DIRS: [(i32, i32); 4] = [(1, 0), (-1, 0), (0, 1), (0, -1)];

impl Layout<'_> {
    /// Caps stair edges with slopes (on top) and inverted slopes
    /// (underneath) where the alphabet has them; returns the swaps made.
    pub fn cap_stairs(&mut self) -> Vec<Swap> {
        let has = |s: Shape| self.shapes.iter().any(|p| p.part.spec().shape == s);
        let (top, under) = (has(Shape::Slope), has(Shape::Inverted));
        let mut swaps = Vec::new();
        if !top && !under {
            return swaps;
        }
        // Half-brick layers only: bricks two layers tall.
        let bricks: Vec<u32> = (0..self.pieces.len() as u32)
            .filter(|&id| {
                let p = &self.pieces[id as usize];
                !p.gone
                    && p.group.is_none()
                    && p.placement.part.spec().shape == Shape::Rect
                    && p.body.bbox.sz == 2
            })
            .collect();
        let mut laid = 0;
        // Roofs from the eaves up: a slope's front row may lie on the back
        // row of the slope capped just below it. Underneath, from the top
        // down.
        for (kind, wanted) in [(Shape::Slope, top), (Shape::Inverted, under)] {
            if !wanted {
                continue;
            }
            let mut order = bricks.clone();
            order.sort_by_key(|&id| {
                let z = self.pieces[id as usize].body.bbox.min.z;
                (if kind == Shape::Slope { z } else { -z }, id)
            });
            for id in order {
                if self.pieces[id as usize].gone {
                    continue;
                }
                let first = self.pieces.len() as u32;
                if let Some(k) = self.cap_piece(id, kind) {
                    laid += k;
                    swaps.push(Swap {
                        brick: id,
                        laid: first..self.pieces.len() as u32,
                        slopes: k,
                    });
                }
            }
        }
        if laid > 0 {
            self.rebuild_bodies();
        }
        swaps
    }

    /// Undoes `swaps` (the bricks back, the slopes out), last first.
    pub fn uncap(&mut self, swaps: &[Swap]) {
        for s in swaps.iter().rev() {
            for id in s.laid.clone() {
                self.remove(id);
            }
            self.restore(s.brick);
        }
        if !swaps.is_empty() {
            self.rebuild_bodies();
        }
    }

    /// Swaps the row of piece `id` along its side that falls most for
    /// slopes of `kind`; the slopes laid, or `None` when no side fits.
    fn cap_piece(&mut self, id: u32, kind: Shape) -> Option<usize> {
        let p = self.pieces[id as usize];
        let b = p.body.bbox;
        let up = kind == Shape::Slope;
        // The sides with nothing over their row (under it, underneath), by
        // how many columns beside them step by a brick.
        let mut sides: Vec<(usize, (i32, i32))> = DIRS
            .iter()
            .filter(|&&d| self.side_bare(&b, d, up))
            .map(|&d| (self.side_steps(&b, d, up), d))
            .filter(|&(k, _)| k > 0)
            .collect();
        sides.sort_by_key(|&(k, d)| (std::cmp::Reverse(k), d));
        for (_, d) in sides {
            if let Some(k) = self.swap_side(id, d, kind) {
                return Some(k);
            }
        }
        None
    }

    /// Whether nothing lies on the row of `b` along its side facing `d`
    /// (under it, underneath when `up` is false), nor is any voxel of the
    /// model left there uncovered.
    fn side_bare(&self, b: &CellBox, d: (i32, i32), up: bool) -> bool {
        let dz = if up { b.sz } else { -1 };
        self.side_cells(b, d).all(|a| {
            let q = a.offset(0, 0, dz);
            !self.must.in_bounds(q) || (self.owner_of(q).is_none() && !self.must.get(q))
        })
    }

    /// How many columns of the side of `b` facing `d` have a neighbour
    /// beyond it that steps a brick (two layers) down, with room for a
    /// slope's front row on it: on top, the neighbour's cells in `b`'s two
    /// layers are free and a piece is under them; underneath (`up` false),
    /// the same upside down.
    fn side_steps(&self, b: &CellBox, d: (i32, i32), up: bool) -> usize {
        self.side_cells(b, d)
            .filter(|&a| {
                let n = a.offset(d.0, d.1, 0);
                if up {
                    // Front row at the brick's bottom layer, open above,
                    // resting on a piece.
                    let f = Cell::new(n.x, n.y, b.min.z);
                    self.free_cell(f)
                        && self.clear_column(f, 1)
                        && self.owner_of(f.offset(0, 0, -1)).is_some()
                } else {
                    // Front row at the brick's top layer, open below,
                    // holding a piece above.
                    let f = Cell::new(n.x, n.y, b.min.z + b.sz - 1);
                    self.free_cell(f)
                        && self.clear_column(f, -1)
                        && self.owner_of(f.offset(0, 0, 1)).is_some()
                }
            })
            .count()
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
            if !self.free_cell(q) || self.must.get(q) {
                return false;
            }
            q = q.offset(0, 0, dz);
        }
        true
    }

    /// A cell in the grid, owned by no piece and not kept empty.
    fn free_cell(&self, c: Cell) -> bool {
        self.must.in_bounds(c) && self.owner_of(c).is_none() && !self.kept_empty(c)
    }

    /// Takes piece `id` out and lays, in its place, slopes of `kind` along
    /// its side facing `d` (back rows on that side, front rows beyond it)
    /// and a shorter brick for the rest of it; puts it back if any part
    /// does not fit or joins nothing through a rule. Returns the slopes
    /// laid.
    fn swap_side(&mut self, id: u32, d: (i32, i32), kind: Shape) -> Option<usize> {
        let p = self.pieces[id as usize];
        let b = p.body.bbox;
        let side: Vec<Cell> = self.side_cells(&b, d).collect();
        let width = side.len() as i32;
        // The rest of the brick: its footprint less the side row.
        let rest = match d {
            (1, 0) => (b.sx > 1).then(|| CellBox { sx: b.sx - 1, ..b }),
            (-1, 0) => (b.sx > 1).then(|| CellBox {
                min: b.min.offset(1, 0, 0),
                sx: b.sx - 1,
                ..b
            }),
            (0, 1) => (b.sy > 1).then(|| CellBox { sy: b.sy - 1, ..b }),
            _ => (b.sy > 1).then(|| CellBox {
                min: b.min.offset(0, 1, 0),
                sy: b.sy - 1,
                ..b
            }),
        };
        // A 1x1 left over would only trade a brick for the smallest piece.
        let rest_piece = match rest {
            Some(r) if r.sx * r.sy == 1 => return None,
            Some(r) => Some(self.brick_for(&r)?),
            None => None,
        };
        // Slopes along the side, longest first.
        let along = side[0];
        let step = if d.0 != 0 { (0, 1) } else { (1, 0) };
        let mut plan: Vec<(Placement, Body)> = Vec::new();
        let mut at = 0;
        while at < width {
            let left = width - at;
            let start = along.offset(step.0 * at, step.1 * at, 0);
            let (w, placed) = self.slope_for(start, step, left, d, kind, &b)?;
            plan.push(placed);
            at += w;
        }
        self.remove(id);
        let all: Vec<(Placement, Body)> = plan.iter().copied().chain(rest_piece).collect();
        // What rested on the brick rests on what is left of it.
        let held = rest_piece.is_none_or(|(pl, body)| {
            self.above(&body).into_iter().all(|o| {
                let a = &self.pieces[o as usize].placement;
                self.book.joint(&pl, a, Dir::Up, self.layer_ldu).is_some()
                    || self.book.joint(a, &pl, Dir::Down, self.layer_ldu).is_some()
            })
        });
        if !held || !all.iter().all(|(pl, body)| self.swap_fits(pl, body)) {
            self.restore(id);
            return None;
        }
        for (placement, body) in all {
            self.repairs.extra_cells += body.cells().filter(|&q| !self.must.get(q)).count();
            self.place(placement, body, None);
        }
        Some(plan.len())
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

    /// The widest 45° slope of `kind` (two rows deep) of the alphabet, at
    /// most `left` studs wide, whose back row starts at `start` and runs
    /// `step`-wise, facing `d`, in the layers of `b`; its width and
    /// placement.
    fn slope_for(
        &self,
        start: Cell,
        step: (i32, i32),
        left: i32,
        d: (i32, i32),
        kind: Shape,
        b: &CellBox,
    ) -> Option<(i32, (Placement, Body))> {
        let mut best: Option<(i32, PartKind, Rot)> = None;
        for s in &self.shapes {
            let spec = s.part.spec();
            if spec.shape != kind || spec.studs_y != 2 || spec.back(s.rot) != (-d.0, -d.1) {
                continue;
            }
            let w = spec.studs_x as i32;
            if w <= left && best.is_none_or(|(bw, _, _)| w > bw) {
                best = Some((w, s.part, s.rot));
            }
        }
        let (w, part, rot) = best?;
        // The slope's box: the back row along the side, the front row one
        // stud beyond it.
        let end = start.offset(step.0 * (w - 1), step.1 * (w - 1), 0);
        let front = (start.offset(d.0, d.1, 0), end.offset(d.0, d.1, 0));
        let min = Cell::new(
            start.x.min(end.x).min(front.0.x).min(front.1.x),
            start.y.min(end.y).min(front.0.y).min(front.1.y),
            b.min.z,
        );
        let body = part.body(rot, min, self.layer_ldu);
        Some((w, (Placement::new(part, min, rot), body)))
    }
}
