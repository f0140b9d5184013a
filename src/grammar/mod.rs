//! The Lego rewriting system (Σ, R) of Lau's paper, section 3.
//!
//! Σ, the alphabet, is a set of piece types from the [catalog](crate::catalog).
//! R is a set of rewriting rules `u -> v`:
//!
//! - a **starting rule** `ε -> P` puts a first piece `P` down;
//! - a **basic-form rule** `A -> A + B` adds a piece `B` stud-connected to an
//!   existing piece `A`, either on top of it (`up`) or underneath (`down`),
//!   at an offset and a rotation relative to `A`;
//! - a **complex rule** `u -> v` adds several pieces, in order, where
//!   several pieces are in place (module [`complex`]; paper, Figure 4).
//!
//! Each rule carries a weight: how often people use it. The layout (the
//! default search) adds, among pieces of equal fit, the one whose joint the
//! heaviest rule makes; the backward search (`--search backward`) draws the
//! rules it tries at each node from the categorical distribution of the
//! weights, so common, sturdy joints are tried first.
//!
//! Rules are read from human-readable files ([`RuleSet::parse`]); the file
//! gives each rule once, with `A` unturned, and the loader generates the
//! rotations about the vertical axis once (paper, section 4), merging the
//! copies a symmetric part makes identical.
//!
//! ```
//! use brickwright::grammar::RuleSet;
//! let text = "part 3003\nstart 3003\nrule 3003 3003 r0 up 1 0 5\n";
//! let rules = RuleSet::parse(text, "inline.rules".as_ref()).unwrap();
//! assert_eq!(rules.alphabet().len(), 1);
//! // A 2x2 half-overlapping a 2x2 looks the same turned by a half turn
//! // only after a shift, so all four quarter turns are distinct rules.
//! assert_eq!(rules.variants().len(), 4);
//! ```

pub mod complex;
mod cover;
mod defaults;
pub mod learn;
mod numbering;
mod parse;

pub use complex::{ComplexId, ComplexRule, ComplexVariant, Link, NewPiece, Plates, RulePiece};
pub use defaults::{
    default_rules, default_rules_text, extended_alphabet, rules_text, COMPLEX_RULES,
    DEFAULT_ALPHABET,
};
pub use numbering::{Numbering, RuleNumbers};
pub use parse::RuleError;

use rayon::prelude::*;
use serde::Serialize;

use crate::catalog::{Family, PartKind};
use crate::geom::{Body, Cell, Rot};

/// Which side of its anchor a rule's new piece goes on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Dir {
    /// The new piece is pressed on top of the anchor.
    Up,
    /// The new piece is pressed onto the anchor from below.
    Down,
}

impl Dir {
    /// `up` or `down`, as in rule files.
    pub fn name(self) -> &'static str {
        match self {
            Dir::Up => "up",
            Dir::Down => "down",
        }
    }
}

/// Index of a rule as written in the file (0-based, in file order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct RuleId(pub u32);

/// A basic-form rule `A -> A + B` as written: `A` unturned at the origin.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Rule {
    /// The existing piece `A`.
    pub anchor: PartKind,
    /// The new piece `B`.
    pub added: PartKind,
    /// `B`'s rotation relative to `A`.
    pub added_rot: Rot,
    /// Whether `B` goes on top of `A` or underneath.
    pub dir: Dir,
    /// Offset of `B`'s minimum corner from `A`'s, in studs.
    pub dx: i32,
    /// Offset of `B`'s minimum corner from `A`'s, in studs.
    pub dy: i32,
    /// How often people use the rule (any positive number).
    pub weight: f64,
    /// The line of the rule file that defines it.
    pub line: usize,
}

