//! The paper's own search (section 4, "Structural Analysis"): backward
//! tracing of the rewriting rules, beside the layout (`--search backward`).
//!
//! The voxels are first cut into parts at horizontal planes where the
//! number of voxels a layer holds changes sharply (the paper's
//! "Hierarchical Approach"; its skyscraper falls into five parts). A cut is
//! kept only if both sides are one piece each, so that each part is
//! "connectable itself". Each part, from the bottom up, is then traced
//! backward whole ([`trace`]): a depth-first tree of voxel grids whose
//! edges are rules applied in reverse, with backtracking. Nothing is grown
//! forward: when a part's tree is exhausted, or the node or time budget
//! runs out, the search fails and says how far it got (nodes, backtracks,
//! seconds), and no build is made.
//!
//! The first part ends in a starting rule; a part above is traced with the
//! pieces of the parts below in place, and a match may join one of them
//! (the paper's parts "can easily be combined together as ... there are
//! typically many voxels connecting the parts"): the lowest course of a
//! roof can only be put on the walls, never pushed in under the course
//! above it. The parts combine into one derivation: the first part's, then
//! the next part's, and so on up. Read backwards, it is the paper's rule
//! sequence.
//!
//! The layout's extras are not used here: no slope guide, no colour
//! splits, no pieces outside the voxels; every piece fills voxels of the
//! model only, as in the paper.
//!
//! Two repairs are made first. Where two voxels meet only along an edge
//! (a one-voxel ring turning by a diagonal step, a handle climbing by
//! one), no piece holds them together: a voxel is added at each such step
//! ([`joinable::fill_steps`]; counted in `extra_cells`, as the layout's
//! cells there). And where pieces stack by more than one layer
//! (with slopes, two half-brick layers): a column of voxels that ends half
//! a course off, where no slope's low row can end it, gets the half course
//! added ([`courses`]; counted in `evened_voxels`, as the layout's evening
//! is). Every piece of a build stands a whole number of courses above the
//! lowest layer, so such a column is in no derivation: the house's ridge
//! at 11 studs with slopes, 17 half layers high, was one. For the same
//! reason the parts are cut on whole courses only.

mod courses;
mod draw;
mod fit;
mod joinable;
mod trace;

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::rulebook::RuleBook;
use super::{Removal, Repairs, SearchError, SearchOptions, SearchOutcome, SearchStats};
use crate::assembly::Placement;
use crate::geom::Cell;
use crate::grammar::RuleSet;
use crate::voxel::VoxelGrid;
use trace::{Counters, Stop, Trace, Tuning};

/// A change in voxels between two layers at least this large (the larger
/// count over the smaller) is a place to cut.
pub const CUT_RATIO: f64 = 1.5;

/// The parts of `v`: ranges of layers `[lo, hi)`, bottom first, cut where
/// a layer's voxel count changes by [`CUT_RATIO`] or more from the one
/// below, each part at least `min_layers` high and one piece (face to
/// face) on its own. Cuts fall a whole number of `step`s of layers above
/// the lowest (the height pieces stack by: a part cut through a course
/// would leave half a brick that no piece of it can fill).
pub fn parts(v: &VoxelGrid, min_layers: i32, step: i32) -> Vec<(i32, i32)> {
    let (_, _, nz) = v.dims();
    let counts: Vec<usize> = (0..nz).map(|z| v.count_layer(z)).collect();
    let lo = counts.iter().position(|&c| c > 0).unwrap_or(0) as i32;
    let hi = counts.iter().rposition(|&c| c > 0).map_or(0, |i| i + 1) as i32;
    let mut cuts: Vec<i32> = Vec::new();
    let mut last = lo;
    for z in lo + 1..hi {
        let (a, b) = (counts[z as usize - 1] as f64, counts[z as usize] as f64);
        if a == 0.0 || b == 0.0 {
            continue;
        }
        let sharp = a.max(b) / a.min(b) >= CUT_RATIO;
        if sharp && (z - lo) % step.max(1) == 0 && z - last >= min_layers && hi - z >= min_layers {
            let below = slab(v, last, z);
            let above = slab(v, z, hi);
            if one_piece(&below) && one_piece(&above) {
                cuts.push(z);
                last = z;
            }
        }
    }
    let mut out = Vec::new();
    let mut from = lo;
    for c in cuts {
        out.push((from, c));
        from = c;
    }
    out.push((from, hi));
    out
}

/// The voxels of `v` in layers `[lo, hi)`.
fn slab(v: &VoxelGrid, lo: i32, hi: i32) -> VoxelGrid {
    let (nx, ny, nz) = v.dims();
    let mut out = VoxelGrid::new(nx, ny, nz);
    for c in v.cells().filter(|c| c.z >= lo && c.z < hi) {
        out.set(c, true);
    }
    out
}

/// Whether the voxels are one piece, face to face.
fn one_piece(v: &VoxelGrid) -> bool {
    let Some(start) = v.cells().next() else {
        return true;
    };
    let (nx, ny, nz) = v.dims();
    let mut seen = VoxelGrid::new(nx, ny, nz);
    seen.set(start, true);
    let mut stack = vec![start];
    let mut n = 0;
    while let Some(c) = stack.pop() {
        n += 1;
        for d in crate::geom::FACES {
            let e = Cell::new(c.x + d.0, c.y + d.1, c.z + d.2);
            if v.in_bounds(e) && v.get(e) && !seen.get(e) {
                seen.set(e, true);
                stack.push(e);
            }
        }
    }
    n == v.count()
}

