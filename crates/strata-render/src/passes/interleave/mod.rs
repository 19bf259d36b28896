//! Buffer splitting (BS) and buffer gathering (BG) of interleaved deferred
//! shading (Segovia, Iehl, Mitanchey, Péroche 2006, "ILS" below): the passes
//! that turn a W×H buffer into n×m tiled sub-buffers and back, for any
//! float-sampled texture format that is a render target (fragment methods) or a
//! storage texture (compute method).
//!
//! # Layout (§3.2)
//!
//! Texel (x, y) of the W×H *image* goes to sub-buffer (i, j) = (x mod n, y mod m)
//! at its local texel (x div n, y div m). The n×m sub-buffers are tiled in one
//! *tiled buffer* of [`InterleaveGeometry::tiled_size`] = (n·⌈W/n⌉, m·⌈H/m⌉)
//! texels: sub-buffer (i, j) occupies the tile at (i·⌈W/n⌉, j·⌈H/m⌉) of size
//! ⌈W/n⌉×⌈H/m⌉. When W or H is divisible by n or m the tiled buffer has the
//! image's size, as in the paper (§4.2).
//!
//! # Padding
//!
//! When n ∤ W or m ∤ H, the last local column (row) of some sub-buffers has no
//! image texel. These *padding* texels hold the padding marker, by default
//! [`PADDING_MARKER`] = (0, 0, 0, 0): all bits zero in every format (strata's
//! camera-space depth targets read 0 as "no surface"); a shading pass on the
//! sub-buffers may skip them. [`Interleave::set_padding`] changes it. Every
//! method writes the marker explicitly (never relies on a clear), and gathering
//! reads only the texels of image texels, so padding never reaches a gathered
//! image.
//!
//! # Methods ([`SplitMethod`]), all bit-identical
//!
//! - [`SplitMethod::Naive`]: one fragment pass reading each output texel
//!   through its index (§3.2; Table 1's incoherent baseline).
//! - [`SplitMethod::Blocks`]: the paper's two passes (§3.3, Fig. 2): *block
//!   splitting* inside blocks of `block`×`block` texels into n×m sub-blocks,
//!   then *block translation* of the sub-blocks to their sub-buffers; BG runs
//!   the inverse block translation then *block gathering* (§3.4). Needs a
//!   [`InterleaveGeometry::block_split_size`] intermediate texture (owned here).
//! - [`SplitMethod::Compute`]: one compute pass whose workgroups read an image
//!   region coherently into workgroup memory and write each sub-buffer's part
//!   contiguously (and the reverse for BG).
//!
//! Every method copies texels through `textureLoad`/store as f32, which is exact
//! for the accepted formats (unorm8, f16, f32) except that NaN payloads may be
//! canonicalised by the driver. Formats whose round trip through f32 is not
//! exact (sRGB, snorm's −128) are refused.
//!
//! The index maths lives once in WGSL (`shaders/common/interleave.wgsl`); its
//! CPU twin is [`InterleaveGeometry`]. Each pass has a profiler label
//! ([`labels`]) for [`Interleave::split_profiled`] / [`Interleave::gather_profiled`].
//!
//! ```ignore
//! let ils = Interleave::new(gpu, wgpu::TextureFormat::Rgba16Float, 1024, 768, 8, 6,
//!                           SplitMethod::Blocks { block: 16 })?;
//! let tiled = ils.create_tiled_texture("normals-split");
//! ils.split(&mut encoder, &normals_view, &tiled.create_view(&Default::default()))?;
//! // … shade each sub-buffer in its tile: ils.geometry().tile_origin(i, j) …
//! ils.gather(&mut encoder, &irradiance_tiled_view, &irradiance_view)?;
//! ```

pub mod bench;

use crate::gpu::GpuContext;
use crate::profiler::Profiler;
use crate::RenderError;

/// Largest interleaving pattern side (n, m ≤ 16).
pub const MAX_PATTERN: u32 = 16;
/// Largest block side of [`SplitMethod::Blocks`].
pub const MAX_BLOCK: u32 = 1024;
/// Default value of padding texels: all components 0 (all bits zero in every format).
pub const PADDING_MARKER: [f32; 4] = [0.0; 4];
/// Image texels per side of one compute workgroup's region (n·a, m·b ≤ this).
const COMPUTE_REGION: u32 = 32;