impl Rule {
    /// Every rule putting `added` against `anchor`, weighing `weight`: each
    /// of `added`'s distinct turns, on top and underneath, at every offset
    /// where their footprints overlap, in that order (the order of the
    /// generated and the unseen rules). Whether the two then stud-connect
    /// is the rule set's to say.
    pub(crate) fn every_between(
        anchor: PartKind,
        added: PartKind,
        weight: f64,
    ) -> impl Iterator<Item = Rule> {
        let (ax, ay) = anchor.spec().footprint(Rot::R0);
        Rot::ALL
            .into_iter()
            .filter(move |&r| added.spec().canonical_rot(r) == r)
            .flat_map(move |rot| {
                let (bx, by) = added.spec().footprint(rot);
                [Dir::Up, Dir::Down].into_iter().flat_map(move |dir| {
                    (-(by - 1)..ay).flat_map(move |dy| {
                        (-(bx - 1)..ax).map(move |dx| Rule {
                            anchor,
                            added,
                            added_rot: rot,
                            dir,
                            dx,
                            dy,
                            weight,
                            line: 0,
                        })
                    })
                })
            })
    }
}

/// A starting rule `ε -> P`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StartRule {
    /// The piece put down.
    pub part: PartKind,
    /// The line of the rule file that defines it.
    pub line: usize,
}

/// A rule turned about the vertical axis and resolved to cell offsets: what
/// the search matches.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Variant {
    /// The rule it was generated from.
    pub rule: RuleId,
    /// The anchor's part.
    pub anchor: PartKind,
    /// The anchor's rotation (canonical for its symmetry).
    pub anchor_rot: Rot,
    /// The new piece's part.
    pub added: PartKind,
    /// The new piece's rotation (canonical for its symmetry).
    pub added_rot: Rot,
    /// Offset of the new piece's minimum corner from the anchor's, in cells.
    pub offset: (i32, i32, i32),
    /// Up or down.
    pub dir: Dir,
    /// The rule's weight shared among its distinct rotations.
    pub weight: f64,
}

/// A variant's geometry, all that two variants must share to be the same
/// move: anchor and its turn, new piece and its turn, offset, side.
pub type VariantKey = (PartKind, Rot, PartKind, Rot, (i32, i32, i32), Dir);

impl Variant {
    /// Its geometry ([`VariantKey`]): what the search matches.
    pub fn key(&self) -> VariantKey {
        (
            self.anchor,
            self.anchor_rot,
            self.added,
            self.added_rot,
            self.offset,
            self.dir,
        )
    }
}

/// Which rule added a piece.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum RuleRef {
    /// A basic-form rule.
    Basic(RuleId),
    /// A complex rule.
    Complex(ComplexId),
}

/// The rewriting system: the alphabet, the starting rules, the basic rules,
/// the complex rules and their rotated variants.
#[derive(Debug, Clone, PartialEq)]
pub struct RuleSet {
    alphabet: Vec<PartKind>,
    starts: Vec<StartRule>,
    /// The basic rules: first the `explicit` ones the file gives, then the
    /// unseen ones [`RuleSet::with_unseen`] adds.
    rules: Vec<Rule>,
    explicit: usize,
    unseen: Option<f64>,
    variants: Vec<Variant>,
    complex: Vec<ComplexRule>,
    complex_variants: Vec<ComplexVariant>,
    /// Where the rules came from, for reports.
    pub source: String,
    /// The numbering of the file this set was cut down from
    /// ([`RuleSet::restricted`]); `None`: the set numbers itself.
    numbered: Option<Box<Numbering>>,
}

/// The height, in LDU, of one voxel layer for an alphabet: a brick (24)
/// for bricks alone, half a brick (12) once slopes are in, a plate (8) once
/// plates are in.
pub fn layer_ldu_for(alphabet: &[PartKind]) -> i32 {
    let has = |f: Family| alphabet.iter().any(|p| p.spec().family() == f);
    if has(Family::Plate) {
        8
    } else if has(Family::Slope) {
        12
    } else {
        24
    }
}

