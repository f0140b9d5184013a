//! Reading rule files.
//!
//! A rule file is plain text, one statement a line, `#` starts a comment:
//!
//! ```text
//! part  3001                           # a letter of the alphabet Σ
//! start 3001                           # a starting rule ε -> 3001
//! rule  3001 3004 r90 up 3 0 12.5      # 3001 -> 3001 + 3004 turned r90, on top,
//!                                      # its corner 3 studs along x: weight 12.5
//! unseen 0.25                          # every other rule that connects two parts
//!                                      # of the alphabet, each with weight 0.25
//! ```
//!
//! A complex rule (module [`complex`](super::complex)) is a block: a
//! `complex NAME` line, then one line per piece, `u` for the pieces that
//! must be in place and `v` for the new ones in the order they are added.
//! A piece is its part, its turn and its minimum corner `X Y` in studs and
//! `Z` in plates (8 LDU), relative to the first `u` piece, which is at
//! `0 0 0`. The block ends at the next statement that is not a piece:
//!
//! ```text
//! complex bridge                        # a 2x4 across two 1x2 columns
//!   u 3004 r90  0 0 0                   #   a column, turned along y
//!   u 3004 r90  2 0 0                   #   another, one stud away
//!   v 3001 r0   0 0 3                   #   the 2x4 on both, a brick up
//! ```
//!
//! Complex rules carry no weight: the search tests one, picked with equal
//! probability, once every few nodes.
//!
//! Every error names the file and line and says what is wrong.

use std::collections::HashMap;
use std::path::Path;

use thiserror::Error;

use super::{ComplexRule, Dir, Plates, Rule, RulePiece, RuleSet, StartRule};
use crate::catalog::PartKind;
use crate::geom::Rot;

/// A rule file that cannot be used.
#[derive(Debug, Error)]
pub enum RuleError {
    /// The file could not be read.
    #[error("{file}: cannot read the rule file: {reason}")]
    Io {
        /// The file.
        file: String,
        /// Why.
        reason: std::io::Error,
    },
    /// A line is malformed or inconsistent.
    #[error("{file}:{line}: {message}")]
    Line {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// The file as a whole is unusable.
    #[error("{file}: {message}")]
    File {
        /// The file.
        file: String,
        /// What is wrong.
        message: String,
    },
}

impl RuleError {
    pub(super) fn at(file: &str, line: usize, message: String) -> RuleError {
        RuleError::Line {
            file: file.to_string(),
            line,
            message,
        }
    }
}

impl RuleSet {
    /// Reads a rule file.
    pub fn load(path: &Path) -> Result<RuleSet, RuleError> {
        let bytes = std::fs::read(path).map_err(|reason| RuleError::Io {
            file: path.display().to_string(),
            reason,
        })?;
        let text = String::from_utf8(bytes).map_err(|e| RuleError::File {
            file: path.display().to_string(),
            message: format!(
                "not a text file (invalid UTF-8 at byte {}); rule files are plain text",
                e.utf8_error().valid_up_to()
            ),
        })?;
        RuleSet::parse(&text, path)
    }

    /// Parses rule-file text; `path` names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<RuleSet, RuleError> {
        let file = path.display().to_string();
        let Statements {
            alphabet,
            starts,
            rules,
            unseen,
            complex,
            ..
        } = statements(text, &file)?;
        if alphabet.is_empty() {
            return Err(RuleError::File {
                file,
                message: "no `part` lines: the alphabet is empty".into(),
            });
        }
        if starts.is_empty() {
            return Err(RuleError::File {
                file,
                message: "no `start` rules: nothing can begin a build".into(),
            });
        }
        RuleSet::new(alphabet, starts, rules, file.clone())?
            .with_unseen(unseen)
            .with_complex(complex)
    }

