//! Path-traced global illumination, diffuse and glossy.
//!
//! A surface is Lambertian with albedo ρ = `base_color × texture.rgb` unless
//! its material is `glossy`: then it has the metallic-roughness GGX BRDF of
//! [`crate::brdf`] with base colour ρ (opacity and texture alpha are ignored
//! either way; so are metallic and roughness of non-glossy materials). Light
//! comes from:
//!
//! - `Light::Sun`: irradiance `illuminance × color` on a surface facing it,
//!   arriving from `−direction`; a shadow ray to infinity;
//! - `Light::Point`: `intensity × color / d²`;
//! - `Light::Spot`: as a point light × `smoothstep(cos outer, cos inner, cos θ)`;
//! - emissive triangles (materials with `emission`): radiance `emission` from the
//!   front (counter-clockwise) face, sampled by next-event estimation with
//!   probability ∝ area × luminance;
//! - the sky: constant radiance `settings.sky` for every ray that leaves the scene.
//!
//! `Light::Rect` entries are hints for the GPU and are ignored: the reference
//! sees the matching emissive geometry instead.
//!
//! Estimator (per pixel, `spp` paths through the pixel centre): vertex 0 is the
//! primary hit. At each vertex k ≤ N (N = `bounces`) all analytic lights are
//! evaluated with shadow rays and one emissive-triangle sample is taken (NEE),
//! and a cosine-weighted bounce ray is traced; if it escapes it adds the sky
//! (the environment light), if it hits a surface that surface becomes vertex
//! k + 1 (when k < N). Emission is added only where the camera ray hits an
//! emitter — everywhere else NEE accounts for it, so nothing is counted twice.
//! Bounce directions below the geometric surface end the path.
//!
//! Glossy vertices sample [`Ggx::sample`] (lobe selection, visible normals)
//! instead of the cosine, weight the path by f·cos/pdf, and combine the two
//! ways of reaching an emissive triangle by multiple importance sampling
//! (power heuristic, β = 2): the NEE sample is weighted by
//! p_light² / (p_light² + p_brdf²), and a bounce ray that hits an emitter's front
//! face adds its emission weighted by p_brdf² / (p_light² + p_brdf²), both pdfs per solid
//! angle (p_light = P(triangle) / area · d² / cos θ_light). Lambertian vertices
//! keep NEE alone (weight 1, no emission on bounce hits), exactly as before.
//! Point, spot and sun lights are deltas: NEE only, f evaluated toward them.
//!
//! Split of the result: **direct** = emission seen by the camera ray + sky seen
//! by the camera ray + all light reaching the primary hit straight from an
//! emitter (NEE at vertex 0 and the sky through vertex 0's bounce ray);
//! **indirect** = everything reflected at least once more (vertices ≥ 1);
//! **total** = direct + indirect. N = 0 gives direct only.

use glam::Vec3;
use strata_scene::{Camera, ImageBuf, Light, Material};

use crate::brdf::Ggx;
use crate::bvh::Bvh;
use crate::sampling::{cosine_hemisphere, hash, triangle_barycentrics, Rng};
use crate::Reference;

/// Settings of the path tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GiSettings {
    /// Paths per pixel (all through the pixel centre).
    pub spp: u32,
    /// Indirect bounces N (0 = direct lighting only).
    pub bounces: u32,
    pub seed: u64,
    /// Russian roulette from vertex 3 on (unbiased; survival probability =
    /// max throughput component, capped at 0.95).
    pub russian_roulette: bool,
}

impl Default for GiSettings {
    /// 64 paths per pixel, 4 bounces, seed 0, Russian roulette on.
    fn default() -> Self {
        Self {
            spp: 64,
            bounces: 4,
            seed: 0,
            russian_roulette: true,
        }
    }
}

/// The three linear-radiance RGB images of [`Reference::gi`].
#[derive(Clone, Debug, PartialEq)]
pub struct GiImages {
    pub total: ImageBuf,
    pub direct: ImageBuf,
    pub indirect: ImageBuf,
}

