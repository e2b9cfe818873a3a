//! Chromatic media: extinction per RGB channel.
//!
//! - An RGB absorbing box against `exp(-sigma_c d)` per channel, for every
//!   transmittance estimator, the spectral free flight's escape weight and
//!   the path tracer's pixels.
//! - Equal channels forced through the spectral code agree with the grey
//!   path tracer within noise, and with the grey ray marcher bit for bit.
//! - Two overlapping chromatic instances render as one medium with their
//!   summed extinction (the per-channel instance weights).

mod common;

use cirrus_kernel::medium::{Extinction, Interaction, Lattice};
use cirrus_kernel::tracking::{sample_free_flight, transmittance, FreeFlight};
use cirrus_kernel::{Ray, Rng, Spectrum};
use cirrus_render::{
    render, Bounds3, Camera, ConstantBox, Counters, IntegratorKind, Lights, Media, Medium, Scene,
    TransmittanceEstimator, Volumes,
};
use common::render_through;
use glam::Vec3;

/// Mean and standard error of each channel of `n` draws.
fn mean_and_error(n: u32, mut draw: impl FnMut(u32) -> Vec3) -> (Vec3, Vec3) {
    let (mut sum, mut sum2) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
    for i in 0..n {
        let v = draw(i).as_dvec3();
        sum += v;
        sum2 += v * v;
    }
    let n = n as f64;
    let mean = sum / n;
    let var = (sum2 / n - mean * mean).max(glam::DVec3::ZERO) * (n / (n - 1.0));
    (mean.as_vec3(), (var / n).as_vec3().map(f32::sqrt))
}

fn rgb_box() -> (Volumes<ConstantBox>, Vec3) {
    let b = ConstantBox::new(Vec3::splat(-0.5), Vec3::splat(0.5), 1.0, 0.05);
    let sigma = Vec3::new(1.6, 0.8, 0.16);
    let e = Extinction::split(sigma);
    let medium = Medium::new(b, e.scale, Vec3::ZERO, 0.0).with_extinction_tint(e.tint);
    (Volumes::from(medium), sigma)
}

#[test]
fn rgb_absorbing_box_matches_beer_lambert_per_channel() {
    let (medium, sigma) = rgb_box();
    assert!(medium.chromatic());
    // A ray crossing the unit box along x: chord 1.
    let ray = Ray::new(Vec3::new(-2.0, 0.1, -0.2), Vec3::X);
    let expected = (-sigma).exp();
    let n = 40_000;
    let check = |label: &str, (mean, se): (Vec3, Vec3)| {
        for c in 0..3 {
            // 5 standard errors: a false failure has probability 6e-7.
            let bound = 5.0 * se[c] + 1e-4;
            assert!(
                (mean[c] - expected[c]).abs() <= bound,
                "{label} channel {c}: {} vs {} (bound {bound})",
                mean[c],
                expected[c]
            );
        }
        eprintln!("{label}: {mean} vs {expected}");
    };
    for est in [
        TransmittanceEstimator::Ratio,
        TransmittanceEstimator::Residual,
        TransmittanceEstimator::TrackLength,
    ] {
        let mut c = Counters::default();
        let r = mean_and_error(n, |i| {
            let mut rng = Rng::new(3, u64::from(i), 0);
            transmittance::<Vec3, _>(est, &medium, &ray, f32::INFINITY, &mut rng, &mut c)
        });
        check(est.name(), r);
        assert_eq!(c.majorant_violations, 0);
    }
    // The spectral free flight's escape weight estimates T per channel.
    let mut c = Counters::default();
    let r = mean_and_error(n, |i| {
        let mut rng = Rng::new(5, u64::from(i), 0);
        let mut beta = Vec3::ONE;
        match sample_free_flight::<Vec3, _>(
            &medium,
            &ray,
            f32::INFINITY,
            &mut beta,
            &mut rng,
            &mut c,
        ) {
            FreeFlight::Escaped => beta,
            _ => Vec3::ZERO,
        }
    });
    check("spectral flight", r);
}

