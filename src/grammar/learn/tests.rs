//! Tests of rule learning on small inline builds.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use super::*;
use crate::geom::Cell;
use crate::grammar::defaults::generate;
use crate::grammar::{Variant, VariantKey, DEFAULT_ALPHABET};
use crate::ldraw::{parse_ldr, placement_position, rot_matrix};

fn kind(id: &str) -> PartKind {
    PartKind::from_id(id).unwrap()
}

/// A brick's height in LDU: the layers of [`pl`] and [`build_text`].
const BRICK: i32 = 24;

/// A plate's height in LDU: the layers of [`build_text_in`] for builds
/// with plates.
const PLATE: i32 = 8;

/// A piece at grid cell `(x, y, z)` turned by `rot`; `z` counts layers of
/// the grid the build is written in (brick layers for [`build_text`]).
fn pl(id: &str, x: i32, y: i32, z: i32, rot: Rot) -> Placement {
    Placement::new(kind(id), Cell::new(x, y, z), rot)
}

/// `p` with the whole build turned by `t` about the vertical axis.
fn turned(p: &Placement, t: Rot) -> Placement {
    // Any layer height that divides every part's will do: turns keep z.
    let b = p.body(PLATE).bbox.turned(t);
    Placement::new(p.part, b.min, p.rot.then(t))
}

/// The LDraw line of `p` (in a grid of brick layers) in colour `color`.
fn line(p: &Placement, color: u16) -> String {
    line_in(BRICK, p, color)
}

/// The LDraw line of `p`, in a grid of `layer_ldu`-high layers, in colour
/// `color`.
fn line_in(layer_ldu: i32, p: &Placement, color: u16) -> String {
    let [x, y, z] = placement_position(p, layer_ldu);
    let m = rot_matrix(p.rot)
        .concat()
        .iter()
        .map(i32::to_string)
        .collect::<Vec<_>>()
        .join(" ");
    format!("1 {color} {x} {y} {z} {m} {}.dat\n", p.part)
}

/// A build of `pieces` (in brick layers) in order, one step each, in red.
fn build_text(pieces: &[Placement]) -> String {
    build_text_in(BRICK, pieces)
}

/// A build of `pieces`, in a grid of `layer_ldu`-high layers, in order, one
/// step each, in red.
fn build_text_in(layer_ldu: i32, pieces: &[Placement]) -> String {
    pieces
        .iter()
        .map(|p| line_in(layer_ldu, p, 4) + "0 STEP\n")
        .collect()
}

fn model(text: &str, name: &str) -> LdrModel {
    parse_ldr(text, Path::new(name)).expect("test builds parse")
}

/// Learns from inline builds, each `(name, text)`.
fn learn_texts(builds: &[(&str, &str)]) -> Result<Learned, LearnError> {
    let mut learner = Learner::new();
    for (name, text) in builds {
        learner.add(&parse_ldr(text, Path::new(name))?)?;
    }
    learner.finish()
}

fn learn_one(text: &str) -> Learned {
    learn_texts(&[("t.ldr", text)]).unwrap()
}

fn learn_err(text: &str) -> String {
    learn_texts(&[("t.ldr", text)]).unwrap_err().to_string()
}

fn key(anchor: &str, added: &str, dir: Dir, rot: Rot, dx: i32, dy: i32) -> RuleKey {
    RuleKey {
        anchor: kind(anchor),
        added: kind(added),
        dir,
        added_rot: rot,
        dx,
        dy,
    }
}

fn counts(l: &Learned) -> Vec<(RuleKey, u64)> {
    l.counts.iter().map(|(k, &n)| (*k, n)).collect()
}

#[test]
fn a_2x4_on_two_2x4s_counts_one_rule_for_each() {
    // Two 2x4s end to end, then a 2x4 on top one stud in: it holds 3
    // studs' width of the first and 1 of the second, two different joints.
    let first = pl("3001", 0, 0, 0, Rot::R0);
    let second = pl("3001", 4, 0, 0, Rot::R0);
    let l = learn_one(&build_text(&[first, second, pl("3001", 1, 0, 1, Rot::R0)]));
    assert_eq!(
        counts(&l),
        [
            (key("3001", "3001", Dir::Up, Rot::R0, -3, 0), 1),
            (key("3001", "3001", Dir::Up, Rot::R0, -1, 0), 1),
        ]
    );
    assert_eq!(
        (l.distinct(), l.total(), l.count_range()),
        (2, 2, Some((1, 1)))
    );
    // Two pieces connect to nothing before them: no data for them.
    assert_eq!(l.report.starts, 2);

    // Centred over the seam (running bond), both joints are one rule seen
    // from either side: one rule, count 2.
    let l = learn_one(&build_text(&[first, second, pl("3001", 2, 0, 1, Rot::R0)]));
    assert_eq!(
        counts(&l),
        [(key("3001", "3001", Dir::Up, Rot::R0, -2, 0), 2)]
    );
}

