//! Interleaved deferred shading of virtual point lights (ILS §4) on an application's
//! G-buffer: the passes of `strata render --technique ils` from the split G-buffer to the
//! discontinuity-aware blur, without strata's lighting, VPL generation or composite.
//!
//! The application gives its depth and normals (as for [`super::EmbeddedAo`]) and a list of
//! VPLs ([`GpuVpl`]: position, the normal on the lit side, reflected flux Φ), for example
//! from a reflective shadow map of its own lights. The G-buffer is split into n×m
//! sub-buffers (§4.2), each pixel shades 1/(n·m) of the VPLs (§4.3), the gather puts the
//! pixels back (§4.4) and the blur averages the n·m subsets across pixels of the same
//! surface (§4.5). It gets back
//! [`EmbeddedIls::output`]: layer 0's indirect irradiance E (rgb); the application composes
//! `direct + ρ/π · E`. Receivers are Lambertian. VPL visibility is ignored by default (SNSM,
//! §6.2's interactive mode). With `shadows = vpl` (SSM, §4.3) the application also gives
//! its world-space triangles, and every VPL gets an omnidirectional shadow map of them.

use std::sync::Arc;

use glam::Vec3;

use super::core::{Core, CoreConfig};
use super::{AoInputs, NormalEncoding, NormalSpace};
use crate::frame::{FrameUniforms, Pass, TargetDesc};
use crate::passes::ils::{GpuVpl, IlsSettings, IlsStage, VplShadows};
use crate::RenderError;

/// What [`EmbeddedIls::new`] builds.
#[derive(Clone, Debug)]
pub struct EmbeddedIlsConfig {
    /// The application's render size in pixels (the inputs' size).
    pub width: u32,
    pub height: u32,
    /// The settings of `strata render --technique ils`: the n×m pattern, the split method,
    /// the blur, `refine`. `clamp_distance` d_c is required (the renderer's default is a
    /// share of the scene's diagonal, which the embedding does not know); `vpls` are the
    /// first frame's VPLs and set how many later frames may pass (a larger count rebuilds).
    /// `shadows`: [`VplShadows::None`] (SNSM) or [`VplShadows::ShadowMaps`] (SSM, which
    /// needs `triangles`).
    pub settings: IlsSettings,
    pub normals: NormalEncoding,
    pub normal_space: NormalSpace,
    /// The scene's triangles in world space, the occluders of the VPL shadow maps (SSM);
    /// required with `shadows = vpl`, not read without.
    pub triangles: Arc<[[Vec3; 3]]>,
    /// How far beyond the box of `triangles` the shadow maps' depth range reaches, as a
    /// share of the box's diagonal on every side, 0..=10: occluders that move within it
    /// are rewritten in place by [`EmbeddedIls::set_triangles`], others rebuild the passes.
    /// A margin costs shadow quality: the maps' depth range and their eye offset grow with
    /// it (0.1 let 2 % of the light through a plate in the tests). Default 0, the
    /// renderer's range (the box itself).
    pub occluder_margin: f32,
}

impl Default for EmbeddedIlsConfig {
    /// 1×1 (set the size), [`IlsSettings::default`] (8×6 sub-buffers, the paper's blur; no
    /// clamp distance and no VPLs: set them), signed world-space normals.
    fn default() -> Self {
        Self {
            width: 1,
            height: 1,
            settings: IlsSettings::default(),
            normals: NormalEncoding::Signed,
            normal_space: NormalSpace::World,
            triangles: Arc::from([]),
            occluder_margin: 0.0,
        }
    }
}

