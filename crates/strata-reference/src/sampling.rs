//! Deterministic random numbers and sample warps.
//!
//! Every estimator seeds its generator from `(seed, pixel, sample, stream)`
//! through a 64-bit hash, so results depend only on those inputs and never on
//! how rayon schedules rows onto threads.

use glam::Vec3;

/// SplitMix64 finaliser: a bijective 64-bit mixer with good avalanche.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Hashes a few integers into one 64-bit value (order-dependent).
#[inline]
pub fn hash(values: &[u64]) -> u64 {
    let mut h = 0x243f_6a88_85a3_08d3u64;
    for &v in values {
        h = mix64(h ^ v.wrapping_add(0x9e37_79b9_7f4a_7c15));
    }
    h
}

/// Converts the top 24 bits of `bits` to a float in [0, 1).
#[inline]
pub fn unit_f32(bits: u64) -> f32 {
    (bits >> 40) as f32 * (1.0 / 16_777_216.0)
}

/// Small, fast SplitMix64 generator for path tracing.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// A generator whose stream is a pure function of `key` (use [`hash`]).
    pub fn new(key: u64) -> Self {
        Self { state: mix64(key) }
    }

    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix64(self.state)
    }

    /// Uniform float in [0, 1).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        unit_f32(self.next_u64())
    }

    #[inline]
    pub fn next_2d(&mut self) -> [f32; 2] {
        [self.next_f32(), self.next_f32()]
    }
}

/// Sample `i` of the R2 low-discrepancy sequence (Roberts 2018), rotated by
/// `offset` (Cranley–Patterson rotation, toroidal shift in [0, 1)²).
#[inline]
pub fn r2(i: u32, offset: [f32; 2]) -> [f32; 2] {
    const A1: f64 = 0.754_877_666_246_692_8; // 1/g, g = plastic number
    const A2: f64 = 0.569_840_290_998_053_3; // 1/g²
    let i = i as f64;
    [
        fract_nonneg(0.5 + A1 * i + offset[0] as f64) as f32,
        fract_nonneg(0.5 + A2 * i + offset[1] as f64) as f32,
    ]
}

/// `x.fract()` for `0 ≤ x < 2⁶³`, bit for bit (the truncation is exact there),
/// without the `trunc` library call the x86-64 baseline makes for `fract`.
#[inline(always)]
fn fract_nonneg(x: f64) -> f64 {
    debug_assert!((0.0..9.2e18).contains(&x));
    x - (x as i64) as f64
}

/// Point `k` of the 4-D Kronecker low-discrepancy sequence α_j = φ₄^−(j+1)
/// (φ₄ the positive root of x⁵ = x + 1; Roberts' generalised golden ratio),
/// rotated by `offset` (Cranley–Patterson).
#[inline]
pub fn kronecker4(k: u32, offset: &[f64; 4]) -> [f32; 4] {
    const PHI4: f64 = 1.167_303_978_261_418_7;
    let mut out = [0.0f32; 4];
    let mut a = 1.0;
    for (j, o) in out.iter_mut().enumerate() {
        a /= PHI4;
        *o = (0.5 + a * k as f64 + offset[j]).fract() as f32;
    }
    out
}

/// Per-pixel Cranley–Patterson offset for [`r2`].
#[inline]
pub fn pixel_offset(key: u64) -> [f32; 2] {
    let h = mix64(key);
    [unit_f32(h), unit_f32(mix64(h))]
}

/// An orthonormal basis (t, b) completing unit vector `n` (Duff et al. 2017).
#[inline]
pub fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bt = Vec3::new(b, sign + n.y * n.y * a, -n.y);
    (t, bt)
}

/// Cosine-weighted direction on the hemisphere around unit `n` (pdf = cos θ / π),
/// by Malley's method: a uniform disk point lifted to the hemisphere.
#[inline]
pub fn cosine_hemisphere(n: Vec3, u: [f32; 2]) -> Vec3 {
    cosine_hemisphere_in(n, basis(n), u)
}

/// [`cosine_hemisphere`] with the basis `(t, b) = basis(n)` computed once by
/// the caller (the same bits).
#[inline]
pub fn cosine_hemisphere_in(n: Vec3, (t, b): (Vec3, Vec3), u: [f32; 2]) -> Vec3 {
    let r = u[0].sqrt();
    let phi = std::f32::consts::TAU * u[1];
    let (x, y) = (r * phi.cos(), r * phi.sin());
    let z = (1.0 - u[0]).max(0.0).sqrt();
    (t * x + b * y + n * z).normalize()
}

