//! Rules drawn from their weights' categorical distribution, without
//! replacement (the paper's sampling of `b` rules at a node).
//!
//! The rule variants are grouped by the shapes of their two pieces (the
//! anchor's and the new piece's part and turn). A draw picks a group in
//! proportion to what weight it has left, then a variant of it in
//! proportion to its weight, and takes it out: successive sampling, the
//! same distribution as drawing from all variants at once. A group whose
//! shapes fit nowhere at a node is shut for that node the first time one
//! of its variants is drawn, so the draws seldom land on a rule that
//! cannot match, and taking a draw costs a few steps of two Fenwick trees,
//! however many rules there are. After the node's draws everything is put
//! back.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::catalog::PartKind;
use crate::geom::Rot;
use crate::grammar::Variant;

/// Weights are drawn as integers: each variant's weight times this,
/// rounded, and at least 1 (so a rule seen 0.05 times keeps its chance).
const SCALE: f64 = 10_000.0;

/// A piece's shape: its part and turn.
type Shape = (PartKind, Rot);

/// A Fenwick (binary indexed) tree of integer weights.
#[derive(Debug, Clone)]
struct Fenwick {
    tree: Vec<u64>,
    vals: Vec<u64>,
}

impl Fenwick {
    fn new(vals: Vec<u64>) -> Fenwick {
        let n = vals.len();
        let mut tree = vec![0u64; n + 1];
        for (i, &v) in vals.iter().enumerate() {
            tree[i + 1] += v;
            let j = i + 1 + ((i + 1) & (i + 1).wrapping_neg());
            if j <= n {
                tree[j] += tree[i + 1];
            }
        }
        Fenwick { tree, vals }
    }

    fn total(&self) -> u64 {
        let mut i = self.vals.len();
        let mut s = 0;
        while i > 0 {
            s += self.tree[i];
            i &= i - 1;
        }
        s
    }

    fn set(&mut self, i: usize, v: u64) {
        let old = self.vals[i];
        if old == v {
            return;
        }
        self.vals[i] = v;
        let mut j = i + 1;
        while j < self.tree.len() {
            self.tree[j] = self.tree[j] - old + v;
            j += j & j.wrapping_neg();
        }
    }

    /// The index whose stretch of the running total holds `u` (`u` below
    /// the total).
    fn find(&self, mut u: u64) -> usize {
        let n = self.vals.len();
        let mut pos = 0;
        let mut step = n.next_power_of_two();
        while step > 0 {
            let next = pos + step;
            if next <= n && self.tree[next] <= u {
                pos = next;
                u -= self.tree[next];
            }
            step >>= 1;
        }
        pos
    }
}

/// A group of variants: the same anchor shape and new piece shape.
#[derive(Debug, Clone)]
struct Group {
    variants: Vec<u32>,
    weights: Fenwick,
}

/// A variant drawn, and its group.
#[derive(Debug, Clone, Copy)]
pub(super) struct Drawn {
    pub variant: u32,
    group: usize,
    index: usize,
}

/// Draws of rule variants without replacement, put back after a node.
#[derive(Debug, Clone)]
pub(super) struct Draws {
    groups: Vec<Group>,
    top: Fenwick,
    /// What was taken out at this node: (group, index in it, weight).
    out: Vec<(usize, usize, u64)>,
    /// Groups closed at this node.
    closed: Vec<usize>,
}

impl Draws {
    /// The draws over `variants` (those of weight 0 are never drawn).
    pub fn new(variants: &[Variant]) -> Draws {
        let mut groups: Vec<Group> = Vec::new();
        let mut index: std::collections::HashMap<(Shape, Shape), usize> =
            std::collections::HashMap::new();
        let mut members: Vec<Vec<(u32, u64)>> = Vec::new();
        for (i, v) in variants.iter().enumerate() {
            if v.weight <= 0.0 {
                continue;
            }
            let key = ((v.anchor, v.anchor_rot), (v.added, v.added_rot));
            let g = *index.entry(key).or_insert_with(|| {
                groups.push(Group {
                    variants: Vec::new(),
                    weights: Fenwick::new(Vec::new()),
                });
                members.push(Vec::new());
                groups.len() - 1
            });
            let w = ((v.weight * SCALE).round() as u64).max(1);
            members[g].push((i as u32, w));
        }
        for (g, m) in groups.iter_mut().zip(members) {
            g.variants = m.iter().map(|&(i, _)| i).collect();
            g.weights = Fenwick::new(m.iter().map(|&(_, w)| w).collect());
        }
        let top = Fenwick::new(groups.iter().map(|g| g.weights.total()).collect());
        Draws {
            groups,
            top,
            out: Vec::new(),
            closed: Vec::new(),
        }
    }

