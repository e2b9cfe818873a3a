//! The majorant structure chosen per medium: the field's own local bounds
//! (the hierarchy) or one global bound over its box.
//!
//! Which is faster depends on the volume, not on the rule of thumb that
//! local bounds are tighter. A tracker pays per tentative collision (a
//! density lookup) and per majorant segment (a walk step). On a sparse
//! cloudscape the hierarchy skips empty space that a global bound fills
//! with null collisions (BENCHMARKS.md: 1.5 lookups and 5.2 segments per
//! path against 148 lookups and 2.1 segments), while on a compact cloud
//! its 58 segments per path cost about as much as the 95 lookups they save
//! (17.6 lookups and 58 segments against 112 and 19, within 2% of equal
//! wall time).
//!
//! [`choose`] measures both on the scene itself: it traces
//! [`PROBE_PATHS`] paths of the path tracer over each structure and
//! counts lookups and segments, then picks the structure whose
//! `lookups + SEGMENT_COST x segments` is smaller. The probe's camera
//! samples are spread over the whole frame with a fixed seed, so the
//! choice is the same for every crop, thread count and render seed (a
//! crop still merges bit-identically), and counts, unlike timings, do not
//! depend on the machine's load.

use crate::path_setup::{path_tracer, ShadowGrid};
use crate::pixel_sampler::PixelSampler;
use crate::scene::RenderSettings;
use cirrus_kernel::integrator::CameraSampler;
use cirrus_kernel::light::Lights;
use cirrus_kernel::medium::{GlobalMedia, Media};
use cirrus_kernel::sampling::{Rng, SampleStream};
use cirrus_kernel::Camera;
use cirrus_kernel::Counters;
use cirrus_kernel::MajorantMode;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// Paths traced over each structure, in parallel chunks of 64
/// (`PROBE_CHUNK`). On the corpus cloud the probe takes about 20 ms
/// (128x128 at 1 spp renders in 60 ms), and its choices on the scenes of
/// BENCHMARKS.md match 4,096 paths' wherever the two costs differ by more
/// than a few percent.
pub const PROBE_PATHS: u32 = 1024;
const PROBE_CHUNK: u32 = 64;

/// A majorant segment's cost in units of one tentative collision (lookup
/// included). Calibrated on the corpus cloud, where the two structures run
/// in nearly equal time (`--stats` of `cirrus render data/cloud.vdb --res
/// 128x128 --spp 64 --majorant hierarchy|global` with the benchmark camera,
/// ten alternated runs each: user time 7.455 s over the hierarchy against
/// 7.57 s globally, medians; 17.6 lookups and 58.2 segments per path
/// against 112.4 and 19.0, so 17.6 + 58.2 c = 0.985 (112.4 + 19.0 c)
/// gives c = 2.36).
pub const SEGMENT_COST: f64 = 2.4;

/// The probe's seed, fixed so that the choice depends on the scene alone.
const PROBE_SEED: u64 = 0x6d61_6a6f_7261_6e74;

/// What a structure's probe paths cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProbeCost {
    pub lookups: u64,
    pub segments: u64,
}

impl ProbeCost {
    fn of(c: &Counters) -> Self {
        ProbeCost {
            lookups: c.density_lookups,
            segments: c.dda_segments,
        }
    }

    /// In tentative collisions.
    pub fn cost(self) -> f64 {
        self.lookups as f64 + SEGMENT_COST * self.segments as f64
    }
}

/// The structure [`MajorantMode::Auto`] resolves to for this scene, with
/// the probe's costs over the hierarchy and the global bound. Only the
/// path tracer chooses; the marchers walk the field's own cells, which
/// are what lets them skip empty space.
pub(crate) fn choose<M: Media>(
    media: &M,
    camera: &Camera,
    lights: &Lights,
    settings: &RenderSettings,
    shadows: Option<&ShadowGrid>,
) -> (MajorantMode, Option<[ProbeCost; 2]>) {
    match settings.majorant {
        MajorantMode::Auto if settings.integrator == crate::IntegratorKind::Path => {
            let local = probe(media, camera, lights, settings, shadows, f64::INFINITY);
            // The global probe stops once it has cost more than the whole
            // hierarchy probe: it has lost, and a global bound far above
            // most of the density (one dense voxel in a large empty box)
            // would otherwise take up to the trackers' collision cap on
            // every ray. Its figure is then a lower bound; the choice is
            // the same however the chunks were scheduled.
            let global = probe(
                &GlobalMedia::new(media),
                camera,
                lights,
                settings,
                shadows,
                local.cost(),
            );
            let mode = if global.cost() < local.cost() {
                MajorantMode::Global
            } else {
                MajorantMode::Hierarchy
            };
            (mode, Some([local, global]))
        }
        MajorantMode::Auto => (MajorantMode::Hierarchy, None),
        mode => (mode, None),
    }
}

/// Lookups and segments of [`PROBE_PATHS`] paths over `media`, or of
/// those traced before their cost passed `limit`.
fn probe<M: Media>(
    media: &M,
    camera: &Camera,
    lights: &Lights,
    settings: &RenderSettings,
    shadows: Option<&ShadowGrid>,
    limit: f64,
) -> ProbeCost {
    // The render's own tracer: its light choice decides how many shadow
    // rays a path traces (one light per vertex, and through the shadow
    // grid few deep in a thick cloud), which shifts the balance between
    // the structures.
    let tracer = path_tracer(media, lights, settings, shadows);
    // The render's own camera rays: shutter time and holdout included.
    let camera_rays = PixelSampler::new(camera, settings);
    let (w, h) = (camera.width().max(1), camera.height().max(1));
    let pixels = u64::from(w) * u64::from(h);
    // Each path has its own numbers and counts add, so the sum is the same
    // however the chunks are scheduled (unless the limit stops it).
    let spent = AtomicU64::new(0);
    (0..PROBE_PATHS / PROBE_CHUNK)
        .into_par_iter()
        .map(|chunk| {
            let mut c = Counters::default();
            for i in chunk * PROBE_CHUNK..(chunk + 1) * PROBE_CHUNK {
                if f64::from_bits(spent.load(Ordering::Relaxed)) > limit {
                    break;
                }
                let before = ProbeCost::of(&c).cost();
                let mut rng = Rng::new(PROBE_SEED, u64::from(i), 0);
                let pixel = (rng.next_u64() % pixels) as u32;
                let mut draws = SampleStream::random(rng);
                let ray = camera_rays.ray(pixel % w, pixel / w, &mut draws);
                tracer.sample_stream(ray, &mut draws, &mut c);
                let path = ProbeCost::of(&c).cost() - before;
                // A float sum in an atomic: only compared with the limit.
                let _ = spent.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |bits| {
                    Some((f64::from_bits(bits) + path).to_bits())
                });
            }
            ProbeCost::of(&c)
        })
        .reduce(ProbeCost::default, |a, b| ProbeCost {
            lookups: a.lookups + b.lookups,
            segments: a.segments + b.segments,
        })
}
