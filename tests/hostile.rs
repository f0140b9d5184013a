//! The binary against a hostile or careless user: references out of the
//! model's folder, absurd options, deep and huge LDraw files, blocked and
//! linked output folders, terminal escapes in names, rule files that
//! cannot cover the shape. Every input is made here.
//!
//! Each test asserts what must happen: one clean line and a known exit
//! code, nothing read or written outside what the user named, no panic.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn brickwright(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_brickwright"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("cannot start the brickwright binary")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn describe(o: &Output) -> String {
    format!(
        "exit {:?}\n--- stdout\n{}--- stderr\n{}",
        o.status.code(),
        text(&o.stdout),
        text(&o.stderr)
    )
}

/// Exit `code`, one `error: ` line on stderr, no panic.
fn assert_one_line(o: &Output, code: i32) {
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(code), "{}", describe(o));
    assert_eq!(err.lines().count(), 1, "{}", describe(o));
    assert!(err.starts_with("error: "), "{}", describe(o));
    assert!(!err.contains("panicked"), "{}", describe(o));
}

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
        .display()
        .to_string()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A glTF cube whose buffer is at `uri`, and the cube's bytes.
fn cube_gltf(uri: &str) -> (String, Vec<u8>) {
    let v: [[f32; 3]; 8] = std::array::from_fn(|i| {
        [
            (i & 1) as f32 * 4.0,
            (i >> 1 & 1) as f32 * 4.0,
            (i >> 2 & 1) as f32 * 4.0,
        ]
    });
    let t: [[u16; 3]; 12] = [
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    let mut bin: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
    bin.extend(t.iter().flatten().flat_map(|i| i.to_le_bytes()));
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
  "buffers": [{{"uri": "{uri}", "byteLength": 168}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 96}}, {{"buffer": 0, "byteOffset": 96, "byteLength": 72}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [0, 0, 0], "max": [4, 4, 4]}},
    {{"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}}]}}"#
    );
    (json, bin)
}

#[test]
fn gltf_buffers_outside_the_model_folder_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let model = tmp.path().join("model");
    std::fs::create_dir(&model).unwrap();
    let (_, bin) = cube_gltf("");
    // A valid buffer one folder up: it must not become the model.
    std::fs::write(tmp.path().join("x.bin"), &bin).unwrap();
    for uri in ["../x.bin", "/etc/passwd", "file:///etc/passwd", "/dev/zero"] {
        let (json, _) = cube_gltf(uri);
        std::fs::write(model.join("m.gltf"), json).unwrap();
        let out = tmp.path().join("out");
        let o = brickwright(tmp.path(), &["build", "model/m.gltf", "-o", s(&out)]);
        assert_one_line(&o, 2);
        let err = text(&o.stderr);
        assert!(err.contains("m.gltf") && err.contains("buffer 0"), "{err}");
        assert!(!err.contains("root:"), "file content leaked: {err}");
        assert!(!out.exists(), "{uri}: nothing written");
    }
    // Beside the model, the same buffer builds.
    std::fs::write(model.join("x.bin"), &bin).unwrap();
    let (json, _) = cube_gltf("x.bin");
    std::fs::write(model.join("m.gltf"), json).unwrap();
    let o = brickwright(
        tmp.path(),
        &[
            "build",
            "model/m.gltf",
            "-o",
            "ok",
            "--studs",
            "4",
            "--formats",
            "ldr",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", describe(&o));
}

#[test]
fn absurd_budgets_saturate_or_are_refused_in_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    for (opt, value) in [
        ("--time-budget", "1e25"),
        ("--time-budget", "1.8e19"),
        ("--stability-budget", "1e25"),
        ("--stability-budget", "1.8e19"),
    ] {
        let o = brickwright(
            tmp.path(),
            &[
                "build",
                &fixture("box.obj"),
                "-o",
                "o",
                "--studs",
                "4",
                "--formats",
                "ldr",
                opt,
                value,
            ],
        );
        assert_eq!(o.status.code(), Some(0), "{opt} {value}\n{}", describe(&o));
    }
    for (opt, value) in [
        ("--time-budget", "-1"),
        ("--time-budget", "NaN"),
        ("--stability-budget", "inf"),
        ("--stability-budget", "0"),
    ] {
        let o = brickwright(
            tmp.path(),
            &[
                "build",
                &fixture("box.obj"),
                "-o",
                "o",
                &format!("{opt}={value}"),
            ],
        );
        assert_one_line(&o, 2);
        assert!(text(&o.stderr).contains(opt), "{}", describe(&o));
    }
}

#[test]
fn a_100000_deep_submodel_chain_neither_overflows_nor_recurses() {
    let tmp = tempfile::tempdir().unwrap();
    let mut mpd = String::new();
    for i in 0..100_000 {
        mpd += &format!(
            "0 FILE m{i}.ldr\n1 16 0 0 0 1 0 0 0 1 0 0 0 1 m{}.ldr\n",
            i + 1
        );
    }
    mpd += "0 FILE m100000.ldr\n1 4 0 -24 0 1 0 0 0 1 0 0 0 1 3001.dat\n\
            1 4 0 -48 0 1 0 0 0 1 0 0 0 1 3001.dat\n";
    let path = tmp.path().join("deep.mpd");
    std::fs::write(&path, mpd).unwrap();
    let o = brickwright(tmp.path(), &["verify", s(&path)]);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&o));
    assert!(text(&o.stdout).contains("OK: 2 pieces"), "{}", describe(&o));
    let o = brickwright(
        tmp.path(),
        &["learn", s(&path), "-o", "deep.rules", "--quiet"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", describe(&o));
}

#[test]
fn verify_of_30000_pieces_on_one_spot_reports_a_bounded_list_and_a_count() {
    let tmp = tempfile::tempdir().unwrap();
    let ldr = "1 4 0 -24 0 1 0 0 0 1 0 0 0 1 3001.dat\n".repeat(30_000);
    let path = tmp.path().join("pile.ldr");
    std::fs::write(&path, ldr).unwrap();
    let o = brickwright(tmp.path(), &["verify", s(&path)]);
    assert_eq!(o.status.code(), Some(1), "{}", describe(&o));
    let out = text(&o.stdout);
    assert!(out.lines().count() < 30, "{out}");
    let first = out.lines().next().unwrap();
    let problems: usize = first
        .split_whitespace()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{first}"));
    assert!(problems >= 29_999, "{first}");
    assert!(out.contains("more"), "{out}");
}

#[test]
fn a_blocked_output_leaves_the_previous_run_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("report.json"), "old report").unwrap();
    std::fs::write(out.join("house.ldr"), "old ldr").unwrap();
    std::fs::create_dir(out.join("house.png")).unwrap();
    let o = brickwright(
        tmp.path(),
        &[
            "build",
            &fixture("house.obj"),
            "-o",
            s(&out),
            "--studs",
            "6",
            "--formats",
            "ldr,png",
        ],
    );
    assert_one_line(&o, 2);
    assert!(text(&o.stderr).contains("house.png"), "{}", describe(&o));
    assert_eq!(
        std::fs::read_to_string(out.join("house.ldr")).unwrap(),
        "old ldr"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("report.json")).unwrap(),
        "old report"
    );
    let mut left: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["house.ldr", "house.png", "report.json"]);
}

