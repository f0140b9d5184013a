//! Step pictures a builder can read, steps of a builder's size, measured
//! on real builds of the fixtures:
//!
//! - framing: in each step image written by the build, the model's
//!   bounding box (its non-white pixels) fills most of the frame (larger
//!   side at least 60% of the frame's in the median step, 45% in the
//!   lowest tenth), and never touches the frame's edge (nothing new is
//!   cut off, and the "turn the model" badge covers no new piece); the
//!   scale changes rarely, by a quarter or more each time;
//! - steps: 3 to 8 new pieces a step (mean at least 3 on models of 100
//!   pieces or more, at least 80% of the steps between 3 and 8), the
//!   steps numbered 1, 2, 3, ... in the order of the pieces;
//! - the page: the booklet's step pictures, cut to the model, are mostly
//!   model (little white around it), no model pixel runs under a step's
//!   number or callout, nothing overlaps or leaves its cell or the page,
//!   and a page holds more steps than the four of a fixed grid.
//!
//! The measures are in `common/framing.rs`, which
//! `examples/framing_table.rs` shares to print them for any mesh.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use brickwright::pipeline::{self, BuildOptions, BuildOutput, Formats, Silent, Stability};
use brickwright::voxel::Sizing;

#[path = "common/framing.rs"]
mod measure;

use measure::{model_box, quantile};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Builds `fixture` at `studs` into `out`, the steps drawn; the stability
/// stage only when `stability` says (it reorders nothing on a fixture that
/// stands, and takes most of the time).
fn build(fixture: &str, studs: u32, stability: Stability, out: &Path) -> BuildOutput {
    let mut opts = BuildOptions::new(root().join("fixtures").join(fixture));
    opts.out_dir = out.to_path_buf();
    opts.sizing = Sizing::Studs(studs);
    opts.formats = Formats::parse("ldr,steps").unwrap();
    opts.stability = stability;
    pipeline::build(&opts, &Silent).unwrap_or_else(|e| panic!("{fixture} does not build: {e}"))
}

/// Builds `fixture` and checks its step pictures, its steps and its
/// booklet's step pages (see the module docs).
fn check(fixture: &str, studs: u32, stability: Stability) {
    let tmp = tempfile::tempdir().unwrap();
    let built = build(fixture, studs, stability, tmp.path());
    let a = &built.assembly;
    let steps = built.report.steps as usize;
    let r = measure::renderer(a);
    assert_eq!(r.steps().len(), steps);
    let images = measure::step_images(&tmp.path().join("steps"), steps);

    // Framing.
    let f = measure::framing(&r, &images);
    let median = quantile(&f.shares, 0.5);
    let tenth = quantile(&f.shares, 0.1);
    let name = format!("{fixture} at {studs} studs");
    eprintln!(
        "{name}: {} pieces, {steps} steps, share median {median:.2}, lowest tenth {tenth:.2}, {} turns",
        built.report.pieces, f.turns
    );
    assert!(
        f.blank.is_empty(),
        "{name}: steps show nothing: {:?}",
        f.blank
    );
    assert!(
        f.at_edge.is_empty(),
        "{name}: steps run off the frame: {:?}",
        f.at_edge
    );
    assert!(
        f.cut_off.is_empty(),
        "{name}: new pieces cut off: {:?}",
        f.cut_off
    );
    assert!(
        f.badge_over_new.is_empty(),
        "{name}: the turn badge covers new pieces: {:?}",
        f.badge_over_new
    );
    assert!(
        f.small_changes().is_empty(),
        "{name}: the scale changes by less than a quarter: {:?}",
        f.small_changes()
    );
    assert!(median >= 0.6, "{name}: median share {median:.2}");
    assert!(tenth >= 0.45, "{name}: lowest tenth's share {tenth:.2}");

    // Steps.
    let sizes = measure::step_sizes(a).expect("steps numbered 1, 2, ... with no gap");
    let pieces: usize = sizes.iter().sum();
    assert_eq!(pieces, built.report.pieces);
    let mean = pieces as f64 / sizes.len() as f64;
    assert!(pieces >= 100, "{name}: only {pieces} pieces");
    assert!(mean >= 3.0, "{name}: {mean:.2} pieces a step");
    assert!(
        sizes.iter().all(|&s| s <= 8),
        "{name}: a step of more than 8 pieces: {sizes:?}"
    );
    let sized = sizes.iter().filter(|&&s| (3..=8).contains(&s)).count();
    assert!(
        sized * 10 >= sizes.len() * 8,
        "{name}: only {sized} of {} steps have 3 to 8 pieces: {sizes:?}",
        sizes.len()
    );

    // The page: the printed pictures are at least 85% model across in
    // the median step and 60% in the lowest tenth (the rest of the
    // frame's white is cut away), and a page of steps holds at least five
    // steps on average.
    let notes: BTreeMap<u32, String> = built
        .report
        .stability
        .iter()
        .flat_map(|s| &s.supports)
        .flat_map(|c| (c.step..=c.last_step).map(|s| (s, pipeline::SUPPORT_NOTE.to_string())))
        .collect();
    let p = measure::pages(a, &r, &images, &notes);
    let (median, tenth) = (quantile(&p.shares, 0.5), quantile(&p.shares, 0.1));
    eprintln!(
        "{name}: {steps} steps on {} pages, printed share median {median:.2}, lowest tenth {tenth:.2}",
        p.pages
    );
    assert!(median >= 0.85, "{name}: printed share median {median:.2}");
    assert!(
        tenth >= 0.6,
        "{name}: printed share lowest tenth {tenth:.2}"
    );
    assert!(
        steps >= 5 * p.pages || p.pages == 1,
        "{name}: {steps} steps on {} pages",
        p.pages
    );
}

#[test]
fn a_tall_model_is_framed_as_it_grows() {
    check("tower.glb", 20, Stability::Off);
}

#[test]
fn a_hollow_model_is_framed_and_stepped_for_people() {
    check("mug.obj", 20, Stability::Off);
}

#[test]
fn a_house_is_framed_and_its_pages_filled() {
    check("house.obj", 16, Stability::Off);
}

#[test]
fn a_barn_with_a_roof_is_framed_and_stepped_for_people() {
    check("barn.obj", 24, Stability::Off);
}

#[test]
fn a_staircase_is_framed_as_it_climbs() {
    check("staircase.obj", 20, Stability::Off);
}

#[test]
fn an_arch_is_framed_and_its_steps_checked_to_stand() {
    // With the stability stage: its order and steps are the build's.
    check("arch.obj", 24, Stability::Repair);
}

#[test]
fn framing_is_measured_on_the_model_not_the_white() {
    // The measure itself: a box drawn on white is found exactly, and a
    // masked corner is left out.
    let mut img = image::RgbImage::from_pixel(100, 80, image::Rgb([255, 255, 255]));
    for y in 10..30 {
        for x in 20..70 {
            img.put_pixel(x, y, image::Rgb([200, 0, 0]));
        }
    }
    img.put_pixel(99, 79, image::Rgb([0, 0, 0]));
    assert_eq!(model_box(&img, 5), Some((20, 10, 69, 29)));
    assert_eq!(model_box(&img, 0), Some((20, 10, 99, 79)));
}
