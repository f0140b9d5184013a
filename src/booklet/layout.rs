//! Step pages: where each step's number, parts callout and picture go.
//!
//! A step's picture is printed at the size of what it shows, not at a
//! fixed share of the page:
//!
//! - it is cut to the model: the steps drawn at one scale (one stage of
//!   the renderer's zoom) share one crop, the box of everything any of
//!   them draws, so within a stage the model stands still from picture to
//!   picture and only the new pieces change, and no picture carries the
//!   white its frame had around the model;
//! - it is printed at [`STUD_MM`] a stud, at least [`MIN_PICTURE_W`] wide
//!   and at most half the page's width (the whole width when the template
//!   puts one step a row) and a step at most [`MAX_STEP_H`] of the page's height: a
//!   stage that shows the first few bricks gets a small picture, the
//!   finished model a big one;
//! - the step number and the parts callout (one picture and count for each
//!   part and colour) sit at the top left of the step's cell, and the
//!   picture moves up beside or under them as far as its own white lets
//!   it: a pixel of the model never runs under them.
//!
//! Cells sit in rows on a grid of thirds or halves of the page's width. A
//! row holds as many steps as the widest of them allows (three small
//! pictures, two of half width, or one whose callout needs the whole
//! width), filled in step order; rows are stacked down the page, and a
//! step is never split.
//!
//! [`plan`] is a pure function of what each step shows ([`Ink`]), its
//! scale and its callout, so tests check the layout without a PDF.

use image::RgbaImage;

use super::template::Template;

/// Print size of a stud's width in a step picture, millimetres (before
/// the limits on a picture's size).
pub const STUD_MM: f32 = 2.8;
/// The narrowest a step picture is printed, millimetres.
pub const MIN_PICTURE_W: f32 = 45.0;
/// The tallest a step, header and picture, is printed, as a share of the
/// page's content height (three rows of steps fit a page): a stage's
/// pictures are no taller than this less the tallest header of its steps
/// (but at least [`MIN_PICTURE_H`] of the page).
pub const MAX_STEP_H: f32 = 0.32;
/// The least height the rule of [`MAX_STEP_H`] leaves a stage's pictures,
/// as a share of the page's content height.
pub const MIN_PICTURE_H: f32 = 0.16;
/// A pixel is ink (part of the model, not the white page) when, printed
/// on white, one of its channels is darker than this.
pub const INK_LEVEL: u8 = 250;

/// Space between two cells of a row, millimetres; a thin rule runs in
/// the middle.
pub const COLUMN_GAP: f32 = 6.0;
/// Space between two rows, millimetres; a thin rule runs in the middle.
pub const ROW_GAP: f32 = 6.0;
/// White kept between the step number or callout and the model's pixels,
/// millimetres.
const HEADER_GAP: f32 = 2.0;
/// White kept around the model inside a picture's crop, pixels.
const CROP_PAD: u32 = 4;

/// Width of a callout item (picture and count), millimetres.
pub const CALLOUT_ITEM_W: f32 = 15.0;
/// Padding inside the callout box, millimetres.
pub const CALLOUT_PAD: f32 = 2.0;
/// Height of a callout picture, millimetres.
pub const CALLOUT_PICTURE: f32 = 11.0;
/// Space between the step number and its callout, millimetres.
const NUMBER_GAP: f32 = 3.0;

/// Millimetres a point measures.
pub const MM_PER_PT: f32 = 25.4 / 72.0;

/// A box of pixels: columns `x0..x1`, rows `y0..y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelBox {
    /// Left column (inclusive).
    pub x0: u32,
    /// Top row (inclusive).
    pub y0: u32,
    /// Right column (exclusive).
    pub x1: u32,
    /// Bottom row (exclusive).
    pub y1: u32,
}

