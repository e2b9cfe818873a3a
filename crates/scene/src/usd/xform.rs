//! World transforms of prims, composed through their parents (instance
//! proxies included: a proxy's ancestors are the instance's), at a time or
//! as time samples where any op on the way is time-sampled.

use glam::DMat4;
use openusd::schemas::geom::{Imageable, Xformable};
use openusd::usd::{Prim, SchemaBase, SchemaKind, Stage, TimeCode};

use crate::description::{MatrixSample, TransformSpec};
use crate::error::{Error, Result};
use crate::timeline::from_dmat4;

use super::values::sample_times;

/// Any prim read as a transformable one (its `xformOp`s, if any).
struct AnyXformable(Prim);

impl SchemaBase for AnyXformable {
    const KIND: SchemaKind = SchemaKind::ConcreteTyped;
    fn prim(&self) -> &Prim {
        &self.0
    }
}
impl Imageable for AnyXformable {}
impl Xformable for AnyXformable {}

/// The prims whose ops make `path`'s world transform, nearest first (up
/// to a `!resetXformStack!`).
fn chain(stage: &Stage, path: &str) -> Result<Vec<AnyXformable>> {
    let mut out = Vec::new();
    let mut current =
        openusd::sdf::path(path).map_err(|e| Error::input(format!("{path}: {e:#}")))?;
    loop {
        if current.is_abs_root() {
            break;
        }
        let x = AnyXformable(stage.prim(current.clone()));
        let resets = x
            .resets_xform_stack()
            .map_err(|e| Error::input(format!("{}: {e:#}", current.as_str())))?;
        out.push(x);
        if resets {
            break;
        }
        match current.parent() {
            Some(p) => current = p,
            None => break,
        }
    }
    Ok(out)
}

/// `path`'s local-to-world matrix at `time` (glam, column vectors).
pub fn world_at(stage: &Stage, path: &str, time: f64) -> Result<DMat4> {
    let mut m = DMat4::IDENTITY;
    for x in chain(stage, path)? {
        let local = x
            .local_to_parent_transform(TimeCode::new(time))
            .map_err(|e| Error::input(format!("{}: transform: {e:#}", x.0.path().as_str())))?;
        // USD's row-vector matrices are glam's column-vector ones read as columns.
        m = DMat4::from_cols_array(&local.0) * m;
    }
    Ok(m)
}

/// The times any op on `path`'s chain is sampled at, sorted, deduplicated.
pub fn sample_times_of(stage: &Stage, path: &str) -> Result<Vec<f64>> {
    let mut times = Vec::new();
    for x in chain(stage, path)? {
        let order = x
            .xform_op_order()
            .map_err(|e| Error::input(format!("{}: {e:#}", x.0.path().as_str())))?;
        for op in order.unwrap_or_default() {
            let name = op.strip_prefix("!invert!").unwrap_or(&op);
            if name.starts_with("xformOp:") {
                times.extend(sample_times(&x.0.attribute(name))?);
            }
        }
    }
    times.sort_by(f64::total_cmp);
    times.dedup();
    Ok(times)
}

/// `path`'s world transform as a scene description gives it: one matrix,
/// or samples at every time any op on the way is sampled at.
pub fn transform_spec(stage: &Stage, path: &str, default_time: f64) -> Result<TransformSpec> {
    let times = sample_times_of(stage, path)?;
    let mut spec = TransformSpec::default();
    if times.len() <= 1 {
        let t = times.first().copied().unwrap_or(default_time);
        spec.matrix = Some(from_dmat4(checked(world_at(stage, path, t)?, path)?));
    } else {
        let samples = times
            .iter()
            .map(|&t| {
                Ok(MatrixSample {
                    time: t,
                    matrix: from_dmat4(checked(world_at(stage, path, t)?, path)?),
                })
            })
            .collect::<Result<Vec<_>>>()?;
        spec.samples = Some(samples);
    }
    Ok(spec)
}

fn checked(m: DMat4, path: &str) -> Result<DMat4> {
    if !m.is_finite() || m.determinant().abs() < 1e-300 {
        return Err(Error::input(format!(
            "{path}: the world transform is singular or not finite"
        )));
    }
    Ok(m)
}