impl RuleSet {
    /// Builds a rule set from its parts, generating rotated variants.
    ///
    /// Errors if a rule names a part outside the alphabet or does not
    /// connect its two pieces; `source` names the file in messages.
    pub fn new(
        alphabet: Vec<PartKind>,
        starts: Vec<StartRule>,
        rules: Vec<Rule>,
        source: String,
    ) -> Result<RuleSet, RuleError> {
        let explicit = rules.len();
        let mut set = RuleSet {
            alphabet,
            starts,
            rules,
            explicit,
            unseen: None,
            variants: Vec::new(),
            complex: Vec::new(),
            complex_variants: Vec::new(),
            source,
            numbered: None,
        };
        set.variants = set.generate_variants()?;
        Ok(set)
    }

    /// The same system with the complex rules `complex` (in place of any it
    /// had), their turns generated.
    ///
    /// Errors, naming the rule file's line, if a piece is not in the
    /// alphabet, a height is not a whole number of layers, two pieces
    /// overlap, or a new piece is not stud-connected to a piece of `u` or a
    /// new piece before it.
    pub fn with_complex(mut self, complex: Vec<ComplexRule>) -> Result<RuleSet, RuleError> {
        self.complex = complex;
        self.complex_variants = self.generate_complex()?;
        Ok(self)
    }

    /// The same system with Σ cut down to the parts `keep` accepts: their
    /// starting rules and the rules between them. Errors if no part or no
    /// starting rule is left.
    pub fn restricted(&self, keep: impl Fn(PartKind) -> bool) -> Result<RuleSet, RuleError> {
        let alphabet: Vec<PartKind> = self.alphabet.iter().copied().filter(|&p| keep(p)).collect();
        let starts: Vec<StartRule> = self
            .starts
            .iter()
            .filter(|s| keep(s.part))
            .cloned()
            .collect();
        if starts.is_empty() {
            return Err(RuleError::File {
                file: self.source.clone(),
                message:
                    "no starting rule is left for the parts asked for (see --slopes and --plates)"
                        .into(),
            });
        }
        let rules = self
            .explicit_rules()
            .iter()
            .filter(|r| keep(r.anchor) && keep(r.added))
            .cloned()
            .collect();
        // The loaded set's numbers are worked out beside the cut one.
        let (numbering, set) = rayon::join(
            || self.numbering(),
            || {
                RuleSet::new(alphabet, starts, rules, self.source.clone())
                    .map(|set| set.with_unseen(self.unseen))
            },
        );
        let set = set?;
        // A complex rule whose heights the new layers cannot express (a
        // plate's offset among bricks) goes with the parts it needs.
        let complex = self
            .complex
            .iter()
            .filter(|r| r.u.iter().chain(&r.v).all(|p| keep(p.part)) && set.fits_layers(r))
            .cloned()
            .collect();
        let mut set = set.with_complex(complex)?;
        set.numbered = Some(Box::new(numbering));
        Ok(set)
    }

    /// The letters of Σ.
    pub fn alphabet(&self) -> &[PartKind] {
        &self.alphabet
    }

    /// The starting rules.
    pub fn starts(&self) -> &[StartRule] {
        &self.starts
    }

    /// The basic-form rules, as written.
    pub fn rules(&self) -> &[Rule] {
        &self.rules
    }

    /// The height in LDU of one layer of the voxel grids this rule set
    /// builds (see [`layer_ldu_for`]).
    pub fn layer_ldu(&self) -> i32 {
        layer_ldu_for(&self.alphabet)
    }

    /// The cells `part` fills turned by `rot` with its minimum corner at
    /// `at`, in this rule set's layers.
    pub fn body(&self, part: PartKind, rot: Rot, at: Cell) -> Body {
        part.body(rot, at, self.layer_ldu())
    }

    /// Every rotation of every basic rule.
    pub fn variants(&self) -> &[Variant] {
        &self.variants
    }

    /// The complex rules, as written.
    pub fn complex(&self) -> &[ComplexRule] {
        &self.complex
    }

