//! Solid voxelization: from a triangle soup to 1 x 1 x 1.2 stud cells.
//!
//! # Frame and size
//!
//! The grid frame has `x` and `y` horizontal and `z` up. A mesh whose up
//! axis is `y` (glTF, most OBJ exports) is turned with
//! `(x, y, z) -> (x, -z, y)`; see [`Up`] and [`to_grid_frame`]. The scale
//! comes from [`Sizing`]: either the longest horizontal side in studs or the
//! height in layers. One voxel is one stud wide and deep and
//! [`LAYER_HEIGHT_STUDS`] (1.2) studs high, a brick's height over a stud's
//! width. The grid is `ceil(extent / voxel size)` cells along each axis,
//! with the shape centred in the leftover fraction of a cell, so layer 0
//! holds the lowest voxels and no border layer is empty.
//!
//! # Which cells are filled
//!
//! A cell is filled when its centre is inside the shape. Real meshes are
//! rarely clean — holes, several overlapping parts, duplicated or flipped
//! triangles — so "inside" is decided by casting rays through the cell
//! centres along all three axes and taking a majority vote:
//!
//! 1. For each axis, every triangle is projected onto the plane across that
//!    axis, and each column (a ray through cell centres) whose centre falls
//!    in the projection records a *crossing*: its depth along the ray and the
//!    side the triangle faces. Coverage is decided with exact edge functions
//!    and a tie rule (as in a rasterizer), so a ray through an edge or
//!    vertex shared by two triangles counts once, not zero or two times.
//! 2. Along a ray, a centre is inside when the crossings before it are odd
//!    in number *or* have a non-zero signed sum (winding number). Parity
//!    copes with flipped triangles, the winding number with overlapping
//!    parts; exact duplicate triangles are removed beforehand.
//! 3. A cell is solid when at least two of its three rays say inside. A hole
//!    in the mesh spoils the rays through it, which then streak to the
//!    grid's edge; the streaks of different axes rarely meet, so the vote
//!    removes them.
//!
//! A thin wall or fin may hold no cell centre at all and would vanish. So a
//! second pass walks every crossing again: if neither the cell holding the
//! crossing nor the neighbour on the near side of it is filled, the cell
//! holding the crossing is filled. A surface thus never lies more than half
//! a cell from a filled cell, while thick parts gain nothing (their own
//! cells already sit next to each crossing). Thin walls and single-sided
//! sheets come out one cell thick. Features thin in *two* directions (a wire
//! narrower than a cell) are kept only where a ray happens to hit them.
//!
//! Everything is deterministic: fixed iteration orders, no hashing order,
//! and threads only where the result cannot depend on them.
//!
//! # Example
//!
//! ```
//! use brickwright::mesh::Mesh;
//! use brickwright::voxel::{voxelize, Sizing, Up, VoxelizeOptions};
//! use glam::Vec3;
//!
//! // A unit cube, z up.
//! let positions = (0..8)
//!     .map(|i| Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32))
//!     .collect();
//! let triangles = vec![
//!     [0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
//!     [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5],
//! ];
//! let mesh = Mesh { positions, triangles, ..Mesh::default() };
//! let opts = VoxelizeOptions::default()
//!     .with_sizing(Sizing::Studs(10))
//!     .with_up(Up::Z);
//! let model = voxelize(&mesh, &opts)?;
//! assert_eq!(model.grid.dims(), (10, 10, 9)); // ceil(10 / 1.2) = 9 layers
//! assert_eq!(model.grid.count(), 900);
//! # Ok::<(), brickwright::voxel::VoxelizeError>(())
//! ```

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::VoxelGrid;
use crate::geom::Cell;
use crate::mesh::Mesh;

/// A voxel's height over its width: a brick is 1.2 studs tall.
pub const LAYER_HEIGHT_STUDS: f32 = 1.2;

/// The most cells [`voxelize`] makes along any one axis.
pub const MAX_SIDE: u32 = 512;

/// The most cells [`voxelize`] makes in all, filled or not (2^24, about
/// 16.8 million): the stages after it (colours, layout, the checks) take
/// time and memory with the grid's cells, not only its voxels, so a thin
/// diagonal rod of a few thousand voxels at 512 studs (512 x 512 x 425
/// cells) took 46 s and 1.2 GB. A solid model that large would pass the
/// search's voxel limit anyway; this bounds the sparse ones.
pub const MAX_CELLS: u64 = 1 << 24;

/// Which input axis points up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Up {
    /// `+y` is up (glTF's convention and most OBJ exports). The default.
    #[default]
    Y,
    /// `+z` is up (STL from CAD tools, Blender's own frame).
    Z,
}

/// How big the model is built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sizing {
    /// The longer horizontal side of the model, in studs.
    Studs(u32),
    /// The model's height, in brick layers.
    Height(u32),
}

impl Default for Sizing {
    /// 24 studs across, a model that fits on a small baseplate.
    fn default() -> Self {
        Sizing::Studs(24)
    }
}

/// Options for [`voxelize`].
///
/// Defaults: [`Sizing::Studs`]`(24)`, [`Up::Y`] and brick-high layers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct VoxelizeOptions {
    /// How big the model is built. Default: 24 studs across.
    pub sizing: Sizing,
    /// The input's up axis. Default: `y`.
    pub up: Up,
    /// A layer's height in LDU: 24 (a brick, the default), 12 (half a
    /// brick, with slopes: a slope's sloping face then shows as a step of
    /// one layer the matcher fits the slope's cells to) or 8 (a plate).
    pub layer_ldu: i32,
}

