//! The `brickwright` command-line tool (being written).

fn main() {}
