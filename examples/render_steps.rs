//! Builds a mesh (or reads an `.ldr` model) and draws its instruction
//! images, timing the renderer.
//!
//! ```text
//! cargo run --release --example render_steps -- MESH OUT_DIR [--studs N] [--slopes] [--plates] [--size WxH] [--no-steps]
//! cargo run --release --example render_steps -- MODEL.ldr OUT_DIR
//! ```
//!
//! Writes `OUT_DIR/model.png` and `OUT_DIR/steps/step-NNN.png`, and prints
//! how many step images a second the renderer made: in memory on one
//! thread, then written to disk (atomically, each file synced) in parallel.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use brickwright::ldraw;
use brickwright::pipeline::{self, BuildOptions, Silent};
use brickwright::render::{self, RenderOptions};
use brickwright::voxel::Sizing;

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let (Some(mesh), Some(out)) = (args.next(), args.next()) else {
        bail!("usage: render_steps MESH OUT_DIR [--studs N] [--slopes] [--plates] [--size WxH] [--no-steps]");
    };
    let out = PathBuf::from(out);
    let build_dir = tempfile::tempdir()?;
    let mut opts = BuildOptions::new(mesh);
    opts.out_dir = build_dir.path().to_path_buf();
    let mut ropts = RenderOptions::default();
    let mut steps = true;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--studs" => {
                let n = args.next().context("--studs needs a number")?;
                opts.sizing = Sizing::Studs(n.parse().context("--studs needs a number")?);
            }
            "--size" => {
                let v = args.next().context("--size needs WIDTHxHEIGHT")?;
                let (w, h) = v.split_once('x').context("--size needs WIDTHxHEIGHT")?;
                ropts = ropts.with_size(w.parse()?, h.parse()?);
            }
            "--no-steps" => steps = false,
            "--slopes" => opts.slopes = true,
            "--plates" => opts.plates = true,
            _ => bail!("unknown argument {a}"),
        }
    }
    let t = Instant::now();
    let asm = if opts
        .input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ldr"))
    {
        ldraw::to_assembly(&ldraw::read_ldr(&opts.input)?)?
    } else {
        pipeline::build(&opts, &Silent)?.assembly
    };
    eprintln!(
        "{} pieces in {} steps in {:.2} s",
        asm.pieces.len(),
        asm.step_count(),
        t.elapsed().as_secs_f64()
    );

    let t = Instant::now();
    let renderer = render::renderer(&asm, &ropts)?;
    let setup = t.elapsed().as_secs_f64();
    let turned: Vec<String> = (0..renderer.steps().len())
        .filter_map(|n| {
            renderer
                .turn_at(n)
                .map(|q| format!("{} (+{} to {})", n + 1, q, renderer.step_turns(n)))
        })
        .collect();
    eprintln!(
        "view turned at steps: {}",
        if turned.is_empty() {
            "none".to_string()
        } else {
            turned.join(", ")
        }
    );
    std::fs::create_dir_all(&out)?;
    renderer.write_png_file(&renderer.model_image(), &out.join("model.png"))?;
    if !steps {
        return Ok(());
    }
    // In memory on this thread: the renderer and encoder alone, no disk.
    let t = Instant::now();
    let mut bytes = 0;
    for (_, img) in renderer.images() {
        let mut png = Vec::new();
        render::write_png(&img, false, &mut png)?;
        bytes += png.len();
    }
    let secs = t.elapsed().as_secs_f64();
    eprintln!(
        "in memory, one thread: {} step images in {:.3} s: {:.1} images/s, {:.0} KiB a PNG",
        renderer.steps().len(),
        secs,
        renderer.steps().len() as f64 / secs.max(1e-9),
        bytes as f64 / 1024.0 / renderer.steps().len().max(1) as f64
    );
    let t = Instant::now();
    let paths = renderer.write_steps(&out.join("steps"))?;
    let secs = t.elapsed().as_secs_f64();
    eprintln!(
        "scene + camera {:.3} s; {} step images of {}x{} in {:.3} s: {:.1} images/s ({} threads)",
        setup,
        paths.len(),
        ropts.width,
        ropts.height,
        secs,
        paths.len() as f64 / secs.max(1e-9),
        rayon::current_num_threads()
    );
    Ok(())
}
