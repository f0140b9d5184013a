//! Complex rules applied in reverse, for the backward tracing.
//!
//! A complex rule `u -> v` matches where every piece of `u` and `v` lies in
//! the voxels left, consistent with the pieces matched so far. Applied in
//! reverse it is one node: the pieces of `u` are committed (they stay, to
//! be peeled later, so they come earlier in the build), and the new pieces
//! are peeled last added first, each with the piece the rule connects it to
//! as its anchor, each checked to be placeable with the pieces added before
//! it still standing.

use super::state::{Anchor, Change, State};
use crate::assembly::Placement;
use crate::geom::{Body, Cell, CellBox};
use crate::grammar::complex::VariantPiece;
use crate::grammar::{ComplexVariant, Link, RuleRef, RuleSet};

/// A structural match of a complex variant in the voxels left.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Reverse {
    /// Index of the variant in [`RuleSet::complex_variants`].
    pub variant: u32,
    /// Where the variant's first `u` piece's minimum corner is.
    pub origin: Cell,
    /// The box holding every new piece.
    pub bbox: CellBox,
    /// The box holding every `u` piece.
    pub u_bbox: CellBox,
    /// Whether some piece of the match is committed already.
    pub committed: bool,
}

fn place(p: &VariantPiece, origin: Cell, layer_ldu: i32) -> (Placement, Body) {
    let pl = Placement::new(p.part, origin.offset(p.at.x, p.at.y, p.at.z), p.rot);
    (pl, pl.body(layer_ldu))
}

fn union(boxes: impl Iterator<Item = CellBox>) -> CellBox {
    boxes.reduce(|a, b| a.union(&b)).expect("a piece")
}

/// The variant `variant` placed so that its new piece `j` has its key cell
/// (see [`Body::key`]) at `cell`, if every piece lies in the voxels left
/// with its sloping face clear and is uncommitted or exactly a committed
/// piece.
pub(crate) fn match_at(
    st: &State,
    rules: &RuleSet,
    variant: u32,
    j: usize,
    cell: Cell,
) -> Option<Reverse> {
    let var = &rules.complex_variants()[variant as usize];
    let u = st.layer_ldu;
    let key = var.v[j].piece.body(Cell::new(0, 0, 0), u).key();
    let origin = cell.offset(-key.x, -key.y, -key.z);
    let mut committed = false;
    let pieces = var.v.iter().map(|n| &n.piece).chain(&var.u);
    for p in pieces {
        let (pl, b) = place(p, origin, u);
        if !st.v.all_set_body(&b) || !st.face_clear(&pl, &b) {
            return None;
        }
        committed |= st.commitment(&b, &pl)?.is_some();
    }
    Some(Reverse {
        variant,
        origin,
        bbox: union(var.v.iter().map(|n| place(&n.piece, origin, u).1.bbox)),
        u_bbox: union(var.u.iter().map(|p| place(p, origin, u).1.bbox)),
        committed,
    })
}

/// Whether a new piece of the match stud-connects to a piece matched
/// earlier or to the structure built before.
pub(crate) fn touches_matched(st: &State, rules: &RuleSet, m: &Reverse) -> bool {
    let var = &rules.complex_variants()[m.variant as usize];
    var.v
        .iter()
        .any(|n| st.touches_matched(&place(&n.piece, m.origin, st.layer_ldu).1))
}

/// Applies the match in reverse. With `check`, each new piece must be
/// placeable once peeled; if one is not, the state is restored and `None`
/// returned.
pub(crate) fn apply(st: &mut State, rules: &RuleSet, m: &Reverse, check: bool) -> Option<Change> {
    let var: &ComplexVariant = &rules.complex_variants()[m.variant as usize];
    let u = st.layer_ldu;
    let mut ch = Change::default();
    let olds: Vec<(Placement, Body)> = var.u.iter().map(|p| place(p, m.origin, u)).collect();
    for (p, b) in &olds {
        match st.commitment(b, p) {
            Some(None) => ch.commits.push(st.commit(*p, b)),
            Some(Some(_)) => {}
            None => {
                st.undo_change(&ch);
                return None;
            }
        }
    }
    let news: Vec<(Placement, Body)> = var.v.iter().map(|n| place(&n.piece, m.origin, u)).collect();
    let rule = Some(RuleRef::Complex(var.rule));
    for (n, (p, b)) in var.v.iter().zip(&news).rev() {
        let (ap, ab) = match n.anchor {
            Link::U(k) => olds[k],
            Link::V(k) => news[k],
        };
        let (Some(was), Some(a_id)) = (st.commitment(b, p), st.commitment(&ab, &ap)) else {
            st.undo_change(&ch);
            return None;
        };
        let r = st.apply(*p, b, was, Anchor::Piece(ap), Some((&ab, a_id)), rule);
        ch.removals.push(r);
        if check && !st.placeable(b) {
            st.undo_change(&ch);
            return None;
        }
    }
    Some(ch)
}

