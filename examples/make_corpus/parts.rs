//! The parts the corpus uses, and how a part sits on the stud grid.
//!
//! The grid counts studs along LDraw x and z and plates up (a brick is 3
//! plates). A piece is placed by the stud cell of its footprint's minimum
//! corner, the height of its underside in plates and a turn about the
//! vertical axis; [`Placed`] turns that into the LDraw origin and matrix and
//! into the cells the piece fills, carries studs on and connects with
//! underneath.
//!
//! Geometry, as measured from the part files: bricks and plates have their
//! origin at the centre of the top face, the long side along x. Slopes and
//! inverted slopes have their origin at the centre of the studded back row
//! and run toward -z at no turn.

/// How a part connects, which decides where its studs and its underside are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A rectangular brick or plate: studs on every top cell, connects on
    /// every cell underneath.
    Rect,
    /// A slope: studs on the back row only, connects on every cell
    /// underneath.
    Slope,
    /// An inverted slope: studs on every top cell, connects underneath only
    /// under the back row.
    Inverted,
}

/// One entry of the parts table.
#[derive(Debug, Clone, Copy)]
pub struct Spec {
    /// LDraw file name without `.dat`.
    pub file: &'static str,
    /// Studs along the part's own x axis.
    pub wide: i32,
    /// Studs along the part's own z axis (for slopes: back row plus slope).
    pub deep: i32,
    /// Height in plates.
    pub plates: i32,
    /// Connection family.
    pub kind: Kind,
}

/// Every part the corpus may use. Brick and plate names read `<deep>x<wide>`
/// as LEGO names them; slope names give the angle and the width in studs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[rustfmt::skip]
pub enum Part {
    Brick1x1, Brick1x2, Brick1x3, Brick1x4, Brick1x6, Brick1x8,
    Brick2x2, Brick2x3, Brick2x4, Brick2x6, Brick2x8,
    Plate1x1, Plate1x2, Plate1x3, Plate1x4, Plate1x6, Plate1x8,
    Plate2x2, Plate2x3, Plate2x4, Plate2x6, Plate2x8,
    /// 45 degrees, 2 deep x 1 wide (3040b).
    Slope45x1,
    /// 45 degrees, 2 deep x 2 wide (3039).
    Slope45x2,
    /// 45 degrees, 2 deep x 3 wide (3038).
    Slope45x3,
    /// 45 degrees, 2 deep x 4 wide (3037).
    Slope45x4,
    /// 33 degrees, 3 deep x 1 wide (4286).
    Slope33x1,
    /// 33 degrees, 3 deep x 2 wide (3298).
    Slope33x2,
    /// Inverted 45 degrees, 2 deep x 1 wide (3665a).
    Inverted45x1,
    /// Inverted 45 degrees, 2 deep x 2 wide (3660a).
    Inverted45x2,
}

impl Part {
    /// Every part, in table order (the order of the README's totals).
    #[rustfmt::skip]
    pub const ALL: [Part; 30] = [
        Part::Brick1x1, Part::Brick1x2, Part::Brick1x3, Part::Brick1x4, Part::Brick1x6,
        Part::Brick1x8, Part::Brick2x2, Part::Brick2x3, Part::Brick2x4, Part::Brick2x6,
        Part::Brick2x8, Part::Plate1x1, Part::Plate1x2, Part::Plate1x3, Part::Plate1x4,
        Part::Plate1x6, Part::Plate1x8, Part::Plate2x2, Part::Plate2x3, Part::Plate2x4,
        Part::Plate2x6, Part::Plate2x8, Part::Slope45x1, Part::Slope45x2, Part::Slope45x3,
        Part::Slope45x4, Part::Slope33x1, Part::Slope33x2, Part::Inverted45x1,
        Part::Inverted45x2,
    ];

