//! Evaluations: a GPU technique against the CPU ground truth for the same camera and pixel
//! centres ([`ao`]: deep-G-buffer AO against the ray-traced obscurance; [`gi`]: deep-G-buffer
//! radiosity against the path tracer; [`ils`]: interleaved VPL shading against its brute force
//! and the one-bounce path tracer), with temporal flicker along the camera path
//! ([`flicker`]) and an HTML report. What both share is here.

use std::path::PathBuf;

use anyhow::{bail, Result};
use strata_render::passes::deep_gbuffer::DeepGBufferSettings;
use strata_render::passes::lighting::LightingSettings;
use strata_render::passes::shadow::ShadowSettings;
use strata_render::renderer::GuardBand;
use strata_render::{GpuContext, RenderSettings, Renderer};
use strata_scene::{Camera, ImageBuf, Scene};

use strata_reference::{ConvergeRule, Converged};

use crate::metrics::{compare, linear_errors, outliers, ErrorStats, RefNoise, OUTLIER_THRESHOLD};
use crate::report::{sections, Page, ReportImage, Section};
use crate::results::{ByLayers, EvalResult, EvalRun, Flicker};
use crate::scene::SceneSpec;

pub mod aba;
pub mod ao;
pub mod bzb;
pub mod gi;
pub mod ils;
pub mod ils_progressive;
pub mod oit;
pub mod views;

/// What every evaluation takes.
#[derive(Clone, Debug)]
pub struct EvalSettings {
    pub scene: SceneSpec,
    /// Adapter name substring (default: the first real GPU).
    pub adapter: Option<String>,
    /// Deep G-buffer construction; `deep.layers` is the k evaluated.
    pub deep: DeepGBufferSettings,
    pub guard_band: GuardBand,
    /// Cap on the CPU reference's samples per pixel, 2..=65536 (default: the technique's).
    pub ref_spp: Option<u32>,
    /// Noise target of the CPU reference: ꟻLIP between its two independent halves, in
    /// [0, 1) (0: always integrate to the `ref_spp` cap). See `strata_reference::converge`.
    pub ref_noise: f64,
    /// Static frames rendered before the evaluated one (gi), 0..=1000.
    pub warmup: u32,
    /// The warm-up frames follow the camera path up to the evaluated frame (f − warmup … f:
    /// camera and objects moving) instead of holding the evaluated camera still (gi, ao).
    pub moving: bool,
    /// Folder of cached reference images.
    pub cache: PathBuf,
    /// Recompute the reference even when cached.
    pub no_cache: bool,
    /// Also measure flicker over this many frames, 2..=1000.
    pub frames: Option<u32>,
    /// Write an HTML report into this folder (with every k from 1 to `deep.layers`).
    pub report: Option<PathBuf>,
    /// Overwrite an existing report.
    pub force: bool,
    /// Progress bars of the CPU reference on stderr.
    pub progress: bool,
    /// The direct light's settings (`--set area-shadows`, …) of every rendered configuration.
    pub lighting: LightingSettings,
    /// The shadow maps' (`--set shadow-resolution`).
    pub shadow: ShadowSettings,
    /// `--set exposure`: the exposure at which the radiance comparisons display both images
    /// for ꟻLIP (RMSE and MAE compare linear values); `None`: the scene's. The references'
    /// convergence is measured at the scene's exposure either way, so cached references
    /// stay valid.
    pub exposure: Option<f32>,
}

impl EvalSettings {
    /// The exposure the comparisons display both images at for ꟻLIP.
    pub(crate) fn display_exposure(&self, scene: &Scene) -> f32 {
        self.exposure.unwrap_or(scene.settings.exposure)
    }

    /// `--report`: an existing report is overwritten only with `--force`.
    pub(crate) fn check_report(&self) -> Result<()> {
        if let Some(dir) = &self.report {
            if dir.join("index.html").exists() && !self.force {
                bail!(
                    "--report {}: a report exists there; pass --force to overwrite it",
                    dir.display()
                );
            }
        }
        Ok(())
    }

