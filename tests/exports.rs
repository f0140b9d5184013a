//! The parts lists of real builds: the BrickLink wanted list and the
//! Rebrickable CSV agree with the `.ldr` by part and colour, sum to the
//! piece count, validate against the wanted-list schema, and match golden
//! files for a small fixture.
//!
//! The schema check runs `xmllint` (Debian's `libxml2-utils`); without it
//! the test says so and passes, except when `CI=true`, where it fails.
//! `BLESS=1 cargo test --test all exports::` rewrites the golden files.

use crate::common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use brickwright::catalog::{Color, Palette, PartKind};
use brickwright::export::partslist::Condition;
use brickwright::pipeline::{self, BuildOptions, Formats, Silent};
use brickwright::voxel::Sizing;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Builds a fixture small into `out` and returns the piece count.
fn build(fixture: &str, out: &Path, configure: impl FnOnce(&mut BuildOptions)) -> usize {
    let mut opts = BuildOptions::new(root().join("fixtures").join(fixture));
    opts.out_dir = out.to_path_buf();
    opts.sizing = Sizing::Studs(10);
    configure(&mut opts);
    let built =
        pipeline::build(&opts, &Silent).unwrap_or_else(|e| panic!("{fixture} does not build: {e}"));
    built.report.pieces
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// (LDraw part, LDraw colour) -> count, from the `.ldr`'s type-1 lines.
fn ldr_counts(ldr: &str) -> BTreeMap<(String, u16), usize> {
    let mut counts = BTreeMap::new();
    for line in ldr.lines() {
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.first() != Some(&"1") {
            continue;
        }
        assert_eq!(fields.len(), 15, "a type-1 line has 15 fields: {line}");
        let color: u16 = fields[1].parse().expect("numeric colour");
        let part = fields[14].trim_end_matches(".dat").to_string();
        *counts.entry((part, color)).or_insert(0) += 1;
    }
    counts
}

/// The `.ldr` counts in a shop's numbering.
fn shop_counts(
    ldr: &BTreeMap<(String, u16), usize>,
    part_id: impl Fn(&PartKind) -> String,
    color_id: impl Fn(Color) -> u16,
) -> BTreeMap<(String, u16), usize> {
    let mut out = BTreeMap::new();
    for ((part, color), n) in ldr {
        let kind = PartKind::from_id(part).expect("catalog part");
        *out.entry((part_id(&kind), color_id(Color(*color))))
            .or_insert(0) += n;
    }
    out
}

/// (ITEMID, COLOR) -> MINQTY from a wanted list, and the CONDITIONs seen.
fn wanted_list(xml: &str) -> (BTreeMap<(String, u16), usize>, Vec<String>) {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(xml);
    let (mut items, mut conditions) = (BTreeMap::new(), Vec::new());
    let mut field = String::new();
    let (mut id, mut color, mut qty) = (String::new(), 0u16, 0usize);
    loop {
        match reader.read_event().expect("well-formed XML") {
            Event::Start(e) => field = String::from_utf8_lossy(e.name().as_ref()).into_owned(),
            Event::Text(t) => {
                let t = t.unescape().expect("text").trim().to_string();
                match field.as_str() {
                    "ITEMTYPE" => assert_eq!(t, "P"),
                    "ITEMID" => id = t,
                    "COLOR" => color = t.parse().expect("numeric colour"),
                    "MINQTY" => qty = t.parse().expect("numeric quantity"),
                    "CONDITION" => conditions.push(t),
                    _ => {}
                }
            }
            Event::End(e) => {
                if e.name().as_ref() == b"ITEM" {
                    let old = items.insert((id.clone(), color), qty);
                    assert!(old.is_none(), "{id} in colour {color} listed twice");
                }
                field.clear();
            }
            Event::Eof => break,
            _ => {}
        }
    }
    (items, conditions)
}

/// (Part, Color) -> Quantity from a Rebrickable CSV.
fn rebrickable(csv: &str) -> BTreeMap<(String, u16), usize> {
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("Part,Color,Quantity"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 3, "{l}");
            (
                (f[0].to_string(), f[1].parse().expect("colour id")),
                f[2].parse().expect("quantity"),
            )
        })
        .collect()
}

