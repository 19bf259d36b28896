//! Scene upload: vertex/index buffers, materials (uniforms + textures), per-object
//! transforms for the current and previous frame, the per-frame uniform buffer.

use glam::Mat4;
use strata_scene::Scene;
use wgpu::util::DeviceExt;

use crate::frame::FrameUniforms;
use crate::gpu::GpuContext;

/// Interleaved vertex: position, normal, uv (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
}

pub const VERTEX_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 32,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2],
};

/// Per-object constants (`ObjectUniforms` in WGSL), one 256-byte slot each.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ObjectUniforms {
    pub model: [[f32; 4]; 4],
    /// Inverse-transpose of the model matrix (upper 3×3 used).
    pub normal_matrix: [[f32; 4]; 4],
    pub prev_model: [[f32; 4]; 4],
    /// Transform at frame t + 1 (exact or extrapolated, see [`NextTransforms`]).
    pub next_model: [[f32; 4]; 4],
}

/// How the frame-(t + 1) object transforms are obtained (DGB §2.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NextTransforms {
    /// The animation's own transform at t + 1 (the DELAY variant knows the future).
    Exact,
    /// Constant-velocity extrapolation from t − 1 and t: M_{t+1} = M_t · M_{t−1}⁻¹ · M_t
    /// (PREDICT).
    Extrapolated,
}
pub const OBJECT_STRIDE: u64 = 256;

/// Material constants (`MaterialUniforms` in WGSL).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MaterialUniforms {
    /// rgb linear base colour, a = opacity
    pub base_color: [f32; 4],
    /// rgb emitted radiance, w = 1 when the texture's alpha multiplies the opacity
    pub emission: [f32; 4],
    /// roughness, metallic, has_texture (0/1), alpha cutoff (< 0: none)
    pub params: [f32; 4],
    /// x = 1 for `Material::glossy` (the GGX receivers of ILS), yzw unused
    pub flags: [f32; 4],
}

pub struct GpuMesh {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub index_count: u32,
    pub material: usize,
}

pub struct GpuScene {
    pub meshes: Vec<GpuMesh>,
    /// (mesh index) per object, in `Scene::objects` order.
    pub object_meshes: Vec<usize>,
    pub object_buffer: wgpu::Buffer,
    pub object_layout: wgpu::BindGroupLayout,
    pub object_bind_group: wgpu::BindGroup,
    pub material_layout: wgpu::BindGroupLayout,
    pub material_bind_groups: Vec<wgpu::BindGroup>,
    pub frame_buffer: wgpu::Buffer,
    pub frame_layout: wgpu::BindGroupLayout,
    pub frame_bind_group: wgpu::BindGroup,
    objects_cpu: Vec<strata_scene::Object>,
}

