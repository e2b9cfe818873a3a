//! Phase functions: every variant's sampling against its own density
//! (chi-square), normalisation, pdf consistency and reciprocity, mean
//! cosines, the Draine inversion at extreme parameters, the Mie fit's
//! numbers. Tables and constructor errors: `phase_tables.rs`; HG against
//! the implementation it replaced: `phase_hg_identity.rs`.

use std::f64::consts::PI;

use cirrus_kernel::phase::{MieFit, Phase};
use cirrus_kernel::Rng;
use glam::{DVec3, Vec3};

/// Samples per chi-square test (Mitsuba 3 tests its phase functions with
/// about 1e6; 2e5 keeps this file fast and still resolves the bins below).
const SAMPLES: usize = 200_000;
const PHI_BINS: usize = 8;

fn dir_in() -> Vec3 {
    Vec3::new(0.36, -0.48, 0.8).normalize()
}

/// A tabulated HG(0.6) on a grid dense toward the forward peak.
fn tabulated_hg() -> Phase {
    let hg = Phase::hg(0.6);
    let cos: Vec<f32> = (0..=400)
        .map(|i| 1.0 - 2.0 * (i as f32 / 400.0).powi(2))
        .rev()
        .collect();
    let values: Vec<f32> = cos.iter().map(|&m| hg.eval_cos(m)).collect();
    Phase::table(&cos, &values).unwrap()
}

/// A tabulated Rayleigh, unnormalised and by decreasing cosine.
fn tabulated_rayleigh() -> Phase {
    let cos: Vec<f32> = (0..=64).map(|i| 1.0 - i as f32 / 32.0).collect();
    let values: Vec<f32> = cos.iter().map(|&m| 5.0 * (1.0 + m * m)).collect();
    Phase::table(&cos, &values).unwrap()
}

fn variants() -> Vec<(String, Phase)> {
    let mut v: Vec<(String, Phase)> = [-0.5, 0.0, 0.3, 0.9]
        .iter()
        .map(|&g| (format!("hg({g})"), Phase::hg(g)))
        .collect();
    v.push((
        "hg2(0.8, -0.4, 0.7)".into(),
        Phase::hg2(0.8, -0.4, 0.7).unwrap(),
    ));
    v.push(("draine(0.5, 1)".into(), Phase::draine(0.5, 1.0).unwrap()));
    v.push((
        "draine(-0.7, 10)".into(),
        Phase::draine(-0.7, 10.0).unwrap(),
    ));
    for d in [5.0, 10.0, 20.0, 50.0] {
        v.push((format!("mie({d})"), Phase::mie(d).unwrap()));
    }
    v.push(("rayleigh".into(), Phase::rayleigh()));
    v.push(("table(hg 0.6)".into(), tabulated_hg()));
    v.push(("table(rayleigh)".into(), tabulated_rayleigh()));
    // Few, uneven knots: the quadratic within each segment is visible.
    let coarse = Phase::table(&[-1.0, -0.2, 0.5, 0.9, 1.0], &[0.3, 0.1, 1.0, 4.0, 2.0]);
    v.push(("table(5 knots)".into(), coarse.unwrap()));
    v
}

/// Bin edges in `mu`, increasing from -1 to 1: uniform steps of 0.1, plus
/// geometric steps in `1 - mu` from 1e-4 so forward peaks are resolved.
/// (Finer than 1e-4 the f32 sampler's quantisation of `mu`, 6e-8 near 1,
/// would itself show.)
fn mu_edges() -> Vec<f64> {
    let mut e: Vec<f64> = (0..=20).map(|i| -1.0 + 0.1 * i as f64).collect();
    let n = 40;
    for k in 0..n {
        e.push(1.0 - 1e-4 * (2e4f64).powf(k as f64 / n as f64));
    }
    e.sort_by(f64::total_cmp);
    e.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    e
}

