//! Deep screen space (DSS, Nalbach, Ritschel, Seidel 2014) with the bounced
//! z-buffer: BZB §4. `--set splat=dss` of `bzb-ao`.
//!
//! Passes (profiler names), after `bzb-directions` (§3.1, shared with the AOV path):
//!
//! 1. `dss-tessellate`, `dss-fine`, `dss-filter` (§4.3, Fig. 6; compute, since
//!    wgpu has no tessellation or geometry shaders): frustum culling with a
//!    safety margin and pre-tessellation of large triangles; fine surfels placed
//!    uniformly at random on each (sub-)triangle from a hash of a world
//!    position; each discarded with probability max(1 − A/A*, 0), survivors
//!    given the ideal radius (a constant projected size). Counters give Table 2.
//! 2. `dss-shuffle` (§4.1, Fig. 5): x_p and ω_p into the interleaved
//!    hierarchical framebuffer (l_max levels stacked in one texture; level l has
//!    4^l sub-images, each holding one random pixel of every 2^l × 2^l
//!    neighbourhood).
//! 3. `dss-splat` (§4.1–4.2): one indirect instanced draw, one instance per
//!    (surfel, level, direction), into a random sub-image per level; shells
//!    (0, d_max] and (d_max·2^(l−1), d_max·2^l]; with visibility a ray–disk test
//!    and depth t² normalised per level (the bounced z-buffer, z kept per
//!    level); without, the original additive shell splatting.
//! 4. `dss-unshuffle`, `dss-reduce` (§4.2): back to pixel order; per (pixel,
//!    direction) the finest level with a hit (or the sum without visibility)
//!    into `bzb-payload`, then the AOV path's `bzb-reconstruct` and bilateral.

use glam::Vec3;
use strata_scene::Camera;

use crate::frame::{Pass, PassInfo, TargetDesc, Targets};
use crate::gpu::GpuContext;
use crate::passes::builder::{FullscreenPass, PassBuilder};
use crate::scene_gpu::GpuScene;
use crate::spiral::pcg_hash;

/// Largest l_max.
pub const MAX_LEVELS: u32 = 6;
/// Fine surfels per (sub-)triangle at most (the tessellator's amplification
/// limit, which pre-tessellation works around).
pub const MAX_FINE: u32 = 64;
/// Largest pre-tessellation factor m (m² sub-triangles).
pub const MAX_SPLIT: u32 = 64;
/// Fine surfels' area as a fraction of the ideal area A* at the triangle's
/// nearest point: fine surfels must be smaller than ideal ones for the
/// filter's keep probability A_P/A* ≤ 1 to preserve the area.
pub const FINE_RATIO: f32 = 0.25;

/// bzb-gi with visibility: ray–disk radius over the surfel radius
/// (`DSS_GI_COVER` in dss_gi_splat.wgsl). Random surfels of total area = mesh
/// area cover only 1 − e^−1 ≈ 63 % of a surface; the bounced z-buffer keeps
/// the nearest hit only, so disks ×2 (coverage 1 − e^−4 ≈ 98 %) add no energy.
pub const GI_COVER: f32 = 2.0;

/// Adjacent triangles whose planes meet at more than this angle (degrees) form a
/// crease: [`open_edges`] counts the edge as open, where GI disks stop.
pub const CREASE_DEG: f32 = 10.0;

/// Per triangle of `scene.world_triangles(0.0)`: which of its edges (a–b, b–c, c–a)
/// are open, i.e. on no other triangle, or on others only at a crease of more than
/// [`CREASE_DEG`] (either winding). Positions are matched to 10 µm. An enlarged GI
/// disk that overhangs an open edge stands in the air beyond the surface's silhouette;
/// one that overhangs a smooth edge lies on the neighbouring triangle.
pub fn open_edges(scene: &strata_scene::Scene) -> Vec<[bool; 3]> {
    let tris = scene.world_triangles(0.0);
    let key = |p: Vec3| (p * 1e5).round().as_i64vec3().to_array();
    let normal = |t: &strata_scene::model::WorldTriangle| (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize();
    let mut edges: std::collections::HashMap<_, Vec<u32>> = std::collections::HashMap::new();
    for (i, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (key(t.p[k]), key(t.p[(k + 1) % 3]));
            edges
                .entry(if a < b { (a, b) } else { (b, a) })
                .or_default()
                .push(i as u32);
        }
    }
    let cos = CREASE_DEG.to_radians().cos();
    tris.iter()
        .enumerate()
        .map(|(i, t)| {
            let n = normal(t);
            std::array::from_fn(|k| {
                let (a, b) = (key(t.p[k]), key(t.p[(k + 1) % 3]));
                let shared = &edges[&if a < b { (a, b) } else { (b, a) }];
                !shared
                    .iter()
                    .any(|&j| j != i as u32 && n.dot(normal(&tris[j as usize])).abs() >= cos)
            })
        })
        .collect()
}

/// DSS settings. Defaults: l_max = 4 (Table 3's memory is 4 levels' worth of
/// shuffled positions: 18 MB at 768×512 = 4 × 12 B per pixel), surfels of 2
/// pixels' radius, frustum culling on, inner-shell fragments redirected (§4.3).
#[derive(Clone, Debug, PartialEq)]
pub struct DssSettings {
    /// l_max: levels of the hierarchical framebuffer (1..=6).
    pub levels: u32,
    /// Ideal surfel radius in pixels (0.5..=16): A* = π (surfel_px · z · pixel size at depth 1)².
    pub surfel_px: f32,
    /// View-frustum culling of triangles before surfelization, with the largest
    /// shell radius as the safety margin.
    pub culling: bool,
    /// BZB §4.3 "More efficient use of fill rate": a level-l fragment whose receiver
    /// lies inside the level's shell is treated as if splatted on the finer level whose
    /// shell holds it (disk radius r·2^l' there) instead of being discarded
    /// ([`fragment_level`]). Off: the original DSS discard.
    pub redirect: bool,
}

impl Default for DssSettings {
    fn default() -> Self {
        Self {
            levels: 4,
            surfel_px: 2.0,
            culling: true,
            redirect: true,
        }
    }
}

impl DssSettings {
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=MAX_LEVELS).contains(&self.levels) {
            return Err(format!(
                "bzb levels {} is out of range: must be in 1..={MAX_LEVELS}",
                self.levels
            ));
        }
        if !(0.5..=16.0).contains(&self.surfel_px) {
            return Err(format!(
                "bzb surfel-size {} is out of range: must be in 0.5..=16",
                self.surfel_px
            ));
        }
        Ok(())
    }

    /// d_max for AO radius r: the outermost shell d_max·2^(l_max−1) reaches r.
    pub fn d_max(&self, r: f32) -> f32 {
        r / (1u32 << (self.levels - 1)) as f32
    }

    /// The padded plane Wp × Hp of one direction on each level (multiples of 2^(l_max−1)).
    pub fn plane(&self, w: u32, h: u32) -> [u32; 2] {
        let b = 1u32 << (self.levels - 1);
        [w.div_ceil(b) * b, h.div_ceil(b) * b]
    }
}

