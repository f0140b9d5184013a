//! The hierarchical approach (paper, section 4) and the repairs that make
//! any voxel model buildable as one connected piece.
//!
//! [`split_parts`] cuts the model at horizontal planes where the voxel count
//! changes sharply (and at least every few layers), so each part's search
//! tree stays shallow; a part whose pieces could not rest on the parts below
//! it is merged with the part above. [`repair_islands`] joins floating
//! islands to the model with support columns, or drops those too small to
//! matter, and reports what it changed.

use serde::Serialize;

use crate::geom::Cell;
use crate::voxel::VoxelGrid;

/// What the repairs changed, for the report.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Repairs {
    /// Islands (parts not touching the rest) dropped.
    pub dropped_islands: usize,
    /// Voxels dropped with them.
    pub dropped_voxels: usize,
    /// Islands joined to the model by a support column.
    pub supported_islands: usize,
    /// Voxels added as supports.
    pub support_voxels: usize,
    /// Voxels added to make one-layer sheets two layers thick (bricks side by
    /// side in one layer cannot hold together).
    pub thickened_voxels: usize,
    /// Voxels left out because no rule could join them to the build.
    pub dropped_unbuildable: usize,
    /// Voxels of the parts the search had no time left for: the build stops
    /// at the last part finished.
    pub budget_left_out: usize,
}

impl Repairs {
    /// Whether the voxels were built as given.
    pub fn is_empty(&self) -> bool {
        *self == Repairs::default()
    }
}

/// Islands smaller than this many voxels, or than this fraction of the
/// model, are dropped rather than propped up.
const MIN_ISLAND: usize = 4;
const MIN_ISLAND_FRACTION: f64 = 0.002;

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

