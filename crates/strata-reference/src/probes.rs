//! Baking irradiance light probes (DGB Fig. 9's static fallback) with the path
//! tracer: each probe integrates incoming radiance over the sphere (including
//! the sky and multiple bounces) and projects it onto order-2 SH.

use glam::Vec3;
use rayon::prelude::*;
use strata_scene::probes::{sh9, sh_band, IrradianceProbes, COSINE_LOBE};

use crate::gi::GiSettings;
use crate::sampling::{hash, Rng};
use crate::Reference;

impl Reference<'_> {
    /// Bakes a `dims` grid of probes spanning the scene's bounds (inset by 5 %
    /// per axis), `rays` paths per probe (Fibonacci-sphere directions, each a
    /// path of `settings.bounces` bounces). Probes whose rays hit back faces
    /// more than [`INSIDE_BACKFACE_FRACTION`] of the time lie inside geometry
    /// and are marked invalid.
    pub fn bake_probes(&self, dims: [u32; 3], rays: u32, settings: &GiSettings) -> IrradianceProbes {
        let (lo, hi) = self.bvh().bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
        let inset = (hi - lo) * 0.05;
        let mut probes = IrradianceProbes::grid(lo + inset, hi - inset, dims);
        let positions: Vec<Vec3> = (0..probes.count()).map(|i| probes.position(i)).collect();
        let rays = rays.max(1);
        let baked: Vec<([[f32; 3]; 9], bool)> = positions
            .par_iter()
            .enumerate()
            .map(|(index, &p)| {
                let mut sum = [[0.0f32; 3]; 9];
                let mut traced = 0u64;
                let mut back = 0u32;
                for k in 0..rays {
                    let d = fibonacci_sphere(k, rays);
                    traced += 1;
                    if let Some(h) = self.bvh().intersect(p, d, 0.0, f32::INFINITY) {
                        back += !self.bvh().surface(&h, d).front_face as u32;
                    }
                    let mut rng = Rng::new(hash(&[settings.seed, index as u64, k as u64]));
                    let l = self.radiance(p, d, settings, &mut rng, &mut traced);
                    let y = sh9(d);
                    for (c, yi) in sum.iter_mut().zip(y) {
                        for ch in 0..3 {
                            c[ch] += l[ch] * yi;
                        }
                    }
                }
                self.add_rays(traced);
                // L_i = 4π/M Σ L Y_i; stored as irradiance E_i = Â_l L_i
                let scale = 4.0 * std::f32::consts::PI / rays as f32;
                let coeffs = std::array::from_fn(|i| sum[i].map(|v| v * scale * COSINE_LOBE[sh_band(i)]));
                // inside geometry: most rays leave through back faces
                (coeffs, (back as f32) < INSIDE_BACKFACE_FRACTION * rays as f32)
            })
            .collect();
        probes.coeffs = baked.iter().map(|b| b.0).collect();
        probes.valid = baked.iter().map(|b| b.1).collect();
        probes
    }
}

/// A probe whose rays hit back faces this often is inside geometry (invalid).
pub const INSIDE_BACKFACE_FRACTION: f32 = 0.25;

