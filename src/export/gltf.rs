//! glTF 2.0 scenes of a build: every piece a node, playable as an animation.
//!
//! glTF is the format 3D viewers, game engines and the web read (Blender,
//! three.js, `model-viewer`, Windows' 3D Viewer). [`write_gltf`] writes an
//! [`Assembly`] as one scene:
//!
//! - a root node named after the model, holding **one node per piece**,
//!   named by its step and part (`step 012 · 3001 Brick 2 x 4`), with
//!   `{"step": 12, "part": "3001", "color": 4}` in its `extras` so tools can
//!   filter by step;
//! - **one mesh per part type and colour**: the part's geometry
//!   ([`partmesh`](super::partmesh)) is stored once and its accessors are
//!   shared by every colour's mesh (a glTF material belongs to a primitive,
//!   so the colour has to live in the mesh);
//! - PBR metallic-roughness **materials in LEGO colours**: LDraw's sRGB
//!   values converted to the linear `baseColorFactor` glTF expects, not
//!   metallic, roughness 0.3, named by colour;
//! - optionally an **exploded** layout ([`explode`](super::explode)) and a
//!   **build animation** named `build`: each piece is hidden (scale 0, `STEP`
//!   interpolation) until its step starts, then drops into place from
//!   [`GltfOptions::drop_height_ldu`] above (`LINEAR`), one step every
//!   [`GltfOptions::step_seconds`].
//!
//! # Units and axes
//!
//! glTF is Y up and in metres; LDraw is -Y up in LDU (0.4 mm). A point
//! `(x, y, z)` in LDraw becomes `(x, -y, -z) · 0.0004` ([`ldraw_to_gltf`]):
//! a half turn about X and a scale, a proper rotation, so nothing is
//! mirrored and triangles keep their winding. Meshes are stored in that
//! frame; each piece node carries its translation and a quarter-turn
//! rotation about Y.
//!
//! # Containers
//!
//! [`Container::Binary`] (the default) writes a `.glb`: a JSON chunk and a
//! binary chunk in one file. [`Container::Embedded`] writes a `.gltf` JSON
//! file with the buffer inside as a base64 `data:` URI. Either way the
//! output is byte-identical for the same assembly and options.
//!
//! # Example
//!
//! ```
//! use brickwright::assembly::{Assembly, Placement};
//! use brickwright::catalog::{Color, PartKind};
//! use brickwright::export::gltf::{write_gltf, GltfOptions};
//! use brickwright::geom::{Cell, Rot};
//!
//! let brick = PartKind::from_id("3001").unwrap();
//! let order = [
//!     Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
//!     Placement::new(brick, Cell::new(1, 0, 1), Rot::R90),
//! ];
//! let asm = Assembly::from_order(&order, 24, Color::RED);
//! let mut glb = Vec::new();
//! write_gltf(&mut glb, &asm, &GltfOptions::default().with_name("two bricks")).unwrap();
//! assert_eq!(&glb[..4], b"glTF");
//!
//! let doc = gltf::Gltf::from_slice(&glb).unwrap();
//! let names: Vec<_> = doc.nodes().filter_map(|n| n.name()).collect();
//! assert_eq!(names, ["two bricks", "step 001 · 3001 Brick 2 x 4", "step 002 · 3001 Brick 2 x 4"]);
//! assert_eq!(doc.meshes().count(), 1);
//! ```

use std::collections::BTreeMap;
use std::io::{self, Write};

use base64::Engine as _;
use glam::Vec3;
use serde::Serialize;

use super::explode::{explode, ExplodeOptions};
use super::partmesh::{part_mesh, piece_transform, PartMesh};
use crate::assembly::Assembly;
use crate::catalog::{Color, PartKind};
use crate::geom::Rot;

/// Metres per LDraw unit (0.4 mm).
pub const METRES_PER_LDU: f32 = 0.0004;

/// An LDraw point (LDU, -Y up) in glTF's frame (metres, +Y up):
/// `(x, -y, -z) · 0.0004`.
pub fn ldraw_to_gltf(v: Vec3) -> Vec3 {
    Vec3::new(v.x, -v.y, -v.z) * METRES_PER_LDU
}

