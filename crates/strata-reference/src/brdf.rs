//! The metallic-roughness GGX BRDF of glossy materials ([`Material::glossy`]).
//!
//! For base colour ρ, metallic m and roughness r (α = r², at least
//! [`ALPHA_MIN`]), unit normal n, view v and light l (both pointing away from
//! the surface), h = normalize(v + l):
//!
//! ```text
//! f(v, l) = (1 − m) ρ/π (1 − F_d(n·v)) (1 − F_d(n·l))          diffuse
//!         + F(v·h) D(h) G2(v, l) / (4 (n·v)(n·l))              specular
//! D(h)    = α² / (π ((n·h)² (α² − 1) + 1)²)                    Trowbridge-Reitz
//! Λ(ω)    = (√(1 + α² tan²θ_ω) − 1) / 2,  G1(ω) = 1 / (1 + Λ(ω))
//! G2      = 1 / (1 + Λ(v) + Λ(l))                             Smith, height-correlated
//! F(c)    = F0 + (1 − F0)(1 − c)⁵,  F0 = lerp(0.04, ρ, m)       Schlick
//! F_d(c)  = 0.04 + 0.96 (1 − c)⁵                               the dielectric's Fresnel
//! ```
//!
//! Energy: F is linear in F0, so f = (1 − m)·f_dielectric + m·f_metal. The
//! metal part reflects at most ∫ D G2/(4 n·v) dl ≤ 1 (F ≤ 1, G2 ≤ G1(v) and the
//! visible normals integrate to 1). The dielectric's Lambert lobe is weighted
//! by (1 − F_d) at both ends (reciprocal) — at most (1 − F_d(n·v))(1 − F̄_d)
//! with F̄_d = 2∫F_d(c)c dc ≈ 0.0857 — which leaves room for its specular
//! albedo; `brdf_tests::albedo_is_at_most_one` checks the sum by Monte Carlo.
//! Roughness 1 does *not* make it Lambert (4 % specular remains): materials
//! that are not `glossy` are shaded by the old Lambert path instead.
//!
//! Sampling: lobe selection with probability P_s = Y(F(n·v)) / (Y(F(n·v)) +
//! Y((1 − m)ρ)(1 − F_d(n·v))) (Y = luminance: the lobes' albedo at normal
//! reflection, roughly), then the specular lobe samples the **visible
//! normals** ([`crate::sampling::ggx_vndf_local`]) and reflects v about h
//! (pdf G1(v) D(h) / (4 n·v)), the diffuse lobe samples cos θ / π. The pdf of
//! the mixture, [`Ggx::pdf`], is what the path weight and MIS use.

use glam::Vec3;

use crate::sampling::{basis, cosine_hemisphere, ggx_vndf_local};

/// Smallest GGX α (r² below this is clamped): the GPU's lighting shader uses the same.
pub const ALPHA_MIN: f32 = 0.002;
/// F0 of dielectrics (index of refraction 1.5).
pub const DIELECTRIC_F0: f32 = 0.04;

/// Trowbridge-Reitz (GGX) normal distribution D at n·h = `cos_h` (0 for `cos_h ≤ 0`).
#[inline]
pub fn ggx_d(cos_h: f32, alpha: f32) -> f32 {
    if cos_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    // (n·h)²(α² − 1) + 1 = sin²θ_h + α² cos²θ_h, with sin² as (1 − c)(1 + c):
    // no cancellation near the peak of narrow lobes.
    let k = (1.0 - cos_h) * (1.0 + cos_h) + a2 * cos_h * cos_h;
    a2 / (std::f32::consts::PI * k * k)
}

