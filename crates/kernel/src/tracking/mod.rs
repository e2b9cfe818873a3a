//! Null-collision trackers over a field's majorant segments: free-flight
//! sampling (`delta`) and three transmittance estimators (`ratio`,
//! `residual`, `track_length`), all built on the walk in `walk`. Each is
//! written once over a [`Spectrum`]: `f32` for grey media, `Vec3` for
//! chromatic ones (extinction per RGB channel), where free flights take
//! spectral tracking and shadow rays per-channel ratio tracking.
//!
//! Every tracker caps its collisions per call at [`MAX_COLLISIONS`]
//! (counted in `Counters::collision_cap_hits`; a capped call returns zero
//! transmittance / ends the path), so an infinite or NaN majorant cannot hang
//! a render. The ratio estimators use pbrt-v4's Russian roulette
//! ([`Spectrum::roulette`]).

mod delta;
mod lookup;
mod ratio;
mod residual;
pub(crate) mod roulette;
mod track_length;
mod walk;

pub use delta::{sample_free_flight, sample_free_flight_pair, FreeFlight};
pub use ratio::ratio_tracking;
pub use residual::residual_ratio_tracking;
pub use track_length::track_length_transmittance;

use crate::counters::Counters;
use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::spectrum::Spectrum;

/// Hard cap on tentative collisions in one tracker call.
pub const MAX_COLLISIONS: u32 = 1_000_000;

pub use roulette::{ROULETTE_Q, ROULETTE_THRESHOLD};

settings_enum! {
    /// How shadow rays estimate transmittance.
    ///
    /// Residual ratio tracking is the default: in BENCHMARKS.md it is 1.07x to
    /// 1.17x as efficient as plain ratio tracking over the hierarchy, with less
    /// noise per path than track-length.
    pub enum TransmittanceEstimator {
        /// Ratio tracking (Novak, Selle, Jarosz 2014).
        Ratio = "ratio",
        /// Residual ratio tracking with the segment minorant as control
        /// (Novak et al. 2014, section 5). Chromatic media take ratio tracking
        /// instead: the segments' one minorant (of the largest channel summed
        /// over instances) is no control for each channel.
        #[default]
        Residual = "residual",
        /// Track-length estimation: 1 if a delta-tracked flight escapes, else 0.
        TrackLength = "track-length",
    }
}

settings_enum! {
    /// Which majorants the trackers use.
    pub enum MajorantMode {
        // The host renders the probe (cirrus_render::majorant_choice).
        /// Whichever of the two a probe of about a thousand paths of the
        /// scene finds cheaper (`--stats` says which).
        #[default]
        Auto = "auto",
        /// The field's own local segments (its hierarchy or grid).
        Hierarchy = "hierarchy",
        /// One global majorant over the field's bounds (Mitsuba 3 style).
        Global = "global",
    }
}

/// Transmittance along `ray` over `[0, t_max]` by the chosen estimator,
/// per channel of `S`; counts one shadow ray.
pub fn transmittance<S: Spectrum, M: Media>(
    estimator: TransmittanceEstimator,
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    c: &mut Counters,
) -> S {
    match estimator {
        TransmittanceEstimator::Residual if !S::CHROMATIC => {
            S::splat(residual_ratio_tracking(medium, ray, t_max, rng, c))
        }
        TransmittanceEstimator::Ratio | TransmittanceEstimator::Residual => {
            ratio_tracking(medium, ray, t_max, rng, c)
        }
        TransmittanceEstimator::TrackLength => {
            track_length_transmittance(medium, ray, t_max, rng, c)
        }
    }
}
