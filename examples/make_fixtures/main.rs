//! Writes brickwright's test meshes, deterministically, into `fixtures/`.
//!
//! ```text
//! cargo run --example make_fixtures                 # writes fixtures/
//! cargo run --example make_fixtures -- --out DIR    # writes DIR/ instead
//! ```
//!
//! Every byte written depends only on this program: coordinates live on a
//! 1e-6 grid and are printed as exact decimals, so a test can regenerate the
//! fixtures into a temporary directory and compare them byte for byte. Before
//! writing, each closed mesh is checked (every edge shared by exactly two
//! triangles in opposite directions, every shell with the expected positive
//! volume); the program fails if a check does not hold.

mod broken;
mod check;
mod colored;
mod formats;
mod mesh;
mod shapes;
mod tower;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use check::Report;
use mesh::{quantize, Mesh};

const USAGE: &str = "usage: make_fixtures [--out DIR]   (DIR defaults to fixtures)";

/// One line of the summary table.
struct Row {
    file: &'static str,
    report: Report,
}

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
        Ok(rows) => {
            print!("{}", table(&rows));
            println!("wrote fixtures to {}", out.display());
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
    let mut out = PathBuf::from("fixtures");
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--out" => out = args.next().ok_or("--out needs a directory")?.into(),
            "-h" | "--help" => return Ok(None),
            other => return Err(format!("unexpected argument {other:?}")),
        }
    }
    Ok(Some(out))
}

fn run(out: &Path) -> Result<Vec<Row>, String> {
    let mut files: Vec<(&str, Vec<u8>)> = Vec::new();
    let mut rows = Vec::new();

    for shape in shapes::all() {
        let report = check::check(&shape.mesh);
        verify(shape.file, &report, &shape.expected)?;
        let bytes = if shape.file.ends_with(".stl") {
            formats::stl(
                "brickwright fixture wedge: triangular prism, y up",
                &shape.mesh,
            )
        } else {
            let name = shape.file.trim_end_matches(".obj");
            let text = formats::obj(
                name,
                "brickwright fixture; regenerate with `cargo run --example make_fixtures`",
                &shape.mesh,
            );
            reread_obj(shape.file, &text, &shape.mesh)?;
            text.into_bytes()
        };
        files.push((shape.file, bytes));
        rows.push(Row {
            file: shape.file,
            report,
        });
    }

    let (glb, world) = tower::build();
    let report = check::check(&world);
    verify("tower.glb", &report, &[(48.0, 1e-4), (36.0, 1e-4)])?;
    let (min, max) = tower::bounds(&world);
    if min != [-3.0, 0.0, -2.0] || max != [3.0, 8.0, 2.0] {
        return Err(format!("tower.glb: world bounds {min:?} .. {max:?}"));
    }
    files.push(("broken/truncated.glb", glb[..40].to_vec()));
    files.push(("tower.glb", glb));
    rows.push(Row {
        file: "tower.glb",
        report,
    });

    let (two_tone, obj, mtl) = colored::two_tone();
    let (vc, vc_obj) = colored::vertex_colors();
    let (tex, tex_glb) = colored::textured();
    let (speckled, speckled_glb) = colored::speckled();
    for (file, mesh) in [
        ("two_tone.obj", &two_tone),
        ("vertex_colors.obj", &vc),
        ("textured.glb", &tex),
        ("speckled.glb", &speckled),
    ] {
        let report = check::check(mesh);
        verify(file, &report, &[(192.0, 1e-6)])?;
        rows.push(Row { file, report });
    }
    files.push(("two_tone.obj", obj.into_bytes()));
    files.push(("two_tone.mtl", mtl.into_bytes()));
    files.push(("vertex_colors.obj", vc_obj.into_bytes()));
    files.push(("textured.glb", tex_glb));
    files.push(("speckled.glb", speckled_glb));

    let open = broken::open_box();
    let report = check::check(&open);
    if report.is_closed() {
        return Err("open_box.obj: check found no defect".into());
    }
    let comment =
        "brickwright fixture: a box without its top face, two repeated and two zero-area triangles";
    files.push((
        "open_box.obj",
        formats::obj("open_box", comment, &open).into_bytes(),
    ));
    rows.push(Row {
        file: "open_box.obj",
        report,
    });

    files.extend(broken::files());
    files.push(("README.md", readme(&rows).into_bytes()));

    for (name, bytes) in &files {
        let path = out.join(name);
        let dir = path.parent().unwrap_or(out);
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        std::fs::write(&path, bytes)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    Ok(rows)
}

/// Fails unless the mesh is closed and its shells have the expected volumes.
fn verify(file: &str, report: &Report, expected: &[(f64, f64)]) -> Result<(), String> {
    if !report.is_closed() {
        return Err(format!("{file}: not a closed, outward surface: {report:?}"));
    }
    let volumes = &report.shell_volumes;
    let matches = volumes.len() == expected.len()
        && volumes
            .iter()
            .zip(expected)
            .all(|(v, (want, tol))| (v - want).abs() <= *tol);
    if !matches {
        return Err(format!(
            "{file}: shell volumes {volumes:?}, expected {expected:?}"
        ));
    }
    Ok(())
}

/// Reads written OBJ text back and fails unless it is exactly `mesh`.
fn reread_obj(file: &str, text: &str, mesh: &Mesh) -> Result<(), String> {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => positions.push(
                words
                    .map(|w| w.parse::<f64>().map(quantize))
                    .collect::<Result<Vec<_>, _>>(),
            ),
            Some("f") => triangles.push(
                words
                    .map(|w| w.parse::<u32>().map(|i| i - 1))
                    .collect::<Result<Vec<_>, _>>(),
            ),
            _ => {}
        }
    }
    let same_positions = positions
        .iter()
        .map(|p| p.as_deref().ok())
        .eq(mesh.positions.iter().map(|p| Some(&p[..])));
    let same_triangles = triangles
        .iter()
        .map(|t| t.as_deref().ok())
        .eq(mesh.triangles.iter().map(|t| Some(&t[..])));
    if same_positions && same_triangles {
        Ok(())
    } else {
        Err(format!(
            "{file}: written OBJ does not read back as the mesh"
        ))
    }
}

fn volumes(report: &Report) -> String {
    let shells: Vec<String> = report
        .shell_volumes
        .iter()
        .map(|v| format!("{v:.4}"))
        .collect();
    shells.join(" + ")
}

/// The summary table, as printed and as put in the README.
fn table(rows: &[Row]) -> String {
    let mut out =
        String::from("| file | triangles | shells | signed volume per shell | closed |\n");
    out.push_str("|---|---:|---:|---|---|\n");
    for Row { file, report } in rows {
        let closed = if report.is_closed() {
            "yes".to_string()
        } else {
            format!(
                "no: {} unpaired edges, {} repeated edges, {} duplicated, {} degenerate triangles",
                report.unpaired_edges, report.repeated_edges, report.duplicated, report.degenerate
            )
        };
        // An open surface has no meaningful volume.
        let volume = if report.is_closed() {
            volumes(report)
        } else {
            "-".to_string()
        };
        writeln!(
            out,
            "| {file} | {} | {} | {volume} | {closed} |",
            report.triangles,
            report.shell_volumes.len(),
        )
        .unwrap();
    }
    out
}

fn readme(rows: &[Row]) -> String {
    format!(
        "{}\n## Measured by the generator\n\n{}",
        include_str!("README.head.md"),
        table(rows)
    )
}
