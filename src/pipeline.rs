//! The whole job: mesh file in, verified LDraw build and report out.
//!
//! [`build`] runs the stages in order, times each, verifies the assembly
//! with the independent [`verify`](crate::assembly::verify) before anything
//! is written, and writes every output atomically: a failed run leaves no
//! file behind.

use std::path::{Path, PathBuf};
use std::time::Instant;

pub mod pictures;
pub mod stability;

pub use stability::{Stability, StabilityReport};

use serde::Serialize;
use thiserror::Error;

use crate::assembly::verify::verify;
use crate::assembly::{Assembly, StepGrouping};
use crate::booklet::template::TemplateError;
use crate::booklet::Template;
use crate::catalog::{Color, Family, Palette};
use crate::export::gltf::{write_gltf, Container, GltfOptions};
use crate::export::html::{write_html, HtmlOptions};
use crate::export::partslist::{
    write_bricklink, write_rebrickable_csv, Condition, PartsList, PartsRow,
};
use crate::fsutil::Outputs;
use crate::grammar::{default_rules, RuleError, RuleSet};
use crate::ldraw::{write_ldr, LdrMeta};
use crate::mesh::{self, MeshError};
use crate::search::{self, Repairs, SearchError, SearchOptions, SearchStats};
use crate::voxel::{voxelize, Sizing, Up, VoxelColors, VoxelGrid, VoxelizeError, VoxelizeOptions};

/// Everything `brickwright build` can be told.
#[derive(Debug, Clone, Serialize)]
pub struct BuildOptions {
    /// The mesh file.
    pub input: PathBuf,
    /// Where outputs go (created if missing). Default `out`.
    pub out_dir: PathBuf,
    /// Model size. Default 24 studs across.
    #[serde(skip)]
    pub sizing: Sizing,
    /// The input's up axis. Default `y`.
    #[serde(skip)]
    pub up: Up,
    /// A rule file; `None` for the built-in default rules.
    pub rules: Option<PathBuf>,
    /// Build with slopes too (layers half a brick high). Default off.
    pub slopes: bool,
    /// Build with plates too (layers a plate high). Default off.
    pub plates: bool,
    /// Step grouping in all outputs. Default [`StepGrouping::Auto`]: by
    /// course, at most 8 pieces a step.
    pub steps: StepGrouping,
    /// Search tuning, including the seed.
    pub search: SearchOptions,
    /// How pieces are coloured. Default [`Palette::Mesh`]: the model's own
    /// colours, or [`Palette::Layers`] for a model without any.
    pub palette: Palette,
    /// With [`Palette::Mesh`], the most colours the build may use (the
    /// model's colours reduced in Lab); `None` for no limit.
    pub max_colors: Option<usize>,
    /// The condition the BrickLink wanted list asks for; `None` (the
    /// default) for any.
    pub condition: Option<Condition>,
    /// The files to write besides `report.json`. Default
    /// [`Formats::default`]: every format but `.gltf`.
    pub formats: Formats,
    /// The booklet's layout template; `None` for the built-in
    /// `templates/default.toml`.
    pub template: Option<PathBuf>,
    /// The stability stage. Default [`Stability::Repair`].
    pub stability: Stability,
    /// Time for the stability stage; past it, no further step is checked
    /// or repaired (the finished model always is). Default
    /// [`DEFAULT_STABILITY_BUDGET`].
    #[serde(skip)]
    pub stability_budget: std::time::Duration,
    /// Whether the stability repair may add support columns (pieces of
    /// their own colour under what the model cannot hold itself). Default
    /// true.
    pub supports: bool,
    /// Fail rather than leave any voxel of the model out. Default off.
    pub strict: bool,
}

/// The booklet's note on a step that adds a support column.
pub const SUPPORT_NOTE: &str = "Support column: not part of the shape; it holds the model up";

/// Default time for the stability stage: two minutes.
pub const DEFAULT_STABILITY_BUDGET: std::time::Duration = std::time::Duration::from_secs(120);