/// Profiler labels of the BS/BG passes, one per pass (`strata bench` reads them).
pub mod labels {
    /// BS, one pass (§3.2).
    pub const BS_NAIVE: &str = "ils-bs-naive";
    /// BS pass 1: block splitting (§3.3).
    pub const BS_BLOCK_SPLITTING: &str = "ils-bs-block-splitting";
    /// BS pass 2: block translation (§3.3).
    pub const BS_BLOCK_TRANSLATION: &str = "ils-bs-block-translation";
    /// BS, compute.
    pub const BS_COMPUTE: &str = "ils-bs-compute";
    /// BG, one pass.
    pub const BG_NAIVE: &str = "ils-bg-naive";
    /// BG pass 1: block translation back to the block-split layout (§3.4).
    pub const BG_BLOCK_TRANSLATION: &str = "ils-bg-block-translation";
    /// BG pass 2: block gathering (§3.4).
    pub const BG_BLOCK_GATHERING: &str = "ils-bg-block-gathering";
    /// BG, compute.
    pub const BG_COMPUTE: &str = "ils-bg-compute";
}

/// How BS and BG are done; all methods produce identical bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SplitMethod {
    /// One fragment pass reading through a per-texel index (§3.2, Table 1's baseline).
    Naive,
    /// Two fragment passes (§3.3, Fig. 2): block splitting inside `block`×`block`
    /// blocks, then block translation. `block` must be a power of two, at least
    /// n and m, at most [`MAX_BLOCK`]. When n (m) does not divide `block`, the
    /// block is widened to the next multiple of n (m) so that every sub-block is
    /// ⌈block/n⌉×⌈block/m⌉ texels (e.g. a 3×2 pattern with block 16: 18×16).
    Blocks { block: u32 },
    /// One compute pass with workgroup-memory staging and contiguous writes.
    Compute,
}

impl SplitMethod {
    /// Short name for tables: `naive`, `blocks-16`, `compute`.
    pub fn name(&self) -> String {
        match self {
            SplitMethod::Naive => "naive".into(),
            SplitMethod::Blocks { block } => format!("blocks-{block}"),
            SplitMethod::Compute => "compute".into(),
        }
    }

    /// The profiler labels of its BS passes, in order.
    pub fn split_labels(&self) -> &'static [&'static str] {
        match self {
            SplitMethod::Naive => &[labels::BS_NAIVE],
            SplitMethod::Blocks { .. } => &[labels::BS_BLOCK_SPLITTING, labels::BS_BLOCK_TRANSLATION],
            SplitMethod::Compute => &[labels::BS_COMPUTE],
        }
    }

    /// The profiler labels of its BG passes, in order.
    pub fn gather_labels(&self) -> &'static [&'static str] {
        match self {
            SplitMethod::Naive => &[labels::BG_NAIVE],
            SplitMethod::Blocks { .. } => &[labels::BG_BLOCK_TRANSLATION, labels::BG_BLOCK_GATHERING],
            SplitMethod::Compute => &[labels::BG_COMPUTE],
        }
    }
}

/// The smallest valid block side for an n×m pattern: the smallest power of two ≥ n, m.
pub fn min_block(n: u32, m: u32) -> u32 {
    n.max(m).next_power_of_two()
}

/// The sizes and index maps of one split: the CPU twin of
/// `shaders/common/interleave.wgsl` (the tests check the GPU against it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InterleaveGeometry {
    /// W, H of the interleaved image.
    pub width: u32,
    pub height: u32,
    /// The n×m interleaving pattern.
    pub n: u32,
    pub m: u32,
    /// Sub-buffer size ⌈W/n⌉ × ⌈H/m⌉.
    pub tile: [u32; 2],
    /// Sub-block size ⌈block/n⌉ × ⌈block/m⌉ ([1, 1] unless [`SplitMethod::Blocks`]).
    pub sub_block: [u32; 2],
    /// Block size n·sub_block.x × m·sub_block.y ([n, m] unless [`SplitMethod::Blocks`]).
    pub block: [u32; 2],
    /// Per-sub-buffer rectangle of one compute workgroup, a × b.
    pub group: [u32; 2],
}

impl InterleaveGeometry {
    /// Checks the parameters (one-line errors naming the parameter and its range).
    pub fn new(width: u32, height: u32, n: u32, m: u32, method: SplitMethod) -> Result<Self, String> {
        for (name, v) in [("n", n), ("m", m)] {
            if !(1..=MAX_PATTERN).contains(&v) {
                return Err(format!(
                    "interleave pattern {name} = {v} is out of range: must be in 1..={MAX_PATTERN}"
                ));
            }
        }
        if width == 0 || height == 0 {
            return Err(format!(
                "interleave image size {width}x{height} is out of range: width and height must be >= 1"
            ));
        }
        let tile = [width.div_ceil(n), height.div_ceil(m)];
        let (sub_block, block) = match method {
            SplitMethod::Blocks { block } => {
                let lo = min_block(n, m);
                if !block.is_power_of_two() || block < lo || block > MAX_BLOCK {
                    return Err(format!(
                        "block size {block} is not valid for the {n}x{m} pattern: must be a power of two in {lo}..={MAX_BLOCK}"
                    ));
                }
                let sb = [block.div_ceil(n), block.div_ceil(m)];
                (sb, [n * sb[0], m * sb[1]])
            }
            _ => ([1, 1], [n, m]),
        };
        let group = [(COMPUTE_REGION / n).max(1), (COMPUTE_REGION / m).max(1)];
        Ok(Self {
            width,
            height,
            n,
            m,
            tile,
            sub_block,
            block,
            group,
        })
    }

