//! Virtual point lights by instant radiosity (Keller 1997), the light samples of
//! interleaved deferred shading (ILS §6: "a set of virtual point light sources is
//! first generated with the sampling strategy provided by Instant Radiosity").
//!
//! Light paths leave every light of the scene, are traced with the reference's
//! BVH, and deposit a VPL where they hit a surface: one bounce (VPLs at the
//! first hits) for the interactive mode (ILS §6.2), up to B bounces for the
//! physically-based mode (§6.3). A VPL at surface point y with facing normal
//! n_y and flux Φ (the power the surface *reflects* there, ρ(y) ⊙ the power that
//! arrived) is a cosine emitter: its radiant intensity towards direction ω is
//! Φ/π · max(n_y · ω, 0). A Lambertian receiver x with normal n_x and albedo ρ_x
//! then gets outgoing radiance
//!
//!   L(x) = ρ_x/π · Σ_k Φ_k/π · cos θ_y · cos θ_x / d²    (· V(x, y_k) with shadows).
//!
//! **Power allocation.** Light i (sun, point, spot, the emissive triangles as one
//! light) of power P_i gets n_i of the N paths by largest remainders of N·P_i/ΣP
//! (every light with power gets at least one path when N ≥ the light count), and
//! each of its paths carries P_i / n_i (spots: weighted by the cone falloff, see
//! [`spot_power`]). So the VPLs' total flux at the first bounce is a
//! stratified estimate of the power the surfaces reflect of what reached them.
//!
//! **Sampling.** Path k of light i uses point k of a 5-D Kronecker
//! low-discrepancy sequence (Roberts' generalised golden ratio) rotated by the
//! seed: emission position (2-D), direction (2-D), emissive triangle (1-D).
//! Later bounces are cosine-weighted from a hashed generator. Everything is a
//! pure function of (scene, frame, N, bounces, seed): a frame is reproducible.
//! Lights: `Sun` from a disk perpendicular to its direction covering the scene's
//! bounding sphere (power = illuminance × disk area); `Point` uniform over the
//! sphere (power 4π·I); `Spot` uniform in its outer cone; emissive triangles
//! one-sided, cosine-weighted (power π·L_e·area). `Rect` lights are GPU hints,
//! ignored as by the path tracer (their emissive geometry is sampled instead).

use glam::Vec3;

use crate::sampling::{cosine_hemisphere, hash, triangle_barycentrics, Rng};
use crate::Reference;
use strata_scene::Light;

/// A virtual point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vpl {
    pub position: Vec3,
    /// Unit normal on the side the light arrived from.
    pub normal: Vec3,
    /// Reflected power (W per colour channel): ρ(y) ⊙ the arriving power.
    pub flux: Vec3,
    /// Diffuse albedo of the surface at the VPL.
    pub albedo: Vec3,
    /// 1 for a VPL at a light path's first hit, 2 for the second, …
    pub bounce: u32,
}

impl Vpl {
    /// Irradiance-like term at receiver `x` with unit normal `n`:
    /// Φ/π · cos θ_y · cos θ_x / d² (visibility not included). Multiply by
    /// ρ_x/π for outgoing radiance. `max_geometry` clamps cos θ_y cos θ_x / d²
    /// (the usual bound that tames the 1/d² singularity near the VPL; ∞: none).
    pub fn irradiance_at(&self, x: Vec3, n: Vec3, max_geometry: f32) -> Vec3 {
        match self.geometry(x, n, max_geometry) {
            Some((_, g)) => self.flux * (g * std::f32::consts::FRAC_1_PI),
            None => Vec3::ZERO,
        }
    }

    /// The unit direction w from the VPL to receiver `x` (unit normal `n`) and
    /// the clamped geometry term min(cos θ_y cos θ_x / d², `max_geometry`), or
    /// `None` when either side faces away (or x is at the VPL).
    fn geometry(&self, x: Vec3, n: Vec3, max_geometry: f32) -> Option<(Vec3, f32)> {
        let v = x - self.position;
        let d2 = v.length_squared();
        if !(d2 > 0.0) {
            return None;
        }
        let w = v / d2.sqrt();
        let cos_y = self.normal.dot(w);
        let cos_x = -n.dot(w);
        if cos_y <= 0.0 || cos_x <= 0.0 {
            return None;
        }
        Some((w, (cos_y * cos_x / d2).min(max_geometry)))
    }

