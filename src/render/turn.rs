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
//!    ([`turned_cameras`]): a piece is the same size in every view. (The
//!    step images are then zoomed to the model built so far, each run of
//!    steps at one scale in all four views; how well a view shows a step
//!    does not depend on the zoom.)
//! 2. **How well each view shows each step.** Every view draws the model
//!    step by step into a small probe depth buffer (320 pixels across, one
//!    sample a pixel), each piece as its bounding box. For each new piece,
//!    the samples it wins in the buffer are compared with the area of its
//!    box drawn alone: that is the share of the piece that can be seen. A piece counts as shown
//!    once [`PIECE_SHOWN`] of it is seen (the top of a brick among its
//!    neighbours is enough), and a step's score in a view is the mean over
//!    its pieces ([`shown`]).
//! 3. **Hysteresis** ([`choose`]). The views of all steps are chosen
//!    together, at least cost: a step costs how far its score falls short
//!    of [`KEEP`], every change of view costs [`SWITCH`], and each step
//!    seen turned a little, [`AWAY`]. So a view
//!    turns only for steps it hides badly, stays put within a run of
//!    steps, a turned view is kept while it still shows the new pieces
//!    (rather than flipping back and forth), the one view that shows a
//!    run of steps on both sides is found when there is one, and a model
//!    built where it can be seen never turns.
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
/// A view shows a step well enough when its score for the step is at
/// least this; below, the step costs the shortfall (see [`choose`]).
pub const KEEP: f32 = 0.75;
/// The cost of changing the view, in steps the view hides: a view turns
/// for one hidden step and back only when that step is mostly hidden, and
/// stays turned as long as it shows the steps well enough.
pub const SWITCH: f32 = 0.45;
/// The extra cost of a step seen from a turned view: a turned view that
/// shows the steps is kept for a while, but not for the rest of the
/// book when the base view would do (it returns home once that saves
/// more than [`SWITCH`]).
pub const AWAY: f32 = 0.02;
/// Costs closer than this are equal.
const TIE: f32 = 1e-5;
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
    // The four fits side by side: each is the same whichever thread.
    let (a, b) = rayon::join(
        || [0, 1].map(|k| Camera::fit(&view.turned(k), scene.points(), width, height, margin)),
        || [2, 3].map(|k| Camera::fit(&view.turned(k), scene.points(), width, height, margin)),
    );
    let fits = [a[0], a[1], b[0], b[1]];
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
/// given how well each view shows each step (see [`shown`]): the choice
/// of least cost, where a step costs how far its view falls short of
/// [`KEEP`] (1 for a step it hides, 0 for one it shows), every change
/// of view costs [`SWITCH`], and a step seen from a turned view costs
/// [`AWAY`] more. Among equal choices a view changes as late as it can,
/// and the last step's view is the lowest turn. Found exactly by dynamic
/// programming over the steps, four views a step.
pub(crate) fn choose(shown: &[[f32; 4]]) -> Vec<u8> {
    let miss = |f: f32| (KEEP - f).max(0.0) / KEEP;
    // cost[k]: the least cost of the steps so far, ending in view k;
    // from[n][k]: the view of step n - 1 on that best path.
    let mut cost = [0.0, f32::INFINITY, f32::INFINITY, f32::INFINITY];
    let mut from: Vec<[u8; 4]> = Vec::with_capacity(shown.len());
    for f in shown {
        let mut next = [0.0; 4];
        let mut back = [0; 4];
        for k in 0..4 {
            let (mut best, mut at) = (f32::INFINITY, 0);
            for (u, &c) in cost.iter().enumerate() {
                let c = c + if u == k { 0.0 } else { SWITCH };
                if c < best - TIE || (c <= best + TIE && u != k) {
                    (best, at) = (c, u);
                }
            }
            next[k] = best + miss(f[k]) + if k == 0 { 0.0 } else { AWAY };
            back[k] = at as u8;
        }
        from.push(back);
        cost = next;
    }
    let mut k = (0..4).fold(0, |b, k| if cost[k] < cost[b] - TIE { k } else { b });
    let mut turns = vec![0; shown.len()];
    for n in (0..shown.len()).rev() {
        turns[n] = k as u8;
        k = usize::from(from[n][k]);
    }
    turns
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [f32; 4] = [1.0; 4];

    #[test]
    fn the_view_stays_while_it_shows_the_step() {
        let f = [ALL, [0.8, 1.0, 1.0, 1.0], [0.76, 0.2, 0.2, 0.2]];
        assert_eq!(choose(&f), [0, 0, 0]);
    }

    #[test]
    fn a_hidden_step_turns_and_the_turned_view_is_kept_while_it_shows() {
        let f = [ALL, [0.0, 0.3, 1.0, 0.3], ALL, ALL];
        assert_eq!(choose(&f), [0, 2, 2, 2]);
        // When the turned view hides a later step, back home as soon as
        // the base view shows the steps again.
        let f = [ALL, [0.0, 0.3, 1.0, 0.3], ALL, [1.0, 0.3, 0.0, 0.3]];
        assert_eq!(choose(&f), [0, 2, 0, 0]);
        // And after a long run that the base view would show as well.
        let mut f = vec![ALL, [0.0, 0.3, 1.0, 0.3]];
        f.extend([ALL; 40]);
        let turns = choose(&f);
        assert_eq!(turns[1], 2);
        assert_eq!(turns[2], 0);
    }

    #[test]
    fn small_shortfalls_and_steps_hidden_everywhere_do_not_turn() {
        assert_eq!(choose(&[ALL, [0.6, 1.0, 1.0, 1.0], ALL]), [0, 0, 0]);
        assert_eq!(choose(&[ALL, [0.1, 0.2, 0.2, 0.2], ALL]), [0, 0, 0]);
    }

    #[test]
    fn a_view_that_shows_both_sides_beats_flipping() {
        // Steps alternate between the front and the back; the side view
        // shows both well enough.
        let front = [1.0, 0.8, 0.0, 0.8];
        let back = [0.0, 0.8, 1.0, 0.8];
        let f = [back, front, back, front, back, front];
        assert_eq!(choose(&f), [1; 6]);
    }
}
