//! The measures of step pictures and steps, on a build's own outputs:
//! shared by `tests/framing.rs`, which bounds them on the fixtures, and
//! `examples/framing_table.rs`, which prints them for any mesh.
//!
//! - framing: in each step image, the model's bounding box (its
//!   non-white pixels, the "turn the model" badge's corner left out) over
//!   the frame, the larger side of the two; whether the box touches the
//!   frame's edge or a step's new pieces leave the frame (a piece cut
//!   off); every change of scale, which must be a quarter or more;
//! - steps: new pieces a step, in step order;
//! - the page: the booklet's layout of the steps (pages, and each step's
//!   model share of its printed picture), with its own checks: nothing
//!   overlaps or leaves its cell or the page, no model pixel runs under a
//!   step's number or callout.

#![allow(dead_code)] // The test and the example each use some of these.

use std::collections::BTreeMap;
use std::path::Path;

use brickwright::assembly::Assembly;
use brickwright::booklet::layout::{Ink, Rect, StepPlace};
use brickwright::booklet::{plan_steps, BookletInput, Template};
use brickwright::render::{self, RenderOptions, StepRenderer};
use image::RgbaImage;

/// The bounding box `(x0, y0, x1, y1)` (inclusive) of the pixels that are
/// not the white background, leaving out the corners' squares of side
/// `corner` (where a "turn the model" badge may be drawn: leaving pixels
/// out only shrinks the box, so the measured share is a lower bound).
pub fn model_box(img: &image::RgbImage, corner: u32) -> Option<(u32, u32, u32, u32)> {
    let (w, h) = img.dimensions();
    let in_corner = |x: u32, y: u32| {
        corner > 0 && (x < corner || x >= w - corner) && (y < corner || y >= h - corner)
    };
    let mut b: Option<(u32, u32, u32, u32)> = None;
    for (x, y, p) in img.enumerate_pixels() {
        if p.0.iter().all(|&c| c >= 250) || in_corner(x, y) {
            continue;
        }
        b = Some(match b {
            None => (x, y, x, y),
            Some((x0, y0, x1, y1)) => (x0.min(x), y0.min(y), x1.max(x), y1.max(y)),
        });
    }
    b
}

/// The value below which `q` of `values` lie (the lowest tenth: 0.1).
pub fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v[((v.len() as f64 * q).ceil() as usize).saturating_sub(1)]
}

/// What one build's step images show.
pub struct Framing {
    /// Each step's model share: its box's larger side over the frame's.
    pub shares: Vec<f64>,
    /// Steps (numbered from 1) whose model touches the frame's edge.
    pub at_edge: Vec<usize>,
    /// Steps whose new pieces run out of the frame.
    pub cut_off: Vec<usize>,
    /// Each change of scale: the step it comes at and its share of the
    /// larger scale.
    pub changes: Vec<(usize, f64)>,
    /// Steps whose view turned.
    pub turns: usize,
    /// Turned steps whose "turn the model" badge covers part of the
    /// screen box of the step's new pieces.
    pub badge_over_new: Vec<usize>,
    /// Steps that show nothing.
    pub blank: Vec<usize>,
}

impl Framing {
    /// The changes of scale smaller than a quarter.
    pub fn small_changes(&self) -> Vec<(usize, f64)> {
        self.changes
            .iter()
            .copied()
            .filter(|&(_, c)| c < 0.25 - 1e-4)
            .collect()
    }
}

/// The renderer a build draws `assembly`'s steps with: which steps turned
/// (and carry the badge), and each step's camera.
pub fn renderer(assembly: &Assembly) -> StepRenderer {
    render::renderer(assembly, &RenderOptions::default()).expect("the default options are valid")
}

