//! Phase functions: [`Phase`], what a medium scatters with.
//!
//! Convention: both directions are *propagation* directions along the path
//! from the camera, so `mu = dot(dir_in, dir_out)` is the cosine of the
//! scattering angle and a forward-peaked function (`g > 0`) scatters with
//! `dir_out` near `dir_in`. For next-event estimation `dir_out` is the
//! direction toward the light, which by reciprocity gives the same `mu` as
//! the light's own path. Every function here depends on `mu` alone, so
//! `eval(a, b) == eval(-b, -a)`.
//!
//! Every variant is sampled exactly: `sample` draws `mu` by inverting the
//! CDF in closed form (or, for blends, picks a lobe and inverts its CDF)
//! and returns `pdf == eval`. The integrators rely on this: a sampled
//! direction's weight `eval / pdf` is 1, and the phase pdf for MIS is the
//! phase value.
//!
//! - `hg`: Henyey-Greenstein, the default.
//! - `blend`: a convex combination of two lobes (two-lobe HG, HG + Draine).
//! - `draine`: Draine (2003), HG times `1 + alpha mu^2`.
//! - `mie`: the approximate Mie fit of Jendersie and d'Eon (2023).
//! - `rayleigh`: Rayleigh scattering.
//! - `table` and `table_file`: a piecewise-linear function of `mu` given as
//!   a table, in memory or in a text file.

mod blend;
mod draine;
mod hg;
mod mie;
mod rayleigh;
mod table;
mod table_file;

use std::f32::consts::PI;
use std::path::Path;
use std::sync::Arc;

use glam::Vec3;

pub use blend::Blend;
pub use draine::Draine;
pub use hg::{HenyeyGreenstein, MAX_ABS_G};
pub use mie::{MieFit, MIE_DIAMETER_RANGE_UM};
pub use rayleigh::Rayleigh;
pub use table::{TabulatedPhase, MAX_TABLE_ROWS};

use crate::error::{Error, Result};
use crate::sampling::from_local;

/// A rotationally symmetric phase function: a density of `mu` per
/// steradian that integrates to 1 over the sphere.
pub trait Lobe {
    /// Density per steradian at scattering-angle cosine `mu`.
    fn eval_cos(&self, mu: f32) -> f32;
    /// `mu` distributed with density `2 pi eval_cos(mu)` on `[-1, 1]`, from
    /// one uniform `u` in `[0, 1)` (monotone in `u`).
    fn sample_cos(&self, u: f32) -> f32;
    /// The mean of `mu`: the first Legendre coefficient (the asymmetry
    /// parameter).
    fn mean_cosine(&self) -> f32;
}

/// The phase function of a medium.
///
/// Small variants are plain values; a table is shared behind an [`Arc`], so
/// cloning a `Phase` never copies it (and collisions borrow the phase,
/// see [`Interaction`](crate::medium::Interaction)).
#[derive(Clone, Debug, PartialEq)]
pub enum Phase {
    /// Henyey-Greenstein; [`Phase::hg`].
    Hg(HenyeyGreenstein),
    /// `w HG(g1) + (1 - w) HG(g2)`; [`Phase::hg2`].
    TwoHg(Blend<HenyeyGreenstein, HenyeyGreenstein>),
    /// [`Phase::draine`].
    Draine(Draine),
    /// `(1 - w_D) HG(g_HG) + w_D Draine(g_D, alpha)`, the shape of the
    /// approximate Mie fit; [`Phase::mie`].
    HgDraine(Blend<HenyeyGreenstein, Draine>),
    /// [`Phase::rayleigh`].
    Rayleigh(Rayleigh),
    /// [`Phase::table`], [`Phase::read_table`].
    Table(Arc<TabulatedPhase>),
}

impl Default for Phase {
    /// Isotropic scattering.
    fn default() -> Self {
        Phase::hg(0.0)
    }
}

impl Phase {
    /// Henyey-Greenstein with asymmetry `g`, clamped to
    /// `[-MAX_ABS_G, MAX_ABS_G]`; |g| below 1e-3 and NaN give isotropic
    /// (as [`HenyeyGreenstein::new`]). Never fails, so media keep their
    /// `g` constructors.
    pub fn hg(g: f32) -> Phase {
        Phase::Hg(HenyeyGreenstein::new(g))
    }

    /// Two HG lobes, `w1 HG(g1) + (1 - w1) HG(g2)`; each `g` is clamped as
    /// in [`Phase::hg`]. Errors: a non-finite `g`, or `w1` outside `[0, 1]`.
    pub fn hg2(g1: f32, g2: f32, w1: f32) -> Result<Phase> {
        let lobe = |g: f32| {
            if g.is_finite() {
                Ok(HenyeyGreenstein::new(g))
            } else {
                Err(Error::invalid(format!(
                    "HG asymmetry g must be finite, got {g}"
                )))
            }
        };
        Ok(Phase::TwoHg(Blend::new(lobe(g1)?, lobe(g2)?, w1)?))
    }