/// Mirrors `Dss` in `common/dss.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DssUniforms {
    pub levels: u32,
    pub directions: u32,
    pub cols: u32,
    pub rows: u32,
    pub size: [u32; 2],
    pub plane: [u32; 2],
    pub d_max: f32,
    pub t_min: f32,
    pub surfel_px: f32,
    pub fine_ratio: f32,
    pub max_fine: u32,
    pub tri_capacity: u32,
    pub fine_capacity: u32,
    pub surfel_capacity: u32,
    pub seed: u32,
    pub visibility: u32,
    pub culling: u32,
    pub triangles: u32,
    pub max_split: u32,
    /// 1 = bzb-gi (RGBA radiance payload, hit flag in alpha), 0 = bzb-ao.
    pub gi: u32,
    /// 1 = shells whose depth range misses every receiver under them are culled
    /// (BZB §4.3's min/max culling, from the AOV path's depth tiles).
    pub depth_culling: u32,
    /// 1 = inner-shell fragments are redirected to their level (§4.3), 0 = discarded.
    pub redirect: u32,
}

/// Buffer capacities (entries) for `triangles` scene triangles.
pub fn capacities(triangles: u32) -> [u32; 3] {
    let tris = (triangles.saturating_mul(8)).clamp(1 << 16, 1 << 20);
    [tris, 1 << 21, 1 << 20]
}

// ---- CPU twins of common/dss.wgsl and dss_surfelize.wgsl ----

/// `dss_hash3`: hash of a world position's bit patterns.
pub fn hash3(q: Vec3, seed: u32) -> u32 {
    pcg_hash(q.x.to_bits() ^ pcg_hash(q.y.to_bits() ^ pcg_hash(q.z.to_bits() ^ pcg_hash(seed))))
}

/// `dss_unit`: 24-bit uniform in [0, 1).
pub fn unit(h: u32) -> f32 {
    (h >> 8) as f32 / 16_777_216.0
}

/// `dss_triangle_point`: uniform point on a triangle from two uniforms.
pub fn triangle_point(v: [Vec3; 3], u: [f32; 2]) -> Vec3 {
    let su = u[0].sqrt();
    v[0] * (1.0 - su) + v[1] * (su * (1.0 - u[1])) + v[2] * (su * u[1])
}

fn layout_keys(nb: [u32; 2], level: u32, s: u32, seed: u32) -> [u32; 3] {
    let h = pcg_hash(nb[0] ^ pcg_hash(nb[1] ^ pcg_hash(level ^ pcg_hash(s ^ pcg_hash(seed ^ 0x5bd1_e995)))));
    let h2 = pcg_hash(h);
    [h | 1, h2, pcg_hash(h2)]
}

/// `dss_sigma` (§4.1, Fig. 5): the neighbourhood pixel (0..4^l, row-major in the
/// 2^l × 2^l block) that sub-image `k` of level `level` receives.
pub fn sigma(k: u32, nb: [u32; 2], level: u32, s: u32, seed: u32) -> u32 {
    let mask = (1u32 << (2 * level)) - 1;
    let [a, b, c] = layout_keys(nb, level, s, seed);
    (a.wrapping_mul((k ^ c) & mask).wrapping_add(b)) & mask
}

/// `dss_sigma_inverse`: the sub-image holding neighbourhood pixel `j`.
pub fn sigma_inverse(j: u32, nb: [u32; 2], level: u32, s: u32, seed: u32) -> u32 {
    let mask = (1u32 << (2 * level)) - 1;
    let [a, b, c] = layout_keys(nb, level, s, seed);
    let mut inv = a;
    for _ in 0..5 {
        inv = inv.wrapping_mul(2u32.wrapping_sub(a.wrapping_mul(inv)));
    }
    (inv.wrapping_mul(j.wrapping_sub(b)) & mask) ^ (c & mask)
}

/// `dss_texel`: texel of the stacked framebuffer for (level, direction s,
/// sub-image k, neighbourhood nb).
pub fn texel(level: u32, s: u32, k: u32, nb: [u32; 2], cols: u32, rows: u32, plane: [u32; 2]) -> [u32; 2] {
    let b = 1u32 << level;
    let sub = [plane[0] / b, plane[1] / b];
    [
        (s % cols) * plane[0] + (k % b) * sub[0] + nb[0],
        level * rows * plane[1] + (s / cols) * plane[1] + (k / b) * sub[1] + nb[1],
    ]
}

/// The shuffle of `dss_shuffle.wgsl`: the frame pixel a texel (level, s, k, nb)
/// receives (may lie in the padding, ≥ the frame size).
pub fn shuffle(level: u32, s: u32, k: u32, nb: [u32; 2], seed: u32) -> [u32; 2] {
    let b = 1u32 << level;
    let j = sigma(k, nb, level, s, seed);
    [nb[0] * b + j % b, nb[1] * b + j / b]
}

/// The unshuffle of `dss_unshuffle.wgsl`: (sub-image k, neighbourhood nb) of pixel `p` on `level`.
pub fn unshuffle(level: u32, s: u32, p: [u32; 2], seed: u32) -> (u32, [u32; 2]) {
    let b = 1u32 << level;
    let nb = [p[0] / b, p[1] / b];
    let off = [p[0] % b, p[1] % b];
    (sigma_inverse(off[1] * b + off[0], nb, level, s, seed), nb)
}

/// Fraction of t_min within which a disk's plane passing the receiver makes the
/// disk the receiver's own surface (WGSL twin: `DSS_COPLANAR`).
pub const COPLANAR: f32 = 0.1;

/// A ray–disk hit at `t` occludes: past t_min, and the disk's plane (centre
/// `c`, normal `ns`) does not pass within COPLANAR·t_min of the receiver `o`
/// (receivers reconstructed a few 1e-5 off their surface would otherwise see
/// their own surface's disks hit at grazing angles). WGSL: `dss_occluding_hit`.
pub fn occluding_hit(o: Vec3, c: Vec3, ns: Vec3, t: f32, t_min: f32) -> bool {
    t > t_min && (c - o).dot(ns).abs() > COPLANAR * t_min
}

