//! EXR files with AOV layers and data windows, and the merge of crop tiles.
//!
//! Layout: one part, 32-bit float channels. `R, G, B, A` are the beauty
//! (as [`write_exr`](crate::image_io::write_exr) writes it) and each AOV is
//! a layer of channels named `layer.channel`, the convention Nuke and
//! Blender read layers by: `albedo.R/G/B`, `depth.Z`, `emission.R/G/B`,
//! `direct.R/G/B`, `samples.Y`. A crop is written at full size with a data
//! window: the display window is the whole image, the data window only the
//! crop (`layer_position` in the exr crate), so compositors place it.
//!
//! [`merge_tiles`] assembles such tiles channel by channel. Every value is
//! copied, never recomputed, so the merge of crops rendered with the same
//! seed is bit for bit the full render (the RNG is keyed by the pixel's
//! index in the full image).

use std::path::Path;

pub use crate::exr_read::{read_channels, ExrChannels};

use crate::film::AovImage;
use crate::render::Rendered;
use cirrus_kernel::{Error, Result};

/// The AOV layers a file can carry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Aov {
    Albedo,
    Depth,
    Emission,
    Direct,
    Samples,
    // Not an AovImage layer: switches on the compositing layers.
    /// One layer per light group (`sun`, `sky`, `emission`, named lights),
    /// summing to the beauty.
    Lights,
    /// Cryptomatte ID mattes per volume and per file.
    Cryptomatte,
}

impl Aov {
    pub const ALL: [Aov; 7] = [
        Aov::Albedo,
        Aov::Depth,
        Aov::Emission,
        Aov::Direct,
        Aov::Samples,
        Aov::Lights,
        Aov::Cryptomatte,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Aov::Albedo => "albedo",
            Aov::Depth => "depth",
            Aov::Emission => "emission",
            Aov::Direct => "direct",
            Aov::Samples => "samples",
            Aov::Lights => "lights",
            Aov::Cryptomatte => "cryptomatte",
        }
    }

    pub fn parse(s: &str) -> Result<Aov> {
        Aov::ALL
            .into_iter()
            .find(|a| a.name() == s.trim())
            .ok_or_else(|| {
                Error::invalid(format!(
                    "unknown AOV {s:?} (known: albedo, depth, emission, direct, samples, \
                     lights, cryptomatte)"
                ))
            })
    }

    /// Channel names and values of this layer over the window's pixels.
    pub fn channels(self, a: &AovImage) -> Vec<(String, Vec<f32>)> {
        let rgb = |layer: &str, v: &[[f32; 3]]| {
            ["R", "G", "B"]
                .iter()
                .enumerate()
                .map(|(c, ch)| (format!("{layer}.{ch}"), v.iter().map(|p| p[c]).collect()))
                .collect::<Vec<_>>()
        };
        match self {
            Aov::Albedo => rgb("albedo", &a.albedo),
            Aov::Emission => rgb("emission", &a.emission),
            Aov::Direct => rgb("direct", &a.direct),
            Aov::Depth => vec![("depth.Z".into(), a.depth.clone())],
            Aov::Samples => vec![("samples.Y".into(), a.samples.clone())],
            // Written from the render's compositing layers instead.
            Aov::Lights | Aov::Cryptomatte => Vec::new(),
        }
    }
}

/// Writes a render as EXR: RGBA plus the requested AOV layers, in a data
/// window when it is a crop. Atomic like every image written here.
pub fn write_exr_layers(path: &Path, r: &Rendered, aovs: &[Aov]) -> std::io::Result<()> {
    write_exr_with(path, r, aovs, Vec::new(), Vec::new())
}

/// [`write_exr_layers`] with `extra` channels after the AOVs (light groups,
/// Cryptomatte) and string attributes for the header.
pub fn write_exr_with(
    path: &Path,
    r: &Rendered,
    aovs: &[Aov],
    extra: Vec<(String, Vec<f32>)>,
    attributes: Vec<(String, String)>,
) -> std::io::Result<()> {
    let img = &r.image;
    let mut channels: Vec<(String, Vec<f32>)> = ["R", "G", "B", "A"]
        .iter()
        .enumerate()
        .map(|(c, n)| (n.to_string(), img.rgba.iter().map(|p| p[c]).collect()))
        .collect();
    if let Some(a) = &r.aovs {
        for aov in aovs {
            channels.extend(aov.channels(a));
        }
    } else if !aovs.is_empty() {
        return Err(std::io::Error::other(
            "AOVs were asked for but the render did not keep them",
        ));
    }
    if let Some(d) = &r.denoised {
        for (layer, rgb) in [("noisy", &d.noisy), ("denoised", &d.plain)] {
            for (c, n) in ["R", "G", "B"].iter().enumerate() {
                channels.push((format!("{layer}.{n}"), rgb.iter().map(|p| p[c]).collect()));
            }
        }
        channels.push(("blend.weight".into(), d.noisy_weight.clone()));
    }
    channels.extend(extra);
    let w = &r.window;
    write_channels(
        path,
        (w.full_width as usize, w.full_height as usize),
        (w.x0 as i32, w.y0 as i32),
        (img.width as usize, img.height as usize),
        channels,
        attributes,
    )
}

