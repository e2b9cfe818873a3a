//! Deep scanline OpenEXR 2 images, written and read through OpenEXR's own
//! C library (OpenEXRCore 3.1 or newer), for the renderer's deep output and
//! the merge of deep crop tiles.
//!
//! The library is loaded at run time, the first time a deep image is
//! written or read (`$CIRRUS_OPENEXR_CORE`, else the loader's usual path:
//! Debian's `libopenexr-3-1-30`), so building cirrus and rendering flat
//! images need no system library; asking for a deep image without it is an
//! error that says what to install.
//!
//! The files are single-part, deep scanline, uncompressed, with 32-bit
//! float channels. Uncompressed because OpenEXRCore 3.1 writes deep
//! chunks as given (`exr_write_deep_scanline_chunk`) and its encoding
//! pipeline has no deep compressor there; reading is limited to files of
//! that form (what this crate writes), each size checked against the
//! header before anything is allocated. Writing goes to a temporary file
//! the library renames over the destination once it is complete.

mod ffi;
mod merge;

pub use merge::{is_deep_file, merge};

use std::ffi::{CStr, CString};
use std::io;
use std::os::raw::c_int;
use std::path::Path;

/// One deep image (or a crop of one): per pixel a list of samples, each
/// with a value in every channel.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DeepImage {
    /// The display window's size (the whole image).
    pub full: (u32, u32),
    /// The data window's top-left corner inside the display window.
    pub origin: (u32, u32),
    /// The data window's size.
    pub width: u32,
    pub height: u32,
    /// Channel names, sorted as OpenEXR stores them (byte order).
    pub channels: Vec<String>,
    /// Samples of each pixel of the data window, row-major.
    pub counts: Vec<u32>,
    /// Per channel, every pixel's samples in pixel order (`counts` says
    /// where each pixel's run starts).
    pub values: Vec<Vec<f32>>,
}

/// The most samples a pixel may hold when read back: far above what the
/// renderer writes, low enough that a corrupt table cannot ask for memory
/// the machine does not have.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 1 << 16;

impl DeepImage {
    /// An image of `channels` (sorted here) with no samples yet.
    pub fn new(full: (u32, u32), origin: (u32, u32), size: (u32, u32), channels: &[&str]) -> Self {
        let mut names: Vec<String> = channels.iter().map(|c| c.to_string()).collect();
        names.sort();
        Self {
            full,
            origin,
            width: size.0,
            height: size.1,
            values: vec![Vec::new(); names.len()],
            channels: names,
            counts: Vec::new(),
        }
    }

    /// Index of the channel called `name`.
    pub fn channel(&self, name: &str) -> Option<usize> {
        self.channels.iter().position(|c| c == name)
    }

    /// Appends the next pixel (row-major order): `samples[k][c]` is
    /// sample `k`'s value in channel `c` (in [`DeepImage::channels`] order).
    pub fn push_pixel(&mut self, samples: &[Vec<f32>]) {
        self.counts.push(samples.len() as u32);
        for s in samples {
            for (c, v) in s.iter().enumerate() {
                self.values[c].push(*v);
            }
        }
    }

    /// Per pixel, the index of its first sample.
    pub fn offsets(&self) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.counts.len() + 1);
        let mut at = 0usize;
        out.push(0);
        for &n in &self.counts {
            at += n as usize;
            out.push(at);
        }
        out
    }

    fn check(&self) -> Result<(), String> {
        let pixels = self.width as usize * self.height as usize;
        let total: usize = self.counts.iter().map(|&n| n as usize).sum();
        if self.width == 0 || self.height == 0 {
            return Err("the data window is empty".into());
        }
        if self.origin.0 + self.width > self.full.0 || self.origin.1 + self.height > self.full.1 {
            return Err("the data window lies outside the image".into());
        }
        if self.counts.len() != pixels || self.values.iter().any(|v| v.len() != total) {
            return Err("sample counts and values disagree".into());
        }
        if self.values.len() != self.channels.len() {
            return Err("one value list per channel is needed".into());
        }
        Ok(())
    }
}

fn message(api: &ffi::Api, code: ffi::ExrResult) -> String {
    // SAFETY: the library returns a pointer to a static, NUL-terminated
    // message for any code (an "unknown error" text for unknown ones).
    let text = unsafe { CStr::from_ptr((api.get_default_error_message)(code)) };
    text.to_string_lossy().into_owned()
}

/// A context that `exr_finish` closes however the caller leaves.
struct Context {
    api: &'static ffi::Api,
    raw: ffi::Context,
}

