//! Fuzzing every parser of untrusted input on stable Rust: OBJ (with its
//! material library and textures), STL, glTF/GLB, LDraw, rule files and
//! booklet templates.
//!
//! Each parser gets inputs made by mutating small valid files the test
//! writes itself (bytes flipped, cut, duplicated, and format words such as
//! `0 FILE`, `"uri"` or `1e39` spliced in) and, for a share, plain random
//! bytes. It must return `Ok` or `Err` and never panic (or hang). proptest
//! drives it and, on a failure, shrinks the input and saves it beside this
//! file (`fuzz.proptest-regressions`) so the next run tries it first.
//!
//! `cargo test` runs a short round: 2,000 inputs a parser. The long run,
//! a million inputs each, in the test profile (optimized, with overflow
//! checks, which turn silent wrap-arounds into findings):
//!
//! ```sh
//! BRICKWRIGHT_FUZZ_CASES=1000000 cargo test --test fuzz
//! ```

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::test_runner::Config;

use brickwright::booklet::template::Template;
use brickwright::grammar::RuleSet;
use brickwright::ldraw::{parse_ldr, to_assembly};
use brickwright::mesh;

/// Inputs a parser: `BRICKWRIGHT_FUZZ_CASES`, default 2,000.
fn config() -> Config {
    let cases = std::env::var("BRICKWRIGHT_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2_000);
    Config {
        cases,
        // A panic is found at once; shrinking it should not take long.
        max_shrink_iters: 2_000,
        ..Config::default()
    }
}

/// One change to a seed file. Positions are taken modulo its length.
#[derive(Debug, Clone)]
enum Edit {
    /// Set the byte at a position.
    Set(usize, u8),
    /// Remove up to `n` bytes at a position.
    Cut(usize, usize),
    /// Copy up to `n` bytes at one position to another.
    Copy(usize, usize, usize),
    /// Insert a word of the format's dictionary at a position.
    Word(usize, usize),
    /// Insert random bytes at a position.
    Bytes(usize, Vec<u8>),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        4 => (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Set(i, b)),
        2 => (any::<usize>(), 1..64usize).prop_map(|(i, n)| Edit::Cut(i, n)),
        1 => (any::<usize>(), 1..256usize, any::<usize>()).prop_map(|(i, n, j)| Edit::Copy(i, n, j)),
        4 => (any::<usize>(), any::<usize>()).prop_map(|(i, w)| Edit::Word(i, w)),
        1 => (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(i, b)| Edit::Bytes(i, b)),
    ]
}

/// A fuzz input: a seed with up to 8 edits, or (one time in eight) random
/// bytes.
#[derive(Debug, Clone)]
enum Input {
    Mutated(usize, Vec<Edit>),
    Random(Vec<u8>),
}

fn input() -> impl Strategy<Value = Input> {
    prop_oneof![
        7 => (any::<usize>(), proptest::collection::vec(edit(), 0..8))
            .prop_map(|(s, e)| Input::Mutated(s, e)),
        1 => proptest::collection::vec(any::<u8>(), 0..512).prop_map(Input::Random),
    ]
}

/// The bytes of `input` over `seeds`, splicing words of `dict`.
fn bytes(input: &Input, seeds: &[Vec<u8>], dict: &[&str]) -> Vec<u8> {
    let (s, edits) = match input {
        Input::Random(b) => return b.clone(),
        Input::Mutated(s, e) => (s, e),
    };
    let mut b = seeds[s % seeds.len()].clone();
    for e in edits {
        let at = |i: usize, len: usize| if len == 0 { 0 } else { i % (len + 1) };
        match e {
            Edit::Set(i, v) if !b.is_empty() => {
                let n = b.len();
                b[i % n] = *v;
            }
            Edit::Set(..) => {}
            Edit::Cut(i, n) => {
                let from = at(*i, b.len());
                let to = (from + n).min(b.len());
                b.drain(from..to);
            }
            Edit::Copy(i, n, j) => {
                let from = at(*i, b.len());
                let to = (from + n).min(b.len());
                let piece = b[from..to].to_vec();
                let dest = at(*j, b.len());
                b.splice(dest..dest, piece);
            }
            Edit::Word(i, w) => {
                let dest = at(*i, b.len());
                let word = dict[w % dict.len()].as_bytes();
                b.splice(dest..dest, word.iter().copied());
            }
            Edit::Bytes(i, v) => {
                let dest = at(*i, b.len());
                b.splice(dest..dest, v.iter().copied());
            }
        }
    }
    b
}