    /// Glossy receivers: outgoing radiance toward `view` (unit, away from the
    /// surface) of receiver `x` (unit normal `n`, GGX material `rho`,
    /// `roughness`, `metallic`: [`crate::brdf::Ggx`]) lit by this VPL:
    /// f(view, l) · Φ/π · min(cos θ_y cos θ_x / d², `max_geometry`), l toward
    /// the VPL. With f = ρ/π it is ρ/π · [`Vpl::irradiance_at`]. GPU twin:
    /// `vpl_glossy_radiance` in strata-render's `shaders/common/vpl.wgsl`.
    #[allow(clippy::too_many_arguments)]
    pub fn glossy_radiance_at(
        &self,
        x: Vec3,
        n: Vec3,
        view: Vec3,
        rho: Vec3,
        roughness: f32,
        metallic: f32,
        max_geometry: f32,
    ) -> Vec3 {
        let Some((w, g)) = self.geometry(x, n, max_geometry) else {
            return Vec3::ZERO;
        };
        let f = crate::brdf::Ggx::new(n, view, rho, roughness, metallic).eval(-w);
        f * self.flux * (g * std::f32::consts::FRAC_1_PI)
    }
}

/// Settings of [`Reference::vpls`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VplSettings {
    /// Light paths N (one VPL per path and bounce that hits a surface).
    pub paths: u32,
    /// Bounces B: VPLs at the first B hits of each path (1 = interactive mode).
    pub bounces: u32,
    pub seed: u64,
}

impl Default for VplSettings {
    /// 480 paths (ILS Table 4 / Fig. 9: 480 secondary VPLs), one bounce, seed 0.
    fn default() -> Self {
        Self {
            paths: 480,
            bounces: 1,
            seed: 0,
        }
    }
}

/// Point `k` of the 5-D Kronecker sequence α_j = φ₅^−(j+1), φ₅ the unique
/// positive root of x⁶ = x + 1, rotated by `offset`.
fn kronecker5(k: u32, offset: &[f64; 5]) -> [f32; 5] {
    const PHI5: f64 = 1.134_724_138_401_518_8;
    let mut out = [0.0f32; 5];
    let mut a = 1.0;
    for (j, o) in out.iter_mut().enumerate() {
        a /= PHI5;
        *o = ((0.5 + a * k as f64 + offset[j]).fract()) as f32;
    }
    out
}

/// Power of a spot light: 2π·I·∫ smoothstep(cos outer, cos inner, c) dc over
/// c ∈ [cos outer, 1] (midpoint rule, 1024 steps; exact for the constant core).
pub fn spot_power(intensity: f32, inner_deg: f32, outer_deg: f32) -> f32 {
    let (ci, co) = (inner_deg.to_radians().cos(), outer_deg.to_radians().cos());
    let steps = 1024;
    let h = (1.0 - co) / steps as f32;
    let mut sum = 0.0f64;
    for s in 0..steps {
        let c = co + (s as f32 + 0.5) * h;
        sum += crate::gi::smoothstep(co, ci, c) as f64;
    }
    std::f32::consts::TAU * intensity * (sum as f32 * h)
}

/// One emitter as seen by the path allocation.
enum Emitter {
    Sun {
        dir: Vec3,
        centre: Vec3,
        radius: f32,
    },
    Point {
        pos: Vec3,
    },
    Spot {
        pos: Vec3,
        axis: Vec3,
        intensity: Vec3,
        cos_inner: f32,
        cos_outer: f32,
    },
    Emissive,
}

