//! Reading LDraw models and mapping them back onto the grid.
//!
//! Reading happens in two passes, so each can stay simple:
//!
//! 1. [`parse_ldr`] checks every line and splits the text into sections: the
//!    whole file for a plain `.ldr`, or one section per `0 FILE` for an MPD.
//!    It then flattens the main section (the first `FILE`), expanding
//!    references to sections of the same file with their transforms composed
//!    and colour 16 ("the parent's colour") resolved. The result is an
//!    [`LdrModel`]: a flat list of part references in file order, each with
//!    its step, the line it came from and the submodel [`Instance`] it
//!    belongs to (so a caller can tell separately built submodels apart).
//!    Any part name is accepted here.
//! 2. [`to_assembly`] maps each reference to a catalog part, a quarter-turn
//!    [`Rot`] and a grid cell, the inverse of [`super::write_ldr`], and
//!    rejects what does not fit: unknown parts, tilted parts, positions off
//!    the stud grid. [`to_placement`] does the same for one reference,
//!    without the shift and with the piece's bottom in LDU (`brickwright
//!    learn` maps its builds with it).
//!
//! Every error names `file:line`; garbage input gives an error, never a
//! panic.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::assembly::{Assembly, Placed, Placement, Step};
use crate::catalog::{Color, Family, PartKind};
use crate::geom::{Cell, Rot};

use super::{origin_offset, rot_matrix, LdrError, LDU_PER_PLATE, LDU_PER_STUD};

/// Most references (parts and submodels) one file may expand to.
const MAX_EXPANDED: usize = 1_000_000;

/// Largest coordinate, in LDU, that [`to_assembly`] accepts (50,000 studs).
const MAX_ABS_LDU: f64 = 1.0e6;

/// How far, in LDU, a coordinate may stray from the grid and still count as
/// on it (editors write rounded decimals).
const GRID_TOLERANCE_LDU: f64 = 0.01;

/// How far a matrix entry may stray from 0, 1 or -1.
const MATRIX_TOLERANCE: f64 = 1e-3;

/// The colour code meaning "the colour of the referencing line".
const INHERIT_COLOUR: Color = Color(16);

/// The finest vertical step, in LDU, a piece may sit at: half a plate.
const Y_GRID_LDU: f64 = 4.0;

/// `0 Author:` lines kept a section, and distinct authors a model; more
/// are ignored.
const MAX_AUTHORS: usize = 16;

/// Characters kept of an `0 Author:` or `0 !LICENSE` line.
const MAX_CREDIT_CHARS: usize = 200;

/// One part reference of a flattened model.
#[derive(Debug, Clone, PartialEq)]
pub struct PartRef {
    /// Index of the step, counted from 0 by the `0 STEP` lines of the main
    /// model before the reference (or before the submodel reference that
    /// brought it in).
    pub step: usize,
    /// The LDraw colour, with 16 resolved to the referencing submodel's
    /// colour (it stays 16 in the main model).
    pub color: Color,
    /// Position of the part's origin in the main model, in LDU.
    pub pos: [f64; 3],
    /// Row-major orientation matrix in the main model (`world = M·local +
    /// pos`).
    pub matrix: [[f64; 3]; 3],
    /// The part file name as written, e.g. `3001.dat`.
    pub part: String,
    /// 1-based line of the type-1 line that names the part.
    pub line: usize,
    /// The submodel instance the reference belongs to directly: an index
    /// into [`LdrModel::instances`], 0 for the main model.
    pub instance: usize,
}

/// One expansion of a model: the main model, or one reference to a
/// submodel (two references to the same submodel are two instances).
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// The instance whose model references this one; `None` for the main
    /// model.
    pub parent: Option<usize>,
    /// The submodel's name as the reference writes it (empty for the main
    /// model).
    pub name: String,
    /// 1-based line of the reference (0 for the main model).
    pub line: usize,
}

/// A parsed and flattened LDraw model.
#[derive(Debug, Clone, PartialEq)]
pub struct LdrModel {
    /// The file the model came from (used in error messages).
    pub path: PathBuf,
    /// Part references in file order, submodels expanded in place.
    pub parts: Vec<PartRef>,
    /// Every model instance, in the order they were expanded: the main
    /// model first, then each submodel reference depth first.
    pub instances: Vec<Instance>,
    /// Part definitions packed inside the file (`0 FILE` sections marked
    /// `0 !LDRAW_ORG Part`, `Subpart`, `Primitive`, ...): never expanded,
    /// a reference to one is a part reference.
    pub packed_parts: usize,
    /// The authors its model sections name (`0 Author:` lines outside
    /// packed part definitions), each once, in file order, at most 16.
    pub authors: Vec<String>,
    /// The licence its model sections state (the first `0 !LICENSE` line
    /// outside packed part definitions), if any.
    pub licence: Option<String>,
}

