//! The interactive step viewer: one self-contained HTML page per build.
//!
//! [`write_html`] writes a page that opens with a double click, offline, in
//! any current browser with WebGL: the model in 3D (turn, zoom and pan with
//! mouse or touch), built step by step: earlier steps' pieces shown, the
//! current step's outlined and tinted, later ones hidden. Buttons, a
//! slider and the arrow keys move between steps, and `#step=N` in the URL
//! opens at step N. Beside the view, the step's parts and the whole parts
//! list; a toggle pulls the model apart into its
//! [exploded](super::explode) view.
//!
//! # What is in the page
//!
//! Everything, inlined: the stylesheet, the viewer script (a small WebGL
//! renderer of our own, `src/export/viewer/viewer.js`, no library) and the
//! model as a JSON document in a `<script type="application/json">` block.
//! The page loads nothing: no URL appears in it, so it works from `file://`
//! and from a mail attachment alike.
//!
//! The model is stored for instanced drawing, **one mesh per part type**:
//!
//! - `parts`: every part type the build uses, in catalog order, with its
//!   triangle mesh from [`partmesh`](super::partmesh) (positions and normals
//!   as little-endian `f32`, indices as `u16` or `u32`, each base64), so a
//!   brick looks as it does in the glTF and the step images, and its
//!   [coarse](super::partmesh::coarse_part_mesh) mesh in the same buffers;
//! - `colors`: every colour used, with its LDraw code, name and sRGB;
//! - `rotations`: the four quarter-turn matrices (LDraw's, row-major);
//! - `pieces`: one row per piece in build order,
//!   `[part, colour, step, rotation, x, y, z, ex, ey, ez, top, bottom, +x,
//!   -x, +z, -z]`: indices into the tables above, the step, the LDraw
//!   position in LDU (-Y up) exactly as the `.ldr` line has it, the
//!   exploded-view offset, and the step from which each face of the piece
//!   is out of sight (0 if never; see [`sight`](super::sight)).
//!
//! A piece takes about 70 bytes, a part type 6 to 65 kB of mesh: the
//! 15,397-piece build of a 64-stud box (11 part types) makes a 1.4 MB
//! page. The viewer draws it in a few instanced calls per part type.
//!
//! The address picks the view: `page.html#step=12` opens at step 12 (out
//! of range goes to the nearest step), `&exploded=1` exploded, and the
//! address follows the viewer. Without WebGL the page says so, and the step
//! controls and parts lists still work.
//!
//! # Drawing little
//!
//! Studs are most of a part's triangles (a 2x8 brick has 1,334, its body
//! about 40), and in a solid model most pieces cannot be seen at all. So
//! the viewer draws, at each step, only what can be seen from outside:
//!
//! - a piece whose six faces are all [out of sight](super::sight) is left
//!   out;
//! - a piece whose top is out of sight is drawn bare: the coarse mesh's
//!   body without studs or top face (`bareIndices`);
//! - a face (bottom or side) out of sight is folded to a point in the
//!   vertex shader, which finds a vertex's face from its normal and the
//!   part's bounds, so it costs no fragment;
//! - when a stud is a few pixels wide, whole pieces are drawn with the
//!   coarse mesh (`coarseIndices`: a 2x4 brick in 140 triangles, not 678).
//!
//! Nothing visible from outside changes; a camera moved inside the model
//! draws everything. The exploded view, which opens the gaps, draws every
//! piece whole. The finished 15,397-piece box at 64 studs draws 114
//! thousand triangles a frame instead of 1.6 million (with its studs
//! coarse: 5 pixels wide in a 660x490 view).
//! The same assembly and options always give byte-identical pages.
//!
//! # Example
//!
//! ```
//! use brickwright::assembly::{Assembly, Placement};
//! use brickwright::catalog::{Color, PartKind};
//! use brickwright::export::html::{write_html, HtmlOptions};
//! use brickwright::geom::{Cell, Rot};
//!
//! let brick = PartKind::from_id("3001").unwrap();
//! let order = [
//!     Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
//!     Placement::new(brick, Cell::new(1, 0, 1), Rot::R90),
//! ];
//! let asm = Assembly::from_order(&order, 24, Color::RED);
//! let mut page = Vec::new();
//! write_html(&mut page, &asm, &HtmlOptions::default().with_name("two bricks")).unwrap();
//! let page = String::from_utf8(page).unwrap();
//! assert!(page.starts_with("<!DOCTYPE html>"));
//! assert!(page.contains("<title>two bricks, built by brickwright</title>"));
//! assert!(!page.contains("http://") && !page.contains("https://"));
//! ```

