//! Tests of the whole renderer on boxes made here.

use glam::Vec3;
use image::{Rgb, RgbaImage};

use super::scene::test_geometry::cuboid;
use super::*;
use crate::assembly::Step;

const RED: Rgb<u8> = Rgb([201, 26, 9]);
const GREY: Rgb<u8> = Rgb([160, 165, 169]);
const BLUE: Rgb<u8> = Rgb([0, 85, 191]);

/// A 2 x 4 "brick" box in LDU at stud `(x, z)`, course `level` (0 = floor).
fn brick(x: f32, z: f32, level: f32) -> Vec<Triangle> {
    let y = -24.0 * level;
    cuboid(
        Vec3::new(20.0 * x, y - 24.0, 20.0 * z),
        Vec3::new(20.0 * x + 80.0, y, 20.0 * z + 40.0),
    )
}

/// Five boxes in four steps, one of them hidden behind the others from
/// some views.
fn little_model() -> Scene {
    let mut s = Scene::new();
    s.add_piece(RED, Step(1), brick(0.0, 0.0, 0.0));
    s.add_piece(GREY, Step(1), brick(4.0, 0.0, 0.0));
    s.add_piece(BLUE, Step(2), brick(2.0, 0.0, 1.0));
    s.add_piece(RED, Step(3), brick(2.0, -2.0, 0.0));
    s.add_piece(GREY, Step(4), brick(3.0, 0.0, 2.0));
    s
}

fn opts() -> RenderOptions {
    RenderOptions::default().with_size(160, 120)
}

fn png(img: &RgbaImage) -> Vec<u8> {
    let mut out = Vec::new();
    write_png(img, false, &mut out).unwrap();
    out
}

fn is_white(p: &image::Rgba<u8>) -> bool {
    p.0 == [255, 255, 255, 255]
}

#[test]
fn outlines_are_drawn_at_the_silhouette() {
    let mut scene = Scene::new();
    scene.add_piece(Rgb([240, 240, 240]), Step(1), brick(0.0, 0.0, 0.0));
    let r = StepRenderer::new(scene, &opts()).unwrap();
    let img = r.model_image();
    // Walk the middle row from the left: the first non-white pixel is
    // dark (the outline), not the light brick colour.
    let y = img.height() / 2;
    let first = (0..img.width())
        .map(|x| img.get_pixel(x, y))
        .find(|p| !is_white(p))
        .expect("the brick shows");
    assert!(first.0[..3].iter().all(|&c| c < 160), "{first:?}");
}

#[test]
fn edges_are_anti_aliased() {
    let mut scene = Scene::new();
    scene.add_piece(RED, Step(1), brick(0.0, 0.0, 0.0));
    let r = StepRenderer::new(scene, &opts()).unwrap();
    let img = r.model_image();
    // Slanted silhouettes leave pixels part line, part background.
    let between = img
        .pixels()
        .filter(|p| {
            let [r, g, b, _] = p.0;
            r == g && g == b && (60..200).contains(&r)
        })
        .count();
    assert!(between > 10, "{between} grey edge pixels");
}

#[test]
fn same_input_gives_the_same_png_bytes() {
    let a = StepRenderer::new(little_model(), &opts()).unwrap();
    let b = StepRenderer::new(little_model(), &opts()).unwrap();
    assert_eq!(png(&a.model_image()), png(&b.model_image()));
    let sa: Vec<_> = a.images().map(|(_, i)| png(&i)).collect();
    let sb: Vec<_> = b.images().map(|(_, i)| png(&i)).collect();
    assert_eq!(sa, sb);
}

#[test]
fn incremental_steps_equal_steps_drawn_from_scratch() {
    for highlight in [
        Highlight::Strong,
        Highlight::Accent(Rgb([255, 160, 0])),
        Highlight::None,
    ] {
        let o = opts().with_highlight(highlight).with_supersample(3);
        let r = StepRenderer::new(little_model(), &o).unwrap();
        let steps: Vec<_> = r.images().collect();
        assert_eq!(steps.len(), 4);
        for (n, (step, img)) in steps.iter().enumerate() {
            assert_eq!(*step, Step(n as u32 + 1));
            assert!(
                *img == r.step_image(n).unwrap(),
                "step {step:?} {highlight:?}"
            );
        }
        // A run starting midway agrees too.
        let tail: Vec<_> = r.images_in(2..4).collect();
        assert!(tail[0].1 == steps[2].1 && tail[1].1 == steps[3].1);
    }
}

