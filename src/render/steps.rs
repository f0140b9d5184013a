//! Step images: one picture per building step, drawn incrementally.
//!
//! Step `k` shows every piece of steps `1..=k`. The pieces of step `k` are
//! drawn in full colour with strong lines, the earlier ones faded toward
//! white. Rather than rasterize the whole model again for each step, the
//! [`StepImages`] iterator keeps the sample buffers of everything drawn so
//! far and adds only step `k`'s pieces; it then composes again only the
//! pixels that can have changed: the screen boxes of step `k`'s pieces
//! (they appear) and of step `k - 1`'s (they fade), grown by the line
//! width. The result is the same, byte for byte, as drawing step `k` from
//! scratch.
//!
//! [`StepRenderer::write_steps`] cuts the steps into runs, one per
//! thread, and renders the runs in parallel with rayon, each run from its
//! own buffers.

use std::borrow::Cow;
use std::io::{self, Write};
use std::ops::Range;
use std::path::{Path, PathBuf};

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ImageEncoder, RgbaImage};
use rayon::prelude::*;

use super::camera::Camera;
use super::compose::{class, compose, PieceLook, Style};
use super::raster::{piece_rect, Light, PixelRect, Samples};
use super::scene::Scene;
use super::{Background, Highlight, RenderError, RenderOptions};
use crate::assembly::Step;
use crate::fsutil::write_atomic;

/// A scene with its fitted camera, ready to draw any step.
#[derive(Debug, Clone)]
pub struct StepRenderer {
    scene: Scene,
    camera: Camera,
    light: Light,
    style: Style,
    supersample: u32,
    /// Piece indices ordered by step (stable).
    order: Vec<usize>,
    /// Each step and its pieces, as a range of `order`.
    steps: Vec<(Step, Range<usize>)>,
    /// Screen box of every piece.
    rects: Vec<PixelRect>,
    /// Pixels around a changed box that composing may touch.
    reach: u32,
    /// Whether PNGs carry alpha.
    alpha: bool,
    /// How new pieces stand out.
    highlight: Highlight,
}

impl StepRenderer {
    /// A renderer for `scene`, its camera fitted once to the whole scene.
    pub fn new(scene: Scene, opts: &RenderOptions) -> Result<StepRenderer, RenderError> {
        opts.validate()?;
        let camera = Camera::fit(
            &opts.view,
            scene.points(),
            opts.width,
            opts.height,
            opts.margin,
        );
        Ok(StepRenderer::with_camera(scene, camera, opts))
    }

    /// A renderer for `scene` seen through `camera` (whose size wins over
    /// the options'), for images that must line up with another scene's.
    /// `opts` must be valid ([`RenderOptions::validate`]).
    pub(crate) fn with_camera(scene: Scene, camera: Camera, opts: &RenderOptions) -> StepRenderer {
        let style = opts.style(&camera);
        let mut order: Vec<usize> = (0..scene.pieces().len()).collect();
        order.sort_by_key(|&i| scene.pieces()[i].step);
        let mut steps: Vec<(Step, Range<usize>)> = Vec::new();
        for (k, &i) in order.iter().enumerate() {
            let step = scene.pieces()[i].step;
            match steps.last_mut() {
                Some((s, r)) if *s == step => r.end = k + 1,
                _ => steps.push((step, k..k + 1)),
            }
        }
        let rects = (0..scene.pieces().len())
            .map(|i| piece_rect(&scene, i, &camera))
            .collect();
        let ss = opts.supersample;
        let reach = (style.radius_new as u32 + 2).div_ceil(ss) + 1;
        StepRenderer {
            light: Light::for_camera(&camera),
            scene,
            camera,
            style,
            supersample: ss,
            order,
            steps,
            rects,
            reach,
            alpha: opts.background == Background::Transparent,
            highlight: opts.highlight,
        }
    }