/// Reads and parses the LDraw (`.ldr` or `.mpd`) file at `path`.
///
/// Bytes that are not UTF-8 (old files use Latin-1 in comments) are replaced
/// rather than rejected; a NUL byte marks the file as binary and is an error.
pub fn read_ldr(path: &Path) -> Result<LdrModel, LdrError> {
    let bytes = std::fs::read(path).map_err(|source| LdrError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse_ldr(&String::from_utf8_lossy(&bytes), path)
}

/// Parses LDraw text; `path` is only used to name the file in errors.
///
/// Line types 2 to 5 (geometry) are checked to be line types and otherwise
/// ignored, as are type-0 comments and meta commands other than `STEP`,
/// `ROTSTEP`, `FILE` and `NOFILE`.
pub fn parse_ldr(text: &str, path: &Path) -> Result<LdrModel, LdrError> {
    let file = parse_sections(text, path)?;
    let mut parts = Vec::new();
    let mut instances = vec![Instance {
        parent: None,
        name: String::new(),
        line: 0,
    }];
    let mut flat = Flattener {
        file: &file,
        path,
        out: &mut parts,
        instances: &mut instances,
        expanded: 0,
        open: (0..file.sections.len()).map(|i| i == file.main).collect(),
    };
    let mut step = 0;
    for cmd in &file.sections[file.main].cmds {
        match cmd {
            Cmd::Step => step += 1,
            Cmd::Ref(r) => flat.expand(r, &Xform::IDENTITY, INHERIT_COLOUR, step, 0)?,
        }
    }
    let models = || file.sections.iter().filter(|s| !s.part);
    let mut authors: Vec<String> = Vec::new();
    for a in models().flat_map(|s| &s.authors) {
        if authors.len() < MAX_AUTHORS && !authors.contains(a) {
            authors.push(a.clone());
        }
    }
    Ok(LdrModel {
        path: path.to_path_buf(),
        parts,
        instances,
        packed_parts: file.sections.iter().filter(|s| s.part).count(),
        authors,
        licence: models().find_map(|s| s.licence.clone()),
    })
}

/// Maps a model onto the brick grid: every reference becomes a catalog part
/// at a grid cell with a quarter-turn rotation.
///
/// The cells are translated so that the lowest x, y and z over all pieces
/// are 0. Steps are renumbered 1, 2, 3, ... in order, skipping steps with no
/// pieces. The layers are as high as the pieces allow: a brick (24 LDU)
/// for bricks on brick layers, 12 LDU with slopes or bricks offset by half
/// a brick, 8 with plates, 4 with both.
pub fn to_assembly(model: &LdrModel) -> Result<Assembly, LdrError> {
    let mut raw = Vec::with_capacity(model.parts.len());
    for r in &model.parts {
        raw.push((to_placement(r, &model.path)?, r.step, r.color));
    }
    let low = raw.iter().map(|(p, _, _)| p.origin.z).min().unwrap_or(0);
    let layer_ldu = layer_ldu_of(raw.iter().map(|(p, _, _)| p));
    for (p, _, _) in &mut raw {
        // The reader leaves the bottom in LDU; make it a layer index.
        p.origin.z = (p.origin.z - low) / layer_ldu;
    }
    let lo = raw
        .iter()
        .fold(Cell::new(i32::MAX, i32::MAX, i32::MAX), |m, (p, _, _)| {
            Cell::new(
                m.x.min(p.origin.x),
                m.y.min(p.origin.y),
                m.z.min(p.origin.z),
            )
        });
    let mut pieces = Vec::with_capacity(raw.len());
    let mut step = 0;
    let mut last_raw_step = None;
    for (mut placement, raw_step, color) in raw {
        if last_raw_step != Some(raw_step) {
            step += 1;
            last_raw_step = Some(raw_step);
        }
        placement.origin = placement.origin.offset(-lo.x, -lo.y, -lo.z);
        pieces.push(Placed {
            placement,
            step: Step(step),
            color,
        });
    }
    Ok(Assembly { pieces, layer_ldu })
}

/// The height in LDU of the layers that `pieces`, as [`to_placement`] gives
/// them (`z` the bottom in LDU), fit on: the largest that divides a brick
/// (24 LDU), every piece's height and every bottom's height above the
/// lowest. A brick for bricks on brick courses, 12 or 4 LDU for bricks half
/// a brick apart or with slopes (whose faces need half-brick layers), 8 once
/// plates appear; 24 for no pieces.
pub fn layer_ldu_of<'a>(pieces: impl Iterator<Item = &'a Placement> + Clone) -> i32 {
    let low = pieces.clone().map(|p| p.origin.z).min().unwrap_or(0);
    let slopes = pieces
        .clone()
        .any(|p| p.part.spec().family() == Family::Slope);
    let g = pieces.fold(24, |g, p| {
        gcd(gcd(g, p.part.spec().height_ldu()), p.origin.z - low)
    });
    // A slope's sloping face needs layers half a brick high at most.
    if slopes && g == 24 {
        12
    } else {
        g
    }
}

