//! LDraw round trips, the golden file, and bad input.
//!
//! Run `BLESS=1 cargo test --test all ldraw_roundtrip::` to rewrite the golden
//! file after an intended change to the output, then review the diff.

use crate::common;

use std::path::{Path, PathBuf};

use brickwright::assembly::{Assembly, Placed, Placement, Step};
use brickwright::catalog::{Color, PartKind};
use brickwright::geom::{Cell, Rot};
use brickwright::ldraw::{parse_ldr, read_ldr, to_assembly, write_ldr, LdrError, LdrMeta};

fn meta(name: &str) -> LdrMeta {
    LdrMeta {
        title: "Test model".into(),
        name: name.into(),
        author: "brickwright tests".into(),
        notes: vec!["brickwright 0.1.0".into(), "seed 7".into()],
        step_notes: Default::default(),
        piece_notes: Default::default(),
    }
}

fn write(asm: &Assembly) -> String {
    let mut out = Vec::new();
    write_ldr(&mut out, asm, &meta("t.ldr")).unwrap();
    String::from_utf8(out).unwrap()
}

fn round_trip(asm: &Assembly) -> Assembly {
    let text = write(asm);
    let model = parse_ldr(&text, Path::new("t.ldr")).unwrap();
    to_assembly(&model).unwrap()
}

fn part(id: &str) -> PartKind {
    PartKind::from_id(id).unwrap()
}

#[test]
fn every_part_in_every_rotation_round_trips() {
    for kind in PartKind::all() {
        for rot in Rot::ALL {
            // An anchor at the origin keeps the minimum corner at 0, so the
            // reader's shift is the identity.
            let order = [
                Placement::new(part("3005"), Cell::new(0, 0, 0), Rot::R0),
                Placement::new(kind, Cell::new(3, 5, 2), rot),
                Placement::new(kind, Cell::new(1, 0, 7), rot.then(Rot::R90)),
            ];
            let asm = Assembly::from_order(&order, 8, Color(71));
            assert_eq!(round_trip(&asm), asm, "{kind} {rot:?}");
        }
    }
}

/// Slopes on half-brick layers: their LDraw origin is on the back row, and
/// the reader picks 12 LDU layers back.
#[test]
fn slopes_on_half_brick_layers_round_trip() {
    let order = [
        Placement::new(part("3001"), Cell::new(0, 0, 0), Rot::R0),
        Placement::new(part("3039"), Cell::new(0, 0, 2), Rot::R90),
        Placement::new(part("3298"), Cell::new(2, 0, 2), Rot::R180),
        Placement::new(part("3004"), Cell::new(0, 0, 1), Rot::R270),
        Placement::new(part("3665a"), Cell::new(5, 1, 3), Rot::R270),
    ];
    let asm = Assembly::from_order(&order, 12, Color(4));
    let back = round_trip(&asm);
    assert_eq!(back, asm);
    assert_eq!(back.layer_ldu, 12);
    // 3039 turned a quarter: the back row (LDraw +Z turned) lies at grid -x,
    // so the origin sits 10 LDU from the footprint's centre toward -X.
    let text = write(&asm);
    assert!(
        text.contains("1 4 10 -48 20 0 0 -1 0 1 0 1 0 0 3039.dat"),
        "{text}"
    );
}

/// Slopes keep half-brick layers when read back even if every piece sits on
/// a whole brick course: a slope's face needs them.
#[test]
fn slopes_on_brick_courses_read_back_on_half_brick_layers() {
    let order = [
        Placement::new(part("3001"), Cell::new(0, 0, 0), Rot::R0),
        Placement::new(part("3039"), Cell::new(0, 0, 2), Rot::R0),
    ];
    let asm = Assembly::from_order(&order, 12, Color(4));
    let back = round_trip(&asm);
    assert_eq!(back.layer_ldu, 12);
    assert_eq!(back, asm);
}

