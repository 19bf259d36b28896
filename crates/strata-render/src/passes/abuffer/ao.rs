//! Opacity-aware multilayer AO over the A-buffer (ABA §III, Algorithm 1,
//! Eq. 3–4): `aba_ao.wgsl` and its CPU twin [`ambient_visibility_cpu`].
//!
//! Per pixel, every fragment of the list, in depth order, is a receiver at
//! `x` (its pixel centre and depth) with the camera-facing normal `n`. Its
//! ambient visibility is `w·AV(x, n) + (1 − w)·AV(x, −n)` with `w = α` for a
//! front face and `1 − α` for a back face (Eq. 3–4; exterior and interior
//! hemispheres), and the pixel's value is the front-to-back blend
//! `Σ_i T_i α_i AV_i + T` with the colour's weights ("separate" integration),
//! stopping once `T < 1e-4` like the OIT resolve.
//!
//! `AV(x, n)` is DGB Eq. 1 with Eq. 2's obscurance (so `aba-ao` and `ao` mean
//! the same radius, bias and ε on one camera) at the DGB §3.4 spiral's N taps,
//! and Algorithm 1 inside: at each tap pixel, the strongest occluder over
//! every fragment of that pixel's list, each weighted by its opacity,
//! `max_f α_f · O(x, f)`. Without `multilayer` only the nearest fragment of
//! the tap pixel occludes (classic single-layer SSAO). With compression (Eq. 5
//! on: the A-buffer's `compress`), the receivers and every tap read the M
//! nodes of the compressed lists (16-bit depth decoded at the bucket's centre,
//! 16-bit α, the fragment's Oct16 normal and facing kept beside them) instead
//! of walking the lists (ABA §III-B: one texel fetch per sample). Fragments
//! Eq. 5 evicted neither receive nor occlude; their share of the blend goes
//! to the background (visibility 1).
//!
//! Multi-resolution (ABA Table II, after Hoang & Low's MSSAO; `multires=L`,
//! [`AbaAoSettings::levels`]): each receiver hemisphere is evaluated on L
//! levels of point-sampled nodes (coarse texel (X, Y) of level k = pixel
//! (2^k X, 2^k Y)) with [`level_radius`] and combined as
//! 1 − (1 − max O_k)(1 − mean O_k); L = 1 is the single resolution.

use glam::Vec3;

use crate::frame::FrameUniforms;
use crate::passes::abuffer::{FragmentLists, T_MIN};
use crate::passes::ao::{obscurance, world_from_csz, AoUniforms};
use crate::passes::bilateral::BilateralSettings;
use crate::spiral::{self, SpiralTurns};
use strata_scene::Scene;

/// Largest accepted tap count N.
pub const MAX_SAMPLES: u32 = 256;

/// The AO kernel Algorithm 1 extends (ABA §V: a single-pass Poisson-disk SSAO
/// and, for opaque multilayer AO, HBAO).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AoKernel {
    /// DGB Eq. 1 over N spiral taps (a Poisson-like disk): AV = 1 − √(π/N · Σ a).
    Ssao = 0,
    /// Horizon-based (Bavoil et al. 2008): D directions × S steps, the highest
    /// horizon per direction; AV = 1 − mean over directions (ABA Table III: 8
    /// samples along x and y; here D = 4 directions rotated per pixel, S = 8).
    Hbao = 1,
    /// Compute-shader HBAO (ABA §V-B): [`AoKernel::Hbao`] with D = 4 and φ = 0,
    /// i.e. S steps along +x, +y, −x, −y, over the compressed nodes (Eq. 5),
    /// which each 8×8 workgroup stages with an apron in workgroup memory
    /// (`hbao_compute.wgsl`). Needs compression; separate integration only.
    HbaoCompute = 2,
}