#[cfg(test)]
mod tests {
    use super::super::dfs::{PartResult, PartSearch};
    use super::super::{build, placements, state, Dice, Removal, SearchOptions, SearchStats};
    use super::*;
    use crate::assembly::verify::verify;
    use crate::assembly::Assembly;
    use crate::catalog::Color;
    use crate::geom::{Cell, CellBox};
    use crate::grammar::{default_rules_text, RuleRef};
    use crate::voxel::VoxelGrid;
    use std::path::Path;
    use std::time::{Duration, Instant};

    const BOND: &str = "complex bond\n u 3001 r0 0 0 0\n v 3001 r0 -2 0 3\n v 3001 r0 2 0 3\n";

    /// The default bricks with only the complex rules of `complex`.
    fn bricks_with(complex: &str) -> RuleSet {
        RuleSet::parse(&default_rules_text(), "default.rules".as_ref())
            .unwrap()
            .restricted(|p| p.spec().family() == crate::catalog::Family::Brick)
            .unwrap()
            .with_complex(vec![])
            .unwrap()
            .with_complex_text(complex, Path::new("c.rules"))
            .unwrap()
    }

    fn grid(dims: (i32, i32, i32), boxes: &[(i32, i32, i32, i32, i32, i32)]) -> VoxelGrid {
        let mut g = VoxelGrid::new(dims.0, dims.1, dims.2);
        for &(x, y, z, sx, sy, sz) in boxes {
            let b = CellBox {
                min: Cell::new(x, y, z),
                sx,
                sy,
                sz,
            };
            g.set_box(&b, true);
        }
        g
    }

    fn complex_pieces(order: &[Removal]) -> usize {
        order
            .iter()
            .filter(|r| matches!(r.rule, Some(RuleRef::Complex(_))))
            .count()
    }

    /// A 2x4 under the middle of a wider slab: running bond fits exactly,
    /// and forward growth (every build's bottom part) applies it; the build
    /// verifies.
    #[test]
    fn forward_growth_applies_a_complex_rule() {
        let g = grid((8, 2, 3), &[(2, 0, 0, 4, 2, 1), (0, 0, 1, 8, 2, 2)]);
        let rules = bricks_with(BOND);
        let opts = SearchOptions::default().with_complex_every(1);
        let out = build(&g, &rules, &opts).unwrap();
        assert!(out.stats.complex_tried > 0);
        assert_eq!(out.stats.complex_applied, 1, "{:?}", out.stats);
        // The two new pieces come one after the other, each held by the
        // 2x4 of u, the first piece of the build.
        assert_eq!(complex_pieces(&out.order), 2);
        let first = out.order[0].piece;
        let news: Vec<&Removal> = out
            .order
            .iter()
            .filter(|r| matches!(r.rule, Some(RuleRef::Complex(_))))
            .collect();
        assert!(news.iter().all(|r| r.anchor == Anchor::Piece(first)));
        let asm = Assembly::from_order(&placements(&out), rules.layer_ldu(), Color::RED);
        let report = verify(&asm, Some(&out.voxels));
        assert!(report.is_ok(), "{report}");
        // Never tried with k = 0.
        let off = build(&g, &rules, &opts.clone().with_complex_every(0)).unwrap();
        assert_eq!((off.stats.complex_tried, off.stats.complex_applied), (0, 0));
        assert_eq!(complex_pieces(&off.order), 0);
    }

