//! The build's stability stage end to end: `--stability check` refuses a
//! build that would tip over, the default repair props it with a support
//! column (and the stress picture shows it holds), the repair without
//! supports reports what it could not fix, a model that stands says so,
//! and the order repair builds a counterweight before the overhang it
//! holds.

use std::path::{Path, PathBuf};
use std::process::Command;

use brickwright::assembly::verify::verify;
use brickwright::assembly::{Assembly, Placed, Placement, Step};
use brickwright::catalog::{Color, PartKind};
use brickwright::geom::{Cell, Rot};
use brickwright::physics::repair::{reorder, reorder_while, MAX_REPAIRED_STEP};
use brickwright::physics::{analyze_steps, Params};
use serde_json::Value;

use crate::common;
use common::tool;

/// A gallows: a post one stud square and four bricks high, and an arm
/// seven studs long on top, all one stud deep. On a table the post tips
/// over as soon as the arm is on (the arm's weight is far past the post's
/// one-stud base); on a baseplate the post's stud holds it.
fn write_gallows(dir: &Path) -> PathBuf {
    let profile = [
        (0.0, 0.0),
        (1.0, 0.0),
        (1.0, 4.8),
        (7.0, 4.8),
        (7.0, 6.0),
        (0.0, 6.0),
    ];
    let mut obj = String::new();
    for z in [0.0, 1.0] {
        for (x, y) in profile {
            obj += &format!("v {x} {y} {z}\n");
        }
    }
    let n = profile.len();
    // The L-shaped caps, in four triangles each, then the sides.
    for (a, b, c) in [(0, 1, 2), (0, 2, 5), (2, 3, 4), (2, 4, 5)] {
        obj += &format!("f {} {} {}\n", a + 1, c + 1, b + 1);
        obj += &format!("f {} {} {}\n", a + n + 1, b + n + 1, c + n + 1);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        obj += &format!("f {} {} {}\n", i + 1, j + 1, j + n + 1);
        obj += &format!("f {} {} {}\n", i + 1, j + n + 1, i + n + 1);
    }
    let path = dir.join("gallows.obj");
    std::fs::write(&path, obj).unwrap();
    path
}

