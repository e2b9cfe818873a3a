//! Reading EXR files: a crop tile's channels, a depth image, an
//! environment map; and the `exr` crate's errors as the renderer's.

use std::path::Path;

use cirrus_kernel::{EnvMap, Error, Result};
use glam::Vec3;

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
            AttributeValue::Text(t) => Some((utf8(k), utf8(t))),
            _ => None,
        })
        .collect();
    attributes.sort();
    if dw.position != Vec2(0, 0) {
        return Err(cirrus_kernel::Error::format(
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
            (utf8(&c.name), v)
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

/// An environment map from the first RGB(A) layer of an OpenEXR file (alpha ignored).
pub fn read_env_map(path: &Path, rotation_degrees: f32) -> Result<EnvMap> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |res: Vec2<usize>, _| (res.width(), vec![Vec3::ZERO; res.area()]),
        |(w, px): &mut (usize, Vec<Vec3>),
         pos: Vec2<usize>,
         (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = Vec3::new(r, g, b);
        },
    )
    .map_err(|e| exr_error(path, e))?;
    let (w, px) = image.layer_data.channel_data.pixels;
    let h = px.len() / w.max(1);
    if w == 0 || h == 0 {
        return Err(cirrus_kernel::Error::format(path, "empty image"));
    }
    Ok(EnvMap::new(w, h, px, rotation_degrees))
}

/// An error of the `exr` crate reading or writing `path`: its I/O errors
/// are the file's, everything else is the file's format.
pub(crate) fn exr_error(path: &Path, e: exr::error::Error) -> Error {
    match e {
        exr::error::Error::Io(source) => Error::io(path, source),
        other => Error::format(path, other),
    }
}

/// A name or text of the file as UTF-8, which OpenEXR's own library and
/// the files written here use (the exr crate's own reading of it is
/// Latin-1).
fn utf8(t: &exr::prelude::Text) -> String {
    String::from_utf8_lossy(t.bytes()).into_owned()
}
