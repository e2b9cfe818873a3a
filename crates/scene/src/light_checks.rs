//! The checks of a description's lights, before any is made: each
//! `[[light]]` on its own (its kind, the keys its kind takes, every value
//! finite and in range, and the values made from them within what a
//! render's f32 arithmetic carries: [`cirrus_render::MAX_LIGHT_VALUE`]),
//! the `[sun]` and `[environment]` tables (and so their flags) alike, and
//! the sky maps named. Scene files and USD stages both come through here,
//! so a light is refused by the same rule whichever wrote it.

use cirrus_render::kernel::light::shown;
use cirrus_render::{Environment, Light, Sun, MAX_LIGHT_EXTENT, MAX_LIGHT_VALUE};
use glam::Vec3;

use crate::description::{EnvironmentSpec, LightSpec, SceneDescription, SunSpec};
use crate::error::{Error, Result};

/// The smallest radius of a sphere or spot light that is a surface: its
/// area `4 pi r^2` and radiance stay normal f32 numbers above it.
const MIN_SURFACE_RADIUS: f32 = 1e-12;
/// The kinds of `[[light]]`.
const KINDS: [&str; 8] = [
    "distant", "sphere", "point", "spot", "rect", "disk", "cylinder", "dome",
];

/// The keys each kind takes besides `type`, `name`, `group`, `color`,
/// `intensity` and `exposure`.
fn keys_of(kind: &str) -> &'static [&'static str] {
    match kind {
        "distant" => &["direction", "angle"],
        "sphere" => &[
            "position",
            "radius",
            "normalize",
            "visible_to_camera",
            "soft_falloff",
        ],
        "point" => &["position"],
        "spot" => &[
            "position",
            "direction",
            "radius",
            "normalize",
            "cone_angle",
            "cone_softness",
            "visible_to_camera",
            "soft_falloff",
        ],
        "rect" => &[
            "position",
            "direction",
            "up",
            "width",
            "height",
            "normalize",
            "visible_to_camera",
        ],
        "disk" => &[
            "position",
            "direction",
            "up",
            "radius",
            "width",
            "height",
            "normalize",
            "visible_to_camera",
        ],
        "cylinder" => &[
            "position",
            "direction",
            "radius",
            "length",
            "normalize",
            "visible_to_camera",
        ],
        _ => &["map", "rotation"],
    }
}

