//! Ambient occlusion oracles.
//!
//! Both estimators start from the primary hit X through each pixel centre, with
//! normal n = the interpolated shading normal flipped to face the viewer. Pixels
//! whose primary ray hits nothing get ambient visibility 1.
//!
//! - **Binary visibility** ([`Reference::ao_binary`]): `AV(X) = 1 − H/N`, where
//!   H of the N cosine-weighted hemisphere rays around n hit any surface within
//!   `radius` of X. Ray origins are offset by [`Reference::epsilon`] along the
//!   viewer-facing geometric normal. Directions are the R2 low-discrepancy
//!   sequence with a per-pixel Cranley–Patterson rotation.
//! - **DGB obscurance** ([`Reference::ao_obscurance`]): DGB Eq. 1–2 evaluated on
//!   the true geometry with *all* layers (see [`ObscuranceSettings`]).

use glam::Vec3;
use strata_scene::{Camera, ImageBuf};

use crate::bundle::BUNDLE;
use crate::sampling::{basis, cosine_hemisphere, cosine_hemisphere_r2_8, hash, pixel_offset, r2};
use crate::Reference;

/// Fewest samples of one pixel that [`Reference::ao_binary_unoccluded`]
/// traces in bundles: with fewer, a bundle's directions spread too far for its
/// shared box tests to pay off (Sponza AO, CPU seconds: equal at 16 samples,
/// −23 % at 32, 2026-11-24).
const BUNDLED_MIN: usize = 16;
/// Samples sorted into bundles at a time.
const BUNDLED_CHUNK: usize = 1024;

/// Settings of the binary ambient-visibility oracle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AoBinarySettings {
    /// World-space occlusion radius: only hits closer than this occlude.
    pub radius: f32,
    /// Hemisphere rays per pixel.
    pub spp: u32,
    /// Seed of the per-pixel sample rotations.
    pub seed: u64,
}

impl AoBinarySettings {
    pub fn new(radius: f32) -> Self {
        Self {
            radius,
            ..Self::default()
        }
    }
}

impl Default for AoBinarySettings {
    /// radius 1, 256 rays per pixel, seed 0.
    fn default() -> Self {
        Self {
            radius: 1.0,
            spp: 256,
            seed: 0,
        }
    }
}

/// Radial distribution of the obscurance sample disk.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DiskSampling {
    /// Uniform over the disk area (radius `r·√u`).
    #[default]
    UniformArea,
    /// Radius `r·u`, uniform in u: the density of the paper's spiral taps
    /// (`h_i = r_p·κ_i`, κ_i = (i + 0.5)/N, DGB §3.4), which concentrates samples
    /// towards the centre. Use it to compare with the GPU's spiral term by term.
    SpiralRadius,
}

/// Settings of the DGB obscurance oracle (Eq. 1–2).
///
/// For pixel X at camera-space depth z, each of the N samples picks a point P
/// in the disk of radius `radius` centred on X in the camera plane at depth z
/// (offsets along camera right/up — the world-space disk whose projection is
/// the GPU's screen-space sample disk), casts the camera ray from the eye
/// through P and collects **every** surface Y_j along it (all layers, back
/// faces included). Then
///
/// - `O(X, Y) = (1 − v·v/r²) · max((v·n − β)/√(v·v + ε), 0)` for |v| < r, else 0,
///   with v = Y − X;
/// - `A_i = max(0, max_j O(X, Y_j))`;
/// - `AV = max(0, 1 − √(π/N · Σ A_i))`.
///
/// An unoccluded plane gives exactly 1 (v·n = 0 on the plane and β > 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObscuranceSettings {
    /// Sample radius r (world units).
    pub radius: f32,
    /// Bias β (world units), subtracted from v·n. Default `0.01·r`.
    pub beta: f32,
    /// ε (world units squared) in the denominator. Default `0.01·r²`.
    pub epsilon: f32,
    /// Samples N per pixel.
    pub spp: u32,
    pub seed: u64,
    pub disk: DiskSampling,
}

impl ObscuranceSettings {
    /// Defaults scaled to `radius`: β = 0.01·r, ε = 0.01·r², 256 samples.
    pub fn new(radius: f32) -> Self {
        Self {
            radius,
            beta: 0.01 * radius,
            epsilon: 0.01 * radius * radius,
            spp: 256,
            seed: 0,
            disk: DiskSampling::UniformArea,
        }
    }

    /// DGB Eq. 2: the obscurance at X (unit normal `n`) due to a surface point at
    /// offset `v = Y − X`.
    pub fn occlusion(&self, v: Vec3, n: Vec3) -> f32 {
        let vv = v.dot(v);
        let r2 = self.radius * self.radius;
        if !(vv < r2) {
            return 0.0;
        }
        (1.0 - vv / r2) * ((v.dot(n) - self.beta) / (vv + self.epsilon).sqrt()).max(0.0)
    }
}

impl Default for ObscuranceSettings {
    fn default() -> Self {
        Self::new(1.0)
    }
}