#[test]
fn parts_lists_agree_with_the_ldr_by_part_and_colour() {
    let tmp = tempfile::tempdir().unwrap();
    let pieces = build("house.obj", tmp.path(), |o| {
        o.slopes = true;
        o.palette = Palette::Random;
        o.condition = Some(Condition::New);
    });
    let ldr = ldr_counts(&read(&tmp.path().join("house.ldr")));
    assert_eq!(ldr.values().sum::<usize>(), pieces);
    assert!(ldr.keys().any(|(p, _)| p == "3040b" || p == "3039"));
    let colors: std::collections::BTreeSet<u16> = ldr.keys().map(|k| k.1).collect();
    assert!(colors.len() > 3, "random palette: {colors:?}");

    let (items, conditions) = wanted_list(&read(&tmp.path().join("house-bricklink.xml")));
    assert_eq!(items.values().sum::<usize>(), pieces);
    assert_eq!(
        items,
        shop_counts(
            &ldr,
            |k| k.spec().bricklink.to_string(),
            |c| c.spec().unwrap().bricklink
        )
    );
    assert_eq!(conditions.len(), items.len());
    assert!(conditions.iter().all(|c| c == "N"));

    let csv = rebrickable(&read(&tmp.path().join("house-parts.csv")));
    assert_eq!(csv.values().sum::<usize>(), pieces);
    assert_eq!(
        csv,
        shop_counts(
            &ldr,
            |k| k.spec().rebrickable().to_string(),
            |c| c.spec().unwrap().rebrickable
        )
    );

    // The report's parts table says the same.
    let report: serde_json::Value =
        serde_json::from_str(&read(&tmp.path().join("report.json"))).unwrap();
    let rows = report["parts"].as_array().unwrap();
    assert_eq!(rows.len(), ldr.len());
    for row in rows {
        let key = (
            row["part"].as_str().unwrap().to_string(),
            row["color"].as_u64().unwrap() as u16,
        );
        assert_eq!(row["count"].as_u64().unwrap() as usize, ldr[&key]);
        assert!(row["bricklink"].is_string() && row["bricklink_color"].is_u64());
    }
    assert_eq!(report["unmapped_colors"], serde_json::json!([]));
}

#[test]
fn formats_choose_the_files_written() {
    let tmp = tempfile::tempdir().unwrap();
    build("wedge.stl", tmp.path(), |o| {
        o.formats = Formats::parse("csv").unwrap();
        o.palette = Palette::Single(Color(14));
    });
    let mut names: Vec<String> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["report.json", "wedge-parts.csv"]);
    let csv = rebrickable(&read(&tmp.path().join("wedge-parts.csv")));
    assert!(csv.keys().all(|(_, c)| *c == 14));
    assert!(Formats::parse("ldr,pdfx").unwrap_err().contains("pdfx"));
}

fn xmllint() -> Option<PathBuf> {
    common::tool("xmllint", "libxml2-utils").then(|| PathBuf::from("xmllint"))
}

#[test]
fn the_wanted_list_validates_against_the_schema() {
    let Some(xmllint) = xmllint() else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    build("barn.obj", tmp.path(), |o| {
        o.slopes = true;
        o.condition = Some(Condition::Used);
    });
    let schema = root().join("tests/data/bricklink-wanted.xsd");
    let xml = tmp.path().join("barn-bricklink.xml");
    let out = Command::new(xmllint)
        .arg("--noout")
        .arg("--schema")
        .arg(&schema)
        .arg(&xml)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "xmllint refused {}:\n{}",
        xml.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    // The schema is not a rubber stamp: a list with a bad condition fails.
    let bad = tmp.path().join("bad.xml");
    std::fs::write(&bad, read(&xml).replace("<CONDITION>U", "<CONDITION>Q")).unwrap();
    let out = Command::new("xmllint")
        .args(["--noout", "--schema"])
        .arg(&schema)
        .arg(&bad)
        .output()
        .unwrap();
    assert!(!out.status.success(), "a bad CONDITION must not validate");
}

fn golden(name: &str, got: &str) {
    common::golden_text(&root().join("tests/golden").join(name), got);
}

#[test]
fn parts_lists_of_a_small_fixture_match_the_golden_files() {
    let tmp = tempfile::tempdir().unwrap();
    build("barn.obj", tmp.path(), |o| {
        o.sizing = Sizing::Studs(8);
        o.slopes = true;
        o.condition = Some(Condition::New);
    });
    let csv = read(&tmp.path().join("barn-parts.csv"));
    // BrickLink and Rebrickable number the slope 2 x 1 3040, LDraw 3040b.
    assert!(csv.contains("\n3040,"), "{csv}");
    golden(
        "barn-bricklink.xml",
        &read(&tmp.path().join("barn-bricklink.xml")),
    );
    golden("barn-parts.csv", &csv);
}