impl GpuScene {
    pub fn new(gpu: &GpuContext, scene: &Scene) -> Self {
        let device = &gpu.device;
        let meshes = scene
            .meshes
            .iter()
            .map(|m| {
                let verts: Vec<Vertex> = (0..m.positions.len())
                    .map(|i| Vertex {
                        position: m.positions[i],
                        normal: m.normals[i],
                        uv: m.uvs[i],
                    })
                    .collect();
                GpuMesh {
                    vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(&m.name),
                        contents: bytemuck::cast_slice(&verts),
                        // COPY_DST: an application's occluders are rewritten in place
                        // (`embed::EmbeddedIls::set_triangles`)
                        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                    }),
                    indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(&m.name),
                        contents: bytemuck::cast_slice(&m.indices),
                        usage: wgpu::BufferUsages::INDEX,
                    }),
                    index_count: m.indices.len() as u32,
                    material: m.material,
                }
            })
            .collect();

        let object_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("object"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<ObjectUniforms>() as u64),
                },
                count: None,
            }],
        });
        let object_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("objects"),
            size: OBJECT_STRIDE * scene.objects.len().max(1) as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let object_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("objects"),
            layout: &object_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &object_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<ObjectUniforms>() as u64),
                }),
            }],
        });

        let material_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("material"),
            entries: &[
                crate::passes::uniform_entry(0),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("material"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            // floors and walls at grazing angles keep their texture detail (as the path
            // tracer's per-pixel average does; docs/deep-gbuffer.md)
            anisotropy_clamp: 16,
            ..Default::default()
        });
        let textures: Vec<wgpu::TextureView> = scene.textures.iter().map(|t| upload_texture(gpu, t)).collect();
        let white = upload_texture(
            gpu,
            &strata_scene::Texture {
                name: "white".into(),
                width: 1,
                height: 1,
                rgba8: vec![255; 4],
            },
        );
        let material_bind_groups = scene
            .materials
            .iter()
            .map(|m| {
                let u = MaterialUniforms {
                    base_color: [m.base_color[0], m.base_color[1], m.base_color[2], m.opacity],
                    emission: [
                        m.emission[0],
                        m.emission[1],
                        m.emission[2],
                        m.texture_alpha as u32 as f32,
                    ],
                    // the alpha rule of `Material::fragment_alpha` (`fragment_alpha` in scene.wgsl)
                    params: [
                        m.roughness,
                        m.metallic,
                        m.base_color_texture.is_some() as u32 as f32,
                        m.alpha_cutoff.unwrap_or(-1.0),
                    ],
                    flags: [m.glossy as u32 as f32, 0.0, 0.0, 0.0],
                };
                let buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(&m.name),
                    contents: bytemuck::bytes_of(&u),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                let tex = m.base_color_texture.and_then(|i| textures.get(i)).unwrap_or(&white);
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(&m.name),
                    layout: &material_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: buf.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(tex),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::Sampler(&sampler),
                        },
                    ],
                })
            })
            .collect();

        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame"),
            size: std::mem::size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let frame_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("frame"),
            layout: &frame_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: frame_buffer.as_entire_binding(),
            }],
        });

        Self {
            meshes,
            object_meshes: scene.objects.iter().map(|o| o.mesh).collect(),
            object_buffer,
            object_layout,
            object_bind_group,
            material_layout,
            material_bind_groups,
            frame_buffer,
            frame_layout,
            frame_bind_group,
            objects_cpu: scene.objects.clone(),
        }
    }

    /// Writes the object transforms for `frame`, the frame last drawn, `previous` (its
    /// transforms: reverse reprojection, the G-buffer's motion), and `frame + 1` ("next",
    /// exact or extrapolated from `previous`).
    pub fn update_objects(&self, gpu: &GpuContext, frame: f32, previous: f32, next: NextTransforms) {
        let mut bytes = vec![0u8; OBJECT_STRIDE as usize * self.objects_cpu.len().max(1)];
        for (i, o) in self.objects_cpu.iter().enumerate() {
            let m: Mat4 = o.transform_at(frame);
            let prev = o.transform_at(previous);
            let next = match next {
                NextTransforms::Exact => o.transform_at(frame + 1.0),
                NextTransforms::Extrapolated if prev == m => m,
                NextTransforms::Extrapolated => m * prev.inverse() * m,
            };
            let u = ObjectUniforms {
                model: m.to_cols_array_2d(),
                normal_matrix: m.inverse().transpose().to_cols_array_2d(),
                prev_model: prev.to_cols_array_2d(),
                next_model: next.to_cols_array_2d(),
            };
            let s = i * OBJECT_STRIDE as usize;
            bytes[s..s + std::mem::size_of::<ObjectUniforms>()].copy_from_slice(bytemuck::bytes_of(&u));
        }
        gpu.queue.write_buffer(&self.object_buffer, 0, &bytes);
    }

    pub fn update_frame(&self, gpu: &GpuContext, u: &FrameUniforms) {
        gpu.queue.write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(u));
    }

    /// Draws every object with its material bound at `material_group` (or none) and
    /// the object transform at `object_group`.
    pub fn draw_all(&self, pass: &mut wgpu::RenderPass<'_>, object_group: u32, material_group: Option<u32>) {
        for (oi, &mi) in self.object_meshes.iter().enumerate() {
            let mesh = &self.meshes[mi];
            pass.set_bind_group(
                object_group,
                &self.object_bind_group,
                &[(oi as u64 * OBJECT_STRIDE) as u32],
            );
            if let Some(g) = material_group {
                pass.set_bind_group(g, &self.material_bind_groups[mesh.material], &[]);
            }
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..mesh.index_count, 0, 0..1);
        }
    }
}

/// Uploads an sRGB RGBA8 texture with a box-filtered mip chain.
fn upload_texture(gpu: &GpuContext, t: &strata_scene::Texture) -> wgpu::TextureView {
    let mut levels = vec![image::RgbaImage::from_raw(t.width, t.height, t.rgba8.clone()).expect("texture size")];
    while {
        let l = levels.last().expect("non-empty");
        l.width() > 1 || l.height() > 1
    } {
        let l = levels.last().expect("non-empty");
        let (w, h) = ((l.width() / 2).max(1), (l.height() / 2).max(1));
        levels.push(image::imageops::resize(l, w, h, image::imageops::FilterType::Triangle));
    }
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(&t.name),
        size: wgpu::Extent3d {
            width: t.width,
            height: t.height,
            depth_or_array_layers: 1,
        },
        mip_level_count: levels.len() as u32,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (mip, img) in levels.iter().enumerate() {
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: mip as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            img.as_raw(),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * img.width()),
                rows_per_image: Some(img.height()),
            },
            wgpu::Extent3d {
                width: img.width(),
                height: img.height(),
                depth_or_array_layers: 1,
            },
        );
    }
    texture.create_view(&Default::default())
}
