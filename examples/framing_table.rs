//! Builds meshes with the command-line tool and measures their step
//! pictures and steps as `tests/framing.rs` does, one table row a build.
//!
//! ```text
//! cargo build --release
//! cargo run --release --example framing_table -- [--studs 24,32] [--stability off] \
//!     [--limit SECS] [--keep DIR] MESH...
//! ```
//!
//! Each mesh is built with `target/release/brickwright build MESH --studs N
//! -o DIR` and the default options (`--stability` passed on when given);
//! a build that takes longer than `--limit` seconds (default 150) is
//! stopped and reported as such. Columns: pieces, steps, mean new pieces
//! a step, share of steps with 3 to 8, the largest step; the model's share
//! of the step image (the larger side of its box over the frame's) in the
//! median step and the lowest tenth; the same of the printed pictures
//! (cut to the model); pages of steps and of the whole booklet; steps
//! whose view turned; and what misses: turned steps whose badge covers
//! the box of the new pieces, changes of scale under a quarter,
//! steps whose new pieces leave the frame or whose model touches its edge.
//! The build's own outputs are measured: its `.ldr` read back gives the
//! steps, its step images the framing. With `--keep DIR` the builds stay
//! in `DIR/NAME-N`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use brickwright::ldraw;

#[path = "../tests/common/framing.rs"]
mod measure;

use measure::quantile;

struct Args {
    bin: PathBuf,
    studs: Vec<u32>,
    stability: Option<String>,
    limit: Duration,
    keep: Option<PathBuf>,
    meshes: Vec<PathBuf>,
}

fn args() -> Result<Args> {
    let mut a = Args {
        bin: PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/release/brickwright"),
        studs: vec![24, 32],
        stability: None,
        limit: Duration::from_secs(150),
        keep: None,
        meshes: Vec::new(),
    };
    let mut it = std::env::args().skip(1);
    while let Some(s) = it.next() {
        let mut value = || it.next().with_context(|| format!("{s} needs a value"));
        match s.as_str() {
            "--studs" => {
                a.studs = value()?
                    .split(',')
                    .map(|n| n.parse().context("--studs needs numbers"))
                    .collect::<Result<_>>()?
            }
            "--stability" => a.stability = Some(value()?),
            "--limit" => a.limit = Duration::from_secs_f64(value()?.parse()?),
            "--keep" => a.keep = Some(PathBuf::from(value()?)),
            "--bin" => a.bin = PathBuf::from(value()?),
            _ if s.starts_with("--") => bail!("unknown option {s}"),
            _ => a.meshes.push(PathBuf::from(s)),
        }
    }
    if a.meshes.is_empty() {
        bail!("usage: framing_table [--studs 24,32] [--stability MODE] [--limit SECS] [--keep DIR] MESH...");
    }
    Ok(a)
}

/// Runs one build into `out`; `Ok(false)` when it ran out of time.
fn run_build(a: &Args, mesh: &Path, studs: u32, out: &Path) -> Result<bool> {
    let mut cmd = Command::new(&a.bin);
    cmd.arg("build")
        .arg(mesh)
        .arg("--studs")
        .arg(studs.to_string())
        .arg("-o")
        .arg(out)
        .arg("--quiet");
    if let Some(s) = &a.stability {
        cmd.arg("--stability").arg(s);
    }
    let mut child = cmd.spawn().context("runs the build")?;
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait()? {
            if !status.success() {
                bail!("the build failed: {status}");
            }
            return Ok(true);
        }
        if start.elapsed() > a.limit {
            child.kill()?;
            child.wait()?;
            return Ok(false);
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

fn row(a: &Args, mesh: &Path, studs: u32, out: &Path) -> Result<String> {
    let name = mesh.file_stem().context("a file name")?.to_string_lossy();
    let head = format!(
        "| {} | {studs} ",
        mesh.file_name().unwrap().to_string_lossy()
    );
    let t = Instant::now();
    if !run_build(a, mesh, studs, out)? {
        return Ok(format!("{head}| over {} s |", a.limit.as_secs()));
    }
    let secs = t.elapsed().as_secs_f64();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json"))?)?;
    let asm = ldraw::to_assembly(&ldraw::read_ldr(&out.join(format!("{name}.ldr")))?)?;
    let steps = asm.step_count() as usize;
    if report["steps"].as_u64() != Some(steps as u64) {
        bail!("the .ldr has {steps} steps, the report {}", report["steps"]);
    }
    let sizes = measure::step_sizes(&asm).context("steps numbered with a gap")?;
    let pieces = asm.pieces.len();
    let sized = sizes.iter().filter(|&&s| (3..=8).contains(&s)).count();
    let r = measure::renderer(&asm);
    let images = measure::step_images(&out.join("steps"), steps);
    let f = measure::framing(&r, &images);
    let notes: BTreeMap<u32, String> = report["stability"]["supports"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|c| Some((c["step"].as_u64()?, c["last_step"].as_u64()?)))
        .flat_map(|(a, b)| a as u32..=b as u32)
        .map(|s| (s, brickwright::pipeline::SUPPORT_NOTE.to_string()))
        .collect();
    let p = measure::pages(&asm, &r, &images, &notes);
    let list = |v: &[usize]| {
        if v.is_empty() {
            "-".to_string()
        } else {
            format!("{v:?}")
        }
    };
    let small: Vec<String> = f
        .small_changes()
        .iter()
        .map(|(s, c)| format!("{s}: {c:.2}"))
        .collect();
    Ok(format!(
        "{head}| {pieces} | {steps} | {:.2} | {:.0}% | {} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} | {} | {} | {} | {} | {} | {secs:.0} |",
        pieces as f64 / steps as f64,
        100.0 * sized as f64 / steps as f64,
        sizes.iter().max().unwrap_or(&0),
        quantile(&f.shares, 0.5),
        quantile(&f.shares, 0.1),
        quantile(&p.shares, 0.5),
        quantile(&p.shares, 0.1),
        p.pages,
        report["booklet_pages"],
        f.turns,
        list(&f.badge_over_new),
        if small.is_empty() { "-".to_string() } else { small.join(", ") },
        list(&f.cut_off),
        list(&f.at_edge),
    ))
}

fn main() -> Result<()> {
    let a = args()?;
    println!("| input | studs | pieces | steps | pieces/step | 3-8 | largest | share median | share 10% | printed median | printed 10% | step pages | pages | turns | badge on new | small changes | cut off | at edge | s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let tmp = tempfile::tempdir()?;
    for mesh in &a.meshes {
        for &studs in &a.studs {
            let name = mesh.file_stem().context("a file name")?.to_string_lossy();
            let out = a
                .keep
                .as_deref()
                .unwrap_or(tmp.path())
                .join(format!("{name}-{studs}"));
            match row(&a, mesh, studs, &out) {
                Ok(r) => println!("{r}"),
                Err(e) => println!("| {} | {studs} | error: {e:#} |", mesh.display()),
            }
        }
    }
    Ok(())
}