impl Drop for Context {
    fn drop(&mut self) {
        let api = self.api;
        if !self.raw.is_null() {
            // SAFETY: `raw` came from a successful exr_start_*; finishing
            // it once (it is nulled by the call) is the required cleanup.
            unsafe { (api.finish)(&mut self.raw) };
        }
    }
}

impl Context {
    /// Finishes explicitly, reporting the error a write's final flush and
    /// rename may give.
    fn finish(mut self) -> Result<(), String> {
        let api = self.api;
        // SAFETY: as in `drop`; the handle is nulled so drop does nothing.
        let rv = unsafe { (api.finish)(&mut self.raw) };
        self.raw = std::ptr::null_mut();
        ok(api, rv, "finish")
    }
}

fn ok(api: &ffi::Api, rv: ffi::ExrResult, what: &str) -> Result<(), String> {
    if rv == ffi::EXR_ERR_SUCCESS {
        Ok(())
    } else {
        Err(format!("{what}: {}", message(api, rv)))
    }
}

fn c_path(path: &Path) -> Result<CString, String> {
    CString::new(path.as_os_str().as_encoded_bytes()).map_err(|_| "path holds a NUL byte".into())
}

/// Loads OpenEXRCore now (once per process; later calls return the first
/// outcome), so that a caller can refuse a deep output before a render
/// rather than after it. The error says what to install.
pub fn load_library() -> io::Result<()> {
    ffi::api().map(|_| ()).map_err(io::Error::other)
}

/// Writes `image` as a deep scanline OpenEXR file, whole or not at all.
pub fn write(path: &Path, image: &DeepImage) -> io::Result<()> {
    write_inner(path, image).map_err(|e| io::Error::other(format!("{}: {e}", path.display())))
}

fn write_inner(path: &Path, image: &DeepImage) -> Result<(), String> {
    image.check()?;
    let name = c_path(path)?;
    let api = ffi::api()?;
    let mut ctx = Context {
        api,
        raw: std::ptr::null_mut(),
    };
    // SAFETY: `ctx.raw` is a valid out-pointer; `name` is NUL-terminated
    // and outlives the call; a null initializer selects the defaults.
    ok(
        api,
        unsafe {
            (api.start_write)(
                &mut ctx.raw,
                name.as_ptr(),
                ffi::EXR_INTERMEDIATE_TEMP_FILE,
                std::ptr::null(),
            )
        },
        "open for writing",
    )?;
    let part = define_part(&ctx, image)?;
    // SAFETY: the part is fully defined; the context is open for writing.
    ok(api, unsafe { (api.write_header)(ctx.raw) }, "write header")?;
    let offsets = image.offsets();
    let w = image.width as usize;
    let mut packed: Vec<u8> = Vec::new();
    let mut table: Vec<u8> = Vec::with_capacity(w * 4);
    for row in 0..image.height as usize {
        let (first, last) = (offsets[row * w], offsets[(row + 1) * w]);
        // The line's sample table is cumulative, little-endian int32; its
        // data holds each channel's samples of the whole line in turn.
        table.clear();
        for x in 0..w {
            let cumulative = offsets[row * w + x + 1] - first;
            table.extend_from_slice(&(cumulative as i32).to_le_bytes());
        }
        packed.clear();
        for values in &image.values {
            for v in &values[first..last] {
                packed.extend_from_slice(&v.to_le_bytes());
            }
        }
        let y = image.origin.1 as c_int + row as c_int;
        // SAFETY: both buffers are live for the call and their lengths are
        // the sizes passed; uncompressed, packed and unpacked sizes agree.
        let rv = unsafe {
            (api.write_deep_scanline_chunk)(
                ctx.raw,
                part,
                y,
                packed.as_ptr().cast(),
                packed.len() as u64,
                packed.len() as u64,
                table.as_ptr().cast(),
                table.len() as u64,
            )
        };
        ok(api, rv, &format!("write scanline {y}"))?;
    }
    ctx.finish()
}