/// Smith Λ of GGX for a direction at cos θ = `cos` from the normal.
#[inline]
pub fn smith_lambda(cos: f32, alpha: f32) -> f32 {
    let c2 = (cos * cos).max(1e-12);
    let tan2 = (1.0 - c2).max(0.0) / c2;
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// Smith masking G1 = 1 / (1 + Λ).
#[inline]
pub fn smith_g1(cos: f32, alpha: f32) -> f32 {
    1.0 / (1.0 + smith_lambda(cos, alpha))
}

/// Height-correlated masking-shadowing G2 = 1 / (1 + Λ(v) + Λ(l)) (Heitz 2014, Eq. 99).
#[inline]
pub fn smith_g2(cos_v: f32, cos_l: f32, alpha: f32) -> f32 {
    1.0 / (1.0 + smith_lambda(cos_v, alpha) + smith_lambda(cos_l, alpha))
}

/// Schlick's Fresnel approximation.
#[inline]
pub fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    let k = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * k
}

fn schlick_dielectric(cos: f32) -> f32 {
    DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * (1.0 - cos.clamp(0.0, 1.0)).powi(5)
}

/// Mean of 1 − F_d(n·l) over the cosine-weighted hemisphere: 1 − (F0 + (1 − F0) · 2/42).
const DIFFUSE_TRANSMITTED: f32 = 1.0 - (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * (2.0 / 42.0));

/// A smooth stand-in for the GGX BRDF's directional albedo ∫ f(v, l) (n·l) dl at
/// n·v = `nv` (WGSL twin `ggx_demodulation`, common/ggx.wgsl): the diffuse lobe's exact
/// (1 − m) ρ (1 − F_d(n·v)) · mean(1 − F_d), and the specular lobe by Karis's fit of
/// the split sum's scale and bias (F0 · A + B; Karis 2014, "Physically based shading on
/// mobile"). Glossy radiance is divided by it before the screen-space filters and
/// multiplied back in compose, so they blur the lighting, not the textures
/// (docs/ils.md § "Glossy receivers"). At least 1e-3 per channel.
pub fn demodulation_albedo(nv: f32, rho: Vec3, roughness: f32, metallic: f32) -> Vec3 {
    let (m, r, c) = (metallic.clamp(0.0, 1.0), roughness.clamp(0.0, 1.0), nv.clamp(0.0, 1.0));
    let f0 = Vec3::splat(DIELECTRIC_F0).lerp(rho, m);
    let q = [1.0 - r, r * -0.0275 + 0.0425, r * -0.572 + 1.04, r * 0.022 - 0.04];
    let a004 = (q[0] * q[0]).min((-9.28 * c).exp2()) * q[0] + q[1];
    let (scale, bias) = (-1.04 * a004 + q[2], 1.04 * a004 + q[3]);
    let diffuse = rho * ((1.0 - m) * (1.0 - schlick_dielectric(c)) * DIFFUSE_TRANSMITTED);
    (diffuse + f0 * scale + Vec3::splat(bias)).max(Vec3::splat(1e-3))
}

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// The GGX BRDF at one path vertex: normal, view direction and material fixed.
#[derive(Clone, Copy, Debug)]
pub struct Ggx {
    n: Vec3,
    t: Vec3,
    b: Vec3,
    v: Vec3,
    /// n·v (the specular lobe is off when it is ≤ 1e-4: shading normals can face away).
    nv: f32,
    alpha: f32,
    f0: Vec3,
    /// (1 − m) ρ (1 − F_d(n·v)) / π: the diffuse lobe before its (1 − F_d(n·l)).
    diffuse: Vec3,
    spec_on: bool,
    /// Probability of sampling the specular lobe.
    p_spec: f32,
}

