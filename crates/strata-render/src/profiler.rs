//! GPU timestamp profiler: one begin/end timestamp pair per named pass, resolved
//! to milliseconds after the frame.

use crate::gpu::GpuContext;

/// Milliseconds of GPU time per pass of one frame, in pass order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PassTimings {
    pub passes: Vec<(String, f64)>,
}

impl PassTimings {
    pub fn get(&self, name: &str) -> Option<f64> {
        self.passes.iter().find(|(n, _)| n == name).map(|(_, t)| *t)
    }
    pub fn total(&self) -> f64 {
        self.passes.iter().map(|(_, t)| t).sum()
    }
}

/// Writes timestamps between passes of a command encoder (needs
/// `TIMESTAMP_QUERY_INSIDE_ENCODERS`); disabled (no timings) without it.
pub struct Profiler {
    query_set: Option<wgpu::QuerySet>,
    resolve: Option<wgpu::Buffer>,
    readback: Option<wgpu::Buffer>,
    capacity: u32,
    /// Pass names of the current frame (interior mutability: passes borrow the renderer).
    names: std::cell::RefCell<Vec<String>>,
    period_ns: f64,
}

impl Profiler {
    pub fn new(gpu: &GpuContext, max_passes: u32) -> Self {
        let enabled = gpu.has(wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);
        let capacity = max_passes * 2;
        let (query_set, resolve, readback) = if enabled {
            let qs = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: capacity,
            });
            let size = capacity as u64 * 8;
            let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp readback"),
                size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            (Some(qs), Some(resolve), Some(readback))
        } else {
            (None, None, None)
        };
        Self {
            query_set,
            resolve,
            readback,
            capacity,
            names: Default::default(),
            period_ns: gpu.queue.get_timestamp_period() as f64,
        }
    }

    pub fn enabled(&self) -> bool {
        self.query_set.is_some()
    }

    /// Starts a new frame's measurements.
    pub fn reset(&self) {
        self.names.borrow_mut().clear();
    }

    /// Marks the start of pass `name`; returns its slot for [`Profiler::end`].
    pub fn begin(&self, encoder: &mut wgpu::CommandEncoder, name: &str) -> Option<u32> {
        let qs = self.query_set.as_ref()?;
        let mut names = self.names.borrow_mut();
        let slot = names.len() as u32;
        if (slot + 1) * 2 > self.capacity {
            return None;
        }
        names.push(name.to_string());
        encoder.write_timestamp(qs, slot * 2);
        Some(slot)
    }

    pub fn end(&self, encoder: &mut wgpu::CommandEncoder, slot: Option<u32>) {
        if let (Some(qs), Some(s)) = (self.query_set.as_ref(), slot) {
            encoder.write_timestamp(qs, s * 2 + 1);
        }
    }

    /// Copies this frame's queries into the read-back buffer (call before `finish`).
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let (Some(qs), Some(r), Some(rb)) = (&self.query_set, &self.resolve, &self.readback) {
            let n = self.names.borrow().len() as u32 * 2;
            if n > 0 {
                encoder.resolve_query_set(qs, 0..n, r, 0);
                encoder.copy_buffer_to_buffer(r, 0, rb, 0, n as u64 * 8);
            }
        }
    }

    /// Reads the frame's timings (after the encoder was submitted).
    pub fn read(&self, gpu: &GpuContext) -> Result<PassTimings, crate::RenderError> {
        let Some(rb) = &self.readback else {
            return Ok(PassTimings::default());
        };
        let names = self.names.borrow();
        if names.is_empty() {
            return Ok(PassTimings::default());
        }
        let bytes = gpu.read_buffer(rb)?;
        let ticks: &[u64] = bytemuck::cast_slice(&bytes);
        let passes = names
            .iter()
            .enumerate()
            .map(|(i, n)| {
                let dt = ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64 * self.period_ns * 1e-6;
                (n.clone(), dt)
            })
            .collect();
        Ok(PassTimings { passes })
    }
}
