//! LDraw `.ldr` files: writing an [`Assembly`] out, and reading models back.
//!
//! LDraw is the open file format every LEGO CAD program reads (LeoCAD,
//! LDView, Studio, BrickLink's tools). A model is plain text, one command a
//! line; the line that matters is type 1, a part reference:
//!
//! ```text
//! 1 <colour> x y z a b c d e f g h i <part>.dat
//! ```
//!
//! which puts the part's own geometry `p` at `M·p + (x, y, z)` with the
//! row-major matrix `M = [a b c; d e f; g h i]`. `0 STEP` ends a building step.
//!
//! # From the grid to LDraw
//!
//! The voxel grid is right-handed with `x`, `y` horizontal and `z` up; LDraw
//! uses LDraw units (LDU, 20 to a stud, 8 to a plate) with **-Y up**. The map
//!
//! ```text
//! LDraw X =  20 * x
//! LDraw Z =  20 * y
//! LDraw Y = -8 * (plates above the ground)
//! ```
//!
//! sends grid `(x, y, z)` to LDraw `(x, -z, y)`, a proper rotation, so a turn
//! that is counter-clockwise seen from above in the grid is the same physical
//! turn in LDraw. A brick's LDraw origin is the centre of its top face, its
//! long side along its own X. A piece whose cells start at `(x0, y0, z)`, with
//! footprint `(sx, sy)` and `h` plates tall, therefore sits at
//!
//! ```text
//! X = 20*x0 + 10*sx,   Z = 20*y0 + 10*sy,   Y = -(layer_ldu*z + 8*h)
//! ```
//!
//! (for bricks in a brick grid, `Y = -24*(z + 1)`), turned by
//! [`rot_matrix`]`(rot)`. [`Rot::R90`] takes the part's X (its long side) to
//! LDraw +Z, grid +y, exactly as [`crate::catalog::PartSpec::footprint`]
//! and [`Rot::apply`] say. A slope's origin is the centre of its studded
//! back row, not of its footprint: it sits `10*(depth - 1)` LDU from the
//! footprint's centre toward the back (the part's own `+Z`), turned with
//! the part.
//!
//! # Reading
//!
//! [`read_ldr`] / [`parse_ldr`] accept plain `.ldr` files and multi-part
//! `.mpd` files (`0 FILE` ... `0 NOFILE`). The first `FILE` is the main model;
//! submodels defined in the same file are flattened into it, transforms
//! composed, their pieces placed at the step that references them.
//! [`to_assembly`] then maps every reference back to a catalog part and grid
//! placement, the exact inverse of [`write_ldr`]. Every input error names the
//! file and line and says what is wrong; no input makes the reader panic.
//!
//! # Example
//!
//! ```
//! use std::path::Path;
//! use brickwright::assembly::{Assembly, Placement};
//! use brickwright::catalog::{Color, PartKind};
//! use brickwright::geom::{Cell, Rot};
//! use brickwright::ldraw::{parse_ldr, to_assembly, write_ldr, LdrMeta};
//!
//! let brick = PartKind::from_id("3001").unwrap();
//! let order = [
//!     Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
//!     Placement::new(brick, Cell::new(1, 0, 1), Rot::R90),
//! ];
//! let asm = Assembly::from_order(&order, 24, Color::RED);
//! let meta = LdrMeta {
//!     title: "Two bricks".into(),
//!     name: "two.ldr".into(),
//!     author: "brickwright".into(),
//!     notes: vec![],
//!     step_notes: Default::default(),
//!     piece_notes: Default::default(),
//! };
//! let mut out = Vec::new();
//! write_ldr(&mut out, &asm, &meta).unwrap();
//! let text = String::from_utf8(out).unwrap();
//! assert!(text.contains("1 4 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat\n"));
//! assert!(text.contains("1 4 40 -48 40 0 0 -1 0 1 0 1 0 0 3001.dat\n"));
//!
//! let back = to_assembly(&parse_ldr(&text, Path::new("two.ldr")).unwrap()).unwrap();
//! assert_eq!(back, asm);
//! ```

mod read;
mod write;

use std::path::PathBuf;

use thiserror::Error;

use crate::assembly::Placement;
use crate::catalog::{PartKind, Shape};
use crate::geom::Rot;

