//! The checked-in corpus is exactly what the generator writes.
//!
//! Runs `cargo run --profile test --example make_corpus -- --out TMP` and
//! compares the `.ldr` files and the README byte for byte with
//! `rules/examples/`, both ways (nothing missing, nothing extra). `--profile
//! test` is the profile `cargo test` already built the example with, so the
//! nested cargo finds it up to date instead of compiling the crate and its
//! dependencies a second time; it still rebuilds a stale example, so the
//! check never runs an old generator. Cargo releases its build lock before it
//! runs tests, so the nested call does not wait on the outer one.
//!
//! To update the corpus after an intended change to the generator, run
//! `cargo run --example make_corpus` and review the diff.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The `.ldr` files directly in `dir`, sorted by name.
fn models(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "ldr"))
        .map(|p| PathBuf::from(p.file_name().unwrap()))
        .collect();
    out.sort();
    out
}

#[test]
fn corpus_matches_the_generator() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().expect("cannot make a temporary directory");
    let out = tmp.path().join("examples");
    let status = Command::new(env!("CARGO"))
        .args([
            "run",
            "--quiet",
            "--profile",
            "test",
            "--example",
            "make_corpus",
            "--",
            "--out",
        ])
        .arg(&out)
        .current_dir(root)
        .stdout(std::process::Stdio::null())
        .status()
        .expect("cannot run cargo");
    assert!(status.success(), "make_corpus failed: {status}");

    let corpus = root.join("rules/examples");
    let want = models(&out);
    let have = models(&corpus);
    assert!(!want.is_empty(), "the generator wrote no .ldr files");
    assert_eq!(
        have, want,
        "rules/examples/ and the generator's output hold different .ldr files; \
         run `cargo run --example make_corpus`"
    );
    let differ: Vec<&Path> = want
        .iter()
        .map(PathBuf::as_path)
        .chain([Path::new("README.md")])
        .filter(|f| std::fs::read(out.join(f)).unwrap() != std::fs::read(corpus.join(f)).unwrap())
        .collect();
    assert!(
        differ.is_empty(),
        "rules/examples/ differs from the generator's output: {differ:?}; \
         run `cargo run --example make_corpus` and review the diff"
    );
}
