//! A purely absorbing constant box in a constant environment: every
//! pixel is the environment attenuated by `exp(-sigma_t d)` along its chord.

mod common;

use cirrus_render::Bounds3;
use cirrus_render::{render, Camera, ConstantBox, IntegratorKind, Lights, Medium, Scene, Volumes};
use glam::Vec3;

/// Average of `exp(-sigma d(x))` over the pixel's footprint by an m x m
/// midpoint rule (the renderer jitters uniformly over the pixel).
fn footprint_transmittance(
    cam: &Camera,
    b: &ConstantBox,
    sigma: f32,
    x: u32,
    y: u32,
    m: u32,
) -> f64 {
    let mut sum = 0f64;
    for j in 0..m {
        for i in 0..m {
            let r = cam.ray(
                x as f32 + (i as f32 + 0.5) / m as f32,
                y as f32 + (j as f32 + 0.5) / m as f32,
            );
            let d = Bounds3::new(b.lo, b.hi)
                .clip_ray(r.origin, r.dir, 0.0, f32::INFINITY)
                .map_or(0.0, |(t0, t1)| t1 - t0);
            sum += (-(sigma as f64) * d as f64).exp();
        }
    }
    sum / (m * m) as f64
}

#[test]
fn absorbing_box_matches_beer_lambert() {
    let b = ConstantBox::new(
        Vec3::new(-0.5, -0.4, -0.6),
        Vec3::new(0.5, 0.4, 0.6),
        1.0,
        0.05,
    );
    let sigma = 1.2;
    let l_env = Vec3::new(1.0, 0.8, 0.5);
    let size = 24;
    let spp = 256;
    let camera = Camera::new(
        Vec3::new(1.8, 1.2, 2.6),
        Vec3::ZERO,
        Vec3::Y,
        32.0,
        size,
        size,
    );
    let scene = Scene {
        media: Volumes::from(Medium::new(b, sigma, Vec3::ZERO, 0.3)),
        camera,
        lights: Lights::sun_and_sky(None, common::env(l_env)),
    };
    let out = render(&scene, &common::settings(IntegratorKind::Path, spp, 17));
    assert_eq!(out.stats.spp, spp);
    assert_eq!(out.stats.counters.nonfinite_samples, 0);

    // Pixels whose four corners all hit the box lie entirely inside its
    // (convex) silhouette, so T varies continuously over their footprint
    // and the midpoint rule converges; the others are skipped.
    let hits = |x: f32, y: f32| {
        let r = camera.ray(x, y);
        Bounds3::new(b.lo, b.hi)
            .clip_ray(r.origin, r.dir, 0.0, f32::INFINITY)
            .is_some_and(|(a, c)| c > a)
    };
    let mut tested = 0;
    let mut z_sum = 0f64;
    for y in 0..size {
        for x in 0..size {
            let (fx, fy) = (x as f32, y as f32);
            if !(hits(fx, fy)
                && hits(fx + 1.0, fy)
                && hits(fx, fy + 1.0)
                && hits(fx + 1.0, fy + 1.0))
            {
                continue;
            }
            // Expected value with a quadrature error estimate: the m = 16
            // and m = 32 rules differ by about 4/3 of the m = 32 error.
            let t_fine = footprint_transmittance(&camera, &b, sigma, x, y, 32);
            let quad_err = (footprint_transmittance(&camera, &b, sigma, x, y, 16) - t_fine).abs();
            let px = out.image.pixel(x, y);
            // Each sample is L * Bernoulli(T) (the camera ray escapes or
            // not), so the standard error is known exactly:
            // L sqrt(T (1 - T) / n). 5 of them per pixel: Gaussian
            // false-failure rate 5.7e-7 per value, < 1e-3 over the ~300
            // pixels x 4 values here.
            let se_unit = (t_fine * (1.0 - t_fine) / spp as f64).sqrt();
            for c in 0..3 {
                let expected = l_env[c] as f64 * t_fine;
                let bound = 5.0 * l_env[c] as f64 * se_unit + l_env[c] as f64 * quad_err + 1e-6;
                let got = px[c] as f64;
                assert!(
                    (got - expected).abs() <= bound,
                    "pixel ({x}, {y}) channel {c}: {got} vs {expected} (bound {bound})"
                );
            }
            // Alpha = 1 - Bernoulli(T): same standard error.
            let alpha_expected = 1.0 - t_fine;
            assert!(
                (px[3] as f64 - alpha_expected).abs() <= 5.0 * se_unit + quad_err + 1e-6,
                "alpha at ({x}, {y})"
            );
            z_sum += (px[1] as f64 - l_env[1] as f64 * t_fine) / (l_env[1] as f64 * se_unit);
            tested += 1;
        }
    }
    eprintln!(
        "{tested} pixels tested, pooled z {:.3}",
        z_sum / (tested as f64).sqrt()
    );
    assert!(tested >= 150, "only {tested} pixels inside the silhouette");
    // Pooled over the image (green channel): sum z / sqrt(N) is N(0, 1).
    let pooled = z_sum / (tested as f64).sqrt();
    assert!(pooled.abs() <= 4.0, "pooled z {pooled}");
    // Corner pixels miss the box: exactly the environment, alpha 0.
    assert_eq!(out.image.pixel(0, 0), [l_env.x, l_env.y, l_env.z, 0.0]);
}
