//! glTF 2.0, as JSON (`.gltf`, buffers embedded as base64 or in side files)
//! or binary (`.glb`).
//!
//! The `gltf` crate parses and validates the document and fetches the
//! buffers; the vertex and index data are then read here, with every offset,
//! stride and length checked against the buffer, because a truncated or
//! hand-edited file must give an error, not a panic or garbage.
//!
//! What is read: every primitive of every mesh instanced by the default
//! scene (or the first scene, or — in a file with no scenes at all — every
//! mesh once, untransformed), with each node's transform composed down the
//! hierarchy. Triangle lists, strips and fans are kept; points and lines are
//! ignored.

use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use glam::{Mat4, Vec3};

use super::{finish, Location, Mesh, MeshError};

/// The most triangles a glTF file may expand to once its node instances are
/// applied, each node visit counting as one more; beyond this a file is
/// taken as malicious or broken (a few kilobytes of nodes that list each
/// other twice over name 2^63 instances).
const MAX_INSTANCED: u64 = 10_000_000;

/// Parses the glTF (JSON or binary) data in `bytes`, read from `path`.
/// Relative buffer URIs are resolved inside `path`'s folder only (see
/// [`super::buffers`]).
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Mesh, MeshError> {
    let malformed = |reason: String| MeshError::Malformed {
        at: Location::file(path),
        reason,
    };
    let invalid =
        |e: ::gltf::Error| malformed(format!("not a valid glTF 2.0 file ({e}); re-export it"));
    // gltf 1.4 subtracts the 12-byte header from a GLB's declared length
    // unchecked (an overflow panic with overflow checks on): check it here.
    if let Some(head) = bytes.strip_prefix(b"glTF") {
        let declared = head
            .get(4..8)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        match declared {
            Some(n) if n >= 12 => {}
            Some(n) => {
                return Err(malformed(format!(
                    "the GLB header declares a length of {n} bytes, less than the header itself; re-export it"
                )))
            }
            None => {
                return Err(malformed(
                    "too short for a GLB file (no whole header); re-export it".into(),
                ))
            }
        }
    }
    let ::gltf::Gltf { document, blob } =
        ::gltf::Gltf::from_slice_without_validation(bytes).map_err(invalid)?;
    // gltf-json 1.4's validator indexes the accessor list with each
    // primitive's POSITION index unchecked; check those first so a broken
    // file is an error rather than a panic.
    let root = document.into_json();
    let accessors = root.accessors.len();
    for (i, mesh) in root.meshes.iter().enumerate() {
        for p in &mesh.primitives {
            if let Some(bad) = p.attributes.values().find(|a| a.value() >= accessors) {
                return Err(malformed(format!(
                    "mesh {i} refers to accessor {} but there are only {accessors}; \
                     re-export it",
                    bad.value()
                )));
            }
        }
    }
    let document = ::gltf::Document::from_json(root).map_err(invalid)?;
    let base = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let buffers = super::buffers::load(&document, base, blob)
        .map_err(|e| malformed(format!("cannot load the glTF buffers: {e}")))?;
    let buffers: Vec<&[u8]> = buffers.iter().map(|b| &b[..]).collect();

    let mut raw = Mesh::default();
    raw.paint = Some(super::gltf_paint::materials(
        &document,
        &buffers,
        path,
        &mut raw.warnings,
    ));
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next());
    match scene {
        Some(scene) => {
            // What the walk will cost, counted before it starts.
            let cost = node_costs(&document).map_err(malformed)?;
            let total = scene
                .nodes()
                .fold(0u64, |t, n| t.saturating_add(cost[n.index()]));
            if total > MAX_INSTANCED {
                return Err(malformed(too_many()));
            }
            let mut warned = vec![false; document.meshes().len()];
            let mut stack: Vec<_> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
            while let Some((node, parent)) = stack.pop() {
                let m = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
                if let Some(mesh) = node.mesh() {
                    let first = !std::mem::replace(&mut warned[mesh.index()], true);
                    add_mesh(path, &mesh, m, &buffers, &mut raw, first).map_err(malformed)?;
                }
                stack.extend(node.children().map(|c| (c, m)));
            }
        }
        None => {
            for mesh in document.meshes() {
                add_mesh(path, &mesh, Mat4::IDENTITY, &buffers, &mut raw, true)
                    .map_err(malformed)?;
            }
        }
    }
    finish(path, raw)
}

