//! The built-in rules are learned from models people built: the header of
//! `rules/default.rules` is what `brickwright learn` writes, crediting each
//! build's authors and licence, and its weights are the counts it states.
//!
//! The models are not part of the project (they keep their own licences),
//! so the file cannot be learned again here. To update it after changing
//! the learner, run `benches/learn.sh FOLDER` on the folder of the models
//! the header names and review the diff. The example corpus of
//! `rules/examples/` is still learned from here, the whole way.

use std::path::{Path, PathBuf};

use brickwright::grammar::learn::{learn, DEFAULT_UNSEEN};
use brickwright::grammar::{default_rules_text, RuleSet};

#[test]
fn the_shipped_rules_are_learned_from_people_s_builds_and_credit_them() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shipped = std::fs::read_to_string(root.join("rules/default.rules")).unwrap();
    assert_eq!(
        default_rules_text(),
        shipped,
        "the binary embeds the shipped file"
    );
    let header: Vec<&str> = shipped.lines().take_while(|l| l.starts_with('#')).collect();
    assert!(
        header[1].starts_with("# Learned by `brickwright learn` from 30 builds"),
        "{}",
        header[1]
    );
    // One credit line a build, each naming an author.
    let credits: Vec<&str> = header
        .iter()
        .skip(3)
        .take_while(|l| l.starts_with("#   "))
        .copied()
        .collect();
    assert_eq!(credits.len(), 30, "{credits:#?}");
    assert!(credits.iter().all(|l| l.contains(": by ")), "{credits:#?}");
    for who in [
        "Roland Dahl",
        "Michael Horvath",
        "Brian Sauls",
        "Tore Eriksson",
    ] {
        assert!(
            credits.iter().any(|l| l.contains(who)),
            "{who} not credited"
        );
    }
    // The weights are the counts the header states.
    let rs = RuleSet::parse(&shipped, Path::new("rules/default.rules")).unwrap();
    let total: f64 = rs.explicit_rules().iter().map(|r| r.weight).sum();
    // "# N rules, total count T, counts from ...", numbers with commas.
    let totals = header
        .iter()
        .find(|l| l.contains(" rules, total count "))
        .expect("the header states the totals");
    let number = |s: &str| -> usize { s.replace(',', "").trim().parse().unwrap() };
    let (rules, rest) = totals[2..].split_once(" rules, total count ").unwrap();
    let count = rest
        .split(',')
        .take_while(|p| !p.contains("counts"))
        .collect::<String>();
    assert_eq!(number(rules), rs.explicit_rules().len(), "{totals}");
    assert_eq!(number(&count), total as usize, "{totals}");
    assert!(rs.explicit_rules().len() > 2000);
    // People's builds teach bricks, plates, slopes and inverted slopes.
    for id in ["3001", "3010", "3024", "3039", "4286", "3660a"] {
        assert!(
            rs.explicit_rules()
                .iter()
                .any(|r| r.added.to_string() == id || r.anchor.to_string() == id),
            "no learned rule for {id}"
        );
    }
}

#[test]
fn the_example_corpus_is_learned_whole() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let corpus: PathBuf = root.join("rules/examples");
    let learned = learn(&[corpus])
        .expect("the corpus is readable")
        .with_unseen(Some(DEFAULT_UNSEEN));
    assert_eq!(learned.report.builds.len(), 20);
    assert_eq!(learned.report.learned_pieces, learned.report.pieces);
    let text = learned.to_rules_text();
    let rs = RuleSet::parse(&text, Path::new("examples.rules")).unwrap();
    assert!(rs.explicit_rules().len() > 100);
}