impl PixelBox {
    /// Columns across.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    /// Rows down.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    fn union(self, o: PixelBox) -> PixelBox {
        PixelBox {
            x0: self.x0.min(o.x0),
            y0: self.y0.min(o.y0),
            x1: self.x1.max(o.x1),
            y1: self.y1.max(o.y1),
        }
    }

    /// Grown by `by` on every side, kept inside a `w` x `h` image.
    fn grown(self, by: u32, (w, h): (u32, u32)) -> PixelBox {
        PixelBox {
            x0: self.x0.saturating_sub(by),
            y0: self.y0.saturating_sub(by),
            x1: (self.x1 + by).min(w),
            y1: (self.y1 + by).min(h),
        }
    }
}

/// Where a picture has ink.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ink {
    /// The picture's size in pixels.
    pub size: (u32, u32),
    /// The box of its inked pixels; `None` when it is blank.
    pub bbox: Option<PixelBox>,
    /// Each column's first inked row (the picture's height where the
    /// column is blank).
    pub top: Vec<u32>,
}

impl Ink {
    /// The ink of `img` printed on white.
    pub fn of(img: &RgbaImage) -> Ink {
        let (w, h) = img.dimensions();
        let mut top = vec![h; w as usize];
        let mut bbox: Option<PixelBox> = None;
        for (y, row) in img.as_raw().chunks_exact(w.max(1) as usize * 4).enumerate() {
            // Most rows of a picture are mostly white: skip them whole.
            if row.iter().all(|&b| b == 255) {
                continue;
            }
            let y = y as u32;
            for (x, p) in row.chunks_exact(4).enumerate() {
                if !is_ink(p) {
                    continue;
                }
                let x = x as u32;
                if top[x as usize] == h {
                    top[x as usize] = y;
                }
                let b = bbox.get_or_insert(PixelBox {
                    x0: x,
                    y0: y,
                    x1: x + 1,
                    y1: y + 1,
                });
                b.x0 = b.x0.min(x);
                b.x1 = b.x1.max(x + 1);
                b.y1 = y + 1;
            }
        }
        Ink {
            size: (w, h),
            bbox,
            top,
        }
    }
}

/// Whether an RGBA pixel, printed on white, is ink.
fn is_ink(p: &[u8]) -> bool {
    let a = u32::from(p[3]);
    p[..3]
        .iter()
        .any(|&c| (u32::from(c) * a + 255 * (255 - a)) / 255 < u32::from(INK_LEVEL))
}

/// What the layout needs to know of one step.
#[derive(Debug, Clone, Copy)]
pub struct StepContent<'a> {
    /// Where its picture has ink.
    pub ink: &'a Ink,
    /// Pixels a stud's width measures in its picture; consecutive steps
    /// of one scale share a crop.
    pub stud_px: f32,
    /// Items in its callout (one a part and colour).
    pub items: usize,
    /// A note printed under its callout.
    pub note: Option<&'a str>,
}

/// A rectangle on the page, millimetres from its top-left corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rect {
    /// Left edge.
    pub x: f32,
    /// Top edge.
    pub y: f32,
    /// Width.
    pub w: f32,
    /// Height.
    pub h: f32,
}

impl Rect {
    /// Right edge.
    pub fn right(&self) -> f32 {
        self.x + self.w
    }

    /// Bottom edge.
    pub fn bottom(&self) -> f32 {
        self.y + self.h
    }

    /// Whether the two rectangles share some area (touching edges do not
    /// count).
    pub fn overlaps(&self, o: &Rect) -> bool {
        const EPS: f32 = 1e-3;
        self.x + EPS < o.right()
            && o.x + EPS < self.right()
            && self.y + EPS < o.bottom()
            && o.y + EPS < self.bottom()
    }

    fn shifted(self, dx: f32, dy: f32) -> Rect {
        Rect {
            x: self.x + dx,
            y: self.y + dy,
            ..self
        }
    }
}

