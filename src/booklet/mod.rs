//! The instruction booklet: a printable PDF made from one assembly and its
//! rendered images.
//!
//! The booklet has, in order:
//! - a cover: the title, the finished model, the piece count and the size
//!   in studs and centimetres;
//! - the bill of materials: each part and colour with its picture, count,
//!   name, colour name, and LDraw and BrickLink ids;
//! - the step pages: each step a big step number, a parts-needed callout
//!   (a picture and "2x" count for each part and colour) and the step's
//!   picture, cut to the model and printed at the size of what it shows;
//!   steps sit in rows on a grid of thirds or halves of the page, a step
//!   is never split (see [`layout`]);
//! - a last page with the exploded view.
//!
//! Every page but the cover is numbered. Text is PDF text in a standard
//! font (selectable, searchable, no font embedded), not pixels. The layout
//! comes from a [`Template`]. Pages are planned first ([`plan_steps`], from
//! what each picture shows; [`layout::plan`] is a pure function that tests
//! check), then drawn with printpdf's operation lists.
//!
//! The images come from the caller (the pipeline renders them with
//! brickwright's renderer); this module only lays them out.

pub mod layout;
pub mod template;

use std::collections::BTreeMap;
use std::io::{self, Write};

use flate2::write::ZlibEncoder;
use flate2::Compression;
use image::RgbaImage;
use printpdf::{
    BuiltinFont, Color as PdfColor, DictItem, ExternalStream, ExternalXObject, Line, LinePoint, Mm,
    Op, PaintMode, ParsedFont, PdfDocument, PdfFontHandle, PdfPage, PdfSaveOptions, Point, Pt, Px,
    Rect, Rgb as PdfRgb, TextItem, XObject, XObjectId, XObjectTransform,
};
use rayon::prelude::*;

use crate::assembly::Assembly;
use crate::catalog::{Color, PartKind};
pub use layout::StepPage;
use layout::{Ink, PixelBox, StepContent, CALLOUT_ITEM_W, CALLOUT_PAD, CALLOUT_PICTURE, MM_PER_PT};
pub use template::Template;
use template::{FontFamily, Rgb};

/// Everything a booklet shows.
pub struct BookletInput<'a> {
    /// The title on the cover and in the PDF's metadata.
    pub title: &'a str,
    /// The build, with its steps grouped as the booklet shows them.
    pub assembly: &'a Assembly,
    /// Size in studs (x, y) and height in bricks.
    pub size_studs: [f64; 3],
    /// Size in centimetres (x, y, height).
    pub size_cm: [f64; 3],
    /// The finished model.
    pub model: &'a RgbaImage,
    /// The exploded view.
    pub exploded: &'a RgbaImage,
    /// One image per step, step 1 first, on white.
    pub steps: &'a [RgbaImage],
    /// Pixels a stud's width measures in each step image: the steps of
    /// one scale (one stage of the zoom) are cut to one crop.
    pub step_scales: &'a [f32],
    /// A picture of each part in each colour the build uses.
    pub parts: &'a BTreeMap<(PartKind, Color), RgbaImage>,
    /// A short note under a step's parts, by step number (a support
    /// column's step says what it is for).
    pub step_notes: &'a BTreeMap<u32, String>,
}

/// The new parts of each step, as callout lines: part, colour, count.
pub fn step_parts(assembly: &Assembly) -> Vec<Vec<(PartKind, Color, usize)>> {
    let mut steps: Vec<BTreeMap<(PartKind, Color), usize>> =
        vec![BTreeMap::new(); assembly.step_count() as usize];
    for p in &assembly.pieces {
        *steps[p.step.0 as usize - 1]
            .entry((p.placement.part, p.color))
            .or_insert(0) += 1;
    }
    steps
        .into_iter()
        .map(|m| m.into_iter().map(|((p, c), n)| (p, c, n)).collect())
        .collect()
}