impl Reference<'_> {
    /// Binary ambient visibility per pixel (1 channel, in [0, 1]; background = 1).
    pub fn ao_binary(&self, camera: &Camera, width: u32, height: u32, settings: &AoBinarySettings) -> ImageBuf {
        let values = self.for_each_pixel("AO binary", width, height, |x, y, rays| {
            let dir = camera.pixel_dir(x, y, width, height);
            *rays += 1;
            let Some(h) = self.bvh.intersect(camera.eye, dir, camera.near, f32::INFINITY) else {
                return 1.0;
            };
            let s = self.bvh.surface(&h, dir);
            let (n, ng) = s.facing_normals(dir);
            *rays += settings.spp as u64;
            self.ao_binary_at(s.position, n, ng, settings, pixel_key(settings.seed, x, y, width))
        });
        ImageBuf {
            width,
            height,
            channels: 1,
            data: values,
        }
    }

    /// Binary ambient visibility at a surface point: `p`, unit shading normal `n`
    /// (sampling hemisphere) and unit geometric normal `ng` (ray offset), both on
    /// the side being evaluated. `key` selects the sample rotation. Returns 1
    /// when `spp` is 0.
    pub fn ao_binary_at(&self, p: Vec3, n: Vec3, ng: Vec3, settings: &AoBinarySettings, key: u64) -> f32 {
        if settings.spp == 0 {
            return 1.0;
        }
        let unoccluded = self.ao_binary_unoccluded(p, n, ng, settings.radius, key, 0..settings.spp);
        1.0 - (settings.spp - unoccluded) as f32 / settings.spp as f32
    }

    /// How many of the hemisphere rays with sample indices in `samples` (R2
    /// sequence rotated by `key`) leave `p` without a hit within `radius`: the
    /// partial sums [`crate::converge`] accumulates sample range by range.
    pub(crate) fn ao_binary_unoccluded(
        &self,
        p: Vec3,
        n: Vec3,
        ng: Vec3,
        radius: f32,
        key: u64,
        samples: std::ops::Range<u32>,
    ) -> u32 {
        let origin = p + ng * self.epsilon;
        let offset = pixel_offset(key);
        if samples.len() < BUNDLED_MIN {
            let mut free = 0u32;
            for i in samples {
                let d = cosine_hemisphere(n, r2(i, offset));
                if !self.bvh.occluded(origin, d, 0.0, radius) {
                    free += 1;
                }
            }
            return free;
        }
        let frame = basis(n);
        let mut free = 0u32;
        let mut start = samples.start;
        while start < samples.end {
            let end = samples.end.min(start.saturating_add(BUNDLED_CHUNK as u32));
            free += self.unoccluded_bundled(origin, n, frame, offset, radius, start..end);
            start = end;
        }
        free
    }

    /// [`Self::ao_binary_unoccluded`] for at most [`BUNDLED_CHUNK`] samples,
    /// traced in bundles of 8 rays ([`crate::bundle`]): the directions are
    /// counting-sorted by octant, then by a cell of the sample square (rings
    /// of equal `u₀`, i.e. equal projected solid angle, serpentine sectors of
    /// `u₁`), so the 8 rays of a bundle span a narrow cone. The count is the
    /// same as ray by ray: every ray is still traced with its own exact
    /// answer; only the order changes.
    fn unoccluded_bundled(
        &self,
        origin: Vec3,
        n: Vec3,
        frame: (Vec3, Vec3),
        offset: [f32; 2],
        radius: f32,
        samples: std::ops::Range<u32>,
    ) -> u32 {
        let count = samples.len();
        debug_assert!(count <= BUNDLED_CHUNK);
        let cells = (count / BUNDLE).max(1);
        let rings = ((cells as f32 / 2.0).sqrt().round() as usize).max(1);
        let sectors = (cells / rings).max(1);
        let per_octant = rings * sectors;
        // Keys: octant * per_octant + cell; the last key (8 * per_octant)
        // holds directions with a zero component, traced one by one.
        let irregular = 8 * per_octant;
        let mut dirs = [Vec3::ZERO; BUNDLED_CHUNK];
        let mut keys = [0u16; BUNDLED_CHUNK];
        let mut starts = [0u16; 8 * BUNDLED_CHUNK / BUNDLE + 2];
        for block in (0..count).step_by(8) {
            let (d8, u8) = cosine_hemisphere_r2_8(n, frame, offset, samples.start + block as u32);
            for (l, (d, u)) in d8.into_iter().zip(u8).take(count - block).enumerate() {
                let j = block + l;
                dirs[j] = d;
                keys[j] = if d.cmpne(Vec3::ZERO).all() {
                    let octant = d.cmplt(Vec3::ZERO).bitmask() as usize;
                    let ring = ((u[0] * rings as f32) as usize).min(rings - 1);
                    let mut sector = ((u[1] * sectors as f32) as usize).min(sectors - 1);
                    if ring % 2 == 1 {
                        sector = sectors - 1 - sector;
                    }
                    (octant * per_octant + ring * sectors + sector) as u16
                } else {
                    irregular as u16
                };
                starts[keys[j] as usize + 1] += 1;
            }
        }
        for k in 1..=irregular + 1 {
            starts[k] += starts[k - 1];
        }
        let mut sorted = [Vec3::ZERO; BUNDLED_CHUNK];
        let mut fill = starts;
        for j in 0..count {
            let k = keys[j] as usize;
            sorted[fill[k] as usize] = dirs[j];
            fill[k] += 1;
        }
        let mut occluded = 0u32;
        for octant in 0..8 {
            let (a, b) = (
                starts[octant * per_octant] as usize,
                starts[(octant + 1) * per_octant] as usize,
            );
            for bundle in sorted[a..b].chunks(BUNDLE) {
                occluded += self.bvh.occluded_bundle(origin, bundle, 0.0, radius).count_ones();
            }
        }
        for &d in &sorted[starts[irregular] as usize..count] {
            occluded += self.bvh.occluded(origin, d, 0.0, radius) as u32;
        }
        count as u32 - occluded
    }

    /// DGB obscurance ambient visibility (Eq. 1–2 over all layers) per pixel
    /// (1 channel, in [0, 1]; background = 1). See [`ObscuranceSettings`].
    pub fn ao_obscurance(&self, camera: &Camera, width: u32, height: u32, settings: &ObscuranceSettings) -> ImageBuf {
        let values = self.for_each_pixel("AO DGB", width, height, |x, y, rays| {
            let dir = camera.pixel_dir(x, y, width, height);
            *rays += 1;
            let Some(h) = self.bvh.intersect(camera.eye, dir, camera.near, f32::INFINITY) else {
                return 1.0;
            };
            let s = self.bvh.surface(&h, dir);
            let (n, _) = s.facing_normals(dir);
            *rays += settings.spp as u64;
            self.ao_obscurance_at(camera, s.position, n, settings, pixel_key(settings.seed, x, y, width))
                .0
        });
        ImageBuf {
            width,
            height,
            channels: 1,
            data: values,
        }
    }

    /// DGB obscurance at point `x` with unit normal `n` seen from `camera`.
    /// Returns (AV, mean A_i) — the second value is `Σ A_i / N` before Eq. 1's
    /// square root, for term-by-term comparison. (1, 0) when `spp` is 0.
    pub fn ao_obscurance_at(
        &self,
        camera: &Camera,
        x: Vec3,
        n: Vec3,
        settings: &ObscuranceSettings,
        key: u64,
    ) -> (f32, f32) {
        if settings.spp == 0 {
            return (1.0, 0.0);
        }
        let sum = self.obscurance_sum(camera, x, n, settings, key, 0..settings.spp);
        let mean = (sum / settings.spp as f64) as f32;
        (obscurance_visibility(mean), mean)
    }

    /// Σ A_i over the samples with indices in `samples` (R2 sequence rotated by
    /// `key`): the partial sums behind [`Reference::ao_obscurance_at`].
    pub(crate) fn obscurance_sum(
        &self,
        camera: &Camera,
        x: Vec3,
        n: Vec3,
        settings: &ObscuranceSettings,
        key: u64,
        samples: std::ops::Range<u32>,
    ) -> f64 {
        let (right, up, _) = camera.basis();
        let z = camera.depth_of(x);
        let r = settings.radius;
        let offset = pixel_offset(key);
        let mut hits = Vec::new();
        let mut sum = 0.0f64;
        for i in samples {
            let [u, w] = r2(i, offset);
            let rho = match settings.disk {
                DiskSampling::UniformArea => r * u.sqrt(),
                DiskSampling::SpiralRadius => r * u,
            };
            let phi = std::f32::consts::TAU * w;
            let p = x + right * (rho * phi.cos()) + up * (rho * phi.sin());
            // Direction with unit forward component: t along it is camera-space depth.
            let dir = (p - camera.eye) / z;
            // |Y − X| ≥ |t − z|, so only depths in (z − r, z + r) can contribute.
            let tmin = camera.near.max(z - r);
            self.bvh.intersect_all(camera.eye, dir, tmin, z + r, &mut hits);
            let mut a = 0.0f32;
            for h in &hits {
                let y = camera.eye + dir * h.t;
                a = a.max(settings.occlusion(y - x, n));
            }
            sum += a as f64;
        }
        sum
    }
}

/// DGB Eq. 1: ambient visibility `max(0, 1 − √(π · mean A_i))` from the mean of
/// the per-sample obscurance terms.
pub fn obscurance_visibility(mean: f32) -> f32 {
    (1.0 - (std::f32::consts::PI * mean).sqrt()).max(0.0)
}

/// Per-pixel key for sample rotations.
pub(crate) fn pixel_key(seed: u64, x: u32, y: u32, width: u32) -> u64 {
    hash(&[seed, y as u64 * width as u64 + x as u64])
}
