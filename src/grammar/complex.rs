//! Complex rules: several pieces in `u`, several new pieces in `v`.
//!
//! The paper's basic rules add one piece to one piece; its Figure 4 shows
//! rules with more: a brick bridging two columns, two bricks laid in running
//! bond on one, a corner locked by the next course. Such a rule `u -> v` is
//! applied where every piece of `u` is already in place, and adds the new
//! pieces of `v` in the order the rule gives, each stud-connected to a piece
//! of `u` or to a new piece added before it.
//!
//! There is no usage data for complex rules, so they carry no weight: the
//! search picks one of them with equal probability to test once every few
//! nodes (paper, section 4; [`crate::search::SearchOptions::complex_every`]).
//!
//! As written, a piece's place is its minimum corner relative to the first
//! `u` piece's, in studs across and plates (8 LDU) up, so one rule reads the
//! same whatever the layer height of the rule set that loads it; the loader
//! resolves it to cells of [`RuleSet::layer_ldu`] and generates the four
//! turns about the vertical axis, merging turns a symmetric rule makes
//! identical.

use serde::Serialize;

use super::{RuleError, RuleSet};
use crate::catalog::PartKind;
use crate::geom::{Body, Cell, Rot};

/// LDU in a plate: the unit of a complex rule's heights.
pub const LDU_PER_PLATE: i32 = 8;

/// Index of a complex rule as written in the file (0-based, in file order
/// among the complex rules).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct ComplexId(pub u32);

/// A height in plates (8 LDU).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct Plates(pub i32);

/// One piece of a complex rule, as written.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RulePiece {
    /// The part.
    pub part: PartKind,
    /// Its turn.
    pub rot: Rot,
    /// Its minimum corner relative to the first `u` piece's, in studs.
    pub x: i32,
    /// Its minimum corner relative to the first `u` piece's, in studs.
    pub y: i32,
    /// Its bottom relative to the first `u` piece's.
    pub z: Plates,
    /// The line of the rule file that gives it.
    pub line: usize,
}

impl RulePiece {
    fn same_place(&self, o: &RulePiece) -> bool {
        (self.part, self.rot, self.x, self.y, self.z) == (o.part, o.rot, o.x, o.y, o.z)
    }
}

/// A complex rule `u -> v` as written: `u` the pieces that must be in
/// place, `v` the new pieces in the order they are added.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComplexRule {
    /// A name for reports and error messages.
    pub name: String,
    /// The pieces already placed; the first is the origin.
    pub u: Vec<RulePiece>,
    /// The new pieces, in the order they are added.
    pub v: Vec<RulePiece>,
    /// The line of the rule file that starts it.
    pub line: usize,
}

impl ComplexRule {
    /// Whether the two rules have the same pieces (lines aside).
    pub fn same_pieces(&self, o: &ComplexRule) -> bool {
        let same = |a: &[RulePiece], b: &[RulePiece]| {
            a.len() == b.len() && a.iter().zip(b).all(|(p, q)| p.same_place(q))
        };
        same(&self.u, &o.u) && same(&self.v, &o.v)
    }
}

/// A piece of a complex variant, placed in cells relative to the variant's
/// first `u` piece.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct VariantPiece {
    /// The part.
    pub part: PartKind,
    /// Its turn, canonical for the part's symmetry.
    pub rot: Rot,
    /// Its minimum corner relative to the first `u` piece's, in cells.
    pub at: Cell,
}

impl VariantPiece {
    /// The piece's body with the variant's first `u` piece at `origin`.
    pub fn body(&self, origin: Cell, layer_ldu: i32) -> Body {
        let at = origin.offset(self.at.x, self.at.y, self.at.z);
        self.part.body(self.rot, at, layer_ldu)
    }
}

/// The piece a new piece of a complex rule stud-connects to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Link {
    /// The `u` piece of this index.
    U(usize),
    /// The new piece of this index, added earlier.
    V(usize),
}

/// A new piece of a complex variant and what it stud-connects to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct NewPiece {
    /// Where it goes.
    pub piece: VariantPiece,
    /// The first piece it stud-connects to: a `u` piece if any, else the
    /// earliest new piece.
    pub anchor: Link,
}

