//! Writers for Wavefront OBJ, binary STL and the GLB container.

use std::fmt::Write as _;

use crate::mesh::{unquantize, Mesh, STEPS_PER_UNIT};

/// A grid coordinate as the shortest exact decimal ("2", "-0.5", "3.965779").
pub fn decimal(q: i64) -> String {
    let steps = STEPS_PER_UNIT.unsigned_abs();
    let sign = if q < 0 { "-" } else { "" };
    let (int, frac) = (q.unsigned_abs() / steps, q.unsigned_abs() % steps);
    if frac == 0 {
        return format!("{sign}{int}");
    }
    let digits = format!("{frac:06}");
    format!("{sign}{int}.{}", digits.trim_end_matches('0'))
}

/// The mesh as OBJ text: `comment` lines, an `o name` line, `v` lines, then
/// triangles as 1-based `f` lines.
pub fn obj(name: &str, comment: &str, mesh: &Mesh) -> String {
    let mut out = String::new();
    for line in comment.lines() {
        writeln!(out, "# {line}").unwrap();
    }
    writeln!(
        out,
        "# {} vertices, {} triangles",
        mesh.positions.len(),
        mesh.triangles.len()
    )
    .unwrap();
    writeln!(out, "o {name}").unwrap();
    for p in &mesh.positions {
        writeln!(
            out,
            "v {} {} {}",
            decimal(p[0]),
            decimal(p[1]),
            decimal(p[2])
        )
        .unwrap();
    }
    for t in &mesh.triangles {
        writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
    out
}

/// A vertex position in units, as `f32`.
pub fn position_f32(mesh: &Mesh, i: u32) -> [f32; 3] {
    mesh.positions[i as usize].map(|q| unquantize(q) as f32)
}

/// The mesh as binary STL: an 80-byte header (which must not start with
/// "solid"), a little-endian u32 triangle count, and 50 bytes per triangle
/// (normal, three vertices, a zero attribute count).
pub fn stl(header: &str, mesh: &Mesh) -> Vec<u8> {
    assert!(
        header.len() <= 80 && !header.starts_with("solid"),
        "bad STL header"
    );
    let mut out = header.as_bytes().to_vec();
    out.resize(80, b' ');
    out.extend_from_slice(&(mesh.triangles.len() as u32).to_le_bytes());
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| position_f32(mesh, i));
        let (u, v) = (
            [0, 1, 2].map(|i| b[i] - a[i]),
            [0, 1, 2].map(|i| c[i] - a[i]),
        );
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        for x in n.map(|x| x / len).iter().chain(&a).chain(&b).chain(&c) {
            out.extend_from_slice(&x.to_le_bytes());
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    out
}

/// A GLB file: 12-byte header, a JSON chunk padded with spaces and a BIN
/// chunk padded with zeros, both to 4 bytes.
pub fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut json = json.as_bytes().to_vec();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    for (kind, data) in [(b"JSON", &json), (b"BIN\0", &bin)] {
        out.extend_from_slice(&(data.len() as u32).to_le_bytes());
        out.extend_from_slice(kind);
        out.extend_from_slice(data);
    }
    out
}
