//! The brick hierarchy on the corpus cloud: the bounds it promises, measured.

use cirrus::bricks::{convert, read_cbrk, write_cbrk, Precision};
use cirrus::vdb::VolumeFile;
use cirrus_bench::baseline::{FixedMajorantGrid, GlobalMajorant};
use cirrus_bench::measure::{density_integral, measure, random_rays};
use std::path::Path;

fn cloud() -> cirrus::vdb::Grid {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/cloud.vdb");
    VolumeFile::open(path)
        .unwrap()
        .read_grid_by_name("density")
        .unwrap()
}

#[test]
fn hierarchy_is_4x_tighter_than_one_majorant_and_tighter_than_a_64_cubed_grid() {
    let grid = cloud();
    let v = convert(&grid, Precision::F32).unwrap();
    let rays = random_rays(&v, 4000, 17);
    let integrals: Vec<f64> = rays.iter().map(|r| density_integral(&v, r)).collect();
    let hits = integrals.iter().filter(|&&d| d > 1e-6).count();
    assert!(hits > 500, "only {hits} of the rays meet the cloud");
    let global = GlobalMajorant::new(&v);
    let fixed = FixedMajorantGrid::build(&v, 64);
    let a = measure("global", &rays, &integrals, |r| {
        global.segments(r.origin, r.dir, 0.0, r.t_max)
    });
    let b = measure("fixed 64^3", &rays, &integrals, |r| {
        fixed.segments(r.origin, r.dir, 0.0, r.t_max)
    });
    let c = measure("hierarchy", &rays, &integrals, |r| {
        v.segments(r.origin, r.dir, 0.0, r.t_max)
    });
    eprintln!(
        "tightness: global {:.2}, fixed {:.2}, hierarchy {:.2}",
        a.tightness, b.tightness, c.tightness
    );
    assert!(
        c.tightness >= 1.0 - 1e-3,
        "a bound below the density: {}",
        c.tightness
    );
    assert!(
        a.tightness >= 4.0 * c.tightness,
        "global {} vs hierarchy {}",
        a.tightness,
        c.tightness
    );
    assert!(
        c.tightness < b.tightness,
        "fixed grid {} vs hierarchy {}",
        b.tightness,
        c.tightness
    );
}

#[test]
fn u8_bricks_take_at_most_a_third_of_the_readers_tree() {
    let grid = cloud();
    let tree_bytes = grid.tree.memory_bytes();
    let v = convert(&grid, Precision::U8).unwrap();
    assert!(
        3 * v.total_bytes() <= tree_bytes,
        "u8 bricks {} bytes, tree {tree_bytes}",
        v.total_bytes()
    );
    assert_eq!(v.info.active_voxels, grid.tree.active_voxel_count());
}

#[test]
fn the_cloud_round_trips_through_cbrk_bit_for_bit() {
    let grid = cloud();
    let v = convert(&grid, Precision::F32).unwrap();
    let path = std::env::temp_dir().join(format!("cirrus-cloud-{}.cbrk", std::process::id()));
    write_cbrk(&v, &path).unwrap();
    let back = read_cbrk(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(back.info, v.info);
    let rays = random_rays(&v, 200, 3);
    for r in &rays {
        let a: Vec<_> = v.segments(r.origin, r.dir, 0.0, r.t_max).collect();
        let b: Vec<_> = back.segments(r.origin, r.dir, 0.0, r.t_max).collect();
        assert_eq!(a, b);
        for k in 0..64 {
            let p = r.origin + r.dir * (r.t_max * k as f32 / 64.0);
            assert_eq!(v.trilinear(p).to_bits(), back.trilinear(p).to_bits());
        }
    }
}