/// A complex rule turned about the vertical axis and resolved to cells:
/// what the search matches.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComplexVariant {
    /// The rule it was generated from.
    pub rule: ComplexId,
    /// The pieces that must be in place; `u[0]` at the origin.
    pub u: Vec<VariantPiece>,
    /// The new pieces, in the order they are added.
    pub v: Vec<NewPiece>,
}

impl ComplexVariant {
    /// The pieces relative to the first new piece, `u` sorted: equal for
    /// two turns exactly when they are the same rule in the grid (a turn
    /// that only changes the order of the new pieces is another rule).
    fn shape(&self) -> (Vec<VariantPiece>, Vec<VariantPiece>) {
        let o = self.v[0].piece.at;
        let rel = |p: &VariantPiece| VariantPiece {
            at: p.at.offset(-o.x, -o.y, -o.z),
            ..*p
        };
        let mut u: Vec<VariantPiece> = self.u.iter().map(rel).collect();
        u.sort();
        (u, self.v.iter().map(|n| rel(&n.piece)).collect())
    }
}

impl RuleSet {
    /// Checks the complex rules against the alphabet and layer height and
    /// generates their turns.
    pub(super) fn generate_complex(&self) -> Result<Vec<ComplexVariant>, RuleError> {
        let mut out = Vec::new();
        for (i, r) in self.complex.iter().enumerate() {
            let bodies = self.complex_bodies(r)?;
            let (ub, vb) = bodies.split_at(r.u.len());
            let mut anchors = Vec::with_capacity(r.v.len());
            for (j, (b, p)) in vb.iter().zip(&r.v).enumerate() {
                let joins = |a: &Body| a.holds(b) || b.holds(a);
                let anchor = match ub.iter().position(joins) {
                    Some(k) => Link::U(k),
                    None => match vb[..j].iter().position(joins) {
                        Some(k) => Link::V(k),
                        None => {
                            return Err(RuleError::at(
                                &self.source,
                                p.line,
                                format!(
                                    "the new {} of rule `{}` is not stud-connected to a `u` piece \
                                     or to a new piece before it; move it so its studs or tubes meet one",
                                    p.part, r.name
                                ),
                            ))
                        }
                    },
                };
                anchors.push(anchor);
            }
            let mut mine: Vec<ComplexVariant> = Vec::new();
            for turn in Rot::ALL {
                let turned: Vec<(VariantPiece, Body)> = bodies
                    .iter()
                    .zip(r.u.iter().chain(&r.v))
                    .map(|(b, p)| {
                        let t = b.turned(turn);
                        let piece = VariantPiece {
                            part: p.part,
                            rot: p.part.spec().canonical_rot(p.rot.then(turn)),
                            at: t.bbox.min,
                        };
                        (piece, t)
                    })
                    .collect();
                let o = turned[0].0.at;
                let rel = |(p, _): &(VariantPiece, Body)| VariantPiece {
                    at: p.at.offset(-o.x, -o.y, -o.z),
                    ..*p
                };
                let var = ComplexVariant {
                    rule: ComplexId(i as u32),
                    u: turned[..r.u.len()].iter().map(rel).collect(),
                    v: turned[r.u.len()..]
                        .iter()
                        .zip(&anchors)
                        .map(|(t, &anchor)| NewPiece {
                            piece: rel(t),
                            anchor,
                        })
                        .collect(),
                };
                if !mine.iter().any(|m| m.shape() == var.shape()) {
                    mine.push(var);
                }
            }
            out.extend(mine);
        }
        Ok(out)
    }

    /// The bodies of a rule's pieces, `u` then `v`, in this rule set's
    /// layers; errors if a part is not in the alphabet, a height is not a
    /// whole number of layers, or two pieces overlap.
    fn complex_bodies(&self, r: &ComplexRule) -> Result<Vec<Body>, RuleError> {
        let layer = self.layer_ldu();
        let mut bodies: Vec<Body> = Vec::with_capacity(r.u.len() + r.v.len());
        for p in r.u.iter().chain(&r.v) {
            let err = |m: String| RuleError::at(&self.source, p.line, m);
            if !self.alphabet.contains(&p.part) {
                return Err(err(format!(
                    "part {} is not in the alphabet; add a `part {}` line",
                    p.part, p.part
                )));
            }
            let ldu = p.z.0 * LDU_PER_PLATE;
            if ldu % layer != 0 {
                let n = layer / LDU_PER_PLATE;
                return Err(err(format!(
                    "z {} plates is not a whole number of layers: this rule set's layers are \
                     {n} plates ({layer} LDU) high, so use a multiple of {n}",
                    p.z.0
                )));
            }
            let b = self.body(p.part, p.rot, Cell::new(p.x, p.y, ldu / layer));
            let all = r.u.iter().chain(&r.v);
            if let Some((q, _)) = all
                .zip(&bodies)
                .find(|(_, other)| other.bbox.intersects(&b.bbox))
            {
                return Err(err(format!(
                    "the {} overlaps the {} of line {} in rule `{}`",
                    p.part, q.part, q.line, r.name
                )));
            }
            bodies.push(b);
        }
        Ok(bodies)
    }

