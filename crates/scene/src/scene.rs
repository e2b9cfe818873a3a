//! [`Scene`]: a description on its way to an image.
//!
//! A scene is made from a scene file, from a lone volume file (rendered as
//! `cirrus render FILE` renders it), or from a description built in code.
//! [`Overrides`] are written over it, then [`Scene::render`] plans, culls,
//! loads and renders:
//!
//! - a lone volume is placed with its centre at the render-space origin and
//!   walks the brick hierarchy refined for its density scale
//!   ([`LoneVolume`], which the benchmarks use to render one volume many
//!   times);
//! - a scene file's volumes are planned from their headers, culled
//!   (`cull.rs`), and only the grids that can matter are read
//!   (`plan.rs`); the instances render together under a top-level BVH.
//!
//! Input paths of a scene file are relative to the file; output paths and
//! paths given as overrides are relative to the working directory.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use cirrus_bricks::{Bounds3, BrickVolume, DBounds3};
use cirrus_render::medium::BrickField;
use cirrus_render::{
    render, render_media, Camera, Crop, DensityField, Medium, RenderControl, RenderSettings,
    Rendered, Shutter, Velocity, Volumes,
};
use cirrus_vdb::VolumeFile;
use glam::{DMat4, DVec3, Vec3};

use crate::cull::{in_frustum, needed};
use crate::defaults as d;
use crate::description::{SceneDescription, VolumeSpec};
use crate::error::{Error, Result};
use crate::grids::{choose_velocity, is_cbrk, load_volume, read_velocity};
use crate::output::Outputs;
use crate::overrides::Overrides;
use crate::plan::{plan, Files};
use crate::settings::SceneSettings;

/// A scene description ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    description: SceneDescription,
    /// Made from a lone volume file rather than a scene file.
    lone: bool,
    /// Draw a progress bar on a terminal's stderr while rendering.
    pub progress_bar: bool,
}

impl Scene {
    /// A scene file (`.toml`), or a lone `.vdb`, `.nvdb` or `.cbrk` volume.
    pub fn load(path: &Path) -> Result<Scene> {
        if path.extension().is_some_and(|e| e == "toml") {
            let description = SceneDescription::read(path)?;
            Scene::from_description(description, parent(path)).map_err(|e| Error {
                message: format!("{}: {}", path.display(), e.message),
                ..e
            })
        } else {
            Ok(Scene::volume(path))
        }
    }

    /// A lone volume file, rendered under the default sun and sky.
    pub fn volume(path: &Path) -> Scene {
        Scene {
            description: SceneDescription {
                volumes: vec![VolumeSpec {
                    file: path.to_path_buf(),
                    ..Default::default()
                }],
                ..Default::default()
            },
            lone: true,
            progress_bar: false,
        }
    }

    /// A description whose input paths are relative to `dir`.
    pub fn from_description(mut description: SceneDescription, dir: &Path) -> Result<Scene> {
        if description.volumes.is_empty() {
            return Err(Error::input("no [[volume]] in the scene"));
        }
        description.rebase(dir);
        crate::compositing::instance_names(&description)?;
        Ok(Scene {
            description,
            lone: false,
            progress_bar: false,
        })
    }

    pub fn description(&self) -> &SceneDescription {
        &self.description
    }

    /// Writes the given overrides over the description.
    pub fn apply(&mut self, overrides: &Overrides) {
        overrides.apply(&mut self.description);
    }

    /// The scene-wide settings, resolved (reads the sky map, if any).
    pub fn settings(&self) -> Result<SceneSettings> {
        SceneSettings::resolve(&self.description)
    }

    pub fn outputs(&self) -> Outputs {
        Outputs::resolve(&self.description)
    }

    /// Renders the scene; see the module doc.
    pub fn render(&self) -> Result<Rendered> {
        self.render_with(None)
    }

    /// [`Scene::render`], watched and stoppable through `control`.
    pub fn render_with(&self, control: Option<Arc<RenderControl>>) -> Result<Rendered> {
        let start = Instant::now();
        let outputs = self.outputs();
        let denoise = self.description.render.denoise.unwrap_or(false);
        let configure = |settings: &mut RenderSettings, res: (u32, u32)| -> Result<()> {
            settings.crop = outputs.crop;
            // The denoiser is guided by the albedo AOV.
            settings.aovs = !outputs.aovs.is_empty() || denoise;
            settings.control = control.clone();
            settings.progress = self.progress_bar;
            if let Some(c) = &outputs.crop {
                c.validate(res.0, res.1)?;
            }
            crate::compositing::configure(settings, &outputs, &self.description, res)?;
            Ok(())
        };
        let mut rendered = if self.lone {
            let lone = LoneVolume::load(self)?;
            let load_seconds = start.elapsed().as_secs_f64();
            let (scene, mut settings) = lone.prepare()?;
            integrator_supports(&scene.medium, &settings)?;
            configure(&mut settings, lone.settings.res)?;
            let mut r = render(&scene, &settings);
            r.stats.bytes_read = lone.bytes_read;
            r.stats.grids_loaded = 1;
            r.stats.load_seconds = load_seconds;
            r
        } else {
            let mut settings = self.settings()?;
            configure(&mut settings.render, settings.res)?;
            render_file(&self.description, &settings, start)?
        };
        if control.as_ref().is_some_and(|c| c.is_cancelled()) {
            return Err(Error::cancelled());
        }
        if denoise {
            crate::denoise::denoise(&mut rendered)?;
        }
        Ok(rendered)
    }

