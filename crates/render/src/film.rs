//! The film: per-pixel running mean and variance, split into tiles so rayon
//! workers own disjoint pixels, and the resolved [`Image`].

use glam::Vec3;

use crate::compositing::{Compositing, Layers, TileLayers};
use cirrus_kernel::integrator::{AovSample, Sample};
use cirrus_kernel::Counters;

/// A finished image (or its crop window, see [`Rendered`](crate::Rendered)):
/// per-pixel mean RGBA (alpha = 1 - camera-ray transmittance), the
/// sample variance of each channel's estimator and the samples behind it.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel: every pixel's count, or with adaptive sampling
    /// the most any pixel took (`samples` has each pixel's).
    pub spp: u32,
    /// Row-major, top row first.
    pub rgba: Vec<[f32; 4]>,
    /// Unbiased sample variance of the per-sample values (0 with one spp).
    pub variance: Vec<[f32; 4]>,
    /// Samples taken per pixel, row-major like `rgba`.
    pub samples: Vec<u32>,
}

impl Image {
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        self.rgba[(y * self.width + x) as usize]
    }

    /// Standard error of each channel's mean: `sqrt(variance / n)` for the
    /// pixel's `n` samples.
    pub fn std_error(&self, x: u32, y: u32) -> [f32; 4] {
        let i = (y * self.width + x) as usize;
        let n = self.samples[i].max(1) as f32;
        self.variance[i].map(|v| (v / n).sqrt())
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

    /// Merges `n` samples given as their mean and `M2` (Chan, Golub and
    /// LeVeque's pairwise update).
    pub(crate) fn merge(&mut self, n: u32, mean: [f32; 4], m2: [f32; 4]) {
        if n == 0 {
            return;
        }
        let total = self.n + n;
        let (na, nb) = (self.n as f32, n as f32);
        for k in 0..4 {
            let delta = mean[k] - self.mean[k];
            self.mean[k] += delta * nb / total as f32;
            self.m2[k] += m2[k] + delta * delta * na * nb / total as f32;
        }
        self.n = total;
    }

    /// Samples added so far.
    #[inline]
    pub(crate) fn count(&self) -> u32 {
        self.n
    }

    #[inline]
    pub(crate) fn mean(&self) -> [f32; 4] {
        self.mean
    }

    pub(crate) fn variance(&self) -> [f32; 4] {
        if self.n < 2 {
            return [0.0; 4];
        }
        self.m2.map(|m2| m2 / (self.n - 1) as f32)
    }
}

/// The image's samples split into two independent halves: each pixel's
/// even-numbered samples (`a`) and its odd-numbered ones (`b`), as running
/// means of RGB. Two images of the same pixels with independent noise let
/// a denoiser's error be measured against data it never saw (one half is
/// filtered, the other is the reference); the two together are exactly the
/// image's samples, so keeping them changes no pixel of the image.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Halves {
    pub a: Vec<[f32; 3]>,
    pub b: Vec<[f32; 3]>,
    /// Samples in `a` and in `b` per pixel, row-major like `a`.
    pub samples: Vec<[u32; 2]>,
}

/// Running means of one pixel's even and odd samples (see [`Halves`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct HalfAccumulator {
    n: [u32; 2],
    mean: [Vec3; 2],
}

impl HalfAccumulator {
    /// Adds sample number `index` of the pixel (counted from 0).
    #[inline]
    fn add(&mut self, index: u32, rgb: Vec3) {
        let h = (index & 1) as usize;
        self.n[h] += 1;
        self.mean[h] += (rgb - self.mean[h]) / self.n[h] as f32;
    }
}

/// The compositing passes of an image (or of its crop window), row-major
/// like [`Image::rgba`]. Each is the per-pixel mean of its
/// [`AovSample`] part over all samples, except `depth`: the mean over the
/// samples whose camera ray collided, and [`NO_DEPTH`] where none did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AovImage {
    pub albedo: Vec<[f32; 3]>,
    pub depth: Vec<f32>,
    pub emission: Vec<[f32; 3]>,
    pub direct: Vec<[f32; 3]>,
    /// Samples taken per pixel.
    pub samples: Vec<f32>,
}

use crate::compositing::deep::NO_DEPTH;

