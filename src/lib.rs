//! brickwright turns a triangle mesh into a LEGO build a person can assemble.
//!
//! The pipeline, one module a stage:
//!
//! ```text
//! mesh  ->  voxel grid  ->  rewriting search  ->  Assembly  ->  exporters
//! (obj,     (1x1x1.2        (grammar: pieces,     (ordered,     ldraw, report
//!  gltf,     cells)          rules; backward       verified
//!  stl)                      tracing)              placements)
//! ```
//!
//! - [`mesh`] loads OBJ, glTF 2.0 and STL files into one triangle soup.
//! - [`voxel`] fills the mesh's inside with 1 x 1 x 1.2 voxels.
//! - [`grammar`] is the Lego rewriting system (Σ, R): piece types and rules
//!   `u -> v`, read from human-readable rule files.
//! - [`search`] peels pieces off the voxels by applying rules in reverse,
//!   depth first with backtracking, and replays the trace forward.
//! - [`assembly`] is the ordered build every exporter reads, with an
//!   independent verifier.
//! - [`ldraw`] writes (and reads back) LDraw `.ldr` files.
//! - [`export`] writes the build for viewers and shops: part meshes,
//!   exploded views, glTF 2.0, BrickLink and Rebrickable parts lists.
//! - [`render`] draws instruction images: step pictures and part pictures.
//! - [`booklet`] lays out the printable PDF instructions.
//! - [`physics`] checks that the build stands, step by step: static
//!   forces, clutch usage and stability scores.
//! - [`pipeline`] ties the stages together for the command-line tool.

pub mod assembly;
pub mod booklet;
pub mod catalog;
pub mod export;
pub mod fsutil;
pub mod geom;
pub mod grammar;
mod keyhash;
pub mod ldraw;
pub mod mesh;
pub mod physics;
pub mod pipeline;
pub mod render;
pub mod search;
pub mod terminal;
pub mod voxel;
