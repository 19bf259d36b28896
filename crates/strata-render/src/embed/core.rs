//! What every embedded technique shares: the application's device, the import of its
//! G-buffer into strata's layered targets (`import.wgsl`), the depth MIP chain, the frame's
//! camera, the history copies and the per-pass timings.

use glam::Mat4;

use super::{is_depth, is_rigid, AoInputs, CameraModel, NormalEncoding, NormalSpace, TextureLayer};
use crate::frame::{FrameUniforms, Pass, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::depth_mip::{DepthMipPass, DepthMipSettings};
use crate::passes::HistoryPass;
use crate::scene_gpu::GpuScene;
use crate::RenderError;

/// Mirrors `Import` in `import.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ImportUniforms {
    inv_proj: [[f32; 4]; 4],
    inv_view: [[f32; 4]; 4],
    size: [f32; 4],
    w_sign: f32,
    reversed: u32,
    _pad: [u32; 2],
}

/// The shading inputs of one layer: its albedo (`EmbeddedRadiosity`; `None` where the
/// technique does not read it) and its outgoing radiance.
pub(crate) type Shading<'a> = (Option<TextureLayer<'a>>, TextureLayer<'a>);

/// Which per-layer shading inputs [`Core`] imports besides depth, normals and motion.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum ShadingImport {
    /// Depth and normals only (AO).
    None,
    /// Each layer's normal, albedo ρ and radiosity B (`normal`, `albedo`, `radiosity0/1`).
    Radiosity,
    /// Each layer's normal and outgoing radiance (layer 0's in `hdr`, layer 1's in
    /// `radiosity1`, both `Rgba16Float`), and layer 0's roughness and metallic from
    /// channels `roughness` and `metallic` of a material texture (into `normal`'s b, a).
    Reflections { roughness: u32, metallic: u32 },
    /// Each layer's normal alone (`normal`, roughness and metallic 0); `albedo` exists and
    /// stays 0 (ILS: Lambert receivers, whose ρ the application applies).
    Normals,
}

/// What an input texture holds, for [`Core::check`].
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Depth,
    /// Normals or motion: an sRGB format would decode them wrongly.
    Vector,
    /// Albedo or radiance: an sRGB format decodes to the linear values wanted.
    Colour,
}

/// What [`Core::new`] builds.
pub(crate) struct CoreConfig {
    /// The technique's name in errors ("embedded AO").
    pub what: &'static str,
    pub width: u32,
    pub height: u32,
    pub layers: u32,
    pub normals: NormalEncoding,
    pub normal_space: NormalSpace,
    /// Levels of the depth MIP chain `zmip`; `None`: no chain (a technique that reads
    /// full-resolution depth only).
    pub mip_levels: Option<u32>,
    /// The technique's kernel: the depth MIP chain's passes take the same form.
    pub kernel: crate::passes::Kernel,
    /// The shading inputs imported per layer; with any, motion is kept for every layer.
    pub shading: ShadingImport,
}

impl CoreConfig {
    /// One layer at the application's size and normal encoding, no depth MIP chain,
    /// fragment passes: the techniques that read full-resolution layer 0 only (the
    /// bounced z-buffer, ILS).
    pub fn one_layer(
        what: &'static str,
        [width, height]: [u32; 2],
        (normals, normal_space): (NormalEncoding, NormalSpace),
        shading: ShadingImport,
    ) -> Self {
        Self {
            what,
            width,
            height,
            layers: 1,
            normals,
            normal_space,
            mip_levels: None,
            kernel: crate::passes::Kernel::Fragment,
            shading,
        }
    }
}

