//! Finding a Vulkan adapter and opening a device on it.

/// Why the GPU backend cannot run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GpuError {
    /// No Vulkan adapter was found.
    #[error("no Vulkan adapter found ({0}); install a Vulkan driver (on Debian: apt-get install mesa-vulkan-drivers libvulkan1, Mesa's CPU driver, slow but complete) or run with [integrator] backend = \"cpu\"")]
    NoAdapter(String),
    /// The adapter could not open a device.
    #[error("the Vulkan adapter {adapter} could not open a device: {message}")]
    Device {
        /// The adapter's name.
        adapter: String,
        /// The driver's message.
        message: String,
    },
    /// The state does not fit the device.
    #[error("{0}")]
    TooLarge(String),
    /// The tissue has a part that the GPU backend does not compute.
    #[error("the GPU backend runs the paper's model and every extension of it but a physics term of your own, and this scene has {0}; run it with [integrator] backend = \"cpu\"")]
    Unsupported(String),
    /// A step setting the GPU backend does not support.
    #[error("{0}")]
    Setting(String),
    /// The device failed while running (lost, out of memory, a map failed).
    #[error("the device failed: {0}")]
    Lost(String),
}

/// An open device: the adapter's description, its limits, the device and its queue.
#[derive(Debug)]
pub struct Device {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pub(crate) info: wgpu::AdapterInfo,
    pub(crate) limits: wgpu::Limits,
}

impl Device {
    /// Opens the first Vulkan adapter, a discrete GPU first (`WGPU_ADAPTER_NAME` picks one
    /// by name), with the adapter's own limits (the step binds 11 storage buffers and large
    /// arrays).
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`] or [`GpuError::Device`].
    pub fn open() -> Result<Self, GpuError> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        desc.backends = wgpu::Backends::VULKAN;
        let instance = wgpu::Instance::new(desc);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("monolayer"),
            required_features: wgpu::Features::empty(),
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device {
            adapter: info.name.clone(),
            message: e.to_string(),
        })?;
        Ok(Self {
            device,
            queue,
            info,
            limits,
        })
    }

    /// The adapter: name, driver and device type, for messages and the run's record.
    pub fn describe(&self) -> String {
        describe(&self.info)
    }

    /// The largest storage-buffer binding, in bytes.
    pub fn max_binding(&self) -> u64 {
        self.limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size)
    }

    /// The device's copy bandwidth in GB/s, bytes read plus bytes written: the best of
    /// `repeats` timed copies of a `bytes`-byte buffer into another (after one untimed), each
    /// submitted alone and waited for, so that the figure includes a submission's latency
    /// (negligible from about 100 MB). This is the roof that the step's counted bytes per
    /// node-update ([`crate::GpuBackend::bytes_per_node_update`]) are set against.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for more than the device's largest buffer, or
    /// [`GpuError::Lost`].
    pub fn copy_bandwidth(&self, bytes: u64, repeats: usize) -> Result<f64, GpuError> {
        let bytes = bytes.max(4) / 4 * 4;
        if bytes > self.limits.max_buffer_size {
            return Err(GpuError::TooLarge(format!(
                "a copy of {bytes} bytes: the device's largest buffer is {} bytes",
                self.limits.max_buffer_size
            )));
        }
        let buffer = |label| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let (from, to) = (buffer("copy from"), buffer("copy to"));
        let mut best = f64::INFINITY;
        for i in 0..=repeats {
            let t0 = std::time::Instant::now();
            let mut enc = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
            enc.copy_buffer_to_buffer(&from, 0, &to, 0, bytes);
            self.queue.submit(Some(enc.finish()));
            self.device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| GpuError::Lost(e.to_string()))?;
            if i > 0 {
                best = best.min(t0.elapsed().as_secs_f64());
            }
        }
        Ok(2.0 * bytes as f64 / best / 1e9)
    }

    /// The wgpu device and queue, for tests that run kernels of their own.
    pub fn raw(&self) -> (&wgpu::Device, &wgpu::Queue) {
        (&self.device, &self.queue)
    }
}

fn describe(info: &wgpu::AdapterInfo) -> String {
    format!(
        "{} ({:?}, {} {})",
        info.name, info.device_type, info.driver, info.driver_info
    )
}

/// The Vulkan adapter the backend would use, described, or why there is none.
///
/// # Errors
/// [`GpuError::NoAdapter`] or [`GpuError::Device`].
pub fn adapter_info() -> Result<String, GpuError> {
    Device::open().map(|d| d.describe())
}
