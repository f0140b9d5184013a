//! Wavefront material libraries (`.mtl`), read by a parser of our own.
//!
//! Only what colours a build is kept: each `newmtl` block's name, its `Kd`
//! (diffuse colour, sRGB) and its `map_Kd` (diffuse texture file). Every
//! other statement is skipped.
//!
//! Why not `tobj`'s own MTL reader: it panics on a short colour line
//! (`Kd 1 1`, `Ks 1`, a bare `Kd`) and stops at the first line it does not
//! like, without a line number. Here a bad line is a warning naming the
//! file and line, and the rest of the library is still read. The parser
//! never panics (`tests/fuzz.rs` feeds it mangled libraries).
//!
//! ```
//! # use brickwright::mesh::mtl;
//! let lib = mtl::parse("newmtl red\nKd 1 0 0\nmap_Kd -s 1 1 1 red.png\n");
//! assert_eq!(lib.materials[0].name, "red");
//! assert_eq!(lib.materials[0].kd, Some([1.0, 0.0, 0.0]));
//! assert_eq!(lib.materials[0].map_kd.as_deref(), Some("red.png"));
//! ```

/// One `newmtl` block.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MtlMaterial {
    /// The name `usemtl` refers to it by.
    pub name: String,
    /// The diffuse colour, sRGB in `0..=1` (clamped), when given.
    pub kd: Option<[f32; 3]>,
    /// The diffuse texture's file name (the last word of `map_Kd`, after
    /// any options), when given.
    pub map_kd: Option<String>,
}

/// A parsed library: its materials in file order and what was skipped.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MtlLibrary {
    /// The materials, in the order of their `newmtl` lines.
    pub materials: Vec<MtlMaterial>,
    /// One `(line, reason)` per statement that was skipped as malformed.
    pub skipped: Vec<(usize, String)>,
}

/// Parses the text of a material library. Never fails: malformed
/// statements are listed in [`MtlLibrary::skipped`] and ignored.
pub fn parse(text: &str) -> MtlLibrary {
    let mut lib = MtlLibrary::default();
    for (i, raw) in text.lines().enumerate() {
        let no = i + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        let Some((key, rest)) = split_key(line) else {
            continue;
        };
        match key {
            "newmtl" => {
                if rest.is_empty() {
                    lib.skipped.push((no, "`newmtl` without a name".into()));
                    // Statements up to the next `newmtl` belong to no
                    // material: park them on a nameless one, dropped below.
                    lib.materials.push(MtlMaterial::default());
                } else {
                    lib.materials.push(MtlMaterial {
                        name: rest.to_string(),
                        ..MtlMaterial::default()
                    });
                }
            }
            "Kd" => match (colour(rest), lib.materials.last_mut()) {
                (Ok(c), Some(m)) => m.kd = Some(c),
                (Ok(_), None) => lib.skipped.push((no, "`Kd` before any `newmtl`".into())),
                (Err(why), _) => lib.skipped.push((no, format!("`Kd` {why}"))),
            },
            "map_Kd" => {
                // `map_Kd -opt ... file`: the file is the last word.
                match (rest.split_whitespace().last(), lib.materials.last_mut()) {
                    (Some(file), Some(m)) => m.map_kd = Some(file.to_string()),
                    (None, _) => lib.skipped.push((no, "`map_Kd` without a file".into())),
                    (Some(_), None) => lib
                        .skipped
                        .push((no, "`map_Kd` before any `newmtl`".into())),
                }
            }
            _ => {}
        }
    }
    lib.materials.retain(|m| !m.name.is_empty());
    lib
}

/// The first word of `line` and the rest, trimmed.
fn split_key(line: &str) -> Option<(&str, &str)> {
    let key = line.split_whitespace().next()?;
    Some((key, line[key.len()..].trim()))
}

/// An RGB triple (`r g b`; a single `r` is grey, as the MTL format allows).
/// Named colour spaces (`Kd spectral ...`, `Kd xyz ...`) are refused.
fn colour(rest: &str) -> Result<[f32; 3], String> {
    let words: Vec<&str> = rest.split_whitespace().collect();
    let nums: Result<Vec<f32>, _> = words.iter().map(|w| w.parse::<f32>()).collect();
    let Ok(nums) = nums else {
        return Err(format!("{rest:?} is not a list of numbers"));
    };
    if nums.iter().any(|x| !x.is_finite()) {
        return Err("has a NaN or infinite value".into());
    }
    let c = match nums.as_slice() {
        [g] => [*g; 3],
        [r, g, b] => [*r, *g, *b],
        _ => {
            return Err(format!(
                "has {} numbers; it needs 3 (r g b) or 1 (grey)",
                nums.len()
            ))
        }
    };
    Ok(c.map(|x| x.clamp(0.0, 1.0)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_and_bare_colour_lines_are_skipped_with_their_line() {
        // Each of these made tobj's MTL reader panic.
        let lib = parse("newmtl a\nKd 1 1\nKs 1\nKd\nnewmtl b\nKd 0.5\n");
        assert_eq!(lib.materials.len(), 2);
        assert_eq!(lib.materials[0].kd, None);
        assert_eq!(lib.materials[1].kd, Some([0.5; 3]));
        let lines: Vec<usize> = lib.skipped.iter().map(|s| s.0).collect();
        assert_eq!(lines, vec![2, 4], "{:?}", lib.skipped);
        assert!(lib.skipped[0].1.contains("2 numbers"), "{:?}", lib.skipped);
    }

    #[test]
    fn names_options_comments_and_orphans() {
        let lib = parse(
            "# lib\nKd 1 0 0\nnewmtl\nKd 1 1 1\nnewmtl two words # c\n\
             Kd 2 -1 nan\nKd 0.2 0.4 0.6\nmap_Kd -bm 0.5 -o 1 1 tex.png\nmap_Kd\n",
        );
        assert_eq!(lib.materials.len(), 1, "{lib:?}");
        let m = &lib.materials[0];
        assert_eq!(m.name, "two words");
        assert_eq!(m.kd, Some([0.2, 0.4, 0.6]));
        assert_eq!(m.map_kd.as_deref(), Some("tex.png"));
        let lines: Vec<usize> = lib.skipped.iter().map(|s| s.0).collect();
        assert_eq!(lines, vec![2, 3, 6, 9], "{:?}", lib.skipped);
    }

    #[test]
    fn out_of_range_colours_are_clamped() {
        let lib = parse("newmtl a\nKd 2 -1 0.5\n");
        assert_eq!(lib.materials[0].kd, Some([1.0, 0.0, 0.5]));
    }
}
