//! The A-buffer of Bauer, Knuth, Kuijper, Bender 2013 ("ABA", *Screen-Space
//! Ambient Occlusion using A-Buffer Techniques*): every rasterised fragment of
//! a pixel, kept in one per-pixel list, here used for order-independent
//! transparency (OIT) and list compression (§III-B, Eq. 5).
//!
//! | pass | ABA | what |
//! |---|---|---|
//! | `abuffer-clear` | Table I "clear" | zero the head pointers / counters / overflow counter |
//! | `abuffer-count` | §IV-B, Table I "count" | linear lists only: fragments per pixel |
//! | `abuffer-prefix-sum` | §IV-B, Table I "prefix sum" | linear lists only: first node of each pixel |
//! | `abuffer-draw` | Table I "draw" | every fragment shaded and stored (dual peel: 1 + ⌈L/2⌉ geometry passes) |
//! | `abuffer-resolve` | Table I "resolve OIT" | per pixel: sort by depth, blend front to back, compress (Eq. 5) |
//! | `aba-ao` | Table I "AO", Algorithm 1 | with [`ABufferSettings::ao`]: opacity-aware multilayer AO of every fragment, blended ([`ao`]) |
//! | `ao-blur-h`, `ao-blur-v` | §III ("separate" integration) | bilateral reconstruction of the blended AO into `ao` |
//!
//! Four constructions ([`ABufferMethod`]) store the same fragments: a
//! per-pixel linked list (PPLL, §IV-A), linear lists (count, prefix sum, fill;
//! §IV-B), a fixed array of K slots per pixel (the paper's Texture3D, §IV-C)
//! and the dual-depth-peeling baseline (Bavoil & Myers, L layers). A fragment
//! holds its camera-space depth, shaded radiance and α (two `pack2x16float`),
//! its Oct16 normal flipped toward the camera and whether it is front-facing.
//!
//! **Shading** (the CPU twin is `strata_reference::oit::shade`): L = emission +
//! albedo·ambient + albedo/π · Σ_l E_l(x, n_c), E_l the unshadowed irradiance of
//! `shaders/common/lights.wgsl`; α = opacity × base-colour texture alpha.
//!
//! **Overflow** never writes out of bounds: a fragment with no room is dropped
//! and counted ([`FragmentLists::overflow`]); linked list: those whose atomic
//! node index is ≥ the pool (an arbitrary, rasterisation-order subset); linear:
//! the pixels whose range starts or runs past the pool (the last pixels in
//! row-major order); fixed array: a pixel's fragments after its K-th (again in
//! rasterisation order); dual peel: the middle layers beyond the L peeled
//! ones, and a second fragment at exactly the depth of a peeled one.
//! See `docs/abuffer.md` for memory, sort, packing and deviations.

pub mod ao;
pub mod compress;

use std::sync::Arc;

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::lights::GpuLight;
use crate::scene_gpu::{GpuScene, VERTEX_LAYOUT};
use crate::RenderError;

/// How the A-buffer is built (ABA §IV and its DDP baseline).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ABufferMethod {
    /// Per-pixel linked lists (Yang et al. 2010): atomic counter, head pointers, node pool.
    LinkedList,
    /// Linear lists (Knowles et al. 2012): count pass, prefix sum, fill pass.
    Linear,
    /// K slots per pixel (the paper's Texture3D).
    FixedArray,
    /// Dual depth peeling (Bavoil & Myers 2008): L layers, geometry re-rendered per peel.
    DualPeel,
}

impl ABufferMethod {
    pub const ALL: [ABufferMethod; 4] = [
        ABufferMethod::LinkedList,
        ABufferMethod::Linear,
        ABufferMethod::FixedArray,
        ABufferMethod::DualPeel,
    ];

    /// The CLI / bench key.
    pub fn name(self) -> &'static str {
        match self {
            ABufferMethod::LinkedList => "linked-list",
            ABufferMethod::Linear => "linear",
            ABufferMethod::FixedArray => "fixed-array",
            ABufferMethod::DualPeel => "dual-peel",
        }
    }

    fn index(self) -> u32 {
        Self::ALL.iter().position(|m| *m == self).expect("listed") as u32
    }

    /// The passes this method adds to the frame, in order.
    pub fn passes(self) -> &'static [&'static str] {
        match self {
            ABufferMethod::Linear => &[
                "abuffer-clear",
                "abuffer-count",
                "abuffer-prefix-sum",
                "abuffer-draw",
                "abuffer-resolve",
            ],
            _ => &["abuffer-clear", "abuffer-draw", "abuffer-resolve"],
        }
    }
}

impl std::str::FromStr for ABufferMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| {
            format!("abuffer '{s}' is unknown: valid methods are linked-list, linear, fixed-array, dual-peel")
        })
    }
}

impl std::fmt::Display for ABufferMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Largest node pool (64 Mi nodes, 1.25 GiB for a linked list).
pub const MAX_POOL: u32 = 1 << 26;
/// Pool nodes per pixel when the pool is not given.
pub const DEFAULT_POOL_PER_PIXEL: u32 = 8;
/// Largest K (fixed-array slots, dual-peel layers).
pub const MAX_LAYERS: u32 = 64;

/// The A-buffer's settings.
///
/// Default (ABA §V): 16 layers (the paper's test setup, "1280×720 with 16
/// depth layers"), M = 6 compressed nodes (§V-A: "24 bytes per pixel" of
/// 32-bit nodes, 16-bit depth + 16-bit opacity) searched in the back half only
/// (§III-B; Fig. 6 c shows it keeps the layers near the camera), a linked list
/// with a pool of [`DEFAULT_POOL_PER_PIXEL`] nodes per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct ABufferSettings {
    pub method: ABufferMethod,
    /// Nodes of the linked-list / linear pool; `None`: [`DEFAULT_POOL_PER_PIXEL`] × pixels
    /// (capped at [`MAX_POOL`], and at what the adapter's largest storage buffer holds: a
    /// larger frame then drops fragments, reported, instead of refusing to render).
    pub pool: Option<u32>,
    /// K: fixed-array slots per pixel, dual-peel layers L (rounded up to even: two per peel).
    pub max_layers: u32,
    /// M nodes of the compressed list (Eq. 5); `None`: no compression.
    pub compress: Option<u32>,
    /// Eq. 5 searches only the back half of the array.
    pub compress_back_half: bool,
    /// Opacity-aware multilayer AO (Algorithm 1) into target `ao`; `None` = off.
    pub ao: Option<ao::AbaAoSettings>,
}

