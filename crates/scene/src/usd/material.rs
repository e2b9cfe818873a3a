//! A volume's bound material: the shader on the material's volume terminal
//! (`outputs:volume`, or `outputs:CONTEXT:volume`) and the inputs cirrus
//! reads from it, by the names volume shaders commonly give them
//! ([`INPUTS`]; the README's USD table lists them). The binding is the
//! nearest direct `material:binding` on the prim or an ancestor.
//! Inputs driven by a connection (a texture, another node) are not
//! evaluated: they take the scene default, with a warning, as does a volume
//! with no volume material at all.

use openusd::sdf::Value;
use openusd::usd::Prim;

use crate::description::{Colour, VolumeSpec};
use crate::error::Result;

use super::values::{number, triple, value};
use super::Reader;

/// What an input sets, and the input names read for it (first authored wins).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Slot {
    /// Extinction per unit density: `density_scale`.
    Density,
    /// Single-scattering albedo.
    Albedo,
    /// Henyey-Greenstein mean cosine.
    Anisotropy,
    EmissionColour,
    EmissionScale,
    BlackbodyScale,
}

pub const INPUTS: [(&str, &[&str]); 6] = [
    (
        "density",
        &[
            "inputs:density",
            "inputs:densityFloat",
            "inputs:density_scale",
        ],
    ),
    (
        "albedo",
        &[
            "inputs:albedo",
            "inputs:scatter_color",
            "inputs:diffuseColor",
            "inputs:color",
        ],
    ),
    (
        "anisotropy",
        &["inputs:anisotropy", "inputs:scatter_anisotropy", "inputs:g"],
    ),
    (
        "emission colour",
        &[
            "inputs:emission_color",
            "inputs:emissionColor",
            "inputs:emitColor",
        ],
    ),
    (
        "emission",
        &[
            "inputs:emission",
            "inputs:emission_strength",
            "inputs:emissionStrength",
        ],
    ),
    (
        "blackbody",
        &["inputs:blackbody_intensity", "inputs:blackbodyIntensity"],
    ),
];

const SLOTS: [Slot; 6] = [
    Slot::Density,
    Slot::Albedo,
    Slot::Anisotropy,
    Slot::EmissionColour,
    Slot::EmissionScale,
    Slot::BlackbodyScale,
];

/// Fills `spec`'s medium from the volume material bound to `path`.
pub fn apply(r: &mut Reader, path: &str, spec: &mut VolumeSpec) -> Result<()> {
    let Some(shader) = volume_shader(r, path)? else {
        r.warn(format!(
            "{path}: no volume material bound (material:binding to a Material whose outputs:volume \
             is connected): density, albedo and anisotropy take the scene defaults"
        ));
        return Ok(());
    };
    let prim = r.stage.prim(shader.as_str());
    let start = r.time.start;
    let mut read = Vec::new();
    for (slot, (what, names)) in SLOTS.iter().zip(INPUTS) {
        for name in names {
            let attr = prim.attribute(*name);
            let connected = attr.connections().map(|c| !c.is_empty()).unwrap_or(false);
            if connected {
                r.warn(format!(
                    "{shader}.{name} ({what}) is driven by a connection cirrus does not evaluate: \
                     the scene default is used"
                ));
                read.push(name.to_string());
                break;
            }
            if let Some(v) = value(&prim, name, start)? {
                set(r, &shader, name, *slot, &v, spec);
                read.push(name.to_string());
                break;
            }
        }
    }
    report_unread(r, &prim, &shader, &read)?;
    if (spec.emission_color.is_some() || spec.emission_scale.is_some()) && spec.emission.is_none() {
        r.warn(format!(
            "{path}: the material emits but the volume has no emission field (field:emission, heat or flame): no emission"
        ));
    }
    Ok(())
}

fn set(r: &mut Reader, shader: &str, name: &str, slot: Slot, v: &Value, spec: &mut VolumeSpec) {
    let bad = |r: &mut Reader| {
        r.warn(format!(
            "{shader}.{name}: {v:?} is not a usable value: the scene default is used"
        ))
    };
    match slot {
        Slot::Albedo | Slot::EmissionColour => {
            match triple(v).filter(|c| c.iter().all(|x| x.is_finite())) {
                Some(c) => {
                    let c = c.map(|x| x as f32);
                    if slot == Slot::Albedo {
                        spec.albedo = Some(Colour::Rgb(c));
                    } else {
                        spec.emission_color = Some(c);
                    }
                }
                None => bad(r),
            }
        }
        _ => match number(v).filter(|x| x.is_finite()) {
            Some(x) => {
                let x = x as f32;
                match slot {
                    Slot::Density => spec.density_scale = Some(Colour::Grey(x)),
                    Slot::Anisotropy => spec.g = Some(x),
                    Slot::EmissionScale => spec.emission_scale = Some(x),
                    _ => spec.blackbody.scale = Some(x),
                }
            }
            None => bad(r),
        },
    }
}

/// Warns of the shader's authored inputs cirrus did not read.
fn report_unread(r: &mut Reader, prim: &Prim, shader: &str, read: &[String]) -> Result<()> {
    let names = prim
        .property_names()
        .map_err(|e| r.error(shader, format!("{e:#}")))?;
    let unread: Vec<String> = names
        .iter()
        .map(|n| n.as_str().to_string())
        .filter(|n| n.starts_with("inputs:") && !read.contains(n))
        .collect();
    if !unread.is_empty() {
        r.warn(format!(
            "{shader}: inputs cirrus does not read: {}",
            unread.join(", ")
        ));
    }
    Ok(())
}

/// The shader driving the volume terminal of the material bound to `path`.
fn volume_shader(r: &Reader, path: &str) -> Result<Option<String>> {
    let Some(material) = bound_material(r, path)? else {
        return Ok(None);
    };
    let prim = r.stage.prim(material.as_str());
    let names = prim
        .property_names()
        .map_err(|e| r.error(&material, format!("{e:#}")))?;
    let mut terminals: Vec<String> = names
        .iter()
        .map(|n| n.as_str().to_string())
        .filter(|n| n == "outputs:volume" || (n.starts_with("outputs:") && n.ends_with(":volume")))
        .collect();
    terminals.sort_by_key(|n| n != "outputs:volume");
    for t in terminals {
        let sources = prim
            .attribute(t.as_str())
            .connections()
            .map_err(|e| r.error(&material, format!("{t}: {e:#}")))?;
        if let Some(source) = sources.first() {
            return Ok(Some(source.prim_path().as_str().to_string()));
        }
    }
    Ok(None)
}

/// The nearest direct `material:binding` target on `path` or an ancestor.
fn bound_material(r: &Reader, path: &str) -> Result<Option<String>> {
    let mut current = openusd::sdf::path(path).map_err(|e| r.error(path, format!("{e:#}")))?;
    while !current.is_abs_root() {
        let targets = r
            .stage
            .prim(current.clone())
            .relationship("material:binding")
            .targets()
            .unwrap_or_default();
        if let Some(t) = targets.first() {
            return Ok(Some(t.as_str().to_string()));
        }
        match current.parent() {
            Some(p) => current = p,
            None => break,
        }
    }
    Ok(None)
}