#[test]
fn a_piece_connected_to_nothing_earlier_adds_nothing() {
    // Two 2x4s apart, then a 1x1 on the first: one count only.
    let l = learn_one(&build_text(&[
        pl("3001", 0, 0, 0, Rot::R0),
        pl("3001", 10, 0, 0, Rot::R0),
        pl("3005", 0, 0, 1, Rot::R0),
    ]));
    assert_eq!(
        counts(&l),
        [(key("3001", "3005", Dir::Up, Rot::R0, 0, 0), 1)]
    );
    assert_eq!((l.report.starts, l.report.learned_pieces), (2, 3));

    // A lone piece gives a rule file with its part and starting rule only.
    let l = learn_one(&build_text(&[pl("3003", 0, 0, 0, Rot::R0)]));
    assert!(l.counts.is_empty());
    assert_eq!(l.report.starts, 1);
    let text = l.to_rules_text();
    assert!(text.contains("\npart 3003 "), "{text}");
    assert!(text.contains("\nstart 3003\n"), "{text}");
    assert!(!text.contains("\nrule "), "{text}");
    assert!(text.contains("0 rules, total count 0."), "{text}");
}

#[test]
fn a_piece_pressed_on_from_below_counts_down() {
    // The top brick first, then a 1x2 pushed onto its underside.
    let l = learn_one(&build_text(&[
        pl("3001", 0, 0, 1, Rot::R0),
        pl("3004", 2, 1, 0, Rot::R0),
    ]));
    assert_eq!(
        counts(&l),
        [(key("3001", "3004", Dir::Down, Rot::R0, 0, 0), 1)]
    );
}

/// The base, a two-brick tower built on its own (`tower.ldr`), and a
/// 1x1 put on the tower's top in the main model.
const TOWER_MPD: &str = "\
0 FILE main.ldr
1 4 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat
0 STEP
1 4 0 -24 0 1 0 0 0 1 0 0 0 1 tower.ldr
0 STEP
1 4 10 -96 10 1 0 0 0 1 0 0 0 1 3005.dat
0 STEP
0 NOFILE
0 FILE tower.ldr
1 16 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat
0 STEP
1 16 20 -48 10 1 0 0 0 1 0 0 0 1 3004.dat
0 STEP
0 NOFILE
";

#[test]
fn a_separately_built_submodel_counts_inside_but_not_where_attached() {
    let l = learn_one(TOWER_MPD);
    // Only the tower's own joint: its 1x2 on its 2x4. The tower's 2x4 on
    // the base and the main model's 1x1 on the tower attach shapes.
    assert_eq!(
        counts(&l),
        [(key("3001", "3004", Dir::Up, Rot::R0, 0, 0), 1)]
    );
    assert_eq!(l.report.attachments, 2);
    assert_eq!(l.report.submodel_builds, 1);
    assert_eq!(l.report.learned_pieces, 4);

    // Each reference is one more build of the tower: two towers, two
    // counts; the second tower stands on the ground, attached to nothing.
    let twice = TOWER_MPD.replace(
        "0 STEP\n0 NOFILE\n0 FILE tower.ldr",
        "1 4 200 0 0 1 0 0 0 1 0 0 0 1 tower.ldr\n0 STEP\n0 NOFILE\n0 FILE tower.ldr",
    );
    let l = learn_one(&twice);
    assert_eq!(
        counts(&l),
        [(key("3001", "3004", Dir::Up, Rot::R0, 0, 0), 2)]
    );
    assert_eq!((l.report.attachments, l.report.submodel_builds), (2, 2));

    // A submodel nested in the tower is another separate build: its joint
    // to the tower is an attachment too. The cap is two 1x1s, the first on
    // the tower's 1x2 beside the main model's 1x1.
    let nested = TOWER_MPD.replace(
        "1 16 20 -48 10 1 0 0 0 1 0 0 0 1 3004.dat\n",
        "1 16 20 -48 10 1 0 0 0 1 0 0 0 1 3004.dat\n\
         1 16 0 -72 0 1 0 0 0 1 0 0 0 1 cap.ldr\n",
    ) + "0 FILE cap.ldr\n1 16 30 0 10 1 0 0 0 1 0 0 0 1 3005.dat\n\
         1 16 30 -24 10 1 0 0 0 1 0 0 0 1 3005.dat\n";
    let l = learn_one(&nested);
    assert_eq!(
        counts(&l),
        [
            (key("3005", "3005", Dir::Up, Rot::R0, 0, 0), 1),
            (key("3001", "3004", Dir::Up, Rot::R0, 0, 0), 1),
        ]
    );
    // Base-tower, tower-1x1 (main), and cap-tower.
    assert_eq!((l.report.attachments, l.report.submodel_builds), (3, 2));
}