/// Pixels that differ between two images.
fn changed(a: &RgbaImage, b: &RgbaImage) -> Vec<(u32, u32)> {
    a.enumerate_pixels()
        .filter(|(x, y, p)| *p != b.get_pixel(*x, *y))
        .map(|(x, y, _)| (x, y))
        .collect()
}

#[test]
fn a_step_changes_only_pixels_near_its_pieces() {
    // Without highlight or fade, only the new pieces change the picture.
    let r = StepRenderer::new(little_model(), &opts().with_highlight(Highlight::None)).unwrap();
    let imgs: Vec<_> = r.images().map(|(_, i)| i).collect();
    let (w, h) = (160, 120);
    for n in 1..imgs.len() {
        let zone = r.step_rect(n).grown(2, w, h);
        let diff = changed(&imgs[n - 1], &imgs[n]);
        assert!(!diff.is_empty(), "step {n} changes something");
        for (x, y) in diff {
            assert!(zone.contains(x, y), "step {n}: ({x}, {y}) outside {zone:?}");
        }
    }
    // With highlight and fade, the previous step's pieces change too.
    let r = StepRenderer::new(little_model(), &opts()).unwrap();
    let imgs: Vec<_> = r.images().map(|(_, i)| i).collect();
    for n in 1..imgs.len() {
        let new = r.step_rect(n).grown(2, w, h);
        let faded = r.step_rect(n - 1).grown(2, w, h);
        for (x, y) in changed(&imgs[n - 1], &imgs[n]) {
            assert!(
                new.contains(x, y) || faded.contains(x, y),
                "step {n}: ({x}, {y})"
            );
        }
    }
}

#[test]
fn earlier_pieces_are_faded_and_new_ones_are_not() {
    let r = StepRenderer::new(little_model(), &opts()).unwrap();
    let (_, last) = r.images().last().unwrap();
    let model = r.model_image();
    // Step 4 adds the top grey brick: inside it the two images agree; on the
    // bottom-left red brick the step image is lighter.
    let red = r.piece_rect(0);
    let (cx, cy) = ((red.x0 + red.x1) / 2, red.y1 - 4);
    let (a, b) = (last.get_pixel(cx, cy).0, model.get_pixel(cx, cy).0);
    assert!(a[1] > b[1] + 40, "faded {a:?} vs plain {b:?}");
    let top = r.piece_rect(4);
    let (tx, ty) = ((top.x0 + top.x1) / 2, (top.y0 + top.y1) / 2);
    assert_eq!(last.get_pixel(tx, ty), model.get_pixel(tx, ty));
}

#[test]
fn parallel_files_match_the_sequential_images() {
    let dir = tempfile::tempdir().unwrap();
    let r = StepRenderer::new(little_model(), &opts()).unwrap();
    let paths = r.write_steps(&dir.path().join("steps")).unwrap();
    let names: Vec<_> = paths
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "step-001.png",
            "step-002.png",
            "step-003.png",
            "step-004.png"
        ]
    );
    for ((_, img), path) in r.images().zip(&paths) {
        assert_eq!(std::fs::read(path).unwrap(), png(&img));
    }
}

#[test]
fn an_empty_scene_gives_blank_images_and_no_steps() {
    let r = StepRenderer::new(Scene::new(), &opts()).unwrap();
    assert_eq!(r.images().count(), 0);
    assert!(r.step_image(0).is_none());
    let img = r.model_image();
    assert!(img.pixels().all(is_white));
    let dir = tempfile::tempdir().unwrap();
    assert!(r.write_steps(dir.path()).unwrap().is_empty());
}

#[test]
fn transparent_background_has_zero_alpha_outside() {
    let o = opts().with_background(Background::Transparent);
    let r = StepRenderer::new(little_model(), &o).unwrap();
    let img = r.model_image();
    assert_eq!(img.get_pixel(0, 0).0[3], 0);
    assert_eq!(img.get_pixel(80, 60).0[3], 255);
    assert!(img.pixels().any(|p| (1..255).contains(&p.0[3])));
}

#[test]
fn bad_options_are_refused_with_a_reason() {
    for o in [
        opts().with_size(0, 10),
        opts().with_size(10, 100_000),
        opts().with_supersample(0),
        opts().with_size(8192, 8192).with_supersample(4),
        opts().with_line_width(f32::NAN),
        opts().with_fade(2.0),
        opts().with_margin(60),
        opts().with_view(View {
            azimuth_deg: f32::INFINITY,
            ..View::default()
        }),
    ] {
        let e = StepRenderer::new(little_model(), &o).unwrap_err();
        assert!(e.to_string().contains("out of range"), "{e}");
    }
}

