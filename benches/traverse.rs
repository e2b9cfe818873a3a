//! Criterion benchmarks of the brick hierarchy on the corpus cloud: ray
//! walks for the three majorant structures, and density lookups.
//! `cargo bench --bench traverse`. (`cirrus bench traverse FILE` prints
//! the same comparison with tightness for any file.)

use cirrus::bricks::{convert, Precision};
use cirrus_bench::baseline::{FixedMajorantGrid, GlobalMajorant};
use cirrus_bench::measure::random_rays;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cloud.vdb");
    let grid = cirrus::vdb::VolumeFile::open(path)
        .unwrap()
        .read_grid_by_name("density")
        .unwrap();
    let v = convert(&grid, Precision::F32).unwrap();
    let rays = random_rays(&v, 4096, 1);
    let global = GlobalMajorant::new(&v);
    let fixed = FixedMajorantGrid::build(&v, 64);
    let mut g = c.benchmark_group("walk 4096 rays");
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.bench_function("global majorant", |b| {
        b.iter(|| {
            rays.iter()
                .map(|r| global.segments(r.origin, r.dir, 0.0, r.t_max).count())
                .sum::<usize>()
        })
    });
    g.bench_function("fixed 64^3 grid", |b| {
        b.iter(|| {
            rays.iter()
                .map(|r| fixed.segments(r.origin, r.dir, 0.0, r.t_max).count())
                .sum::<usize>()
        })
    });
    g.bench_function("cirrus hierarchy", |b| {
        b.iter(|| {
            rays.iter()
                .map(|r| v.segments(r.origin, r.dir, 0.0, r.t_max).count())
                .sum::<usize>()
        })
    });
    g.finish();
    let points: Vec<glam::Vec3> = rays
        .iter()
        .map(|r| r.origin + r.dir * (r.t_max * 0.5))
        .collect();
    let mut g = c.benchmark_group("density lookups");
    g.throughput(Throughput::Elements(points.len() as u64));
    for precision in [Precision::F32, Precision::F16, Precision::U8] {
        let v = convert(&grid, precision).unwrap();
        g.bench_function(format!("trilinear {}", precision.name()), |b| {
            b.iter(|| {
                points
                    .iter()
                    .map(|&p| v.trilinear(black_box(p)))
                    .sum::<f32>()
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("conversion");
    g.throughput(Throughput::Elements(grid.tree.active_voxel_count()));
    g.sample_size(10);
    g.bench_function("cloud to f32 bricks", |b| {
        b.iter(|| convert(&grid, Precision::F32).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
