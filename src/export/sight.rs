//! Which faces of each piece can be seen from outside the model, step by
//! step: what the step viewer may leave undrawn.
//!
//! A piece has six faces in its own frame (see
//! [`partmesh`](super::partmesh)): the studded top, the bottom, and the
//! four sides at `±X` and `±Z`. A face is **out of sight** from the step at
//! which every cell just beyond it either is filled solid (by a piece of
//! that step or an earlier one) or cannot be reached from outside the model
//! without passing through solid cells (a cavity closed in). From then on a
//! viewer outside the model can leave the face out and nothing it shows
//! changes: the faces of the union of the pieces are all still drawn. A
//! piece all of whose faces are out of sight can be left out whole.
//!
//! The top is special: it is out of sight as soon as every cell over its
//! studs is filled by any piece, solid or not (every part's underside is
//! flat and covers the studs it sits on).
//!
//! A cell counts as solid where a part fills it completely: every cell of a
//! brick or plate, and the back row of a slope or an inverted slope; a
//! slope's other rows leave part of their cells open under or over the
//! slanted face, so they block nothing.
//!
//! The cavity test is a widest-path flood over the grid (padded by one cell
//! all round): a cell is reachable until the step at which the last path
//! from outside through cells not yet solid closes. With steps as bucket
//! keys it runs in time linear in the grid's cells.
//!
//! ```
//! use brickwright::assembly::{Assembly, Placement};
//! use brickwright::catalog::{Color, PartKind};
//! use brickwright::export::sight::{sight, Side};
//! use brickwright::geom::{Cell, Rot};
//!
//! let brick = PartKind::from_id("3003").unwrap(); // 2x2
//! let order = [
//!     Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
//!     Placement::new(brick, Cell::new(2, 0, 0), Rot::R0),
//!     Placement::new(brick, Cell::new(1, 0, 1), Rot::R0),
//! ];
//! let seen = sight(&Assembly::from_order(&order, 24, Color::RED));
//! // The third brick covers half of the first one's studs: never all.
//! assert_eq!(seen[0].top, 0);
//! // Its +X side touches the second brick from step 2 on.
//! assert_eq!(seen[0].sides[Side::PlusX as usize], 2);
//! assert_eq!(seen[0].sides[Side::MinusX as usize], 0);
//! ```

use crate::assembly::Assembly;
use crate::geom::{Body, Cell, CellBox};
use crate::ldraw::rot_matrix;

/// A piece's faces other than the top, in its own LDraw frame (-Y up), in
/// the order of [`Sight::sides`]; the step viewer tags mesh vertices with
/// the same order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The underside (`+Y`).
    Bottom,
    /// The end at `+X`.
    PlusX,
    /// The end at `-X`.
    MinusX,
    /// The side at `+Z` (a slope's back).
    PlusZ,
    /// The side at `-Z` (a slope's front lip).
    MinusZ,
}

impl Side {
    /// Every side, in [`Sight::sides`] order.
    pub const ALL: [Side; 5] = [
        Side::Bottom,
        Side::PlusX,
        Side::MinusX,
        Side::PlusZ,
        Side::MinusZ,
    ];

    /// The outward normal in the part's LDraw frame.
    pub const fn normal(self) -> [i32; 3] {
        match self {
            Side::Bottom => [0, 1, 0],
            Side::PlusX => [1, 0, 0],
            Side::MinusX => [-1, 0, 0],
            Side::PlusZ => [0, 0, 1],
            Side::MinusZ => [0, 0, -1],
        }
    }
}

/// From which step each face of a piece is out of sight; 0 when never.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Sight {
    /// The studded top (studs and top face).
    pub top: u32,
    /// The other faces, in [`Side::ALL`] order.
    pub sides: [u32; 5],
}

impl Sight {
    /// The step from which the whole piece is out of sight, 0 if never.
    pub fn hidden(&self) -> u32 {
        let s = self.sides;
        let faces = [self.top, s[0], s[1], s[2], s[3], s[4]];
        if faces.contains(&0) {
            0
        } else {
            faces.into_iter().max().unwrap_or(0)
        }
    }
}

/// Not before any step: never filled, or never closed in.
const NEVER: u32 = u32::MAX;

/// A dense box of cells, indexed x fastest.
struct Grid {
    min: Cell,
    size: [i32; 3],
}

impl Grid {
    fn len(&self) -> usize {
        self.size.iter().map(|&s| s as usize).product()
    }

    fn index(&self, c: Cell) -> usize {
        let [sx, sy, _] = self.size.map(|s| s as usize);
        let (x, y, z) = (c.x - self.min.x, c.y - self.min.y, c.z - self.min.z);
        x as usize + sx * (y as usize + sy * z as usize)
    }

    fn cell(&self, i: usize) -> [i32; 3] {
        let [sx, sy, _] = self.size.map(|s| s as usize);
        [
            (i % sx) as i32,
            (i / sx % sy) as i32,
            (i / (sx * sy)) as i32,
        ]
    }
}

