//! `cirrus bench interleave FILE`: free flights one at a time against two
//! at a time on one thread ([`sample_free_flight_pair`]), on the flights a
//! path tracer makes through the volume.
//!
//! A flight is a chain of dependent steps (cell, bounds, brick, voxel,
//! decision), so one core runs it well below its width; two independent
//! flights advanced in turn let the core overlap the chains. The ratio of
//! the two times is what batching paths could gain on the walks, which
//! take nearly half of a path's time.

use crate::BenchResult;
use cirrus_bricks::BrickVolume;
use cirrus_kernel::medium::{BrickField, Media, Medium};
use cirrus_kernel::sampling::uniform_sphere;
use cirrus_kernel::tracking::{sample_free_flight, sample_free_flight_pair, FreeFlight};
use cirrus_kernel::{Counters, Ray, Rng, Volumes};
use cirrus_vdb::VolumeFile;
use glam::{DMat4, DVec3, Vec3};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct InterleaveArgs {
    pub file: PathBuf,
    #[arg(long)]
    pub grid: Option<String>,
    /// Extinction per unit density over one voxel, as `render`'s default
    /// density scale is for a volume of unit voxels.
    #[arg(long, default_value_t = cirrus_scene::DENSITY_SCALE_PER_VOXEL)]
    pub density_scale: f32,
    /// Flights in the workload.
    #[arg(long, default_value_t = 1_000_000)]
    pub flights: usize,
    /// Timed rounds, the two ways alternated; medians are printed.
    #[arg(long, default_value_t = 9)]
    pub rounds: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

pub fn run(args: &InterleaveArgs) -> BenchResult {
    let scale = args.density_scale;
    if !(scale.is_finite() && scale > 0.0) {
        return Err(format!("--density-scale must be finite and > 0, got {scale}").into());
    }
    if args.flights < 2 || args.rounds == 0 {
        return Err("--flights must be at least 2 and --rounds at least 1".into());
    }
    let file = VolumeFile::open(&args.file)?;
    let index = cirrus_scene::grids::choose_grid(&file, args.grid.as_deref())?;
    let volume = cirrus_scene::grids::read_render_bricks(&file, index)?;
    // The volume's own voxel units, refined as the renderer refines it.
    let field = BrickField::new(&volume, DMat4::IDENTITY, DVec3::ZERO).with_refinement(scale, 1.0);
    let media = Volumes::from(Medium::new(field, scale, Vec3::ONE, 0.0));
    let rays = workload(&media, &volume, args.flights & !1, args.seed);

    let (single, singles) = one_at_a_time(&media, &rays, args.seed);
    let (paired, pairs) = two_at_a_time(&media, &rays, args.seed);
    if pairs != singles || paired != single {
        return Err("paired flights ended elsewhere than single flights".into());
    }
    let collisions = singles
        .iter()
        .filter(|f| matches!(f, FreeFlight::Collision { .. }))
        .count();
    println!(
        "{} flights through {} ({} end in a collision), {:.2} tentative collisions and {:.2} segments each",
        rays.len(),
        args.file.display(),
        collisions,
        (single.real_collisions + single.null_collisions) as f64 / rays.len() as f64,
        single.dda_segments as f64 / rays.len() as f64,
    );
    let (mut one, mut two) = (vec![], vec![]);
    for _ in 0..args.rounds {
        let start = Instant::now();
        std::hint::black_box(one_at_a_time(&media, &rays, args.seed));
        one.push(start.elapsed().as_secs_f64());
        let start = Instant::now();
        std::hint::black_box(two_at_a_time(&media, &rays, args.seed));
        two.push(start.elapsed().as_secs_f64());
    }
    let ns = |t: f64| t * 1e9 / rays.len() as f64;
    let (one, two) = (median(&mut one), median(&mut two));
    println!("  one at a time  {:.3} s  {:.1} ns a flight", one, ns(one));
    println!("  two at a time  {:.3} s  {:.1} ns a flight", two, ns(two));
    println!(
        "  two / one      {:.3} of the time (medians of {} alternated rounds)",
        two / one,
        args.rounds
    );
    Ok(())
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Flight `i`'s own generator.
fn flight_rng(seed: u64, i: usize) -> Rng {
    Rng::new(seed, i as u64, 1)
}

fn one_at_a_time<M: Media>(media: &M, rays: &[Ray], seed: u64) -> (Counters, Vec<FreeFlight>) {
    let mut c = Counters::default();
    let flights = rays
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let mut beta = Vec3::ONE;
            sample_free_flight::<f32, _>(
                media,
                r,
                r.t_max,
                &mut beta,
                &mut flight_rng(seed, i),
                &mut c,
            )
        })
        .collect();
    (c, flights)
}

fn two_at_a_time<M: Media>(media: &M, rays: &[Ray], seed: u64) -> (Counters, Vec<FreeFlight>) {
    let mut c = Counters::default();
    let mut flights = Vec::with_capacity(rays.len());
    for (k, pair) in rays.chunks_exact(2).enumerate() {
        let [a, b] = [&pair[0], &pair[1]];
        let (mut ga, mut gb) = (flight_rng(seed, 2 * k), flight_rng(seed, 2 * k + 1));
        let (mut ba, mut bb) = (Vec3::ONE, Vec3::ONE);
        flights.extend(sample_free_flight_pair::<f32, _>(
            media,
            [a, b],
            [a.t_max, b.t_max],
            [&mut ba, &mut bb],
            [&mut ga, &mut gb],
            &mut c,
        ));
    }
    (c, flights)
}

/// `n` flights as a path tracer makes them: rays from outside toward the
/// middle of the volume, then from each real collision in a random
/// direction, up to 64 flights a path.
fn workload<M: Media>(media: &M, volume: &BrickVolume, n: usize, seed: u64) -> Vec<Ray> {
    let extent = volume.local_extent();
    let centre = extent * 0.5;
    let mut rng = Rng::new(seed, u64::MAX, 0);
    let mut c = Counters::default();
    let mut rays = Vec::with_capacity(n);
    'paths: while rays.len() < n {
        let target =
            centre + (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5) * extent * 0.6;
        let from = centre - extent.length() * uniform_sphere(rng.uniform(), rng.uniform());
        let mut ray = Ray::new(from, (target - from).normalize());
        for _ in 0..64 {
            if rays.len() == n {
                break 'paths;
            }
            rays.push(ray);
            let mut beta = Vec3::ONE;
            let flight =
                sample_free_flight::<f32, _>(media, &ray, ray.t_max, &mut beta, &mut rng, &mut c);
            let FreeFlight::Collision { t } = flight else {
                continue 'paths;
            };
            ray = ray.spawn(ray.at(t), uniform_sphere(rng.uniform(), rng.uniform()));
        }
    }
    rays
}