#[test]
fn every_quarter_turn_shows_the_whole_model() {
    for turns in 0..4 {
        let o = opts().with_view(View::default().turned(turns));
        let r = StepRenderer::new(little_model(), &o).unwrap();
        let img = r.model_image();
        // Nothing touches the image border (the margin is free).
        let (w, h) = img.dimensions();
        for x in 0..w {
            assert!(is_white(img.get_pixel(x, 0)) && is_white(img.get_pixel(x, h - 1)));
        }
        for y in 0..h {
            assert!(is_white(img.get_pixel(0, y)) && is_white(img.get_pixel(w - 1, y)));
        }
    }
}

#[test]
fn long_sliver_triangles_leave_no_specks() {
    // Regression: a face cut into a fan of slivers (as part meshes cut
    // faces to avoid T-junctions) once showed stray line dots, its depth
    // interpolated too coarsely. A flat square facing the viewer, fanned
    // from one corner to 60 points along the far edges:
    let (lo, hi) = (-100.0_f32, 100.0_f32);
    let corner = Vec3::new(lo, lo, 0.0);
    let mut rim = Vec::new();
    for k in 0..=30 {
        rim.push(Vec3::new(hi, lo + (hi - lo) * k as f32 / 30.0, 0.0));
    }
    for k in 1..=30 {
        rim.push(Vec3::new(hi - (hi - lo) * k as f32 / 30.0, hi, 0.0));
    }
    let fan: Vec<Triangle> = rim
        .windows(2)
        .map(|w| Triangle {
            positions: [corner, w[0], w[1]],
            normal: Vec3::new(0.0, 0.0, -1.0),
        })
        .collect();
    let mut scene = Scene::new();
    scene.add_piece(GREY, Step(1), fan);
    let view = View {
        azimuth_deg: 20.0,
        elevation_deg: 25.0,
        quarter_turns: 0,
    };
    let r = StepRenderer::new(scene, &opts().with_size(320, 320).with_view(view)).unwrap();
    let img = r.model_image();
    // Inside the face every pixel has the face's one colour.
    let centre = *img.get_pixel(160, 160);
    for y in 120..200 {
        for x in 120..200 {
            assert_eq!(*img.get_pixel(x, y), centre, "speck at ({x}, {y})");
        }
    }
}

/// A tall wall along the front and right of the base view, built first,
/// then a brick hidden behind it at its foot, then one on top of the wall.
fn wall_then_behind() -> Scene {
    let mut s = Scene::new();
    // The base view looks from the front right (-Z, +X) and above.
    for level in 0..6 {
        let l = level as f32;
        s.add_piece(GREY, Step(1), brick(0.0, -2.0, l)); // front, x 0..4
        s.add_piece(GREY, Step(1), brick(4.0, -2.0, l)); // front, x 4..8
        s.add_piece(
            GREY,
            Step(1),
            cuboid(
                Vec3::new(160.0, -24.0 * (l + 1.0), -40.0),
                Vec3::new(200.0, -24.0 * l, 80.0),
            ),
        ); // right, z -2..4
    }
    s.add_piece(RED, Step(2), brick(2.0, 1.0, 0.0));
    s.add_piece(BLUE, Step(3), brick(0.0, -2.0, 6.0));
    s
}

/// Pixels within one of `rgb` (per channel), as full-colour new pieces are
/// drawn on their lit faces.
fn pixels_near(img: &RgbaImage, rgb: Rgb<u8>) -> usize {
    img.pixels()
        .filter(|p| {
            // The same hue at some shade: channels in the colour's ratio.
            let top = (0..3).max_by_key(|&k| rgb.0[k]).unwrap_or(0);
            let s = f32::from(p.0[top]) / f32::from(rgb.0[top].max(1));
            s > 0.3 && (0..3).all(|k| (f32::from(p.0[k]) - s * f32::from(rgb.0[k])).abs() < 12.0)
        })
        .count()
}