impl Ggx {
    /// The BRDF at a vertex with shading normal `n`, direction toward the viewer
    /// `v` (both normalised here: camera rays are not unit length), base colour
    /// `rho` and the material's roughness and metallic (clamped to [0, 1]).
    pub fn new(n: Vec3, v: Vec3, rho: Vec3, roughness: f32, metallic: f32) -> Self {
        let (n, v) = (n.normalize_or(Vec3::Z), v.normalize_or(n));
        let m = metallic.clamp(0.0, 1.0);
        let r = roughness.clamp(0.0, 1.0);
        let alpha = (r * r).max(ALPHA_MIN);
        let nv = n.dot(v);
        let f0 = Vec3::splat(DIELECTRIC_F0).lerp(rho, m);
        let diffuse_albedo = rho * (1.0 - m);
        let diffuse = diffuse_albedo * (1.0 - schlick_dielectric(nv)) * std::f32::consts::FRAC_1_PI;
        let spec_on = nv > 1e-4;
        let p_spec = if spec_on {
            let ws = luminance(schlick(f0, nv));
            let wd = luminance(diffuse_albedo) * (1.0 - schlick_dielectric(nv));
            let p = ws / (ws + wd);
            if p.is_finite() {
                p.clamp(0.0, 1.0)
            } else {
                0.5
            }
        } else {
            0.0
        };
        let (t, b) = basis(n);
        Self {
            n,
            t,
            b,
            v,
            nv,
            alpha,
            f0,
            diffuse,
            spec_on,
            p_spec,
        }
    }

    /// GGX α in use.
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// Probability that [`Ggx::sample`] picks the specular lobe.
    pub fn specular_probability(&self) -> f32 {
        self.p_spec
    }

    /// f(v, l) (without the cosine); 0 below the shading hemisphere.
    pub fn eval(&self, l: Vec3) -> Vec3 {
        let nl = self.n.dot(l);
        if nl <= 0.0 {
            return Vec3::ZERO;
        }
        let mut f = self.diffuse * (1.0 - schlick_dielectric(nl));
        if self.spec_on {
            let h = (self.v + l).normalize_or_zero();
            let d = ggx_d(self.n.dot(h), self.alpha);
            if d > 0.0 {
                let g = smith_g2(self.nv, nl, self.alpha);
                f += schlick(self.f0, self.v.dot(h)) * (d * g / (4.0 * self.nv * nl));
            }
        }
        f
    }

    /// The solid-angle pdf of [`Ggx::sample`] at `l`, over the whole sphere
    /// (specular samples that reflect below the surface are part of it: the
    /// path ends there).
    pub fn pdf(&self, l: Vec3) -> f32 {
        let mut p = 0.0;
        if self.p_spec < 1.0 {
            p += (1.0 - self.p_spec) * self.n.dot(l).max(0.0) * std::f32::consts::FRAC_1_PI;
        }
        if self.p_spec > 0.0 {
            let h = (self.v + l).normalize_or_zero();
            if self.v.dot(h) > 0.0 {
                // D_v(h) / (4 v·h) = G1(v) D(h) / (4 n·v)
                let d = ggx_d(self.n.dot(h), self.alpha);
                p += self.p_spec * smith_g1(self.nv, self.alpha) * d / (4.0 * self.nv);
            }
        }
        p
    }

    /// A direction l: the specular lobe when `u_lobe < P_s` (visible-normal
    /// sample reflected about h; may point below the surface), else a
    /// cosine-weighted one. `u` in [0, 1)².
    pub fn sample(&self, u_lobe: f32, u: [f32; 2]) -> Vec3 {
        if u_lobe < self.p_spec {
            let vl = Vec3::new(self.v.dot(self.t), self.v.dot(self.b), self.nv);
            let h = ggx_vndf_local(vl, self.alpha, u);
            let h = self.t * h.x + self.b * h.y + self.n * h.z;
            (2.0 * self.v.dot(h) * h - self.v).normalize_or(self.n)
        } else {
            cosine_hemisphere(self.n, u)
        }
    }
}

#[cfg(test)]
mod brdf_tests {
    use super::*;
    use crate::sampling::Rng;

    fn view(theta_deg: f32) -> Vec3 {
        let t = theta_deg.to_radians();
        Vec3::new(t.sin(), 0.0, t.cos())
    }