impl Default for ABufferSettings {
    fn default() -> Self {
        Self {
            method: ABufferMethod::LinkedList,
            pool: None,
            max_layers: 16,
            compress: Some(6),
            compress_back_half: true,
            ao: None,
        }
    }
}

/// Stored fragments per pixel (the `--debug-view abuffer-count` heat map).
pub const COUNT: TargetDesc = TargetDesc::new(
    "abuffer-count",
    wgpu::TextureFormat::R32Float,
    1,
    "A-buffer: fragments stored per pixel (after overflow)",
);

/// The multilayer AO before the bilateral reconstruction.
pub const AO_RAW: TargetDesc = TargetDesc::new(
    "ao-raw",
    wgpu::TextureFormat::R32Float,
    1,
    "ABA multilayer AO (Algorithm 1), blended over the fragments, before reconstruction (1 = unoccluded)",
);

/// The OIT colour with each fragment's AO applied inside the blend (ABA §III).
pub const AO_INSIDE: TargetDesc = TargetDesc::new(
    "hdr-aba-inside",
    wgpu::TextureFormat::Rgba32Float,
    1,
    "OIT colour with AO inside the blend: Σ T_i α_i AV_i L_i + T·sky (linear HDR; integration=inside)",
);

/// The OIT colour times the separately blended AO, before the AO's blur.
pub const AO_SEPARATE: TargetDesc = TargetDesc::new(
    "hdr-aba-separate",
    wgpu::TextureFormat::Rgba32Float,
    1,
    "OIT colour × separately blended AO, before the blur (linear HDR; integration=inside)",
);

/// The composited colour (linear HDR, sky behind).
pub const OUTPUT: TargetDesc = TargetDesc::new(
    "hdr-oit",
    wgpu::TextureFormat::Rgba32Float,
    1,
    "A-buffer OIT: fragments blended front to back over the sky (linear HDR)",
);

impl ABufferSettings {
    pub fn validate(&self) -> Result<(), String> {
        if let Some(p) = self.pool {
            if !(1..=MAX_POOL).contains(&p) {
                return Err(format!("pool {p} is out of range: must be in 1..={MAX_POOL}"));
            }
        }
        if !(1..=MAX_LAYERS).contains(&self.max_layers) {
            return Err(format!(
                "max-layers {} is out of range: must be in 1..={MAX_LAYERS}",
                self.max_layers
            ));
        }
        if let Some(m) = self.compress {
            if !(1..=compress::MAX_NODES).contains(&m) {
                return Err(format!(
                    "compress {m} is out of range: must be in 1..={} (0 = off)",
                    compress::MAX_NODES
                ));
            }
        }
        if let Some(a) = &self.ao {
            a.validate()?;
            if a.kernel == ao::AoKernel::HbaoCompute {
                // §V-B stages the compressed nodes (Eq. 5) in workgroup memory
                if self.compress.is_none() {
                    return Err(format!(
                        "kernel hbao-compute needs compress in 1..={} (it stages the compressed nodes)",
                        compress::MAX_NODES
                    ));
                }
                if a.inside {
                    return Err("kernel hbao-compute supports integration=separate only".into());
                }
            }
        }
        Ok(())
    }

    /// Pool nodes at `w`×`h` before the adapter's limit ([`Self::pool_nodes_within`]).
    pub fn pool_nodes(&self, w: u32, h: u32) -> u32 {
        self.pool_nodes_within(w, h, u64::MAX)
    }

    /// Pool nodes at `w`×`h` on an adapter whose largest storage buffer is `max_bytes`: a
    /// given pool as is (refused when it does not fit), the default capped to fit.
    pub fn pool_nodes_within(&self, w: u32, h: u32, max_bytes: u64) -> u32 {
        self.pool.unwrap_or_else(|| {
            (w as u64 * h as u64 * DEFAULT_POOL_PER_PIXEL as u64)
                .min(MAX_POOL as u64)
                .min(max_bytes / NODE_BYTES)
                .max(1) as u32
        })
    }

    /// What to raise when fragments were dropped: the pool (and the per-pixel cap) of the
    /// pooled methods, the per-pixel slots of the fixed ones.
    pub fn overflow_hint(&self) -> &'static str {
        if self.slots() > 0 {
            "raise --set max-layers=K"
        } else {
            "raise --set pool=N or max-layers=K"
        }
    }

    /// Node slots per pixel: K (fixed array), 2·⌈L/2⌉ (dual peel), 0 (pooled methods).
    pub fn slots(&self) -> u32 {
        match self.method {
            ABufferMethod::FixedArray => self.max_layers,
            ABufferMethod::DualPeel => 2 * self.max_layers.div_ceil(2),
            _ => 0,
        }
    }

    /// Dual-peel geometry passes after the first: ⌈L/2⌉.
    pub fn peels(&self) -> u32 {
        self.max_layers.div_ceil(2)
    }

    /// Bytes of the A-buffer structure at `w`×`h` (docs/abuffer.md): nodes of
    /// 16 bytes, per-pixel heads / counters / offsets of 4 bytes, 16 bytes of
    /// counters; outputs (colour, compressed nodes) not included.
    pub fn memory_bytes(&self, w: u32, h: u32) -> u64 {
        let px = w as u64 * h as u64;
        let pool = self.pool_nodes(w, h) as u64;
        let slots = self.slots() as u64;
        16 + match self.method {
            // heads + nodes + next pointers
            ABufferMethod::LinkedList => px * 4 + pool * (NODE_BYTES + 4),
            // counts + offsets + fill cursors + nodes
            ABufferMethod::Linear => px * 12 + pool * NODE_BYTES,
            // counts + K nodes per pixel
            ABufferMethod::FixedArray => px * 4 + px * slots * NODE_BYTES,
            // layer flags (2 words) + two intervals (2 words each) + L nodes per pixel
            ABufferMethod::DualPeel => px * 8 + 2 * px * 8 + px * slots * NODE_BYTES,
        }
    }

    /// Bytes of the compressed lists: 2·⌈M/4⌉ RGBA32Uint texels per pixel
    /// (depth + α words, then normal + facing words).
    pub fn compressed_bytes(&self, w: u32, h: u32) -> u64 {
        w as u64 * h as u64 * 32 * self.compress.map_or(0, |m| m.div_ceil(4)) as u64
    }

    /// Everything the stage allocates: structure, output colour, fragment
    /// counts, compressed lists and the 1-byte-per-pixel dummy attachment.
    pub fn estimated_bytes(&self, w: u32, h: u32) -> u64 {
        let px = w as u64 * h as u64;
        // AO: ao-raw (4 bytes), ao-blur-h and ao (2 bytes each); inside: two RGBA32F
        let ao = self
            .ao
            .as_ref()
            .map_or(0, |a| px * 8 + if a.inside { px * 32 } else { 0 });
        self.memory_bytes(w, h) + self.compressed_bytes(w, h) + px * 16 + px * 4 + px + ao
    }
}

