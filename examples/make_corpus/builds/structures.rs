//! Solid and hollow structures: a column, a stepped pyramid, a box, a
//! staircase, a bridge, a boat and a tower.

use crate::build::{Build, Corners, Dir, COURSE};
use crate::parts::{Colour, Part, Turn};

/// A square column 4 x 4: pairs of 2x4 bricks, turned a quarter each time,
/// alternate with pinwheels of four 1x3 bricks round a 2x2 brick; a cap of
/// four 2x2 slopes.
pub fn column() -> Build {
    let mut b = Build::new(
        "column",
        "Column of Crossed and Pinwheel Courses",
        "a 4 x 4 column, 12 courses: 2x4 pairs turned a quarter each time, pinwheels of 1x3 round a 2x2, a cap of four 2x2 slopes",
        Colour::LightBluishGrey,
    );
    for c in 0..12 {
        let h = c * COURSE;
        match c % 4 {
            0 => {
                b.put(Part::Brick2x4, 0, 0, h, Turn::R0);
                b.put(Part::Brick2x4, 0, 2, h, Turn::R0);
            }
            1 => {
                b.put(Part::Brick2x2, 1, 1, h, Turn::R0);
                b.put(Part::Brick1x3, 0, 0, h, Turn::R0);
                b.put(Part::Brick1x3, 3, 0, h, Turn::R90);
                b.put(Part::Brick1x3, 1, 3, h, Turn::R0);
                b.put(Part::Brick1x3, 0, 1, h, Turn::R90);
            }
            2 => {
                b.put(Part::Brick2x4, 0, 0, h, Turn::R90);
                b.put(Part::Brick2x4, 2, 0, h, Turn::R90);
            }
            _ => {
                b.put(Part::Brick2x2, 1, 1, h, Turn::R0);
                b.put(Part::Brick1x3, 1, 0, h, Turn::R0);
                b.put(Part::Brick1x3, 3, 1, h, Turn::R90);
                b.put(Part::Brick1x3, 0, 3, h, Turn::R0);
                b.put(Part::Brick1x3, 0, 0, h, Turn::R90);
            }
        }
    }
    // A cap of four 2x2 slopes, each facing out of its quarter.
    b.colour(Colour::DarkBluishGrey);
    let cap = 12 * COURSE;
    b.put(Part::Slope45x2, 0, 0, cap, Turn::R0);
    b.put(Part::Slope45x2, 2, 0, cap, Turn::R270);
    b.put(Part::Slope45x2, 2, 2, cap, Turn::R180);
    b.put(Part::Slope45x2, 0, 2, cap, Turn::R90);
    b
}

/// A solid stepped pyramid, 12 x 12 at the base, each step one brick high
/// and a stud in on every side; the rows of 2x bricks cross from step to
/// step.
pub fn pyramid() -> Build {
    let mut b = Build::new(
        "pyramid",
        "Stepped Pyramid",
        "a solid stepped pyramid 12 x 12 x 6 courses of 2x bricks, rows crossing from step to step",
        Colour::Tan,
    );
    // (rows of 2x bricks, each row's lengths); rows run along x on even
    // steps and along z on odd ones.
    let steps: [&[&[i32]]; 6] = [
        &[&[8, 4], &[4, 8], &[6, 6], &[8, 4], &[4, 8], &[6, 6]],
        &[&[6, 4], &[4, 6], &[6, 4], &[4, 6], &[6, 4]],
        &[&[8], &[2, 6], &[4, 4], &[6, 2]],
        &[&[6], &[2, 4], &[4, 2]],
        &[&[4], &[2, 2]],
        &[&[2]],
    ];
    for (s, rows) in (0..).zip(steps) {
        for (r, lengths) in (0..).zip(rows.iter()) {
            let across = s + 2 * r;
            if s % 2 == 0 {
                b.bricks(s * COURSE, (s, across), Dir::East, 2, lengths);
            } else {
                b.bricks(s * COURSE, (across, s), Dir::South, 2, lengths);
            }
        }
    }
    b
}

