//! Free-flight sampling and the transmittance estimators against closed
//! forms and quadrature.

use cirrus_kernel::tracking::{
    ratio_tracking, residual_ratio_tracking, sample_free_flight, sample_free_flight_pair,
    track_length_transmittance, transmittance, FreeFlight, TransmittanceEstimator,
};
use cirrus_kernel::Bounds3;
use cirrus_kernel::{ConstantBox, Counters, DensityField, GlobalMedia, Media, Medium, Volumes};
use cirrus_kernel::{GridField, Ray, Rng};
use glam::Vec3;

const ESTIMATORS: [TransmittanceEstimator; 3] = [
    TransmittanceEstimator::Ratio,
    TransmittanceEstimator::Residual,
    TransmittanceEstimator::TrackLength,
];

/// Mean and standard error of `n` calls of `f(rng)`, each with its own
/// counter-based stream.
fn estimate(n: u32, seed: u64, mut f: impl FnMut(&mut Rng) -> f32) -> (f64, f64) {
    let (mut sum, mut sum2) = (0f64, 0f64);
    for i in 0..n {
        let x = f(&mut Rng::new(seed, i as u64, 0)) as f64;
        sum += x;
        sum2 += x * x;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0) * n as f64 / (n - 1) as f64;
    (mean, (var / n as f64).sqrt())
}

fn unit_box(density: f32) -> ConstantBox {
    ConstantBox::new(Vec3::splat(-0.5), Vec3::splat(0.5), density, 0.05)
}

/// A ray crossing the box along x: chord length 1.
fn chord_ray() -> Ray {
    Ray::new(Vec3::new(-1.0, 0.1, 0.2), Vec3::X)
}

#[test]
fn estimators_match_exp_on_a_constant_box() {
    // Optical depths from thin to thick; RR kicks in for the last.
    for sigma in [0.2f32, 1.0, 2.5, 6.0] {
        let medium = Volumes::from(Medium::new(unit_box(1.0), sigma, Vec3::ONE, 0.0));
        let exact = (-sigma as f64).exp();
        for est in ESTIMATORS {
            let mut c = Counters::default();
            let (mean, se) = estimate(20_000, 1, |rng| {
                transmittance::<f32, _>(est, &medium, &chord_ray(), f32::INFINITY, rng, &mut c)
            });
            // 5 standard errors; with se = 0 (an exact estimator) only f32
            // rounding of exp is allowed.
            let bound = 5.0 * se + 1e-6;
            assert!(
                (mean - exact).abs() <= bound,
                "{est:?}, sigma {sigma}: {mean} vs {exact} (bound {bound})"
            );
            assert_eq!(c.shadow_rays, 20_000);
            assert_eq!(c.collision_cap_hits + c.majorant_violations, 0);
        }
    }
}

#[test]
fn residual_tracking_is_exact_where_the_majorant_is_tight() {
    // Constant segment: sigma_maj == sigma_c, no collisions, every estimate
    // is exp(-sigma d) itself (up to f32 rounding).
    let medium = Volumes::from(Medium::new(unit_box(1.0), 1.7, Vec3::ONE, 0.0));
    let mut c = Counters::default();
    for i in 0..100 {
        let mut rng = Rng::new(2, i, 0);
        let t = residual_ratio_tracking(&medium, &chord_ray(), f32::INFINITY, &mut rng, &mut c);
        assert!((t - (-1.7f32).exp()).abs() <= 1e-6);
    }
    assert_eq!(c.density_lookups, 0);
}

#[test]
fn t_max_limits_the_estimate() {
    // Stopping at t = 1.25 leaves a chord of 0.75 inside the box.
    let medium = Volumes::from(Medium::new(unit_box(1.0), 2.0, Vec3::ONE, 0.0));
    let exact = (-2.0f64 * 0.75).exp();
    for est in ESTIMATORS {
        let mut c = Counters::default();
        let (mean, se) = estimate(20_000, 3, |rng| {
            transmittance::<f32, _>(est, &medium, &chord_ray(), 1.25, rng, &mut c)
        });
        assert!(
            (mean - exact).abs() <= 5.0 * se + 1e-6,
            "{est:?}: {mean} vs {exact}"
        );
    }
}