    /// Size of the tiled buffer: (n·⌈W/n⌉, m·⌈H/m⌉).
    pub fn tiled_size(&self) -> [u32; 2] {
        [self.n * self.tile[0], self.m * self.tile[1]]
    }

    /// Top-left texel of sub-buffer (i, j) in the tiled buffer.
    pub fn tile_origin(&self, i: u32, j: u32) -> [u32; 2] {
        [i * self.tile[0], j * self.tile[1]]
    }

    /// Size of the block-split buffer of [`SplitMethod::Blocks`] (whole blocks).
    pub fn block_split_size(&self) -> [u32; 2] {
        [
            self.width.div_ceil(self.block[0]) * self.block[0],
            self.height.div_ceil(self.block[1]) * self.block[1],
        ]
    }

    /// Compute workgroups of one BS or BG dispatch.
    pub fn workgroups(&self) -> [u32; 2] {
        [
            self.tile[0].div_ceil(self.group[0]),
            self.tile[1].div_ceil(self.group[1]),
        ]
    }

    /// Image texel (x, y) → its texel in the tiled buffer (§3.2).
    pub fn split_index(&self, x: u32, y: u32) -> [u32; 2] {
        [
            (x % self.n) * self.tile[0] + x / self.n,
            (y % self.m) * self.tile[1] + y / self.m,
        ]
    }

    /// Tiled texel (tx, ty) → its image texel; `None` for padding.
    pub fn gather_index(&self, tx: u32, ty: u32) -> Option<[u32; 2]> {
        let (i, j) = (tx / self.tile[0], ty / self.tile[1]);
        let x = (tx % self.tile[0]) * self.n + i;
        let y = (ty % self.tile[1]) * self.m + j;
        (i < self.n && j < self.m && x < self.width && y < self.height).then_some([x, y])
    }

    /// Sub-buffer (i, j) of image texel (x, y).
    pub fn sub_buffer(&self, x: u32, y: u32) -> [u32; 2] {
        [x % self.n, y % self.m]
    }

    /// Block splitting (§3.3, Fig. 2 b→c): image texel → block-split texel.
    pub fn block_split_index(&self, x: u32, y: u32) -> [u32; 2] {
        let f = |p: u32, a: usize, pat: u32| {
            let u = p % self.block[a];
            p - u + (u % pat) * self.sub_block[a] + u / pat
        };
        [f(x, 0, self.n), f(y, 1, self.m)]
    }

    /// Inverse of [`Self::block_split_index`]; `None` where the image has no texel.
    pub fn block_gather_index(&self, qx: u32, qy: u32) -> Option<[u32; 2]> {
        let f = |q: u32, a: usize, pat: u32| {
            let u = q % self.block[a];
            q - u + (u % self.sub_block[a]) * pat + u / self.sub_block[a]
        };
        let (x, y) = (f(qx, 0, self.n), f(qy, 1, self.m));
        (x < self.width && y < self.height).then_some([x, y])
    }

    /// Block translation (§3.3, Fig. 2 c→d): block-split texel → tiled texel.
    pub fn block_translate_index(&self, qx: u32, qy: u32) -> [u32; 2] {
        let f = |q: u32, a: usize| {
            let (b, u) = (q / self.block[a], q % self.block[a]);
            (u / self.sub_block[a]) * self.tile[a] + b * self.sub_block[a] + u % self.sub_block[a]
        };
        [f(qx, 0), f(qy, 1)]
    }

    /// Inverse block translation: tiled texel → block-split texel.
    pub fn block_untranslate_index(&self, tx: u32, ty: u32) -> [u32; 2] {
        let f = |t: u32, a: usize| {
            let (s, l) = (t / self.tile[a], t % self.tile[a]);
            (l / self.sub_block[a]) * self.block[a] + s * self.sub_block[a] + l % self.sub_block[a]
        };
        [f(tx, 0), f(ty, 1)]
    }

    /// BS on the CPU: `image` (W·H texels, row-major) → tiled buffer, padding = `padding`.
    pub fn split_cpu<T: Clone>(&self, image: &[T], padding: T) -> Vec<T> {
        assert_eq!(image.len(), (self.width * self.height) as usize, "image is W×H texels");
        let [tw, th] = self.tiled_size();
        let mut out = Vec::with_capacity((tw * th) as usize);
        for ty in 0..th {
            for tx in 0..tw {
                out.push(match self.gather_index(tx, ty) {
                    Some([x, y]) => image[(y * self.width + x) as usize].clone(),
                    None => padding.clone(),
                });
            }
        }
        out
    }

