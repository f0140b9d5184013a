//! Instruction images: reference renders and step images of a real build.
//!
//! Reference images live in `tests/reference/`. A render may differ from
//! its reference by a small per-channel tolerance (so harmless float
//! changes pass); past it the test writes the actual image and a diff image
//! (changed pixels red on a faded copy) into the target directory and says
//! where. Run `BLESS=1 cargo test --test all render::` to rewrite the references
//! after an intended change, then look at them.

use crate::common;

use std::path::{Path, PathBuf};

use brickwright::assembly::{Assembly, Placed, Placement};
use brickwright::catalog::{Color, PartKind};
use brickwright::geom::{Cell, Rot};
use brickwright::pipeline::{self, BuildOptions, Silent};
use brickwright::render::{self, Highlight, RenderOptions};
use brickwright::voxel::Sizing;
use image::RgbaImage;

/// Largest per-channel difference a pixel may have from its reference.
const TOLERANCE: u8 = 8;
/// Pixels allowed past the tolerance (edge pixels that round differently).
const MAX_BAD_PIXELS: usize = 4;

fn part(id: &str) -> PartKind {
    PartKind::from_id(id).unwrap()
}

fn reference_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference")
}

fn load_png(path: &Path) -> Option<RgbaImage> {
    let bytes = std::fs::read(path).ok()?;
    image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .ok()
        .map(|i| i.to_rgba8())
}

fn save_png(img: &RgbaImage, path: &Path) {
    let mut out = Vec::new();
    render::write_png(img, true, &mut out).unwrap();
    std::fs::write(path, out).unwrap();
}

/// Compares `actual` with `tests/reference/<name>.png`.
fn check_reference(name: &str, actual: &RgbaImage) {
    let path = reference_dir().join(format!("{name}.png"));
    // A blessed reference is still compared below (it must read back as
    // the image it was written from).
    if common::bless() {
        std::fs::create_dir_all(reference_dir()).unwrap();
        save_png(actual, &path);
    }
    let expected = load_png(&path).unwrap_or_else(|| {
        panic!(
            "{} is missing or unreadable; run with BLESS=1 to create it",
            path.display()
        )
    });
    let mut diff = RgbaImage::new(actual.width(), actual.height());
    let mut bad = 0;
    let same_size = expected.dimensions() == actual.dimensions();
    if same_size {
        for (x, y, a) in actual.enumerate_pixels() {
            let e = expected.get_pixel(x, y);
            let off = a.0.iter().zip(e.0).any(|(&p, q)| p.abs_diff(q) > TOLERANCE);
            bad += usize::from(off);
            let faded = a.0.map(|c| 192 + c / 4);
            diff.put_pixel(
                x,
                y,
                image::Rgba(if off { [255, 0, 0, 255] } else { faded }),
            );
        }
    }
    if !same_size || bad > MAX_BAD_PIXELS {
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("render-reference");
        std::fs::create_dir_all(&out).unwrap();
        let actual_path = out.join(format!("{name}.actual.png"));
        let diff_path = out.join(format!("{name}.diff.png"));
        save_png(actual, &actual_path);
        save_png(&diff, &diff_path);
        panic!(
            "{name}: {} (expected {:?}, got {:?}); actual image {}, diff {}; \
             run with BLESS=1 if the change is intended",
            if same_size {
                format!("{bad} pixels differ by more than {TOLERANCE}")
            } else {
                "sizes differ".to_string()
            },
            expected.dimensions(),
            actual.dimensions(),
            actual_path.display(),
            diff_path.display()
        );
    }
}

fn small_opts() -> RenderOptions {
    RenderOptions::default().with_size(240, 180)
}

/// A 2 x 4 brick, a 2 x 2 slope on its back half and a 1 x 2 brick in
/// front, one piece a step.
fn three_pieces() -> Assembly {
    let order = [
        Placement::new(part("3001"), Cell::new(0, 0, 0), Rot::R0),
        Placement::new(part("3039"), Cell::new(0, 0, 1), Rot::R180),
        Placement::new(part("3004"), Cell::new(2, 1, 1), Rot::R0),
    ];
    let mut asm = Assembly::from_order(&order, 24, Color::RED);
    asm.pieces[1].color = Color::WHITE;
    asm.pieces[2].color = Color(1);
    asm
}

#[test]
fn reference_brick_2x4() {
    check_reference("part-3001", &render::part_image(part("3001"), Color::RED));
}

