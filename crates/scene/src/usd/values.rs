//! Reading typed values off a composed stage: numbers, colours, tokens,
//! asset paths and time samples, whatever precision they were authored in.

use openusd::sdf::Value;
use openusd::usd::{Attribute, Prim, Stage, TimeCode};

use crate::error::{Error, Result};

/// An error naming the stage and the prim.
pub fn prim_error(stage_file: &str, prim: &str, what: impl std::fmt::Display) -> Error {
    Error::input(format!("{stage_file}: {prim}: {what}"))
}

/// The composed value of `name` on `prim` at `time`, if authored (or a
/// schema fallback the reader knows).
pub fn value(prim: &Prim, name: &str, time: f64) -> Result<Option<Value>> {
    prim.attribute(name)
        .get_at::<Value>(TimeCode::new(time))
        .map_err(|e| Error::input(format!("{}.{name}: {e:#}", prim.path().as_str())))
}

pub fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Float(x) => Some(f64::from(*x)),
        Value::Double(x) => Some(*x),
        Value::Half(x) => Some(f64::from(x.to_f32())),
        Value::Int(x) => Some(f64::from(*x)),
        Value::Int64(x) => Some(*x as f64),
        Value::Uint(x) => Some(f64::from(*x)),
        _ => None,
    }
}

pub fn triple(v: &Value) -> Option<[f64; 3]> {
    match v {
        Value::Vec3f(c) => Some([c.x, c.y, c.z].map(f64::from)),
        Value::Vec3d(c) => Some([c.x, c.y, c.z]),
        Value::Vec3h(c) => Some([c.x, c.y, c.z].map(|x| f64::from(x.to_f32()))),
        _ => number(v).map(|x| [x; 3]),
    }
}

pub fn text(v: &Value) -> Option<String> {
    match v {
        Value::Token(t) => Some(t.as_str().to_string()),
        Value::String(s) => Some(s.clone()),
        _ => None,
    }
}

/// A number attribute, `Ok(None)` when unauthored, an error naming it when
/// authored with a type that is not a number.
pub fn attr_number(prim: &Prim, name: &str, time: f64) -> Result<Option<f64>> {
    match value(prim, name, time)? {
        None => Ok(None),
        Some(v) => number(&v)
            .filter(|x| x.is_finite())
            .map(Some)
            .ok_or_else(|| not_a(prim, name, "finite number", &v)),
    }
}

pub fn attr_triple(prim: &Prim, name: &str, time: f64) -> Result<Option<[f64; 3]>> {
    match value(prim, name, time)? {
        None => Ok(None),
        Some(v) => triple(&v)
            .filter(|c| c.iter().all(|x| x.is_finite()))
            .map(Some)
            .ok_or_else(|| not_a(prim, name, "colour or vector", &v)),
    }
}

pub fn attr_text(prim: &Prim, name: &str, time: f64) -> Result<Option<String>> {
    Ok(value(prim, name, time)?.as_ref().and_then(text))
}

fn not_a(prim: &Prim, name: &str, what: &str, v: &Value) -> Error {
    Error::input(format!(
        "{}.{name}: expected a {what}, got {}",
        prim.path().as_str(),
        shown(v)
    ))
}

/// A number as a person writes it: `-1e38`, `0.25`, `nan`, `inf`.
pub fn shown_number(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.into()
    } else if (x as f32) as f64 == x {
        // A float (as most light inputs are authored): its own shortest
        // digits, `-1e38` rather than the double's `-9.999999680285692e37`.
        short(x as f32)
    } else {
        short(x)
    }
}

/// The shortest digits that round-trip (Rust's), in exponent form when
/// far from 1.
fn short<T: std::fmt::Display + std::fmt::LowerExp + Into<f64> + Copy>(x: T) -> String {
    let v: f64 = x.into();
    if v != 0.0 && (v.abs() >= 1e6 || v.abs() < 1e-4) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// A value as a person writes it in a message: a number, a vector
/// `(1, 2, nan)`, a quoted token or string, else its type.
fn shown(v: &Value) -> String {
    if let Some(x) = number(v) {
        return shown_number(x);
    }
    if let Some(c) = triple(v) {
        return format!("({})", c.map(shown_number).join(", "));
    }
    if let Some(t) = text(v) {
        let t: String = t.chars().take(60).collect();
        return format!("{t:?}");
    }
    let debug = format!("{v:?}");
    let kind: String = debug.chars().take_while(|c| c.is_alphanumeric()).collect();
    format!("a value of type {kind}")
}

/// An asset attribute at `time`: `(authored, resolved)`; `resolved` is
/// `None` when the path names no file that exists.
pub fn attr_asset(prim: &Prim, name: &str, time: f64) -> Result<Option<(String, Option<String>)>> {
    let (authored, resolved) = match value(prim, name, time)? {
        Some(Value::AssetPath(a)) => (
            a.authored_path.clone(),
            a.resolved_path()
                .filter(|p| !p.is_empty())
                .map(str::to_string),
        ),
        Some(Value::String(s)) => (s, None),
        _ => return Ok(None),
    };
    let resolved = match resolved {
        Some(r) => Some(r),
        None => anchored(&prim.attribute(name), &authored),
    };
    Ok(Some((authored, resolved)))
}

/// `authored` anchored to the layers that author `attr`, strongest first,
/// where the file exists: value resolution leaves time-sampled asset
/// values of openusd 0.6 unresolved.
fn anchored(attr: &Attribute, authored: &str) -> Option<String> {
    let path = std::path::Path::new(authored);
    if path.is_absolute() {
        return path.exists().then(|| authored.to_string());
    }
    let stack = attr.property_stack().ok()?;
    stack.iter().find_map(|(layer, _)| {
        let candidate = std::path::Path::new(layer).parent()?.join(path);
        candidate
            .exists()
            .then(|| candidate.to_string_lossy().into_owned())
    })
}

/// The times `attr` has samples at.
pub fn sample_times(attr: &Attribute) -> Result<Vec<f64>> {
    attr.time_sample_times()
        .map_err(|e| Error::input(format!("{}: {e:#}", attr.path().as_str())))
}

/// The type name of the prim at `path` ("" for a typeless prim).
pub fn type_name(stage: &Stage, path: &str) -> Result<String> {
    stage
        .prim(path)
        .type_name()
        .map(|t| t.map(|t| t.as_str().to_string()).unwrap_or_default())
        .map_err(|e| Error::input(format!("{path}: {e:#}")))
}