/// Compute HBAO: pixels per side of a workgroup's tile.
pub const TILE: u32 = 8;
/// Compute HBAO: RGBA32Uint texels (4 node words each) of workgroup memory
/// for the staged nodes (16 KiB, WebGPU's guaranteed
/// `maxComputeWorkgroupStorageSize`).
pub const SHARED_TEXELS: u32 = 1024;

/// Compute HBAO: the largest apron (pixels on each side of the tile) whose
/// nodes fit in workgroup memory with `texels` texels per pixel (⌈M/4⌉ with
/// Algorithm 1, 1 for the single layer): the largest side s with s² · texels
/// ≤ [`SHARED_TEXELS`], apron = ⌊(s − [`TILE`]) / 2⌋. M = 5..8 gives 7 px,
/// M ≤ 4 and the single layer 12 px. Taps farther out read global memory.
pub fn apron(texels: u32) -> u32 {
    let mut s = TILE;
    while (s + 1) * (s + 1) * texels.max(1) <= SHARED_TEXELS {
        s += 1;
    }
    (s - TILE) / 2
}

/// Largest number of resolution levels of the multi-resolution AO (`multires`).
pub const MAX_LEVELS: u32 = 4;
/// Multi-resolution AO: the screen radius, in the level's texels, at which
/// every level but the coarsest is capped (MSSAO's typical cap, Hoang & Low).
pub const LEVEL_CAP: f32 = 5.0;

/// Largest HBAO directions D and steps S.
pub const MAX_DIRECTIONS: u32 = 16;
pub const MAX_STEPS: u32 = 32;

/// Multilayer AO settings. Defaults: N = 16 taps (ABA §V: "16 uniformly
/// distributed sample directions with depth-dependent length"), multilayer on,
/// the scene's AO radius r with β = 0.01·r and ε = 0.01·r² (as DGB AO and the
/// CPU reference), intensity 1, τ from DGB Listing 3, φ per pixel, and the
/// DGB AO's bilateral reconstruction (5 taps, 1 px apart).
#[derive(Clone, Debug, PartialEq)]
pub struct AbaAoSettings {
    /// World-space radius r; `None` = the scene's `ao_radius`.
    pub radius: Option<f32>,
    /// Bias β; `None` = 0.01·r.
    pub bias: Option<f32>,
    /// ε; `None` = 0.01·r².
    pub epsilon: Option<f32>,
    pub intensity: f32,
    /// Taps N per receiver hemisphere.
    pub samples: u32,
    pub turns: SpiralTurns,
    pub rotate: bool,
    /// Algorithm 1 (every layer occludes); false: the nearest layer only.
    pub multilayer: bool,
    /// getAO's kernel (ABA extends both).
    pub kernel: AoKernel,
    /// HBAO: screen directions D per receiver hemisphere.
    pub directions: u32,
    /// HBAO: steps S along each direction.
    pub steps: u32,
    /// Also write the colour with AO applied inside the OIT blend and the
    /// separate product (targets `hdr-aba-inside`, `hdr-aba-separate`; ABA §III's
    /// comparison). The compressed nodes hold no colour, so with it the AO walks
    /// the lists even when the A-buffer compresses.
    pub inside: bool,
    /// Bilateral reconstruction after the blend (ABA: possible because the AO is separate).
    pub blur: BilateralSettings,
    /// Multi-resolution AO (ABA Table II, after Hoang & Low's MSSAO): the
    /// number L of resolution levels (1 = off, today's single resolution).
    /// Level k reads the nodes at 1/2^k resolution, where a coarse texel
    /// (X, Y) holds exactly the nodes (or list) of full-resolution pixel
    /// (2^k X, 2^k Y) (point-sampled downsample); the levels combine as
    /// MSSAO: O = 1 − (1 − max_k O_k)(1 − mean_k O_k). See [`level_radius`].
    pub levels: u32,
}

