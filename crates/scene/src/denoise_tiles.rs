//! Denoising a cropped render where the whole image exists: at the merge.
//!
//! The denoiser and the blend weights look at a neighbourhood of each
//! pixel, so a crop denoised alone differs from the full image at its
//! edges. A crop rendered with `--denoise` therefore writes its noisy RGB
//! and, as `denoise_input.*` channels, everything the denoiser reads (the
//! albedo guide, the variance, the two halves of the samples and their
//! counts); the light groups' names go in a header attribute. The merge
//! assembles the tiles, runs the same denoiser and blend on the whole
//! image, and writes the channels a full `--denoise` render writes, inputs
//! dropped: bit for bit the full render, since every input is the same f32.

use std::path::Path;

use cirrus_render::exr_layers::{assemble_tiles, write_channels, ExrChannels};
use cirrus_render::{AovImage, Halves, Image, Layers, Rendered, Window};

use crate::error::{Error, Result};

/// The prefix of the channels a denoised crop leaves for the merge.
pub const INPUT_LAYER: &str = "denoise_input";
/// The header attribute naming a denoised crop's light groups (JSON).
const GROUPS_ATTRIBUTE: &str = "cirrus/denoise_input/light_groups";
const RGB: [&str; 3] = ["R", "G", "B"];

type Channels = Vec<(String, Vec<f32>)>;
type Attributes = Vec<(String, String)>;

/// What a crop rendered for denoising at the merge writes beside its noisy
/// image: the denoiser's inputs as channels and the groups' names.
pub(crate) fn input_channels(r: &Rendered) -> Result<(Channels, Attributes)> {
    let missing = || Error::input("denoise: the render kept no albedo guide or sample halves");
    let aovs = r.aovs.as_ref().ok_or_else(missing)?;
    let halves = r.halves.as_ref().ok_or_else(missing)?;
    let mut channels = Vec::new();
    let variance: Vec<[f32; 3]> = r
        .image
        .variance
        .iter()
        .map(|v| [v[0], v[1], v[2]])
        .collect();
    for (layer, rgb) in [
        ("albedo", &aovs.albedo),
        ("variance", &variance),
        ("half_a", &halves.a),
        ("half_b", &halves.b),
    ] {
        for (c, ch) in RGB.iter().enumerate() {
            let values = rgb.iter().map(|p| p[c]).collect();
            channels.push((format!("{INPUT_LAYER}.{layer}.{ch}"), values));
        }
    }
    for (h, name) in ["even", "odd"].iter().enumerate() {
        // Exact in f32 below 2^24 samples a pixel.
        let counts = halves.samples.iter().map(|s| s[h] as f32).collect();
        channels.push((format!("{INPUT_LAYER}.half_samples.{name}"), counts));
    }
    let groups = r.layers.as_ref().map_or(&[][..], |l| &l.group_names[..]);
    let names = serde_json::to_string(groups).expect("strings serialise");
    Ok((channels, vec![(GROUPS_ATTRIBUTE.into(), names)]))
}

/// Merges crop tiles into `out`; where they carry the denoiser's inputs
/// (crops rendered with `--denoise`), denoises the whole image there.
/// Returns whether it denoised.
pub fn merge_tiles(out: &Path, tiles: &[&Path]) -> Result<bool> {
    let mut merged = assemble_tiles(tiles)?;
    let groups = match merged
        .attributes
        .iter()
        .position(|(k, _)| k == GROUPS_ATTRIBUTE)
    {
        Some(i) => Some(merged.attributes.remove(i).1),
        None => None,
    };
    if let Some(groups) = &groups {
        let groups: Vec<String> = serde_json::from_str(groups).map_err(|e| {
            Error::input(format!(
                "{}: header attribute {GROUPS_ATTRIBUTE}: {e}",
                tiles[0].display()
            ))
        })?;
        denoise_merged(&mut merged, &groups).map_err(|e| e.within(out.display()))?;
    }
    write_channels(
        out,
        merged.full,
        (0, 0),
        merged.full,
        merged.channels,
        merged.attributes,
    )
    .map_err(|e| Error::file(format!("{}: {e}", out.display())))?;
    Ok(groups.is_some())
}

/// Denoises assembled tiles in place: the beauty and light groups become
/// what a full render's denoising makes of them, the inputs are dropped
/// and the `noisy`, `denoised` and `blend.weight` layers added.
fn denoise_merged(merged: &mut ExrChannels, groups: &[String]) -> Result<()> {
    let mut rendered = take_inputs(merged, groups)?;
    crate::denoise::denoise(&mut rendered)?;
    let channels = &mut merged.channels;
    let beauty: Vec<[f32; 3]> = rendered
        .image
        .rgba
        .iter()
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    set_rgb(channels, "", &beauty);
    if let Some(layers) = &rendered.layers {
        for (name, values) in layers.group_names.iter().zip(&layers.groups) {
            set_rgb(channels, name, values);
        }
    }
    let d = rendered.denoised.expect("denoise leaves its layers");
    set_rgb(channels, "noisy", &d.noisy);
    set_rgb(channels, "denoised", &d.plain);
    channels.push(("blend.weight".into(), d.noisy_weight));
    Ok(())
}

