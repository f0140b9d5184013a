//! A LEGO colour for every voxel of a coloured mesh.
//!
//! The mesh's surface is sampled as densely as the voxelizer samples it
//! (every third of a cell or finer); each sample's colour ([`Paint::sample`]:
//! material × texture × vertex colour) is matched to the nearest catalog
//! colour some part is made in, by CIEDE2000 ([`lab::nearest_in`]), and each cell the surface
//! passes through takes the colour most of its samples have. Filled cells
//! with no sample (inner voxels, and the odd surface voxel the surface only
//! grazes) take the colour of the nearest coloured cell, by a breadth-first
//! walk through the filled cells.
//!
//! With a colour limit, the model's colours are reduced first
//! ([`lab::reduce`]: the rarest merged into its nearest in Lab), so the build
//! uses at most that many. Last, the surface colours are smoothed
//! ([`smooth`](super::smooth)): specks and ragged edges would cut the
//! pieces into many small ones.
//!
//! [`Paint::sample`]: crate::mesh::Paint::sample

use std::collections::{HashMap, VecDeque};

use glam::Vec3;

use super::{to_grid_frame, Up, VoxelGrid, VoxelModel};
use crate::catalog::{buildable, lab, Color, COLORS};
use crate::geom::{Cell, FACES};
use crate::mesh::{paint::linear_to_srgb, Mesh};

/// The colours of a model's voxels.
#[derive(Debug, Clone, PartialEq)]
pub struct VoxelColors {
    /// Per cell of the grid (by [`VoxelGrid::index`]): the colour of a
    /// filled cell, `None` for an empty one; on the surface, after the smoothing
    /// ([`smooth`](super::smooth)). The colours the layout and the pieces
    /// follow.
    pub cells: Vec<Option<Color>>,
    /// Per cell: the colour as sampled from the model, before the
    /// smoothing: what the build is measured against.
    pub sampled: Vec<Option<Color>>,
    /// Surface voxels the smoothing gave their neighbours' colour.
    pub smoothed: usize,
    /// Per cell: whether it is a surface voxel (filled, with a face on an
    /// empty cell or the grid's edge): the voxels a viewer sees.
    pub surface: Vec<bool>,
    /// The colours used, with how many surface voxels show each, most
    /// first.
    pub used: Vec<(Color, usize)>,
    /// Whether the colours were reduced to a limit: a piece whose part is
    /// not made in its colour then takes the nearest of `used` it is made
    /// in, so the build keeps to the limit.
    pub limited: bool,
}

impl VoxelColors {
    /// Per cell: `code + 1` of a surface voxel's colour, 0 elsewhere: what
    /// the layout keeps apart.
    pub fn surface_labels(&self) -> Vec<u16> {
        self.cells
            .iter()
            .zip(&self.surface)
            .map(|(c, &s)| match (c, s) {
                (Some(c), true) => c.0.saturating_add(1),
                _ => 0,
            })
            .collect()
    }
}