    /// Adds the complex rules of `text`, a file of `complex` blocks only
    /// (such as `rules/complex.rules`), to this rule set's; `path` names
    /// the file in errors.
    pub fn with_complex_text(self, text: &str, path: &Path) -> Result<RuleSet, RuleError> {
        let file = path.display().to_string();
        let found = statements(text, &file)?;
        let (line, what) = match (
            found.alphabet.first(),
            found.starts.first(),
            found.rules.first(),
        ) {
            (Some(p), _, _) => (found.first_part_line, format!("`part {p}`")),
            (_, Some(s), _) => (s.line, "`start`".to_string()),
            (_, _, Some(r)) => (r.line, "`rule`".to_string()),
            _ if found.unseen.is_some() => (found.unseen_line, "`unseen`".to_string()),
            _ => (0, String::new()),
        };
        if !what.is_empty() {
            return Err(RuleError::at(
                &file,
                line,
                format!("{what} in a file of complex rules: it may hold only `complex` blocks"),
            ));
        }
        // This file's rules were checked against each other as it was read;
        // against the earlier ones, by hashed keys, not pairwise.
        let names: HashMap<&str, usize> = self
            .complex
            .iter()
            .enumerate()
            .map(|(i, p)| (p.name.as_str(), i))
            .collect();
        let blocks: HashMap<_, usize> = self
            .complex
            .iter()
            .enumerate()
            .map(|(i, p)| (block_key(p), i))
            .collect();
        let mut complex = self.complex.clone();
        for r in &found.complex {
            let prev = names
                .get(r.name.as_str())
                .or_else(|| blocks.get(&block_key(r)))
                .map(|&i| &self.complex[i]);
            if let Some(prev) = prev {
                return Err(RuleError::at(
                    &file,
                    r.line,
                    format!(
                        "complex rule `{}` repeats `{}` of {}:{}",
                        r.name, prev.name, self.source, prev.line
                    ),
                ));
            }
            complex.push(r.clone());
        }
        // Checked with this file's name in the messages, then merged.
        // (Only the alphabet and the layers are needed: not the basic rules'
        // turns, which are most of a rule set.)
        let alone = RuleSet {
            alphabet: self.alphabet.clone(),
            starts: Vec::new(),
            rules: Vec::new(),
            explicit: 0,
            unseen: None,
            variants: Vec::new(),
            complex: Vec::new(),
            complex_variants: Vec::new(),
            source: file,
            numbered: None,
        };
        alone.with_complex(found.complex)?;
        self.with_complex(complex)
    }
}

/// The statements of a rule file, in file order.
struct Statements {
    alphabet: Vec<PartKind>,
    starts: Vec<StartRule>,
    rules: Vec<Rule>,
    unseen: Option<f64>,
    complex: Vec<ComplexRule>,
    /// The line of the first `part` statement.
    first_part_line: usize,
    /// The line of the `unseen` statement.
    unseen_line: usize,
}

