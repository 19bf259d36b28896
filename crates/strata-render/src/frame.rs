//! A frame: per-frame uniforms, the render targets, and the visible list of
//! passes with their declared inputs and outputs.

use std::collections::BTreeMap;

use strata_scene::{Camera, Scene};

use crate::gpu::GpuContext;

/// Mirrors `shaders/common/frame.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    pub view: [[f32; 4]; 4],
    pub proj: [[f32; 4]; 4],
    pub view_proj: [[f32; 4]; 4],
    pub inv_view_proj: [[f32; 4]; 4],
    pub prev_view_proj: [[f32; 4]; 4],
    /// View-projection of frame t + 1 (exact for `Variant::Delay`, extrapolated
    /// for `Variant::Predict`; equal to `view_proj` otherwise).
    pub next_view_proj: [[f32; 4]; 4],
    pub eye: [f32; 4],
    pub cam_right: [f32; 4],
    pub cam_up: [f32; 4],
    pub cam_forward: [f32; 4],
    pub size: [f32; 4],
    pub sky: [f32; 4],
    pub ambient: [f32; 4],
}

impl FrameUniforms {
    pub fn new(scene: &Scene, cams: &FrameCameras, width: u32, height: u32, frame: f32, exposure: f32) -> Self {
        let aspect = width as f32 / height as f32;
        let camera = &cams.current;
        let vp = camera.view_projection(aspect);
        let (r, u, f) = camera.basis();
        let t = (0.5 * camera.fov_y_deg.to_radians()).tan();
        let s = &scene.settings;
        Self {
            view: camera.view().to_cols_array_2d(),
            proj: camera.projection(aspect).to_cols_array_2d(),
            view_proj: vp.to_cols_array_2d(),
            inv_view_proj: vp.inverse().to_cols_array_2d(),
            prev_view_proj: cams.previous.view_projection(aspect).to_cols_array_2d(),
            next_view_proj: (camera.projection(aspect) * cams.next_view).to_cols_array_2d(),
            eye: camera.eye.extend(camera.near).to_array(),
            cam_right: (r * t * aspect).extend(0.0).to_array(),
            cam_up: (u * t).extend(0.0).to_array(),
            cam_forward: f.extend(0.0).to_array(),
            size: [width as f32, height as f32, 1.0 / width as f32, 1.0 / height as f32],
            sky: [s.sky[0], s.sky[1], s.sky[2], exposure],
            ambient: [s.ambient[0], s.ambient[1], s.ambient[2], frame],
        }
    }
}

/// The cameras of frames t − 1, t and t + 1 that a frame's passes use: the
/// previous one for reverse reprojection, the next one (as a view matrix, since
/// an extrapolated camera is any rigid transform) for the depth oracle of the
/// deep G-buffer's `Delay` and `Predict` variants.
#[derive(Clone, Copy, Debug)]
pub struct FrameCameras {
    pub previous: Camera,
    pub current: Camera,
    /// World → camera transform of frame t + 1.
    pub next_view: glam::Mat4,
}

impl FrameCameras {
    /// A camera that does not move.
    pub fn fixed(camera: Camera) -> Self {
        Self {
            previous: camera,
            current: camera,
            next_view: camera.view(),
        }
    }

    /// The scene's camera path at `frame − 1`, `frame` and (exactly) `frame + 1`.
    pub fn along_path(scene: &Scene, frame: f32) -> Self {
        Self {
            previous: scene.camera_at(frame - 1.0),
            current: scene.camera_at(frame),
            next_view: scene.camera_at(frame + 1.0).view(),
        }
    }

    /// `next_view` extrapolated from frames t − 1 and t at constant velocity
    /// (DGB §2.2 PREDICT): V_{t+1} = V_t · V_{t−1}⁻¹ · V_t.
    /// A camera at rest predicts itself exactly.
    pub fn predicted(previous: Camera, current: Camera) -> Self {
        let (vp, vc) = (previous.view(), current.view());
        Self {
            previous,
            current,
            next_view: if vp == vc { vc } else { vc * vp.inverse() * vc },
        }
    }

    /// Replaces the current (and, consistently, previous/next) cameras by their
    /// guard-band widened versions for an image of `height` rows and `g` guard pixels.
    pub fn with_guard_band(&self, height: u32, g: u32) -> Self {
        Self {
            previous: self.previous.with_guard_band(height, g),
            current: self.current.with_guard_band(height, g),
            next_view: self.next_view,
        }
    }
}

/// How a target's texels read back as floats (for debug views and tests).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Decode {
    /// Raw float channels.
    Float,
    /// UNORM8 channels → [0,1] (sRGB formats are decoded to linear).
    Unorm,
}

/// Declaration of a render target a pass writes.
#[derive(Clone, Copy, Debug)]
pub struct TargetDesc {
    pub name: &'static str,
    pub format: wgpu::TextureFormat,
    pub layers: u32,
    /// MIP levels (1 for render targets; more for MIP chains such as `zmip`).
    pub mips: u32,
    pub doc: &'static str,
}

impl TargetDesc {
    pub const fn new(name: &'static str, format: wgpu::TextureFormat, layers: u32, doc: &'static str) -> Self {
        Self {
            name,
            format,
            layers,
            mips: 1,
            doc,
        }
    }