/// Screen radius in level-`k` texels of the taps of level `k` out of
/// `levels`, for the full-resolution projected radius `r_p`: the coarsest
/// level covers the whole world radius (`r_p / 2^k`), the finer ones are
/// capped at [`LEVEL_CAP`] texels (MSSAO). With one level it is `r_p`.
pub fn level_radius(r_p: f32, k: u32, levels: u32) -> f32 {
    let r = r_p / (1u32 << k) as f32;
    if k + 1 >= levels {
        r
    } else {
        r.min(LEVEL_CAP)
    }
}

impl Default for AbaAoSettings {
    fn default() -> Self {
        let dgb = crate::passes::ao::AoSettings::default();
        Self {
            radius: None,
            bias: None,
            epsilon: None,
            intensity: 1.0,
            samples: 16,
            turns: SpiralTurns::Optimal,
            rotate: true,
            multilayer: true,
            kernel: AoKernel::Ssao,
            directions: 4,
            steps: 8,
            inside: false,
            blur: dgb.blur,
            levels: 1,
        }
    }
}

impl AbaAoSettings {
    pub fn validate(&self) -> Result<(), String> {
        // the shared checks of DGB AO (radius, bias, ε, intensity, turns, blur)
        let dgb = crate::passes::ao::AoSettings {
            radius: self.radius,
            bias: self.bias,
            epsilon: self.epsilon,
            intensity: self.intensity,
            turns: self.turns,
            blur: self.blur,
            samples: self.samples.min(crate::passes::ao::MAX_SAMPLES),
            ..Default::default()
        };
        dgb.validate()?;
        if !(1..=MAX_DIRECTIONS).contains(&self.directions) {
            return Err(format!(
                "AO directions {} is out of range: must be in 1..={MAX_DIRECTIONS}",
                self.directions
            ));
        }
        if !(1..=MAX_STEPS).contains(&self.steps) {
            return Err(format!(
                "AO steps {} is out of range: must be in 1..={MAX_STEPS}",
                self.steps
            ));
        }
        if !(1..=MAX_SAMPLES).contains(&self.samples) {
            return Err(format!(
                "AO samples {} is out of range: must be in 1..={MAX_SAMPLES}",
                self.samples
            ));
        }
        if !(1..=MAX_LEVELS).contains(&self.levels) {
            return Err(format!(
                "AO multires {} is out of range: must be in 1..={MAX_LEVELS}",
                self.levels
            ));
        }
        if self.levels > 1 && self.kernel == AoKernel::HbaoCompute {
            return Err("AO multires > 1 needs kernel ssao or hbao (hbao-compute stages one resolution)".into());
        }
        Ok(())
    }

    /// r, β, ε for `scene`.
    pub fn resolve(&self, scene: &Scene) -> (f32, f32, f32) {
        let r = self.radius.unwrap_or(scene.settings.ao_radius);
        (r, self.bias.unwrap_or(0.01 * r), self.epsilon.unwrap_or(0.01 * r * r))
    }
}

/// Mirrors `AbaAo` in `aba_ao.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AbaAoUniforms {
    pub radius: f32,
    pub bias: f32,
    pub epsilon: f32,
    pub intensity: f32,
    pub proj_scale: f32,
    pub tau: f32,
    pub samples: u32,
    pub seed: u32,
    pub rotate: u32,
    pub multilayer: u32,
    pub compressed: u32,
    /// 0 = Poisson-disk SSAO, 1 = HBAO ([`AoKernel`]).
    pub kernel: u32,
    pub directions: u32,
    pub steps: u32,
    /// Compute HBAO: the staged apron in pixels ([`apron`]); 0 otherwise.
    pub apron: u32,
    /// Multi-resolution levels L (1 = single resolution).
    pub levels: u32,
}

impl AbaAoUniforms {
    /// The uniforms of one frame (`frame`: the guard-banded frame's uniforms);
    /// `compressed`: the A-buffer keeps compressed lists.
    pub fn new(s: &AbaAoSettings, scene: &Scene, frame: &FrameUniforms, compressed: bool) -> Self {
        Self::with_nodes(s, scene, frame, compressed, 0)
    }