/// Transmittance by midpoint quadrature in f64 over the ray's overlap
/// with the field; 20 000 steps over at most ~2 units of a field with
/// 1/16-unit voxels: the error is far below the Monte Carlo tolerance.
fn quadrature_transmittance<M: Media>(medium: &M, ray: &Ray) -> f64 {
    let Bounds3 { min: lo, max: hi } = medium.bounds();
    let Some((t0, t1)) = Bounds3::new(lo, hi).clip_ray(ray.origin, ray.dir, 0.0, f32::INFINITY)
    else {
        return 1.0;
    };
    let n = 20_000;
    let h = (t1 - t0) as f64 / n as f64;
    let tau: f64 = (0..n)
        .map(|i| {
            let p = ray.at((t0 as f64 + (i as f64 + 0.5) * h) as f32);
            medium.extinction::<f32>(p, 0.0) as f64 * h
        })
        .sum();
    (-tau).exp()
}

#[test]
fn estimators_match_quadrature_on_a_grid_field_with_both_majorant_modes() {
    let field = GridField::cloud(4, Vec3::ZERO);
    let Bounds3 { min: lo, max: hi } = field.bounds();
    let centre = 0.5 * (lo + hi);
    let medium = Volumes::from(Medium::new(field, 6.0, Vec3::ONE, 0.0));
    let global = GlobalMedia::new(&medium);
    let rays = [
        Ray::new(
            centre - Vec3::new(2.0, 0.3, 0.1),
            Vec3::new(1.0, 0.15, 0.05).normalize(),
        ),
        Ray::new(centre, Vec3::new(-0.3, 1.0, 0.4).normalize()),
        Ray::new(centre + Vec3::new(0.1, -0.2, 0.0), Vec3::Z),
    ];
    for (r, ray) in rays.iter().enumerate() {
        let exact = quadrature_transmittance(&medium, ray);
        assert!(
            exact > 0.01 && exact < 0.9,
            "ray {r}: pick a ray with a useful T ({exact})"
        );
        for est in ESTIMATORS {
            let mut c = Counters::default();
            let (m_local, se_local) = estimate(20_000, 10 + r as u64, |rng| {
                transmittance::<f32, _>(est, &medium, ray, f32::INFINITY, rng, &mut c)
            });
            let (m_global, se_global) = estimate(20_000, 20 + r as u64, |rng| {
                transmittance::<f32, _>(est, &global, ray, f32::INFINITY, rng, &mut c)
            });
            for (mode, m, se) in [
                ("local", m_local, se_local),
                ("global", m_global, se_global),
            ] {
                assert!(
                    (m - exact).abs() <= 5.0 * se + 1e-5,
                    "ray {r} {est:?} {mode}: {m} vs {exact} (se {se})"
                );
            }
            assert_eq!(c.majorant_violations, 0, "{est:?}");
        }
    }
}

#[test]
fn delta_tracking_samples_exponential_flights() {
    // Homogeneous box: the flight from the entry is exponential with rate
    // sigma, truncated at the chord d = 1, so P(escape) = exp(-sigma) and
    // E[min(s, d)] = (1 - exp(-sigma d)) / sigma.
    let sigma = 1.3f32;
    let medium = Volumes::from(Medium::new(unit_box(1.0), sigma, Vec3::ONE, 0.0));
    let mut c = Counters::default();
    let flight = |rng: &mut Rng, c: &mut Counters| {
        let mut beta = Vec3::ONE;
        sample_free_flight::<f32, _>(&medium, &chord_ray(), f32::INFINITY, &mut beta, rng, c)
    };
    let (escape, se_e) = estimate(40_000, 4, |rng| {
        (flight(rng, &mut c) == FreeFlight::Escaped) as u8 as f32
    });
    let (dist, se_d) = estimate(40_000, 5, |rng| match flight(rng, &mut c) {
        FreeFlight::Collision { t } => t - 0.5,
        _ => 1.0,
    });
    let e = (-sigma as f64).exp();
    assert!((escape - e).abs() <= 5.0 * se_e, "escape {escape} vs {e}");
    let d = (1.0 - e) / sigma as f64;
    assert!((dist - d).abs() <= 5.0 * se_d, "mean flight {dist} vs {d}");
    // A constant box's minorant equals its majorant: every collision is
    // accepted without a lookup.
    assert_eq!(c.density_lookups, 0);
    assert!(c.real_collisions > 0 && c.null_collisions == 0);
}

