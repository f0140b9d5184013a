//! Instruction images: a small software renderer for LEGO building steps.
//!
//! Printed instructions have a look of their own: a fixed three-quarter
//! view from above, flat colours with light tops and two side shades, dark
//! outlines around every piece, and the pieces a step adds standing out
//! from the ones already built. This module draws exactly that, with no
//! GPU and no heavy dependency, deterministically: the same input gives the
//! same PNG bytes.
//!
//! # How a picture is made
//!
//! 1. **Scene.** Every piece becomes triangles in LDraw world coordinates
//!    (LDU, -Y up), each piece with its colour and step ([`Scene`]).
//! 2. **Camera.** An orthographic [`Camera`] is fitted to the finished
//!    model ([`View`] sets azimuth, elevation and quarter turns). Step
//!    images are framed to the model as built so far: runs of steps share
//!    one camera, fitted to what is built by the run's end, and the scale
//!    changes rarely, a quarter or more at a time
//!    ([`RenderOptions::zoom`]). A step whose
//!    new pieces that view hides is seen from it turned by quarter turns
//!    about the vertical axis, at the same scale, and its image shows a
//!    "turn the model" arrow ([`Turning`]; the view stays put over runs
//!    of steps).
//! 3. **Raster.** Triangles facing the viewer are filled at 2 x 2 (by
//!    default) samples a pixel into a depth buffer that keeps, per sample,
//!    the nearest piece and its face: visibility is exact whatever order
//!    pieces are drawn in.
//! 4. **Compose.** Samples get the piece colour times the face's shade (a
//!    light fixed to the camera: tops light, left sides mid, right sides
//!    dark), faded toward white for earlier steps; samples where the piece,
//!    the face direction or the depth changes sharply get the line colour.
//!    Averaging each block of samples gives anti-aliased pixels.
//!
//! For a sequence of steps the sample buffers are kept and only the new
//! pieces drawn, and only the pixels near changed pieces composed again
//! (see [`StepImages`]); [`StepRenderer::write_steps`] renders runs of
//! steps in parallel.
//!
//! # Examples
//!
//! From an [`Assembly`], the usual way in: pieces get their part meshes
//! from [`crate::export::partmesh`], placed exactly as the `.ldr` places
//! them.
//!
//! ```
//! use brickwright::assembly::{Assembly, Placement};
//! use brickwright::catalog::{Color, PartKind};
//! use brickwright::geom::{Cell, Rot};
//! use brickwright::render::{self, RenderOptions};
//!
//! let brick = PartKind::from_id("3001").unwrap();
//! let order = [
//!     Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
//!     Placement::new(brick, Cell::new(1, 0, 1), Rot::R90),
//! ];
//! let asm = Assembly::from_order(&order, 24, Color::RED);
//! let opts = RenderOptions::default().with_size(200, 150);
//!
//! let model = render::model_image(&asm, &opts).unwrap();
//! assert_eq!(model.dimensions(), (200, 150));
//! let steps: Vec<_> = render::steps(&asm, &opts).unwrap().collect();
//! assert_eq!(steps.len(), 2);
//! let dir = tempfile::tempdir().unwrap();
//! let files = render::write_steps(&asm, &opts, dir.path()).unwrap();
//! assert!(files[1].ends_with("step-002.png"));
//! let thumb = render::part_image(brick, Color::RED);
//! assert_eq!(thumb.dimensions(), (128, 128));
//! ```
//!
//! Any geometry, through a [`Scene`]: a red box added in step 1 and a grey
//! one on top in step 2.
//!
//! ```
//! use brickwright::assembly::Step;
//! use brickwright::render::{RenderOptions, Scene, StepRenderer, Triangle};
//! use glam::Vec3;
//! use image::Rgb;
//!
//! // A box as 12 triangles wound counter-clockwise seen from outside.
//! fn cuboid(lo: Vec3, hi: Vec3) -> Vec<Triangle> {
//!     let v = |i: usize| Vec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), hi, lo);
//!     let quads = [[1, 3, 7, 5], [0, 4, 6, 2], [2, 6, 7, 3], [0, 1, 5, 4], [4, 5, 7, 6], [0, 2, 3, 1]];
//!     quads
//!         .iter()
//!         .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
//!         .map(|t| Triangle::from_winding(t.map(v)))
//!         .collect()
//! }
//!
//! let mut scene = Scene::new();
//! scene.add_piece(Rgb([201, 26, 9]), Step(1), cuboid(Vec3::new(0.0, -24.0, 0.0), Vec3::new(80.0, 0.0, 40.0)));
//! scene.add_piece(Rgb([160, 165, 169]), Step(2), cuboid(Vec3::new(0.0, -48.0, 0.0), Vec3::new(40.0, -24.0, 40.0)));
//!
//! let opts = RenderOptions::default().with_size(160, 120);
//! let renderer = StepRenderer::new(scene, &opts).unwrap();
//! let images: Vec<_> = renderer.images().collect();
//! assert_eq!(images.len(), 2);
//! assert_eq!(images[1].1.dimensions(), (160, 120));
//! // The corner is background; the middle of the image is not.
//! assert_eq!(images[1].1.get_pixel(0, 0).0, [255, 255, 255, 255]);
//! assert_ne!(images[1].1.get_pixel(80, 60).0, [255, 255, 255, 255]);
//! ```