/// `2 pi` times the integral of `f` over `mu` in `[a, b]`, by the
/// trapezoid rule in `x = 1 - mu` on a geometric grid (2000 steps), which
/// resolves forward peaks however narrow (HG at g = 0.998 is 2e-6 wide in
/// `x`); a bin reaching `mu = 1` starts the grid at `x = 1e-12`, the
/// sliver below taken at `f(1)`.
fn integrate(f: &impl Fn(f32) -> f32, a: f64, b: f64) -> f64 {
    let (x_lo, x_hi) = (1.0 - b, 1.0 - a);
    let start = x_lo.max(1e-12);
    let sliver = if x_lo < start {
        f(1.0) as f64 * (start - x_lo)
    } else {
        0.0
    };
    let steps = 2000;
    let r = (x_hi / start).powf(1.0 / steps as f64);
    let g = |x: f64| f((1.0 - x) as f32) as f64;
    let mut total = sliver;
    let mut x0 = start;
    for i in 0..steps {
        let x1 = if i + 1 == steps { x_hi } else { x0 * r };
        total += 0.5 * (g(x0) + g(x1)) * (x1 - x0);
        x0 = x1;
    }
    2.0 * PI * total
}

/// `ln Gamma(a)` for `a > 0`: Stirling's series after shifting `a` past 10.
fn ln_gamma(mut a: f64) -> f64 {
    let mut shift = 0.0;
    while a < 10.0 {
        shift -= a.ln();
        a += 1.0;
    }
    let inv = 1.0 / a;
    let inv2 = inv * inv;
    let series = inv * (1.0 / 12.0 - inv2 * (1.0 / 360.0 - inv2 * (1.0 / 1260.0 - inv2 / 1680.0)));
    shift + (a - 0.5) * a.ln() - a + 0.5 * (2.0 * PI).ln() + series
}

/// Upper tail of the chi-square distribution with `k` degrees of freedom:
/// the regularised gamma `Q(k / 2, x / 2)`, by its power series below
/// `a + 1` and Legendre's continued fraction (modified Lentz) above.
fn chi2_upper_tail(x: f64, k: usize) -> f64 {
    let (a, x) = (k as f64 / 2.0, x / 2.0);
    if x <= 0.0 {
        return 1.0;
    }
    let prefactor = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        while term.abs() > sum.abs() * 1e-15 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
        }
        1.0 - prefactor * sum
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            d = if d.abs() < tiny { tiny } else { d };
            c = b + an / c;
            c = if c.abs() < tiny { tiny } else { c };
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        prefactor * h
    }
}

/// Chi-square goodness of fit of directions drawn by `sample` against the
/// density `eval_cos`, binned in `mu` ([`mu_edges`]) and azimuth about
/// `dir_in` (as Mitsuba 3's `ChiSquareTest`): cells expecting fewer than 5
/// samples are pooled. The bin at the pole (`1 - mu < 1e-4`) is not split
/// in azimuth: there a sampled `mu` that rounds to 1 in f32 (0.7 % of
/// HG(0.998)'s samples) gives `dir_in` itself, whose azimuth is rounding
/// noise. Returns the p-value and the degrees of freedom.
fn chi_square(
    sample: impl Fn(Vec3, f32, f32) -> Vec3,
    eval_cos: impl Fn(f32) -> f32,
    seed: u64,
) -> (f64, usize) {
    let din = dir_in();
    let (s, t) = din.any_orthonormal_pair();
    let dind = din.as_dvec3().normalize();
    let edges = mu_edges();
    let bins = edges.len() - 1;
    let mut observed = vec![0f64; bins * PHI_BINS];
    let mut rng = Rng::new(seed, 1, 2);
    for _ in 0..SAMPLES {
        let dir = sample(din, rng.uniform(), rng.uniform());
        // 1 - mu from the f64 chord, which keeps its digits near mu = 1.
        let d: DVec3 = dir.as_dvec3().normalize();
        let mu = 1.0 - 0.5 * (d - dind).length_squared();
        let i = edges.partition_point(|&e| e <= mu).clamp(1, bins) - 1;
        let phi = (dir.dot(t) as f64)
            .atan2(dir.dot(s) as f64)
            .rem_euclid(2.0 * PI);
        let j = if i == bins - 1 {
            0
        } else {
            ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1)
        };
        observed[i * PHI_BINS + j] += 1.0;
    }
    let (mut chi2, mut cells) = (0.0, 0usize);
    let (mut pooled_obs, mut pooled_exp) = (0.0, 0.0);
    for i in 0..bins {
        let cells_here = if i == bins - 1 { 1 } else { PHI_BINS };
        let expected =
            SAMPLES as f64 * integrate(&eval_cos, edges[i], edges[i + 1]) / cells_here as f64;
        for j in 0..cells_here {
            let o = observed[i * PHI_BINS + j];
            if expected < 5.0 {
                pooled_obs += o;
                pooled_exp += expected;
            } else {
                chi2 += (o - expected).powi(2) / expected;
                cells += 1;
            }
        }
    }
    if pooled_exp >= 5.0 {
        chi2 += (pooled_obs - pooled_exp).powi(2) / pooled_exp;
        cells += 1;
    } else {
        assert!(
            pooled_obs <= pooled_exp + 5.0 * pooled_exp.sqrt() + 5.0,
            "{pooled_obs} samples where {pooled_exp} are expected"
        );
    }
    (chi2_upper_tail(chi2, cells - 1), cells - 1)
}