#[test]
fn track_length_and_ratio_agree_through_the_public_functions() {
    let medium = Volumes::from(Medium::new(unit_box(1.0), 0.8, Vec3::ONE, 0.0));
    let mut c = Counters::default();
    let (a, se_a) = estimate(20_000, 6, |rng| {
        ratio_tracking::<f32, _>(&GlobalMedia::new(&medium), &chord_ray(), 9.0, rng, &mut c)
    });
    let (b, se_b) = estimate(20_000, 7, |rng| {
        track_length_transmittance::<f32, _>(&medium, &chord_ray(), 9.0, rng, &mut c)
    });
    assert!((a - b).abs() <= 5.0 * (se_a * se_a + se_b * se_b).sqrt());
}

/// `integral of sigma_t(t) T(t) f(t) dt` over the ray's overlap with the
/// field, by midpoint quadrature in f64: the expectation of `f` at a free
/// flight's collision.
fn quadrature_collision_mean<M: Media>(medium: &M, ray: &Ray, f: impl Fn(f32) -> f64) -> f64 {
    let Bounds3 { min: lo, max: hi } = medium.bounds();
    let (t0, t1) = Bounds3::new(lo, hi)
        .clip_ray(ray.origin, ray.dir, 0.0, f32::INFINITY)
        .expect("the ray crosses the field");
    let n = 20_000;
    let h = (t1 - t0) as f64 / n as f64;
    let (mut tau, mut sum) = (0f64, 0f64);
    for i in 0..n {
        let t = (t0 as f64 + (i as f64 + 0.5) * h) as f32;
        let sigma = medium.extinction::<f32>(ray.at(t), 0.0) as f64;
        // Transmittance to the step's midpoint.
        let mid = tau + 0.5 * sigma * h;
        sum += sigma * (-mid).exp() * f(t) * h;
        tau += sigma * h;
    }
    sum
}

#[test]
fn delta_tracked_flights_collide_with_density_sigma_t_times_transmittance() {
    // Through a heterogeneous field under its global majorant (null
    // collisions at most tentative points): the escape frequency is the
    // transmittance, and the mean collision point that of the density
    // `sigma_t T` along the ray.
    let field = GridField::cloud(4, Vec3::ZERO);
    let Bounds3 { min: lo, max: hi } = field.bounds();
    let centre = 0.5 * (lo + hi);
    let medium = Volumes::from(Medium::new(field, 6.0, Vec3::ONE, 0.0));
    let global = GlobalMedia::new(&medium);
    let ray = Ray::new(
        centre - Vec3::new(2.0, 0.3, 0.1),
        Vec3::new(1.0, 0.15, 0.05).normalize(),
    );
    let exact_t = quadrature_transmittance(&medium, &ray);
    let exact_at = quadrature_collision_mean(&medium, &ray, |t| t as f64);
    let mut c = Counters::default();
    let mut flight = |rng: &mut Rng| {
        let mut beta = Vec3::ONE;
        sample_free_flight::<f32, _>(&global, &ray, f32::INFINITY, &mut beta, rng, &mut c)
    };
    let (escape, se_e) = estimate(40_000, 30, |rng| match flight(rng) {
        FreeFlight::Escaped => 1.0,
        _ => 0.0,
    });
    let (at, se_at) = estimate(40_000, 31, |rng| match flight(rng) {
        FreeFlight::Collision { t } => t,
        _ => 0.0,
    });
    assert!(
        (escape - exact_t).abs() <= 5.0 * se_e,
        "escape {escape} vs T {exact_t} (se {se_e})"
    );
    assert!(
        (at - exact_at).abs() <= 5.0 * se_at,
        "collision mean {at} vs {exact_at} (se {se_at})"
    );
    // The collision point's mean differs from the unweighted ray's
    // midpoint in the field: the test can tell a uniform distance.
    let (t0, t1) = Bounds3::new(lo, hi)
        .clip_ray(ray.origin, ray.dir, 0.0, f32::INFINITY)
        .unwrap();
    let uniform = f64::from(0.5 * (t0 + t1)) * (1.0 - exact_t);
    assert!(
        (uniform - exact_at).abs() > 5.0 * se_at,
        "{uniform} vs {exact_at}"
    );
    assert!(c.null_collisions > c.real_collisions / 4, "{c:?}");
}

