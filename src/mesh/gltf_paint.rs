//! glTF colours: each material's `baseColorFactor` and `baseColorTexture`
//! (its image, texture coordinate set and sampler wrap modes), and each
//! primitive's `COLOR_0`, read into a [`Paint`].
//!
//! Images are decoded from a buffer view, a `data:` URI, or a file next to
//! the model (never outside its folder). An image that cannot be had is a
//! warning naming it; the material's factor stands in.

use std::collections::HashMap;
use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::texture::WrappingMode;
use base64::Engine as _;

use super::paint::{
    inside_folder, read_side_file, Material, Paint, TextureBudget, Wrap, MAX_SIDE_FILE,
};
use super::FacePaint;

/// The largest image file or `data:` URI decoded, in bytes.
const MAX_IMAGE_BYTES: usize = MAX_SIDE_FILE as usize;

/// The document's materials, in order (triangles name them by index), with
/// the textures of those some primitive uses decoded: each image once per
/// wrap mode however many textures name it, all under one
/// [`TextureBudget`].
pub(super) fn materials(
    document: &::gltf::Document,
    buffers: &[&[u8]],
    path: &Path,
    warnings: &mut Vec<String>,
) -> Paint {
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut paint = Paint::default();
    let mut used = vec![false; document.materials().len()];
    for mesh in document.meshes() {
        for prim in mesh.primitives() {
            if let Some(u) = prim.material().index().and_then(|i| used.get_mut(i)) {
                *u = true;
            }
        }
    }
    let mut budget = TextureBudget::default();
    let mut decoded: HashMap<(usize, [Wrap; 2]), Option<usize>> = HashMap::new();
    for m in document.materials() {
        let pbr = m.pbr_metallic_roughness();
        let f = pbr.base_color_factor();
        let mut texture = None;
        let info = pbr
            .base_color_texture()
            .filter(|_| m.index().is_some_and(|i| used[i]));
        if let Some(info) = info {
            let t = info.texture();
            let image = t.source();
            let s = t.sampler();
            let wraps = [wrap(s.wrap_s()), wrap(s.wrap_t())];
            texture = *decoded.entry((image.index(), wraps)).or_insert_with(|| {
                let got = image_bytes(&image, buffers, folder).and_then(|b| budget.decode(&b));
                match got {
                    Ok(mut tex) => {
                        tex.wrap = wraps;
                        paint.textures.push(tex);
                        Some(paint.textures.len() - 1)
                    }
                    Err(why) => {
                        let name = image.name().map_or_else(
                            || format!("image {}", image.index()),
                            |n| format!("image {n:?}"),
                        );
                        warnings.push(format!(
                            "{}: {name} {why}; the material's base colour stands in",
                            path.display()
                        ));
                        None
                    }
                }
            });
        }
        paint.materials.push(Material {
            name: m.name().unwrap_or_default().to_string(),
            color: [f[0], f[1], f[2]],
            texture,
            flip_v: false,
        });
    }
    paint
}

/// A glTF sampler's wrap mode.
fn wrap(m: WrappingMode) -> Wrap {
    match m {
        WrappingMode::ClampToEdge => Wrap::Clamp,
        WrappingMode::MirroredRepeat => Wrap::Mirror,
        WrappingMode::Repeat => Wrap::Repeat,
    }
}

