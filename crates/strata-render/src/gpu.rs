//! Headless wgpu context: adapter choice, feature detection, validation-error
//! capture and read-back helpers.

use std::sync::{Arc, Mutex};

use crate::RenderError;

pub use wgpu::Features;

/// Features strata uses, with whether each is required by some pass.
pub const STRATA_FEATURES: &[(&str, wgpu::Features, &str)] = &[
    (
        "MULTIVIEW",
        wgpu::Features::MULTIVIEW,
        "single-pass deep G-buffer (both layers in one geometry pass)",
    ),
    (
        "TIMESTAMP_QUERY",
        wgpu::Features::TIMESTAMP_QUERY,
        "per-pass GPU timings",
    ),
    (
        "TIMESTAMP_QUERY_INSIDE_ENCODERS",
        wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS,
        "timestamps between passes",
    ),
    (
        "TIMESTAMP_QUERY_INSIDE_PASSES",
        wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES,
        "timestamps inside passes",
    ),
    (
        "SHADER_INT64",
        wgpu::Features::SHADER_INT64,
        "64-bit fragment-list heads (A-buffer)",
    ),
    (
        "SHADER_INT64_ATOMIC_MIN_MAX",
        wgpu::Features::SHADER_INT64_ATOMIC_MIN_MAX,
        "64-bit atomics (the bounced z-buffer's compute splats)",
    ),
    ("TEXTURE_ATOMIC", wgpu::Features::TEXTURE_ATOMIC, "R32 texture atomics"),
    ("SUBGROUP", wgpu::Features::SUBGROUP, "subgroup reductions"),
    ("SHADER_F16", wgpu::Features::SHADER_F16, "half-precision shading"),
    (
        "RG11B10UFLOAT_RENDERABLE",
        wgpu::Features::RG11B10UFLOAT_RENDERABLE,
        "R11G11B10 radiosity/emission targets",
    ),
    (
        "FLOAT32_FILTERABLE",
        wgpu::Features::FLOAT32_FILTERABLE,
        "filtered camera-space depth",
    ),
    (
        "TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES",
        wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES,
        "compute passes writing R16F / RG11B10 targets (storage textures)",
    ),
];

/// Options for [`GpuContext::new`].
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// Substring of the adapter name to pick (case-insensitive); also read from `STRATA_ADAPTER`.
    pub adapter: Option<String>,
}

/// The device plus everything passes need to know about it.
pub struct GpuContext {
    /// The instance the device was opened from; `None` for an application's device
    /// ([`GpuContext::from_device`]).
    pub instance: Option<wgpu::Instance>,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub features: wgpu::Features,
    errors: Arc<Mutex<Vec<String>>>,
}

impl GpuContext {
    /// Opens a headless device on Vulkan (falling back to any backend wgpu finds),
    /// requesting every feature in [`STRATA_FEATURES`] the adapter has.
    pub fn new(opts: &GpuOptions) -> Result<Self, RenderError> {
        Self::with_instance(opts, Self::instance(), None)
    }

