//! The megakernel on the device: the WGSL stages joined into one module,
//! the flat scene uploaded once, each pixel's path and the film's moments
//! kept on the device across dispatches and read back at the end.

use std::borrow::Cow;

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::device::{block_on, Gpu, GpuError};
use crate::flat::{FlatScene, Params};

/// The kernel's stages, in the order they are joined (WGSL declarations
/// may come in any order; this is the order to read them in).
pub const STAGES: [(&str, &str); 12] = [
    ("common.wgsl", include_str!("shaders/common.wgsl")),
    ("lookup.wgsl", include_str!("shaders/lookup.wgsl")),
    ("walk.wgsl", include_str!("shaders/walk.wgsl")),
    ("spectral.wgsl", include_str!("shaders/spectral.wgsl")),
    ("delta.wgsl", include_str!("shaders/delta.wgsl")),
    ("ratio.wgsl", include_str!("shaders/ratio.wgsl")),
    ("phase.wgsl", include_str!("shaders/phase.wgsl")),
    ("table_phase.wgsl", include_str!("shaders/table_phase.wgsl")),
    ("lights.wgsl", include_str!("shaders/lights.wgsl")),
    (
        "sphere_light.wgsl",
        include_str!("shaders/sphere_light.wgsl"),
    ),
    ("area_light.wgsl", include_str!("shaders/area_light.wgsl")),
    ("path.wgsl", include_str!("shaders/path.wgsl")),
];

/// The entry point of `path.wgsl`.
pub const ENTRY: &str = "render_pass";

/// Pixels a workgroup covers per axis (`@workgroup_size(8, 8, 1)`).
const GROUP: u32 = 8;

/// Storage bindings besides the atlas's chunks (`common.wgsl`).
const OTHER_STORAGE_BINDINGS: u32 = 9;

/// The binding of the atlas's second chunk (the first is binding 2).
const FIRST_EXTRA_CHUNK_BINDING: u32 = 11;

/// The WGSL module for an atlas in `chunks` bindings: every stage, joined,
/// and the chunks' declarations.
pub fn source(chunks: u32) -> String {
    let mut s: Vec<String> = STAGES.iter().map(|(_, s)| s.to_string()).collect();
    s.push(atlas_chunks_source(chunks));
    s.join("\n")
}

/// The atlas's chunks past the first (`atlas_1`, ...) and `atlas_word`,
/// word `i` of chunk `chunk`: a switch, as WGSL has no arrays of storage
/// buffers without an extension.
fn atlas_chunks_source(chunks: u32) -> String {
    let mut s = String::from("// Written by kernel.rs (`atlas_chunks_source`).\n");
    for k in 1..chunks {
        let binding = FIRST_EXTRA_CHUNK_BINDING + k - 1;
        s += &format!("@group(0) @binding({binding}) var<storage, read> atlas_{k}: array<u32>;\n");
    }
    s += "fn atlas_word(chunk: u32, i: u32) -> u32 {\n    switch chunk {\n";
    for k in 1..chunks {
        s += &format!("        case {k}u: {{\n            return atlas_{k}[i];\n        }}\n");
    }
    s += "        default: {\n            return atlas_0[i];\n        }\n    }\n}\n";
    s
}

/// One pixel's running moments on the device (`PixelSlot` in
/// `common.wgsl`): with the samples replaced by zero for not being
/// finite, those cut short by the device's loop limit, and the
/// collisions its paths took.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PixelSlot {
    pub mean: [f32; 4],
    pub m2: [f32; 4],
    pub n: u32,
    pub nonfinite: u32,
    pub cut: u32,
    pub reals: u32,
    pub nulls: u32,
    pub shadows: u32,
    pub pad: [u32; 2],
}

/// Bytes of a pixel's path under way (`PathState` in `common.wgsl`).
const PATH_STATE_BYTES: u64 = 80;

/// The device's buffers, one a binding of `common.wgsl`.
struct Buffers {
    params: wgpu::Buffer,
    map: wgpu::Buffer,
    /// The atlas's chunks, whole bricks each.
    atlas: Vec<wgpu::Buffer>,
    constants: wgpu::Buffer,
    pyramid: wgpu::Buffer,
    lights: wgpu::Buffer,
    film: wgpu::Buffer,
    paths: wgpu::Buffer,
    pending: wgpu::Buffer,
    partition: wgpu::Buffer,
    phase_table: wgpu::Buffer,
}

/// How the atlas is split: stored bricks a chunk, and chunks.
#[derive(Clone, Copy, Debug)]
struct AtlasSplit {
    bricks_per_chunk: u64,
    chunks: u32,
}