mod camera;
mod compose;
mod marks;
mod raster;
mod scene;
mod steps;
mod stress;
mod turn;
mod zoom;

use std::path::{Path, PathBuf};

use glam::Affine3A;
use image::{Rgb, RgbaImage};
use thiserror::Error;

use crate::assembly::{Assembly, Step};
use crate::catalog::{Color, PartKind};

pub use camera::{Camera, View};
pub use raster::PixelRect;
pub use scene::{Scene, ScenePiece, Triangle};
pub(crate) use steps::Finished;
pub use steps::{write_png, StepImages, StepRenderer};
pub use stress::{draw_stress_legend, stress_color};
pub use turn::Turning;

use compose::Style;

/// Largest image side, in pixels.
pub const MAX_SIZE: u32 = 8192;

/// Most samples (pixels times supersamples) an image may take: its
/// buffers hold 12 bytes a sample.
pub const MAX_SAMPLES: u64 = 64 << 20;

/// Side in pixels of [`part_image`]'s square pictures.
pub const PART_IMAGE_SIZE: u32 = 128;

/// A step renderer for `assembly`, its base camera fitted to the finished
/// model, its step images framed as [`StepRenderer::new`] says.
pub fn renderer(assembly: &Assembly, opts: &RenderOptions) -> Result<StepRenderer, RenderError> {
    StepRenderer::new(Scene::from_assembly(assembly), opts)
}

/// The step images of `assembly`, in order, each `(step, image)`.
///
/// Step `k` shows the pieces of steps `1..=k`, those of step `k`
/// highlighted (see [`Highlight`]). An empty assembly gives no images.
pub fn steps(
    assembly: &Assembly,
    opts: &RenderOptions,
) -> Result<StepImages<'static>, RenderError> {
    Ok(renderer(assembly, opts)?.into_images())
}

/// Writes the step images of `assembly` into `dir` (created if missing) as
/// `step-001.png`, `step-002.png`, ..., each atomically, in parallel, and
/// returns their paths in step order.
pub fn write_steps(
    assembly: &Assembly,
    opts: &RenderOptions,
    dir: &Path,
) -> Result<Vec<PathBuf>, RenderError> {
    renderer(assembly, opts)?.write_steps(dir)
}

/// The finished model, every piece plain. An empty assembly gives a blank
/// image.
pub fn model_image(assembly: &Assembly, opts: &RenderOptions) -> Result<RgbaImage, RenderError> {
    // Framing the steps (zoom) never changes the finished model's view.
    Ok(renderer(assembly, &opts.with_zoom(false))?.model_image())
}

/// The finished model with piece `i` of `assembly.pieces` in `colors[i]`
/// instead of its own colour (shaded like any colour), as
/// [`model_image`] draws it: for pictures that colour pieces by a
/// measure, such as a stress picture with [`stress_color`].
///
/// Fails with [`RenderError::Colors`] unless there is one colour a piece.
///
/// ```
/// use brickwright::assembly::{Assembly, Placement};
/// use brickwright::catalog::{Color, PartKind};
/// use brickwright::geom::{Cell, Rot};
/// use brickwright::render::{self, stress_color, RenderOptions};
///
/// let brick = PartKind::from_id("3001").unwrap();
/// let order = [
///     Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
///     Placement::new(brick, Cell::new(1, 0, 1), Rot::R90),
/// ];
/// let asm = Assembly::from_order(&order, 24, Color::RED);
/// let colors = [stress_color(0.1), stress_color(0.9)];
/// let opts = RenderOptions::default().with_size(200, 150);
/// let mut img = render::model_image_with_colors(&asm, &colors, &opts).unwrap();
/// render::draw_stress_legend(&mut img);
/// assert_eq!(img.dimensions(), (200, 150));
/// ```
pub fn model_image_with_colors(
    assembly: &Assembly,
    colors: &[Rgb<u8>],
    opts: &RenderOptions,
) -> Result<RgbaImage, RenderError> {
    let mut scene = Scene::from_assembly(assembly);
    scene.recolor(colors)?;
    Ok(StepRenderer::new(scene, &opts.with_zoom(false))?.model_image())
}

