//! The bytes of a glTF file's buffers, fetched as untrusted input.
//!
//! A buffer is the `.glb`'s own binary chunk, a `data:` URI (base64 in the
//! JSON), or a file named by a relative URI. A model is a file someone sent,
//! so its references are kept on a short leash:
//!
//! - only relative URIs, resolved inside the folder that holds the model
//!   (no absolute path, no `file:` or other scheme, no `..` out of the
//!   folder, no symbolic link leading out of it);
//! - only regular files (a FIFO or a device such as `/dev/zero` is refused
//!   before it is opened, so nothing blocks or reads forever);
//! - never more than the buffer's declared `byteLength` bytes, and a file
//!   shorter than that is an error.
//!
//! Image URIs are never opened: the mesh is all that is read.

use std::io::Read;
use std::path::{Component, Path, PathBuf};

use base64::Engine as _;

/// Reads every buffer of `document`; `base` is the folder holding the model
/// and `blob` the `.glb` binary chunk. The error is one phrase for the user.
pub(super) fn load(
    document: &::gltf::Document,
    base: &Path,
    mut blob: Option<Vec<u8>>,
) -> Result<Vec<Vec<u8>>, String> {
    let mut out = Vec::new();
    for buffer in document.buffers() {
        let i = buffer.index();
        let declared = buffer.length();
        let data = match buffer.source() {
            ::gltf::buffer::Source::Bin => blob
                .take()
                .ok_or_else(|| format!("buffer {i} refers to a binary chunk the file lacks"))?,
            ::gltf::buffer::Source::Uri(uri) => read_uri(uri, base, declared)
                .map_err(|why| format!("buffer {i} (uri {}): {why}", shorten(uri)))?,
        };
        if data.len() < declared {
            return Err(format!(
                "buffer {i} holds {} bytes but declares a byteLength of {declared}",
                data.len()
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// The bytes a buffer URI names, at most `limit` of them.
fn read_uri(uri: &str, base: &Path, limit: usize) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, b64)) = rest.split_once(";base64,") else {
            return Err("a data: URI that is not base64".into());
        };
        let mut data = base64::engine::general_purpose::STANDARD
            .decode(b64.trim())
            .map_err(|e| format!("bad base64 ({e})"))?;
        data.truncate(limit);
        return Ok(data);
    }
    let path = resolve(uri, base)?;
    read_regular(&path, limit)
}

/// The file a relative URI names inside `base`, or why it is refused.
pub(super) fn resolve(uri: &str, base: &Path) -> Result<PathBuf, String> {
    // A scheme is letters, digits, `+`, `-`, `.` before the first `:`.
    if let Some((scheme, _)) = uri.split_once(':') {
        let is_scheme = scheme.starts_with(|c: char| c.is_ascii_alphabetic())
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
        if is_scheme {
            return Err(format!(
                "the `{scheme}:` scheme is not followed; put the buffer beside the model and name it by a relative path"
            ));
        }
    }
    let decoded = urlencoding::decode(uri).map_err(|_| "not valid UTF-8 once decoded")?;
    let rel = Path::new(decoded.as_ref());
    if decoded.is_empty() || decoded.contains('\0') {
        return Err("an empty or invalid path".into());
    }
    if decoded.starts_with(['/', '\\']) || rel.is_absolute() || rel.has_root() {
        return Err("an absolute path; only files in the model's own folder are read".into());
    }
    for c in rel.components() {
        match c {
            Component::Normal(_) | Component::CurDir => {}
            _ => {
                return Err(
                    "a path that leaves the model's folder; only files in it are read".into(),
                )
            }
        }
    }
    let path = base.join(rel);
    // Symbolic links may not lead out of the folder either.
    let (Ok(real_base), Ok(real)) = (base.canonicalize(), path.canonicalize()) else {
        return Err("no such file beside the model".into());
    };
    if !real.starts_with(&real_base) {
        return Err("a link that leads out of the model's folder".into());
    }
    Ok(real)
}

/// Up to `limit` bytes of `path`, which must be a regular file at least
/// that long.
fn read_regular(path: &Path, limit: usize) -> Result<Vec<u8>, String> {
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err("not a regular file".into());
    }
    if meta.len() < limit as u64 {
        return Err(format!(
            "the file holds {} bytes but the buffer declares {limit}",
            meta.len()
        ));
    }
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    // Checked again on the open file, in case it changed in between.
    if !file.metadata().map_err(|e| e.to_string())?.is_file() {
        return Err("not a regular file".into());
    }
    let mut data = Vec::with_capacity(limit);
    file.take(limit as u64)
        .read_to_end(&mut data)
        .map_err(|e| e.to_string())?;
    Ok(data)
}

/// A URI cut short for a message (a `data:` URI can be megabytes long).
fn shorten(uri: &str) -> String {
    const MAX: usize = 60;
    match uri.char_indices().nth(MAX) {
        Some((at, _)) => format!("{}...", &uri[..at]),
        None => uri.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::resolve;
    use std::path::Path;

    #[test]
    fn only_relative_paths_inside_the_folder_resolve() {
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path().join("model");
        std::fs::create_dir_all(base.join("sub")).unwrap();
        std::fs::write(base.join("sub/a b.bin"), b"x").unwrap();
        std::fs::write(dir.path().join("outside.bin"), b"x").unwrap();
        assert!(resolve("sub/a%20b.bin", &base).is_ok());
        assert!(resolve("./sub/a b.bin", &base).is_ok());
        for bad in [
            "file:///etc/passwd",
            "file:/etc/passwd",
            "FILE:outside.bin",
            "http://example.com/x.bin",
            "/etc/passwd",
            "%2Fetc%2Fpasswd",
            "../outside.bin",
            "sub/../../outside.bin",
            "..%2Foutside.bin",
            "",
            "missing.bin",
        ] {
            assert!(resolve(bad, &base).is_err(), "{bad:?} resolved");
        }
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(dir.path().join("outside.bin"), base.join("link.bin"))
                .unwrap();
            let e = resolve("link.bin", &base).unwrap_err();
            assert!(e.contains("out of the model's folder"), "{e}");
        }
        assert!(resolve("x", Path::new("/nonexistent-folder")).is_err());
    }
}
