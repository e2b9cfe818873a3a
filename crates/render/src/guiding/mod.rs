//! Path guiding: a radiance cache learned from the render's own paths, and
//! the sampling decisions it guides.
//!
//! - `regions`: a binary tree over the media refined where samples fall,
//!   each leaf a [`Region`] holding the mean incident radiance per
//!   direction bin and its mean in-scattered radiance (Müller, Gross,
//!   Novák 2017's SD-tree, with a fixed equal-area directional grid,
//!   `sphere`, in place of their quadtrees: inside a cloud the light that
//!   is not the sun's own is smooth).
//! - `learn`: what a path teaches the cache ([`PathRecorder`]).
//! - `training`: the fixed schedule of training passes over the whole
//!   frame ([`train`]).
//!
//! - `grid`: the in-scattered radiance on a pyramid of regular grids,
//!   finer than the regions, for roulette and splitting.
//!
//! A [`Guide`] is the cache frozen for a pass. It guides three decisions
//! ([`Decisions`]), each unbiased for any cache:
//! - roulette and splitting (`integrator/path_split.rs`, Vorba and
//!   Křivánek 2016): a path whose expected contribution, its throughput
//!   times the learned in-scattered radiance, falls far below what it was
//!   expected to bring at its first vertex plays roulette, one far above
//!   splits;
//! - directions (`integrator/path_scatter.rs`): a one-sample mixture of
//!   the phase function and the product of the phase function with the
//!   learned incident light (Herholz et al. 2019, "Volume Path Guiding
//!   Based on Zero-Variance Random Walk Theory", section 4), its density
//!   exact;
//! - distances (`tracking/guided.rs`): whether a tentative collision is
//!   real or null, weighed by the learned in-scattered radiance at it
//!   against the learned light arriving along the ray from beyond it
//!   (the same paper's section 5, in null-collision form).
//!
//! Measured on a thick, bright cloud and a thin sky-lit one (BENCHMARKS.md,
//! "Guided path tracing", "Guided distances") none pays yet at equal time,
//! so `auto` renders unguided.

mod grid;
mod learn;
mod regions;
mod sphere;
mod training;

pub use grid::InscatteredGrid;
pub use learn::{luminance, Ignore, Learner, PathRecorder};
pub use regions::{Record, Region, Regions, MAX_REGIONS};
pub use sphere::{bin_centres, BinDistribution, IncidentLight, BINS};

use sphere::bin_of;
pub use training::{train, Frame, TrainingSchedule};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::medium::Bounds3;
use crate::phase::Phase;

/// Whether the path tracer learns and follows a radiance cache, and which
/// decisions it guides ([`Decisions`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum GuidingMode {
    /// Where it pays. Measured against unguided rendering at equal time
    /// (BENCHMARKS.md, "Guided path tracing"), the guide as it stands
    /// pays on no scene yet, thick bright clouds included, so `auto`
    /// renders unguided: the same image, bit for bit, as `off`.
    #[default]
    Auto,
    /// Roulette and splitting against the learned in-scattered light.
    On,
    /// As `on`, and scattered directions resampled toward the learned
    /// incident light.
    Directions,
    /// As `directions`, and free flights' collisions guided by the learned
    /// in-scattered light. Chromatic media keep spectral tracking's
    /// unguided flights.
    Distances,
    Off,
}

impl GuidingMode {
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::On => "on",
            Self::Directions => "directions",
            Self::Distances => "distances",
            Self::Off => "off",
        }
    }

    /// The decisions a guide makes in this mode (`auto` as it resolves),
    /// `None` for unguided rendering.
    pub fn decisions(self) -> Option<Decisions> {
        match self {
            Self::Auto | Self::Off => None,
            Self::On => Some(Decisions {
                directions: false,
                roulette: true,
                distances: false,
            }),
            Self::Directions => Some(Decisions {
                directions: true,
                roulette: true,
                distances: false,
            }),
            Self::Distances => Some(Decisions {
                directions: true,
                roulette: true,
                distances: true,
            }),
        }
    }
}

/// Where a path vertex lies in the cache: its region and its grid cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Site {
    pub region: u32,
    pub cell: u32,
}

/// Which sampling decisions a guide makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decisions {
    /// Scattered directions resampled toward the learned incident light.
    pub directions: bool,
    /// Russian roulette and splitting against the learned in-scattered
    /// radiance (Vorba and Křivánek 2016).
    pub roulette: bool,
    /// Tentative collisions made real or null in proportion to what each
    /// choice is expected to bring (Herholz et al. 2019, section 5).
    pub distances: bool,
}