    /// The lone volume of a scene made from one volume file, loaded.
    pub fn lone(&self) -> Result<LoneVolume> {
        if !self.lone {
            return Err(Error::input("a scene file is not a lone volume"));
        }
        LoneVolume::load(self)
    }

    /// The scene of frame `frame`: every input and output path with its
    /// frame pattern replaced (see [`frames`](crate::frames)).
    pub fn for_frame(&self, frame: i64) -> Scene {
        let mut scene = self.clone();
        scene.description.substitute_frame(frame);
        scene
    }

    /// The volume files the scene names (after overrides).
    pub fn inputs(&self) -> Vec<PathBuf> {
        self.description
            .volumes
            .iter()
            .map(|v| v.file.clone())
            .collect()
    }
}

fn parent(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// One volume loaded whole, as `cirrus render FILE` renders it.
pub struct LoneVolume {
    pub volume: BrickVolume,
    /// What moves it while the shutter is open (none when it is closed).
    pub velocity: Option<Velocity>,
    /// Bytes read from disk to load it.
    pub bytes_read: u64,
    pub settings: SceneSettings,
    spec: VolumeSpec,
}

impl LoneVolume {
    fn load(scene: &Scene) -> Result<LoneVolume> {
        let spec = scene.description.volumes[0].clone();
        let settings = scene.settings()?;
        let (volume, bytes_read) = load_volume(&spec.file, spec.density.as_deref())?;
        let velocity = lone_velocity(&spec, settings.render.shutter)?;
        Ok(LoneVolume {
            volume,
            velocity,
            bytes_read,
            settings,
            spec,
        })
    }

    /// The renderer's scene and settings over this volume.
    ///
    /// Render space is world space minus the volume's centre, computed in
    /// f64, so f32 stays precise for volumes far from the origin.
    pub fn prepare(&self) -> Result<(cirrus_render::Scene<BrickField<'_>>, RenderSettings)> {
        let volume = &self.volume;
        let s = &self.settings;
        let centre = self.centre();
        let field = BrickField::new(volume, DMat4::IDENTITY, centre);
        let camera = camera(s, centre, field.bounds());
        let extinction =
            crate::plan::extinction(&self.spec.file, self.spec.density_scale, field.voxel_size())?;
        let field = crate::plan::walk_cells(
            field,
            s.render.integrator,
            extinction.scale,
            s.refine_optical_depth,
        );
        // After the camera: a moving volume is framed as its still frame.
        let field = match &self.velocity {
            Some(v) => field
                .with_motion(v, s.render.shutter)
                .map_err(|e| Error::input(format!("{}: {e}", self.spec.file.display())))?,
            None => field,
        };
        let albedo = self
            .spec
            .albedo
            .map_or(Vec3::splat(d::ALBEDO), |a| Vec3::from_array(a.rgb()));
        let phase = crate::plan::phase_of(&self.spec)?;
        let scene = cirrus_render::Scene {
            medium: Medium::new(field, extinction.scale, albedo, d::G)
                .with_phase(phase)
                .with_extinction_tint(extinction.tint),
            camera,
            lights: s.lights.clone(),
        };
        scene.validate()?;
        Ok((scene, s.render.clone()))
    }
}

/// The velocity of a lone volume: read only when the shutter reaches
/// away from the frame's instant and the file has (or names) one.
fn lone_velocity(spec: &VolumeSpec, shutter: Shutter) -> Result<Option<Velocity>> {
    if shutter.max_abs_time() == 0.0 {
        return Ok(None);
    }
    if is_cbrk(&spec.file) {
        return match &spec.velocity {
            Some(_) => Err(Error::input(format!(
                "{}: a .cbrk holds one density grid; velocity needs the .vdb",
                spec.file.display()
            ))),
            None => Ok(None),
        };
    }
    let f = VolumeFile::open(&spec.file)?;
    let Some(index) = choose_velocity(&f, spec.velocity.as_deref())? else {
        return Ok(None);
    };
    let scale = spec.velocity_scale.unwrap_or(d::VELOCITY_SCALE);
    if !scale.is_finite() {
        return Err(Error::input(format!(
            "{}: velocity scale must be finite, got {scale}",
            spec.file.display()
        )));
    }
    Ok(Some(Velocity {
        grid: Arc::new(read_velocity(&f, index)?),
        unit: spec.velocity_unit.unwrap_or(d::VELOCITY_UNIT),
        scale,
    }))
}

impl LoneVolume {
    /// The world position of render space's origin: the volume's centre.
    pub fn centre(&self) -> DVec3 {
        let world_from_local = self.volume.local_from_world().inverse();
        world_from_local.transform_point3(self.volume.local_extent().as_dvec3() * 0.5)
    }
}

/// The camera of `s` in render space (world minus `centre`), framing
/// `bounds` (render space) when no eye and target are given.
fn camera(s: &SceneSettings, centre: DVec3, bounds: Bounds3) -> Camera {
    let to_render = |p: DVec3| (p - centre).as_vec3();
    let (w, h) = s.res;
    match s.look_at {
        Some((from, to)) => Camera::new(to_render(from), to_render(to), s.camera_up, s.fov, w, h),
        None => Camera::framing(bounds, w, h),
    }
}

/// A scene file's volumes: planned from their headers, culled, loaded
/// where they can matter, rendered together.
fn render_file(
    desc: &SceneDescription,
    settings: &SceneSettings,
    start: Instant,
) -> Result<Rendered> {
    let mut files = Files::default();
    let shutter = settings.render.shutter;
    let moving = shutter.max_abs_time() > 0.0;
    let plans = desc
        .volumes
        .iter()
        .map(|v| plan(v, &mut files, moving))
        .collect::<Result<Vec<_>>>()?;
    let boxes: Vec<DBounds3> = plans
        .iter()
        .map(|p| match p.world_box {
            Some(b) => Ok(b),
            None => files.density_box(p),
        })
        .collect::<Result<_>>()?;
    let union = boxes.iter().fold(DBounds3::EMPTY, |u, &b| u.union(b));
    // Render space: world minus the scene's centre, in f64.
    let centre = union.centre();
    let camera = camera(settings, centre, union.relative_to(centre));
    let (w, h) = settings.res;
    let window = settings.render.crop.unwrap_or(Crop {
        x0: 0,
        y0: 0,
        x1: w,
        y1: h,
    });
    // Culling sees where the density can move to over the shutter; the
    // framing and render space above stay those of the still frame.
    let boxes: Vec<DBounds3> = plans
        .iter()
        .zip(boxes)
        .map(|(p, b)| files.motion_box(p, b, shutter))
        .collect::<Result<_>>()?;
    let visible: Vec<bool> = boxes
        .iter()
        .map(|b| in_frustum(&camera, window, b.relative_to(centre)))
        .collect();
    let any_emission = plans.iter().any(|p| p.emits());
    let keep = needed(
        &visible,
        &boxes,
        &settings.lights,
        any_emission,
        settings.render.max_depth,
    );

    // Read what is needed, then place it.
    let kept = || plans.iter().zip(&keep).filter(|(_, k)| **k).map(|(p, _)| p);
    for p in kept() {
        files.load_grids(p)?;
    }
    let instances = kept()
        .map(|p| {
            files.instance(
                p,
                centre,
                settings.render.integrator,
                settings.refine_optical_depth,
                shutter,
            )
        })
        .collect::<Result<Vec<_>>>()?;
    let volumes = Volumes::new(instances);
    if volumes.instances().is_empty() {
        return Err(Error::input(
            "no volume is visible and none can light one: nothing to render",
        ));
    }
    integrator_supports(&volumes, &settings.render)?;
    let load_seconds = start.elapsed().as_secs_f64();
    let mut rendered = render_media(&volumes, &camera, &settings.lights, &settings.render);
    let kept: Vec<usize> = (0..keep.len()).filter(|&i| keep[i]).collect();
    crate::compositing::renumber_instances(&mut rendered, &kept);
    rendered.stats.bytes_read = files.bytes_read();
    rendered.stats.grids_loaded = files.grids_loaded();
    rendered.stats.volumes_culled = keep.iter().filter(|k| !**k).count() as u64;
    rendered.stats.load_seconds = load_seconds;
    Ok(rendered)
}

/// Whether the chosen integrator can render `media`: the two-pass marcher
/// caches one transmittance per light, so it cannot attenuate channels
/// apart.
fn integrator_supports<M: cirrus_render::Media>(
    media: &M,
    settings: &RenderSettings,
) -> Result<()> {
    if media.chromatic() && settings.integrator == cirrus_render::IntegratorKind::RayMarch2Pass {
        return Err(Error::input(
            "raymarch2pass caches one transmittance per light and cannot render a chromatic \
             medium (a density scale per channel); use --integrator path or raymarch",
        ));
    }
    Ok(())
}
