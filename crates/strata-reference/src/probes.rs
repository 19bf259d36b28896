//! Baking irradiance light probes (DGB Fig. 9's static fallback) with the path
//! tracer: each probe integrates incoming radiance over the sphere (including
//! the sky and multiple bounces) and projects it onto order-2 SH.

use glam::Vec3;
use rayon::prelude::*;
use strata_scene::probes::{
    fibonacci_sphere, oct_decode, sh9, sh_band, IrradianceProbes, COSINE_LOBE, DEPTH_OCT, DEPTH_TEXELS,
};

use crate::gi::GiSettings;
use crate::sampling::{hash, Rng};
use crate::Reference;

impl Reference<'_> {
    /// Bakes a `dims` grid of probes spanning the scene's bounds (inset by 5 %
    /// per axis), `rays` paths per probe (Fibonacci-sphere directions, each a
    /// path of `settings.bounces` bounces). Probes whose rays hit back faces
    /// more than [`INSIDE_BACKFACE_FRACTION`] of the time lie inside geometry
    /// and are marked invalid. Each probe's distance map ([`IrradianceProbes::depth`])
    /// holds the moments of its rays' first-hit distances, weighted per texel by
    /// cos^[`DEPTH_SHARPNESS`] between the ray and the texel's direction, each distance
    /// clamped to [`DEPTH_RANGE`] × the grid cell's diagonal (misses count as that).
    pub fn bake_probes(&self, dims: [u32; 3], rays: u32, settings: &GiSettings) -> IrradianceProbes {
        let (lo, hi) = self.bvh().bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
        let inset = (hi - lo) * 0.05;
        self.bake_grid(IrradianceProbes::grid(lo + inset, hi - inset, dims), rays, settings)
    }

    /// Bakes the probes of `probes`' grid as [`Self::bake_probes`] does (its
    /// coefficients, validity and distance maps are replaced).
    pub fn bake_grid(&self, mut probes: IrradianceProbes, rays: u32, settings: &GiSettings) -> IrradianceProbes {
        let (lo, hi) = self.bvh().bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
        let rays = rays.max(1);
        // probe relocation: a probe on or next to a surface moves off it first
        probes.offsets = (0..probes.count())
            .into_par_iter()
            .map(|i| {
                self.relocation(probes.grid_position(i), probes.spacing, probes.dims)
                    .to_array()
            })
            .collect();
        let positions: Vec<Vec3> = (0..probes.count()).map(|i| probes.position(i)).collect();
        let far = depth_range(probes.spacing, lo, hi);
        // Each texel's lobe: the rays (the same Fibonacci directions for every probe) whose
        // weight cos^DEPTH_SHARPNESS exceeds LOBE_CUTOFF, in ray order, so a probe's
        // moments sum only the rays that matter (about 1/7 of them at 16×16).
        let lobes: Vec<Vec<(u32, f32)>> = (0..DEPTH_TEXELS)
            .into_par_iter()
            .map(|t| {
                let uv = glam::Vec2::new((t % DEPTH_OCT) as f32 + 0.5, (t / DEPTH_OCT) as f32 + 0.5) / DEPTH_OCT as f32;
                let dir = oct_decode(uv);
                (0..rays)
                    .filter_map(|k| {
                        let c = dir.dot(fibonacci_sphere(k, rays));
                        let w = if c > 0.0 { c.powi(DEPTH_SHARPNESS) } else { 0.0 };
                        (w > LOBE_CUTOFF).then_some((k, w))
                    })
                    .collect()
            })
            .collect();
        let baked: Vec<BakedProbe> = positions
            .par_iter()
            .enumerate()
            .map(|(index, &p)| {
                let mut sum = [[0.0f32; 3]; 9];
                let mut traced = 0u64;
                let mut back = 0u32;
                let mut dists = vec![far; rays as usize];
                for k in 0..rays {
                    let d = fibonacci_sphere(k, rays);
                    traced += 1;
                    let mut dist = far;
                    if let Some(h) = self.bvh().intersect(p, d, 0.0, f32::INFINITY) {
                        back += !self.bvh().surface(&h, d).front_face as u32;
                        dist = h.t.min(far);
                    }
                    dists[k as usize] = dist;
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
                let depth = std::array::from_fn(|t| {
                    let mut m = [0.0f32; 3];
                    for &(k, w) in &lobes[t] {
                        let dist = dists[k as usize];
                        m[0] += w * dist;
                        m[1] += w * dist * dist;
                        m[2] += w;
                    }
                    [m[0] / m[2].max(1e-12), m[1] / m[2].max(1e-12)]
                });
                // inside geometry: most rays leave through back faces
                (coeffs, (back as f32) < INSIDE_BACKFACE_FRACTION * rays as f32, depth)
            })
            .collect();
        probes.coeffs = baked.iter().map(|b| b.0).collect();
        probes.valid = baked.iter().map(|b| b.1).collect();
        probes.depth = baked.iter().map(|b| b.2).collect();
        probes
    }
}

