//! Colours: LDraw codes with their names, RGB, and BrickLink and
//! Rebrickable ids, and the palettes that paint a build.
//!
//! LDraw codes are the colours' identity everywhere in brickwright (the
//! `.ldr` carries them); the exports map them to BrickLink's ids (wanted
//! lists) and Rebrickable's (its CSV import, which uses the LDraw codes for
//! every solid colour listed here). RGB values are LDraw's `LDConfig.ldr`.
//!
//! ```
//! use brickwright::catalog::Color;
//!
//! let c = Color::parse("light bluish grey").unwrap();
//! assert_eq!(c, Color(71));
//! let spec = c.spec().unwrap();
//! assert_eq!((spec.bricklink, spec.rebrickable), (86, 71));
//! assert_eq!(Color::parse("5"), Some(Color(5)));
//! ```

use std::fmt;

use serde::Serialize;

/// An LDraw colour code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct Color(pub u16);

/// One colour of the catalog.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ColorSpec {
    /// The LDraw code.
    pub code: Color,
    /// The LDraw name, words separated by spaces.
    pub name: &'static str,
    /// sRGB, as LDraw's `LDConfig.ldr` gives it.
    pub rgb: [u8; 3],
    /// BrickLink's colour id.
    pub bricklink: u16,
    /// BrickLink's colour name.
    pub bricklink_name: &'static str,
    /// Rebrickable's colour id.
    pub rebrickable: u16,
}

macro_rules! color {
    ($code:literal, $name:literal, $rgb:literal, $bl:literal, $blname:literal) => {
        ColorSpec {
            code: Color($code),
            name: $name,
            rgb: [
                (($rgb >> 16) & 0xff) as u8,
                (($rgb >> 8) & 0xff) as u8,
                ($rgb & 0xff) as u8,
            ],
            bricklink: $bl,
            bricklink_name: $blname,
            rebrickable: $code,
        }
    };
}

/// The solid colours brickwright knows, in LDraw code order.
pub static COLORS: &[ColorSpec] = &[
    color!(0, "Black", 0x1B2A34, 11, "Black"),
    color!(1, "Blue", 0x1E5AA8, 7, "Blue"),
    color!(2, "Green", 0x00852B, 6, "Green"),
    color!(3, "Dark Turquoise", 0x069D9F, 39, "Dark Turquoise"),
    color!(4, "Red", 0xB40000, 5, "Red"),
    color!(5, "Dark Pink", 0xD3359D, 47, "Dark Pink"),
    color!(6, "Brown", 0x543324, 8, "Brown"),
    color!(7, "Light Grey", 0x8A928D, 9, "Light Gray"),
    color!(8, "Dark Grey", 0x545955, 10, "Dark Gray"),
    color!(10, "Bright Green", 0x58AB41, 36, "Bright Green"),
    color!(13, "Pink", 0xF6A9BB, 23, "Pink"),
    color!(14, "Yellow", 0xFAC80A, 3, "Yellow"),
    color!(15, "White", 0xF4F4F4, 1, "White"),
    color!(17, "Light Green", 0xADD9A8, 38, "Light Green"),
    color!(19, "Tan", 0xD7BA8C, 2, "Tan"),
    color!(22, "Purple", 0x671F81, 24, "Purple"),
    color!(25, "Orange", 0xD67923, 4, "Orange"),
    color!(26, "Magenta", 0x901F76, 71, "Magenta"),
    color!(27, "Lime", 0xA5CA18, 34, "Lime"),
    color!(28, "Dark Tan", 0x897D62, 69, "Dark Tan"),
    color!(70, "Reddish Brown", 0x5F3109, 88, "Reddish Brown"),
    color!(71, "Light Bluish Grey", 0x969696, 86, "Light Bluish Gray"),
    color!(72, "Dark Bluish Grey", 0x646464, 85, "Dark Bluish Gray"),
    color!(73, "Medium Blue", 0x7396C8, 42, "Medium Blue"),
    color!(84, "Medium Nougat", 0xAA7D55, 150, "Medium Nougat"),
    color!(92, "Nougat", 0xBB805A, 28, "Nougat"),
    color!(
        191,
        "Bright Light Orange",
        0xFCAC00,
        110,
        "Bright Light Orange"
    ),
    color!(
        226,
        "Bright Light Yellow",
        0xFFEC6C,
        103,
        "Bright Light Yellow"
    ),
    color!(272, "Dark Blue", 0x19325A, 63, "Dark Blue"),
    color!(288, "Dark Green", 0x00451A, 80, "Dark Green"),
    color!(308, "Dark Brown", 0x352100, 120, "Dark Brown"),
    color!(320, "Dark Red", 0x720012, 59, "Dark Red"),
    color!(321, "Dark Azure", 0x469BC3, 153, "Dark Azure"),
    color!(322, "Medium Azure", 0x68C3E2, 156, "Medium Azure"),
    color!(484, "Dark Orange", 0x91501C, 68, "Dark Orange"),
];

/// The colours `--palette random` draws from: common, easily bought brick
/// colours that read apart from each other.
pub const RANDOM_PALETTE: &[Color] = &[
    Color(4),
    Color(1),
    Color(14),
    Color(2),
    Color(15),
    Color(25),
    Color(71),
    Color(19),
    Color(0),
    Color(10),
];

/// The two colours `--palette layers` alternates, course by course.
pub const LAYER_PALETTE: [Color; 2] = [Color::RED, Color::WHITE];

impl Color {
    /// LDraw 4, red.
    pub const RED: Color = Color(4);
    /// LDraw 15, white.
    pub const WHITE: Color = Color(15);
    /// LDraw 71, light bluish grey.
    pub const LIGHT_BLUISH_GREY: Color = Color(71);

