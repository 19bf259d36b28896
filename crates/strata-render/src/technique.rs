//! The technique registry: every shading technique strata renders, by name, with
//! what it outputs, how `eval` compares it and which presets it has. Tools that
//! must cover every technique (the validation matrix test, `strata techniques`)
//! iterate [`registry`]; a new technique adds one entry here and its own module.

use crate::passes::abuffer::ao::AbaAoSettings;
use crate::passes::abuffer::{ABufferMethod, ABufferSettings};
use crate::passes::bzb::{BzbSettings, Hemisphere};
use crate::passes::interleave::SplitMethod;
use crate::passes::{ao::AoSettings, ils::IlsSettings, ils::VplShadows, radiosity, reflections::ReflectionSettings};
use crate::{RenderError, RenderSettings};

/// How `eval` compares a technique's output with the CPU reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EvalKind {
    /// Not compared (no ground-truth counterpart).
    None,
    /// Ambient visibility in [0, 1] against ray-traced AO.
    AmbientVisibility,
    /// Radiance against the path tracer.
    Radiance,
    /// VPL radiance (ILS): against the brute force of the same VPLs and the one-bounce path tracer.
    VplRadiance,
    /// Composited radiance (OIT): against the CPU compositing of every surface crossing.
    Composite,
}

impl EvalKind {
    pub fn name(self) -> &'static str {
        match self {
            EvalKind::None => "none",
            EvalKind::AmbientVisibility => "ambient-visibility",
            EvalKind::Radiance => "radiance",
            EvalKind::VplRadiance => "vpl-radiance",
            EvalKind::Composite => "composite",
        }
    }
}

/// The valid values of a numeric setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Range {
    /// a..=b
    Closed(f64, f64),
    /// [a, b)
    HalfOpen(f64, f64),
    /// ≥ a
    AtLeast(f64),
    /// > a
    Above(f64),
    /// 0 (off) or a..=b, a > 0
    OffOr(f64, f64),
}

impl Range {
    pub fn contains(self, v: f64) -> bool {
        match self {
            Range::Closed(a, b) => (a..=b).contains(&v),
            Range::HalfOpen(a, b) => (a..b).contains(&v),
            Range::AtLeast(a) => v >= a && v.is_finite(),
            Range::Above(a) => v > a && v.is_finite(),
            Range::OffOr(a, b) => v == 0.0 || (a..=b).contains(&v),
        }
    }

    /// The range's extreme values a user can type, in `step`s (1 for an integer setting,
    /// 10⁻³ otherwise): both ends of a closed range, the last step before an open end,
    /// the first step above an exclusive lower end, and 0 plus both ends of "0 or a..=b".
    /// An unbounded range gives its lower end only.
    pub fn ends(self, integer: bool) -> Vec<f64> {
        let step = if integer { 1.0 } else { 1e-3 };
        match self {
            Range::Closed(a, b) => vec![a, b],
            Range::HalfOpen(a, b) => vec![a, b - step],
            Range::AtLeast(a) => vec![a],
            Range::Above(a) => vec![a + step],
            Range::OffOr(a, b) => vec![0.0, a, b],
        }
    }
}

impl std::fmt::Display for Range {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Range::Closed(a, b) => write!(f, "{a}..={b}"),
            Range::HalfOpen(a, b) => write!(f, "[{a}, {b})"),
            Range::AtLeast(a) => write!(f, ">= {a}"),
            Range::Above(a) => write!(f, "> {a}"),
            Range::OffOr(a, b) => write!(f, "0 or {a}..={b}"),
        }
    }
}

/// One numeric setting of a technique, as `strata techniques` lists it and a
/// viewer edits it. `name` is the CLI flag without `--`; `get` returns `None`
/// where the value comes from the scene (e.g. the AO radius). The declared
/// range is the one `RenderSettings::validate` enforces (a test checks both ends).
pub struct SettingInfo {
    pub name: &'static str,
    pub doc: &'static str,
    pub range: Range,
    /// Whole numbers only.
    pub integer: bool,
    pub get: fn(&RenderSettings) -> Option<f64>,
    pub set: fn(&mut RenderSettings, f64),
    /// Names of the values 0, 1, … where the setting is a choice (`--set shadows=vpl`); empty otherwise.
    pub values: &'static [&'static str],
}

impl SettingInfo {
    /// The value `text` names: a number, or one of [`SettingInfo::values`].
    pub fn parse_value(&self, text: &str) -> Option<f64> {
        let t = text.trim();
        t.parse()
            .ok()
            .or_else(|| self.values.iter().position(|v| *v == t).map(|i| i as f64))
    }
}

/// `NAME=TEXT` of a setting whose values have names: the number `TEXT` stands for in any
/// registered technique (`None`: no setting `name` names `text`).
pub fn named_value(name: &str, text: &str) -> Option<f64> {
    registry()
        .iter()
        .flat_map(|t| t.setting_list())
        .filter(|i| i.name == name && !i.values.is_empty())
        .find_map(|i| i.parse_value(text))
}

/// The named values of setting `name` over every technique (e.g. `split`:
/// naive, blocks, compute), deduplicated, in registry order; empty when it has none.
pub fn named_values(name: &str) -> Vec<&'static str> {
    let mut out: Vec<&'static str> = Vec::new();
    for v in registry()
        .iter()
        .flat_map(|t| t.setting_list())
        .filter(|i| i.name == name)
        .flat_map(|i| i.values.iter().copied())
    {
        if !out.contains(&v) {
            out.push(v);
        }
    }
    out
}

macro_rules! setting {
    ($name:literal, $doc:literal, $range:expr, $int:literal, |$s:ident| $get:expr, |$t:ident, $v:ident| $set:expr) => {
        SettingInfo {
            name: $name,
            doc: $doc,
            range: $range,
            integer: $int,
            get: |$s: &RenderSettings| $get,
            set: |$t: &mut RenderSettings, $v: f64| $set,
            values: &[],
        }
    };
}

/// A two-valued setting stored as a `bool` field (path `$field` of what `$of` reads and `$mut`
/// writes): value 0 = `values[0]` (false), 1 = `values[1]` (true).
macro_rules! bool_setting {
    ($name:literal, $doc:literal, $of:ident, $mut:ident, $($field:ident).+, $values:expr) => {
        SettingInfo {
            name: $name,
            doc: $doc,
            range: Range::Closed(0.0, 1.0),
            integer: true,
            get: |s: &RenderSettings| Some($of(s).$($field).+ as u32 as f64),
            set: |s: &mut RenderSettings, v: f64| $mut(s).$($field).+ = v != 0.0,
            values: &$values,
        }
    };
}

/// A two-valued radiosity setting ([`bool_setting!`] of [`RadiositySettings`]).
macro_rules! radiosity_switch {
    ($name:literal, $doc:literal, $field:ident, $values:expr) => {
        bool_setting!($name, $doc, radiosity_of, radiosity_mut, $field, $values)
    };
}

/// A setting choosing one variant of a `Copy` enum field (`$of`/`$mut` its settings): the
/// variants in discriminant order, each with the name `--set` takes.
macro_rules! enum_setting {
    ($name:literal, $doc:literal, $of:ident, $mut:ident, $field:ident, [$($variant:expr => $value:literal),+ $(,)?]) => {
        SettingInfo {
            name: $name,
            doc: $doc,
            range: Range::Closed(0.0, ([$($value),+].len() - 1) as f64),
            integer: true,
            get: |s: &RenderSettings| Some($of(s).$field as u32 as f64),
            // values past the range clamp to the last variant (the range check reports them)
            set: |s: &mut RenderSettings, v: f64| {
                let variants = [$($variant),+];
                $mut(s).$field = variants[(v as usize).min(variants.len() - 1)]
            },
            values: &[$($value),+],
        }
    };
}

/// The splatting algorithm of a bounced-z-buffer technique (`$of`/`$mut` its settings).
macro_rules! splat_setting {
    ($doc:literal, $of:ident, $mut:ident) => {
        SettingInfo {
            name: "splat",
            doc: $doc,
            range: Range::Closed(0.0, 1.0),
            integer: true,
            get: |s: &RenderSettings| Some($of(s).splat as u32 as f64),
            set: |s: &mut RenderSettings, v: f64| {
                $mut(s).splat = if v == 0.0 {
                    crate::passes::bzb::Splat::Aov
                } else {
                    crate::passes::bzb::Splat::Dss
                }
            },
            values: &["aov", "dss"],
        }
    };
}

/// `filter-fresh-radius` of a BZB technique's bilateral filter (`$of`/`$mut` its settings):
/// [`BilateralSettings::fresh_radius`](crate::passes::bilateral::BilateralSettings::fresh_radius), 0 = off.
macro_rules! fresh_radius_setting {
    ($of:ident, $mut:ident) => {
        SettingInfo {
            name: "filter-fresh-radius",
            doc: "with alpha > 0: taps on each side for a pixel whose history was just rejected (disoccluded), falling as 1/sqrt(n + 1) over its n history frames to filter-radius; 0 = off (not in the paper)",
            range: Range::Closed(0.0, 32.0),
            integer: true,
            get: |s: &RenderSettings| Some($of(s).filter.fresh_radius.unwrap_or(0) as f64),
            set: |s: &mut RenderSettings, v: f64| $mut(s).filter.fresh_radius = (v >= 1.0).then_some(v as u32),
            values: &[],
        }
    };
}

/// A two-valued switch (off, on) of the temporal filter of the settings `$of` reads and
/// `$mut` writes: `$field` of [`TemporalSettings`](crate::passes::temporal::TemporalSettings)
/// (the history clamp, the start-up ramp).
macro_rules! temporal_flag {
    ($name:literal, $doc:literal, $of:ident, $mut:ident, $field:ident) => {
        SettingInfo {
            name: $name,
            doc: $doc,
            range: Range::Closed(0.0, 1.0),
            integer: true,
            get: |s: &RenderSettings| Some($of(s).temporal.is_some_and(|t| t.$field) as u32 as f64),
            set: |s: &mut RenderSettings, v: f64| {
                // nothing to set when the filter is off
                if let Some(t) = &mut $mut(s).temporal {
                    t.$field = v != 0.0;
                }
            },
            values: &["off", "on"],
        }
    };
}

