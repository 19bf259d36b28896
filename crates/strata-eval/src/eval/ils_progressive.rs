//! ILS §6.3's physically-based mode (`eval --technique ils --progressive K`): frames
//! accumulated with a fresh VPL set each (instant radiosity with B bounces, seed =
//! the frame), VPL visibility from per-VPL shadow maps (SSM, §4.3), until the RMS
//! error of the running mean against the converged image *of the same estimator*
//! (the mean of K independent VPL sets, seeds disjoint from the accumulated ones)
//! is below 1 % — Table 5's "time to < 1 % RMS" for n×m = 1×1 and 2×2. Then the
//! distance of that converged image to the path tracer with B indirect bounces:
//! the bias of the geometry-term clamp and of the VPL singularities, stated.
//!
//! Time to the threshold = the frames' GPU time (the renderer's timestamp total)
//! plus the CPU time that generated their VPLs, reported apart.

use anyhow::{bail, Result};
use strata_reference::gi::GiSettings;
use strata_reference::vpl::VplSettings;
use strata_reference::{Estimator, Reference};
use strata_render::frame::FrameCameras;
use strata_render::passes::ils::{GpuVpl, VplShadows};
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{Camera, ImageBuf, Scene};

use super::gi::{indirect, total};
use super::{half_flip, EvalSettings, RefImage};
use crate::cache::{scene_fingerprint, RefCache};
use crate::metrics::{compare_radiance, display};
use crate::results::{IlsProgressive, IlsProgressivePattern};

/// Relative RMS error at which a running mean counts as converged (Table 5: 1 %).
pub const TARGET_RMS: f64 = 0.01;

/// Seeds of the converged image's VPL sets start here (the accumulated frames use 0, 1, …).
const REFERENCE_SEED: u64 = 1 << 20;

/// Relative RMS difference `‖a − b‖ / ‖b‖` over every channel.
pub fn relative_rms(a: &ImageBuf, b: &ImageBuf) -> f64 {
    let (mut d, mut n) = (0.0f64, 0.0f64);
    for (x, y) in a.data.iter().zip(&b.data) {
        d += ((x - y) as f64).powi(2);
        n += (*y as f64).powi(2);
    }
    (d / n.max(1e-30)).sqrt()
}

fn vpls(reference: &Reference, paths: u32, bounces: u32, seed: u64) -> Vec<GpuVpl> {
    reference
        .vpls(&VplSettings { paths, bounces, seed })
        .iter()
        .map(|v| GpuVpl::new(v.position.into(), v.normal.into(), v.flux.into()))
        .collect()
}

/// A VPL set and the CPU milliseconds that generated it.
struct VplSet {
    vpls: Vec<GpuVpl>,
    ms: f64,
}

fn vpl_set(reference: &Reference, paths: u32, bounces: u32, seed: u64) -> VplSet {
    let start = std::time::Instant::now();
    let vpls = vpls(reference, paths, bounces, seed);
    VplSet {
        vpls,
        ms: start.elapsed().as_secs_f64() * 1e3,
    }
}

/// One frame with `set`: (full image, GPU ms).
fn frame(
    r: &mut Renderer,
    gpu: &GpuContext,
    scene: &Scene,
    camera: Camera,
    set: &VplSet,
    at: f32,
) -> Result<(ImageBuf, f64)> {
    r.set_vpls(gpu, &set.vpls)?;
    let t = r.render(gpu, scene, &FrameCameras::fixed(camera), at)?;
    let full = super::gi::rgb(&r.read_target(gpu, "hdr-full")?);
    gpu.check_errors()?;
    Ok((full, t.total()))
}

fn accumulate(sum: &mut ImageBuf, img: &ImageBuf) {
    for (s, v) in sum.data.iter_mut().zip(&img.data) {
        *s += v;
    }
}

fn scaled(sum: &ImageBuf, k: u32) -> ImageBuf {
    let mut m = sum.clone();
    m.data.iter_mut().for_each(|v| *v /= k as f32);
    m
}

