//! DGB §3.2 single-bounce diffuse indirect illumination from the deep G-buffer
//! (Eq. 4–7), gathered with §3.4's spiral taps on the `zmip` chain from every
//! layer's radiosity B (Table 1), for layer 0 and — sharing the taps — layer 1
//! (Fig. 5). Outputs `indirect-raw` / `indirect1-raw`: rgb = irradiance E,
//! a = confidence M/N.
//!
//! Units: B is outgoing radiance (Lambertian direct + emission, as the lighting
//! pass writes it), so Eq. 4's E(X) = 2π/M Σ B(Y) max(ω̂·n̂_X, 0) is irradiance
//! and the reflected radiance of the bounce is ρ_X/π · E(X) · boost(ρ_X)
//! (Eq. 6 with the Lambertian 1/π made explicit).

pub(crate) mod stage;

use crate::passes::builder::{Kernel, PassBuilder, ScreenPass};
use glam::Vec3;
use strata_scene::ImageBuf;

use crate::frame::{FrameUniforms, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::bilateral::BilateralSettings;
use crate::passes::depth_mip::DepthMipSettings;
use crate::passes::temporal::TemporalSettings;
use crate::scene_gpu::GpuScene;
use crate::spiral::{self, SpiralTurns};

/// Radiosity settings. Defaults: Table 2's BALANCED preset (N = 14, 11
/// reconstruction taps, n̂_Y test on, minimum MIP level 2), the scene's radius
/// (the paper gives none; the authors' demo scenes use 7.4 of their units),
/// q = 8 px, boost off (energy-conserving, comparable with the path tracer),
/// temporal α = 0.85, multi-bounce δ = 0.9 (the demo's "propagation damping"
/// 0.1, documented as 1 − δ).
///
/// Three defaults deviate from the paper (issue 14, measured in
/// docs/radiosity.md § "Issue 14" and § "Cosine normalisation"): `temporal_noise`
/// (the spiral's rotation also hashes the frame index, so the temporal filter
/// averages different tap patterns; the paper hashes the pixel only), `solid_angle`
/// (taps weighted by the solid angle they cover instead of Eq. 4's equal weights)
/// and `normalisation` (Eq. 4's 2π/Σw becomes π/max(Σw·cos, ½Σw)); since then
/// `radius_jitter` (κ_i = (i + ξ)/N, docs/radiosity.md § "Jittered tap radii"). The
/// paper's estimator: [`RadiositySettings::paper`].
#[derive(Clone, Debug, PartialEq)]
pub struct RadiositySettings {
    /// Samples N per pixel.
    pub samples: u32,
    /// World-space gather radius r; `None` = the scene's `radiosity_radius`.
    pub radius: Option<f32>,
    /// Eq. 5's second test, ω̂·n̂_Y < 0 (off: the paper's cheaper, biased variant).
    pub normal_test: bool,
    /// Lowest MIP level a tap reads (Table 2's "minimum MIP level").
    pub min_mip: u32,
    pub q: f32,
    pub turns: SpiralTurns,
    pub rotate: bool,
    pub temporal_noise: bool,
    /// Weight each tap by the solid angle its screen area subtends at the receiver
    /// (self-normalised: E = 2π Σ w·B·cos / Σ w) instead of Eq. 4's equal weights.
    pub solid_angle: bool,
    /// Eq. 7's boost(ρ) on the reflected bounce (false: boost = 1).
    pub boost: bool,
    /// §3.3 progressive multi-bounce damping δ in [0, 1]: each frame feeds
    /// δ · ρ/π · E_{t−1} back into B (0 = single bounce).
    pub delta: f32,
    pub mips: DepthMipSettings,
    pub blur: BilateralSettings,
    pub temporal: Option<TemporalSettings>,
    /// Fraction of the guard band (DGB §3.5) in which the gather runs, in
    /// [0, 1]; outside it E = 0 and confidence 0.
    pub guard_band_shaded: f32,
    /// Confidence = M / U, U the taps whose direction lies in the receiver's hemisphere (by
    /// more than cos 0.1; background taps by their camera ray), instead of the paper's M / N:
    /// taps on the receiver's own plane or behind it say nothing about its light, so they no
    /// longer hand the pixel to the light probes (docs/image-quality.md). Not in the paper.
    pub coverage_confidence: bool,
    /// Background taps (no surface in any layer) count as the sky's radiance along their
    /// camera ray, with the solid-angle weight of a surface at infinity, instead of being
    /// skipped (which fills their part of the hemisphere with the other taps' light).
    pub open_sky: bool,
    /// Taps that fail Eq. 5's n̂_Y test count as black occluders (their weight, no light)
    /// instead of being skipped.
    pub hidden_black: bool,
    /// The light probes' visibility test: a probe whose distance map says a surface lies
    /// between it and the receiver barely counts in the probe blend (no light leaking
    /// through walls; `IrradianceProbes::visibility`). Needs probes baked with distance
    /// maps; not in the paper (default true).
    pub probe_visibility: bool,
    /// How AO modulates the probes' irradiance ([`ProbeAo`]; default `MultiBounce`).
    pub probe_ao: ProbeAo,
    /// The gather's normaliser ([`Normalisation`]; default `Bounded`, not in the paper).
    pub normalisation: Normalisation,
    /// With light probes, E = G·E_probe + c·(Ê[B] − Ê[L_probe]) instead of DGB's
    /// c·Ê[B] + (1 − c)·G·E_probe: the gather also evaluates the probes' order-2 SH
    /// radiance along its own taps, and adds only the difference — what the probes miss
    /// in the directions screen space saw (a control variate; docs/radiosity.md §
    /// "Probe detail"). Not in the paper.
    pub probe_detail: bool,
    /// With light probes, the blend's confidence is one-sided: where the gather's
    /// irradiance is darker (in luminance) than the probes', c is scaled by the ratio of
    /// the two ([`probe_blend`]). Screen space misses the light of surfaces it cannot see
    /// (hidden behind the layers, off-screen), which the probes do see; where it sees
    /// more, that is the local detail the coarse probes cannot resolve, and c stands.
    /// Not in the paper (default true; off: DGB's c everywhere).
    pub one_sided_confidence: bool,
    /// A visibility test for the hidden layer's taps (0 = none, as the paper; else the
    /// steps along the segment, at least 2): a layer-1 sender counts as nothing for layer
    /// 0's receiver when a point between them lies within Δz behind a surface of either
    /// layer ([`segment_blocked`]). Layer-1 senders are hidden from the camera, most often
    /// by the very surface that hides them from the receiver: without the test the red
    /// floor behind the warehouse's partition lights the wall in front of it. Layer 1's
    /// receiver (whose E feeds only the next bounce) is not tested. Costs about +60 % of
    /// the gather on lavapipe at 8 steps (docs/radiosity.md § "Visibility of hidden
    /// taps"); [`tap_visibility_all`](Self::tap_visibility_all) extends it to every tap.
    /// Not in the paper (default 0).
    pub tap_visibility: u32,
    /// With [`tap_visibility`](Self::tap_visibility) on, the visible (layer-0) senders are
    /// tested too, by whether their segment pierces the visible surface between two steps
    /// ([`segment_blocked`]'s crossing test), and the hidden ones by both tests (the slab
    /// test on visible senders darkened the surroundings of thin ledges into outliers). Screen space otherwise lights a
    /// receiver with every visible surface in its hemisphere, walls or not: the warehouse's
    /// back wall beside the partition took the lit room behind it (docs/radiosity.md §
    /// "Visible senders too"). 3–4× the gather's cost at 8 steps on lavapipe (+60 %
    /// without). Not in the paper (default true; off: hidden senders only, slab test only,
    /// as before).
    pub tap_visibility_all: bool,
    /// Each tap's radius is drawn within its stratum, κ_i = (i + ξ)/N with ξ per pixel
    /// (and per frame with `temporal_noise`), instead of the paper's fixed (i + ½)/N. With
    /// only the rotation random, tap i of a pixel always reads the same ring of radius
    /// h_i, and the ring averages of bright, sharp-edged senders (the warehouse's red
    /// patch) leave bands and blotches that stay put under the temporal filter
    /// (docs/radiosity.md § "Jittered tap radii"). Not in the paper (default true).
    pub radius_jitter: bool,
    /// The gather, the indirect light's bilateral passes and compose as fullscreen fragment
    /// passes or as compute passes (8×8 pixels per workgroup, storage-texture outputs): the same
    /// shader code and values (docs/radiosity.md § "The gather as a compute pass"). Not in
    /// the paper (default [`Kernel::Auto`]: compute on GPUs, fragment on CPU adapters).
    pub kernel: Kernel,
    /// The gather's resolution divisor s, 1..=[`crate::passes::upsample::MAX_SCALE`]: at s > 1 the
    /// gather shades one pixel of each s×s block (a different one each frame with
    /// `temporal_noise`, all s² in s² frames) and a joint bilateral upsampling (the
    /// indirect blur's plane and normal weights) fills the rest before the temporal
    /// filter (docs/radiosity.md § "Reduced-resolution gather"). Not in the paper (default
    /// 1: every pixel, as DGB).
    pub gather_scale: u32,
}

/// The most steps [`RadiositySettings::tap_visibility`] takes.
pub const MAX_TAP_VISIBILITY: u32 = 32;

/// Where two of [`segment_blocked`]'s steps show different surfaces, its crossing test
/// adds `SEG_SUB − 1` points between them.
pub const SEG_SUB: u32 = 4;

/// Whether the segment from receiver `x` to sender `y` passes through a surface the
/// layers hold, tested at its `steps − 1` inner points, each projected to its pixel
/// (`zmip` level 0):
/// - `slab`: a point lies behind that pixel's layer-0 or layer-1 depth by more than
///   0.1 % + 1 cm and less than `thickness`;
/// - `crossing`: a point lies behind layer 0's depth (by the same margin) while the last
///   point before it (first the receiver `x` itself) lay in front of or on it, and the two
///   pixels show one continuous visible surface: their layer-0 depths differ by no more
///   than the two points' camera-space depths do, plus `thickness`. The segment went
///   through that surface (a thin wall that no point lands inside). Where two steps'
///   pixels show different surfaces (a silhouette between them, e.g. a wall's top seen
///   from above), [`SEG_SUB`] − 1 more points between them join the chain, for the short
///   stretch just behind the wall that the camera does not see. Points off screen or
///   behind the eye break the chain.
///
/// CPU twin of `segment_blocked` in radiosity.wgsl.
#[allow(clippy::too_many_arguments)]
pub fn segment_blocked(
    f: &FrameUniforms,
    zmip: &ImageBuf,
    layers: u32,
    steps: u32,
    thickness: f32,
    (slab, crossing): (bool, bool),
    x: Vec3,
    y: Vec3,
) -> bool {
    let eye = Vec3::from_slice(&f.eye[..3]);
    let forward = Vec3::from_slice(&f.cam_forward[..3]);
    // (both layers' depths at the point's pixel, the point's own depth)
    type SegPoint = ([f32; 2], f32);
    let point = |t: f32| -> Option<SegPoint> {
        let pt = x.lerp(y, t);
        let [px, py] = crate::passes::ao::pixel_of_world(f, pt)?;
        let (qx, qy) = (px.floor() as i64, py.floor() as i64);
        if qx < 0 || qy < 0 || qx >= zmip.width as i64 || qy >= zmip.height as i64 {
            return None;
        }
        let zl = zmip.pixel(qx as u32, qy as u32);
        Some(([zl[0], zl[1]], (pt - eye).dot(forward)))
    };
    let behind = |z: f32, d: f32| z > 0.0 && d > z * 1.001 + 0.01;
    let continuous = |a: SegPoint, b: SegPoint| (b.0[0] - a.0[0]).abs() <= (b.1 - a.1).abs() + thickness;
    // the last point, if it lay in front of (or on) layer 0
    let front_of = |p: Option<SegPoint>| p.filter(|&(zl, d)| zl[0] > 0.0 && !behind(zl[0], d));
    // one link of the chain: whether `cur` lies behind a surface continuous with the last
    // point in front; then `cur` becomes the last point
    let chain = |last: &mut Option<SegPoint>, cur: Option<SegPoint>| {
        let hit = matches!((*last, cur), (Some(a), Some(b)) if behind(b.0[0], b.1) && continuous(a, b));
        *last = front_of(cur);
        hit
    };
    let mut last = front_of(point(0.0));
    let mut prev_t = 0.0;
    for s in 1..steps {
        let t = s as f32 / steps as f32;
        let cur = point(t);
        if let Some((zl, d)) = cur.filter(|_| slab) {
            if zl
                .iter()
                .take(layers.min(2) as usize)
                .any(|&z| behind(z, d) && d < z + thickness)
            {
                return true;
            }
        }
        if crossing {
            if matches!((last, cur), (Some(a), Some(b)) if !continuous(a, b)) {
                for k in 1..SEG_SUB {
                    let tk = prev_t + (t - prev_t) * (k as f32 / SEG_SUB as f32);
                    if chain(&mut last, point(tk)) {
                        return true;
                    }
                }
            }
            if chain(&mut last, cur) {
                return true;
            }
        }
        prev_t = t;
    }
    false
}

/// Rec. 709 luminance weights of [`probe_blend`]'s comparison.
pub const LUMINANCE: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// DGB Fig. 9's blend of the gather's irradiance `e_dgb` (confidence `c`) with the probes'
/// `e_probe` (× AO's factor): c·E_dgb + (1 − c)·E_probe, or with `one_sided`
/// ([`RadiositySettings::one_sided_confidence`]) the same with c' = c·min(1, Y(E_dgb) /
/// Y(E_probe)). CPU twin of compose.wgsl's blend.
pub fn probe_blend(e_dgb: Vec3, c: f32, e_probe: Vec3, one_sided: bool) -> Vec3 {
    let c = c.clamp(0.0, 1.0);
    let c = if one_sided {
        let y = Vec3::from(LUMINANCE);
        c * (e_dgb.dot(y) / e_probe.dot(y).max(1e-6)).min(1.0)
    } else {
        c
    };
    c * e_dgb + (1.0 - c) * e_probe
}

/// The composite of [`RadiositySettings::probe_detail`]: E = max(E_probe + c·detail, 0), with
/// `detail` = Ê[B] − Ê[L_probe] the gather's output (the probes' irradiance `e_probe`
/// already × AO's factor). CPU twin of compose.wgsl's `use_probes == 2`.
pub fn probe_detail_blend(detail: Vec3, c: f32, e_probe: Vec3) -> Vec3 {
    (e_probe + c.clamp(0.0, 1.0) * detail).max(Vec3::ZERO)
}

/// How AO's visibility AV modulates the light probes' irradiance in the composite
/// (DGB Fig. 9: E = c·E_dgb + (1 − c)·AV·E_probe). The discriminants are compose.wgsl's
/// `use_ao` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProbeAo {
    /// AV does not touch the probes.
    Off = 0,
    /// × AV, as the paper: treats the occluders within the AO radius as black.
    Plain = 1,
    /// × G(AV, ρ), the multi-bounce fit of Jimenez et al. 2016 (GTAO §5): occluders
    /// reflect light too, the more the brighter the receiver's albedo ρ, so AV darkens
    /// less than × AV does (G(AV, ρ) ≥ AV, G(1, ρ) = 1; not in the paper).
    MultiBounce = 2,
    /// × G(AV, ρ) / G(V_probe, ρ), at most 1: only the occlusion the probes do not hold
    /// already. V_probe is the blended probes' own openness within the AO radius, from
    /// their distance maps (`IrradianceProbes::openness_sh`): the baked irradiance of a
    /// probe near a wall already lacks the light that wall blocks, so × G alone removes
    /// it twice. Occluders the bake has not seen (a moved object) still darken fully.
    /// Without distance maps V_probe = 1 and this is `MultiBounce`. Not in the paper.
    Relative = 3,
}