#[cfg(unix)]
#[test]
fn a_steps_link_out_of_the_output_folder_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let elsewhere = tmp.path().join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();
    std::fs::write(elsewhere.join("step-999.png"), "not mine").unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::os::unix::fs::symlink(&elsewhere, out.join("steps")).unwrap();
    let o = brickwright(
        tmp.path(),
        &[
            "build",
            &fixture("box.obj"),
            "-o",
            s(&out),
            "--studs",
            "4",
            "--formats",
            "ldr,steps",
        ],
    );
    assert_one_line(&o, 2);
    assert!(
        text(&o.stderr).contains("symbolic link"),
        "{}",
        describe(&o)
    );
    let names: Vec<PathBuf> = std::fs::read_dir(&elsewhere)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(names, [elsewhere.join("step-999.png")]);
    assert!(!out.join("box.ldr").exists());
}

#[test]
fn control_characters_in_names_are_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("evil.ldr");
    std::fs::write(
        &path,
        "1 4 0 -24 0 1 0 0 0 1 0 0 0 1 \u{1b}[2J\u{1b}]0;pwned\u{7}.dat\n",
    )
    .unwrap();
    let o = brickwright(tmp.path(), &["verify", s(&path)]);
    assert_one_line(&o, 2);
    let err = text(&o.stderr);
    assert!(!err.trim_end().chars().any(char::is_control), "{err:?}");
    assert!(err.contains("\\u{1b}[2J"), "{err:?}");
}

