//! Inputs a loader must reject (or, for `open_box.obj` and `huge.obj`, must
//! survive). Each returns `(path under the fixture directory, bytes)`.

use crate::mesh::Mesh;

/// A deterministic xorshift generator, so `garbage.obj` never changes.
struct XorShift(u64);

impl XorShift {
    fn below(&mut self, n: u64) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0 % n
    }

    fn pick(&mut self, from: &[u8]) -> char {
        char::from(from[self.below(from.len() as u64) as usize])
    }
}

/// Text lines that are not OBJ statements. Every line starts with a capital
/// letter, digit or symbol, so none can be read as an OBJ keyword.
fn garbage() -> String {
    const FIRST: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789@%&*!?=+";
    const REST: &[u8] = b"abcdefghijklmnopqrstuvwxyz0123456789 ,.;:-_/()[]{}<>'\"\\|~^$";
    let mut rng = XorShift(0x5eed_b41c_4a11_0b1d);
    let mut out = String::new();
    for _ in 0..32 {
        out.push(rng.pick(FIRST));
        for _ in 0..rng.below(60) {
            out.push(rng.pick(REST));
        }
        out = out.trim_end().to_string();
        out.push('\n');
    }
    out
}

/// A 4 x 3 x 2 box without its top face (four boundary edges), with two
/// triangles repeated and two zero-area triangles: one with a repeated index,
/// one through three collinear points on a bottom edge.
pub fn open_box() -> Mesh {
    let mut mesh = Mesh::default();
    mesh.add_box([0.0, 0.0, 0.0], [4.0, 3.0, 2.0]);
    let top = mesh.positions.iter().map(|p| p[1]).max().unwrap_or(0);
    let positions = mesh.positions.clone();
    mesh.triangles
        .retain(|t| !t.iter().all(|&i| positions[i as usize][1] == top));
    let (first, second) = (mesh.triangles[0], mesh.triangles[5]);
    mesh.triangle(first[0], first[1], first[2]);
    mesh.triangle(second[1], second[2], second[0]);
    let (a, b) = (mesh.vertex([0.0, 0.0, 0.0]), mesh.vertex([4.0, 0.0, 0.0]));
    let mid = mesh.vertex([2.0, 0.0, 0.0]);
    mesh.triangle(a, a, b);
    mesh.triangle(a, mid, b);
    mesh
}

/// The hand-written broken files, except those derived from other fixtures.
pub fn files() -> Vec<(&'static str, Vec<u8>)> {
    let text = |s: &str| s.as_bytes().to_vec();
    vec![
        ("broken/garbage.obj", text(&garbage())),
        (
            "broken/empty.obj",
            text("# brickwright fixture: vertices but no faces\no empty\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"),
        ),
        (
            "broken/nan.obj",
            text(concat!(
                "# brickwright fixture: vertex 2 (line 3) has a NaN coordinate; faces use it\n",
                "v 0 0 0\n",
                "v nan 0 0\n",
                "v 0 1 0\n",
                "v 0 0 1\n",
                "f 1 3 2\n",
                "f 1 2 4\n",
                "f 1 4 3\n",
                "f 2 3 4\n",
            )),
        ),
        (
            "broken/badindex.obj",
            text(concat!(
                "# brickwright fixture: the face on line 7 uses vertex 5, there are only 4\n",
                "v 0 0 0\n",
                "v 1 0 0\n",
                "v 0 1 0\n",
                "v 0 0 1\n",
                "f 1 3 2\n",
                "f 1 2 5\n",
            )),
        ),
        (
            "broken/huge.obj",
            text(concat!(
                "# brickwright fixture: one valid triangle whose vertices are 1e12 apart\n",
                "v 0 0 0\n",
                "v 1000000000000 0 0\n",
                "v 0 1000000000000 0\n",
                "f 1 2 3\n",
            )),
        ),
        (
            "broken/notamesh.gltf",
            text(concat!(
                "{\n",
                "  \"name\": \"brickwright fixture\",\n",
                "  \"description\": \"valid JSON that is not glTF: no asset, no meshes\",\n",
                "  \"items\": [1, 2.5, \"three\", null, true],\n",
                "  \"nested\": {\"nodes\": \"not a list\"}\n",
                "}\n",
            )),
        ),
        ("broken/empty.stl", Vec::new()),
    ]
}
