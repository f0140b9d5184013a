//! From samples to pixels: colours, fading, outlines and the box filter.
//!
//! The rasterizer leaves, per sample, a depth, a piece and a face. Here
//! each sample gets its colour (the piece's colour times the face's shade,
//! blended toward white for pieces of earlier steps), and samples on an
//! edge get the line colour instead. A sample is on an edge when one of
//! its four neighbours belongs to another piece or to the background, faces
//! a direction more than about 37 degrees away, or lies far behind or in
//! front of it (a stud seen against the top behind it). Lines are then
//! thickened by a small square dilation, thicker for the pieces the step
//! adds, and every `ss x ss` block of samples is averaged into one pixel:
//! that average is the anti-aliasing.
//!
//! Everything a pixel needs lies within a few samples of it, so a
//! rectangle of the image can be composed again on its own: the step
//! renderer redraws only where the step changed something.

use image::{Rgb, RgbaImage};
use rayon::prelude::*;

use super::raster::{PixelRect, Samples, EMPTY};

/// Classes of pieces, which decide fading and line weight; higher wins
/// where two pieces meet.
pub(crate) mod class {
    /// A piece of an earlier step: faded, light lines.
    pub const OLD: u8 = 1;
    /// A piece shown plainly (the finished model, a single part).
    pub const PLAIN: u8 = 2;
    /// A piece the step adds: full colour, strong lines.
    pub const NEW: u8 = 3;
}

/// How one piece looks in the image being composed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct PieceLook {
    /// Base colour.
    pub rgb: [u8; 3],
    /// One of [`class`].
    pub class: u8,
}

/// Everything about the look that is the same for every piece.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Style {
    /// Blend of old pieces toward white, in 256ths.
    pub fade: u16,
    /// Dilation of ordinary lines, in samples.
    pub radius: usize,
    /// Dilation of the lines of new pieces, in samples (at least `radius`).
    pub radius_new: usize,
    /// Depth jump (LDU) between neighbouring samples that makes an edge.
    pub depth_jump: f32,
    /// Background pixel.
    pub background: [u8; 4],
    /// Line colour of new pieces.
    pub new_line: [u8; 3],
}

/// Line colour of plain pieces.
const LINE: [u8; 3] = [28, 28, 28];
/// Line colour inside dark pieces, where a black line would not show.
const LINE_ON_DARK: [u8; 3] = [105, 105, 105];
/// Smallest cosine between two face normals of one piece without a line
/// (about 37 degrees), in units of 127 squared.
const CREASE_DOT: i32 = 12_900;

fn is_dark(rgb: [u8; 3]) -> bool {
    let [r, g, b] = rgb.map(u32::from);
    (r * 30 + g * 59 + b * 11) / 100 < 60
}

fn fade(c: [u8; 3], f: u16) -> [u8; 3] {
    c.map(|v| (u32::from(v) + (((255 - u32::from(v)) * u32::from(f)) >> 8)) as u8)
}

/// The edge class between samples `i` and `j` (0 for no edge).
#[inline(always)]
fn pair(s: &Samples, looks: &[PieceLook], i: usize, j: usize, jump: f32) -> u8 {
    let (pi, pj) = (s.piece[i], s.piece[j]);
    let cls = |p: u32| looks.get(p as usize).map_or(class::PLAIN, |l| l.class);
    if pi == pj {
        // The common case: inside one face of one piece, or background.
        if pi == EMPTY {
            return 0;
        }
        let (fi, fj) = (s.face[i], s.face[j]);
        // The normals compared as three bytes, not as slices (a call).
        let crease = [fi[0], fi[1], fi[2]] != [fj[0], fj[1], fj[2]] && {
            let dot: i32 = (0..3)
                .map(|k| i32::from(fi[k] as i8) * i32::from(fj[k] as i8))
                .sum();
            dot < CREASE_DOT
        };
        return if crease || (s.depth[i] - s.depth[j]).abs() > jump {
            // Lines inside a new piece keep the plain weight: thick
            // lines are for its outline only.
            cls(pi).min(class::PLAIN)
        } else {
            0
        };
    }
    match (pi == EMPTY, pj == EMPTY) {
        (true, _) => cls(pj),
        (_, true) => cls(pi),
        _ => cls(pi).max(cls(pj)),
    }
}

