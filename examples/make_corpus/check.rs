//! The checks every build passes before it is written.
//!
//! A piece fills the box of its footprint cells times its height in plates
//! (a slope fills its whole box too). Two pieces connect where studs on top
//! of one meet the underside of the other at the same height: a slope has
//! studs on its back row only, an inverted slope takes studs under its back
//! row only. The checks:
//!
//! - 30 to 150 pieces;
//! - no two pieces share a cell;
//! - every piece above the table connects to an earlier piece (pressed on
//!   top of it or under it), so the order is one a person can follow;
//! - the whole build is one connected piece;
//! - nothing rests on the slanted face of a slope or hangs under the slanted
//!   face of an inverted slope;
//! - running bond: no vertical seam between two pieces continues straight
//!   into the layer above.

use std::collections::BTreeMap;

use crate::build::Build;
use crate::parts::{Kind, Placed};

/// The allowed number of pieces in a build.
pub const PIECES: std::ops::RangeInclusive<usize> = 30..=150;

/// A cell of the grid: stud x, stud z, plate level (0 = the lowest plate).
type Cell = (i32, i32, i32);

/// Runs every check on `build`; the error names the build and the piece
/// (counted from 1, which is also its step).
pub fn check(build: &Build) -> Result<(), String> {
    let n = build.pieces.len();
    if !PIECES.contains(&n) {
        return Err(format!(
            "{}: {n} pieces, expected {} to {}",
            build.name,
            PIECES.start(),
            PIECES.end()
        ));
    }
    check_pieces(build)
}

/// Every check but the number of pieces.
fn check_pieces(build: &Build) -> Result<(), String> {
    let name = build.name;
    let pieces = &build.pieces;
    let mut owner: BTreeMap<Cell, usize> = BTreeMap::new();
    let mut studs: BTreeMap<Cell, usize> = BTreeMap::new();
    let mut undersides: BTreeMap<Cell, usize> = BTreeMap::new();
    let mut groups = UnionFind::new(pieces.len());

    for (i, p) in pieces.iter().enumerate() {
        if p.h < 0 {
            return Err(format!("{name}: {} is below the table", describe(i, p)));
        }
        for (x, z) in p.cells() {
            for l in p.h..p.top() {
                if let Some(&j) = owner.get(&(x, z, l)) {
                    return Err(format!(
                        "{name}: {} overlaps {} at stud ({x}, {z}), plate {l}",
                        describe(i, p),
                        describe(j, &pieces[j])
                    ));
                }
                owner.insert((x, z, l), i);
            }
        }
        let mut joined = Vec::new();
        for (x, z) in p.underside() {
            joined.extend(studs.get(&(x, z, p.h)).copied());
        }
        for (x, z) in p.studs() {
            joined.extend(undersides.get(&(x, z, p.top())).copied());
        }
        if p.h > 0 && joined.is_empty() {
            return Err(format!(
                "{name}: {} connects to no earlier piece",
                describe(i, p)
            ));
        }
        for j in joined {
            groups.union(i, j);
        }
        for (x, z) in p.studs() {
            studs.insert((x, z, p.top()), i);
        }
        for (x, z) in p.underside() {
            undersides.insert((x, z, p.h), i);
        }
    }

    for (i, p) in pieces.iter().enumerate() {
        if groups.find(i) != groups.find(0) {
            return Err(format!(
                "{name}: {} is not connected to piece 1",
                describe(i, p)
            ));
        }
    }

    for (i, p) in pieces.iter().enumerate() {
        let (level, side) = match p.part.spec().kind {
            Kind::Rect => continue,
            Kind::Slope => (p.top(), "on"),
            Kind::Inverted => (p.h - 1, "under"),
        };
        for (x, z) in p.slanted() {
            if let Some(&j) = owner.get(&(x, z, level)) {
                return Err(format!(
                    "{name}: {} sits {side} the slanted face of {}",
                    describe(j, &pieces[j]),
                    describe(i, p)
                ));
            }
        }
    }

    running_bond(build, &owner)
}

