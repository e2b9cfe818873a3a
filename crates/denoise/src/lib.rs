//! Denoising of rendered images with Intel Open Image Denoise (OIDN) 2.x,
//! loaded at run time.
//!
//! The path tracer's images are Monte Carlo estimates; OIDN's "RT" filter
//! removes most of their noise, so a frame needs far fewer samples per pixel.
//! OIDN is not linked at build time: `cargo build` needs nothing but Rust,
//! and the library is opened only when a [`Denoiser`] is made. Where OIDN is
//! missing, [`Denoiser::load`] says how to install it (`pip install pyoidn`,
//! whose wheel bundles `libOpenImageDenoise.so.2` with its CPU device and TBB).
//!
//! How the parts fit:
//! - [`SearchPath`] (module `search`) lists where the library may be:
//!   `$CIRRUS_OIDN` (a file or directory; when set it is the only place
//!   tried), `$OIDN_DIR/lib`, the `pyoidn` package of a `venv` beside the
//!   binary (`target/venv`, where `tools/oidn.sh` installs it), that of
//!   `python3` on PATH, then
//!   the system loader's `libOpenImageDenoise.so.2`.
//! - The private `ffi` module resolves the few C entry points used, with the
//!   signatures of `OpenImageDenoise/oidn.h` 2.x, into function pointers.
//! - [`Denoiser`] owns one committed CPU device (made once, reused for every
//!   image) and a cached "RT" filter; [`Denoiser::denoise`] checks the sizes,
//!   replaces non-finite inputs by 0, runs the filter on RGB `f32` images and
//!   guarantees a finite output.
//! - [`blend`] weighs the noisy image against the denoised one per pixel by
//!   each one's estimated error (the denoiser's measured on the two
//!   independent halves of the samples), so raising the sample count never
//!   makes the final image worse.
//!
//! ```no_run
//! # fn main() -> Result<(), cirrus_denoise::DenoiseError> {
//! let (w, h) = (64, 32);
//! let noisy = vec![0.5f32; w * h * 3];
//! let denoiser = cirrus_denoise::Denoiser::load()?;
//! let clean = denoiser.denoise(&noisy, None, None, w, h, true)?;
//! assert_eq!(clean.len(), noisy.len());
//! # Ok(()) }
//! ```

pub mod blend;
mod ffi;
mod search;

use std::ffi::{c_char, CStr};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

pub use search::{pyoidn_dir, pyoidn_lib_dirs, SearchPath, LIBRARY_NAMES, SYSTEM_NAME};

/// The one command that installs the library (see [`DenoiseError::NotFound`]).
pub const INSTALL_HINT: &str = "pip install pyoidn";

/// What can go wrong while loading OIDN or denoising an image.
#[derive(Debug, thiserror::Error)]
pub enum DenoiseError {
    /// No candidate of the [`SearchPath`] loaded as OIDN 2.x; `tried` holds
    /// each candidate with the reason it was rejected.
    #[error("{}", not_found_message(.tried))]
    NotFound { tried: Vec<(PathBuf, String)> },
    /// The arguments do not describe a valid image (zero or overflowing size,
    /// a slice of the wrong length, a normal without an albedo).
    #[error("invalid denoiser input: {0}")]
    InvalidInput(String),
    /// OIDN reported an error (`oidnGetDeviceError`) after the named step.
    #[error("Open Image Denoise failed at {stage} (error code {code}): {message}")]
    Oidn {
        stage: &'static str,
        code: i32,
        message: String,
    },
}

fn not_found_message(tried: &[(PathBuf, String)]) -> String {
    let mut s = format!(
        "Open Image Denoise 2.x (libOpenImageDenoise.so.2) could not be loaded. \
         Install it with `{INSTALL_HINT}` (into the python3 on PATH) or `bash tools/oidn.sh \
         target/venv/bin/python` (beside target/release/cirrus), or set CIRRUS_OIDN \
         to the library file or the directory holding it."
    );
    if tried.is_empty() {
        s.push_str(" Nothing to try.");
    } else {
        s.push_str(" Tried:");
        for (path, why) in tried {
            s.push_str(&format!("\n  {}: {why}", path.display()));
        }
    }
    s
}