impl Reference<'_> {
    /// How far a probe at grid point `g` moves (probe relocation, as in DDGI), at most
    /// 0.45 × the spacing per axis (the probe stays in its cell):
    /// - near a surface: when the plane of the nearest front face that [`RELOCATE_RAYS`]
    ///   rays find is closer than [`RELOCATE`] × the smallest spacing, along that face's
    ///   normal until it is that far. A probe on a floor otherwise sees half of its
    ///   distance map at zero and half far away, and the visibility test's variance lets
    ///   it leak through the floor;
    /// - then, if it is inside geometry (at least [`INSIDE_BACKFACE_FRACTION`] of those
    ///   rays leave through back faces, as the bake's validity test counts them): out
    ///   through the nearest back face, to [`RELOCATE`] × the smallest spacing beyond it.
    ///   A probe inside a sofa or a table top otherwise stays invalid, and the receivers
    ///   around that object blend only the probes left, often ones in its shadow. Where
    ///   that step would leave the cell, the probe stays (and the bake marks it invalid).
    pub fn relocation(&self, g: Vec3, spacing: Vec3, dims: [u32; 3]) -> Vec3 {
        let Some(min_spacing) = strata_scene::probes::min_spacing(spacing, dims) else {
            return Vec3::ZERO;
        };
        let want = RELOCATE * min_spacing;
        let limit = 0.45 * spacing;
        let off = self.off_surface(g, want).clamp(-limit, limit);
        // inside geometry: the nearest back face (its distance, the ray's direction)
        let p = g + off;
        let (mut back, mut nearest_back) = (0u32, None::<(f32, Vec3)>);
        for k in 0..RELOCATE_RAYS {
            let d = fibonacci_sphere(k, RELOCATE_RAYS);
            let Some(h) = self.bvh().intersect(p, d, 0.0, f32::INFINITY) else {
                continue;
            };
            if !self.bvh().surface(&h, d).front_face {
                back += 1;
                if nearest_back.is_none_or(|(t, _)| h.t < t) {
                    nearest_back = Some((h.t, d));
                }
            }
        }
        self.add_rays(RELOCATE_RAYS as u64);
        if (back as f32) < INSIDE_BACKFACE_FRACTION * RELOCATE_RAYS as f32 {
            return off;
        }
        match nearest_back {
            Some((t, d)) if (off + d * (t + want)).abs().cmple(limit).all() => off + d * (t + want),
            _ => off,
        }
    }

    /// The move that takes a probe at `p` to `want` from the plane of the nearest front face
    /// within `want` (zero when there is none).
    fn off_surface(&self, p: Vec3, want: f32) -> Vec3 {
        // (distance to the face's plane, its normal towards the probe)
        let mut nearest: Option<(f32, Vec3)> = None;
        for k in 0..RELOCATE_RAYS {
            let d = fibonacci_sphere(k, RELOCATE_RAYS);
            let Some(h) = self.bvh().intersect(p, d, 0.0, want) else {
                continue;
            };
            let s = self.bvh().surface(&h, d);
            if !s.front_face {
                continue;
            }
            let plane = h.t * d.dot(s.geometric_normal).abs();
            if nearest.is_none_or(|(t, _)| plane < t) {
                nearest = Some((plane, s.geometric_normal));
            }
        }
        self.add_rays(RELOCATE_RAYS as u64);
        nearest.map_or(Vec3::ZERO, |(t, n)| n * (want - t))
    }
}

