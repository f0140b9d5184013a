//! Voxels: the solid, quantized shape the search builds.
//!
//! One voxel is 1 x 1 x 1.2 (a stud by a brick's height).

mod grid;
pub mod voxelize;

pub use grid::VoxelGrid;
pub use voxelize::{
    to_grid_frame, voxelize, Sizing, Slant, Up, VoxelModel, VoxelizeError, VoxelizeOptions,
};
pub mod colour;
pub mod smooth;
pub use colour::{color_voxels, VoxelColors};
pub mod hollow;
pub use hollow::{hollow, Hollowed, Wall};
