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
//!   `+10` at the back to `10 - 20·depth` at the front, toward -Z);
//! - corner slopes (3045) and inverted corner slopes (3676): the centre of
//!   the top of the full-height cell, on the back row at -X (`x` from `-10`
//!   to `20·studs_x - 10`, `z` from `+10` to `10 - 20·depth`).
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
//! from the back row to a 4 LDU lip. A corner slope (3045) is the
//! intersection of two such slope prisms at right angles: from its one
//! full-height cell its faces fall at 45° to +X and to -Z, meeting along a
//! hip, down to 4 LDU lips; an inverted corner slope (3676) is the same solid
//! upside down, its underside rising from its one full-height cell. Studs
//! are 16-sided cylinders of radius 6 LDU and height 4 on the studded cells
//! (every top cell, a slope's back row only, a corner slope's full cell
//! only). Bodies are solid: no hollow underside or tubes, which a picture of
//! an assembled model never shows.
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
    if spec.shape.is_corner() {
        return build_corner_mesh(spec, false);
    }
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
    if spec.shape.is_corner() {
        return build_corner_mesh(spec, true);
    }
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

/// A prism part's profile, half width and the centres of its stud columns
/// (x) and rows (z).
fn layout(spec: &PartSpec) -> (Profile, f32, Vec<f32>, Vec<f32>) {
    let w = i32::from(spec.studs_x.max(1));
    let d = i32::from(spec.studs_y.max(1));
    let h = spec.height_ldu().max(8) as f32;
    let (columns, rows) = stud_grid(spec);
    (
        Profile::of(spec.shape, d, h),
        10.0 * w as f32,
        columns,
        rows,
    )
}

