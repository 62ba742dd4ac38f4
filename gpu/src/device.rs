//! Headless device setup shared by every GPU stage.

/// Errors setting up the GPU.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter was found.
    #[error("no GPU adapter found ({0}); on a machine without a GPU install Mesa's lavapipe: apt-get install mesa-vulkan-drivers")]
    NoAdapter(String),
    /// The device could not be created.
    #[error("could not create a GPU device on {adapter}: {reason}")]
    Device {
        /// Adapter name.
        adapter: String,
        /// Why.
        reason: String,
    },
    /// The adapter cannot render this format at this sample count.
    #[error("{format:?} does not support {samples}x multisampling on this adapter")]
    SampleCount {
        /// The format.
        format: wgpu::TextureFormat,
        /// The sample count asked for.
        samples: u32,
    },
    /// wgpu refused to create a resource or run a command.
    #[error("wgpu: {0}")]
    Wgpu(String),
    /// The device was lost or a readback failed.
    #[error("GPU readback failed: {0}")]
    Readback(String),
}

/// A device with what trisort learned about its adapter.
pub struct Gpu {
    /// The adapter.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Adapter information (name, driver, backend).
    pub info: wgpu::AdapterInfo,
}

/// Features trisort uses when the adapter has them. The three texture-compression features
/// let the player sample a baked file's block-compressed textures as stored
/// ([`crate::scene_gpu::ArrayUpload`]); without them it uploads their decoded texels.
pub fn wanted_features() -> wgpu::Features {
    wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES
        | wgpu::Features::TEXTURE_COMPRESSION_BC
        | wgpu::Features::TEXTURE_COMPRESSION_ETC2
        | wgpu::Features::TEXTURE_COMPRESSION_ASTC
        | wgpu::Features::SHADER_EARLY_DEPTH_TEST
        | wgpu::Features::PRIMITIVE_INDEX
        | wgpu::Features::TIMESTAMP_QUERY
        | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
        | wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES
        | wgpu::Features::PIPELINE_STATISTICS_QUERY
}

/// An adapter as a trisort file records it: name, driver (name and version) and backend.
pub fn device_info(info: &wgpu::AdapterInfo) -> trisort_format::DeviceInfo {
    trisort_format::DeviceInfo {
        adapter: info.name.clone(),
        driver: format!("{} {}", info.driver, info.driver_info)
            .trim()
            .to_string(),
        backend: format!("{:?}", info.backend),
    }
}

pub use trisort_format::{DeviceBackend, DeviceLimits};

/// How to open a device: backend and limits ([`Gpu::with_options`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// The backend.
    pub backend: DeviceBackend,
    /// The limits.
    pub limits: DeviceLimits,
}