#[test]
fn rgb_absorbing_box_renders_beer_lambert_per_channel() {
    let (medium, sigma) = rgb_box();
    let b = medium.instances()[0].field;
    let l_env = Vec3::new(1.0, 0.8, 0.5);
    let size = 16;
    let camera = Camera::new(
        Vec3::new(0.0, 0.0, 3.0),
        Vec3::ZERO,
        Vec3::Y,
        12.0,
        size,
        size,
    );
    let scene = Scene {
        media: medium,
        camera,
        lights: Lights::sun_and_sky(None, common::env(l_env)),
    };
    let spp = 256;
    let out = render(&scene, &common::settings(IntegratorKind::Path, spp, 11));
    // Looking down z through the unit box face on, every pixel whose
    // footprint lies inside the face sees a chord close to 1; the chord
    // varies by under 0.1% over this narrow view, bounded below.
    let mut tested = 0;
    for y in 0..size {
        for x in 0..size {
            let chords: Vec<f32> = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .iter()
                .map(|&(dx, dy)| {
                    let r = camera.ray(x as f32 + dx, y as f32 + dy);
                    Bounds3::new(b.lo, b.hi)
                        .clip_ray(r.origin, r.dir, 0.0, f32::INFINITY)
                        .map_or(0.0, |(t0, t1)| t1 - t0)
                })
                .collect();
            let (lo, hi) = chords
                .iter()
                .fold((f32::MAX, 0f32), |(a, b), &d| (a.min(d), b.max(d)));
            if lo <= 0.0 {
                continue;
            }
            let px = out.image.pixel(x, y);
            let se = out.image.std_error(x, y);
            for c in 0..3 {
                let (t_hi, t_lo) = ((-sigma[c] * lo).exp(), (-sigma[c] * hi).exp());
                let got = px[c] / l_env[c];
                let bound = 5.0 * se[c] / l_env[c] + 1e-5;
                assert!(
                    got >= t_lo - bound && got <= t_hi + bound,
                    "pixel ({x}, {y}) channel {c}: {got} outside [{t_lo}, {t_hi}] +- {bound}"
                );
            }
            tested += 1;
        }
    }
    assert!(tested >= 100, "only {tested} pixels inside the box");
    assert_eq!(out.stats.counters.nonfinite_samples, 0);
}

/// Any media, declared chromatic: equal channels through the spectral code.
struct ForceChromatic<M>(M);

impl<M: Media> Media for ForceChromatic<M> {
    type Majorants<'a>
        = M::Majorants<'a>
    where
        Self: 'a;
    fn majorants(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> Self::Majorants<'_> {
        self.0.majorants(o, d, t0, t1)
    }
    fn extinction<S: Spectrum>(&self, p: Vec3, time: f32) -> S {
        self.0.extinction(p, time)
    }
    fn chromatic(&self) -> bool {
        true
    }
    /// Each channel looked up, as for a mixture of tints.
    fn uniform_tint(&self) -> Option<Vec3> {
        None
    }
    fn march_lattice(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        lattice: Lattice,
        visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        self.0.march_lattice(o, d, t_max, lattice, visit)
    }
    fn bounds(&self) -> Bounds3 {
        self.0.bounds()
    }
    fn voxel_size(&self) -> f32 {
        self.0.voxel_size()
    }
    fn max_sigma_t(&self) -> f32 {
        self.0.max_sigma_t()
    }
    fn interaction(&self, p: Vec3, time: f32, rng: &mut Rng) -> Interaction<'_> {
        self.0.interaction(p, time, rng)
    }
    fn emits(&self) -> bool {
        self.0.emits()
    }
    fn emission(&self, p: Vec3, time: f32, instance: u32, c: &mut Counters) -> Vec3 {
        self.0.emission(p, time, instance, c)
    }
}

fn cloud_scene() -> (Volumes<cirrus_render::GridField>, Camera, Lights) {
    let medium = common::medium(common::cloud_field(4), 12.0, 0.9, 0.5);
    let lights = Lights::sun_and_sky(common::sun(0.0), common::env(Vec3::new(0.3, 0.4, 0.6)));
    let s = common::scene(medium, 24, lights);
    (s.media, s.camera, s.lights)
}

