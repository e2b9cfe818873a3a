//! The film side of the compositing layers: per-tile accumulators, fed
//! sample by sample next to the beauty, and the resolved images.

use glam::{DVec3, Vec3};
use smallvec::SmallVec;

use super::deep::{DeepPixel, DeepSample};
use super::Compositing;
use cirrus_kernel::integrator::Sample;

/// What one tile keeps for the layers its render asked for; every vector
/// is empty when its layer is off.
#[derive(Default)]
pub(crate) struct TileLayers {
    groups: usize,
    /// Per pixel, `groups` running sums (f64, so the means sum to the
    /// beauty's to its own rounding).
    group_sums: Vec<DVec3>,
    /// Per pixel, (instance, samples whose camera ray first collided in it).
    coverage: Vec<SmallVec<[(u32, u32); 2]>>,
    deep: Vec<DeepPixel>,
}

impl TileLayers {
    pub fn new(c: &Compositing, pixels: usize) -> Self {
        let groups = c.light_groups.len();
        Self {
            groups,
            group_sums: vec![DVec3::ZERO; pixels * groups],
            coverage: if c.cryptomatte {
                vec![SmallVec::new(); pixels]
            } else {
                Vec::new()
            },
            deep: if c.deep_samples.is_some() {
                vec![DeepPixel::default(); pixels]
            } else {
                Vec::new()
            },
        }
    }

    /// Adds pixel `i`'s sample `s`; `finite`: whether the film kept its
    /// beauty (a non-finite sample counts as zero everywhere); `view_cos`
    /// turns its distance along the camera ray into planar depth.
    #[inline]
    pub fn add(&mut self, i: usize, s: &Sample, finite: bool, view_cos: f32) {
        if self.groups > 0 {
            let groups = &s.groups[..self.groups];
            let ok = finite && groups.iter().all(|g| g.is_finite());
            for (sum, g) in self.group_sums[i * self.groups..].iter_mut().zip(groups) {
                if ok {
                    *sum += g.as_dvec3();
                }
            }
        }
        let visible = s.aov.instance.filter(|_| finite);
        if let (Some(cov), Some(inst)) = (self.coverage.get_mut(i), visible) {
            match cov.iter_mut().find(|(k, _)| *k == inst) {
                Some(entry) => entry.1 += 1,
                None => cov.push((inst, 1)),
            }
        }
        if let Some(deep) = self.deep.get_mut(i) {
            let l = if finite { s.radiance } else { Vec3::ZERO };
            deep.add(visible.and(s.aov.depth).map(|t| t * view_cos), l);
        }
    }
}

/// The compositing layers of a render (or of its crop window), row-major
/// like [`Image::rgba`](crate::Image).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Layers {
    /// Layer names of the light groups, in group order.
    pub group_names: Vec<String>,
    /// Per group, each pixel's mean radiance.
    pub groups: Vec<Vec<[f32; 3]>>,
    /// Per pixel, (instance, fraction of samples whose camera ray first
    /// collided in it); empty without Cryptomatte.
    pub coverage: Vec<Vec<(u32, f32)>>,
    /// Per pixel, its deep samples front to back; empty without deep.
    pub deep: Vec<Vec<DeepSample>>,
}

/// Resolves the layers of `tiles`, each pixel over its `count(tile, i)`
/// samples, into a `width x height` window at `(x0, y0)`.
pub(crate) fn resolve<'a, T: 'a>(
    c: &Compositing,
    window: (u32, u32, u32, u32),
    tiles: impl Iterator<Item = (&'a TileLayers, (u32, u32, u32, u32), &'a T)>,
    count: impl Fn(&T, usize) -> u32,
) -> Layers {
    let (x0, y0, width, height) = window;
    let n = (width * height) as usize;
    let groups = c.light_groups.len();
    let mut out = Layers {
        group_names: c.light_groups.clone(),
        groups: vec![vec![[0.0; 3]; n]; groups],
        coverage: if c.cryptomatte {
            vec![Vec::new(); n]
        } else {
            Vec::new()
        },
        deep: if c.deep_samples.is_some() {
            vec![Vec::new(); n]
        } else {
            Vec::new()
        },
    };
    let max_deep = c.deep_samples.unwrap_or(1) as usize;
    for (layers, (tx0, ty0, tw, th), tile) in tiles {
        for ty in 0..th {
            for tx in 0..tw {
                let local = (ty * tw + tx) as usize;
                let i = ((ty0 - y0 + ty) * width + tx0 - x0 + tx) as usize;
                let samples = count(tile, local);
                let inv = 1.0 / f64::from(samples.max(1));
                for g in 0..groups {
                    out.groups[g][i] = (layers.group_sums[local * groups + g] * inv)
                        .as_vec3()
                        .to_array();
                }
                if let Some(cov) = layers.coverage.get(local) {
                    out.coverage[i] = cov
                        .iter()
                        .map(|&(inst, hits)| (inst, (f64::from(hits) * inv) as f32))
                        .collect();
                }
                if let Some(deep) = layers.deep.get(local) {
                    out.deep[i] = deep.resolve(samples, max_deep);
                }
            }
        }
    }
    out
}
