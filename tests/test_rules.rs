//! The rules the other tests follow for outside tools and golden files
//! (see `tests/common`): when a missing tool may be skipped, and when
//! golden files are rewritten.

use crate::common;

use common::{bless_rule, skip_rule};

#[test]
fn a_missing_tool_is_skipped_outside_ci_unless_required() {
    // A fresh machine: nothing set, the checks without their tool skip.
    assert!(skip_rule(None, None));
    assert!(skip_rule(None, Some("")));
    assert!(skip_rule(Some("1"), None));
    assert!(skip_rule(Some("yes"), None));
    // BRICKWRIGHT_SKIP_TOOLS=0 makes every tool required outside CI too.
    assert!(!skip_rule(Some("0"), None));
    assert!(!skip_rule(Some("0"), Some("")));
    // Any non-empty CI makes every tool required, whatever else is set.
    for ci in ["true", "1", "false", "github"] {
        for skip in [None, Some("1"), Some("0")] {
            assert!(
                !skip_rule(skip, Some(ci)),
                "CI={ci} BRICKWRIGHT_SKIP_TOOLS={skip:?}"
            );
        }
    }
}

#[test]
fn the_skip_notice_names_each_check_and_the_install_command() {
    let notice = common::skip_notice(&["qpdf", "gltf-validator"]);
    assert!(
        notice.contains("qpdf: the booklet's PDF structure"),
        "{notice}"
    );
    assert!(
        notice.contains("gltf-validator: the .glb files"),
        "{notice}"
    );
    assert!(!notice.contains("chromium"), "{notice}");
    assert!(notice.contains(common::INSTALL_ALL), "{notice}");
}

#[test]
fn every_outside_tool_is_installed_by_ci() {
    // `.ci/run tools` must install what the notice says it does.
    let ci = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/.ci/run")).unwrap();
    assert!(
        ci.contains("\"${1:-}\" = tools"),
        ".ci/run has no `tools` mode"
    );
    let apt: Vec<Vec<&str>> = ci
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("need_apt "))
        .map(|l| l.split_whitespace().collect())
        .collect();
    for tool in &common::OUTSIDE_TOOLS {
        let installed = match tool.name {
            "gltf-validator" => ci.contains("npm install") && ci.contains("gltf-validator@"),
            _ => apt.iter().any(|words| words[2..].contains(&tool.package)),
        };
        assert!(
            installed,
            ".ci/run does not install {} ({})",
            tool.name, tool.package
        );
    }
}

#[test]
fn goldens_are_blessed_only_by_bless_1_and_never_under_ci() {
    assert_eq!(bless_rule(None, None), Ok(false));
    assert_eq!(bless_rule(Some("0"), None), Ok(false));
    assert_eq!(bless_rule(Some(""), None), Ok(false));
    assert_eq!(bless_rule(Some("1"), None), Ok(true));
    assert_eq!(bless_rule(Some("1"), Some("")), Ok(true));
    for ci in ["true", "1", "false"] {
        assert!(bless_rule(Some("1"), Some(ci)).is_err(), "CI={ci}");
        assert!(bless_rule(Some("0"), Some(ci)).is_err(), "CI={ci}");
        assert_eq!(bless_rule(None, Some(ci)), Ok(false));
    }
}
