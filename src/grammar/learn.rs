//! Learning rule frequencies from example builds.
//!
//! The paper weighs its rules by how often people use them (section 3,
//! "Using Example Data"): users build shapes piece by piece, and
//!
//! - for each newly added piece, the basic-form rule `A -> A + B` gets one
//!   count for **each** earlier piece `A` the new piece `B` stud-connects to
//!   (`up` when `B` goes on top of `A`, `down` when underneath);
//! - starting rules get no data: a piece that connects to nothing built
//!   before it adds nothing;
//! - a shape built separately and then attached counts its own building,
//!   but not the joints that attach it.
//!
//! Here a build is a step-ordered LDraw file (`.ldr` or `.mpd`): pieces are
//! taken in file order, which is step order. Each reference to an MPD
//! submodel (`0 FILE`) is one separate build of that submodel: the joints
//! among its own pieces count, the joints between its pieces and anything
//! outside that instance (the model it is attached to, or a submodel nested
//! in it) do not. Colours do not matter. Parts outside the catalog are
//! skipped and reported, with a count and the first place each was met;
//! a piece off the stud grid or the half-plate (4 LDU) grid, or tilted, is
//! an error naming its `file:line`.
//!
//! Pieces are bodies (see [`crate::geom::Body`]): `B` stud-connects to `A`
//! when `B`'s tubes press onto `A`'s studs or the other way round, so a
//! brick on a slope's back row counts and a brick on its stud-less front
//! row does not. Every piece of a learning run is mapped onto one grid, its
//! layers as high as all the builds allow (as [`crate::ldraw::to_assembly`]
//! chooses them: 24 LDU for bricks on brick courses, 8 once plates appear,
//! 12 or 4 for bricks half a brick apart). A rule's geometry (`dx`, `dy` in
//! studs, `dir`, `B`'s rotation) does not depend on that height, so one
//! learned file serves every layer height.
//!
//! A rule is counted once however the observed pair was turned: see
//! [`RuleKey`]. The result, [`Learned`], writes a rule file that
//! [`RuleSet::parse`] reads, with the counts as weights.
//!
//! ```
//! use std::path::Path;
//! use brickwright::grammar::learn::Learner;
//! use brickwright::ldraw::parse_ldr;
//!
//! // Two 2x4s side by side, then a 2x4 bridging them.
//! let text = "\
//! 1 4 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat
//! 1 4 40 -24 60 1 0 0 0 1 0 0 0 1 3001.dat
//! 0 STEP
//! 1 4 40 -48 40 1 0 0 0 1 0 0 0 1 3001.dat
//! ";
//! let mut learner = Learner::new();
//! learner.add(&parse_ldr(text, Path::new("wall.ldr")).unwrap()).unwrap();
//! let learned = learner.finish().unwrap();
//! // The third brick holds on to both: two counts, one for each half overlap
//! // (the same rule, seen from either side, once turned by a half turn).
//! assert_eq!(learned.total(), 2);
//! assert!(learned.to_rules_text().contains("rule 3001   3001   r0   up      0  -1  2\n"));
//! ```

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use std::path::PathBuf;

use serde::Serialize;
use thiserror::Error;

use super::{Dir, Rule, RuleError, RuleSet, StartRule, DEFAULT_ALPHABET};
use crate::assembly::Placement;
use crate::catalog::PartKind;
use crate::geom::{Body, Cell, Rot};
use crate::ldraw::{layer_ldu_of, read_ldr, to_placement, LdrError, LdrModel};

/// The paper's figures for its collected data (section 5), shown beside
/// ours in [`Learned::summary`]: distinct rules, total count, lowest and
/// highest count.
pub const PAPER_FIGURES: (u64, u64, u64, u64) = (223, 2484, 1, 139);

/// How many skipped parts the summary lists, most frequent first.
const SKIPPED_LISTED: usize = 12;

/// How many part names an error lists before it says "...".
const NAMES_IN_ERRORS: usize = 5;

