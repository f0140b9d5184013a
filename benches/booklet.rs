//! The booklet's speed: rendering every step image, the model, the
//! exploded view and the part pictures, then laying out the PDF, for
//! models of about 1,000 and 5,000 pieces.
//!
//! Targets (2 cores): the full booklet of a 1,000-piece model in under
//! 5 s, of a 5,000-piece model in under 30 s. The models are solid blocks
//! of 2 x 4 bricks, each course turned a quarter from the one below, built
//! course by course and grouped into steps as `build` groups them; the
//! search is not part of this benchmark (`benches/pipeline.rs` has it).
//!
//! ```text
//! cargo bench --bench booklet
//! cargo bench --bench booklet -- --warm-up-time 1 --measurement-time 5
//! ```

use criterion::{criterion_main, BenchmarkId, Criterion};

mod common;
use common::block;

use brickwright::booklet::Template;
use brickwright::pipeline::pictures::{booklet, render_all, Pictures};

fn bench(c: &mut Criterion) {
    let template = Template::default();
    let mut group = c.benchmark_group("booklet");
    group.sample_size(10);
    // 16 x 16 studs: 32 bricks a course; 24 x 24: 72.
    for (side, courses) in [(16, 32), (24, 70)] {
        let a = block(side, courses);
        let n = a.pieces.len();
        let size = f64::from(side);
        let pictures = Pictures {
            assembly: &a,
            title: "block",
            size_studs: [size, size, f64::from(courses)],
            size_cm: [size * 0.8, size * 0.8, f64::from(courses) * 0.96],
            step_notes: Default::default(),
        };
        group.bench_function(BenchmarkId::new("pieces", n), |b| {
            b.iter(|| {
                let rendered =
                    render_all(&pictures, true, &brickwright::pipeline::Silent).expect("renders");
                booklet(&pictures, &rendered, &template).expect("lays out")
            })
        });
    }
    group.finish();
}

/// Every benchmark, configured from the command line. Written out instead
/// of `criterion_group!`, whose generated `pub fn` has no doc comment.
fn benches() {
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
}

criterion_main!(benches);