/// The encoded bytes of `image`.
fn image_bytes(
    image: &::gltf::image::Image<'_>,
    buffers: &[&[u8]],
    folder: &Path,
) -> Result<Vec<u8>, String> {
    match image.source() {
        ::gltf::image::Source::View { view, .. } => {
            let data = buffers
                .get(view.buffer().index())
                .ok_or("refers to a missing buffer")?;
            let end = view
                .offset()
                .checked_add(view.length())
                .ok_or("reaches past its buffer")?;
            Ok(data
                .get(view.offset()..end)
                .ok_or("reaches past its buffer")?
                .to_vec())
        }
        ::gltf::image::Source::Uri { uri, .. } => {
            if let Some(rest) = uri.strip_prefix("data:") {
                let (_, b64) = rest
                    .split_once(";base64,")
                    .ok_or("has a data URI that is not base64")?;
                if b64.len() / 4 * 3 > MAX_IMAGE_BYTES {
                    return Err("is too large".into());
                }
                return base64::engine::general_purpose::STANDARD
                    .decode(b64.trim())
                    .map_err(|e| format!("has a bad data URI ({e})"));
            }
            let name = percent_decode(uri);
            let p = inside_folder(folder, &name)
                .ok_or_else(|| format!("file {name:?} is outside the model's folder"))?;
            read_side_file(&p, MAX_SIDE_FILE).map_err(|why| format!("file {name:?} {why}"))
        }
    }
}