/// The k-th of n nearly uniform unit directions (spherical Fibonacci).
fn fibonacci_sphere(k: u32, n: u32) -> Vec3 {
    let golden = 0.618_034_f32;
    let z = 1.0 - (2.0 * k as f32 + 1.0) / n as f32;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * ((k as f32 * golden).fract());
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;
    use strata_scene::{shapes::MeshBuilder, Material, Object, Scene, SceneSettings};

    /// Inside a closed box whose walls emit L and reflect nothing, every probe
    /// sees radiance L in every direction: irradiance πL for every normal.
    #[test]
    fn probes_in_a_glowing_box_see_pi_l_but_not_rect_lights() {
        let mut walls = MeshBuilder::new();
        walls.cuboid(Vec3::splat(-1.0), Vec3::splat(1.0));
        let l = 0.5;
        let mut m = Material::diffuse("glow", [0.0; 3]);
        m.emission = [l; 3];
        // walls facing inward (emission leaves front faces only)
        let mut mesh = walls.build("walls", 0);
        for t in mesh.indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
        for n in &mut mesh.normals {
            *n = n.map(|v| -v);
        }
        let mut scene = Scene {
            name: "glow".into(),
            meshes: vec![mesh],
            objects: vec![Object {
                name: "walls".into(),
                mesh: 0,
                transform: Mat4::IDENTITY,
                animation: None,
            }],
            materials: vec![m],
            settings: SceneSettings::default(),
            ..Default::default()
        };
        scene.settings.sky = [0.0; 3];
        let r = Reference::new(&scene, 0.0);
        let probes = r.bake_probes([2, 2, 2], 256, &GiSettings::default());
        assert!(
            probes.valid.iter().all(|&v| v),
            "inward-facing walls: every probe is outside geometry"
        );
        // the same box with outward faces is a solid: every probe is inside it
        let mut solid = scene.clone();
        for t in solid.meshes[0].indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
        let inside = Reference::new(&solid, 0.0).bake_probes([2, 2, 2], 64, &GiSettings::default());
        assert!(
            inside.valid.iter().all(|&v| !v),
            "probes inside a solid must be invalid"
        );
        for i in 0..probes.count() {
            for n in [Vec3::X, -Vec3::Y, Vec3::new(0.3, 0.4, -0.866).normalize()] {
                let e = probes.probe_irradiance(i, n);
                assert!(
                    (e.x - std::f32::consts::PI * l).abs() < 0.05 * std::f32::consts::PI * l,
                    "probe {i} normal {n}: {e}"
                );
            }
        }
        // the ceiling and the floor declared as rect lights: the GPU lights the receivers
        // with them directly, so the probes (indirect light only) must not see their
        // emission — only the four side walls, which still glow.
        let mut lit = scene.clone();
        let rect = |c: Vec3, u: Vec3, v: Vec3| strata_scene::Light::Rect {
            center: c,
            half_u: u,
            half_v: v,
            radiance: [l; 3],
        };
        lit.lights = vec![rect(Vec3::Y, Vec3::X, Vec3::Z), rect(-Vec3::Y, Vec3::Z, Vec3::X)];
        let probes = Reference::new(&lit, 0.0).bake_probes([2, 2, 2], 1024, &GiSettings::default());
        // oracle: L × ∫ cos over the directions whose ray leaves the box through a side wall
        let side_walls = |p: Vec3, n: Vec3| {
            let k = 20_000;
            let mut e = 0.0;
            for i in 0..k {
                let d = fibonacci_sphere(i, k);
                let c = d.dot(n);
                if c <= 0.0 {
                    continue;
                }
                // exit axis: the smallest t = (±1 − p_i) / d_i
                let t = |i: usize| (d[i].signum() - p[i]) / d[i];
                if t(1) > t(0).min(t(2)) {
                    e += c;
                }
            }
            e * 4.0 * std::f32::consts::PI / k as f32 * l
        };
        for i in 0..probes.count() {
            for n in [Vec3::Y, Vec3::X, Vec3::new(0.3, 0.4, -0.866).normalize()] {
                let e = probes.probe_irradiance(i, n).x;
                let want = side_walls(probes.position(i), n);
                assert!(
                    (e - want).abs() < 0.1 * std::f32::consts::PI * l,
                    "probe {i} normal {n}: {e}, expected {want}"
                );
            }
        }
        // every wall a rect light: no indirect light at all
        lit.lights.extend([
            rect(Vec3::X, Vec3::Y, Vec3::Z),
            rect(-Vec3::X, Vec3::Z, Vec3::Y),
            rect(Vec3::Z, Vec3::X, Vec3::Y),
            rect(-Vec3::Z, Vec3::Y, Vec3::X),
        ]);
        let dark = Reference::new(&lit, 0.0).bake_probes([2, 2, 2], 64, &GiSettings::default());
        for i in 0..dark.count() {
            let e = dark.probe_irradiance(i, Vec3::new(0.3, 0.4, -0.866).normalize());
            assert!(e.max_element().abs() < 1e-4, "probe {i}: {e}");
        }
    }
}
