//! Whether a new piece can be put in place: the paper's flood fill.
//!
//! Before a rule is applied in reverse, the new piece must be able to reach
//! its place past what is already built (paper, section 4: "we check that
//! there is space below or above the new piece(s) and that the space is
//! not completely enclosed ... by flood filling the empty space of the
//! voxel grid with the padded piece until it reaches some boundary or it
//! is completely enclosed"). The piece's box is moved a cell at a time
//! through empty cells, from its place, until it is clear of the grid
//! (placeable) or no move is left (enclosed), by the moves the verifier
//! allows ([`crate::assembly::verify`]): up and down freely, sideways only
//! with the layers just above and below the box clear (the half voxel of
//! padding its studs need), so the trace never makes a build the verifier
//! refuses. Moving whole cells is the padding: a box never slips through a
//! gap narrower than itself, nor past a corner it would graze. The straight
//! paths, up and down, are tried first: they are nearly always the answer.

use std::collections::{HashSet, VecDeque};

use crate::assembly::verify::{escape, Escape};
use crate::geom::{Cell, CellBox};
use crate::voxel::VoxelGrid;

/// The most positions one flood fill visits before it calls the piece
/// enclosed (a box in a hollow far bigger than any model of this size).
const MAX_VISITED: usize = 200_000;

/// The box of `sx` by `sy` by `sz` cells from `min`.
fn bx(min: Cell, sx: i32, sy: i32, sz: i32) -> CellBox {
    CellBox { min, sx, sy, sz }
}

/// Whether the box `b` can be pressed into its place from above
/// (`from_above`, a piece pressed onto studs below it) or from below,
/// through cells `solid` leaves empty: the cell layer beside it that way
/// is empty, and from there the box travels out of the grid.
#[cfg(test)]
pub(super) fn placeable(b: &CellBox, solid: &VoxelGrid, from_above: bool) -> bool {
    placeable_in(b, solid, from_above, None)
}

/// Whether the box `b` can be pressed into its place (as `placeable`),
/// with `air` (if given) the empty cells of `solid` with `b`'s piece in it
/// that reach the space beside the grid or above it ([`air`]): the same
/// answer, found without a flood fill where the piece may pass under the
/// build.
pub(super) fn placeable_in(
    b: &CellBox,
    solid: &VoxelGrid,
    from_above: bool,
    air: Option<&VoxelGrid>,
) -> bool {
    let open = |b: &CellBox, solid: &VoxelGrid| match air {
        Some(a) => open_to(b, a),
        None => open(b, solid),
    };
    let clear = |at: &CellBox| !solid.any_set(at);
    let (nx, ny, nz) = solid.dims();
    // Straight up or straight down.
    let column = |from: i32, to: i32| {
        bx(
            Cell::new(b.min.x, b.min.y, from.max(0)),
            b.sx,
            b.sy,
            (to.min(nz) - from.max(0)).max(0),
        )
    };
    let straight = if from_above {
        column(b.min.z + b.sz, nz)
    } else {
        column(0, b.min.z)
    };
    if clear(&straight) {
        // Straight up it is out; straight down it passes under the build,
        // which is no way in from a cavity the build shuts on every side.
        return from_above || open(b, solid);
    }
    // The box one cell that way must be free: it is pressed on last.
    let dz = if from_above { 1 } else { -1 };
    let first = bx(b.min.offset(0, 0, dz), b.sx, b.sy, b.sz);
    if !clear(&first) {
        return false;
    }
    // From there, the verifier's own moves: up and down freely, sideways a
    // stud at a time with the studs clear above and below. It may pass
    // under the build only to a place open to the side or above.
    let (lo, hi) = (Cell::new(0, 0, 0), Cell::new(nx - 1, ny - 1, nz - 1));
    let out = escape(b, lo, hi, |x| solid.any_set(x), MAX_VISITED);
    out == Escape::Out && open(b, solid)
}

/// Whether the cells of `b` are joined, face to face through cells
/// `solid` leaves empty, to the space beside the grid or above it (not
/// below: the build stands on the table). A place shut in on every side
/// by what is built (a hollow's inside under its closed shell) is not,
/// though a box may pass under the ground to reach it.
fn open(b: &CellBox, solid: &VoxelGrid) -> bool {
    let (nx, ny, nz) = solid.dims();
    let mut seen: HashSet<Cell> = b.cells().collect();
    let mut queue: VecDeque<Cell> = b.cells().collect();
    while let Some(c) = queue.pop_front() {
        for (dx, dy, dz) in crate::geom::FACES {
            let n = Cell::new(c.x + dx, c.y + dy, c.z + dz);
            if n.z < 0 || seen.contains(&n) {
                continue;
            }
            if n.x < 0 || n.y < 0 || n.x >= nx || n.y >= ny || n.z >= nz {
                return true;
            }
            if !solid.get(n) {
                seen.insert(n);
                queue.push_back(n);
            }
        }
    }
    false
}

/// The empty cells of `solid` joined, face to face through empty cells,
/// to the space beside the grid or above it (not below: the build stands
/// on the table): what [`open`] floods to.
pub(super) fn air(solid: &VoxelGrid) -> VoxelGrid {
    let (nx, ny, nz) = solid.dims();
    let mut seen = VoxelGrid::new(nx, ny, nz);
    let mut stack: Vec<Cell> = Vec::new();
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let edge = x == 0 || y == 0 || x == nx - 1 || y == ny - 1 || z == nz - 1;
                let c = Cell::new(x, y, z);
                if edge && !solid.get(c) {
                    seen.set(c, true);
                    stack.push(c);
                }
            }
        }
    }
    while let Some(c) = stack.pop() {
        for (dx, dy, dz) in crate::geom::FACES {
            let n = Cell::new(c.x + dx, c.y + dy, c.z + dz);
            if solid.in_bounds(n) && !solid.get(n) && !seen.get(n) {
                seen.set(n, true);
                stack.push(n);
            }
        }
    }
    seen
}