/// Traces `voxels` (already repaired: `repairs`) backward, part by part.
pub(super) fn build(
    mut voxels: VoxelGrid,
    mut repairs: Repairs,
    emptied: Option<VoxelGrid>,
    rules: &RuleSet,
    opts: &SearchOptions,
    started: Instant,
) -> Result<SearchOutcome, SearchError> {
    let book = RuleBook::new(rules);
    let shapes = trace::coverers(rules);
    let tuning = Tuning {
        b_min: opts.branching.0,
        b_max: opts.branching.1.max(opts.branching.0),
        complex_every: opts.complex_every,
        node_budget: opts.node_budget,
        restart: opts.restart,
        deadline: started + opts.time_budget,
        step: courses::step(&shapes),
        base: voxels.bounds().map_or(0, |b| b.min.z),
    };
    // Parts at least a brick high (a course: 1 layer for bricks, more for
    // slopes or plates).
    let course = (24 / rules.layer_ldu()).max(1);
    // A wall one voxel thin that turns by diagonal steps gets a voxel at
    // each step, as the layout gives it a cell there.
    repairs.extra_cells += joinable::fill_steps(&mut voxels);
    // Every column of voxels ends on a whole course, or where a slope can
    // end it: a half course is added where neither is so (the ridge of a
    // roof of half courses), and a column that still cannot be filled
    // fails at once.
    repairs.evened_voxels += courses::even(&mut voxels, &shapes);
    // A shape refused before any node is searched.
    let refused = |why: String| SearchError::Backward {
        why,
        nodes: 0,
        backtracks: 0,
        secs: started.elapsed().as_secs_f64(),
    };
    if let Some(c) = courses::uneven(&voxels, &shapes) {
        return Err(refused(format!(
            "the column of voxels at ({}, {}) ends at layer {} between two courses, where no slope can end it and no half course can be added: these rules cannot build the shape",
            c.x, c.y, c.z
        )));
    }
    let cuts = if opts.cut {
        parts(&voxels, 2 * course, tuning.step)
    } else {
        vec![(0, voxels.dims().2)]
    };
    // A shape whose voxels no pieces in them can hold together fails at
    // once, not when the budget ends.
    if let Some((c, n)) = joinable::unjoinable(&voxels, rules) {
        return Err(refused(format!(
            "no pieces in the voxels can join the {n} voxels from ({}, {}, {}) to the rest (they touch it only along edges, or across a layer no piece spans): these rules cannot build the shape",
            c.x, c.y, c.z
        )));
    }
    let (nx, ny, nz) = voxels.dims();
    let mut below = VoxelGrid::new(nx, ny, nz);
    let mut below_pieces: Vec<Placement> = Vec::new();
    let mut order: Vec<Removal> = Vec::new();
    let mut count = Counters::default();
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    for (i, &(lo, hi)) in cuts.iter().enumerate() {
        let cells = slab(&voxels, lo, hi);
        if cells.is_empty() {
            continue;
        }
        let mut t = Trace::new(
            rules,
            &book,
            tuning,
            cells.clone(),
            &below,
            &below_pieces,
            order.is_empty(),
        );
        let part = t.run(&mut rng, &mut count).map_err(|stop| SearchError::Backward {
            why: match stop {
                Stop::Exhausted => format!(
                    "every branch of the tree was tried: these rules cannot build part {} of {} (layers {lo} to {})",
                    i + 1,
                    cuts.len(),
                    hi - 1
                ),
                Stop::Apart(c) => format!(
                    "no piece can hold the voxel at ({}, {}, {}) to the rest (nothing above or below it within a piece's reach): these rules cannot build part {} of {} (layers {lo} to {})",
                    c.x,
                    c.y,
                    c.z,
                    i + 1,
                    cuts.len(),
                    hi - 1
                ),
                Stop::Nodes => format!(
                    "the node budget ({}) ran out in part {} of {}; raise --node-budget",
                    opts.node_budget,
                    i + 1,
                    cuts.len()
                ),
                Stop::Time => format!(
                    "the time budget ran out in part {} of {}; raise --time-budget",
                    i + 1,
                    cuts.len()
                ),
            },
            nodes: count.nodes,
            backtracks: count.backtracks,
            secs: started.elapsed().as_secs_f64(),
        })?;
        for c in cells.cells() {
            below.set(c, true);
        }
        below_pieces.extend(trace::pieces(&part));
        order.extend(part);
    }
    if order.is_empty() {
        return Err(SearchError::Empty);
    }
    let mut target = VoxelGrid::new(nx, ny, nz);
    for r in &order {
        target.set_body(&r.piece.body(rules.layer_ldu()), true);
    }
    let stats = SearchStats {
        nodes: count.nodes,
        backtracks: count.backtracks,
        parts: cuts.len() as u64,
        complex_tried: count.complex_tried,
        complex_applied: count.complex_applied,
        starts: order
            .iter()
            .filter(|r| r.anchor == super::Anchor::Start)
            .count() as u64,
        ..SearchStats::default()
    };
    Ok(SearchOutcome {
        order,
        voxels: target,
        repairs,
        emptied,
        stats,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tower_on_a_wide_base_is_cut_where_it_narrows() {
        // A 6x6 base two layers high under a 2x2 tower four layers high.
        let mut v = VoxelGrid::new(6, 6, 6);
        for z in 0..6 {
            for y in 0..6 {
                for x in 0..6 {
                    let tower = (2..4).contains(&x) && (2..4).contains(&y);
                    if z < 2 || tower {
                        v.set(Cell::new(x, y, z), true);
                    }
                }
            }
        }
        assert_eq!(parts(&v, 2, 1), [(0, 2), (2, 6)]);
        // Parts must be two layers high at least: no cut at 1.
        assert_eq!(parts(&v, 5, 1), [(0, 6)]);
        // Nor where it falls inside a step of three layers.
        assert_eq!(parts(&v, 2, 3), [(0, 6)]);
    }
}
