//! The examples' "application": its device, its boxes, and its own G-buffer, drawn with plain
//! wgpu: hardware depth and a normal texture from world-space triangles; DGB's second
//! layer, peeled with a minimum separation (§2); and, lit by a sun without shadows, each
//! layer's albedo, material (glTF's roughness in g, metallic in b) and outgoing diffuse
//! radiance. Nothing here is strata's; the `embed_*` examples and `tests/embed*.rs` draw
//! their G-buffers with it.
// three examples and three tests share this file, each using part of it
#![allow(dead_code)]

use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

/// How the normal texture stores the normal (the shader's `mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normals {
    /// World-space xyz, signed.
    WorldSigned,
    /// View-space xyz · ½ + ½.
    ViewUnsigned,
    /// View-space xyz, signed.
    ViewSigned,
}

/// The G-buffer's formats and conventions.
#[derive(Clone, Copy, Debug)]
pub struct Layout {
    pub depth: wgpu::TextureFormat,
    pub normal: wgpu::TextureFormat,
    pub normals: Normals,
    /// Depth cleared to 0 and tested with `Greater` (reversed z), else cleared to 1, `Less`.
    pub reversed: bool,
}

impl Layout {
    /// `Depth32Float` with standard depth, signed world normals in `Rgba16Float`.
    pub fn standard() -> Self {
        Self {
            depth: wgpu::TextureFormat::Depth32Float,
            normal: wgpu::TextureFormat::Rgba16Float,
            normals: Normals::WorldSigned,
            reversed: false,
        }
    }
}

/// The application's device on the first adapter wgpu finds (lavapipe where there is no
/// GPU), with `features` and, where the adapter has them, timestamps inside encoders (so
/// that strata can report its passes' GPU time).
pub fn open_device(
    features: wgpu::Features,
) -> Result<(wgpu::Adapter, wgpu::Device, wgpu::Queue), Box<dyn std::error::Error>> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let timing = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: features | (adapter.features() & timing),
        ..Default::default()
    }))?;
    Ok((adapter, device, queue))
}

/// A surface's material: diffuse albedo (a metal's F0), roughness and metallic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    pub albedo: Vec3,
    pub roughness: f32,
    pub metallic: f32,
}

impl Surface {
    /// A polished metal: metallic 1, roughness 0, F0 = `albedo`.
    pub fn mirror(albedo: Vec3) -> Self {
        Self {
            albedo,
            roughness: 0.0,
            metallic: 1.0,
        }
    }
}

impl From<Vec3> for Surface {
    /// A rough dielectric of diffuse albedo `albedo`.
    fn from(albedo: Vec3) -> Self {
        Self {
            albedo,
            roughness: 1.0,
            metallic: 0.0,
        }
    }
}

/// A box's 12 triangles of one surface (outward normals, counter-clockwise from outside).
pub fn cuboid(lo: Vec3, hi: Vec3, surface: impl Into<Surface>) -> Vec<Triangle> {
    let surface = surface.into();
    let c = |i: usize| {
        Vec3::new(
            if i & 1 != 0 { hi.x } else { lo.x },
            if i & 2 != 0 { hi.y } else { lo.y },
            if i & 4 != 0 { hi.z } else { lo.z },
        )
    };
    // each face: four corners counter-clockwise from outside, and its normal
    let faces = [
        ([0, 4, 6, 2], -Vec3::X),
        ([1, 3, 7, 5], Vec3::X),
        ([0, 1, 5, 4], -Vec3::Y),
        ([2, 6, 7, 3], Vec3::Y),
        ([0, 2, 3, 1], -Vec3::Z),
        ([4, 5, 7, 6], Vec3::Z),
    ];
    faces
        .iter()
        .flat_map(|(q, n)| {
            let p = q.map(c);
            [
                ([p[0], p[1], p[2]], [*n; 3], surface),
                ([p[0], p[2], p[3]], [*n; 3], surface),
            ]
        })
        .collect()
}

