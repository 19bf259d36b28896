//! The screen-space oracle: the indirect light a *perfect* gather over k deep-G-buffer
//! layers would see, and DGB's blend with light probes built on it.
//!
//! DGB §3.2 gathers the radiance of the surfaces its layers hold and blends the result
//! with a probe's irradiance by the confidence c: E = c·Ê + (1 − c)·E_probe, Ê the
//! gather's estimate of the whole hemisphere's irradiance from what it saw. A perfect
//! gather sees exactly the directions whose first surface lies in one of the layers,
//! and over them it gets the path tracer's light. Then c is the cosine-weighted share of
//! those directions, c·Ê is their irradiance E_seen, and
//!
//!   E_oracle = E_seen + (1 − c)·E_probe                       (DGB §3.2's blend)
//!
//! is what that blend gives with these probes and nothing lost in the gather; Ê = E_seen / c
//! is what screen space alone gives. Neither depends on the gather's taps, MIP levels,
//! filters or bounces: the errors left are the probes', what the layers miss, and the
//! blend's assumption that the directions the layers miss carry the probes' average.
//!
//! Which surfaces "a layer holds" is decided along the camera ray through the bounce's
//! hit point y itself, with the layer rule of [`crate::layers`]: y is in layer 0 when
//! nothing lies in front of it, and in layer j when it is the first surface more than
//! Δz behind layer j − 1's (the rule applied at y's own image position, not at a pixel
//! centre: a gather at any resolution approaches this). y must also project inside the
//! image. The radius-bounded variants also require |y − x| ≤ r, the gather's world-space
//! radius.
//!
//! The estimator shares the path tracer's paths ([`Reference::gi_pixel_paths`]): its
//! total is [`crate::Estimator::Gi`]'s indirect light with the same seed, bit for bit.
//! Each path's indirect light arrives through its first bounce, so sorting paths by
//! where that bounce landed splits the indirect light exactly. At a Lambertian receiver
//! the paths are cosine-distributed, so c is the cosine-weighted share; at a glossy one
//! they follow its BRDF, and c weights the directions by it.

use glam::Vec3;
use strata_scene::{Camera, ImageBuf};

use crate::gi::GiSettings;
use crate::Reference;

/// The variants the estimator tracks: (layers k, bounded by the radius).
pub const ORACLE_VARIANTS: [(usize, bool); 4] = [(1, false), (2, false), (1, true), (2, true)];

/// Channels per variant: the indirect light of the paths it sees (3), their share c (1),
/// and the mean over all paths of the seen indicator × the order-2 SH basis of the first
/// bounce's direction (9; `strata_scene::probes::sh9`).
const PER_VARIANT: usize = 13;
/// Channels before the variants: the indirect light (3), the receiver's albedo ρ (3), its
/// position (3) and its shading normal facing the camera (3).
const HEAD: usize = 12;

/// Channels of [`crate::Estimator::ScreenOracle`]'s per-pixel means: see `HEAD` and
/// `PER_VARIANT`, one block per variant of [`ORACLE_VARIANTS`].
pub const ORACLE_CHANNELS: u32 = (HEAD + PER_VARIANT * ORACLE_VARIANTS.len()) as u32;

/// Settings of the screen-space oracle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenOracleSettings {
    /// The paths (bounces, seed; `spp` is unused, the sample range decides).
    pub gi: GiSettings,
    /// DGB's minimum separation Δz between layers (camera-space depth).
    pub min_separation: f32,
    /// The gather's world-space radius r for the bounded variants.
    pub radius: f32,
}

/// The layer (0-based) that holds the point `p` as the camera sees it: the camera ray
/// towards `p` peeled with the minimum separation `min_separation` (relative tolerance
/// `tolerance`, as [`crate::LayerSettings::depth_tolerance`]), or `None` when `p` lies
/// outside the image, within the separation of the layer before it, or deeper than
/// `count` layers.
#[allow(clippy::too_many_arguments)]
pub fn screen_layer(
    r: &Reference,
    camera: &Camera,
    (width, height): (u32, u32),
    min_separation: f32,
    tolerance: f32,
    count: usize,
    p: Vec3,
    rays: &mut u64,
) -> Option<usize> {
    let (right, up, forward) = camera.basis();
    let d = p - camera.eye;
    let z = d.dot(forward);
    if !(z > camera.near) {
        return None;
    }
    let t = (0.5 * camera.fov_y_deg.to_radians()).tan();
    let aspect = width as f32 / height as f32;
    let (nx, ny) = (d.dot(right) / (z * t * aspect), d.dot(up) / (z * t));
    if !(nx.abs() <= 1.0 && ny.abs() <= 1.0) {
        return None;
    }
    // the ray's parameter is camera-space depth, as `Camera::pixel_dir`'s
    let dir = d / z;
    // p's own surface, a hair in front of it, does not count as a layer before it
    let end = z * (1.0 - 1e-4);
    let mut start = camera.near;
    for j in 0..count {
        if z < start {
            return None;
        }
        *rays += 1;
        match r.bvh.intersect(camera.eye, dir, start, end) {
            None => return Some(j),
            Some(h) => start = h.t + min_separation + tolerance * h.t,
        }
    }
    None
}