/// Emissive triangles with a CDF ∝ area × luminance(emission).
pub(crate) struct EmissiveLights {
    /// (triangle index, area, emitted radiance)
    pub(crate) tris: Vec<(u32, f32, Vec3)>,
    /// Inclusive prefix sums of the weights, normalised to end at 1.
    cdf: Vec<f32>,
    /// Σ weights.
    total: f64,
}

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl EmissiveLights {
    pub(crate) fn new(bvh: &Bvh, materials: &[Material]) -> Self {
        let mut tris = Vec::new();
        let mut weights = Vec::new();
        for (i, t) in bvh.triangles().iter().enumerate() {
            let Some(m) = materials.get(t.material as usize) else {
                continue;
            };
            let e = Vec3::from(m.emission).max(Vec3::ZERO);
            let area = 0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).length();
            let w = area as f64 * luminance(e) as f64;
            if w > 0.0 && w.is_finite() {
                tris.push((i as u32, area, e));
                weights.push(w);
            }
        }
        let total: f64 = weights.iter().sum();
        let mut acc = 0.0f64;
        let cdf = weights
            .iter()
            .map(|w| {
                acc += w;
                (acc / total) as f32
            })
            .collect();
        Self { tris, cdf, total }
    }

    /// Picks a light triangle for uniform `u`: (index into `tris`, probability).
    pub(crate) fn pick(&self, u: f32) -> (usize, f32) {
        let i = self.cdf.partition_point(|&c| c <= u).min(self.tris.len() - 1);
        let w = self.tris[i].1 as f64 * luminance(self.tris[i].2) as f64;
        (i, (w / self.total) as f32)
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// (probability of picking, area) of the emitter with triangle index `tri`, if it is one.
    pub(crate) fn find(&self, tri: u32) -> Option<(f32, f32)> {
        let i = self.tris.binary_search_by_key(&tri, |e| e.0).ok()?;
        let (_, area, le) = self.tris[i];
        Some(((area as f64 * luminance(le) as f64 / self.total) as f32, area))
    }
}

/// Power heuristic (β = 2) weight of the strategy with pdf `a` against `b`.
fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 && (a2 + b2).is_finite() {
        a2 / (a2 + b2)
    } else if a.is_infinite() {
        1.0
    } else {
        0.0
    }
}