/// The n×m patterns of the `deinterleave` setting, value v ≥ 1 = pattern v − 1: the square
/// ones first (the values 1..=3 that were its only ones), then every other pattern
/// `--deinterleave NxM` takes (n, m in 1..=4), so both accept the same patterns.
const DEINTERLEAVE_PATTERNS: [[u32; 2]; 16] = [
    [2, 2],
    [3, 3],
    [4, 4],
    [1, 1],
    [1, 2],
    [1, 3],
    [1, 4],
    [2, 1],
    [2, 3],
    [2, 4],
    [3, 1],
    [3, 2],
    [3, 4],
    [4, 1],
    [4, 2],
    [4, 3],
];

fn ao_mut(s: &mut RenderSettings) -> &mut AoSettings {
    s.ao.get_or_insert_with(AoSettings::default)
}

fn ao_of(s: &RenderSettings) -> AoSettings {
    s.ao.clone().unwrap_or_default()
}

/// α of an optional temporal filter: 0 turns it off, any other value keeps its distance threshold
/// (`off`'s when the filter was off).
fn set_alpha(
    t: &mut Option<crate::passes::temporal::TemporalSettings>,
    v: f64,
    off: crate::passes::temporal::TemporalSettings,
) {
    *t = (v != 0.0).then(|| crate::passes::temporal::TemporalSettings {
        alpha: v as f32,
        ..t.unwrap_or(off)
    });
}

fn radiosity_mut(s: &mut RenderSettings) -> &mut radiosity::RadiositySettings {
    s.radiosity.get_or_insert_with(Default::default)
}

fn radiosity_of(s: &RenderSettings) -> radiosity::RadiositySettings {
    s.radiosity.clone().unwrap_or_default()
}

static DIRECT_SETTINGS: [SettingInfo; 4] = [
    setting!(
        "shadow-resolution",
        "shadow map resolution per light",
        Range::Closed(64.0, 8192.0),
        true,
        |s| Some(s.shadow.resolution as f64),
        |s, v| s.shadow.resolution = v as u32
    ),
    setting!(
        "exposure",
        "exposure multiplier before tonemapping (default: the scene's)",
        Range::Above(0.0),
        false,
        |s| s.exposure.map(f64::from),
        |s, v| s.exposure = Some(v as f32)
    ),
    SettingInfo {
        name: "area-shadows",
        doc: "shadows of rect (area) lights: soft (PCSS: the light's image through the blockers is the filter, so penumbrae widen with the blocker-to-receiver distance) or hard (one shadow test from the light's centre)",
        range: Range::Closed(0.0, 1.0),
        integer: true,
        get: |s| Some(s.lighting.area_penumbrae as u32 as f64),
        set: |s, v| s.lighting.area_penumbrae = v != 0.0,
        values: &["hard", "soft"],
    },
    enum_setting!(
        "lighting-kernel",
        "the deferred direct lighting as a fullscreen fragment pass or as a compute pass (8x8 pixels per workgroup); auto: compute on GPUs whose storage textures take R16F and RG11B10, fragment on CPU adapters (the same shader code and values; not in a paper)",
        lighting_of,
        lighting_mut,
        kernel,
        [
            crate::passes::Kernel::Auto => "auto",
            crate::passes::Kernel::Fragment => "fragment",
            crate::passes::Kernel::Compute => "compute",
        ]
    ),
];

fn lighting_of(s: &RenderSettings) -> crate::passes::lighting::LightingSettings {
    s.lighting.clone()
}

fn lighting_mut(s: &mut RenderSettings) -> &mut crate::passes::lighting::LightingSettings {
    &mut s.lighting
}

static AO_SETTINGS: [SettingInfo; 18] = [
    setting!(
        "ao-radius",
        "world-space AO radius r (DGB Eq. 1; default: the scene's ao_radius)",
        Range::Above(0.0),
        false,
        |s| ao_of(s).radius.map(f64::from),
        |s, v| ao_mut(s).radius = Some(v as f32)
    ),
    setting!(
        "ao-bias",
        "bias β in scene units (default 0.01·r)",
        Range::AtLeast(0.0),
        false,
        |s| ao_of(s).bias.map(f64::from),
        |s, v| ao_mut(s).bias = Some(v as f32)
    ),
    setting!(
        "ao-intensity",
        "multiplies the sum in DGB Eq. 1",
        Range::AtLeast(0.0),
        false,
        |s| Some(ao_of(s).intensity as f64),
        |s, v| ao_mut(s).intensity = v as f32
    ),
    setting!(
        "samples",
        "AO taps N per pixel (τ from DGB Listing 3 for N <= 98)",
        Range::Closed(1.0, 256.0),
        true,
        |s| Some(ao_of(s).samples as f64),
        |s, v| ao_mut(s).samples = v as u32
    ),
    setting!(
        "alpha",
        "temporal filter weight α of the history (DGB §3.3; 0 = off)",
        Range::HalfOpen(0.0, 1.0),
        false,
        |s| Some(ao_of(s).temporal.map_or(0.0, |t| t.alpha as f64)),
        |s, v| set_alpha(&mut ao_mut(s).temporal, v, Default::default())
    ),
    temporal_flag!(
        "temporal-clamp",
        "on: clamp the reprojected history to the range of this frame's AO over the pixel's 3x3 neighbourhood before blending (no ghosts of moved occluders; not in the paper); off: DGB's filter as published",
        ao_of,
        ao_mut,
        clamp_history
    ),
    temporal_flag!(
        "temporal-ramp",
        "on: the AO's temporal filter averages the first frames after a cut equally (alpha_n = min(alpha, n/(n+1)); not in the paper); off: alpha from the first frame",
        ao_of,
        ao_mut,
        ramp
    ),
    temporal_flag!(
        "temporal-motion",
        "on: the AO's temporal filter reprojects with per-object velocities (the deep G-buffer's motion target), so moving objects keep their history (DGB 3.3); off: the camera's motion only",
        ao_of,
        ao_mut,
        object_motion
    ),
    setting!(
        "temporal-distance",
        "reprojection accepted within this distance of either layer (scene units)",
        Range::Above(0.0),
        false,
        |s| Some(ao_of(s).temporal.unwrap_or_default().max_distance as f64),
        |s, v| {
            let a = ao_mut(s);
            let mut t = a.temporal.unwrap_or_default();
            t.max_distance = v as f32;
            a.temporal = Some(t)
        }
    ),
    setting!(
        "blur-radius",
        "bilateral taps on each side (0 = none)",
        Range::Closed(0.0, 32.0),
        true,
        |s| Some(ao_of(s).blur.radius as f64),
        |s, v| ao_mut(s).blur.radius = v as u32
    ),
    setting!(
        "blur-step",
        "pixels between bilateral taps",
        Range::Closed(1.0, 8.0),
        true,
        |s| Some(ao_of(s).blur.step as f64),
        |s, v| ao_mut(s).blur.step = v as u32
    ),
    setting!(
        "mip-levels",
        "depth MIP levels",
        Range::Closed(1.0, crate::passes::depth_mip::MAX_LEVELS as f64),
        true,
        |s| Some(ao_of(s).mips.levels as f64),
        |s, v| ao_mut(s).mips.levels = v as u32
    ),
    setting!(
        "mip-q",
        "tap radius q in pixels at which the MIP level first increments (DGB §3.4)",
        Range::AtLeast(1.0),
        false,
        |s| Some(ao_of(s).q as f64),
        |s, v| ao_mut(s).q = v as f32
    ),
    SettingInfo {
        name: "deinterleave",
        doc: "deinterleaved AO (issue 11 item 8): ILS split into n x m sub-buffers, sub-buffer s = i + n*j evaluates the spiral taps k with k mod n*m = s, then gather + the same temporal/bilateral (off = one full-resolution pass)",
        range: Range::Closed(0.0, DEINTERLEAVE_PATTERNS.len() as f64),
        integer: true,
        get: |s| {
            Some(ao_of(s).deinterleave.map_or(0.0, |p| {
                DEINTERLEAVE_PATTERNS.iter().position(|&q| q == p).map_or(f64::NAN, |i| i as f64 + 1.0)
            }))
        },
        // (a value past the table, which `set` refuses, gives a pattern validation refuses)
        set: |s, v| {
            ao_mut(s).deinterleave = (v >= 1.0).then(|| {
                DEINTERLEAVE_PATTERNS
                    .get(v as usize - 1)
                    .copied()
                    .unwrap_or([v as u32 + 1; 2])
            })
        },
        values: &[
            "off", "2x2", "3x3", "4x4", "1x1", "1x2", "1x3", "1x4", "2x1", "2x3", "2x4", "3x1", "3x2", "3x4", "4x1",
            "4x2", "4x3",
        ],
    },
    setting!(
        "ao-scale",
        "the AO pass's resolution divisor s: at s > 1 it shades one pixel of each s x s block (a different one each frame), a joint bilateral upsampling fills the rest (1 = every pixel, as the paper; not with deinterleave; not in the paper, docs/ao.md)",
        Range::Closed(1.0, crate::passes::upsample::MAX_SCALE as f64),
        true,
        |s| Some(ao_of(s).scale as f64),
        |s, v| ao_mut(s).scale = v as u32
    ),
    enum_setting!(
        "ao-kernel",
        "the AO pass (Eq. 1-2, not the deinterleaved one) and its temporal and bilateral filters as fullscreen fragment passes or as compute passes (8x8 pixels per workgroup); auto: compute on GPUs, fragment on CPU adapters (R16F outputs: where the adapter's storage textures take them) (the same shader code and values; not in the paper; docs/ao.md)",
        ao_of,
        ao_mut,
        kernel,
        [
            crate::passes::Kernel::Auto => "auto",
            crate::passes::Kernel::Fragment => "fragment",
            crate::passes::Kernel::Compute => "compute",
        ]
    ),
    bool_setting!(
        "filter-obscurance",
        "on: the temporal and bilateral filters average Eq. 1's obscurance mean before the square root, then AV = 1 - sqrt (not in the paper; removes the brightening of few-tap deinterleaved AO); off: DGB's order",
        ao_of,
        ao_mut,
        filter_obscurance,
        ["off", "on"]
    ),
    bool_setting!(
        "blur-distance",
        "on: the bilateral reconstruction also weighs a tap by its surface's world distance from X, max(0, 1 - d^2/r^2) with r the AO radius (not in the paper; a surface seen at a grazing angle no longer averages pixels metres apart); off: DGB's plane and normal weights",
        ao_of,
        ao_mut,
        distance_weight,
        ["off", "on"]
    ),
];

