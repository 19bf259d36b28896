//! A reduced-resolution layer into the full-resolution arrays (DGB Fig. 11; see
//! [`DeepGBufferSettings::layer_scale`] and `layer_upsample.wgsl`).

use wgpu::util::DeviceExt;

use glam::Vec3;

use super::{DeepGBufferSettings, DEPTH_FORMAT, REDUCED, SURFACE_TOLERANCE};
use crate::frame::{FrameUniforms, Pass, PassInfo, Targets};
use crate::gpu::GpuContext;
use crate::scene_gpu::GpuScene;

/// `UpsampleParams` in WGSL.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct UpsampleParams {
    min_separation: f32,
    scale: u32,
    near: f32,
    _pad: u32,
}

/// Writes reduced layer `layer` (≥ 1) into its slice of `depth`, `csz`, `normal`,
/// `albedo`, `emission` (and `motion`), keeping the layer's minimum separation from
/// this frame's layer `layer` − 1 at every full-resolution pixel ([`upsample_pick`]).
pub struct LayerUpsamplePass {
    name: &'static str,
    layer: u32,
    scale: u32,
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    params: wgpu::Buffer,
    motion: bool,
}

const NAMES: [&str; 4] = ["", "layer1-upsample", "layer2-upsample", "layer3-upsample"];

impl LayerUpsamplePass {
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        settings: &DeepGBufferSettings,
        layer: u32,
    ) -> Self {
        let device = &gpu.device;
        let motion = targets.try_get("motion").is_some();
        let module = crate::shader::module(device, "layer_upsample", include_str!("layer_upsample.wgsl"));
        let mut entries = vec![crate::passes::uniform_entry(0)];
        for b in 1..=6 {
            entries.push(crate::passes::texture_entry(b, wgpu::TextureViewDimension::D2, false));
        }
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("layer_upsample"),
            entries: &entries,
        });
        let scale = settings.layer_scale;
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("layer_upsample"),
            contents: bytemuck::bytes_of(&UpsampleParams {
                min_separation: 0.0,
                scale,
                near: 1.0,
                _pad: 0,
            }),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let reduced = |name: &str| &targets.get(name).view;
        // without a motion target the shader's motion output has no attachment; any
        // float texture stands in for its input
        let motion_input = if motion { REDUCED[5].0 } else { REDUCED[1].0 };
        let views = [
            reduced(REDUCED[1].0),
            reduced(REDUCED[2].0),
            reduced(REDUCED[3].0),
            reduced(REDUCED[4].0),
            reduced(motion_input),
            targets.get("csz").layer(layer - 1),
        ];
        let mut group_entries = vec![wgpu::BindGroupEntry {
            binding: 0,
            resource: params.as_entire_binding(),
        }];
        for (i, v) in views.into_iter().enumerate() {
            group_entries.push(wgpu::BindGroupEntry {
                binding: i as u32 + 1,
                resource: wgpu::BindingResource::TextureView(v),
            });
        }
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("layer_upsample"),
            layout: &group_layout,
            entries: &group_entries,
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("layer_upsample"),
            bind_group_layouts: &[Some(&group_layout), Some(&scene.frame_layout)],
            immediate_size: 0,
        });
        let color_targets = settings.layer_color_targets(motion);
        let pipeline = crate::passes::fullscreen_pipeline_writing_depth(
            device,
            NAMES[layer as usize],
            &layout,
            &module,
            "fs_upsample",
            &[],
            &color_targets,
            Some(DEPTH_FORMAT),
        );
        Self {
            name: NAMES[layer as usize],
            layer,
            scale,
            pipeline,
            group,
            params,
            motion,
        }
    }

    /// This frame's Δz and the camera's near plane.
    pub fn set_frame(&self, gpu: &GpuContext, min_separation: f32, near: f32) {
        let p = UpsampleParams {
            min_separation,
            scale: self.scale,
            near,
            _pad: 0,
        };
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
    }
}