/// Reads the statements of rule-file text; `file` names it in errors.
fn statements(text: &str, file: &str) -> Result<Statements, RuleError> {
    let mut alphabet: Vec<PartKind> = Vec::new();
    let mut starts: Vec<StartRule> = Vec::new();
    let mut rules: Vec<Rule> = Vec::new();
    let mut complex: Vec<ComplexRule> = Vec::new();
    // Earlier statements by what makes them the same, for the duplicate
    // checks (hashed: a file of 200,000 rules is not compared pairwise).
    let mut seen = Seen::default();
    // Whether the last statement belongs to an open `complex` block.
    let mut in_block = false;
    let mut first_part_line = 0;
    let mut unseen: Option<f64> = None;
    let mut unseen_line = 0;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let err = |m: String| RuleError::at(file, line, m);
        let body = raw.split('#').next().unwrap_or("").trim();
        if body.is_empty() {
            continue;
        }
        let f: Vec<&str> = body.split_whitespace().collect();
        if in_block && !matches!(f[0], "u" | "v") {
            in_block = false;
            check_block(&complex, &mut seen, file)?;
        }
        let part = |s: &str| {
            PartKind::from_id(s).ok_or_else(|| {
                err(format!(
                    "unknown part `{s}`: not in brickwright's parts catalog"
                ))
            })
        };
        match f[0] {
            "part" => {
                if f.len() != 2 {
                    return Err(err(format!(
                        "`part` takes one part id, found {}",
                        f.len() - 1
                    )));
                }
                let p = part(f[1])?;
                if alphabet.contains(&p) {
                    return Err(err(format!("part {p} is declared twice")));
                }
                if alphabet.is_empty() {
                    first_part_line = line;
                }
                alphabet.push(p);
            }
            "unseen" => {
                let w = f.get(1).and_then(|w| w.parse::<f64>().ok());
                match (f.len(), w) {
                    (2, Some(w)) if w.is_finite() && w > 0.0 => {
                        if unseen.is_some() {
                            return Err(err("`unseen` is given twice".into()));
                        }
                        unseen = Some(w);
                        unseen_line = line;
                    }
                    _ => {
                        return Err(err(
                            "`unseen` takes one positive weight, e.g. `unseen 0.25`".into(),
                        ))
                    }
                }
            }
            "start" => {
                if f.len() != 2 {
                    return Err(err(format!(
                        "`start` takes one part id, found {}",
                        f.len() - 1
                    )));
                }
                let p = part(f[1])?;
                if !alphabet.contains(&p) {
                    return Err(err(format!(
                        "part {p} is not in the alphabet; declare it with `part {p}` first"
                    )));
                }
                starts.push(StartRule { part: p, line });
            }
            "rule" => {
                if f.len() != 8 {
                    return Err(err(format!(
                        "`rule` takes 7 fields (anchor new rot up|down dx dy weight), found {}",
                        f.len() - 1
                    )));
                }
                let anchor = part(f[1])?;
                let added = part(f[2])?;
                let added_rot = Rot::parse(f[3]).ok_or_else(|| {
                    err(format!(
                        "bad rotation `{}`: use r0, r90, r180 or r270",
                        f[3]
                    ))
                })?;
                let dir = match f[4] {
                    "up" => Dir::Up,
                    "down" => Dir::Down,
                    o => return Err(err(format!("bad direction `{o}`: use up or down"))),
                };
                let int = |s: &str, what: &str| {
                    s.parse::<i32>()
                        .map_err(|_| err(format!("bad {what} `{s}`: not an integer")))
                };
                let dx = int(f[5], "dx")?;
                let dy = int(f[6], "dy")?;
                let weight: f64 = f[7]
                    .parse()
                    .map_err(|_| err(format!("bad weight `{}`: not a number", f[7])))?;
                if !(weight.is_finite() && weight > 0.0) {
                    return Err(err(format!("weight {} must be a positive number", f[7])));
                }
                let r = Rule {
                    anchor,
                    added,
                    added_rot,
                    dir,
                    dx,
                    dy,
                    weight,
                    line,
                };
                let key = (r.anchor, r.added, r.added_rot, r.dir, r.dx, r.dy);
                if let Some(prev) = seen.rules.insert(key, line) {
                    return Err(err(format!("same rule as line {prev}")));
                }
                rules.push(r);
            }
            "complex" => {
                let name = match f[..] {
                    [_, name] => name,
                    _ => {
                        return Err(err(format!(
                            "`complex` takes one name, found {}",
                            f.len() - 1
                        )))
                    }
                };
                if let Some(&prev) = seen.names.get(name) {
                    return Err(err(format!(
                        "complex rule `{name}` is already defined on line {prev}"
                    )));
                }
                seen.names.insert(name.to_string(), line);
                complex.push(ComplexRule {
                    name: name.to_string(),
                    u: Vec::new(),
                    v: Vec::new(),
                    line,
                });
                in_block = true;
            }
            tag @ ("u" | "v") => {
                if !in_block {
                    return Err(err(format!(
                        "`{tag}` outside a complex rule: start the block with `complex NAME`"
                    )));
                }
                if f.len() != 6 {
                    return Err(err(format!(
                        "`{tag}` takes 5 fields (part rot x y z), found {}",
                        f.len() - 1
                    )));
                }
                let int = |s: &str, what: &str| {
                    s.parse::<i32>()
                        .map_err(|_| err(format!("bad {what} `{s}`: not an integer")))
                };
                let piece = RulePiece {
                    part: part(f[1])?,
                    rot: Rot::parse(f[2]).ok_or_else(|| {
                        err(format!(
                            "bad rotation `{}`: use r0, r90, r180 or r270",
                            f[2]
                        ))
                    })?,
                    x: int(f[3], "x")?,
                    y: int(f[4], "y")?,
                    z: Plates(int(f[5], "z (plates)")?),
                    line,
                };
                let r = complex.last_mut().expect("an open block");
                if tag == "u" && r.u.is_empty() && (piece.x, piece.y, piece.z.0) != (0, 0, 0) {
                    return Err(err(format!(
                            "the first `u` piece is the origin of the others: put it at 0 0 0, not {} {} {}",
                            piece.x, piece.y, piece.z.0
                        )));
                }
                if tag == "u" && !r.v.is_empty() {
                    return Err(err(
                        "`u` after a `v`: give the pieces in place first, then the new ones".into(),
                    ));
                }
                if tag == "u" {
                    r.u.push(piece);
                } else {
                    r.v.push(piece);
                }
            }
            other => {
                return Err(err(format!(
                    "unknown statement `{other}`: expected part, start, rule, unseen or complex"
                )))
            }
        }
    }
    if in_block {
        check_block(&complex, &mut seen, file)?;
    }
    Ok(Statements {
        alphabet,
        starts,
        rules,
        unseen,
        complex,
        first_part_line,
        unseen_line,
    })
}