static RADIOSITY_SETTINGS: [SettingInfo; 26] = [
    enum_setting!(
        "irradiance-normalisation",
        "the gather's normaliser (docs/radiosity.md): hemisphere (DGB Eq. 4: 2pi/sum w; over-estimates E where screen-space taps cluster near the normal), cosine (pi/sum w*cos: exact for a uniform surround, over-fills where only grazing taps hit) or bounded (pi/max(sum w*cos, sum w/2): the smaller of the two; not in the paper)",
        radiosity_of,
        radiosity_mut,
        normalisation,
        [
            crate::passes::radiosity::Normalisation::Hemisphere => "hemisphere",
            crate::passes::radiosity::Normalisation::Cosine => "cosine",
            crate::passes::radiosity::Normalisation::Bounded => "bounded",
        ]
    ),
    radiosity_switch!(
        "open-sky",
        "background taps of the gather: fill (skipped, the paper: their part of the hemisphere takes the other taps' light) or sky (the sky's radiance along the tap's camera ray)",
        open_sky,
        ["fill", "sky"]
    ),
    enum_setting!(
        "probe-ao",
        "how AO darkens the light probes' irradiance: off, plain (x AV, DGB Fig. 9: occluders are black), multibounce (x GTAO's multi-bounce G(AV, albedo): occluders reflect light too; not in the paper) or relative (x G(AV, albedo) / G(V_probe, albedo), at most 1: only the occlusion the probes' bake does not hold, V_probe their own openness within the AO radius from their distance maps; not in the paper)",
        radiosity_of,
        radiosity_mut,
        probe_ao,
        [
            crate::passes::radiosity::ProbeAo::Off => "off",
            crate::passes::radiosity::ProbeAo::Plain => "plain",
            crate::passes::radiosity::ProbeAo::MultiBounce => "multibounce",
            crate::passes::radiosity::ProbeAo::Relative => "relative",
        ]
    ),
    radiosity_switch!(
        "probe-visibility",
        "on: a light probe that its distance map says is behind a surface from the receiver barely counts in the probe blend (Chebyshev test; no light through walls; not in the paper); off: probes weigh by distance and facing only",
        probe_visibility,
        ["off", "on"]
    ),
    radiosity_switch!(
        "hidden-taps",
        "taps that fail Eq. 5's n_Y test: fill (skipped, the paper) or black (occluders: their weight, no light)",
        hidden_black,
        ["fill", "black"]
    ),
    radiosity_switch!(
        "coverage-confidence",
        "on: the probe blend's confidence is M/U, U = the taps in the receiver's hemisphere (taps on its own plane or behind it no longer count against screen space; not in the paper, docs/image-quality.md); off: DGB's M/N",
        coverage_confidence,
        ["off", "on"]
    ),
    radiosity_switch!(
        "probe-detail",
        "on: with probes, E = G*E_probe + c*(E_screen - E_probe along the same taps): the gather adds only what the probes miss in the directions it saw (not in the paper); off: DGB's blend c*E_screen + (1 - c)*G*E_probe",
        probe_detail,
        ["off", "on"]
    ),
    radiosity_switch!(
        "one-sided-confidence",
        "on: where the gather's irradiance is darker than the probes' (luminance), the probe blend's confidence c is scaled by their ratio: the light screen space lacks comes from surfaces it cannot see, which the probes do (not in the paper, docs/image-quality.md); off: DGB's c everywhere",
        one_sided_confidence,
        ["off", "on"]
    ),
    radiosity_switch!(
        "indirect-weights",
        "tap weights of the gather: paper (DGB Eq. 4, every tap weighs 1) or solid-angle (each tap weighs the solid angle its screen area covers at the receiver, self-normalised)",
        solid_angle,
        ["paper", "solid-angle"]
    ),
    radiosity_switch!(
        "tap-visibility-senders",
        "which taps --tap-visibility tests: hidden (layer-1 senders, by whether a point between lies within min separation behind a surface) or all (the visible senders too, by whether the segment passes from in front of the visible surface to behind it between two steps, and the hidden ones by both tests: no light through thin walls; 3-4x the gather's cost at 8 steps on lavapipe)",
        tap_visibility_all,
        ["hidden", "all"]
    ),
    enum_setting!(
        "indirect-kernel",
        "the radiosity gather, the multi-bounce propagation, the indirect light's temporal and bilateral filters and compose as fullscreen fragment passes or as compute passes (8x8 pixels per workgroup); auto: compute on GPUs, fragment on CPU adapters (R16F/RG11B10 outputs: where the adapter's storage textures take them) (the same shader code and values; not in the paper; docs/radiosity.md)",
        radiosity_of,
        radiosity_mut,
        kernel,
        [
            crate::passes::Kernel::Auto => "auto",
            crate::passes::Kernel::Fragment => "fragment",
            crate::passes::Kernel::Compute => "compute",
        ]
    ),
    radiosity_switch!(
        "radius-jitter",
        "on: each gather tap's radius is drawn within its stratum, kappa_i = (i + xi)/N with xi per pixel and frame (no fixed rings: their averages of bright senders left static blotches; not in the paper); off: the paper's (i + 1/2)/N",
        radius_jitter,
        ["off", "on"]
    ),
    radiosity_switch!(
        "indirect-temporal-noise",
        "on: hash the frame index into the gather's spiral rotation, so the temporal filter averages different tap patterns (the paper hashes the pixel only)",
        temporal_noise,
        ["off", "on"]
    ),
    setting!(
        "tap-visibility",
        "steps of a visibility test for the radiosity taps (which ones: --tap-visibility-senders): a sender counts as nothing for layer 0's receiver when a point between them lies within the deep G-buffer's min separation behind a surface of either layer (0 = off, as the paper; not in the paper, docs/radiosity.md)",
        Range::OffOr(2.0, radiosity::MAX_TAP_VISIBILITY as f64),
        true,
        |s| Some(radiosity_of(s).tap_visibility as f64),
        |s, v| radiosity_mut(s).tap_visibility = v as u32
    ),
    setting!(
        "gather-scale",
        "the radiosity gather's resolution divisor s: at s > 1 it shades one pixel of each s x s block (a different one each frame) and a joint bilateral upsampling fills the rest (1 = every pixel, as the paper; not in the paper, docs/radiosity.md)",
        Range::Closed(1.0, crate::passes::upsample::MAX_SCALE as f64),
        true,
        |s| Some(radiosity_of(s).gather_scale as f64),
        |s, v| radiosity_mut(s).gather_scale = v as u32
    ),
    setting!(
        "indirect-samples",
        "radiosity taps N per pixel (DGB Eq. 4-5; default: the preset's)",
        Range::Closed(1.0, 256.0),
        true,
        |s| Some(radiosity_of(s).samples as f64),
        |s, v| radiosity_mut(s).samples = v as u32
    ),
    setting!(
        "radiosity-radius",
        "world-space gather radius (default: the scene's radiosity_radius)",
        Range::Above(0.0),
        false,
        |s| radiosity_of(s).radius.map(f64::from),
        |s, v| radiosity_mut(s).radius = Some(v as f32)
    ),
    setting!(
        "indirect-blur-radius",
        "bilateral taps on each side for the indirect light",
        Range::Closed(0.0, 32.0),
        true,
        |s| Some(radiosity_of(s).blur.radius as f64),
        |s, v| radiosity_mut(s).blur.radius = v as u32
    ),
    setting!(
        "indirect-alpha",
        "temporal filter weight α of the indirect light (0 = off)",
        Range::HalfOpen(0.0, 1.0),
        false,
        |s| Some(radiosity_of(s).temporal.map_or(0.0, |t| t.alpha as f64)),
        |s, v| set_alpha(
            &mut radiosity_mut(s).temporal,
            v,
            crate::passes::radiosity::indirect_temporal()
        )
    ),
    temporal_flag!(
        "indirect-temporal-clamp",
        "on: clamp the reprojected indirect history to the range of this frame's over the pixel's 3x3 neighbourhood before blending (not in the paper); off: DGB's filter as published",
        radiosity_of,
        radiosity_mut,
        clamp_history
    ),
    temporal_flag!(
        "indirect-temporal-ramp",
        "on: the indirect light's temporal filter averages the first frames after a cut equally (alpha_n = min(alpha, n/(n+1)); not in the paper); off: alpha from the first frame",
        radiosity_of,
        radiosity_mut,
        ramp
    ),
    temporal_flag!(
        "indirect-temporal-motion",
        "on: the indirect light's temporal filter and the multi-bounce propagation reproject with per-object velocities (the deep G-buffer's motion target), so moving objects keep their history and bounces (DGB 3.3); off: the camera's motion only",
        radiosity_of,
        radiosity_mut,
        object_motion
    ),
    setting!(
        "delta",
        "progressive multi-bounce damping δ (DGB §3.3; 0 = single bounce)",
        Range::Closed(0.0, 1.0),
        false,
        |s| Some(radiosity_of(s).delta as f64),
        |s, v| radiosity_mut(s).delta = v as f32
    ),
    setting!(
        "reflection-distance",
        "mirror ray-march length in scene units (DGB §3.6)",
        Range::Above(0.0),
        false,
        |s| Some(s.reflections.unwrap_or_default().max_distance as f64),
        |s, v| s
            .reflections
            .get_or_insert_with(ReflectionSettings::default)
            .max_distance = v as f32
    ),
    setting!(
        "reflection-steps",
        "mirror ray-march steps",
        Range::Closed(1.0, 1024.0),
        true,
        |s| Some(s.reflections.unwrap_or_default().steps as f64),
        |s, v| s.reflections.get_or_insert_with(ReflectionSettings::default).steps = v as u32
    ),
    enum_setting!(
        "reflection-kernel",
        "the mirror ray march as a fullscreen fragment pass or as a compute pass (8x8 pixels per workgroup); auto: compute on GPUs, fragment on CPU adapters (the same shader code and values; not in the paper; docs/radiosity.md)",
        reflections_of,
        reflections_mut,
        kernel,
        [
            crate::passes::Kernel::Auto => "auto",
            crate::passes::Kernel::Fragment => "fragment",
            crate::passes::Kernel::Compute => "compute",
        ]
    ),
];