/// The factor by which AO darkens the probes' irradiance in channel ρ ([`ProbeAo`]; CPU
/// twin of compose.wgsl's `occlusion`): `av` the receiver's AV, `open` the blended probes'
/// openness V_probe (`IrradianceProbes::openness_at`).
pub fn probe_ao_factor(mode: ProbeAo, av: f32, open: f32, rho: f32) -> f32 {
    match mode {
        ProbeAo::Off => 1.0,
        ProbeAo::Plain => av,
        ProbeAo::MultiBounce => ao_multibounce(av, rho),
        ProbeAo::Relative => (ao_multibounce(av, rho) / ao_multibounce(open, rho).max(1e-3)).min(1.0),
    }
}

/// GTAO's multi-bounce fit G(AV, ρ) per colour channel (CPU twin of `ao_multibounce` in
/// compose.wgsl): max(AV, ((AV·a + b)·AV + c)·AV), a = 2.0404ρ − 0.3324,
/// b = −4.7951ρ + 0.6417, c = 2.7552ρ + 0.6903.
pub fn ao_multibounce(av: f32, rho: f32) -> f32 {
    let a = 2.0404 * rho - 0.3324;
    let b = -4.7951 * rho + 0.6417;
    let c = 2.7552 * rho + 0.6903;
    av.max(((av * a + b) * av + c) * av)
}