/// Bytes of one stored fragment.
pub const NODE_BYTES: u64 = 16;

/// One stored fragment as the GPU writes it (`Fragment` in the WGSL).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuFragment {
    pub depth: f32,
    pub rg: u32,
    pub ba: u32,
    pub normal_facing: u32,
}

/// A fragment read back from the A-buffer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StoredFragment {
    /// Its node (pool index, or slot index for the array methods): the sort's tie-break.
    pub node: u32,
    /// Camera-space depth.
    pub depth: f32,
    pub radiance: [f32; 3],
    pub alpha: f32,
    /// Unit normal toward the camera (decoded Oct16).
    pub normal: [f32; 3],
    pub front_facing: bool,
}

impl StoredFragment {
    fn decode(node: u32, f: &GpuFragment) -> Self {
        let h = |w: u32| {
            [
                crate::renderer::f16_to_f32(w as u16),
                crate::renderer::f16_to_f32((w >> 16) as u16),
            ]
        };
        let [r, g] = h(f.rg);
        let [b, a] = h(f.ba);
        let n = crate::packing::oct16_unpack([f.normal_facing as u8, (f.normal_facing >> 8) as u8]);
        Self {
            node,
            depth: f.depth,
            radiance: [r, g, b],
            alpha: a,
            normal: n.to_array(),
            front_facing: (f.normal_facing >> 16) & 1 == 1,
        }
    }
}

/// Every pixel's stored fragments, sorted by depth (ties by node), as the resolve visits them.
#[derive(Clone, Debug)]
pub struct FragmentLists {
    pub width: u32,
    pub height: u32,
    /// Row-major, one list per pixel.
    pub lists: Vec<Vec<StoredFragment>>,
    /// Fragments dropped for lack of room.
    pub overflow: u32,
    /// Fragments rasterised (after the alpha cutoff), as counted on the GPU.
    pub total: u32,
}

impl FragmentLists {
    pub fn at(&self, x: u32, y: u32) -> &[StoredFragment] {
        &self.lists[(y * self.width + x) as usize]
    }

    /// Stored fragments in all lists.
    pub fn stored(&self) -> usize {
        self.lists.iter().map(|l| l.len()).sum()
    }
}

/// Transmittance below which the blend stops (the rest is hidden).
pub const T_MIN: f32 = 1e-4;

/// Front-to-back blend of a sorted list over `sky`: C += T·α·L, T *= 1 − α
/// while T ≥ [`T_MIN`]; the sky gets the remaining T (none once T < T_MIN).
/// The CPU counterpart of `resolve.wgsl`'s blend.
pub fn blend_front_to_back(list: &[StoredFragment], sky: [f32; 3]) -> [f32; 3] {
    let mut c = [0.0f32; 3];
    let mut t = 1.0f32;
    for f in list {
        if t < T_MIN {
            break;
        }
        for (ck, lk) in c.iter_mut().zip(f.radiance) {
            *ck += t * f.alpha * lk;
        }
        t *= 1.0 - f.alpha;
    }
    if t >= T_MIN {
        for (ck, sk) in c.iter_mut().zip(sky) {
            *ck += t * sk;
        }
    }
    c
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct DrawParams {
    width: u32,
    height: u32,
    pool: u32,
    slots: u32,
    light_count: u32,
    peel: u32,
    last_peel: u32,
    _pad: u32,
}

/// The resolve pass's uniforms.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ResolveParams {
    pub width: u32,
    pub height: u32,
    pub pool: u32,
    pub slots: u32,
    pub method: u32,
    pub compress: u32,
    pub back_half: u32,
    pub _pad: u32,
    /// z16 = ⌊min(csz · depth_scale, 65535)⌋ (see [`compress`]).
    pub depth_scale: f32,
    pub _pad1: [f32; 3],
}

/// Everything the A-buffer's passes share.
struct Shared {
    settings: ABufferSettings,
    width: u32,
    height: u32,
    pool: u32,
    nodes: wgpu::Buffer,
    links: wgpu::Buffer,
    counts: wgpu::Buffer,
    offsets: wgpu::Buffer,
    /// linear: fill cursors; dual peel: interval buffer A
    cursor: wgpu::Buffer,
    /// dual peel: interval buffer B
    interval_b: wgpu::Buffer,
    stats: wgpu::Buffer,
    compressed: wgpu::Texture,
    resolve_params: wgpu::Buffer,
    attachment: wgpu::TextureView,
    count_pipeline: Option<wgpu::RenderPipeline>,
    /// linked list / linear fill / fixed array / dual init
    draw_pipeline: wgpu::RenderPipeline,
    peel_pipeline: Option<wgpu::RenderPipeline>,
    /// one per geometry pass (dual peel: init, then one per peel)
    draw_groups: Vec<wgpu::BindGroup>,
    prefix: Option<(wgpu::ComputePipeline, wgpu::BindGroup)>,
    resolve_pipeline: wgpu::RenderPipeline,
    resolve_group: wgpu::BindGroup,
    /// multilayer AO: pipeline, lists group (1), AO group (2), its uniform buffer
    ao: Option<AoResources>,
}

