//! The values settings are made of: colours, transforms and their time
//! samples, blackbody parameters; plain data with the checks serde cannot
//! make.

use std::path::PathBuf;

use serde::Deserialize;

/// A 4x4 matrix as rows (column vectors: the translation is the last column).
pub type Matrix = [[f64; 4]; 4];

/// A matrix at a time in frames.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MatrixSample {
    pub time: f64,
    pub matrix: Matrix,
}

/// A volume file from a time on (held until the next sample).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FileSample {
    pub time: f64,
    pub file: PathBuf,
}

/// A number or an RGB triple.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum Colour {
    Grey(f32),
    Rgb([f32; 3]),
}

impl Colour {
    pub fn rgb(self) -> [f32; 3] {
        match self {
            Colour::Grey(v) => [v; 3],
            Colour::Rgb(c) => c,
        }
    }

    pub fn vec3(self) -> glam::Vec3 {
        glam::Vec3::from_array(self.rgb())
    }
}

/// The command-line form: `x` or `r,g,b`.
impl std::fmt::Display for Colour {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Colour::Grey(v) => write!(f, "{v}"),
            Colour::Rgb([r, g, b]) => write!(f, "{r},{g},{b}"),
        }
    }
}

/// Object to world: scale, then rotate, then translate.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TransformSpec {
    #[serde(default, deserialize_with = "crate::parse::triple_field")]
    pub translate: Option<[f64; 3]>,
    /// Axis-angle rotation.
    pub rotate: Option<AxisAngle>,
    /// Euler angles in degrees, applied about X, then Y, then Z
    /// (exclusive with `rotate`).
    #[serde(default, deserialize_with = "crate::parse::triple_field")]
    pub euler: Option<[f64; 3]>,
    /// Uniform (a number) or per axis.
    pub scale: Option<ScaleSpec>,
    /// Object to world as a 4x4 matrix (rows, column vectors), exclusive
    /// with the fields above.
    pub matrix: Option<Matrix>,
    /// Time-sampled object-to-world matrices (frames), interpolated between
    /// samples (translation and scale linearly, rotation by slerp): motion
    /// blur when the shutter is open. Exclusive with the fields above.
    pub samples: Option<Vec<MatrixSample>>,
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AxisAngle {
    pub axis: [f64; 3],
    pub degrees: f64,
}

#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum ScaleSpec {
    Uniform(f64),
    Axes([f64; 3]),
}

/// pbrt-v4's blackbody parameters: `Le = scale * Blackbody((T - offset) * temperature_scale)`.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BlackbodySpec {
    pub scale: Option<f32>,
    pub offset: Option<f32>,
    pub temperature_scale: Option<f32>,
}

pub(crate) fn finite_matrix(m: &Matrix) -> bool {
    m.iter().flatten().all(|x| x.is_finite())
}

pub(crate) fn check_samples(
    samples: impl Iterator<Item = (f64, bool)>,
    what: &str,
) -> Result<(), String> {
    let mut last = f64::NEG_INFINITY;
    let mut count = 0;
    for (time, ok) in samples {
        if !time.is_finite() || time <= last {
            return Err(format!("{what}: times must be finite and increasing"));
        }
        if !ok {
            return Err(format!("{what}: the matrix at time {time} is not finite"));
        }
        last = time;
        count += 1;
    }
    if count == 0 {
        return Err(format!("{what}: give at least one sample"));
    }
    Ok(())
}