/// The GI examples' scene: an open box (a red wall on the left, a green one on the right,
/// a white floor and back wall) around two white blocks, a sun without shadows from the
/// right and above (it lights the red wall, the floor and the blocks' right faces), and
/// the camera looking in, for a `width`×`height` frame: triangles, sun, view, projection.
pub fn open_box(width: u32, height: u32) -> (Vec<Triangle>, Sun, Mat4, Mat4) {
    let (white, red, green) = (
        Vec3::splat(0.75),
        Vec3::new(0.75, 0.08, 0.06),
        Vec3::new(0.1, 0.6, 0.12),
    );
    let mut triangles = cuboid(Vec3::new(-2.0, -0.1, -2.0), Vec3::new(2.0, 0.0, 2.0), white);
    triangles.extend(cuboid(Vec3::new(-2.0, 0.0, -2.0), Vec3::new(-1.9, 2.0, 2.0), red));
    triangles.extend(cuboid(Vec3::new(1.9, 0.0, -2.0), Vec3::new(2.0, 2.0, 2.0), green));
    triangles.extend(cuboid(Vec3::new(-1.9, 0.0, -2.0), Vec3::new(1.9, 2.0, -1.9), white));
    triangles.extend(cuboid(Vec3::new(-1.2, 0.0, -1.0), Vec3::new(-0.4, 0.8, -0.2), white));
    triangles.extend(cuboid(Vec3::new(0.4, 0.0, -1.3), Vec3::new(1.0, 1.4, -0.7), white));
    let sun = Sun {
        direction: Vec3::new(1.0, 0.8, 0.2),
        irradiance: Vec3::splat(4.0),
    };
    use glam::camera::rh;
    let view = rh::view::look_at_mat4(Vec3::new(0.0, 1.4, 4.2), Vec3::new(0.0, 0.7, -0.5), Vec3::Y);
    let proj = rh::proj::directx::perspective(45f32.to_radians(), width as f32 / height as f32, 0.05, 50.0);
    (triangles, sun, view, proj)
}

/// The GI examples' application around [`open_box`]: its device, both lit layers, the
/// camera, and strata's `EmbeddedRadiosity` (2 layers, gather radius 2, Δz = 0.3).
pub struct OpenBox {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter: wgpu::Adapter,
    pub first: GBuffer,
    pub second: GBuffer,
    pub view: Mat4,
    pub proj: Mat4,
    pub gi: strata_render::embed::EmbeddedRadiosity,
}

impl OpenBox {
    pub fn new(width: u32, height: u32) -> Result<Self, Box<dyn std::error::Error>> {
        use strata_render::embed::{EmbeddedRadiosity, EmbeddedRadiosityConfig, NormalEncoding};
        // the radiosity buffers are R11G11B10 render targets (DGB Table 1)
        let (adapter, device, queue) = open_device(wgpu::Features::RG11B10UFLOAT_RENDERABLE)?;
        let (triangles, sun, view, proj) = open_box(width, height);
        let first = GBuffer::lit(&device, [width, height], Layout::standard(), &triangles, sun);
        let second = GBuffer::second_layer_lit(&device, &first, 0.3, &triangles);
        let gi = EmbeddedRadiosity::new(
            &adapter,
            &device,
            &queue,
            EmbeddedRadiosityConfig {
                width,
                height,
                layers: 2,
                settings: strata_render::passes::radiosity::RadiositySettings {
                    radius: Some(2.0),
                    ..Default::default()
                },
                min_separation: 0.3,
                normals: NormalEncoding::Signed,
                ..EmbeddedRadiosityConfig::default()
            },
        )?;
        Ok(Self {
            device,
            queue,
            adapter,
            first,
            second,
            view,
            proj,
            gi,
        })
    }

