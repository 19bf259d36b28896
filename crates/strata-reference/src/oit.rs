//! A-buffer ground truth (ABA: Bauer et al. 2013, "Screen-Space Ambient
//! Occlusion using A-Buffer Techniques"): every surface crossing along a
//! primary ray, order-independent-transparency compositing of them, and
//! ambient occlusion with opacity. `docs/abuffer-reference.md` restates the
//! rules below for the GPU side.
//!
//! # Crossings ([`Reference::crossings`])
//!
//! The primary ray of pixel (x, y) is exactly [`Reference::primary_hit`]'s:
//! origin the eye, direction [`Camera::pixel_dir`] through the pixel centre
//! (its forward component is 1, so the ray parameter `t` *is* the linear
//! camera-space depth, the GPU's "csz"), hits with `near < t` (rasterisation
//! clips at the near plane of the reversed-Z, infinite-far projection).
//! Every hit becomes a [`Crossing`], sorted front to back by `(t, triangle)`,
//! except:
//!
//! - fragments that [`strata_scene::Material::fragment_alpha`] discards (glTF MASK below
//!   the cutoff) are no crossings;
//! - **shared edges**: a ray through an edge (or vertex) shared by triangles
//!   of one surface may hit each of them with the same `t` (the watertight
//!   test never misses both, but may report both). Rasterisation's fill rule
//!   produces one fragment there, so hits with `|t_a − t_b| ≤ 1e-6 · t_a`
//!   whose triangles belong to the same object, have the same material and the
//!   same facing are merged into one crossing (the lowest triangle index, the
//!   first in `(t, triangle)` order). Distinct surfaces at the same depth
//!   (different objects, materials or facings) stay separate crossings.
//!
//! # OIT shading model ([`shade`])
//!
//! The radiance a crossing contributes (the GPU implements exactly this):
//!
//! ```text
//! L = emission + albedo · ambient + albedo / π · Σ_lights E_l(x, n_c)
//! ```
//!
//! with `ambient = scene.settings.ambient`, `n_c` the interpolated shading
//! normal flipped to the camera's side (as [`crate::SurfaceHit::facing_normals`]
//! flips it: by the geometric normal's facing) and `E_l` the *unshadowed*
//! irradiance of light l ([`light_irradiance`]):
//!
//! - sun: `color · illuminance · max(n·l, 0)`, `l = −direction`;
//! - point: `color · intensity · max(n·l, 0) / d²`;
//! - spot: as point × `smoothstep(cos outer, cos inner, axis · (x − p)/|x − p|)`;
//! - rect: `radiance · F`, F the exact Lambert polygon form factor of the
//!   rectangle clipped to the hemisphere above x ([`rect_irradiance`], the
//!   CPU twin of `rect_irradiance` in the GPU lighting pass).
//!
//! Emissive triangles light nothing in this model and nothing casts shadows:
//! OIT tests compare *compositing* (which fragments, in which order, with
//! which α), not visibility.
//!
//! # Compositing ([`Reference::composite`])
//!
//! Front to back over the crossings, `T = 1`, `C = 0`:
//! `C += T · α_i · L_i; T *= 1 − α_i`, stopping after an opaque crossing
//! (α = 1) or as soon as `T < 1e-4`; then `C += T · sky` (the background; 0
//! after an opaque crossing, < 1e-4 · sky after an early stop).
//!
//! # AO with opacity ([`Reference::ao_with_opacity`])
//!
//! Same sampling as [`Reference::ao_binary_at`] (cosine-weighted hemisphere,
//! R2 directions rotated by the key, rays of length `radius` from the point
//! offset by [`Reference::epsilon`] along the geometric normal of the
//! sampled side). Each ray collects every crossing within the radius (MASK-cut
//! fragments excluded) and its occlusion is, in two models:
//!
//! - `strongest = max_i α_i` — the paper's strongest-occluder model
//!   (Algorithm 1's `max` over all layers);
//! - `transmittance = 1 − Π_i (1 − α_i)` — the physical one.
//!
//! Both are 1 for an opaque hit and equal for a single layer. A hemisphere's
//! ambient visibility is `1 − mean occlusion`. A receiver of opacity α is a
//! two-sided hull: exterior AO_e (hemisphere around the camera-facing normal
//! n) and interior AO_i (around −n) are combined as
//! `AO = w·AO_e + (1 − w)·AO_i` with `w = α` for a front-facing and `1 − α`
//! for a back-facing fragment (summary Eq. 3–4). Since back faces' n is
//! flipped towards the camera, this is the same as weighting the hemisphere
//! around the mesh's own (winding) normal by α, whichever side is seen.
//!
//! Per pixel ([`Reference::ao_with_opacity_image`]) the per-fragment AO is
//! blended front to back with the colour's weights (the paper's "separate"
//! integration), over a background of visibility 1:
//! `AO_pixel = Σ_i T_i α_i AO_i + T_n`, with the same stopping rule as
//! [`Reference::composite`]. See that function for why.

