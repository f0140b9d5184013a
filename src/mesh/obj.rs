//! Wavefront OBJ: a line-based text format (`v x y z`, `f 1 2 3 ...`).
//!
//! `tobj` does the reading (polygons triangulated, every object and group
//! merged), but its errors carry no line numbers. So the text is first
//! checked here, line by line, for the mistakes users actually hit — a
//! vertex with a non-numeric, NaN or infinite coordinate, a face with fewer
//! than three corners or an index past the vertex list, binary content — and
//! those are reported as `file.obj:17: ...`. Only what gets past that check
//! is handed to `tobj`.

use std::borrow::Cow;
use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use glam::Vec3;
use rayon::prelude::*;

use super::mtl::{self, MtlMaterial};
use super::paint::{inside_folder, read_side_file, srgb_to_linear, TextureBudget, MAX_SIDE_FILE};
use super::{finish, FacePaint, Location, Material, Mesh, MeshError, Paint};

/// The most skipped-line warnings given for one material library; past
/// them one line says how many more there were.
const MAX_MTL_WARNINGS: usize = 5;

/// The OBJ's materials as [`Material`]s: `Kd` (sRGB) as the base colour and
/// `map_Kd` decoded from the OBJ's folder, for the materials some face uses
/// (`used`) only. Each texture file is decoded once however many materials
/// name it, all of them under one [`TextureBudget`]. A texture that is
/// missing or cannot be decoded is a warning naming it, and `Kd` stands in.
fn obj_materials(
    path: &Path,
    folder: &Path,
    mats: &[MtlMaterial],
    used: &[bool],
    warnings: &mut Vec<String>,
) -> Paint {
    let mut paint = Paint::default();
    let mut budget = TextureBudget::default();
    let mut decoded: HashMap<PathBuf, Option<usize>> = HashMap::new();
    for (i, m) in mats.iter().enumerate() {
        let kd = m.kd.unwrap_or([1.0; 3]);
        let mut texture = None;
        if let Some(file) = m.map_kd.as_deref().filter(|_| used[i]) {
            let loaded = inside_folder(folder, file)
                .ok_or_else(|| "is outside the model's folder".to_string())
                .map(|p| p.canonicalize().unwrap_or(p));
            texture = match loaded {
                Ok(p) => match decoded.get(&p) {
                    Some(&t) => t,
                    None => {
                        let got = read_side_file(&p, MAX_SIDE_FILE).and_then(|b| budget.decode(&b));
                        let t = match got {
                            Ok(t) => {
                                paint.textures.push(t);
                                Some(paint.textures.len() - 1)
                            }
                            Err(why) => {
                                warnings.push(texture_warning(path, file, &m.name, &why));
                                None
                            }
                        };
                        decoded.insert(p, t);
                        t
                    }
                },
                Err(why) => {
                    warnings.push(texture_warning(path, file, &m.name, &why));
                    None
                }
            };
        }
        paint.materials.push(Material {
            name: m.name.clone(),
            color: kd.map(srgb_to_linear),
            texture,
            flip_v: true,
        });
    }
    paint
}

/// The warning for a texture that could not be had.
fn texture_warning(path: &Path, file: &str, material: &str, why: &str) -> String {
    format!(
        "{}: texture {file:?} of material {material:?} {why}; its Kd colour stands in",
        path.display()
    )
}

/// Reads the material libraries an OBJ names, each once (by resolved
/// path) however often `mtllib` repeats it, with our own MTL parser; the
/// materials gathered in the order `tobj` numbers them.
#[derive(Default)]
struct Libraries {
    read: HashSet<PathBuf>,
    materials: Vec<MtlMaterial>,
    warnings: Vec<String>,
}

