//! The derivation: the laid pieces as a sequence of rule applications.
//!
//! The layout decides where pieces go; the derivation decides the order in
//! which the rules add them, so that replayed from the start it is a
//! derivation of the rewriting system: a starting rule puts a piece on the
//! ground (as a person starts each foot of a model on the table), and every
//! other piece is added by a rule of the file to a piece already there, on
//! top of it or underneath it (a complex rule adds its pieces together,
//! once its `u` pieces are there). Pieces are taken lowest course first, in
//! the order they were laid, as soon as a rule joins them: a piece hanging
//! under an overhang comes right after the piece it hangs from, and every
//! piece goes in from above or from below, never into a gap between pieces.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::layout::Layout;
use super::{Anchor, Removal};
use crate::geom::{Cell, CellBox};
use crate::grammar::{Dir, Link, RuleId, RuleRef};
use crate::voxel::VoxelGrid;

/// The derivation of the laid pieces, and the pieces it cannot reach (no
/// rule joins them to the rest, or no starting rule fits the ground).
pub(crate) fn derive(l: &Layout) -> (Vec<Removal>, Vec<u32>) {
    let n = l.pieces.len();
    let alive = |i: usize| !l.pieces[i].gone;
    // Stud joints: (lower, upper).
    let mut adj: Vec<Vec<(u32, bool)>> = vec![Vec::new(); n];
    for i in 0..n {
        if !alive(i) {
            continue;
        }
        for o in l.below(&l.pieces[i].body) {
            adj[i].push((o, true));
            adj[o as usize].push((i as u32, false));
        }
    }
    let u = l.layer_ldu;
    // The rule adding piece `new` to piece `old` in place.
    let rule = |old: u32, new: u32, old_is_lower: bool| -> Option<(f64, RuleId)> {
        let (a, b) = (
            &l.pieces[old as usize].placement,
            &l.pieces[new as usize].placement,
        );
        let dir = if old_is_lower { Dir::Up } else { Dir::Down };
        l.book.joint(a, b, dir, u)
    };
    let z = |i: usize| l.pieces[i].body.bbox.min.z;
    let ground = (0..n).filter(|&i| alive(i)).map(z).min().unwrap_or(0);
    let mut order: Vec<Removal> = Vec::with_capacity(n);
    let mut placed = vec![false; n];
    let mut queued = vec![false; n];
    let mut heap: BinaryHeap<Reverse<(i32, u32)>> = BinaryHeap::new();
    // Every piece on the ground a starting rule can put down.
    let starts =
        |i: usize| alive(i) && z(i) == ground && l.rules.can_start(l.pieces[i].placement.part);
    for i in (0..n).filter(|&i| starts(i)) {
        queued[i] = true;
        heap.push(Reverse((z(i), i as u32)));
    }
    let settle = |i: usize,
                  removal: Removal,
                  order: &mut Vec<Removal>,
                  placed: &mut Vec<bool>,
                  queued: &mut Vec<bool>,
                  heap: &mut BinaryHeap<Reverse<(i32, u32)>>| {
        order.push(removal);
        placed[i] = true;
        for &(j, j_lower) in &adj[i] {
            let j = j as usize;
            if !placed[j] && !queued[j] && rule(i as u32, j as u32, !j_lower).is_some() {
                queued[j] = true;
                heap.push(Reverse((z(j), j as u32)));
            }
        }
    };
    // What is in place, for the straight-in check.
    let (nx, ny, nz) = l.must.dims();
    let mut occ = VoxelGrid::new(nx, ny, nz);
    let mut rescued = vec![false; n];
    let mut stack: Vec<usize> = Vec::new();
    while let Some(Reverse((_, j))) = heap.pop() {
        stack.push(j as usize);
        while let Some(j) = stack.pop() {
            if placed[j] {
                continue;
            }
            // Pieces in the same column that go in straight now but would
            // be shut in by this one: they go first.
            let bj = l.pieces[j].body.bbox;
            let rescue: Vec<usize> = column(l, &bj)
                .into_iter()
                .filter(|&y| {
                    queued[y]
                        && !placed[y]
                        && !rescued[y]
                        && straight_in(&l.pieces[y].body.bbox, &occ, None)
                        && !straight_in(&l.pieces[y].body.bbox, &occ, Some(&bj))
                })
                .collect();
            if !rescue.is_empty() {
                stack.push(j);
                for y in rescue {
                    rescued[y] = true;
                    stack.push(y);
                }
                continue;
            }
            // A complex rule's pieces go in together, once its `u` is there.
            if let Some(g) = l.pieces[j].group {
                let group = &l.groups[g as usize];
                if !group.v.is_empty()
                    && group.u.iter().all(|&k| placed[k as usize])
                    && group.v.iter().all(|&k| !placed[k as usize])
                {
                    let var = &l.rules.complex_variants()[group.variant as usize];
                    for (k, new) in var.v.iter().enumerate() {
                        let id = group.v[k] as usize;
                        let anchor = match new.anchor {
                            Link::U(a) => group.u[a],
                            Link::V(a) => group.v[a],
                        };
                        let r = Removal::forward(
                            l.pieces[id].placement,
                            Anchor::Piece(l.pieces[anchor as usize].placement),
                            Some(RuleRef::Complex(var.rule)),
                        );
                        occ.set_box(&l.pieces[id].body.bbox, true);
                        settle(id, r, &mut order, &mut placed, &mut queued, &mut heap);
                    }
                    continue;
                }
            }
            // The heaviest rule joining it to a piece in place.
            let best = adj[j]
                .iter()
                .filter(|(o, _)| placed[*o as usize])
                .filter_map(|&(o, o_lower)| rule(o, j as u32, o_lower).map(|r| (o, r)))
                .max_by(|a, b| a.1 .0.total_cmp(&b.1 .0).then(b.0.cmp(&a.0)));
            let r = match best {
                Some((anchor, (_, id))) => Removal::forward(
                    l.pieces[j].placement,
                    Anchor::Piece(l.pieces[anchor as usize].placement),
                    Some(RuleRef::Basic(id)),
                ),
                None if starts(j) => Removal::new_start(l.pieces[j].placement),
                None => continue,
            };
            occ.set_box(&bj, true);
            settle(j, r, &mut order, &mut placed, &mut queued, &mut heap);
        }
    }
    let unreached = (0..n)
        .filter(|&i| alive(i) && !placed[i])
        .map(|i| i as u32)
        .collect();
    (order, unreached)
}