/// How the gather turns Σ w·B·cos into irradiance E (docs/radiosity.md § "Cosine
/// normalisation"). Uniform solid-angle samples have mean cos ½, so all three agree for
/// them; screen-space taps are not uniform in direction. The discriminants are the
/// shader's `normalisation` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normalisation {
    /// DGB Eq. 4: E = 2π Σ w·B·cos / Σ w. Where the taps cluster near n̂_X (a floor seeing
    /// the walls above it) it over-estimates E, up to 2×, and the progressive bounces (§3.3)
    /// compound that.
    Hemisphere = 0,
    /// E = π Σ w·B·cos / Σ w·cos: π times the cosine-weighted mean radiance of the taps,
    /// exact for a uniformly radiant surround whatever the taps' directions; where only
    /// grazing taps find a surface it fills the whole hemisphere with their light.
    Cosine = 1,
    /// E = π Σ w·B·cos / max(Σ w·cos, ½ Σ w) = min(Cosine, Hemisphere) per pixel: never
    /// above Eq. 4. Biased low by up to ~11 % in a uniform enclosure with solid-angle
    /// weights (test `cosine_normalisation_…`), which offsets the gather's over-estimate
    /// from assumed mutual visibility; the steadiest of the three against the path tracer.
    Bounded = 2,
}

