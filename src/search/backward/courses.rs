//! Whole courses: whether each column of voxels can be filled by pieces
//! stacked from the ground, and the half courses added on top (or below)
//! where it cannot.
//!
//! Pieces join only by studs, so in a build every piece's bottom lies the
//! same number of layers above the lowest layer, modulo the height that
//! pieces stack by (their *step*: the greatest common divisor of the box
//! pieces' heights; with slopes, whose grid is half a brick, two layers).
//! A run of voxels up a column whose top (or bottom) falls between steps
//! can then only end in a piece's column that is shorter than the piece:
//! a slope's low front row, which fills the lower half of a course (an
//! inverted slope's, the upper half). The house's ridge at 11 studs with
//! slopes is 17 half layers high and has no taller column beside it for a
//! slope to lean on: no derivation builds it, and the trace would search
//! until its budget ended. [`even`] adds the missing half course on such
//! a run (as the layout evens its courses), and [`uneven`] names a run that
//! still cannot be filled, so the trace says so at once.

use crate::geom::{Body, Cell};
use crate::voxel::VoxelGrid;

/// The height pieces stack by, in layers: the greatest common divisor of
/// the heights of the box-shaped pieces among `shapes` (1 when there are
/// none).
pub(super) fn step(shapes: &[Body]) -> i32 {
    fn gcd(a: i32, b: i32) -> i32 {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
    let g = shapes
        .iter()
        .filter(|s| s.is_box())
        .fold(0, |g, s| gcd(g, s.bbox.sz));
    g.max(1)
}

/// Which end of a column run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum End {
    Top,
    Bottom,
}

/// The column runs of `v` whose `end` falls between steps (the lowest
/// layer of `v` is step 0) and that no piece of `shapes` lying wholly in
/// `v`, at a step, can end there: each as that end's cell.
fn open_ends(v: &VoxelGrid, shapes: &[Body], step: i32, end: End) -> Vec<Cell> {
    let base = v.bounds().map_or(0, |b| b.min.z);
    off_step_ends(v, step, end)
        .into_iter()
        .filter(|&c| short_column_piece(v, shapes, step, base, c, end, None).is_none())
        .collect()
}

/// The cells where the column runs of `v` end (at their `end`) between
/// steps.
fn off_step_ends(v: &VoxelGrid, step: i32, end: End) -> Vec<Cell> {
    let Some(bounds) = v.bounds() else {
        return Vec::new();
    };
    let base = bounds.min.z;
    let on_step = |z: i32| (z - base).rem_euclid(step) == 0;
    let (nx, ny, nz) = v.dims();
    let mut out = Vec::new();
    for y in 0..ny {
        for x in 0..nx {
            let mut z = 0;
            while z < nz {
                if !v.get(Cell::new(x, y, z)) {
                    z += 1;
                    continue;
                }
                let lo = z;
                while z < nz && v.get(Cell::new(x, y, z)) {
                    z += 1;
                }
                let (cell, ok) = match end {
                    End::Top => (Cell::new(x, y, z - 1), on_step(z)),
                    End::Bottom => (Cell::new(x, y, lo), on_step(lo)),
                };
                if !ok {
                    out.push(cell);
                }
            }
        }
    }
    out
}

/// The first piece of `shapes` lying wholly in `v` and in no cell of
/// `taken`, its bottom at a step and its sloping face clear of `v`, that
/// has a column ending (at its `end`) at `c`.
fn short_column_piece(
    v: &VoxelGrid,
    shapes: &[Body],
    step: i32,
    base: i32,
    c: Cell,
    end: End,
    taken: Option<&VoxelGrid>,
) -> Option<Body> {
    let past = match end {
        End::Top => 1,
        End::Bottom => -1,
    };
    shapes.iter().find_map(|s| {
        s.cells().find_map(|q| {
            if s.contains(q.offset(0, 0, past)) {
                return None;
            }
            let b = s.moved(c.x - q.x, c.y - q.y, c.z - q.z);
            let fits = (b.bbox.min.z - base).rem_euclid(step) == 0
                && b.cells()
                    .all(|d| v.get(d) && !taken.is_some_and(|t| t.get(d)))
                && b.bbox.cells().all(|d| b.contains(d) || !v.get(d));
            fits.then_some(b)
        })
    })
}