fn gcd(a: i32, b: i32) -> i32 {
    if b == 0 {
        a.abs()
    } else {
        gcd(b, a % b)
    }
}

/// One reference's catalog part, rotation and raw (unshifted) grid cell,
/// with the height of its bottom above LDraw's `Y = 0`, in LDU, as `z`
/// (a multiple of 4: pieces stand on a half-plate grid). `path` names the
/// file in errors.
///
/// [`to_assembly`] turns `z` into a layer index once it knows the layer
/// height of the whole model; `brickwright learn` does the same over all
/// its builds.
///
/// Errors if the part is not in the catalog, is not turned by a quarter turn
/// about the vertical axis, or does not sit on the stud grid and the
/// half-plate grid.
pub fn to_placement(r: &PartRef, path: &Path) -> Result<Placement, LdrError> {
    let kind = PartKind::from_id(&r.part).ok_or_else(|| LdrError::UnknownPart {
        path: path.to_path_buf(),
        line: r.line,
        part: r.part.clone(),
    })?;
    let rot = rot_from_matrix(&r.matrix).ok_or_else(|| LdrError::NotQuarterTurn {
        path: path.to_path_buf(),
        line: r.line,
        part: r.part.clone(),
        matrix: Box::new(r.matrix),
    })?;
    let spec = kind.spec();
    let (sx, sy) = spec.footprint(rot);
    let stud = f64::from(LDU_PER_STUD);
    let (ox, oz) = origin_offset(kind, rot);
    let centre = [r.pos[0] - ox as f64, r.pos[2] - oz as f64];
    let height = f64::from(LDU_PER_PLATE) * f64::from(spec.height_plates);
    let off_grid = |axis: char, value: f64, why: String| LdrError::OffGrid {
        path: path.to_path_buf(),
        line: r.line,
        part: r.part.clone(),
        axis,
        value,
        why,
    };
    let turned = format!("{} turned {}", spec.id, rot.name());
    let x = grid_index(centre[0] - stud / 2.0 * f64::from(sx), stud).map_err(|far| {
        off_grid(
            'X',
            r.pos[0],
            if far {
                format!("is too far from the origin (over {MAX_ABS_LDU} LDU)")
            } else {
                format!("but {turned} must sit at X = 20*n + {}", 10 * sx)
            },
        )
    })?;
    let y = grid_index(centre[1] - stud / 2.0 * f64::from(sy), stud).map_err(|far| {
        off_grid(
            'Z',
            r.pos[2],
            if far {
                format!("is too far from the origin (over {MAX_ABS_LDU} LDU)")
            } else {
                format!("but {turned} must sit at Z = 20*n + {}", 10 * sy)
            },
        )
    })?;
    let z = grid_index(-r.pos[1] - height, Y_GRID_LDU).map_err(|far| {
        off_grid(
            'Y',
            r.pos[1],
            if far {
                format!("is too far from the origin (over {MAX_ABS_LDU} LDU)")
            } else {
                format!(
                    "but {} must sit at Y = -(4*n + {height}) to stand on the plate grid",
                    spec.id
                )
            },
        )
    })?;
    Ok(Placement::new(
        kind,
        Cell::new(x, y, z * Y_GRID_LDU as i32),
        rot,
    ))
}