    /// BG on the CPU: tiled buffer → W·H image texels.
    pub fn gather_cpu<T: Clone>(&self, tiled: &[T]) -> Vec<T> {
        let [tw, th] = self.tiled_size();
        assert_eq!(tiled.len(), (tw * th) as usize, "tiled buffer has tiled_size() texels");
        let mut out = Vec::with_capacity((self.width * self.height) as usize);
        for y in 0..self.height {
            for x in 0..self.width {
                let [tx, ty] = self.split_index(x, y);
                out.push(tiled[(ty * tw + tx) as usize].clone());
            }
        }
        out
    }

    /// The `Interleave` uniforms of `common/interleave.wgsl` for this geometry.
    pub(crate) fn uniforms(&self, padding: [f32; 4]) -> IlsUniforms {
        IlsUniforms {
            size: [self.width, self.height],
            pattern: [self.n, self.m],
            tile: self.tile,
            sub_block: self.sub_block,
            block: self.block,
            group: self.group,
            padding,
        }
    }
}

/// Mirrors `Interleave` in `common/interleave.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct IlsUniforms {
    size: [u32; 2],
    pattern: [u32; 2],
    tile: [u32; 2],
    sub_block: [u32; 2],
    block: [u32; 2],
    group: [u32; 2],
    padding: [f32; 4],
}

/// WGSL storage-texture name of the formats the compute method accepts.
fn storage_format_name(format: wgpu::TextureFormat) -> Option<&'static str> {
    use wgpu::TextureFormat as F;
    Some(match format {
        F::R8Unorm => "r8unorm",
        F::Rg8Unorm => "rg8unorm",
        F::Rgba8Unorm => "rgba8unorm",
        F::Bgra8Unorm => "bgra8unorm",
        F::R16Float => "r16float",
        F::Rg16Float => "rg16float",
        F::Rgba16Float => "rgba16float",
        F::R32Float => "r32float",
        F::Rg32Float => "rg32float",
        F::Rgba32Float => "rgba32float",
        F::Rgb10a2Unorm => "rgb10a2unorm",
        F::R16Unorm => "r16unorm",
        F::Rg16Unorm => "rg16unorm",
        F::Rgba16Unorm => "rgba16unorm",
        _ => return None,
    })
}

/// Whether `format`'s texels survive `textureLoad` → f32 → store bit for bit.
fn exact_through_f32(format: wgpu::TextureFormat) -> bool {
    !format.is_srgb()
        && !format.is_compressed()
        && !format.is_depth_stencil_format()
        && !matches!(
            format,
            wgpu::TextureFormat::R8Snorm
                | wgpu::TextureFormat::Rg8Snorm
                | wgpu::TextureFormat::Rgba8Snorm
                | wgpu::TextureFormat::R16Snorm
                | wgpu::TextureFormat::Rg16Snorm
                | wgpu::TextureFormat::Rgba16Snorm
        )
}

enum Pipelines {
    Naive {
        split: wgpu::RenderPipeline,
        gather: wgpu::RenderPipeline,
    },
    Blocks {
        splitting: wgpu::RenderPipeline,
        translation: wgpu::RenderPipeline,
        untranslation: wgpu::RenderPipeline,
        gathering: wgpu::RenderPipeline,
        /// The block-split buffer and a bind group reading it.
        block_split: wgpu::Texture,
        block_split_view: wgpu::TextureView,
        block_split_group: wgpu::BindGroup,
    },
    Compute {
        split: wgpu::ComputePipeline,
        gather: wgpu::ComputePipeline,
    },
}

/// BS and BG of one image size, pattern, format and method (see the module docs).
pub struct Interleave {
    geometry: InterleaveGeometry,
    format: wgpu::TextureFormat,
    method: SplitMethod,
    device: wgpu::Device,
    uniforms: wgpu::Buffer,
    padding: [f32; 4],
    layout: wgpu::BindGroupLayout,
    pipelines: Pipelines,
}

