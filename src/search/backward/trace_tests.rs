//! A derivation of a twelve-brick shape with the paper's Figure 2 rules,
//! replayed in reverse through the trace one step at a time: every step
//! must be a match the trace generates, and the last piece must close.

use std::path::Path;
use std::time::{Duration, Instant};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::catalog::PartKind;
use crate::geom::{Cell, Rot};

fn figure2() -> RuleSet {
    RuleSet::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("rules/figure2.rules")).unwrap()
}

/// The twelve pieces of the test shape (as tests/backward.rs builds it).
fn pieces() -> Vec<Placement> {
    let b12 = PartKind::from_id("3004").unwrap();
    let b22 = PartKind::from_id("3003").unwrap();
    [
        (b12, 0, 0, 0),
        (b12, 2, 0, 0),
        (b12, 1, 0, 1),
        (b12, 3, 0, 1),
        (b12, 0, 0, 2),
        (b12, 2, 0, 2),
        (b22, 1, 0, 3),
        (b12, 4, 0, 0),
        (b12, 5, 0, 1),
        (b22, 4, 0, 2),
        (b12, 4, 0, 3),
        (b12, 1, 0, 4),
    ]
    .into_iter()
    .map(|(p, x, y, z)| Placement::new(p, Cell::new(x, y, z), Rot::R0))
    .collect()
}

fn tuning() -> Tuning {
    Tuning {
        b_min: 1000,
        b_max: 1000,
        complex_every: 0,
        node_budget: 1_000_000,
        restart: 0,
        deadline: Instant::now() + Duration::from_secs(60),
        step: 1,
        base: 0,
    }
}

/// Every match the trace generates at its current node.
fn matches(t: &Trace<'_>, frame: &Frame) -> Vec<(Placement, Placement, RuleRef)> {
    let mut out = Vec::new();
    for v in 0..t.rules.variants().len() as u32 {
        let mut from = 0;
        while let Some((c, k)) = t.match_basic(v, frame, from) {
            out.push((c.taken[0].0, c.taken[0].1, c.rule));
            from = k + 1;
        }
    }
    out
}

/// The voxels of `pieces`, in a grid the size of Figure 5's shape.
fn grid_of(pieces: &[Placement]) -> VoxelGrid {
    let mut grid = VoxelGrid::new(7, 3, 6);
    for q in pieces {
        grid.set_body(&q.body(24), true);
    }
    grid
}