/// Splits `n` paths over `powers` by largest remainders (≥ 1 per light with
/// power when `n` allows).
fn allocate(n: u32, powers: &[f64]) -> Vec<u32> {
    let total: f64 = powers.iter().sum();
    if !(total > 0.0) || n == 0 {
        return vec![0; powers.len()];
    }
    let exact: Vec<f64> = powers.iter().map(|p| n as f64 * p / total).collect();
    let mut counts: Vec<u32> = exact.iter().map(|e| e.floor() as u32).collect();
    let mut left = n - counts.iter().sum::<u32>();
    // lights with power but no path first, then by remainder
    let mut order: Vec<usize> = (0..powers.len()).collect();
    order.sort_by(|&a, &b| {
        let ka = (counts[a] == 0 && powers[a] > 0.0, exact[a] - exact[a].floor());
        let kb = (counts[b] == 0 && powers[b] > 0.0, exact[b] - exact[b].floor());
        kb.partial_cmp(&ka).unwrap_or(std::cmp::Ordering::Equal)
    });
    for &i in order.iter().cycle().take(powers.len() * 2) {
        if left == 0 {
            break;
        }
        if powers[i] > 0.0 && (counts[i] == 0 || exact[i] > counts[i] as f64) {
            counts[i] += 1;
            left -= 1;
        }
    }
    // anything still left goes to the most powerful light
    if left > 0 {
        let imax = (0..powers.len())
            .max_by(|&a, &b| powers[a].total_cmp(&powers[b]))
            .unwrap_or(0);
        counts[imax] += left;
    }
    counts
}

fn luminance(c: Vec3) -> f64 {
    (0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z) as f64
}