#[test]
fn reference_slope_3039() {
    check_reference("part-3039", &render::part_image(part("3039"), Color(14)));
}

#[test]
fn reference_three_piece_model_and_steps() {
    let asm = three_pieces();
    check_reference(
        "three-model",
        &render::model_image(&asm, &small_opts()).unwrap(),
    );
    for (step, img) in render::steps(&asm, &small_opts()).unwrap() {
        check_reference(&format!("three-step-{}", step.0), &img);
    }
}

#[test]
fn an_empty_assembly_renders_a_blank_model_and_no_steps() {
    let asm = Assembly {
        pieces: Vec::<Placed>::new(),
        layer_ldu: 24,
    };
    let img = render::model_image(&asm, &small_opts()).unwrap();
    assert!(img.pixels().all(|p| p.0 == [255, 255, 255, 255]));
    assert_eq!(render::steps(&asm, &small_opts()).unwrap().count(), 0);
}

/// Pixels that differ between two images.
fn changed(a: &RgbaImage, b: &RgbaImage) -> Vec<(u32, u32)> {
    a.enumerate_pixels()
        .filter(|(x, y, p)| *p != b.get_pixel(*x, *y))
        .map(|(x, y, _)| (x, y))
        .collect()
}

#[test]
fn every_step_of_a_real_build_has_an_image_that_adds_only_its_pieces() {
    let build_dir = tempfile::tempdir().unwrap();
    let mut opts =
        BuildOptions::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/house.obj"));
    opts.out_dir = build_dir.path().to_path_buf();
    opts.sizing = Sizing::Studs(10);
    let asm = pipeline::build(&opts, &Silent).unwrap().assembly;
    let steps = asm.step_count() as usize;
    assert!(steps > 5);

    // One file per step, named by step.
    let ropts = RenderOptions::default().with_size(200, 150);
    let out = tempfile::tempdir().unwrap();
    let paths = render::write_steps(&asm, &ropts, &out.path().join("steps")).unwrap();
    assert_eq!(paths.len(), steps);
    for (k, p) in paths.iter().enumerate() {
        assert_eq!(
            p.file_name().unwrap().to_string_lossy(),
            format!("step-{:03}.png", k + 1)
        );
        let img = load_png(p).unwrap();
        assert_eq!(img.dimensions(), (200, 150));
    }

    // The unfaded layer: a step changes pixels only near its own pieces
    // (unless the view turned to show them, or zoomed out).
    let plain = ropts.with_highlight(Highlight::None);
    let r = render::renderer(&asm, &plain).unwrap();
    let imgs: Vec<RgbaImage> = r.images().map(|(_, i)| i).collect();
    for n in 1..imgs.len() {
        // A step seen turned or zoomed is drawn anew.
        if r.turn_at(n).is_some() || r.step_camera(n) != r.step_camera(n - 1) {
            continue;
        }
        let zone = r.step_rect(n).grown(2, 200, 150);
        for (x, y) in changed(&imgs[n - 1], &imgs[n]) {
            assert!(
                zone.contains(x, y),
                "step {}: pixel ({x}, {y}) outside {zone:?}",
                n + 1
            );
        }
    }
    // The last unfaded step is the finished model, seen from its view.
    let last = imgs.len() - 1;
    if r.step_turns(last) == 0 && r.turn_at(last).is_none() {
        assert!(imgs[last] == r.model_image());
    }

    // Highlighted: the previous step's pieces fade too, nothing else moves.
    let r = render::renderer(&asm, &ropts).unwrap();
    let imgs: Vec<RgbaImage> = r.images().map(|(_, i)| i).collect();
    // Drawn incrementally or from scratch, a step image is the same.
    for n in (0..imgs.len()).step_by(4) {
        assert!(r.step_image(n).unwrap() == imgs[n], "step {}", n + 1);
    }
    for n in 1..imgs.len() {
        // A step seen turned or zoomed is drawn anew.
        if r.turn_at(n).is_some() || r.step_camera(n) != r.step_camera(n - 1) {
            continue;
        }
        let new = r.step_rect(n).grown(2, 200, 150);
        let faded = r.step_rect(n - 1).grown(2, 200, 150);
        for (x, y) in changed(&imgs[n - 1], &imgs[n]) {
            assert!(
                new.contains(x, y) || faded.contains(x, y),
                "step {}: ({x}, {y})",
                n + 1
            );
        }
    }
}
