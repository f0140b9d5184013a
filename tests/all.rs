//! Every integration test, in one test binary.
//!
//! Each file `tests/NAME.rs` is a module here, so `cargo test` builds and
//! links one binary instead of one a file: on two cores that halves the
//! time spent building the integration tests (see `docs/contributing.md`).
//! A new `tests/NAME.rs` must be listed below (`mod NAME;`), which
//! [`every_test_file_is_listed`] checks; run one file's tests with
//! `cargo test --test all NAME::`. Helpers shared by the files live in
//! `tests/common` (`use crate::common;`).

mod common;

mod backward;
mod booklet;
mod cli;
mod colours;
mod corpus_regen;
mod default_rules;
mod docs;
mod exports;
mod fixtures_regen;
mod framing;
mod fuzz;
mod gltf;
mod hollow;
mod hostile;
mod layout;
mod ldraw_roundtrip;
mod physics;
mod render;
mod roofs;
mod stability;
mod sweep;
mod test_rules;
mod viewer;

/// Every `tests/*.rs` file is a module of this binary: Cargo.toml sets
/// `autotests = false`, so a file not listed here would never run.
#[test]
fn every_test_file_is_listed() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let listed: std::collections::BTreeSet<String> = include_str!("all.rs")
        .lines()
        .filter_map(|l| l.strip_prefix("mod ")?.strip_suffix(';'))
        .map(str::to_string)
        .collect();
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "rs"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .filter(|name| name != "all")
        .collect();
    files.sort();
    assert!(files.len() >= 20, "only {} test files found", files.len());
    let missing: Vec<&String> = files.iter().filter(|f| !listed.contains(*f)).collect();
    assert!(
        missing.is_empty(),
        "tests/{{{}}}.rs not in tests/all.rs: add `mod NAME;` there",
        missing
            .iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>()
            .join(",")
    );
    let gone: Vec<&String> = listed
        .iter()
        .filter(|m| *m != "common" && !files.contains(m))
        .collect();
    assert!(
        gone.is_empty(),
        "tests/all.rs lists {gone:?}, which have no file"
    );
}
