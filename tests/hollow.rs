//! Hollow builds on the fixtures: the box's inside is empty and its walls
//! as thick as asked, its lid holds; the house keeps its roof, and at 32
//! studs inner pillars hold it up, built before the roof closes; every
//! step stands, `verify` passes, and the report measures the solid build
//! the hollow one replaces.

use std::path::{Path, PathBuf};
use std::process::Command;

use brickwright::assembly::verify::{verify, Failure};
use brickwright::assembly::{Assembly, Placed, Placement, Step};
use brickwright::catalog::PartKind;
use brickwright::geom::{Cell, Rot};
use brickwright::pipeline::{self, BuildOptions, BuildOutput, Formats, Silent, Stability};
use brickwright::voxel::{voxelize, Sizing, VoxelGrid, VoxelizeOptions, Wall};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
}

/// Builds fixture `name` at `studs` into `out`, hollow with walls `wall`
/// thick (`None`: solid).
fn build(name: &str, studs: u32, wall: Option<u32>, out: &Path) -> BuildOutput {
    let mut opts = BuildOptions::new(fixture(name));
    opts.out_dir = out.to_path_buf();
    opts.sizing = Sizing::Studs(studs);
    opts.formats = Formats::parse("ldr").unwrap();
    opts.search = opts
        .search
        .clone()
        .with_hollow(wall.map(|w| Wall::new(w).unwrap()));
    pipeline::build(&opts, &Silent).unwrap()
}

/// The fixture's voxels, as the build sees them.
fn solid(name: &str, studs: u32) -> VoxelGrid {
    let mesh = brickwright::mesh::load(&fixture(name)).unwrap();
    let opts = VoxelizeOptions::default().with_sizing(Sizing::Studs(studs));
    voxelize(&mesh, &opts).unwrap().grid
}

/// The cells the pieces fill.
fn filled(asm: &Assembly, dims: (i32, i32, i32)) -> VoxelGrid {
    let mut g = VoxelGrid::new(dims.0, dims.1, dims.2);
    for p in &asm.pieces {
        g.set_body(&p.placement.body(asm.layer_ldu), true);
    }
    g
}

