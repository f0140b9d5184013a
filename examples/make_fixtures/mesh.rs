//! Indexed triangle meshes on a fixed 1e-6 grid, and the pieces the fixtures
//! are built from: boxes, extruded profiles, revolved rings.
//!
//! Coordinates are stored as integer multiples of 1e-6 units. Welding vertices
//! is then exact, the closedness check can use exact integer arithmetic, and the
//! written text never depends on how a platform rounds `sin`/`cos` or prints a
//! float.

use std::collections::BTreeMap;

/// Grid steps per model unit.
pub const STEPS_PER_UNIT: i64 = 1_000_000;

/// A vertex position in grid steps.
pub type Point = [i64; 3];

/// An indexed triangle mesh whose equal positions are always one vertex.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    /// Vertex positions in grid steps.
    pub positions: Vec<Point>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    lookup: BTreeMap<Point, u32>,
}

/// Rounds a coordinate in units to grid steps.
pub fn quantize(x: f64) -> i64 {
    (x * STEPS_PER_UNIT as f64).round() as i64
}

/// A grid coordinate back in units.
pub fn unquantize(q: i64) -> f64 {
    q as f64 / STEPS_PER_UNIT as f64
}

impl Mesh {
    /// The vertex at `p` (units), created if new.
    pub fn vertex(&mut self, p: [f64; 3]) -> u32 {
        let key = p.map(quantize);
        if let Some(&i) = self.lookup.get(&key) {
            return i;
        }
        let i = self.positions.len() as u32;
        self.positions.push(key);
        self.lookup.insert(key, i);
        i
    }

    /// Adds triangle `a b c` as given, without any check (fixtures for broken
    /// input need duplicated and degenerate triangles).
    pub fn triangle(&mut self, a: u32, b: u32, c: u32) {
        self.triangles.push([a, b, c]);
    }

    /// Adds the planar quad `a b c d` (counter-clockwise from outside).
    pub fn quad(&mut self, a: u32, b: u32, c: u32, d: u32) {
        self.triangle(a, b, c);
        self.triangle(a, c, d);
    }

    /// Closes a ring with triangles to `center`. A ring running from +x towards
    /// +z around +y gives triangles facing -y.
    pub fn fan(&mut self, center: u32, ring: &[u32]) {
        for k in 0..ring.len() {
            self.triangle(center, ring[k], ring[(k + 1) % ring.len()]);
        }
    }

    /// Joins two closed rings of equal length with quads. Rings running from
    /// +x towards +z around +y, with `upper` above `lower`, give a wall facing
    /// away from the axis.
    pub fn band(&mut self, lower: &[u32], upper: &[u32]) {
        assert_eq!(lower.len(), upper.len(), "band rings differ in length");
        let n = lower.len();
        for k in 0..n {
            let next = (k + 1) % n;
            self.quad(lower[k], upper[k], upper[next], lower[next]);
        }
    }

    /// Extrudes a simple counter-clockwise polygon in the xy plane from
    /// `z0` to `z1` (`z0 < z1`) into a closed prism.
    pub fn extrude(&mut self, profile: &[[f64; 2]], z0: f64, z1: f64) {
        let back: Vec<u32> = profile
            .iter()
            .map(|p| self.vertex([p[0], p[1], z0]))
            .collect();
        let front: Vec<u32> = profile
            .iter()
            .map(|p| self.vertex([p[0], p[1], z1]))
            .collect();
        for [i, j, k] in triangulate(profile) {
            self.triangle(front[i], front[j], front[k]);
            self.triangle(back[i], back[k], back[j]);
        }
        let n = profile.len();
        for i in 0..n {
            let j = (i + 1) % n;
            self.quad(back[i], back[j], front[j], front[i]);
        }
    }

    /// Extrudes a simple counter-clockwise polygon of `(x, z)` points from
    /// `y0` to `y1` (`y0 < y1`) into a closed prism: [`Mesh::extrude`] with
    /// y and z swapped (a mirror, so each triangle is turned back).
    pub fn extrude_y(&mut self, profile: &[[f64; 2]], y0: f64, y1: f64) {
        let mut prism = Mesh::default();
        prism.extrude(profile, y0, y1);
        for t in &prism.triangles {
            let [a, b, c] = t.map(|i| {
                let p = prism.positions[i as usize].map(unquantize);
                self.vertex([p[0], p[2], p[1]])
            });
            self.triangle(a, c, b);
        }
    }

    /// Adds the closed axis-aligned box from `min` to `max`.
    pub fn add_box(&mut self, min: [f64; 3], max: [f64; 3]) {
        let rect = [
            [min[0], min[1]],
            [max[0], min[1]],
            [max[0], max[1]],
            [min[0], max[1]],
        ];
        self.extrude(&rect, min[2], max[2]);
    }
}

/// Twice the signed area of a polygon (positive when counter-clockwise).
pub fn twice_area(poly: &[[f64; 2]]) -> f64 {
    (0..poly.len())
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Triangulates a simple counter-clockwise polygon without collinear
/// neighbours by ear clipping; triangles index `poly` and are counter-clockwise.
pub fn triangulate(poly: &[[f64; 2]]) -> Vec<[usize; 3]> {
    assert!(twice_area(poly) > 0.0, "profile must be counter-clockwise");
    let mut left: Vec<usize> = (0..poly.len()).collect();
    let mut out = Vec::with_capacity(poly.len() - 2);
    while left.len() > 3 {
        let n = left.len();
        let ear = (0..n)
            .find(|&i| {
                let (a, b, c) = (left[(i + n - 1) % n], left[i], left[(i + 1) % n]);
                let (pa, pb, pc) = (poly[a], poly[b], poly[c]);
                cross(pa, pb, pc) > 0.0
                    && left
                        .iter()
                        .filter(|&&v| v != a && v != b && v != c)
                        .all(|&v| {
                            let p = poly[v];
                            // Reject points inside or on the candidate ear.
                            cross(pa, pb, p) < 0.0
                                || cross(pb, pc, p) < 0.0
                                || cross(pc, pa, p) < 0.0
                        })
            })
            .expect("simple polygon always has an ear");
        out.push([left[(ear + n - 1) % n], left[ear], left[(ear + 1) % n]]);
        left.remove(ear);
    }
    out.push([left[0], left[1], left[2]]);
    out
}

/// Area of the regular `n`-gon inscribed in a circle of radius `r`.
pub fn ngon_area(n: usize, r: f64) -> f64 {
    0.5 * n as f64 * r * r * (std::f64::consts::TAU / n as f64).sin()
}
