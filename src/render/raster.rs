//! Triangle fill with a depth buffer, at the supersampled resolution.
//!
//! A plain edge-function rasterizer: for each triangle, every sample centre
//! inside its screen bounding box is tested against the three edges
//! (top-left fill rule, so two triangles sharing an edge never both or
//! neither cover a sample), its depth interpolated, and it is kept when
//! nearer than what the sample holds. What a sample keeps is not a colour
//! but the facts the compositor needs: depth, which piece, and the face
//! normal with its shade. Colours, fading and outlines come later, so the
//! same buffer serves every look of a step.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::camera::Camera;
use super::scene::Scene;

/// A sample's piece when nothing covers it.
pub(crate) const EMPTY: u32 = u32::MAX;

/// An axis-aligned rectangle of pixels, `x0..x1` by `y0..y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelRect {
    /// Left column (inclusive).
    pub x0: u32,
    /// Top row (inclusive).
    pub y0: u32,
    /// Right column (exclusive).
    pub x1: u32,
    /// Bottom row (exclusive).
    pub y1: u32,
}

impl PixelRect {
    /// True when the rectangle holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    /// The smallest rectangle holding both (an empty one adds nothing).
    pub fn union(self, o: PixelRect) -> PixelRect {
        if self.is_empty() {
            return o;
        }
        if o.is_empty() {
            return self;
        }
        PixelRect {
            x0: self.x0.min(o.x0),
            y0: self.y0.min(o.y0),
            x1: self.x1.max(o.x1),
            y1: self.y1.max(o.y1),
        }
    }

    /// Grown by `d` pixels on every side, clipped to `w` x `h`.
    pub fn grown(self, d: u32, w: u32, h: u32) -> PixelRect {
        if self.is_empty() {
            return self;
        }
        PixelRect {
            x0: self.x0.saturating_sub(d),
            y0: self.y0.saturating_sub(d),
            x1: (self.x1 + d).min(w),
            y1: (self.y1 + d).min(h),
        }
    }

    /// True when pixel `(x, y)` lies inside.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        x >= self.x0 && x < self.x1 && y >= self.y0 && y < self.y1
    }

    /// The empty rectangle.
    pub const EMPTY: PixelRect = PixelRect {
        x0: 0,
        y0: 0,
        x1: 0,
        y1: 0,
    };
}

/// How a face is lit: a light fixed to the camera, from above and from the
/// viewer's left, so tops are light, the left-hand side mid and the
/// right-hand side dark, whatever the view.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Light {
    up: Vec3,
    left: Vec3,
    eye: Vec3,
}

impl Light {
    pub(crate) fn for_camera(camera: &Camera) -> Light {
        Light {
            up: Vec3::new(0.0, -1.0, 0.0),
            left: -camera.right(),
            eye: camera.toward_eye(),
        }
    }

    /// Brightness in 0..=255 of a face with unit normal `n`.
    pub(crate) fn shade(&self, n: Vec3) -> u8 {
        let s = 0.60 + 0.34 * n.dot(self.up) + 0.17 * n.dot(self.left) + 0.06 * n.dot(self.eye);
        (s.clamp(0.25, 1.0) * 255.0).round() as u8
    }
}

/// The supersampled buffers: per sample, depth, piece and face.
#[derive(Debug, Clone)]
pub(crate) struct Samples {
    /// Width in samples.
    pub w: usize,
    /// Height in samples.
    pub h: usize,
    /// Samples per pixel along each axis.
    pub ss: usize,
    /// Distance from the viewer in LDU; `INFINITY` where empty.
    pub depth: Vec<f32>,
    /// Scene piece index, or [`EMPTY`].
    pub piece: Vec<u32>,
    /// Quantized face normal (x, y, z as `i8` bits) and shade.
    pub face: Vec<[u8; 4]>,
}

