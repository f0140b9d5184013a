//! What a build did: the contents of `report.json`.

use serde::Serialize;

use super::input::Voxels;
use super::options::step_name;
use super::pictures::size_cm;
use super::stability::Settled;
use super::{BuildOptions, Formats, Stability, StabilityReport};
use crate::assembly::Assembly;
use crate::catalog::{Color, Palette};
use crate::export::partslist::{Condition, PartsList, PartsRow};
use crate::grammar::RuleSet;
use crate::mesh::Mesh;
use crate::search::{Derivation, Repairs, SearchStats};
use crate::voxel::{Sizing, Up, VoxelColors, VoxelGrid};

/// Seconds spent in each stage.
#[derive(Debug, Clone, Default, Serialize)]
pub struct StageTimes {
    /// Reading the mesh.
    pub load: f64,
    /// Voxelizing.
    pub voxelize: f64,
    /// Loading rules.
    pub rules: f64,
    /// The structural analysis.
    pub search: f64,
    /// Independent verification.
    pub verify: f64,
    /// Rendering the images (steps, model, exploded view, part pictures).
    pub render: f64,
    /// Laying out the booklet.
    pub booklet: f64,
    /// The stability check of every step, and its repairs.
    pub stability: f64,
    /// Writing outputs.
    pub write: f64,
}

/// What `report.json` holds.
#[derive(Debug, Clone, Serialize)]
pub struct MeshColorReport {
    /// LDraw colours the model's surface voxels take, with how many show
    /// each, most first.
    pub colors: Vec<(u16, usize)>,
    /// Surface voxels of the model.
    pub surface_voxels: usize,
    /// Of those, how many the build shows in their own colour: the colour
    /// sampled from the model, before the smoothing.
    pub own_color: usize,
    /// `own_color / surface_voxels`.
    pub own_color_share: f64,
    /// Surface voxels the smoothing gave their neighbours' colour.
    pub smoothed: usize,
}

/// What a build did, written to `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct BuildReport {
    /// brickwright's version.
    pub tool_version: String,
    /// The input file as given.
    pub input: String,
    /// Options, as given.
    pub options: ReportOptions,
    /// Triangles in the input.
    pub triangles: usize,
    /// Grid size in studs (x, y) and layers (z).
    pub grid: [i32; 3],
    /// Height of a layer in LDU: 24 (a brick), 12 (with slopes), 8 (with
    /// plates).
    pub layer_ldu: i32,
    /// Voxels of the input after voxelization.
    pub voxels_input: usize,
    /// Voxels built (after repairs).
    pub voxels: usize,
    /// Pieces in all (support columns included).
    pub pieces: usize,
    /// Mean voxels per piece of the model (support columns left out).
    pub voxels_per_piece: f64,
    /// Vertical seams and how many continue into the course above.
    pub seams: crate::assembly::metrics::SeamStats,
    /// How good a build it is, in one place: what was left out, seams,
    /// piece size, 1x1s, size against the size asked for.
    pub quality: Quality,
    /// Pieces by part and colour, with their BrickLink and Rebrickable ids.
    pub parts: Vec<PartsRow>,
    /// What the mesh loader could not use (a missing texture, ...), one
    /// line each; the build went on without it.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// The model's colours, when the build is painted from them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh_colors: Option<MeshColorReport>,
    /// LDraw colours of the build that have no known BrickLink or
    /// Rebrickable id (their parts-list lines say so).
    pub unmapped_colors: Vec<u16>,
    /// A hollow build's size beside the solid build it replaces; absent
    /// for a solid build.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hollow: Option<super::hollow::HollowReport>,
    /// Connected components of the finished build (1 when verified).
    pub components: usize,
    /// Steps in the outputs.
    pub steps: u32,
    /// Pages of the booklet, when one was written.
    pub booklet_pages: Option<usize>,
    /// The stability check of every step and what its repair changed;
    /// `None` with `--stability off`.
    pub stability: Option<StabilityReport>,
    /// The build order: `by course` (the search's pieces re-sequenced
    /// course by course, verified) or `search trace` (when the
    /// re-sequenced order did not verify).
    pub order: String,
    /// Size of the finished model, centimetres (x, y, height).
    pub size_cm: [f64; 3],
    /// Seconds per stage.
    pub seconds: StageTimes,
    /// Search counters.
    pub search: SearchStats,
    /// The rule sequence of the build, in the loaded rule file's numbers
    /// (forward, and backward as the paper prints it).
    pub derivation: Derivation,
    /// What had to change so the voxels could be built.
    pub repairs: Repairs,
    /// Files written.
    pub outputs: Vec<String>,
}