    /// The instance [`GpuContext::new`] opens its device from (Vulkan first). A window
    /// creates its surface from it and passes both to [`GpuContext::with_instance`].
    pub fn instance() -> wgpu::Instance {
        if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            // Mesa's loaders warn loudly without it; a private tmp dir is enough headless.
            let dir = std::env::temp_dir().join("strata-xdg");
            let _ = std::fs::create_dir_all(&dir);
            // SAFETY-free in practice: set before any thread of ours reads the environment.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", dir) };
        }
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        if std::env::var_os("WGPU_BACKEND").is_none() {
            desc.backends = wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12;
        }
        wgpu::Instance::new(desc)
    }

    /// Like [`GpuContext::new`] on `instance`; with `compatible`, only adapters that can
    /// present to that surface (created from `instance`) are considered.
    pub fn with_instance(
        opts: &GpuOptions,
        instance: wgpu::Instance,
        compatible: Option<&wgpu::Surface<'_>>,
    ) -> Result<Self, RenderError> {
        let wanted = opts.adapter.clone().or_else(|| std::env::var("STRATA_ADAPTER").ok());
        let mut adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        if let Some(s) = compatible {
            adapters.retain(|a| a.is_surface_supported(s));
        }
        if adapters.is_empty() {
            return Err(RenderError::NoAdapter(
                "no GPU adapter found: install a Vulkan driver (run scripts/setup.sh; on Debian it installs mesa-vulkan-drivers and libvulkan1)"
                    .into(),
            ));
        }
        let adapter = match &wanted {
            Some(w) => {
                let wl = w.to_lowercase();
                let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
                adapters
                    .into_iter()
                    .find(|a| a.get_info().name.to_lowercase().contains(&wl))
                    .ok_or_else(|| {
                        RenderError::NoAdapter(format!(
                            "--adapter '{w}' matches no adapter; available: {}",
                            names.join(", ")
                        ))
                    })?
            }
            None => {
                // Prefer a real GPU, then anything (lavapipe is a CPU adapter).
                let mut sorted = adapters;
                sorted.sort_by_key(|a| match a.get_info().device_type {
                    wgpu::DeviceType::DiscreteGpu => 0,
                    wgpu::DeviceType::IntegratedGpu => 1,
                    wgpu::DeviceType::VirtualGpu => 2,
                    wgpu::DeviceType::Cpu => 3,
                    wgpu::DeviceType::Other => 4,
                });
                sorted.into_iter().next().expect("non-empty")
            }
        };
        let available = adapter.features();
        let mut features = wgpu::Features::empty();
        for (_, f, _) in STRATA_FEATURES {
            if available.contains(*f) {
                features |= *f;
            }
        }
        let alimits = adapter.limits();
        let limits = wgpu::Limits {
            max_texture_dimension_2d: alimits.max_texture_dimension_2d,
            max_texture_array_layers: alimits.max_texture_array_layers,
            max_storage_buffer_binding_size: alimits.max_storage_buffer_binding_size,
            max_buffer_size: alimits.max_buffer_size,
            max_bind_groups: alimits.max_bind_groups.min(8),
            max_color_attachments: alimits.max_color_attachments,
            max_color_attachment_bytes_per_sample: alimits.max_color_attachment_bytes_per_sample,
            max_multiview_view_count: alimits.max_multiview_view_count,
            ..wgpu::Limits::default()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("strata"),
            required_features: features,
            required_limits: limits,
            ..Default::default()
        }))
        .map_err(|e| RenderError::NoAdapter(format!("cannot open device: {e}")))?;
        if let Some(w) = known_driver_issue(&adapter.get_info()) {
            tracing::warn!("{w}");
        }
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().unwrap_or_else(|p| p.into_inner()).push(e.to_string());
        }));
        // A lost device (driver reset, destroyed) becomes an error of the next check, not a hang.
        let lost = errors.clone();
        device.set_device_lost_callback(move |reason, message| {
            lost.lock()
                .unwrap_or_else(|p| p.into_inner())
                .push(format!("the GPU device was lost ({reason:?}): {message}"));
        });
        Ok(Self {
            instance: Some(instance),
            adapter,
            device,
            queue,
            features,
            errors,
        })
    }

    /// Wraps an application's device (`strata_render::embed`): its features are the ones
    /// the application requested, and its errors go to the application's handler and
    /// error scopes, so [`GpuContext::check_errors`] reports none.
    pub fn from_device(adapter: &wgpu::Adapter, device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        Self {
            instance: None,
            adapter: adapter.clone(),
            device: device.clone(),
            queue: queue.clone(),
            features: device.features(),
            errors: Arc::new(Mutex::new(Vec::new())),
        }
    }

    /// A known defect of this adapter's driver that affects strata (see [`known_driver_issue`]).
    pub fn driver_issue(&self) -> Option<String> {
        known_driver_issue(&self.adapter.get_info())
    }

    /// Errors if `feature` is missing, naming it and the pass that needs it.
    pub fn require(&self, feature: wgpu::Features, pass: &str) -> Result<(), RenderError> {
        if self.features.contains(feature) {
            Ok(())
        } else {
            let name = STRATA_FEATURES
                .iter()
                .find(|(_, f, _)| *f == feature)
                .map(|(n, _, _)| *n)
                .unwrap_or("?");
            Err(RenderError::MissingFeature {
                feature: name.to_string(),
                pass: pass.to_string(),
            })
        }
    }

    pub fn has(&self, feature: wgpu::Features) -> bool {
        self.features.contains(feature)
    }

    /// Waits for the GPU and returns every validation error wgpu reported since the
    /// last check (tests fail on any).
    pub fn check_errors(&self) -> Result<(), RenderError> {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
        let mut errs = self.errors.lock().unwrap_or_else(|p| p.into_inner());
        if errs.is_empty() {
            Ok(())
        } else {
            let all = errs.drain(..).collect::<Vec<_>>().join("\n");
            Err(RenderError::Validation(all))
        }
    }

    /// Adapter description for `strata info` and benchmark records.
    pub fn describe(&self) -> String {
        let i = self.adapter.get_info();
        format!("{} ({:?}, {} {})", i.name, i.backend, i.driver, i.driver_info)
    }

    /// Reads a whole 2D texture (one array layer, mip 0) back as raw texel bytes, rows tightly packed.
    pub fn read_texture(&self, texture: &wgpu::Texture, layer: u32) -> Result<Vec<u8>, RenderError> {
        self.read_texture_level(texture, layer, 0)
    }

    /// Reads MIP level `mip` of one array layer (its size is the level's size).
    pub fn read_texture_level(&self, texture: &wgpu::Texture, layer: u32, mip: u32) -> Result<Vec<u8>, RenderError> {
        let fmt = texture.format();
        let bpp = fmt
            .block_copy_size(Some(wgpu::TextureAspect::All))
            .or_else(|| fmt.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)))
            .ok_or_else(|| RenderError::Other(format!("cannot read back format {fmt:?}")))?;
        let (w, h) = ((texture.width() >> mip).max(1), (texture.height() >> mip).max(1));
        let row = w * bpp;
        let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buf = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: (padded * h) as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let aspect = if fmt.is_depth_stencil_format() {
            wgpu::TextureAspect::DepthOnly
        } else {
            wgpu::TextureAspect::All
        };
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: mip,
                origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
                aspect,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buf,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        self.queue.submit([enc.finish()]);
        let bytes = self.read_buffer(&buf)?;
        let mut out = Vec::with_capacity((row * h) as usize);
        for y in 0..h {
            let s = (y * padded) as usize;
            out.extend_from_slice(&bytes[s..s + row as usize]);
        }
        Ok(out)
    }

    /// Copies a COPY_SRC (storage) buffer into a fresh staging buffer and reads it.
    pub fn read_storage(&self, buf: &wgpu::Buffer) -> Result<Vec<u8>, RenderError> {
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: buf.size(),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(buf, 0, &staging, 0, buf.size());
        self.queue.submit([enc.finish()]);
        self.read_buffer(&staging)
    }

    /// Maps a MAP_READ buffer and copies it out.
    pub fn read_buffer(&self, buf: &wgpu::Buffer) -> Result<Vec<u8>, RenderError> {
        let (tx, rx) = std::sync::mpsc::channel();
        buf.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
        rx.recv()
            .map_err(|_| RenderError::Other("buffer map callback never ran".into()))?
            .map_err(|e| RenderError::Other(format!("buffer map failed: {e}")))?;
        let data = buf
            .get_mapped_range(..)
            .map_err(|e| RenderError::Other(format!("{e}")))?
            .to_vec();
        buf.unmap();
        self.check_errors()?;
        Ok(data)
    }
}

