//! Where a camera sample's ray comes from: the pixel's jitter, its time
//! within the shutter, and the holdout depth that ends it. The render's
//! passes and the majorant probe draw their camera rays here, so both
//! trace what the image is made of.

use crate::compositing::DepthHoldout;
use crate::scene::RenderSettings;
use cirrus_kernel::sampling::{Draw, SampleStream};
use cirrus_kernel::Camera;
use cirrus_kernel::Ray;
use cirrus_kernel::Shutter;

/// The camera rays of one render.
#[derive(Clone, Copy)]
pub(crate) struct PixelSampler<'a> {
    camera: &'a Camera,
    shutter: Shutter,
    holdout: Option<&'a DepthHoldout>,
}

impl<'a> PixelSampler<'a> {
    /// The camera rays `settings` render through `camera`.
    pub fn new(camera: &'a Camera, settings: &'a RenderSettings) -> Self {
        Self {
            camera,
            shutter: settings.shutter,
            holdout: settings.compositing.holdout_depth.as_deref(),
        }
    }

    pub fn camera(&self) -> &'a Camera {
        self.camera
    }

    /// The ray of one sample of pixel `(x, y)`: jittered inside the pixel
    /// by the sample's [`Draw::PixelJitter`], at its shutter time, ended
    /// at the holdout's depth where one is given.
    #[inline]
    pub fn ray(&self, x: u32, y: u32, draws: &mut SampleStream) -> Ray {
        let (u, v) = draws.get_2d(Draw::PixelJitter, 0);
        let time = self.shutter.sample(draws);
        let ray = self.camera.ray_at(x as f32 + u, y as f32 + v, time);
        match self.holdout {
            Some(h) => ray.with_t_max(h.t_max(x, y, ray.dir, self.camera.forward())),
            None => ray,
        }
    }
}