impl Libraries {
    /// `tobj`'s material loader: the library `name` (relative to `folder`)
    /// as names only (what `usemtl` needs); its colours are kept here.
    fn load(&mut self, path: &Path, folder: &Path, name: &Path) -> tobj::MTLLoadResult {
        let shown = name.display().to_string();
        let mut warn = |why: &str| {
            self.warnings.push(format!(
                "{}: material library {shown:?} {why}; its materials are ignored",
                path.display()
            ))
        };
        let Some(file) = inside_folder(folder, &shown) else {
            warn("is outside the model's folder");
            return Ok(Default::default());
        };
        if !self
            .read
            .insert(file.canonicalize().unwrap_or(file.clone()))
        {
            return Ok(Default::default());
        }
        let lib = match read_side_file(&file, MAX_SIDE_FILE) {
            Ok(bytes) => mtl::parse(&String::from_utf8_lossy(&bytes)),
            Err(why) => {
                warn(&why);
                return Ok(Default::default());
            }
        };
        for (line, why) in lib.skipped.iter().take(MAX_MTL_WARNINGS) {
            self.warnings.push(format!(
                "{}:{line}: {why}; the line is skipped",
                file.display()
            ));
        }
        if lib.skipped.len() > MAX_MTL_WARNINGS {
            self.warnings.push(format!(
                "{}: {} more malformed lines skipped",
                file.display(),
                lib.skipped.len() - MAX_MTL_WARNINGS
            ));
        }
        let names: Vec<tobj::Material> = lib
            .materials
            .iter()
            .map(|m| tobj::Material {
                name: m.name.clone(),
                ..tobj::Material::default()
            })
            .collect();
        let map = names
            .iter()
            .enumerate()
            .map(|(i, m)| (m.name.clone(), i))
            .collect();
        self.materials.extend(lib.materials);
        Ok((names, map))
    }
}

/// Parses the OBJ text in `bytes` (read from `path`, used in messages).
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Mesh, MeshError> {
    let text = prescan(path, bytes)?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // Material libraries are read only from the OBJ's own folder; one that
    // is missing or unreadable is a warning, and its faces go uncoloured.
    let folder = path.parent().unwrap_or(Path::new("."));
    let libs = RefCell::new(Libraries::default());
    let (models, _) = tobj::load_obj_buf(&mut Joined::new(&text), &opts, |name| {
        libs.borrow_mut().load(path, folder, name)
    })
    .map_err(|e| MeshError::Malformed {
        at: Location::file(path),
        reason: format!("not a valid OBJ file ({e}); re-export it"),
    })?;
    let libs = libs.into_inner();
    let mut used = vec![false; libs.materials.len()];
    for model in &models {
        if let Some(u) = model.mesh.material_id.and_then(|i| used.get_mut(i)) {
            *u |= !model.mesh.indices.is_empty();
        }
    }
    let mut raw = Mesh {
        warnings: libs.warnings,
        ..Mesh::default()
    };
    let paint = obj_materials(path, folder, &libs.materials, &used, &mut raw.warnings);
    // A face is coloured by a material or by vertex colours; when none
    // is, the mesh has no paint (`finish` would drop it), and the faces'
    // paint is not made: a big mesh's would take 80 bytes a triangle.
    let painted = models.iter().any(|model| {
        let m = &model.mesh;
        !m.indices.is_empty()
            && (m.material_id.is_some_and(|i| i < paint.materials.len())
                || (m.vertex_color.len() == m.positions.len() && !m.vertex_color.is_empty()))
    });
    let mut faces = Vec::with_capacity(if painted {
        models.iter().map(|m| m.mesh.indices.len() / 3).sum()
    } else {
        0
    });
    for model in &models {
        let m = &model.mesh;
        let base = raw.positions.len() as u32;
        raw.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        raw.triangles.extend(
            m.indices
                .chunks_exact(3)
                .map(|c| [c[0] + base, c[1] + base, c[2] + base]),
        );
        let material = m
            .material_id
            .filter(|&i| i < paint.materials.len())
            .map(|i| i as u32);
        let has_uv = m.texcoord_indices.len() == m.indices.len() && !m.texcoords.is_empty();
        let has_vc = m.vertex_color.len() == m.positions.len() && !m.vertex_color.is_empty();
        if !painted {
            continue;
        }
        for (k, c) in m.indices.chunks_exact(3).enumerate() {
            let uv = has_uv
                .then(|| {
                    let t = &m.texcoord_indices[3 * k..3 * k + 3];
                    let get = |i: u32| {
                        let i = i as usize * 2;
                        Some([*m.texcoords.get(i)?, *m.texcoords.get(i + 1)?])
                    };
                    Some([get(t[0])?, get(t[1])?, get(t[2])?])
                })
                .flatten();
            let color = has_vc.then(|| {
                [c[0], c[1], c[2]].map(|i| {
                    let i = i as usize * 3;
                    [0, 1, 2].map(|j| {
                        super::paint::srgb_to_linear(m.vertex_color[i + j].clamp(0.0, 1.0))
                    })
                })
            });
            faces.push(FacePaint {
                material,
                uv,
                color,
            });
        }
    }
    raw.paint = painted.then_some(Paint { faces, ..paint });
    finish(path, raw)
}

