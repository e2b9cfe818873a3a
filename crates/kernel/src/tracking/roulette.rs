//! Russian roulette on a transmittance estimate, shared by the trackers,
//! the spectra they carry (`Spectrum::roulette`) and the marchers: once an
//! estimate is small, most of its remaining work buys little.

/// pbrt-v4 (`TraceTransmittance`): roulette once the estimate is below this...
pub const ROULETTE_THRESHOLD: f32 = 0.05;
/// ...terminating with this probability, else dividing by `1 - q`.
pub const ROULETTE_Q: f32 = 0.75;
