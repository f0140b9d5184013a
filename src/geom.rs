//! Integer grid geometry shared by every stage: cells, orientations, boxes.
//!
//! The voxel grid is right-handed with `x` and `y` horizontal (one stud each)
//! and `z` vertical (one layer each, 1.2 studs for bricks). A piece's place is
//! the minimum corner of its bounding box of cells plus its [`Rot`] about the
//! vertical axis. LDraw's axes are derived from these in `export::ldraw`.

use serde::Serialize;

/// The six face neighbours' offsets of a cell: along x, y, then z.
pub const FACES: [(i32, i32, i32); 6] = [
    (1, 0, 0),
    (-1, 0, 0),
    (0, 1, 0),
    (0, -1, 0),
    (0, 0, 1),
    (0, 0, -1),
];

/// A set of cells hashed cheaply (see [`crate::keyhash`]): the
/// placeability searches test millions of cells.
pub(crate) type CellSet = crate::keyhash::KeySet<Cell>;

/// A voxel cell (or a piece's minimum corner) in grid coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct Cell {
    /// Stud column along the grid's x axis.
    pub x: i32,
    /// Stud row along the grid's y axis.
    pub y: i32,
    /// Layer, counted upward from 0.
    pub z: i32,
}

impl Cell {
    /// A cell from its three coordinates.
    pub const fn new(x: i32, y: i32, z: i32) -> Self {
        Cell { x, y, z }
    }

    /// This cell moved by `(dx, dy, dz)`.
    pub const fn offset(self, dx: i32, dy: i32, dz: i32) -> Self {
        Cell::new(self.x + dx, self.y + dy, self.z + dz)
    }
}

/// A quarter-turn rotation about the vertical axis, counter-clockwise seen
/// from above.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Rot {
    /// The part as drawn in its library file.
    R0,
    /// A quarter turn.
    R90,
    /// A half turn.
    R180,
    /// Three quarter turns.
    R270,
}

impl Rot {
    /// All four rotations, in order.
    pub const ALL: [Rot; 4] = [Rot::R0, Rot::R90, Rot::R180, Rot::R270];

    /// The number of quarter turns.
    pub const fn quarter_turns(self) -> u8 {
        match self {
            Rot::R0 => 0,
            Rot::R90 => 1,
            Rot::R180 => 2,
            Rot::R270 => 3,
        }
    }

    /// The rotation with `n` quarter turns (taken modulo 4).
    pub const fn from_quarter_turns(n: u8) -> Rot {
        match n % 4 {
            0 => Rot::R0,
            1 => Rot::R90,
            2 => Rot::R180,
            _ => Rot::R270,
        }
    }

    /// This rotation followed by `other`.
    pub const fn then(self, other: Rot) -> Rot {
        Rot::from_quarter_turns(self.quarter_turns() + other.quarter_turns())
    }

    /// Whether the footprint's width and depth swap.
    pub const fn swaps_axes(self) -> bool {
        matches!(self, Rot::R90 | Rot::R270)
    }

    /// The rotation's angle in degrees.
    pub const fn degrees(self) -> u16 {
        self.quarter_turns() as u16 * 90
    }

    /// Parses `r0`, `r90`, `r180` or `r270`.
    pub fn parse(s: &str) -> Option<Rot> {
        match s {
            "r0" => Some(Rot::R0),
            "r90" => Some(Rot::R90),
            "r180" => Some(Rot::R180),
            "r270" => Some(Rot::R270),
            _ => None,
        }
    }

    /// The form [`Rot::parse`] reads.
    pub const fn name(self) -> &'static str {
        match self {
            Rot::R0 => "r0",
            Rot::R90 => "r90",
            Rot::R180 => "r180",
            Rot::R270 => "r270",
        }
    }

    /// Rotates the horizontal vector `(x, y)` by this rotation.
    pub const fn apply(self, x: i32, y: i32) -> (i32, i32) {
        match self {
            Rot::R0 => (x, y),
            Rot::R90 => (-y, x),
            Rot::R180 => (-x, -y),
            Rot::R270 => (y, -x),
        }
    }
}