impl Samples {
    /// Empty buffers for a `width` x `height` pixel image with `ss` x `ss`
    /// samples a pixel.
    pub(crate) fn new(width: u32, height: u32, ss: u32) -> Samples {
        let ss = ss.max(1) as usize;
        let w = width as usize * ss;
        let h = height as usize * ss;
        Samples {
            w,
            h,
            ss,
            depth: vec![f32::INFINITY; w * h],
            piece: vec![EMPTY; w * h],
            face: vec![[0; 4]; w * h],
        }
    }

    /// The samples of pixel rectangle `rect`, as a range of indices a
    /// row.
    pub(crate) fn rows(
        &self,
        rect: PixelRect,
    ) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        let ss = self.ss;
        let (x0, x1) = (
            (rect.x0 as usize * ss).min(self.w),
            (rect.x1 as usize * ss).min(self.w),
        );
        let (y0, y1) = (
            (rect.y0 as usize * ss).min(self.h),
            (rect.y1 as usize * ss).min(self.h),
        );
        (y0..y1).map(move |y| y * self.w + x0..y * self.w + x1.max(x0))
    }

    /// Draws piece `index` of `scene`, culling faces turned away from the
    /// viewer.
    pub(crate) fn draw_piece(
        &mut self,
        scene: &Scene,
        index: usize,
        camera: &Camera,
        light: &Light,
    ) {
        let ss = self.ss;
        let mut band = self.whole();
        for f in flats(scene, index, camera, light, ss) {
            band.fill_narrowing(&f, NARROW_ROWS);
        }
    }

    /// Draws `pieces` of `scene` in that order, as [`draw_piece`]
    /// (Self::draw_piece) one after the other would. Many pieces are drawn
    /// with the rows cut into bands filled in parallel: their triangles
    /// are projected once, a few hundred pieces at a time, then each band
    /// takes every triangle in the same order and fills only its own rows,
    /// so every sample ends as it would drawn whole.
    pub(crate) fn draw_pieces(
        &mut self,
        scene: &Scene,
        pieces: &[usize],
        camera: &Camera,
        light: &Light,
    ) {
        if pieces.len() < BANDED_PIECES || self.w == 0 {
            for &i in pieces {
                self.draw_piece(scene, i, camera, light);
            }
            return;
        }
        let rows = band_rows(self.h);
        let (w, ss) = (self.w, self.ss);
        let bands = self.h.div_ceil(rows);
        let mut binned: Vec<Vec<u32>> = vec![Vec::new(); bands];
        for chunk in pieces.chunks(256) {
            let flats: Vec<Flat> = chunk
                .iter()
                .flat_map(|&i| flats(scene, i, camera, light, ss))
                .collect();
            // Each band's triangles, in drawing order: those whose rows
            // (give or take a sample) reach into it.
            binned.iter_mut().for_each(Vec::clear);
            for (k, f) in flats.iter().enumerate() {
                let ys = f.p.map(|v| v.y);
                let lo = ys[0].min(ys[1]).min(ys[2]).floor() - 1.0;
                let hi = ys[0].max(ys[1]).max(ys[2]).ceil() + 1.0;
                if !(lo.is_finite() && hi.is_finite()) || hi < 0.0 {
                    continue;
                }
                let first = lo.max(0.0) as usize / rows;
                let last = (hi as usize / rows).min(bands - 1);
                for band in binned.iter_mut().take(last + 1).skip(first) {
                    band.push(k as u32);
                }
            }
            self.depth
                .par_chunks_mut(rows * w)
                .zip(self.piece.par_chunks_mut(rows * w))
                .zip(self.face.par_chunks_mut(rows * w))
                .enumerate()
                .zip(&binned)
                .for_each(|((k, ((depth, piece), face)), mine)| {
                    let mut band = Band {
                        w,
                        y0: k * rows,
                        y1: k * rows + depth.len() / w,
                        depth,
                        piece,
                        face,
                    };
                    for &f in mine {
                        band.fill_narrowing(&flats[f as usize], NARROW_ROWS);
                    }
                });
        }
    }

    /// Every row, as one band.
    fn whole(&mut self) -> Band<'_> {
        Band {
            w: self.w,
            y0: 0,
            y1: self.h,
            depth: &mut self.depth,
            piece: &mut self.piece,
            face: &mut self.face,
        }
    }

    /// Fills one triangle given in sample coordinates (x, y) with depth z,
    /// the depth growing by `slope` per sample along x and y.
    #[cfg(test)]
    fn fill(&mut self, p: [Vec3; 3], slope: Vec2, piece: u32, face: [u8; 4]) {
        let f = Flat {
            p,
            slope,
            piece,
            face,
        };
        self.whole().fill_narrowing(&f, NARROW_ROWS);
    }

    /// [`fill`](Self::fill), narrowing the rows of triangles wider than
    /// `narrow_rows` samples.
    #[cfg(test)]
    fn fill_narrowing(
        &mut self,
        p: [Vec3; 3],
        slope: Vec2,
        piece: u32,
        face: [u8; 4],
        narrow_rows: usize,
    ) {
        let f = Flat {
            p,
            slope,
            piece,
            face,
        };
        self.whole().fill_narrowing(&f, narrow_rows);
    }
}

