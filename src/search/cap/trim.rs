//! Rows outside the model trimmed off bricks and plates.
//!
//! The layout may fill cells the surface passes through, outside the
//! model, where a wider piece scores better than a narrower one (or joins
//! a thin feature). Where a whole side row of a brick or plate lies
//! outside the model with nothing over it, the row stands out of the
//! shape: on a roof, a course above the step it belongs to (the house at
//! 24 studs had five 2x8 bricks laid across the roof's run with their
//! ends on a step, nine columns of it standing a course high).
//!
//! Such a piece becomes what is left without the row: the piece of the
//! alphabet that fills it, or as few as do, none a 1x1 (a 2x8 less its
//! end is a 2x4 and a 2x3: at most [`TRIM_ADDED`] more); a 1x1 left of a
//! 1x2 only where it merges at once with a neighbour into a longer piece.
//! The pieces must fit as the layout's own candidates must, and the
//! pieces the trimmed one joined still meet through the rules (a row that
//! joins a thin feature stays). No voxel of the model is left uncovered:
//! only cells outside it are given up.

use super::Swap;
use crate::catalog::Shape;
use crate::geom::{Cell, CellBox};
use crate::search::layout::Layout;

/// The most pieces a trim may add.
const TRIM_ADDED: usize = 1;

impl Layout<'_> {
    /// Trims every side row outside the model, with nothing over it, off
    /// the bricks and plates (see the module docs); the swaps made (no
    /// slopes), to be undone with the others.
    pub(crate) fn trim_outside(&mut self) -> Vec<Swap> {
        let mut swaps = Vec::new();
        let mut undone = false;
        // Pieces laid here are looked at too: a piece may lose a row on
        // two sides.
        let mut id = 0;
        while id < self.pieces.len() as u32 {
            swaps.extend(self.trim_piece(id, &mut undone));
            id += 1;
        }
        if !swaps.is_empty() || undone {
            self.rebuild_bodies();
        }
        swaps
    }

    /// Trims a side row of piece `id` that lies wholly outside the model,
    /// if what is left fits and keeps the joints; the swaps made (none, or
    /// the trim and a merge). `undone` is set when a trim laid a piece and
    /// took it out again (the bodies are to be made again).
    fn trim_piece(&mut self, id: u32, undone: &mut bool) -> Vec<Swap> {
        let p = self.pieces[id as usize];
        if p.gone || p.group.is_some() || p.placement.part.spec().shape != Shape::Rect {
            return Vec::new();
        }
        let b = p.body.bbox;
        for d in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            let Some(Some(rest)) = super::rest_box(&b, d, 1) else {
                continue;
            };
            let row = || b.cells().filter(move |&q| !rest.contains(q));
            let top = b.min.z + b.sz - 1;
            let bare = |q: Cell| {
                let over = q.offset(0, 0, 1);
                !self.must.in_bounds(over)
                    || (!self.must.get(over) && self.owner_of(over).is_none())
            };
            if !row().all(|q| !self.must.get(q)) || !row().filter(|q| q.z == top).all(bare) {
                continue;
            }
            let single = rest.sx * rest.sy == 1;
            let new = if single {
                self.brick_for(&rest).map(|one| vec![one])
            } else {
                self.bricks_for(&rest)
            };
            let Some(new) = new.filter(|n| n.len() <= 1 + TRIM_ADDED) else {
                continue;
            };
            let joined = self.joined_with(id);
            self.remove(id);
            if !new.iter().all(|(pl, body)| self.swap_fits(pl, body))
                || !self.still_joined(&new, &joined)
            {
                self.restore(id);
                continue;
            }
            let first = self.pieces.len() as u32;
            for (placement, body) in new {
                self.place(placement, body, None);
            }
            let trim = Swap {
                taken: vec![id],
                laid: first..self.pieces.len() as u32,
                slopes: 0,
            };
            let mut swaps = vec![trim];
            if single {
                match self.merge_single(first, &rest) {
                    Some(merge) => swaps.push(merge),
                    None => {
                        self.remove(first);
                        self.restore(id);
                        *undone = true;
                        continue;
                    }
                }
            }
            let given_up = (b.volume() - rest.volume()) as usize;
            self.repairs.extra_cells = self.repairs.extra_cells.saturating_sub(given_up);
            return swaps;
        }
        Vec::new()
    }

    /// Merges the 1x1 piece `one` (filling `cell`) with a neighbour into a
    /// longer piece of the alphabet; the merge as a swap.
    fn merge_single(&mut self, one: u32, cell: &CellBox) -> Option<Swap> {
        let c = cell.min;
        // The merge takes a piece and its neighbour past its +x or +y side.
        let before = [c.offset(-1, 0, 0), c.offset(0, -1, 0)]
            .into_iter()
            .filter_map(|q| self.owner_of(q))
            .collect::<Vec<u32>>();
        for a in std::iter::once(one).chain(before) {
            let at = self.pieces.len() as u32;
            if let Some(b) = self.merge_with_neighbour(a) {
                if a == one || b == one {
                    return Some(Swap {
                        taken: vec![a, b],
                        laid: at..at + 1,
                        slopes: 0,
                    });
                }
                // Another pair merged: undone.
                self.remove(at);
                self.restore(b);
                self.restore(a);
            }
        }
        None
    }
}
