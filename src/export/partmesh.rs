//! Triangle meshes of the catalog's parts, in each part's own LDraw frame.
//!
//! Every consumer that draws pieces (the glTF writer, the software renderer,
//! the booklet) takes its geometry from here, so a brick looks the same in
//! every output and lines up with the `.ldr` exactly.
//!
//! # The frame
//!
//! A mesh is in LDraw units (LDU, 20 to a stud, 8 to a plate) with **-Y
//! up** and its origin where the LDraw part file has it:
//!
//! - bricks and plates: the centre of the top face; the body runs from
//!   `y = 0` down to `y = 8 * height_plates`, the studs stand up to `y = -4`;
//!   the long side lies along X (`x` in `±10·studs_x`, `z` in `±10·studs_y`);
//! - slopes and inverted slopes: the centre of the studded back row (`z` from
//!   `+10` at the back to `10 - 20·depth` at the front, toward -Z).
//!
//! A piece's world position is then exactly the `.ldr` line's:
//! `world = rot_matrix(rot)·local + placement_position(p, layer_ldu)`, the
//! affine map [`piece_transform`] returns.
//!
//! # The shapes
//!
//! Each body is a prism: a profile in the `(z, y)` plane extruded across the
//! part's width. A brick's profile is a rectangle; a slope's falls from the
//! back row's flat top along its slanted face to a lip 4 LDU high at the
//! front (45° over one row for 3039, 33° over two rows for 3298, as in the
//! LDraw files); an inverted slope is flat on top and its underside rises
//! from the back row to a 4 LDU lip. Studs are 16-sided cylinders of radius
//! 6 LDU and height 4 on the studded cells (every top cell, a slope's back
//! row only). Bodies are solid: no hollow underside or tubes, which a
//! picture of an assembled model never shows.
//!
//! Each mesh is one closed, watertight surface: the top face is cut around
//! each stud's foot and every face carries the vertices its neighbours put
//! on their shared edges, so every edge is shared by exactly two triangles
//! in opposite directions (no T-junctions). Triangles wind counter-clockwise
//! seen from outside. Flat faces have flat normals (vertices are duplicated
//! at hard edges); a stud's side is one curved face with smooth radial
//! normals.
//!
//! # Example
//!
//! ```
//! use brickwright::catalog::PartKind;
//! use brickwright::export::partmesh::part_mesh;
//!
//! let brick = part_mesh(PartKind::from_id("3001").unwrap());
//! let (lo, hi) = brick.bounds().unwrap();
//! assert_eq!((lo, hi), ([-40.0, -4.0, -20.0], [40.0, 24.0, 20.0]));
//! assert_eq!(brick.indices.len() % 3, 0);
//! ```

use std::collections::HashMap;
use std::sync::OnceLock;

use glam::{Affine3A, Mat3A, Vec3, Vec3A};

use crate::assembly::Placement;
use crate::catalog::{PartKind, PartSpec, Shape, PARTS};
use crate::ldraw::{placement_position, rot_matrix};

/// Sides of a stud's cylinder.
pub const STUD_SEGMENTS: usize = 16;

/// Sides of a stud's prism in a [`coarse_part_mesh`].
pub const COARSE_STUD_SEGMENTS: usize = 6;

/// A stud's radius in LDU.
pub const STUD_RADIUS: f32 = 6.0;

/// A stud's height in LDU.
pub const STUD_HEIGHT: f32 = 4.0;

/// The height in LDU of a slope's front lip (and an inverted slope's front
/// edge).
pub const LIP_HEIGHT: f32 = 4.0;

/// One part's triangle mesh: plain arrays, ready to upload or rasterize.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PartMesh {
    /// Vertex positions in LDU, in the part's LDraw frame.
    pub positions: Vec<[f32; 3]>,
    /// Unit vertex normals, one per position, pointing out of the part.
    pub normals: Vec<[f32; 3]>,
    /// Triangles as triples of indices into `positions`, counter-clockwise
    /// seen from outside.
    pub indices: Vec<u32>,
}

