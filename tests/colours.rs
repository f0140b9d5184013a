//! Builds keep the model's colours: the coloured fixtures (a two-material
//! OBJ, a vertex-coloured OBJ, a textured GLB) built with the default
//! palette and checked region by region, and the outputs carrying the
//! colours (`.ldr` colour codes, parts list by part and colour).

use std::path::{Path, PathBuf};

use brickwright::assembly::Placed;
use brickwright::catalog::{Color, Palette};
use brickwright::pipeline::{self, BuildOptions, BuildOutput, Formats, Silent};
use brickwright::voxel::Sizing;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn build_path(
    input: PathBuf,
    out: &Path,
    configure: impl FnOnce(&mut BuildOptions),
) -> BuildOutput {
    let mut opts = BuildOptions::new(input.clone());
    opts.out_dir = out.to_path_buf();
    opts.sizing = Sizing::Studs(16);
    opts.formats = Formats::parse("ldr,csv").unwrap();
    configure(&mut opts);
    pipeline::build(&opts, &Silent)
        .unwrap_or_else(|e| panic!("{} does not build: {e}", input.display()))
}

fn build(fixture: &str, out: &Path, configure: impl FnOnce(&mut BuildOptions)) -> BuildOutput {
    build_path(root().join("fixtures").join(fixture), out, configure)
}

/// The cells (`x`, `y`, layer) a piece fills.
fn cells(p: &Placed, layer_ldu: i32) -> Vec<(i32, i32, i32)> {
    p.placement
        .body(layer_ldu)
        .cells()
        .map(|c| (c.x, c.y, c.z))
        .collect()
}

/// The colours of the pieces lying wholly where `inside` holds.
fn colours_where(out: &BuildOutput, inside: impl Fn((i32, i32, i32)) -> bool) -> Vec<Color> {
    let a = &out.assembly;
    let mut v: Vec<Color> = a
        .pieces
        .iter()
        .filter(|p| cells(p, a.layer_ldu).into_iter().all(&inside))
        .map(|p| p.color)
        .collect();
    v.sort();
    v.dedup();
    v
}

fn share(out: &BuildOutput) -> f64 {
    let c = out
        .report
        .mesh_colors
        .as_ref()
        .expect("the build is painted from the mesh");
    assert!(c.surface_voxels > 0);
    c.own_color_share
}

#[test]
fn two_materials_paint_the_halves() {
    let tmp = tempfile::tempdir().unwrap();
    let out = build("two_tone.obj", tmp.path(), |_| {});
    // 16 x 8 studs, 10 layers (0.6 units each): y = 3 is between layers 4 and 5.
    assert_eq!(colours_where(&out, |c| c.2 <= 3), vec![Color(4)]);
    assert_eq!(colours_where(&out, |c| c.2 >= 6), vec![Color(1)]);
    assert!(share(&out) >= 0.95, "{:?}", out.report.mesh_colors);
    assert_eq!(out.report.options.palette, "mesh");
    assert!(out.report.warnings.is_empty(), "{:?}", out.report.warnings);
    // The .ldr carries the colour codes, the parts list one line a part
    // and colour.
    let ldr = std::fs::read_to_string(tmp.path().join("two_tone.ldr")).unwrap();
    let codes: std::collections::BTreeSet<&str> = ldr
        .lines()
        .filter(|l| l.starts_with("1 "))
        .filter_map(|l| l.split_whitespace().nth(1))
        .collect();
    assert_eq!(codes.into_iter().collect::<Vec<_>>(), vec!["1", "4"]);
    let colours: std::collections::BTreeSet<u16> =
        out.report.parts.iter().map(|r| r.color).collect();
    assert_eq!(colours.into_iter().collect::<Vec<_>>(), vec![1, 4]);
}

#[test]
fn a_colour_limit_and_other_palettes_override() {
    let tmp = tempfile::tempdir().unwrap();
    let one = build("two_tone.obj", tmp.path(), |o| o.max_colors = Some(1));
    let all = colours_where(&one, |_| true);
    assert_eq!(all.len(), 1, "{all:?}");
    assert_eq!(one.report.mesh_colors.as_ref().unwrap().colors.len(), 1);
    let tmp = tempfile::tempdir().unwrap();
    let single = build("two_tone.obj", tmp.path(), |o| {
        o.palette = Palette::Single(Color(14));
    });
    assert_eq!(colours_where(&single, |_| true), vec![Color(14)]);
    assert!(single.report.mesh_colors.is_none());
    // An uncoloured model falls back to layers.
    let tmp = tempfile::tempdir().unwrap();
    let plain = build("box.obj", tmp.path(), |_| {});
    assert_eq!(plain.report.options.palette, "layers");
    assert_eq!(colours_where(&plain, |_| true), vec![Color(4), Color(15)]);
}

#[test]
fn vertex_colours_run_from_yellow_to_blue() {
    let tmp = tempfile::tempdir().unwrap();
    let out = build("vertex_colors.obj", tmp.path(), |_| {});
    assert_eq!(colours_where(&out, |c| c.2 == 0), vec![Color(14)]);
    assert_eq!(colours_where(&out, |c| c.2 == 9), vec![Color(1)]);
    assert!(share(&out) >= 0.95, "{:?}", out.report.mesh_colors);
}

#[test]
fn a_texture_paints_by_its_coordinates_and_clamps() {
    let tmp = tempfile::tempdir().unwrap();
    let out = build("textured.glb", tmp.path(), |_| {});
    // x < 4 units is studs 0..8: green; beyond, yellow, the far end too
    // (clamp-to-edge; a repeating sampler would wrap it to green).
    assert_eq!(colours_where(&out, |c| c.0 <= 6), vec![Color(2)]);
    assert_eq!(colours_where(&out, |c| c.0 >= 9), vec![Color(14)]);
    assert!(share(&out) >= 0.95, "{:?}", out.report.mesh_colors);
}

#[test]
fn a_missing_texture_is_a_warning_and_kd_stands_in() {
    let tmp = tempfile::tempdir().unwrap();
    let src = root().join("fixtures");
    std::fs::copy(src.join("two_tone.obj"), tmp.path().join("two_tone.obj")).unwrap();
    let mtl = std::fs::read_to_string(src.join("two_tone.mtl")).unwrap();
    let mtl = mtl.replace("newmtl red\n", "newmtl red\nmap_Kd bricks.png\n");
    std::fs::write(tmp.path().join("two_tone.mtl"), mtl).unwrap();
    let out_dir = tmp.path().join("out");
    let out = build_path(tmp.path().join("two_tone.obj"), &out_dir, |_| {});
    assert_eq!(out.report.warnings.len(), 1, "{:?}", out.report.warnings);
    let w = &out.report.warnings[0];
    assert!(w.contains("bricks.png") && w.contains("Kd"), "{w}");
    assert_eq!(colours_where(&out, |c| c.2 <= 3), vec![Color(4)]);
}