    /// Checks what every technique shares and returns the reference's convergence rule: the
    /// `ref_noise` target, the cap `ref_spp` (`default_cap` unless given), first rounds of
    /// `first_spp` samples per half.
    pub(crate) fn check(&self, default_cap: u32, first_spp: u32) -> Result<ConvergeRule> {
        let spp = self.ref_spp.unwrap_or(default_cap);
        if !(2..=65536).contains(&spp) {
            bail!("--ref-spp {spp} is out of range: must be in 2..=65536");
        }
        if !(0.0..1.0).contains(&self.ref_noise) {
            bail!("--ref-noise {} is out of range: must be in [0, 1)", self.ref_noise);
        }
        if let Some(n) = self.frames {
            if !(2..=1000).contains(&n) {
                bail!("--frames {n} is out of range: must be in 2..=1000");
            }
        }
        self.check_report()?;
        Ok(ConvergeRule {
            target: self.ref_noise,
            first_spp: first_spp.min(spp / 2),
            max_spp: spp,
        })
    }

    /// Render settings of this size and construction with `layers` layers (the technique's
    /// stages still to set).
    pub(crate) fn render_settings(&self, layers: u32) -> RenderSettings {
        RenderSettings {
            width: self.scene.width,
            height: self.scene.height,
            deep: DeepGBufferSettings { layers, ..self.deep },
            guard_band: self.guard_band,
            lighting: self.lighting.clone(),
            shadow: self.shadow.clone(),
            ..Default::default()
        }
    }

    /// What the result says about this run besides its errors.
    pub(crate) fn run_info(
        &self,
        ref_spp: u32,
        reference: &str,
        device: String,
        flicker: Option<Flicker>,
        warnings: Vec<String>,
    ) -> EvalRun {
        EvalRun {
            scene: self.scene.scene.clone(),
            layers: self.deep.layers,
            variant: self.deep.variant.to_string(),
            // as run: one layer is never reduced, except in the 2-layer DGB baseline of
            // bzb-ao, aba-ao and bzb-gi (`eval` refuses the scale where nothing reads it)
            layer_scale: if self.deep.layer_scale > 1 {
                self.deep.layer_scale
            } else {
                1
            },
            width: self.scene.width,
            height: self.scene.height,
            frame: self.scene.frame,
            ref_spp,
            reference: reference.into(),
            device,
            moving: self.moving,
            display_exposure: self.exposure,
            flicker,
            warnings,
        }
    }

    /// With a report, the errors of every evaluated layer count (`(layers, errors)` pairs).
    pub(crate) fn by_layers<E: Copy>(&self, evaluated: impl Iterator<Item = (u32, E)>) -> Vec<ByLayers<E>> {
        match self.report {
            Some(_) => evaluated.map(|(layers, errors)| ByLayers { layers, errors }).collect(),
            None => Vec::new(),
        }
    }

    /// The layer counts to evaluate: k, and with a report every count from 1 to k.
    pub(crate) fn layer_counts(&self) -> Vec<u32> {
        let k = self.deep.layers;
        match self.report {
            Some(_) => (1..=k).collect(),
            None => vec![k],
        }
    }
}

/// A converged reference image with its measured noise and speckles.
pub(crate) struct RefImage {
    /// Values as compared (AV, or linear radiance).
    pub image: ImageBuf,
    pub noise: RefNoise,
    /// [`outliers`] of the reference's display values.
    pub outliers: u32,
}

