//! Turning the view to show the side being built.
//!
//! Step images share the user's base view (by default three-quarters from
//! the front right, above). When a step adds pieces behind what is already
//! built (the back of a tall wall, the far side of a tower), the base view
//! shows little of them; printed instructions then turn the model and say
//! so with a curved arrow. Here the same is decided before any step image
//! is drawn:
//!
//! 1. **Four cameras, one scale.** The base view turned by 0, 1, 2 and 3
//!    quarter turns about the vertical axis, each fitted to the finished
//!    model, then all given the smallest of the four scales
//!    ([`turned_cameras`]): a piece is the same size in every view.
//! 2. **How well each view shows each step.** Every view draws the model
//!    step by step into a small probe depth buffer (320 pixels across, one
//!    sample a pixel), each piece as its bounding box. For each new piece,
//!    the samples it wins in the buffer are compared with the area of its
//!    box drawn alone: that is the share of the piece that can be seen. A piece counts as shown
//!    once [`PIECE_SHOWN`] of it is seen (the top of a brick among its
//!    neighbours is enough), and a step's score in a view is the mean over
//!    its pieces ([`shown`]).
//! 3. **Hysteresis** ([`choose`]). The view stays as it is while it
//!    shows [`KEEP`] of the step. Otherwise it turns to the view that
//!    shows at least [`GAIN`] more, preferring the one that also shows the
//!    next step well, and the base view among near equals. So the view
//!    stays put within a run of steps, a turned view is kept while it
//!    still shows the new pieces, and a model built where it can be seen
//!    never turns.
//!
//! Everything is computed in a fixed order from the scene alone, so the
//! choice, and the images, are the same on every run.

use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

use super::camera::{Camera, View};
use super::raster::{piece_rect, Light, Samples};
use super::scene::{cuboid, Scene};
use crate::assembly::Step;

/// Whether step images may turn away from the base view.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Turning {
    /// A step whose new pieces the current view hides is seen from the
    /// base view turned by the quarter turns that show them, marked with a
    /// "turn the model" arrow (the default).
    #[default]
    Auto,
    /// Every step is seen from the base view.
    Off,
}

/// Longer side of the probe images, in pixels.
const PROBE_SIDE: f32 = 320.0;
/// Share of a piece that must be seen for it to count as shown.
pub const PIECE_SHOWN: f32 = 0.4;
/// A view is kept while its score for the step is at least this.
pub const KEEP: f32 = 0.75;
/// How much higher another view must score for the view to turn to it.
pub const GAIN: f32 = 0.25;
/// Weight of the next step's score in choosing among better views.
const LOOKAHEAD: f32 = 0.5;
/// Head start of the base view in choosing among better views.
const HOME: f32 = 0.1;
/// Pieces covering fewer probe samples than this count as shown (too
/// small to judge).
const MIN_SAMPLES: f32 = 4.0;

/// The cameras of `view` turned by 0, 1, 2 and 3 quarter turns, each
/// fitted to `scene` in a `width` x `height` image with `margin` free
/// pixels, all at the smallest of their scales.
pub fn turned_cameras(
    view: &View,
    scene: &Scene,
    width: u32,
    height: u32,
    margin: u32,
) -> [Camera; 4] {
    let fits =
        [0, 1, 2, 3].map(|k| Camera::fit(&view.turned(k), scene.points(), width, height, margin));
    let scale = fits.iter().map(Camera::scale).fold(f32::INFINITY, f32::min);
    fits.map(|c| c.with_scale(scale))
}

/// How well each camera shows each step's new pieces: `shown[n][k]`, 0
/// (hidden) to 1 (every piece shown), for step number `n` and camera `k`.
/// `steps` are ranges of `order`, which lists scene pieces by step.
///
/// Each piece stands in as its bounding box: at the probe's size a stud
/// is a pixel or two, and a box is 12 triangles where a brick with its
/// studs is hundreds, with a projected area known exactly.
pub(crate) fn shown(
    scene: &Scene,
    order: &[usize],
    steps: &[(Step, Range<usize>)],
    cameras: &[Camera; 4],
) -> Vec<[f32; 4]> {
    let mut boxes = Scene::new();
    let mut sizes = Vec::with_capacity(scene.pieces().len());
    for (i, p) in scene.pieces().iter().enumerate() {
        let corners = scene.piece_triangles(i).iter().flat_map(|t| t.positions);
        let (lo, hi) = corners.fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), v| (lo.min(v), hi.max(v)),
        );
        if lo.cmple(hi).all() {
            boxes.add_piece(p.color, p.step, cuboid(lo, hi));
            sizes.push(hi - lo);
        } else {
            boxes.add_piece(p.color, p.step, []);
            sizes.push(Vec3::ZERO);
        }
    }
    let per_view: Vec<Vec<f32>> = cameras
        .par_iter()
        .map(|c| shown_in(&boxes, &sizes, order, steps, c))
        .collect();
    (0..steps.len())
        .map(|n| [0, 1, 2, 3].map(|k| per_view[k][n]))
        .collect()
}

