//! The path tracer a render's settings ask for, and the shadow grid its
//! light choice weighs lights by: built once per render, before the
//! majorant probe, which traces the same tracer.

use std::time::Instant;

use crate::scene::RenderSettings;
use cirrus_kernel::integrator::{IntegratorKind, LightGrid, LightSampling, PathTracer};
use cirrus_kernel::light::Lights;
use cirrus_kernel::medium::Media;

/// The path tracer `settings` ask for over `medium`, picking lights through
/// `shadows` where it picks one per vertex: what the render traces and
/// what the majorant probe measures.
pub(crate) fn path_tracer<'a, M: Media>(
    medium: &'a M,
    lights: &Lights,
    settings: &RenderSettings,
    shadows: Option<&'a ShadowGrid>,
) -> PathTracer<'a, M> {
    PathTracer::new(
        medium,
        lights.clone(),
        settings.transmittance,
        settings.max_depth,
    )
    .with_light_groups(!settings.compositing.light_groups.is_empty())
    .with_light_sampling(settings.light_sampling)
    .with_sunward(settings.sunward)
    .with_distance_sampling(settings.distance_sampling)
    .with_shadows(shadows.map(|s| &s.grid))
}

/// The light choice's shadow grid ([`LightGrid::for_light_choice`]) and
/// the seconds it took to build.
pub(crate) struct ShadowGrid {
    grid: LightGrid,
    seconds: f64,
}

/// The shadow grid a path-traced render's light choice needs, if it picks
/// one light per vertex.
pub(crate) fn shadow_grid<M: Media>(
    media: &M,
    lights: &Lights,
    settings: &RenderSettings,
) -> Option<ShadowGrid> {
    let start = Instant::now();
    let picks = settings.integrator == IntegratorKind::Path
        && settings.light_sampling.picks_one(&lights.clone().pruned());
    picks.then(|| ShadowGrid {
        grid: LightGrid::for_light_choice(media, lights),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// `--stats`' light sampling: the mode (what `auto` chose for `tracer`),
/// and the shadow grid the pick weighs lights by, its lattice and build
/// time.
pub(crate) fn light_sampling_stat<M: Media>(
    settings: &RenderSettings,
    tracer: &PathTracer<M>,
    grid: Option<&ShadowGrid>,
) -> String {
    let mode = match settings.light_sampling {
        LightSampling::Auto => format!("auto: {}", tracer.light_sampling().name()),
        mode => mode.name().into(),
    };
    match grid {
        Some(g) => {
            let [x, y, z] = g.grid.lattice();
            let seconds = g.seconds;
            format!("{mode}, through a {x}x{y}x{z} shadow grid ({seconds:.2} s)")
        }
        None => mode,
    }
}