impl RefImage {
    /// Channels `pick` selects from `c`'s image and halves, with noise measured on `display`
    /// values (ꟻLIP) and the picked values (RMSE).
    pub fn of(
        c: &Converged,
        pick: impl Fn(&ImageBuf) -> ImageBuf,
        display: impl Fn(&ImageBuf) -> ImageBuf,
    ) -> Result<Self> {
        let [a, b] = c.half_images().map(|h| pick(&h));
        let (stats, _) = compare(&display(&a), &display(&b))?;
        let image = pick(&c.image());
        Ok(Self {
            outliers: outliers(&display(&image), OUTLIER_THRESHOLD),
            noise: RefNoise {
                flip: stats.flip,
                rmse: linear_errors(&a, &b).0,
                spp: c.spp(),
                converged: c.converged,
            },
            image,
        })
    }

    /// `stats` (of a test image against this reference) with the reference's noise and the
    /// outliers of both (the test image's on its `display` values).
    pub fn annotate(&self, mut stats: ErrorStats, test_display: &ImageBuf) -> ErrorStats {
        stats.ref_noise = Some(self.noise);
        stats.outliers = Some(outliers(test_display, OUTLIER_THRESHOLD));
        stats.ref_outliers = Some(self.outliers);
        stats
    }
}

/// ꟻLIP between two half images on `display` values: the noise measure the convergence rule
/// drives to its target (1 when they cannot be compared, so the rule keeps integrating).
pub(crate) fn half_flip(a: &ImageBuf, b: &ImageBuf, display: impl Fn(&ImageBuf) -> ImageBuf) -> f64 {
    compare(&display(a), &display(b)).map_or(1.0, |(s, _)| s.flip as f64)
}

/// The warnings an evaluation's reader must see: references stopped by the cap, and errors
/// within 2× of their reference's noise. Also printed on stderr.
pub(crate) fn noise_warnings(errors: &[(&str, &ErrorStats)]) -> Vec<String> {
    let mut out = Vec::new();
    for (name, e) in errors {
        let Some(n) = e.ref_noise else { continue };
        if !n.converged {
            out.push(format!(
                "{name}: the reference stopped at the --ref-spp cap of {} spp with noise ꟻLIP {:.4} above the \
                 --ref-noise target",
                n.spp, n.flip
            ));
        }
        if e.within_ref_noise() {
            out.push(format!(
                "{name}: the error (ꟻLIP {:.4}, RMSE {:.4}) is within 2× of the reference's own noise (ꟻLIP {:.4}, \
                 RMSE {:.4}): converge the reference further (--ref-noise, --ref-spp) to tell them apart",
                e.flip, e.rmse, n.flip, n.rmse
            ));
        }
    }
    out.dedup();
    for w in &out {
        eprintln!("warning: {w}");
    }
    out
}

/// Writes `dir/index.html`: the result's tables and plots, then `images` (sections of figures
/// already saved in `dir`).
pub(crate) fn write_report(
    dir: &std::path::Path,
    title: String,
    result: &EvalResult,
    images: Vec<Section>,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("--report {}: {e}", dir.display()))?;
    let mut page = Page::new(title);
    page.sections = sections::eval_sections(result, dir, "plot-")?;
    page.sections.extend(images);
    page.write(&dir.join("index.html"))?;
    Ok(())
}

/// One radiance evaluation's images: linear radiance of the frame and of its indirect
/// light, and their ꟻLIP maps against the path tracer (`eval --technique bzb-gi`, `ils`).
pub(crate) struct GiImages {
    pub full: ImageBuf,
    pub indirect: ImageBuf,
    pub full_map: ImageBuf,
    pub indirect_map: ImageBuf,
}

