//! Where a render goes: the EXR (with AOV layers and a crop's data
//! window), the PNG preview and the statistics, each written whole or not
//! at all.

use std::path::{Path, PathBuf};

use cirrus_render::exr_layers::{write_exr_with, Aov};
use cirrus_render::image_io::write_png;
use cirrus_render::{Crop, Rendered};

use crate::description::SceneDescription;
use crate::error::{Error, Result};

/// The resolved `[output]` table.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Outputs {
    /// `None` leaves the image to the caller (the bindings return it).
    pub exr: Option<PathBuf>,
    pub png: Option<PathBuf>,
    /// Of the PNG preview, in stops.
    pub exposure: f32,
    pub stats: Option<PathBuf>,
    pub aovs: Vec<Aov>,
    pub crop: Option<Crop>,
    pub light_groups: bool,
    pub cryptomatte: bool,
    pub deep: Option<PathBuf>,
    pub deep_samples: u32,
    /// A crop of a denoised render: its EXR keeps the denoiser's inputs
    /// for `cirrus merge`, which denoises the whole image.
    pub denoise_at_merge: bool,
    /// Each volume's Cryptomatte name and asset, by its index in the scene.
    pub object_names: Vec<String>,
    pub asset_names: Vec<String>,
}

impl Outputs {
    pub fn resolve(desc: &SceneDescription) -> Outputs {
        let o = &desc.output;
        let aovs = o.aov.clone().unwrap_or_default();
        Outputs {
            light_groups: o.light_groups() || aovs.contains(&Aov::Lights),
            cryptomatte: o.cryptomatte() || aovs.contains(&Aov::Cryptomatte),
            deep: o.deep.clone(),
            deep_samples: o.deep_samples(),
            denoise_at_merge: desc.render.denoise.unwrap_or(false) && o.crop.is_some(),
            // A clash of names is refused before rendering (Scene::render).
            object_names: crate::compositing::instance_names(desc).unwrap_or_default(),
            asset_names: crate::compositing::asset_names(desc),
            // `-o NAME.png` alone is a PNG-only render.
            exr: o
                .output
                .clone()
                .filter(|p| o.png.is_some() || !has_extension(p, "png")),
            png: o
                .png
                .clone()
                .or_else(|| o.output.clone().filter(|p| has_extension(p, "png"))),
            exposure: o.exposure(),
            stats: o.stats.clone(),
            aovs: o.aov.clone().unwrap_or_default(),
            crop: o.crop.map(|[x0, y0, x1, y1]| Crop { x0, y0, x1, y1 }),
        }
    }

    /// The compositing layers these outputs need the render to keep.
    pub(crate) fn layer_request(&self) -> crate::compositing::LayerRequest {
        crate::compositing::LayerRequest {
            light_groups: self.light_groups,
            cryptomatte: self.cryptomatte,
            deep_samples: self.deep.as_ref().map(|_| self.deep_samples),
        }
    }

    /// Refuses a file whose extension names another format than the one
    /// it would be written in: the format is told by the extension.
    pub fn check(&self) -> Result<()> {
        if let Some(p) = &self.exr {
            if !has_extension(p, "exr") {
                let why = match has_extension(p, "png") {
                    true => "-o names a PNG and --png another: give the PNG once",
                    false => "-o writes OpenEXR (.exr) or PNG (.png), told by the extension; name the file .exr or .png",
                };
                return Err(Error::input(format!("{}: {why}", p.display())));
            }
        }
        for (path, flag, ext, format) in [
            (&self.png, "--png", "png", "PNG"),
            (&self.deep, "--deep", "exr", "deep OpenEXR"),
        ] {
            if let Some(p) = path.as_ref().filter(|p| !has_extension(p, ext)) {
                return Err(Error::input(format!(
                    "{}: {flag} writes {format}; name the file .{ext}",
                    p.display()
                )));
            }
        }
        Ok(())
    }

    /// The files [`Outputs::write`] writes, in the order it writes them.
    pub fn files(&self) -> Vec<&Path> {
        [&self.deep, &self.exr, &self.png, &self.stats]
            .into_iter()
            .flatten()
            .map(|p| p.as_path())
            .collect()
    }

    /// Writes every output that is set.
    pub fn write(&self, rendered: &Rendered) -> Result<()> {
        let file_err = |p: &Path, e: std::io::Error| Error::file(format!("{}: {e}", p.display()));
        // The deep file first: an existing EXR marks a finished frame.
        if let Some(deep) = &self.deep {
            crate::compositing::write_deep(deep, rendered)?;
        }
        if let Some(exr) = &self.exr {
            let aovs = crate::compositing::written_aovs(&self.aovs, rendered.layers.as_ref());
            let names = [&self.object_names[..], &self.asset_names[..]];
            let (mut extra, mut attributes) = crate::compositing::layer_channels(rendered, names);
            if self.denoise_at_merge {
                let (inputs, groups) = crate::denoise_tiles::input_channels(rendered)?;
                extra.extend(inputs);
                attributes.extend(groups);
            }
            write_exr_with(exr, rendered, &aovs, extra, attributes)
                .map_err(|e| file_err(exr, e))?;
        }
        if let Some(png) = &self.png {
            write_png(png, &rendered.image, self.exposure).map_err(|e| file_err(png, e))?;
        }
        if let Some(path) = &self.stats {
            write_whole(path, rendered.stats.to_json().as_bytes())
                .map_err(|e| Error::file(e.to_string()))?;
        }
        Ok(())
    }
}

/// Whether `path` ends in `.ext`, in any case.
pub fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Writes a file whole or not at all: a temporary beside it, then a rename.
pub fn write_whole(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("out");
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = std::fs::write(&tmp, bytes).and_then(|_| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", path.display())))
}