#[test]
fn parts_outside_the_catalog_are_skipped_and_reported() {
    let text = "\
1 4 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat
1 4 40 -32 20 1 0 0 0 1 0 0 0 1 87079.dat
1 4 40 -56 20 1 0 0 0 1 0 0 0 1 3001.DAT
1 4 40 -64 20 1 0 0 0 1 0 0 0 1 87079.dat
1 4 0 0 0 1 0 0 0 0 -1 0 1 0 6141.dat
";
    let l = learn_one(text);
    // The bricks sit on tiles, never on each other: nothing to count.
    assert!(l.counts.is_empty());
    let r = &l.report;
    assert_eq!((r.pieces, r.learned_pieces), (5, 2));
    let skipped: Vec<(&str, usize, usize)> = r
        .skipped
        .iter()
        .map(|s| (s.part.as_str(), s.count, s.first.line))
        .collect();
    assert_eq!(skipped, [("87079", 2, 2), ("6141", 1, 5)]);
    assert_eq!(r.skipped[0].first.file, Path::new("t.ldr"));
    assert_eq!(r.parts, [kind("3001")]);
    let summary = l.summary();
    assert!(
        summary.contains("5 pieces, 2 of catalog parts, 3 skipped"),
        "{summary}"
    );
    assert!(
        summary.contains("2 x 87079      first at t.ldr:2"),
        "{summary}"
    );
}

#[test]
fn colour_does_not_matter() {
    let pieces = [
        pl("3001", 0, 0, 0, Rot::R0),
        pl("3001", 2, 1, 1, Rot::R90),
        pl("3003", 2, 1, 2, Rot::R0),
    ];
    let colours = |cs: [u16; 3]| -> String {
        pieces
            .iter()
            .zip(cs)
            .map(|(p, c)| line(p, c) + "0 STEP\n")
            .collect()
    };
    let red = learn_one(&colours([4, 4, 4]));
    let mixed = learn_one(&colours([16, 1, 71]));
    assert_eq!(red.total(), 2);
    assert_eq!(red.counts, mixed.counts);
    assert_eq!(red.to_rules_text(), mixed.to_rules_text());
}

#[test]
fn one_joint_seen_at_all_four_turns_is_one_rule_counted_four_times() {
    // A 1x2 across the end of a 2x4, on top and underneath, the whole pair
    // turned each of the four ways (the 2x4 written as LDraw turns it).
    let anchor = pl("3001", 0, 0, 1, Rot::R0);
    for (added, dir) in [
        (pl("3004", 3, 0, 2, Rot::R90), Dir::Up),
        (pl("3004", 3, 0, 0, Rot::R270), Dir::Down),
    ] {
        let texts: Vec<(String, String)> = Rot::ALL
            .iter()
            .map(|&t| {
                let text = build_text(&[turned(&anchor, t), turned(&added, t)]);
                (format!("{}.ldr", t.name()), text)
            })
            .collect();
        let builds: Vec<(&str, &str)> = texts
            .iter()
            .map(|(n, t)| (n.as_str(), t.as_str()))
            .collect();
        let l = learn_texts(&builds).unwrap();
        assert_eq!(
            counts(&l),
            [(key("3001", "3004", dir, Rot::R90, 0, 0), 4)],
            "{dir:?}"
        );
        // The rule file holds it once; loading it gives its four turns.
        let rs = RuleSet::parse(&l.to_rules_text(), Path::new("l.rules")).unwrap();
        assert_eq!(rs.rules().len(), 1);
        assert_eq!(rs.variants().len(), 4);
        assert!(rs.variants().iter().all(|v| v.weight == 1.0));
    }
    // A 2x2 centred on a 2x2 looks the same every way: one variant.
    let l = learn_texts(&[(
        "sq.ldr",
        &build_text(&[pl("3003", 0, 0, 0, Rot::R0), pl("3003", 0, 0, 1, Rot::R90)]),
    )])
    .unwrap();
    assert_eq!(
        counts(&l),
        [(key("3003", "3003", Dir::Up, Rot::R0, 0, 0), 1)]
    );
}

/// The variant an observed joint of `b` to `a` is, in a rule set's grid of
/// `layer_ldu`-high layers.
fn observed_variant(a: &Placement, b: &Placement, dir: Dir, layer_ldu: i32) -> VariantKey {
    let (ab, bb) = (a.body(layer_ldu).bbox, b.body(layer_ldu).bbox);
    let dz = match dir {
        Dir::Up => ab.sz,
        Dir::Down => -bb.sz,
    };
    let offset = (bb.min.x - ab.min.x, bb.min.y - ab.min.y, dz);
    (a.part, a.rot, b.part, b.rot, offset, dir)
}