/// The render the tiles' channels describe, as far as the denoiser reads
/// it (the beauty, the albedo guide, the variance, the halves and the
/// light groups), the `denoise_input.*` channels taken out of `merged`.
fn take_inputs(merged: &mut ExrChannels, groups: &[String]) -> Result<Rendered> {
    let (width, height) = merged.full;
    let channels = &mut merged.channels;
    let rgba = {
        let [r, g, b, a] = ["R", "G", "B", "A"].map(|n| find(channels, n));
        let [r, g, b, a] = [r?, g?, b?, a?];
        (0..width * height)
            .map(|i| [r[i], g[i], b[i], a[i]])
            .collect()
    };
    let albedo = take_rgb(channels, &format!("{INPUT_LAYER}.albedo"))?;
    let variance = take_rgb(channels, &format!("{INPUT_LAYER}.variance"))?;
    let a = take_rgb(channels, &format!("{INPUT_LAYER}.half_a"))?;
    let b = take_rgb(channels, &format!("{INPUT_LAYER}.half_b"))?;
    let even = take(channels, &format!("{INPUT_LAYER}.half_samples.even"))?;
    let odd = take(channels, &format!("{INPUT_LAYER}.half_samples.odd"))?;
    let samples: Vec<[u32; 2]> = even
        .iter()
        .zip(&odd)
        .map(|(&e, &o)| [e as u32, o as u32])
        .collect();
    let layers = match groups.is_empty() {
        true => None,
        false => Some(Layers {
            group_names: groups.to_vec(),
            groups: groups
                .iter()
                .map(|g| find_rgb(channels, g))
                .collect::<Result<_>>()?,
            ..Default::default()
        }),
    };
    Ok(Rendered {
        image: Image {
            width: width as u32,
            height: height as u32,
            spp: samples.iter().map(|s| s[0] + s[1]).max().unwrap_or(0),
            rgba,
            variance: variance.iter().map(|v| [v[0], v[1], v[2], 0.0]).collect(),
            samples: samples.iter().map(|s| s[0] + s[1]).collect(),
        },
        stats: Default::default(),
        window: Window {
            x0: 0,
            y0: 0,
            full_width: width as u32,
            full_height: height as u32,
        },
        aovs: Some(AovImage {
            albedo,
            ..Default::default()
        }),
        halves: Some(Halves { a, b, samples }),
        denoised: None,
        layers,
    })
}

/// Sets the R, G, B channels of `layer` ("" for the beauty), adding them
/// where they are missing.
fn set_rgb(channels: &mut Channels, layer: &str, values: &[[f32; 3]]) {
    for (c, ch) in RGB.iter().enumerate() {
        let name = match layer {
            "" => ch.to_string(),
            l => format!("{l}.{ch}"),
        };
        let v = values.iter().map(|p| p[c]).collect();
        match channels.iter_mut().find(|(n, _)| *n == name) {
            Some((_, old)) => *old = v,
            None => channels.push((name, v)),
        }
    }
}

fn missing(name: &str) -> Error {
    Error::input(format!(
        "the tiles carry denoiser inputs but no channel {name}"
    ))
}

fn find<'c>(channels: &'c Channels, name: &str) -> Result<&'c [f32]> {
    channels
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| &v[..])
        .ok_or_else(|| missing(name))
}

fn take(channels: &mut Channels, name: &str) -> Result<Vec<f32>> {
    let i = channels
        .iter()
        .position(|(n, _)| n == name)
        .ok_or_else(|| missing(name))?;
    Ok(channels.remove(i).1)
}

fn find_rgb(channels: &Channels, layer: &str) -> Result<Vec<[f32; 3]>> {
    let [r, g, b] = RGB.map(|c| find(channels, &format!("{layer}.{c}")));
    let [r, g, b] = [r?, g?, b?];
    Ok((0..r.len()).map(|i| [r[i], g[i], b[i]]).collect())
}

fn take_rgb(channels: &mut Channels, layer: &str) -> Result<Vec<[f32; 3]>> {
    let [r, g, b] = RGB.map(|c| take(channels, &format!("{layer}.{c}")));
    let [r, g, b] = [r?, g?, b?];
    Ok((0..r.len()).map(|i| [r[i], g[i], b[i]]).collect())
}