/// The file layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Container {
    /// Binary glTF, `.glb` (the default).
    #[default]
    Binary,
    /// glTF JSON, `.gltf`, with the buffer embedded as a base64 data URI.
    Embedded,
}

impl Container {
    /// The usual file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Container::Binary => "glb",
            Container::Embedded => "gltf",
        }
    }
}

/// Where pieces sit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// As built (the default).
    #[default]
    Assembled,
    /// Pulled apart by [`explode`], with [`GltfOptions::explode`].
    Exploded,
}

/// Whether the scene carries the build animation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Animation {
    /// An animation named `build` that drops each piece in at its step
    /// (the default).
    #[default]
    Build,
    /// A still scene.
    None,
}

/// How [`write_gltf`] writes a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfOptions {
    /// `.glb` or `.gltf`. Default [`Container::Binary`].
    pub container: Container,
    /// Assembled or exploded. Default [`Layout::Assembled`].
    pub layout: Layout,
    /// How far an exploded layout pulls pieces apart. Default
    /// [`ExplodeOptions::default`].
    pub explode: ExplodeOptions,
    /// The build animation. Default [`Animation::Build`].
    pub animation: Animation,
    /// The model's name: the root node's and the scene's. Default `model`.
    pub name: String,
    /// Seconds between steps in the animation. Default 0.5.
    pub step_seconds: f32,
    /// Seconds a piece takes to drop into place. Default 0.3.
    pub drop_seconds: f32,
    /// Height in LDU a piece drops from. Default 72 (three bricks).
    pub drop_height_ldu: f32,
}

impl Default for GltfOptions {
    fn default() -> Self {
        GltfOptions {
            container: Container::Binary,
            layout: Layout::Assembled,
            explode: ExplodeOptions::default(),
            animation: Animation::Build,
            name: "model".into(),
            step_seconds: 0.5,
            drop_seconds: 0.3,
            drop_height_ldu: 72.0,
        }
    }
}

impl GltfOptions {
    /// Sets [`GltfOptions::container`].
    pub fn with_container(mut self, container: Container) -> Self {
        self.container = container;
        self
    }

    /// Sets [`GltfOptions::layout`].
    pub fn with_layout(mut self, layout: Layout) -> Self {
        self.layout = layout;
        self
    }

    /// [`Layout::Exploded`] when `exploded`, else [`Layout::Assembled`].
    pub fn with_exploded(self, exploded: bool) -> Self {
        self.with_layout(if exploded {
            Layout::Exploded
        } else {
            Layout::Assembled
        })
    }

    /// Sets [`GltfOptions::explode`].
    pub fn with_explode(mut self, explode: ExplodeOptions) -> Self {
        self.explode = explode;
        self
    }

    /// Sets [`GltfOptions::animation`].
    pub fn with_animation(mut self, animation: Animation) -> Self {
        self.animation = animation;
        self
    }

    /// [`Animation::Build`] when `animated`, else [`Animation::None`].
    pub fn with_animated(self, animated: bool) -> Self {
        self.with_animation(if animated {
            Animation::Build
        } else {
            Animation::None
        })
    }

    /// Sets [`GltfOptions::name`].
    pub fn with_name(mut self, name: impl Into<String>) -> Self {
        self.name = name.into();
        self
    }

    /// Sets [`GltfOptions::step_seconds`].
    pub fn with_step_seconds(mut self, seconds: f32) -> Self {
        self.step_seconds = seconds;
        self
    }

    /// Sets [`GltfOptions::drop_seconds`].
    pub fn with_drop_seconds(mut self, seconds: f32) -> Self {
        self.drop_seconds = seconds;
        self
    }

    /// Sets [`GltfOptions::drop_height_ldu`].
    pub fn with_drop_height_ldu(mut self, ldu: f32) -> Self {
        self.drop_height_ldu = ldu;
        self
    }
}

/// `v` when it is finite and at least `min`, else `fallback`.
fn sane(v: f32, min: f32, fallback: f32) -> f32 {
    if v.is_finite() && v >= min {
        v
    } else {
        fallback
    }
}