impl Pass for LayerUpsamplePass {
    fn info(&self) -> PassInfo {
        let n = 5 + self.motion as usize;
        // not the reduced depth: the layer's depth is near / z
        let mut inputs: Vec<&'static str> = REDUCED.iter().take(n).skip(1).map(|r| r.0).collect();
        inputs.push("csz");
        PassInfo {
            name: self.name,
            inputs,
            outputs: REDUCED.iter().take(n).map(|r| r.1).collect(),
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let view = |name: &str| targets.get(name).layer(self.layer);
        let mut pass = super::begin_layer_pass(encoder, self.name, view, self.motion, None);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_bind_group(1, &scene.frame_bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// CPU twin of `pick` in `layer_upsample.wgsl`: the reduced texel that full-resolution
/// pixel `p` of layer j takes, or `None` for no surface. `reduced` holds the reduced
/// layer's camera-space depths (`size` = [w, h], row-major), `z_front` layer j − 1's
/// depth at `p` this frame, `scale` the divisor s.
pub fn upsample_pick(
    reduced: &[f32],
    size: [u32; 2],
    p: [u32; 2],
    z_front: f32,
    scale: u32,
    min_separation: f32,
) -> Option<[u32; 2]> {
    if z_front <= 0.0 {
        return None;
    }
    let behind = |z: f32| z > 0.0 && z > z_front + min_separation + SURFACE_TOLERANCE * z_front;
    let last = [size[0] as i64 - 1, size[1] as i64 - 1];
    let q = [
        (p[0] / scale).min(size[0] - 1) as i64,
        (p[1] / scale).min(size[1] - 1) as i64,
    ];
    let at = |t: [i64; 2]| reduced[(t[1] * size[0] as i64 + t[0]) as usize];
    if behind(at(q)) {
        return Some([q[0] as u32, q[1] as u32]);
    }
    let mut best: Option<([i64; 2], f32)> = None;
    for dy in -1..=1 {
        for dx in -1..=1 {
            let t = [q[0] + dx, q[1] + dy];
            if (dx == 0 && dy == 0) || t[0] < 0 || t[1] < 0 || t[0] > last[0] || t[1] > last[1] {
                continue;
            }
            let z = at(t);
            if behind(z) && best.is_none_or(|(_, bz)| z < bz) {
                best = Some((t, z));
            }
        }
    }
    best.map(|(t, _)| [t[0] as u32, t[1] as u32])
}

/// The depth at full-resolution pixel `p` of the plane through reduced texel `t`'s point
/// (depth `z_t`) with world normal `n`, before [`upsample_depth`]'s checks.
pub fn texel_plane_depth(f: &FrameUniforms, t: [u32; 2], scale: u32, z_t: f32, n: Vec3, p: [u32; 2]) -> f32 {
    let dir = |pix: [f32; 2]| crate::passes::ao::pixel_dir(f, pix);
    let s = scale as f32;
    let d_t = dir([(t[0] as f32 + 0.5) * s, (t[1] as f32 + 0.5) * s]);
    let d_p = dir([p[0] as f32 + 0.5, p[1] as f32 + 0.5]);
    z_t * n.dot(d_t) / n.dot(d_p)
}

/// `MAX_PLANE_CHANGE` in `layer_upsample.wgsl`.
const MAX_PLANE_CHANGE: f32 = 0.25;

/// CPU twin of `plane_depth` in `layer_upsample.wgsl`: the depth full-resolution pixel `p`
/// of layer j takes from reduced texel `t` (depth `z_t` at its centre, world normal `n`):
/// where p's ray meets the plane through the texel's point with its normal, or `z_t` where
/// that changes the depth by more than a quarter or breaks the separation from `z_front`.
#[allow(clippy::too_many_arguments)]
pub fn upsample_depth(
    f: &FrameUniforms,
    t: [u32; 2],
    scale: u32,
    z_t: f32,
    n: Vec3,
    p: [u32; 2],
    z_front: f32,
    min_separation: f32,
) -> f32 {
    let z = texel_plane_depth(f, t, scale, z_t, n, p);
    let behind = z > 0.0 && z > z_front + min_separation + SURFACE_TOLERANCE * z_front;
    // (false for NaN, as the WGSL test)
    let small_change = (z - z_t).abs() <= MAX_PLANE_CHANGE * z_t;
    if !small_change || !behind {
        return z_t;
    }
    z
}

#[cfg(test)]
mod tests {
    use super::upsample_pick;

    #[test]
    fn the_covering_texel_wins_when_it_keeps_the_separation() {
        // 2×2 reduced layer; full pixel (3, 1) at s = 2 lies in texel (1, 0)
        let z = [5.0, 6.0, 7.0, 8.0];
        assert_eq!(upsample_pick(&z, [2, 2], [3, 1], 1.0, 2, 0.5), Some([1, 0]));
    }

    #[test]
    fn otherwise_the_nearest_separated_neighbour_and_else_nothing() {
        // texel (1, 0) is within Δz of the front layer (z 6 vs 5.8 + 0.5): its neighbours
        // (0, 0) = 5 is too close as well, (0, 1) = 9 and (1, 1) = 7 lie behind: 7 wins
        let z = [5.0, 6.0, 9.0, 7.0];
        assert_eq!(upsample_pick(&z, [2, 2], [2, 0], 5.8, 2, 0.5), Some([1, 1]));
        // nothing lies behind 10
        assert_eq!(upsample_pick(&z, [2, 2], [2, 0], 10.0, 2, 0.5), None);
        // an empty front layer has nothing behind it
        assert_eq!(upsample_pick(&z, [2, 2], [0, 0], 0.0, 2, 0.5), None);
        // empty texels (z = 0) never count
        let z = [0.0, 0.0, 0.0, 0.0];
        assert_eq!(upsample_pick(&z, [2, 2], [1, 1], 1.0, 2, 0.0), None);
    }

    #[test]
    fn an_edge_pixel_takes_its_neighbour_where_the_partial_column_is_empty() {
        // a 5-pixel-wide image at s = 2 has ⌈5/2⌉ = 3 reduced columns; pixel 4 lies in column
        // 2, which the geometry pass leaves empty (scissored): column 1 stands in
        let z = [2.0, 2.5, 0.0];
        assert_eq!(upsample_pick(&z, [3, 1], [4, 0], 1.0, 2, 0.5), Some([1, 0]));
        // and where column 2 holds a surface, it is taken
        let z = [2.0, 2.5, 3.0];
        assert_eq!(upsample_pick(&z, [3, 1], [4, 0], 1.0, 2, 0.5), Some([2, 0]));
    }
}
