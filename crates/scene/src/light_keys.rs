//! Lights that change over time: a `[[light]]`'s `keys`, each a time in
//! frames and the values the light has then (`position`, `direction`,
//! `color`, `intensity`, sizes, a spot's cone). A value keyed at least
//! once is interpolated linearly between the keys that give it and held
//! before the first and after the last; a value no key gives is the
//! table's. Directions are interpolated as vectors and normalised where
//! the light is made (so they turn at a speed that varies a little within
//! a segment, the same path USD takes between two sampled vectors).
//!
//! A frame renders its lights at its own instant and, where the shutter
//! is open, at the times the renderer tabulates over it
//! ([`LightSpec::moves_within`] says whether it needs to).

use glam::Vec3;
use serde::Deserialize;

use crate::description::LightSpec;
use crate::values::check_samples;

/// A light's values at a time (frames); the values not given are the
/// other keys' (or the table's).
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LightKey {
    pub time: f64,
    #[serde(default, deserialize_with = "crate::parse::triple_field")]
    pub position: Option<[f32; 3]>,
    #[serde(default, deserialize_with = "crate::parse::triple_field")]
    pub direction: Option<[f32; 3]>,
    #[serde(default, deserialize_with = "crate::parse::triple_field")]
    pub up: Option<[f32; 3]>,
    #[serde(default, deserialize_with = "crate::parse::triple_field")]
    pub color: Option<[f32; 3]>,
    pub intensity: Option<f32>,
    pub exposure: Option<f32>,
    pub radius: Option<f32>,
    pub width: Option<f32>,
    pub height: Option<f32>,
    pub length: Option<f32>,
    pub angle: Option<f32>,
    pub cone_angle: Option<f32>,
    pub cone_softness: Option<f32>,
}

/// Applies `$do!(field)` to each value a key can give.
macro_rules! each_keyed_value {
    ($do:ident) => {
        $do!(position);
        $do!(direction);
        $do!(up);
        $do!(color);
        $do!(intensity);
        $do!(exposure);
        $do!(radius);
        $do!(width);
        $do!(height);
        $do!(length);
        $do!(angle);
        $do!(cone_angle);
        $do!(cone_softness);
    };
}

impl LightKey {
    /// The values the key gives, by their names in the file.
    fn given(&self) -> Vec<&'static str> {
        let mut names = Vec::new();
        macro_rules! name_of {
            ($f:ident) => {
                if self.$f.is_some() {
                    names.push(stringify!($f));
                }
            };
        }
        each_keyed_value!(name_of);
        names
    }
}

impl LightKey {
    /// The key at `time` of every value `spec` gives that a key can.
    pub fn of(spec: &LightSpec, time: f64) -> LightKey {
        let mut key = LightKey {
            time,
            ..Default::default()
        };
        macro_rules! copy {
            ($f:ident) => {
                key.$f = spec.$f;
            };
        }
        each_keyed_value!(copy);
        key
    }
}

/// A value interpolated linearly between two keys.
trait Keyed: Copy {
    fn lerp(a: Self, b: Self, u: f32) -> Self;
}

impl Keyed for f32 {
    fn lerp(a: f32, b: f32, u: f32) -> f32 {
        a + (b - a) * u
    }
}

impl Keyed for [f32; 3] {
    fn lerp(a: [f32; 3], b: [f32; 3], u: f32) -> [f32; 3] {
        Vec3::from_array(a).lerp(Vec3::from_array(b), u).to_array()
    }
}

/// The value `get` reads off the keys at `time`: interpolated between the
/// two keys about it that give one, held outside them; `None` where no
/// key gives it.
fn keyed_at<T: Keyed>(
    keys: &[LightKey],
    time: f64,
    get: impl Fn(&LightKey) -> Option<T>,
) -> Option<T> {
    let given: Vec<(f64, T)> = keys
        .iter()
        .filter_map(|k| Some((k.time, get(k)?)))
        .collect();
    let after = given.partition_point(|(t, _)| *t <= time);
    match (after.checked_sub(1).map(|i| given[i]), given.get(after)) {
        (None, None) => None,
        (Some((_, a)), None) => Some(a),
        (None, Some(&(_, b))) => Some(b),
        (Some((t0, a)), Some(&(t1, b))) => Some(T::lerp(a, b, ((time - t0) / (t1 - t0)) as f32)),
    }
}

impl LightSpec {
    /// The light at `time` (frames), its keys folded in; a light without
    /// keys is itself.
    pub fn at(&self, time: f64) -> LightSpec {
        let mut spec = self.clone();
        let Some(keys) = spec.keys.take().filter(|k| !k.is_empty()) else {
            return spec;
        };
        macro_rules! fold {
            ($f:ident) => {
                if let Some(v) = keyed_at(&keys, time, |k| k.$f) {
                    spec.$f = Some(v);
                }
            };
        }
        each_keyed_value!(fold);
        spec
    }

    /// Whether the light changes between `open` and `close` (frames): a key
    /// inside, or different values at the two ends.
    pub fn moves_within(&self, open: f64, close: f64) -> bool {
        let Some(keys) = self.keys.as_deref() else {
            return false;
        };
        close > open
            && (keys.iter().any(|k| k.time > open && k.time < close)
                || self.at(open) != self.at(close))
    }