#[test]
fn reader_shifts_the_lowest_corner_to_zero_and_keeps_steps_and_colours() {
    let p = |id, x, y, z, rot, step, color| Placed {
        placement: Placement::new(part(id), Cell::new(x, y, z), rot),
        step: Step(step),
        color: Color(color),
    };
    let asm = Assembly {
        pieces: vec![
            p("3001", -4, 10, 3, Rot::R0, 1, 4),
            p("3010", -2, 9, 4, Rot::R90, 1, 15),
            p("3003", 0, 12, 5, Rot::R0, 2, 1),
        ],
        layer_ldu: 24,
    };
    let back = round_trip(&asm);
    let shifted: Vec<Placed> = asm
        .pieces
        .iter()
        .map(|q| Placed {
            placement: Placement {
                origin: q.placement.origin.offset(4, -9, -3),
                ..q.placement
            },
            ..*q
        })
        .collect();
    assert_eq!(back.pieces, shifted);
}

fn golden_assembly() -> Assembly {
    let p = |id, x, y, z, rot, step, color| Placed {
        placement: Placement::new(part(id), Cell::new(x, y, z), rot),
        step: Step(step),
        color: Color(color),
    };
    Assembly {
        pieces: vec![
            p("3001", 0, 0, 0, Rot::R0, 1, 4),
            p("3001", 4, 0, 0, Rot::R90, 1, 4),
            p("3010", 1, 1, 1, Rot::R0, 2, 15),
            p("3003", 4, 2, 1, Rot::R0, 2, 1),
        ],
        layer_ldu: 24,
    }
}

#[test]
fn golden_small_ldr() {
    let golden = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden/small.ldr");
    let mut out = Vec::new();
    let meta = LdrMeta {
        title: "Small test model".into(),
        name: "small.ldr".into(),
        author: "brickwright".into(),
        notes: vec![
            "brickwright golden test".into(),
            "hand-made: two 2x4s, a 1x4, a 2x2".into(),
        ],
        step_notes: Default::default(),
        piece_notes: Default::default(),
    };
    write_ldr(&mut out, &golden_assembly(), &meta).unwrap();
    let text = String::from_utf8(out).unwrap();
    common::golden_text(&golden, &text);
    // The golden file reads back to the same assembly.
    let back = to_assembly(&read_ldr(&golden).unwrap()).unwrap();
    assert_eq!(back, golden_assembly());
}

/// Writes `text` to a fresh file and returns the error reading it.
fn read_err(dir: &Path, name: &str, text: &[u8]) -> (PathBuf, LdrError) {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let err = read_ldr(&path)
        .and_then(|m| to_assembly(&m))
        .expect_err("expected an error");
    (path, err)
}

#[test]
fn bad_files_give_errors_naming_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = "1 4 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat\n";
    let cases: &[(&str, String, usize, &str)] = &[
        (
            "unknown.ldr",
            format!("0 Title\n{good}1 4 0 -24 0 1 0 0 0 1 0 0 0 1 4315.dat\n"),
            3,
            "unknown part `4315.dat`",
        ),
        (
            "offgrid.ldr",
            format!("{good}\n1 4 45 -24 20 1 0 0 0 1 0 0 0 1 3001.dat\n"),
            3,
            "off the grid: X = 45 LDU",
        ),
        (
            "offlayer.ldr",
            format!("{good}1 4 40 -30 20 1 0 0 0 1 0 0 0 1 3001.dat\n"),
            2,
            "off the grid: Y = -30 LDU",
        ),
        (
            "tilted.ldr",
            format!("{good}1 4 40 -24 20 1 0 0 0 0 -1 0 1 0 3001.dat\n"),
            2,
            "not turned by a quarter turn",
        ),
        (
            "number.ldr",
            "0 x\r\n1 4 40 -24 2O 1 0 0 0 1 0 0 0 1 3001.dat\r\n".into(),
            2,
            "bad z: expected a number, found `2O`",
        ),
        (
            "short.ldr",
            "1 4 40 -24 20 1 0 0\n".into(),
            1,
            "too few fields",
        ),
        (
            "prose.ldr",
            "This is not a model.\n".into(),
            1,
            "not LDraw text",
        ),
        (
            "loop.mpd",
            "0 FILE a.ldr\n1 4 0 0 0 1 0 0 0 1 0 0 0 1 a.ldr\n".into(),
            2,
            "submodel `a.ldr` contains itself",
        ),
    ];
    for (name, text, line, what) in cases {
        let (path, err) = read_err(dir.path(), name, text.as_bytes());
        let msg = err.to_string();
        let prefix = format!("{}:{line}: ", path.display());
        assert!(msg.starts_with(&prefix), "{name}: {msg}");
        assert!(msg.contains(what), "{name}: {msg}");
    }
    let (path, err) = read_err(dir.path(), "binary.ldr", b"0 x\n\x00\x01\x02");
    assert_eq!(
        err.to_string(),
        format!(
            "{}:2: not LDraw text: binary data (a NUL byte)",
            path.display()
        )
    );
    let missing = dir.path().join("nope.ldr");
    let err = read_ldr(&missing).unwrap_err();
    assert!(matches!(err, LdrError::Read { .. }));
    assert!(err
        .to_string()
        .starts_with(&format!("{}: cannot read", missing.display())));
}

