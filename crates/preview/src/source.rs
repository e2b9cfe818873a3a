//! What is previewed and how one pass of it is rendered.
//!
//! A lone volume is read once: its render scene is prepared once and each
//! pass only rewrites the camera, lights and medium parameters. A scene
//! file is rendered through [`Scene::render_with`] with the view's
//! overrides, which reads its files again per pass (the scene library has
//! no way yet to keep several placed volumes loaded).

use std::path::Path;
use std::sync::Arc;

use cirrus_render::medium::{BrickField, Extinction};
use cirrus_render::{render, Camera, Phase, RenderControl, Rendered};
use cirrus_scene::description::SceneDescription;
use cirrus_scene::{defaults as d, Error, LoneVolume, Overrides, Result, Scene};
use glam::{DMat4, DVec3, Vec3};

use crate::view::{sun_angles, CameraView, Lighting, Mode, SunView, View};

/// Renders one pass: the overrides carry the view, resolution, spp and
/// seed.
pub trait Renderer {
    fn render(&mut self, o: &Overrides, control: Arc<RenderControl>) -> Result<Rendered>;
}

/// An opened input with what the page starts from.
pub struct Source {
    pub kind: Kind,
    pub view: View,
    pub lighting: Lighting,
    pub base_res: (u32, u32),
}

pub enum Kind {
    /// Boxed: a loaded volume is large, and moves to the render thread.
    Volume {
        scene: Scene,
        lone: Box<LoneVolume>,
    },
    File {
        scene: Scene,
    },
}

impl Source {
    /// Opens `path` (a volume is read here, so errors show before the
    /// server starts); `res` overrides the scene's resolution.
    pub fn open(path: &Path, res: Option<(u32, u32)>) -> Result<Source> {
        let mut scene = Scene::load(path)?;
        scene.apply(&Overrides {
            res,
            ..Default::default()
        });
        let desc = scene.description().clone();
        let base_res = desc.camera.res.unwrap_or(d::RES);
        let lighting = lighting(&desc);
        let mut view = initial_view(&desc);
        if path.extension().is_some_and(|e| e == "toml") {
            let (Some(from), Some(to)) = (desc.camera.from, desc.camera.to) else {
                return Err(Error::input(format!(
                    "{}: the preview needs the scene's [camera] `from` and `to`",
                    path.display()
                )));
            };
            view.camera.from = from;
            view.camera.to = to;
            return Ok(Source {
                kind: Kind::File { scene },
                view,
                lighting,
                base_res,
            });
        }
        let lone = scene.lone()?;
        {
            // The library's own camera (framed when none is given) and
            // medium, brought to world space.
            let (prepared, _) = lone.prepare()?;
            let centre = lone.centre();
            let c = &prepared.camera;
            view.camera = CameraView {
                from: (c.from().as_dvec3() + centre).to_array(),
                to: (c.to().as_dvec3() + centre).to_array(),
                up: c.up().to_array(),
                fov: c.vfov_degrees(),
            };
            let m = &prepared.medium;
            view.density_scale = Some(m.density_scale);
            view.albedo = Some(m.albedo.x);
            view.g = Some(desc.volumes[0].g.unwrap_or(d::G));
        }
        Ok(Source {
            kind: Kind::Volume {
                scene,
                lone: Box::new(lone),
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
    let (azimuth, elevation) =
        sun_angles(Vec3::from_array(sun.direction.unwrap_or(d::SUN_DIRECTION)));
    View {
        camera: CameraView {
            from: [0.0, 0.0, 1.0],
            to: [0.0; 3],
            up: c.up.unwrap_or(d::CAMERA_UP),
            fov: c.fov.unwrap_or(d::FOV),
        },
        sun: SunView {
            enabled: sun.enabled.unwrap_or(true),
            azimuth,
            elevation,
            intensity: 1.0,
        },
        sky: 1.0,
        density_scale: None,
        albedo: None,
        g: None,
        exposure: desc.output.exposure.unwrap_or(d::EXPOSURE),
        integrator: Mode::Auto,
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
        sun_irradiance: Vec3::from_array(sun.irradiance.unwrap_or(d::SUN_IRRADIANCE)),
        sky_radiance: env
            .map
            .is_none()
            .then(|| Vec3::from_array(env.radiance.unwrap_or(d::SKY_RADIANCE))),
        sky_map_intensity: env.intensity.unwrap_or(d::SKY_INTENSITY),
    }
}

/// A lone volume's prepared render scene, rewritten per pass.
pub struct VolumeRenderer<'a> {
    lone: &'a LoneVolume,
    base: Scene,
    centre: DVec3,
    scene: cirrus_render::Scene<BrickField<'a>>,
    /// The density scale the majorant cells were refined for.
    refined_for: f32,
    /// Keep the albedo AOV (it guides the denoiser).
    aovs: bool,
}

impl<'a> VolumeRenderer<'a> {
    pub fn new(base: Scene, lone: &'a LoneVolume, aovs: bool) -> Result<Self> {
        let (scene, _) = lone.prepare()?;
        Ok(VolumeRenderer {
            lone,
            base,
            centre: lone.centre(),
            refined_for: scene.medium.density_scale,
            scene,
            aovs,
        })
    }
}

impl Renderer for VolumeRenderer<'_> {
    fn render(&mut self, o: &Overrides, control: Arc<RenderControl>) -> Result<Rendered> {
        // The library resolves the overrides (lights, defaults, checks) as
        // `cirrus render` would; only the placement is done here.
        let mut desc = self.base.clone();
        desc.apply(o);
        let s = desc.settings()?;
        let (from, to) = s
            .look_at
            .ok_or_else(|| Error::input("the preview always sets a camera"))?;
        let to_render = |p: DVec3| (p - self.centre).as_vec3();
        let (w, h) = s.res;
        self.scene.camera = Camera::new(to_render(from), to_render(to), s.camera_up, s.fov, w, h);
        self.scene.lights = s.lights.clone();
        if let Some(rgb) = o.density_scale {
            let Extinction { scale, tint } = Extinction::split(rgb.vec3());
            // Cells refined for another scale stay correct bounds, only
            // less efficient; refine again past a factor of two.
            let ratio = scale / self.refined_for;
            if scale > 0.0 && !(0.5..=2.0).contains(&ratio) {
                self.scene.medium.field =
                    BrickField::new(&self.lone.volume, DMat4::IDENTITY, self.centre)
                        .with_refinement(scale, s.refine_optical_depth);
                self.refined_for = scale;
            }
            self.scene.medium.density_scale = scale;
            self.scene.medium.extinction_tint = tint;
        }
        if let Some(a) = o.albedo {
            self.scene.medium.albedo = a.vec3();
        }
        if let Some(g) = o.g {
            self.scene.medium.phase = Phase::hg(g);
        }
        self.scene.validate()?;
        let mut settings = s.render;
        settings.control = Some(control);
        settings.progress = false;
        settings.aovs = self.aovs;
        Ok(render(&self.scene, &settings))
    }
}

/// A scene file, rendered whole per pass.
pub struct FileRenderer {
    pub base: Scene,
}

impl Renderer for FileRenderer {
    fn render(&mut self, o: &Overrides, control: Arc<RenderControl>) -> Result<Rendered> {
        let mut scene = self.base.clone();
        scene.apply(o);
        scene.render_with(Some(control))
    }
}