use glam::Vec3;
use strata_scene::{Camera, ImageBuf, Light};

use crate::ao::{pixel_key, AoBinarySettings};
use crate::bvh::{Hit, SurfaceHit};
use crate::gi::smoothstep;
use crate::sampling::{cosine_hemisphere, hash, pixel_offset, r2};
use crate::Reference;

/// Compositing stops once the transmittance falls below this.
pub const MIN_TRANSMITTANCE: f32 = 1e-4;

/// Relative depth tolerance under which two hits of one surface are the same
/// crossing (a ray through a shared edge).
pub const EDGE_MERGE_EPSILON: f32 = 1e-6;

/// One surface crossing along a primary ray (an A-buffer fragment).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    /// Linear camera-space depth (the GPU's csz); equals `t` for primary rays.
    pub depth: f32,
    /// Ray parameter along [`Camera::pixel_dir`].
    pub t: f32,
    pub position: Vec3,
    /// Interpolated shading normal, flipped to the camera's side (unit).
    pub normal: Vec3,
    /// Geometric normal, flipped to face the camera (unit).
    pub geometric_normal: Vec3,
    /// The GPU's `front_facing`: the ray arrives at the counter-clockwise side.
    pub front_facing: bool,
    /// Fragment alpha: [`strata_scene::Material::fragment_alpha`] of the texture alpha.
    pub alpha: f32,
    /// Linear albedo (`base_color × texture.rgb`).
    pub albedo: Vec3,
    pub emission: Vec3,
    /// Radiance of the OIT shading model ([`shade`]).
    pub radiance: Vec3,
    pub material: u32,
    pub triangle: u32,
    pub object: u32,
}

impl Default for Crossing {
    fn default() -> Self {
        Self {
            depth: 0.0,
            t: 0.0,
            position: Vec3::ZERO,
            normal: Vec3::Y,
            geometric_normal: Vec3::Y,
            front_facing: true,
            alpha: 1.0,
            albedo: Vec3::ZERO,
            emission: Vec3::ZERO,
            radiance: Vec3::ZERO,
            material: 0,
            triangle: 0,
            object: 0,
        }
    }
}

/// Ambient visibility in the two occluder-opacity models (1 = unoccluded).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OpacityAo {
    /// Strongest-occluder model: occlusion of a ray = max α over its crossings.
    pub strongest: f32,
    /// Transmittance model: occlusion of a ray = 1 − Π(1 − α).
    pub transmittance: f32,
}