/// Paired flights against the same flights one at a time, for
/// spectrum `S`: every flight's end, weight and generator state, and the
/// counters, are the same bit for bit.
fn pairs_match_single_flights<S: cirrus_kernel::Spectrum, M: Media>(medium: &M, centre: Vec3) {
    let ray = |i: u64| {
        let a = i as f32 * 0.7;
        let dir = Vec3::new(a.cos(), 0.3 * (1.3 * a).sin(), a.sin()).normalize();
        Ray::new(
            centre - 2.0 * dir + Vec3::new(0.0, 0.05 * (i % 7) as f32, 0.0),
            dir,
        )
    };
    let (mut single, mut paired) = (Counters::default(), Counters::default());
    let mut ends = [0u32; 2];
    for i in (0..2_000u64).step_by(2) {
        let (r0, r1) = (ray(i), ray(i + 1));
        let t_max = [f32::INFINITY, if i % 6 == 0 { 1.5 } else { f32::INFINITY }];
        let mut alone = [Rng::new(4, i, 0), Rng::new(4, i + 1, 0)];
        let mut beta_alone = [Vec3::ONE; 2];
        let [ga, gb] = &mut alone;
        let [ba, bb] = &mut beta_alone;
        let expected = [
            sample_free_flight::<S, _>(medium, &r0, t_max[0], ba, ga, &mut single),
            sample_free_flight::<S, _>(medium, &r1, t_max[1], bb, gb, &mut single),
        ];
        let mut both = [Rng::new(4, i, 0), Rng::new(4, i + 1, 0)];
        let mut beta_both = [Vec3::ONE; 2];
        let [ga, gb] = &mut both;
        let [ba, bb] = &mut beta_both;
        let got = sample_free_flight_pair::<S, _>(
            medium,
            [&r0, &r1],
            t_max,
            [ba, bb],
            [ga, gb],
            &mut paired,
        );
        assert_eq!(got, expected, "pair {i}");
        assert_eq!(beta_both, beta_alone, "pair {i}");
        for k in 0..2 {
            assert_eq!(
                both[k].uniform().to_bits(),
                alone[k].uniform().to_bits(),
                "pair {i}"
            );
            ends[usize::from(matches!(got[k], FreeFlight::Escaped))] += 1;
        }
    }
    assert_eq!(paired, single);
    // Both kinds of ending occur, so the test can tell an early stop.
    assert!(
        ends[0] > 200 && ends[1] > 200,
        "collisions and escapes: {ends:?}"
    );
}

#[test]
fn paired_flights_end_where_single_flights_do() {
    let field = GridField::cloud(4, Vec3::ZERO);
    let Bounds3 { min: lo, max: hi } = field.bounds();
    let centre = 0.5 * (lo + hi);
    let grey = Volumes::from(Medium::new(field.clone(), 6.0, Vec3::ONE, 0.0));
    pairs_match_single_flights::<f32, _>(&grey, centre);
    let tinted = Volumes::from(
        Medium::new(field, 6.0, Vec3::ONE, 0.0).with_extinction_tint(Vec3::new(0.5, 1.0, 1.5)),
    );
    pairs_match_single_flights::<Vec3, _>(&tinted, centre);
}
