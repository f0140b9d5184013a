//! The renderer's input: triangles in LDraw world space, grouped by piece.
//!
//! A [`Scene`] knows nothing of parts or grids: each piece is a colour, the
//! step that adds it, and its triangles (world LDU, -Y up) with outward unit
//! normals. [`Scene::from_assembly`](Scene::from_assembly) fills one from an
//! [`Assembly`](crate::assembly::Assembly); tests and other callers may add
//! any geometry with [`Scene::add_piece`].

use std::ops::Range;

use glam::{Affine3A, Vec3};
use image::Rgb;

use crate::assembly::{Assembly, Step};
use crate::catalog::{Color, PartKind};
use crate::export::partmesh::{part_mesh, piece_transform, PartMesh};

/// One triangle of a piece, in world coordinates (LDU).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triangle {
    /// The three corners.
    pub positions: [Vec3; 3],
    /// The outward unit normal of the face, used for shading, back-face
    /// culling and crease outlines.
    pub normal: Vec3,
}

impl Triangle {
    /// A triangle whose normal follows its winding: counter-clockwise seen
    /// from outside (`(b - a) x (c - a)` points out). A degenerate triangle
    /// gets a zero normal and is never drawn.
    pub fn from_winding(positions: [Vec3; 3]) -> Triangle {
        let [a, b, c] = positions;
        Triangle {
            positions,
            normal: (b - a).cross(c - a).normalize_or_zero(),
        }
    }
}

/// One piece of a scene: how it looks and when it is added.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenePiece {
    /// Base colour (sRGB), before shading.
    pub color: Rgb<u8>,
    /// The building step that adds it.
    pub step: Step,
    /// Its triangles in [`Scene::triangles`].
    triangles: Range<usize>,
}

/// Pieces and their triangles, in the order they were added.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    pieces: Vec<ScenePiece>,
    triangles: Vec<Triangle>,
}

impl Scene {
    /// An empty scene.
    pub fn new() -> Scene {
        Scene::default()
    }

    /// Adds a piece and returns its index. Triangles with a zero or
    /// non-finite normal or corner are dropped (they cannot be drawn).
    pub fn add_piece(
        &mut self,
        color: Rgb<u8>,
        step: Step,
        triangles: impl IntoIterator<Item = Triangle>,
    ) -> usize {
        let start = self.triangles.len();
        self.triangles.extend(triangles.into_iter().filter(|t| {
            t.normal.is_finite()
                && t.normal.length_squared() > 0.5
                && t.positions.iter().all(|p| p.is_finite())
        }));
        self.pieces.push(ScenePiece {
            color,
            step,
            triangles: start..self.triangles.len(),
        });
        self.pieces.len() - 1
    }

    /// The scene of an assembly: every piece's part mesh
    /// ([`part_mesh`]) placed exactly as its `.ldr` line places it
    /// ([`piece_transform`]), in its colour and step.
    ///
    /// The pieces' triangles are made on rayon's threads a batch at a time
    /// and added in order: the same scene as adding them one by one, with
    /// no more than a batch held twice (a 5,000-piece build's scene is
    /// about 150 MB).
    pub fn from_assembly(assembly: &Assembly) -> Scene {
        use rayon::prelude::*;
        const BATCH: usize = 256;
        let mut scene = Scene::new();
        let most: usize = assembly
            .pieces
            .iter()
            .map(|p| part_mesh(p.placement.part).indices.len() / 3)
            .sum();
        scene.triangles.reserve_exact(most);
        for batch in assembly.pieces.chunks(BATCH) {
            let made: Vec<Vec<Triangle>> = batch
                .par_iter()
                .map(|p| {
                    let at = piece_transform(&p.placement, assembly.layer_ldu);
                    mesh_triangles(part_mesh(p.placement.part), at).collect()
                })
                .collect();
            for (p, t) in batch.iter().zip(made) {
                scene.add_piece(Rgb(p.color.rgb()), p.step, t);
            }
        }
        scene
    }

    /// Adds one part, its mesh moved by `transform` (a rotation and a
    /// translation, as [`piece_transform`] gives), and returns its index.
    pub fn add_part(
        &mut self,
        part: PartKind,
        transform: Affine3A,
        color: Color,
        step: Step,
    ) -> usize {
        self.add_piece(
            Rgb(color.rgb()),
            step,
            mesh_triangles(part_mesh(part), transform),
        )
    }