/// [`open`] from [`air`]: a cell of the box beside the grid (not below it)
/// or next to a cell of the air outside the box. A flood from the box
/// leaves it last at such a cell, and from there on passes only cells
/// empty with the piece in place.
fn open_to(b: &CellBox, air: &VoxelGrid) -> bool {
    let (nx, ny, nz) = air.dims();
    let m = b.max_excl();
    if b.min.x == 0 || b.min.y == 0 || m.x >= nx || m.y >= ny || m.z >= nz {
        return true;
    }
    // The cells beside each face of the box (not its edges: a flood moves
    // face to face), under it only above the table.
    let (x, y, z) = (b.min.x, b.min.y, b.min.z);
    let faces = [
        bx(Cell::new(x - 1, y, z), 1, b.sy, b.sz),
        bx(Cell::new(m.x, y, z), 1, b.sy, b.sz),
        bx(Cell::new(x, y - 1, z), b.sx, 1, b.sz),
        bx(Cell::new(x, m.y, z), b.sx, 1, b.sz),
        bx(Cell::new(x, y, m.z), b.sx, b.sy, 1),
        bx(Cell::new(x, y, z - 1), b.sx, b.sy, 1),
    ];
    faces.iter().any(|f| air.any_set(f))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(cells: &[(i32, i32, i32)]) -> VoxelGrid {
        let mut g = VoxelGrid::new(5, 5, 6);
        for &(x, y, z) in cells {
            g.set(Cell::new(x, y, z), true);
        }
        g
    }

    #[test]
    fn a_piece_under_a_roof_slides_out_sideways_but_not_from_a_closed_box() {
        let b = bx(Cell::new(2, 2, 2), 1, 1, 1);
        // A roof just above: not pressed on from above.
        let g = grid(&[(2, 2, 3), (2, 2, 1)]);
        assert!(!placeable(&b, &g, true));
        // A roof higher up and a floor below: lowered to the layer over its
        // place, studs clear above and below, it slides out to the side.
        let g = grid(&[(2, 2, 4), (2, 2, 1)]);
        assert!(!placeable(&b, &g, true), "the roof just over the slide");
        let g = grid(&[(2, 2, 5), (2, 2, 1)]);
        assert!(placeable(&b, &g, true));
        assert!(!placeable(&b, &g, false));
        // A roof above and nothing below: pushed up from under it.
        let g = grid(&[(2, 2, 3)]);
        assert!(placeable(&b, &g, false));
        // Walled in on all six sides: enclosed.
        let g = grid(&[
            (2, 2, 3),
            (2, 2, 1),
            (1, 2, 2),
            (3, 2, 2),
            (2, 1, 2),
            (2, 3, 2),
        ]);
        assert!(!placeable(&b, &g, true));
        // A 2-wide piece does not pass a 1-wide gap.
        let wide = bx(Cell::new(1, 2, 2), 2, 1, 1);
        let mut g = VoxelGrid::new(5, 5, 5);
        for x in 0..5 {
            for y in 0..5 {
                if !(y == 2 && (1..=2).contains(&x)) {
                    g.set(Cell::new(x, y, 2), true);
                }
                g.set(Cell::new(x, y, 1), true);
                if x != 2 || y != 2 {
                    g.set(Cell::new(x, y, 3), true);
                }
            }
        }
        assert!(!placeable(&wide, &g, true));
        assert!(placeable(&bx(Cell::new(2, 2, 2), 1, 1, 1), &g, true));
    }

    #[test]
    fn a_piece_shut_in_on_the_table_cannot_come_in_from_under_the_build() {
        // A 1x1 at the bottom, walled in on four sides and covered.
        let b = bx(Cell::new(2, 2, 0), 1, 1, 1);
        let g = grid(&[(1, 2, 0), (3, 2, 0), (2, 1, 0), (2, 3, 0), (2, 2, 1)]);
        assert!(!placeable(&b, &g, false));
        // With a side open, it comes in from below (under an overhang).
        let g = grid(&[(1, 2, 0), (3, 2, 0), (2, 1, 0), (2, 2, 1)]);
        assert!(placeable(&b, &g, false));
    }

    #[test]
    fn the_air_test_agrees_with_the_flood_fill() {
        // Random builds in a small grid: for every box of 1 to 2 cells a
        // side, emptied of its cells as the trace empties a piece's, the
        // two tests agree.
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) as u32
        };
        let mut checked = 0;
        for _ in 0..40 {
            let mut g = VoxelGrid::new(5, 4, 4);
            for z in 0..4 {
                for y in 0..4 {
                    for x in 0..5 {
                        if next() % 100 < 60 {
                            g.set(Cell::new(x, y, z), true);
                        }
                    }
                }
            }
            for (sx, sy, sz) in [(1, 1, 1), (2, 1, 1), (1, 2, 2), (2, 2, 1)] {
                for z in 0..=4 - sz {
                    for y in 0..=4 - sy {
                        for x in 0..=5 - sx {
                            let b = bx(Cell::new(x, y, z), sx, sy, sz);
                            let mut with = g.clone();
                            with.set_box(&b, true);
                            let a = air(&with);
                            let mut solid = with.clone();
                            solid.set_box(&b, false);
                            assert_eq!(open(&b, &solid), open_to(&b, &a), "{b:?}");
                            for up in [true, false] {
                                assert_eq!(
                                    placeable(&b, &solid, up),
                                    placeable_in(&b, &solid, up, Some(&a))
                                );
                            }
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 1000);
    }
}
