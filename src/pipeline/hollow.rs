//! What a hollow build saves: the build set beside the solid one it
//! replaces, both measured.
//!
//! The solid build is laid out for real, by the same search with the same
//! rules and seed, the inside filled; its pieces and mass are counted, not
//! estimated from the voxels. (It gets no stability stage: support columns
//! are a handful of pieces either way, and the solid model's layout is what
//! a hollow one replaces.)

use serde::Serialize;

use crate::assembly::{Assembly, Placement};
use crate::geom::Cell;
use crate::grammar::RuleSet;
use crate::physics::support::Column;
use crate::search::{self, Guide, SearchError, SearchOptions, SearchOutcome};
use crate::voxel::VoxelGrid;

/// One build's size.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Size {
    /// Pieces, support columns and inner pillars included.
    pub pieces: usize,
    /// Mass of the pieces, grams.
    pub mass_g: f64,
    /// Cells the pieces fill, over the model's voxels: how much of its
    /// volume is plastic (a solid build fills a little more than 1 where
    /// pieces join thin features outside the voxels).
    pub filled_share: f64,
}

impl Size {
    /// The size of `placements`, against a model of `volume` cells.
    fn of(placements: impl Iterator<Item = Placement>, layer_ldu: i32, volume: usize) -> Size {
        let (mut pieces, mut mass, mut cells) = (0, 0.0, 0usize);
        for p in placements {
            pieces += 1;
            mass += f64::from(p.part.spec().mass_g);
            cells += p.body(layer_ldu).volume() as usize;
        }
        Size {
            pieces,
            mass_g: (mass * 10.0).round() / 10.0,
            filled_share: share(cells, volume),
        }
    }
}

/// The `hollow` section of `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct HollowReport {
    /// The shell's thickness, studs across and courses up and down.
    pub wall: u32,
    /// Voxels of the model left empty inside the shell.
    pub emptied_voxels: usize,
    /// Pieces standing in the emptied space: inner pillars the stability
    /// stage added to hold up what is over the hollow.
    pub inner_pieces: usize,
    /// This build.
    pub hollow: Size,
    /// The solid build of the same model, options and seed.
    pub solid: Size,
    /// `hollow.pieces / solid.pieces`.
    pub pieces_share: f64,
    /// `hollow.mass_g / solid.mass_g`.
    pub mass_share: f64,
}

/// The report of the hollow build `assembly` (whose search gave `outcome`,
/// with `outcome.emptied` set): its size and the solid build's, laid out by
/// `search_opts` without `hollow`.
pub fn report(
    assembly: &Assembly,
    outcome: &SearchOutcome,
    voxels: &VoxelGrid,
    guide: Guide<'_>,
    rules: &RuleSet,
    search_opts: &SearchOptions,
) -> Result<Option<HollowReport>, SearchError> {
    let (Some(emptied), Some(wall)) = (&outcome.emptied, search_opts.hollow) else {
        return Ok(None);
    };
    let solid_opts = search_opts.clone().with_hollow(None);
    let solid = search::build_guided(voxels, guide, rules, &solid_opts)?;
    let u = assembly.layer_ldu;
    let volume = voxels.count();
    let solid = Size::of(search::placements(&solid).into_iter(), u, volume);
    let hollow = Size::of(assembly.pieces.iter().map(|p| p.placement), u, volume);
    let inner_pieces = assembly
        .pieces
        .iter()
        .filter(|p| p.placement.body(u).cells().any(|c| emptied.get(c)))
        .count();
    Ok(Some(HollowReport {
        wall: wall.studs(),
        emptied_voxels: emptied.count(),
        inner_pieces,
        pieces_share: share(hollow.pieces, solid.pieces),
        mass_share: if solid.mass_g > 0.0 {
            ((hollow.mass_g / solid.mass_g) * 1e4).round() / 1e4
        } else {
            0.0
        },
        hollow,
        solid,
    }))
}

/// The booklet's note on a step that adds an inner pillar of a hollow
/// build: a support column standing in its emptied inside.
pub const PILLAR_NOTE: &str = "Inner pillar: inside the shell, it holds up what is over the hollow";

/// The note on the step of support column `c`: an inner pillar when it
/// stands in the cells a hollow build `emptied`, else a support column.
pub fn note(c: &Column, emptied: Option<&VoxelGrid>) -> &'static str {
    let inside = emptied.is_some_and(|e| e.get(Cell::new(c.x, c.y, c.bottom)));
    if inside {
        PILLAR_NOTE
    } else {
        crate::pipeline::SUPPORT_NOTE
    }
}

/// `a / b` to four places, 0 when `b` is.
fn share(a: usize, b: usize) -> f64 {
    if b == 0 {
        0.0
    } else {
        ((a as f64 / b as f64) * 1e4).round() / 1e4
    }
}