impl Reference<'_> {
    /// The power (W per channel) each light emits, in the order of
    /// `scene.lights` followed by the emissive triangles as one entry; what the
    /// path allocation splits N by (luminance).
    pub fn light_powers(&self) -> Vec<Vec3> {
        self.emitters().into_iter().map(|(_, p)| p).collect()
    }

    fn emitters(&self) -> Vec<(Emitter, Vec3)> {
        let (centre, radius) = match self.bvh.bounds() {
            Some((lo, hi)) => (0.5 * (lo + hi), 0.5 * (hi - lo).length() * 1.001 + self.epsilon),
            None => (Vec3::ZERO, 0.0),
        };
        let mut out = Vec::new();
        for light in &self.scene.lights {
            match *light {
                Light::Sun {
                    direction,
                    color,
                    illuminance,
                } => {
                    let dir = direction.normalize_or_zero();
                    let area = std::f32::consts::PI * radius * radius;
                    if dir != Vec3::ZERO {
                        out.push((
                            Emitter::Sun { dir, centre, radius },
                            Vec3::from(color) * illuminance * area,
                        ));
                    }
                }
                Light::Point {
                    position,
                    color,
                    intensity,
                } => out.push((
                    Emitter::Point { pos: position },
                    Vec3::from(color) * intensity * 4.0 * std::f32::consts::PI,
                )),
                Light::Spot {
                    position,
                    direction,
                    color,
                    intensity,
                    inner_deg,
                    outer_deg,
                } => {
                    let axis = direction.normalize_or_zero();
                    if axis != Vec3::ZERO {
                        out.push((
                            Emitter::Spot {
                                pos: position,
                                axis,
                                intensity: Vec3::from(color) * intensity,
                                cos_inner: inner_deg.to_radians().cos(),
                                cos_outer: outer_deg.to_radians().cos(),
                            },
                            Vec3::from(color) * spot_power(1.0, inner_deg, outer_deg) * intensity,
                        ));
                    }
                }
                Light::Rect { .. } => {}
            }
        }
        if !self.lights.is_empty() {
            let p = self.lights.tris.iter().fold(Vec3::ZERO, |acc, (_, area, le)| {
                acc + *le * (std::f32::consts::PI * area)
            });
            out.push((Emitter::Emissive, p));
        }
        out
    }

    /// Traces the light paths of instant radiosity and returns their VPLs
    /// (in path order; a path deposits one VPL per bounce up to
    /// `settings.bounces` that hits a surface).
    pub fn vpls(&self, settings: &VplSettings) -> Vec<Vpl> {
        let emitters = self.emitters();
        let powers: Vec<f64> = emitters.iter().map(|(_, p)| luminance(*p)).collect();
        let counts = allocate(settings.paths, &powers);
        let offset = {
            let mut r = Rng::new(hash(&[settings.seed, 0x1f1]));
            [0; 5].map(|_: u8| r.next_f32() as f64)
        };
        let mut out = Vec::new();
        let mut k = 0u32;
        for ((emitter, power), &count) in emitters.iter().zip(&counts) {
            for _ in 0..count {
                let u = kronecker5(k, &offset);
                k += 1;
                let Some((origin, dir, carried)) = self.emit(emitter, *power, count, u) else {
                    continue;
                };
                self.follow(origin, dir, carried, settings, k, &mut out);
            }
        }
        self.add_rays(k as u64);
        out
    }

    /// Start of one light path: origin, direction and carried power.
    fn emit(&self, e: &Emitter, power: Vec3, count: u32, u: [f32; 5]) -> Option<(Vec3, Vec3, Vec3)> {
        let per_path = power / count.max(1) as f32;
        match *e {
            Emitter::Sun { dir, centre, radius } => {
                let (t, b) = crate::sampling::basis(dir);
                let r = radius * u[0].sqrt();
                let phi = std::f32::consts::TAU * u[1];
                let origin = centre - dir * (radius + 1.0) + (t * phi.cos() + b * phi.sin()) * r;
                Some((origin, dir, per_path))
            }
            Emitter::Point { pos, .. } => Some((pos, uniform_sphere([u[2], u[3]]), per_path)),
            Emitter::Spot {
                pos,
                axis,
                intensity,
                cos_inner,
                cos_outer,
            } => {
                // uniform in the outer cone: weight I·s(θ)·Ω / n
                let c = 1.0 - u[2] * (1.0 - cos_outer);
                let s = (1.0 - c * c).max(0.0).sqrt();
                let phi = std::f32::consts::TAU * u[3];
                let (t, b) = crate::sampling::basis(axis);
                let dir = (axis * c + (t * phi.cos() + b * phi.sin()) * s).normalize();
                let omega = std::f32::consts::TAU * (1.0 - cos_outer);
                let w = crate::gi::smoothstep(cos_outer, cos_inner, c) * omega / count.max(1) as f32;
                Some((pos, dir, intensity * w))
            }
            Emitter::Emissive => {
                let (i, prob) = self.lights.pick(u[4]);
                let (tri_index, area, le) = self.lights.tris[i];
                let tri = &self.bvh.triangles()[tri_index as usize];
                let (b1, b2) = triangle_barycentrics([u[0], u[1]]);
                let q = tri.p[0] * (1.0 - b1 - b2) + tri.p[1] * b1 + tri.p[2] * b2;
                let nl = (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]).normalize_or_zero();
                let dir = cosine_hemisphere(nl, [u[2], u[3]]);
                // π·L_e·area of this triangle over its pick probability, per path
                let carried = le * (std::f32::consts::PI * area / prob / count.max(1) as f32);
                Some((q + nl * self.epsilon, dir, carried))
            }
        }
    }

    /// Follows one light path, depositing a VPL at each of its first
    /// `settings.bounces` surface hits.
    fn follow(&self, origin: Vec3, dir: Vec3, carried: Vec3, settings: &VplSettings, path: u32, out: &mut Vec<Vpl>) {
        let (mut origin, mut dir, mut carried) = (origin, dir, carried);
        let mut rng = Rng::new(hash(&[settings.seed, path as u64, 0x1f2]));
        for bounce in 1..=settings.bounces {
            let Some(h) = self.bvh.intersect(origin, dir, 0.0, f32::INFINITY) else {
                return;
            };
            let hit = self.bvh.surface(&h, dir);
            let (n, ng) = hit.facing_normals(dir);
            let albedo = self.albedo(&hit);
            let flux = carried * albedo;
            if flux.max_element() <= 0.0 {
                return;
            }
            out.push(Vpl {
                position: hit.position,
                normal: n,
                flux,
                albedo,
                bounce,
            });
            // Lambertian bounce, cosine-weighted: the carried power becomes the reflected power
            let wi = cosine_hemisphere(n, rng.next_2d());
            if wi.dot(ng) <= 0.0 {
                return;
            }
            origin = hit.position + ng * self.epsilon;
            dir = wi;
            carried = flux;
        }
    }
}

