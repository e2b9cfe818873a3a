//! Shared scenes and statistics for the integration tests.
#![allow(dead_code)]

use cirrus_render::Bounds3;
use cirrus_render::{
    render, Budget, Camera, Crop, Environment, GridField, Image, IntegratorKind, Lights,
    MajorantMode, Media, Medium, RenderSettings, Rendered, Scene, Sun, Volumes,
};
use glam::Vec3;

/// The kernel's test cloud ([`GridField::cloud`]).
pub fn cloud_field(cell_voxels: usize) -> GridField {
    GridField::cloud(cell_voxels, Vec3::ZERO)
}

/// [`cloud_field`] moved by `offset`.
pub fn cloud_field_at(cell_voxels: usize, offset: Vec3) -> GridField {
    GridField::cloud(cell_voxels, offset)
}

pub fn medium<F: cirrus_render::DensityField>(
    field: F,
    scale: f32,
    albedo: f32,
    g: f32,
) -> Medium<F> {
    Medium::new(field, scale, Vec3::splat(albedo), g)
}

pub fn env(radiance: Vec3) -> Option<Environment> {
    Some(Environment::new(radiance))
}

pub fn sun(angular_diameter_degrees: f32) -> Option<Sun> {
    Some(Sun::new(
        Vec3::new(-0.4, -1.0, -0.3),
        Vec3::new(3.0, 2.8, 2.5),
        angular_diameter_degrees.to_radians(),
    ))
}

/// `medium` alone, framed, under `lights`.
pub fn scene<F>(medium: Medium<F>, size: u32, lights: Lights) -> Scene<Volumes<F>>
where
    F: cirrus_render::DensityField,
{
    // Frame the blob's core rather than the array's bounds, so the blob
    // fills the image.
    let Bounds3 { min: lo, max: hi } = medium.field.bounds();
    let centre = 0.5 * (lo + hi);
    let blob = Vec3::new(0.3, 0.22, 0.3);
    let camera = Camera::framing(Bounds3::new(centre - blob, centre + blob), size, size);
    Scene {
        media: Volumes::from(medium),
        camera,
        lights,
    }
}

/// The 20x20 cloud (density 8, albedo 0.9, g 0.5) under a 2-degree sun
/// and a blue sky: the scene the thread-count and film tests share.
pub fn sunlit_cloud() -> Scene<Volumes<GridField>> {
    let lights = Lights::sun_and_sky(sun(2.0), env(Vec3::new(0.2, 0.3, 0.45)));
    scene(medium(cloud_field(4), 8.0, 0.9, 0.5), 20, lights)
}

/// Renders `media` (borrowed) through `camera` under `lights`.
pub fn render_through<M: Media>(
    media: &M,
    camera: &Camera,
    lights: &Lights,
    settings: &RenderSettings,
) -> Rendered {
    let scene = Scene {
        media,
        camera: *camera,
        lights: lights.clone(),
    };
    render(&scene, settings)
}

/// The tests' settings: the defaults, but the field's own majorant
/// hierarchy always (not the probe's choice), so that what a test traces
/// does not move with the probe.
pub fn settings(integrator: IntegratorKind, spp: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        integrator,
        budget: Budget::Spp(spp),
        seed,
        majorant: MajorantMode::Hierarchy,
        progress: false,
        ..Default::default()
    }
}

/// Per-pixel differences of two images in one channel and their variances
/// `se_a^2 + se_b^2`, for pixels where that is positive; also the largest
/// absolute difference where it is 0 (both exact, which must then agree up
/// to rounding). One channel, because the channels of a pixel share their
/// samples and are strongly correlated, which would break the independence
/// the pooled tests assume.
pub struct Differences {
    pub diff: Vec<f64>,
    pub var: Vec<f64>,
    pub exact_diff: f64,
}

