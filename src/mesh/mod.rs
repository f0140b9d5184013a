//! Triangle meshes and their loaders (Wavefront OBJ, glTF 2.0, STL).
//!
//! Every loader returns one [`Mesh`]: a triangle soup in the file's own units
//! and axes, all parts and primitives merged, node transforms applied.

use glam::Vec3;

/// A triangle mesh: positions and triangles indexing them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions in the file's units and axes.
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}
