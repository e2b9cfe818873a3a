//! The part of the Open Image Denoise 2.x C API (`OpenImageDenoise/oidn.h`)
//! that this crate calls, resolved from a library opened at run time.
//!
//! Every type below mirrors oidn.h 2.x: handles are opaque pointers, the
//! `OIDNDeviceType`, `OIDNError` and `OIDNFormat` enums are C `int`s, C
//! `bool` is Rust `bool` and `size_t` is `usize`.

use std::ffi::{c_char, c_int, c_void};

use libloading::Library;

/// `OIDNDevice` (`struct OIDNDeviceImpl*`).
pub(crate) type Device = *mut c_void;
/// `OIDNFilter` (`struct OIDNFilterImpl*`).
pub(crate) type Filter = *mut c_void;

/// `OIDN_DEVICE_TYPE_CPU` of `OIDNDeviceType`. The CPU device is asked for by
/// name (not `OIDN_DEVICE_TYPE_DEFAULT`) because the images are handed over
/// as host pointers (`oidnSetSharedFilterImage`), which a GPU device could
/// not read.
pub(crate) const DEVICE_TYPE_CPU: c_int = 1;
/// `OIDN_ERROR_NONE` of `OIDNError`.
pub(crate) const ERROR_NONE: c_int = 0;
/// `OIDN_FORMAT_FLOAT3` of `OIDNFormat` (`OIDN_FORMAT_FLOAT` = 1, then +2).
pub(crate) const FORMAT_FLOAT3: c_int = 3;

/// The entry points, copied out of the library as plain function pointers.
///
/// They stay valid for the life of the process because the [`Library`] they
/// come from is never unloaded (see [`Api::load`]).
#[derive(Clone, Copy)]
pub(crate) struct Api {
    /// `OIDNDevice oidnNewDevice(OIDNDeviceType type)`
    pub new_device: unsafe extern "C" fn(c_int) -> Device,
    /// `void oidnCommitDevice(OIDNDevice device)`
    pub commit_device: unsafe extern "C" fn(Device),
    /// `void oidnReleaseDevice(OIDNDevice device)`
    pub release_device: unsafe extern "C" fn(Device),
    /// `int oidnGetDeviceInt(OIDNDevice device, const char* name)`
    pub get_device_int: unsafe extern "C" fn(Device, *const c_char) -> c_int,
    /// `OIDNError oidnGetDeviceError(OIDNDevice device, const char** outMessage)`
    pub get_device_error: unsafe extern "C" fn(Device, *mut *const c_char) -> c_int,
    /// `OIDNFilter oidnNewFilter(OIDNDevice device, const char* type)`
    pub new_filter: unsafe extern "C" fn(Device, *const c_char) -> Filter,
    /// `void oidnReleaseFilter(OIDNFilter filter)`
    pub release_filter: unsafe extern "C" fn(Filter),
    /// `void oidnSetSharedFilterImage(OIDNFilter filter, const char* name,
    ///   void* devPtr, OIDNFormat format, size_t width, size_t height,
    ///   size_t byteOffset, size_t pixelByteStride, size_t rowByteStride)`
    #[allow(clippy::type_complexity)]
    pub set_shared_filter_image: unsafe extern "C" fn(
        Filter,
        *const c_char,
        *mut c_void,
        c_int,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    /// `void oidnSetFilterBool(OIDNFilter filter, const char* name, bool value)`
    pub set_filter_bool: unsafe extern "C" fn(Filter, *const c_char, bool),
    /// `void oidnCommitFilter(OIDNFilter filter)`
    pub commit_filter: unsafe extern "C" fn(Filter),
    /// `void oidnExecuteFilter(OIDNFilter filter)`
    pub execute_filter: unsafe extern "C" fn(Filter),
}

impl Api {
    /// Resolves every entry point of `lib`; on success `lib` is never
    /// unloaded, so that the copied function pointers can never dangle.
    ///
    /// Never unloading is deliberate: the library starts TBB worker threads
    /// that can outlive every device, and unmapping their code under them
    /// (`dlclose`) would crash the process. The cost is one mapping per
    /// distinct library loaded, which in practice is one per process. On
    /// failure nothing escapes and `lib` is closed as usual.
    pub(crate) fn load(lib: Library) -> Result<Api, libloading::Error> {
        macro_rules! sym {
            ($name:literal) => {
                // SAFETY: the field type this initialises is the exact C
                // signature of the symbol in oidn.h 2.x (see the field's doc),
                // and the pointer is copied out only when every symbol
                // resolved, after which `lib` is never unloaded (below).
                *unsafe { lib.get(concat!($name, "\0").as_bytes())? }
            };
        }
        let api = Api {
            new_device: sym!("oidnNewDevice"),
            commit_device: sym!("oidnCommitDevice"),
            release_device: sym!("oidnReleaseDevice"),
            get_device_int: sym!("oidnGetDeviceInt"),
            get_device_error: sym!("oidnGetDeviceError"),
            new_filter: sym!("oidnNewFilter"),
            release_filter: sym!("oidnReleaseFilter"),
            set_shared_filter_image: sym!("oidnSetSharedFilterImage"),
            set_filter_bool: sym!("oidnSetFilterBool"),
            commit_filter: sym!("oidnCommitFilter"),
            execute_filter: sym!("oidnExecuteFilter"),
        };
        std::mem::forget(lib);
        Ok(api)
    }
}
