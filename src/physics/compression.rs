//! The compression certificate: a group of pieces whose weights can all
//! be passed down to the ground in compression stands using no clutch,
//! and that answer is exact without a solve.
//!
//! Every cost of the program is zero or positive (hands, joint usage and
//! stud tension cost; compression is free), so an equilibrium that uses
//! compression alone has cost 0, the least there is: it is optimal, and
//! every optimal answer uses no clutch and no hand. Every piece's usage
//! is then 0 exactly, whatever solver is asked.
//!
//! Such an equilibrium is found (when it is easy to find) top down: each
//! piece sums what rests on it and its own weight into one vertical load
//! at one point; a load inside the corners of the faces the piece rests on
//! is a sum of pushes at those corners with non-negative weights (the
//! bilinear weights of one face's corners, else a triangle's barycentric
//! weights), which become loads on the pieces below, down to the ground.
//! A piece whose load point lies outside all its supports, as an overhang
//! or a piece held by its clutch does, fails the check, and the group is
//! solved. This is the straight-drop certificate grown to loads that
//! spread over several supports, and it costs a walk down the structure:
//! a solid 7,000-piece build is certified in milliseconds where its
//! program takes tens of seconds.

use std::collections::BTreeMap;

use super::model::Structure;

/// Whether the weights of `pieces` (sorted: a group, standing on the
/// ground and on each other) pass down to the ground in compression.
pub(super) fn holds(s: &Structure, pieces: &[usize]) -> bool {
    let placed = |p: usize| pieces.binary_search(&p).is_ok();
    // Loads, highest first: (bottom layer, piece) -> (down force, its
    // moments about the origin).
    let mut loads: BTreeMap<(i32, usize), [f64; 3]> = BTreeMap::new();
    let add = |loads: &mut BTreeMap<(i32, usize), [f64; 3]>, p: usize, at: (f64, f64), f: f64| {
        let l = loads.entry((s.bottom(p), p)).or_insert([0.0; 3]);
        l[0] += f;
        l[1] += f * at.0;
        l[2] += f * at.1;
    };
    for &p in pieces {
        let (w, com) = s.weight(p);
        add(&mut loads, p, com, w);
    }
    while let Some(((_, p), [f, mx, my])) = loads.pop_last() {
        if f <= 0.0 {
            return false;
        }
        let at = (mx / f, my / f);
        let supports = s.supports(p, placed);
        let Some(weights) = spread(&supports, at) else {
            return false;
        };
        for (&(below, pt), w) in supports.iter().zip(weights) {
            if let (Some(q), true) = (below, w > 0.0) {
                add(&mut loads, q, pt, w * f);
            }
        }
    }
    true
}

/// Non-negative weights summing to 1 on the `points` whose weighted mean
/// is `at`: the bilinear weights of a face's four corners when one holds
/// it (corners come in fours, a face at a time), else a triangle's
/// barycentric weights. `None` when `at` lies outside them all.
fn spread(points: &[(Option<usize>, (f64, f64))], at: (f64, f64)) -> Option<Vec<f64>> {
    const EPS: f64 = 1e-9;
    let mut w = vec![0.0; points.len()];
    // Faces: corners (x0, y0), (x1, y0), (x0, y1), (x1, y1), each four
    // from one support; they may have been filtered, so check each four.
    for (k, quad) in points.chunks_exact(4).enumerate() {
        let same = quad.iter().all(|q| q.0 == quad[0].0);
        let (x0, y0) = quad[0].1;
        let (x1, y1) = quad[3].1;
        let is_face = same && quad[1].1 == (x1, y0) && quad[2].1 == (x0, y1) && x1 > x0 && y1 > y0;
        if is_face && (x0 - EPS..=x1 + EPS).contains(&at.0) && (y0 - EPS..=y1 + EPS).contains(&at.1)
        {
            let tx = ((at.0 - x0) / (x1 - x0)).clamp(0.0, 1.0);
            let ty = ((at.1 - y0) / (y1 - y0)).clamp(0.0, 1.0);
            let base = 4 * k;
            w[base] = (1.0 - tx) * (1.0 - ty);
            w[base + 1] = tx * (1.0 - ty);
            w[base + 2] = (1.0 - tx) * ty;
            w[base + 3] = tx * ty;
            return Some(w);
        }
    }
    // Triangles, in a fixed order.
    let n = points.len().min(32);
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let (a, b, c) = (points[i].1, points[j].1, points[k].1);
                let det = (b.0 - a.0) * (c.1 - a.1) - (c.0 - a.0) * (b.1 - a.1);
                if det.abs() < 1e-12 {
                    continue;
                }
                let l1 = ((at.0 - a.0) * (c.1 - a.1) - (c.0 - a.0) * (at.1 - a.1)) / det;
                let l2 = ((b.0 - a.0) * (at.1 - a.1) - (at.0 - a.0) * (b.1 - a.1)) / det;
                let l0 = 1.0 - l1 - l2;
                if l0 >= -EPS && l1 >= -EPS && l2 >= -EPS {
                    let (l0, l1, l2) = (l0.max(0.0), l1.max(0.0), l2.max(0.0));
                    let sum = l0 + l1 + l2;
                    w[i] = l0 / sum;
                    w[j] = l1 / sum;
                    w[k] = l2 / sum;
                    return Some(w);
                }
            }
        }
    }
    None
}