impl PartMesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Every triangle's three corners.
    pub fn triangles(&self) -> impl Iterator<Item = [Vec3; 3]> + '_ {
        self.indices.chunks_exact(3).map(|t| {
            [0, 1, 2].map(|k| {
                self.positions
                    .get(t[k] as usize)
                    .map_or(Vec3::ZERO, |&p| Vec3::from(p))
            })
        })
    }

    /// The axis-aligned bounding box `(min, max)` of the vertices, or
    /// `None` for an empty mesh.
    pub fn bounds(&self) -> Option<([f32; 3], [f32; 3])> {
        let first = Vec3::from(*self.positions.first()?);
        let (lo, hi) = self.positions.iter().fold((first, first), |(lo, hi), &p| {
            (lo.min(Vec3::from(p)), hi.max(Vec3::from(p)))
        });
        Some((lo.to_array(), hi.to_array()))
    }

    /// The signed volume enclosed, in cubic LDU: positive when the
    /// triangles wind outward (divergence theorem over the surface).
    pub fn volume(&self) -> f64 {
        self.triangles()
            .map(|[a, b, c]| f64::from(a.dot(b.cross(c))) / 6.0)
            .sum()
    }
}

/// The mesh of `part`, built once for the whole catalog on first use.
pub fn part_mesh(part: PartKind) -> &'static PartMesh {
    static MESHES: OnceLock<Vec<PartMesh>> = OnceLock::new();
    static EMPTY: PartMesh = PartMesh {
        positions: Vec::new(),
        normals: Vec::new(),
        indices: Vec::new(),
    };
    let meshes = MESHES.get_or_init(|| PARTS.iter().map(build_part_mesh).collect());
    meshes.get(part.0 as usize).unwrap_or(&EMPTY)
}

/// The mesh of `part` with fewer triangles, for pieces drawn a few pixels
/// wide (the step viewer's level of detail): the same body with a plain
/// top face, and studs as [`COARSE_STUD_SEGMENTS`]-sided prisms standing
/// on it, open at the foot. Same bounds and outward winding as
/// [`part_mesh`]; a 2x4 brick has 140 triangles instead of 678.
pub fn coarse_part_mesh(part: PartKind) -> &'static PartMesh {
    static MESHES: OnceLock<Vec<PartMesh>> = OnceLock::new();
    static EMPTY: PartMesh = PartMesh {
        positions: Vec::new(),
        normals: Vec::new(),
        indices: Vec::new(),
    };
    let meshes = MESHES.get_or_init(|| PARTS.iter().map(build_coarse_part_mesh).collect());
    meshes.get(part.0 as usize).unwrap_or(&EMPTY)
}

/// The affine map from `p`'s part frame to LDraw world coordinates (LDU),
/// exactly as the `.ldr` line places it: the rotation
/// [`rot_matrix`]`(rot)` followed by the translation
/// [`placement_position`]`(p, layer_ldu)`.
///
/// ```
/// use brickwright::assembly::Placement;
/// use brickwright::catalog::PartKind;
/// use brickwright::export::partmesh::piece_transform;
/// use brickwright::geom::{Cell, Rot};
/// use glam::Vec3;
///
/// let p = Placement::new(PartKind::from_id("3001").unwrap(), Cell::new(0, 0, 0), Rot::R90);
/// let m = piece_transform(&p, 24);
/// // The corner at local (+40, 0, -20) lands at grid offset (1, 2) studs.
/// assert_eq!(m.transform_point3(Vec3::new(40.0, 0.0, -20.0)), Vec3::new(40.0, -24.0, 80.0));
/// ```
pub fn piece_transform(p: &Placement, layer_ldu: i32) -> Affine3A {
    let m = rot_matrix(p.rot);
    let col = |j: usize| Vec3A::new(m[0][j] as f32, m[1][j] as f32, m[2][j] as f32);
    let [x, y, z] = placement_position(p, layer_ldu);
    Affine3A {
        matrix3: Mat3A::from_cols(col(0), col(1), col(2)),
        translation: Vec3A::new(x as f32, y as f32, z as f32),
    }
}

/// Builds the mesh of one catalog entry (uncached; see [`part_mesh`]).
pub fn build_part_mesh(spec: &PartSpec) -> PartMesh {
    let (profile, hx, columns, rows) = layout(spec);
    let mut b = Builder::default();
    b.studded_top(&columns, &rows);
    let x_extras = edge_points(&columns);
    let z_extras = edge_points(&rows);
    b.prism(&profile, hx, &x_extras, &z_extras);
    b.mesh
}