pub(crate) struct Core {
    pub gpu: GpuContext,
    /// A scene without geometry: the technique's radii, and the frame uniforms' buffer.
    pub scene: strata_scene::Scene,
    pub scene_gpu: GpuScene,
    pub targets: Targets,
    pub width: u32,
    pub height: u32,
    pub layers: u32,
    what: &'static str,
    /// [`NormalEncoding::FromDepth`]: the normals come from the depth.
    normals_from_depth: bool,
    geometry: wgpu::RenderPipeline,
    /// One per layer (empty without shading).
    shading: Vec<wgpu::RenderPipeline>,
    /// The target each layer's radiance goes to.
    radiance_targets: Vec<&'static str>,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    /// Zeros at the render size: bound where the application gives no motion texture, and
    /// for the shading inputs a technique does not read.
    zeros: wgpu::TextureView,
    mip: Option<DepthMipPass>,
    pub history: HistoryPass,
    /// Per-pass GPU time where the application's device has timestamp queries inside
    /// encoders (`TIMESTAMP_QUERY | TIMESTAMP_QUERY_INSIDE_ENCODERS`).
    profiler: crate::profiler::Profiler,
    pub frames: u32,
    prev_view_proj: Option<Mat4>,
    /// The import's bind group and the textures it was made for: kept while the
    /// application passes the same textures, so a steady frame creates no views or bind
    /// groups (each one is a descriptor set the driver allocates and frees).
    import: Option<(ImportKey, wgpu::BindGroup)>,
}

/// The textures (and array layers) of one frame's import: depth, normals, the second
/// layer's depth and normals, motion, the shading inputs, the material.
type ImportKey = Vec<Option<(wgpu::Texture, u32)>>;

fn import_key(inputs: &AoInputs<'_>, shading: &[Shading<'_>], material: Option<TextureLayer<'_>>) -> ImportKey {
    let k = |t: Option<TextureLayer<'_>>| t.map(|t| (t.texture.clone(), t.layer));
    let mut key = vec![
        k(Some(inputs.depth)),
        k(Some(inputs.normals)),
        k(inputs.second.map(|s| s.0)),
        k(inputs.second.map(|s| s.1)),
        k(inputs.motion),
    ];
    key.extend(shading.iter().flat_map(|(a, r)| [k(*a), k(Some(*r))]));
    key.push(k(material));
    key
}