/// DGB Table 2's parameter sets, read from `presets/*.toml` (embedded).
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Preset {
    pub name: String,
    /// Indirect samples N.
    pub samples: u32,
    /// Reconstruction filter taps per direction (odd: 2·radius + 1).
    pub reconstruction_taps: u32,
    /// Eq. 5's n̂_Y test.
    pub normal_test: bool,
    pub min_mip: u32,
    /// Fraction of the guard band shaded.
    pub guard_band_shaded: f32,
}

/// The preset files, by name.
pub const PRESETS: [(&str, &str); 3] = [
    (
        "high-performance",
        include_str!("../../../../../presets/high-performance.toml"),
    ),
    ("balanced", include_str!("../../../../../presets/balanced.toml")),
    ("high-quality", include_str!("../../../../../presets/high-quality.toml")),
];

impl Preset {
    /// The preset called `name` (high-performance, balanced, high-quality).
    pub fn named(name: &str) -> Result<Self, String> {
        let (_, text) = PRESETS.iter().find(|(n, _)| *n == name).ok_or_else(|| {
            let names: Vec<_> = PRESETS.iter().map(|(n, _)| *n).collect();
            format!("unknown preset '{name}': valid presets are {}", names.join(", "))
        })?;
        Self::parse(text).map_err(|e| format!("presets/{name}.toml: {e}"))
    }

    /// Parses and checks a preset file's text.
    pub fn parse(text: &str) -> Result<Self, String> {
        let p: Preset = toml::from_str(text).map_err(|e| e.to_string())?;
        if p.reconstruction_taps.is_multiple_of(2) {
            return Err(format!(
                "reconstruction_taps {} must be odd (2·radius + 1)",
                p.reconstruction_taps
            ));
        }
        if !(0.0..=1.0).contains(&p.guard_band_shaded) {
            return Err(format!(
                "guard_band_shaded {} is out of range: must be in [0, 1]",
                p.guard_band_shaded
            ));
        }
        Ok(p)
    }

    /// Settings with this preset's values (the rest from `base`).
    pub fn apply(&self, base: RadiositySettings) -> RadiositySettings {
        RadiositySettings {
            samples: self.samples,
            normal_test: self.normal_test,
            min_mip: self.min_mip,
            guard_band_shaded: self.guard_band_shaded,
            blur: BilateralSettings {
                radius: self.reconstruction_taps / 2,
                ..base.blur
            },
            ..base
        }
    }
}

impl Default for RadiositySettings {
    fn default() -> Self {
        Self {
            samples: 14,
            radius: None,
            normal_test: true,
            min_mip: 2,
            q: 8.0,
            turns: SpiralTurns::Optimal,
            rotate: true,
            temporal_noise: true,
            solid_angle: true,
            boost: false,
            delta: 0.9,
            mips: DepthMipSettings::default(),
            blur: BilateralSettings {
                radius: 5,
                step: 1,
                ..Default::default()
            },
            temporal: Some(indirect_temporal()),
            guard_band_shaded: 0.5,
            coverage_confidence: false,
            open_sky: false,
            hidden_black: false,
            probe_visibility: true,
            probe_ao: ProbeAo::Relative,
            normalisation: Normalisation::Bounded,
            probe_detail: false,
            one_sided_confidence: true,
            tap_visibility: 0,
            tap_visibility_all: true,
            radius_jitter: true,
            kernel: Kernel::Auto,
            gather_scale: 1,
        }
    }
}

impl RadiositySettings {
    /// DGB's estimator exactly as published: per-pixel (not per-frame) spiral
    /// rotation, Eq. 4's equal tap weights and normaliser, probes blended without a
    /// visibility test and darkened by × AV with DGB's confidence c, the temporal filter's
    /// α from the first frame (the rest as [`Default`]).
    pub fn paper() -> Self {
        Self {
            temporal_noise: false,
            temporal: Some(TemporalSettings {
                ramp: false,
                ..indirect_temporal()
            }),
            solid_angle: false,
            normalisation: Normalisation::Hemisphere,
            probe_visibility: false,
            probe_ao: ProbeAo::Plain,
            one_sided_confidence: false,
            radius_jitter: false,
            ..Default::default()
        }
    }

    pub fn validate(&self) -> Result<(), String> {
        if self.tap_visibility == 1 || self.tap_visibility > MAX_TAP_VISIBILITY {
            return Err(format!(
                "radiosity tap-visibility {} is out of range: must be 0 (off) or in 2..={MAX_TAP_VISIBILITY}",
                self.tap_visibility
            ));
        }
        if !(1..=crate::passes::ao::MAX_SAMPLES).contains(&self.samples) {
            return Err(format!(
                "radiosity samples {} is out of range: must be in 1..={}",
                self.samples,
                crate::passes::ao::MAX_SAMPLES
            ));
        }
        if let Some(r) = self.radius {
            if !(r > 0.0 && r.is_finite()) {
                return Err(format!("radiosity radius {r} is out of range: must be > 0"));
            }
        }
        if self.min_mip >= self.mips.levels {
            return Err(format!(
                "minimum MIP level {} is out of range: must be below the {} MIP levels",
                self.min_mip, self.mips.levels
            ));
        }
        if !(self.q >= 1.0 && self.q.is_finite()) {
            return Err(format!("MIP radius q {} is out of range: must be >= 1 pixel", self.q));
        }
        if !(0.0..=1.0).contains(&self.guard_band_shaded) {
            return Err(format!(
                "fraction of the guard band shaded {} is out of range: must be in [0, 1]",
                self.guard_band_shaded
            ));
        }
        if !(0.0..=1.0).contains(&self.delta) {
            return Err(format!(
                "propagation damping δ {} is out of range: must be in [0, 1]",
                self.delta
            ));
        }
        if !(1..=crate::passes::upsample::MAX_SCALE).contains(&self.gather_scale) {
            return Err(format!(
                "radiosity gather-scale {} is out of range: must be in 1..={}",
                self.gather_scale,
                crate::passes::upsample::MAX_SCALE
            ));
        }
        self.mips.validate()?;
        self.blur.validate()?;
        if let Some(t) = &self.temporal {
            t.validate()?;
        }
        Ok(())
    }
}

