//! The parts catalog: every piece type brickwright knows, as data.
//!
//! A part is known by its LDraw file name ([`PartId`]) and described by its
//! footprint in studs and its height in plates. Adding a rectangular part to
//! the alphabet Σ is one entry in [`PARTS`]; nothing else in the code names a
//! part number. Colours live here too, keyed by their LDraw code, with the
//! colours each part is made in (`catalog/part_colors.txt`).

use std::fmt;

use serde::Serialize;

use crate::geom::{Body, Cell, CellBox, Rot, MAX_BODY_BOXES};

mod color;
pub mod lab;
mod part_colors;
pub use color::{Color, ColorSpec, Palette, COLORS, LAYER_PALETTE, RANDOM_PALETTE};
pub use part_colors::buildable;

/// An LDraw part file name without its `.dat` extension, e.g. `3001`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct PartId(pub &'static str);

impl fmt::Display for PartId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

/// The shape family of a part, which decides how it fills its cells and
/// where it connects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Shape {
    /// A rectangular brick or plate: studs on every top cell, tubes below.
    Rect,
    /// A slope: studs on its back row only, open below across its whole
    /// footprint. The face falls from the back row (the part's own `+y`,
    /// LDraw `+Z`) to a lip 4 LDU high at the front.
    Slope,
    /// An inverted slope: studs on its whole top, connecting below only
    /// under its back row; the underside rises from the back row to a lip
    /// 4 LDU thick at the front.
    Inverted,
    /// An outside corner slope (double convex, 3045): 2 x 2, full height
    /// only at its back row's `-x` cell, whose one stud it carries; from
    /// there its faces fall two ways, to the front (`-y`) as a slope's do
    /// and to `+x`, meeting along a hip. Open below across its footprint.
    Corner,
    /// An inverted outside corner slope (3676): [`Shape::Corner`] upside
    /// down, studs on its whole top, connecting below only under its
    /// back row's `-x` cell.
    InvertedCorner,
}

impl Shape {
    /// Whether the part's faces slant up to its studs (slopes and corner
    /// slopes; the inverted ones slant under it).
    pub fn is_up(self) -> bool {
        matches!(self, Shape::Slope | Shape::Corner)
    }

    /// Whether the part is a corner slope, up or inverted.
    pub fn is_corner(self) -> bool {
        matches!(self, Shape::Corner | Shape::InvertedCorner)
    }

    /// Whether the part's faces slant under it (inverted slopes).
    pub fn is_inverted(self) -> bool {
        matches!(self, Shape::Inverted | Shape::InvertedCorner)
    }
}

/// How a part's geometry repeats under rotation about the vertical axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Symmetry {
    /// Changed by every turn (slopes).
    None,
    /// Unchanged by a half turn (every rectangular brick and plate).
    HalfTurn,
    /// Unchanged by a quarter turn (square bricks and plates).
    QuarterTurn,
}