impl Core {
    /// Opens the application's device, checks the size and layers, and builds the import
    /// and the depth MIP chain; `stage` then adds the technique's passes.
    pub fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        c: CoreConfig,
        scene: strata_scene::Scene,
    ) -> Result<Self, RenderError> {
        let what = c.what;
        if !(1..=super::MAX_LAYERS).contains(&c.layers) {
            return Err(RenderError::Parameter(format!(
                "{what}: layers {} is out of range: must be in 1..={}",
                c.layers,
                super::MAX_LAYERS
            )));
        }
        let max = device.limits().max_texture_dimension_2d;
        if !(1..=max).contains(&c.width) || !(1..=max).contains(&c.height) {
            return Err(RenderError::Parameter(format!(
                "{what}: size {}x{} is out of range: width and height must be in 1..={max}",
                c.width, c.height
            )));
        }
        let gpu = GpuContext::from_device(adapter, device, queue);
        Ok(Self::build(gpu, c, scene))
    }

    fn build(gpu: GpuContext, c: CoreConfig, scene: strata_scene::Scene) -> Self {
        use wgpu::TextureFormat as F;
        let (w, h, layers) = (c.width, c.height, c.layers);
        let shading = c.shading != ShadingImport::None;
        let radiance_targets: Vec<&'static str> = match c.shading {
            ShadingImport::None | ShadingImport::Normals => Vec::new(),
            ShadingImport::Radiosity => crate::passes::lighting::RADIOSITY.to_vec(),
            ShadingImport::Reflections { .. } => vec!["hdr", crate::passes::lighting::RADIOSITY[1]],
        };
        let radiance_targets: Vec<_> = radiance_targets.into_iter().take(layers as usize).collect();
        // the radiosity's B in DGB Table 1's format; the reflections' radiance in one every
        // device renders to (RG11B10 needs a feature) and that holds it exactly
        let radiance_format = match c.shading {
            ShadingImport::Radiosity => crate::passes::deep_gbuffer::RADIOSITY_FORMAT,
            _ => F::Rgba16Float,
        };
        let scene_gpu = GpuScene::new(&gpu, &scene);
        let mut targets = Targets::new(w, h);
        let mut imported = vec![
            TargetDesc::new(
                "zpack",
                F::Rg32Float,
                1,
                "DGB Table 1: camera-space z of layers 0 (r) and 1 (g)",
            ),
            TargetDesc::new(
                "npack",
                F::Rgba8Unorm,
                1,
                "DGB Table 1: Oct16 normals of layers 0 (rg) and 1 (ba)",
            ),
            TargetDesc::new(
                "csz",
                F::R32Float,
                layers,
                "camera-space depth z per layer (0 = no surface)",
            ),
            TargetDesc::new(
                "motion",
                F::Rgba16Float,
                if shading { layers } else { 1 },
                "world-space motion since last frame (layer 0's from the application, others 0)",
            ),
        ];
        if shading {
            imported.push(TargetDesc::new(
                "normal",
                F::Rgba8Unorm,
                layers,
                "rg = Oct16 world normal, b = roughness, a = metallic per layer",
            ));
            imported.push(TargetDesc::new(
                "albedo",
                F::Rgba8UnormSrgb,
                layers,
                "diffuse albedo ρ per layer",
            ));
            for name in &radiance_targets {
                imported.push(TargetDesc::new(
                    name,
                    radiance_format,
                    1,
                    "the layer's outgoing radiance from the application (DGB Table 1's radiosity B)",
                ));
            }
        }
        for d in imported {
            targets.create(&gpu, d);
        }
        let mip = c.mip_levels.map(|levels| {
            let zmip = DepthMipSettings { levels }.output(layers, w, h);
            let compute = DepthMipPass::compute_on(&gpu, c.kernel, zmip.format);
            targets.create_storable(&gpu, zmip, compute);
            DepthMipPass::new(&gpu, &targets, layers, compute)
        });

        let device = &gpu.device;
        let depth_entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let colour = |b| crate::passes::texture_entry(b, wgpu::TextureViewDimension::D2, false);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("embed-import"),
            entries: &[
                crate::passes::uniform_entry(0),
                depth_entry(1),
                colour(2),
                depth_entry(3),
                colour(4),
                colour(5),
                colour(6),
                colour(7),
                colour(8),
                colour(9),
                colour(10),
            ],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("embed-import"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = crate::shader::module(device, "embed-import", include_str!("import.wgsl"));
        let normals = match c.normals {
            NormalEncoding::Signed => 0.0,
            NormalEncoding::Unsigned => 1.0,
            NormalEncoding::Octahedral => 2.0,
            NormalEncoding::FromDepth => 3.0,
        };
        let (material, roughness, metallic) = match c.shading {
            ShadingImport::Reflections { roughness, metallic } => (1.0, roughness as f64, metallic as f64),
            _ => (0.0, 1.0, 2.0),
        };
        let pipeline = |entry: &str, layer: u32, formats: &[F]| {
            let color: Vec<_> = formats.iter().map(|f| Some(wgpu::ColorTargetState::from(*f))).collect();
            let constants = [
                ("NORMALS", normals),
                ("VIEW_SPACE", (c.normal_space == NormalSpace::View) as u32 as f64),
                ("LAYER", layer as f64),
                ("MATERIAL", if layer == 0 { material } else { 0.0 }),
                ("ROUGHNESS", roughness),
                ("METALLIC", metallic),
            ];
            crate::passes::fullscreen_pipeline_with(device, "embed-import", &pl, &module, entry, &constants, &color)
        };
        let mut formats = vec![F::Rg32Float, F::Rgba8Unorm, F::R32Float, F::Rgba16Float];
        if layers == 2 {
            formats.push(F::R32Float);
        }
        let geometry = pipeline(if layers == 2 { "fs_import2" } else { "fs_import1" }, 0, &formats);
        let per_layer = [F::Rgba8Unorm, F::Rgba8UnormSrgb, radiance_format];
        let shading_pipelines = match c.shading {
            ShadingImport::Normals => (0..layers).map(|j| pipeline("fs_normal", j, &per_layer[..1])).collect(),
            _ => (0..radiance_targets.len() as u32)
                .map(|j| pipeline("fs_shading", j, &per_layer))
                .collect(),
        };
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("embed-import"),
            size: std::mem::size_of::<ImportUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // zero-initialised by wgpu
        let zeros = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("embed-zeros"),
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: F::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
            .create_view(&Default::default());
        let profiler = crate::profiler::Profiler::new(&gpu, 24);
        Self {
            gpu,
            scene,
            scene_gpu,
            targets,
            width: w,
            height: h,
            layers,
            what: c.what,
            normals_from_depth: c.normals == NormalEncoding::FromDepth,
            geometry,
            shading: shading_pipelines,
            radiance_targets,
            layout,
            uniforms,
            zeros,
            import: None,
            mip,
            history: HistoryPass { copies: Vec::new() },
            profiler,
            frames: 0,
            prev_view_proj: None,
        }
    }

    /// Runs `build` inside a validation error scope: a wgpu error while building becomes
    /// the returned error instead of the application's uncaptured-error handler's.
    pub fn scoped<T>(device: &wgpu::Device, build: impl FnOnce() -> Result<T, RenderError>) -> Result<T, RenderError> {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let built = build();
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RenderError::Validation(e.to_string()));
        }
        built
    }

    /// Checks one input texture: size, usage, sampling, format kind and layer.
    pub fn check(&self, what: &str, t: TextureLayer<'_>, kind: Kind) -> Result<(), RenderError> {
        let depth = kind == Kind::Depth;
        let bad = |why: String| Err(RenderError::Parameter(format!("{}: {what} {why}", self.what)));
        let tex = t.texture;
        let (w, h) = (self.width, self.height);
        if tex.width() != w || tex.height() != h {
            return bad(format!(
                "is {}x{}: it must be the configured {w}x{h} (the config's width/height)",
                tex.width(),
                tex.height()
            ));
        }
        if tex.dimension() != wgpu::TextureDimension::D2 {
            return bad("must be a 2D texture".into());
        }
        if t.layer >= tex.depth_or_array_layers() {
            return bad(format!(
                "layer {} is out of range: must be in 0..{}",
                t.layer,
                tex.depth_or_array_layers()
            ));
        }
        if !tex.usage().contains(wgpu::TextureUsages::TEXTURE_BINDING) {
            return bad("lacks TextureUsages::TEXTURE_BINDING".into());
        }
        if tex.sample_count() != 1 {
            return bad(format!(
                "has {} samples: resolve it to a single-sampled texture first",
                tex.sample_count()
            ));
        }
        let f = tex.format();
        if depth && !is_depth(f) {
            return bad(format!(
                "has format {f:?}: it must be a depth format (Depth16Unorm, Depth24Plus[Stencil8], Depth32Float[Stencil8])"
            ));
        }
        if !depth {
            let float = matches!(
                f.sample_type(None, Some(self.gpu.features)),
                Some(wgpu::TextureSampleType::Float { .. })
            );
            if !float || f.is_depth_stencil_format() {
                return bad(format!(
                    "has format {f:?}: it must be a float, unorm or snorm colour format"
                ));
            }
            if f.is_srgb() && kind == Kind::Vector {
                return bad(format!(
                    "has format {f:?}: an sRGB format would decode the values; use its linear twin"
                ));
            }
        }
        Ok(())
    }

    /// Checks the G-buffer inputs, the shading inputs (one pair per layer where the
    /// technique reads them) and the material texture, and reads the camera.
    pub fn check_inputs(
        &self,
        inputs: &AoInputs<'_>,
        shading: &[Shading<'_>],
        material: Option<TextureLayer<'_>>,
    ) -> Result<CameraModel, RenderError> {
        let what = self.what;
        // NormalEncoding::FromDepth reads no normal texture
        let normals = !self.normals_from_depth;
        self.check("depth", inputs.depth, Kind::Depth)?;
        if normals {
            self.check("normals", inputs.normals, Kind::Vector)?;
        }
        match (self.layers, &inputs.second) {
            (2, Some((d, n))) => {
                self.check("second depth", *d, Kind::Depth)?;
                if normals {
                    self.check("second normals", *n, Kind::Vector)?;
                }
            }
            (2, None) => {
                return Err(RenderError::Parameter(format!(
                    "{what}: 2 layers need AoInputs::second (the second layer's depth and normals)"
                )))
            }
            (_, Some(_)) => {
                return Err(RenderError::Parameter(format!(
                    "{what}: AoInputs::second is given but the config has 1 layer (layers = 2 uses it)"
                )))
            }
            _ => {}
        }
        for (j, (albedo, radiance)) in shading.iter().enumerate() {
            let layer = if j == 0 { "" } else { "second " };
            if let Some(albedo) = albedo {
                self.check(&format!("{layer}albedo"), *albedo, Kind::Colour)?;
            }
            self.check(&format!("{layer}radiance"), *radiance, Kind::Colour)?;
        }
        if let Some(m) = material {
            self.check("material", m, Kind::Vector)?;
        }
        if let Some(m) = inputs.motion {
            self.check("motion", m, Kind::Vector)?;
        }
        if !is_rigid(inputs.view) {
            return Err(RenderError::Parameter(format!(
                "{what}: view is not a rigid transform (a rotation and a translation, without scale)"
            )));
        }
        CameraModel::of(inputs.proj, self.width, self.height).map_err(|e| match e {
            RenderError::Parameter(m) => RenderError::Parameter(format!("{what}: {m}")),
            e => e,
        })
    }

    /// This frame's uniforms for `cam` (the frame buffer is written), and whether the
    /// temporal filters have last frame's history.
    pub fn begin(&mut self, inputs: &AoInputs<'_>, cam: &CameraModel) -> (FrameUniforms, bool) {
        let vp = cam.unjittered * inputs.view;
        let has_history = self.prev_view_proj.is_some();
        let frame = cam.frame_uniforms(inputs.view, self.prev_view_proj.unwrap_or(vp), self.width, self.height);
        self.scene_gpu.update_frame(&self.gpu, &frame);
        let u = ImportUniforms {
            inv_proj: inputs.proj.inverse().to_cols_array_2d(),
            inv_view: inputs.view.inverse().to_cols_array_2d(),
            size: frame.size,
            w_sign: cam.w_sign,
            reversed: cam.reversed as u32,
            _pad: [0; 2],
        };
        self.gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        self.prev_view_proj = Some(vp);
        (frame, has_history)
    }

    /// The highest MIP level of `zmip`.
    pub fn max_mip(&self) -> u32 {
        self.targets.get("zmip").desc.mips - 1
    }

    fn view(t: TextureLayer<'_>, depth: bool) -> wgpu::TextureView {
        t.texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("embed-input"),
            dimension: Some(wgpu::TextureViewDimension::D2),
            aspect: if depth {
                wgpu::TextureAspect::DepthOnly
            } else {
                wgpu::TextureAspect::All
            },
            base_array_layer: t.layer,
            array_layer_count: Some(1),
            mip_level_count: Some(1),
            ..Default::default()
        })
    }

    /// The import's bind group over views of this frame's textures.
    fn import_group(
        &self,
        inputs: &AoInputs<'_>,
        shading: &[Shading<'_>],
        material: Option<TextureLayer<'_>>,
    ) -> wgpu::BindGroup {
        let depth0 = Self::view(inputs.depth, true);
        // NormalEncoding::FromDepth: the shader reads no normal texture
        let normal = |n| match self.normals_from_depth {
            true => self.zeros.clone(),
            false => Self::view(n, false),
        };
        let normal0 = normal(inputs.normals);
        let (depth1, normal1) = match inputs.second {
            Some((d, n)) => (Self::view(d, true), normal(n)),
            None => (depth0.clone(), normal0.clone()),
        };
        let motion = inputs.motion.map(|m| Self::view(m, false));
        let shade: Vec<Option<wgpu::TextureView>> = shading
            .iter()
            .flat_map(|(a, r)| [a.map(|a| Self::view(a, false)), Some(Self::view(*r, false))])
            .collect();
        let shade_at = |i: usize| shade.get(i).and_then(|v| v.as_ref()).unwrap_or(&self.zeros);
        let material = material.map(|m| Self::view(m, false));
        use wgpu::BindingResource as R;
        crate::passes::bind_group(
            &self.gpu.device,
            "embed-import",
            &self.layout,
            &[
                self.uniforms.as_entire_binding(),
                R::TextureView(&depth0),
                R::TextureView(&normal0),
                R::TextureView(&depth1),
                R::TextureView(&normal1),
                R::TextureView(motion.as_ref().unwrap_or(&self.zeros)),
                R::TextureView(shade_at(0)),
                R::TextureView(shade_at(1)),
                R::TextureView(shade_at(2)),
                R::TextureView(shade_at(3)),
                R::TextureView(material.as_ref().unwrap_or(&self.zeros)),
            ],
        )
    }

    /// Records the import, the depth MIP chain, `stage` and the history copies, each timed.
    pub fn record(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &AoInputs<'_>,
        shading: &[Shading<'_>],
        material: Option<TextureLayer<'_>>,
        stage: Vec<&dyn Pass>,
    ) {
        let key = import_key(inputs, shading, material);
        if self.import.as_ref().is_none_or(|(k, _)| *k != key) {
            let group = self.import_group(inputs, shading, material);
            self.import = Some((key, group));
        }
        let group = &self.import.as_ref().expect("made above").1;
        let t = &self.targets;
        let mut outputs = vec![
            &t.get("zpack").view,
            &t.get("npack").view,
            &t.get("csz").layer_views[0],
            &t.get("motion").layer_views[0],
        ];
        if self.layers == 2 {
            outputs.push(&t.get("csz").layer_views[1]);
        }
        let prof = &self.profiler;
        prof.reset();
        let slot = prof.begin(encoder, "embed-import");
        crate::passes::fullscreen_pass(encoder, "embed-import", &self.geometry, &outputs, &[group]);
        prof.end(encoder, slot);
        if !self.shading.is_empty() {
            let slot = prof.begin(encoder, "embed-import-shading");
            for (j, pipeline) in self.shading.iter().enumerate() {
                let normal = &t.get("normal").layer_views[j];
                match self.radiance_targets.get(j) {
                    Some(radiance) => {
                        let outputs = [normal, &t.get("albedo").layer_views[j], &t.get(radiance).view];
                        crate::passes::fullscreen_pass(encoder, "embed-import-shading", pipeline, &outputs, &[group]);
                    }
                    // ShadingImport::Normals
                    None => {
                        crate::passes::fullscreen_pass(encoder, "embed-import-shading", pipeline, &[normal], &[group])
                    }
                }
            }
            prof.end(encoder, slot);
        }
        let mut passes: Vec<&dyn Pass> = self.mip.iter().map(|m| m as &dyn Pass).collect();
        passes.extend(stage);
        if !self.history.copies.is_empty() {
            passes.push(&self.history);
        }
        for p in passes {
            let slot = prof.begin(encoder, p.info().name);
            p.encode(&self.gpu, &self.scene_gpu, t, encoder);
            prof.end(encoder, slot);
        }
        prof.resolve(encoder);
        self.frames = self.frames.wrapping_add(1);
    }

    /// The pass names [`Core::record`] records around `stage`'s, in order.
    pub fn pass_names(&self, stage: Vec<&dyn Pass>) -> Vec<&'static str> {
        let mut v = vec!["embed-import"];
        if !self.shading.is_empty() {
            v.push("embed-import-shading");
        }
        v.extend(self.mip.iter().map(|m| m.info().name));
        v.extend(stage.iter().map(|p| p.info().name));
        if !self.history.copies.is_empty() {
            v.push(self.history.info().name);
        }
        v
    }

    /// Reads layer 0 of target `name` back as floats.
    pub fn read_target(&self, name: &str) -> Result<strata_scene::ImageBuf, RenderError> {
        let t = self
            .targets
            .try_get(name)
            .ok_or_else(|| RenderError::Parameter(format!("{}: unknown target '{name}'", self.what)))?;
        let bytes = self.gpu.read_texture(&t.texture, 0)?;
        crate::renderer::decode_texels(&bytes, t.desc.format, t.texture.width(), t.texture.height())
    }

    /// GPU milliseconds per pass of the last submitted frame (waits for it).
    pub fn timings(&self) -> Result<crate::PassTimings, RenderError> {
        self.profiler.read(&self.gpu)
    }

    pub fn reset_history(&mut self) {
        self.prev_view_proj = None;
    }
}