/// The gather's irradiance Ê = E_seen / c of a receiver of albedo ρ, from the radiance
/// `seen` (ρ/π·E_seen) of the paths the layers hold and their share `c` (0 where it saw
/// nothing or ρ is 0).
pub fn gathered_irradiance(seen: Vec3, c: f32, albedo: Vec3) -> Vec3 {
    let e = |s: f32, a: f32| {
        if c > 0.0 && a > 0.0 {
            s * std::f32::consts::PI / (a * c)
        } else {
            0.0
        }
    };
    Vec3::new(e(seen.x, albedo.x), e(seen.y, albedo.y), e(seen.z, albedo.z))
}

/// DGB §3.2's blend with a perfect gather, c·Ê + (1 − c)·E_probe = E_seen + (1 − c)·E_probe,
/// as the blend rule of [`OracleImages::blend`].
pub fn paper_blend(e_hat: Vec3, c: f32, e_probe: Vec3) -> Vec3 {
    let c = c.clamp(0.0, 1.0);
    c * e_hat + (1.0 - c) * e_probe
}

/// The oracle's per-pixel means split into images.
#[derive(Clone, Debug)]
pub struct OracleImages {
    /// The path tracer's indirect light (RGB).
    pub total: ImageBuf,
    /// The receiver's albedo (RGB; black where the pixel has no surface).
    pub albedo: ImageBuf,
    /// The receiver's position and shading normal (facing the camera), RGB each.
    pub position: ImageBuf,
    pub normal: ImageBuf,
    /// Per variant of [`ORACLE_VARIANTS`]: the indirect light of the paths it sees (RGB).
    pub seen: Vec<ImageBuf>,
    /// Per variant: the share of the paths it sees, c (1 channel).
    pub confidence: Vec<ImageBuf>,
    /// Per variant: the mean of the seen indicator × `sh9` of the path's first direction
    /// (9 channels). With cosine-distributed paths, π Σ L_lm · this is the cosine-weighted
    /// integral of an SH radiance L over the directions the variant sees.
    pub seen_sh: Vec<ImageBuf>,
}

/// [`OracleImages::gather_agreement`]'s result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GatherAgreement {
    /// Σ E_gathered / Σ Ê per RGB channel.
    pub irradiance_ratio: [f64; 3],
    /// The pixels compared.
    pub pixels: u32,
}

impl OracleImages {
    /// Splits a [`ORACLE_CHANNELS`]-channel image of means.
    pub fn from_means(means: &ImageBuf) -> Self {
        assert_eq!(
            means.channels, ORACLE_CHANNELS,
            "oracle means have {ORACLE_CHANNELS} channels"
        );
        let take = |first: usize, n: u32| {
            let mut out = ImageBuf::new(means.width, means.height, n);
            for (o, p) in out
                .data
                .chunks_exact_mut(n as usize)
                .zip(means.data.chunks_exact(ORACLE_CHANNELS as usize))
            {
                o.copy_from_slice(&p[first..first + n as usize]);
            }
            out
        };
        let variants = 0..ORACLE_VARIANTS.len();
        let block = |v: usize| HEAD + PER_VARIANT * v;
        Self {
            total: take(0, 3),
            albedo: take(3, 3),
            position: take(6, 3),
            normal: take(9, 3),
            seen: variants.clone().map(|v| take(block(v), 3)).collect(),
            confidence: variants.clone().map(|v| take(block(v) + 3, 1)).collect(),
            seen_sh: variants.map(|v| take(block(v) + 4, 9)).collect(),
        }
    }

    /// The index of variant (k, bounded) in [`ORACLE_VARIANTS`].
    pub fn variant(k: usize, bounded: bool) -> usize {
        ORACLE_VARIANTS
            .iter()
            .position(|&v| v == (k.clamp(1, 2), bounded))
            .expect("k is 1 or 2")
    }

    /// The indirect radiance ρ/π·E of a blend `rule`(Ê, c, E_probe) → E at every pixel, Ê
    /// the perfect gather's irradiance ([`gathered_irradiance`]) and E_probe the probes'
    /// irradiance `e_probe` (RGB).
    pub fn blend(&self, variant: usize, e_probe: &ImageBuf, rule: impl Fn(Vec3, f32, Vec3) -> Vec3) -> ImageBuf {
        self.per_pixel(variant, |seen, c, albedo, i| {
            let e = Vec3::from_slice(&e_probe.data[e_probe.channels as usize * i..][..3]);
            albedo * std::f32::consts::FRAC_1_PI * rule(gathered_irradiance(seen, c, albedo), c, e)
        })
    }

    /// Screen space alone, ρ/π·Ê = seen / c, at every pixel.
    pub fn alone(&self, variant: usize) -> ImageBuf {
        self.per_pixel(variant, |seen, c, _, _| if c > 0.0 { seen / c } else { Vec3::ZERO })
    }

