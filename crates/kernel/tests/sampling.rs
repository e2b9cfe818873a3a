//! The random number generator and the Henyey-Greenstein phase function
//! (`Phase::hg`; the other phase functions are in `phase_functions.rs`).

use cirrus_kernel::light::Sun;
use cirrus_kernel::Phase;
use cirrus_kernel::Rng;
use glam::Vec3;

fn draws(seed: u64, stream: u64, sample: u64, n: usize) -> Vec<u64> {
    let mut rng = Rng::new(seed, stream, sample);
    (0..n).map(|_| rng.next_u64()).collect()
}

#[test]
fn rng_is_a_pure_function_of_its_key() {
    let a = draws(7, 3, 5, 100);
    assert_eq!(a, draws(7, 3, 5, 100), "same key, same stream");
    // Changing any part of the key changes every draw: a coincidence has
    // probability 100 * 2^-64 per comparison.
    for other in [
        draws(7, 3, 6, 100),
        draws(7, 4, 5, 100),
        draws(8, 3, 5, 100),
    ] {
        assert!(a.iter().zip(&other).all(|(x, y)| x != y));
    }
}

#[test]
fn rng_uniform_is_in_range_with_mean_one_half() {
    let n = 200_000;
    let mut rng = Rng::new(1, 2, 3);
    let mut sum = 0f64;
    for _ in 0..n {
        let u = rng.uniform();
        assert!((0.0..1.0).contains(&u));
        sum += u as f64;
    }
    // Var(U) = 1/12; 5 standard errors.
    let se = (1.0 / 12.0 / n as f64).sqrt();
    assert!((sum / n as f64 - 0.5).abs() <= 5.0 * se);
}

const GS: [f32; 6] = [-0.7, 0.0, 0.3, 0.6, 0.85, 0.99];

#[test]
fn hg_sampled_mean_cosine_is_g() {
    let n = 100_000;
    let dir_in = Vec3::new(0.3, -0.5, 0.8).normalize();
    for g in GS {
        let hg = Phase::hg(g);
        let mut rng = Rng::new(11, g.to_bits() as u64, 0);
        let (mut sum, mut sum2) = (0f64, 0f64);
        for _ in 0..n {
            let (dir, pdf) = hg.sample(dir_in, rng.uniform(), rng.uniform());
            assert!(dir.is_finite() && pdf.is_finite() && pdf > 0.0);
            assert!((dir.length() - 1.0).abs() < 1e-5);
            let mu = dir.dot(dir_in) as f64;
            sum += mu;
            sum2 += mu * mu;
        }
        let mean = sum / n as f64;
        let var = (sum2 / n as f64 - mean * mean).max(0.0);
        // 5 standard errors of the sample mean (Var(mu) <= 1).
        let bound = 5.0 * (var / n as f64).sqrt();
        assert!(
            (mean - g as f64).abs() <= bound,
            "g = {g}: mean cosine {mean}, bound {bound}"
        );
    }
}

#[test]
fn hg_pdf_integrates_to_one() {
    // Integral over the sphere = 2 pi * integral of p(mu) over [-1, 1].
    // Trapezoid rule in x = 1 - mu on a geometric grid from 1e-9 to 2, so
    // the forward peak (width ~ (1 - g)^2 / 2g, 5e-5 at g = 0.99) is
    // resolved: relative spacing 2e-4 gives a relative error near
    // (2e-4)^2 / 12; the skipped sliver [0, 1e-9] holds at most
    // 2 pi p_max 1e-9 < 1e-5; f32 evaluation adds ~1e-6. Tolerance 1e-4.
    for g in GS {
        let hg = Phase::hg(g);
        let steps = 100_000;
        let (lo, hi) = (1e-9f64, 2.0f64);
        let r = (hi / lo).powf(1.0 / steps as f64);
        let f = |x: f64| 2.0 * std::f64::consts::PI * hg.eval_cos((1.0 - x) as f32) as f64;
        let mut total = 0.0;
        let mut x0 = lo;
        for _ in 0..steps {
            let x1 = x0 * r;
            total += 0.5 * (f(x0) + f(x1)) * (x1 - x0);
            x0 = x1;
        }
        assert!((total - 1.0).abs() < 1e-4, "g = {g}: integral {total}");
    }
}

#[test]
fn hg_is_robust_at_the_extremes() {
    for g in [1.0, -1.0, f32::NAN, 1e-4, -1e-4] {
        let hg = Phase::hg(g);
        assert!(hg.mean_cosine().abs() < 1.0);
        for mu in [-1.0, -0.5, 0.0, 0.999, 1.0] {
            let p = hg.eval_cos(mu);
            assert!(p.is_finite() && p > 0.0, "g = {g}, mu = {mu}: {p}");
        }
        for u in [0.0, 0.5, 0.999_999_94] {
            let mu = hg.sample_cos(u);
            assert!((-1.0..=1.0).contains(&mu));
        }
    }
    // Tiny g is snapped to isotropic so sample and eval agree exactly.
    let hg = Phase::hg(1e-4);
    assert_eq!(hg.eval_cos(0.3), 1.0 / (4.0 * std::f32::consts::PI));
}

#[test]
fn sun_disc_samples_hit_the_disc() {
    let sun = Sun::new(Vec3::new(0.2, -1.0, 0.1), Vec3::ONE, 0.53f32.to_radians());
    assert!(!sun.is_delta());
    let mut rng = Rng::new(3, 0, 0);
    for _ in 0..10_000 {
        let s = sun.sample(rng.uniform(), rng.uniform());
        let (radiance, pdf) = sun.hit(s.to_light).expect("inside the disc");
        assert_eq!(Some(pdf), s.pdf);
        assert_eq!(radiance, s.radiance);
    }
    // Radiance times solid angle returns the irradiance.
    let (radiance, pdf) = sun.hit(-sun.direction()).unwrap();
    assert!(((radiance.x / pdf) - 1.0).abs() < 1e-6);
    assert!(sun.hit(Vec3::Y).is_none());
    let delta = Sun::new(Vec3::NEG_Y, Vec3::ONE, 0.0);
    assert!(delta.is_delta() && delta.hit(Vec3::Y).is_none());
}