/// An open box 10 x 8: a floor of 2x bricks, then five courses of walls
/// round its edge with interlocking corners.
pub fn hollow_box() -> Build {
    let mut b = Build::new(
        "hollow_box",
        "Hollow Box with a Floor",
        "a floor of 2x bricks 10 x 8 and 5 courses of walls round it, corners interlocking",
        Colour::Blue,
    );
    let floor: [&[i32]; 4] = [&[3, 3, 4], &[4, 6], &[6, 4], &[3, 4, 3]];
    for (r, lengths) in (0..).zip(floor) {
        b.bricks(0, (0, 2 * r), Dir::East, 2, lengths);
    }
    b.colour(Colour::Yellow);
    let courses: [[&[i32]; 4]; 5] = [
        [&[4, 6], &[6], &[6, 4], &[6]],
        [&[2, 6], &[4, 4], &[2, 6], &[2, 6]],
        [&[6, 4], &[2, 4], &[4, 6], &[4, 2]],
        [&[4, 4], &[6, 2], &[4, 4], &[4, 4]],
        [&[3, 4, 3], &[4, 2], &[2, 8], &[6]],
    ];
    for (c, sides) in (1..).zip(courses) {
        let corners = if c % 2 == 1 {
            Corners::FrontBack
        } else {
            Corners::Sides
        };
        b.ring(c * COURSE, (0, 0), (10, 8), corners, sides);
    }
    b
}

/// A solid staircase 6 wide rising along +x: seven steps, each a brick high
/// and two studs deep. Layers alternate three rows of 2x bricks with 1x
/// rows at the edges round two 2x rows, so no seam runs through.
pub fn staircase() -> Build {
    let mut b = Build::new(
        "staircase",
        "Solid Staircase",
        "a solid staircase 6 wide, 7 steps of one brick, layers of 2x rows alternating with 1x-2x-2x-1x rows",
        Colour::LightBluishGrey,
    );
    // Per step: the rows from front (z 0) to back as (width, lengths).
    let steps: [&[(i32, &[i32])]; 7] = [
        &[(2, &[8, 6]), (2, &[6, 8]), (2, &[8, 6])],
        &[(1, &[4, 8]), (2, &[8, 4]), (2, &[8, 4]), (1, &[4, 8])],
        &[(2, &[4, 3, 3]), (2, &[4, 3, 3]), (2, &[4, 3, 3])],
        &[(1, &[6, 2]), (2, &[8]), (2, &[4, 4]), (1, &[3, 3, 2])],
        &[(2, &[6]), (2, &[4, 2]), (2, &[3, 3])],
        &[(1, &[4]), (2, &[4]), (2, &[4]), (1, &[3, 1])],
        &[(2, &[2]), (2, &[2]), (2, &[2])],
    ];
    for (s, rows) in (0..).zip(steps) {
        let mut z = 0;
        for &(deep, lengths) in rows {
            b.bricks(s * COURSE, (2 * s, z), Dir::East, deep, lengths);
            z += deep;
        }
    }
    b
}

/// A bridge 24 long: an abutment at each end and two piers standing on the
/// table, a deck of 2x bricks with staggered joints over the piers, a layer
/// of plates across the deck, and railings of 1x1 posts and 1x rails.
pub fn bridge() -> Build {
    let mut b = Build::new(
        "bridge",
        "Bridge on Piers",
        "a bridge 24 long on two abutments and two piers, brick deck laminated with crossing plates, railings on posts",
        Colour::LightBluishGrey,
    );
    for x in [0, 7, 15, 22] {
        b.put(Part::Brick2x4, x, 0, 0, Turn::R90);
        b.put(Part::Brick2x2, x, 0, COURSE, Turn::R0);
        b.put(Part::Brick2x2, x, 2, COURSE, Turn::R0);
        b.put(Part::Brick2x4, x, 0, 2 * COURSE, Turn::R90);
    }
    b.colour(Colour::DarkBluishGrey);
    let deck = 3 * COURSE;
    b.bricks(deck, (0, 0), Dir::East, 2, &[8, 8, 8]);
    b.bricks(deck, (0, 2), Dir::East, 2, &[6, 6, 6, 6]);
    b.colour(Colour::Tan);
    let mut planks = vec![Part::Plate1x4];
    planks.extend([Part::Plate2x4; 11]);
    planks.push(Part::Plate1x4);
    b.lay(deck + COURSE, (0, 0), Dir::East, Turn::R90, &planks);
    b.colour(Colour::ReddishBrown);
    let posts = deck + COURSE + 1;
    for (z, rails) in [(0, &[8, 8, 8][..]), (3, &[6, 8, 6, 4][..])] {
        for x in [0, 4, 8, 12, 16, 20, 23] {
            b.put(Part::Brick1x1, x, z, posts, Turn::R0);
        }
        b.bricks(posts + COURSE, (0, z), Dir::East, 1, rails);
    }
    b
}

