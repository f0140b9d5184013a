//! Writing an [`Assembly`] as an LDraw model.
//!
//! The output is deterministic, byte for byte: a fixed header, one type-1
//! line a piece in build order, and `0 STEP` after the last piece of each
//! step. Positions and matrix entries are whole numbers (the grid guarantees
//! it), so they print as integers with no `.0`. Lines end in LF.

use std::io::{self, Write};

use crate::assembly::Assembly;

use super::{placement_position, rot_matrix};

/// The header of a written model.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LdrMeta {
    /// The model's title, the first line (`0 <title>`).
    pub title: String,
    /// The file name LDraw tools show, e.g. `house.ldr` (`0 Name: ...`).
    pub name: String,
    /// Who or what made the model (`0 Author: ...`).
    pub author: String,
    /// Extra comment lines (`0 // ...`): tool version, input file, options,
    /// seed.
    pub notes: Vec<String>,
    /// A comment line (`0 // ...`) at the start of a step, by step number:
    /// what the step is for (a support column, say).
    pub step_notes: std::collections::BTreeMap<u32, String>,
    /// A comment line (`0 // ...`) just before a piece, by the piece's
    /// index in the assembly: the rule of the derivation that adds it
    /// (`rule 5`). LDraw tools ignore `0 //` comments.
    pub piece_notes: std::collections::BTreeMap<usize, String>,
}

/// Writes `asm` as an LDraw `.ldr` model to `w`.
///
/// The header is `0 <title>`, `0 Name: <name>`, `0 Author: <author>` and one
/// `0 // <note>` line per note; line breaks inside header texts become
/// spaces, so a header can never inject commands. No `0 !LDRAW_ORG` line is
/// written: the file is a model, not an official library part.
pub fn write_ldr(w: &mut dyn Write, asm: &Assembly, meta: &LdrMeta) -> io::Result<()> {
    header_line(w, "", &meta.title)?;
    header_line(w, "Name: ", &meta.name)?;
    header_line(w, "Author: ", &meta.author)?;
    for note in &meta.notes {
        header_line(w, "// ", note)?;
    }
    for (i, piece) in asm.pieces.iter().enumerate() {
        let starts = i == 0 || asm.pieces[i - 1].step != piece.step;
        if let Some(note) = meta.step_notes.get(&piece.step.0).filter(|_| starts) {
            header_line(w, "// ", note)?;
        }
        if let Some(note) = meta.piece_notes.get(&i) {
            header_line(w, "// ", note)?;
        }
        let p = &piece.placement;
        let [x, y, z] = placement_position(p, asm.layer_ldu);
        let m = rot_matrix(p.rot);
        write!(w, "1 {} {x} {y} {z}", piece.color.0)?;
        for row in m {
            for v in row {
                write!(w, " {v}")?;
            }
        }
        writeln!(w, " {}.dat", p.part.spec().id)?;
        let step_ends = asm.pieces.get(i + 1).is_none_or(|n| n.step != piece.step);
        if step_ends {
            writeln!(w, "0 STEP")?;
        }
    }
    Ok(())
}

/// Writes `0 <prefix><text>` with line breaks flattened and no trailing
/// blanks.
fn header_line(w: &mut dyn Write, prefix: &str, text: &str) -> io::Result<()> {
    let flat: String = text
        .chars()
        .map(|c| if c == '\n' || c == '\r' { ' ' } else { c })
        .collect();
    writeln!(w, "{}", format!("0 {prefix}{flat}").trim_end())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::{Placed, Placement, Step};
    use crate::catalog::{Color, PartKind};
    use crate::geom::{Cell, Rot};

    fn write(asm: &Assembly, meta: &LdrMeta) -> String {
        let mut out = Vec::new();
        write_ldr(&mut out, asm, meta).unwrap();
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn steps_close_after_their_last_piece() {
        let k = PartKind::from_id("3005").unwrap();
        let piece = |x, step| Placed {
            placement: Placement::new(k, Cell::new(x, 0, 0), Rot::R0),
            step: Step(step),
            color: Color(15),
        };
        let asm = Assembly {
            pieces: vec![piece(0, 1), piece(1, 1), piece(2, 2)],
            layer_ldu: 24,
        };
        let text = write(&asm, &LdrMeta::default());
        let kinds: Vec<&str> = text.lines().map(|l| l.get(..3).unwrap_or(l)).collect();
        assert_eq!(
            kinds,
            ["0", "0 N", "0 A", "1 1", "1 1", "0 S", "1 1", "0 S"]
        );
        assert!(text.ends_with("1 15 50 -24 10 1 0 0 0 1 0 0 0 1 3005.dat\n0 STEP\n"));
    }

    #[test]
    fn a_step_note_opens_its_step() {
        let brick = PartKind::from_id("3005").unwrap();
        let order = [
            Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
            Placement::new(brick, Cell::new(0, 0, 1), Rot::R0),
        ];
        let asm = Assembly::from_order(&order, 24, Color::RED);
        let meta = LdrMeta {
            step_notes: [(2, "a\nnote".to_string())].into(),
            ..LdrMeta::default()
        };
        let text = write(&asm, &meta);
        let kinds: Vec<&str> = text.lines().map(|l| l.get(..4).unwrap_or(l)).collect();
        assert_eq!(
            kinds,
            ["0", "0 Na", "0 Au", "1 4 ", "0 ST", "0 //", "1 4 ", "0 ST"]
        );
        assert!(text.contains("0 // a note\n1 4 10 -48 10"), "{text}");
    }

    #[test]
    fn a_piece_note_comes_just_before_its_piece() {
        let brick = PartKind::from_id("3005").unwrap();
        let order = [
            Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
            Placement::new(brick, Cell::new(0, 0, 1), Rot::R0),
        ];
        let asm = Assembly::from_order(&order, 24, Color::RED);
        let meta = LdrMeta {
            piece_notes: [(0, "rule 0".to_string()), (1, "rule 7".to_string())].into(),
            ..LdrMeta::default()
        };
        let text = write(&asm, &meta);
        assert!(text.contains("0 // rule 0\n1 4 10 -24 10"), "{text}");
        assert!(
            text.contains("0 STEP\n0 // rule 7\n1 4 10 -48 10"),
            "{text}"
        );
    }

    #[test]
    fn header_texts_cannot_inject_lines() {
        let meta = LdrMeta {
            title: "evil\n1 4 0 0 0 1 0 0 0 1 0 0 0 1 3001.dat".into(),
            name: "x.ldr".into(),
            author: "me\r\n".into(),
            notes: vec!["a\nb".into()],
            step_notes: Default::default(),
            piece_notes: Default::default(),
        };
        let text = write(&Assembly::from_order(&[], 24, Color::RED), &meta);
        assert_eq!(
            text,
            "0 evil 1 4 0 0 0 1 0 0 0 1 0 0 0 1 3001.dat\n0 Name: x.ldr\n0 Author: me\n0 // a b\n"
        );
    }
}