/// One part alone in `color`, [`PART_IMAGE_SIZE`] pixels square on white,
/// for parts lists. Every part is seen from the same view, scaled to fill
/// the picture.
pub fn part_image(part: PartKind, color: Color) -> RgbaImage {
    let opts = RenderOptions::part_default();
    let mut scene = Scene::new();
    scene.add_part(part, Affine3A::IDENTITY, color, Step(1));
    // The part defaults are in range, so this cannot fail; fall back to a
    // blank picture rather than panic if they ever were not.
    StepRenderer::new(scene, &opts).map_or_else(
        |_| RgbaImage::from_pixel(PART_IMAGE_SIZE, PART_IMAGE_SIZE, image::Rgba([255; 4])),
        |r| r.model_image(),
    )
}

/// [`part_image`] with other options (size, view, background).
pub fn part_image_with(
    part: PartKind,
    color: Color,
    opts: &RenderOptions,
) -> Result<RgbaImage, RenderError> {
    let mut scene = Scene::new();
    scene.add_part(part, Affine3A::IDENTITY, color, Step(1));
    Ok(StepRenderer::new(scene, opts)?.model_image())
}

/// What lies behind the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Background {
    /// Opaque white, as on a printed page (PNGs are written as RGB).
    White,
    /// Transparent (PNGs are written as RGBA).
    Transparent,
}

/// How the pieces a step adds are set apart from the earlier ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Highlight {
    /// New pieces in full colour with thick dark lines, earlier pieces
    /// faded (the default).
    Strong,
    /// Like [`Highlight::Strong`], the new pieces' lines in this colour.
    Accent(Rgb<u8>),
    /// No highlight and no fading: each step image is just the model so
    /// far.
    None,
}

/// Everything the renderer can be told. Build with `default()` and the
/// `with_*` setters; [`RenderOptions::validate`] says what is out of range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels, 1 to [`MAX_SIZE`]. Default 800.
    pub width: u32,
    /// Image height in pixels, 1 to [`MAX_SIZE`]. Default 600.
    pub height: u32,
    /// Where the viewer stands. Default: azimuth 45, elevation 30.
    pub view: View,
    /// Samples a pixel along each axis (anti-aliasing), 1 to 4. Default 2.
    pub supersample: u32,
    /// Free pixels around the fitted model. Default 12.
    pub margin: u32,
    /// Line width in pixels, 0.5 to 8 (lines of new pieces are drawn
    /// about 1.8 times as thick). Default 1.
    pub line_width: f32,
    /// How far earlier pieces are blended toward white, 0 (not at all)
    /// to 1 (white). Default 0.55.
    pub fade: f32,
    /// What lies behind the model. Default white.
    pub background: Background,
    /// How new pieces stand out. Default [`Highlight::Strong`].
    pub highlight: Highlight,
    /// Whether step images may turn away from `view` to show pieces it
    /// hides (`view` stays the base view, and the finished model is
    /// always seen from it). Default [`Turning::Auto`].
    pub turn: Turning,
    /// Whether each step's picture is framed to the model as built so far
    /// (zooming out in a few stages as it grows) rather than to the
    /// finished model. Default true.
    pub zoom: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 800,
            height: 600,
            view: View::default(),
            supersample: 2,
            margin: 12,
            line_width: 1.0,
            fade: 0.55,
            background: Background::White,
            highlight: Highlight::Strong,
            turn: Turning::Auto,
            zoom: true,
        }
    }
}

impl RenderOptions {
    /// The options of [`part_image`]: [`PART_IMAGE_SIZE`] square, 3 x 3
    /// samples a pixel, a small margin, no turning.
    pub fn part_default() -> Self {
        RenderOptions {
            width: PART_IMAGE_SIZE,
            height: PART_IMAGE_SIZE,
            supersample: 3,
            margin: 6,
            turn: Turning::Off,
            ..RenderOptions::default()
        }
    }

    /// With this image size in pixels.
    pub fn with_size(self, width: u32, height: u32) -> Self {
        RenderOptions {
            width,
            height,
            ..self
        }
    }

    /// With this view.
    pub fn with_view(self, view: View) -> Self {
        RenderOptions { view, ..self }
    }

    /// With `n` x `n` samples a pixel.
    pub fn with_supersample(self, n: u32) -> Self {
        RenderOptions {
            supersample: n,
            ..self
        }
    }