/// Adds to `v` the half courses its column runs need to end on a step,
/// where no slope can end them and the cells are empty and in the grid:
/// on top of a run, up to the next step; under a run, down to the step
/// below. How many voxels it added.
///
/// The runs are gone over bottom up; each run's end takes the first slope
/// that can end it whose cells no slope taken before holds: two runs
/// either side of a ridge cannot both lean on the ridge's one column, so
/// the second is evened.
pub(super) fn even(v: &mut VoxelGrid, shapes: &[Body]) -> usize {
    let step = step(shapes);
    if step < 2 {
        return 0;
    }
    let Some(bounds) = v.bounds() else {
        return 0;
    };
    let base = bounds.min.z;
    let mut add: Vec<Cell> = Vec::new();
    let (nx, ny, nz) = v.dims();
    let mut held = VoxelGrid::new(nx, ny, nz);
    // The smallest slope first: it holds the fewest cells other runs need.
    let mut small = shapes.to_vec();
    small.sort_by_key(Body::volume);
    for (end, dir) in [(End::Top, 1), (End::Bottom, -1)] {
        let mut ends = off_step_ends(v, step, end);
        ends.sort_by_key(|c| (c.z, c.y, c.x));
        for c in ends {
            if held.get(c) {
                continue;
            }
            if let Some(b) = short_column_piece(v, &small, step, base, c, end, Some(&held)) {
                held.set_body(&b, true);
                continue;
            }
            let mut fill = Vec::new();
            let mut d = c.offset(0, 0, dir);
            loop {
                let at_step = match end {
                    End::Top => (d.z - base).rem_euclid(step) == 0,
                    End::Bottom => (d.z + 1 - base).rem_euclid(step) == 0,
                };
                if at_step {
                    break;
                }
                fill.push(d);
                d = d.offset(0, 0, dir);
            }
            if fill.iter().all(|&f| v.in_bounds(f) && !v.get(f)) {
                add.extend(fill);
            }
        }
    }
    add.sort_by_key(|c| (c.z, c.y, c.x));
    add.dedup();
    for &c in &add {
        v.set(c, true);
    }
    add.len()
}

/// A column run's end that no piece can fill to (the first, bottom up):
/// no derivation builds `v`.
pub(super) fn uneven(v: &VoxelGrid, shapes: &[Body]) -> Option<Cell> {
    let step = step(shapes);
    if step < 2 {
        return None;
    }
    let mut ends: Vec<Cell> = [End::Top, End::Bottom]
        .into_iter()
        .flat_map(|e| open_ends(v, shapes, step, e))
        .collect();
    ends.sort_by_key(|c| (c.z, c.y, c.x));
    ends.first().copied()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::Family;
    use crate::geom::CellBox;
    use crate::grammar::RuleSet;

    fn rules(keep: impl Fn(Family) -> bool) -> RuleSet {
        crate::grammar::default_rules()
            .restricted(|p| keep(p.spec().family()))
            .unwrap()
    }

    /// A roof of half courses, columns `h` half layers high from x = 0 (the
    /// house's at 11 studs: 10, 12, 13, 15, 17, 15, 13, 12, 10).
    fn roof(h: [i32; 9]) -> VoxelGrid {
        let mut v = VoxelGrid::new(9, 3, 20);
        for x in 0..9 {
            let h = h[x as usize];
            v.set_box(
                &CellBox {
                    min: Cell::new(x, 0, 0),
                    sx: 1,
                    sy: 3,
                    sz: h,
                },
                true,
            );
        }
        v
    }

    #[test]
    fn a_ridge_an_odd_half_course_high_is_evened_and_the_slopes_lean_on_it() {
        let rules = rules(|f| f != Family::Plate);
        let shapes = super::super::trace::coverers(&rules);
        assert_eq!(step(&shapes), 2);
        let mut v = roof([10, 12, 13, 15, 17, 15, 13, 12, 10]);
        assert_eq!(uneven(&v, &shapes), Some(Cell::new(4, 0, 16)));
        // The ridge goes up a half layer; the runs of 13 end in a slope's
        // low row leaning on the column of 15 beside them, and the first
        // run of 15 in one leaning on the ridge; the other run of 15
        // cannot lean on the ridge too, and goes up a half layer.
        assert_eq!(even(&mut v, &shapes), 6);
        assert_eq!(v, roof([10, 12, 13, 15, 18, 16, 13, 12, 10]));
        assert_eq!(uneven(&v, &shapes), None);
    }

    #[test]
    fn bricks_alone_stack_by_one_layer() {
        let shapes = super::super::trace::coverers(&rules(|f| f == Family::Brick));
        assert_eq!(step(&shapes), 1);
        let mut v = roof([10, 12, 13, 15, 17, 15, 13, 12, 10]);
        assert_eq!(even(&mut v, &shapes), 0);
        assert_eq!(uneven(&v, &shapes), None);
    }
}
