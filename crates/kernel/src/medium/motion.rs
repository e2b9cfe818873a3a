//! Motion blur from a velocity grid, for a [`BrickField`](super::BrickField).
//!
//! Eulerian lookup, as Arnold and RenderMan do for grid velocity: the
//! density at point `x` and time `t` is the frame's density at
//! `x - v(x) * t` (velocity sampled at the frame's own instant, t_ref = 0,
//! at `x` itself rather than traced back), in the field's local index
//! space. Majorants come from the volume's motion shell
//! ([`BrickVolume::motion_shell`]), dilated by the largest displacement
//! the velocity grid allows over the shutter.

use std::sync::Arc;

use cirrus_bricks::{BrickError, BrickVolume, VelocityGrid};
use glam::{DMat3, DMat4, Mat3, Mat4, Vec3};

use crate::shutter::Shutter;

settings_enum! {
    /// What a velocity value means.
    pub enum VelocityUnit {
        /// World units (of the grid's file, before any instance transform)
        /// per frame.
        #[default]
        World = "world",
        /// Voxels of the velocity grid per frame.
        Voxels = "voxels",
    }
}

/// A velocity grid and how its values move a field.
#[derive(Clone, Debug)]
pub struct Velocity {
    pub grid: Arc<VelocityGrid>,
    pub unit: VelocityUnit,
    /// Multiplies every value (e.g. 1/24 for metres per second at 24 fps).
    pub scale: f32,
}

/// A field's motion: where its velocity is and how far it moves.
pub(crate) struct Motion {
    grid: Arc<VelocityGrid>,
    /// Velocity-grid index coordinates from the field's local coordinates.
    velocity_from_local: Mat4,
    /// The field's local displacement per frame for a velocity value.
    displacement: Mat3,
    /// The dilated bounds the walk uses instead of the volume's.
    pub shell: BrickVolume,
    /// Shell-local coordinates = field-local + `shell_offset`.
    pub shell_offset: Vec3,
}

impl Motion {
    /// The motion of `volume` (placed with `world_from_local`, the grid's
    /// world space from its local index space) over `shutter`.
    pub fn new(
        volume: &BrickVolume,
        velocity: &Velocity,
        shutter: Shutter,
    ) -> Result<Motion, BrickError> {
        let grid = &velocity.grid;
        let local_from_world = volume.local_from_world();
        let velocity_from_local = grid.index_from_world() * local_from_world.inverse();
        let linear = |m: DMat4| DMat3::from_mat4(m);
        let world_from_value = match velocity.unit {
            VelocityUnit::World => DMat3::IDENTITY,
            VelocityUnit::Voxels => linear(grid.index_to_world),
        };
        let displacement = linear(local_from_world) * world_from_value * f64::from(velocity.scale);
        if !displacement.is_finite() {
            return Err(BrickError::Unsupported(format!(
                "velocity grid {}: scale {} gives no finite displacement",
                grid.name, velocity.scale
            )));
        }
        let radius =
            max_displacement(displacement.as_mat3(), grid.max_abs()) * shutter.max_abs_time();
        // Slack for the f32 rounding of `x - d t` and of the matrices.
        let radius = radius * (1.0 + 1e-4) + 1e-3;
        let shell = volume.motion_shell(radius)?;
        Ok(Motion {
            shell_offset: volume.shell_offset(&shell),
            shell,
            velocity_from_local: velocity_from_local.as_mat4(),
            displacement: displacement.as_mat3(),
            grid: grid.clone(),
        })
    }

    /// The local point whose frame density is seen at local `q` at `time`.
    #[inline]
    pub fn source(&self, q: Vec3, time: f32) -> Vec3 {
        let v = self
            .grid
            .trilinear(self.velocity_from_local.transform_point3(q));
        q - (self.displacement * v) * time
    }
}

/// Per local axis, the largest `|(m v)_i|` for `|v_j| <= max_abs_j`.
fn max_displacement(m: Mat3, max_abs: Vec3) -> Vec3 {
    let a = Mat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
    a * max_abs
}
