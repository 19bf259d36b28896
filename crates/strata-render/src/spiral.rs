//! DGB §3.4 quasi-Monte Carlo spiral sampling, the CPU mirror of
//! `shaders/common/spiral.wgsl` (same integer hash, same formulas), used to pick τ
//! for the GPU passes and by the CPU evaluations that check them.
//!
//! The i-th of N taps around pixel (x, y) lies at `texel(x, y) + h_i û_i` with
//! κ_i = (i + 0.5)/N (the radiosity gather's default: (i + ξ)/N, [`spiral_tap_at`]),
//! h_i = r_p κ_i, û_i = (cos θ_i, sin θ_i), θ_i = 2π κ_i τ + φ,
//! and reads MIP level m_i = ⌊log2(h_i / q)⌋.

use std::f32::consts::TAU as TWO_PI;

/// DGB Listing 3: `TAU[N − 1]` is the discrepancy-minimising number of spiral
/// turns for N samples. The listing has 98 entries (N = 1..=98).
pub const LISTING3_TAU: [u32; 98] = [
    1, 1, 2, 3, 2, 5, 2, 3, 2, 3, 3, 5, 5, 3, 4, 7, 5, 5, 7, 9, 8, 5, 5, 7, 7, 7, 8, 5, 8, 11, 12, 7, 10, 13, 8, 11, 8,
    7, 14, 11, 11, 13, 12, 13, 19, 17, 13, 11, 18, 19, 11, 11, 14, 17, 21, 15, 16, 17, 18, 13, 17, 11, 17, 19, 18, 25,
    18, 19, 19, 29, 21, 19, 27, 31, 29, 21, 18, 17, 29, 31, 31, 23, 18, 25, 26, 25, 23, 19, 34, 19, 27, 21, 25, 39, 29,
    17, 21, 27,
];

/// 2 − golden ratio: the golden-angle fraction of a turn (Vogel's spiral).
const GOLDEN_TURN: f32 = 0.381_966_02;

/// How many turns the spiral makes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum SpiralTurns {
    #[default]
    /// Listing 3's τ for N ≤ 98; beyond the table, Vogel's golden-angle spiral
    /// (τ = 0.381966·N: consecutive taps 137.5° apart), also low-discrepancy.
    Optimal,
    /// A fixed τ (SAO used τ = 7, tuned for N = 9; Fig. 7 left).
    Fixed(f32),
}

impl SpiralTurns {
    /// τ for `n` samples.
    pub fn tau(&self, n: u32) -> f32 {
        match *self {
            SpiralTurns::Fixed(t) => t,
            SpiralTurns::Optimal => match LISTING3_TAU.get(n.wrapping_sub(1) as usize) {
                Some(&t) => t as f32,
                None => GOLDEN_TURN * n as f32,
            },
        }
    }
}

/// PCG hash (Jarzynski & Olano 2020), bit-identical to `spiral.wgsl`'s `pcg_hash`.
pub fn pcg_hash(v: u32) -> u32 {
    let s = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let w = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
    (w >> 22) ^ w
}

/// The per-pixel rotation φ ∈ [0, 2π) from a hash of the pixel and `seed`
/// (0 = the paper's fixed per-pixel pattern; the frame index for temporal noise).
pub fn pixel_angle(x: u32, y: u32, seed: u32) -> f32 {
    let h = pcg_hash(x.wrapping_add(pcg_hash(y.wrapping_add(pcg_hash(seed)))));
    // 24 high bits → [0, 1) exactly representable, identical on the GPU
    (h >> 8) as f32 * (1.0 / 16_777_216.0) * TWO_PI
}

/// The full-resolution pixel that texel `t` of a gather run at 1/`s` resolution shades:
/// one pixel of t's s×s block, the block's hashed phase plus `seed` stepping through all
/// s² pixels in s² frames, clamped into an image of `size` pixels. Bit-identical to
/// `spiral.wgsl`'s `block_pixel`; s = 1 gives `t`.
pub fn block_pixel(t: [u32; 2], s: u32, seed: u32, size: [u32; 2]) -> [u32; 2] {
    let k = pcg_hash(t[0].wrapping_add(pcg_hash(t[1] ^ 0x68e3_1da4))).wrapping_add(seed) % (s * s);
    [(t[0] * s + k % s).min(size[0] - 1), (t[1] * s + k / s).min(size[1] - 1)]
}

