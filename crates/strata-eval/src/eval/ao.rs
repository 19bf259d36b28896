//! Deep-G-buffer AO against the CPU ground truth for the same camera and pixel centres: the
//! obscurance of DGB Eq. 2 over all surfaces (same r, β, ε; FLIP, RMSE, MAE) and binary AO.

use std::path::Path;

use anyhow::Result;
use strata_reference::ao::{AoBinarySettings, DiskSampling, ObscuranceSettings};
use strata_reference::{Estimator, Reference};
use strata_render::passes::ao::AoSettings;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::{ImageBuf, Scene};

use super::{figure, flicker, half_flip, noise_warnings, write_report, EvalSettings, RefImage};
use crate::cache::{scene_fingerprint, RefCache};
use crate::metrics::compare;
use crate::report::Section;
use crate::results::{AoErrors, AoEval, EvalResult};

/// Default cap on the references' samples per pixel (`--ref-spp`).
pub const DEFAULT_CAP: u32 = 32_768;

/// One GPU AO evaluation: the image and its errors against both references.
pub(crate) struct AoResult {
    pub(crate) layers: u32,
    pub(crate) av: ImageBuf,
    pub(crate) errors: AoErrors,
    pub(crate) obscurance_map: ImageBuf,
    pub(crate) binary_map: ImageBuf,
}

impl AoResult {
    /// `av` (of a `layers`-layer configuration) against both references.
    fn of(layers: u32, av: ImageBuf, (ref_obscurance, ref_binary): (&RefImage, &RefImage)) -> Result<Self> {
        let (obscurance, obscurance_map) = compare(&ref_obscurance.image, &av)?;
        let (binary, binary_map) = compare(&ref_binary.image, &av)?;
        Ok(Self {
            layers,
            errors: AoErrors {
                obscurance: ref_obscurance.annotate(obscurance, &av),
                binary: ref_binary.annotate(binary, &av),
            },
            av,
            obscurance_map,
            binary_map,
        })
    }
}

pub(crate) fn render_settings(s: &EvalSettings, layers: u32, ao: &AoSettings) -> RenderSettings {
    RenderSettings {
        shade: false,
        ao: Some(ao.clone()),
        // `--guard-band auto`: what `render --technique ao` uses
        guard_band: s.guard_band.or_default(strata_render::renderer::AO_GUARD_BAND),
        ..s.render_settings(layers)
    }
}

pub fn run(s: &EvalSettings, settings: &AoSettings) -> Result<AoEval> {
    let rule = s.check(DEFAULT_CAP, 16)?;
    let (scene, cams) = s.scene.load()?;
    render_settings(s, s.deep.layers, settings)
        .validate()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let camera = cams.current;
    let (radius, beta, epsilon) = settings.resolve(&scene);

    let (ref_obscurance, ref_binary) = references(s, &scene, &camera, (radius, beta, epsilon), &rule)?;

    let gpu = GpuContext::new(&GpuOptions {
        adapter: s.adapter.clone(),
    })?;
    let evaluate = |layers: u32| -> Result<AoResult> {
        let mut r = Renderer::new(&gpu, &scene, render_settings(s, layers, settings))?;
        let av = render_frame(&mut r, &gpu, &scene, s, s.scene.frame)?;
        AoResult::of(layers, av, (&ref_obscurance, &ref_binary))
    };
    let k = s.deep.layers;
    let mut results = s.layer_counts().into_iter().map(evaluate).collect::<Result<Vec<_>>>()?;
    let main = results.pop().expect("k is evaluated");
    let flicker = match s.frames {
        Some(n) => {
            let threshold = settings.temporal.map_or(0.01, |t| t.max_distance);
            let rs = render_settings(s, k, settings);
            Some(flicker(&gpu, &scene, &s.scene, rs, "ao", threshold, n)?)
        }
        None => None,
    };
    let out = AoEval {
        run: s.run_info(
            ref_obscurance.noise.spp,
            "obscurance (DGB Eq. 2 over all surfaces, spiral radial density)",
            gpu.describe(),
            flicker,
            noise_warnings(&[
                ("ao vs obscurance", &main.errors.obscurance),
                ("ao vs binary AO", &main.errors.binary),
            ]),
        ),
        samples: settings.samples,
        radius,
        bias: beta,
        epsilon,
        errors: main.errors,
        layers_1: results.first().map(|o| o.errors),
        by_layers: s.by_layers(results.iter().chain([&main]).map(|r| (r.layers, r.errors))),
        directions: None,
        visibility: None,
        no_visibility: None,
        dgb_2_layers: None,
        temporal_alpha: None,
        warmup_frames: None,
    };
    if let Some(dir) = &s.report {
        write_ao_report(
            dir,
            s,
            &out,
            &main,
            results.first(),
            &ref_obscurance.image,
            &ref_binary.image,
        )?;
    }
    Ok(out)
}

