//! Stair edges: where a build's surface steps instead of slanting, and how
//! many of those steps a slope caps.
//!
//! Look down on a build and take each column of cells (one stud square)
//! from its lowest filled cell to its highest. A **stair edge** on the top
//! is a column whose top stands one to three plates (8 to 24 LDU) above a
//! neighbouring column's top (the four side neighbours; an empty
//! neighbouring column is a wall, not a step). It is **capped** when the
//! piece at the top of the higher column is a slope whose low side (its
//! front, or either of a corner slope's two) faces down the step, towards
//! the lower neighbour: a roof built of slopes reads as a roof, a roof of
//! bricks as a staircase.
//!
//! The **underside** is the same upside down: a column whose lowest cell
//! hangs one to three plates below a neighbour's lowest cell (the eaves of
//! a roof, a chin), capped when the piece at the bottom of the lower column
//! is an inverted slope whose thin side faces the higher neighbour.
//!
//! ```
//! use brickwright::assembly::{stairs, Assembly, Placement};
//! use brickwright::catalog::{Color, PartKind};
//! use brickwright::geom::{Cell, Rot};
//!
//! // A 1x2 brick with a 1x1 brick on one end: one step of a brick's height
//! // (24 LDU), built of bricks, so not capped.
//! let brick = |id: &str, x, z| Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0);
//! let asm = Assembly::from_order(&[brick("3004", 0, 0), brick("3005", 0, 1)], 24, Color::RED);
//! let s = stairs::stair_edges(&asm);
//! assert_eq!((s.edges.top, s.capped.top), (1, 0));
//! ```

use std::collections::HashMap;

use serde::Serialize;

use super::Assembly;

/// A count on the top surface and on the underside.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct TopUnder {
    /// On the top surface (roofs, slanted tops).
    pub top: usize,
    /// On the underside (overhangs, eaves).
    pub underside: usize,
}

/// Stair edges of a build and how many a slope caps.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct StairEdges {
    /// Places where the surface steps by one to three plates.
    pub edges: TopUnder,
    /// Of those, the ones a slope (an inverted slope underneath) caps,
    /// facing down the step.
    pub capped: TopUnder,
}

impl StairEdges {
    /// The share of the top's stair edges that are capped (1 when there
    /// are none).
    pub fn top_share(&self) -> f64 {
        share(self.capped.top, self.edges.top)
    }

    /// The share of the underside's stair edges that are capped (1 when
    /// there are none).
    pub fn underside_share(&self) -> f64 {
        share(self.capped.underside, self.edges.underside)
    }
}

fn share(k: usize, n: usize) -> f64 {
    if n == 0 {
        1.0
    } else {
        k as f64 / n as f64
    }
}

/// One column's extent: its lowest and highest filled layers and the
/// pieces there.
#[derive(Debug, Clone, Copy)]
struct Column {
    low: i32,
    low_piece: usize,
    high: i32,
    high_piece: usize,
}

