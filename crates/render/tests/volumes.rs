//! Several volume instances: overlapping copies add, one instance walks
//! its own segments (no BVH, no merge), and empty space costs nothing.

mod common;

use cirrus_kernel::medium::Scaled;
use cirrus_kernel::{Ray, Rng};
use cirrus_render::{
    render, ConstantBox, DensityField, IntegratorKind, Lights, Media, Medium,
    TransmittanceEstimator, Volumes,
};
use glam::Vec3;

fn lights() -> Lights {
    Lights::sun_and_sky(common::sun(0.53), common::env(Vec3::new(0.3, 0.4, 0.6)))
}

/// Two half-density copies with different albedos (and majorant grids with
/// different cells, so their segment boundaries interleave) are one copy
/// at full density with the mean albedo: extinction adds, and choosing
/// the scattering instance with probability `sigma_t,i / sigma_t` makes
/// `sigma_s = 0.5 sigma (a1 + a2)`.
#[test]
fn two_half_density_copies_render_as_one_full_copy() {
    let (scale, g) = (8.0, 0.4);
    let (a1, a2) = (0.95, 0.55);
    let one = common::medium(common::cloud_field(4), scale, 0.5 * (a1 + a2), g);
    let scene = common::scene(one, 16, lights());
    for (i, estimator) in [
        TransmittanceEstimator::Ratio,
        TransmittanceEstimator::Residual,
    ]
    .into_iter()
    .enumerate()
    {
        let mut settings = common::settings(IntegratorKind::Path, 64, 31 + i as u64);
        settings.transmittance = estimator;
        let single = render(&scene, &settings);

        let copies = Volumes::new(vec![
            Medium::new(common::cloud_field(4), 0.5 * scale, Vec3::splat(a1), g),
            Medium::new(common::cloud_field(3), 0.5 * scale, Vec3::splat(a2), g),
        ]);
        settings.seed += 1000;
        let double = common::render_through(&copies, &scene.camera, &scene.lights, &settings);
        for out in [&single, &double] {
            assert_eq!(
                out.stats.counters.nonfinite_samples + out.stats.counters.collision_cap_hits,
                0
            );
            assert_eq!(
                out.stats.counters.majorant_violations, 0,
                "merged majorants bound"
            );
        }
        let label = format!("two copies vs one ({estimator:?})");
        common::assert_pooled_agreement(
            &label,
            &common::differences(&single.image, &double.image, 1),
        );
        // Per pixel: 5 combined standard errors (Gaussian false-failure
        // rate 5.7e-7 per pixel, ~1.5e-4 over 256 pixels), plus f32
        // rounding of the means.
        for y in 0..16 {
            for x in 0..16 {
                let (a, b) = (single.image.pixel(x, y)[1], double.image.pixel(x, y)[1]);
                let (sa, sb) = (
                    single.image.std_error(x, y)[1],
                    double.image.std_error(x, y)[1],
                );
                let bound = 5.0 * (sa * sa + sb * sb).sqrt() + 1e-5 * a.abs().max(b.abs());
                assert!((a - b).abs() <= bound, "{label}: ({x}, {y}) {a} vs {b}");
            }
        }
    }
}

/// One instance takes the fast path, no BVH and no merge: along any ray
/// its segments are its field's own, scaled, bit for bit, and so is its
/// extinction.
#[test]
fn one_instance_walks_its_own_segments() {
    let volumes = Volumes::from(Medium::new(
        common::cloud_field(4),
        6.0,
        Vec3::splat(0.9),
        0.5,
    ));
    let field = common::cloud_field(4);
    let mut rng = Rng::new(9, 0, 0);
    let mut segments = 0;
    for _ in 0..200 {
        let o = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        let d = cirrus_kernel::sampling::uniform_sphere(rng.uniform(), rng.uniform());
        let ours: Vec<_> = volumes.majorants(o, d, 0.0, f32::INFINITY).collect();
        let own: Vec<_> = Scaled::new(field.segments(o, d, 0.0, f32::INFINITY), 6.0).collect();
        assert_eq!(ours, own);
        segments += own.len();
        let p = Ray::new(o, d).at(0.2);
        assert_eq!(volumes.extinction::<f32>(p, 0.0), 6.0 * field.density(p));
    }
    assert!(segments > 200, "only {segments} segments");
}

/// Rays that miss every instance do no tracking: no segments, no lookups.
#[test]
fn rays_that_miss_every_volume_do_no_work() {
    let boxes = |x: f32| {
        Medium::new(
            ConstantBox::new(
                Vec3::new(x, -0.5, -0.5),
                Vec3::new(x + 1.0, 0.5, 0.5),
                1.0,
                0.1,
            ),
            2.0,
            Vec3::splat(0.8),
            0.0,
        )
    };
    let volumes = Volumes::new(vec![boxes(-3.0), boxes(2.0), boxes(5.0)]);
    // A camera looking up, away from all three boxes.
    let camera = cirrus_render::Camera::new(Vec3::ZERO, Vec3::Y, Vec3::Z, 30.0, 8, 8);
    let out = common::render_through(
        &volumes,
        &camera,
        &lights(),
        &common::settings(IntegratorKind::Path, 4, 1),
    );
    assert_eq!(out.stats.counters.paths, 256);
    assert_eq!(out.stats.counters.dda_segments, 0);
    assert_eq!(out.stats.counters.density_lookups, 0);
}
