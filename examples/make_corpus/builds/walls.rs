//! Walls: straight walls in running bond, a two-thick garden wall, an L, a
//! closed rectangle and a wall with a corbelled arch and a lintel.

use crate::build::{Build, Corners, Dir, COURSE};
use crate::parts::Colour;

/// A wall 20 studs long and 8 courses high in running bond of 1x2 to 1x8
/// bricks; every other course starts and ends with a half brick (1x2).
pub fn long_wall() -> Build {
    let mut b = Build::new(
        "long_wall",
        "Long Wall in Running Bond",
        "a wall 20 long, 8 courses, 1x2 to 1x8 bricks in running bond, half-brick ends",
        Colour::Red,
    );
    let courses: [&[i32]; 8] = [
        &[4, 8, 4, 4],
        &[2, 4, 4, 8, 2],
        &[8, 4, 8],
        &[2, 4, 8, 4, 2],
        &[4, 6, 6, 4],
        &[2, 6, 4, 6, 2],
        &[4, 6, 4, 6],
        &[2, 6, 4, 6, 2],
    ];
    for (c, lengths) in (0..).zip(courses) {
        b.bricks(c * COURSE, (0, 0), Dir::East, 1, lengths);
    }
    b
}

/// A wall 12 long and 9 courses high of short bricks (1x1 to 1x6), laid
/// back and forth: one course from the left, the next from the right.
pub fn tall_wall() -> Build {
    let mut b = Build::new(
        "tall_wall",
        "Tall Wall of Short Bricks",
        "a wall 12 long, 9 courses, 1x1 to 1x6 bricks, courses laid back and forth",
        Colour::Tan,
    );
    // Left to right as seen from the front, whichever way the course is laid.
    let courses: [&[i32]; 9] = [
        &[3, 6, 3],
        &[1, 4, 2, 4, 1],
        &[3, 3, 3, 3],
        &[2, 2, 4, 2, 2],
        &[3, 6, 3],
        &[1, 4, 2, 4, 1],
        &[3, 3, 3, 3],
        &[2, 2, 4, 2, 2],
        &[3, 6, 3],
    ];
    for (c, lengths) in (0..).zip(courses) {
        if c % 2 == 0 {
            b.bricks(c * COURSE, (0, 0), Dir::East, 1, lengths);
        } else {
            let reversed: Vec<i32> = lengths.iter().rev().copied().collect();
            b.bricks(c * COURSE, (12, 0), Dir::West, 1, &reversed);
        }
    }
    b
}

/// A garden wall two studs thick: courses of two rows of 1x bricks tied by
/// courses of 2x bricks, capped with 2x plates and a coping of 1x plates.
pub fn garden_wall() -> Build {
    let mut b = Build::new(
        "garden_wall",
        "Garden Wall Capped with Plates",
        "a wall 16 long and 2 thick: 1x rows tied by 2x courses, capped with 2x and 1x plates",
        Colour::Tan,
    );
    // (front row, back row laid from the right) or a tying course of 2x bricks.
    let rows: [(&[i32], &[i32]); 3] = [
        (&[4, 8, 4], &[2, 6, 6, 2]),
        (&[8, 4, 4], &[2, 6, 6, 2]),
        (&[4, 8, 4], &[2, 6, 6, 2]),
    ];
    let ties: [&[i32]; 3] = [&[6, 4, 6], &[3, 6, 4, 3], &[6, 4, 6]];
    for (i, ((front, back), tie)) in (0..).zip(rows.into_iter().zip(ties)) {
        let h = 2 * i * COURSE;
        b.bricks(h, (0, 0), Dir::East, 1, front);
        b.bricks(h, (16, 1), Dir::West, 1, back);
        b.bricks(h + COURSE, (0, 0), Dir::East, 2, tie);
    }
    b.colour(Colour::DarkBluishGrey);
    let top = 6 * COURSE;
    b.plates(top, (0, 0), Dir::East, 2, &[4, 8, 4]);
    b.plates(top + 1, (0, 0), Dir::East, 1, &[6, 8, 2]);
    b.plates(top + 1, (16, 1), Dir::West, 1, &[6, 8, 2]);
    b
}