/// Ground truth for `camera`, converged to the noise target and cached: the obscurance of
/// Eq. 2 over all surfaces with the spiral's radial density (r, β, ε), and binary
/// visibility within r.
pub(crate) fn references(
    s: &EvalSettings,
    scene: &Scene,
    camera: &strata_scene::Camera,
    (radius, beta, epsilon): (f32, f32, f32),
    rule: &strata_reference::ConvergeRule,
) -> Result<(RefImage, RefImage)> {
    let (w, h) = (s.scene.width, s.scene.height);
    let cache = RefCache::new(&s.cache);
    let reference = Reference::new(scene, s.scene.frame).with_progress(s.progress);
    let obscurance = Estimator::Obscurance(ObscuranceSettings {
        radius,
        beta,
        epsilon,
        disk: DiskSampling::SpiralRadius,
        ..ObscuranceSettings::new(radius)
    });
    let binary = Estimator::AoBinary(AoBinarySettings::new(radius));
    let scene_id = scene_fingerprint(scene, s.scene.frame);
    let cam_id = format!("{camera:?} {w}x{h}");
    let converge = |name: &str, est: &Estimator| {
        let description = format!("v2 converged {name} {scene_id} {cam_id} {est:?} {rule:?}");
        let c = cache.converged(s.no_cache, &description, est, || {
            reference.converge(camera, w, h, est, rule, |a, b| half_flip(a, b, |i| i.clone()))
        });
        RefImage::of(&c, |i| i.clone(), |i| i.clone())
    };
    Ok((converge("obscurance", &obscurance)?, converge("binary-ao", &binary)?))
}

/// What the side-by-side AO evaluations (`bzb-ao`, `aba-ao`) share before any GPU
/// work: every configuration validated, both references, the GPU.
pub(crate) fn av_setup(
    s: &EvalSettings,
    scene: &Scene,
    camera: &strata_scene::Camera,
    configurations: &[RenderSettings],
    rbe: (f32, f32, f32),
    rule: &strata_reference::ConvergeRule,
) -> Result<(RefImage, RefImage, GpuContext)> {
    for rs in configurations {
        rs.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    let (ref_obscurance, ref_binary) = references(s, scene, camera, rbe, rule)?;
    let gpu = GpuContext::new(&GpuOptions {
        adapter: s.adapter.clone(),
    })?;
    Ok((ref_obscurance, ref_binary, gpu))
}

/// One GPU configuration's AV (`rs`, frame of `s`) against both references, the
/// frame's wall time and `note` (e.g. dropped fragments) printed under `what`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate_av(
    gpu: &GpuContext,
    scene: &Scene,
    s: &EvalSettings,
    rs: RenderSettings,
    what: &str,
    refs: (&RefImage, &RefImage),
    note: impl Fn(&Renderer) -> Result<String>,
) -> Result<AoResult> {
    let layers = rs.deep.layers;
    let mut r = Renderer::new(gpu, scene, rs)?;
    let start = std::time::Instant::now();
    let av = render_frame(&mut r, gpu, scene, s, s.scene.frame)?;
    eprintln!(
        "{what}: frame rendered and read back in {:.2} s{}",
        start.elapsed().as_secs_f64(),
        note(&r)?
    );
    AoResult::of(layers, av, refs)
}