pub(crate) fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    if e1 <= e0 {
        return if x >= e1 { 1.0 } else { 0.0 };
    }
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl Reference<'_> {
    /// Path-traced diffuse GI (linear RGB radiance): total, direct and indirect.
    pub fn gi(&self, camera: &Camera, width: u32, height: u32, settings: &GiSettings) -> GiImages {
        let px = self.for_each_pixel("GI", width, height, |x, y, rays| {
            let [direct, indirect] = self.gi_pixel_sum(camera, x, y, width, height, settings, 0..settings.spp, rays);
            let k = 1.0 / settings.spp.max(1) as f32;
            [direct * k, indirect * k]
        });
        let mut out = GiImages {
            total: ImageBuf::new(width, height, 3),
            direct: ImageBuf::new(width, height, 3),
            indirect: ImageBuf::new(width, height, 3),
        };
        for (i, [d, ind]) in px.iter().enumerate() {
            let t = *d + *ind;
            out.direct.data[3 * i..3 * i + 3].copy_from_slice(&d.to_array());
            out.indirect.data[3 * i..3 * i + 3].copy_from_slice(&ind.to_array());
            out.total.data[3 * i..3 * i + 3].copy_from_slice(&t.to_array());
        }
        out
    }

    /// (direct, indirect) radiance summed over the paths with sample indices in
    /// `samples` through the centre of pixel (x, y): the partial sums
    /// [`crate::converge`] accumulates. Path `s` of a pixel is the same whatever
    /// range it is traced in.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn gi_pixel_sum(
        &self,
        camera: &Camera,
        x: u32,
        y: u32,
        width: u32,
        height: u32,
        settings: &GiSettings,
        samples: std::ops::Range<u32>,
        rays: &mut u64,
    ) -> [Vec3; 2] {
        let (mut direct, mut indirect) = (Vec3::ZERO, Vec3::ZERO);
        self.gi_pixel_paths(camera, x, y, width, height, settings, samples, rays, |d, i, _| {
            direct += d;
            indirect += i;
        });
        [direct, indirect]
    }

    /// Traces the paths with sample indices in `samples` through the centre of pixel
    /// (x, y) and hands each one's (direct, indirect) radiance to `each`, with the
    /// first bounce's hit point (`None` when it left the scene or the path ended at
    /// the primary hit). [`Self::gi_pixel_sum`] sums them; the screen-space oracle
    /// ([`crate::oracle`]) sorts them by where the first bounce landed.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn gi_pixel_paths(
        &self,
        camera: &Camera,
        x: u32,
        y: u32,
        width: u32,
        height: u32,
        settings: &GiSettings,
        samples: std::ops::Range<u32>,
        rays: &mut u64,
        mut each: impl FnMut(Vec3, Vec3, Option<Vec3>),
    ) {
        let dir = camera.pixel_dir(x, y, width, height);
        let pixel = y as u64 * width as u64 + x as u64;
        // The first bounce direction (the dimension the indirect light depends
        // on most) follows the R2 sequence with a per-pixel rotation; the
        // rest of the path is random.
        let offset = {
            let mut r = Rng::new(hash(&[settings.seed, pixel, 0x0b0c]));
            [0; 4].map(|_: u8| r.next_f32() as f64)
        };
        // Every sample of the pixel starts with the same camera ray (pixel
        // centre) and so the same first vertex: its hit and its (noise-free)
        // direct light from the scene's sun/point/spot lights are found once.
        let mut memo = FirstVertex::default();
        for s in samples {
            let mut rng = Rng::new(hash(&[settings.seed, pixel, s as u64]));
            let first = Some(crate::sampling::kronecker4(s, &offset));
            let (d, i) = self.trace_path(
                camera.eye,
                camera.near,
                dir,
                settings,
                first,
                Some(&mut memo),
                &mut rng,
                rays,
            );
            each(d, i, memo.bounce);
        }
    }

    /// Radiance arriving at `origin` from direction −`dir` (one path sample) that a
    /// receiver there gets as *indirect* light: the emission, direct light and further
    /// bounces of the first surface along `dir`, or the sky — less the emission of a
    /// surface that lies on a [`Light::Rect`], whose light the GPU's direct lighting
    /// already carries (counting it here too would add it twice). Used to bake light
    /// probes.
    pub fn radiance(&self, origin: Vec3, dir: Vec3, settings: &GiSettings, rng: &mut Rng, rays: &mut u64) -> Vec3 {
        let (d, i) = self.trace_path(origin, 0.0, dir, settings, None, None, rng, rays);
        let direct_light = self.bvh.intersect(origin, dir, 0.0, f32::INFINITY).and_then(|h| {
            let hit = self.bvh.surface(&h, dir);
            (hit.front_face && self.on_rect_light(hit.position))
                .then(|| Vec3::from(self.material(hit.material).emission).max(Vec3::ZERO))
        });
        (d - direct_light.unwrap_or(Vec3::ZERO)).max(Vec3::ZERO) + i
    }

    /// One path sample of the radiance arriving at `origin` from direction −`dir`, as
    /// (the first surface's emission and direct light, or the sky; the further bounces).
    pub fn path_radiance(
        &self,
        origin: Vec3,
        dir: Vec3,
        settings: &GiSettings,
        rng: &mut Rng,
        rays: &mut u64,
    ) -> (Vec3, Vec3) {
        self.trace_path(origin, 0.0, dir, settings, None, None, rng, rays)
    }

    /// Whether `p` lies on one of the scene's [`Light::Rect`] rectangles (within 1 mm of
    /// its plane, inside its edges).
    fn on_rect_light(&self, p: Vec3) -> bool {
        self.scene.lights.iter().any(|l| match *l {
            Light::Rect {
                center, half_u, half_v, ..
            } => {
                let d = p - center;
                let n = half_u.cross(half_v).normalize_or_zero();
                let inside = |h: Vec3| d.dot(h).abs() <= h.length_squared() * (1.0 + 1e-3) + 1e-6;
                d.dot(n).abs() < 1e-3 && inside(half_u) && inside(half_v)
            }
            _ => false,
        })
    }

    /// One path from `origin` (hits beyond `t_min`) along `dir`: (direct, indirect).
    /// `first_bounces`: uniform samples of the first two bounce directions (random when `None`).
    /// `memo`: the first vertex's deterministic parts, shared by paths that all
    /// start with this same ray (filled by the first of them); the results are
    /// the same bits with or without it.
    #[allow(clippy::too_many_arguments)]
    fn trace_path(
        &self,
        origin: Vec3,
        t_min: f32,
        dir: Vec3,
        settings: &GiSettings,
        first_bounces: Option<[f32; 4]>,
        mut memo: Option<&mut FirstVertex>,
        rng: &mut Rng,
        rays: &mut u64,
    ) -> (Vec3, Vec3) {
        let sky = Vec3::from(self.scene.settings.sky);
        let (mut direct, mut indirect) = (Vec3::ZERO, Vec3::ZERO);
        if let Some(m) = memo.as_deref_mut() {
            m.bounce = None;
        }
        let first_hit = match memo.as_deref_mut() {
            Some(FirstVertex { hit: Some(h), .. }) => *h,
            _ => {
                *rays += 1;
                let h = self.bvh.intersect(origin, dir, t_min, f32::INFINITY);
                if let Some(m) = memo.as_deref_mut() {
                    m.hit = Some(h);
                }
                h
            }
        };
        let Some(h) = first_hit else {
            return (sky, indirect);
        };
        let mut hit = self.bvh.surface(&h, dir);
        if hit.front_face {
            direct += Vec3::from(self.material(hit.material).emission).max(Vec3::ZERO);
        }
        let mut wo = dir;
        let mut throughput = Vec3::ONE;
        for depth in 0..=settings.bounces {
            let sink = if depth == 0 { &mut direct } else { &mut indirect };
            let (n, ng) = hit.facing_normals(wo);
            let albedo = self.albedo(&hit);
            let p = hit.position + ng * self.epsilon;
            let sp = ShadingPoint {
                x: hit.position,
                origin: p,
                n,
                ng,
            };
            let m = self.material(hit.material);
            let ggx = m.glossy.then(|| Ggx::new(n, -wo, albedo, m.roughness, m.metallic));
            let lights = match (depth, memo.as_deref_mut()) {
                (0, Some(FirstVertex { lights: Some(e), .. })) => *e,
                (0, Some(mv)) => *mv.lights.insert(self.lights_irradiance(&sp, ggx.as_ref(), rays)),
                _ => self.lights_irradiance(&sp, ggx.as_ref(), rays),
            };
            let e = self.add_emissive(lights, &sp, ggx.as_ref(), rng, rays);
            match &ggx {
                None => *sink += throughput * albedo * e * std::f32::consts::FRAC_1_PI,
                Some(_) => *sink += throughput * e,
            }
            // MIS: a glossy vertex also collects emitters its bounce ray hits.
            let mis = ggx.is_some() && !self.lights.is_empty();

            // Bounce: at the last vertex only to collect the sky (and, glossy, emitters).
            let last = depth == settings.bounces;
            if last && sky == Vec3::ZERO && !mis {
                break;
            }
            let u = match (depth, first_bounces) {
                (0, Some(u)) => [u[0], u[1]],
                (1, Some(u)) => [u[2], u[3]],
                _ => rng.next_2d(),
            };
            let (wi, weight, brdf_pdf) = match &ggx {
                None => (cosine_hemisphere(n, u), albedo, 0.0),
                Some(g) => {
                    let wi = g.sample(rng.next_f32(), u);
                    let c = n.dot(wi);
                    let pdf = g.pdf(wi);
                    if !(c > 0.0 && pdf > 0.0) {
                        break;
                    }
                    (wi, g.eval(wi) * (c / pdf), pdf)
                }
            };
            if wi.dot(ng) <= 0.0 {
                break;
            }
            throughput *= weight;
            if !(throughput.max_element() > 0.0) || !throughput.is_finite() {
                break;
            }
            *rays += 1;
            let Some(next) = self.bvh.intersect(p, wi, 0.0, f32::INFINITY) else {
                *sink += throughput * sky;
                break;
            };
            if mis {
                if let Some((prob, area)) = self.lights.find(next.triangle) {
                    let tri = &self.bvh.triangles()[next.triangle as usize];
                    let nl = (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]).normalize_or_zero();
                    let cl = -nl.dot(wi);
                    if cl > 0.0 {
                        let le = Vec3::from(self.material(tri.material).emission).max(Vec3::ZERO);
                        let light_pdf = prob / area * next.t * next.t / cl;
                        *sink += throughput * le * power_heuristic(brdf_pdf, light_pdf);
                    }
                }
            }
            if last {
                break;
            }
            if settings.russian_roulette && depth >= 2 {
                let q = throughput.max_element().min(0.95);
                if rng.next_f32() >= q {
                    break;
                }
                throughput /= q;
            }
            hit = self.bvh.surface(&next, wi);
            if let (0, Some(m)) = (depth, memo.as_deref_mut()) {
                m.bounce = Some(hit.position);
            }
            wo = wi;
        }
        (direct, indirect)
    }

    /// Irradiance-like sum at a shading point from all lights: Σ E·max(n·l, 0)·V,
    /// to be multiplied by ρ/π. Emissive triangles contribute one NEE sample.
    /// With a GGX BRDF `brdf`, each term is also multiplied by f(v, l) (the
    /// sum is then outgoing radiance) and the emissive sample by its MIS weight.
    fn direct_irradiance(&self, sp: &ShadingPoint, brdf: Option<&Ggx>, rng: &mut Rng, rays: &mut u64) -> Vec3 {
        let e = self.lights_irradiance(sp, brdf, rays);
        self.add_emissive(e, sp, brdf, rng, rays)
    }

    /// [`Self::direct_irradiance`]'s sum over the scene's sun, point and spot
    /// lights (no random numbers: the same for every path through `sp`).
    fn lights_irradiance(&self, sp: &ShadingPoint, brdf: Option<&Ggx>, rays: &mut u64) -> Vec3 {
        let weigh = |l: Vec3, e: Vec3| match brdf {
            None => e,
            Some(g) => g.eval(l) * e,
        };
        let mut e = Vec3::ZERO;
        for light in &self.scene.lights {
            match *light {
                Light::Sun {
                    direction,
                    color,
                    illuminance,
                } => {
                    let l = -direction.normalize_or_zero();
                    let c = sp.cos(l);
                    if c > 0.0 {
                        *rays += 1;
                        if !self.bvh.occluded(sp.origin, l, 0.0, f32::INFINITY) {
                            e += weigh(l, Vec3::from(color) * illuminance * c);
                        }
                    }
                }
                Light::Point {
                    position,
                    color,
                    intensity,
                } => {
                    let (li, l) = self.point_light(sp, position, Vec3::from(color) * intensity, rays, |_| 1.0);
                    e += weigh(l, li);
                }
                Light::Spot {
                    position,
                    direction,
                    color,
                    intensity,
                    inner_deg,
                    outer_deg,
                } => {
                    let axis = direction.normalize_or_zero();
                    let (ci, co) = (inner_deg.to_radians().cos(), outer_deg.to_radians().cos());
                    let (li, l) = self.point_light(sp, position, Vec3::from(color) * intensity, rays, |to_x| {
                        smoothstep(co, ci, axis.dot(to_x))
                    });
                    e += weigh(l, li);
                }
                Light::Rect { .. } => {}
            }
        }
        e
    }

    /// `e` plus one next-event sample of the emissive triangles (when there are any).
    fn add_emissive(&self, mut e: Vec3, sp: &ShadingPoint, brdf: Option<&Ggx>, rng: &mut Rng, rays: &mut u64) -> Vec3 {
        if !self.lights.is_empty() {
            e += self.sample_emissive(sp, brdf, rng, rays);
        }
        e
    }

    /// Point-like light at `pos` with intensity `i`, times `cone(unit direction light → x)`:
    /// (irradiance-like term, unit direction toward the light).
    fn point_light(
        &self,
        sp: &ShadingPoint,
        pos: Vec3,
        i: Vec3,
        rays: &mut u64,
        cone: impl Fn(Vec3) -> f32,
    ) -> (Vec3, Vec3) {
        let to_light = pos - sp.x;
        let d2 = to_light.length_squared();
        if !(d2 > 0.0) {
            return (Vec3::ZERO, Vec3::Z);
        }
        let l = to_light / d2.sqrt();
        let c = sp.cos(l);
        if c <= 0.0 {
            return (Vec3::ZERO, l);
        }
        let k = cone(-l);
        if k <= 0.0 || !self.visible(sp.origin, pos, rays) {
            return (Vec3::ZERO, l);
        }
        (i * (k * c / d2), l)
    }

    /// One next-event-estimation sample of the emissive triangles.
    fn sample_emissive(&self, sp: &ShadingPoint, brdf: Option<&Ggx>, rng: &mut Rng, rays: &mut u64) -> Vec3 {
        let (i, prob) = self.lights.pick(rng.next_f32());
        let (tri_index, area, le) = self.lights.tris[i];
        let tri = &self.bvh.triangles()[tri_index as usize];
        let (b1, b2) = triangle_barycentrics(rng.next_2d());
        let q = tri.p[0] * (1.0 - b1 - b2) + tri.p[1] * b1 + tri.p[2] * b2;
        let nl = (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]).normalize_or_zero();
        let to_light = q - sp.x;
        let d2 = to_light.length_squared();
        if !(d2 > 0.0) {
            return Vec3::ZERO;
        }
        let l = to_light / d2.sqrt();
        let c = sp.cos(l);
        let cl = -nl.dot(l); // one-sided: the light's front face must see x
        if c <= 0.0 || cl <= 0.0 || !self.visible(sp.origin, q, rays) {
            return Vec3::ZERO;
        }
        // pdf over the light's area = prob / area.
        let e = le * (c * cl / d2 * area / prob);
        match brdf {
            None => e,
            Some(g) => {
                // per solid angle: prob / area · d² / cos θ_light
                let light_pdf = prob / area * d2 / cl;
                g.eval(l) * e * power_heuristic(light_pdf, g.pdf(l))
            }
        }
    }

    /// Shadow ray from the offset origin `p` to the point `q`, stopping
    /// [`Reference::epsilon`] short of it.
    fn visible(&self, p: Vec3, q: Vec3, rays: &mut u64) -> bool {
        let to = q - p;
        let d = to.length();
        if !(d > self.epsilon) {
            return true;
        }
        *rays += 1;
        !self.bvh.occluded(p, to / d, 0.0, d - self.epsilon)
    }
}

