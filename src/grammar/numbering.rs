//! Rule numbers: how a derivation names its rules, as the paper does
//! (Figure 5's backward order `{10,5,6,5,8,9,3,2,2,5,5,0}`).
//!
//! The rules of a loaded file are numbered from 0: first its `start` rules,
//! then its `rule` lines, then the rules `unseen` adds, then the complex
//! rules, each group in the order the file gives it. A file that lists its
//! starting rules first (as `rules/figure2.rules` and the shipped files do)
//! is thus numbered in reading order, like the paper's Figure 2.
//!
//! A build cuts the loaded file down to the parts it may use
//! ([`RuleSet::restricted`]), which renumbers the rules inside; the numbers
//! written out stay those of the loaded file: the restricted set keeps the
//! numbering of the set it came from and [`RuleSet::numbers`] maps its own
//! rules back to it.

use std::collections::HashMap;

use crate::catalog::PartKind;
use crate::geom::Rot;

use super::{Dir, RuleRef, RuleSet, Variant};
use crate::keyhash::KeyMap;

/// What identifies a basic rule whatever the layer height: a turn of it,
/// without the vertical offset (which depends on the layers).
type BasicKey = (PartKind, Rot, PartKind, Rot, (i32, i32), Dir);

fn key(v: &Variant) -> BasicKey {
    (
        v.anchor,
        v.anchor_rot,
        v.added,
        v.added_rot,
        (v.offset.0, v.offset.1),
        v.dir,
    )
}

/// The numbers of a loaded rule file's rules.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Numbering {
    starts: Vec<PartKind>,
    basic: KeyMap<BasicKey, u32>,
    basic_count: u32,
    complex: Vec<String>,
}

impl Numbering {
    /// The numbering of `set` as loaded.
    pub(super) fn of(set: &RuleSet) -> Numbering {
        let starts: Vec<PartKind> = set.starts.iter().map(|s| s.part).collect();
        let first = starts.len() as u32;
        let mut basic = KeyMap::with_capacity_and_hasher(set.variants.len(), Default::default());
        for v in &set.variants {
            basic.entry(key(v)).or_insert(first + v.rule.0);
        }
        Numbering {
            starts,
            basic,
            basic_count: set.rules.len() as u32,
            complex: set.complex.iter().map(|c| c.name.clone()).collect(),
        }
    }

    /// How many rules are numbered.
    pub fn len(&self) -> u32 {
        self.starts.len() as u32 + self.basic_count + self.complex.len() as u32
    }

    /// Whether no rule is numbered.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The loaded file's number of every rule of a (possibly restricted) set.
#[derive(Debug, Clone, PartialEq)]
pub struct RuleNumbers {
    starts: HashMap<PartKind, u32>,
    basic: Vec<u32>,
    complex: Vec<u32>,
    /// How many rules the loaded file numbers.
    pub total: u32,
}

impl RuleNumbers {
    /// The number of the rule `rule` (a starting rule putting down `part`
    /// when `None`); `None` if the set has no such rule.
    pub fn of(&self, rule: Option<RuleRef>, part: PartKind) -> Option<u32> {
        match rule {
            None => self.starts.get(&part).copied(),
            Some(RuleRef::Basic(id)) => self.basic.get(id.0 as usize).copied(),
            Some(RuleRef::Complex(id)) => self.complex.get(id.0 as usize).copied(),
        }
    }
}

impl RuleSet {
    /// The numbering of the file this set was loaded from.
    pub fn numbering(&self) -> Numbering {
        match &self.numbered {
            Some(n) => (**n).clone(),
            None => Numbering::of(self),
        }
    }

    /// Each rule's number in the loaded file: the `rule` statements counted
    /// in the order the file lists them (see [`RuleNumbers`]).
    pub fn numbers(&self) -> RuleNumbers {
        let n = self.numbering();
        let starts = self
            .starts
            .iter()
            .filter_map(|s| {
                let i = n.starts.iter().position(|&p| p == s.part)?;
                Some((s.part, i as u32))
            })
            .collect();
        let mut basic = vec![u32::MAX; self.rules.len()];
        for v in &self.variants {
            let slot = &mut basic[v.rule.0 as usize];
            if *slot == u32::MAX {
                if let Some(&k) = n.basic.get(&key(v)) {
                    *slot = k;
                }
            }
        }
        let first_complex = n.starts.len() as u32 + n.basic_count;
        let complex = self
            .complex
            .iter()
            .map(|c| {
                n.complex
                    .iter()
                    .position(|m| *m == c.name)
                    .map_or(u32::MAX, |i| first_complex + i as u32)
            })
            .collect();
        RuleNumbers {
            starts,
            basic,
            complex,
            total: n.len(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grammar::RuleId;

    const TEXT: &str = "part 3004\npart 3003\npart 3022\nstart 3004\nstart 3003\n\
        rule 3004 3004 r0 up 1 0 5\nrule 3003 3003 r0 up 1 0 2\nrule 3022 3004 r0 up 0 0 1\n";

    #[test]
    fn starts_come_first_then_rules_in_file_order() {
        let set = RuleSet::parse(TEXT, "t.rules".as_ref()).unwrap();
        let n = set.numbers();
        let p = |id| PartKind::from_id(id).unwrap();
        assert_eq!(n.of(None, p("3004")), Some(0));
        assert_eq!(n.of(None, p("3003")), Some(1));
        assert_eq!(n.of(Some(RuleRef::Basic(RuleId(0))), p("3004")), Some(2));
        assert_eq!(n.of(Some(RuleRef::Basic(RuleId(2))), p("3004")), Some(4));
        assert_eq!(n.total, 5);
    }

    #[test]
    fn a_restricted_set_keeps_the_loaded_numbers() {
        let set = RuleSet::parse(TEXT, "t.rules".as_ref()).unwrap();
        let bricks = set.restricted(|p| p.spec().id.0 != "3022").unwrap();
        // The plate's rule is gone, and the layers are a brick high now;
        // the two brick rules keep their numbers 2 and 3.
        assert_eq!(bricks.rules().len(), 2);
        let n = bricks.numbers();
        let p = PartKind::from_id("3003").unwrap();
        assert_eq!(n.of(Some(RuleRef::Basic(RuleId(1))), p), Some(3));
        assert_eq!(n.of(None, p), Some(1));
        assert_eq!(n.total, 5);
    }
}