/// A file name for a configuration's label: lower-case letters and digits, every other run of
/// characters one '-' ("bzb-ao visibility=off (additive)" → "bzb-ao-visibility-off-additive").
pub(crate) fn slug(label: &str) -> String {
    label
        .to_ascii_lowercase()
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .collect::<Vec<_>>()
        .join("-")
}

/// `--report` of the side-by-side AO evaluations (`bzb-ao`, `aba-ao`: `technique`): the
/// result's tables, both references, then each configuration's AV (`rows`: label, result)
/// beside its ꟻLIP maps against both.
pub(crate) fn write_side_by_side_report(
    dir: &Path,
    s: &EvalSettings,
    technique: &str,
    result: &EvalResult,
    (ref_obscurance, ref_binary): (&ImageBuf, &ImageBuf),
    rows: &[(&str, &AoResult)],
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("--report {}: {e}", dir.display()))?;
    let fig = |img: &ImageBuf, name: &str, caption: String| figure(dir, img, name, caption);
    let mut sections = vec![Section::new("Ground truth")
        .text(format!(
            "AV = 1 − AO (white = unoccluded), {}×{} pixels, frame {}, shown as grey bytes 255·AV; ꟻLIP maps use the magma scale. Binary AO within r is what the bounced z-buffer and the A-buffer estimate; DGB Eq. 2's obscurance is what deep-G-buffer AO estimates. Both references: {} spp.",
            s.scene.width,
            s.scene.height,
            s.scene.frame,
            result.run().ref_spp
        ))
        .figures(vec![
            fig(ref_binary, "reference-binary.png", "binary AV within r".into())?,
            fig(ref_obscurance, "reference-obscurance.png", "obscurance (DGB Eq. 2)".into())?,
        ])];
    for (label, r) in rows {
        let (name, e) = (slug(label), &r.errors);
        sections.push(Section::new(*label).figures(vec![
            fig(
                &r.av,
                &format!("{name}.png"),
                format!(
                    "{label}: ꟻLIP {:.4} vs binary, {:.4} vs obscurance",
                    e.binary.flip, e.obscurance.flip
                ),
            )?,
            fig(
                &r.binary_map,
                &format!("flip-binary-{name}.png"),
                "ꟻLIP vs binary AV".into(),
            )?,
            fig(
                &r.obscurance_map,
                &format!("flip-obscurance-{name}.png"),
                "ꟻLIP vs obscurance".into(),
            )?,
        ]));
    }
    write_report(
        dir,
        format!("strata eval: {technique} on {}", s.scene.scene),
        result,
        sections,
    )
}

/// Renders frame `f` (after frame f − 1 when the first frame has no history
/// yet and the variant needs it) and returns AV, cropped to the image.
pub(crate) fn render_frame(
    r: &mut Renderer,
    gpu: &GpuContext,
    scene: &Scene,
    s: &EvalSettings,
    f: f32,
) -> Result<ImageBuf> {
    if s.moving {
        // camera and objects move through the warm-up: the temporal filter reprojects
        super::render_along_path(r, gpu, scene, s, f)?;
        return Ok(r.read_target(gpu, "ao")?);
    }
    if r.settings.ao.as_ref().is_some_and(|a| a.temporal_noise)
        || r.settings.bzb.as_ref().is_some_and(|b| b.temporal.is_some())
    {
        // per-frame spiral rotations (bzb-ao with `alpha`: per-frame directions): `warmup`
        // static frames at the evaluated camera first, so the temporal filter averages
        // different tap patterns as in `render --warmup N` (with the paper's fixed rotation
        // every static frame is the same, so none are rendered)
        let fixed = strata_render::frame::FrameCameras::fixed(s.scene.cameras_at(scene, f).current);
        for _ in 0..s.warmup.max(r.settings.deep.uses_history() as u32) {
            r.render(gpu, scene, &fixed, f)?;
        }
        r.render(gpu, scene, &fixed, f)?;
        return Ok(r.read_target(gpu, "ao")?);
    }
    if r.settings.deep.uses_history() {
        r.render(gpu, scene, &s.scene.cameras_at(scene, f - 1.0), f - 1.0)?;
    }
    r.render(gpu, scene, &s.scene.cameras_at(scene, f), f)?;
    Ok(r.read_target(gpu, "ao")?)
}