/// One step on its page.
#[derive(Debug, Clone, PartialEq)]
pub struct StepPlace {
    /// The step's number.
    pub step: u32,
    /// Its cell: the column's width, the row's height.
    pub cell: Rect,
    /// The step number's box (its baseline is the box's bottom).
    pub number: Rect,
    /// The callout box.
    pub callout: Rect,
    /// Callout items a row.
    pub per_row: usize,
    /// The note's lines, each with its baseline's left end.
    pub note: Vec<(f32, f32, String)>,
    /// Where the picture is printed.
    pub picture: Rect,
    /// The part of the step's image printed there.
    pub crop: PixelBox,
}

impl StepPlace {
    /// The box around the number, callout and note: the model's pixels
    /// never run under it.
    pub fn header(&self) -> Rect {
        let mut r = self.number;
        for b in [self.callout]
            .into_iter()
            .chain(self.note.iter().map(|(x, y, _)| Rect {
                x: *x,
                y: *y - 1.0,
                w: 0.0,
                h: 1.0,
            }))
        {
            let (x1, y1) = (r.right().max(b.right()), r.bottom().max(b.bottom()));
            r.x = r.x.min(b.x);
            r.y = r.y.min(b.y);
            r.w = x1 - r.x;
            r.h = y1 - r.y;
        }
        r
    }
}

/// A row of steps.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The columns of its grid: 1, 2 or 3.
    pub columns: usize,
    /// Its area on the page.
    pub area: Rect,
    /// Its steps, left to right.
    pub steps: Vec<StepPlace>,
}

/// One page of steps.
#[derive(Debug, Clone, PartialEq)]
pub struct StepPage {
    /// Its rows, top to bottom.
    pub rows: Vec<Row>,
}

impl StepPage {
    /// Every step on the page, in order.
    pub fn steps(&self) -> impl Iterator<Item = &StepPlace> {
        self.rows.iter().flat_map(|r| &r.steps)
    }
}

/// Measures text: its width in millimetres at a size in points, bold or
/// not.
pub type TextWidth<'a> = &'a dyn Fn(&str, f32, bool) -> f32;

/// The page's measures for laying out steps.
struct Frame<'a> {
    /// Left and top of the content area.
    origin: (f32, f32),
    /// Width and height of the content area.
    size: (f32, f32),
    columns: usize,
    per_page: usize,
    number_size: f32,
    text_size: f32,
    width: TextWidth<'a>,
}

impl Frame<'_> {
    /// Width of a cell in a row of `k` columns.
    fn cell_w(&self, k: usize) -> f32 {
        (self.size.0 - (k - 1) as f32 * COLUMN_GAP) / k as f32
    }

    /// The largest picture under a header `header_h` high: half the width
    /// (all of it when the template puts one step a row), the height
    /// [`MAX_STEP_H`] leaves (more when a page holds one step).
    fn picture_cap(&self, header_h: f32) -> (f32, f32) {
        let w = self.cell_w(self.columns.min(2));
        let h = if self.per_page == 1 {
            0.7 * self.size.1
        } else {
            (MAX_STEP_H * self.size.1 - header_h).max(MIN_PICTURE_H * self.size.1)
        };
        (w, h)
    }

    fn item_h(&self) -> f32 {
        CALLOUT_PICTURE + self.text_size * MM_PER_PT + 2.5
    }
}

/// A step's header (number, callout, note) laid out in a cell of width
/// `w`, relative to the cell's top-left corner.
struct Header {
    number: Rect,
    callout: Rect,
    per_row: usize,
    rows: usize,
    note: Vec<(f32, f32, String)>,
    /// The box around it all.
    bounds: Rect,
}