/// The centres of a part's studded cells: its columns (x) and rows (z).
fn stud_grid(spec: &PartSpec) -> (Vec<f32>, Vec<f32>) {
    let w = i32::from(spec.studs_x.max(1));
    let d = i32::from(spec.studs_y.max(1));
    let centred: Vec<f32> = (0..w).map(|i| (20 * i - 10 * w + 10) as f32).collect();
    let from_back = || (0..d).rev().map(|j| (-20 * j) as f32).collect();
    match spec.shape {
        Shape::Rect => (
            centred,
            (0..d).map(|j| (20 * j - 10 * d + 10) as f32).collect(),
        ),
        Shape::Slope => (centred, vec![0.0]),
        Shape::Inverted => (centred, from_back()),
        // The origin is on the -X back cell: columns run from it toward +X.
        Shape::Corner => (vec![0.0], vec![0.0]),
        Shape::InvertedCorner => ((0..w).map(|i| (20 * i) as f32).collect(), from_back()),
    }
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
/// from corner 1 to corner 2 is the (studded) top. A corner slope is no
/// prism (its faces come from [`corner_faces`]); its profile here is its
/// slope's, its section across its full cell (its face at `x = -10`).
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
            Shape::Slope | Shape::Corner => vec![
                [10.0, h],
                [10.0, 0.0],
                [-10.0, 0.0],
                [front, h - LIP_HEIGHT],
                [front, h],
            ],
            Shape::Inverted | Shape::InvertedCorner => vec![
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

/// A planar face: its corners in order and a vector pointing out of the
/// solid.
type Face = (Vec<Vec3>, Vec3);

/// Builds a corner slope's mesh ([`Shape::Corner`], [`Shape::InvertedCorner`]):
/// its convex body's faces, each carrying every vertex that another face
/// (or the studded top's cells) puts on its edges, with the studded top and
/// full studs, or with `coarse` a plain top and [`Builder::stud_prism`]s.
fn build_corner_mesh(spec: &PartSpec, coarse: bool) -> PartMesh {
    let (columns, rows) = stud_grid(spec);
    let (top, mut faces) = corner_faces(spec);
    let mut b = Builder::default();
    if coarse {
        faces.insert(0, top);
    } else {
        b.studded_top(&columns, &rows);
    }
    let mut points: Vec<Vec3> = faces.iter().flat_map(|f| f.0.iter().copied()).collect();
    if !coarse {
        // The points the studded cells put on their squares' edges, computed
        // exactly as `studded_top` does.
        for &cz in &rows {
            for &cx in &columns {
                points.extend(
                    square_points()
                        .iter()
                        .map(|o| Vec3::new(cx + o[0], 0.0, cz + o[1])),
                );
            }
        }
    }
    for (corners, outward) in &faces {
        b.convex_face(&with_edge_points(corners, &points), *outward);
    }
    if coarse {
        for &cz in &rows {
            for &cx in &columns {
                b.stud_prism(cx, cz);
            }
        }
    }
    b.mesh
}

/// A corner slope's faces: its studded top (the full cell's square for
/// 3045, the whole footprint for 3676) and the others.
///
/// The upright solid (3045) is the points of its footprint (`x` from -10 to
/// `far`, `z` from `front` to +10) between `y = 0` and the bottom `y = h`,
/// and under both slanted planes: face A through the line `x = 10, y = 0`
/// and `x = far, y = h - lip`, face B through `z = -10, y = 0` and
/// `z = front, y = h - lip`. They meet along the hip from `(10, 0, -10)` to
/// `(far, h - lip, front)`. Its faces at `x = -10` and `z = +10` are the
/// slope's [`Profile`]. The inverted solid (3676) is the same mirrored
/// through `y = h / 2`.
fn corner_faces(spec: &PartSpec) -> (Face, Vec<Face>) {
    let h = spec.height_ldu().max(8) as f32;
    let far = (20 * i32::from(spec.studs_x.max(2)) - 10) as f32;
    let front = (10 - 20 * i32::from(spec.studs_y.max(2))) as f32;
    let low = h - LIP_HEIGHT;
    let p = Vec3::new;
    let mut faces: Vec<Face> = vec![
        // The full cell's top.
        (
            vec![
                p(-10.0, 0.0, 10.0),
                p(10.0, 0.0, 10.0),
                p(10.0, 0.0, -10.0),
                p(-10.0, 0.0, -10.0),
            ],
            Vec3::NEG_Y,
        ),
        // Face A, falling toward +X.
        (
            vec![
                p(10.0, 0.0, 10.0),
                p(10.0, 0.0, -10.0),
                p(far, low, front),
                p(far, low, 10.0),
            ],
            Vec3::new(low, 10.0 - far, 0.0),
        ),
        // Face B, falling toward -Z.
        (
            vec![
                p(10.0, 0.0, -10.0),
                p(-10.0, 0.0, -10.0),
                p(-10.0, low, front),
                p(far, low, front),
            ],
            Vec3::new(0.0, front + 10.0, -low),
        ),
        // The lips.
        (
            vec![
                p(far, low, 10.0),
                p(far, low, front),
                p(far, h, front),
                p(far, h, 10.0),
            ],
            Vec3::X,
        ),
        (
            vec![
                p(-10.0, low, front),
                p(far, low, front),
                p(far, h, front),
                p(-10.0, h, front),
            ],
            Vec3::NEG_Z,
        ),
        // The back faces.
        (
            vec![
                p(-10.0, h, 10.0),
                p(-10.0, 0.0, 10.0),
                p(10.0, 0.0, 10.0),
                p(far, low, 10.0),
                p(far, h, 10.0),
            ],
            Vec3::Z,
        ),
        (
            vec![
                p(-10.0, h, 10.0),
                p(-10.0, 0.0, 10.0),
                p(-10.0, 0.0, -10.0),
                p(-10.0, low, front),
                p(-10.0, h, front),
            ],
            Vec3::NEG_X,
        ),
        // The bottom.
        (
            vec![
                p(-10.0, h, 10.0),
                p(far, h, 10.0),
                p(far, h, front),
                p(-10.0, h, front),
            ],
            Vec3::Y,
        ),
    ];
    if spec.shape == Shape::InvertedCorner {
        let flip = |v: Vec3| Vec3::new(v.x, h - v.y, v.z);
        for (corners, outward) in &mut faces {
            for c in corners.iter_mut() {
                *c = flip(*c);
            }
            outward.y = -outward.y;
        }
        // The bottom, turned over, is the studded top.
        faces.rotate_right(1);
    }
    let top = faces.remove(0);
    (top, faces)
}

/// The polygon `corners` with, on each edge, every point of `points` lying
/// strictly inside that edge inserted in order along it (duplicates once).
fn with_edge_points(corners: &[Vec3], points: &[Vec3]) -> Vec<Vec3> {
    let mut out = Vec::new();
    for (i, &a) in corners.iter().enumerate() {
        let b = corners[(i + 1) % corners.len()];
        let e = b - a;
        let len2 = e.length_squared();
        let mut on: Vec<(f32, Vec3)> = points
            .iter()
            .filter(|&&q| q != a && q != b)
            .filter_map(|&q| {
                let t = (q - a).dot(e) / len2;
                let off = (q - a).cross(e).length_squared() / len2;
                (t > 0.0 && t < 1.0 && off < 1e-6).then_some((t, q))
            })
            .collect();
        on.sort_by(|x, y| x.0.total_cmp(&y.0));
        on.dedup_by(|x, y| x.1 == y.1);
        out.push(a);
        out.extend(on.into_iter().map(|(_, q)| q));
    }
    out
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

    /// A planar convex polygon whose edges may carry intermediate points
    /// (`pts` in order): fanned from a corner whose two edges carry none,
    /// or if there is no such corner, from a new vertex at the corners'
    /// centroid.
    fn convex_face(&mut self, pts: &[Vec3], outward: Vec3) {
        let n = pts.len();
        if n < 3 {
            return;
        }
        let corner = |i: usize| {
            let (a, b, c) = (pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]);
            let (u, v) = (b - a, c - b);
            u.cross(v).length_squared() > 1e-6 * u.length_squared() * v.length_squared()
        };
        let apex = (0..n).find(|&i| corner(i) && corner((i + 1) % n) && corner((i + n - 1) % n));
        if let Some(i) = apex {
            let fan: Vec<Vec3> = pts[i..].iter().chain(&pts[..i]).copied().collect();
            self.polygon(&fan, outward);
            return;
        }
        let corners: Vec<Vec3> = (0..n).filter(|&i| corner(i)).map(|i| pts[i]).collect();
        let centre = corners.iter().copied().sum::<Vec3>() / corners.len().max(1) as f32;
        for i in 0..n {
            self.polygon(&[centre, pts[i], pts[(i + 1) % n]], outward);
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
            // The full cell, two strips under one slanted face (a slope's
            // trapezoid), and the square under the hip: there the depth is
            // h less the drop, which is the larger of two uniform ones.
            Shape::Corner | Shape::InvertedCorner => {
                let drop = h - lip;
                let body = 20.0 * 20.0 * h
                    + 2.0 * 20.0 * run * (h + lip) / 2.0
                    + run * run * (h - 2.0 * drop / 3.0);
                let studs = if spec.shape == Shape::Corner {
                    1.0
                } else {
                    w * d
                };
                (body, studs)
            }
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
            // Two slanted quads carrying the stud's 3 points on their top
            // edge, two back pentagons carrying them too, two lips, bottom.
            Shape::Corner => stud + 2 * 5 + 2 * 6 + 2 * 2 + 2,
            // Two back pentagons and two lips along the top's outer edges
            // (4 points a cell, less one), two slanted quads, bottom.
            Shape::InvertedCorner => {
                stud * w * d + (4 * w + 2) + (4 * d + 2) + (4 * d + 1) + (4 * w + 1) + 3 * 2
            }
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
            // A corner slope's origin is on its -X cell.
            let (xlo, xhi) = if s.shape.is_corner() {
                (-10.0, 2.0 * hx - 10.0)
            } else {
                (-hx, hx)
            };
            let want = ([xlo, -STUD_HEIGHT, zlo], [xhi, s.height_ldu() as f32, zhi]);
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

    /// Panics unless `m` is one closed surface: welded by position, every
    /// directed edge is used once and its reverse once.
    fn assert_closed(m: &PartMesh, part: PartKind) {
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
        assert!(!edges.is_empty(), "{part}: empty mesh");
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1, "{part}: edge {a}->{b} used {n} times");
            assert_eq!(edges.get(&(b, a)), Some(&1), "{part}: edge {a}->{b} open");
        }
    }

    #[test]
    fn meshes_are_closed_and_consistently_wound() {
        for part in PartKind::all() {
            assert_closed(part_mesh(part), part);
        }
    }

    /// The heights `y` of `m`'s surface over the point `(x, z)`.
    fn heights_over(m: &PartMesh, x: f32, z: f32) -> Vec<f32> {
        let mut out = Vec::new();
        for [a, b, c] in m.triangles() {
            let d = (b.x - a.x) * (c.z - a.z) - (c.x - a.x) * (b.z - a.z);
            if d.abs() < 1e-6 {
                continue; // vertical
            }
            let u = ((x - a.x) * (c.z - a.z) - (c.x - a.x) * (z - a.z)) / d;
            let v = ((b.x - a.x) * (z - a.z) - (x - a.x) * (b.z - a.z)) / d;
            if u >= -1e-5 && v >= -1e-5 && u + v <= 1.0 + 1e-5 {
                out.push(a.y + u * (b.y - a.y) + v * (c.y - a.y));
            }
        }
        out
    }

    /// How many studs `m` has: distinct vertices on the studs' caps, a
    /// cap having `segments`.
    fn studs(m: &PartMesh, segments: usize) -> usize {
        let mut caps: Vec<[u32; 3]> = m
            .positions
            .iter()
            .filter(|p| p[1] == -STUD_HEIGHT)
            .map(|p| p.map(f32::to_bits))
            .collect();
        caps.sort_unstable();
        caps.dedup();
        assert_eq!(caps.len() % segments, 0);
        caps.len() / segments
    }

    #[test]
    fn corner_slopes_are_closed_and_watertight() {
        for id in ["3045", "3676"] {
            let part = PartKind::from_id(id).unwrap();
            assert!(part.spec().shape.is_corner());
            assert_closed(part_mesh(part), part);
        }
        assert_eq!(mesh("3045").triangle_count(), 106);
        assert_eq!(mesh("3676").triangle_count(), 356);
    }

    #[test]
    fn corner_slopes_span_their_ldraw_footprints() {
        let want = Some(([-10.0, -4.0, -30.0], [30.0, 24.0, 10.0]));
        for id in ["3045", "3676"] {
            let part = PartKind::from_id(id).unwrap();
            assert_eq!(part_mesh(part).bounds(), want, "{id}");
            assert_eq!(coarse_part_mesh(part).bounds(), want, "{id}");
        }
    }

    #[test]
    fn corner_slopes_have_their_studs() {
        // 3045's one stud stands on its full cell, at the origin.
        assert_eq!(studs(mesh("3045"), STUD_SEGMENTS), 1);
        assert!(mesh("3045")
            .positions
            .iter()
            .filter(|p| p[1] == -STUD_HEIGHT)
            .all(|p| p[0].hypot(p[2]) <= STUD_RADIUS + 1e-4));
        assert_eq!(studs(mesh("3676"), STUD_SEGMENTS), 4);
        let coarse = |id| coarse_part_mesh(PartKind::from_id(id).unwrap());
        assert_eq!(studs(coarse("3045"), COARSE_STUD_SEGMENTS), 1);
        assert_eq!(studs(coarse("3676"), COARSE_STUD_SEGMENTS), 4);
        // 3676's studs are on its four cells' centres.
        for (x, z) in [(0.0, 0.0), (20.0, 0.0), (0.0, -20.0), (20.0, -20.0)] {
            let top = heights_over(mesh("3676"), x, z);
            assert!(top.contains(&-STUD_HEIGHT), "({x}, {z}): {top:?}");
        }
    }

    #[test]
    fn corner_slopes_have_their_measured_faces() {
        // 3045.dat: the faces fall from y 0 at the full cell's edges to
        // y 20 at the lips, meeting along the hip (10, 0, -10)-(30, 20, -30).
        let top = |m: &PartMesh, x, z| {
            heights_over(m, x, z)
                .into_iter()
                .fold(f32::INFINITY, f32::min)
        };
        let under = |m: &PartMesh, x, z| {
            heights_over(m, x, z)
                .into_iter()
                .fold(f32::NEG_INFINITY, f32::max)
        };
        let s = mesh("3045");
        assert_eq!(top(s, 20.0, 0.0), 10.0); // face A
        assert_eq!(top(s, 0.0, -20.0), 10.0); // face B
        assert_eq!(top(s, 20.0, -20.0), 10.0); // the hip
        assert!((top(s, 25.0, -15.0) - 15.0).abs() < 1e-4); // A beside the hip
        assert!((top(s, 15.0, -25.0) - 15.0).abs() < 1e-4); // B beside the hip
        assert_eq!(top(s, 30.0, -30.0), 20.0);
        assert_eq!(under(s, 20.0, -20.0), 24.0);
        let has = |m: &PartMesh, p: [f32; 3]| m.positions.contains(&p);
        assert!(has(s, [10.0, 0.0, -10.0]) && has(s, [30.0, 20.0, -30.0]));
        // Face A's normal points up (-Y) and toward +X, B's up and toward -Z.
        let normal_at = |m: &PartMesh, p: [f32; 3], keep: fn(&[f32; 3]) -> bool| {
            m.positions
                .iter()
                .zip(&m.normals)
                .find(|(q, n)| **q == p && keep(n))
                .map(|(_, n)| *n)
                .unwrap()
        };
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let a = normal_at(s, [30.0, 20.0, 10.0], |n| n[0] > 0.1 && n[1] < -0.1);
        assert!(
            (Vec3::from(a) - Vec3::new(h, -h, 0.0)).length() < 1e-5,
            "{a:?}"
        );
        let b = normal_at(s, [-10.0, 20.0, -30.0], |n| n[2] < -0.1 && n[1] < -0.1);
        assert!(
            (Vec3::from(b) - Vec3::new(0.0, -h, -h)).length() < 1e-5,
            "{b:?}"
        );
        // 3676.dat: the underside rises from y 24 under the full cell to
        // y 4 at the lips.
        let inv = mesh("3676");
        assert_eq!(under(inv, 20.0, 0.0), 14.0);
        assert_eq!(under(inv, 0.0, -20.0), 14.0);
        assert_eq!(under(inv, 20.0, -20.0), 14.0);
        assert_eq!(under(inv, 0.0, 0.0), 24.0);
        assert_eq!(under(inv, 30.0, -30.0), 4.0);
        assert!(has(inv, [10.0, 24.0, -10.0]) && has(inv, [30.0, 4.0, -30.0]));
        let a = normal_at(inv, [30.0, 4.0, 10.0], |n| n[0] > 0.1 && n[1] > 0.1);
        assert!(
            (Vec3::from(a) - Vec3::new(h, h, 0.0)).length() < 1e-5,
            "{a:?}"
        );
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