impl Default for VoxelizeOptions {
    fn default() -> Self {
        VoxelizeOptions {
            sizing: Sizing::default(),
            up: Up::default(),
            layer_ldu: 24,
        }
    }
}

impl VoxelizeOptions {
    /// These options with `sizing` replaced.
    pub fn with_sizing(mut self, sizing: Sizing) -> Self {
        self.sizing = sizing;
        self
    }

    /// These options with `up` replaced.
    pub fn with_up(mut self, up: Up) -> Self {
        self.up = up;
        self
    }

    /// These options with layers `layer_ldu` high (24, 12, 8 or 4).
    pub fn with_layer_ldu(mut self, layer_ldu: i32) -> Self {
        self.layer_ldu = layer_ldu;
        self
    }
}

/// A voxelized mesh and how its cells map back to the input's units.
#[derive(Debug, Clone, PartialEq)]
pub struct VoxelModel {
    /// The filled cells; `z` is up, one cell is 1 x 1 x 1.2 studs.
    pub grid: VoxelGrid,
    /// Input units per stud.
    pub stud_size: f32,
    /// A cell's height in studs ([`LAYER_HEIGHT_STUDS`]).
    pub layer_height_studs: f32,
    /// The grid's `(0, 0, 0)` corner, in input units in the grid frame
    /// (the input turned by [`to_grid_frame`]).
    pub origin: Vec3,
    /// Where the surface slants, and which way it faces: what a slope
    /// needs to be placed there.
    pub slant: Slant,
    /// The cells the surface passes through (filled or not): the layout may
    /// fill those outside the model to join a feature one voxel thin.
    pub surface: VoxelGrid,
}

/// The cells the mesh's surface passes through where it slants, by the way
/// it faces: `up[d]` for a surface facing up and toward horizontal
/// direction `d` (a roof: where a slope goes), `down[d]` for one facing down
/// and toward `d` (an overhang: where an inverted slope goes). Directions
/// are [`Slant::DIRS`]: `+x, -x, +y, -y` in the grid.
///
/// A face slants when its normal is between about 15 and 75 degrees from
/// the vertical; a face leaning diagonally marks both of its directions.
#[derive(Debug, Clone, PartialEq)]
pub struct Slant {
    /// Up-facing slanted surface cells, by direction.
    pub up: [VoxelGrid; 4],
    /// Down-facing slanted surface cells, by direction.
    pub down: [VoxelGrid; 4],
}

impl Slant {
    /// The four horizontal directions, in the order of the grids.
    pub const DIRS: [(i32, i32); 4] = [(1, 0), (-1, 0), (0, 1), (0, -1)];

    /// No slanted surface anywhere, for grids of `dims`.
    pub fn none(dims: (i32, i32, i32)) -> Slant {
        let g = VoxelGrid::new(dims.0, dims.1, dims.2);
        Slant {
            up: std::array::from_fn(|_| g.clone()),
            down: std::array::from_fn(|_| g.clone()),
        }
    }

    /// The grid of surface cells facing `dir` (one of [`Slant::DIRS`]),
    /// up-facing or down-facing.
    pub fn facing(&self, dir: (i32, i32), up: bool) -> Option<&VoxelGrid> {
        let k = Slant::DIRS.iter().position(|&d| d == dir)?;
        Some(if up { &self.up[k] } else { &self.down[k] })
    }

    /// Marks the cells the triangles (in cell units) pass through where
    /// they slant.
    fn mark(tris: &[[DVec3; 3]], real: &[[DVec3; 3]], dims: (i32, i32, i32)) -> Slant {
        let mut out = Slant::none(dims);
        for (t, w) in tris.iter().zip(real) {
            // The facing in real units (cells are taller than wide).
            let n = (w[1] - w[0]).cross(w[2] - w[0]);
            let len = n.length();
            if !len.is_normal() {
                continue;
            }
            let n = n / len;
            let vertical = n.z.abs();
            if !(0.26..=0.97).contains(&vertical) {
                continue;
            }
            let h = (n.x * n.x + n.y * n.y).sqrt();
            let grids = if n.z > 0.0 {
                &mut out.up
            } else {
                &mut out.down
            };
            let mut dirs = Vec::new();
            for (k, &(dx, dy)) in Slant::DIRS.iter().enumerate() {
                if (f64::from(dx) * n.x + f64::from(dy) * n.y) / h > 0.38 {
                    dirs.push(k);
                }
            }
            // Sample the triangle every half cell or finer.
            sample_cells(t, 2.0, |c| {
                if grids[0].in_bounds(c) {
                    for &k in &dirs {
                        grids[k].set(c, true);
                    }
                }
            });
        }
        out
    }
}

impl VoxelModel {
    /// The size of one cell in input units: `(s, s, 1.2 s)`.
    pub fn cell_size(&self) -> Vec3 {
        Vec3::new(
            self.stud_size,
            self.stud_size,
            self.stud_size * self.layer_height_studs,
        )
    }

    /// The centre of cell `c`, in input units in the grid frame.
    pub fn cell_center(&self, c: Cell) -> Vec3 {
        self.origin + (Vec3::new(c.x as f32, c.y as f32, c.z as f32) + 0.5) * self.cell_size()
    }
}

