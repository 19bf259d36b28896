//! Bounced-z-buffer AO (BZB §3) on an application's G-buffer and geometry: the passes of
//! `strata render --technique bzb-ao`, from the directions to the bilateral filter.
//!
//! Screen-space AO sees only what the G-buffer holds. The bounced z-buffer splats the
//! scene's triangles themselves into a depth-buffered framebuffer of per-pixel directions,
//! so each ray's nearest occluder wins wherever it is, on screen or not (BZB §3.2). The
//! application therefore gives its world-space triangles once ([`EmbeddedBzbAo::new`]), and
//! again when they move ([`EmbeddedBzbAo::set_triangles`], or
//! [`EmbeddedBzbAo::set_triangle_range`] for one object's range), besides the per-frame depth and
//! normals [`super::EmbeddedAo`] reads. It gets back the same output: ambient visibility
//! AV in [0, 1], 1 = unoccluded, binary AO within the radius r.

use glam::{Mat4, Vec3};

use super::core::{Core, CoreConfig};
use super::{AoInputs, NormalEncoding, NormalSpace};
use crate::frame::{FrameUniforms, Pass, TargetDesc};
use crate::passes::bzb::dss::SurfelCounts;
use crate::passes::bzb::{BzbSettings, BzbStage, TEMPORAL, TEMPORAL_FRAMES};
use crate::RenderError;

/// What [`EmbeddedBzbAo::new`] builds.
#[derive(Clone, Debug)]
pub struct EmbeddedBzbAoConfig {
    /// The application's render size in pixels (the inputs' size).
    pub width: u32,
    pub height: u32,
    /// The settings of `strata render --technique bzb-ao`: S directions, AOV triangle
    /// splats or DSS surfels, the temporal filter (`temporal`, BZB §6), the bilateral
    /// filter. `radius` is required: r = d_max in world units.
    pub settings: BzbSettings,
    pub normals: NormalEncoding,
    pub normal_space: NormalSpace,
}

impl Default for EmbeddedBzbAoConfig {
    /// 1×1 (set the size), [`BzbSettings::default`] (S = 4, AOV splats with visibility; no
    /// radius: set it), signed world-space normals.
    fn default() -> Self {
        Self {
            width: 1,
            height: 1,
            settings: BzbSettings::default(),
            normals: NormalEncoding::Signed,
            normal_space: NormalSpace::World,
        }
    }
}

/// The triangles of an indexed mesh in world space: `indices` in threes into `positions`,
/// each position moved by `model`. An index out of range is a one-line error.
pub fn indexed_triangles(positions: &[Vec3], indices: &[u32], model: Mat4) -> Result<Vec<[Vec3; 3]>, RenderError> {
    if !indices.len().is_multiple_of(3) {
        return Err(RenderError::Parameter(format!(
            "indexed triangles: {} indices is not a multiple of 3",
            indices.len()
        )));
    }
    indices
        .chunks_exact(3)
        .map(|t| {
            let mut tri = [Vec3::ZERO; 3];
            for (k, &i) in t.iter().enumerate() {
                let p = positions.get(i as usize).ok_or_else(|| {
                    RenderError::Parameter(format!(
                        "indexed triangles: index {i} is out of range: must be in 0..{}",
                        positions.len()
                    ))
                })?;
                tri[k] = model.transform_point3(*p);
            }
            Ok(tri)
        })
        .collect()
}

/// `triangles` in the splat buffer's layout (3 × vec4 each), checked finite.
fn splat_data(triangles: &[[Vec3; 3]]) -> Result<Vec<[f32; 4]>, RenderError> {
    super::check_triangles("embedded bzb AO", triangles, 0)?;
    let mut data = vec![[0.0; 4]; triangles.len() * 3];
    fill_splat_data(&mut data, triangles);
    Ok(data)
}

/// Writes `triangles` into `data` (3 entries each) in the splat buffer's layout.
fn fill_splat_data(data: &mut [[f32; 4]], triangles: &[[Vec3; 3]]) {
    for (d, p) in data.iter_mut().zip(triangles.iter().flatten()) {
        *d = p.extend(0.0).to_array();
    }
}

/// The bounced-z-buffer AO passes of `strata render --technique bzb-ao` on an
/// application's G-buffer and triangles.
pub struct EmbeddedBzbAo {
    core: Core,
    config: EmbeddedBzbAoConfig,
    stage: BzbStage,
    /// The triangles the stage splats (kept to rebuild on a resize or a new count).
    data: Vec<[f32; 4]>,
}

super::embedded_common!(EmbeddedBzbAo, EmbeddedBzbAoConfig);

