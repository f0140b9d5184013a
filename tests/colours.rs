//! Builds keep the model's colours: the coloured fixtures (a two-material
//! OBJ, a vertex-coloured OBJ, a textured GLB) built with the default
//! palette and checked region by region, and the outputs carrying the
//! colours (`.ldr` colour codes, parts list by part and colour, each part
//! in a colour it is made in); specks of a texture smoothed away.

use std::path::{Path, PathBuf};

use brickwright::assembly::Placed;
use brickwright::catalog::{Color, Palette, PartKind, COLORS, PARTS};
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

/// Every (part, colour) a build's parts lists order, read back from the
/// files (Rebrickable CSV: part, LDraw colour; BrickLink XML: item, BrickLink
/// colour) and from the report, each checked against the colours the part
/// is made in.
fn assert_parts_exist(out: &BuildOutput, dir: &Path, stem: &str) {
    let mut seen = 0;
    let mut check = |part: PartKind, color: Color, from: &str| {
        assert!(
            part.exists_in(color),
            "{from} orders {} in {color}, a colour it is not made in",
            part.spec().id
        );
        seen += 1;
    };
    for r in &out.report.parts {
        check(
            PartKind::from_id(&r.part).unwrap(),
            Color(r.color),
            "report",
        );
    }
    let csv = std::fs::read_to_string(dir.join(format!("{stem}-parts.csv"))).unwrap();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let part = PARTS
            .iter()
            .position(|p| p.rebrickable() == f[0])
            .map(|i| PartKind(i as u16))
            .unwrap_or_else(|| panic!("CSV part {}", f[0]));
        check(part, Color(f[1].parse().unwrap()), "the CSV");
    }
    let xml = std::fs::read_to_string(dir.join(format!("{stem}-bricklink.xml"))).unwrap();
    let tag = |item: &str, t: &str| -> String {
        let open = format!("<{t}>");
        let at = item.find(&open).unwrap() + open.len();
        item[at..at + item[at..].find('<').unwrap()].to_string()
    };
    for item in xml.split("<ITEM>").skip(1) {
        let id = tag(item, "ITEMID");
        let part = PARTS
            .iter()
            .position(|p| p.bricklink == id)
            .map(|i| PartKind(i as u16))
            .unwrap_or_else(|| panic!("BrickLink item {id}"));
        let bl: u16 = tag(item, "COLOR").parse().unwrap();
        let color = COLORS.iter().find(|c| c.bricklink == bl).unwrap().code;
        check(part, color, "the BrickLink list");
    }
    assert!(seen >= 3 * out.report.parts.len(), "{stem}: {seen} rows");
}

#[test]
fn parts_lists_order_parts_only_in_colours_they_are_made_in() {
    type Configure = fn(&mut BuildOptions);
    let cases: [(&str, Configure); 8] = [
        ("two_tone.obj", |_| {}),
        ("vertex_colors.obj", |_| {}),
        ("textured.glb", |_| {}),
        ("speckled.glb", |_| {}),
        ("speckled.glb", |o| o.max_colors = Some(2)),
        ("vertex_colors.obj", |o| o.max_colors = Some(3)),
        ("house.obj", |o| o.palette = Palette::Random),
        // No 2 x 8 brick or 2 x 4 slope is made in Dark Pink: those
        // pieces take the nearest colour they are made in.
        ("barn.obj", |o| {
            o.palette = Palette::Single(Color(5));
            o.slopes = true;
            o.sizing = Sizing::Studs(24);
        }),
    ];
    for (fixture, configure) in cases {
        let tmp = tempfile::tempdir().unwrap();
        let out = build(fixture, tmp.path(), |o| {
            o.formats = Formats::parse("ldr,csv,bricklink").unwrap();
            configure(o);
        });
        let stem = fixture.split('.').next().unwrap();
        assert_parts_exist(&out, tmp.path(), stem);
    }
}

/// The colour the build shows at each cell: the piece covering it.
fn shown(out: &BuildOutput) -> std::collections::HashMap<(i32, i32, i32), Color> {
    let a = &out.assembly;
    a.pieces
        .iter()
        .flat_map(|p| cells(p, a.layer_ldu).into_iter().map(move |c| (c, p.color)))
        .collect()
}

/// `speckled.glb`'s white texels `(x, row)`, row 0 at the top, and its
/// yellow patch `x0..x1` by rows `r0..r1` (examples/make_fixtures).
const SPECKS: [(u32, u32); 4] = [(3, 2), (6, 7), (12, 8), (9, 1)];
const PATCH: (u32, u32, u32, u32) = (9, 13, 3, 7);

#[test]
fn specks_are_smoothed_and_real_patches_kept() {
    let tmp = tempfile::tempdir().unwrap();
    let out = build("speckled.glb", tmp.path(), |_| {});
    let report = out.report.mesh_colors.as_ref().unwrap();
    // The specks show on the front and the back; the smoothing takes them
    // (and little else) away.
    assert!(
        (8..=40).contains(&report.smoothed),
        "{} voxels smoothed",
        report.smoothed
    );
    // Measured against the colours as sampled, specks included.
    assert!(share(&out) >= 0.95, "{report:?}");
    let at = shown(&out);
    let ny = out.report.grid[1];
    for face in [0, ny - 1] {
        // Texel (x, row) is voxel (x, face, layer 9 - row).
        for (x, row) in SPECKS {
            let c = at[&(x as i32, face, 9 - row as i32)];
            assert_eq!(c, Color::RED, "speck ({x}, {row}) on face {face}");
        }
        let (x0, x1, r0, r1) = PATCH;
        let yellow = (x0..x1)
            .flat_map(|x| (r0..r1).map(move |r| (x as i32, face, 9 - r as i32)))
            .filter(|c| at[c] == Color(14))
            .count();
        assert!(
            yellow >= 15,
            "{yellow} of 16 patch voxels yellow on face {face}"
        );
    }
    // The build's colours: red and yellow, no white.
    let colours: std::collections::BTreeSet<u16> =
        out.report.parts.iter().map(|r| r.color).collect();
    assert_eq!(colours.into_iter().collect::<Vec<_>>(), vec![4, 14]);
}