/// Why a mesh could not be voxelized. [`crate::mesh::load`] rules out the
/// mesh problems for loaded files; the size problems depend on the options.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VoxelizeError {
    /// The mesh has no triangles.
    #[error("the mesh has no triangles")]
    EmptyMesh,
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle index {index} is out of range ({count} vertices)")]
    IndexOutOfRange {
        /// The bad index.
        index: u32,
        /// How many vertices there are.
        count: usize,
    },
    /// A vertex used by a triangle is NaN or infinite.
    #[error("vertex {index} has a NaN or infinite coordinate")]
    NonFinite {
        /// The vertex.
        index: u32,
    },
    /// `Studs(0)` or `Height(0)`.
    #[error("the requested size is zero; ask for at least 1 stud or 1 layer")]
    ZeroSize,
    /// The mesh has no extent along the axis the sizing measures.
    #[error("the mesh is flat along the axis {sizing:?} measures; size it by {other} instead")]
    Flat {
        /// The sizing asked for.
        sizing: Sizing,
        /// The sizing to use instead.
        other: &'static str,
    },
    /// The grid would be too big.
    #[error(
        "the model would be {nx} x {ny} x {nz} cells, beyond the limit of {MAX_SIDE} a side \
         and {MAX_CELLS} in all; ask for a smaller size: fewer studs (--studs) or layers (--height)"
    )]
    TooLarge {
        /// Cells along x.
        nx: u64,
        /// Cells along y.
        ny: u64,
        /// Cells along z.
        nz: u64,
    },
}

/// Turns an input point into the grid frame (`z` up): for [`Up::Y`],
/// `(x, y, z) -> (x, -z, y)`; for [`Up::Z`], unchanged. Both are rotations,
/// so shapes are not mirrored.
pub fn to_grid_frame(p: Vec3, up: Up) -> Vec3 {
    match up {
        Up::Y => Vec3::new(p.x, -p.z, p.y),
        Up::Z => p,
    }
}

/// The fewest layers of `layer_ldu` a sheet of voxels must be to hold
/// together: two courses of bricks (pieces side by side in one course do
/// not hold each other), or two plates, which laminate.
pub fn sheet_layers(layer_ldu: i32) -> i32 {
    let course = 24 / layer_ldu.clamp(1, 24);
    if layer_ldu == 8 {
        2
    } else {
        2 * course
    }
}

/// Fills the cells whose centres lie inside `mesh`, plus the cells needed to
/// keep thin parts (see the module docs).
pub fn voxelize(mesh: &Mesh, opts: &VoxelizeOptions) -> Result<VoxelModel, VoxelizeError> {
    let tris = unique_triangles(mesh, opts.up)?;
    let (lo, hi) = tris.iter().flatten().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let ext = hi - lo;
    let brick = f64::from(LAYER_HEIGHT_STUDS);
    let ratio = brick * f64::from(opts.layer_ldu) / 24.0;
    let stud = match opts.sizing {
        Sizing::Studs(0) | Sizing::Height(0) => return Err(VoxelizeError::ZeroSize),
        Sizing::Studs(n) => {
            let across = ext.x.max(ext.y);
            if across <= 0.0 {
                return Err(VoxelizeError::Flat {
                    sizing: opts.sizing,
                    other: "height",
                });
            }
            across / f64::from(n)
        }
        Sizing::Height(n) => {
            if ext.z <= 0.0 {
                return Err(VoxelizeError::Flat {
                    sizing: opts.sizing,
                    other: "studs",
                });
            }
            ext.z / (f64::from(n) * brick)
        }
    };
    let cell = DVec3::new(stud, stud, stud * ratio);
    // A hair below an exact multiple still counts as that multiple, so that
    // a 1-unit cube at 0.1 units a stud is 10 studs, not 11.
    let cells = (ext / cell - 1e-6).ceil().max(DVec3::ONE);
    let (nx, ny, nz) = (cells.x as u64, cells.y as u64, cells.z as u64);
    let side = u64::from(MAX_SIDE);
    if nx > side || ny > side || nz > side || nx * ny * nz > MAX_CELLS {
        return Err(VoxelizeError::TooLarge { nx, ny, nz });
    }
    // Centre the shape in the grid's leftover fraction of a cell.
    let origin = lo - (cells * cell - ext) * 0.5;
    // Room on top for whole brick courses: a grid of half-brick layers
    // gets an empty layer over an odd count, so a flat top can be evened up.
    // And room for a sheet to be made two courses thick (with plates, two
    // plates, which a course of three holds): a flat shape one layer high
    // (a glider at 4 studs) had no layer to grow into, and its bricks side
    // by side fell apart into pieces left out.
    let course = (24 / opts.layer_ldu.clamp(1, 24)) as u64;
    let least = (sheet_layers(opts.layer_ldu) as u64).div_ceil(course) * course;
    let nz = (nz.div_ceil(course) * course).max(least);
    let dims = [nx as usize, ny as usize, nz as usize];
    let scaled: Vec<[DVec3; 3]> = tris
        .iter()
        .map(|t| t.map(|p| (p - origin) / cell))
        .collect();

    // The three passes over the triangles are independent: they run side
    // by side (each alone, as before, so the result is the same).
    let d = (dims[0] as i32, dims[1] as i32, dims[2] as i32);
    let (grid, (slant, surface)) = rayon::join(
        || fill(&scaled, dims),
        || {
            rayon::join(
                || Slant::mark(&scaled, &tris, d),
                || surface_cells(&scaled, d),
            )
        },
    );
    Ok(VoxelModel {
        grid,
        surface,
        stud_size: stud as f32,
        layer_height_studs: ratio as f32,
        origin: origin.as_vec3(),
        slant,
    })
}

