//! Writing images: linear RGBA EXR and a tone-mapped sRGB PNG preview.
//!
//! Both are written atomically: to a temporary file in the destination's
//! directory, synced, then renamed over the destination, so a reader (or a
//! crash) sees the whole file or none.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::film::Image;

/// Writes `image` as a 32-bit float RGBA OpenEXR file. RGB is radiance,
/// alpha is `1 - T` of the camera rays.
pub fn write_exr(path: &Path, image: &Image) -> io::Result<()> {
    use exr::prelude::*;
    atomic_write(path, |file| {
        let (w, h) = (image.width as usize, image.height as usize);
        let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
            let [r, g, b, a] = image.rgba[y * w + x];
            (r, g, b, a)
        });
        let layer = Layer::new(
            (w, h),
            LayerAttributes::default(),
            Encoding::SMALL_LOSSLESS,
            channels,
        );
        Image::from_layer(layer)
            .write()
            .to_buffered(BufWriter::new(file))
            .map_err(|e| io::Error::other(e.to_string()))
    })
}

/// Writes an 8-bit sRGB PNG preview: radiance times `2^exposure_stops`,
/// through [`tonemap`], then the sRGB transfer function. Opaque RGB: the
/// radiance already contains whatever background the lights provide.
pub fn write_png(path: &Path, image: &Image, exposure_stops: f32) -> io::Result<()> {
    let scale = exposure_stops.exp2();
    let mut data = Vec::with_capacity(image.rgba.len() * 3);
    for px in &image.rgba {
        for &c in &px[..3] {
            let v = srgb_encode(tonemap(c * scale));
            data.push((v * 255.0 + 0.5) as u8);
        }
    }
    atomic_write(path, |file| {
        let mut enc = png::Encoder::new(BufWriter::new(file), image.width, image.height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        let mut writer = enc.write_header().map_err(io::Error::other)?;
        writer.write_image_data(&data).map_err(io::Error::other)?;
        writer.finish().map_err(io::Error::other)
    })
}

/// Narkowicz's (2015) fit of the ACES filmic curve: a toe, a shoulder that
/// rolls highlights off instead of clipping them, output in [0, 1]. NaN
/// and negative input map to 0.
pub fn tonemap(x: f32) -> f32 {
    let x = if x.is_nan() { 0.0 } else { x.max(0.0) };
    if x.is_infinite() {
        return 1.0;
    }
    let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(0.0, 1.0)
}

/// The sRGB transfer function (IEC 61966-2-1) on a value in [0, 1].
pub fn srgb_encode(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Runs `write` on a temporary file next to `path`, syncs it and renames
/// it to `path`; on any error the temporary file is removed.
pub(crate) fn atomic_write(
    path: &Path,
    write: impl FnOnce(&File) -> io::Result<()>,
) -> io::Result<()> {
    let tmp = temp_path(path);
    let result = (|| {
        let file = File::create(&tmp)?;
        write(&file)?;
        (&file).flush()?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}