use std::io::{self, Write};

use base64::Engine as _;
use serde::Serialize;

use super::explode::{explode, ExplodeOptions};
use super::partmesh::{coarse_part_mesh, part_mesh, piece_transform, PartMesh};
use super::sight::sight;
use crate::assembly::Assembly;
use crate::catalog::{Color, PartKind};
use crate::geom::Rot;
use crate::ldraw::rot_matrix;

/// The page around the viewer: markup with `{{TITLE}}`, `{{STYLE}}`,
/// `{{MODEL}}` and `{{SCRIPT}}` slots.
const PAGE: &str = include_str!("viewer/page.html");
/// The viewer's stylesheet.
const STYLE: &str = include_str!("viewer/viewer.css");
/// The viewer: a WebGL renderer, camera controls and the step UI.
const SCRIPT: &str = include_str!("viewer/viewer.js");

/// How [`write_html`] writes a page.
#[derive(Debug, Clone, PartialEq)]
pub struct HtmlOptions {
    /// The model's name: the page title and heading. Default `model`.
    pub name: String,
    /// How far the exploded view pulls pieces apart. Default
    /// [`ExplodeOptions::default`], as in the exploded glTF and picture.
    pub explode: ExplodeOptions,
}

impl Default for HtmlOptions {
    fn default() -> Self {
        HtmlOptions {
            name: "model".into(),
            explode: ExplodeOptions::default(),
        }
    }
}

impl HtmlOptions {
    /// Sets [`HtmlOptions::name`].
    pub fn with_name(mut self, name: impl Into<String>) -> Self {
        self.name = name.into();
        self
    }

    /// Sets [`HtmlOptions::explode`].
    pub fn with_explode(mut self, explode: ExplodeOptions) -> Self {
        self.explode = explode;
        self
    }
}

/// The model as the page carries it (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ViewerModel {
    /// The model's name.
    pub name: String,
    /// The tool and version that wrote the page.
    pub generator: String,
    /// Number of steps.
    pub steps: u32,
    /// Part types used, in catalog order.
    pub parts: Vec<ViewerPart>,
    /// Colours used, in LDraw code order.
    pub colors: Vec<ViewerColor>,
    /// The quarter turns' rotation matrices, row-major, indexed by
    /// [`Rot`] order.
    pub rotations: [[i32; 9]; 4],
    /// One [`PieceRow`] per piece, in build order.
    pub pieces: Vec<PieceRow>,
}

/// One piece: `[part, colour, step, rotation, x, y, z, ex, ey, ez, top,
/// bottom, +x, -x, +z, -z]`: the last six are the steps from which its
/// faces are out of sight ([`Sight`](super::sight::Sight), 0 for never).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PieceRow(
    pub u32,
    pub u32,
    pub u32,
    pub u32,
    pub f32,
    pub f32,
    pub f32,
    pub f32,
    pub f32,
    pub f32,
    pub u32,
    pub u32,
    pub u32,
    pub u32,
    pub u32,
    pub u32,
);

/// A part type and its mesh.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "camelCase")]
pub struct ViewerPart {
    /// LDraw part id.
    pub id: String,
    /// Part name.
    pub name: String,
    /// Vertex count: the full mesh's, then the coarse mesh's.
    pub vertices: usize,
    /// Positions in LDU, the part's LDraw frame: base64 of `f32` LE
    /// triples, the full mesh's vertices then the coarse mesh's.
    pub positions: String,
    /// Unit normals: base64 of `f32` LE triples.
    pub normals: String,
    /// The full mesh's triangles: base64 of `u16` LE, or `u32` LE when
    /// [`ViewerPart::index32`].
    pub indices: String,
    /// The [coarse](coarse_part_mesh) mesh's triangles, for pieces a few
    /// pixels wide: base64 like [`ViewerPart::indices`].
    pub coarse_indices: String,
    /// The coarse mesh without the studs and the studded top face, for a
    /// piece whose top is out of sight: base64 like
    /// [`ViewerPart::indices`].
    pub bare_indices: String,
    /// Whether indices are 32-bit.
    pub index32: bool,
    /// The centre of the mesh's bounding box, LDU (the outline grows away
    /// from it).
    pub center: [f32; 3],
    /// Half the bounding box's size, LDU.
    pub half: [f32; 3],
}