/// A boat 14 long with a tapered bow: a solid bottom course, three courses
/// of sides round an open cockpit with the bow built solid, a small deck of
/// plates at the bow and two thwarts.
pub fn boat() -> Build {
    let mut b = Build::new(
        "boat",
        "Boat with Tapered Bow",
        "a boat hull 14 long, bow tapering 6-4-2, solid bottom course and staggered sides round a cockpit",
        Colour::ReddishBrown,
    );
    // The bottom course: keel row first, then the sides and the bow.
    b.bricks(0, (0, 2), Dir::East, 2, &[6, 8]);
    b.bricks(0, (0, 0), Dir::East, 2, &[4, 6]);
    b.bricks(0, (0, 4), Dir::East, 2, &[6, 4]);
    b.put(Part::Brick1x2, 10, 1, 0, Turn::R0);
    b.put(Part::Brick1x2, 10, 4, 0, Turn::R0);

    // Courses 1 and 3 run the sides to the bow, which is a 2x4, a 1x4 and a
    // 2x2 at the tip; course 2 runs the stern and a bulkhead through the
    // corners and builds the bow of small bricks crossing the joints below.
    boat_course(&mut b, COURSE, &[6, 4]);
    let h = 2 * COURSE;
    b.bricks(h, (0, 6), Dir::North, 1, &[6]);
    b.bricks(h, (1, 0), Dir::East, 1, &[2, 6]);
    b.put(Part::Brick1x6, 9, 0, h, Turn::R90);
    b.put(Part::Brick1x2, 10, 1, h, Turn::R0);
    b.put(Part::Brick2x3, 10, 2, h, Turn::R0);
    b.put(Part::Brick1x2, 13, 2, h, Turn::R90);
    b.put(Part::Brick1x2, 10, 4, h, Turn::R0);
    b.bricks(h, (9, 5), Dir::West, 1, &[2, 6]);
    boat_course(&mut b, 3 * COURSE, &[8, 2]);

    b.colour(Colour::Tan);
    let deck = 4 * COURSE;
    b.put(Part::Plate1x4, 9, 1, deck, Turn::R90);
    b.put(Part::Plate1x2, 10, 1, deck, Turn::R0);
    b.put(Part::Plate2x4, 10, 2, deck, Turn::R0);
    b.put(Part::Plate1x2, 10, 4, deck, Turn::R0);
    b.put(Part::Plate1x6, 6, 0, deck, Turn::R90);
    b.put(Part::Plate1x6, 3, 0, deck, Turn::R90);
    b
}

/// A course of the boat's sides with the long sides running to the bow:
/// round from the stern along one side, across the bow, back along the
/// other side, and the stern.
fn boat_course(b: &mut Build, h: i32, side: &[i32]) {
    b.bricks(h, (0, 0), Dir::East, 1, side);
    b.put(Part::Brick2x4, 9, 1, h, Turn::R90);
    b.put(Part::Brick1x4, 11, 1, h, Turn::R90);
    b.put(Part::Brick2x2, 12, 2, h, Turn::R0);
    b.bricks(h, (10, 5), Dir::West, 1, side);
    b.bricks(h, (0, 5), Dir::North, 1, &[4]);
}