/// A file `brickwright build` can write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Format {
    /// `<stem>.ldr`: the LDraw model, a `0 STEP` per step.
    Ldr,
    /// `<stem>.glb`: the glTF 2.0 assembly with its build animation.
    Glb,
    /// `<stem>-exploded.glb`: the glTF assembly pulled apart.
    ExplodedGlb,
    /// `<stem>.gltf`: the glTF assembly as JSON with its data embedded
    /// (not in the default set: name it).
    Gltf,
    /// `<stem>-bricklink.xml`: a BrickLink wanted list.
    Bricklink,
    /// `<stem>-parts.csv`: a Rebrickable parts list.
    Csv,
    /// `steps/step-001.png`...: an image of every step.
    Steps,
    /// `<stem>.png`: the finished model.
    Png,
    /// `<stem>-exploded.png`: the exploded view, the finished model beside it.
    ExplodedPng,
    /// `<stem>.pdf`: the printable instruction booklet.
    Pdf,
    /// `<stem>-stress.png`: the finished model, each piece coloured by
    /// the share of its clutch used (green none, red all); needs the
    /// stability check.
    Stress,
    /// `<stem>.html`: the interactive step viewer, one self-contained page.
    Html,
}

impl Format {
    /// Every format, in the order files are written.
    pub const ALL: [Format; 12] = [
        Format::Ldr,
        Format::Glb,
        Format::ExplodedGlb,
        Format::Gltf,
        Format::Bricklink,
        Format::Csv,
        Format::Steps,
        Format::Png,
        Format::ExplodedPng,
        Format::Pdf,
        Format::Stress,
        Format::Html,
    ];

    /// Whether `--formats all` (and the default) includes it: every format
    /// but `.gltf`, which repeats the `.glb` as JSON.
    pub fn in_all(self) -> bool {
        self != Format::Gltf
    }

    /// The name `--formats` takes.
    pub fn name(self) -> &'static str {
        match self {
            Format::Ldr => "ldr",
            Format::Glb => "glb",
            Format::ExplodedGlb => "exploded-glb",
            Format::Gltf => "gltf",
            Format::Bricklink => "bricklink",
            Format::Csv => "csv",
            Format::Steps => "steps",
            Format::Png => "png",
            Format::ExplodedPng => "exploded-png",
            Format::Pdf => "pdf",
            Format::Stress => "stress",
            Format::Html => "html",
        }
    }

    /// The file this format writes for a model named `stem`.
    pub fn file_name(self, stem: &str) -> String {
        match self {
            Format::Ldr => format!("{stem}.ldr"),
            Format::Glb => format!("{stem}.glb"),
            Format::ExplodedGlb => format!("{stem}-exploded.glb"),
            Format::Gltf => format!("{stem}.gltf"),
            Format::Bricklink => format!("{stem}-bricklink.xml"),
            Format::Csv => format!("{stem}-parts.csv"),
            Format::Steps => "steps".into(),
            Format::Png => format!("{stem}.png"),
            Format::ExplodedPng => format!("{stem}-exploded.png"),
            Format::Pdf => format!("{stem}.pdf"),
            Format::Stress => format!("{stem}-stress.png"),
            Format::Html => format!("{stem}.html"),
        }
    }
}

/// A set of [`Format`]s.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Formats(Vec<Format>);

impl Default for Formats {
    /// Every format but `.gltf`.
    fn default() -> Self {
        Formats(Format::ALL.into_iter().filter(|f| f.in_all()).collect())
    }
}

