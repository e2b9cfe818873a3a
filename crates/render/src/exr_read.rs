//! Reading an EXR's channels back: a crop tile, a depth image.

use std::path::Path;

use crate::error::{exr_error, Result};

/// What [`read_channels`] returns.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrChannels {
    /// The display window's size.
    pub full: (usize, usize),
    /// The data window's corner and size.
    pub position: (i32, i32),
    pub size: (usize, usize),
    pub channels: Vec<(String, Vec<f32>)>,
    /// The header's text attributes (the Cryptomatte manifest), sorted by
    /// name.
    pub attributes: Vec<(String, String)>,
}

/// Every channel of an EXR's first layer over its data window, by name,
/// with the window's position and size and the header's text attributes:
/// what the merge of crop tiles and the depth holdout read, and tests.
pub fn read_channels(path: &Path) -> Result<ExrChannels> {
    use exr::prelude::*;
    let err = |e| exr_error(path, e);
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(err)?;
    let dw = image.attributes.display_window;
    let layer = image.layer_data;
    // The exr crate reads a header's unknown attributes into the layer's.
    let mut attributes: Vec<(String, String)> = layer
        .attributes
        .other
        .iter()
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
            _ => None,
        })
        .collect();
    attributes.sort();
    if dw.position != Vec2(0, 0) {
        return Err(crate::error::Error::format(
            path,
            "display window must start at 0,0",
        ));
    }
    let channels = layer
        .channel_data
        .list
        .into_iter()
        .map(|c| {
            let v = match c.sample_data {
                FlatSamples::F32(v) => v,
                FlatSamples::F16(v) => v.into_iter().map(|h| h.to_f32()).collect(),
                FlatSamples::U32(v) => v.into_iter().map(|u| u as f32).collect(),
            };
            (c.name.to_string(), v)
        })
        .collect();
    Ok(ExrChannels {
        full: (dw.size.0, dw.size.1),
        position: (
            layer.attributes.layer_position.0,
            layer.attributes.layer_position.1,
        ),
        size: (layer.size.0, layer.size.1),
        channels,
        attributes,
    })
}