/// Unshadowed irradiance (linear RGB) at `x` with unit normal `n` from `light`.
pub fn light_irradiance(light: &Light, x: Vec3, n: Vec3) -> Vec3 {
    let point = |pos: Vec3, i: Vec3| -> (Vec3, Vec3) {
        let d = pos - x;
        let d2 = d.length_squared();
        if !(d2 > 0.0) {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        let l = d / d2.sqrt();
        (i * n.dot(l).max(0.0) / d2, -l)
    };
    match *light {
        Light::Sun {
            direction,
            color,
            illuminance,
        } => {
            let l = -direction.normalize_or_zero();
            Vec3::from(color) * illuminance * n.dot(l).max(0.0)
        }
        Light::Point {
            position,
            color,
            intensity,
        } => point(position, Vec3::from(color) * intensity).0,
        Light::Spot {
            position,
            direction,
            color,
            intensity,
            inner_deg,
            outer_deg,
        } => {
            let (e, to_x) = point(position, Vec3::from(color) * intensity);
            let axis = direction.normalize_or_zero();
            e * smoothstep(
                outer_deg.to_radians().cos(),
                inner_deg.to_radians().cos(),
                axis.dot(to_x),
            )
        }
        Light::Rect {
            center,
            half_u,
            half_v,
            radiance,
        } => {
            let nl = half_u.cross(half_v).normalize_or_zero();
            Vec3::from(radiance) * rect_irradiance(x, n, center, half_u, half_v, nl)
        }
    }
}

/// Irradiance per unit radiance (E / L) at `p` with unit normal `n` from the
/// one-sided rectangle `c ± hu ± hv` emitting towards `nl`: Lambert's polygon
/// formula `½ |Σ_i Θ_i (n · Γ_i)|` over the rectangle clipped to the
/// hemisphere `n · x ≥ 0` around p (Sutherland–Hodgman, ≤ 5 vertices). The CPU
/// twin of the GPU lighting pass's `rect_irradiance`, step for step.
pub fn rect_irradiance(p: Vec3, n: Vec3, c: Vec3, hu: Vec3, hv: Vec3, nl: Vec3) -> f32 {
    if (p - c).dot(nl) <= 0.0 {
        return 0.0;
    }
    let q = [c - hu - hv - p, c + hu - hv - p, c + hu + hv - p, c - hu + hv - p];
    let mut poly = [Vec3::ZERO; 5];
    let mut k = 0usize;
    for i in 0..4 {
        let a = q[i];
        let b = q[(i + 1) % 4];
        let (da, db) = (a.dot(n), b.dot(n));
        if da >= 0.0 {
            poly[k] = a;
            k += 1;
        }
        if (da >= 0.0) != (db >= 0.0) {
            poly[k] = a + (b - a) * (da / (da - db));
            k += 1;
        }
    }
    if k < 3 {
        return 0.0;
    }
    let mut sum = 0.0f32;
    for i in 0..k {
        let (a, b) = (poly[i], poly[(i + 1) % k]);
        let (la, lb) = (a.length(), b.length());
        if la < 1e-12 || lb < 1e-12 {
            continue;
        }
        let (ua, ub) = (a / la, b / lb);
        let cr = ua.cross(ub);
        let s = cr.length();
        if s > 1e-9 {
            sum += s.atan2(ua.dot(ub)) * n.dot(cr / s);
        }
    }
    0.5 * sum.abs()
}

/// The OIT shading model: `L = emission + albedo · ambient + albedo/π · Σ_l E_l(x, n_c)`
/// (unshadowed [`light_irradiance`]; `n_c` the camera-facing unit shading normal).
pub fn shade(lights: &[Light], ambient: Vec3, x: Vec3, n_c: Vec3, albedo: Vec3, emission: Vec3) -> Vec3 {
    let e: Vec3 = lights.iter().map(|l| light_irradiance(l, x, n_c)).sum();
    emission + albedo * ambient + albedo * std::f32::consts::FRAC_1_PI * e
}

/// Front-to-back compositing of `crossings` (sorted by depth) over `sky`:
/// `C += T α_i L_i; T *= 1 − α_i`, stopping after an opaque crossing or when
/// `T <` [`MIN_TRANSMITTANCE`]; then `C += T · sky`. Returns (C, final T).
pub fn composite_crossings(crossings: &[Crossing], sky: Vec3) -> (Vec3, f32) {
    let mut c = Vec3::ZERO;
    let mut t = 1.0f32;
    for x in crossings {
        c += t * x.alpha * x.radiance;
        t *= 1.0 - x.alpha;
        if x.alpha >= 1.0 || t < MIN_TRANSMITTANCE {
            break;
        }
    }
    (c + t * sky, t)
}

impl Reference<'_> {
    /// The fragment alpha of a hit ([`strata_scene::Material::fragment_alpha`] of the
    /// base-colour texture's alpha at the hit's UV), or `None` when the
    /// fragment is discarded (MASK below the cutoff).
    pub fn opacity(&self, hit: &SurfaceHit) -> Option<f32> {
        let m = self.material(hit.material);
        let tex_alpha = match m.base_color_texture.and_then(|t| self.scene().textures.get(t)) {
            Some(tex)
                if m.texture_alpha
                    && tex.width > 0
                    && tex.height > 0
                    && tex.rgba8.len() >= (tex.width * tex.height * 4) as usize =>
            {
                tex.sample_linear(hit.uv)[3]
            }
            _ => 1.0,
        };
        m.fragment_alpha(tex_alpha)
    }

    /// Emitted radiance of a hit's material.
    fn emission_of(&self, hit: &SurfaceHit) -> Vec3 {
        Vec3::from(self.material(hit.material).emission)
    }

    /// Every surface crossing along the primary ray through the centre of
    /// pixel (x, y), front to back (module docs: near clipping, MASK, shared edges).
    pub fn crossings(&self, camera: &Camera, x: u32, y: u32, width: u32, height: u32) -> Vec<Crossing> {
        let mut hits = Vec::new();
        let mut out = Vec::new();
        self.crossings_into(camera, x, y, width, height, &mut hits, &mut out);
        out
    }

    #[allow(clippy::too_many_arguments)]
    fn crossings_into(
        &self,
        camera: &Camera,
        x: u32,
        y: u32,
        width: u32,
        height: u32,
        hits: &mut Vec<Hit>,
        out: &mut Vec<Crossing>,
    ) {
        out.clear();
        let dir = camera.pixel_dir(x, y, width, height);
        self.bvh()
            .intersect_all(camera.eye, dir, camera.near, f32::INFINITY, hits);
        let scene = self.scene();
        let ambient = Vec3::from(scene.settings.ambient);
        let mut last: Option<(f32, u32, u32, bool)> = None; // (t, object, material, front)
        for h in hits.iter() {
            let s = self.bvh().surface(h, dir);
            let Some(alpha) = self.opacity(&s) else { continue };
            let key = (s.t, s.object, s.material, s.front_face);
            if let Some((t0, o, m, f)) = last {
                if (o, m, f) == (key.1, key.2, key.3) && (s.t - t0).abs() <= EDGE_MERGE_EPSILON * t0.abs() {
                    continue;
                }
            }
            last = Some(key);
            let (n, ng) = s.facing_normals(dir);
            let albedo = self.albedo(&s);
            let emission = self.emission_of(&s);
            out.push(Crossing {
                depth: s.t,
                t: s.t,
                position: s.position,
                normal: n,
                geometric_normal: ng,
                front_facing: s.front_face,
                alpha,
                albedo,
                emission,
                radiance: shade(&scene.lights, ambient, s.position, n, albedo, emission),
                material: s.material,
                triangle: s.triangle,
                object: s.object,
            });
        }
    }

    /// [`Reference::crossings`] for every pixel, row-major (rows in parallel).
    pub fn crossings_image(&self, camera: &Camera, width: u32, height: u32) -> Vec<Vec<Crossing>> {
        self.for_each_pixel("crossings", width, height, |x, y, rays| {
            *rays += 1;
            self.crossings(camera, x, y, width, height)
        })
    }

    /// Ground-truth OIT image (linear RGB, 3 channels): every pixel's
    /// crossings composited front to back ([`composite_crossings`]) over the
    /// scene's sky.
    pub fn composite(&self, camera: &Camera, width: u32, height: u32) -> ImageBuf {
        let sky = Vec3::from(self.scene().settings.sky);
        let px = self.for_each_pixel("OIT", width, height, |x, y, rays| {
            *rays += 1;
            let list = self.crossings(camera, x, y, width, height);
            composite_crossings(&list, sky).0.to_array()
        });
        ImageBuf {
            width,
            height,
            channels: 3,
            data: px.into_iter().flatten().collect(),
        }
    }

    /// Ambient visibility with opacity at a fragment: point `p`, camera-facing
    /// unit shading normal `n` and geometric normal `ng`, fragment opacity
    /// `alpha` and facing (module docs, Eq. 3–4). `settings` and `key` mean what
    /// they mean for [`Reference::ao_binary_at`]: with every α = 1 and a
    /// front-facing receiver both models return exactly its value.
    #[allow(clippy::too_many_arguments)]
    pub fn ao_with_opacity(
        &self,
        p: Vec3,
        n: Vec3,
        ng: Vec3,
        alpha: f32,
        front_facing: bool,
        settings: &AoBinarySettings,
        key: u64,
    ) -> OpacityAo {
        if settings.spp == 0 {
            return OpacityAo {
                strongest: 1.0,
                transmittance: 1.0,
            };
        }
        // Eq. 3–4: the exterior hemisphere's weight.
        let w = if front_facing { alpha } else { 1.0 - alpha };
        let mut ao = OpacityAo::default();
        let mut hits = Vec::new();
        for (weight, side) in [(w, 1.0f32), (1.0 - w, -1.0)] {
            if weight <= 0.0 {
                continue;
            }
            let v = self.hemisphere_opacity_ao(p, side * n, side * ng, settings, key, &mut hits);
            ao.strongest += weight * v.strongest;
            ao.transmittance += weight * v.transmittance;
        }
        ao
    }

    /// Ambient visibility of the hemisphere around `n` in both models.
    fn hemisphere_opacity_ao(
        &self,
        p: Vec3,
        n: Vec3,
        ng: Vec3,
        settings: &AoBinarySettings,
        key: u64,
        hits: &mut Vec<Hit>,
    ) -> OpacityAo {
        let origin = p + ng * self.epsilon();
        let offset = pixel_offset(key);
        let (mut strongest, mut transmittance) = (0.0f32, 0.0f32);
        for i in 0..settings.spp {
            let d = cosine_hemisphere(n, r2(i, offset));
            self.bvh().intersect_all(origin, d, 0.0, settings.radius, hits);
            let (mut max_a, mut through) = (0.0f32, 1.0f32);
            for h in hits.iter() {
                let s = self.bvh().surface(h, d);
                if let Some(a) = self.opacity(&s) {
                    max_a = max_a.max(a);
                    through *= 1.0 - a;
                }
            }
            strongest += max_a;
            transmittance += 1.0 - through;
        }
        let spp = settings.spp as f32;
        OpacityAo {
            strongest: 1.0 - strongest / spp,
            transmittance: 1.0 - transmittance / spp,
        }
    }

    /// Per-pixel AO with opacity (3 channels: strongest, transmittance,
    /// coverage): each crossing's [`Reference::ao_with_opacity`] blended front
    /// to back with the colour's weights over a background of visibility 1,
    ///
    /// `AO_pixel = Σ_i T_i α_i AO_i + T_n`, `T_i = Π_{j<i} (1 − α_j)`,
    ///
    /// with [`composite_crossings`]' stopping rule, and coverage `1 − T_n =
    /// Σ_i T_i α_i`. Why this normalisation: it is what blending each layer's
    /// AO into an AO texture cleared to 1 gives (the paper's "separate"
    /// integration), and multiplying the composited colour by it darkens each
    /// layer's contribution by that layer's AO and leaves the background seen
    /// through the layers untouched. The fragment-weighted mean
    /// `Σ T_i α_i AO_i / Σ T_i α_i` is `(AO_pixel − T_n) / coverage`; the two
    /// agree wherever the list ends in an opaque crossing (T_n = 0). Pixels
    /// without crossings are (1, 1, 0).
    ///
    /// Fragment i of pixel (x, y) samples with key `pixel_key(seed, x, y)` for
    /// i = 0 (the key [`Reference::ao_binary`] uses, so an opaque front-facing
    /// first crossing gives exactly the binary AO image) and
    /// `hash([pixel_key, i])` for deeper ones.
    pub fn ao_with_opacity_image(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        settings: &AoBinarySettings,
    ) -> ImageBuf {
        let px = self.for_each_pixel("AO opacity", width, height, |x, y, rays| {
            *rays += 1;
            let list = self.crossings(camera, x, y, width, height);
            let pk = pixel_key(settings.seed, x, y, width);
            let (mut s, mut tr, mut t) = (0.0f32, 0.0f32, 1.0f32);
            for (i, c) in list.iter().enumerate() {
                let key = if i == 0 { pk } else { hash(&[pk, i as u64]) };
                *rays += settings.spp as u64;
                let ao = self.ao_with_opacity(
                    c.position,
                    c.normal,
                    c.geometric_normal,
                    c.alpha,
                    c.front_facing,
                    settings,
                    key,
                );
                s += t * c.alpha * ao.strongest;
                tr += t * c.alpha * ao.transmittance;
                t *= 1.0 - c.alpha;
                if c.alpha >= 1.0 || t < MIN_TRANSMITTANCE {
                    break;
                }
            }
            [s + t, tr + t, 1.0 - t]
        });
        ImageBuf {
            width,
            height,
            channels: 3,
            data: px.into_iter().flatten().collect(),
        }
    }
}
