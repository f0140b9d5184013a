//! Coloured fixtures: a two-material OBJ with its MTL, a vertex-coloured OBJ
//! and two textured GLBs. Each is an 8 x 6 x 4 box (y up), coloured so that a
//! test can check the build region by region; the colours are exact LEGO
//! colours (LDConfig sRGB), so the nearest catalog colour is known.

use std::fmt::Write as _;

use crate::formats::{decimal, glb, position_f32};
use crate::mesh::{quantize, Mesh};

/// LDraw 4, Red, as sRGB.
const RED: [u8; 3] = [0xB4, 0x00, 0x00];
/// LDraw 1, Blue.
const BLUE: [u8; 3] = [0x1E, 0x5A, 0xA8];
/// LDraw 14, Yellow.
const YELLOW: [u8; 3] = [0xFA, 0xC8, 0x0A];
/// LDraw 2, Green.
const GREEN: [u8; 3] = [0x00, 0x85, 0x2B];
/// LDraw 15, White.
const WHITE: [u8; 3] = [0xF4, 0xF4, 0xF4];

/// The box's far corner; the near one is the origin.
const SIZE: [f64; 3] = [8.0, 6.0, 4.0];

/// An sRGB byte as an exact-enough decimal fraction for `Kd` and vertex
/// colours (six digits).
fn unit(c: u8) -> String {
    decimal(quantize(f64::from(c) / 255.0))
}

/// The closed box, its side faces split at `y = 3` so that the lower and
/// upper halves are separate faces (no face crosses the split).
pub fn split_box() -> Mesh {
    let mut m = Mesh::default();
    m.add_box([0.0; 3], [SIZE[0], 3.0, SIZE[2]]);
    m.add_box([0.0, 3.0, 0.0], SIZE);
    let mid = quantize(3.0);
    let positions = m.positions.clone();
    m.triangles
        .retain(|t| !t.iter().all(|&i| positions[i as usize][1] == mid));
    m
}

