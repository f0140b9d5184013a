//! The first stages: the rules and template, the mesh, and its voxels.

use std::path::Path;

use super::{BuildError, BuildOptions};
use crate::booklet::Template;
use crate::catalog::{Family, Palette};
use crate::grammar::{default_rules, RuleError, RuleSet};
use crate::mesh::{self, Mesh};
use crate::voxel::{color_voxels, VoxelColors, VoxelModel, VoxelizeOptions};

/// What the build is made with: the rules restricted to the parts the
/// options allow, and the booklet's template.
pub(super) struct Setup {
    pub rules: RuleSet,
    pub template: Template,
}

/// The voxelized model and, with `--palette mesh` on a coloured mesh, its
/// voxels' colours.
pub(super) struct Voxels {
    pub model: VoxelModel,
    pub colors: Option<VoxelColors>,
    /// [`VoxelColors::surface_labels`], which the layout keeps apart.
    pub labels: Option<Vec<u16>>,
}

/// Loads the rules named in `opts`, or the built-in defaults.
pub fn load_rules(path: Option<&Path>) -> Result<RuleSet, RuleError> {
    match path {
        Some(p) => RuleSet::load(p),
        None => Ok(default_rules()),
    }
}

/// Loads the rule file and the template (while the mesh loads: a bad one
/// fails the build before the mesh is voxelized).
pub(super) fn setup(opts: &BuildOptions) -> Result<Setup, BuildError> {
    let rules = load_rules(opts.rules.as_deref())?.restricted(|p| match p.spec().family() {
        Family::Brick => true,
        Family::Plate => opts.plates,
        Family::Slope => opts.slopes,
    })?;
    let template = match &opts.template {
        Some(path) => Template::load(path)?,
        None => Template::default(),
    };
    Ok(Setup { rules, template })
}

/// Reads the input mesh.
pub(super) fn load(opts: &BuildOptions) -> Result<Mesh, BuildError> {
    Ok(mesh::load(&opts.input)?)
}

/// Voxelizes `mesh` at the size asked for, in layers of the rules' height,
/// and colours the voxels when the palette is the mesh's own.
pub(super) fn voxelize(
    opts: &BuildOptions,
    mesh: &Mesh,
    rules: &RuleSet,
) -> Result<Voxels, BuildError> {
    let vopts = VoxelizeOptions::default()
        .with_sizing(opts.sizing)
        .with_up(opts.up)
        .with_layer_ldu(rules.layer_ldu());
    let model = crate::voxel::voxelize(mesh, &vopts).map_err(|reason| BuildError::Voxelize {
        file: opts.input.display().to_string(),
        reason,
    })?;
    let colors = match opts.palette {
        Palette::Mesh => color_voxels(mesh, &model, opts.up, opts.max_colors),
        _ => None,
    };
    let labels = colors.as_ref().map(VoxelColors::surface_labels);
    Ok(Voxels {
        model,
        colors,
        labels,
    })
}

/// The mesh at `path`, `studs` studs across, built in bricks alone (the
/// default rules), in course order and grouped in steps as `build` groups
/// them, without the planner's checks and repairs: the structure the force
/// analysis's tests and benchmarks measure.
#[doc(hidden)]
pub fn bricks_by_course(path: &Path, studs: u32) -> anyhow::Result<crate::assembly::Assembly> {
    use crate::assembly::{order::by_course, Assembly, StepGrouping};
    use crate::search::{self, SearchOptions};
    use crate::voxel::{voxelize, Sizing};
    let mesh = mesh::load(path)?;
    let opts = VoxelizeOptions::default().with_sizing(Sizing::Studs(studs));
    let model = voxelize(&mesh, &opts)?;
    let rules = load_rules(None)?.restricted(|p| p.spec().family() == Family::Brick)?;
    let outcome = search::build_guided(
        &model.grid,
        search::Guide {
            slant: Some(&model.slant),
            surface: Some(&model.surface),
            ..Default::default()
        },
        &rules,
        &SearchOptions::default(),
    )?;
    let order = search::placements(&outcome);
    let mut a = by_course(&Assembly::from_order(
        &order,
        24,
        crate::catalog::Color::RED,
    ));
    a.regroup(StepGrouping::Auto);
    Ok(a)
}