/// A path vertex as seen by the light sampling: the surface point `x` (for
/// distances and angles), the shadow-ray origin (offset along `ng`), and the
/// shading and geometric normals facing the incoming ray.
struct ShadingPoint {
    x: Vec3,
    origin: Vec3,
    n: Vec3,
    ng: Vec3,
}

impl ShadingPoint {
    /// `max(n·l, 0)`, and 0 when `l` points below the geometric surface.
    fn cos(&self, l: Vec3) -> f32 {
        if l.dot(self.ng) <= 0.0 {
            0.0
        } else {
            self.n.dot(l).max(0.0)
        }
    }
}

/// Settings of [`Reference::one_bounce`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OneBounceSettings {
    /// Surface samples per pixel.
    pub spp: u32,
    /// Trace X–Y visibility (false: assume mutual visibility, as screen-space
    /// radiosity does — DGB Fig. 10's "no visibility" reference).
    pub visibility: bool,
    pub seed: u64,
}

impl Default for OneBounceSettings {
    fn default() -> Self {
        Self {
            spp: 256,
            visibility: true,
            seed: 0,
        }
    }
}

impl Reference<'_> {
    /// Single-bounce indirect radiance at each pixel's primary hit X:
    /// ρ_X/π · ∫_A B(Y) cosθ_X cosθ_Y / d² · V(X, Y) dA, where B(Y) = ρ_Y/π ·
    /// E_direct(Y) is Y's Lambertian direct light toward X (emission excluded:
    /// the emitters' own light at X is direct light). Y is sampled uniformly by
    /// area over every triangle, so V can be traced or assumed 1 (DGB Fig. 10).
    pub fn one_bounce(&self, camera: &Camera, width: u32, height: u32, settings: &OneBounceSettings) -> ImageBuf {
        let tris = self.bvh.triangles();
        let mut cdf = Vec::with_capacity(tris.len());
        let mut total = 0.0f64;
        for t in tris {
            total += 0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).length() as f64;
            cdf.push(total);
        }
        let label = if settings.visibility {
            "one bounce"
        } else {
            "one bounce, no visibility"
        };
        let px = self.for_each_pixel(label, width, height, |x, y, rays| {
            let dir = camera.pixel_dir(x, y, width, height);
            *rays += 1;
            let Some(h) = self.bvh.intersect(camera.eye, dir, camera.near, f32::INFINITY) else {
                return Vec3::ZERO;
            };
            if total <= 0.0 {
                return Vec3::ZERO;
            }
            let hx = self.bvh.surface(&h, dir);
            let (nx, ngx) = hx.facing_normals(dir);
            let origin = hx.position + ngx * self.epsilon;
            let mut e = Vec3::ZERO;
            for s in 0..settings.spp {
                let mut rng = Rng::new(hash(&[settings.seed, (y * width + x) as u64, s as u64, 0x0b]));
                let u = rng.next_f32() as f64 * total;
                let ti = cdf.partition_point(|&c| c < u).min(tris.len() - 1);
                let t = &tris[ti];
                let (b1, b2) = triangle_barycentrics(rng.next_2d());
                let q = t.p[0] * (1.0 - b1 - b2) + t.p[1] * b1 + t.p[2] * b2;
                let d = q - hx.position;
                let d2 = d.length_squared();
                if !(d2 > 1e-12) {
                    continue;
                }
                let w = d / d2.sqrt();
                let cos_x = nx.dot(w);
                if cos_x <= 0.0 || ngx.dot(w) <= 0.0 {
                    continue;
                }
                let hy = self.bvh.surface(
                    &crate::bvh::Hit {
                        t: 0.0,
                        triangle: ti as u32,
                        b1,
                        b2,
                    },
                    w,
                );
                let (ny, ngy) = hy.facing_normals(w);
                let cos_y = ny.dot(-w);
                if cos_y <= 0.0 {
                    continue;
                }
                if settings.visibility && !self.visible(origin, q, rays) {
                    continue;
                }
                let sp = ShadingPoint {
                    x: q,
                    origin: q + ngy * self.epsilon,
                    n: ny,
                    ng: ngy,
                };
                let b =
                    self.albedo(&hy) * self.direct_irradiance(&sp, None, &mut rng, rays) * std::f32::consts::FRAC_1_PI;
                e += b * (cos_x * cos_y / d2);
            }
            e * (total as f32 / settings.spp.max(1) as f32) * self.albedo(&hx) * std::f32::consts::FRAC_1_PI
        });
        let mut img = ImageBuf::new(width, height, 3);
        for (o, v) in img.data.chunks_exact_mut(3).zip(&px) {
            o.copy_from_slice(&v.to_array());
        }
        img
    }
}

