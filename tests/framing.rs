//! Step pictures a builder can read, steps of a builder's size, measured
//! on real builds of the fixtures:
//!
//! - framing: in each step image written by the build, the model's
//!   bounding box (its non-white pixels) fills most of the frame (larger
//!   side at least 60% of the frame's in the median step, 45% in the
//!   lowest tenth), and never touches the frame's edge (nothing new is
//!   cut off); the scale changes rarely, by a quarter or more each time;
//! - steps: 3 to 8 new pieces a step (mean at least 3 on models of 100
//!   pieces or more), the steps numbered 1, 2, 3, ... in the order of the
//!   pieces;
//! - the page: the booklet's step pictures, cut to the model, are mostly
//!   model (little white around it), no model pixel runs under a step's
//!   number or callout, nothing overlaps or leaves its cell or the page,
//!   and a page holds more steps than the four of a fixed grid.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use brickwright::booklet::layout::{Ink, Rect, StepPlace};
use brickwright::booklet::{plan_steps, BookletInput, Template};
use brickwright::pipeline::pictures::{render_all, Pictures};
use brickwright::pipeline::{self, BuildOptions, BuildOutput, Formats, Silent};
use brickwright::render::{self, RenderOptions};
use brickwright::voxel::Sizing;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn build(fixture: &str, studs: u32, out: &Path) -> BuildOutput {
    let mut opts = BuildOptions::new(root().join("fixtures").join(fixture));
    opts.out_dir = out.to_path_buf();
    opts.sizing = Sizing::Studs(studs);
    opts.formats = Formats::parse("ldr,steps").unwrap();
    pipeline::build(&opts, &Silent).unwrap_or_else(|e| panic!("{fixture} does not build: {e}"))
}

