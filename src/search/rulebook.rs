//! The rules of a [`RuleSet`] indexed by the joint they make: given a piece
//! in place and a piece to add, which rule adds it, and with what weight.

use crate::assembly::Placement;
use crate::catalog::PartKind;
use crate::geom::Rot;
use crate::grammar::{Dir, RuleId, RuleSet};
use crate::keyhash::KeyMap;

type Key = (PartKind, Rot, PartKind, Rot, (i32, i32, i32), Dir);

/// Every basic rule variant by the joint it makes.
pub(crate) struct RuleBook {
    joints: KeyMap<Key, (f64, RuleId)>,
    /// Per part: the mean weight of the variants it takes part in (as the
    /// piece in place or the piece added).
    means: KeyMap<PartKind, f64>,
}

impl RuleBook {
    /// Indexes every variant of `rules`; where two rules make the same
    /// joint, the heavier one stands for it.
    pub fn new(rules: &RuleSet) -> RuleBook {
        let mut joints: KeyMap<Key, (f64, RuleId)> =
            KeyMap::with_capacity_and_hasher(rules.variants().len(), Default::default());
        let mut sums: KeyMap<PartKind, (f64, usize)> = KeyMap::default();
        for v in rules.variants() {
            let key = v.key();
            for part in [v.anchor, v.added] {
                let s = sums.entry(part).or_default();
                s.0 += v.weight;
                s.1 += 1;
            }
            let e = joints.entry(key).or_insert((v.weight, v.rule));
            if v.weight > e.0 || (v.weight == e.0 && v.rule < e.1) {
                *e = (v.weight, v.rule);
            }
        }
        let means = sums
            .into_iter()
            .map(|(part, (sum, n))| (part, (sum / n as f64).max(f64::MIN_POSITIVE)))
            .collect();
        RuleBook { joints, means }
    }

    /// The joint that adds `added` to `anchor` (as [`RuleBook::joint`]),
    /// its weight relative to the mean weight of the joints `part` (one of
    /// the two) takes part in: how typical the joint is of the way people
    /// join that part, whatever how often they use the part itself.
    pub fn typical(
        &self,
        anchor: &Placement,
        added: &Placement,
        dir: Dir,
        layer_ldu: i32,
        part: PartKind,
    ) -> Option<f64> {
        let (w, _) = self.joint(anchor, added, dir, layer_ldu)?;
        Some(w / self.means.get(&part).copied().unwrap_or(1.0))
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
