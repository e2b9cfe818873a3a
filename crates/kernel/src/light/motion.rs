//! Lights that change while the shutter is open: the scene's lights
//! tabulated at evenly spaced times over the shutter, each table the
//! same lights in the same order (so light groups, the light choice's
//! indices and the shadow grid's slots mean the same in each). A camera
//! sample renders with the table nearest its time: a light's values are
//! off by at most half a step of its change over the shutter, a
//! `1 / (2 (TABLES - 1))` part (0.8% with the scene's 65 tables, the
//! resolution moving volumes' transforms are tabulated at).

use super::Lights;

/// The lights at `tables.len()` evenly spaced times from `open` to
/// `close` (frames).
#[derive(Clone, Debug)]
pub struct LightsOverShutter {
    open: f32,
    step: f32,
    tables: Vec<Lights>,
}

impl LightsOverShutter {
    /// `tables[k]` holds the lights at `open + k (close - open) / (n - 1)`;
    /// `None` unless there are two tables or more over an open shutter,
    /// all of the same lights (count and groups).
    pub fn new(open: f32, close: f32, tables: Vec<Lights>) -> Option<Self> {
        let first = tables.first()?;
        let same = tables
            .iter()
            .all(|t| t.len() == first.len() && t.groups == first.groups);
        (tables.len() >= 2 && close > open && same).then(|| Self {
            open,
            step: (close - open) / (tables.len() - 1) as f32,
            tables,
        })
    }

    /// The index of the table nearest `time`.
    #[inline]
    pub fn index_at(&self, time: f32) -> usize {
        let x = ((time - self.open) / self.step).round();
        (x.max(0.0) as usize).min(self.tables.len() - 1)
    }

    /// The tables, in time order.
    pub fn tables(&self) -> &[Lights] {
        &self.tables
    }

    /// Each table mapped by `f` (the same map as the frame's lights).
    pub(super) fn map(&self, f: impl Fn(Lights) -> Lights) -> Self {
        Self {
            open: self.open,
            step: self.step,
            tables: self.tables.iter().cloned().map(f).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{Light, SphereLight};
    use glam::Vec3;

    fn at(x: f32) -> Lights {
        Lights::new([Light::from(SphereLight::new(
            Vec3::new(x, 0.0, 0.0),
            0.0,
            Vec3::ONE,
        ))])
    }

    #[test]
    fn a_time_takes_the_nearest_table_clamped_to_the_shutter() {
        let m = LightsOverShutter::new(-0.5, 0.5, (0..5).map(|k| at(k as f32)).collect()).unwrap();
        // Tables at -0.5, -0.25, 0, 0.25, 0.5.
        assert_eq!(m.index_at(-0.5), 0);
        assert_eq!(m.index_at(-0.37), 1);
        assert_eq!(m.index_at(-0.38), 0);
        assert_eq!(m.index_at(0.0), 2);
        assert_eq!(m.index_at(0.13), 3);
        assert_eq!(m.index_at(0.5), 4);
        assert_eq!(m.index_at(-9.0), 0);
        assert_eq!(m.index_at(9.0), 4);
    }

    #[test]
    fn tables_must_be_two_or_more_of_the_same_lights_over_an_open_shutter() {
        assert!(LightsOverShutter::new(0.0, 1.0, vec![at(0.0)]).is_none());
        assert!(LightsOverShutter::new(0.0, 0.0, vec![at(0.0), at(1.0)]).is_none());
        let two = Lights::new([at(0.0).get(0).clone(), at(1.0).get(0).clone()]);
        assert!(LightsOverShutter::new(0.0, 1.0, vec![at(0.0), two]).is_none());
        assert!(LightsOverShutter::new(0.0, 1.0, vec![at(0.0), at(1.0)]).is_some());
    }
}