/// Face-connected components of `g`, largest first (ties by first cell).
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
            for n in neighbors6(comp[k]) {
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

/// Joins or drops floating islands so the model is one face-connected body.
pub fn repair_islands(v: &VoxelGrid) -> (VoxelGrid, Repairs) {
    let mut out = v.clone();
    let mut rep = Repairs::default();
    let comps = components(v);
    if comps.len() <= 1 {
        return (out, rep);
    }
    let total = v.count();
    let min = MIN_ISLAND.max((total as f64 * MIN_ISLAND_FRACTION) as usize);
    let (nx, ny, nz) = v.dims();
    // `joined` holds the main body and every island joined so far.
    let mut joined = VoxelGrid::new(nx, ny, nz);
    for &c in &comps[0] {
        joined.set(c, true);
    }
    let mut pending: Vec<&Vec<Cell>> = comps[1..].iter().collect();
    while !pending.is_empty() {
        let mut progress = false;
        let mut i = 0;
        while i < pending.len() {
            let island = pending[i];
            if island.len() < min {
                for &c in island {
                    out.set(c, false);
                }
                rep.dropped_islands += 1;
                rep.dropped_voxels += island.len();
                pending.remove(i);
                progress = true;
                continue;
            }
            if let Some(col) = shortest_support(island, &joined, &out) {
                for &c in &col {
                    out.set(c, true);
                    joined.set(c, true);
                }
                for &c in island {
                    joined.set(c, true);
                }
                rep.supported_islands += 1;
                rep.support_voxels += col.len();
                pending.remove(i);
                progress = true;
                continue;
            }
            i += 1;
        }
        if !progress {
            for island in pending.drain(..) {
                for &c in island {
                    out.set(c, false);
                }
                rep.dropped_islands += 1;
                rep.dropped_voxels += island.len();
            }
        }
    }
    (out, rep)
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

/// Cuts `v` into parts at horizontal planes, bottom part first.
///
/// A cut goes where the layer's voxel count differs from the layer below by
/// more than half, or where a part would grow past `max_layers`, and above
/// the second layer. A part some
/// of whose pieces could not touch the parts below it (or, for the bottom
/// part, that is not in one piece) is merged with the part above.
pub fn split_parts(v: &VoxelGrid, max_layers: i32, course: i32) -> Vec<VoxelGrid> {
    let (nx, ny, nz) = v.dims();
    let counts: Vec<usize> = (0..nz).map(|z| v.count_layer(z)).collect();
    let mut cuts = vec![0];
    let mut start = 0;
    // Cuts fall between brick courses only: `course` layers make one.
    for z in (course..nz).step_by(course.max(1) as usize) {
        let (a, b) = (counts[z as usize - 1] as f64, counts[z as usize] as f64);
        let sharp = (a - b).abs() > 0.5 * a.max(b) && (a - b).abs() >= 4.0;
        // The bottom part, which nothing holds from below, is kept to two
        // courses: its pieces must interlock among themselves.
        let (two, most) = (2 * course, max_layers.max(1) * course);
        if (sharp && z - start >= two) || z - start >= most || (start == 0 && z == two) {
            cuts.push(z);
            start = z;
        }
    }
    cuts.push(nz);
    let slab = |lo: i32, hi: i32| {
        let mut g = VoxelGrid::new(nx, ny, nz);
        for z in lo..hi {
            for c in v.layer_cells(z) {
                g.set(c, true);
            }
        }
        g
    };
    let mut parts: Vec<(i32, i32)> = cuts
        .windows(2)
        .map(|w| (w[0], w[1]))
        .filter(|w| w.0 < w.1)
        .collect();
    let mut k = 0;
    while k < parts.len() {
        let (lo, hi) = parts[k];
        let g = slab(lo, hi);
        let comps = components(&g);
        let ok = if k == 0 {
            comps.len() <= 1
        } else {
            comps
                .iter()
                .all(|comp| comp.iter().any(|c| c.z == lo && v.get(c.offset(0, 0, -1))))
        };
        if ok || k + 1 == parts.len() {
            k += 1;
        } else {
            parts[k].1 = parts[k + 1].1;
            parts.remove(k + 1);
        }
    }
    parts
        .into_iter()
        .map(|(lo, hi)| slab(lo, hi))
        .filter(|g| !g.is_empty())
        .collect()
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

    #[test]
    fn floating_island_gets_a_support_and_specks_are_dropped() {
        let base = CellBox {
            min: Cell::new(0, 0, 0),
            sx: 6,
            sy: 6,
            sz: 2,
        };
        let island = CellBox {
            min: Cell::new(1, 1, 5),
            sx: 3,
            sy: 3,
            sz: 2,
        };
        let speck = CellBox {
            min: Cell::new(10, 10, 10),
            sx: 1,
            sy: 1,
            sz: 1,
        };
        let g = grid_with(&[base, island, speck]);
        let (fixed, rep) = repair_islands(&g);
        assert_eq!(rep.dropped_islands, 1);
        assert_eq!(rep.dropped_voxels, 1);
        assert_eq!(rep.supported_islands, 1);
        assert_eq!(rep.support_voxels, 3);
        assert_eq!(components(&fixed).len(), 1);
        assert_eq!(fixed.count(), g.count() - 1 + 3);
    }

    #[test]
    fn one_layer_sheets_get_a_second_layer() {
        // A thick block with a one-layer fin sticking out at its top layer.
        let mut g = grid_with(&[
            CellBox {
                min: Cell::new(0, 0, 0),
                sx: 3,
                sy: 3,
                sz: 3,
            },
            CellBox {
                min: Cell::new(3, 0, 2),
                sx: 4,
                sy: 1,
                sz: 1,
            },
        ]);
        let mut rep = Repairs::default();
        thicken_sheets(&mut g, &mut rep, 2);
        assert_eq!(rep.thickened_voxels, 4);
        assert!((3..7).all(|x| g.get(Cell::new(x, 0, 3))));
        // Nothing bare is left, so a second pass changes nothing.
        let before = g.clone();
        thicken_sheets(&mut g, &mut rep, 2);
        assert_eq!(g, before);
    }

    #[test]
    fn parts_cut_where_the_count_changes_and_merge_when_they_cannot_rest() {
        // A wide base, a narrow tower: cut between them.
        let g = grid_with(&[
            CellBox {
                min: Cell::new(0, 0, 0),
                sx: 8,
                sy: 8,
                sz: 3,
            },
            CellBox {
                min: Cell::new(2, 2, 3),
                sx: 2,
                sy: 2,
                sz: 5,
            },
        ]);
        let parts = split_parts(&g, 6, 1);
        let counts: Vec<usize> = parts.iter().map(|p| p.count()).collect();
        assert_eq!(counts, vec![8 * 8 * 2, 8 * 8 + 2 * 2 * 5]);
        // Two legs and a top: the legs part is not one piece, so it merges.
        let t = grid_with(&[
            CellBox {
                min: Cell::new(0, 0, 0),
                sx: 1,
                sy: 1,
                sz: 3,
            },
            CellBox {
                min: Cell::new(6, 0, 0),
                sx: 1,
                sy: 1,
                sz: 3,
            },
            CellBox {
                min: Cell::new(0, 0, 3),
                sx: 7,
                sy: 3,
                sz: 1,
            },
        ]);
        let parts = split_parts(&t, 6, 1);
        assert_eq!(parts.len(), 1);
        assert_eq!(parts[0].count(), t.count());
    }
}
