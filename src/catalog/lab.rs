//! Perceptual colour matching: sRGB to CIELAB (D65), the CIEDE2000
//! difference, the nearest catalog colour to any sRGB colour, and the
//! reduction of a model's colours to at most `n`.
//!
//! ```
//! use brickwright::catalog::{lab, Color};
//!
//! assert_eq!(lab::nearest([200, 10, 10]), Color::RED);
//! assert_eq!(lab::nearest([250, 250, 250]), Color::WHITE);
//! ```

use super::color::{Color, COLORS};

/// CIELAB `(L*, a*, b*)` under D65.
pub type Lab = [f64; 3];

/// An sRGB colour (0–255 a channel) in CIELAB.
pub fn to_lab(rgb: [u8; 3]) -> Lab {
    let lin = rgb.map(|c| {
        let c = f64::from(c) / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    });
    let x = 0.412_456_4 * lin[0] + 0.357_576_1 * lin[1] + 0.180_437_5 * lin[2];
    let y = 0.212_672_9 * lin[0] + 0.715_152_2 * lin[1] + 0.072_175_0 * lin[2];
    let z = 0.019_333_9 * lin[0] + 0.119_192_0 * lin[1] + 0.950_304_1 * lin[2];
    let f = |t: f64| {
        if t > 216.0 / 24389.0 {
            t.cbrt()
        } else {
            (24389.0 / 27.0 * t + 16.0) / 116.0
        }
    };
    let (fx, fy, fz) = (f(x / 0.950_47), f(y), f(z / 1.088_83));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// The CIEDE2000 colour difference between two Lab colours (Sharma, Wu and
/// Dalal's formulation; `kL = kC = kH = 1`).
pub fn ciede2000(a: Lab, b: Lab) -> f64 {
    use std::f64::consts::PI;
    let (l1, a1, b1) = (a[0], a[1], a[2]);
    let (l2, a2, b2) = (b[0], b[1], b[2]);
    let c1 = a1.hypot(b1);
    let c2 = a2.hypot(b2);
    let cbar = (c1 + c2) / 2.0;
    let g = 0.5 * (1.0 - (cbar.powi(7) / (cbar.powi(7) + 25f64.powi(7))).sqrt());
    let (a1p, a2p) = ((1.0 + g) * a1, (1.0 + g) * a2);
    let (c1p, c2p) = (a1p.hypot(b1), a2p.hypot(b2));
    let hue = |b: f64, a: f64| {
        if b == 0.0 && a == 0.0 {
            0.0
        } else {
            let h = b.atan2(a).to_degrees();
            if h < 0.0 {
                h + 360.0
            } else {
                h
            }
        }
    };
    let (h1p, h2p) = (hue(b1, a1p), hue(b2, a2p));
    let dlp = l2 - l1;
    let dcp = c2p - c1p;
    let dhp = if c1p * c2p == 0.0 {
        0.0
    } else if (h2p - h1p).abs() <= 180.0 {
        h2p - h1p
    } else if h2p - h1p > 180.0 {
        h2p - h1p - 360.0
    } else {
        h2p - h1p + 360.0
    };
    let dhp_big = 2.0 * (c1p * c2p).sqrt() * (dhp.to_radians() / 2.0).sin();
    let lbp = (l1 + l2) / 2.0;
    let cbp = (c1p + c2p) / 2.0;
    let hbp = if c1p * c2p == 0.0 {
        h1p + h2p
    } else if (h1p - h2p).abs() <= 180.0 {
        (h1p + h2p) / 2.0
    } else if h1p + h2p < 360.0 {
        (h1p + h2p + 360.0) / 2.0
    } else {
        (h1p + h2p - 360.0) / 2.0
    };
    let t = 1.0 - 0.17 * (hbp - 30.0).to_radians().cos()
        + 0.24 * (2.0 * hbp).to_radians().cos()
        + 0.32 * (3.0 * hbp + 6.0).to_radians().cos()
        - 0.20 * (4.0 * hbp - 63.0).to_radians().cos();
    let dtheta = 30.0 * (-((hbp - 275.0) / 25.0).powi(2)).exp();
    let rc = 2.0 * (cbp.powi(7) / (cbp.powi(7) + 25f64.powi(7))).sqrt();
    let sl = 1.0 + 0.015 * (lbp - 50.0).powi(2) / (20.0 + (lbp - 50.0).powi(2)).sqrt();
    let sc = 1.0 + 0.045 * cbp;
    let sh = 1.0 + 0.015 * cbp * t;
    let rt = -(2.0 * dtheta * PI / 180.0).sin() * rc;
    let (x, y, z) = (dlp / sl, dcp / sc, dhp_big / sh);
    (x * x + y * y + z * z + rt * y * z).sqrt()
}

/// The catalog colour nearest to `rgb` by CIEDE2000, among `choices`.
pub fn nearest_in(rgb: [u8; 3], choices: &[Color]) -> Color {
    let lab = to_lab(rgb);
    choices
        .iter()
        .copied()
        .min_by(|&x, &y| {
            ciede2000(lab, to_lab(x.rgb()))
                .total_cmp(&ciede2000(lab, to_lab(y.rgb())))
                .then(x.cmp(&y))
        })
        .unwrap_or(Color::LIGHT_BLUISH_GREY)
}

/// The catalog colour nearest to `rgb` by CIEDE2000, among every solid
/// colour of the catalog.
pub fn nearest(rgb: [u8; 3]) -> Color {
    let all: Vec<Color> = COLORS.iter().map(|c| c.code).collect();
    nearest_in(rgb, &all)
}

/// Reduces the colours of a model, each with its weight (e.g. how many
/// surface samples it covers), to at most `n`: the lightest colour is merged
/// into its nearest (CIEDE2000) remaining colour until `n` are left.
/// Returns the colour each input colour becomes; ties break by code, so the
/// result is deterministic.
pub fn reduce(weights: &[(Color, u64)], n: usize) -> Vec<(Color, Color)> {
    let mut live: Vec<(Color, u64)> = weights.to_vec();
    live.sort_by_key(|&(c, _)| c);
    let mut into: Vec<(Color, Color)> = live.iter().map(|&(c, _)| (c, c)).collect();
    while live.len() > n.max(1) {
        let (i, _) = live
            .iter()
            .enumerate()
            .min_by_key(|&(_, &(c, w))| (w, c))
            .expect("more than one colour");
        let (gone, w) = live.remove(i);
        let lab = to_lab(gone.rgb());
        let j = (0..live.len())
            .min_by(|&x, &y| {
                ciede2000(lab, to_lab(live[x].0.rgb()))
                    .total_cmp(&ciede2000(lab, to_lab(live[y].0.rgb())))
            })
            .expect("a colour is left");
        live[j].1 += w;
        let target = live[j].0;
        for e in &mut into {
            if e.1 == gone {
                e.1 = target;
            }
        }
    }
    into
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sharma_reference_pairs() {
        // Pairs 1, 7 and 17 of Sharma, Wu and Dalal's test data.
        let cases = [
            ([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425),
            ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669),
            ([50.0, 2.5, 0.0], [73.0, 25.0, -18.0], 27.1492),
        ];
        for (a, b, want) in cases {
            let got = ciede2000(a, b);
            assert!((got - want).abs() < 1e-3, "{got} vs {want}");
        }
    }

    #[test]
    fn lab_of_white_and_black() {
        let w = to_lab([255, 255, 255]);
        assert!((w[0] - 100.0).abs() < 0.01 && w[1].abs() < 0.01 && w[2].abs() < 0.01);
        assert!(to_lab([0, 0, 0])[0].abs() < 1e-9);
    }

    #[test]
    fn nearest_picks_the_obvious_bricks() {
        assert_eq!(nearest([30, 90, 170]), Color(1));
        assert_eq!(nearest([255, 220, 0]), Color(14));
        assert_eq!(nearest([10, 10, 10]), Color(0));
        assert_eq!(nearest([10, 120, 40]), Color(2));
    }

    #[test]
    fn reduce_merges_the_lightest_into_its_nearest() {
        let w = [(Color(4), 100), (Color(320), 5), (Color(1), 50)];
        let m = reduce(&w, 2);
        assert!(m.contains(&(Color(320), Color(4))), "{m:?}");
        assert!(m.contains(&(Color(1), Color(1))));
        assert_eq!(reduce(&w, 5).len(), 3);
    }
}
