//! Deep-G-buffer radiosity against the CPU path tracer for the same camera: the indirect diffuse
//! light alone and the full image (direct + indirect), as FLIP on tonemapped images and RMSE/MAE
//! on linear radiance; optionally DGB Fig. 10's error-source study.

use std::path::Path;

use anyhow::{bail, Result};
use glam::Vec3;
use strata_reference::gi::{GiSettings, OneBounceSettings};
use strata_reference::{Estimator, Reference};
use strata_render::frame::FrameCameras;
use strata_render::passes::lighting::LightingSettings;
use strata_render::passes::radiosity::{probe_blend, probe_detail_blend, RadiositySettings};
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::{Camera, ImageBuf, Scene};

use super::{figure, flicker, half_flip, noise_warnings, write_report, EvalSettings, RefImage};
use crate::cache::{scene_fingerprint, RefCache};
use crate::metrics::{compare_radiance, display};
use crate::report::Section;
use crate::results::{
    EvalResult, Fig10, Fig10Row, GiErrors, GiEval, GiGatherAgreement, GiOracle, GiOracleEntry, GiOracleRow,
};

/// Default cap on the path tracer's samples per pixel (`--ref-spp`).
pub const DEFAULT_CAP: u32 = 32_768;
/// Samples per pixel of Fig. 10's single-bounce references.
const FIG10_SPP: u32 = 256;

/// What only the GI evaluation takes.
#[derive(Clone, Debug)]
pub struct GiEvalSettings {
    /// Indirect bounces of the path-traced reference, 1..=64.
    pub bounces: u32,
    /// Also run DGB Fig. 10's error-source study.
    pub fig10: bool,
    /// Blend with light probes baked from the evaluated scene (DGB's coarse-scale fallback).
    pub probes: bool,
    /// Bake the probes from this scene instead (stale probes; sky and ambient off as for
    /// the evaluated scene).
    pub probes_from: Option<String>,
    /// The probes' grid, probes per axis (`cache::probes::GRID` by default).
    pub probe_bake: crate::cache::probes::ProbeBake,
    /// Also evaluate DGB's blend with a perfect gather (`strata_reference::oracle`).
    pub oracle: bool,
}

/// GPU images of one configuration and their errors.
struct GiResult {
    layers: u32,
    full: ImageBuf,
    indirect: ImageBuf,
    errors: GiErrors,
    full_map: ImageBuf,
    indirect_map: ImageBuf,
    /// The probes' irradiance the GPU blended with (`--oracle` with probes).
    probe_irradiance: Option<ImageBuf>,
    /// The GPU's gathered irradiance E_dgb (RGB) and confidence c (A), as compose reads
    /// them (`--oracle`).
    gathered: Option<ImageBuf>,
}

/// The path tracer's GI of `camera` with `bounces` indirect bounces, converged under
/// `rule` until both the full image and the indirect light of its two halves are within
/// the noise target (ꟻLIP on the tonemapped images), and cached by scene, camera, size,
/// estimator and rule — `eval gi`, `ils` (one bounce), `bzb-gi` and ILS §6.3 share
/// entries. No Russian roulette: the path length is bounded by `bounces` anyway, and
/// roulette's reweighted survivors were most of the noise of the deeper bounces.
pub(crate) fn converged_gi(
    s: &EvalSettings,
    scene: &Scene,
    camera: Camera,
    bounces: u32,
    rule: &strata_reference::ConvergeRule,
) -> strata_reference::Converged {
    let (w, h) = (s.scene.width, s.scene.height);
    let estimator = Estimator::Gi(GiSettings {
        bounces,
        russian_roulette: false,
        ..Default::default()
    });
    let description = format!(
        "v2 converged gi {} {camera:?} {w}x{h} {estimator:?} {rule:?}",
        scene_fingerprint(scene, s.scene.frame)
    );
    let exposure = scene.settings.exposure;
    let shown = |img: &ImageBuf| display(img, exposure);
    RefCache::new(&s.cache).converged(s.no_cache, &description, &estimator, || {
        Reference::new(scene, s.scene.frame).with_progress(s.progress).converge(
            &camera,
            w,
            h,
            &estimator,
            rule,
            |a, b| half_flip(&total(a), &total(b), shown).max(half_flip(&indirect(a), &indirect(b), shown)),
        )
    })
}