/// `v / unit` as an integer if `v` is within the tolerance of a multiple of
/// `unit`; `Err(true)` if `v` is too large, `Err(false)` if off the grid.
fn grid_index(v: f64, unit: f64) -> Result<i32, bool> {
    if !v.is_finite() || v.abs() > MAX_ABS_LDU {
        return Err(true);
    }
    let n = (v / unit).round();
    if (v - n * unit).abs() > GRID_TOLERANCE_LDU {
        return Err(false);
    }
    Ok(n as i32)
}

/// The quarter turn whose matrix is `m`, within [`MATRIX_TOLERANCE`].
fn rot_from_matrix(m: &[[f64; 3]; 3]) -> Option<Rot> {
    Rot::ALL.into_iter().find(|&r| {
        let q = rot_matrix(r);
        (0..3).all(|i| (0..3).all(|j| (m[i][j] - f64::from(q[i][j])).abs() <= MATRIX_TOLERANCE))
    })
}

/// A placement transform: `world = m·local + t`.
#[derive(Debug, Clone, Copy)]
struct Xform {
    m: [[f64; 3]; 3],
    t: [f64; 3],
}

impl Xform {
    const IDENTITY: Xform = Xform {
        m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        t: [0.0; 3],
    };

    /// `self` applied after `inner`: the transform of a child placed by
    /// `inner` inside a model placed by `self`.
    fn compose(&self, inner: &Xform) -> Xform {
        let row = |i: usize, v: [f64; 3]| (0..3).map(|k| self.m[i][k] * v[k]).sum::<f64>();
        let column = |j: usize| [inner.m[0][j], inner.m[1][j], inner.m[2][j]];
        Xform {
            m: [0, 1, 2].map(|i| [0, 1, 2].map(|j| row(i, column(j)))),
            t: [0, 1, 2].map(|i| row(i, inner.t) + self.t[i]),
        }
    }
}

/// A command of a section that matters for the model.
#[derive(Debug)]
enum Cmd {
    Step,
    Ref(RawRef),
}

/// A type-1 line as written.
#[derive(Debug)]
struct RawRef {
    line: usize,
    color: Color,
    xform: Xform,
    name: String,
}

/// One model of the file: the whole file, or one `0 FILE` of an MPD.
#[derive(Debug, Default)]
struct Section {
    cmds: Vec<Cmd>,
    /// The section defines a part (`0 !LDRAW_ORG Part`, `Subpart`,
    /// `Primitive`, ...), as packed files inline the official parts they
    /// use: a reference to it is a part, not a submodel.
    part: bool,
    /// Its `0 Author:` lines, as written.
    authors: Vec<String>,
    /// Its first `0 !LICENSE` line, as written.
    licence: Option<String>,
}

/// The sections of a file, with the main one and a lookup by name.
#[derive(Debug)]
struct File {
    sections: Vec<Section>,
    by_name: HashMap<String, usize>,
    main: usize,
}

/// Whether a `0 !LDRAW_ORG` line's type (`Part UPDATE 2004-01`,
/// `Unofficial_Subpart`, `48_Primitive`, `Shortcut`, ...) marks a part
/// definition rather than a model.
fn defines_part(kind: &str) -> bool {
    let Some((word, _)) = next_token(kind) else {
        return false;
    };
    let word = word.to_ascii_lowercase();
    let word = word.strip_prefix("unofficial_").unwrap_or(&word);
    [
        "part",
        "subpart",
        "primitive",
        "8_primitive",
        "48_primitive",
        "shortcut",
        "alias",
        "physical_colour",
    ]
    .contains(&word)
}

/// Submodel names compare case-insensitively, with either slash.
fn normalize_name(name: &str) -> String {
    name.trim().replace('\\', "/").to_ascii_lowercase()
}

/// The first whitespace-separated token of `s` and the text after it.
fn next_token(s: &str) -> Option<(&str, &str)> {
    let s = s.trim_start();
    if s.is_empty() {
        return None;
    }
    let end = s.find(char::is_whitespace).unwrap_or(s.len());
    Some(s.split_at(end))
}

/// At most 40 characters of `s`, for error messages.
fn excerpt(s: &str) -> String {
    let mut e: String = s.chars().take(40).collect();
    if e.len() < s.len() {
        e.push_str("...");
    }
    e
}

