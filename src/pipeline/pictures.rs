//! The pictured outputs of a build: step images, the finished model, the
//! exploded view, and the PDF booklet that lays them out.
//!
//! Everything is rendered once, in parallel: the step images serve both
//! `steps/step-NNN.png` and the booklet's step pages. The pipeline calls
//! these; they are public for benchmarks and for library users who want
//! the pictures of an assembly without a build.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use image::RgbaImage;
use rayon::prelude::*;

use crate::assembly::Assembly;
use crate::booklet::{write_booklet, BookletInput, Template};
use crate::catalog::{Color, PartKind};
use crate::export::explode::{explode, ExplodeOptions};
use crate::export::partmesh::piece_transform;
use crate::render::{self, write_png, Background, RenderError, RenderOptions, Scene, StepRenderer};

/// What the pictured outputs need to know of the build.
pub struct Pictures<'a> {
    /// The build, steps grouped.
    pub assembly: &'a Assembly,
    /// The model's name, for the cover.
    pub title: &'a str,
    /// Size in studs (x, y) and height in bricks.
    pub size_studs: [f64; 3],
    /// Size in centimetres.
    pub size_cm: [f64; 3],
    /// A short note for some steps, by step number, for the booklet.
    pub step_notes: BTreeMap<u32, String>,
}

/// Rendered images, ready to be written.
pub struct Rendered {
    /// One image a step, step 1 first (empty unless asked for).
    pub steps: Vec<RgbaImage>,
    /// Pixels a stud's width measures in each step image.
    pub step_scales: Vec<f32>,
    /// The finished model.
    pub model: RgbaImage,
    /// The exploded view with the finished model beside it.
    pub exploded: RgbaImage,
}

/// Instruction images are 800 x 600.
fn options() -> RenderOptions {
    RenderOptions::default()
}

/// Renders what the outputs need: step images only when `steps`, their
/// count reported to `progress` as they are drawn.
pub fn render_all(
    p: &Pictures<'_>,
    steps: bool,
    progress: &dyn super::Progress,
) -> Result<Rendered, RenderError> {
    let opts = options();
    let renderer = render::renderer(p.assembly, &opts)?;
    // The exploded view is drawn beside the step images; the finished
    // model is composed from the buffer the last step leaves, when that
    // step is seen as the model is.
    let exploded = || exploded_alone(p.assembly);
    let ((step_images, finished), exploded) = if steps {
        let total = p.assembly.step_count() as u64;
        // The images are drawn on worker threads; each finished one is
        // counted here, on the caller's thread.
        let (tx, rx) = std::sync::mpsc::channel::<()>();
        std::thread::scope(|s| {
            let worker = s.spawn(|| rayon::join(|| step_images(&renderer, tx), exploded));
            let mut done = 0;
            for () in rx {
                done += 1;
                progress.advance(done, total);
            }
            worker
                .join()
                .unwrap_or_else(|e| std::panic::resume_unwind(e))
        })
    } else {
        ((Vec::new(), None), exploded())
    };
    let model = renderer.model_image_from(finished);
    let exploded = exploded_view(&model, &exploded?);
    // A camera's scale is pixels an LDU; a stud is 20 LDU across.
    let step_scales = (0..step_images.len())
        .map(|n| renderer.step_camera(n).scale() * 20.0)
        .collect();
    Ok(Rendered {
        steps: step_images,
        step_scales,
        model,
        exploded,
    })
}

/// Every step image, drawn incrementally in as many runs as threads; a
/// message on `drawn` for each. With them, the buffer the last step
/// leaves (see [`StepImages::into_finished`](render::StepImages)).
fn step_images(
    renderer: &StepRenderer,
    drawn: std::sync::mpsc::Sender<()>,
) -> (Vec<RgbaImage>, Option<render::Finished>) {
    let runs: Vec<(Vec<RgbaImage>, Option<render::Finished>)> = renderer
        .runs()
        .into_par_iter()
        .map(|r| {
            let mut images = renderer.images_in(r);
            let drawn: Vec<RgbaImage> = images
                .by_ref()
                .map(|(_, img)| {
                    let _ = drawn.send(());
                    img
                })
                .collect();
            (drawn, images.into_finished())
        })
        .collect();
    let mut finished = None;
    let mut all = Vec::new();
    for (images, last) in runs {
        all.extend(images);
        finished = finished.or(last);
    }
    (all, finished)
}

