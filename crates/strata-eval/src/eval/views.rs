//! `strata eval --technique full --views`: the image-quality numbers of issue 14's full-frame
//! part, for `render --technique full` with light probes (DGB Fig. 9):
//!
//! - **clipping**: the fraction of pixels with a channel at 255 in the PNG that `render` writes
//!   for the final image and for the debug views `probe-only`, `blended`, `gbuffer-only`;
//! - **how much screen space changes the picture**: mean |blended − probe-only| of those views'
//!   display bytes, over the image and per region;
//! - **colour bleeding against the path tracer**: in fixed regions of the frame where the
//!   reference shows the banners' colour on neutral surfaces (`REGIONS`, atrium's default
//!   camera), the CIELAB chroma C*ab of the region's mean display colour of three composites —
//!   direct + ρ/π·E with E = the probes only, the blend, the deep G-buffer only — and of the
//!   path-traced frame (sky on, the same exposure and tone curve).
//!
//! Everything compared with the path tracer (ꟻLIP, outliers, chroma, the `final` view) is
//! rendered with the GPU's direct GGX specular lobe off, as `eval gi`, `ils` and `bzb` do: the
//! path tracer is Lambertian. The `final-specular` view is the frame exactly as `render` shows
//! it, for its clipping.
//!
//! Regions are rectangles in normalised image coordinates; a pixel counts when it is a surface
//! whose albedo is near-neutral (chroma (max − min)/max < 0.3: the banners themselves are out).

use anyhow::Result;
use serde::{Deserialize, Serialize};
use strata_reference::gi::GiSettings;
use strata_reference::{Estimator, Reference};
use strata_render::frame::FrameCameras;
use strata_render::{GpuContext, GpuOptions, RenderSettings, Renderer};
use strata_scene::ImageBuf;

use super::gi::{rgb, total};
use super::{half_flip, EvalSettings};
use crate::cache::{scene_fingerprint, RefCache};
use crate::metrics::{compare, display, outliers, OUTLIER_THRESHOLD};
use crate::results::EvalRun;

/// A named rectangle `[x0, y0, x1, y1]` in normalised image coordinates (0..1, y down).
pub type Rect = (&'static str, [f32; 4]);

/// The regions of atrium's default camera (frame 0) where the light-probe composite's hue is
/// furthest from the path-traced frame's (per-pixel (a*, b*) distance, 5×5 box, measured at
/// 320×180): the upper gallery's columns and arch soffits around the banners, lit by them and by
/// each other at a scale the 8×4×8 probe grid cannot resolve — where screen-space light should
/// win. The gallery floor is hidden by its parapet from this camera. Other scenes or cameras:
/// the same rectangles, not meaningful.
pub const REGIONS: [Rect; 3] = [
    // the columns between the blue and the green banner
    ("columns-blue-green", [0.60, 0.0, 0.72, 0.36]),
    // the arch soffits and columns beside the yellow and blue banners
    ("soffits-yellow-blue", [0.47, 0.10, 0.60, 0.36]),
    // the columns and wall between the green and the red banner
    ("columns-green-red", [0.72, 0.0, 0.84, 0.30]),
];

/// Display-byte statistics of one view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewClip {
    pub view: String,
    /// Fraction of all pixels with a channel at byte 255.
    pub clip_fraction: f64,
    /// Mean display value (bytes, 0..255) over all pixels and channels.
    pub mean: f64,
    /// Pixels more than 0.25 from their 3×3 median in a channel of the sRGB display values
    /// (`metrics::outliers`, as `eval` counts them).
    pub outliers: u32,
}