/// Eight consecutive samples `first..first + 8` of [`r2`] (rotated by
/// `offset`) mapped by [`cosine_hemisphere_in`]: the same bits lane by lane
/// (the same IEEE operations in the same order; square roots, divisions and
/// the arithmetic run over the 8 lanes at once, which the scalar form's
/// serial `sqrt → div` chain per sample cannot). Returns the directions and
/// the square samples.
#[inline]
pub fn cosine_hemisphere_r2_8(
    n: Vec3,
    (t, b): (Vec3, Vec3),
    offset: [f32; 2],
    first: u32,
) -> ([Vec3; 8], [[f32; 2]; 8]) {
    let mut u = [[0.0f32; 2]; 8];
    let (mut u0, mut cos, mut sin) = ([0.0f32; 8], [0.0f32; 8], [0.0f32; 8]);
    for l in 0..8 {
        u[l] = r2(first.wrapping_add(l as u32), offset);
        u0[l] = u[l][0];
        let phi = std::f32::consts::TAU * u[l][1];
        (cos[l], sin[l]) = (phi.cos(), phi.sin());
    }
    let (mut dx, mut dy, mut dz) = ([0.0f32; 8], [0.0f32; 8], [0.0f32; 8]);
    for l in 0..8 {
        let r = u0[l].sqrt();
        let (x, y) = (r * cos[l], r * sin[l]);
        let z = (1.0 - u0[l]).max(0.0).sqrt();
        // (t·x + b·y) + n·z, then glam's normalize: v · (1 / √((vx² + vy²) + vz²)).
        let v = [
            t.x * x + b.x * y + n.x * z,
            t.y * x + b.y * y + n.y * z,
            t.z * x + b.z * y + n.z * z,
        ];
        let inv = 1.0 / (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        (dx[l], dy[l], dz[l]) = (v[0] * inv, v[1] * inv, v[2] * inv);
    }
    (std::array::from_fn(|l| Vec3::new(dx[l], dy[l], dz[l])), u)
}

/// A GGX (Trowbridge-Reitz) microfacet normal sampled from the distribution
/// of normals visible from `v` (Heitz 2018, D_v(h) = G1(v) max(v·h, 0) D(h) / v_z),
/// in the local frame where the macro normal is +Z and `v.z > 0`; isotropic
/// roughness `alpha`. Dupuy & Benyoub 2023 ("Sampling Visible GGX Normals with
/// Spherical Caps"): stretch `v` to the α = 1 configuration, sample the
/// spherical cap of directions c with c_z ≥ −v_z uniformly, h_std = v_std + c,
/// then unstretch.
#[inline]
pub fn ggx_vndf_local(v: Vec3, alpha: f32, u: [f32; 2]) -> Vec3 {
    let vs = Vec3::new(v.x * alpha, v.y * alpha, v.z).normalize();
    let phi = std::f32::consts::TAU * u[0];
    let z = (1.0 - u[1]) * (1.0 + vs.z) - vs.z;
    let s = (1.0 - z * z).max(0.0).sqrt();
    let hs = Vec3::new(s * phi.cos(), s * phi.sin(), z) + vs;
    Vec3::new(hs.x * alpha, hs.y * alpha, hs.z.max(0.0)).normalize_or(Vec3::Z)
}

/// Uniform point on a triangle as barycentric weights (b1, b2) of vertices 1 and 2.
#[inline]
pub fn triangle_barycentrics(u: [f32; 2]) -> (f32, f32) {
    let s = u[0].sqrt();
    (u[1] * s, 1.0 - s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_samples_are_unit_and_above() {
        let n = Vec3::new(0.3, -0.8, 0.52).normalize();
        let mut rng = Rng::new(7);
        let mut mean_cos = 0.0;
        for _ in 0..20_000 {
            let d = cosine_hemisphere(n, rng.next_2d());
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert!(d.dot(n) >= -1e-6);
            mean_cos += d.dot(n) as f64;
        }
        // E[cos θ] under pdf cos θ / π is 2/3.
        assert!((mean_cos / 20_000.0 - 2.0 / 3.0).abs() < 0.01);
    }

    /// The 8-lane sampler is the scalar `r2` + `cosine_hemisphere` bit for bit
    /// (and so is `fract_nonneg` inside `r2`, against `f64::fract`).
    #[test]
    fn eight_lane_cosine_sampler_equals_the_scalar_one_bitwise() {
        let mut rng = Rng::new(3);
        for k in 0..2000u32 {
            let n = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5).normalize_or(Vec3::Z);
            let n = [n, Vec3::Z, -Vec3::Z, Vec3::X][(k % 4) as usize];
            let offset = pixel_offset(k as u64 * 77);
            let first = [0, 8 * k, u32::MAX - 20, 1_000_000 + k][(k / 4 % 4) as usize];
            let (dirs, u) = cosine_hemisphere_r2_8(n, basis(n), offset, first);
            for l in 0..8 {
                let i = first.wrapping_add(l as u32);
                assert_eq!(u[l], r2(i, offset));
                let want = cosine_hemisphere(n, r2(i, offset));
                assert_eq!(
                    dirs[l].to_array().map(f32::to_bits),
                    want.to_array().map(f32::to_bits),
                    "n {n} i {i}"
                );
                let x = 0.5 + 0.754_877_666_246_692_8 * i as f64 + offset[0] as f64;
                assert_eq!(fract_nonneg(x).to_bits(), x.fract().to_bits());
            }
        }
    }

    #[test]
    fn basis_is_orthonormal() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(1.0, 2.0, -3.0).normalize()] {
            let (t, b) = basis(n);
            assert!(t.dot(n).abs() < 1e-6 && b.dot(n).abs() < 1e-6 && t.dot(b).abs() < 1e-6);
            assert!((t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
        }
    }
}