/// Lays out the step pages of `input` (see [`layout`]): what each step's
/// picture shows is measured here, in parallel.
pub fn plan_steps(input: &BookletInput<'_>, template: &Template) -> io::Result<Vec<StepPage>> {
    let parts = step_parts(input.assembly);
    let n = parts.len();
    if input.steps.len() != n || input.step_scales.len() != n {
        return Err(io::Error::other(format!(
            "the booklet has {} step images and {} step scales for {n} steps",
            input.steps.len(),
            input.step_scales.len(),
        )));
    }
    let inks: Vec<Ink> = input.steps.par_iter().map(Ink::of).collect();
    let content: Vec<StepContent<'_>> = inks
        .iter()
        .zip(input.step_scales)
        .zip(&parts)
        .enumerate()
        .map(|(i, ((ink, &stud_px), items))| StepContent {
            ink,
            stud_px,
            items: items.len(),
            note: input.step_notes.get(&(i as u32 + 1)).map(String::as_str),
        })
        .collect();
    let fonts = Fonts::new(template.fonts.family);
    Ok(layout::plan(&content, template, &|s, size, bold| {
        fonts.width(s, size, bold)
    }))
}

/// Page furniture: fonts and their metrics.
struct Fonts {
    regular: BuiltinFont,
    bold: BuiltinFont,
    metrics_regular: Option<ParsedFont>,
    metrics_bold: Option<ParsedFont>,
}

impl Fonts {
    fn new(family: FontFamily) -> Self {
        let (regular, bold) = match family {
            FontFamily::Helvetica => (BuiltinFont::Helvetica, BuiltinFont::HelveticaBold),
            FontFamily::Times => (BuiltinFont::TimesRoman, BuiltinFont::TimesBold),
            FontFamily::Courier => (BuiltinFont::Courier, BuiltinFont::CourierBold),
        };
        let metrics = |f: BuiltinFont| {
            let bytes = f.get_subset_font().bytes;
            ParsedFont::from_bytes(&bytes, 0, &mut Vec::new())
        };
        Fonts {
            regular,
            bold,
            metrics_regular: metrics(regular),
            metrics_bold: metrics(bold),
        }
    }

    /// Width of `text` at `size` points, millimetres.
    fn width(&self, text: &str, size: f32, bold: bool) -> f32 {
        let font = if bold {
            &self.metrics_bold
        } else {
            &self.metrics_regular
        };
        let em = match font {
            Some(f) => {
                let units = f32::from(f.units_per_em.max(1));
                text.chars()
                    .map(|c| {
                        f.lookup_glyph_index(c as u32)
                            .and_then(|g| f.get_glyph_width(g))
                            .map_or(0.55, |w| f32::from(w) / units)
                    })
                    .sum::<f32>()
            }
            // No metrics: the average width of a Helvetica character.
            None => text.chars().count() as f32 * 0.55,
        };
        em * size * 25.4 / 72.0
    }
}

/// One page's operations, laid out in millimetres from the top-left
/// corner and written in PDF points from the bottom-left.
struct PageOps {
    ops: Vec<Op>,
    height: f32,
}

fn pdf_rgb(c: Rgb) -> PdfColor {
    PdfColor::Rgb(PdfRgb {
        r: f32::from(c.0[0]) / 255.0,
        g: f32::from(c.0[1]) / 255.0,
        b: f32::from(c.0[2]) / 255.0,
        icc_profile: None,
    })
}

impl PageOps {
    fn new(height: f32) -> Self {
        PageOps {
            ops: Vec::new(),
            height,
        }
    }

    fn point(&self, x: f32, y: f32) -> Point {
        Point::new(Mm(x), Mm(self.height - y))
    }

    /// Text with its baseline at `y`.
    fn text(&mut self, fonts: &Fonts, x: f32, y: f32, style: (f32, bool, Rgb), s: &str) {
        let (size, bold, color) = style;
        let font = if bold { fonts.bold } else { fonts.regular };
        let pos = self.point(x, y);
        self.ops.extend([
            Op::StartTextSection,
            Op::SetFillColor {
                col: pdf_rgb(color),
            },
            Op::SetFont {
                font: PdfFontHandle::Builtin(font),
                size: Pt(size),
            },
            Op::SetTextCursor { pos },
            Op::ShowText {
                items: vec![TextItem::Text(s.to_string())],
            },
            Op::EndTextSection,
        ]);
    }