#[test]
fn the_learned_rule_set_has_exactly_the_variants_of_the_observed_joints() {
    // Every joint of the default alphabet (bricks, plates and slopes): each
    // pair of parts, each turn of the new piece, each overlapping offset,
    // up and down, each built once with the whole pair turned some way.
    // Where the footprints overlap but no stud meets a tube (on a slope's
    // front row), the pair is built too and must count nothing.
    let parts: Vec<PartKind> = DEFAULT_ALPHABET.iter().map(|id| kind(id)).collect();
    let rule_layer = crate::grammar::layer_ldu_for(&parts);
    let mut learner = Learner::new();
    let mut observed: BTreeSet<VariantKey> = BTreeSet::new();
    let (mut joints, mut apart) = (0u64, 0u64);
    for &a in &parts {
        for &b in &parts {
            for rot in Rot::ALL {
                let (ax, ay) = a.spec().footprint(Rot::R0);
                let (bx, by) = b.spec().footprint(rot);
                // In plate layers, A three bricks up; B on it or under it.
                let z0 = 9;
                for dir in [Dir::Up, Dir::Down] {
                    let z = match dir {
                        Dir::Up => z0 + a.spec().height_ldu() / PLATE,
                        Dir::Down => z0 - b.spec().height_ldu() / PLATE,
                    };
                    for dy in 1 - by..ay {
                        for dx in 1 - bx..ax {
                            let n = joints + apart;
                            let t = Rot::from_quarter_turns((dx + 2 * dy + n as i32) as u8 & 3);
                            let pa = Placement::new(a, Cell::new(0, 0, z0), Rot::R0);
                            let pb = Placement::new(b, Cell::new(dx, dy, z), rot);
                            let (ba, bb) = (pa.body(PLATE), pb.body(PLATE));
                            let linked = match dir {
                                Dir::Up => ba.holds(&bb),
                                Dir::Down => bb.holds(&ba),
                            };
                            let (pa, pb) = (turned(&pa, t), turned(&pb, t));
                            let text = build_text_in(PLATE, &[pa, pb]);
                            learner.add(&model(&text, "joint.ldr")).unwrap();
                            if !linked {
                                apart += 1;
                                continue;
                            }
                            for u in Rot::ALL {
                                let (ta, tb) = (turned(&pa, u), turned(&pb, u));
                                observed.insert(observed_variant(&ta, &tb, dir, rule_layer));
                            }
                            joints += 1;
                        }
                    }
                }
            }
        }
    }
    // Slopes leave some overlaps unconnected; bricks and plates none.
    assert!(
        apart > 0 && joints > apart,
        "{joints} joints, {apart} apart"
    );
    let l = learner.finish().unwrap();
    assert_eq!(l.total(), joints);

    // The rule file loads to the same rule set, whose variants are exactly
    // the observed joints and all their turns, each once.
    let rs = RuleSet::parse(&l.to_rules_text(), Path::new("learned.rules")).unwrap();
    assert_eq!(rs.variants(), l.rule_set().variants());
    let keys: Vec<VariantKey> = rs.variants().iter().map(Variant::key).collect();
    let distinct: BTreeSet<VariantKey> = keys.iter().copied().collect();
    assert_eq!(
        distinct.len(),
        keys.len(),
        "two learned rules share a variant"
    );
    assert_eq!(distinct, observed);

    // The same rules as the generated default set, which merges the rules
    // that are turns of each other in its own way.
    let generated = generate(&DEFAULT_ALPHABET);
    assert_eq!(rs.rules().len(), generated.rules().len());
    let generated: BTreeSet<VariantKey> = generated.variants().iter().map(Variant::key).collect();
    assert_eq!(distinct, generated);

    // Each rule's count is shared among its turns.
    let weight: f64 = rs.variants().iter().map(|v| v.weight).sum();
    assert!(
        (weight - joints as f64).abs() < 1e-6,
        "{weight} vs {joints}"
    );
}

