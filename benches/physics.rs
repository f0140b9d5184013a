//! The force analysis's speed on solid blocks of 2 x 4 bricks (each
//! course turned a quarter from the one below, as `benches/booklet.rs`
//! builds them).
//!
//! Targets (2 cores): the full analysis of a 1,000-piece model in under
//! 1 s and of a 5,000-piece model in under 10 s; every step of the
//! 1,000-piece build (grouped as `build` groups it) in under 10 s in all.
//!
//! Measured (2 busy cores): 1,024 pieces in 1.3 ms, 5,040 in 8.6 ms, every
//! step of the 1,024-piece build in 5.5 ms: a block stands on compression
//! alone, which is certified without a solve (Clarabel with QDLDL took
//! 0.13 s and 0.61 s for the two finished blocks).
//!
//! A real build is slower, since most of its steps add pieces that need
//! clutch and are solved one by one: `steps/mug` checks every step of the
//! search's build of `fixtures/mug.obj` at 32 studs, and `support/arch`
//! plans and checks the support columns of `fixtures/arch.obj` at 24
//! studs (the search leaves one leg's voxels out, so its span hangs from
//! the other leg) until it stands.
//!
//! ```text
//! cargo bench --bench physics
//! cargo bench --bench physics -- --warm-up-time 1 --measurement-time 5
//! ```

use criterion::{criterion_main, BenchmarkId, Criterion};

use std::path::Path;

use brickwright::assembly::Assembly;
use brickwright::catalog::Color;
use brickwright::physics::support::{shore_up, Upto};
use brickwright::physics::{analyze, analyze_steps, Params};

mod common;
use common::block;

/// The search's build of a fixture mesh, searched, sequenced and grouped
/// as `build` does it.
fn fixture_build(name: &str, studs: u32) -> Assembly {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name);
    brickwright::pipeline::bricks_by_course(&path, studs).expect("the fixture builds")
}

fn bench(c: &mut Criterion) {
    let params = Params::default();
    let mut group = c.benchmark_group("physics");
    group.sample_size(10);
    // 16 x 16 studs, 32 courses: 1,024 bricks; 24 x 24, 70: 5,040.
    for (side, courses) in [(16, 32), (24, 70)] {
        let a = block(side, courses);
        group.bench_function(BenchmarkId::new("analyze", a.pieces.len()), |b| {
            b.iter(|| analyze(&a, &params).expect("solves"))
        });
    }
    let a = block(16, 32);
    group.bench_function(BenchmarkId::new("steps", a.pieces.len()), |b| {
        b.iter(|| analyze_steps(&a, &params, false).expect("solves"))
    });
    let mug = fixture_build("mug.obj", 32);
    group.bench_function(BenchmarkId::new("steps/mug", mug.pieces.len()), |b| {
        b.iter(|| analyze_steps(&mug, &params, false).expect("solves"))
    });
    // Organic builds at the sizes the issue names: every step of the mug
    // (a curved shell with an overhanging handle) at 48 and 64 studs.
    for studs in [48, 64] {
        let mug = fixture_build("mug.obj", studs);
        group.bench_function(
            BenchmarkId::new(format!("steps/mug-{studs}"), mug.pieces.len()),
            |b| b.iter(|| analyze_steps(&mug, &params, false).expect("solves")),
        );
    }
    let arch = fixture_build("arch.obj", 24);
    let fails = analyze_steps(&arch, &params, false)
        .expect("solves")
        .first_failure;
    group.bench_function(BenchmarkId::new("support/arch", arch.pieces.len()), |b| {
        b.iter(|| {
            let shored = shore_up(
                &arch,
                &params,
                fails.map_or(Upto::Finished, Upto::Failing),
                0,
                Color(71),
                None,
                false,
            )
            .expect("solves")
            .expect("columns");
            assert!(shored.stands);
            shored
        })
    });
    group.finish();
}

/// Every benchmark, configured from the command line. Written out instead
/// of `criterion_group!`, whose generated `pub fn` has no doc comment.
fn benches() {
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
}

criterion_main!(benches);
