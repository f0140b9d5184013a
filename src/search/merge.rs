//! Merging neighbours: two pieces side by side in the same layers whose
//! union is a piece of the alphabet become that piece.
//!
//! The layout chooses piece by piece, and where every way of covering a
//! strip continues the same seams below, a short piece can score as well as
//! a long one. Merging afterwards never adds a seam (the merged piece covers
//! the same cells, with one seam fewer between them) and never removes a
//! connection (its studs and tubes cover both), so it only saves pieces.

use super::layout::Layout;
use crate::assembly::Placement;
use crate::catalog::Shape;
use crate::geom::CellBox;

/// Passes over the pieces before merging stops.
const ROUNDS: usize = 4;

impl Layout<'_> {
    /// Merges neighbouring pieces into bigger ones of the alphabet while
    /// any pair can, keeping every joint to the pieces around a rule of
    /// the file.
    pub fn merge(&mut self) {
        for _ in 0..ROUNDS {
            let mut merged = 0;
            for a in 0..self.pieces.len() as u32 {
                if self.pieces[a as usize].gone {
                    continue;
                }
                if self.merge_with_neighbour(a).is_some() {
                    merged += 1;
                }
            }
            self.stats.merges += merged;
            if merged == 0 {
                break;
            }
        }
        self.rebuild_bodies();
    }

    /// Merges piece `a` with its neighbour past its +x or +y side if their
    /// union is a piece of the alphabet; the neighbour merged, if any.
    pub(super) fn merge_with_neighbour(&mut self, a: u32) -> Option<u32> {
        let pa = self.pieces[a as usize];
        if pa.placement.part.spec().shape != Shape::Rect || pa.group.is_some() {
            return None;
        }
        let ba = pa.body.bbox;
        for (dx, dy) in [(ba.sx, 0), (0, ba.sy)] {
            let Some(b) = self.owner_of(ba.min.offset(dx, dy, 0)) else {
                continue;
            };
            let pb = self.pieces[b as usize];
            let bb = pb.body.bbox;
            if b == a || pb.placement.part.spec().shape != Shape::Rect || pb.group.is_some() {
                continue;
            }
            if !continues(&ba, &bb, dx > 0) {
                continue;
            }
            let union = CellBox {
                min: ba.min,
                sx: if dx > 0 { ba.sx + bb.sx } else { ba.sx },
                sy: if dy > 0 { ba.sy + bb.sy } else { ba.sy },
                sz: ba.sz,
            };
            let Some(shape) = self
                .shapes
                .iter()
                .find(|s| s.part.spec().shape == Shape::Rect && s.body_at(union.min).bbox == union)
                .cloned()
            else {
                continue;
            };
            let placement = Placement::new(shape.part, union.min, shape.rot);
            let body = shape.body_at(union.min);
            // The pieces the two join now: the merged piece must join each
            // through a rule.
            let around: Vec<(u32, bool)> = self
                .below(&pa.body)
                .into_iter()
                .chain(self.below(&pb.body))
                .map(|o| (o, true))
                .chain(
                    self.above(&pa.body)
                        .into_iter()
                        .chain(self.above(&pb.body))
                        .map(|o| (o, false)),
                )
                .collect();
            self.remove(a);
            self.remove(b);
            let colours_ok = self
                .fits(&placement, &body, super::layout::Reach::Far)
                .is_some();
            let rules_ok = around.iter().all(|&(o, lower)| {
                let other = &self.pieces[o as usize].placement;
                let u = self.layer_ldu;
                use crate::grammar::Dir;
                if lower {
                    self.book.joint(other, &placement, Dir::Up, u).is_some()
                        || self.book.joint(&placement, other, Dir::Down, u).is_some()
                } else {
                    self.book.joint(other, &placement, Dir::Down, u).is_some()
                        || self.book.joint(&placement, other, Dir::Up, u).is_some()
                }
            });
            if colours_ok && rules_ok {
                self.place(placement, body, None);
                return Some(b);
            }
            self.restore(a);
            self.restore(b);
        }
        None
    }
}

/// Whether box `b` continues box `a` (same layers, same width) right after
/// it along x (`along_x`) or along y: the two make one box.
pub(super) fn continues(a: &CellBox, b: &CellBox, along_x: bool) -> bool {
    b.min.z == a.min.z
        && b.sz == a.sz
        && if along_x {
            b.min.y == a.min.y && b.sy == a.sy && b.min.x == a.min.x + a.sx
        } else {
            b.min.x == a.min.x && b.sx == a.sx && b.min.y == a.min.y + a.sy
        }
}
