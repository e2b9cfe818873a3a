//! The film: per-pixel running mean and variance, split into tiles so rayon
//! workers own disjoint pixels, and the resolved [`Image`].

use crate::integrator::Sample;
use crate::stats::Counters;

/// A finished image: per-pixel mean RGBA (alpha = 1 - camera-ray
/// transmittance) and the sample variance of each channel's estimator.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel behind every pixel.
    pub spp: u32,
    /// Row-major, top row first.
    pub rgba: Vec<[f32; 4]>,
    /// Unbiased sample variance of the per-sample values (0 with one spp).
    pub variance: Vec<[f32; 4]>,
}

impl Image {
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        self.rgba[(y * self.width + x) as usize]
    }

    /// Standard error of each channel's mean: `sqrt(variance / spp)`.
    pub fn std_error(&self, x: u32, y: u32) -> [f32; 4] {
        let v = self.variance[(y * self.width + x) as usize];
        v.map(|v| (v / self.spp.max(1) as f32).sqrt())
    }
}

/// Welford's running mean and sum of squared deviations, stable in f32.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PixelAccumulator {
    n: u32,
    mean: [f32; 4],
    m2: [f32; 4],
}

impl PixelAccumulator {
    #[inline]
    fn add(&mut self, x: [f32; 4]) {
        self.n += 1;
        let inv = 1.0 / self.n as f32;
        for ((m, m2), x) in self.mean.iter_mut().zip(&mut self.m2).zip(x) {
            let delta = x - *m;
            *m += delta * inv;
            *m2 += delta * (x - *m);
        }
    }

    fn variance(&self) -> [f32; 4] {
        if self.n < 2 {
            return [0.0; 4];
        }
        self.m2.map(|m2| m2 / (self.n - 1) as f32)
    }
}

/// A rectangle of pixels owned by one task at a time.
pub(crate) struct Tile {
    pub x0: u32,
    pub y0: u32,
    pub w: u32,
    pub h: u32,
    pub pixels: Vec<PixelAccumulator>,
}

impl Tile {
    /// Adds one sample to the pixel at `(x, y)` (tile-local), replacing a
    /// non-finite sample by zero and counting it: a NaN must never reach
    /// the image, and dropping the sample instead would bias the mean.
    #[inline]
    pub fn add(&mut self, x: u32, y: u32, s: Sample, c: &mut Counters) {
        let v = [s.radiance.x, s.radiance.y, s.radiance.z, s.alpha];
        let v = if v.iter().all(|x| x.is_finite()) {
            v
        } else {
            c.nonfinite_samples += 1;
            [0.0; 4]
        };
        self.pixels[(y * self.w + x) as usize].add(v);
    }
}

pub(crate) struct Film {
    pub width: u32,
    pub height: u32,
    pub tiles: Vec<Tile>,
}

impl Film {
    pub fn new(width: u32, height: u32, tile: u32) -> Self {
        let tile = tile.max(1);
        let mut tiles = Vec::new();
        for y0 in (0..height).step_by(tile as usize) {
            for x0 in (0..width).step_by(tile as usize) {
                let (w, h) = (tile.min(width - x0), tile.min(height - y0));
                tiles.push(Tile {
                    x0,
                    y0,
                    w,
                    h,
                    pixels: vec![PixelAccumulator::default(); (w * h) as usize],
                });
            }
        }
        Self {
            width,
            height,
            tiles,
        }
    }

    /// The image so far. Means are finite by construction (non-finite
    /// samples never enter); one that still is not (overflow) is zeroed and
    /// counted. Variances are reported as they are.
    pub fn resolve(&self, spp: u32, c: &mut Counters) -> Image {
        let n = (self.width * self.height) as usize;
        let mut rgba = vec![[0.0; 4]; n];
        let mut variance = vec![[0.0; 4]; n];
        for tile in &self.tiles {
            for ty in 0..tile.h {
                for tx in 0..tile.w {
                    let acc = &tile.pixels[(ty * tile.w + tx) as usize];
                    let i = ((tile.y0 + ty) * self.width + tile.x0 + tx) as usize;
                    let mut m = acc.mean;
                    if !m.iter().all(|x| x.is_finite()) {
                        c.nonfinite_samples += 1;
                        m = [0.0; 4];
                    }
                    rgba[i] = m;
                    variance[i] = acc.variance();
                }
            }
        }
        Image {
            width: self.width,
            height: self.height,
            spp,
            rgba,
            variance,
        }
    }
}