pub fn run(s: &EvalSettings, rs: &RadiositySettings, g: &GiEvalSettings) -> Result<GiEval> {
    let rule = s.check(DEFAULT_CAP, 8)?;
    if !(1..=64).contains(&g.bounces) {
        bail!("--bounces {} is out of range: must be in 1..=64", g.bounces);
    }
    if g.oracle && !(1..=2).contains(&s.deep.layers) {
        bail!(
            "--layers {} with --oracle: the oracle splits the light by 1 or 2 layers, so --layers must be in 1..=2",
            s.deep.layers
        );
    }
    let (mut scene, cams) = s.scene.load()?;
    // Compare like with like: the reference is Lambertian with no ambient
    // term, and the sky is an environment light that screen-space radiosity
    // does not see (the light-probe fallback's job): both are removed.
    scene.settings.ambient = [0.0; 3];
    scene.settings.sky = [0.0; 3];
    let (_w, _h) = (s.scene.width, s.scene.height);
    let camera = cams.current;
    render_settings(s, s.deep.layers, rs)
        .validate()
        .map_err(|e| anyhow::anyhow!("{e}"))?;

    let cache = RefCache::new(&s.cache);
    let exposure = s.display_exposure(&scene);
    let shown = |img: &ImageBuf| display(img, exposure);
    let converged = converged_gi(s, &scene, camera, g.bounces, &rule);
    let ref_total = RefImage::of(&converged, total, shown)?;
    let ref_indirect = RefImage::of(&converged, indirect, shown)?;

    let gpu = GpuContext::new(&GpuOptions {
        adapter: s.adapter.clone(),
    })?;
    // the probes see the scene as evaluated: sky and ambient off
    let probes = match (g.probes, &g.probes_from) {
        (false, _) => None,
        (true, None) => Some(crate::cache::probes::scene_probes(
            &scene,
            g.probe_bake,
            &cache,
            !s.progress,
        )?),
        (true, Some(other)) => {
            let mut source = strata_scene::load_scene(other).map_err(|e| anyhow::anyhow!("--probes-from: {e}"))?;
            source.settings.ambient = [0.0; 3];
            source.settings.sky = [0.0; 3];
            Some(crate::cache::probes::scene_probes(
                &source,
                g.probe_bake,
                &cache,
                !s.progress,
            )?)
        }
    };
    let evaluate = |layers: u32| -> Result<GiResult> {
        let settings = RenderSettings {
            probes: probes.clone(),
            ..render_settings(s, layers, rs)
        };
        let mut r = Renderer::new(&gpu, &scene, settings)?;
        // warm-up at the evaluated camera (bounces and temporal history), or along the
        // camera path up to it (--moving)
        let (full, indirect) = if s.moving {
            super::render_along_path(&mut r, &gpu, &scene, s, s.scene.frame)?;
            read_indirect(&r, &gpu)?
        } else {
            render_indirect(&mut r, &gpu, &scene, camera, s.scene.frame, s.warmup.max(1) + 1)?
        };
        // RMSE / MAE on linear radiance, FLIP on the tonemapped images
        let (full_stats, full_map) = compare_radiance(&ref_total.image, &full, exposure)?;
        let (indirect_stats, indirect_map) = compare_radiance(&ref_indirect.image, &indirect, exposure)?;
        let full_stats = ref_total.annotate(full_stats, &display(&full, exposure));
        let indirect_stats = ref_indirect.annotate(indirect_stats, &display(&indirect, exposure));
        let gathered = match g.oracle {
            true => Some(r.read_target(&gpu, "indirect")?),
            false => None,
        };
        let probe_irradiance = match g.oracle && probes.is_some() {
            true => Some(rgb(&r.read_target(&gpu, "probe-irradiance")?)),
            false => None,
        };
        Ok(GiResult {
            layers,
            full,
            indirect,
            errors: GiErrors {
                indirect: indirect_stats,
                full: full_stats,
            },
            full_map,
            indirect_map,
            probe_irradiance,
            gathered,
        })
    };
    let k = s.deep.layers;
    let mut results = s.layer_counts().into_iter().map(evaluate).collect::<Result<Vec<_>>>()?;
    let main = results.pop().expect("k is evaluated");
    let fig10 = match g.fig10 {
        // single-bounce references at a fixed sample count (not converged)
        true => Some(fig10(s, &gpu, &scene, rs, &cache, rule.max_spp.min(FIG10_SPP))?),
        false => None,
    };
    let flicker = match s.frames {
        Some(n) => {
            // temporal stability of the indirect irradiance (red channel) along the path
            let threshold = rs.temporal.map_or(0.01, |t| t.max_distance);
            Some(flicker(
                &gpu,
                &scene,
                &s.scene,
                render_settings(s, k, rs),
                "indirect",
                threshold,
                n,
            )?)
        }
        None => None,
    };
    let (oracle, oracle_figures) = match g.oracle {
        true => oracle_rows(
            s,
            &scene,
            camera,
            (g.bounces, rs.radius.unwrap_or(scene.settings.radiosity_radius)),
            (
                match rs.probe_detail && probes.is_some() {
                    true => Compose::Detail,
                    false => Compose::Blend {
                        one_sided: rs.one_sided_confidence,
                    },
                },
                rs.one_sided_confidence,
                probes.as_ref(),
            ),
            &rule,
            (&converged, &ref_indirect),
            results.iter().chain([&main]),
        )
        .map(|(o, f)| (Some(o), f))?,
        false => (None, Vec::new()),
    };
    let out = GiEval {
        run: s.run_info(
            converged.spp(),
            "path-traced diffuse GI, sky and ambient off (indirect = light reflected at least twice)",
            gpu.describe(),
            flicker,
            noise_warnings(&[("gi indirect", &main.errors.indirect), ("gi full", &main.errors.full)]),
        ),
        samples: rs.samples,
        radius: rs.radius.unwrap_or(scene.settings.radiosity_radius),
        normal_test: rs.normal_test,
        min_mip: rs.min_mip,
        delta: rs.delta,
        boost: rs.boost,
        warmup: s.warmup,
        ref_bounces: g.bounces,
        probes: g.probes,
        probes_from: g.probes_from.clone(),
        probe_grid: g.probes.then_some(g.probe_bake.grid),
        probe_rays: g.probes.then_some(g.probe_bake.rays),
        errors: main.errors,
        layers_1: results.first().map(|o| o.errors),
        fig10,
        by_layers: s.by_layers(results.iter().chain([&main]).map(|r| (r.layers, r.errors))),
        oracle,
    };
    if let Some(dir) = &s.report {
        let refs = (&ref_total.image, &ref_indirect.image);
        write_gi_report(dir, s, &out, (&main, results.first()), &oracle_figures, refs, exposure)?;
    }
    Ok(out)
}