/// Builds that cannot be learned from.
#[derive(Debug, Error)]
pub enum LearnError {
    /// A build could not be read, or has a bad line: a line that is not
    /// LDraw, a piece off the stud or half-plate grid, a tilted piece.
    #[error(transparent)]
    Ldraw(#[from] LdrError),
    /// A directory given as a build could not be listed.
    #[error("{}: cannot list the directory: {source}", dir.display())]
    ReadDir {
        /// The directory.
        dir: PathBuf,
        /// Why the system refused.
        source: std::io::Error,
    },
    /// A directory given as a build holds no `.ldr` or `.mpd` file.
    #[error("{}: no .ldr or .mpd files in this directory", dir.display())]
    EmptyDir {
        /// The directory.
        dir: PathBuf,
    },
    /// A build has no piece of a catalog part, so it teaches nothing.
    #[error("{}: nothing to learn from: {why}", path.display())]
    NothingToLearn {
        /// The build.
        path: PathBuf,
        /// What it holds instead, and what to do.
        why: String,
    },
    /// No builds were given.
    #[error("no builds to learn from: give at least one .ldr or .mpd file")]
    NoBuilds,
    /// The learned rules do not load as a rule set. This is a bug in
    /// brickwright, not a problem with the builds.
    #[error("the learned rules do not load (a bug in brickwright, please report it): {0}")]
    Inconsistent(RuleError),
}

/// A basic-form rule `A -> A + B` in canonical form: what one count goes to.
///
/// As in rule files, `B`'s rotation and the offset `(dx, dy)` of its
/// minimum corner from `A`'s, in studs, are measured with `A` unturned.
/// Observations that differ only by a turn of the whole pair, or by a turn
/// that leaves `A` looking the same (a 2x4 turned by a half turn), are the
/// same rule: of the ways to write the pair with `A` unturned, the key keeps
/// the one with the smallest `(added_rot, dx, dy)`, and `added_rot` is
/// canonical for `B`'s symmetry. The derived order (anchor, added, dir,
/// rot, dx, dy) is the order of the rules in a learned rule file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct RuleKey {
    /// The earlier piece `A`.
    pub anchor: PartKind,
    /// The new piece `B`.
    pub added: PartKind,
    /// Whether `B` went on top of `A` or underneath.
    pub dir: Dir,
    /// `B`'s rotation relative to `A`.
    pub added_rot: Rot,
    /// Offset of `B`'s minimum corner from `A`'s, in studs.
    pub dx: i32,
    /// Offset of `B`'s minimum corner from `A`'s, in studs.
    pub dy: i32,
}

/// Where something was first met in the builds.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Location {
    /// The build, as given.
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
}

/// A part outside the catalog, skipped.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Skipped {
    /// The part's name, lower case without `.dat`.
    pub part: String,
    /// How many references named it.
    pub count: usize,
    /// The first reference.
    pub first: Location,
}

/// What one build had that could not be learned from.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct BuildSkips {
    /// The build.
    pub file: PathBuf,
    /// Part references read.
    pub pieces: usize,
    /// Pieces learned from.
    pub learned: usize,
    /// Pieces of parts outside the catalog.
    pub unknown: usize,
    /// Pieces turned off the vertical axis (not by a quarter turn about it).
    pub tilted: usize,
    /// Pieces off the stud grid or the half-plate grid.
    pub off_grid: usize,
    /// Part definitions packed inside the file (an MPD's `0 !LDRAW_ORG Part`
    /// sections), read as parts, not as submodels.
    pub packed_parts: usize,
    /// The line of the first tilted piece.
    pub first_tilted: Option<usize>,
    /// The line of the first piece off the grid.
    pub first_off_grid: Option<usize>,
}

impl BuildSkips {
    /// Pieces skipped.
    pub fn skipped(&self) -> usize {
        self.unknown + self.tilted + self.off_grid
    }
}

/// Who made a build and under which licence, as its file says.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Credit {
    /// The build, as given.
    pub file: PathBuf,
    /// Its `0 Author:` lines, each once.
    pub authors: Vec<String>,
    /// Its `0 !LICENSE` line, if any.
    pub licence: Option<String>,
}

