//! What is previewed and how one pass of it is rendered.
//!
//! A volume file or a scene file is a [`Scene`]; every pass renders it
//! through the scene library's one road ([`Scene::render_cached`]) with the
//! view's overrides, and a [`VolumeCache`] keeps the files and grids read
//! by the first pass for the next ones. So the preview renders exactly
//! what `cirrus render` renders for the same flags, `--device` included:
//! a pass goes to the [`RenderTarget`] its device names (opened once,
//! when first asked for), and a GPU pass is folded into the same
//! accumulation as a CPU pass would be (the GPU keys its random numbers
//! by seed, pixel and sample too, so passes with distinct seeds are
//! independent).

use std::path::Path;
use std::sync::Arc;

use cirrus_render::exr_layers::Aov;
use cirrus_render::{RenderControl, Rendered};
use cirrus_scene::description::SceneDescription;
use cirrus_scene::{Device, Overrides, RenderTarget, Result, Scene, VolumeCache};
use glam::Vec3;

use crate::view::{sun_angles, CameraView, Lighting, Mode, SunView, View};

/// Renders one pass: the overrides carry the view, resolution, spp and
/// seed.
pub trait Renderer {
    fn render(&mut self, o: &Overrides, control: Arc<RenderControl>) -> Result<Rendered>;
}

/// An opened input with what the page starts from.
pub struct Source {
    /// "volume" or "scene".
    pub kind: &'static str,
    pub renderer: SceneRenderer,
    pub view: View,
    pub lighting: Lighting,
    pub base_res: (u32, u32),
}

impl Source {
    /// Opens `path` (its volumes are read here, so errors show before the
    /// server starts); `res` overrides the scene's resolution, `device`
    /// the scene's `[render] device` (whose GPU is opened here too, so a
    /// missing Vulkan driver is said before the server starts).
    pub fn open(path: &Path, res: Option<(u32, u32)>, device: Option<Device>) -> Result<Source> {
        let mut scene = Scene::load(path)?;
        scene.apply(&Overrides {
            res,
            device,
            ..Default::default()
        });
        let device = scene.settings()?.device;
        let target = RenderTarget::open(device)?;
        let desc = scene.description().clone();
        let base_res = desc.camera.res();
        let lighting = lighting(&desc);
        let mut view = initial_view(&desc);
        view.device = device;
        let mut cache = VolumeCache::default();
        {
            // The library's own camera (framed when none is given) and
            // medium, brought to world space.
            let prepared = scene.prepare(&mut cache, None)?;
            let c = &prepared.scene.camera;
            let world = |p: Vec3| (p.as_dvec3() + prepared.centre).to_array();
            let (from, to) = match (desc.camera.camera_from, desc.camera.camera_to) {
                (Some(from), Some(to)) => (from, to),
                _ => (world(c.from()), world(c.to())),
            };
            view.camera = CameraView {
                from,
                to,
                up: c.up().to_array(),
                fov: c.vfov_degrees(),
            };
            if let [m] = prepared.scene.media.instances() {
                view.density_scale = Some(m.density_scale);
                view.albedo = Some(m.albedo.x);
                view.g = Some(desc.volumes[0].g());
            }
        }
        let scene_file = path.extension().is_some_and(|e| e == "toml");
        let volume = !scene_file && !cirrus_scene::usd::is_usd(path);
        Ok(Source {
            kind: if volume { "volume" } else { "scene" },
            renderer: SceneRenderer {
                base: scene,
                cache,
                aovs: false,
                targets: vec![(device, target)],
            },
            view,
            lighting,
            base_res,
        })
    }
}

/// The view a description starts from (camera filled in by the caller).
fn initial_view(desc: &SceneDescription) -> View {
    let c = &desc.camera;
    let sun = desc.sun.clone().unwrap_or_default();
    let (azimuth, elevation) = sun_angles(Vec3::from_array(sun.sun_dir()));
    View {
        camera: CameraView {
            from: [0.0, 0.0, 1.0],
            to: [0.0; 3],
            up: c.camera_up(),
            fov: c.fov(),
        },
        sun: SunView {
            enabled: sun.sun(),
            azimuth,
            elevation,
            intensity: 1.0,
        },
        sky: 1.0,
        density_scale: None,
        albedo: None,
        g: None,
        exposure: desc.output.exposure(),
        integrator: Mode::Auto,
        device: Device::Cpu,
        interactive: false,
        denoise: false,
        viewport: None,
    }
}

/// The scene's own sun and sky, which the sliders scale.
fn lighting(desc: &SceneDescription) -> Lighting {
    let sun = desc.sun.clone().unwrap_or_default();
    let env = desc.environment.clone().unwrap_or_default();
    Lighting {
        sun_irradiance: Vec3::from_array(sun.sun_irradiance()),
        sky_radiance: env
            .env_map
            .is_none()
            .then(|| Vec3::from_array(env.env_radiance())),
        sky_map_intensity: env.env_intensity(),
    }
}

/// A scene rendered per pass with the view's overrides, its volumes read
/// once.
pub struct SceneRenderer {
    pub base: Scene,
    cache: VolumeCache,
    /// Keep the albedo AOV (it guides the denoiser) where the CPU renders.
    pub aovs: bool,
    /// The devices opened so far, each once.
    targets: Vec<(Device, RenderTarget)>,
}

impl SceneRenderer {
    /// Where `device` renders (its index in `targets`), opened the first
    /// time it is asked for.
    fn target(&mut self, device: Device) -> Result<usize> {
        if let Some(i) = self.targets.iter().position(|(d, _)| *d == device) {
            return Ok(i);
        }
        self.targets.push((device, RenderTarget::open(device)?));
        Ok(self.targets.len() - 1)
    }
}

impl Renderer for SceneRenderer {
    fn render(&mut self, o: &Overrides, control: Arc<RenderControl>) -> Result<Rendered> {
        let mut scene = self.base.clone();
        scene.apply(o);
        let device = scene.settings()?.device;
        // The GPU renders no AOVs: its passes are denoised unguided, as a
        // pass without the albedo is (`Accumulation::add`).
        let i = self.target(device)?;
        let target = &self.targets[i].1;
        if self.aovs && !target.is_gpu() {
            scene.apply(&Overrides {
                aov: Some(vec![Aov::Albedo]),
                ..Default::default()
            });
        }
        target.render_cached(&scene, &mut self.cache, Some(control))
    }
}