    /// Gives piece `i` colour `colors[i]`, for pictures that colour pieces
    /// by a measure; fails unless there is one colour a piece.
    pub fn recolor(&mut self, colors: &[Rgb<u8>]) -> Result<(), super::RenderError> {
        if colors.len() != self.pieces.len() {
            return Err(super::RenderError::Colors {
                expected: self.pieces.len(),
                got: colors.len(),
            });
        }
        for (p, &c) in self.pieces.iter_mut().zip(colors) {
            p.color = c;
        }
        Ok(())
    }

    /// Every piece, in the order added.
    pub fn pieces(&self) -> &[ScenePiece] {
        &self.pieces
    }

    /// The triangles of piece `i` (none for an index out of range).
    pub fn piece_triangles(&self, i: usize) -> &[Triangle] {
        self.pieces
            .get(i)
            .map_or(&[][..], |p| &self.triangles[p.triangles.clone()])
    }

    /// Every corner of every triangle, for fitting a camera.
    pub fn points(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.triangles.iter().flat_map(|t| t.positions)
    }

    /// True when the scene has no triangles to draw.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }
}

/// The triangles of `mesh` moved by `transform`, each with the mean of its
/// vertex normals (a stud's facet gets its own radial direction, a flat face
/// its face normal), or the winding's normal where the mesh has none.
fn mesh_triangles(mesh: &PartMesh, transform: Affine3A) -> impl Iterator<Item = Triangle> + '_ {
    mesh.indices.chunks_exact(3).filter_map(move |t| {
        let corner = |k: usize| mesh.positions.get(t[k] as usize).map(|&p| Vec3::from(p));
        let positions = [corner(0)?, corner(1)?, corner(2)?].map(|p| transform.transform_point3(p));
        let winding = Triangle::from_winding(positions);
        let mean: Option<Vec3> = (0..3)
            .map(|k| mesh.normals.get(t[k] as usize).map(|&n| Vec3::from(n)))
            .sum();
        let normal = mean
            .map(|n| transform.transform_vector3(n).normalize_or_zero())
            .filter(|n| n.dot(winding.normal) > 0.0)
            .unwrap_or(winding.normal);
        Some(Triangle { positions, normal })
    })
}

/// The 12 outward-wound triangles of the axis-aligned box `lo..hi`.
pub(crate) fn cuboid(lo: Vec3, hi: Vec3) -> Vec<Triangle> {
    let c = |x: bool, y: bool, z: bool| {
        Vec3::new(
            if x { hi.x } else { lo.x },
            if y { hi.y } else { lo.y },
            if z { hi.z } else { lo.z },
        )
    };
    // Each face: four corners counter-clockwise seen from outside.
    let faces = [
        [
            c(true, false, false),
            c(true, true, false),
            c(true, true, true),
            c(true, false, true),
        ], // +X
        [
            c(false, false, false),
            c(false, false, true),
            c(false, true, true),
            c(false, true, false),
        ], // -X
        [
            c(false, true, false),
            c(false, true, true),
            c(true, true, true),
            c(true, true, false),
        ], // +Y
        [
            c(false, false, false),
            c(true, false, false),
            c(true, false, true),
            c(false, false, true),
        ], // -Y
        [
            c(false, false, true),
            c(true, false, true),
            c(true, true, true),
            c(false, true, true),
        ], // +Z
        [
            c(false, false, false),
            c(false, true, false),
            c(true, true, false),
            c(true, false, false),
        ], // -Z
    ];
    faces
        .iter()
        .flat_map(|[a, b, c, d]| {
            [
                Triangle::from_winding([*a, *b, *c]),
                Triangle::from_winding([*a, *c, *d]),
            ]
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod test_geometry {
    //! Boxes for the renderer's own tests (the library's part meshes come
    //! from `export::partmesh`).
    pub(crate) use super::cuboid;
    use super::*;

    #[test]
    fn cuboid_normals_point_out() {
        let lo = Vec3::new(-1.0, -2.0, -3.0);
        let hi = Vec3::new(1.0, 2.0, 3.0);
        let centre = (lo + hi) / 2.0;
        for t in cuboid(lo, hi) {
            let mid = (t.positions[0] + t.positions[1] + t.positions[2]) / 3.0;
            assert!(t.normal.dot(mid - centre) > 0.0, "{t:?}");
        }
    }
}