/// What was read and what was left out.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct LearnReport {
    /// What each build had that could not be learned from, in the order
    /// read.
    pub per_build: Vec<BuildSkips>,
    /// Pieces skipped as tilted, in all.
    pub tilted: usize,
    /// Pieces skipped as off the grid, in all.
    pub off_grid: usize,
    /// Part definitions packed inside the files, in all.
    pub packed_parts: usize,
    /// Builds that had nothing to learn from, with why; [`learn`] skips
    /// them and goes on.
    pub empty_builds: Vec<(PathBuf, String)>,
    /// The builds read, as given, in the order read.
    pub builds: Vec<PathBuf>,
    /// Who made each build read and under which licence, in the order read.
    pub credits: Vec<Credit>,
    /// Submodel instances built separately inside them.
    pub submodel_builds: usize,
    /// Part references read, catalog parts or not.
    pub pieces: usize,
    /// Pieces of catalog parts, the ones learned from.
    pub learned_pieces: usize,
    /// Learned pieces that connected to nothing built before them in their
    /// own build (uses of starting rules, which get no data).
    pub starts: usize,
    /// Joints between a separately built submodel and what it is attached
    /// to, not counted.
    pub attachments: u64,
    /// Parts outside the catalog, most frequent first.
    pub skipped: Vec<Skipped>,
    /// The catalog parts seen, in catalog order.
    pub parts: Vec<PartKind>,
    /// The height in LDU of the grid layers all pieces were mapped onto:
    /// the largest the builds allow (24, 12, 8 or 4).
    pub layer_ldu: i32,
}

/// Rule counts learned from builds, and how they were read.
#[derive(Debug, Clone, PartialEq)]
pub struct Learned {
    /// How often each rule was used, in rule-file order.
    pub counts: BTreeMap<RuleKey, u64>,
    /// What was read and skipped.
    pub report: LearnReport,
    /// The counts as a rule set (checked when learning ends).
    rules: RuleSet,
}

/// Reads step-ordered LDraw builds and counts the rules they use.
///
/// A directory in `paths` stands for the `.ldr` and `.mpd` files in it. The
/// files are read in sorted order, each once, so the same files in any
/// order give the same result.
///
/// A build with nothing to learn from (no catalog piece on the grid) is
/// skipped and listed in [`LearnReport::empty_builds`]; it is an error only
/// when no build at all teaches anything.
pub fn learn(paths: &[PathBuf]) -> Result<Learned, LearnError> {
    let mut learner = Learner::new();
    let mut empty = Vec::new();
    let mut last_empty = None;
    for path in build_files(paths)? {
        match learner.add(&read_ldr(&path)?) {
            Ok(()) => {}
            Err(e @ LearnError::NothingToLearn { .. }) => {
                if let LearnError::NothingToLearn { path, why } = &e {
                    empty.push((path.clone(), why.clone()));
                }
                last_empty = Some(e);
            }
            Err(e) => return Err(e),
        }
    }
    if learner.builds.is_empty() {
        if let Some(e) = last_empty {
            return Err(e);
        }
    }
    learner.report.empty_builds = empty;
    learner.finish()
}

/// The files `paths` stand for: directories expanded to their `.ldr` and
/// `.mpd` files, sorted, each once.
fn build_files(paths: &[PathBuf]) -> Result<Vec<PathBuf>, LearnError> {
    let mut files = Vec::new();
    for path in paths {
        if !path.is_dir() {
            files.push(path.clone());
            continue;
        }
        let listing = std::fs::read_dir(path).map_err(|source| LearnError::ReadDir {
            dir: path.clone(),
            source,
        })?;
        let before = files.len();
        for entry in listing {
            let entry = entry.map_err(|source| LearnError::ReadDir {
                dir: path.clone(),
                source,
            })?;
            let file = entry.path();
            let is_build = file
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| e.eq_ignore_ascii_case("ldr") || e.eq_ignore_ascii_case("mpd"));
            if is_build && file.is_file() {
                files.push(file);
            }
        }
        if files.len() == before {
            return Err(LearnError::EmptyDir { dir: path.clone() });
        }
    }
    files.sort();
    files.dedup();
    Ok(files)
}

/// Reads builds and counts the rules they use; [`learn`] drives it over
/// files.
///
/// [`Learner::add`] reads a build's pieces and checks them;
/// [`Learner::finish`] counts the joints, once the layer height all the
/// builds allow is known.
#[derive(Debug, Default)]
pub struct Learner {
    /// Each build's catalog pieces in build order, with the submodel
    /// instance each belongs to; `z` is the piece's bottom in LDU above the
    /// build's lowest piece.
    builds: Vec<Vec<(usize, Placement)>>,
    report: LearnReport,
    skipped: BTreeMap<String, Skipped>,
}

impl Learner {
    /// A learner that has seen nothing.
    pub fn new() -> Self {
        Learner::default()
    }