    /// One frame: draws both layers, records the radiosity, then `more` with layer 0's
    /// inputs into the same encoder, and submits it.
    pub fn frame(
        &mut self,
        more: impl FnOnce(
            &mut wgpu::CommandEncoder,
            &strata_render::embed::AoInputs<'_>,
        ) -> Result<(), strata_render::RenderError>,
    ) -> Result<(), Box<dyn std::error::Error>> {
        let (view, proj) = (self.view, self.proj);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        self.first.draw(&self.queue, &mut encoder, view, proj);
        self.second.draw(&self.queue, &mut encoder, view, proj);
        let (a0, b0) = self.first.shading.as_ref().ok_or("lit")?;
        let (a1, b1) = self.second.shading.as_ref().ok_or("lit")?;
        let layer0 = self.first.inputs(view, proj);
        let inputs = strata_render::embed::RadiosityInputs {
            gbuffer: strata_render::embed::AoInputs {
                second: Some(((&self.second.depth).into(), (&self.second.normals).into())),
                ..layer0
            },
            albedo: a0.into(),
            radiance: b0.into(),
            second: Some((a1.into(), b1.into())),
        };
        self.gi.encode(&mut encoder, &inputs)?;
        more(&mut encoder, &layer0)?;
        self.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// The application's composite, on the CPU from the embedded radiosity's imported
    /// copies of its albedo ρ and radiance B: one panel per entry, side by side, each
    /// B + ρ/π · E with that entry's irradiance E (`None`: B alone).
    pub fn composite(
        &self,
        panels: &[Option<&strata_scene::ImageBuf>],
    ) -> Result<image::RgbImage, strata_render::RenderError> {
        let (albedo, b) = (self.gi.read_target("albedo")?, self.gi.read_target("radiosity0")?);
        let (w, h) = (b.width, b.height);
        let mut img = image::RgbImage::new(panels.len() as u32 * w, h);
        for y in 0..h {
            for x in 0..w {
                let (pa, pb) = (albedo.pixel(x, y), b.pixel(x, y));
                for (panel, e) in panels.iter().enumerate() {
                    for k in 0..3 {
                        let indirect = e.map_or(0.0, |e| pa[k] / std::f32::consts::PI * e.pixel(x, y)[k]);
                        img.get_pixel_mut(panel as u32 * w + x, y)[k] = display(pb[k] + indirect);
                    }
                }
            }
        }
        Ok(img)
    }
}

/// Linear → 8-bit sRGB of a value tone-mapped by v / (1 + v): the examples' PNGs.
pub fn display(v: f32) -> u8 {
    let x = (v / (1.0 + v)).clamp(0.0, 1.0);
    let s = if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// Prints strata's per-pass GPU times, where the device measured them.
pub fn print_timings(t: &strata_render::PassTimings) {
    if !t.passes.is_empty() {
        let each: Vec<String> = t.passes.iter().map(|(n, ms)| format!("{n} {ms:.2}")).collect();
        println!("GPU ms, last frame: {} (total {:.2})", each.join(", "), t.total());
    }
}

/// A directional light without shadows: the application's whole direct lighting here.
#[derive(Clone, Copy, Debug)]
pub struct Sun {
    /// Towards the light.
    pub direction: Vec3,
    /// Irradiance on a surface facing it (rgb).
    pub irradiance: Vec3,
}

/// A triangle: world-space corners, their normals, and its surface.
pub type Triangle = ([Vec3; 3], [Vec3; 3], Surface);

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Uniforms {
    view_proj: [[f32; 4]; 4],
    view: [[f32; 4]; 4],
    inv_proj: [[f32; 4]; 4],
    /// x: the normals' mode, y: 1 = reversed depth
    mode: [u32; 4],
    /// x: the minimum separation Δz, y: 1 = peel behind the first layer
    peel: [f32; 4],
    /// xyz: towards the sun
    sun_direction: [f32; 4],
    /// rgb: the sun's irradiance
    sun: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    albedo: [f32; 3],
    /// roughness, metallic
    material: [f32; 2],
}

const SHADER: &str = r#"
struct U {
    view_proj: mat4x4f, view: mat4x4f, inv_proj: mat4x4f, mode: vec4u, peel: vec4f,
    sun_direction: vec4f, sun: vec4f,
}
@group(0) @binding(0) var<uniform> u: U;
@group(0) @binding(1) var first_depth: texture_depth_2d;
// csz: the distance in front of the (right-handed) camera
struct V {
    @builtin(position) pos: vec4f, @location(0) n: vec3f, @location(1) csz: f32,
    @location(2) albedo: vec3f, @location(3) material: vec2f,
}
@vertex fn vs(
    @location(0) p: vec3f, @location(1) n: vec3f, @location(2) albedo: vec3f, @location(3) material: vec2f,
) -> V {
    return V(u.view_proj * vec4f(p, 1.0), n, -(u.view * vec4f(p, 1.0)).z, albedo, material);
}
// the second layer (DGB §2): the nearest surface more than Δz behind the first layer's
fn behind_first(v: V) -> bool {
    let d0 = textureLoad(first_depth, vec2i(v.pos.xy), 0);
    if (select(d0 >= 1.0, d0 <= 0.0, u.mode.y != 0u)) {
        return false;
    }
    let uv = v.pos.xy / vec2f(textureDimensions(first_depth));
    let q = u.inv_proj * vec4f(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, d0, 1.0);
    let z0 = -q.z / q.w;
    // within 1e-4·z0 of the first layer is the first layer's own surface
    return v.csz > z0 + u.peel.x + 1e-4 * z0;
}
// two-sided: a back face's normal points towards the viewer
fn world_normal(v: V, front: bool) -> vec3f {
    return normalize(v.n) * select(-1.0, 1.0, front);
}
@fragment fn fs(v: V, @builtin(front_facing) front: bool) -> @location(0) vec4f {
    if (u.peel.y != 0.0 && !behind_first(v)) {
        discard;
    }
    return encoded(world_normal(v, front));
}
struct Lit {
    @location(0) normal: vec4f, @location(1) albedo: vec4f, @location(2) radiance: vec4f,
    @location(3) material: vec4f,
}
// the G-buffer and the sun's Lambertian outgoing radiance B = (1 − metallic) ρ/π · E ·
// max(0, n·l) (a metal reflects only specularly); the material as glTF's (1, roughness,
// metallic)
@fragment fn fs_lit(v: V, @builtin(front_facing) front: bool) -> Lit {
    if (u.peel.y != 0.0 && !behind_first(v)) {
        discard;
    }
    let n = world_normal(v, front);
    let diffuse = v.albedo * (1.0 - v.material.y);
    let b = diffuse / 3.14159265 * u.sun.rgb * max(dot(n, u.sun_direction.xyz), 0.0);
    return Lit(encoded(n), vec4f(v.albedo, 1.0), vec4f(b, 1.0), vec4f(1.0, v.material, 1.0));
}
fn encoded(world: vec3f) -> vec4f {
    var n = world;
    if (u.mode.x != 0u) {
        n = (u.view * vec4f(n, 0.0)).xyz;
    }
    if (u.mode.x == 1u) {
        return vec4f(n * 0.5 + 0.5, 1.0);
    }
    return vec4f(n, 1.0);
}
"#;

/// Depth and normal textures (and, lit, albedo and radiance) and the pipeline that fills them.
pub struct GBuffer {
    pub depth: wgpu::Texture,
    pub normals: wgpu::Texture,
    /// Lit G-buffers: diffuse albedo (`Rgba8UnormSrgb`) and outgoing diffuse radiance
    /// (`Rgba16Float`).
    pub shading: Option<(wgpu::Texture, wgpu::Texture)>,
    /// Lit G-buffers: the material (`Rgba8Unorm`; g = roughness, b = metallic, as glTF).
    pub material: Option<wgpu::Texture>,
    sun: Option<Sun>,
    layout: Layout,
    /// Peeling behind another G-buffer's depth: Δz.
    min_separation: Option<f32>,
    pipeline: wgpu::RenderPipeline,
    uniforms: wgpu::Buffer,
    group: wgpu::BindGroup,
    vertices: wgpu::Buffer,
    count: u32,
}

impl GBuffer {
    /// The first layer of `triangles` (their albedo is not read).
    pub fn new(device: &wgpu::Device, size: [u32; 2], layout: Layout, triangles: &[Triangle]) -> Self {
        Self::build(device, size, layout, triangles, None, None)
    }

    /// The first layer of `triangles`, lit by `sun`: also albedo and radiance.
    pub fn lit(device: &wgpu::Device, size: [u32; 2], layout: Layout, triangles: &[Triangle], sun: Sun) -> Self {
        Self::build(device, size, layout, triangles, None, Some(sun))
    }

    /// The second layer behind `first`, lit as `first` is.
    pub fn second_layer_lit(
        device: &wgpu::Device,
        first: &GBuffer,
        min_separation: f32,
        triangles: &[Triangle],
    ) -> Self {
        let size = [first.depth.width(), first.depth.height()];
        let behind = Some((&first.depth, min_separation));
        Self::build(device, size, first.layout, triangles, behind, first.sun)
    }

    /// The second layer behind `first`: the nearest surfaces more than `min_separation`
    /// behind it (draw `first` before it, with the same camera, each frame).
    pub fn second_layer(device: &wgpu::Device, first: &GBuffer, min_separation: f32, triangles: &[Triangle]) -> Self {
        let size = [first.depth.width(), first.depth.height()];
        let behind = Some((&first.depth, min_separation));
        Self::build(device, size, first.layout, triangles, behind, None)
    }

    fn build(
        device: &wgpu::Device,
        size: [u32; 2],
        layout: Layout,
        triangles: &[Triangle],
        first: Option<(&wgpu::Texture, f32)>,
        sun: Option<Sun>,
    ) -> Self {
        let texture = |label, format| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: size[0],
                    height: size[1],
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                // TEXTURE_BINDING: strata's AO reads both
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        let depth = texture("app-depth", layout.depth);
        let normals = texture("app-normals", layout.normal);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("app-gbuffer"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("app-gbuffer"),
            size: std::mem::size_of::<Uniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("app-gbuffer"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        // the first layer's depth, or (drawing the first layer) one it does not read
        let unused = (first.is_none()).then(|| texture("app-unused", layout.depth));
        let first_depth = first
            .map(|f| f.0)
            .or(unused.as_ref())
            .expect("one of them")
            .create_view(&Default::default());
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("app-gbuffer"),
            layout: &group_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&first_depth),
                },
            ],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("app-gbuffer"),
            bind_group_layouts: &[Some(&group_layout)],
            immediate_size: 0,
        });
        let mut targets = vec![Some(layout.normal.into())];
        if sun.is_some() {
            targets.push(Some(wgpu::TextureFormat::Rgba8UnormSrgb.into()));
            targets.push(Some(wgpu::TextureFormat::Rgba16Float.into()));
            targets.push(Some(wgpu::TextureFormat::Rgba8Unorm.into()));
        }
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("app-gbuffer"),
            layout: Some(&pl),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<Vertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![
                        0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x2
                    ],
                })],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: layout.depth,
                depth_write_enabled: Some(true),
                depth_compare: Some(if layout.reversed {
                    wgpu::CompareFunction::Greater
                } else {
                    wgpu::CompareFunction::Less
                }),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(if sun.is_some() { "fs_lit" } else { "fs" }),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        });
        let verts: Vec<Vertex> = triangles
            .iter()
            .flat_map(|(p, n, surface)| {
                (0..3).map(move |k| Vertex {
                    position: p[k].to_array(),
                    normal: n[k].to_array(),
                    albedo: surface.albedo.to_array(),
                    material: [surface.roughness, surface.metallic],
                })
            })
            .collect();
        let shading = sun.map(|_| {
            (
                texture("app-albedo", wgpu::TextureFormat::Rgba8UnormSrgb),
                texture("app-radiance", wgpu::TextureFormat::Rgba16Float),
            )
        });
        let material = sun.map(|_| texture("app-material", wgpu::TextureFormat::Rgba8Unorm));
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("app-triangles"),
            contents: bytemuck::cast_slice(&verts),
            usage: wgpu::BufferUsages::VERTEX,
        });
        Self {
            depth,
            normals,
            shading,
            material,
            sun,
            layout,
            min_separation: first.map(|f| f.1),
            pipeline,
            uniforms,
            group,
            vertices,
            count: verts.len() as u32,
        }
    }

    /// This layer's depth and normals as strata's embedded techniques take them.
    pub fn inputs(&self, view: Mat4, proj: Mat4) -> strata_render::embed::AoInputs<'_> {
        strata_render::embed::AoInputs::new((&self.depth).into(), (&self.normals).into(), view, proj)
    }

    /// Draws the triangles with `view` and `proj` into the depth and normal textures.
    pub fn draw(&self, queue: &wgpu::Queue, encoder: &mut wgpu::CommandEncoder, view: Mat4, proj: Mat4) {
        let mode = match self.layout.normals {
            Normals::WorldSigned => 0,
            Normals::ViewUnsigned => 1,
            Normals::ViewSigned => 2,
        };
        let u = Uniforms {
            view_proj: (proj * view).to_cols_array_2d(),
            view: view.to_cols_array_2d(),
            inv_proj: proj.inverse().to_cols_array_2d(),
            mode: [mode, self.layout.reversed as u32, 0, 0],
            peel: [
                self.min_separation.unwrap_or(0.0),
                self.min_separation.is_some() as u32 as f32,
                0.0,
                0.0,
            ],
            sun_direction: self
                .sun
                .map_or(Vec3::ZERO, |s| s.direction.normalize())
                .extend(0.0)
                .to_array(),
            sun: self.sun.map_or(Vec3::ZERO, |s| s.irradiance).extend(0.0).to_array(),
        };
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        let mut views = vec![self.normals.create_view(&Default::default())];
        if let Some((albedo, radiance)) = &self.shading {
            views.push(albedo.create_view(&Default::default()));
            views.push(radiance.create_view(&Default::default()));
        }
        if let Some(material) = &self.material {
            views.push(material.create_view(&Default::default()));
        }
        let attachments: Vec<_> = views
            .iter()
            .map(|view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect();
        let depth = self.depth.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("app-gbuffer"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(if self.layout.reversed { 0.0 } else { 1.0 }),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.draw(0..self.count, 0..1);
    }
}

/// A strata scene's triangles at frame 0 with their materials: the tests draw strata's
/// scenes as an application would.
pub fn scene_triangles(scene: &strata_scene::Scene) -> Vec<Triangle> {
    scene
        .world_triangles(0.0)
        .iter()
        .map(|t| {
            let m = &scene.materials[t.material as usize];
            let surface = Surface {
                albedo: Vec3::from(m.base_color),
                roughness: m.roughness,
                metallic: m.metallic,
            };
            (t.p, t.n, surface)
        })
        .collect()
}
