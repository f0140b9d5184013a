//! Hollow models: a shell of the voxels near the outside, the rest left
//! empty.
//!
//! A solid build spends most of its pieces where no one sees them. Builders
//! of big models build a shell instead, and so does [`hollow`]: a voxel is
//! kept when an outside cell lies within the wall's thickness of it, in its
//! own layer (`wall` studs, chessboard distance, so a wall is as thick along
//! a diagonal as along an axis) or in its own column (`wall` courses up or
//! down). Everything else is emptied, and those cells must stay empty: the
//! layout never fills them.
//!
//! - Thin parts stay solid: each of their voxels is near the outside.
//! - The ground is not the outside: a model standing on the table has no
//!   floor over it, as a person builds a big hollow model (the table is the
//!   floor, and the shell is closed all the same).
//! - A lid over the hollow is at least as thick as the thinnest sheet that
//!   holds together (two courses of bricks side by side do, one does not).
//! - No floor thinner than a lid is left on the table under the hollow
//!   (where the lowest layer of a foot keeps a pocket too narrow to empty):
//!   it is emptied too, unless it is all that stands there (a pedestal),
//!   which is made as thick as a lid instead.
//! - Pockets narrower than [`MIN_HOLE`] studs are filled again: a slot
//!   under a ridge costs more pieces, short ones bridging it, than it
//!   saves.
//! - Nothing of the shell hangs over the hollow with nothing under it: a
//!   part of a layer's shell none of whose cells has shell under it, over
//!   the hollow (the walls of a tier set back on the tier below, whose
//!   middle is hollow), gets a lid under it: the hollow it lies over is
//!   filled again for a lid's thickness, across the whole stretch of
//!   hollow in each of those layers, so the lid rests on the walls below.
//! - Nothing of the shell stands under the hollow with nothing over it: a
//!   part of a layer's shell none of whose cells has shell over it, under
//!   the hollow (the rim of a pedestal under a wider body), gets a lid
//!   over it, as a part hanging over the hollow gets one under it.
//!
//! What holds a lid or a roof over the hollow is decided later, by the
//! stability stage, which adds inner pillars where the statics need them.
//!
//! ```
//! use brickwright::voxel::{hollow, VoxelGrid, Wall};
//! use brickwright::geom::{Cell, CellBox};
//!
//! let mut solid = VoxelGrid::new(10, 10, 10);
//! let all = CellBox { min: Cell::new(0, 0, 0), sx: 10, sy: 10, sz: 10 };
//! solid.set_box(&all, true);
//! let h = hollow(&solid, Wall::new(2).unwrap(), 1, 2);
//! // 6 x 6 studs inside the walls, from the ground to under the 2-course lid.
//! assert_eq!(h.emptied.count(), 6 * 6 * 8);
//! assert_eq!(h.shell.count() + h.emptied.count(), 1000);
//! ```

use serde::Serialize;

use super::VoxelGrid;
use crate::geom::Cell;

/// The narrowest hollow, in studs both ways: a narrower pocket is filled
/// again, as a slot under a ridge or between two walls costs more pieces
/// (short ones, bridging it) than it saves.
pub const MIN_HOLE: i32 = 4;

/// The thickest wall `--wall` takes, in studs.
pub const MAX_WALL: u32 = 16;

/// A shell's wall thickness: studs horizontally, courses vertically.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Wall(u32);

impl Wall {
    /// The default, two studs: the wall bricks overlap across its
    /// thickness, and a lid of two courses holds together.
    pub const DEFAULT: Wall = Wall(2);

    /// A wall `n` studs thick, 1 to [`MAX_WALL`].
    pub fn new(n: u32) -> Option<Wall> {
        (1..=MAX_WALL).contains(&n).then_some(Wall(n))
    }

    /// Its thickness in studs (and in courses).
    pub fn studs(self) -> u32 {
        self.0
    }
}

