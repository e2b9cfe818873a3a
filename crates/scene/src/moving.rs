//! What moves while the shutter is open, besides matter inside a velocity
//! grid: volumes whose transform is time-sampled and a camera placed by
//! time-sampled matrices, plus the camera a description places by a matrix
//! or a lens (focal length, apertures, clipping).
//!
//! A moving volume renders as a [`MovingField`] over its still placement
//! at the frame's instant; its majorants come from a shell of its bricks
//! dilated by the farthest any point moves over the shutter
//! ([`PoseTable::reach`]). Still volumes wrap their fields unchanged.

use std::sync::Arc;

use cirrus_bricks::{BrickVolume, DBounds3};
use cirrus_kernel::medium::BrickField;
use cirrus_kernel::transform_motion::{MovingField, PoseTable};
use cirrus_render::{Camera, CameraMotion, CameraPose, Emission, Medium};
use glam::{DMat4, DVec3, Vec3};

use crate::description::{SceneDescription, VolumeSpec};
use crate::error::{Error, Result};
use crate::plan::{Plan, Pose, VolumeCache};
use crate::settings::SceneSettings;
use crate::timeline::{camera_placement, lens_fov, matrix_at};

/// Evenly spaced maps a moving volume's shutter is tabulated at.
const TABLE_MAPS: usize = 65;

/// A volume's transforms over the shutter (world, f64), at the table's times.
pub struct Track {
    open: f32,
    close: f32,
    /// Object to world at each tabulated time; `still` at the frame.
    pub matrices: Vec<DMat4>,
    pub still: DMat4,
}

/// The track of volume `v` when its transform changes within the shutter.
pub fn track(v: &VolumeSpec, frame: f64, shutter: [f32; 2]) -> Option<Track> {
    let samples = v.transform.samples.as_ref()?;
    let [open, close] = shutter;
    if close.partial_cmp(&open) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let matrices: Vec<DMat4> = (0..TABLE_MAPS)
        .map(|k| {
            let t = f64::from(open) + f64::from(close - open) * k as f64 / (TABLE_MAPS - 1) as f64;
            matrix_at(samples, frame + t)
        })
        .collect();
    if matrices.iter().all(|m| *m == matrices[0]) {
        return None;
    }
    Some(Track {
        open,
        close,
        matrices,
        still: matrix_at(samples, frame),
    })
}

impl Track {
    /// Render-space maps from each time's placement to the still one.
    pub fn table(&self, centre: DVec3) -> Result<Arc<PoseTable>> {
        let to_render = DMat4::from_translation(-centre);
        let to_world = DMat4::from_translation(centre);
        let maps = self
            .matrices
            .iter()
            .map(|m| (to_render * self.still * m.inverse() * to_world).as_mat4())
            .collect();
        Ok(Arc::new(PoseTable::new(self.open, self.close, maps)?))
    }

    /// `world_box` (the still placement's) grown to every pose's.
    pub fn swept(&self, world_box: DBounds3) -> DBounds3 {
        let back = self.still.inverse();
        self.matrices.iter().fold(world_box, |acc, m| {
            acc.union(world_box.transformed(*m * back))
        })
    }
}

/// The shell whose bricks bound `volume`, placed by `object_to_world` in
/// render space (world minus `centre`), over every pose of `table`.
pub fn shell(
    volume: &BrickVolume,
    object_to_world: DMat4,
    centre: DVec3,
    table: &PoseTable,
) -> Result<BrickVolume> {
    let local_from_render =
        volume.local_from_world() * object_to_world.inverse() * DMat4::from_translation(centre);
    let local_box = cirrus_bricks::Bounds3::new(Vec3::ZERO, volume.local_extent());
    let reach = table.reach(local_from_render.as_mat4(), local_box);
    // Slack for the f32 rounding of the maps and lookups.
    let reach = reach * (1.0 + 1e-3) + 1e-2;
    volume
        .motion_shell(reach)
        .map_err(|e| Error::input(format!("moving volume: {e}")))
}

/// Per kept plan, the pose table and shell of the moving ones (their
/// grids loaded).
pub fn poses<'a>(
    files: &VolumeCache,
    kept: impl Iterator<Item = (&'a Plan, &'a Option<Track>)>,
    centre: DVec3,
) -> Result<Vec<Option<Pose>>> {
    kept.map(|(p, track)| {
        let Some(track) = track else { return Ok(None) };
        let table = track.table(centre)?;
        let shell = shell(files.density_volume(p), p.object_to_world(), centre, &table)?;
        Ok(Some((table, shell)))
    })
    .collect()
}

