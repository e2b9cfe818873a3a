//! A description resolved into what the renderer takes: camera placement,
//! lights and render settings, with every default applied. Per-volume
//! values are resolved by the volume's plan (`plan.rs`).

use std::sync::Arc;

use cirrus_render::{Adaptive, Budget, EnvMap, Environment, Lights, RenderSettings, Shutter, Sun};
use glam::{DVec3, Vec3};

use crate::defaults as d;
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
    pub denoise: bool,
}

impl SceneSettings {
    /// Resolves `desc` (the sky map, if any, is read here).
    pub fn resolve(desc: &SceneDescription) -> Result<SceneSettings> {
        let c = &desc.camera;
        let look_at = match (c.from, c.to) {
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
            (None, None) => Budget::Spp(d::SPP),
        };
        let render = RenderSettings {
            integrator: r.integrator.unwrap_or(d::INTEGRATOR),
            transmittance: r.transmittance.unwrap_or(d::TRANSMITTANCE),
            majorant: r.majorant.unwrap_or(d::MAJORANT),
            budget,
            seed: r.seed.unwrap_or(d::SEED),
            sampler: r.sampler.unwrap_or(d::SAMPLER),
            adaptive: r.noise_threshold.map(|threshold| Adaptive {
                threshold,
                min_spp: r.min_spp.unwrap_or(d::MIN_SPP),
            }),
            max_depth: r.max_depth,
            step_voxels: r.step.unwrap_or(d::STEP),
            shadow_step_voxels: r.shadow_step,
            shutter: {
                let [open, close] = r.shutter.unwrap_or(d::SHUTTER);
                Shutter::new(open, close)
            },
            progress: false,
            ..Default::default()
        };
        render.validate()?;
        Ok(SceneSettings {
            res: c.res.unwrap_or(d::RES),
            look_at,
            camera_up: Vec3::from_array(c.up.unwrap_or(d::CAMERA_UP)),
            fov: c.fov.unwrap_or(d::FOV),
            lights: lights(desc)?,
            render,
            refine_optical_depth: r.refine_optical_depth.unwrap_or(d::REFINE_OPTICAL_DEPTH),
            denoise: r.denoise.unwrap_or(false),
        })
    }
}

/// The sun and sky of `desc`; absent or black lights pruned.
fn lights(desc: &SceneDescription) -> Result<Lights> {
    let sun = desc.sun.clone().unwrap_or_default();
    let sun = sun.enabled.unwrap_or(true).then(|| {
        Sun::new(
            Vec3::from_array(sun.direction.unwrap_or(d::SUN_DIRECTION)),
            Vec3::from_array(sun.irradiance.unwrap_or(d::SUN_IRRADIANCE)),
            sun.angle.unwrap_or(d::SUN_ANGLE).to_radians(),
        )
    });
    let env = desc.environment.clone().unwrap_or_default();
    let environment = match &env.map {
        None => Environment::new(Vec3::from_array(env.radiance.unwrap_or(d::SKY_RADIANCE))),
        Some(path) => {
            let map = EnvMap::read_exr(path, env.rotation.unwrap_or(d::SKY_ROTATION))?;
            Environment::from_map(
                Arc::new(map),
                Vec3::splat(env.intensity.unwrap_or(d::SKY_INTENSITY)),
            )
        }
    };
    Ok(Lights {
        sun,
        environment: Some(environment),
    }
    .pruned())
}