    /// The catalog entry, or `None` for a code the catalog does not know.
    pub fn spec(self) -> Option<&'static ColorSpec> {
        COLORS
            .binary_search_by_key(&self, |c| c.code)
            .ok()
            .map(|i| &COLORS[i])
    }

    /// A colour by LDraw code (`71`), LDraw or BrickLink name in any case,
    /// with spaces, `_` or `-` between words (`light-bluish-gray`), or
    /// `bl:ID` for a BrickLink id. `None` when the catalog has no such
    /// colour.
    pub fn parse(s: &str) -> Option<Color> {
        let s = s.trim();
        if let Ok(code) = s.parse::<u16>() {
            return Color(code).spec().map(|c| c.code);
        }
        if let Some(id) = s.strip_prefix("bl:").and_then(|t| t.parse::<u16>().ok()) {
            return COLORS.iter().find(|c| c.bricklink == id).map(|c| c.code);
        }
        let key = normalize(s);
        COLORS
            .iter()
            .find(|c| normalize(c.name) == key || normalize(c.bricklink_name) == key)
            .map(|c| c.code)
    }

    /// sRGB; a mid grey for a code the catalog does not know.
    pub fn rgb(self) -> [u8; 3] {
        self.spec().map_or([0x80, 0x80, 0x80], |c| c.rgb)
    }

    /// The LDraw name, or `colour N` for a code the catalog does not know.
    pub fn name(self) -> String {
        self.spec()
            .map_or_else(|| format!("colour {}", self.0), |c| c.name.to_string())
    }
}

impl fmt::Display for Color {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.spec() {
            Some(c) => write!(f, "{} ({})", c.name, self.0),
            None => write!(f, "colour {}", self.0),
        }
    }
}

/// Lower case, words joined by single spaces, "gray" spelled "grey".
fn normalize(s: &str) -> String {
    s.split(|c: char| c.is_whitespace() || c == '_' || c == '-')
        .filter(|w| !w.is_empty())
        .map(|w| {
            let w = w.to_ascii_lowercase();
            if w == "gray" {
                "grey".to_string()
            } else {
                w
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// How a build's pieces are coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Palette {
    /// Every piece one colour.
    Single(Color),
    /// A colour per piece drawn from [`RANDOM_PALETTE`] with the build's
    /// seed (the paper's photographs used random colours).
    Random,
    /// Alternating colours by brick course ([`LAYER_PALETTE`]), so the
    /// bond between courses reads (what [`Palette::Mesh`] falls back to for
    /// an uncoloured model).
    Layers,
    /// The model's own colours (materials, textures, vertex colours), each
    /// matched to the nearest catalog colour; for a model without colours,
    /// [`Palette::Layers`] (the default).
    #[default]
    Mesh,
}

impl Palette {
    /// `mesh`, `layers`, `random`, or one colour as [`Color::parse`] reads it.
    pub fn parse(s: &str) -> Option<Palette> {
        match s.trim().to_ascii_lowercase().as_str() {
            "layers" => Some(Palette::Layers),
            "random" => Some(Palette::Random),
            "mesh" => Some(Palette::Mesh),
            _ => Color::parse(s).map(Palette::Single),
        }
    }

    /// The palette's name as the options echo it.
    pub fn describe(&self) -> String {
        match self {
            Palette::Single(c) => format!("{}", c.0),
            Palette::Random => "random".into(),
            Palette::Layers => "layers".into(),
            Palette::Mesh => "mesh".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalog_is_sorted_and_ids_are_unique() {
        assert!(COLORS.windows(2).all(|w| w[0].code < w[1].code));
        let mut bl: Vec<u16> = COLORS.iter().map(|c| c.bricklink).collect();
        bl.sort_unstable();
        bl.dedup();
        assert_eq!(bl.len(), COLORS.len());
        for c in RANDOM_PALETTE.iter().chain(&LAYER_PALETTE) {
            assert!(c.spec().is_some(), "{c}");
        }
    }

    #[test]
    fn the_common_colours_map_as_bricklink_numbers_them() {
        // LDraw -> BrickLink, as BrickLink's colour guide lists them.
        let pairs = [
            (0, 11),
            (1, 7),
            (2, 6),
            (4, 5),
            (14, 3),
            (15, 1),
            (19, 2),
            (25, 4),
            (70, 88),
            (71, 86),
            (72, 85),
        ];
        for (ldraw, bl) in pairs {
            let spec = Color(ldraw).spec().unwrap();
            assert_eq!(spec.bricklink, bl, "{}", spec.name);
            assert_eq!(spec.rebrickable, ldraw);
        }
        assert_eq!(Color::RED.rgb(), [0xB4, 0, 0]);
    }

    #[test]
    fn names_codes_and_bricklink_ids_parse() {
        assert_eq!(Color::parse("Red"), Some(Color(4)));
        assert_eq!(Color::parse("dark_bluish_grey"), Some(Color(72)));
        assert_eq!(Color::parse("Dark Bluish Gray"), Some(Color(72)));
        assert_eq!(Color::parse("light-grey"), Some(Color(7)));
        assert_eq!(Color::parse("bl:86"), Some(Color(71)));
        assert_eq!(Color::parse("15"), Some(Color(15)));
        assert_eq!(Color::parse("9999"), None);
        assert_eq!(Color::parse("chartreuse"), None);
        assert_eq!(Palette::parse("Random"), Some(Palette::Random));
        assert_eq!(Palette::parse("tan"), Some(Palette::Single(Color(19))));
        assert_eq!(Color(9999).name(), "colour 9999");
    }
}