    /// The same slab on a built base: the backward tracing matches the
    /// rule in the voxels and peels both new pieces as one node, last
    /// added first, with the 2x4 under them committed and peeled after.
    #[test]
    fn backward_tracing_applies_a_complex_rule() {
        let g = grid((8, 2, 3), &[(2, 0, 1, 4, 2, 1), (0, 0, 2, 8, 2, 1)]);
        let built = grid((8, 2, 3), &[(0, 0, 0, 8, 2, 1)]);
        let rules = bricks_with(BOND);
        let opts = SearchOptions::default().with_complex_every(1);
        let search = PartSearch::new(&rules, &opts, Instant::now() + Duration::from_secs(60));
        let mut stats = SearchStats::default();
        let mut rng = Dice::new(1);
        let solid = {
            let mut s = g.clone();
            s.set_box(
                &CellBox {
                    min: Cell::new(0, 0, 0),
                    sx: 8,
                    sy: 2,
                    sz: 1,
                },
                true,
            );
            s
        };
        let PartResult::Built(trace) = search.run(
            g.clone(),
            &built,
            state::Model {
                solid: &solid,
                slant: None,
                studs: &built,
                tubes: &built,
            },
            1000,
            &mut rng,
            &mut stats,
        ) else {
            panic!("not built: {stats:?}");
        };
        assert!(stats.complex_applied >= 1, "{stats:?}");
        assert_eq!(stats.backtracks, 0);
        // Peeled in reverse: the second new piece before the first.
        let k = trace
            .iter()
            .position(|r| matches!(r.rule, Some(RuleRef::Complex(_))))
            .unwrap();
        let (second, first) = (trace[k].piece, trace[k + 1].piece);
        assert_eq!(trace[k + 1].rule, trace[k].rule);
        assert_eq!(second.origin.x, first.origin.x + 4);
        // Every voxel is covered once, and the build order verifies on the
        // base.
        let covered: i32 = trace.iter().map(|r| r.piece.body(24).volume()).sum();
        assert_eq!(covered as usize, g.count());
        let base = crate::assembly::Placement::new(
            crate::catalog::PartKind::from_id("3008").unwrap(),
            Cell::new(0, 0, 0),
            crate::geom::Rot::R0,
        );
        let mut order = vec![base];
        order.extend(trace.iter().rev().map(|r| r.piece));
        let asm = Assembly::from_order(&order, 24, Color::RED);
        let report = verify(&asm, None);
        assert!(report.is_ok(), "{report}");
    }

    /// With complex rules tested at every node, the same seed still gives
    /// the same build, and the build verifies.
    #[test]
    fn complex_rules_keep_builds_deterministic() {
        let g = grid((16, 12, 6), &[(0, 0, 0, 16, 12, 6)]);
        let rules = bricks_with(crate::grammar::COMPLEX_RULES);
        let opts = SearchOptions::default()
            .with_complex_every(1)
            .with_time_budget(Duration::from_secs(60));
        let a = build(&g, &rules, &opts).unwrap();
        let b = build(&g, &rules, &opts).unwrap();
        assert!(a.stats.complex_applied > 0, "{:?}", a.stats);
        assert_eq!(placements(&a), placements(&b));
        assert_eq!(
            a.order.iter().map(|r| r.rule).collect::<Vec<_>>(),
            b.order.iter().map(|r| r.rule).collect::<Vec<_>>()
        );
        let asm = Assembly::from_order(&placements(&a), 24, Color::RED);
        let report = verify(&asm, Some(&a.voxels));
        assert!(report.is_ok(), "{report}");
    }

    /// Complex rules are picked from a stream of their own: where none
    /// applies (no 2x4 fits a tower three studs wide), testing them changes
    /// nothing.
    #[test]
    fn complex_rules_that_never_apply_change_nothing() {
        let g = grid((3, 3, 6), &[(0, 0, 0, 3, 3, 6)]);
        let rules = bricks_with(crate::grammar::COMPLEX_RULES);
        let on = build(&g, &rules, &SearchOptions::default().with_complex_every(1)).unwrap();
        let off = build(&g, &rules, &SearchOptions::default().with_complex_every(0)).unwrap();
        assert!(on.stats.complex_tried > 0);
        assert_eq!(on.stats.complex_applied, 0);
        assert_eq!(placements(&on), placements(&off));
    }
}
