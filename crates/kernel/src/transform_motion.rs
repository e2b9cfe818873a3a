//! Motion blur from a moving transform: a field whose placement changes
//! over the shutter (an animated USD xform, time-sampled matrices of a
//! scene file), as opposed to matter moving inside it (a velocity grid).
//!
//! [`MovingField`] wraps a field placed at the frame's own instant (time 0)
//! and a [`PoseTable`]: at shutter time t a render-space point p maps to
//! the point of the still placement it shows, `table(t) p`, tabulated at
//! evenly spaced times and interpolated linearly between them. Lookups at
//! time t read the still field there. The walk's majorants come from a
//! second field (`bound`) whose segments bound the density of every pose:
//! the caller builds it from the volume's bounds dilated by the farthest a
//! point moves in voxels ([`PoseTable::reach`]), as velocity motion does.
//! A still field (no table) is the wrapped field exactly, call for call.

use std::sync::Arc;

use glam::{Mat4, Vec3};

use crate::error::{Error, Result};
use crate::medium::{Bounds3, DensityField, Lattice};

/// Render-space maps from a shutter time's placement to the still one,
/// at evenly spaced times over `[open, close]`.
#[derive(Clone, Debug)]
pub struct PoseTable {
    open: f32,
    step: f32,
    maps: Vec<Mat4>,
}

impl PoseTable {
    /// `maps[k]` at time `open + k (close - open) / (maps.len() - 1)`; at
    /// least two maps and `close > open`.
    pub fn new(open: f32, close: f32, maps: Vec<Mat4>) -> Result<PoseTable> {
        if maps.len() < 2
            || close.partial_cmp(&open) != Some(std::cmp::Ordering::Greater)
            || !open.is_finite()
            || !close.is_finite()
        {
            return Err(Error::invalid(format!(
                "a pose table needs two or more maps over open < close, got {} over [{open}, {close}]",
                maps.len()
            )));
        }
        if maps.iter().any(|m| !m.is_finite()) {
            return Err(Error::invalid("a pose table's maps must be finite"));
        }
        let step = (close - open) / (maps.len() - 1) as f32;
        Ok(PoseTable { open, step, maps })
    }

    /// The map at `time`, clamped to the shutter.
    #[inline]
    pub fn at(&self, time: f32) -> Mat4 {
        let x = ((time - self.open) / self.step).max(0.0);
        let last = self.maps.len() - 1;
        let i = (x as usize).min(last - 1);
        let u = (x - i as f32).min(1.0);
        let (a, b) = (&self.maps[i], &self.maps[i + 1]);
        Mat4::from_cols(
            a.x_axis.lerp(b.x_axis, u),
            a.y_axis.lerp(b.y_axis, u),
            a.z_axis.lerp(b.z_axis, u),
            a.w_axis.lerp(b.w_axis, u),
        )
    }

    /// Per axis of a field's local space (`local_from_render`), the
    /// farthest a point inside `local_box` is from the point any map of
    /// the table shows there: how far majorants must reach. Interpolated
    /// maps stay within the tabulated ones' reach at the box's corners (a
    /// convex combination), and the caller pads for rounding.
    pub fn reach(&self, local_from_render: Mat4, local_box: Bounds3) -> Vec3 {
        let render_from_local = local_from_render.inverse();
        let mut reach = Vec3::ZERO;
        for m in &self.maps {
            let local = local_from_render * *m * render_from_local;
            for c in local_box.corners() {
                // A point that shows c moves to c; its distance in voxels.
                let inverse = local.inverse().transform_point3(c);
                reach = reach.max((inverse - c).abs());
            }
        }
        reach
    }

    /// `bounds` (render space, still) grown to every pose's.
    pub fn swept(&self, bounds: Bounds3) -> Bounds3 {
        let mut out = bounds;
        for m in &self.maps {
            let inverse = m.inverse();
            for c in bounds.corners() {
                let p = inverse.transform_point3(c);
                out = out.union(Bounds3::new(p, p));
            }
        }
        out
    }
}