/// [`shown`] for one camera, `boxes` holding each piece's bounding box
/// of size `sizes[i]`.
fn shown_in(
    boxes: &Scene,
    sizes: &[Vec3],
    order: &[usize],
    steps: &[(Step, Range<usize>)],
    camera: &Camera,
) -> Vec<f32> {
    let side = camera.width().max(camera.height()).max(1) as f32;
    let probe = camera.resized(PROBE_SIDE / side);
    let light = Light::for_camera(&probe);
    let eye = probe.toward_eye().abs();
    let mut samples = Samples::new(probe.width(), probe.height(), 1);
    let mut out = Vec::with_capacity(steps.len());
    for (_, range) in steps {
        let pieces = &order[range.clone()];
        for &i in pieces {
            samples.draw_piece(boxes, i, &probe, &light);
        }
        let score: f32 = pieces
            .iter()
            .map(|&i| {
                // The box's projected area: its faces facing the viewer.
                let d = sizes[i];
                let area = (d.y * d.z * eye.x + d.x * d.z * eye.y + d.x * d.y * eye.z)
                    * probe.scale()
                    * probe.scale();
                if area < MIN_SAMPLES {
                    return 1.0;
                }
                let seen: usize = samples
                    .rows(piece_rect(boxes, i, &probe))
                    .map(|r| samples.piece[r].iter().filter(|&&p| p == i as u32).count())
                    .sum();
                (seen as f32 / area / PIECE_SHOWN).min(1.0)
            })
            .sum();
        out.push(if pieces.is_empty() {
            1.0
        } else {
            score / pieces.len() as f32
        });
    }
    out
}

/// The quarter turns (0 to 3) from the base view of each step's view,
/// given how well each view shows each step (see [`shown`] and the
/// module docs).
pub(crate) fn choose(shown: &[[f32; 4]]) -> Vec<u8> {
    let mut current = 0;
    shown
        .iter()
        .enumerate()
        .map(|(n, f)| {
            if f[current] < KEEP {
                let next = shown.get(n + 1);
                let score = |k: usize| {
                    f[k] + next.map_or(0.0, |g| LOOKAHEAD * g[k]) + if k == 0 { HOME } else { 0.0 }
                };
                let mut best: Option<usize> = None;
                for k in 0..4 {
                    let better = f[k] >= f[current] + GAIN;
                    if k != current && better && best.is_none_or(|b| score(k) > score(b)) {
                        best = Some(k);
                    }
                }
                current = best.unwrap_or(current);
            }
            current as u8
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_view_stays_while_it_shows_the_step() {
        let f = [
            [1.0, 1.0, 1.0, 1.0],
            [0.8, 1.0, 1.0, 1.0],
            [0.76, 0.2, 0.2, 0.2],
        ];
        assert_eq!(choose(&f), [0, 0, 0]);
    }

    #[test]
    fn a_hidden_step_turns_to_the_view_that_shows_it_and_stays_there() {
        let f = [
            [1.0, 1.0, 1.0, 1.0],
            [0.1, 0.5, 1.0, 0.5],
            // Seen from both; the turned view is kept.
            [0.9, 0.9, 0.8, 0.9],
            // The turned view hides this one: back to the base view.
            [1.0, 0.7, 0.2, 0.7],
        ];
        assert_eq!(choose(&f), [0, 2, 2, 0]);
    }

    #[test]
    fn small_gains_and_hidden_everywhere_do_not_turn() {
        let f = [[0.6, 0.8, 0.8, 0.8], [0.1, 0.2, 0.2, 0.2]];
        assert_eq!(choose(&f), [0, 0]);
    }

    #[test]
    fn among_equals_the_base_view_and_then_the_next_step_decide() {
        // From a turned view that hides the step, home wins a tie.
        let f = [[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 1.0]];
        assert_eq!(choose(&f), [2, 0]);
        // The view that shows the next step too wins.
        let f = [[0.2, 1.0, 0.2, 1.0], [0.2, 0.3, 0.2, 1.0]];
        assert_eq!(choose(&f), [3, 3]);
    }
}