/// The indirect light's temporal filter: DGB §3.3's, without the history clamp that AO
/// uses. The gather's noise is correlated over 4×4-pixel blocks (minimum MIP 2), so a 3×3
/// range is too narrow to hold the converged mean and the clamp undoes the accumulation:
/// `--no-probes` Sponza 0.1204 → 0.1320 ꟻLIP (docs/radiosity.md; `--set
/// indirect-temporal-clamp=on` turns it on).
pub fn indirect_temporal() -> TemporalSettings {
    TemporalSettings {
        clamp_history: false,
        ..Default::default()
    }
}

/// Eq. 7: boost(ρ) = (max_λ ρ − min_λ ρ) / max_λ ρ (0 for black).
pub fn boost(rho: Vec3) -> f32 {
    let max = rho.max_element();
    if max <= 0.0 {
        0.0
    } else {
        (max - rho.min_element()) / max
    }
}

/// Mirrors `Radiosity` in `radiosity.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct RadiosityUniforms {
    pub radius: f32,
    pub proj_scale: f32,
    pub q: f32,
    pub tau: f32,
    pub samples: u32,
    pub min_mip: u32,
    pub max_mip: u32,
    pub normal_test: u32,
    pub seed: u32,
    pub rotate: u32,
    /// 1 = confidence M/U (taps in the receiver's hemisphere), 0 = M/N.
    pub coverage: u32,
    /// 1 = solid-angle tap weights ([`RadiositySettings::solid_angle`]).
    pub solid_angle: u32,
    /// 1 = background taps count as the sky ([`RadiositySettings::open_sky`]).
    pub open_sky: u32,
    /// 1 = back-facing taps count as black ([`RadiositySettings::hidden_black`]).
    pub hidden_black: u32,
    /// [`Normalisation`] as its discriminant: 0 = Eq. 4, 1 = π/Σ w·cos, 2 = π/max(Σ w·cos, ½ Σ w).
    pub normalisation: u32,
    /// 1 = [`RadiositySettings::probe_detail`] (set by the pass when it has probes).
    pub probe_detail: u32,
    /// The probes' grid (set by the pass).
    pub grid: crate::passes::compose::ProbeGridUniform,
    /// [`RadiositySettings::tap_visibility`].
    pub vis_steps: u32,
    /// The deep G-buffer's minimum separation Δz: how far behind a layer's surface counts
    /// as solid.
    pub thickness: f32,
    /// 1 = [`RadiositySettings::radius_jitter`].
    pub radius_jitter: u32,
    /// 1 = [`RadiositySettings::tap_visibility_all`].
    pub vis_all: u32,
}

impl RadiosityUniforms {
    pub fn new(
        s: &RadiositySettings,
        scene: &strata_scene::Scene,
        frame: &FrameUniforms,
        max_mip: u32,
        frame_index: u32,
        min_separation: f32,
    ) -> Self {
        Self {
            radius: s.radius.unwrap_or(scene.settings.radiosity_radius),
            proj_scale: crate::passes::ao::proj_scale(frame),
            q: s.q,
            tau: s.turns.tau(s.samples),
            samples: s.samples,
            min_mip: s.min_mip,
            max_mip,
            normal_test: s.normal_test as u32,
            seed: if s.temporal_noise { frame_index } else { 0 },
            rotate: s.rotate as u32,
            coverage: s.coverage_confidence as u32,
            solid_angle: s.solid_angle as u32,
            open_sky: s.open_sky as u32,
            hidden_black: s.hidden_black as u32,
            normalisation: s.normalisation as u32,
            probe_detail: s.probe_detail as u32,
            grid: bytemuck::Zeroable::zeroed(),
            vis_steps: s.tap_visibility,
            thickness: min_separation,
            radius_jitter: s.radius_jitter as u32,
            vis_all: s.tap_visibility_all as u32,
        }
    }
}

pub const OUTPUTS: [TargetDesc; 2] = [
    TargetDesc::new(
        "indirect-raw",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "DGB Eq. 4 irradiance E of layer 0 (rgb) and confidence M/N (a), before reconstruction",
    ),
    TargetDesc::new(
        "indirect1-raw",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "DGB Eq. 4 irradiance E of layer 1 (rgb) and confidence (a), sharing layer 0's taps",
    ),
];

/// The reduced-resolution gather's outputs (same formats as [`OUTPUTS`]).
pub const LOW_OUTPUTS: [TargetDesc; 2] = [
    TargetDesc::new(
        "indirect-raw-low",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "the gather at 1/s resolution: layer 0's E (rgb) and confidence (a) of one pixel per s×s block",
    ),
    TargetDesc::new(
        "indirect1-raw-low",
        wgpu::TextureFormat::Rgba16Float,
        1,
        "the gather at 1/s resolution: layer 1's E (rgb) and confidence (a) of one pixel per s×s block",
    ),
];

pub struct RadiosityPass {
    pass: ScreenPass,
    /// The probes' grid, when the gather has probes for the detail term.
    grid: Option<crate::passes::compose::ProbeGridUniform>,
    last: std::cell::Cell<RadiosityUniforms>,
}