    /// Every distinct rotation of every complex rule, rule by rule.
    pub fn complex_variants(&self) -> &[ComplexVariant] {
        &self.complex_variants
    }

    /// Whether `part` has a starting rule.
    pub fn can_start(&self, part: PartKind) -> bool {
        self.starts.iter().any(|s| s.part == part)
    }

    fn generate_variants(&self) -> Result<Vec<Variant>, RuleError> {
        let mut out: Vec<Variant> = Vec::new();
        for (i, r) in self.rules.iter().enumerate() {
            for part in [r.anchor, r.added] {
                if !self.alphabet.contains(&part) {
                    return Err(RuleError::at(
                        &self.source,
                        r.line,
                        format!("part {part} is not in the alphabet; add a `part {part}` line"),
                    ));
                }
            }
            let mine = self.rule_variants(RuleId(i as u32), r).ok_or_else(|| {
                RuleError::at(
                    &self.source,
                    r.line,
                    format!(
                        "the new {} at offset ({}, {}) {} is not stud-connected to the {}",
                        r.added,
                        r.dx,
                        r.dy,
                        if r.dir == Dir::Up {
                            "on top"
                        } else {
                            "underneath"
                        },
                        r.anchor
                    ),
                )
            })?;
            out.extend(mine);
        }
        Ok(out)
    }

    /// The distinct turns of rule `r` (numbered `id`), its weight shared
    /// among them; `None` if its pieces do not stud-connect.
    fn rule_variants(&self, id: RuleId, r: &Rule) -> Option<Vec<Variant>> {
        let anchor = self.body(r.anchor, Rot::R0, Cell::new(0, 0, 0));
        let mut mine = Vec::new();
        self.rule_variants_into(id, r, &anchor, &mut mine)
            .then_some(mine)
    }

    /// [`rule_variants`](Self::rule_variants) added to `out`, given the
    /// anchor's body at the origin unturned; false (nothing added) if the
    /// pieces do not stud-connect.
    fn rule_variants_into(&self, id: RuleId, r: &Rule, a: &Body, out: &mut Vec<Variant>) -> bool {
        let dz = match r.dir {
            Dir::Up => a.bbox.sz,
            Dir::Down => -(r.added.spec().height_ldu() / self.layer_ldu()).max(1),
        };
        let b0 = self.body(r.added, r.added_rot, Cell::new(r.dx, r.dy, dz));
        let connects = match r.dir {
            Dir::Up => a.holds(&b0),
            Dir::Down => b0.holds(a),
        };
        if !connects {
            return false;
        }
        let first = out.len();
        for turn in Rot::ALL {
            let ra = a.bbox.turned(turn);
            let rb = b0.bbox.turned(turn);
            let v = Variant {
                rule: id,
                anchor: r.anchor,
                anchor_rot: r.anchor.spec().canonical_rot(turn),
                added: r.added,
                added_rot: r.added.spec().canonical_rot(r.added_rot.then(turn)),
                offset: (rb.min.x - ra.min.x, rb.min.y - ra.min.y, dz),
                dir: r.dir,
                weight: 0.0,
            };
            if !out[first..].iter().any(|m| same_geometry(m, &v)) {
                out.push(v);
            }
        }
        let mine = &mut out[first..];
        let n = mine.len() as f64;
        for v in mine {
            v.weight = r.weight / n;
        }
        true
    }