    /// The part's table entry.
    pub fn spec(self) -> Spec {
        use Kind::{Inverted, Rect, Slope};
        let (file, wide, deep, plates, kind) = match self {
            Part::Brick1x1 => ("3005", 1, 1, 3, Rect),
            Part::Brick1x2 => ("3004", 2, 1, 3, Rect),
            Part::Brick1x3 => ("3622", 3, 1, 3, Rect),
            Part::Brick1x4 => ("3010", 4, 1, 3, Rect),
            Part::Brick1x6 => ("3009", 6, 1, 3, Rect),
            Part::Brick1x8 => ("3008", 8, 1, 3, Rect),
            Part::Brick2x2 => ("3003", 2, 2, 3, Rect),
            Part::Brick2x3 => ("3002", 3, 2, 3, Rect),
            Part::Brick2x4 => ("3001", 4, 2, 3, Rect),
            Part::Brick2x6 => ("2456", 6, 2, 3, Rect),
            Part::Brick2x8 => ("3007", 8, 2, 3, Rect),
            Part::Plate1x1 => ("3024", 1, 1, 1, Rect),
            Part::Plate1x2 => ("3023b", 2, 1, 1, Rect),
            Part::Plate1x3 => ("3623", 3, 1, 1, Rect),
            Part::Plate1x4 => ("3710", 4, 1, 1, Rect),
            Part::Plate1x6 => ("3666", 6, 1, 1, Rect),
            Part::Plate1x8 => ("3460", 8, 1, 1, Rect),
            Part::Plate2x2 => ("3022", 2, 2, 1, Rect),
            Part::Plate2x3 => ("3021", 3, 2, 1, Rect),
            Part::Plate2x4 => ("3020", 4, 2, 1, Rect),
            Part::Plate2x6 => ("3795", 6, 2, 1, Rect),
            Part::Plate2x8 => ("3034", 8, 2, 1, Rect),
            Part::Slope45x1 => ("3040b", 1, 2, 3, Slope),
            Part::Slope45x2 => ("3039", 2, 2, 3, Slope),
            Part::Slope45x3 => ("3038", 3, 2, 3, Slope),
            Part::Slope45x4 => ("3037", 4, 2, 3, Slope),
            Part::Slope33x1 => ("4286", 1, 3, 3, Slope),
            Part::Slope33x2 => ("3298", 2, 3, 3, Slope),
            Part::Inverted45x1 => ("3665a", 1, 2, 3, Inverted),
            Part::Inverted45x2 => ("3660a", 2, 2, 3, Inverted),
        };
        Spec {
            file,
            wide,
            deep,
            plates,
            kind,
        }
    }

    /// The brick `deep` x `long` studs, if there is one.
    pub fn brick(deep: i32, long: i32) -> Option<Part> {
        Part::ALL.into_iter().find(|p| {
            let s = p.spec();
            s.kind == Kind::Rect && s.plates == 3 && s.deep == deep && s.wide == long
        })
    }

    /// The plate `deep` x `long` studs, if there is one.
    pub fn plate(deep: i32, long: i32) -> Option<Part> {
        Part::ALL.into_iter().find(|p| {
            let s = p.spec();
            s.kind == Kind::Rect && s.plates == 1 && s.deep == deep && s.wide == long
        })
    }
}

/// A turn about the vertical axis. A slope at `R0` runs down toward -z,
/// at `R90` toward -x, at `R180` toward +z and at `R270` toward +x.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Turn {
    /// No turn.
    R0,
    /// A quarter turn: the part's x axis along world z.
    R90,
    /// A half turn.
    R180,
    /// Three quarters.
    R270,
}

