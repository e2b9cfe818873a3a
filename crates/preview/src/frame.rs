//! Turning an accumulation into what the page shows: optionally denoised,
//! exposed, tone-mapped and sRGB-encoded exactly as `cirrus render --png`
//! does (the renderer's own `tonemap` and `srgb_encode`), as a PNG.

use std::sync::OnceLock;

use cirrus_denoise::Denoiser;
use cirrus_render::image_io::{srgb_encode, tonemap};

use crate::accumulate::Accumulation;

/// The denoiser, loaded once per process (loading costs tens of
/// milliseconds), or why it is not available.
pub fn denoiser() -> Result<&'static Denoiser, String> {
    static DENOISER: OnceLock<Result<Denoiser, String>> = OnceLock::new();
    DENOISER
        .get_or_init(|| Denoiser::load().map_err(|e| e.to_string()))
        .as_ref()
        .map_err(Clone::clone)
}

/// The accumulation's RGB, denoised when asked and possible. The flag
/// says whether it was denoised.
pub fn display_rgb(acc: &Accumulation, denoise: bool) -> (Vec<f32>, bool) {
    let rgb: Vec<f32> = acc.rgba.iter().flat_map(|p| [p[0], p[1], p[2]]).collect();
    if !denoise {
        return (rgb, false);
    }
    let Ok(d) = denoiser() else {
        return (rgb, false);
    };
    let albedo: Option<Vec<f32>> = acc
        .albedo
        .as_ref()
        .map(|a| a.iter().flatten().copied().collect());
    let (w, h) = (acc.width as usize, acc.height as usize);
    match d.denoise(&rgb, albedo.as_deref(), None, w, h, true) {
        Ok(clean) => (clean, true),
        Err(_) => (rgb, false),
    }
}

/// An 8-bit sRGB PNG of linear `rgb` (`width x height`) at `exposure` stops.
pub fn encode_png(rgb: &[f32], width: u32, height: u32, exposure: f32) -> std::io::Result<Vec<u8>> {
    let scale = exposure.exp2();
    let data: Vec<u8> = rgb
        .iter()
        .map(|&c| (srgb_encode(tonemap(c * scale)) * 255.0 + 0.5) as u8)
        .collect();
    let mut out = Vec::with_capacity(data.len() / 2);
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        // Frames are shown once and replaced: speed over size.
        enc.set_compression(png::Compression::Fast);
        let mut writer = enc.write_header().map_err(std::io::Error::other)?;
        writer
            .write_image_data(&data)
            .map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)?;
    }
    Ok(out)
}
