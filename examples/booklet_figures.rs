//! The booklet's figures for finished builds: pieces, steps, pieces a
//! step, booklet pages, and how much of each step image the model fills
//! (the larger side of its box over the frame's, median and lowest tenth),
//! one Markdown table row a build.
//!
//! ```text
//! brickwright build MESH -o OUT --studs N
//! cargo run --release --example booklet_figures -- OUT...
//! ```
//!
//! The model's box is the image's non-white pixels, leaving out the
//! corner squares where a "turn the model" badge may be drawn (so a share
//! is a lower bound), as `tests/framing.rs` measures it.

use std::path::Path;

use anyhow::{bail, Context, Result};

/// The larger side of the box of non-white pixels over the frame's,
/// corners of side `corner` left out.
fn share(img: &image::RgbImage, corner: u32) -> f64 {
    let (w, h) = img.dimensions();
    let in_corner =
        |x: u32, y: u32| (x < corner || x >= w - corner) && (y < corner || y >= h - corner);
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for (x, y, p) in img.enumerate_pixels() {
        if p.0.iter().all(|&c| c >= 250) || in_corner(x, y) {
            continue;
        }
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
    }
    if x1 <= x0 {
        return 0.0;
    }
    f64::max(
        f64::from(x1 - x0) / f64::from(w),
        f64::from(y1 - y0) / f64::from(h),
    )
}

fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() as f64 * q).ceil() as usize).saturating_sub(1)]
}

fn row(dir: &Path) -> Result<String> {
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("report.json"))
            .with_context(|| format!("{}: no report.json", dir.display()))?,
    )?;
    let pieces = report["pieces"].as_u64().unwrap_or(0);
    let steps = report["steps"].as_u64().unwrap_or(0);
    let pages = report["booklet_pages"]
        .as_u64()
        .map_or("-".into(), |p| p.to_string());
    let mut shares = Vec::new();
    for n in 1..=steps {
        let path = dir.join("steps").join(format!("step-{n:03}.png"));
        let img = image::open(&path)
            .with_context(|| format!("{}", path.display()))?
            .to_rgb8();
        let corner = (img.width().min(img.height()) as f32 * 0.15).round() as u32 + 24;
        shares.push(share(&img, corner));
    }
    if shares.is_empty() {
        bail!("{}: no step images", dir.display());
    }
    Ok(format!(
        "| {} | {pieces} | {steps} | {:.1} | {pages} | {:.2} / {:.2} |",
        dir.file_name().unwrap_or_default().to_string_lossy(),
        pieces as f64 / steps.max(1) as f64,
        quantile(&mut shares, 0.5),
        quantile(&mut shares, 0.1),
    ))
}

fn main() -> Result<()> {
    let dirs: Vec<String> = std::env::args().skip(1).collect();
    if dirs.is_empty() {
        bail!("usage: booklet_figures BUILD_DIR...");
    }
    println!(
        "| build | pieces | steps | pieces a step | pages | framing share, median / lowest tenth |"
    );
    println!("|---|---|---|---|---|---|");
    for d in dirs {
        println!("{}", row(Path::new(&d))?);
    }
    Ok(())
}