#[test]
fn chi_square_machinery_is_right() {
    // Textbook 5 % critical values: chi2(1) 3.841, chi2(10) 18.307,
    // chi2(100) 124.342; and the mean of chi2(k) is k.
    for (x, k) in [(3.841, 1), (18.307, 10), (124.342, 100)] {
        let p = chi2_upper_tail(x, k);
        assert!((p - 0.05).abs() < 2e-4, "chi2({k}) at {x}: {p}");
    }
    assert!((chi2_upper_tail(2.0, 2) - (-1.0f64).exp()).abs() < 1e-12);
    // The test has power: HG(0.3) samples against HG(0.35)'s density.
    let (a, b) = (Phase::hg(0.3), Phase::hg(0.35));
    let (p, _) = chi_square(|d, u1, u2| a.sample(d, u1, u2).0, |m| b.eval_cos(m), 7);
    assert!(p < 1e-6, "a wrong density must be rejected, p = {p}");
    // And a Draine sampled as HG is caught as well.
    let (h, d) = (Phase::hg(0.5), Phase::draine(0.5, 1.0).unwrap());
    let (p, _) = chi_square(|x, u1, u2| h.sample(x, u1, u2).0, |m| d.eval_cos(m), 7);
    assert!(p < 1e-6, "p = {p}");
}

#[test]
fn every_variant_samples_its_density() {
    let mut report = Vec::new();
    for (k, (name, phase)) in variants().into_iter().enumerate() {
        let (p, dof) = chi_square(
            |d, u1, u2| phase.sample(d, u1, u2).0,
            |m| phase.eval_cos(m),
            1000 + k as u64,
        );
        println!("chi-square {name}: p = {p:.4} ({dof} degrees of freedom)");
        report.push((name, p));
    }
    for (name, p) in report {
        assert!(p > 0.01, "{name}: sampling does not match eval, p = {p}");
    }
}

/// `2 pi` times the integral of `mu^k p(mu)` over [-1, 1] by the trapezoid
/// rule in `x = 1 - mu` on a geometric grid from 1e-9, which resolves any
/// forward peak here (width >= 1e-6) to ~1e-8 relative.
fn moment(phase: &Phase, k: i32) -> f64 {
    let steps = 100_000;
    let (lo, hi) = (1e-9f64, 2.0f64);
    let r = (hi / lo).powf(1.0 / steps as f64);
    let f = |x: f64| 2.0 * PI * (1.0 - x).powi(k) * phase.eval_cos((1.0 - x) as f32) as f64;
    let mut total = f(0.0) * lo;
    let mut x0 = lo;
    for _ in 0..steps {
        let x1 = x0 * r;
        total += 0.5 * (f(x0) + f(x1)) * (x1 - x0);
        x0 = x1;
    }
    total
}

#[test]
fn every_variant_integrates_to_one_and_has_its_mean_cosine() {
    for (name, phase) in variants() {
        let total = moment(&phase, 0);
        assert!((total - 1.0).abs() < 1e-3, "{name}: integral {total}");
        let mean = moment(&phase, 1);
        assert!(
            (f64::from(phase.mean_cosine()) - mean).abs() < 1e-3,
            "{name}: mean_cosine {} but the integral gives {mean}",
            phase.mean_cosine()
        );
    }
    for g in [-0.5f32, 0.0, 0.3, 0.9] {
        assert_eq!(Phase::hg(g).mean_cosine(), g, "HG's mean cosine is g");
    }
}