/// Writes `assembly` as a glTF 2.0 scene to `w` (any writer, also a
/// `&mut dyn Write` such as [`write_atomic`](crate::fsutil::write_atomic)
/// hands out).
///
/// Fails only when `w` fails, or (as [`io::ErrorKind::InvalidData`]) when a
/// binary file would pass the 4 GiB a `.glb` can hold.
pub fn write_gltf<W: Write + ?Sized>(
    w: &mut W,
    assembly: &Assembly,
    opts: &GltfOptions,
) -> io::Result<()> {
    let (root, bin) = document(assembly, opts);
    match opts.container {
        Container::Binary => write_glb(w, &root, &bin),
        Container::Embedded => {
            let mut root = root;
            if let Some(buffer) = root.buffers.first_mut() {
                let data = base64::engine::general_purpose::STANDARD.encode(&bin);
                buffer.uri = Some(format!("data:application/octet-stream;base64,{data}"));
            }
            serde_json::to_writer_pretty(&mut *w, &root).map_err(io::Error::other)?;
            w.write_all(b"\n")
        }
    }
}

fn write_glb<W: Write + ?Sized>(w: &mut W, root: &Root, bin: &[u8]) -> io::Result<()> {
    let mut json = serde_json::to_vec(root).map_err(io::Error::other)?;
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let bin_padded = bin.len().div_ceil(4) * 4;
    let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin_padded };
    let total = 12 + 8 + json.len() + bin_chunk;
    let too_big = || {
        io::Error::new(
            io::ErrorKind::InvalidData,
            "the model is too large for .glb",
        )
    };
    let total = u32::try_from(total).map_err(|_| too_big())?;
    let json_len = u32::try_from(json.len()).map_err(|_| too_big())?;
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&total.to_le_bytes())?;
    w.write_all(&json_len.to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&json)?;
    if !bin.is_empty() {
        let bin_len = u32::try_from(bin_padded).map_err(|_| too_big())?;
        w.write_all(&bin_len.to_le_bytes())?;
        w.write_all(b"BIN\0")?;
        w.write_all(bin)?;
        w.write_all(&[0u8; 3][..bin_padded - bin.len()])?;
    }
    Ok(())
}