    /// The same system with every basic rule the file does not give (every
    /// pair of its parts, every turn, every offset and side where a stud
    /// connects them) added with weight `weight`: a rule no builder was seen
    /// using is still allowed, only rarely tried. `None` adds nothing.
    pub fn with_unseen(mut self, weight: Option<f64>) -> RuleSet {
        self.rules.truncate(self.explicit);
        self.variants
            .retain(|v| (v.rule.0 as usize) < self.explicit);
        self.unseen = weight;
        let Some(w) = weight else {
            return self;
        };
        let key = Variant::key;
        type Key = VariantKey;
        let mut seen: crate::keyhash::KeySet<Key> = self.variants.iter().map(key).collect();
        // Every rule between two parts that connects, with its turns, in
        // the order the loops make them: made for each anchor in parallel
        // (turning the rules is most of the work), then kept in that order
        // unless a turn of it is already a rule's.
        let parts = &self.alphabet;
        type Found = (Vec<(Rule, usize)>, Vec<Variant>);
        let found: Vec<Found> = parts
            .par_iter()
            .map(|&a| {
                let anchor = self.body(a, Rot::R0, Cell::new(0, 0, 0));
                let (mut rules, mut turns) = (Vec::new(), Vec::new());
                for rule in parts.iter().flat_map(|&b| Rule::every_between(a, b, w)) {
                    let before = turns.len();
                    if self.rule_variants_into(RuleId(0), &rule, &anchor, &mut turns) {
                        rules.push((rule, turns.len() - before));
                    }
                }
                (rules, turns)
            })
            .collect();
        for (rules, turns) in found {
            let mut at = 0;
            for (rule, n) in rules {
                let vs = &turns[at..at + n];
                at += n;
                if vs.iter().any(|v| seen.contains(&key(v))) {
                    continue;
                }
                let id = RuleId(self.rules.len() as u32);
                seen.extend(vs.iter().map(key));
                self.variants
                    .extend(vs.iter().map(|v| Variant { rule: id, ..*v }));
                self.rules.push(rule);
            }
        }
        self
    }

    /// The weight given to rules the file does not list, if any (the
    /// `unseen` statement).
    pub fn unseen(&self) -> Option<f64> {
        self.unseen
    }

    /// The rules the file gives (the rest of [`RuleSet::rules`] are unseen
    /// rules added by [`RuleSet::with_unseen`]).
    pub fn explicit_rules(&self) -> &[Rule] {
        &self.rules[..self.explicit]
    }

    /// Writes the rule set back as a rule file that [`RuleSet::parse`]
    /// reads to an equal rule set.
    pub fn to_text(&self, header: &str) -> String {
        let mut s = String::new();
        for line in header.lines() {
            s.push_str("# ");
            s.push_str(line);
            s.push('\n');
        }
        s.push('\n');
        for p in &self.alphabet {
            s.push_str(&format!("part {:<6} # {}\n", p.to_string(), p.spec().name));
        }
        s.push('\n');
        for st in &self.starts {
            s.push_str(&format!("start {}\n", st.part));
        }
        if let Some(w) = self.unseen {
            s.push_str(&format!(
                "\n# every other connecting rule, as if seen with weight {}\nunseen {}\n",
                fmt_weight(w),
                fmt_weight(w)
            ));
        }
        s.push_str("\n#    anchor new    rot  dir   dx  dy  weight\n");
        for r in self.explicit_rules() {
            s.push_str(&format!(
                "rule {:<6} {:<6} {:<4} {:<5} {:>3} {:>3}  {}\n",
                r.anchor.to_string(),
                r.added.to_string(),
                r.added_rot.name(),
                r.dir.name(),
                r.dx,
                r.dy,
                fmt_weight(r.weight)
            ));
        }
        self.complex_text(&mut s);
        s
    }
}

