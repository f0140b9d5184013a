//! Buildings with slopes: a house under a 45-degree gabled roof, a cabin
//! under a 33-degree roof, and a house whose upper storey overhangs on
//! inverted slopes.

use crate::build::{Build, Corners, Dir, COURSE};
use crate::parts::{Colour, Part, Turn};

/// Walls `courses` courses high round `(x0, z0)..(x1, z1)`, the corners
/// alternating, the first course running front and back through them.
fn walls(b: &mut Build, h: i32, corner: (i32, i32), far: (i32, i32), courses: &[[&[i32]; 4]]) {
    for (c, sides) in (0..).zip(courses) {
        let corners = if c % 2 == 0 {
            Corners::FrontBack
        } else {
            Corners::Sides
        };
        b.ring(h + c * COURSE, corner, far, corners, *sides);
    }
}

/// A house 14 x 8 with a door, five windows and a gabled roof of 45-degree
/// slopes, the gable ends filled with bricks and the ridge capped with
/// plates.
pub fn house() -> Build {
    use Part::{Slope45x1 as S1, Slope45x2 as S2, Slope45x3 as S3, Slope45x4 as S4};
    let mut b = Build::new(
        "house",
        "House with Gabled Roof",
        "a house 14 x 8, door and windows under lintels, gabled roof of 45-degree slopes 3037/3038/3039/3040b",
        Colour::White,
    );
    walls(
        &mut b,
        0,
        (0, 0),
        (14, 8),
        &[
            [&[4, 2, -2, 2, 4], &[4, 2], &[6, 8], &[2, 4]],
            [
                &[1, -2, 2, -2, 2, -2, 1],
                &[3, -2, 3],
                &[3, 2, -2, 2, 3],
                &[3, -2, 3],
            ],
            [
                &[2, -2, 2, -2, 2, -2, 2],
                &[2, -2, 2],
                &[6, -2, 6],
                &[2, -2, 2],
            ],
            [&[4, 1, -2, 1, 4], &[2, 4, 2], &[2, 8, 2], &[2, 4, 2]],
            [&[4, 6, 4], &[3, 3], &[4, 6, 4], &[3, 3]],
        ],
    );
    // Each roof row steps a stud in and a brick up; the front slopes run
    // down toward -z (R0), the back ones toward +z (R180). Between the rows
    // the gable ends are filled with bricks.
    let eaves = 5 * COURSE;
    let rows: [(&[Part], &[Part]); 3] = [
        (&[S3, S4, S4, S3], &[S3, S4, S4, S3]),
        (&[S2, S4, S4, S4], &[S4, S4, S4, S2]),
        (&[S1, S4, S4, S4, S1], &[S2, S4, S4, S4]),
    ];
    let gables: [&[i32]; 2] = [&[4], &[2]];
    for (r, (front, back)) in (0..).zip(rows) {
        let h = eaves + r * COURSE;
        b.colour(Colour::Red);
        b.lay(h, (0, r), Dir::East, Turn::R0, front);
        b.lay(h, (14, 6 - r), Dir::West, Turn::R180, back);
        if let Some(lengths) = gables.get(r as usize) {
            b.colour(Colour::White);
            b.bricks(h, (13, 2 + r), Dir::South, 1, lengths);
            b.bricks(h, (0, 6 - r), Dir::North, 1, lengths);
        }
    }
    b.colour(Colour::Red);
    b.plates(eaves + 3 * COURSE, (0, 3), Dir::East, 2, &[6, 8]);
    b
}

