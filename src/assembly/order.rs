//! Re-sequencing a verified build course by course, so that its steps read
//! like instructions.
//!
//! The search's trace is a valid build order, but it can move up and down
//! between brick courses (the layout's derivation takes a piece hanging
//! under an overhang right after the piece it hangs from, and
//! `--search backward`'s derivation adds pieces in the reverse of the order
//! its trace took them away, wherever a rule matched). A person builds
//! a course, then the next; instructions that jump between courses make
//! many tiny steps. [`by_course`] re-sequences the same pieces greedily:
//! at each turn it adds, among the pieces on the ground or stud-connected
//! to what is already built, the one on the lowest course (earliest in the
//! trace on a tie). So the bottom course is laid first, as on a table, and
//! separate parts (the legs of an animal) rise side by side until the
//! courses above join them. Every piece still joins an earlier one or the
//! ground by construction; the caller verifies the result (placeability
//! included) and keeps the original order if it fails.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

use super::{Assembly, Placed};
use crate::geom::Cell;

/// The assembly's pieces in course-by-course order, steps renumbered one
/// piece a step (regroup afterwards).
pub fn by_course(assembly: &Assembly) -> Assembly {
    let n = assembly.pieces.len();
    let layer_ldu = assembly.layer_ldu;
    let bodies: Vec<_> = assembly
        .pieces
        .iter()
        .map(|p| p.placement.body(layer_ldu))
        .collect();
    let course = |i: usize| (assembly.pieces[i].placement.origin.z * layer_ldu).div_euclid(24);
    // Who takes studs where, and who offers them.
    let mut tubes: HashMap<Cell, Vec<usize>> = HashMap::new();
    let mut studs: HashMap<Cell, Vec<usize>> = HashMap::new();
    for (i, b) in bodies.iter().enumerate() {
        for c in b.tubes.cells() {
            tubes.entry(c).or_default().push(i);
        }
        for c in b.studs.cells() {
            studs.entry(c).or_default().push(i);
        }
    }
    let neighbours = |i: usize| -> Vec<usize> {
        let b = &bodies[i];
        let mut out: Vec<usize> = b
            .over_studs()
            .cells()
            .flat_map(|c| tubes.get(&c).into_iter().flatten().copied())
            .filter(|&j| b.holds(&bodies[j]))
            .chain(
                b.under_tubes()
                    .cells()
                    .flat_map(|c| studs.get(&c).into_iter().flatten().copied())
                    .filter(|&j| bodies[j].holds(b)),
            )
            .filter(|&j| j != i)
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    };
    let mut placed = vec![false; n];
    let mut queued = vec![false; n];
    let mut heap: BinaryHeap<Reverse<(i32, usize)>> = BinaryHeap::new();
    let mut order: Vec<usize> = Vec::with_capacity(n);
    let mut next_seed = 0;
    // Everything on the ground can start at once: a person lays the bottom
    // course on the table before building on it.
    let ground = bodies.iter().map(|b| b.bbox.min.z).min().unwrap_or(0);
    for (i, b) in bodies.iter().enumerate() {
        if b.bbox.min.z == ground {
            queued[i] = true;
            heap.push(Reverse((course(i), i)));
        }
    }
    while order.len() < n {
        if heap.is_empty() {
            // A new start: the lowest, earliest piece not yet placed (the
            // first time; more only if the build had several components).
            let start = (next_seed..n)
                .filter(|&i| !placed[i])
                .min_by_key(|&i| (course(i), i))
                .expect("unplaced pieces remain");
            next_seed = start.min(next_seed);
            queued[start] = true;
            heap.push(Reverse((course(start), start)));
        }
        let Reverse((_, i)) = heap.pop().expect("not empty");
        placed[i] = true;
        order.push(i);
        for j in neighbours(i) {
            if !queued[j] {
                queued[j] = true;
                heap.push(Reverse((course(j), j)));
            }
        }
    }
    Assembly {
        pieces: order
            .iter()
            .enumerate()
            .map(|(k, &i)| Placed {
                step: super::Step(k as u32 + 1),
                ..assembly.pieces[i]
            })
            .collect(),
        layer_ldu,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::verify::verify;
    use crate::assembly::Placement;
    use crate::catalog::{Color, PartKind};
    use crate::geom::Rot;

    #[test]
    fn a_zigzag_trace_is_built_course_by_course() {
        let brick = PartKind::from_id("3001").unwrap();
        // A 3-course wall in running bond, traced a column at a time.
        let mut order = Vec::new();
        for i in 0..4 {
            order.push(Placement::new(brick, Cell::new(4 * i, 0, 0), Rot::R0));
            order.push(Placement::new(brick, Cell::new(4 * i + 2, 0, 1), Rot::R0));
            order.push(Placement::new(brick, Cell::new(4 * i, 0, 2), Rot::R0));
        }
        let a = Assembly::from_order(&order, 24, Color::RED);
        assert!(verify(&a, None).is_ok());
        let b = by_course(&a);
        assert!(verify(&b, None).is_ok(), "{}", verify(&b, None));
        let courses: Vec<i32> = b.pieces.iter().map(|p| p.placement.origin.z).collect();
        // The bottom course is laid on the table first, then each course
        // in one run.
        assert_eq!(courses, [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2]);
        let mut sorted = b.pieces.iter().map(|p| p.placement).collect::<Vec<_>>();
        sorted.sort_by_key(|p| (p.origin.z, p.origin.x));
        let mut orig = order.clone();
        orig.sort_by_key(|p| (p.origin.z, p.origin.x));
        assert_eq!(sorted, orig, "the same pieces");
    }
}