#[test]
fn the_rule_file_names_the_builds_and_round_trips() {
    let pieces = [
        pl("3001", 0, 0, 0, Rot::R0),
        pl("3001", 4, 0, 0, Rot::R0),
        pl("3001", 2, 0, 1, Rot::R0),
        pl("3004", 2, 0, 2, Rot::R90),
    ];
    let text = build_text(&pieces);
    let l = learn_texts(&[("walls/b.ldr", &text), ("a.ldr", TOWER_MPD)]).unwrap();
    let file = l.to_rules_text();
    assert!(
        file.starts_with("# brickwright rule file: the Lego rewriting system (Σ, R).\n"),
        "{file}"
    );
    assert!(
        file.contains(
            "# Learned by `brickwright learn` from 2 builds (1 separately built submodel),\n\
             # with the authors and licences their files name:\n\
             #   a.ldr\n\
             #   b.ldr\n"
        ),
        "{file}"
    );
    assert!(
        file.contains("# 3 rules, total count 4, counts from 1 to 2.\n"),
        "{file}"
    );
    let rules: Vec<&str> = file.lines().filter(|l| l.starts_with("rule ")).collect();
    // By anchor, then new part, in catalog order (3004 before 3001).
    assert_eq!(
        rules,
        [
            "rule 3001   3004   r0   up      0   0  1",
            "rule 3001   3004   r90  up      0   0  1",
            "rule 3001   3001   r0   up     -2   0  2",
        ]
    );
    let rs = RuleSet::parse(&file, Path::new("l.rules")).unwrap();
    // The parts seen, and the rest of the built-in alphabet beside them.
    assert_eq!(rs.alphabet().len(), crate::grammar::DEFAULT_ALPHABET.len());
    for id in ["3005", "3004", "3001", "3003", "3024", "3039"] {
        assert!(rs.alphabet().contains(&kind(id)), "{id}");
    }
    assert_eq!(rs.starts().len(), rs.alphabet().len());
    assert!(
        file.contains("Parts: the 3 the builds used, and 20 more"),
        "{file}"
    );
    assert_eq!(rs.variants(), l.rule_set().variants());
    assert_eq!(rs.to_text("x"), l.rule_set().to_text("x"));
    // Restricted to the parts seen.
    let seen = l.clone().seen_parts_only().unwrap();
    let text = seen.to_rules_text();
    assert!(!text.contains("Parts: "), "{text}");
    let rs = RuleSet::parse(&text, Path::new("l.rules")).unwrap();
    assert_eq!(rs.alphabet(), [kind("3005"), kind("3004"), kind("3001")]);
    assert_eq!(rs.starts().len(), 3);
    assert_eq!(rs.variants(), seen.rule_set().variants());
}

#[test]
fn the_same_files_in_any_order_give_the_same_rule_file() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| -> PathBuf {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let a = write("a.ldr", TOWER_MPD);
    let b = write(
        "b.LDR",
        &build_text(&[pl("3001", 0, 0, 0, Rot::R0), pl("3003", 1, 0, 1, Rot::R0)]),
    );
    let c = write(
        "c.mpd",
        &build_text(&[pl("3002", 0, 0, 0, Rot::R90), pl("3005", 1, 2, 1, Rot::R0)]),
    );
    write("notes.txt", "not a build");
    let one = learn(&[a.clone(), b.clone(), c.clone()]).unwrap();
    let text = one.to_rules_text();
    for order in [
        vec![c.clone(), a.clone(), b.clone()],
        vec![b.clone(), c.clone(), a.clone(), b.clone()],
        vec![dir.path().to_path_buf()],
        vec![a.clone(), dir.path().to_path_buf()],
    ] {
        let other = learn(&order).unwrap();
        assert_eq!(other.report.builds, one.report.builds, "{order:?}");
        assert_eq!(other.to_rules_text(), text, "{order:?}");
    }
    assert_eq!(one.report.builds, [a, b, c]);
}

#[test]
fn tilted_and_off_grid_pieces_are_skipped_and_counted() {
    let brick = "1 4 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat\n";
    let text = format!(
        "{brick}1 4 45 -48 20 1 0 0 0 1 0 0 0 1 3001.dat\n\
         1 4 40 -26 20 1 0 0 0 1 0 0 0 1 3001.dat\n\
         0 c\n1 4 40 -48 20 1 0 0 0 0 -1 0 1 0 3001.dat\n\
         1 4 40 -48 20 1 0 0 0 1 0 0 0 1 3001.dat\n\
         1 4 40 -48 20 1 0 0 0 1 0 0 0 1 87079.dat\n"
    );
    let l = learn_one(&text);
    let r = &l.report;
    assert_eq!(
        (r.tilted, r.off_grid, r.learned_pieces, r.pieces),
        (1, 2, 2, 6)
    );
    let b = &r.per_build[0];
    assert_eq!((b.unknown, b.tilted, b.off_grid, b.learned), (1, 1, 2, 2));
    assert_eq!((b.first_off_grid, b.first_tilted), (Some(2), Some(5)));
    // The two bricks on the grid still teach their joint.
    assert_eq!(l.total(), 1);
    let s = l.summary();
    assert!(
        s.contains("skipped: 1 not in the catalog, 1 tilted, 2 off the grid"),
        "{s}"
    );
    assert!(s.contains("t.ldr: learned 2 of 6; skipped 1 not in the catalog, 1 tilted (first at line 5), 2 off the grid (first at line 2)"), "{s}");
}