struct AoResources {
    /// the colour integrations are written too (`AbaAoSettings::inside`)
    inside: bool,
    pipeline: wgpu::RenderPipeline,
    lists_group: wgpu::BindGroup,
    group: wgpu::BindGroup,
    uniforms: wgpu::Buffer,
    /// kernel `hbao-compute` (§V-B): runs instead of the fragment pass
    compute: Option<ComputeAo>,
}

/// The compute-shader HBAO's pipeline, groups 2 and its storage output.
struct ComputeAo {
    pipeline: wgpu::ComputePipeline,
    /// AO uniforms, compressed nodes, `out`
    group: wgpu::BindGroup,
    /// R32Float storage texture, copied into `ao-raw` (frame targets are not storage-bindable)
    out: wgpu::Texture,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Clear,
    Count,
    PrefixSum,
    Draw,
    Resolve,
    Ao,
}

/// One of the A-buffer's passes in the frame.
pub struct ABufferPass {
    kind: Kind,
    shared: Arc<Shared>,
}

/// The A-buffer's passes and resources.
pub struct ABufferStage {
    shared: Arc<Shared>,
    passes: Vec<ABufferPass>,
    /// the AO's bilateral reconstruction (horizontal, vertical)
    blur: Vec<crate::passes::bilateral::BilateralPass>,
    depth_scale: std::cell::Cell<f32>,
    ao_uniforms: std::cell::Cell<Option<ao::AbaAoUniforms>>,
}

fn storage_buffer(gpu: &GpuContext, label: &str, size: u64) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

fn layout_entry(binding: u32, visibility: wgpu::ShaderStages, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty,
        count: None,
    }
}

fn storage_ty(read_only: bool) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only },
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

const UNIFORM_TY: wgpu::BindingType = wgpu::BindingType::Buffer {
    ty: wgpu::BufferBindingType::Uniform,
    has_dynamic_offset: false,
    min_binding_size: None,
};

fn uniform_buffer<T: bytemuck::Pod>(gpu: &GpuContext, label: &str, value: &T) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::bytes_of(value),
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    })
}

