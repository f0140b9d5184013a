//! The command line: subcommands, their arguments, and the build options
//! they make.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Result;
use clap::{Args, Parser, Subcommand, ValueEnum};

use brickwright::assembly::StepGrouping;
use brickwright::pipeline::{self, BuildOptions};
use brickwright::voxel::{Sizing, Up};

/// Examples and exit codes, shown after the options in `--help`.
const AFTER_HELP: &str = "\
Examples:
  brickwright build house.obj -o house                 every output in house/
  brickwright build tower.glb --studs 32 --slopes --formats ldr,pdf
  brickwright build part.stl --up z --height 12 --stability check
  brickwright verify house/house.ldr --stability       re-check a build
  brickwright learn my-builds/ -o learned.rules        rules from your own builds
  brickwright build house.obj --rules learned.rules -o house-learned

Exit codes: 0 done; 1 a check failed (verify found problems, or a build
would not stand under --stability check); 2 an error (bad input or options,
an output that cannot be written). Warnings go to standard error, with
--quiet too.";

/// Turn a 3D model into a LEGO build a person can assemble.
#[derive(Parser)]
#[command(
    name = "brickwright",
    version,
    about,
    long_about = None,
    propagate_version = true,
    after_help = AFTER_HELP
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Build a mesh (OBJ, glTF .gltf/.glb, STL) into bricks: writes DIR/<name>.ldr and DIR/report.json.
    #[command(after_help = "Examples:
  brickwright build house.obj -o house
  brickwright build tower.glb --studs 32 --slopes --formats ldr,pdf,bricklink
  brickwright build part.stl --up z --height 12 --plates --seed 7
  brickwright build house.obj --stability check --formats ldr   (exit 1 if a step would fall)")]
    Build(BuildArgs),
    /// Check an LDraw file made of catalog parts: overlaps, connections, placeability, one piece.
    #[command(after_help = "Examples:
  brickwright verify house/house.ldr
  brickwright verify model.mpd --stability --ground baseplate

Exit 0 when sound (and standing, with --stability), 1 when not, 2 on an unreadable file.")]
    Verify {
        /// The .ldr or .mpd file.
        file: PathBuf,
        /// Also check that the build stands at every step (static forces and stud clutch);
        /// fails when something would fall or break off.
        #[arg(long)]
        stability: bool,
        /// What the lowest layer stands on, for --stability.
        #[arg(long, value_enum, default_value_t = GroundArg::Table, requires = "stability")]
        ground: GroundArg,
    },
    /// Write a generated rule file (the default rules, or every brick of the catalog).
    #[command(after_help = "Examples:
  brickwright rules > default.rules
  brickwright rules --alphabet extended -o extended.rules")]
    Rules {
        /// Which alphabet: the default seven bricks, or every brick in the catalog.
        #[arg(long, value_enum, default_value_t = Alphabet::Default)]
        alphabet: Alphabet,
        /// Where to write (default: standard output).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Learn rule weights from step-ordered LDraw builds (.ldr/.mpd) and write a rule file.
    #[command(after_help = "Examples:
  brickwright learn my-builds/ -o learned.rules
  brickwright learn castle.mpd --seen-parts-only --unseen 0 -o strict.rules")]
    Learn(LearnArgs),
}