#[cfg(test)]
mod one_bounce_tests {
    use super::*;

    /// Area sampling with traced visibility integrates the same single bounce
    /// as the path tracer's second vertex (Cornell box: no sky); dropping
    /// visibility can only add light.
    #[test]
    fn one_bounce_matches_the_path_tracer_and_visibility_removes_light() {
        let scene = strata_scene::procedural::builtin("cornell").unwrap();
        let r = Reference::new(&scene, 0.0);
        let cam = scene.camera;
        let (w, h) = (24, 24);
        let mean = |img: &ImageBuf| img.data.iter().map(|&v| v as f64).sum::<f64>() / img.data.len() as f64;
        let traced = r.one_bounce(
            &cam,
            w,
            h,
            &OneBounceSettings {
                spp: 512,
                ..Default::default()
            },
        );
        let path = r.gi(
            &cam,
            w,
            h,
            &GiSettings {
                spp: 512,
                bounces: 1,
                russian_roulette: false,
                ..Default::default()
            },
        );
        let blind = r.one_bounce(
            &cam,
            w,
            h,
            &OneBounceSettings {
                spp: 512,
                visibility: false,
                ..Default::default()
            },
        );
        let (a, b, c) = (mean(&traced), mean(&path.indirect), mean(&blind));
        eprintln!("one bounce: area-sampled {a:.5}, path-traced {b:.5}, no visibility {c:.5}");
        assert!((a - b).abs() < 0.05 * b, "area-sampled {a} vs path-traced {b}");
        assert!(c > a * 1.02, "assuming visibility should add light: {c} vs {a}");
    }

