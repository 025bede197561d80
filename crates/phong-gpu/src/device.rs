//! The device: opening the adapter, its limits and features, and how GPU errors become
//! [`Error`](enum@Error)s (error scopes around each piece of work, a sink for uncaptured errors and device
//! loss).

use crate::{Error, Gpu, GpuPath, ITEM_CAPACITY, RENDER_WGSL};
use std::collections::HashMap;
use std::sync::Mutex;

fn storage_entry(binding: u32, read_only: bool, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// Error scopes around GPU work: what they catch becomes [`Error::Failed`] ([`Gpu::check`]).
pub(crate) struct Scopes {
    out_of_memory: wgpu::ErrorScopeGuard,
    validation: wgpu::ErrorScopeGuard,
}

impl Gpu {
    pub(crate) fn scopes(&self) -> Scopes {
        Scopes {
            out_of_memory: self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory),
            validation: self.device.push_error_scope(wgpu::ErrorFilter::Validation),
        }
    }

    /// Pops `scopes` (the last pushed first): a validation or out-of-memory error while
    /// `doing` is an error.
    pub(crate) fn check(&self, scopes: Scopes, doing: &'static str) -> Result<(), Error> {
        if let Some(e) = pollster::block_on(scopes.validation.pop()) {
            return Err(self.fail(doing, e.to_string()));
        }
        if let Some(e) = pollster::block_on(scopes.out_of_memory.pop()) {
            return Err(self.fail(doing, format!("out of memory: {e}")));
        }
        Ok(())
    }

    /// Opens the first adapter wgpu finds (high performance preferred); `WGPU_BACKEND` and
    /// `WGPU_ADAPTER_NAME` select another, as wgpu documents.
    pub fn new() -> Result<Gpu, Error> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| Error::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("phong"),
            required_limits: limits.clone(),
            // Timestamps time the render pass on the GPU itself, where the adapter has them.
            // and 64-bit integers and atomics make the compute rasterizer.
            required_features: adapter.features()
                & (wgpu::Features::TIMESTAMP_QUERY
                    | wgpu::Features::SHADER_INT64
                    | wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX),
            ..Default::default()
        }))
        .map_err(|e| Error::Device {
            adapter: info.name.clone(),
            reason: e.to_string(),
        })?;
        // Errors are caught with error scopes around each render; anything else is recorded
        // here instead of wgpu's default panic, and reported by the next render.
        let lost = std::sync::Arc::new(Mutex::new(None));
        let sink = lost.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            *sink.lock().unwrap_or_else(|p| p.into_inner()) = Some(e.to_string());
        }));
        let sink = lost.clone();
        device.set_device_lost_callback(move |_, msg| {
            *sink.lock().unwrap_or_else(|p| p.into_inner()) = Some(format!("device lost: {msg}"));
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("phong render"),
            source: wgpu::ShaderSource::Wgsl(RENDER_WGSL.into()),
        });
        let both = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("phong frame"),
            entries: &[
                uniform_entry(0, both),
                storage_entry(1, true, both),
                storage_entry(2, true, both),
            ],
        });
        let maps_layout = crate::textures::maps_layout(&device);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("phong"),
            bind_group_layouts: &[Some(&layout), Some(&maps_layout)],
            immediate_size: 0,
        });
        Ok(Gpu {
            device,
            queue,
            info,
            limits,
            module,
            layout,
            maps_layout,
            pipeline_layout,
            pipelines: Mutex::new(HashMap::new()),
            textures: Mutex::new(Vec::new()),
            kernels: std::sync::OnceLock::new(),
            path: GpuPath::Auto,
            item_capacity: ITEM_CAPACITY,
            lost,
        })
    }

    /// The adapter's name and backend, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan)".
    pub fn adapter_name(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    /// Chooses how frames are drawn from now on (default [`GpuPath::Auto`]).
    pub fn set_path(&mut self, path: GpuPath) {
        self.path = path;
    }

    /// Sets the compute rasterizer's tile item capacity (for tests of its overflow).
    #[doc(hidden)]
    pub fn set_item_capacity(&mut self, items: u32) {
        self.item_capacity = items.max(1);
    }

    /// Whether the adapter runs on the CPU (Mesa's lavapipe): [`GpuPath::Auto`] takes the
    /// pipeline there.
    pub fn is_cpu_adapter(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// The largest storage buffer binding the device allows, in bytes.
    pub fn max_storage_bytes(&self) -> u64 {
        self.limits
            .max_buffer_size
            .min(self.limits.max_storage_buffer_binding_size)
    }

    /// Whether renders time their pass on the GPU ([`GpuStats::gpu_pass`](crate::GpuStats::gpu_pass)): the adapter has
    /// timestamp queries.
    pub fn has_timestamps(&self) -> bool {
        self.device.features().contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    pub(crate) fn fail(&self, doing: &'static str, reason: String) -> Error {
        Error::Failed {
            doing,
            adapter: self.info.name.clone(),
            reason,
        }
    }

    pub(crate) fn check_lost(&self, doing: &'static str) -> Result<(), Error> {
        match self.lost.lock().unwrap_or_else(|p| p.into_inner()).take() {
            Some(reason) => Err(self.fail(doing, reason)),
            None => Ok(()),
        }
    }

    pub(crate) fn wait(&self, doing: &'static str) -> Result<(), Error> {
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: None,
                timeout: None,
            })
            .map_err(|e| self.fail(doing, e.to_string()))?;
        self.check_lost(doing)
    }

    pub(crate) fn check_limit(&self, what: &'static str, asked: u64, limit: u64) -> Result<(), Error> {
        if asked > limit {
            return Err(Error::Limit {
                what,
                asked,
                limit,
                adapter: self.info.name.clone(),
            });
        }
        Ok(())
    }
}
