//! Zoom: each step's picture framed to the model as built so far.
//!
//! One camera fitted to the finished model leaves the first steps of a
//! tall or wide model a small cluster in white space. Instead the steps
//! are cut into *stages*, runs of steps that share one camera, fitted to
//! everything built by the end of the stage: the new pieces of every step
//! in the stage are inside the frame, and the model fills most of it.
//!
//! Where the stages start is chosen to fill the pictures as much as
//! possible with few changes of scale (see [`stages`]); two stages' scales
//! differ by at least [`MIN_CHANGE`], so the picture never jumps by a
//! small step a reader would take for a mistake. The zoom is at most
//! [`MAX_ZOOM`] times the finished model's, so the first pieces are not
//! drawn a page wide.
//!
//! When the view turns (see [`Turning`](super::Turning)), a stage's scale
//! is the smallest of its fits in the four turned views, so turning does
//! not change the scale either.

use super::camera::{Bounds, Camera, View};
use super::scene::Scene;
use crate::assembly::Step;
use std::ops::Range;

use rayon::prelude::*;

/// The cost of a change of scale, in steps drawn at nothing (see
/// [`stages`]): a change must make the pictures of several steps much
/// fuller to be worth it.
pub const CHANGE_COST: f32 = 0.6;
/// Two stages' scales differ by at least this share of the larger: the
/// scale changes by a quarter or more, or not at all.
pub const MIN_CHANGE: f32 = 0.25;
/// The largest zoom, in times the finished model's scale.
pub const MAX_ZOOM: f32 = 3.0;

/// The cameras of the steps' pictures.
#[derive(Debug, Clone)]
pub(crate) struct Framing {
    /// Each stage's steps, as a range of step numbers, and its scale.
    pub stages: Vec<(Range<usize>, f32)>,
    /// For each stage, its camera in each of `views` (fitted to what is
    /// built by the stage's end, at the stage's scale).
    pub cameras: Vec<Vec<Camera>>,
}

/// The framing of `steps` (ranges of `order`, which lists `scene`'s pieces
/// by step) in `views` (the base view, and its turned views when steps may
/// turn), in `width` x `height` images with `margin` free pixels.
pub(crate) fn frame(
    scene: &Scene,
    order: &[usize],
    steps: &[(Step, Range<usize>)],
    views: &[View],
    (width, height, margin): (u32, u32, u32),
) -> Framing {
    // What is built by the end of each step, in each view: the views side
    // by side (each grown in step order, as one pass would).
    let by_view: Vec<Vec<Bounds>> = views
        .par_iter()
        .map(|v| {
            let mut built = Bounds::EMPTY;
            steps
                .iter()
                .map(|(_, range)| {
                    for &i in &order[range.clone()] {
                        built.extend(v, scene.piece_triangles(i).iter().flat_map(|t| t.positions));
                    }
                    built
                })
                .collect()
        })
        .collect();
    let prefix: Vec<Vec<Bounds>> = (0..steps.len())
        .map(|n| by_view.iter().map(|b| b[n]).collect())
        .collect();
    let fit = |b: &[Bounds]| -> f32 {
        views
            .iter()
            .zip(b)
            .map(|(v, b)| Camera::fit_bounds(v, b, width, height, margin).scale())
            .fold(f32::INFINITY, f32::min)
    };
    let full = prefix.last().map_or(1.0, |b| fit(b));
    let scales: Vec<f32> = prefix.iter().map(|b| fit(b).min(full * MAX_ZOOM)).collect();
    let stages = stages(&scales);
    let cameras = stages
        .iter()
        .map(|(r, scale)| {
            let built = &prefix[r.end - 1];
            views
                .iter()
                .zip(built)
                .map(|(v, b)| Camera::fit_bounds(v, b, width, height, margin).with_scale(*scale))
                .collect()
        })
        .collect();
    Framing { stages, cameras }
}

/// Cuts steps into stages given `scales[n]`, the scale that fits the
/// model built by step `n` (never growing from one step to the next):
/// each stage with its steps and scale (that of its last step).
///
/// A step drawn at scale `s` fills `s / scales[n]` of what it could; it
/// costs the square of the shortfall, and each change of scale costs
/// [`CHANGE_COST`]. Consecutive stages' scales differ by at least
/// [`MIN_CHANGE`]. The cut of least cost is found exactly by dynamic
/// programming over where the last stage starts.
pub(crate) fn stages(scales: &[f32]) -> Vec<(Range<usize>, f32)> {
    let n = scales.len();
    if n == 0 {
        return Vec::new();
    }
    // Each stage's cost: shortfalls of steps s..e at scales[e - 1].
    let stage_cost = |s: usize, e: usize| -> f32 {
        let scale = scales[e - 1];
        scales[s..e]
            .iter()
            .map(|&f| {
                let short = 1.0 - (scale / f).min(1.0);
                short * short
            })
            .sum()
    };
    // best[e]: least cost of steps 0..e cut into stages, the last ending
    // at e - 1; from[e]: where that last stage starts.
    let mut best = vec![f32::INFINITY; n + 1];
    let mut from = vec![0; n + 1];
    best[0] = 0.0;
    for e in 1..=n {
        for s in 0..e {
            if !best[s].is_finite() {
                continue;
            }
            // The scale changes by a quarter or more from stage to stage.
            if s > 0 && scales[e - 1] > scales[s - 1] * (1.0 - MIN_CHANGE) {
                continue;
            }
            let change = if s > 0 { CHANGE_COST } else { 0.0 };
            let c = best[s] + change + stage_cost(s, e);
            if c < best[e] - 1e-6 {
                best[e] = c;
                from[e] = s;
            }
        }
    }
    let mut out = Vec::new();
    let mut e = n;
    while e > 0 {
        let s = from[e];
        out.push((s..e, scales[e - 1]));
        e = s;
    }
    out.reverse();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_growing_model_zooms_out_in_stages_a_quarter_apart() {
        let scales: Vec<f32> = (0..40).map(|n| 4.0 / (1.0 + n as f32 * 0.1)).collect();
        let st = stages(&scales);
        assert!(st.len() > 2, "{st:?}");
        assert_eq!(st[0].0.start, 0);
        assert_eq!(st.last().unwrap().0.end, 40);
        for w in st.windows(2) {
            assert_eq!(w[0].0.end, w[1].0.start);
            assert!(w[1].1 <= w[0].1 * (1.0 - MIN_CHANGE), "{st:?}");
        }
        // Each step is drawn at a scale no larger than its own fit.
        for (r, s) in &st {
            assert!(r.clone().all(|n| *s <= scales[n]));
        }
    }

    #[test]
    fn a_model_that_barely_grows_keeps_one_scale() {
        let scales = [1.0, 0.98, 0.95, 0.9, 0.85];
        assert_eq!(stages(&scales), vec![(0..5, 0.85)]);
        assert!(stages(&[]).is_empty());
    }
}