#[derive(Args)]
pub struct LearnArgs {
    /// The builds: .ldr or .mpd files, or directories of them.
    #[arg(required = true)]
    pub builds: Vec<PathBuf>,
    /// Where to write the rule file; `-` or none for standard output.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Weight of every connecting rule the builds never used (0: leave them out, so the
    /// search can only use joints seen in the builds).
    #[arg(long, default_value_t = brickwright::grammar::learn::DEFAULT_UNSEEN)]
    pub unseen: f64,
    /// Keep only the parts the builds used; by default the built-in parts stay in too, so
    /// the rule file can build any shape (with the parts no build used weighted `unseen`).
    #[arg(long)]
    pub seen_parts_only: bool,
    /// Print nothing but errors (and the rule file, to standard output).
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum Alphabet {
    /// 1x1, 1x2, 1x3, 1x4, 2x2, 2x3, 2x4 bricks.
    Default,
    /// Every brick in the catalog (adds 1x6, 1x8, 2x6, 2x8).
    Extended,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum GroundArg {
    /// A table: it pushes up, never holds studs.
    Table,
    /// A baseplate: it also holds the lowest pieces' tubes.
    Baseplate,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum UpAxis {
    /// +Y is up (OBJ and glTF convention).
    Y,
    /// +Z is up (CAD and STL convention).
    Z,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum StepBy {
    /// A new step whenever the build moves to another layer.
    Layer,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum SearchArg {
    /// The forward layout, course by course (fast, keeps the whole shape).
    Layout,
    /// The paper's backward tracing of the rules (section 4), with backtracking; fails
    /// (exit 2, no files) when the rules cannot build the shape within the budgets.
    Backward,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum StabilityArg {
    /// Check every step and fix what fails.
    Repair,
    /// Check every step; fail the build when one would not stand.
    Check,
    /// No check.
    Off,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum ConditionArg {
    /// New parts.
    #[value(name = "N", alias = "n")]
    New,
    /// Used parts.
    #[value(name = "U", alias = "u")]
    Used,
}

fn parse_color(s: &str) -> Result<brickwright::catalog::Color, String> {
    brickwright::catalog::Color::parse(s).ok_or_else(|| {
        format!("unknown colour `{s}` (give an LDraw code, a colour name such as \"light bluish grey\", or bl:ID)")
    })
}

fn parse_palette(s: &str) -> Result<brickwright::catalog::Palette, String> {
    brickwright::catalog::Palette::parse(s)
        .ok_or_else(|| format!("unknown palette `{s}` (mesh, layers, random, or a colour)"))
}

fn parse_formats(s: &str) -> Result<pipeline::Formats, String> {
    pipeline::Formats::parse(s)
}

#[derive(Args)]
pub struct BuildArgs {
    /// The mesh file: .obj, .gltf, .glb or .stl.
    pub input: PathBuf,
    /// Output directory (created if missing).
    #[arg(short, long, default_value = "out")]
    pub output: PathBuf,
    /// Size: the model's longest horizontal side, in studs [default: 24].
    #[arg(long, conflicts_with = "height", value_parser = clap::value_parser!(u32).range(1..=512))]
    pub studs: Option<u32>,
    /// Size: the model's height, in bricks (layers), instead of --studs.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=512))]
    pub height: Option<u32>,
    /// Which axis of the input points up.
    #[arg(long, value_enum, default_value_t = UpAxis::Y)]
    pub up: UpAxis,
    /// Seed of the search's random draws (the layout's among near-equal pieces, the backward
    /// search's rule sampling): the same input, options and seed give the same files.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// A rule file (see rules/default.rules); default: the built-in default rules.
    #[arg(long)]
    pub rules: Option<PathBuf>,
    /// Use slopes too, where the surface slants (voxels become half a brick high).
    #[arg(long)]
    pub slopes: bool,
    /// Use plates too, to follow the shape more closely (voxels become a plate high).
    #[arg(long)]
    pub plates: bool,
    /// Put this many pieces in each step (default: a step per course, at most 8 pieces a
    /// step, more only to keep a big model within the 255 steps LeoCAD can show).
    #[arg(long, conflicts_with = "step_by", value_parser = clap::value_parser!(u32).range(1..))]
    pub step_size: Option<u32>,
    /// Group steps another way.
    #[arg(long, value_enum)]
    pub step_by: Option<StepBy>,
    /// The search: layout (default) or backward (the paper's backward tracing).
    #[arg(long, value_enum, default_value_t = SearchArg::Layout)]
    pub search: SearchArg,
    /// With --search backward, give up after this many tree nodes.
    #[arg(long, value_name = "N", default_value_t = 1_000_000, value_parser = clap::value_parser!(u64).range(1..))]
    pub node_budget: u64,
    /// Test a complex rule (several pieces at once) once every K search nodes (the paper: 1 to 5);
    /// 0 never. Default: 5 with --search backward (the paper's "once every fifth node"), 0 with the
    /// layout.
    #[arg(long, value_name = "K")]
    pub complex_every: Option<u32>,
    /// Colour every piece this colour: an LDraw code (4), an LDraw or BrickLink name
    /// ("light bluish grey"), or bl:ID for a BrickLink colour id.
    #[arg(long, conflicts_with = "palette", value_parser = parse_color)]
    pub color: Option<brickwright::catalog::Color>,
    /// How to colour the pieces: mesh (the model's own colours; layers when it has none),
    /// layers (alternating by course), random, or one colour.
    #[arg(long, default_value = "mesh", value_parser = parse_palette)]
    pub palette: brickwright::catalog::Palette,
    /// With the mesh palette, use at most N LEGO colours (the model's colours reduced in Lab).
    #[arg(long = "colors", visible_alias = "colours", value_name = "N", value_parser = clap::value_parser!(u32).range(1..=64))]
    pub colors: Option<u32>,
    /// The condition the BrickLink wanted list asks for: N (new) or U (used); default any.
    #[arg(long, value_enum)]
    pub condition: Option<ConditionArg>,
    /// The files to write, comma-separated: ldr, glb, exploded-glb, gltf, bricklink, csv,
    /// steps, png, exploded-png, pdf, stress, html (the step viewer page), or all (every one
    /// but gltf); report.json is always written.
    #[arg(long, default_value = "all", value_parser = parse_formats)]
    pub formats: pipeline::Formats,
    /// The booklet's layout (page size, margins, steps a page, fonts, colours): a TOML file
    /// like templates/default.toml; default the built-in one.
    #[arg(long, value_name = "FILE")]
    pub template: Option<PathBuf>,
    /// Check that the build stands at every step (static forces, clutch at the studs):
    /// repair fixes what fails (support columns under what the model cannot hold itself,
    /// another layout, or weak pieces moved to later steps), check fails the build when a
    /// step would not stand, off skips the check.
    #[arg(long, value_enum, default_value_t = StabilityArg::Repair)]
    pub stability: StabilityArg,
    /// Time for the stability check and its repairs, in seconds; past it, no further step is
    /// checked (the finished model always is), and the report says how far it got.
    #[arg(long, value_name = "SECS", default_value_t = 120.0)]
    pub stability_budget: f64,
    /// Repair without support columns: only other layouts and orders of the model's own
    /// pieces (for a model to be built on a baseplate, say).
    #[arg(long)]
    pub no_supports: bool,
    /// Build a hollow shell (walls --wall thick, inner pillars where the roof needs them)
    /// instead of a solid model: a fraction of the pieces.
    #[arg(long)]
    pub hollow: bool,
    /// With --hollow, the shell's thickness: studs across, courses up and down (1 to 16).
    #[arg(long, value_name = "N", default_value_t = 2, requires = "hollow", value_parser = clap::value_parser!(u32).range(1..=brickwright::voxel::hollow::MAX_WALL as i64))]
    pub wall: u32,
    /// Give up the search after this many seconds.
    #[arg(long, default_value_t = 300.0)]
    pub time_budget: f64,
    /// Fail (exit 2) when any voxel of the model is left out of the build.
    #[arg(long)]
    pub strict: bool,
    /// Print nothing but errors and warnings.
    #[arg(short, long)]
    pub quiet: bool,
}

/// The longest time budget kept: about 31 years; more is taken as this
/// (no budget, in effect) rather than overflowing a clock.
const MAX_BUDGET_SECS: f64 = 1e9;

/// How often the backward search tests a complex rule by default: once
/// every fifth node, the paper's least frequent setting (section 5: "once
/// every fifth node to once every node").
const BACKWARD_COMPLEX_EVERY: u32 = 5;

/// A `--...-budget` value: positive seconds, saturated at [`MAX_BUDGET_SECS`].
fn budget(option: &str, secs: f64) -> Result<Duration> {
    if !(secs.is_finite() && secs > 0.0) {
        anyhow::bail!("{option} must be a positive number of seconds, not {secs}");
    }
    Ok(Duration::from_secs_f64(secs.min(MAX_BUDGET_SECS)))
}

impl BuildArgs {
    /// The build options these arguments ask for.
    pub fn options(self) -> Result<BuildOptions> {
        let a = self;
        let time_budget = budget("--time-budget", a.time_budget)?;
        let stability_budget = budget("--stability-budget", a.stability_budget)?;
        let mut opts = BuildOptions::new(&a.input);
        opts.out_dir = a.output;
        opts.sizing = match (a.studs, a.height) {
            (_, Some(h)) => Sizing::Height(h),
            (Some(s), None) => Sizing::Studs(s),
            (None, None) => Sizing::default(),
        };
        opts.up = match a.up {
            UpAxis::Y => Up::Y,
            UpAxis::Z => Up::Z,
        };
        opts.rules = a.rules;
        opts.slopes = a.slopes;
        opts.plates = a.plates;
        opts.steps = match (a.step_size, a.step_by) {
            (Some(n), _) => StepGrouping::Size(n as usize),
            (None, Some(StepBy::Layer)) => StepGrouping::Layer,
            (None, None) => StepGrouping::Auto,
        };
        opts.palette = a
            .color
            .map_or(a.palette, brickwright::catalog::Palette::Single);
        opts.max_colors = a.colors.map(|n| n as usize);
        opts.condition = a.condition.map(|c| match c {
            ConditionArg::New => brickwright::export::partslist::Condition::New,
            ConditionArg::Used => brickwright::export::partslist::Condition::Used,
        });
        opts.formats = a.formats;
        opts.template = a.template;
        opts.stability_budget = stability_budget;
        opts.supports = !a.no_supports;
        opts.strict = a.strict;
        opts.stability = match a.stability {
            StabilityArg::Repair => pipeline::Stability::Repair,
            StabilityArg::Check => pipeline::Stability::Check,
            StabilityArg::Off => pipeline::Stability::Off,
        };
        opts.search = opts
            .search
            .with_seed(a.seed)
            .with_time_budget(time_budget)
            .with_complex_every(a.complex_every.unwrap_or(match a.search {
                SearchArg::Layout => 0,
                SearchArg::Backward => BACKWARD_COMPLEX_EVERY,
            }))
            .with_method(match a.search {
                SearchArg::Layout => brickwright::search::Method::Layout,
                SearchArg::Backward => brickwright::search::Method::Backward,
            })
            .with_node_budget(a.node_budget)
            .with_hollow(brickwright::voxel::Wall::new(a.wall).filter(|_| a.hollow));
        Ok(opts)
    }
}