/// `--oracle`: the screen-space oracle converged under `rule` (paths independent of the
/// reference's, cached like it), and per evaluated layer count its blends with the GPU's
/// probe irradiance and its screen space alone against the reference's indirect light.
#[allow(clippy::too_many_arguments)]
fn oracle_rows<'a>(
    s: &EvalSettings,
    scene: &Scene,
    camera: Camera,
    (bounces, radius): (u32, f32),
    (compose, one_sided, field): (Compose, bool, Option<&strata_scene::probes::IrradianceProbes>),
    rule: &strata_reference::ConvergeRule,
    (reference, ref_indirect): (&strata_reference::Converged, &RefImage),
    results: impl Iterator<Item = &'a GiResult>,
) -> Result<(GiOracle, Vec<OracleFigure>)> {
    use std::f32::consts::FRAC_1_PI;
    use strata_reference::oracle::{paper_blend, OracleImages, ScreenOracleSettings};
    let (w, h) = (s.scene.width, s.scene.height);
    let min_separation = s.deep.min_separation.unwrap_or(scene.settings.min_separation);
    let estimator = Estimator::ScreenOracle(ScreenOracleSettings {
        gi: GiSettings {
            bounces,
            russian_roulette: false,
            // a stream of its own: sharing the reference's paths would share its noise
            seed: 0x05ac1e,
            ..Default::default()
        },
        min_separation,
        radius,
    });
    let exposure = s.display_exposure(scene);
    let shown = |img: &ImageBuf| display(img, exposure);
    let k = s.deep.layers as usize;
    let results: Vec<&GiResult> = results.collect();
    let probe_e = results.last().and_then(|r| r.probe_irradiance.clone());
    // the renderer's blend rule, with a perfect gather
    let renderer = |e_hat: Vec3, c: f32, e_probe: Vec3| probe_blend(e_hat, c, e_probe, one_sided);
    // the images the oracle's noise is measured on (k layers, within r): the renderer's
    // rule and the control variate with probes, the seen light and screen space alone
    // without (the alone image's noise grows as 1/c, so it would hold the rule up forever
    // where the layers see little)
    let noisy = |means: &ImageBuf| -> Vec<ImageBuf> {
        let img = OracleImages::from_means(means);
        let v = OracleImages::variant(k, true);
        match (&probe_e, field) {
            (Some(e), Some(f)) => vec![img.blend(v, e, renderer), detail_blend(&img, v, f, camera.eye)],
            (Some(e), None) => vec![img.blend(v, e, renderer)],
            _ => vec![img.seen[v].clone()],
        }
    };
    let shown_blend = |means: &ImageBuf| noisy(means).swap_remove(0);
    // at least 64 paths per half before the first noise measure
    let rule = &strata_reference::ConvergeRule {
        first_spp: rule.first_spp.max(64),
        ..*rule
    };
    // what the convergence measured is part of the entry: an oracle converged on the seen
    // light alone is not converged for the blends with probes, nor the other way round
    let criterion = match (&probe_e, field) {
        (Some(_), Some(_)) => "renderer+detail",
        (Some(_), None) => "renderer",
        _ => "seen",
    };
    let description = format!(
        "v1 screen oracle {} {camera:?} {w}x{h} {estimator:?} {rule:?} criterion={criterion} k={k}",
        scene_fingerprint(scene, s.scene.frame),
    );
    let converged = RefCache::new(&s.cache).converged(s.no_cache, &description, &estimator, || {
        Reference::new(scene, s.scene.frame).with_progress(s.progress).converge(
            &camera,
            w,
            h,
            &estimator,
            rule,
            |a, b| {
                let (a, b) = (noisy(a), noisy(b));
                a.iter()
                    .zip(&b)
                    .map(|(a, b)| half_flip(a, b, shown))
                    .fold(0.0, f64::max)
            },
        )
    });
    let noise = RefImage::of(&converged, shown_blend, shown)?.noise;
    let image = OracleImages::from_means(&converged.image());
    let halves = converged.halves.each_ref().map(OracleImages::from_means);
    let ref_halves = reference.half_images().map(|hf| indirect(&hf));
    // the `detail` rows read the CPU twin of the probe field: how far it is from the GPU's
    let probe_twin_error = match (field, &probe_e) {
        (Some(field), Some(e)) => {
            let (mut d, mut t) = (0.0f64, 0.0f64);
            for i in 0..(w * h) as usize {
                let p = Vec3::from_slice(&image.position.data[3 * i..3 * i + 3]);
                let n = Vec3::from_slice(&image.normal.data[3 * i..3 * i + 3]);
                if n != Vec3::ZERO {
                    let c = field.irradiance(p, n, (camera.eye - p).normalize_or_zero());
                    let g = Vec3::from_slice(&e.data[3 * i..3 * i + 3]);
                    d += (c - g).abs().element_sum() as f64;
                    t += g.element_sum() as f64;
                }
            }
            Some(d / t.max(1e-30))
        }
        _ => None,
    };
    let mut rows = Vec::new();
    let mut figures = Vec::new();
    for r in &results {
        let kl = r.layers as usize;
        let c = &image.confidence[OracleImages::variant(kl, true)];
        figures.push(OracleFigure {
            file: format!("oracle-confidence-k{kl}.png"),
            caption: format!("perfect gather's c, k = {kl} (white = 1)"),
            image: ImageBuf {
                data: c.data.iter().flat_map(|v| [*v; 3]).collect(),
                channels: 3,
                ..c.clone()
            },
            radiance: false,
        });
        let mut entries = Vec::new();
        for within_radius in [false, true] {
            let v = OracleImages::variant(kl, within_radius);
            let mut blends: Vec<(&str, OracleBlend)> = Vec::new();
            if let Some(e) = r.probe_irradiance.clone() {
                let e2 = e.clone();
                blends.push(("paper", Box::new(move |o: &OracleImages| o.blend(v, &e, paper_blend))));
                if one_sided {
                    blends.push(("renderer", Box::new(move |o: &OracleImages| o.blend(v, &e2, renderer))));
                }
            }
            // the probes' own radiance along the directions the layers miss (the control
            // variate of `--set probe-detail=on`): E_probe + E_seen − ∫_seen L_probe cos,
            // with the CPU twin of the GPU's probe field
            if let Some(field) = field {
                let eye = camera.eye;
                blends.push((
                    "detail",
                    Box::new(move |o: &OracleImages| detail_blend(o, v, field, eye)),
                ));
            }
            // which half of the GPU's pair keeps it from the perfect gather: the GPU's
            // gathered term with the oracle's c, and the oracle's term with the GPU's c, both
            // by the rule compose ran; `gpu` recomposes the GPU's own pair
            if let (Some(e), Some(g)) = (&r.probe_irradiance, &r.gathered) {
                // (gathered term, c) of the GPU and E_probe at pixel i
                fn gathered(g: &ImageBuf, i: usize) -> (Vec3, f32) {
                    (Vec3::from_slice(&g.data[4 * i..4 * i + 3]), g.data[4 * i + 3])
                }
                fn probe(e: &ImageBuf, i: usize) -> Vec3 {
                    Vec3::from_slice(&e.data[3 * i..3 * i + 3])
                }
                let (e1, g1) = (e.clone(), g.clone());
                blends.push((
                    "gpu",
                    Box::new(move |o: &OracleImages| {
                        o.per_pixel(v, |_, _, albedo, i| {
                            let (eg, cg) = gathered(&g1, i);
                            albedo * FRAC_1_PI * compose.apply(eg, cg, probe(&e1, i))
                        })
                    }),
                ));
                let (e2, g2) = (e.clone(), g.clone());
                blends.push((
                    "gpu-gather-oracle-c",
                    Box::new(move |o: &OracleImages| {
                        o.per_pixel(v, |_, c, albedo, i| {
                            albedo * FRAC_1_PI * compose.apply(gathered(&g2, i).0, c, probe(&e2, i))
                        })
                    }),
                ));
                let (e3, g3) = (e.clone(), g.clone());
                let eye = camera.eye;
                blends.push((
                    "oracle-gather-gpu-c",
                    Box::new(move |o: &OracleImages| {
                        o.per_pixel(v, |seen, c, albedo, i| {
                            let term = compose.oracle_term(o, v, (seen, c, albedo), field.map(|f| (f, eye)), i);
                            albedo * FRAC_1_PI * compose.apply(term, gathered(&g3, i).1, probe(&e3, i))
                        })
                    }),
                ));
            }
            blends.push(("alone", Box::new(move |o: &OracleImages| o.alone(v))));
            // the probes alone (c = 0), once per row
            if let (false, Some(e)) = (within_radius, r.probe_irradiance.clone()) {
                blends.push((
                    "probes",
                    Box::new(move |o: &OracleImages| o.blend(v, &e, |_, _, ep| ep)),
                ));
            }
            for (name, f) in blends {
                let img = f(&image);
                let (stats, _) = compare_radiance(&ref_indirect.image, &img, exposure)?;
                if within_radius || name == "probes" {
                    figures.push(OracleFigure {
                        file: format!("oracle-{name}-k{kl}.png"),
                        caption: format!("perfect gather, {name}, k = {kl}: FLIP {:.4}", stats.flip),
                        image: img.clone(),
                        radiance: true,
                    });
                }
                entries.push(GiOracleEntry {
                    blend: name.into(),
                    within_radius,
                    errors: ref_indirect.annotate(stats, &display(&img, exposure)),
                    rmse_denoised: denoised_rmse(
                        &ref_indirect.image,
                        &ref_halves,
                        &img,
                        Some(&halves.each_ref().map(&f)),
                    ),
                });
            }
        }
        // the gather's irradiance over the receivers both see (with DGB's blend, where the
        // gathered term is E_dgb)
        let gather = match (compose, &r.gathered) {
            (Compose::Blend { .. }, Some(g)) => {
                let v = OracleImages::variant(kl, true);
                image
                    .gather_agreement(v, g, GATHER_MIN_CONFIDENCE)
                    .map(|a| GiGatherAgreement {
                        confidence: mean_confidence_of(g, &image.albedo),
                        irradiance_ratio: a.irradiance_ratio,
                        min_confidence: GATHER_MIN_CONFIDENCE,
                        pixels: a.pixels,
                    })
            }
            _ => None,
        };
        rows.push(GiOracleRow {
            layers: r.layers,
            confidence: image.mean_confidence(OracleImages::variant(kl, false)),
            confidence_within_radius: image.mean_confidence(OracleImages::variant(kl, true)),
            gpu_rmse_denoised: denoised_rmse(&ref_indirect.image, &ref_halves, &r.indirect, None),
            gather,
            entries,
        });
    }
    let oracle = GiOracle {
        noise,
        radius,
        probe_twin_error,
        by_layers: rows,
    };
    Ok((oracle, figures))
}