/// One region's numbers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RegionChroma {
    pub name: String,
    pub rect: [f32; 4],
    /// Pixels counted (surfaces with near-neutral albedo).
    pub pixels: u32,
    /// C*ab of the region's mean display colour: path tracer, and the composites with E from
    /// the probes only, the blend (the final image), the deep G-buffer only.
    pub chroma_reference: f64,
    pub chroma_probe_only: f64,
    pub chroma_blended: f64,
    pub chroma_gbuffer_only: f64,
    /// CIELAB (a*, b*) of the region's mean display colour, same order: the hue the banners
    /// push the neutral surfaces to.
    pub ab_reference: [f64; 2],
    pub ab_probe_only: [f64; 2],
    pub ab_blended: [f64; 2],
    pub ab_gbuffer_only: [f64; 2],
    /// Distance in the (a*, b*) plane to the reference's: how far each composite's colour is.
    pub ab_error_probe_only: f64,
    pub ab_error_blended: f64,
    pub ab_error_gbuffer_only: f64,
    /// Mean |blended − probe-only| of the debug views' display bytes in the region.
    pub blended_vs_probe_only: f64,
    /// Mean confidence c = M/N in the region.
    pub confidence: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewsEval {
    #[serde(flatten)]
    pub run: EvalRun,
    pub exposure: f32,
    pub views: Vec<ViewClip>,
    /// Outliers of the path-traced frame's display values (compare with the final image's).
    pub reference_outliers: u32,
    /// Mean |blended − probe-only| of the debug views' display bytes, whole image.
    pub blended_vs_probe_only: f64,
    pub mean_confidence: f64,
    /// ꟻLIP of the whole frame against the path-traced one: the final image (blend), and the
    /// composites with the probes only and the deep G-buffer only.
    pub flip_blended: f32,
    pub flip_probe_only: f32,
    pub flip_gbuffer_only: f32,
    pub regions: Vec<RegionChroma>,
    /// The scene the probes were baked from when not the evaluated one (`--probes-from`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probes_from: Option<String>,
}