fn brickwright(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_brickwright"))
        .args(args)
        .output()
        .expect("cannot start the brickwright binary")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Builds the gallows at 7 studs into `tmp/out` with `extra` options;
/// the run and the output directory.
fn build_gallows(tmp: &Path, extra: &[&str]) -> (std::process::Output, PathBuf) {
    let mesh = write_gallows(tmp);
    let out = tmp.join("out");
    (build(&mesh, "7", &out, extra), out)
}

/// `brickwright build MESH --studs STUDS -o OUT EXTRA...`.
fn build(mesh: &Path, studs: &str, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["build", s(mesh), "--studs", studs, "-o", s(out)];
    args.extend_from_slice(extra);
    brickwright(&args)
}

fn report(out: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap()
}

#[test]
fn check_refuses_a_build_that_tips_over_with_one_line_and_no_files() {
    let tmp = tempfile::tempdir().unwrap();
    let (run, out) = build_gallows(tmp.path(), &["--stability", "check"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    // A failed check is a finding, not an error: exit 1, as `verify
    // --stability` does.
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: ") && stderr.contains("gallows.obj: at step "),
        "{stderr}"
    );
    // It names the arm that tips the post, with its step.
    assert!(stderr.contains("3009 Brick 1 x 6"), "{stderr}");
    assert!(!out.exists(), "no files on failure");
}

/// Pixels of `img` that read as the stress ramp's red end, but for the
/// legend's own ramp (bottom right).
fn red_pixels(img: &image::RgbaImage) -> usize {
    let (w, h) = img.dimensions();
    img.enumerate_pixels()
        .filter(|(x, y, _)| !(*x > w / 2 && *y > h * 4 / 5))
        .filter(|(_, _, p)| p[0] > 150 && p[1] < 60 && p[2] < 60 && p[3] == 255)
        .count()
}

#[test]
fn repair_props_the_gallows_arm_with_a_support_column() {
    let tmp = tempfile::tempdir().unwrap();
    let (run, out) = build_gallows(tmp.path(), &["--formats", "ldr,stress,pdf"]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}");
    assert!(stdout.contains("repaired supports: "), "{stdout}");
    assert!(stdout.contains("stands at every step"), "{stdout}");
    let r = report(&out);
    let st = &r["stability"];
    assert_eq!(st["stands"], true, "{st}");
    // It did not stand before: the arm tipped the post.
    assert!(st["before"]["first_failure"].as_u64().is_some(), "{st}");
    assert_eq!(st["before"]["final_stands"], false, "{st}");
    let columns = st["supports"].as_array().unwrap();
    assert!(!columns.is_empty(), "{st}");
    let ldr = std::fs::read_to_string(out.join("gallows.ldr")).unwrap();
    // The arm (the 1 x 6, six studs long from x = 1) and where it is put.
    let lines: Vec<Vec<&str>> = ldr
        .lines()
        .map(|l| l.split_whitespace().collect())
        .collect();
    let arm_line = lines
        .iter()
        .position(|l| l.first() == Some(&"1") && l.last() == Some(&"3009.dat"))
        .expect("the arm");
    let mut pieces_in_columns = 0;
    for c in columns {
        // Under the arm, from the table up to it, one stud from the post at
        // least, and added before it.
        let x = c["x"].as_i64().unwrap();
        assert!((2..=6).contains(&x), "{c}");
        assert_eq!(c["on_ground"], true, "{c}");
        assert_eq!(c["bottom"], 0, "{c}");
        pieces_in_columns += c["pieces"].as_u64().unwrap();
    }
    assert_eq!(st["support_pieces"].as_u64(), Some(pieces_in_columns));
    // The columns' bricks: light bluish grey (71), all before the arm.
    let support_lines: Vec<usize> = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| l.first() == Some(&"1") && l[1] == "71")
        .map(|(i, l)| {
            assert!(["3003.dat", "3004.dat", "3005.dat"].contains(l.last().unwrap()));
            i
        })
        .collect();
    assert_eq!(support_lines.len() as u64, pieces_in_columns);
    // The column's step opens with a comment saying what it is for.
    assert_eq!(
        ldr.lines().nth(support_lines[0] - 1),
        Some(format!("0 // {}", brickwright::pipeline::SUPPORT_NOTE).as_str())
    );
    assert!(support_lines.iter().all(|&i| i < arm_line), "{ldr}");
    // Any checker agrees: the written model stands.
    let verified = brickwright(&["verify", "--stability", s(&out.join("gallows.ldr"))]);
    assert!(
        verified.status.success(),
        "{}",
        String::from_utf8_lossy(&verified.stdout)
    );
    let img = image::open(out.join("gallows-stress.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(red_pixels(&img), 0, "no red on the model");
    // The picture's usages: the finished model's force program, solved
    // once after the repairs (their checks ask only for verdicts).
    assert_eq!(st["stress_map"], "program", "{st}");
    // The booklet says what the column's step is for.
    if tool("pdftotext", "poppler-utils") {
        let text = Command::new("pdftotext")
            .args([s(&out.join("gallows.pdf")), "-"])
            .output()
            .unwrap();
        // The note may wrap in its step's cell: compare words.
        let words = |t: &str| t.split_whitespace().collect::<Vec<_>>().join(" ");
        let text = words(&String::from_utf8_lossy(&text.stdout));
        assert!(
            text.contains(&words(brickwright::pipeline::SUPPORT_NOTE)),
            "{text}"
        );
    }
}

#[test]
fn repair_without_supports_reports_what_it_could_not_fix_and_draws_the_stress() {
    let tmp = tempfile::tempdir().unwrap();
    let (run, out) = build_gallows(tmp.path(), &["--formats", "ldr,stress", "--no-supports"]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("warning: at step"), "{stderr}");
    assert!(stdout.contains("baseplate"), "{stdout}");
    let r = report(&out);
    let st = &r["stability"];
    assert_eq!(st["mode"], "repair", "{st}");
    assert_eq!(st["stands"], false, "{st}");
    assert_eq!(st["stands_on_baseplate"], true, "{st}");
    assert!(st["first_failure"].as_u64().is_some(), "{st}");
    assert!(!st["repairs"].as_array().unwrap().is_empty(), "{st}");
    let weakest = st["weakest"].as_array().unwrap();
    assert!(weakest.iter().any(|w| w["falls"] == true), "{st}");
    assert_eq!(
        st["steps"].as_array().unwrap().len() as u64,
        r["steps"].as_u64().unwrap()
    );
    // The stress picture has the falling pieces in red.
    assert!(st["supports"].as_array().unwrap().is_empty(), "{st}");
    let img = image::open(out.join("gallows-stress.png"))
        .unwrap()
        .to_rgba8();
    let red = red_pixels(&img);
    assert!(red > 500, "{red} red pixels");
}

/// A table: a top 20 units by 12 and 1 thick, 10 up, on four legs 1 unit
/// square (the shape of a thin-feature mesh a user tried), as one OBJ of
/// five overlapping boxes.
fn write_table(dir: &Path) -> PathBuf {
    let mut boxes = vec![([-10.0, 10.0, -6.0], [10.0, 11.0, 6.0])];
    for (sx, sz) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
        let (x, z) = (8.5 * sx, 4.5 * sz);
        boxes.push(([x - 0.5, 0.0, z - 0.5], [x + 0.5, 10.5, z + 0.5]));
    }
    let solids: Vec<_> = boxes
        .iter()
        .map(|&([x0, y0, z0], [x1, y1, z1])| {
            ([(x0, z0, y0), (x1, z0, y0), (x1, z1, y0), (x0, z1, y0)], y1)
        })
        .collect();
    let path = dir.join("table.obj");
    std::fs::write(&path, common::prisms(&solids)).unwrap();
    path
}

/// A table top's first course bridges the legs with nothing under it: its
/// pieces hang from the course over them, which cantilevers off a leg and
/// tips it. A support column can only go under such a piece if the piece
/// stands on it instead, before the piece it hung from: the repair moves
/// it there, and the table stands at every step (it failed at step 25
/// when hung pieces got no column).
#[test]
fn repair_props_a_table_top_under_the_pieces_it_hung() {
    let tmp = tempfile::tempdir().unwrap();
    let mesh = write_table(tmp.path());
    let out = tmp.path().join("out");
    let run = build(&mesh, "24", &out, &["--formats", "ldr", "-q"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let r = report(&out);
    let st = &r["stability"];
    assert!(st["before"]["first_failure"].as_u64().is_some(), "{st}");
    assert_eq!(st["stands"], true, "{st}");
    assert_eq!(st["complete"], true, "{st}");
    let columns = st["supports"].as_array().unwrap();
    assert!(!columns.is_empty(), "{st}");
    // The columns prop the top: they reach up to the layer under it.
    let top = columns.iter().map(|c| c["top"].as_i64().unwrap()).max();
    assert!(top >= Some(7), "{st}");
    // Any checker agrees: the written model is in order and stands.
    let verified = brickwright(&["verify", "--stability", s(&out.join("table.ldr"))]);
    assert!(
        verified.status.success(),
        "{}",
        String::from_utf8_lossy(&verified.stdout)
    );
}

#[test]
fn a_model_that_stands_says_so_and_stress_needs_the_check() {
    let tmp = tempfile::tempdir().unwrap();
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/house.obj");
    let out = tmp.path().join("out");
    let run = build(&mesh, "10", &out, &["--formats", "ldr,stress", "-q"]);
    assert!(run.status.success());
    let st = report(&out)["stability"].clone();
    assert_eq!(st["stands"], true, "{st}");
    assert!(st["first_failure"].is_null(), "{st}");
    let min = st["min_score"].as_f64().unwrap();
    let mean = st["mean_score"].as_f64().unwrap();
    assert!(
        (0.0..=1.0).contains(&min) && min <= mean && mean <= 1.0,
        "{st}"
    );
    assert!(out.join("house-stress.png").is_file());
    let ldr = out.join("house.ldr");
    let verified = brickwright(&["verify", "--stability", s(&ldr)]);
    assert!(
        verified.status.success(),
        "{}",
        String::from_utf8_lossy(&verified.stdout)
    );

    // Off: no section, and naming the stress picture is an error.
    let off = tmp.path().join("off");
    let run = build(
        &mesh,
        "10",
        &off,
        &["--formats", "ldr", "--stability", "off", "-q"],
    );
    assert!(run.status.success());
    assert!(report(&off)["stability"].is_null());
    let run = brickwright(&[
        "build",
        s(&mesh),
        "-o",
        s(&off),
        "--formats",
        "stress",
        "--stability",
        "off",
    ]);
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("--formats stress"));
}

#[test]
fn the_check_stops_at_its_time_budget_and_says_so() {
    let tmp = tempfile::tempdir().unwrap();
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/house.obj");
    let out = tmp.path().join("out");
    let run = build(
        &mesh,
        "10",
        &out,
        &["--formats", "ldr", "--stability-budget", "0.000001"],
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}");
    // The warning is on standard error.
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("warning: ") && stderr.contains("--stability-budget"),
        "{stderr}"
    );
    let r = report(&out);
    let st = &r["stability"];
    assert_eq!(st["complete"], false, "{st}");
    assert_eq!(st["stands"], false, "unchecked steps are not claimed: {st}");
    assert!(st["steps_checked"].as_u64().unwrap() < r["steps"].as_u64().unwrap());
    // The finished model is still analysed.
    assert!(st["mean_score"].as_f64().unwrap() > 0.0, "{st}");
}

#[test]
fn past_its_budget_the_stage_analyses_the_finished_model_once_and_names_what_fails() {
    // The gallows tips over: with the budget spent at once, no step is
    // checked, and neither the order repair, the support columns, other
    // layouts nor the baseplate's check may run past it; the one analysis
    // is the finished model's, and the failure names its pieces.
    let tmp = tempfile::tempdir().unwrap();
    let (run, out) = build_gallows(
        tmp.path(),
        &["--formats", "ldr", "--stability-budget", "0.000001"],
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}");
    assert!(
        stdout.contains("(score = 1 - share of stud clutch used; 1 analysis)"),
        "{stdout}"
    );
    let r = report(&out);
    let st = &r["stability"];
    assert_eq!(st["complete"], false, "{st}");
    assert_eq!(st["steps_checked"], 0, "{st}");
    assert_eq!(st["solves"], 1, "{st}");
    assert_eq!(st["stands_on_baseplate"], Value::Null, "{st}");
    assert_eq!(st["support_pieces"], 0, "{st}");
    let failure = st["failure"].as_str().unwrap();
    assert!(
        failure.contains("piece ") && failure.contains("Brick 1 x 6"),
        "{failure}"
    );
    let repairs: Vec<&str> = st["repairs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(
        repairs,
        ["layout: the stability budget ran out before other layouts of the same voxels could be tried"],
        "{st}"
    );
}

/// A 1x4 base on the table, a 1x6 overhang clutched to its last stud, and
/// a 1x2 counterweight on its other end: built overhang first, the base
/// tips at step 2 (the known answer of tests/physics.rs).
fn overhang_first() -> Assembly {
    let piece = |id: &str, x: i32, z: i32, step: u32| Placed {
        placement: Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0),
        step: Step(step),
        color: Color::RED,
    };
    Assembly {
        pieces: vec![
            piece("3010", 0, 0, 1),
            piece("3009", 3, 1, 2),
            piece("3004", 0, 1, 3),
        ],
        layer_ldu: 24,
    }
}

#[test]
fn the_order_repair_puts_the_counterweight_before_the_overhang() {
    let params = Params::default();
    let wrong = overhang_first();
    let check = analyze_steps(&wrong, &params, false).unwrap();
    assert_eq!(check.first_failure, Some(2));
    let fixed = reorder(&wrong, &params, 2, None)
        .unwrap()
        .expect("a better order");
    let parts: Vec<&str> = fixed
        .assembly
        .pieces
        .iter()
        .map(|p| p.placement.part.spec().id.0)
        .collect();
    assert_eq!(parts, ["3010", "3004", "3009"]);
    assert_eq!(fixed.moved.len(), 1);
    assert_eq!(fixed.moved[0].part, "3009");
    assert_eq!(fixed.moved[0].from_step, 2);
    // The overhang alone has no equilibrium: the analysis says what falls
    // (one program); with the counterweight, the equilibrium kept from
    // the base is changed to hold both, and checked (no program of the
    // whole structure).
    assert_eq!((fixed.solves, fixed.certified), (1, 1), "{fixed:?}");
    assert!(verify(&fixed.assembly, None).is_ok());
    let again = analyze_steps(&fixed.assembly, &params, false).unwrap();
    assert_eq!(again.first_failure, None, "{again:?}");
    // Every step the walk kept was certified: its certificates are the
    // new order's check from step 2 on, with the verdicts of the check
    // made again.
    let walked = fixed.walked.as_ref().expect("every step certified");
    let verdicts = |c: &[brickwright::physics::StepCheck]| {
        c.iter().map(|c| (c.step, c.stands)).collect::<Vec<_>>()
    };
    assert_eq!(verdicts(&walked.steps), verdicts(&again.steps[1..]));
    assert_eq!(verdicts(&walked.steps), [(2, true)]);
    assert!(walked.last.stands(), "{walked:?}");
    assert_eq!(walked.last.pieces.len(), 3);
}

#[test]
fn the_order_repair_stops_once_a_deferred_piece_is_shut_in() {
    // The overhang of `overhang_first` tips its base at step 2 and is
    // deferred. A pillar of three 1x1 bricks on the table beside it (step
    // 3) and a 2x4 roof on the pillar, over the overhang's place one layer
    // clear of it (step 4), shut it in: under the roof and over the base,
    // its studs cannot slide out. A stack on the base and a 1x6 from it
    // to the roof join the two parts (step 5). No order that builds the
    // overhang after the roof passes the verifier, so the repair gives up
    // there instead of walking on.
    let piece = |id: &str, x: i32, y: i32, z: i32, step: u32| Placed {
        placement: Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, y, z), Rot::R0),
        step: Step(step),
        color: Color::RED,
    };
    let mut pieces = vec![piece("3010", 0, 0, 0, 1), piece("3009", 3, 0, 1, 2)];
    pieces.extend((0..3).map(|z| piece("3005", 6, 1, z, 3)));
    pieces.push(piece("3001", 4, 0, 3, 4));
    pieces.extend((1..4).map(|z| piece("3005", 1, 0, z, 5)));
    pieces.push(piece("3009", 1, 0, 4, 5));
    let asm = Assembly {
        pieces,
        layer_ldu: 24,
    };
    assert!(verify(&asm, None).is_ok(), "{}", verify(&asm, None));
    let params = Params::default();
    assert_eq!(
        analyze_steps(&asm, &params, false).unwrap().first_failure,
        Some(2)
    );
    // The overhang anywhere after the roof: the verifier refuses it.
    let mut late = asm.clone();
    let overhang = late.pieces.remove(1);
    late.pieces.insert(5, overhang);
    assert!(!verify(&late, None).is_ok());
    assert!(reorder(&asm, &params, 2, None).unwrap().is_none());
}