/// The control variate of `--set probe-detail=on` with a perfect gather, as indirect
/// radiance: ρ/π·max(E_probe + E_seen − ∫_seen L_probe cos, 0), L_probe the probe field's
/// order-2 SH radiance at the receiver (the CPU twin of the GPU's field) integrated over the
/// seen directions through the oracle's SH moments.
fn detail_blend(
    o: &strata_reference::oracle::OracleImages,
    v: usize,
    field: &strata_scene::probes::IrradianceProbes,
    eye: Vec3,
) -> ImageBuf {
    use std::f32::consts::FRAC_1_PI;
    o.per_pixel(v, |seen, _, albedo, i| match probe_split(o, v, field, eye, i) {
        Some((e_probe, e_probe_seen)) if albedo != Vec3::ZERO => {
            (seen + albedo * FRAC_1_PI * (e_probe - e_probe_seen)).max(Vec3::ZERO)
        }
        _ => Vec3::ZERO,
    })
}

/// The CPU twin's probe irradiance at pixel `i`'s receiver and the part of it that arrives
/// from the directions variant `v` sees, ∫_seen L_probe cos (L_probe the field's order-2 SH
/// radiance, through the oracle's SH moments); `None` where the pixel has no surface.
fn probe_split(
    o: &strata_reference::oracle::OracleImages,
    v: usize,
    field: &strata_scene::probes::IrradianceProbes,
    eye: Vec3,
    i: usize,
) -> Option<(Vec3, Vec3)> {
    let p = Vec3::from_slice(&o.position.data[3 * i..3 * i + 3]);
    let n = Vec3::from_slice(&o.normal.data[3 * i..3 * i + 3]);
    if n == Vec3::ZERO {
        return None;
    }
    let view = (eye - p).normalize_or_zero();
    let l = field.radiance_sh(p, n, view);
    let moments = &o.seen_sh[v].data[9 * i..9 * i + 9];
    let seen: Vec3 = l.iter().zip(moments).map(|(li, m)| *li * *m).sum::<Vec3>() * std::f32::consts::PI;
    Some((field.irradiance(p, n, view), seen))
}

