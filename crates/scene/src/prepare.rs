//! A scene description on its way to the renderer: planned, placed in
//! render space, culled and loaded ([`Prepared`]), the one road every
//! render takes, whether the scene came from a scene file, a lone volume
//! file, a Python dict or a preview's view.

use std::time::Instant;

use cirrus_bricks::{Bounds3, DBounds3};
use cirrus_kernel::medium::BrickField;
use cirrus_kernel::transform_motion::MovingField;
use cirrus_render::{Camera, Crop, DensityField, RenderSettings, Rendered, Volumes};
use glam::DVec3;

use crate::cull::{in_frustum, needed};
use crate::description::SceneDescription;
use crate::error::{Error, Result};
use crate::plan::{plan, GridPrecision, Plan, VolumeCache};
use crate::settings::SceneSettings;

/// Where render space and the default camera come from.
///
/// Render space is world space minus a centre chosen in f64, so that f32
/// stays precise for volumes far from the origin.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// Centred on the union of the volumes' world boxes (from their
    /// headers where the files give them, so culling reads no voxel), the
    /// default camera framing that union; `.vdb`/`.nvdb` grids kept in
    /// f32. Scene files.
    Volumes,
    /// Centred on the one volume's brick grid and framed by it; its grid
    /// kept at render precision ([`GridPrecision::Render`]). A lone volume
    /// file.
    OwnGrid,
}

impl Placement {
    fn precision(self) -> GridPrecision {
        match self {
            Placement::Volumes => GridPrecision::F32,
            Placement::OwnGrid => GridPrecision::Render,
        }
    }
}

/// What the renderer takes, with what it cost to load.
pub struct Prepared<'c> {
    pub scene: cirrus_render::Scene<Volumes<MovingField<BrickField<'c>>>>,
    pub settings: RenderSettings,
    /// The world position of render space's origin.
    pub centre: DVec3,
    /// Whether the camera was framed on the volumes (none was given).
    pub framed: bool,
    /// What loading found wrong but could render (bad voxels, an open
    /// shutter with no velocity grid), each said once.
    pub warnings: Vec<String>,
    /// Volumes neither the camera nor any light path can reach (not loaded).
    pub culled: u64,
    /// The scene's index of each instance rendered.
    pub kept: Vec<usize>,
    pub bytes_read: u64,
    pub grids_loaded: u64,
    /// Wall time spent planning, reading and converting.
    pub load_seconds: f64,
}

impl Prepared<'_> {
    /// Renders, with the load figures in the statistics.
    pub fn render(&self) -> Rendered {
        let mut rendered = cirrus_render::render(&self.scene, &self.settings);
        crate::compositing::renumber_instances(&mut rendered, &self.kept);
        let s = &mut rendered.stats;
        s.bytes_read = self.bytes_read;
        s.grids_loaded = self.grids_loaded;
        s.volumes_culled = self.culled;
        s.load_seconds = self.load_seconds;
        s.warnings = self.warnings.clone();
        let c = &self.scene.camera;
        let world = |p: glam::Vec3| (p.as_dvec3() + self.centre).to_array();
        s.camera = Some(cirrus_render::CameraReport {
            from: world(c.from()),
            to: world(c.to()),
            up: c.up().to_array(),
            fov: c.vfov_degrees(),
            framed: self.framed,
        });
        rendered
    }
}