fn reflections_mut(s: &mut RenderSettings) -> &mut ReflectionSettings {
    s.reflections.get_or_insert_with(ReflectionSettings::default)
}

fn reflections_of(s: &RenderSettings) -> ReflectionSettings {
    s.reflections.unwrap_or_default()
}

fn ils_mut(s: &mut RenderSettings) -> &mut IlsSettings {
    s.ils.get_or_insert_with(Default::default)
}

fn ils_of(s: &RenderSettings) -> IlsSettings {
    s.ils.clone().unwrap_or_default()
}

static ILS_SETTINGS: [SettingInfo; 21] = [
    SettingInfo {
        name: "shadows",
        doc: "VPL visibility: none (SNSM, ILS §6.2) or vpl (SSM: a cube shadow map per VPL, §4.3, §6.3)",
        range: Range::Closed(0.0, 1.0),
        integer: true,
        get: |s| Some(ils_of(s).shadows as u32 as f64),
        set: |s, v| {
            ils_mut(s).shadows = if v == 0.0 {
                VplShadows::None
            } else {
                VplShadows::ShadowMaps
            }
        },
        values: &["none", "vpl"],
    },
    setting!(
        "vpl-shadow-resolution",
        "texels per side of each cube face of a VPL's shadow map (shadows = vpl; 6 faces per VPL)",
        Range::Closed(8.0, 512.0),
        true,
        |s| Some(ils_of(s).vpl_shadow_resolution as f64),
        |s, v| ils_mut(s).vpl_shadow_resolution = v as u32
    ),
    bool_setting!(
        "vpl-shadow-cache",
        "VPL shadow maps (shadows = vpl) of VPLs that stay put in a scene with no animated object: redraw every frame (as ILS §6.3's fresh VPL sets must) or keep those of the first frame until new VPLs arrive (not in the paper)",
        ils_of,
        ils_mut,
        vpl_shadow_cache,
        ["redraw", "keep"]
    ),
    setting!(
        "vpls",
        "VPLs N the caller generates by instant radiosity (ILS Table 4: 480)",
        Range::Closed(1.0, crate::passes::ils::MAX_VPLS as f64),
        true,
        |s| Some(ils_of(s).vpl_count as f64),
        |s, v| ils_mut(s).vpl_count = v as u32
    ),
    setting!(
        "interleave-n",
        "interleaving pattern n (columns; ILS Table 4: 8)",
        Range::Closed(1.0, 16.0),
        true,
        |s| Some(ils_of(s).pattern[0] as f64),
        |s, v| ils_mut(s).pattern[0] = v as u32
    ),
    setting!(
        "interleave-m",
        "interleaving pattern m (rows; ILS Table 4: 6)",
        Range::Closed(1.0, 16.0),
        true,
        |s| Some(ils_of(s).pattern[1] as f64),
        |s, v| ils_mut(s).pattern[1] = v as u32
    ),
    setting!(
        "split-block",
        "BS/BG block size (ILS §3.3; a power of two >= n, m) or 0 for the one-pass split (default)",
        Range::Closed(0.0, 1024.0),
        true,
        |s| Some(match ils_of(s).method {
            SplitMethod::Blocks { block } => block as f64,
            _ => 0.0,
        }),
        |s, v| ils_mut(s).method = if v == 0.0 {
            SplitMethod::Naive
        } else {
            SplitMethod::Blocks { block: v as u32 }
        }
    ),
    SettingInfo {
        name: "split",
        doc: "BS/BG method (ILS §3): naive (one pass through an index, Table 1's baseline), blocks (§3.3's block splitting + translation, block size `split-block`, 16 unless set) or compute (one compute pass, tiles read coherently; the modern form); all give the same bits",
        range: Range::Closed(0.0, 2.0),
        integer: true,
        get: |s| {
            Some(match ils_of(s).method {
                SplitMethod::Naive => 0.0,
                SplitMethod::Blocks { .. } => 1.0,
                SplitMethod::Compute => 2.0,
            })
        },
        set: |s, v| {
            let i = ils_mut(s);
            i.method = match (v as u32, i.method) {
                (0, _) => SplitMethod::Naive,
                (1, SplitMethod::Blocks { block }) => SplitMethod::Blocks { block },
                (1, _) => SplitMethod::Blocks { block: 16 },
                _ => SplitMethod::Compute,
            }
        },
        values: &["naive", "blocks", "compute"],
    },
    setting!(
        "clamp-distance",
        "geometry term clamped to 1/d^2 below this distance (default: 4% of the scene diagonal)",
        Range::Above(0.0),
        false,
        |s| ils_of(s).clamp_distance.map(f64::from),
        |s, v| ils_mut(s).clamp_distance = Some(v as f32)
    ),
    setting!(
        "brute-force",
        "1 = every pixel shades all N VPLs, unblurred (ILS Table 4's no IS)",
        Range::Closed(0.0, 1.0),
        true,
        |s| Some(ils_of(s).brute_force as u32 as f64),
        |s, v| ils_mut(s).brute_force = v != 0.0
    ),
    setting!(
        "all-vpls",
        "1 = every sub-buffer shades all N VPLs (test hook: equals the brute force)",
        Range::Closed(0.0, 1.0),
        true,
        |s| Some(ils_of(s).all_vpls_per_sub_buffer as u32 as f64),
        |s, v| ils_mut(s).all_vpls_per_sub_buffer = v != 0.0
    ),
    setting!(
        "blur",
        "Gaussian kernel scale (ILS §4.5): radius floor(blur*n/2) x floor(blur*m/2); 0 = no blur",
        Range::Closed(0.0, 4.0),
        false,
        |s| Some(ils_of(s).blur as f64),
        |s, v| ils_mut(s).blur = v as f32
    ),
    setting!(
        "bilinear",
        "1 = two texels per bilinear tap (ILS Fig. 4 b), 0 = texel centres (Fig. 4 a)",
        Range::Closed(0.0, 1.0),
        true,
        |s| Some(ils_of(s).bilinear as u32 as f64),
        |s, v| ils_mut(s).bilinear = v != 0.0
    ),
    bool_setting!(
        "blur-weights",
        "tap weights of the blur: gaussian (ILS §4.5) or equal-subsets (each Gaussian weight divided by the window's sum over its sub-buffer, so on a flat region the n (m) sub-buffers of a row (column) weigh the same and no grid remains; not in the paper)",
        ils_of,
        ils_mut,
        equal_subsets,
        ["gaussian", "equal-subsets"]
    ),
    setting!(
        "per-axis-db",
        "1 = each blur pass stops at discontinuities along its own axis only (not in ILS; sharper edges)",
        Range::Closed(0.0, 1.0),
        true,
        |s| Some(ils_of(s).per_axis_discontinuities as u32 as f64),
        |s, v| ils_mut(s).per_axis_discontinuities = v != 0.0
    ),
    setting!(
        "blur-slide",
        "1 = where an edge cuts the blur on one side, its window slides away from the edge to keep n (m) texels (not in ILS)",
        Range::Closed(0.0, 1.0),
        true,
        |s| Some(ils_of(s).slide_window as u32 as f64),
        |s, v| ils_mut(s).slide_window = v != 0.0
    ),
    setting!(
        "refine",
        "after the blur, pixels that averaged less than this share of the n*m VPL subsets (edges, thin features: speckles) are shaded again with all N VPLs (0 = off; not in ILS)",
        Range::Closed(0.0, 1.0),
        false,
        |s| Some(ils_of(s).refine as f64),
        |s, v| ils_mut(s).refine = v as f32
    ),
    setting!(
        "refine-roughness",
        "ils-refine also shades glossy receivers smoother than this roughness with all N VPLs (sharp lobes stay n*m blocks under the blur; 0 = off; not in ILS)",
        Range::Closed(0.0, 1.0),
        false,
        |s| Some(ils_of(s).refine_roughness as f64),
        |s, v| ils_mut(s).refine_roughness = v as f32
    ),
    setting!(
        "refine-peak",
        "ils-refine also shades Lambert pixels whose blur window holds a gathered texel that outshines its own VPL subset one period away by more than this times n*m times the blurred irradiance (channel sums; a VPL near the receivers: n*m blocks under the blur; 0 = off; not in ILS)",
        Range::Closed(0.0, 1.0),
        false,
        |s| Some(ils_of(s).refine_peak as f64),
        |s, v| ils_mut(s).refine_peak = v as f32
    ),
    setting!(
        "depth-threshold",
        "discontinuity beyond this tangent-plane distance / depth (ILS §4.5)",
        Range::Above(0.0),
        false,
        |s| Some(ils_of(s).depth_threshold as f64),
        |s, v| ils_mut(s).depth_threshold = v as f32
    ),
    setting!(
        "normal-threshold",
        "discontinuity beyond this normal difference in degrees (ILS §4.5)",
        Range::Closed(0.0, 180.0),
        false,
        |s| Some(ils_of(s).normal_threshold_deg as f64),
        |s, v| ils_mut(s).normal_threshold_deg = v as f32
    ),
];

fn abuffer_mut(s: &mut RenderSettings) -> &mut ABufferSettings {
    s.abuffer.get_or_insert_with(Default::default)
}

fn abuffer_of(s: &RenderSettings) -> ABufferSettings {
    s.abuffer.clone().unwrap_or_default()
}