/// The filter last used, kept because creating and committing an "RT"
/// filter (building the network) costs more than running it on a small image.
struct CachedFilter {
    filter: ffi::Filter,
    key: FilterKey,
}

#[derive(Clone, Copy, PartialEq, Eq)]
struct FilterKey {
    width: usize,
    height: usize,
    albedo: bool,
    normal: bool,
    hdr: bool,
}

/// A loaded OIDN library with a committed CPU device, made once and reused
/// for any number of images. It is `Send` and `Sync`: OIDN's API is
/// thread-safe, and calls from several threads on one `Denoiser` take turns.
pub struct Denoiser {
    api: ffi::Api,
    device: ffi::Device,
    library: PathBuf,
    version: (u32, u32, u32),
    filter: Mutex<Option<CachedFilter>>,
}

// SAFETY: `device` and the cached filter are OIDN handles, which OIDN allows
// to be used from any thread ("All API calls are thread-safe"); the filter is
// only touched with `filter` locked, and the function pointers are plain
// code addresses in a library that is never unloaded.
unsafe impl Send for Denoiser {}
// SAFETY: as for `Send`; shared use only reads `api`, `device` and the
// immutable fields, and OIDN keeps errors per device *and* calling thread, so
// concurrent callers each read their own error state.
unsafe impl Sync for Denoiser {}

impl std::fmt::Debug for Denoiser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Denoiser")
            .field("library", &self.library)
            .field("version", &self.version)
            .finish_non_exhaustive()
    }
}

impl Denoiser {
    /// Loads OIDN from the places of [`SearchPath::from_env`] and creates a
    /// CPU device.
    pub fn load() -> Result<Denoiser, DenoiseError> {
        Denoiser::load_from(&SearchPath::from_env())
    }

    /// Loads OIDN from the first candidate of `search` that is a usable OIDN
    /// 2.x library, and creates a CPU device with it.
    pub fn load_from(search: &SearchPath) -> Result<Denoiser, DenoiseError> {
        let mut tried = Vec::new();
        for path in search.candidates() {
            // SAFETY: opening a library runs its initialisers; an OIDN library
            // (or any library named like one) has no initialisers that demand
            // more of us than being opened from a normal Rust thread.
            let lib = match unsafe { libloading::Library::new(&path) } {
                Ok(lib) => lib,
                Err(e) => {
                    tried.push((path, e.to_string()));
                    continue;
                }
            };
            let api = match ffi::Api::load(lib) {
                Ok(api) => api,
                Err(e) => {
                    tried.push((path, format!("not an OIDN 2.x library: {e}")));
                    continue;
                }
            };
            return Denoiser::with_api(api, path);
        }
        Err(DenoiseError::NotFound { tried })
    }

