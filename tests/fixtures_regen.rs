//! The checked-in fixtures are exactly what the generator writes.
//!
//! Runs `cargo run --profile test --example make_fixtures -- --out TMP` and
//! compares every file byte for byte with `fixtures/`, both ways (nothing
//! missing, nothing extra). `--profile test` is the profile `cargo test`
//! already built the example with, so the nested cargo finds it up to date
//! instead of compiling the crate and its dependencies a second time; it
//! still rebuilds a stale example, so the check never runs an old
//! generator. Cargo releases its build lock before it runs tests, so the
//! nested call does not wait on the outer one.
//!
//! To update the fixtures after an intended change to the generator, run
//! `cargo run --example make_fixtures` and review the diff.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Every file under `dir`, as paths relative to it, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let path = e.unwrap().path();
            if path.is_dir() {
                todo.push(path);
            } else {
                out.push(path.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

#[test]
fn fixtures_match_the_generator() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().expect("cannot make a temporary directory");
    let out = tmp.path().join("fixtures");
    let status = Command::new(env!("CARGO"))
        .args([
            "run",
            "--quiet",
            "--profile",
            "test",
            "--example",
            "make_fixtures",
            "--",
            "--out",
        ])
        .arg(&out)
        .current_dir(root)
        .stdout(std::process::Stdio::null())
        .status()
        .expect("cannot run cargo");
    assert!(status.success(), "make_fixtures failed: {status}");

    let fixtures = root.join("fixtures");
    let want = files(&out);
    let have = files(&fixtures);
    assert_eq!(
        have, want,
        "fixtures/ and the generator's output hold different files; \
         run `cargo run --example make_fixtures`"
    );
    let differ: Vec<&PathBuf> = want
        .iter()
        .filter(|f| std::fs::read(out.join(f)).unwrap() != std::fs::read(fixtures.join(f)).unwrap())
        .collect();
    assert!(
        differ.is_empty(),
        "fixtures differ from the generator's output: {differ:?}; \
         run `cargo run --example make_fixtures` and review the diff"
    );
}