/// The A-buffer's settings (ABA §IV, §III-B).
static ABUFFER_SETTINGS: [SettingInfo; 5] = [
    SettingInfo {
        name: "abuffer",
        doc: "A-buffer construction: linked-list (PPLL), linear (count + prefix sum + fill), fixed-array (K slots, Texture3D), dual-peel (DDP baseline)",
        range: Range::Closed(0.0, 3.0),
        integer: true,
        get: |s| Some(ABufferMethod::ALL.iter().position(|m| *m == abuffer_of(s).method).unwrap_or(0) as f64),
        set: |s, v| abuffer_mut(s).method = ABufferMethod::ALL[(v.max(0.0) as usize).min(3)],
        values: &["linked-list", "linear", "fixed-array", "dual-peel"],
    },
    setting!(
        "pool",
        "node pool of the linked-list and linear methods (default: 8 nodes per pixel); extra fragments are dropped and counted",
        Range::Closed(1.0, crate::passes::abuffer::MAX_POOL as f64),
        true,
        |s| abuffer_of(s).pool.map(f64::from),
        |s, v| abuffer_mut(s).pool = Some(v as u32)
    ),
    setting!(
        "max-layers",
        "K: fixed-array slots per pixel and dual-peel layers L (ABA: 16)",
        Range::Closed(1.0, crate::passes::abuffer::MAX_LAYERS as f64),
        true,
        |s| Some(abuffer_of(s).max_layers as f64),
        |s, v| abuffer_mut(s).max_layers = v as u32
    ),
    setting!(
        "compress",
        "M nodes of the compressed list (ABA Eq. 5); 0 = no compression",
        Range::Closed(0.0, crate::passes::abuffer::compress::MAX_NODES as f64),
        true,
        |s| Some(abuffer_of(s).compress.unwrap_or(0) as f64),
        |s, v| abuffer_mut(s).compress = (v != 0.0).then_some(v as u32)
    ),
    setting!(
        "compress-back-half",
        "1 = Eq. 5 evicts only from the back half of the array (the nearest nodes stay)",
        Range::Closed(0.0, 1.0),
        true,
        |s| Some(abuffer_of(s).compress_back_half as u32 as f64),
        |s, v| abuffer_mut(s).compress_back_half = v != 0.0
    ),
];

fn aba_ao_mut(s: &mut RenderSettings) -> &mut AbaAoSettings {
    abuffer_mut(s).ao.get_or_insert_with(Default::default)
}

fn aba_ao_of(s: &RenderSettings) -> AbaAoSettings {
    abuffer_of(s).ao.unwrap_or_default()
}

/// ABA multilayer AO (Algorithm 1); the names mean what DGB AO's mean.
static ABA_AO_SETTINGS: [SettingInfo; 12] = [
    setting!(
        "ao-radius",
        "world-space AO radius r (DGB Eq. 1-2, as for ao; default: the scene's ao_radius)",
        Range::Above(0.0),
        false,
        |s| aba_ao_of(s).radius.map(f64::from),
        |s, v| aba_ao_mut(s).radius = Some(v as f32)
    ),
    setting!(
        "ao-bias",
        "bias β in scene units (default 0.01·r)",
        Range::AtLeast(0.0),
        false,
        |s| aba_ao_of(s).bias.map(f64::from),
        |s, v| aba_ao_mut(s).bias = Some(v as f32)
    ),
    setting!(
        "ao-intensity",
        "multiplies the sum in DGB Eq. 1",
        Range::AtLeast(0.0),
        false,
        |s| Some(aba_ao_of(s).intensity as f64),
        |s, v| aba_ao_mut(s).intensity = v as f32
    ),
    setting!(
        "samples",
        "AO taps N per receiver hemisphere (ABA §V: 16)",
        Range::Closed(1.0, crate::passes::abuffer::ao::MAX_SAMPLES as f64),
        true,
        |s| Some(aba_ao_of(s).samples as f64),
        |s, v| aba_ao_mut(s).samples = v as u32
    ),
    bool_setting!(
        "multilayer",
        "on: every fragment of a tap pixel occludes (ABA Algorithm 1); off: the nearest only (single-layer SSAO)",
        aba_ao_of,
        aba_ao_mut,
        multilayer,
        ["off", "on"]
    ),
    enum_setting!(
        "kernel",
        "getAO kernel extended by Algorithm 1: ssao (Poisson-disk: DGB Eq. 1 over `samples` spiral taps), hbao (horizon-based: `directions` x `steps`, fragment shader) or hbao-compute (ABA §V-B: `steps` along +-x and +-y, 8x8 tiles of compressed nodes staged in workgroup memory; needs compress >= 1)",
        aba_ao_of,
        aba_ao_mut,
        kernel,
        [
            crate::passes::abuffer::ao::AoKernel::Ssao => "ssao",
            crate::passes::abuffer::ao::AoKernel::Hbao => "hbao",
            crate::passes::abuffer::ao::AoKernel::HbaoCompute => "hbao-compute",
        ]
    ),
    bool_setting!(
        "integration",
        "separate: AO blended apart from the colour (ABA's choice, then filtered); inside: also write the colour with AO inside the OIT blend and the separate product (hdr-aba-inside, hdr-aba-separate; needs compress=0)",
        aba_ao_of,
        aba_ao_mut,
        inside,
        ["separate", "inside"]
    ),
    setting!(
        "multires",
        "multi-resolution AO levels L (ABA Table II after MSSAO; default 1 = off): level k reads the nodes of pixel (2^k X, 2^k Y) per coarse texel, taps capped at 5 texels except on the coarsest level, combined as O = 1-(1-max O_k)(1-mean O_k); not with hbao-compute",
        Range::Closed(1.0, crate::passes::abuffer::ao::MAX_LEVELS as f64),
        true,
        |s| Some(aba_ao_of(s).levels as f64),
        |s, v| aba_ao_mut(s).levels = v as u32
    ),
    setting!(
        "directions",
        "HBAO screen directions D per hemisphere (rotated per pixel; hbao-compute always uses the 4 axis directions, unrotated)",
        Range::Closed(1.0, crate::passes::abuffer::ao::MAX_DIRECTIONS as f64),
        true,
        |s| Some(aba_ao_of(s).directions as f64),
        |s, v| aba_ao_mut(s).directions = v as u32
    ),
    setting!(
        "steps",
        "HBAO steps S along each direction (ABA Table III: 8; also hbao-compute's samples along +-x and +-y)",
        Range::Closed(1.0, crate::passes::abuffer::ao::MAX_STEPS as f64),
        true,
        |s| Some(aba_ao_of(s).steps as f64),
        |s, v| aba_ao_mut(s).steps = v as u32
    ),
    setting!(
        "blur-radius",
        "bilateral taps on each side (0 = none)",
        Range::Closed(0.0, 32.0),
        true,
        |s| Some(aba_ao_of(s).blur.radius as f64),
        |s, v| aba_ao_mut(s).blur.radius = v as u32
    ),
    setting!(
        "blur-step",
        "pixels between bilateral taps",
        Range::Closed(1.0, 8.0),
        true,
        |s| Some(aba_ao_of(s).blur.step as f64),
        |s, v| aba_ao_mut(s).blur.step = v as u32
    ),
];

fn bzb_mut(s: &mut RenderSettings) -> &mut BzbSettings {
    s.bzb.get_or_insert_with(BzbSettings::default)
}

fn bzb_of(s: &RenderSettings) -> BzbSettings {
    s.bzb.clone().unwrap_or_default()
}

static BZB_SETTINGS: [SettingInfo; 17] = [
    bool_setting!(
        "visibility",
        "on: bounced z-buffer (BZB §3.2, nearest occluder per direction); off: AOV baseline (additive, McGuire 2010)",
        bzb_of,
        bzb_mut,
        visibility,
        ["off", "on"]
    ),
    bool_setting!(
        "culling",
        "cull splats (AOV triangles, DSS shells) whose depth range misses every receiver under them (min/max depth tiles, BZB §4.3; the image is unchanged)",
        bzb_of,
        bzb_mut,
        culling,
        ["off", "on"]
    ),
    bool_setting!(
        "splat-bounds",
        "AOV splats: rect = the screen rectangle of the triangle's AABB grown by r; box = the box around its occlusion volume, clipped to that rectangle (fewer texels; the image is unchanged)",
        bzb_of,
        bzb_mut,
        box_splats,
        ["rect", "box"]
    ),
    enum_setting!(
        "splat-kernel",
        "AOV splats with visibility: fragment = the rasteriser's depth test (the paper); compute = the same rectangles tested in a compute pass, the nearest hit kept with 64-bit atomics (rect splats only); auto: compute on GPUs with those atomics, fragment on CPU adapters (the image is unchanged; docs/bzb.md)",
        bzb_of,
        bzb_mut,
        splat_kernel,
        [
            crate::passes::Kernel::Auto => "auto",
            crate::passes::Kernel::Fragment => "fragment",
            crate::passes::Kernel::Compute => "compute",
        ]
    ),
    setting!(
        "directions",
        "directions S per pixel, one interleaved sub-image each (BZB §3.1, §5: 4)",
        Range::Closed(1.0, crate::passes::bzb::MAX_DIRECTIONS as f64),
        true,
        |s| Some(bzb_of(s).directions as f64),
        |s, v| bzb_mut(s).directions = v as u32
    ),
    SettingInfo {
        name: "hemisphere",
        doc: "direction pdf (BZB §3.1): cosine (cos θ/π) or uniform (1/2π, the paper's AO choice)",
        range: Range::Closed(0.0, 1.0),
        integer: true,
        get: |s| Some(bzb_of(s).hemisphere as u32 as f64),
        set: |s, v| {
            bzb_mut(s).hemisphere = if v == 0.0 {
                Hemisphere::Cosine
            } else {
                Hemisphere::Uniform
            }
        },
        values: &["cosine", "uniform"],
    },
    setting!(
        "ao-radius",
        "world-space AO radius r = d_max of BZB §3.2 (default: the scene's ao_radius)",
        Range::Above(0.0),
        false,
        |s| bzb_of(s).radius.map(f64::from),
        |s, v| bzb_mut(s).radius = Some(v as f32)
    ),
    setting!(
        "ao-bias",
        "ray t_min in scene units: nearer hits do not occlude (default 0.01·r)",
        Range::AtLeast(0.0),
        false,
        |s| bzb_of(s).bias.map(f64::from),
        |s, v| bzb_mut(s).bias = Some(v as f32)
    ),
    splat_setting!(
        "splatting algorithm: aov (one occlusion volume per triangle, McGuire 2010) or dss (surfels shell-splatted into an interleaved hierarchical framebuffer, BZB §4)",
        bzb_of,
        bzb_mut
    ),
    setting!(
        "levels",
        "DSS levels l_max of the hierarchical framebuffer (BZB §4.1; 4, Table 3); d_max = r / 2^(l_max-1)",
        Range::Closed(1.0, crate::passes::bzb::dss::MAX_LEVELS as f64),
        true,
        |s| Some(bzb_of(s).dss.levels as f64),
        |s, v| bzb_mut(s).dss.levels = v as u32
    ),
    setting!(
        "surfel-size",
        "DSS ideal surfel radius in pixels (BZB §4.3: constant projected size)",
        Range::Closed(0.5, 16.0),
        false,
        |s| Some(bzb_of(s).dss.surfel_px as f64),
        |s, v| bzb_mut(s).dss.surfel_px = v as f32
    ),
    bool_setting!(
        "surfel-culling",
        "DSS view-frustum culling of triangles before surfelization, margin = the outermost shell radius (BZB §5)",
        bzb_of,
        bzb_mut,
        dss.culling,
        ["off", "on"]
    ),
    bool_setting!(
        "inner-shell",
        "DSS fragments whose receiver lies inside the level's shell: redirect (BZB §4.3 \"more efficient use of fill rate\": tested with the disk of the finer level whose shell holds it) or discard (the original DSS)",
        bzb_of,
        bzb_mut,
        dss.redirect,
        ["discard", "redirect"]
    ),
    setting!(
        "filter-radius",
        "cross-bilateral taps on each side (BZB §3.3; 0 = none)",
        Range::Closed(0.0, 32.0),
        true,
        |s| Some(bzb_of(s).filter.radius as f64),
        |s, v| bzb_mut(s).filter.radius = v as u32
    ),
    fresh_radius_setting!(bzb_of, bzb_mut),
    setting!(
        "filter-step",
        "pixels between cross-bilateral taps",
        Range::Closed(1.0, 8.0),
        true,
        |s| Some(bzb_of(s).filter.step as f64),
        |s, v| bzb_mut(s).filter.step = v as u32
    ),
    setting!(
        "alpha",
        "temporal filter weight α of the history (BZB §6's re-projection: DGB §3.3's filter on the reconstructed AV before the bilateral filter, directions re-drawn every frame). 0 = off, the default: every frame stands alone. With it a narrower bilateral filter (filter-radius=1) measured closer to the ray-traced AO (docs/bzb.md)",
        Range::HalfOpen(0.0, 1.0),
        false,
        |s| Some(bzb_of(s).temporal.map_or(0.0, |t| t.alpha as f64)),
        |s, v| set_alpha(&mut bzb_mut(s).temporal, v, crate::passes::bzb::temporal_filter())
    ),
];

