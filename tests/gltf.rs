//! End-to-end tests of the glTF export on real builds.
//!
//! Each test builds a fixture with the library pipeline (which also writes
//! the `.ldr`), writes a `.glb`, an exploded `.glb` and an embedded `.gltf`
//! with `export::gltf`, reads them back with the `gltf` crate and checks:
//!
//! - one node per piece, in build order, under one root node;
//! - every node's step (its `extras`) equals the piece's step in the
//!   assembly and in the `.ldr` the pipeline wrote (`0 STEP` groups);
//! - every node's translation is the piece's LDraw position converted
//!   (plus its exploded offset in the exploded file), and exploded pieces
//!   do not overlap;
//! - the Khronos glTF-Validator reports no errors
//!   (`tests/tools/validate-gltf.js`).
//!
//! The validator is looked up in `$GLTF_VALIDATOR_NODE_PATH`, then
//! `./node_modules`, then the cache `.ci/run tools` installs it into, then
//! `/tmp/gv/node_modules` (see `tests/common`). Without it (or without
//! node) the validation is skipped, except under `CI`, where it fails.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

use brickwright::assembly::Assembly;
use brickwright::export::explode::{explode, ExplodeOptions};
use brickwright::export::gltf::{ldraw_to_gltf, write_gltf, Container, GltfOptions};
use brickwright::fsutil::write_atomic;
use brickwright::ldraw::placement_position;
use brickwright::pipeline::{build, BuildOptions, Silent};
use brickwright::voxel::Sizing;
use glam::Vec3;
use serde_json::Value;
use tempfile::TempDir;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
}

/// The step of every part line in an `.ldr`, counting `0 STEP` lines.
fn ldr_steps(text: &str) -> Vec<u32> {
    let mut step = 1;
    let mut steps = Vec::new();
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["1", ..] => steps.push(step),
            ["0", "STEP"] => step += 1,
            _ => {}
        }
    }
    steps
}