/// Pass 1: checks every line and sorts the commands into sections.
fn parse_sections(text: &str, path: &Path) -> Result<File, LdrError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Lines before the first `0 FILE` (the whole file if there is none).
    let mut preamble = Section::default();
    let mut sections: Vec<Section> = Vec::new();
    let mut by_name = HashMap::new();
    // Where commands go: None after `0 NOFILE`, Some(None) for the preamble.
    let mut current: Option<Option<usize>> = Some(None);
    for (i, raw_line) in text.split('\n').enumerate() {
        let line_no = i + 1;
        let line = raw_line.strip_suffix('\r').unwrap_or(raw_line);
        if line.contains('\0') {
            return Err(LdrError::NotLdraw {
                path: path.to_path_buf(),
                line: line_no,
                what: "binary data (a NUL byte)".into(),
            });
        }
        let Some((kind, rest)) = next_token(line) else {
            continue; // blank line
        };
        let cmd = match kind.parse::<u8>() {
            Ok(0) => match next_token(rest) {
                Some((word, name)) if word.eq_ignore_ascii_case("FILE") => {
                    sections.push(Section::default());
                    let idx = sections.len() - 1;
                    by_name.entry(normalize_name(name)).or_insert(idx);
                    current = Some(Some(idx));
                    continue;
                }
                Some((word, _)) if word.eq_ignore_ascii_case("NOFILE") => {
                    current = None;
                    continue;
                }
                Some((word, kind)) if word.eq_ignore_ascii_case("!LDRAW_ORG") => {
                    if let (Some(Some(idx)), true) = (current, defines_part(kind)) {
                        sections[idx].part = true;
                    }
                    continue;
                }
                Some((word, said))
                    if word.eq_ignore_ascii_case("Author:")
                        || word.eq_ignore_ascii_case("!LICENSE") =>
                {
                    let said: String = said.trim().chars().take(MAX_CREDIT_CHARS).collect();
                    let section = match current {
                        Some(Some(idx)) => &mut sections[idx],
                        Some(None) => &mut preamble,
                        None => continue,
                    };
                    if said.is_empty() {
                        continue;
                    }
                    if word.eq_ignore_ascii_case("!LICENSE") {
                        section.licence.get_or_insert(said);
                    } else if section.authors.len() < MAX_AUTHORS {
                        section.authors.push(said);
                    }
                    continue;
                }
                Some((word, _))
                    if word.eq_ignore_ascii_case("STEP")
                        || word.eq_ignore_ascii_case("ROTSTEP") =>
                {
                    Cmd::Step
                }
                _ => continue, // comment or other meta command
            },
            Ok(1) => Cmd::Ref(parse_ref(rest, path, line_no)?),
            Ok(2..=5) => continue,
            _ => {
                return Err(LdrError::NotLdraw {
                    path: path.to_path_buf(),
                    line: line_no,
                    what: format!(
                        "a line starting with `{}` (LDraw lines start with a line type 0 to 5)",
                        excerpt(kind)
                    ),
                })
            }
        };
        match current {
            Some(Some(idx)) => sections[idx].cmds.push(cmd),
            Some(None) => preamble.cmds.push(cmd),
            None => {}
        }
    }
    if sections.is_empty() {
        sections.push(preamble);
    }
    // The main model is a model even if it says otherwise.
    sections[0].part = false;
    Ok(File {
        sections,
        by_name,
        main: 0,
    })
}

/// Field names of a type-1 line after the line type, for error messages.
const REF_FIELDS: [&str; 13] = [
    "x", "y", "z", "matrix a", "matrix b", "matrix c", "matrix d", "matrix e", "matrix f",
    "matrix g", "matrix h", "matrix i", "",
];

/// Parses the fields of a type-1 line after its line type.
fn parse_ref(mut rest: &str, path: &Path, line: usize) -> Result<RawRef, LdrError> {
    let too_few = |found: usize| LdrError::TooFewFields {
        path: path.to_path_buf(),
        line,
        kind: 1,
        needed: 15,
        found,
    };
    let bad = |field: &'static str, text: &str| LdrError::BadNumber {
        path: path.to_path_buf(),
        line,
        field,
        text: excerpt(text),
    };
    let (tok, r) = next_token(rest).ok_or_else(|| too_few(1))?;
    rest = r;
    let color = tok
        .parse::<u16>()
        .map(Color)
        .map_err(|_| bad("colour", tok))?;
    let mut nums = [0.0f64; 12];
    for (k, slot) in nums.iter_mut().enumerate() {
        let (tok, r) = next_token(rest).ok_or_else(|| too_few(2 + k))?;
        rest = r;
        *slot = tok
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(REF_FIELDS[k], tok))?;
    }
    let name = rest.trim();
    if name.is_empty() {
        return Err(too_few(14));
    }
    Ok(RawRef {
        line,
        color,
        xform: Xform {
            m: [
                [nums[3], nums[4], nums[5]],
                [nums[6], nums[7], nums[8]],
                [nums[9], nums[10], nums[11]],
            ],
            t: [nums[0], nums[1], nums[2]],
        },
        name: name.to_string(),
    })
}