/// `dss_ray_disk` (§4.2): t of o + t·d on the disk (centre c, unit normal n,
/// radius r), both faces; `None` on a miss.
pub fn ray_disk(o: Vec3, d: Vec3, c: Vec3, n: Vec3, r: f32) -> Option<f32> {
    let dn = d.dot(n);
    if dn.abs() < 1e-8 {
        return None;
    }
    let t = (c - o).dot(n) / dn;
    let q = o + t * d - c;
    if q.dot(q) > r * r {
        return None;
    }
    Some(t)
}

/// `dss_shell`: (inner, outer] of level `level`'s shell.
pub fn shell(level: u32, d_max: f32) -> (f32, f32) {
    let outer = d_max * (1u32 << level) as f32;
    (if level == 0 { 0.0 } else { 0.5 * outer }, outer)
}

/// `dss_fragment_level`: the level whose disk radius a fragment of the level-`level`
/// splat uses for a receiver at distance `dist` from the surfel, or `None` (discard).
/// `level` itself inside its shell; with `redirect` (BZB §4.3, "we compute which
/// shell around the surfel x_p belongs to and then perform the same computations as
/// if the fragment was actually placed on the corresponding level") the finer level
/// whose shell holds a receiver inside the inner radius.
pub fn fragment_level(dist: f32, level: u32, d_max: f32, redirect: bool) -> Option<u32> {
    let (inner, outer) = shell(level, d_max);
    if dist > inner && dist <= outer {
        return Some(level);
    }
    if !redirect || dist <= 0.0 || dist > inner {
        return None;
    }
    (0..level).find(|l| dist <= shell(*l, d_max).1)
}

/// `dss_surfel_subimage` (dss_splat.wgsl, §4.1): the sub-image of level
/// `level` that receives the surfel at `c` for direction `s`.
pub fn surfel_subimage(c: Vec3, level: u32, s: u32, seed: u32) -> u32 {
    let mask = (1u32 << (2 * level)) - 1;
    pcg_hash(hash3(c, seed ^ 0x2545_f491) ^ pcg_hash(level + 16 * s)) & mask
}

/// The DSS bounced z-buffer on the CPU for one receiver (pixel `p`, direction
/// `s`, origin `o`, direction `d`): the finest level l with a hit among the
/// surfels that level l's shell splatting brings to p (those in p's sub-image,
/// centre in the shell, disk enlarged to r·2^l, t > t_min), as
/// `Some((level, t))`, or `None`. With `redirect` (§4.3) level l also tests the
/// surfels inside its shell, with their own level's radius ([`fragment_level`]).
/// What dss-shuffle, dss-splat, dss-unshuffle and dss-reduce compute together.
#[allow(clippy::too_many_arguments)]
pub fn dss_hit(
    p: [u32; 2],
    s: u32,
    o: Vec3,
    n: Vec3,
    d: Vec3,
    surfels: &[Surfel],
    levels: u32,
    d_max: f32,
    t_min: f32,
    seed: u32,
    redirect: bool,
) -> Option<(u32, f32)> {
    for l in 0..levels {
        let (k, _) = unshuffle(l, s, p, seed);
        let mut best: Option<f32> = None;
        for sf in surfels {
            let dist = (o - sf.position).length();
            let Some(fl) = fragment_level(dist, l, d_max, redirect) else {
                continue;
            };
            if surfel_subimage(sf.position, l, s, seed) != k || !above_tangent_plane(o, n, sf.position) {
                continue;
            }
            let scale = (1u32 << fl) as f32;
            if let Some(t) = ray_disk(o, d, sf.position, sf.normal, sf.radius * scale) {
                if occluding_hit(o, sf.position, sf.normal, t, t_min) && best.is_none_or(|b| t < b) {
                    best = Some(t);
                }
            }
        }
        if let Some(t) = best {
            return Some((l, t));
        }
    }
    None
}

/// A surfel: a world-space disk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surfel {
    pub position: Vec3,
    pub normal: Vec3,
    pub radius: f32,
}

/// Table 2's counts: triangles after frustum culling, sub-triangles after
/// pre-tessellation, fine surfels, surfels after filtering.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct SurfelCounts {
    pub triangles_in: u32,
    pub triangles_culled: u32,
    pub subtriangles: u32,
    pub fine_surfels: u32,
    pub surfels: u32,
}

impl SurfelCounts {
    /// One line naming what the frame dropped because a surfel buffer was full
    /// (`capacity`: sub-triangles, fine surfels, surfels), and what to change;
    /// `None` when everything fitted.
    pub fn overflow(&self, capacity: [u32; 3]) -> Option<String> {
        let stages = [
            ("sub-triangles", self.subtriangles, capacity[0]),
            ("fine surfels", self.fine_surfels, capacity[1]),
            ("surfels", self.surfels, capacity[2]),
        ];
        let full: Vec<String> = stages
            .iter()
            .filter(|(_, n, cap)| n > cap)
            .map(|(what, n, cap)| format!("{n} {what} for a buffer of {cap}"))
            .collect();
        (!full.is_empty()).then(|| {
            format!(
                "dss surfelization overflowed ({}; the excess was dropped, so the frame misses those surfaces): \
                 raise surfel-size (0.5..=16 px) or lower the resolution",
                full.join(", ")
            )
        })
    }
}

/// The camera quantities surfelization needs (from `FrameUniforms`).
#[derive(Clone, Copy, Debug)]
pub struct SurfelCamera {
    pub eye: Vec3,
    pub forward: Vec3,
    pub near: f32,
    /// Unit right and up, and tan of the half-angles (x: · aspect).
    pub right: Vec3,
    pub up: Vec3,
    pub tan_x: f32,
    pub tan_y: f32,
    /// World radius of a pixel at depth 1: 2 tan(fov_y/2) / H.
    pub pixel_scale: f32,
}

impl SurfelCamera {
    pub fn new(c: &Camera, w: u32, h: u32) -> Self {
        let forward = (c.target - c.eye).normalize();
        let right = forward.cross(c.up).normalize();
        let up = right.cross(forward);
        let tan_y = (0.5 * c.fov_y_deg.to_radians()).tan();
        Self {
            eye: c.eye,
            forward,
            near: c.near,
            right,
            up,
            tan_x: tan_y * w as f32 / h as f32,
            tan_y,
            pixel_scale: 2.0 * tan_y / h as f32,
        }
    }

    /// `depth_of`: the eye distance (at least the near plane's).
    fn depth(&self, q: Vec3) -> f32 {
        (q - self.eye).length().max(self.near)
    }

    /// `min_depth`: the smallest eye distance over a triangle (at least the near plane's).
    fn min_depth(&self, v: [Vec3; 3]) -> f32 {
        super::triangle_dist2(self.eye, v).sqrt().max(self.near)
    }