/// Calls `f` with the cell of every sample of the triangle `t` (in cell
/// units), taken on a grid of `per_cell` samples a cell along its longest
/// side (at most 4,096 along it); a cell may come more than once.
fn sample_cells(t: &[DVec3; 3], per_cell: f64, mut f: impl FnMut(Cell)) {
    let span = (t[1] - t[0])
        .length()
        .max((t[2] - t[0]).length())
        .max((t[2] - t[1]).length());
    let steps = (span * per_cell).ceil().clamp(1.0, 4096.0) as usize;
    for i in 0..=steps {
        for j in 0..=(steps - i) {
            let (a, b) = (i as f64 / steps as f64, j as f64 / steps as f64);
            let p = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
            f(Cell::new(
                p.x.floor() as i32,
                p.y.floor() as i32,
                p.z.floor() as i32,
            ));
        }
    }
}

/// The cells the triangles (in cell units) pass through, sampled every
/// third of a cell or finer.
fn surface_cells(tris: &[[DVec3; 3]], dims: (i32, i32, i32)) -> VoxelGrid {
    let mut out = VoxelGrid::new(dims.0, dims.1, dims.2);
    for t in tris {
        sample_cells(t, 3.0, |c| {
            if out.in_bounds(c) {
                out.set(c, true);
            }
        });
    }
    out
}

/// Fills a grid of `dims` cells from triangles already scaled to cell units
/// (cell `(i, j, k)` spans `[i, i+1] x [j, j+1] x [k, k+1]`).
///
/// This is the core of [`voxelize`], public so benchmarks and other stages
/// can call it on prepared input.
pub fn fill(tris: &[[DVec3; 3]], dims: [usize; 3]) -> VoxelGrid {
    let mut bits = Bits::new(dims);
    // Each axis alone, the three side by side.
    let per_axis: Vec<(Vec<Crossing>, Bits)> = (0..3usize)
        .into_par_iter()
        .map(|axis| {
            let list = crossings(tris, dims, axis);
            let inside = inside_along(&list, dims, axis);
            (list, inside)
        })
        .collect();
    let (crossings, votes): (Vec<Vec<Crossing>>, Vec<Bits>) = per_axis.into_iter().unzip();

    // Majority vote of the three axes.
    for (((w, a), b), c) in bits
        .words
        .iter_mut()
        .zip(&votes[0].words)
        .zip(&votes[1].words)
        .zip(&votes[2].words)
    {
        *w = (a & b) | (a & c) | (b & c);
    }

    // Keep every surface within half a cell of a filled cell.
    for (axis, list) in crossings.iter().enumerate() {
        let n = dims[axis];
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for cr in list {
            let (iu, iv) = (cr.col as usize % dims[u], cr.col as usize / dims[u]);
            let at = |k: usize| {
                let mut c = [0; 3];
                c[axis] = k;
                c[u] = iu;
                c[v] = iv;
                c
            };
            let t = f64::from(cr.t);
            let k = (t.floor().max(0.0) as usize).min(n - 1);
            let near = if t - (k as f64) < 0.5 {
                k.checked_sub(1)
            } else {
                Some(k + 1).filter(|&k| k < n)
            };
            if !bits.get(at(k)) && !near.is_some_and(|j| bits.get(at(j))) {
                bits.set(at(k));
            }
        }
    }

    keep_borders(&mut bits, tris, dims);

    let mut grid = VoxelGrid::new(dims[0] as i32, dims[1] as i32, dims[2] as i32);
    for c in bits.ones() {
        grid.set(Cell::new(c[0] as i32, c[1] as i32, c[2] as i32), true);
    }
    grid
}

/// The triangles of `mesh` in the grid frame (f64), with exact duplicates
/// (the same three corners in any order) removed, first one kept.
///
/// Duplicates are found by sorting, not hashing, in parallel: each
/// triangle's key (its corners' bits, in order) sorted with its index, so
/// the first of a run of equal keys is the earliest triangle. A hash set of
/// a million 36-byte keys was a quarter of a big mesh's voxelizing, most
/// of it cache misses; the mesh's file decides the keys, so no hash that
/// chosen keys can defeat either.
fn unique_triangles(mesh: &Mesh, up: Up) -> Result<Vec<[DVec3; 3]>, VoxelizeError> {
    if mesh.triangles.is_empty() {
        return Err(VoxelizeError::EmptyMesh);
    }
    let count = mesh.positions.len();
    let corner = |i: u32| mesh.positions.get(i as usize).filter(|p| p.is_finite());
    // The first bad triangle, named as a walk in order would name it.
    if let Some(k) = mesh
        .triangles
        .par_iter()
        .position_first(|t| t.iter().any(|&i| corner(i).is_none()))
    {
        for &i in &mesh.triangles[k] {
            let p = mesh
                .positions
                .get(i as usize)
                .ok_or(VoxelizeError::IndexOutOfRange { index: i, count })?;
            if !p.is_finite() {
                return Err(VoxelizeError::NonFinite { index: i });
            }
        }
    }
    let corners: Vec<[Vec3; 3]> = mesh
        .triangles
        .par_iter()
        .map(|t| t.map(|i| to_grid_frame(mesh.positions[i as usize], up)))
        .collect();
    let mut keys: Vec<([[u32; 3]; 3], u32)> = corners
        .par_iter()
        .enumerate()
        .map(|(k, c)| {
            let mut key = c.map(|p| p.to_array().map(f32::to_bits));
            key.sort_unstable();
            (key, k as u32)
        })
        .collect();
    keys.par_sort_unstable();
    let mut keep = vec![false; corners.len()];
    let mut last = None;
    for (key, k) in &keys {
        if last != Some(key) {
            keep[*k as usize] = true;
            last = Some(key);
        }
    }
    drop(keys);
    Ok(corners
        .par_iter()
        .zip(&keep)
        .filter(|(_, &k)| k)
        .map(|(c, _)| c.map(|p| p.as_dvec3()))
        .collect())
}