/// The message for a scene past [`MAX_INSTANCED`].
fn too_many() -> String {
    format!(
        "more than {} million triangles and node visits once its nodes are instanced; \
         simplify the model or flatten its instances",
        MAX_INSTANCED / 1_000_000
    )
}

/// An upper bound on the triangles of one instance of `mesh`, from its
/// accessors' declared counts (no data read).
fn mesh_triangles(mesh: &::gltf::Mesh<'_>) -> u64 {
    mesh.primitives()
        .map(|p| {
            let n = match p.indices() {
                Some(a) => a.count(),
                None => p.get(&::gltf::Semantic::Positions).map_or(0, |a| a.count()),
            } as u64;
            match p.mode() {
                Mode::Triangles => n / 3,
                Mode::TriangleStrip | Mode::TriangleFan => n.saturating_sub(2),
                _ => 0,
            }
        })
        .fold(0, u64::saturating_add)
}

/// For each node, what walking its subtree once costs: one per node visit
/// plus the triangles of every mesh instance under it (saturating). Each
/// node is looked at once, whatever the number of paths to it, so a node
/// graph that names a node many times over is priced, not walked; a cycle
/// is an error.
fn node_costs(document: &::gltf::Document) -> Result<Vec<u64>, String> {
    let nodes: Vec<_> = document.nodes().collect();
    let tris: Vec<u64> = document.meshes().map(|m| mesh_triangles(&m)).collect();
    // 0: not seen, 1: on the path being walked, 2: done.
    let mut state = vec![0u8; nodes.len()];
    let mut cost = vec![0u64; nodes.len()];
    for root in 0..nodes.len() {
        if state[root] != 0 {
            continue;
        }
        // (node, whether its children are done)
        let mut stack = vec![(root, false)];
        while let Some((i, children_done)) = stack.pop() {
            if children_done {
                let own = 1 + nodes[i].mesh().map_or(0, |m| tris[m.index()]);
                cost[i] = nodes[i]
                    .children()
                    .fold(own, |t, c| t.saturating_add(cost[c.index()]));
                state[i] = 2;
                continue;
            }
            if state[i] != 0 {
                continue;
            }
            state[i] = 1;
            stack.push((i, true));
            for c in nodes[i].children() {
                match state[c.index()] {
                    0 => stack.push((c.index(), false)),
                    1 => return Err("the node hierarchy has a cycle; re-export the scene".into()),
                    _ => {}
                }
            }
        }
    }
    Ok(cost)
}

/// Appends every triangle primitive of `mesh`, transformed by `m`; `first`
/// for the mesh's first instance, the one whose notes become warnings
/// (naming `path`).
fn add_mesh(
    path: &Path,
    mesh: &::gltf::Mesh<'_>,
    m: Mat4,
    buffers: &[&[u8]],
    out: &mut Mesh,
    first: bool,
) -> Result<(), String> {
    let name = mesh.name().map_or_else(
        || format!("mesh {}", mesh.index()),
        |n| format!("mesh {n:?}"),
    );
    for prim in mesh.primitives() {
        let mode = prim.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            continue;
        }
        let here = |what: &str| format!("{name}, primitive {}: {what}", prim.index());
        let Some(pos) = prim.get(&::gltf::Semantic::Positions) else {
            return Err(here("no POSITION attribute"));
        };
        if pos.data_type() != DataType::F32 || pos.dimensions() != Dimensions::Vec3 {
            return Err(here(
                "positions are not 32-bit float triples (quantized meshes are not \
                 supported; re-export without compression)",
            ));
        }
        let mut positions = Vec::new();
        for_each_element(&pos, buffers, 12, |b| {
            let f = |i: usize| f32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
            positions.push(m.transform_point3(Vec3::new(f(0), f(4), f(8))));
        })
        .map_err(|e| here(&e))?;
        let indices: Vec<u32> = match prim.indices() {
            Some(acc) => {
                let size = match (acc.data_type(), acc.dimensions()) {
                    (DataType::U8, Dimensions::Scalar) => 1,
                    (DataType::U16, Dimensions::Scalar) => 2,
                    (DataType::U32, Dimensions::Scalar) => 4,
                    _ => return Err(here("indices are not unsigned integer scalars")),
                };
                let mut v = Vec::new();
                for_each_element(&acc, buffers, size, |b| {
                    v.push(match size {
                        1 => u32::from(b[0]),
                        2 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                    });
                })
                .map_err(|e| here(&e))?;
                v
            }
            None => (0..positions.len() as u32).collect(),
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(here(&format!(
                "vertex index {bad} is out of range ({} vertices)",
                positions.len()
            )));
        }
        let base = out.positions.len() as u32;
        let n = indices.len();
        let tris: Box<dyn Iterator<Item = [usize; 3]>> = match mode {
            Mode::TriangleStrip => Box::new((0..n.saturating_sub(2)).map(|i| {
                if i % 2 == 0 {
                    [i, i + 1, i + 2]
                } else {
                    [i + 1, i, i + 2]
                }
            })),
            Mode::TriangleFan => Box::new((1..n.saturating_sub(1)).map(|i| [0, i, i + 1])),
            _ => Box::new((0..n / 3).map(|i| [3 * i, 3 * i + 1, 3 * i + 2])),
        };
        let tris: Vec<[u32; 3]> = tris.map(|t| t.map(|k| indices[k])).collect();
        if let Some(paint) = out.paint.as_mut() {
            let (faces, note) = super::gltf_paint::faces(&prim, buffers, &tris, positions.len())
                .map_err(|e| here(&e))?;
            paint.faces.extend(faces);
            if let Some(note) = note.filter(|_| first) {
                out.warnings
                    .push(format!("{}: {}", path.display(), here(&note)));
            }
        }
        out.triangles
            .extend(tris.iter().map(|t| t.map(|i| i + base)));
        out.positions.extend(positions);
        if out.triangles.len() as u64 > MAX_INSTANCED {
            return Err(too_many());
        }
    }
    Ok(())
}

