//! The film fed from outside the render loop: another device (the GPU
//! backend, `cirrus-gpu`) renders passes of whole images and hands each
//! pixel's running moments here, so its image resolves, and writes, exactly
//! as a CPU render's does.

use std::time::Instant;

use cirrus_kernel::Camera;

use crate::film::Film;
use crate::render::{crop_of, Rendered, Window};
use crate::scene::{Crop, RenderSettings};
use crate::stats::RenderStats;

/// One pixel's samples as running moments: the count, the mean RGBA and
/// the sum of squared deviations from it (Welford's `M2`), the form the
/// host film keeps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelMoments {
    pub n: u32,
    pub mean: [f32; 4],
    pub m2: [f32; 4],
}

/// A film over a render's window that takes per-pixel moments.
pub struct PassFilm {
    film: Film,
    window: Crop,
    full: (u32, u32),
    start: Instant,
    /// Samples per pixel added so far.
    spp: u32,
}

impl PassFilm {
    /// The film `settings` ask for over `camera`'s image (its crop
    /// window), without AOVs, halves or layers: a caller that wants those
    /// renders on the CPU.
    pub fn new(camera: &Camera, settings: &RenderSettings) -> Self {
        let window = crop_of(settings, camera);
        let (w, h) = (window.x1 - window.x0, window.y1 - window.y0);
        let film = Film::new(
            (window.x0, window.y0, w, h),
            w.max(h),
            (false, false),
            &Default::default(),
        );
        Self {
            film,
            window,
            full: (camera.width(), camera.height()),
            start: Instant::now(),
            spp: 0,
        }
    }

    /// The window rendered, in the camera's image.
    pub fn window(&self) -> Crop {
        self.window
    }

    /// Merges moments of `spp` more samples per pixel, row-major over the
    /// window (Chan et al.'s pairwise update: the same mean and `M2` as
    /// adding the samples one by one, up to rounding).
    pub fn add(&mut self, pass: &[PixelMoments], spp: u32) {
        let (x0, y0, width) = (self.film.x0, self.film.y0, self.film.width);
        for tile in &mut self.film.tiles {
            for ty in 0..tile.h {
                for tx in 0..tile.w {
                    let local = (ty * tile.w + tx) as usize;
                    let i = ((tile.y0 - y0 + ty) * width + tile.x0 - x0 + tx) as usize;
                    if let Some(m) = pass.get(i) {
                        tile.pixels[local].merge(m.n, m.mean, m.m2);
                    }
                }
            }
        }
        self.spp += spp;
    }

    /// The finished render: the image resolved as the CPU's is, with
    /// `stats` completed by the image's size, samples and wall time since
    /// the film was made.
    pub fn finish(self, mut stats: RenderStats) -> Rendered {
        let mut counters = stats.counters;
        let image = self.film.resolve(self.spp, &mut counters);
        stats.counters = counters;
        stats.width = image.width;
        stats.height = image.height;
        stats.spp = self.spp;
        // Every pixel takes every pass's sample.
        stats.spp_min = self.spp;
        stats.spp_max = self.spp;
        stats.spp_mean = f64::from(self.spp);
        stats.wall_seconds = self.start.elapsed().as_secs_f64();
        stats.rays_per_second = counters.paths as f64 / stats.wall_seconds.max(1e-9);
        Rendered {
            image,
            stats,
            window: Window {
                x0: self.window.x0,
                y0: self.window.y0,
                full_width: self.full.0,
                full_height: self.full.1,
            },
            aovs: None,
            halves: None,
            denoised: None,
            layers: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::PixelAccumulator;

    /// Moments of a sequence, as a device keeps them (Welford).
    fn moments(xs: &[[f32; 4]]) -> PixelMoments {
        let mut m = PixelMoments::default();
        for x in xs {
            m.n += 1;
            for (k, &v) in x.iter().enumerate() {
                let delta = v - m.mean[k];
                m.mean[k] += delta / m.n as f32;
                m.m2[k] += delta * (v - m.mean[k]);
            }
        }
        m
    }

    /// Two passes merged give the mean and variance of all their
    /// samples, as adding them one by one does.
    #[test]
    fn merged_passes_are_their_samples() {
        let xs: Vec<[f32; 4]> = (0..13)
            .map(|i| {
                let v = (i as f32 * 0.37).sin() * 3.0 + 1.0;
                [v, v * v, -v, 0.5]
            })
            .collect();
        let (a, b) = xs.split_at(5);
        let mut merged = PixelAccumulator::default();
        for m in [moments(a), moments(b)] {
            merged.merge(m.n, m.mean, m.m2);
        }
        let whole = moments(&xs);
        assert_eq!(merged.count(), 13);
        for k in 0..4 {
            assert!((merged.mean()[k] - whole.mean[k]).abs() < 1e-5);
            let v = whole.m2[k] / 12.0;
            assert!((merged.variance()[k] - v).abs() <= 1e-4 * v.abs().max(1.0));
        }
    }

    /// A film fed one pass resolves to its moments, in the window's place.
    #[test]
    fn a_pass_resolves_to_its_moments() {
        let camera = Camera::new(glam::Vec3::ZERO, glam::Vec3::Z, glam::Vec3::Y, 40.0, 5, 3);
        let mut film = PassFilm::new(&camera, &RenderSettings::default());
        let pass: Vec<PixelMoments> = (0..15)
            .map(|i| moments(&[[i as f32, 0.0, 0.0, 1.0], [i as f32 + 2.0, 0.0, 0.0, 1.0]]))
            .collect();
        film.add(&pass, 2);
        let r = film.finish(RenderStats::default());
        assert_eq!((r.image.width, r.image.height, r.image.spp), (5, 3, 2));
        assert_eq!(r.image.pixel(3, 2)[0], 14.0);
        assert_eq!(r.image.samples[7], 2);
        assert_eq!(r.image.variance[7][0], 2.0);
    }
}