impl RadiosityPass {
    /// Gathers from the radiosity buffers `b` (layer 0, layer 1) inside the
    /// `scissor` rectangle [x, y, w, h] (`None`: everywhere); `receiver1`: also
    /// for layer 1's surfaces (only multi-bounce propagation reads them); `probes`: for
    /// [`RadiositySettings::probe_detail`]; `compute`: [`RadiositySettings::kernel`] resolved
    /// (the outputs must then allow storage binding); `scale`:
    /// [`RadiositySettings::gather_scale`] (> 1: into [`LOW_OUTPUTS`], `scissor` in
    /// full-resolution pixels).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        layers: u32,
        b: [&'static str; 2],
        scissor: Option<[u32; 4]>,
        receiver1: bool,
        probes: Option<&crate::passes::compose::ProbeGpu>,
        compute: bool,
        scale: u32,
    ) -> Self {
        let scissor = scissor.map(|r| crate::passes::upsample::low_rect(r, scale));
        let outputs = if scale > 1 { LOW_OUTPUTS } else { OUTPUTS };
        let zeroed: RadiosityUniforms = bytemuck::Zeroable::zeroed();
        let dummy;
        let gpu_probes = match probes {
            Some(p) => p,
            None => {
                dummy = crate::passes::compose::ProbeGpu::new(gpu, None, None);
                &dummy
            }
        };
        let builder = PassBuilder::new(gpu, targets, "radiosity")
            .kernel_in(compute, scissor)
            .shader("radiosity", include_str!("radiosity.wgsl"))
            .constant("LAYERS", layers as f64)
            .constant("RECEIVER1", receiver1 as u32 as f64)
            .constant("SCALE", scale as f64)
            .frame(scene)
            .uniforms(&zeroed)
            .read("zmip")
            .read("npack")
            .read(b[0])
            // one layer: layer 0's buffer fills the binding
            .read(if layers > 1 { b[1] } else { b[0] })
            .storage(&gpu_probes.probes)
            .storage(&gpu_probes.depth);
        let pass = ScreenPass::build_in(builder, &outputs.map(|t| t.name), compute, scissor);
        Self {
            pass,
            grid: probes.map(|p| p.grid),
            last: std::cell::Cell::new(zeroed),
        }
    }

    pub fn set_frame(&self, gpu: &GpuContext, mut u: RadiosityUniforms) {
        match self.grid {
            Some(g) => u.grid = g,
            None => u.probe_detail = 0,
        }
        self.pass.set_uniforms(gpu, &u);
        self.last.set(u);
    }

    pub fn uniforms(&self) -> RadiosityUniforms {
        self.last.get()
    }
}

crate::passes::builder::delegate_pass!(RadiosityPass);

/// Mirrors `Propagate` in `propagate.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PropagateUniforms {
    pub delta: f32,
    pub max_distance: f32,
    pub has_history: u32,
    pub boost: u32,
    /// 1 = [`TemporalSettings::object_motion`].
    pub motion: u32,
    pub _pad: [u32; 3],
}

/// The radiosity inputs of this frame's gather (§3.3): `bounce0`/`bounce1` =
/// direct + δ · ρ/π · boost · reprojected E_{t−1} of the same layer.
pub const BOUNCE_OUTPUTS: [TargetDesc; 2] = [
    TargetDesc::new(
        "bounce0",
        crate::passes::deep_gbuffer::RADIOSITY_FORMAT,
        1,
        "layer 0 radiosity B for this frame's gather: direct + δ·ρ/π·E(t−1)",
    ),
    TargetDesc::new(
        "bounce1",
        crate::passes::deep_gbuffer::RADIOSITY_FORMAT,
        1,
        "layer 1 radiosity B for this frame's gather: direct + δ·ρ/π·E(t−1)",
    ),
];

pub struct PropagatePass {
    pass: ScreenPass,
    settings: PropagateUniforms,
}

impl PropagatePass {
    /// `compute`: the compute form ([`Kernel`]), for [`BOUNCE_OUTPUTS`] with storage binding.
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &Targets,
        layers: u32,
        s: &RadiositySettings,
        temporal: &TemporalSettings,
        compute: bool,
    ) -> Self {
        let settings = PropagateUniforms {
            delta: s.delta,
            max_distance: temporal.max_distance,
            has_history: 0,
            boost: s.boost as u32,
            motion: temporal.object_motion as u32,
            _pad: [0; 3],
        };
        // one layer: layer 0's buffers fill layer 1's bindings
        let (direct1, e1) = if layers > 1 {
            ("radiosity1", "indirect1-history")
        } else {
            ("radiosity0", "indirect-history")
        };
        let b = PassBuilder::new(gpu, targets, "propagate")
            .kernel(compute)
            .shader("propagate", include_str!("propagate.wgsl"))
            .constant("LAYERS", layers as f64)
            .frame(scene)
            .uniforms(&settings)
            .read_array("csz")
            .read_array("albedo")
            .read_array("normal")
            .read("radiosity0")
            .read(direct1)
            .read_array("csz-history")
            .read("indirect-history")
            .read(e1)
            .read_array("motion");
        Self {
            pass: ScreenPass::build(b, &BOUNCE_OUTPUTS.map(|t| t.name), compute),
            settings,
        }
    }

    /// Whether last frame's E is in the history targets.
    pub fn set_frame(&self, gpu: &GpuContext, has_history: bool) {
        let u = PropagateUniforms {
            has_history: has_history as u32,
            ..self.settings
        };
        self.pass.set_uniforms(gpu, &u);
    }
}

crate::passes::builder::delegate_pass!(PropagatePass);

