//! Writes the step viewer page of an LDraw build made of catalog parts,
//! without building it again: `cargo run --release --example viewer_page
//! -- model.ldr model.html`. Handy for trying the viewer on big builds
//! (`benches/viewer-fps` uses it).

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use brickwright::export::html::{write_html, HtmlOptions};

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let (Some(ldr), Some(out)) = (args.next(), args.next()) else {
        bail!("usage: viewer_page MODEL.ldr OUT.html");
    };
    let (ldr, out) = (PathBuf::from(ldr), PathBuf::from(out));
    let model = brickwright::ldraw::read_ldr(&ldr)?;
    let asm = brickwright::ldraw::to_assembly(&model)?;
    let name = ldr
        .file_stem()
        .map_or("model".into(), |s| s.to_string_lossy().into_owned());
    brickwright::fsutil::write_atomic(&out, |w| {
        write_html(w, &asm, &HtmlOptions::default().with_name(name))
    })
    .with_context(|| format!("{}: cannot write", out.display()))?;
    println!(
        "{}: {} pieces in {} steps, {} bytes",
        out.display(),
        asm.pieces.len(),
        asm.step_count(),
        std::fs::metadata(&out)?.len()
    );
    Ok(())
}
