//! The statistics of a finished render: its settings as reported, its
//! times and the kernel's [`Counters`] summed over tasks.

use serde::Serialize;

use cirrus_kernel::Counters;

/// The statistics of a render, serialisable to JSON for benchmarks.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RenderStats {
    /// Where the render ran: "cpu", or "gpu: " and the adapter.
    pub device: String,
    pub integrator: String,
    pub transmittance: String,
    /// The majorant structure walked; with `auto`, the one chosen
    /// ("auto: global").
    pub majorant: String,
    /// With `auto` and the path tracer: the probe's costs over the
    /// hierarchy and the global bound, in tentative collisions
    /// ([`crate::majorant_choice`]).
    pub majorant_probe: Option<[f64; 2]>,
    /// The path tracer's next-event estimation: "all" or "one", with
    /// `auto` the choice ("auto: one"); empty for the marchers.
    pub light_sampling: String,
    /// The path tracer's sunward scattering setting ("auto", "on",
    /// "off"; `counters.sunward_rays` says how often it ran); empty for
    /// the marchers.
    pub sunward: String,
    pub width: u32,
    pub height: u32,
    /// Samples per pixel actually taken (with a time budget: reached).
    pub spp: u32,
    pub wall_seconds: f64,
    /// Part of `wall_seconds` spent before the first camera ray (the
    /// two-pass light grid).
    pub setup_seconds: f64,
    /// What the integrators and trackers did (flattened into the JSON).
    #[serde(flatten)]
    pub counters: Counters,
    /// Bytes read from volume files to build the scene (set by the caller
    /// that loaded them; 0 when unknown).
    pub bytes_read: u64,
    /// Grids read from volume files (density, temperature, emission).
    pub grids_loaded: u64,
    /// Volumes of a scene left unloaded: neither the camera nor any light
    /// path can reach them.
    pub volumes_culled: u64,
    /// Wall time spent reading and converting volumes before rendering.
    pub load_seconds: f64,
    /// Wall time spent denoising after rendering (0 without `denoise`).
    pub denoise_seconds: f64,
    /// Camera paths per second of wall time.
    pub rays_per_second: f64,
    /// Samples per pixel over the image: their mean, fewest and most
    /// (with adaptive sampling they differ from pixel to pixel).
    pub spp_mean: f64,
    pub spp_min: u32,
    pub spp_max: u32,
    /// The camera as rendered, in world space (set by the caller that
    /// placed it; `None` when unknown).
    pub camera: Option<CameraReport>,
    /// What loading found wrong but could render (bad voxels, an open
    /// shutter with no velocity grid).
    pub warnings: Vec<String>,
}

/// Where the camera was, in world space, and whether it was framed on the
/// volumes because none was given.
#[derive(Clone, Debug, Default, Serialize)]
pub struct CameraReport {
    pub from: [f64; 3],
    pub to: [f64; 3],
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub fov: f32,
    pub framed: bool,
}

impl RenderStats {
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("stats serialise")
    }
}