impl Formats {
    /// Formats from a comma-separated list of names (`ldr,bricklink`), or
    /// `all`. The error names the unknown format and the known ones.
    pub fn parse(s: &str) -> Result<Formats, String> {
        let mut set = Vec::new();
        for name in s.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            if name == "all" {
                set.extend(Format::ALL.into_iter().filter(|f| f.in_all()));
                continue;
            }
            let f = Format::ALL
                .into_iter()
                .find(|f| f.name() == name)
                .ok_or_else(|| {
                    let known: Vec<&str> = Format::ALL.iter().map(|f| f.name()).collect();
                    format!("unknown format `{name}` (known: {}, all)", known.join(", "))
                })?;
            set.push(f);
        }
        if set.is_empty() {
            let known: Vec<&str> = Format::ALL.iter().map(|f| f.name()).collect();
            return Err(format!(
                "no format given (known: {}, all)",
                known.join(", ")
            ));
        }
        set.sort_unstable();
        set.dedup();
        Ok(Formats(set))
    }

    /// Whether `f` is in the set.
    pub fn contains(&self, f: Format) -> bool {
        self.0.contains(&f)
    }

    /// The formats, in writing order.
    pub fn iter(&self) -> impl Iterator<Item = Format> + '_ {
        self.0.iter().copied()
    }
}

impl BuildOptions {
    /// Options with defaults for `input`.
    pub fn new(input: impl Into<PathBuf>) -> Self {
        BuildOptions {
            input: input.into(),
            out_dir: PathBuf::from("out"),
            sizing: Sizing::default(),
            up: Up::default(),
            rules: None,
            slopes: false,
            plates: false,
            steps: StepGrouping::Auto,
            search: SearchOptions::default(),
            palette: Palette::default(),
            max_colors: None,
            condition: None,
            formats: Formats::default(),
            template: None,
            stability: Stability::default(),
            stability_budget: DEFAULT_STABILITY_BUDGET,
            supports: true,
            strict: false,
        }
    }
}

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
    /// Of those, how many the build shows in their own colour.
    pub own_color: usize,
    /// `own_color / surface_voxels`.
    pub own_color_share: f64,
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
}

