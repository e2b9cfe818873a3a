//! The spatial half of the radiance cache: a binary tree over the media's
//! bounds whose leaves are [`Region`]s, refined where samples fall
//! (Müller, Gross, Novák 2017, "Practical Path Guiding": a leaf splits at
//! its longest axis's midpoint once it has seen more than
//! [`SPLIT_RECORDS`] samples in a training pass), each region holding what
//! was learned there: the mean incident radiance per direction bin
//! (`sphere.rs`) and the mean in-scattered radiance.

use glam::Vec3;

use super::sphere::{IncidentLight, BINS};
use crate::medium::Bounds3;

/// A leaf splits once a training pass recorded more than this many
/// samples in it.
pub const SPLIT_RECORDS: u32 = 4_000;
/// At most this many regions (about 1.6 kB each): the cache's memory bound.
pub const MAX_REGIONS: usize = 16_384;
/// A region guides once it has learned from this many samples.
pub const MIN_RECORDS: u32 = 128;

/// One sample of the light arriving at a path vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    /// The leaf the vertex lies in (valid for the tree it was made with).
    pub region: u32,
    /// The vertex's cell in the in-scattered grid.
    pub cell: u32,
    /// The bin of the direction the path left along.
    pub bin: u16,
    /// An estimate of the radiance that arrived along that direction
    /// (luminance).
    pub incident: f32,
    /// An estimate of the in-scattered radiance at the vertex (luminance,
    /// phase-weighted incident light, direct included).
    pub inscattered: f32,
}

/// What one leaf has learned.
#[derive(Clone, Debug)]
pub struct Region {
    bounds: Bounds3,
    /// Sum of the records' incident radiance, and their count, per
    /// direction bin.
    incident: [f32; BINS],
    counts: [u32; BINS],
    /// Records in all passes, and in the current one.
    records: u32,
    pass_records: u32,
    inscattered_sum: f64,
    /// What guides sampling, once it has enough records.
    light: Option<IncidentLight>,
}

impl Region {
    fn new(bounds: Bounds3) -> Region {
        Region {
            bounds,
            incident: [0.0; BINS],
            counts: [0; BINS],
            records: 0,
            pass_records: 0,
            inscattered_sum: 0.0,
            light: None,
        }
    }

    /// The learned incident radiance over directions.
    #[inline]
    pub fn light(&self) -> Option<&IncidentLight> {
        self.light.as_ref()
    }

    /// The mean in-scattered radiance (luminance) of the samples seen.
    pub fn inscattered(&self) -> f32 {
        if self.records == 0 {
            return 0.0;
        }
        (self.inscattered_sum / f64::from(self.records)) as f32
    }

    fn add(&mut self, r: &Record) {
        let bin = usize::from(r.bin);
        if r.incident.is_finite() {
            self.incident[bin] += r.incident.max(0.0);
            self.counts[bin] += 1;
        }
        if r.inscattered.is_finite() {
            self.inscattered_sum += f64::from(r.inscattered.max(0.0));
        }
        self.records += 1;
        self.pass_records += 1;
    }

    /// The two halves of this region at its longest axis's midpoint, each
    /// starting from half of what it learned.
    fn split(&self) -> (u8, f32, Region, Region) {
        let size = self.bounds.size();
        let axis = if size.x >= size.y && size.x >= size.z {
            0
        } else if size.y >= size.z {
            1
        } else {
            2
        };
        let mid = 0.5 * (self.bounds.min[axis] + self.bounds.max[axis]);
        let half = |lo: bool| {
            let (mut min, mut max) = (self.bounds.min, self.bounds.max);
            if lo {
                max[axis] = mid;
            } else {
                min[axis] = mid;
            }
            let mut r = Region::new(Bounds3::new(min, max));
            for (a, b) in r.incident.iter_mut().zip(&self.incident) {
                *a = 0.5 * b;
            }
            for (a, b) in r.counts.iter_mut().zip(&self.counts) {
                *a = b / 2;
            }
            r.records = self.records / 2;
            // The halves keep the mean in-scattered radiance exactly.
            r.inscattered_sum = if self.records == 0 {
                0.0
            } else {
                self.inscattered_sum * f64::from(r.records) / f64::from(self.records)
            };
            r.light = self.light.clone();
            r
        };
        (axis as u8, mid, half(true), half(false))
    }
}

/// A node of the tree: a split, or a leaf's region index.
#[derive(Clone, Copy, Debug)]
enum Node {
    Split { axis: u8, at: f32, low: u32 },
    Leaf(u32),
}

/// The tree of regions over the media's bounds.
#[derive(Clone, Debug)]
pub struct Regions {
    nodes: Vec<Node>,
    regions: Vec<Region>,
}