    fn in_frustum(&self, v: [Vec3; 3], margin: f32) -> bool {
        let m = (v[0] + v[1] + v[2]) / 3.0;
        let rad = v
            .iter()
            .map(|p| (*p - m).length_squared())
            .fold(0.0f32, f32::max)
            .sqrt()
            + margin;
        let d = m - self.eye;
        let z = d.dot(self.forward);
        if z < self.near - rad {
            return false;
        }
        let (x, y) = (d.dot(self.right), d.dot(self.up));
        let kx = 1.0 / (1.0 + self.tan_x * self.tan_x).sqrt();
        let ky = 1.0 / (1.0 + self.tan_y * self.tan_y).sqrt();
        (x - self.tan_x * z) * kx <= rad
            && (-x - self.tan_x * z) * kx <= rad
            && (y - self.tan_y * z) * ky <= rad
            && (-y - self.tan_y * z) * ky <= rad
    }
}

fn tri_area(v: [Vec3; 3]) -> f32 {
    0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length()
}

/// `dss_surfelize.wgsl` on the CPU: the surfel cloud and Table 2's counts for
/// world triangles `tris` (same hashes; the GPU appends in another order, and
/// float rounding can differ in the last bit, so a few decisions may too).
pub fn surfelize(
    tris: &[[Vec3; 3]],
    cam: &SurfelCamera,
    s: &DssSettings,
    r: f32,
    seed: u32,
) -> (Vec<Surfel>, SurfelCounts) {
    let ideal_area = |z: f32| {
        let rr = s.surfel_px * z * cam.pixel_scale;
        std::f32::consts::PI * rr * rr
    };
    let fine_count = |v: [Vec3; 3]| (tri_area(v) / (FINE_RATIO * ideal_area(cam.min_depth(v)))).ceil();
    let margin = s.d_max(r) * (1u32 << (s.levels - 1)) as f32;
    let mut counts = SurfelCounts {
        triangles_in: tris.len() as u32,
        ..Default::default()
    };
    let mut subtris = Vec::new();
    for &v in tris {
        if tri_area(v) <= 0.0 || (s.culling && !cam.in_frustum(v, margin)) {
            continue;
        }
        counts.triangles_culled += 1;
        let n = fine_count(v);
        let m = ((n / MAX_FINE as f32).sqrt().ceil() as u32).clamp(1, MAX_SPLIT);
        let (e1, e2) = ((v[1] - v[0]) / m as f32, (v[2] - v[0]) / m as f32);
        for i in 0..m {
            for j in 0..m - i {
                let p = v[0] + i as f32 * e1 + j as f32 * e2;
                subtris.push([p, p + e1, p + e2]);
                if i + j + 1 < m {
                    subtris.push([p + e1, p + e1 + e2, p + e2]);
                }
            }
        }
    }
    counts.subtriangles = subtris.len() as u32;
    let mut surfels = Vec::new();
    for v in subtris {
        let n = fine_count(v).clamp(1.0, MAX_FINE as f32) as u32;
        let area = tri_area(v) / n as f32;
        let nor = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        for k in 0..n {
            let g = [(k as f32 + 0.5) / n as f32, ((k as f32 + 0.5) * 0.618034).fract()];
            let h = hash3(triangle_point(v, g), seed);
            let x = triangle_point(v, [unit(h), unit(pcg_hash(h))]);
            counts.fine_surfels += 1;
            let a_ideal = ideal_area(cam.depth(x));
            // keep with probability A/A* (discard max(1 − A/A*, 0); see dss_surfelize.wgsl)
            if unit(pcg_hash(hash3(x, seed ^ 0x68e3_1da4))) < area / a_ideal {
                surfels.push(Surfel {
                    position: x,
                    normal: nor,
                    radius: (a_ideal / std::f32::consts::PI).sqrt(),
                });
            }
        }
    }
    counts.surfels = surfels.len() as u32;
    (surfels, counts)
}

/// dss_splat.wgsl's receiver test: only disks centred above the receiver's
/// tangent plane (normal `n` at `o`) occlude.
pub fn above_tangent_plane(o: Vec3, n: Vec3, c: Vec3) -> bool {
    n.dot(c - o) > 0.0
}

/// Binary AO within the shells of the surfel cloud along one ray, as DSS with
/// l_max = 1 estimates it: 1 when the ray from `o` (normal `n`) along `d` hits
/// (t > t_min) a disk centred above the tangent plane within `outer` of `o`,
/// else 0 (the CPU ray tracer of the same cloud, brute force).
pub fn ray_occluded(o: Vec3, n: Vec3, d: Vec3, surfels: &[Surfel], outer: f32, t_min: f32) -> bool {
    surfels.iter().any(|sf| {
        let dist = (sf.position - o).length();
        dist > 0.0
            && dist <= outer
            && above_tangent_plane(o, n, sf.position)
            && ray_disk(o, d, sf.position, sf.normal, sf.radius)
                .is_some_and(|t| occluding_hit(o, sf.position, sf.normal, t, t_min))
    })
}

// ---- passes ----

pub const ORIGINS: TargetDesc = TargetDesc::new(
    "dss-origins",
    wgpu::TextureFormat::Rgba32Float,
    1,
    "DSS §4.1 shuffled ray origins x_p: l_max levels stacked, 4^l sub-images per level (w = 1: has a sample)",
);
pub const DIRECTIONS: TargetDesc = TargetDesc::new(
    "dss-directions",
    wgpu::TextureFormat::Rgba32Float,
    1,
    "DSS §4.1 shuffled ω_p and α (visibility on) or receiver normals (off), stacked like dss-origins",
);
pub const PAYLOAD: TargetDesc = TargetDesc::new(
    "dss-payload",
    wgpu::TextureFormat::R16Float,
    1,
    "DSS §4.2 per-level payload in the shuffled layout (occlusion of the nearest hit, or the summed shells)",
);
pub const DEPTH: TargetDesc = TargetDesc::new(
    "dss-depth",
    wgpu::TextureFormat::Depth32Float,
    1,
    "DSS §4.2 bounced z per level: t² / (d_max·2^l + r_l)² (1 = none)",
);
pub const UNSHUFFLED: TargetDesc = TargetDesc::new(
    "dss-unshuffled",
    wgpu::TextureFormat::R16Float,
    1,
    "DSS per-level payload back in pixel order: levels stacked, directions tiled as bzb-payload",
);

pub const GI_PAYLOAD: TargetDesc = TargetDesc::new(
    "dss-gi-payload",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "bzb-gi DSS per-level payload in the shuffled layout: the nearest surfel's radiance and a hit flag (alpha), or the summed π·F·L of the shells",
);
pub const GI_UNSHUFFLED: TargetDesc = TargetDesc::new(
    "dss-gi-unshuffled",
    wgpu::TextureFormat::Rgba16Float,
    1,
    "bzb-gi DSS per-level payload back in pixel order: levels stacked, directions tiled as bzb-gi-payload",
);