fn random_dir(rng: &mut Rng) -> Vec3 {
    cirrus_kernel::sampling::uniform_sphere(rng.uniform(), rng.uniform())
}

#[test]
fn pdf_is_eval_samples_report_it_and_eval_is_reciprocal() {
    let mut rng = Rng::new(3, 4, 5);
    for (name, phase) in variants() {
        for _ in 0..2000 {
            let (a, b) = (random_dir(&mut rng), random_dir(&mut rng));
            // Exact sampling: the pdf is the phase value, bit for bit.
            assert_eq!(
                phase.pdf(a, b).to_bits(),
                phase.eval(a, b).to_bits(),
                "{name}"
            );
            // Reciprocity: the reversed path scatters through the same angle.
            assert_eq!(
                phase.eval(a, b).to_bits(),
                phase.eval(-b, -a).to_bits(),
                "{name}"
            );
            assert!(
                phase.eval(a, b).is_finite() && phase.eval(a, b) >= 0.0,
                "{name}"
            );

            let (u1, u2) = (rng.uniform(), rng.uniform());
            let (dir, pdf) = phase.sample(a, u1, u2);
            assert!((dir.length() - 1.0).abs() < 1e-5, "{name}: {dir}");
            assert_eq!(
                pdf.to_bits(),
                phase.eval_cos(phase.sample_cos(u1)).to_bits()
            );
            // The returned pdf is at the sampled mu; `pdf` recomputes mu
            // from the f32 direction, off by up to a few 1e-7, which at a
            // forward peak (HG g = 0.998 in mie(50): log-slope ~1e6) moves
            // the value by more than any fixed tolerance: allow the change
            // of the function over that distance.
            let again = phase.pdf(a, dir);
            let mu = a.dot(dir);
            let spread = (phase.eval_cos(mu + 3e-7) - phase.eval_cos(mu - 3e-7)).abs();
            assert!(
                pdf > 0.0 && (pdf - again).abs() <= 1e-4 * pdf.max(again) + spread,
                "{name}: sample says {pdf}, pdf() says {again}"
            );
        }
    }
}

/// Draine's density in f64, written out independently of the crate.
fn draine_f64(g: f64, alpha: f64, mu: f64) -> f64 {
    let hg = (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * mu).powf(1.5));
    hg * (1.0 + alpha * mu * mu) / (1.0 + alpha * (1.0 + 2.0 * g * g) / 3.0)
}

/// `P(M <= mu)`; for `g < 0` by the mirror symmetry `p_g(mu) = p_-g(-mu)`,
/// so the quadrature always starts at the peak.
fn draine_cdf(g: f64, alpha: f64, mu: f64) -> f64 {
    if g >= 0.0 {
        1.0 - draine_tail(g, alpha, mu)
    } else {
        draine_tail(-g, alpha, -mu)
    }
}

/// `P(M > mu)` for `g >= 0` by the trapezoid rule in `x = 1 - mu`,
/// geometric from 1e-13.
fn draine_tail(g: f64, alpha: f64, mu: f64) -> f64 {
    let x_end = 1.0 - mu;
    if x_end <= 1e-13 {
        return 2.0 * PI * draine_f64(g, alpha, 1.0) * x_end;
    }
    let steps = 20_000;
    let r = (x_end / 1e-13).powf(1.0 / steps as f64);
    let f = |x: f64| 2.0 * PI * draine_f64(g, alpha, 1.0 - x);
    let mut total = f(0.0) * 1e-13;
    let mut x0 = 1e-13;
    for _ in 0..steps {
        let x1 = (x0 * r).min(x_end);
        total += 0.5 * (f(x0) + f(x1)) * (x1 - x0);
        x0 = x1;
    }
    total
}