/// The faces out of sight of every piece of `assembly`, by step (see the
/// [module docs](self)).
pub fn sight(assembly: &Assembly) -> Vec<Sight> {
    let layer = assembly.layer_ldu;
    let bodies: Vec<Body> = assembly
        .pieces
        .iter()
        .map(|p| p.placement.body(layer))
        .collect();
    let Some(grid) = padded_grid(&bodies) else {
        return Vec::new();
    };
    // The step each cell is filled at (by any piece), and at which it
    // turns solid.
    let mut filled = vec![NEVER; grid.len()];
    let mut solid = vec![NEVER; grid.len()];
    for (p, body) in assembly.pieces.iter().zip(&bodies) {
        for c in body.cells() {
            filled[grid.index(c)] = p.step.0;
        }
        for c in solid_cells(body) {
            solid[grid.index(c)] = p.step.0;
        }
    }
    let open = open_until(&grid, &solid, assembly.step_count());
    let out_of_sight = |cells: CellBox, covered: &dyn Fn(usize) -> u32| {
        let step = cells.cells().map(|c| covered(grid.index(c))).max();
        step.filter(|&s| s != NEVER).unwrap_or(0)
    };
    assembly
        .pieces
        .iter()
        .zip(&bodies)
        .map(|(p, body)| {
            let m = rot_matrix(p.placement.rot);
            Sight {
                top: out_of_sight(body.over_studs(), &|i| filled[i].min(open[i])),
                sides: Side::ALL.map(|side| {
                    let n = side.normal();
                    let world = [0, 1, 2].map(|r| (0..3).map(|k| m[r][k] * n[k]).sum::<i32>());
                    // LDraw X, Z are the grid's x, y; LDraw -Y is up.
                    let beyond = beside(&body.bbox, [world[0], world[2], -world[1]]);
                    out_of_sight(beyond, &|i| open[i])
                }),
            }
        })
        .collect()
}

/// The box around every body with one free cell on each side, or `None`
/// for no bodies.
fn padded_grid(bodies: &[Body]) -> Option<Grid> {
    let first = bodies.first()?.bbox;
    let b = bodies.iter().fold(first, |b, body| b.union(&body.bbox));
    let max = b.max_excl();
    Some(Grid {
        min: b.min.offset(-1, -1, -1),
        size: [
            max.x - b.min.x + 2,
            max.y - b.min.y + 2,
            max.z - b.min.z + 2,
        ],
    })
}

/// The cells a piece fills completely: the columns under its studs that
/// also stand on its tubes (every cell of a brick or plate, a slope's back
/// row).
fn solid_cells(body: &Body) -> impl Iterator<Item = Cell> + '_ {
    let (s, t) = (body.studs, body.tubes);
    let in_footprint = |b: &CellBox, c: Cell| {
        c.x >= b.min.x && c.x < b.min.x + b.sx && c.y >= b.min.y && c.y < b.min.y + b.sy
    };
    body.bbox
        .cells()
        .filter(move |&c| in_footprint(&s, c) && in_footprint(&t, c))
}

/// The layer of cells just beyond `b` in the grid direction `d` (one axis
/// only).
fn beside(b: &CellBox, d: [i32; 3]) -> CellBox {
    let max = b.max_excl();
    let at = |k: usize, lo: i32, hi: i32| match d[k] {
        1 => (hi, 1),
        -1 => (lo - 1, 1),
        _ => (lo, hi - lo),
    };
    let (x, sx) = at(0, b.min.x, max.x);
    let (y, sy) = at(1, b.min.y, max.y);
    let (z, sz) = at(2, b.min.z, max.z);
    CellBox {
        min: Cell::new(x, y, z),
        sx,
        sy,
        sz,
    }
}