/// A colour of the build.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ViewerColor {
    /// LDraw colour code.
    pub code: u16,
    /// Colour name.
    pub name: String,
    /// sRGB as `#rrggbb`.
    pub rgb: String,
}

impl ViewerModel {
    /// The page's model of `assembly`.
    pub fn of(assembly: &Assembly, opts: &HtmlOptions) -> ViewerModel {
        let mut part_kinds: Vec<PartKind> =
            assembly.pieces.iter().map(|p| p.placement.part).collect();
        part_kinds.sort_unstable();
        part_kinds.dedup();
        let mut colors: Vec<Color> = assembly.pieces.iter().map(|p| p.color).collect();
        colors.sort_unstable();
        colors.dedup();
        let offsets = explode(assembly, &opts.explode);
        let seen = sight(assembly);
        let pieces = assembly
            .pieces
            .iter()
            .zip(&offsets)
            .zip(&seen)
            .map(|((p, e), seen)| {
                let pl = &p.placement;
                let t = piece_transform(pl, assembly.layer_ldu).translation;
                let index = |v: usize| v as u32;
                PieceRow(
                    index(part_kinds.binary_search(&pl.part).unwrap_or(0)),
                    index(colors.binary_search(&p.color).unwrap_or(0)),
                    p.step.0,
                    index(Rot::ALL.iter().position(|&r| r == pl.rot).unwrap_or(0)),
                    t.x,
                    t.y,
                    t.z,
                    round2(e.x),
                    round2(e.y),
                    round2(e.z),
                    seen.top,
                    seen.sides[0],
                    seen.sides[1],
                    seen.sides[2],
                    seen.sides[3],
                    seen.sides[4],
                )
            })
            .collect();
        ViewerModel {
            name: opts.name.clone(),
            generator: format!("brickwright {}", env!("CARGO_PKG_VERSION")),
            steps: assembly.step_count(),
            parts: part_kinds.into_iter().map(viewer_part).collect(),
            colors: colors
                .into_iter()
                .map(|c| {
                    let [r, g, b] = c.rgb();
                    ViewerColor {
                        code: c.0,
                        name: c.name(),
                        rgb: format!("#{r:02x}{g:02x}{b:02x}"),
                    }
                })
                .collect(),
            rotations: Rot::ALL.map(|r| {
                let m = rot_matrix(r);
                [
                    m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2], m[2][0], m[2][1], m[2][2],
                ]
            }),
            pieces,
        }
    }
}

/// Rounds to hundredths of an LDU: exploded offsets need no more, and the
/// page stays short.
fn round2(v: f32) -> f32 {
    (v * 100.0).round() / 100.0
}

/// The triangles of `mesh` that stay visible when its studs are covered:
/// none with a corner above the top (`y < 0`, a stud) nor lying in the
/// top plane (`y = 0`, the studded top face).
fn bare_triangles(mesh: &PartMesh) -> Vec<u32> {
    let y = |i: u32| mesh.positions.get(i as usize).map_or(0.0, |p| p[1]);
    mesh.indices
        .chunks_exact(3)
        .filter(|t| t.iter().all(|&i| y(i) >= 0.0) && !t.iter().all(|&i| y(i) == 0.0))
        .flatten()
        .copied()
        .collect()
}