impl ABufferStage {
    /// Creates the A-buffer's resources and passes and its output target
    /// [`OUTPUT`]; `lights` are the scene's lights (shadow layers unused).
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &mut Targets,
        settings: &ABufferSettings,
        lights: &[GpuLight],
    ) -> Result<Self, RenderError> {
        settings.validate().map_err(RenderError::Parameter)?;
        let device = &gpu.device;
        let (w, h) = (targets.width, targets.height);
        let px = w as u64 * h as u64;
        let method = settings.method;
        let limits = device.limits();
        let max = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let pool = settings.pool_nodes_within(w, h, max);
        let slots = settings.slots();
        let pooled = matches!(method, ABufferMethod::LinkedList | ABufferMethod::Linear);
        let node_bytes = if pooled {
            pool as u64 * NODE_BYTES
        } else {
            px * slots as u64 * NODE_BYTES
        };
        if node_bytes > max {
            let what = if pooled {
                format!("pool {pool} nodes")
            } else {
                format!("max-layers {} at {w}x{h}", settings.max_layers)
            };
            return Err(RenderError::Parameter(format!(
                "A-buffer {what} needs a {} MiB node buffer: over the adapter's largest storage buffer of {} MiB (lower pool, max-layers or the size)",
                node_bytes >> 20,
                max >> 20
            )));
        }
        targets.create(gpu, OUTPUT);
        targets.create(gpu, COUNT);
        let dummy = || storage_buffer(gpu, "abuffer-unused", 16);
        let nodes = storage_buffer(gpu, "abuffer-nodes", node_bytes);
        let links = if method == ABufferMethod::LinkedList {
            storage_buffer(gpu, "abuffer-links", pool as u64 * 4)
        } else {
            dummy()
        };
        let per_pixel_words = if method == ABufferMethod::DualPeel { 2 } else { 1 };
        let counts = storage_buffer(gpu, "abuffer-counts", px * 4 * per_pixel_words);
        let offsets = if method == ABufferMethod::Linear {
            storage_buffer(gpu, "abuffer-offsets", px * 4)
        } else {
            dummy()
        };
        let cursor = match method {
            ABufferMethod::Linear => storage_buffer(gpu, "abuffer-cursor", px * 4),
            ABufferMethod::DualPeel => storage_buffer(gpu, "abuffer-interval-a", px * 8),
            _ => dummy(),
        };
        let interval_b = if method == ABufferMethod::DualPeel {
            storage_buffer(gpu, "abuffer-interval-b", px * 8)
        } else {
            dummy()
        };
        let stats = storage_buffer(gpu, "abuffer-stats", 16);
        let light_data: Vec<GpuLight> = if lights.is_empty() {
            vec![bytemuck::Zeroable::zeroed()]
        } else {
            lights.to_vec()
        };
        let lights_buf = {
            use wgpu::util::DeviceExt;
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("abuffer-lights"),
                contents: bytemuck::cast_slice(&light_data),
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let m = settings.compress.unwrap_or(0);
        let compressed = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("abuffer-compressed"),
            size: wgpu::Extent3d {
                width: if m > 0 { w } else { 1 },
                height: if m > 0 { h } else { 1 },
                depth_or_array_layers: (2 * m.div_ceil(4)).max(1),
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Uint,
            usage: wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let compressed_view = compressed.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let attachment = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("abuffer-attachment"),
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::R8Unorm,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&Default::default());

        // --- geometry passes
        let frag = wgpu::ShaderStages::FRAGMENT;
        let mut entries = vec![
            layout_entry(0, frag, UNIFORM_TY),
            layout_entry(1, frag, storage_ty(true)),
        ];
        for b in 2..=8 {
            entries.push(layout_entry(b, frag, storage_ty(false)));
        }
        let draw_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("abuffer-draw"),
            entries: &entries,
        });
        let params = |peel: u32| DrawParams {
            width: w,
            height: h,
            pool,
            slots,
            light_count: lights.len() as u32,
            peel,
            last_peel: settings.peels().saturating_sub(1),
            _pad: 0,
        };
        let draw_group = |peel: u32, cursor: &wgpu::Buffer, interval: &wgpu::Buffer| {
            let u = uniform_buffer(gpu, "abuffer-draw", &params(peel));
            crate::passes::bind_group(
                device,
                "abuffer-draw",
                &draw_layout,
                &[
                    u.as_entire_binding(),
                    lights_buf.as_entire_binding(),
                    nodes.as_entire_binding(),
                    links.as_entire_binding(),
                    counts.as_entire_binding(),
                    offsets.as_entire_binding(),
                    cursor.as_entire_binding(),
                    stats.as_entire_binding(),
                    interval.as_entire_binding(),
                ],
            )
        };
        let unused = dummy();
        let draw_groups = if method == ABufferMethod::DualPeel {
            // init writes interval A; peel p reads interval p % 2 and widens the other
            let bufs = [&cursor, &interval_b];
            let mut g = vec![draw_group(0, &cursor, &unused)];
            for p in 0..settings.peels() {
                g.push(draw_group(p, bufs[(p as usize + 1) % 2], bufs[p as usize % 2]));
            }
            g
        } else {
            vec![draw_group(0, &cursor, &unused)]
        };
        let draw_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("abuffer-draw"),
            bind_group_layouts: &[
                Some(&scene.frame_layout),
                Some(&scene.object_layout),
                Some(&scene.material_layout),
                Some(&draw_layout),
            ],
            immediate_size: 0,
        });
        let module = crate::shader::module(device, "abuffer", include_str!("abuffer.wgsl"));
        let geometry_pipeline = |entry: &str| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(entry),
                layout: Some(&draw_pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(VERTEX_LAYOUT)],
                },
                // every fragment: no culling, no depth test
                primitive: wgpu::PrimitiveState {
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: wgpu::TextureFormat::R8Unorm,
                        blend: None,
                        write_mask: wgpu::ColorWrites::empty(),
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let draw_pipeline = geometry_pipeline(match method {
            ABufferMethod::LinkedList => "fs_linked_list",
            ABufferMethod::Linear => "fs_linear",
            ABufferMethod::FixedArray => "fs_fixed_array",
            ABufferMethod::DualPeel => "fs_dual_init",
        });
        let count_pipeline = (method == ABufferMethod::Linear).then(|| geometry_pipeline("fs_count"));
        let peel_pipeline = (method == ABufferMethod::DualPeel).then(|| geometry_pipeline("fs_dual_peel"));

        // --- prefix sum (linear)
        let prefix = (method == ABufferMethod::Linear).then(|| {
            let comp = wgpu::ShaderStages::COMPUTE;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("abuffer-prefix-sum"),
                entries: &[
                    layout_entry(0, comp, UNIFORM_TY),
                    layout_entry(1, comp, storage_ty(true)),
                    layout_entry(2, comp, storage_ty(false)),
                ],
            });
            let u = uniform_buffer(gpu, "abuffer-prefix-sum", &[px as u32, 0, 0, 0]);
            let group = crate::passes::bind_group(
                device,
                "abuffer-prefix-sum",
                &layout,
                &[
                    u.as_entire_binding(),
                    counts.as_entire_binding(),
                    offsets.as_entire_binding(),
                ],
            );
            let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("abuffer-prefix-sum"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            let module = crate::shader::module(device, "abuffer-prefix-sum", include_str!("prefix_sum.wgsl"));
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("abuffer-prefix-sum"),
                layout: Some(&pl),
                module: &module,
                entry_point: Some("cs_main"),
                compilation_options: Default::default(),
                cache: None,
            });
            (pipeline, group)
        });

        // --- resolve
        let resolve_params = uniform_buffer(
            gpu,
            "abuffer-resolve",
            &ResolveParams {
                width: w,
                height: h,
                pool,
                slots,
                method: method.index(),
                compress: m,
                back_half: settings.compress_back_half as u32,
                _pad: 0,
                depth_scale: 1.0,
                _pad1: [0.0; 3],
            },
        );
        // lists.wgsl's group 1: parameters, nodes, links, counts, offsets
        // fragment (resolve, AO) and compute (§V-B HBAO) passes read them
        let frag_comp = frag | wgpu::ShaderStages::COMPUTE;
        let lists_entries = [
            layout_entry(0, frag_comp, UNIFORM_TY),
            layout_entry(1, frag_comp, storage_ty(true)),
            layout_entry(2, frag_comp, storage_ty(true)),
            layout_entry(3, frag_comp, storage_ty(true)),
            layout_entry(4, frag_comp, storage_ty(true)),
        ];
        let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("abuffer-resolve"),
            entries: &[
                lists_entries[0],
                lists_entries[1],
                lists_entries[2],
                lists_entries[3],
                lists_entries[4],
                layout_entry(
                    5,
                    frag,
                    wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: wgpu::TextureFormat::Rgba32Uint,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                    },
                ),
            ],
        });
        let resolve_group = crate::passes::bind_group(
            device,
            "abuffer-resolve",
            &resolve_layout,
            &[
                resolve_params.as_entire_binding(),
                nodes.as_entire_binding(),
                links.as_entire_binding(),
                counts.as_entire_binding(),
                offsets.as_entire_binding(),
                wgpu::BindingResource::TextureView(&compressed_view),
            ],
        );
        let resolve_pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("abuffer-resolve"),
            bind_group_layouts: &[Some(&scene.frame_layout), Some(&resolve_layout)],
            immediate_size: 0,
        });
        let resolve_module = crate::shader::module(device, "abuffer-resolve", include_str!("resolve.wgsl"));
        let resolve_pipeline = crate::passes::fullscreen_pipeline(
            device,
            "abuffer-resolve",
            &resolve_pl,
            &resolve_module,
            &crate::passes::color_targets(&[OUTPUT, COUNT]),
        );
        // --- multilayer AO (Algorithm 1), then the bilateral reconstruction
        let mut blur = Vec::new();
        let ao = settings.ao.as_ref().map(|a| {
            targets.create(gpu, AO_RAW);
            blur.extend(crate::passes::ao::stage::reconstruction(
                gpu,
                scene,
                targets,
                &a.blur,
                AO_RAW.name,
                "ao",
                false,
            ));
            let lists_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("aba-ao-lists"),
                entries: &lists_entries,
            });
            let lists_group = crate::passes::bind_group(
                device,
                "aba-ao-lists",
                &lists_layout,
                &[
                    resolve_params.as_entire_binding(),
                    nodes.as_entire_binding(),
                    links.as_entire_binding(),
                    counts.as_entire_binding(),
                    offsets.as_entire_binding(),
                ],
            );
            let ao_entries = [
                layout_entry(0, frag_comp, UNIFORM_TY),
                layout_entry(
                    1,
                    frag_comp,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Uint,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                ),
            ];
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("aba-ao"),
                entries: &ao_entries,
            });
            let uniforms = uniform_buffer(gpu, "aba-ao", &<ao::AbaAoUniforms as bytemuck::Zeroable>::zeroed());
            let group = crate::passes::bind_group(
                device,
                "aba-ao",
                &layout,
                &[
                    uniforms.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&compressed_view),
                ],
            );
            let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("aba-ao"),
                bind_group_layouts: &[Some(&scene.frame_layout), Some(&lists_layout), Some(&layout)],
                immediate_size: 0,
            });
            let module = crate::shader::module(device, "aba-ao", include_str!("aba_ao.wgsl"));
            let pipeline = if a.inside {
                targets.create(gpu, AO_INSIDE);
                targets.create(gpu, AO_SEPARATE);
                crate::passes::fullscreen_pipeline_with(
                    device,
                    "aba-ao",
                    &pl,
                    &module,
                    "fs_inside",
                    &[],
                    &crate::passes::color_targets(&[AO_RAW, AO_INSIDE, AO_SEPARATE]),
                )
            } else {
                crate::passes::fullscreen_pipeline(
                    device,
                    "aba-ao",
                    &pl,
                    &module,
                    &crate::passes::color_targets(&[AO_RAW]),
                )
            };
            // §V-B compute HBAO: writes a storage texture, copied into `ao-raw`
            let compute = (a.kernel == ao::AoKernel::HbaoCompute).then(|| {
                let out = gpu.device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("aba-ao-compute"),
                    size: wgpu::Extent3d {
                        width: w,
                        height: h,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: AO_RAW.format,
                    usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                });
                let out_view = out.create_view(&Default::default());
                let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("aba-ao-compute"),
                    entries: &[
                        ao_entries[0],
                        ao_entries[1],
                        crate::passes::builder::storage_texture_entry(2, AO_RAW.format),
                    ],
                });
                let group = crate::passes::bind_group(
                    device,
                    "aba-ao-compute",
                    &layout,
                    &[
                        uniforms.as_entire_binding(),
                        wgpu::BindingResource::TextureView(&compressed_view),
                        wgpu::BindingResource::TextureView(&out_view),
                    ],
                );
                let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("aba-ao-compute"),
                    bind_group_layouts: &[Some(&scene.frame_layout), Some(&lists_layout), Some(&layout)],
                    immediate_size: 0,
                });
                let module = crate::shader::module(device, "aba-ao-compute", include_str!("hbao_compute.wgsl"));
                let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some("aba-ao-compute"),
                    layout: Some(&pl),
                    module: &module,
                    entry_point: Some("cs_main"),
                    compilation_options: Default::default(),
                    cache: None,
                });
                ComputeAo { pipeline, group, out }
            });
            AoResources {
                inside: a.inside,
                pipeline,
                lists_group,
                group,
                uniforms,
                compute,
            }
        });
        let shared = Arc::new(Shared {
            settings: settings.clone(),
            width: w,
            height: h,
            pool,
            nodes,
            links,
            counts,
            offsets,
            cursor,
            interval_b,
            stats,
            compressed,
            resolve_params,
            attachment,
            count_pipeline,
            draw_pipeline,
            peel_pipeline,
            draw_groups,
            prefix,
            resolve_pipeline,
            resolve_group,
            ao,
        });
        let mut names = method.passes().to_vec();
        if settings.ao.is_some() {
            names.push("aba-ao");
        }
        let passes = names
            .iter()
            .map(|n| ABufferPass {
                kind: match *n {
                    "abuffer-clear" => Kind::Clear,
                    "abuffer-count" => Kind::Count,
                    "abuffer-prefix-sum" => Kind::PrefixSum,
                    "abuffer-draw" => Kind::Draw,
                    "aba-ao" => Kind::Ao,
                    _ => Kind::Resolve,
                },
                shared: shared.clone(),
            })
            .collect();
        Ok(Self {
            shared,
            passes,
            blur,
            depth_scale: std::cell::Cell::new(1.0),
            ao_uniforms: std::cell::Cell::new(None),
        })
    }

    /// The stage's passes in frame order.
    pub fn passes(&self) -> impl Iterator<Item = &dyn Pass> {
        self.passes
            .iter()
            .map(|p| p as &dyn Pass)
            .chain(self.blur.iter().map(|p| p as &dyn Pass))
    }

    /// Sets the multilayer AO's uniforms of the next frame (no-op without AO).
    pub fn set_ao_frame(&self, gpu: &GpuContext, u: ao::AbaAoUniforms) {
        if let Some(a) = &self.shared.ao {
            gpu.queue.write_buffer(&a.uniforms, 0, bytemuck::bytes_of(&u));
            self.ao_uniforms.set(Some(u));
        }
    }

    /// The multilayer AO's uniforms of the last frame (for the CPU twin).
    pub fn ao_uniforms(&self) -> Option<ao::AbaAoUniforms> {
        self.ao_uniforms.get()
    }

    pub fn settings(&self) -> &ABufferSettings {
        &self.shared.settings
    }

    /// Nodes in the pool (linked list, linear).
    pub fn pool(&self) -> u32 {
        self.shared.pool
    }

    /// Sets the frame's normalised-depth scale: 65535 / `far`, `far` the
    /// farthest camera-space depth of the scene (see [`compress`]).
    pub fn set_frame(&self, gpu: &GpuContext, far: f32) {
        self.depth_scale.set(depth_scale(far));
        let mut bytes = [0u8; 4];
        bytes.copy_from_slice(bytemuck::bytes_of(&depth_scale(far)));
        // depth_scale sits after 8 u32
        gpu.queue.write_buffer(&self.shared.resolve_params, 32, &bytes);
    }

    /// The normalised-depth scale of the last frame (z16 = ⌊min(csz · scale, 65535)⌋).
    pub fn depth_scale(&self) -> f32 {
        self.depth_scale.get()
    }

    /// Reads every pixel's list back, sorted as the resolve visits it; an
    /// ill-formed list (index outside the pool, a cycle, more nodes than
    /// room) is an error naming the pixel.
    pub fn read_lists(&self, gpu: &GpuContext) -> Result<FragmentLists, RenderError> {
        let s = &self.shared;
        let u32s = |b: &wgpu::Buffer| -> Result<Vec<u32>, RenderError> {
            Ok(bytemuck::cast_slice::<u8, u32>(&gpu.read_storage(b)?).to_vec())
        };
        let stats = u32s(&s.stats)?;
        let counts = u32s(&s.counts)?;
        let node_bytes = gpu.read_storage(&s.nodes)?;
        let nodes: &[GpuFragment] = bytemuck::cast_slice(&node_bytes);
        let (w, h) = (s.width, s.height);
        let px = (w * h) as usize;
        let pool = s.pool;
        let slots = s.settings.slots();
        let bad = |p: usize, what: String| {
            RenderError::Other(format!(
                "A-buffer list of pixel ({}, {}) is ill-formed: {what}",
                p % w as usize,
                p / w as usize
            ))
        };
        let mut lists = Vec::with_capacity(px);
        match s.settings.method {
            ABufferMethod::LinkedList => {
                let links = u32s(&s.links)?;
                let mut seen = vec![false; pool as usize];
                for (p, &head) in counts.iter().enumerate().take(px) {
                    let mut list = Vec::new();
                    let mut next = head;
                    while next != 0 {
                        if next > pool {
                            return Err(bad(p, format!("node {} is outside the pool of {pool}", next - 1)));
                        }
                        let i = (next - 1) as usize;
                        if seen[i] {
                            return Err(bad(p, format!("node {i} is reached twice (a cycle or a shared tail)")));
                        }
                        seen[i] = true;
                        list.push(StoredFragment::decode(i as u32, &nodes[i]));
                        next = links[i];
                    }
                    lists.push(list);
                }
            }
            ABufferMethod::Linear => {
                let offsets = u32s(&s.offsets)?;
                let mut expected = 0u64;
                for p in 0..px {
                    if offsets[p] as u64 != expected {
                        return Err(bad(
                            p,
                            format!("offset {} is not the prefix sum {expected}", offsets[p]),
                        ));
                    }
                    expected += counts[p] as u64;
                    let o = offsets[p].min(pool);
                    let n = counts[p].min(pool - o);
                    lists.push(
                        (o..o + n)
                            .map(|i| StoredFragment::decode(i, &nodes[i as usize]))
                            .collect(),
                    );
                }
            }
            ABufferMethod::FixedArray => {
                for (p, &c) in counts.iter().enumerate().take(px) {
                    let base = p as u32 * slots;
                    lists.push(
                        (base..base + c.min(slots))
                            .map(|i| StoredFragment::decode(i, &nodes[i as usize]))
                            .collect(),
                    );
                }
            }
            ABufferMethod::DualPeel => {
                for p in 0..px {
                    let (f, b) = (counts[2 * p], counts[2 * p + 1]);
                    let (nf, nb) = (f.count_ones(), b.count_ones());
                    // the peels fill layers 0, 1, … without gaps
                    let full = |n: u32| ((1u64 << n) - 1) as u32;
                    if f != full(nf) || b != full(nb) {
                        return Err(bad(p, format!("peeled layers {f:#b} / {b:#b} have gaps")));
                    }
                    if nf + nb > slots {
                        return Err(bad(p, format!("{} layers in {slots} slots", nf + nb)));
                    }
                    let base = p as u32 * slots;
                    let list: Vec<StoredFragment> = (0..nf)
                        .map(|k| base + k)
                        .chain((0..nb).map(|k| base + slots - 1 - k))
                        .map(|i| StoredFragment::decode(i, &nodes[i as usize]))
                        .collect();
                    lists.push(list);
                }
            }
        }
        for l in &mut lists {
            l.sort_by_key(|a| (a.depth.to_bits(), a.node));
        }
        Ok(FragmentLists {
            width: w,
            height: h,
            lists,
            overflow: stats[1],
            total: stats[2],
        })
    }

    /// The compressed lists (Eq. 5) as packed words, M per pixel (row-major);
    /// `None` without compression.
    pub fn read_compressed(&self, gpu: &GpuContext) -> Result<Option<Vec<Vec<u32>>>, RenderError> {
        self.read_compressed_layers(gpu, 0)
    }

    /// The compressed nodes' normal and facing words (the fragment's
    /// `normal_facing`; 0 for an empty node), M per pixel, in node order.
    pub fn read_compressed_normals(&self, gpu: &GpuContext) -> Result<Option<Vec<Vec<u32>>>, RenderError> {
        let first = self.shared.settings.compress.map_or(0, |m| m.div_ceil(4));
        self.read_compressed_layers(gpu, first)
    }

    fn read_compressed_layers(&self, gpu: &GpuContext, first: u32) -> Result<Option<Vec<Vec<u32>>>, RenderError> {
        let s = &self.shared;
        let Some(m) = s.settings.compress else {
            return Ok(None);
        };
        let px = (s.width * s.height) as usize;
        let mut out = vec![Vec::with_capacity(m as usize); px];
        for l in 0..m.div_ceil(4) {
            let bytes = gpu.read_texture(&s.compressed, first + l)?;
            let words: &[u32] = bytemuck::cast_slice(&bytes);
            for (p, o) in out.iter_mut().enumerate() {
                for e in 0..4 {
                    if l * 4 + e < m {
                        o.push(words[p * 4 + e as usize]);
                    }
                }
            }
        }
        Ok(Some(out))
    }
}

