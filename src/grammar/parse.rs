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
//! Every error names the file and line and says what is wrong.

use std::path::Path;

use thiserror::Error;

use super::{Dir, Rule, RuleSet, StartRule};
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
        let mut alphabet: Vec<PartKind> = Vec::new();
        let mut starts: Vec<StartRule> = Vec::new();
        let mut rules: Vec<Rule> = Vec::new();
        let mut unseen: Option<f64> = None;
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let err = |m: String| RuleError::at(&file, line, m);
            let body = raw.split('#').next().unwrap_or("").trim();
            if body.is_empty() {
                continue;
            }
            let f: Vec<&str> = body.split_whitespace().collect();
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
                    if let Some(prev) = rules.iter().find(|p| {
                        (p.anchor, p.added, p.added_rot, p.dir, p.dx, p.dy)
                            == (r.anchor, r.added, r.added_rot, r.dir, r.dx, r.dy)
                    }) {
                        return Err(err(format!("same rule as line {}", prev.line)));
                    }
                    rules.push(r);
                }
                other => {
                    return Err(err(format!(
                        "unknown statement `{other}`: expected part, start or rule"
                    )))
                }
            }
        }
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
        Ok(RuleSet::new(alphabet, starts, rules, file)?.with_unseen(unseen))
    }
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