/// Two walls meeting at a right angle, 12 and 10 long, 7 courses; the
/// corner interlocks and the free ends are finished with half bricks.
pub fn l_wall() -> Build {
    let mut b = Build::new(
        "l_wall",
        "L-Shaped Wall",
        "two walls 12 and 10 long meeting in an interlocking corner, 7 courses",
        Colour::LightBluishGrey,
    );
    // (along x from the corner, along z from the corner); even courses run
    // the x wall through the corner, odd courses the z wall.
    let courses: [(&[i32], &[i32]); 7] = [
        (&[4, 8], &[3, 6]),
        (&[2, 6, 3], &[6, 4]),
        (&[6, 4, 2], &[4, 4, 1]),
        (&[4, 4, 3], &[2, 8]),
        (&[4, 8], &[3, 6]),
        (&[2, 6, 3], &[6, 4]),
        (&[6, 4, 2], &[4, 4, 1]),
    ];
    for (c, (along_x, along_z)) in (0..).zip(courses) {
        let h = c * COURSE;
        let (x0, z0) = if c % 2 == 0 { (0, 1) } else { (1, 0) };
        b.bricks(h, (x0, 0), Dir::East, 1, along_x);
        b.bricks(h, (0, z0), Dir::South, 1, along_z);
    }
    b
}

/// A closed rectangle of walls, 12 by 8 outside, 6 courses, laid round
/// course by course with the corners overlapping in alternate courses.
pub fn rectangle() -> Build {
    let mut b = Build::new(
        "rectangle",
        "Rectangle with Interlocking Corners",
        "a closed rectangle of walls 12 x 8, 6 courses, corners overlapping in alternate courses",
        Colour::White,
    );
    let courses: [[&[i32]; 4]; 6] = [
        [&[4, 8], &[6], &[4, 8], &[3, 3]],
        [&[6, 4], &[4, 4], &[6, 4], &[2, 6]],
        [&[3, 6, 3], &[6], &[3, 6, 3], &[6]],
        [&[4, 6], &[2, 6], &[4, 6], &[6, 2]],
        [&[8, 4], &[3, 3], &[8, 4], &[2, 4]],
        [&[4, 6], &[8], &[2, 8], &[8]],
    ];
    for (c, sides) in (0..).zip(courses) {
        let corners = if c % 2 == 0 {
            Corners::FrontBack
        } else {
            Corners::Sides
        };
        b.ring(c * COURSE, (0, 0), (12, 8), corners, sides);
    }
    b
}

/// A wall 24 long with two openings: a corbelled arch (each course steps a
/// stud further in until the sides meet) and a doorway under a 1x6 lintel.
pub fn arches() -> Build {
    let mut b = Build::new(
        "arches",
        "Wall with Corbelled Arch and Lintel",
        "a wall 24 long, 8 courses, with a corbelled arch over a 6-stud opening and a lintel over a 4-stud one",
        Colour::DarkBluishGrey,
    );
    let courses: [&[i32]; 8] = [
        &[4, -6, 3, 2, -4, 2, 3],
        &[2, 2, -6, 2, 3, -4, 3, 2],
        &[1, 3, -6, 3, 2, -4, 2, 3],
        &[3, 2, -4, 2, 4, -4, 3, 2],
        &[2, 4, -2, 6, 6, 4],
        &[4, 3, 3, 6, 8],
        &[6, 6, 6, 6],
        &[2, 8, 4, 8, 2],
    ];
    for (c, lengths) in (0..).zip(courses) {
        b.bricks(c * COURSE, (0, 0), Dir::East, 1, lengths);
    }
    b
}