#[test]
fn a_build_with_nothing_to_learn_is_skipped_among_others() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("a.ldr");
    let empty = dir.path().join("b.ldr");
    std::fs::write(
        &good,
        "1 4 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat\n1 4 40 -48 20 1 0 0 0 1 0 0 0 1 3001.dat\n",
    )
    .unwrap();
    std::fs::write(&empty, "1 4 0 -8 0 1 0 0 0 1 0 0 0 1 87079.dat\n").unwrap();
    let l = learn(&[dir.path().to_path_buf()]).unwrap();
    assert_eq!(l.report.builds, [good]);
    assert_eq!(l.report.empty_builds.len(), 1);
    assert_eq!(l.report.empty_builds[0].0, empty);
    assert!(l
        .summary()
        .contains("b.ldr: skipped whole: its 1 part references are all outside"));
}

#[test]
fn bad_builds_are_errors_naming_file_and_line() {
    let brick = "1 4 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat\n";
    let cases = [
        (
            "1 4 45 -48 20 1 0 0 0 1 0 0 0 1 3001.dat\n".to_string(),
            "t.ldr: nothing to learn from: of its 1 part references, 0 are tilted, 1 off the grid and 0 outside brickwright's catalog",
        ),
        (
            format!("{brick}this is not LDraw\n"),
            "t.ldr:2: not LDraw text",
        ),
        (
            "0 an empty model\n0 STEP\n".to_string(),
            "t.ldr: nothing to learn from: it has no part references (type-1 lines)",
        ),
        (
            "1 4 0 -8 0 1 0 0 0 1 0 0 0 1 3068b.dat\n1 4 0 -8 0 1 0 0 0 1 0 0 0 1 87079.dat\n\
             1 4 0 -8 0 1 0 0 0 1 0 0 0 1 3068b.dat\n"
                .to_string(),
            "t.ldr: nothing to learn from: its 3 part references are all outside brickwright's catalog (3068b, 87079)",
        ),
    ];
    for (text, want) in cases {
        let e = learn_err(&text);
        assert!(e.starts_with(want), "got  {e}\nwant {want}");
    }
    // A plate-high step, and a half-plate one, are on the grid: fine.
    for y in [-32, -28] {
        learn_one(&format!(
            "{brick}1 4 40 {y} 20 1 0 0 0 1 0 0 0 1 3001.dat\n"
        ));
    }

    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.ldr");
    let e = learn(std::slice::from_ref(&missing))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.ldr: cannot read the file"), "{e}");
    let e = learn(&[dir.path().to_path_buf()]).unwrap_err().to_string();
    assert!(
        e.ends_with(": no .ldr or .mpd files in this directory"),
        "{e}"
    );
    assert!(matches!(learn(&[]), Err(LearnError::NoBuilds)));
}

/// Loads `l`'s rule file and checks it is `l`'s rule set and every variant
/// stud-connects its pieces.
fn loads(l: &Learned) -> RuleSet {
    let rs = RuleSet::parse(&l.to_rules_text(), Path::new("l.rules")).unwrap();
    assert_eq!(rs.variants(), l.rule_set().variants());
    for v in rs.variants() {
        let a = rs.body(v.anchor, v.anchor_rot, Cell::new(0, 0, 0));
        let (dx, dy, dz) = v.offset;
        let b = rs.body(v.added, v.added_rot, Cell::new(dx, dy, dz));
        match v.dir {
            Dir::Up => assert!(a.holds(&b), "{v:?}"),
            Dir::Down => assert!(b.holds(&a), "{v:?}"),
        }
    }
    rs
}

#[test]
fn a_slope_on_a_brick_and_a_brick_on_a_slopes_back_row_are_learned() {
    // A 2x2 slope on a 2x4, its studded back row (the part's +y) at y = 1,
    // then a 1x2 on that back row; the whole build turned each way.
    let pieces = [
        pl("3001", 0, 0, 0, Rot::R0),
        pl("3039", 1, 0, 1, Rot::R0),
        pl("3004", 1, 1, 2, Rot::R0),
    ];
    for t in Rot::ALL {
        let turned_pieces: Vec<Placement> = pieces.iter().map(|p| turned(p, t)).collect();
        let l = learn_one(&build_text(&turned_pieces));
        assert_eq!(
            counts(&l),
            [
                (key("3001", "3039", Dir::Up, Rot::R0, 1, 0), 1),
                (key("3039", "3004", Dir::Up, Rot::R0, 0, 1), 1),
            ],
            "{t:?}"
        );
        assert_eq!(
            (l.report.starts, l.report.layer_ldu),
            (1, 12),
            "slopes need half-brick layers"
        );
        // Over the parts seen (the built-in alphabet has plates, and its
        // layers would be a plate high).
        let rs = loads(&l.clone().seen_parts_only().unwrap());
        // Slopes look different every way: four variants a rule.
        assert_eq!((rs.rules().len(), rs.variants().len()), (2, 8));
        assert_eq!(rs.layer_ldu(), 12);
        let text = l.to_rules_text();
        assert!(
            text.contains("\nrule 3001   3039   r0   up      1   0  1\n"),
            "{text}"
        );
        assert!(
            text.contains("\nrule 3039   3004   r0   up      0   1  1\n"),
            "{text}"
        );
    }
    // Facing the other way on the brick, the slope makes the same joint
    // (the 2x4 looks the same turned a half turn); turned a quarter, it
    // makes another.
    for (rot, want) in [
        (Rot::R180, Rot::R0),
        (Rot::R90, Rot::R90),
        (Rot::R270, Rot::R90),
    ] {
        let l = learn_one(&build_text(&[
            pl("3001", 0, 0, 0, Rot::R0),
            pl("3039", 1, 0, 1, rot),
        ]));
        assert_eq!(
            counts(&l),
            [(key("3001", "3039", Dir::Up, want, 1, 0), 1)],
            "{rot:?}"
        );
        loads(&l);
    }
}