/// Runs the Khronos validator on `files`; panics on any error. Skips (or
/// fails under `CI`) when the validator or node is not installed.
fn validate(files: &[PathBuf]) {
    let Some(node_path) = common::gltf_validator() else {
        return;
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/tools/validate-gltf.js");
    let out = Command::new("node")
        .arg(&script)
        .args(files)
        .env("NODE_PATH", &node_path)
        .output()
        .expect("node must be installed to run the validator");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("{stdout}{stderr}");
    assert_eq!(
        out.status.code(),
        Some(0),
        "validator reported errors\n{stdout}{stderr}"
    );
    assert_eq!(stdout.matches("errors=0 ").count(), files.len(), "{stdout}");
}

/// Builds `name` at 10 studs and returns the assembly, the `.ldr` text and
/// the temporary output directory.
fn build_fixture(name: &str, slopes: bool) -> (Assembly, String, TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let mut opts = BuildOptions::new(fixture(name));
    opts.out_dir = dir.path().to_path_buf();
    opts.sizing = Sizing::Studs(10);
    opts.slopes = slopes;
    let out = build(&opts, &Silent).unwrap();
    let stem = Path::new(name).file_stem().unwrap().to_string_lossy();
    let ldr = std::fs::read_to_string(dir.path().join(format!("{stem}.ldr"))).unwrap();
    (out.assembly, ldr, dir)
}

fn check(name: &str, slopes: bool) {
    let (asm, ldr, dir) = build_fixture(name, slopes);
    assert!(!asm.pieces.is_empty());
    let stem = Path::new(name).file_stem().unwrap().to_string_lossy();
    let base = GltfOptions::default().with_name(stem.to_string());
    let files = [
        ("assembled.glb", base.clone()),
        ("exploded.glb", base.clone().with_exploded(true)),
        (
            "embedded.gltf",
            base.clone().with_container(Container::Embedded),
        ),
    ];
    let steps_in_ldr = ldr_steps(&ldr);
    assert_eq!(steps_in_ldr.len(), asm.pieces.len());
    let offsets = explode(&asm, &ExplodeOptions::default());
    let mut paths = Vec::new();
    for (file, opts) in &files {
        let path = dir.path().join(file);
        write_atomic(&path, |w| write_gltf(w, &asm, opts)).unwrap();
        let (doc, _, _) = gltf::import(&path).unwrap();
        assert_eq!(
            doc.default_scene().unwrap().nodes().count(),
            1,
            "{name} {file}: one root node"
        );
        let root = doc.nodes().next().unwrap();
        assert_eq!(root.name(), Some(&*stem));
        let pieces: Vec<gltf::Node> = doc.nodes().filter(|n| n.mesh().is_some()).collect();
        assert_eq!(pieces.len(), asm.pieces.len(), "{name} {file}");
        assert_eq!(root.children().count(), asm.pieces.len());
        let exploded = file.starts_with("exploded");
        for (i, (node, piece)) in pieces.iter().zip(&asm.pieces).enumerate() {
            let extras: Value =
                serde_json::from_str(node.extras().as_ref().unwrap().get()).unwrap();
            let step = extras["step"].as_u64().unwrap() as u32;
            assert_eq!(step, piece.step.0, "{name} {file}: node {i}");
            assert_eq!(step, steps_in_ldr[i], "{name} {file}: node {i} vs .ldr");
            let id = piece.placement.part.spec().id.0;
            assert_eq!(extras["part"], id);
            assert_eq!(extras["color"], piece.color.0);
            assert!(node.name().unwrap().contains(id));
            let [x, y, z] = placement_position(&piece.placement, asm.layer_ldu);
            let mut want = Vec3::new(x as f32, y as f32, z as f32);
            if exploded {
                want += offsets[i];
            }
            let got = Vec3::from(node.transform().decomposed().0);
            assert!(
                got.abs_diff_eq(ldraw_to_gltf(want), 1e-6),
                "{name} {file}: node {i} at {got}, want {}",
                ldraw_to_gltf(want)
            );
        }
        paths.push(path);
    }
    // Same assembly, same bytes.
    let mut again = Vec::new();
    write_gltf(&mut again, &asm, &files[0].1).unwrap();
    assert_eq!(again, std::fs::read(&paths[0]).unwrap());
    check_exploded_apart(&asm, &offsets);
    validate(&paths);
}

/// No two pieces' displaced bounding boxes (studs left out) overlap.
fn check_exploded_apart(asm: &Assembly, offsets: &[Vec3]) {
    let boxes: Vec<(Vec3, Vec3)> = asm
        .pieces
        .iter()
        .zip(offsets)
        .map(|(p, &o)| {
            let b = p.placement.body(asm.layer_ldu).bbox;
            let m = b.max_excl();
            let l = asm.layer_ldu as f32;
            let lo = Vec3::new(
                20.0 * b.min.x as f32,
                -l * m.z as f32,
                20.0 * b.min.y as f32,
            );
            let hi = Vec3::new(20.0 * m.x as f32, -l * b.min.z as f32, 20.0 * m.y as f32);
            (lo + o, hi + o)
        })
        .collect();
    for i in 0..boxes.len() {
        for j in 0..i {
            let (a, b) = (boxes[i], boxes[j]);
            let overlap = (0..3).all(|k| a.0[k] < b.1[k] - 1e-3 && b.0[k] < a.1[k] - 1e-3);
            assert!(!overlap, "exploded pieces {j} and {i} overlap");
        }
    }
}

#[test]
fn house_exports_valid_gltf() {
    check("house.obj", false);
}

#[test]
fn barn_with_slopes_exports_valid_gltf() {
    check("barn.obj", true);
}

#[test]
fn ldr_step_parser_counts_step_lines() {
    let text = "0 FILE a.ldr\n1 4 0 0 0 1 0 0 0 1 0 0 0 1 3001.dat\n0 STEP\n\
                1 4 0 0 0 1 0 0 0 1 0 0 0 1 3001.dat\n1 4 0 0 0 1 0 0 0 1 0 0 0 1 3001.dat\n0 STEP\n";
    assert_eq!(ldr_steps(text), [1, 2, 2]);
}
