//! `tower.glb`: a glTF 2.0 scene whose shape is only right when a loader
//! applies node transforms and merges every primitive.
//!
//! - Node `base` (no transform) holds mesh `base`: a 6 x 2 x 4 box on the
//!   ground split into two primitives, sides and bottom (u16 indices) and the
//!   top face (u16 indices, its own vertices). Dropping a primitive opens it.
//! - Node `top_pivot` turns 90° about +y and has child `top`, which holds mesh
//!   `unit_cube` (u32 indices) with translation (0.5, 5, 0) and scale
//!   (3, 6, 2). In the world the cube becomes the box x in [-1, 1],
//!   y in [2, 8], z in [-2, 1], standing on the base. Without the rotation it
//!   would span x in [-1, 2], z in [-1, 1]; without any transform it would be
//!   a unit cube at the origin.
//!
//! The JSON is written by hand (fixed key order, Rust's shortest float
//! formatting) so the bytes never depend on serde_json features.

use glam::{Mat4, Quat, Vec3};

use crate::formats::{glb, position_f32};
use crate::mesh::{unquantize, Mesh};

/// Base box corners.
const BASE: ([f64; 3], [f64; 3]) = ([-3.0, 0.0, -2.0], [3.0, 2.0, 2.0]);
/// The top node's translation and scale.
const TOP_TRANSLATION: [f32; 3] = [0.5, 5.0, 0.0];
const TOP_SCALE: [f32; 3] = [3.0, 6.0, 2.0];

/// One primitive: positions and triangles indexing them.
struct Primitive {
    positions: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Primitive {
    /// The triangles of `mesh` that `keep` accepts, with only the vertices
    /// they use, renumbered in first-use order.
    fn select(mesh: &Mesh, keep: impl Fn(&[[f32; 3]; 3]) -> bool) -> Self {
        let mut remap = vec![None; mesh.positions.len()];
        let mut prim = Primitive {
            positions: Vec::new(),
            triangles: Vec::new(),
        };
        for t in &mesh.triangles {
            if !keep(&t.map(|i| position_f32(mesh, i))) {
                continue;
            }
            let tri = t.map(|i| {
                *remap[i as usize].get_or_insert_with(|| {
                    prim.positions.push(position_f32(mesh, i));
                    prim.positions.len() as u32 - 1
                })
            });
            prim.triangles.push(tri);
        }
        prim
    }

    fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        for p in &self.positions {
            for i in 0..3 {
                min[i] = min[i].min(p[i]);
                max[i] = max[i].max(p[i]);
            }
        }
        (min, max)
    }
}

fn floats(v: &[f32]) -> String {
    let items: Vec<String> = v.iter().map(|x| x.to_string()).collect();
    format!("[{}]", items.join(","))
}

/// Appends `bytes` to `bin` at a 4-byte boundary and returns the offset.
fn append(bin: &mut Vec<u8>, bytes: &[u8]) -> usize {
    bin.resize(bin.len().next_multiple_of(4), 0);
    let at = bin.len();
    bin.extend_from_slice(bytes);
    at
}

fn top_pivot_rotation() -> Quat {
    Quat::from_xyzw(
        0.0,
        std::f32::consts::FRAC_1_SQRT_2,
        0.0,
        std::f32::consts::FRAC_1_SQRT_2,
    )
}

