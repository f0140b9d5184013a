//! Capping a line of bricks at once.
//!
//! Where the layout lays a roof's course of bricks across the run (a 2x8
//! from one side of the course to the other, the next course resting on
//! its middle), each brick shows a stud or two at its ends, and capping
//! it brick by brick costs a piece for every stair column or two: a slope
//! as wide as the brick and a shorter brick where it was. Taken together,
//! the bricks of such a line (side by side, in the same layers, with the
//! same ends) are one box; its rows along the two sides become rows of
//! slopes as long as the alphabet has, across the bricks' seams, and
//! what is left of each brick between them is laid as the fewest bricks,
//! across the run as before. The barn's course of thirteen bricks, 24
//! studs long and shown at both ends, becomes twelve 2x4 slopes and
//! thirteen 2x6 and 1x6 bricks: twelve pieces more for its 48 stair
//! columns, where brick by brick the budget ran out first.
//!
//! The bricks between stay across the run: laid along it (three 2x8s
//! where the six 2x6s were) they would take fewer pieces, but their long
//! seams run straight up through the courses (the barn's continued seams
//! went from 5% to 10%).
//!
//! A line's swap is kept on the same terms as a brick's (every piece fits
//! and joins a piece through the rules, the pieces the bricks joined still
//! meet through the new ones), and only if it caps at least [`LINE_YIELD`]
//! stair columns for each piece it adds.

use std::collections::HashSet;

use super::{Budget, Part, Swap};
use crate::catalog::Shape;
use crate::geom::{Cell, CellBox};
use crate::search::layout::Layout;

/// The stair columns a line's swap must cap for each piece it adds.
const LINE_YIELD: usize = 3;

/// A way to lay a line's box again: the stair columns its slopes cap, the
/// pieces, and how many of them are slopes.
type Plan = (usize, Vec<Part>, usize);

