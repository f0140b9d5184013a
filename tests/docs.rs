//! The documentation stays true to the command-line tool.
//!
//! - Every `brickwright ...` command in `README.md` and `docs/*.md` (in code
//!   blocks and in inline code, and `cargo run --release -- ...` too) names a
//!   subcommand that exists and only options that subcommand accepts, and
//!   the repository files it names exist.
//! - Every option `docs/options.md` lists under a subcommand is accepted by
//!   it, and every option the tool accepts is listed there.
//! - Every relative link in those files points at a file that exists, and
//!   at a heading of it when it names one.
//! - The README's test command is the one `.ci/run` runs.
//!
//! What the tool accepts is read from its own `--help`, so a new option
//! (or a renamed one) fails here until the manual says so.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `brickwright ARGS --help`.
fn help(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_brickwright"))
        .args(args)
        .arg("--help")
        .output()
        .expect("brickwright runs");
    assert!(out.status.success(), "brickwright {args:?} --help failed");
    String::from_utf8(out.stdout).expect("help is UTF-8")
}

/// The options a clap help text lists: `-o`, `--output`, and aliases.
fn options_in_help(help: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    for line in help.lines() {
        // Option lines: "  -o, --output <OUTPUT>" or "      --studs <STUDS>".
        let spec = if let Some(rest) = line.strip_prefix("  -") {
            match rest.split_once(", --") {
                Some((short, long)) => {
                    found.insert(format!("-{short}"));
                    format!("--{long}")
                }
                None => format!("-{rest}"),
            }
        } else if let Some(rest) = line.strip_prefix("      --") {
            format!("--{rest}")
        } else {
            String::new()
        };
        if let Some(name) = spec.split_whitespace().next() {
            found.insert(name.to_string());
        }
        for key in ["[alias: ", "[aliases: "] {
            if let Some(at) = line.find(key) {
                let list = line[at + key.len()..].trim_end_matches(']');
                for alias in list.split(", ") {
                    found.insert(alias.trim().to_string());
                }
            }
        }
    }
    found
}

/// The subcommands of the tool and the options each accepts.
fn cli() -> BTreeMap<String, BTreeSet<String>> {
    let top = help(&[]);
    let commands = top
        .split("Commands:")
        .nth(1)
        .expect("the help lists commands")
        .lines()
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect::<Vec<_>>();
    commands
        .into_iter()
        .map(|sub| {
            let options = options_in_help(&help(&[&sub]));
            (sub, options)
        })
        .collect()
}

/// One command a document shows.
#[derive(Debug, PartialEq)]
struct DocCommand {
    /// `file:line`, for messages.
    at: String,
    /// The subcommand, or `None` for `brickwright --help` and the like.
    sub: Option<String>,
    options: Vec<String>,
    /// Words naming files of this repository (`fixtures/house.obj`).
    repo_paths: Vec<String>,
}

/// Folders whose files a documented command may name.
const REPO_DIRS: [&str; 3] = ["fixtures/", "rules/", "templates/"];

/// The command in `text`, when it is a run of the tool: `brickwright ...`,
/// or `cargo run [--release] -- ...` (not `--example`, whose options are
/// the example's).
fn parse_command(text: &str, at: String) -> Option<DocCommand> {
    let words: Vec<&str> = text
        .trim()
        .trim_start_matches("$ ")
        .split_whitespace()
        .collect();
    let args = match words.as_slice() {
        ["brickwright", rest @ ..] => rest,
        ["cargo", "run", rest @ ..] => {
            let dashes = rest.iter().position(|w| *w == "--")?;
            if rest[..dashes].iter().any(|w| *w != "--release") {
                return None;
            }
            &rest[dashes + 1..]
        }
        _ => return None,
    };
    // A comment, a pipe or a redirection ends the command.
    let end = args
        .iter()
        .position(|w| w.starts_with('#') || ["|", ">", "2>", "&&", ";"].contains(w))
        .unwrap_or(args.len());
    let args = &args[..end];
    let mut options = Vec::new();
    let mut repo_paths = Vec::new();
    for word in args {
        let word = word.trim_matches(|c| c == '[' || c == ']' || c == '`');
        let name = word.split('=').next().unwrap_or(word);
        let is_option = name.starts_with('-')
            && name.len() > 1
            && name
                .trim_start_matches('-')
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic())
            && name
                .trim_start_matches('-')
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-');
        if is_option {
            options.push(name.to_string());
        } else if REPO_DIRS.iter().any(|d| word.starts_with(d)) {
            repo_paths.push(word.trim_end_matches([',', '.', ')']).to_string());
        }
    }
    let sub = args
        .first()
        .filter(|w| !w.starts_with('-'))
        .map(|w| w.to_string());
    Some(DocCommand {
        at,
        sub,
        options,
        repo_paths,
    })
}

