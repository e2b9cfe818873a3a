//! Denoising a finished render with Open Image Denoise: the image's RGB is
//! replaced by the filter's output, guided by the first-scattering albedo
//! (as Cycles' denoising albedo pass), and the noisy RGB is kept for the
//! EXR's `noisy` layer. Alpha is left as it is: it is a coverage estimate
//! the compositor needs unfiltered.

use std::sync::OnceLock;
use std::time::Instant;

use cirrus_denoise::Denoiser;
use cirrus_render::Rendered;

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

/// Denoises `r` in place; its AOVs must hold the albedo.
pub fn denoise(r: &mut Rendered) -> Result<()> {
    let start = Instant::now();
    let denoiser = denoiser()?;
    let img = &mut r.image;
    let (w, h) = (img.width as usize, img.height as usize);
    let noisy: Vec<[f32; 3]> = img.rgba.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let color: Vec<f32> = noisy.iter().flatten().copied().collect();
    let albedo: Option<Vec<f32>> = r
        .aovs
        .as_ref()
        .map(|a| a.albedo.iter().flatten().copied().collect());
    let clean = denoiser
        .denoise(&color, albedo.as_deref(), None, w, h, true)
        .map_err(|e| Error::input(format!("denoise: {e}")))?;
    for (p, c) in img.rgba.iter_mut().zip(clean.chunks_exact(3)) {
        p[..3].copy_from_slice(c);
    }
    r.noisy = Some(noisy);
    // Light groups: each denoised with the same guide, then made to sum
    // to the denoised beauty (crate::compositing::denoise_groups).
    crate::compositing::denoise_groups(r, |group| {
        let color: Vec<f32> = group.iter().flatten().copied().collect();
        let clean = denoiser
            .denoise(&color, albedo.as_deref(), None, w, h, true)
            .map_err(|e| Error::input(format!("denoise: {e}")))?;
        Ok(clean.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    })?;
    r.stats.denoise_seconds = start.elapsed().as_secs_f64();
    Ok(())
}
