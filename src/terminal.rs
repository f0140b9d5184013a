//! Text bound for a terminal: file names, part names and other pieces of
//! untrusted input are shown with their control characters escaped, so a
//! hostile file cannot move the cursor, recolour the terminal or hide a
//! line of a message.
//!
//! ```
//! use brickwright::terminal::escape_controls;
//!
//! assert_eq!(escape_controls("3001\u{1b}[2J.dat"), "3001\\u{1b}[2J.dat");
//! assert_eq!(escape_controls("plain text"), "plain text");
//! ```

use std::borrow::Cow;

/// `s` with every control character (C0, DEL, C1; tabs and newlines too,
/// since a message is one line) written as a `\u{..}` escape. Text with
/// none is returned as it is.
pub fn escape_controls(s: &str) -> Cow<'_, str> {
    if !s.chars().any(char::is_control) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        if c.is_control() {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// [`escape_controls`] for text of several lines: each line escaped, the
/// line breaks kept.
pub fn escape_lines(s: &str) -> String {
    let mut out: Vec<Cow<'_, str>> = s.split('\n').map(escape_controls).collect();
    if out.last().is_some_and(|l| l.is_empty()) {
        out.pop();
        return out.join("\n") + "\n";
    }
    out.join("\n")
}
/// A message of one or more lines (a warning, an error chain) for a line
/// that starts with a label such as `error: `: every line escaped as in
/// [`escape_controls`], its real line breaks kept, and each line after the
/// first indented by two spaces, so no part of the message (not even a
/// hostile name holding a line break) can pass for a line of its own.
/// Trailing line breaks are dropped.
///
/// ```
/// use brickwright::terminal::escape_message;
///
/// assert_eq!(escape_message("failed:\n 2 overlaps\n"), "failed:\n   2 overlaps");
/// ```
pub fn escape_message(s: &str) -> String {
    s.trim_end_matches(['\n', '\r'])
        .split('\n')
        .map(|l| escape_controls(l.strip_suffix('\r').unwrap_or(l)))
        .collect::<Vec<_>>()
        .join("\n  ")
}

#[cfg(test)]
mod tests {
    use super::{escape_controls, escape_lines, escape_message};

    #[test]
    fn messages_keep_real_line_breaks_indented() {
        // Was one line with a literal `\u{a}` (issue 30, finding 13).
        let shown = escape_message("internal error (3 problems:\n a\r\n b\u{1b}[2J)\n\n");
        assert_eq!(shown, "internal error (3 problems:\n   a\n   b\\u{1b}[2J)");
        assert!(!shown.contains("\\u{a}"), "{shown}");
        assert_eq!(escape_message("one line"), "one line");
    }

    #[test]
    fn lines_keep_their_breaks() {
        assert_eq!(escape_lines("a\u{1b}\nb\n"), "a\\u{1b}\nb\n");
        assert_eq!(escape_lines("a\nb"), "a\nb");
    }

    #[test]
    fn every_control_character_is_escaped() {
        let hostile = "a\u{1b}]0;title\u{7}b\u{9b}31mc\rd\ne\u{7f}";
        let shown = escape_controls(hostile);
        assert!(!shown.chars().any(char::is_control), "{shown}");
        assert_eq!(
            shown,
            "a\\u{1b}]0;title\\u{7}b\\u{9b}31mc\\u{d}d\\u{a}e\\u{7f}"
        );
        assert_eq!(escape_controls("brique ½ ü"), "brique ½ ü");
    }
}