fn header(f: &Frame<'_>, step: u32, items: usize, note: Option<&str>, w: f32) -> Header {
    let ns = f.number_size;
    let label = step.to_string();
    let number = Rect {
        x: 0.0,
        y: 0.0,
        w: (f.width)(&label, ns, true),
        h: ns * MM_PER_PT * 0.75,
    };
    let cx = number.right() + NUMBER_GAP;
    let per_row = ((w - cx - 2.0 * CALLOUT_PAD) / CALLOUT_ITEM_W)
        .floor()
        .max(1.0) as usize;
    let rows = items.div_ceil(per_row).max(1);
    let callout = Rect {
        x: cx,
        y: 0.0,
        w: per_row.min(items).max(1) as f32 * CALLOUT_ITEM_W + 2.0 * CALLOUT_PAD,
        h: rows as f32 * f.item_h() + 2.0 * CALLOUT_PAD,
    };
    let mut bottom = number.bottom().max(callout.bottom());
    let mut right = callout.right();
    let mut lines = Vec::new();
    if let Some(note) = note {
        let ts = f.text_size;
        for line in wrap(note, w - 1.0, &|s| (f.width)(s, ts, false)) {
            bottom += ts * MM_PER_PT + 1.2;
            right = right.max(1.0 + (f.width)(&line, ts, false));
            lines.push((1.0, bottom, line));
        }
    }
    Header {
        number,
        callout,
        per_row,
        rows,
        note: lines,
        bounds: Rect {
            x: 0.0,
            y: 0.0,
            w: right,
            h: bottom,
        },
    }
}

/// `text` cut into lines at most `w` wide (a word longer than that gets
/// its own line).
fn wrap(text: &str, w: f32, width: &dyn Fn(&str) -> f32) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(line) if width(&format!("{line} {word}")) <= w => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

/// A step's picture: its crop and print scale (millimetres a pixel).
#[derive(Debug, Clone, Copy)]
struct Picture {
    crop: PixelBox,
    mm_per_px: f32,
}

impl Picture {
    fn size(&self) -> (f32, f32) {
        (
            self.crop.width() as f32 * self.mm_per_px,
            self.crop.height() as f32 * self.mm_per_px,
        )
    }
}