/// `two_tone.obj` and `two_tone.mtl`: the lower half red, the upper half
/// blue, as two materials.
pub fn two_tone() -> (Mesh, String, String) {
    let m = split_box();
    let mut obj = String::from(
        "# brickwright fixture: an 8 x 6 x 4 box, lower half material red, upper half blue\n\
         mtllib two_tone.mtl\no two_tone\n",
    );
    for p in &m.positions {
        writeln!(
            obj,
            "v {} {} {}",
            decimal(p[0]),
            decimal(p[1]),
            decimal(p[2])
        )
        .unwrap();
    }
    let mid = quantize(3.0);
    let upper = |t: &[u32; 3]| t.iter().any(|&i| m.positions[i as usize][1] > mid);
    for (name, want) in [("red", false), ("blue", true)] {
        writeln!(obj, "usemtl {name}").unwrap();
        for t in m.triangles.iter().filter(|t| upper(t) == want) {
            writeln!(obj, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
        }
    }
    let mut mtl = String::from("# brickwright fixture: the materials of two_tone.obj\n");
    for (name, rgb) in [("red", RED), ("blue", BLUE)] {
        writeln!(
            mtl,
            "newmtl {name}\nKa 0 0 0\nKd {} {} {}\nKs 0 0 0\nillum 1",
            unit(rgb[0]),
            unit(rgb[1]),
            unit(rgb[2])
        )
        .unwrap();
    }
    (m, obj, mtl)
}

/// `vertex_colors.obj`: the box with yellow corners at the bottom and blue
/// ones at the top (`v x y z r g b`), so the colour runs from yellow to blue
/// up the sides.
pub fn vertex_colors() -> (Mesh, String) {
    let mut m = Mesh::default();
    m.add_box([0.0; 3], SIZE);
    let mut obj = String::from(
        "# brickwright fixture: an 8 x 6 x 4 box, vertex colours yellow at y = 0, blue at y = 6\n\
         o vertex_colors\n",
    );
    for p in &m.positions {
        let c = if p[1] == 0 { YELLOW } else { BLUE };
        writeln!(
            obj,
            "v {} {} {} {} {} {}",
            decimal(p[0]),
            decimal(p[1]),
            decimal(p[2]),
            unit(c[0]),
            unit(c[1]),
            unit(c[2])
        )
        .unwrap();
    }
    for t in &m.triangles {
        writeln!(obj, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
    (m, obj)
}

/// `img` as PNG bytes.
fn png(img: &image::RgbImage) -> Vec<u8> {
    let mut out = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .expect("PNG encodes");
    out
}

/// A 2 x 1 PNG: a green texel, then a yellow one.
fn texture_png() -> Vec<u8> {
    png(&image::RgbImage::from_fn(2, 1, |x, _| {
        image::Rgb(if x == 0 { GREEN } else { YELLOW })
    }))
}

/// The white specks of `speckled.glb`'s texture, texel `(x, row)` with row
/// 0 at the top of the box.
pub const SPECKS: [(u32, u32); 4] = [(3, 2), (6, 7), (12, 8), (9, 1)];

/// The yellow patch of `speckled.glb`'s texture: texels `x0..x1` by rows
/// `r0..r1`.
pub const PATCH: (u32, u32, u32, u32) = (9, 13, 3, 7);

/// A 16 x 10 PNG: red, with single white texels at [`SPECKS`] and a 4 x 4
/// yellow patch at [`PATCH`].
fn speckled_png() -> Vec<u8> {
    let (x0, x1, r0, r1) = PATCH;
    png(&image::RgbImage::from_fn(16, 10, |x, r| {
        image::Rgb(if SPECKS.contains(&(x, r)) {
            WHITE
        } else if (x0..x1).contains(&x) && (r0..r1).contains(&r) {
            YELLOW
        } else {
            RED
        })
    }))
}

/// `textured.glb`: the box with a 2 x 1 texture (green, yellow) mapped by
/// `u = x / 8`, sampled with clamp-to-edge, so the half `x < 4` is green and
/// the half `x > 4` yellow, the `x = 8` end too (it would be green if the
/// sampler repeated).
pub fn textured() -> (Mesh, Vec<u8>) {
    textured_box(
        &texture_png(),
        |p| [p[0] / SIZE[0] as f32, 0.5],
        "green_yellow",
    )
}

/// `speckled.glb`: the box with a 16 x 10 texture mapped by `u = x / 8`,
/// `v = 1 - y / 6`: built 16 studs long, one texel a voxel on the sides
/// facing z (rows are layers, from the top), so the front and back show
/// red with four single white voxels and a 4 x 4 yellow patch.
pub fn speckled() -> (Mesh, Vec<u8>) {
    textured_box(
        &speckled_png(),
        |p| [p[0] / SIZE[0] as f32, 1.0 - p[1] / SIZE[1] as f32],
        "speckled",
    )
}

/// The box as a GLB whose material is the texture `png`, with texture
/// coordinates `uv` of each corner, sampled nearest with clamp-to-edge.
fn textured_box(png: &[u8], uv: impl Fn([f32; 3]) -> [f32; 2], material: &str) -> (Mesh, Vec<u8>) {
    let mut m = Mesh::default();
    m.add_box([0.0; 3], SIZE);
    let mut bin: Vec<u8> = Vec::new();
    for i in 0..m.positions.len() as u32 {
        bin.extend(position_f32(&m, i).iter().flat_map(|x| x.to_le_bytes()));
    }
    let uv_at = bin.len();
    for i in 0..m.positions.len() as u32 {
        for t in uv(position_f32(&m, i)) {
            bin.extend(t.to_le_bytes());
        }
    }
    let idx_at = bin.len();
    for t in &m.triangles {
        for &i in t {
            bin.extend((i as u16).to_le_bytes());
        }
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let png_at = bin.len();
    bin.extend(png);
    let n = m.positions.len();
    let json = format!(
        r#"{{"asset":{{"version":"2.0","generator":"brickwright make_fixtures"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"name":"box","mesh":0}}],"meshes":[{{"name":"box","primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2,"material":0}}]}}],"materials":[{{"name":"{material}","pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,1],"baseColorTexture":{{"index":0}},"metallicFactor":0}}}}],"textures":[{{"sampler":0,"source":0}}],"samplers":[{{"magFilter":9728,"minFilter":9728,"wrapS":33071,"wrapT":33071}}],"images":[{{"bufferView":3,"mimeType":"image/png"}}],"buffers":[{{"byteLength":{total}}}],"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{pos_len}}},{{"buffer":0,"byteOffset":{uv_at},"byteLength":{uv_len}}},{{"buffer":0,"byteOffset":{idx_at},"byteLength":{idx_len}}},{{"buffer":0,"byteOffset":{png_at},"byteLength":{png_len}}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3","min":[0,0,0],"max":[8,6,4]}},{{"bufferView":1,"componentType":5126,"count":{n},"type":"VEC2"}},{{"bufferView":2,"componentType":5123,"count":{count},"type":"SCALAR"}}]}}"#,
        total = bin.len(),
        pos_len = uv_at,
        uv_len = idx_at - uv_at,
        idx_len = m.triangles.len() * 6,
        png_len = png.len(),
        count = m.triangles.len() * 3,
    );
    (m, glb(&json, &bin))
}
