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
//! A step may be seen from the base view turned by quarter turns, to show
//! pieces the base view hides (see [`Turning`](super::Turning)); a step
//! whose view differs from the step before is drawn from scratch and gets
//! the "turn the model" badge.
//!
//! [`StepRenderer::write_steps`] cuts the steps into runs of one view, at
//! most one run's share of the steps per thread each, and renders the runs
//! in parallel with rayon, each run from its own buffers.

use std::borrow::Cow;
use std::io::{self, Write};
use std::ops::Range;
use std::path::{Path, PathBuf};

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ImageEncoder, RgbaImage};
use rayon::prelude::*;

use super::camera::Camera;
use super::compose::{class, compose, PieceLook, Style};
use super::marks::draw_turn;
use super::raster::{piece_rect, Light, PixelRect, Samples};
use super::scene::Scene;
use super::turn::{self, Turning};
use super::zoom;
use super::View;
use super::{Background, Highlight, RenderError, RenderOptions};
use crate::assembly::Step;
use crate::fsutil::write_atomic;

/// One way of seeing the scene: a camera and what depends on it.
#[derive(Debug, Clone)]
struct Eye {
    camera: Camera,
    light: Light,
    /// Screen box of every piece.
    rects: Vec<PixelRect>,
}

impl Eye {
    fn new(scene: &Scene, camera: Camera) -> Eye {
        Eye {
            light: Light::for_camera(&camera),
            rects: (0..scene.pieces().len())
                .into_par_iter()
                .map(|i| piece_rect(scene, i, &camera))
                .collect(),
            camera,
        }
    }
}

/// A scene with its fitted cameras, ready to draw any step.
#[derive(Debug, Clone)]
pub struct StepRenderer {
    scene: Scene,
    /// The base view fitted to the finished model (always first), then
    /// the other views the steps are seen through.
    eyes: Vec<Eye>,
    /// Each step's view: quarter turns from the base view.
    step_turns: Vec<u8>,
    /// Each step's eye, an index of `eyes`.
    step_eye: Vec<usize>,
    style: Style,
    supersample: u32,
    /// Piece indices ordered by step (stable).
    order: Vec<usize>,
    /// Each step and its pieces, as a range of `order`.
    steps: Vec<(Step, Range<usize>)>,
    /// Pixels around a changed box that composing may touch.
    reach: u32,
    /// Whether PNGs carry alpha.
    alpha: bool,
    /// How new pieces stand out.
    highlight: Highlight,
}

impl StepRenderer {
    /// A renderer for `scene`, its base camera fitted to the whole scene
    /// (the finished model's picture).
    ///
    /// With [`Turning::Auto`] (the default), the steps whose new pieces
    /// the view hides are seen from the base view turned (see
    /// [`Turning`]); the turned views share the base view's scale, so
    /// pieces keep their size when the view turns.
    ///
    /// With [`RenderOptions::zoom`] (the default), each step's picture is
    /// framed to the model as built so far, zooming out in a few stages as
    /// it grows (see the `zoom` module docs); otherwise every step is seen
    /// at the finished model's scale.
    pub fn new(scene: Scene, opts: &RenderOptions) -> Result<StepRenderer, RenderError> {
        opts.validate()?;
        let camera = Camera::fit(
            &opts.view,
            scene.points(),
            opts.width,
            opts.height,
            opts.margin,
        );
        let mut r = StepRenderer::with_camera(scene, camera, opts);
        if opts.turn == Turning::Auto && r.steps.len() > 1 {
            let cameras =
                turn::turned_cameras(&opts.view, &r.scene, opts.width, opts.height, opts.margin);
            let turns = turn::choose(&turn::shown(&r.scene, &r.order, &r.steps, &cameras));
            if turns.iter().any(|&t| t != 0) {
                r.style = opts.style(&cameras[0]);
                r.eyes = cameras.map(|c| Eye::new(&r.scene, c)).into();
                r.step_turns = turns;
            }
        }
        r.step_eye = r.step_turns.iter().map(|&t| usize::from(t)).collect();
        if opts.zoom && r.steps.len() > 1 {
            r.zoom(opts);
        }
        Ok(r)
    }