    /// As [`Self::new`]; `nodes` = M of the compressed lists (the compute
    /// HBAO's staged words per pixel with Algorithm 1).
    pub fn with_nodes(s: &AbaAoSettings, scene: &Scene, frame: &FrameUniforms, compressed: bool, nodes: u32) -> Self {
        let (radius, bias, epsilon) = s.resolve(scene);
        let compute = s.kernel == AoKernel::HbaoCompute;
        Self {
            radius,
            bias,
            epsilon,
            intensity: s.intensity,
            proj_scale: crate::passes::ao::proj_scale(frame),
            tau: s.turns.tau(s.samples),
            samples: s.samples,
            seed: 0,
            // compute HBAO: the axis directions, φ = 0
            rotate: (s.rotate && !compute) as u32,
            multilayer: s.multilayer as u32,
            // the inside integration needs every fragment's colour: the lists
            compressed: (compressed && !s.inside) as u32,
            kernel: s.kernel as u32,
            directions: if compute { 4 } else { s.directions },
            steps: s.steps,
            apron: if compute {
                apron(if s.multilayer { nodes.div_ceil(4) } else { 1 })
            } else {
                0
            },
            levels: if compute { 1 } else { s.levels },
        }
    }

    /// The same r, β, ε as DGB AO's uniforms, for [`obscurance`].
    fn eq2(&self) -> AoUniforms {
        AoUniforms {
            radius: self.radius,
            bias: self.bias,
            epsilon: self.epsilon,
            ..bytemuck::Zeroable::zeroed()
        }
    }
}

/// What the taps read: the read-back lists, or the compressed nodes
/// (`ABufferStage::read_compressed`) with the frame's depth scale.
pub enum Occluders<'a> {
    Lists,
    /// `nodes`: `read_compressed`; `normals`: `read_compressed_normals`.
    Compressed {
        nodes: &'a [Vec<u32>],
        normals: &'a [Vec<u32>],
        depth_scale: f32,
    },
}

/// What every tap of one pixel's evaluation reads.
struct Twin<'a> {
    lists: &'a FragmentLists,
    occ: &'a Occluders<'a>,
    frame: &'a FrameUniforms,
    u: &'a AbaAoUniforms,
}

/// A receiver: pixel `p`, position `x`, hemisphere normal `n`, depth `z`, rotation `phi`.
struct Receiver {
    p: (u32, u32),
    x: Vec3,
    n: Vec3,
    z: f32,
    phi: f32,
}