    /// A filled rectangle, top-left at (x, y).
    fn fill(&mut self, x: f32, y: f32, w: f32, h: f32, color: Rgb) {
        let ll = self.point(x, y + h);
        self.ops.extend([
            Op::SetFillColor {
                col: pdf_rgb(color),
            },
            Op::DrawRectangle {
                rectangle: Rect {
                    mode: Some(PaintMode::Fill),
                    ..Rect::from_xywh(ll.x, ll.y, Mm(w).into(), Mm(h).into())
                },
            },
        ]);
    }

    /// A thin horizontal line.
    fn rule(&mut self, x0: f32, x1: f32, y: f32, color: Rgb) {
        self.line((x0, y), (x1, y), color);
    }

    /// A thin vertical line.
    fn vrule(&mut self, x: f32, y0: f32, y1: f32, color: Rgb) {
        self.line((x, y0), (x, y1), color);
    }

    /// A thin line from `a` to `b`.
    fn line(&mut self, a: (f32, f32), b: (f32, f32), color: Rgb) {
        let (a, b) = (self.point(a.0, a.1), self.point(b.0, b.1));
        self.ops.extend([
            Op::SetOutlineColor {
                col: pdf_rgb(color),
            },
            Op::SetOutlineThickness { pt: Pt(0.5) },
            Op::DrawLine {
                line: Line {
                    points: vec![
                        LinePoint {
                            p: a,
                            bezier: false,
                        },
                        LinePoint {
                            p: b,
                            bezier: false,
                        },
                    ],
                    is_closed: false,
                },
            },
        ]);
    }

    /// An image fitted into the box (x, y, w, h), centred, aspect kept.
    fn image(&mut self, img: &Placed, x: f32, y: f32, w: f32, h: f32) {
        if img.width == 0 || img.height == 0 || w <= 0.0 || h <= 0.0 {
            return;
        }
        let scale = (w / img.width as f32).min(h / img.height as f32);
        let (iw, ih) = (img.width as f32 * scale, img.height as f32 * scale);
        self.image_in(img, (x + (w - iw) / 2.0, y + (h - ih) / 2.0, iw, ih));
    }

    /// An image printed exactly over the box (x, y, w, h).
    fn image_in(&mut self, img: &Placed, (ix, iy, iw, ih): (f32, f32, f32, f32)) {
        if img.width == 0 || img.height == 0 || iw <= 0.0 || ih <= 0.0 {
            return;
        }
        let ll = self.point(ix, iy + ih);
        // At 72 dpi one pixel is one point; scale from there.
        let pt_per_mm = 72.0 / 25.4;
        self.ops.push(Op::UseXobject {
            id: img.id.clone(),
            transform: XObjectTransform {
                translate_x: Some(ll.x),
                translate_y: Some(ll.y),
                scale_x: Some(iw * pt_per_mm / img.width as f32),
                scale_y: Some(ih * pt_per_mm / img.height as f32),
                dpi: Some(72.0),
                ..Default::default()
            },
        });
    }
}

/// An image added to the document, by id and pixel size.
#[derive(Clone)]
struct Placed {
    id: XObjectId,
    width: usize,
    height: usize,
}

/// An image to add: a part of a picture, and the colour it is flattened
/// onto.
struct ImageJob<'a> {
    img: &'a RgbaImage,
    crop: PixelBox,
    bg: Rgb,
}

/// The images of a booklet, named as they are added and compressed all
/// at once, in parallel, when the layout is done.
struct Images<'a> {
    jobs: Vec<ImageJob<'a>>,
}

impl<'a> Images<'a> {
    /// Adds `img` flattened onto white; returns its name (stable names,
    /// `Im0`, `Im1`..., keep the output the same run to run) and size.
    fn add(&mut self, img: &'a RgbaImage) -> Placed {
        self.add_on(img, Rgb([255, 255, 255]))
    }