/// What `bzb-gi` adds to the DSS stage: the sender shading's inputs for the
/// `dss-gi-shade` pass (the resources of `bzb-gi-shade`).
pub(crate) struct DssGiInputs<'a> {
    pub gi_uniforms: &'a wgpu::Buffer,
    pub senders: &'a wgpu::Buffer,
    pub lights: &'a wgpu::Buffer,
    pub shadow_view: &'a wgpu::TextureView,
    pub sampler: &'a wgpu::Sampler,
    pub shadow_mats: &'a wgpu::Buffer,
    /// The senders' textures (`gi::sender_texels`).
    pub texels: &'a wgpu::Buffer,
}

/// Buffers of the surfelization.
struct SurfelBuffers {
    subtris: wgpu::Buffer,
    fine: wgpu::Buffer,
    surfels: wgpu::Buffer,
    counters: wgpu::Buffer,
    args: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// bzb-gi: two vec4 per surfel, the radiance of its +n and −n faces.
    radiance: Option<wgpu::Buffer>,
}

/// One surfelization compute pass (`dss-tessellate`, `dss-fine`, `dss-filter`).
pub struct SurfelizePass {
    name: &'static str,
    pipelines: Vec<wgpu::ComputePipeline>,
    group: wgpu::BindGroup,
    /// Threads of each pipeline.
    threads: Vec<u32>,
    counters: Option<wgpu::Buffer>,
}

impl Pass for SurfelizePass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: self.name,
            inputs: vec![],
            outputs: vec![],
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, _targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        if let Some(c) = &self.counters {
            encoder.clear_buffer(c, 0, None);
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(self.name),
            timestamp_writes: None,
        });
        pass.set_bind_group(0, &scene.frame_bind_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        for (p, n) in self.pipelines.iter().zip(&self.threads) {
            pass.set_pipeline(p);
            // capacities keep this within one dimension's 65535 workgroups
            pass.dispatch_workgroups(n.div_ceil(64).clamp(1, 65535), 1, 1);
        }
    }
}

/// `dss-splat`: the indirect instanced draw of shells.
pub struct DssSplatPass {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    args: wgpu::Buffer,
    visibility: bool,
    payload: &'static str,
}

impl Pass for DssSplatPass {
    fn info(&self) -> PassInfo {
        PassInfo {
            name: "dss-splat",
            inputs: vec![ORIGINS.name, DIRECTIONS.name],
            outputs: vec![self.payload],
        }
    }

    fn encode(&self, _gpu: &GpuContext, scene: &GpuScene, targets: &Targets, encoder: &mut wgpu::CommandEncoder) {
        let depth = self
            .visibility
            .then(|| crate::passes::clear_depth_attachment(&targets.get(DEPTH.name).view));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("dss-splat"),
            color_attachments: &[crate::passes::clear_attachment(&targets.get(self.payload).view)],
            depth_stencil_attachment: depth,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &scene.frame_bind_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass.draw_indirect(&self.args, 0);
    }
}

/// The DSS passes between `bzb-directions` and `bzb-reconstruct`.
pub(crate) struct DssStage {
    pub(crate) tessellate: SurfelizePass,
    pub(crate) fine: SurfelizePass,
    pub(crate) filter: SurfelizePass,
    /// bzb-gi: `dss-gi-shade`, the surfels' direct-light radiance.
    pub(crate) shade: Option<SurfelizePass>,
    pub(crate) shuffle: FullscreenPass,
    pub(crate) splat: DssSplatPass,
    pub(crate) unshuffle: FullscreenPass,
    pub(crate) reduce: FullscreenPass,
    uniforms: wgpu::Buffer,
    buffers: SurfelBuffers,
    /// The frame's W × H.
    pub(crate) size: [u32; 2],
    /// Capacities of the sub-triangle, fine-surfel and surfel buffers.
    capacity: [u32; 3],
}

macro_rules! dss_shader {
    ($file:literal) => {
        include_str!($file)
    };
}

