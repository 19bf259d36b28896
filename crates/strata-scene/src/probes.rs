//! Irradiance light probes (the coarse, static fallback of DGB §3.2 / Fig. 9):
//! a regular 3D grid of probes, each holding irradiance as order-2 (9-term)
//! real spherical harmonics per colour channel. Baked by the CPU reference,
//! evaluated on the GPU and here with the same formulas.

use glam::Vec3;

pub use crate::oct::{oct_decode, oct_encode};

/// Cosine-lobe convolution of SH band l (Ramamoorthi & Hanrahan 2001): Â_0 = π,
/// Â_1 = 2π/3, Â_2 = π/4.
pub const COSINE_LOBE: [f32; 3] = [
    std::f32::consts::PI,
    2.0 * std::f32::consts::PI / 3.0,
    std::f32::consts::FRAC_PI_4,
];

/// The 9 real SH basis functions at unit direction `d` (order l = 0, 1, 2).
pub fn sh9(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        0.282_095,
        0.488_603 * y,
        0.488_603 * z,
        0.488_603 * x,
        1.092_548 * x * y,
        1.092_548 * y * z,
        0.315_392 * (3.0 * z * z - 1.0),
        1.092_548 * x * z,
        0.546_274 * (x * x - y * y),
    ]
}

/// The k-th of n nearly uniform unit directions (spherical Fibonacci).
pub fn fibonacci_sphere(k: u32, n: u32) -> Vec3 {
    let golden = 0.618_034_f32;
    let z = 1.0 - (2.0 * k as f32 + 1.0) / n as f32;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * ((k as f32 * golden).fract());
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// [`IrradianceProbes::openness_sh`] of a probe open in every direction (1 for every
/// normal: 1/Y_0 in band 0).
pub const OPEN_EVERYWHERE: [f32; 4] = [1.0 / 0.282_095, 0.0, 0.0, 0.0];

/// Directions [`IrradianceProbes::openness_sh`] projects over.
pub const OPENNESS_RAYS: u32 = 512;

/// The complementary error function, erfc(x) = 1 − erf(x), to 1.5·10⁻⁷ (Abramowitz &
/// Stegun 7.1.26, mirrored for x < 0).
pub fn erfc(x: f32) -> f32 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t * (0.254_829_6 + t * (-0.284_496_74 + t * (1.421_413_7 + t * (-1.453_152_1 + t * 1.061_405_4))));
    let r = poly * (-z * z).exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// The chance that a direction's first surface lies beyond `r`, for a distance map texel's
/// moments (mean, mean square): a normal distribution of that mean and variance, its
/// deviation at least 1 % of the mean.
pub fn open_fraction(r: f32, mean: f32, mean2: f32) -> f32 {
    let sigma = (mean2 - mean * mean).max(0.0).sqrt().max(0.01 * mean).max(1e-6);
    0.5 * erfc((r - mean) / (sigma * std::f32::consts::SQRT_2))
}

/// Band of coefficient i.
pub fn sh_band(i: usize) -> usize {
    match i {
        0 => 0,
        1..=3 => 1,
        _ => 2,
    }
}

/// A grid of irradiance probes over an axis-aligned box.
#[derive(Clone, Debug, PartialEq)]
pub struct IrradianceProbes {
    /// Position of probe (0, 0, 0).
    pub origin: Vec3,
    /// Distance between neighbouring probes per axis.
    pub spacing: Vec3,
    /// Probes per axis (each ≥ 1).
    pub dims: [u32; 3],
    /// Per probe (x fastest, then y, then z): irradiance SH coefficients
    /// E_i = Â_l · L_i, so E(n) = Σ_i E_i · Y_i(n).
    pub coeffs: Vec<[[f32; 3]; 9]>,
    /// Per probe: false when it lies inside geometry (most of its rays hit back
    /// faces); invalid probes get no weight in the interpolation.
    pub valid: Vec<bool>,
    /// Per probe (empty: no visibility test): the mean and mean square of the
    /// distance to the first surface, over the directions of each texel of a
    /// [`DEPTH_OCT`]² octahedral map ([`oct_encode`]). A receiver farther from the
    /// probe than that surface is likely hidden from it ([`chebyshev_visibility`]).
    pub depth: Vec<[[f32; 2]; DEPTH_TEXELS]>,
    /// Per probe (empty: none): how far the bake moved it off its grid point, away from
    /// a surface it sat on or next to (probe relocation). The trilinear weights keep
    /// the grid points; the facing weight, the visibility test and the bake use the
    /// moved position ([`Self::position`]).
    pub offsets: Vec<[f32; 3]>,
}

/// The texel of an `n`×`n` octahedral map that a bilinear lookup one texel beyond the
/// border (x or y in −1..=n) reads: the square's edges fold onto themselves (texel (n, j)
/// lies beside (n − 1, n − 1 − j) on the sphere), and its four corners are one direction,
/// so a texel diagonally beyond a corner is the opposite corner (`oct_wrap_texel` in
/// `common/probes.wgsl`). Clamping to the edge instead joins directions that are far
/// apart on the sphere and cuts the distance maps along the folds.
pub fn oct_wrap_texel(x: i32, y: i32, n: i32) -> (usize, usize) {
    let (out_x, out_y) = (!(0..n).contains(&x), !(0..n).contains(&y));
    let (x, y) = match (out_x, out_y) {
        (true, true) => (if x < 0 { n - 1 } else { 0 }, if y < 0 { n - 1 } else { 0 }),
        (true, false) => (x.clamp(0, n - 1), n - 1 - y),
        (false, true) => (n - 1 - x, y.clamp(0, n - 1)),
        (false, false) => (x, y),
    };
    (x as usize, y as usize)
}

/// Texels per side of a probe's octahedral distance map.
pub const DEPTH_OCT: usize = 16;
/// Texels of a probe's distance map.
pub const DEPTH_TEXELS: usize = DEPTH_OCT * DEPTH_OCT;

/// Receivers are moved this fraction of the smallest probe spacing along their
/// normal before the visibility test, so that a surface is not hidden from a probe
/// by itself ([`IrradianceProbes::visibility_bias`]; compose.wgsl gets it as `spacing.w`).
pub const VISIBILITY_BIAS: f32 = 0.1;

/// … and this fraction of the smallest spacing towards the viewer
/// ([`IrradianceProbes::view_bias`]; `origin.w` in the shaders). The segment from a
/// visible point to the eye is free space, so the moved point stays on the receiver's
/// side of every wall, while a probe beyond a thin wall now sees it farther behind
/// that wall's outer corner: the distance-map texels there straddle the wall and the
/// sky beyond, and their variance passed a receiver right in the corner
/// (DDGI's view bias, Majercik et al. 2021; `docs/radiosity.md` § "View bias").
pub const VIEW_BIAS: f32 = 0.4;

/// Chebyshev's bound on the chance that a receiver at distance `dist` from a probe
/// is visible from it, given the mean `mean` and mean square `mean2` of the
/// distance to the probe's first surface in that direction: 1 in front of the
/// surface, var / (var + (dist − mean)²) behind it, cubed to sharpen the cut and
/// floored at [`VISIBILITY_FLOOR`] (`chebyshev_visibility` in compose.wgsl).
pub fn chebyshev_visibility(dist: f32, mean: f32, mean2: f32) -> f32 {
    if dist <= mean {
        return 1.0;
    }
    let var = (mean2 - mean * mean).max(1e-4 * mean * mean + 1e-8);
    let t = dist - mean;
    let p = var / (var + t * t);
    (p * p * p).max(VISIBILITY_FLOOR)
}

/// What a probe behind a surface still counts (0 would leave a receiver that every
/// probe's test rejects with no weight).
pub const VISIBILITY_FLOOR: f32 = 0.002;

/// The smallest of a grid's `spacing` over the axes with more than one probe (`dims`);
/// `None` for a single probe.
pub fn min_spacing(spacing: Vec3, dims: [u32; 3]) -> Option<f32> {
    (0..3)
        .filter(|&i| dims[i] > 1)
        .map(|i| spacing[i])
        .min_by(f32::total_cmp)
}

impl IrradianceProbes {
    /// Probe positions of a grid spanning `lo`..`hi` with `dims` probes per axis.
    pub fn grid(lo: Vec3, hi: Vec3, dims: [u32; 3]) -> Self {
        let d = Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32);
        let spacing = ((hi - lo) / (d - 1.0).max(Vec3::ONE)).max(Vec3::splat(1e-6));
        Self {
            origin: lo,
            spacing,
            dims,
            coeffs: vec![[[0.0; 3]; 9]; (dims[0] * dims[1] * dims[2]) as usize],
            valid: vec![true; (dims[0] * dims[1] * dims[2]) as usize],
            depth: Vec::new(),
            offsets: Vec::new(),
        }
    }

    pub fn count(&self) -> usize {
        self.coeffs.len()
    }

    /// Position of probe `index`: its grid point plus its relocation offset.
    pub fn position(&self, index: usize) -> Vec3 {
        self.grid_position(index) + self.offsets.get(index).map_or(Vec3::ZERO, |o| Vec3::from(*o))
    }

    /// Grid point of probe `index`.
    pub fn grid_position(&self, index: usize) -> Vec3 {
        let [dx, dy, _] = self.dims;
        let i = index as u32;
        let (x, y, z) = (i % dx, (i / dx) % dy, i / (dx * dy));
        self.origin + self.spacing * Vec3::new(x as f32, y as f32, z as f32)
    }

    /// Irradiance of one probe for normal `n`: Σ E_i Y_i(n), clamped at 0.
    pub fn probe_irradiance(&self, index: usize, n: Vec3) -> Vec3 {
        let y = sh9(n);
        let c = &self.coeffs[index];
        let mut e = Vec3::ZERO;
        for i in 0..9 {
            e += Vec3::from(c[i]) * y[i];
        }
        e.max(Vec3::ZERO)
    }

    /// The distance map of probe `index` at direction `d`: (mean, mean square),
    /// bilinear between texel centres (clamped at the map's border).
    pub fn depth_moments(&self, index: usize, d: Vec3) -> [f32; 2] {
        let map = &self.depth[index];
        let st = oct_encode(d) * DEPTH_OCT as f32 - 0.5;
        let base = st.floor();
        let f = st - base;
        let mut m = [0.0f32; 2];
        for k in 0..4 {
            let (ox, oy) = (k & 1, k >> 1);
            let w = if ox == 1 { f.x } else { 1.0 - f.x } * if oy == 1 { f.y } else { 1.0 - f.y };
            let (x, y) = oct_wrap_texel(base.x as i32 + ox, base.y as i32 + oy, DEPTH_OCT as i32);
            let t = map[y * DEPTH_OCT + x];
            m[0] += w * t[0];
            m[1] += w * t[1];
        }
        m
    }

    /// How far a receiver moves along its normal before the visibility test:
    /// [`VISIBILITY_BIAS`] × the smallest spacing between probes (over the axes with more
    /// than one probe; a single probe: 0).
    pub fn visibility_bias(&self) -> f32 {
        VISIBILITY_BIAS * self.min_spacing()
    }

    /// How far a receiver moves towards the viewer before the visibility test:
    /// [`VIEW_BIAS`] × the smallest spacing between probes.
    pub fn view_bias(&self) -> f32 {
        VIEW_BIAS * self.min_spacing()
    }

    /// The smallest spacing between probes over the axes with more than one (a single
    /// probe: 0).
    fn min_spacing(&self) -> f32 {
        min_spacing(self.spacing, self.dims).unwrap_or(0.0)
    }

    /// How visible a receiver at `p` (normal `n`, unit direction `view` towards the
    /// viewer, or zero for none) is from probe `index`: 1 without distance maps, else
    /// [`chebyshev_visibility`] of the receiver moved by [`Self::visibility_bias`] along
    /// `n` and [`Self::view_bias`] along `view`.
    pub fn visibility(&self, index: usize, p: Vec3, n: Vec3, view: Vec3) -> f32 {
        if self.depth.is_empty() {
            return 1.0;
        }
        let x = p + n * self.visibility_bias() + view * self.view_bias();
        let d = x - self.position(index);
        let dist = d.length();
        if dist <= 1e-6 {
            return 1.0;
        }
        let [mean, mean2] = self.depth_moments(index, d / dist);
        chebyshev_visibility(dist, mean, mean2)
    }

    /// Irradiance at `p` for normal `n`: trilinear blend of the valid ones of
    /// the 8 surrounding probes (positions clamped to the grid), each weight times
    /// [`facing_weight`] and [`Self::visibility`] (seen along `view`, as there),
    /// renormalised; all 8 when none is valid.
    pub fn irradiance(&self, p: Vec3, n: Vec3, view: Vec3) -> Vec3 {
        self.corner_weights(p, n, view)
            .iter()
            .map(|&(index, w)| self.probe_irradiance(index, n) * w)
            .sum()
    }

    /// The 8 probes around p and their normalised blend weights for a receiver at p
    /// with normal n, as [`Self::irradiance`] blends them (`probe_corners` and
    /// `probe_weights` in `common/probes.wgsl`).
    pub fn corner_weights(&self, p: Vec3, n: Vec3, view: Vec3) -> [(usize, f32); 8] {
        let g = ((p - self.origin) / self.spacing).max(Vec3::ZERO);
        let max = Vec3::new(
            (self.dims[0] - 1) as f32,
            (self.dims[1] - 1) as f32,
            (self.dims[2] - 1) as f32,
        );
        let g = g.min(max);
        let i0 = g.floor();
        let t = g - i0;
        let mut out = [(0usize, 0.0f32); 8];
        let (mut sum, mut sum_all) = (0.0f32, 0.0f32);
        for (corner, slot) in out.iter_mut().enumerate() {
            let o = Vec3::new(
                (corner & 1) as f32,
                ((corner >> 1) & 1) as f32,
                ((corner >> 2) & 1) as f32,
            );
            let c = (i0 + o).min(max);
            let w = (if o.x > 0.0 { t.x } else { 1.0 - t.x })
                * (if o.y > 0.0 { t.y } else { 1.0 - t.y })
                * (if o.z > 0.0 { t.z } else { 1.0 - t.z });
            let index = (c.x as u32 + self.dims[0] * (c.y as u32 + self.dims[1] * c.z as u32)) as usize;
            let w = w * facing_weight(self.position(index) - p, n) * self.visibility(index, p, n, view);
            sum_all += w;
            if self.valid[index] {
                sum += w;
            }
            *slot = (index, w);
        }
        for (index, w) in &mut out {
            *w = if sum > 1e-6 {
                if self.valid[*index] {
                    *w / sum
                } else {
                    0.0
                }
            } else {
                *w / sum_all.max(1e-6)
            };
        }
        out
    }

    /// Probe `index`'s openness within radius `r` as order-1 SH (Y_0..Y_3), convolved with
    /// the clamped cosine and divided by π: [`Self::openness`] for a normal n is the
    /// cosine-weighted share of the hemisphere around n whose first surface (distance map,
    /// [`open_fraction`]) lies beyond r — the ambient visibility that the probe's baked
    /// irradiance already holds. 1 for every n without distance maps.
    pub fn openness_sh(&self, index: usize, r: f32) -> [f32; 4] {
        if self.depth.is_empty() {
            return OPEN_EVERYWHERE;
        }
        let mut o = [0.0f32; 4];
        for k in 0..OPENNESS_RAYS {
            let d = fibonacci_sphere(k, OPENNESS_RAYS);
            // the texel holding d (a bilinear lookup would blur each surface's edge over
            // a band of texels, about a fifth of a hemisphere at 16×16)
            let st = (oct_encode(d) * DEPTH_OCT as f32).floor();
            let (x, y) = (
                st.x.clamp(0.0, DEPTH_OCT as f32 - 1.0),
                st.y.clamp(0.0, DEPTH_OCT as f32 - 1.0),
            );
            let [mean, mean2] = self.depth[index][y as usize * DEPTH_OCT + x as usize];
            let v = open_fraction(r, mean, mean2);
            for (oi, yi) in o.iter_mut().zip(sh9(d)) {
                *oi += v * yi;
            }
        }
        let dw = 4.0 * std::f32::consts::PI / OPENNESS_RAYS as f32;
        // Â_l / π: 1 for band 0, 2/3 for band 1
        let mut out = [0.0f32; 4];
        for (i, (out, oi)) in out.iter_mut().zip(o).enumerate() {
            *out = oi * dw * COSINE_LOBE[sh_band(i)] / std::f32::consts::PI;
        }
        out
    }

    /// Probe `index`'s openness for normal `n` from its [`Self::openness_sh`] coefficients
    /// `v`, clamped to [0, 1] (`probe_openness` in `common/probes.wgsl`).
    pub fn openness(v: &[f32; 4], n: Vec3) -> f32 {
        let y = sh9(n);
        (0..4).map(|i| v[i] * y[i]).sum::<f32>().clamp(0.0, 1.0)
    }

    /// The probes' openness at receiver p (normal n), blended with [`Self::irradiance`]'s
    /// weights; `v` = every probe's [`Self::openness_sh`].
    pub fn openness_at(&self, v: &[[f32; 4]], p: Vec3, n: Vec3, view: Vec3) -> f32 {
        self.corner_weights(p, n, view)
            .iter()
            .map(|&(index, w)| Self::openness(&v[index], n) * w)
            .sum()
    }

    /// The blended probes' incident radiance at p (receiver normal n) as order-2 SH
    /// coefficients: L_lm = E_lm / Â_l ([`COSINE_LOBE`]), so that the cosine-weighted
    /// hemisphere integral of [`sh_radiance`] (without its clamp) is
    /// [`Self::irradiance`] (`probe_radiance_sh` in `common/probes.wgsl`).
    pub fn radiance_sh(&self, p: Vec3, n: Vec3, view: Vec3) -> [Vec3; 9] {
        let mut l = [Vec3::ZERO; 9];
        for (index, w) in self.corner_weights(p, n, view) {
            for (i, li) in l.iter_mut().enumerate() {
                *li += Vec3::from(self.coeffs[index][i]) * w;
            }
        }
        for (i, li) in l.iter_mut().enumerate() {
            *li /= COSINE_LOBE[sh_band(i)];
        }
        l
    }
}

