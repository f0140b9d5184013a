//! The closed test shapes, each with the shell volumes it must have.
//!
//! All shapes are Y-up, stand on the ground plane y = 0, and are closed,
//! outward-facing triangle surfaces. Prisms are one polyhedron made by
//! extruding a profile along z, so no two closed parts overlap (overlaps would
//! make ray-parity inside tests wrong inside the overlap).

use std::f64::consts::{PI, TAU};

use crate::mesh::{ngon_area, twice_area, Mesh};

/// A closed shape and the volumes its shells must have.
pub struct Shape {
    /// File name under the fixture directory.
    pub file: &'static str,
    /// The mesh.
    pub mesh: Mesh,
    /// Expected shell volumes in units³, largest first, with absolute
    /// tolerances.
    pub expected: Vec<(f64, f64)>,
}

/// Tolerance for polyhedra whose volume is known exactly (grid rounding only).
const EXACT: f64 = 1e-6;

/// All closed OBJ and STL shapes.
pub fn all() -> Vec<Shape> {
    vec![
        box_shape(),
        staircase(),
        house(),
        barn(),
        mug(),
        arch(),
        floating(),
        wedge(),
        skyscraper(),
        shuttle(),
    ]
}

/// A 4 (x) by 3 (y, up) by 2 (z) box with a corner at the origin.
fn box_shape() -> Shape {
    let mut mesh = Mesh::default();
    mesh.add_box([0.0, 0.0, 0.0], [4.0, 3.0, 2.0]);
    Shape {
        file: "box.obj",
        mesh,
        expected: vec![(24.0, EXACT)],
    }
}

/// Four steps, each 1 deep (x) and 1 high, rising along +x, 2 wide (z).
fn staircase() -> Shape {
    let mut profile = vec![[0.0, 0.0], [4.0, 0.0]];
    for step in (1..=4).rev() {
        let (x, y) = (f64::from(step), f64::from(step));
        profile.push([x, y]);
        profile.push([x - 1.0, y]);
    }
    // The last point pushed is (0, 1); the profile closes back to (0, 0).
    let mut mesh = Mesh::default();
    mesh.extrude(&profile, 0.0, 2.0);
    Shape {
        file: "staircase.obj",
        mesh,
        expected: vec![(20.0, EXACT)],
    }
}

/// Walls 6 wide (x), 4 high, 8 deep (z), under a gable roof rising 3 more to a
/// ridge along z: the pentagon profile extruded along the depth.
fn house() -> Shape {
    let profile = [[0.0, 0.0], [6.0, 0.0], [6.0, 4.0], [3.0, 7.0], [0.0, 4.0]];
    let mut mesh = Mesh::default();
    mesh.extrude(&profile, 0.0, 8.0);
    Shape {
        file: "house.obj",
        mesh,
        expected: vec![((24.0 + 9.0) * 8.0, EXACT)],
    }
}

/// A long barn: walls 8 wide (x), 3 high, 12 deep (z), under a shallow gable
/// roof rising 2.5 to a ridge along z (about 32 degrees, the pitch of a 33
/// degree slope).
fn barn() -> Shape {
    let profile = [[0.0, 0.0], [8.0, 0.0], [8.0, 3.0], [4.0, 5.5], [0.0, 3.0]];
    let mut mesh = Mesh::default();
    mesh.extrude(&profile, 0.0, 12.0);
    Shape {
        file: "barn.obj",
        mesh,
        expected: vec![((24.0 + 10.0) * 12.0, EXACT)],
    }
}

