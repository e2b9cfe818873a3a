//! Where a render runs: the `device` setting (`[render] device`,
//! `cirrus render --device`, Python's `render(..., device=)`), and the
//! device a render was sent to ([`RenderTarget`]), which renders a scene
//! there (the GPU backend, `cirrus-gpu`, refuses by name what it does not
//! render).

use cirrus_gpu::{Gpu, GpuError};
use std::sync::Arc;

use cirrus_render::{RenderControl, Rendered};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::plan::VolumeCache;
use crate::scene::Scene;

/// Where a render runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Device {
    /// The CPU, always (the default): touches no GPU.
    #[default]
    #[serde(rename = "cpu")]
    #[cfg_attr(feature = "clap", value(name = "cpu"))]
    Cpu,
    /// A hardware GPU where there is one, else the CPU; a scene the GPU
    /// does not render goes to the CPU, saying why.
    #[serde(rename = "auto")]
    #[cfg_attr(feature = "clap", value(name = "auto"))]
    Auto,
    /// A GPU adapter, a software one (lavapipe) included; an error when
    /// there is none or when it does not render the scene.
    #[serde(rename = "gpu")]
    #[cfg_attr(feature = "clap", value(name = "gpu"))]
    Gpu,
}

impl Device {
    /// The value's name, as scene files, flags and reports spell it.
    pub fn name(self) -> &'static str {
        match self {
            Device::Cpu => "cpu",
            Device::Auto => "auto",
            Device::Gpu => "gpu",
        }
    }
}

/// Where renders run: the CPU, or an open GPU.
pub enum RenderTarget {
    Cpu,
    Gpu(Box<Gpu>, Device),
}

impl RenderTarget {
    /// Opens what `device` asks for: `cpu` touches no GPU; `gpu` takes any
    /// Vulkan adapter (lavapipe included) or fails saying what to
    /// install; `auto` takes a hardware GPU, else the CPU. Says which on
    /// stderr.
    pub fn open(device: Device) -> Result<RenderTarget> {
        match device {
            Device::Cpu => Ok(RenderTarget::Cpu),
            Device::Gpu | Device::Auto => match cirrus_gpu::open(device == Device::Gpu) {
                Ok(gpu) => {
                    eprintln!("cirrus: rendering on the GPU: {}", gpu.describe());
                    Ok(RenderTarget::Gpu(Box::new(gpu), device))
                }
                Err(GpuError::NoAdapter(why)) if device == Device::Auto => {
                    eprintln!("cirrus: no hardware GPU ({why}): rendering on the CPU");
                    Ok(RenderTarget::Cpu)
                }
                Err(e) => Err(Error::input(e.to_string())),
            },
        }
    }

    /// Whether renders go to a GPU (under `auto`, one in hardware).
    pub fn is_gpu(&self) -> bool {
        matches!(self, RenderTarget::Gpu(..))
    }

    /// Renders `scene` here. Under `auto`, a scene the GPU does not render
    /// goes to the CPU, saying why; under `gpu` it is an error naming what.
    pub fn render(&self, scene: &Scene) -> Result<Rendered> {
        self.render_cached(scene, &mut VolumeCache::default(), None)
    }

    /// [`RenderTarget::render`] with the volumes read through `cache` (kept
    /// for the next render, as [`Scene::render_cached`] does). `control`
    /// watches and stops a CPU render; a GPU render is not stopped midway
    /// (a cancelled one is reported as such once it returns).
    pub fn render_cached(
        &self,
        scene: &Scene,
        cache: &mut VolumeCache,
        control: Option<Arc<RenderControl>>,
    ) -> Result<Rendered> {
        let (gpu, device) = match self {
            RenderTarget::Cpu => return scene.render_cached(cache, control),
            RenderTarget::Gpu(gpu, device) => (gpu, *device),
        };
        let prepared = scene.prepare(cache, control.clone())?;
        if scene.warn_on_stderr {
            for w in &prepared.warnings {
                eprintln!("cirrus: warning: {w}");
            }
        }
        match cirrus_gpu::render(gpu, &prepared.scene, &prepared.settings) {
            Ok(mut rendered) => {
                if let Some(means) = cirrus_gpu::substitutions(&prepared.scene, &prepared.settings)
                {
                    if scene.warn_on_stderr {
                        eprintln!("cirrus: the GPU estimates the same image with {means}");
                    }
                }
                let s = &mut rendered.stats;
                s.device = format!("gpu: {}", gpu.describe());
                s.bytes_read = prepared.bytes_read;
                s.grids_loaded = prepared.grids_loaded;
                s.volumes_culled = prepared.culled;
                s.load_seconds = prepared.load_seconds;
                if control.as_ref().is_some_and(|c| c.is_cancelled()) {
                    return Err(Error::cancelled());
                }
                Scene::refuse_all_dropped(&rendered)?;
                Ok(rendered)
            }
            Err(GpuError::Unsupported(what)) if device == Device::Auto => {
                // Said where it is seen: on stderr for the command line,
                // with the render's warnings for Python, Blender and farms.
                let why = format!(
                    "the GPU does not render {} yet: rendered on the CPU",
                    what.join(", ")
                );
                if scene.warn_on_stderr {
                    eprintln!("cirrus: {why}");
                }
                drop(prepared);
                let mut rendered = scene.render_cached(cache, control)?;
                rendered.stats.warnings.push(why);
                Ok(rendered)
            }
            Err(e) => Err(Error::input(e.to_string())),
        }
    }
}