/// The perfect gather's c from which `--oracle` compares the GPU's gathered irradiance with
/// its Ê (below it Ê = E_seen / c is mostly noise).
const GATHER_MIN_CONFIDENCE: f32 = 0.1;

/// The mean of `gathered`'s fourth channel (the GPU's confidence) over the pixels whose
/// `albedo` is not black.
fn mean_confidence_of(gathered: &ImageBuf, albedo: &ImageBuf) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0u32);
    for (g, a) in gathered.data.chunks_exact(4).zip(albedo.data.chunks_exact(3)) {
        if a.iter().any(|v| *v > 0.0) {
            sum += g[3] as f64;
            n += 1;
        }
    }
    sum / n.max(1) as f64
}

/// The rule compose ran on the GPU's gathered pair (its `indirect` target: the gathered term
/// and c) and the probes' irradiance, for the `gpu*` rows of `--oracle`.
#[derive(Clone, Copy, Debug)]
enum Compose {
    /// DGB Fig. 9's c·E_dgb + (1 − c)·E_probe ([`probe_blend`]); the gathered term is E_dgb.
    Blend { one_sided: bool },
    /// `--set probe-detail=on`: max(E_probe + c·detail, 0) ([`probe_detail_blend`]); the
    /// gathered term is detail = Ê[B] − Ê[L_probe].
    Detail,
}