fn viewer_part(part: PartKind) -> ViewerPart {
    let spec = part.spec();
    let (mesh, coarse) = (part_mesh(part), coarse_part_mesh(part));
    let base = mesh.positions.len() as u32;
    let shifted = |indices: &[u32]| -> Vec<u32> { indices.iter().map(|i| i + base).collect() };
    let b64 = |bytes: Vec<u8>| base64::engine::general_purpose::STANDARD.encode(bytes);
    let floats = |v: &[[f32; 3]]| {
        b64(v
            .iter()
            .flatten()
            .flat_map(|f| f.to_le_bytes())
            .collect::<Vec<u8>>())
    };
    let vertices = mesh.positions.len() + coarse.positions.len();
    let index32 = vertices > usize::from(u16::MAX);
    let encode = |indices: &[u32]| {
        if index32 {
            b64(indices.iter().flat_map(|i| i.to_le_bytes()).collect())
        } else {
            b64(indices
                .iter()
                .flat_map(|&i| (i as u16).to_le_bytes())
                .collect())
        }
    };
    let (lo, hi) = mesh.bounds().unwrap_or(([0.0; 3], [0.0; 3]));
    ViewerPart {
        id: spec.id.0.to_string(),
        name: spec.name.to_string(),
        vertices,
        positions: floats(&[&mesh.positions[..], &coarse.positions].concat()),
        normals: floats(&[&mesh.normals[..], &coarse.normals].concat()),
        indices: encode(&mesh.indices),
        coarse_indices: encode(&shifted(&coarse.indices)),
        bare_indices: encode(&shifted(&bare_triangles(coarse))),
        index32,
        center: [0, 1, 2].map(|k| (lo[k] + hi[k]) / 2.0),
        half: [0, 1, 2].map(|k| (hi[k] - lo[k]) / 2.0),
    }
}

/// Writes the viewer page of `assembly` to `w`.
pub fn write_html<W: Write + ?Sized>(
    w: &mut W,
    assembly: &Assembly,
    opts: &HtmlOptions,
) -> io::Result<()> {
    let model = ViewerModel::of(assembly, opts);
    let json = serde_json::to_string(&model).map_err(io::Error::other)?;
    let title = escape_html(&opts.name);
    let model = escape_script(&json);
    // One pass over the template: a value written into a slot is never
    // read again, so a model named `{{MODEL}}.obj` stays a title.
    fill_slots(w, PAGE, |slot| match slot {
        "TITLE" => Some(title.as_str()),
        "STYLE" => Some(STYLE.trim_end()),
        "SCRIPT" => Some(SCRIPT.trim_end()),
        "MODEL" => Some(model.as_str()),
        _ => None,
    })
}

/// Writes `template` to `w` with each `{{NAME}}` slot replaced by
/// `value(NAME)`, in a single pass; an unknown or unclosed slot is an error.
fn fill_slots<'a, W: Write + ?Sized>(
    w: &mut W,
    template: &str,
    value: impl Fn(&str) -> Option<&'a str>,
) -> io::Result<()> {
    let mut rest = template;
    while let Some(at) = rest.find("{{") {
        w.write_all(&rest.as_bytes()[..at])?;
        let after = &rest[at + 2..];
        let end = after
            .find("}}")
            .ok_or_else(|| io::Error::other("viewer page template has an unclosed slot"))?;
        let name = &after[..end];
        let v = value(name).ok_or_else(|| {
            io::Error::other(format!("viewer page template has an unknown slot {name:?}"))
        })?;
        w.write_all(v.as_bytes())?;
        rest = &after[end + 2..];
    }
    w.write_all(rest.as_bytes())
}