/// A scene of `triangles` (one mesh, flat normals, one grey material) for the VPL shadow
/// maps to draw; no geometry without them. Two zero-area triangles after them, at the
/// corners of `reach` (the box grown by the margin), stretch the scene's bounds, from
/// which the maps take their depth range, without drawing anything.
fn occluder_scene(triangles: &[[Vec3; 3]], reach: Option<(Vec3, Vec3)>) -> strata_scene::Scene {
    use strata_scene::model::{Material, Mesh, Object};
    let mut scene = strata_scene::Scene {
        name: "embedded".into(),
        ..Default::default()
    };
    if triangles.is_empty() {
        return scene;
    }
    let corners = reach.map_or(Vec::new(), |(lo, hi)| vec![[lo; 3], [hi; 3]]);
    let all = || triangles.iter().chain(&corners);
    let positions: Vec<[f32; 3]> = all().flatten().map(|p| p.to_array()).collect();
    let normals = all().flat_map(|t| [flat_normal(t).to_array(); 3]).collect();
    scene.meshes.push(Mesh {
        name: "occluders".into(),
        uvs: vec![[0.0; 2]; positions.len()],
        indices: (0..positions.len() as u32).collect(),
        positions,
        normals,
        material: 0,
    });
    scene.objects.push(Object {
        name: "occluders".into(),
        mesh: 0,
        transform: glam::Mat4::IDENTITY,
        animation: None,
    });
    scene.materials.push(Material::diffuse("occluder", [0.5; 3]));
    scene
}

/// A triangle's unit normal (+y for a degenerate one), as the occluder mesh has it.
fn flat_normal(t: &[Vec3; 3]) -> Vec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize_or(Vec3::Y)
}

/// The axis-aligned box of `triangles` (None without any), grown by `margin` × its
/// diagonal on every side.
fn reach_box(triangles: &[[Vec3; 3]], margin: f32) -> Option<(Vec3, Vec3)> {
    let mut points = triangles.iter().flatten();
    let first = *points.next()?;
    let (lo, hi) = points.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let grow = Vec3::splat(margin * (hi - lo).length());
    Some((lo - grow, hi + grow))
}

/// The ILS passes of `strata render --technique ils` on an application's G-buffer and VPLs.
pub struct EmbeddedIls {
    core: Core,
    config: EmbeddedIlsConfig,
    stage: IlsStage,
    /// The VPL buffer's capacity (the VPLs given to `new` or the last rebuild).
    capacity: usize,
    /// With SSM: the box of the occluders the passes were built with, grown by
    /// `occluder_margin`. The shadow maps' depth ranges cover it, so triangles that stay
    /// inside are rewritten in place.
    occluder_box: Option<(Vec3, Vec3)>,
}

super::embedded_common!(EmbeddedIls, EmbeddedIlsConfig, resize);