impl Compose {
    fn apply(self, term: Vec3, c: f32, e_probe: Vec3) -> Vec3 {
        match self {
            Compose::Blend { one_sided } => probe_blend(term, c, e_probe, one_sided),
            Compose::Detail => probe_detail_blend(term, c, e_probe),
        }
    }

    /// The perfect gather's counterpart of the GPU's gathered term at pixel `i`, from its
    /// seen radiance, c and albedo: Ê = E_seen / c, or with `Detail` (E_seen − ∫_seen
    /// L_probe cos) / c (the CPU twin of the probe field seen from `eye`).
    fn oracle_term(
        self,
        o: &strata_reference::oracle::OracleImages,
        v: usize,
        (seen, c, albedo): (Vec3, f32, Vec3),
        field: Option<(&strata_scene::probes::IrradianceProbes, Vec3)>,
        i: usize,
    ) -> Vec3 {
        let e_hat = strata_reference::oracle::gathered_irradiance(seen, c, albedo);
        match (self, field) {
            (Compose::Detail, Some((field, eye))) if c > 0.0 => {
                let probe_seen = probe_split(o, v, field, eye, i).map_or(Vec3::ZERO, |(_, s)| s);
                e_hat - probe_seen / c
            }
            (Compose::Detail, _) => Vec3::ZERO,
            (Compose::Blend { .. }, _) => e_hat,
        }
    }
}

/// One of `--oracle`'s images, made from the oracle's means (or one half's).
type OracleBlend<'a> = Box<dyn Fn(&strata_reference::oracle::OracleImages) -> ImageBuf + 'a>;

/// An image of `--oracle` for the report.
struct OracleFigure {
    file: String,
    caption: String,
    image: ImageBuf,
    /// Tonemapped as radiance (else shown as it is).
    radiance: bool,
}