/// The quality of a build, as `report.json` gives it and `build` prints it.
#[derive(Debug, Clone, Serialize)]
pub struct Quality {
    /// Voxels of the model not built (nothing could join them, or the
    /// search ran out of time).
    pub left_out: usize,
    /// Where they are, and why.
    pub left_out_places: Vec<crate::search::LeftOut>,
    /// Cells outside the model filled to join thin features and islands.
    pub extra_cells: usize,
    /// Share of the vertical seams that continue into the course above.
    pub seams_continued: f64,
    /// Mean voxels a piece.
    pub voxels_per_piece: f64,
    /// Share of the pieces that are 1x1 (bricks or plates).
    pub share_1x1: f64,
    /// The build's longest horizontal side, in studs.
    pub extent_studs: i32,
    /// The longest side asked for (`--studs`), if sized that way.
    pub requested_studs: Option<u32>,
    /// Stair edges, on the top and on the underside: where a column
    /// stands one to three plates above (below, underneath) a neighbouring
    /// column (see [`crate::assembly::stairs`]).
    pub stair_edges: crate::assembly::stairs::TopUnder,
    /// Of `stair_edges`, those a slope caps facing down the step (an
    /// inverted slope, underneath).
    pub stair_edges_capped: crate::assembly::stairs::TopUnder,
}

impl Quality {
    pub(super) fn of(
        asm: &Assembly,
        rep: &Repairs,
        seams: crate::assembly::metrics::SeamStats,
        sizing: Sizing,
    ) -> Quality {
        let n = asm.pieces.len().max(1);
        let singles = asm
            .pieces
            .iter()
            .filter(|p| p.placement.part.spec().studs() == 1)
            .count();
        let (mut lo, mut hi) = ((i32::MAX, i32::MAX), (i32::MIN, i32::MIN));
        let mut cells = 0usize;
        for p in &asm.pieces {
            let b = p.placement.body(asm.layer_ldu);
            cells += b.volume() as usize;
            lo = (lo.0.min(b.bbox.min.x), lo.1.min(b.bbox.min.y));
            hi = (
                hi.0.max(b.bbox.min.x + b.bbox.sx),
                hi.1.max(b.bbox.min.y + b.bbox.sy),
            );
        }
        let round = |x: f64, k: f64| (x * k).round() / k;
        let stairs = crate::assembly::stairs::stair_edges(asm);
        Quality {
            left_out: rep.left_out + rep.budget_left_out,
            left_out_places: rep.left_out_places.clone(),
            extra_cells: rep.extra_cells,
            seams_continued: seams.fraction,
            voxels_per_piece: round(cells as f64 / n as f64, 100.0),
            share_1x1: round(singles as f64 / n as f64, 10_000.0),
            extent_studs: (hi.0 - lo.0).max(hi.1 - lo.1).max(0),
            requested_studs: match sizing {
                Sizing::Studs(k) => Some(k),
                Sizing::Height(_) => None,
            },
            stair_edges: stairs.edges,
            stair_edges_capped: stairs.capped,
        }
    }
}

/// The options part of the report.
#[derive(Debug, Clone, Serialize)]
pub struct ReportOptions {
    /// `studs N` or `height N`.
    pub size: String,
    /// `y` or `z`.
    pub up: String,
    /// Rule file, or `default`.
    pub rules: String,
    /// Step grouping.
    pub steps: String,
    /// Seed.
    pub seed: u64,
    /// Search budget, seconds.
    pub time_budget: f64,
    /// Whether slopes were allowed.
    pub slopes: bool,
    /// Whether plates were allowed.
    pub plates: bool,
    /// The palette: `layers`, `random`, or an LDraw colour code.
    pub palette: String,
    /// The wanted list's condition: `N`, `U`, or `any`.
    pub condition: String,
    /// The stability stage: `repair`, `check` or `off`.
    pub stability: Stability,
    /// The files asked for.
    pub formats: Formats,
}

/// How many of the model's surface voxels the build shows in their own
/// colour: the piece covering each has that colour.
pub(super) fn mesh_color_report(
    assembly: &Assembly,
    grid: &VoxelGrid,
    c: &VoxelColors,
) -> MeshColorReport {
    let mut shown: Vec<Option<Color>> = vec![None; grid.len()];
    for p in &assembly.pieces {
        for q in p.placement.body(assembly.layer_ldu).cells() {
            if grid.in_bounds(q) {
                shown[grid.index(q)] = Some(p.color);
            }
        }
    }
    let (mut surface, mut own) = (0, 0);
    for (i, (&s, want)) in c.surface.iter().zip(&c.sampled).enumerate() {
        if s {
            surface += 1;
            if want.is_some() && shown[i] == *want {
                own += 1;
            }
        }
    }
    MeshColorReport {
        colors: c.used.iter().map(|&(col, n)| (col.0, n)).collect(),
        surface_voxels: surface,
        own_color: own,
        own_color_share: if surface == 0 {
            1.0
        } else {
            ((own as f64 / surface as f64) * 1e4).round() / 1e4
        },
        smoothed: c.smoothed,
    }
}