/// Fewest pieces [`Samples::draw_pieces`] draws in bands: below, one
/// thread draws them (the steps' few new pieces, drawn while other
/// threads draw other steps).
const BANDED_PIECES: usize = 64;

/// Sample rows a band of [`Samples::draw_pieces`] takes: the rows cut in
/// two bands a thread, at least 64 rows each.
fn band_rows(h: usize) -> usize {
    h.div_ceil(2 * rayon::current_num_threads()).max(64)
}

/// Rows `y0..y1` of the sample buffers: the buffers' slices of those
/// rows, indexed from row `y0`.
struct Band<'a> {
    w: usize,
    y0: usize,
    y1: usize,
    depth: &'a mut [f32],
    piece: &'a mut [u32],
    face: &'a mut [[u8; 4]],
}

/// A triangle ready to fill: its corners in sample coordinates (x, y)
/// with depth z, the depth's growth per sample along x and y, and what a
/// sample it covers keeps.
struct Flat {
    p: [Vec3; 3],
    slope: Vec2,
    piece: u32,
    face: [u8; 4],
}

/// The triangles of piece `index` of `scene` seen through `camera` at
/// `ss` samples a pixel, faces turned away from the viewer culled.
fn flats<'a>(
    scene: &'a Scene,
    index: usize,
    camera: &'a Camera,
    light: &'a Light,
    ss: usize,
) -> impl Iterator<Item = Flat> + 'a {
    let eye = camera.toward_eye();
    let ss = ss as f32;
    let per_sample = camera.scale() * ss;
    scene.piece_triangles(index).iter().filter_map(move |t| {
        if t.normal.dot(eye) <= 1e-4 {
            return None;
        }
        // Depth across the screen follows the triangle's plane, taken
        // from its world corners: stable even for long slivers, where
        // barycentric weights lose precision.
        let [a, b, c] = t.positions;
        let g = (b - a).cross(c - a);
        let toward = g.dot(eye);
        if toward.abs() <= 1e-6 * g.length() {
            return None;
        }
        let slope = Vec2::new(g.dot(camera.right()), g.dot(camera.down())) / (toward * per_sample);
        let p = t.positions.map(|v| {
            let q = camera.project(v);
            Vec3::new(q.x * ss, q.y * ss, q.z)
        });
        let n = t.normal;
        let q = |c: f32| (c.clamp(-1.0, 1.0) * 127.0).round() as i8 as u8;
        Some(Flat {
            p,
            slope,
            piece: index as u32,
            face: [q(n.x), q(n.y), q(n.z), light.shade(n)],
        })
    })
}

