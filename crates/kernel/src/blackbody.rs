//! Blackbody emission as linear sRGB, the way pbrt-v4 defines it for its
//! NanoVDB medium: `Le = scale * Blackbody((T - offset) * tscale)`, zero at
//! or below 100 K, where `Blackbody(T)` is Planck's law normalised to 1 at
//! its peak wavelength (pbrt-v4 `BlackbodySpectrum`, peak from Wien's
//! displacement law `lambda_max = 2.8977721e-3 m K / T`).
//!
//! To RGB: the spectrum is integrated against CIE 1931 colour matching
//! functions from 360 to 830 nm at 1 nm, divided by the integral of y-bar
//! (pbrt-v4 `SpectrumToXYZ`), then XYZ goes to linear sRGB (D65, IEC
//! 61966-2-1 matrix) with negative components clamped to 0. The matching
//! functions are the analytic multi-lobe fit of Wyman, Sloan and Shirley
//! 2013 ("Simple Analytic Approximations to the CIE XYZ Color Matching
//! Functions", JCGT 2(2), eq. 2 and table 1), within about 1% of the
//! tabulated curves. The result is tabulated once over temperature, log
//! spaced, and interpolated linearly in log T.

use std::sync::OnceLock;

use glam::Vec3;

/// Temperatures at or below this emit nothing (pbrt-v4's cut-off).
pub const MIN_KELVIN: f32 = 100.0;
const MAX_KELVIN: f32 = 100_000.0;
const TABLE: usize = 1024;

/// The pbrt-v4 blackbody emission parameters of a temperature grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blackbody {
    /// Multiplies the normalised spectrum (pbrt's `Lescale`).
    pub scale: f32,
    /// Subtracted from the grid value before scaling (pbrt's `temperatureoffset`).
    pub offset: f32,
    /// Multiplies the offset value to give kelvin (pbrt's `temperaturescale`).
    pub temperature_scale: f32,
}

impl Default for Blackbody {
    fn default() -> Self {
        Self {
            scale: 1.0,
            offset: 0.0,
            temperature_scale: 1.0,
        }
    }
}

impl Blackbody {
    /// Emitted radiance for a temperature-grid value.
    #[inline]
    pub fn radiance(&self, value: f32) -> Vec3 {
        self.scale * blackbody_rgb((value - self.offset) * self.temperature_scale)
    }
}

/// Linear sRGB of the peak-normalised blackbody spectrum at `kelvin`
/// (0 at or below [`MIN_KELVIN`] and for NaN; clamped above 100,000 K).
#[inline]
pub fn blackbody_rgb(kelvin: f32) -> Vec3 {
    if kelvin.is_nan() || kelvin <= MIN_KELVIN {
        return Vec3::ZERO;
    }
    let table = TABLE_RGB.get_or_init(build_table);
    let x = (kelvin.min(MAX_KELVIN) / MIN_KELVIN).ln() / (MAX_KELVIN / MIN_KELVIN).ln();
    let f = x * (TABLE - 1) as f32;
    let i = (f as usize).min(TABLE - 2);
    let w = f - i as f32;
    table[i].lerp(table[i + 1], w)
}

static TABLE_RGB: OnceLock<Vec<Vec3>> = OnceLock::new();

fn build_table() -> Vec<Vec3> {
    let y_integral: f64 = (360..=830).map(|l| cie_xyz(l as f64)[1]).sum();
    (0..TABLE)
        .map(|i| {
            let x = i as f64 / (TABLE - 1) as f64;
            let t = MIN_KELVIN as f64 * ((MAX_KELVIN / MIN_KELVIN) as f64).powf(x);
            let peak = planck(2.897_772_1e-3 / t, t);
            let mut xyz = [0.0f64; 3];
            for l in 360..=830 {
                let lambda = l as f64;
                let s = planck(lambda * 1e-9, t) / peak;
                let cmf = cie_xyz(lambda);
                for c in 0..3 {
                    xyz[c] += s * cmf[c];
                }
            }
            let [x, y, z] = xyz.map(|v| v / y_integral);
            let r = 3.240_454_2 * x - 1.537_138_5 * y - 0.498_531_4 * z;
            let g = -0.969_266_0 * x + 1.876_010_8 * y + 0.041_556_0 * z;
            let b = 0.055_643_4 * x - 0.204_025_9 * y + 1.057_225_2 * z;
            Vec3::new(r as f32, g as f32, b as f32).max(Vec3::ZERO)
        })
        .collect()
}

/// Planck's law: spectral radiance at wavelength `lambda` (metres) and
/// temperature `t` (kelvin), W / (sr m^3).
fn planck(lambda: f64, t: f64) -> f64 {
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    const KB: f64 = 1.380_649e-23;
    let l5 = lambda.powi(5);
    (2.0 * H * C * C) / (l5 * ((H * C / (lambda * KB * t)).exp() - 1.0))
}

/// Wyman, Sloan, Shirley (2013) multi-lobe fit of the CIE 1931 2-degree
/// colour matching functions at `lambda` nanometres.
fn cie_xyz(lambda: f64) -> [f64; 3] {
    let g = |mu: f64, s1: f64, s2: f64| {
        let t = (lambda - mu) / if lambda < mu { s1 } else { s2 };
        (-0.5 * t * t).exp()
    };
    [
        1.056 * g(599.8, 37.9, 31.0) + 0.362 * g(442.0, 16.0, 26.7) - 0.065 * g(501.1, 20.4, 26.2),
        0.821 * g(568.8, 46.9, 40.5) + 0.286 * g(530.9, 16.3, 31.1),
        1.217 * g(437.0, 11.8, 36.0) + 0.681 * g(459.0, 26.0, 13.8),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blackbody_colours_run_from_red_to_blue() {
        assert_eq!(blackbody_rgb(100.0), Vec3::ZERO);
        assert_eq!(blackbody_rgb(f32::NAN), Vec3::ZERO);
        // Candle/fire temperatures are red-orange: r > g > b.
        let fire = blackbody_rgb(1500.0);
        assert!(fire.x > fire.y && fire.y > fire.z, "{fire}");
        // Near 6500 K the normalised spectrum is close to white (D65 is
        // not a blackbody, so only roughly): channels within 15%.
        let white = blackbody_rgb(6500.0);
        assert!(white.max_element() < 1.15 * white.min_element(), "{white}");
        // Hot stars are blue.
        let hot = blackbody_rgb(20_000.0);
        assert!(hot.z > hot.x, "{hot}");
        // Brighter (in the visible, relative to the peak) as T rises to the
        // visible range: 1000 K is far dimmer than 3000 K.
        assert!(blackbody_rgb(1000.0).x < 0.05 * blackbody_rgb(3000.0).x);
    }
}