pub use read::{
    layer_ldu_of, parse_ldr, read_ldr, to_assembly, to_placement, Instance, LdrModel, PartRef,
};
pub use write::{write_ldr, LdrMeta};

#[cfg(doc)]
use crate::assembly::Assembly;

/// LDraw units per stud (horizontal grid step).
pub const LDU_PER_STUD: i32 = 20;

/// LDraw units per plate height (a brick is three plates, 24 LDU).
pub const LDU_PER_PLATE: i32 = 8;

/// The 3 x 3 LDraw matrix (row-major, `world = M·local`) that turns a part
/// by `rot` about the vertical axis.
///
/// Derived from the grid-to-LDraw map `(x, y, z) -> (x, -z, y)`:
/// [`Rot::apply`] sends grid `(1, 0)` to `(0, 1)` for [`Rot::R90`], so LDraw
/// `+X` goes to `+Z` and `+Z` to `-X`. Every matrix has determinant +1.
///
/// | rot  | matrix rows                      |
/// |------|----------------------------------|
/// | R0   | `[1 0 0] [0 1 0] [0 0 1]`        |
/// | R90  | `[0 0 -1] [0 1 0] [1 0 0]`       |
/// | R180 | `[-1 0 0] [0 1 0] [0 0 -1]`      |
/// | R270 | `[0 0 1] [0 1 0] [-1 0 0]`       |
pub const fn rot_matrix(rot: Rot) -> [[i32; 3]; 3] {
    match rot {
        Rot::R0 => [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
        Rot::R90 => [[0, 0, -1], [0, 1, 0], [1, 0, 0]],
        Rot::R180 => [[-1, 0, 0], [0, 1, 0], [0, 0, -1]],
        Rot::R270 => [[0, 0, 1], [0, 1, 0], [-1, 0, 0]],
    }
}

/// The LDraw position `(X, Y, Z)` in LDU of a placement's part origin (the
/// centre of a brick's top face, of a slope's studded back row), for a grid
/// of `layer_ldu`-high layers.
///
/// The part's bottom rests on the floor of its origin layer:
/// `Y = -(layer_ldu * z + 8 * height_plates)`.
pub fn placement_position(p: &Placement, layer_ldu: i32) -> [i64; 3] {
    let spec = p.part.spec();
    let (sx, sy) = spec.footprint(p.rot);
    let stud = i64::from(LDU_PER_STUD);
    let plate = i64::from(LDU_PER_PLATE);
    let (bx, by) = origin_offset(p.part, p.rot);
    let x = stud * i64::from(p.origin.x) + stud / 2 * i64::from(sx) + bx;
    let z = stud * i64::from(p.origin.y) + stud / 2 * i64::from(sy) + by;
    let bottom = i64::from(layer_ldu) * i64::from(p.origin.z);
    let y = -(bottom + plate * i64::from(spec.height_plates));
    [x, y, z]
}

/// Where a part's LDraw origin lies from the centre of its footprint, in
/// LDU along LDraw `(X, Z)`: nowhere for bricks and plates, toward the back
/// row for slopes.
pub(crate) fn origin_offset(part: PartKind, rot: Rot) -> (i64, i64) {
    let spec = part.spec();
    if spec.shape == Shape::Rect {
        return (0, 0);
    }
    if spec.shape.is_corner() {
        // On its one full cell: back row, -X (measured from 3045.dat and
        // 3676.dat).
        let half = i64::from(LDU_PER_STUD) / 2;
        let (x, z) = rot.apply(-1, 1);
        return (half * i64::from(x), half * i64::from(z));
    }
    let d = i64::from(LDU_PER_STUD) / 2 * (i64::from(spec.studs_y) - 1);
    let (bx, by) = spec.back(rot);
    (d * i64::from(bx), d * i64::from(by))
}

/// Everything that can go wrong reading an LDraw file.
///
/// Input errors carry the file and the 1-based line, so a message reads
/// `house.ldr:12: ...` and points at the line to fix.
#[derive(Debug, Error)]
pub enum LdrError {
    /// The file could not be opened or read (missing, unreadable, a
    /// directory).
    #[error("{}: cannot read the file: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why the system refused.
        source: std::io::Error,
    },
    /// The file is not LDraw text: binary content, or a line that does not
    /// start with a line type 0 to 5.
    #[error("{}:{line}: not LDraw text: {what}", path.display())]
    NotLdraw {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What was found instead.
        what: String,
    },
    /// A line has fewer fields than its line type needs.
    #[error(
        "{}:{line}: too few fields: a type {kind} line needs {needed}, found {found}",
        path.display()
    )]
    TooFewFields {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The line type.
        kind: u8,
        /// Fields needed, counting the line type.
        needed: usize,
        /// Fields present.
        found: usize,
    },
    /// A field that must be a number is not one (or is not finite).
    #[error("{}:{line}: bad {field}: expected a number, found `{text}`", path.display())]
    BadNumber {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// Which field, e.g. `x` or `colour`.
        field: &'static str,
        /// The text found.
        text: String,
    },
    /// A reference names a part the catalog does not know.
    #[error(
        "{}:{line}: unknown part `{part}`: brickwright only builds with the parts in its catalog",
        path.display()
    )]
    UnknownPart {
        /// The file.
        path: PathBuf,
        /// 1-based line number of the reference.
        line: usize,
        /// The part name as written.
        part: String,
    },
    /// A part's position does not lie on the stud/layer grid.
    #[error(
        "{}:{line}: part `{part}` is off the grid: {axis} = {value} LDU {why}",
        path.display()
    )]
    OffGrid {
        /// The file.
        path: PathBuf,
        /// 1-based line number of the reference.
        line: usize,
        /// The part name.
        part: String,
        /// `X`, `Y` or `Z`.
        axis: char,
        /// The coordinate found.
        value: f64,
        /// What the coordinate should be.
        why: String,
    },
    /// A part's matrix is not one of the four quarter turns about the
    /// vertical axis (tilted, mirrored, scaled).
    #[error(
        "{}:{line}: part `{part}` is not turned by a quarter turn about the vertical (-Y) axis; \
         matrix {matrix:?}",
        path.display()
    )]
    NotQuarterTurn {
        /// The file.
        path: PathBuf,
        /// 1-based line number of the reference.
        line: usize,
        /// The part name.
        part: String,
        /// The composed matrix, row-major (boxed to keep the error small).
        matrix: Box<[[f64; 3]; 3]>,
    },
    /// A submodel references itself, directly or through others.
    #[error("{}:{line}: submodel `{name}` contains itself", path.display())]
    Recursion {
        /// The file.
        path: PathBuf,
        /// 1-based line of the reference that closes the loop.
        line: usize,
        /// The submodel.
        name: String,
    },
    /// Flattening the submodels produces more pieces than any build needs
    /// (a guard against files that nest references exponentially).
    #[error("{}:{line}: the model expands to more than {limit} parts", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// 1-based line of the reference that went over.
        line: usize,
        /// The limit.
        limit: usize,
    },
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::PartKind;
    use crate::geom::Cell;

    fn det(m: [[i32; 3]; 3]) -> i32 {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    }

    fn mul(m: [[i32; 3]; 3], v: [i32; 3]) -> [i32; 3] {
        [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
    }

    /// Grid horizontal vector (x, y) to LDraw (X, Y, Z), one LDU a unit.
    fn grid_to_ldraw(x: i32, y: i32) -> [i32; 3] {
        [x, 0, y]
    }

    #[test]
    fn matrices_are_proper_vertical_rotations() {
        for r in Rot::ALL {
            let m = rot_matrix(r);
            assert_eq!(det(m), 1, "{r:?}");
            // The vertical axis stays put.
            assert_eq!(mul(m, [0, 1, 0]), [0, 1, 0], "{r:?}");
        }
    }

    #[test]
    fn matrices_turn_the_same_way_as_rot_apply() {
        // For every horizontal vector, turning it in the grid with
        // Rot::apply and mapping to LDraw equals mapping then multiplying.
        for r in Rot::ALL {
            for (x, y) in [(1, 0), (0, 1), (3, -2), (-5, 7)] {
                let (gx, gy) = r.apply(x, y);
                assert_eq!(
                    mul(rot_matrix(r), grid_to_ldraw(x, y)),
                    grid_to_ldraw(gx, gy),
                    "{r:?} on ({x}, {y})"
                );
            }
        }
        // R90: the long side (+X) ends up along +Z, grid +y.
        assert_eq!(mul(rot_matrix(Rot::R90), [1, 0, 0]), [0, 0, 1]);
    }

    #[test]
    fn transformed_part_corners_fill_exactly_the_placement_cells() {
        // Take the 8 corners of each part's body in its own LDraw frame
        // (X in ±10*studs_x, Z in ±10*studs_y, Y from 0 down to the
        // bottom at +8*height), place them with the matrix and position, map
        // back to grid units, and compare with the placement's cell box.
        for part in PartKind::all() {
            let s = part.spec();
            let (hx, hz) = (10 * s.studs_x as i32, 10 * s.studs_y as i32);
            // A slope's origin is on its back row: its body runs from
            // +10 to the front at -(20*depth - 10) (measured from 3039.dat).
            let (zlo, zhi) = if s.shape == Shape::Rect {
                (-hz, hz)
            } else {
                (10 - 2 * hz, 10)
            };
            // A corner slope's origin is on its full cell, at -X.
            let (xlo, xhi) = if s.shape.is_corner() {
                (-10, 2 * hx - 10)
            } else {
                (-hx, hx)
            };
            let h = 8 * s.height_plates as i32;
            for r in Rot::ALL {
                let p = Placement {
                    part,
                    origin: Cell::new(3, -2, 5),
                    rot: r,
                };
                let pos = placement_position(&p, 8).map(|v| v as i32);
                let (mut lo, mut hi) = ([i32::MAX; 3], [i32::MIN; 3]);
                for cx in [xlo, xhi] {
                    for cy in [0, h] {
                        for cz in [zlo, zhi] {
                            let w = mul(rot_matrix(r), [cx, cy, cz]);
                            for a in 0..3 {
                                lo[a] = lo[a].min(w[a] + pos[a]);
                                hi[a] = hi[a].max(w[a] + pos[a]);
                            }
                        }
                    }
                }
                let b = p.body(8).bbox;
                let m = b.max_excl();
                assert_eq!([lo[0], hi[0]], [20 * b.min.x, 20 * m.x], "{part} {r:?} X");
                assert_eq!([lo[2], hi[2]], [20 * b.min.y, 20 * m.y], "{part} {r:?} Z");
                assert_eq!([-hi[1], -lo[1]], [8 * b.min.z, 8 * m.z], "{part} {r:?} Y");
            }
        }
    }

    #[test]
    fn a_corner_slopes_origin_is_on_its_full_cell() {
        // 3045's origin is its one stud, 3676's the centre of the cell it
        // is held by from below: the full cell of the grid body, turned
        // any way.
        for (id, up) in [("3045", true), ("3676", false)] {
            let part = PartKind::from_id(id).unwrap();
            for rot in Rot::ALL {
                let p = Placement {
                    part,
                    origin: Cell::new(4, 7, 2),
                    rot,
                };
                let [x, _, z] = placement_position(&p, 12);
                let body = p.body(12);
                let full = if up { body.studs } else { body.tubes };
                assert_eq!((full.sx, full.sy), (1, 1), "{id} {rot:?}");
                assert_eq!(
                    ((x - 10) / 20, (z - 10) / 20),
                    (i64::from(full.min.x), i64::from(full.min.y)),
                    "{id} {rot:?}"
                );
            }
        }
    }

    #[test]
    fn a_marked_corner_goes_where_rot_apply_sends_it() {
        // The 2x4's corner at local (+40, 0, -20): grid offset (2, -1) from
        // the centre. Turned R90 it must sit at grid offset (1, 2).
        let p = Placement {
            part: PartKind::from_id("3001").unwrap(),
            origin: Cell::new(0, 0, 0),
            rot: Rot::R90,
        };
        let pos = placement_position(&p, 24);
        assert_eq!(pos, [20, -24, 40]);
        let w = mul(rot_matrix(Rot::R90), [40, 0, -20]);
        assert_eq!([w[0] / 20, w[2] / 20], [1, 2]);
        assert_eq!(Rot::R90.apply(2, -1), (1, 2));
    }
}
