//! Flat marks drawn over finished images: the "turn the model" arrow of a
//! turned step, and the colour ramp of a stress picture.
//!
//! Each shape is given by its distance from a point (zero inside), and is
//! painted with 4 x 4 samples a pixel, blended over what is there: smooth
//! edges with no drawing library. Marks are small, so testing every sample
//! against every shape costs little.

use glam::Vec2;
use image::{Rgba, RgbaImage};

use super::raster::PixelRect;

/// Samples a pixel along each axis when painting.
const SUB: u32 = 4;

/// Paints `rgb` over `img` wherever `dist(point) <= 0`, `point` in pixel
/// coordinates (pixel `(x, y)` spans `x..x + 1`), within `rect`.
fn paint(img: &mut RgbaImage, rect: PixelRect, rgb: [u8; 3], dist: impl Fn(Vec2) -> f32) {
    let rect = PixelRect {
        x1: rect.x1.min(img.width()),
        y1: rect.y1.min(img.height()),
        ..rect
    };
    for y in rect.y0..rect.y1 {
        for x in rect.x0..rect.x1 {
            let mut hits = 0;
            for sy in 0..SUB {
                for sx in 0..SUB {
                    let p = Vec2::new(
                        x as f32 + (sx as f32 + 0.5) / SUB as f32,
                        y as f32 + (sy as f32 + 0.5) / SUB as f32,
                    );
                    hits += u32::from(dist(p) <= 0.0);
                }
            }
            if hits > 0 {
                blend(img.get_pixel_mut(x, y), rgb, hits, SUB * SUB);
            }
        }
    }
}

/// `rgb` at coverage `num / den` over `px` (premultiplied "over").
fn blend(px: &mut Rgba<u8>, rgb: [u8; 3], num: u32, den: u32) {
    let [r, g, b, a] = px.0.map(u32::from);
    let a_out = (num * 255 + (den - num) * a + den / 2) / den;
    if a_out == 0 {
        return;
    }
    let mix = |src: u8, dst: u32| {
        let v = (u32::from(src) * 255 * num + dst * a * (den - num)) / den;
        ((v + a_out / 2) / a_out).min(255) as u8
    };
    px.0 = [mix(rgb[0], r), mix(rgb[1], g), mix(rgb[2], b), a_out as u8];
}

/// Distance from `p` to the segment `a b`.
fn segment(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
    (p - (a + ab * t)).length()
}

/// Distance from `p` to the polyline through `points`.
fn polyline(p: Vec2, points: &[Vec2]) -> f32 {
    points
        .windows(2)
        .map(|w| segment(p, w[0], w[1]))
        .fold(f32::INFINITY, f32::min)
}

/// Distance from `p` to the convex polygon `points` (either winding),
/// zero inside.
fn polygon(p: Vec2, points: &[Vec2]) -> f32 {
    let n = points.len();
    let mut sign = 0.0_f32;
    let mut inside = true;
    let mut d = f32::INFINITY;
    for k in 0..n {
        let (a, b) = (points[k], points[(k + 1) % n]);
        let c = (b - a).perp_dot(p - a);
        if c != 0.0 {
            if sign == 0.0 {
                sign = c.signum();
            } else if c.signum() != sign {
                inside = false;
            }
        }
        d = d.min(segment(p, a, b));
    }
    if inside {
        0.0
    } else {
        d
    }
}

/// Distance from `p` to the rectangle `lo..hi` with corners rounded by
/// `r`, zero inside.
fn rounded_rect(p: Vec2, lo: Vec2, hi: Vec2, r: f32) -> f32 {
    let c = (lo + hi) / 2.0;
    let half = (hi - lo) / 2.0 - Vec2::splat(r);
    let q = (p - c).abs() - half;
    q.max(Vec2::ZERO).length() + q.x.max(q.y).min(0.0) - r
}