    /// Adds `img` flattened onto `bg`: printed pages have no alpha.
    fn add_on(&mut self, img: &'a RgbaImage, bg: Rgb) -> Placed {
        let whole = PixelBox {
            x0: 0,
            y0: 0,
            x1: img.width(),
            y1: img.height(),
        };
        self.add_crop(img, whole, bg)
    }

    /// Adds the part `crop` of `img` flattened onto `bg`.
    fn add_crop(&mut self, img: &'a RgbaImage, crop: PixelBox, bg: Rgb) -> Placed {
        let id = XObjectId(format!("Im{}", self.jobs.len()));
        self.jobs.push(ImageJob { img, crop, bg });
        Placed {
            id,
            width: crop.width() as usize,
            height: crop.height() as usize,
        }
    }

    /// Flattens and deflates every image in parallel and adds them to the
    /// document as image XObjects.
    fn finish(self, doc: &mut PdfDocument) {
        let streams: Vec<Vec<u8>> = self
            .jobs
            .par_iter()
            .map(|job| {
                // The crop flattened onto the background, RGB rows.
                let (c, w) = (job.crop, job.img.width() as usize);
                let mut data = Vec::with_capacity(c.width() as usize * c.height() as usize * 3);
                for row in job
                    .img
                    .as_raw()
                    .chunks_exact(w * 4)
                    .take(c.y1 as usize)
                    .skip(c.y0 as usize)
                {
                    for p in row[c.x0 as usize * 4..c.x1 as usize * 4].chunks_exact(4) {
                        let a = u32::from(p[3]);
                        for (c, b) in p[..3].iter().zip(job.bg.0) {
                            let (c, b) = (u32::from(*c), u32::from(b));
                            data.push(((c * a + b * (255 - a) + 127) / 255) as u8);
                        }
                    }
                }
                let mut z = ZlibEncoder::new(Vec::new(), Compression::new(4));
                z.write_all(&data)
                    .expect("deflating into memory does not fail");
                z.finish().expect("deflating into memory does not fail")
            })
            .collect();
        for (i, (job, content)) in self.jobs.iter().zip(streams).enumerate() {
            let (w, h) = (job.crop.width() as usize, job.crop.height() as usize);
            let dict = BTreeMap::from([
                ("Type".to_string(), DictItem::Name(b"XObject".to_vec())),
                ("Subtype".to_string(), DictItem::Name(b"Image".to_vec())),
                ("Width".to_string(), DictItem::Int(w as i64)),
                ("Height".to_string(), DictItem::Int(h as i64)),
                (
                    "ColorSpace".to_string(),
                    DictItem::Name(b"DeviceRGB".to_vec()),
                ),
                ("BitsPerComponent".to_string(), DictItem::Int(8)),
                (
                    "Filter".to_string(),
                    DictItem::Name(b"FlateDecode".to_vec()),
                ),
            ]);
            let xobject = ExternalXObject {
                stream: ExternalStream {
                    dict,
                    content,
                    compress: false,
                },
                width: Some(Px(w)),
                height: Some(Px(h)),
                dpi: None,
            };
            doc.resources
                .xobjects
                .map
                .insert(XObjectId(format!("Im{i}")), XObject::External(xobject));
        }
    }
}

/// Writes the booklet as PDF; returns its number of pages.
pub fn write_booklet<W: Write + ?Sized>(
    w: &mut W,
    input: &BookletInput<'_>,
    template: &Template,
) -> io::Result<usize> {
    let (pdf, pages) = booklet_bytes(input, template)?;
    w.write_all(&pdf)?;
    Ok(pages)
}

fn bom_lines(assembly: &Assembly) -> Vec<(PartKind, Color, usize)> {
    let mut counts: BTreeMap<(PartKind, Color), usize> = BTreeMap::new();
    for p in &assembly.pieces {
        *counts.entry((p.placement.part, p.color)).or_insert(0) += 1;
    }
    counts.into_iter().map(|((p, c), n)| (p, c, n)).collect()
}