impl Quality {
    fn of(
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

/// Stage callbacks, for progress display.
pub trait Progress {
    /// A stage starts.
    fn stage(&self, name: &str);
    /// The current stage ended.
    fn done(&self);
    /// `done` of the current stage's `total` items are finished (step
    /// images drawn, say), for a display with counts and time left. By
    /// default nothing.
    fn advance(&self, done: u64, total: u64) {
        let _ = (done, total);
    }
}

/// No progress display.
pub struct Silent;

impl Progress for Silent {
    fn stage(&self, _: &str) {}
    fn done(&self) {}
}

/// The build and what happened.
#[derive(Debug, Clone)]
pub struct BuildOutput {
    /// The verified assembly, steps grouped.
    pub assembly: Assembly,
    /// The report written to `report.json`.
    pub report: BuildReport,
}

/// How many of the model's surface voxels the build shows in their own
/// colour: the piece covering each has that colour.
fn mesh_color_report(assembly: &Assembly, grid: &VoxelGrid, c: &VoxelColors) -> MeshColorReport {
    let mut shown: Vec<Option<Color>> = vec![None; grid.len()];
    for p in &assembly.pieces {
        for q in p.placement.body(assembly.layer_ldu).cells() {
            if grid.in_bounds(q) {
                shown[grid.index(q)] = Some(p.color);
            }
        }
    }
    let (mut surface, mut own) = (0, 0);
    for (i, (&s, want)) in c.surface.iter().zip(&c.cells).enumerate() {
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
    }
}

fn secs(t: Instant) -> f64 {
    (t.elapsed().as_secs_f64() * 1000.0).round() / 1000.0
}

/// Loads the rules named in `opts`, or the built-in defaults.
pub fn load_rules(path: Option<&Path>) -> Result<RuleSet, RuleError> {
    match path {
        Some(p) => RuleSet::load(p),
        None => Ok(default_rules()),
    }
}

/// The error for a rule file (not the built-in rules) with [`RuleSet::gaps`]
/// whose build of the input left `left_out` voxels unjoined (`None`: no
/// build was found); `None` when the rules lack nothing.
fn cover_error(
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

/// Runs the pipeline and writes `<stem>.ldr` and `report.json` into
/// `opts.out_dir`.
pub fn build(opts: &BuildOptions, progress: &dyn Progress) -> Result<BuildOutput, BuildError> {
    let file = opts.input.display().to_string();
    let mut times = StageTimes::default();

    if opts.stability == Stability::Off
        && opts.formats.contains(Format::Stress)
        && opts.formats != Formats::default()
    {
        return Err(BuildError::Options(
            "--formats stress needs the stability check; drop --stability off".into(),
        ));
    }
    // Rules first: a bad rule file should fail before any slow work.
    let t = Instant::now();
    let rules = load_rules(opts.rules.as_deref())?.restricted(|p| match p.spec().family() {
        Family::Brick => true,
        Family::Plate => opts.plates,
        Family::Slope => opts.slopes,
    })?;
    let template = match &opts.template {
        Some(path) => Template::load(path)?,
        None => Template::default(),
    };
    times.rules = secs(t);

    progress.stage("loading mesh");
    let t = Instant::now();
    let mesh = mesh::load(&opts.input)?;
    times.load = secs(t);
    progress.done();

    progress.stage("voxelizing");
    let t = Instant::now();
    let vopts = VoxelizeOptions::default()
        .with_sizing(opts.sizing)
        .with_up(opts.up)
        .with_layer_ldu(rules.layer_ldu());
    let model = voxelize(&mesh, &vopts).map_err(|reason| BuildError::Voxelize {
        file: file.clone(),
        reason,
    })?;
    let colors = match opts.palette {
        Palette::Mesh => crate::voxel::color_voxels(&mesh, &model, opts.up, opts.max_colors),
        _ => None,
    };
    let labels = colors
        .as_ref()
        .map(crate::voxel::VoxelColors::surface_labels);
    times.voxelize = secs(t);
    progress.done();

    progress.stage("searching");
    let t = Instant::now();
    // Search, verify, re-sequence and group: the plan every output
    // follows. The stability repair may ask for another seed's plan.
    let verify_secs = std::cell::Cell::new(0.0);
    let plan = |seed: u64| -> Result<stability::Plan, BuildError> {
        let search_opts = opts.search.clone().with_seed(seed);
        let guide = search::Guide {
            slant: Some(&model.slant),
            surface: Some(&model.surface),
            colors: labels.as_deref(),
        };
        let outcome =
            search::build_guided(&model.grid, guide, &rules, &search_opts).map_err(|reason| {
                BuildError::Search {
                    file: file.clone(),
                    reason,
                }
            })?;
        let t = Instant::now();
        let order = search::placements(&outcome);
        let mut assembly = Assembly::from_order(&order, rules.layer_ldu(), Color::RED);
        assembly.paint(opts.palette, seed);
        if let Some(c) = &colors {
            assembly.paint_voxels(&model.grid, c);
        }
        let check = verify(&assembly, Some(&outcome.voxels));
        if !check.is_ok() {
            return Err(BuildError::Unverified {
                file: file.clone(),
                report: check.to_string(),
            });
        }
        // Re-sequence course by course so steps read like instructions;
        // keep the search's order if the re-sequenced one does not verify.
        let by_course = crate::assembly::order::by_course(&assembly);
        let order_name = if verify(&by_course, Some(&outcome.voxels)).is_ok() {
            assembly = by_course;
            "by course"
        } else {
            "search trace"
        };
        assembly.regroup(opts.steps);
        verify_secs.set(verify_secs.get() + secs(t));
        Ok((outcome, assembly, order_name))
    };
    // A rule file that cannot cover the shape is an error naming what it
    // lacks, not a build of a fragment.
    let first = plan(opts.search.seed).map_err(|e| match e {
        BuildError::Search { .. } => cover_error(&rules, opts, None).unwrap_or(e),
        e => e,
    })?;
    let left_out = first.0.repairs.left_out;
    if left_out > 0 {
        if let Some(e) = cover_error(&rules, opts, Some(left_out)) {
            return Err(e);
        }
    }
    if opts.strict {
        let rep = &first.0.repairs;
        if let Some(p) = rep.left_out_places.first() {
            return Err(BuildError::LeftOut {
                file,
                voxels: rep.left_out + rep.budget_left_out,
                layer: p.layer,
                x: p.x,
                y: p.y,
                reason: p.reason.clone(),
            });
        }
    }
    times.verify = verify_secs.get();
    times.search = secs(t) - times.verify;
    progress.done();

    let ((outcome, assembly, order_name), stability) = match opts.stability {
        Stability::Off => (first, None),
        mode => {
            progress.stage("checking stability");
            let t = Instant::now();
            let params = crate::physics::Params::default();
            let (planned, report, finished) = stability::settle(
                mode,
                first,
                opts.search.seed,
                &params,
                opts.stability_budget,
                opts.supports,
                &plan,
            )?;
            if mode == Stability::Check && report.first_failure.is_some() {
                return Err(BuildError::Unstable {
                    file,
                    reason: report.failure.clone().unwrap_or_default(),
                });
            }
            times.stability = secs(t);
            progress.done();
            (planned, Some((report, finished)))
        }
    };

    // What the booklet and the `.ldr` say of a support column's step.
    let step_notes: std::collections::BTreeMap<u32, String> = stability
        .iter()
        .flat_map(|(r, _)| &r.supports)
        .map(|c| (c.step, SUPPORT_NOTE.to_string()))
        .collect();
    let stem = opts
        .input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "model".into());
    let (nx, ny, nz) = outcome.voxels.dims();
    let size_cm = [
        nx as f64 * 0.8,
        ny as f64 * 0.8,
        (f64::from(nz * rules.layer_ldu()) * 0.04 * 100.0).round() / 100.0,
    ];
    let formats = &opts.formats;
    let wants_steps = formats.contains(Format::Steps) || formats.contains(Format::Pdf);
    let rendered =
        if wants_steps || formats.contains(Format::Png) || formats.contains(Format::ExplodedPng) {
            progress.stage("rendering");
            let t = Instant::now();
            let pictures = pictures::Pictures {
                assembly: &assembly,
                title: &stem,
                size_studs: [
                    f64::from(nx),
                    f64::from(ny),
                    f64::from(nz * rules.layer_ldu()) / 24.0,
                ],
                size_cm,
                step_notes: step_notes.clone(),
            };
            let rendered = pictures::render_all(&pictures, wants_steps, progress)?;
            times.render = secs(t);
            let booklet = if formats.contains(Format::Pdf) {
                let t = Instant::now();
                let pdf = pictures::booklet(&pictures, &rendered, &template).map_err(|reason| {
                    BuildError::Write {
                        path: opts
                            .out_dir
                            .join(Format::Pdf.file_name(&stem))
                            .display()
                            .to_string(),
                        reason,
                    }
                })?;
                times.booklet = secs(t);
                Some(pdf)
            } else {
                None
            };
            progress.done();
            Some((rendered, booklet))
        } else {
            None
        };

    progress.stage("writing");
    let t = Instant::now();
    // Folders made for this run go again if it fails.
    let mut made = crate::fsutil::CreatedDirs::new();
    made.create(&opts.out_dir)
        .map_err(|reason| BuildError::Write {
            path: opts.out_dir.display().to_string(),
            reason,
        })?;
    let report_path = opts.out_dir.join("report.json");
    let meta = LdrMeta {
        title: format!("{stem}, built by brickwright"),
        name: format!("{stem}.ldr"),
        author: "brickwright".into(),
        notes: vec![
            format!("brickwright {}", env!("CARGO_PKG_VERSION")),
            format!(
                "input: {}",
                opts.input
                    .file_name()
                    .map(|s| s.to_string_lossy())
                    .unwrap_or_default()
            ),
            format!("options: {}", describe(opts)),
            format!("seed: {}", opts.search.seed),
        ],
        step_notes,
    };
    let parts = PartsList::of(&assembly);
    let pieces = assembly.pieces.len();
    let seams = crate::assembly::metrics::seams(&assembly);
    let voxels = outcome.voxels.count();
    let mut report = BuildReport {
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        input: file.clone(),
        options: ReportOptions {
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
            palette: match (opts.palette, &colors) {
                (Palette::Mesh, None) => Palette::Layers.describe(),
                (p, _) => p.describe(),
            },
            condition: match opts.condition {
                Some(Condition::New) => "N".into(),
                Some(Condition::Used) => "U".into(),
                None => "any".into(),
            },
            formats: opts.formats.clone(),
            stability: opts.stability,
        },
        triangles: mesh.triangles.len(),
        grid: [nx, ny, nz],
        layer_ldu: rules.layer_ldu(),
        voxels_input: model.grid.count(),
        voxels,
        pieces,
        // The model's own pieces: support columns fill no voxel of it.
        voxels_per_piece: {
            let own = pieces
                - stability
                    .as_ref()
                    .map_or(0, |(r, _)| r.support_pieces)
                    .min(pieces);
            ((voxels as f64 / own.max(1) as f64) * 100.0).round() / 100.0
        },
        seams,
        quality: Quality::of(&assembly, &outcome.repairs, seams, opts.sizing),
        parts: parts.rows(),
        warnings: mesh.warnings.clone(),
        mesh_colors: colors
            .as_ref()
            .map(|c| mesh_color_report(&assembly, &model.grid, c)),
        unmapped_colors: parts.unmapped().iter().map(|c| c.0).collect(),
        components: crate::assembly::verify::components(&assembly),
        steps: assembly.step_count(),
        booklet_pages: rendered
            .as_ref()
            .and_then(|(_, b)| b.as_ref())
            .map(|b| b.pages),
        stability: stability.as_ref().map(|(r, _)| r.clone()),
        order: order_name.into(),
        size_cm,
        seconds: times,
        search: outcome.stats.clone(),
        repairs: outcome.repairs.clone(),
        outputs: Vec::new(),
    };
    // Every file is staged first and renamed into place together, so a
    // failed run leaves none of them.
    let mut files = Outputs::new();
    for format in opts.formats.iter() {
        let path = opts.out_dir.join(format.file_name(&stem));
        let written = match format {
            Format::Ldr => files.add(&path, |w| write_ldr(w, &assembly, &meta)),
            Format::Glb | Format::ExplodedGlb | Format::Gltf => {
                let gltf = GltfOptions::default()
                    .with_name(&stem)
                    .with_exploded(format == Format::ExplodedGlb)
                    .with_container(if format == Format::Gltf {
                        Container::Embedded
                    } else {
                        Container::Binary
                    });
                files.add(&path, |w| write_gltf(w, &assembly, &gltf))
            }
            Format::Bricklink => files.add(&path, |w| write_bricklink(w, &parts, opts.condition)),
            Format::Stress => {
                // Drawn only when the stability stage ran (`all` skips it
                // under `--stability off`; naming it then is an error, above).
                let Some((_, finished)) = &stability else {
                    continue;
                };
                let png = pictures::encode(&pictures::stress_image(&assembly, finished)?);
                files.add(&path, |w| w.write_all(&png))
            }
            Format::Csv => files.add(&path, |w| write_rebrickable_csv(w, &parts)),
            Format::Html => files.add(&path, |w| {
                write_html(w, &assembly, &HtmlOptions::default().with_name(&stem))
            }),
            Format::Steps | Format::Png | Format::ExplodedPng | Format::Pdf => {
                let Some((rendered, booklet)) = &rendered else {
                    unreachable!("pictures are rendered when a pictured format is asked for")
                };
                match format {
                    Format::Steps => {
                        // Never a link to a folder outside `-o`.
                        crate::fsutil::refuse_link(&path)
                            .and_then(|()| made.create(&path))
                            .map_err(|reason| BuildError::Write {
                                path: path.display().to_string(),
                                reason,
                            })?;
                        let pngs = pictures::encode_all(&rendered.steps);
                        let paths = pictures::step_paths(&path, pngs.len());
                        let mut written = Ok(());
                        for (png, p) in pngs.iter().zip(&paths) {
                            written = files.add(p, |w| w.write_all(png));
                            if written.is_err() {
                                break;
                            }
                        }
                        written
                    }
                    Format::Png => {
                        let png = pictures::encode(&rendered.model);
                        files.add(&path, |w| w.write_all(&png))
                    }
                    Format::ExplodedPng => {
                        let png = pictures::encode(&rendered.exploded);
                        files.add(&path, |w| w.write_all(&png))
                    }
                    _ => {
                        let pdf = booklet.as_ref().map_or(&[][..], |b| &b.pdf);
                        files.add(&path, |w| w.write_all(pdf))
                    }
                }
            }
        };
        written.map_err(|reason| BuildError::Write {
            path: path.display().to_string(),
            reason,
        })?;
    }
    report.outputs = files
        .paths()
        .chain([report_path.as_path()])
        .map(|p| p.display().to_string())
        .collect();
    report.seconds.write = secs(t);
    files
        .add(&report_path, |w| {
            serde_json::to_writer_pretty(&mut *w, &report).map_err(std::io::Error::other)?;
            w.write_all(b"\n")
        })
        .map_err(|reason| BuildError::Write {
            path: report_path.display().to_string(),
            reason,
        })?;
    files.commit().map_err(|(path, reason)| BuildError::Write {
        path: path.display().to_string(),
        reason,
    })?;
    made.keep();
    if let Some((rendered, _)) = &rendered {
        if formats.contains(Format::Steps) {
            pictures::remove_stale_steps(&opts.out_dir.join("steps"), rendered.steps.len());
        }
    }
    progress.done();
    Ok(BuildOutput { assembly, report })
}

fn step_name(s: StepGrouping) -> String {
    match s {
        StepGrouping::Auto => "by course, at most 8 pieces a step (more past 255 steps)".into(),
        StepGrouping::Each => "one piece a step".into(),
        StepGrouping::Size(n) => format!("{n} pieces a step"),
        StepGrouping::Layer => "by layer".into(),
    }
}

/// The options as a one-line command-line echo, for file headers.
fn describe(opts: &BuildOptions) -> String {
    let size = match opts.sizing {
        Sizing::Studs(n) => format!("--studs {n}"),
        Sizing::Height(n) => format!("--height {n}"),
    };
    let up = match opts.up {
        Up::Y => "y",
        Up::Z => "z",
    };
    let rules = opts
        .rules
        .as_ref()
        .map(|p| {
            format!(
                " --rules {}",
                p.file_name()
                    .map(|s| s.to_string_lossy())
                    .unwrap_or_default()
            )
        })
        .unwrap_or_default();
    let steps = match opts.steps {
        StepGrouping::Auto => String::new(),
        StepGrouping::Each => " --step-size 1".into(),
        StepGrouping::Size(n) => format!(" --step-size {n}"),
        StepGrouping::Layer => " --step-by layer".into(),
    };
    let slopes = if opts.slopes { " --slopes" } else { "" };
    let plates = if opts.plates { " --plates" } else { "" };
    let palette = match (opts.palette, opts.max_colors) {
        (Palette::Mesh, None) => String::new(),
        (Palette::Mesh, Some(n)) => format!(" --colors {n}"),
        (p, _) => format!(" --palette {}", p.describe()),
    };
    let stability = match opts.stability {
        Stability::Repair => String::new(),
        s => format!(" --stability {}", s.name()),
    };
    format!(
        "{size} --up {up} --seed {}{rules}{slopes}{plates}{steps}{palette}{stability}",
        opts.search.seed
    )
}