/// Composes pixel rectangle `rect` of `out` from `samples`; a large one
/// with its rows cut into bands composed in parallel (a pixel depends
/// only on the samples near it, so a band composed on its own is what
/// composing the whole rectangle makes of it).
pub(crate) fn compose(
    samples: &Samples,
    looks: &[PieceLook],
    style: &Style,
    rect: PixelRect,
    out: &mut RgbaImage,
) {
    let rect = PixelRect {
        x1: rect.x1.min(out.width()),
        y1: rect.y1.min(out.height()),
        ..rect
    };
    if rect.is_empty() || samples.w == 0 || samples.h == 0 {
        return;
    }
    let width = out.width() as usize;
    let area = u64::from(rect.x1 - rect.x0) * u64::from(rect.y1 - rect.y0);
    let rows = if area < BANDED_PIXELS {
        rect.y1 - rect.y0
    } else {
        band_rows(rect.y1 - rect.y0)
    };
    let (y0, y1) = (rect.y0 as usize, rect.y1 as usize);
    let pixels: &mut [u8] = out;
    pixels[y0 * width * 4..y1 * width * 4]
        .par_chunks_mut(rows as usize * width * 4)
        .enumerate()
        .for_each(|(k, band)| {
            let top = rect.y0 + k as u32 * rows;
            let rect = PixelRect {
                y0: top,
                y1: top + (band.len() / (width * 4)) as u32,
                ..rect
            };
            compose_rows(
                samples,
                looks,
                style,
                rect,
                Rows {
                    pixels: band,
                    width,
                    top,
                },
            );
        });
}

/// Fewest pixels [`compose`] composes in bands: a smaller rectangle (a
/// step's few new pieces) is one thread's, while other threads compose
/// other steps.
const BANDED_PIXELS: u64 = 100_000;

/// Pixel rows a band of [`compose`] takes: the rows cut in four bands a
/// thread, at least 16 rows each.
fn band_rows(rows: u32) -> u32 {
    rows.div_ceil(4 * rayon::current_num_threads() as u32)
        .max(16)
}

/// Rows of an RGBA image from row `top`, `width` pixels each.
struct Rows<'a> {
    pixels: &'a mut [u8],
    width: usize,
    top: u32,
}

impl Rows<'_> {
    fn put(&mut self, x: u32, y: u32, rgba: [u8; 4]) {
        let i = ((y - self.top) as usize * self.width + x as usize) * 4;
        self.pixels[i..i + 4].copy_from_slice(&rgba);
    }
}

