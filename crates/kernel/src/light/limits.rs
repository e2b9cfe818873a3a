//! What a render's `f32` arithmetic can carry: the limits every light's
//! derived values are checked against where a scene is read, so a light
//! that would overflow (or underflow into nothing) is refused by name
//! instead of rendering a black image of dropped samples.
//!
//! A path multiplies a light's radiance by throughputs, phase values (up
//! to about 1.6e5 for an HG lobe of g = 0.999), MIS weights and inverse
//! densities (a distant light's radiance is its irradiance over its solid
//! angle, 1/6.7e-5 for the sun), so values past [`MAX_LIGHT_VALUE`] leave
//! such products no room below `f32::MAX` (3.4e38). Positions and sizes
//! past [`MAX_LIGHT_EXTENT`] make squared distances and areas of 1e24 and
//! more, which the same products overflow.

use glam::Vec3;

use super::{AreaLight, Environment, Light, SphereLight, Sun};

/// The largest radiance, irradiance or radiant intensity a light may have.
pub const MAX_LIGHT_VALUE: f32 = 1e30;

/// The largest position coordinate, radius, width, height or length a
/// light may have, in scene units.
pub const MAX_LIGHT_EXTENT: f32 = 1e12;

/// `v` as a person writes it in a message: `[3.400e41, 0, inf]`.
pub fn shown(v: Vec3) -> String {
    let n = |x: f32| {
        if x != 0.0 && x.is_finite() && (x.abs() >= 1e6 || x.abs() < 1e-4) {
            format!("{x:.3e}")
        } else {
            format!("{x}")
        }
    };
    format!("[{}, {}, {}]", n(v.x), n(v.y), n(v.z))
}

/// `Err` naming `what` where `v` is not finite, negative or past
/// [`MAX_LIGHT_VALUE`].
fn check_value(what: &str, v: Vec3) -> Result<(), String> {
    if !v.is_finite() {
        return Err(format!("its {what} {} is not finite in f32", shown(v)));
    }
    if v.max_element() > MAX_LIGHT_VALUE {
        return Err(format!(
            "its {what} {} is past {MAX_LIGHT_VALUE:e}, more than a render's f32 arithmetic can carry",
            shown(v)
        ));
    }
    Ok(())
}

/// `Err` naming `what` where a position or size is not finite or past
/// [`MAX_LIGHT_EXTENT`].
fn check_extent(what: &str, v: Vec3) -> Result<(), String> {
    if !v.is_finite() || v.abs().max_element() > MAX_LIGHT_EXTENT {
        return Err(format!(
            "its {what} {} is past {MAX_LIGHT_EXTENT:e} units, where squared distances overflow f32",
            shown(v)
        ));
    }
    Ok(())
}

impl Light {
    /// Checks the values the light was made with and those derived from
    /// them against the limits above; `Err` says which value and why.
    pub fn check_limits(&self) -> Result<(), String> {
        match self {
            Self::Distant(sun) => sun.check_limits(),
            Self::Dome(env) => env.check_limits(),
            Self::Sphere(s) => s.check_limits(),
            Self::Area(a) => a.check_limits(),
        }
    }
}

impl Sun {
    fn check_limits(&self) -> Result<(), String> {
        if !self.direction().is_finite() {
            return Err("its direction is zero or not finite".into());
        }
        check_value("irradiance", self.irradiance())?;
        if !self.is_delta() {
            check_value(
                "radiance (irradiance over the disc's solid angle)",
                self.irradiance() / self.solid_angle(),
            )?;
        }
        Ok(())
    }
}

impl Environment {
    fn check_limits(&self) -> Result<(), String> {
        check_value("mean radiance", self.mean_radiance())
    }
}

impl SphereLight {
    fn check_limits(&self) -> Result<(), String> {
        check_extent("position", self.position())?;
        check_extent("radius", Vec3::splat(self.radius()))?;
        check_value("radiant intensity", self.intensity())?;
        if let Some(spot) = self.spot() {
            if !spot.axis().is_finite() {
                return Err("its spot axis is zero or not finite".into());
            }
        }
        if !self.is_point() {
            check_value("surface radiance", self.radiance())?;
        }
        Ok(())
    }
}

impl AreaLight {
    fn check_limits(&self) -> Result<(), String> {
        check_extent("centre", self.centre())?;
        check_extent("size", Vec3::splat(self.area().sqrt()))?;
        // NaN is not positive either.
        if self.area().is_nan() || self.area() <= 0.0 {
            return Err(format!("its area {:e} is not positive in f32", self.area()));
        }
        if !self.normal().is_finite() {
            return Err("its normal is zero or not finite".into());
        }
        check_value("radiance", self.radiance())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{AreaShape, Spot};

    #[test]
    fn lights_within_the_limits_pass_and_each_overflow_is_named() {
        let ok: [Light; 4] = [
            Sun::new(Vec3::NEG_Y, Vec3::splat(3.0), 0.01).into(),
            Environment::new(Vec3::splat(1e3)).into(),
            SphereLight::new(Vec3::splat(1e11), 1e3, Vec3::splat(1e29)).into(),
            AreaLight::new(
                AreaShape::Rect,
                Vec3::ZERO,
                Vec3::X,
                Vec3::Z,
                Vec3::Y,
                Vec3::ONE,
            )
            .into(),
        ];
        for l in &ok {
            assert_eq!(l.check_limits(), Ok(()), "{l:?}");
        }
        let bad: [(Light, &str); 8] = [
            (Sun::new(Vec3::ZERO, Vec3::ONE, 0.0).into(), "direction"),
            (
                Sun::new(Vec3::Y, Vec3::splat(f32::INFINITY), 0.0).into(),
                "irradiance",
            ),
            // 1e30 W/m^2 over the sun's 6.7e-5 sr.
            (
                Sun::new(Vec3::Y, Vec3::splat(1e30), 0.0093).into(),
                "radiance",
            ),
            (Environment::new(Vec3::splat(2e30)).into(), "mean radiance"),
            (
                SphereLight::new(Vec3::new(1e20, 0.0, 0.0), 1.0, Vec3::ONE).into(),
                "position",
            ),
            (
                SphereLight::new(Vec3::ZERO, 1e19, Vec3::ONE).into(),
                "radius",
            ),
            // A ball of 1e-20 radius sending 1: its surface is 3e39 bright.
            (
                SphereLight::new(Vec3::ZERO, 1e-20, Vec3::ONE).into(),
                "surface radiance",
            ),
            (
                SphereLight::new(Vec3::ZERO, 0.0, Vec3::ONE)
                    .with_spot(Spot::new(Vec3::ZERO, 0.5, 0.0))
                    .into(),
                "spot axis",
            ),
        ];
        for (l, what) in &bad {
            let e = l.check_limits().expect_err(what);
            assert!(e.contains(what), "{e:?} should name {what}");
        }
    }
}
