//! Whether pieces laid in the voxels alone could ever hold them together:
//! a test made once, before the trace, that fails at once on a shape no
//! derivation builds however long it searches.
//!
//! Pieces hold each other only through studs, where a cell of one lies
//! just above a cell of another. So in any build of the voxels, two
//! voxels that each have a voxel above or below them (their *contacts*)
//! are joined by a chain: up and down between pieces, and across a piece
//! from one of its contacts to another. The test joins every two voxels
//! one above the other, and all the contacts of every place a piece of the
//! alphabet fits wholly in the voxels; if the contacts still fall into two
//! groups, no build holds them together. (It may join more than a build
//! can, as places that overlap share contacts, never less: a shape it
//! passes may still be one the rules cannot build.) A one-voxel ring whose
//! wall turns a corner by a diagonal step, standing on a disc one layer
//! thick, is such a shape: no piece holds two voxels across an edge, and
//! every piece under the straight stretch beyond the step reaches under
//! that stretch alone. Such steps are filled before the test
//! ([`fill_steps`]), so a mug's ring passes it; a sheet one voxel thin
//! whose far end no piece reaches (a delta wing's) is still refused.

use crate::geom::Cell;
use crate::grammar::RuleSet;
use crate::voxel::VoxelGrid;

/// Above this many voxels times piece shapes, the test is not made (it
/// visits every place every shape fits; the trace does not finish on
/// shapes that big within any budget a user waits for).
const MAX_WORK: usize = 50_000_000;

/// A voxel whose contacts no piece joins to the rest (the first, bottom up,
/// of the smaller group), and how many voxels that group holds; `None`
/// when the contacts are one group (or the test is not made).
pub(super) fn unjoinable(v: &VoxelGrid, rules: &RuleSet) -> Option<(Cell, usize)> {
    let shapes = super::trace::coverers(rules);
    if v.count().saturating_mul(shapes.len().max(1)) > MAX_WORK {
        return None;
    }
    let contact = |c: Cell| v.get(c.offset(0, 0, 1)) || v.get(c.offset(0, 0, -1));
    let mut parent: Vec<usize> = (0..v.len()).collect();
    let find = |parent: &mut Vec<usize>, mut i: usize| {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    };
    let unite = |parent: &mut Vec<usize>, a: usize, b: usize| {
        let (ra, rb) = (find(parent, a), find(parent, b));
        if ra != rb {
            parent[ra.max(rb)] = ra.min(rb);
        }
    };
    let cells: Vec<Cell> = v.cells().collect();
    for &c in &cells {
        let up = c.offset(0, 0, 1);
        if v.get(up) {
            unite(&mut parent, v.index(c), v.index(up));
        }
    }
    // Every place a shape fits, from each voxel as its key cell.
    for s in &shapes {
        let key = s.key();
        for &c in &cells {
            let b = s.moved(c.x - key.x, c.y - key.y, c.z - key.z);
            if !b.cells().all(|q| v.get(q)) {
                continue;
            }
            let mut first: Option<usize> = None;
            for q in b.cells().filter(|&q| contact(q)) {
                let i = v.index(q);
                match first {
                    None => first = Some(i),
                    Some(f) => unite(&mut parent, f, i),
                }
            }
        }
    }
    let contacts: Vec<Cell> = cells.iter().copied().filter(|&c| contact(c)).collect();
    let mut sizes: std::collections::BTreeMap<usize, (usize, Cell)> = Default::default();
    for &c in &contacts {
        let r = find(&mut parent, v.index(c));
        sizes.entry(r).or_insert((0, c)).0 += 1;
    }
    if sizes.len() <= 1 {
        return None;
    }
    // The smallest group (the first found if equal): the one to name.
    sizes
        .values()
        .min_by_key(|(n, c)| (*n, (c.z, c.y, c.x)))
        .map(|&(n, c)| (c, n))
}

