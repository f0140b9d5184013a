//! Why a build could not be made.

use thiserror::Error;

use super::BuildOptions;
use crate::booklet::template::TemplateError;
use crate::catalog::Family;
use crate::grammar::{RuleError, RuleSet};
use crate::mesh::MeshError;
use crate::search::SearchError;
use crate::voxel::VoxelizeError;

/// A build that could not be made. Each variant names the file at fault.
#[derive(Debug, Error)]
pub enum BuildError {
    /// The mesh file is missing or bad.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The mesh cannot be voxelized at this size.
    #[error("{file}: {reason}")]
    Voxelize {
        /// The input file.
        file: String,
        /// Why.
        reason: VoxelizeError,
    },
    /// The rule file is bad.
    #[error(transparent)]
    Rules(#[from] RuleError),
    /// The booklet template is bad.
    #[error(transparent)]
    Template(#[from] TemplateError),
    /// The images could not be drawn.
    #[error("rendering: {0}")]
    Render(#[from] crate::render::RenderError),
    /// The search found no build.
    #[error("{file}: {reason}")]
    Search {
        /// The input file.
        file: String,
        /// Why.
        reason: SearchError,
    },
    /// The verifier refused the search's build: a bug, never bad input.
    #[error("internal error: the build of {file} failed verification ({report}); please report this with the input and options")]
    Unverified {
        /// The input file.
        file: String,
        /// What failed.
        report: String,
    },
    /// The force analysis failed (a solver failure, never bad input).
    #[error("stability analysis: {0}")]
    Physics(crate::physics::PhysicsError),
    /// `--stability check` found a step that would not stand.
    #[error(
        "{file}: {reason} (--stability repair fixes what it can; --stability off skips the check)"
    )]
    Unstable {
        /// The input file.
        file: String,
        /// Which step fails, and the weak pieces.
        reason: String,
    },
    /// `--strict`, and voxels of the model were left out.
    #[error("{file}: {voxels} voxels of the model cannot be joined to the build (first at layer {layer}, stud ({x}, {y}): {reason}); --strict refuses to leave them out")]
    LeftOut {
        /// The input file.
        file: String,
        /// Voxels left out.
        voxels: usize,
        /// Layer of the first place.
        layer: i32,
        /// Stud column of the first place.
        x: i32,
        /// Stud row of the first place.
        y: i32,
        /// Why.
        reason: String,
    },
    /// Options that do not go together.
    #[error("{0}")]
    Options(String),
    /// An output could not be written.
    #[error("{path}: cannot write: {reason}")]
    Write {
        /// The output file.
        path: String,
        /// Why.
        reason: std::io::Error,
    },
}

/// The error for a rule file (not the built-in rules) with [`RuleSet::gaps`]
/// whose build of the input left `left_out` voxels unjoined (`None`: no
/// build was found); `None` when the rules lack nothing.
pub(super) fn cover_error(
    rules: &RuleSet,
    opts: &BuildOptions,
    left_out: Option<usize>,
) -> Option<BuildError> {
    let path = opts.rules.as_ref()?;
    let family = if opts.plates {
        Family::Plate
    } else {
        Family::Brick
    };
    let gaps = rules.gaps(family);
    if gaps.is_empty() {
        return None;
    }
    let input = opts.input.file_name().map_or_else(
        || opts.input.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let what = match left_out {
        Some(n) => format!("{n} voxels of {input} could not be joined"),
        None => format!("no build of {input} was found"),
    };
    Some(BuildError::Rules(RuleError::File {
        file: path.display().to_string(),
        message: format!(
            "the rules cannot cover the shape ({what}); they lack {}; add those, learn \
             without --seen-parts-only (the built-in parts stay in), or use the default rules",
            gaps.join(", and ")
        ),
    }))
}
