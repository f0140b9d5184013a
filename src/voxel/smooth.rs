//! Smoothing of a model's surface colours before the layout.
//!
//! A texture sampled at a few voxels a stud leaves specks (one voxel of a
//! colour in a field of another) and ragged boundaries (a region's edge
//! that steps in and out from course to course). Each speck cuts the
//! pieces of its course in two, and each tooth of a boundary leaves a
//! 1 x 1 brick; neither is a shape the model has. The filter takes them
//! out before the layout and keeps every region that is more than a
//! speck, so that the build still shows the model's own colour on nearly
//! all of its surface (the report measures that against the colours as
//! sampled, before this filter).
//!
//! The filter is a mode filter on the surface: each surface voxel looks at
//! its surface neighbours (the 26 around it that are surface voxels too)
//! and takes the colour most of them have when its own colour is all but
//! missing among them. Every voxel is decided from the colours of the pass
//! before, so the result does not depend on the order voxels are visited.
//! It recolours at most 2% of the surface, the most isolated voxels first,
//! which leaves the layout most of the 5% of the surface it may show in
//! another colour. (On engine.glb at 32 studs, 2% took about 9 pieces in
//! 350 away and a fifth of the 1 x 1 bricks.)

use crate::catalog::Color;
use crate::geom::Cell;

use super::VoxelGrid;

/// Passes of the filter. Each pass also shortens a line one voxel wide by
/// a voxel at each end, so few passes keep thin lines that are real.
const PASSES: usize = 2;

/// The most surface voxels the filter may recolour, in thousandths of the
/// surface: every one it changes shows a colour the model does not have
/// there, and the build must show the model's own colour on 95% of its
/// surface, the layout's own slack included.
const BUDGET_PER_MILLE: usize = 20;

/// Smooths the colours of the surface voxels of `grid` in place
/// (`cells` and `surface` indexed by [`VoxelGrid::index`]). Returns how
/// many voxels changed colour.
///
/// Within the budget, the most isolated voxels go first: those sharing
/// their colour with no neighbour, then with one; among those, the ones
/// whose neighbours agree most on another colour.
pub fn smooth(grid: &VoxelGrid, cells: &mut [Option<Color>], surface: &[bool]) -> usize {
    let (nx, ny, nz) = grid.dims();
    let mut budget = surface.iter().filter(|&&s| s).count() * BUDGET_PER_MILLE / 1000;
    let mut changed = 0;
    for _ in 0..PASSES {
        let mut found: Vec<Change> = Vec::new();
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let c = Cell::new(x, y, z);
                    let i = grid.index(c);
                    let Some(own) = cells[i].filter(|_| surface[i]) else {
                        continue;
                    };
                    found.extend(
                        verdict(grid, cells, surface, c, own).map(|v| Change { at: i, ..v }),
                    );
                }
            }
        }
        if found.is_empty() || budget == 0 {
            break;
        }
        // Decided from the colours before the pass, so the order voxels are
        // visited in does not matter; ties by cell index.
        found.sort_by_key(|v| (v.mine, std::cmp::Reverse(v.agree), v.at));
        found.truncate(budget);
        budget -= found.len();
        changed += found.len();
        for v in found {
            cells[v.at] = Some(v.to);
        }
    }
    changed
}

/// A surface voxel to recolour.
#[derive(Debug, Clone, Copy)]
struct Change {
    /// Its index in the grid.
    at: usize,
    /// Its new colour.
    to: Color,
    /// Neighbours of its own colour.
    mine: u32,
    /// Neighbours of the new colour.
    agree: u32,
}

/// How the surface voxel `c` (of colour `own`) changes, if it does (the
/// returned `at` is left 0).
fn verdict(
    grid: &VoxelGrid,
    cells: &[Option<Color>],
    surface: &[bool],
    c: Cell,
    own: Color,
) -> Option<Change> {
    // At most 26 neighbours; a handful of colours among them.
    let mut tally: Vec<(Color, u32)> = Vec::with_capacity(4);
    let mut total = 0;
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                if (dx, dy, dz) == (0, 0, 0) {
                    continue;
                }
                let n = c.offset(dx, dy, dz);
                if !grid.in_bounds(n) {
                    continue;
                }
                let j = grid.index(n);
                let Some(col) = cells[j].filter(|_| surface[j]) else {
                    continue;
                };
                total += 1;
                match tally.iter_mut().find(|(k, _)| *k == col) {
                    Some(e) => e.1 += 1,
                    None => tally.push((col, 1)),
                }
            }
        }
    }
    let mine = tally.iter().find(|(k, _)| *k == own).map_or(0, |e| e.1);
    let (best, n) = tally
        .iter()
        .filter(|(k, _)| *k != own)
        .copied()
        .max_by_key(|&(k, n)| (n, std::cmp::Reverse(k)))?;
    (mine <= 1 && 2 * n >= total).then_some(Change {
        at: 0,
        to: best,
        mine,
        agree: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::CellBox;

    /// A wall one voxel thick (every voxel on the surface), red, with a
    /// white speck and a 2 x 2 yellow patch.
    fn wall() -> (VoxelGrid, Vec<Option<Color>>, Vec<bool>) {
        let mut g = VoxelGrid::new(40, 1, 20);
        g.set_box(
            &CellBox {
                min: Cell::new(0, 0, 0),
                sx: 40,
                sy: 1,
                sz: 20,
            },
            true,
        );
        let mut cells = vec![Some(Color::RED); g.len()];
        cells[g.index(Cell::new(5, 0, 5))] = Some(Color::WHITE);
        for (x, z) in [(20, 10), (21, 10), (20, 11), (21, 11)] {
            cells[g.index(Cell::new(x, 0, z))] = Some(Color(14));
        }
        (g, cells, vec![true; 800])
    }

    #[test]
    fn a_speck_takes_its_neighbours_colour_and_a_patch_stays() {
        let (g, mut cells, surface) = wall();
        assert_eq!(smooth(&g, &mut cells, &surface), 1);
        assert_eq!(cells[g.index(Cell::new(5, 0, 5))], Some(Color::RED));
        assert_eq!(cells[g.index(Cell::new(21, 0, 11))], Some(Color(14)));
        assert_eq!(cells.iter().filter(|&&c| c == Some(Color(14))).count(), 4);
    }

    #[test]
    fn the_budget_takes_the_most_isolated_first() {
        let (g, mut cells, surface) = wall();
        // 21 specks and a pair are more than 2% of 800 voxels: 16 of the
        // specks go, the pair stays.
        for k in 0..20 {
            cells[g.index(Cell::new(2 + (k % 10) * 3, 0, 2 + (k / 10) * 14))] = Some(Color::WHITE);
        }
        cells[g.index(Cell::new(37, 0, 8))] = Some(Color::WHITE);
        cells[g.index(Cell::new(37, 0, 9))] = Some(Color::WHITE);
        assert_eq!(smooth(&g, &mut cells, &surface), 16);
        assert_eq!(cells[g.index(Cell::new(37, 0, 8))], Some(Color::WHITE));
    }
}