    /// Frames each step to the model built so far (see [`zoom`]).
    fn zoom(&mut self, opts: &RenderOptions) {
        let views: Vec<View> = if self.eyes.len() > 1 {
            (0..4).map(|k| opts.view.turned(k)).collect()
        } else {
            vec![opts.view]
        };
        let framing = zoom::frame(
            &self.scene,
            &self.order,
            &self.steps,
            &views,
            (opts.width, opts.height, opts.margin),
        );
        let mut made: Vec<((usize, u8), usize)> = Vec::new();
        for (j, (range, _)) in framing.stages.iter().enumerate() {
            for n in range.clone() {
                let t = self.step_turns[n];
                let key = (j, t);
                let idx = match made.iter().find(|(k, _)| *k == key) {
                    Some(&(_, idx)) => idx,
                    None => {
                        let cam = framing.cameras[j][usize::from(t).min(views.len() - 1)];
                        self.eyes.push(Eye::new(&self.scene, cam));
                        made.push((key, self.eyes.len() - 1));
                        self.eyes.len() - 1
                    }
                };
                self.step_eye[n] = idx;
            }
        }
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
        let ss = opts.supersample;
        let reach = (style.radius_new as u32 + 2).div_ceil(ss) + 1;
        StepRenderer {
            eyes: vec![Eye::new(&scene, camera)],
            step_turns: vec![0; steps.len()],
            step_eye: vec![0; steps.len()],
            scene,
            style,
            supersample: ss,
            order,
            steps,
            reach,
            alpha: opts.background == Background::Transparent,
            highlight: opts.highlight,
        }
    }

    /// The camera of the base view, fitted to the finished model: of the
    /// finished model's picture, and of every step neither turned nor
    /// zoomed.
    pub fn camera(&self) -> &Camera {
        &self.eyes[0].camera
    }

    /// Quarter turns (0 to 3) from the base view of step number `n`'s
    /// view (counted from 0 in [`StepRenderer::steps`]; 0 past the last
    /// step). A quarter turn walks the viewer around the model the way
    /// [`View::turned`](super::View::turned) does.
    pub fn step_turns(&self, n: usize) -> u8 {
        self.step_turns.get(n).copied().unwrap_or(0)
    }

    /// The camera of step number `n`'s image (the base camera past the
    /// last step).
    pub fn step_camera(&self, n: usize) -> &Camera {
        &self.eye(n).camera
    }

    /// Quarter turns (1 to 3) from the previous step's view to step number
    /// `n`'s (from the base view for the first step), or `None` when the
    /// view did not turn. A step that turned shows the "turn the model"
    /// badge in a corner of its image.
    pub fn turn_at(&self, n: usize) -> Option<u8> {
        let before = n.checked_sub(1).map_or(0, |m| self.step_turns(m));
        let turns = (self.step_turns(n) + 4 - before) % 4;
        (n < self.steps.len() && turns != 0).then_some(turns)
    }

    /// The eye (an index of `eyes`) of step number `n`; the base eye past
    /// the last step.
    fn step_eye(&self, n: usize) -> usize {
        self.step_eye.get(n).copied().unwrap_or(0)
    }