/// Fails where a seam between pieces `a | b` has pieces `c | d` right above
/// it, both new (not `a` or `b` continuing upward).
fn running_bond(build: &Build, owner: &BTreeMap<Cell, usize>) -> Result<(), String> {
    let pieces = &build.pieces;
    for (&(x, z, l), &a) in owner {
        for (nx, nz) in [(x + 1, z), (x, z + 1)] {
            let Some(&b) = owner.get(&(nx, nz, l)) else {
                continue;
            };
            let (Some(&c), Some(&d)) = (owner.get(&(x, z, l + 1)), owner.get(&(nx, nz, l + 1)))
            else {
                continue;
            };
            if a != b && c != d && c != a && d != b {
                return Err(format!(
                    "{}: the seam between {} and {} continues between {} and {} \
                     (studs ({x}, {z}) | ({nx}, {nz}))",
                    build.name,
                    describe(a, &pieces[a]),
                    describe(b, &pieces[b]),
                    describe(c, &pieces[c]),
                    describe(d, &pieces[d]),
                ));
            }
        }
    }
    Ok(())
}

/// `piece 12 (3001 at stud (4, 0), plate 3)`.
fn describe(i: usize, p: &Placed) -> String {
    format!(
        "piece {} ({} at stud ({}, {}), plate {})",
        i + 1,
        p.part.spec().file,
        p.x,
        p.z,
        p.h
    )
}

/// Disjoint sets over piece indices.
struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n).collect(),
        }
    }

    fn find(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        self.parent[ra.max(rb)] = ra.min(rb);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parts::{Colour, Part, Turn};

    fn build(pieces: &[(Part, i32, i32, i32, Turn)]) -> Build {
        let mut b = Build::new("test", "Test", "test", Colour::Red);
        for &(part, x, z, h, turn) in pieces {
            b.put(part, x, z, h, turn);
        }
        b
    }

    fn error(pieces: &[(Part, i32, i32, i32, Turn)]) -> String {
        check_pieces(&build(pieces)).expect_err("the check should fail")
    }

    use Part::{Brick1x2, Brick1x4, Brick2x2, Slope45x2};
    use Turn::R0;

    #[test]
    fn a_running_bond_passes() {
        let wall = [
            (Brick1x2, 0, 0, 0, R0),
            (Brick1x2, 2, 0, 0, R0),
            (Brick1x2, 1, 0, 3, R0),
        ];
        assert_eq!(check_pieces(&build(&wall)), Ok(()));
    }

    #[test]
    fn overlaps_are_found() {
        let e = error(&[(Brick2x2, 0, 0, 0, R0), (Brick1x2, 1, 1, 0, R0)]);
        assert!(
            e.contains("piece 2 (3004 at stud (1, 1), plate 0) overlaps piece 1"),
            "{e}"
        );
    }

    #[test]
    fn a_piece_must_press_onto_an_earlier_one() {
        // Placed top first: the upper brick floats when it is placed.
        let e = error(&[(Brick1x2, 0, 0, 3, R0), (Brick1x2, 0, 0, 0, R0)]);
        assert!(
            e.contains("piece 1") && e.contains("no earlier piece"),
            "{e}"
        );
    }

    #[test]
    fn the_build_is_one_piece() {
        let e = error(&[(Brick1x2, 0, 0, 0, R0), (Brick1x2, 2, 0, 0, R0)]);
        assert!(e.contains("piece 2") && e.contains("not connected"), "{e}");
    }

    #[test]
    fn stacked_seams_are_found() {
        let e = error(&[
            (Brick1x4, 0, 0, 0, R0),
            (Brick1x2, 0, 0, 3, R0),
            (Brick1x2, 2, 0, 3, R0),
            (Brick1x2, 0, 0, 6, R0),
            (Brick1x2, 2, 0, 6, R0),
        ]);
        assert!(
            e.contains("between piece 2") && e.contains("continues between piece 4"),
            "{e}"
        );
    }

    #[test]
    fn slopes_take_nothing_on_their_slanted_face() {
        // A slope at R0 has its back row at z 1: a 1x2 on z 1 sits on the
        // studs, a 2x2 over z 0 and 1 also on the slanted face.
        let on_studs = [(Slope45x2, 0, 0, 0, R0), (Brick1x2, 0, 1, 3, R0)];
        assert_eq!(check_pieces(&build(&on_studs)), Ok(()));
        let e = error(&[(Slope45x2, 0, 0, 0, R0), (Brick2x2, 0, 0, 3, R0)]);
        assert!(e.contains("slanted face"), "{e}");
    }
}