impl DssStage {
    /// `u`: the uniforms; `triangles`: the scene's triangle buffer (3 vec4 each) and
    /// `tiles` the receivers' min/max depth tiles (`bzb-zminmax`) its shells are culled against;
    /// `payload`: the bounced z-buffer's payload target the reduction writes.
    pub fn new(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        targets: &mut Targets,
        u: &DssUniforms,
        (triangles, tiles): (&wgpu::Buffer, &wgpu::Buffer),
        payload: &'static str,
        gi: Option<DssGiInputs>,
    ) -> Result<Self, crate::RenderError> {
        use wgpu::util::DeviceExt;
        let (level_payload, unshuffled) = if gi.is_some() {
            (GI_PAYLOAD, GI_UNSHUFFLED)
        } else {
            (PAYLOAD, UNSHUFFLED)
        };
        let device = &gpu.device;
        let big = [u.cols * u.plane[0], u.levels * u.rows * u.plane[1]];
        let out = [u.cols * u.size[0], u.levels * u.rows * u.size[1]];
        let max = device.limits().max_texture_dimension_2d;
        if big.iter().chain(out.iter()).any(|d| *d > max) {
            return Err(crate::RenderError::Parameter(format!(
                "bzb levels {} × directions {}: the DSS framebuffer of {}x{} exceeds the adapter's largest texture {max}x{max} (lower levels, directions or the size)",
                u.levels, u.directions, big[0], big[1]
            )));
        }
        for d in [ORIGINS, DIRECTIONS, level_payload] {
            targets.create_sized(gpu, d, big);
        }
        if u.visibility == 1 {
            targets.create_sized(gpu, DEPTH, big);
        }
        targets.create_sized(gpu, unshuffled, out);
        let limit = device.limits().max_storage_buffer_binding_size;
        let storage =
            |label: &str, bytes: u64, extra: wgpu::BufferUsages| -> Result<wgpu::Buffer, crate::RenderError> {
                if bytes > limit {
                    return Err(crate::RenderError::Parameter(format!(
                        "DSS {label}: {bytes} bytes exceed the adapter's storage buffer binding size {limit}"
                    )));
                }
                Ok(device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | extra,
                    mapped_at_creation: false,
                }))
            };
        let none = wgpu::BufferUsages::empty();
        let buffers = SurfelBuffers {
            subtris: storage("dss-subtriangles", u.tri_capacity as u64 * 48, none)?,
            fine: storage("dss-fine-surfels", u.fine_capacity as u64 * 32, none)?,
            surfels: storage("dss-surfels", u.surfel_capacity as u64 * 32, none)?,
            counters: storage("dss-counters", 32, wgpu::BufferUsages::COPY_DST)?,
            args: storage("dss-args", 16, wgpu::BufferUsages::INDIRECT)?,
            readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("dss-counters-readback"),
                size: 32,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            radiance: match gi {
                Some(_) => Some(storage("dss-surfel-radiance", u.surfel_capacity as u64 * 32, none)?),
                None => None,
            },
        };
        let uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("dss"),
            contents: bytemuck::bytes_of(u),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });

        // surfelization: one layout for the four entry points
        let comp = wgpu::ShaderStages::COMPUTE;
        let buf = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: comp,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let rw = wgpu::BufferBindingType::Storage { read_only: false };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dss-surfelize"),
            entries: &[
                buf(0, wgpu::BufferBindingType::Uniform),
                buf(1, wgpu::BufferBindingType::Storage { read_only: true }),
                buf(2, rw),
                buf(3, rw),
                buf(4, rw),
                buf(5, rw),
                buf(6, rw),
            ],
        });
        let group = |label| {
            crate::passes::bind_group(
                device,
                label,
                &layout,
                &[
                    uniforms.as_entire_binding(),
                    triangles.as_entire_binding(),
                    buffers.subtris.as_entire_binding(),
                    buffers.fine.as_entire_binding(),
                    buffers.surfels.as_entire_binding(),
                    buffers.counters.as_entire_binding(),
                    buffers.args.as_entire_binding(),
                ],
            )
        };
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dss-surfelize"),
            bind_group_layouts: &[Some(&scene_gpu.frame_layout), Some(&layout)],
            immediate_size: 0,
        });
        let module = crate::shader::module(device, "dss-surfelize", dss_shader!("dss_surfelize.wgsl"));
        let pipeline = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pl),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let tessellate = SurfelizePass {
            name: "dss-tessellate",
            pipelines: vec![pipeline("cs_tessellate")],
            group: group("dss-tessellate"),
            threads: vec![u.triangles],
            counters: Some(buffers.counters.clone()),
        };
        let fine = SurfelizePass {
            name: "dss-fine",
            pipelines: vec![pipeline("cs_fine")],
            group: group("dss-fine"),
            threads: vec![u.tri_capacity],
            counters: None,
        };
        let filter = SurfelizePass {
            name: "dss-filter",
            pipelines: vec![pipeline("cs_filter"), pipeline("cs_args")],
            group: group("dss-filter"),
            threads: vec![u.fine_capacity, 1],
            counters: None,
        };

        let shuffle = PassBuilder::new(gpu, targets, "dss-shuffle")
            .shader("dss-shuffle", dss_shader!("dss_shuffle.wgsl"))
            .frame(scene_gpu)
            .uniforms(u)
            .read(super::ORIGINS.name)
            .read(super::DIRECTIONS.name)
            .read("npack")
            .write(ORIGINS.name)
            .write(DIRECTIONS.name)
            .build();
        let unshuffle = PassBuilder::new(gpu, targets, "dss-unshuffle")
            .shader("dss-unshuffle", dss_shader!("dss_unshuffle.wgsl"))
            .frame(scene_gpu)
            .uniforms(u)
            .read(level_payload.name)
            .write(unshuffled.name)
            .build();
        let reduce = PassBuilder::new(gpu, targets, "dss-reduce")
            .shader("dss-reduce", dss_shader!("dss_reduce.wgsl"))
            .frame(scene_gpu)
            .uniforms(u)
            .read(unshuffled.name)
            .write(payload)
            .build();
        let shade = gi
            .as_ref()
            .map(|g| Self::shade_pass(gpu, scene_gpu, u, triangles, &buffers, g));
        let splat = Self::splat_pass(
            gpu,
            scene_gpu,
            targets,
            u,
            (&uniforms, tiles, triangles),
            &buffers,
            level_payload.name,
        );
        Ok(Self {
            tessellate,
            fine,
            filter,
            shade,
            shuffle,
            splat,
            unshuffle,
            reduce,
            uniforms,
            buffers,
            size: u.size,
            capacity: [u.tri_capacity, u.fine_capacity, u.surfel_capacity],
        })
    }

    /// `tiles`: the receivers' min/max depth tiles (`bzb-zminmax`) the vertex shader culls
    /// shells against (`DssUniforms::depth_culling`).
    fn splat_pass(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        targets: &Targets,
        u: &DssUniforms,
        (uniforms, tiles, triangles): (&wgpu::Buffer, &wgpu::Buffer, &wgpu::Buffer),
        buffers: &SurfelBuffers,
        payload: &'static str,
    ) -> DssSplatPass {
        let device = &gpu.device;
        let vf = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let tex = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let buf = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: vf,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let mut entries = vec![
            buf(0, wgpu::BufferBindingType::Uniform),
            buf(1, wgpu::BufferBindingType::Storage { read_only: true }),
            tex(2),
            tex(3),
            tex(4),
        ];
        let mut resources = vec![
            uniforms.as_entire_binding(),
            buffers.surfels.as_entire_binding(),
            wgpu::BindingResource::TextureView(&targets.get(ORIGINS.name).view),
            wgpu::BindingResource::TextureView(&targets.get(DIRECTIONS.name).view),
            wgpu::BindingResource::TextureView(&targets.get("npack").view),
        ];
        entries.push(wgpu::BindGroupLayoutEntry {
            visibility: wgpu::ShaderStages::VERTEX,
            ..buf(5, wgpu::BufferBindingType::Storage { read_only: true })
        });
        resources.push(tiles.as_entire_binding());
        if let Some(r) = &buffers.radiance {
            entries.push(wgpu::BindGroupLayoutEntry {
                visibility: wgpu::ShaderStages::FRAGMENT,
                ..buf(6, wgpu::BufferBindingType::Storage { read_only: true })
            });
            resources.push(r.as_entire_binding());
            // the surfels' source triangles: GI disks end at their triangle's edges
            entries.push(wgpu::BindGroupLayoutEntry {
                visibility: wgpu::ShaderStages::FRAGMENT,
                ..buf(7, wgpu::BufferBindingType::Storage { read_only: true })
            });
            resources.push(triangles.as_entire_binding());
        }
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dss-splat"),
            entries: &entries,
        });
        let group = crate::passes::bind_group(device, "dss-splat", &layout, &resources);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dss-splat"),
            bind_group_layouts: &[Some(&scene_gpu.frame_layout), Some(&layout)],
            immediate_size: 0,
        });
        let visibility = u.visibility == 1;
        let pipeline = if buffers.radiance.is_some() {
            let module = crate::shader::module(
                device,
                "dss-gi-splat",
                concat!(include_str!("dss_splat.wgsl"), "\n", include_str!("dss_gi_splat.wgsl")),
            );
            super::splat_pipeline_with(
                device,
                "dss-splat",
                &pipeline_layout,
                &module,
                visibility,
                GI_PAYLOAD.format,
                ("fs_gi_visibility", "fs_gi_additive"),
                &[],
            )
        } else {
            let module = crate::shader::module(device, "dss-splat", dss_shader!("dss_splat.wgsl"));
            super::splat_pipeline(device, "dss-splat", &pipeline_layout, &module, visibility)
        };
        DssSplatPass {
            pipeline,
            group,
            args: buffers.args.clone(),
            visibility,
            payload,
        }
    }

    /// `dss-gi-shade` (bzb-gi, §4.3): every surfel's direct-light radiance.
    fn shade_pass(
        gpu: &GpuContext,
        scene_gpu: &GpuScene,
        u: &DssUniforms,
        triangles: &wgpu::Buffer,
        buffers: &SurfelBuffers,
        g: &DssGiInputs,
    ) -> SurfelizePass {
        let device = &gpu.device;
        let comp = wgpu::ShaderStages::COMPUTE;
        let buf = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: comp,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let ro = wgpu::BufferBindingType::Storage { read_only: true };
        let [shadow_texture, shadow_sampler] = crate::passes::shadow_map_entries(4, comp);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dss-gi-shade"),
            entries: &[
                buf(0, wgpu::BufferBindingType::Uniform),
                buf(1, ro),
                buf(2, ro),
                buf(3, ro),
                shadow_texture,
                shadow_sampler,
                buf(6, ro),
                buf(7, ro),
                buf(8, ro),
                buf(9, wgpu::BufferBindingType::Storage { read_only: false }),
                buf(10, ro),
            ],
        });
        let radiance = buffers.radiance.as_ref().expect("bzb-gi DSS has a radiance buffer");
        let group = crate::passes::bind_group(
            device,
            "dss-gi-shade",
            &layout,
            &[
                g.gi_uniforms.as_entire_binding(),
                triangles.as_entire_binding(),
                g.senders.as_entire_binding(),
                g.lights.as_entire_binding(),
                wgpu::BindingResource::TextureView(g.shadow_view),
                wgpu::BindingResource::Sampler(g.sampler),
                g.shadow_mats.as_entire_binding(),
                buffers.surfels.as_entire_binding(),
                buffers.counters.as_entire_binding(),
                radiance.as_entire_binding(),
                g.texels.as_entire_binding(),
            ],
        );
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dss-gi-shade"),
            bind_group_layouts: &[Some(&scene_gpu.frame_layout), Some(&layout)],
            immediate_size: 0,
        });
        let module = crate::shader::module(device, "dss-gi-shade", gi_sender_shader!("dss_gi_shade.wgsl"));
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("dss-gi-shade"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("cs_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        SurfelizePass {
            name: "dss-gi-shade",
            pipelines: vec![pipeline],
            group,
            threads: vec![u.surfel_capacity],
            counters: None,
        }
    }

    pub fn set_uniforms(&self, gpu: &GpuContext, u: &DssUniforms) {
        gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(u));
        self.shuffle.set_uniforms(gpu, u);
        self.unshuffle.set_uniforms(gpu, u);
        self.reduce.set_uniforms(gpu, u);
    }

    pub fn passes(&self) -> Vec<&dyn Pass> {
        let mut v: Vec<&dyn Pass> = vec![&self.tessellate, &self.fine, &self.filter];
        if let Some(p) = &self.shade {
            v.push(p);
        }
        v.extend([&self.shuffle as &dyn Pass, &self.splat, &self.unshuffle, &self.reduce]);
        v
    }

    /// Capacities of the sub-triangle, fine-surfel and surfel buffers
    /// ([`SurfelCounts::overflow`]).
    pub fn capacity(&self) -> [u32; 3] {
        self.capacity
    }

    /// Table 2's counts of the last frame (`triangles_in` = `triangles`); counts
    /// beyond a buffer's capacity are reported (and were dropped).
    pub fn read_counts(&self, gpu: &GpuContext, triangles: u32) -> Result<SurfelCounts, crate::RenderError> {
        let c = read_buffer(gpu, &self.buffers.counters, &self.buffers.readback, 32)?;
        let c: &[u32] = bytemuck::cast_slice(&c);
        Ok(SurfelCounts {
            triangles_in: triangles,
            triangles_culled: c[3],
            subtriangles: c[0],
            fine_surfels: c[1],
            surfels: c[2],
        })
    }

    /// bzb-gi: the radiance of the last frame's first `count` surfels (same
    /// order as [`Self::read_surfels`]): (towards +n incl. emission, towards −n).
    pub fn read_radiance(&self, gpu: &GpuContext, count: u32) -> Result<Vec<(Vec3, Vec3)>, crate::RenderError> {
        let Some(src) = &self.buffers.radiance else {
            return Ok(Vec::new());
        };
        let bytes = count as u64 * 32;
        if bytes == 0 {
            return Ok(Vec::new());
        }
        let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("dss-radiance-readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let data = read_buffer(gpu, src, &staging, bytes)?;
        let f: &[f32] = bytemuck::cast_slice(&data);
        Ok(f.chunks_exact(8)
            .map(|v| (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[4], v[5], v[6])))
            .collect())
    }

    /// The surfels of the last frame (in the GPU's append order).
    pub fn read_surfels(&self, gpu: &GpuContext, count: u32) -> Result<Vec<Surfel>, crate::RenderError> {
        let bytes = count as u64 * 32;
        if bytes == 0 {
            return Ok(Vec::new());
        }
        let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("dss-surfels-readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let data = read_buffer(gpu, &self.buffers.surfels, &staging, bytes)?;
        let f: &[f32] = bytemuck::cast_slice(&data);
        Ok(f.chunks_exact(8)
            .map(|v| Surfel {
                position: Vec3::new(v[0], v[1], v[2]),
                radius: v[3],
                normal: Vec3::new(v[4], v[5], v[6]),
            })
            .collect())
    }
}