/// Builds the mesh of [`coarse_part_mesh`] (uncached).
pub fn build_coarse_part_mesh(spec: &PartSpec) -> PartMesh {
    let (profile, hx, columns, rows) = layout(spec);
    let mut b = Builder::default();
    b.prism(&profile, hx, &[], &[]);
    let (zb, zf) = (profile.corners[1][0], profile.corners[2][0]);
    let top = [[-hx, zb], [hx, zb], [hx, zf], [-hx, zf]].map(|[x, z]| Vec3::new(x, 0.0, z));
    b.polygon(&top, Vec3::NEG_Y);
    for &cz in &rows {
        for &cx in &columns {
            b.stud_prism(cx, cz);
        }
    }
    b.mesh
}

/// A part's profile, half width and the centres of its stud columns (x)
/// and rows (z).
fn layout(spec: &PartSpec) -> (Profile, f32, Vec<f32>, Vec<f32>) {
    let w = i32::from(spec.studs_x.max(1));
    let d = i32::from(spec.studs_y.max(1));
    let h = spec.height_ldu().max(8) as f32;
    let columns: Vec<f32> = (0..w).map(|i| (20 * i - 10 * w + 10) as f32).collect();
    let rows: Vec<f32> = match spec.shape {
        Shape::Rect => (0..d).map(|j| (20 * j - 10 * d + 10) as f32).collect(),
        Shape::Slope => vec![0.0],
        Shape::Inverted => (0..d).rev().map(|j| (-20 * j) as f32).collect(),
    };
    (
        Profile::of(spec.shape, d, h),
        10.0 * w as f32,
        columns,
        rows,
    )
}

/// Offsets, from a cell's centre, of the 16 points where rays from the
/// centre toward each stud vertex meet the cell's square edge (half side
/// 10), counter-clockwise from +X toward +Z. Corners and edge midpoints are
/// among them, so neighbouring cells put the same points on a shared edge.
fn square_points() -> [[f32; 2]; STUD_SEGMENTS] {
    let t = 10.0 * (std::f32::consts::SQRT_2 - 1.0); // 10·tan 22.5°
    [
        [10.0, 0.0],
        [10.0, t],
        [10.0, 10.0],
        [t, 10.0],
        [0.0, 10.0],
        [-t, 10.0],
        [-10.0, 10.0],
        [-10.0, t],
        [-10.0, 0.0],
        [-10.0, -t],
        [-10.0, -10.0],
        [-t, -10.0],
        [0.0, -10.0],
        [t, -10.0],
        [10.0, -10.0],
        [10.0, -t],
    ]
}

/// Offsets of a stud's vertices from its cell's centre, in the directions
/// of [`square_points`].
fn circle_points() -> [[f32; 2]; STUD_SEGMENTS] {
    square_points().map(|[x, z]| {
        let v = glam::Vec2::new(x, z).normalize() * STUD_RADIUS;
        [v.x, v.y]
    })
}

/// The points a row of studded cells (centres `centres`, ascending) puts on
/// an outer edge of the top face along that axis, without the two ends:
/// each cell contributes its edge's corner, the two ray points and the
/// midpoint.
fn edge_points(centres: &[f32]) -> Vec<f32> {
    let t = square_points()[1][1];
    let mut out = Vec::with_capacity(4 * centres.len());
    for (i, &c) in centres.iter().enumerate() {
        if i > 0 {
            out.push(c + -10.0);
        }
        out.extend([c + -t, c, c + t]);
    }
    out
}

/// A prism's cross-section in the `(z, y)` plane: convex corners in order,
/// starting at the bottom back corner, then the back top corner; the edge
/// from corner 1 to corner 2 is the (studded) top.
struct Profile {
    corners: Vec<[f32; 2]>,
}

impl Profile {
    fn of(shape: Shape, depth: i32, h: f32) -> Profile {
        let front = (10 - 20 * depth) as f32;
        let corners = match shape {
            Shape::Rect => {
                let hz = 10.0 * depth as f32;
                vec![[hz, h], [hz, 0.0], [-hz, 0.0], [-hz, h]]
            }
            Shape::Slope => vec![
                [10.0, h],
                [10.0, 0.0],
                [-10.0, 0.0],
                [front, h - LIP_HEIGHT],
                [front, h],
            ],
            Shape::Inverted => vec![
                [10.0, h],
                [10.0, 0.0],
                [front, 0.0],
                [front, LIP_HEIGHT],
                [-10.0, h],
            ],
        };
        Profile { corners }
    }

