//! The whole job: mesh file in, verified LDraw build and report out.
//!
//! [`build`] runs the stages in order, each a function with its own input
//! and output, in a module named for it: `input` loads the rules, the mesh
//! and voxelizes it; `plan` lays the pieces out and orders them in
//! verified steps; [`stability`] checks and repairs every step;
//! [`pictures`] draws the step images and the booklet; `write` writes every
//! output; `report` is what `report.json` says. The assembly is verified
//! with the independent [`verify`](crate::assembly::verify) before
//! anything is written, and every output is written atomically: a failed
//! run leaves no file behind.

use std::time::Instant;

mod error;
pub mod hollow;
mod input;
mod options;
pub mod pictures;
mod plan;
mod report;
pub mod stability;
mod write;

pub use error::BuildError;
pub use input::{bricks_by_course, load_rules};
pub use options::{BuildOptions, Format, Formats, DEFAULT_STABILITY_BUDGET, SUPPORT_NOTE};
pub use report::{BuildReport, MeshColorReport, Quality, ReportOptions, StageTimes};
pub use stability::{Stability, StabilityReport};

use crate::assembly::Assembly;

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

/// Seconds since `t`, to the millisecond.
fn secs(t: Instant) -> f64 {
    (t.elapsed().as_secs_f64() * 1000.0).round() / 1000.0
}

/// Runs `f` as the stage `name`: shown by `progress`, its time added to
/// `time`.
fn stage<T>(
    progress: &dyn Progress,
    name: &str,
    time: &mut f64,
    f: impl FnOnce() -> Result<T, BuildError>,
) -> Result<T, BuildError> {
    progress.stage(name);
    let t = Instant::now();
    let out = f();
    *time += secs(t);
    progress.done();
    out
}

/// Runs the pipeline and writes the outputs `opts.formats` names and
/// `report.json` into `opts.out_dir`.
pub fn build(opts: &BuildOptions, progress: &dyn Progress) -> Result<BuildOutput, BuildError> {
    opts.check()?;
    let mut times = StageTimes::default();
    // The rules are made while the mesh loads; a bad rule file is the
    // error reported when both fail.
    let (setup, mesh) = std::thread::scope(|s| {
        let rules = &mut times.rules;
        let setup = s.spawn(move || stage(&Silent, "", rules, || input::setup(opts)));
        let mesh = stage(progress, "loading mesh", &mut times.load, || {
            input::load(opts)
        });
        let setup = setup
            .join()
            .unwrap_or_else(|e| std::panic::resume_unwind(e));
        (setup, mesh)
    });
    let (setup, mesh) = (setup?, mesh?);
    let model = stage(progress, "voxelizing", &mut times.voxelize, || {
        input::voxelize(opts, &mesh, &setup.rules)
    })?;

    let planner = plan::Planner::new(opts, &model, &setup.rules, progress);
    let mut search_time = 0.0;
    let first = stage(progress, "searching", &mut search_time, || planner.first())?;
    times.verify = planner.verify_secs();
    times.search = search_time - times.verify;

    let settled = match opts.stability {
        Stability::Off => stability::Settled::unchecked(first),
        _ => stage(progress, "checking stability", &mut times.stability, || {
            stability::stage(opts, first, &planner, progress)
        })?,
    };

    // A hollow build is set beside the solid one it replaces, laid out too.
    let hollow = match opts.search.hollow {
        Some(_) => stage(
            progress,
            "laying out the solid build",
            &mut times.search,
            || planner.solid_report(&settled),
        )?,
        None => None,
    };

    let stem = opts.stem();
    let pictures = pictures::Pictures::of(&settled, &stem, setup.rules.layer_ldu());
    // The outputs without pictures are made beside the pictures, and the
    // pictures' PNG files beside the booklet: each pair on its own thread.
    let (rendered, data) = std::thread::scope(|s| {
        let data = s.spawn(|| write::data_outputs(opts, &setup.rules, &settled, &pictures));
        let rendered = match pictures::wanted(&opts.formats) {
            Some(steps) => stage(progress, "rendering", &mut times.render, || {
                Ok(Some(pictures::render_all(&pictures, steps, progress)?))
            }),
            None => Ok(None),
        };
        let data = data.join().unwrap_or_else(|e| std::panic::resume_unwind(e));
        rendered.map(|r| (r, data))
    })?;
    let (booklet, encoded) = std::thread::scope(|s| {
        let encoded = rendered
            .as_ref()
            .map(|r| s.spawn(|| write::encode_pictures(opts, r)));
        let booklet = match &rendered {
            Some(rendered) if opts.formats.contains(Format::Pdf) => stage(
                progress,
                "laying out the booklet",
                &mut times.booklet,
                || write::booklet(opts, &pictures, rendered, &setup.template),
            )
            .map(Some),
            _ => Ok(None),
        };
        let encoded = encoded.map(|e| e.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
        booklet.map(|b| (b, encoded))
    })?;

    let pages = booklet.as_ref().map(|b| b.pages);
    let mut report = report::compose(
        opts,
        &setup.rules,
        &mesh,
        &model,
        &settled,
        hollow,
        pages,
        times,
    );
    report.warnings.extend(planner.notes());
    progress.stage("writing");
    let report = write::write(
        opts,
        &settled,
        &pictures,
        data,
        encoded.as_ref(),
        booklet.as_ref().map(|b| b.pdf.as_slice()),
        report,
    )?;
    progress.done();
    Ok(BuildOutput {
        assembly: settled.assembly,
        report,
    })
}