fn bzb_gi_mut(s: &mut RenderSettings) -> &mut crate::passes::bzb::gi::BzbGiSettings {
    s.bzb_gi.get_or_insert_with(Default::default)
}

fn bzb_gi_of(s: &RenderSettings) -> crate::passes::bzb::gi::BzbGiSettings {
    s.bzb_gi.clone().unwrap_or_default()
}

static BZB_GI_SETTINGS: [SettingInfo; 16] = [
    splat_setting!(
        "splats: aov (the scene's triangles, radiance shaded per hit) or dss (surfels shaded with direct light at surfelization, shell-splatted into DSS's hierarchical framebuffer, BZB §4)",
        bzb_gi_of,
        bzb_gi_mut
    ),
    setting!(
        "levels",
        "DSS levels l_max (splat=dss, BZB §4.1); the outermost shell reaches dmax",
        Range::Closed(1.0, crate::passes::bzb::dss::MAX_LEVELS as f64),
        true,
        |s| Some(bzb_gi_of(s).dss.levels as f64),
        |s, v| bzb_gi_mut(s).dss.levels = v as u32
    ),
    setting!(
        "surfel-size",
        "DSS ideal surfel radius in pixels (splat=dss, BZB §4.3: constant projected size)",
        Range::Closed(0.5, 16.0),
        false,
        |s| Some(bzb_gi_of(s).dss.surfel_px as f64),
        |s, v| bzb_gi_mut(s).dss.surfel_px = v as f32
    ),
    bool_setting!(
        "inner-shell",
        "DSS fragments whose receiver lies inside the level's shell (splat=dss): redirect (BZB §4.3: tested with the disk of the finer level whose shell holds it) or discard (the original DSS)",
        bzb_gi_of,
        bzb_gi_mut,
        dss.redirect,
        ["discard", "redirect"]
    ),
    bool_setting!(
        "visibility",
        "on: bounced z-buffer (BZB §3.2, the nearest sender per direction); off: the additive baseline (every triangle within d_max adds π·form factor·radiance)",
        bzb_gi_of,
        bzb_gi_mut,
        visibility,
        ["off", "on"]
    ),
    setting!(
        "directions",
        "directions S per pixel, one interleaved sub-image each, importance-sampled by the receiver's BRDF × cos (BZB §3.1, §5: 4)",
        Range::Closed(1.0, crate::passes::bzb::MAX_DIRECTIONS as f64),
        true,
        |s| Some(bzb_gi_of(s).directions as f64),
        |s, v| bzb_gi_mut(s).directions = v as u32
    ),
    setting!(
        "dmax",
        "largest sender distance d_max in scene units (BZB §3.2; default: the scene's bounding-box diagonal). bzb-gi: a ray that hits nothing within it brings the sky's light only while d_max spans the scene (at least the diagonal)",
        Range::Above(0.0),
        false,
        |s| bzb_gi_of(s).d_max.map(f64::from),
        |s, v| bzb_gi_mut(s).d_max = Some(v as f32)
    ),
    setting!(
        "bias",
        "ray t_min in scene units: nearer hits are the receiver itself (default 0.01 × the scene's ao_radius)",
        Range::AtLeast(0.0),
        false,
        |s| bzb_gi_of(s).bias.map(f64::from),
        |s, v| bzb_gi_mut(s).bias = Some(v as f32)
    ),
    setting!(
        "clamp",
        "largest sender radiance (RGB component) a payload keeps; biased, removes caustic fireflies (default: off)",
        Range::Above(0.0),
        false,
        |s| bzb_gi_of(s).clamp.map(f64::from),
        |s, v| bzb_gi_mut(s).clamp = Some(v as f32)
    ),
    bool_setting!(
        "culling",
        "cull splats (AOV triangles, DSS shells) whose depth range misses every receiver under them (min/max depth tiles, BZB §4.3; the image is unchanged)",
        bzb_gi_of,
        bzb_gi_mut,
        culling,
        ["off", "on"]
    ),
    bool_setting!(
        "splat-bounds",
        "AOV splats: rect = the screen rectangle of the triangle's AABB grown by d_max; box = the box around its occlusion volume, clipped to that rectangle (fewer texels; the image is unchanged)",
        bzb_gi_of,
        bzb_gi_mut,
        box_splats,
        ["rect", "box"]
    ),
    enum_setting!(
        "splat-kernel",
        "AOV splats with visibility: fragment = the rasteriser's depth test (the paper); compute = the same rectangles tested in a compute pass, the nearest hit kept with 64-bit atomics (rect splats only); auto: compute on GPUs with those atomics, fragment on CPU adapters (the image is unchanged; docs/bzb.md)",
        bzb_gi_of,
        bzb_gi_mut,
        splat_kernel,
        [
            crate::passes::Kernel::Auto => "auto",
            crate::passes::Kernel::Fragment => "fragment",
            crate::passes::Kernel::Compute => "compute",
        ]
    ),
    setting!(
        "filter-radius",
        "cross-bilateral taps on each side (BZB §3.3; 0 = none)",
        Range::Closed(0.0, 32.0),
        true,
        |s| Some(bzb_gi_of(s).filter.radius as f64),
        |s, v| bzb_gi_mut(s).filter.radius = v as u32
    ),
    fresh_radius_setting!(bzb_gi_of, bzb_gi_mut),
    setting!(
        "filter-step",
        "pixels between cross-bilateral taps",
        Range::Closed(1.0, 8.0),
        true,
        |s| Some(bzb_gi_of(s).filter.step as f64),
        |s, v| bzb_gi_mut(s).filter.step = v as u32
    ),
    setting!(
        "alpha",
        "temporal filter weight α of the history (DGB §3.3's filter on the reconstructed light before the bilateral filter, directions re-drawn every frame; not in BZB). 0 = off, the default: every frame stands alone",
        Range::HalfOpen(0.0, 1.0),
        false,
        |s| Some(bzb_gi_of(s).temporal.map_or(0.0, |t| t.alpha as f64)),
        |s, v| set_alpha(
            &mut bzb_gi_mut(s).temporal,
            v,
            crate::passes::bzb::gi::BzbGiSettings::temporal_filter()
        )
    ),
];

/// One registered technique.
pub struct Technique {
    pub name: &'static str,
    /// One line: what it renders and from which paper section.
    pub doc: &'static str,
    /// The target holding the technique's linear result (EXR output, `eval`).
    pub output: &'static str,
    /// The target a PNG shows, and whether it is sRGB-encoded (false: raw values, e.g. AV).
    pub display: (&'static str, bool),
    pub eval: EvalKind,
    /// Named parameter sets (the first is the default); empty when it has none.
    pub presets: &'static [&'static str],
    /// The passes it adds to the frame, in frame order (what `strata bench technique`
    /// times; a test checks each runs in its frame).
    pub passes: &'static [&'static str],
    /// Passes that some of its settings add (e.g. `gather-scale`'s upsampling): `strata
    /// bench technique` times those the frame has, in frame order.
    pub optional_passes: &'static [&'static str],
    /// Its numeric settings, in groups (e.g. `full` = direct's + AO's + its own).
    pub settings: &'static [&'static [SettingInfo]],
    /// Turns `s` into this technique's settings with `preset` (`None`: the default
    /// preset). The caller keeps size, layers, variant and guard band; light probes
    /// (baked on the CPU) stay the caller's to add.
    pub configure: fn(&mut RenderSettings, Option<&str>) -> Result<(), RenderError>,
}

impl Technique {
    /// Every setting of this technique.
    pub fn setting_list(&self) -> impl Iterator<Item = &'static SettingInfo> {
        self.settings.iter().flat_map(|g| g.iter())
    }

    /// Sets setting `name` to `value` after checking its range; the error names
    /// the setting and its valid range.
    pub fn set(&self, s: &mut RenderSettings, name: &str, value: f64) -> Result<(), RenderError> {
        let info = self.setting_list().find(|i| i.name == name).ok_or_else(|| {
            let names: Vec<_> = self.setting_list().map(|i| i.name).collect();
            RenderError::Parameter(format!(
                "technique '{}' has no setting '{name}': valid settings are {}",
                self.name,
                names.join(", ")
            ))
        })?;
        if !info.range.contains(value) || (info.integer && value.fract() != 0.0) {
            return Err(RenderError::Parameter(format!(
                "{name} {value} is out of range: must be {}{}",
                if info.integer { "a whole number in " } else { "" },
                info.range
            )));
        }
        (info.set)(s, value);
        Ok(())
    }

    /// Settings for this technique on top of `base`.
    pub fn settings(&self, base: &RenderSettings, preset: Option<&str>) -> Result<RenderSettings, RenderError> {
        let mut s = base.clone();
        (self.configure)(&mut s, preset)?;
        s.guard_band = s.guard_band.or_default(crate::renderer::GuardBand::Pixels(0));
        Ok(s)
    }
}