impl Interleave {
    /// Builds the passes splitting a `width`×`height` texture of `format` into
    /// n×m sub-buffers with `method`. Errors (never panics) on an invalid
    /// parameter or a format the method cannot write, naming it and what is valid.
    pub fn new(
        gpu: &GpuContext,
        format: wgpu::TextureFormat,
        width: u32,
        height: u32,
        n: u32,
        m: u32,
        method: SplitMethod,
    ) -> Result<Self, RenderError> {
        let geometry = InterleaveGeometry::new(width, height, n, m, method).map_err(RenderError::Parameter)?;
        let device = &gpu.device;
        let max = device.limits().max_texture_dimension_2d;
        let mut sizes = vec![("tiled buffer", geometry.tiled_size())];
        if let SplitMethod::Blocks { .. } = method {
            sizes.push(("block-split buffer", geometry.block_split_size()));
        }
        for (what, [w, h]) in sizes {
            if w > max || h > max {
                return Err(RenderError::Parameter(format!(
                    "interleave {what} {w}x{h} for a {width}x{height} image is too large: each side must be <= {max}"
                )));
            }
        }
        let features = format.guaranteed_format_features(device.features());
        let float = matches!(
            format.sample_type(None, Some(device.features())),
            Some(wgpu::TextureSampleType::Float { .. })
        );
        let write = match method {
            SplitMethod::Compute => wgpu::TextureUsages::STORAGE_BINDING,
            _ => wgpu::TextureUsages::RENDER_ATTACHMENT,
        };
        let storage_ok = method != SplitMethod::Compute || storage_format_name(format).is_some();
        if !float || !exact_through_f32(format) || !features.allowed_usages.contains(write) || !storage_ok {
            return Err(RenderError::Parameter(format!(
                "interleave format {format:?} is not supported by method {}: it must be a float-sampled, \
                 non-sRGB, non-snorm {} format (e.g. Rgba16Float, Rgba32Float, R32Float, Rgba8Unorm)",
                method.name(),
                if method == SplitMethod::Compute {
                    "storage"
                } else {
                    "render-target"
                },
            )));
        }

        let visibility = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let mut entries = vec![
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
        ];
        if method == SplitMethod::Compute {
            entries.push(crate::passes::builder::storage_texture_entry(2, format));
        }
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("interleave"),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("interleave"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let padding = PADDING_MARKER;
        let uniforms = {
            use wgpu::util::DeviceExt;
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("interleave"),
                contents: bytemuck::bytes_of(&geometry.uniforms(padding)),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            })
        };