impl Default for Wall {
    fn default() -> Self {
        Wall::DEFAULT
    }
}

/// A hollowed model.
#[derive(Debug, Clone)]
pub struct Hollowed {
    /// The voxels kept: the shell.
    pub shell: VoxelGrid,
    /// The voxels emptied: no piece may fill them.
    pub emptied: VoxelGrid,
}

/// The shell of `solid` with walls `wall` thick: `course` layers make a
/// course, and a lid over the hollow is at least `min_lid` layers thick.
pub fn hollow(solid: &VoxelGrid, wall: Wall, course: i32, min_lid: i32) -> Hollowed {
    let (nx, ny, nz) = solid.dims();
    let n = wall.studs() as i32;
    let up = (n * course.max(1)).max(min_lid);
    let across = horizontal_depth(solid);
    let mut inner = VoxelGrid::new(nx, ny, nz);
    for c in solid.cells() {
        if across[solid.index(c)] > n && deep_in_column(solid, c, up) {
            inner.set(c, true);
        }
    }
    let mut emptied = open_square(&inner);
    let mut shell = solid.clone();
    for c in emptied.cells() {
        shell.set(c, false);
    }
    no_thin_floor(&mut shell, &mut emptied, min_lid);
    lid_under_hanging(&mut shell, &mut emptied, up);
    lid_over_standing(&mut shell, &mut emptied, up);
    Hollowed { shell, emptied }
}

/// Mends the shell standing on the table under the hollow where it is
/// thinner than `min_lid` layers (a floor that does not hold together): a
/// pocket too narrow to empty in a low layer (a foot rounded at the bottom
/// is narrower there than above) left a floor a course thick under the
/// hollow, whose pieces could join nothing above them (the hollow) nor
/// below (the table), and the layout left them out (the bunny at 72 studs,
/// `--hollow`: 8 voxels). A stretch of such floor beside shell that goes on
/// up (the foot's wall) is emptied: the table is the floor there, as
/// everywhere under the hollow. A stretch with none beside it is all that
/// stands there (a pedestal under a wider body): it is thickened instead,
/// the hollow over it filled again to a lid's thickness, so that its upper
/// layer lies beside the shell around it.
fn no_thin_floor(shell: &mut VoxelGrid, emptied: &mut VoxelGrid, min_lid: i32) {
    let (nx, ny, nz) = shell.dims();
    let lid = min_lid.min(nz);
    // Per column: the floor's thickness where it is thin under the hollow.
    let mut thin = vec![0i32; (nx * ny) as usize];
    for y in 0..ny {
        for x in 0..nx {
            let floor = (0..lid)
                .take_while(|&z| shell.get(Cell::new(x, y, z)))
                .count() as i32;
            if floor > 0 && floor < lid && emptied.get(Cell::new(x, y, floor)) {
                thin[(y * nx + x) as usize] = floor;
            }
        }
    }
    let mut seen = vec![false; thin.len()];
    for start in 0..thin.len() {
        if thin[start] == 0 || seen[start] {
            continue;
        }
        // One stretch of thin floor, side by side in the lowest layer.
        seen[start] = true;
        let mut stretch = vec![start];
        let mut beside_wall = false;
        let mut k = 0;
        while k < stretch.len() {
            let i = stretch[k] as i32;
            k += 1;
            for (dx, dy) in SIDES {
                let (x, y) = (i % nx + dx, i / nx + dy);
                if x < 0 || y < 0 || x >= nx || y >= ny {
                    continue;
                }
                let j = (y * nx + x) as usize;
                if thin[j] > 0 {
                    if !seen[j] {
                        seen[j] = true;
                        stretch.push(j);
                    }
                } else if shell.get(Cell::new(x, y, 0)) {
                    beside_wall = true;
                }
            }
        }
        for &i in &stretch {
            let (x, y) = (i as i32 % nx, i as i32 / nx);
            if beside_wall {
                for z in 0..thin[i] {
                    shell.set(Cell::new(x, y, z), false);
                    emptied.set(Cell::new(x, y, z), true);
                }
            } else {
                for z in thin[i]..lid {
                    let c = Cell::new(x, y, z);
                    if !emptied.get(c) {
                        break;
                    }
                    emptied.set(c, false);
                    shell.set(c, true);
                }
            }
        }
    }
}

