//! Getting the voxels ready to lay: every island joined to the body, every
//! sheet thick enough to interlock, every flat top a whole course.
//!
//! A layout lays pieces on voxels, and a piece joins others only through
//! studs, so a voxel model must be one body in the sense of touching
//! (corners and edges count: the layout reaches across a diagonal step with
//! a piece that fills a cell just outside the surface). [`repair_islands`]
//! joins every part that does not touch the body to it, by the shortest
//! support column straight down (or up), else by the shortest bridge through
//! empty cells: nothing is dropped. [`thicken_sheets`] gives a layer one
//! brick thin a second one (bricks side by side in one layer cannot hold
//! together), and [`even_courses`] tops columns up to whole courses when
//! layers are half a brick.

use std::collections::VecDeque;

use serde::Serialize;

use crate::geom::Cell;
use crate::voxel::{Slant, VoxelGrid};

/// Islands past this many are left out rather than bridged through empty
/// space one breadth-first search each (supports straight down or up are
/// always tried): a guard on hostile input, never reached by real meshes.
const MAX_BRIDGES: usize = 256;

/// A place where voxels were left out, and why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct LeftOut {
    /// The lowest layer of the voxels left out there.
    pub layer: i32,
    /// Stud column of their first voxel.
    pub x: i32,
    /// Stud row of their first voxel.
    pub y: i32,
    /// How many voxels.
    pub voxels: usize,
    /// Why.
    pub reason: String,
}

/// What the repairs changed, for the report.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Repairs {
    /// Islands (parts not touching the rest) joined to the model by a
    /// support column or a bridge.
    pub joined_islands: usize,
    /// Voxels added as support columns and bridges.
    pub support_voxels: usize,
    /// Voxels added to make one-layer sheets two layers thick (bricks side by
    /// side in one layer cannot hold together).
    pub thickened_voxels: usize,
    /// Voxels added to bring flat tops up to a whole brick course (with
    /// slopes, layers are half a brick, and a column half a course short
    /// could only be filled by a slope).
    pub evened_voxels: usize,
    /// Cells just outside the voxels that pieces fill to join a feature one
    /// voxel thin to the rest (a handle's diagonal step, a ring).
    pub extra_cells: usize,
    /// Voxels left out: nothing could join them to the build.
    pub left_out: usize,
    /// Where they are (at most 50 places), and why.
    pub left_out_places: Vec<LeftOut>,
    /// Voxels of the layers the search had no time left for.
    pub budget_left_out: usize,
}

impl Repairs {
    /// Whether the voxels were built as given.
    pub fn is_empty(&self) -> bool {
        *self == Repairs::default()
    }

    /// Records `voxels` left out at `at` for `reason` (the place is kept
    /// while fewer than 50 are).
    pub fn leave_out(&mut self, at: Cell, voxels: usize, reason: &str) {
        self.left_out += voxels;
        if self.left_out_places.len() < 50 {
            self.left_out_places.push(LeftOut {
                layer: at.z,
                x: at.x,
                y: at.y,
                voxels,
                reason: reason.to_string(),
            });
        }
    }
}

/// The six face neighbours of `c`.
pub(crate) fn neighbors6(c: Cell) -> [Cell; 6] {
    [
        c.offset(1, 0, 0),
        c.offset(-1, 0, 0),
        c.offset(0, 1, 0),
        c.offset(0, -1, 0),
        c.offset(0, 0, 1),
        c.offset(0, 0, -1),
    ]
}

/// The 26 neighbours of `c`: faces, edges and corners.
fn neighbors26(c: Cell) -> impl Iterator<Item = Cell> {
    (-1..=1).flat_map(move |dz| {
        (-1..=1).flat_map(move |dy| {
            (-1..=1)
                .filter(move |&dx| (dx, dy, dz) != (0, 0, 0))
                .map(move |dx| c.offset(dx, dy, dz))
        })
    })
}

/// Touching components of `g` (cells sharing a face, an edge or a corner),
/// largest first (ties by first cell).
pub fn components(g: &VoxelGrid) -> Vec<Vec<Cell>> {
    let mut seen = vec![false; g.len()];
    let mut comps: Vec<Vec<Cell>> = Vec::new();
    for c in g.cells() {
        if seen[g.index(c)] {
            continue;
        }
        seen[g.index(c)] = true;
        let mut comp = vec![c];
        let mut k = 0;
        while k < comp.len() {
            for n in neighbors26(comp[k]) {
                if g.get(n) && !seen[g.index(n)] {
                    seen[g.index(n)] = true;
                    comp.push(n);
                }
            }
            k += 1;
        }
        comps.push(comp);
    }
    comps.sort_by(|a, b| b.len().cmp(&a.len()).then(a[0].cmp(&b[0])));
    comps
}

