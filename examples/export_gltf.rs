//! Builds a mesh with the library pipeline and writes its glTF scenes, for
//! looking at the export by hand (`tests/tools/screenshot-gltf.sh`) and for
//! timing it. The command-line tool gets its own `--formats` option; this
//! example only shows the library calls.
//!
//! ```text
//! cargo run --release --example export_gltf -- MESH OUT_DIR [--studs N] [--slopes] [--plates]
//! ```
//!
//! Writes `OUT_DIR/<stem>.ldr`, `<stem>.glb`, `<stem>-exploded.glb` and
//! `<stem>.gltf`, and prints the size and time of each export.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use brickwright::export::gltf::{write_gltf, Container, GltfOptions};
use brickwright::fsutil::write_atomic;
use brickwright::pipeline::{build, BuildOptions, Silent};
use brickwright::voxel::Sizing;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let usage = "usage: export_gltf MESH OUT_DIR [--studs N] [--slopes] [--plates]";
    let input = PathBuf::from(args.next().ok_or_else(|| anyhow::anyhow!(usage))?);
    let out_dir = PathBuf::from(args.next().ok_or_else(|| anyhow::anyhow!(usage))?);
    let mut opts = BuildOptions::new(&input);
    opts.out_dir = out_dir.clone();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--studs" => {
                let n = args.next().ok_or_else(|| anyhow::anyhow!(usage))?;
                opts.sizing = Sizing::Studs(n.parse()?);
            }
            "--slopes" => opts.slopes = true,
            "--plates" => opts.plates = true,
            _ => anyhow::bail!("{usage}"),
        }
    }
    let t = Instant::now();
    let built = build(&opts, &Silent)?;
    println!(
        "built {} pieces in {} steps in {:.2} s",
        built.assembly.pieces.len(),
        built.assembly.step_count(),
        t.elapsed().as_secs_f64()
    );
    let stem = input
        .file_stem()
        .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned());
    let base = GltfOptions::default().with_name(stem.clone());
    let outputs = [
        (format!("{stem}.glb"), base.clone()),
        (
            format!("{stem}-exploded.glb"),
            base.clone().with_exploded(true),
        ),
        (
            format!("{stem}.gltf"),
            base.clone().with_container(Container::Embedded),
        ),
    ];
    for (name, gopts) in &outputs {
        let path = out_dir.join(name);
        let t = Instant::now();
        write_atomic(&path, |w| write_gltf(w, &built.assembly, gopts))?;
        let secs = t.elapsed().as_secs_f64();
        let bytes = std::fs::metadata(&path)?.len();
        println!(
            "{}: {bytes} bytes in {:.1} ms",
            path.display(),
            secs * 1000.0
        );
    }
    Ok(())
}
