//! The colours of a mesh's surface: materials (a base colour and an optional
//! texture), texture coordinates and vertex colours, per triangle.
//!
//! Every loader that finds colours fills a [`Paint`]: one [`FacePaint`] per
//! triangle, naming its [`Material`] and carrying its corners' texture
//! coordinates and vertex colours when the file has them. [`Paint::sample`]
//! then gives the colour at any point of a triangle (barycentric
//! coordinates), the way a renderer would: base colour × texture × vertex
//! colour, all in linear RGB.
//!
//! Textures are decoded with the `image` crate under a memory limit
//! ([`MAX_TEXTURE_SIDE`] a side), and only from files inside the model's own
//! folder (see [`inside_folder`]).

use std::path::{Component, Path, PathBuf};

/// The widest or tallest texture accepted, in texels.
pub const MAX_TEXTURE_SIDE: u32 = 8192;

/// The most texels decoded for one model, all its textures together (one
/// image of [`MAX_TEXTURE_SIDE`] a side, 256 MB as RGBA): a texture that
/// would pass it is a warning and its material's colour stands in.
pub const MAX_MODEL_TEXELS: u64 = (MAX_TEXTURE_SIDE as u64) * (MAX_TEXTURE_SIDE as u64);

/// The largest side file (material library or image) read, in bytes.
pub const MAX_SIDE_FILE: u64 = 256 << 20;

/// How texture coordinates outside `[0, 1]` wrap (glTF's sampler modes;
/// OBJ textures repeat).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Wrap {
    /// Tile the texture (the default).
    #[default]
    Repeat,
    /// Use the edge texel.
    Clamp,
    /// Tile, flipping every other copy.
    Mirror,
}

impl Wrap {
    /// Maps a coordinate to `[0, 1]`.
    fn apply(self, t: f32) -> f32 {
        match self {
            Wrap::Repeat => t - t.floor(),
            Wrap::Clamp => t.clamp(0.0, 1.0),
            Wrap::Mirror => {
                let m = t.rem_euclid(2.0);
                if m > 1.0 {
                    2.0 - m
                } else {
                    m
                }
            }
        }
    }
}

/// A decoded texture: sRGB texels, row by row from the top.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Texture {
    /// Texels across.
    pub width: u32,
    /// Texels down.
    pub height: u32,
    /// `width * height` RGBA texels, sRGB.
    pub texels: Vec<[u8; 4]>,
    /// How `u` and `v` wrap.
    pub wrap: [Wrap; 2],
}

impl Texture {
    /// Decodes PNG or JPEG `bytes`, refusing images larger than
    /// [`MAX_TEXTURE_SIDE`] a side before any texel is decoded.
    pub fn decode(bytes: &[u8]) -> Result<Texture, String> {
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| e.to_string())?;
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_TEXTURE_SIDE);
        limits.max_image_height = Some(MAX_TEXTURE_SIDE);
        limits.max_alloc = Some(u64::from(MAX_TEXTURE_SIDE).pow(2) * 8);
        reader.limits(limits);
        let img = reader.decode().map_err(|e| e.to_string())?.to_rgba8();
        Ok(Texture {
            width: img.width(),
            height: img.height(),
            texels: img.pixels().map(|p| p.0).collect(),
            wrap: [Wrap::Repeat; 2],
        })
    }

    /// The width and height `bytes` declare, read from the header only.
    pub fn dimensions(bytes: &[u8]) -> Result<(u32, u32), String> {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| e.to_string())?
            .into_dimensions()
            .map_err(|e| e.to_string())
    }

    /// The texel at `uv` (nearest; `v` = 0 is the top row, as in glTF), in
    /// linear RGB.
    pub fn at(&self, uv: [f32; 2]) -> [f32; 3] {
        if self.width == 0 || self.height == 0 {
            return [1.0; 3];
        }
        let u = self.wrap[0].apply(uv[0]);
        let v = self.wrap[1].apply(uv[1]);
        let x = ((u * self.width as f32) as u32).min(self.width - 1);
        let y = ((v * self.height as f32) as u32).min(self.height - 1);
        let t = self.texels[(y * self.width + x) as usize];
        [t[0], t[1], t[2]].map(|c| srgb_to_linear(f32::from(c) / 255.0))
    }
}

/// A surface material: a base colour, optionally multiplied by a texture.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Material {
    /// The name the file gives it (may be empty).
    pub name: String,
    /// The base colour, linear RGB.
    pub color: [f32; 3],
    /// An index into [`Paint::textures`].
    pub texture: Option<usize>,
    /// Whether texture coordinates count `v` up from the bottom (OBJ) rather
    /// than down from the top (glTF).
    pub flip_v: bool,
}

/// The paint of one triangle.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FacePaint {
    /// An index into [`Paint::materials`], or `None` for no material (white).
    pub material: Option<u32>,
    /// The corners' texture coordinates.
    pub uv: Option<[[f32; 2]; 3]>,
    /// The corners' vertex colours, linear RGB.
    pub color: Option<[[f32; 3]; 3]>,
}

/// A mesh's colours: see the module docs.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Paint {
    /// The materials triangles refer to.
    pub materials: Vec<Material>,
    /// The textures materials refer to.
    pub textures: Vec<Texture>,
    /// One per triangle of the mesh, in order.
    pub faces: Vec<FacePaint>,
}

impl Paint {
    /// Whether anything here gives a colour (a material, or vertex colours).
    pub fn has_color(&self) -> bool {
        self.faces
            .iter()
            .any(|f| f.material.is_some() || f.color.is_some())
    }

