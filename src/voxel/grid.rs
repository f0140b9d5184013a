//! A dense bitset of voxels, one bit a cell, rows of 64-bit words.

use crate::geom::{Body, Cell, CellBox};

/// A dense 3D bitset over `nx * ny * nz` cells; `x` is the fastest axis.
///
/// Each row of cells along x is padded to whole 64-bit words, so a run of
/// cells along x is tested with a mask.
#[derive(Clone, PartialEq, Eq)]
pub struct VoxelGrid {
    nx: i32,
    ny: i32,
    nz: i32,
    words_per_row: usize,
    bits: Vec<u64>,
}

impl std::fmt::Debug for VoxelGrid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "VoxelGrid({}x{}x{}, {} filled)",
            self.nx,
            self.ny,
            self.nz,
            self.count()
        )
    }
}

impl VoxelGrid {
    /// An empty grid of the given size. Sizes below 1 are raised to 1.
    pub fn new(nx: i32, ny: i32, nz: i32) -> Self {
        let (nx, ny, nz) = (nx.max(1), ny.max(1), nz.max(1));
        let words_per_row = (nx as usize).div_ceil(64);
        VoxelGrid {
            nx,
            ny,
            nz,
            words_per_row,
            bits: vec![0; words_per_row * ny as usize * nz as usize],
        }
    }

    /// Size along x, y and z.
    pub fn dims(&self) -> (i32, i32, i32) {
        (self.nx, self.ny, self.nz)
    }

    /// Whether `c` lies inside the grid.
    #[inline]
    pub fn in_bounds(&self, c: Cell) -> bool {
        c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < self.nx && c.y < self.ny && c.z < self.nz
    }

    #[inline]
    fn row(&self, y: i32, z: i32) -> usize {
        (z as usize * self.ny as usize + y as usize) * self.words_per_row
    }

    /// Whether `c` is filled; cells outside the grid are empty.
    #[inline]
    pub fn get(&self, c: Cell) -> bool {
        if !self.in_bounds(c) {
            return false;
        }
        let w = self.row(c.y, c.z) + (c.x as usize >> 6);
        self.bits[w] >> (c.x & 63) & 1 == 1
    }

    /// Fills or clears `c`. Panics if `c` is outside the grid (a caller bug).
    #[inline]
    pub fn set(&mut self, c: Cell, on: bool) {
        assert!(self.in_bounds(c), "cell {c:?} outside grid {self:?}");
        let w = self.row(c.y, c.z) + (c.x as usize >> 6);
        let m = 1u64 << (c.x & 63);
        if on {
            self.bits[w] |= m;
        } else {
            self.bits[w] &= !m;
        }
    }

    /// Mask of the bits for cells `x0..x0+len` within one word, and the word.
    #[inline]
    fn run_words(&self, x0: i32, len: i32) -> impl Iterator<Item = (usize, u64)> {
        let x1 = x0 + len; // exclusive
        let first = x0 as usize >> 6;
        let last = (x1 as usize - 1) >> 6;
        (first..=last).map(move |w| {
            let lo = if w == first { x0 as usize & 63 } else { 0 };
            let hi = if w == last {
                ((x1 as usize - 1) & 63) + 1
            } else {
                64
            };
            let mask = if hi - lo == 64 {
                u64::MAX
            } else {
                ((1u64 << (hi - lo)) - 1) << lo
            };
            (w, mask)
        })
    }