    /// Sharing a pixel's first vertex between its samples ([`FirstVertex`])
    /// changes nothing: every path returns the same bits as when traced alone,
    /// in scenes with a sun (atrium), an emitter (cornell) and glossy
    /// surfaces with point lights (still-life), on pixels that hit and miss.
    #[test]
    fn shared_first_vertex_gives_the_same_paths() {
        for name in ["atrium", "cornell", "still-life"] {
            let scene = strata_scene::procedural::builtin(name).unwrap();
            let r = Reference::new(&scene, 0.0);
            let cam = scene.camera;
            let settings = GiSettings {
                bounces: 3,
                ..Default::default()
            };
            let (mut paths, mut hits) = (0, 0);
            for (x, y) in [(0, 0), (5, 3), (11, 7), (15, 11), (8, 0)] {
                let dir = cam.pixel_dir(x, y, 16, 12);
                hits += r.bvh.intersect(cam.eye, dir, cam.near, f32::INFINITY).is_some() as u32;
                let mut memo = FirstVertex::default();
                for s in 0..24u64 {
                    let first = Some(crate::sampling::kronecker4(s as u32, &[0.1, 0.2, 0.3, 0.4]));
                    let trace = |memo: Option<&mut FirstVertex>| {
                        let mut rng = Rng::new(hash(&[9, x as u64, y as u64, s]));
                        let mut rays = 0;
                        r.trace_path(cam.eye, cam.near, dir, &settings, first, memo, &mut rng, &mut rays)
                    };
                    let (alone, shared) = (trace(None), trace(Some(&mut memo)));
                    let bits = |v: (Vec3, Vec3)| [v.0.to_array(), v.1.to_array()].map(|a| a.map(f32::to_bits));
                    assert_eq!(bits(alone), bits(shared), "{name} pixel ({x}, {y}) sample {s}");
                    paths += ((alone.0 + alone.1).max_element() > 0.0) as u32;
                }
            }
            assert!(
                hits >= 3 && paths > 24,
                "{name}: {hits} pixels hit, {paths} paths carried light"
            );
        }
    }
}

/// The deterministic parts of a pixel's first path vertex (see
/// [`Reference::gi_pixel_sum`]): the camera ray's hit and the first vertex's
/// direct light from the sun, point and spot lights.
#[derive(Default)]
pub(crate) struct FirstVertex {
    hit: Option<Option<crate::bvh::Hit>>,
    lights: Option<Vec3>,
    /// The current path's first bounce hit (vertex 1), written by every path.
    bounce: Option<Vec3>,
}