#[test]
fn draine_inverts_its_cdf_at_extreme_parameters() {
    let params = [
        (0.001, 1.0),
        (0.01, 0.5),
        (0.5, 1e-5),
        (0.5, 1e6),
        (-0.7, 10.0),
        (0.9, 30.0),
        (0.9999, 1e-5),
        (0.9999, 100.0),
        (-0.9999, 3.0),
        (0.0, 1.0),
        (0.0, 1e4),
    ];
    for (g, alpha) in params {
        let phase = Phase::draine(g, alpha).unwrap();
        let mut last = -1.0f32;
        for i in 0..=200 {
            let u = (i as f32 / 200.0).min(1.0 - f32::EPSILON / 2.0);
            let mu = phase.sample_cos(u);
            assert!(mu >= last, "g {g} alpha {alpha}: not monotone at u = {u}");
            last = mu;
            // F(mu) = u, with F from the independent f64 density; the
            // tolerance covers f32 mu (1e-7 times the density, up to ~1e3
            // per unit mu at g = 0.9999 in the peak) and the quadrature.
            let cdf = draine_cdf(g as f64, alpha as f64, mu as f64);
            let slack = 1e-5 + 2e-7 * 2.0 * PI * draine_f64(g as f64, alpha as f64, mu as f64);
            assert!(
                (cdf - u as f64).abs() < slack,
                "g {g} alpha {alpha}: u {u} gives mu {mu}, whose CDF is {cdf}"
            );
        }
        for mu in [-1.0, -0.3, 0.0, 0.5, 0.99] {
            let (ours, exact) = (
                phase.eval_cos(mu),
                draine_f64(g as f64, alpha as f64, mu as f64),
            );
            assert!(
                ((ours as f64) - exact).abs() <= 1e-5 * exact,
                "g {g} alpha {alpha} mu {mu}: {ours} vs {exact}"
            );
        }
    }
}

#[test]
fn draine_special_cases_are_hg_and_rayleigh() {
    let (hg, draine0) = (Phase::hg(0.7), Phase::draine(0.7, 0.0).unwrap());
    let ray = Phase::rayleigh();
    let draine_r = Phase::draine(0.0, 1.0).unwrap();
    for i in 0..=100 {
        let mu = -1.0 + i as f32 / 50.0;
        assert_eq!(hg.eval_cos(mu), draine0.eval_cos(mu));
        let (a, b) = (ray.eval_cos(mu), draine_r.eval_cos(mu));
        assert!((a - b).abs() <= 1e-6 * a, "{mu}: {a} {b}");
        let u = i as f32 / 101.0;
        assert_eq!(hg.sample_cos(u), draine0.sample_cos(u));
        assert_eq!(ray.sample_cos(u), draine_r.sample_cos(u));
    }
    assert_eq!(Phase::rayleigh().mean_cosine(), 0.0);
}

#[test]
fn mie_fit_matches_the_published_formulas() {
    // Computed separately in Python (f64) from Jendersie and d'Eon's
    // eqs. 7-10: g_HG, g_D, alpha, w_D, then p(1) and p(-1) of
    // (1 - w_D) HG(g_HG) + w_D Draine(g_D, alpha).
    let expected = [
        (
            10.0,
            [0.988177, 0.555671, 21.9955, 0.481955],
            586.86,
            0.012715,
        ),
        (
            20.0,
            [0.99461, 0.593791, 27.1137, 0.498159],
            2742.51,
            0.010914,
        ),
    ];
    let close = |a: f32, b: f64, tol: f64| ((a as f64) - b).abs() <= tol * b.abs();
    for (d, params, forward, backward) in expected {
        let fit = MieFit::new(d).unwrap();
        let got = [fit.g_hg, fit.g_d, fit.alpha, fit.w_d];
        for (name, (a, b)) in ["g_HG", "g_D", "alpha", "w_D"]
            .iter()
            .zip(got.iter().zip(params))
        {
            assert!(close(*a, b, 1e-5), "d = {d}: {name} = {a}, expected {b}");
        }
        let phase = Phase::mie(d).unwrap();
        let (f, b) = (phase.eval_cos(1.0), phase.eval_cos(-1.0));
        assert!(
            close(f, forward, 1e-4),
            "d = {d}: p(1) = {f}, expected {forward}"
        );
        assert!(
            close(b, backward, 1e-4),
            "d = {d}: p(-1) = {b}, expected {backward}"
        );
    }
    for bad in [4.99, 50.01, 0.0, -10.0, f32::NAN, f32::INFINITY] {
        let err = Phase::mie(bad).unwrap_err().to_string();
        assert!(err.contains("[5, 50]"), "{bad}: {err}");
    }
    assert!(Phase::mie(5.0).is_ok() && Phase::mie(50.0).is_ok());
}
