//! Exploded views: where each piece moves so that every course shows.
//!
//! The paper's exploded view pushes each piece away from the model's centre
//! in proportion to its position. That spreads a tall model evenly, but a
//! course of bricks still hides the one below it when the push is small,
//! and a large push flings the pieces far apart sideways. This module keeps
//! the horizontal push modest and pulls the model apart **along the build
//! direction** instead:
//!
//! - **Levels.** Pieces are grouped by the height of their bottom face. In a
//!   model of bricks a level is a brick course; with slopes (half-brick
//!   layers) or plates there are more, finer levels. Level `k` rises by
//!   `off[k] = off[k-1] + max(gap, h_max - (b[k] - b[k-1]))` LDU, where `b`
//!   are the distinct bottom heights and `h_max` the tallest piece. The
//!   second term makes the rise at least as large as any overlap in height
//!   between a piece and one on a higher level, so the displaced pieces of
//!   two levels never intersect, even a slope and the brick resting on its
//!   sloped front whose bounding boxes overlap in the assembled model.
//! - **Spread.** Each piece moves horizontally by `spread` times the vector
//!   from the model's footprint centre to the piece's footprint centre.
//!   Two pieces whose boxes are apart along an axis keep their order along
//!   it and their gap only grows (the farther piece's centre is farther out),
//!   so pieces of one level do not collide either.
//!
//! Order is kept: a piece that sits lower than another in the model sits
//! lower in the exploded view. Offsets are a pure function of the assembly
//! (integer geometry, no randomness), in LDraw world LDU (-Y up), to be added
//! to each piece's translation from
//! [`piece_transform`](super::partmesh::piece_transform).
//!
//! ```
//! use brickwright::assembly::{Assembly, Placement};
//! use brickwright::catalog::{Color, PartKind};
//! use brickwright::export::explode::{explode, ExplodeOptions};
//! use brickwright::geom::{Cell, Rot};
//!
//! let brick = PartKind::from_id("3001").unwrap();
//! let order = [
//!     Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
//!     Placement::new(brick, Cell::new(0, 0, 1), Rot::R0),
//! ];
//! let asm = Assembly::from_order(&order, 24, Color::RED);
//! let off = explode(&asm, &ExplodeOptions::default());
//! // The upper course rises by the gap (LDraw's up is -Y).
//! assert_eq!(off[0].y, 0.0);
//! assert_eq!(off[1].y, -ExplodeOptions::default().level_gap_ldu);
//! ```

use glam::Vec3;

use crate::assembly::Assembly;
use crate::ldraw::LDU_PER_STUD;

/// How far an exploded view pulls the pieces apart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExplodeOptions {
    /// The least vertical gap in LDU between consecutive levels. Default
    /// 16 (two plates), enough to see into every course from above.
    pub level_gap_ldu: f32,
    /// Horizontal push as a fraction of each piece's distance from the
    /// model's centre. Default 0.2.
    pub spread: f32,
}

impl Default for ExplodeOptions {
    fn default() -> Self {
        ExplodeOptions {
            level_gap_ldu: 16.0,
            spread: 0.2,
        }
    }
}

impl ExplodeOptions {
    /// Sets [`ExplodeOptions::level_gap_ldu`] (negative values count as 0).
    pub fn with_level_gap_ldu(mut self, gap: f32) -> Self {
        self.level_gap_ldu = if gap.is_finite() { gap.max(0.0) } else { 0.0 };
        self
    }

    /// Sets [`ExplodeOptions::spread`] (negative values count as 0).
    pub fn with_spread(mut self, spread: f32) -> Self {
        self.spread = if spread.is_finite() {
            spread.max(0.0)
        } else {
            0.0
        };
        self
    }
}