/// Joins every island to the model's largest body, so the voxels are one
/// touching body; an island nothing can reach is left out and reported.
pub fn repair_islands(v: &VoxelGrid) -> (VoxelGrid, Repairs) {
    let mut out = v.clone();
    let mut rep = Repairs::default();
    let comps = components(v);
    if comps.len() <= 1 {
        return (out, rep);
    }
    let (nx, ny, nz) = v.dims();
    // `joined` holds the main body and every island joined so far.
    let mut joined = VoxelGrid::new(nx, ny, nz);
    for &c in &comps[0] {
        joined.set(c, true);
    }
    let mut pending: Vec<&Vec<Cell>> = comps[1..].iter().collect();
    let mut bridges = 0;
    while !pending.is_empty() {
        let mut progress = false;
        let mut i = 0;
        while i < pending.len() {
            let island = pending[i];
            let touching = island
                .iter()
                .any(|&c| neighbors26(c).any(|n| joined.get(n)));
            let link = if touching {
                Some(Vec::new())
            } else {
                shortest_support(island, &joined, &out)
            };
            if let Some(col) = link {
                join(island, &col, &mut out, &mut joined, &mut rep);
                pending.remove(i);
                progress = true;
                continue;
            }
            i += 1;
        }
        if progress {
            continue;
        }
        // No column reaches: bridge the nearest island through empty cells.
        let bridge = (bridges < MAX_BRIDGES)
            .then(|| shortest_bridge(&pending, &joined, &out))
            .flatten();
        let Some((k, path)) = bridge else {
            for island in pending.drain(..) {
                for &c in island {
                    out.set(c, false);
                }
                rep.leave_out(island[0], island.len(), "an island nothing can reach");
            }
            break;
        };
        bridges += 1;
        let island = pending.remove(k);
        join(island, &path, &mut out, &mut joined, &mut rep);
    }
    (out, rep)
}

fn join(
    island: &[Cell],
    link: &[Cell],
    out: &mut VoxelGrid,
    joined: &mut VoxelGrid,
    rep: &mut Repairs,
) {
    for &c in link {
        out.set(c, true);
        joined.set(c, true);
    }
    for &c in island {
        joined.set(c, true);
    }
    rep.joined_islands += 1;
    rep.support_voxels += link.len();
}

/// The shortest vertical run of empty cells linking `island` to `joined`,
/// looking straight down from its cells first, then straight up.
fn shortest_support(island: &[Cell], joined: &VoxelGrid, all: &VoxelGrid) -> Option<Vec<Cell>> {
    let (_, _, nz) = all.dims();
    let mut best: Option<Vec<Cell>> = None;
    for dir in [-1, 1] {
        for &c in island {
            let mut gap = Vec::new();
            let mut z = c.z + dir;
            let mut hit = false;
            while z >= 0 && z < nz {
                let p = Cell::new(c.x, c.y, z);
                if joined.get(p) {
                    hit = true;
                    break;
                }
                if all.get(p) {
                    break; // its own island or another one: not a support
                }
                gap.push(p);
                z += dir;
            }
            if hit && !gap.is_empty() && best.as_ref().is_none_or(|b| gap.len() < b.len()) {
                best = Some(gap);
            }
        }
        if best.is_some() {
            return best;
        }
    }
    best
}

/// The shortest path of empty cells from `joined` to one of the `pending`
/// islands (a breadth-first search over face neighbours from the whole
/// joined body at once): the island's index and the path's cells.
fn shortest_bridge(
    pending: &[&Vec<Cell>],
    joined: &VoxelGrid,
    all: &VoxelGrid,
) -> Option<(usize, Vec<Cell>)> {
    let mut island_of = vec![u32::MAX; all.len()];
    for (k, island) in pending.iter().enumerate() {
        for &c in island.iter() {
            island_of[all.index(c)] = k as u32;
        }
    }
    let mut from = vec![u32::MAX; all.len()];
    let mut queue = VecDeque::new();
    for c in joined.cells() {
        from[all.index(c)] = all.index(c) as u32;
        queue.push_back(c);
    }
    while let Some(c) = queue.pop_front() {
        for n in neighbors6(c) {
            if !all.in_bounds(n) || from[all.index(n)] != u32::MAX {
                continue;
            }
            from[all.index(n)] = all.index(c) as u32;
            let k = island_of[all.index(n)];
            if k != u32::MAX {
                // Walk back to the body: the empty cells in between.
                let mut path = Vec::new();
                let mut at = all.index(c);
                while !joined.get(cell_at(all, at)) {
                    path.push(cell_at(all, at));
                    at = from[at] as usize;
                }
                return Some((k as usize, path));
            }
            if !all.get(n) {
                queue.push_back(n);
            }
        }
    }
    None
}

