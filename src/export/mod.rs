//! Exporters: the files made from one verified [`Assembly`](crate::assembly::Assembly).
//!
//! Everything here reads only the assembly and the [catalog](crate::catalog),
//! never voxels or rules, and writes to any [`std::io::Write`]; only the
//! pipeline knows paths, and it writes every file atomically.
//!
//! - [`partmesh`] gives every part type a closed triangle mesh in its own
//!   LDraw frame, and every piece the affine map that places it exactly as
//!   the `.ldr` does.
//! - [`explode`] moves pieces apart, level by level, for exploded views.
//! - [`gltf`] writes a glTF 2.0 scene (`.glb` or `.gltf`): a node per
//!   piece, a mesh per part and colour, LEGO-coloured materials and a build
//!   animation.
//! - [`html`] writes the interactive step viewer: one self-contained web
//!   page with the model, a WebGL renderer and the parts lists inlined.
//! - [`partslist`] writes the parts lists for buying the bricks: a
//!   BrickLink wanted list and a Rebrickable CSV.

pub mod explode;
pub mod gltf;
pub mod html;
pub mod partmesh;
pub mod partslist;
pub mod sight;