/// Checks the text line by line and returns what `tobj` is to read, in
/// pieces.
///
/// Reports the first line with a bad vertex or face; `tobj` would either
/// reject those without a line number or misread them. A big file is cut
/// into pieces at statement boundaries, counted and checked in parallel:
/// each piece starts from the vertices before it, so the text handed on
/// and the first error (the earliest piece's) are those of one pass.
fn prescan(path: &Path, bytes: &[u8]) -> Result<Vec<String>, MeshError> {
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            let line = 1 + bytes[..e.valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            return Err(MeshError::Malformed {
                at: Location::line(path, line),
                reason: "not text (invalid UTF-8); is this really an OBJ file?".into(),
            });
        }
    };
    let pieces = statement_pieces(text, rayon::current_num_threads() * 4);
    // Positive face indices may refer forward, so count all vertices first.
    let counts: Vec<Counted> = pieces.par_iter().map(|p| count(p)).collect();
    let total = counts.iter().fold(Counted::default(), |a, &c| a.then(c));
    let starts = counts.iter().scan(Counted::default(), |before, &c| {
        let start = *before;
        *before = before.then(c);
        Some(start)
    });
    let checked: Vec<Result<String, MeshError>> = pieces
        .par_iter()
        .zip(starts.collect::<Vec<_>>())
        .map(|(p, start)| check(path, p, start, total))
        .collect();
    checked.into_iter().collect()
}

/// The checked pieces of a file read one after another, as one text,
/// without joining them (a copy of a big file).
struct Joined<'a> {
    pieces: &'a [String],
    /// The piece being read, and the bytes of it read.
    at: usize,
    read: usize,
}

impl<'a> Joined<'a> {
    fn new(pieces: &'a [String]) -> Self {
        Joined {
            pieces,
            at: 0,
            read: 0,
        }
    }
}

impl std::io::Read for Joined<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        use std::io::BufRead;
        let left = self.fill_buf()?;
        let n = left.len().min(buf.len());
        buf[..n].copy_from_slice(&left[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl std::io::BufRead for Joined<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        while self
            .pieces
            .get(self.at)
            .is_some_and(|p| self.read >= p.len())
        {
            self.at += 1;
            self.read = 0;
        }
        Ok(self
            .pieces
            .get(self.at)
            .map_or(&[][..], |p| &p.as_bytes()[self.read..]))
    }

    fn consume(&mut self, n: usize) {
        self.read += n;
    }
}

/// Physical lines, vertices and texture coordinates in a piece of the
/// file (or before it).
#[derive(Debug, Default, Clone, Copy)]
struct Counted {
    lines: usize,
    v: usize,
    vt: usize,
}

impl Counted {
    /// These counts followed by `o`'s.
    fn then(self, o: Counted) -> Counted {
        Counted {
            lines: self.lines + o.lines,
            v: self.v + o.v,
            vt: self.vt + o.vt,
        }
    }
}