impl Twin<'_> {
    /// The pixel at offset `d` from `p`, if inside the image.
    fn tap_pixel(&self, p: (u32, u32), d: [i32; 2]) -> Option<(u32, u32)> {
        let (qx, qy) = (p.0 as i32 + d[0], p.1 as i32 + d[1]);
        let inside = qx >= 0 && qy >= 0 && qx < self.lists.width as i32 && qy < self.lists.height as i32;
        inside.then_some((qx as u32, qy as u32))
    }

    /// Algorithm 1's inner loop at tap pixel `q`.
    fn tap_occlusion(&self, q: (u32, u32), x: Vec3, n: Vec3) -> f32 {
        let centre = [q.0 as f32 + 0.5, q.1 as f32 + 0.5];
        let eq2 = self.u.eq2();
        let o = |z: f32, alpha: f32| alpha * obscurance(&eq2, world_from_csz(self.frame, centre, z) - x, n);
        let mut a = 0.0f32;
        match self.occ {
            Occluders::Compressed { nodes, depth_scale, .. } => {
                for &word in &nodes[(q.1 * self.lists.width + q.0) as usize] {
                    let alpha = (word & 0xffff) as f32 / 65535.0;
                    if alpha <= 0.0 {
                        continue;
                    }
                    let z = ((word >> 16) as f32 + 0.5) / depth_scale;
                    a = a.max(o(z, alpha));
                    if self.u.multilayer == 0 {
                        return a;
                    }
                }
            }
            Occluders::Lists => {
                let list = self.lists.at(q.0, q.1);
                if self.u.multilayer == 0 {
                    // lists are sorted by (depth, node): the first is the nearest
                    return list.first().map_or(0.0, |f| o(f.depth, f.alpha));
                }
                for f in list {
                    a = a.max(o(f.depth, f.alpha));
                }
            }
        }
        a
    }

    /// The full-resolution pixel holding level `k`'s nodes at level-`k` offset
    /// `d` from `p`'s level-`k` texel (the point-sampled downsample), if inside.
    fn level_pixel(&self, p: (u32, u32), d: [i32; 2], k: u32) -> Option<(u32, u32)> {
        let qx = ((p.0 >> k) as i32 + d[0]) << k;
        let qy = ((p.1 >> k) as i32 + d[1]) << k;
        self.tap_pixel((0, 0), [qx, qy])
    }

    /// DGB Eq. 1 over the receiver's hemisphere at level `k` (`hemisphere_av` of `aba_ao.wgsl`).
    fn ssao(&self, r: &Receiver, k: u32) -> f32 {
        let u = self.u;
        let r_p = level_radius(u.proj_scale * u.radius / r.z, k, u.levels.max(1));
        let mut sum = 0.0f32;
        for i in 0..u.samples {
            let tap = spiral::spiral_tap(i, u.samples, u.tau, r_p, r.phi);
            if let Some(q) = self.level_pixel(r.p, spiral::tap_texel(tap.offset), k) {
                sum += self.tap_occlusion(q, r.x, r.n);
            }
        }
        (1.0 - (u.intensity * std::f32::consts::PI / u.samples as f32 * sum).sqrt()).max(0.0)
    }

    /// `hemisphere_hbao` of `aba_ao.wgsl` at level `k`.
    fn hbao(&self, r: &Receiver, k: u32) -> f32 {
        let u = self.u;
        let r_p = level_radius(u.proj_scale * u.radius / r.z, k, u.levels.max(1));
        let mut sum = 0.0f32;
        for d in 0..u.directions {
            let ang = r.phi + std::f32::consts::TAU * d as f32 / u.directions as f32;
            let dir = [ang.cos(), ang.sin()];
            let mut horizon = 0.0f32;
            for s in 0..u.steps {
                let len = r_p * (s as f32 + 0.5) / u.steps as f32;
                let Some(q) = self.level_pixel(r.p, spiral::tap_texel([dir[0] * len, dir[1] * len]), k) else {
                    break;
                };
                horizon = horizon.max(self.tap_occlusion(q, r.x, r.n));
            }
            sum += horizon;
        }
        (1.0 - u.intensity * sum / u.directions as f32).max(0.0)
    }

    /// The receiver hemisphere's AV with the uniforms' kernel.
    /// (Compute HBAO is [`Self::hbao`] with the uniforms' D = 4, φ = 0: its
    /// tile staging changes where nodes are read, not what is computed.)
    fn level(&self, r: &Receiver, k: u32) -> f32 {
        if self.u.kernel != AoKernel::Ssao as u32 {
            self.hbao(r, k)
        } else {
            self.ssao(r, k)
        }
    }

    /// Multi-resolution: MSSAO's combination of the levels' occlusions
    /// O_k = 1 − AV_k, O = 1 − (1 − max O_k)(1 − mean O_k); one level: AV_0.
    fn hemisphere(&self, r: &Receiver) -> f32 {
        let levels = self.u.levels.max(1);
        if levels == 1 {
            return self.level(r, 0);
        }
        let (mut max_o, mut sum_o) = (0.0f32, 0.0f32);
        for k in 0..levels {
            let o = 1.0 - self.level(r, k);
            max_o = max_o.max(o);
            sum_o += o;
        }
        (1.0 - max_o) * (1.0 - sum_o / levels as f32)
    }
}