impl LightSpec {
    /// The keys given, by their names in the file.
    fn given(&self) -> Vec<&'static str> {
        let present = [
            ("position", self.position.is_some()),
            ("direction", self.direction.is_some()),
            ("up", self.up.is_some()),
            ("width", self.width.is_some()),
            ("height", self.height.is_some()),
            ("length", self.length.is_some()),
            ("radius", self.radius.is_some()),
            ("normalize", self.normalize.is_some()),
            ("angle", self.angle.is_some()),
            ("cone_angle", self.cone_angle.is_some()),
            ("cone_softness", self.cone_softness.is_some()),
            ("map", self.map.is_some()),
            ("visible_to_camera", self.visible_to_camera.is_some()),
            ("soft_falloff", self.soft_falloff.is_some()),
            ("rotation", self.rotation.is_some()),
        ];
        present.iter().filter(|p| p.1).map(|p| p.0).collect()
    }

    /// Checks the light on its own: its kind, the keys its kind takes,
    /// and every value finite and in range, at each of its keys where it
    /// has any ([`LightSpec::check_keys`]).
    pub fn check(&self) -> std::result::Result<(), String> {
        let kind = self.kind.as_str();
        if !KINDS.contains(&kind) {
            return Err(format!(
                "unknown type {kind:?}; one of {}",
                KINDS.join(", ")
            ));
        }
        match self.keys {
            Some(_) => self.check_keys(keys_of(kind)),
            None => self.check_unkeyed(),
        }
    }

    /// [`Self::check`] of a light whose keys are folded in.
    pub(crate) fn check_unkeyed(&self) -> std::result::Result<(), String> {
        let kind = self.kind.as_str();
        let takes = keys_of(kind);
        if let Some(key) = self.given().into_iter().find(|k| !takes.contains(k)) {
            return Err(format!("`{key}` does not apply to a {kind} light"));
        }
        self.check_values()?;
        self.check_kind()?;
        self.check_derived()
    }

    /// Every value given finite and in range.
    fn check_values(&self) -> std::result::Result<(), String> {
        let finite = |key: &str, v: &[f32]| {
            if v.iter().all(|x| x.is_finite()) {
                Ok(())
            } else {
                Err(format!("`{key}` is not finite: {v:?}"))
            }
        };
        let at_least_zero = |key: &str, v: &[f32]| {
            finite(key, v)?;
            if v.iter().all(|&x| x >= 0.0) {
                Ok(())
            } else {
                Err(format!("`{key}` is negative: {v:?}"))
            }
        };
        at_least_zero("intensity", &[self.intensity.unwrap_or(1.0)])?;
        at_least_zero("color", &self.color.unwrap_or([1.0; 3]))?;
        finite("exposure", &[self.exposure.unwrap_or(0.0)])?;
        for (key, v) in [("position", self.position), ("up", self.up)] {
            v.map_or(Ok(()), |v| finite(key, &v))?;
        }
        for (key, v) in [("radius", self.radius), ("angle", self.angle)] {
            v.map_or(Ok(()), |v| at_least_zero(key, &[v]))?;
        }
        if let Some(r) = self.rotation {
            finite("rotation", &[r])?;
        }
        if self.map.as_ref().is_some_and(|m| m.as_os_str().is_empty()) {
            return Err(
                "`map` is empty: give an EXR file, or leave `map` out for a constant dome".into(),
            );
        }
        for (key, size) in [
            ("width", self.width),
            ("height", self.height),
            ("length", self.length),
        ] {
            if let Some(x) = size {
                finite(key, &[x])?;
                if x <= 0.0 {
                    return Err(format!(
                        "`{key}` {x} is not positive: an area light needs an area"
                    ));
                }
            }
        }
        if let Some(d) = self.direction {
            finite("direction", &d)?;
            if Vec3::from_array(d).length_squared() == 0.0 {
                return Err("`direction` is zero".into());
            }
        }
        Ok(())
    }

    /// What the light's kind needs: its position, direction, size, cone.
    fn check_kind(&self) -> std::result::Result<(), String> {
        let kind = self.kind.as_str();
        if matches!(kind, "disk" | "cylinder") && self.radius == Some(0.0) {
            return Err("`radius` 0: an area light needs an area".into());
        }
        if kind == "disk"
            && self.radius.is_some()
            && (self.width.is_some() || self.height.is_some())
        {
            return Err("give a disk `radius`, or `width` and `height`, not both".into());
        }
        match kind {
            "distant" if self.direction.is_none() => {
                Err("a distant light needs `direction`".into())
            }
            "sphere" | "point" | "spot" if self.position.is_none() => {
                Err(format!("a {kind} light needs `position`"))
            }
            "spot" | "rect" | "disk" | "cylinder" if self.direction.is_none() => {
                Err(format!("a {kind} light needs `direction`"))
            }
            "rect" | "disk" | "cylinder" if self.position.is_none() => {
                Err(format!("a {kind} light needs `position`"))
            }
            "spot" => {
                let angle = self.cone_angle.ok_or("a spot light needs `cone_angle`")?;
                if !(angle > 0.0 && angle <= 180.0) {
                    return Err(format!(
                        "`cone_angle` {angle} is not in (0, 180] degrees (the half-angle off the axis)"
                    ));
                }
                let soft = self.cone_softness.unwrap_or(0.0);
                if !(0.0..=1.0).contains(&soft) {
                    return Err(format!("`cone_softness` {soft} is not in [0, 1]"));
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// The values made from the keys (`intensity * 2^exposure * color`,
    /// then the light's radiance, area or intensity) within what a
    /// render's f32 arithmetic carries ([`Light::check_limits`]); a
    /// dome's map stands in as its multiplier.
    fn check_derived(&self) -> std::result::Result<(), String> {
        let strength = self.strength();
        if !strength.is_finite() || strength.max_element() > MAX_LIGHT_VALUE {
            return Err(format!(
                "`intensity` x 2^`exposure` x `color` is {}: past {MAX_LIGHT_VALUE:e}, more than a render's f32 arithmetic can carry",
                shown(strength)
            ));
        }
        for (key, v) in [
            ("radius", self.radius),
            ("width", self.width),
            ("height", self.height),
            ("length", self.length),
        ] {
            if v.is_some_and(|v| v > MAX_LIGHT_EXTENT) {
                return Err(format!(
                    "`{key}` {:e} is past {MAX_LIGHT_EXTENT:e} units, where areas and squared distances overflow f32",
                    v.unwrap_or_default()
                ));
            }
        }
        if let Some(p) = self.position.map(Vec3::from_array) {
            if p.abs().max_element() > MAX_LIGHT_EXTENT {
                return Err(format!(
                    "`position` {} is past {MAX_LIGHT_EXTENT:e} units from the origin, where squared distances overflow f32",
                    shown(p)
                ));
            }
        }
        let r = self.radius.unwrap_or(0.0);
        if matches!(self.kind.as_str(), "sphere" | "spot") && r > 0.0 && r < MIN_SURFACE_RADIUS {
            return Err(format!(
                "`radius` {r:e} is too small to be a surface in f32 (under {MIN_SURFACE_RADIUS:e}): give `radius = 0`, a point"
            ));
        }
        let light = match self.kind.as_str() {
            "dome" => Environment::new(strength).into(),
            _ => self.light().map_err(|e| e.to_string())?,
        };
        let keys = self.value_keys();
        light
            .check_limits()
            .map_err(|e| format!("{e} (made from {keys})"))?;
        if strength.max_element() > 0.0 && light.is_black() {
            return Err(format!(
                "it delivers no light in f32: its values ({keys}) underflow to 0"
            ));
        }
        Ok(())
    }

    /// The keys given that its strength and shape are made from, for
    /// messages: "`intensity`, `radius`".
    fn value_keys(&self) -> String {
        let strength = [
            ("intensity", self.intensity.is_some()),
            ("exposure", self.exposure.is_some()),
            ("color", self.color.is_some()),
        ];
        let shape = ["radius", "width", "height", "length", "normalize", "angle"];
        let keys: Vec<String> = strength
            .iter()
            .filter(|k| k.1)
            .map(|k| k.0)
            .chain(self.given().into_iter().filter(|k| shape.contains(k)))
            .map(|k| format!("`{k}`"))
            .collect();
        if keys.is_empty() {
            "its defaults".into()
        } else {
            keys.join(", ")
        }
    }
}

impl SunSpec {
    /// The `[sun]` table's (or its flags') values, as a distant light's
    /// are checked: a finite, non-zero direction, an irradiance finite,
    /// at least 0 and within what a render carries, an angle in [0, 180]
    /// degrees.
    pub fn check(&self) -> std::result::Result<(), String> {
        let dir = Vec3::from_array(self.sun_dir());
        if !dir.is_finite() || dir.length_squared() == 0.0 {
            return Err(format!(
                "[sun] direction {} must be finite and not zero",
                shown(dir)
            ));
        }
        let e = Vec3::from_array(self.sun_irradiance());
        if !e.is_finite() || e.min_element() < 0.0 {
            return Err(format!(
                "[sun] irradiance {} must be finite and at least 0",
                shown(e)
            ));
        }
        let angle = self.sun_angle();
        if !(0.0..=180.0).contains(&angle) {
            return Err(format!("[sun] angle {angle} is not in [0, 180] degrees"));
        }
        Light::from(Sun::new(dir, e, angle.to_radians()))
            .check_limits()
            .map_err(|e| format!("[sun] {e}"))
    }
}

impl EnvironmentSpec {
    /// The `[environment]` table's (or its flags') values: a radiance and
    /// a map's intensity finite, at least 0 and within what a render
    /// carries, a finite rotation.
    pub fn check(&self) -> std::result::Result<(), String> {
        let l = Vec3::from_array(self.env_radiance());
        if !l.is_finite() || l.min_element() < 0.0 {
            return Err(format!(
                "[environment] radiance {} must be finite and at least 0",
                shown(l)
            ));
        }
        let k = self.env_intensity();
        if !k.is_finite() || k < 0.0 {
            return Err(format!(
                "[environment] intensity {k} must be finite and at least 0"
            ));
        }
        if self
            .env_map
            .as_ref()
            .is_some_and(|m| m.as_os_str().is_empty())
        {
            return Err("[environment] map is empty: give an EXR file, or leave `map` out".into());
        }
        let r = self.env_rotation();
        if !r.is_finite() {
            return Err(format!("[environment] rotation {r} is not finite"));
        }
        for v in [l, Vec3::splat(k)] {
            Light::from(Environment::new(v))
                .check_limits()
                .map_err(|e| format!("[environment] {e}"))?;
        }
        Ok(())
    }
}

/// Checks that every sky map a description names (`[environment] map`,
/// a dome's `map`) is a file that exists, naming the table or light and
/// the key: read later, when the render starts, its error would name only
/// the map.
pub(crate) fn check_maps(desc: &SceneDescription) -> Result<()> {
    let env = desc.environment.as_ref().and_then(|e| e.env_map.as_deref());
    let lights = desc
        .lights
        .iter()
        .enumerate()
        .filter_map(|(i, l)| Some((format!("{}: `map`", l.label(i)), l.map.as_deref()?)));
    for (what, path) in env
        .map(|p| ("[environment] map".to_string(), p))
        .into_iter()
        .chain(lights)
    {
        let why = match std::fs::metadata(path) {
            Err(e) => e.to_string(),
            Ok(m) if m.is_dir() => "a directory, not an EXR file".into(),
            Ok(_) => continue,
        };
        return Err(Error::file(format!("{what} {}: {why}", path.display())));
    }
    Ok(())
}

/// Checks the `[sun]` and `[environment]` tables a description has.
pub(crate) fn check_shorthands(desc: &SceneDescription) -> std::result::Result<(), String> {
    if let Some(sun) = desc.sun.as_ref().filter(|s| s.sun()) {
        sun.check()?;
    }
    if let Some(env) = &desc.environment {
        env.check()?;
    }
    Ok(())
}
