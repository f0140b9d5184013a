//! Benchmarks of the instruction renderer, on a seeded build.
//!
//! - `render/house.obj_24_studs/steps`: every step image of the house
//!   fixture built 24 studs across (seed 1, about 540 pieces), 800 x 600,
//!   drawn incrementally and encoded as PNG in memory, on one thread.
//! - `render/house.obj_24_studs/model`: the finished model alone.
//!
//! ```text
//! cargo bench --bench render
//! ```
//!
//! The goal: a 1,000-piece booklet's step images in well under 5 s on two
//! cores; `examples/render_steps.rs` measures the parallel writer.

use std::path::Path;

use criterion::{criterion_main, Criterion};

use brickwright::pipeline::{self, BuildOptions, Silent};
use brickwright::render::{self, RenderOptions};
use brickwright::voxel::Sizing;

fn bench_render(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let mut opts =
        BuildOptions::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/house.obj"));
    opts.out_dir = dir.path().to_path_buf();
    opts.sizing = Sizing::Studs(24);
    let asm = pipeline::build(&opts, &Silent)
        .expect("house builds")
        .assembly;
    let ropts = RenderOptions::default();
    let renderer = render::renderer(&asm, &ropts).expect("valid options");

    let mut group = c.benchmark_group("render/house.obj_24_studs");
    group.sample_size(10);
    group.bench_function("steps", |b| {
        b.iter(|| {
            let mut bytes = 0;
            for (_, img) in renderer.images() {
                let mut out = Vec::new();
                render::write_png(&img, false, &mut out).expect("in memory");
                bytes += out.len();
            }
            bytes
        })
    });
    group.bench_function("model", |b| b.iter(|| renderer.model_image()));
    group.finish();
}

/// Every benchmark, configured from the command line. Written out instead
/// of `criterion_group!`, whose generated `pub fn` has no doc comment.
fn benches() {
    let mut c = Criterion::default().configure_from_args();
    bench_render(&mut c);
}

criterion_main!(benches);