        let render = |label: &str, entry: &str, module: &wgpu::ShaderModule| {
            crate::passes::fullscreen_pipeline_with(
                device,
                label,
                &pipeline_layout,
                module,
                entry,
                &[],
                &[Some(wgpu::ColorTargetState::from(format))],
            )
        };
        let pipelines = match method {
            SplitMethod::Naive => {
                let module = crate::shader::module(device, "interleave", include_str!("interleave.wgsl"));
                Pipelines::Naive {
                    split: render(labels::BS_NAIVE, "fs_naive_split", &module),
                    gather: render(labels::BG_NAIVE, "fs_naive_gather", &module),
                }
            }
            SplitMethod::Blocks { .. } => {
                let module = crate::shader::module(device, "interleave", include_str!("interleave.wgsl"));
                let [bw, bh] = geometry.block_split_size();
                let block_split = device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("ils block-split buffer"),
                    size: wgpu::Extent3d {
                        width: bw,
                        height: bh,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                        | wgpu::TextureUsages::TEXTURE_BINDING
                        | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                });
                let block_split_view = block_split.create_view(&Default::default());
                let block_split_group = crate::passes::bind_group(
                    device,
                    "ils block-split buffer",
                    &layout,
                    &[
                        uniforms.as_entire_binding(),
                        wgpu::BindingResource::TextureView(&block_split_view),
                    ],
                );
                Pipelines::Blocks {
                    splitting: render(labels::BS_BLOCK_SPLITTING, "fs_block_splitting", &module),
                    translation: render(labels::BS_BLOCK_TRANSLATION, "fs_block_translation", &module),
                    untranslation: render(labels::BG_BLOCK_TRANSLATION, "fs_block_untranslation", &module),
                    gathering: render(labels::BG_BLOCK_GATHERING, "fs_block_gathering", &module),
                    block_split,
                    block_split_view,
                    block_split_group,
                }
            }
            SplitMethod::Compute => {
                let name = storage_format_name(format).expect("checked above");
                let source = include_str!("interleave_compute.wgsl").replace("STORAGE_FORMAT", name);
                let module = crate::shader::module(device, "interleave-compute", &source);
                let compute = |label: &str, entry: &str| {
                    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                        label: Some(label),
                        layout: Some(&pipeline_layout),
                        module: &module,
                        entry_point: Some(entry),
                        compilation_options: Default::default(),
                        cache: None,
                    })
                };
                Pipelines::Compute {
                    split: compute(labels::BS_COMPUTE, "cs_split"),
                    gather: compute(labels::BG_COMPUTE, "cs_gather"),
                }
            }
        };
        Ok(Self {
            geometry,
            format,
            method,
            device: device.clone(),
            uniforms,
            padding,
            layout,
            pipelines,
        })
    }

    /// Sizes and index maps (the CPU twin of the shaders).
    pub fn geometry(&self) -> &InterleaveGeometry {
        &self.geometry
    }

    /// Size of the tiled buffer BS writes and BG reads (see [`InterleaveGeometry::tiled_size`]).
    pub fn tiled_size(&self) -> [u32; 2] {
        self.geometry.tiled_size()
    }

    /// W, H of the interleaved image.
    pub fn image_size(&self) -> [u32; 2] {
        [self.geometry.width, self.geometry.height]
    }

    pub fn method(&self) -> SplitMethod {
        self.method
    }

    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// The value padding texels hold ([`PADDING_MARKER`] unless changed).
    pub fn padding(&self) -> [f32; 4] {
        self.padding
    }

    /// Sets the value written to padding texels by the next BS (converted to
    /// the format as a shader output is; a marker is best exact in it).
    pub fn set_padding(&mut self, gpu: &GpuContext, marker: [f32; 4]) {
        self.padding = marker;
        gpu.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&self.geometry.uniforms(marker)));
    }

    /// The usage BS's destination and BG's destination need with this method
    /// (besides `TEXTURE_BINDING` for reading them afterwards).
    pub fn write_usage(&self) -> wgpu::TextureUsages {
        match self.method {
            SplitMethod::Compute => wgpu::TextureUsages::STORAGE_BINDING,
            _ => wgpu::TextureUsages::RENDER_ATTACHMENT,
        }
    }

    /// A texture of the tiled size and format usable as BS destination and BG
    /// source with this method (plus `COPY_SRC | COPY_DST`).
    pub fn create_tiled_texture(&self, label: &str) -> wgpu::Texture {
        self.create(label, self.tiled_size())
    }

    /// A texture of the image size and format usable as BS source and BG
    /// destination with this method (plus `COPY_SRC | COPY_DST`).
    pub fn create_image_texture(&self, label: &str) -> wgpu::Texture {
        self.create(label, self.image_size())
    }

    fn create(&self, label: &str, [width, height]: [u32; 2]) -> wgpu::Texture {
        self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.format,
            usage: self.write_usage()
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        })
    }

    /// Records BS: `src` (the W×H image) → `dst` (the tiled buffer). Both are
    /// whole-texture views of single-mip 2D textures of this format; `dst`'s
    /// texture has [`Self::tiled_size`] and [`Self::write_usage`].
    pub fn split(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        src: &wgpu::TextureView,
        dst: &wgpu::TextureView,
    ) -> Result<(), RenderError> {
        self.split_profiled(encoder, src, dst, None)
    }

    /// Records BG: `src` (the tiled buffer) → `dst` (the W×H image).
    pub fn gather(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        src: &wgpu::TextureView,
        dst: &wgpu::TextureView,
    ) -> Result<(), RenderError> {
        self.gather_profiled(encoder, src, dst, None)
    }

    /// [`Self::split`] with a timestamp pair per pass in `profiler` (labels: [`labels`]).
    pub fn split_profiled(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        src: &wgpu::TextureView,
        dst: &wgpu::TextureView,
        profiler: Option<&Profiler>,
    ) -> Result<(), RenderError> {
        self.check(
            "split source",
            src,
            self.image_size(),
            wgpu::TextureUsages::TEXTURE_BINDING,
        )?;
        self.check("split destination", dst, self.tiled_size(), self.write_usage())?;
        self.check_distinct(src, dst)?;
        let group = self.group(src, dst);
        match &self.pipelines {
            Pipelines::Naive { split, .. } => {
                timed(encoder, profiler, labels::BS_NAIVE, |e| {
                    crate::passes::fullscreen_pass(e, labels::BS_NAIVE, split, &[dst], &[&group])
                });
            }
            Pipelines::Blocks {
                splitting,
                translation,
                block_split_view,
                block_split_group,
                ..
            } => {
                timed(encoder, profiler, labels::BS_BLOCK_SPLITTING, |e| {
                    let label = labels::BS_BLOCK_SPLITTING;
                    crate::passes::fullscreen_pass(e, label, splitting, &[block_split_view], &[&group])
                });
                timed(encoder, profiler, labels::BS_BLOCK_TRANSLATION, |e| {
                    let label = labels::BS_BLOCK_TRANSLATION;
                    crate::passes::fullscreen_pass(e, label, translation, &[dst], &[block_split_group])
                });
            }
            Pipelines::Compute { split, .. } => {
                timed(encoder, profiler, labels::BS_COMPUTE, |e| {
                    self.dispatch(e, labels::BS_COMPUTE, split, &group)
                });
            }
        }
        Ok(())
    }

    /// [`Self::gather`] with a timestamp pair per pass in `profiler` (labels: [`labels`]).
    pub fn gather_profiled(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        src: &wgpu::TextureView,
        dst: &wgpu::TextureView,
        profiler: Option<&Profiler>,
    ) -> Result<(), RenderError> {
        self.check(
            "gather source",
            src,
            self.tiled_size(),
            wgpu::TextureUsages::TEXTURE_BINDING,
        )?;
        self.check("gather destination", dst, self.image_size(), self.write_usage())?;
        self.check_distinct(src, dst)?;
        let group = self.group(src, dst);
        match &self.pipelines {
            Pipelines::Naive { gather, .. } => {
                timed(encoder, profiler, labels::BG_NAIVE, |e| {
                    crate::passes::fullscreen_pass(e, labels::BG_NAIVE, gather, &[dst], &[&group])
                });
            }
            Pipelines::Blocks {
                untranslation,
                gathering,
                block_split_view,
                block_split_group,
                ..
            } => {
                timed(encoder, profiler, labels::BG_BLOCK_TRANSLATION, |e| {
                    let label = labels::BG_BLOCK_TRANSLATION;
                    crate::passes::fullscreen_pass(e, label, untranslation, &[block_split_view], &[&group])
                });
                timed(encoder, profiler, labels::BG_BLOCK_GATHERING, |e| {
                    let label = labels::BG_BLOCK_GATHERING;
                    crate::passes::fullscreen_pass(e, label, gathering, &[dst], &[block_split_group])
                });
            }
            Pipelines::Compute { gather, .. } => {
                timed(encoder, profiler, labels::BG_COMPUTE, |e| {
                    self.dispatch(e, labels::BG_COMPUTE, gather, &group)
                });
            }
        }
        Ok(())
    }

    /// The block-split texture of [`SplitMethod::Blocks`] (for debugging views).
    pub fn block_split_texture(&self) -> Option<&wgpu::Texture> {
        match &self.pipelines {
            Pipelines::Blocks { block_split, .. } => Some(block_split),
            _ => None,
        }
    }

    fn dispatch(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        pipeline: &wgpu::ComputePipeline,
        group: &wgpu::BindGroup,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        let [x, y] = self.geometry.workgroups();
        pass.dispatch_workgroups(x, y, 1);
    }

    fn group(&self, src: &wgpu::TextureView, dst: &wgpu::TextureView) -> wgpu::BindGroup {
        let mut resources = vec![
            self.uniforms.as_entire_binding(),
            wgpu::BindingResource::TextureView(src),
        ];
        if self.method == SplitMethod::Compute {
            resources.push(wgpu::BindingResource::TextureView(dst));
        }
        crate::passes::bind_group(&self.device, "interleave", &self.layout, &resources)
    }

    fn check(
        &self,
        what: &str,
        view: &wgpu::TextureView,
        [w, h]: [u32; 2],
        usage: wgpu::TextureUsages,
    ) -> Result<(), RenderError> {
        let t = view.texture();
        let problem = if t.format() != self.format {
            Some(format!("has format {:?}, expected {:?}", t.format(), self.format))
        } else if (t.width(), t.height()) != (w, h) {
            Some(format!("is {}x{}, expected {w}x{h}", t.width(), t.height()))
        } else if t.mip_level_count() != 1 || t.depth_or_array_layers() != 1 || t.sample_count() != 1 {
            Some("must be a single-mip, single-layer, single-sample 2D texture".to_string())
        } else if !t.usage().contains(usage) {
            Some(format!("lacks usage {usage:?}"))
        } else {
            None
        };
        match problem {
            Some(p) => Err(RenderError::Parameter(format!("interleave {what} texture {p}"))),
            None => Ok(()),
        }
    }

    fn check_distinct(&self, src: &wgpu::TextureView, dst: &wgpu::TextureView) -> Result<(), RenderError> {
        if src.texture() == dst.texture() {
            return Err(RenderError::Parameter(
                "interleave source and destination must be different textures".into(),
            ));
        }
        Ok(())
    }
}