/// Plans, places, culls and loads `desc` (resolved as `settings`) through
/// `cache`.
pub fn prepare<'c>(
    desc: &SceneDescription,
    settings: SceneSettings,
    placement: Placement,
    cache: &'c mut VolumeCache,
) -> Result<Prepared<'c>> {
    let start = Instant::now();
    let shutter = settings.render.shutter;
    let moving = shutter.max_abs_time() > 0.0;
    // Time-sampled transforms read at the frame, and over the shutter.
    let frame = desc.frame();
    let tracks: Vec<_> = desc
        .volumes
        .iter()
        .map(|v| crate::moving::track(v, frame, [shutter.open, shutter.close]))
        .collect();
    let desc = &crate::timeline::at_frame(desc);
    let plans = desc
        .volumes
        .iter()
        .map(|v| plan(v, cache, moving, placement.precision()))
        .collect::<Result<Vec<_>>>()?;
    let (boxes, centre, framed) = render_space(placement, cache, &plans)?;
    let placed = crate::moving::camera(desc, &settings, centre)?;
    let framed_camera = placed.is_none() && settings.look_at.is_none();
    let camera = match placed {
        Some(c) => c,
        None => camera(&settings, centre, framed),
    };
    // Culling sees where the density can move to over the shutter (its
    // transform's poses, its velocity); the framing and render space above
    // stay those of the still frame.
    let boxes: Vec<DBounds3> = plans
        .iter()
        .zip(boxes)
        .zip(&tracks)
        .map(|((p, b), t)| {
            let b = t.as_ref().map_or(b, |t| t.swept(b));
            cache.motion_box(p, b, shutter)
        })
        .collect::<Result<_>>()?;
    let keep = reachable(&settings, &camera, &plans, &boxes, centre);

    // Read what is needed, then place it.
    let kept = || {
        plans
            .iter()
            .zip(&tracks)
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|(p, _)| p)
    };
    for (p, _) in kept() {
        cache.load_grids(p)?;
    }
    // Moving volumes' pose tables and the shells bounding their poses,
    // kept by the cache for as long as this scene borrows it.
    cache.poses = crate::moving::poses(cache, kept(), centre)?;
    let warnings = std::mem::take(&mut cache.warnings);
    let cache: &'c VolumeCache = cache;
    let instances = kept()
        .zip(&cache.poses)
        .map(|((p, _), pose)| crate::moving::instance(cache, p, pose.as_ref(), centre, &settings))
        .collect::<Result<Vec<_>>>()?;
    let r = &settings.render;
    if instances.is_empty() {
        return Err(Error::input(
            "no volume is visible and none can light one: nothing to render",
        ));
    }
    let volumes = Volumes::new(instances);
    integrator_supports(&volumes, r)?;
    Ok(Prepared {
        scene: cirrus_render::Scene {
            media: volumes,
            camera,
            lights: settings.lights.relative_to(centre),
        },
        settings: settings.render,
        centre,
        framed: framed_camera,
        warnings,
        culled: keep.iter().filter(|k| !**k).count() as u64,
        kept: (0..keep.len()).filter(|&i| keep[i]).collect(),
        bytes_read: cache.bytes_read(),
        grids_loaded: cache.grids_loaded(),
        load_seconds: start.elapsed().as_secs_f64(),
    })
}

/// The volumes' world boxes, and render space: its centre in the world
/// and the boxes' union about it (what the camera frames).
fn render_space(
    placement: Placement,
    cache: &mut VolumeCache,
    plans: &[Plan],
) -> Result<(Vec<DBounds3>, DVec3, Bounds3)> {
    let boxes: Vec<DBounds3> = plans
        .iter()
        .map(|p| match p.world_box {
            Some(b) => Ok(b),
            None => cache.density_box(p),
        })
        .collect::<Result<_>>()?;
    let (centre, framed) = match (placement, plans) {
        (Placement::OwnGrid, [one]) => own_grid(cache, one)?,
        _ => {
            let union = boxes.iter().fold(DBounds3::EMPTY, |u, &b| u.union(b));
            let centre = union.centre();
            (centre, union.relative_to(centre))
        }
    };
    Ok((boxes, centre, framed))
}

/// [`Placement::OwnGrid`]'s centre, the middle of the volume's brick grid
/// (object to world applied), and the grid's render-space box.
fn own_grid(cache: &mut VolumeCache, p: &Plan) -> Result<(DVec3, Bounds3)> {
    let volume = cache.density(p)?;
    let world_from_local = p.object_to_world() * volume.local_from_world().inverse();
    let centre = world_from_local.transform_point3(volume.local_extent().as_dvec3() * 0.5);
    let framed = BrickField::new(volume, p.object_to_world(), centre).bounds();
    Ok((centre, framed))
}

/// Which volumes can matter: in the camera's frustum (of the crop window)
/// or reachable by light paths from one that is (`cull.rs`).
fn reachable(
    settings: &SceneSettings,
    camera: &Camera,
    plans: &[Plan],
    boxes: &[DBounds3],
    centre: DVec3,
) -> Vec<bool> {
    let (w, h) = settings.res;
    let window = settings.render.crop.unwrap_or(Crop {
        x0: 0,
        y0: 0,
        x1: w,
        y1: h,
    });
    // A moving camera sees more than its frame's frustum.
    let visible: Vec<bool> = boxes
        .iter()
        .map(|b| camera.moves() || in_frustum(camera, window, b.relative_to(centre)))
        .collect();
    let any_emission = plans.iter().any(|p| p.emits());
    needed(
        &visible,
        boxes,
        &settings.lights,
        any_emission,
        settings.render.max_depth,
    )
}

/// The camera of `s` in render space (world minus `centre`), framing
/// `framed` (render space) when no eye and target are given.
fn camera(s: &SceneSettings, centre: DVec3, framed: Bounds3) -> Camera {
    let to_render = |p: DVec3| (p - centre).as_vec3();
    let (w, h) = s.res;
    match s.look_at {
        Some((from, to)) => Camera::new(to_render(from), to_render(to), s.camera_up, s.fov, w, h),
        None => Camera::framing_with_fov(framed, w, h, s.fov),
    }
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