/// The four neighbours of a cell in its layer.
const SIDES: [(i32, i32); 4] = [(1, 0), (-1, 0), (0, 1), (0, -1)];

/// The cells of `g` joined to `start` side by side in its layer (`start`
/// included if in `g`).
fn layer_part(g: &VoxelGrid, start: Cell) -> Vec<Cell> {
    if !g.in_bounds(start) || !g.get(start) {
        return Vec::new();
    }
    // Cells seen, as many as the part has (not the layer's area: a layer
    // may hold many small parts).
    let mut seen: crate::keyhash::KeySet<(i32, i32)> = crate::keyhash::KeySet::default();
    seen.insert((start.x, start.y));
    let mut stack = vec![start];
    let mut out = Vec::new();
    while let Some(c) = stack.pop() {
        out.push(c);
        for (dx, dy) in SIDES {
            let d = c.offset(dx, dy, 0);
            if g.in_bounds(d) && g.get(d) && seen.insert((d.x, d.y)) {
                stack.push(d);
            }
        }
    }
    out
}

/// Gives every part of a layer's shell that hangs wholly over the hollow
/// (no cell of it has shell under it, and some has hollow) a lid of `up`
/// layers under it: in each of those layers, the stretch of hollow under
/// its cells is filled again, whole (see the module docs). Layers go from
/// the bottom up, so a lid made is in place when the layers above it are
/// looked at.
fn lid_under_hanging(shell: &mut VoxelGrid, emptied: &mut VoxelGrid, up: i32) {
    lid_where_unheld(shell, emptied, up, -1);
}

/// Gives every part of a layer's shell that stands wholly under the
/// hollow (no cell of it has shell over it, and some has hollow) a lid of
/// `up` layers over it, the same way, so that what stands there is joined
/// to the shell around (a pedestal under a wider body, two layers high:
/// its rim stood under the body's hollow, joined to nothing, and was left
/// out). The mirror of [`lid_under_hanging`]; layers go from the top down.
fn lid_over_standing(shell: &mut VoxelGrid, emptied: &mut VoxelGrid, up: i32) {
    lid_where_unheld(shell, emptied, up, 1);
}

/// [`lid_under_hanging`] (`dz` -1: the side looked at is under each part)
/// and [`lid_over_standing`] (`dz` 1: over it). Layers go away from that
/// side, so a lid made is in place when the layers beyond it are looked at.
fn lid_where_unheld(shell: &mut VoxelGrid, emptied: &mut VoxelGrid, up: i32, dz: i32) {
    let (nx, ny, nz) = shell.dims();
    let layers: Vec<i32> = if dz < 0 {
        (1..nz).collect()
    } else {
        (0..nz - 1).rev().collect()
    };
    for z in layers {
        // Layers on the side looked at, to the grid's end.
        let room = if dz < 0 { z } else { nz - 1 - z };
        let mut looked = vec![false; (nx * ny) as usize];
        for y in 0..ny {
            for x in 0..nx {
                let c = Cell::new(x, y, z);
                if looked[(y * nx + x) as usize] || !shell.get(c) {
                    continue;
                }
                let part = layer_part(shell, c);
                for q in &part {
                    looked[(q.y * nx + q.x) as usize] = true;
                }
                let held = part.iter().any(|q| shell.get(q.offset(0, 0, dz)));
                let by_hollow = part.iter().any(|q| emptied.get(q.offset(0, 0, dz)));
                if held || !by_hollow {
                    continue;
                }
                for k in 1..=up.min(room) {
                    for q in &part {
                        let side = Cell::new(q.x, q.y, z + dz * k);
                        for h in layer_part(emptied, side) {
                            emptied.set(h, false);
                            shell.set(h, true);
                        }
                    }
                }
            }
        }
    }
}