/// The bounding box `(x0, y0, x1, y1)` (inclusive) of the pixels that are
/// not the white background, leaving out `masked` corners' squares of
/// side `corner` (where a "turn the model" badge may be drawn: leaving
/// pixels out only shrinks the box, so the measured share is a lower
/// bound).
fn model_box(img: &image::RgbImage, corner: u32) -> Option<(u32, u32, u32, u32)> {
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

/// What one build's step images show.
struct Framing {
    /// Each step's model share: its box's larger side over the frame's.
    shares: Vec<f64>,
}

fn framing(fixture: &str, studs: u32) -> (BuildOutput, Framing) {
    let tmp = tempfile::tempdir().unwrap();
    let built = build(fixture, studs, tmp.path());
    // The renderer the build drew the steps with, for which steps turned
    // (and carry the badge) and each step's camera.
    let opts = RenderOptions::default();
    let r = render::renderer(&built.assembly, &opts).unwrap();
    let badge = (opts.width.min(opts.height) as f32 * 0.15).round() as u32 + 24;
    let mut shares = Vec::new();
    for n in 0..built.report.steps as usize {
        let path = tmp
            .path()
            .join("steps")
            .join(format!("step-{:03}.png", n + 1));
        let img = image::open(&path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .to_rgb8();
        let (w, h) = img.dimensions();
        let corner = if r.turn_at(n).is_some() { badge } else { 0 };
        let (x0, y0, x1, y1) = model_box(&img, corner)
            .unwrap_or_else(|| panic!("{fixture}: step {} shows nothing", n + 1));
        assert!(
            x0 > 0 && y0 > 0 && x1 + 1 < w && y1 + 1 < h,
            "{fixture}: step {} runs off the frame: box {:?} in {w} x {h}",
            n + 1,
            (x0, y0, x1, y1)
        );
        let share = f64::max(
            f64::from(x1 - x0 + 1) / f64::from(w),
            f64::from(y1 - y0 + 1) / f64::from(h),
        );
        shares.push(share);
        // The scale changes rarely, and then by a quarter or more.
        if n > 0 {
            let (a, b) = (r.step_camera(n - 1).scale(), r.step_camera(n).scale());
            let change = (a - b).abs() / a.max(b);
            assert!(
                !(1e-4..0.25 - 1e-4).contains(&change),
                "{fixture}: the scale changes by {change:.3} at step {}",
                n + 1
            );
        }
    }
    (built, Framing { shares })
}

fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v[((v.len() as f64 * q).ceil() as usize).saturating_sub(1)]
}

/// New pieces a step, in step order; checks the steps are numbered 1, 2,
/// ... with no gap.
fn step_sizes(built: &BuildOutput) -> Vec<usize> {
    let mut count: BTreeMap<u32, usize> = BTreeMap::new();
    for p in &built.assembly.pieces {
        *count.entry(p.step.0).or_default() += 1;
    }
    let numbers: Vec<u32> = count.keys().copied().collect();
    assert_eq!(numbers, (1..=numbers.len() as u32).collect::<Vec<_>>());
    count.into_values().collect()
}

fn check(fixture: &str, studs: u32) {
    let (built, f) = framing(fixture, studs);
    let median = quantile(&f.shares, 0.5);
    let tenth = quantile(&f.shares, 0.1);
    eprintln!(
        "{fixture} at {studs} studs: {} pieces, {} steps, share median {median:.2}, lowest tenth {tenth:.2}",
        built.report.pieces, built.report.steps
    );
    assert!(median >= 0.6, "{fixture}: median share {median:.2}");
    assert!(tenth >= 0.45, "{fixture}: lowest tenth's share {tenth:.2}");

    let sizes = step_sizes(&built);
    let pieces: usize = sizes.iter().sum();
    assert_eq!(pieces, built.report.pieces);
    let mean = pieces as f64 / sizes.len() as f64;
    assert!(pieces >= 100, "{fixture}: only {pieces} pieces");
    assert!(mean >= 3.0, "{fixture}: {mean:.2} pieces a step");
    assert!(
        sizes.iter().all(|&s| s <= 8),
        "{fixture}: a step of more than 8 pieces: {sizes:?}"
    );
    let sized = sizes.iter().filter(|&&s| (3..=8).contains(&s)).count();
    assert!(
        sized * 10 >= sizes.len() * 7,
        "{fixture}: only {sized} of {} steps have 3 to 8 pieces: {sizes:?}",
        sizes.len()
    );
}

/// Checks the booklet's step pages of a real build (see the module
/// docs); returns the steps' count, the pages of steps, and each step's
/// model share of its printed picture (the larger side of the model's box
/// over the picture's).
fn page_use(built: &BuildOutput) -> (usize, usize, Vec<f64>) {
    let a = &built.assembly;
    let notes: BTreeMap<u32, String> = built
        .report
        .stability
        .iter()
        .flat_map(|s| &s.supports)
        .map(|c| (c.step, pipeline::SUPPORT_NOTE.to_string()))
        .collect();
    let pictures = Pictures {
        assembly: a,
        title: "model",
        size_studs: [0.0; 3],
        size_cm: [0.0; 3],
        step_notes: notes.clone(),
    };
    let rendered = render_all(&pictures, true, &Silent).unwrap();
    let template = Template::default();
    let input = BookletInput {
        title: "model",
        assembly: a,
        size_studs: [0.0; 3],
        size_cm: [0.0; 3],
        model: &rendered.model,
        exploded: &rendered.exploded,
        steps: &rendered.steps,
        step_scales: &rendered.step_scales,
        parts: &BTreeMap::new(),
        step_notes: &notes,
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
            let ink = Ink::of(&rendered.steps[p.step as usize - 1]);
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
    assert_eq!(next - 1, built.report.steps, "every step is on a page");
    (built.report.steps as usize, plan.len(), shares)
}

/// The page checks and bounds: the printed pictures are at least 85% model
/// across in the median step and 60% in the lowest tenth (the rest of the
/// frame's white is cut away), and a page of steps holds at least five
/// steps on average.
fn check_pages(fixture: &str, built: &BuildOutput) {
    let (steps, pages, shares) = page_use(built);
    let (median, tenth) = (quantile(&shares, 0.5), quantile(&shares, 0.1));
    eprintln!(
        "{fixture}: {steps} steps on {pages} pages, printed share median {median:.2}, lowest tenth {tenth:.2}"
    );
    assert!(
        median >= 0.85,
        "{fixture}: printed share median {median:.2}"
    );
    assert!(
        tenth >= 0.6,
        "{fixture}: printed share lowest tenth {tenth:.2}"
    );
    assert!(
        steps >= 5 * pages || pages == 1,
        "{fixture}: {steps} steps on {pages} pages"
    );
}

#[test]
fn a_tall_model_is_framed_as_it_grows() {
    check("tower.glb", 20);
}

#[test]
fn a_hollow_model_is_framed_and_stepped_for_people() {
    check("mug.obj", 20);
}

#[test]
fn the_booklet_pages_are_filled_with_model_not_white() {
    for (fixture, studs) in [("tower.glb", 20), ("house.obj", 16)] {
        let tmp = tempfile::tempdir().unwrap();
        check_pages(fixture, &build(fixture, studs, tmp.path()));
    }
}

#[test]
fn framing_is_measured_on_the_model_not_the_white() {
    // The measure itself: a box drawn on white is found exactly, and a
    // masked corner is left out.
    let mut img = image::RgbImage::from_pixel(100, 80, image::Rgb([255, 255, 255]));
    for y in 10..30 {
        for x in 20..70 {
            img.put_pixel(x, y, image::Rgb([200, 0, 0]));
        }
    }
    img.put_pixel(99, 79, image::Rgb([0, 0, 0]));
    assert_eq!(model_box(&img, 5), Some((20, 10, 69, 29)));
    assert_eq!(model_box(&img, 0), Some((20, 10, 99, 79)));
}