/// Pixel rectangle around the points `lo..hi`, grown by `d`.
fn around(lo: Vec2, hi: Vec2, d: f32) -> PixelRect {
    let f = |v: f32| (v.max(0.0)) as u32;
    PixelRect {
        x0: f((lo.x - d).floor()),
        y0: f((lo.y - d).floor()),
        x1: f((hi.x + d).ceil() + 1.0),
        y1: f((hi.y + d).ceil() + 1.0),
    }
}

/// Ink of marks: outlines and the arrow's rim.
const INK: [u8; 3] = [28, 28, 28];
/// The turn badge's ground, the pale blue of instruction callouts.
const BADGE: [u8; 3] = [221, 234, 246];
/// The arrow's body.
const ARROW: [u8; 3] = [255, 255, 255];
/// The little model the arrow goes around: top and two sides.
const BLOCK: [[u8; 3]; 3] = [[196, 200, 204], [150, 156, 162], [112, 118, 124]];

/// Side of the turn badge for an image `width` x `height`, in pixels.
pub(crate) fn badge_side(width: u32, height: u32) -> u32 {
    (width.min(height) as f32 * 0.15).round().clamp(20.0, 160.0) as u32
}

/// Draws the "turn the model" badge for a view turned by `quarter_turns`
/// (1 to 3) from the last step's, in the corner of `img` that covers the
/// least of `new` (the screen box of the step's new pieces: a badge never
/// hides a new piece where a corner is free of them), and of those where
/// the least differs from `background`: a curved arrow around a little block, as
/// printed instructions show a turn. The arrow's front goes the way the
/// model's front turns: to the left for one quarter turn (the viewer
/// walks right, around to the model's right side), to the right for
/// three, and with a double head for a half turn.
pub(crate) fn draw_turn(
    img: &mut RgbaImage,
    quarter_turns: u8,
    background: [u8; 4],
    new: PixelRect,
) {
    let (w, h) = img.dimensions();
    let side = badge_side(w, h);
    if side + 2 > w || side + 2 > h {
        return;
    }
    let pad = (side / 10).max(2);
    let corners = [
        (w - side - pad, pad),
        (pad, pad),
        (w - side - pad, h - side - pad),
        (pad, h - side - pad),
    ];
    let busy = |&(x0, y0): &(u32, u32)| {
        let over =
            |a0: u32, a1: u32, b0: u32, b1: u32| u64::from(a1.min(b1).saturating_sub(a0.max(b0)));
        let hidden = over(x0, x0 + side, new.x0, new.x1) * over(y0, y0 + side, new.y0, new.y1);
        let differ = (y0..y0 + side)
            .flat_map(|y| (x0..x0 + side).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0 != background)
            .count();
        (hidden, differ)
    };
    let mut at = corners[0];
    let mut least = busy(&at);
    for c in &corners[1..] {
        let n = busy(c);
        if n < least {
            (at, least) = (*c, n);
        }
    }
    let s = side as f32;
    let lo = Vec2::new(at.0 as f32, at.1 as f32);
    let hi = lo + Vec2::splat(s);
    let rect = around(lo, hi, 1.0);
    let line = (s / 40.0).max(1.0);

    // The badge: a rounded square with a thin rim.
    let radius = s * 0.12;
    paint(img, rect, INK, |p| rounded_rect(p, lo, hi, radius));
    paint(img, rect, BADGE, |p| rounded_rect(p, lo, hi, radius) + line);

    // The arrow goes around an ellipse on the ground, seen from above.
    let centre = lo + Vec2::new(0.5, 0.56) * s;
    let radii = Vec2::new(0.36, 0.15) * s;
    let mirror = if quarter_turns == 3 { -1.0 } else { 1.0 };
    let at_angle = |t: f32| centre + Vec2::new(mirror * radii.x * t.cos(), radii.y * t.sin());
    // From the back right (t < 0, above the centre) down round the front
    // (t = pi / 2) to the left: angles grow the way the arrow goes.
    let (t0, t1) = (-0.45 * std::f32::consts::PI, 0.9 * std::f32::consts::PI);
    let arc = |a: f32, b: f32| -> Vec<Vec2> {
        let n = 32;
        (0..=n)
            .map(|k| at_angle(a + (b - a) * k as f32 / n as f32))
            .collect()
    };
    let body = s * 0.075;
    let rim = line * 1.5;
    let (back, front) = (arc(t0, 0.0), arc(0.0, t1));

    // The back half of the arrow, behind the block.
    paint(img, rect, INK, |p| polyline(p, &back) - body / 2.0 - rim);
    paint(img, rect, ARROW, |p| polyline(p, &back) - body / 2.0);

    // The block: a little brick seen from above, its top and two sides.
    let bw = s * 0.17;
    let bh = s * 0.14;
    let top_c = centre - Vec2::new(0.0, s * 0.14);
    let t = [
        top_c + Vec2::new(-bw, 0.0),
        top_c + Vec2::new(0.0, -bw * 0.5),
        top_c + Vec2::new(bw, 0.0),
        top_c + Vec2::new(0.0, bw * 0.5),
    ];
    let left = [t[0], t[3], t[3] + Vec2::Y * bh, t[0] + Vec2::Y * bh];
    let right = [t[3], t[2], t[2] + Vec2::Y * bh, t[3] + Vec2::Y * bh];
    for (face, rgb) in [(&t, BLOCK[0]), (&left, BLOCK[1]), (&right, BLOCK[2])] {
        paint(img, rect, INK, |p| polygon(p, face) - line);
        paint(img, rect, rgb, |p| polygon(p, face));
    }

    // The front half, over the block, and the head (two for a half turn).
    let tangent =
        |t: f32| Vec2::new(-mirror * radii.x * t.sin(), radii.y * t.cos()).normalize_or_zero();
    let head_len = s * 0.17;
    let head_w = s * 0.13;
    let heads: Vec<[Vec2; 3]> = {
        let dir = tangent(t1);
        let normal = dir.perp();
        let tip = at_angle(t1) + dir * head_len * 0.55;
        let head = |tip: Vec2| {
            let base = tip - dir * head_len;
            [tip, base + normal * head_w, base - normal * head_w]
        };
        if quarter_turns == 2 {
            vec![head(tip), head(tip - dir * head_len * 0.55)]
        } else {
            vec![head(tip)]
        }
    };
    paint(img, rect, INK, |p| {
        let mut d = polyline(p, &front) - body / 2.0;
        for hd in &heads {
            d = d.min(polygon(p, hd));
        }
        d - rim
    });
    paint(img, rect, ARROW, |p| polyline(p, &front) - body / 2.0);
    for hd in &heads {
        paint(img, rect, ARROW, |p| polygon(p, hd));
    }
}