    /// Checks the keys: times finite and increasing, each giving a value
    /// the light's kind takes, the light valid at every key (between
    /// keys every value is between two valid ones), and no direction
    /// turning half round between two keys (where it would pass through
    /// zero).
    pub(crate) fn check_keys(&self, takes: &[&str]) -> Result<(), String> {
        let Some(keys) = self.keys.as_deref() else {
            return Ok(());
        };
        check_samples(keys.iter().map(|k| (k.time, true)), "keys")?;
        for k in keys {
            let given = k.given();
            if given.is_empty() {
                return Err(format!("the key at time {} gives no value", k.time));
            }
            let shared = ["color", "intensity", "exposure"];
            if let Some(name) = given
                .iter()
                .find(|n| !takes.contains(n) && !shared.contains(n))
            {
                return Err(format!(
                    "the key at time {}: `{name}` does not apply to a {} light",
                    k.time, self.kind
                ));
            }
        }
        for k in keys {
            self.at(k.time)
                .check_unkeyed()
                .map_err(|e| format!("at the key at time {}: {e}", k.time))?;
        }
        for pair in keys.windows(2) {
            for (name, a, b) in [
                (
                    "direction",
                    self.at(pair[0].time).direction,
                    self.at(pair[1].time).direction,
                ),
                ("up", self.at(pair[0].time).up, self.at(pair[1].time).up),
            ] {
                let (Some(a), Some(b)) = (a, b) else { continue };
                let (a, b) = (
                    Vec3::from_array(a).normalize(),
                    Vec3::from_array(b).normalize(),
                );
                if a.dot(b) < -0.999 {
                    return Err(format!(
                        "`{name}` turns half round between the keys at times {} and {}: add a key between them",
                        pair[0].time, pair[1].time
                    ));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f64) -> LightKey {
        LightKey {
            time,
            ..Default::default()
        }
    }

    fn point() -> LightSpec {
        LightSpec {
            kind: "point".into(),
            position: Some([0.0, 1.0, 0.0]),
            intensity: Some(2.0),
            ..Default::default()
        }
    }

    #[test]
    fn keyed_values_interpolate_between_keys_and_hold_outside() {
        let mut spec = point();
        spec.keys = Some(vec![
            LightKey {
                position: Some([0.0, 0.0, 0.0]),
                ..key(1.0)
            },
            LightKey {
                intensity: Some(10.0),
                ..key(2.0)
            },
            LightKey {
                position: Some([4.0, 0.0, 8.0]),
                intensity: Some(20.0),
                ..key(5.0)
            },
        ]);
        // Position keyed at 1 and 5: a quarter of the way at 2.
        let at2 = spec.at(2.0);
        assert_eq!(at2.position, Some([1.0, 0.0, 2.0]));
        assert_eq!(at2.intensity, Some(10.0));
        // Intensity keyed at 2 and 5: held at 10 before 2.
        assert_eq!(spec.at(0.0).intensity, Some(10.0));
        assert_eq!(spec.at(0.0).position, Some([0.0, 0.0, 0.0]));
        assert_eq!(spec.at(3.5).intensity, Some(15.0));
        assert_eq!(spec.at(9.0).position, Some([4.0, 0.0, 8.0]));
        assert!(spec.at(3.0).keys.is_none());
        // Values no key gives are the table's.
        assert_eq!(spec.at(3.0).color, None);
        assert_eq!(spec.at(3.0).kind, "point");
    }

    #[test]
    fn a_light_without_keys_is_the_same_at_every_time() {
        let spec = point();
        assert_eq!(spec.at(-7.0), spec);
        assert!(!spec.moves_within(-0.25, 0.25));
    }

    #[test]
    fn moves_within_sees_keys_inside_and_differing_ends() {
        let mut spec = point();
        spec.keys = Some(vec![
            LightKey {
                intensity: Some(1.0),
                ..key(0.0)
            },
            LightKey {
                intensity: Some(1.0),
                ..key(1.0)
            },
            LightKey {
                intensity: Some(3.0),
                ..key(2.0)
            },
        ]);
        assert!(!spec.moves_within(0.0, 1.0), "constant between 0 and 1");
        assert!(spec.moves_within(0.5, 1.5));
        assert!(spec.moves_within(1.5, 1.75));
        assert!(!spec.moves_within(2.5, 3.0), "held after the last key");
        assert!(!spec.moves_within(1.5, 1.5), "a closed shutter");
    }

    #[test]
    fn bad_keys_are_refused_by_what_is_wrong() {
        let takes = ["position"];
        let check = |keys: Vec<LightKey>| {
            let mut spec = point();
            spec.keys = Some(keys);
            spec.check_keys(&takes).unwrap_err()
        };
        let e = check(vec![key(1.0), key(0.0)]);
        assert!(e.contains("increasing"), "{e}");
        let e = check(vec![key(f64::NAN)]);
        assert!(e.contains("finite"), "{e}");
        let e = check(vec![key(0.0)]);
        assert!(e.contains("gives no value"), "{e}");
        let e = check(vec![LightKey {
            cone_angle: Some(10.0),
            ..key(0.0)
        }]);
        assert!(
            e.contains("`cone_angle` does not apply to a point light"),
            "{e}"
        );
        let e = check(vec![LightKey {
            intensity: Some(-1.0),
            ..key(3.0)
        }]);
        assert!(
            e.contains("at the key at time 3") && e.contains("negative"),
            "{e}"
        );
        let mut spot = point();
        spot.kind = "spot".into();
        spot.cone_angle = Some(30.0);
        spot.keys = Some(vec![
            LightKey {
                direction: Some([0.0, -1.0, 0.0]),
                ..key(0.0)
            },
            LightKey {
                direction: Some([0.0, 1.0, 0.0]),
                ..key(1.0)
            },
        ]);
        let e = spot
            .check_keys(&["position", "direction", "cone_angle"])
            .unwrap_err();
        assert!(e.contains("half round"), "{e}");
    }
}
