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
//! ground by construction, but a piece hung under the course above can be
//! shut in by the courses laid under it first: [`by_course_placeable`]
//! mends that, and the caller verifies the result (placeability
//! included) and keeps the original order if it still fails.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::verify::connections;
use super::{Assembly, Placed};
use crate::geom::Body;

/// Mends [`by_course_placeable`] makes at most.
const MENDS: usize = 24;

/// Pieces shut in past the first order's that stop the mends.
const MEND_SLACK: usize = 10;

/// [`by_course`], mended where it shuts a piece in: a piece hung under
/// the course above (joined only to pieces over it) goes in from below,
/// after the piece it hangs from, but the course-by-course order lays the
/// courses under it first. The pieces under such a piece (in the column
/// of its footprint, down to the ground) then come right after it, top
/// down, each going in from below, and after them the pieces that joined
/// the build only through them. `None` if the order still fails the
/// verifier's order rules after a few mends (the caller keeps the
/// search's trace, which climbs a part to its top before the next: the
/// bunny at 56 studs then built a tower leaning out from its feet, which
/// broke at step 3).
pub fn by_course_placeable(assembly: &Assembly) -> Option<Assembly> {
    use super::verify::{verify, Failure};
    let bodies = bodies(assembly);
    let joins = connections(&bodies);
    let boxes: Vec<_> = bodies.iter().map(|b| b.bbox).collect();
    let ground = boxes.iter().map(|b| b.min.z).min().unwrap_or(0);
    let mut order = course_order(assembly, &bodies, &joins);
    let mut most = None;
    for _ in 0..MENDS {
        let ordered = reordered(assembly, &order);
        let report = verify(&ordered, None);
        if report.is_ok() {
            return Some(ordered);
        }
        // A mend may shut in a few pieces more for a while (the bunny at
        // 56 studs: 1, then 9, then down to none in 14 mends); mends that
        // shut in ever more (at 96 studs: 7 to over a hundred) stop.
        let most = *most.get_or_insert(report.failures.len() + MEND_SLACK);
        if report.failures.len() > most {
            return None;
        }
        let t = report.failures.iter().find_map(|f| match *f {
            Failure::NotPlaceable { piece, .. } => Some(piece),
            _ => None,
        })?;
        let b = boxes[order[t]];
        // The pieces before it under its footprint, top down.
        let mut below: Vec<(i32, usize)> = order[..t]
            .iter()
            .filter_map(|&i| {
                let c = boxes[i];
                let overlaps = c.min.x < b.min.x + b.sx
                    && b.min.x < c.min.x + c.sx
                    && c.min.y < b.min.y + b.sy
                    && b.min.y < c.min.y + c.sy;
                (overlaps && c.min.z + c.sz <= b.min.z).then_some((-(c.min.z + c.sz), i))
            })
            .collect();
        below.sort_unstable();
        let mut gone = vec![false; assembly.pieces.len()];
        for &(_, i) in &below {
            gone[i] = true;
        }
        // The pieces after them that joined the build only through them.
        let mut before = vec![false; assembly.pieces.len()];
        let mut after = Vec::new();
        for &i in &order[..t] {
            if !gone[i]
                && boxes[i].min.z > ground
                && !joins[i].iter().any(|&k| before[k] && !gone[k])
            {
                gone[i] = true;
                after.push(i);
            }
            before[i] = true;
        }
        let mut next: Vec<usize> = order[..t].iter().copied().filter(|&i| !gone[i]).collect();
        next.push(order[t]);
        next.extend(below.iter().map(|&(_, i)| i));
        next.extend(after);
        next.extend_from_slice(&order[t + 1..]);
        order = next;
    }
    None
}

/// `assembly`'s pieces in `order` (indices into its pieces), one a step.
fn reordered(assembly: &Assembly, order: &[usize]) -> Assembly {
    Assembly {
        pieces: order
            .iter()
            .enumerate()
            .map(|(k, &i)| Placed {
                step: super::Step(k as u32 + 1),
                ..assembly.pieces[i]
            })
            .collect(),
        layer_ldu: assembly.layer_ldu,
    }
}

/// The assembly's pieces in course-by-course order, steps renumbered one
/// piece a step (regroup afterwards).
pub fn by_course(assembly: &Assembly) -> Assembly {
    let bodies = bodies(assembly);
    reordered(
        assembly,
        &course_order(assembly, &bodies, &connections(&bodies)),
    )
}

/// The pieces' bodies.
fn bodies(assembly: &Assembly) -> Vec<Body> {
    assembly
        .pieces
        .iter()
        .map(|p| p.placement.body(assembly.layer_ldu))
        .collect()
}

/// [`by_course`]'s order, as indices into `assembly`'s pieces, whose
/// `bodies` are stud-connected as `joins` says ([`connections`]).
fn course_order(assembly: &Assembly, bodies: &[Body], joins: &[Vec<usize>]) -> Vec<usize> {
    let n = assembly.pieces.len();
    let layer_ldu = assembly.layer_ldu;
    let course = |i: usize| (assembly.pieces[i].placement.origin.z * layer_ldu).div_euclid(24);
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
        for &j in &joins[i] {
            if !queued[j] {
                queued[j] = true;
                heap.push(Reverse((course(j), j)));
            }
        }
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::verify::verify;
    use crate::assembly::Placement;
    use crate::catalog::{Color, PartKind};
    use crate::geom::{Cell, Rot};

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
