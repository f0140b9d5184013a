//! The fixed orthographic camera of instruction images.
//!
//! Printed instructions use a parallel projection: a brick looks the same
//! size wherever it sits, and every step image of a model shares one
//! projection and one scale, so the model does not jump between pages. A
//! [`View`] says where the viewer stands (azimuth and elevation, in LDraw's
//! frame with -Y up and the model's front toward -Z); [`Camera::fit`] then
//! fixes the scale and offset once, from every point of the finished model.

use glam::{Vec2, Vec3};

/// Where the viewer stands, as angles about the model.
///
/// The default, azimuth 45 degrees and elevation 30 degrees, is the classic
/// three-quarter view from above: the model's front (LDraw -Z) and one side
/// are seen, tops light, the two sides in two distinct shades.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Degrees about the vertical axis from the front: 0 looks straight at
    /// the front (from -Z), positive values walk the viewer toward +X (the
    /// model's right). Default 45.
    pub azimuth_deg: f32,
    /// Degrees above the horizon, clamped to [-89, 89]. Default 30.
    pub elevation_deg: f32,
    /// Extra quarter turns of the viewer around the model (0 to 3), to show
    /// its back or sides. Default 0.
    pub quarter_turns: u8,
}

impl Default for View {
    fn default() -> Self {
        View {
            azimuth_deg: 45.0,
            elevation_deg: 30.0,
            quarter_turns: 0,
        }
    }
}

impl View {
    /// This view turned by `n` more quarter turns around the model.
    pub fn turned(self, n: u8) -> View {
        View {
            quarter_turns: (self.quarter_turns + n) % 4,
            ..self
        }
    }

    /// The unit vector from the model toward the viewer, in LDraw world
    /// coordinates.
    pub fn toward_eye(&self) -> Vec3 {
        let az = (self.azimuth_deg + 90.0 * f32::from(self.quarter_turns % 4)).to_radians();
        let el = self.elevation_deg.clamp(-89.0, 89.0).to_radians();
        let v = Vec3::new(az.sin() * el.cos(), -el.sin(), -az.cos() * el.cos());
        if v.is_finite() {
            v.normalize()
        } else {
            View::default().toward_eye()
        }
    }
}

/// A fitted orthographic camera: world (LDU) to image pixels.
///
/// [`Camera::project`] maps a world point to `(x, y, depth)`: `x` to the
/// right and `y` down in pixels of the output image, `depth` in LDU growing
/// away from the viewer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// World direction of the image's +x.
    right: Vec3,
    /// World direction of the image's +y (down on the page).
    down: Vec3,
    /// World direction into the image, away from the viewer.
    forward: Vec3,
    /// Pixels per LDU.
    scale: f32,
    /// Pixel position of the world origin.
    offset: Vec2,
    /// Image width in pixels.
    width: u32,
    /// Image height in pixels.
    height: u32,
}

/// LDraw's up direction.
const UP: Vec3 = Vec3::new(0.0, -1.0, 0.0);

impl Camera {
    /// A camera for `view` with the given scale (pixels per LDU), placing
    /// the world point `center` at the centre of a `width` x `height` image.
    pub fn new(view: &View, center: Vec3, scale: f32, width: u32, height: u32) -> Camera {
        let forward = -view.toward_eye();
        // Right-handed: right x down = forward, as in LDraw's own front view
        // (X right, Y down, Z into the screen).
        let right = forward.cross(UP).try_normalize().unwrap_or(Vec3::X);
        let down = forward.cross(right);
        let scale = if scale.is_finite() && scale > 0.0 {
            scale
        } else {
            1.0
        };
        let mut cam = Camera {
            right,
            down,
            forward,
            scale,
            offset: Vec2::ZERO,
            width,
            height,
        };
        let c = cam.project(center);
        cam.offset = Vec2::new(width as f32 / 2.0 - c.x, height as f32 / 2.0 - c.y);
        cam
    }

    /// The camera for `view` that fits every one of `points` into a `width`
    /// x `height` image with `margin` pixels left free on each side, centred.
    ///
    /// Fit it once to the finished model and reuse it for every step image.
    /// With no points (an empty model) the camera looks at the origin at one
    /// pixel per LDU.
    pub fn fit(
        view: &View,
        points: impl IntoIterator<Item = Vec3>,
        width: u32,
        height: u32,
        margin: u32,
    ) -> Camera {
        // The view's axes are worked out once, not once a point: their
        // trigonometry cost more than the points themselves.
        let mut bounds = Bounds::EMPTY;
        bounds.extend(view, points);
        Camera::fit_bounds(view, &bounds, width, height, margin)
    }

    /// [`Camera::fit`] to points whose extent in `view` is `bounds`.
    pub(crate) fn fit_bounds(
        view: &View,
        bounds: &Bounds,
        width: u32,
        height: u32,
        margin: u32,
    ) -> Camera {
        let unit = Camera::new(view, Vec3::ZERO, 1.0, width, height);
        let Bounds {
            lo,
            hi,
            lo_depth,
            hi_depth,
        } = *bounds;
        if !lo.is_finite() || !hi.is_finite() {
            return unit;
        }
        let free_w = (width as f32 - 2.0 * margin as f32).max(1.0);
        let free_h = (height as f32 - 2.0 * margin as f32).max(1.0);
        let extent = (hi - lo).max(Vec2::splat(1e-3));
        let scale = (free_w / extent.x).min(free_h / extent.y);
        // Back from screen-plane centre and mid-depth to a world point.
        let mid = (lo + hi) / 2.0;
        let depth = (lo_depth + hi_depth) / 2.0;
        let center = unit.right * mid.x + unit.down * mid.y + unit.forward * depth;
        Camera::new(view, center, scale, width, height)
    }