/// GPU bytes of the DSS buffers and targets (Table 3's rows).
pub fn memory(u: &DssUniforms) -> DssMemory {
    let big = (u.cols * u.plane[0]) as u64 * (u.levels * u.rows * u.plane[1]) as u64;
    let out = (u.cols * u.size[0]) as u64 * (u.levels * u.rows * u.size[1]) as u64;
    // AO's payload is one f16 (occlusion), GI's four (radiance and the hit flag): BZB
    // Table 3's "float textures" against "3D vectors"; GI also keeps each surfel's radiance
    let payload = if u.gi != 0 { 8 } else { 2 };
    let surfel_radiance = if u.gi != 0 { u.surfel_capacity as u64 * 32 } else { 0 };
    DssMemory {
        shuffled_positions: big * 16,
        shuffled_directions: big * 16,
        layered_framebuffer: big * (payload + if u.visibility == 1 { 4 } else { 0 }) + out * payload,
        framebuffer_layout: 0,
        surfels: u.tri_capacity as u64 * 48
            + u.fine_capacity as u64 * 32
            + u.surfel_capacity as u64 * 32
            + surfel_radiance,
    }
}

/// Table 3's rows for DSS (bytes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct DssMemory {
    pub shuffled_positions: u64,
    pub shuffled_directions: u64,
    /// Per-level payload and bounced z, and the unshuffled levels.
    pub layered_framebuffer: u64,
    /// 0: the layout is a hashed affine permutation computed in the shaders, not lookup textures.
    pub framebuffer_layout: u64,
    /// Sub-triangle, fine-surfel and surfel buffers at capacity.
    pub surfels: u64,
}