/// Running means of the AOV parts of one pixel's samples.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct AovAccumulator {
    n: u32,
    albedo: Vec3,
    emission: Vec3,
    direct: Vec3,
    hits: u32,
    depth: f32,
}

impl AovAccumulator {
    #[inline]
    fn add(&mut self, a: &AovSample) {
        self.n += 1;
        let inv = 1.0 / self.n as f32;
        self.albedo += (a.albedo - self.albedo) * inv;
        self.emission += (a.emission - self.emission) * inv;
        self.direct += (a.direct - self.direct) * inv;
        if let Some(d) = a.depth.filter(|d| d.is_finite()) {
            self.hits += 1;
            self.depth += (d - self.depth) / self.hits as f32;
        }
    }
}

/// A rectangle of pixels owned by one task at a time; `x0, y0` are
/// absolute image coordinates.
pub(crate) struct Tile {
    pub x0: u32,
    pub y0: u32,
    pub w: u32,
    pub h: u32,
    pub pixels: Vec<PixelAccumulator>,
    /// Pixels that adaptive sampling has stopped.
    pub stopped: Vec<bool>,
    /// Empty unless the render keeps AOVs.
    pub aovs: Vec<AovAccumulator>,
    /// Empty unless the render keeps the two halves of its samples.
    pub halves: Vec<HalfAccumulator>,
    /// Light groups, coverage and deep bins, when kept.
    pub layers: TileLayers,
}

impl Tile {
    /// Adds one sample to the pixel at `(x, y)` (tile-local), replacing a
    /// non-finite sample by zero and counting it: a NaN must never reach
    /// the image, and dropping the sample instead would bias the mean.
    /// `view_cos`: the cosine of its camera ray to the view axis (deep
    /// samples store planar depth).
    #[inline]
    pub fn add(&mut self, x: u32, y: u32, s: Sample, view_cos: f32, c: &mut Counters) {
        let v = [s.radiance.x, s.radiance.y, s.radiance.z, s.alpha];
        let finite = v.iter().all(|x| x.is_finite());
        let v = if finite {
            v
        } else {
            c.nonfinite_samples += 1;
            [0.0; 4]
        };
        let i = (y * self.w + x) as usize;
        if let Some(h) = self.halves.get_mut(i) {
            // The pixel's count before this sample is the sample's number:
            // samples are added in order.
            h.add(self.pixels[i].count(), Vec3::new(v[0], v[1], v[2]));
        }
        self.pixels[i].add(v);
        self.layers.add(i, &s, finite, view_cos);
        if let Some(a) = self.aovs.get_mut(i) {
            let finite =
                s.aov.albedo.is_finite() && s.aov.emission.is_finite() && s.aov.direct.is_finite();
            a.add(&if finite { s.aov } else { AovSample::default() });
        }
    }
}

/// The pixels being rendered: the whole image or a crop window of it at
/// `(x0, y0)`, `width x height` pixels.
pub(crate) struct Film {
    pub x0: u32,
    pub y0: u32,
    pub width: u32,
    pub height: u32,
    pub tiles: Vec<Tile>,
    pub aovs: bool,
    pub halves: bool,
    pub compositing: Compositing,
}

impl Film {
    /// Tiles of edge `tile` over the window; AOV accumulators if `aovs`,
    /// half-image accumulators if `halves`, and the layers `compositing`
    /// asks for.
    pub fn new(
        (x0, y0, width, height): (u32, u32, u32, u32),
        tile: u32,
        (aovs, halves): (bool, bool),
        compositing: &Compositing,
    ) -> Self {
        let tile = tile.max(1);
        let mut tiles = Vec::new();
        for ty in (0..height).step_by(tile as usize) {
            for tx in (0..width).step_by(tile as usize) {
                let (w, h) = (tile.min(width - tx), tile.min(height - ty));
                let n = (w * h) as usize;
                tiles.push(Tile {
                    x0: x0 + tx,
                    y0: y0 + ty,
                    w,
                    h,
                    pixels: vec![PixelAccumulator::default(); n],
                    stopped: vec![false; n],
                    aovs: if aovs {
                        vec![AovAccumulator::default(); n]
                    } else {
                        Vec::new()
                    },
                    halves: if halves {
                        vec![HalfAccumulator::default(); n]
                    } else {
                        Vec::new()
                    },
                    layers: TileLayers::new(compositing, n),
                });
            }
        }
        Self {
            x0,
            y0,
            width,
            height,
            tiles,
            aovs,
            halves,
            compositing: compositing.clone(),
        }
    }