impl Turn {
    /// The LDraw rotation matrix, row-major.
    pub fn matrix(self) -> [[i32; 3]; 3] {
        match self {
            Turn::R0 => [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
            Turn::R90 => [[0, 0, 1], [0, 1, 0], [-1, 0, 0]],
            Turn::R180 => [[-1, 0, 0], [0, 1, 0], [0, 0, -1]],
            Turn::R270 => [[0, 0, -1], [0, 1, 0], [1, 0, 0]],
        }
    }

    /// A horizontal vector `(x, z)` of the part's frame in world axes.
    fn apply(self, (x, z): (i32, i32)) -> (i32, i32) {
        let m = self.matrix();
        (m[0][0] * x + m[0][2] * z, m[2][0] * x + m[2][2] * z)
    }
}

/// An LDraw colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Colour {
    /// 1
    Blue,
    /// 2
    Green,
    /// 4
    Red,
    /// 14
    Yellow,
    /// 15
    White,
    /// 19
    Tan,
    /// 70
    ReddishBrown,
    /// 71
    LightBluishGrey,
    /// 72
    DarkBluishGrey,
}

impl Colour {
    /// The LDraw colour code.
    pub fn code(self) -> u16 {
        match self {
            Colour::Blue => 1,
            Colour::Green => 2,
            Colour::Red => 4,
            Colour::Yellow => 14,
            Colour::White => 15,
            Colour::Tan => 19,
            Colour::ReddishBrown => 70,
            Colour::LightBluishGrey => 71,
            Colour::DarkBluishGrey => 72,
        }
    }
}

/// LDraw units per stud.
const LDU_PER_STUD: i32 = 20;
/// LDraw units per plate height.
const LDU_PER_PLATE: i32 = 8;

/// One piece of a build.
#[derive(Debug, Clone, Copy)]
pub struct Placed {
    /// What it is.
    pub part: Part,
    /// Stud cell of the footprint's minimum x.
    pub x: i32,
    /// Stud cell of the footprint's minimum z.
    pub z: i32,
    /// Height of the underside above the table, in plates.
    pub h: i32,
    /// Turn about the vertical axis.
    pub turn: Turn,
    /// Colour.
    pub colour: Colour,
}

/// A cell of the part's own footprint: its centre in the part's frame (LDU)
/// and whether it lies in the back row.
struct LocalCell {
    centre: (i32, i32),
    back_row: bool,
}

impl Placed {
    /// Footprint `(along x, along z)` in studs.
    pub fn footprint(&self) -> (i32, i32) {
        let s = self.part.spec();
        match self.turn {
            Turn::R0 | Turn::R180 => (s.wide, s.deep),
            Turn::R90 | Turn::R270 => (s.deep, s.wide),
        }
    }

    /// Height of the top face in plates.
    pub fn top(&self) -> i32 {
        self.h + self.part.spec().plates
    }

    /// The part's bounding box in its own frame, `(min x, max x, min z, max z)`
    /// in LDU.
    fn local_box(&self) -> (i32, i32, i32, i32) {
        let s = self.part.spec();
        let half_x = s.wide * LDU_PER_STUD / 2;
        match s.kind {
            Kind::Rect => {
                let half_z = s.deep * LDU_PER_STUD / 2;
                (-half_x, half_x, -half_z, half_z)
            }
            Kind::Slope | Kind::Inverted => {
                let back = LDU_PER_STUD / 2;
                (-half_x, half_x, back - s.deep * LDU_PER_STUD, back)
            }
        }
    }

    fn local_cells(&self) -> Vec<LocalCell> {
        let (x0, _, _, z1) = self.local_box();
        let s = self.part.spec();
        let mut cells = Vec::new();
        for u in 0..s.wide {
            for v in 0..s.deep {
                let centre = (
                    x0 + LDU_PER_STUD / 2 + u * LDU_PER_STUD,
                    z1 - LDU_PER_STUD / 2 - v * LDU_PER_STUD,
                );
                // For slopes v = 0 is the studded back row; for rectangular
                // parts the flag is unused.
                cells.push(LocalCell {
                    centre,
                    back_row: v == 0,
                });
            }
        }
        cells
    }