/// Where a ray through cell centres meets a triangle.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    /// The ray: `iu + iv * n_u` over the two axes across the ray.
    col: u32,
    /// Depth along the ray, in cells.
    t: f32,
    /// +1 when the triangle faces along the ray, -1 against it.
    dir: i8,
}

/// Every crossing of the rays along `axis` with the triangles, sorted by
/// ray, then depth.
fn crossings(tris: &[[DVec3; 3]], dims: [usize; 3], axis: usize) -> Vec<Crossing> {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let (nu, nv) = (dims[u], dims[v]);
    let mut out = Vec::new();
    for tri in tris {
        let mut p = tri.map(|q| [q[u], q[v], q[axis]]);
        let area = cross2(p[0], p[1], p[2]);
        if area == 0.0 {
            continue; // seen edge-on: no ray crosses it
        }
        let dir = if area > 0.0 { 1 } else { -1 };
        if area < 0.0 {
            p.swap(1, 2);
        }
        let area = area.abs();
        let lo_u = p.iter().map(|q| q[0]).fold(f64::INFINITY, f64::min);
        let hi_u = p.iter().map(|q| q[0]).fold(f64::NEG_INFINITY, f64::max);
        let lo_v = p.iter().map(|q| q[1]).fold(f64::INFINITY, f64::min);
        let hi_v = p.iter().map(|q| q[1]).fold(f64::NEG_INFINITY, f64::max);
        let Some((u0, u1)) = column_range(lo_u, hi_u, nu) else {
            continue;
        };
        let Some((v0, v1)) = column_range(lo_v, hi_v, nv) else {
            continue;
        };
        for iv in v0..=v1 {
            for iu in u0..=u1 {
                let pt = [iu as f64 + 0.5, iv as f64 + 0.5];
                let w0 = edge(p[1], p[2], pt);
                let w1 = edge(p[2], p[0], pt);
                let w2 = edge(p[0], p[1], pt);
                if !(covers(w0, p[1], p[2]) && covers(w1, p[2], p[0]) && covers(w2, p[0], p[1])) {
                    continue;
                }
                let t = (w0 * p[0][2] + w1 * p[1][2] + w2 * p[2][2]) / area;
                out.push(Crossing {
                    col: (iv * nu + iu) as u32,
                    t: t as f32,
                    dir,
                });
            }
        }
    }
    out.sort_unstable_by(|a, b| a.col.cmp(&b.col).then(a.t.total_cmp(&b.t)));
    out
}

/// The columns `i` with centre `i + 0.5` in `[lo, hi]`, clamped to `0..n`.
fn column_range(lo: f64, hi: f64, n: usize) -> Option<(usize, usize)> {
    let first = (lo - 0.5).ceil().max(0.0);
    let last = (hi - 0.5).floor().min(n as f64 - 1.0);
    (first <= last).then_some((first as usize, last as usize))
}

