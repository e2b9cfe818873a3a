//! The few OpenEXRCore functions and types this crate uses (OpenEXR 3.1's
//! `openexr.h`), resolved from the library opened at run time. Only the
//! layouts used are declared; every struct is `#[repr(C)]` with the
//! header's field order. The C API has been stable since 3.1, so any
//! OpenEXRCore from 3.1 on serves.

use std::os::raw::{c_char, c_int, c_void};
use std::path::PathBuf;
use std::sync::OnceLock;

use libloading::Library;

pub type ExrResult = i32;
pub const EXR_ERR_SUCCESS: ExrResult = 0;

/// `exr_context_t`: an opaque handle owned by the library.
pub type Context = *mut c_void;

/// `exr_storage_t`.
pub const EXR_STORAGE_DEEP_SCANLINE: c_int = 2;
/// `exr_compression_t`.
pub const EXR_COMPRESSION_NONE: c_int = 0;
/// `exr_pixel_type_t`.
pub const EXR_PIXEL_FLOAT: c_int = 2;
/// `exr_perceptual_treatment_t`: depth and alpha are not perceptual.
pub const EXR_PERCEPTUALLY_LINEAR: c_int = 1;
/// `exr_default_write_mode_t`: write a temporary file and rename it over
/// the destination only once the file is complete.
pub const EXR_INTERMEDIATE_TEMP_FILE: c_int = 1;

/// `exr_attr_box2i_t` (inside `#pragma pack(1)`, but two pairs of
/// `int32_t` have no padding either way).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct Box2i {
    pub min_x: i32,
    pub min_y: i32,
    pub max_x: i32,
    pub max_y: i32,
}

/// `exr_chunk_info_t`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct ChunkInfo {
    pub idx: i32,
    pub start_x: i32,
    pub start_y: i32,
    pub height: i32,
    pub width: i32,
    pub level_x: u8,
    pub level_y: u8,
    pub kind: u8,
    pub compression: u8,
    pub data_offset: u64,
    pub packed_size: u64,
    pub unpacked_size: u64,
    pub sample_count_data_offset: u64,
    pub sample_count_table_size: u64,
}

/// `exr_attr_string_t`.
#[repr(C)]
pub struct AttrString {
    pub length: i32,
    pub alloc_size: i32,
    pub str: *const c_char,
}

/// `exr_attr_chlist_entry_t`.
#[repr(C)]
pub struct ChannelEntry {
    pub name: AttrString,
    pub pixel_type: c_int,
    pub p_linear: u8,
    pub reserved: [u8; 3],
    pub x_sampling: i32,
    pub y_sampling: i32,
}

/// `exr_attr_chlist_t`.
#[repr(C)]
pub struct ChannelList {
    pub num_channels: c_int,
    pub num_alloced: c_int,
    pub entries: *const ChannelEntry,
}

/// File names handed to the dynamic loader, newest OpenEXR first: the
/// versioned names of the 3.x releases (Debian bookworm ships 3.1's
/// `libOpenEXRCore-3_1.so.30` in `libopenexr-3-1-30`), then the unversioned
/// development link and macOS's name.
pub const LIBRARY_NAMES: [&str; 8] = [
    "libOpenEXRCore-3_4.so.33",
    "libOpenEXRCore-3_3.so.32",
    "libOpenEXRCore-3_2.so.31",
    "libOpenEXRCore-3_1.so.30",
    "libOpenEXRCore.so",
    "libOpenEXRCore-3_1.so",
    "libOpenEXRCore.dylib",
    "libOpenEXRCore-3_1.dylib",
];

/// The variable naming the library file to load instead of searching.
pub const LIBRARY_VAR: &str = "CIRRUS_OPENEXR_CORE";

/// The entry points, copied out of the library as plain function pointers.
/// They stay valid for the life of the process because the [`Library`]
/// they come from is never unloaded (see [`Api::load`]).
#[derive(Clone, Copy)]
pub struct Api {
    pub get_default_error_message: unsafe extern "C" fn(ExrResult) -> *const c_char,
    pub start_write:
        unsafe extern "C" fn(*mut Context, *const c_char, c_int, *const c_void) -> ExrResult,
    pub start_read: unsafe extern "C" fn(*mut Context, *const c_char, *const c_void) -> ExrResult,
    pub finish: unsafe extern "C" fn(*mut Context) -> ExrResult,
    pub add_part: unsafe extern "C" fn(Context, *const c_char, c_int, *mut c_int) -> ExrResult,
    pub initialize_required_attr_simple:
        unsafe extern "C" fn(Context, c_int, i32, i32, c_int) -> ExrResult,
    pub set_data_window: unsafe extern "C" fn(Context, c_int, *const Box2i) -> ExrResult,
    pub set_display_window: unsafe extern "C" fn(Context, c_int, *const Box2i) -> ExrResult,
    pub add_channel:
        unsafe extern "C" fn(Context, c_int, *const c_char, c_int, c_int, i32, i32) -> ExrResult,
    pub write_header: unsafe extern "C" fn(Context) -> ExrResult,
    #[allow(clippy::type_complexity)]
    pub write_deep_scanline_chunk: unsafe extern "C" fn(
        Context,
        c_int,
        c_int,
        *const c_void,
        u64,
        u64,
        *const c_void,
        u64,
    ) -> ExrResult,
    pub get_count: unsafe extern "C" fn(Context, *mut c_int) -> ExrResult,
    pub get_storage: unsafe extern "C" fn(Context, c_int, *mut c_int) -> ExrResult,
    pub get_compression: unsafe extern "C" fn(Context, c_int, *mut c_int) -> ExrResult,
    pub get_data_window: unsafe extern "C" fn(Context, c_int, *mut Box2i) -> ExrResult,
    pub get_display_window: unsafe extern "C" fn(Context, c_int, *mut Box2i) -> ExrResult,
    pub get_channels: unsafe extern "C" fn(Context, c_int, *mut *const ChannelList) -> ExrResult,
    pub read_scanline_chunk_info:
        unsafe extern "C" fn(Context, c_int, c_int, *mut ChunkInfo) -> ExrResult,
    pub read_deep_chunk: unsafe extern "C" fn(
        Context,
        c_int,
        *const ChunkInfo,
        *mut c_void,
        *mut c_void,
    ) -> ExrResult,
}

