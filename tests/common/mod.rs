//! Helpers shared by the integration tests: outside tools and golden files.
//!
//! - A test that checks an output with an outside tool (xmllint, qpdf,
//!   pdftotext, pdfinfo, node with the glTF validator, Chromium, Firefox
//!   with Xvfb and ImageMagick) asks for it with [`tool`] (or
//!   [`required_tool`], [`gltf_validator`]). Outside CI a missing tool skips
//!   that check, and the first such request of the run probes every tool
//!   and prints one notice to standard error (once a `cargo test` run, not
//!   once a test binary): which checks are skipped and
//!   the command that installs what they need (`.ci/run tools`). Under CI
//!   (any non-empty `CI`, which `.ci/run` sets) a missing tool fails the
//!   test naming it, so a green CI run means every check really ran;
//!   `BRICKWRIGHT_SKIP_TOOLS=0` asks for the same outside CI.
//! - Golden files are rewritten only with `BLESS=1`, never when `CI` is set,
//!   and a blessed file is still compared with the output it was written
//!   from.

#![allow(dead_code)] // Each test file uses some of these.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// Whether `CI` is set to anything but the empty string.
pub fn in_ci() -> bool {
    std::env::var_os("CI").is_some_and(|v| !v.is_empty())
}

/// The skip rule, from the values of `BRICKWRIGHT_SKIP_TOOLS` and `CI`:
/// whether a missing outside tool skips its check (rather than failing the
/// test). It does outside CI unless `BRICKWRIGHT_SKIP_TOOLS=0`; under CI,
/// never.
pub fn skip_rule(skip: Option<&str>, ci: Option<&str>) -> bool {
    ci.is_none_or(str::is_empty) && skip != Some("0")
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

/// Whether a missing tool skips its check: outside CI, unless
/// `BRICKWRIGHT_SKIP_TOOLS=0`.
pub fn may_skip_tools() -> bool {
    skip_rule(
        var("BRICKWRIGHT_SKIP_TOOLS").as_deref(),
        var("CI").as_deref(),
    )
}

/// The command that installs every outside tool the tests use.
pub const INSTALL_ALL: &str = ".ci/run tools";

/// An outside tool: its command, how to ask it for its version (to see it
/// is there), its Debian package and what the tests check with it.
pub struct OutsideTool {
    pub name: &'static str,
    pub probe: &'static str,
    pub package: &'static str,
    pub checks: &'static str,
}

/// Every outside tool the tests use; `.ci/run tools` installs them all.
pub const OUTSIDE_TOOLS: [OutsideTool; 9] = [
    OutsideTool {
        name: "xmllint",
        probe: "--version",
        package: "libxml2-utils",
        checks: "the BrickLink wanted list against its schema",
    },
    OutsideTool {
        name: "qpdf",
        probe: "--version",
        package: "qpdf",
        checks: "the booklet's PDF structure and page count",
    },
    OutsideTool {
        name: "pdftotext",
        probe: "-v",
        package: "poppler-utils",
        checks: "the booklet's text",
    },
    OutsideTool {
        name: "pdfinfo",
        probe: "-v",
        package: "poppler-utils",
        checks: "the booklet's page size",
    },
    OutsideTool {
        name: "gltf-validator",
        probe: "",
        package: "nodejs npm, then npm install gltf-validator",
        checks: "the .glb files with the Khronos glTF validator",
    },
    OutsideTool {
        name: "chromium",
        probe: "--version",
        package: "chromium",
        checks: "the step viewer page in Chromium",
    },
    OutsideTool {
        name: "firefox-esr",
        probe: "--version",
        package: "firefox-esr",
        checks: "the step viewer page in Firefox",
    },
    OutsideTool {
        name: "Xvfb",
        probe: "-help",
        package: "xvfb",
        checks: "the step viewer page in Firefox (its X server)",
    },
    OutsideTool {
        name: "import",
        probe: "-version",
        package: "imagemagick",
        checks: "the step viewer page in Firefox (its screenshot)",
    },
];

/// Whether `name` runs at all when asked `probe`.
fn answers(name: &str, probe: &str) -> bool {
    Command::new(name).arg(probe).output().is_ok()
}

/// Which of [`OUTSIDE_TOOLS`] are missing, probed once a process; the first
/// call, outside CI, prints the notice of what that skips.
fn missing_tools() -> &'static [&'static str] {
    static MISSING: OnceLock<Vec<&'static str>> = OnceLock::new();
    MISSING.get_or_init(|| {
        let missing: Vec<&'static str> = OUTSIDE_TOOLS
            .iter()
            .filter(|t| match t.name {
                "gltf-validator" => find_gltf_validator().is_none(),
                name => !answers(name, t.probe),
            })
            .map(|t| t.name)
            .collect();
        if !missing.is_empty() && may_skip_tools() && first_notice_of_this_run() {
            // Straight to the process's standard error: the test harness
            // captures `eprintln!`, and this must be seen.
            let _ = std::io::stderr()
                .lock()
                .write_all(skip_notice(&missing).as_bytes());
        }
        missing
    })
}