#[test]
fn a_piece_on_a_slopes_front_row_is_not_connected() {
    // The front row (y = 0) has no studs: a 1x2 on it holds nothing, turned
    // any way; a 2x2 over both rows holds on to the back row.
    let slope = pl("3039", 0, 0, 0, Rot::R0);
    for t in Rot::ALL {
        let on_front = [slope, pl("3004", 0, 0, 1, Rot::R0)].map(|p| turned(&p, t));
        let l = learn_one(&build_text(&on_front));
        assert!(l.counts.is_empty(), "{t:?}: {:?}", counts(&l));
        assert_eq!(l.report.starts, 2);
        let over_both = [slope, pl("3003", 0, 0, 1, Rot::R0)].map(|p| turned(&p, t));
        let l = learn_one(&build_text(&over_both));
        assert_eq!(
            counts(&l),
            [(key("3039", "3003", Dir::Up, Rot::R0, 0, 0), 1)],
            "{t:?}"
        );
        loads(&l);
    }
    // An inverted slope takes studs from below under its back row only.
    let inverted = pl("3660a", 0, 0, 1, Rot::R0);
    let l = learn_one(&build_text(&[inverted, pl("3004", 0, 0, 0, Rot::R0)]));
    assert!(l.counts.is_empty(), "{:?}", counts(&l));
    let l = learn_one(&build_text(&[inverted, pl("3004", 0, 1, 0, Rot::R0)]));
    assert_eq!(
        counts(&l),
        [(key("3660a", "3004", Dir::Down, Rot::R0, 0, 1), 1)]
    );
    loads(&l);
}

#[test]
fn a_plate_on_a_brick_counts() {
    // In plate layers: a 2x4 brick, a 2x4 plate half on it, a 2x4 brick on
    // the plate.
    let l = learn_one(&build_text_in(
        PLATE,
        &[
            pl("3001", 0, 0, 0, Rot::R0),
            pl("3020", 2, 0, 3, Rot::R0),
            pl("3001", 2, 0, 4, Rot::R0),
        ],
    ));
    assert_eq!(
        counts(&l),
        [
            (key("3001", "3020", Dir::Up, Rot::R0, -2, 0), 1),
            (key("3020", "3001", Dir::Up, Rot::R0, 0, 0), 1),
        ]
    );
    assert_eq!(l.report.layer_ldu, PLATE);
    let rs = loads(&l);
    assert_eq!(rs.layer_ldu(), PLATE);
    // Pressed on from below: down.
    let l = learn_one(&build_text_in(
        PLATE,
        &[pl("3001", 0, 0, 1, Rot::R0), pl("3020", 0, 0, 0, Rot::R90)],
    ));
    assert_eq!(
        counts(&l),
        [(key("3001", "3020", Dir::Down, Rot::R90, 0, 0), 1)]
    );
    loads(&l);
}

