//! A description resolved into what the renderer takes: camera placement,
//! lights and render settings, with every default applied. Per-volume
//! values are resolved by the volume's plan (`plan.rs`).

use cirrus_render::{Adaptive, Budget, Lights, RenderSettings, Shutter};
use glam::{DVec3, Vec3};

use crate::description::SceneDescription;
use crate::error::{Error, Result};

/// The scene-wide settings of a description.
#[derive(Clone, Debug)]
pub struct SceneSettings {
    pub res: (u32, u32),
    /// World-space eye and target; `None` frames the volumes.
    pub look_at: Option<(DVec3, DVec3)>,
    pub camera_up: Vec3,
    pub fov: f32,
    pub lights: Lights,
    pub render: RenderSettings,
    pub refine_optical_depth: f32,
    /// Where the render runs.
    pub device: crate::device::Device,
    pub denoise: bool,
}

impl SceneSettings {
    /// Resolves `desc` (the sky map, if any, is read here).
    pub fn resolve(desc: &SceneDescription) -> Result<SceneSettings> {
        crate::ranges::check(desc)?;
        let c = &desc.camera;
        let look_at = match (c.camera_from, c.camera_to) {
            (Some(f), Some(t)) => Some((DVec3::from_array(f), DVec3::from_array(t))),
            (None, None) => None,
            _ => {
                return Err(Error::input(
                    "[camera] needs both `from` and `to` (or neither)",
                ))
            }
        };
        let r = &desc.render;
        let budget = match (r.spp, r.time) {
            (Some(_), Some(_)) => {
                return Err(Error::input("[render] give `spp` or `time`, not both"))
            }
            (_, Some(t)) => Budget::Time(t),
            (Some(n), None) => Budget::Spp(n),
            (None, None) => Budget::Spp(r.spp()),
        };
        let render = RenderSettings {
            integrator: r.integrator(),
            transmittance: r.transmittance(),
            majorant: r.majorant(),
            light_sampling: r.light_sampling(),
            sunward: r.sunward(),
            distance_sampling: r.distance_sampling(),
            budget,
            seed: r.seed(),
            sampler: r.sampler(),
            adaptive: r.noise_threshold.map(|threshold| Adaptive {
                threshold,
                min_spp: r.min_spp(),
            }),
            max_depth: r.max_depth,
            step_voxels: r.step(),
            shadow_step_voxels: r.shadow_step,
            shutter: {
                let [open, close] = r.shutter();
                Shutter::new(open, close)
            },
            progress: false,
            ..Default::default()
        };
        render.validate()?;
        Ok(SceneSettings {
            res: c.res(),
            look_at,
            camera_up: Vec3::from_array(c.camera_up()),
            fov: c.fov(),
            lights: crate::lights::lights(desc)?,
            render,
            refine_optical_depth: r.refine_optical_depth(),
            device: r.device(),
            denoise: r.denoise(),
        })
    }
}