/// Colours `model`'s voxels from `mesh` (voxelized with `up`), with at most
/// `max_colors` colours when given. `None` when the mesh has no colours.
pub fn color_voxels(
    mesh: &Mesh,
    model: &VoxelModel,
    up: Up,
    max_colors: Option<usize>,
) -> Option<VoxelColors> {
    let paint = mesh.paint.as_ref().filter(|p| p.has_color())?;
    let grid = &model.grid;
    // Only colours some part is made in: a voxel of a colour no piece
    // comes in could not be built.
    let all: Vec<Color> = COLORS
        .iter()
        .map(|c| c.code)
        .filter(|&c| buildable(c))
        .collect();
    let mut cache: HashMap<[u8; 3], Color> = HashMap::new();
    let cell = model.cell_size();
    let frame = |t: &[u32; 3]| {
        t.map(|i| (to_grid_frame(mesh.positions[i as usize], up) - model.origin) / cell)
    };
    let steps = sample_steps(
        mesh.triangles.iter().map(|t| {
            let p = frame(t);
            (p[1] - p[0])
                .length()
                .max((p[2] - p[0]).length())
                .max((p[2] - p[1]).length())
        }),
        sample_budget(grid.count()),
    );
    let mut votes: Vec<(u32, Color, u32)> = Vec::new();
    for (k, t) in mesh.triangles.iter().enumerate() {
        let p = frame(t);
        let steps = steps[k] as usize;
        // A sample on a cell boundary (a face flush with the grid) belongs
        // to the cell behind the face: step a hair inward.
        let inward = -(p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero() * 0.01;
        for i in 0..=steps {
            for j in 0..=(steps - i) {
                let (a, b) = (i as f32 / steps as f32, j as f32 / steps as f32);
                // Pull samples a hair toward the centroid so a corner
                // shared by two materials is not a tie.
                let (a, b) = (a * 0.98 + 0.0066, b * 0.98 + 0.0066);
                let q: Vec3 = p[0] + (p[1] - p[0]) * a + (p[2] - p[0]) * b + inward;
                let c = Cell::new(q.x.floor() as i32, q.y.floor() as i32, q.z.floor() as i32);
                if !grid.in_bounds(c) {
                    continue;
                }
                let lin = paint.sample(k, [1.0 - a - b, a, b]);
                let rgb = lin.map(|x| (linear_to_srgb(x) * 255.0).round() as u8);
                let key = rgb.map(|x| x & 0xfc);
                let lego = *cache
                    .entry(key)
                    .or_insert_with(|| lab::nearest_in(key, &all));
                let idx = grid.index(c) as u32;
                // Runs of samples in one cell and colour count as one entry.
                match votes.last_mut() {
                    Some(v) if v.0 == idx && v.1 == lego => v.2 += 1,
                    _ => votes.push((idx, lego, 1)),
                }
            }
        }
    }
    votes.sort_unstable();
    let mut cells: Vec<Option<Color>> = vec![None; grid.len()];
    let mut run = 0;
    while run < votes.len() {
        let idx = votes[run].0;
        let end = run + votes[run..].partition_point(|v| v.0 == idx);
        // Most votes; ties to the lower code.
        let mut best = (0u32, Color(u16::MAX));
        let mut i = run;
        while i < end {
            let c = votes[i].1;
            let n = votes[i..end].partition_point(|v| v.1 == c);
            let w: u32 = votes[i..i + n].iter().map(|v| v.2).sum();
            if w > best.0 {
                best = (w, c);
            }
            i += n;
        }
        cells[idx as usize] = Some(best.1);
        run = end;
    }
    spread(grid, &mut cells);
    let surface = surface_cells(grid);
    let mut used = count(&cells, &surface);
    let limited = max_colors.is_some_and(|n| n < used.len());
    if let Some(n) = max_colors.filter(|&n| n < used.len()) {
        let weights: Vec<(Color, u64)> = used.iter().map(|&(c, w)| (c, w as u64)).collect();
        let into: HashMap<Color, Color> = lab::reduce(&weights, n).into_iter().collect();
        for c in cells.iter_mut().flatten() {
            *c = into[c];
        }
    }
    let sampled = cells.clone();
    let smoothed = super::smooth::smooth(grid, &mut cells, &surface);
    used = count(&cells, &surface);
    Some(VoxelColors {
        cells,
        sampled,
        smoothed,
        surface,
        used,
        limited,
    })
}

/// The most surface samples [`color_voxels`] takes in all, for a grid of
/// `voxels` filled cells: 8 million, or 8 a voxel for a larger model
/// (every triangle still gets its three samples of one step). Without a
/// budget, a small file repeating one large triangle 10,000 times asked for
/// hundreds of millions of samples.
fn sample_budget(voxels: usize) -> u64 {
    (1u64 << 23).max(8 * voxels as u64)
}

/// Samples along each side of each triangle (the sample count of a
/// triangle is `(s + 1)(s + 2) / 2` for `s` steps): every third of a cell
/// over its longest side (`spans`, in cells), at most 4096; then, if the
/// total passes `budget`, every triangle's steps scaled down alike (at
/// least 1) until it is under, so the total stays at most the budget (or
/// one step a triangle) whatever the file repeats.
fn sample_steps(spans: impl Iterator<Item = f32>, budget: u64) -> Vec<u16> {
    let mut steps: Vec<u16> = spans
        .map(|span| (span * 3.0).ceil().clamp(1.0, 4096.0) as u16)
        .collect();
    let count = |s: u16| (u64::from(s) + 1) * (u64::from(s) + 2) / 2;
    let total: u64 = steps.iter().map(|&s| count(s)).sum();
    if total > budget {
        let full = steps.clone();
        let mut f = (budget as f64 / total as f64).sqrt();
        // The counts' linear terms can leave the first guess a little over:
        // shrink on until under (or every triangle is at one step).
        loop {
            for (s, &n) in steps.iter_mut().zip(&full) {
                *s = ((f64::from(n) * f).floor() as u16).max(1);
            }
            let now: u64 = steps.iter().map(|&s| count(s)).sum();
            if now <= budget || steps.iter().all(|&s| s == 1) {
                break;
            }
            f *= 0.97;
        }
    }
    steps
}

/// Gives every filled cell the colour of the nearest coloured cell (a
/// breadth-first walk through filled cells from every coloured one), then
/// clears the empty cells.
fn spread(grid: &VoxelGrid, cells: &mut [Option<Color>]) {
    let (nx, ny, nz) = grid.dims();
    let mut queue: VecDeque<Cell> = VecDeque::new();
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let c = Cell::new(x, y, z);
                if cells[grid.index(c)].is_some() {
                    queue.push_back(c);
                }
            }
        }
    }
    while let Some(c) = queue.pop_front() {
        let color = cells[grid.index(c)];
        for (dx, dy, dz) in FACES {
            let n = c.offset(dx, dy, dz);
            if grid.in_bounds(n) && grid.get(n) && cells[grid.index(n)].is_none() {
                cells[grid.index(n)] = color;
                queue.push_back(n);
            }
        }
    }
    let fallback = Color::LIGHT_BLUISH_GREY;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let c = Cell::new(x, y, z);
                let slot = &mut cells[grid.index(c)];
                if !grid.get(c) {
                    *slot = None;
                } else if slot.is_none() {
                    *slot = Some(fallback);
                }
            }
        }
    }
}

