//! A scene's compositing outputs: which layers the render keeps (light
//! groups, Cryptomatte, deep samples, a depth holdout), the volumes' names
//! the ID mattes are keyed by, and how the layers are written.

use std::path::Path;
use std::sync::Arc;

use cirrus_deep_exr::DeepImage;
use cirrus_render::compositing::{cryptomatte, DEFAULT_FAR};
use cirrus_render::exr_layers::Aov;
use cirrus_render::{DepthHoldout, IntegratorKind, Layers, RenderSettings, Rendered};

use crate::description::SceneDescription;
use crate::error::{Error, Result};

/// Cryptomatte layer of the volume instances' names.
pub const OBJECT_LAYER: &str = "CryptoObject";
/// Cryptomatte layer of the volumes' files.
pub const ASSET_LAYER: &str = "CryptoAsset";

/// Layer names the EXR already uses: a light group may not take one.
const RESERVED: [&str; 10] = [
    "albedo",
    "depth",
    "direct",
    "samples",
    "noisy",
    "denoised",
    "blend",
    crate::denoise_tiles::INPUT_LAYER,
    OBJECT_LAYER,
    ASSET_LAYER,
];

/// Each volume's name: its `name`, else its file's stem, with `_2`, `_3`
/// ... added to make it unique. Two volumes given the same name are an
/// error naming it.
pub fn instance_names(desc: &SceneDescription) -> Result<Vec<String>> {
    let mut names: Vec<String> = Vec::with_capacity(desc.volumes.len());
    for v in &desc.volumes {
        if let Some(n) = &v.name {
            if names.contains(n) {
                return Err(Error::input(format!("two volumes are named {n:?}")));
            }
            check_name(n)?;
            names.push(n.clone());
        } else {
            names.push(String::new());
        }
    }
    for (i, v) in desc.volumes.iter().enumerate() {
        if v.name.is_some() {
            continue;
        }
        let stem = file_stem(&v.file);
        let mut candidate = stem.clone();
        let mut k = 2;
        while names.contains(&candidate) {
            candidate = format!("{stem}_{k}");
            k += 1;
        }
        names[i] = candidate;
    }
    Ok(names)
}

/// Each volume's asset: its file's name (two instances of one file are
/// one asset).
pub fn asset_names(desc: &SceneDescription) -> Vec<String> {
    desc.volumes
        .iter()
        .map(|v| {
            v.file
                .file_name()
                .map_or("volume".into(), |n| ascii(&n.to_string_lossy()))
        })
        .collect()
}

fn file_stem(path: &Path) -> String {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
    let name = name.unwrap_or_else(|| "volume".into());
    // `cloud.0001.vdb` and `cloud.vdb` both give `cloud`.
    ascii(
        name.split('.')
            .next()
            .filter(|s| !s.is_empty())
            .unwrap_or("volume"),
    )
}

/// Names go into EXR text attributes: printable ASCII only.
fn ascii(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_graphic() || c == ' ' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

fn check_name(n: &str) -> Result<()> {
    if n.is_empty() || !n.chars().all(|c| c.is_ascii_graphic() || c == ' ') {
        return Err(Error::input(format!(
            "volume name {n:?}: printable ASCII, not empty"
        )));
    }
    Ok(())
}

/// The compositing layers a scene's outputs ask the render to keep.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct LayerRequest {
    pub light_groups: bool,
    pub cryptomatte: bool,
    /// Samples per deep pixel, when a deep file is written.
    pub deep_samples: Option<u32>,
}

/// Sets the compositing layers `asked` and reads the depth holdout, if
/// any, for a camera of `res`. Refuses what the integrator cannot give and
/// light-group names that clash with other layers.
pub(crate) fn configure(
    settings: &mut RenderSettings,
    asked: LayerRequest,
    desc: &SceneDescription,
    res: (u32, u32),
) -> Result<()> {
    let c = &mut settings.compositing;
    if asked.light_groups {
        c.light_groups = crate::lights::light_group_names(desc)?;
    }
    c.cryptomatte = asked.cryptomatte;
    c.deep_samples = asked.deep_samples;
    let needs_paths = c.cryptomatte || c.deep_samples.is_some();
    if needs_paths && settings.integrator != IntegratorKind::Path {
        return Err(Error::input(format!(
            "Cryptomatte and deep output come from the path tracer's camera paths; \
             --integrator {} cannot give them",
            settings.integrator.name()
        )));
    }
    check_group_names(&settings.compositing.light_groups)?;
    if let Some(spec) = &desc.render.holdout_depth {
        let (file, channel) = crate::parse::split_depth_spec(spec);
        if !file.exists() {
            return Err(Error::file(format!(
                "{}: holdout depth image not found",
                file.display()
            )));
        }
        let far = desc.render.holdout_far.unwrap_or(DEFAULT_FAR);
        let depth = DepthHoldout::read(&file, channel.as_deref(), far, res)?;
        settings.compositing.holdout_depth = Some(Arc::new(depth));
    }
    Ok(settings.compositing.validate()?)
}

