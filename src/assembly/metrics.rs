//! How well an assembly holds together, measured the way builders judge it.
//!
//! A **vertical seam** is a place where two pieces meet side by side in a
//! layer. In a strong wall the piece above bridges it (running bond); where
//! the seam continues straight into the next course, the wall can split
//! along it. [`seams`] counts the seams whose next course up is filled on
//! both sides and how many of those continue. A seam between two tall pieces
//! (two layers of the same pair) is one seam, and the next course is the
//! first layer above where either side changes piece.

use std::collections::HashMap;

use serde::Serialize;

use super::Assembly;
use crate::geom::Cell;

/// Seam counts of an assembly.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct SeamStats {
    /// Seams with pieces on both sides in the course above.
    pub seams: usize,
    /// Of those, the seams that continue into the course above.
    pub continued: usize,
    /// `continued / seams` (0 when there are no seams): lower is stronger.
    pub fraction: f64,
    /// Of `seams`, those between pieces of two colours: where a coloured
    /// model changes colour, the pieces must meet.
    pub colour_seams: usize,
    /// Of `colour_seams`, those that continue into the course above.
    pub colour_continued: usize,
    /// The share of the seams within one colour that continue: the bond
    /// away from colour boundaries.
    pub fraction_in_colour: f64,
}

/// Counts the vertical seams of `asm` and those that continue upward.
pub fn seams(asm: &Assembly) -> SeamStats {
    let mut owner: HashMap<Cell, usize> = HashMap::new();
    for (i, p) in asm.pieces.iter().enumerate() {
        for c in p.placement.body(asm.layer_ldu).cells() {
            owner.insert(c, i);
        }
    }
    let mut stats = SeamStats::default();
    let mut cells: Vec<(&Cell, &usize)> = owner.iter().collect();
    cells.sort();
    for (&c, &a) in cells {
        for n in [c.offset(1, 0, 0), c.offset(0, 1, 0)] {
            let Some(&b) = owner.get(&n) else { continue };
            if a == b {
                continue;
            }
            // Count a seam once, at the bottom layer of the pair.
            let below = (
                owner.get(&c.offset(0, 0, -1)),
                owner.get(&n.offset(0, 0, -1)),
            );
            if below == (Some(&a), Some(&b)) {
                continue;
            }
            // Walk up while the same two pieces meet here.
            let mut z = 1;
            let (up_a, up_b) = loop {
                let pair = (owner.get(&c.offset(0, 0, z)), owner.get(&n.offset(0, 0, z)));
                if pair != (Some(&a), Some(&b)) {
                    break pair;
                }
                z += 1;
            };
            if let (Some(&ua), Some(&ub)) = (up_a, up_b) {
                let colour = asm.pieces[a].color != asm.pieces[b].color;
                stats.seams += 1;
                stats.colour_seams += usize::from(colour);
                if ua != ub {
                    stats.continued += 1;
                    stats.colour_continued += usize::from(colour);
                }
            }
        }
    }
    let share = |k: usize, n: usize| {
        if n == 0 {
            0.0
        } else {
            ((k as f64 / n as f64) * 10_000.0).round() / 10_000.0
        }
    };
    stats.fraction = share(stats.continued, stats.seams);
    stats.fraction_in_colour = share(
        stats.continued - stats.colour_continued,
        stats.seams - stats.colour_seams,
    );
    stats
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Placement;
    use crate::catalog::{Color, PartKind};
    use crate::geom::Rot;

    fn wall(courses: &[&[(i32, &str)]], layer_ldu: i32, course_layers: i32) -> Assembly {
        let mut order = Vec::new();
        for (k, row) in courses.iter().enumerate() {
            for &(x, id) in row.iter() {
                let z = k as i32 * course_layers;
                order.push(Placement::new(
                    PartKind::from_id(id).unwrap(),
                    Cell::new(x, 0, z),
                    Rot::R0,
                ));
            }
        }
        Assembly::from_order(&order, layer_ldu, Color::RED)
    }

    #[test]
    fn stacked_seams_continue_and_running_bond_breaks_them() {
        // Stack bond: 1x4 on 1x4, the seam at x = 4 runs through.
        let stack = wall(
            &[&[(0, "3010"), (4, "3010")], &[(0, "3010"), (4, "3010")]],
            24,
            1,
        );
        let s = seams(&stack);
        assert_eq!((s.seams, s.continued), (1, 1));
        assert_eq!(s.fraction, 1.0);
        // Running bond: the course above is offset by two studs.
        let bond = wall(
            &[
                &[(0, "3010"), (4, "3010")],
                &[(2, "3010"), (0, "3004"), (6, "3004")],
            ],
            24,
            1,
        );
        let s = seams(&bond);
        assert_eq!((s.seams, s.continued), (1, 0));
        // The same stack on half-brick layers: bricks are two layers tall,
        // and the seam still counts once.
        let half = wall(
            &[&[(0, "3010"), (4, "3010")], &[(0, "3010"), (4, "3010")]],
            12,
            2,
        );
        assert_eq!(seams(&half), seams(&stack));
    }
}