impl Layout<'_> {
    /// Swaps the line of bricks through brick `id` (two bricks at least)
    /// for slopes of `kind` along its stepped sides and bricks between
    /// them; the swap, or `None` (nothing changed) when no plan fits
    /// within `budget`. The bricks of a line that did not fit are marked
    /// in `tried` (with the line's way: `true` for the sides facing x),
    /// so that their line is not tried again.
    pub(super) fn cap_line(
        &mut self,
        id: u32,
        kind: Shape,
        budget: &mut Budget,
        tried: &mut HashSet<(u32, bool)>,
    ) -> Option<Swap> {
        let mut lines: Vec<(Vec<u32>, CellBox, bool)> = [true, false]
            .into_iter()
            .filter(|&across_x| !tried.contains(&(id, across_x)))
            .map(|across_x| {
                let (ids, r) = self.brick_line(id, across_x);
                (ids, r, across_x)
            })
            .filter(|(ids, _, _)| ids.len() >= 2)
            .collect();
        lines.sort_by_key(|(ids, _, across_x)| (std::cmp::Reverse(ids.len()), !across_x));
        for (ids, r, across_x) in lines {
            if let Some(swap) = self.swap_line(&ids, &r, across_x, kind, budget) {
                return Some(swap);
            }
            for &o in &ids {
                tried.insert((o, across_x));
            }
        }
        None
    }

    /// Whether piece `o` is a brick the cap pass may swap: rectangular,
    /// two layers tall, laid by itself.
    pub(super) fn cappable(&self, o: u32) -> bool {
        let p = &self.pieces[o as usize];
        !p.gone
            && p.group.is_none()
            && p.placement.part.spec().shape == Shape::Rect
            && p.body.bbox.sz == 2
    }

    /// The bricks in line with brick `id`: side by side along y when
    /// `across_x` (the line's sides face x), along x otherwise, each in the
    /// same layers and with the same ends as `id`; and their box.
    fn brick_line(&self, id: u32, across_x: bool) -> (Vec<u32>, CellBox) {
        let b = self.pieces[id as usize].body.bbox;
        let mut ids = vec![id];
        let mut whole = b;
        for forward in [false, true] {
            let mut cur = b;
            loop {
                let probe = match (across_x, forward) {
                    (true, false) => cur.min.offset(0, -1, 0),
                    (true, true) => cur.min.offset(0, cur.sy, 0),
                    (false, false) => cur.min.offset(-1, 0, 0),
                    (false, true) => cur.min.offset(cur.sx, 0, 0),
                };
                let Some(o) = self.owner_of(probe) else {
                    break;
                };
                let ob = self.pieces[o as usize].body.bbox;
                let same_ends = if across_x {
                    ob.min.x == b.min.x && ob.sx == b.sx
                } else {
                    ob.min.y == b.min.y && ob.sy == b.sy
                };
                if !self.cappable(o) || !same_ends || ob.min.z != b.min.z || ob.sz != b.sz {
                    break;
                }
                ids.push(o);
                cur = ob;
                let lo = Cell::new(
                    whole.min.x.min(ob.min.x),
                    whole.min.y.min(ob.min.y),
                    whole.min.z,
                );
                let hi = (
                    (whole.min.x + whole.sx).max(ob.min.x + ob.sx),
                    (whole.min.y + whole.sy).max(ob.min.y + ob.sy),
                );
                whole = CellBox {
                    min: lo,
                    sx: hi.0 - lo.x,
                    sy: hi.1 - lo.y,
                    sz: whole.sz,
                };
            }
        }
        (ids, whole)
    }

    /// Takes the bricks `ids` (box `r`) out and lays the plan for `r` that
    /// caps the most stair columns with the fewest pieces and fits; puts
    /// them back if none does.
    fn swap_line(
        &mut self,
        ids: &[u32],
        r: &CellBox,
        across_x: bool,
        kind: Shape,
        budget: &mut Budget,
    ) -> Option<Swap> {
        let boxes: Vec<CellBox> = ids
            .iter()
            .map(|&id| self.pieces[id as usize].body.bbox)
            .collect();
        let plans = self.line_plans(r, &boxes, across_x, kind);
        if plans.is_empty() {
            return None;
        }
        // The pieces the bricks joined, which the new ones must still join.
        let mut joined: Vec<u32> = Vec::new();
        for &id in ids {
            let body = self.pieces[id as usize].body;
            joined.extend(
                self.below(&body)
                    .into_iter()
                    .filter(|&o| self.joined_by_rule(o, id)),
            );
            joined.extend(
                self.above(&body)
                    .into_iter()
                    .filter(|&o| self.joined_by_rule(id, o)),
            );
        }
        joined.retain(|o| !ids.contains(o));
        joined.sort_unstable();
        joined.dedup();
        for &id in ids {
            self.remove(id);
        }
        for (steps, parts, slopes) in plans {
            let added = parts.len().saturating_sub(ids.len());
            if added > budget.pieces || steps < LINE_YIELD.max(budget.min_yield) * added {
                continue;
            }
            let fits = parts.iter().all(|(pl, body)| self.swap_fits(pl, body));
            if !fits || !self.still_joined(&parts, &joined) {
                continue;
            }
            budget.pieces -= added;
            let first = self.pieces.len() as u32;
            for (placement, body) in parts {
                self.repairs.extra_cells += body.cells().filter(|&q| !self.must.get(q)).count();
                self.place(placement, body, None);
            }
            return Some(Swap {
                taken: ids.to_vec(),
                laid: first..self.pieces.len() as u32,
                slopes,
            });
        }
        for &id in ids {
            self.restore(id);
        }
        None
    }

    /// The ways to lay box `r` again with slopes of `kind` along one or
    /// both of its sides facing x (`across_x`) or y that step down, and
    /// bricks between (see [`Layout::bricks_between`]): the most stair
    /// columns capped first, then the fewest pieces.
    fn line_plans(&self, r: &CellBox, boxes: &[CellBox], across_x: bool, kind: Shape) -> Vec<Plan> {
        let up = kind == Shape::Slope;
        let sides: [(i32, i32); 2] = if across_x {
            [(-1, 0), (1, 0)]
        } else {
            [(0, -1), (0, 1)]
        };
        // For each side: the slopes' depths it may take (0: none) and the
        // stair columns beside it.
        let options: Vec<(Vec<i32>, usize)> = sides
            .iter()
            .map(|&d| {
                let steps = if self.side_bare(r, d, up) {
                    self.side_steps(r, d, up)
                } else {
                    0
                };
                (if steps > 0 { vec![0, 2, 3] } else { vec![0] }, steps)
            })
            .collect();
        let depth = if across_x { r.sx } else { r.sy };
        let mut plans = Vec::new();
        for &a in &options[0].0 {
            for &b in &options[1].0 {
                let rows = |k: i32| (k - 1).max(0);
                if (a == 0 && b == 0) || rows(a) + rows(b) > depth {
                    continue;
                }
                let mut parts = Vec::new();
                let mut steps = 0;
                let mut ok = true;
                for (k, (&d, opt)) in [a, b].into_iter().zip(sides.iter().zip(&options)) {
                    if k == 0 {
                        continue;
                    }
                    let side: Vec<Cell> = self.side_cells(r, d).collect();
                    match self.slope_row(&side, d, kind, k) {
                        Some(row) => parts.extend(row),
                        None => ok = false,
                    }
                    steps += opt.1;
                }
                let slopes = parts.len();
                if !ok {
                    continue;
                }
                let middle = middle_box(r, across_x, rows(a), rows(b));
                let Some(m) = middle else {
                    plans.push((steps, parts, slopes));
                    continue;
                };
                if let Some(bricks) = self.bricks_between(&m, boxes) {
                    parts.extend(bricks);
                    plans.push((steps, parts, slopes));
                }
            }
        }
        plans.sort_by_key(|(steps, parts, _)| (std::cmp::Reverse(*steps), parts.len()));
        plans
    }

    /// Bricks filling box `m` as the line's bricks `boxes` did, each what
    /// is left of it in `m` laid as the fewest bricks.
    fn bricks_between(&self, m: &CellBox, boxes: &[CellBox]) -> Option<Vec<Part>> {
        let mut out = Vec::new();
        for b in boxes {
            let lo = Cell::new(b.min.x.max(m.min.x), b.min.y.max(m.min.y), b.min.z);
            let hi = (
                (b.min.x + b.sx).min(m.min.x + m.sx),
                (b.min.y + b.sy).min(m.min.y + m.sy),
            );
            let part = CellBox {
                min: lo,
                sx: hi.0 - lo.x,
                sy: hi.1 - lo.y,
                sz: b.sz,
            };
            out.extend(self.bricks_for(&part)?);
        }
        Some(out)
    }
}