/// An axis-aligned box of cells, `min` inclusive, `size` cells along each axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct CellBox {
    /// The minimum corner.
    pub min: Cell,
    /// Extent along x, in cells (at least 1).
    pub sx: i32,
    /// Extent along y, in cells (at least 1).
    pub sy: i32,
    /// Extent along z, in cells (at least 1).
    pub sz: i32,
}

impl CellBox {
    /// The exclusive maximum corner.
    pub const fn max_excl(&self) -> Cell {
        self.min.offset(self.sx, self.sy, self.sz)
    }

    /// Number of cells in the box.
    pub const fn volume(&self) -> i32 {
        self.sx * self.sy * self.sz
    }

    /// Whether `c` lies inside the box.
    pub const fn contains(&self, c: Cell) -> bool {
        c.x >= self.min.x
            && c.y >= self.min.y
            && c.z >= self.min.z
            && c.x < self.min.x + self.sx
            && c.y < self.min.y + self.sy
            && c.z < self.min.z + self.sz
    }

    /// Whether the two boxes share a cell.
    pub const fn intersects(&self, o: &CellBox) -> bool {
        self.min.x < o.min.x + o.sx
            && o.min.x < self.min.x + self.sx
            && self.min.y < o.min.y + o.sy
            && o.min.y < self.min.y + self.sy
            && self.min.z < o.min.z + o.sz
            && o.min.z < self.min.z + self.sz
    }

    /// The smallest box holding both.
    pub fn union(&self, o: &CellBox) -> CellBox {
        let (a, b) = (self.max_excl(), o.max_excl());
        let min = Cell::new(
            self.min.x.min(o.min.x),
            self.min.y.min(o.min.y),
            self.min.z.min(o.min.z),
        );
        CellBox {
            min,
            sx: a.x.max(b.x) - min.x,
            sy: a.y.max(b.y) - min.y,
            sz: a.z.max(b.z) - min.z,
        }
    }

    /// Whether the footprints (x, y) of the two boxes overlap.
    pub const fn footprints_overlap(&self, o: &CellBox) -> bool {
        self.min.x < o.min.x + o.sx
            && o.min.x < self.min.x + self.sx
            && self.min.y < o.min.y + o.sy
            && o.min.y < self.min.y + self.sy
    }

    /// The one-layer box directly below this one's footprint.
    pub const fn layer_below(&self) -> CellBox {
        CellBox {
            min: self.min.offset(0, 0, -1),
            sz: 1,
            ..*self
        }
    }

    /// The one-layer box directly above this one's footprint.
    pub const fn layer_above(&self) -> CellBox {
        CellBox {
            min: self.min.offset(0, 0, self.sz),
            sz: 1,
            ..*self
        }
    }

    /// Every one-layer box of the given footprints that covers `u`.
    pub fn covering(u: Cell, footprints: &[(i32, i32)]) -> impl Iterator<Item = CellBox> + '_ {
        footprints.iter().flat_map(move |&(sx, sy)| {
            (0..sy).flat_map(move |oy| {
                (0..sx).map(move |ox| CellBox {
                    min: u.offset(-ox, -oy, 0),
                    sx,
                    sy,
                    sz: 1,
                })
            })
        })
    }

    /// Every cell of the box, x fastest, then y, then z.
    pub fn cells(&self) -> impl Iterator<Item = Cell> + '_ {
        let m = self.min;
        (0..self.sz).flat_map(move |dz| {
            (0..self.sy).flat_map(move |dy| (0..self.sx).map(move |dx| m.offset(dx, dy, dz)))
        })
    }
}

impl CellBox {
    /// The box turned by `rot` about the vertical axis through the origin
    /// (cell corners turn, so a box `[0, 2) x [0, 1)` turned a quarter is
    /// `[-1, 0) x [0, 2)`).
    pub const fn turned(&self, rot: Rot) -> CellBox {
        let (x0, y0) = (self.min.x, self.min.y);
        let (x1, y1) = (self.min.x + self.sx, self.min.y + self.sy);
        let (ax, ay) = rot.apply(x0, y0);
        let (bx, by) = rot.apply(x1, y1);
        CellBox {
            min: Cell::new(
                if ax < bx { ax } else { bx },
                if ay < by { ay } else { by },
                self.min.z,
            ),
            sx: (ax - bx).abs(),
            sy: (ay - by).abs(),
            sz: self.sz,
        }
    }

