//! What `brickwright build` can be told: [`BuildOptions`] and the output
//! [`Format`]s.

use std::path::PathBuf;

use serde::Serialize;

use super::{BuildError, Stability};
use crate::assembly::StepGrouping;
use crate::catalog::Palette;
use crate::export::partslist::Condition;
use crate::search::SearchOptions;
use crate::voxel::{Sizing, Up};

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
    /// Options that do not go together, found before any work is done.
    pub(super) fn check(&self) -> Result<(), BuildError> {
        if self.stability == Stability::Off
            && self.formats.contains(Format::Stress)
            && self.formats != Formats::default()
        {
            return Err(BuildError::Options(
                "--formats stress needs the stability check; drop --stability off".into(),
            ));
        }
        Ok(())
    }

    /// The input's file name without its extension: the outputs' name.
    pub fn stem(&self) -> String {
        self.input
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "model".into())
    }

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

/// The step grouping in words, for the report.
pub(super) fn step_name(s: StepGrouping) -> String {
    match s {
        StepGrouping::Auto => "by course, at most 8 pieces a step (more past 255 steps)".into(),
        StepGrouping::Each => "one piece a step".into(),
        StepGrouping::Size(n) => format!("{n} pieces a step"),
        StepGrouping::Layer => "by layer".into(),
    }
}

/// The options as a one-line command-line echo, for file headers.
pub(super) fn describe(opts: &BuildOptions) -> String {
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
    let search = match opts.search.method {
        crate::search::Method::Layout => "",
        crate::search::Method::Backward => " --search backward",
    };
    format!(
        "{size} --up {up} --seed {}{search}{rules}{slopes}{plates}{steps}{palette}{stability}",
        opts.search.seed
    )
}