/// A light group may not take a layer name the EXR already uses (the
/// `emission` group is the emission AOV itself, so that one is shared).
pub fn check_group_names(groups: &[String]) -> Result<()> {
    for g in groups {
        if RESERVED.contains(&g.as_str()) || ["R", "G", "B", "A"].contains(&g.as_str()) {
            return Err(Error::input(format!(
                "light group {g:?} clashes with the {g} layer of the EXR; rename the group"
            )));
        }
    }
    Ok(())
}

/// The AOVs written as AOV layers: without the two that only switch
/// layers on, and without `emission` when the `emission` light group
/// (the same estimate) is written.
pub(crate) fn written_aovs(aovs: &[Aov], layers: Option<&Layers>) -> Vec<Aov> {
    let group_emission = layers.is_some_and(|l| l.group_names.iter().any(|g| g == "emission"));
    aovs.iter()
        .copied()
        .filter(|a| !matches!(a, Aov::Lights | Aov::Cryptomatte))
        .filter(|a| !(group_emission && *a == Aov::Emission))
        .collect()
}

/// Named f32 channels of an EXR layer set.
type Channels = Vec<(String, Vec<f32>)>;
/// Header text attributes, by name.
type Attributes = Vec<(String, String)>;

/// The light-group and Cryptomatte channels of a render, with the
/// Cryptomatte header attributes; `names` are the volumes' object and
/// asset names, by their index in the scene.
pub(crate) fn layer_channels(r: &Rendered, names: [&[String]; 2]) -> (Channels, Attributes) {
    let (mut channels, mut attributes) = (Vec::new(), Vec::new());
    let Some(layers) = &r.layers else {
        return (channels, attributes);
    };
    for (name, values) in layers.group_names.iter().zip(&layers.groups) {
        for (c, ch) in ["R", "G", "B"].iter().enumerate() {
            channels.push((
                format!("{name}.{ch}"),
                values.iter().map(|p| p[c]).collect(),
            ));
        }
    }
    if !layers.coverage.is_empty() {
        let [objects, assets] = names;
        channels.extend(cryptomatte::channels(
            OBJECT_LAYER,
            &layers.coverage,
            objects,
        ));
        channels.extend(cryptomatte::channels(ASSET_LAYER, &layers.coverage, assets));
        attributes.extend(cryptomatte::header(
            OBJECT_LAYER,
            objects.iter().map(|s| s.as_str()),
        ));
        attributes.extend(cryptomatte::header(
            ASSET_LAYER,
            assets.iter().map(|s| s.as_str()),
        ));
    }
    (channels, attributes)
}

/// Writes a render's deep samples as a deep scanline EXR (`Z`, `ZBack`,
/// `R`, `G`, `B`, `A`), in the crop's data window.
pub(crate) fn write_deep(path: &Path, r: &Rendered) -> Result<()> {
    let layers = r
        .layers
        .as_ref()
        .filter(|l| !l.deep.is_empty())
        .ok_or_else(|| {
            Error::input(format!(
                "{}: the render kept no deep samples",
                path.display()
            ))
        })?;
    let w = &r.window;
    let mut image = DeepImage::new(
        (w.full_width, w.full_height),
        (w.x0, w.y0),
        (r.image.width, r.image.height),
        &["R", "G", "B", "A", "Z", "ZBack"],
    );
    // Channels are stored sorted: A, B, G, R, Z, ZBack.
    for pixel in &layers.deep {
        let samples: Vec<Vec<f32>> = pixel
            .iter()
            .map(|s| vec![s.alpha, s.rgb[2], s.rgb[1], s.rgb[0], s.z, s.z_back])
            .collect();
        image.push_pixel(&samples);
    }
    cirrus_deep_exr::write(path, &image).map_err(|e| Error::file(e.to_string()))
}