/// A field that may move by a transform over the shutter; see the module doc.
pub struct MovingField<F> {
    still: F,
    motion: Option<Motion<F>>,
}

struct Motion<F> {
    table: Arc<PoseTable>,
    /// Segments bounding every pose; `None` for fields never walked
    /// (emission grids), which only need [`MovingField::bounds`].
    bound: Option<F>,
    swept: Bounds3,
}

impl<F: DensityField> MovingField<F> {
    /// A field that does not move: the wrapped field exactly.
    pub fn still(field: F) -> Self {
        Self {
            still: field,
            motion: None,
        }
    }

    /// `still` moving through `table`, walked over `bound`'s segments
    /// (when it is walked at all).
    pub fn moving(still: F, table: Arc<PoseTable>, bound: Option<F>) -> Self {
        let swept = table.swept(still.bounds());
        let swept = match &bound {
            Some(b) => swept.union(b.bounds()),
            None => swept,
        };
        Self {
            still,
            motion: Some(Motion {
                table,
                bound,
                swept,
            }),
        }
    }

    /// Whether the field moves over the shutter.
    pub fn moves(&self) -> bool {
        self.motion.is_some()
    }

    /// The field placed at the frame's instant.
    pub fn still_field(&self) -> &F {
        &self.still
    }

    /// The field placed at the frame's instant, given back.
    pub fn into_still(self) -> F {
        self.still
    }

    fn walked(&self) -> &F {
        match &self.motion {
            Some(Motion { bound: Some(b), .. }) => b,
            _ => &self.still,
        }
    }
}

impl<F: DensityField> DensityField for MovingField<F> {
    type Segments<'a>
        = F::Segments<'a>
    where
        Self: 'a;

    fn bounds(&self) -> Bounds3 {
        match &self.motion {
            Some(m) => m.swept,
            None => self.still.bounds(),
        }
    }

    #[inline]
    fn density(&self, p: Vec3) -> f32 {
        self.still.density(p)
    }

    #[inline]
    fn density_at(&self, p: Vec3, time: f32) -> f32 {
        match &self.motion {
            None => self.still.density_at(p, time),
            Some(m) => self
                .still
                .density_at(m.table.at(time).transform_point3(p), time),
        }
    }

    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Segments<'_> {
        self.walked().segments(origin, dir, t_min, t_max)
    }

    /// The marchers render the frame's instant: the still field's march.
    fn march_lattice(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        self.still.march_lattice(origin, dir, t_max, lattice, visit)
    }

    fn global_majorant(&self) -> f32 {
        self.walked().global_majorant()
    }

    fn voxel_size(&self) -> f32 {
        self.still.voxel_size()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_interpolates_and_clamps() {
        let a = Mat4::IDENTITY;
        let b = Mat4::from_translation(Vec3::new(4.0, 0.0, 0.0));
        let t = PoseTable::new(-1.0, 1.0, vec![a, b]).unwrap();
        assert_eq!(t.at(-1.0), a);
        assert_eq!(t.at(1.0), b);
        assert_eq!(t.at(5.0), b);
        assert_eq!(t.at(-3.0), a);
        let mid = t.at(0.0).transform_point3(Vec3::ZERO);
        assert!((mid - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-6);
        let unit = Bounds3::new(Vec3::ZERO, Vec3::ONE);
        let reach = t.reach(Mat4::from_scale(Vec3::splat(2.0)), unit);
        // Four render units are eight voxels of a field of voxel size 0.5.
        assert!(
            (reach - Vec3::new(8.0, 0.0, 0.0)).length() < 1e-4,
            "{reach}"
        );
        let swept = t.swept(unit);
        assert!((swept.min - Vec3::new(-4.0, 0.0, 0.0)).length() < 1e-6);
        assert!(PoseTable::new(0.0, 0.0, vec![a, b]).is_err());
        assert!(PoseTable::new(0.0, 1.0, vec![a]).is_err());
    }
}