    fn centroid(&self) -> [f32; 2] {
        let n = self.corners.len() as f32;
        let (z, y) = self
            .corners
            .iter()
            .fold((0.0, 0.0), |(z, y), c| (z + c[0], y + c[1]));
        [z / n, y / n]
    }
}

/// Accumulates faces, sharing a vertex only between triangles with the
/// same position and normal (so hard edges get duplicate vertices).
#[derive(Default)]
struct Builder {
    mesh: PartMesh,
    seen: HashMap<([u32; 3], [u32; 3]), u32>,
}

impl Builder {
    fn vertex(&mut self, p: Vec3, n: Vec3) -> u32 {
        let key = (
            p.to_array().map(f32::to_bits),
            n.to_array().map(f32::to_bits),
        );
        if let Some(&i) = self.seen.get(&key) {
            return i;
        }
        let i = self.mesh.positions.len() as u32;
        self.mesh.positions.push(p.to_array());
        self.mesh.normals.push(n.to_array());
        self.seen.insert(key, i);
        i
    }

    /// A planar convex polygon with a flat normal, fanned from `pts[0]`
    /// (which must not lie on an edge with intermediate points) and wound
    /// so that it faces `outward`.
    fn polygon(&mut self, pts: &[Vec3], outward: Vec3) {
        if pts.len() < 3 {
            return;
        }
        let n = outward.normalize_or_zero();
        let mut newell = Vec3::ZERO;
        for (i, &a) in pts.iter().enumerate() {
            newell += a.cross(pts[(i + 1) % pts.len()]);
        }
        let ids: Vec<u32> = pts.iter().map(|&p| self.vertex(p, n)).collect();
        let flip = newell.dot(n) < 0.0;
        for i in 1..ids.len() - 1 {
            let (b, c) = if flip {
                (ids[i + 1], ids[i])
            } else {
                (ids[i], ids[i + 1])
            };
            self.mesh.indices.extend([ids[0], b, c]);
        }
    }

    /// The top face, cut around each stud's foot, and the studs, for the
    /// grid of cells `columns` (x) by `rows` (z) at `y = 0`.
    fn studded_top(&mut self, columns: &[f32], rows: &[f32]) {
        let up = Vec3::NEG_Y;
        let square = square_points();
        let circle = circle_points();
        let top = -STUD_HEIGHT;
        for &cz in rows {
            for &cx in columns {
                let at = |o: [f32; 2], y: f32| Vec3::new(cx + o[0], y, cz + o[1]);
                for k in 0..STUD_SEGMENTS {
                    let k1 = (k + 1) % STUD_SEGMENTS;
                    // The ring between the cell's square and the stud's foot.
                    self.polygon(
                        &[
                            at(circle[k], 0.0),
                            at(square[k], 0.0),
                            at(square[k1], 0.0),
                            at(circle[k1], 0.0),
                        ],
                        up,
                    );
                    // The stud's side, smooth: normals point along the radius.
                    let radial = |o: [f32; 2]| Vec3::new(o[0], 0.0, o[1]) / STUD_RADIUS;
                    let (n0, n1) = (radial(circle[k]), radial(circle[k1]));
                    let a = self.vertex(at(circle[k], 0.0), n0);
                    let b = self.vertex(at(circle[k1], 0.0), n1);
                    let c = self.vertex(at(circle[k1], top), n1);
                    let e = self.vertex(at(circle[k], top), n0);
                    // Counter-clockwise seen from outside: foot k -> foot
                    // k+1 -> head k+1 (the angle grows from +X toward +Z,
                    // and the head is at -Y).
                    self.mesh.indices.extend([a, b, c, a, c, e]);
                }
                let cap: Vec<Vec3> = circle.iter().map(|&o| at(o, top)).collect();
                self.polygon(&cap, up);
            }
        }
    }

