//! The built-in rule file, and rule sets generated from good building
//! practice.
//!
//! The built-in rules ([`default_rules_text`]) are learned from 30 models
//! people built. The generated sets (`brickwright rules`) weigh their rules
//! instead by what builder's guides teach (A. Bedford, *The Unofficial LEGO Builder's
//! Guide*, ch. 2 "staggering" and "overlapping"): a joint that bridges a seam
//! holds better than bricks stacked seam on seam, and a bigger brick holds
//! more studs. A rule `A -> A + B` weighs
//!
//! ```text
//! weight = studs(A) x studs(B) x joint(A, B) x side
//! joint  = 1  B sits exactly on A's footprint (seam on seam)
//!          2  B lies inside A's footprint
//!          3  B covers A's footprint and more (bridges A's seams)
//!          4  B overlaps part of A and reaches past it (staggered)
//!          6  staggered, and B rests half on A (running bond)
//! side   = 1 for up, 1/2 for down (people build upward)
//! ```
//!
//! The generated files also carry the shipped complex rules of
//! `rules/complex.rules` ([`COMPLEX_RULES`]) whose parts are in the alphabet.

use std::collections::HashSet;
use std::path::Path;

use super::{Dir, Rule, RuleSet, StartRule};
use crate::catalog::{Family, PartKind};
use crate::geom::Rot;

/// The alphabet of the default rule set: the paper's six bricks and the
/// 2x3, the six plates the issue names, and the slopes (used with
/// `--plates` and `--slopes`).
pub const DEFAULT_ALPHABET: [&str; 23] = [
    "3005", "3004", "3622", "3010", "3003", "3002", "3001", // bricks
    "3024", "3023b", "3623", "3710", "3022", "3020", // plates
    "3040b", "3039", "3038", "3037", "4286", "3298", "3665a", "3660a", // slopes
    "4445", "3297", // long slopes, for a roof's run
];

/// Every brick in the catalog, for `--rules rules/extended.rules`.
pub fn extended_alphabet() -> Vec<&'static str> {
    PartKind::all()
        .filter(|k| k.spec().family() == Family::Brick)
        .map(|k| k.spec().id.0)
        .collect()
}

fn joint_factor(a: (i32, i32), b_at: (i32, i32), b: (i32, i32)) -> f64 {
    let (ax1, ay1) = a;
    let (bx0, by0) = b_at;
    let (bx1, by1) = (bx0 + b.0, by0 + b.1);
    let ox = (ax1.min(bx1) - bx0.max(0)).max(0);
    let oy = (ay1.min(by1) - by0.max(0)).max(0);
    let overlap = ox * oy;
    let b_area = b.0 * b.1;
    let a_area = ax1 * ay1;
    if (bx0, by0, bx1, by1) == (0, 0, ax1, ay1) {
        1.0
    } else if overlap == b_area {
        2.0
    } else if overlap == a_area {
        3.0
    } else if 2 * overlap == b_area {
        6.0
    } else {
        4.0
    }
}

/// A rotated rule's geometry: anchor, its turn, new piece, its turn, offset, side.
type VariantKey = (PartKind, Rot, PartKind, Rot, (i32, i32, i32), Dir);

/// Generates the rule set for `alphabet`: every pair, every rotation of the
/// new piece, every overlapping offset, up and down; one rule per class of
/// rules that only differ by a turn of the whole.
pub fn generate(alphabet: &[&str]) -> RuleSet {
    let parts: Vec<PartKind> = alphabet
        .iter()
        .map(|id| PartKind::from_id(id).expect("default alphabet is in the catalog"))
        .collect();
    let starts = parts
        .iter()
        .map(|&part| StartRule { part, line: 0 })
        .collect();
    let mut rules = Vec::new();
    let mut seen: HashSet<VariantKey> = HashSet::new();
    for &a in &parts {
        for &b in &parts {
            for rule in Rule::every_between(a, b, 1.0) {
                let (ax, ay) = a.spec().footprint(Rot::R0);
                let (bx, by) = b.spec().footprint(rule.added_rot);
                let (dir, dx, dy) = (rule.dir, rule.dx, rule.dy);
                // Slopes connect on part of their top or bottom
                // only: skip offsets where no stud meets.
                let Ok(one) =
                    RuleSet::new(parts.clone(), vec![], vec![rule.clone()], String::new())
                else {
                    continue;
                };
                let keys: Vec<_> = one
                    .variants()
                    .iter()
                    .map(|v| {
                        (
                            v.anchor,
                            v.anchor_rot,
                            v.added,
                            v.added_rot,
                            v.offset,
                            v.dir,
                        )
                    })
                    .collect();
                if keys.iter().any(|k| seen.contains(k)) {
                    continue;
                }
                seen.extend(keys);
                let side = if dir == Dir::Up { 1.0 } else { 0.5 };
                let studs = b.spec().studs() as f64;
                let weight = studs * studs * joint_factor((ax, ay), (dx, dy), (bx, by)) * side;
                rules.push(Rule { weight, ..rule });
            }
        }
    }
    RuleSet::new(parts, starts, rules, "generated".into()).expect("generated rules are valid")
}