    /// The colour of triangle `face` at barycentric `w` (weights of its
    /// three corners), linear RGB.
    pub fn sample(&self, face: usize, w: [f32; 3]) -> [f32; 3] {
        let Some(f) = self.faces.get(face) else {
            return [1.0; 3];
        };
        let mut c = [1.0f32; 3];
        if let Some(m) = f.material.and_then(|m| self.materials.get(m as usize)) {
            c = m.color;
            if let (Some(t), Some(uv)) = (m.texture.and_then(|t| self.textures.get(t)), f.uv) {
                let mut p = [0.0f32; 2];
                for k in 0..3 {
                    p[0] += uv[k][0] * w[k];
                    p[1] += uv[k][1] * w[k];
                }
                if m.flip_v {
                    p[1] = 1.0 - p[1];
                }
                let tex = t.at(p);
                c = [c[0] * tex[0], c[1] * tex[1], c[2] * tex[2]];
            }
        }
        if let Some(vc) = f.color {
            for (i, ci) in c.iter_mut().enumerate() {
                *ci *= vc[0][i] * w[0] + vc[1][i] * w[1] + vc[2][i] * w[2];
            }
        }
        c
    }
}

/// sRGB (0..1) to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear to sRGB (0..1).
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Decodes a model's textures under one budget of texels for them all
/// ([`MAX_MODEL_TEXELS`]): however many materials name however large
/// images, memory stays bounded. Callers decode each source once (a cache
/// by resolved path or image index) and only for materials in use.
#[derive(Debug)]
pub(crate) struct TextureBudget {
    left: u64,
}

impl Default for TextureBudget {
    fn default() -> Self {
        TextureBudget {
            left: MAX_MODEL_TEXELS,
        }
    }
}

impl TextureBudget {
    /// Decodes `bytes` if its texels fit what is left of the budget.
    pub(crate) fn decode(&mut self, bytes: &[u8]) -> Result<Texture, String> {
        let (w, h) = Texture::dimensions(bytes).map_err(|e| format!("cannot be decoded ({e})"))?;
        let texels = u64::from(w) * u64::from(h);
        if texels > self.left {
            return Err(format!(
                "is not decoded: its {w} x {h} texels would pass the limit of {} million \
                 texels for all of a model's textures together (shrink the images)",
                MAX_MODEL_TEXELS / 1_000_000
            ));
        }
        self.left -= texels;
        Texture::decode(bytes).map_err(|e| format!("cannot be decoded ({e})"))
    }
}

/// The bytes of a side file a model names (material library, texture),
/// at most `max` of them. Only a regular file is opened (checked on the
/// link-resolved path before opening, and again on the open file): a FIFO
/// or a device is refused, never read, so nothing blocks. The error is a
/// phrase to follow the file's name ("is missing", "is not a regular file").
pub(crate) fn read_side_file(path: &Path, max: u64) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let meta = std::fs::metadata(path).map_err(|_| "is missing".to_string())?;
    if !meta.is_file() {
        return Err("is not a regular file".into());
    }
    if meta.len() > max {
        return Err(format!("is larger than {} MB", max >> 20));
    }
    let file = std::fs::File::open(path).map_err(|e| format!("cannot be read ({e})"))?;
    if !file.metadata().is_ok_and(|m| m.is_file()) {
        return Err("is not a regular file".into());
    }
    let mut out = Vec::with_capacity(meta.len() as usize);
    file.take(max + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("cannot be read ({e})"))?;
    if out.len() as u64 > max {
        return Err(format!("is larger than {} MB", max >> 20));
    }
    Ok(out)
}

/// `name` resolved inside `folder`, or `None` when it would leave it (an
/// absolute path, `..`, or a link pointing out): a model's references stay
/// in its own folder.
pub fn inside_folder(folder: &Path, name: &str) -> Option<PathBuf> {
    let rel = Path::new(name.trim());
    if rel
        .components()
        .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return None;
    }
    let path = folder.join(rel);
    if let (Ok(real), Ok(base)) = (path.canonicalize(), folder.canonicalize()) {
        if !real.starts_with(base) {
            return None;
        }
    }
    Some(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wraps() {
        assert!((Wrap::Repeat.apply(1.25) - 0.25).abs() < 1e-6);
        assert_eq!(Wrap::Clamp.apply(1.25), 1.0);
        assert!((Wrap::Mirror.apply(1.25) - 0.75).abs() < 1e-6);
        assert!((Wrap::Repeat.apply(-0.25) - 0.75).abs() < 1e-6);
    }

    #[test]
    fn folder_escape_is_refused() {
        let d = Path::new("/tmp");
        assert!(inside_folder(d, "../etc/passwd").is_none());
        assert!(inside_folder(d, "/etc/passwd").is_none());
        assert_eq!(inside_folder(d, "a.png"), Some(PathBuf::from("/tmp/a.png")));
    }

    #[test]
    fn sample_multiplies_material_texture_and_vertex_colour() {
        let tex = Texture {
            width: 2,
            height: 1,
            texels: vec![[255, 0, 0, 255], [0, 0, 255, 255]],
            wrap: [Wrap::Repeat; 2],
        };
        let paint = Paint {
            materials: vec![Material {
                name: "m".into(),
                color: [1.0, 1.0, 1.0],
                texture: Some(0),
                flip_v: false,
            }],
            textures: vec![tex],
            faces: vec![FacePaint {
                material: Some(0),
                uv: Some([[0.1, 0.5], [0.2, 0.5], [0.9, 0.5]]),
                color: Some([[1.0, 0.5, 1.0]; 3]),
            }],
        };
        assert_eq!(paint.sample(0, [1.0, 0.0, 0.0]), [1.0, 0.0, 0.0]);
        assert_eq!(paint.sample(0, [0.0, 0.0, 1.0]), [0.0, 0.0, 1.0]);
        assert!(paint.has_color());
    }
}