impl Api {
    /// Resolves every entry point of `lib`; on success `lib` is never
    /// unloaded, so the copied function pointers can never dangle (one
    /// mapping per process, the cost of never having to track their use).
    fn load(lib: Library) -> Result<Api, libloading::Error> {
        macro_rules! sym {
            ($name:literal) => {
                // SAFETY: the field this initialises has the exact C
                // signature of the symbol in OpenEXR 3.1's openexr.h (its
                // declarations there, argument for argument), and the
                // pointer is kept only when every symbol resolved, after
                // which `lib` is never unloaded (below).
                *unsafe { lib.get(concat!($name, "\0").as_bytes())? }
            };
        }
        let api = Api {
            get_default_error_message: sym!("exr_get_default_error_message"),
            start_write: sym!("exr_start_write"),
            start_read: sym!("exr_start_read"),
            finish: sym!("exr_finish"),
            add_part: sym!("exr_add_part"),
            initialize_required_attr_simple: sym!("exr_initialize_required_attr_simple"),
            set_data_window: sym!("exr_set_data_window"),
            set_display_window: sym!("exr_set_display_window"),
            add_channel: sym!("exr_add_channel"),
            write_header: sym!("exr_write_header"),
            write_deep_scanline_chunk: sym!("exr_write_deep_scanline_chunk"),
            get_count: sym!("exr_get_count"),
            get_storage: sym!("exr_get_storage"),
            get_compression: sym!("exr_get_compression"),
            get_data_window: sym!("exr_get_data_window"),
            get_display_window: sym!("exr_get_display_window"),
            get_channels: sym!("exr_get_channels"),
            read_scanline_chunk_info: sym!("exr_read_scanline_chunk_info"),
            read_deep_chunk: sym!("exr_read_deep_chunk"),
        };
        std::mem::forget(lib);
        Ok(api)
    }

    /// The first of `candidates` that loads with every entry point, or an
    /// error naming each one tried and what went wrong with it, with the
    /// packages that provide the library.
    pub fn open(candidates: &[PathBuf]) -> Result<Api, String> {
        let mut tried = Vec::new();
        for path in candidates {
            // SAFETY: loading runs the library's initialisers; OpenEXRCore's
            // only set up its own static tables (no threads, no handlers).
            match unsafe { Library::new(path) } {
                Ok(lib) => match Api::load(lib) {
                    Ok(api) => return Ok(api),
                    Err(e) => tried.push(format!("{}: {e}", path.display())),
                },
                // The loader's message names the file.
                Err(e) => tried.push(e.to_string()),
            }
        }
        Err(format!(
            "deep EXR files are written and read by OpenEXR's C library \
             (OpenEXRCore 3.1 or newer), loaded when a deep image is asked for, \
             and none could be loaded. Install it (Debian and Ubuntu: \
             `apt-get install libopenexr-3-1-30`, or `libopenexr-dev`; Fedora: \
             `dnf install openexr-libs`; macOS: `brew install openexr`) or set \
             {LIBRARY_VAR} to the library file. Tried: {}",
            tried.join("; ")
        ))
    }

    /// What to try: `$CIRRUS_OPENEXR_CORE` alone when it is set (an
    /// explicit choice that fails is reported, never replaced silently by
    /// another copy), otherwise each of [`LIBRARY_NAMES`] on the loader's
    /// usual path.
    pub fn candidates() -> Vec<PathBuf> {
        match std::env::var_os(LIBRARY_VAR).filter(|v| !v.is_empty()) {
            Some(p) => vec![PathBuf::from(p)],
            None => LIBRARY_NAMES.iter().map(PathBuf::from).collect(),
        }
    }
}

/// The process's OpenEXRCore, loaded on first use; the outcome, success or
/// the error, is kept for the life of the process.
pub fn api() -> Result<&'static Api, String> {
    static API: OnceLock<Result<Api, String>> = OnceLock::new();
    API.get_or_init(|| Api::open(&Api::candidates()))
        .as_ref()
        .map_err(Clone::clone)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_library_that_does_not_load_is_named_with_what_to_install() {
        let missing = PathBuf::from("/nonexistent/libOpenEXRCore-none.so");
        let e = Api::open(std::slice::from_ref(&missing))
            .err()
            .expect("no such file");
        assert!(e.contains("/nonexistent/libOpenEXRCore-none.so"), "{e}");
        assert!(e.contains("apt-get install libopenexr-3-1-30"), "{e}");
        assert!(e.contains(LIBRARY_VAR), "{e}");
    }

    #[test]
    fn a_library_without_the_entry_points_is_refused() {
        // The C library loads but holds no OpenEXRCore symbol.
        let libc = PathBuf::from("libc.so.6");
        let e = Api::open(&[libc]).err().expect("libc is no OpenEXRCore");
        assert!(e.contains("libc.so.6") && e.contains("exr_"), "{e}");
    }
}