/// The image sections of a radiance evaluation's `--report`: the path tracer's indirect
/// light and frame (`ref_spp` samples; `detail` ends the caption), then each
/// configuration's (`rows`: label, errors, images) indirect light and frame beside their
/// ꟻLIP maps, tonemapped with `exposure`.
pub(crate) fn gi_report_sections(
    dir: &std::path::Path,
    s: &EvalSettings,
    ref_spp: u32,
    detail: &str,
    (ref_indirect, ref_total): (&ImageBuf, &ImageBuf),
    exposure: f32,
    rows: &[(&str, &crate::results::GiErrors, &GiImages)],
) -> Result<Vec<Section>> {
    use crate::metrics::display;
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("--report {}: {e}", dir.display()))?;
    let shown = |img: &ImageBuf, name: &str, caption: String| figure(dir, &display(img, exposure), name, caption);
    let map = |img: &ImageBuf, name: &str, caption: String| figure(dir, img, name, caption);
    let header = format!(
        "{}×{} pixels, frame {}, {ref_spp} spp; sky and ambient off. Tonemapped with the scene's exposure ({exposure}); indirect = the composed frame − the direct light. ꟻLIP maps use the magma scale. {detail}",
        s.scene.width, s.scene.height, s.scene.frame
    );
    let mut sections = vec![Section::new("Path tracer, one indirect bounce")
        .text(header)
        .figures(vec![
            shown(ref_indirect, "reference-indirect.png", "indirect light".into())?,
            shown(ref_total, "reference-full.png", "direct + indirect".into())?,
        ])];
    for (label, e, img) in rows {
        let name = ao::slug(label);
        sections.push(Section::new(*label).figures(vec![
            shown(
                &img.indirect,
                &format!("indirect-{name}.png"),
                format!("indirect: ꟻLIP {:.4}, RMSE {:.4}", e.indirect.flip, e.indirect.rmse),
            )?,
            map(
                &img.indirect_map,
                &format!("flip-indirect-{name}.png"),
                "ꟻLIP of the indirect light".into(),
            )?,
            shown(
                &img.full,
                &format!("full-{name}.png"),
                format!("frame: ꟻLIP {:.4}", e.full.flip),
            )?,
            map(
                &img.full_map,
                &format!("flip-full-{name}.png"),
                "ꟻLIP of the frame".into(),
            )?,
        ]));
    }
    Ok(sections)
}

/// Saves `img` as `dir/name` (display values: bytes written as is) and returns its figure.
pub(crate) fn figure(dir: &std::path::Path, img: &ImageBuf, name: &str, caption: String) -> Result<ReportImage> {
    img.save(&dir.join(name), false).map_err(|e| anyhow::anyhow!(e))?;
    Ok(ReportImage {
        caption,
        file: name.into(),
    })
}

/// Last frame's depth and AV at sub-pixel position (px, py): 1/z and AV
/// interpolated bilinearly between the four nearest texel centres (1/z is
/// exact on planes); `None` where any of the four has no surface.
fn reproject(csz: &ImageBuf, av: &ImageBuf, px: f32, py: f32) -> Option<(f32, f32)> {
    let (fx, fy) = (px - 0.5, py - 0.5);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - x0, fy - y0);
    let clampx = |x: f32| (x.max(0.0) as u32).min(csz.width - 1);
    let clampy = |y: f32| (y.max(0.0) as u32).min(csz.height - 1);
    let (mut inv, mut value) = (0.0f32, 0.0f32);
    for (dx, dy, w) in [
        (0.0, 0.0, (1.0 - tx) * (1.0 - ty)),
        (1.0, 0.0, tx * (1.0 - ty)),
        (0.0, 1.0, (1.0 - tx) * ty),
        (1.0, 1.0, tx * ty),
    ] {
        let (x, y) = (clampx(x0 + dx), clampy(y0 + dy));
        let z = csz.pixel(x, y)[0];
        if z <= 0.0 {
            return None;
        }
        inv += w / z;
        value += w * av.pixel(x, y)[0];
    }
    Some((1.0 / inv, value))
}

