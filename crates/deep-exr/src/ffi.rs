//! Hand-written declarations of the few OpenEXRCore functions and types
//! this crate uses (OpenEXR 3.1's `openexr.h`). Only the layouts used are
//! declared; every struct is `#[repr(C)]` with the header's field order.

use std::os::raw::{c_char, c_int, c_void};

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

extern "C" {
    pub fn exr_get_default_error_message(code: ExrResult) -> *const c_char;

    pub fn exr_start_write(
        ctxt: *mut Context,
        filename: *const c_char,
        default_mode: c_int,
        init: *const c_void,
    ) -> ExrResult;
    pub fn exr_start_read(
        ctxt: *mut Context,
        filename: *const c_char,
        init: *const c_void,
    ) -> ExrResult;
    pub fn exr_finish(ctxt: *mut Context) -> ExrResult;

    pub fn exr_add_part(
        ctxt: Context,
        name: *const c_char,
        storage: c_int,
        new_index: *mut c_int,
    ) -> ExrResult;
    pub fn exr_initialize_required_attr_simple(
        ctxt: Context,
        part: c_int,
        width: i32,
        height: i32,
        compression: c_int,
    ) -> ExrResult;
    pub fn exr_set_data_window(ctxt: Context, part: c_int, dw: *const Box2i) -> ExrResult;
    pub fn exr_set_display_window(ctxt: Context, part: c_int, dw: *const Box2i) -> ExrResult;
    pub fn exr_add_channel(
        ctxt: Context,
        part: c_int,
        name: *const c_char,
        pixel_type: c_int,
        perceptual: c_int,
        x_sampling: i32,
        y_sampling: i32,
    ) -> ExrResult;
    pub fn exr_write_header(ctxt: Context) -> ExrResult;
    pub fn exr_write_deep_scanline_chunk(
        ctxt: Context,
        part: c_int,
        y: c_int,
        packed: *const c_void,
        packed_size: u64,
        unpacked_size: u64,
        sample_data: *const c_void,
        sample_data_size: u64,
    ) -> ExrResult;

    pub fn exr_get_count(ctxt: Context, count: *mut c_int) -> ExrResult;
    pub fn exr_get_storage(ctxt: Context, part: c_int, out: *mut c_int) -> ExrResult;
    pub fn exr_get_compression(ctxt: Context, part: c_int, out: *mut c_int) -> ExrResult;
    pub fn exr_get_data_window(ctxt: Context, part: c_int, out: *mut Box2i) -> ExrResult;
    pub fn exr_get_display_window(ctxt: Context, part: c_int, out: *mut Box2i) -> ExrResult;
    pub fn exr_get_channels(ctxt: Context, part: c_int, out: *mut *const ChannelList) -> ExrResult;
    pub fn exr_read_scanline_chunk_info(
        ctxt: Context,
        part: c_int,
        y: c_int,
        out: *mut ChunkInfo,
    ) -> ExrResult;
    pub fn exr_read_deep_chunk(
        ctxt: Context,
        part: c_int,
        cinfo: *const ChunkInfo,
        packed: *mut c_void,
        sample_data: *mut c_void,
    ) -> ExrResult;
}
