//! STL, ASCII (`solid ... facet ... vertex x y z`) or binary (an 80-byte
//! header, a triangle count, then 50 bytes a triangle), read by `stl_io`.
//!
//! STL stores each triangle's corners separately; `stl_io` welds corners
//! with identical coordinates, which is what the voxelizer wants. A binary
//! file whose length disagrees with its triangle count is reported as
//! truncated before reading, since `stl_io` would only say "failed to fill
//! whole buffer"; one holding more whole triangles than its count is an
//! error too (a reader trusting the count would build part of the mesh).

use std::io::Cursor;
use std::path::Path;

use glam::Vec3;

use super::{finish, Location, Mesh, MeshError};

/// Parses the STL data in `bytes` (read from `path`, used in messages).
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Mesh, MeshError> {
    let malformed = |reason: String| MeshError::Malformed {
        at: Location::file(path),
        reason,
    };
    let looks_ascii = bytes.trim_ascii_start().starts_with(b"solid");
    if !looks_ascii {
        if bytes.len() < 84 {
            return Err(malformed(format!(
                "too short for an STL file ({} bytes); re-export it",
                bytes.len()
            )));
        }
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        let have = (bytes.len() as u64 - 84) / 50;
        if have < n {
            return Err(malformed(format!(
                "binary STL is truncated: its header promises {n} triangles but the file \
                 holds {have}; re-export it"
            )));
        }
        if have > n {
            // Whole triangles past the count would be silently dropped:
            // a build of part of the mesh. (Less than one triangle of
            // trailing bytes is padding some exporters add.)
            return Err(malformed(format!(
                "binary STL header says {n} triangles but the file holds {have}; \
                 re-export it"
            )));
        }
    }
    let stl = stl_io::read_stl(&mut Cursor::new(bytes)).map_err(|e| {
        malformed(format!(
            "not a valid {} STL file ({e}); re-export it",
            if looks_ascii { "ASCII" } else { "binary" }
        ))
    })?;
    let raw = Mesh {
        positions: stl.vertices.iter().map(|v| Vec3::from_array(v.0)).collect(),
        triangles: stl
            .faces
            .iter()
            .map(|f| f.vertices.map(|i| i as u32))
            .collect(),
        ..Mesh::default()
    };
    finish(path, raw)
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{cube, write};
    use super::super::{load, MeshError};

    fn cube_triangles() -> Vec<stl_io::Triangle> {
        let (v, t) = cube();
        t.iter()
            .map(|tri| stl_io::Triangle {
                normal: stl_io::Normal::new([0.0; 3]),
                vertices: tri.map(|i| stl_io::Vertex::new(v[i as usize])),
            })
            .collect()
    }

    fn binary_cube() -> Vec<u8> {
        let mut out = Vec::new();
        stl_io::write_stl(&mut out, cube_triangles().iter()).unwrap();
        out
    }

    #[test]
    fn loads_binary_cube() {
        let f = write("cube.stl", &binary_cube());
        let m = load(&f.path).unwrap();
        assert_eq!((m.triangles.len(), m.positions.len()), (12, 8));
    }

    #[test]
    fn loads_ascii_cube() {
        let mut s = String::from("solid cube\n");
        for t in cube_triangles() {
            s += "  facet normal 0 0 0\n    outer loop\n";
            for v in t.vertices {
                s += &format!("      vertex {} {} {}\n", v[0], v[1], v[2]);
            }
            s += "    endloop\n  endfacet\n";
        }
        s += "endsolid cube\n";
        let f = write("cube.STL", s.as_bytes());
        let m = load(&f.path).unwrap();
        assert_eq!((m.triangles.len(), m.positions.len()), (12, 8));
    }

    #[test]
    fn truncated_and_garbage_files_are_errors() {
        let mut b = binary_cube();
        b.truncate(b.len() - 30);
        let f = write("cut.stl", &b);
        let e = load(&f.path).unwrap_err();
        assert!(matches!(e, MeshError::Malformed { .. }), "{e}");
        let msg = e.to_string();
        assert!(
            msg.contains("cut.stl") && msg.contains("truncated"),
            "{msg}"
        );

        let f = write("junk.stl", b"hello");
        assert!(matches!(load(&f.path), Err(MeshError::Malformed { .. })));
        let f = write("junk.stl", b"solid x\n facet normal a b c\n garbage\n");
        let e = load(&f.path).unwrap_err();
        assert!(matches!(e, MeshError::Malformed { .. }), "{e}");
        assert!(e.to_string().contains("junk.stl"));

        // A header count lower than the triangles held: an error, not a
        // build of the first few.
        let mut b = binary_cube();
        b[80..84].copy_from_slice(&5u32.to_le_bytes());
        let f = write("low.stl", &b);
        let e = load(&f.path).unwrap_err().to_string();
        assert!(
            e.contains("low.stl") && e.contains("says 5 triangles but the file holds 12"),
            "{e}"
        );
        // Trailing bytes short of a triangle are padding.
        let mut b = binary_cube();
        b.extend([0u8; 20]);
        let f = write("pad.stl", &b);
        assert_eq!(load(&f.path).unwrap().triangles.len(), 12);

        // A header claiming zero triangles: an empty mesh.
        let f = write("empty.stl", &[0u8; 84]);
        assert!(matches!(load(&f.path), Err(MeshError::Empty { .. })));
    }

    #[test]
    fn nan_vertex_is_an_error() {
        let mut tris = cube_triangles();
        tris[3].vertices[1] = stl_io::Vertex::new([f32::NAN, 0.0, 0.0]);
        let mut out = Vec::new();
        stl_io::write_stl(&mut out, tris.iter()).unwrap();
        let f = write("nan.stl", &out);
        let e = load(&f.path).unwrap_err();
        assert!(matches!(e, MeshError::NonFinite { .. }), "{e}");
        assert!(e.to_string().contains("nan.stl: vertex has a NaN"), "{e}");
    }
}