/// Composes pixel rectangle `rect`, which lies within `out`'s rows.
fn compose_rows(
    samples: &Samples,
    looks: &[PieceLook],
    style: &Style,
    rect: PixelRect,
    mut out: Rows<'_>,
) {
    let ss = samples.ss;
    let (w, h) = (samples.w, samples.h);
    let (sx0, sy0) = (rect.x0 as usize * ss, rect.y0 as usize * ss);
    let (sx1, sy1) = (
        (rect.x1 as usize * ss).min(w),
        (rect.y1 as usize * ss).min(h),
    );
    let r = style.radius_new.max(style.radius);
    let (ex0, ey0) = (sx0.saturating_sub(r), sy0.saturating_sub(r));
    let (ex1, ey1) = ((sx1 + r).min(w), (sy1 + r).min(h));
    let ew = ex1 - ex0;

    // Edge classes over the region grown by the dilation radius: each
    // pair of neighbours is judged once, across (`across[k]` between
    // samples k and k + 1 of a row) and down (`down[k]` between rows).
    let eh = ey1 - ey0;
    let mut across = vec![0u8; ew * eh];
    let mut down = vec![0u8; ew * eh];
    for y in ey0..ey1 {
        for x in ex0..ex1 {
            let i = y * w + x;
            let k = (y - ey0) * ew + (x - ex0);
            if x + 1 < w {
                across[k] = pair(samples, looks, i, i + 1, style.depth_jump);
            }
            if y + 1 < h {
                down[k] = pair(samples, looks, i, i + w, style.depth_jump);
            }
        }
    }
    let mut edges = vec![0u8; ew * eh];
    for y in ey0..ey1 {
        for x in ex0..ex1 {
            let k = (y - ey0) * ew + (x - ex0);
            let mut c = across[k].max(down[k]);
            if x > ex0 {
                c = c.max(across[k - 1]);
            } else if x > 0 {
                c = c.max(pair(
                    samples,
                    looks,
                    y * w + x,
                    y * w + x - 1,
                    style.depth_jump,
                ));
            }
            if y > ey0 {
                c = c.max(down[k - ew]);
            } else if y > 0 {
                c = c.max(pair(
                    samples,
                    looks,
                    y * w + x,
                    (y - 1) * w + x,
                    style.depth_jump,
                ));
            }
            edges[k] = c;
        }
    }
    let lines = dilate(edges, ew, eh, style.radius, style.radius_new);

    let n = (ss * ss) as u32;
    let old_line = fade(LINE, style.fade);
    let old_line_on_dark = fade(LINE_ON_DARK, style.fade);
    for py in rect.y0..rect.y1 {
        for px in rect.x0..rect.x1 {
            if let Some(px_out) = uniform(samples, &lines, (ex0, ey0, ew), (px, py), looks, style) {
                out.put(px, py, px_out);
                continue;
            }
            let (mut sr, mut sg, mut sb, mut opaque) = (0u32, 0u32, 0u32, 0u32);
            for sy in py as usize * ss..(py as usize + 1) * ss {
                for sx in px as usize * ss..(px as usize + 1) * ss {
                    let (sx, sy) = (sx.min(w - 1), sy.min(h - 1));
                    let i = sy * w + sx;
                    let line = lines[(sy - ey0) * ew + (sx - ex0)];
                    let p = samples.piece[i];
                    let look = looks.get(p as usize);
                    let rgb = if line != 0 {
                        let dark = look.is_some_and(|l| is_dark(l.rgb));
                        match line {
                            class::OLD if dark => old_line_on_dark,
                            class::OLD => old_line,
                            _ if dark => LINE_ON_DARK,
                            class::NEW => style.new_line,
                            _ => LINE,
                        }
                    } else if let Some(l) = look {
                        let shade = u32::from(samples.face[i][3]);
                        let lit = l.rgb.map(|v| ((u32::from(v) * shade + 127) / 255) as u8);
                        if l.class == class::OLD {
                            fade(lit, style.fade)
                        } else {
                            lit
                        }
                    } else {
                        let [r, g, b, a] = style.background;
                        if a == 0 {
                            continue;
                        }
                        [r, g, b]
                    };
                    sr += u32::from(rgb[0]);
                    sg += u32::from(rgb[1]);
                    sb += u32::from(rgb[2]);
                    opaque += 1;
                }
            }
            let px_out = if opaque == 0 {
                let [r, g, b, _] = style.background;
                [r, g, b, 0]
            } else {
                let avg = |s: u32| ((s + opaque / 2) / opaque) as u8;
                [
                    avg(sr),
                    avg(sg),
                    avg(sb),
                    ((opaque * 255 + n / 2) / n) as u8,
                ]
            };
            out.put(px, py, px_out);
        }
    }
}

/// The pixel `(px, py)` when its samples are all alike: no line, one
/// piece (or the background) and one shade, so their average is the one
/// colour they share, exactly as the general loop computes it (`n`
/// equal values `c` average to `(n c + n / 2) / n = c`). `None` otherwise,
/// or when the pixel reaches past the samples' edge. `lines` covers the
/// samples from `(ex0, ey0)`, `ew` a row.
#[inline]
fn uniform(
    samples: &Samples,
    lines: &[u8],
    (ex0, ey0, ew): (usize, usize, usize),
    (px, py): (u32, u32),
    looks: &[PieceLook],
    style: &Style,
) -> Option<[u8; 4]> {
    let (ss, w) = (samples.ss, samples.w);
    let (x0, y0) = (px as usize * ss, py as usize * ss);
    if x0 + ss > w || y0 + ss > samples.h {
        return None;
    }
    let first = y0 * w + x0;
    let p = samples.piece[first];
    let shade = samples.face[first][3];
    for sy in y0..y0 + ss {
        let row = sy * w;
        let line_row = (sy - ey0) * ew;
        for sx in x0..x0 + ss {
            let i = row + sx;
            if lines[line_row + sx - ex0] != 0 || samples.piece[i] != p {
                return None;
            }
            if p != EMPTY && samples.face[i][3] != shade {
                return None;
            }
        }
    }
    Some(match looks.get(p as usize) {
        Some(l) => {
            let shade = u32::from(shade);
            let lit = l.rgb.map(|v| ((u32::from(v) * shade + 127) / 255) as u8);
            let [r, g, b] = if l.class == class::OLD {
                fade(lit, style.fade)
            } else {
                lit
            };
            [r, g, b, 255]
        }
        None => {
            let [r, g, b, a] = style.background;
            [r, g, b, if a == 0 { 0 } else { 255 }]
        }
    })
}