    /// Whether every cell of `b` is filled (false if `b` leaves the grid).
    pub fn all_set(&self, b: &CellBox) -> bool {
        let m = b.max_excl();
        if b.min.x < 0
            || b.min.y < 0
            || b.min.z < 0
            || m.x > self.nx
            || m.y > self.ny
            || m.z > self.nz
        {
            return false;
        }
        for z in b.min.z..m.z {
            for y in b.min.y..m.y {
                let r = self.row(y, z);
                for (w, mask) in self.run_words(b.min.x, b.sx) {
                    if self.bits[r + w] & mask != mask {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// Whether any cell of `b` inside the grid is filled.
    pub fn any_set(&self, b: &CellBox) -> bool {
        let m = b.max_excl();
        let (x0, y0, z0) = (b.min.x.max(0), b.min.y.max(0), b.min.z.max(0));
        let (x1, y1, z1) = (m.x.min(self.nx), m.y.min(self.ny), m.z.min(self.nz));
        if x0 >= x1 || y0 >= y1 || z0 >= z1 {
            return false;
        }
        for z in z0..z1 {
            for y in y0..y1 {
                let r = self.row(y, z);
                for (w, mask) in self.run_words(x0, x1 - x0) {
                    if self.bits[r + w] & mask != 0 {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Fills or clears every cell a piece fills (inside the grid).
    pub fn set_body(&mut self, b: &Body, on: bool) {
        for x in b.boxes() {
            self.set_box(x, on);
        }
    }

    /// Fills or clears every cell of `b` (which must lie inside the grid).
    pub fn set_box(&mut self, b: &CellBox, on: bool) {
        let m = b.max_excl();
        assert!(self.in_bounds(b.min) && self.in_bounds(m.offset(-1, -1, -1)));
        // The masks are the same for every row of the box.
        let mut masks = [(0usize, 0u64); 16];
        let mut n = 0;
        for (w, mask) in self.run_words(b.min.x, b.sx) {
            if n == masks.len() {
                break;
            }
            masks[n] = (w, mask);
            n += 1;
        }
        for z in b.min.z..m.z {
            for y in b.min.y..m.y {
                let r = self.row(y, z);
                for &(w, mask) in &masks[..n] {
                    if on {
                        self.bits[r + w] |= mask;
                    } else {
                        self.bits[r + w] &= !mask;
                    }
                }
            }
        }
    }

    /// Number of filled cells.
    pub fn count(&self) -> usize {
        self.bits.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// Number of filled cells in layer `z`.
    pub fn count_layer(&self, z: i32) -> usize {
        if z < 0 || z >= self.nz {
            return 0;
        }
        let n = self.words_per_row * self.ny as usize;
        let s = z as usize * n;
        self.bits[s..s + n]
            .iter()
            .map(|w| w.count_ones() as usize)
            .sum()
    }

    /// Whether no cell is filled.
    pub fn is_empty(&self) -> bool {
        self.bits.iter().all(|&w| w == 0)
    }

    /// Filled cells of layer `z`, in raster order (x fastest).
    pub fn layer_cells(&self, z: i32) -> impl Iterator<Item = Cell> + '_ {
        let wpr = self.words_per_row;
        let rows = if z >= 0 && z < self.nz { self.ny } else { 0 };
        (0..rows).flat_map(move |y| {
            let r = self.row(y, z);
            (0..wpr).flat_map(move |w| {
                let mut word = self.bits[r + w];
                std::iter::from_fn(move || {
                    if word == 0 {
                        return None;
                    }
                    let b = word.trailing_zeros();
                    word &= word - 1;
                    Some(Cell::new((w as i32) * 64 + b as i32, y, z))
                })
            })
        })
    }

    /// Every filled cell, layer by layer from the bottom, raster order within.
    pub fn cells(&self) -> impl Iterator<Item = Cell> + '_ {
        (0..self.nz).flat_map(move |z| self.layer_cells(z))
    }

    /// The smallest box holding every filled cell, or `None` if empty.
    pub fn bounds(&self) -> Option<CellBox> {
        let mut lo = Cell::new(i32::MAX, i32::MAX, i32::MAX);
        let mut hi = Cell::new(i32::MIN, i32::MIN, i32::MIN);
        for c in self.cells() {
            lo = Cell::new(lo.x.min(c.x), lo.y.min(c.y), lo.z.min(c.z));
            hi = Cell::new(hi.x.max(c.x), hi.y.max(c.y), hi.z.max(c.z));
        }
        (lo.x <= hi.x).then(|| CellBox {
            min: lo,
            sx: hi.x - lo.x + 1,
            sy: hi.y - lo.y + 1,
            sz: hi.z - lo.z + 1,
        })
    }

    /// The cells `o` at which every box of `boxes`, moved by `o`, lies
    /// wholly in filled cells: where a piece whose body is `boxes` at the
    /// origin fits. Boxes must not reach below the origin on any axis
    /// (none is found where one does).
    pub fn fits(&self, boxes: &[CellBox]) -> VoxelGrid {
        let mut out = VoxelGrid::new(self.nx, self.ny, self.nz);
        if boxes.is_empty()
            || boxes
                .iter()
                .any(|b| b.min.x < 0 || b.min.y < 0 || b.min.z < 0)
        {
            return out;
        }
        let wpr = self.words_per_row;
        let rows = (self.ny * self.nz) as usize;
        // `row` shifted down by `k` bits (cell x + k to bit x), ANDed into
        // `acc`.
        let and_shifted = |acc: &mut [u64], row: &[u64], k: usize| {
            let (q, r) = (k / 64, k % 64);
            for (w, a) in acc.iter_mut().enumerate() {
                let lo = row.get(w + q).copied().unwrap_or(0);
                let v = if r == 0 {
                    lo
                } else {
                    let hi = row.get(w + q + 1).copied().unwrap_or(0);
                    (lo >> r) | (hi << (64 - r))
                };
                *a &= v;
            }
        };
        out.bits.fill(u64::MAX);
        // Each box is worn down one axis at a time: along x within each
        // row, then across rows along y, then across layers along z.
        let mut xs = vec![0u64; self.bits.len()];
        let mut ys = vec![0u64; self.bits.len()];
        for b in boxes {
            xs.fill(u64::MAX);
            for i in 0..rows {
                let (row, acc) = (
                    &self.bits[i * wpr..(i + 1) * wpr],
                    &mut xs[i * wpr..(i + 1) * wpr],
                );
                for dx in 0..b.sx {
                    and_shifted(acc, row, (b.min.x + dx) as usize);
                }
            }
            for z in 0..self.nz {
                for y in 0..self.ny {
                    let r = self.row(y, z);
                    let acc = &mut ys[r..r + wpr];
                    acc.fill(u64::MAX);
                    for dy in 0..b.sy {
                        let sy = y + b.min.y + dy;
                        if sy >= self.ny {
                            acc.fill(0);
                            break;
                        }
                        let s = self.row(sy, z);
                        for w in 0..wpr {
                            acc[w] &= xs[s + w];
                        }
                    }
                }
            }
            for z in 0..self.nz {
                for y in 0..self.ny {
                    let r = self.row(y, z);
                    for dz in 0..b.sz {
                        let sz = z + b.min.z + dz;
                        if sz >= self.nz {
                            out.bits[r..r + wpr].fill(0);
                            break;
                        }
                        let s = self.row(y, sz);
                        for w in 0..wpr {
                            out.bits[r + w] &= ys[s + w];
                        }
                    }
                }
            }
        }
        out
    }

    /// The cells (filled or not) whose neighbour `dz` layers up (down, if
    /// negative) is empty, or lies above or below the grid.
    pub fn empty_beside(&self, dz: i32) -> VoxelGrid {
        let mut out = VoxelGrid::new(self.nx, self.ny, self.nz);
        let wpr = self.words_per_row;
        // The bits of a row's cells (no padding).
        let full: Vec<u64> = (0..wpr)
            .map(|w| {
                let n = (self.nx as usize).saturating_sub(w * 64).min(64);
                if n == 64 {
                    u64::MAX
                } else {
                    (1u64 << n) - 1
                }
            })
            .collect();
        for z in 0..self.nz {
            let from = z + dz;
            for y in 0..self.ny {
                let r = out.row(y, z);
                for (w, &mask) in full.iter().enumerate() {
                    out.bits[r + w] = if from < 0 || from >= self.nz {
                        mask
                    } else {
                        !self.bits[self.row(y, from) + w] & mask
                    };
                }
            }
        }
        out
    }

    /// Keeps the cells filled in both grids (of the same size).
    pub fn intersect(&mut self, other: &VoxelGrid) {
        debug_assert_eq!(self.dims(), other.dims());
        for (a, b) in self.bits.iter_mut().zip(&other.bits) {
            *a &= b;
        }
    }

    /// Fills the cells filled in `other` (of the same size).
    pub fn unite(&mut self, other: &VoxelGrid) {
        debug_assert_eq!(self.dims(), other.dims());
        for (a, b) in self.bits.iter_mut().zip(&other.bits) {
            *a |= b;
        }
    }

    /// Linear index of an in-bounds cell (x fastest), for side tables.
    #[inline]
    pub fn index(&self, c: Cell) -> usize {
        (c.z as usize * self.ny as usize + c.y as usize) * self.nx as usize + c.x as usize
    }

    /// Number of cells in the grid, filled or not.
    pub fn len(&self) -> usize {
        self.nx as usize * self.ny as usize * self.nz as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_get_and_boxes_across_word_boundaries() {
        let mut g = VoxelGrid::new(130, 3, 2);
        let b = CellBox {
            min: Cell::new(60, 1, 0),
            sx: 70,
            sy: 2,
            sz: 2,
        };
        g.set_box(&b, true);
        assert_eq!(g.count(), 70 * 2 * 2);
        assert!(g.all_set(&b));
        assert!(g.get(Cell::new(63, 1, 1)) && g.get(Cell::new(64, 2, 0)));
        assert!(!g.get(Cell::new(59, 1, 0)));
        let inner = CellBox {
            min: Cell::new(100, 1, 1),
            sx: 3,
            sy: 1,
            sz: 1,
        };
        g.set_box(&inner, false);
        assert!(!g.all_set(&b));
        assert!(g.any_set(&b));
        assert_eq!(g.layer_cells(1).count(), 70 * 2 - 3);
        assert_eq!(g.bounds().unwrap(), b);
        assert!(!g.any_set(&CellBox {
            min: Cell::new(0, 0, 0),
            sx: 60,
            sy: 3,
            sz: 2
        }));
    }

    #[test]
    fn fits_finds_every_place_a_body_lies_in_filled_cells() {
        // A grid wider than a word, filled at random; an L of two boxes
        // and a long bar: each place compared with testing every box.
        let mut g = VoxelGrid::new(70, 3, 3);
        let mut state = 7u64;
        for c in
            (0..3).flat_map(|z| (0..3).flat_map(move |y| (0..70).map(move |x| Cell::new(x, y, z))))
        {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            g.set(c, (state >> 33) % 100 < 85);
        }
        let b = |x, y, z, sx, sy, sz| CellBox {
            min: Cell::new(x, y, z),
            sx,
            sy,
            sz,
        };
        for boxes in [
            vec![b(0, 0, 0, 2, 1, 1), b(1, 0, 1, 1, 2, 1)],
            vec![b(0, 0, 0, 8, 1, 1)],
            vec![b(0, 0, 0, 1, 1, 1)],
        ] {
            let fit = g.fits(&boxes);
            let mut n = 0;
            for z in 0..3 {
                for y in 0..3 {
                    for x in 0..70 {
                        let want = boxes.iter().all(|q| g.all_set(&q.moved(x, y, z)));
                        assert_eq!(
                            fit.get(Cell::new(x, y, z)),
                            want,
                            "{boxes:?} at {x} {y} {z}"
                        );
                        n += usize::from(want);
                    }
                }
            }
            assert!(n > 0, "{boxes:?} fits somewhere");
        }
    }
}