pub fn differences(a: &Image, b: &Image, channel: usize) -> Differences {
    let mut d = Differences {
        diff: Vec::new(),
        var: Vec::new(),
        exact_diff: 0.0,
    };
    for y in 0..a.height {
        for x in 0..a.width {
            let sa = a.std_error(x, y)[channel] as f64;
            let sb = b.std_error(x, y)[channel] as f64;
            let diff = a.pixel(x, y)[channel] as f64 - b.pixel(x, y)[channel] as f64;
            if sa > 0.0 || sb > 0.0 {
                d.diff.push(diff);
                d.var.push(sa * sa + sb * sb);
            } else {
                d.exact_diff = d.exact_diff.max(diff.abs());
            }
        }
    }
    d
}

/// Pooled tests that two images estimate the same thing, for independent
/// pixels:
/// - bias: `sum(diff) / sqrt(sum(var))` is N(0, 1), so `|.| <= 4` fails
///   falsely with probability 6.3e-5. (Summing per-pixel z-scores instead
///   is itself biased: for a skewed estimator a pixel's mean and its
///   estimated variance are correlated.)
/// - spread: `sum(diff^2 / var)` is near chi-square with N degrees of
///   freedom (mean N, standard deviation sqrt(2N)); `<= N + 5 sqrt(2N)`
///   catches per-pixel disagreements that cancel in the sum. The slack
///   beyond 4 standard deviations (Wilson-Hilferty: ~3e-5 for N in the
///   hundreds) absorbs the t-like inflation of z with estimated standard
///   errors (variance (n-1)/(n-3), 3% at 64 spp).
///
/// Also asserts exactly-known pixels agree to f32 rounding.
pub fn assert_pooled_agreement(label: &str, d: &Differences) {
    let n = d.diff.len() as f64;
    assert!(n >= 50.0, "{label}: only {n} pixels with variance");
    let bias = d.diff.iter().sum::<f64>() / d.var.iter().sum::<f64>().sqrt();
    let chi2: f64 = d.diff.iter().zip(&d.var).map(|(x, v)| x * x / v).sum();
    let chi2_bound = n + 5.0 * (2.0 * n).sqrt();
    eprintln!("{label}: N = {n}, bias z = {bias:.3}, chi2 = {chi2:.1} (bound {chi2_bound:.1})");
    assert!(bias.abs() <= 4.0, "{label}: pooled bias z = {bias}");
    assert!(chi2 <= chi2_bound, "{label}: chi2 = {chi2} > {chi2_bound}");
    assert!(
        d.exact_diff <= 1e-5,
        "{label}: exact pixels differ by {}",
        d.exact_diff
    );
}

/// Runs `f` on a pool of `threads` workers.
pub fn with_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// The bits of a render's pixels and their variances: equal bits, equal
/// images (even -0.0 against 0.0 differs).
pub fn image_bits(r: &Rendered) -> Vec<u32> {
    r.image
        .rgba
        .iter()
        .chain(&r.image.variance)
        .flatten()
        .map(|x| x.to_bits())
        .collect()
}

/// A crop window inside every 20x20 test image, off its tile grid.
pub const CROP: Crop = Crop {
    x0: 3,
    y0: 5,
    x1: 17,
    y1: 12,
};

/// Every pixel of `part`, a render of `crop`, has the bits of the same
/// pixel of `full`: its value, its variance and its sample count.
pub fn assert_crop_of(label: &str, part: &Rendered, full: &Rendered, crop: Crop) {
    let (w, fw) = (part.image.width, full.image.width);
    for y in 0..part.image.height {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let j = ((y + crop.y0) * fw + x + crop.x0) as usize;
            let (a, b) = (&part.image, &full.image);
            assert_eq!(
                a.rgba[i].map(f32::to_bits),
                b.rgba[j].map(f32::to_bits),
                "{label}: crop pixel ({x}, {y})"
            );
            assert_eq!(
                a.variance[i].map(f32::to_bits),
                b.variance[j].map(f32::to_bits),
                "{label}: crop pixel ({x}, {y})'s variance"
            );
            assert_eq!(
                a.samples[i], b.samples[j],
                "{label}: crop pixel ({x}, {y})'s samples"
            );
        }
    }
}
