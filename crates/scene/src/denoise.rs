//! Denoising a finished render with Open Image Denoise, blended with the
//! noisy image by each one's estimated error: the image's RGB becomes
//! `w * noisy + (1 - w) * denoised` per pixel, where the denoiser's error is
//! measured on the two independent halves of the samples
//! ([`cirrus_denoise::blend`]), so more samples never give a worse image.
//! The filter is guided by the first-scattering albedo (as Cycles'
//! denoising albedo pass). The EXR keeps the noisy RGB, the plain denoised
//! RGB and the weight `w`. Alpha is left as it is: it is a coverage
//! estimate the compositor needs unfiltered.

use std::sync::OnceLock;
use std::time::Instant;

use cirrus_denoise::blend::{self, BlendInputs};
use cirrus_denoise::Denoiser;
use cirrus_render::{Denoised, Halves, Rendered};

use crate::error::{Error, Result};

/// One loaded library and device per process: loading costs tens of
/// milliseconds and the device is reusable.
fn denoiser() -> Result<&'static Denoiser> {
    static DENOISER: OnceLock<std::result::Result<Denoiser, String>> = OnceLock::new();
    DENOISER
        .get_or_init(|| Denoiser::load().map_err(|e| e.to_string()))
        .as_ref()
        .map_err(|e| Error::file(format!("denoise: {e}")))
}

/// Whether Open Image Denoise loads; the error says how to install it.
pub fn denoise_available() -> Result<()> {
    denoiser().map(|_| ())
}

/// Denoises `r` in place; its AOVs must hold the albedo. With the halves
/// of its samples (`RenderSettings::halves`) the result is the blend;
/// without them (a preview's accumulated passes) it is the plain
/// denoised image.
pub fn denoise(r: &mut Rendered) -> Result<()> {
    let start = Instant::now();
    let denoiser = denoiser()?;
    let (w, h) = (r.image.width as usize, r.image.height as usize);
    let albedo: Option<Vec<f32>> = r
        .aovs
        .as_ref()
        .map(|a| a.albedo.iter().flatten().copied().collect());
    let filter = |rgb: &[[f32; 3]]| -> Result<Vec<[f32; 3]>> {
        let color: Vec<f32> = rgb.iter().flatten().copied().collect();
        let clean = denoiser
            .denoise(&color, albedo.as_deref(), None, w, h, true)
            .map_err(|e| Error::input(format!("denoise: {e}")))?;
        Ok(clean.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    };
    let noisy: Vec<[f32; 3]> = r.image.rgba.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let plain = filter(&noisy)?;
    // A pixel with samples in one half only (1 spp) allows no estimate and
    // gets the denoised image; where none has two, the halves are not
    // filtered at all.
    let two_halves = |h: &&Halves| h.samples.iter().any(|&[a, b]| a > 0 && b > 0);
    let noisy_weight = match r.halves.as_ref().filter(two_halves) {
        Some(halves) => {
            let variance: Vec<[f32; 3]> = r
                .image
                .variance
                .iter()
                .map(|v| [v[0], v[1], v[2]])
                .collect();
            let (da, db) = (filter(&halves.a)?, filter(&halves.b)?);
            let inputs = BlendInputs {
                width: w,
                height: h,
                variance: &variance,
                half_samples: &halves.samples,
                halves: [&halves.a, &halves.b],
                denoised_halves: [&da, &db],
            };
            blend::noisy_weights(&inputs, blend::DEFAULT_RADIUS)
        }
        None => vec![0.0; w * h],
    };
    let out = blend::blend(&noisy, &plain, &noisy_weight);
    for (p, c) in r.image.rgba.iter_mut().zip(&out) {
        p[..3].copy_from_slice(c);
    }
    // Light groups: each denoised with the same guide, made to sum to the
    // plain denoised beauty, then blended as the beauty was
    // (crate::compositing::denoise_groups).
    crate::compositing::denoise_groups(r, &plain, &noisy_weight, filter)?;
    r.denoised = Some(Denoised {
        noisy,
        plain,
        noisy_weight,
    });
    r.stats.denoise_seconds = start.elapsed().as_secs_f64();
    Ok(())
}