/// Fills the diagonal steps of `v`: where two voxels meet only along an
/// edge (neither of the two cells beside both is a voxel), one of those
/// two cells is made a voxel. In a layer, the one nearer the middle of
/// the layer's voxels (on a ring, the inside of the turn; the first on a
/// tie); up a step, the one under the upper voxel, where a piece holds
/// both. No piece holds two voxels across an edge, so a wall one voxel
/// thin that turns by such steps (a mug's, a ring's) or a handle that
/// climbs by them is in no derivation as voxelized ([`unjoinable`] says
/// so); the layout joins them the same way, with a cell just outside the
/// voxels at each step. Repeated until no step is left; how many voxels
/// were added.
pub(super) fn fill_steps(v: &mut VoxelGrid) -> usize {
    let (nx, ny, nz) = v.dims();
    let mut added = 0;
    loop {
        let mut fill = VoxelGrid::new(nx, ny, nz);
        for z in 0..nz {
            let cells: Vec<Cell> = v.layer_cells(z).collect();
            if cells.is_empty() {
                continue;
            }
            let n = cells.len() as f64;
            let mx = cells.iter().map(|c| f64::from(c.x)).sum::<f64>() / n;
            let my = cells.iter().map(|c| f64::from(c.y)).sum::<f64>() / n;
            let off_middle =
                |c: Cell| (f64::from(c.x) - mx).powi(2) + (f64::from(c.y) - my).powi(2);
            let on = |c: Cell| v.in_bounds(c) && v.get(c);
            for &c in &cells {
                // Up a step: the cell under the upper voxel, beside the
                // lower one (a piece there holds both).
                for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                    let side = c.offset(dx, dy, 0);
                    if on(side.offset(0, 0, 1)) && !on(side) && !on(c.offset(0, 0, 1)) {
                        fill.set(side, true);
                    }
                }
                for dy in [1, -1] {
                    let (p, q) = (c.offset(1, 0, 0), c.offset(0, dy, 0));
                    if on(c.offset(1, dy, 0)) && !on(p) && !on(q) {
                        let pick = if off_middle(q) < off_middle(p) { q } else { p };
                        fill.set(pick, true);
                    }
                }
            }
        }
        let n = fill.count();
        if n == 0 {
            return added;
        }
        added += n;
        v.unite(&fill);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grammar::default_rules;

    fn bricks() -> RuleSet {
        default_rules()
            .restricted(|p| p.spec().family() == crate::catalog::Family::Brick)
            .expect("the default rules have bricks")
    }

    #[test]
    fn a_solid_box_is_one_group() {
        let mut v = VoxelGrid::new(6, 4, 3);
        for c in
            (0..3).flat_map(|z| (0..4).flat_map(move |y| (0..6).map(move |x| Cell::new(x, y, z))))
        {
            v.set(c, true);
        }
        assert_eq!(unjoinable(&v, &bricks()), None);
    }

    #[test]
    fn a_column_beside_a_wall_only_across_an_edge_falls_apart() {
        // Two walls three layers high, on a one-layer floor, that touch
        // only along an edge: the floor under the short wall reaches no
        // further than the long one's floor cells under the short wall's
        // own; no piece in the floor lies under both.
        let mut v = VoxelGrid::new(12, 12, 3);
        for z in 1..3 {
            for x in 0..10 {
                v.set(Cell::new(x, 0, z), true);
            }
            v.set(Cell::new(10, 1, z), true);
            v.set(Cell::new(10, 2, z), true);
        }
        // The floor: under the long wall, and under the short one, with
        // a gap no piece of the alphabet spans between them.
        for x in 0..10 {
            v.set(Cell::new(x, 0, 0), true);
        }
        v.set(Cell::new(10, 1, 0), true);
        v.set(Cell::new(10, 2, 0), true);
        let (c, n) = unjoinable(&v, &bricks()).expect("the short wall is joined to nothing");
        assert_eq!((c, n), (Cell::new(10, 1, 0), 6));
        // Filled at the step, the two are one.
        for z in 0..3 {
            v.set(Cell::new(10, 0, z), true);
        }
        assert_eq!(unjoinable(&v, &bricks()), None);
    }

    #[test]
    fn a_voxel_at_each_diagonal_step_joins_what_met_along_an_edge() {
        // The walls above, meeting along an edge in each of their three
        // layers: a voxel at each step, inside the turn.
        let mut v = VoxelGrid::new(12, 12, 3);
        for z in 0..3 {
            for x in 0..10 {
                v.set(Cell::new(x, 0, z), true);
            }
            v.set(Cell::new(10, 1, z), true);
            v.set(Cell::new(10, 2, z), true);
        }
        assert!(unjoinable(&v, &bricks()).is_some());
        assert_eq!(fill_steps(&mut v), 3);
        assert!((0..3).all(|z| v.get(Cell::new(9, 1, z))));
        assert_eq!(unjoinable(&v, &bricks()), None);
        assert_eq!(fill_steps(&mut v), 0, "no step is left");
        // A column standing on another's edge: the cell under it.
        let mut v = VoxelGrid::new(4, 4, 4);
        for z in 0..2 {
            v.set(Cell::new(0, 0, z), true);
            v.set(Cell::new(1, 0, z + 2), true);
        }
        assert_eq!(fill_steps(&mut v), 1);
        assert!(v.get(Cell::new(1, 0, 1)));
        assert_eq!(unjoinable(&v, &bricks()), None);
        // The same up a step the other way along x and either way along
        // y: always the cell under the upper voxel.
        for (dx, dy) in [(-1, 0), (0, 1), (0, -1)] {
            let mut v = VoxelGrid::new(4, 4, 4);
            v.set(Cell::new(1, 1, 0), true);
            v.set(Cell::new(1 + dx, 1 + dy, 1), true);
            assert_eq!(fill_steps(&mut v), 1, "({dx}, {dy})");
            assert!(v.get(Cell::new(1 + dx, 1 + dy, 0)), "({dx}, {dy})");
        }
        // A diagonal step down in y within a layer (the cells at y - 1),
        // two voxels alone in it: the two candidates tie, and the one
        // beside the first voxel along x is taken.
        let mut v = VoxelGrid::new(4, 4, 1);
        v.set(Cell::new(1, 2, 0), true);
        v.set(Cell::new(2, 1, 0), true);
        assert_eq!(fill_steps(&mut v), 1);
        assert!(v.get(Cell::new(2, 2, 0)));
    }
}
