//! The `brickwright` command-line tool: parse, run, report.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};

use brickwright::assembly::verify::verify;
use brickwright::assembly::StepGrouping;
use brickwright::grammar::learn::learn;
use brickwright::grammar::{extended_alphabet, rules_text, DEFAULT_ALPHABET};
use brickwright::pipeline::{self, BuildOptions, Progress, Silent};
use brickwright::terminal::{escape_controls, escape_lines};
use brickwright::voxel::{Sizing, Up};

/// `println!` that ends the program quietly when standard output has been
/// closed (`brickwright verify x.ldr | head -1`) instead of panicking; the
/// exit code is the shell's for a broken pipe.
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if writeln!(std::io::stdout(), $($t)*).is_err() {
            std::process::exit(141);
        }
    }};
}

/// `print!`, as [`outln!`].
macro_rules! out {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if write!(std::io::stdout(), $($t)*).is_err() {
            std::process::exit(141);
        }
    }};
}

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
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
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
struct LearnArgs {
    /// The builds: .ldr or .mpd files, or directories of them.
    #[arg(required = true)]
    builds: Vec<PathBuf>,
    /// Where to write the rule file; `-` or none for standard output.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Weight of every connecting rule the builds never used (0: leave them out, so the
    /// search can only use joints seen in the builds).
    #[arg(long, default_value_t = brickwright::grammar::learn::DEFAULT_UNSEEN)]
    unseen: f64,
    /// Keep only the parts the builds used; by default the built-in parts stay in too, so
    /// the rule file can build any shape (with the parts no build used weighted `unseen`).
    #[arg(long)]
    seen_parts_only: bool,
    /// Print nothing but errors (and the rule file, to standard output).
    #[arg(short, long)]
    quiet: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum Alphabet {
    /// 1x1, 1x2, 1x3, 1x4, 2x2, 2x3, 2x4 bricks.
    Default,
    /// Every brick in the catalog (adds 1x6, 1x8, 2x6, 2x8).
    Extended,
}

#[derive(Clone, Copy, ValueEnum)]
enum GroundArg {
    /// A table: it pushes up, never holds studs.
    Table,
    /// A baseplate: it also holds the lowest pieces' tubes.
    Baseplate,
}

#[derive(Clone, Copy, ValueEnum)]
enum UpAxis {
    /// +Y is up (OBJ and glTF convention).
    Y,
    /// +Z is up (CAD and STL convention).
    Z,
}

#[derive(Clone, Copy, ValueEnum)]
enum StepBy {
    /// A new step whenever the build moves to another layer.
    Layer,
}

#[derive(Clone, Copy, ValueEnum)]
enum StabilityArg {
    /// Check every step and fix what fails.
    Repair,
    /// Check every step; fail the build when one would not stand.
    Check,
    /// No check.
    Off,
}

#[derive(Clone, Copy, ValueEnum)]
enum ConditionArg {
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
struct BuildArgs {
    /// The mesh file: .obj, .gltf, .glb or .stl.
    input: PathBuf,
    /// Output directory (created if missing).
    #[arg(short, long, default_value = "out")]
    output: PathBuf,
    /// Size: the model's longest horizontal side, in studs [default: 24].
    #[arg(long, conflicts_with = "height", value_parser = clap::value_parser!(u32).range(1..=512))]
    studs: Option<u32>,
    /// Size: the model's height, in bricks (layers), instead of --studs.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=512))]
    height: Option<u32>,
    /// Which axis of the input points up.
    #[arg(long, value_enum, default_value_t = UpAxis::Y)]
    up: UpAxis,
    /// Seed for the search's rule sampling: the same input, options and seed give the same files.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// A rule file (see rules/default.rules); default: the built-in default rules.
    #[arg(long)]
    rules: Option<PathBuf>,
    /// Use slopes too, where the surface slants (voxels become half a brick high).
    #[arg(long)]
    slopes: bool,
    /// Use plates too, to follow the shape more closely (voxels become a plate high).
    #[arg(long)]
    plates: bool,
    /// Put this many pieces in each step (default: a step per course, at most 8 pieces a
    /// step, more only to keep a big model within the 255 steps LeoCAD can show).
    #[arg(long, conflicts_with = "step_by", value_parser = clap::value_parser!(u32).range(1..))]
    step_size: Option<u32>,
    /// Group steps another way.
    #[arg(long, value_enum)]
    step_by: Option<StepBy>,
    /// Test a complex rule (several pieces at once) once every K search nodes (the paper: 1 to 5); 0 never.
    #[arg(long, value_name = "K", default_value_t = 0)]
    complex_every: u32,
    /// Colour every piece this colour: an LDraw code (4), an LDraw or BrickLink name
    /// ("light bluish grey"), or bl:ID for a BrickLink colour id.
    #[arg(long, conflicts_with = "palette", value_parser = parse_color)]
    color: Option<brickwright::catalog::Color>,
    /// How to colour the pieces: mesh (the model's own colours; layers when it has none),
    /// layers (alternating by course), random, or one colour.
    #[arg(long, default_value = "mesh", value_parser = parse_palette)]
    palette: brickwright::catalog::Palette,
    /// With the mesh palette, use at most N LEGO colours (the model's colours reduced in Lab).
    #[arg(long = "colors", visible_alias = "colours", value_name = "N", value_parser = clap::value_parser!(u32).range(1..=64))]
    colors: Option<u32>,
    /// The condition the BrickLink wanted list asks for: N (new) or U (used); default any.
    #[arg(long, value_enum)]
    condition: Option<ConditionArg>,
    /// The files to write, comma-separated: ldr, glb, exploded-glb, gltf, bricklink, csv,
    /// steps, png, exploded-png, pdf, stress, html (the step viewer page), or all (every one
    /// but gltf); report.json is always written.
    #[arg(long, default_value = "all", value_parser = parse_formats)]
    formats: pipeline::Formats,
    /// The booklet's layout (page size, margins, steps a page, fonts, colours): a TOML file
    /// like templates/default.toml; default the built-in one.
    #[arg(long, value_name = "FILE")]
    template: Option<PathBuf>,
    /// Check that the build stands at every step (static forces, clutch at the studs):
    /// repair fixes what fails (support columns under what the model cannot hold itself,
    /// another layout, or weak pieces moved to later steps), check fails the build when a
    /// step would not stand, off skips the check.
    #[arg(long, value_enum, default_value_t = StabilityArg::Repair)]
    stability: StabilityArg,
    /// Time for the stability check and its repairs, in seconds; past it, no further step is
    /// checked (the finished model always is), and the report says how far it got.
    #[arg(long, value_name = "SECS", default_value_t = 120.0)]
    stability_budget: f64,
    /// Repair without support columns: only other layouts and orders of the model's own
    /// pieces (for a model to be built on a baseplate, say).
    #[arg(long)]
    no_supports: bool,
    /// Give up the search after this many seconds.
    #[arg(long, default_value_t = 300.0)]
    time_budget: f64,
    /// Fail (exit 2) when any voxel of the model is left out of the build.
    #[arg(long)]
    strict: bool,
    /// Print nothing but errors and warnings.
    #[arg(short, long)]
    quiet: bool,
}

/// Spinners on standard error, one per stage; hidden when not a terminal.
struct Spinners {
    bar: std::cell::RefCell<Option<ProgressBar>>,
}

impl Progress for Spinners {
    fn stage(&self, name: &str) {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("valid template"),
        );
        bar.set_message(name.to_string());
        bar.enable_steady_tick(Duration::from_millis(120));
        *self.bar.borrow_mut() = Some(bar);
    }
    fn done(&self) {
        if let Some(b) = self.bar.borrow_mut().take() {
            b.finish_and_clear();
        }
    }
    fn advance(&self, done: u64, total: u64) {
        if let Some(b) = self.bar.borrow().as_ref() {
            if b.length() != Some(total) {
                // From a spinner to a bar with counts and time left.
                b.set_style(
                    ProgressStyle::with_template(
                        "{spinner} {msg} [{bar:30}] {pos}/{len}, {eta} left",
                    )
                    .expect("valid template")
                    .progress_chars("=> "),
                );
                b.set_length(total);
            }
            b.set_position(done);
        }
    }
}

/// The longest time budget kept: about 31 years; more is taken as this
/// (no budget, in effect) rather than overflowing a clock.
const MAX_BUDGET_SECS: f64 = 1e9;

/// A `--...-budget` value: positive seconds, saturated at [`MAX_BUDGET_SECS`].
fn budget(option: &str, secs: f64) -> Result<Duration> {
    if !(secs.is_finite() && secs > 0.0) {
        anyhow::bail!("{option} must be a positive number of seconds, not {secs}");
    }
    Ok(Duration::from_secs_f64(secs.min(MAX_BUDGET_SECS)))
}

fn run_build(a: BuildArgs) -> Result<()> {
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
        .with_complex_every(a.complex_every);
    let spinners = Spinners {
        bar: Default::default(),
    };
    let progress: &dyn Progress = if a.quiet { &Silent } else { &spinners };
    let opts_out = opts.out_dir.clone();
    let out = pipeline::build(&opts, progress)?;
    // Warnings go to standard error, with --quiet too.
    for w in out
        .report
        .warnings
        .iter()
        .cloned()
        .chain(build_warnings(&out.report))
    {
        eprintln!("warning: {}", escape_controls(&w));
    }
    if !a.quiet {
        let r = &out.report;
        outln!(
            "{} -> {}: {} pieces in {} steps, {} voxels ({:.1} voxels a piece), {}x{} studs x {} bricks high, verified",
            r.input, opts_out.display(), r.pieces, r.steps, r.voxels, r.voxels_per_piece, r.grid[0], r.grid[1],
            fmt_bricks(r.grid[2], r.layer_ldu)
        );
        outln!(
            "  {:>5}   {:<6} {:<30} {:<22} BrickLink",
            "count",
            "part",
            "name",
            "colour"
        );
        for p in &r.parts {
            let bl_color = p.bricklink_color.map_or_else(
                || "no BrickLink colour".to_string(),
                |c| format!("colour {c}"),
            );
            outln!(
                "  {:>5} x {:<6} {:<30} {:<22} {} {}",
                p.count,
                p.part,
                p.name,
                p.color_name,
                p.bricklink,
                bl_color
            );
        }
        let is_step = |f: &str| {
            std::path::Path::new(f)
                .parent()
                .is_some_and(|d| d.ends_with("steps"))
        };
        let steps: Vec<&String> = r.outputs.iter().filter(|f| is_step(f)).collect();
        for f in r.outputs.iter().filter(|f| !is_step(f)) {
            match r.booklet_pages.filter(|_| f.ends_with(".pdf")) {
                Some(n) => outln!("  wrote {f} ({n} pages)"),
                None => outln!("  wrote {f}"),
            }
        }
        if let Some(first) = steps.first() {
            let dir = std::path::Path::new(first.as_str())
                .parent()
                .unwrap_or(std::path::Path::new("."));
            outln!("  wrote {} step images in {}", steps.len(), dir.display());
        }
        let rep = &r.repairs;
        if rep.joined_islands + rep.thickened_voxels + rep.evened_voxels + rep.extra_cells > 0 {
            outln!(
                "  repairs: {} islands joined ({} voxels of supports and bridges), {} voxels added to make one-layer sheets two layers thick, {} voxels added to even flat tops to whole courses, {} cells outside the surface filled to join thin features",
                rep.joined_islands, rep.support_voxels, rep.thickened_voxels, rep.evened_voxels, rep.extra_cells
            );
        }
        let q = &r.quality;
        outln!(
            "  quality: {} voxels left out, {:.0}% of seams continued, {:.1} voxels a piece, {:.0}% 1x1s, {} studs across (asked {})",
            q.left_out,
            100.0 * q.seams_continued,
            q.voxels_per_piece,
            100.0 * q.share_1x1,
            q.extent_studs,
            q.requested_studs.map_or("by height".to_string(), |n| n.to_string())
        );
        outln!(
            "  seams: {} of {} vertical seams continue into the course above ({:.0}%; lower is stronger)",
            r.seams.continued,
            r.seams.seams,
            100.0 * r.seams.fraction
        );
        if let Some(st) = &r.stability {
            print_build_stability(st);
        }
        let s = &r.seconds;
        outln!(
            "  search: {} nodes, {} candidates, {} joins; time: load {:.2}s, voxelize {:.2}s, search {:.2}s, verify {:.2}s, stability {:.2}s, render {:.2}s, booklet {:.2}s, write {:.2}s",
            r.search.nodes, r.search.candidates, r.search.joins, s.load, s.voxelize, s.search, s.verify, s.stability, s.render, s.booklet, s.write
        );
    }
    Ok(())
}

/// What a user of a finished build should know: each a line for standard
/// error.
fn build_warnings(r: &pipeline::BuildReport) -> Vec<String> {
    let mut out = Vec::new();
    if !r.unmapped_colors.is_empty() {
        out.push(format!(
            "colours with no known BrickLink or Rebrickable id: {:?}; their parts-list lines say so",
            r.unmapped_colors
        ));
    }
    if r.repairs.budget_left_out > 0 {
        out.push(format!(
            "{}: the search ran out of time (--time-budget {}); {} voxels above the last layer laid are not built (raise --time-budget or lower --studs)",
            r.input, r.options.time_budget, r.repairs.budget_left_out
        ));
    }
    if r.repairs.left_out > 0 {
        let mut w = format!(
            "{}: {} voxels of the model are left out: nothing could join them to the build",
            r.input, r.repairs.left_out
        );
        for p in &r.repairs.left_out_places {
            w.push_str(&format!(
                "\n  {} voxels at layer {}, stud ({}, {}): {}",
                p.voxels, p.layer, p.x, p.y, p.reason
            ));
        }
        out.push(w);
    }
    if let Some(st) = &r.stability {
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

/// The stability lines of the build summary.
fn print_build_stability(st: &pipeline::StabilityReport) {
    let verdict = match (st.first_failure, st.complete) {
        (None, true) => "stands at every step".to_string(),
        (None, false) => format!(
            "checked {} steps before its time budget ran out; they and the finished model stand",
            st.steps_checked
        ),
        (Some(step), _) => format!("does not stand from step {step} on"),
    };
    outln!(
        "  stability: {verdict}; finished model: lowest score {:.2}, mean {:.2} (score = 1 - share of stud clutch used; {} analyses)",
        st.min_score, st.mean_score, st.solves
    );
    for line in &st.repairs {
        outln!("  repaired {line}");
    }
    match st.stands_on_baseplate {
        Some(true) => outln!(
            "  hint: it stands at every step when built on a baseplate, whose studs hold the bottom course"
        ),
        Some(false) => outln!("  (it would not stand on a baseplate either)"),
        None => {}
    }
}

/// A height of `layers` layers `layer_ldu` high, in bricks (24 LDU).
fn fmt_bricks(layers: i32, layer_ldu: i32) -> String {
    let ldu = layers * layer_ldu;
    if ldu % 24 == 0 {
        (ldu / 24).to_string()
    } else {
        format!("{:.2}", f64::from(ldu) / 24.0)
    }
}

fn run_verify(file: PathBuf, stability: Option<GroundArg>) -> Result<bool> {
    let model = brickwright::ldraw::read_ldr(&file)?;
    let asm = brickwright::ldraw::to_assembly(&model)?;
    let report = verify(&asm, None);
    let sound = report.is_ok();
    if sound {
        outln!(
            "{}: OK: {} pieces, {} steps, one connected build",
            file.display(),
            asm.pieces.len(),
            asm.step_count()
        );
    } else {
        outln!("{}: {} problems", file.display(), report.failures.len());
        outln!("{report}");
    }
    let stands = match stability {
        Some(ground) => print_stability(&file, &model, &asm, ground)?,
        None => true,
    };
    Ok(sound && stands)
}

/// Prints the static force analysis of every step; whether it all stands.
fn print_stability(
    file: &std::path::Path,
    model: &brickwright::ldraw::LdrModel,
    asm: &brickwright::assembly::Assembly,
    ground: GroundArg,
) -> Result<bool> {
    use brickwright::physics::{analyze_steps, Ground, Params};
    let (ground, on) = match ground {
        GroundArg::Table => (Ground::Table, "on a table"),
        GroundArg::Baseplate => (Ground::Baseplate, "on a baseplate"),
    };
    let params = Params::default().with_ground(ground);
    let s = analyze_steps(asm, &params, false)
        .with_context(|| format!("{}: stability analysis", file.display()))?;
    let a = &s.last;
    let stands = s.first_failure.is_none();
    outln!(
        "{}: stability: {}: min score {:.3}, mean {:.3}, max clutch usage {:.3} (clutch {} N a stud, {on})",
        file.display(),
        if stands { "stands at every step" } else { "FAILS" },
        a.min_score,
        a.mean_score,
        a.max_usage,
        params.clutch_n
    );
    let describe = |i: usize| {
        let p = &asm.pieces[i];
        let st = &a.pieces[i];
        let what = if st.falls {
            "falls".to_string()
        } else if st.breaks {
            format!("breaks off, clutch usage {:.3}", st.usage)
        } else {
            format!("clutch usage {:.3}, score {:.3}", st.usage, st.score)
        };
        let line = model
            .parts
            .get(i)
            .map_or_else(String::new, |r| format!("line {}, ", r.line));
        format!(
            "piece #{i} ({line}{}, step {}): {what}",
            p.placement.part.spec().id,
            p.step.0
        )
    };
    if !a.pieces.is_empty() {
        outln!("  weakest pieces of the finished build:");
        for i in a.weakest(5) {
            outln!("    {}", describe(i));
        }
    }
    if let Some(step) = s.first_failure {
        let check = s.steps.iter().find(|c| c.step == step);
        outln!("  first failing step: {step}");
        if let Some(c) = check {
            for &i in c.weakest.iter().take(3) {
                let p = &asm.pieces[i];
                outln!(
                    "    piece #{i} ({}{}, step {})",
                    model
                        .parts
                        .get(i)
                        .map_or_else(String::new, |r| format!("line {}, ", r.line)),
                    p.placement.part.spec().id,
                    p.step.0
                );
            }
        }
    }
    outln!(
        "  {} steps checked: {} programs solved, {} groups carried over, {:.2} s",
        s.steps.len(),
        s.solves,
        s.reused,
        s.seconds
    );
    Ok(stands)
}

fn run_rules(alphabet: Alphabet, output: Option<PathBuf>) -> Result<()> {
    let text = match alphabet {
        Alphabet::Default => rules_text(&DEFAULT_ALPHABET, "default"),
        Alphabet::Extended => rules_text(&extended_alphabet(), "extended"),
    };
    match output {
        Some(p) => brickwright::fsutil::write_atomic(&p, |w| w.write_all(text.as_bytes()))
            .with_context(|| format!("{}: cannot write", p.display()))?,
        None => out!("{text}"),
    }
    Ok(())
}

fn run_learn(a: LearnArgs) -> Result<()> {
    if !(a.unseen.is_finite() && a.unseen >= 0.0) {
        anyhow::bail!("--unseen must be a weight of 0 or more");
    }
    let mut learned = learn(&a.builds)?;
    if a.seen_parts_only {
        learned = learned.seen_parts_only()?;
    }
    let learned = learned.with_unseen((a.unseen > 0.0).then_some(a.unseen));
    let text = learned.to_rules_text();
    let file = a.output.filter(|p| p.as_os_str() != "-");
    match &file {
        Some(p) => brickwright::fsutil::write_atomic(p, |w| w.write_all(text.as_bytes()))
            .with_context(|| format!("{}: cannot write", p.display()))?,
        None => out!("{text}"),
    }
    if !a.quiet {
        // The summary goes beside the rule file, never into it.
        match &file {
            Some(p) => outln!(
                "{}  wrote {}",
                escape_lines(&learned.summary()),
                p.display()
            ),
            None => eprint!("{}", escape_lines(&learned.summary())),
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Build(a) => run_build(a).map(|()| true),
        Command::Verify {
            file,
            stability,
            ground,
        } => run_verify(file, stability.then_some(ground)),
        Command::Rules { alphabet, output } => run_rules(alphabet, output).map(|()| true),
        Command::Learn(a) => run_learn(a).map(|()| true),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            // A failed stability check is a finding, as in `verify
            // --stability`: exit 1; anything else is an error: exit 2.
            let code = match e.downcast_ref::<pipeline::BuildError>() {
                Some(pipeline::BuildError::Unstable { .. }) => 1,
                _ => 2,
            };
            // One line: the error, then any cause its message does not
            // already say.
            let mut line = e.to_string();
            for cause in e.chain().skip(1) {
                let c = cause.to_string();
                if !line.contains(&c) {
                    line.push_str(": ");
                    line.push_str(&c);
                }
            }
            eprintln!("error: {}", escape_controls(&line));
            ExitCode::from(code)
        }
    }
}