#[test]
fn the_order_repair_gives_up_once_more_pieces_wait_than_a_step_may_hold() {
    // The overhang of `overhang_first` tips its base at step 2, and a
    // column of 1x1 bricks goes up from its far end, one a step: each
    // hangs on the overhang, so each waits with it, and nothing later
    // ever stands. The walk gives up once more pieces wait than a
    // repaired step may hold, rather than walk every step of the column.
    let piece = |id: &str, x: i32, z: i32, step: u32| Placed {
        placement: Placement::new(PartKind::from_id(id).unwrap(), Cell::new(x, 0, z), Rot::R0),
        step: Step(step),
        color: Color::RED,
    };
    let column = 3 * MAX_REPAIRED_STEP as i32;
    let mut pieces = vec![piece("3010", 0, 0, 1), piece("3009", 3, 1, 2)];
    pieces.extend((0..column).map(|k| piece("3005", 8, 2 + k, 3 + k as u32)));
    let asm = Assembly {
        pieces,
        layer_ldu: 24,
    };
    assert!(verify(&asm, None).is_ok(), "{}", verify(&asm, None));
    let params = Params::default();
    let trials = std::cell::Cell::new(0);
    let go = || {
        trials.set(trials.get() + 1);
        true
    };
    assert!(reorder_while(&asm, &params, 2, &go).unwrap().is_none());
    // One trial or two a step (the step, then without what fails), up to
    // the step where too many wait: about a third of the column.
    assert!(
        trials.get() <= 2 * (MAX_REPAIRED_STEP + 2),
        "{} trials for a column of {column}",
        trials.get()
    );
}

