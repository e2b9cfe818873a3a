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