/// Numbers that break naive parsers, shared by every dictionary.
const NUMBERS: &[&str] = &[
    " 0",
    " -1",
    " 1e39",
    " -1e39",
    " nan",
    " inf",
    " 4294967295",
    " 18446744073709551616",
    " 2147483648",
    " 0.5",
    " 1e-45",
    " -0",
    " 99999999999999999999",
    " 3",
];

fn dict(words: &[&'static str]) -> Vec<&'static str> {
    words.iter().chain(NUMBERS).copied().collect()
}

fn cube() -> ([[f32; 3]; 8], [[u32; 3]; 12]) {
    let v = std::array::from_fn(|i| [(i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32]);
    let t = [
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    (v, t)
}

fn obj_seeds() -> Vec<Vec<u8>> {
    let (v, t) = cube();
    let mut s = String::from("# cube\nmtllib x.mtl\no cube\n");
    for p in v {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    s += "vt 0 0\nvn 0 0 1\n";
    for f in t {
        s += &format!("f {}/1/1 {}/1/1 {}/1/1\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 2 3 4\nf -1 -2 -3\ng g\ns off\n";
    vec![s.into_bytes(), quad.as_bytes().to_vec()]
}

fn mtl_seeds() -> Vec<Vec<u8>> {
    let full = "# lib\nnewmtl red\nKa 0 0 0\nKd 1 0 0\nKs 0.5 0.5 0.5\nNs 10\nd 1\nillum 2\n\
                newmtl tex\nKd 1 1 1\nmap_Kd -s 1 1 1 tex.png\nmap_Bump n.png\n";
    vec![full.as_bytes().to_vec(), b"newmtl a\nKd 0.5\n".to_vec()]
}

/// A small PNG: 4 x 4 texels, two colours.
fn png_seed() -> Vec<u8> {
    let img = image::RgbImage::from_fn(4, 4, |x, _| {
        image::Rgb(if x < 2 { [200, 0, 0] } else { [0, 0, 200] })
    });
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A textured square using both materials of [`mtl_seeds`].
const TEXTURED_OBJ: &str = "mtllib a.mtl\nmtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3\nusemtl red\nf 1/1 3/3 4/4\n";

/// Loads [`TEXTURED_OBJ`] from a fresh folder holding `mtl` as its
/// material library and `png` as its texture.
fn load_textured(mtl: &[u8], png: &[u8]) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.mtl"), mtl).unwrap();
    std::fs::write(dir.path().join("tex.png"), png).unwrap();
    let path = dir.path().join("m.obj");
    std::fs::write(&path, TEXTURED_OBJ).unwrap();
    let _ = mesh::load(&path);
}

fn stl_seeds() -> Vec<Vec<u8>> {
    let (v, t) = cube();
    let mut bin = vec![0u8; 80];
    bin.extend(12u32.to_le_bytes());
    let mut ascii = String::from("solid cube\n");
    for f in t {
        bin.extend([0f32; 3].iter().flat_map(|x| x.to_le_bytes()));
        ascii += " facet normal 0 0 0\n  outer loop\n";
        for i in f {
            bin.extend(v[i as usize].iter().flat_map(|x| x.to_le_bytes()));
            let p = v[i as usize];
            ascii += &format!("   vertex {} {} {}\n", p[0], p[1], p[2]);
        }
        ascii += "  endloop\n endfacet\n";
        bin.extend([0u8; 2]);
    }
    ascii += "endsolid cube\n";
    vec![bin, ascii.into_bytes()]
}

/// The cube's buffer: positions then u16 indices (168 bytes).
fn cube_buffer() -> Vec<u8> {
    let (v, t) = cube();
    let mut b: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
    b.extend(t.iter().flatten().flat_map(|&i| (i as u16).to_le_bytes()));
    b
}

fn gltf_json(uri: Option<&str>) -> String {
    let uri = uri.map_or(String::new(), |u| format!(r#""uri": "{u}", "#));
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
"nodes": [{{"translation": [1, 0, 0], "children": [1]}}, {{"scale": [2, 2, 2], "mesh": 0}}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}},
  {{"attributes": {{"POSITION": 0}}, "mode": 5}}]}}],
"buffers": [{{{uri}"byteLength": 168}}],
"bufferViews": [{{"buffer": 0, "byteLength": 96, "byteStride": 12}},
  {{"buffer": 0, "byteOffset": 96, "byteLength": 72}}],
"accessors": [{{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
  "min": [0, 0, 0], "max": [1, 1, 1]}},
  {{"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}}]}}"#
    )
}

fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    j.resize(j.len().next_multiple_of(4), b' ');
    let mut b = bin.to_vec();
    b.resize(b.len().next_multiple_of(4), 0);
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + j.len() + 8 + b.len()) as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(j);
    out.extend((b.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(b);
    out
}

fn base64(bytes: &[u8]) -> String {
    use base64::Engine as _;
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

fn gltf_seeds() -> Vec<Vec<u8>> {
    let data = format!(
        "data:application/octet-stream;base64,{}",
        base64(&cube_buffer())
    );
    vec![
        gltf_json(Some(&data)).into_bytes(),
        gltf_json(Some("cube.bin")).into_bytes(),
    ]
}

fn ldraw_seeds() -> Vec<Vec<u8>> {
    let mpd = "0 FILE main.ldr\n0 Name: main.ldr\n\
               1 4 0 -24 0 1 0 0 0 1 0 0 0 1 3001.dat\n0 STEP\n\
               1 16 20 -48 0 1 0 0 0 1 0 0 0 1 wall.ldr\n0 ROTSTEP 10 20 0 REL\n\
               1 1 0 -96 0 0 0 1 0 1 0 -1 0 0 3039.dat\n2 24 0 0 0 1 1 1\n0 NOFILE\n\
               0 FILE wall.ldr\n1 16 0 0 0 1 0 0 0 1 0 0 0 1 3004.dat\n\
               1 16 0 0 0 1 0 0 0 1 0 0 0 1 post.ldr\n0 FILE post.ldr\n\
               1 16 10 -8 10 1 0 0 0 1 0 0 0 1 3024.dat\n";
    let ldr = "0 a wall\n1 4 40 -24 20 1 0 0 0 1 0 0 0 1 3001.dat\n\
               1 4 40 -24 60 1 0 0 0 1 0 0 0 1 3001.dat\n0 STEP\n\
               1 4 40 -48 40 1 0 0 0 1 0 0 0 1 3001.dat\n";
    vec![mpd.as_bytes().to_vec(), ldr.as_bytes().to_vec()]
}

fn rule_seeds() -> Vec<Vec<u8>> {
    let basic = "# rules\npart 3005\npart 3001\npart 3003\nstart 3005\nstart 3001\n\
                 rule 3001 3001 r0 up 0 -1 2\nrule 3001 3003 r90 down 1 0 0.5\n\
                 rule 3005 3005 r0 up 0 0 1\nunseen 0.05\n";
    let complex = "part 3001\nstart 3001\nrule 3001 3001 r0 up 2 0 1\n\
                   complex bond-2x4\n  u 3001 r0 0 0 0\n  v 3001 r0 -2 0 3\n  v 3001 r0 2 0 3\n";
    vec![basic.as_bytes().to_vec(), complex.as_bytes().to_vec()]
}

fn template_seeds() -> Vec<Vec<u8>> {
    let default = include_str!("../templates/default.toml");
    let small = "[page]\nsize = \"Letter\"\nmargin = 5.0\n[steps]\nper_page = 2\n\
                 [colors]\naccent = \"#FF0000\"\n";
    vec![default.as_bytes().to_vec(), small.as_bytes().to_vec()]
}

/// A folder for the files the glTF inputs may name, with the cube's
/// buffer in it.
fn gltf_dir() -> &'static Path {
    static DIR: std::sync::OnceLock<tempfile::TempDir> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join("cube.bin"), cube_buffer()).unwrap();
        d
    })
    .path()
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn obj_never_panics(i in input()) {
        let words = dict(&["\nv", "\nf", " /", "//", "\nvt", "\nvn", "\no ", "\ng ",
            "\nmtllib /etc/passwd", "\nf 1 2 3 4 5 6", "\nf -9 -8 -7", "\\\n", "#"]);
        let b = bytes(&i, &obj_seeds(), &words);
        let _ = mesh::parse(Path::new("fuzz.obj"), &b);
    }

    #[test]
    fn material_libraries_never_panic(i in input()) {
        // `Kd 1 1`, `Ks 1` and a bare `Kd` made tobj's own reader panic.
        let words = dict(&["\nnewmtl", "\nnewmtl ", "\nKd", "\nKd 1 1", "\nKs 1", " nan",
            " inf", " -1e39", "\nmap_Kd", "\nmap_Kd ../x.png", "\nmap_Kd /dev/zero",
            "\nmap_Kd tex.png", " -o 1 1", "#", "\t", "\r\n"]);
        let b = bytes(&i, &mtl_seeds(), &words);
        let lib = mesh::mtl::parse(&String::from_utf8_lossy(&b));
        prop_assert!(lib.materials.iter().all(|m| !m.name.is_empty()));
        prop_assert!(lib.materials.iter().flat_map(|m| m.kd).flatten().all(|c| (0.0..=1.0).contains(&c)));
        load_textured(&b, &png_seed());
    }

    #[test]
    fn textures_never_panic(i in input()) {
        let words = dict(&["\u{89}PNG\r\n\u{1a}\n", "IHDR", "IDAT", "IEND", "\u{ff}\u{d8}\u{ff}",
            "\u{0}\u{0}\u{ff}\u{ff}", "\u{7f}\u{ff}\u{ff}\u{ff}"]);
        let b = bytes(&i, &[png_seed()], &words);
        load_textured(&mtl_seeds()[0], &b);
    }

    #[test]
    fn stl_never_panics(i in input()) {
        let words = dict(&["solid", "facet normal", "outer loop", "vertex", "endloop",
            "endfacet", "endsolid", "\n", "\u{0}\u{0}\u{0}\u{7f}"]);
        let b = bytes(&i, &stl_seeds(), &words);
        let _ = mesh::parse(Path::new("fuzz.stl"), &b);
    }

    #[test]
    fn gltf_never_panics(i in input()) {
        let words = dict(&["\"uri\": \"../x\", ", "\"uri\": \"/dev/zero\", ",
            "\"uri\": \"file:///etc/passwd\", ", "\"byteLength\": 1e12, ", "\"byteStride\": 0, ",
            "\"count\": 4294967295, ", "\"children\": [0], ", "\"mode\": 6, ",
            "\"componentType\": 5121, ", "\"type\": \"MAT4\", ", "\"sparse\": {}, ",
            "\"matrix\": [0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0], ", "{", "}", "[", "]", ",", "\""]);
        let seeds = gltf_seeds();
        let b = bytes(&i, &seeds, &words);
        let _ = mesh::parse(&gltf_dir().join("fuzz.gltf"), &b);
        // The same JSON in a binary container.
        let _ = mesh::parse(&gltf_dir().join("fuzz.glb"), &glb(&String::from_utf8_lossy(&b), &cube_buffer()));
    }

    #[test]
    fn glb_containers_never_panic(i in input()) {
        let seeds = vec![glb(&gltf_json(None), &cube_buffer())];
        let words = dict(&["glTF", "JSON", "BIN\u{0}", "\u{ff}\u{ff}\u{ff}\u{ff}", "\u{0}\u{0}\u{0}\u{0}"]);
        let b = bytes(&i, &seeds, &words);
        let _ = mesh::parse(&gltf_dir().join("fuzz.glb"), &b);
    }

    #[test]
    fn ldraw_never_panics(i in input()) {
        let words = dict(&["\n0 FILE main.ldr\n", "\n0 FILE wall.ldr\n", "\n0 STEP\n",
            "\n0 NOFILE\n", "\n1 16 0 0 0 1 0 0 0 1 0 0 0 1 main.ldr\n",
            "\n1 16 0 0 0 1 0 0 0 1 0 0 0 1 wall.ldr\n", "\n1 4", " 3001.dat", " 3039.dat",
            " 0 0 1 0 1 0 -1 0 0", "\n5 ", "\n\u{1b}[2J", "\u{feff}"]);
        let b = bytes(&i, &ldraw_seeds(), &words);
        if let Ok(model) = parse_ldr(&String::from_utf8_lossy(&b), Path::new("fuzz.mpd")) {
            if let Ok(asm) = to_assembly(&model) {
                let _ = brickwright::assembly::verify::verify(&asm, None);
            }
        }
    }

    #[test]
    fn rule_files_never_panic(i in input()) {
        let words = dict(&["\npart 3005", "\npart 3001", "\npart 3039", "\nstart 3001",
            "\nrule 3001 3001 r0 up", "\nrule 3005 3001 r270 down", " r90", " r180",
            "\nunseen", "\ncomplex x\n", "\n  u 3001 r0", "\n  v 3001 r90", "\n  v 3024 r0",
            " 100000", " -100000"]);
        let b = bytes(&i, &rule_seeds(), &words);
        let _ = RuleSet::parse(&String::from_utf8_lossy(&b), &PathBuf::from("fuzz.rules"));
    }

    #[test]
    fn templates_never_panic(i in input()) {
        let words = dict(&["\n[page]\n", "\n[steps]\n", "\n[fonts]\n", "\n[colors]\n",
            "\nsize = \"A4\"", "\nper_page = ", "\nmargin = ", "\ntitle_size = ",
            "\naccent = \"#", "\"", "=", "[", "]", "{", "'''"]);
        let b = bytes(&i, &template_seeds(), &words);
        let _ = Template::parse(&String::from_utf8_lossy(&b), "fuzz.toml");
    }
}