/// Draws a colour ramp bar along the bottom of `img`, its colour at each
/// point given by `color(u)` for `u` from 0 (left) to 1 (right), with
/// tick marks at 0, 1/4, 1/2, 3/4 and 1 (long at 0, 1/2 and 1).
pub(crate) fn draw_ramp(img: &mut RgbaImage, color: impl Fn(f64) -> [u8; 3]) {
    let (w, h) = img.dimensions();
    let bar_w = (w as f32 * 0.4).round();
    let bar_h = (h as f32 * 0.03).round().max(4.0);
    let pad = (h as f32 * 0.04).round().max(2.0);
    let tick = (bar_h * 0.6).max(3.0);
    if bar_w < 10.0 || bar_h + tick * 2.0 + pad * 2.0 > h as f32 {
        return;
    }
    let lo = Vec2::new(w as f32 - pad - bar_w, h as f32 - pad - tick * 1.6 - bar_h);
    let hi = lo + Vec2::new(bar_w, bar_h);
    let rect = around(lo, hi + Vec2::new(0.0, tick * 1.6), 2.0);
    let line = (bar_h / 8.0).max(1.0);
    paint(img, rect, INK, |p| rounded_rect(p, lo, hi, 0.0) - line);
    for x in lo.x as u32..hi.x as u32 {
        let u = f64::from((x as f32 + 0.5 - lo.x) / bar_w);
        let col = PixelRect {
            x0: x,
            y0: lo.y as u32,
            x1: x + 1,
            y1: hi.y.ceil() as u32,
        };
        paint(img, col, color(u), |p| rounded_rect(p, lo, hi, 0.0));
    }
    for k in 0..=4 {
        let x = lo.x + bar_w * k as f32 / 4.0;
        let len = if k % 2 == 0 { tick * 1.5 } else { tick };
        let (a, b) = (Vec2::new(x, hi.y), Vec2::new(x, hi.y + len));
        paint(img, rect, INK, |p| segment(p, a, b) - line / 2.0 - 0.25);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn white(w: u32, h: u32) -> RgbaImage {
        RgbaImage::from_pixel(w, h, Rgba([255; 4]))
    }

    #[test]
    fn blend_over_opaque_and_transparent() {
        let mut px = Rgba([255, 255, 255, 255]);
        blend(&mut px, [0, 0, 0], 8, 16);
        assert_eq!(px.0, [127, 127, 127, 255]);
        let mut px = Rgba([255, 255, 255, 0]);
        blend(&mut px, [10, 20, 30], 16, 16);
        assert_eq!(px.0, [10, 20, 30, 255]);
    }

    #[test]
    fn the_turn_badge_goes_to_the_emptiest_corner() {
        let mut img = white(200, 150);
        // Fill the top-right corner: the badge moves to the top left.
        for y in 0..60 {
            for x in 140..200 {
                img.put_pixel(x, y, Rgba([0, 0, 0, 255]));
            }
        }
        let before = img.clone();
        draw_turn(&mut img, 1, [255; 4], PixelRect::EMPTY);
        let side = badge_side(200, 150);
        let changed = |x0: u32, y0: u32| {
            (y0..y0 + side)
                .flat_map(|y| (x0..x0 + side).map(move |x| (x, y)))
                .filter(|&(x, y)| img.get_pixel(x, y) != before.get_pixel(x, y))
                .count()
        };
        assert!(changed(0, 0) > (side * side / 2) as usize);
        assert_eq!(changed(200 - side, 150 - side), 0);
    }

    #[test]
    fn the_turn_badge_never_covers_the_new_pieces_when_a_corner_is_free() {
        // The top left is empty but holds the new pieces' box; the top
        // right is full of old pieces: the badge goes to a bottom corner.
        let mut img = white(200, 150);
        for y in 0..60 {
            for x in 140..200 {
                img.put_pixel(x, y, Rgba([0, 0, 0, 255]));
            }
        }
        let new = PixelRect {
            x0: 10,
            y0: 5,
            x1: 30,
            y1: 25,
        };
        let before = img.clone();
        draw_turn(&mut img, 1, [255; 4], new);
        let side = badge_side(200, 150);
        for y in 0..side {
            for x in 0..side {
                assert_eq!(img.get_pixel(x, y), before.get_pixel(x, y));
            }
        }
        assert_ne!(img, before);
    }

    #[test]
    fn each_turn_draws_its_own_arrow() {
        let imgs: Vec<RgbaImage> = (1..=3)
            .map(|q| {
                let mut img = white(200, 150);
                draw_turn(&mut img, q, [255; 4], PixelRect::EMPTY);
                img
            })
            .collect();
        assert!(imgs[0] != imgs[1] && imgs[1] != imgs[2] && imgs[0] != imgs[2]);
    }

    #[test]
    fn the_ramp_runs_from_left_to_right() {
        let mut img = white(200, 150);
        draw_ramp(&mut img, |u| [(u * 255.0) as u8, 0, 0]);
        // Rows where the bar's middle is pure ramp colour (no ink blended).
        let rows: Vec<u32> = (0..150)
            .filter(|&y| img.get_pixel(150, y).0[1] == 0)
            .collect();
        let y = rows[rows.len() / 2];
        let reds: Vec<u8> = (0..200)
            .map(|x| img.get_pixel(x, y))
            .filter(|p| p.0[1] == 0 && p.0[0] > 0)
            .map(|p| p.0[0])
            .collect();
        assert!(reds.len() > 50);
        assert!(reds.windows(2).all(|w| w[0] <= w[1]));
    }
}
