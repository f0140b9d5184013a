//! Exporters that draw the build: part meshes, exploded views and glTF 2.0
//! scenes.
//!
//! Everything here reads only the [`Assembly`](crate::assembly::Assembly)
//! and the parts catalog, never voxels or rules.
//!
//! - [`partmesh`] gives every part type a closed triangle mesh in its own
//!   LDraw frame, and every piece the affine map that places it exactly as
//!   the `.ldr` does.
//! - [`explode`] moves pieces apart, level by level, for exploded views.
//! - [`gltf`] writes a glTF 2.0 scene (`.glb` or `.gltf`): a node per
//!   piece, a mesh per part and colour, LEGO-coloured materials and a build
//!   animation.

pub mod explode;
pub mod gltf;
pub mod partmesh;
