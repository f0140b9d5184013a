//! Colours for pictures that show a measure piece by piece, such as how
//! much of its clutch each piece uses: a green-yellow-red ramp and a
//! legend bar for it.
//!
//! Draw such a picture with [`model_image_with_colors`](super::model_image_with_colors),
//! one [`stress_color`] a piece, then [`draw_stress_legend`] on it.

use image::{Rgb, RgbaImage};

use super::marks::draw_ramp;

/// No clutch used.
const GREEN: [u8; 3] = [0, 168, 68];
/// Half the clutch used.
const YELLOW: [u8; 3] = [250, 200, 10];
/// The clutch used up.
const RED: [u8; 3] = [214, 24, 24];
/// No measure.
const GREY: [u8; 3] = [150, 150, 150];

/// The colour of `usage`, the share of a piece's clutch used: green at 0
/// (and below), yellow at 0.5, red at 1 (and above), blended linearly in
/// between; grey for NaN (no measure).
pub fn stress_color(usage: f64) -> Rgb<u8> {
    if usage.is_nan() {
        return Rgb(GREY);
    }
    let u = usage.clamp(0.0, 1.0);
    let (a, b, t) = if u <= 0.5 {
        (GREEN, YELLOW, u * 2.0)
    } else {
        (YELLOW, RED, u * 2.0 - 1.0)
    };
    Rgb([0, 1, 2]
        .map(|k| (f64::from(a[k]) + (f64::from(b[k]) - f64::from(a[k])) * t).round() as u8))
}

/// Draws the legend of [`stress_color`] in the bottom right corner of
/// `img`: a ramp bar from no clutch used (left) to all of it (right), with
/// long tick marks at 0, 50 % and 100 % and short ones at 25 % and 75 %.
/// An image too small for it is left as it is.
pub fn draw_stress_legend(img: &mut RgbaImage) {
    draw_ramp(img, |u| stress_color(u).0);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_goes_green_yellow_red() {
        assert_eq!(stress_color(0.0).0, GREEN);
        assert_eq!(stress_color(0.5).0, YELLOW);
        assert_eq!(stress_color(1.0).0, RED);
        assert_eq!(stress_color(-3.0).0, GREEN);
        assert_eq!(stress_color(7.0).0, RED);
        assert_eq!(stress_color(f64::INFINITY).0, RED);
        assert_eq!(stress_color(f64::NAN).0, GREY);
        // Between, the red channel grows and then the green falls.
        let reds: Vec<u8> = (0..=10)
            .map(|k| stress_color(k as f64 / 20.0).0[0])
            .collect();
        assert!(reds.windows(2).all(|w| w[0] <= w[1]), "{reds:?}");
        let greens: Vec<u8> = (10..=20)
            .map(|k| stress_color(k as f64 / 20.0).0[1])
            .collect();
        assert!(greens.windows(2).all(|w| w[0] >= w[1]), "{greens:?}");
    }

    #[test]
    fn the_legend_shows_both_ends_of_the_ramp() {
        let mut img = RgbaImage::from_pixel(400, 300, image::Rgba([255; 4]));
        draw_stress_legend(&mut img);
        let has = |c: [u8; 3]| img.pixels().any(|p| p.0[..3] == c);
        assert!(has(stress_color(0.01).0) || has(GREEN));
        assert!(img.pixels().any(|p| p.0[0] > 200 && p.0[1] < 60));
        // Only the bottom of the image is touched.
        assert!((0..400).all(|x| (0..200).all(|y| img.get_pixel(x, y).0 == [255; 4])));
    }
}