/// Each step's crop and print scale: the steps of one scale share a crop,
/// the box of all their ink.
fn pictures(steps: &[StepContent<'_>], f: &Frame<'_>) -> Vec<Picture> {
    let mut out = Vec::with_capacity(steps.len());
    let mut start = 0;
    while start < steps.len() {
        let scale = steps[start].stud_px;
        let end = start
            + steps[start..]
                .iter()
                .take_while(|s| s.stud_px.to_bits() == scale.to_bits())
                .count();
        let stage = &steps[start..end];
        let cell = f.cell_w(f.columns.min(2));
        let header_h = (start..end)
            .map(|i| {
                header(f, i as u32 + 1, steps[i].items, steps[i].note, cell)
                    .bounds
                    .h
            })
            .fold(0.0, f32::max);
        let (cap_w, cap_h) = f.picture_cap(header_h);
        let size = stage[0].ink.size;
        let full = PixelBox {
            x0: 0,
            y0: 0,
            x1: size.0.max(1),
            y1: size.1.max(1),
        };
        let crop = stage
            .iter()
            .filter_map(|s| s.ink.bbox)
            .reduce(PixelBox::union)
            .map_or(full, |b| b.grown(CROP_PAD, size));
        let (cw, ch) = (crop.width() as f32, crop.height() as f32);
        let studs = if scale > 0.0 { cw / scale } else { 0.0 };
        let want = (studs * STUD_MM).clamp(MIN_PICTURE_W.min(cap_w), cap_w);
        let mm_per_px = (want / cw).min(cap_h / ch);
        out.extend(std::iter::repeat_n(
            Picture { crop, mm_per_px },
            stage.len(),
        ));
        start = end;
    }
    out
}

/// A step laid out in a cell, relative to the cell's top-left corner.
struct Block {
    header: Header,
    picture: Rect,
    height: f32,
}

/// Step `step` in a cell of a `k`-column row; `None` when it does not fit
/// (its callout would take more than two rows, or its picture is wider).
fn block(f: &Frame<'_>, step: u32, s: &StepContent<'_>, pic: &Picture, k: usize) -> Option<Block> {
    let w = f.cell_w(k);
    let header = header(f, step, s.items, s.note, w);
    let (pw, ph) = pic.size();
    let fits = k == 1
        || (header.rows <= 2
            && header.callout.right() <= w + 1e-3
            && header.bounds.w <= w + 1e-3
            && pw <= w + 1e-3);
    if !fits {
        return None;
    }
    // The picture centred, or at the right of the cell: moved up until
    // its ink clears the header.
    let lift = |ox: f32| -> f32 {
        let clear = header.bounds.h + HEADER_GAP;
        let reach = header.bounds.w + HEADER_GAP - ox;
        if reach <= 0.0 {
            return 0.0;
        }
        let cols = ((reach / pic.mm_per_px).ceil() as u32).min(pic.crop.width());
        let first = s.ink.top[pic.crop.x0 as usize..(pic.crop.x0 + cols) as usize]
            .iter()
            .min()
            .copied()
            .unwrap_or(pic.crop.y1);
        let below = first.max(pic.crop.y0) - pic.crop.y0;
        (clear - below as f32 * pic.mm_per_px).max(0.0)
    };
    let centred = ((w - pw) / 2.0).max(0.0);
    let right = (w - pw).max(0.0);
    let (tc, tr) = (lift(centred), lift(right));
    // Right-aligned only when it saves real height.
    let (ox, top) = if tr + 1.0 < tc {
        (right, tr)
    } else {
        (centred, tc)
    };
    let picture = Rect {
        x: ox,
        y: top,
        w: pw,
        h: ph,
    };
    let height = header.bounds.h.max(picture.bottom());
    Some(Block {
        header,
        picture,
        height,
    })
}

/// Lays out the steps on pages (see the module docs). `steps[i]` is step
/// `i + 1`.
pub fn plan(steps: &[StepContent<'_>], template: &Template, width: TextWidth<'_>) -> Vec<StepPage> {
    let (pw, ph) = template.page.size.mm();
    let m = template.page.margin;
    let per_page = template.steps.per_page as usize;
    let f = Frame {
        origin: (m, m),
        size: (pw - 2.0 * m, ph - 2.0 * m),
        columns: (template.steps.columns as usize).min(per_page).clamp(1, 3),
        per_page,
        number_size: template.fonts.step_number_size,
        text_size: template.fonts.text_size,
        width,
    };
    let pics = pictures(steps, &f);
    let number = |i: usize| i as u32 + 1;
    // The most columns each step allows.
    let most: Vec<usize> = steps
        .iter()
        .enumerate()
        .map(|(i, s)| {
            (1..=f.columns)
                .rev()
                .find(|&k| block(&f, number(i), s, &pics[i], k).is_some())
                .unwrap_or(1)
        })
        .collect();
    // Rows, filled in step order.
    let mut rows: Vec<(usize, Vec<usize>)> = Vec::new();
    for (i, &k) in most.iter().enumerate() {
        match rows.last_mut() {
            Some((cols, members)) if members.len() < (*cols).min(k) => {
                *cols = (*cols).min(k);
                members.push(i);
            }
            _ => rows.push((k, vec![i])),
        }
    }
    // Rows stacked down the pages.
    let mut pages: Vec<StepPage> = Vec::new();
    let mut y = f.origin.1;
    let bottom = f.origin.1 + f.size.1;
    for (cols, members) in rows {
        let blocks: Vec<Block> = members
            .iter()
            .map(|&i| {
                block(&f, number(i), &steps[i], &pics[i], cols)
                    .expect("a row's steps fit its columns")
            })
            .collect();
        let h = blocks.iter().map(|b| b.height).fold(0.0, f32::max);
        let on_page = pages.last().map_or(0, |p| p.steps().count());
        let fits =
            !pages.is_empty() && y + h <= bottom + 1e-3 && on_page + members.len() <= f.per_page;
        if !fits {
            pages.push(StepPage { rows: Vec::new() });
            y = f.origin.1;
        }
        let cw = f.cell_w(cols);
        let places = members
            .iter()
            .zip(blocks)
            .enumerate()
            .map(|(j, (&i, b))| {
                let (x, cy) = (f.origin.0 + j as f32 * (cw + COLUMN_GAP), y);
                StepPlace {
                    step: number(i),
                    cell: Rect { x, y: cy, w: cw, h },
                    number: b.header.number.shifted(x, cy),
                    callout: b.header.callout.shifted(x, cy),
                    per_row: b.header.per_row,
                    note: b
                        .header
                        .note
                        .into_iter()
                        .map(|(nx, ny, s)| (nx + x, ny + cy, s))
                        .collect(),
                    picture: b.picture.shifted(x, cy),
                    crop: pics[i].crop,
                }
            })
            .collect();
        let page = pages.last_mut().expect("a page was started");
        page.rows.push(Row {
            columns: cols,
            area: Rect {
                x: f.origin.0,
                y,
                w: f.size.0,
                h,
            },
            steps: places,
        });
        y += h + ROW_GAP;
    }
    pages
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `w` x `h` white picture with a black block at `b`.
    fn picture(w: u32, h: u32, b: PixelBox) -> RgbaImage {
        RgbaImage::from_fn(w, h, |x, y| {
            let inside = (b.x0..b.x1).contains(&x) && (b.y0..b.y1).contains(&y);
            image::Rgba(if inside {
                [20, 20, 20, 255]
            } else {
                [255, 255, 255, 255]
            })
        })
    }

    fn width(s: &str, size: f32, _bold: bool) -> f32 {
        s.chars().count() as f32 * 0.55 * size * MM_PER_PT
    }

    #[test]
    fn ink_is_the_models_pixels() {
        let b = PixelBox {
            x0: 30,
            y0: 20,
            x1: 90,
            y1: 50,
        };
        let ink = Ink::of(&picture(120, 80, b));
        assert_eq!(ink.bbox, Some(b));
        assert_eq!(ink.top[10], 80);
        assert_eq!(ink.top[30], 20);
        assert_eq!(Ink::of(&RgbaImage::new(4, 4)).bbox, None, "transparent");
    }

    #[test]
    fn pictures_are_cut_to_their_stage_and_sized_by_what_they_show() {
        let t = Template::default();
        // Two stages: a small cluster zoomed in (3 steps), then the whole
        // model at a third of the scale (3 steps).
        let small = PixelBox {
            x0: 300,
            y0: 200,
            x1: 500,
            y1: 400,
        };
        let big = PixelBox {
            x0: 100,
            y0: 100,
            x1: 700,
            y1: 500,
        };
        let inks: Vec<Ink> = [small, small, small, big, big, big]
            .iter()
            .map(|&b| Ink::of(&picture(800, 600, b)))
            .collect();
        let steps: Vec<StepContent<'_>> = inks
            .iter()
            .enumerate()
            .map(|(i, ink)| StepContent {
                ink,
                stud_px: if i < 3 { 30.0 } else { 10.0 },
                items: 2,
                note: None,
            })
            .collect();
        let pages = plan(&steps, &t, &width);
        let placed: Vec<&StepPlace> = pages.iter().flat_map(StepPage::steps).collect();
        assert_eq!(placed.len(), 6);
        assert_eq!(pages.len(), 1, "{pages:#?}");
        // Cut to the model, with a little white.
        assert_eq!(placed[0].crop, small.grown(CROP_PAD, (800, 600)));
        assert_eq!(placed[5].crop, big.grown(CROP_PAD, (800, 600)));
        // 200 px at 30 px a stud: 6.7 studs, below the smallest picture.
        let p0 = placed[0].picture;
        assert!((p0.w - MIN_PICTURE_W).abs() < 0.01, "{p0:?}");
        // 600 px at 10 a stud: 60 studs, capped at half the width.
        let p5 = placed[5].picture;
        let half = (210.0 - 24.0 - COLUMN_GAP) / 2.0;
        assert!((p5.w - half).abs() < 0.01, "{p5:?}");
        // The small stage's three steps share a row of thirds.
        assert!(placed[..3].iter().all(|p| p.cell.y == placed[0].cell.y));
        assert!(placed[3].cell.y > placed[0].cell.y);
        // Nothing overlaps: cells, and within a cell the picture's ink and
        // the header.
        for (i, a) in placed.iter().enumerate() {
            for b in &placed[i + 1..] {
                assert!(!a.cell.overlaps(&b.cell), "{a:?} {b:?}");
            }
            assert!(a.picture.x >= a.cell.x - 1e-3 && a.picture.right() <= a.cell.right() + 1e-3);
            assert!(a.picture.bottom() <= a.cell.bottom() + 1e-3);
        }
    }

    #[test]
    fn the_picture_moves_up_into_its_own_white_beside_the_header() {
        let t = Template::default();
        // Ink only in the right half of the crop's top: the picture can
        // rise beside the callout.
        let mut img = picture(
            800,
            600,
            PixelBox {
                x0: 100,
                y0: 300,
                x1: 700,
                y1: 500,
            },
        );
        for y in 100..300 {
            for x in 500..700 {
                img.put_pixel(x, y, image::Rgba([20, 20, 20, 255]));
            }
        }
        let ink = Ink::of(&img);
        let step = StepContent {
            ink: &ink,
            stud_px: 12.0,
            items: 1,
            note: None,
        };
        let pages = plan(&[step], &t, &width);
        let p = pages[0].steps().next().unwrap();
        let header = p.header();
        assert!(p.picture.y < header.bottom(), "{p:?}");
        // The ink under the header's columns starts below it.
        let s = p.picture.w / p.crop.width() as f32;
        for (x, &top) in ink.top.iter().enumerate() {
            let mx = p.picture.x + (x as f32 - p.crop.x0 as f32) * s;
            if mx < header.right() && mx >= p.picture.x && top < 600 {
                let my = p.picture.y + (top as f32 - p.crop.y0 as f32) * s;
                assert!(my >= header.bottom(), "column {x}: ink at {my} mm");
            }
        }
    }

    #[test]
    fn big_callouts_widen_the_cell_and_the_template_caps_a_page() {
        let mut t = Template::default();
        let ink = Ink::of(&picture(
            800,
            600,
            PixelBox {
                x0: 300,
                y0: 200,
                x1: 500,
                y1: 400,
            },
        ));
        let step = |items| StepContent {
            ink: &ink,
            stud_px: 30.0,
            items,
            note: Some("Support column: not part of the shape; it holds the model up"),
        };
        let steps = [step(1), step(12), step(1)];
        let pages = plan(&steps, &t, &width);
        let rows: Vec<usize> = pages[0].rows.iter().map(|r| r.columns).collect();
        assert_eq!(rows, [3, 1, 3], "{pages:#?}");
        for p in pages.iter().flat_map(StepPage::steps) {
            // The note wraps inside the cell.
            for (x, _, line) in &p.note {
                assert!(x + width(line, t.fonts.text_size, false) <= p.cell.right());
            }
        }
        t.steps.per_page = 1;
        let pages = plan(&steps, &t, &width);
        assert_eq!(pages.len(), 3);
    }

    #[test]
    fn text_wraps_at_words() {
        let w = |s: &str| s.len() as f32;
        assert_eq!(wrap("aa bb cc", 5.0, &w), ["aa bb", "cc"]);
        assert_eq!(wrap("longword a", 3.0, &w), ["longword", "a"]);
    }
}
