//! Corner slopes where two rows of slopes meet.
//!
//! A straight slope caps one side of a column. At the end of a row of
//! slopes, on a rounded top or at a hip, the column at the end of the
//! slope's back row steps down two ways: toward the slope's front, which
//! the slope caps, and past its end, which it cannot. There a corner slope
//! (3045, double convex; 3676 upside down, underneath) takes the end of
//! the slope: its full cell on the back row's end cell, its faces falling
//! to the front and past the end, its two low cells past the end lying on
//! the step below, as a slope's front row does. What is left of the slope
//! is laid as slopes of the alphabet, longest first. A slope one stud wide
//! becomes a corner slope with no piece added; a wider one adds a piece.
//!
//! Each swap keeps the build whole as the straight caps do (see the
//! [module docs](super)): every new piece fits where the layout's own
//! candidates must, joins a piece through the rules, and the pieces the
//! slope joined still meet through them; a swap that fails any of that is
//! undone. The swaps come out of the same budget as the straight caps.

use super::{Budget, Part, Swap};
use crate::assembly::Placement;
use crate::catalog::{PartKind, Shape};
use crate::geom::{Cell, CellBox, Rot};
use crate::search::layout::Layout;

impl Layout<'_> {
    /// Swaps the ends of the 45° slopes of `kind` (a slope, or an
    /// inverted slope underneath) whose back row's end column steps down
    /// past the end too for a corner slope and what is left of the slope;
    /// the swaps made.
    pub(super) fn cap_corners(&mut self, kind: Shape, budget: &mut Budget) -> Vec<Swap> {
        let corner = if kind == Shape::Slope {
            Shape::Corner
        } else {
            Shape::InvertedCorner
        };
        let Some(part) = self
            .shapes
            .iter()
            .map(|s| s.part)
            .find(|p| p.spec().shape == corner)
        else {
            return Vec::new();
        };
        let mut swaps = Vec::new();
        // The slopes laid for what is left are looked at too: a slope may
        // meet a step past either end.
        let mut id = 0;
        while id < self.pieces.len() as u32 {
            let p = self.pieces[id as usize];
            let spec = p.placement.part.spec();
            if !p.gone && p.group.is_none() && spec.shape == kind && spec.studs_y == 2 {
                let first = self.pieces.len() as u32;
                if let Some(slopes) = self.corner_swap(id, kind, part, budget) {
                    swaps.push(Swap {
                        taken: vec![id],
                        laid: first..self.pieces.len() as u32,
                        slopes,
                    });
                }
            }
            id += 1;
        }
        swaps
    }

    /// Swaps an end of slope `id` for corner slope `part` and slopes for
    /// the rest, if either end's column steps down past the end with room
    /// for the corner's low cells; the slopes laid.
    fn corner_swap(
        &mut self,
        id: u32,
        kind: Shape,
        part: PartKind,
        budget: &mut Budget,
    ) -> Option<usize> {
        let p = self.pieces[id as usize];
        let spec = p.placement.part.spec();
        let b = p.body.bbox;
        let back = spec.back(p.placement.rot);
        let front = (-back.0, -back.1);
        // The back row's cells in the slope's bottom layer, along its width.
        let along = if back.0 == 0 { (1, 0) } else { (0, 1) };
        let mut row: Vec<Cell> = b
            .cells()
            .filter(|c| c.z == b.min.z && !b.contains(c.offset(back.0, back.1, 0)))
            .collect();
        row.sort_by_key(|c| c.x * along.0 + c.y * along.1);
        let ends = [(row.first()?, (-along.0, -along.1)), (row.last()?, along)];
        for (&c, e) in ends {
            let Some(new) = self.plan_corner(&b, kind, part, c, front, e, &row) else {
                continue;
            };
            let added = new.len() - 1;
            if added > budget.per_swap || added > budget.pieces {
                continue;
            }
            let joined = self.joined_with(id);
            self.remove(id);
            let fits = new.iter().all(|(pl, body)| self.swap_fits(pl, body));
            if !fits || !self.still_joined(&new, &joined) {
                self.restore(id);
                continue;
            }
            budget.pieces -= added;
            let slopes = new.len();
            for (placement, body) in new {
                self.repairs.extra_cells += body.cells().filter(|&q| !self.must.get(q)).count();
                self.place(placement, body, None);
            }
            return Some(slopes);
        }
        None
    }

    /// The corner slope `part` on back row cell `c` of slope box `b`
    /// (facing `front`), falling past the end `e` too, and the slopes for
    /// the rest of `row` (the back row): `None` if the cells past the end
    /// are not free and open with a piece to lie on (hold, underneath), or
    /// the alphabet has no slopes for the rest.
    #[allow(clippy::too_many_arguments)]
    fn plan_corner(
        &self,
        b: &CellBox,
        kind: Shape,
        part: PartKind,
        c: Cell,
        front: (i32, i32),
        e: (i32, i32),
        row: &[Cell],
    ) -> Option<Vec<Part>> {
        let up = kind == Shape::Slope;
        // The corner's low cells past the end: in the slope's bottom layer
        // on top, its top layer underneath.
        let z = if up { b.min.z } else { b.min.z + b.sz - 1 };
        let past = [
            c.offset(e.0, e.1, 0),
            c.offset(e.0 + front.0, e.1 + front.1, 0),
        ];
        let dz = if up { -1 } else { 1 };
        let open = past.iter().all(|q| {
            let q = Cell::new(q.x, q.y, z);
            self.free(q) && self.clear_column(q, -dz)
        });
        let rests = past
            .iter()
            .any(|q| self.owner_of(Cell::new(q.x, q.y, z + dz)).is_some());
        if !open || !rests {
            return None;
        }
        // Turned so that its faces fall to the front and past the end
        // (the part is the same either way round).
        let spec = part.spec();
        let rot = Rot::ALL.into_iter().find(|&r| {
            let f: Vec<(i32, i32)> = spec.faces(r).collect();
            f.contains(&front) && f.contains(&e)
        })?;
        let cells = [c, c.offset(front.0, front.1, 0)].into_iter().chain(past);
        let min = cells.fold(Cell::new(i32::MAX, i32::MAX, b.min.z), |m, q| {
            Cell::new(m.x.min(q.x), m.y.min(q.y), b.min.z)
        });
        let body = part.body(rot, min, self.layer_ldu);
        let full = if up { body.studs.min } else { body.tubes.min };
        if (full.x, full.y) != (c.x, c.y) {
            return None;
        }
        let mut new: Vec<Part> = vec![(Placement::new(part, min, rot), body)];
        let rest: Vec<Cell> = row.iter().copied().filter(|&q| q != c).collect();
        if !rest.is_empty() {
            new.extend(self.slope_row(&rest, front, kind, 2)?);
        }
        Some(new)
    }
}