impl EmbeddedIls {
    /// Builds the passes for `config` on the application's device. Errors name the
    /// parameter and its valid range.
    pub fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: EmbeddedIlsConfig,
    ) -> Result<Self, RenderError> {
        let what = "embedded ILS";
        let s = &config.settings;
        s.validate()
            .map_err(|e| RenderError::Parameter(format!("{what}: {e}")))?;
        if s.clamp_distance.is_none() {
            return Err(RenderError::Parameter(format!(
                "{what}: settings.clamp_distance is required: the world-space clamp distance d_c (> 0), \
                 below which a VPL's 1/d² is held (the renderer's default, 4 % of the scene's diagonal, needs the scene)"
            )));
        }
        if s.shadows == VplShadows::ShadowMaps && config.triangles.is_empty() {
            return Err(RenderError::Parameter(format!(
                "{what}: settings.shadows '{}' needs config.triangles, the world-space occluders of the VPL shadow maps (SSM, §4.3); or shadows none (SNSM)",
                s.shadows.name()
            )));
        }
        super::check_triangles(what, &config.triangles, 0)?;
        if s.vpls.is_empty() {
            return Err(RenderError::Parameter(format!(
                "{what}: settings.vpls is empty: give the first frame's VPLs (their count is the capacity)"
            )));
        }
        let margin = config.occluder_margin;
        if !(0.0..=10.0).contains(&margin) {
            return Err(RenderError::Parameter(format!(
                "{what}: occluder_margin {margin} is out of range: a share of the occluders' box diagonal in 0..=10 (default 0)"
            )));
        }
        let shadows = s.shadows == VplShadows::ShadowMaps;
        let reach = if shadows {
            reach_box(&config.triangles, margin)
        } else {
            None
        };
        let scene = occluder_scene(
            if shadows { &config.triangles } else { &[] },
            reach.filter(|_| margin > 0.0),
        );
        let core = CoreConfig::one_layer(
            what,
            [config.width, config.height],
            (config.normals, config.normal_space),
            super::core::ShadingImport::Normals,
        );
        Core::scoped(device, || {
            let mut core = Core::new(adapter, device, queue, core, scene)?;
            // the occluders stand still: their (identity) transforms once
            core.scene_gpu
                .update_objects(&core.gpu, 0.0, 0.0, crate::scene_gpu::NextTransforms::Exact);
            // the G-buffer's emission (a = 2 flags a glossy receiver): none here, all Lambert
            core.targets.create(
                &core.gpu,
                TargetDesc::new("emission", wgpu::TextureFormat::Rgba16Float, 1, "0: Lambert receivers"),
            );
            let stage = IlsStage::new(&core.gpu, &core.scene_gpu, &mut core.targets, s, &core.scene, false).map_err(
                |e| match e {
                    RenderError::Parameter(m) => RenderError::Parameter(format!("{what}: {m}")),
                    e => e,
                },
            )?;
            Ok(Self {
                core,
                config: config.clone(),
                stage,
                capacity: s.vpls.len(),
                occluder_box: reach,
            })
        })
    }

    /// Replaces the VPLs. Up to as many as the capacity are written in place; more
    /// rebuild the passes with the new count as the capacity. An empty list or a
    /// non-finite VPL is a one-line error, and then nothing changes.
    pub fn set_vpls(&mut self, vpls: &[GpuVpl]) -> Result<(), RenderError> {
        if vpls.is_empty() {
            return Err(RenderError::Parameter(
                "embedded ILS: set_vpls was given no VPLs: pass at least one (a black one for no light)".into(),
            ));
        }
        crate::passes::ils::check_vpls(vpls).map_err(|e| RenderError::Parameter(format!("embedded ILS: {e}")))?;
        if vpls.len() <= self.capacity {
            self.stage.set_vpls(&self.core.gpu, vpls)?;
            // kept for `resize`, which rebuilds from the config: copied into the kept list
            // where it has the same length (a frame of moving lights allocates nothing)
            match Arc::get_mut(&mut self.config.settings.vpls).filter(|kept| kept.len() == vpls.len()) {
                Some(kept) => kept.copy_from_slice(vpls),
                None => self.config.settings.vpls = vpls.into(),
            }
            return Ok(());
        }
        let mut config = self.config.clone();
        config.settings.vpls = vpls.into();
        config.settings.vpl_count = vpls.len() as u32;
        let gpu = &self.core.gpu;
        *self = Self::new(&gpu.adapter, &gpu.device, &gpu.queue, config)?;
        Ok(())
    }

    /// Replaces the occluders of the VPL shadow maps (SSM). As many triangles as before,
    /// inside the box of those the passes were built with, are written in place (a frame
    /// of moving geometry allocates nothing and compiles nothing) and the maps are drawn
    /// again; other triangles rebuild the passes. Without SSM they are only kept (for a
    /// later rebuild). A triangle with a non-finite vertex is a one-line error, and then
    /// nothing changes.
    pub fn set_triangles(&mut self, triangles: &[[Vec3; 3]]) -> Result<(), RenderError> {
        super::check_triangles("embedded ILS", triangles, 0)?;
        if triangles.len() == self.config.triangles.len() && self.write_in_place(0, triangles) {
            return Ok(());
        }
        let mut config = self.config.clone();
        config.triangles = triangles.into();
        if self.config.settings.shadows != VplShadows::ShadowMaps {
            self.config = config;
            return Ok(());
        }
        let gpu = &self.core.gpu;
        *self = Self::new(&gpu.adapter, &gpu.device, &gpu.queue, config)?;
        Ok(())
    }

    /// Replaces occluders `first..first + triangles.len()` of the VPL shadow maps (SSM),
    /// in place where they stay inside the box the passes were built with (else the
    /// passes are rebuilt with the whole list). A range past the end or a non-finite
    /// vertex is a one-line error, and then nothing changes.
    pub fn set_triangle_range(&mut self, first: usize, triangles: &[[Vec3; 3]]) -> Result<(), RenderError> {
        let count = self.config.triangles.len();
        if first.checked_add(triangles.len()).is_none_or(|end| end > count) {
            return Err(RenderError::Parameter(format!(
                "embedded ILS: set_triangle_range({first}, {} triangles) passes the end: the occluders are {count} triangles (set_triangles changes their number)",
                triangles.len()
            )));
        }
        super::check_triangles("embedded ILS", triangles, first)?;
        if self.write_in_place(first, triangles) {
            return Ok(());
        }
        let mut all = self.config.triangles.to_vec();
        all[first..first + triangles.len()].copy_from_slice(triangles);
        self.set_triangles(&all)
    }

    /// Writes `triangles` over the occluders from `first` on, keeps them in the config,
    /// and has the maps drawn again, if they lie inside the built box (SSM) or no maps
    /// are drawn (SNSM); false, with nothing changed, otherwise.
    fn write_in_place(&mut self, first: usize, triangles: &[[Vec3; 3]]) -> bool {
        let ssm = self.config.settings.shadows == VplShadows::ShadowMaps;
        if ssm {
            let Some((lo, hi)) = self.occluder_box else {
                return false;
            };
            let inside = |p: &Vec3| p.cmpge(lo).all() && p.cmple(hi).all();
            if !triangles.iter().flatten().all(inside) {
                return false;
            }
            let vertices: Vec<crate::scene_gpu::Vertex> = triangles
                .iter()
                .flat_map(|t| {
                    let normal = flat_normal(t).to_array();
                    t.map(|p| crate::scene_gpu::Vertex {
                        position: p.to_array(),
                        normal,
                        uv: [0.0; 2],
                    })
                })
                .collect();
            let stride = std::mem::size_of::<crate::scene_gpu::Vertex>() as u64;
            let gpu = &self.core.gpu;
            gpu.queue.write_buffer(
                &self.core.scene_gpu.meshes[0].vertices,
                3 * first as u64 * stride,
                bytemuck::cast_slice(&vertices),
            );
            self.stage.invalidate_vpl_shadows();
        }
        // kept for `resize` and rebuilds: copied into the kept list where no one else holds it
        match Arc::get_mut(&mut self.config.triangles) {
            Some(kept) => kept[first..first + triangles.len()].copy_from_slice(triangles),
            None => {
                let mut all = self.config.triangles.to_vec();
                all[first..first + triangles.len()].copy_from_slice(triangles);
                self.config.triangles = all.into();
            }
        }
        true
    }

    /// VPLs the buffer holds without a rebuild (after `resize`: the current count).
    pub fn vpl_capacity(&self) -> usize {
        self.capacity
    }

    /// Layer 0's indirect irradiance E (rgb; a = the share of the n·m VPL subsets the blur
    /// averaged), `Rgba16Float`, written by the last [`EmbeddedIls::encode`] once its
    /// encoder is submitted.
    pub fn output(&self) -> &wgpu::Texture {
        &self.core.targets.get(self.config.settings.output().name).texture
    }

    /// A view of [`EmbeddedIls::output`] to bind in the application's composite.
    pub fn output_view(&self) -> &wgpu::TextureView {
        &self.core.targets.get(self.config.settings.output().name).view
    }

    /// Records this frame's ILS passes into `encoder` and writes its uniforms with the
    /// queue: submit `encoder` before the next call. `inputs` has one layer (no `second`).
    /// Inputs are checked first; a bad one is a one-line error and nothing is recorded.
    pub fn encode(&mut self, encoder: &mut wgpu::CommandEncoder, inputs: &AoInputs<'_>) -> Result<(), RenderError> {
        if inputs.second.is_some() {
            return Err(RenderError::Parameter(
                "embedded ILS: AoInputs::second is given, but ILS shades layer 0 only: pass None".into(),
            ));
        }
        let cam = self.core.check_inputs(inputs, &[], None)?;
        let (_frame, _history): (FrameUniforms, bool) = self.core.begin(inputs, &cam);
        let passes: Vec<&dyn Pass> = self.stage.passes();
        self.core.record(encoder, inputs, &[], None, passes);
        Ok(())
    }
}
