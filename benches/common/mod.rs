//! Synthetic models shared by the benchmarks.

use brickwright::assembly::{Assembly, Placement, StepGrouping};
use brickwright::catalog::{Palette, PartKind};
use brickwright::geom::{Cell, Rot};

/// A `side` x `side` stud block of 2 x 4 bricks, `courses` high, each
/// course turned a quarter from the one below, built course by course,
/// coloured by course and grouped into steps as `build` groups them.
pub fn block(side: i32, courses: i32) -> Assembly {
    let brick = PartKind::from_id("3001").expect("3001 is in the catalog");
    let mut order = Vec::new();
    for z in 0..courses {
        let rot = if z % 2 == 0 { Rot::R0 } else { Rot::R90 };
        let (sx, sy) = if z % 2 == 0 { (4, 2) } else { (2, 4) };
        for y in (0..side).step_by(sy as usize) {
            for x in (0..side).step_by(sx as usize) {
                order.push(Placement::new(brick, Cell::new(x, y, z), rot));
            }
        }
    }
    let mut a = Assembly::from_order(&order, 24, brickwright::catalog::Color::RED);
    a.paint(Palette::Layers, 1);
    a.regroup(StepGrouping::Auto);
    a
}