/// Calls `f` with the `size` bytes of each element of `acc`, checking every
/// offset against the buffer view and buffer.
pub(super) fn for_each_element(
    acc: &::gltf::Accessor<'_>,
    buffers: &[&[u8]],
    size: usize,
    mut f: impl FnMut(&[u8]),
) -> Result<(), String> {
    let count = acc.count();
    if acc.sparse().is_some() {
        return Err("sparse accessors are not supported; re-export without them".into());
    }
    let Some(view) = acc.view() else {
        // No buffer view: the spec says all zeros.
        if count > 1 << 24 {
            return Err(format!("accessor {} is too large", acc.index()));
        }
        (0..count).for_each(|_| f(&[0u8; 16][..size]));
        return Ok(());
    };
    let too_short = || {
        format!(
            "accessor {} reaches past the end of its buffer (file truncated?)",
            acc.index()
        )
    };
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "buffer view {} has a stride below the element size",
            view.index()
        ));
    }
    let data = buffers.get(view.buffer().index()).ok_or_else(too_short)?;
    let view_end = view
        .offset()
        .checked_add(view.length())
        .ok_or_else(too_short)?;
    let data = data.get(view.offset()..view_end).ok_or_else(too_short)?;
    if count == 0 {
        return Ok(());
    }
    let end = (count - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(acc.offset()))
        .and_then(|x| x.checked_add(size))
        .ok_or_else(too_short)?;
    if end > data.len() {
        return Err(too_short());
    }
    for i in 0..count {
        let at = acc.offset() + i * stride;
        f(&data[at..at + size]);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{cube, write};
    use super::super::{bounds, load, MeshError};
    use glam::Vec3;

    fn base64(bytes: &[u8]) -> String {
        const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut s = String::new();
        for c in bytes.chunks(3) {
            let n = (u32::from(c[0]) << 16)
                | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
                | u32::from(*c.get(2).unwrap_or(&0));
            for k in 0..4 {
                if k <= c.len() {
                    s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
                } else {
                    s.push('=');
                }
            }
        }
        s
    }

    /// The cube's positions (96 bytes) then its 36 u16 indices (72 bytes).
    fn cube_buffer() -> Vec<u8> {
        let (v, t) = cube();
        let mut b: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        b.extend(t.iter().flatten().flat_map(|&i| (i as u16).to_le_bytes()));
        b
    }

    /// A document with a parent node (translation) holding a child node
    /// (scale) with the cube as two primitives of six triangles each.
    fn cube_json(buffer_uri: Option<&str>) -> String {
        let uri = buffer_uri.map_or(String::new(), |u| format!(r#""uri": "{u}", "#));
        format!(
            r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [
    {{"translation": [10, 0, 0], "children": [1]}},
    {{"scale": [2, 2, 2], "mesh": 0}}
  ],
  "meshes": [{{"name": "cube", "primitives": [
    {{"attributes": {{"POSITION": 0}}, "indices": 1}},
    {{"attributes": {{"POSITION": 0}}, "indices": 2, "mode": 4}},
    {{"attributes": {{"POSITION": 0}}, "mode": 1}}
  ]}}],
  "buffers": [{{{uri}"byteLength": 168}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 96}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 72}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
      "min": [0, 0, 0], "max": [1, 1, 1]}},
    {{"bufferView": 1, "byteOffset": 0, "componentType": 5123, "count": 18, "type": "SCALAR"}},
    {{"bufferView": 1, "byteOffset": 36, "componentType": 5123, "count": 18, "type": "SCALAR"}}
  ]
}}"#
        )
    }

    fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
        let mut j = json.as_bytes().to_vec();
        while !j.len().is_multiple_of(4) {
            j.push(b' ');
        }
        let mut b = bin.to_vec();
        while !b.len().is_multiple_of(4) {
            b.push(0);
        }
        let total = 12 + 8 + j.len() + 8 + b.len();
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((j.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(j);
        out.extend((b.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(b);
        out
    }

    fn check_transformed_cube(m: &super::Mesh) {
        assert_eq!(m.triangles.len(), 12);
        // Each primitive brings its own copy of the shared vertices.
        assert_eq!(m.positions.len(), 16);
        let (lo, hi) = bounds(&m.positions);
        assert_eq!(lo, Vec3::new(10.0, 0.0, 0.0));
        assert_eq!(hi, Vec3::new(12.0, 2.0, 2.0));
    }

    #[test]
    fn loads_gltf_with_embedded_buffer_and_transforms() {
        let uri = format!(
            "data:application/octet-stream;base64,{}",
            base64(&cube_buffer())
        );
        let f = write("cube.gltf", cube_json(Some(&uri)).as_bytes());
        check_transformed_cube(&load(&f.path).unwrap());
    }

    #[test]
    fn loads_gltf_with_side_buffer() {
        let f = write("cube.gltf", cube_json(Some("cube.bin")).as_bytes());
        std::fs::write(f.path.with_file_name("cube.bin"), cube_buffer()).unwrap();
        check_transformed_cube(&load(&f.path).unwrap());
    }

    #[test]
    fn loads_glb() {
        let f = write("cube.GLB", &glb(&cube_json(None), &cube_buffer()));
        check_transformed_cube(&load(&f.path).unwrap());
    }

    #[test]
    fn strips_and_fans() {
        // A unit square as a 4-vertex strip, and as a fan, non-indexed.
        let pos: Vec<u8> = [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]]
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        for (mode, tris) in [(5, 2), (6, 2)] {
            let json = format!(
                r#"{{"asset": {{"version": "2.0"}},
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "mode": {mode}}}]}}],
  "buffers": [{{"byteLength": 48}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 48}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
      "min": [0, 0, 0], "max": [1, 1, 0]}}]}}"#
            );
            let f = write("s.glb", &glb(&json, &pos));
            let m = load(&f.path).unwrap();
            assert_eq!(m.triangles.len(), tris, "mode {mode}");
        }
    }

    #[test]
    fn garbage_and_truncated_files_are_errors_not_panics() {
        let f = write("junk.gltf", b"{ not json");
        let e = load(&f.path).unwrap_err();
        assert!(matches!(e, MeshError::Malformed { .. }), "{e}");
        assert!(e.to_string().starts_with(&format!("{}:", f.path.display())));

        let good = glb(&cube_json(None), &cube_buffer());
        for cut in (0..good.len()).step_by(7) {
            let f = write("cut.glb", &good[..cut]);
            assert!(load(&f.path).is_err(), "cut at {cut}");
        }
        // Corrupt single bytes all over the file.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..500 {
            let mut b = good.clone();
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let i = (state % b.len() as u64) as usize;
            b[i] = (state >> 56) as u8;
            let f = write("flip.glb", &b);
            let _ = load(&f.path);
        }
    }

    #[test]
    fn a_glb_declaring_less_than_its_header_is_an_error() {
        // Found by tests/fuzz.rs: a declared length under 12 bytes.
        let mut b = glb(&cube_json(None), &cube_buffer());
        for n in [0u32, 11] {
            b[8..12].copy_from_slice(&n.to_le_bytes());
            let f = write("short.glb", &b);
            let e = load(&f.path).unwrap_err().to_string();
            assert!(e.contains("declares a length of"), "{e}");
        }
        let f = write("stub.glb", b"glTF\x02\x00");
        assert!(load(&f.path).is_err());
    }

    #[test]
    fn accessor_past_buffer_end_is_an_error() {
        let json = cube_json(None).replace(r#""count": 8"#, r#""count": 800"#);
        let f = write("long.glb", &glb(&json, &cube_buffer()));
        let e = load(&f.path).unwrap_err();
        assert!(e.to_string().contains("long.glb"), "{e}");
    }

    #[test]
    fn nan_translation_is_an_error() {
        // JSON has no NaN; an overflowing scale gives infinities instead.
        let json = cube_json(None).replace("[2, 2, 2]", "[1e38, 1e38, 1e38]");
        let json = json.replace("[10, 0, 0]", "[0, 0, 0], \"scale\": [1e38, 1, 1]");
        let f = write("inf.glb", &glb(&json, &cube_buffer()));
        let e = load(&f.path).unwrap_err();
        assert!(matches!(e, MeshError::NonFinite { .. }), "{e}");
    }

    /// Loads a `.gltf` in `dir/model/` whose buffer URI is `uri`; `dir`
    /// also holds `outside.bin`, a valid cube buffer out of the folder.
    fn load_with_uri(dir: &std::path::Path, uri: &str) -> Result<super::Mesh, MeshError> {
        let model = dir.join("model");
        std::fs::create_dir_all(&model).unwrap();
        std::fs::write(dir.join("outside.bin"), cube_buffer()).unwrap();
        let path = model.join("m.gltf");
        std::fs::write(&path, cube_json(Some(uri))).unwrap();
        load(&path)
    }

    #[test]
    fn buffer_uris_stay_in_the_model_folder() {
        let dir = tempfile::tempdir().unwrap();
        let outside = dir.path().join("outside.bin");
        for uri in [
            "file:///etc/passwd".to_string(),
            "/etc/passwd".to_string(),
            "../outside.bin".to_string(),
            format!("file://{}", outside.display()),
            outside.display().to_string(),
        ] {
            let e = load_with_uri(dir.path(), &uri).unwrap_err().to_string();
            assert!(e.contains("m.gltf") && e.contains("buffer 0"), "{uri}: {e}");
            // Nothing of the file named leaks into the message.
            assert!(!e.contains("root:"), "{uri}: {e}");
        }
        // The same buffer inside the folder builds.
        std::fs::write(dir.path().join("model/inside.bin"), cube_buffer()).unwrap();
        check_transformed_cube(&load_with_uri(dir.path(), "inside.bin").unwrap());
    }

    #[cfg(unix)]
    #[test]
    fn devices_fifos_and_links_out_are_refused_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let model = dir.path().join("model");
        std::fs::create_dir_all(&model).unwrap();
        std::os::unix::fs::symlink("/dev/zero", model.join("zero.bin")).unwrap();
        std::os::unix::fs::symlink(dir.path().join("outside.bin"), model.join("out.bin")).unwrap();
        let fifo = model.join("fifo.bin");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        for uri in [
            "/dev/zero",
            "/dev/urandom",
            "zero.bin",
            "out.bin",
            "fifo.bin",
        ] {
            if uri == "fifo.bin" && !made.as_ref().is_ok_and(|s| s.success()) {
                continue;
            }
            // Returns (no hang on the FIFO, no endless read of /dev/zero).
            let e = load_with_uri(dir.path(), uri).unwrap_err().to_string();
            assert!(e.contains("buffer 0"), "{uri}: {e}");
        }
        // A device inside the folder is not a regular file.
        std::fs::remove_file(model.join("zero.bin")).unwrap();
        let e = std::fs::hard_link("/dev/null", model.join("null.bin"));
        if e.is_ok() {
            assert!(load_with_uri(dir.path(), "null.bin").is_err());
        }
        if made.is_ok_and(|s| s.success()) {
            let e = load_with_uri(dir.path(), "fifo.bin")
                .unwrap_err()
                .to_string();
            assert!(e.contains("not a regular file"), "{e}");
        }
    }

    #[test]
    fn a_buffer_is_read_no_further_than_its_byte_length() {
        let dir = tempfile::tempdir().unwrap();
        let model = dir.path().join("model");
        std::fs::create_dir_all(&model).unwrap();
        // A side file far longer than declared: only 168 bytes are taken.
        let mut long = cube_buffer();
        long.resize(1 << 20, 0xff);
        std::fs::write(model.join("long.bin"), &long).unwrap();
        check_transformed_cube(&load_with_uri(dir.path(), "long.bin").unwrap());
        // Shorter than declared: an error naming both lengths.
        std::fs::write(model.join("short.bin"), &cube_buffer()[..100]).unwrap();
        let e = load_with_uri(dir.path(), "short.bin")
            .unwrap_err()
            .to_string();
        assert!(e.contains("100") && e.contains("168"), "{e}");
    }
}