/// Adds the deep part with its windows and channels; returns its index.
fn define_part(ctx: &Context, image: &DeepImage) -> Result<c_int, String> {
    let api = ctx.api;
    let mut part: c_int = 0;
    let part_name = CString::new("deep").expect("no NUL");
    // SAFETY: the context is open for writing; the out-pointer is valid.
    ok(
        api,
        unsafe {
            (api.add_part)(
                ctx.raw,
                part_name.as_ptr(),
                ffi::EXR_STORAGE_DEEP_SCANLINE,
                &mut part,
            )
        },
        "add part",
    )?;
    let (fw, fh) = (image.full.0 as i32, image.full.1 as i32);
    // SAFETY: as above, for the part just added.
    ok(
        api,
        unsafe {
            (api.initialize_required_attr_simple)(ctx.raw, part, fw, fh, ffi::EXR_COMPRESSION_NONE)
        },
        "initialise header",
    )?;
    let display = ffi::Box2i {
        min_x: 0,
        min_y: 0,
        max_x: fw - 1,
        max_y: fh - 1,
    };
    let (x0, y0) = (image.origin.0 as i32, image.origin.1 as i32);
    let data = ffi::Box2i {
        min_x: x0,
        min_y: y0,
        max_x: x0 + image.width as i32 - 1,
        max_y: y0 + image.height as i32 - 1,
    };
    // SAFETY: the boxes are live for the calls; the part exists.
    ok(
        api,
        unsafe { (api.set_display_window)(ctx.raw, part, &display) },
        "display window",
    )?;
    ok(
        api,
        unsafe { (api.set_data_window)(ctx.raw, part, &data) },
        "data window",
    )?;
    for channel in &image.channels {
        let c = CString::new(channel.as_str()).map_err(|_| "channel name holds a NUL")?;
        // SAFETY: `c` is NUL-terminated and live; the library copies it.
        ok(
            api,
            unsafe {
                (api.add_channel)(
                    ctx.raw,
                    part,
                    c.as_ptr(),
                    ffi::EXR_PIXEL_FLOAT,
                    ffi::EXR_PERCEPTUALLY_LINEAR,
                    1,
                    1,
                )
            },
            &format!("add channel {channel}"),
        )?;
    }
    Ok(part)
}

/// Reads a deep scanline file of the form [`write`] makes.
pub fn read(path: &Path) -> io::Result<DeepImage> {
    read_inner(path).map_err(|e| io::Error::other(format!("{}: {e}", path.display())))
}

fn read_inner(path: &Path) -> Result<DeepImage, String> {
    let name = c_path(path)?;
    let api = ffi::api()?;
    let mut ctx = Context {
        api,
        raw: std::ptr::null_mut(),
    };
    // SAFETY: as for writing; a null initializer selects the defaults.
    ok(
        api,
        unsafe { (api.start_read)(&mut ctx.raw, name.as_ptr(), std::ptr::null()) },
        "open",
    )?;
    let mut image = read_header(&ctx)?;
    let w = image.width as usize;
    let nch = image.channels.len();
    for row in 0..image.height as usize {
        let y = image.origin.1 as c_int + row as c_int;
        let mut info = ffi::ChunkInfo::default();
        // SAFETY: the context is open for reading; `info` is a valid
        // out-pointer.
        ok(
            api,
            unsafe { (api.read_scanline_chunk_info)(ctx.raw, 0, y, &mut info) },
            &format!("scanline {y}"),
        )?;
        if info.height != 1
            || info.width as usize != w
            || info.sample_count_table_size != 4 * w as u64
        {
            return Err(format!("scanline {y}: unexpected chunk layout"));
        }
        let mut table = vec![0u8; 4 * w];
        // SAFETY: `table` holds exactly `sample_count_table_size` bytes
        // (checked above); a null packed pointer reads the table alone.
        ok(
            api,
            unsafe {
                (api.read_deep_chunk)(
                    ctx.raw,
                    0,
                    &info,
                    std::ptr::null_mut(),
                    table.as_mut_ptr().cast(),
                )
            },
            &format!("scanline {y} sample table"),
        )?;
        let counts = line_counts(&table, y)?;
        let total: usize = counts.iter().map(|&n| n as usize).sum();
        if info.packed_size != (total * nch * 4) as u64 {
            return Err(format!(
                "scanline {y}: data size disagrees with its sample table"
            ));
        }
        let mut packed = vec![0u8; total * nch * 4];
        // SAFETY: `packed` holds exactly `packed_size` bytes (checked
        // against the table, whose own size was checked first).
        ok(
            api,
            unsafe {
                (api.read_deep_chunk)(
                    ctx.raw,
                    0,
                    &info,
                    packed.as_mut_ptr().cast(),
                    std::ptr::null_mut(),
                )
            },
            &format!("scanline {y} data"),
        )?;
        image.counts.extend_from_slice(&counts);
        for (c, chunk) in packed.chunks_exact(total * 4).enumerate().take(nch) {
            let vals = chunk
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
            image.values[c].extend(vals);
        }
    }
    ctx.finish()?;
    Ok(image)
}