/// Radiance along unit direction `d` of order-2 SH radiance coefficients `l`, clamped
/// at 0 (order 2 rings below zero near strong lobes; `sh_radiance` in
/// `common/probes.wgsl`).
pub fn sh_radiance(l: &[Vec3; 9], d: Vec3) -> Vec3 {
    let y = sh9(d);
    l.iter().zip(y).map(|(li, yi)| *li * yi).sum::<Vec3>().max(Vec3::ZERO)
}

/// The facing weight's floor: what a probe straight behind the receiver still counts
/// (`FACING_FLOOR` in compose.wgsl; 0 would leave a receiver with every probe behind it
/// with no weight).
pub const FACING_FLOOR: f32 = 0.002;

/// How much a probe at offset `to_probe` from a receiver with normal `n` counts:
/// ((1 + cos)/2)² + [`FACING_FLOOR`], cos between `n` and the direction to the probe. A probe
/// behind the receiver's tangent plane sees the other side of its surface (through a
/// wall or a floor: light leaking) and gets almost no weight; one in front counts
/// fully. (The wrap-shading weight of irradiance-field probes; a probe at the
/// receiver itself counts as one in its plane.)
pub fn facing_weight(to_probe: Vec3, n: Vec3) -> f32 {
    let len = to_probe.length();
    if len <= 1e-4 {
        return 0.25 + FACING_FLOOR;
    }
    let f = 0.5 * (to_probe.dot(n) / len + 1.0);
    f * f + FACING_FLOOR
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erfc_matches_tabulated_values() {
        for (x, want) in [
            (0.0f32, 1.0f32),
            (0.5, 0.479_500_1),
            (1.0, 0.157_299_2),
            (2.0, 0.004_677_7),
            (-1.0, 1.842_700_8),
        ] {
            assert!((erfc(x) - want).abs() < 2e-6, "erfc({x}) = {} vs {want}", erfc(x));
        }
        // the normal model: half the mass beyond the mean, almost none 4σ short of it
        assert!((open_fraction(1.0, 1.0, 1.01) - 0.5).abs() < 1e-6);
        assert!(open_fraction(1.4, 1.0, 1.01) < 1e-4);
        assert!(open_fraction(0.6, 1.0, 1.01) > 1.0 - 1e-4);
    }

    /// A probe whose lower half-space (z < 0) has surfaces 5 cm away and whose upper half
    /// is open: its openness within r = 0.5 is exactly the cosine-weighted share of the
    /// hemisphere above z = 0 (order-1 SH holds a half-space's cosine convolution exactly):
    /// 1 facing up, 0 facing down, ½ sideways; open everywhere without distance maps.
    #[test]
    fn openness_of_a_half_space_is_its_cosine_weighted_share() {
        let mut p = IrradianceProbes::grid(Vec3::ZERO, Vec3::ONE, [1, 1, 1]);
        let v = p.openness_sh(0, 0.5);
        for n in [Vec3::X, -Vec3::Z, Vec3::new(1.0, 2.0, -3.0).normalize()] {
            assert!((IrradianceProbes::openness(&v, n) - 1.0).abs() < 1e-5);
        }
        let mut map = [[0.0f32; 2]; DEPTH_TEXELS];
        for (t, m) in map.iter_mut().enumerate() {
            let uv = glam::Vec2::new((t % DEPTH_OCT) as f32 + 0.5, (t / DEPTH_OCT) as f32 + 0.5) / DEPTH_OCT as f32;
            let d = if oct_decode(uv).z < 0.0 { 0.05 } else { 50.0 };
            *m = [d, d * d];
        }
        p.depth = vec![map];
        let v = p.openness_sh(0, 0.5);
        for (n, want) in [(Vec3::Z, 1.0), (-Vec3::Z, 0.0), (Vec3::X, 0.5), (-Vec3::Y, 0.5)] {
            let got = IrradianceProbes::openness(&v, n);
            // texels straddling the plane z = 0 count as near or far whole
            assert!((got - want).abs() < 0.06, "n = {n}: openness {got} vs {want}");
        }
        // beyond the near surfaces' distance nothing is open below
        let near = p.openness_sh(0, 0.01);
        assert!((IrradianceProbes::openness(&near, -Vec3::Z) - 1.0).abs() < 0.02);
    }

    /// A probe of uniform radiance L gives irradiance πL for every normal.
    #[test]
    fn uniform_radiance_gives_pi_l() {
        let mut p = IrradianceProbes::grid(Vec3::ZERO, Vec3::ONE, [1, 1, 1]);
        // L_00 = L · √(4π) (projection of a constant), E_00 = π L_00
        let l = 0.7;
        p.coeffs[0][0] = [COSINE_LOBE[0] * l * (4.0 * std::f32::consts::PI).sqrt(); 3];
        for n in [Vec3::X, Vec3::Y, -Vec3::Z, Vec3::new(1.0, 1.0, 0.0).normalize()] {
            let e = p.irradiance(Vec3::splat(0.3), n, Vec3::ZERO);
            assert!((e.x - std::f32::consts::PI * l).abs() < 1e-3, "{e}");
        }
    }

    #[test]
    fn trilinear_blend_between_probes() {
        let mut p = IrradianceProbes::grid(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), [2, 1, 1]);
        p.coeffs[0][0] = [1.0; 3];
        p.coeffs[1][0] = [3.0; 3];
        let y0 = sh9(Vec3::Y)[0];
        assert!((p.irradiance(Vec3::new(0.5, 0.0, 0.0), Vec3::Y, Vec3::ZERO).x - 1.5 * y0).abs() < 1e-5);
        assert!((p.irradiance(Vec3::new(9.0, 0.0, 0.0), Vec3::Y, Vec3::ZERO).x - 3.0 * y0).abs() < 1e-5);
        assert_eq!(p.position(1), Vec3::new(2.0, 0.0, 0.0));
        // an invalid probe gets no weight
        p.valid[1] = false;
        assert!((p.irradiance(Vec3::new(1.5, 0.0, 0.0), Vec3::Y, Vec3::ZERO).x - y0).abs() < 1e-5);
        // a receiver facing probe 1 (normal +x, probe 0 behind it): weights
        // 0.25 · floor and 0.75 · (1 + floor) at x = 1.5
        p.valid[1] = true;
        let e = p.irradiance(Vec3::new(1.5, 0.0, 0.0), Vec3::X, Vec3::ZERO).x / sh9(Vec3::X)[0];
        let (w0, w1) = (0.25 * FACING_FLOOR, 0.75 * (1.0 + FACING_FLOOR));
        assert!((e - (w0 * 1.0 + w1 * 3.0) / (w0 + w1)).abs() < 1e-4, "{e}");
        // facing away from probe 1: probe 0 wins
        let e = p.irradiance(Vec3::new(1.5, 0.0, 0.0), -Vec3::X, Vec3::ZERO).x / sh9(-Vec3::X)[0];
        let (w0, w1) = (0.25 * (1.0 + FACING_FLOOR), 0.75 * FACING_FLOOR);
        assert!((e - (w0 * 1.0 + w1 * 3.0) / (w0 + w1)).abs() < 1e-4, "{e}");
    }

    /// The probes' SH radiance integrates back to their irradiance: ∫ L(ω) max(ω·n, 0) dω
    /// over the sphere (midpoint quadrature, no clamp active) equals
    /// [`IrradianceProbes::irradiance`] for several normals of a direction-dependent probe.
    #[test]
    fn radiance_sh_integrates_to_the_irradiance() {
        let mut p = IrradianceProbes::grid(Vec3::ZERO, Vec3::ONE, [1, 1, 1]);
        p.coeffs[0] = [
            [3.0, 2.5, 2.0],
            [0.4, -0.2, 0.1],
            [-0.3, 0.5, 0.2],
            [0.2, 0.1, -0.4],
            [0.1, -0.05, 0.08],
            [-0.1, 0.06, 0.02],
            [0.05, 0.1, -0.07],
            [0.09, -0.02, 0.04],
            [-0.06, 0.03, 0.1],
        ];
        for n in [Vec3::Y, Vec3::X, Vec3::new(0.3, -0.5, 0.8).normalize()] {
            let l = p.radiance_sh(Vec3::splat(0.5), n, Vec3::ZERO);
            let (nt, np) = (400, 800);
            let mut e = Vec3::ZERO;
            for i in 0..nt {
                let theta = (i as f32 + 0.5) / nt as f32 * std::f32::consts::PI;
                for j in 0..np {
                    let phi = (j as f32 + 0.5) / np as f32 * 2.0 * std::f32::consts::PI;
                    let d = Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                    let r = sh_radiance(&l, d);
                    assert!(r.min_element() > 0.0, "the clamp is active at {d}: {r}");
                    let dw =
                        theta.sin() * (std::f32::consts::PI / nt as f32) * (2.0 * std::f32::consts::PI / np as f32);
                    e += r * d.dot(n).max(0.0) * dw;
                }
            }
            let want = p.irradiance(Vec3::splat(0.5), n, Vec3::ZERO);
            assert!(
                (e - want).abs().max_element() < 2e-3 * want.max_element(),
                "n {n}: {e} vs {want}"
            );
        }
    }

    /// Bilinear lookups in the distance map are continuous across the octahedral folds:
    /// the points just inside the square's edge at (1 − ε, v) and (1 − ε, 1 − v) (and
    /// the other three edges) are the same direction to within ε on the sphere, so their
    /// moments agree for an arbitrary map (with the edge clamped they would differ by
    /// whole texels' values).
    #[test]
    fn distance_map_lookups_are_continuous_across_the_folds() {
        let mut p = IrradianceProbes::grid(Vec3::ZERO, Vec3::ONE, [1, 1, 1]);
        p.depth = vec![std::array::from_fn(|t| {
            let v = ((t * 37 + 11) % 23) as f32;
            [v, v * v]
        })];
        let e = 1e-4f32;
        let mut worst = 0.0f32;
        for k in 1..20 {
            let v = k as f32 / 20.0;
            for (a, b) in [
                (glam::Vec2::new(1.0 - e, v), glam::Vec2::new(1.0 - e, 1.0 - v)),
                (glam::Vec2::new(e, v), glam::Vec2::new(e, 1.0 - v)),
                (glam::Vec2::new(v, 1.0 - e), glam::Vec2::new(1.0 - v, 1.0 - e)),
                (glam::Vec2::new(v, e), glam::Vec2::new(1.0 - v, e)),
            ] {
                let (da, db) = (oct_decode(a), oct_decode(b));
                assert!(
                    da.angle_between(db) < 1e-2,
                    "{a} and {b} are not neighbours: {da} vs {db}"
                );
                let (ma, mb) = (p.depth_moments(0, da), p.depth_moments(0, db));
                worst = worst.max((ma[0] - mb[0]).abs());
            }
        }
        // the two lookups lie 2e apart in uv, 2e·DEPTH_OCT texels: bilinear over texel
        // values 0..22 moves at most that × 22; the bound allows twice that (a clamped
        // lookup jumps by whole texel values)
        let bound = 2.0 * (2.0 * e * DEPTH_OCT as f32) * 22.0;
        assert!(
            worst < bound,
            "the lookup jumps by {worst} (> {bound}) across a fold (texel values 0..22)"
        );
    }
}