    /// Opens a node again: what it drew before stays out, and the groups
    /// it shut stay shut.
    pub fn reopen(&mut self, drawn: &[Drawn], shut: &[Drawn]) {
        for d in drawn {
            let group = &mut self.groups[d.group];
            let w = group.weights.vals[d.index];
            if w > 0 {
                group.weights.set(d.index, 0);
                self.out.push((d.group, d.index, w));
            }
        }
        for d in drawn {
            let t = self.groups[d.group].weights.total();
            self.top.set(d.group, t);
        }
        for &d in shut {
            self.shut(d);
        }
    }

    /// Closes the group of variant draw `d` for the rest of the node:
    /// neither of its shapes fits anywhere here.
    pub fn shut(&mut self, d: Drawn) {
        self.top.set(d.group, 0);
        self.closed.push(d.group);
    }

    /// The next variant, drawn in proportion to its weight among those
    /// not drawn yet at this node; `None` when every one is drawn.
    pub fn draw(&mut self, rng: &mut ChaCha8Rng) -> Option<Drawn> {
        let total = self.top.total();
        if total == 0 {
            return None;
        }
        let g = self.top.find(rng.gen_range(0..total));
        let group = &mut self.groups[g];
        let k = group.weights.find(rng.gen_range(0..group.weights.total()));
        let w = group.weights.vals[k];
        group.weights.set(k, 0);
        let left = group.weights.total();
        self.top.set(g, left);
        self.out.push((g, k, w));
        Some(Drawn {
            variant: group.variants[k],
            group: g,
            index: k,
        })
    }

    /// Closes the node: everything drawn or closed is put back.
    pub fn close(&mut self) {
        let mut touched: Vec<usize> = self.closed.drain(..).collect();
        for (g, k, w) in self.out.drain(..).rev() {
            self.groups[g].weights.set(k, w);
            touched.push(g);
        }
        for g in touched {
            let t = self.groups[g].weights.total();
            self.top.set(g, t);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grammar::{Dir, RuleId};
    use rand::SeedableRng;

    /// Three variants of weights 1, 2 and 7; the first two share a group.
    fn variants() -> Vec<Variant> {
        let b12 = PartKind::from_id("3004").unwrap();
        let b22 = PartKind::from_id("3003").unwrap();
        let v = |added, weight| Variant {
            rule: RuleId(0),
            anchor: b12,
            anchor_rot: Rot::R0,
            added,
            added_rot: Rot::R0,
            offset: (0, 0, 1),
            dir: Dir::Up,
            weight,
        };
        vec![v(b12, 1.0), v(b12, 2.0), v(b22, 7.0)]
    }

    #[test]
    fn the_first_draw_falls_in_proportion_to_the_weights() {
        let mut d = Draws::new(&variants());
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut hits = [0u32; 3];
        for _ in 0..20_000 {
            hits[d.draw(&mut rng).unwrap().variant as usize] += 1;
            d.close();
        }
        let share: Vec<f64> = hits.iter().map(|&h| f64::from(h) / 20_000.0).collect();
        for (s, want) in share.iter().zip([0.1, 0.2, 0.7]) {
            assert!((s - want).abs() < 0.015, "{share:?}");
        }
    }

    #[test]
    fn a_node_draws_each_variant_once_and_keeps_them_out_when_opened_again() {
        let mut d = Draws::new(&variants());
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let first = d.draw(&mut rng).unwrap();
        d.close();
        // Opened again: the first draw stays out, the other two come.
        d.reopen(&[first], &[]);
        let mut rest: Vec<u32> = std::iter::from_fn(|| d.draw(&mut rng))
            .map(|x| x.variant)
            .collect();
        d.close();
        rest.push(first.variant);
        rest.sort();
        assert_eq!(rest, [0, 1, 2]);
        // A shut group is never drawn at the node.
        let x = d.draw(&mut rng).unwrap();
        d.shut(x);
        let others: Vec<u32> = std::iter::from_fn(|| d.draw(&mut rng))
            .map(|y| y.variant)
            .collect();
        d.close();
        let group_of = |v: u32| if v == 2 { 1 } else { 0 };
        assert!(others.iter().all(|&v| group_of(v) != group_of(x.variant)));
        // Closed, everything is back.
        let all = std::iter::from_fn(|| d.draw(&mut rng)).count();
        assert_eq!(all, 3);
    }

    #[test]
    fn a_fenwick_tree_finds_the_stretch_a_number_falls_in() {
        let f = Fenwick::new(vec![3, 0, 5, 2]);
        assert_eq!(f.total(), 10);
        let at: Vec<usize> = (0..10).map(|u| f.find(u)).collect();
        assert_eq!(at, [0, 0, 0, 2, 2, 2, 2, 2, 3, 3]);
    }
}
