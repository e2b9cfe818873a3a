//! Where the path tracer samples distances along a ray: a setting, apart
//! from the equi-angular strategy (`path_equiangular.rs`) so that the
//! tracer can hold it.

use crate::medium::Media;

settings_enum! {
    /// How the path tracer samples where light scatters along a ray.
    pub enum DistanceSampling {
        // "3 mean free paths" is THIN_OPTICAL_DEPTH.
        /// `equiangular` where the media are thin (under 3 mean free paths
        /// across at their densest), free flights alone otherwise.
        #[default]
        Auto = "auto",
        /// Free flights, and equi-angular sampling toward sphere, point and
        /// spot lights, weighed by MIS.
        Equiangular = "equiangular",
        /// Free flights alone.
        FreeFlight = "free-flight",
    }
}

/// `auto` samples equi-angularly where the media's densest extinction
/// times their box's smallest side is under this. Measured
/// (BENCHMARKS.md, "Equi-angular sampling"): a beam in fog (0.26) gains
/// 14x, a lamp in the corpus cloud at 2 gains 10x, at 6 loses 0.7x, at 20
/// loses 0.24x (in a thick cloud the collision already falls where the
/// light arrives, and the second transmittance walk doubles a segment's
/// cost).
pub const THIN_OPTICAL_DEPTH: f32 = 3.0;

impl DistanceSampling {
    /// Whether segments in `media` take an equi-angular sample.
    pub fn samples_equiangular<M: Media>(self, media: &M) -> bool {
        match self {
            Self::Equiangular => true,
            Self::FreeFlight => false,
            Self::Auto => {
                let b = media.bounds();
                let side = (b.max - b.min).min_element();
                media.max_sigma_t() * side < THIN_OPTICAL_DEPTH
            }
        }
    }
}
