//! Triangle meshes and their loaders (Wavefront OBJ, glTF 2.0, STL).
//!
//! Every loader returns one [`Mesh`]: a triangle soup in the file's own units
//! and axes, all parts and primitives merged, node transforms applied.
//!
//! [`load`] picks the loader from the file extension (case-insensitive):
//!
//! | extension       | reader   | what is kept                                        |
//! |-----------------|----------|-----------------------------------------------------|
//! | `.obj`          | `tobj`   | every object and group, polygons triangulated       |
//! | `.gltf`, `.glb` | `gltf`   | every primitive of the default (or first) scene      |
//! | `.stl`          | `stl_io` | every facet, ASCII or binary                        |
//!
//! Whatever the format, the result is checked the same way before it is
//! returned (see [`MeshError`] for the cases): every coordinate is finite,
//! every index is in range, degenerate triangles (two equal corners or zero
//! area) are dropped silently, vertices no triangle uses are removed, and the
//! mesh must be neither a single point nor absurdly large. The voxelizer can
//! therefore trust a loaded mesh.
//!
//! Bad input never panics: a truncated `.glb`, a binary file named `.obj` or
//! a face pointing past the vertex list each give a one-line error naming the
//! file (and, for OBJ, the line) and saying how to fix it.
//!
//! ```no_run
//! use brickwright::mesh;
//!
//! let mesh = mesh::load(std::path::Path::new("teapot.obj"))?;
//! println!("{} triangles", mesh.triangles.len());
//! # Ok::<(), mesh::MeshError>(())
//! ```

mod buffers;
mod gltf;
mod gltf_paint;
pub mod mtl;
mod obj;
pub mod paint;
mod stl;

pub use paint::{FacePaint, Material, Paint, Texture, Wrap};

use std::fmt;
use std::path::{Path, PathBuf};

use glam::Vec3;

/// A triangle mesh: positions and triangles indexing them, and the
/// surface's colours when the file has any.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions in the file's units and axes.
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// The surface's colours, one [`FacePaint`] per triangle; `None` when
    /// the file has none (STL, or an OBJ or glTF without materials or
    /// vertex colours).
    pub paint: Option<Paint>,
    /// What the loader could not use but built on anyway, one line each
    /// (e.g. a missing texture file, its material's colour standing in).
    pub warnings: Vec<String>,
}

impl Mesh {
    /// Whether the mesh carries colours of its own.
    pub fn has_color(&self) -> bool {
        self.paint.as_ref().is_some_and(Paint::has_color)
    }
}

/// The largest extent along any axis, in file units, that [`load`] accepts.
///
/// Larger meshes almost always come from a unit mix-up or a stray vertex.
pub const MAX_EXTENT: f32 = 1e7;

/// Where in an input file something went wrong: the path and, when known,
/// the 1-based line. Displays as `path` or `path:line`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file as given to [`load`].
    pub path: PathBuf,
    /// The 1-based line number, for text formats when it is known.
    pub line: Option<usize>,
}

impl Location {
    /// The whole file, no line.
    pub fn file(path: &Path) -> Self {
        Location {
            path: path.to_path_buf(),
            line: None,
        }
    }

    /// One line of the file.
    pub fn line(path: &Path, line: usize) -> Self {
        Location {
            path: path.to_path_buf(),
            line: Some(line),
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{l}", self.path.display()),
            None => write!(f, "{}", self.path.display()),
        }
    }
}

/// Why a mesh file could not be loaded. Every variant names the file; the
/// message is one line and says how to fix the input where that is possible.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be opened or read.
    #[error("{}: cannot read the file: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// The extension is not one of the supported formats.
    #[error(
        "{}: unknown mesh format {ext:?}; convert it to .obj, .gltf, .glb or .stl",
        path.display()
    )]
    UnknownFormat {
        /// The file.
        path: PathBuf,
        /// The extension found (empty when there is none).
        ext: String,
    },
    /// The content is not a valid file of its format (garbage, truncated,
    /// or a structure the loader cannot follow).
    #[error("{at}: {reason}")]
    Malformed {
        /// Where.
        at: Location,
        /// What is wrong, phrased for the user.
        reason: String,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("{at}: vertex has {what} coordinate; fix or remove the vertex in your modelling tool")]
    NonFinite {
        /// Where.
        at: Location,
        /// `"a NaN"` or `"an infinite"`.
        what: &'static str,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "{at}: vertex index {index} is out of range (the file has {count} vertices); \
         re-export the mesh"
    )]
    IndexOutOfRange {
        /// Where.
        at: Location,
        /// The index as written in the file.
        index: i64,
        /// How many vertices there are.
        count: usize,
    },
    /// No triangles are left (none in the file, or all degenerate).
    #[error("{at}: the mesh has no triangles{detail}; export surfaces, not points or lines")]
    Empty {
        /// Where.
        at: Location,
        /// Extra detail, e.g. how many degenerate triangles were dropped.
        detail: String,
    },
    /// Every vertex is at the same point.
    #[error("{at}: all vertices are at one point, so the mesh has no size; check the export")]
    ZeroExtent {
        /// Where.
        at: Location,
    },
    /// The mesh is larger than [`MAX_EXTENT`] along some axis.
    #[error(
        "{at}: the mesh is {extent:e} units across, more than the limit of 1e7; \
         rescale it or remove stray far-away vertices"
    )]
    TooLarge {
        /// Where.
        at: Location,
        /// The largest extent found.
        extent: f32,
    },
}

