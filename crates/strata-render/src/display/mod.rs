//! The 8-bit display image of a target, made on the GPU.
//!
//! `strata view` shows the bytes a PNG of the frame would hold ([`ImageBuf::to_rgba8`]).
//! Reading the target back and encoding it on the CPU every frame costs a GPU→CPU copy,
//! a wait for the GPU and an upload; [`DisplayEncoder`] writes the same bytes into a
//! texture that the window draws directly.
//!
//! Exactness: the CPU encoding of a channel is a monotone step function of its f32
//! value. [`thresholds`] finds, for each byte k in 1..=255, the smallest f32 the CPU
//! encodes to k or more, and the shader counts the thresholds at or below its value
//! ([`encode_cpu`] is its twin). 8-bit targets are read as their raw bytes and decoded
//! through the CPU's own table. So GPU and CPU agree byte for byte, not within a
//! rounding tolerance (test `display_encoder_equals_to_rgba8`).
//!
//! [`ImageBuf::to_rgba8`]: strata_scene::image_buf::ImageBuf::to_rgba8

use crate::gpu::GpuContext;
use crate::RenderError;
pub use strata_scene::image_buf::to_byte;

/// For k = 1..=255 (index k − 1), the smallest f32 that [`to_byte`] encodes to k or more.
/// Found by bisection over the bit patterns of [0, 1], which order like the values.
pub fn thresholds(srgb: bool) -> [f32; 255] {
    let mut t = [0.0f32; 255];
    for (i, t) in t.iter_mut().enumerate() {
        let k = i as u8 + 1;
        // the answer lies in (lo, hi]: to_byte(lo) < k <= to_byte(hi)
        let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if to_byte(f32::from_bits(mid), srgb) >= k {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        *t = f32::from_bits(hi);
    }
    t
}

/// The shader's encoding on the CPU: how many of `t` lie at or below `v`.
pub fn encode_cpu(v: f32, t: &[f32; 255]) -> u8 {
    t.iter().filter(|&&t| t <= v).count() as u8
}

/// How the CPU decodes `format` for display: the channels of its `ImageBuf`, and for
/// 8-bit formats the value of each byte.
fn layout_of(format: wgpu::TextureFormat) -> Option<(u32, Option<[f32; 256]>)> {
    use wgpu::TextureFormat as F;
    let table = |f: fn(u8) -> f32| {
        let mut t = [0.0f32; 256];
        t.iter_mut().enumerate().for_each(|(b, v)| *v = f(b as u8));
        t
    };
    Some(match format {
        F::R32Float | F::R16Float => (1, None),
        F::Rg32Float => (2, None),
        F::Rg11b10Ufloat => (3, None),
        F::Rgba16Float | F::Rgba32Float => (4, None),
        F::Rgba8Unorm => (4, Some(table(|b| b as f32 / 255.0))),
        F::Rgba8UnormSrgb => (4, Some(table(strata_scene::model::srgb_to_linear))),
        _ => return None,
    })
}

/// Whether [`DisplayEncoder::encode`] takes a texture of `format`. An 8-bit sRGB texture
/// also needs `Rgba8Unorm` among its view formats (strata's targets have it).
pub fn supports(format: wgpu::TextureFormat) -> bool {
    layout_of(format).is_some()
}

/// The part of a texture to show: array layer `layer`, `size` texels from `origin`
/// ([`crate::Renderer::display_region`] gives a target's image inside its guard band).
#[derive(Clone, Copy, Debug)]
pub struct Region<'a> {
    pub texture: &'a wgpu::Texture,
    pub layer: u32,
    pub origin: [u32; 2],
    pub size: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    origin: [u32; 2],
    size: [u32; 2],
    gain: f32,
    channels: u32,
    bytes: u32,
    srgb: u32,
}

/// Writes the display bytes of a target region into an `Rgba8Unorm` texture (alpha 255),
/// which a window can draw (egui samples `Rgba8Unorm` as gamma-encoded bytes).
pub struct DisplayEncoder {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    thresholds: wgpu::Buffer,
    decode: wgpu::Buffer,
    params: wgpu::Buffer,
    output: Option<(wgpu::Texture, wgpu::TextureView)>,
    decode_of: Option<wgpu::TextureFormat>,
}

