//! Tests of `cirrus-denoise`.
//!
//! The tests that run OIDN need the library: they are skipped (with a
//! message) only when `CIRRUS_OIDN` is unset and nothing loads; with
//! `CIRRUS_OIDN` set, a library that does not load fails them.

use std::path::PathBuf;

use cirrus_denoise::{DenoiseError, Denoiser, SearchPath};
use cirrus_testkit::SplitMix64;

/// The denoiser, or `None` (after saying why) when the test should be skipped.
fn denoiser(test: &str) -> Option<Denoiser> {
    match Denoiser::load() {
        Ok(d) => {
            eprintln!(
                "{test}: OIDN {:?} from {}",
                d.version(),
                d.library().display()
            );
            Some(d)
        }
        Err(e) => {
            if std::env::var_os("CIRRUS_OIDN").is_some_and(|v| !v.is_empty()) {
                panic!("CIRRUS_OIDN is set but OIDN did not load: {e}");
            }
            eprintln!("{test}: SKIPPED, Open Image Denoise not found (set CIRRUS_OIDN): {e}");
            None
        }
    }
}

/// The tests' SplitMix64, for noise that is the same on every run.
struct Rng(SplitMix64);

impl Rng {
    /// Uniform in (0, 1].
    fn uniform(&mut self) -> f64 {
        ((self.0.next_u64() >> 11) + 1) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box-Muller).
    fn gaussian(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

const W: usize = 192;
const H: usize = 128;
const SIGMA: f64 = 0.08;

/// A smooth image: a colour gradient with a flat-coloured disc on it,
/// values within [0.1, 0.9]. Also returns the matching albedo.
fn clean_image() -> (Vec<f32>, Vec<f32>) {
    let mut color = Vec::with_capacity(W * H * 3);
    let mut albedo = Vec::with_capacity(W * H * 3);
    for y in 0..H {
        for x in 0..W {
            let (fx, fy) = (x as f32 / (W - 1) as f32, y as f32 / (H - 1) as f32);
            let (dx, dy) = (x as f32 - 0.6 * W as f32, y as f32 - 0.5 * H as f32);
            let in_disc = dx * dx + dy * dy < (0.3 * H as f32).powi(2);
            let (rgb, alb) = if in_disc {
                ([0.8, 0.3, 0.2], [0.8, 0.3, 0.2])
            } else {
                let shade = 0.2 + 0.6 * fx;
                ([shade, 0.2 + 0.5 * fy, 0.9 - 0.6 * fx], [0.5, 0.5, 0.5])
            };
            color.extend(rgb);
            albedo.extend(alb);
        }
    }
    (color, albedo)
}

fn add_noise(clean: &[f32], seed: u64) -> Vec<f32> {
    let mut rng = Rng(SplitMix64(seed));
    clean
        .iter()
        .map(|&v| (v as f64 + SIGMA * rng.gaussian()) as f32)
        .collect()
}

fn mse(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
        .sum::<f64>()
        / a.len() as f64
}

#[test]
fn denoising_lowers_mse_at_least_5x() {
    let Some(d) = denoiser("denoising_lowers_mse_at_least_5x") else {
        return;
    };
    let (clean, albedo) = clean_image();
    let noisy = add_noise(&clean, 7);
    let noisy_mse = mse(&noisy, &clean);
    // The noise has the variance asked for (within sampling error).
    let var = SIGMA * SIGMA;
    assert!(
        (noisy_mse - var).abs() < 0.05 * var,
        "noisy MSE {noisy_mse}, expected {var}"
    );

    for (label, albedo, hdr) in [
        ("ldr", None, false),
        ("hdr", None, true),
        ("hdr+albedo", Some(albedo.as_slice()), true),
        ("ldr again (cached filter rebuilt)", None, false),
    ] {
        let t = std::time::Instant::now();
        let out = d.denoise(&noisy, albedo, None, W, H, hdr).expect("denoise");
        assert_eq!(out.len(), W * H * 3);
        assert!(
            out.iter().all(|v| v.is_finite()),
            "{label}: non-finite output"
        );
        let denoised_mse = mse(&out, &clean);
        let ratio = noisy_mse / denoised_mse;
        eprintln!(
            "{label}: noisy MSE {noisy_mse:.3e}, denoised MSE {denoised_mse:.3e}, \
             ratio {ratio:.1}x, {:.0} ms",
            t.elapsed().as_secs_f64() * 1e3
        );
        assert!(ratio >= 5.0, "{label}: MSE only {ratio:.2}x lower");
    }

    // The cached filter, reused with new buffers, gives the same result.
    let a = d.denoise(&noisy, None, None, W, H, true).unwrap();
    let b = d.denoise(&noisy, None, None, W, H, true).unwrap();
    assert_eq!(a, b);
}

#[test]
fn non_finite_input_gives_finite_output() {
    let Some(d) = denoiser("non_finite_input_gives_finite_output") else {
        return;
    };
    let (clean, albedo) = clean_image();
    let mut noisy = add_noise(&clean, 11);
    let mut albedo = albedo;
    for i in (0..noisy.len()).step_by(97) {
        noisy[i] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][i % 3];
    }
    albedo[5] = f32::NAN;
    for hdr in [true, false] {
        let out = d
            .denoise(&noisy, Some(&albedo), None, W, H, hdr)
            .expect("denoise");
        assert_eq!(out.len(), W * H * 3);
        assert!(
            out.iter().all(|v| v.is_finite()),
            "hdr={hdr}: non-finite output"
        );
        // The bad samples did not spread: still close to the clean image.
        let m = mse(&out, &clean);
        assert!(m < SIGMA * SIGMA, "hdr={hdr}: MSE {m} after NaN input");
    }
}

#[test]
fn albedo_and_normal_guide_the_filter() {
    let Some(d) = denoiser("albedo_and_normal_guide_the_filter") else {
        return;
    };
    let (clean, albedo) = clean_image();
    let noisy = add_noise(&clean, 3);
    let normal: Vec<f32> = (0..W * H).flat_map(|_| [0.0, 0.0, 1.0]).collect();
    let out = d
        .denoise(&noisy, Some(&albedo), Some(&normal), W, H, true)
        .expect("denoise with albedo and normal");
    assert!(mse(&out, &clean) * 5.0 <= mse(&noisy, &clean));
}

#[test]
fn denoiser_is_send_and_sync() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Denoiser>();
}

