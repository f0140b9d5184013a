//! Benchmarks of the independent verifier on hostile input: `n` 2x4 bricks
//! all at one spot (every one overlaps every other), for n = 7,500 and
//! 30,000. The time should grow about linearly with n (the overlaps are
//! named for at most 8 earlier pieces each). For scale: `brickwright
//! verify` of such a 30,000-line file took 0.46 s in all (release build,
//! reading and reporting included) when this was written, where reporting
//! every overlapping pair had taken more than a minute.
//!
//! ```text
//! cargo bench --bench verify
//! ```

use criterion::{criterion_main, BenchmarkId, Criterion};

use brickwright::assembly::verify::verify;
use brickwright::assembly::{Assembly, Placement};
use brickwright::catalog::{Color, PartKind};
use brickwright::geom::{Cell, Rot};

fn pile(n: usize) -> Assembly {
    let brick = PartKind::from_id("3001").expect("3001 is in the catalog");
    let order = vec![Placement::new(brick, Cell::new(0, 0, 0), Rot::R0); n];
    Assembly::from_order(&order, 24, Color::RED)
}

fn bench_pile(c: &mut Criterion) {
    let mut group = c.benchmark_group("verify_pile");
    group.sample_size(10);
    for n in [7_500, 30_000] {
        let asm = pile(n);
        group.bench_function(BenchmarkId::new("one_spot", n), |b| {
            b.iter(|| verify(&asm, None).failures.len())
        });
    }
    group.finish();
}

/// Every benchmark, configured from the command line.
fn benches() {
    let mut c = Criterion::default().configure_from_args();
    bench_pile(&mut c);
}

criterion_main!(benches);
