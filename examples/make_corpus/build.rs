//! A build: pieces in the order a person places them, and the helpers the
//! build declarations use to lay courses.

use std::fmt::Write as _;

use crate::parts::{Colour, Part, Placed, Turn};

/// Plates per brick course.
pub const COURSE: i32 = 3;

/// Which walls of a ring run through its corners.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Corners {
    /// Front and back run the full length; the sides fit between them.
    FrontBack,
    /// The sides run the full depth; front and back fit between them.
    Sides,
}

/// The direction a row of pieces is laid in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dir {
    /// Toward +x.
    East,
    /// Toward -x.
    West,
    /// Toward +z.
    South,
    /// Toward -z.
    North,
}

/// One build of the corpus.
#[derive(Debug, Clone)]
pub struct Build {
    /// File stem of the `.ldr` file.
    pub name: &'static str,
    /// The model's title.
    pub title: &'static str,
    /// One line on what the build shows (header comment and README).
    pub about: &'static str,
    /// Pieces in placing order, one a step.
    pub pieces: Vec<Placed>,
    colour: Colour,
}

impl Build {
    /// An empty build laid in `colour` until [`Build::colour`] changes it.
    pub fn new(
        name: &'static str,
        title: &'static str,
        about: &'static str,
        colour: Colour,
    ) -> Build {
        Build {
            name,
            title,
            about,
            pieces: Vec::new(),
            colour,
        }
    }

    /// Lays the following pieces in `colour`.
    pub fn colour(&mut self, colour: Colour) {
        self.colour = colour;
    }

    /// Places `part` with its footprint's minimum corner at stud cell
    /// `(x, z)`, its underside `h` plates above the table, turned by `turn`.
    pub fn put(&mut self, part: Part, x: i32, z: i32, h: i32, turn: Turn) {
        self.pieces.push(Placed {
            part,
            x,
            z,
            h,
            turn,
            colour: self.colour,
        });
    }

    /// Lays `parts` one after another along `dir`, turned by `turn`, and
    /// returns where the row ends.
    ///
    /// The row starts at the edge `(x, z)`: for `East` and `South` that is
    /// the minimum corner of the first piece; for `West` the first piece ends
    /// at `x` (exclusive), for `North` at `z`. Across the row, `z` (or `x`)
    /// is the minimum cell.
    pub fn lay(&mut self, h: i32, (x, z): (i32, i32), dir: Dir, turn: Turn, parts: &[Part]) -> i32 {
        let mut at = match dir {
            Dir::East | Dir::West => x,
            Dir::South | Dir::North => z,
        };
        for &part in parts {
            let probe = Placed {
                part,
                x: 0,
                z: 0,
                h,
                turn,
                colour: self.colour,
            };
            let (fx, fz) = probe.footprint();
            match dir {
                Dir::East => {
                    self.put(part, at, z, h, turn);
                    at += fx;
                }
                Dir::West => {
                    at -= fx;
                    self.put(part, at, z, h, turn);
                }
                Dir::South => {
                    self.put(part, x, at, h, turn);
                    at += fz;
                }
                Dir::North => {
                    at -= fz;
                    self.put(part, x, at, h, turn);
                }
            }
        }
        at
    }

    /// Lays bricks `deep` studs wide of the given lengths along `dir`, long
    /// side along the row; a negative length leaves that many studs open (a
    /// door, a window). Returns where the row ends.
    pub fn bricks(&mut self, h: i32, at: (i32, i32), dir: Dir, deep: i32, lengths: &[i32]) -> i32 {
        self.row(h, at, dir, lengths, |n| {
            Part::brick(deep, n).unwrap_or_else(|| panic!("no brick {deep} x {n}"))
        })
    }

    /// Lays plates `deep` studs wide of the given lengths along `dir`, as
    /// [`Build::bricks`] does.
    pub fn plates(&mut self, h: i32, at: (i32, i32), dir: Dir, deep: i32, lengths: &[i32]) -> i32 {
        self.row(h, at, dir, lengths, |n| {
            Part::plate(deep, n).unwrap_or_else(|| panic!("no plate {deep} x {n}"))
        })
    }

    fn row(
        &mut self,
        h: i32,
        (x, z): (i32, i32),
        dir: Dir,
        lengths: &[i32],
        part: impl Fn(i32) -> Part,
    ) -> i32 {
        let forward = matches!(dir, Dir::East | Dir::South);
        let mut at = match dir {
            Dir::East | Dir::West => x,
            Dir::South | Dir::North => z,
        };
        for &n in lengths {
            if n < 0 {
                at += if forward { -n } else { n };
                continue;
            }
            let start = match dir {
                Dir::East | Dir::West => (at, z),
                Dir::South | Dir::North => (x, at),
            };
            at = self.lay(h, start, dir, along(dir), &[part(n)]);
        }
        at
    }

    /// One course of a wall one stud thick around the rectangle with outer
    /// corners `(x0, z0)` and `(x1, z1)` (exclusive), laid the way a person
    /// goes round: the front (`z0`) toward +x, the right side (`x1 - 1`)
    /// toward +z, the back (`z1 - 1`) toward -x, the left side (`x0`) toward
    /// -z. `corners` says which walls run through the corners; alternate it
    /// course by course so the corners interlock. `sides` are the brick
    /// lengths of front, right, back and left in laying order, negative for
    /// openings.
    pub fn ring(
        &mut self,
        h: i32,
        (x0, z0): (i32, i32),
        (x1, z1): (i32, i32),
        corners: Corners,
        [front, right, back, left]: [&[i32]; 4],
    ) {
        let (fx, sz) = match corners {
            Corners::FrontBack => (0, 1),
            Corners::Sides => (1, 0),
        };
        let spans = [
            (front, x1 - x0 - 2 * fx),
            (right, z1 - z0 - 2 * sz),
            (back, x1 - x0 - 2 * fx),
            (left, z1 - z0 - 2 * sz),
        ];
        for (i, (lengths, span)) in spans.iter().enumerate() {
            let sum: i32 = lengths.iter().map(|n| n.abs()).sum();
            assert_eq!(
                sum, *span,
                "{}: side {i} of the ring at plate {h}",
                self.name
            );
        }
        self.bricks(h, (x0 + fx, z0), Dir::East, 1, front);
        self.bricks(h, (x1 - 1, z0 + sz), Dir::South, 1, right);
        self.bricks(h, (x1 - fx, z1 - 1), Dir::West, 1, back);
        self.bricks(h, (x0, z1 - sz), Dir::North, 1, left);
    }

    /// The build as LDraw text: header, then each piece followed by
    /// `0 STEP`.
    pub fn to_ldr(&self) -> String {
        let mut out = String::new();
        writeln!(out, "0 {}", self.title).unwrap();
        writeln!(out, "0 Name: {}.ldr", self.name).unwrap();
        writeln!(out, "0 Author: brickwright corpus generator").unwrap();
        writeln!(out, "0 // {}", self.about).unwrap();
        for p in &self.pieces {
            let (x, y, z) = p.origin();
            write!(out, "1 {} {x} {y} {z}", p.colour.code()).unwrap();
            for row in p.turn.matrix() {
                for v in row {
                    write!(out, " {v}").unwrap();
                }
            }
            writeln!(out, " {}.dat", p.part.spec().file).unwrap();
            writeln!(out, "0 STEP").unwrap();
        }
        out
    }
}

/// The turn that puts a part's long side along a row laid in `dir`.
fn along(dir: Dir) -> Turn {
    match dir {
        Dir::East | Dir::West => Turn::R0,
        Dir::South | Dir::North => Turn::R90,
    }
}