/// Twice the signed area of the 2D triangle `a b c` (first two coordinates).
fn cross2(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// The edge function of `p0 -> p1` at `pt` (positive to the left).
///
/// It is always evaluated from the lexicographically smaller end, so the two
/// triangles sharing an edge get exactly opposite values, with no rounding
/// difference that could let a ray slip between them or hit both.
fn edge(p0: [f64; 3], p1: [f64; 3], pt: [f64; 2]) -> f64 {
    let raw =
        |a: [f64; 3], b: [f64; 3]| (b[0] - a[0]) * (pt[1] - a[1]) - (b[1] - a[1]) * (pt[0] - a[0]);
    if (p0[0], p0[1]) <= (p1[0], p1[1]) {
        raw(p0, p1)
    } else {
        -raw(p1, p0)
    }
}

/// Whether a point with edge value `w` on edge `p0 -> p1` of a
/// counter-clockwise triangle is covered: inside, or exactly on an edge that
/// the tie rule gives to this side (of an edge and its reverse, exactly one
/// is given the points on it).
fn covers(w: f64, p0: [f64; 3], p1: [f64; 3]) -> bool {
    if w != 0.0 {
        return w > 0.0;
    }
    let (du, dv) = (p1[0] - p0[0], p1[1] - p0[1]);
    dv < 0.0 || (dv == 0.0 && du > 0.0)
}

/// For one axis, the cells whose centre the rays along that axis find
/// inside: an odd number of crossings before it, or a non-zero winding.
fn inside_along(list: &[Crossing], dims: [usize; 3], axis: usize) -> Bits {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut bits = Bits::new(dims);
    let n = dims[axis];
    let mut rest = list;
    while let Some(first) = rest.first() {
        let col = first.col;
        let len = rest.iter().take_while(|c| c.col == col).count();
        let (ray, tail) = rest.split_at(len);
        rest = tail;
        let (iu, iv) = (col as usize % dims[u], col as usize / dims[u]);
        let (mut i, mut parity, mut winding) = (0, false, 0i32);
        for k in 0..n {
            let centre = k as f32 + 0.5;
            while i < ray.len() && ray[i].t < centre {
                parity = !parity;
                winding += i32::from(ray[i].dir);
                i += 1;
            }
            if i == ray.len() && !parity && winding == 0 {
                break;
            }
            if parity || winding != 0 {
                let mut c = [0; 3];
                c[axis] = k;
                c[u] = iu;
                c[v] = iv;
                bits.set(c);
            }
        }
    }
    bits
}

/// Makes sure no border layer of the grid is empty: a sharp tip may reach
/// into a border cell without any ray hitting it. The cell holding the
/// tip's extreme vertex is filled.
fn keep_borders(bits: &mut Bits, tris: &[[DVec3; 3]], dims: [usize; 3]) {
    for axis in 0..3 {
        for high in [false, true] {
            let k = if high { dims[axis] - 1 } else { 0 };
            if bits.any_in_layer(axis, k) {
                continue;
            }
            let pick = |a: &DVec3, b: &DVec3| a[axis].total_cmp(&b[axis]);
            let extreme = if high {
                tris.iter().flatten().max_by(|a, b| pick(a, b))
            } else {
                tris.iter().flatten().min_by(|a, b| pick(a, b))
            };
            if let Some(p) = extreme {
                let c = [0, 1, 2].map(|i| (p[i].floor().max(0.0) as usize).min(dims[i] - 1));
                bits.set(c);
            }
        }
    }
}

/// A plain bitset over the grid's cells (x fastest), for the working sets.
struct Bits {
    dims: [usize; 3],
    words: Vec<u64>,
}

impl Bits {
    fn new(dims: [usize; 3]) -> Self {
        let n = dims[0] * dims[1] * dims[2];
        Bits {
            dims,
            words: vec![0; n.div_ceil(64)],
        }
    }

    fn index(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    fn get(&self, c: [usize; 3]) -> bool {
        let i = self.index(c);
        self.words[i >> 6] >> (i & 63) & 1 == 1
    }

    fn set(&mut self, c: [usize; 3]) {
        let i = self.index(c);
        self.words[i >> 6] |= 1 << (i & 63);
    }

    fn any_in_layer(&self, axis: usize, k: usize) -> bool {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        (0..self.dims[v]).any(|iv| {
            (0..self.dims[u]).any(|iu| {
                let mut c = [0; 3];
                c[axis] = k;
                c[u] = iu;
                c[v] = iv;
                self.get(c)
            })
        })
    }

    /// The filled cells in index order.
    fn ones(&self) -> impl Iterator<Item = [usize; 3]> + '_ {
        let [nx, ny, _] = self.dims;
        self.words.iter().enumerate().flat_map(move |(w, &word)| {
            let mut word = word;
            std::iter::from_fn(move || {
                if word == 0 {
                    return None;
                }
                let i = w * 64 + word.trailing_zeros() as usize;
                word &= word - 1;
                Some([i % nx, i / nx % ny, i / (nx * ny)])
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An axis-aligned box `lo..hi` as 8 corners and 12 outward triangles,
    /// appended to `m`.
    fn add_box(m: &mut Mesh, lo: Vec3, hi: Vec3) {
        let base = m.positions.len() as u32;
        m.positions.extend((0..8).map(|i| {
            Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        }));
        let t: [[u32; 3]; 12] = [
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5], // +x face
            [3, 7, 5],
        ];
        m.triangles.extend(t.iter().map(|t| t.map(|i| i + base)));
    }

    fn boxed(lo: Vec3, hi: Vec3) -> Mesh {
        let mut m = Mesh::default();
        add_box(&mut m, lo, hi);
        m
    }

    /// A UV sphere of radius `r` around the origin.
    fn sphere(r: f32, segments: u32, rings: u32) -> Mesh {
        let mut m = Mesh::default();
        for i in 0..=rings {
            let th = std::f32::consts::PI * i as f32 / rings as f32;
            for j in 0..segments {
                let ph = std::f32::consts::TAU * j as f32 / segments as f32;
                m.positions
                    .push(Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * r);
            }
        }
        for i in 0..rings {
            for j in 0..segments {
                let a = i * segments + j;
                let b = i * segments + (j + 1) % segments;
                let (c, d) = (a + segments, b + segments);
                m.triangles.push([a, c, b]);
                m.triangles.push([b, c, d]);
            }
        }
        m
    }

    fn z_up(sizing: Sizing) -> VoxelizeOptions {
        VoxelizeOptions::default()
            .with_sizing(sizing)
            .with_up(Up::Z)
    }

    #[test]
    fn defaults_are_documented_values() {
        let o = VoxelizeOptions::default();
        assert_eq!(o.sizing, Sizing::Studs(24));
        assert_eq!(o.up, Up::Y);
    }

    #[test]
    fn unit_cube_fills_ten_by_ten_by_nine() {
        let cube = boxed(Vec3::ZERO, Vec3::ONE);
        for up in [Up::Y, Up::Z] {
            let m = voxelize(&cube, &z_up(Sizing::Studs(10)).with_up(up)).unwrap();
            assert_eq!(m.grid.dims(), (10, 10, 9));
            assert_eq!(m.grid.count(), 900);
            assert!((m.stud_size - 0.1).abs() < 1e-6);
            assert_eq!(m.layer_height_studs, 1.2);
        }
        let m = voxelize(&cube, &z_up(Sizing::Height(5))).unwrap();
        assert_eq!(m.grid.dims(), (6, 6, 5));
        assert_eq!(m.grid.count(), 180);
    }

    #[test]
    fn origin_and_cell_centres_map_back_to_input() {
        let cube = boxed(Vec3::new(5.0, 6.0, 7.0), Vec3::new(6.0, 7.0, 8.0));
        let m = voxelize(&cube, &z_up(Sizing::Studs(10))).unwrap();
        // 9 layers of 0.12 leave 0.08 spare, split above and below.
        assert!((m.origin - Vec3::new(5.0, 6.0, 6.96)).length() < 1e-5);
        let c = m.cell_center(Cell::new(0, 0, 0));
        assert!((c - Vec3::new(5.05, 6.05, 7.02)).length() < 1e-5);
    }

    #[test]
    fn open_mesh_still_solid_by_majority_vote() {
        // Box A is missing its +x face, so every x ray through it streaks
        // on through the gap to box B; the y and z rays outvote that.
        let mut m = boxed(Vec3::ZERO, Vec3::ONE);
        m.triangles.truncate(10);
        add_box(&mut m, Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 1.0));
        let v = voxelize(&m, &z_up(Sizing::Studs(30))).unwrap();
        assert_eq!(v.grid.dims(), (30, 10, 9));
        assert_eq!(v.grid.count(), 1800);
        for c in v.grid.cells() {
            assert!(c.x < 10 || c.x >= 20, "gap cell {c:?} filled");
        }
    }

    #[test]
    fn duplicated_flipped_and_degenerate_triangles_change_nothing() {
        let cube = boxed(Vec3::ZERO, Vec3::ONE);
        let want = voxelize(&cube, &z_up(Sizing::Studs(10))).unwrap();
        let mut messy = cube.clone();
        let copies: Vec<[u32; 3]> = cube.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect();
        messy.triangles.extend(copies);
        messy.triangles.extend(cube.triangles.iter().copied());
        messy.triangles.push([0, 0, 1]);
        messy.triangles.push([0, 1, 1]);
        let got = voxelize(&messy, &z_up(Sizing::Studs(10))).unwrap();
        assert_eq!(got, want);
    }

    #[test]
    fn overlapping_parts_have_no_hole() {
        // Two boxes overlapping in the middle third: parity alone would
        // leave the overlap empty; the winding number fills it.
        let mut m = boxed(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0));
        add_box(&mut m, Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 1.0));
        let v = voxelize(&m, &z_up(Sizing::Studs(30))).unwrap();
        assert_eq!(v.grid.count(), 30 * 10 * 9);
    }

    #[test]
    fn sphere_volume_within_five_percent() {
        let s = sphere(1.0, 64, 32);
        let v = voxelize(&s, &z_up(Sizing::Studs(24))).unwrap();
        let r = 12.0f64; // studs
        let want = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) / 1.2;
        let got = v.grid.count() as f64;
        assert!(
            (got - want).abs() / want < 0.05,
            "{got} voxels, want {want}"
        );
        assert_eq!(v.grid.dims(), (24, 24, 20));
    }

    #[test]
    fn up_y_and_up_z_agree_on_rotated_input() {
        // An L of two boxes, asymmetric along every axis, in z-up.
        let mut m = boxed(Vec3::ZERO, Vec3::new(4.0, 1.0, 1.0));
        add_box(&mut m, Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 2.5, 3.0));
        let mut y_up = m.clone();
        // Inverse of (x, y, z) -> (x, -z, y).
        for p in &mut y_up.positions {
            *p = Vec3::new(p.x, p.z, -p.y);
        }
        let opts = VoxelizeOptions::default().with_sizing(Sizing::Studs(16));
        let a = voxelize(&m, &opts.with_up(Up::Z)).unwrap();
        let b = voxelize(&y_up, &opts.with_up(Up::Y)).unwrap();
        assert_eq!(a, b);
        assert!(a.grid.get(Cell::new(15, 0, 0)) && !a.grid.get(Cell::new(15, 0, 5)));
    }

    #[test]
    fn thin_wall_survives_one_cell_thick() {
        // A 20 x 10 x 12 block, and 4 units away a wall 0.3 units thick.
        let mut m = boxed(Vec3::ZERO, Vec3::new(20.0, 10.0, 12.0));
        add_box(
            &mut m,
            Vec3::new(0.0, 14.35, 0.0),
            Vec3::new(20.0, 14.65, 12.0),
        );
        let v = voxelize(&m, &z_up(Sizing::Studs(20))).unwrap();
        assert_eq!(v.grid.dims(), (20, 15, 10));
        for z in 0..10 {
            for x in 0..20 {
                let wall = (11..15).filter(|&y| v.grid.get(Cell::new(x, y, z))).count();
                assert_eq!(wall, 1, "at x={x} z={z}");
            }
        }
        assert_eq!(v.grid.count(), 2000 + 200);
    }

    #[test]
    fn single_sided_sheet_survives() {
        // One quad, no thickness at all, tilted, next to a cube.
        let mut m = boxed(Vec3::ZERO, Vec3::splat(4.0));
        let b = m.positions.len() as u32;
        m.positions.extend([
            Vec3::new(0.0, 6.0, 0.0),
            Vec3::new(8.0, 6.0, 0.0),
            Vec3::new(0.0, 7.3, 4.0),
            Vec3::new(8.0, 7.3, 4.0),
        ]);
        m.triangles
            .extend([[b, b + 1, b + 2], [b + 1, b + 3, b + 2]]);
        let v = voxelize(&m, &z_up(Sizing::Studs(8))).unwrap();
        for x in 0..8 {
            for z in 0..3 {
                assert!(
                    (5..8).any(|y| v.grid.get(Cell::new(x, y, z))),
                    "sheet lost at x={x} z={z}"
                );
            }
        }
    }

    #[test]
    fn errors() {
        let cube = boxed(Vec3::ZERO, Vec3::ONE);
        let o = VoxelizeOptions::default();
        assert_eq!(
            voxelize(&Mesh::default(), &o),
            Err(VoxelizeError::EmptyMesh)
        );
        assert_eq!(
            voxelize(&cube, &o.with_sizing(Sizing::Studs(0))),
            Err(VoxelizeError::ZeroSize)
        );
        let e = voxelize(&cube, &o.with_sizing(Sizing::Studs(600))).unwrap_err();
        assert!(matches!(e, VoxelizeError::TooLarge { .. }));
        assert!(e.to_string().contains("fewer studs"), "{e}");
        let tall = boxed(Vec3::ZERO, Vec3::new(1.0, 1.0, 1000.0));
        let e = voxelize(&tall, &z_up(Sizing::Studs(24))).unwrap_err();
        assert!(matches!(e, VoxelizeError::TooLarge { .. }), "{e}");
        let flat = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            triangles: vec![[0, 1, 2]],
            ..Mesh::default()
        };
        let e = voxelize(&flat, &z_up(Sizing::Height(3))).unwrap_err();
        assert!(matches!(e, VoxelizeError::Flat { .. }), "{e}");
        // Sized by studs, a flat sheet is one layer, in a grid with room
        // over it to be made two layers thick.
        let v = voxelize(&flat, &z_up(Sizing::Studs(4))).unwrap();
        assert_eq!(v.grid.dims().2, 2);
        assert!(v.grid.count_layer(0) >= 4);
        assert_eq!(v.grid.count_layer(1), 0);
        let mut bad = flat.clone();
        bad.triangles[0][1] = 9;
        assert!(matches!(
            voxelize(&bad, &o),
            Err(VoxelizeError::IndexOutOfRange { index: 9, .. })
        ));
        let mut bad = flat;
        bad.positions[2].x = f32::NAN;
        assert_eq!(
            voxelize(&bad, &o),
            Err(VoxelizeError::NonFinite { index: 2 })
        );
    }

    #[test]
    fn duplicates_go_the_first_kept_in_order_and_the_first_bad_triangle_is_named() {
        let positions: Vec<Vec3> = (0..40)
            .map(|k| Vec3::new(k as f32, (k * k % 7) as f32, (k % 3) as f32))
            .collect();
        // Triangle k, and every fifth again later with its corners turned.
        let mut triangles: Vec<[u32; 3]> = (0..30).map(|k| [k, k + 1, k + 5]).collect();
        triangles.extend((0..30).step_by(5).map(|k| [k + 5, k, k + 1]));
        triangles.insert(3, [7, 8, 12]);
        let mesh = Mesh {
            positions,
            triangles,
            ..Mesh::default()
        };
        let got = unique_triangles(&mesh, Up::Z).unwrap();
        // Triangle 7 first comes fourth.
        let mut order: Vec<usize> = (0..30).filter(|&k| k != 7).collect();
        order.insert(3, 7);
        let want: Vec<[DVec3; 3]> = order
            .into_iter()
            .map(|k| [k, k + 1, k + 5].map(|i| mesh.positions[i].as_dvec3()))
            .collect();
        assert_eq!(got, want);
        let mut bad = mesh.clone();
        bad.positions[9].y = f32::INFINITY;
        bad.triangles[1] = [2, 3, 99];
        assert_eq!(
            unique_triangles(&bad, Up::Z),
            Err(VoxelizeError::IndexOutOfRange {
                index: 99,
                count: 40
            })
        );
        bad.triangles[1] = [2, 3, 4];
        assert_eq!(
            unique_triangles(&bad, Up::Z),
            Err(VoxelizeError::NonFinite { index: 9 })
        );
    }

    #[test]
    fn borders_are_never_empty() {
        // A steep cone (a pyramid of many sides): its tip reaches the top
        // layer but no ray through a cell centre hits it there.
        let mut m = Mesh::default();
        let n = 7;
        for i in 0..n {
            let a = std::f32::consts::TAU * i as f32 / n as f32;
            m.positions.push(Vec3::new(a.cos(), a.sin(), 0.0));
        }
        m.positions.push(Vec3::new(0.0, 0.0, 5.0));
        m.positions.push(Vec3::ZERO);
        for i in 0..n {
            let j = (i + 1) % n;
            m.triangles.push([i, j, n]);
            m.triangles.push([j, i, n + 1]);
        }
        let v = voxelize(&m, &z_up(Sizing::Studs(5))).unwrap();
        let (nx, ny, nz) = v.grid.dims();
        let b = v.grid.bounds().unwrap();
        assert_eq!((b.min, b.sx, b.sy, b.sz), (Cell::new(0, 0, 0), nx, ny, nz));
    }

    /// Release-mode timing: `cargo test --release --lib voxelize_speed -- --ignored --nocapture`.
    #[test]
    #[ignore = "timing, run by hand in release mode"]
    fn voxelize_speed() {
        let s = sphere(1.0, 317, 158); // ~100k triangles
        let opts = z_up(Sizing::Studs(64));
        let t = std::time::Instant::now();
        let v = voxelize(&s, &opts).unwrap();
        let once = t.elapsed();
        let t = std::time::Instant::now();
        for _ in 0..5 {
            voxelize(&s, &opts).unwrap();
        }
        println!(
            "{} triangles at 64 studs: first {:?}, mean {:?}, {} cells filled",
            s.triangles.len(),
            once,
            t.elapsed() / 5,
            v.grid.count()
        );
    }
}