impl Band<'_> {
    /// Fills the band's rows of one triangle given in sample coordinates
    /// (x, y) with depth z, the depth growing by `slope` per sample along x
    /// and y, narrowing the rows of triangles wider than `narrow_rows`
    /// samples.
    fn fill_narrowing(&mut self, f: &Flat, narrow_rows: usize) {
        let (slope, piece, face) = (f.slope, f.piece, f.face);
        let [mut a, mut b, c] = f.p;
        let (za, zx, zy) = (a.z - slope.x * a.x - slope.y * a.y, slope.x, slope.y);
        let area = edge(a.truncate(), b.truncate(), c.truncate());
        if !area.is_finite() || area.abs() < 1e-6 {
            return;
        }
        // Make the winding positive on screen (y down): culling is done by
        // the normal, so either winding is drawn.
        if area < 0.0 {
            std::mem::swap(&mut a, &mut b);
        }
        let (a2, b2, c2) = (a.truncate(), b.truncate(), c.truncate());
        let lo = a2.min(b2).min(c2);
        let hi = a2.max(b2).max(c2);
        let x0 = ceil(lo.x - 0.5).max(0.0) as usize;
        let y0 = (ceil(lo.y - 0.5).max(0.0) as usize).max(self.y0);
        let x1 = (floor(hi.x - 0.5) + 1.0).clamp(0.0, self.w as f32) as usize;
        let y1 = ((floor(hi.y - 0.5) + 1.0).clamp(0.0, self.y1 as f32) as usize).min(self.y1);
        if x0 >= x1 || y0 >= y1 {
            return;
        }
        // Edge functions w_i(x, y) = A_i x + B_i y + C_i, positive inside.
        // A sample exactly on an edge belongs to the triangle for which the
        // edge is "top-left"; the neighbour across the edge evaluates the
        // exact negation, so exactly one of the two takes it.
        let setup = |u: Vec2, v: Vec2| {
            let (ea, eb) = (u.y - v.y, v.x - u.x);
            let ec = u.x * v.y - u.y * v.x;
            let top_left = (ea == 0.0 && eb < 0.0) || ea > 0.0;
            (ea, eb, ec, top_left)
        };
        let outside = |w: f32, top_left: bool| if top_left { w < 0.0 } else { w <= 0.0 };
        let e0 = setup(b2, c2);
        let e1 = setup(c2, a2);
        let e2 = setup(a2, b2);
        // Each edge's 1 / A, for narrowing the rows: a row's bounds only
        // need to be within the slack (a sample and more) of the exact
        // crossing, which a reciprocal's rounding stays far inside, and
        // divisions a row cost more than the rest of a small triangle.
        let inverse = |e: (f32, f32, f32, bool)| if e.0 == 0.0 { 0.0 } else { 1.0 / e.0 };
        let inv = [inverse(e0), inverse(e1), inverse(e2)];
        // A narrow triangle's rows are scanned whole: narrowing them costs
        // more than testing the few samples it would skip (most of a
        // stud's facets are a few samples wide). Either way the samples
        // covered are the same: each edge value grows (or shrinks) with x,
        // its rounding too, so a row's covered samples are one run, and
        // any range holding the run finds it.
        let narrow = x1 - x0 > narrow_rows;
        for y in y0..y1 {
            let py = y as f32 + 0.5;
            let row = (y - self.y0) * self.w;
            // Each edge value is evaluated exactly, in the same order for
            // both triangles of a shared edge (so they see exact negations);
            // a row's covered samples are contiguous, so leave the row once
            // past them.
            let (r0, r1, r2) = (e0.1 * py + e0.2, e1.1 * py + e1.2, e2.1 * py + e2.2);
            // Narrow the row to where the edges cross it (with a sample of
            // slack each side; the exact tests below decide), so long thin
            // triangles cost their area, not their bounding box.
            let (mut lo, mut hi) = (x0 as f32, x1 as f32);
            let edges = [(e0, r0), (e1, r1), (e2, r2)].into_iter().zip(inv);
            for ((e, r), inv) in edges.take(if narrow { 3 } else { 0 }) {
                let ea = e.0;
                if ea == 0.0 {
                    continue;
                }
                // Where the edge crosses the row, give or take the rounding
                // of `r` divided by a possibly small slope (nearly
                // horizontal edges), plus a sample.
                let cross = -r * inv - 0.5;
                let slack = 1.0 + (e.1.abs() * py + e.2.abs() + ea.abs() * hi) * 1e-6 * inv.abs();
                if ea > 0.0 {
                    lo = lo.max(floor(cross - slack));
                } else {
                    hi = hi.min(ceil(cross + slack) + 1.0);
                }
            }
            if lo >= hi {
                continue;
            }
            let (xa, xb) = (lo as usize, (hi as usize).min(x1));
            let mut entered = false;
            for x in xa..xb {
                let px = x as f32 + 0.5;
                let w0 = e0.0 * px + r0;
                let w1 = e1.0 * px + r1;
                let w2 = e2.0 * px + r2;
                if outside(w0, e0.3) || outside(w1, e1.3) || outside(w2, e2.3) {
                    if entered {
                        break;
                    }
                    continue;
                }
                entered = true;
                let z = za + zx * px + zy * py;
                let i = row + x;
                if z < self.depth[i] {
                    self.depth[i] = z;
                    self.piece[i] = piece;
                    self.face[i] = face;
                }
            }
        }
    }
}