    /// Demodulation needs L / `demodulation_albedo` to be the same for every base
    /// colour under the same light. Under uniform light L is the directional
    /// albedo ∫ f (n·l) dl (the BRDF's own sampler, 200,000 samples), so the ratio
    /// MC / fit must barely change across ρ's channels (0.9, 0.45, 0.1): ≤ 12 %
    /// spread (10 % seen). It must also stay within 35 % of 1, a bound on the fit
    /// itself (30 % seen, rough metal at grazing view: Karis fitted another Smith
    /// term); the absolute scale cancels in the round trip.
    #[test]
    fn demodulation_albedo_tracks_the_directional_albedo() {
        let rho = Vec3::new(0.9, 0.45, 0.1);
        let (mut spread, mut off) = (0.0f32, 0.0f32);
        for th in [10.0f32, 45.0, 70.0] {
            for r in [0.15f32, 0.4, 0.8] {
                for m in [0.0f32, 0.5, 1.0] {
                    let g = Ggx::new(Vec3::Z, view(th), rho, r, m);
                    let mut rng = Rng::new(5);
                    let k = 200_000;
                    let mut sum = Vec3::ZERO;
                    for _ in 0..k {
                        let l = g.sample(rng.next_f32(), rng.next_2d());
                        let p = g.pdf(l);
                        if l.z > 0.0 && p > 0.0 {
                            sum += g.eval(l) * (l.z / p);
                        }
                    }
                    let mc = sum / k as f32;
                    let ratio = mc / demodulation_albedo(th.to_radians().cos(), rho, r, m);
                    let s = ratio.max_element() / ratio.min_element() - 1.0;
                    eprintln!("θ {th}° roughness {r} metallic {m}: MC {mc:.4}, MC / fit {ratio:.3} (spread {s:.3})");
                    spread = spread.max(s);
                    off = off.max((ratio - Vec3::ONE).abs().max_element());
                }
            }
        }
        eprintln!("worst spread {spread:.3}, worst |MC / fit − 1| {off:.3}");
        assert!(
            spread < 0.12,
            "MC / fit varies by {spread} across the base colour's channels"
        );
        assert!(off < 0.35, "MC / fit is {off} from 1");
    }

    /// ∫ D(h) (n·h) dω_h = 1 (the projected microfacet area is the macro
    /// area): 2π ∫ D(cos θ) cos θ sin θ dθ by the midpoint rule in θ with
    /// 2·10⁶ intervals (≥ 3000 across the narrowest lobe), summed in f64.
    #[test]
    fn ggx_d_is_normalised() {
        for r in [0.0f32, 0.05, 0.1, 0.2, 0.4, 0.7, 1.0] {
            let alpha = (r * r).max(ALPHA_MIN);
            let n = 2_000_000;
            let dt = std::f64::consts::FRAC_PI_2 / n as f64;
            let mut sum = 0.0f64;
            for i in 0..n {
                let t = (i as f64 + 0.5) * dt;
                sum += ggx_d(t.cos() as f32, alpha) as f64 * t.cos() * t.sin();
            }
            let integral = sum * dt * std::f64::consts::TAU;
            eprintln!("roughness {r}: ∫ D cos = {integral:.5}");
            assert!((integral - 1.0).abs() < 2e-3, "roughness {r}: {integral}");
        }
    }