/// The pieces other than the one boxed in `b` with a cell in `b`'s
/// footprint, at any height.
fn column(l: &Layout, b: &CellBox) -> Vec<usize> {
    let (_, _, nz) = l.must.dims();
    let mut out: Vec<usize> = Vec::new();
    for y in b.min.y..b.min.y + b.sy {
        for x in b.min.x..b.min.x + b.sx {
            for z in 0..nz {
                if (b.min.z..b.min.z + b.sz).contains(&z) {
                    continue;
                }
                if let Some(o) = l.owner_of(Cell::new(x, y, z)) {
                    if !out.contains(&(o as usize)) {
                        out.push(o as usize);
                    }
                }
            }
        }
    }
    out
}

/// Whether the box `b` goes in straight from above or from below past
/// what is in place (`occ`, and `extra` if given): the verifier's fast path.
fn straight_in(b: &CellBox, occ: &VoxelGrid, extra: Option<&CellBox>) -> bool {
    let (_, _, nz) = occ.dims();
    let blocked = |z: i32| {
        (b.min.y..b.min.y + b.sy).any(|y| {
            (b.min.x..b.min.x + b.sx).any(|x| {
                let c = Cell::new(x, y, z);
                occ.get(c) || extra.is_some_and(|e| e.contains(c))
            })
        })
    };
    let up = (b.min.z + b.sz..nz).all(|z| !blocked(z));
    let down = (0..b.min.z).all(|z| !blocked(z));
    up || down
}