const HEADER: &str = "\
brickwright rule file: the Lego rewriting system (Σ, R).
Generated by `brickwright rules --alphabet {ALPHA}` (formula weights, not
learned ones; the built-in rules/default.rules is learned from builds);
edit freely, or write your own.

Statements (one a line, `#` starts a comment):
  part  ID                             a letter of Σ (an LDraw part id)
  start ID                             starting rule  ε -> ID
  rule  A B ROT up|down DX DY WEIGHT   basic rule     A -> A + B
    B is turned by ROT (r0 r90 r180 r270) relative to A, goes on top of A
    (up) or underneath (down), with its minimum corner DX, DY studs from
    A's (x along A's long side). Turns of the whole rule are generated
    when the file is loaded, so each rule is written once.
  complex NAME                         complex rule   u -> v (no weight), then
    u PART ROT X Y Z                   a piece that must be in place, and
    v PART ROT X Y Z                   a new piece, in the order they are added:
    minimum corner X, Y in studs and bottom Z in plates (8 LDU) relative
    to the first u piece (at 0 0 0). Each new piece stud-connects to a u
    piece or to a new piece before it. The search tests one, picked with
    equal probability, once every --complex-every nodes.

Where the weights come from: a formula, no data; they encode building
practice (Bedford, The Unofficial LEGO Builder's Guide, ch. 2):
  weight = studs(A) x studs(B) x joint x side   (big bricks: fewer, stronger joints)
  joint  = 1 seam on seam, 2 inside A, 3 covers A, 4 staggered,
           6 staggered with B half on A (running bond)
  side   = 1 up, 0.5 down";

/// The shipped complex rules, `rules/complex.rules`: a file of `complex`
/// blocks only (see [`RuleSet::with_complex_text`]). No builds teach them
/// (the paper collects no data for complex rules), so they are kept apart
/// from the learned `rules/default.rules` and added to it by
/// [`default_rules`] and to the files `brickwright rules` writes.
pub const COMPLEX_RULES: &str = include_str!("../../rules/complex.rules");

/// The built-in rules: the learned basic rules of `rules/default.rules`
/// and the shipped complex rules of `rules/complex.rules`.
pub fn default_rules() -> RuleSet {
    RuleSet::parse(
        &default_rules_text(),
        Path::new("rules/default.rules (built in)"),
    )
    .and_then(|r| r.with_complex_text(COMPLEX_RULES, Path::new("rules/complex.rules (built in)")))
    .expect("the built-in rules are valid")
}

/// The shipped complex rules whose parts are all in `set`'s alphabet and
/// whose heights its layers can express.
fn shipped_complex(set: &RuleSet) -> Vec<super::ComplexRule> {
    let every: Vec<PartKind> = PartKind::all().collect();
    let starts = every
        .iter()
        .map(|&part| StartRule { part, line: 0 })
        .collect();
    let all = RuleSet::new(every, starts, vec![], String::new())
        .and_then(|s| s.with_complex_text(COMPLEX_RULES, Path::new("rules/complex.rules")))
        .expect("the shipped complex rules are valid");
    all.restricted(|p| set.alphabet().contains(&p))
        .map(|r| r.complex().to_vec())
        .unwrap_or_default()
}

/// The text of the shipped default rule file `rules/default.rules`: rule
/// frequencies learned by `brickwright learn` from 30 LDraw models people
/// built (official set models and Datsville's buildings; its header credits
/// each model's authors and licence; `benches/learn.sh` learns it again).
pub fn default_rules_text() -> String {
    include_str!("../../rules/default.rules").to_string()
}

/// The text of a generated rule file for `alphabet`, called `name` in the
/// header (the `--alphabet` value that makes it).
pub fn rules_text(alphabet: &[&str], name: &str) -> String {
    let set = generate(alphabet);
    let complex = shipped_complex(&set);
    let set = set
        .with_complex(complex)
        .expect("the shipped complex rules fit the generated rules");
    set.to_text(&HEADER.replace("{ALPHA}", name))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn shipped_extended_file_is_the_generated_one() {
        let shipped = include_str!("../../rules/extended.rules");
        assert!(
            shipped == rules_text(&extended_alphabet(), "extended"),
            "regenerate with `brickwright rules --alphabet extended -o rules/extended.rules`"
        );
        let rs = RuleSet::parse(shipped, Path::new("rules/extended.rules")).unwrap();
        assert_eq!(rs.alphabet().len(), 11);
    }

    #[test]
    fn the_default_alphabet_has_formula_rules_for_every_family() {
        let rs = generate(&DEFAULT_ALPHABET);
        for f in [Family::Brick, Family::Plate, Family::Slope] {
            assert!(rs.rules().iter().any(|r| r.added.spec().family() == f));
        }
    }

    #[test]
    fn staggered_joints_weigh_more_than_stacked_ones() {
        assert_eq!(joint_factor((4, 2), (0, 0), (4, 2)), 1.0);
        assert_eq!(joint_factor((4, 2), (2, 0), (4, 2)), 6.0);
        assert_eq!(joint_factor((4, 2), (1, 0), (4, 2)), 4.0);
        assert_eq!(joint_factor((2, 2), (-1, 0), (4, 2)), 3.0);
        assert_eq!(joint_factor((4, 2), (1, 0), (2, 2)), 2.0);
    }
}