fn no_preset(name: &str, preset: Option<&str>) -> Result<(), RenderError> {
    match preset {
        None => Ok(()),
        Some(p) => Err(RenderError::Parameter(format!(
            "technique '{name}' has no presets (got '{p}')"
        ))),
    }
}

fn configure_direct(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    no_preset("direct", preset)?;
    s.shade = true;
    s.abuffer = None;
    s.ils = None;
    s.ao = None;
    s.radiosity = None;
    s.reflections = None;
    s.bzb = None;
    s.bzb_gi = None;
    Ok(())
}

fn configure_ao(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    no_preset("ao", preset)?;
    // AO alone needs no lighting passes
    s.shade = false;
    s.abuffer = None;
    s.ils = None;
    s.ao = Some(s.ao.clone().unwrap_or_default());
    s.radiosity = None;
    s.reflections = None;
    s.guard_band = s.guard_band.or_default(crate::renderer::AO_GUARD_BAND);
    s.bzb = None;
    s.bzb_gi = None;
    Ok(())
}

fn configure_full(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    let name = preset.unwrap_or(radiosity::PRESETS[1].0);
    let p = radiosity::Preset::named(name).map_err(RenderError::Parameter)?;
    s.shade = true;
    s.abuffer = None;
    s.ils = None;
    s.ao = Some(s.ao.clone().unwrap_or_default());
    s.radiosity = Some(p.apply(radiosity::RadiositySettings::default()));
    s.reflections = Some(s.reflections.unwrap_or_default());
    s.guard_band = s.guard_band.or_default(crate::renderer::AO_GUARD_BAND);
    s.bzb = None;
    s.bzb_gi = None;
    Ok(())
}

/// ILS §6.2's interactive mode: direct light + one-bounce VPLs, interleaved.
/// The VPLs are the caller's to add (like the light probes): `IlsSettings::vpls`.
fn configure_ils(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    let ils = s.ils.clone().unwrap_or_default();
    let ils = ils
        .with_preset(preset.unwrap_or(crate::passes::ils::PRESETS[0]))
        .map_err(RenderError::Parameter)?;
    s.shade = true;
    s.abuffer = None;
    s.ao = None;
    s.radiosity = None;
    s.reflections = None;
    s.probes = None;
    s.ils = Some(ils);
    s.bzb = None;
    s.bzb_gi = None;
    Ok(())
}

/// ABA OIT: every fragment in an A-buffer, sorted and blended front to back.
fn configure_oit(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    no_preset("oit", preset)?;
    // the A-buffer shades its own fragments: no deferred lighting
    s.shade = false;
    s.ao = None;
    s.radiosity = None;
    s.reflections = None;
    s.probes = None;
    s.ils = None;
    s.bzb = None;
    s.bzb_gi = None;
    let mut a = s.abuffer.clone().unwrap_or_default();
    a.ao = None;
    s.abuffer = Some(a);
    Ok(())
}

/// ABA AO: the A-buffer of `oit` plus opacity-aware multilayer AO (Algorithm 1).
/// The caller's DGB AO radius, bias, ε and intensity (`--ao-radius`, …) carry
/// over, so they mean what they mean for `ao`; the guard band defaults to AO's.
fn configure_aba_ao(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    no_preset("aba-ao", preset)?;
    let dgb = s.ao.take();
    let own = s.abuffer.as_ref().and_then(|a| a.ao.clone());
    configure_oit(s, None)?;
    let a = abuffer_mut(s).ao.insert(own.unwrap_or_default());
    if let Some(d) = dgb {
        a.radius = a.radius.or(d.radius);
        a.bias = a.bias.or(d.bias);
        a.epsilon = a.epsilon.or(d.epsilon);
        a.intensity = d.intensity;
    }
    s.guard_band = s.guard_band.or_default(crate::renderer::AO_GUARD_BAND);
    Ok(())
}

const ABA_AO_PASSES: &[&str] = &[
    "abuffer-clear",
    "abuffer-draw",
    "abuffer-resolve",
    "aba-ao",
    "ao-blur-h",
    "ao-blur-v",
    "tonemap",
];

/// The OIT frame with the default (linked-list) A-buffer; `linear` adds
/// `abuffer-count` and `abuffer-prefix-sum` ([`ABufferMethod::passes`]).
const OIT_PASSES: &[&str] = &["abuffer-clear", "abuffer-draw", "abuffer-resolve", "tonemap"];
/// BZB AO (AOV splats with a bounced z-buffer). The AO radius and bias of the
/// caller's DGB AO settings (`--ao-radius`, `--ao-bias`) carry over, so they mean
/// what they mean for `ao`.
fn configure_bzb_ao(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    no_preset("bzb-ao", preset)?;
    s.shade = false;
    s.abuffer = None;
    s.ils = None;
    s.radiosity = None;
    s.reflections = None;
    s.bzb_gi = None;
    let mut b = s.bzb.clone().unwrap_or_default();
    if let Some(ao) = s.ao.take() {
        b.radius = b.radius.or(ao.radius);
        b.bias = b.bias.or(ao.bias);
    }
    s.bzb = Some(b);
    Ok(())
}

const BZB_AO_PASSES: &[&str] = &[
    "bzb-directions",
    "bzb-zminmax",
    "bzb-splat",
    "bzb-reconstruct",
    "bzb-blur-h",
    "bzb-blur-v",
];

/// BZB GI: direct light + one bounce gathered through the bounced z-buffer
/// (AOV triangle splats with a radiance payload), composed like ILS.
fn configure_bzb_gi(s: &mut RenderSettings, preset: Option<&str>) -> Result<(), RenderError> {
    no_preset("bzb-gi", preset)?;
    s.shade = true;
    s.abuffer = None;
    s.ao = None;
    s.radiosity = None;
    s.reflections = None;
    s.probes = None;
    s.ils = None;
    s.bzb = None;
    s.bzb_gi = Some(s.bzb_gi.clone().unwrap_or_default());
    Ok(())
}

const BZB_GI_PASSES: &[&str] = &[
    "shadow",
    "lighting",
    "bzb-directions",
    "bzb-zminmax",
    "bzb-splat",
    "bzb-gi-shade",
    "bzb-reconstruct",
    "bzb-gi-blur-h",
    "bzb-gi-blur-v",
    "bzb-gi-glossy-blur-h",
    "bzb-gi-glossy-blur-v",
    "compose",
    "tonemap",
];

/// The default frame's passes in every scene; `ils-bg-glossy`, `ils-blur-glossy-h` and
/// `-v` join them in scenes with glossy materials, and the settings add others
/// (`IlsSettings::passes`).
const ILS_PASSES: &[&str] = &[
    "shadow",
    "lighting",
    "ils-gbuffer",
    "ils-bs",
    "ils-snsm",
    "ils-bg",
    "ils-db",
    "ils-blur-h",
    "ils-blur-v",
    "compose",
    "tonemap",
];

/// The AO stage's passes (DGB Table 4's AO column).
pub const AO_PASSES: &[&str] = &["depth-mip", "ao", "ao-temporal", "ao-blur-h", "ao-blur-v"];

/// The radiosity stage's passes (Table 4's indirect columns: gather, reconstruction, compose).
pub const RADIOSITY_PASSES: &[&str] = &[
    "depth-mip",
    "propagate",
    "radiosity",
    // only with `gather-scale` > 1
    "radiosity-upsample",
    "indirect-temporal",
    "indirect-blur-h",
    "indirect-blur-v",
    "compose",
];

const DIRECT_PASSES: &[&str] = &["shadow", "lighting", "tonemap"];

const FULL_PASSES: &[&str] = &[
    "shadow",
    "lighting",
    "depth-mip",
    "ao",
    "ao-temporal",
    "ao-blur-h",
    "ao-blur-v",
    "propagate",
    "radiosity",
    "indirect-temporal",
    "indirect-blur-h",
    "indirect-blur-v",
    "compose",
    "reflections",
    "tonemap",
];

/// Passes `full`'s settings may add: the reduced-resolution AO's and gather's upsampling
/// (`ao-scale`, `gather-scale` > 1).
const FULL_OPTIONAL_PASSES: &[&str] = &["ao-upsample", "radiosity-upsample"];

/// Passes `ao`'s settings may add: the reduced-resolution AO's upsampling (`ao-scale` > 1).
pub const AO_OPTIONAL_PASSES: &[&str] = &["ao-upsample"];

/// Preset names of the DGB radiosity (Table 2), default first.
const FULL_PRESETS: &[&str] = &["balanced", "high-performance", "high-quality"];

