//! What a rule set lacks to build shapes in general.
//!
//! The search grows a build piece by piece through the rules, so a rule
//! set can only cover a voxel shape when its rules can reach every voxel.
//! Three things are needed for shapes in general, and [`RuleSet::gaps`]
//! names each one missing:
//!
//! - a 1x1 piece of the family being built (a brick or a plate), for the
//!   voxels a bigger piece cannot fill (a course one stud wide, an odd
//!   corner);
//! - rules in both directions, a piece put on top (`up`) and one pressed on
//!   from below (`down`), since a build grows both ways from where it
//!   starts;
//! - a rule that puts the new piece past the side of the piece it joins
//!   (an offset that makes it reach beyond the anchor's footprint): pieces
//!   side by side in a course are only ever joined through a piece across
//!   them in the course above or below.
//!
//! A rule set with gaps can still build some shapes (a 1x1 tower needs only
//! stacking), so the pipeline turns them into an error only when a build
//! could not be covered.

use super::{Dir, RuleSet};
use crate::catalog::Family;
use crate::geom::Rot;

impl RuleSet {
    /// What this rule set lacks to cover shapes in general, one phrase
    /// each; empty when nothing is missing. Only parts of `family` count
    /// for the 1x1 piece (the family whose layers are built).
    pub fn gaps(&self, family: Family) -> Vec<String> {
        let mut gaps = Vec::new();
        let one_by_one = self
            .alphabet()
            .iter()
            .any(|p| p.spec().family() == family && p.spec().footprint(Rot::R0) == (1, 1));
        if !one_by_one {
            gaps.push(format!(
                "a 1x1 {} (for courses one stud wide and odd corners)",
                match family {
                    Family::Plate => "plate (3024)",
                    _ => "brick (3005)",
                }
            ));
        }
        for (dir, name) in [(Dir::Up, "up"), (Dir::Down, "down")] {
            if !self.variants().iter().any(|v| v.dir == dir) {
                gaps.push(format!(
                    "a rule joining a piece {name} ({})",
                    if dir == Dir::Up {
                        "on top of another"
                    } else {
                        "pressed on from below"
                    }
                ));
            }
        }
        let reaches_past = self.variants().iter().any(|v| {
            let (ax, ay) = v.anchor.spec().footprint(v.anchor_rot);
            let (bx, by) = v.added.spec().footprint(v.added_rot);
            let (dx, dy, _) = v.offset;
            dx < 0 || dy < 0 || dx + bx > ax || dy + by > ay
        });
        if !reaches_past {
            gaps.push(
                "a rule putting a piece past the side of the one it joins (so pieces side by \
                 side can be bridged)"
                    .into(),
            );
        }
        gaps
    }
}

#[cfg(test)]
mod tests {
    use crate::catalog::Family;
    use crate::grammar::{default_rules, RuleSet};

    fn parse(text: &str) -> RuleSet {
        RuleSet::parse(text, "t.rules".as_ref()).unwrap()
    }

    #[test]
    fn the_default_rules_lack_nothing() {
        assert!(default_rules().gaps(Family::Brick).is_empty());
    }

    #[test]
    fn stacking_only_lacks_the_bridge_and_two_by_only_lacks_the_1x1() {
        let stack = parse(
            "part 3005\nstart 3005\nrule 3005 3005 r0 up 0 0 1\nrule 3005 3005 r0 down 0 0 1\n",
        );
        let gaps = stack.gaps(Family::Brick);
        assert_eq!(gaps.len(), 1, "{gaps:?}");
        assert!(gaps[0].contains("past the side"), "{gaps:?}");

        let two = parse(
            "part 3003\npart 3001\nstart 3003\nstart 3001\n\
             rule 3001 3001 r0 up 0 -1 1\nrule 3001 3003 r0 down 0 0 1\n",
        );
        let gaps = two.gaps(Family::Brick);
        assert_eq!(gaps.len(), 1, "{gaps:?}");
        assert!(gaps[0].contains("1x1 brick (3005)"), "{gaps:?}");

        let up_only = parse("part 3005\nstart 3005\nrule 3005 3005 r0 up 0 0 1\n");
        let gaps = up_only.gaps(Family::Brick);
        assert!(gaps.iter().any(|g| g.contains("down")), "{gaps:?}");
    }
}