impl EmbeddedBzbAo {
    /// Builds the passes for `config` on the application's device, splatting `triangles`
    /// (world space, the occluders: typically every opaque triangle of the scene). Errors
    /// name the parameter and its valid range.
    pub fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: EmbeddedBzbAoConfig,
        triangles: &[[Vec3; 3]],
    ) -> Result<Self, RenderError> {
        let data = splat_data(triangles)?;
        Self::build(adapter, device, queue, config, data)
    }

    fn build(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: EmbeddedBzbAoConfig,
        data: Vec<[f32; 4]>,
    ) -> Result<Self, RenderError> {
        let what = "embedded bzb AO";
        let s = &config.settings;
        let radius = super::required_radius(what, s.radius, "the world-space AO radius r = d_max", s.validate())?;
        let mut scene = strata_scene::Scene {
            name: "embedded".into(),
            ..Default::default()
        };
        scene.settings.ao_radius = radius;
        // BZB's receivers are the visible surfaces (one layer); its occluders are the
        // triangles
        let core = CoreConfig::one_layer(
            what,
            [config.width, config.height],
            (config.normals, config.normal_space),
            super::core::ShadingImport::None,
        );
        Core::scoped(device, || {
            let mut core = Core::new(adapter, device, queue, core, scene)?;
            if s.temporal.is_some() {
                core.targets.create(
                    &core.gpu,
                    TargetDesc::new("csz-history", wgpu::TextureFormat::R32Float, 1, "last frame's csz"),
                );
            }
            let stage =
                BzbStage::with_triangles(&core.gpu, &core.scene_gpu, &mut core.targets, s, &core.scene, 1, &data)?;
            if stage.temporal.is_some() {
                let [n, h] = TEMPORAL_FRAMES;
                core.history.copies = vec![("csz", "csz-history"), (TEMPORAL[0].name, TEMPORAL[1].name), (n, h)];
            }
            Ok(Self {
                core,
                config: config.clone(),
                stage,
                data,
            })
        })
    }

    /// Replaces the splatted triangles (moving or changed geometry). With as many
    /// triangles as before they are written in place; another count rebuilds the passes
    /// (the temporal history then starts afresh). On error nothing changes.
    pub fn set_triangles(&mut self, triangles: &[[Vec3; 3]]) -> Result<(), RenderError> {
        if triangles.len() * 3 == self.data.len() {
            return self.set_triangle_range(0, triangles);
        }
        let data = splat_data(triangles)?;
        let gpu = &self.core.gpu;
        *self = Self::build(&gpu.adapter, &gpu.device, &gpu.queue, self.config.clone(), data)?;
        Ok(())
    }

    /// Replaces triangles `first..first + triangles.len()` in place, for an object that
    /// moves while the rest stays: only that range is written to the GPU, and nothing is
    /// allocated. The range must lie within the current triangles; a range outside them
    /// or a non-finite vertex is a one-line error, and then nothing changes.
    pub fn set_triangle_range(&mut self, first: u32, triangles: &[[Vec3; 3]]) -> Result<(), RenderError> {
        let count = self.data.len() / 3;
        let (start, end) = (first as usize, first as usize + triangles.len());
        if end > count {
            return Err(RenderError::Parameter(format!(
                "embedded bzb AO: triangle range {start}..{end} is out of range: must lie within 0..{count} (set_triangles changes the count)"
            )));
        }
        super::check_triangles("embedded bzb AO", triangles, start)?;
        let data = &mut self.data[start * 3..end * 3];
        fill_splat_data(data, triangles);
        self.stage.write_triangles(&self.core.gpu, first, data);
        Ok(())
    }

    /// With DSS surfels (`settings.splat`): the last submitted frame's surfel counts
    /// (BZB Table 2), read back (this waits for the GPU). `None` with AOV splats.
    pub fn dss_counts(&self) -> Option<Result<SurfelCounts, RenderError>> {
        let d = self.stage.dss()?;
        Some(d.read_counts(&self.core.gpu, self.stage.triangle_count()))
    }

    /// With DSS surfels: a one-line message when the last submitted frame's surfelization
    /// overflowed a buffer ([`SurfelCounts::overflow`]; the excess was dropped, so that
    /// frame misses occluders), `Ok(None)` when everything fitted or with AOV splats. It
    /// reads the counts back, so call it now and then (after a change of triangles or
    /// camera), not every frame.
    pub fn dss_overflow(&self) -> Result<Option<String>, RenderError> {
        match (self.stage.dss(), self.dss_counts()) {
            (Some(d), Some(c)) => Ok(c?.overflow(d.capacity()).map(|m| format!("embedded bzb AO: {m}"))),
            _ => Ok(None),
        }
    }

    /// Triangles splatted each frame.
    pub fn triangle_count(&self) -> u32 {
        self.stage.triangle_count()
    }

    /// Rebuilds the passes for a new render size (a resized window), keeping the config
    /// and the triangles; the temporal history starts afresh. On error the old size stays.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), RenderError> {
        let mut config = self.config.clone();
        config.width = width;
        config.height = height;
        let gpu = &self.core.gpu;
        *self = Self::build(&gpu.adapter, &gpu.device, &gpu.queue, config, self.data.clone())?;
        Ok(())
    }

    /// The ambient visibility AV (`R16Float`, 1 = unoccluded), written by the last
    /// [`EmbeddedBzbAo::encode`] once its encoder is submitted.
    pub fn output(&self) -> &wgpu::Texture {
        &self.core.targets.get("ao").texture
    }

    /// A view of [`EmbeddedBzbAo::output`] to bind in the application's lighting pass.
    pub fn output_view(&self) -> &wgpu::TextureView {
        &self.core.targets.get("ao").view
    }

    /// Records this frame's AO into `encoder` and writes its uniforms with the queue: submit
    /// `encoder` before the next call. `inputs` has one layer (no `second`). Inputs are
    /// checked first; a bad one is a one-line error and nothing is recorded.
    pub fn encode(&mut self, encoder: &mut wgpu::CommandEncoder, inputs: &AoInputs<'_>) -> Result<(), RenderError> {
        if inputs.second.is_some() {
            return Err(RenderError::Parameter(
                "embedded bzb AO: AoInputs::second is given, but the bounced z-buffer reads one layer (its occluders are the triangles): pass None".into(),
            ));
        }
        let cam = self.core.check_inputs(inputs, &[], None)?;
        let (_frame, has_history): (FrameUniforms, bool) = self.core.begin(inputs, &cam);
        // the triangles are the application's: written by `set_triangles`, not per frame
        self.stage.set_frame(
            &self.core.gpu,
            &self.core.scene,
            0.0,
            false,
            self.core.frames,
            has_history,
        );
        let passes: Vec<&dyn Pass> = self.stage.passes();
        self.core.record(encoder, inputs, &[], None, passes);
        Ok(())
    }
}