/// 65534 / `far` (the scale of the 16-bit normalised depth): the farthest
/// geometry maps to 65534, below the empty nodes' 65535, so Eq. 5's metric
/// α·(65535 − z) of any real fragment is > 0 and an empty node is evicted
/// first (with 65535 / far an opaque fragment at the far bound scored 0 and,
/// losing the tie, evicted itself: found by the multilayer AO tests).
pub fn depth_scale(far: f32) -> f32 {
    65534.0 / far
}

/// The farthest camera-space depth of any point of `scene` at `frame` seen by
/// `camera` (a corner of the bounding box), at least twice the near plane.
pub fn far_depth(scene: &strata_scene::Scene, camera: &strata_scene::Camera, frame: f32) -> f32 {
    let (lo, hi) = scene.bounds(frame);
    let (_, _, f) = camera.basis();
    let mut far = 2.0 * camera.near;
    for i in 0..8 {
        let c = glam::Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let z = (c - camera.eye).dot(f);
        if z.is_finite() {
            far = far.max(z);
        }
    }
    far
}

impl ABufferPass {
    fn name(&self) -> &'static str {
        match self.kind {
            Kind::Clear => "abuffer-clear",
            Kind::Count => "abuffer-count",
            Kind::PrefixSum => "abuffer-prefix-sum",
            Kind::Draw => "abuffer-draw",
            Kind::Resolve => "abuffer-resolve",
            Kind::Ao => "aba-ao",
        }
    }

    fn geometry(
        &self,
        scene: &GpuScene,
        encoder: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::RenderPipeline,
        group: &wgpu::BindGroup,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(self.name()),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.shared.attachment,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Discard,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &scene.frame_bind_group, &[]);
        pass.set_bind_group(3, group, &[]);
        scene.draw_all(&mut pass, 1, Some(2));
    }
}