/// Replaces coverage indices of the instances rendered by the indices of
/// their volumes in the scene (`kept[i]` is instance `i`'s volume).
pub(crate) fn renumber_instances(r: &mut Rendered, kept: &[usize]) {
    if let Some(layers) = r.layers.as_mut() {
        for pixel in &mut layers.coverage {
            for (inst, _) in pixel.iter_mut() {
                *inst = kept.get(*inst as usize).map_or(*inst, |&v| v as u32);
            }
        }
    }
}

/// After denoising the beauty: each light group is denoised with the same
/// albedo guide by `denoise`, then scaled per pixel and channel so the
/// groups sum to the plain denoised beauty `plain` (the denoiser is not
/// linear, so the groups denoised alone would not), then blended with its
/// noisy self by the beauty's weights, so the groups sum to the blended
/// beauty `w * noisy + (1 - w) * plain` as the noisy groups summed to the
/// noisy beauty. A pixel whose denoised groups are all zero keeps the
/// noisy groups' proportions.
pub(crate) fn denoise_groups(
    r: &mut Rendered,
    plain: &[[f32; 3]],
    noisy_weight: &[f32],
    mut denoise: impl FnMut(&[[f32; 3]]) -> Result<Vec<[f32; 3]>>,
) -> Result<()> {
    let Some(layers) = r.layers.as_mut() else {
        return Ok(());
    };
    let clean: Vec<Vec<[f32; 3]>> = layers
        .groups
        .iter()
        .map(|g| denoise(g))
        .collect::<Result<_>>()?;
    let n = layers.groups.len().max(1) as f32;
    for (i, (beauty, &w)) in plain.iter().zip(noisy_weight).enumerate() {
        for c in 0..3 {
            let weights: Vec<f32> = clean.iter().map(|g| g[i][c].max(0.0)).collect();
            let noisy: Vec<f32> = layers.groups.iter().map(|g| g[i][c]).collect();
            let (shares, total) = match weights.iter().sum::<f32>() {
                s if s > 0.0 => (weights, s),
                _ => {
                    let kept: Vec<f32> = noisy.iter().map(|v| v.max(0.0)).collect();
                    let s = kept.iter().sum::<f32>();
                    (kept, s)
                }
            };
            for ((g, share), noisy) in layers.groups.iter_mut().zip(&shares).zip(&noisy) {
                let denoised = if total > 0.0 {
                    beauty[c] * (share / total)
                } else {
                    beauty[c] / n
                };
                g[i][c] = w * noisy + (1.0 - w) * denoised;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_come_from_files_made_unique_and_clashes_are_refused() {
        let d = SceneDescription::parse(
            "[[volume]]\nfile = \"a/cloud.0001.vdb\"\n[[volume]]\nfile = \"b/cloud.vdb\"\n\
             [[volume]]\nfile = \"c.vdb\"\nname = \"cloud_2\"\n[[volume]]\nfile = \"fire.vdb\"\n",
        )
        .unwrap();
        assert_eq!(
            instance_names(&d).unwrap(),
            ["cloud", "cloud_3", "cloud_2", "fire"]
        );
        assert_eq!(
            asset_names(&d),
            ["cloud.0001.vdb", "cloud.vdb", "c.vdb", "fire.vdb"]
        );
        let d = SceneDescription::parse(
            "[[volume]]\nfile = \"a.vdb\"\nname = \"x\"\n[[volume]]\nfile = \"b.vdb\"\nname = \"x\"\n",
        )
        .unwrap();
        let e = instance_names(&d).unwrap_err().to_string();
        assert!(e.contains("\"x\""), "{e}");
    }

    #[test]
    fn light_groups_may_not_take_another_layers_name() {
        for bad in ["albedo", "CryptoObject", "A"] {
            let e = check_group_names(&[bad.to_string()])
                .unwrap_err()
                .to_string();
            assert!(e.contains(bad) && e.contains("clashes"), "{e}");
        }
        assert!(check_group_names(&["sun".into(), "emission".into()]).is_ok());
        let twice = cirrus_render::Compositing {
            light_groups: vec!["key".into(), "key".into()],
            ..Default::default()
        };
        assert!(twice
            .validate()
            .unwrap_err()
            .to_string()
            .contains("\"key\" is named twice"));
    }
}
