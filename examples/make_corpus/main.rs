//! Writes brickwright's corpus of example builds into `rules/examples/`.
//!
//! ```text
//! cargo run --example make_corpus                 # writes rules/examples/
//! cargo run --example make_corpus -- --out DIR    # writes DIR/ instead
//! cargo test --example make_corpus                # the geometry's unit tests
//! ```
//!
//! Each build is an LDraw model with one piece a step, in the order a person
//! places them: bottom course first, each course laid along the wall or
//! round the rectangle, every piece above the table pressed onto (or under)
//! a piece placed before it. The tool counts how often each way of joining
//! two pieces occurs in these files, so they are built the way people
//! build: running bond, interlocking corners, lintels over openings, slopes
//! facing down the roof.
//!
//! Builds are declared in `builds/` through the helpers of `build.rs`, on a
//! stud grid (x and z in studs, heights in plates); `parts.rs` turns a
//! placement into LDraw coordinates. Before anything is written every build
//! is checked (`check.rs`); the program fails, naming the build and the
//! piece, if a check does not hold. Output depends only on this program, so
//! a test can regenerate the corpus and compare it byte for byte.

mod build;
mod builds;
mod check;
mod parts;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use build::Build;
use parts::{Kind, Part};

const USAGE: &str = "usage: make_corpus [--out DIR]   (DIR defaults to rules/examples)";

fn main() -> ExitCode {
    let out = match parse_args(std::env::args().skip(1)) {
        Ok(Some(out)) => out,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(message) => {
            eprintln!("error: {message}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(&out) {
        Ok(builds) => {
            print!("{}", build_table(&builds));
            println!("wrote {} builds to {}", builds.len(), out.display());
            ExitCode::SUCCESS
        }
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// The output directory, or `None` when help was asked for.
fn parse_args(mut args: impl Iterator<Item = String>) -> Result<Option<PathBuf>, String> {
    let mut out = PathBuf::from("rules/examples");
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--out" => out = args.next().ok_or("--out needs a directory")?.into(),
            "-h" | "--help" => return Ok(None),
            other => return Err(format!("unexpected argument {other:?}")),
        }
    }
    Ok(Some(out))
}

/// Checks every build, then writes the `.ldr` files and the README.
fn run(out: &Path) -> Result<Vec<Build>, String> {
    let builds = builds::all();
    let mut files: Vec<(String, String)> = Vec::new();
    for build in &builds {
        check::check(build)?;
        if files
            .iter()
            .any(|(f, _)| *f == format!("{}.ldr", build.name))
        {
            return Err(format!("{}: two builds share the name", build.name));
        }
        files.push((format!("{}.ldr", build.name), build.to_ldr()));
    }
    files.push(("README.md".to_string(), readme(&builds)));

    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    for (name, text) in &files {
        let path = out.join(name);
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    Ok(builds)
}

/// One line a build: file, pieces, what it shows.
fn build_table(builds: &[Build]) -> String {
    let mut out = String::from("| file | pieces | what it shows |\n|---|---:|---|\n");
    for b in builds {
        writeln!(
            out,
            "| `{}.ldr` | {} | {} |",
            b.name,
            b.pieces.len(),
            b.about
        )
        .unwrap();
    }
    let total: usize = builds.iter().map(|b| b.pieces.len()).sum();
    writeln!(out, "| all | {total} | |").unwrap();
    out
}

/// How many of each part the corpus uses, by family.
fn part_table(builds: &[Build]) -> String {
    let mut out = String::from("| part | LDraw file | studs | pieces |\n|---|---|---|---:|\n");
    for part in Part::ALL {
        let n = builds
            .iter()
            .flat_map(|b| &b.pieces)
            .filter(|p| p.part == part)
            .count();
        let s = part.spec();
        let family = match (s.kind, s.plates) {
            (Kind::Rect, 3) => "brick",
            (Kind::Rect, _) => "plate",
            (Kind::Slope, _) => "slope",
            (Kind::Inverted, _) => "inverted slope",
        };
        writeln!(
            out,
            "| {family} | `{}.dat` | {} x {} | {n} |",
            s.file, s.deep, s.wide
        )
        .unwrap();
    }
    out
}

fn readme(builds: &[Build]) -> String {
    format!(
        "{}\n## The builds\n\n{}\n## Parts used\n\nStuds are given deep x wide \
         (for slopes: deep is the back row plus the slope).\n\n{}",
        include_str!("README.head.md"),
        build_table(builds),
        part_table(builds)
    )
}
