//! The rules the other tests follow for outside tools and golden files
//! (see `tests/common`): when a missing tool may be skipped, and when
//! golden files are rewritten.

mod common;

use common::{bless_rule, skip_rule};

#[test]
fn a_missing_tool_is_skipped_only_when_asked_and_never_under_ci() {
    assert!(!skip_rule(None, None));
    assert!(!skip_rule(Some("0"), None));
    assert!(!skip_rule(Some("yes"), None));
    assert!(skip_rule(Some("1"), None));
    assert!(skip_rule(Some("1"), Some("")));
    // Any non-empty CI makes every tool required.
    for ci in ["true", "1", "false", "github"] {
        assert!(!skip_rule(Some("1"), Some(ci)), "CI={ci}");
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