/// The radiance cache, frozen: what a pass's paths are guided by.
#[derive(Clone, Debug)]
pub struct Guide {
    regions: Regions,
    grid: InscatteredGrid,
    decisions: Decisions,
    /// Per region and direction bin, what a tentative collision on a ray
    /// along the bin is worth real over null (see
    /// [`Guide::collision_worth_along`]), 0 where there is no estimate;
    /// `None` where the region learned no light, and empty until
    /// [`Guide::scatter_light`].
    worth: Vec<Option<[f32; BINS]>>,
}

impl Guide {
    /// An empty cache over `bounds` (it guides nothing until it learns)
    /// making `decisions`.
    pub fn new(bounds: Bounds3, decisions: Decisions) -> Guide {
        Guide {
            regions: Regions::new(bounds),
            grid: InscatteredGrid::new(bounds),
            decisions,
            worth: Vec::new(),
        }
    }

    /// Where `p` lies in the cache.
    #[inline]
    pub fn site_of(&self, p: Vec3) -> Site {
        Site {
            region: self.regions.index_of(p),
            cell: self.grid.cell_of(p),
        }
    }

    /// The learned incident light that guides directions at `site`, if
    /// the guide guides directions and has learned there.
    #[inline]
    pub fn light(&self, site: Site) -> Option<&IncidentLight> {
        if !self.decisions.directions {
            return None;
        }
        self.regions.region(site.region).light()
    }

    /// The learned in-scattered radiance (luminance) at `site`, for
    /// roulette and splitting: the cell's mean where it has learned
    /// enough, else its region's; `None` where the guide does not do
    /// roulette or nothing was learned.
    #[inline]
    pub fn inscattered(&self, site: Site) -> Option<f32> {
        if !self.decisions.roulette {
            return None;
        }
        let l = self
            .grid
            .mean(site.cell)
            .unwrap_or_else(|| self.regions.region(site.region).inscattered());
        (l > 0.0).then_some(l)
    }

    /// Readies guided distances once learning is over: for each region
    /// and direction bin, its learned light scattered by `phase` back
    /// along a ray in that bin ([`IncidentLight::scattered`]), over its
    /// learned light arriving from that bin (the light beyond a collision
    /// that a null collision goes on to gather).
    pub fn scatter_light(&mut self, phase: &Phase) {
        if !self.decisions.distances {
            return;
        }
        self.worth = (0..self.regions.len() as u32)
            .map(|r| {
                let light = self.regions.region(r).light()?;
                let scattered = light.scattered(phase);
                Some(std::array::from_fn(|b| {
                    let worth = scattered[b] / light.bins()[b];
                    if worth.is_finite() && worth > 0.0 {
                        worth
                    } else {
                        0.0
                    }
                }))
            })
            .collect();
    }

    /// What a tentative collision at a point on a ray along `dir` is
    /// expected to bring if real, over what it brings if null, as a
    /// function of the point (the direction's bin found once per flight).
    /// It gives `None` where the guide does not guide distances or has not
    /// learned there.
    #[inline]
    pub fn collision_worth_along(&self, dir: Vec3) -> impl Fn(Vec3) -> Option<f32> + '_ {
        let bin = bin_of(dir);
        move |p| {
            let table = self
                .worth
                .get(self.regions.index_of(p) as usize)?
                .as_ref()?;
            let worth = table[bin];
            (worth > 0.0).then_some(worth)
        }
    }

    pub fn decisions(&self) -> Decisions {
        self.decisions
    }

    /// Learns records made with this guide's tree and grid.
    pub(crate) fn accumulate(&mut self, records: Vec<Record>) {
        for r in &records {
            self.grid.add(r.cell, r.inscattered);
        }
        self.regions.accumulate(records);
    }

    pub fn memory_bytes(&self) -> usize {
        self.regions.memory_bytes() + self.grid.memory_bytes()
    }

    pub fn regions(&self) -> &Regions {
        &self.regions
    }
}

/// The learned-stats of a render that followed a guide.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct GuidingStats {
    /// "on", "off", or with `auto` the choice ("auto: on").
    pub mode: String,
    pub training_passes: u32,
    /// Samples per pixel spent on training (not in the image).
    pub training_spp: u32,
    pub training_seconds: f64,
    pub regions: usize,
    pub memory_bytes: usize,
    /// Records the cache learned from.
    pub records: u64,
}