    fn with_api(api: ffi::Api, library: PathBuf) -> Result<Denoiser, DenoiseError> {
        // SAFETY: `new_device` has the oidn.h 2.x signature
        // `OIDNDevice oidnNewDevice(OIDNDeviceType)` and takes no pointers.
        let device = unsafe { (api.new_device)(ffi::DEVICE_TYPE_CPU) };
        if device.is_null() {
            // OIDN allows a NULL device here, to ask why creation failed.
            let (code, message) = device_error(&api, std::ptr::null_mut());
            return Err(DenoiseError::Oidn {
                stage: "oidnNewDevice(CPU)",
                code,
                message: message.unwrap_or_else(|| "no device was created".into()),
            });
        }
        let mut denoiser = Denoiser {
            api,
            device,
            library,
            version: (0, 0, 0),
            filter: Mutex::new(None),
        };
        // From here on `denoiser`'s Drop releases the device on every path.
        // SAFETY: `device` is a live handle just returned by oidnNewDevice;
        // `commit_device` has the signature of oidnCommitDevice in oidn.h 2.x.
        unsafe { (api.commit_device)(device) };
        denoiser.check("oidnCommitDevice")?;
        // SAFETY: live device; the name is a NUL-terminated literal that lives
        // for the call; signature of oidnGetDeviceInt in oidn.h 2.x.
        let v = unsafe { (api.get_device_int)(device, c"version".as_ptr()) };
        denoiser.check("oidnGetDeviceInt(version)")?;
        let v = u32::try_from(v).unwrap_or(0);
        denoiser.version = (v / 10000, v / 100 % 100, v % 100);
        if denoiser.version.0 != 2 {
            return Err(DenoiseError::NotFound {
                tried: vec![(
                    denoiser.library.clone(),
                    format!("version {v} is not OIDN 2.x"),
                )],
            });
        }
        Ok(denoiser)
    }

    /// The library file (or loader name) this denoiser was loaded from.
    pub fn library(&self) -> &Path {
        &self.library
    }

    /// OIDN's version as (major, minor, patch), e.g. (2, 5, 1).
    pub fn version(&self) -> (u32, u32, u32) {
        self.version
    }

    /// Denoises an RGB image with OIDN's "RT" filter and returns the result
    /// in the same layout.
    ///
    /// `color` (and `albedo`, `normal` when given) are `width * height`
    /// pixels of interleaved `f32` RGB, rows top to bottom. `hdr` says the
    /// colour is linear radiance of any range; without it, colour values
    /// should lie in [0, 1]. An `albedo` guides the filter (it keeps texture
    /// and edge detail); a `normal` is only accepted together with an albedo.
    /// Both are taken as noisy (`cleanAux` = false).
    ///
    /// NaN and infinite input values are replaced by 0 before denoising, and
    /// any non-finite value in the output by that (sanitised) input value, so
    /// the result is always finite.
    pub fn denoise(
        &self,
        color: &[f32],
        albedo: Option<&[f32]>,
        normal: Option<&[f32]>,
        width: usize,
        height: usize,
        hdr: bool,
    ) -> Result<Vec<f32>, DenoiseError> {
        let len = validate(color, albedo, normal, width, height)?;

        // Owned, finite copies: OIDN reads the inputs through `void*`, and
        // the renderer never wants a NaN to spread over a filter footprint.
        let mut color = finite_copy(color);
        let mut albedo = albedo.map(finite_copy);
        let mut normal = normal.map(finite_copy);
        let mut output = vec![0.0f32; len];

        let key = FilterKey {
            width,
            height,
            albedo: albedo.is_some(),
            normal: normal.is_some(),
            hdr,
        };
        let mut cache = self.filter.lock().unwrap_or_else(|e| e.into_inner());
        let filter = match cache.as_ref() {
            Some(c) if c.key == key => c.filter,
            _ => {
                if let Some(old) = cache.take() {
                    self.release_filter(old.filter);
                }
                let filter = self.new_rt_filter(hdr)?;
                *cache = Some(CachedFilter { filter, key });
                filter
            }
        };

        let mut images: Vec<(&CStr, &mut [f32])> = vec![(c"color", &mut color)];
        if let Some(a) = albedo.as_mut() {
            images.push((c"albedo", a));
        }
        if let Some(n) = normal.as_mut() {
            images.push((c"normal", n));
        }
        images.push((c"output", &mut output));
        if let Err(e) = self.run_filter(filter, images, width, height) {
            // Do not keep a filter whose state is unknown.
            if let Some(old) = cache.take() {
                self.release_filter(old.filter);
            }
            return Err(e);
        }
        drop(cache);

        for (out, &input) in output.iter_mut().zip(&color) {
            if !out.is_finite() {
                *out = input;
            }
        }
        Ok(output)
    }