    /// With this margin in pixels.
    pub fn with_margin(self, margin: u32) -> Self {
        RenderOptions { margin, ..self }
    }

    /// With this line width in pixels.
    pub fn with_line_width(self, line_width: f32) -> Self {
        RenderOptions { line_width, ..self }
    }

    /// With this fade of earlier pieces.
    pub fn with_fade(self, fade: f32) -> Self {
        RenderOptions { fade, ..self }
    }

    /// With this background.
    pub fn with_background(self, background: Background) -> Self {
        RenderOptions { background, ..self }
    }

    /// With this highlight of new pieces.
    pub fn with_highlight(self, highlight: Highlight) -> Self {
        RenderOptions { highlight, ..self }
    }

    /// With this choice of turning the view.
    pub fn with_turn(self, turn: Turning) -> Self {
        RenderOptions { turn, ..self }
    }

    /// With or without framing each step to the model built so far.
    pub fn with_zoom(self, zoom: bool) -> Self {
        RenderOptions { zoom, ..self }
    }

    /// Checks every option's range.
    pub fn validate(&self) -> Result<(), RenderError> {
        if !(1..=MAX_SIZE).contains(&self.width) || !(1..=MAX_SIZE).contains(&self.height) {
            return Err(RenderError::Size {
                width: self.width,
                height: self.height,
            });
        }
        let bad = |name, value: String, expected| {
            Err(RenderError::Option {
                name,
                value,
                expected,
            })
        };
        if !(1..=4).contains(&self.supersample) {
            return bad("supersample", self.supersample.to_string(), "1 to 4");
        }
        let samples = u64::from(self.width)
            * u64::from(self.height)
            * u64::from(self.supersample * self.supersample);
        if samples > MAX_SAMPLES {
            return bad(
                "size x supersample",
                format!(
                    "{} x {} pixels at {} x {} samples",
                    self.width, self.height, self.supersample, self.supersample
                ),
                "at most 64 Mi samples (about 4096 x 4096 pixels at 2 x 2)",
            );
        }
        if !(0.5..=8.0).contains(&self.line_width) {
            return bad("line width", self.line_width.to_string(), "0.5 to 8 pixels");
        }
        if !(0.0..=1.0).contains(&self.fade) {
            return bad("fade", self.fade.to_string(), "0 to 1");
        }
        if !self.view.azimuth_deg.is_finite() || !self.view.elevation_deg.is_finite() {
            return bad(
                "view",
                format!("{:?}", self.view),
                "finite azimuth and elevation in degrees",
            );
        }
        if self.margin.saturating_mul(2) >= self.width.min(self.height) {
            return bad(
                "margin",
                self.margin.to_string(),
                "less than half the image's smaller side",
            );
        }
        Ok(())
    }

    /// The compositor's settings for images through `camera`.
    pub(crate) fn style(&self, camera: &Camera) -> Style {
        let ss = self.supersample.max(1) as f32;
        let samples = |w: f32| ((w * ss - 2.0) / 2.0).round().max(0.0) as usize;
        let radius = samples(self.line_width);
        let radius_new = match self.highlight {
            Highlight::None => radius,
            _ => samples(self.line_width * 1.8).max(radius),
        };
        Style {
            fade: (self.fade.clamp(0.0, 1.0) * 256.0).round() as u16,
            radius,
            radius_new,
            depth_jump: 3.0 + 4.0 / (camera.scale() * ss),
            background: match self.background {
                Background::White => [255, 255, 255, 255],
                Background::Transparent => [255, 255, 255, 0],
            },
            new_line: compose::new_line(match self.highlight {
                Highlight::Accent(c) => Some(c),
                _ => None,
            }),
        }
    }
}

/// What can go wrong rendering.
#[derive(Debug, Error)]
pub enum RenderError {
    /// The image size is zero or too large.
    #[error(
        "image size {width} x {height} is out of range: each side must be 1 to {MAX_SIZE} pixels"
    )]
    Size {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// An option is out of range.
    #[error("render option {name} = {value} is out of range: expected {expected}")]
    Option {
        /// The option.
        name: &'static str,
        /// Its value.
        value: String,
        /// What it may be.
        expected: &'static str,
    },
    /// A picture coloured piece by piece was given the wrong number of
    /// colours.
    #[error(
        "{got} colours for {expected} pieces: give one colour a piece, in the assembly's order"
    )]
    Colors {
        /// Pieces in the model.
        expected: usize,
        /// Colours given.
        got: usize,
    },
    /// An image could not be written.
    #[error("{}: cannot write the image: {source}", path.display())]
    Write {
        /// The file or directory.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

#[cfg(test)]
mod tests;