    /// The view of step number `n`.
    fn eye(&self, n: usize) -> &Eye {
        &self.eyes[self.step_eye(n).min(self.eyes.len() - 1)]
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
    /// from 0 in [`StepRenderer::steps`]) adds, in its own view; empty past
    /// the last step.
    pub fn step_rect(&self, n: usize) -> PixelRect {
        let rects = &self.eye(n).rects;
        self.steps.get(n).map_or(PixelRect::EMPTY, |(_, r)| {
            self.order[r.clone()]
                .iter()
                .fold(PixelRect::EMPTY, |acc, &i| acc.union(rects[i]))
        })
    }

    /// The pixel rectangles to compose again when step number `n` follows
    /// step `n - 1` in the same view: around each piece of both steps, or
    /// one box around them all when that is smaller.
    fn dirty_rects(&self, n: usize) -> Vec<PixelRect> {
        let eye = self.eye(n);
        let (w, h) = (eye.camera.width(), eye.camera.height());
        let area = |r: &PixelRect| u64::from(r.x1 - r.x0) * u64::from(r.y1 - r.y0);
        let rects: Vec<PixelRect> = [n.wrapping_sub(1), n]
            .into_iter()
            .filter_map(|m| self.steps.get(m))
            .flat_map(|(_, range)| self.order[range.clone()].iter())
            .map(|&i| eye.rects[i].grown(self.reach, w, h))
            .filter(|r| !r.is_empty())
            .collect();
        let union = rects.iter().fold(PixelRect::EMPTY, |a, &r| a.union(r));
        if rects.iter().map(area).sum::<u64>() > area(&union) {
            vec![union]
        } else {
            rects
        }
    }

    /// The screen box (pixels) of scene piece `i` in the base view.
    pub fn piece_rect(&self, i: usize) -> PixelRect {
        self.eyes[0]
            .rects
            .get(i)
            .copied()
            .unwrap_or(PixelRect::EMPTY)
    }

    fn blank(&self) -> RgbaImage {
        let camera = self.camera();
        RgbaImage::from_pixel(
            camera.width(),
            camera.height(),
            image::Rgba(self.style.background),
        )
    }

    fn samples(&self) -> Samples {
        let camera = self.camera();
        Samples::new(camera.width(), camera.height(), self.supersample)
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

    /// Draws the pieces of step number `n` seen through `eye`.
    fn draw_step(&self, samples: &mut Samples, n: usize, eye: &Eye) {
        self.draw_steps(samples, n..n + 1, eye);
    }

    /// Draws the pieces of step numbers `steps` seen through `eye`, in
    /// step order.
    fn draw_steps(&self, samples: &mut Samples, steps: Range<usize>, eye: &Eye) {
        let at = |n: usize| self.steps.get(n).map(|(_, r)| r.start);
        let (Some(from), to) = (at(steps.start), at(steps.end)) else {
            return;
        };
        let pieces = &self.order[from..to.unwrap_or(self.order.len())];
        samples.draw_pieces(&self.scene, pieces, &eye.camera, &eye.light);
    }

    /// The finished model, every piece plain (none faded or highlighted).
    pub fn model_image(&self) -> RgbaImage {
        self.model_image_from(None)
    }

    /// The finished model as [`model_image`](Self::model_image) draws it,
    /// from the buffer the step images left (see
    /// [`StepImages::into_finished`]) when it holds every step seen through
    /// the base camera: the last step's view is the finished model's
    /// unless it turned, and drawing the model again costs as much as
    /// every step image. The samples are the same as drawn afresh (the
    /// same camera, the same pieces in the same order), so the image is
    /// too.
    pub(crate) fn model_image_from(&self, finished: Option<Finished>) -> RgbaImage {
        let samples = match finished {
            Some(f) if f.camera == *self.camera() => f.samples,
            _ => {
                let mut samples = self.samples();
                self.draw_steps(&mut samples, 0..self.steps.len(), &self.eyes[0]);
                samples
            }
        };
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

    /// The steps cut into runs for drawing in parallel (each run
    /// incrementally, with [`images_in`](Self::images_in)): runs of one
    /// view, each at most a thread's share of the steps.
    pub fn runs(&self) -> Vec<Range<usize>> {
        let n = self.steps.len();
        let threads = rayon::current_num_threads().clamp(1, n.max(1));
        let per_run = n.div_ceil(threads).max(1);
        let mut runs = Vec::new();
        let mut start = 0;
        for end in 1..=n {
            if end == n || end - start == per_run || self.step_eye(end) != self.step_eye(end - 1) {
                runs.push(start..end);
                start = end;
            }
        }
        runs
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

/// Most sample buffers a [`StepImages`] keeps, one an eye: enough for the
/// four quarter turns of one zoom stage (about 23 MB each at 800 x 600
/// and 2 x 2 samples).
const KEPT_EYES: usize = 4;

/// Every step drawn through one camera: what [`StepImages`] leaves once
/// it has handed out the last step's image.
#[derive(Debug)]
pub(crate) struct Finished {
    camera: Camera,
    samples: Samples,
}

/// A sample buffer kept for an eye: everything up to a step drawn
/// through it.
#[derive(Debug)]
struct Kept {
    /// The eye, an index of the renderer's eyes.
    eye: usize,
    /// Steps numbered below this are drawn.
    drawn: usize,
    samples: Samples,
}

/// Step images in order, each `(step, image)`; see the module docs for how
/// they are drawn incrementally.
#[derive(Debug)]
pub struct StepImages<'a> {
    renderer: Cow<'a, StepRenderer>,
    /// Sample buffers of the eyes seen lately, the current one first:
    /// a view that turns back finds its buffer and draws only the steps
    /// since, rather than the whole model again.
    kept: Vec<Kept>,
    image: RgbaImage,
    next: usize,
    end: usize,
}

impl<'a> StepImages<'a> {
    fn new(renderer: Cow<'a, StepRenderer>, range: Range<usize>) -> StepImages<'a> {
        let end = range.end.min(renderer.steps.len());
        StepImages {
            image: RgbaImage::new(0, 0),
            kept: Vec::new(),
            next: range.start.min(end),
            end,
            renderer,
        }
    }

    /// Moves the buffer of eye `eye` to the front of `kept` with every
    /// step up to `n` drawn: the one kept, brought up to date, or a new
    /// one (the least recently used dropped past [`KEPT_EYES`]). Drawing
    /// goes in step order either way, so the samples are the same as
    /// drawn from scratch.
    fn bring_up(&mut self, eye: usize, n: usize) {
        let r = &*self.renderer;
        let mut kept = match self.kept.iter().position(|k| k.eye == eye) {
            Some(i) => self.kept.remove(i),
            None => {
                self.kept.truncate(KEPT_EYES - 1);
                Kept {
                    eye,
                    drawn: 0,
                    samples: r.samples(),
                }
            }
        };
        r.draw_steps(&mut kept.samples, kept.drawn..n + 1, r.eye(n));
        kept.drawn = n + 1;
        self.kept.insert(0, kept);
    }
}

impl StepImages<'_> {
    /// The buffer of the last step's view once the iterator has handed
    /// out the last step's image (it then holds every step); `None`
    /// before, or for a range that stops short of the last step.
    pub(crate) fn into_finished(mut self) -> Option<Finished> {
        let r = &*self.renderer;
        let last = r.steps.len();
        if self.next != last || self.kept.first().is_none_or(|k| k.drawn != last) {
            return None;
        }
        let kept = self.kept.swap_remove(0);
        Some(Finished {
            camera: self.renderer.eyes[kept.eye].camera,
            samples: kept.samples,
        })
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
        let eye = r.step_eye(n);
        match self.kept.first_mut() {
            Some(k) if k.eye == eye && k.drawn == n => {
                r.draw_step(&mut k.samples, n, r.eye(n));
                k.drawn = n + 1;
                for rect in r.dirty_rects(n) {
                    compose(&k.samples, &looks, &r.style, rect, &mut self.image);
                }
            }
            _ => {
                self.bring_up(eye, n);
                let r = &*self.renderer;
                self.image = r.blank();
                let (w, h) = (self.image.width(), self.image.height());
                let full = PixelRect {
                    x0: 0,
                    y0: 0,
                    x1: w,
                    y1: h,
                };
                compose(
                    &self.kept[0].samples,
                    &looks,
                    &r.style,
                    full,
                    &mut self.image,
                );
            }
        }
        let r = &*self.renderer;
        self.next += 1;
        // The badge goes on the image handed out only: the kept image is
        // composed on by the next step.
        let mut out = self.image.clone();
        if let Some(turned) = r.turn_at(n) {
            draw_turn(&mut out, turned, r.style.background, r.step_rect(n));
        }
        Some((r.steps[n].0, out))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.end - self.next;
        (left, Some(left))
    }
}

impl ExactSizeIterator for StepImages<'_> {}
