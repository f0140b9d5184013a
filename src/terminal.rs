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

#[cfg(test)]
mod tests {
    use super::{escape_controls, escape_lines};

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