/// Read-back inputs of the gather, for [`irradiance_cpu`].
pub struct GatherInputs<'a> {
    /// `zmip` levels (channel j = layer j).
    pub zmip: &'a [ImageBuf],
    /// Decoded world normals of layers 0 and 1 (3 channels each).
    pub normals: [&'a ImageBuf; 2],
    /// Radiosity B of layers 0 and 1 (3 channels each).
    pub radiosity: [&'a ImageBuf; 2],
    pub frame: &'a FrameUniforms,
    pub uniforms: &'a RadiosityUniforms,
    pub layers: u32,
    /// The probes the gather's detail term reads (`uniforms.probe_detail`).
    pub probes: Option<&'a strata_scene::probes::IrradianceProbes>,
}

/// CPU evaluation of exactly what `radiosity.wgsl` computes for receiver layer
/// `receiver` (0 or 1) at pixel (x, y): (E, confidence).
/// The coverage confidence's tangent-plane margin (`COVERAGE_COS` in radiosity.wgsl): a tap
/// counts as in the receiver's hemisphere when cos(ω̂, n̂_X) exceeds it.
pub const COVERAGE_COS: f32 = 0.1;

pub fn irradiance_cpu(g: &GatherInputs, receiver: usize, x: u32, y: u32) -> (Vec3, f32) {
    let u = g.uniforms;
    let zx = g.zmip[0].pixel(x, y);
    if zx[0] <= 0.0 || zx.get(receiver).is_none_or(|&z| z <= 0.0) {
        return (Vec3::ZERO, 0.0);
    }
    let v3 = |img: &ImageBuf, px: u32, py: u32| {
        let p = img.pixel(px, py);
        Vec3::new(p[0], p[1], p[2])
    };
    let world = |px: f32, py: f32, z: f32| crate::passes::ao::world_from_csz(g.frame, [px + 0.5, py + 0.5], z);
    let pos = world(x as f32, y as f32, zx[receiver]);
    let n = v3(g.normals[receiver], x, y);
    let r_p = u.proj_scale * u.radius / zx[0];
    let phi = if u.rotate != 0 {
        spiral::pixel_angle(x, y, u.seed)
    } else {
        0.0
    };
    let xi = if u.radius_jitter != 0 {
        spiral::pixel_jitter(x, y, u.seed)
    } else {
        0.5
    };
    let (w, h) = (g.zmip[0].width as i32, g.zmip[0].height as i32);
    let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let eye = Vec3::from_slice(&g.frame.eye[..3]);
    let (mut sum, mut wsum, mut wcsum, mut m_count, mut u_count) = (Vec3::ZERO, 0.0f32, 0.0f32, 0u32, 0u32);
    // probe_detail (layer 0 only): Σ w·L_probe(ω̂)·cos over the same taps
    let probe_sh = g
        .probes
        .filter(|_| receiver == 0 && u.probe_detail != 0)
        .map(|p| p.radiance_sh(pos, n, (eye - pos).normalize()));
    let mut sum_probe = Vec3::ZERO;
    for i in 0..u.samples {
        let tap = spiral::spiral_tap_at(i, u.samples, u.tau, r_p, phi, xi);
        let d = spiral::tap_texel(tap.offset);
        let (qx, qy) = (x as i32 + d[0], y as i32 + d[1]);
        if qx < 0 || qy < 0 || qx >= w || qy >= h {
            continue;
        }
        let m = spiral::mip_level(tap.radius, u.q, u.max_mip).max(u.min_mip.min(u.max_mip));
        let (tx, ty) = crate::passes::depth_mip::mip_texel(qx as u32, qy as u32, m, w as u32, h as u32);
        let zs = g.zmip[m as usize].pixel(tx, ty);
        let (sx, sy) = crate::passes::depth_mip::source_pixel(tx, ty, m, w as u32, h as u32);
        // (light · cos · w, w, w · cos, carries light, ω̂): a light-carrying term wins over a
        // black occluder (`hidden_black`), which wins over nothing (as `union_term`)
        let mut best: Option<(Vec3, f32, f32, bool, Vec3)> = None;
        for (j, &zj) in zs.iter().enumerate().take(g.layers.min(2) as usize) {
            if zj <= 0.0 {
                continue;
            }
            let yv = world(sx as f32, sy as f32, zj);
            let v = yv - pos;
            let vv = v.dot(v);
            if vv.partial_cmp(&(u.radius * u.radius)) != Some(std::cmp::Ordering::Less) || vv <= 0.0 {
                continue;
            }
            let wdir = v / vv.sqrt();
            let cos_x = wdir.dot(n);
            if cos_x <= 0.0 {
                continue;
            }
            let ny = v3(g.normals[j], sx, sy);
            let wt = if u.solid_angle != 0 {
                solid_angle_weight(eye, yv, ny, wdir, vv, tap.radius, u.radius)
            } else {
                1.0
            };
            if u.normal_test != 0 && wdir.dot(ny) >= 0.0 {
                if u.hidden_black != 0 && best.is_none() {
                    best = Some((Vec3::ZERO, wt, cos_x * wt, false, wdir));
                }
                continue;
            }
            // a sender behind a surface from layer 0's receiver (`tap_visibility`: hidden
            // senders, and with `vis_all` the visible ones too)
            if u.vis_steps > 1
                && (j == 1 || u.vis_all != 0)
                && receiver == 0
                && segment_blocked(
                    g.frame,
                    &g.zmip[0],
                    g.layers,
                    u.vis_steps,
                    u.thickness,
                    (j == 1, u.vis_all != 0),
                    pos,
                    yv,
                )
            {
                continue;
            }
            let c = v3(g.radiosity[j], sx, sy) * cos_x * wt;
            if best.is_none_or(|(b, _, _, light, _)| !light || luminance(c) > luminance(b)) {
                best = Some((c, wt, cos_x * wt, true, wdir));
            }
        }
        // a background tap: the sky along its camera ray, weight h (`sky_term`)
        if u.open_sky != 0 && zs[0] <= 0.0 {
            best = None;
            let dir = (world(sx as f32, sy as f32, 1.0e4) - pos).normalize();
            let cos_x = dir.dot(n);
            if cos_x > 0.0 {
                let wt = if u.solid_angle != 0 { tap.radius } else { 1.0 };
                best = Some((
                    Vec3::from_slice(&g.frame.sky[..3]) * cos_x * wt,
                    wt,
                    cos_x * wt,
                    false,
                    dir,
                ));
            }
        }
        if let Some((b, wt, wc, light, dir)) = best {
            if let Some(l) = &probe_sh {
                sum_probe += strata_scene::probes::sh_radiance(l, dir) * wc;
            }
            sum += b;
            wsum += wt;
            wcsum += wc;
            m_count += light as u32;
        }
        // coverage confidence: the tap's direction (layer 0's point, else its camera ray)
        // lies in the receiver's hemisphere (as `hemisphere_tap` in radiosity.wgsl)
        let y0 = world(sx as f32, sy as f32, if zs[0] > 0.0 { zs[0] } else { 1.0e4 });
        u_count += (best.is_some_and(|b| b.3) || (y0 - pos).normalize().dot(n) > COVERAGE_COS) as u32;
    }
    if wsum <= 0.0 {
        return (Vec3::ZERO, 0.0);
    }
    let confidence = if u.coverage != 0 {
        m_count as f32 / u_count.max(m_count) as f32
    } else {
        m_count as f32 / u.samples as f32
    };
    // Eq. 4: π / (½ Σ w); cosine: π / Σ w·cos; bounded: π / max(Σ w·cos, ½ Σ w)
    let denom = match u.normalisation {
        0 => 0.5 * wsum,
        1 => wcsum,
        _ => wcsum.max(0.5 * wsum),
    };
    // probe_detail: Ê[B] − Ê[L_probe] (same taps, weights, normaliser)
    ((sum - sum_probe) * (std::f32::consts::PI / denom), confidence)
}

/// `radiosity.wgsl`'s `solid_angle_weight`: the solid angle (up to a constant
/// factor, which the self-normalised estimate cancels) that a tap at screen
/// radius `h` covers on the surface at `y` (normal `ny`) seen from the receiver
/// (direction `w`, squared distance `vv`). The spiral spreads taps linearly in
/// radius, so tap i stands for an annulus of screen area ∝ h; a pixel's
/// footprint on Y is ∝ z²/cos_view; that area subtends cos θ_Y/d² per unit
/// area at X. cos_view ≥ 0.25 and d ≥ 0.05 r keep one tap from dominating.
pub fn solid_angle_weight(eye: Vec3, y: Vec3, ny: Vec3, w: Vec3, vv: f32, h: f32, radius: f32) -> f32 {
    let to_eye = eye - y;
    let z2 = to_eye.dot(to_eye);
    let cos_view = ny.dot(to_eye / z2.sqrt()).abs().max(0.25);
    let cos_y = w.dot(ny).abs();
    let dmin = 0.05 * radius;
    h * z2 * cos_y / (cos_view * vv.max(dmin * dmin))
}

/// The gather's scissor for a `w`×`h` target with `guard` pixels of guard band
/// on each side, of which the fraction `shaded` is shaded (Table 2).
pub fn shaded_region(w: u32, h: u32, guard: u32, shaded: f32) -> Option<[u32; 4]> {
    let inset = (guard as f32 * (1.0 - shaded.clamp(0.0, 1.0))).round() as u32;
    (inset > 0).then(|| [inset, inset, w - 2 * inset, h - 2 * inset])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// GTAO's multi-bounce fit: no occlusion stays none (G(1, ρ) = 1), it never darkens
    /// more than × AV, the brighter the albedo the less it darkens, and black occluders
    /// (ρ = 0) leave it close to × AV.
    #[test]
    fn ao_multibounce_lies_between_av_and_one() {
        for rho in [0.0f32, 0.2, 0.5, 0.8, 1.0] {
            assert!((ao_multibounce(1.0, rho) - 1.0).abs() < 1e-3, "G(1, {rho})");
            for k in 0..=20 {
                let av = k as f32 / 20.0;
                let g = ao_multibounce(av, rho);
                assert!(g >= av && g <= 1.0 + 1e-3, "G({av}, {rho}) = {g}");
                assert!(
                    ao_multibounce(av, (rho + 0.1).min(1.0)) >= g - 1e-6,
                    "monotone in ρ at {av}"
                );
            }
        }
        assert!((ao_multibounce(0.5, 0.0) - 0.5).abs() < 0.05);
        assert!(ao_multibounce(0.5, 0.8) > 0.6);
    }

    /// The preset files reproduce DGB Table 2 and change the settings they name.
    #[test]
    fn presets_are_table_2() {
        // (name, N, taps, n̂_Y test, minimum MIP, guard band shaded)
        let table2 = [
            ("high-performance", 13, 9, false, 3, 0.10),
            ("balanced", 14, 11, true, 2, 0.50),
            ("high-quality", 30, 13, true, 0, 0.80),
        ];
        for (name, n, taps, ny, mip, guard) in table2 {
            let p = Preset::named(name).unwrap();
            assert_eq!(p.name, name);
            let base = RadiositySettings {
                samples: 99,
                normal_test: !ny,
                min_mip: 4,
                guard_band_shaded: 0.33,
                ..Default::default()
            };
            let s = p.apply(base);
            assert_eq!(s.samples, n, "{name}");
            assert_eq!(s.blur.taps(), taps, "{name}");
            assert_eq!(s.normal_test, ny, "{name}");
            assert_eq!(s.min_mip, mip, "{name}");
            assert_eq!(s.guard_band_shaded, guard, "{name}");
            s.validate().unwrap();
        }
        assert!(Preset::named("ultra")
            .unwrap_err()
            .contains("high-performance, balanced, high-quality"));
        assert!(Preset::parse("name = 'x'\nsamples = 1\nreconstruction_taps = 4\nnormal_test = true\nmin_mip = 0\nguard_band_shaded = 0.5")
            .unwrap_err()
            .contains("odd"));
        assert!(Preset::parse("samples = 'many'").is_err());
    }

    #[test]
    fn boost_is_eq7() {
        assert_eq!(boost(Vec3::splat(0.5)), 0.0);
        assert!((boost(Vec3::new(0.8, 0.2, 0.4)) - 0.75).abs() < 1e-6);
        assert_eq!(boost(Vec3::ZERO), 0.0);
    }

    #[test]
    fn shaded_region_insets_the_unshaded_guard_band() {
        assert_eq!(shaded_region(100, 80, 10, 1.0), None);
        assert_eq!(shaded_region(100, 80, 10, 0.5), Some([5, 5, 90, 70]));
        assert_eq!(shaded_region(100, 80, 10, 0.0), Some([10, 10, 80, 60]));
        assert_eq!(shaded_region(100, 80, 0, 0.1), None);
    }
}
