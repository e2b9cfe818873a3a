//! Measuring a majorant structure on random rays: segments per ray, walk
//! speed, and bound tightness = integral of the majorant over integral of
//! the density along a ray (1.0 is the physical limit; delta tracking's
//! null collisions per real collision grow with it).

use cirrus_bricks::BrickVolume;
use cirrus_bricks::MajorantSegment;
use glam::Vec3;
use std::time::Instant;

/// A ray in the volume's local index space.
#[derive(Clone, Copy, Debug)]
pub struct LocalRay {
    pub origin: Vec3,
    pub dir: Vec3,
    pub t_max: f32,
}

/// `n` seeded random rays between two points on the sphere around the volume.
pub fn random_rays(volume: &BrickVolume, n: usize, seed: u64) -> Vec<LocalRay> {
    let mut s = seed ^ 0x9E37_79B9_7F4A_7C15;
    let mut rnd = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 40) as f32) / (1u64 << 24) as f32
    };
    let extent = volume.local_extent();
    let centre = extent * 0.5;
    let radius = extent.length() * 0.5 + 1.0;
    let mut sphere = move || {
        let z = 2.0 * rnd() - 1.0;
        let phi = std::f32::consts::TAU * rnd();
        let r = (1.0 - z * z).max(0.0).sqrt();
        centre + Vec3::new(r * phi.cos(), r * phi.sin(), z) * radius
    };
    (0..n)
        .map(|_| {
            let a = sphere();
            let b = sphere();
            LocalRay {
                origin: a,
                dir: (b - a).normalize_or(Vec3::X),
                t_max: (b - a).length(),
            }
        })
        .collect()
}

/// Integral of the trilinear density along a ray by the midpoint rule with
/// steps of a quarter voxel.
pub fn density_integral(volume: &BrickVolume, ray: &LocalRay) -> f64 {
    let h = 0.25f32;
    let n = (ray.t_max / h).ceil() as usize;
    (0..n)
        .map(|i| volume.trilinear(ray.origin + ray.dir * ((i as f32 + 0.5) * h)) as f64 * h as f64)
        .sum()
}

/// What one majorant structure did on a set of rays.
#[derive(Clone, Debug, Default)]
pub struct TraversalReport {
    pub name: String,
    pub rays: usize,
    pub segments_per_ray: f64,
    pub rays_per_second: f64,
    /// Mean over rays with density of integral(majorant) / integral(density).
    /// Grazing rays through thin edges weigh as much as any: this mean is
    /// dominated by them.
    pub tightness: f64,
    /// Sum of integral(majorant) over sum of integral(density): the ratio of
    /// tentative to real collisions a delta tracker would see along these rays.
    pub pooled_tightness: f64,
}

/// Runs `walk` over every ray (timed), then measures tightness against the
/// precomputed density integrals.
pub fn measure<I: Iterator<Item = MajorantSegment>>(
    name: &str,
    rays: &[LocalRay],
    integrals: &[f64],
    walk: impl Fn(&LocalRay) -> I,
) -> TraversalReport {
    let start = Instant::now();
    let mut segments = 0usize;
    let mut majorant_integrals = Vec::with_capacity(rays.len());
    for r in rays {
        let mut m = 0f64;
        for s in walk(r) {
            segments += 1;
            m += s.majorant as f64 * (s.t1 - s.t0) as f64;
        }
        majorant_integrals.push(m);
    }
    let secs = start.elapsed().as_secs_f64().max(1e-9);
    let (mut sum, mut counted, mut sum_m, mut sum_d) = (0f64, 0usize, 0f64, 0f64);
    for (&m, &d) in majorant_integrals.iter().zip(integrals) {
        sum_m += m;
        sum_d += d;
        if d > 1e-6 {
            sum += m / d;
            counted += 1;
        }
    }
    TraversalReport {
        name: name.to_string(),
        rays: rays.len(),
        segments_per_ray: segments as f64 / rays.len().max(1) as f64,
        rays_per_second: rays.len() as f64 / secs,
        tightness: sum / counted.max(1) as f64,
        pooled_tightness: sum_m / sum_d.max(1e-300),
    }
}