#[test]
fn rule_files_that_cannot_cover_the_shape_say_what_they_lack() {
    let tmp = tempfile::tempdir().unwrap();
    // Only 1x1 stacking: nothing joins neighbouring columns.
    std::fs::write(
        tmp.path().join("stack.rules"),
        "part 3005\nstart 3005\nrule 3005 3005 r0 up 0 0 1\nrule 3005 3005 r0 down 0 0 1\n",
    )
    .unwrap();
    let o = brickwright(
        tmp.path(),
        &[
            "build",
            &fixture("box.obj"),
            "-o",
            "o1",
            "--studs",
            "6",
            "--rules",
            "stack.rules",
        ],
    );
    assert_one_line(&o, 2);
    let err = text(&o.stderr);
    assert!(
        err.contains("stack.rules") && err.contains("past the side"),
        "{err}"
    );
    assert!(!tmp.path().join("o1").exists());

    // A model of 2x2 and 2x4 bricks only: its learned file builds any
    // shape, as the built-in parts stay in...
    let wall = "1 4 20 -24 20 1 0 0 0 1 0 0 0 1 3003.dat\n\
                1 4 80 -24 20 1 0 0 0 1 0 0 0 1 3001.dat\n0 STEP\n\
                1 4 40 -48 20 1 0 0 0 1 0 0 0 1 3001.dat\n\
                1 4 100 -48 20 1 0 0 0 1 0 0 0 1 3003.dat\n";
    std::fs::write(tmp.path().join("wall.ldr"), wall).unwrap();
    let o = brickwright(
        tmp.path(),
        &["learn", "wall.ldr", "-o", "wall.rules", "--quiet"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", describe(&o));
    let rules = std::fs::read_to_string(tmp.path().join("wall.rules")).unwrap();
    assert!(rules.contains("part 3005"), "{rules}");
    let o = brickwright(
        tmp.path(),
        &[
            "build",
            &fixture("house.obj"),
            "-o",
            "o2",
            "--studs",
            "7",
            "--formats",
            "ldr",
            "--rules",
            "wall.rules",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", describe(&o));
    // ...and restricted to the parts seen, a shape they cannot cover is an
    // error naming the missing 1x1 brick.
    let o = brickwright(
        tmp.path(),
        &[
            "learn",
            "wall.ldr",
            "-o",
            "seen.rules",
            "--quiet",
            "--seen-parts-only",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", describe(&o));
    let rules = std::fs::read_to_string(tmp.path().join("seen.rules")).unwrap();
    assert!(!rules.contains("part 3005"), "{rules}");
    let o = brickwright(
        tmp.path(),
        &[
            "build",
            &fixture("house.obj"),
            "-o",
            "o3",
            "--studs",
            "7",
            "--formats",
            "ldr",
            "--rules",
            "seen.rules",
        ],
    );
    assert_one_line(&o, 2);
    let err = text(&o.stderr);
    assert!(
        err.contains("seen.rules") && err.contains("1x1 brick (3005)"),
        "{err}"
    );
}

#[test]
fn warnings_go_to_stderr_and_survive_quiet() {
    let tmp = tempfile::tempdir().unwrap();
    let o = brickwright(
        tmp.path(),
        &[
            "build",
            &fixture("house.obj"),
            "-o",
            "o",
            "--studs",
            "8",
            "--formats",
            "ldr",
            "--stability-budget",
            "0.000001",
            "--quiet",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", describe(&o));
    assert_eq!(text(&o.stdout), "", "--quiet prints nothing on stdout");
    let err = text(&o.stderr);
    assert!(err.lines().count() >= 1, "{err}");
    assert!(err.lines().all(|l| l.starts_with("warning: ")), "{err}");
    // Without --quiet, with images drawn: the same warnings, and no
    // progress display on a standard error that is not a terminal.
    let o = brickwright(
        tmp.path(),
        &[
            "build",
            &fixture("house.obj"),
            "-o",
            "o2",
            "--studs",
            "8",
            "--formats",
            "ldr,steps",
            "--stability-budget",
            "0.000001",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", describe(&o));
    assert!(text(&o.stdout).contains("step images"), "{}", describe(&o));
    assert_eq!(text(&o.stderr), err, "{}", describe(&o));
}

#[test]
fn every_subcommand_knows_the_version_and_shows_examples() {
    let tmp = tempfile::tempdir().unwrap();
    let version = env!("CARGO_PKG_VERSION");
    for sub in ["build", "verify", "rules", "learn"] {
        let o = brickwright(tmp.path(), &[sub, "--version"]);
        assert_eq!(o.status.code(), Some(0), "{sub}: {}", describe(&o));
        assert!(text(&o.stdout).contains(version), "{sub}: {}", describe(&o));
        let o = brickwright(tmp.path(), &[sub, "--help"]);
        assert!(
            text(&o.stdout).contains("Examples:\n  brickwright "),
            "{sub}: {}",
            describe(&o)
        );
    }
    let o = brickwright(tmp.path(), &["--help"]);
    assert!(text(&o.stdout).contains("Exit codes:"), "{}", describe(&o));
}

/// Round two of the probe (issue 30), in its own file.
#[path = "hostile/round_two.rs"]
mod round_two;