/// Loads a mesh file, choosing the format from its extension
/// (`.obj`, `.gltf`, `.glb`, `.stl`; case-insensitive).
///
/// The result holds only vertices that triangles use, no degenerate
/// triangles, finite coordinates and a size between zero and
/// [`MAX_EXTENT`]; anything else is a [`MeshError`].
pub fn load(path: &Path) -> Result<Mesh, MeshError> {
    let loader = loader(path)?;
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    loader(path, &bytes)
}

/// Parses `bytes` as the format `path`'s extension names, as [`load`] does
/// once it has read the file; `path` names the file in errors, and a glTF
/// file's buffer files are looked for in its folder.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<Mesh, MeshError> {
    loader(path)?(path, bytes)
}

/// A format's parser, chosen by `path`'s extension.
#[allow(clippy::type_complexity)]
fn loader(path: &Path) -> Result<fn(&Path, &[u8]) -> Result<Mesh, MeshError>, MeshError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let loader: fn(&Path, &[u8]) -> Result<Mesh, MeshError> = match ext.as_str() {
        "obj" => obj::parse,
        "gltf" | "glb" => self::gltf::parse,
        "stl" => stl::parse,
        _ => {
            return Err(MeshError::UnknownFormat {
                path: path.to_path_buf(),
                ext,
            })
        }
    };
    Ok(loader)
}

/// Checks and tidies a freshly read triangle soup (shared by every loader).
///
/// Rejects non-finite coordinates and out-of-range indices, drops degenerate
/// triangles, removes unused vertices, and rejects empty, point-sized and
/// absurdly large meshes.
pub(crate) fn finish(path: &Path, raw: Mesh) -> Result<Mesh, MeshError> {
    let at = || Location::file(path);
    if let Some(p) = raw.positions.iter().find(|p| !p.is_finite()) {
        let what = if p.is_nan() { "a NaN" } else { "an infinite" };
        return Err(MeshError::NonFinite { at: at(), what });
    }
    let count = raw.positions.len();
    if let Some(&i) = raw
        .triangles
        .iter()
        .flatten()
        .find(|&&i| i as usize >= count)
    {
        return Err(MeshError::IndexOutOfRange {
            at: at(),
            index: i64::from(i),
            count,
        });
    }
    let total = raw.triangles.len();
    if total > 0 {
        let (lo, hi) = raw.triangles.iter().flatten().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &i| {
                let p = raw.positions[i as usize];
                (lo.min(p), hi.max(p))
            },
        );
        if (hi - lo).max_element() == 0.0 {
            return Err(MeshError::ZeroExtent { at: at() });
        }
    }
    let mut remap = vec![u32::MAX; count];
    let mut mesh = Mesh {
        warnings: raw.warnings.clone(),
        positions: Vec::with_capacity(count),
        triangles: Vec::with_capacity(total),
        ..Mesh::default()
    };
    let mut faces = Vec::with_capacity(if raw.paint.is_some() { total } else { 0 });
    for (k, t) in raw.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|i| raw.positions[i as usize]);
        if a == b || b == c || a == c || (b - a).cross(c - a) == Vec3::ZERO {
            continue;
        }
        let tri = t.map(|i| {
            let slot = &mut remap[i as usize];
            if *slot == u32::MAX {
                *slot = mesh.positions.len() as u32;
                mesh.positions.push(raw.positions[i as usize]);
            }
            *slot
        });
        mesh.triangles.push(tri);
        if let Some(p) = &raw.paint {
            faces.push(p.faces.get(k).copied().unwrap_or_default());
        }
    }
    if let Some(p) = raw.paint {
        mesh.paint = Some(Paint { faces, ..p }).filter(Paint::has_color);
    }
    if mesh.triangles.is_empty() {
        let detail = if total > 0 {
            format!(" (all {total} were degenerate: zero area)")
        } else {
            String::new()
        };
        return Err(MeshError::Empty { at: at(), detail });
    }
    let (lo, hi) = bounds(&mesh.positions);
    let extent = (hi - lo).max_element();
    if extent > MAX_EXTENT {
        return Err(MeshError::TooLarge { at: at(), extent });
    }
    Ok(mesh)
}