    /// Whether every height of `r` is a whole number of this rule set's
    /// layers.
    pub(super) fn fits_layers(&self, r: &ComplexRule) -> bool {
        let layer = self.layer_ldu();
        r.u.iter()
            .chain(&r.v)
            .all(|p| (p.z.0 * LDU_PER_PLATE) % layer == 0)
    }

    /// Writes the complex rules in the form [`RuleSet::parse`] reads.
    pub(super) fn complex_text(&self, s: &mut String) {
        if self.complex.is_empty() {
            return;
        }
        s.push_str("\n# complex NAME, then its pieces:  u|v PART ROT X Y Z(plates)\n");
        for r in &self.complex {
            s.push_str(&format!("complex {}\n", r.name));
            for (tag, ps) in [("u", &r.u), ("v", &r.v)] {
                for p in ps {
                    s.push_str(&format!(
                        "  {tag} {:<6} {:<4} {:>3} {:>3} {:>3}\n",
                        p.part.to_string(),
                        p.rot.name(),
                        p.x,
                        p.y,
                        p.z.0
                    ));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grammar::{default_rules, default_rules_text, COMPLEX_RULES};
    use std::path::Path;

    const BRICKS: &str = "part 3004\npart 3010\npart 3001\nstart 3001\n";

    fn parse(text: &str) -> Result<RuleSet, RuleError> {
        RuleSet::parse(text, Path::new("c.rules"))
    }

    fn err(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    #[test]
    fn errors_name_file_and_line() {
        let e = |body: &str| err(&format!("{BRICKS}{body}"));
        // Lines 1-4 are the alphabet; the block starts on line 5.
        assert!(e("complex a\n u 3004 r0 0 0 0\n v 9999 r0 0 0 3\n")
            .starts_with("c.rules:7: unknown part `9999`"));
        assert!(e("complex a\n u 3004 r0 0 0 0\n v 3003 r0 0 0 3\n")
            .starts_with("c.rules:7: part 3003 is not in the alphabet"));
        assert_eq!(
            e("complex a\n u 3004 r0 0 0 0\n v 3004 r0 0 0 2\n"),
            "c.rules:7: z 2 plates is not a whole number of layers: this rule set's layers \
             are 3 plates (24 LDU) high, so use a multiple of 3"
        );
        assert_eq!(
            e("complex a\n u 3004 r0 0 0 0\n v 3004 r0 5 0 3\n"),
            "c.rules:7: the new 3004 of rule `a` is not stud-connected to a `u` piece or to \
             a new piece before it; move it so its studs or tubes meet one"
        );
        // A new piece may hang from an earlier new piece.
        assert!(parse(&format!(
            "{BRICKS}complex a\n u 3004 r0 0 0 0\n v 3010 r0 0 0 3\n v 3004 r0 3 0 6\n"
        ))
        .is_ok());
        assert!(
            e("complex a\n u 3004 r0 0 0 0\n v 3010 r0 0 0 3\n v 3004 r0 1 0 3\n")
                .starts_with("c.rules:8: the 3004 overlaps the 3010 of line 7 in rule `a`")
        );
        assert!(
            e("complex a\n u 3004 r0 0 0 0\n u 3004 r0 1 0 0\n v 3001 r0 0 0 3\n")
                .starts_with("c.rules:7: the 3004 overlaps the 3004 of line 6")
        );
        assert!(e("complex a\n v 3004 r0 0 0 3\n")
            .starts_with("c.rules:5: complex rule `a` has no `u` pieces"));
        assert!(e("complex a\n u 3004 r0 0 0 0\nstart 3004\n")
            .starts_with("c.rules:5: complex rule `a` has no `v` pieces"));
        assert!(e("complex a\n u 3004 r0 0 0 0\n")
            .starts_with("c.rules:5: complex rule `a` has no `v`"));
        assert!(e(" v 3004 r0 0 0 3\n").starts_with("c.rules:5: `v` outside a complex rule"));
        assert!(e("complex a\n u 3004 r0 1 0 0\n").starts_with("c.rules:6: the first `u` piece"));
        assert!(
            e("complex a\n u 3004 r0 0 0 0\n v 3004 r0 0 0 3\n u 3004 r0 2 0 0\n")
                .starts_with("c.rules:8: `u` after a `v`")
        );
        assert!(e("complex a\n u 3004 r45 0 0 0\n").starts_with("c.rules:6: bad rotation `r45`"));
        assert!(e("complex a\n u 3004 r0 0 0\n").starts_with("c.rules:6: `u` takes 5 fields"));
        assert!(e("complex a\n u 3004 r0 0 0 x\n").starts_with("c.rules:6: bad z (plates) `x`"));
        assert!(e("complex\n").starts_with("c.rules:5: `complex` takes one name"));
        let one = "complex a\n u 3004 r0 0 0 0\n v 3004 r0 1 0 3\n";
        assert!(e(&format!("{one}{one}"))
            .starts_with("c.rules:8: complex rule `a` is already defined on line 5"));
        assert!(e(&format!(
            "{one}complex b\n u 3004 r0 0 0 0\n v 3004 r0 1 0 3\n"
        ))
        .starts_with("c.rules:8: complex rule `b` has the same pieces as `a` on line 5"));
    }

    #[test]
    fn a_complex_file_holds_complex_blocks_only() {
        let base = parse(BRICKS).unwrap();
        let bad = base
            .clone()
            .with_complex_text("# c\npart 3004\n", Path::new("x.rules"))
            .unwrap_err();
        assert!(bad
            .to_string()
            .starts_with("x.rules:2: `part 3004` in a file of complex rules"));
        // Errors in the added file name that file and its lines.
        let bad = base
            .clone()
            .with_complex_text(
                "complex a\n u 3004 r0 0 0 0\n v 3004 r0 9 0 3\n",
                Path::new("x.rules"),
            )
            .unwrap_err();
        assert!(
            bad.to_string().starts_with("x.rules:3: the new 3004"),
            "{bad}"
        );
        let ok = base
            .with_complex_text(
                "complex a\n u 3004 r0 0 0 0\n v 3004 r0 1 0 3\n",
                Path::new("x.rules"),
            )
            .unwrap();
        assert_eq!(ok.complex().len(), 1);
        assert_eq!(ok.source, "c.rules");
    }

    #[test]
    fn the_shipped_file_appends_to_a_rule_file() {
        let text = format!("{}\n{}", default_rules_text(), COMPLEX_RULES);
        let rs = RuleSet::parse(&text, Path::new("with-complex.rules")).unwrap();
        assert_eq!(rs.complex_variants(), default_rules().complex_variants());
        assert_eq!(rs.variants(), default_rules().variants());
    }

    #[test]
    fn complex_rules_round_trip() {
        let rs = default_rules();
        assert!(
            rs.complex().len() == 3,
            "the default rules carry the shipped complex rules"
        );
        let text = rs.to_text("round trip");
        let back = RuleSet::parse(&text, Path::new("d.rules")).unwrap();
        let lineless = |r: &RuleSet| -> Vec<(String, usize, usize)> {
            r.complex()
                .iter()
                .map(|c| (c.name.clone(), c.u.len(), c.v.len()))
                .collect()
        };
        assert_eq!(lineless(&back), lineless(&rs));
        assert!(back
            .complex()
            .iter()
            .zip(rs.complex())
            .all(|(a, b)| a.same_pieces(b)));
        assert_eq!(back.complex_variants(), rs.complex_variants());
        assert_eq!(back.to_text("round trip"), text);
    }

    /// Rules tried on the fixtures: the shipped ones and some that cost.
    const TRIED: &str = "\
complex bridge\n u 3004 r90 0 0 0\n u 3004 r90 2 0 0\n v 3001 r0 0 0 3\n\
complex lintel\n u 3004 r0 0 0 0\n u 3004 r0 4 0 0\n v 3010 r0 1 0 3\n\
complex corner-lock\n u 3010 r0 0 0 0\n u 3010 r90 0 1 0\n v 3010 r90 0 0 3\n v 3010 r0 1 0 3\n";

    #[test]
    fn turns_are_generated_and_symmetric_copies_merged() {
        let rs = parse(BRICKS)
            .unwrap()
            .with_complex_text(COMPLEX_RULES, Path::new("complex.rules"))
            .unwrap()
            .with_complex_text(TRIED, Path::new("tried.rules"))
            .unwrap();
        let turns = |name: &str| {
            let id = rs.complex().iter().position(|r| r.name == name).unwrap();
            rs.complex_variants()
                .iter()
                .filter(|v| v.rule == ComplexId(id as u32))
                .collect::<Vec<_>>()
        };
        // A lintel or a tie looks the same after a half turn; this bridge
        // does not (its 2x4 reaches past one post), nor does a corner.
        assert_eq!(turns("bridge").len(), 4);
        assert_eq!(turns("lintel").len(), 2);
        assert_eq!(turns("tie-2x4").len(), 2);
        // Running bond does too, but for the order of its new pieces, which
        // is part of the rule.
        assert_eq!(turns("bond-2x4").len(), 4);
        assert_eq!(turns("corner-lock").len(), 4);
        // Turned a quarter, the bond runs along y: its new pieces sit two
        // studs either way along y, a brick up, each held by the 2x4 below.
        let q = turns("bond-2x4")
            .into_iter()
            .find(|v| v.u[0].rot == Rot::R90)
            .unwrap();
        let ys: Vec<i32> = q.v.iter().map(|n| n.piece.at.y).collect();
        assert_eq!(ys, vec![-2, 2]);
        assert!(q
            .v
            .iter()
            .all(|n| n.piece.at.z == 1 && n.anchor == Link::U(0)));
        // Every turn of every rule connects each new piece to its anchor.
        for var in rs.complex_variants() {
            let o = Cell::new(0, 0, 0);
            for n in &var.v {
                let b = n.piece.body(o, 24);
                let a = match n.anchor {
                    Link::U(k) => var.u[k].body(o, 24),
                    Link::V(k) => var.v[k].piece.body(o, 24),
                };
                assert!(a.holds(&b) || b.holds(&a), "{var:?}");
            }
        }
    }

    #[test]
    fn slopes_and_plates_are_pieces_too() {
        // Plates: layers of 8 LDU, so a plate on a brick is 3 layers up and
        // a brick on a plate 1.
        let text = "part 3001\npart 3020\npart 3039\nstart 3001\n\
                    complex sandwich\n u 3001 r0 0 0 0\n v 3020 r0 0 0 3\n v 3001 r0 2 0 4\n\
                    complex roof\n u 3001 r0 0 0 0\n v 3039 r0 0 0 3\n v 3039 r180 2 0 3\n";
        let rs = parse(text).unwrap();
        assert_eq!(rs.layer_ldu(), 8);
        let v = &rs.complex_variants()[0];
        assert_eq!(v.v[0].piece.at, Cell::new(0, 0, 3));
        assert_eq!(v.v[1].piece.at, Cell::new(2, 0, 4));
        assert_eq!(v.v[1].anchor, Link::V(0));
        // Slopes never repeat under a turn: the roof has four turns.
        assert_eq!(
            rs.complex_variants()
                .iter()
                .filter(|v| v.rule == ComplexId(1))
                .count(),
            4
        );
        // Without plates (layers of 12 LDU with slopes), the sandwich cannot
        // be written in whole layers and goes with the plate.
        let no_plates = rs
            .restricted(|p| p.spec().family() != crate::catalog::Family::Plate)
            .unwrap();
        assert_eq!(no_plates.layer_ldu(), 12);
        let names: Vec<&str> = no_plates
            .complex()
            .iter()
            .map(|r| r.name.as_str())
            .collect();
        assert_eq!(names, vec!["roof"]);
        assert_eq!(
            no_plates.complex_variants()[0].v[0].piece.at,
            Cell::new(0, 0, 2)
        );
        // A slope's studs are on its back row only: nothing stands on its face.
        let bad = "part 3001\npart 3039\nstart 3001\n\
                   complex a\n u 3039 r0 0 0 0\n v 3001 r0 0 -1 3\n";
        assert!(err(bad).starts_with("c.rules:6: the new 3001 of rule `a` is not stud-connected"));
    }
}
