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
use strata_reference::vpl::VplSettings;
use strata_reference::Reference;
use strata_render::frame::FrameCameras;
use strata_render::passes::ils::{GpuVpl, VplShadows};
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{Camera, ImageBuf, Scene};

use super::gi::total;
use super::{EvalSettings, RefImage};
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

/// Where a run of many thousand frames is: a bar on a terminal; elsewhere (logs, pipes) a
/// line a minute and one when the phase ends. Silent with `--quiet`.
struct Progress {
    bar: indicatif::ProgressBar,
    label: String,
    len: u64,
    show: bool,
    start: std::time::Instant,
    last_line: std::time::Instant,
}

impl Progress {
    const LINE_EVERY: std::time::Duration = std::time::Duration::from_secs(60);

    fn new(show: bool, label: String, len: u64) -> Self {
        use std::io::IsTerminal;
        let bar = if show && std::io::stderr().is_terminal() {
            let bar = indicatif::ProgressBar::new(len);
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{prefix} [{bar:40}] {pos}/{len} {msg} {elapsed_precise} eta {eta}",
            ) {
                bar.set_style(style.progress_chars("=> "));
            }
            bar.set_prefix(label.clone());
            bar
        } else {
            indicatif::ProgressBar::hidden()
        };
        let now = std::time::Instant::now();
        Self {
            bar,
            label,
            len,
            show,
            start: now,
            last_line: now,
        }
    }

    /// `pos` of `len` done; `note` says how far the run has got (e.g. the current RMS).
    fn set(&mut self, pos: u64, note: &str) {
        self.bar.set_position(pos);
        self.bar.set_message(note.to_string());
        if self.show && self.bar.is_hidden() && self.last_line.elapsed() >= Self::LINE_EVERY {
            self.last_line = std::time::Instant::now();
            self.line(pos, note);
        }
    }

    fn line(&self, pos: u64, note: &str) {
        let t = self.start.elapsed().as_secs();
        eprintln!(
            "strata: {}: {pos}/{} {note} ({}m{:02}s)",
            self.label,
            self.len,
            t / 60,
            t % 60
        );
    }

    fn finish(self, pos: u64, note: &str) {
        self.bar.finish_and_clear();
        if self.show && self.bar.is_hidden() && self.start.elapsed() >= Self::LINE_EVERY {
            self.line(pos, note);
        }
    }
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

/// GPU milliseconds of a frame: all passes, and those that depend on the VPL set
/// (the VPL shadow maps and the shading pass). With a fixed view the rest (G-buffer,
/// direct light, BS, DB) is the same every frame, and BG and the blur are linear
/// with weights fixed by the view, so they could run once on the accumulated
/// sub-buffers: §6.3's "the G-buffer creation, the manipulation passes and the
/// filters become free".
struct FrameMs {
    total: f64,
    vpl_dependent: f64,
}

/// One frame with `set`: (full image, GPU ms).
fn frame(
    r: &mut Renderer,
    gpu: &GpuContext,
    scene: &Scene,
    camera: Camera,
    set: &VplSet,
    at: f32,
) -> Result<(ImageBuf, FrameMs)> {
    r.set_vpls(gpu, &set.vpls)?;
    let t = r.render(gpu, scene, &FrameCameras::fixed(camera), at)?;
    let full = super::gi::rgb(&r.read_target(gpu, "hdr-full")?);
    gpu.check_errors()?;
    let vpl_dependent = [
        strata_render::passes::ils::VPL_SHADOW_PASS,
        "ils-ssm",
        "ils-snsm",
        strata_render::passes::ils::BRUTE_FORCE_PASS,
    ]
    .iter()
    .filter_map(|p| t.get(p))
    .sum();
    Ok((
        full,
        FrameMs {
            total: t.total(),
            vpl_dependent,
        },
    ))
}

fn accumulate(sum: &mut ImageBuf, img: &ImageBuf) {
    for (s, v) in sum.data.iter_mut().zip(&img.data) {
        *s += v;
    }
}

/// Σ and Σ² over K independent frames of one estimator, per pixel and channel, in f64
/// (the per-set variance is a small difference of large sums).
pub struct SetMoments {
    k: u32,
    sum: Vec<f64>,
    sum_sq: Vec<f64>,
}

impl SetMoments {
    pub fn new(len: usize) -> Self {
        Self {
            k: 0,
            sum: vec![0.0; len],
            sum_sq: vec![0.0; len],
        }
    }