/// `brickwright verify --stability FILE` passes.
fn verified_with_stability(ldr: &Path) {
    let run = Command::new(env!("CARGO_BIN_EXE_brickwright"))
        .args(["verify", "--stability", ldr.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
}

#[test]
fn the_hollow_box_is_empty_inside_with_walls_as_thick_as_asked_and_its_lid_holds() {
    let model = solid("box.obj", 24);
    let (nx, ny, nz) = model.dims();
    assert_eq!(model.count() as i32, nx * ny * nz, "the box fills its grid");
    for wall in [1, 2] {
        let tmp = tempfile::tempdir().unwrap();
        let out = build("box.obj", 24, Some(wall), tmp.path());
        let cells = filled(&out.assembly, model.dims());
        // Walls `wall` studs thick, a lid of two courses (one course of
        // bricks side by side does not hold together), no floor on the
        // table; nothing else.
        let lid = wall.max(2) as i32;
        let w = wall as i32;
        for c in model.cells() {
            let inside = c.x >= w && c.x < nx - w && c.y >= w && c.y < ny - w && c.z < nz - lid;
            assert_eq!(cells.get(c), !inside, "wall {wall}: cell {c:?}");
        }
        let r = &out.report;
        let h = r.hollow.as_ref().expect("a hollow section");
        assert_eq!(h.wall, wall);
        assert_eq!(h.inner_pieces, 0, "the lid spans the box without pillars");
        assert_eq!(
            h.emptied_voxels as i32,
            (nx - 2 * w) * (ny - 2 * w) * (nz - lid)
        );
        assert_eq!(h.hollow.pieces, out.assembly.pieces.len());
        assert!(h.hollow.pieces < h.solid.pieces, "{h:?}");
        assert!(h.mass_share < 0.6, "{h:?}");
        // The lid holds at every step, and any checker agrees.
        let st = r.stability.as_ref().unwrap();
        assert!(st.stands && st.first_failure.is_none(), "{st:?}");
        assert!(verify(&out.assembly, None).is_ok());
        verified_with_stability(&tmp.path().join("box.ldr"));
    }
}

#[test]
fn the_report_measures_the_solid_build_it_replaces() {
    let tmp = tempfile::tempdir().unwrap();
    let hollow = build("box.obj", 24, Some(2), &tmp.path().join("hollow"));
    let mut opts = BuildOptions::new(fixture("box.obj"));
    opts.out_dir = tmp.path().join("solid");
    opts.sizing = Sizing::Studs(24);
    opts.formats = Formats::parse("ldr").unwrap();
    opts.stability = Stability::Off;
    let solid_run = pipeline::build(&opts, &Silent).unwrap();
    let h = hollow.report.hollow.unwrap();
    // The same layout, laid out for real: its pieces and mass.
    assert_eq!(h.solid.pieces, solid_run.assembly.pieces.len());
    let mass: f64 = solid_run
        .assembly
        .pieces
        .iter()
        .map(|p| f64::from(p.placement.part.spec().mass_g))
        .sum();
    assert!(
        (h.solid.mass_g - mass).abs() < 0.1,
        "{} vs {mass}",
        h.solid.mass_g
    );
    assert!((h.solid.filled_share - 1.0).abs() < 1e-9);
    let model = solid("box.obj", 24).count() as f64;
    let shell = filled(&hollow.assembly, (24, 12, 15)).count() as f64;
    assert!(
        (h.hollow.filled_share - shell / model).abs() < 1e-4,
        "{h:?}"
    );
    assert!(h.mass_share < 0.6 && h.pieces_share < 0.6, "{h:?}");
    // report.json says the same.
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(tmp.path().join("hollow/report.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(json["hollow"]["solid"]["pieces"], h.solid.pieces);
    assert_eq!(json["hollow"]["hollow"]["pieces"], h.hollow.pieces);
    assert_eq!(json["pieces"], h.hollow.pieces);
}

/// The top voxel of every column of `model` is filled in `cells`.
fn roof_kept(model: &VoxelGrid, cells: &VoxelGrid) {
    let (nx, ny, nz) = model.dims();
    for y in 0..ny {
        for x in 0..nx {
            if let Some(z) = (0..nz).rev().find(|&z| model.get(Cell::new(x, y, z))) {
                assert!(cells.get(Cell::new(x, y, z)), "roof at ({x}, {y}, {z})");
            }
        }
    }
}

#[test]
fn the_hollow_house_keeps_its_roof() {
    let tmp = tempfile::tempdir().unwrap();
    let model = solid("house.obj", 24);
    let out = build("house.obj", 24, Some(2), tmp.path());
    let cells = filled(&out.assembly, model.dims());
    roof_kept(&model, &cells);
    let h = out.report.hollow.as_ref().unwrap();
    assert!(h.emptied_voxels * 2 > model.count(), "{h:?}");
    let st = out.report.stability.as_ref().unwrap();
    assert!(st.stands, "{st:?}");
    verified_with_stability(&tmp.path().join("house.ldr"));
}

/// The paper's skyscraper, hollow: each tier is set back on the one
/// below, its walls over that one's hollow, so each tier below gets a lid;
/// the whole model is built and verified.
#[test]
fn a_hollow_skyscraper_keeps_every_tier() {
    let tmp = tempfile::tempdir().unwrap();
    let model = solid("skyscraper.obj", 32);
    let out = build("skyscraper.obj", 32, Some(2), tmp.path());
    let cells = filled(&out.assembly, model.dims());
    roof_kept(&model, &cells);
    assert_eq!(out.report.quality.left_out, 0, "{:?}", out.report.quality);
    let h = out.report.hollow.as_ref().unwrap();
    assert!(h.emptied_voxels * 4 > model.count(), "{h:?}");
    verified_with_stability(&tmp.path().join("skyscraper.ldr"));
}

/// A body `w` wide, `d` deep and `h` high on a pedestal under its middle,
/// `pw` wide (across x), one layer high and as deep as the body: the
/// profile of an upside-down T extruded along z, as OBJ text (y up).
fn on_a_pedestal(w: f64, d: f64, h: f64, pw: f64) -> String {
    let (a, b, h0) = ((w - pw) / 2.0, (w + pw) / 2.0, 1.2);
    let profile = [
        (a, 0.0),
        (b, 0.0),
        (b, h0),
        (w, h0),
        (w, h),
        (0.0, h),
        (0.0, h0),
        (a, h0),
    ];
    let n = profile.len();
    let mut obj = String::from("o pedestal\n");
    for z in [0.0, d] {
        for (x, y) in profile {
            obj += &format!("v {x} {y} {z}\n");
        }
    }
    // Each end: the pedestal's rectangle and the body's hexagon (a fan).
    let caps = [
        (0, 2, 1),
        (0, 7, 2),
        (5, 7, 6),
        (5, 2, 7),
        (5, 3, 2),
        (5, 4, 3),
    ];
    let mut f: Vec<(usize, usize, usize)> = Vec::new();
    for (i, j, k) in caps {
        f.push((i, j, k));
        f.push((i + n, k + n, j + n));
    }
    for i in 0..n {
        let j = (i + 1) % n;
        f.push((i, j + n, j));
        f.push((i, i + n, j + n));
    }
    for (i, j, k) in f {
        obj += &format!("f {} {} {}\n", i + 1, j + 1, k + 1);
    }
    obj
}

/// A box `w` square and `h` high on a square pedestal `pw` wide under its
/// middle, one layer high, as OBJ text (y up).
fn on_a_square_pedestal(w: f64, h: f64, pw: f64) -> String {
    let (a, b, h0) = ((w - pw) / 2.0, (w + pw) / 2.0, 1.2);
    let v = [
        (0.0, h0, 0.0),
        (w, h0, 0.0),
        (w, h0, w),
        (0.0, h0, w),
        (0.0, h, 0.0),
        (w, h, 0.0),
        (w, h, w),
        (0.0, h, w),
        (a, h0, a),
        (b, h0, a),
        (b, h0, b),
        (a, h0, b),
        (a, 0.0, a),
        (b, 0.0, a),
        (b, 0.0, b),
        (a, 0.0, b),
    ];
    // The top, the sides, the body's underside round the pedestal, the
    // pedestal's sides and bottom.
    let quads = [
        [4, 7, 6, 5],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
        [0, 8, 9, 1],
        [1, 9, 10, 2],
        [2, 10, 11, 3],
        [3, 11, 8, 0],
        [8, 12, 13, 9],
        [9, 13, 14, 10],
        [10, 14, 15, 11],
        [11, 15, 12, 8],
        [12, 15, 14, 13],
    ];
    let mut obj = String::from("o pedestal\n");
    for (x, y, z) in v {
        obj += &format!("v {x} {y} {z}\n");
    }
    for [i, j, k, l] in quads {
        obj += &format!(
            "f {} {} {}\nf {} {} {}\n",
            i + 1,
            j + 1,
            k + 1,
            i + 1,
            k + 1,
            l + 1
        );
    }
    obj
}

/// Bodies on pedestals narrower than themselves, hollow. Where the
/// pedestal's one layer keeps a pocket too narrow to empty under the
/// hollow emptied over it, that floor joined nothing, and its voxels were
/// left out (a body on a pedestal as deep as itself at 22-26 studs: 24-28
/// voxels; on a square pedestal at 20-26 studs: 24-64). The floor is now
/// emptied where the model stands on the table beside it (the long
/// pedestal's ends, under the end walls), or made as thick as a lid where
/// it is all that stands there (the square pedestal). At 28-30 studs the
/// square pedestal is two layers high, a rim round a hollow of its own
/// standing under the body's hollow (128 voxels left out): the body gets
/// a lid over it, as a part hanging over the hollow gets one under it.
/// Every voxel of the shell is built.
#[test]
fn nothing_stands_under_the_hollow_joined_to_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let long = tmp.path().join("long.obj");
    std::fs::write(&long, on_a_pedestal(20.0, 20.0, 8.0, 7.0)).unwrap();
    let square = tmp.path().join("square.obj");
    std::fs::write(&square, on_a_square_pedestal(20.0, 8.0, 7.0)).unwrap();
    for (path, studs) in [(&long, 22), (&long, 24), (&long, 26)]
        .into_iter()
        .chain([20, 22, 24, 26, 28, 30].map(|s| (&square, s)))
    {
        let mut opts = BuildOptions::new(path.clone());
        opts.out_dir = tmp.path().join(format!("out{studs}"));
        opts.sizing = Sizing::Studs(studs);
        opts.formats = Formats::parse("ldr").unwrap();
        opts.stability = Stability::Off;
        opts.search = opts.search.clone().with_hollow(Wall::new(2));
        let out = pipeline::build(&opts, &Silent).unwrap();
        let at = format!("{} at {studs} studs", path.display());
        assert_eq!(
            out.report.quality.left_out, 0,
            "{at}: {:?}",
            out.report.quality
        );
        let h = out.report.hollow.as_ref().unwrap();
        assert!(h.emptied_voxels > 0, "{at}: {h:?}");
    }
}

#[test]
fn at_44_studs_inner_pillars_hold_the_house_roof_and_go_in_before_it_closes() {
    let tmp = tempfile::tempdir().unwrap();
    // At 44 studs with walls 2 thick the roof needs pillars (at 32-40 it
    // holds without them).
    let model = solid("house.obj", 44);
    let out = build("house.obj", 44, Some(2), tmp.path());
    let cells = filled(&out.assembly, model.dims());
    roof_kept(&model, &cells);
    let r = &out.report;
    let h = r.hollow.as_ref().unwrap();
    // The target: at most 40% of the solid build's pieces.
    assert!(h.pieces_share <= 0.40, "{h:?}");
    // The stability stage put pillars in the hollow, and the build stands.
    let st = r.stability.as_ref().unwrap();
    assert!(st.stands, "{st:?}");
    assert!(
        h.inner_pieces > 0 && h.inner_pieces == st.support_pieces,
        "{h:?}"
    );
    let ldr = std::fs::read_to_string(tmp.path().join("house.ldr")).unwrap();
    assert!(
        ldr.contains(&format!("0 // {}", pipeline::hollow::PILLAR_NOTE)),
        "{ldr}"
    );
    verified_with_stability(&tmp.path().join("house.ldr"));
    // The pillars' pieces put in last, after the roof closed over them,
    // are refused: they would be inside a closed cavity.
    let inside = |c: Cell| {
        st.supports.iter().any(|col| {
            (col.x..col.x + col.size[0]).contains(&c.x)
                && (col.y..col.y + col.size[1]).contains(&c.y)
                && (col.bottom..=col.top).contains(&c.z)
        })
    };
    let pillar: Vec<Placed> = out
        .assembly
        .pieces
        .iter()
        .filter(|p| p.placement.body(out.assembly.layer_ldu).cells().all(inside))
        .cloned()
        .collect();
    assert_eq!(pillar.len(), st.support_pieces);
    assert!(!pillar.is_empty());
    let mut late = out.assembly.clone();
    late.pieces.retain(|p| !pillar.contains(p));
    let last = late.pieces.last().unwrap().step.0;
    late.pieces.extend(pillar.iter().map(|p| Placed {
        step: Step(last + 1),
        ..*p
    }));
    let report = verify(&late, None);
    assert!(
        report
            .failures
            .iter()
            .any(|f| matches!(f, Failure::Enclosed { .. })),
        "{report}"
    );
}

#[test]
fn a_piece_put_in_the_closed_box_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = build("box.obj", 24, Some(2), tmp.path());
    let mut asm = out.assembly.clone();
    // A 2 x 2 brick on the table in the middle of the box, after the lid.
    let inner = Placement::new(
        PartKind::from_id("3003").unwrap(),
        Cell::new(11, 5, 0),
        Rot::R0,
    );
    let step = Step(asm.pieces.last().unwrap().step.0 + 1);
    asm.pieces.push(Placed {
        placement: inner,
        step,
        color: asm.pieces[0].color,
    });
    // Shut in (and, on its own, joined to nothing).
    let report = verify(&asm, None);
    let shut: Vec<&Failure> = report
        .failures
        .iter()
        .filter(|f| matches!(f, Failure::Enclosed { .. }))
        .collect();
    assert_eq!(
        shut,
        [&Failure::Enclosed {
            piece: asm.pieces.len() - 1,
            step
        }],
        "{report}"
    );
}

#[test]
fn wall_needs_hollow_and_a_thickness_from_1_to_16() {
    let tmp = tempfile::tempdir().unwrap();
    for args in [
        vec!["--wall", "2"],
        vec!["--hollow", "--wall", "0"],
        vec!["--hollow", "--wall", "17"],
    ] {
        let out = tmp.path().join("out");
        let run = Command::new(env!("CARGO_BIN_EXE_brickwright"))
            .args(["build", fixture("box.obj").to_str().unwrap(), "-o"])
            .arg(&out)
            .args(&args)
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(2), "{args:?}");
        assert!(!out.exists(), "{args:?}");
    }
}

/// The last resort a build takes when every layout fails verification
/// (`SearchOptions::leave_unplaceable`: pieces no order can put in place
/// are left out) changes nothing where every piece can be put in place.
#[test]
fn the_last_resort_changes_no_layout_whose_pieces_all_go_in() {
    use brickwright::grammar::default_rules;
    use brickwright::search::{self, Guide, SearchOptions};
    let rules = default_rules();
    for (name, studs) in [("house.obj", 32), ("mug.obj", 24), ("skyscraper.obj", 32)] {
        let grid = solid(name, studs);
        let opts = SearchOptions::default().with_hollow(Wall::new(2));
        let plain = search::build_guided(&grid, Guide::default(), &rules, &opts).unwrap();
        let last = opts.clone().with_leave_unplaceable(true);
        let resort = search::build_guided(&grid, Guide::default(), &rules, &last).unwrap();
        assert_eq!(
            search::placements(&plain),
            search::placements(&resort),
            "{name}"
        );
        assert_eq!(resort.repairs.left_out, plain.repairs.left_out, "{name}");
    }
}
