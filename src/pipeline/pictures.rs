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
}

/// Rendered images, ready to be written.
pub struct Rendered {
    /// One image a step, step 1 first (empty unless asked for).
    pub steps: Vec<RgbaImage>,
    /// The finished model.
    pub model: RgbaImage,
    /// The exploded view with the finished model beside it.
    pub exploded: RgbaImage,
}

/// Instruction images are 800 x 600.
fn options() -> RenderOptions {
    RenderOptions::default()
}

/// Renders what the outputs need: step images only when `steps`.
pub fn render_all(p: &Pictures<'_>, steps: bool) -> Result<Rendered, RenderError> {
    let opts = options();
    let renderer = render::renderer(p.assembly, &opts)?;
    let step_images = if steps {
        step_images(&renderer)
    } else {
        Vec::new()
    };
    let model = renderer.model_image();
    let exploded = exploded_view(p.assembly, &model)?;
    Ok(Rendered {
        steps: step_images,
        model,
        exploded,
    })
}

/// Every step image, drawn incrementally in as many runs as threads.
fn step_images(renderer: &StepRenderer) -> Vec<RgbaImage> {
    renderer
        .runs()
        .into_par_iter()
        .map(|r| {
            renderer
                .images_in(r)
                .map(|(_, img)| img)
                .collect::<Vec<_>>()
        })
        .collect::<Vec<_>>()
        .into_iter()
        .flatten()
        .collect()
}

/// The exploded view (pieces pulled apart course by course, see
/// [`explode`]) with the finished model above it, a third of its size
/// (portrait, as a booklet page is).
fn exploded_view(assembly: &Assembly, model: &RgbaImage) -> Result<RgbaImage, RenderError> {
    let offsets = explode(assembly, &ExplodeOptions::default());
    let mut scene = Scene::new();
    for (p, off) in assembly.pieces.iter().zip(&offsets) {
        let mut at = piece_transform(&p.placement, assembly.layer_ldu);
        at.translation += glam::Vec3A::from(*off);
        scene.add_part(p.placement.part, at, p.color, p.step);
    }
    let opts = options();
    let (w, h) = (opts.width, opts.height);
    let exploded = StepRenderer::new(scene, &opts)?.model_image();
    let small = image::imageops::resize(model, w / 3, h / 3, image::imageops::FilterType::Triangle);
    let mut out = RgbaImage::from_pixel(w, h + h / 3, image::Rgba([255, 255, 255, 255]));
    image::imageops::overlay(&mut out, &small, i64::from(w - w / 3), 0);
    image::imageops::overlay(&mut out, &exploded, 0, i64::from(h / 3));
    Ok(out)
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
/// that cannot be removed stays.
pub fn remove_stale_steps(dir: &Path, steps: usize) {
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

/// The booklet PDF's bytes.
pub fn booklet(p: &Pictures<'_>, r: &Rendered, template: &Template) -> std::io::Result<Vec<u8>> {
    let parts = part_images(p.assembly).map_err(std::io::Error::other)?;
    let input = BookletInput {
        title: p.title,
        assembly: p.assembly,
        size_studs: p.size_studs,
        size_cm: p.size_cm,
        model: &r.model,
        exploded: &r.exploded,
        steps: &r.steps,
        parts: &parts,
    };
    let mut pdf = Vec::new();
    write_booklet(&mut pdf, &input, template)?;
    Ok(pdf)
}

/// The finished model with each piece coloured by the share of its clutch
/// capacity used: green none, yellow half, red all (or falls).
pub fn stress_image(
    assembly: &Assembly,
    analysis: &crate::physics::Analysis,
) -> Result<RgbaImage, RenderError> {
    let colors: Vec<_> = analysis
        .pieces
        .iter()
        .map(|p| render::stress_color(if p.falls { f64::INFINITY } else { p.usage }))
        .collect();
    let mut img = render::model_image_with_colors(assembly, &colors, &options())?;
    render::draw_stress_legend(&mut img);
    Ok(img)
}