    /// The camera every image of this renderer shares.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The scene being drawn.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The building steps, in order (one image each).
    pub fn steps(&self) -> impl ExactSizeIterator<Item = Step> + '_ {
        self.steps.iter().map(|(s, _)| *s)
    }

    /// The screen box (pixels) of the pieces step number `n` (counted
    /// from 0 in [`StepRenderer::steps`]) adds; empty past the last step.
    pub fn step_rect(&self, n: usize) -> PixelRect {
        self.steps.get(n).map_or(PixelRect::EMPTY, |(_, r)| {
            self.order[r.clone()]
                .iter()
                .fold(PixelRect::EMPTY, |acc, &i| acc.union(self.rects[i]))
        })
    }

    /// The pixel rectangles to compose again when step number `n` follows
    /// step `n - 1`: around each piece of both steps, or one box around
    /// them all when that is smaller.
    fn dirty_rects(&self, n: usize) -> Vec<PixelRect> {
        let (w, h) = (self.camera.width(), self.camera.height());
        let area = |r: &PixelRect| u64::from(r.x1 - r.x0) * u64::from(r.y1 - r.y0);
        let rects: Vec<PixelRect> = [n.wrapping_sub(1), n]
            .into_iter()
            .filter_map(|m| self.steps.get(m))
            .flat_map(|(_, range)| self.order[range.clone()].iter())
            .map(|&i| self.rects[i].grown(self.reach, w, h))
            .filter(|r| !r.is_empty())
            .collect();
        let union = rects.iter().fold(PixelRect::EMPTY, |a, &r| a.union(r));
        if rects.iter().map(area).sum::<u64>() > area(&union) {
            vec![union]
        } else {
            rects
        }
    }

    /// The screen box (pixels) of scene piece `i`.
    pub fn piece_rect(&self, i: usize) -> PixelRect {
        self.rects.get(i).copied().unwrap_or(PixelRect::EMPTY)
    }

    fn blank(&self) -> RgbaImage {
        RgbaImage::from_pixel(
            self.camera.width(),
            self.camera.height(),
            image::Rgba(self.style.background),
        )
    }

    fn samples(&self) -> Samples {
        Samples::new(self.camera.width(), self.camera.height(), self.supersample)
    }

    /// The looks of every piece when step number `n` is shown.
    fn looks(&self, n: usize) -> Vec<PieceLook> {
        let current = match self.highlight {
            Highlight::None => None,
            _ => self.steps.get(n).map(|(s, _)| *s),
        };
        self.scene
            .pieces()
            .iter()
            .map(|p| PieceLook {
                rgb: p.color.0,
                class: match current {
                    Some(s) if p.step == s => class::NEW,
                    Some(_) => class::OLD,
                    None => class::PLAIN,
                },
            })
            .collect()
    }

    fn draw_step(&self, samples: &mut Samples, n: usize) {
        if let Some((_, r)) = self.steps.get(n) {
            for &i in &self.order[r.clone()] {
                samples.draw_piece(&self.scene, i, &self.camera, &self.light);
            }
        }
    }

    /// The finished model, every piece plain (none faded or highlighted).
    pub fn model_image(&self) -> RgbaImage {
        let mut samples = self.samples();
        for n in 0..self.steps.len() {
            self.draw_step(&mut samples, n);
        }
        let mut img = self.blank();
        let full = PixelRect {
            x0: 0,
            y0: 0,
            x1: img.width(),
            y1: img.height(),
        };
        compose(
            &samples,
            &self.looks(usize::MAX),
            &self.style,
            full,
            &mut img,
        );
        img
    }

    /// The image of step number `n` (counted from 0), drawn from scratch;
    /// `None` past the last step. [`StepRenderer::images`] is much faster
    /// for every step in turn.
    pub fn step_image(&self, n: usize) -> Option<RgbaImage> {
        self.images_in(n..n + 1).next().map(|(_, img)| img)
    }

    /// Every step image in order, drawn incrementally.
    pub fn images(&self) -> StepImages<'_> {
        self.images_in(0..self.steps.len())
    }

    /// Every step image in order, owning the renderer.
    pub fn into_images(self) -> StepImages<'static> {
        let end = self.steps.len();
        StepImages::new(Cow::Owned(self), 0..end)
    }

    /// The step images of steps numbered `range` (counted from 0).
    pub fn images_in(&self, range: Range<usize>) -> StepImages<'_> {
        StepImages::new(Cow::Borrowed(self), range)
    }

    /// The steps cut into one run a thread, for drawing runs in parallel
    /// (each run incrementally, with [`images_in`](Self::images_in)).
    pub fn runs(&self) -> Vec<Range<usize>> {
        let n = self.steps.len();
        let runs = rayon::current_num_threads().clamp(1, n.max(1));
        let per_run = n.div_ceil(runs).max(1);
        (0..n)
            .step_by(per_run)
            .map(|a| a..(a + per_run).min(n))
            .collect()
    }

    /// Writes `step-001.png`, `step-002.png`, ... (the step's number, at
    /// least three digits) into `dir`, created if missing, each file
    /// atomically, rendering in parallel. Returns the paths in step order.
    pub fn write_steps(&self, dir: &Path) -> Result<Vec<PathBuf>, RenderError> {
        std::fs::create_dir_all(dir).map_err(|source| RenderError::Write {
            path: dir.to_path_buf(),
            source,
        })?;
        let digits = self
            .steps
            .last()
            .map_or(1, |(s, _)| s.0.to_string().len())
            .max(3);
        let paths: Vec<PathBuf> = self
            .steps
            .iter()
            .map(|(s, _)| dir.join(format!("step-{:0digits$}.png", s.0)))
            .collect();
        self.runs().into_par_iter().try_for_each(|range| {
            for (k, (_, img)) in range.clone().zip(self.images_in(range)) {
                self.write_png_file(&img, &paths[k])?;
            }
            Ok::<(), RenderError>(())
        })?;
        Ok(paths)
    }

    /// Writes one image to `path` atomically as PNG.
    pub fn write_png_file(&self, img: &RgbaImage, path: &Path) -> Result<(), RenderError> {
        let alpha = self.alpha;
        write_atomic(path, |w| write_png(img, alpha, w)).map_err(|source| RenderError::Write {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// Encodes `img` as PNG into `w`: RGBA when `alpha`, else RGB (the alpha
/// channel dropped). Same image, same bytes.
pub fn write_png(img: &RgbaImage, alpha: bool, w: &mut dyn Write) -> io::Result<()> {
    let enc = PngEncoder::new_with_quality(w, CompressionType::Fast, FilterType::Adaptive);
    let (width, height) = img.dimensions();
    let res = if alpha {
        enc.write_image(img.as_raw(), width, height, image::ExtendedColorType::Rgba8)
    } else {
        let mut rgb = vec![0u8; img.as_raw().len() / 4 * 3];
        for (d, s) in rgb.chunks_exact_mut(3).zip(img.as_raw().chunks_exact(4)) {
            d.copy_from_slice(&s[..3]);
        }
        enc.write_image(&rgb, width, height, image::ExtendedColorType::Rgb8)
    };
    res.map_err(io::Error::other)
}

/// Step images in order, each `(step, image)`; see the module docs for how
/// they are drawn incrementally.
#[derive(Debug)]
pub struct StepImages<'a> {
    renderer: Cow<'a, StepRenderer>,
    samples: Option<Samples>,
    image: RgbaImage,
    next: usize,
    end: usize,
}

impl<'a> StepImages<'a> {
    fn new(renderer: Cow<'a, StepRenderer>, range: Range<usize>) -> StepImages<'a> {
        let end = range.end.min(renderer.steps.len());
        StepImages {
            image: RgbaImage::new(0, 0),
            samples: None,
            next: range.start.min(end),
            end,
            renderer,
        }
    }
}

impl Iterator for StepImages<'_> {
    type Item = (Step, RgbaImage);

    fn next(&mut self) -> Option<(Step, RgbaImage)> {
        if self.next >= self.end {
            return None;
        }
        let r = &*self.renderer;
        let n = self.next;
        let looks = r.looks(n);
        match &mut self.samples {
            Some(samples) => {
                r.draw_step(samples, n);
                for rect in r.dirty_rects(n) {
                    compose(samples, &looks, &r.style, rect, &mut self.image);
                }
            }
            None => {
                let mut samples = r.samples();
                for m in 0..=n {
                    r.draw_step(&mut samples, m);
                }
                self.image = r.blank();
                let (w, h) = (self.image.width(), self.image.height());
                let full = PixelRect {
                    x0: 0,
                    y0: 0,
                    x1: w,
                    y1: h,
                };
                compose(&samples, &looks, &r.style, full, &mut self.image);
                self.samples = Some(samples);
            }
        }
        self.next += 1;
        Some((r.steps[n].0, self.image.clone()))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.end - self.next;
        (left, Some(left))
    }
}

impl ExactSizeIterator for StepImages<'_> {}