    pub fn add(&mut self, img: &ImageBuf) {
        self.k += 1;
        for ((s, q), v) in self.sum.iter_mut().zip(&mut self.sum_sq).zip(&img.data) {
            let v = *v as f64;
            *s += v;
            *q += v * v;
        }
    }

    /// σ₁: the relative RMS of ONE set about the estimator's expectation,
    /// √(Σ_px s²) / ‖mean‖ with s² the unbiased sample variance over the K sets.
    /// The running mean of N fresh sets is then σ₁/√N from the expectation, and
    /// σ₁·√(1/N + 1/K) from a converged image of K other sets.
    pub fn per_set_rel_rms(&self) -> f64 {
        let k = self.k as f64;
        assert!(self.k >= 2, "the sample variance needs two sets");
        let (mut var, mut norm) = (0.0f64, 0.0f64);
        for (s, q) in self.sum.iter().zip(&self.sum_sq) {
            let mean = s / k;
            var += ((q - k * mean * mean) / (k - 1.0)).max(0.0);
            norm += mean * mean;
        }
        (var / norm.max(1e-30)).sqrt()
    }
}

/// Frames N until σ₁/√N < `target`: Table 5's criterion against the estimator's
/// expectation (the converged image without the K-set reference's own noise).
pub fn predicted_frames(per_set_rel_rms: f64, target: f64) -> u64 {
    ((per_set_rel_rms / target).powi(2).ceil() as u64).max(1)
}

fn scaled(sum: &ImageBuf, k: u32) -> ImageBuf {
    let mut m = sum.clone();
    m.data.iter_mut().for_each(|v| *v /= k as f32);
    m
}

