//! Helpers shared by the integration tests: outside tools and golden files.
//!
//! - A test that needs an outside tool (xmllint, qpdf, pdftotext, node with
//!   the glTF validator) fails when the tool is missing, unless skipping is
//!   asked for with `BRICKWRIGHT_SKIP_TOOLS=1`, which any non-empty `CI`
//!   overrides: `.ci/run` installs every tool, so a green CI run means they
//!   all ran.
//! - Golden files are rewritten only with `BLESS=1`, never when `CI` is set,
//!   and a blessed file is still compared with the output it was written
//!   from.

#![allow(dead_code)] // Each test file uses some of these.

use std::path::Path;
use std::process::Command;

/// Whether `CI` is set to anything but the empty string.
pub fn in_ci() -> bool {
    std::env::var_os("CI").is_some_and(|v| !v.is_empty())
}

/// The skip rule, from the values of `BRICKWRIGHT_SKIP_TOOLS` and `CI`.
pub fn skip_rule(skip: Option<&str>, ci: Option<&str>) -> bool {
    skip == Some("1") && ci.is_none_or(str::is_empty)
}

/// The bless rule, from the values of `BLESS` and `CI`: whether to rewrite,
/// or why not at all.
pub fn bless_rule(bless: Option<&str>, ci: Option<&str>) -> Result<bool, &'static str> {
    match bless {
        None => Ok(false),
        Some(_) if !ci.is_none_or(str::is_empty) => {
            Err("BLESS is set under CI: golden files are only rewritten on a developer's machine")
        }
        Some(v) => Ok(v == "1"),
    }
}

fn var(name: &str) -> Option<String> {
    std::env::var(name).ok()
}

/// Whether a missing tool may be skipped: `BRICKWRIGHT_SKIP_TOOLS=1`
/// outside CI.
pub fn may_skip_tools() -> bool {
    skip_rule(
        var("BRICKWRIGHT_SKIP_TOOLS").as_deref(),
        var("CI").as_deref(),
    )
}

/// Handles a missing outside tool: returns (the caller skips, with a note
/// printed) when [`may_skip_tools`], panics naming what to install
/// otherwise.
pub fn missing_tool(what: &str, install: &str) {
    assert!(
        may_skip_tools(),
        "{what} is missing: {install} (.ci/run installs it), or set \
         BRICKWRIGHT_SKIP_TOOLS=1 to skip the checks that need it (ignored under CI)"
    );
    eprintln!("skipped (BRICKWRIGHT_SKIP_TOOLS=1): {what} is missing ({install})");
}

/// Whether the outside tool `name` (from Debian's `package`) is there;
/// `false` only when it is missing and skipping was asked for (see the
/// module docs), a failure otherwise.
pub fn tool(name: &str, package: &str) -> bool {
    if Command::new(name).arg("-v").output().is_ok() {
        return true;
    }
    missing_tool(name, &format!("apt-get install {package}"));
    false
}

/// Whether the outside tool `name` (from Debian's `package`) answers
/// `name version_arg` (for tools whose `-v` does something else, such as
/// Chromium). A missing tool fails the test unless skipping was asked for
/// (see [`may_skip_tools`]), so a green run means the check really ran.
pub fn required_tool(name: &str, package: &str, version_arg: &str) -> bool {
    if Command::new(name).arg(version_arg).output().is_ok() {
        return true;
    }
    missing_tool(name, &format!("apt-get install {package}"));
    false
}

/// Whether golden files are to be rewritten: `BLESS=1`. Panics when `BLESS`
/// is set under CI, where goldens never bless themselves.
pub fn bless() -> bool {
    bless_rule(var("BLESS").as_deref(), var("CI").as_deref()).unwrap_or_else(|e| panic!("{e}"))
}

/// Compares `got` with the golden file at `path`, after rewriting it first
/// when [`bless`] says so.
pub fn golden_text(path: &Path, got: &str) {
    if bless() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, got).unwrap();
    }
    let want = std::fs::read_to_string(path)
        .unwrap_or_else(|_| panic!("{} is missing; BLESS=1 creates it", path.display()));
    assert!(
        got == want,
        "{} differs from the output; BLESS=1 to accept",
        path.display()
    );
}