/// Records `f` between a begin/end timestamp pair named `label` when profiling.
fn timed(
    encoder: &mut wgpu::CommandEncoder,
    profiler: Option<&Profiler>,
    label: &str,
    f: impl FnOnce(&mut wgpu::CommandEncoder),
) {
    let slot = profiler.and_then(|p| p.begin(encoder, label));
    f(encoder);
    if let Some(p) = profiler {
        p.end(encoder, slot);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PATTERNS: [(u32, u32); 7] = [(1, 1), (2, 2), (4, 4), (8, 6), (3, 2), (16, 16), (5, 7)];
    const SIZES: [(u32, u32); 5] = [(37, 23), (64, 48), (1, 1), (17, 3), (40, 40)];

    fn methods(n: u32, m: u32) -> Vec<SplitMethod> {
        let lo = min_block(n, m);
        vec![
            SplitMethod::Naive,
            SplitMethod::Compute,
            SplitMethod::Blocks { block: lo },
            SplitMethod::Blocks { block: lo * 4 },
        ]
    }

    #[test]
    fn split_and_gather_indices_are_inverse_bijections() {
        for (n, m) in PATTERNS {
            for (w, h) in SIZES {
                let g = InterleaveGeometry::new(w, h, n, m, SplitMethod::Naive).unwrap();
                let [tw, th] = g.tiled_size();
                let mut hit = vec![false; (tw * th) as usize];
                for y in 0..h {
                    for x in 0..w {
                        let [tx, ty] = g.split_index(x, y);
                        assert!(tx < tw && ty < th);
                        assert!(!std::mem::replace(&mut hit[(ty * tw + tx) as usize], true));
                        assert_eq!(g.gather_index(tx, ty), Some([x, y]));
                        // §3.2: sub-buffer (x mod n, y mod m) holds it, at (x div n, y div m)
                        let [i, j] = g.sub_buffer(x, y);
                        assert_eq!(
                            [tx, ty],
                            [g.tile_origin(i, j)[0] + x / n, g.tile_origin(i, j)[1] + y / m]
                        );
                    }
                }
                let padding = hit.iter().filter(|h| !**h).count() as u32;
                assert_eq!(padding, tw * th - w * h, "{n}x{m} {w}x{h}");
                for ty in 0..th {
                    for tx in 0..tw {
                        assert_eq!(g.gather_index(tx, ty).is_some(), hit[(ty * tw + tx) as usize]);
                    }
                }
            }
        }
    }

    #[test]
    fn two_pass_blocks_compose_to_the_one_pass_split() {
        for (n, m) in PATTERNS {
            for (w, h) in SIZES {
                for method in methods(n, m) {
                    let g = InterleaveGeometry::new(w, h, n, m, method).unwrap();
                    let [bw, bh] = g.block_split_size();
                    for y in 0..h {
                        for x in 0..w {
                            let [qx, qy] = g.block_split_index(x, y);
                            assert!(qx < bw && qy < bh);
                            assert_eq!(g.block_gather_index(qx, qy), Some([x, y]));
                            let t = g.block_translate_index(qx, qy);
                            assert_eq!(t, g.split_index(x, y), "{method:?} {n}x{m} {w}x{h} ({x},{y})");
                            assert_eq!(g.block_untranslate_index(t[0], t[1]), [qx, qy]);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn cpu_split_then_gather_is_identity() {
        let g = InterleaveGeometry::new(37, 23, 8, 6, SplitMethod::Naive).unwrap();
        let img: Vec<u32> = (1..=37 * 23).collect();
        let tiled = g.split_cpu(&img, 0);
        assert_eq!(tiled.iter().filter(|v| **v == 0).count(), 40 * 24 - 37 * 23);
        assert_eq!(g.gather_cpu(&tiled), img);
    }

    #[test]
    fn invalid_parameters_are_one_line_errors() {
        let bad = [
            (8, 8, 0, 2, SplitMethod::Naive, "n = 0"),
            (8, 8, 17, 2, SplitMethod::Naive, "n = 17"),
            (8, 8, 2, 0, SplitMethod::Compute, "m = 0"),
            (0, 8, 2, 2, SplitMethod::Naive, "size 0x8"),
            (8, 8, 2, 2, SplitMethod::Blocks { block: 12 }, "block size 12"),
            (8, 8, 8, 4, SplitMethod::Blocks { block: 4 }, "block size 4"),
            (8, 8, 3, 2, SplitMethod::Blocks { block: 2 }, "block size 2"),
            (8, 8, 2, 2, SplitMethod::Blocks { block: 1 }, "block size 1"),
            (8, 8, 2, 2, SplitMethod::Blocks { block: 2048 }, "block size 2048"),
            (8, 8, 2, 2, SplitMethod::Blocks { block: 0 }, "block size 0"),
        ];
        for (w, h, n, m, method, needle) in bad {
            let e = InterleaveGeometry::new(w, h, n, m, method).unwrap_err();
            assert!(e.contains(needle) && !e.contains('\n'), "{e}");
        }
        assert!(InterleaveGeometry::new(8, 8, 3, 2, SplitMethod::Blocks { block: 4 }).is_ok());
        assert!(InterleaveGeometry::new(8, 8, 16, 16, SplitMethod::Blocks { block: 16 }).is_ok());
        assert!(InterleaveGeometry::new(8, 8, 1, 1, SplitMethod::Blocks { block: 1 }).is_ok());
    }
}
