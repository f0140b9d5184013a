//! The booklet and the pictures of real builds: the PDF passes `qpdf
//! --check`, has the pages the layout plans, and its text (pdftotext)
//! holds every step number and every parts-list line with its count; the
//! step images exist, one a step, and change from step to step.
//!
//! `qpdf` and `pdftotext` (Debian's `qpdf` and `poppler-utils`) are outside
//! tools: without them the checks that need them say so and pass, except
//! when `CI=true`, where they fail.

use std::path::{Path, PathBuf};
use std::process::Command;

use brickwright::pipeline::{self, BuildOptions, BuildOutput, Formats, Silent};
use brickwright::voxel::Sizing;

use crate::common;
use common::tool;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn build(fixture: &str, out: &Path, configure: impl FnOnce(&mut BuildOptions)) -> BuildOutput {
    let mut opts = BuildOptions::new(root().join("fixtures").join(fixture));
    opts.out_dir = out.to_path_buf();
    opts.sizing = Sizing::Studs(10);
    configure(&mut opts);
    pipeline::build(&opts, &Silent).unwrap_or_else(|e| panic!("{fixture} does not build: {e}"))
}

fn run(cmd: &str, args: &[&str]) -> String {
    let out = Command::new(cmd).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{cmd} {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn the_booklet_has_every_step_and_part() {
    let tmp = tempfile::tempdir().unwrap();
    let built = build("house.obj", tmp.path(), |o| {
        o.slopes = true;
        o.formats = Formats::parse("ldr,pdf,steps,png,exploded-png").unwrap();
    });
    let pdf = tmp.path().join("house.pdf");
    let bytes = std::fs::read(&pdf).unwrap();
    assert!(bytes.starts_with(b"%PDF-"));
    // The booklet may shrink, not grow: it was 348,236 bytes (4 pages,
    // 8 steps) when this bound was set, 15% below it.
    assert!(
        bytes.len() <= 400_000,
        "the booklet grew: {} bytes",
        bytes.len()
    );
    let report = &built.report;
    let pages = report.booklet_pages.expect("a booklet was written");
    // Cover, at least one parts-list page, the step pages, the exploded view.
    assert!(
        pages >= 4 && pages < 4 + report.steps as usize,
        "{pages} pages"
    );

    if tool("qpdf", "qpdf") {
        run("qpdf", &["--check", pdf.to_str().unwrap()]);
        let n = run("qpdf", &["--show-npages", pdf.to_str().unwrap()]);
        assert_eq!(n.trim().parse::<usize>().unwrap(), pages);
    }
    if tool("pdftotext", "poppler-utils") {
        let text = run("pdftotext", &["-layout", pdf.to_str().unwrap(), "-"]);
        let pages_text: Vec<&str> = text.split('\u{c}').collect();
        assert!(
            pages_text[0].contains("house")
                && pages_text[0].contains(&format!("{} pieces", report.pieces))
        );
        // Every parts-list line: its count and name.
        let bom = pages_text[1];
        assert!(bom.contains("Parts list"));
        let all = text.as_str();
        // Each parts-list cell reads, top to bottom: "<count>x", the name,
        // the colour, "LDraw <part> / <colour>", "BrickLink ...". Find each
        // row's LDraw line and read the count three lines above it, in the
        // same column.
        let lines: Vec<&str> = text.lines().collect();
        let mut counted = std::collections::BTreeMap::new();
        for (i, line) in lines.iter().enumerate().skip(3) {
            for (col, _) in line.match_indices("LDraw ") {
                let cell: Vec<&str> = line[col..].split_whitespace().take(4).collect();
                let above = lines[i - 3].get(col..).unwrap_or("");
                if let ([_, part, "/", code], Some(count)) =
                    (cell.as_slice(), above.split_whitespace().next())
                {
                    counted.insert((part.to_string(), code.to_string()), count.to_string());
                }
            }
        }
        for row in &report.parts {
            let key = (row.part.clone(), row.color.to_string());
            assert_eq!(
                counted.get(&key).map(String::as_str),
                Some(format!("{}x", row.count).as_str()),
                "count of {row:?} in the parts list"
            );
            assert!(all.contains(&row.name), "{}", row.name);
            assert!(
                all.contains(&format!("BrickLink {}", row.bricklink)),
                "{}",
                row.bricklink
            );
        }
        // Every step number, as a word on the step pages, in order.
        let words: Vec<&str> = pages_text[2..pages_text.len() - 1]
            .iter()
            .flat_map(|p| p.split_whitespace())
            .collect();
        let mut next = 1u32;
        for w in &words {
            if w.parse::<u32>() == Ok(next) {
                next += 1;
            }
        }
        assert_eq!(next - 1, report.steps, "step numbers found in order");
        assert!(pages_text[pages - 1].contains("Exploded view"));
    }

    // One image a step, all the same size; each step changes the picture.
    let steps_dir = tmp.path().join("steps");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&steps_dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert_eq!(files.len(), report.steps as usize);
    assert!(files[0].ends_with("step-001.png"));
    let images: Vec<image::RgbaImage> = files
        .iter()
        .map(|f| image::open(f).unwrap().to_rgba8())
        .collect();
    for (k, w) in images.windows(2).enumerate() {
        assert_eq!(w[0].dimensions(), w[1].dimensions());
        assert_ne!(w[0], w[1], "step {} changes nothing", k + 2);
    }
    for name in ["house.png", "house-exploded.png"] {
        let img = image::open(tmp.path().join(name)).unwrap().to_rgba8();
        assert!(
            img.pixels().any(|p| p.0 != [255, 255, 255, 255]),
            "{name} is blank"
        );
    }
}

#[test]
fn a_template_changes_the_layout_and_a_bad_one_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let template = tmp.path().join("letter.toml");
    std::fs::write(
        &template,
        "[page]\nsize = \"Letter\"\n[steps]\nper_page = 1\n",
    )
    .unwrap();
    let built = build("wedge.stl", tmp.path(), |o| {
        o.formats = Formats::parse("pdf").unwrap();
        o.template = Some(template.clone());
    });
    // One step a page: cover, parts list, a page a step, exploded view.
    let report = &built.report;
    assert_eq!(report.booklet_pages, Some(report.steps as usize + 3));
    if tool("pdfinfo", "poppler-utils") {
        let info = run("pdfinfo", &[tmp.path().join("wedge.pdf").to_str().unwrap()]);
        assert!(info.contains("612 x 792 pts"), "{info}");
    }

    let bad = tmp.path().join("bad.toml");
    std::fs::write(&bad, "[page]\nsize = \"A4\"\n[steps]\nper_page = 13\n").unwrap();
    let out = tmp.path().join("bad-out");
    let mut opts = BuildOptions::new(root().join("fixtures/wedge.stl"));
    opts.out_dir = out.clone();
    opts.template = Some(bad.clone());
    let err = pipeline::build(&opts, &Silent).unwrap_err().to_string();
    assert!(err.starts_with(&format!("{}:4: ", bad.display())), "{err}");
    assert!(!out.exists(), "nothing written for a bad template");
}