/// The largest K `--progressive` takes: the atrium's crossing at d_c = 4 % needs about
/// 8,000 sets (2×2), 2σ₁²/10⁻⁴ with σ₁ = 0.58.
pub const MAX_SETS: u32 = 16384;

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
    if !(2..=MAX_SETS).contains(&sets) {
        bail!("--progressive {sets} is out of range: must be in 2..={MAX_SETS}");
    }
    if !(1..=64).contains(&bounces) {
        bail!("--bounces {bounces} is out of range: must be in 1..=64");
    }
    let ils = base.ils.clone().expect("ILS is on");
    let paths = ils.vpl_count;
    let reference = Reference::new(scene, s.scene.frame).with_progress(false);
    let at = s.scene.frame;
    // every VPL set of the run: the converged image's K and the progressive K
    let mut progress = Progress::new(s.progress, "ils §6.3: VPL sets".into(), 2 * sets as u64);
    let mut set_of = |k: u32, seed: u64| {
        progress.set(k as u64, "generated");
        vpl_set(&reference, paths, bounces, seed)
    };
    let converged_sets: Vec<VplSet> = (0..sets).map(|k| set_of(k, REFERENCE_SEED + k as u64)).collect();
    let progressive_sets: Vec<VplSet> = (0..sets).map(|k| set_of(sets + k, k as u64)).collect();
    progress.finish(2 * sets as u64, "generated");
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
    let exposure = s.display_exposure(scene);
    let shown = |img: &ImageBuf| display(img, exposure);
    let traced = super::gi::converged_gi(s, scene, camera, bounces, &rule);
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
        let mut moments = SetMoments::new(sum.data.len());
        let label = |what: &str| format!("ils §6.3 {}x{}: {what}", pattern[0], pattern[1]);
        let mut progress = Progress::new(s.progress, label("converged image"), sets as u64);
        for (k, set) in converged_sets.iter().enumerate() {
            progress.set(k as u64, "sets");
            let (img, _) = frame(&mut r, gpu, scene, camera, set, at)?;
            accumulate(&mut sum, &img);
            moments.add(&img);
        }
        progress.finish(sets as u64, "sets");
        let mut progress = Progress::new(s.progress, label("accumulation"), sets as u64);
        let converged = scaled(&sum, sets);
        // the progressive run
        let mut acc = ImageBuf::new(s.scene.width, s.scene.height, 3);
        let (mut gpu_ms, mut vpl_ms, mut dependent_ms) = (0.0, 0.0, 0.0);
        let mut curve = Vec::new();
        let mut pt_curve = Vec::new();
        let mut reached = None;
        for (k, set) in (1..=sets).zip(&progressive_sets) {
            let (img, g) = frame(&mut r, gpu, scene, camera, set, at)?;
            accumulate(&mut acc, &img);
            moments.add(&img);
            gpu_ms += g.total;
            dependent_ms += g.vpl_dependent;
            vpl_ms += set.ms;
            let mean = scaled(&acc, k);
            let e = relative_rms(&mean, &converged);
            progress.set(k as u64, &format!("frames, relative RMS {e:.4}"));
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
        let last = curve.last().copied().unwrap_or((0, 1.0));
        progress.finish(last.0 as u64, &format!("frames, relative RMS {:.4}", last.1));
        // σ₁ from every set this pattern rendered: the K of the converged image and the
        // accumulated ones (independent seeds; VPL noise is heavy-tailed, so the more sets
        // the steadier the estimate)
        let sigma = moments.per_set_rel_rms();
        let predicted = predicted_frames(sigma, TARGET_RMS);
        let per_frame = gpu_ms / curve.len() as f64;
        let dependent_per_frame = dependent_ms / curve.len() as f64;
        // a static view: one frame's fixed passes, then only the VPL-dependent ones
        let static_view_ms = per_frame - dependent_per_frame + predicted as f64 * dependent_per_frame;
        let vpl_per_frame = vpl_ms / curve.len() as f64;
        eprintln!(
            "ils §6.3 {}x{}: one set {sigma:.4} relative RMS → {predicted} frames to 1 % ≈ {:.1} s GPU; {}",
            pattern[0],
            pattern[1],
            predicted as f64 * per_frame / 1e3,
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
            gpu_ms_per_frame: per_frame,
            per_set_rel_rms: sigma,
            predicted_frames_to_target: predicted,
            predicted_gpu_ms_to_target: predicted as f64 * per_frame,
            predicted_vpl_ms_to_target: predicted as f64 * vpl_per_frame,
            vpl_dependent_ms_per_frame: dependent_per_frame,
            predicted_static_view_gpu_ms_to_target: static_view_ms,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn image(values: &[f32]) -> ImageBuf {
        let mut img = ImageBuf::new(values.len() as u32, 1, 3);
        for (px, v) in img.data.chunks_mut(3).zip(values) {
            px.fill(*v);
        }
        img
    }

    #[test]
    fn per_set_rms_is_the_sample_deviation_over_the_mean() {
        // sets alternate μ ± σ per pixel: sample variance σ²·K/(K − 1), so
        // σ₁ = (σ/μ)·√(K/(K − 1)) exactly
        let (mu, sigma, k) = (2.0f32, 0.5f32, 8u32);
        let mut m = SetMoments::new(4 * 3);
        for i in 0..k {
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            m.add(&image(&[mu + sign * sigma; 4]));
        }
        let expect = (sigma / mu) as f64 * (k as f64 / (k as f64 - 1.0)).sqrt();
        assert!((m.per_set_rel_rms() - expect).abs() < 1e-9, "{}", m.per_set_rel_rms());
        // identical sets have no variance
        let mut still = SetMoments::new(4 * 3);
        (0..3).for_each(|_| still.add(&image(&[1.0, 2.0, 3.0, 4.0])));
        assert_eq!(still.per_set_rel_rms(), 0.0);
    }

    #[test]
    fn per_set_rms_predicts_the_running_mean_error() {
        // Gaussian-ish noise (sum of 12 uniforms − 6) of relative deviation 0.3 on a
        // 256-pixel image: the running mean of N fresh sets is σ₁/√N from the expectation
        let (n_px, mu, rel) = (256usize, 1.5f64, 0.3f64);
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut normal = || {
            let mut s = 0.0;
            for _ in 0..12 {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                s += (state >> 11) as f64 / (1u64 << 53) as f64;
            }
            s - 6.0
        };
        let mut draw = || {
            image(
                &(0..n_px)
                    .map(|_| (mu * (1.0 + rel * normal())) as f32)
                    .collect::<Vec<_>>(),
            )
        };
        let mut m = SetMoments::new(n_px * 3);
        (0..64).for_each(|_| m.add(&draw()));
        let sigma = m.per_set_rel_rms();
        assert!((sigma / rel - 1.0).abs() < 0.1, "σ₁ {sigma} vs {rel}");
        let truth = image(&vec![mu as f32; n_px]);
        for n in [1u32, 4, 16] {
            let mut sum = ImageBuf::new(n_px as u32, 1, 3);
            (0..n).for_each(|_| accumulate(&mut sum, &draw()));
            let e = relative_rms(&scaled(&sum, n), &truth);
            let want = sigma / (n as f64).sqrt();
            assert!((e / want - 1.0).abs() < 0.25, "N {n}: {e} vs {want}");
        }
        assert_eq!(predicted_frames(0.025, 0.01), 7);
        assert_eq!(predicted_frames(0.01, 0.01), 1);
        assert_eq!(predicted_frames(0.0, 0.01), 1);
    }
}