/// The exploded-view offset of every piece, in assembly order, in LDraw
/// world LDU (-Y up).
pub fn explode(assembly: &Assembly, opts: &ExplodeOptions) -> Vec<Vec3> {
    let layer = i64::from(assembly.layer_ldu);
    let stud = i64::from(LDU_PER_STUD);
    // Footprint (x0, z0, x1, z1) and bottom height of each piece, in LDU.
    let boxes: Vec<([i64; 4], i64)> = assembly
        .pieces
        .iter()
        .map(|p| {
            let pl = &p.placement;
            let (sx, sy) = pl.part.spec().footprint(pl.rot);
            let (x0, z0) = (i64::from(pl.origin.x) * stud, i64::from(pl.origin.y) * stud);
            let foot = [x0, z0, x0 + i64::from(sx) * stud, z0 + i64::from(sy) * stud];
            (foot, layer * i64::from(pl.origin.z))
        })
        .collect();
    let Some(first) = boxes.first() else {
        return Vec::new();
    };
    let mut extent = first.0;
    for (f, _) in &boxes {
        extent = [
            extent[0].min(f[0]),
            extent[1].min(f[1]),
            extent[2].max(f[2]),
            extent[3].max(f[3]),
        ];
    }
    // Twice the centres, to stay in integers.
    let centre2 = [extent[0] + extent[2], extent[1] + extent[3]];

    let tallest = assembly
        .pieces
        .iter()
        .map(|p| i64::from(p.placement.part.spec().height_ldu()))
        .max()
        .unwrap_or(0);
    let mut bottoms: Vec<i64> = boxes.iter().map(|&(_, b)| b).collect();
    bottoms.sort_unstable();
    bottoms.dedup();
    let gap = f64::from(opts.level_gap_ldu);
    let mut rise = Vec::with_capacity(bottoms.len());
    let mut acc = 0.0f64;
    for (k, &b) in bottoms.iter().enumerate() {
        if k > 0 {
            let overlap = (tallest - (b - bottoms[k - 1])) as f64;
            acc += gap.max(overlap);
        }
        rise.push(acc);
    }

    let spread = f64::from(opts.spread);
    boxes
        .iter()
        .map(|&(f, b)| {
            let level = bottoms.binary_search(&b).unwrap_or(0);
            let dx = spread * ((f[0] + f[2]) - centre2[0]) as f64 / 2.0;
            let dz = spread * ((f[1] + f[3]) - centre2[1]) as f64 / 2.0;
            Vec3::new(dx as f32, -(rise[level] as f32), dz as f32)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Placement;
    use crate::catalog::{Color, PartKind};
    use crate::geom::{Cell, Rot};

    /// The LDraw-world box (min, max) of each piece's solid (studs left
    /// out), displaced by its offset.
    fn displaced_boxes(asm: &Assembly, off: &[Vec3]) -> Vec<(Vec3, Vec3)> {
        asm.pieces
            .iter()
            .zip(off)
            .flat_map(|(p, &o)| {
                let layer = asm.layer_ldu as f32;
                p.placement
                    .body(asm.layer_ldu)
                    .boxes()
                    .iter()
                    .map(|b| {
                        let m = b.max_excl();
                        let lo = Vec3::new(
                            20.0 * b.min.x as f32,
                            -layer * m.z as f32,
                            20.0 * b.min.y as f32,
                        );
                        let hi = Vec3::new(
                            20.0 * m.x as f32,
                            -layer * b.min.z as f32,
                            20.0 * m.y as f32,
                        );
                        (lo + o, hi + o)
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    fn overlap(a: &(Vec3, Vec3), b: &(Vec3, Vec3)) -> bool {
        (0..3).all(|k| a.0[k] < b.1[k] - 1e-3 && b.0[k] < a.1[k] - 1e-3)
    }

    /// Whole-piece boxes (a slope's full prism), displaced.
    fn piece_boxes(asm: &Assembly, off: &[Vec3]) -> Vec<(Vec3, Vec3)> {
        asm.pieces
            .iter()
            .zip(off)
            .map(|(p, &o)| {
                let b = p.placement.body(asm.layer_ldu).bbox;
                let m = b.max_excl();
                let layer = asm.layer_ldu as f32;
                let lo = Vec3::new(
                    20.0 * b.min.x as f32,
                    -layer * m.z as f32,
                    20.0 * b.min.y as f32,
                );
                let hi = Vec3::new(
                    20.0 * m.x as f32,
                    -layer * b.min.z as f32,
                    20.0 * m.y as f32,
                );
                (lo + o, hi + o)
            })
            .collect()
    }

    /// A small roof: a running-bond wall of bricks on half-brick layers, a
    /// row of slopes on it, and a second slope resting on the first one's
    /// front row (their whole-piece boxes overlap before exploding).
    fn roof() -> Assembly {
        let part = |id| PartKind::from_id(id).unwrap();
        let (brick, slope, inv) = (part("3001"), part("3039"), part("3660a"));
        let order = [
            Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
            Placement::new(brick, Cell::new(4, 0, 0), Rot::R0),
            Placement::new(brick, Cell::new(2, 0, 2), Rot::R0),
            Placement::new(part("3003"), Cell::new(0, 0, 2), Rot::R0),
            Placement::new(slope, Cell::new(0, 0, 4), Rot::R0),
            Placement::new(slope, Cell::new(2, 0, 4), Rot::R180),
            Placement::new(slope, Cell::new(0, -1, 5), Rot::R0),
            Placement::new(inv, Cell::new(4, 0, 4), Rot::R90),
        ];
        Assembly::from_order(&order, 12, Color::RED)
    }

    #[test]
    fn displaced_pieces_never_overlap() {
        let asm = roof();
        for opts in [
            ExplodeOptions::default(),
            ExplodeOptions::default()
                .with_spread(0.0)
                .with_level_gap_ldu(0.0),
            ExplodeOptions::default().with_spread(1.0),
        ] {
            let off = explode(&asm, &opts);
            assert_eq!(off.len(), asm.pieces.len());
            let boxes = piece_boxes(&asm, &off);
            for i in 0..boxes.len() {
                for j in 0..i {
                    assert!(!overlap(&boxes[i], &boxes[j]), "{opts:?}: {i} and {j}");
                }
            }
            // The solids never overlapped in the first place, and still do not.
            let solids = displaced_boxes(&asm, &off);
            for i in 0..solids.len() {
                for j in 0..i {
                    assert!(!overlap(&solids[i], &solids[j]), "{opts:?}");
                }
            }
        }
        // Without exploding, the two stacked slopes' boxes do overlap.
        let zero = vec![Vec3::ZERO; asm.pieces.len()];
        let boxes = piece_boxes(&asm, &zero);
        assert!(overlap(&boxes[4], &boxes[6]));
    }

    #[test]
    fn courses_keep_their_order_and_rise_by_at_least_the_gap() {
        let asm = roof();
        let opts = ExplodeOptions::default();
        let off = explode(&asm, &opts);
        let bottom = |i: usize| -(asm.pieces[i].placement.origin.z * 12) as f32 + off[i].y;
        for i in 0..asm.pieces.len() {
            for j in 0..asm.pieces.len() {
                let (zi, zj) = (
                    asm.pieces[i].placement.origin.z,
                    asm.pieces[j].placement.origin.z,
                );
                if zi < zj {
                    // Higher in the model is higher (more negative Y) here.
                    assert!(bottom(j) <= bottom(i) - 12.0 - opts.level_gap_ldu);
                } else if zi == zj {
                    assert_eq!(off[i].y, off[j].y);
                }
            }
        }
        // Ground level stays; spread is symmetric about the centre.
        assert_eq!(off[0].y, 0.0);
        assert_eq!(off[0].x, -off[1].x);
    }

    #[test]
    fn offsets_are_deterministic_and_empty_models_are_fine() {
        let asm = roof();
        let opts = ExplodeOptions::default();
        assert_eq!(explode(&asm, &opts), explode(&asm, &opts));
        let empty = Assembly {
            pieces: vec![],
            layer_ldu: 24,
        };
        assert!(explode(&empty, &opts).is_empty());
        let bad = ExplodeOptions::default()
            .with_spread(f32::NAN)
            .with_level_gap_ldu(-3.0);
        assert_eq!((bad.spread, bad.level_gap_ldu), (0.0, 0.0));
    }
}