    /// The LDraw origin `(x, y, z)` in LDU.
    pub fn origin(&self) -> (i32, i32, i32) {
        let (x0, x1, z0, z1) = self.local_box();
        let corners = [(x0, z0), (x0, z1), (x1, z0), (x1, z1)].map(|c| self.turn.apply(c));
        let min_x = corners.iter().map(|c| c.0).min().unwrap_or(0);
        let min_z = corners.iter().map(|c| c.1).min().unwrap_or(0);
        (
            self.x * LDU_PER_STUD - min_x,
            -self.top() * LDU_PER_PLATE,
            self.z * LDU_PER_STUD - min_z,
        )
    }

    /// World stud cells `(x, z)` of the local cells that pass `keep`.
    fn world_cells(&self, keep: impl Fn(&LocalCell) -> bool) -> Vec<(i32, i32)> {
        let (ox, _, oz) = self.origin();
        let mut out: Vec<(i32, i32)> = self
            .local_cells()
            .iter()
            .filter(|c| keep(c))
            .map(|c| {
                let (dx, dz) = self.turn.apply(c.centre);
                let (wx, wz) = (ox + dx, oz + dz);
                (
                    (wx - LDU_PER_STUD / 2) / LDU_PER_STUD,
                    (wz - LDU_PER_STUD / 2) / LDU_PER_STUD,
                )
            })
            .collect();
        out.sort_unstable();
        out
    }

    /// Every cell of the footprint.
    pub fn cells(&self) -> Vec<(i32, i32)> {
        self.world_cells(|_| true)
    }

    /// The cells with studs on top.
    pub fn studs(&self) -> Vec<(i32, i32)> {
        match self.part.spec().kind {
            Kind::Slope => self.world_cells(|c| c.back_row),
            Kind::Rect | Kind::Inverted => self.cells(),
        }
    }

    /// The cells whose underside takes studs.
    pub fn underside(&self) -> Vec<(i32, i32)> {
        match self.part.spec().kind {
            Kind::Inverted => self.world_cells(|c| c.back_row),
            Kind::Rect | Kind::Slope => self.cells(),
        }
    }

    /// The cells under the slanted face: above them for a slope, below them
    /// for an inverted slope.
    pub fn slanted(&self) -> Vec<(i32, i32)> {
        match self.part.spec().kind {
            Kind::Rect => Vec::new(),
            Kind::Slope | Kind::Inverted => self.world_cells(|c| !c.back_row),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(part: Part, turn: Turn) -> Placed {
        Placed {
            part,
            x: 0,
            z: 0,
            h: 0,
            turn,
            colour: Colour::Red,
        }
    }

    #[test]
    fn a_brick_at_the_origin_cell() {
        let p = at(Part::Brick2x4, Turn::R0);
        assert_eq!(p.origin(), (40, -24, 20));
        assert_eq!(at(Part::Brick2x4, Turn::R90).origin(), (20, -24, 40));
        assert_eq!(at(Part::Brick1x3, Turn::R0).origin(), (30, -24, 10));
        assert_eq!(p.cells().len(), 8);
    }

    #[test]
    fn slopes_have_studs_on_the_back_row() {
        // 3039 spans z -30..10 about its origin: placed at cell z 0 its
        // origin is at z 30, its back row the cells z = 1.
        let p = at(Part::Slope45x2, Turn::R0);
        assert_eq!(p.origin(), (20, -24, 30));
        assert_eq!(p.studs(), vec![(0, 1), (1, 1)]);
        assert_eq!(p.slanted(), vec![(0, 0), (1, 0)]);
        // A half turn: the back row is the low z side, the slope runs to +z.
        let q = at(Part::Slope45x2, Turn::R180);
        assert_eq!(q.studs(), vec![(0, 0), (1, 0)]);
        // A quarter turn runs the slope toward -x.
        let r = at(Part::Slope33x1, Turn::R90);
        assert_eq!(r.footprint(), (3, 1));
        assert_eq!(r.studs(), vec![(2, 0)]);
    }

    #[test]
    fn inverted_slopes_connect_under_the_back_row() {
        let p = at(Part::Inverted45x2, Turn::R0);
        assert_eq!(p.studs().len(), 4);
        assert_eq!(p.underside(), vec![(0, 1), (1, 1)]);
    }
}