/// One spiral tap: screen offset in pixels and its radius h_i.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpiralTap {
    pub offset: [f32; 2],
    pub radius: f32,
}

/// The per-pixel offset ξ ∈ [0, 1) of the taps' radii ([`spiral_tap_at`]): a second
/// hash, independent of [`pixel_angle`]'s for the same pixel and seed.
pub fn pixel_jitter(x: u32, y: u32, seed: u32) -> f32 {
    let h = pcg_hash(pcg_hash(x.wrapping_add(pcg_hash(y.wrapping_add(pcg_hash(seed))))) ^ 0x5bd1_e995);
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The i-th of `n` taps of a spiral of radius `r_p` pixels with `tau` turns,
/// rotated by `phi` (κ_i = (i + ½)/n).
pub fn spiral_tap(i: u32, n: u32, tau: f32, r_p: f32, phi: f32) -> SpiralTap {
    spiral_tap_at(i, n, tau, r_p, phi, 0.5)
}

/// [`spiral_tap`] with κ_i = (i + ξ)/n: ξ = ½ is the paper's spiral; a per-pixel,
/// per-frame ξ ∈ [0, 1) spreads each tap over its whole stratum of radii.
pub fn spiral_tap_at(i: u32, n: u32, tau: f32, r_p: f32, phi: f32, xi: f32) -> SpiralTap {
    let kappa = (i as f32 + xi) / n as f32;
    let h = r_p * kappa;
    let theta = TWO_PI * kappa * tau + phi;
    SpiralTap {
        offset: [h * theta.cos(), h * theta.sin()],
        radius: h,
    }
}

/// MIP level m_i = ⌊log2(h / q)⌋ clamped to `0..=max_level`.
pub fn mip_level(h: f32, q: f32, max_level: u32) -> u32 {
    let m = (h / q).log2().floor();
    if m.is_nan() || m < 0.0 {
        0
    } else {
        (m as u32).min(max_level)
    }
}

/// Integer texel offset of a tap: ⌊offset + ½⌋ per axis.
pub fn tap_texel(offset: [f32; 2]) -> [i32; 2] {
    [(offset[0] + 0.5).floor() as i32, (offset[1] + 0.5).floor() as i32]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each block's pixel lies in its block (or on the image's last row or column), s = 1
    /// is the identity, and s² consecutive seeds visit every pixel of a block once.
    #[test]
    fn block_pixel_cycles_through_its_block() {
        let size = [13, 9];
        for t in [[0u32, 0], [3, 2], [6, 4]] {
            assert_eq!(block_pixel(t, 1, 17, size), t);
            for s in [2u32, 3] {
                let mut seen = std::collections::HashSet::new();
                for seed in 40..40 + s * s {
                    let p = block_pixel(t, s, seed, size);
                    for a in 0..2 {
                        let lo = (t[a] * s).min(size[a] - 1);
                        assert!(p[a] >= lo && p[a] < (t[a] * s + s).min(size[a]), "{t:?} s={s}: {p:?}");
                    }
                    seen.insert(p);
                }
                let inside = (0..2).all(|a| t[a] * s + s <= size[a]);
                if inside {
                    assert_eq!(seen.len() as u32, s * s, "{t:?} s={s}");
                }
            }
        }
    }

    #[test]
    fn listing3_values() {
        // spot checks against the paper's listing (tau[N-1])
        assert_eq!(LISTING3_TAU[0], 1);
        assert_eq!(LISTING3_TAU[8], 2); // N = 9: not SAO's 7
        assert_eq!(LISTING3_TAU[18], 7); // N = 19
        assert_eq!(LISTING3_TAU[93], 39);
        assert_eq!(LISTING3_TAU[97], 27);
        assert_eq!(LISTING3_TAU.iter().sum::<u32>(), 1432);
        assert_eq!(SpiralTurns::Optimal.tau(14), 3.0);
        assert_eq!(SpiralTurns::Optimal.tau(30), 11.0);
        assert!((SpiralTurns::Optimal.tau(200) - 76.39).abs() < 0.01);
    }

    #[test]
    fn spiral_has_n_distinct_radii_in_range() {
        for n in [1u32, 9, 19, 30, 98, 150] {
            let r_p = 37.5;
            let tau = SpiralTurns::Optimal.tau(n);
            let mut radii: Vec<f32> = (0..n).map(|i| spiral_tap(i, n, tau, r_p, 1.3).radius).collect();
            for (i, t) in (0..n).map(|i| spiral_tap(i, n, tau, r_p, 1.3)).enumerate() {
                let len = (t.offset[0].powi(2) + t.offset[1].powi(2)).sqrt();
                assert!(
                    (len - t.radius).abs() < 1e-3,
                    "tap {i}: |offset| {len} != h {}",
                    t.radius
                );
            }
            assert!(radii.iter().all(|&h| h > 0.0 && h <= r_p), "n = {n}");
            radii.sort_by(f32::total_cmp);
            radii.dedup();
            assert_eq!(radii.len(), n as usize, "n = {n}: radii not distinct");
        }
    }

    /// `spiral_tap_at` with ξ from `pixel_jitter`: over frames (seeds) tap i of one pixel
    /// lands at every radius of its stratum [i, i + 1)·r_p/n, evenly (8 bins each within
    /// 15 % of uniform), ξ is independent of the rotation φ (their correlation is small),
    /// and ξ = ½ is the paper's fixed radius.
    #[test]
    fn jittered_radii_fill_each_stratum_evenly() {
        let (n, r_p) = (14u32, 100.0f32);
        let tau = SpiralTurns::Optimal.tau(n);
        for i in [0u32, 5, 13] {
            assert_eq!(spiral_tap_at(i, n, tau, r_p, 0.7, 0.5), spiral_tap(i, n, tau, r_p, 0.7));
            let (lo, hi) = (i as f32 * r_p / n as f32, (i + 1) as f32 * r_p / n as f32);
            let mut hist = [0u32; 8];
            let seeds = 4096u32;
            let (mut sxy, mut sx, mut sy, mut sxx, mut syy) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
            for seed in 0..seeds {
                let (xi, phi) = (pixel_jitter(17, 9, seed), pixel_angle(17, 9, seed) / TWO_PI);
                assert!((0.0..1.0).contains(&xi));
                let h = spiral_tap_at(i, n, tau, r_p, 0.0, xi).radius;
                assert!(h >= lo - 1e-4 && h < hi + 1e-4, "tap {i}: h = {h} outside [{lo}, {hi})");
                hist[(((h - lo) / (hi - lo)) * 8.0).clamp(0.0, 7.0) as usize] += 1;
                let (a, b) = (xi as f64, phi as f64);
                (sxy, sx, sy, sxx, syy) = (sxy + a * b, sx + a, sy + b, sxx + a * a, syy + b * b);
            }
            let expected = seeds as f32 / 8.0;
            for (b, &c) in hist.iter().enumerate() {
                assert!(
                    (c as f32 - expected).abs() < 0.15 * expected,
                    "tap {i}, bin {b}: {c} of {expected}"
                );
            }
            let m = seeds as f64;
            let corr =
                (sxy / m - sx * sy / (m * m)) / ((sxx / m - (sx / m).powi(2)) * (syy / m - (sy / m).powi(2))).sqrt();
            assert!(corr.abs() < 0.05, "ξ and φ correlate: {corr}");
        }
    }

    #[test]
    fn mip_levels_follow_log2() {
        assert_eq!(mip_level(3.0, 8.0, 4), 0);
        assert_eq!(mip_level(8.0, 8.0, 4), 0);
        assert_eq!(mip_level(16.0, 8.0, 4), 1);
        assert_eq!(mip_level(31.9, 8.0, 4), 1);
        assert_eq!(mip_level(64.0, 8.0, 4), 3);
        assert_eq!(mip_level(1e6, 8.0, 4), 4);
        assert_eq!(mip_level(0.0, 8.0, 4), 0);
    }

    #[test]
    fn pixel_angles_are_spread() {
        let mut hist = [0u32; 8];
        for y in 0..64 {
            for x in 0..64 {
                let a = pixel_angle(x, y, 0);
                assert!((0.0..TWO_PI).contains(&a));
                hist[(a / TWO_PI * 8.0) as usize] += 1;
            }
        }
        // 4096 angles, 512 expected per bin
        assert!(hist.iter().all(|&c| (400..=624).contains(&c)), "{hist:?}");
        assert_ne!(pixel_angle(3, 4, 0), pixel_angle(3, 4, 1));
    }
}
