//! Closedness and volume checks, in exact integer arithmetic on grid steps.
//!
//! A mesh is closed when every directed edge `a -> b` occurs exactly once and
//! its reverse `b -> a` occurs exactly once: each edge is shared by exactly two
//! triangles that traverse it in opposite directions, so the surface is
//! watertight and consistently oriented. Outward orientation then shows as a
//! positive signed volume for every shell (connected component).

use std::collections::BTreeMap;

use crate::mesh::{Mesh, STEPS_PER_UNIT};

/// What the check found in one mesh.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Number of triangles.
    pub triangles: usize,
    /// Signed volume of each shell in units³, largest first.
    pub shell_volumes: Vec<f64>,
    /// Triangles with a repeated index or zero area.
    pub degenerate: usize,
    /// Triangles that repeat an earlier one (same vertices, any rotation).
    pub duplicated: usize,
    /// Directed edges whose reverse is missing (holes, flipped triangles).
    pub unpaired_edges: usize,
    /// Directed edges used by more than one triangle.
    pub repeated_edges: usize,
}

impl Report {
    /// Whether the mesh is a closed, consistently oriented surface with every
    /// shell facing outwards.
    pub fn is_closed(&self) -> bool {
        self.degenerate == 0
            && self.duplicated == 0
            && self.unpaired_edges == 0
            && self.repeated_edges == 0
            && self.shell_volumes.iter().all(|&v| v > 0.0)
    }
}

fn sub(a: [i64; 3], b: [i64; 3]) -> [i128; 3] {
    [0, 1, 2].map(|i| i128::from(a[i]) - i128::from(b[i]))
}

fn cross(a: [i128; 3], b: [i128; 3]) -> [i128; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Six times the signed volume of the tetrahedron (origin, a, b, c), in steps³.
fn det(a: [i64; 3], b: [i64; 3], c: [i64; 3]) -> i128 {
    let [a, b, c] = [a, b, c].map(|p| p.map(i128::from));
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Checks `mesh` for closedness and measures its shells.
pub fn check(mesh: &Mesh) -> Report {
    let p = &mesh.positions;
    let mut report = Report {
        triangles: mesh.triangles.len(),
        ..Report::default()
    };
    let mut edges: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    let mut seen: BTreeMap<[u32; 3], usize> = BTreeMap::new();
    let mut parent: Vec<usize> = (0..p.len()).collect();
    for &[a, b, c] in &mesh.triangles {
        let (pa, pb, pc) = (p[a as usize], p[b as usize], p[c as usize]);
        if a == b || b == c || c == a || cross(sub(pb, pa), sub(pc, pa)) == [0; 3] {
            report.degenerate += 1;
        }
        // Rotate so the smallest index leads; duplicates then compare equal.
        let mut key = [a, b, c];
        let lead = key
            .iter()
            .enumerate()
            .min_by_key(|(_, &v)| v)
            .map_or(0, |(i, _)| i);
        key.rotate_left(lead);
        *seen.entry(key).or_default() += 1;
        for (u, v) in [(a, b), (b, c), (c, a)] {
            if u != v {
                *edges.entry((u, v)).or_default() += 1;
            }
        }
        for (u, v) in [(a, b), (b, c)] {
            let (ru, rv) = (find(&mut parent, u as usize), find(&mut parent, v as usize));
            parent[ru] = rv;
        }
    }
    report.duplicated = seen.values().map(|&n| n - 1).sum();
    for (&(u, v), &n) in &edges {
        if n > 1 {
            report.repeated_edges += 1;
        }
        if !edges.contains_key(&(v, u)) {
            report.unpaired_edges += 1;
        }
    }
    let mut shells: BTreeMap<usize, i128> = BTreeMap::new();
    for &[a, b, c] in &mesh.triangles {
        let root = find(&mut parent, a as usize);
        *shells.entry(root).or_default() += det(p[a as usize], p[b as usize], p[c as usize]);
    }
    let scale = 6.0 * (STEPS_PER_UNIT as f64).powi(3);
    report.shell_volumes = shells.values().map(|&v| v as f64 / scale).collect();
    report.shell_volumes.sort_by(|x, y| y.total_cmp(x));
    report
}