/// `base`: the ILS settings of the evaluation (VPL paths, blur, …); `sets` K, `bounces` B.
pub fn run(
    s: &EvalSettings,
    base: &RenderSettings,
    scene: &Scene,
    camera: Camera,
    gpu: &GpuContext,
    sets: u32,
    bounces: u32,
) -> Result<IlsProgressive> {
    if !(2..=4096).contains(&sets) {
        bail!("--progressive {sets} is out of range: must be in 2..=4096");
    }
    if !(1..=64).contains(&bounces) {
        bail!("--bounces {bounces} is out of range: must be in 1..=64");
    }
    let ils = base.ils.clone().expect("ILS is on");
    let paths = ils.vpl_count;
    let reference = Reference::new(scene, s.scene.frame).with_progress(false);
    let at = s.scene.frame;
    // every VPL set of the run: the converged image's K and the progressive K
    let converged_sets: Vec<VplSet> = (0..sets)
        .map(|k| vpl_set(&reference, paths, bounces, REFERENCE_SEED + k as u64))
        .collect();
    let progressive_sets: Vec<VplSet> = (0..sets)
        .map(|k| vpl_set(&reference, paths, bounces, k as u64))
        .collect();
    let largest = converged_sets
        .iter()
        .chain(&progressive_sets)
        .max_by_key(|v| v.vpls.len())
        .expect("sets ≥ 2");
    // the renderer is built for the largest set (set_vpls takes up to that many)
    let mut initial = largest.vpls.clone();
    if initial.is_empty() {
        bail!(
            "scene '{}': the lights' paths hit no surface, so there are no VPLs",
            scene.name
        );
    }
    // the path tracer with B indirect bounces (cached like `eval gi`)
    let rule = s.check(super::gi::DEFAULT_CAP, 8)?;
    let estimator = Estimator::Gi(GiSettings {
        bounces,
        russian_roulette: false,
        ..Default::default()
    });
    let (w, h) = (s.scene.width, s.scene.height);
    let exposure = scene.settings.exposure;
    let shown = |img: &ImageBuf| display(img, exposure);
    let description = format!(
        "v2 converged gi {} {camera:?} {w}x{h} {estimator:?} {rule:?}",
        scene_fingerprint(scene, s.scene.frame)
    );
    let traced = RefCache::new(&s.cache).converged(s.no_cache, &description, &estimator, || {
        Reference::new(scene, s.scene.frame).with_progress(s.progress).converge(
            &camera,
            w,
            h,
            &estimator,
            &rule,
            |a, b| half_flip(&total(a), &total(b), shown).max(half_flip(&indirect(a), &indirect(b), shown)),
        )
    });
    let ref_total = RefImage::of(&traced, total, shown)?;
    let mut patterns = Vec::new();
    let mut converged_1x1 = None;
    for pattern in [[1u32, 1u32], [2, 2]] {
        let mut rs = base.clone();
        let i = rs.ils.as_mut().expect("ILS is on");
        i.pattern = pattern;
        i.shadows = VplShadows::ShadowMaps;
        i.vpls = std::mem::take(&mut initial).into();
        initial = i.vpls.to_vec();
        rs.validate()?;
        let mut r = Renderer::new(gpu, scene, rs)?;
        // the converged image of this estimator: K independent sets
        let mut sum = ImageBuf::new(s.scene.width, s.scene.height, 3);
        for set in &converged_sets {
            let (img, _) = frame(&mut r, gpu, scene, camera, set, at)?;
            accumulate(&mut sum, &img);
        }
        let converged = scaled(&sum, sets);
        // the progressive run
        let mut acc = ImageBuf::new(s.scene.width, s.scene.height, 3);
        let (mut gpu_ms, mut vpl_ms) = (0.0, 0.0);
        let mut curve = Vec::new();
        let mut pt_curve = Vec::new();
        let mut reached = None;
        for (k, set) in (1..=sets).zip(&progressive_sets) {
            let (img, g) = frame(&mut r, gpu, scene, camera, set, at)?;
            accumulate(&mut acc, &img);
            gpu_ms += g;
            vpl_ms += set.ms;
            let mean = scaled(&acc, k);
            let e = relative_rms(&mean, &converged);
            curve.push((k, e));
            if k.is_power_of_two() {
                pt_curve.push((k, relative_rms(&mean, &ref_total.image)));
            }
            if e < TARGET_RMS && reached.is_none() {
                reached = Some((k, gpu_ms, vpl_ms));
            }
            if reached.is_some() && k >= 8 && !(pattern == [1, 1] && k < sets) {
                break;
            }
        }
        eprintln!(
            "ils §6.3 {}x{}: {}",
            pattern[0],
            pattern[1],
            match reached {
                Some((k, g, v)) => format!("< 1 % RMS after {k} frames, {g:.0} ms GPU + {v:.0} ms VPLs"),
                None => format!(
                    "1 % not reached in {sets} frames (last {:.4})",
                    curve.last().map_or(1.0, |c| c.1)
                ),
            }
        );
        patterns.push(IlsProgressivePattern {
            pattern: format!("{}x{}", pattern[0], pattern[1]),
            frames_to_target: reached.map(|r| r.0),
            gpu_ms_to_target: reached.map(|r| r.1),
            vpl_ms_to_target: reached.map(|r| r.2),
            gpu_ms_per_frame: gpu_ms / curve.len() as f64,
            rms_curve: curve,
            rms_vs_path_tracer: pt_curve,
        });
        if pattern == [1, 1] {
            converged_1x1 = Some(converged);
        }
    }
    let conv = converged_1x1.expect("1x1 ran");
    let (d, _) = compare_radiance(&ref_total.image, &conv, exposure)?;
    Ok(IlsProgressive {
        sets,
        bounces,
        vpl_paths: paths,
        target_rms: TARGET_RMS,
        patterns,
        converged_vs_path_tracer: ref_total.annotate(d, &display(&conv, exposure)),
        ref_spp: traced.spp(),
    })
}