    /// The same target with `mips` MIP levels.
    pub const fn with_mips(mut self, mips: u32) -> Self {
        self.mips = mips;
        self
    }
}

/// A created render target.
pub struct Target {
    pub desc: TargetDesc,
    pub texture: wgpu::Texture,
    /// The whole texture (`D2Array` when it has several layers).
    pub view: wgpu::TextureView,
    /// The whole texture as a `D2Array` view (also when it has one layer).
    pub array_view: wgpu::TextureView,
    /// One `D2` view per array layer (all MIP levels).
    pub layer_views: Vec<wgpu::TextureView>,
    /// One `D2` view of layer 0 per MIP level (render attachments of MIP passes).
    pub mip_views: Vec<wgpu::TextureView>,
}

impl Target {
    /// A `D2` view of array layer `j`.
    pub fn layer(&self, j: u32) -> &wgpu::TextureView {
        &self.layer_views[j as usize]
    }
}

/// All targets of a frame, by name.
#[derive(Default)]
pub struct Targets {
    pub width: u32,
    pub height: u32,
    map: BTreeMap<&'static str, Target>,
}

impl Targets {
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            map: BTreeMap::new(),
        }
    }

    pub fn create(&mut self, gpu: &GpuContext, desc: TargetDesc) {
        self.create_sized(gpu, desc, [self.width, self.height]);
    }

    /// [`Targets::create`], with `STORAGE_BINDING` when `storage` (a compute pass writes it).
    pub fn create_storable(&mut self, gpu: &GpuContext, desc: TargetDesc, storage: bool) {
        let usage = if storage {
            wgpu::TextureUsages::STORAGE_BINDING
        } else {
            wgpu::TextureUsages::empty()
        };
        self.create_with_usage(gpu, desc, [self.width, self.height], usage);
    }

    /// A target of its own size (e.g. the tiled sub-buffers of interleaved
    /// shading, which can be a few texels larger than the frame); read-back and
    /// debug views show it whole (no guard-band crop).
    pub fn create_sized(&mut self, gpu: &GpuContext, desc: TargetDesc, size: [u32; 2]) {
        self.create_with_usage(gpu, desc, size, wgpu::TextureUsages::empty());
    }

    /// [`Targets::create_sized`] with `extra` usages, e.g. `STORAGE_BINDING` for a
    /// target a compute pass writes (the compute split/gather of interleaved shading).
    pub fn create_with_usage(
        &mut self,
        gpu: &GpuContext,
        desc: TargetDesc,
        [width, height]: [u32; 2],
        extra: wgpu::TextureUsages,
    ) {
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(desc.name),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: desc.layers,
            },
            mip_level_count: desc.mips,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: desc.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST
                | extra,
            // an 8-bit sRGB target can also be read as its raw bytes (`crate::display`)
            view_formats: if desc.format == wgpu::TextureFormat::Rgba8UnormSrgb {
                &[wgpu::TextureFormat::Rgba8Unorm]
            } else {
                &[]
            },
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(if desc.layers > 1 {
                wgpu::TextureViewDimension::D2Array
            } else {
                wgpu::TextureViewDimension::D2
            }),
            ..Default::default()
        });
        let array_view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let layer_views = (0..desc.layers)
            .map(|j| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: j,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let mip_views = (0..desc.mips)
            .map(|m| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_mip_level: m,
                    mip_level_count: Some(1),
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        self.map.insert(
            desc.name,
            Target {
                desc,
                texture,
                view,
                array_view,
                layer_views,
                mip_views,
            },
        );
    }

    pub fn get(&self, name: &str) -> &Target {
        self.map
            .get(name)
            .unwrap_or_else(|| panic!("render target '{name}' was not declared by any pass"))
    }

    pub fn try_get(&self, name: &str) -> Option<&Target> {
        self.map.get(name)
    }

    pub fn names(&self) -> impl Iterator<Item = &&'static str> {
        self.map.keys()
    }
}

/// What a pass reads and writes, shown by `strata render --list-passes` and checked
/// when the frame is built (every input must be written by an earlier pass).
#[derive(Clone, Debug)]
pub struct PassInfo {
    pub name: &'static str,
    pub inputs: Vec<&'static str>,
    pub outputs: Vec<&'static str>,
}

/// One technique's pass in the frame.
pub trait Pass {
    fn info(&self) -> PassInfo;
    /// Records the pass's GPU work for the current frame.
    fn encode(
        &self,
        gpu: &GpuContext,
        scene: &crate::scene_gpu::GpuScene,
        targets: &Targets,
        encoder: &mut wgpu::CommandEncoder,
    );
}

/// Checks the declared data flow of an ordered pass list: every input must be
/// written by an earlier pass, except `…-history` inputs, which hold the
/// previous frame's data and must be written by some pass of the frame.
pub fn validate_pass_order(infos: &[PassInfo]) -> Result<(), String> {
    let mut written: Vec<&str> = vec!["scene"];
    for p in infos {
        for i in &p.inputs {
            if i.ends_with("-history") {
                if !infos.iter().any(|q| q.outputs.contains(i)) {
                    return Err(format!("pass '{}' reads '{}' but no pass keeps it", p.name, i));
                }
            } else if !written.contains(i) {
                return Err(format!("pass '{}' reads '{}' before any pass writes it", p.name, i));
            }
        }
        written.extend(p.outputs.iter().copied());
    }
    Ok(())
}
