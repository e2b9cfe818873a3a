//! Progressive accumulation: passes of a few samples per pixel, each with
//! its own seed, averaged weighted by their sample counts.
//!
//! The renderer keys every random number by (seed, pixel, sample), so
//! passes with distinct seeds are independent estimates of the same image
//! and their spp-weighted mean is the estimate with all their samples.

use cirrus_render::{Image, Rendered};
use cirrus_scene::Overrides;

/// The running mean of the passes rendered for one set of overrides.
pub struct Accumulation {
    /// What the passes rendered (without spp and seed).
    pub key: Overrides,
    pub width: u32,
    pub height: u32,
    /// The most samples any pixel has (all have as many unless the
    /// renderer samples adaptively).
    pub spp: u32,
    pub passes: u32,
    /// Samples behind each pixel: the weights of the running means.
    pub counts: Vec<u32>,
    pub rgba: Vec<[f32; 4]>,
    /// The first-scattering albedo, when every pass kept it (guides the
    /// denoiser).
    pub albedo: Option<Vec<[f32; 3]>>,
    pub paths: u64,
    /// Render time of the passes, seconds.
    pub seconds: f64,
    /// Where the last pass ran (its stats' `device`).
    pub device: String,
}

impl Accumulation {
    pub fn new(key: Overrides, width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Accumulation {
            key,
            width,
            height,
            spp: 0,
            passes: 0,
            counts: vec![0; n],
            rgba: vec![[0.0; 4]; n],
            albedo: Some(vec![[0.0; 3]; n]),
            paths: 0,
            seconds: 0.0,
            device: String::new(),
        }
    }

    /// Folds a finished pass in; `false` (and no change) when its size is
    /// not this accumulation's.
    pub fn add(&mut self, r: &Rendered) -> bool {
        let img = &r.image;
        let n = self.rgba.len();
        if (img.width, img.height) != (self.width, self.height) || img.rgba.len() != n {
            return false;
        }
        // A pass's pixels took `samples` each (fewer where adaptive
        // sampling stopped them early).
        let aov_albedo = r.aovs.as_ref().map(|a| &a.albedo).filter(|a| a.len() == n);
        if aov_albedo.is_none() {
            self.albedo = None;
        }
        for i in 0..n {
            let k = img.samples.get(i).copied().unwrap_or(img.spp);
            if k == 0 {
                continue;
            }
            self.counts[i] += k;
            // The new samples' share of the pixel's mean.
            let w = k as f32 / self.counts[i] as f32;
            for (a, p) in self.rgba[i].iter_mut().zip(img.rgba[i]) {
                *a += (p - *a) * w;
            }
            if let (Some(acc), Some(src)) = (&mut self.albedo, aov_albedo) {
                for (a, p) in acc[i].iter_mut().zip(src[i]) {
                    *a += (p - *a) * w;
                }
            }
        }
        self.spp += img.spp;
        self.passes += 1;
        self.paths += r.stats.counters.paths;
        self.seconds += r.stats.wall_seconds;
        self.device.clone_from(&r.stats.device);
        true
    }

    pub fn paths_per_second(&self) -> f64 {
        self.paths as f64 / self.seconds.max(1e-9)
    }

    /// The accumulated image (no variance: passes keep only their means).
    pub fn image(&self) -> Image {
        Image {
            width: self.width,
            height: self.height,
            spp: self.spp,
            rgba: self.rgba.clone(),
            variance: vec![[0.0; 4]; self.rgba.len()],
            samples: self.counts.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cirrus_render::{RenderStats, Window};

    fn pass(spp: u32, value: f32) -> Rendered {
        Rendered {
            image: Image {
                width: 2,
                height: 1,
                spp,
                rgba: vec![[value; 4]; 2],
                variance: vec![[0.0; 4]; 2],
                samples: vec![spp; 2],
            },
            stats: RenderStats::default(),
            window: Window {
                x0: 0,
                y0: 0,
                full_width: 2,
                full_height: 1,
            },
            aovs: None,
            halves: None,
            denoised: None,
            layers: None,
        }
    }

    #[test]
    fn passes_average_weighted_by_their_samples() {
        let mut a = Accumulation::new(Overrides::default(), 2, 1);
        assert!(a.add(&pass(1, 1.0)));
        assert!(a.add(&pass(3, 5.0)));
        assert_eq!(a.spp, 4);
        assert!((a.rgba[0][0] - 4.0).abs() < 1e-6);
        assert!(a.albedo.is_none(), "passes without albedo drop it");
        let mut wrong = pass(1, 0.0);
        wrong.image.width = 3;
        assert!(!a.add(&wrong));
        assert_eq!(a.spp, 4);
    }
}