/// The atlas in chunks of as many whole bricks as a binding holds.
fn split_atlas(gpu: &Gpu, scene: &FlatScene) -> Result<AtlasSplit, GpuError> {
    let brick_bytes = 4 * scene.brick_words() as u64;
    let bricks = (scene.atlas.len() as u64).div_ceil(scene.brick_words() as u64);
    let bricks_per_chunk = (gpu.max_binding / brick_bytes).min(u64::from(u32::MAX));
    if bricks_per_chunk == 0 {
        return Err(GpuError::Device(format!(
            "the device binds at most {} bytes, less than a brick ({brick_bytes})",
            gpu.max_binding
        )));
    }
    let chunks = bricks.div_ceil(bricks_per_chunk).max(1);
    let room = u64::from(gpu.max_bindings.saturating_sub(OTHER_STORAGE_BINDINGS));
    if chunks > room {
        return Err(GpuError::Device(format!(
            "the volume's atlas ({} MiB) needs {chunks} bindings of at most {} MiB and the \
             device allows {room} for it",
            (scene.atlas.len() * 4) >> 20,
            gpu.max_binding >> 20
        )));
    }
    Ok(AtlasSplit {
        bricks_per_chunk,
        chunks: chunks as u32,
    })
}

/// Rows of the window a band of it holds: as many as keep a band's paths
/// (the larger per-pixel array) within one binding.
fn band_rows(gpu: &Gpu, width: u32, height: u32) -> Result<u32, GpuError> {
    let row_bytes = u64::from(width) * PATH_STATE_BYTES;
    let rows = gpu.max_binding / row_bytes.max(1);
    if rows == 0 {
        return Err(GpuError::Device(format!(
            "a {width}-pixel row needs {row_bytes} bytes of paths and the device binds at most \
             {} bytes",
            gpu.max_binding
        )));
    }
    Ok(rows.min(u64::from(height.max(1))) as u32)
}

/// Bands a `width` x `height` window is rendered in on `gpu`: one where
/// its paths fit a binding.
pub fn window_bands(gpu: &Gpu, width: u32, height: u32) -> Result<u32, GpuError> {
    Ok(height.div_ceil(band_rows(gpu, width, height)?).max(1))
}

/// Refuses a scene whose arrays exceed what a binding holds or whose
/// buffers together (the film and paths of a band of `pixels`) exceed the
/// device's memory, before anything is uploaded.
fn check_sizes(gpu: &Gpu, scene: &FlatScene, pixels: u64) -> Result<(), GpuError> {
    let largest = scene.largest_binding();
    if largest > gpu.max_binding {
        return Err(GpuError::Device(format!(
            "the volume needs a {} MiB array besides its atlas and the device binds at most \
             {} MiB",
            largest >> 20,
            gpu.max_binding >> 20
        )));
    }
    // The film twice (on the device, and read back), and the paths.
    let film_bytes = pixels * std::mem::size_of::<PixelSlot>() as u64;
    let needed = scene.bytes() + 2 * film_bytes + pixels * PATH_STATE_BYTES;
    if needed > gpu.memory {
        return Err(GpuError::Device(format!(
            "the scene needs {} MiB on the device ({} MiB of volume) and the device has {} MiB",
            needed.div_ceil(1 << 20),
            scene.bytes().div_ceil(1 << 20),
            gpu.memory >> 20
        )));
    }
    Ok(())
}

/// The scene uploaded, the film zeroed and the paths' room made, for a
/// band of `pixels`.
fn upload(device: &wgpu::Device, scene: &FlatScene, pixels: u64, split: AtlasSplit) -> Buffers {
    use wgpu::BufferUsages as U;
    let init = |label: &str, bytes: &[u8], usage: U| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytes,
            usage,
        })
    };
    let empty = |label: &str, size: u64, usage: U| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage,
            mapped_at_creation: false,
        })
    };
    let film = vec![PixelSlot::default(); pixels as usize];
    let chunk_words = split.bricks_per_chunk as usize * scene.brick_words();
    let mut atlas: Vec<wgpu::Buffer> = scene
        .atlas
        .chunks(chunk_words)
        .map(|c| init("atlas", bytemuck::cast_slice(c), U::STORAGE))
        .collect();
    if atlas.is_empty() {
        atlas.push(init("atlas", bytemuck::cast_slice(&[0u32]), U::STORAGE));
    }
    Buffers {
        params: init(
            "params",
            bytemuck::bytes_of(&scene.params),
            U::UNIFORM | U::COPY_DST,
        ),
        map: init("brick map", bytemuck::cast_slice(&scene.map), U::STORAGE),
        atlas,
        constants: init(
            "constants",
            bytemuck::cast_slice(&scene.constants),
            U::STORAGE,
        ),
        pyramid: init("pyramid", bytemuck::cast_slice(&scene.pyramid), U::STORAGE),
        partition: init(
            "partition",
            bytemuck::cast_slice(&scene.partition),
            U::STORAGE,
        ),
        lights: init("lights", bytemuck::cast_slice(&scene.lights), U::STORAGE),
        phase_table: init(
            "phase table",
            bytemuck::cast_slice(&scene.phase_table),
            U::STORAGE,
        ),
        film: init(
            "film",
            bytemuck::cast_slice(&film),
            U::STORAGE | U::COPY_SRC | U::COPY_DST,
        ),
        // Zero-filled at creation: no path under way, no sample taken.
        paths: empty("paths", pixels * PATH_STATE_BYTES, U::STORAGE | U::COPY_DST),
        pending: empty("pending", 4, U::STORAGE | U::COPY_SRC | U::COPY_DST),
    }
}

