//! Where the path tracer runs sunward scattering (`path_sunward.rs`): a
//! setting, apart from the strategy so that the tracer can hold it.

use crate::phase::Phase;

settings_enum! {
    /// Where sunward scattering runs.
    pub enum Sunward {
        // 0.6 is FORWARD_MEAN_COSINE.
        /// At vertices whose phase function's mean cosine is at least 0.6
        /// (forward scattering, where it was measured to pay).
        #[default]
        Auto = "auto",
        /// At every vertex under a sun.
        On = "on",
        /// Never.
        Off = "off",
    }
}

impl Sunward {
    /// Whether the strategy runs at a vertex scattering by `phase`.
    #[inline]
    pub fn runs_at(self, phase: &Phase) -> bool {
        match self {
            Self::Auto => phase.mean_cosine() >= FORWARD_MEAN_COSINE,
            Self::On => true,
            Self::Off => false,
        }
    }
}

/// `auto`'s threshold: between the measured break-even (g 0.5, 0.96x) and
/// the first gain (g 0.65, 1.26x).
pub const FORWARD_MEAN_COSINE: f32 = 0.6;