#[test]
fn equal_channels_through_spectral_tracking_agree_with_grey() {
    let (medium, camera, lights) = cloud_scene();
    let settings = common::settings(IntegratorKind::Path, 64, 21);
    let grey = render_through(&medium, &camera, &lights, &settings);
    let forced = ForceChromatic(medium);
    // With equal channels spectral tracking takes delta tracking's
    // decisions from the same numbers, its weights 1 up to rounding: with
    // the same seed the images match to rounding...
    let same_seed = render_through(&forced, &camera, &lights, &settings);
    assert_ne!(
        grey.image.rgba, same_seed.image.rgba,
        "the spectral code ran"
    );
    for (a, b) in grey.image.rgba.iter().zip(&same_seed.image.rgba) {
        for c in 0..4 {
            assert!(
                (a[c] - b[c]).abs() <= 1e-4 * (1.0 + a[c].abs()),
                "{a:?} vs {b:?}"
            );
        }
    }
    // ...and with another seed they agree within noise.
    let settings = common::settings(IntegratorKind::Path, 64, 22);
    let spectral = render_through(&forced, &camera, &lights, &settings);
    for c in 0..4 {
        let mut d = common::differences(&grey.image, &spectral.image, c);
        // Where every grey sample escaped (variance 0), the spectral
        // weights vary by rounding alone (variance ~1e-14): such pixels
        // are exact, not noisy, and must agree to rounding.
        let (mut diff, mut var) = (Vec::new(), Vec::new());
        for (&x, &v) in d.diff.iter().zip(&d.var) {
            if v < 1e-10 {
                d.exact_diff = d.exact_diff.max(x.abs());
            } else {
                diff.push(x);
                var.push(v);
            }
        }
        (d.diff, d.var) = (diff, var);
        common::assert_pooled_agreement(&format!("channel {c}"), &d);
    }
}

#[test]
fn equal_channels_through_the_rgb_march_are_the_grey_march() {
    let (medium, camera, lights) = cloud_scene();
    let mut settings = common::settings(IntegratorKind::RayMarch, 4, 8);
    settings.step_voxels = 1.0;
    let grey = render_through(&medium, &camera, &lights, &settings);
    let forced = ForceChromatic(medium);
    let rgb = render_through(&forced, &camera, &lights, &settings);
    for (a, b) in grey.image.rgba.iter().zip(&rgb.image.rgba) {
        assert_eq!(a[..3], b[..3]);
        assert!((a[3] - b[3]).abs() <= 1e-6);
    }
}

#[test]
fn overlapping_chromatic_instances_render_as_their_sum() {
    let (_, camera, lights) = cloud_scene();
    let field = common::cloud_field(4);
    let (a, b) = (Vec3::new(1.0, 0.4, 0.2), Vec3::new(0.3, 1.0, 0.6));
    let (sa, sb) = (7.0, 5.0);
    let albedo = Vec3::new(0.95, 0.9, 0.8);
    let instance = |scale: f32, tint: Vec3| {
        Medium::new(field.clone(), scale, albedo, 0.5).with_extinction_tint(tint)
    };
    let pair = Volumes::new(vec![instance(sa, a), instance(sb, b)]);
    let sum = Extinction::split(sa * a + sb * b);
    let one = Volumes::new(vec![instance(sum.scale, sum.tint)]);
    assert!(pair.chromatic() && one.chromatic());
    let r_pair = render_through(
        &pair,
        &camera,
        &lights,
        &common::settings(IntegratorKind::Path, 64, 33),
    );
    let r_one = render_through(
        &one,
        &camera,
        &lights,
        &common::settings(IntegratorKind::Path, 64, 34),
    );
    for c in 0..3 {
        let d = common::differences(&r_pair.image, &r_one.image, c);
        common::assert_pooled_agreement(&format!("channel {c}"), &d);
    }
    assert_eq!(r_pair.stats.counters.nonfinite_samples, 0);
}
