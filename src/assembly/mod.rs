//! The assembly: the ordered, verified list of placements every exporter reads.
//!
//! An [`Assembly`] is the single plan that the LDraw, glTF, parts-list and
//! booklet back ends trust. It is produced by the search and checked by the
//! independent [`verify`] module before anything is written.

pub mod metrics;
pub mod verify;

use serde::Serialize;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::catalog::{Color, Palette, PartKind, LAYER_PALETTE, RANDOM_PALETTE};
use crate::geom::{Body, Cell, Rot};

/// A building step number, counted from 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct Step(pub u32);

/// One piece placed in the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct Placement {
    /// Which part.
    pub part: PartKind,
    /// Minimum corner of the cells the piece fills.
    pub origin: Cell,
    /// Rotation about the vertical axis.
    pub rot: Rot,
}

impl Placement {
    /// A placement with its rotation made canonical for the part's symmetry.
    pub fn new(part: PartKind, origin: Cell, rot: Rot) -> Self {
        Placement {
            part,
            origin,
            rot: part.spec().canonical_rot(rot),
        }
    }

    /// The cells the piece fills and where it connects, in a grid of
    /// `layer_ldu`-high layers.
    pub fn body(&self, layer_ldu: i32) -> Body {
        self.part.body(self.rot, self.origin, layer_ldu)
    }
}

/// A placement with its place in the build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Placed {
    /// Where and what.
    pub placement: Placement,
    /// The step that adds it.
    pub step: Step,
    /// Its colour.
    pub color: Color,
}

/// The ordered build: pieces in the order a person adds them.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Assembly {
    /// Pieces in build order; steps never decrease.
    pub pieces: Vec<Placed>,
    /// Height of a voxel layer in LDU: 24 for bricks, 12 with slopes, 8
    /// with plates.
    pub layer_ldu: i32,
}

impl Assembly {
    /// An assembly from placements in build order, one step each.
    pub fn from_order(order: &[Placement], layer_ldu: i32, color: Color) -> Self {
        Assembly {
            pieces: order
                .iter()
                .enumerate()
                .map(|(i, &placement)| Placed {
                    placement,
                    step: Step(i as u32 + 1),
                    color,
                })
                .collect(),
            layer_ldu,
        }
    }

    /// Number of steps (the highest step number).
    pub fn step_count(&self) -> u32 {
        self.pieces.last().map_or(0, |p| p.step.0)
    }

    /// Regroups the steps: `StepGrouping::Each` one piece a step,
    /// `Size(n)` n pieces a step, `Layer` one step per layer run.
    pub fn regroup(&mut self, grouping: StepGrouping) {
        let grouping = match grouping {
            StepGrouping::Auto if self.pieces.len() <= MAX_STEPS => StepGrouping::Each,
            StepGrouping::Auto => StepGrouping::Size(self.pieces.len().div_ceil(MAX_STEPS)),
            g => g,
        };
        let mut step = 0u32;
        let mut in_step = 0usize;
        let mut last_z = i32::MIN;
        // Layers by brick course (24 LDU), whatever the grid's layer height.
        let layer_ldu = self.layer_ldu;
        let course = |p: &Placed| p.placement.origin.z * layer_ldu / 24;
        for p in &mut self.pieces {
            let new_step = match grouping {
                StepGrouping::Each | StepGrouping::Auto => true,
                StepGrouping::Size(n) => in_step >= n.max(1),
                StepGrouping::Layer => course(p) != last_z,
            };
            if new_step || step == 0 {
                step += 1;
                in_step = 0;
            }
            in_step += 1;
            last_z = course(p);
            p.step = Step(step);
        }
    }

    /// Colours every piece by `palette`; `seed` drives
    /// [`Palette::Random`], so the same seed gives the same colours.
    pub fn paint(&mut self, palette: Palette, seed: u64) {
        let layer_ldu = self.layer_ldu;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for p in &mut self.pieces {
            p.color = match palette {
                Palette::Single(c) => c,
                Palette::Random => RANDOM_PALETTE[rng.gen_range(0..RANDOM_PALETTE.len())],
                Palette::Layers => {
                    // By brick course (24 LDU), whatever the layer height.
                    let course = (p.placement.origin.z * layer_ldu).div_euclid(24);
                    LAYER_PALETTE[course.rem_euclid(LAYER_PALETTE.len() as i32) as usize]
                }
            };
        }
    }

    /// Pieces counted by part, in catalog order.
    pub fn counts_by_part(&self) -> Vec<(PartKind, usize)> {
        let mut counts = std::collections::BTreeMap::new();
        for p in &self.pieces {
            *counts.entry(p.placement.part).or_insert(0) += 1;
        }
        counts.into_iter().collect()
    }
}

/// Steps LeoCAD shows at most (its step counter is one byte); a model with
/// more steps loads, but its later steps are missing from the view.
pub const MAX_STEPS: usize = 255;

/// How pieces are grouped into steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum StepGrouping {
    /// One piece a step, or as few pieces a step as keep the steps within
    /// [`MAX_STEPS`] (the default).
    Auto,
    /// One piece a step (the default).
    Each,
    /// At most this many pieces a step.
    Size(usize),
    /// A new step whenever the build moves to another layer.
    Layer,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assembly(n: usize) -> Assembly {
        let part = PartKind::from_id("3005").unwrap();
        let order: Vec<Placement> = (0..n)
            .map(|i| Placement::new(part, Cell::new(0, 0, i as i32 / 3), Rot::R0))
            .collect();
        Assembly::from_order(&order, 24, Color::RED)
    }

    #[test]
    fn auto_steps_stay_within_what_leocad_shows() {
        let mut small = assembly(200);
        small.regroup(StepGrouping::Auto);
        assert_eq!(small.step_count(), 200);
        let mut big = assembly(1000);
        big.regroup(StepGrouping::Auto);
        assert_eq!(big.step_count(), 250);
        assert!(big.step_count() as usize <= MAX_STEPS);
        let mut sized = assembly(10);
        sized.regroup(StepGrouping::Size(4));
        assert_eq!(sized.step_count(), 3);
        let mut layers = assembly(9);
        layers.regroup(StepGrouping::Layer);
        assert_eq!(layers.step_count(), 3);
    }

    #[test]
    fn palettes_paint_by_layer_at_random_or_all_alike() {
        let mut a = assembly(9);
        a.paint(Palette::Layers, 1);
        let colors: Vec<u16> = a.pieces.iter().map(|p| p.color.0).collect();
        assert_eq!(colors, [4, 4, 4, 15, 15, 15, 4, 4, 4]);
        a.paint(Palette::Single(Color(1)), 1);
        assert!(a.pieces.iter().all(|p| p.color == Color(1)));
        let mut b = assembly(200);
        b.paint(Palette::Random, 7);
        let mut c = b.clone();
        c.paint(Palette::Random, 7);
        assert_eq!(b, c);
        let distinct: std::collections::BTreeSet<_> = b.pieces.iter().map(|p| p.color).collect();
        assert_eq!(distinct.len(), RANDOM_PALETTE.len());
        c.paint(Palette::Random, 8);
        assert_ne!(b, c);
    }
}