/// For each cell, the step until which some path from outside the grid
/// reaches it through cells not yet solid (a cell is open before the step
/// in `solid`): it is in sight at steps before the value, out of sight
/// from it on. [`NEVER`] for cells open to the end.
fn open_until(grid: &Grid, solid: &[u32], steps: u32) -> Vec<u32> {
    // Bucket k holds cells reached with value k; the last, NEVER.
    let key = |v: u32| {
        if v == NEVER {
            steps as usize + 1
        } else {
            v as usize
        }
    };
    let mut open = vec![0u32; grid.len()];
    let mut buckets: Vec<Vec<usize>> = vec![Vec::new(); steps as usize + 2];
    for (i, open) in open.iter_mut().enumerate() {
        let c = grid.cell(i);
        if (0..3).any(|k| c[k] == 0 || c[k] == grid.size[k] - 1) {
            *open = NEVER;
            buckets[key(NEVER)].push(i);
        }
    }
    let strides = [
        1,
        grid.size[0] as usize,
        (grid.size[0] * grid.size[1]) as usize,
    ];
    for b in (1..buckets.len()).rev() {
        while let Some(i) = buckets[b].pop() {
            let v = open[i];
            if key(v) != b {
                continue;
            }
            let c = grid.cell(i);
            for k in 0..3 {
                for (j, inside) in [
                    (i.wrapping_sub(strides[k]), c[k] > 0),
                    (i + strides[k], c[k] < grid.size[k] - 1),
                ] {
                    if !inside {
                        continue;
                    }
                    let w = v.min(solid[j]);
                    if w > open[j] {
                        open[j] = w;
                        buckets[key(w)].push(j);
                    }
                }
            }
        }
    }
    open
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::{Placement, Step};
    use crate::catalog::{Color, PartKind};
    use crate::geom::Rot;

    fn part(id: &str) -> PartKind {
        PartKind::from_id(id).unwrap()
    }

    /// A hollow cube of 1x1 bricks, `n` cells a side, built a layer a
    /// step from the bottom: walls one cell thick around a cavity.
    fn hollow_cube(n: i32) -> Assembly {
        let mut order = Vec::new();
        let mut steps = Vec::new();
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let wall = [x, y, z].iter().any(|&v| v == 0 || v == n - 1);
                    if wall {
                        order.push(Placement::new(part("3005"), Cell::new(x, y, z), Rot::R0));
                        steps.push(z as u32 + 1);
                    }
                }
            }
        }
        let mut asm = Assembly::from_order(&order, 24, Color::RED);
        for (p, s) in asm.pieces.iter_mut().zip(steps) {
            p.step = Step(s);
        }
        asm
    }

    #[test]
    fn a_closed_cavity_hides_the_walls_inner_faces_from_the_closing_step() {
        let n = 5;
        let asm = hollow_cube(n);
        let seen = sight(&asm);
        let at = |x, y, z| {
            asm.pieces
                .iter()
                .position(|p| p.placement.origin == Cell::new(x, y, z))
                .unwrap()
        };
        // A floor brick under the cavity: its studs face the cavity, which
        // the lid closes at step n; its underside faces the outside.
        let floor = seen[at(2, 2, 0)];
        assert_eq!(floor.top, n as u32);
        assert_eq!(floor.sides[Side::Bottom as usize], 0);
        // Its four neighbours are floor bricks of step 1.
        for side in [Side::PlusX, Side::MinusX, Side::PlusZ, Side::MinusZ] {
            assert_eq!(floor.sides[side as usize], 1, "{side:?}");
        }
        assert_eq!(floor.hidden(), 0);
        // A wall brick: outside at -X, the cavity at +X.
        let wall = seen[at(0, 2, 2)];
        assert_eq!(wall.sides[Side::MinusX as usize], 0);
        assert_eq!(wall.sides[Side::PlusX as usize], n as u32);
        assert_eq!(wall.top, 4);
        // A lid brick: its studs stay in the open.
        assert_eq!(seen[at(2, 2, n - 1)].top, 0);
    }

    #[test]
    fn a_solid_block_hides_its_core_and_shows_its_skin() {
        let mut order = Vec::new();
        for z in 0..3 {
            for y in 0..3 {
                for x in 0..3 {
                    order.push(Placement::new(part("3005"), Cell::new(x, y, z), Rot::R0));
                }
            }
        }
        let asm = Assembly::from_order(&order, 24, Color::RED);
        let seen = sight(&asm);
        // The core is the 14th piece, hidden once the brick over it is in.
        assert_eq!(seen[13].hidden(), 23);
        let shown = seen.iter().filter(|s| s.hidden() == 0).count();
        assert_eq!(shown, 26);
    }

    #[test]
    fn sides_turn_with_the_piece() {
        // A 1x2 brick's +X end, turned each way, against a 1x1 brick put
        // where the part mesh's end lands in the world.
        for rot in Rot::ALL {
            let long = Placement::new(part("3004"), Cell::new(4, 4, 0), rot);
            let hx = 10.0 * f32::from(part("3004").spec().studs_x);
            let t = crate::export::partmesh::piece_transform(&long, 24);
            let w = t.transform_point3(glam::Vec3::new(hx + 10.0, 12.0, 0.0));
            let cell = Cell::new(
                (w.x / 20.0).floor() as i32,
                (w.z / 20.0).floor() as i32,
                (-w.y / 24.0).floor() as i32,
            );
            let order = [long, Placement::new(part("3005"), cell, Rot::R0)];
            let seen = sight(&Assembly::from_order(&order, 24, Color::RED))[0];
            let mut want = [0; 5];
            want[Side::PlusX as usize] = 2;
            assert_eq!(seen.sides, want, "{rot:?}: neighbour at {cell:?}");
        }
    }

    #[test]
    fn slopes_block_only_with_their_back_row() {
        // 3039 is two rows deep: the back row stands full height, the
        // front one under the slanted face.
        let body = part("3039").spec().body(Rot::R0, Cell::new(0, 0, 0), 24);
        let solid: Vec<Cell> = solid_cells(&body).collect();
        assert_eq!(solid.len(), 2, "{solid:?}");
        assert!(solid.iter().all(|&c| body.studs.contains(c)), "{solid:?}");
    }

    #[test]
    fn an_empty_assembly_has_no_sight() {
        let asm = Assembly {
            pieces: vec![],
            layer_ldu: 24,
        };
        assert!(sight(&asm).is_empty());
    }
}