/// The cell of grid index `i`.
fn cell_at(g: &VoxelGrid, i: usize) -> Cell {
    let (nx, ny, _) = g.dims();
    let (nx, ny) = (nx as usize, ny as usize);
    Cell::new(
        (i % nx) as i32,
        (i / nx % ny) as i32,
        (i / (nx * ny)) as i32,
    )
}

/// Makes one-layer sheets two layers thick: a voxel with nothing directly
/// above or below it can only join a build through a brick that also covers
/// a neighbour with something above or below, and a sheet one layer thick
/// (the bottom layer of a model, a mug's floor, a fin) cannot hold together
/// at all. Such voxels get the voxel above them (below, at the grid's top).
pub fn thicken_sheets(v: &mut VoxelGrid, rep: &mut Repairs, min_thick: i32) {
    let (nx, ny, nz) = v.dims();
    if nz < min_thick {
        return;
    }
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
                // A run thinner than `min_thick` grows upward, or downward
                // where the grid ends.
                let mut top = z;
                let mut bottom = lo;
                while top - bottom < min_thick {
                    if top < nz {
                        v.set(Cell::new(x, y, top), true);
                        top += 1;
                    } else {
                        bottom -= 1;
                        v.set(Cell::new(x, y, bottom), true);
                    }
                    rep.thickened_voxels += 1;
                }
                z = top;
            }
        }
    }
}

/// Makes every column run of `v` a whole number of `course` layers, by
/// adding layers on top, except where the run's top cell lies on an
/// up-facing slanted surface (`slant`): a slope's lower front row fills half
/// a course there. Counted in `rep.evened_voxels`.
pub fn even_courses(v: &mut VoxelGrid, slant: Option<&Slant>, course: i32, rep: &mut Repairs) {
    if course < 2 {
        return;
    }
    let (nx, ny, nz) = v.dims();
    let slanted = |c: Cell| slant.is_some_and(|s| s.up.iter().any(|g| g.get(c)));
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
                let short = (course - (z - lo) % course) % course;
                let top = Cell::new(x, y, z - 1);
                if short == 0 || slanted(top) || slanted(top.offset(0, 0, 1)) {
                    continue;
                }
                let room = (z..z + short).all(|k| k < nz && !v.get(Cell::new(x, y, k)));
                if room {
                    for k in z..z + short {
                        v.set(Cell::new(x, y, k), true);
                        rep.evened_voxels += 1;
                    }
                    z += short;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::CellBox;

    fn grid_with(boxes: &[CellBox]) -> VoxelGrid {
        let mut g = VoxelGrid::new(12, 12, 12);
        for b in boxes {
            g.set_box(b, true);
        }
        g
    }

    fn bx(x: i32, y: i32, z: i32, sx: i32, sy: i32, sz: i32) -> CellBox {
        CellBox {
            min: Cell::new(x, y, z),
            sx,
            sy,
            sz,
        }
    }

    #[test]
    fn islands_are_propped_or_bridged_never_dropped() {
        // A base, an island over it (a column), a speck beside it in the air
        // at the grid's top (a bridge), and a cell touching the base at a
        // corner (no island: the layout reaches across).
        let g = grid_with(&[
            bx(0, 0, 0, 6, 6, 2),
            bx(1, 1, 5, 3, 3, 2),
            bx(10, 10, 11, 1, 1, 1),
            bx(6, 6, 2, 1, 1, 1),
        ]);
        let (fixed, rep) = repair_islands(&g);
        assert_eq!(rep.left_out, 0);
        assert_eq!(rep.joined_islands, 2);
        assert_eq!(components(&fixed).len(), 1);
        // The column is 3 cells; the speck's path is the rest.
        assert!(rep.support_voxels >= 3 + 8, "{rep:?}");
        assert_eq!(fixed.count(), g.count() + rep.support_voxels);
    }

    #[test]
    fn corner_touching_cells_are_one_body() {
        let mut g = VoxelGrid::new(4, 4, 4);
        for i in 0..4 {
            g.set(Cell::new(i, 0, i), true);
        }
        assert_eq!(components(&g).len(), 1);
        let (fixed, rep) = repair_islands(&g);
        assert_eq!(fixed, g);
        assert!(rep.is_empty());
    }

    #[test]
    fn one_layer_sheets_get_a_second_layer() {
        // A thick block with a one-layer fin sticking out at its top layer.
        let mut g = grid_with(&[bx(0, 0, 0, 3, 3, 3), bx(3, 0, 2, 4, 1, 1)]);
        let mut rep = Repairs::default();
        thicken_sheets(&mut g, &mut rep, 2);
        assert_eq!(rep.thickened_voxels, 4);
        assert!((3..7).all(|x| g.get(Cell::new(x, 0, 3))));
        // Nothing bare is left, so a second pass changes nothing.
        let before = g.clone();
        thicken_sheets(&mut g, &mut rep, 2);
        assert_eq!(g, before);
    }
}
