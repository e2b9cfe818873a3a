//! White furnace: a non-absorbing medium in a constant environment,
//! without a sun, is invisible. Every pixel must equal the environment
//! whatever the density, with unlimited scattering; so under a sun that
//! covers the sphere, and inside a sphere light.

mod common;

use std::f32::consts::PI;

use cirrus_render::{
    render, DistanceSampling, IntegratorKind, Lights, MajorantMode, Rendered, SphereLight, Sun,
    TransmittanceEstimator,
};
use glam::Vec3;

#[test]
fn white_furnace_is_invisible() {
    let l_env = 0.75f32;
    let configs = [
        (TransmittanceEstimator::Ratio, MajorantMode::Hierarchy, 0.6),
        (
            TransmittanceEstimator::Residual,
            MajorantMode::Hierarchy,
            -0.3,
        ),
        (
            TransmittanceEstimator::TrackLength,
            MajorantMode::Global,
            0.0,
        ),
    ];
    for (i, (estimator, majorant, g)) in configs.into_iter().enumerate() {
        // Peak optical depth across the cloud about 5: many paths scatter
        // several times before escaping.
        let medium = common::medium(common::cloud_field(4), 8.0, 1.0, g);
        let lights = Lights::sun_and_sky(None, common::env(Vec3::splat(l_env)));
        let scene = common::scene(medium, 16, lights);
        let mut settings = common::settings(IntegratorKind::Path, 64, 100 + i as u64);
        settings.transmittance = estimator;
        settings.majorant = majorant;
        settings.max_depth = None;
        let out = render(&scene, &settings);
        let label = format!("{estimator:?}/{majorant:?}/g={g}");
        assert_eq!(
            out.stats.counters.nonfinite_samples + out.stats.counters.collision_cap_hits,
            0,
            "{label}"
        );
        assert!(
            out.stats.counters.real_collisions > 1000,
            "{label}: the medium must matter"
        );

        let img = &out.image;
        let (mut diff_sum, mut var_sum, mut with_variance) = (0f64, 0f64, 0usize);
        for y in 0..img.height {
            for x in 0..img.width {
                let (px, se) = (img.pixel(x, y), img.std_error(x, y));
                for c in 0..3 {
                    // 5 standard errors (estimated from the pixel's own 64
                    // samples) per value: for a t distribution with 63
                    // degrees of freedom about 5e-6 each, ~4e-3 over the
                    // 256 x 3 values (strongly correlated across channels,
                    // so nearer 1e-3). Plus f32 rounding of the running
                    // mean, 1e-5 relative.
                    let bound = 5.0 * se[c] + 1e-5 * l_env;
                    assert!(
                        (px[c] - l_env).abs() <= bound,
                        "{label}: pixel ({x}, {y}) = {} (bound {bound})",
                        px[c]
                    );
                }
                if se[1] > 0.0 {
                    diff_sum += (px[1] - l_env) as f64;
                    var_sum += (se[1] as f64).powi(2);
                    with_variance += 1;
                }
            }
        }
        assert!(
            with_variance > 128,
            "{label}: most pixels should see the cloud"
        );
        // Pooled over the image (green channel): the summed error over its
        // summed variance, sum(m - L) / sqrt(sum se^2), is N(0, 1) for
        // independent pixels; |.| <= 4 fails falsely with probability
        // 6e-5. (Summing per-pixel z-scores instead would be biased: for a
        // skewed estimator a pixel's mean and its estimated variance are
        // correlated.)
        let pooled = diff_sum / var_sum.sqrt();
        eprintln!(
            "{label}: {with_variance} pixels with variance, pooled z {pooled:.3}, {:.2} s",
            out.stats.wall_seconds
        );
        assert!(pooled.abs() <= 4.0, "{label}: pooled z {pooled}");
    }
}

#[test]
fn a_sun_covering_the_sphere_is_a_furnace_too() {
    // A sun of angular diameter 2 pi is a uniform sphere of radiance
    // E / (4 pi): the same furnace, but through the sun's own sampling,
    // disc test and MIS weights.
    let irradiance = 2.0f32;
    let l = irradiance / (4.0 * PI);
    let sun = Sun::new(Vec3::new(0.3, -1.0, 0.2), Vec3::splat(irradiance), 2.0 * PI);
    let medium = common::medium(common::cloud_field(4), 8.0, 1.0, 0.5);
    let scene = common::scene(medium, 16, Lights::sun_and_sky(Some(sun), None));
    let out = render(&scene, &common::settings(IntegratorKind::Path, 64, 7));
    assert_uniform("sphere sun", &out, l);
}

#[test]
fn inside_a_sphere_light_the_cloud_is_a_furnace_too() {
    // A ball of radiance L around the cloud and the camera lights every
    // point inside it with L from every direction: the furnace again,
    // through the ball's sampling from inside and the rays that leave it
    // (camera rays see its inside too).
    let (l, r) = (0.6f32, 40.0f32);
    let medium = common::medium(common::cloud_field(4), 8.0, 1.0, 0.3);
    let ball =
        SphereLight::new(Vec3::splat(0.5), r, Vec3::splat(l * PI * r * r)).seen_by_camera(true);
    let scene = common::scene(medium, 16, Lights::new([ball.into()]));
    for sampling in [DistanceSampling::FreeFlight, DistanceSampling::Equiangular] {
        let mut settings = common::settings(IntegratorKind::Path, 64, 9);
        settings.distance_sampling = sampling;
        let out = render(&scene, &settings);
        assert!(out.stats.counters.nee_rays_sphere > 1000);
        let equiangular = out.stats.counters.equiangular_samples > 0;
        assert_eq!(equiangular, sampling == DistanceSampling::Equiangular);
        assert_uniform(&format!("inside a ball, {}", sampling.name()), &out, l);
    }
}

/// Every pixel of `out` is `l` in green, within 5 of its standard errors
/// (and f32 rounding), and pooled over the image within 4.
fn assert_uniform(label: &str, out: &Rendered, l: f32) {
    let img = &out.image;
    let (mut diff_sum, mut var_sum) = (0f64, 0f64);
    for y in 0..img.height {
        for x in 0..img.width {
            let (px, se) = (img.pixel(x, y), img.std_error(x, y));
            // Same per-pixel and pooled bounds as the furnace's above.
            assert!(
                (px[1] - l).abs() <= 5.0 * se[1] + 1e-5 * l,
                "{label}: pixel ({x}, {y}) = {}",
                px[1]
            );
            diff_sum += (px[1] - l) as f64;
            var_sum += (se[1] as f64).powi(2);
        }
    }
    let pooled = diff_sum / var_sum.sqrt();
    eprintln!("{label}: pooled z {pooled:.3}");
    assert!(pooled.abs() <= 4.0, "{label}: pooled z {pooled}");
}