/// An sRGB channel (0..=255) as linear light (0..=1).
fn srgb_to_linear(c: u8) -> f32 {
    let c = f32::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A piece's rotation as a glTF quaternion `[x, y, z, w]`: LDraw's turn
/// `rot` (`+X` to `+Z` for [`Rot::R90`]) is a turn about glTF's `+Y` by the
/// same angle.
fn rotation(rot: Rot) -> Option<[f32; 4]> {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    match rot {
        Rot::R0 => None,
        Rot::R90 => Some([0.0, s, 0.0, s]),
        Rot::R180 => Some([0.0, 1.0, 0.0, 0.0]),
        Rot::R270 => Some([0.0, -s, 0.0, s]),
    }
}

/// The JSON document and its binary buffer.
fn document(assembly: &Assembly, opts: &GltfOptions) -> (Root, Vec<u8>) {
    let mut bin = BinBuilder::default();

    // Geometry: one set of accessors per part type used, in catalog order.
    let parts: Vec<PartKind> = assembly
        .counts_by_part()
        .into_iter()
        .map(|(k, _)| k)
        .collect();
    let mut geometry: BTreeMap<PartKind, (u32, u32, u32)> = BTreeMap::new();
    for &part in &parts {
        geometry.insert(part, bin.part(part_mesh(part)));
    }

    // Materials, one per colour used, by LDraw code.
    let colors: Vec<Color> = {
        let mut c: Vec<Color> = assembly.pieces.iter().map(|p| p.color).collect();
        c.sort_unstable();
        c.dedup();
        c
    };
    let materials: Vec<Material> = colors
        .iter()
        .map(|&c| {
            let [r, g, b] = c.rgb().map(srgb_to_linear);
            Material {
                name: c.name(),
                pbr_metallic_roughness: Pbr {
                    base_color_factor: [r, g, b, 1.0],
                    metallic_factor: 0.0,
                    roughness_factor: 0.3,
                },
            }
        })
        .collect();

    // Meshes, one per (part, colour) pair, sharing the part's accessors.
    let mut pairs: Vec<(PartKind, Color)> = assembly
        .pieces
        .iter()
        .map(|p| (p.placement.part, p.color))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    let mut mesh_of: BTreeMap<(PartKind, Color), u32> = BTreeMap::new();
    let mut meshes = Vec::with_capacity(pairs.len());
    for (i, &(part, color)) in pairs.iter().enumerate() {
        let (position, normal, indices) = geometry.get(&part).copied().unwrap_or_default();
        let material = colors.binary_search(&color).unwrap_or(0) as u32;
        let spec = part.spec();
        meshes.push(Mesh {
            name: format!("{} {} · {}", spec.id, spec.name, color.name()),
            primitives: vec![Primitive {
                attributes: Attributes { position, normal },
                indices,
                material,
            }],
        });
        mesh_of.insert((part, color), i as u32);
    }

    // Nodes: the root first, then the pieces in build order.
    let offsets = match opts.layout {
        Layout::Assembled => vec![Vec3::ZERO; assembly.pieces.len()],
        Layout::Exploded => explode(assembly, &opts.explode),
    };
    let width = assembly.step_count().to_string().len().max(3);
    let mut nodes = Vec::with_capacity(assembly.pieces.len() + 1);
    nodes.push(Node {
        name: opts.name.clone(),
        children: (1..=assembly.pieces.len() as u32).collect(),
        ..Node::default()
    });
    let mut translations = Vec::with_capacity(assembly.pieces.len());
    for (p, &offset) in assembly.pieces.iter().zip(&offsets) {
        let spec = p.placement.part.spec();
        let origin = Vec3::from(piece_transform(&p.placement, assembly.layer_ldu).translation);
        let t = ldraw_to_gltf(origin + offset);
        translations.push(t);
        nodes.push(Node {
            name: format!("step {:0width$} · {} {}", p.step.0, spec.id, spec.name),
            mesh: mesh_of.get(&(p.placement.part, p.color)).copied(),
            translation: Some(t.to_array()),
            rotation: rotation(p.placement.rot),
            extras: Some(NodeExtras {
                step: p.step.0,
                part: spec.id.0,
                color: p.color.0,
            }),
            ..Node::default()
        });
    }

    let mut animations = Vec::new();
    if opts.animation == Animation::Build && !assembly.pieces.is_empty() {
        animations.push(build_animation(assembly, opts, &translations, &mut bin));
    }

    let buffers = if bin.data.is_empty() {
        Vec::new()
    } else {
        vec![Buffer {
            byte_length: bin.data.len(),
            uri: None,
        }]
    };
    let root = Root {
        asset: Asset {
            version: "2.0",
            generator: format!("brickwright {}", env!("CARGO_PKG_VERSION")),
        },
        scene: 0,
        scenes: vec![Scene {
            name: opts.name.clone(),
            nodes: vec![0],
        }],
        nodes,
        meshes,
        materials,
        accessors: bin.accessors,
        buffer_views: bin.views,
        buffers,
        animations,
    };
    (root, bin.data)
}

/// The `build` animation: per step one time accessor `[0, start, start +
/// drop]`; per piece a `STEP` scale channel (hidden, shown, shown) and a
/// `LINEAR` translation channel (above, above, in place).
fn build_animation(
    assembly: &Assembly,
    opts: &GltfOptions,
    translations: &[Vec3],
    bin: &mut BinBuilder,
) -> AnimationJson {
    let defaults = GltfOptions::default();
    let step = sane(opts.step_seconds, 0.01, defaults.step_seconds);
    let drop = sane(opts.drop_seconds, 0.01, defaults.drop_seconds);
    let height = sane(opts.drop_height_ldu, 0.0, defaults.drop_height_ldu) * METRES_PER_LDU;

    // Times, one accessor per step that has pieces, in one buffer view.
    let mut steps: Vec<u32> = assembly.pieces.iter().map(|p| p.step.0).collect();
    steps.dedup();
    let times: Vec<[f32; 3]> = steps
        .iter()
        .map(|&s| {
            // Step numbers start at 1, so every piece starts after t = 0.
            let start = s.max(1) as f32 * step;
            [0.0, start, start + drop]
        })
        .collect();
    let time_view = bin.view(times.iter().flatten().flat_map(|v| v.to_le_bytes()), None);
    let time_accessors: Vec<u32> = times
        .iter()
        .enumerate()
        .map(|(i, t)| {
            bin.accessor(Accessor {
                buffer_view: time_view,
                byte_offset: 12 * i,
                component_type: FLOAT,
                count: 3,
                kind: "SCALAR",
                min: Some(vec![t[0]]),
                max: Some(vec![t[2]]),
            })
        })
        .collect();

    // Scales, shared by every piece.
    let scales = [[0.0f32; 3], [1.0; 3], [1.0; 3]];
    let scale_view = bin.view(scales.iter().flatten().flat_map(|v| v.to_le_bytes()), None);
    let scale = bin.accessor(Accessor {
        buffer_view: scale_view,
        byte_offset: 0,
        component_type: FLOAT,
        count: 3,
        kind: "VEC3",
        min: None,
        max: None,
    });

    // Translations, three per piece, in one buffer view.
    let lift = Vec3::new(0.0, height, 0.0);
    let drops: Vec<[f32; 3]> = translations
        .iter()
        .flat_map(|&t| [(t + lift).to_array(), (t + lift).to_array(), t.to_array()])
        .collect();
    let drop_view = bin.view(drops.iter().flatten().flat_map(|v| v.to_le_bytes()), None);

    let mut channels = Vec::with_capacity(2 * assembly.pieces.len());
    let mut samplers = Vec::with_capacity(2 * assembly.pieces.len());
    for (i, p) in assembly.pieces.iter().enumerate() {
        let k = steps.binary_search(&p.step.0).unwrap_or(0);
        let input = time_accessors.get(k).copied().unwrap_or(0);
        let output = bin.accessor(Accessor {
            buffer_view: drop_view,
            byte_offset: 36 * i,
            component_type: FLOAT,
            count: 3,
            kind: "VEC3",
            min: None,
            max: None,
        });
        let node = i as u32 + 1;
        for (path, output, interpolation) in
            [("scale", scale, "STEP"), ("translation", output, "LINEAR")]
        {
            channels.push(Channel {
                sampler: samplers.len() as u32,
                target: Target { node, path },
            });
            samplers.push(Sampler {
                input,
                interpolation,
                output,
            });
        }
    }
    AnimationJson {
        name: "build".into(),
        channels,
        samplers,
    }
}

const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// The binary buffer, its views and accessors, as they are appended.
#[derive(Default)]
struct BinBuilder {
    data: Vec<u8>,
    views: Vec<BufferView>,
    accessors: Vec<Accessor>,
}

impl BinBuilder {
    /// Appends `bytes` as a new buffer view, 4-byte aligned.
    fn view(&mut self, bytes: impl IntoIterator<Item = u8>, target: Option<u32>) -> u32 {
        while !self.data.len().is_multiple_of(4) {
            self.data.push(0);
        }
        let start = self.data.len();
        self.data.extend(bytes);
        self.views.push(BufferView {
            buffer: 0,
            byte_offset: start,
            byte_length: self.data.len() - start,
            target,
        });
        self.views.len() as u32 - 1
    }

    fn accessor(&mut self, a: Accessor) -> u32 {
        self.accessors.push(a);
        self.accessors.len() as u32 - 1
    }

    /// A part's positions, normals and indices in glTF's frame; returns
    /// their accessors.
    fn part(&mut self, mesh: &PartMesh) -> (u32, u32, u32) {
        let positions: Vec<Vec3> = mesh
            .positions
            .iter()
            .map(|&p| ldraw_to_gltf(Vec3::from(p)))
            .collect();
        let normals: Vec<Vec3> = mesh
            .normals
            .iter()
            .map(|&[x, y, z]| Vec3::new(x, -y, -z))
            .collect();
        let (lo, hi) = positions.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let vec3_view = |b: &mut BinBuilder, v: &[Vec3]| {
            let bytes = v
                .iter()
                .flat_map(|p| p.to_array())
                .flat_map(f32::to_le_bytes);
            b.view(bytes, Some(ARRAY_BUFFER))
        };
        let pv = vec3_view(self, &positions);
        let position = self.accessor(Accessor {
            buffer_view: pv,
            byte_offset: 0,
            component_type: FLOAT,
            count: positions.len(),
            kind: "VEC3",
            min: (!positions.is_empty()).then(|| lo.to_array().to_vec()),
            max: (!positions.is_empty()).then(|| hi.to_array().to_vec()),
        });
        let nv = vec3_view(self, &normals);
        let normal = self.accessor(Accessor {
            buffer_view: nv,
            byte_offset: 0,
            component_type: FLOAT,
            count: normals.len(),
            kind: "VEC3",
            min: None,
            max: None,
        });
        let short = mesh.positions.len() <= usize::from(u16::MAX);
        let iv = if short {
            let bytes = mesh.indices.iter().flat_map(|&i| (i as u16).to_le_bytes());
            self.view(bytes, Some(ELEMENT_ARRAY_BUFFER))
        } else {
            let bytes = mesh.indices.iter().flat_map(|&i| i.to_le_bytes());
            self.view(bytes, Some(ELEMENT_ARRAY_BUFFER))
        };
        let indices = self.accessor(Accessor {
            buffer_view: iv,
            byte_offset: 0,
            component_type: if short { UNSIGNED_SHORT } else { UNSIGNED_INT },
            count: mesh.indices.len(),
            kind: "SCALAR",
            min: None,
            max: None,
        });
        (position, normal, indices)
    }
}

// The JSON document: only what brickwright writes, in glTF's field names.

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Root {
    asset: Asset,
    scene: u32,
    scenes: Vec<Scene>,
    nodes: Vec<Node>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    meshes: Vec<Mesh>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    materials: Vec<Material>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    accessors: Vec<Accessor>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    buffer_views: Vec<BufferView>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    buffers: Vec<Buffer>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    animations: Vec<AnimationJson>,
}

#[derive(Serialize)]
struct Asset {
    version: &'static str,
    generator: String,
}

#[derive(Serialize)]
struct Scene {
    name: String,
    nodes: Vec<u32>,
}

#[derive(Serialize, Default)]
struct Node {
    name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    mesh: Option<u32>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    children: Vec<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    translation: Option<[f32; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    rotation: Option<[f32; 4]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    extras: Option<NodeExtras>,
}

#[derive(Serialize)]
struct NodeExtras {
    step: u32,
    part: &'static str,
    color: u16,
}

#[derive(Serialize)]
struct Mesh {
    name: String,
    primitives: Vec<Primitive>,
}

#[derive(Serialize)]
struct Primitive {
    attributes: Attributes,
    indices: u32,
    material: u32,
}

#[derive(Serialize)]
struct Attributes {
    #[serde(rename = "POSITION")]
    position: u32,
    #[serde(rename = "NORMAL")]
    normal: u32,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Material {
    name: String,
    pbr_metallic_roughness: Pbr,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Pbr {
    base_color_factor: [f32; 4],
    metallic_factor: f32,
    roughness_factor: f32,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Accessor {
    buffer_view: u32,
    #[serde(skip_serializing_if = "is_zero")]
    byte_offset: usize,
    component_type: u32,
    count: usize,
    #[serde(rename = "type")]
    kind: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    min: Option<Vec<f32>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    max: Option<Vec<f32>>,
}

fn is_zero(v: &usize) -> bool {
    *v == 0
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct BufferView {
    buffer: u32,
    byte_offset: usize,
    byte_length: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    target: Option<u32>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Buffer {
    byte_length: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    uri: Option<String>,
}

#[derive(Serialize)]
struct AnimationJson {
    name: String,
    channels: Vec<Channel>,
    samplers: Vec<Sampler>,
}

#[derive(Serialize)]
struct Channel {
    sampler: u32,
    target: Target,
}

#[derive(Serialize)]
struct Target {
    node: u32,
    path: &'static str,
}

#[derive(Serialize)]
struct Sampler {
    input: u32,
    interpolation: &'static str,
    output: u32,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Placement;
    use crate::catalog::PartKind;
    use crate::geom::Cell;
    use crate::ldraw::rot_matrix;
    use glam::{Mat3, Quat};

    fn small() -> Assembly {
        let part = |id| PartKind::from_id(id).unwrap();
        let order = [
            Placement::new(part("3001"), Cell::new(0, 0, 0), Rot::R0),
            Placement::new(part("3001"), Cell::new(2, 0, 2), Rot::R90),
            Placement::new(part("3039"), Cell::new(0, 0, 2), Rot::R180),
            Placement::new(part("3039"), Cell::new(4, 2, 4), Rot::R270),
        ];
        let mut asm = Assembly::from_order(&order, 12, Color::RED);
        asm.pieces[1].color = Color::WHITE;
        asm
    }

    fn parse(bytes: &[u8]) -> ::gltf::Gltf {
        ::gltf::Gltf::from_slice(bytes).unwrap()
    }

    #[test]
    fn rotations_match_ldraw_matrices_in_gltf_axes() {
        // C·R·C with C = diag(1, -1, -1), the LDraw-to-glTF half turn.
        let c = Mat3::from_diagonal(Vec3::new(1.0, -1.0, -1.0));
        for r in Rot::ALL {
            let m = rot_matrix(r);
            let col = |j: usize| Vec3::new(m[0][j] as f32, m[1][j] as f32, m[2][j] as f32);
            let want = c * Mat3::from_cols(col(0), col(1), col(2)) * c;
            let q = rotation(r).map_or(Quat::IDENTITY, Quat::from_array);
            let got = Mat3::from_quat(q);
            assert!(got.abs_diff_eq(want, 1e-6), "{r:?}: {got} vs {want}");
            assert!((q.length() - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn nodes_meshes_and_materials() {
        let asm = small();
        let mut out = Vec::new();
        write_gltf(&mut out, &asm, &GltfOptions::default().with_name("tiny")).unwrap();
        let doc = parse(&out);
        let nodes: Vec<_> = doc.nodes().collect();
        assert_eq!(nodes.len(), 5);
        assert_eq!(nodes[0].name(), Some("tiny"));
        assert_eq!(nodes[0].children().count(), 4);
        assert_eq!(
            nodes[3].name(),
            Some("step 003 · 3039 Slope Brick 45 2 x 2")
        );
        let extras = nodes[3].extras().as_ref().unwrap().get();
        assert_eq!(extras, r#"{"step":3,"part":"3039","color":4}"#);
        // 3001 red, 3001 white, 3039 red: three meshes over two geometries.
        assert_eq!(doc.meshes().count(), 3);
        let pos: Vec<usize> = doc
            .meshes()
            .map(|m| {
                m.primitives()
                    .next()
                    .unwrap()
                    .get(&::gltf::Semantic::Positions)
                    .unwrap()
                    .index()
            })
            .collect();
        assert_eq!(pos[0], pos[1]);
        assert_ne!(pos[0], pos[2]);
        let mats: Vec<_> = doc
            .materials()
            .map(|m| m.name().unwrap().to_string())
            .collect();
        assert_eq!(mats, ["Red", "White"]);
        let red = doc
            .materials()
            .next()
            .unwrap()
            .pbr_metallic_roughness()
            .base_color_factor();
        assert!((red[0] - srgb_to_linear(0xB4)).abs() < 1e-6 && red[1] == 0.0);
        assert!((srgb_to_linear(0xB4) - 0.456).abs() < 1e-3);
        assert_eq!(doc.animations().next().unwrap().name(), Some("build"));
        assert_eq!(doc.animations().next().unwrap().channels().count(), 8);
    }

    #[test]
    fn positions_are_ldraw_positions_in_metres() {
        let asm = small();
        let mut out = Vec::new();
        write_gltf(&mut out, &asm, &GltfOptions::default()).unwrap();
        let doc = parse(&out);
        for (p, node) in asm.pieces.iter().zip(doc.nodes().skip(1)) {
            let ldraw = Vec3::from(piece_transform(&p.placement, 12).translation);
            let (t, _, _) = node.transform().decomposed();
            assert_eq!(Vec3::from(t), ldraw_to_gltf(ldraw));
        }
        // A brick at the origin: its top at 24 LDU = 9.6 mm up.
        let t = Vec3::from(doc.nodes().nth(1).unwrap().transform().decomposed().0);
        assert!(t.abs_diff_eq(Vec3::new(0.016, 0.0096, -0.008), 1e-7), "{t}");
    }

    #[test]
    fn output_is_deterministic_and_both_containers_agree() {
        let asm = small();
        let opts = GltfOptions::default().with_exploded(true);
        let mut a = Vec::new();
        let mut b = Vec::new();
        write_gltf(&mut a, &asm, &opts).unwrap();
        write_gltf(&mut b, &asm, &opts).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.len() % 4, 0);
        assert_eq!(
            u32::from_le_bytes([a[8], a[9], a[10], a[11]]) as usize,
            a.len()
        );
        let mut text = Vec::new();
        let embedded = opts.clone().with_container(Container::Embedded);
        write_gltf(&mut text, &asm, &embedded).unwrap();
        let text = String::from_utf8(text).unwrap();
        assert!(text.contains("data:application/octet-stream;base64,"));
        let (d1, b1, _) = ::gltf::import_slice(&a).unwrap();
        let (d2, b2, _) = ::gltf::import_slice(text.as_bytes()).unwrap();
        assert_eq!(b1[0].0, b2[0].0);
        assert_eq!(d1.nodes().count(), d2.nodes().count());
    }

    #[test]
    fn animation_times_increase_and_pieces_drop_in_at_their_step() {
        let asm = small();
        let mut out = Vec::new();
        let opts = GltfOptions::default()
            .with_step_seconds(f32::NAN)
            .with_drop_seconds(-1.0);
        write_gltf(&mut out, &asm, &opts).unwrap();
        let (doc, buffers, _) = ::gltf::import_slice(&out).unwrap();
        let anim = doc.animations().next().unwrap();
        for ch in anim.channels() {
            let r = ch.reader(|b| Some(&buffers[b.index()]));
            let times: Vec<f32> = r.read_inputs().unwrap().collect();
            assert!(times.windows(2).all(|w| w[0] < w[1]), "{times:?}");
            let node = ch.target().node();
            let step = node.index() as f32; // one piece a step, nodes 1..
            assert_eq!(times, [0.0, 0.5 * step, 0.5 * step + 0.3]);
            match r.read_outputs().unwrap() {
                ::gltf::animation::util::ReadOutputs::Scales(s) => {
                    assert_eq!(s.collect::<Vec<_>>(), [[0.0; 3], [1.0; 3], [1.0; 3]]);
                }
                ::gltf::animation::util::ReadOutputs::Translations(t) => {
                    let t: Vec<[f32; 3]> = t.collect();
                    assert_eq!(t[2], node.transform().decomposed().0);
                    assert!((t[0][1] - t[2][1] - 72.0 * METRES_PER_LDU).abs() < 1e-6);
                }
                _ => panic!("unexpected channel"),
            }
        }
        // A still scene has no animation.
        let mut still = Vec::new();
        write_gltf(
            &mut still,
            &asm,
            &GltfOptions::default().with_animated(false),
        )
        .unwrap();
        assert_eq!(parse(&still).animations().count(), 0);
    }

    #[test]
    fn an_empty_assembly_is_a_valid_empty_scene() {
        let asm = Assembly {
            pieces: vec![],
            layer_ldu: 24,
        };
        for c in [Container::Binary, Container::Embedded] {
            let mut out = Vec::new();
            write_gltf(&mut out, &asm, &GltfOptions::default().with_container(c)).unwrap();
            let doc = parse(&out);
            assert_eq!(doc.nodes().count(), 1);
            assert_eq!(doc.buffers().count(), 0);
        }
    }
}