/// Parts-list geometry: columns of cells on a page; a cell is its part's
/// picture over [`BOM_TEXT_H`] of text.
const BOM_COLUMNS: usize = 4;
const BOM_TEXT_H: f32 = 24.0;
/// The picture's height in a cell, and the least it may shrink to so that
/// the list takes a page less.
const BOM_PICTURE_H: f32 = 22.0;
const BOM_PICTURE_MIN_H: f32 = 15.0;

/// The parts list's rows a page and its pictures' height for `kinds`
/// lines: full-size pictures, unless smaller ones (down to
/// [`BOM_PICTURE_MIN_H`]) put the list on fewer pages, as when one or two
/// parts would spill onto a page of their own.
fn bom_grid(template: &Template, kinds: usize) -> (usize, f32) {
    let (_, h) = template.page.size.mm();
    let usable = h - 2.0 * template.page.margin - 16.0 - 8.0;
    let rows = |picture: f32| ((usable / (picture + BOM_TEXT_H)).floor() as usize).max(1);
    let pages = |picture: f32| kinds.div_ceil(BOM_COLUMNS * rows(picture)).max(1);
    let full = pages(BOM_PICTURE_H);
    // The largest picture that takes fewer pages, in steps of a millimetre.
    let smaller = (BOM_PICTURE_MIN_H as u32..BOM_PICTURE_H as u32)
        .rev()
        .map(|mm| mm as f32)
        .find(|&p| pages(p) < full);
    let picture = smaller.unwrap_or(BOM_PICTURE_H);
    (rows(picture), picture)
}

