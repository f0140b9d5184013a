//! The rules of a [`RuleSet`] indexed by the joint they make: given a piece
//! in place and a piece to add, which rule adds it, and with what weight.

use std::collections::HashMap;

use crate::assembly::Placement;
use crate::catalog::PartKind;
use crate::geom::Rot;
use crate::grammar::{Dir, RuleId, RuleSet};

type Key = (PartKind, Rot, PartKind, Rot, (i32, i32, i32), Dir);

/// Every basic rule variant by the joint it makes.
pub(crate) struct RuleBook {
    joints: HashMap<Key, (f64, RuleId)>,
    /// The mean weight of a variant: scores use weights relative to it.
    pub mean: f64,
}

impl RuleBook {
    /// Indexes every variant of `rules`; where two rules make the same
    /// joint, the heavier one stands for it.
    pub fn new(rules: &RuleSet) -> RuleBook {
        let mut joints: HashMap<Key, (f64, RuleId)> = HashMap::new();
        let mut sum = 0.0;
        for v in rules.variants() {
            let key = (
                v.anchor,
                v.anchor_rot,
                v.added,
                v.added_rot,
                v.offset,
                v.dir,
            );
            sum += v.weight;
            let e = joints.entry(key).or_insert((v.weight, v.rule));
            if v.weight > e.0 || (v.weight == e.0 && v.rule < e.1) {
                *e = (v.weight, v.rule);
            }
        }
        let n = rules.variants().len().max(1) as f64;
        RuleBook {
            joints,
            mean: (sum / n).max(f64::MIN_POSITIVE),
        }
    }

    /// The rule that adds `added` to `anchor` in place, on top of it
    /// (`Dir::Up`) or underneath (`Dir::Down`), and its weight.
    pub fn joint(
        &self,
        anchor: &Placement,
        added: &Placement,
        dir: Dir,
        layer_ldu: i32,
    ) -> Option<(f64, RuleId)> {
        let (a, b) = (anchor.body(layer_ldu).bbox, added.body(layer_ldu).bbox);
        let key = (
            anchor.part,
            anchor.rot,
            added.part,
            added.rot,
            (b.min.x - a.min.x, b.min.y - a.min.y, b.min.z - a.min.z),
            dir,
        );
        self.joints.get(&key).copied()
    }
}