    /// The box moved by `(dx, dy, dz)`.
    pub const fn moved(&self, dx: i32, dy: i32, dz: i32) -> CellBox {
        CellBox {
            min: self.min.offset(dx, dy, dz),
            ..*self
        }
    }
}

/// Most boxes a [`Body`] is made of: one per distinct row height.
pub const MAX_BODY_BOXES: usize = 3;

/// The cells one placed piece fills and where it connects: a union of at
/// most [`MAX_BODY_BOXES`] disjoint boxes (one for a brick or plate, one
/// per terrace of a slope), bottom box first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Body {
    boxes: [CellBox; MAX_BODY_BOXES],
    n: u8,
    /// The bounding box: what the piece takes up in space (a slope's
    /// sloping face passes through the cells of its box it does not fill).
    pub bbox: CellBox,
    /// The top-layer cells that carry studs.
    pub studs: CellBox,
    /// The bottom-layer cells that take studs from below.
    pub tubes: CellBox,
}

impl Body {
    /// A body from its boxes (bottom first), bounding box and connection
    /// boxes.
    pub fn new(boxes: &[CellBox], bbox: CellBox, studs: CellBox, tubes: CellBox) -> Body {
        assert!(!boxes.is_empty() && boxes.len() <= MAX_BODY_BOXES);
        let mut b = [boxes[0]; MAX_BODY_BOXES];
        b[..boxes.len()].copy_from_slice(boxes);
        Body {
            boxes: b,
            n: boxes.len() as u8,
            bbox,
            studs,
            tubes,
        }
    }

    /// A plain box: a brick or plate.
    pub fn solid(b: CellBox) -> Body {
        Body::new(
            &[b],
            b,
            CellBox {
                min: b.min.offset(0, 0, b.sz - 1),
                sz: 1,
                ..b
            },
            CellBox { sz: 1, ..b },
        )
    }

    /// The disjoint boxes the piece fills.
    pub fn boxes(&self) -> &[CellBox] {
        &self.boxes[..self.n as usize]
    }

    /// Whether the piece fills its whole bounding box.
    pub fn is_box(&self) -> bool {
        self.n == 1 && self.boxes[0] == self.bbox
    }

    /// Every cell the piece fills.
    pub fn cells(&self) -> impl Iterator<Item = Cell> + '_ {
        self.boxes().iter().flat_map(|b| b.cells())
    }

    /// Number of cells filled.
    pub fn volume(&self) -> i32 {
        self.boxes().iter().map(CellBox::volume).sum()
    }

    /// Whether the piece fills `c`.
    pub fn contains(&self, c: Cell) -> bool {
        self.boxes().iter().any(|b| b.contains(c))
    }

    /// A filled cell every placement of the same part and turn has at the
    /// same place relative to its origin: the first cell of the bottom box.
    pub fn key(&self) -> Cell {
        self.boxes[0].min
    }

    /// The cells just above the studs: where a piece pressed on top sits.
    pub fn over_studs(&self) -> CellBox {
        self.studs.layer_above()
    }

    /// The cells just below the tubes: where a piece it is pressed onto sits.
    pub fn under_tubes(&self) -> CellBox {
        self.tubes.layer_below()
    }

    /// Whether `upper` is pressed onto this piece's studs.
    pub fn holds(&self, upper: &Body) -> bool {
        self.over_studs().intersects(&upper.tubes)
    }

    /// The body moved by `(dx, dy, dz)`.
    pub fn moved(&self, dx: i32, dy: i32, dz: i32) -> Body {
        let mut b = *self;
        for x in b.boxes.iter_mut() {
            *x = x.moved(dx, dy, dz);
        }
        b.bbox = b.bbox.moved(dx, dy, dz);
        b.studs = b.studs.moved(dx, dy, dz);
        b.tubes = b.tubes.moved(dx, dy, dz);
        b
    }

    /// The body turned by `rot` about the vertical axis through the origin.
    pub fn turned(&self, rot: Rot) -> Body {
        let mut b = *self;
        for x in b.boxes.iter_mut() {
            *x = x.turned(rot);
        }
        b.bbox = b.bbox.turned(rot);
        b.studs = b.studs.turned(rot);
        b.tubes = b.tubes.turned(rot);
        b
    }
}
