//! A depth holdout: a camera-space depth image from another renderer (the
//! geometry the cloud must render behind and around) that ends each camera
//! ray at its pixel's depth.
//!
//! Depth is distance along the camera's view axis (planar depth), the
//! convention of Blender's Z pass (Cycles writes the point's camera-space
//! z for perspective cameras) and of Nuke's `DeepToImage` Z; the ray
//! through a pixel ends at `depth / cos(angle to the view axis)`. Pixels
//! with no depth are `+inf` or at least the stated far value (Blender
//! writes 1e10 for its background), and are left untouched.

use std::path::Path;

use crate::exr_read::exr_error;
use cirrus_kernel::{Error, Result};

use glam::Vec3;

/// Planar depth per pixel of the camera's full image.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthHoldout {
    width: u32,
    height: u32,
    /// Row-major, top row first; `f32::INFINITY` where nothing holds out.
    depth: Vec<f32>,
}

/// Blender's background depth, the default far value.
pub const DEFAULT_FAR: f32 = 1e10;

impl DepthHoldout {
    /// A holdout from planar depths of a `width x height` image; values at
    /// or beyond `far` mean no depth.
    pub fn new(width: u32, height: u32, depth: Vec<f32>, far: f32) -> Result<Self> {
        if depth.len() != width as usize * height as usize {
            return Err(Error::invalid(format!(
                "{} depths for a {width}x{height} image",
                depth.len()
            )));
        }
        let mut depth = depth;
        for (i, z) in depth.iter_mut().enumerate() {
            if z.is_nan() || *z < 0.0 {
                let (x, y) = (i % width as usize, i / width as usize);
                return Err(Error::invalid(format!(
                    "pixel ({x}, {y}) has depth {z}; depths must be >= 0 (or +inf for none)"
                )));
            }
            if *z >= far {
                *z = f32::INFINITY;
            }
        }
        Ok(Self {
            width,
            height,
            depth,
        })
    }

    /// Reads channel `channel` (default: the one called `Z` or ending in
    /// `.Z`, if exactly one does) of an EXR whose display window is the
    /// camera's `size`; errors name the file and what is wrong.
    pub fn read(path: &Path, channel: Option<&str>, far: f32, size: (u32, u32)) -> Result<Self> {
        // A readable image that does not fit the camera is wrong input.
        let bad = |message: String| Error::invalid(format!("{}: {message}", path.display()));
        let meta =
            exr::meta::MetaData::read_from_file(path, false).map_err(|e| exr_error(path, e))?;
        let header = meta.headers.first().ok_or_else(|| bad("no image".into()))?;
        let display = header.shared_attributes.display_window;
        if (display.size.0, display.size.1) != (size.0 as usize, size.1 as usize) {
            return Err(bad(format!(
                "the depth image is {}x{}, the camera's image {}x{}",
                display.size.0, display.size.1, size.0, size.1
            )));
        }
        let image = crate::exr_read::read_channels(path)?;
        let names: Vec<&str> = image.channels.iter().map(|(n, _)| n.as_str()).collect();
        let chosen = match channel {
            Some(c) => names
                .iter()
                .position(|n| *n == c)
                .ok_or_else(|| bad(format!("no channel {c:?} (it has {})", names.join(", "))))?,
            None => {
                let zs: Vec<usize> = (0..names.len())
                    .filter(|&i| names[i] == "Z" || names[i].ends_with(".Z"))
                    .collect();
                match zs[..] {
                    [i] => i,
                    _ => {
                        return Err(bad(format!(
                            "name the depth channel as FILE:CHANNEL (channels: {})",
                            names.join(", ")
                        )))
                    }
                }
            }
        };
        let values = &image.channels[chosen].1;
        // The data window may be smaller than the image: no depth outside.
        let (w, h) = (size.0 as usize, size.1 as usize);
        let mut depth = vec![f32::INFINITY; w * h];
        let (x0, y0) = image.position;
        for (k, &v) in values.iter().enumerate() {
            let (x, y) = (
                x0 as i64 + (k % image.size.0) as i64,
                y0 as i64 + (k / image.size.0) as i64,
            );
            if (0..w as i64).contains(&x) && (0..h as i64).contains(&y) {
                depth[y as usize * w + x as usize] = v;
            }
        }
        Self::new(size.0, size.1, depth, far)
            .map_err(|e| bad(format!("channel {}: {e}", names[chosen])))
    }

    /// Where the camera ray through pixel `(x, y)` along `dir` ends, for a
    /// camera looking along `forward` (both unit vectors).
    #[inline]
    pub fn t_max(&self, x: u32, y: u32, dir: Vec3, forward: Vec3) -> f32 {
        if x >= self.width || y >= self.height {
            return f32::INFINITY;
        }
        let z = self.depth[(y * self.width + x) as usize];
        if z.is_infinite() {
            return f32::INFINITY;
        }
        z / dir.dot(forward).max(1e-6)
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
}