/// The Mesa version in a driver string such as "Mesa 22.3.6" or
/// "Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)": (major, minor).
pub fn mesa_version(driver_info: &str) -> Option<(u32, u32)> {
    let rest = &driver_info[driver_info.find("Mesa ")? + 5..];
    let mut parts = rest.split(|c: char| !c.is_ascii_digit());
    let major = parts.next()?.parse().ok()?;
    let minor = parts.next()?.parse().ok()?;
    Some((major, minor))
}

/// Driver defects that change what strata does, as a one-line warning.
///
/// lavapipe from Mesa 22.x (Debian 12's) leaks about 1 KB per triangle drawn by a
/// deep-G-buffer pass of layer >= 1 whose fragment shader reads the depth oracle
/// at a computed position (about 5 MB per frame on `atrium` with two layers);
/// Mesa 25.0 does not (docs/reliability.md).
pub fn known_driver_issue(info: &wgpu::AdapterInfo) -> Option<String> {
    let lavapipe = info.device_type == wgpu::DeviceType::Cpu && info.name.contains("llvmpipe");
    lavapipe_issue(lavapipe, &info.driver_info)
}

fn lavapipe_issue(lavapipe: bool, driver_info: &str) -> Option<String> {
    match mesa_version(driver_info) {
        Some((major, _)) if lavapipe && major < 23 => Some(format!(
            "lavapipe from Mesa {major}.x leaks about 1 KB per triangle of every deep-G-buffer layer >= 1 \
             (memory grows each frame with --layers >= 2); run scripts/setup.sh to install Mesa 25 \
             (docs/reliability.md)"
        )),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesa_versions_parse() {
        assert_eq!(mesa_version("Mesa 22.3.6 (LLVM 15.0.6)"), Some((22, 3)));
        assert_eq!(mesa_version("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"), Some((25, 0)));
        assert_eq!(mesa_version("NVIDIA 550.1"), None);
    }

    #[test]
    fn leaky_lavapipe_is_flagged() {
        assert!(lavapipe_issue(true, "Mesa 22.3.6 (LLVM 15.0.6)").is_some());
        assert!(lavapipe_issue(true, "Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)").is_none());
        assert!(lavapipe_issue(false, "Mesa 22.3.6").is_none());
    }
}