/// Writes named f32 channels of a `size` data window at `position` inside
/// a `full` display window, with text `attributes` in the header.
pub fn write_channels(
    path: &Path,
    full: (usize, usize),
    position: (i32, i32),
    size: (usize, usize),
    channels: Vec<(String, Vec<f32>)>,
    attributes: Vec<(String, String)>,
) -> std::io::Result<()> {
    use exr::prelude::*;
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .into_iter()
        .map(|(name, v)| AnyChannel::new(utf8_text(&name), FlatSamples::F32(v)))
        .collect();
    let mut layer_attributes = LayerAttributes {
        layer_position: Vec2(position.0, position.1),
        ..LayerAttributes::default()
    };
    for (name, value) in attributes {
        layer_attributes
            .other
            .insert(utf8_text(&name), AttributeValue::Text(utf8_text(&value)));
    }
    let layer = Layer::new(
        Vec2(size.0, size.1),
        layer_attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    let image = Image::new(
        ImageAttributes::new(IntegerBounds::new(Vec2(0, 0), Vec2(full.0, full.1))),
        layer,
    );
    crate::image_io::atomic_write(path, |file| {
        image
            .write()
            .to_buffered(std::io::BufWriter::new(file))
            .map_err(|e| std::io::Error::other(e.to_string()))
    })
}

/// `s` as EXR text in UTF-8, as OpenEXR's own library writes and reads
/// names (the exr crate's `From<&str>` takes Latin-1 alone and panics on
/// anything else, a light group named in Japanese say). Names are
/// checked for OpenEXR's 255-byte limit where they are made
/// ([`crate::compositing::Compositing::validate`]).
fn utf8_text(s: &str) -> exr::prelude::Text {
    exr::prelude::Text::from_slice_unchecked(s.as_bytes())
}

/// Assembles crop tiles into one full-size EXR. The tiles must share the
/// display window and channel names, lie inside the image, not overlap,
/// and cover it exactly; any violation is an error naming the file.
pub fn merge_tiles(out: &Path, tiles: &[&Path]) -> Result<()> {
    let merged = assemble_tiles(tiles)?;
    write_channels(
        out,
        merged.full,
        (0, 0),
        merged.full,
        merged.channels,
        merged.attributes,
    )
    .map_err(|e| Error::io(out, e))
}

/// The channels of crop tiles copied into place over the whole image (the
/// checks of [`merge_tiles`]), without writing them.
pub fn assemble_tiles(tiles: &[&Path]) -> Result<ExrChannels> {
    let first = tiles
        .first()
        .ok_or_else(|| Error::invalid("no tiles to merge"))?;
    let t0 = read_channels(first)?;
    let (fw, fh) = t0.full;
    let names: Vec<String> = t0.channels.iter().map(|(n, _)| n.clone()).collect();
    let attributes = t0.attributes.clone();
    let mut data: Vec<Vec<f32>> = vec![vec![0.0; fw * fh]; names.len()];
    let mut covered = vec![false; fw * fh];
    for (k, path) in tiles.iter().enumerate() {
        let t = if k == 0 {
            ExrChannels {
                channels: t0.channels.clone(),
                attributes: t0.attributes.clone(),
                ..t0
            }
        } else {
            read_channels(path)?
        };
        let misfit = |message: String| Error::format(path, message);
        if t.full != (fw, fh) {
            return Err(misfit(format!(
                "image is {}x{}, the first tile's is {fw}x{fh}",
                t.full.0, t.full.1
            )));
        }
        let tile_names: Vec<&String> = t.channels.iter().map(|(n, _)| n).collect();
        if tile_names != names.iter().collect::<Vec<_>>() {
            return Err(misfit("channels differ from the first tile's".into()));
        }
        if t.attributes != attributes {
            return Err(misfit(
                "header attributes (the Cryptomatte manifest) differ from the first tile's".into(),
            ));
        }
        let (x0, y0) = t.position;
        let (w, h) = t.size;
        if x0 < 0 || y0 < 0 || x0 as usize + w > fw || y0 as usize + h > fh {
            return Err(misfit("data window lies outside the image".into()));
        }
        let (x0, y0) = (x0 as usize, y0 as usize);
        for y in 0..h {
            for x in 0..w {
                let i = (y0 + y) * fw + x0 + x;
                if covered[i] {
                    return Err(misfit(format!(
                        "pixel ({}, {}) is in two tiles",
                        x0 + x,
                        y0 + y
                    )));
                }
                covered[i] = true;
            }
        }
        for (c, (_, v)) in t.channels.iter().enumerate() {
            for y in 0..h {
                let dst = (y0 + y) * fw + x0;
                data[c][dst..dst + w].copy_from_slice(&v[y * w..(y + 1) * w]);
            }
        }
    }
    if let Some(i) = covered.iter().position(|c| !c) {
        return Err(Error::invalid(format!(
            "the tiles leave pixel ({}, {}) uncovered",
            i % fw,
            i / fw
        )));
    }
    Ok(ExrChannels {
        full: (fw, fh),
        position: (0, 0),
        size: (fw, fh),
        channels: names.into_iter().zip(data).collect(),
        attributes,
    })
}