fn write_ao_report(
    dir: &Path,
    s: &EvalSettings,
    out: &AoEval,
    main: &AoResult,
    one: Option<&AoResult>,
    ref_obscurance: &ImageBuf,
    ref_binary: &ImageBuf,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("--report {}: {e}", dir.display()))?;
    let k = s.deep.layers;
    let fig = |img: &ImageBuf, name: &str, caption: String| figure(dir, img, name, caption);
    let st = &main.errors.obscurance;
    let mut sections = vec![Section::new(format!(
        "{k}-layer deep-G-buffer AO against the ray-traced obscurance"
    ))
    .text(format!(
        "AV = 1 − AO (white = unoccluded), {}×{} pixels, frame {}. The reference evaluates DGB Eq. 2 with the same r, β, ε over every surface along each sample ray ({} spp converged to ꟻLIP {:.4} between two independent halves, spiral radial density). Values are shown as grey bytes 255·AV; FLIP maps use the magma scale.",
        s.scene.width, s.scene.height, s.scene.frame, out.run.ref_spp, out.errors.obscurance.ref_noise.map_or(0.0, |n| n.flip)
    ))
    .figures(vec![
        fig(&main.av, &format!("gpu-k{k}.png"), format!("GPU, k = {k}: FLIP {:.4}, MAE {:.4}", st.flip, st.mae))?,
        fig(ref_obscurance, "reference-obscurance.png", "reference: obscurance, all layers".into())?,
        fig(&main.obscurance_map, &format!("flip-k{k}.png"), format!("FLIP error, k = {k}"))?,
    ])];
    if let Some(o) = one.filter(|_| k != 1) {
        let so = &o.errors.obscurance;
        sections.push(
            Section::new(format!("1 layer vs {k} layers"))
                .text("Occluders hidden behind the first surface are only seen by later layers (DGB Eq. 1's max over layers).")
                .figures(vec![
                    fig(&o.av, "gpu-k1.png", format!("GPU, k = 1: FLIP {:.4}, MAE {:.4}", so.flip, so.mae))?,
                    fig(&main.av, &format!("gpu-k{k}.png"), format!("GPU, k = {k}: FLIP {:.4}, MAE {:.4}", st.flip, st.mae))?,
                    fig(&o.obscurance_map, "flip-k1.png", "FLIP error, k = 1".into())?,
                    fig(&main.obscurance_map, &format!("flip-k{k}.png"), format!("FLIP error, k = {k}"))?,
                ]),
        );
    }
    sections.push(
        Section::new("Against binary ambient visibility")
            .text("Cosine-weighted hit/miss within r (a different quantity from Eq. 2's obscurance; shown for scale).")
            .figures(vec![
                fig(ref_binary, "reference-binary.png", "reference: binary AV".into())?,
                fig(
                    &main.binary_map,
                    &format!("flip-binary-k{k}.png"),
                    format!("FLIP vs binary, k = {k}: {:.4}", main.errors.binary.flip),
                )?,
            ]),
    );
    write_report(
        dir,
        format!("strata eval: AO on {}", s.scene.scene),
        &EvalResult::Ao(out.clone()),
        sections,
    )
}
