//! The merge of deep crop tiles into one deep image, value for value.

use std::io;
use std::path::Path;

use crate::{read, write, DeepImage};

/// Whether `path` is an OpenEXR file holding deep data: the version
/// field's "non-image" bit (bit 11), which OpenEXR sets for deep parts.
pub fn is_deep_file(path: &Path) -> io::Result<bool> {
    use std::io::Read;
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
    let magic = u32::from_le_bytes([head[0], head[1], head[2], head[3]]);
    let version = u32::from_le_bytes([head[4], head[5], head[6], head[7]]);
    Ok(magic == 20000630 && version & 0x800 != 0)
}

/// Assembles deep crop tiles (written by [`write`] with data windows) into
/// one image of the display window. The tiles must share the display
/// window and channels and cover the image exactly once; a violation is
/// an error naming the file. Every sample is copied, never recomputed.
pub fn merge(out: &Path, tiles: &[&Path]) -> io::Result<()> {
    let err = |p: &Path, m: String| io::Error::other(format!("{}: {m}", p.display()));
    let first = tiles
        .first()
        .ok_or_else(|| io::Error::other("no tiles to merge"))?;
    let images: Vec<DeepImage> = tiles.iter().map(|p| read(p)).collect::<io::Result<_>>()?;
    let (fw, fh) = images[0].full;
    let channels = images[0].channels.clone();
    let mut owner: Vec<Option<(usize, usize)>> = vec![None; fw as usize * fh as usize];
    for (k, (img, path)) in images.iter().zip(tiles).enumerate() {
        if img.full != (fw, fh) {
            return Err(err(
                path,
                format!("image is {:?}, the first tile's {:?}", img.full, (fw, fh)),
            ));
        }
        if img.channels != channels {
            return Err(err(path, "channels differ from the first tile's".into()));
        }
        for y in 0..img.height {
            for x in 0..img.width {
                let (gx, gy) = (img.origin.0 + x, img.origin.1 + y);
                let slot = &mut owner[(gy * fw + gx) as usize];
                if slot.is_some() {
                    return Err(err(path, format!("pixel ({gx}, {gy}) is in two tiles")));
                }
                *slot = Some((k, (y * img.width + x) as usize));
            }
        }
    }
    let offsets: Vec<Vec<usize>> = images.iter().map(|i| i.offsets()).collect();
    let names: Vec<&str> = channels.iter().map(|c| c.as_str()).collect();
    let mut merged = DeepImage::new((fw, fh), (0, 0), (fw, fh), &names);
    for (i, slot) in owner.iter().enumerate() {
        let Some((k, p)) = *slot else {
            let (x, y) = (i as u32 % fw, i as u32 / fw);
            return Err(err(
                first,
                format!("the tiles leave pixel ({x}, {y}) uncovered"),
            ));
        };
        let (a, b) = (offsets[k][p], offsets[k][p + 1]);
        merged.counts.push((b - a) as u32);
        for (dst, src) in merged.values.iter_mut().zip(&images[k].values) {
            dst.extend_from_slice(&src[a..b]);
        }
    }
    write(out, &merged)
}