#[test]
fn one_grid_for_the_whole_run_and_the_rules_do_not_depend_on_it() {
    // A stack of two 2x4s, learned alone and beside builds that need finer
    // layers: 1x1s half a brick apart (12 LDU), a plate (8), both (4).
    let stack = build_text(&[pl("3001", 0, 0, 0, Rot::R0), pl("3001", 1, 0, 1, Rot::R0)]);
    let half = "1 4 10 -24 10 1 0 0 0 1 0 0 0 1 3005.dat\n\
                1 4 110 -36 10 1 0 0 0 1 0 0 0 1 3005.dat\n";
    let plate = "1 4 10 -8 10 1 0 0 0 1 0 0 0 1 3024.dat\n";
    let alone = learn_one(&stack);
    assert_eq!(alone.report.layer_ldu, BRICK);
    assert_eq!(
        counts(&alone),
        [(key("3001", "3001", Dir::Up, Rot::R0, -1, 0), 1)]
    );
    for (others, layer) in [(vec![half], 12), (vec![plate], 8), (vec![half, plate], 4)] {
        let mut builds = vec![("stack.ldr", stack.as_str())];
        builds.extend(others.iter().map(|t| ("other.ldr", *t)));
        let l = learn_texts(&builds).unwrap();
        assert_eq!(l.report.layer_ldu, layer);
        assert_eq!(l.counts, alone.counts, "at {layer} LDU");
        loads(&l);
    }
    // A build lifted off the ground by half a plate is the same build.
    let lifted = stack.replace(" -24 ", " -28 ").replace(" -48 ", " -52 ");
    let l = learn_one(&lifted);
    assert_eq!((l.report.layer_ldu, &l.counts), (BRICK, &alone.counts));
}

#[test]
fn summary_sets_the_totals_beside_the_papers() {
    let l = learn_one(&build_text(&[
        pl("3001", 0, 0, 0, Rot::R0),
        pl("3001", 4, 0, 0, Rot::R0),
        pl("3001", 2, 0, 1, Rot::R0),
    ]));
    let s = l.summary();
    assert!(s.starts_with("read 1 build (0 separately built submodels): 3 pieces, 3 of catalog parts, 0 skipped\n"), "{s}");
    assert!(
        s.contains("  distinct rules             1         223\n"),
        "{s}"
    );
    assert!(
        s.contains("  total count                2       2,484\n"),
        "{s}"
    );
    assert!(
        s.contains("  counts                2 to 2    1 to 139\n"),
        "{s}"
    );
    // Every count in thousands: 1,001 1x1s in a row, none on another.
    let row: Vec<Placement> = (0..1001).map(|x| pl("3005", x, 0, 0, Rot::R0)).collect();
    let l = learn_one(&build_text(&row));
    let s = l.summary();
    assert!(
        s.contains(": 1,001 pieces, 1,001 of catalog parts, 0 skipped\n"),
        "{s}"
    );
    let text = l.to_rules_text();
    assert!(
        text.contains("# 1,001 pieces read: 1,001 of catalog parts, 0 skipped"),
        "{text}"
    );
    assert_eq!(thousands(1_234_567), "1,234,567");
    assert_eq!(thousands(999), "999");
}

/// The rule file credits each build's authors and licence, as its file
/// names them, and only its model sections' (not packed parts').
#[test]
fn the_rule_file_credits_the_builds_authors_and_licences() {
    let text = "0 FILE wall.ldr\n0 Author: Ann Builder [ann]\n\
        0 !LICENSE Redistributable under CC BY-SA version 4.0\n\
        1 4 0 -24 0 1 0 0 0 1 0 0 0 1 3001.dat\n\
        1 4 40 -48 0 1 0 0 0 1 0 0 0 1 3001.dat\n1 4 0 0 0 1 0 0 0 1 0 0 0 1 sub.ldr\n\
        0 FILE sub.ldr\n0 Author: Bo Second\n0 Author: Ann Builder [ann]\n\
        1 4 0 -72 0 1 0 0 0 1 0 0 0 1 3001.dat\n\
        0 FILE 3001.dat\n0 Author: Part Maker\n0 !LDRAW_ORG Part\n\
        0 !LICENSE Parts licence\n";
    let l = learn_one(text);
    assert_eq!(
        l.report.credits[0].authors,
        vec!["Ann Builder [ann]".to_string(), "Bo Second".to_string()]
    );
    let rules = l.to_rules_text();
    assert!(
        rules.contains(
            "#   t.ldr: by Ann Builder [ann], Bo Second; \
             Redistributable under CC BY-SA version 4.0\n"
        ),
        "{rules}"
    );
    assert!(!rules.contains("Part Maker") && !rules.contains("Parts licence"));
}

#[test]
fn people_s_part_names_map_to_the_catalog() {
    let id = |s: &str| catalog_part(s).map(|k| k.spec().id.0);
    assert_eq!(id("3001.dat"), Some("3001"));
    assert_eq!(id("parts/3001.dat"), Some("3001"));
    assert_eq!(id("parts\\3003.DAT"), Some("3003"));
    // Another variant or a print of the same shape.
    assert_eq!(id("3023.dat"), Some("3023b"));
    assert_eq!(id("3040a.dat"), Some("3040b"));
    assert_eq!(id("3039p23.dat"), Some("3039"));
    // A subpart, a primitive and an unknown part are not catalog parts.
    assert_eq!(id("s/3001s01.dat"), None);
    assert_eq!(id("stud.dat"), None);
    assert_eq!(id("3069b.dat"), None);
}