/// Probes nearer than this fraction of the smallest probe spacing to a front face are
/// moved off it ([`Reference::relocation`]).
pub const RELOCATE: f32 = 0.25;

/// Rays per probe that look for the nearest surface before relocation.
pub const RELOCATE_RAYS: u32 = 256;

/// One probe's irradiance coefficients, validity and distance map.
type BakedProbe = ([[f32; 3]; 9], bool, [[f32; 2]; DEPTH_TEXELS]);

/// Exponent of the cosine lobe that spreads a ray's distance over the distance
/// map's texels (about a texel's width at 16 × 16, as DDGI's).
pub const DEPTH_SHARPNESS: i32 = 50;

/// The distance maps hold first-hit distances clamped to this many grid-cell diagonals
/// (DDGI's 1.5): a receiver is never farther than one diagonal from the probes it blends,
/// so longer distances tell its visibility test nothing — and a miss stored as a long
/// distance inflates the variance of every texel whose lobe it reaches, which
/// Chebyshev's bound then reads as "visible" (sky light leaking through a wall into the
/// room's concave edges; docs/radiosity.md § "Distance-map range").
pub const DEPTH_RANGE: f32 = 1.5;

/// [`DEPTH_RANGE`] × the diagonal of a grid cell of `spacing`, or twice the scene's
/// diagonal (`lo`..`hi`) where that is shorter.
pub fn depth_range(spacing: Vec3, lo: Vec3, hi: Vec3) -> f32 {
    (DEPTH_RANGE * spacing.length()).min(2.0 * (hi - lo).length()).max(1e-3)
}

/// Ray weights below this are left out of a distance-map texel's moments (at cos⁵⁰, rays
/// more than 44° off the texel's direction; on the warehouse the moments moved by at most
/// 4.4e-4 relative, the irradiance coefficients not at all).
pub const LOBE_CUTOFF: f32 = 1e-7;

