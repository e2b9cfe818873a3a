//! Counts, bounds and value ranges of a tree, as `vdb_print -l` reports them.

use super::*;

/// Active tiles per level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TileCounts {
    /// 8^3 tiles in lower nodes.
    pub lower: u64,
    /// 128^3 tiles in upper nodes.
    pub upper: u64,
    /// 4096^3 tiles in the root.
    pub root: u64,
}

impl TileCounts {
    pub fn total(&self) -> u64 {
        self.lower + self.upper + self.root
    }
}

/// Component-wise minimum and maximum over the active values, NaN excluded
/// (`nan_count` says how many were left out).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ValueRange {
    pub min: [f64; 3],
    pub max: [f64; 3],
    /// 1 for scalars, 3 for vectors.
    pub components: usize,
    pub nan_count: u64,
}

impl ValueRange {
    /// Widens `range` (`None` before the first value) to the first `k`
    /// components of `c`; returns false, leaving it alone, for a value
    /// with a NaN component, which the caller counts.
    #[inline]
    pub fn include(range: &mut Option<ValueRange>, c: [f64; 3], k: usize) -> bool {
        if c[..k].iter().any(|x| x.is_nan()) {
            return false;
        }
        match range {
            None => {
                *range = Some(ValueRange {
                    min: c,
                    max: c,
                    components: k,
                    nan_count: 0,
                })
            }
            Some(r) => {
                for (i, &x) in c.iter().enumerate().take(k) {
                    r.min[i] = r.min[i].min(x);
                    r.max[i] = r.max[i].max(x);
                }
            }
        }
        true
    }
}

impl<V: Value> Tree<V> {
    /// Active voxels, with every active tile counted at its full volume.
    pub fn active_voxel_count(&self) -> u64 {
        let mut n: u64 = self
            .leaves
            .iter()
            .map(|l| l.value_mask.count_on() as u64)
            .sum();
        self.for_each_active_tile(|b, _, _| n += b.volume());
        n
    }

    pub fn active_tile_counts(&self) -> TileCounts {
        let mut t = TileCounts::default();
        self.for_each_active_tile(|_, _, level| match level {
            Level::Lower => t.lower += 1,
            Level::Upper => t.upper += 1,
            _ => t.root += 1,
        });
        t
    }

    /// The inclusive box over the centres of active voxels and tile voxels,
    /// as OpenVDB's `evalActiveVoxelBoundingBox`; `None` when nothing is active.
    pub fn active_bbox(&self) -> Option<CoordBBox> {
        let mut bbox: Option<CoordBBox> = None;
        let mut add = |b: CoordBBox| bbox = Some(bbox.map_or(b, |a| a.union(b)));
        for leaf in &self.leaves {
            if leaf.value_mask.is_off() {
                continue;
            }
            // Per axis, the extent of the on bits: scan the mask once.
            let (mut lo, mut hi) = (Coord::splat(7), Coord::splat(0));
            for n in leaf.value_mask.iter_on() {
                let c = Coord::new((n >> 6) as i32, ((n >> 3) & 7) as i32, (n & 7) as i32);
                lo = lo.min(c);
                hi = hi.max(c);
            }
            add(CoordBBox::new(leaf.origin + lo, leaf.origin + hi));
        }
        self.for_each_active_tile(|b, _, _| add(b));
        bbox
    }

    /// Range of the active values, tiles included; `None` when nothing is active.
    pub fn value_range(&self) -> Option<ValueRange> {
        let mut r: Option<ValueRange> = None;
        let mut nan = 0u64;
        let mut add = |v: V| {
            let (c, k) = v.components();
            if !ValueRange::include(&mut r, c, k) {
                nan += 1;
            }
        };
        for leaf in &self.leaves {
            for n in leaf.value_mask.iter_on() {
                add(leaf.values[n]);
            }
        }
        self.for_each_active_tile(|_, v, _| add(v));
        r.map(|mut r| {
            r.nan_count = nan;
            r
        })
    }
}
