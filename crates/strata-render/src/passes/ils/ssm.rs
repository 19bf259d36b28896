//! ILS §4.3 SSM ("shading with shadow maps", the physically-based mode of §6.3): the
//! visibility of every VPL from its own omnidirectional shadow map.
//!
//! A VPL at y with normal n_y lights its hemisphere; its map is the six cube faces of
//! a point light (`crate::lights`: 95° perspective faces along ±X, ±Y, ±Z, the face
//! picked by the major axis of the direction from the light), centred at
//! y + ε·n_y (ε = [`EYE_OFFSET`] × the scene diagonal, so the VPL's own surface lies
//! below every face's horizon). A hemicube would need five faces (three whole); the
//! world-aligned cube keeps the point lights' face code, so a tilted VPL needs all six.
//!
//! **Layout.** One layer of a `Depth32Float` 2-D array per VPL, its six faces in a
//! 3×2 atlas (face f at tile (f mod 3, f div 3)) of R×R texels each, so N VPLs need N
//! layers (≤ the device's `max_texture_array_layers`: 2048 on lavapipe), not 6N.
//! **Memory:** N · 6 · R² · 4 bytes: 480 VPLs at R = 64 are 45 MiB, at R = 128
//! 180 MiB; plus 6 · N · (256 + 64) bytes of face matrices (0.9 MiB for 480).
//!
//! **Cost.** The scene is drawn up to 6N times per frame (2880 draws for 480 VPLs):
//! the price §6.3 pays for visibility, which SNSM (§6.2) skips. A face that no
//! direction of the VPL's lit hemisphere selects ([`lit_faces`]: the face opposite an
//! axis-aligned normal) is not drawn. §6.3 draws fresh VPL sets,
//! so it pays it every frame; VPLs that stay put in a scene that does not move keep
//! their maps ([`VplShadowPass::set_cached`]) until new VPLs arrive
//! ([`VplShadowPass::set_vpls`]).

use glam::{Mat4, Vec3};

use crate::frame::{Pass, PassInfo, Targets};
use crate::gpu::GpuContext;
use crate::scene_gpu::GpuScene;
use crate::RenderError;

use super::GpuVpl;

/// ε of the shadow-map eye above the VPL's surface, relative to the scene's bounding-box diagonal.
pub const EYE_OFFSET: f32 = 1e-3;

/// Uniform stride of one face's view-projection (dynamic offsets).
const STRIDE: u64 = 256;

/// The VPL shadow maps' pass (`ils-vpl-shadows`) and what the SSM shading reads.
pub(crate) struct VplShadowPass {
    pipeline: wgpu::RenderPipeline,
    views_buffer: wgpu::Buffer,
    views_group: wgpu::BindGroup,
    _maps: wgpu::Texture,
    pub array_view: wgpu::TextureView,
    /// 6 view-projections per VPL (`array<mat4x4f>`, index 6k + face).
    pub matrices: wgpu::Buffer,
    pub sampler: wgpu::Sampler,
    layer_views: Vec<wgpu::TextureView>,
    resolution: u32,
    /// VPLs whose maps are rendered (≤ the layers).
    count: usize,
    /// Per VPL, the faces its lit hemisphere can look up ([`lit_faces`]).
    faces: Vec<[bool; 6]>,
    eye_offset: f32,
    bounds: (Vec3, f32),
    /// Whether a frame draws the maps (kept for fixed VPLs: [`Self::set_cached`];
    /// [`Self::set_vpls`] redraws).
    draw: crate::passes::DrawOnce,
}

/// Scene centre and bounding radius (as `crate::lights` fits its shadow frusta).
fn scene_sphere(scene: &strata_scene::Scene) -> (Vec3, f32) {
    let (lo, hi) = scene.bounds(0.0);
    if lo.is_finite() && hi.is_finite() {
        ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-3))
    } else {
        (Vec3::ZERO, 1.0)
    }
}

/// ε in scene units for `scene`.
pub fn eye_offset(scene: &strata_scene::Scene) -> f32 {
    EYE_OFFSET * 2.0 * scene_sphere(scene).1
}

/// The six cube-face view-projections of every VPL's map (index 6k + face).
pub fn face_matrices(vpls: &[GpuVpl], eye_offset: f32, (centre, radius): (Vec3, f32)) -> Vec<Mat4> {
    vpls.iter()
        .flat_map(|v| {
            let eye = Vec3::from_slice(&v.position[..3]) + Vec3::from_slice(&v.normal[..3]) * eye_offset;
            (0..6).map(move |f| crate::lights::cube_face_matrix(eye, f, radius, centre))
        })
        .collect()
}