    /// A coarse stud on the cell centred at `(cx, cz)`: a prism's sides,
    /// smooth as a full stud's, and its cap.
    fn stud_prism(&mut self, cx: f32, cz: f32) {
        let n = COARSE_STUD_SEGMENTS;
        let dir = |k: usize| {
            let a = std::f32::consts::TAU * (k % n) as f32 / n as f32;
            Vec3::new(a.cos(), 0.0, a.sin())
        };
        let at = |k: usize, y: f32| Vec3::new(cx, y, cz) + dir(k) * STUD_RADIUS;
        let top = -STUD_HEIGHT;
        for k in 0..n {
            let a = self.vertex(at(k, 0.0), dir(k));
            let b = self.vertex(at(k + 1, 0.0), dir(k + 1));
            let c = self.vertex(at(k + 1, top), dir(k + 1));
            let e = self.vertex(at(k, top), dir(k));
            // Wound as a full stud's side (see `studded_top`).
            self.mesh.indices.extend([a, b, c, a, c, e]);
        }
        let cap: Vec<Vec3> = (0..n).map(|k| at(k, top)).collect();
        self.polygon(&cap, Vec3::NEG_Y);
    }

    /// The body: the profile extruded over `x` in `±hx`, with the top face
    /// left to [`Builder::studded_top`]. `x_extras` and `z_extras` are the
    /// points the top face puts on its outer edges (across and along the
    /// profile), which the neighbouring faces must carry too.
    fn prism(&mut self, profile: &Profile, hx: f32, x_extras: &[f32], z_extras: &[f32]) {
        let c = &profile.corners;
        let n = c.len();
        let p3 = |x: f32, zy: [f32; 2]| Vec3::new(x, zy[1], zy[0]);
        // End caps: the profile with the top edge's points inserted.
        let mut cap: Vec<[f32; 2]> = vec![c[0], c[1]];
        let (zb, zf) = (c[1][0], c[2][0]);
        cap.extend(
            z_extras
                .iter()
                .rev()
                .filter(|&&z| z < zb && z > zf)
                .map(|&z| [z, 0.0]),
        );
        cap.extend_from_slice(&c[2..]);
        for side in [-1.0f32, 1.0] {
            let pts: Vec<Vec3> = cap.iter().map(|&zy| p3(side * hx, zy)).collect();
            self.polygon(&pts, Vec3::X * side);
        }
        // Side faces, one per profile edge except the top.
        let centre = profile.centroid();
        let inner: Vec<f32> = x_extras
            .iter()
            .copied()
            .filter(|&x| x > -hx && x < hx)
            .collect();
        for i in 0..n {
            if i == 1 {
                continue;
            }
            let (a, b) = (c[i], c[(i + 1) % n]);
            let edge = [b[0] - a[0], b[1] - a[1]];
            let mut normal = Vec3::new(0.0, edge[0], -edge[1]);
            let mid = [
                (a[0] + b[0]) / 2.0 - centre[0],
                (a[1] + b[1]) / 2.0 - centre[1],
            ];
            if normal.z * mid[0] + normal.y * mid[1] < 0.0 {
                normal = -normal;
            }
            let pts: Vec<Vec3> = if i + 1 == 1 {
                // Ends at the back top corner: its top edge meets the studs.
                let mut v = vec![p3(-hx, a), p3(hx, a), p3(hx, b)];
                v.extend(inner.iter().rev().map(|&x| p3(x, b)));
                v.push(p3(-hx, b));
                v
            } else if i == 2 {
                // Starts at the front top corner.
                let mut v = vec![p3(hx, b), p3(-hx, b), p3(-hx, a)];
                v.extend(inner.iter().map(|&x| p3(x, a)));
                v.push(p3(hx, a));
                v
            } else {
                vec![p3(-hx, a), p3(hx, a), p3(hx, b), p3(-hx, b)]
            };
            self.polygon(&pts, normal);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Cell, Rot};
    use std::collections::BTreeMap;

    fn mesh(id: &str) -> &'static PartMesh {
        part_mesh(PartKind::from_id(id).unwrap())
    }

    /// Area of the stud's 16-gon.
    fn stud_area() -> f64 {
        let r = f64::from(STUD_RADIUS);
        0.5 * STUD_SEGMENTS as f64 * r * r * (std::f64::consts::TAU / STUD_SEGMENTS as f64).sin()
    }

    fn expected_volume(spec: &PartSpec) -> f64 {
        let (w, d) = (f64::from(spec.studs_x), f64::from(spec.studs_y));
        let h = f64::from(spec.height_ldu());
        let run = 20.0 * (d - 1.0);
        let lip = f64::from(LIP_HEIGHT);
        let (body, studs) = match spec.shape {
            Shape::Rect => (20.0 * w * 20.0 * d * h, w * d),
            // Back row full height, then a trapezoid from h down to the lip.
            Shape::Slope => (20.0 * w * (20.0 * h + run * (h + lip) / 2.0), w),
            // The same solid upside down, with studs on every cell.
            Shape::Inverted => (20.0 * w * (20.0 * h + run * (h + lip) / 2.0), w * d),
        };
        body + studs * stud_area() * f64::from(STUD_HEIGHT)
    }