/// Pass 2: expands submodel references depth first into part references.
///
/// The expansion keeps its own stack of open submodels rather than
/// recursing, so however deep a file nests its submodels, the program's
/// stack does not grow with it.
struct Flattener<'a> {
    file: &'a File,
    path: &'a Path,
    out: &'a mut Vec<PartRef>,
    /// The model instances met so far; see [`LdrModel::instances`].
    instances: &'a mut Vec<Instance>,
    /// References expanded so far, against [`MAX_EXPANDED`].
    expanded: usize,
    /// Sections being expanded, by section index, to catch a submodel that
    /// contains itself.
    open: Vec<bool>,
}

/// A submodel being expanded: its remaining commands and its placement.
struct Frame<'a> {
    section: usize,
    cmds: std::slice::Iter<'a, Cmd>,
    xf: Xform,
    color: Color,
    instance: usize,
}

impl<'a> Flattener<'a> {
    /// Expands `r`, found inside model instance `instance` placed by
    /// `parent` in `color`, at main-model step `step`.
    fn expand(
        &mut self,
        r: &RawRef,
        parent: &Xform,
        color: Color,
        step: usize,
        instance: usize,
    ) -> Result<(), LdrError> {
        let mut frames: Vec<Frame<'a>> = Vec::new();
        frames.extend(self.enter(r, parent, color, step, instance)?);
        while let Some(top) = frames.last_mut() {
            match top.cmds.next() {
                Some(Cmd::Ref(child)) => {
                    let (xf, color, me) = (top.xf, top.color, top.instance);
                    let inner = self.enter(child, &xf, color, step, me)?;
                    frames.extend(inner);
                }
                Some(Cmd::Step) => {}
                None => {
                    self.open[top.section] = false;
                    frames.pop();
                }
            }
        }
        Ok(())
    }