/// Per cell (by [`VoxelGrid::index`]): the chessboard distance, within its
/// layer, to the nearest cell outside `g` (off the grid counts as outside);
/// 0 for cells outside. Two passes of the classic chamfer transform, exact
/// for this metric.
fn horizontal_depth(g: &VoxelGrid) -> Vec<i32> {
    let (nx, ny, nz) = g.dims();
    let mut d = vec![0i32; g.len()];
    let at = |x: i32, y: i32, z: i32| g.index(Cell::new(x, y, z));
    for z in 0..nz {
        // Off the grid, the distance is 0: a border cell is 1 deep.
        let get = |d: &[i32], x: i32, y: i32| {
            if x < 0 || y < 0 || x >= nx || y >= ny {
                0
            } else {
                d[at(x, y, z)]
            }
        };
        for y in 0..ny {
            for x in 0..nx {
                if !g.get(Cell::new(x, y, z)) {
                    continue;
                }
                let m = [(-1, 0), (-1, -1), (0, -1), (1, -1)]
                    .iter()
                    .map(|&(dx, dy)| get(&d, x + dx, y + dy))
                    .min()
                    .unwrap_or(0);
                d[at(x, y, z)] = m + 1;
            }
        }
        for y in (0..ny).rev() {
            for x in (0..nx).rev() {
                if !g.get(Cell::new(x, y, z)) {
                    continue;
                }
                let m = [(1, 0), (1, 1), (0, 1), (-1, 1)]
                    .iter()
                    .map(|&(dx, dy)| get(&d, x + dx, y + dy) + 1)
                    .min()
                    .unwrap_or(i32::MAX);
                let i = at(x, y, z);
                d[i] = d[i].min(m);
            }
        }
    }
    d
}

/// Whether the `up` cells above `c` and the `up` cells below it (down to
/// the ground, which is no outside) are all in `g`; above the grid is
/// outside.
fn deep_in_column(g: &VoxelGrid, c: Cell, up: i32) -> bool {
    let (_, _, nz) = g.dims();
    (1..=up).all(|k| c.z + k < nz && g.get(c.offset(0, 0, k)))
        && (1..=up).all(|k| c.z - k < 0 || g.get(c.offset(0, 0, -k)))
}

