//! The derivation written out: the rule sequence of a build, as the paper
//! gives it (Figure 5: "the backward order of rules
//! {10,5,6,5,8,9,3,2,2,5,5,0}").
//!
//! A search's [`Removal`]s name each piece's rule inside the rule set it
//! ran with; [`Derivation::of`] turns them into the numbers of the loaded
//! rule file (see [`crate::grammar::RuleNumbers`]): one number per rule
//! application, in the forward order (first the starting rule that puts
//! the first piece down) and in the backward order the paper prints (the
//! last piece's rule first, a starting rule last). A complex rule adds
//! several pieces in one application, so it appears once for all of them.
//!
//! ```
//! use brickwright::grammar::RuleSet;
//! use brickwright::search::{build, Derivation, SearchOptions};
//! use brickwright::voxel::VoxelGrid;
//! let rules = RuleSet::parse(
//!     "part 3004\nstart 3004\nrule 3004 3004 r0 up 1 0 5\n",
//!     "inline.rules".as_ref(),
//! ).unwrap();
//! let mut grid = VoxelGrid::new(3, 1, 2);
//! for c in [(0, 0, 0), (1, 0, 0), (1, 0, 1), (2, 0, 1)] {
//!     grid.set(brickwright::geom::Cell::new(c.0, c.1, c.2), true);
//! }
//! let out = build(&grid, &rules, &SearchOptions::default()).unwrap();
//! let d = Derivation::of(&out.order, &rules);
//! // A starting rule (rule 0) puts the first 1x2 down; backward, it comes
//! // last.
//! assert_eq!(d.forward[0], 0);
//! assert_eq!(d.backward.last(), Some(&0));
//! assert_eq!(d.forward.iter().rev().copied().collect::<Vec<_>>(), d.backward);
//! ```

use std::collections::{BTreeMap, HashMap};

use serde::Serialize;

use super::Removal;
use crate::assembly::Placement;
use crate::grammar::{RuleRef, RuleSet};

/// A build's rule sequence, in the loaded rule file's numbers.
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct Derivation {
    /// The rule file the numbers refer to.
    pub rule_file: String,
    /// How the rules are numbered.
    pub numbering: &'static str,
    /// One number per rule application, from the first piece on.
    pub forward: Vec<u32>,
    /// The same, backward, as the paper prints a derivation: the last
    /// piece's rule first, a starting rule last.
    pub backward: Vec<u32>,
    /// How often each rule was applied, by number.
    pub uses: BTreeMap<u32, u32>,
}

/// How [`Derivation::numbering`] reads.
pub const NUMBERING: &str =
    "from 0: the start rules, then the basic rules (the file's `rule` lines, then those `unseen` adds), then the complex rules, each in file order";

impl Derivation {
    /// The backward order as the paper prints it: `{10,5,6,5,8,9,3,2,2,5,5,0}`.
    pub fn paper(&self) -> String {
        let n: Vec<String> = self.backward.iter().map(u32::to_string).collect();
        format!("{{{}}}", n.join(","))
    }

    /// The derivation of `order`, whose rules refer to `rules`.
    pub fn of(order: &[Removal], rules: &RuleSet) -> Derivation {
        let numbers = rules.numbers();
        let mut forward = Vec::with_capacity(order.len());
        let mut i = 0;
        while i < order.len() {
            let r = &order[i];
            let step = match r.rule {
                // A complex rule's new pieces come together.
                Some(RuleRef::Complex(id)) => rules
                    .complex()
                    .get(id.0 as usize)
                    .map_or(1, |c| c.v.len().max(1)),
                _ => 1,
            };
            if let Some(n) = numbers.of(r.rule, r.piece.part) {
                forward.push(n);
            }
            i += step;
        }
        let mut uses = BTreeMap::new();
        for &n in &forward {
            *uses.entry(n).or_insert(0) += 1;
        }
        let backward = forward.iter().rev().copied().collect();
        Derivation {
            rule_file: rules.source.clone(),
            numbering: NUMBERING,
            forward,
            backward,
            uses,
        }
    }

    /// Each rule's share of the applications, by number.
    pub fn shares(&self) -> BTreeMap<u32, f64> {
        let total = self.forward.len().max(1) as f64;
        self.uses
            .iter()
            .map(|(&n, &k)| (n, k as f64 / total))
            .collect()
    }
}

/// The rule number that added each piece of `order`, by placement.
pub fn piece_rules(order: &[Removal], rules: &RuleSet) -> HashMap<Placement, u32> {
    let numbers = rules.numbers();
    order
        .iter()
        .filter_map(|r| Some((r.piece, numbers.of(r.rule, r.piece.part)?)))
        .collect()
}

/// Total variation distance between two distributions over rule numbers:
/// half the sum of the absolute differences, 0 (equal) to 1 (disjoint).
pub fn total_variation(a: &BTreeMap<u32, f64>, b: &BTreeMap<u32, f64>) -> f64 {
    let keys: std::collections::BTreeSet<u32> = a.keys().chain(b.keys()).copied().collect();
    keys.iter()
        .map(|k| (a.get(k).unwrap_or(&0.0) - b.get(k).unwrap_or(&0.0)).abs())
        .sum::<f64>()
        / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Placement;
    use crate::catalog::PartKind;
    use crate::geom::{Cell, Rot};
    use crate::grammar::RuleId;
    use crate::search::Anchor;

    #[test]
    fn backward_is_forward_reversed_and_ends_in_a_start() {
        let text = "part 3004\npart 3003\nstart 3004\nstart 3003\n\
            rule 3004 3004 r0 up 1 0 5\nrule 3003 3004 r0 up 0 0 2\n";
        let rules = RuleSet::parse(text, "t.rules".as_ref()).unwrap();
        let p =
            |id, x, z| Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0);
        let order = [
            Removal::new_start(p("3003", 0, 0)),
            Removal::forward(
                p("3004", 0, 1),
                Anchor::Piece(p("3003", 0, 0)),
                Some(RuleRef::Basic(RuleId(1))),
            ),
            Removal::forward(
                p("3004", 1, 2),
                Anchor::Piece(p("3004", 0, 1)),
                Some(RuleRef::Basic(RuleId(0))),
            ),
        ];
        let d = Derivation::of(&order, &rules);
        assert_eq!(d.forward, [1, 3, 2]);
        assert_eq!(d.backward, [2, 3, 1]);
        assert_eq!(d.uses.values().sum::<u32>(), 3);
        let by_piece = piece_rules(&order, &rules);
        assert_eq!(by_piece[&p("3004", 1, 2)], 2);
    }

    #[test]
    fn total_variation_runs_from_equal_to_disjoint() {
        let a: BTreeMap<u32, f64> = [(0, 0.5), (1, 0.5)].into();
        let b: BTreeMap<u32, f64> = [(2, 1.0)].into();
        assert_eq!(total_variation(&a, &a), 0.0);
        assert_eq!(total_variation(&a, &b), 1.0);
        let c: BTreeMap<u32, f64> = [(0, 1.0)].into();
        assert!((total_variation(&a, &c) - 0.5).abs() < 1e-12);
    }
}
