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
