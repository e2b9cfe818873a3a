//! Emission against its closed form: a constant, purely absorbing box that
//! emits `Le` shows `Le (1 - exp(-sigma d))` along a chord of length `d`
//! (the RTE's source term `sigma_a Le` integrated through the box), for an
//! emission grid and for a blackbody temperature grid.

mod common;

use cirrus_kernel::blackbody::blackbody_rgb;
use cirrus_render::Bounds3;
use cirrus_render::{
    Blackbody, Camera, ConstantBox, Emission, IntegratorKind, Lights, Medium, Volumes,
};
use glam::Vec3;

fn unit_box(value: f32) -> ConstantBox {
    ConstantBox::new(
        Vec3::new(-0.5, -0.4, -0.6),
        Vec3::new(0.5, 0.4, 0.6),
        value,
        0.05,
    )
}

/// Mean of `1 - exp(-sigma d)` over the pixel by an m x m midpoint rule.
fn footprint_opacity(cam: &Camera, b: &ConstantBox, sigma: f32, x: u32, y: u32, m: u32) -> f64 {
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
            sum += 1.0 - (-(sigma as f64) * d as f64).exp();
        }
    }
    sum / (m * m) as f64
}

fn check(label: &str, emission: Emission<ConstantBox>, le: Vec3) {
    let sigma = 1.5;
    let volumes =
        Volumes::from(Medium::new(unit_box(1.0), sigma, Vec3::ZERO, 0.0).with_emission(emission));
    let size = 20;
    let spp = 256;
    let camera = Camera::new(
        Vec3::new(1.8, 1.2, 2.6),
        Vec3::ZERO,
        Vec3::Y,
        32.0,
        size,
        size,
    );
    let mut settings = common::settings(IntegratorKind::Path, spp, 11);
    settings.aovs = true;
    let out = common::render_through(&volumes, &camera, &Lights::default(), &settings);
    assert!(out.stats.counters.emission_lookups > 0, "{label}");
    // All the light is emitted: the emission AOV is the beauty, exactly;
    // nothing is scattered; albedo 0; every pixel took every sample; and
    // a pixel's depth (mean sampled first-collision distance) lies on its
    // rays' chords through the box.
    let aovs = out.aovs.as_ref().expect("AOVs kept");
    for (i, px) in out.image.rgba.iter().enumerate() {
        assert_eq!(
            aovs.emission[i],
            [px[0], px[1], px[2]],
            "{label}: pixel {i}"
        );
        assert_eq!(aovs.direct[i], [0.0; 3]);
        assert_eq!(aovs.albedo[i], [0.0; 3]);
        assert_eq!(aovs.samples[i], spp as f32);
        let d = aovs.depth[i];
        assert!(
            d == cirrus_render::compositing::deep::NO_DEPTH || (2.0..=4.5).contains(&d),
            "{label}: depth {d} at pixel {i}"
        );
    }
    assert_eq!(
        out.stats.counters.shadow_rays, 0,
        "{label}: no lights, no NEE"
    );
    let b = unit_box(1.0);
    let (mut z_sum, mut tested) = (0f64, 0usize);
    for y in 0..size {
        for x in 0..size {
            // Each sample is Le * Bernoulli(p), p the opacity: standard
            // error Le sqrt(p (1 - p) / n), known exactly. 5 of them plus
            // the quadrature error (m = 16 vs 32); the silhouette's edge
            // pixels, where p is discontinuous, get the quadrature slack.
            let p = footprint_opacity(&camera, &b, sigma, x, y, 32);
            let quad = (footprint_opacity(&camera, &b, sigma, x, y, 16) - p).abs();
            let se = (p * (1.0 - p) / spp as f64).sqrt();
            let px = out.image.pixel(x, y);
            for c in 0..3 {
                let expected = le[c] as f64 * p;
                let bound = le[c] as f64 * (5.0 * se + 4.0 * quad) + 1e-6;
                assert!(
                    (px[c] as f64 - expected).abs() <= bound,
                    "{label}: ({x}, {y}) channel {c}: {} vs {expected} (bound {bound})",
                    px[c]
                );
            }
            if se > 0.0 && quad < 1e-3 {
                z_sum += (px[1] as f64 - le[1] as f64 * p) / (le[1] as f64 * se);
                tested += 1;
            }
        }
    }
    let pooled = z_sum / (tested as f64).sqrt();
    eprintln!("{label}: {tested} pixels, pooled z {pooled:.3}");
    assert!(tested > 100, "{label}: {tested}");
    assert!(pooled.abs() <= 4.0, "{label}: pooled z {pooled}");
}

#[test]
fn an_emission_grid_glows_as_the_closed_form() {
    let colour = Vec3::new(2.0, 1.0, 0.5);
    check(
        "emission grid",
        Emission {
            temperature: None,
            grid: Some((unit_box(1.0), colour)),
        },
        colour,
    );
}

#[test]
fn a_temperature_grid_glows_as_the_blackbody() {
    let bb = Blackbody {
        scale: 20.0,
        offset: 100.0,
        temperature_scale: 2.0,
    };
    // Grid value 850 -> (850 - 100) * 2 = 1500 K.
    let le = 20.0 * blackbody_rgb(1500.0);
    assert!(le.x > le.y && le.y > le.z && le.z >= 0.0);
    check(
        "blackbody",
        Emission {
            temperature: Some((unit_box(850.0), bb)),
            grid: None,
        },
        le,
    );
}