/// What a part is, for alphabets and reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Family {
    /// A brick, 24 LDU high.
    Brick,
    /// A plate, 8 LDU high.
    Plate,
    /// A slope or inverted slope.
    Slope,
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
    /// Studs along the part's own x axis (its long side; a slope's width).
    pub studs_x: u8,
    /// Studs along the part's own z axis in LDraw (grid y; a slope's depth,
    /// back row included).
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
        if self.shape != Shape::Rect {
            Symmetry::None
        } else if self.studs_x == self.studs_y {
            Symmetry::QuarterTurn
        } else {
            Symmetry::HalfTurn
        }
    }

    /// The canonical representative of `rot` under this part's symmetry, so
    /// that two placements with the same geometry compare equal.
    pub fn canonical_rot(&self, rot: Rot) -> Rot {
        match self.symmetry() {
            Symmetry::None => rot,
            Symmetry::QuarterTurn => Rot::R0,
            Symmetry::HalfTurn => Rot::from_quarter_turns(rot.quarter_turns() % 2),
        }
    }

    /// Rebrickable's part number: Rebrickable numbers these parts as
    /// BrickLink does (`3040`, not LDraw's `3040b`).
    pub fn rebrickable(&self) -> &'static str {
        self.bricklink
    }

    /// Brick, plate or slope.
    pub fn family(&self) -> Family {
        match (self.shape, self.height_plates) {
            (Shape::Slope | Shape::Inverted | Shape::Corner | Shape::InvertedCorner, _) => {
                Family::Slope
            }
            (Shape::Rect, 1) => Family::Plate,
            _ => Family::Brick,
        }
    }

    /// The cells the part fills turned by `rot` with its bounding box's
    /// minimum corner at `origin`, in a grid of `layer_ldu`-high layers
    /// (24 for bricks, 12 with slopes, 8 with plates). `layer_ldu` must
    /// divide the part's height.
    pub fn body(&self, rot: Rot, origin: Cell, layer_ldu: i32) -> Body {
        debug_assert_eq!(self.height_ldu() % layer_ldu, 0, "{}", self.id);
        let full = (self.height_ldu() / layer_ldu).max(1);
        let (w, d) = (self.studs_x as i32, self.studs_y as i32);
        let bbox = CellBox {
            min: Cell::new(0, 0, 0),
            sx: w,
            sy: d,
            sz: full,
        };
        let row_box = |rows: i32, z: i32, sz: i32| CellBox {
            min: Cell::new(0, d - rows, z),
            sx: w,
            sy: rows,
            sz,
        };
        let local = if self.shape == Shape::Rect {
            Body::solid(bbox)
        } else if self.shape.is_corner() {
            // The full cell (back row, -x) is the whole height; the other
            // three are as high as a 45° slope's front row (the diagonal
            // cell a little less, under the hip, counted the same).
            let low = self.row_layers(layer_ldu)[1];
            let full_cell = |z: i32, sz: i32| CellBox {
                min: Cell::new(0, d - 1, z),
                sx: 1,
                sy: 1,
                sz,
            };
            let (boxes, studs, tubes) = if self.shape == Shape::Corner {
                (
                    vec![CellBox { sz: low, ..bbox }, full_cell(low, full - low)],
                    full_cell(full - 1, 1),
                    CellBox { sz: 1, ..bbox },
                )
            } else {
                (
                    vec![
                        full_cell(0, full - low),
                        CellBox {
                            min: Cell::new(0, 0, full - low),
                            sz: low,
                            ..bbox
                        },
                    ],
                    CellBox {
                        min: Cell::new(0, 0, full - 1),
                        sz: 1,
                        ..bbox
                    },
                    full_cell(0, 1),
                )
            };
            let boxes: Vec<CellBox> = boxes.into_iter().filter(|b| b.sz > 0).collect();
            Body::new(&boxes, bbox, studs, tubes)
        } else {
            let rows = self.row_layers(layer_ldu);
            // Rows filled in layer k, counted from the back: a slope's
            // rows stand on the floor, an inverted slope's hang from the top.
            let filled = |k: i32| match self.shape {
                Shape::Inverted => rows.iter().filter(|&&h| full - h <= k).count() as i32,
                _ => rows.iter().filter(|&&h| h > k).count() as i32,
            };
            let mut boxes: Vec<CellBox> = Vec::with_capacity(MAX_BODY_BOXES);
            for k in 0..full {
                let m = filled(k);
                match boxes.last_mut() {
                    Some(b) if b.sy == m => b.sz += 1,
                    _ => boxes.push(row_box(m, k, 1)),
                }
            }
            let (studs, tubes) = match self.shape {
                Shape::Inverted => (
                    CellBox {
                        min: Cell::new(0, 0, full - 1),
                        sz: 1,
                        ..bbox
                    },
                    row_box(1, 0, 1),
                ),
                _ => (row_box(1, full - 1, 1), CellBox { sz: 1, ..bbox }),
            };
            Body::new(&boxes, bbox, studs, tubes)
        };
        let turned = local.turned(rot);
        let m = turned.bbox.min;
        turned.moved(origin.x - m.x, origin.y - m.y, origin.z - m.z)
    }

    /// The direction, in grid `(x, y)`, from a slope's front to its back
    /// row when turned by `rot`.
    pub fn back(&self, rot: Rot) -> (i32, i32) {
        rot.apply(0, 1)
    }

    /// The directions, in grid `(x, y)`, a slope's faces fall toward when
    /// turned by `rot`: its front for a slope, its front and its `+x`
    /// side for a corner slope; none for a brick or plate.
    pub fn faces(&self, rot: Rot) -> impl Iterator<Item = (i32, i32)> {
        let (bx, by) = self.back(rot);
        let front = (self.shape != Shape::Rect).then_some((-bx, -by));
        let side = self.shape.is_corner().then(|| rot.apply(1, 0));
        front.into_iter().chain(side)
    }

    /// Height in LDU.
    pub fn height_ldu(&self) -> i32 {
        8 * self.height_plates as i32
    }

    /// The number of layers of `layer_ldu` each row of the part fills, back
    /// row first (`rows[0]`), for the rows `0..studs_y`; rectangular parts
    /// fill every row to their full height.
    ///
    /// A slope's face falls linearly from its full height at the front edge
    /// of the back row to a 4 LDU lip at the front edge; a layer of a row
    /// counts as filled when the part fills at least half of it (averaged
    /// over the row), and every row fills at least one layer (the lip). An
    /// inverted slope is the same shape upside down, its layers counted from
    /// the top.
    pub fn row_layers(&self, layer_ldu: i32) -> Vec<i32> {
        let full = self.height_ldu() / layer_ldu;
        let depth = self.studs_y as i32;
        if self.shape == Shape::Rect || depth < 2 {
            return vec![full; depth as usize];
        }
        let run = f64::from(20 * (depth - 1));
        let top = f64::from(self.height_ldu());
        let lip = 4.0;
        let height = |t: f64| top - (top - lip) * t / run;
        let u = f64::from(layer_ldu);
        let mut rows = vec![full];
        for r in 1..depth {
            let mut filled = 0;
            for k in 0..full {
                // Mean fill of layer k over the row, by the midpoint rule.
                let n = 64;
                let mut sum = 0.0;
                for i in 0..n {
                    let t = f64::from(20 * (r - 1)) + 20.0 * (f64::from(i) + 0.5) / f64::from(n);
                    sum += ((height(t) - u * f64::from(k)) / u).clamp(0.0, 1.0);
                }
                if sum / f64::from(n) >= 0.5 {
                    filled = k + 1;
                }
            }
            rows.push(filled.max(1));
        }
        rows
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

/// The layer heights, in LDU, whose bodies [`PartKind::body`] caches.
const CACHED_LAYERS: [i32; 4] = [24, 12, 8, 4];

impl PartKind {
    /// [`PartSpec::body`], from a table computed once per layer height (a
    /// slope's rows take some arithmetic, and the search asks often).
    pub fn body(self, rot: Rot, origin: Cell, layer_ldu: i32) -> Body {
        use std::sync::OnceLock;
        static TABLES: [OnceLock<Vec<Option<Body>>>; 4] = [
            OnceLock::new(),
            OnceLock::new(),
            OnceLock::new(),
            OnceLock::new(),
        ];
        let Some(k) = CACHED_LAYERS.iter().position(|&u| u == layer_ldu) else {
            return self.spec().body(rot, origin, layer_ldu);
        };
        let table = TABLES[k].get_or_init(|| {
            PARTS
                .iter()
                .flat_map(|p| {
                    Rot::ALL.into_iter().map(move |r| {
                        (p.height_ldu() % layer_ldu == 0)
                            .then(|| p.body(r, Cell::new(0, 0, 0), layer_ldu))
                    })
                })
                .collect()
        });
        match table[self.0 as usize * 4 + rot.quarter_turns() as usize] {
            Some(b) => b.moved(origin.x, origin.y, origin.z),
            None => self.spec().body(rot, origin, layer_ldu),
        }
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

macro_rules! plate {
    ($id:literal, $bl:literal, $name:literal, $x:literal, $y:literal, $g:literal) => {
        PartSpec {
            height_plates: 1,
            ..brick!($id, $bl, $name, $x, $y, $g)
        }
    };
}

macro_rules! slope {
    ($id:literal, $bl:literal, $name:literal, $shape:expr, $w:literal, $d:literal, $g:literal) => {
        PartSpec {
            shape: $shape,
            ..brick!($id, $bl, $name, $w, $d, $g)
        }
    };
}

/// The catalog. Masses are the commonly published weights of the parts.
///
/// Slopes give their width as `studs_x` and their depth (back row
/// included) as `studs_y`: LDraw's "Slope Brick 45 2 x 4" (3037) is 4 wide
/// and 2 deep.
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
    plate!("3024", "3024", "Plate 1 x 1", 1, 1, 0.17),
    plate!("3023b", "3023", "Plate 1 x 2", 2, 1, 0.30),
    plate!("3623", "3623", "Plate 1 x 3", 3, 1, 0.42),
    plate!("3710", "3710", "Plate 1 x 4", 4, 1, 0.55),
    plate!("3666", "3666", "Plate 1 x 6", 6, 1, 0.80),
    plate!("3460", "3460", "Plate 1 x 8", 8, 1, 1.05),
    plate!("3022", "3022", "Plate 2 x 2", 2, 2, 0.51),
    plate!("3021", "3021", "Plate 2 x 3", 3, 2, 0.74),
    plate!("3020", "3020", "Plate 2 x 4", 4, 2, 0.97),
    plate!("3795", "3795", "Plate 2 x 6", 6, 2, 1.42),
    plate!("3034", "3034", "Plate 2 x 8", 8, 2, 1.88),
    slope!(
        "3040b",
        "3040",
        "Slope Brick 45 2 x 1",
        Shape::Slope,
        1,
        2,
        0.67
    ),
    slope!(
        "3039",
        "3039",
        "Slope Brick 45 2 x 2",
        Shape::Slope,
        2,
        2,
        1.17
    ),
    slope!(
        "3038",
        "3038",
        "Slope Brick 45 2 x 3",
        Shape::Slope,
        3,
        2,
        1.66
    ),
    slope!(
        "3037",
        "3037",
        "Slope Brick 45 2 x 4",
        Shape::Slope,
        4,
        2,
        2.15
    ),
    slope!(
        "4286",
        "4286",
        "Slope Brick 33 3 x 1",
        Shape::Slope,
        1,
        3,
        0.85
    ),
    slope!(
        "3298",
        "3298",
        "Slope Brick 33 3 x 2",
        Shape::Slope,
        2,
        3,
        1.53
    ),
    slope!(
        "3665a",
        "3665",
        "Slope Brick 45 2 x 1 Inverted",
        Shape::Inverted,
        1,
        2,
        0.68
    ),
    slope!(
        "3660a",
        "3660",
        "Slope Brick 45 2 x 2 Inverted",
        Shape::Inverted,
        2,
        2,
        1.18
    ),
    // The long slopes that cap a roof's run with half the pieces; their
    // masses scaled from the 2 x 4 and 3 x 2 ones (no published weight
    // found).
    slope!(
        "4445",
        "4445",
        "Slope Brick 45 2 x 8",
        Shape::Slope,
        8,
        2,
        4.15
    ),
    slope!(
        "3297",
        "3297",
        "Slope Brick 33 3 x 4",
        Shape::Slope,
        4,
        3,
        2.93
    ),
    // Outside corners, where two rows of slopes meet at a hip (on the
    // rounded tops and undersides of organic models); masses published
    // for the parts: 3045 0.98 g, 3676 1.16 g.
    slope!(
        "3045",
        "3045",
        "Slope Brick 45 2 x 2 Double Convex",
        Shape::Corner,
        2,
        2,
        0.98
    ),
    slope!(
        "3676",
        "3676",
        "Slope Brick 45 2 x 2 Inverted Double Convex",
        Shape::InvertedCorner,
        2,
        2,
        1.16
    ),
];

#[cfg(test)]
mod tests {
    use super::*;

    fn part(id: &str) -> &'static PartSpec {
        PartKind::from_id(id).unwrap().spec()
    }

    #[test]
    fn slope_rows_follow_the_measured_faces() {
        // 45 degrees: the front row is half filled at 12 LDU a layer, two
        // of three plates at 8.
        assert_eq!(part("3039").row_layers(12), vec![2, 1]);
        assert_eq!(part("3039").row_layers(8), vec![3, 2]);
        // 33 degrees: the middle row is mostly full.
        assert_eq!(part("3298").row_layers(12), vec![2, 2, 1]);
        assert_eq!(part("4286").row_layers(8), vec![3, 2, 1]);
        assert_eq!(part("3001").row_layers(24), vec![1, 1]);
    }

    #[test]
    fn slope_bodies_have_studs_on_the_back_row_only() {
        let s = part("3039");
        let b = s.body(Rot::R0, Cell::new(0, 0, 0), 12);
        assert_eq!(b.volume(), 2 * 2 + 2);
        assert!(b.contains(Cell::new(0, 1, 1)) && !b.contains(Cell::new(0, 0, 1)));
        assert_eq!(b.studs.min, Cell::new(0, 1, 1));
        assert_eq!((b.studs.sx, b.studs.sy), (2, 1));
        assert_eq!((b.tubes.sx, b.tubes.sy), (2, 2));
        // Turned a half turn the back row is at the low y.
        let t = s.body(Rot::R180, Cell::new(5, 5, 0), 12);
        assert_eq!(t.bbox.min, Cell::new(5, 5, 0));
        assert!(t.contains(Cell::new(5, 5, 1)) && !t.contains(Cell::new(5, 6, 1)));
        assert_eq!(s.back(Rot::R180), (0, -1));
        // An inverted slope hangs its front row from the top and connects
        // below only under its back row.
        let inv = part("3665a").body(Rot::R0, Cell::new(0, 0, 0), 12);
        assert!(inv.contains(Cell::new(0, 0, 1)) && !inv.contains(Cell::new(0, 0, 0)));
        assert_eq!(inv.key(), Cell::new(0, 1, 0));
        assert_eq!((inv.tubes.min, inv.tubes.sy), (Cell::new(0, 1, 0), 1));
        assert_eq!((inv.studs.sy, inv.studs.min.z), (2, 1));
        // A brick is one box; a plate one layer at 8 LDU.
        assert!(part("3001").body(Rot::R90, Cell::new(0, 0, 0), 24).is_box());
        assert_eq!(part("3020").body(Rot::R0, Cell::new(0, 0, 0), 8).bbox.sz, 1);
        assert_eq!(part("3001").body(Rot::R0, Cell::new(0, 0, 0), 8).bbox.sz, 3);
    }

    #[test]
    fn corner_slopes_are_full_at_one_cell_and_fall_two_ways() {
        let c = part("3045");
        let b = c.body(Rot::R0, Cell::new(0, 0, 0), 12);
        // The full cell, back row at -x, two layers; the other three one.
        assert_eq!(b.volume(), 4 + 1);
        assert!(b.contains(Cell::new(0, 1, 1)));
        for q in [Cell::new(1, 1, 1), Cell::new(0, 0, 1), Cell::new(1, 0, 1)] {
            assert!(!b.contains(q) && b.contains(q.offset(0, 0, -1)), "{q:?}");
        }
        assert_eq!(
            (b.studs.min, b.studs.sx, b.studs.sy),
            (Cell::new(0, 1, 1), 1, 1)
        );
        assert_eq!((b.tubes.sx, b.tubes.sy, b.tubes.min.z), (2, 2, 0));
        assert_eq!(c.faces(Rot::R0).collect::<Vec<_>>(), vec![(0, -1), (1, 0)]);
        assert_eq!(c.faces(Rot::R90).collect::<Vec<_>>(), vec![(1, 0), (0, 1)]);
        assert_eq!(c.family(), Family::Slope);
        // At 8 LDU a layer: three plates at the full cell, two elsewhere.
        assert_eq!(c.body(Rot::R0, Cell::new(0, 0, 0), 8).volume(), 3 + 3 * 2);
        // Upside down: studs on the whole top, held below at the full cell.
        let inv = part("3676").body(Rot::R0, Cell::new(0, 0, 0), 12);
        assert_eq!(inv.volume(), 4 + 1);
        assert!(inv.contains(Cell::new(0, 1, 0)) && !inv.contains(Cell::new(1, 0, 0)));
        assert_eq!(
            (inv.tubes.min, inv.tubes.sx, inv.tubes.sy),
            (Cell::new(0, 1, 0), 1, 1)
        );
        assert_eq!((inv.studs.sx, inv.studs.sy, inv.studs.min.z), (2, 2, 1));
        // A brick's faces fall nowhere; a slope's to its front.
        assert_eq!(part("3001").faces(Rot::R0).count(), 0);
        assert_eq!(
            part("3039").faces(Rot::R180).collect::<Vec<_>>(),
            vec![(0, 1)]
        );
    }

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