fn booklet_bytes(input: &BookletInput<'_>, t: &Template) -> io::Result<(Vec<u8>, usize)> {
    let steps = step_parts(input.assembly);
    let plan = plan_steps(input, t)?;
    let fonts = Fonts::new(t.fonts.family);
    let (pw, ph) = t.page.size.mm();
    let m = t.page.margin;
    let (cw, ch) = (pw - 2.0 * m, ph - 2.0 * m);
    let text = t.colors.text;
    let ts = t.fonts.text_size;
    let mut doc = PdfDocument::new(input.title);
    doc.metadata.info.creator = format!("brickwright {}", env!("CARGO_PKG_VERSION"));
    doc.metadata.info.producer = doc.metadata.info.creator.clone();
    let mut images = Images { jobs: Vec::new() };
    let mut pages: Vec<PdfPage> = Vec::new();
    let mut number = 1usize;
    let mut finish = |mut page: PageOps, pages: &mut Vec<PdfPage>, numbered: bool| {
        if numbered {
            let label = number.to_string();
            let x = pw / 2.0 - fonts.width(&label, ts, false) / 2.0;
            page.text(&fonts, x, ph - m / 2.0, (ts, false, text), &label);
        }
        number += 1;
        pages.push(PdfPage::new(Mm(pw), Mm(ph), page.ops));
    };

    // Cover.
    let mut page = PageOps::new(ph);
    let title_size = t.fonts.title_size;
    let title_w = fonts.width(input.title, title_size, true);
    page.text(
        &fonts,
        (pw - title_w).max(0.0) / 2.0,
        m + title_size * 0.3528,
        (title_size, true, t.colors.accent),
        input.title,
    );
    let model = images.add(input.model);
    let top = m + title_size * 0.3528 + 8.0;
    page.image(&model, m, top, cw, ch - (top - m) - 30.0);
    let pieces = input.assembly.pieces.len();
    let [sx, sy, sh] = input.size_studs;
    let [cx, cy, chh] = input.size_cm;
    let lines = [
        format!("{pieces} pieces"),
        format!("{sx} x {sy} studs, {sh} bricks high"),
        format!("{cx:.1} x {cy:.1} x {chh:.1} cm"),
    ];
    let mut y = ph - m - 22.0;
    for (i, l) in lines.iter().enumerate() {
        let size = if i == 0 {
            t.fonts.heading_size
        } else {
            ts * 1.4
        };
        let wd = fonts.width(l, size, i == 0);
        page.text(&fonts, (pw - wd) / 2.0, y, (size, i == 0, text), l);
        y += size * 0.3528 + 3.0;
    }
    finish(page, &mut pages, false);

    // Parts pictures, each added once on white (parts list) and once on
    // the callout colour (step pages).
    let mut pictures: BTreeMap<(PartKind, Color), Placed> = BTreeMap::new();
    let mut callout_pictures: BTreeMap<(PartKind, Color), Placed> = BTreeMap::new();
    for (key, img) in input.parts {
        pictures.insert(*key, images.add(img));
        callout_pictures.insert(*key, images.add_on(img, t.colors.callout));
    }

    // Bill of materials.
    let bom = bom_lines(input.assembly);
    let (rows, picture_h) = bom_grid(t, bom.len());
    let cell_w = cw / BOM_COLUMNS as f32;
    for chunk in bom.chunks(BOM_COLUMNS * rows) {
        let mut page = PageOps::new(ph);
        let hs = t.fonts.heading_size;
        let head_y = m + hs * 0.3528;
        page.text(&fonts, m, head_y, (hs, true, t.colors.accent), "Parts list");
        let total = format!("{pieces} pieces, {} kinds", bom.len());
        let tw = fonts.width(&total, ts, false);
        page.text(&fonts, pw - m - tw, head_y, (ts, false, text), &total);
        page.rule(m, pw - m, head_y + 3.0, t.colors.rule);
        for (i, &(part, color, count)) in chunk.iter().enumerate() {
            let (col, row) = (i % BOM_COLUMNS, i / BOM_COLUMNS);
            let x = m + col as f32 * cell_w;
            let y = head_y + 8.0 + row as f32 * (picture_h + BOM_TEXT_H);
            if let Some(pic) = pictures.get(&(part, color)) {
                page.image(pic, x + 2.0, y, cell_w - 4.0, picture_h);
            }
            let spec = part.spec();
            let bl_color = color
                .spec()
                .map_or_else(|| "no BrickLink colour".into(), |c| c.bricklink.to_string());
            let mut ly = y + picture_h + ts * 0.3528 + 2.0;
            page.text(
                &fonts,
                x + 2.0,
                ly,
                (ts * 1.3, true, text),
                &format!("{count}x"),
            );
            ly += ts * 0.3528 * 1.3 + 1.5;
            for (l, s) in [
                spec.name.to_string(),
                color.name(),
                format!("LDraw {} / {}", spec.id, color.0),
                format!("BrickLink {} / {}", spec.bricklink, bl_color),
            ]
            .iter()
            .enumerate()
            {
                let size = if l == 0 { ts } else { ts * 0.85 };
                page.text(&fonts, x + 2.0, ly, (size, false, text), s);
                ly += size * 0.3528 + 1.2;
            }
        }
        finish(page, &mut pages, true);
    }

    // Steps.
    for plan in &plan {
        let mut page = PageOps::new(ph);
        for (r, row) in plan.rows.iter().enumerate() {
            if r > 0 {
                let y = row.area.y - layout::ROW_GAP / 2.0;
                page.rule(m, pw - m, y, t.colors.rule);
            }
            for place in row.steps.iter().skip(1) {
                let x = place.cell.x - layout::COLUMN_GAP / 2.0;
                page.vrule(x, row.area.y, row.area.bottom(), t.colors.rule);
            }
            for place in &row.steps {
                // The picture first: the header is drawn over its white
                // (the layout keeps the model's pixels out from under it).
                let img = &input.steps[place.step as usize - 1];
                let pic = images.add_crop(img, place.crop, Rgb([255, 255, 255]));
                let r = place.picture;
                page.image_in(&pic, (r.x, r.y, r.w, r.h));
                let items = &steps[place.step as usize - 1];
                draw_step(&mut page, &fonts, t, place, items, &callout_pictures);
            }
        }
        finish(page, &mut pages, true);
    }

    // Exploded view.
    let mut page = PageOps::new(ph);
    let hs = t.fonts.heading_size;
    page.text(
        &fonts,
        m,
        m + hs * 0.3528,
        (hs, true, t.colors.accent),
        "Exploded view",
    );
    let ex = images.add(input.exploded);
    let top = m + hs * 0.3528 + 6.0;
    page.image(&ex, m, top, cw, ch - (top - m) - 4.0);
    finish(page, &mut pages, true);

    images.finish(&mut doc);
    let pages_made = pages.len();
    let mut warnings = Vec::new();
    let mut pdf = doc
        .with_pages(pages)
        .save(&PdfSaveOptions::default(), &mut warnings);
    stable_ids(&mut pdf);
    Ok((pdf, pages_made))
}