/// Per cell: filled with an empty or out-of-grid face neighbour.
fn surface_cells(grid: &VoxelGrid) -> Vec<bool> {
    let mut out = vec![false; grid.len()];
    for c in grid.cells() {
        out[grid.index(c)] = FACES.iter().any(|&(dx, dy, dz)| {
            let n = c.offset(dx, dy, dz);
            !grid.in_bounds(n) || !grid.get(n)
        });
    }
    out
}

/// Surface voxels per colour, most first (ties by code).
fn count(cells: &[Option<Color>], surface: &[bool]) -> Vec<(Color, usize)> {
    let mut m: HashMap<Color, usize> = HashMap::new();
    for (c, &s) in cells.iter().zip(surface) {
        if let (Some(c), true) = (c, s) {
            *m.entry(*c).or_default() += 1;
        }
    }
    let mut v: Vec<(Color, usize)> = m.into_iter().collect();
    v.sort_by_key(|&(c, n)| (std::cmp::Reverse(n), c));
    v
}

#[cfg(test)]
mod tests {
    use super::sample_steps;

    fn samples(steps: &[u16]) -> u64 {
        steps
            .iter()
            .map(|&s| (u64::from(s) + 1) * (u64::from(s) + 2) / 2)
            .sum()
    }

    #[test]
    fn samples_stay_under_the_budget_however_often_a_triangle_repeats() {
        // One triangle 200 cells across, 10,000 times (issue 30, finding 4):
        // 181 million samples unbounded.
        let spans = std::iter::repeat_n(200.0f32, 10_000);
        let steps = sample_steps(spans, 1 << 23);
        let n = samples(&steps);
        assert!(n <= 1 << 23, "{n}");
        assert!(n > 1 << 22, "the budget is used, not starved: {n}");
        // Under the budget nothing changes: every third of a cell.
        assert_eq!(
            sample_steps([0.1f32, 2.0, 10.0].into_iter(), 1 << 23),
            vec![1, 6, 30]
        );
        // Tiny triangles past the budget keep one step each.
        let tiny = sample_steps(std::iter::repeat_n(0.2f32, 100), 10);
        assert!(tiny.iter().all(|&s| s == 1));
    }
}