/// Two pillars 2 wide and 5 high with a gap of 4, under a span 1.5 thick:
/// a "Π" profile 8 wide and 6.5 high extruded 2 deep along z.
fn arch() -> Shape {
    let profile = [
        [0.0, 0.0],
        [2.0, 0.0],
        [2.0, 5.0],
        [6.0, 5.0],
        [6.0, 0.0],
        [8.0, 0.0],
        [8.0, 6.5],
        [0.0, 6.5],
    ];
    let mut mesh = Mesh::default();
    mesh.extrude(&profile, 0.0, 2.0);
    Shape {
        file: "arch.obj",
        mesh,
        expected: vec![((8.0 * 6.5 - 4.0 * 5.0) * 2.0, EXACT)],
    }
}

/// A 4 x 1 x 4 slab on the ground and a 2 x 1 x 2 box floating 1 above it.
fn floating() -> Shape {
    let mut mesh = Mesh::default();
    mesh.add_box([0.0, 0.0, 0.0], [4.0, 1.0, 4.0]);
    mesh.add_box([1.0, 2.0, 1.0], [3.0, 3.0, 3.0]);
    Shape {
        file: "floating.obj",
        mesh,
        expected: vec![(16.0, EXACT), (4.0, EXACT)],
    }
}

/// A ramp: the right triangle (0,0), (4,0), (0,2) extruded 3 deep along z.
fn wedge() -> Shape {
    let mut mesh = Mesh::default();
    mesh.extrude(&[[0.0, 0.0], [4.0, 0.0], [0.0, 2.0]], 0.0, 3.0);
    Shape {
        file: "wedge.stl",
        mesh,
        expected: vec![(12.0, EXACT)],
    }
}

/// The paper's skyscraper (Lau et al., Figure 6): five setback tiers, each a
/// box centred on the y axis standing on the one below, which it touches
/// face to face (separate shells, no overlap): (width x, depth z, height).
const SKYSCRAPER_TIERS: [(f64, f64, f64); 5] = [
    (8.0, 6.0, 3.0),
    (6.0, 5.0, 3.0),
    (5.0, 4.0, 3.0),
    (4.0, 3.0, 3.0),
    (2.0, 2.0, 2.0),
];

/// A skyscraper in five parts: [`SKYSCRAPER_TIERS`] stacked, 14 high.
fn skyscraper() -> Shape {
    let mut mesh = Mesh::default();
    let mut y = 0.0;
    let mut expected = Vec::new();
    for (w, d, h) in SKYSCRAPER_TIERS {
        mesh.add_box([-w / 2.0, y, -d / 2.0], [w / 2.0, y + h, d / 2.0]);
        expected.push((w * d * h, EXACT));
        y += h;
    }
    Shape {
        file: "skyscraper.obj",
        mesh,
        expected,
    }
}

/// A space shuttle lying along x, nose at +x, standing on its belly: a
/// fuselage (a side profile 12 long and 2.6 high with a sloped nose,
/// extruded 2.5 wide), two delta wings 0.5 thick touching its sides, and a
/// tail fin 0.5 thick standing on its back. Four shells, touching, none
/// overlapping.
fn shuttle() -> Shape {
    let body = [
        [0.0, 0.0],
        [10.0, 0.0],
        [12.0, 0.8],
        [11.0, 2.0],
        [9.0, 2.6],
        [0.0, 2.6],
    ];
    let half = 1.25;
    let right_wing = [[1.0, half], [7.0, half], [1.5, 5.0], [0.5, 5.0]];
    let left_wing = [[1.0, -half], [0.5, -5.0], [1.5, -5.0], [7.0, -half]];
    let fin = [[0.0, 2.6], [2.5, 2.6], [0.8, 5.0], [0.0, 5.0]];
    let mut mesh = Mesh::default();
    mesh.extrude(&body, -half, half);
    mesh.extrude_y(&right_wing, 0.0, 0.5);
    mesh.extrude_y(&left_wing, 0.0, 0.5);
    mesh.extrude(&fin, -0.25, 0.25);
    let area = |p: &[[f64; 2]]| twice_area(p).abs() / 2.0;
    let wing = area(&right_wing) * 0.5;
    Shape {
        file: "shuttle.obj",
        mesh,
        expected: vec![
            (area(&body) * 2.0 * half, EXACT),
            (wing, EXACT),
            (wing, EXACT),
            (area(&fin) * 0.5, EXACT),
        ],
    }
}