/// The step images `DIR/step-001.png`... of a build of `steps` steps.
pub fn step_images(dir: &Path, steps: usize) -> Vec<RgbaImage> {
    let digits = steps.to_string().len().max(3);
    (1..=steps)
        .map(|s| {
            let path = dir.join(format!("step-{s:0digits$}.png"));
            image::open(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .to_rgba8()
        })
        .collect()
}

/// Measures the framing of `images`, the step images `r` drew.
pub fn framing(r: &StepRenderer, images: &[RgbaImage]) -> Framing {
    let opts = RenderOptions::default();
    let badge = (opts.width.min(opts.height) as f32 * 0.15).round() as u32 + 24;
    let mut f = Framing {
        shares: Vec::new(),
        at_edge: Vec::new(),
        cut_off: Vec::new(),
        changes: Vec::new(),
        turns: 0,
        badge_over_new: Vec::new(),
        blank: Vec::new(),
    };
    for (n, img) in images.iter().enumerate() {
        let img = image::DynamicImage::ImageRgba8(img.clone()).to_rgb8();
        let (w, h) = img.dimensions();
        let turned = r.turn_at(n).is_some();
        f.turns += usize::from(turned);
        if turned && badge_over_new(r, n, &img) {
            f.badge_over_new.push(n + 1);
        }
        let corner = if turned { badge } else { 0 };
        let Some((x0, y0, x1, y1)) = model_box(&img, corner) else {
            f.blank.push(n + 1);
            f.shares.push(0.0);
            continue;
        };
        if x0 == 0 || y0 == 0 || x1 + 1 >= w || y1 + 1 >= h {
            f.at_edge.push(n + 1);
        }
        if new_piece_cut_off(r, n) {
            f.cut_off.push(n + 1);
        }
        f.shares.push(f64::max(
            f64::from(x1 - x0 + 1) / f64::from(w),
            f64::from(y1 - y0 + 1) / f64::from(h),
        ));
        if n > 0 {
            let (a, b) = (r.step_camera(n - 1).scale(), r.step_camera(n).scale());
            let change = f64::from((a - b).abs() / a.max(b));
            if change >= 1e-4 {
                f.changes.push((n + 1, change));
            }
        }
    }
    f
}

/// Whether the "turn the model" badge of step number `n`'s image `img`
/// (found as the corner square with the most of the badge's colour)
/// covers part of the screen box of the step's new pieces.
fn badge_over_new(r: &StepRenderer, n: usize, img: &image::RgbImage) -> bool {
    const BADGE: [u8; 3] = [221, 234, 246];
    let (w, h) = img.dimensions();
    let side = (w.min(h) as f32 * 0.15).round().clamp(20.0, 160.0) as u32;
    let pad = (side / 10).max(2);
    let corners = [
        (w - side - pad, pad),
        (pad, pad),
        (w - side - pad, h - side - pad),
        (pad, h - side - pad),
    ];
    let badge = |&(x0, y0): &(u32, u32)| {
        (y0..y0 + side)
            .flat_map(|y| (x0..x0 + side).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0 == BADGE)
            .count()
    };
    let Some(&(x0, y0)) = corners.iter().max_by_key(|c| badge(c)) else {
        return false;
    };
    let new = r.step_rect(n);
    x0 < new.x1 && new.x0 < x0 + side && y0 < new.y1 && new.y0 < y0 + side
}

/// Whether a point of a piece step number `n` adds lies outside its
/// image, in the step's own view.
fn new_piece_cut_off(r: &StepRenderer, n: usize) -> bool {
    let Some(step) = r.steps().nth(n) else {
        return false;
    };
    let camera = r.step_camera(n);
    let (w, h) = (camera.width() as f32, camera.height() as f32);
    let scene = r.scene();
    (0..scene.pieces().len())
        .filter(|&i| scene.pieces()[i].step == step)
        .flat_map(|i| scene.piece_triangles(i))
        .flat_map(|t| t.positions)
        .any(|v| {
            let p = camera.project(v);
            p.x < 0.0 || p.y < 0.0 || p.x > w || p.y > h
        })
}

/// New pieces a step, in step order; `None` unless the steps are
/// numbered 1, 2, ... with no gap.
pub fn step_sizes(assembly: &Assembly) -> Option<Vec<usize>> {
    let mut count: BTreeMap<u32, usize> = BTreeMap::new();
    for p in &assembly.pieces {
        *count.entry(p.step.0).or_default() += 1;
    }
    let numbers: Vec<u32> = count.keys().copied().collect();
    (numbers == (1..=numbers.len() as u32).collect::<Vec<_>>())
        .then(|| count.into_values().collect())
}

/// The booklet's step pages of `assembly`, its step images `images` drawn
/// by `r`, `notes` by step number.
pub struct Pages {
    /// Pages of steps.
    pub pages: usize,
    /// Each step's model share of its printed picture: the larger side of
    /// the model's box over the picture's.
    pub shares: Vec<f64>,
}

/// Lays out the step pages as the build does and checks them (see the
/// module docs); panics on a broken page.
pub fn pages(
    assembly: &Assembly,
    r: &StepRenderer,
    images: &[RgbaImage],
    notes: &BTreeMap<u32, String>,
) -> Pages {
    let step_scales: Vec<f32> = (0..images.len())
        .map(|n| r.step_camera(n).scale() * 20.0)
        .collect();
    let template = Template::default();
    let input = BookletInput {
        title: "model",
        assembly,
        size_studs: [0.0; 3],
        size_cm: [0.0; 3],
        model: &images[images.len() - 1],
        exploded: &images[images.len() - 1],
        steps: images,
        step_scales: &step_scales,
        parts: &BTreeMap::new(),
        step_notes: notes,
    };
    let plan = plan_steps(&input, &template).unwrap();
    let (pw, ph) = template.page.size.mm();
    let m = template.page.margin;
    let content = Rect {
        x: m,
        y: m,
        w: pw - 2.0 * m,
        h: ph - 2.0 * m,
    };
    let inside = |r: Rect, o: Rect| {
        r.x >= o.x - 1e-3
            && r.y >= o.y - 1e-3
            && r.right() <= o.right() + 1e-3
            && r.bottom() <= o.bottom() + 1e-3
    };
    let mut next = 1;
    let mut shares = Vec::new();
    for page in &plan {
        let places: Vec<&StepPlace> = page.steps().collect();
        assert!(!places.is_empty());
        for (i, p) in places.iter().enumerate() {
            // Every step once, in order: rows top to bottom, left to right.
            assert_eq!(p.step, next);
            next += 1;
            let header = p.header();
            assert!(inside(p.cell, content), "step {}: {p:?}", p.step);
            assert!(inside(p.picture, p.cell), "step {}: {p:?}", p.step);
            assert!(inside(header, p.cell), "step {}: {p:?}", p.step);
            for q in &places[i + 1..] {
                assert!(!p.cell.overlaps(&q.cell), "{p:?} {q:?}");
            }
            // Printed at the image's own aspect.
            let s = p.picture.w / p.crop.width() as f32;
            assert!((p.picture.h - p.crop.height() as f32 * s).abs() < 0.01);
            // No model pixel under the header: each column's first ink.
            let ink = Ink::of(&images[p.step as usize - 1]);
            for x in p.crop.x0..p.crop.x1 {
                let top = ink.top[x as usize];
                if top >= p.crop.y1 {
                    continue;
                }
                let mx = p.picture.x + (x - p.crop.x0) as f32 * s;
                let my = p.picture.y + (top - p.crop.y0) as f32 * s;
                assert!(
                    mx < header.x || mx > header.right() || my >= header.bottom(),
                    "step {}: ink at ({mx:.1}, {my:.1}) mm under the header {header:?}",
                    p.step
                );
            }
            let b = ink.bbox.expect("a step shows something");
            shares.push(f64::max(
                f64::from(b.width()) / f64::from(p.crop.width()),
                f64::from(b.height()) / f64::from(p.crop.height()),
            ));
        }
    }
    assert_eq!(next as usize - 1, images.len(), "every step is on a page");
    Pages {
        pages: plan.len(),
        shares,
    }
}