    /// The mean confidence of a variant over the pixels with a surface.
    pub fn mean_confidence(&self, variant: usize) -> f64 {
        let (mut sum, mut n) = (0.0f64, 0u32);
        for (c, a) in self.confidence[variant]
            .data
            .iter()
            .zip(self.albedo.data.chunks_exact(3))
        {
            if a.iter().any(|v| *v > 0.0) {
                sum += *c as f64;
                n += 1;
            }
        }
        sum / n.max(1) as f64
    }

    /// How a real gather's irradiance `gathered` (RGB, its confidence in the fourth channel
    /// when it has one) compares with the perfect gather's Ê over the same receivers: per
    /// channel Σ E_gathered / Σ Ê over the pixels where the variant's c ≥ `min_c` and the
    /// real gather found something (c > 0), with the number of those pixels. `None` where
    /// there are none.
    pub fn gather_agreement(&self, variant: usize, gathered: &ImageBuf, min_c: f32) -> Option<GatherAgreement> {
        let n = gathered.channels as usize;
        let (mut sum_gpu, mut sum_oracle, mut pixels) = (glam::DVec3::ZERO, glam::DVec3::ZERO, 0u32);
        for i in 0..(self.total.width * self.total.height) as usize {
            let c = self.confidence[variant].data[i];
            let a = Vec3::from_slice(&self.albedo.data[3 * i..3 * i + 3]);
            let g = &gathered.data[n * i..n * i + n];
            let found = n < 4 || g[3] > 0.0;
            if c >= min_c && found && a.min_element() > 0.0 {
                let seen = Vec3::from_slice(&self.seen[variant].data[3 * i..3 * i + 3]);
                sum_oracle += gathered_irradiance(seen, c, a).as_dvec3();
                sum_gpu += Vec3::from_slice(&g[..3]).as_dvec3();
                pixels += 1;
            }
        }
        (pixels > 0 && sum_oracle.min_element() > 0.0).then(|| GatherAgreement {
            irradiance_ratio: (sum_gpu / sum_oracle).to_array(),
            pixels,
        })
    }

    /// `f`(seen radiance, c, albedo, pixel index) → radiance at every pixel of a variant.
    pub fn per_pixel(&self, variant: usize, f: impl Fn(Vec3, f32, Vec3, usize) -> Vec3) -> ImageBuf {
        let mut out = ImageBuf::new(self.total.width, self.total.height, 3);
        let seen = &self.seen[variant].data;
        let c = &self.confidence[variant].data;
        for (i, o) in out.data.chunks_exact_mut(3).enumerate() {
            let s = Vec3::from_slice(&seen[3 * i..3 * i + 3]);
            let a = Vec3::from_slice(&self.albedo.data[3 * i..3 * i + 3]);
            o.copy_from_slice(&f(s, c[i], a, i).to_array());
        }
        out
    }
}

impl Reference<'_> {
    /// Per-pixel sums of the oracle over the sample indices `samples`
    /// ([`ORACLE_CHANNELS`] values, see there).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn oracle_pixel_sum(
        &self,
        camera: &Camera,
        x: u32,
        y: u32,
        (width, height): (u32, u32),
        s: &ScreenOracleSettings,
        samples: std::ops::Range<u32>,
        rays: &mut u64,
    ) -> Vec<f64> {
        let mut out = vec![0.0f64; ORACLE_CHANNELS as usize];
        let dir = camera.pixel_dir(x, y, width, height);
        *rays += 1;
        let Some(h) = self.bvh.intersect(camera.eye, dir, camera.near, f32::INFINITY) else {
            return out;
        };
        let hit = self.bvh.surface(&h, dir);
        let receiver = hit.position;
        let n = samples.len() as f64;
        let fixed = [self.albedo(&hit), receiver, hit.facing_normals(dir).0];
        for (j, v) in fixed.iter().enumerate() {
            for c in 0..3 {
                out[3 + 3 * j + c] = v[c] as f64 * n;
            }
        }
        let tolerance = crate::LayerSettings::default().depth_tolerance;
        let mut layer_rays = 0;
        // summed as `gi_pixel_sum` sums, so that the total is its indirect light bit for bit
        let mut total = Vec3::ZERO;
        self.gi_pixel_paths(camera, x, y, width, height, &s.gi, samples, rays, |_, i, bounce| {
            total += i;
            let Some(p) = bounce else {
                return;
            };
            let layer = screen_layer(
                self,
                camera,
                (width, height),
                s.min_separation,
                tolerance,
                2,
                p,
                &mut layer_rays,
            );
            let near = (p - receiver).length() <= s.radius;
            let sh = strata_scene::probes::sh9((p - receiver).normalize_or_zero());
            for (v, &(k, bounded)) in ORACLE_VARIANTS.iter().enumerate() {
                if layer.is_some_and(|j| j < k) && (!bounded || near) {
                    let o = HEAD + PER_VARIANT * v;
                    for c in 0..3 {
                        out[o + c] += i[c] as f64;
                    }
                    out[o + 3] += 1.0;
                    for (m, y) in sh.iter().enumerate() {
                        out[o + 4 + m] += *y as f64;
                    }
                }
            }
        });
        *rays += layer_rays;
        for c in 0..3 {
            out[c] = total[c] as f64;
        }
        out
    }
}
