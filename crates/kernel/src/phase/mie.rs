//! The approximate Mie phase function of water droplets.

use super::blend::Blend;
use super::draine::Draine;
use super::hg::HenyeyGreenstein;
use crate::error::{Error, Result};

/// The droplet diameters, in micrometres, that the fit below covers. The
/// paper fits smaller droplets with other formulas (its eqs. 11-22), which
/// are not implemented: [`MieFit::new`] refuses diameters outside this
/// range rather than clamping them, so a scene never silently renders a
/// droplet size other than the one it asked for.
pub const MIE_DIAMETER_RANGE_UM: (f32, f32) = (5.0, 50.0);

/// Jendersie and d'Eon (2023), "An Approximate Mie Scattering Function for
/// Fog and Cloud Rendering" (SIGGRAPH 2023 Talks; supplemental, eqs. 7-10,
/// for 5 <= d <= 50 um): Mie scattering by water droplets of diameter `d`
/// is fitted by `(1 - w_D) HG(g_HG) + w_D Draine(g_D, alpha)` with
///
/// - `g_HG = exp(-0.0990567 / (d - 1.67154))`
/// - `g_D = exp(-2.20679 / (d + 3.91029) - 0.428934)`
/// - `alpha = exp(3.62489 - 8.29288 / (d + 5.52825))`
/// - `w_D = exp(-0.599085 / (d - 0.641583) - 0.665888)`
///
/// The constants were checked against Blender Cycles' implementation of
/// the same fit (`phase_mie_fitted_parameters` in
/// `intern/cycles/kernel/closure/volume_util.h`, its "Eq (7 - 10)" branch).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MieFit {
    pub diameter_um: f32,
    pub g_hg: f32,
    pub g_d: f32,
    pub alpha: f32,
    /// The Draine lobe's weight.
    pub w_d: f32,
}

impl MieFit {
    /// Errors for a non-finite diameter or one outside
    /// [`MIE_DIAMETER_RANGE_UM`].
    pub fn new(diameter_um: f32) -> Result<Self> {
        let (lo, hi) = MIE_DIAMETER_RANGE_UM;
        if !(lo..=hi).contains(&diameter_um) {
            return Err(Error::invalid(format!(
                "droplet diameter must be in [{lo}, {hi}] um (the range of the \
                 Jendersie-d'Eon fit), got {diameter_um}"
            )));
        }
        let d = f64::from(diameter_um);
        Ok(Self {
            diameter_um,
            g_hg: (-0.0990567 / (d - 1.67154)).exp() as f32,
            g_d: (-2.20679 / (d + 3.91029) - 0.428934).exp() as f32,
            alpha: (3.62489 - 8.29288 / (d + 5.52825)).exp() as f32,
            w_d: (-0.599085 / (d - 0.641583) - 0.665888).exp() as f32,
        })
    }

    /// The phase function: HG first, with weight `1 - w_D`. Over the
    /// fitted range `g_HG` is in [0.97, 0.998] (below HG's clamp),
    /// `g_D` in [0.5, 0.63], `alpha` in [17, 33] and `w_D` in [0.45, 0.51],
    /// so the lobe constructors accept them unchanged (the errors cannot
    /// occur for a `MieFit` from [`MieFit::new`]).
    pub fn blend(&self) -> Result<Blend<HenyeyGreenstein, Draine>> {
        let hg = HenyeyGreenstein::new(self.g_hg);
        let draine = Draine::new(self.g_d, self.alpha)?;
        Blend::new(hg, draine, 1.0 - self.w_d)
    }
}