    /// Sets `images` (each `width * height` RGB `f32`, by OIDN name) on
    /// `filter`, commits and executes it; the caller holds the filter
    /// cache's lock.
    fn run_filter(
        &self,
        filter: ffi::Filter,
        images: Vec<(&CStr, &mut [f32])>,
        width: usize,
        height: usize,
    ) -> Result<(), DenoiseError> {
        let len = image_len(width, height)?;
        for (name, data) in images {
            if data.len() != len {
                return Err(DenoiseError::InvalidInput(format!(
                    "{name:?} holds {} values, not {len}",
                    data.len()
                )));
            }
            // SAFETY: `filter` is a live handle (cached, released only
            // under the cache's lock, which the caller holds); `data` holds
            // exactly width*height*3 f32 (checked just above, its byte size
            // checked not to overflow in `image_len`), matching FLOAT3 with
            // packed strides (0 = auto);
            // it outlives the execute below and the filter is never
            // executed again without these images being set anew. The
            // signature is oidnSetSharedFilterImage's in oidn.h 2.x.
            unsafe {
                (self.api.set_shared_filter_image)(
                    filter,
                    name.as_ptr(),
                    data.as_mut_ptr().cast(),
                    ffi::FORMAT_FLOAT3,
                    width,
                    height,
                    0,
                    0,
                    0,
                )
            };
            self.check("oidnSetSharedFilterImage")?;
        }
        // SAFETY: live filter with all its images set to buffers that are
        // alive; signature of oidnCommitFilter in oidn.h 2.x.
        unsafe { (self.api.commit_filter)(filter) };
        self.check("oidnCommitFilter")?;
        // SAFETY: as above; oidnExecuteFilter is synchronous, so OIDN is
        // done with the buffers when it returns.
        unsafe { (self.api.execute_filter)(filter) };
        self.check("oidnExecuteFilter")
    }

    /// A new committed-later "RT" filter with `hdr` set and `cleanAux` off.
    fn new_rt_filter(&self, hdr: bool) -> Result<ffi::Filter, DenoiseError> {
        // SAFETY: live device; "RT" is a NUL-terminated literal; signature of
        // oidnNewFilter in oidn.h 2.x.
        let filter = unsafe { (self.api.new_filter)(self.device, c"RT".as_ptr()) };
        if let Err(e) = self.check("oidnNewFilter(RT)") {
            if !filter.is_null() {
                self.release_filter(filter);
            }
            return Err(e);
        }
        if filter.is_null() {
            return Err(DenoiseError::Oidn {
                stage: "oidnNewFilter(RT)",
                code: -1,
                message: "no filter was created".into(),
            });
        }
        for (name, value) in [(c"hdr", hdr), (c"cleanAux", false)] {
            // SAFETY: live filter; NUL-terminated literal name; C `bool` is
            // Rust `bool`; signature of oidnSetFilterBool in oidn.h 2.x.
            unsafe { (self.api.set_filter_bool)(filter, name.as_ptr(), value) };
            if let Err(e) = self.check("oidnSetFilterBool") {
                self.release_filter(filter);
                return Err(e);
            }
        }
        Ok(filter)
    }

    fn release_filter(&self, filter: ffi::Filter) {
        // SAFETY: `filter` is a live handle owned by this denoiser, released
        // once (callers drop every copy of it); oidnReleaseFilter's signature.
        unsafe { (self.api.release_filter)(filter) };
    }

    /// `Err` with OIDN's message if the device has an error for this thread.
    fn check(&self, stage: &'static str) -> Result<(), DenoiseError> {
        match device_error(&self.api, self.device) {
            (ffi::ERROR_NONE, _) => Ok(()),
            (code, message) => Err(DenoiseError::Oidn {
                stage,
                code,
                message: message.unwrap_or_else(|| "no message".into()),
            }),
        }
    }
}

