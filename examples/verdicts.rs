//! Compares the step check's verdicts with the force program's, step by
//! step, on built models: one table row a model.
//!
//! ```text
//! cargo run --release --example verdicts -- MODEL.ldr...
//! ```
//!
//! The step check ([`analyze_steps`]) says a step stands when it finds an
//! equilibrium of the pieces placed so far with no hand force and every
//! stud joint within its capacity, and checks it (see docs/stability.md).
//! Here every step's structure is also solved whole by the force program
//! ([`analyze`]: the least total usage, a hand only where nothing else
//! holds a piece), and the two verdicts are compared. Columns: pieces,
//! steps, the step check's seconds, the force programs' seconds (all
//! steps), steps where both agree, steps the check says stand while the
//! program's optimum breaks a joint (the safe theorem's case: an
//! equilibrium within every capacity exists, the least total usage
//! overloads one joint), and steps the check says fail while the program
//! holds them (none may be: that would be a wrong verdict; the example
//! exits 1).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use brickwright::ldraw::{read_ldr, to_assembly};
use brickwright::physics::{analyze, analyze_steps, Params};

fn main() -> Result<()> {
    let files: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    if files.is_empty() {
        anyhow::bail!("usage: verdicts MODEL.ldr...");
    }
    let params = Params::default();
    println!(
        "| model | pieces | steps | check s | programs s | agree | check stands, program breaks | check fails, program stands |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let mut wrong = 0;
    for file in &files {
        let model = read_ldr(file).with_context(|| file.display().to_string())?;
        let asm = to_assembly(&model).with_context(|| file.display().to_string())?;
        let begun = Instant::now();
        let fast = analyze_steps(&asm, &params, false)?;
        let check_s = begun.elapsed().as_secs_f64();
        let begun = Instant::now();
        let (mut agree, mut safe_only, mut missed) = (0, 0, 0);
        for check in &fast.steps {
            let prefix = asm.through_step(check.step);
            let full = analyze(&prefix, &params)?;
            match (check.stands, full.stands()) {
                (a, b) if a == b => agree += 1,
                (true, false) => safe_only += 1,
                _ => missed += 1,
            }
        }
        wrong += missed;
        println!(
            "| {} | {} | {} | {:.2} | {:.2} | {agree} | {safe_only} | {missed} |",
            file.file_name().unwrap_or_default().to_string_lossy(),
            asm.pieces.len(),
            fast.steps.len(),
            check_s,
            begun.elapsed().as_secs_f64(),
        );
    }
    if wrong > 0 {
        anyhow::bail!("{wrong} steps the step check failed that the force program holds");
    }
    Ok(())
}