/// The report of a settled build of `mesh`, its voxels `voxels`
/// (`hollow`: beside the solid build), its booklet `booklet_pages` long,
/// the stages having taken `times` (the outputs and
/// the write time are filled in when they are written).
#[allow(clippy::too_many_arguments)]
pub(super) fn compose(
    opts: &BuildOptions,
    rules: &RuleSet,
    mesh: &Mesh,
    voxels: &Voxels,
    settled: &Settled,
    hollow: Option<super::hollow::HollowReport>,
    booklet_pages: Option<usize>,
    times: StageTimes,
) -> BuildReport {
    let assembly = &settled.assembly;
    let outcome = &settled.outcome;
    let layer_ldu = assembly.layer_ldu;
    let (nx, ny, nz) = outcome.voxels.dims();
    let parts = PartsList::of(assembly);
    let pieces = assembly.pieces.len();
    let seams = crate::assembly::metrics::seams(assembly);
    let built = outcome.voxels.count();
    // The model's own pieces: support columns fill no voxel of it.
    let own = pieces - settled.support_pieces().min(pieces);
    BuildReport {
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        input: opts.input.display().to_string(),
        options: ReportOptions::of(opts, voxels.colors.is_some()),
        triangles: mesh.triangles.len(),
        grid: [nx, ny, nz],
        layer_ldu,
        voxels_input: voxels.model.grid.count(),
        voxels: built,
        pieces,
        voxels_per_piece: ((built as f64 / own.max(1) as f64) * 100.0).round() / 100.0,
        seams,
        quality: Quality::of(assembly, &outcome.repairs, seams, opts.sizing),
        parts: parts.rows(),
        warnings: mesh.warnings.clone(),
        mesh_colors: voxels
            .colors
            .as_ref()
            .map(|c| mesh_color_report(assembly, &voxels.model.grid, c)),
        unmapped_colors: parts.unmapped().iter().map(|c| c.0).collect(),
        hollow,
        components: crate::assembly::verify::components(assembly),
        steps: assembly.step_count(),
        booklet_pages,
        stability: settled.stability.as_ref().map(|(r, _)| r.clone()),
        order: settled.order.into(),
        size_cm: size_cm(outcome.voxels.dims(), layer_ldu),
        seconds: times,
        search: outcome.stats.clone(),
        derivation: Derivation::of(&outcome.order, rules),
        repairs: outcome.repairs.clone(),
        outputs: Vec::new(),
    }
}

impl ReportOptions {
    /// The options as the report gives them; `colored`: the build is
    /// painted from the mesh's colours.
    fn of(opts: &BuildOptions, colored: bool) -> Self {
        ReportOptions {
            size: match opts.sizing {
                Sizing::Studs(n) => format!("studs {n}"),
                Sizing::Height(n) => format!("height {n}"),
            },
            up: match opts.up {
                Up::Y => "y".into(),
                Up::Z => "z".into(),
            },
            rules: opts
                .rules
                .as_ref()
                .map_or("default".into(), |p| p.display().to_string()),
            steps: step_name(opts.steps),
            seed: opts.search.seed,
            time_budget: opts.search.time_budget.as_secs_f64(),
            slopes: opts.slopes,
            plates: opts.plates,
            palette: match (opts.palette, colored) {
                (Palette::Mesh, false) => Palette::Layers.describe(),
                (p, _) => p.describe(),
            },
            condition: match opts.condition {
                Some(Condition::New) => "N".into(),
                Some(Condition::Used) => "U".into(),
                None => "any".into(),
            },
            formats: opts.formats.clone(),
            stability: opts.stability,
        }
    }
}

impl BuildReport {
    /// What a user of the finished build should know, a message each (the
    /// command line prints them on standard error): unmapped colours,
    /// voxels left out, a budget run out, a step that would not stand.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = self.warnings.clone();
        if !self.unmapped_colors.is_empty() {
            out.push(format!(
                "colours with no known BrickLink or Rebrickable id: {:?}; their parts-list lines say so",
                self.unmapped_colors
            ));
        }
        if self.repairs.budget_left_out > 0 {
            out.push(format!(
                "{}: the search ran out of time (--time-budget {}); {} voxels above the last layer laid are not built (raise --time-budget or lower --studs)",
                self.input, self.options.time_budget, self.repairs.budget_left_out
            ));
        }
        if self.repairs.left_out > 0 {
            let mut w = format!(
                "{}: {} voxels of the model are left out: nothing could join them to the build",
                self.input, self.repairs.left_out
            );
            for p in &self.repairs.left_out_places {
                w.push_str(&format!(
                    "\n  {} voxels at layer {}, stud ({}, {}): {}",
                    p.voxels, p.layer, p.x, p.y, p.reason
                ));
            }
            out.push(w);
        }
        if let Some(st) = &self.stability {
            if st.first_failure.is_none() && !st.complete {
                out.push(format!(
                    "the stability check covered {} steps before its time budget ran out (raise --stability-budget)",
                    st.steps_checked
                ));
            }
            if let Some(reason) = &st.failure {
                out.push(reason.clone());
            }
        }
        out
    }
}