/// Which cube faces (`crate::lights::CUBE_FACES` order) a VPL with normal `n` can
/// look up: the shading selects a face by the major axis of the direction d from the
/// VPL and only for receivers in its lit hemisphere (the VPL term's cos θ_y > 0). The
/// directions whose major axis is face f's a form the cone spanned by a ± b ± c (b, c
/// the other two axes), so max dot(d, n) over it is at one of those four corners: a
/// face whose corners all have dot ≤ 0 is never looked up and need not be drawn
/// (the face opposite an axis-aligned normal; a tilted normal keeps all six).
pub fn lit_faces(n: Vec3) -> [bool; 6] {
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    std::array::from_fn(|f| {
        let a = crate::lights::CUBE_FACES[f];
        let (b, c) = (axes[(f / 2 + 1) % 3], axes[(f / 2 + 2) % 3]);
        [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
            .iter()
            .any(|&(sb, sc)| n.dot(a + sb * b + sc * c) > 0.0)
    })
}

/// World-space size of one shadow-map texel at distance 1 from the eye (R texels over a
/// 95° face).
pub fn texel_at_unit_distance(resolution: u32) -> f32 {
    2.0 * (crate::lights::CUBE_FACE_FOV_DEG.to_radians() * 0.5).tan() / resolution as f32
}

impl VplShadowPass {
    pub(crate) fn new(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        scene: &strata_scene::Scene,
        vpls: &[GpuVpl],
        capacity: usize,
        resolution: u32,
    ) -> Result<Self, RenderError> {
        let device = &gpu.device;
        // one layer per VPL, for as many as `set_vpls` may later pass
        let layers = vpls.len().max(capacity).max(1) as u32;
        let max_layers = device.limits().max_texture_array_layers;
        if layers > max_layers {
            return Err(RenderError::Parameter(format!(
                "shadows vpl needs one shadow-map layer per VPL ({layers} VPLs): vpls must be in 1..={max_layers} on this device, or shadows another method"
            )));
        }
        let (w, h) = (3 * resolution, 2 * resolution);
        let max_dim = device.limits().max_texture_dimension_2d;
        if w > max_dim {
            return Err(RenderError::Parameter(format!(
                "vpl-shadow-resolution {resolution} is out of range: must be in 8..={} on this device",
                max_dim / 3
            )));
        }
        let maps = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("ils vpl shadow maps"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: layers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let array_view = maps.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let layer_views = (0..layers)
            .map(|i| {
                maps.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: i,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let faces = 6 * layers as u64;
        let views_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ils vpl shadow views"),
            size: STRIDE * faces,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let matrices = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ils vpl shadow matrices"),
            size: 64 * faces,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // the point lights' depth-only pipeline: the face matrix at a dynamic offset
        let (views_group, pipeline) = crate::passes::shadow::depth_only_pipeline(
            device,
            &scene_gpu.object_layout,
            &views_buffer,
            "ils vpl shadows",
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("ils vpl shadow compare"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let mut pass = Self {
            pipeline,
            views_buffer,
            views_group,
            _maps: maps,
            array_view,
            matrices,
            sampler,
            layer_views,
            resolution,
            count: 0,
            faces: Vec::new(),
            eye_offset: eye_offset(scene),
            bounds: scene_sphere(scene),
            draw: Default::default(),
        };
        pass.set_vpls(gpu, vpls);
        Ok(pass)
    }

    /// Uploads the face matrices of `vpls` (at most the layers the pass was built with).
    pub(crate) fn set_vpls(&mut self, gpu: &GpuContext, vpls: &[GpuVpl]) {
        let vpls = &vpls[..vpls.len().min(self.layer_views.len())];
        let mats = face_matrices(vpls, self.eye_offset, self.bounds);
        let mut strided = vec![0u8; mats.len() * STRIDE as usize];
        for (i, m) in mats.iter().enumerate() {
            let s = i * STRIDE as usize;
            strided[s..s + 64].copy_from_slice(bytemuck::bytes_of(&m.to_cols_array_2d()));
        }
        let packed: Vec<[[f32; 4]; 4]> = mats.iter().map(|m| m.to_cols_array_2d()).collect();
        if !packed.is_empty() {
            gpu.queue.write_buffer(&self.views_buffer, 0, &strided);
            gpu.queue.write_buffer(&self.matrices, 0, bytemuck::cast_slice(&packed));
        }
        self.count = vpls.len();
        self.faces = vpls
            .iter()
            .map(|v| lit_faces(Vec3::from_slice(&v.normal[..3])))
            .collect();
        self.draw.invalidate();
    }

    /// Keep the maps from frame to frame instead of redrawing them: for VPLs that stay
    /// put in a scene that does not move (`IlsSettings::vpl_shadow_cache`, and the
    /// renderer turns it off when an object is animated).
    pub(crate) fn set_cached(&mut self, cached: bool) {
        self.draw.set_cached(cached);
    }

    /// Draws the maps again next frame (the occluders moved).
    pub(crate) fn invalidate(&self) {
        self.draw.invalidate();
    }

    /// Whether the maps are kept from frame to frame.
    pub(crate) fn cached(&self) -> bool {
        self.draw.cached()
    }

    pub(crate) fn eye_offset(&self) -> f32 {
        self.eye_offset
    }

    pub(crate) fn resolution(&self) -> u32 {
        self.resolution
    }
}

impl Pass for VplShadowPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "ils-vpl-shadows",
            inputs: vec!["scene"],
            outputs: vec!["ils-vpl-shadow-maps"],
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, _targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        if !self.draw.must_draw() {
            return;
        }
        let r = self.resolution as f32;
        for (k, view) in self.layer_views.iter().enumerate().take(self.count) {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("ils-vpl-shadows"),
                color_attachments: &[],
                depth_stencil_attachment: Some(crate::passes::clear_depth_attachment(view)),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            for face in (0..6u32).filter(|&f| self.faces[k][f as usize]) {
                // face f of the 3×2 atlas
                let (x, y) = ((face % 3) as f32 * r, (face / 3) as f32 * r);
                pass.set_viewport(x, y, r, r, 0.0, 1.0);
                pass.set_scissor_rect(x as u32, y as u32, self.resolution, self.resolution);
                let slot = (k * 6 + face as usize) as u64;
                pass.set_bind_group(0, &self.views_group, &[(slot * STRIDE) as u32]);
                scene.draw_all(&mut pass, 1, None);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The face the shading picks for direction d (ils_snsm.wgsl's `vpl_visibility`).
    fn face_of(d: Vec3) -> usize {
        let a = d.abs();
        let mut face = 4;
        if a.x >= a.y && a.x >= a.z {
            face = 0;
        } else if a.y >= a.z {
            face = 2;
        }
        if (face == 0 && d.x < 0.0) || (face == 2 && d.y < 0.0) || (face == 4 && d.z < 0.0) {
            face += 1;
        }
        face
    }

    /// Skipping faces is conservative: for random normals and random directions of
    /// their lit hemisphere, the face the shading looks up is always drawn; an
    /// axis-aligned normal skips exactly the opposite face, and a tilted one none.
    #[test]
    fn skipped_faces_are_never_looked_up_from_the_lit_hemisphere() {
        let mut h = 1u32;
        let mut rnd = || {
            h = crate::spiral::pcg_hash(h);
            (h >> 8) as f32 / 16_777_216.0 * 2.0 - 1.0
        };
        let mut skipped = 0;
        for _ in 0..2000 {
            let n = Vec3::new(rnd(), rnd(), rnd()).normalize_or(Vec3::Y);
            let lit = lit_faces(n);
            skipped += lit.iter().filter(|&&l| !l).count();
            for _ in 0..200 {
                let d = Vec3::new(rnd(), rnd(), rnd());
                if d.dot(n) > 0.0 {
                    assert!(lit[face_of(d)], "n {n}, d {d}: face {} skipped", face_of(d));
                }
            }
        }
        // random normals: a face is skipped only near the axes
        assert!(skipped < 2000, "{skipped} faces skipped for 2000 random normals");
        for (f, &a) in crate::lights::CUBE_FACES.iter().enumerate() {
            let lit = lit_faces(a);
            let opposite = f ^ 1;
            for (g, &l) in lit.iter().enumerate() {
                assert_eq!(l, g != opposite, "normal {a}: face {g}");
            }
        }
        assert_eq!(lit_faces(Vec3::new(1.0, 1.0, 0.3).normalize()), [true; 6]);
    }
}