    fn expected_triangles(spec: &PartSpec) -> usize {
        let (w, d) = (spec.studs_x as usize, spec.studs_y as usize);
        // A stud: 16 ring quads, 16 side quads, a 16-gon cap.
        let stud = 2 * 16 + 2 * 16 + 14;
        match spec.shape {
            Shape::Rect => stud * w * d + 2 + 2 * (4 * w + 1) + 2 * (4 * d + 1),
            // Back wall, 2 end caps of 8 points, face, lip, bottom.
            Shape::Slope => stud * w + (4 * w + 1) + 2 * 6 + (4 * w + 1) + 2 + 2,
            // Back wall, 2 end caps, front lip, underside, bottom.
            Shape::Inverted => stud * w * d + (4 * w + 1) + 2 * (4 * d + 2) + (4 * w + 1) + 4,
        }
    }

    #[test]
    fn triangle_counts_follow_the_construction() {
        assert_eq!(mesh("3001").triangle_count(), 678);
        assert_eq!(mesh("3039").triangle_count(), 190);
        assert_eq!(mesh("3660a").triangle_count(), 354);
        for part in PartKind::all() {
            let spec = part.spec();
            let m = part_mesh(part);
            assert_eq!(m.triangle_count(), expected_triangles(spec), "{part}");
            assert_eq!(m.positions.len(), m.normals.len());
            assert!(m.indices.iter().all(|&i| (i as usize) < m.positions.len()));
        }
    }

    #[test]
    fn coarse_meshes_keep_the_bounds_and_the_winding_with_fewer_triangles() {
        assert_eq!(
            coarse_part_mesh(PartKind::from_id("3001").unwrap()).triangle_count(),
            140
        );
        for part in PartKind::all() {
            let (fine, coarse) = (part_mesh(part), coarse_part_mesh(part));
            assert_eq!(coarse.bounds(), fine.bounds(), "{part}");
            assert!(
                coarse.triangle_count() * 3 < fine.triangle_count(),
                "{part}"
            );
            for t in coarse.indices.chunks_exact(3) {
                let p = [0, 1, 2].map(|k| Vec3::from(coarse.positions[t[k] as usize]));
                let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
                for &i in t {
                    let n = Vec3::from(coarse.normals[i as usize]);
                    assert!(n.dot(face) > 0.8, "{part}: {n} vs {face}");
                }
            }
        }
    }

    #[test]
    fn bounding_boxes_are_the_catalog_sizes() {
        assert_eq!(
            mesh("3001").bounds(),
            Some(([-40.0, -4.0, -20.0], [40.0, 24.0, 20.0]))
        );
        assert_eq!(
            mesh("3020").bounds(),
            Some(([-40.0, -4.0, -20.0], [40.0, 8.0, 20.0]))
        );
        // Measured in 3039.dat and 3298.dat: back at +10, front at -30 / -50.
        assert_eq!(
            mesh("3039").bounds(),
            Some(([-20.0, -4.0, -30.0], [20.0, 24.0, 10.0]))
        );
        assert_eq!(
            mesh("3298").bounds(),
            Some(([-20.0, -4.0, -50.0], [20.0, 24.0, 10.0]))
        );
        assert_eq!(
            mesh("3665a").bounds(),
            Some(([-10.0, -4.0, -30.0], [10.0, 24.0, 10.0]))
        );
        for part in PartKind::all() {
            let s = part.spec();
            let (hx, hz) = (10.0 * f32::from(s.studs_x), 10.0 * f32::from(s.studs_y));
            let (zlo, zhi) = match s.shape {
                Shape::Rect => (-hz, hz),
                _ => (10.0 - 2.0 * hz, 10.0),
            };
            let want = ([-hx, -STUD_HEIGHT, zlo], [hx, s.height_ldu() as f32, zhi]);
            assert_eq!(part_mesh(part).bounds(), Some(want), "{part}");
        }
    }

