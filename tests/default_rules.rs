//! The built-in rules are exactly what `brickwright learn` makes of the
//! example builds in `rules/examples/`: the default rule set's frequencies
//! come from that corpus, and nothing else.
//!
//! To update after changing the corpus or the learner, run
//! `cargo run --release -- learn rules/examples -o rules/default.rules` and
//! review the diff.

use std::path::{Path, PathBuf};

use brickwright::grammar::learn::{learn, DEFAULT_UNSEEN};
use brickwright::grammar::{default_rules_text, RuleSet};

#[test]
fn learning_the_corpus_gives_the_shipped_rules() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let corpus: PathBuf = root.join("rules/examples");
    let learned = learn(&[corpus])
        .expect("the corpus is readable")
        .with_unseen(Some(DEFAULT_UNSEEN));
    let text = learned.to_rules_text();
    let shipped = std::fs::read_to_string(root.join("rules/default.rules")).unwrap();
    assert!(
        text == shipped,
        "rules/default.rules is not what `brickwright learn rules/examples` writes; regenerate it"
    );
    assert_eq!(
        default_rules_text(),
        shipped,
        "the binary embeds the shipped file"
    );
    // The corpus teaches bricks, plates and slopes.
    let rs = RuleSet::parse(&shipped, Path::new("rules/default.rules")).unwrap();
    assert!(
        learned.report.builds.len() >= 12,
        "{} builds",
        learned.report.builds.len()
    );
    assert!(rs.explicit_rules().len() > 100);
    for id in ["3001", "3024", "3039", "3660a"] {
        assert!(
            rs.explicit_rules()
                .iter()
                .any(|r| r.added.to_string() == id || r.anchor.to_string() == id),
            "no learned rule for {id}"
        );
    }
}
