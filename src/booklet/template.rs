//! The booklet's layout template: page size, margins, steps per page,
//! fonts and colours, read from a TOML file.
//!
//! The shipped `templates/default.toml` is built in and documents every
//! key; a user copies it and passes the copy with `--template FILE`. Keys
//! left out keep their defaults; unknown keys and bad values are errors
//! naming the file and line.
//!
//! ```
//! use brickwright::booklet::template::{PageSize, Template};
//!
//! let t = Template::parse("[page]\nsize = \"Letter\"\n", "mine.toml").unwrap();
//! assert_eq!(t.page.size, PageSize::Letter);
//! assert_eq!(t.steps.columns, 3); // the default
//! let err = Template::parse("[page]\nsize = \"A5\"\n", "mine.toml").unwrap_err();
//! assert!(err.to_string().starts_with("mine.toml:2: "), "{err}");
//! ```

use std::path::Path;

use serde::Deserialize;
use thiserror::Error;

/// The template `templates/default.toml`, built in.
pub const DEFAULT_TEMPLATE: &str = include_str!("../../templates/default.toml");

/// A template that cannot be used.
#[derive(Debug, Error)]
pub enum TemplateError {
    /// The file cannot be read.
    #[error("{file}: cannot read: {reason}")]
    Io {
        /// The template file.
        file: String,
        /// Why.
        reason: std::io::Error,
    },
    /// A syntax error, an unknown key or a bad value.
    #[error("{file}:{line}: {message}")]
    Invalid {
        /// The template file.
        file: String,
        /// 1-based line of the fault.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// Paper sizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum PageSize {
    /// 210 x 297 mm.
    A4,
    /// 8.5 x 11 inches.
    Letter,
}

impl PageSize {
    /// Width and height in millimetres.
    pub fn mm(self) -> (f32, f32) {
        match self {
            PageSize::A4 => (210.0, 297.0),
            PageSize::Letter => (215.9, 279.4),
        }
    }
}

/// The standard PDF font families (every PDF reader has them, so the
/// booklet embeds no font and its text stays selectable).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum FontFamily {
    /// Helvetica (sans serif).
    Helvetica,
    /// Times (serif).
    Times,
    /// Courier (monospaced).
    Courier,
}

/// An sRGB colour written `"#RRGGBB"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rgb(pub [u8; 3]);

impl<'de> Deserialize<'de> for Rgb {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        let hex = s
            .strip_prefix('#')
            .filter(|h| h.len() == 6 && h.chars().all(|c| c.is_ascii_hexdigit()))
            .ok_or_else(|| {
                serde::de::Error::custom(format!("`{s}` is not a colour like \"#B40000\""))
            })?;
        let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).unwrap_or(0);
        Ok(Rgb([byte(0), byte(2), byte(4)]))
    }
}

/// `[page]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PageSection {
    /// Paper size.
    pub size: PageSize,
    /// Blank border on every side, millimetres.
    pub margin: f32,
}

/// `[steps]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepsSection {
    /// At most this many steps on a page: 1 to 12.
    pub per_page: u32,
    /// At most this many steps side by side: 1, 2 or 3.
    pub columns: u32,
}

/// `[fonts]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FontsSection {
    /// The font family of all text.
    pub family: FontFamily,
    /// The cover title, points.
    pub title_size: f32,
    /// Page headings, points.
    pub heading_size: f32,
    /// Step numbers, points.
    pub step_number_size: f32,
    /// Names, counts and page numbers, points.
    pub text_size: f32,
}

/// `[colors]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColorsSection {
    /// Body text.
    pub text: Rgb,
    /// Step numbers and headings.
    pub accent: Rgb,
    /// The parts-needed box.
    pub callout: Rgb,
    /// Thin lines and frames.
    pub rule: Rgb,
}

/// A booklet layout.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Template {
    /// `[page]`.
    pub page: PageSection,
    /// `[steps]`.
    pub steps: StepsSection,
    /// `[fonts]`.
    pub fonts: FontsSection,
    /// `[colors]`.
    pub colors: ColorsSection,
}

impl Default for Template {
    /// The built-in `templates/default.toml`.
    fn default() -> Self {
        Template::parse(DEFAULT_TEMPLATE, "templates/default.toml")
            .expect("the built-in template is valid (tested)")
    }
}