#[test]
fn mpd_file_reads_into_one_assembly() {
    let text = "\
0 FILE house.ldr
0 House
1 4 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat
0 STEP
1 15 0 0 0 1 0 0 0 1 0 0 0 1 top.ldr
0 STEP
0 NOFILE
0 FILE top.ldr
1 16 40 -48 20 1 0 0 0 1 0 0 0 1 3001.dat
0 NOFILE
";
    let asm = to_assembly(&parse_ldr(text, Path::new("house.mpd")).unwrap()).unwrap();
    let order = [
        Placement::new(part("3001"), Cell::new(0, 0, 0), Rot::R0),
        Placement::new(part("3001"), Cell::new(0, 0, 1), Rot::R0),
    ];
    let mut want = Assembly::from_order(&order, 24, Color(4));
    want.pieces[1].color = Color(15);
    assert_eq!(asm, want);
}

/// A small deterministic generator (xorshift), so failures reproduce.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
}

/// Parsing and mapping must return, never panic; the result is irrelevant.
fn must_not_panic(text: &str) {
    if let Ok(model) = parse_ldr(text, Path::new("fuzz.ldr")) {
        let _ = to_assembly(&model);
    }
}

#[test]
fn garbage_and_truncated_input_never_panics() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    // Random bytes, through the file reader.
    let dir = tempfile::tempdir().unwrap();
    for i in 0..200 {
        let len = (rng.next() % 400) as usize;
        let bytes: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        let path = dir.path().join(format!("r{i}.ldr"));
        std::fs::write(&path, &bytes).unwrap();
        if let Ok(m) = read_ldr(&path) {
            let _ = to_assembly(&m);
        }
    }
    // Every prefix of a valid MPD.
    let mut good = Vec::new();
    write_ldr(&mut good, &golden_assembly(), &meta("g.ldr")).unwrap();
    let good = format!(
        "0 FILE main.ldr\n{}1 16 20 -72 0 0 0 1 0 1 0 -1 0 0 sub.ldr\n0 FILE sub.ldr\n\
         1 16 10 -24 10 1 0 0 0 1 0 0 0 1 3005.dat\n",
        String::from_utf8(good).unwrap()
    );
    for end in 0..=good.len() {
        must_not_panic(&good[..end]);
    }
    // Valid lines with tokens swapped for troublemakers.
    let nasty = [
        "",
        "-",
        "1e308",
        "-1e308",
        "1e-320",
        "0x10",
        "99999999999",
        "-0",
        "NaN",
        "STEP",
        "FILE",
        "0",
        "1",
        "16",
        "sub.ldr",
        "main.ldr",
        "é",
        "\t",
        "3001.dat",
        "1e9",
    ];
    let lines: Vec<&str> = good.lines().collect();
    for _ in 0..3000 {
        let mut out = String::new();
        for line in &lines {
            let mut toks: Vec<&str> = line.split(' ').collect();
            if rng.next().is_multiple_of(3) {
                let k = (rng.next() as usize) % toks.len();
                toks[k] = nasty[(rng.next() as usize) % nasty.len()];
            }
            out += &toks.join(" ");
            out.push('\n');
        }
        must_not_panic(&out);
    }
}
