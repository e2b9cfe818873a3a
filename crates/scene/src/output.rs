//! Where a render goes: the EXR (with AOV layers and a crop's data
//! window), the PNG preview and the statistics, each written whole or not
//! at all.

use std::path::{Path, PathBuf};

use cirrus_render::exr_layers::{write_exr_layers, Aov};
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
}

impl Outputs {
    pub fn resolve(desc: &SceneDescription) -> Outputs {
        let o = &desc.output;
        Outputs {
            exr: o.output.clone(),
            png: o.png.clone(),
            exposure: o.exposure(),
            stats: o.stats.clone(),
            aovs: o.aov.clone().unwrap_or_default(),
            crop: o.crop.map(|[x0, y0, x1, y1]| Crop { x0, y0, x1, y1 }),
        }
    }

    /// Writes every output that is set.
    pub fn write(&self, rendered: &Rendered) -> Result<()> {
        let file_err = |p: &Path, e: std::io::Error| Error::file(format!("{}: {e}", p.display()));
        if let Some(exr) = &self.exr {
            write_exr_layers(exr, rendered, &self.aovs).map_err(|e| file_err(exr, e))?;
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