impl Gpu {
    #[cfg(not(target_arch = "wasm32"))]
    /// Opens the default adapter headless (no surface) with the adapter's own limits and the
    /// [`wanted_features`] it supports. `WGPU_BACKEND` and `WGPU_ADAPTER_NAME` select as in
    /// wgpu.
    pub fn new() -> Result<Gpu, GpuError> {
        Gpu::with_flags(wgpu::InstanceFlags::from_build_config().with_env())
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// Like [`Gpu::new`], with the instance created with `flags` instead of wgpu's defaults
    /// (`WGPU_BACKEND` and `WGPU_ADAPTER_NAME` still select). Use it to switch wgpu's
    /// indirect-call validation ([`wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL`], on by
    /// default even in release builds) on or off: the flag is read when the device is created.
    pub fn with_flags(flags: wgpu::InstanceFlags) -> Result<Gpu, GpuError> {
        Gpu::with_options(flags, GpuOptions::default())
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// [`Gpu::with_flags`] on the backend and with the limits of `options` (a backend other
    /// than [`DeviceBackend::Auto`] overrides `WGPU_BACKEND`).
    pub fn with_options(flags: wgpu::InstanceFlags, options: GpuOptions) -> Result<Gpu, GpuError> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        desc.flags = flags;
        match options.backend {
            DeviceBackend::Auto => {}
            DeviceBackend::Vulkan => desc.backends = wgpu::Backends::VULKAN,
            DeviceBackend::Gl => desc.backends = wgpu::Backends::GL,
        }
        let instance = wgpu::Instance::new(desc);
        Gpu::open(&instance, None, "trisort", options.limits)
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// A device on an adapter of `instance` that can present to `surface` (a window's, created
    /// from `instance`), with the adapter's own limits and the [`wanted_features`] it supports,
    /// chosen like [`Gpu::new`] otherwise.
    pub fn for_surface(
        instance: &wgpu::Instance,
        surface: &wgpu::Surface<'_>,
    ) -> Result<Gpu, GpuError> {
        Gpu::open(
            instance,
            Some(surface),
            "trisort window",
            DeviceLimits::Adapter,
        )
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// The one adapter and device request behind [`Gpu::with_flags`] and [`Gpu::for_surface`]:
    /// [`Gpu::open_async`], waited for.
    fn open(
        instance: &wgpu::Instance,
        compatible_surface: Option<&wgpu::Surface<'_>>,
        label: &str,
        limits: DeviceLimits,
    ) -> Result<Gpu, GpuError> {
        pollster::block_on(Gpu::open_async(instance, compatible_surface, label, limits))
    }

    /// Requests an adapter of `instance` (compatible with `compatible_surface` when given)
    /// and a device on it with `limits` and the [`wanted_features`] it supports. The one
    /// request behind every constructor; a browser awaits it directly (it never completes a
    /// blocking wait), natively [`Gpu::new`] and the others wait for it.
    pub async fn open_async(
        instance: &wgpu::Instance,
        compatible_surface: Option<&wgpu::Surface<'_>>,
        label: &str,
        limits: DeviceLimits,
    ) -> Result<Gpu, GpuError> {
        let power_preference =
            wgpu::PowerPreference::from_env().unwrap_or(wgpu::PowerPreference::HighPerformance);
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference,
                force_fallback_adapter: false,
                compatible_surface,
                apply_limit_buckets: false,
            })
            .await
            .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let features = adapter.features() & wanted_features();
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some(label),
                required_features: features,
                required_limits: match limits {
                    DeviceLimits::Adapter => adapter.limits(),
                    DeviceLimits::Webgl2 => {
                        wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits())
                    }
                },
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError::Device {
                adapter: info.name.clone(),
                reason: e.to_string(),
            })?;
        Ok(Gpu {
            adapter,
            device,
            queue,
            info,
        })
    }

    /// One line describing the adapter, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Mesa 22.3.6)`.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {} {})",
            self.info.name, self.info.backend, self.info.driver, self.info.driver_info
        )
    }

    /// The adapter as a trisort file records it (see [`device_info`]).
    pub fn device_info(&self) -> trisort_format::DeviceInfo {
        device_info(&self.info)
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// Reads back a buffer region synchronously (copies into a mappable staging buffer).
    pub fn read_buffer(&self, buffer: &wgpu::Buffer, offset: u64, size: u64) -> Vec<u8> {
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(buffer, offset, &staging, 0, size);
        self.queue.submit([enc.finish()]);
        self.map_read(&staging)
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// Maps a `MAP_READ` buffer after the queue has finished with it, and returns its bytes.
    pub fn map_read(&self, staging: &wgpu::Buffer) -> Vec<u8> {
        let slice = staging.slice(..);
        slice.map_async(wgpu::MapMode::Read, |r| r.expect("buffer mapping failed"));
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("GPU device lost while waiting for a readback");
        let out = slice.get_mapped_range().expect("mapped range").to_vec();
        staging.unmap();
        out
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// Reads back a 2D RGBA8/BGRA8/R32 texture (4 bytes per texel, one sample, mip 0, layer 0)
    /// as tightly packed rows.
    pub fn read_texture_4bpp(&self, texture: &wgpu::Texture) -> Vec<u8> {
        let (w, h) = (texture.width(), texture.height());
        let row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("texture readback"),
            size: row as u64 * h as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            texture.size(),
        );
        self.queue.submit([enc.finish()]);
        let padded = self.map_read(&staging);
        let mut out = Vec::with_capacity((w * h * 4) as usize);
        for y in 0..h as usize {
            out.extend_from_slice(&padded[y * row as usize..][..(w * 4) as usize]);
        }
        out
    }
}

/// The first wgpu error that no error scope caught, kept for the caller to report: a viewer
/// (the window, a browser canvas) checks it after each frame instead of letting wgpu's default
/// handler panic.
#[derive(Clone, Default)]
pub struct UncapturedError(std::sync::Arc<std::sync::Mutex<Option<String>>>);

impl UncapturedError {
    /// Installs the slot as `device`'s uncaptured-error handler.
    pub fn install(device: &wgpu::Device) -> UncapturedError {
        let slot = UncapturedError::default();
        let inner = slot.0.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            let mut first = inner.lock().unwrap_or_else(|p| p.into_inner());
            first.get_or_insert_with(|| e.to_string());
        }));
        slot
    }

    /// The first error since the last call, if any.
    pub fn take(&self) -> Option<String> {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).take()
    }
}