/// `%20` and the like in a relative URI.
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() && s.is_char_boundary(i + 3) {
            if let Ok(v) = u8::from_str_radix(&s[i + 1..i + 3], 16) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The paint of each triangle `tris` (corner indices into the primitive's
/// `vertices`) of `prim`: its material, texture coordinates (the set its
/// material samples) and `COLOR_0`; and a note when some of it is ignored
/// (a `COLOR_0` or texture coordinate list shorter than the vertex list).
pub(super) fn faces(
    prim: &::gltf::Primitive<'_>,
    buffers: &[&[u8]],
    tris: &[[u32; 3]],
    vertices: usize,
) -> Result<(Vec<FacePaint>, Option<String>), String> {
    let material = prim.material().index().map(|i| i as u32);
    let set = prim
        .material()
        .pbr_metallic_roughness()
        .base_color_texture()
        .map(|i| i.tex_coord());
    let uvs = match set {
        Some(s) => match prim.get(&::gltf::Semantic::TexCoords(s)) {
            Some(acc) => Some(read_floats(&acc, buffers, 2)?),
            None => None,
        },
        None => None,
    };
    let colors = match prim.get(&::gltf::Semantic::Colors(0)) {
        Some(acc) => {
            let n = match acc.dimensions() {
                Dimensions::Vec3 => 3,
                Dimensions::Vec4 => 4,
                _ => return Err("COLOR_0 is not VEC3 or VEC4".into()),
            };
            Some((read_floats(&acc, buffers, n)?, n))
        }
        None => None,
    };
    let mut note = None;
    if let Some((c, n)) = &colors {
        if c.len() / n < vertices {
            note = Some(format!(
                "COLOR_0 has {} colours for {vertices} vertices; the triangles past it are \
                 not vertex-coloured (re-export the colours)",
                c.len() / n
            ));
        }
    }
    if let Some(u) = &uvs {
        if u.len() / 2 < vertices && note.is_none() {
            note = Some(format!(
                "the texture coordinates number {} for {vertices} vertices; the triangles \
                 past them are not textured (re-export the model)",
                u.len() / 2
            ));
        }
    }
    let corner = |v: &[f32], n: usize, i: u32| -> Option<Vec<f32>> {
        let i = i as usize * n;
        v.get(i..i + n).map(<[f32]>::to_vec)
    };
    let faces = tris
        .iter()
        .map(|t| FacePaint {
            material,
            uv: uvs.as_ref().and_then(|u| {
                let c = t.map(|i| corner(u, 2, i));
                let [a, b, c] = c;
                Some([a?, b?, c?].map(|v| [v[0], v[1]]))
            }),
            color: colors.as_ref().and_then(|(v, n)| {
                let [a, b, c] = t.map(|i| corner(v, *n, i));
                Some([a?, b?, c?].map(|v| [v[0], v[1], v[2]]))
            }),
        })
        .collect();
    Ok((faces, note))
}

/// An accessor of `n` components per element as floats: `f32`, or
/// normalized `u8` / `u16`.
fn read_floats(
    acc: &::gltf::Accessor<'_>,
    buffers: &[&[u8]],
    n: usize,
) -> Result<Vec<f32>, String> {
    let (size, scale) = match acc.data_type() {
        DataType::F32 => (4, 1.0),
        DataType::U8 => (1, 255.0),
        DataType::U16 => (2, 65535.0),
        _ => {
            return Err(format!(
                "accessor {} has an unsupported component type",
                acc.index()
            ))
        }
    };
    let mut out = Vec::with_capacity(acc.count().min(1 << 24) * n);
    super::gltf::for_each_element(acc, buffers, size * n, |b| {
        for k in 0..n {
            let c = &b[k * size..(k + 1) * size];
            out.push(match size {
                4 => f32::from_le_bytes([c[0], c[1], c[2], c[3]]),
                2 => f32::from(u16::from_le_bytes([c[0], c[1]])) / scale,
                _ => f32::from(c[0]) / scale,
            });
        }
    })?;
    if out.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "accessor {} has a NaN or infinite value",
            acc.index()
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{cube, write};
    use super::super::{load, Mesh};

    fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
        let mut j = json.as_bytes().to_vec();
        while !j.len().is_multiple_of(4) {
            j.push(b' ');
        }
        let mut b = bin.to_vec();
        while !b.len().is_multiple_of(4) {
            b.push(0);
        }
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(((28 + j.len() + b.len()) as u32).to_le_bytes());
        out.extend((j.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(j);
        out.extend((b.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(b);
        out
    }

    /// The unit cube twice: primitive 0 with `COLOR_0` (normalized u8
    /// RGBA: red at z = 0, green at z = 1) and no material, primitive 1
    /// with a material whose factor is blue and whose texture is a missing
    /// file.
    fn coloured_cube() -> Mesh {
        let (v, t) = cube();
        let mut b: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        for p in &v {
            b.extend(if p[2] == 0.0 {
                [255, 0, 0, 255]
            } else {
                [0, 255, 0, 255]
            });
        }
        b.extend(t.iter().flatten().flat_map(|&i| (i as u16).to_le_bytes()));
        let json = r#"{"asset": {"version": "2.0"},
  "meshes": [{"primitives": [
    {"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2},
    {"attributes": {"POSITION": 0}, "indices": 2, "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 1, 1],
    "baseColorTexture": {"index": 0}}}],
  "textures": [{"source": 0}],
  "images": [{"uri": "missing.png"}],
  "buffers": [{"byteLength": 200}],
  "bufferViews": [{"buffer": 0, "byteLength": 96}, {"buffer": 0, "byteOffset": 96, "byteLength": 32},
    {"buffer": 0, "byteOffset": 128, "byteLength": 72}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
    {"bufferView": 1, "componentType": 5121, "normalized": true, "count": 8, "type": "VEC4"},
    {"bufferView": 2, "componentType": 5123, "count": 36, "type": "SCALAR"}]}"#;
        let f = write("coloured.glb", &glb(json, &b));
        load(&f.path).unwrap()
    }

    #[test]
    fn color_0_and_base_color_factor_for_every_primitive() {
        let m = coloured_cube();
        let paint = m.paint.as_ref().expect("colours are read");
        assert_eq!(m.triangles.len(), 24);
        assert_eq!(paint.faces.len(), 24);
        // The z = 0 face of primitive 0 (its first two triangles) is red.
        assert_eq!(paint.sample(0, [1.0 / 3.0; 3]), [1.0, 0.0, 0.0]);
        // Its z = 1 face is green.
        assert_eq!(paint.sample(2, [1.0 / 3.0; 3]), [0.0, 1.0, 0.0]);
        // Primitive 1: the material's factor, blue.
        assert_eq!(paint.sample(12, [1.0 / 3.0; 3]), [0.0, 0.0, 1.0]);
        // The missing texture is a warning naming it.
        assert_eq!(m.warnings.len(), 1, "{:?}", m.warnings);
        assert!(m.warnings[0].contains("missing.png"), "{:?}", m.warnings);
    }
}