impl Regions {
    /// One region over `bounds`.
    pub fn new(bounds: Bounds3) -> Regions {
        Regions {
            nodes: vec![Node::Leaf(0)],
            regions: vec![Region::new(bounds)],
        }
    }

    /// The index of the region holding `p` (points outside the bounds
    /// take the nearest leaf along each split).
    #[inline]
    pub fn index_of(&self, p: Vec3) -> u32 {
        let mut node = 0usize;
        loop {
            match self.nodes[node] {
                Node::Leaf(r) => return r,
                Node::Split { axis, at, low } => {
                    node = low as usize + usize::from(p[axis as usize] >= at);
                }
            }
        }
    }

    #[inline]
    pub fn region(&self, index: u32) -> &Region {
        &self.regions[index as usize]
    }

    pub fn len(&self) -> usize {
        self.regions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.regions.is_empty()
    }

    /// Bytes the tree and its regions hold.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>()
            + self.regions.capacity() * std::mem::size_of::<Region>()
    }

    /// Adds records made with this tree (in a fixed order, so the sums do
    /// not depend on thread count). The distributions guiding the pass
    /// are left as they are until [`Regions::finish_pass`].
    pub fn accumulate(&mut self, records: impl IntoIterator<Item = Record>) {
        for r in records {
            if let Some(region) = self.regions.get_mut(r.region as usize) {
                region.add(&r);
            }
        }
    }

    /// Ends a training pass: splits the regions that saw many records and
    /// rebuilds every distribution from what was learned.
    pub fn finish_pass(&mut self) {
        self.split_busy();
        for region in &mut self.regions {
            region.pass_records = 0;
            region.light = if region.records >= MIN_RECORDS {
                IncidentLight::new(&region.incident, &region.counts)
            } else {
                None
            };
        }
    }

    /// Splits each leaf that saw more than [`SPLIT_RECORDS`] samples this
    /// pass, in node order (so the tree is a function of the records
    /// alone), while the tree holds fewer than [`MAX_REGIONS`].
    fn split_busy(&mut self) {
        for n in 0..self.nodes.len() {
            if self.regions.len() >= MAX_REGIONS {
                break;
            }
            let Node::Leaf(r) = self.nodes[n] else {
                continue;
            };
            if self.regions[r as usize].pass_records <= SPLIT_RECORDS {
                continue;
            }
            let (axis, at, low, high) = self.regions[r as usize].split();
            let low_node = self.nodes.len() as u32;
            // The low half keeps the region's index, the high half is new.
            self.regions[r as usize] = low;
            self.regions.push(high);
            self.nodes.push(Node::Leaf(r));
            self.nodes.push(Node::Leaf(self.regions.len() as u32 - 1));
            self.nodes[n] = Node::Split {
                axis,
                at,
                low: low_node,
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records concentrated in one corner split the regions there, and
    /// every point finds the leaf whose bounds contain it.
    #[test]
    fn busy_regions_split_and_points_find_their_leaf() {
        let mut tree = Regions::new(Bounds3::new(Vec3::ZERO, Vec3::splat(8.0)));
        for _ in 0..8 {
            let mut records = Vec::new();
            for k in 0..20_000u32 {
                let p = Vec3::new(
                    (k % 97) as f32 / 97.0,
                    (k % 89) as f32 / 89.0,
                    (k % 83) as f32 / 83.0,
                );
                records.push(Record {
                    region: tree.index_of(p),
                    cell: 0,
                    bin: (k % 7) as u16,
                    incident: if k % 7 == 3 { 5.0 } else { 1.0 },
                    inscattered: 2.0,
                });
            }
            tree.accumulate(records);
            tree.finish_pass();
        }
        assert!(tree.len() > 8, "{} regions", tree.len());
        let corner = tree.region(tree.index_of(Vec3::splat(0.5)));
        assert!(corner.bounds.size().max_element() < 4.0);
        assert!((corner.inscattered() - 2.0).abs() < 1e-5);
        let light = corner.light().expect("learned");
        let bin3 = crate::guiding::sphere::bin_centre(3);
        assert!(light.radiance(bin3) > light.radiance(-bin3));
        for k in 0..500 {
            let p = Vec3::new(
                (k * 37 % 800) as f32 / 100.0,
                (k * 11 % 800) as f32 / 100.0,
                (k * 23 % 800) as f32 / 100.0,
            );
            let b = tree.region(tree.index_of(p)).bounds;
            assert!(p.cmpge(b.min).all() && p.cmple(b.max).all(), "{p} in {b:?}");
        }
    }
}