/// A band of the window's rows, rendered by itself: its first row (from
/// the window's top) and its rows.
#[derive(Clone, Copy, Debug)]
struct Band {
    y0: u32,
    rows: u32,
}

/// The uploaded scene, the film and paths of one band of the window on
/// the device, and the pipeline. A window whose paths exceed a binding is
/// rendered band by band (each pixel's samples keyed by its place in the
/// image, so the bands make the unsplit image, bit for bit); the
/// moments of the bands not on the device wait on the host.
pub struct Kernel<'g> {
    gpu: &'g Gpu,
    params: Params,
    params_buffer: wgpu::Buffer,
    film: wgpu::Buffer,
    paths: wgpu::Buffer,
    pending: wgpu::Buffer,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// The window's top row in the image.
    window_y0: u32,
    width: u32,
    bands: Vec<Band>,
    /// The band on the device.
    current: usize,
    /// Every band's moments while several take turns on the device.
    host_film: Vec<PixelSlot>,
}

impl<'g> Kernel<'g> {
    /// Uploads `scene` and builds the pipeline; refuses arrays larger than
    /// a binding may be.
    pub fn new(gpu: &'g Gpu, scene: &FlatScene) -> Result<Self, GpuError> {
        let [w, h] = [scene.params.window[0], scene.params.window[1]];
        let rows = band_rows(gpu, w, h)?;
        let pixels = u64::from(w) * u64::from(rows);
        check_sizes(gpu, scene, pixels)?;
        let bands: Vec<Band> = (0..h.div_ceil(rows).max(1))
            .map(|k| Band {
                y0: k * rows,
                rows: rows.min(h - k * rows),
            })
            .collect();
        let split = split_atlas(gpu, scene)?;
        let mut params = scene.params;
        params.counts[1] = split.bricks_per_chunk as u32;
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let b = upload(device, scene, pixels, split);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("path tracer"),
            source: wgpu::ShaderSource::Wgsl(Cow::Owned(source(split.chunks))),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("path tracer"),
            layout: None,
            module: &module,
            entry_point: Some(ENTRY),
            compilation_options: Default::default(),
            cache: None,
        });
        // In the order of `common.wgsl`'s bindings, then the atlas's
        // other chunks.
        let mut bound = vec![
            &b.params,
            &b.map,
            &b.atlas[0],
            &b.constants,
            &b.pyramid,
            &b.lights,
            &b.film,
            &b.paths,
            &b.pending,
            &b.partition,
            &b.phase_table,
        ];
        bound.extend(&b.atlas[1..]);
        let entries: Vec<wgpu::BindGroupEntry> = bound
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        if let Some(e) = block_on(scope.pop()) {
            return Err(GpuError::Device(format!("the kernel was refused: {e}")));
        }
        let host_film = if bands.len() > 1 {
            vec![PixelSlot::default(); w as usize * h as usize]
        } else {
            Vec::new()
        };
        let mut kernel = Self {
            gpu,
            params,
            params_buffer: b.params,
            film: b.film,
            paths: b.paths,
            pending: b.pending,
            pipeline,
            bind_group,
            window_y0: scene.params.image[3],
            width: w,
            bands,
            current: 0,
            host_film,
        };
        kernel.place_band(0);
        Ok(kernel)
    }

    /// Bands the window is rendered in.
    pub fn bands(&self) -> usize {
        self.bands.len()
    }

    /// Puts band `k` on the device: its rows in the parameters, and where
    /// the window is split, its moments so far in the film and no path
    /// under way (each pixel's next sample is its count of samples,
    /// `path.wgsl`).
    pub fn enter_band(&mut self, k: usize) -> Result<(), GpuError> {
        if self.bands.len() == 1 {
            return Ok(());
        }
        self.place_band(k);
        let range = self.band_slots(k);
        self.gpu
            .queue
            .write_buffer(&self.film, 0, bytemuck::cast_slice(&self.host_film[range]));
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("band"),
            });
        encoder.clear_buffer(&self.paths, 0, None);
        self.gpu.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// Keeps the moments of the band on the device on the host (where the
    /// window is split), once its pixels are done.
    pub fn leave_band(&mut self) -> Result<(), GpuError> {
        if self.bands.len() == 1 {
            return Ok(());
        }
        let range = self.band_slots(self.current);
        let slots = self.read_band_film(range.len())?;
        self.host_film[range].copy_from_slice(&slots);
        Ok(())
    }

    fn place_band(&mut self, k: usize) {
        let band = self.bands[k];
        self.current = k;
        self.params.image[3] = self.window_y0 + band.y0;
        self.params.window[1] = band.rows;
    }

    /// Band `k`'s slots in the window's film.
    fn band_slots(&self, k: usize) -> std::ops::Range<usize> {
        let band = self.bands[k];
        let w = self.width as usize;
        band.y0 as usize * w..(band.y0 + band.rows) as usize * w
    }

    /// Queues a dispatch: each pixel with fewer than `target` samples
    /// advances its path by up to `events` scattering events (starting
    /// its next samples as paths end).
    pub fn dispatch(&mut self, target: u32, events: u32) {
        self.params.window[2] = target;
        self.params.window[3] = events;
        let gpu = self.gpu;
        gpu.queue
            .write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("pass"),
            });
        encoder.clear_buffer(&self.pending, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("pass"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            let [w, h] = [self.params.window[0], self.params.window[1]];
            pass.dispatch_workgroups(w.div_ceil(GROUP), h.div_ceil(GROUP), 1);
        }
        gpu.queue.submit([encoder.finish()]);
    }

    /// Waits for the passes queued so far.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.gpu
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Device(format!("waiting for a pass: {e}")))
    }

    /// The window's moments (after every dispatch queued): the film on
    /// the device, or the bands' kept on the host.
    pub fn read_film(&self) -> Result<Vec<PixelSlot>, GpuError> {
        if self.bands.len() > 1 {
            return Ok(self.host_film.clone());
        }
        self.read_band_film(self.band_slots(0).len())
    }

    /// The first `pixels` slots of the film on the device.
    fn read_band_film(&self, pixels: usize) -> Result<Vec<PixelSlot>, GpuError> {
        let bytes = (pixels * std::mem::size_of::<PixelSlot>()) as u64;
        let raw = self.read(&self.film, bytes)?;
        Ok(bytemuck::cast_slice::<u8, PixelSlot>(&raw).to_vec())
    }

    /// How many pixels had samples left after the last dispatch.
    pub fn pending(&self) -> Result<u32, GpuError> {
        let raw = self.read(&self.pending, 4)?;
        Ok(u32::from_le_bytes([raw[0], raw[1], raw[2], raw[3]]))
    }

    /// The first `bytes` of `buffer`, read back after every dispatch
    /// queued.
    fn read(&self, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>, GpuError> {
        let device = &self.gpu.device;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("film readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("readback"),
        });
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
        self.gpu.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        let (send, receive) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = send.send(r);
        });
        self.wait()?;
        receive
            .recv()
            .map_err(|e| GpuError::Device(format!("reading the film back: {e}")))?
            .map_err(|e| GpuError::Device(format!("reading the film back: {e}")))?;
        let view = slice
            .get_mapped_range()
            .map_err(|e| GpuError::Device(format!("reading the film back: {e:?}")))?;
        Ok(view.to_vec())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The joined stages parse and validate as WGSL (naga, as wgpu's
    /// Vulkan backend will), with no device needed.
    #[test]
    fn the_kernel_is_valid_wgsl() {
        use wgpu::naga;
        // One chunk of atlas, and three.
        for chunks in [1, 3] {
            let source = source(chunks);
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::default(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
            assert!(module.entry_points.iter().any(|e| e.name == ENTRY));
        }
    }

    /// The host's sizes of the device's structs are `common.wgsl`'s.
    #[test]
    fn struct_sizes_match_the_kernel() {
        use wgpu::naga;
        let module = naga::front::wgsl::parse_str(&source(1)).unwrap();
        let size = |name: &str| {
            let (_, ty) = module
                .types
                .iter()
                .find(|(_, t)| t.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("no struct {name}"));
            u64::from(ty.inner.size(module.to_ctx()))
        };
        assert_eq!(size("PixelSlot"), std::mem::size_of::<PixelSlot>() as u64);
        assert_eq!(size("PathState"), PATH_STATE_BYTES);
        assert_eq!(
            size("Params"),
            std::mem::size_of::<crate::flat::Params>() as u64
        );
        assert_eq!(
            size("LightRecord"),
            std::mem::size_of::<crate::flat::LightRecord>() as u64
        );
    }
}
