//! `cirrus bench traverse FILE`: majorant structures side by side on the
//! same random rays, plus conversion speed and memory.

use crate::baseline::{FixedMajorantGrid, GlobalMajorant};
use crate::measure::{density_integral, measure, random_rays, LocalRay, TraversalReport};
use crate::BenchResult;
use cirrus_bricks::{convert, BrickVolume, Precision};
use cirrus_vdb::{Grid, VolumeFile};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct TraverseArgs {
    pub file: PathBuf,
    #[arg(long)]
    pub grid: Option<String>,
    /// Random rays through the volume.
    #[arg(long, default_value_t = 20_000)]
    pub rays: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Cells per axis of the fixed majorant grid (pbrt-v4's NanoVDB medium uses 64).
    #[arg(long, default_value_t = 64)]
    pub fixed_res: i32,
    /// Size of the same volume as .nvdb, for the memory comparison.
    #[arg(long)]
    pub nvdb: Option<PathBuf>,
}

pub fn run(args: &TraverseArgs) -> BenchResult {
    let file = VolumeFile::open(&args.file)?;
    let index = cirrus_scene::grids::choose_grid(&file, args.grid.as_deref())?;
    let start = Instant::now();
    let grid = file.read_grid(index)?;
    let load_s = start.elapsed().as_secs_f64();
    let tree_bytes = grid.tree.memory_bytes();
    println!(
        "file {} grid {:?}: {} active voxels, loaded in {:.3} s",
        args.file.display(),
        grid.name,
        grid.tree.active_voxel_count(),
        load_s
    );

    let volume = convert_each_precision(&grid, tree_bytes)?;
    if let Some(nvdb) = &args.nvdb {
        let len = std::fs::metadata(nvdb)?.len();
        println!(
            "  .nvdb file {}: {} bytes; f32 bricks are {:.3} x that",
            nvdb.display(),
            len,
            volume.total_bytes() as f64 / len as f64
        );
    }

    let rays = random_rays(&volume, args.rays, args.seed);
    let integrals: Vec<f64> = rays.iter().map(|r| density_integral(&volume, r)).collect();
    let global = GlobalMajorant::new(&volume);
    let start = Instant::now();
    let fixed = FixedMajorantGrid::build(&volume, args.fixed_res);
    let fixed_s = start.elapsed().as_secs_f64();
    let reports: Vec<TraversalReport> = vec![
        measure("(a) global majorant", &rays, &integrals, |r| {
            global.segments(r.origin, r.dir, 0.0, r.t_max)
        }),
        measure(
            &format!("(b) fixed {0}^3 grid", args.fixed_res),
            &rays,
            &integrals,
            |r| fixed.segments(r.origin, r.dir, 0.0, r.t_max),
        ),
        measure("(c) cirrus hierarchy", &rays, &integrals, |r| {
            volume.segments(r.origin, r.dir, 0.0, r.t_max)
        }),
    ];
    println!(
        "\ntraversal of {} random rays ({} hit density), fixed grid built in {:.3} s:",
        rays.len(),
        integrals.iter().filter(|&&d| d > 1e-6).count(),
        fixed_s
    );
    print_traversals(&reports);
    lookup_rate(&volume, &rays);
    Ok(())
}

/// Converts `grid` at each precision, printing time, size against the
/// reader's tree (`tree_bytes`) and error; returns the f32 volume.
fn convert_each_precision(
    grid: &Grid,
    tree_bytes: usize,
) -> Result<BrickVolume, Box<dyn std::error::Error>> {
    println!(
        "\nconversion (rayon, {} threads):",
        rayon::current_num_threads()
    );
    let mut volume = None;
    for precision in [Precision::F32, Precision::F16, Precision::U8] {
        let start = Instant::now();
        let v = convert(grid, precision)?;
        let s = start.elapsed().as_secs_f64();
        println!(
            "  {:>3}: {:.3} s, {:.1} M active voxels/s, {} bytes = {:.3} x the reader's tree ({} bytes), max error {:e}",
            precision.name(),
            s,
            v.info.active_voxels as f64 / s / 1e6,
            v.total_bytes(),
            v.total_bytes() as f64 / tree_bytes as f64,
            tree_bytes,
            v.info.max_error
        );
        if precision == Precision::F32 {
            volume = Some(v);
        }
    }
    Ok(volume.expect("converted above"))
}

/// The traversal table: each structure against the global majorant (a).
fn print_traversals(reports: &[TraversalReport]) {
    println!(
        "  {:<24} {:>13} {:>12} {:>14} {:>9} {:>16} {:>9}",
        "structure", "segments/ray", "rays/s", "tightness", "vs (a)", "pooled tightness", "vs (a)"
    );
    for r in reports {
        println!(
            "  {:<24} {:>13.2} {:>12.0} {:>14.2} {:>8.1}x {:>16.3} {:>8.1}x",
            r.name,
            r.segments_per_ray,
            r.rays_per_second,
            r.tightness,
            reports[0].tightness / r.tightness,
            r.pooled_tightness,
            reports[0].pooled_tightness / r.pooled_tightness
        );
    }
    println!(
        "  (tightness: mean over rays of integral(majorant) / integral(density), 1 is the limit;"
    );
    println!("   pooled: the ratio of the sums, which grazing rays do not dominate)");
}

/// Trilinear lookups per second on one thread, at points along `rays`.
fn lookup_rate(volume: &BrickVolume, rays: &[LocalRay]) {
    let points: Vec<glam::Vec3> = rays
        .iter()
        .flat_map(|r| (0..16).map(move |k| r.origin + r.dir * (r.t_max * (k as f32 + 0.5) / 16.0)))
        .collect();
    let start = Instant::now();
    let mut sum = 0f32;
    for p in &points {
        sum += volume.trilinear(*p);
    }
    let s = start.elapsed().as_secs_f64();
    println!(
        "\ndensity lookups: {:.1} M trilinear lookups/s on one thread (checksum {sum:.3})",
        points.len() as f64 / s / 1e6
    );
}