/// A weight as rule files write it: no trailing zeros.
fn fmt_weight(w: f64) -> String {
    let s = format!("{w:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

fn same_geometry(a: &Variant, b: &Variant) -> bool {
    a.anchor == b.anchor
        && a.anchor_rot == b.anchor_rot
        && a.added == b.added
        && a.added_rot == b.added_rot
        && a.offset == b.offset
        && a.dir == b.dir
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kind(id: &str) -> PartKind {
        PartKind::from_id(id).unwrap()
    }

    #[test]
    fn rotations_are_generated_and_symmetric_copies_merged() {
        // A 2x2 centred on a 2x2: every turn gives the same rule.
        let text = "part 3003\nstart 3003\nrule 3003 3003 r0 up 0 0 4\n";
        let rs = RuleSet::parse(text, "t.rules".as_ref()).unwrap();
        assert_eq!(rs.variants().len(), 1);
        assert_eq!(rs.variants()[0].weight, 4.0);
        // A 1x2 across the end of a 2x4: four distinct turns.
        let text = "part 3001\npart 3004\nstart 3001\nrule 3001 3004 r90 up 3 0 8\n";
        let rs = RuleSet::parse(text, "t.rules".as_ref()).unwrap();
        let v = rs.variants();
        assert_eq!(v.len(), 4);
        assert!(v.iter().all(|v| (v.weight - 2.0).abs() < 1e-12));
        // Turned a quarter, the 2x4 stands along y and the 1x2 along x.
        let q = v
            .iter()
            .find(|v| v.anchor_rot == Rot::R90 && v.offset.1 == 3)
            .unwrap();
        assert_eq!(q.added_rot, Rot::R0);
        assert_eq!(q.offset, (0, 3, 1));
        assert_eq!(q.anchor, kind("3001"));
    }

    #[test]
    fn unseen_rules_fill_in_every_other_connecting_joint() {
        let seen = "part 3004\npart 3040b\nstart 3004\nrule 3004 3004 r0 up 1 0 7\n";
        let bare = RuleSet::parse(seen, "t.rules".as_ref()).unwrap();
        assert_eq!(bare.rules().len(), 1);
        let text = format!("{seen}unseen 0.5\n");
        let rs = RuleSet::parse(&text, "t.rules".as_ref()).unwrap();
        assert_eq!(rs.explicit_rules().len(), 1);
        assert!(rs.rules().len() > 20, "{}", rs.rules().len());
        // The seen joint keeps its weight and is not repeated.
        assert_eq!(rs.rules().iter().filter(|r| r.weight == 7.0).count(), 1);
        assert!(rs.rules()[1..].iter().all(|r| r.weight == 0.5));
        // Every added rule connects (slopes only through their back row).
        for v in rs.variants() {
            let a = rs.body(v.anchor, v.anchor_rot, Cell::new(0, 0, 0));
            let (dx, dy, dz) = v.offset;
            let b = rs.body(v.added, v.added_rot, Cell::new(dx, dy, dz));
            assert!(if v.dir == Dir::Up {
                a.holds(&b)
            } else {
                b.holds(&a)
            });
        }
        // The file round-trips with the statement, not the added rules.
        let back = rs.to_text("t");
        assert!(back.contains("\nunseen 0.5\n") && back.matches("\nrule ").count() == 1);
        let again = RuleSet::parse(&back, "t.rules".as_ref()).unwrap();
        assert!(
            again.variants() == rs.variants(),
            "the round trip changed the rules"
        );
        // Restricting the alphabet regenerates them for the parts kept.
        let bricks = rs
            .restricted(|p| p.spec().family() == Family::Brick)
            .unwrap();
        assert!(bricks.rules().iter().all(|r| r.added.to_string() == "3004"));
        let bad = RuleSet::parse(&format!("{seen}unseen -1\n"), "t.rules".as_ref());
        assert!(bad
            .unwrap_err()
            .to_string()
            .starts_with("t.rules:5: `unseen`"));
    }

    #[test]
    fn every_variant_connects_its_pieces() {
        let rs = RuleSet::parse(&default_rules_text(), "default.rules".as_ref()).unwrap();
        for v in rs.variants() {
            let a = rs.body(v.anchor, v.anchor_rot, Cell::new(0, 0, 0));
            let (dx, dy, dz) = v.offset;
            let b = rs.body(v.added, v.added_rot, Cell::new(dx, dy, dz));
            match v.dir {
                Dir::Up => assert!(a.holds(&b), "{v:?}"),
                Dir::Down => assert!(b.holds(&a), "{v:?}"),
            }
        }
    }
}