/// The minimum and maximum corner of the points' bounding box
/// (`(+inf, -inf)` when there are none).
pub fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    points.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

#[cfg(test)]
pub(crate) mod test_util {
    //! Writes small mesh files for the loader tests.

    use std::path::PathBuf;

    /// A temporary directory holding one file; kept alive with the path.
    pub struct TempFile {
        _dir: tempfile::TempDir,
        /// The file's path.
        pub path: PathBuf,
    }

    /// Writes `bytes` to a fresh file called `name`.
    pub fn write(name: &str, bytes: &[u8]) -> TempFile {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        TempFile { _dir: dir, path }
    }

    /// A unit cube `[0,1]^3` as 8 corners and 12 outward-facing triangles.
    pub fn cube() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let v = (0..8)
            .map(|i| [(i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32])
            .collect();
        let t = vec![
            [0, 2, 1],
            [1, 2, 3], // z = 0
            [4, 5, 6],
            [5, 7, 6], // z = 1
            [0, 1, 4],
            [1, 5, 4], // y = 0
            [2, 6, 3],
            [3, 6, 7], // y = 1
            [0, 4, 2],
            [2, 4, 6], // x = 0
            [1, 3, 5],
            [3, 7, 5], // x = 1
        ];
        (v, t)
    }
}

#[cfg(test)]
mod tests {
    use super::test_util::write;
    use super::*;

    #[test]
    fn unknown_extension_names_file_and_formats() {
        let f = write("model.fbx", b"whatever");
        let e = load(&f.path).unwrap_err();
        assert!(matches!(e, MeshError::UnknownFormat { .. }), "{e}");
        let msg = e.to_string();
        assert!(msg.contains("model.fbx") && msg.contains(".obj"), "{msg}");
        let f = write("noext", b"whatever");
        assert!(matches!(
            load(&f.path),
            Err(MeshError::UnknownFormat { .. })
        ));
    }

    #[test]
    fn missing_file_is_io_error() {
        let e = load(Path::new("/nonexistent/dir/missing.obj")).unwrap_err();
        assert!(matches!(e, MeshError::Io { .. }), "{e}");
        assert!(e.to_string().contains("missing.obj"));
    }

    #[test]
    fn extension_is_case_insensitive() {
        let f = write("CUBE.OBJ", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        assert_eq!(load(&f.path).unwrap().triangles.len(), 1);
    }

    #[test]
    fn finish_drops_degenerate_and_unused() {
        let p = Path::new("x.obj");
        let raw = Mesh {
            positions: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::Y,
                Vec3::splat(9.0),
                Vec3::X * 2.0,
            ],
            triangles: vec![[0, 1, 2], [0, 0, 1], [0, 1, 4]],
            ..Mesh::default()
        };
        let m = finish(p, raw).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        assert_eq!(m.positions, vec![Vec3::ZERO, Vec3::X, Vec3::Y]);
    }

    #[test]
    fn finish_rejects_bad_meshes() {
        let p = Path::new("bad.stl");
        let tri = |a: Vec3, b: Vec3, c: Vec3| Mesh {
            positions: vec![a, b, c],
            triangles: vec![[0, 1, 2]],
            ..Mesh::default()
        };
        let e = finish(p, tri(Vec3::ZERO, Vec3::X, Vec3::Y * 2e7)).unwrap_err();
        assert!(matches!(e, MeshError::TooLarge { .. }), "{e}");
        let e = finish(p, tri(Vec3::ZERO, Vec3::X, Vec3::NAN)).unwrap_err();
        assert!(e.to_string().contains("NaN"), "{e}");
        let e = finish(p, tri(Vec3::ONE, Vec3::ONE, Vec3::ONE)).unwrap_err();
        assert!(matches!(e, MeshError::ZeroExtent { .. }), "{e}");
        let e = finish(p, tri(Vec3::ZERO, Vec3::X, Vec3::X * 2.0)).unwrap_err();
        assert!(matches!(e, MeshError::Empty { .. }), "{e}");
        assert!(e.to_string().contains("degenerate"), "{e}");
        let e = finish(p, Mesh::default()).unwrap_err();
        assert!(matches!(e, MeshError::Empty { .. }), "{e}");
        let mut m = tri(Vec3::ZERO, Vec3::X, Vec3::Y);
        m.triangles[0][2] = 7;
        let e = finish(p, m).unwrap_err();
        assert!(
            matches!(e, MeshError::IndexOutOfRange { index: 7, .. }),
            "{e}"
        );
    }
}