/// The counts of `piece`.
fn count(piece: &str) -> Counted {
    let mut c = Counted {
        lines: piece.lines().count(),
        ..Counted::default()
    };
    for (_, l) in logical_lines(piece) {
        match l.split_whitespace().next() {
            Some("v") => c.v += 1,
            Some("vt") => c.vt += 1,
            _ => {}
        }
    }
    c
}

/// `text` cut into about `n` pieces of whole statements: each ends with a
/// line break that does not continue the line (`\` at its end). Pieces
/// are at least 64 KiB, so a small file is one piece.
fn statement_pieces(text: &str, n: usize) -> Vec<&str> {
    let bytes = text.as_bytes();
    let size = (bytes.len() / n.max(1)).max(1 << 16);
    let mut pieces = Vec::new();
    let mut start = 0;
    while start < bytes.len() {
        let mut end = (start + size).min(bytes.len());
        loop {
            let Some(j) = bytes[end..].iter().position(|&b| b == b'\n') else {
                end = bytes.len();
                break;
            };
            let nl = end + j;
            let line_end = if nl > 0 && bytes[nl - 1] == b'\r' {
                nl - 1
            } else {
                nl
            };
            end = nl + 1;
            if line_end == 0 || bytes[line_end - 1] != b'\\' {
                break;
            }
        }
        // A line break is one byte, so `end` is a character boundary.
        pieces.push(&text[start..end]);
        start = end;
    }
    pieces
}

/// Checks the statements of `piece`, which comes after `before` (lines,
/// vertices and texture coordinates) in a file of `total`; returns the
/// piece's text to hand on.
fn check(path: &Path, piece: &str, before: Counted, total: Counted) -> Result<String, MeshError> {
    let bad = |line: usize, reason: String| MeshError::Malformed {
        at: Location::line(path, line),
        reason,
    };
    let (total, total_vt) = (total.v, total.vt);
    let mut seen = before.v;
    let mut seen_vt = before.vt;
    // The text handed on: comments gone, continued lines joined, and face
    // corners cut to their vertex and texture indices, both checked
    // (`tobj` multiplies indices unchecked, and the mesh needs no normals).
    let mut out = String::with_capacity(piece.len());
    for (no, line) in logical_lines(piece) {
        let no = no + before.lines;
        if line.contains('\0') {
            return Err(bad(
                no,
                "binary content (NUL byte); is this really an OBJ file?".into(),
            ));
        }
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                seen += 1;
                let coords: Vec<&str> = words.take(3).collect();
                if coords.len() < 3 {
                    return Err(bad(
                        no,
                        format!("vertex has {} coordinates, needs 3", coords.len()),
                    ));
                }
                for w in coords {
                    let Ok(x) = w.parse::<f32>() else {
                        return Err(bad(no, format!("vertex coordinate {w:?} is not a number")));
                    };
                    if !x.is_finite() {
                        let what = if x.is_nan() { "a NaN" } else { "an infinite" };
                        return Err(MeshError::NonFinite {
                            at: Location::line(path, no),
                            what,
                        });
                    }
                }
            }
            Some("vt") => seen_vt += 1,
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(bad(
                        no,
                        format!("face has {} corners, needs at least 3", corners.len()),
                    ));
                }
                let face_start = out.len();
                let mut corner_v: Vec<&str> = Vec::with_capacity(corners.len());
                let mut corner_vt: Vec<Option<&str>> = Vec::with_capacity(corners.len());
                out.push('f');
                for c in corners {
                    let first = c.split('/').next().unwrap_or("");
                    corner_v.push(first);
                    let Ok(i) = first.parse::<i64>() else {
                        return Err(bad(no, format!("face corner {c:?} is not a vertex index")));
                    };
                    // 1-based from the start, or negative: relative to the
                    // vertices read so far.
                    let ok = if i > 0 {
                        i as u64 <= total as u64
                    } else {
                        i < 0 && i.unsigned_abs() <= seen as u64
                    };
                    if !ok {
                        let count = if i < 0 { seen } else { total };
                        return Err(MeshError::IndexOutOfRange {
                            at: Location::line(path, no),
                            index: i,
                            count,
                        });
                    }
                    out.push(' ');
                    out.push_str(first);
                    corner_vt.push(c.split('/').nth(1).filter(|t| !t.is_empty()));
                }
                // Texture indices, when every corner has a valid one: a
                // face whose are missing or out of range is read without
                // (a sloppy exporter's, or a hostile file's).
                let valid = |t: &str| {
                    t.parse::<i64>().is_ok_and(|k| {
                        if k > 0 {
                            k as u64 <= total_vt as u64
                        } else {
                            k < 0 && k.unsigned_abs() <= seen_vt as u64
                        }
                    })
                };
                if corner_vt.iter().all(|t| t.is_some_and(valid)) {
                    let mut with = String::from("f");
                    for (v, t) in corner_v.iter().zip(&corner_vt) {
                        with.push(' ');
                        with.push_str(v);
                        with.push('/');
                        with.push_str(t.unwrap_or_default());
                    }
                    out.truncate(face_start);
                    out.push_str(&with);
                }
                out.push('\n');
                continue;
            }
            _ => {}
        }
        out.push_str(&line);
        out.push('\n');
    }
    Ok(out)
}