    #[test]
    fn slopes_have_their_measured_faces() {
        // 3039.dat's slanted face: (y 0, z -10) to (y 20, z -30); 3665a's
        // underside: (y 24, z -10) to (y 4, z -30).
        let has = |m: &PartMesh, p: [f32; 3]| m.positions.contains(&p);
        let s = mesh("3039");
        assert!(has(s, [20.0, 0.0, -10.0]) && has(s, [20.0, 20.0, -30.0]));
        let s = mesh("3298");
        assert!(has(s, [20.0, 0.0, -10.0]) && has(s, [20.0, 20.0, -50.0]));
        let inv = mesh("3665a");
        assert!(has(inv, [10.0, 24.0, -10.0]) && has(inv, [10.0, 4.0, -30.0]));
        // The slanted face's normal points up (-Y) and forward (-Z).
        let n = s
            .positions
            .iter()
            .zip(&s.normals)
            .find(|(p, n)| **p == [20.0, 20.0, -50.0] && n[1] < 0.0)
            .map(|(_, n)| *n)
            .unwrap();
        assert!(n[1] < -0.85 && n[2] < -0.4, "{n:?}");
    }

    #[test]
    fn meshes_are_closed_and_consistently_wound() {
        for part in PartKind::all() {
            let m = part_mesh(part);
            // Weld by position, then count directed edges.
            let mut ids: HashMap<[u32; 3], usize> = HashMap::new();
            let weld: Vec<usize> = m
                .positions
                .iter()
                .map(|p| {
                    let n = ids.len();
                    *ids.entry(p.map(f32::to_bits)).or_insert(n)
                })
                .collect();
            let mut edges: BTreeMap<(usize, usize), i32> = BTreeMap::new();
            for t in m.indices.chunks_exact(3) {
                let v = [0, 1, 2].map(|k| weld[t[k] as usize]);
                assert!(v[0] != v[1] && v[1] != v[2] && v[0] != v[2], "{part}");
                for k in 0..3 {
                    *edges.entry((v[k], v[(k + 1) % 3])).or_default() += 1;
                }
            }
            for (&(a, b), &n) in &edges {
                assert_eq!(n, 1, "{part}: edge {a}->{b} used {n} times");
                assert_eq!(edges.get(&(b, a)), Some(&1), "{part}: edge {a}->{b} open");
            }
        }
    }

    #[test]
    fn normals_point_outward_and_volumes_match() {
        for part in PartKind::all() {
            let m = part_mesh(part);
            let want = expected_volume(part.spec());
            let got = m.volume();
            assert!((got - want).abs() < 1e-3 * want, "{part}: {got} vs {want}");
            // Each triangle's stored normals agree with its winding.
            for t in m.indices.chunks_exact(3) {
                let p = [0, 1, 2].map(|k| Vec3::from(m.positions[t[k] as usize]));
                let face = (p[1] - p[0]).cross(p[2] - p[0]);
                assert!(face.length() > 1e-4, "{part}: degenerate triangle");
                for &i in t {
                    let n = Vec3::from(m.normals[i as usize]);
                    assert!((n.length() - 1.0).abs() < 1e-5, "{part}");
                    assert!(n.dot(face.normalize()) > 0.9, "{part}: {n} vs {face}");
                }
            }
        }
    }

    #[test]
    fn placed_bodies_fill_their_cells() {
        // The transformed body (studs left out) spans the placement's cells.
        for part in PartKind::all() {
            for r in Rot::ALL {
                let p = Placement {
                    part,
                    origin: Cell::new(2, -3, 4),
                    rot: r,
                };
                let t = piece_transform(&p, 8);
                let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
                for &q in &part_mesh(part).positions {
                    if q[1] < 0.0 {
                        continue;
                    }
                    let w = t.transform_point3(Vec3::from(q));
                    lo = lo.min(w);
                    hi = hi.max(w);
                }
                let b = p.body(8).bbox;
                let m = b.max_excl();
                let want_lo = Vec3::new(
                    20.0 * b.min.x as f32,
                    -8.0 * m.z as f32,
                    20.0 * b.min.y as f32,
                );
                let want_hi =
                    Vec3::new(20.0 * m.x as f32, -8.0 * b.min.z as f32, 20.0 * m.y as f32);
                assert_eq!((lo, hi), (want_lo, want_hi), "{part} {r:?}");
            }
        }
    }
}