/// The instance of a plan whose grids are loaded, moving through `pose`
/// (its table and shell) when it has one.
pub fn instance<'v>(
    files: &'v VolumeCache,
    p: &Plan,
    pose: Option<&'v Pose>,
    centre: DVec3,
    settings: &SceneSettings,
) -> Result<Medium<MovingField<BrickField<'v>>>> {
    let s = &settings.render;
    let inst = files.instance(
        p,
        centre,
        s.integrator,
        settings.refine_optical_depth,
        s.shutter,
    )?;
    let motion = match pose {
        Some((table, shell)) => {
            let bound = files.bound_field(p, shell, centre, settings, s.shutter)?;
            Some((table.clone(), bound))
        }
        None => None,
    };
    Ok(wrap(inst, motion))
}

/// `inst`'s fields wrapped: still, or moving through `table` with the
/// density walked over `bound`.
pub fn wrap<'v>(
    inst: Medium<BrickField<'v>>,
    motion: Option<(Arc<PoseTable>, BrickField<'v>)>,
) -> Medium<MovingField<BrickField<'v>>> {
    let (density, table) = match motion {
        None => (MovingField::still(inst.field), None),
        Some((table, bound)) => (
            MovingField::moving(inst.field, table.clone(), Some(bound)),
            Some(table),
        ),
    };
    let field = |f: BrickField<'v>| match &table {
        None => MovingField::still(f),
        Some(t) => MovingField::moving(f, t.clone(), None),
    };
    Medium {
        field: density,
        density_scale: inst.density_scale,
        extinction_tint: inst.extinction_tint,
        albedo: inst.albedo,
        phase: inst.phase,
        holdout: inst.holdout,
        emission: inst.emission.map(|e| Emission {
            temperature: e.temperature.map(|(f, bb)| (field(f), bb)),
            grid: e.grid.map(|(f, c)| (field(f), c)),
        }),
    }
}

/// The camera a description places by a matrix or samples, or whose lens
/// or clipping it gives; `None` leaves the camera to `from`/`to` or the
/// framing. Render space is world minus `centre`.
pub fn camera(desc: &SceneDescription, s: &SceneSettings, centre: DVec3) -> Result<Option<Camera>> {
    let c = &desc.camera;
    let shutter = desc.render.shutter.unwrap_or([0.0, 0.0]);
    let placement = camera_placement(c, desc.frame(), shutter);
    if placement.is_none() && c.focal_length.is_none() && c.clipping.is_none() {
        return Ok(None);
    }
    let (w, h) = s.res;
    let fov = lens_fov(c, f64::from(w) / f64::from(h)).unwrap_or(s.fov);
    let to_render = |p: DVec3| (p - centre).as_vec3();
    let mut camera = match (&placement, s.look_at) {
        (Some(p), _) => Camera::new(
            to_render(p.eye),
            to_render(p.target),
            p.up.as_vec3(),
            fov,
            w,
            h,
        ),
        (None, Some((from, to))) => {
            Camera::new(to_render(from), to_render(to), s.camera_up, fov, w, h)
        }
        (None, None) => {
            return Err(Error::input(
                "[camera] a lens or clipping needs a placed camera (`from`/`to` or `matrix`)",
            ))
        }
    };
    if let Some(p) = placement.filter(|p| p.poses.len() > 1) {
        let poses: Vec<(f32, CameraPose)> = resample(&p.poses)
            .into_iter()
            .map(|(t, pos, rot)| {
                (
                    t,
                    CameraPose {
                        position: to_render(pos),
                        rotation: rot.as_quat().normalize(),
                    },
                )
            })
            .collect();
        camera = camera.with_motion(CameraMotion::new(&poses)?);
    }
    // The far plane is not clipped: rays end where the medium does.
    if let Some([near, _far]) = c.clipping {
        camera = camera.with_near_clip(near);
    }
    Ok(Some(camera))
}

/// At most the camera's pose capacity, evenly chosen, ends kept.
fn resample(poses: &[(f32, DVec3, glam::DQuat)]) -> Vec<(f32, DVec3, glam::DQuat)> {
    let max = cirrus_kernel::camera_motion::MAX_POSES;
    if poses.len() <= max {
        return poses.to_vec();
    }
    (0..max)
        .map(|k| poses[k * (poses.len() - 1) / (max - 1)])
        .collect()
}