    /// Calls `visit(tile, local, image)` for every pixel: its tile, its
    /// index in the tile and its index in the window's row-major image.
    fn for_each_pixel(&self, mut visit: impl FnMut(&Tile, usize, usize)) {
        for tile in &self.tiles {
            for ty in 0..tile.h {
                for tx in 0..tile.w {
                    let local = (ty * tile.w + tx) as usize;
                    let i =
                        ((tile.y0 - self.y0 + ty) * self.width + tile.x0 - self.x0 + tx) as usize;
                    visit(tile, local, i);
                }
            }
        }
    }

    /// The compositing layers so far (`None` unless the film keeps any).
    pub fn resolve_layers(&self) -> Option<Layers> {
        if !self.compositing.keeps_layers() {
            return None;
        }
        let tiles = self
            .tiles
            .iter()
            .map(|t| (&t.layers, (t.x0, t.y0, t.w, t.h), t));
        let window = (self.x0, self.y0, self.width, self.height);
        Some(crate::compositing::film::resolve(
            &self.compositing,
            window,
            tiles,
            |t: &Tile, i| t.pixels[i].count(),
        ))
    }

    /// The AOV passes so far (`None` unless the film keeps them).
    pub fn resolve_aovs(&self) -> Option<AovImage> {
        if !self.aovs {
            return None;
        }
        let n = (self.width * self.height) as usize;
        let mut out = AovImage {
            albedo: vec![[0.0; 3]; n],
            depth: vec![NO_DEPTH; n],
            emission: vec![[0.0; 3]; n],
            direct: vec![[0.0; 3]; n],
            samples: vec![0.0; n],
        };
        self.for_each_pixel(|tile, local, i| {
            let a = &tile.aovs[local];
            out.albedo[i] = a.albedo.to_array();
            out.emission[i] = a.emission.to_array();
            out.direct[i] = a.direct.to_array();
            out.samples[i] = a.n as f32;
            if a.hits > 0 {
                out.depth[i] = a.depth;
            }
        });
        Some(out)
    }

    /// The two halves of the samples so far (`None` unless the film keeps
    /// them). A non-finite mean (overflow) is zeroed, as in [`Film::resolve`].
    pub fn resolve_halves(&self) -> Option<Halves> {
        if !self.halves {
            return None;
        }
        let n = (self.width * self.height) as usize;
        let mut out = Halves {
            a: vec![[0.0; 3]; n],
            b: vec![[0.0; 3]; n],
            samples: vec![[0; 2]; n],
        };
        let finite = |v: Vec3| {
            if v.is_finite() {
                v.to_array()
            } else {
                [0.0; 3]
            }
        };
        self.for_each_pixel(|tile, local, i| {
            let h = &tile.halves[local];
            out.a[i] = finite(h.mean[0]);
            out.b[i] = finite(h.mean[1]);
            out.samples[i] = h.n;
        });
        Some(out)
    }

    /// The image so far. Means are finite by construction (non-finite
    /// samples never enter); one that still is not (overflow) is zeroed and
    /// counted. Variances are reported as they are.
    pub fn resolve(&self, spp: u32, c: &mut Counters) -> Image {
        let n = (self.width * self.height) as usize;
        let mut rgba = vec![[0.0; 4]; n];
        let mut variance = vec![[0.0; 4]; n];
        let mut samples = vec![0; n];
        self.for_each_pixel(|tile, local, i| {
            let acc = &tile.pixels[local];
            let mut m = acc.mean;
            if !m.iter().all(|x| x.is_finite()) {
                c.nonfinite_samples += 1;
                m = [0.0; 4];
            }
            rgba[i] = m;
            variance[i] = acc.variance();
            samples[i] = acc.n;
        });
        Image {
            width: self.width,
            height: self.height,
            spp,
            rgba,
            variance,
            samples,
        }
    }
}