    /// Draine (2003) with asymmetry-like `g` (clamped as in [`Phase::hg`])
    /// and `alpha >= 0`; see [`Draine::new`].
    pub fn draine(g: f32, alpha: f32) -> Result<Phase> {
        Ok(Phase::Draine(Draine::new(g, alpha)?))
    }

    /// The approximate Mie phase function of cloud and fog droplets of
    /// diameter `diameter_um` (micrometres), Jendersie and d'Eon (2023).
    /// Diameters outside the fit's range `[5, 50]` are refused, not
    /// clamped; see [`MieFit::new`].
    pub fn mie(diameter_um: f32) -> Result<Phase> {
        Ok(Phase::HgDraine(MieFit::new(diameter_um)?.blend()?))
    }

    /// Rayleigh scattering, `3 / (16 pi) (1 + mu^2)`.
    pub fn rayleigh() -> Phase {
        Phase::Rayleigh(Rayleigh)
    }

    /// A piecewise-linear function of `mu` through the points
    /// `(cos_values[i], values[i])`, normalised to integrate to 1; see
    /// [`TabulatedPhase::new`] for what is accepted.
    pub fn table(cos_values: &[f32], values: &[f32]) -> Result<Phase> {
        Ok(Phase::Table(Arc::new(TabulatedPhase::new(
            cos_values, values,
        )?)))
    }

    /// [`Phase::table`] from a text file of two columns, `cos(theta)` and
    /// value, separated by whitespace or a comma; `#` starts a comment.
    /// Errors name the file and, for a bad row, the line.
    pub fn read_table(path: impl AsRef<Path>) -> Result<Phase> {
        let path = path.as_ref();
        let (cos, values) = table_file::read(path)?;
        Phase::table(&cos, &values).map_err(|e| Error::format(path, e))
    }

    /// Density per steradian for scattering-angle cosine `mu`.
    #[inline]
    pub fn eval_cos(&self, mu: f32) -> f32 {
        match self {
            Phase::Hg(p) => p.eval_cos(mu),
            Phase::TwoHg(p) => p.eval_cos(mu),
            Phase::Draine(p) => p.eval_cos(mu),
            Phase::HgDraine(p) => p.eval_cos(mu),
            Phase::Rayleigh(p) => p.eval_cos(mu),
            Phase::Table(p) => p.eval_cos(mu),
        }
    }

    /// Density of scattering from propagation direction `dir_in` into
    /// `dir_out` (both unit vectors).
    #[inline]
    pub fn eval(&self, dir_in: Vec3, dir_out: Vec3) -> f32 {
        self.eval_cos(dir_in.dot(dir_out))
    }

    /// The solid-angle density with which [`Phase::sample`] returns
    /// `dir_out`: the phase value, since every variant samples exactly.
    #[inline]
    pub fn pdf(&self, dir_in: Vec3, dir_out: Vec3) -> f32 {
        self.eval(dir_in, dir_out)
    }

    /// A scattering-angle cosine with density `2 pi eval_cos(mu)`, from one
    /// uniform number.
    #[inline]
    pub fn sample_cos(&self, u: f32) -> f32 {
        match self {
            Phase::Hg(p) => p.sample_cos(u),
            Phase::TwoHg(p) => p.sample_cos(u),
            Phase::Draine(p) => p.sample_cos(u),
            Phase::HgDraine(p) => p.sample_cos(u),
            Phase::Rayleigh(p) => p.sample_cos(u),
            Phase::Table(p) => p.sample_cos(u),
        }
    }

    /// Samples an outgoing propagation direction from two uniform numbers:
    /// `mu` from `u1`, the azimuth `2 pi u2` about `dir_in`. Returns it and
    /// its pdf, which equals the phase value (the path weight is 1).
    #[inline]
    pub fn sample(&self, dir_in: Vec3, u1: f32, u2: f32) -> (Vec3, f32) {
        let mu = self.sample_cos(u1);
        let sin = (1.0 - mu * mu).max(0.0).sqrt();
        let phi = 2.0 * PI * u2;
        let dir = from_local(dir_in, sin * phi.cos(), sin * phi.sin(), mu);
        (dir, self.eval_cos(mu))
    }

    /// The mean scattering cosine `<mu>`: `g` itself for HG. The light
    /// grid's first-order (band 1) in-scattering term uses it.
    pub fn mean_cosine(&self) -> f32 {
        match self {
            Phase::Hg(p) => p.mean_cosine(),
            Phase::TwoHg(p) => p.mean_cosine(),
            Phase::Draine(p) => p.mean_cosine(),
            Phase::HgDraine(p) => p.mean_cosine(),
            Phase::Rayleigh(p) => p.mean_cosine(),
            Phase::Table(p) => p.mean_cosine(),
        }
    }
}