/// Whether no other test binary of this `cargo test` run has printed the
/// notice: the binaries of one run are children of one cargo process, so
/// the first to create a marker named by that process's id prints it.
fn first_notice_of_this_run() -> bool {
    #[cfg(unix)]
    let run = std::os::unix::process::parent_id();
    #[cfg(not(unix))]
    let run = std::process::id();
    let marker = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("outside-tools-notice-{run}"));
    // A marker that cannot be made (a read-only target) means printing
    // again, never staying silent.
    !matches!(
        std::fs::OpenOptions::new().write(true).create_new(true).open(&marker),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists
    )
}

/// The notice printed once a run when outside tools are missing.
pub fn skip_notice(missing: &[&str]) -> String {
    let mut text = String::from(
        "\nnote: outside tools are missing, so the checks that need them are skipped \
         (under CI they are required):\n",
    );
    for tool in OUTSIDE_TOOLS.iter().filter(|t| missing.contains(&t.name)) {
        text += &format!("  - {}: {} ({})\n", tool.name, tool.checks, tool.package);
    }
    text += &format!(
        "  Install them all (Debian, as root): {INSTALL_ALL}\n  \
         (set BRICKWRIGHT_SKIP_TOOLS=0 to make a missing tool fail its test)\n\n"
    );
    text
}

/// Handles a missing outside tool: returns (the caller skips; the run's
/// notice says so) when [`may_skip_tools`], panics naming what to install
/// otherwise.
pub fn missing_tool(what: &str, install: &str) {
    assert!(
        may_skip_tools(),
        "{what} is missing: {install}; under CI every outside tool is required \
         ({INSTALL_ALL} installs them all)"
    );
    if !missing_tools().contains(&what) {
        // A tool the list does not know: say so on its own.
        let _ = writeln!(
            std::io::stderr().lock(),
            "note: {what} is missing, its check is skipped: {install}"
        );
    }
}

/// Whether the outside tool `name` (from Debian's `package`) is there:
/// `false` (skip the check) only when it is missing and may be skipped (see
/// the module docs), a failure naming it otherwise.
pub fn tool(name: &str, package: &str) -> bool {
    let probe = OUTSIDE_TOOLS
        .iter()
        .find(|t| t.name == name)
        .map_or("-v", |t| t.probe);
    required_tool(name, package, probe)
}

/// Whether the outside tool `name` (from Debian's `package`) answers
/// `name version_arg` (for tools whose `-v` does something else, such as
/// Chromium); `false` only when it may be skipped, as [`tool`].
pub fn required_tool(name: &str, package: &str, version_arg: &str) -> bool {
    let known_missing = missing_tools().contains(&name);
    if !known_missing && answers(name, version_arg) {
        return true;
    }
    missing_tool(name, &format!("apt-get install {package}"));
    false
}