    /// Reads one build, learning from every piece it can: pieces of parts
    /// outside the catalog, tilted pieces and pieces off the stud or
    /// half-plate grid are skipped and counted ([`BuildSkips`]).
    ///
    /// Errors, taking nothing in, if the build has no catalog piece it can
    /// learn from.
    pub fn add(&mut self, model: &LdrModel) -> Result<(), LearnError> {
        let mut placed: Vec<(usize, Placement)> = Vec::new();
        let mut skipped: Vec<(String, usize)> = Vec::new();
        let mut mine = BuildSkips {
            file: model.path.clone(),
            pieces: model.parts.len(),
            packed_parts: model.packed_parts,
            ..BuildSkips::default()
        };
        for r in &model.parts {
            let Some(kind) = catalog_part(&r.part) else {
                skipped.push((part_name(&r.part), r.line));
                mine.unknown += 1;
                continue;
            };
            let r = &crate::ldraw::PartRef {
                part: kind.spec().id.0.to_string(),
                ..r.clone()
            };
            match to_placement(r, &model.path) {
                Ok(p) => placed.push((r.instance, p)),
                Err(LdrError::NotQuarterTurn { line, .. }) => {
                    mine.tilted += 1;
                    mine.first_tilted.get_or_insert(line);
                }
                Err(LdrError::OffGrid { line, .. }) => {
                    mine.off_grid += 1;
                    mine.first_off_grid.get_or_insert(line);
                }
                Err(e) => return Err(e.into()),
            }
        }
        let Some(low) = placed.iter().map(|(_, p)| p.origin.z).min() else {
            return Err(LearnError::NothingToLearn {
                path: model.path.clone(),
                why: nothing_to_learn(&skipped, &mine),
            });
        };
        mine.learned = placed.len();
        for (_, p) in &mut placed {
            p.origin.z -= low;
        }
        for (part, line) in skipped {
            self.skipped
                .entry(part.clone())
                .or_insert_with(|| Skipped {
                    part,
                    count: 0,
                    first: Location {
                        file: model.path.clone(),
                        line,
                    },
                })
                .count += 1;
        }
        let r = &mut self.report;
        r.tilted += mine.tilted;
        r.off_grid += mine.off_grid;
        r.packed_parts += mine.packed_parts;
        r.per_build.push(mine);
        r.builds.push(model.path.clone());
        r.credits.push(Credit {
            file: model.path.clone(),
            authors: model.authors.clone(),
            licence: model.licence.clone(),
        });
        r.submodel_builds += model.instances.len() - 1;
        r.pieces += model.parts.len();
        r.learned_pieces += placed.len();
        for (_, p) in &placed {
            if let Err(at) = r.parts.binary_search(&p.part) {
                r.parts.insert(at, p.part);
            }
        }
        self.builds.push(placed);
        Ok(())
    }

    /// Counts the rules the builds use, on one grid for all of them, and
    /// makes the rule set.
    pub fn finish(self) -> Result<Learned, LearnError> {
        let mut report = self.report;
        if self.builds.is_empty() {
            return Err(LearnError::NoBuilds);
        }
        report.layer_ldu = layer_ldu_of(self.builds.iter().flatten().map(|(_, p)| p));
        let mut counts = BTreeMap::new();
        for build in &self.builds {
            count_build(build, report.layer_ldu, &mut counts, &mut report);
        }
        report.skipped = self.skipped.into_values().collect();
        report
            .skipped
            .sort_by(|a, b| b.count.cmp(&a.count).then_with(|| a.part.cmp(&b.part)));
        // The built-in alphabet stays in beside the parts seen, so the file
        // builds any shape (unused parts get the `unseen` weight, if any);
        // [`Learned::seen_parts_only`] drops it.
        let mut alphabet = report.parts.clone();
        alphabet.extend(
            DEFAULT_ALPHABET
                .iter()
                .filter_map(|id| PartKind::from_id(id)),
        );
        alphabet.sort_unstable();
        alphabet.dedup();
        let rules = rule_set(&alphabet, &counts)?;
        Ok(Learned {
            counts,
            report,
            rules,
        })
    }
}