/// The cells of `g` that lie in a [`MIN_HOLE`]-wide square of its cells
/// in their layer.
fn open_square(g: &VoxelGrid) -> VoxelGrid {
    let (nx, ny, nz) = g.dims();
    let k = MIN_HOLE;
    // Per cell, the side of the biggest square of cells whose corner of
    // highest x and y it is (dynamic programming over the layer).
    let mut side = vec![0i32; g.len()];
    let mut out = VoxelGrid::new(nx, ny, nz);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let c = Cell::new(x, y, z);
                if !g.get(c) {
                    continue;
                }
                let at = |dx: i32, dy: i32| {
                    let q = c.offset(dx, dy, 0);
                    if q.x < 0 || q.y < 0 {
                        0
                    } else {
                        side[g.index(q)]
                    }
                };
                let s = 1 + at(-1, 0).min(at(0, -1)).min(at(-1, -1));
                side[g.index(c)] = s;
                if s >= k {
                    for dy in 0..k {
                        for dx in 0..k {
                            out.set(c.offset(-dx, -dy, 0), true);
                        }
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::CellBox;

    fn block(nx: i32, ny: i32, nz: i32) -> VoxelGrid {
        let mut g = VoxelGrid::new(nx, ny, nz);
        let all = CellBox {
            min: Cell::new(0, 0, 0),
            sx: nx,
            sy: ny,
            sz: nz,
        };
        g.set_box(&all, true);
        g
    }

    #[test]
    fn a_block_keeps_walls_as_thick_as_asked_and_no_floor() {
        for n in [1, 2, 3] {
            let g = block(14, 11, 10);
            let h = hollow(&g, Wall::new(n).unwrap(), 1, 2);
            let lid = (n as i32).max(2);
            for c in g.cells() {
                let edge = c.x.min(c.y).min(13 - c.x).min(10 - c.y);
                let inside = edge >= n as i32 && c.z < 10 - lid;
                assert_eq!(h.emptied.get(c), inside, "wall {n}, cell {c:?}");
                assert_eq!(h.shell.get(c), !inside);
            }
        }
    }

    #[test]
    fn lids_are_measured_in_courses() {
        // Three layers a course (plates): a 2-course lid is 6 layers.
        let h = hollow(&block(10, 10, 12), Wall::DEFAULT, 3, 2);
        let c = Cell::new(5, 5, 0);
        let top = (0..12).filter(|&z| h.emptied.get(c.offset(0, 0, z))).max();
        assert_eq!(top, Some(5));
    }

    #[test]
    fn thin_parts_stay_solid_and_narrow_pockets_are_filled_again() {
        // A slab 4 studs deep: every voxel within 2 of the outside.
        let thin = block(20, 4, 8);
        assert_eq!(hollow(&thin, Wall::DEFAULT, 1, 2).shell, thin);
        // 7 deep: a pocket 3 studs wide inside, too narrow to keep.
        let narrow = block(20, 7, 8);
        assert!(hollow(&narrow, Wall::DEFAULT, 1, 2).emptied.is_empty());
        // 8 deep: a pocket 4 studs wide, kept.
        let wide = hollow(&block(20, 8, 8), Wall::DEFAULT, 1, 2);
        assert_eq!(wide.emptied.count(), 16 * 4 * 6);
    }

    /// A tower on a wider base, set back so far that its walls stand
    /// wholly over the base's hollow: the base gets a lid under them, a
    /// whole one (the walls rest on it and it on the base's walls), and the
    /// tower above is hollow again.
    #[test]
    fn walls_set_back_over_the_hollow_get_a_lid_under_them() {
        let mut g = block(20, 20, 16);
        // The base is 20 x 20 and 8 high; the tower 8 x 8 in its middle.
        for z in 8..16 {
            for y in 0..20 {
                for x in 0..20 {
                    if !(6..14).contains(&x) || !(6..14).contains(&y) {
                        g.set(Cell::new(x, y, z), false);
                    }
                }
            }
        }
        let h = hollow(&g, Wall::new(2).unwrap(), 1, 2);
        // The base's top two layers are whole under the tower.
        for z in 6..8 {
            for y in 0..20 {
                for x in 0..20 {
                    assert!(h.shell.get(Cell::new(x, y, z)), "({x}, {y}, {z})");
                }
            }
        }
        // Below the lid, the base is hollow; the tower is hollow too.
        assert!(!h.shell.get(Cell::new(10, 10, 3)));
        assert!(!h.shell.get(Cell::new(10, 10, 11)));
        // No part of a layer's shell hangs over the hollow.
        for c in h.shell.cells().filter(|c| c.z > 0) {
            let part = layer_part(&h.shell, c);
            assert!(
                part.iter().any(|q| h.shell.get(q.offset(0, 0, -1)))
                    || !part.iter().any(|q| h.emptied.get(q.offset(0, 0, -1))),
                "{c:?} hangs over the hollow"
            );
        }
        assert_eq!(h.shell.count() + h.emptied.count(), g.count());
    }

    #[test]
    fn wall_thickness_is_validated() {
        assert!(Wall::new(0).is_none());
        assert!(Wall::new(MAX_WALL + 1).is_none());
        assert_eq!(Wall::new(1).map(Wall::studs), Some(1));
    }
}