/// Uniform direction on the unit sphere.
fn uniform_sphere(u: [f32; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * u[1];
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A glossy receiver's highlight sits at the mirror point of the VPL and
    /// moves with the view; the Lambert term does not depend on the view.
    #[test]
    fn glossy_highlight_follows_the_mirror_point() {
        // VPL 1 above the plane y = 0, facing down; receiver: metal, roughness 0.1
        let vpl = Vpl {
            position: Vec3::new(0.0, 1.0, 0.0),
            normal: -Vec3::Y,
            flux: Vec3::ONE,
            albedo: Vec3::ONE,
            bounce: 1,
        };
        let rho = Vec3::new(0.9, 0.8, 0.5);
        let peak = |eye: Vec3| {
            // x along the line z = 0 from −2 to 2, step 0.001
            (0..=4000)
                .map(|i| -2.0 + i as f32 * 0.001)
                .map(|x| {
                    let p = Vec3::new(x, 0.0, 0.0);
                    let l = vpl.glossy_radiance_at(p, Vec3::Y, (eye - p).normalize(), rho, 0.1, 1.0, f32::INFINITY);
                    (x, l.y)
                })
                .fold((0.0, -1.0), |a, b| if b.1 > a.1 { b } else { a })
                .0
        };
        for eye_x in [-3.0f32, 0.0, 2.0, 4.0] {
            let eye = Vec3::new(eye_x, 2.0, 0.0);
            // mirror point: the VPL at height 1 and the eye at height 2 → x = eye_x / 3
            let mirror = eye_x / 3.0;
            let x = peak(eye);
            assert!(
                (x - mirror).abs() < 0.05,
                "eye x {eye_x}: peak at {x}, mirror point {mirror}"
            );
        }
        let p = Vec3::new(0.3, 0.0, 0.0);
        // a rough dielectric is dominated by its diffuse lobe: close to ρ/π · E(1 − F_d)²
        let e = vpl.irradiance_at(p, Vec3::Y, f32::INFINITY);
        let l = vpl.glossy_radiance_at(p, Vec3::Y, Vec3::Y, rho, 1.0, 0.0, f32::INFINITY);
        let lambert = rho * std::f32::consts::FRAC_1_PI * e;
        assert!(
            (l - lambert).abs().max_element() < 0.15 * lambert.max_element(),
            "{l} vs {lambert}"
        );
    }

    #[test]
    fn allocation_sums_to_n_and_gives_every_light_a_path() {
        assert_eq!(allocate(10, &[1.0, 1.0, 1.0]).iter().sum::<u32>(), 10);
        assert_eq!(allocate(480, &[100.0, 1e-3]), vec![479, 1]);
        assert_eq!(allocate(5, &[0.0, 2.0, 3.0]), vec![0, 2, 3]);
        assert_eq!(allocate(7, &[0.0, 0.0]), vec![0, 0]);
        assert_eq!(allocate(0, &[1.0]), vec![0]);
    }

    #[test]
    fn spot_power_of_a_hard_cone_is_its_solid_angle() {
        // inner = outer: a hard cone of solid angle 2π(1 − cos θ)
        let p = spot_power(3.0, 30.0, 30.0);
        let exact = 3.0 * std::f32::consts::TAU * (1.0 - 30f32.to_radians().cos());
        assert!((p - exact).abs() < 1e-3 * exact, "{p} vs {exact}");
        assert!(spot_power(3.0, 10.0, 30.0) < exact);
    }

    #[test]
    fn kronecker_points_are_in_the_unit_cube_and_spread() {
        let o = [0.1; 5];
        let pts: Vec<_> = (0..1024).map(|k| kronecker5(k, &o)).collect();
        assert!(pts.iter().flatten().all(|v| (0.0..1.0).contains(v)));
        for j in 0..5 {
            let mean = pts.iter().map(|p| p[j] as f64).sum::<f64>() / 1024.0;
            assert!((mean - 0.5).abs() < 0.01, "dim {j}: {mean}");
        }
    }
}