    /// The sampler's pdf integrates to 1 over the sphere (uniform-sphere Monte
    /// Carlo, 2·10⁶ points, for lobes wide enough for that estimator), and the
    /// sample histogram over 12 × 16 (cos θ, φ) bins matches the pdf
    /// integrated over each bin: Pearson χ² below the 10⁻⁴ tail of its
    /// distribution (Wilson-Hilferty), bins with < 5 expected samples pooled.
    #[test]
    fn sampler_pdf_integrates_to_one_and_matches_its_histogram() {
        let n = Vec3::Z;
        for (r, m, th) in [
            (0.5f32, 0.0f32, 30.0f32),
            (0.7, 1.0, 60.0),
            (0.4, 0.5, 75.0),
            (1.0, 0.0, 0.0),
            (0.6, 0.2, 45.0),
            (0.2, 0.7, 49.5),
        ] {
            let v = view(th);
            let v = Vec3::new(v.x * 0.8, v.x * 0.6, v.z); // off the xz plane
            let g = Ggx::new(n, v, Vec3::new(0.8, 0.5, 0.3), r, m);
            // ∫ pdf over the sphere
            let mut rng = Rng::new(11);
            let k = 2_000_000;
            let mut sum = 0.0f64;
            for _ in 0..k {
                let [a, b] = rng.next_2d();
                let z = 1.0 - 2.0 * a;
                let s = (1.0 - z * z).max(0.0).sqrt();
                let phi = std::f32::consts::TAU * b;
                sum += g.pdf(Vec3::new(s * phi.cos(), s * phi.sin(), z)) as f64;
            }
            let integral = sum / k as f64 * 4.0 * std::f64::consts::PI;
            // histogram
            const NT: usize = 12;
            const NP: usize = 16;
            let samples = 400_000;
            let mut counts = [[0u32; NP]; NT];
            let bin = |l: Vec3| {
                let t = (((l.z + 1.0) * 0.5) * NT as f32).clamp(0.0, NT as f32 - 1.0) as usize;
                let phi = l.y.atan2(l.x).rem_euclid(std::f32::consts::TAU);
                let p = (phi / std::f32::consts::TAU * NP as f32).clamp(0.0, NP as f32 - 1.0) as usize;
                (t, p)
            };
            for _ in 0..samples {
                let l = g.sample(rng.next_f32(), rng.next_2d());
                let (t, p) = bin(l);
                counts[t][p] += 1;
            }
            // expected: the pdf integrated over each bin, 24 × 24 midpoints in (z, φ)
            let q = 24;
            let (mut chi2, mut dof) = (0.0f64, 0i32);
            let (mut pool_e, mut pool_o) = (0.0f64, 0.0f64);
            for (t, row) in counts.iter().enumerate() {
                for (p, &c) in row.iter().enumerate() {
                    let mut e = 0.0f64;
                    for i in 0..q {
                        for j in 0..q {
                            let z = -1.0 + 2.0 * (t as f64 + (i as f64 + 0.5) / q as f64) / NT as f64;
                            let phi = std::f64::consts::TAU * (p as f64 + (j as f64 + 0.5) / q as f64) / NP as f64;
                            let s = (1.0 - z * z).max(0.0).sqrt();
                            e += g.pdf(Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32)) as f64;
                        }
                    }
                    // bin solid angle = (2/NT)(2π/NP)
                    e *= 2.0 / NT as f64 * std::f64::consts::TAU / NP as f64 / (q * q) as f64 * samples as f64;
                    if e < 5.0 {
                        pool_e += e;
                        pool_o += c as f64;
                    } else {
                        chi2 += (c as f64 - e).powi(2) / e;
                        dof += 1;
                    }
                }
            }
            if pool_e > 0.0 {
                chi2 += (pool_o - pool_e).powi(2) / pool_e.max(1.0);
                dof += 1;
            }
            let dof = (dof - 1) as f64;
            // Wilson-Hilferty: χ²_k ≈ k (1 − 2/9k + z √(2/9k))³, z = 3.72 for 10⁻⁴
            let c = 2.0 / (9.0 * dof);
            let limit = dof * (1.0 - c + 3.72 * c.sqrt()).powi(3);
            eprintln!("r {r} m {m} θ {th}: ∫pdf = {integral:.4}, χ² {chi2:.1} (dof {dof}, limit {limit:.1})");
            assert!((integral - 1.0).abs() < 0.01, "∫ pdf = {integral}");
            assert!(chi2 < limit, "χ² {chi2} ≥ {limit} (dof {dof})");
        }
    }

    /// Directional albedo ∫ f cos dl ≤ 1 for a white base colour (the
    /// non-absorbing worst case) over roughness × view angle × metallic, by
    /// importance sampling (100k samples); where the lobe is wide enough the
    /// estimate is checked against plain cosine sampling, an independent
    /// estimator of the same integral (5σ).
    #[test]
    fn albedo_is_at_most_one() {
        let n = Vec3::Z;
        let mut worst = 0.0f64;
        for r in [0.05f32, 0.1, 0.25, 0.5, 0.75, 1.0] {
            for th in [0.0f32, 30.0, 60.0, 75.0, 85.0, 89.0] {
                for m in [0.0f32, 0.5, 1.0] {
                    let g = Ggx::new(n, view(th), Vec3::ONE, r, m);
                    let mut rng = Rng::new(crate::sampling::hash(&[
                        r.to_bits() as u64,
                        th.to_bits() as u64,
                        m.to_bits() as u64,
                    ]));
                    let k = 100_000;
                    let (mut s, mut s2) = (0.0f64, 0.0f64);
                    let (mut c, mut c2) = (0.0f64, 0.0f64);
                    for _ in 0..k {
                        let l = g.sample(rng.next_f32(), rng.next_2d());
                        let nl = l.z;
                        let w = if nl > 0.0 {
                            let pdf = g.pdf(l);
                            (g.eval(l).x * nl / pdf) as f64
                        } else {
                            0.0
                        };
                        s += w;
                        s2 += w * w;
                        let l = cosine_hemisphere(n, rng.next_2d());
                        let w = (g.eval(l).x * std::f32::consts::PI) as f64;
                        c += w;
                        c2 += w * w;
                    }
                    let (mean, var) = (s / k as f64, (s2 / k as f64 - (s / k as f64).powi(2)).max(0.0));
                    let (cmean, cvar) = (c / k as f64, (c2 / k as f64 - (c / k as f64).powi(2)).max(0.0));
                    let sigma = ((var + cvar) / k as f64).sqrt();
                    worst = worst.max(mean);
                    assert!(mean <= 1.0 + 1e-3, "r {r} θ {th} m {m}: albedo {mean}");
                    if r >= 0.25 {
                        assert!(
                            (mean - cmean).abs() < 5.0 * sigma + 1e-3,
                            "r {r} θ {th} m {m}: importance {mean} vs cosine {cmean} (σ {sigma})"
                        );
                    }
                    if th == 0.0 || th == 75.0 {
                        eprintln!("r {r} θ {th} m {m}: albedo {mean:.4} (cosine-sampled {cmean:.4})");
                    }
                }
            }
        }
        eprintln!("largest albedo {worst:.4}");
    }

    /// Reciprocity f(v, l) = f(l, v), and the metal's per-sample weight
    /// F G2/G1(v) never exceeds 1 for a white F0.
    #[test]
    fn brdf_is_reciprocal_and_white_metal_weights_are_at_most_one() {
        let mut rng = Rng::new(5);
        let n = Vec3::Z;
        for _ in 0..2000 {
            let v = cosine_hemisphere(n, rng.next_2d());
            let l = cosine_hemisphere(n, rng.next_2d());
            let r = rng.next_f32();
            let m = rng.next_f32();
            let rho = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let a = Ggx::new(n, v, rho, r, m).eval(l);
            let b = Ggx::new(n, l, rho, r, m).eval(v);
            // f32 rounding of h near the peak of narrow lobes: 1e-2 relative
            assert!(
                (a - b).abs().max_element() <= 1e-2 * a.max_element().max(1.0),
                "{a} vs {b}"
            );
            let g = Ggx::new(n, v, Vec3::ONE, r, 1.0);
            let l = g.sample(0.0, rng.next_2d());
            if l.z > 0.0 {
                let w = g.eval(l) * l.z / g.pdf(l);
                assert!(w.max_element() <= 1.0 + 1e-4, "weight {w}");
            }
        }
    }
}
