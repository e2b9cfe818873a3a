//! `cirrus render --device cpu|auto|gpu`: where a render runs, said on
//! stderr, and the GPU backend's render of a scene (`cirrus-gpu`), which
//! refuses by name what it does not render.

use cirrus_gpu::{DeviceChoice, Gpu, GpuError};
use cirrus_render::Rendered;
use cirrus_scene::{Scene, VolumeCache};

/// Parses `--device`.
pub fn parse_device(s: &str) -> Result<DeviceChoice, String> {
    DeviceChoice::from_name(s).ok_or_else(|| {
        format!(
            "unknown device {s:?}: one of {}",
            DeviceChoice::NAMES.join(", ")
        )
    })
}

/// Where renders run: the CPU, or an open GPU.
pub enum Target {
    Cpu,
    Gpu(Box<Gpu>, DeviceChoice),
}

impl Target {
    /// Opens what `choice` asks for: `cpu` touches no GPU; `gpu` takes any
    /// Vulkan adapter (lavapipe included) or fails saying what to
    /// install; `auto` takes a hardware GPU, else the CPU. Says which on
    /// stderr.
    pub fn open(choice: DeviceChoice) -> Result<Target, GpuError> {
        match choice {
            DeviceChoice::Cpu => Ok(Target::Cpu),
            DeviceChoice::Gpu | DeviceChoice::Auto => {
                match cirrus_gpu::open(choice == DeviceChoice::Gpu) {
                    Ok(gpu) => {
                        eprintln!("cirrus: rendering on the GPU: {}", gpu.describe());
                        Ok(Target::Gpu(Box::new(gpu), choice))
                    }
                    Err(GpuError::NoAdapter(why)) if choice == DeviceChoice::Auto => {
                        eprintln!("cirrus: no hardware GPU ({why}): rendering on the CPU");
                        Ok(Target::Cpu)
                    }
                    Err(e) => Err(e),
                }
            }
        }
    }

    /// Renders `scene` here. Under `auto`, a scene the GPU does not render
    /// goes to the CPU, saying why; under `gpu` it is an error naming what.
    pub fn render(&self, scene: &Scene) -> Result<Rendered, Box<dyn std::error::Error>> {
        let (gpu, choice) = match self {
            Target::Cpu => return Ok(scene.render()?),
            Target::Gpu(gpu, choice) => (gpu, *choice),
        };
        let mut cache = VolumeCache::default();
        let prepared = scene.prepare(&mut cache, None)?;
        if scene.warn_on_stderr {
            for w in &prepared.warnings {
                eprintln!("cirrus: warning: {w}");
            }
        }
        match cirrus_gpu::render(gpu, &prepared.scene, &prepared.settings) {
            Ok(mut rendered) => {
                if let Some(means) = cirrus_gpu::substitutions(&prepared.settings) {
                    eprintln!("cirrus: the GPU estimates the same image with {means}");
                }
                let s = &mut rendered.stats;
                s.bytes_read = prepared.bytes_read;
                s.grids_loaded = prepared.grids_loaded;
                s.volumes_culled = prepared.culled;
                s.load_seconds = prepared.load_seconds;
                Scene::refuse_all_dropped(&rendered)?;
                Ok(rendered)
            }
            Err(GpuError::Unsupported(what)) if choice == DeviceChoice::Auto => {
                eprintln!(
                    "cirrus: the GPU does not render {} yet: rendering on the CPU",
                    what.join(", ")
                );
                drop(prepared);
                Ok(scene.render()?)
            }
            Err(e) => Err(e.into()),
        }
    }
}