/// The file's statements with their 1-based starting line numbers: comments
/// stripped, lines ending in `\` joined with the next (a line needing
/// neither is handed on as it is, not copied).
fn logical_lines(text: &str) -> impl Iterator<Item = (usize, Cow<'_, str>)> + '_ {
    let mut lines = text.lines().enumerate().peekable();
    std::iter::from_fn(move || {
        let (i, first) = lines.next()?;
        if !first.ends_with('\\') {
            let kept = match first.find('#') {
                Some(hash) => &first[..hash],
                None => first,
            };
            return Some((i + 1, Cow::Borrowed(kept)));
        }
        let mut joined = String::from(first);
        while joined.ends_with('\\') {
            joined.pop();
            match lines.next() {
                Some((_, next)) => {
                    joined.push(' ');
                    joined.push_str(next);
                }
                None => break,
            }
        }
        if let Some(hash) = joined.find('#') {
            joined.truncate(hash);
        }
        Some((i + 1, Cow::Owned(joined)))
    })
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{cube, write};
    use super::super::{load, MeshError};

    fn cube_obj() -> String {
        let (v, t) = cube();
        let mut s = String::from("# a cube\nmtllib missing.mtl\no cube\n");
        for p in v {
            s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        // Faces as quads split across two groups, to test merging and
        // triangulation: pair up the triangles back into quads where simple.
        s += "g first\n";
        for tri in &t[..6] {
            s += &format!("f {} {} {}\n", tri[0] + 1, tri[1] + 1, tri[2] + 1);
        }
        s += "o second\n";
        for tri in &t[6..] {
            s += &format!("f {}/1 {}//2 {}\n", tri[0] + 1, tri[1] + 1, tri[2] + 1);
        }
        s
    }

    #[test]
    fn loads_cube_merging_objects() {
        let f = write("cube.obj", cube_obj().as_bytes());
        let m = load(&f.path).unwrap();
        assert_eq!(m.triangles.len(), 12);
        // Each object keeps its own copy of the vertices it uses.
        assert!((8..=16).contains(&m.positions.len()));
    }

    #[test]
    fn triangulates_polygons_and_negative_indices() {
        let src = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n";
        let f = write("quad.obj", src.as_bytes());
        let m = load(&f.path).unwrap();
        assert_eq!(m.triangles.len(), 2);
    }

    fn err(src: &str) -> (MeshError, String) {
        let f = write("bad.obj", src.as_bytes());
        let e = load(&f.path).unwrap_err();
        let msg = e.to_string();
        (e, msg)
    }

    #[test]
    fn nan_vertex_reports_line() {
        let (e, msg) = err("# header\nv 0 0 0\nv 1 0 0\nv 0 NaN 0\nf 1 2 3\n");
        assert!(matches!(e, MeshError::NonFinite { .. }));
        assert!(
            msg.contains("bad.obj:4: vertex has a NaN coordinate"),
            "{msg}"
        );
        let (_, msg) = err("v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n");
        assert!(
            msg.contains("bad.obj:2:") && msg.contains("infinite"),
            "{msg}"
        );
    }

    #[test]
    fn non_numeric_vertex_reports_line() {
        let (e, msg) = err("v 0 0 0\nv 1 zero 0\n");
        assert!(matches!(e, MeshError::Malformed { .. }));
        assert!(
            msg.contains("bad.obj:2:") && msg.contains("\"zero\""),
            "{msg}"
        );
        let (_, msg) = err("v 0 0\n");
        assert!(
            msg.contains("bad.obj:1:") && msg.contains("needs 3"),
            "{msg}"
        );
    }

    #[test]
    fn index_out_of_range_reports_line() {
        let (e, msg) = err("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n");
        assert!(matches!(
            e,
            MeshError::IndexOutOfRange {
                index: 4,
                count: 3,
                ..
            }
        ));
        assert!(msg.contains("bad.obj:5:"), "{msg}");
        let (_, msg) = err("v 0 0 0\nv 1 0 0\nf 0 1 2\n");
        assert!(msg.contains("bad.obj:3:"), "{msg}");
        // Texture and normal indices are not the mesh's: any of them, even
        // huge (found by tests/fuzz.rs: `tobj` multiplied one and
        // overflowed), leaves the triangle as it is.
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
        for corner in [
            "1/9223372036854775807",
            "1/2",
            "1/-2",
            "1//2",
            "1/1/18446744073709551617",
            "1/1/1",
        ] {
            let f = write(
                "ok.obj",
                format!("{tri}f {corner} 2/-1/-1 3//1\n").as_bytes(),
            );
            assert_eq!(load(&f.path).unwrap().triangles.len(), 1, "{corner}");
        }
        let (_, msg) = err("v 0 0 0\nf -2 -1 -1\nv 1 0 0\n");
        assert!(msg.contains("bad.obj:2:"), "{msg}");
        let (_, msg) = err("v 0 0 0\nv 1 0 0\nf 1 x 2\n");
        assert!(msg.contains("bad.obj:3:") && msg.contains("\"x\""), "{msg}");
    }

    /// A file big enough to be checked in pieces: a strip of triangles,
    /// every vertex written across two lines (`\\`), CRLF line ends.
    fn big_strip(n: usize) -> String {
        let mut s = String::new();
        for k in 0..n {
            s += &format!("v {k} \\\r\n {} 0\r\n", k % 2);
        }
        for k in 1..n - 1 {
            s += &format!("f {k} {} -1 # after vertex {}\r\n", k + 1, k + 2);
        }
        s
    }

    #[test]
    fn a_big_file_checked_in_pieces_reads_as_one() {
        let text = big_strip(20_000);
        assert!(text.len() > 4 << 16, "several pieces");
        for n in [1, 3, 8, 64] {
            let pieces = super::statement_pieces(&text, n);
            assert_eq!(pieces.concat(), text);
            for p in &pieces {
                let last = p.trim_end_matches('\n').trim_end_matches('\r');
                assert!(p.ends_with('\n') && !last.ends_with('\\'), "{n}");
            }
            if n == 64 {
                assert!(pieces.len() > 4, "{}", pieces.len());
            }
        }
        let f = write("strip.obj", text.as_bytes());
        let m = load(&f.path).unwrap();
        assert_eq!(m.triangles.len(), 19_998);
        // Errors deep in the file name their line, counted over every
        // piece before (two lines a vertex).
        let bad_vertex = text.replacen("v 15000 \\\r\n 0 0", "v 15000 \\\r\n zero 0", 1);
        let (_, msg) = err(&bad_vertex);
        assert!(msg.contains("bad.obj:30001:"), "{msg}");
        let bad_face = format!("{text}f 1 2 20001\r\n");
        let (_, msg) = err(&bad_face);
        assert!(
            msg.contains("bad.obj:59999:") && msg.contains("20001"),
            "{msg}"
        );
    }

    #[test]
    fn garbage_and_empty_files() {
        let (e, msg) = err("\u{0}\u{1}\u{2}binary");
        assert!(matches!(e, MeshError::Malformed { .. }), "{msg}");
        let f = write("bin.obj", &[0xff, 0xfe, 0x00, 0x80, 0x81]);
        let e = load(&f.path).unwrap_err();
        assert!(e.to_string().contains("bin.obj:1:"), "{e}");
        let (e, msg) = err("# nothing\nv 0 0 0\nv 1 1 1\n");
        assert!(matches!(e, MeshError::Empty { .. }), "{msg}");
        assert!(msg.contains("bad.obj"), "{msg}");
        let (e, _) = err("v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n");
        assert!(matches!(e, MeshError::ZeroExtent { .. }));
        let (e, _) = err("v 0 0 0\nv 1e8 0 0\nv 0 1 0\nf 1 2 3\n");
        assert!(matches!(e, MeshError::TooLarge { .. }));
    }

    #[test]
    fn never_panics_on_mangled_input() {
        let base = cube_obj().into_bytes();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..300 {
            let mut b = base.clone();
            for _ in 0..4 {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let i = (state % b.len() as u64) as usize;
                b[i] = b" /-0123456789fv\nx.e#\\"[(state >> 32) as usize % 21];
            }
            b.truncate(((state >> 40) as usize % b.len()).max(1));
            let f = write("m.obj", &b);
            let _ = load(&f.path);
        }
    }
}

#[cfg(test)]
mod colour_tests {
    use super::super::load;

    /// A quad with texture coordinates, its MTL naming a 2 x 2 PNG (top
    /// row red, bottom row blue) beside it; and a vertex-coloured triangle.
    #[test]
    fn map_kd_textures_and_vertex_colours() {
        let dir = tempfile::tempdir().unwrap();
        let img = image::RgbImage::from_fn(2, 2, |_, y| {
            image::Rgb(if y == 0 { [255, 0, 0] } else { [0, 0, 255] })
        });
        img.save(dir.path().join("tex.png")).unwrap();
        std::fs::write(
            dir.path().join("m.mtl"),
            "newmtl t\nKd 1 1 1\nmap_Kd tex.png\n",
        )
        .unwrap();
        let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                   vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
        let path = dir.path().join("q.obj");
        std::fs::write(&path, obj).unwrap();
        let m = load(&path).unwrap();
        assert!(m.warnings.is_empty(), "{:?}", m.warnings);
        let p = m.paint.as_ref().unwrap();
        // OBJ's v counts up: v = 0 is the image's bottom row (blue).
        assert_eq!(p.sample(0, [0.9, 0.05, 0.05]), [0.0, 0.0, 1.0]);
        assert_eq!(p.sample(1, [0.05, 0.05, 0.9]), [1.0, 0.0, 0.0]);

        let path = dir.path().join("vc.obj");
        std::fs::write(
            &path,
            "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 0 1 0 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let m = load(&path).unwrap();
        let p = m.paint.as_ref().unwrap();
        assert_eq!(p.sample(0, [1.0, 0.0, 0.0]), [1.0, 0.0, 0.0]);
        assert_eq!(p.sample(0, [0.0, 0.0, 1.0]), [0.0, 1.0, 0.0]);
    }

    #[test]
    fn a_material_library_outside_the_folder_is_not_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.obj");
        std::fs::write(
            &path,
            "mtllib ../secret.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let m = load(&path).unwrap();
        assert!(m.paint.is_none());
        assert!(
            m.warnings.len() == 1 && m.warnings[0].contains("outside"),
            "{:?}",
            m.warnings
        );
    }
}