/// Renders the warm-up frames f − warmup … f − 1 along the camera path (clamped at frame 0;
/// at least one), then frame `f`, whose pass timings it returns: `EvalSettings::moving`.
pub(crate) fn render_along_path(
    r: &mut Renderer,
    gpu: &GpuContext,
    scene: &Scene,
    s: &EvalSettings,
    f: f32,
) -> Result<strata_render::PassTimings> {
    let mut timings = Default::default();
    for k in (0..=s.warmup.max(1)).rev() {
        let fk = (f - k as f32).max(0.0);
        timings = r.render(gpu, scene, &s.scene.cameras_at(scene, fk), fk)?;
    }
    Ok(timings)
}

/// Temporal instability of channel 0 of target `target` rendered with `settings` along the
/// camera path from `spec.frame` over `frames` frames: mean |v_t(p) − v_{t−1}(p′)| over pixels
/// whose surface reprojects (p′ in frame t − 1, interpolated; moved back by its object's
/// `motion` first) onto the same surface within `threshold`, averaged over consecutive frame
/// pairs.
pub fn flicker(
    gpu: &GpuContext,
    scene: &Scene,
    spec: &SceneSpec,
    settings: RenderSettings,
    target: &str,
    threshold: f32,
    frames: u32,
) -> Result<Flicker> {
    let mut r = Renderer::new(gpu, scene, settings)?;
    let (w, h) = (spec.width, spec.height);
    let mut prev: Option<(Camera, ImageBuf, ImageBuf)> = None;
    let (mut sum, mut pairs, mut valid, mut counted) = (0.0f64, 0u32, 0u64, 0u64);
    // one warm-up frame so the first measured pair already has history
    let f0 = spec.frame;
    r.render(gpu, scene, &spec.cameras_at(scene, f0 - 1.0), f0 - 1.0)?;
    let mut per_frame = Vec::new();
    for i in 0..frames {
        let f = f0 + i as f32;
        let cams = spec.cameras_at(scene, f);
        r.render(gpu, scene, &cams, f)?;
        let av = r.read_target(gpu, target)?.channel(0);
        let csz = r.read_target(gpu, "csz")?;
        // without a reprojecting pass the G-buffer writes no motion: pixels pair by the camera alone
        let motion = r.read_target(gpu, "motion").ok();
        if let Some((pcam, pav, pcsz)) = &prev {
            let vp = pcam.view_projection(w as f32 / h as f32);
            let (mut d, mut n) = (0.0f64, 0u64);
            for y in 0..h {
                for x in 0..w {
                    let z = csz.pixel(x, y)[0];
                    if z <= 0.0 {
                        continue;
                    }
                    counted += 1;
                    // where the surface point was at t − 1 (a moving object's too)
                    let m = motion
                        .as_ref()
                        .map_or(glam::Vec3::ZERO, |m| glam::Vec3::from_slice(&m.pixel(x, y)[..3]));
                    let p = cams.current.eye + cams.current.pixel_dir(x, y, w, h) * z - m;
                    let clip = vp * p.extend(1.0);
                    if clip.w <= 0.0 {
                        continue;
                    }
                    let (px, py) = (
                        (clip.x / clip.w * 0.5 + 0.5) * w as f32,
                        (0.5 - 0.5 * clip.y / clip.w) * h as f32,
                    );
                    if !(px >= 0.0 && py >= 0.0 && px < w as f32 && py < h as f32) {
                        continue;
                    }
                    let Some((zq, prev_av)) = reproject(pcsz, pav, px, py) else {
                        continue;
                    };
                    if (zq - clip.w).abs() >= threshold {
                        continue;
                    }
                    d += (av.pixel(x, y)[0] - prev_av).abs() as f64;
                    n += 1;
                }
            }
            if n > 0 {
                sum += d / n as f64;
                pairs += 1;
                per_frame.push([f as f64, d / n as f64]);
            }
            valid += n;
        }
        prev = Some((cams.current, av, csz));
    }
    Ok(Flicker {
        mean: if pairs > 0 { sum / pairs as f64 } else { 0.0 },
        frames,
        valid_fraction: if counted > 0 {
            valid as f64 / counted as f64
        } else {
            0.0
        },
        per_frame,
    })
}