/// A step's number, callout and note.
fn draw_step(
    page: &mut PageOps,
    fonts: &Fonts,
    t: &Template,
    place: &layout::StepPlace,
    items: &[(PartKind, Color, usize)],
    pictures: &BTreeMap<(PartKind, Color), Placed>,
) {
    let (ts, text) = (t.fonts.text_size, t.colors.text);
    let ns = t.fonts.step_number_size;
    let n = place.number;
    page.text(
        fonts,
        n.x,
        n.bottom(),
        (ns, true, t.colors.accent),
        &place.step.to_string(),
    );
    let c = place.callout;
    page.fill(c.x, c.y, c.w, c.h, t.colors.callout);
    let item_h = CALLOUT_PICTURE + ts * MM_PER_PT + 2.5;
    let per_row = place.per_row.max(1);
    for (j, &(part, color, count)) in items.iter().enumerate() {
        let ix = c.x + CALLOUT_PAD + (j % per_row) as f32 * CALLOUT_ITEM_W;
        let iy = c.y + CALLOUT_PAD + (j / per_row) as f32 * item_h;
        if let Some(pic) = pictures.get(&(part, color)) {
            page.image(pic, ix, iy, CALLOUT_ITEM_W - 2.0, CALLOUT_PICTURE);
        }
        page.text(
            fonts,
            ix + 1.0,
            iy + CALLOUT_PICTURE + ts * MM_PER_PT + 0.5,
            (ts, true, text),
            &format!("{count}x"),
        );
    }
    for (x, y, line) in &place.note {
        page.text(fonts, *x, *y, (ts, false, text), line);
    }
}

