//! Which solid colours each part is produced in.
//!
//! A parts list that orders a 2 x 8 brick in Medium Nougat orders nothing:
//! the part was never made in that colour. The data is `part_colors.txt`
//! beside this file (its header names its source), one line a part; it is
//! read once into a colour mask a part, so that the layout can ask
//! [`PartKind::exists_in`] for every candidate it weighs.
//!
//! ```
//! use brickwright::catalog::{Color, PartKind};
//!
//! let brick_2x8 = PartKind::from_id("3007").unwrap();
//! assert!(brick_2x8.exists_in(Color::RED));
//! assert!(!brick_2x8.exists_in(Color(84))); // Medium Nougat
//! assert_eq!(brick_2x8.nearest_color(Color::RED, None), Color::RED);
//! ```

use std::sync::OnceLock;

use super::color::{Color, COLORS};
use super::{lab, PartKind, PARTS};

/// The data file, compiled in.
const DATA: &str = include_str!("part_colors.txt");

/// A set of catalog colours, bit `i` for `COLORS[i]`.
type Mask = u64;

const _: () = assert!(COLORS.len() <= Mask::BITS as usize);

/// The bit of `c` in a [`Mask`]; 0 for a code the catalog does not know.
fn bit(c: Color) -> Mask {
    COLORS
        .binary_search_by_key(&c, |s| s.code)
        .map_or(0, |i| 1 << i)
}

/// A part's line of [`DATA`] that does not parse: a bug in the data file,
/// which a unit test keeps out.
#[derive(Debug, PartialEq)]
struct DataError(String);

/// Parses [`DATA`]: the colour mask of every part of [`PARTS`], in order.
fn parse(data: &str) -> Result<Vec<Mask>, DataError> {
    let mut masks: Vec<Option<Mask>> = vec![None; PARTS.len()];
    for (n, line) in data.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        let mut words = line.split_whitespace();
        let Some(id) = words.next() else {
            continue;
        };
        let at = |what: String| DataError(format!("part_colors.txt line {}: {what}", n + 1));
        let kind = PartKind::from_id(id).ok_or_else(|| at(format!("unknown part {id}")))?;
        let mut mask = 0;
        for w in words {
            let b = w
                .parse::<u16>()
                .ok()
                .map(|code| bit(Color(code)))
                .filter(|&b| b != 0)
                .ok_or_else(|| at(format!("unknown colour {w}")))?;
            mask |= b;
        }
        let slot = &mut masks[kind.0 as usize];
        if slot.is_some() {
            return Err(at(format!("part {id} listed twice")));
        }
        *slot = Some(mask);
    }
    masks
        .into_iter()
        .zip(PARTS)
        .map(|(m, p)| m.ok_or_else(|| DataError(format!("part {} has no colours", p.id))))
        .collect()
}

/// Every part's colour mask, parsed once.
fn masks() -> &'static [Mask] {
    static MASKS: OnceLock<Vec<Mask>> = OnceLock::new();
    MASKS.get_or_init(|| match parse(DATA) {
        Ok(m) => m,
        // The data is compiled in and checked by the tests below.
        Err(e) => panic!("{}", e.0),
    })
}

impl PartKind {
    /// Whether the part is produced in `color`.
    pub fn exists_in(self, color: Color) -> bool {
        masks()[self.0 as usize] & bit(color) != 0
    }

    /// The colours the part is produced in, in LDraw code order.
    pub fn colors(self) -> impl Iterator<Item = Color> {
        let m = masks()[self.0 as usize];
        COLORS
            .iter()
            .enumerate()
            .filter(move |&(i, _)| m & (1 << i) != 0)
            .map(|(_, c)| c.code)
    }

    /// `want` if the part is made in it, else the colour nearest to it
    /// (CIEDE2000) that the part is made in, among `among` when some of
    /// those are (a build limited to a few colours stays within them).
    pub fn nearest_color(self, want: Color, among: Option<&[Color]>) -> Color {
        if self.exists_in(want) {
            return want;
        }
        let limited: Vec<Color> = among
            .unwrap_or(&[])
            .iter()
            .copied()
            .filter(|&c| self.exists_in(c))
            .collect();
        let choices = if limited.is_empty() {
            self.colors().collect()
        } else {
            limited
        };
        lab::nearest_in(want.rgb(), &choices)
    }
}

/// Whether some part of the catalog is made in `color`: the colours a
/// model's voxels may take.
pub fn buildable(color: Color) -> bool {
    masks().iter().any(|m| m & bit(color) != 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_data_file_names_every_part_once_with_known_colours() {
        let m = parse(DATA).unwrap();
        assert_eq!(m.len(), PARTS.len());
        assert!(m.iter().all(|&x| x.count_ones() >= 10));
    }

    #[test]
    fn bad_lines_are_named() {
        let e = parse("3005 0 4\n3005 15\n").unwrap_err();
        assert_eq!(e.0, "part_colors.txt line 2: part 3005 listed twice");
        let e = parse("3005 0 9999\n").unwrap_err();
        assert!(e.0.contains("line 1: unknown colour 9999"), "{}", e.0);
        assert!(parse("3005 0 4\n")
            .unwrap_err()
            .0
            .contains("has no colours"));
    }

    #[test]
    fn every_part_comes_in_the_basic_colours() {
        // Black, red, yellow, white, light and dark bluish grey: every
        // brick, plate and slope of the alphabet is sold in these.
        for k in PartKind::all() {
            for c in [0, 4, 14, 15, 71, 72] {
                assert!(k.exists_in(Color(c)), "{k} in {c}");
            }
        }
    }

    #[test]
    fn a_missing_colour_falls_to_the_nearest_made() {
        let k = PartKind::from_id("3007").unwrap();
        // No 2 x 8 brick was made in Dark Pink: the nearest colour it was
        // made in stands in.
        let c = k.nearest_color(Color(5), None);
        assert!(k.exists_in(c) && c != Color(5));
        // Within a limited palette when the part is made in one of it.
        assert_eq!(
            k.nearest_color(Color(5), Some(&[Color::WHITE, Color(84)])),
            Color::WHITE
        );
        assert!(buildable(Color::RED));
    }
}