/// Thickens lines: each sample takes the highest class within `radius`
/// (Chebyshev distance), and [`class::NEW`] within `radius_new`.
fn dilate(edges: Vec<u8>, w: usize, h: usize, radius: usize, radius_new: usize) -> Vec<u8> {
    let all = max_filter(edges.clone(), w, h, radius);
    if radius_new <= radius || !edges.contains(&class::NEW) {
        return all;
    }
    let new: Vec<u8> = edges
        .iter()
        .map(|&c| if c == class::NEW { c } else { 0 })
        .collect();
    let new = max_filter(new, w, h, radius_new);
    all.iter().zip(&new).map(|(&a, &b)| a.max(b)).collect()
}

/// The maximum over each `(2r + 1)` square, separably.
fn max_filter(src: Vec<u8>, w: usize, h: usize, r: usize) -> Vec<u8> {
    if r == 0 || w == 0 {
        return src;
    }
    // Across: each element takes the max of its neighbours up to r away.
    let mut tmp = src.clone();
    for (out, row) in tmp.chunks_exact_mut(w).zip(src.chunks_exact(w)) {
        for d in 1..=r.min(w - 1) {
            for x in 0..w - d {
                out[x] = out[x].max(row[x + d]);
                out[x + d] = out[x + d].max(row[x]);
            }
        }
    }
    // Down: whole rows at a time.
    let mut out = tmp.clone();
    for y in 0..h {
        let (a, b) = (y.saturating_sub(r), (y + r + 1).min(h));
        for yy in a..b {
            if yy == y {
                continue;
            }
            let dst = &mut out[y * w..(y + 1) * w];
            let src_row = &tmp[yy * w..(yy + 1) * w];
            for (o, &v) in dst.iter_mut().zip(src_row) {
                *o = (*o).max(v);
            }
        }
    }
    out
}

/// The line colour of new pieces for an accent colour, or the plain line.
pub(crate) fn new_line(accent: Option<Rgb<u8>>) -> [u8; 3] {
    accent.map_or(LINE, |c| c.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::camera::{Camera, View};
    use crate::render::raster::{tests::heap, Light};
    use crate::render::RenderOptions;

    #[test]
    fn a_large_rectangle_composed_in_bands_is_the_rectangle_composed_whole() {
        let scene = heap(60);
        let opts = RenderOptions::default();
        let (w, h) = (opts.width, opts.height);
        let cam = Camera::fit(&View::default(), scene.points(), w, h, opts.margin);
        let light = Light::for_camera(&cam);
        let mut samples = Samples::new(w, h, opts.supersample);
        for i in 0..scene.pieces().len() {
            samples.draw_piece(&scene, i, &cam, &light);
        }
        // New, old and plain pieces: every line weight and fade.
        let looks: Vec<PieceLook> = scene
            .pieces()
            .iter()
            .enumerate()
            .map(|(i, p)| PieceLook {
                rgb: p.color.0,
                class: [class::NEW, class::OLD, class::PLAIN][i % 3],
            })
            .collect();
        let style = opts.style(&cam);
        let rect = PixelRect {
            x0: 3,
            y0: 5,
            x1: w - 7,
            y1: h - 2,
        };
        let area = u64::from(rect.x1 - rect.x0) * u64::from(rect.y1 - rect.y0);
        assert!(area >= BANDED_PIXELS && rect.y1 - rect.y0 > 2 * band_rows(rect.y1 - rect.y0));
        let blank = RgbaImage::from_pixel(w, h, image::Rgba(style.background));
        let mut banded = blank.clone();
        compose(&samples, &looks, &style, rect, &mut banded);
        let mut whole = blank;
        let width = whole.width() as usize;
        compose_rows(
            &samples,
            &looks,
            &style,
            rect,
            Rows {
                pixels: &mut whole,
                width,
                top: 0,
            },
        );
        assert!(banded == whole, "the bands' pixels differ from the whole's");
        let colours: std::collections::BTreeSet<[u8; 4]> = whole.pixels().map(|p| p.0).collect();
        assert!(
            colours.len() > 50,
            "{} colours: too plain a test",
            colours.len()
        );
    }
}
