//! A render whose lights change while the shutter is open: one camera
//! sampler per table of [`LightsOverShutter`], each made as the still
//! render's is, and a camera sample traced by the one of the table
//! nearest its time. Every table holds the same lights in the same order,
//! so they share the frame's shadow grid and light groups; a scene whose
//! lights hold still never comes here.

use cirrus_kernel::integrator::{CameraSampler, Sample};
use cirrus_kernel::light::{Lights, LightsOverShutter};
use cirrus_kernel::sampling::{Rng, SampleStream};
use cirrus_kernel::{Counters, Ray};

/// The samplers of the lights over the shutter, by table.
pub(crate) struct OverShutter<'a, S> {
    shutter: &'a LightsOverShutter,
    samplers: Vec<S>,
}

impl<'a, S: CameraSampler> OverShutter<'a, S> {
    /// A sampler made by `make` for each table of `shutter`.
    pub fn new(shutter: &'a LightsOverShutter, make: impl Fn(&Lights) -> S) -> Self {
        Self {
            shutter,
            samplers: shutter.tables().iter().map(make).collect(),
        }
    }

    #[inline]
    fn at(&self, time: f32) -> &S {
        &self.samplers[self.shutter.index_at(time)]
    }
}

impl<S: CameraSampler> CameraSampler for OverShutter<'_, S> {
    fn sample(&self, ray: Ray, rng: &mut Rng, c: &mut Counters) -> Sample {
        self.at(ray.time).sample(ray, rng, c)
    }

    fn sample_stream(&self, ray: Ray, stream: &mut SampleStream, c: &mut Counters) -> Sample {
        self.at(ray.time).sample_stream(ray, stream, c)
    }
}