/// A probe whose rays hit back faces this often is inside geometry (invalid).
pub const INSIDE_BACKFACE_FRACTION: f32 = 0.25;

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;
    use strata_scene::{shapes::MeshBuilder, Material, Object, Scene, SceneSettings};

    /// A one-mesh scene of grey diffuse geometry.
    fn grey_scene(name: &str, geo: MeshBuilder) -> Scene {
        Scene {
            name: name.into(),
            meshes: vec![geo.build(name, 0)],
            objects: vec![Object {
                name: name.into(),
                mesh: 0,
                transform: Mat4::IDENTITY,
                animation: None,
            }],
            materials: vec![Material::diffuse("grey", [0.5; 3])],
            settings: SceneSettings::default(),
            ..Default::default()
        }
    }

    /// A probe grid whose lower layer lies on a 10 cm slab's top face: relocation lifts
    /// those probes by RELOCATE × the smallest spacing (1 m here), leaves the upper layer
    /// where it was, and the lifted probe's distance map then hides it from a ceiling
    /// receiver under the slab.
    #[test]
    fn probes_on_a_floor_move_off_it_and_do_not_leak_through() {
        let mut geo = MeshBuilder::new();
        geo.cuboid(Vec3::new(-10.0, -0.1, -10.0), Vec3::new(10.0, 0.0, 10.0));
        let scene = grey_scene("slab", geo);
        let grid = IrradianceProbes::grid(Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), [2, 2, 1]);
        let probes = Reference::new(&scene, 0.0).bake_grid(grid, 1024, &GiSettings::default());
        for i in 0..probes.count() {
            let moved = probes.position(i) - probes.grid_position(i);
            let want = if probes.grid_position(i).y == 0.0 {
                RELOCATE
            } else {
                0.0
            };
            assert!(
                (moved - Vec3::new(0.0, want, 0.0)).length() < 0.02,
                "probe {i} at {}: moved by {moved}",
                probes.grid_position(i)
            );
        }
        assert!(probes.valid.iter().all(|&v| v));
        // under the slab, a ceiling (normal down) below probe 0
        let v = probes.visibility(0, Vec3::new(-1.0, -0.3, 0.0), -Vec3::Y, Vec3::ZERO);
        assert!(v < 0.05, "the lifted probe still sees through the slab: visibility {v}");
    }

    /// Two probes 1 m either side of a wall (x = 0, 10 cm thick) and a receiver
    /// 0.5 m in front of it: the distance map of the probe behind the wall says the
    /// wall is about 0.95 m away towards +x (the lobe's spread adds a little), so that probe fails the
    /// visibility test and the receiver's light is the near probe's alone.
    #[test]
    fn distance_maps_hide_probes_behind_a_wall() {
        let mut geo = MeshBuilder::new();
        // a 10 cm thick slab (its faces outward: both probes see front faces)
        geo.cuboid(Vec3::new(-0.05, -10.0, -10.0), Vec3::new(0.05, 10.0, 10.0));
        let scene = grey_scene("wall", geo);
        let grid = IrradianceProbes::grid(Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), [2, 1, 1]);
        let mut probes = Reference::new(&scene, 0.0).bake_grid(grid, 1024, &GiSettings::default());
        let [mean, mean2] = probes.depth_moments(0, Vec3::X);
        // the lobe averages slanted rays (0.95 / cos θ): at least the wall's distance, at most 15 % more
        assert!(
            (0.95..1.1).contains(&mean),
            "probe 0 towards the wall: mean distance {mean}"
        );
        assert!(probes.valid.iter().all(|&v| v), "both probes are outside the slab");
        assert!(mean2 >= mean * mean - 1e-4, "moments {mean}, {mean2}");
        // open side: the misses read the distance maps' range, 1.5 grid-cell diagonals
        let range = depth_range(probes.spacing, Vec3::splat(-10.0), Vec3::splat(10.0));
        assert!((range - 1.5 * 2.0).abs() < 1e-3, "range {range}");
        let [open, open2] = probes.depth_moments(0, -Vec3::X);
        assert!(
            (open - range).abs() < 1e-3 && (open2 - range * range).abs() < 1e-2,
            "open side {open}, {open2}"
        );
        // a floor-like receiver: both probes lie in its tangent plane (equal facing weights)
        let (p, n) = (Vec3::new(0.5, 0.0, 0.0), Vec3::Y);
        let far = probes.visibility(0, p, n, Vec3::ZERO);
        let near = probes.visibility(1, p, n, Vec3::ZERO);
        assert!(far < 0.01, "the probe behind the wall: visibility {far}");
        assert_eq!(near, 1.0, "the probe in front of the receiver");
        // the receiver's light: the near probe's, not a blend with the far one's
        probes.coeffs[0] = [[0.0; 3]; 9];
        probes.coeffs[0][0] = [10.0; 3];
        probes.coeffs[1] = [[0.0; 3]; 9];
        probes.coeffs[1][0] = [1.0; 3];
        let e = probes.irradiance(p, n, Vec3::ZERO).x / strata_scene::probes::sh9(n)[0];
        assert!(
            (e - 1.0).abs() < 0.05,
            "receiver in front of the wall: {e} (near probe 1, far probe 10)"
        );
        let blind = IrradianceProbes {
            depth: Vec::new(),
            ..probes.clone()
        };
        let e_blind = blind.irradiance(p, n, Vec3::ZERO).x / strata_scene::probes::sh9(n)[0];
        // trilinear weights 1/4 and 3/4: 0.25 · 10 + 0.75 · 1
        assert!(
            (e_blind - 3.25).abs() < 0.05,
            "without distance maps the far probe leaks in: {e_blind}"
        );
    }

    /// A probe 1 m behind a wall that ends 25 cm beside the line to a receiver in front of
    /// it: the texel's lobe reaches past the wall's edge, so a few of its rays miss. Stored
    /// as the scene's far distance, those misses made the texel's variance so large that
    /// Chebyshev's bound called the receiver visible (sky light leaking into a room's
    /// concave edges); clamped to the maps' range the receiver stays hidden.
    #[test]
    fn misses_in_a_lobe_do_not_make_a_hidden_receiver_visible() {
        let mut geo = MeshBuilder::new();
        // a 10 cm wall at x = 0 whose edge is at z = 0
        geo.cuboid(Vec3::new(-0.05, -10.0, -10.0), Vec3::new(0.05, 10.0, 0.0));
        let scene = grey_scene("edge", geo);
        let grid = IrradianceProbes::grid(Vec3::new(-1.0, 0.0, -0.55), Vec3::new(1.0, 0.0, -0.55), [2, 1, 1]);
        let probes = Reference::new(&scene, 0.0).bake_grid(grid, 4096, &GiSettings::default());
        let (p, n) = (Vec3::new(0.5, 0.0, -0.4), Vec3::Y);
        let d = p + n * probes.visibility_bias() - probes.position(0);
        let [mean, mean2] = probes.depth_moments(0, d.normalize());
        let wall = 0.95 / d.normalize().x;
        let sd = (mean2 - mean * mean).max(0.0).sqrt();
        let v = probes.visibility(0, p, n, Vec3::ZERO);
        eprintln!(
            "wall at {wall:.3}, texel mean {mean:.3} sd {sd:.3}, receiver at {:.3}: visibility {v:.4}",
            d.length()
        );
        assert!(
            mean > 1.02 * wall,
            "the lobe does not reach past the edge (mean {mean}, wall {wall})"
        );
        assert!(v < 0.05, "the receiver behind the wall is visible: {v}");
    }

    /// A room's inner corner between two 20 cm walls, and a probe outside, 0.67 m behind
    /// the back wall and 0.84 m along it (`interior`'s probe beside its back-left corner).
    /// The texel that holds the corner receiver's direction lies 16° from the walls'
    /// outer corner, so its lobe mixes the back wall's outer face with the open sky
    /// beyond the corner, and Chebyshev's bound on that texel passed the receiver: sky
    /// light along the room's concave edges. Moved towards a viewer inside the room
    /// (`IrradianceProbes::view_bias`), the receiver is seen farther from the outer
    /// corner and farther behind the wall, and the probe fails the test.
    #[test]
    fn a_view_bias_hides_an_inner_corner_from_a_probe_beyond_the_outer_corner() {
        let mut geo = MeshBuilder::new();
        // the left wall (room at x > 0) and the back wall (room at z > 0)
        geo.cuboid(Vec3::new(-0.2, -10.0, -0.2), Vec3::new(0.0, 10.0, 10.0));
        geo.cuboid(Vec3::new(0.0, -10.0, -0.2), Vec3::new(10.0, 10.0, 0.0));
        let scene = grey_scene("corner", geo);
        // one cell of `interior`'s grid (spacing 1.44 × 0.44 × 1.09 m: the view bias, 0.4 ×
        // the smallest, and the maps' range, 1.5 cell diagonals, are that scene's); probe 0
        // outside
        let lo = Vec3::new(0.84, 0.0, -0.67);
        let grid = IrradianceProbes::grid(lo, lo + Vec3::new(1.44, 0.437, 1.092), [2, 2, 2]);
        let probes = Reference::new(&scene, 0.0).bake_grid(grid, 4096, &GiSettings::default());
        assert!(probes.position(0).distance(lo) < 1e-4, "probe 0 stays where it is");
        // on the left wall, 1 cm from the corner, seen from inside the room
        let (p, n) = (Vec3::new(0.0, 0.08, 0.01), Vec3::X);
        let view = (Vec3::new(0.7, 0.0, 5.1) - p).normalize();
        let unbiased = probes.visibility(0, p, n, Vec3::ZERO);
        let biased = probes.visibility(0, p, n, view);
        eprintln!("visibility of the corner receiver: {unbiased:.3} without the view bias, {biased:.4} with it");
        assert!(
            unbiased > 0.3,
            "the straddling texel no longer passes the receiver: {unbiased}"
        );
        assert!(
            biased < 0.05,
            "the receiver in the corner is visible through the wall: {biased}"
        );
    }

    /// A probe whose grid point lies 10 cm inside a solid block (a sofa, a table top) moves
    /// out through the block's nearest face to RELOCATE × the smallest spacing beyond it,
    /// and is valid there; a probe beside the block stays put.
    #[test]
    fn probes_inside_an_object_step_out_through_its_nearest_face() {
        let mut geo = MeshBuilder::new();
        // a 1.2 × 0.5 × 1.2 m block on the ground; grid points at y = 0.4 inside and beside it
        geo.cuboid(Vec3::new(-0.6, 0.0, -0.6), Vec3::new(0.6, 0.5, 0.6));
        let scene = grey_scene("block", geo);
        let grid = IrradianceProbes::grid(Vec3::new(0.0, 0.4, 0.0), Vec3::new(2.0, 2.4, 2.0), [2, 2, 2]);
        let probes = Reference::new(&scene, 0.0).bake_grid(grid, 1024, &GiSettings::default());
        let want = RELOCATE * 2.0;
        let moved = probes.position(0) - probes.grid_position(0);
        assert!(
            (moved - Vec3::new(0.0, 0.1 + want, 0.0)).length() < 0.02,
            "probe 0 (inside the block's top, 10 cm under it): moved by {moved}"
        );
        assert!(probes.valid[0], "the probe above the block is outside geometry");
        for i in 1..probes.count() {
            assert_eq!(
                probes.position(i),
                probes.grid_position(i),
                "probe {i} is clear of the block"
            );
            assert!(probes.valid[i], "probe {i}");
        }
    }

    /// The bake's noise (two seeds' difference) falls as 1/√rays: 16× the paths, ¼ the
    /// noise (docs/radiosity.md § "Rays per probe").
    #[test]
    fn bake_noise_falls_as_one_over_the_root_of_the_rays() {
        let scene = strata_scene::procedural::builtin("cornell").unwrap();
        let r = Reference::new(&scene, 0.0);
        let noise = |rays: u32| {
            let bake = |seed| {
                let s = GiSettings {
                    bounces: 3,
                    seed,
                    ..Default::default()
                };
                r.bake_probes([3, 3, 3], rays, &s)
            };
            let (a, b) = (bake(0), bake(1));
            let y = Vec3::new(0.2126, 0.7152, 0.0722);
            let (mut sum, mut count) = (0.0f32, 0);
            for i in (0..a.count()).filter(|&i| a.valid[i]) {
                for n in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
                    let (ea, eb) = (a.probe_irradiance(i, n).dot(y), b.probe_irradiance(i, n).dot(y));
                    if ea + eb > 1e-4 {
                        sum += 2.0 * (ea - eb).abs() / (ea + eb);
                        count += 1;
                    }
                }
            }
            assert!(count > 20, "{count} probe normals lit");
            sum / count as f32
        };
        let (n256, n4096) = (noise(256), noise(4096));
        assert!(n256 > 0.01, "two seeds should differ at 256 paths: {n256}");
        let ratio = n4096 / n256;
        assert!(
            (0.15..0.4).contains(&ratio),
            "noise {n256} → {n4096}: ratio {ratio}, 1/√16 = 0.25"
        );
    }

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
        // the same box with outward faces is a solid: probes 0.8 m inside it, 0.4 m apart,
        // cannot step out within their cells (relocation) and stay invalid
        let mut solid = scene.clone();
        for t in solid.meshes[0].indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
        let deep = IrradianceProbes::grid(Vec3::splat(-0.2), Vec3::splat(0.2), [2, 2, 2]);
        let inside = Reference::new(&solid, 0.0).bake_grid(deep, 64, &GiSettings::default());
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
