//! The parts catalog: every piece type brickwright knows, as data.
//!
//! A part is known by its LDraw file name ([`PartId`]) and described by its
//! footprint in studs and its height in plates. Adding a rectangular part to
//! the alphabet Σ is one entry in [`PARTS`]; nothing else in the code names a
//! part number. Colours live here too, keyed by their LDraw code.

use std::fmt;

use serde::Serialize;

use crate::geom::Rot;

/// An LDraw part file name without its `.dat` extension, e.g. `3001`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct PartId(pub &'static str);

impl fmt::Display for PartId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

/// The shape family of a part, which decides how it connects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Shape {
    /// A rectangular brick or plate: studs on every top cell, tubes below.
    Rect,
}

/// How a part's geometry repeats under rotation about the vertical axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Symmetry {
    /// Unchanged by a half turn (every rectangular brick and plate).
    HalfTurn,
    /// Unchanged by a quarter turn (square bricks and plates).
    QuarterTurn,
}

/// One entry of the catalog.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PartSpec {
    /// LDraw file name, without `.dat`.
    pub id: PartId,
    /// The part's name as the LDraw library gives it.
    pub name: &'static str,
    /// BrickLink's item number, where it differs from the LDraw one.
    pub bricklink: &'static str,
    /// Studs along the part's own x axis (its long side).
    pub studs_x: u8,
    /// Studs along the part's own z axis in LDraw (grid y).
    pub studs_y: u8,
    /// Height in plates: 3 for a brick, 1 for a plate.
    pub height_plates: u8,
    /// Shape family.
    pub shape: Shape,
    /// Mass in grams, for the physics stage and the parts list.
    pub mass_g: f32,
}

impl PartSpec {
    /// Rotational symmetry of the footprint and geometry.
    pub fn symmetry(&self) -> Symmetry {
        if self.studs_x == self.studs_y {
            Symmetry::QuarterTurn
        } else {
            Symmetry::HalfTurn
        }
    }

    /// The canonical representative of `rot` under this part's symmetry, so
    /// that two placements with the same geometry compare equal.
    pub fn canonical_rot(&self, rot: Rot) -> Rot {
        match self.symmetry() {
            Symmetry::QuarterTurn => Rot::R0,
            Symmetry::HalfTurn => Rot::from_quarter_turns(rot.quarter_turns() % 2),
        }
    }

    /// Footprint `(along x, along y)` in studs when turned by `rot`.
    pub fn footprint(&self, rot: Rot) -> (i32, i32) {
        if rot.swaps_axes() {
            (self.studs_y as i32, self.studs_x as i32)
        } else {
            (self.studs_x as i32, self.studs_y as i32)
        }
    }

    /// Number of studs on top.
    pub fn studs(&self) -> u32 {
        self.studs_x as u32 * self.studs_y as u32
    }
}

/// Index of a part in [`PARTS`]: the alphabet's letters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct PartKind(pub u16);

impl PartKind {
    /// The catalog entry.
    pub fn spec(self) -> &'static PartSpec {
        &PARTS[self.0 as usize]
    }

    /// Looks a part up by its LDraw id (with or without `.dat`, any case).
    pub fn from_id(id: &str) -> Option<PartKind> {
        let id = id.trim();
        let id = id
            .strip_suffix(".dat")
            .or_else(|| id.strip_suffix(".DAT"))
            .unwrap_or(id);
        PARTS
            .iter()
            .position(|p| p.id.0.eq_ignore_ascii_case(id))
            .map(|i| PartKind(i as u16))
    }

    /// Every part of the catalog.
    pub fn all() -> impl Iterator<Item = PartKind> {
        (0..PARTS.len()).map(|i| PartKind(i as u16))
    }
}

impl fmt::Display for PartKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.spec().id)
    }
}

macro_rules! brick {
    ($id:literal, $bl:literal, $name:literal, $x:literal, $y:literal, $g:literal) => {
        PartSpec {
            id: PartId($id),
            name: $name,
            bricklink: $bl,
            studs_x: $x,
            studs_y: $y,
            height_plates: 3,
            shape: Shape::Rect,
            mass_g: $g,
        }
    };
}

/// The catalog. Masses are the commonly published weights of the parts.
pub static PARTS: &[PartSpec] = &[
    brick!("3005", "3005", "Brick 1 x 1", 1, 1, 0.44),
    brick!("3004", "3004", "Brick 1 x 2", 2, 1, 0.80),
    brick!("3622", "3622", "Brick 1 x 3", 3, 1, 1.15),
    brick!("3010", "3010", "Brick 1 x 4", 4, 1, 1.52),
    brick!("3009", "3009", "Brick 1 x 6", 6, 1, 2.24),
    brick!("3008", "3008", "Brick 1 x 8", 8, 1, 2.92),
    brick!("3003", "3003", "Brick 2 x 2", 2, 2, 1.15),
    brick!("3002", "3002", "Brick 2 x 3", 3, 2, 1.63),
    brick!("3001", "3001", "Brick 2 x 4", 4, 2, 2.32),
    brick!("2456", "2456", "Brick 2 x 6", 6, 2, 3.32),
    brick!("3007", "3007", "Brick 2 x 8", 8, 2, 4.38),
];

/// An LDraw colour code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct Color(pub u16);

impl Color {
    /// LDraw 4, red.
    pub const RED: Color = Color(4);
    /// LDraw 71, light bluish grey.
    pub const LIGHT_BLUISH_GREY: Color = Color(71);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_by_id_accepts_dat_suffix_and_case() {
        let k = PartKind::from_id("3001.DAT").unwrap();
        assert_eq!(k.spec().name, "Brick 2 x 4");
        assert_eq!(PartKind::from_id("3001"), Some(k));
        assert_eq!(PartKind::from_id("9999"), None);
    }

    #[test]
    fn footprints_swap_on_quarter_turns() {
        let s = PartKind::from_id("3001").unwrap().spec();
        assert_eq!(s.footprint(Rot::R0), (4, 2));
        assert_eq!(s.footprint(Rot::R90), (2, 4));
        assert_eq!(s.canonical_rot(Rot::R270), Rot::R90);
        let sq = PartKind::from_id("3003").unwrap().spec();
        assert_eq!(sq.canonical_rot(Rot::R90), Rot::R0);
    }
}