/// Per-pixel counts from a line's cumulative table, checked to rise and to
/// stay under [`MAX_SAMPLES_PER_PIXEL`] per pixel.
fn line_counts(table: &[u8], y: c_int) -> Result<Vec<u32>, String> {
    let mut prev = 0i64;
    table
        .chunks_exact(4)
        .map(|b| {
            let c = i64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]]));
            let n = c - prev;
            prev = c;
            if !(0..=i64::from(MAX_SAMPLES_PER_PIXEL)).contains(&n) {
                return Err(format!("scanline {y}: a pixel claims {n} samples"));
            }
            Ok(n as u32)
        })
        .collect()
}

/// The part's windows and channels, checked to be what [`write`] makes.
fn read_header(ctx: &Context) -> Result<DeepImage, String> {
    let api = ctx.api;
    let (mut parts, mut storage, mut compression) = (0, 0, 0);
    // SAFETY: the context is open for reading; the out-pointers are valid.
    unsafe {
        ok(api, (api.get_count)(ctx.raw, &mut parts), "part count")?;
        if parts != 1 {
            return Err(format!(
                "{parts} parts; a deep image of one part is expected"
            ));
        }
        ok(api, (api.get_storage)(ctx.raw, 0, &mut storage), "storage")?;
        ok(
            api,
            (api.get_compression)(ctx.raw, 0, &mut compression),
            "compression",
        )?;
    }
    if storage != ffi::EXR_STORAGE_DEEP_SCANLINE {
        return Err("not a deep scanline image".into());
    }
    if compression != ffi::EXR_COMPRESSION_NONE {
        return Err(
            "compressed deep images are not read here (cirrus writes them uncompressed)".into(),
        );
    }
    let (mut display, mut data) = (ffi::Box2i::default(), ffi::Box2i::default());
    // SAFETY: as above.
    unsafe {
        ok(
            api,
            (api.get_display_window)(ctx.raw, 0, &mut display),
            "display window",
        )?;
        ok(
            api,
            (api.get_data_window)(ctx.raw, 0, &mut data),
            "data window",
        )?;
    }
    let size = |min: i32, max: i32| -> Result<u32, String> {
        let n = i64::from(max) - i64::from(min) + 1;
        if !(1..=1 << 16).contains(&n) {
            return Err(format!("a window of {n} pixels across is refused"));
        }
        Ok(n as u32)
    };
    if display.min_x != 0 || display.min_y != 0 || data.min_x < 0 || data.min_y < 0 {
        return Err("the display window must start at 0,0 and hold the data window".into());
    }
    let full = (size(0, display.max_x)?, size(0, display.max_y)?);
    let (w, h) = (size(data.min_x, data.max_x)?, size(data.min_y, data.max_y)?);
    let channels = channel_names(ctx)?;
    let names: Vec<&str> = channels.iter().map(|s| s.as_str()).collect();
    let mut image = DeepImage::new(full, (data.min_x as u32, data.min_y as u32), (w, h), &names);
    if image.origin.0 + w > full.0 || image.origin.1 + h > full.1 {
        return Err("the data window lies outside the display window".into());
    }
    image.counts.reserve(w as usize * h as usize);
    Ok(image)
}

fn channel_names(ctx: &Context) -> Result<Vec<String>, String> {
    let api = ctx.api;
    let mut list: *const ffi::ChannelList = std::ptr::null();
    // SAFETY: the context is open; the library returns a pointer into its
    // own header, valid until the context is finished (after this copy).
    ok(
        api,
        unsafe { (api.get_channels)(ctx.raw, 0, &mut list) },
        "channels",
    )?;
    if list.is_null() {
        return Err("no channel list".into());
    }
    // SAFETY: non-null, pointing at the library's channel list, whose
    // `entries` holds `num_channels` entries with NUL-terminated names.
    let list = unsafe { &*list };
    if !(1..=64).contains(&list.num_channels) || list.entries.is_null() {
        return Err(format!("{} channels", list.num_channels));
    }
    // SAFETY: `entries` is non-null and holds `num_channels` (1 to 64)
    // entries owned by the header, alive while the context is open.
    let entries = unsafe { std::slice::from_raw_parts(list.entries, list.num_channels as usize) };
    entries
        .iter()
        .map(|e| {
            if e.pixel_type != ffi::EXR_PIXEL_FLOAT || e.x_sampling != 1 || e.y_sampling != 1 {
                return Err("only unsampled 32-bit float channels are read".to_string());
            }
            // SAFETY: see above: a NUL-terminated name owned by the header.
            let name = unsafe { CStr::from_ptr(e.name.str) };
            Ok(name.to_string_lossy().into_owned())
        })
        .collect()
}
