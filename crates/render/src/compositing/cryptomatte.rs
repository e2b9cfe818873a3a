//! Cryptomatte (Psyop's open specification, v1.2), as Nuke's and
//! Blender's readers decode it.
//!
//! - A name's ID is MurmurHash3_32 (seed 0) of its UTF-8 bytes, with bit 23
//!   flipped when the exponent bits are all 0 or all 1 (so the ID is never
//!   a denormal, an infinity or a NaN), read as an f32.
//! - A layer `NAME` is written as `NAME00.R/G/B/A`, `NAME01...`: per rank,
//!   an (ID, coverage) pair, two pairs a channel set, ranks by coverage,
//!   highest first.
//! - The header holds `cryptomatte/<key>/name`, `/hash`
//!   (`MurmurHash3_32`), `/conversion` (`uint32_to_float32`) and
//!   `/manifest` (JSON of each name to its ID's 8 hex digits), where
//!   `<key>` is the first 7 hex digits of the layer name's own ID.

use std::collections::BTreeMap;

/// Ranks written per layer (three channel sets), the specification's
/// default depth.
pub const RANKS: usize = 6;

/// The 32 bits of a name's ID.
pub fn id_bits(name: &str) -> u32 {
    let mut bytes = name.as_bytes();
    let h = murmur3::murmur3_32(&mut bytes, 0).expect("reading a slice cannot fail");
    let exponent = (h >> 23) & 0xff;
    if exponent == 0 || exponent == 0xff {
        h ^ (1 << 23)
    } else {
        h
    }
}

/// A name's ID as the float stored in the image.
pub fn id(name: &str) -> f32 {
    f32::from_bits(id_bits(name))
}

/// The header key of a layer: its name's ID in hex, first 7 digits.
pub fn layer_key(layer: &str) -> String {
    format!("{:08x}", id_bits(layer))[..7].to_string()
}

/// The manifest of `names`: a JSON object of name to 8 hex digits.
pub fn manifest<'a>(names: impl IntoIterator<Item = &'a str>) -> String {
    let map: BTreeMap<&str, String> = names
        .into_iter()
        .map(|n| (n, format!("{:08x}", id_bits(n))))
        .collect();
    serde_json::to_string(&map).expect("strings serialise")
}

/// The header attributes of layer `layer` over `names`.
pub fn header<'a>(layer: &str, names: impl IntoIterator<Item = &'a str>) -> Vec<(String, String)> {
    let key = layer_key(layer);
    let at = |field: &str| format!("cryptomatte/{key}/{field}");
    vec![
        (at("name"), layer.to_string()),
        (at("hash"), "MurmurHash3_32".into()),
        (at("conversion"), "uint32_to_float32".into()),
        (at("manifest"), manifest(names)),
    ]
}

/// The channels of layer `layer`: each pixel's (name index, coverage)
/// pairs mapped to IDs by `names`, pairs of one ID summed (two instances
/// of one asset), ranked by coverage (ties by ID), the top [`RANKS`].
pub fn channels(
    layer: &str,
    coverage: &[Vec<(u32, f32)>],
    names: &[String],
) -> Vec<(String, Vec<f32>)> {
    let ids: Vec<f32> = names.iter().map(|n| id(n)).collect();
    let sets = RANKS.div_ceil(2);
    let mut out: Vec<(String, Vec<f32>)> = (0..sets)
        .flat_map(|s| ["R", "G", "B", "A"].map(|c| (format!("{layer}{s:02}.{c}"), Vec::new())))
        .collect();
    for pixel in coverage {
        let mut by_id: Vec<(f32, f32)> = Vec::new();
        for &(i, cov) in pixel {
            let Some(&id) = ids.get(i as usize) else {
                continue;
            };
            match by_id.iter_mut().find(|(x, _)| x.to_bits() == id.to_bits()) {
                Some(entry) => entry.1 += cov,
                None => by_id.push((id, cov)),
            }
        }
        by_id.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.to_bits().cmp(&b.0.to_bits())));
        for rank in 0..RANKS {
            let (id, cov) = by_id.get(rank).copied().unwrap_or((0.0, 0.0));
            out[2 * rank].1.push(id);
            out[2 * rank + 1].1.push(cov);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference values from the specification's own examples: the ID of
    /// "bunny" (hex 13851a76) and the key of "CryptoObject" (3ae39a5, as PyPI's mmh3 gives it).
    #[test]
    fn ids_match_the_specification() {
        assert_eq!(format!("{:08x}", id_bits("bunny")), "13851a76");
        assert_eq!(layer_key("CryptoObject"), "3ae39a5");
        assert!(id("bunny").is_normal());
    }
}
