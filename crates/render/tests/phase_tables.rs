//! Tabulated phase functions (in memory and from files), constructor
//! errors for every variant, and phase functions in a render (furnace).

mod common;

use std::path::PathBuf;

use cirrus_kernel::phase::MAX_TABLE_ROWS;
use cirrus_render::{render, IntegratorKind, Lights, Phase};
use glam::Vec3;

/// A file in the temporary directory, removed when dropped.
struct TempFile(PathBuf);

impl TempFile {
    fn new(name: &str, contents: &str) -> Self {
        let path =
            std::env::temp_dir().join(format!("cirrus-phase-{}-{name}.txt", std::process::id()));
        std::fs::write(&path, contents).unwrap();
        Self(path)
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// `2 pi` times the trapezoid integral of `eval_cos` on a uniform grid
/// (exact up to rounding for a piecewise-linear function whose knots are
/// on the grid, close otherwise).
fn integral(phase: &Phase) -> f64 {
    let n = 200_000;
    let f = |i: usize| phase.eval_cos(-1.0 + 2.0 * i as f32 / n as f32) as f64;
    let inner: f64 = (1..n).map(f).sum();
    2.0 * std::f64::consts::PI * (inner + 0.5 * (f(0) + f(n))) * 2.0 / n as f64
}

#[test]
fn table_is_normalised_and_interpolates_linearly() {
    // A triangle peaked forward, scaled by 7: the normalised function is
    // 1 + mu over [-1, 1] divided by its integral 2 pi * 2 = 4 pi.
    let phase = Phase::table(&[-1.0, 1.0], &[0.0, 14.0]).unwrap();
    let pi = std::f32::consts::PI;
    for mu in [-1.0f32, -0.5, 0.0, 0.25, 1.0] {
        let expected = (1.0 + mu) / (4.0 * pi);
        assert!((phase.eval_cos(mu) - expected).abs() < 1e-7, "{mu}");
    }
    assert!((integral(&phase) - 1.0).abs() < 1e-6);
    // Mean cosine of (1 + mu) / 2 on [-1, 1]: 1/3.
    assert!((phase.mean_cosine() - 1.0 / 3.0).abs() < 1e-6);
    // Sampling inverts F(mu) = (1 + mu)^2 / 4 exactly: mu = 2 sqrt(u) - 1.
    for u in [0.0f32, 0.01, 0.25, 0.5, 0.9, 0.999] {
        let mu = phase.sample_cos(u);
        assert!((mu - (2.0 * u.sqrt() - 1.0)).abs() < 1e-6, "{u}: {mu}");
    }
}

#[test]
fn tabulated_rayleigh_matches_rayleigh() {
    let cos: Vec<f32> = (0..=2000).map(|i| -1.0 + i as f32 / 1000.0).collect();
    let values: Vec<f32> = cos.iter().map(|&m| 1.0 + m * m).collect();
    let table = Phase::table(&cos, &values).unwrap();
    let rayleigh = Phase::rayleigh();
    for i in 0..=997 {
        let mu = -1.0 + i as f32 * 2.0 / 997.0;
        let (a, b) = (table.eval_cos(mu), rayleigh.eval_cos(mu));
        assert!((a - b).abs() <= 1e-5 * b, "{mu}: {a} vs {b}");
        let u = i as f32 / 998.0;
        let (a, b) = (table.sample_cos(u), rayleigh.sample_cos(u));
        assert!((a - b).abs() <= 1e-4, "u {u}: {a} vs {b}");
    }
    assert!(table.mean_cosine().abs() < 1e-6);
}

#[test]
fn table_with_zero_stretches_samples_only_where_it_is_positive() {
    // Zero on [-1, 0]: no sample may land there.
    let phase = Phase::table(&[-1.0, 0.0, 0.5, 1.0], &[0.0, 0.0, 2.0, 1.0]).unwrap();
    for i in 0..1000 {
        let mu = phase.sample_cos(i as f32 / 1000.0);
        assert!(mu >= 0.0, "{mu}");
    }
}

#[test]
fn table_file_is_read_with_comments_commas_and_either_order() {
    let file = TempFile::new(
        "good",
        "# A phase table by increasing angle (decreasing cosine).\n\
         # cos(theta), value\n\
         \n\
         1.0, 4.0   # forward\n\
         0.5\t3.0\n\
         \x20 0.0 , 2.0\n\
         -0.5 1.5\n\
         -1 1\n",
    );
    let read = Phase::read_table(&file.0).unwrap();
    let direct = Phase::table(&[-1.0, -0.5, 0.0, 0.5, 1.0], &[1.0, 1.5, 2.0, 3.0, 4.0]).unwrap();
    assert_eq!(read, direct);
    assert!((integral(&read) - 1.0).abs() < 1e-6);
    // Ends within 1e-4 of +-1 are snapped onto them.
    let snapped = TempFile::new("snapped", "-0.99995 1\n0.99995 1\n");
    let p = Phase::read_table(&snapped.0).unwrap();
    assert!((p.eval_cos(0.3) - 0.25 / std::f32::consts::PI).abs() < 1e-7);
}

#[test]
fn bad_table_files_name_the_file_and_line() {
    let cases = [
        (
            "word",
            "-1 1\n# fine\n0.5 abc\n1 1\n",
            ":3:",
            "not a number",
        ),
        (
            "columns",
            "-1 1\n0 1\n\n0.5 1 2\n1 1\n",
            ":4:",
            "two columns",
        ),
        ("one-column", "-1 1\n0\n1 1\n", ":2:", "two columns"),
        ("negative", "-1 1\n0 -2\n1 1\n", ":2:", ">= 0"),
        ("nan", "-1 1\n0 NaN\n1 1\n", ":2:", ">= 0"),
        ("infinite", "-1 1\n0 inf\n1 1\n", ":2:", ">= 0"),
        (
            "order",
            "# header\n-1 1\n0.5 1\n0.2 1\n1 1\n",
            ":4:",
            "strictly increasing",
        ),
        ("repeat", "-1 1\n0 1\n0 2\n1 1\n", ":3:", "strictly"),
        ("range", "-1 1\n1.5 1\n", ":2:", "[-1, 1]"),
        ("partial", "-0.5 1\n1 1\n", ": ", "from -1 to 1"),
        ("single", "# only\n1 1\n", ": ", "2 to"),
        ("empty", "# nothing here\n", ": ", "2 to"),
        ("zero", "-1 0\n1 0\n", ": ", "positive"),
    ];
    for (name, contents, place, what) in cases {
        let file = TempFile::new(name, contents);
        let err = Phase::read_table(&file.0).unwrap_err().to_string();
        let prefix = format!("{}{place}", file.0.display());
        assert!(
            err.starts_with(&prefix),
            "{name}: '{err}' should start with '{prefix}'"
        );
        assert!(err.contains(what), "{name}: '{err}' should say '{what}'");
    }
    let missing = std::env::temp_dir().join("cirrus-phase-no-such-file.txt");
    let err = Phase::read_table(&missing).unwrap_err().to_string();
    assert!(err.contains("cirrus-phase-no-such-file.txt"), "{err}");
}

#[test]
fn constructors_refuse_bad_input_without_panicking() {
    let n = MAX_TABLE_ROWS + 1;
    let cos: Vec<f32> = (0..n)
        .map(|i| -1.0 + 2.0 * i as f32 / (n - 1) as f32)
        .collect();
    assert!(Phase::table(&cos, &vec![1.0; n])
        .unwrap_err()
        .to_string()
        .contains("rows"));
    assert!(Phase::table(&[-1.0, 1.0], &[1.0]).is_err());
    assert!(Phase::table(&[], &[]).is_err());
    assert!(Phase::table(&[-1.0, f32::NAN, 1.0], &[1.0; 3]).is_err());
    assert!(Phase::table(&[-1.0, 1.0], &[1.0, f32::INFINITY]).is_err());

    for w in [-0.1, 1.1, f32::NAN] {
        assert!(Phase::hg2(0.5, -0.5, w).is_err(), "weight {w}");
    }
    assert!(Phase::hg2(f32::NAN, 0.0, 0.5).is_err());
    assert!(Phase::hg2(0.5, f32::INFINITY, 0.5).is_err());
    for (g, alpha) in [
        (0.5, -1.0),
        (0.5, f32::NAN),
        (0.5, f32::INFINITY),
        (f32::NAN, 1.0),
    ] {
        assert!(Phase::draine(g, alpha).is_err(), "g {g} alpha {alpha}");
    }
    // |g| >= 1 is clamped, as for HG, and stays usable.
    for phase in [
        Phase::hg2(1.0, -1.0, 0.5).unwrap(),
        Phase::draine(1.0, 2.0).unwrap(),
        Phase::draine(-3.0, 0.5).unwrap(),
    ] {
        for u in [0.0, 0.5, 1.0 - f32::EPSILON / 2.0] {
            let (dir, pdf) = phase.sample(Vec3::Z, u, 0.3);
            assert!(
                dir.is_finite() && pdf.is_finite() && pdf > 0.0,
                "{phase:?} u {u}"
            );
        }
    }
    // Blends at their extreme weights are their lobes.
    let (only1, only2) = (
        Phase::hg2(0.6, -0.3, 1.0).unwrap(),
        Phase::hg2(0.6, -0.3, 0.0).unwrap(),
    );
    for u in [0.0, 0.3, 0.999] {
        assert_eq!(only1.sample_cos(u), Phase::hg(0.6).sample_cos(u));
        assert_eq!(only2.sample_cos(u), Phase::hg(-0.3).sample_cos(u));
    }
}

#[test]
fn white_furnace_is_invisible_with_every_phase_function() {
    // As furnace.rs, with the other phase functions: a non-absorbing medium
    // in a constant environment renders as the environment, whatever the
    // phase function, when sampling and MIS weights are consistent.
    let l_env = 0.6f32;
    let table = Phase::table(&[-1.0, 0.0, 0.9, 1.0], &[0.2, 0.5, 3.0, 9.0]).unwrap();
    let phases = [
        Phase::mie(20.0).unwrap(),
        Phase::draine(-0.4, 5.0).unwrap(),
        Phase::hg2(0.9, -0.5, 0.6).unwrap(),
        Phase::rayleigh(),
        table,
    ];
    for (i, phase) in phases.into_iter().enumerate() {
        let label = format!("{phase:?}");
        let medium = common::medium(common::cloud_field(4), 8.0, 1.0, 0.0).with_phase(phase);
        let lights = Lights::sun_and_sky(None, common::env(Vec3::splat(l_env)));
        let scene = common::scene(medium, 12, lights);
        let mut settings = common::settings(IntegratorKind::Path, 64, 300 + i as u64);
        settings.max_depth = None;
        let out = render(&scene, &settings);
        assert_eq!(out.stats.counters.nonfinite_samples, 0, "{label}");
        assert!(out.stats.counters.real_collisions > 500, "{label}");
        let img = &out.image;
        for y in 0..img.height {
            for x in 0..img.width {
                let (px, se) = (img.pixel(x, y), img.std_error(x, y));
                for c in 0..3 {
                    let bound = 5.0 * se[c] + 1e-5 * l_env;
                    assert!(
                        (px[c] - l_env).abs() <= bound,
                        "{label}: pixel ({x}, {y}) = {} (bound {bound})",
                        px[c]
                    );
                }
            }
        }
    }
}