impl DssMemory {
    /// Every row of Table 3.
    pub fn total(&self) -> u64 {
        self.shuffled_positions
            + self.shuffled_directions
            + self.layered_framebuffer
            + self.framebuffer_layout
            + self.surfels
    }
}

fn read_buffer(
    gpu: &GpuContext,
    src: &wgpu::Buffer,
    staging: &wgpu::Buffer,
    bytes: u64,
) -> Result<Vec<u8>, crate::RenderError> {
    let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("dss-readback"),
    });
    enc.copy_buffer_to_buffer(src, 0, staging, 0, bytes);
    gpu.queue.submit([enc.finish()]);
    let data = gpu.read_buffer(staging)?;
    Ok(data)
}

#[cfg(test)]
mod overflow_tests {
    use super::SurfelCounts;

    /// A full buffer is named with its count and capacity and the setting to
    /// change; counts at capacity are not an overflow.
    #[test]
    fn overflow_names_the_full_buffer_and_the_setting() {
        let c = SurfelCounts {
            triangles_in: 10,
            triangles_culled: 10,
            subtriangles: 100,
            fine_surfels: 5000,
            surfels: 300,
        };
        assert_eq!(c.overflow([100, 5000, 300]), None);
        let m = c.overflow([100, 4096, 300]).expect("fine surfels overflowed");
        assert!(m.contains("5000 fine surfels for a buffer of 4096"), "{m}");
        assert!(m.contains("surfel-size (0.5..=16 px)") && !m.contains('\n'), "{m}");
        assert!(
            !m.contains("sub-triangles") && !m.contains(" surfels for a buffer of 300"),
            "{m}"
        );
    }
}

#[cfg(test)]
mod fragment_level_tests {
    use super::{fragment_level, shell};

    /// Every distance in (0, d_max·2^(l_max−1)] has exactly one shell; a level-l
    /// fragment keeps its own level there, and with §4.3's redirection a receiver
    /// inside the inner radius goes to the level whose shell holds it.
    #[test]
    fn redirection_finds_the_shell_holding_the_receiver() {
        let d_max = 0.125;
        for i in 1..=4000 {
            let dist = i as f32 * 1e-3 * 0.25;
            let own: Vec<u32> = (0..4)
                .filter(|l| fragment_level(dist, *l, d_max, false).is_some())
                .collect();
            if dist > shell(3, d_max).1 {
                assert!(own.is_empty(), "{dist} beyond the outermost shell");
                continue;
            }
            assert_eq!(own.len(), 1, "{dist}: levels {own:?}");
            let home = own[0];
            let (inner, outer) = shell(home, d_max);
            assert!(dist > inner && dist <= outer);
            for l in 0..4 {
                let redirected = fragment_level(dist, l, d_max, true);
                let expect = if l >= home { Some(home) } else { None };
                assert_eq!(redirected, expect, "{dist} splatted on level {l}");
            }
        }
        assert_eq!(fragment_level(0.0, 2, d_max, true), None);
    }
}

#[cfg(test)]
mod open_edge_tests {
    use super::{open_edges, CREASE_DEG};
    use glam::Vec3;
    use strata_scene::model::{Material, Mesh, Object};
    use strata_scene::Scene;

    /// A scene of one mesh per list of triangles.
    fn scene(meshes: &[Vec<[Vec3; 3]>]) -> Scene {
        let mut s = Scene {
            materials: vec![Material::diffuse("grey", [0.5; 3])],
            ..Default::default()
        };
        for (i, tris) in meshes.iter().enumerate() {
            s.meshes.push(Mesh {
                name: format!("m{i}"),
                positions: tris.iter().flatten().map(|p| p.to_array()).collect(),
                normals: vec![[0.0, 1.0, 0.0]; 3 * tris.len()],
                uvs: vec![[0.0; 2]; 3 * tris.len()],
                indices: (0..3 * tris.len() as u32).collect(),
                material: 0,
            });
            s.objects.push(Object {
                name: format!("m{i}"),
                mesh: i,
                transform: glam::Mat4::IDENTITY,
                animation: None,
            });
        }
        s
    }

    fn quad(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> Vec<[Vec3; 3]> {
        vec![[a, b, c], [a, c, d]]
    }

    /// A flat quad's diagonal is smooth and its outline open; a cube's face diagonals
    /// are smooth and its twelve 90° edges open, even with each face in its own mesh
    /// (edges match by position); a strip folded by less than [`CREASE_DEG`] stays
    /// smooth along the fold, and one folded by more does not.
    #[test]
    fn open_edges_are_outlines_and_creases() {
        let (o, x, y, z) = (Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z);
        let flat = open_edges(&scene(&[quad(o, x, x + z, z)]));
        assert_eq!(flat, vec![[true, true, false], [false, true, true]]);

        let faces = [
            quad(o, z, z + y, y),
            quad(x, x + y, x + y + z, x + z),
            quad(o, x, x + z, z),
            quad(y, y + z, x + y + z, x + y),
            quad(o, y, x + y, x),
            quad(z, x + z, x + y + z, y + z),
        ];
        let cube = open_edges(&scene(&faces));
        let open: usize = cube.iter().flatten().filter(|&&e| e).count();
        assert_eq!(
            open, 24,
            "each of the 12 cube edges is open on both its faces: {cube:?}"
        );
        assert!(cube.iter().all(|e| e.iter().filter(|&&v| v).count() == 2));

        for (deg, fold_open) in [(0.5 * CREASE_DEG, false), (2.0 * CREASE_DEG, true)] {
            let t = deg.to_radians();
            let far = Vec3::new(1.0 + t.cos(), t.sin(), 0.0);
            let strip = open_edges(&scene(&[quad(o, x, x + z, z), quad(x, far, far + z, x + z)]));
            // the fold is the first quad's edge x → x + z (triangle 0, edge 1) and the
            // second's edge x + z → x (triangle 1, edge 2)
            assert_eq!((strip[0][1], strip[3][2]), (fold_open, fold_open), "{deg}°: {strip:?}");
        }
    }
}