impl Drop for Denoiser {
    fn drop(&mut self) {
        let cache = self.filter.get_mut().unwrap_or_else(|e| e.into_inner());
        if let Some(c) = cache.take() {
            self.release_filter(c.filter);
        }
        // SAFETY: `device` is the live handle made in `with_api`, released
        // exactly once here, after its filter; oidnReleaseDevice's signature.
        unsafe { (self.api.release_device)(self.device) };
    }
}

/// Checks the arguments of [`Denoiser::denoise`] without denoising: a
/// non-empty `width x height` whose `f32` RGB size does not overflow, every
/// slice exactly `width * height * 3` long, and no normal without an albedo.
/// Returns `width * height * 3`.
pub fn validate(
    color: &[f32],
    albedo: Option<&[f32]>,
    normal: Option<&[f32]>,
    width: usize,
    height: usize,
) -> Result<usize, DenoiseError> {
    let len = image_len(width, height)?;
    check_len("color", color, len)?;
    if let Some(a) = albedo {
        check_len("albedo", a, len)?;
    }
    if let Some(n) = normal {
        check_len("normal", n, len)?;
        if albedo.is_none() {
            return Err(DenoiseError::InvalidInput(
                "a normal image needs an albedo image too (OIDN's RT filter)".into(),
            ));
        }
    }
    Ok(len)
}

/// Queries and clears the device's first error for this thread, copying the
/// message (which OIDN owns only until its next call).
fn device_error(api: &ffi::Api, device: ffi::Device) -> (i32, Option<String>) {
    let mut msg: *const c_char = std::ptr::null();
    // SAFETY: `device` is live or NULL (both allowed); `msg` is a valid
    // out-pointer for the call; signature of oidnGetDeviceError in oidn.h 2.x.
    let code = unsafe { (api.get_device_error)(device, &mut msg) };
    let message = (!msg.is_null()).then(|| {
        // SAFETY: OIDN set `msg` to a NUL-terminated string that stays valid
        // until the next OIDN call on this thread; it is copied right away.
        unsafe { CStr::from_ptr(msg) }
            .to_string_lossy()
            .into_owned()
    });
    (code, message)
}

/// `width * height * 3`, checked for zero and for overflow (of the element
/// count and of its byte size, which OIDN computes).
fn image_len(width: usize, height: usize) -> Result<usize, DenoiseError> {
    if width == 0 || height == 0 {
        return Err(DenoiseError::InvalidInput(format!(
            "empty image ({width} x {height})"
        )));
    }
    width
        .checked_mul(height)
        .and_then(|p| p.checked_mul(3))
        .filter(|&n| {
            n.checked_mul(size_of::<f32>())
                .is_some_and(|b| b <= isize::MAX as usize)
        })
        .ok_or_else(|| {
            DenoiseError::InvalidInput(format!("image size {width} x {height} x 3 overflows"))
        })
}

fn check_len(name: &str, data: &[f32], len: usize) -> Result<(), DenoiseError> {
    if data.len() == len {
        Ok(())
    } else {
        Err(DenoiseError::InvalidInput(format!(
            "{name} has {} values, expected width * height * 3 = {len}",
            data.len()
        )))
    }
}

fn finite_copy(data: &[f32]) -> Vec<f32> {
    data.iter()
        .map(|&v| if v.is_finite() { v } else { 0.0 })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_len_checks() {
        assert_eq!(image_len(4, 2).unwrap(), 24);
        assert!(image_len(0, 2).is_err());
        assert!(image_len(usize::MAX, 2).is_err());
        assert!(image_len(usize::MAX / 3, 1).is_err()); // bytes overflow
    }

    #[test]
    fn finite_copy_zeroes_non_finite() {
        let v = finite_copy(&[1.0, f32::NAN, f32::INFINITY, -f32::INFINITY, -2.0]);
        assert_eq!(v, [1.0, 0.0, 0.0, 0.0, -2.0]);
    }
}