/// RMSE between `test` and `reference` with the Monte Carlo noise of both taken out: the mean
/// squared difference less each image's variance, estimated from its two halves as
/// mean((a − b)²) / 4 (the variance of their mean). 0 when the noise explains it all.
fn denoised_rmse(
    reference: &ImageBuf,
    ref_halves: &[ImageBuf; 2],
    test: &ImageBuf,
    test_halves: Option<&[ImageBuf; 2]>,
) -> f32 {
    let mse = |a: &ImageBuf, b: &ImageBuf| {
        let n = a.data.len().max(1) as f64;
        a.data
            .iter()
            .zip(&b.data)
            .map(|(x, y)| ((x - y) as f64).powi(2))
            .sum::<f64>()
            / n
    };
    let variance = |h: &[ImageBuf; 2]| mse(&h[0], &h[1]) / 4.0;
    let noise = variance(ref_halves) + test_halves.map_or(0.0, variance);
    (mse(reference, test) - noise).max(0.0).sqrt() as f32
}

pub(crate) fn render_settings(s: &EvalSettings, layers: u32, radiosity: &RadiositySettings) -> RenderSettings {
    RenderSettings {
        lighting: LightingSettings {
            // the reference is Lambertian
            specular: false,
            ..s.lighting.clone()
        },
        radiosity: Some(radiosity.clone()),
        // `--guard-band auto`: what `render --technique full` uses
        guard_band: s.guard_band.or_default(strata_render::renderer::AO_GUARD_BAND),
        ..s.render_settings(layers)
    }
}

/// Renders `renders` frames at the fixed `camera` (bounces and temporal history converge) and
/// returns the composed image and its indirect part (composed − direct), RGB.
pub(crate) fn render_indirect(
    r: &mut Renderer,
    gpu: &GpuContext,
    scene: &Scene,
    camera: Camera,
    frame: f32,
    renders: u32,
) -> Result<(ImageBuf, ImageBuf)> {
    let fixed = FrameCameras::fixed(camera);
    for _ in 0..renders {
        r.render(gpu, scene, &fixed, frame)?;
    }
    read_indirect(r, gpu)
}

/// The last rendered frame's composed image and its indirect part (composed − direct), RGB.
fn read_indirect(r: &Renderer, gpu: &GpuContext) -> Result<(ImageBuf, ImageBuf)> {
    let full = rgb(&r.read_target(gpu, "hdr-full")?);
    let direct = rgb(&r.read_target(gpu, "hdr")?);
    let mut indirect = full.clone();
    for (o, d) in indirect.data.iter_mut().zip(&direct.data) {
        *o = (*o - d).max(0.0);
    }
    Ok((full, indirect))
}

/// Channels `first..first + 3` of `img` as an RGB image.
fn channels3(img: &ImageBuf, first: usize) -> ImageBuf {
    let mut out = ImageBuf::new(img.width, img.height, 3);
    for (o, p) in out
        .data
        .chunks_exact_mut(3)
        .zip(img.data.chunks_exact(img.channels as usize))
    {
        o.copy_from_slice(&p[first..first + 3]);
    }
    out
}

/// Direct + indirect of a 6-channel GI estimate (`Estimator::Gi`).
pub(crate) fn total(img: &ImageBuf) -> ImageBuf {
    let mut out = channels3(img, 0);
    for (o, i) in out.data.iter_mut().zip(channels3(img, 3).data) {
        *o += i;
    }
    out
}

/// The indirect part of a 6-channel GI estimate.
pub(crate) fn indirect(img: &ImageBuf) -> ImageBuf {
    channels3(img, 3)
}

pub(crate) fn rgb(img: &ImageBuf) -> ImageBuf {
    let mut out = ImageBuf::new(img.width, img.height, 3);
    for (o, p) in out
        .data
        .chunks_exact_mut(3)
        .zip(img.data.chunks_exact(img.channels as usize))
    {
        o.copy_from_slice(&p[..3]);
    }
    out
}