    /// Places `r`: a part goes to the output; a submodel opens a new
    /// [`Frame`] for its commands.
    fn enter(
        &mut self,
        r: &RawRef,
        parent: &Xform,
        color: Color,
        step: usize,
        instance: usize,
    ) -> Result<Option<Frame<'a>>, LdrError> {
        self.expanded += 1;
        if self.expanded > MAX_EXPANDED {
            return Err(LdrError::TooLarge {
                path: self.path.to_path_buf(),
                line: r.line,
                limit: MAX_EXPANDED,
            });
        }
        let xf = parent.compose(&r.xform);
        let color = if r.color == INHERIT_COLOUR {
            color
        } else {
            r.color
        };
        let file: &'a File = self.file;
        let sub = file
            .by_name
            .get(&normalize_name(&r.name))
            .copied()
            .filter(|&i| !file.sections[i].part);
        let Some(sub) = sub else {
            self.out.push(PartRef {
                step,
                color,
                pos: xf.t,
                matrix: xf.m,
                part: r.name.clone(),
                line: r.line,
                instance,
            });
            return Ok(None);
        };
        if self.open[sub] {
            return Err(LdrError::Recursion {
                path: self.path.to_path_buf(),
                line: r.line,
                name: r.name.clone(),
            });
        }
        self.open[sub] = true;
        self.instances.push(Instance {
            parent: Some(instance),
            name: r.name.clone(),
            line: r.line,
        });
        Ok(Some(Frame {
            section: sub,
            cmds: file.sections[sub].cmds.iter(),
            xf,
            color,
            instance: self.instances.len() - 1,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<LdrModel, LdrError> {
        parse_ldr(text, Path::new("t.ldr"))
    }

    #[test]
    fn a_packed_part_definition_is_a_part_not_a_submodel() {
        let text = "0 FILE main.ldr\n\
            1 4 0 -24 0 1 0 0 0 1 0 0 0 1 3001.dat\n\
            1 4 0 -48 0 1 0 0 0 1 0 0 0 1 sub.ldr\n\
            0 FILE sub.ldr\n\
            1 4 0 0 0 1 0 0 0 1 0 0 0 1 3003.dat\n\
            0 FILE 3001.dat\n\
            0 !LDRAW_ORG Part UPDATE 2004-03\n\
            1 16 0 0 0 1 0 0 0 1 0 0 0 1 stud.dat\n\
            0 FILE 3003.dat\n\
            0 !LDRAW_ORG Unofficial_Part\n\
            1 16 0 0 0 1 0 0 0 1 0 0 0 1 s/3003s01.dat\n";
        let m = parse(text).unwrap();
        let names: Vec<&str> = m.parts.iter().map(|p| p.part.as_str()).collect();
        assert_eq!(names, ["3001.dat", "3003.dat"]);
        assert_eq!(m.packed_parts, 2);
        // The submodel is still a separate instance.
        assert_eq!(m.instances.len(), 2);
    }

    #[test]
    fn mpd_flattens_submodels_at_the_referencing_step() {
        let text = "\
0 FILE main.ldr
0 Main
1 4 0 -24 0 1 0 0 0 1 0 0 0 1 3001.dat
0 STEP
1 4 100 -24 0 0 0 -1 0 1 0 1 0 0 Sub.ldr
0 STEP
0 NOFILE
0 FILE sub.ldr
1 16 40 0 20 1 0 0 0 1 0 0 0 1 3001.dat
0 STEP
1 2 0 -24 0 1 0 0 0 1 0 0 0 1 3005.dat
0 NOFILE
";
        let m = parse(text).unwrap();
        assert_eq!(m.parts.len(), 3);
        assert_eq!(m.parts[0].step, 0);
        // Both sub parts at main step 1; the 1x1 keeps its own colour.
        assert_eq!(
            m.parts[1..]
                .iter()
                .map(|p| (p.step, p.color.0, p.line))
                .collect::<Vec<_>>(),
            [(1, 4, 9), (1, 2, 11)]
        );
        // Child (40, 0, 20) turned R90 about (100, -24, 0): (100-20, -24, 40).
        assert_eq!(m.parts[1].pos, [80.0, -24.0, 40.0]);
        assert_eq!(
            m.parts[1].matrix,
            [[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
        );
        assert_eq!(m.parts[2].pos, [100.0, -48.0, 0.0]);
    }

    #[test]
    fn each_submodel_reference_is_a_new_instance() {
        let text = "\
0 FILE main.ldr
1 4 0 -24 0 1 0 0 0 1 0 0 0 1 3001.dat
1 4 0 -48 0 1 0 0 0 1 0 0 0 1 wall.ldr
1 4 0 -96 0 1 0 0 0 1 0 0 0 1 wall.ldr
0 FILE wall.ldr
1 16 0 0 0 1 0 0 0 1 0 0 0 1 3004.dat
1 16 0 0 0 1 0 0 0 1 0 0 0 1 post.ldr
0 FILE post.ldr
1 16 0 0 0 1 0 0 0 1 0 0 0 1 3005.dat
";
        let m = parse(text).unwrap();
        let seen: Vec<(&str, usize)> = m
            .parts
            .iter()
            .map(|p| (p.part.as_str(), p.instance))
            .collect();
        assert_eq!(
            seen,
            [
                ("3001.dat", 0),
                ("3004.dat", 1),
                ("3005.dat", 2),
                ("3004.dat", 3),
                ("3005.dat", 4)
            ]
        );
        let chain: Vec<(Option<usize>, &str, usize)> = m
            .instances
            .iter()
            .map(|i| (i.parent, i.name.as_str(), i.line))
            .collect();
        assert_eq!(
            chain,
            [
                (None, "", 0),
                (Some(0), "wall.ldr", 3),
                (Some(1), "post.ldr", 7),
                (Some(0), "wall.ldr", 4),
                (Some(3), "post.ldr", 7)
            ]
        );
    }

    #[test]
    fn self_reference_is_an_error_with_its_line() {
        let text = "0 FILE a.ldr\n1 4 0 0 0 1 0 0 0 1 0 0 0 1 b.ldr\n0 FILE b.ldr\n\
                    1 4 0 0 0 1 0 0 0 1 0 0 0 1 a.ldr\n";
        let e = parse(text).unwrap_err();
        assert!(matches!(e, LdrError::Recursion { line: 4, .. }), "{e}");
        assert!(
            e.to_string().starts_with("t.ldr:4: submodel `a.ldr`"),
            "{e}"
        );
    }

    #[test]
    fn exponential_nesting_is_cut_off() {
        let mut text = String::from("0 FILE m0\n");
        for i in 0..40 {
            text += &format!(
                "1 4 0 0 0 1 0 0 0 1 0 0 0 1 m{0}\n1 4 0 0 0 1 0 0 0 1 0 0 0 1 m{0}\n0 FILE m{0}\n",
                i + 1
            );
        }
        assert!(matches!(parse(&text), Err(LdrError::TooLarge { .. })));
    }

    #[test]
    fn a_100000_deep_chain_of_submodels_is_read_without_recursion() {
        // m0 holds m1, which holds m2, ... down to a brick: the depth is
        // set by the file, so the reader must not recurse on it.
        const DEPTH: usize = 100_000;
        let mut text = String::new();
        for i in 0..DEPTH {
            text += &format!("0 FILE m{i}\n1 16 0 -24 0 1 0 0 0 1 0 0 0 1 m{}\n", i + 1);
        }
        text += &format!("0 FILE m{DEPTH}\n1 4 0 -24 0 1 0 0 0 1 0 0 0 1 3001.dat\n");
        // On a small thread stack, as a recursive reader would overflow it.
        let m = std::thread::Builder::new()
            .stack_size(256 * 1024)
            .spawn(move || parse(&text).unwrap())
            .unwrap()
            .join()
            .unwrap();
        assert_eq!(m.parts.len(), 1);
        assert_eq!(m.instances.len(), DEPTH + 1);
        assert_eq!(m.parts[0].pos[1], -24.0 * (DEPTH + 1) as f64);
        // A cycle at the bottom of the chain is still found.
        let mut text = String::new();
        for i in 0..1000 {
            text += &format!("0 FILE m{i}\n1 16 0 0 0 1 0 0 0 1 0 0 0 1 m{}\n", i + 1);
        }
        text += "0 FILE m1000\n1 16 0 0 0 1 0 0 0 1 0 0 0 1 m500\n";
        assert!(matches!(parse(&text), Err(LdrError::Recursion { .. })));
    }

    #[test]
    fn name_may_contain_spaces_and_line_types_are_checked() {
        let m = parse("1 4 0 0 0 1 0 0 0 1 0 0 0 1 my part.dat  \r\n2 24 0 0 0 1 1 1\n").unwrap();
        assert_eq!(m.parts[0].part, "my part.dat");
        let e = parse("0 ok\nhello world\n").unwrap_err();
        assert!(e.to_string().starts_with("t.ldr:2: not LDraw text"), "{e}");
        assert!(parse("7 1 2 3\n").is_err());
    }

    #[test]
    fn field_errors_name_the_field() {
        let e = parse("1 4 0 zero 0 1 0 0 0 1 0 0 0 1 3001.dat").unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.ldr:1: bad y: expected a number, found `zero`"
        );
        let e = parse("\n1 4 0 0 0 1 0 0").unwrap_err();
        assert!(
            matches!(
                e,
                LdrError::TooFewFields {
                    line: 2,
                    found: 8,
                    ..
                }
            ),
            "{e}"
        );
        let e = parse("1 4 0 0 0 1 0 0 0 1 0 0 0 1").unwrap_err();
        assert!(matches!(e, LdrError::TooFewFields { found: 14, .. }), "{e}");
        assert!(parse("1 0x2FF0000 0 0 0 1 0 0 0 1 0 0 0 1 3001.dat").is_err());
        assert!(parse("1 4 NaN 0 0 1 0 0 0 1 0 0 0 1 3001.dat").is_err());
        assert!(parse("1 4 inf 0 0 1 0 0 0 1 0 0 0 1 3001.dat").is_err());
    }

    #[test]
    fn matrices_near_a_quarter_turn_are_accepted() {
        let m = [[0.0, 0.0, -0.9999], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0001]];
        assert_eq!(rot_from_matrix(&m), Some(Rot::R90));
        let mirrored = [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(rot_from_matrix(&mirrored), None);
        let upside_down = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];
        assert_eq!(rot_from_matrix(&upside_down), None);
    }
}
