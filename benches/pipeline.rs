//! Benchmarks of the pipeline's slow stages, on seeded, reproducible inputs.
//!
//! - `voxelize/sphere_100k_tris/64_studs`: a generated UV sphere of about
//!   100,000 triangles, voxelized 64 studs across.
//! - `search/<fixture>/<n>_studs`: [`brickwright::search::build`] with the
//!   default rules' bricks and default options (seed 1): `house.obj` and
//!   `box.obj` at 16 and 24 studs, the thin-walled `mug.obj` at 48, and
//!   `box.obj` at 69 studs, a solid of 102,000 voxels (the layout's goal:
//!   100,000 voxels in 10 s or less on two cores).
//! - `pipeline/house.obj/16_studs`: the whole [`brickwright::pipeline::build`],
//!   outputs written into a temporary directory.
//!
//! ```text
//! cargo bench                                   # all, full measurement
//! cargo bench -- search                         # only the search
//! cargo bench -- --warm-up-time 1 --measurement-time 2   # a quick look
//! ```
//!
//! Speed goals belong here, never in timed unit tests.

use std::path::Path;

use criterion::{criterion_main, BenchmarkId, Criterion};
use glam::Vec3;

use brickwright::mesh::{self, Mesh};
use brickwright::pipeline::{self, BuildOptions, Silent};
use brickwright::search::{self, SearchOptions};
use brickwright::voxel::{voxelize, Sizing, VoxelGrid, VoxelizeOptions};

/// A closed UV sphere of radius 10 centred at (0, 10, 0), with `rings`
/// latitude bands and `2 * rings` longitude segments:
/// `4 * rings * (rings - 1)` triangles.
fn uv_sphere(rings: u32) -> Mesh {
    let segments = 2 * rings;
    let radius = 10.0_f32;
    let mut positions = vec![Vec3::new(0.0, 2.0 * radius, 0.0)];
    for i in 1..rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            positions.push(Vec3::new(
                radius * theta.sin() * phi.cos(),
                radius + radius * theta.cos(),
                radius * theta.sin() * phi.sin(),
            ));
        }
    }
    let south = positions.len() as u32;
    positions.push(Vec3::ZERO);

    let ring = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, ring(1, j + 1), ring(1, j)]);
        triangles.push([south, ring(rings - 1, j), ring(rings - 1, j + 1)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b) = (ring(i, j), ring(i, j + 1));
            let (c, d) = (ring(i + 1, j), ring(i + 1, j + 1));
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    Mesh {
        positions,
        triangles,
        ..Mesh::default()
    }
}

fn fixture(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
}

/// The fixture voxelized in brick-high layers.
fn voxels(name: &str, studs: u32) -> VoxelGrid {
    let mesh = mesh::load(&fixture(name)).expect("fixture loads");
    let opts = VoxelizeOptions::default().with_sizing(Sizing::Studs(studs));
    voxelize(&mesh, &opts).expect("fixture voxelizes").grid
}

fn bench_voxelize(c: &mut Criterion) {
    let sphere = uv_sphere(160);
    let opts = VoxelizeOptions::default().with_sizing(Sizing::Studs(64));
    let mut group = c.benchmark_group("voxelize");
    group.sample_size(10);
    group.bench_function(
        BenchmarkId::new(
            format!("sphere_{}k_tris", sphere.triangles.len() / 1000),
            "64_studs",
        ),
        |b| b.iter(|| voxelize(&sphere, &opts).expect("the sphere voxelizes")),
    );
    group.finish();
}

fn bench_search(c: &mut Criterion) {
    let rules = pipeline::load_rules(None)
        .and_then(|r| r.restricted(|p| p.spec().family() == brickwright::catalog::Family::Brick))
        .expect("the default rules load");
    let opts = SearchOptions::default();
    let mut group = c.benchmark_group("search");
    group.sample_size(10);
    let runs = [
        ("house.obj", 16),
        ("house.obj", 24),
        ("box.obj", 16),
        ("box.obj", 24),
        ("mug.obj", 48),
        ("box.obj", 69),
    ];
    for (name, studs) in runs {
        let grid = voxels(name, studs);
        group.bench_with_input(
            BenchmarkId::new(name, format!("{studs}_studs")),
            &grid,
            |b, grid| b.iter(|| search::build(grid, &rules, &opts).expect("a build")),
        );
    }
    group.finish();
}

fn bench_pipeline(c: &mut Criterion) {
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let mut opts = BuildOptions::new(fixture("house.obj"));
    opts.out_dir = tmp.path().to_path_buf();
    opts.sizing = Sizing::Studs(16);
    let mut group = c.benchmark_group("pipeline");
    group.sample_size(10);
    group.bench_function(BenchmarkId::new("house.obj", "16_studs"), |b| {
        b.iter(|| pipeline::build(&opts, &Silent).expect("house.obj builds"))
    });
    group.finish();
}

/// Every benchmark, configured from the command line. Written out instead
/// of `criterion_group!`, whose generated `pub fn` has no doc comment.
fn benches() {
    let mut c = Criterion::default().configure_from_args();
    bench_voxelize(&mut c);
    bench_search(&mut c);
    bench_pipeline(&mut c);
}

criterion_main!(benches);