/// What makes a piece of a complex rule the same as another.
type PieceKey = (PartKind, Rot, i32, i32, super::Plates);

/// What makes two complex rules the same: their `u` and `v` pieces.
fn block_key(r: &ComplexRule) -> (Vec<PieceKey>, Vec<PieceKey>) {
    let keys = |ps: &[RulePiece]| -> Vec<PieceKey> {
        ps.iter().map(|p| (p.part, p.rot, p.x, p.y, p.z)).collect()
    };
    (keys(&r.u), keys(&r.v))
}

/// The statements read so far, keyed by what makes two the same.
#[derive(Default)]
struct Seen {
    /// Basic rules: anchor, added part, its turn, side and offset -> line.
    rules: HashMap<(PartKind, PartKind, Rot, Dir, i32, i32), usize>,
    /// Complex rule names -> line.
    names: HashMap<String, usize>,
    /// Complex rules' `u` and `v` pieces -> index into the complex rules.
    blocks: HashMap<(Vec<PieceKey>, Vec<PieceKey>), usize>,
}

/// The checks of a complete `complex` block (the last of `complex`): both
/// sides have pieces, and no earlier rule has the same ones.
fn check_block(complex: &[ComplexRule], seen: &mut Seen, file: &str) -> Result<(), RuleError> {
    let r = complex.last().expect("an open block");
    for (side, pieces) in [("u", &r.u), ("v", &r.v)] {
        if pieces.is_empty() {
            return Err(RuleError::at(
                file,
                r.line,
                format!(
                    "complex rule `{}` has no `{side}` pieces: add a `{side} PART ROT X Y Z` line",
                    r.name
                ),
            ));
        }
    }
    let key = block_key(r);
    if let Some(prev) = seen.blocks.get(&key).map(|&i| &complex[i]) {
        return Err(RuleError::at(
            file,
            r.line,
            format!(
                "complex rule `{}` has the same pieces as `{}` on line {}",
                r.name, prev.name, prev.line
            ),
        ));
    }
    seen.blocks.insert(key, complex.len() - 1);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        RuleSet::parse(text, Path::new("bad.rules"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn errors_name_file_and_line() {
        let head = "part 3001\nstart 3001\n";
        assert_eq!(
            err(&format!("{head}rule 3001 3001 r0 up 9 0 1\n")),
            "bad.rules:3: the new 3001 at offset (9, 0) on top is not stud-connected to the 3001"
        );
        assert!(err(&format!("{head}\n# c\nrule 3001 9999 r0 up 0 0 1\n"))
            .starts_with("bad.rules:5: unknown part `9999`"));
        assert!(
            err(&format!("{head}rule 3001 3001 r45 up 0 0 1\n")).contains(":3: bad rotation `r45`")
        );
        assert!(
            err(&format!("{head}rule 3001 3001 r0 sideways 0 0 1\n")).contains(":3: bad direction")
        );
        assert!(err(&format!("{head}rule 3001 3001 r0 up 0 0 -2\n"))
            .contains(":3: weight -2 must be a positive"));
        assert!(
            err(&format!("{head}rule 3001 3001 r0 up 0 0\n")).contains(":3: `rule` takes 7 fields")
        );
        assert!(err(&format!("{head}rule 3001 3001 r0 up x 0 1\n")).contains(":3: bad dx `x`"));
        assert!(err(&format!(
            "{head}rule 3001 3001 r0 up 1 0 1\nrule 3001 3001 r0 up 1 0 2\n"
        ))
        .contains(":4: same rule as line 3"));
        assert!(err("part 3001\nstart 3003\n").contains(":2: part 3003 is not in the alphabet"));
        assert!(err("start\n").contains(":1: `start` takes one part id"));
        assert!(err("brick 3001\n").contains(":1: unknown statement `brick`"));
        assert!(err("part 3001\n").contains("no `start` rules"));
        assert!(err("part 3001\nstart 3001\nrule 3001 3003 r0 up 0 0 1\n")
            .contains(":3: part 3003 is not in the alphabet"));
    }

    #[test]
    fn rule_files_round_trip() {
        let rs =
            RuleSet::parse(&crate::grammar::default_rules_text(), Path::new("d.rules")).unwrap();
        let text = rs.to_text("round trip");
        let back = RuleSet::parse(&text, Path::new("d.rules")).unwrap();
        assert_eq!(back.alphabet(), rs.alphabet());
        assert_eq!(back.variants(), rs.variants());
        assert_eq!(back.to_text("round trip"), text);
    }
}