/// The commands a Markdown file shows, in code blocks and inline code.
fn commands_in(name: &str, markdown: &str) -> Vec<DocCommand> {
    let mut found = Vec::new();
    let mut in_block = false;
    // A paragraph outside code blocks, with the line it starts on: inline
    // code may run over a line break.
    let mut paragraph = (0, String::new());
    let inline = |paragraph: &mut (usize, String), found: &mut Vec<DocCommand>| {
        let at = format!("{name}:{}", paragraph.0);
        for (k, span) in paragraph.1.split('`').enumerate() {
            if k % 2 == 1 {
                found.extend(parse_command(span, at.clone()));
            }
        }
        paragraph.1.clear();
    };
    for (i, line) in markdown.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            inline(&mut paragraph, &mut found);
            in_block = !in_block;
        } else if in_block {
            found.extend(parse_command(line, format!("{name}:{}", i + 1)));
        } else if line.trim().is_empty() {
            inline(&mut paragraph, &mut found);
        } else {
            if paragraph.1.is_empty() {
                paragraph.0 = i + 1;
            }
            paragraph.1.push_str(line);
            paragraph.1.push('\n');
        }
    }
    inline(&mut paragraph, &mut found);
    found
}

/// The documents: the front page and the manual.
fn documents() -> Vec<(String, String)> {
    let mut files = vec![root().join("README.md")];
    let mut manual: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .expect("docs/ exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    manual.sort();
    files.extend(manual);
    files
        .into_iter()
        .map(|p| {
            let name = p.strip_prefix(root()).unwrap().display().to_string();
            let text = std::fs::read_to_string(&p).unwrap();
            (name, text)
        })
        .collect()
}

#[test]
fn documented_commands_use_only_options_the_tool_has() {
    let cli = cli();
    assert!(cli.contains_key("build") && cli["build"].contains("--studs"));
    let mut problems = Vec::new();
    let mut checked = 0;
    for (name, text) in documents() {
        for cmd in commands_in(&name, &text) {
            checked += 1;
            let accepted = match &cmd.sub {
                Some(sub) => match cli.get(sub) {
                    Some(accepted) => accepted,
                    None => {
                        problems.push(format!("{}: no subcommand `{sub}`", cmd.at));
                        continue;
                    }
                },
                None => &BTreeSet::from([
                    "--help".into(),
                    "--version".into(),
                    "-h".into(),
                    "-V".into(),
                ]),
            };
            for option in &cmd.options {
                if !accepted.contains(option) {
                    let sub = cmd.sub.as_deref().unwrap_or("(none)");
                    problems.push(format!("{}: `{sub}` has no option {option}", cmd.at));
                }
            }
            for path in &cmd.repo_paths {
                if !root().join(path).exists() {
                    problems.push(format!("{}: {path} does not exist", cmd.at));
                }
            }
        }
    }
    // The front page and the manual show dozens of commands: finding few
    // means the parsing broke, not that all is well.
    assert!(checked >= 20, "only {checked} commands found in the docs");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// `docs/options.md` by subcommand: the options in the first cell of each
/// table row under a `` ## `SUB` `` heading; `None` holds the text before
/// the first such heading (options every subcommand takes).
fn options_md_sections(markdown: &str) -> BTreeMap<Option<String>, BTreeSet<String>> {
    let mut sections: BTreeMap<Option<String>, BTreeSet<String>> = BTreeMap::new();
    let mut current: Option<String> = None;
    for line in markdown.lines() {
        if let Some(heading) = line.strip_prefix("## ") {
            current = Some(heading.trim().trim_matches('`').to_string());
        }
        let entry = sections.entry(current.clone()).or_default();
        // Options every subcommand takes are named in the text before the
        // first heading; a subcommand's own, in its table.
        let cell = match (&current, line.strip_prefix('|')) {
            (None, _) => Some(line),
            (Some(_), Some(row)) => row.split(" | ").next(),
            (Some(_), None) => None,
        };
        if let Some(cell) = cell {
            for (k, span) in cell.split('`').enumerate() {
                if k % 2 == 1 {
                    for word in span.split([' ', ',']) {
                        if word.starts_with('-') && word.len() > 1 {
                            entry.insert(word.to_string());
                        }
                    }
                }
            }
        }
    }
    sections
}

#[test]
fn options_md_lists_every_option_and_only_real_ones() {
    let cli = cli();
    let text = std::fs::read_to_string(root().join("docs/options.md")).unwrap();
    let sections = options_md_sections(&text);
    let mut problems = Vec::new();
    // Options every subcommand takes (`--help`) may be documented once, in
    // the text before the first heading.
    let in_intro = sections.get(&None).cloned().unwrap_or_default();
    let common: BTreeSet<String> = cli
        .values()
        .fold(None, |acc: Option<BTreeSet<String>>, opts| {
            Some(match acc {
                None => opts.clone(),
                Some(acc) => acc.intersection(opts).cloned().collect(),
            })
        })
        .unwrap_or_default();
    for (sub, accepted) in &cli {
        let Some(listed) = sections.get(&Some(sub.clone())) else {
            problems.push(format!("docs/options.md has no \"## `{sub}`\" section"));
            continue;
        };
        for option in listed {
            if !accepted.contains(option) {
                problems.push(format!(
                    "docs/options.md lists {option} under `{sub}`, which has no such option"
                ));
            }
        }
        for option in accepted {
            let documented =
                listed.contains(option) || (common.contains(option) && in_intro.contains(option));
            if !documented {
                problems.push(format!("`{sub} {option}` is not in docs/options.md"));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// GitHub's anchor for a heading: lower case, punctuation but `-` and `_`
/// dropped, spaces to `-`.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == '-' || *c == '_' || *c == ' ')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

fn anchors(markdown: &str) -> BTreeSet<String> {
    let mut in_block = false;
    let mut found = BTreeSet::new();
    for line in markdown.lines() {
        if line.trim_start().starts_with("```") {
            in_block = !in_block;
        } else if !in_block && line.starts_with('#') {
            found.insert(anchor(line.trim_start_matches('#')));
        }
    }
    found
}

/// The targets of the Markdown links `[text](target)` in `markdown`.
fn link_targets(markdown: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut rest = markdown;
    while let Some(at) = rest.find("](") {
        rest = &rest[at + 2..];
        if let Some(end) = rest.find(')') {
            found.push(rest[..end].to_string());
        }
    }
    found
}

#[test]
fn relative_links_point_at_files_and_headings_that_exist() {
    let mut problems = Vec::new();
    let mut checked = 0;
    for (name, text) in documents() {
        let dir = root().join(&name).parent().unwrap().to_path_buf();
        for target in link_targets(&text) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            checked += 1;
            let (path, fragment) = target.split_once('#').unwrap_or((&target, ""));
            let file = if path.is_empty() {
                root().join(&name)
            } else {
                dir.join(path)
            };
            if !file.exists() {
                problems.push(format!("{name}: link to {target}: no such file"));
                continue;
            }
            if !fragment.is_empty() && file.extension().is_some_and(|e| e == "md") {
                let headings = anchors(&std::fs::read_to_string(&file).unwrap());
                if !headings.contains(fragment) {
                    problems.push(format!("{name}: link to {target}: no such heading"));
                }
            }
        }
    }
    assert!(checked >= 20, "only {checked} links found in the docs");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_readme_runs_the_tests_as_ci_does() {
    let command_lines = |text: &str| -> Vec<String> {
        text.lines()
            .map(str::trim)
            .filter(|l| l.starts_with("cargo test"))
            .map(|l| l.replace(" --locked", ""))
            .collect()
    };
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    let readme_tests = command_lines(&readme);
    let ci_tests = command_lines(&ci);
    assert_eq!(
        ci_tests.len(),
        1,
        ".ci/run runs one test command: {ci_tests:?}"
    );
    assert!(
        readme_tests.contains(&ci_tests[0]),
        "README.md gives {readme_tests:?}, .ci/run runs {:?}",
        ci_tests[0]
    );
}

#[test]
fn commands_are_parsed_from_blocks_and_inline_code() {
    let md = "Run `brickwright verify out/a.ldr --stability` or:\n\n```sh\n\
              $ cargo run --release -- build fixtures/house.obj -o out --studs=12  # note --fake\n\
              cargo run --release --example viewer_page -- a.ldr b.html\n\
              brickwright rules [--alphabet default|extended] [-o FILE]   write -> a file\n\
              ```\n";
    let found = commands_in("x.md", md);
    let want = |at: &str, sub: &str, options: &[&str], paths: &[&str]| DocCommand {
        at: at.into(),
        sub: Some(sub.into()),
        options: options.iter().map(|s| s.to_string()).collect(),
        repo_paths: paths.iter().map(|s| s.to_string()).collect(),
    };
    assert_eq!(
        found,
        [
            want("x.md:1", "verify", &["--stability"], &[]),
            want(
                "x.md:4",
                "build",
                &["-o", "--studs"],
                &["fixtures/house.obj"]
            ),
            want("x.md:6", "rules", &["--alphabet", "-o"], &[]),
        ]
    );
}

#[test]
fn help_options_are_read_with_their_aliases() {
    let text = "Options:\n  -o, --output <OUTPUT>\n          Where\n      --colors <N>\n\
                \x20         [alias: --colours]\n      --slopes  Use slopes\n  -h, --help\n\
                Examples:\n  brickwright build a.obj --fake\n";
    let got: Vec<String> = options_in_help(text).into_iter().collect();
    assert_eq!(
        got,
        [
            "--colors",
            "--colours",
            "--help",
            "--output",
            "--slopes",
            "-h",
            "-o"
        ]
    );
}

#[test]
fn anchors_follow_github() {
    assert_eq!(anchor(" `build`"), "build");
    assert_eq!(anchor("report.json"), "reportjson");
    assert_eq!(anchor("The layout's scaling"), "the-layouts-scaling");
    assert_eq!(
        anchor("Steps, pictures and the booklet"),
        "steps-pictures-and-the-booklet"
    );
    assert!(Path::new(&root()).join("docs/README.md").exists());
}