/// The `node_modules` directory holding the Khronos glTF validator, looked
/// up in `$GLTF_VALIDATOR_NODE_PATH`, `./node_modules`, the cache `.ci/run`
/// installs it into and `/tmp/gv/node_modules`, with `node` to run it.
fn find_gltf_validator() -> Option<PathBuf> {
    let cache = var("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| var("HOME").map(|h| Path::new(&h).join(".cache")))
        .map(|c| c.join("brickwright-gltf-validator/node_modules"));
    let found = var("GLTF_VALIDATOR_NODE_PATH")
        .map(PathBuf::from)
        .into_iter()
        .chain([Path::new(env!("CARGO_MANIFEST_DIR")).join("node_modules")])
        .chain(cache)
        .chain([PathBuf::from("/tmp/gv/node_modules")])
        .find(|dir| dir.join("gltf-validator").is_dir())?;
    answers("node", "--version").then_some(found)
}

/// The glTF validator's `node_modules` directory, or `None` when it (or
/// node) is missing and may be skipped; a failure naming it otherwise.
pub fn gltf_validator() -> Option<PathBuf> {
    if !missing_tools().contains(&"gltf-validator") {
        if let Some(found) = find_gltf_validator() {
            return Some(found);
        }
    }
    missing_tool(
        "gltf-validator",
        "node and `npm install gltf-validator@2.0.0-dev.3.10` (in ./node_modules, or set \
         GLTF_VALIDATOR_NODE_PATH to the node_modules holding it)",
    );
    None
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

/// A solid of six faces: a bottom quad, its corners counter-clockwise seen
/// from above as `(x, z, height)`, and the height its top lies at over them.
pub type Prism = ([(f64, f64, f64); 4], f64);

/// Solids of six faces ([`Prism`]) as OBJ text (y up): the generated
/// meshes of the tests.
pub fn prisms(solids: &[Prism]) -> String {
    let (mut verts, mut faces) = (String::new(), String::new());
    for (k, (bottom, top)) in solids.iter().enumerate() {
        for (x, z, h) in bottom
            .iter()
            .copied()
            .chain(bottom.map(|(x, z, _)| (x, z, *top)))
        {
            verts += &format!("v {x} {h} {z}\n");
        }
        let b = 8 * k + 1;
        for [p, q, r] in [
            [0, 1, 2],
            [0, 2, 3],
            [4, 6, 5],
            [4, 7, 6],
            [0, 4, 5],
            [0, 5, 1],
            [1, 5, 6],
            [1, 6, 2],
            [2, 6, 7],
            [2, 7, 3],
            [3, 7, 4],
            [3, 4, 0],
        ] {
            faces += &format!("f {} {} {}\n", b + p, b + q, b + r);
        }
    }
    verts + &faces
}

/// An ellipsoid `a` across, `b` deep and `c` high, as OBJ text (y up),
/// `n` segments round and `n / 2` rings: a rounded top and a rounded
/// underside, stepped both ways at once where the surface curves round.
pub fn ellipsoid(a: f64, b: f64, c: f64, n: usize) -> String {
    let rings = n / 2;
    let mut obj = String::from("o pebble\n");
    obj += &format!("v 0 {c} 0\n");
    for i in 1..rings {
        let t = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..n {
            let p = 2.0 * std::f64::consts::PI * j as f64 / n as f64;
            let (x, y, z) = (a * t.sin() * p.cos(), c * t.cos(), b * t.sin() * p.sin());
            obj += &format!("v {x:.5} {y:.5} {z:.5}\n");
        }
    }
    obj += &format!("v 0 {} 0\n", -c);
    let at = |i: usize, j: usize| 2 + (i - 1) * n + j % n;
    let last = 2 + (rings - 1) * n;
    for j in 0..n {
        obj += &format!("f 1 {} {}\n", at(1, j + 1), at(1, j));
        obj += &format!("f {last} {} {}\n", at(rings - 1, j), at(rings - 1, j + 1));
        for i in 1..rings - 1 {
            let (p, q, r, s) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
            obj += &format!("f {p} {q} {r}\nf {p} {r} {s}\n");
        }
    }
    obj
}
