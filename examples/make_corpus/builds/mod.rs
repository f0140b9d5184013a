//! The builds of the corpus, one function each.
//!
//! Coordinates are stud cells: `x` along LDraw x, `z` along LDraw z, and
//! heights in plates above the table (`c * COURSE` for brick course `c`).
//! Row lengths are listed in laying order; a negative length is an opening.

mod houses;
mod plates;
mod structures;
mod walls;

use crate::build::Build;

/// Every build, in the order of the README.
pub fn all() -> Vec<Build> {
    vec![
        walls::long_wall(),
        walls::tall_wall(),
        walls::garden_wall(),
        walls::l_wall(),
        walls::rectangle(),
        walls::arches(),
        structures::column(),
        structures::pyramid(),
        structures::hollow_box(),
        structures::staircase(),
        structures::bridge(),
        structures::boat(),
        structures::tower(),
        structures::solid_block(),
        structures::thick_wall(),
        houses::house(),
        houses::cabin(),
        houses::jetty(),
        plates::table(),
        plates::platform(),
    ]
}