/// Triangles at most this many samples wide are not narrowed row by row
/// (see [`Samples::fill`]).
const NARROW_ROWS: usize = 24;

/// `x.floor()`, inline: without SSE4.1 (the baseline x86-64 target) the
/// standard one is a call into libm, and the fill rounds a few values a
/// row of every triangle. Exact: a float of magnitude 2^23 or more (or
/// not finite) is its own floor.
#[inline(always)]
fn floor(x: f32) -> f32 {
    if x.abs() < 8_388_608.0 {
        let t = x as i32 as f32;
        if t > x {
            t - 1.0
        } else {
            t
        }
    } else {
        x
    }
}

/// `x.ceil()`, inline, exact (see [`floor`]).
#[inline(always)]
fn ceil(x: f32) -> f32 {
    if x.abs() < 8_388_608.0 {
        let t = x as i32 as f32;
        if t < x {
            t + 1.0
        } else {
            t
        }
    } else {
        x
    }
}

/// Twice the signed area of `a b c`, positive when clockwise on a y-down
/// screen (counter-clockwise in the usual y-up picture).
fn edge(a: Vec2, b: Vec2, c: Vec2) -> f32 {
    (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)
}

/// The pixels a piece can touch: the screen bounding box of its corners,
/// clipped to the image.
pub(crate) fn piece_rect(scene: &Scene, index: usize, camera: &Camera) -> PixelRect {
    let mut lo = Vec2::splat(f32::INFINITY);
    let mut hi = Vec2::splat(f32::NEG_INFINITY);
    for t in scene.piece_triangles(index) {
        for &v in &t.positions {
            let q = camera.project(v).truncate();
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    if !lo.is_finite() || !hi.is_finite() {
        return PixelRect::EMPTY;
    }
    let (w, h) = (camera.width() as f32, camera.height() as f32);
    PixelRect {
        x0: lo.x.floor().clamp(0.0, w) as u32,
        y0: lo.y.floor().clamp(0.0, h) as u32,
        x1: (hi.x.ceil() + 1.0).clamp(0.0, w) as u32,
        y1: (hi.y.ceil() + 1.0).clamp(0.0, h) as u32,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::assembly::Step;
    use crate::render::camera::View;
    use crate::render::scene::test_geometry::cuboid;
    use image::Rgb;

    fn two_boxes(near_first: bool) -> (Scene, usize, usize) {
        let mut scene = Scene::new();
        let near = || cuboid(Vec3::new(-10.0, -10.0, -30.0), Vec3::new(10.0, 10.0, -10.0));
        let far = || cuboid(Vec3::new(-20.0, -20.0, 10.0), Vec3::new(20.0, 20.0, 30.0));
        let (n, f);
        if near_first {
            n = scene.add_piece(Rgb([255, 0, 0]), Step(1), near());
            f = scene.add_piece(Rgb([0, 0, 255]), Step(1), far());
        } else {
            f = scene.add_piece(Rgb([0, 0, 255]), Step(1), far());
            n = scene.add_piece(Rgb([255, 0, 0]), Step(1), near());
        }
        (scene, n, f)
    }

    /// A heap of `n` overlapping boxes of many sizes and depths, some
    /// sharing faces (equal depths: the first drawn keeps the sample).
    pub(crate) fn heap(n: usize) -> Scene {
        let mut scene = Scene::new();
        for i in 0..n {
            let k = i as f32;
            let lo = Vec3::new(
                (k * 37.0) % 200.0 - 100.0,
                (k * 53.0) % 120.0 - 60.0,
                (k * 11.0) % 90.0 - 45.0,
            );
            let size = Vec3::new(10.0 + (k * 7.0) % 40.0, 8.0 + (k * 3.0) % 30.0, 12.0);
            let rgb = Rgb([(i * 40 % 256) as u8, (i * 90 % 256) as u8, 128]);
            scene.add_piece(rgb, Step(1 + i as u32 / 10), cuboid(lo, lo + size));
        }
        scene
    }

    #[test]
    fn pieces_drawn_in_bands_leave_the_samples_drawing_one_by_one_leaves() {
        let scene = heap(3 * BANDED_PIECES);
        let cam = Camera::fit(&View::default(), scene.points(), 400, 300, 4);
        let light = Light::for_camera(&cam);
        let order: Vec<usize> = (0..scene.pieces().len()).collect();
        let mut banded = Samples::new(400, 300, 2);
        banded.draw_pieces(&scene, &order, &cam, &light);
        let mut single = Samples::new(400, 300, 2);
        for &i in &order {
            single.draw_piece(&scene, i, &cam, &light);
        }
        // Many bands, many pieces: the test is not trivially one band.
        assert!(banded.h / band_rows(banded.h) >= 2);
        assert!(single.piece.iter().filter(|&&p| p != EMPTY).count() > 50_000);
        assert_eq!(banded.piece, single.piece);
        assert_eq!(banded.face, single.face);
        assert!(banded
            .depth
            .iter()
            .zip(&single.depth)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    #[test]
    fn the_near_box_hides_the_far_one_in_any_drawing_order() {
        let front = View {
            azimuth_deg: 0.0,
            elevation_deg: 0.0,
            quarter_turns: 0,
        };
        for near_first in [true, false] {
            let (scene, near, far) = two_boxes(near_first);
            let cam = Camera::fit(&front, scene.points(), 64, 64, 2);
            let light = Light::for_camera(&cam);
            let mut s = Samples::new(64, 64, 1);
            for i in 0..2 {
                s.draw_piece(&scene, i, &cam, &light);
            }
            // The centre shows the near box, a point off its side the far one.
            assert_eq!(s.piece[32 * 64 + 32], near as u32);
            assert_eq!(s.piece[32 * 64 + 6], far as u32);
            assert_eq!(s.piece[0], EMPTY);
        }
    }

    #[test]
    fn shared_edges_leave_no_gaps_or_double_cover() {
        // A quad as two triangles: no sample is covered twice, and the
        // samples along the shared diagonal are all covered.
        let q = [
            Vec3::new(1.3, 2.1, 0.0),
            Vec3::new(14.7, 1.9, 0.0),
            Vec3::new(13.2, 14.6, 0.0),
            Vec3::new(2.2, 13.9, 0.0),
        ];
        let mut t = Samples::new(16, 16, 1);
        t.fill([q[0], q[1], q[2]], Vec2::ZERO, 0, [0; 4]);
        let mut u = Samples::new(16, 16, 1);
        u.fill([q[0], q[2], q[3]], Vec2::ZERO, 1, [0; 4]);
        let mut both = Samples::new(16, 16, 1);
        both.fill([q[0], q[1], q[2]], Vec2::ZERO, 0, [0; 4]);
        both.fill([q[0], q[2], q[3]], Vec2::ZERO, 1, [0; 4]);
        for i in 0..256 {
            let (a, b) = (t.piece[i] != EMPTY, u.piece[i] != EMPTY);
            assert!(!(a && b), "sample {i} covered twice");
            assert_eq!(a || b, both.piece[i] != EMPTY);
        }
        for k in 3..13 {
            // Samples next to the diagonal, well inside the quad.
            assert_ne!(both.piece[k * 16 + k], EMPTY, "gap at ({k}, {k})");
        }
    }

    #[test]
    fn rows_narrowed_or_scanned_whole_cover_the_same_samples() {
        // Triangles of every size and slant, many sharing edges, drawn
        // with every row narrowed and with none.
        let rng = std::cell::Cell::new(0x2545_f491_4f6c_dd1du64);
        let next = |scale: f32| {
            let mut x = rng.get();
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            rng.set(x);
            (x >> 40) as f32 / (1u64 << 24) as f32 * scale
        };
        let (mut narrowed, mut whole) = (Samples::new(64, 48, 1), Samples::new(64, 48, 1));
        for k in 0..3000u32 {
            let size = [2.0, 8.0, 30.0, 70.0][k as usize % 4];
            let a = Vec3::new(next(64.0), next(48.0), next(50.0));
            let corner = |d: f32| a + Vec3::new(next(d) - d / 2.0, next(d) - d / 2.0, next(9.0));
            let tri = [a, corner(size), corner(size)];
            let slope = Vec2::new(next(0.2) - 0.1, next(0.2) - 0.1);
            narrowed.fill_narrowing(tri, slope, k, [0; 4], 0);
            whole.fill_narrowing(tri, slope, k, [0; 4], usize::MAX);
            // A neighbour across the first edge.
            let other = [tri[1], tri[0], corner(size)];
            narrowed.fill_narrowing(other, slope, k + 5000, [1; 4], 0);
            whole.fill_narrowing(other, slope, k + 5000, [1; 4], usize::MAX);
        }
        assert_eq!(narrowed.piece, whole.piece);
        assert_eq!(narrowed.depth, whole.depth);
        assert!(narrowed.piece.iter().filter(|&&p| p != EMPTY).count() > 2000);
    }

    #[test]
    fn inline_floor_and_ceil_match_the_standard_ones() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.999_999_8,
            -2.999_999_8,
            8_388_607.5,
            -8_388_607.5,
            8_388_608.0,
            1e20,
            -1e20,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        // A sweep through the range pictures use, in odd steps.
        xs.extend((-40_000..40_000).map(|k| k as f32 * 0.173_1));
        for x in xs {
            assert_eq!(floor(x), x.floor(), "floor({x})");
            assert_eq!(ceil(x), x.ceil(), "ceil({x})");
        }
        assert!(floor(f32::NAN).is_nan() && ceil(f32::NAN).is_nan());
    }

    #[test]
    fn faces_turned_away_are_culled_and_sides_shade_apart() {
        let cam = Camera::new(&View::default(), Vec3::ZERO, 1.0, 10, 10);
        let light = Light::for_camera(&cam);
        let top = light.shade(Vec3::new(0.0, -1.0, 0.0));
        let front = light.shade(Vec3::new(0.0, 0.0, -1.0));
        let right = light.shade(Vec3::new(1.0, 0.0, 0.0));
        assert!(top > front && front > right, "{top} {front} {right}");
        assert!(front - right > 40);
    }
}