/// The exploded view alone: the pieces pulled apart course by course (see
/// [`explode`]).
fn exploded_alone(assembly: &Assembly) -> Result<RgbaImage, RenderError> {
    let offsets = explode(assembly, &ExplodeOptions::default());
    let mut scene = Scene::new();
    for (p, off) in assembly.pieces.iter().zip(&offsets) {
        let mut at = piece_transform(&p.placement, assembly.layer_ldu);
        at.translation += glam::Vec3A::from(*off);
        scene.add_part(p.placement.part, at, p.color, p.step);
    }
    // Only the finished picture is drawn: no step framing (zoom) to work
    // out, as it never changes that picture.
    Ok(StepRenderer::new(scene, &options().with_zoom(false))?.model_image())
}

/// The exploded view (see [`exploded_alone`]) with the finished model
/// above it, a third of its size (portrait, as a booklet page is).
fn exploded_view(model: &RgbaImage, exploded: &RgbaImage) -> RgbaImage {
    let opts = options();
    let (w, h) = (opts.width, opts.height);
    let small = image::imageops::resize(model, w / 3, h / 3, image::imageops::FilterType::Triangle);
    let mut out = RgbaImage::from_pixel(w, h + h / 3, image::Rgba([255, 255, 255, 255]));
    image::imageops::overlay(&mut out, &small, i64::from(w - w / 3), 0);
    image::imageops::overlay(&mut out, exploded, 0, i64::from(h / 3));
    out
}

/// PNG bytes of every image, encoded in parallel.
pub fn encode_all(images: &[RgbaImage]) -> Vec<Vec<u8>> {
    images
        .par_iter()
        .map(|img| {
            let mut buf = Vec::new();
            write_png(img, false, &mut buf).expect("encoding into memory does not fail");
            buf
        })
        .collect()
}

/// PNG bytes of one image.
pub fn encode(img: &RgbaImage) -> Vec<u8> {
    let mut buf = Vec::new();
    write_png(img, false, &mut buf).expect("encoding into memory does not fail");
    buf
}

/// The step image files, `DIR/steps/step-001.png`..., at least three digits.
pub fn step_paths(dir: &Path, steps: usize) -> Vec<PathBuf> {
    let digits = steps.to_string().len().max(3);
    (1..=steps)
        .map(|s| dir.join(format!("step-{s:0digits$}.png")))
        .collect()
}

/// Removes `step-NNN.png` files of an earlier, longer run from `dir`, so
/// the directory holds exactly this build's steps. Best effort: a file
/// that cannot be removed stays. A `dir` that is a symbolic link is left
/// alone: nothing outside the output folder is deleted.
pub fn remove_stale_steps(dir: &Path, steps: usize) {
    if crate::fsutil::refuse_link(dir).is_err() {
        return;
    }
    let keep: std::collections::BTreeSet<PathBuf> = step_paths(dir, steps).into_iter().collect();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let path = e.path();
        let name = e.file_name();
        let name = name.to_string_lossy();
        let is_step = name.starts_with("step-")
            && name.ends_with(".png")
            && name[5..name.len() - 4].chars().all(|c| c.is_ascii_digit());
        if is_step && !keep.contains(&path) {
            let _ = std::fs::remove_file(&path);
        }
    }
}

/// Pictures of every part in every colour the build uses, on a
/// transparent background (the booklet puts them on white and on its
/// callout colour), in parallel.
fn part_images(assembly: &Assembly) -> Result<BTreeMap<(PartKind, Color), RgbaImage>, RenderError> {
    let opts = RenderOptions::part_default().with_background(Background::Transparent);
    let mut keys: Vec<(PartKind, Color)> = assembly
        .pieces
        .iter()
        .map(|p| (p.placement.part, p.color))
        .collect();
    keys.sort_unstable();
    keys.dedup();
    keys.into_par_iter()
        .map(|(part, color)| Ok(((part, color), render::part_image_with(part, color, &opts)?)))
        .collect()
}

/// A laid-out booklet.
pub struct Booklet {
    /// The PDF's bytes.
    pub pdf: Vec<u8>,
    /// Its number of pages.
    pub pages: usize,
}