    /// This camera at `scale` pixels per LDU, the world point at the
    /// image's centre kept there: how views of one model share a scale.
    pub fn with_scale(&self, scale: f32) -> Camera {
        if !(scale.is_finite() && scale > 0.0) {
            return *self;
        }
        let centre = Vec2::new(self.width as f32, self.height as f32) / 2.0;
        Camera {
            scale,
            offset: centre - (centre - self.offset) * (scale / self.scale),
            ..*self
        }
    }

    /// The same picture drawn `factor` times as large: an image of about
    /// `factor` times the width and height (at least one pixel), every
    /// point projected `factor` times as far from the corner.
    pub(crate) fn resized(&self, factor: f32) -> Camera {
        let side = |s: u32| ((s as f32 * factor).round() as u32).max(1);
        Camera {
            scale: self.scale * factor,
            offset: self.offset * factor,
            width: side(self.width),
            height: side(self.height),
            ..*self
        }
    }

    /// `(x, y, depth)`: image pixels (x right, y down) and LDU away from
    /// the viewer.
    #[inline]
    pub fn project(&self, p: Vec3) -> Vec3 {
        Vec3::new(
            p.dot(self.right) * self.scale + self.offset.x,
            p.dot(self.down) * self.scale + self.offset.y,
            p.dot(self.forward),
        )
    }

    /// The unit vector from the model toward the viewer.
    pub fn toward_eye(&self) -> Vec3 {
        -self.forward
    }

    /// The world direction of the image's +x (to the right on the page).
    pub fn right(&self) -> Vec3 {
        self.right
    }

    /// The world direction of the image's +y (down the page).
    pub fn down(&self) -> Vec3 {
        self.down
    }

    /// Pixels per LDU.
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }
}

/// The extent of some points as a view sees them: along its screen axes
/// (LDU, at one pixel per LDU) and in depth. Bounds of parts of a model
/// unite into the bounds of the whole, so a camera can be fitted to any
/// prefix of the building steps without visiting its points again.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Bounds {
    lo: Vec2,
    hi: Vec2,
    lo_depth: f32,
    hi_depth: f32,
}

impl Bounds {
    /// No points.
    pub(crate) const EMPTY: Bounds = Bounds {
        lo: Vec2::splat(f32::INFINITY),
        hi: Vec2::splat(f32::NEG_INFINITY),
        lo_depth: f32::INFINITY,
        hi_depth: f32::NEG_INFINITY,
    };

    /// Grows the bounds to hold every one of `points` as `view` sees them;
    /// a point that is not finite is left out.
    pub(crate) fn extend(&mut self, view: &View, points: impl IntoIterator<Item = Vec3>) {
        let forward = -view.toward_eye();
        let right = forward.cross(UP).try_normalize().unwrap_or(Vec3::X);
        let down = forward.cross(right);
        for p in points {
            self.add_on_axes(right, down, forward, p);
        }
    }

    fn add_on_axes(&mut self, right: Vec3, down: Vec3, forward: Vec3, p: Vec3) {
        let q = Vec3::new(p.dot(right), p.dot(down), p.dot(forward));
        if !q.is_finite() {
            return;
        }
        self.lo = self.lo.min(q.truncate());
        self.hi = self.hi.max(q.truncate());
        self.lo_depth = self.lo_depth.min(q.z);
        self.hi_depth = self.hi_depth.max(q.z);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn front_view_matches_ldraw_screen_axes() {
        let view = View {
            azimuth_deg: 0.0,
            elevation_deg: 0.0,
            quarter_turns: 0,
        };
        let cam = Camera::new(&view, Vec3::ZERO, 1.0, 100, 100);
        // LDraw's front view: X right, Y down, Z into the screen.
        assert!((cam.project(Vec3::X) - Vec3::new(51.0, 50.0, 0.0)).length() < 1e-5);
        assert!((cam.project(Vec3::Y) - Vec3::new(50.0, 51.0, 0.0)).length() < 1e-5);
        assert!((cam.project(Vec3::Z) - Vec3::new(50.0, 50.0, 1.0)).length() < 1e-5);
    }

    #[test]
    fn fit_keeps_points_inside_the_margins() {
        let pts = [
            Vec3::new(-40.0, -24.0, -20.0),
            Vec3::new(40.0, 0.0, 20.0),
            Vec3::new(-40.0, 0.0, 20.0),
            Vec3::new(40.0, -24.0, -20.0),
        ];
        for turns in 0..4 {
            let view = View::default().turned(turns);
            let cam = Camera::fit(&view, pts, 200, 100, 10);
            for p in pts {
                let q = cam.project(p);
                assert!(q.x >= 9.99 && q.x <= 190.01, "{q}");
                assert!(q.y >= 9.99 && q.y <= 90.01, "{q}");
            }
        }
    }

    #[test]
    fn empty_and_degenerate_inputs_give_a_usable_camera() {
        let cam = Camera::fit(&View::default(), [], 64, 64, 4);
        assert!(cam.scale() > 0.0);
        let nan = View {
            azimuth_deg: f32::NAN,
            elevation_deg: f32::INFINITY,
            quarter_turns: 7,
        };
        let cam = Camera::fit(&nan, [Vec3::ONE, Vec3::ZERO], 64, 64, 4);
        assert!(cam.project(Vec3::ONE).is_finite());
    }

    #[test]
    fn up_is_up_on_the_page() {
        let cam = Camera::new(&View::default(), Vec3::ZERO, 1.0, 100, 100);
        // Higher in the world (more negative LDraw Y) is higher on the page.
        assert!(cam.project(Vec3::new(0.0, -10.0, 0.0)).y < cam.project(Vec3::ZERO).y);
    }
}