impl DisplayEncoder {
    pub fn new(gpu: &GpuContext) -> Self {
        let d = &gpu.device;
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty,
            count: None,
        };
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display-encode"),
            entries: &[
                entry(
                    0,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                entry(
                    1,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
                entry(2, storage),
                entry(
                    3,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
                entry(
                    4,
                    wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: wgpu::TextureFormat::Rgba8Unorm,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                ),
            ],
        });
        let module = crate::shader::module(d, "display-encode", include_str!("display.wgsl"));
        let pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("display-encode"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("display-encode"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let buffer = |label, size, usage| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: usage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let thresholds = buffer("display thresholds", 512 * 4, wgpu::BufferUsages::UNIFORM);
        let mut table: Vec<f32> = [thresholds_of(false), thresholds_of(true)].concat();
        table.resize(512, f32::INFINITY);
        gpu.queue.write_buffer(&thresholds, 0, bytemuck::cast_slice(&table));
        DisplayEncoder {
            pipeline,
            layout,
            thresholds,
            decode: buffer("display decode", 256 * 4, wgpu::BufferUsages::STORAGE),
            params: buffer(
                "display params",
                std::mem::size_of::<Params>() as u64,
                wgpu::BufferUsages::UNIFORM,
            ),
            output: None,
            decode_of: None,
        }
    }

    /// Encodes `region` (as `ImageBuf::to_rgba8(srgb)` of its values times `gain`, alpha
    /// 255) and returns the output texture, the region's size. The work is submitted;
    /// nothing waits for it.
    pub fn encode(
        &mut self,
        gpu: &GpuContext,
        region: &Region<'_>,
        srgb: bool,
        gain: f32,
    ) -> Result<&wgpu::Texture, RenderError> {
        let Region {
            texture: src,
            layer,
            origin,
            size,
        } = *region;
        let format = src.format();
        let (channels, table) = layout_of(format)
            .ok_or_else(|| RenderError::Parameter(format!("display: a {format:?} texture cannot be shown")))?;
        if size[0] == 0
            || size[1] == 0
            || origin[0] + size[0] > src.width()
            || origin[1] + size[1] > src.height()
            || layer >= src.depth_or_array_layers()
        {
            return Err(RenderError::Parameter(format!(
                "display: region {size:?} at {origin:?}, layer {layer}, is outside the {}×{}×{} texture",
                src.width(),
                src.height(),
                src.depth_or_array_layers()
            )));
        }
        if let Some(t) = table.as_ref().filter(|_| self.decode_of != Some(format)) {
            gpu.queue
                .write_buffer(&self.decode, 0, bytemuck::cast_slice(t.as_slice()));
            self.decode_of = Some(format);
        }
        let params = Params {
            origin,
            size,
            gain,
            channels,
            bytes: table.is_some() as u32,
            srgb: srgb as u32,
        };
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        if self
            .output
            .as_ref()
            .is_none_or(|(t, _)| [t.width(), t.height()] != size)
        {
            let t = gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("display"),
                size: wgpu::Extent3d {
                    width: size[0],
                    height: size[1],
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8Unorm,
                usage: wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            let v = t.create_view(&Default::default());
            self.output = Some((t, v));
        }
        let (out, out_view) = self.output.as_ref().expect("made above");
        let src_view = src.create_view(&wgpu::TextureViewDescriptor {
            label: Some("display source"),
            // 8-bit sRGB: the raw bytes, decoded by the CPU's table
            format: table.is_some().then_some(wgpu::TextureFormat::Rgba8Unorm),
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: layer,
            array_layer_count: Some(1),
            base_mip_level: 0,
            mip_level_count: Some(1),
            ..Default::default()
        });
        let bg = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("display-encode"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&src_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: self.thresholds.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.decode.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(out_view),
                },
            ],
        });
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("display-encode"),
        });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("display-encode"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(size[0].div_ceil(8), size[1].div_ceil(8), 1);
        }
        gpu.queue.submit([enc.finish()]);
        Ok(out)
    }

    /// The last output and its view, if any.
    pub fn output(&self) -> Option<(&wgpu::Texture, &wgpu::TextureView)> {
        self.output.as_ref().map(|(t, v)| (t, v))
    }
}

/// [`thresholds`] computed once per encoding (each is 255 bisections of ~30 steps).
fn thresholds_of(srgb: bool) -> Vec<f32> {
    static T: std::sync::OnceLock<[[f32; 255]; 2]> = std::sync::OnceLock::new();
    T.get_or_init(|| [thresholds(false), thresholds(true)])[srgb as usize].to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The threshold count is `to_byte` itself: at each threshold, just below it, and on
    /// values spread over [−0.1, 1.1] plus the special values.
    #[test]
    fn threshold_count_equals_the_cpu_encoding() {
        for srgb in [false, true] {
            let t = thresholds(srgb);
            assert!(t.windows(2).all(|w| w[0] < w[1]), "sorted");
            for (i, &x) in t.iter().enumerate() {
                let k = i as u8 + 1;
                assert_eq!(to_byte(x, srgb), k, "threshold {k} (srgb {srgb})");
                let below = f32::from_bits(x.to_bits() - 1);
                assert_eq!(to_byte(below, srgb), k - 1, "just below threshold {k} (srgb {srgb})");
                assert_eq!(encode_cpu(x, &t), k);
                assert_eq!(encode_cpu(below, &t), k - 1);
            }
            let mut state = 0x9e37_79b9u32;
            for _ in 0..200_000 {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                let v = state as f32 / u32::MAX as f32 * 1.2 - 0.1;
                assert_eq!(encode_cpu(v, &t), to_byte(v, srgb), "v = {v:e} (srgb {srgb})");
            }
            for v in [
                f32::NAN,
                f32::INFINITY,
                f32::NEG_INFINITY,
                -0.0,
                0.0,
                1.0,
                f32::MIN_POSITIVE,
                1e-30,
            ] {
                assert_eq!(encode_cpu(v, &t), to_byte(v, srgb), "v = {v} (srgb {srgb})");
            }
        }
    }
}