/// The booklet PDF.
pub fn booklet(p: &Pictures<'_>, r: &Rendered, template: &Template) -> std::io::Result<Booklet> {
    let parts = part_images(p.assembly).map_err(std::io::Error::other)?;
    let input = BookletInput {
        title: p.title,
        assembly: p.assembly,
        size_studs: p.size_studs,
        size_cm: p.size_cm,
        model: &r.model,
        exploded: &r.exploded,
        steps: &r.steps,
        step_scales: &r.step_scales,
        parts: &parts,
        step_notes: &p.step_notes,
    };
    let mut pdf = Vec::new();
    let pages = write_booklet(&mut pdf, &input, template)?;
    Ok(Booklet { pdf, pages })
}

/// The finished model with each piece coloured by the share of its clutch
/// capacity used: green none, yellow half, red all (or falls). It is seen
/// from the quarter turn of the default view that shows the most of the
/// weakest pieces (see [`stress_turns`]). Pieces past the analysis (of
/// the steps a check cut short by its budget reached) are grey.
pub fn stress_image(
    assembly: &Assembly,
    analysis: &crate::physics::Analysis,
) -> Result<RgbaImage, RenderError> {
    let colors: Vec<_> = analysis
        .pieces
        .iter()
        .map(|p| render::stress_color(if p.falls { f64::INFINITY } else { p.usage }))
        .chain(std::iter::repeat(render::stress_color(f64::NAN)))
        .take(assembly.pieces.len())
        .collect();
    let view = render::View::default().turned(stress_turns(assembly, analysis)?);
    let mut img = render::model_image_with_colors(assembly, &colors, &options().with_view(view))?;
    render::draw_stress_legend(&mut img);
    Ok(img)
}

/// Pieces that count as the weakest, for choosing the stress picture's
/// view: those that fail, and those using at least this share of the
/// highest usage.
const WEAK_SHARE: f64 = 0.5;

/// Below this highest usage nothing is weak enough to turn the view for.
const WEAK_MIN: f64 = 0.05;

/// The quarter turns (0 to 3) of the default view that show the most of
/// the model's weakest pieces (see `weak_pixels`); the default view
/// keeps ties, and a model with no weak piece.
pub fn stress_turns(
    assembly: &Assembly,
    analysis: &crate::physics::Analysis,
) -> Result<u8, RenderError> {
    let Some(counts) = weak_pixels(assembly, analysis)? else {
        return Ok(0);
    };
    let best = (0..4)
        .max_by_key(|&k| (counts[k], std::cmp::Reverse(k)))
        .unwrap_or(0);
    Ok(best as u8)
}

/// How many pixels of the weakest pieces each quarter turn of the default
/// view shows: each view drawn small, the weakest pieces in one colour and
/// the rest in another. `None` when no piece is weak.
fn weak_pixels(
    assembly: &Assembly,
    analysis: &crate::physics::Analysis,
) -> Result<Option<[usize; 4]>, RenderError> {
    let top = analysis.max_usage;
    let weak: Vec<bool> = analysis
        .pieces
        .iter()
        .map(|p| p.fails() || (top >= WEAK_MIN && p.usage >= WEAK_SHARE * top))
        .chain(std::iter::repeat(false))
        .take(assembly.pieces.len())
        .collect();
    if !weak.contains(&true) {
        return Ok(None);
    }
    const MARK: image::Rgb<u8> = image::Rgb([255, 0, 255]);
    let colors: Vec<_> = weak
        .iter()
        .map(|&w| if w { MARK } else { image::Rgb([255, 255, 255]) })
        .collect();
    let counts: Vec<usize> = (0..4u8)
        .into_par_iter()
        .map(|k| {
            let opts = options()
                .with_size(320, 240)
                .with_view(render::View::default().turned(k));
            render::model_image_with_colors(assembly, &colors, &opts).map(|img| {
                // The mark's hue, whatever its shading.
                img.pixels()
                    .filter(|p| p[0] > p[1].saturating_add(60) && p[2] > p[1].saturating_add(60))
                    .count()
            })
        })
        .collect::<Result<_, _>>()?;
    Ok(Some([counts[0], counts[1], counts[2], counts[3]]))
}