/// Segments around the mug.
const MUG_SEGMENTS: usize = 48;
/// Segments along the handle's half turn, and around its tube.
const HANDLE_SEGMENTS: (usize, usize) = (24, 16);

/// A ring of `n` vertices at height `y` around the y axis, from +x towards +z.
fn ring(mesh: &mut Mesh, n: usize, radius: f64, y: f64) -> Vec<u32> {
    (0..n)
        .map(|k| {
            let a = TAU * k as f64 / n as f64;
            mesh.vertex([radius * a.cos(), y, radius * a.sin()])
        })
        .collect()
}

/// A mug on the y axis: outer radius 4, inner radius 3.2, height 8, a solid
/// bottom 0.8 thick and an open top, as one closed surface (outer wall, rim,
/// inner wall, inner floor, outer bottom). Its handle is a separate closed
/// shell: half a torus (major radius 2.2, tube radius 0.6) on the +x side,
/// capped at both ends, whose caps sit about 0.2 inside the wall so the two
/// parts connect. Both parities are only wrong in that thin overlap.
fn mug() -> Shape {
    let (outer, inner, height, floor) = (4.0, 3.2, 8.0, 0.8);
    let n = MUG_SEGMENTS;
    let mut mesh = Mesh::default();
    let outer_bottom = ring(&mut mesh, n, outer, 0.0);
    let outer_top = ring(&mut mesh, n, outer, height);
    let inner_top = ring(&mut mesh, n, inner, height);
    let inner_floor = ring(&mut mesh, n, inner, floor);
    mesh.band(&outer_bottom, &outer_top);
    mesh.band(&outer_top, &inner_top);
    mesh.band(&inner_top, &inner_floor);
    let floor_center = mesh.vertex([0.0, floor, 0.0]);
    let mut up: Vec<u32> = inner_floor.clone();
    up.reverse();
    mesh.fan(floor_center, &up);
    let bottom_center = mesh.vertex([0.0, 0.0, 0.0]);
    mesh.fan(bottom_center, &outer_bottom);
    let body = ngon_area(n, outer) * height - ngon_area(n, inner) * (height - floor);

    // Handle: tube centre C + R (cos t, sin t, 0) for t in [-90°, 90°]; each
    // cross-section ring runs from the outward direction u towards +z, like
    // the mug's rings around their axis, so `band` and `fan` orient it alike.
    let (major, tube, center_x, center_y) = (2.2, 0.6, 3.8, height / 2.0);
    let (sweep, around) = HANDLE_SEGMENTS;
    let rings: Vec<Vec<u32>> = (0..=sweep)
        .map(|j| {
            let t = -PI / 2.0 + PI * j as f64 / sweep as f64;
            let u = [t.cos(), t.sin()];
            (0..around)
                .map(|k| {
                    let phi = TAU * k as f64 / around as f64;
                    let r = major + tube * phi.cos();
                    mesh.vertex([center_x + r * u[0], center_y + r * u[1], tube * phi.sin()])
                })
                .collect()
        })
        .collect();
    for pair in rings.windows(2) {
        mesh.band(&pair[0], &pair[1]);
    }
    let start = mesh.vertex([center_x, center_y - major, 0.0]);
    mesh.fan(start, &rings[0]);
    let end = mesh.vertex([center_x, center_y + major, 0.0]);
    let mut last = rings[sweep].clone();
    last.reverse();
    mesh.fan(end, &last);
    // Pappus: cross-section area times the path of its centroid (half a turn).
    let handle = PI * tube * tube * PI * major;
    Shape {
        file: "mug.obj",
        mesh,
        expected: vec![(body, 1e-3), (handle, 0.05 * handle)],
    }
}