#[test]
fn missing_library_error_names_pip_install() {
    let search = SearchPath {
        cirrus_oidn: Some(PathBuf::from(
            "/nonexistent/cirrus/libOpenImageDenoise.so.2",
        )),
        oidn_dir: None,
        python: Some("python3".into()),
        executable: None,
        system: true,
    };
    // An explicit CIRRUS_OIDN is the only place tried, whatever else exists.
    assert_eq!(search.candidates().len(), 1);
    let err = Denoiser::load_from(&search).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, DenoiseError::NotFound { .. }), "{msg}");
    assert!(msg.contains("pip install pyoidn"), "{msg}");
    assert!(msg.contains("CIRRUS_OIDN"), "{msg}");
    assert!(
        msg.contains("/nonexistent/cirrus/libOpenImageDenoise.so.2"),
        "{msg}"
    );

    // Nothing to search at all: the same advice.
    let err = Denoiser::load_from(&SearchPath::default()).unwrap_err();
    assert!(err.to_string().contains("pip install pyoidn"), "{err}");

    // A directory without the library, and a file that is not one.
    let dir = std::env::temp_dir().join(format!("cirrus-denoise-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bogus = dir.join("libOpenImageDenoise.so.2");
    for (path, write) in [(dir.clone(), false), (bogus.clone(), true)] {
        if write {
            std::fs::write(&bogus, b"not a shared library").unwrap();
        }
        let search = SearchPath {
            cirrus_oidn: Some(path),
            ..SearchPath::default()
        };
        let err = Denoiser::load_from(&search).unwrap_err();
        assert!(err.to_string().contains("pip install pyoidn"), "{err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn size_mismatch_is_an_error_not_a_panic() {
    let img = vec![0.5f32; 4 * 4 * 3];
    let short = vec![0.5f32; 4 * 4 * 3 - 1];
    type Case<'a> = (
        &'a [f32],
        Option<&'a [f32]>,
        Option<&'a [f32]>,
        usize,
        usize,
    );
    let cases: [Case; 7] = [
        (&short, None, None, 4, 4),
        (&img, Some(&short), None, 4, 4),
        (&img, Some(&img), Some(&short), 4, 4),
        (&img, None, Some(&img), 4, 4), // normal without albedo
        (&img, None, None, 4, 5),
        (&img, None, None, 0, 4),
        (&img, None, None, usize::MAX, 3),
    ];
    // The checks run before OIDN is called: tested without the library...
    for (i, &(c, a, n, w, h)) in cases.iter().enumerate() {
        match cirrus_denoise::validate(c, a, n, w, h) {
            Err(DenoiseError::InvalidInput(msg)) => eprintln!("case {i}: {msg}"),
            other => panic!("case {i}: expected InvalidInput, got {other:?}"),
        }
    }
    assert_eq!(
        cirrus_denoise::validate(&img, Some(&img), Some(&img), 4, 4).unwrap(),
        48
    );

    // ...and through `denoise` when it is there.
    let Some(d) = denoiser("size_mismatch_is_an_error_not_a_panic") else {
        return;
    };
    for (i, (c, a, n, w, h)) in cases.into_iter().enumerate() {
        match d.denoise(c, a, n, w, h, true) {
            Err(DenoiseError::InvalidInput(_)) => {}
            other => panic!("case {i}: expected InvalidInput, got {other:?}"),
        }
    }
    // The denoiser still works afterwards.
    assert_eq!(
        d.denoise(&img, None, None, 4, 4, true).unwrap().len(),
        img.len()
    );
}

#[test]
fn one_denoiser_shared_by_threads() {
    let Some(d) = denoiser("one_denoiser_shared_by_threads") else {
        return;
    };
    let (clean, _) = clean_image();
    let noisy = add_noise(&clean, 5);
    let expected = d.denoise(&noisy, None, None, W, H, true).unwrap();
    std::thread::scope(|s| {
        for t in 0..3usize {
            let (d, noisy, expected) = (&d, &noisy, &expected);
            s.spawn(move || {
                for _ in 0..3 {
                    // Alternate filter keys so the cached filter is swapped.
                    if t % 2 == 1 {
                        let out = d
                            .denoise(&noisy[..48 * 3], None, None, 16, 3, false)
                            .unwrap();
                        assert!(out.iter().all(|v| v.is_finite()));
                    }
                    assert_eq!(&d.denoise(noisy, None, None, W, H, true).unwrap(), expected);
                }
            });
        }
    });
}
