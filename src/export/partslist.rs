//! Parts lists for buying the bricks: a BrickLink wanted list (XML) and a
//! Rebrickable parts CSV, both from one [`PartsList`].
//!
//! A parts list counts the assembly's pieces by part and colour and maps
//! each to the shops' numbering through the [catalog](crate::catalog): the
//! LDraw part `3040b` is BrickLink's and Rebrickable's `3040`; LDraw colour
//! 71 (Light Bluish Grey) is BrickLink colour 86. A colour the catalog
//! cannot map is never dropped: [`PartsList::unmapped`] names it, the
//! wanted list keeps the line without a colour (BrickLink then matches
//! any colour) and says why in its `REMARKS`, and the CSV keeps the LDraw
//! code.
//!
//! ```
//! use brickwright::assembly::{Assembly, Placement};
//! use brickwright::catalog::{Color, PartKind};
//! use brickwright::export::partslist::{write_bricklink, write_rebrickable_csv, Condition, PartsList};
//! use brickwright::geom::{Cell, Rot};
//!
//! let part = PartKind::from_id("3001").unwrap();
//! let order = [
//!     Placement::new(part, Cell::new(0, 0, 0), Rot::R0),
//!     Placement::new(part, Cell::new(2, 0, 1), Rot::R0),
//! ];
//! let list = PartsList::of(&Assembly::from_order(&order, 24, Color::RED));
//! let mut xml = Vec::new();
//! write_bricklink(&mut xml, &list, Some(Condition::New)).unwrap();
//! let xml = String::from_utf8(xml).unwrap();
//! assert!(xml.contains("<ITEMID>3001</ITEMID>") && xml.contains("<MINQTY>2</MINQTY>"));
//! let mut csv = Vec::new();
//! write_rebrickable_csv(&mut csv, &list).unwrap();
//! assert_eq!(String::from_utf8(csv).unwrap(), "Part,Color,Quantity\n3001,4,2\n");
//! ```

use std::collections::BTreeMap;
use std::io::{self, Write};

use quick_xml::events::BytesText;
use quick_xml::Writer;
use serde::Serialize;

use crate::assembly::Assembly;
use crate::catalog::{Color, PartKind};

/// One line of a parts list: a part in a colour, and how many.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PartsLine {
    /// The part.
    pub part: PartKind,
    /// Its colour.
    pub color: Color,
    /// How many.
    pub count: usize,
}

/// A parts list line as `report.json` and the terminal show it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct PartsRow {
    /// LDraw part id.
    pub part: String,
    /// Part name.
    pub name: String,
    /// LDraw colour code.
    pub color: u16,
    /// Colour name.
    pub color_name: String,
    /// How many.
    pub count: usize,
    /// BrickLink item number.
    pub bricklink: String,
    /// BrickLink colour id; `None` when the catalog has no mapping.
    pub bricklink_color: Option<u16>,
    /// Rebrickable part number.
    pub rebrickable: String,
    /// Rebrickable colour id; `None` when the catalog has no mapping.
    pub rebrickable_color: Option<u16>,
}

/// Every piece of an assembly counted by part and colour, in catalog order
/// (then colour code).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct PartsList {
    /// The lines, each part and colour once.
    pub lines: Vec<PartsLine>,
}

impl PartsList {
    /// Counts the assembly's pieces.
    pub fn of(assembly: &Assembly) -> Self {
        let mut counts: BTreeMap<(PartKind, Color), usize> = BTreeMap::new();
        for p in &assembly.pieces {
            *counts.entry((p.placement.part, p.color)).or_insert(0) += 1;
        }
        PartsList {
            lines: counts
                .into_iter()
                .map(|((part, color), count)| PartsLine { part, color, count })
                .collect(),
        }
    }

    /// Pieces in all.
    pub fn total(&self) -> usize {
        self.lines.iter().map(|l| l.count).sum()
    }

    /// Colours the catalog cannot map to BrickLink's or Rebrickable's ids,
    /// each once. (Every part of the catalog has its shop numbers.)
    pub fn unmapped(&self) -> Vec<Color> {
        let mut colors: Vec<Color> = self
            .lines
            .iter()
            .map(|l| l.color)
            .filter(|c| c.spec().is_none())
            .collect();
        colors.sort_unstable();
        colors.dedup();
        colors
    }

    /// The lines as rows for reports.
    pub fn rows(&self) -> Vec<PartsRow> {
        self.lines
            .iter()
            .map(|l| {
                let spec = l.part.spec();
                let color = l.color.spec();
                PartsRow {
                    part: spec.id.0.to_string(),
                    name: spec.name.to_string(),
                    color: l.color.0,
                    color_name: l.color.name(),
                    count: l.count,
                    bricklink: spec.bricklink.to_string(),
                    bricklink_color: color.map(|c| c.bricklink),
                    rebrickable: spec.rebrickable().to_string(),
                    rebrickable_color: color.map(|c| c.rebrickable),
                }
            })
            .collect()
    }
}