/// What `aba_ao.wgsl`'s `integrate` returns for a pixel: the blended AV and
/// (list path; zero with compressed receivers) the colour with AO applied
/// inside the blend and the separate product (colour blend × AV blend).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integrated {
    pub av: f32,
    pub inside: [f32; 3],
    pub separate: [f32; 3],
}

/// CPU evaluation of exactly what `aba_ao.wgsl` writes at pixel (x, y) (before
/// the bilateral filter), from the read-back lists (sorted as the GPU visits
/// them) and, for compressed taps, the compressed nodes.
pub fn ambient_visibility_cpu(
    lists: &FragmentLists,
    occ: &Occluders,
    frame: &FrameUniforms,
    u: &AbaAoUniforms,
    x: u32,
    y: u32,
) -> f32 {
    integrate_cpu(lists, occ, frame, u, x, y).av
}

/// [`ambient_visibility_cpu`] with the two colour integrations (`fs_inside`).
pub fn integrate_cpu(
    lists: &FragmentLists,
    occ: &Occluders,
    frame: &FrameUniforms,
    u: &AbaAoUniforms,
    x: u32,
    y: u32,
) -> Integrated {
    let phi = if u.rotate != 0 {
        spiral::pixel_angle(x, y, u.seed)
    } else {
        0.0
    };
    // receivers: (α, depth, normal, front facing, radiance) in depth order
    let receivers: Vec<(f32, f32, Vec3, bool, Vec3)> = match occ {
        Occluders::Lists => lists
            .at(x, y)
            .iter()
            .map(|f| {
                (
                    f.alpha,
                    f.depth,
                    Vec3::from(f.normal),
                    f.front_facing,
                    Vec3::from(f.radiance),
                )
            })
            .collect(),
        Occluders::Compressed {
            nodes,
            normals,
            depth_scale,
        } => {
            let p = (y * lists.width + x) as usize;
            nodes[p]
                .iter()
                .zip(&normals[p])
                .map(|(&word, &nf)| {
                    let n = crate::packing::oct16_unpack([nf as u8, (nf >> 8) as u8]);
                    (
                        (word & 0xffff) as f32 / 65535.0,
                        ((word >> 16) as f32 + 0.5) / depth_scale,
                        n,
                        (nf >> 16) & 1 == 1,
                        Vec3::ZERO,
                    )
                })
                .collect()
        }
    };
    let compressed = matches!(occ, Occluders::Compressed { .. });
    let twin = Twin { lists, occ, frame, u };
    let (mut av, mut t) = (0.0f32, 1.0f32);
    let (mut colour, mut inside) = (Vec3::ZERO, Vec3::ZERO);
    for (alpha, depth, n, front, radiance) in receivers {
        if t < T_MIN {
            break;
        }
        if alpha <= 0.0 {
            continue;
        }
        let pos = world_from_csz(frame, [x as f32 + 0.5, y as f32 + 0.5], depth);
        let at = |n: Vec3| Receiver {
            p: (x, y),
            x: pos,
            n,
            z: depth,
            phi,
        };
        // Eq. 3–4
        let wt = if front { alpha } else { 1.0 - alpha };
        let mut a = 0.0f32;
        if wt > 0.0 {
            a += wt * twin.hemisphere(&at(n));
        }
        if wt < 1.0 {
            a += (1.0 - wt) * twin.hemisphere(&at(-n));
        }
        av += t * alpha * a;
        colour += t * alpha * radiance;
        inside += t * alpha * a * radiance;
        t *= 1.0 - alpha;
    }
    if t >= T_MIN {
        let sky = Vec3::new(frame.sky[0], frame.sky[1], frame.sky[2]);
        av += t;
        colour += t * sky;
        inside += t * sky;
    }
    if compressed {
        (colour, inside) = (Vec3::ZERO, Vec3::ZERO);
    }
    Integrated {
        av,
        inside: inside.to_array(),
        separate: (colour * av).to_array(),
    }
}