/// Counts the joints of one build, whose pieces' bottoms are in LDU, in a
/// grid of `layer_ldu`-high layers (which divides every bottom): each joint
/// inside a submodel instance into `counts`, the others, and the pieces
/// joined to nothing earlier, into `report`.
fn count_build(
    pieces: &[(usize, Placement)],
    layer_ldu: i32,
    counts: &mut BTreeMap<RuleKey, u64>,
    report: &mut LearnReport,
) {
    let mut placed: Vec<(usize, Placement, Body)> = Vec::with_capacity(pieces.len());
    // Earlier pieces by the cells of their top and bottom layers: only a
    // piece whose top meets this one's bottom, or whose bottom meets its
    // top, over a shared cell can hold it or be held. Each cell remembers
    // the first few pieces (one, in a build without overlaps), so a file
    // stacking thousands of copies on one spot is not paired copy by copy.
    let mut tops: HashMap<Cell, Vec<usize>> = HashMap::new();
    let mut bottoms: HashMap<Cell, Vec<usize>> = HashMap::new();
    let mut near: Vec<usize> = Vec::new();
    for &(instance, mut piece) in pieces {
        debug_assert_eq!(piece.origin.z % layer_ldu, 0);
        piece.origin.z /= layer_ldu;
        let body = piece.body(layer_ldu);
        let bx = body.bbox;
        let (bottom, top) = (bx.min.z, bx.min.z + bx.sz);
        let footprint = |z: i32| {
            (bx.min.y..bx.min.y + bx.sy)
                .flat_map(move |y| (bx.min.x..bx.min.x + bx.sx).map(move |x| Cell::new(x, y, z)))
        };
        near.clear();
        for c in footprint(bottom) {
            near.extend(tops.get(&c).into_iter().flatten());
        }
        for c in footprint(top) {
            near.extend(bottoms.get(&c).into_iter().flatten());
        }
        near.sort_unstable();
        near.dedup();
        let mut joined = false;
        for &k in &near {
            let (earlier_instance, earlier, earlier_body) = &placed[k];
            let Some(dir) = link(earlier_body, &body) else {
                continue;
            };
            if *earlier_instance == instance {
                let key = rule_key(earlier, earlier_body, &piece, &body, dir);
                *counts.entry(key).or_insert(0) += 1;
                joined = true;
            } else {
                report.attachments += 1;
            }
        }
        if !joined {
            report.starts += 1;
        }
        let i = placed.len();
        for (index, z) in [(&mut tops, top), (&mut bottoms, bottom)] {
            for c in footprint(z) {
                let here = index.entry(c).or_default();
                if here.len() < MAX_PIECES_PER_CELL {
                    here.push(i);
                }
            }
        }
        placed.push((instance, piece, body));
    }
}

/// The catalog part a reference names, as people's files write it: with
/// a folder (`parts/3001.dat`, as packed files have it), or another
/// variant of the same shape (`3023` for the catalog's `3023b`, `3040a` for
/// `3040b`, a print such as `3039p23` for `3039`): the one catalog part whose
/// number is the same, if there is exactly one.
pub fn catalog_part(written: &str) -> Option<PartKind> {
    let name = written.trim().replace('\\', "/");
    let name = name.rsplit('/').next().unwrap_or(&name);
    if let Some(k) = PartKind::from_id(name) {
        return Some(k);
    }
    let stem = name.to_ascii_lowercase();
    let stem = stem.strip_suffix(".dat").unwrap_or(&stem);
    let digits = |s: &str| -> String { s.chars().take_while(char::is_ascii_digit).collect() };
    let number = digits(stem);
    // A letter and digits after the number are a variant or a print; a
    // part with anything else after it (`3001s01`, a subpart) is not.
    let rest = &stem[number.len()..];
    let variant = rest.is_empty()
        || rest.len() == 1 && rest.chars().all(|c| c.is_ascii_alphabetic())
        || rest.starts_with('p') && rest[1..].chars().all(|c| c.is_ascii_alphanumeric());
    if number.is_empty() || !variant {
        return None;
    }
    let mut same = PartKind::all().filter(|k| digits(k.spec().id.0) == number);
    match (same.next(), same.next()) {
        (Some(k), None) => Some(k),
        _ => None,
    }
}
/// How many pieces a cell of [`count_build`]'s index remembers: one in a
/// build without overlaps; the bound keeps a pile of copies linear.
const MAX_PIECES_PER_CELL: usize = 8;