/// What is left of box `r` when `low` rows on its low side and `high` on
/// its high side (along x when `across_x`) become slopes; `None` if
/// nothing is.
fn middle_box(r: &CellBox, across_x: bool, low: i32, high: i32) -> Option<CellBox> {
    let depth = if across_x { r.sx } else { r.sy };
    let left = depth - low - high;
    (left > 0).then(|| {
        if across_x {
            CellBox {
                min: r.min.offset(low, 0, 0),
                sx: left,
                ..*r
            }
        } else {
            CellBox {
                min: r.min.offset(0, low, 0),
                sy: left,
                ..*r
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_middle_of_a_line_is_what_the_slopes_leave() {
        let r = CellBox {
            min: Cell::new(4, 0, 14),
            sx: 8,
            sy: 24,
            sz: 2,
        };
        // A 45° row on each side (one row each): six rows between.
        assert_eq!(
            middle_box(&r, true, 1, 1),
            Some(CellBox {
                min: Cell::new(5, 0, 14),
                sx: 6,
                ..r
            })
        );
        // A 33° row on the low side (two rows), none on the high one.
        assert_eq!(
            middle_box(&r, true, 2, 0).map(|m| (m.min.x, m.sx)),
            Some((6, 6))
        );
        assert_eq!(middle_box(&r, true, 4, 4), None);
        assert_eq!(
            middle_box(&r, false, 1, 0).map(|m| (m.min.y, m.sy)),
            Some((1, 23))
        );
    }
}
