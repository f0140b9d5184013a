//! Builds of plates: a table of plates on brick legs, and a platform of
//! three layers of plates laminated across each other's seams.

use crate::build::{Build, Dir, COURSE};
use crate::parts::{Colour, Part, Turn};

/// A table 14 x 6: four legs of stacked 2x2 bricks, two plates bridging
/// each pair of legs, a top of 2x plates with staggered seams, a border of
/// 1x plates and a few small plates set on it.
pub fn table() -> Build {
    let mut b = Build::new(
        "table",
        "Table of Plates on Brick Legs",
        "a table 14 x 6: legs of 2x2 bricks, a top of 2x plates laminated over plates across the legs, a 1x plate border",
        Colour::ReddishBrown,
    );
    for (x, z) in [(0, 0), (12, 0), (12, 4), (0, 4)] {
        for c in 0..4 {
            b.put(Part::Brick2x2, x, z, c * COURSE, Turn::R0);
        }
    }
    b.colour(Colour::Tan);
    let top = 4 * COURSE;
    b.put(Part::Plate2x6, 0, 0, top, Turn::R90);
    b.put(Part::Plate2x6, 12, 0, top, Turn::R90);
    let rows: [&[i32]; 3] = [&[8, 6], &[6, 8], &[8, 6]];
    for (r, lengths) in (0..).zip(rows) {
        b.plates(top + 1, (0, 2 * r), Dir::East, 2, lengths);
    }
    b.colour(Colour::ReddishBrown);
    b.plates(top + 2, (0, 0), Dir::East, 1, &[6, 8]);
    b.plates(top + 2, (13, 1), Dir::South, 1, &[4]);
    b.plates(top + 2, (14, 5), Dir::West, 1, &[8, 6]);
    b.plates(top + 2, (0, 5), Dir::North, 1, &[4]);
    // Things on the table, each within a row of the top or across a joint.
    b.colour(Colour::White);
    b.put(Part::Plate2x2, 2, 1, top + 2, Turn::R0);
    b.put(Part::Plate2x3, 6, 1, top + 2, Turn::R0);
    b.colour(Colour::Blue);
    b.put(Part::Plate1x1, 11, 2, top + 2, Turn::R0);
    b.put(Part::Plate1x1, 11, 3, top + 2, Turn::R0);
    b.colour(Colour::Yellow);
    b.put(Part::Plate1x2, 4, 3, top + 2, Turn::R90);
    b.put(Part::Plate1x3, 8, 4, top + 2, Turn::R0);
    b
}

/// A platform 10 x 8 of three layers of plates laid on the table, each layer
/// crossing the one below so no seam runs through.
pub fn platform() -> Build {
    let mut b = Build::new(
        "platform",
        "Plate-Laminated Platform",
        "a platform 10 x 8 of three layers of 1x and 2x plates, each layer crossing the seams of the one below",
        Colour::DarkBluishGrey,
    );
    let bottom: [&[i32]; 4] = [&[8, 2], &[4, 6], &[6, 4], &[2, 8]];
    for (r, lengths) in (0..).zip(bottom) {
        b.plates(0, (0, 2 * r), Dir::East, 2, lengths);
    }
    // The middle layer runs along z, its rows one stud off the bottom
    // layer's; (x, width, lengths).
    b.colour(Colour::LightBluishGrey);
    let middle: [(i32, i32, &[i32]); 6] = [
        (0, 1, &[8]),
        (1, 2, &[8]),
        (3, 2, &[3, 2, 3]),
        (5, 2, &[3, 2, 3]),
        (7, 2, &[8]),
        (9, 1, &[3, 2, 3]),
    ];
    for (x, deep, lengths) in middle {
        b.plates(1, (x, 0), Dir::South, deep, lengths);
    }
    b.colour(Colour::Green);
    let top: [(i32, i32, &[i32]); 6] = [
        (0, 1, &[6, 4]),
        (1, 1, &[2, 8]),
        (2, 2, &[4, 6]),
        (4, 2, &[8, 2]),
        (6, 1, &[4, 6]),
        (7, 1, &[8, 2]),
    ];
    for (z, deep, lengths) in top {
        b.plates(2, (0, z), Dir::East, deep, lengths);
    }
    b
}
