//! Helpers shared by the integration tests.

use std::process::Command;

/// Whether the outside tool `name` (from Debian's `package`) is there; a
/// note when it is missing outside CI, a failure when `CI=true` (where
/// `.ci/run` installs it).
pub fn tool(name: &str, package: &str) -> bool {
    if Command::new(name).arg("-v").output().is_ok() {
        return true;
    }
    assert!(
        std::env::var("CI").as_deref() != Ok("true"),
        "{name} is missing, and CI=true: .ci/run installs {package}"
    );
    eprintln!("skipped: {name} is missing (apt-get install {package})");
    false
}

/// Whether the outside tool `name` (from Debian's `package`) answers
/// `name version_arg`. A missing tool fails the test unless
/// `BRICKWRIGHT_SKIP_TOOLS=1` asks to skip it (then a note says so), so a
/// green run means the check really ran; `.ci/run` installs the tools.
#[allow(dead_code, reason = "each test crate uses the helpers it needs")]
pub fn required_tool(name: &str, package: &str, version_arg: &str) -> bool {
    if Command::new(name).arg(version_arg).output().is_ok() {
        return true;
    }
    assert!(
        std::env::var("BRICKWRIGHT_SKIP_TOOLS").as_deref() == Ok("1"),
        "{name} is missing: apt-get install {package} (.ci/run does), \
         or set BRICKWRIGHT_SKIP_TOOLS=1 to skip the checks that need it"
    );
    eprintln!("skipped: {name} is missing and BRICKWRIGHT_SKIP_TOOLS=1");
    false
}