/// sRGB display value (0..1) → CIELAB (a*, b*), D65.
fn lab_ab(srgb: [f64; 3]) -> [f64; 2] {
    let lin = srgb.map(|c| {
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    });
    let x = 0.4124 * lin[0] + 0.3576 * lin[1] + 0.1805 * lin[2];
    let y = 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2];
    let z = 0.0193 * lin[0] + 0.1192 * lin[1] + 0.9505 * lin[2];
    let f = |t: f64| {
        if t > 216.0 / 24389.0 {
            t.cbrt()
        } else {
            (24389.0 / 27.0 * t + 16.0) / 116.0
        }
    };
    let (fx, fy, fz) = (f(x / 0.95047), f(y), f(z / 1.08883));
    [500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// The byte a PNG writer stores for display value `v` (sRGB-encoded).
fn byte(v: f32) -> f64 {
    (strata_scene::image_buf::linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0 + 0.5).floor() as f64
}

fn clip_of(view: &str, img: &ImageBuf) -> ViewClip {
    let c = img.channels as usize;
    let n = (img.width * img.height) as usize;
    let (mut clipped, mut sum) = (0usize, 0.0f64);
    for p in img.data.chunks_exact(c) {
        let b: Vec<f64> = p[..3].iter().map(|&v| byte(v)).collect();
        clipped += b.iter().any(|&v| v >= 255.0) as usize;
        sum += b.iter().sum::<f64>() / 3.0;
    }
    let mut shown = ImageBuf::new(img.width, img.height, 3);
    for (o, p) in shown.data.chunks_exact_mut(3).zip(img.data.chunks_exact(c)) {
        for k in 0..3 {
            o[k] = strata_scene::image_buf::linear_to_srgb(p[k].clamp(0.0, 1.0));
        }
    }
    ViewClip {
        view: view.into(),
        clip_fraction: clipped as f64 / n as f64,
        mean: sum / n as f64,
        outliers: outliers(&shown, OUTLIER_THRESHOLD),
    }
}

/// Runs `settings` (the technique's, probes included) at the evaluated camera.
pub fn run(s: &EvalSettings, settings: RenderSettings) -> Result<ViewsEval> {
    let rule = s.check(super::gi::DEFAULT_CAP, 8)?;
    let (scene, cams) = s.scene.load()?;
    let (w, h) = (s.scene.width, s.scene.height);
    let camera = cams.current;
    let exposure = settings.exposure.unwrap_or(scene.settings.exposure);
    let gpu = GpuContext::new(&GpuOptions {
        adapter: s.adapter.clone(),
    })?;
    let fixed = FrameCameras::fixed(camera);
    let warm = |settings: RenderSettings| -> Result<Renderer> {
        let mut r = Renderer::new(&gpu, &scene, settings)?;
        for _ in 0..s.warmup.max(1) + 1 {
            r.render(&gpu, &scene, &fixed, s.scene.frame)?;
        }
        Ok(r)
    };
    // The frame exactly as `render` shows it (GGX specular lobe on): its clipping only. The
    // path tracer is Lambertian, so everything compared with it below comes from the same
    // settings with the GPU's direct specular lobe off (as `eval gi`, `ils` and `bzb` do).
    let shown_final = {
        let r = warm(settings.clone())?;
        clip_of("final-specular", &r.read_target(&gpu, "ldr")?)
    };
    let r = warm(RenderSettings {
        lighting: strata_render::passes::lighting::LightingSettings {
            specular: false,
            ..settings.lighting.clone()
        },
        ..settings
    })?;
    // the final image and the three views (display values, linear)
    let final_img = r.read_target(&gpu, "ldr")?;
    let names = ["probe-only", "blended", "gbuffer-only"];
    let views: Vec<ImageBuf> = names
        .iter()
        .map(|v| r.debug_view(&gpu, v, false))
        .collect::<Result<_, _>>()?;
    let mut clips = vec![clip_of("final", &final_img)];
    clips.extend(names.iter().zip(&views).map(|(n, v)| clip_of(n, v)));
    clips.push(shown_final);

    // composites direct + ρ/π·E for each E, as sRGB display values (the frame's tone curve)
    let direct = rgb(&r.read_target(&gpu, "hdr")?);
    let raw: Vec<ImageBuf> = ["probe-irradiance", "indirect-blended", "indirect"]
        .iter()
        .map(|t| r.read_target(&gpu, t).map(|i| rgb(&i)))
        .collect::<Result<_, _>>()?;
    let albedo = r.read_target_layer(&gpu, "albedo", 0)?;
    let normal = r.read_target_layer(&gpu, "normal", 0)?;
    let csz = r.read_target(&gpu, "csz")?;
    let conf = r.read_target(&gpu, "indirect-blended")?.channel(3);
    let boost = r.settings.radiosity.as_ref().is_some_and(|x| x.boost);
    let n = (w * h) as usize;
    let (ca, cn, cz) = (
        albedo.channels as usize,
        normal.channels as usize,
        csz.channels as usize,
    );
    let rho: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            let m = 1.0 - normal.data[i * cn + 3];
            let a = glam::Vec3::from_slice(&albedo.data[i * ca..i * ca + 3]) * m;
            let k = if boost {
                strata_render::passes::radiosity::boost(a)
            } else {
                1.0
            };
            (a * k / std::f32::consts::PI).to_array()
        })
        .collect();
    let composites: Vec<ImageBuf> = raw
        .iter()
        .map(|e| {
            let mut o = direct.clone();
            let pixels = o.data.chunks_exact_mut(3).zip(e.data.chunks_exact(3)).zip(&rho);
            for (i, ((o, e), rho)) in pixels.enumerate() {
                if csz.data[i * cz] > 0.0 {
                    for ((o, e), r) in o.iter_mut().zip(e).zip(rho) {
                        *o += r * e;
                    }
                }
            }
            display(&o, exposure)
        })
        .collect();

    // the path-traced frame: sky on, the scene as rendered (converged, cached)
    let estimator = Estimator::Gi(GiSettings {
        bounces: 4,
        russian_roulette: false,
        ..Default::default()
    });
    let cache = RefCache::new(&s.cache);
    let reference = Reference::new(&scene, s.scene.frame).with_progress(s.progress);
    let description = format!(
        "v1 converged views gi {} {camera:?} {w}x{h} {estimator:?} {rule:?}",
        scene_fingerprint(&scene, s.scene.frame)
    );
    let shown = |img: &ImageBuf| display(img, exposure);
    let converged = cache.converged(s.no_cache, &description, &estimator, || {
        reference.converge(&camera, w, h, &estimator, &rule, |a, b| {
            half_flip(&total(a), &total(b), shown)
        })
    });
    let ref_display = display(&total(&converged.image()), exposure);

    let flips = [0, 1, 2].map(|i| compare(&ref_display, &composites[i]).map_or(f32::NAN, |(st, _)| st.flip));
    let mean_abs = |a: &ImageBuf, b: &ImageBuf, pix: &mut dyn Iterator<Item = usize>| -> f64 {
        let (mut s, mut k) = (0.0, 0usize);
        for i in pix {
            for c in 0..3 {
                s += (byte(a.data[i * 3 + c]) - byte(b.data[i * 3 + c])).abs();
            }
            k += 1;
        }
        s / (3 * k.max(1)) as f64
    };
    let blended_vs_probe_only = mean_abs(&views[1], &views[0], &mut (0..n));
    let mean_conf = conf.data.iter().map(|&c| c as f64).sum::<f64>() / n as f64;
    let mut regions = Vec::new();
    for (name, rect) in REGIONS {
        let (x0, x1) = ((rect[0] * w as f32) as u32, (rect[2] * w as f32) as u32);
        let (y0, y1) = ((rect[1] * h as f32) as u32, (rect[3] * h as f32) as u32);
        let pix: Vec<usize> = (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (y * w + x) as usize))
            .filter(|&i| {
                let a = &albedo.data[i * ca..i * ca + 3];
                let mx = a[0].max(a[1]).max(a[2]);
                let mn = a[0].min(a[1]).min(a[2]);
                csz.data[i * cz] > 0.0 && mx > 0.0 && (mx - mn) / mx < 0.3
            })
            .collect();
        let mean_ab = |img: &ImageBuf| -> [f64; 2] {
            let c = img.channels as usize;
            let mut m = [0.0f64; 3];
            for &i in &pix {
                for (m, v) in m.iter_mut().zip(&img.data[i * c..i * c + 3]) {
                    *m += *v as f64;
                }
            }
            lab_ab(m.map(|v| v / pix.len().max(1) as f64))
        };
        let ab = [&ref_display, &composites[0], &composites[1], &composites[2]].map(mean_ab);
        let chroma = |x: [f64; 2]| x[0].hypot(x[1]);
        let err = |x: [f64; 2]| (x[0] - ab[0][0]).hypot(x[1] - ab[0][1]);
        regions.push(RegionChroma {
            name: name.into(),
            rect,
            pixels: pix.len() as u32,
            chroma_reference: chroma(ab[0]),
            chroma_probe_only: chroma(ab[1]),
            chroma_blended: chroma(ab[2]),
            chroma_gbuffer_only: chroma(ab[3]),
            ab_reference: ab[0],
            ab_probe_only: ab[1],
            ab_blended: ab[2],
            ab_gbuffer_only: ab[3],
            ab_error_probe_only: err(ab[1]),
            ab_error_blended: err(ab[2]),
            ab_error_gbuffer_only: err(ab[3]),
            blended_vs_probe_only: mean_abs(&views[1], &views[0], &mut pix.iter().copied()),
            confidence: pix.iter().map(|&i| conf.data[i] as f64).sum::<f64>() / pix.len().max(1) as f64,
        });
    }
    if let Some(dir) = &s.report {
        std::fs::create_dir_all(dir)?;
        // linear display values are sRGB-encoded on writing; `display` values already are
        let save =
            |img: &ImageBuf, name: &str, srgb: bool| img.save(&dir.join(name), srgb).map_err(|e| anyhow::anyhow!(e));
        save(&final_img, "final.png", true)?;
        for (n, v) in names.iter().zip(&views) {
            save(v, &format!("{n}.png"), true)?;
        }
        save(&composites[0], "composite-probe-only.png", false)?;
        save(&composites[1], "composite-blended.png", false)?;
        save(&composites[2], "composite-gbuffer-only.png", false)?;
        save(&ref_display, "reference.png", false)?;
    }
    Ok(ViewsEval {
        run: s.run_info(
            converged.spp(),
            "path-traced frame (sky on, 4 bounces), the views and composites as `render` shows them",
            gpu.describe(),
            None,
            Vec::new(),
        ),
        exposure,
        views: clips,
        reference_outliers: outliers(&ref_display, OUTLIER_THRESHOLD),
        blended_vs_probe_only,
        mean_confidence: mean_conf,
        flip_blended: flips[1],
        flip_probe_only: flips[0],
        flip_gbuffer_only: flips[2],
        regions,
        probes_from: None,
    })
}