static REGISTRY: [Technique; 8] = [
    Technique {
        name: "direct",
        doc: "direct light (shadowed sun, point, spot, rect) and emission from G-buffer layer 0, tonemapped",
        output: "hdr",
        display: ("ldr", true),
        eval: EvalKind::None,
        presets: &[],
        passes: DIRECT_PASSES,
        optional_passes: &[],
        settings: &[&DIRECT_SETTINGS],
        configure: configure_direct,
    },
    Technique {
        name: "ao",
        doc: "deep-G-buffer ambient obscurance over every layer (DGB §3.1, Eq. 1-2), temporal + bilateral filtered",
        output: "ao",
        display: ("ao", false),
        eval: EvalKind::AmbientVisibility,
        presets: &[],
        passes: AO_PASSES,
        optional_passes: AO_OPTIONAL_PASSES,
        settings: &[&AO_SETTINGS],
        configure: configure_ao,
    },
    Technique {
        name: "full",
        doc: "direct + deep-G-buffer radiosity (DGB §3.2-3.3) + light probes + AO + mirror reflections (§3.6)",
        output: "hdr-reflected",
        display: ("ldr", true),
        eval: EvalKind::Radiance,
        presets: FULL_PRESETS,
        passes: FULL_PASSES,
        optional_passes: FULL_OPTIONAL_PASSES,
        settings: &[&DIRECT_SETTINGS, &AO_SETTINGS, &RADIOSITY_SETTINGS],
        configure: configure_full,
    },
    Technique {
        name: "ils",
        doc:
            "direct + interleaved deferred shading of one-bounce VPLs (ILS §4, §6.2; 480 VPLs, 8x6), VPL visibility: none (SNSM) or shadow maps (SSM, §4.3)",
        output: "hdr-full",
        display: ("ldr", true),
        // against the brute force of the same VPLs and the one-bounce path tracer
        eval: EvalKind::VplRadiance,
        presets: &crate::passes::ils::PRESETS,
        passes: ILS_PASSES,
        optional_passes: &[],
        settings: &[&DIRECT_SETTINGS, &ILS_SETTINGS],
        configure: configure_ils,
    },
    Technique {
        name: "oit",
        doc: "order-independent transparency from an A-buffer of every fragment (ABA §IV: linked-list, linear, fixed-array or dual-peel), sorted and blended front to back; lists compressed to M nodes (Eq. 5)",
        output: "hdr-oit",
        display: ("ldr", true),
        eval: EvalKind::Composite,
        presets: &[],
        passes: OIT_PASSES,
        optional_passes: &[],
        settings: &[&ABUFFER_SETTINGS],
        configure: configure_oit,
    },
    Technique {
        name: "aba-ao",
        doc: "opacity-aware multilayer AO over the A-buffer (ABA Algorithm 1, Eq. 3-4: every layer occludes, weighted by α; transparent receivers blend exterior and interior AO), blended like the colour, bilateral filtered",
        output: "ao",
        display: ("ao", false),
        eval: EvalKind::AmbientVisibility,
        presets: &[],
        passes: ABA_AO_PASSES,
        optional_passes: &[],
        settings: &[&ABUFFER_SETTINGS, &ABA_AO_SETTINGS],
        configure: configure_aba_ao,
    },
    Technique {
        name: "bzb-ao",
        doc: "ambient occlusion volumes (splat=aov) or deep-screen-space surfels (splat=dss, BZB §4) splatted into a bounced z-buffer (BZB §3: S directions per pixel, nearest occluder wins; visibility=off: the additive baseline)",
        output: "ao",
        display: ("ao", false),
        eval: EvalKind::AmbientVisibility,
        presets: &[],
        passes: BZB_AO_PASSES,
        optional_passes: &[],
        settings: &[&BZB_SETTINGS],
        configure: configure_bzb_ao,
    },
    Technique {
        name: "bzb-gi",
        doc: "direct + one-bounce diffuse/glossy GI through a bounced z-buffer (BZB §3): S BRDF-sampled directions per pixel, triangle splats (splat=aov) or DSS surfels shaded at surfelization (splat=dss, BZB §4.3) carrying the sender's shadow-mapped direct radiance, nearest sender wins; visibility=off: the additive form-factor baseline (DSS's additive shell splatting with splat=dss)",
        output: "hdr-full",
        display: ("ldr", true),
        eval: EvalKind::Radiance,
        presets: &[],
        passes: BZB_GI_PASSES,
        optional_passes: &[],
        settings: &[&DIRECT_SETTINGS, &BZB_GI_SETTINGS],
        configure: configure_bzb_gi,
    },
];

/// Every registered technique.
pub fn registry() -> &'static [Technique] {
    &REGISTRY
}

/// The technique called `name`; the error lists the valid names.
pub fn find(name: &str) -> Result<&'static Technique, RenderError> {
    registry().iter().find(|t| t.name == name).ok_or_else(|| {
        let names: Vec<_> = registry().iter().map(|t| t.name).collect();
        RenderError::Parameter(format!(
            "unknown technique '{name}': valid techniques are {}",
            names.join(", ")
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--set deinterleave=NxM` takes every pattern `--deinterleave NxM` takes, and reads back
    /// the pattern it set (it used to know the square ones only and read n×m back as n×n).
    #[test]
    fn every_deinterleave_pattern_round_trips_through_its_setting() {
        let ao = find("ao").unwrap();
        let info = ao.setting_list().find(|i| i.name == "deinterleave").unwrap();
        assert_eq!(info.values.len(), DEINTERLEAVE_PATTERNS.len() + 1);
        let mut seen = Vec::new();
        for n in 1..=crate::passes::ao::MAX_DEINTERLEAVE {
            for m in 1..=crate::passes::ao::MAX_DEINTERLEAVE {
                let text = format!("{n}x{m}");
                let v = named_value("deinterleave", &text).unwrap_or_else(|| panic!("{text} is not a value"));
                let mut s = ao.settings(&RenderSettings::default(), None).unwrap();
                ao.set(&mut s, "deinterleave", v).unwrap();
                assert_eq!(s.ao.as_ref().unwrap().deinterleave, Some([n, m]), "{text}");
                assert_eq!((info.get)(&s), Some(v), "{text}");
                seen.push(v);
            }
        }
        seen.sort_by(f64::total_cmp);
        seen.dedup();
        assert_eq!(seen.len(), 16);
        // the values that were the only ones keep their meaning
        for (v, text) in [(0.0, "off"), (1.0, "2x2"), (2.0, "3x3"), (3.0, "4x4")] {
            assert_eq!(named_value("deinterleave", text), Some(v));
        }
    }

    #[test]
    fn auto_guard_band_is_the_techniques_default_and_an_explicit_one_wins() {
        use crate::renderer::{GuardBand, AO_GUARD_BAND};
        let auto = RenderSettings {
            guard_band: GuardBand::Auto,
            ..Default::default()
        };
        for t in registry() {
            let s = t.settings(&auto, None).unwrap();
            let want = if matches!(t.name, "ao" | "full" | "aba-ao") {
                AO_GUARD_BAND
            } else {
                GuardBand::Pixels(0)
            };
            assert_eq!(s.guard_band, want, "{}", t.name);
            let explicit = RenderSettings {
                guard_band: GuardBand::Pixels(7),
                ..Default::default()
            };
            assert_eq!(
                t.settings(&explicit, None).unwrap().guard_band,
                GuardBand::Pixels(7),
                "{}",
                t.name
            );
        }
        assert_eq!("auto".parse::<GuardBand>().unwrap(), GuardBand::Auto);
        assert_eq!(GuardBand::Auto.pixels(360), 0);
    }

    #[test]
    fn names_are_unique_and_found() {
        for (i, t) in registry().iter().enumerate() {
            assert!(registry()[..i].iter().all(|u| u.name != t.name), "duplicate {}", t.name);
            assert_eq!(find(t.name).unwrap().name, t.name);
        }
        let e = find("nope").err().expect("unknown name").to_string();
        assert!(e.contains("direct") && e.contains("full"), "{e}");
    }

    #[test]
    fn every_preset_configures_and_validates() {
        let base = RenderSettings::default();
        for t in registry() {
            let presets: Vec<Option<&str>> = if t.presets.is_empty() {
                vec![None]
            } else {
                t.presets.iter().map(|p| Some(*p)).collect()
            };
            for p in presets {
                let s = t.settings(&base, p).unwrap();
                s.validate().unwrap();
            }
            assert!(
                t.settings(&base, Some("nope")).is_err(),
                "{} accepted an unknown preset",
                t.name
            );
        }
    }

    /// The declared ranges are the validated ones: each end inside validates,
    /// each end outside fails `RenderSettings::validate` (where the type can hold it).
    #[test]
    fn declared_ranges_match_validation() {
        let base = RenderSettings::default();
        for t in registry() {
            let defaults = t.settings(&base, None).unwrap();
            for info in t.setting_list() {
                let check = |v: f64, valid: bool| {
                    let mut s = defaults.clone();
                    (info.set)(&mut s, v);
                    if !valid && (info.get)(&s) != Some(v) {
                        // the type cannot hold v (a 0/1 switch stores a bool): nothing to validate
                        return;
                    }
                    let r = s.validate();
                    assert_eq!(
                        r.is_ok(),
                        valid,
                        "{} {}: {v} ({}): {r:?}",
                        t.name,
                        info.name,
                        info.range
                    );
                    if valid {
                        assert_eq!(
                            (info.get)(&s),
                            Some(v as f32 as f64),
                            "{} {} reads back",
                            t.name,
                            info.name
                        );
                    }
                };
                let step = if info.integer { 1.0 } else { 1e-3 };
                for v in info.range.ends(info.integer) {
                    check(v, true);
                }
                // the first value outside each end
                match info.range {
                    Range::Closed(a, b) => {
                        check(b + step, false);
                        if a - step >= 0.0 || !info.integer {
                            check(a - step, false);
                        }
                    }
                    Range::HalfOpen(a, b) => {
                        check(b, false);
                        check(a - step, false);
                    }
                    Range::AtLeast(a) => check(a - step, false),
                    Range::Above(a) => check(a, false),
                    Range::OffOr(a, b) => {
                        check(b + step, false);
                        if a - step > 0.0 {
                            check(a - step, false);
                        }
                        check(-step, false);
                    }
                }
                assert!(!info.doc.is_empty());
            }
        }
    }

    #[test]
    fn set_checks_the_range_and_names_it() {
        let t = find("ao").unwrap();
        let mut s = t.settings(&RenderSettings::default(), None).unwrap();
        t.set(&mut s, "samples", 32.0).unwrap();
        assert_eq!(s.ao.as_ref().unwrap().samples, 32);
        let e = t.set(&mut s, "samples", 300.0).unwrap_err().to_string();
        assert!(e.contains("samples") && e.contains("1..=256"), "{e}");
        let e = t.set(&mut s, "samples", 2.5).unwrap_err().to_string();
        assert!(e.contains("whole number"), "{e}");
        let e = t.set(&mut s, "nope", 1.0).unwrap_err().to_string();
        assert!(e.contains("valid settings are") && e.contains("ao-radius"), "{e}");
    }

    #[test]
    fn full_presets_are_table_2s_files() {
        let names: Vec<_> = radiosity::PRESETS.iter().map(|(n, _)| *n).collect();
        for p in FULL_PRESETS {
            assert!(names.contains(p), "{p}");
        }
        assert_eq!(FULL_PRESETS.len(), names.len());
    }
}