impl<'a> Pictures<'a> {
    /// The pictures of a settled build named `title`.
    pub(super) fn of(
        settled: &'a super::stability::Settled,
        title: &'a str,
        layer_ldu: i32,
    ) -> Self {
        let (nx, ny, nz) = settled.outcome.voxels.dims();
        Pictures {
            assembly: &settled.assembly,
            title,
            size_studs: [
                f64::from(nx),
                f64::from(ny),
                f64::from(nz * layer_ldu) / 24.0,
            ],
            size_cm: size_cm(settled.outcome.voxels.dims(), layer_ldu),
            step_notes: settled.step_notes(),
        }
    }
}

/// The size of a model of `nx` by `ny` studs and `nz` layers of
/// `layer_ldu`, in centimetres (x, y, height).
pub(super) fn size_cm((nx, ny, nz): (i32, i32, i32), layer_ldu: i32) -> [f64; 3] {
    [
        f64::from(nx) * 0.8,
        f64::from(ny) * 0.8,
        (f64::from(nz * layer_ldu) * 0.04 * 100.0).round() / 100.0,
    ]
}

/// Whether any of `formats` is a picture (step images and the booklet need
/// the steps drawn; the model and exploded views do not).
pub(super) fn wanted(formats: &super::Formats) -> Option<bool> {
    use super::Format;
    let steps = formats.contains(Format::Steps) || formats.contains(Format::Pdf);
    (steps || formats.contains(Format::Png) || formats.contains(Format::ExplodedPng))
        .then_some(steps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::{Placed, Placement, Step};
    use crate::geom::{Cell, Rot};
    use crate::physics::{analyze, Params};

    fn piece(id: &str, x: i32, y: i32, z: i32, rot: Rot) -> Placed {
        Placed {
            placement: Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, y, z), rot),
            step: Step(1),
            color: Color::RED,
        }
    }

    /// A cantilever (a 2 x 8 arm on a 2 x 2 column, which tips it: the
    /// only failing pieces) in the middle of a 20 x 20 stud yard, and a
    /// wall twelve bricks high along one side of the yard: `side` 0 to 3.
    fn yard(side: u8) -> Assembly {
        let mut pieces = Vec::new();
        for z in 0..4 {
            pieces.push(piece("3003", 7, 7, z, Rot::R0));
        }
        pieces.push(piece("3007", 7, 7, 4, Rot::R0));
        for z in 0..12 {
            for k in 0..5 {
                let (x, y, rot) = match side {
                    0 => (k * 4, 0, Rot::R0),
                    1 => (k * 4, 19, Rot::R0),
                    2 => (0, k * 4, Rot::R90),
                    _ => (19, k * 4, Rot::R90),
                };
                pieces.push(piece("3010", x, y, z, rot));
            }
        }
        Assembly {
            pieces,
            layer_ldu: 24,
        }
    }

    #[test]
    fn the_stress_picture_turns_to_show_the_weakest_pieces() {
        let params = Params::default();
        let mut turns = Vec::new();
        for side in 0..4 {
            let asm = yard(side);
            let a = analyze(&asm, &params).unwrap();
            // The arm tips its column; the walls stand.
            assert!(a.pieces[..5].iter().any(|p| p.fails()), "{a:?}");
            assert!(a.pieces[5..].iter().all(|p| !p.fails()), "{a:?}");
            turns.push(stress_turns(&asm, &a).unwrap());
        }
        // The view goes round the wall: it does not stay put.
        let mut distinct = turns.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert!(distinct.len() >= 2, "{turns:?}");
        // Where the wall hides the arm from the default view, the chosen
        // view shows it plainly.
        let mut hidden = 0;
        for side in 0..4 {
            let asm = yard(side);
            let a = analyze(&asm, &params).unwrap();
            let counts = weak_pixels(&asm, &a).unwrap().unwrap();
            let chosen = counts[turns[side as usize] as usize];
            assert!(chosen > 300, "{counts:?}");
            if counts[0] * 3 < chosen {
                hidden += 1;
                assert_ne!(turns[side as usize], 0);
            }
        }
        assert!(
            hidden >= 1,
            "the wall hid the arm from the default view somewhere"
        );
        // A model with nothing weak keeps the default view.
        let calm = Assembly {
            pieces: vec![piece("3001", 0, 0, 0, Rot::R0)],
            layer_ldu: 24,
        };
        let a = analyze(&calm, &params).unwrap();
        assert_eq!(stress_turns(&calm, &a).unwrap(), 0);
    }
}