#[test]
fn a_known_derivation_is_found_step_by_step_in_reverse() {
    let rules = figure2();
    let book = RuleBook::new(&rules);
    let p = pieces();
    let grid = grid_of(&p);
    let below = VoxelGrid::new(7, 3, 6);
    let mut t = Trace::new(&rules, &book, tuning(), grid, &below, &[], true);
    // Backward: (piece taken away, its anchor), pieces numbered from 1 as
    // listed in `pieces`.
    let steps = [
        (12, 7),
        (7, 5),
        (6, 4),
        (11, 10),
        (10, 4),
        (9, 8),
        (8, 4),
        (5, 3),
        (4, 2),
        (1, 3),
        (3, 2),
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let count = Counters::default();
    for (i, &(b, a)) in steps.iter().enumerate() {
        let (b, a) = (p[b - 1], p[a - 1]);
        let frame = t.frame(&mut rng, &count, None);
        let found = matches(&t, &frame);
        let Some(&(_, _, rule)) = found.iter().find(|m| m.0 == b && m.1 == a) else {
            panic!(
                "step {i}: ({b:?} on {a:?}) not generated; generated: {:?}",
                found
                    .iter()
                    .map(|m| (m.0.origin, m.1.origin))
                    .collect::<Vec<_>>()
            );
        };
        let c = Change {
            rule,
            taken: vec![(b, a)],
            new_pending: if t.is_pending(&a) { vec![] } else { vec![a] },
        };
        t.apply(&c);
        assert!(t.connected(), "step {i}: what is left falls apart");
    }
    let last = t
        .finished()
        .expect("the last piece closes with a starting rule");
    assert_eq!(
        last.expect("the first part ends in a starting rule").piece,
        p[1]
    );
}

#[test]
fn the_tuned_b_finds_a_derivation_for_every_seed_widening_when_a_pass_fails() {
    let rules = figure2();
    let book = RuleBook::new(&rules);
    let mut grid = VoxelGrid::new(7, 3, 6);
    for q in &pieces() {
        grid.set_body(&q.body(24), true);
    }
    let below = VoxelGrid::new(7, 3, 6);
    let mut widened = 0;
    for (b, seeds) in [((20, 150), 1..=5), ((1, 1), 1..=5)] {
        for seed in seeds {
            let mut tu = tuning();
            (tu.b_min, tu.b_max) = b;
            let mut t = Trace::new(&rules, &book, tu, grid.clone(), &below, &[], true);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let mut count = Counters::default();
            let d = t.run(&mut rng, &mut count).expect("a derivation");
            assert_eq!(d.len(), 12, "seed {seed}");
            assert_eq!(d[0].anchor, Anchor::Start);
            assert!(count.nodes < 5_000, "seed {seed}: {} nodes", count.nodes);
            widened += u32::from(t.widen > 1);
        }
    }
    // With b = 1 (one matching rule a node), some seed's first pass
    // misses and a wider one finds it.
    assert!(widened >= 1);
}

#[test]
fn the_luby_sequence_doubles_after_each_run_of_ones() {
    let terms: Vec<u64> = (1..=15).map(luby).collect();
    assert_eq!(terms, [1, 1, 2, 1, 1, 2, 4, 1, 1, 2, 1, 1, 2, 4, 8]);
}

/// The place-by-place list of the rules that match a node is the same set
/// as trying each rule: at every step of a known derivation, and on a box
/// with the default rules.
#[test]
fn listing_the_rules_that_match_agrees_with_trying_each() {
    let check = |t: &Trace<'_>, frame: &Frame, what: &str| {
        let listed = t.matching(frame, &KeySet::default());
        let tried: Vec<u32> = (0..t.rules.variants().len() as u32)
            .filter(|&v| t.rules.variants()[v as usize].weight > 0.0)
            .filter(|&v| t.match_basic(v, frame, 0).is_some())
            .collect();
        assert_eq!(listed, tried, "{what}");
    };
    let rules = figure2();
    let book = RuleBook::new(&rules);
    let p = pieces();
    let grid = grid_of(&p);
    let below = VoxelGrid::new(7, 3, 6);
    let mut t = Trace::new(&rules, &book, tuning(), grid, &below, &[], true);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let count = Counters::default();
    for (i, &(b, a)) in [(12, 7), (7, 5), (6, 4), (11, 10), (10, 4)]
        .iter()
        .enumerate()
    {
        let frame = t.frame(&mut rng, &count, None);
        check(&t, &frame, &format!("figure 2, step {i}"));
        let (b, a) = (p[b - 1], p[a - 1]);
        let found = matches(&t, &frame);
        let &(_, _, rule) = found.iter().find(|m| m.0 == b && m.1 == a).unwrap();
        let c = Change {
            rule,
            taken: vec![(b, a)],
            new_pending: if t.is_pending(&a) { vec![] } else { vec![a] },
        };
        t.apply(&c);
    }
    // The default rules (bricks) on a box of 4 x 3 studs, two courses: the
    // root, and a node after the first child.
    let rules = crate::grammar::default_rules()
        .restricted(|p| p.spec().family() == crate::catalog::Family::Brick)
        .unwrap();
    let book = RuleBook::new(&rules);
    let mut grid = VoxelGrid::new(4, 3, 2);
    for c in [0, 1] {
        for y in 0..3 {
            for x in 0..4 {
                grid.set(Cell::new(x, y, c), true);
            }
        }
    }
    let below = VoxelGrid::new(4, 3, 2);
    let mut t = Trace::new(&rules, &book, tuning(), grid, &below, &[], true);
    let frame = t.frame(&mut rng, &count, None);
    check(&t, &frame, "box, root");
    let (c, _) = (0..rules.variants().len() as u32)
        .find_map(|v| t.match_basic(v, &frame, 0))
        .unwrap();
    t.apply(&c);
    let frame = t.frame(&mut rng, &count, None);
    check(&t, &frame, "box, second node");
    // With slopes (layers half a brick high, 61,000 rule variants, most of
    // them joints people never made): a gabled block of 6 x 4 studs, two
    // courses and a ridge, at every node down a path of drawn matches.
    let rules = crate::grammar::default_rules()
        .restricted(|p| p.spec().family() != crate::catalog::Family::Plate)
        .unwrap();
    let book = RuleBook::new(&rules);
    let mut grid = VoxelGrid::new(6, 4, 6);
    for z in 0..6 {
        for y in 0..4 {
            for x in 0..6 {
                // Walls four layers high, then a ridge two layers high.
                if z < 4 || (1..3).contains(&y) {
                    grid.set(Cell::new(x, y, z), true);
                }
            }
        }
    }
    let below = VoxelGrid::new(6, 4, 6);
    let mut t = Trace::new(&rules, &book, tuning(), grid, &below, &[], true);
    let mut steps = 0;
    for i in 0..12 {
        let frame = t.frame(&mut rng, &count, None);
        check(&t, &frame, &format!("slopes, node {i}"));
        let listed = t.matching(&frame, &KeySet::default());
        let Some(c) = listed
            .iter()
            .rev()
            .find_map(|&v| t.match_basic(v, &frame, 0).map(|(c, _)| c))
        else {
            break;
        };
        t.apply(&c);
        steps += 1;
    }
    // (Six: a slope whose face would meet a voxel left over its low row
    // is no match, so the path drawn here ends sooner than it did.)
    assert!(steps >= 6, "{steps} steps");
}