impl Template {
    /// Reads a template file.
    pub fn load(path: &Path) -> Result<Template, TemplateError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|reason| TemplateError::Io {
            file: file.clone(),
            reason,
        })?;
        Template::parse(&text, &file)
    }

    /// Parses template text; `file` names it in errors. Keys left out take
    /// the built-in template's values.
    pub fn parse(text: &str, file: &str) -> Result<Template, TemplateError> {
        let invalid = |line: usize, message: String| TemplateError::Invalid {
            file: file.to_string(),
            line,
            message,
        };
        let user: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            let line = e.span().map_or(1, |s| line_of(text, s.start));
            let message: Vec<&str> = e.message().lines().map(str::trim).collect();
            invalid(line, message.join("; "))
        })?;
        let mut merged: toml::Table = DEFAULT_TEMPLATE
            .parse()
            .expect("the built-in template is valid TOML");
        for (section, value) in &user {
            let line = line_of_key(text, section);
            let Some(base) = merged.get_mut(section).and_then(|v| v.as_table_mut()) else {
                return Err(invalid(
                    line,
                    format!("unknown section `{section}` (known: page, steps, fonts, colors)"),
                ));
            };
            let Some(table) = value.as_table() else {
                return Err(invalid(line, format!("`{section}` must be a [section]")));
            };
            for (key, v) in table {
                if !base.contains_key(key) {
                    let known: Vec<&str> = base.keys().map(String::as_str).collect();
                    return Err(invalid(
                        line_of_key(text, key),
                        format!(
                            "unknown key `{key}` in [{section}] (known: {})",
                            known.join(", ")
                        ),
                    ));
                }
                base.insert(key.clone(), v.clone());
            }
        }
        let template: Template = toml::Value::Table(merged).try_into().map_err(|e| {
            // The merged table has no spans: the message ends with the key's
            // path (`in `page.size``); point at that key's line.
            let full = format!("{e}");
            let mut lines = full.lines().map(str::trim).filter(|l| !l.is_empty());
            let message = lines.next().unwrap_or("invalid value").to_string();
            let key = lines
                .find_map(|l| l.strip_prefix("in `"))
                .and_then(|path| path.trim_end_matches('`').rsplit('.').next())
                .unwrap_or("");
            let line = if key.is_empty() {
                1
            } else {
                line_of_key(text, key)
            };
            let message = if key.is_empty() {
                message
            } else {
                format!("{key}: {message}")
            };
            invalid(line, message)
        })?;
        template
            .check()
            .map_err(|(key, message)| invalid(line_of_key(text, key), message))?;
        Ok(template)
    }

    /// Values the types allow but a page cannot hold.
    fn check(&self) -> Result<(), (&'static str, String)> {
        let (w, h) = self.page.size.mm();
        if !(0.0..=w.min(h) / 4.0).contains(&self.page.margin) {
            return Err((
                "margin",
                format!(
                    "margin must be between 0 and {} mm, not {}",
                    w.min(h) / 4.0,
                    self.page.margin
                ),
            ));
        }
        if !(1..=12).contains(&self.steps.per_page) {
            return Err((
                "per_page",
                format!("per_page must be 1 to 12, not {}", self.steps.per_page),
            ));
        }
        if !(1..=3).contains(&self.steps.columns) {
            return Err((
                "columns",
                format!("columns must be 1, 2 or 3, not {}", self.steps.columns),
            ));
        }
        let f = &self.fonts;
        for (key, size) in [
            ("title_size", f.title_size),
            ("heading_size", f.heading_size),
            ("step_number_size", f.step_number_size),
            ("text_size", f.text_size),
        ] {
            if !(4.0..=96.0).contains(&size) {
                return Err((key, format!("{key} must be 4 to 96 points, not {size}")));
            }
        }
        Ok(())
    }
}

/// The 1-based line of byte offset `at`.
fn line_of(text: &str, at: usize) -> usize {
    text[..at.min(text.len())].matches('\n').count() + 1
}

/// The line where `key` is set or `[key]` opens, or 1.
fn line_of_key(text: &str, key: &str) -> usize {
    text.lines()
        .position(|l| {
            let l = l.trim_start();
            l.strip_prefix(key)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
                || l.trim_start_matches('[').trim_end().trim_end_matches(']') == key
        })
        .map_or(1, |i| i + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_template_is_valid() {
        let t = Template::default();
        assert_eq!(t.page.size, PageSize::A4);
        assert_eq!(t.fonts.family, FontFamily::Helvetica);
        assert_eq!(t.colors.accent, Rgb([0xB4, 0, 0]));
    }

    #[test]
    fn errors_name_the_file_and_line() {
        let cases = [
            ("[page]\nsize = \"A5\"\n", 2, "A5"),
            ("[page]\nmargin = 200.0\n", 2, "margin"),
            ("[steps]\nper_page = 13\n", 2, "per_page"),
            ("[steps]\n\ncolumns = 4\n", 3, "columns"),
            ("[fonts]\n\ntext_size = 1.0\n", 3, "text_size"),
            ("[colors]\naccent = \"red\"\n", 2, "#B40000"),
            (
                "[page]\nsize = \"A4\"\npaper = 1\n",
                3,
                "unknown key `paper`",
            ),
            ("[cover]\ntitle = 1\n", 1, "unknown section `cover`"),
            ("[page\nsize = 1\n", 1, ""),
            ("[page]\nmargin = \"wide\"\n", 2, ""),
        ];
        for (text, line, needle) in cases {
            let err = Template::parse(text, "t.toml").unwrap_err().to_string();
            assert!(
                err.starts_with(&format!("t.toml:{line}: ")) && err.contains(needle),
                "{text:?}: {err}"
            );
            assert_eq!(err.lines().count(), 1, "{err}");
        }
        let err = Template::load(Path::new("/no/such/template.toml")).unwrap_err();
        assert!(err
            .to_string()
            .starts_with("/no/such/template.toml: cannot read"));
    }
}