#[test]
fn an_order_repaired_build_reports_the_repair_and_every_step_stands_checked_again() {
    // A pebble three times as wide as it is deep and high, at 32 studs:
    // course by course, a 1 x 8 at step 2 hangs out past what holds it;
    // the order repair builds it a step later. Every step the repair's
    // walk kept was certified, and those certificates are the new order's
    // check: checked again here, and each step solved whole.
    use brickwright::ldraw::{read_ldr, to_assembly};
    let tmp = tempfile::tempdir().unwrap();
    let mesh = tmp.path().join("pebble.obj");
    std::fs::write(&mesh, common::ellipsoid(3.0, 1.0, 1.0, 32)).unwrap();
    let out = tmp.path().join("out");
    let run = build(&mesh, "32", &out, &["--formats", "ldr"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let r = report(&out);
    let st = &r["stability"];
    assert_eq!(st["stands"], true, "{st}");
    let moved = st["moved"].as_array().unwrap();
    assert!(!moved.is_empty(), "{st}");
    // The report says what was repaired, and how it stood before.
    let repairs = st["repairs"].as_array().unwrap();
    assert!(
        repairs
            .iter()
            .any(|x| x.as_str().unwrap().starts_with("order: ")),
        "{st}"
    );
    let before = st["before"]["first_failure"].as_u64().unwrap();
    assert!(before >= 1, "{st}");
    let model = read_ldr(&out.join("pebble.ldr")).unwrap();
    let asm = to_assembly(&model).unwrap();
    let params = Params::default();
    let again = analyze_steps(&asm, &params, false).unwrap();
    assert_eq!(again.first_failure, None, "{again:?}");
    let steps = st["steps"].as_array().unwrap();
    assert_eq!(steps.len(), again.steps.len());
    for (reported, check) in steps.iter().zip(&again.steps) {
        assert_eq!(reported["step"].as_u64(), Some(u64::from(check.step)));
        assert_eq!(reported["stands"], true);
        let whole = brickwright::physics::analyze(&asm.through_step(check.step), &params).unwrap();
        assert!(whole.stands(), "step {}", check.step);
    }
}