/// A square tower 6 x 6 and 12 courses high with windows on every face,
/// lintels over them, and battlements on top.
pub fn tower() -> Build {
    let mut b = Build::new(
        "tower",
        "Tower with Windows",
        "a tower 6 x 6, 12 courses, windows on every face under 1x6 and 1x4 lintels, battlements",
        Colour::DarkBluishGrey,
    );
    // Front, right, back, left; even courses run front and back through the
    // corners (6, 4, 6, 4 studs), odd ones the sides (4, 6, 4, 6).
    let courses: [[&[i32]; 4]; 12] = [
        [&[4, 2], &[4], &[4, 2], &[4]],
        [&[2, 2], &[2, 4], &[2, 2], &[4, 2]],
        [&[2, 4], &[2, 2], &[2, 4], &[1, 3]],
        [&[4], &[6], &[4], &[6]],
        [&[2, -2, 2], &[1, -2, 1], &[2, -2, 2], &[1, -2, 1]],
        [&[1, -2, 1], &[2, -2, 2], &[1, -2, 1], &[2, -2, 2]],
        [&[6], &[4], &[6], &[4]],
        [&[2, 2], &[4, 2], &[2, 2], &[2, 4]],
        [&[2, -2, 2], &[2, 2], &[2, -2, 2], &[3, 1]],
        [&[1, -2, 1], &[6], &[1, -2, 1], &[6]],
        [&[6], &[1, 3], &[6], &[4]],
        [&[2, 2], &[4, 2], &[2, 2], &[2, 4]],
    ];
    for (c, sides) in (0..).zip(courses) {
        let corners = if c % 2 == 0 {
            Corners::FrontBack
        } else {
            Corners::Sides
        };
        b.ring(c * COURSE, (0, 0), (6, 6), corners, sides);
    }
    // Battlements: merlons at the corners and in the middle of each face.
    let top = 12 * COURSE;
    b.put(Part::Brick1x1, 0, 0, top, Turn::R0);
    b.put(Part::Brick1x2, 2, 0, top, Turn::R0);
    b.put(Part::Brick1x1, 5, 0, top, Turn::R0);
    b.put(Part::Brick1x2, 5, 2, top, Turn::R90);
    b.put(Part::Brick1x1, 5, 5, top, Turn::R0);
    b.put(Part::Brick1x2, 2, 5, top, Turn::R0);
    b.put(Part::Brick1x1, 0, 5, top, Turn::R0);
    b.put(Part::Brick1x2, 0, 2, top, Turn::R90);
    b
}

/// A solid block 8 x 8, six courses of 2x bricks, each course laid across
/// the one below, its joints at odd studs so no seam runs on up.
pub fn solid_block() -> Build {
    let mut b = Build::new(
        "solid_block",
        "Solid Block",
        "a solid block 8 x 8 x 6 courses of 2x bricks, each course crossing the one below",
        Colour::Red,
    );
    for c in 0..6 {
        for r in 0..4 {
            if c % 2 == 0 {
                b.bricks(c * COURSE, (0, 2 * r), Dir::East, 2, &[3, 2, 3]);
            } else {
                b.bricks(c * COURSE, (2 * r, 0), Dir::South, 2, &[3, 2, 3]);
            }
        }
    }
    b
}

/// A wall two studs thick and 24 long, seven courses of 2x bricks in running
/// bond: each course's joints fall between those of the course below.
pub fn thick_wall() -> Build {
    let mut b = Build::new(
        "thick_wall",
        "Thick Wall",
        "a wall 2 studs thick, 24 long, 7 courses of 2x bricks in running bond",
        Colour::White,
    );
    let courses: [&[i32]; 7] = [
        &[4, 4, 4, 4, 4, 4],
        &[2, 4, 4, 4, 4, 4, 2],
        &[4, 8, 4, 8],
        &[6, 8, 4, 6],
        &[3, 6, 4, 8, 3],
        &[8, 8, 8],
        &[2, 4, 4, 4, 4, 4, 2],
    ];
    for (c, lengths) in (0..).zip(courses) {
        b.bricks(c * COURSE, (0, 0), Dir::East, 2, lengths);
    }
    b
}
