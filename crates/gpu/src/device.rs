//! Finding a device: which adapter a render may use, and what to say when
//! there is none.

use std::fmt;

/// Why no GPU render happened.
#[derive(Debug)]
pub enum GpuError {
    /// No Vulkan adapter at all.
    NoAdapter(String),
    /// The scene or settings ask for what the GPU kernel does not do.
    Unsupported(Vec<String>),
    /// The device refused something (sizes, the kernel, a lost device).
    Device(String),
}

/// What to install when no adapter is found.
pub const INSTALL_HINT: &str = "install a Vulkan driver: on Debian `apt-get install \
mesa-vulkan-drivers libvulkan1` (lavapipe, Vulkan on the CPU), or your GPU's driver";

impl fmt::Display for GpuError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GpuError::NoAdapter(why) => {
                write!(
                    f,
                    "--device gpu: no Vulkan adapter found ({why}); {INSTALL_HINT}"
                )
            }
            GpuError::Unsupported(what) => write!(
                f,
                "--device gpu does not render {} yet; use --device cpu",
                what.join(", ")
            ),
            GpuError::Device(why) => write!(f, "--device gpu: {why}"),
        }
    }
}

impl std::error::Error for GpuError {}

/// An open device: the adapter's description, the device and its queue.
pub struct Gpu {
    pub info: wgpu::AdapterInfo,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// The largest storage binding the device allows, in bytes.
    pub max_binding: u64,
    /// Storage bindings a kernel may have.
    pub max_bindings: u32,
    /// Bytes of the device's largest device-local memory heap (`u64::MAX`
    /// where Vulkan does not say).
    pub memory: u64,
}

impl Gpu {
    /// The same device as if it bound at most `bytes` a storage binding
    /// (tests force the atlas's split with it).
    pub fn with_binding_limit(mut self, bytes: u64) -> Self {
        self.max_binding = self.max_binding.min(bytes);
        self
    }

    /// The same device as if it had `bytes` of memory (tests force the
    /// refusal of a scene too large with it).
    pub fn with_memory_limit(mut self, bytes: u64) -> Self {
        self.memory = self.memory.min(bytes);
        self
    }

    /// Whether the adapter is a GPU in hardware (not lavapipe or another
    /// software rasteriser).
    pub fn is_hardware(&self) -> bool {
        hardware(&self.info)
    }

    /// The adapter in words, for messages: its name and kind.
    pub fn describe(&self) -> String {
        let memory = match self.memory {
            u64::MAX => String::new(),
            bytes => format!(", {} MiB", bytes >> 20),
        };
        format!(
            "{} ({:?}, {:?}{memory})",
            self.info.name, self.info.device_type, self.info.backend
        )
    }
}

fn hardware(info: &wgpu::AdapterInfo) -> bool {
    !matches!(info.device_type, wgpu::DeviceType::Cpu)
}

/// Opens the best Vulkan adapter: a discrete GPU over an integrated one
/// over the rest; a software adapter only where `software` allows it.
pub fn open(software: bool) -> Result<Gpu, GpuError> {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(desc);
    let adapters = block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
    let rank = |info: &wgpu::AdapterInfo| match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    };
    let found = adapters.len();
    let adapter = adapters
        .into_iter()
        .filter(|a| software || hardware(&a.get_info()))
        .min_by_key(|a| rank(&a.get_info()));
    let Some(adapter) = adapter else {
        let why = match found {
            0 => "no Vulkan driver or device".to_string(),
            n => format!("{n} software adapter(s) only, which --device auto does not use"),
        };
        return Err(GpuError::NoAdapter(why));
    };
    // All the adapter allows: the largest bindings (a volume's atlas) above all.
    let limits = adapter.limits();
    let memory = device_memory(&adapter);
    let (device, queue) = block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("cirrus"),
        required_limits: limits.clone(),
        ..Default::default()
    }))
    .map_err(|e| GpuError::Device(format!("the adapter gave no device: {e}")))?;
    Ok(Gpu {
        info: adapter.get_info(),
        device,
        queue,
        max_binding: limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size),
        max_bindings: limits.max_storage_buffers_per_shader_stage,
        memory,
    })
}

/// The size of the adapter's largest device-local memory heap, which
/// every buffer of a render must fit in (wgpu does not say; Vulkan does).
fn device_memory(adapter: &wgpu::Adapter) -> u64 {
    // Vulkan's VK_MEMORY_HEAP_DEVICE_LOCAL_BIT.
    const DEVICE_LOCAL: u32 = 1;
    // SAFETY: the adapter is a Vulkan one (the instance has no other
    // backend) and outlives the call; the query reads properties only.
    let heaps = unsafe {
        adapter.as_hal::<wgpu::hal::api::Vulkan>().map(|hal| {
            let instance = hal.shared_instance().raw_instance();
            let props = instance.get_physical_device_memory_properties(hal.raw_physical_device());
            props.memory_heaps[..props.memory_heap_count as usize]
                .iter()
                .filter(|h| h.flags.as_raw() & DEVICE_LOCAL != 0)
                .map(|h| h.size)
                .max()
                .unwrap_or(0)
        })
    };
    match heaps {
        Some(bytes) if bytes > 0 => bytes,
        _ => u64::MAX,
    }
}

/// Runs a future to completion on this thread: wgpu's native futures are
/// ready at once or after a device poll, so a spin with a no-op waker is
/// enough (and needs no executor crate).
pub(crate) fn block_on<F: std::future::Future>(future: F) -> F::Output {
    use std::task::{Context, Poll, Waker};
    let mut future = std::pin::pin!(future);
    let mut cx = Context::from_waker(Waker::noop());
    loop {
        if let Poll::Ready(out) = future.as_mut().poll(&mut cx) {
            return out;
        }
        std::thread::yield_now();
    }
}