/// Replaces the file identifiers printpdf draws from a process-wide
/// counter (the trailer's `/ID[(...)(...)]`) with ones derived from the
/// content, same length, so the same booklet gives the same bytes however
/// many were made before it in the process.
fn stable_ids(pdf: &mut [u8]) {
    const KEY: &[u8] = b"/ID[(";
    let Some(at) = pdf.windows(KEY.len()).rposition(|w| w == KEY) else {
        return;
    };
    // FNV-1a over everything before the trailer's identifiers.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in &pdf[..at] {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    let mut i = at + KEY.len();
    for _ in 0..2 {
        let len = pdf[i..].iter().position(|&b| b == b')').unwrap_or(0);
        for b in &mut pdf[i..i + len] {
            h = h.rotate_left(5) ^ 0x9e37_79b9_7f4a_7c15;
            h = h.wrapping_mul(0x0100_0000_01b3);
            *b = b'A' + (h % 16) as u8;
        }
        // Past `)(` to the second identifier.
        i += len + 2;
        if i >= pdf.len() {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::{Placement, StepGrouping};
    use crate::geom::{Cell, Rot};

    #[test]
    fn a_parts_list_a_few_kinds_over_a_page_shrinks_its_pictures_to_fit() {
        let t = Template::default();
        let (full_rows, full) = bom_grid(&t, 1);
        assert_eq!(full, BOM_PICTURE_H);
        let per_page = BOM_COLUMNS * full_rows;
        // A page's worth keeps full-size pictures.
        assert_eq!(bom_grid(&t, per_page), (full_rows, BOM_PICTURE_H));
        // One or two kinds over: smaller pictures, one page.
        for kinds in [per_page + 1, per_page + 2] {
            let (rows, picture) = bom_grid(&t, kinds);
            assert!((BOM_PICTURE_MIN_H..BOM_PICTURE_H).contains(&picture));
            assert!(BOM_COLUMNS * rows >= kinds, "{kinds} kinds in {rows} rows");
        }
        // Whole pages' worth, as many pages either way: full-size pictures.
        assert_eq!(bom_grid(&t, 3 * per_page).1, BOM_PICTURE_H);
    }

    /// A two-course wall of 2x4s and a slope, one colour per course, and
    /// flat test pictures for it.
    fn wall() -> Assembly {
        let brick = PartKind::from_id("3001").unwrap();
        let slope = PartKind::from_id("3039").unwrap();
        let mut order = Vec::new();
        for i in 0..6 {
            order.push(Placement::new(brick, Cell::new(4 * i, 0, 0), Rot::R0));
        }
        for i in 0..5 {
            order.push(Placement::new(brick, Cell::new(4 * i + 2, 0, 1), Rot::R0));
        }
        order.push(Placement::new(slope, Cell::new(2, 0, 4), Rot::R0));
        let mut a = Assembly::from_order(&order, 12, Color::RED);
        a.paint(crate::catalog::Palette::Layers, 1);
        a.regroup(StepGrouping::Size(2));
        a
    }

    fn picture(w: u32, h: u32, rgb: [u8; 3]) -> RgbaImage {
        RgbaImage::from_fn(w, h, |x, y| {
            let edge = x < 2 || y < 2 || x + 2 >= w || y + 2 >= h;
            let c = if edge { [0, 0, 0] } else { rgb };
            image::Rgba([c[0], c[1], c[2], 255])
        })
    }

    pub(crate) fn sample_pdf(template: &Template) -> (Vec<u8>, usize) {
        let a = wall();
        let steps: Vec<RgbaImage> = (0..a.step_count())
            .map(|i| picture(160, 120, [200, 200 - 20 * i as u8, 120]))
            .collect();
        let mut parts = BTreeMap::new();
        for p in &a.pieces {
            parts
                .entry((p.placement.part, p.color))
                .or_insert_with(|| picture(64, 64, p.color.rgb()));
        }
        let (model, exploded) = (
            picture(200, 150, [90, 90, 200]),
            picture(150, 200, [90, 200, 90]),
        );
        let input = BookletInput {
            title: "wall",
            assembly: &a,
            size_studs: [24.0, 2.0, 2.5],
            size_cm: [19.2, 1.6, 2.4],
            model: &model,
            exploded: &exploded,
            steps: &steps,
            step_scales: &vec![12.0; steps.len()],
            parts: &parts,
            step_notes: &BTreeMap::from([(2, "Support column".to_string())]),
        };
        let mut pdf = Vec::new();
        let pages = write_booklet(&mut pdf, &input, template).unwrap();
        // Step 2's note is wrapped in its cell.
        let plan = plan_steps(&input, template).unwrap();
        let two = plan.iter().flat_map(StepPage::steps).find(|p| p.step == 2);
        assert!(two.is_some_and(|p| !p.note.is_empty()));
        assert_eq!(pages, 1 + 1 + plan.len() + 1);
        (pdf, pages)
    }

    #[test]
    fn the_booklet_is_a_pdf_with_the_planned_pages() {
        let (pdf, pages) = sample_pdf(&Template::default());
        assert!(pdf.starts_with(b"%PDF-"));
        // Cover, one parts-list page, 6 small steps on one page, exploded view.
        assert_eq!(pages, 1 + 1 + 1 + 1);
        // The same booklet twice in one process: the same bytes.
        let again = sample_pdf(&Template::default()).0;
        assert!(pdf == again, "booklets differ");
        let mut letter = Template::default();
        letter.page.size = template::PageSize::Letter;
        letter.steps.per_page = 1;
        assert_eq!(sample_pdf(&letter).1, 1 + 1 + 6 + 1);
    }
}
