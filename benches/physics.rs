//! The force analysis's speed on solid blocks of 2 x 4 bricks (each
//! course turned a quarter from the one below, as `benches/booklet.rs`
//! builds them).
//!
//! Targets (2 cores): the full analysis of a 1,000-piece model in under
//! 1 s and of a 5,000-piece model in under 10 s; every step of the
//! 1,000-piece build (grouped as `build` groups it) in under 10 s in all.
//!
//! Measured (2 cores, Clarabel with QDLDL): 1,024 pieces in 0.13 s, 5,040
//! in 0.61 s, every step of the 1,024-piece build in 0.10 s (every step
//! but the last is certified without a solve: each brick rests straight
//! on the ones below). A real model is slower: the 756-piece bunny of
//! `build --studs 32` takes 0.5 s whole and 42 s step by step, since most
//! of its steps add pieces that need clutch and are solved one by one.
//!
//! ```text
//! cargo bench --bench physics
//! cargo bench --bench physics -- --warm-up-time 1 --measurement-time 5
//! ```

use criterion::{criterion_main, BenchmarkId, Criterion};

use brickwright::physics::{analyze, analyze_steps, Params};

mod common;
use common::block;

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
    group.finish();
}

/// Every benchmark, configured from the command line. Written out instead
/// of `criterion_group!`, whose generated `pub fn` has no doc comment.
fn benches() {
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
}

criterion_main!(benches);
