//! The `brickwright` command-line tool: parse, run, report.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Parser;

use brickwright::assembly::verify::verify;
use brickwright::grammar::learn::learn;
use brickwright::grammar::{extended_alphabet, rules_text, DEFAULT_ALPHABET};
use brickwright::pipeline::{self, Progress, Silent};
use brickwright::terminal::{escape_lines, escape_message};

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

mod cli;

use cli::args::{Alphabet, BuildArgs, Cli, Command, GroundArg, LearnArgs};
use cli::{print, progress::Spinners};

fn run_build(a: BuildArgs) -> Result<()> {
    let quiet = a.quiet;
    let opts = a.options()?;
    let spinners = Spinners::default();
    let progress: &dyn Progress = if quiet { &Silent } else { &spinners };
    let out = pipeline::build(&opts, progress)?;
    // Warnings go to standard error, with --quiet too.
    for w in out.report.warnings() {
        eprintln!("warning: {}", escape_message(&w));
    }
    if !quiet {
        print::build_summary(&out.report, &opts.out_dir);
    }
    Ok(())
}

fn run_verify(file: PathBuf, stability: Option<GroundArg>) -> Result<bool> {
    let model = brickwright::ldraw::read_ldr(&file)?;
    let asm = brickwright::ldraw::to_assembly(&model)?;
    if asm.pieces.is_empty() {
        // Nothing to check is not a sound build.
        outln!("{}: 1 problem", file.display());
        outln!("  - it has no pieces: no line places a part (LDraw line type 1)");
        return Ok(false);
    }
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
        Some(ground) => print::stability(&file, &model, &asm, ground)?,
        None => true,
    };
    Ok(sound && stands)
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
    // Ctrl-C: no half-written outputs or temporary files left behind (a
    // commit under way is let finish), then the shell's code for SIGINT.
    let _ = ctrlc::set_handler(|| {
        brickwright::fsutil::interrupted();
        std::process::exit(130);
    });
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
            // The error, then any cause its message does not already say;
            // a message of several lines keeps them, indented.
            let mut line = e.to_string();
            for cause in e.chain().skip(1) {
                let c = cause.to_string();
                if !line.contains(&c) {
                    line.push_str(": ");
                    line.push_str(&c);
                }
            }
            eprintln!("error: {}", escape_message(&line));
            ExitCode::from(code)
        }
    }
}
