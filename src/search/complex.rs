//! Complex rules in the layout: several pieces at once where several are
//! in place (the paper's Figure 4).
//!
//! Once every [`SearchOptions::complex_every`](super::SearchOptions) nodes
//! the layout picks one complex rule variant with equal probability and
//! tests it over the voxel to cover next, before scoring the basic rules'
//! pieces; it applies when its `u` pieces are laid exactly as the rule has
//! them and its new pieces fit. Its new pieces are one node; the
//! derivation adds them together.

use super::layout::{Group, Layout, Reach};
use crate::assembly::Placement;
use crate::geom::{Body, Cell};

impl Layout<'_> {
    /// Tests complex variant `variant` with one of its new pieces over
    /// `c`: it applies when every `u` piece is laid as the rule has it and
    /// every new piece fits among the model's voxels and cells the surface
    /// passes through, stud-connected as the rule says.
    pub(super) fn try_complex(&mut self, variant: u32, c: Cell) -> Option<usize> {
        let var = &self.rules.complex_variants()[variant as usize];
        let u = self.layer_ldu;
        // Every way a new piece's bottom layer covers `c`.
        let origins: Vec<Cell> = var
            .v
            .iter()
            .flat_map(|n| {
                let b = n.piece.body(Cell::new(0, 0, 0), u);
                let z0 = b.bbox.min.z;
                b.cells()
                    .filter(move |k| k.z == z0)
                    .map(move |k| c.offset(-k.x, -k.y, -k.z))
                    .collect::<Vec<_>>()
            })
            .collect();
        for origin in origins {
            let place = |p: &crate::grammar::complex::VariantPiece| {
                let pl = Placement::new(p.part, origin.offset(p.at.x, p.at.y, p.at.z), p.rot);
                (pl, pl.body(u))
            };
            // Every `u` piece laid exactly there.
            let mut olds = Vec::with_capacity(var.u.len());
            for p in &var.u {
                let (pl, b) = place(p);
                match self.owner_of(b.key()) {
                    Some(o) if self.pieces[o as usize].placement == pl => olds.push(o),
                    _ => break,
                }
            }
            if olds.len() < var.u.len() {
                continue;
            }
            // Every new piece fits, over voxels of the model mostly, none
            // of them overlapping another.
            let news: Vec<(Placement, Body)> = var.v.iter().map(|n| place(&n.piece)).collect();
            let overlap = news
                .iter()
                .enumerate()
                .any(|(i, (_, a))| news[..i].iter().any(|(_, b)| a.bbox.intersects(&b.bbox)));
            // Every piece on a course's start (see [`super::layout::phase`]).
            if overlap
                || news
                    .iter()
                    .any(|(pl, _)| pl.origin.z.rem_euclid(self.phase) != 0)
            {
                continue;
            }
            let ok = news.iter().all(|(pl, b)| {
                self.fits(pl, b, Reach::Near)
                    .is_some_and(|(inside, near, _)| inside > 0 && inside >= 2 * near)
            });
            if !ok {
                continue;
            }
            let g = self.groups.len() as u32;
            let cells: usize = news.iter().map(|(_, b)| b.volume() as usize).sum();
            let mut ids = Vec::with_capacity(news.len());
            for (pl, b) in news {
                let extra = self.fits(&pl, &b, Reach::Near).map_or(0, |(_, n, _)| n);
                self.repairs.extra_cells += extra;
                ids.push(self.place(pl, b, Some(g)));
            }
            self.groups.push(Group {
                variant,
                u: olds,
                v: ids,
            });
            return Some(cells);
        }
        None
    }
}