/// Text for HTML content and attribute values.
fn escape_html(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// JSON made safe inside a `<script>` element: no `<` can close it or open
/// a comment (`\u003c` means the same to the JSON parser).
fn escape_script(json: &str) -> String {
    json.replace('<', "\\u003c")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Placement;
    use crate::geom::Cell;

    fn page(asm: &Assembly, opts: &HtmlOptions) -> String {
        let mut out = Vec::new();
        write_html(&mut out, asm, opts).unwrap();
        String::from_utf8(out).unwrap()
    }

    /// The JSON block between the model script's tags.
    fn model_json(page: &str) -> serde_json::Value {
        let start = page.find("id=\"model\">").unwrap() + "id=\"model\">".len();
        let len = page[start..].find("</script>").unwrap();
        serde_json::from_str(&page[start..start + len]).unwrap()
    }

    /// A wall of `n` 2x4 bricks in running bond, 8 a course, 4 a step,
    /// alternating red and white by course.
    fn wall(n: usize) -> Assembly {
        let brick = PartKind::from_id("3001").unwrap();
        let order: Vec<Placement> = (0..n)
            .map(|i| {
                let course = (i / 8) as i32;
                let x = 4 * (i % 8) as i32 + 2 * (course % 2);
                Placement::new(brick, Cell::new(x, 0, course), Rot::R0)
            })
            .collect();
        let mut asm = Assembly::from_order(&order, 24, Color::RED);
        for (i, p) in asm.pieces.iter_mut().enumerate() {
            p.step = crate::assembly::Step((i / 4) as u32 + 1);
            if (i / 8) % 2 == 1 {
                p.color = Color::WHITE;
            }
        }
        asm
    }

    #[test]
    fn the_page_carries_every_piece_where_the_ldr_puts_it() {
        let part = |id| PartKind::from_id(id).unwrap();
        let order = [
            Placement::new(part("3001"), Cell::new(0, 0, 0), Rot::R0),
            Placement::new(part("3003"), Cell::new(1, 1, 1), Rot::R90),
            Placement::new(part("3001"), Cell::new(0, 0, 2), Rot::R90),
        ];
        let mut asm = Assembly::from_order(&order, 24, Color::RED);
        asm.pieces[1].color = Color(14);
        let model = model_json(&page(&asm, &HtmlOptions::default()));
        assert_eq!(model["steps"], 3);
        let ids: Vec<&str> = model["parts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["id"].as_str().unwrap())
            .collect();
        // Catalog order.
        let mut want = [part("3001"), part("3003")];
        want.sort_unstable();
        assert_eq!(ids, want.map(|p| p.spec().id.0));
        let colors: Vec<u64> = model["colors"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["code"].as_u64().unwrap())
            .collect();
        assert_eq!(colors, [4, 14]);
        assert_eq!(model["colors"][0]["rgb"], "#b40000");
        let pieces = model["pieces"].as_array().unwrap();
        assert_eq!(pieces.len(), 3);
        for (row, p) in pieces.iter().zip(&asm.pieces) {
            let row: Vec<f64> = row
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            let [x, y, z] = crate::ldraw::placement_position(&p.placement, 24);
            assert_eq!(row[4..7], [x as f64, y as f64, z as f64]);
            assert_eq!(row[2], f64::from(p.step.0));
            let rot = Rot::ALL[row[3] as usize];
            assert_eq!(rot, p.placement.rot);
        }
        // The second piece is the yellow 2x2, the third a turned 2x4.
        assert_eq!(
            model["parts"][pieces[1][0].as_u64().unwrap() as usize]["id"],
            "3003"
        );
        assert_eq!(pieces[1][1], 1);
        assert_eq!(
            model["parts"][pieces[2][0].as_u64().unwrap() as usize]["id"],
            "3001"
        );
        assert_eq!(
            model["rotations"][1],
            serde_json::json!([0, 0, -1, 0, 1, 0, 1, 0, 0])
        );
    }

    #[test]
    fn meshes_decode_to_the_part_meshes() {
        let asm = wall(3);
        let model = model_json(&page(&asm, &HtmlOptions::default()));
        let p = &model["parts"][0];
        let brick = PartKind::from_id("3001").unwrap();
        let (mesh, coarse) = (part_mesh(brick), coarse_part_mesh(brick));
        let dec = |k: &str| {
            base64::engine::general_purpose::STANDARD
                .decode(p[k].as_str().unwrap())
                .unwrap()
        };
        let pos: Vec<f32> = dec("positions")
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        let want: Vec<f32> = [&mesh.positions[..], &coarse.positions]
            .concat()
            .into_iter()
            .flatten()
            .collect();
        assert_eq!(pos, want);
        let n = mesh.positions.len();
        assert_eq!(p["vertices"], n + coarse.positions.len());
        assert_eq!(dec("normals").len(), 4 * want.len());
        assert_eq!(p["index32"], false);
        let ints = |k: &str| -> Vec<u32> {
            dec(k)
                .chunks_exact(2)
                .map(|b| u32::from(u16::from_le_bytes([b[0], b[1]])))
                .collect()
        };
        assert_eq!(ints("indices"), mesh.indices);
        // The coarse mesh's triangles, and its bare ones, index its own
        // vertices, after the full mesh's.
        let coarse_idx: Vec<u32> = coarse.indices.iter().map(|i| i + n as u32).collect();
        assert_eq!(ints("coarseIndices"), coarse_idx);
        let bare = ints("bareIndices");
        assert!(!bare.is_empty() && bare.len() < coarse_idx.len());
        assert!(bare.iter().all(|i| coarse_idx.contains(i)));
        assert_eq!(p["center"], serde_json::json!([0.0, 10.0, 0.0]));
    }

    #[test]
    fn the_page_is_self_contained_deterministic_and_escaped() {
        let asm = wall(20);
        let opts = HtmlOptions::default().with_name("a <b> & \"c\"</script>");
        let a = page(&asm, &opts);
        assert_eq!(a, page(&asm, &opts));
        for needle in ["://", "src=", "href=", "@import", "url(", "{{"] {
            assert!(!a.contains(needle), "the page holds `{needle}`");
        }
        assert!(a.contains("<title>a &lt;b&gt; &amp; &quot;c&quot;&lt;/script&gt;, built"));
        // One closing tag per script element: the name did not close one.
        assert_eq!(a.matches("</script>").count(), 2);
        assert_eq!(model_json(&a)["name"], "a <b> & \"c\"</script>");
    }

    #[test]
    fn exploded_offsets_are_the_explode_modules() {
        let asm = wall(24);
        let model = model_json(&page(&asm, &HtmlOptions::default()));
        let off = explode(&asm, &ExplodeOptions::default());
        for (row, o) in model["pieces"].as_array().unwrap().iter().zip(&off) {
            for k in 0..3 {
                let got = row[7 + k].as_f64().unwrap();
                assert!((got - f64::from(o[k])).abs() < 0.006, "{got} vs {}", o[k]);
            }
        }
        // Upper courses rise.
        assert!(model["pieces"][16][8].as_f64().unwrap() < 0.0);
    }

    #[test]
    fn rows_carry_the_steps_from_which_faces_are_out_of_sight() {
        // Course 0 spans x 0..32, course 1 (steps 3 and 4) x 2..34.
        let asm = wall(16);
        let seen = sight(&asm);
        let rows = model_json(&page(&asm, &HtmlOptions::default()));
        for (row, s) in rows["pieces"].as_array().unwrap().iter().zip(&seen) {
            let faces: Vec<u64> = (10..16).map(|k| row[k].as_u64().unwrap()).collect();
            assert_eq!(faces[0], u64::from(s.top));
            assert_eq!(faces[1..], s.sides.map(u64::from));
        }
        assert_eq!(rows["pieces"][0][10], 0, "its left half stays open");
        assert_eq!(rows["pieces"][1][10], 3);
        // The second brick's ends touch the first (step 1) and the third
        // (step 1) bricks of the course.
        assert_eq!(rows["pieces"][1][12], 1);
        assert_eq!(rows["pieces"][1][13], 1);
    }

    #[test]
    fn bare_meshes_drop_the_studs_and_the_top_and_keep_the_rest() {
        for part in PartKind::all() {
            let mesh = coarse_part_mesh(part);
            let bare = bare_triangles(mesh);
            assert!(bare.len().is_multiple_of(3) && !bare.is_empty(), "{part}");
            assert!(
                bare.len() * 2 < mesh.indices.len(),
                "{part}: {}",
                bare.len()
            );
            if ["3001", "3007"].contains(&part.spec().id.0) {
                assert!(
                    bare.len() * 40 < part_mesh(part).indices.len(),
                    "{part}: {}",
                    bare.len()
                );
            }
            let y = |i: &u32| mesh.positions[*i as usize][1];
            assert!(bare.iter().all(|i| y(i) >= 0.0), "{part}");
            // The bottom face (the part's full height) is kept.
            let h = part.spec().height_ldu().max(8) as f32;
            assert!(bare.iter().any(|i| y(i) == h), "{part}");
        }
    }

    #[test]
    fn five_thousand_pieces_make_a_page_of_a_few_hundred_kilobytes() {
        let asm = wall(5000);
        let a = page(&asm, &HtmlOptions::default());
        assert!(a.len() < 1_000_000, "{} bytes", a.len());
        assert_eq!(model_json(&a)["pieces"].as_array().unwrap().len(), 5000);
    }

    #[test]
    fn an_empty_assembly_still_makes_a_page() {
        let asm = Assembly {
            pieces: vec![],
            layer_ldu: 24,
        };
        let model = model_json(&page(&asm, &HtmlOptions::default()));
        assert_eq!(model["steps"], 0);
        assert_eq!(model["pieces"], serde_json::json!([]));
    }
}