fn write_gi_report(
    dir: &Path,
    s: &EvalSettings,
    out: &GiEval,
    (main, one): (&GiResult, Option<&GiResult>),
    oracle: &[OracleFigure],
    (ref_total, ref_indirect): (&ImageBuf, &ImageBuf),
    exposure: f32,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("--report {}: {e}", dir.display()))?;
    let k = s.deep.layers;
    let fig = |img: &ImageBuf, name: &str, caption: String| figure(dir, &display(img, exposure), name, caption);
    let map = |img: &ImageBuf, name: &str, caption: String| figure(dir, img, name, caption);
    let st = &main.errors.indirect;
    let mut sections = vec![
        Section::new(format!("Indirect diffuse light, {k} layers, against the path tracer"))
            .text(format!(
                "Tonemapped at exposure {exposure} (the scene's unless `--set exposure`); GPU indirect = composed image − direct. Reference: {} spp (converged to ꟻLIP {:.4} between two independent halves), {} bounces.",
                out.run.ref_spp, out.errors.indirect.ref_noise.map_or(0.0, |n| n.flip), out.ref_bounces
            ))
            .figures(vec![
                fig(&main.indirect, &format!("indirect-k{k}.png"), format!("GPU, k = {k}: FLIP {:.4}", st.flip))?,
                fig(ref_indirect, "reference-indirect.png", "path-traced indirect".into())?,
                map(&main.indirect_map, &format!("flip-indirect-k{k}.png"), format!("FLIP error, k = {k}"))?,
            ]),
        Section::new("Direct + indirect").figures(vec![
            fig(&main.full, &format!("full-k{k}.png"), format!("GPU, k = {k}: FLIP {:.4}", main.errors.full.flip))?,
            fig(ref_total, "reference-full.png", "path-traced".into())?,
            map(&main.full_map, &format!("flip-full-k{k}.png"), format!("FLIP error, k = {k}"))?,
        ]),
    ];
    if let Some(o) = one.filter(|_| k != 1) {
        sections.push(
            Section::new(format!("1 layer vs {k} layers (indirect)"))
                .text("Light from surfaces hidden behind the first layer only reaches the gather through layer 1.")
                .figures(vec![
                    fig(
                        &o.indirect,
                        "indirect-k1.png",
                        format!("GPU, k = 1: FLIP {:.4}", o.errors.indirect.flip),
                    )?,
                    fig(
                        &main.indirect,
                        &format!("indirect-k{k}.png"),
                        format!("GPU, k = {k}: FLIP {:.4}", st.flip),
                    )?,
                    map(&o.indirect_map, "flip-indirect-k1.png", "FLIP error, k = 1".into())?,
                ]),
        );
    }
    if !oracle.is_empty() {
        let figures = oracle
            .iter()
            .map(|f| match f.radiance {
                true => fig(&f.image, &f.file, f.caption.clone()),
                false => map(&f.image, &f.file, f.caption.clone()),
            })
            .collect::<Result<Vec<_>>>()?;
        sections.push(
            Section::new("A perfect gather (`--oracle`)")
                .text(
                    "The path tracer's light from the surfaces the layers hold (within the gather's radius), c the share of paths they hold, and the GPU's probes for the rest: `paper` c·Ê + (1 − c)·E_probe, `renderer` the GPU's blend rule, `alone` Ê, `probes` E_probe.",
                )
                .figures(figures),
        );
    }
    write_report(
        dir,
        format!("strata eval: GI on {}", s.scene.scene),
        &EvalResult::Gi(out.clone()),
        sections,
    )
}

/// DGB Fig. 10's error sources: one GPU bounce (δ = 0) with and without the n̂_Y
/// test, each against single-bounce references with traced visibility and with
/// mutual visibility assumed (indirect radiance; FLIP on tonemapped images).
fn fig10(
    s: &EvalSettings,
    gpu: &GpuContext,
    scene: &Scene,
    rs: &RadiositySettings,
    cache: &RefCache,
    spp: u32,
) -> Result<Fig10> {
    let (w, h) = (s.scene.width, s.scene.height);
    let camera = s.scene.cameras_at(scene, s.scene.frame).current;
    let reference = Reference::new(scene, s.scene.frame).with_progress(s.progress);
    let mut refs = Vec::new();
    for visibility in [true, false] {
        let settings = OneBounceSettings {
            spp,
            visibility,
            ..Default::default()
        };
        let d = format!(
            "v1 one-bounce {} {camera:?} {w}x{h} {settings:?}",
            scene_fingerprint(scene, s.scene.frame)
        );
        refs.push(cache.get_or_compute(s.no_cache, &d, || reference.one_bounce(&camera, w, h, &settings)));
    }
    let exposure = s.display_exposure(scene);
    let row = |normal_test: bool| -> Result<Fig10Row> {
        let settings = RadiositySettings {
            normal_test,
            delta: 0.0,
            ..rs.clone()
        };
        let mut r = Renderer::new(gpu, scene, render_settings(s, s.deep.layers, &settings))?;
        let (_, indirect) = render_indirect(&mut r, gpu, scene, camera, s.scene.frame, s.warmup + 1)?;
        Ok(Fig10Row {
            vs_visibility: compare_radiance(&refs[0], &indirect, exposure)?.0,
            vs_mutual_visibility: compare_radiance(&refs[1], &indirect, exposure)?.0,
        })
    };
    Ok(Fig10 {
        normal_test: row(true)?,
        no_normal_test: row(false)?,
    })
}