/// A log cabin 12 x 10 with a door and two windows, under a roof of
/// 33-degree slopes (3298, with 4286 at the ends of the upper rows).
pub fn cabin() -> Build {
    use Part::{Slope33x1 as S1, Slope33x2 as S2};
    let mut b = Build::new(
        "cabin",
        "Cabin with 33-Degree Roof",
        "a cabin 12 x 10 with a door and windows under a roof of 33-degree slopes 3298/4286",
        Colour::ReddishBrown,
    );
    walls(
        &mut b,
        0,
        (0, 0),
        (12, 10),
        &[
            [&[3, 2, -2, 2, 3], &[4, 4], &[4, 8], &[2, 6]],
            [&[4, -2, 4], &[4, -2, 4], &[6, 4], &[4, -2, 4]],
            [&[2, 3, -2, 3, 2], &[3, -2, 3], &[8, 4], &[3, -2, 3]],
            [&[2, 6, 2], &[2, 6, 2], &[4, 6], &[2, 6, 2]],
        ],
    );
    // A 33-degree slope is three studs deep: each row steps two studs in.
    let eaves = 4 * COURSE;
    let low: &[Part] = &[S2; 6];
    let high: &[Part] = &[S1, S2, S2, S2, S2, S2, S1];
    b.colour(Colour::DarkBluishGrey);
    b.lay(eaves, (0, 0), Dir::East, Turn::R0, low);
    b.lay(eaves, (12, 7), Dir::West, Turn::R180, low);
    b.colour(Colour::ReddishBrown);
    b.bricks(eaves, (11, 3), Dir::South, 1, &[4]);
    b.bricks(eaves, (0, 7), Dir::North, 1, &[4]);
    b.colour(Colour::DarkBluishGrey);
    b.lay(eaves + COURSE, (0, 2), Dir::East, Turn::R0, high);
    b.lay(eaves + COURSE, (12, 5), Dir::West, Turn::R180, high);
    b.plates(eaves + 2 * COURSE, (0, 4), Dir::East, 2, &[2, 8, 2]);
    b
}

/// A two-storey house whose upper storey overhangs the ground floor by a
/// stud at front and back, carried on rows of inverted slopes; flat roof of
/// plates.
pub fn jetty() -> Build {
    use Part::{Inverted45x1 as I1, Inverted45x2 as I2};
    let mut b = Build::new(
        "jetty",
        "Jettied House on Inverted Slopes",
        "a ground floor 8 x 6 and an upper storey 8 x 8 overhanging front and back on inverted slopes 3660a/3665a",
        Colour::LightBluishGrey,
    );
    // Ground floor, z 1..7; the first course runs the sides through the
    // corners so the slope rows above can run through them.
    for (c, sides) in (0..).zip([
        [&[2, -2, 2][..], &[6], &[4, 2], &[2, 4]],
        [&[3, -2, 3], &[4], &[2, 4, 2], &[4]],
        [&[6], &[3, 3], &[6], &[4, 2]],
    ]) {
        let corners = if c % 2 == 0 {
            Corners::Sides
        } else {
            Corners::FrontBack
        };
        b.ring(c * COURSE, (0, 1), (8, 7), corners, sides);
    }
    // The jetty course: inverted slopes with their back row on the front and
    // back walls, the overhang outward; plain bricks on the sides.
    let jetty = 3 * COURSE;
    b.colour(Colour::White);
    b.lay(jetty, (0, 0), Dir::East, Turn::R0, &[I2, I2, I2, I2]);
    b.put(Part::Brick1x4, 7, 2, jetty, Turn::R90);
    b.lay(jetty, (8, 6), Dir::West, Turn::R180, &[I2, I1, I2, I1, I2]);
    b.put(Part::Brick1x4, 0, 2, jetty, Turn::R90);
    // The upper storey, z 0..8, with a window on every face.
    b.colour(Colour::Tan);
    walls(
        &mut b,
        4 * COURSE,
        (0, 0),
        (8, 8),
        &[
            [&[3, 2, 3], &[3, 3], &[4, 4], &[2, 4]],
            [&[2, -2, 2], &[3, -2, 3], &[2, -2, 2], &[3, -2, 3]],
            [&[8], &[6], &[8], &[6]],
        ],
    );
    b.colour(Colour::DarkBluishGrey);
    let roof = 7 * COURSE;
    let rows: [&[i32]; 4] = [&[8], &[6, 2], &[2, 6], &[8]];
    for (r, lengths) in (0..).zip(rows) {
        b.plates(roof, (0, 2 * r), Dir::East, 2, lengths);
    }
    b
}