/// A part name as reports give it: lower case, without `.dat`.
fn part_name(written: &str) -> String {
    let name = written.trim().to_ascii_lowercase();
    match name.strip_suffix(".dat") {
        Some(stem) => stem.to_string(),
        None => name,
    }
}

/// Why a build with no catalog piece teaches nothing.
fn nothing_to_learn(skipped: &[(String, usize)], mine: &BuildSkips) -> String {
    if mine.tilted + mine.off_grid > 0 {
        return format!(
            "of its {} part references, {} are tilted, {} off the grid and {} outside brickwright's catalog",
            mine.pieces, mine.tilted, mine.off_grid, mine.unknown
        );
    }
    if skipped.is_empty() {
        return "it has no part references (type-1 lines)".into();
    }
    let mut names: Vec<&str> = skipped.iter().map(|(n, _)| n.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    let mut list = names
        .iter()
        .take(NAMES_IN_ERRORS)
        .copied()
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > NAMES_IN_ERRORS {
        list.push_str(", ...");
    }
    format!(
        "its {} part references are all outside brickwright's catalog ({list}); \
         learn from builds made of catalog bricks",
        skipped.len()
    )
}

/// The rule set of `counts` over the alphabet `parts`, every part a
/// starting rule.
fn rule_set(parts: &[PartKind], counts: &BTreeMap<RuleKey, u64>) -> Result<RuleSet, LearnError> {
    let starts = parts
        .iter()
        .map(|&part| StartRule { part, line: 0 })
        .collect();
    let rules = counts
        .iter()
        .map(|(k, &n)| Rule {
            anchor: k.anchor,
            added: k.added,
            added_rot: k.added_rot,
            dir: k.dir,
            dx: k.dx,
            dy: k.dy,
            weight: n as f64,
            line: 0,
        })
        .collect();
    RuleSet::new(parts.to_vec(), starts, rules, "learned".into()).map_err(LearnError::Inconsistent)
}

/// Whether `b` stud-connects to `a`, and on which side of `a` it is: `Up`
/// when `b` is pressed onto `a`'s studs, `Down` when `a` is pressed onto
/// `b`'s.
///
/// All of the "what connects" geometry of learning is here (and in
/// [`rule_key`]); it is the bodies' own, as the rule set checks its rules:
/// a piece on a slope's stud-less front row is not connected.
fn link(a: &Body, b: &Body) -> Option<Dir> {
    if a.holds(b) {
        Some(Dir::Up)
    } else if b.holds(a) {
        Some(Dir::Down)
    } else {
        None
    }
}

/// The canonical rule that joining `b` (body `bb`) to `a` (body `ab`) on
/// side `dir` uses.
///
/// Writes the pair with `a` unturned in each way that leaves `a` looking
/// the same (undoing its rotation, then any turn of its symmetry: none but
/// the identity for a slope) and keeps the smallest `(added_rot, dx, dy)`;
/// so every turn of the same joint gives the same key, and distinct keys
/// generate distinct rule variants. Offsets are between the bounding boxes'
/// minimum corners, in studs, as in rule files.
fn rule_key(a: &Placement, ab: &Body, b: &Placement, bb: &Body, dir: Dir) -> RuleKey {
    let (sa, sb) = (a.part.spec(), b.part.spec());
    Rot::ALL
        .into_iter()
        .filter(|&s| sa.canonical_rot(s) == Rot::R0)
        .map(|s| {
            let undo = inverse(a.rot.then(s));
            let (ta, tb) = (ab.bbox.turned(undo), bb.bbox.turned(undo));
            RuleKey {
                anchor: a.part,
                added: b.part,
                dir,
                added_rot: sb.canonical_rot(b.rot.then(undo)),
                dx: tb.min.x - ta.min.x,
                dy: tb.min.y - ta.min.y,
            }
        })
        .min_by_key(|k| (k.added_rot, k.dx, k.dy))
        .expect("the unturned rotation leaves every part looking the same")
}

/// The rotation that undoes `r`.
fn inverse(r: Rot) -> Rot {
    Rot::from_quarter_turns(4 - r.quarter_turns())
}

/// The weight `brickwright learn` gives rules no build used, below the
/// lowest count (1): such rules stay possible but are rarely drawn.
pub const DEFAULT_UNSEEN: f64 = 0.05;

impl Learned {
    /// These counts with every rule no build used allowed at weight `w`
    /// (the rule file's `unseen` statement), or not at all for `None`.
    pub fn with_unseen(mut self, w: Option<f64>) -> Learned {
        self.rules = self.rules.with_unseen(w);
        self
    }

    /// These counts over the parts the builds used only, without the
    /// built-in alphabet: the search can then use no other part (and a
    /// shape those parts cannot cover is an error at build time).
    pub fn seen_parts_only(mut self) -> Result<Learned, LearnError> {
        let seen = &self.report.parts;
        self.rules = self
            .rules
            .restricted(|p| seen.contains(&p))
            .map_err(LearnError::Inconsistent)?;
        Ok(self)
    }

    /// The rule set of the counts: every part seen and (unless
    /// [`Learned::seen_parts_only`]) the built-in alphabet, a starting rule
    /// for each, the rules with their counts as weights.
    pub fn rule_set(&self) -> &RuleSet {
        &self.rules
    }

    /// Number of distinct rules.
    pub fn distinct(&self) -> usize {
        self.counts.len()
    }

    /// Sum of all counts.
    pub fn total(&self) -> u64 {
        self.counts.values().sum()
    }

    /// The lowest and highest count, if any rule was used.
    pub fn count_range(&self) -> Option<(u64, u64)> {
        let min = self.counts.values().min()?;
        let max = self.counts.values().max()?;
        Some((*min, *max))
    }

    /// The rule file: a header naming the builds (file names only, sorted),
    /// with the authors and licence each file names, and the totals, then the rules with their counts as weights.
    /// [`RuleSet::parse`] reads it back to [`Learned::rule_set`].
    pub fn to_rules_text(&self) -> String {
        let r = &self.report;
        let mut h = String::new();
        h.push_str("brickwright rule file: the Lego rewriting system (Σ, R).\n");
        let _ = writeln!(
            h,
            "Learned by `brickwright learn` from {} ({}),\n\
             with the authors and licences their files name:",
            plural(r.builds.len(), "build"),
            plural(r.submodel_builds, "separately built submodel")
        );
        let mut credits: Vec<String> = r.credits.iter().map(credit_line).collect();
        credits.sort();
        for line in credits {
            let _ = writeln!(h, "  {line}");
        }
        let unknown = r.pieces - r.learned_pieces - r.tilted - r.off_grid;
        let _ = writeln!(
            h,
            "{} read: {} of catalog parts, {} skipped ({} not in the catalog,\n\
             {} tilted, {} off the grid).",
            plural(r.pieces, "piece"),
            thousands(r.learned_pieces as u64),
            thousands((r.pieces - r.learned_pieces) as u64),
            thousands(unknown as u64),
            thousands(r.tilted as u64),
            thousands(r.off_grid as u64)
        );
        let _ = writeln!(h, "{}.", self.totals());
        let extra = self.rules.alphabet().len().saturating_sub(r.parts.len());
        if extra > 0 {
            let _ = writeln!(
                h,
                "Parts: the {} the builds used, and {extra} more of the built-in alphabet\n\
                 no build used (they start, and join only through `unseen`, if any).",
                r.parts.len()
            );
        }
        h.push_str(
            "\n\
             Each weight is a count (the paper's \"example data\", section 3): every\n\
             piece added to a build counts once for each earlier piece A of the same\n\
             build it stud-connects to, as the rule A -> A + B. Starting rules get no\n\
             data, and joints that attach separately built submodels are not counted.\n\
             Statements: part ID; start ID; rule A B ROT up|down DX DY WEIGHT, with B\n\
             turned by ROT relative to A and its corner DX, DY studs from A's\n\
             (see rules/default.rules).",
        );
        if let Some(w) = self.rules.unseen() {
            let _ = write!(
                h,
                "\nRules no build used are allowed too, each as if seen {w} times\n\
                 (`unseen`), so the search can still join any voxel a stud reaches."
            );
        }
        self.rules.to_text(&h)
    }

    /// "N rules, total count T, counts from MIN to MAX".
    fn totals(&self) -> String {
        let mut s = format!(
            "{}, total count {}",
            plural(self.distinct(), "rule"),
            thousands(self.total())
        );
        if let Some((lo, hi)) = self.count_range() {
            let _ = write!(s, ", counts from {lo} to {hi}");
        }
        s
    }

    /// A few lines for the terminal: what was read, what was skipped, and
    /// the totals beside the paper's.
    pub fn summary(&self) -> String {
        let r = &self.report;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "read {} ({}): {}, {} of catalog parts, {} skipped",
            plural(r.builds.len(), "build"),
            plural(r.submodel_builds, "separately built submodel"),
            plural(r.pieces, "piece"),
            thousands(r.learned_pieces as u64),
            thousands((r.pieces - r.learned_pieces) as u64)
        );
        let unknown = r.pieces - r.learned_pieces - r.tilted - r.off_grid;
        let _ = writeln!(
            s,
            "  skipped: {} not in the catalog, {} tilted, {} off the grid; \
             {} read as parts (definitions packed in the files)",
            thousands(unknown as u64),
            thousands(r.tilted as u64),
            thousands(r.off_grid as u64),
            plural(r.packed_parts, "part definition")
        );
        for b in r.per_build.iter().filter(|b| b.skipped() > 0) {
            let mut why = Vec::new();
            if b.unknown > 0 {
                why.push(format!("{} not in the catalog", b.unknown));
            }
            if let Some(line) = b.first_tilted {
                why.push(format!("{} tilted (first at line {line})", b.tilted));
            }
            if let Some(line) = b.first_off_grid {
                why.push(format!(
                    "{} off the grid (first at line {line})",
                    b.off_grid
                ));
            }
            let _ = writeln!(
                s,
                "    {}: learned {} of {}; skipped {}",
                b.file.display(),
                thousands(b.learned as u64),
                thousands(b.pieces as u64),
                why.join(", ")
            );
        }
        for (file, why) in &r.empty_builds {
            let _ = writeln!(s, "    {}: skipped whole: {why}", file.display());
        }
        if !r.skipped.is_empty() {
            s.push_str("  skipped, not in the catalog:\n");
            for k in r.skipped.iter().take(SKIPPED_LISTED) {
                let _ = writeln!(
                    s,
                    "  {:>6} x {:<10} first at {}:{}",
                    k.count,
                    k.part,
                    k.first.file.display(),
                    k.first.line
                );
            }
            if r.skipped.len() > SKIPPED_LISTED {
                let _ = writeln!(
                    s,
                    "  ... and {} more parts",
                    r.skipped.len() - SKIPPED_LISTED
                );
            }
        }
        let _ = writeln!(
            s,
            "  pieces joined to nothing earlier (starting rules, no data): {}; \
             joints attaching separate submodels (not counted): {}",
            thousands(r.starts as u64),
            thousands(r.attachments)
        );
        let _ = writeln!(
            s,
            "  pieces mapped onto layers of {} LDU (the rules hold at any layer height)",
            r.layer_ldu
        );
        let (p_rules, p_total, p_min, p_max) = PAPER_FIGURES;
        let range = match self.count_range() {
            Some((lo, hi)) => format!("{lo} to {hi}"),
            None => "-".into(),
        };
        let rows = [
            ("", "learned".to_string(), "paper".to_string()),
            (
                "distinct rules",
                thousands(self.distinct() as u64),
                thousands(p_rules),
            ),
            ("total count", thousands(self.total()), thousands(p_total)),
            ("counts", range, format!("{p_min} to {p_max}")),
        ];
        for (what, ours, paper) in rows {
            let _ = writeln!(s, "  {what:<16}{ours:>12}{paper:>12}");
        }
        s
    }
}

/// One build's credit: `NAME: by AUTHOR, AUTHOR; LICENCE`, the parts its
/// file does not name left out.
fn credit_line(c: &Credit) -> String {
    let mut line = match c.file.file_name() {
        Some(n) => n.to_string_lossy().into_owned(),
        None => c.file.display().to_string(),
    };
    if !c.authors.is_empty() {
        let _ = write!(line, ": by {}", c.authors.join(", "));
    }
    if let Some(l) = &c.licence {
        line.push_str(if c.authors.is_empty() { ": " } else { "; " });
        line.push_str(l);
    }
    line
}

/// `n thing` or `n things`.
fn plural(n: usize, thing: &str) -> String {
    plural_u64(n as u64, thing)
}

/// `n thing` or `n things`.
fn plural_u64(n: u64, thing: &str) -> String {
    if n == 1 {
        format!("1 {thing}")
    } else {
        format!("{} {thing}s", thousands(n))
    }
}

/// `n` with commas between thousands, as the paper writes 2,484.
fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests;