impl Pass for ABufferPass {
    fn info(&self) -> PassInfo {
        let (inputs, outputs) = match self.kind {
            Kind::Clear => (vec![], vec!["abuffer"]),
            Kind::Count => (vec!["scene", "abuffer"], vec!["abuffer-counts"]),
            Kind::PrefixSum => (vec!["abuffer-counts"], vec!["abuffer-offsets"]),
            Kind::Draw => (vec!["scene", "abuffer"], vec!["abuffer-lists"]),
            Kind::Resolve => (vec!["abuffer-lists"], vec![OUTPUT.name, COUNT.name]),
            Kind::Ao => (
                vec!["abuffer-lists"],
                if self.shared.ao.as_ref().is_some_and(|a| a.inside) {
                    vec![AO_RAW.name, AO_INSIDE.name, AO_SEPARATE.name]
                } else {
                    vec![AO_RAW.name]
                },
            ),
        };
        PassInfo {
            name: self.name(),
            inputs,
            outputs,
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let s = &*self.shared;
        match self.kind {
            Kind::Clear => {
                encoder.clear_buffer(&s.stats, 0, None);
                encoder.clear_buffer(&s.counts, 0, None);
                if matches!(s.settings.method, ABufferMethod::Linear | ABufferMethod::DualPeel) {
                    encoder.clear_buffer(&s.cursor, 0, None);
                }
            }
            Kind::Count => {
                let p = s.count_pipeline.as_ref().expect("linear lists count");
                self.geometry(scene, encoder, p, &s.draw_groups[0]);
            }
            Kind::PrefixSum => {
                let (pipeline, group) = s.prefix.as_ref().expect("linear lists scan");
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("abuffer-prefix-sum"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(1, 1, 1);
            }
            Kind::Draw => {
                self.geometry(scene, encoder, &s.draw_pipeline, &s.draw_groups[0]);
                if let Some(peel) = &s.peel_pipeline {
                    for p in 0..s.settings.peels() as usize {
                        // the interval this peel widens starts empty
                        let next = if p % 2 == 0 { &s.interval_b } else { &s.cursor };
                        encoder.clear_buffer(next, 0, None);
                        self.geometry(scene, encoder, peel, &s.draw_groups[p + 1]);
                    }
                }
            }
            Kind::Resolve => {
                let out = &targets.get(OUTPUT.name).view;
                let count = &targets.get(COUNT.name).view;
                crate::passes::fullscreen_pass(
                    encoder,
                    "abuffer-resolve",
                    &s.resolve_pipeline,
                    &[out, count],
                    &[&scene.frame_bind_group, &s.resolve_group],
                );
            }
            Kind::Ao => {
                let a = s.ao.as_ref().expect("the stage has AO");
                if let Some(c) = &a.compute {
                    {
                        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                            label: Some("aba-ao"),
                            timestamp_writes: None,
                        });
                        pass.set_pipeline(&c.pipeline);
                        pass.set_bind_group(0, &scene.frame_bind_group, &[]);
                        pass.set_bind_group(1, &a.lists_group, &[]);
                        pass.set_bind_group(2, &c.group, &[]);
                        pass.dispatch_workgroups(s.width.div_ceil(ao::TILE), s.height.div_ceil(ao::TILE), 1);
                    }
                    encoder.copy_texture_to_texture(
                        c.out.as_image_copy(),
                        targets.get(AO_RAW.name).texture.as_image_copy(),
                        wgpu::Extent3d {
                            width: s.width,
                            height: s.height,
                            depth_or_array_layers: 1,
                        },
                    );
                    return;
                }
                let mut views = vec![&targets.get(AO_RAW.name).view];
                if a.inside {
                    views.extend([&targets.get(AO_INSIDE.name).view, &targets.get(AO_SEPARATE.name).view]);
                }
                crate::passes::fullscreen_pass(
                    encoder,
                    "aba-ao",
                    &a.pipeline,
                    &views,
                    &[&scene.frame_bind_group, &a.lists_group, &a.group],
                );
            }
        }
    }
}