/// The condition a BrickLink wanted list asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Condition {
    /// New parts only (`N`).
    New,
    /// Used parts only (`U`).
    Used,
}

impl Condition {
    fn code(self) -> &'static str {
        match self {
            Condition::New => "N",
            Condition::Used => "U",
        }
    }
}

/// Writes a BrickLink wanted list (the XML its "Upload" page takes): one
/// `ITEM` per line of the list, with `ITEMTYPE` P, BrickLink's `ITEMID` and
/// `COLOR`, `MINQTY`, and `CONDITION` when `condition` is given (none:
/// any condition).
pub fn write_bricklink<W: Write + ?Sized>(
    w: &mut W,
    list: &PartsList,
    condition: Option<Condition>,
) -> io::Result<()> {
    let mut xml = Writer::new_with_indent(&mut *w, b' ', 2);
    xml.create_element("INVENTORY").write_inner_content(|xml| {
        for line in &list.lines {
            let spec = line.part.spec();
            xml.create_element("ITEM").write_inner_content(|xml| {
                text(xml, "ITEMTYPE", "P")?;
                text(xml, "ITEMID", spec.bricklink)?;
                match line.color.spec() {
                    Some(c) => text(xml, "COLOR", &c.bricklink.to_string())?,
                    None => text(
                        xml,
                        "REMARKS",
                        &format!(
                            "LDraw colour {} has no known BrickLink colour: choose one",
                            line.color.0
                        ),
                    )?,
                }
                text(xml, "MINQTY", &line.count.to_string())?;
                if let Some(c) = condition {
                    text(xml, "CONDITION", c.code())?;
                }
                Ok::<_, io::Error>(())
            })?;
        }
        Ok::<_, io::Error>(())
    })?;
    w.write_all(b"\n")
}

fn text<W: Write>(xml: &mut Writer<W>, name: &str, value: &str) -> io::Result<()> {
    xml.create_element(name)
        .write_text_content(BytesText::new(value))?;
    Ok(())
}

/// Writes a Rebrickable parts CSV (`Part,Color,Quantity`, colours as
/// Rebrickable's numeric ids), which Rebrickable imports as a parts list.
/// A colour with no known Rebrickable id keeps its LDraw code.
pub fn write_rebrickable_csv<W: Write + ?Sized>(w: &mut W, list: &PartsList) -> io::Result<()> {
    let mut csv = csv::Writer::from_writer(w);
    csv.write_record(["Part", "Color", "Quantity"])?;
    for line in &list.lines {
        let color = line.color.spec().map_or(line.color.0, |c| c.rebrickable);
        csv.write_record([
            line.part.spec().rebrickable().to_string(),
            color.to_string(),
            line.count.to_string(),
        ])?;
    }
    csv.flush()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Placement;
    use crate::geom::{Cell, Rot};

    fn list() -> PartsList {
        let brick = PartKind::from_id("3001").unwrap();
        let slope = PartKind::from_id("3040b").unwrap();
        let order = [
            Placement::new(brick, Cell::new(0, 0, 0), Rot::R0),
            Placement::new(brick, Cell::new(2, 0, 1), Rot::R0),
            Placement::new(slope, Cell::new(0, 0, 2), Rot::R0),
        ];
        let mut asm = Assembly::from_order(&order, 24, Color::RED);
        asm.pieces[1].color = Color(71);
        asm.pieces[2].color = Color(9999);
        PartsList::of(&asm)
    }

    #[test]
    fn counts_by_part_and_colour_in_catalog_order() {
        let l = list();
        assert_eq!(l.total(), 3);
        let keys: Vec<(&str, u16)> = l
            .lines
            .iter()
            .map(|l| (l.part.spec().id.0, l.color.0))
            .collect();
        assert_eq!(keys, [("3001", 4), ("3001", 71), ("3040b", 9999)]);
        assert_eq!(l.unmapped(), [Color(9999)]);
        let rows = l.rows();
        assert_eq!(rows[1].bricklink_color, Some(86));
        assert_eq!(rows[2].bricklink, "3040");
        assert_eq!(rows[2].bricklink_color, None);
    }

    #[test]
    fn unmapped_colours_are_kept_and_explained() {
        let mut xml = Vec::new();
        write_bricklink(&mut xml, &list(), Some(Condition::Used)).unwrap();
        let xml = String::from_utf8(xml).unwrap();
        assert_eq!(xml.matches("<ITEM>").count(), 3);
        assert_eq!(xml.matches("<CONDITION>U</CONDITION>").count(), 3);
        assert!(xml.contains("<ITEMID>3040</ITEMID>"));
        assert!(xml.contains("LDraw colour 9999 has no known BrickLink colour"));
        let mut csv = Vec::new();
        write_rebrickable_csv(&mut csv, &list()).unwrap();
        assert_eq!(
            String::from_utf8(csv).unwrap(),
            "Part,Color,Quantity\n3001,4,1\n3001,71,1\n3040,9999,1\n"
        );
    }
}