/// The GLB bytes, and the same scene flattened to world space for checking.
pub fn build() -> (Vec<u8>, Mesh) {
    let mut base = Mesh::default();
    base.add_box(BASE.0, BASE.1);
    let top_y = BASE.1[1] as f32;
    let on_top = |t: &[[f32; 3]; 3]| t.iter().all(|p| p[1] == top_y);
    let base_prims = [
        Primitive::select(&base, |t| !on_top(t)),
        Primitive::select(&base, on_top),
    ];
    let mut cube = Mesh::default();
    cube.add_box([-0.5; 3], [0.5; 3]);
    let cube_prim = Primitive::select(&cube, |_| true);

    // BIN layout: all positions (view 0), u16 indices (view 1), u32 indices (view 2).
    let prims = [&base_prims[0], &base_prims[1], &cube_prim];
    let mut positions = Vec::new();
    let mut position_offsets = Vec::new();
    for prim in prims {
        position_offsets.push(positions.len());
        positions.extend(
            prim.positions
                .iter()
                .flatten()
                .flat_map(|x| x.to_le_bytes()),
        );
    }
    let mut short = Vec::new();
    let mut short_offsets = Vec::new();
    for prim in &base_prims {
        short_offsets.push(short.len());
        let indices = prim
            .triangles
            .iter()
            .flatten()
            .map(|&i| u16::try_from(i).unwrap());
        short.extend(indices.flat_map(u16::to_le_bytes));
    }
    let long: Vec<u8> = cube_prim
        .triangles
        .iter()
        .flatten()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    let mut bin = Vec::new();
    let views = [
        (append(&mut bin, &positions), positions.len(), 34962),
        (append(&mut bin, &short), short.len(), 34963),
        (append(&mut bin, &long), long.len(), 34963),
    ];

    let mut accessors = Vec::new();
    for (prim, offset) in prims.iter().zip(&position_offsets) {
        let (min, max) = prim.bounds();
        accessors.push(format!(
            r#"{{"bufferView":0,"byteOffset":{offset},"componentType":5126,"count":{},"type":"VEC3","min":{},"max":{}}}"#,
            prim.positions.len(),
            floats(&min),
            floats(&max)
        ));
    }
    for (prim, offset) in base_prims.iter().zip(&short_offsets) {
        accessors.push(format!(
            r#"{{"bufferView":1,"byteOffset":{offset},"componentType":5123,"count":{},"type":"SCALAR"}}"#,
            prim.triangles.len() * 3
        ));
    }
    accessors.push(format!(
        r#"{{"bufferView":2,"byteOffset":0,"componentType":5125,"count":{},"type":"SCALAR"}}"#,
        cube_prim.triangles.len() * 3
    ));
    let views: Vec<String> = views
        .iter()
        .map(|(offset, len, target)| {
            // Several accessors share the vertex view, so it needs a stride.
            let stride = if *target == 34962 { r#","byteStride":12"# } else { "" };
            format!(
                r#"{{"buffer":0,"byteOffset":{offset},"byteLength":{len}{stride},"target":{target}}}"#
            )
        })
        .collect();
    let q = top_pivot_rotation();
    let json = [
        r#"{"asset":{"version":"2.0","generator":"brickwright examples/make_fixtures"},"#.to_string(),
        r#""scene":0,"scenes":[{"name":"tower","nodes":[0,1]}],"#.to_string(),
        r#""nodes":[{"name":"base","mesh":0},"#.to_string(),
        format!(r#"{{"name":"top_pivot","rotation":{},"children":[2]}},"#, floats(&q.to_array())),
        format!(
            r#"{{"name":"top","mesh":1,"translation":{},"scale":{}}}],"#,
            floats(&TOP_TRANSLATION),
            floats(&TOP_SCALE)
        ),
        r#""meshes":[{"name":"base","primitives":[{"attributes":{"POSITION":0},"indices":3,"mode":4},"#
            .to_string(),
        r#"{"attributes":{"POSITION":1},"indices":4,"mode":4}]},"#.to_string(),
        r#"{"name":"unit_cube","primitives":[{"attributes":{"POSITION":2},"indices":5,"mode":4}]}],"#
            .to_string(),
        format!(r#""accessors":[{}],"#, accessors.join(",")),
        format!(r#""bufferViews":[{}],"#, views.join(",")),
        format!(r#""buffers":[{{"byteLength":{}}}]}}"#, bin.len()),
    ]
    .concat();

    // The same scene in world space, welded, for the closedness check.
    let top = Mat4::from_quat(q)
        * Mat4::from_scale_rotation_translation(
            Vec3::from(TOP_SCALE),
            Quat::IDENTITY,
            Vec3::from(TOP_TRANSLATION),
        );
    let mut world = Mesh::default();
    for (prim, transform) in [
        (&base_prims[0], Mat4::IDENTITY),
        (&base_prims[1], Mat4::IDENTITY),
        (&cube_prim, top),
    ] {
        for t in &prim.triangles {
            let [a, b, c] = t.map(|i| {
                let p = transform.transform_point3(Vec3::from(prim.positions[i as usize]));
                world.vertex(p.to_array().map(f64::from))
            });
            world.triangle(a, b, c);
        }
    }
    (glb(&json, &bin), world)
}

/// World-space bounds of a mesh in units, for the summary.
pub fn bounds(mesh: &Mesh) -> ([f64; 3], [f64; 3]) {
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    for p in &mesh.positions {
        for i in 0..3 {
            min[i] = min[i].min(unquantize(p[i]));
            max[i] = max[i].max(unquantize(p[i]));
        }
    }
    (min, max)
}