#[test]
fn a_step_behind_a_wall_turns_the_view_and_shows_its_pieces() {
    let o = opts().with_size(320, 240);
    let turned = StepRenderer::new(wall_then_behind(), &o).unwrap();
    let fixed = StepRenderer::new(wall_then_behind(), &o.with_turn(Turning::Off)).unwrap();
    assert_eq!(turned.step_turns(0), 0);
    assert_ne!(turned.step_turns(1), 0, "the hidden step is seen turned");
    assert!(turned.turn_at(1).is_some());
    assert_eq!(turned.turn_at(0), None);
    assert!((0..3).all(|n| fixed.step_turns(n) == 0 && fixed.turn_at(n).is_none()));
    // Every view shares one scale; without a turn the base camera is as it was.
    let s = turned.step_camera(1).scale();
    assert!((turned.camera().scale() - s).abs() < 1e-6);
    assert!(fixed.camera().scale() >= s);

    let red_turned = pixels_near(&turned.step_image(1).unwrap(), RED);
    let red_fixed = pixels_near(&fixed.step_image(1).unwrap(), RED);
    assert!(
        red_turned > 200 && red_turned > 10 * red_fixed.max(1),
        "red pixels: turned {red_turned}, fixed {red_fixed}"
    );
    // Incremental and from-scratch images agree across the turn.
    let imgs: Vec<_> = turned.images().map(|(_, i)| i).collect();
    for (n, img) in imgs.iter().enumerate() {
        assert!(*img == turned.step_image(n).unwrap(), "step {}", n + 1);
    }
    // Runs never span a turn.
    for run in turned.runs() {
        assert!(
            run.clone().skip(1).all(|n| turned.turn_at(n).is_none()),
            "{run:?}"
        );
    }
}

#[test]
fn a_model_built_front_first_never_turns() {
    // Rows of bricks from the front (the viewer's side) to the back, then
    // a second course: every new piece is in view.
    let mut s = Scene::new();
    let mut step = 0;
    for level in 0..2 {
        for z in 0..4 {
            step += 1;
            for x in 0..3 {
                s.add_piece(
                    RED,
                    Step(step),
                    brick(
                        4.0 * x as f32 + 2.0 * level as f32,
                        -2.0 * z as f32,
                        level as f32,
                    ),
                );
            }
        }
    }
    let r = StepRenderer::new(s, &opts()).unwrap();
    assert!((0..r.steps().len()).all(|n| r.step_turns(n) == 0));
}

#[test]
fn turned_images_are_the_same_bytes_every_time() {
    let a = StepRenderer::new(wall_then_behind(), &opts()).unwrap();
    let b = StepRenderer::new(wall_then_behind(), &opts()).unwrap();
    let sa: Vec<_> = a.images().map(|(_, i)| png(&i)).collect();
    let sb: Vec<_> = b.images().map(|(_, i)| png(&i)).collect();
    assert_eq!(sa, sb);
    // Written in parallel runs, the files are the same images.
    let dir = tempfile::tempdir().unwrap();
    let paths = a.write_steps(dir.path()).unwrap();
    for (bytes, path) in sa.iter().zip(&paths) {
        assert_eq!(&std::fs::read(path).unwrap(), bytes);
    }
}

#[test]
fn pieces_take_the_colours_they_are_given() {
    use crate::assembly::{Assembly, Placement};
    use crate::catalog::{Color, PartKind};
    use crate::geom::{Cell, Rot};
    let brick = PartKind::from_id("3001").unwrap();
    let order = [
        Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
        Placement::new(brick, Cell::new(4, 0, 0), Rot::R0),
    ];
    let asm = Assembly::from_order(&order, 24, Color::RED);
    let colors = [stress_color(0.0), stress_color(1.0)];
    let img = model_image_with_colors(&asm, &colors, &opts().with_size(240, 180)).unwrap();
    for c in colors {
        assert!(
            pixels_near(&img, c) > 100,
            "{c:?}: {}",
            pixels_near(&img, c)
        );
    }
    let e = model_image_with_colors(&asm, &colors[..1], &opts()).unwrap_err();
    assert!(
        matches!(
            e,
            RenderError::Colors {
                expected: 2,
                got: 1
            }
        ),
        "{e}"
    );
}

#[test]
fn the_model_composed_from_the_last_steps_buffer_is_the_one_drawn_afresh() {
    // A model whose last step is seen as the model is (the buffer is
    // used), and one whose last step turns (it is not): the same image
    // either way.
    for scene in [little_model(), wall_then_behind()] {
        let r = StepRenderer::new(scene, &opts().with_size(320, 240)).unwrap();
        let mut images = r.images();
        for _ in images.by_ref() {}
        let finished = images.into_finished();
        assert!(r.model_image_from(finished) == r.model_image());
    }
    // A range short of the last step leaves nothing to reuse.
    let r = StepRenderer::new(wall_then_behind(), &opts().with_size(320, 240)).unwrap();
    let mut images = r.images_in(0..1);
    for _ in images.by_ref() {}
    assert!(images.into_finished().is_none());
}