/// The most stair edges of `asm` that straight slopes could cap, on top
/// and underneath: one a column, since a slope faces one way. A column
/// that steps down two ways (a corner of a hip or of a rounded top) or
/// both ways (a ridge one stud wide) has stair edges no slope of the
/// alphabet caps all of; corner and ridge slopes would.
///
/// ```
/// use brickwright::assembly::{stairs, Assembly, Placement};
/// use brickwright::catalog::{Color, PartKind};
/// use brickwright::geom::{Cell, Rot};
///
/// // A 1x1 brick on the middle of a 1x3: one column, two stair edges,
/// // at most one capped.
/// let brick = |id: &str, x, z| Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0);
/// let asm = Assembly::from_order(&[brick("3622", 0, 0), brick("3005", 1, 1)], 24, Color::RED);
/// assert_eq!(stairs::stair_edges(&asm).edges.top, 2);
/// assert_eq!(stairs::cappable_at_most(&asm).top, 1);
/// ```
pub fn cappable_at_most(asm: &Assembly) -> TopUnder {
    let cols = columns(asm);
    let u = asm.layer_ldu.max(1);
    let is_step = |layers: i32| (8..=24).contains(&(layers * u));
    let mut out = TopUnder::default();
    for (&(x, y), a) in &cols {
        let near = || {
            [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .into_iter()
                .filter_map(|d: (i32, i32)| cols.get(&(x + d.0, y + d.1)))
        };
        out.top += usize::from(near().any(|b| is_step(a.high - b.high)));
        out.underside += usize::from(near().any(|b| is_step(b.low - a.low)));
    }
    out
}

/// Every column of `asm`'s cells, by its (x, y).
fn columns(asm: &Assembly) -> HashMap<(i32, i32), Column> {
    let mut cols: HashMap<(i32, i32), Column> = HashMap::new();
    for (i, p) in asm.pieces.iter().enumerate() {
        for c in p.placement.body(asm.layer_ldu).cells() {
            let col = cols.entry((c.x, c.y)).or_insert(Column {
                low: c.z,
                low_piece: i,
                high: c.z,
                high_piece: i,
            });
            if c.z < col.low {
                (col.low, col.low_piece) = (c.z, i);
            }
            if c.z > col.high {
                (col.high, col.high_piece) = (c.z, i);
            }
        }
    }
    cols
}

/// Counts the stair edges of `asm` on its top and underside, and how many
/// are capped (see the module docs).
pub fn stair_edges(asm: &Assembly) -> StairEdges {
    let cols = columns(asm);
    let u = asm.layer_ldu.max(1);
    let is_step = |layers: i32| (8..=24).contains(&(layers * u));
    // The piece faces from column `a` towards its neighbour at `dir`: its
    // front (low side), or a corner slope's other low side, is that way.
    let faces = |piece: usize, up: bool, dir: (i32, i32)| {
        let p = &asm.pieces[piece].placement;
        let spec = p.part.spec();
        let kind = if up {
            spec.shape.is_up()
        } else {
            spec.shape.is_inverted()
        };
        kind && spec.faces(p.rot).any(|f| f == dir)
    };
    let mut keys: Vec<&(i32, i32)> = cols.keys().collect();
    keys.sort();
    let mut out = StairEdges::default();
    for &(x, y) in keys {
        let a = cols[&(x, y)];
        for dir in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            let Some(b) = cols.get(&(x + dir.0, y + dir.1)) else {
                continue;
            };
            if is_step(a.high - b.high) {
                out.edges.top += 1;
                out.capped.top += usize::from(faces(a.high_piece, true, dir));
            }
            if is_step(b.low - a.low) {
                out.edges.underside += 1;
                out.capped.underside += usize::from(faces(a.low_piece, false, dir));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Placement;
    use crate::catalog::{Color, PartKind};
    use crate::geom::{Cell, Rot};

    fn asm(pieces: &[(&str, (i32, i32, i32), Rot)], layer_ldu: i32) -> Assembly {
        let order: Vec<Placement> = pieces
            .iter()
            .map(|&(id, (x, y, z), rot)| {
                Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, y, z), rot)
            })
            .collect();
        Assembly::from_order(&order, layer_ldu, Color::RED)
    }

    #[test]
    fn unturned_slopes_face_minus_y() {
        // The tests below rely on it: a slope's back row is at +y unturned.
        assert_eq!(
            PartKind::from_id("3039").unwrap().spec().back(Rot::R0),
            (0, 1)
        );
    }

    #[test]
    fn a_staircase_of_bricks_has_uncapped_edges() {
        // Two 1x4 rows side by side and a third row on the second: four
        // stair edges of a brick (two half-brick layers), none capped.
        let s = stair_edges(&asm(
            &[
                ("3010", (0, 0, 0), Rot::R0),
                ("3010", (0, 1, 0), Rot::R0),
                ("3010", (0, 1, 2), Rot::R0),
            ],
            12,
        ));
        assert_eq!(s.edges.top, 4);
        assert_eq!(s.capped.top, 0);
        assert_eq!(s.edges.underside, 0);
        assert_eq!(s.top_share(), 0.0);
        assert_eq!(s.underside_share(), 1.0);
    }

    #[test]
    fn a_slope_caps_the_step_it_faces_and_not_one_beside_it() {
        // A 2x3 brick (x 0..3, y 0..2) with a 2x2 slope on x 0..2, its back
        // row at y = 1, its front row over y = 0 (facing -y): the steps from
        // y = 1 to y = 0 under the slope are capped (two); the step from the
        // slope's back row at x = 1 down to the bare brick at x = 2 is a
        // step the slope does not face (one), and the front row's lip at
        // x = 1 stands one layer above x = 2 too (one, not capped).
        let s = stair_edges(&asm(
            &[("3002", (0, 0, 0), Rot::R0), ("3039", (0, 0, 2), Rot::R0)],
            12,
        ));
        assert_eq!(s.edges.top, 2 + 2);
        assert_eq!(s.capped.top, 2);
        // Turned to face +y, the back row is at y = 0 and it caps the steps
        // down to y = 1 instead: the same counts.
        let t = stair_edges(&asm(
            &[("3002", (0, 0, 0), Rot::R0), ("3039", (0, 0, 2), Rot::R180)],
            12,
        ));
        assert_eq!((t.edges.top, t.capped.top), (4, 2));
    }

    #[test]
    fn steps_taller_than_three_plates_are_walls_not_stairs() {
        // A column two bricks tall beside one a brick tall: 24 LDU, a stair;
        // three bricks beside one (48 LDU) is a wall.
        let brick = |id, z| (id, (0, 0, z), Rot::R0);
        let two = stair_edges(&asm(&[brick("3004", 0), brick("3005", 1)], 24));
        assert_eq!(two.edges.top, 1);
        let three = stair_edges(&asm(
            &[brick("3004", 0), brick("3005", 1), brick("3005", 2)],
            24,
        ));
        assert_eq!(three.edges.top, 0);
    }

    #[test]
    fn an_inverted_slope_caps_the_underside_step_it_faces() {
        // A 2x2 inverted slope on the ground, a 2x2 brick on it: its back
        // row (y = 1) fills both layers, its front row (y = 0) the top layer
        // only, so the underside steps up from y = 1 to y = 0 by a layer,
        // and the thin side faces that way.
        let s = stair_edges(&asm(
            &[("3660a", (0, 0, 0), Rot::R0), ("3003", (0, 0, 2), Rot::R0)],
            12,
        ));
        assert_eq!((s.edges.underside, s.capped.underside), (2, 2));
        // The same step under bricks: a 1x4 brick on the ground, a 2x2
        // brick one layer up overhanging it. Not capped.
        let b = stair_edges(&asm(
            &[("3010", (0, 0, 0), Rot::R0), ("3003", (0, 1, 1), Rot::R0)],
            12,
        ));
        assert_eq!((b.edges.underside, b.capped.underside), (2, 0));
    }
}
