//! The scene model: meshes, materials, textures, lights, objects with rigid
//! animation, a camera and an optional camera path.

use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

use crate::camera::Camera;
use crate::error::short;
use crate::path::CameraPath;

/// Largest magnitude of a vertex coordinate (object and world space) a loaded
/// scene may have: far beyond any real scene, small enough that bounds,
/// diagonals and camera distances computed from them stay finite in f32.
pub const MAX_COORDINATE: f32 = 1e18;

/// Triangle mesh in object space. One material per mesh (loaders split by material).
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    /// Per-vertex unit normals, same length as `positions` (generated when the file has none).
    pub normals: Vec<[f32; 3]>,
    /// Per-vertex UVs, same length as `positions` (zeros when the file has none).
    pub uvs: Vec<[f32; 2]>,
    /// Triangle list, counter-clockwise front faces.
    pub indices: Vec<u32>,
    pub material: usize,
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

/// RGBA8 texture; colour textures hold sRGB-encoded texels.
#[derive(Clone, Debug)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
}

impl Texture {
    /// Bilinear-free nearest lookup with wrap addressing, returned as linear RGBA
    /// (sRGB decode on RGB). Used by the CPU reference.
    pub fn sample_linear(&self, uv: [f32; 2]) -> [f32; 4] {
        let u = uv[0] - uv[0].floor();
        let v = uv[1] - uv[1].floor();
        let x = ((u * self.width as f32) as u32).min(self.width - 1);
        let y = ((v * self.height as f32) as u32).min(self.height - 1);
        let i = ((y * self.width + x) * 4) as usize;
        let t = &self.rgba8[i..i + 4];
        [
            srgb_to_linear(t[0]),
            srgb_to_linear(t[1]),
            srgb_to_linear(t[2]),
            t[3] as f32 / 255.0,
        ]
    }
}

pub fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Metallic-roughness material. Colours are linear RGB.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    pub name: String,
    /// Linear base colour (albedo for diffuse surfaces).
    pub base_color: [f32; 3],
    /// Index into `Scene::textures`, multiplied with `base_color`.
    pub base_color_texture: Option<usize>,
    /// Emitted radiance (linear RGB, scene radiance units).
    pub emission: [f32; 3],
    /// Opacity α of the surface, 1 = opaque (glTF: `baseColorFactor.a` unless
    /// `alphaMode` is OPAQUE; OBJ: `d` or `1 − Tr`). For a MASK material this
    /// is the alpha the cutoff test uses, not the opacity of kept fragments
    /// (which is 1): see [`Material::fragment_alpha`].
    pub opacity: f32,
    pub roughness: f32,
    pub metallic: f32,
    /// glTF `alphaMode` MASK: a fragment is kept iff its alpha
    /// (`opacity × texture alpha`) is ≥ the cutoff (glTF default 0.5), and a
    /// kept fragment is opaque. `None` for OPAQUE and BLEND materials.
    #[serde(default)]
    pub alpha_cutoff: Option<f32>,
    /// Whether the base-colour texture's alpha multiplies `opacity`: true for
    /// glTF BLEND and MASK materials, false for OPAQUE ones (whose alpha the
    /// glTF spec says to ignore) and for OBJ/MTL (`map_Kd` alpha is not
    /// opacity there; only `d`/`Tr` are).
    #[serde(default)]
    pub texture_alpha: bool,
    /// How the CPU reference's path tracer shades the surface: `true` = the
    /// metallic-roughness GGX model (Lambert lobe + Trowbridge-Reitz specular
    /// lobe from `roughness`, `metallic`, `base_color`; docs/reference.md,
    /// "Glossy GI"); `false` (default) = Lambert with albedo `base_color`,
    /// whatever `roughness` and `metallic` say — the reference's model before
    /// GGX, so materials that do not opt in keep their results and cache keys.
    /// The GPU renderer ignores it (it always adds its GGX lobe).
    #[serde(default)]
    pub glossy: bool,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: "default".into(),
            base_color: [0.8, 0.8, 0.8],
            base_color_texture: None,
            emission: [0.0; 3],
            opacity: 1.0,
            roughness: 0.8,
            metallic: 0.0,
            alpha_cutoff: None,
            texture_alpha: false,
            glossy: false,
        }
    }
}

impl Material {
    pub fn diffuse(name: &str, rgb: [f32; 3]) -> Self {
        Self {
            name: name.into(),
            base_color: rgb,
            ..Default::default()
        }
    }
    pub fn emissive(name: &str, radiance: [f32; 3]) -> Self {
        Self {
            name: name.into(),
            base_color: [0.0; 3],
            emission: radiance,
            ..Default::default()
        }
    }
    /// A glossy material for the CPU reference's GGX model ([`Material::glossy`]).
    pub fn glossy(name: &str, rgb: [f32; 3], roughness: f32, metallic: f32) -> Self {
        Self {
            name: name.into(),
            base_color: rgb,
            roughness,
            metallic,
            glossy: true,
            ..Default::default()
        }
    }
    pub fn is_emissive(&self) -> bool {
        self.emission.iter().any(|&e| e > 0.0)
    }

    /// The alpha of a fragment of this material whose base-colour texture
    /// alpha is `texture_alpha` (pass 1 where there is no texture), or `None`
    /// when the fragment is discarded (MASK below the cutoff). The one rule the
    /// GPU and the CPU reference share:
    ///
    /// - `a = opacity × (texture_alpha if self.texture_alpha else 1)`;
    /// - MASK (`alpha_cutoff = Some(c)`): kept iff `a ≥ c`, with alpha 1;
    /// - otherwise (OPAQUE: opacity 1; BLEND): kept, with alpha `a`.
    ///
    /// A BLEND fragment of alpha 0 is kept (it is a crossing that adds
    /// nothing), so fragment counts do not depend on texture contents.
    pub fn fragment_alpha(&self, texture_alpha: f32) -> Option<f32> {
        let a = if self.texture_alpha {
            self.opacity * texture_alpha
        } else {
            self.opacity
        };
        match self.alpha_cutoff {
            Some(c) => (a >= c).then_some(1.0),
            None => Some(a),
        }
    }

    /// True when every fragment of this material is opaque (α = 1, no cutoff).
    pub fn is_opaque(&self) -> bool {
        self.alpha_cutoff.is_none() && self.opacity >= 1.0 && !self.texture_alpha
    }
}

/// Analytic lights. Emissive surfaces are materials with `emission`; a
/// [`Light::Rect`] additionally tells the GPU direct-light pass where one is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum Light {
    /// Directional light. `direction` points *from the light* (the way photons travel).
    /// `illuminance` is the irradiance on a surface facing the sun (per colour channel × `color`).
    Sun {
        direction: Vec3,
        color: [f32; 3],
        illuminance: f32,
    },
    /// Isotropic point light with radiant intensity `intensity` × `color` (per steradian).
    Point {
        position: Vec3,
        color: [f32; 3],
        intensity: f32,
    },
    /// Spot light: point light restricted to a cone with smooth falloff between the
    /// inner and outer half-angles (degrees).
    Spot {
        position: Vec3,
        direction: Vec3,
        color: [f32; 3],
        intensity: f32,
        inner_deg: f32,
        outer_deg: f32,
    },
    /// One-sided rectangular area light (centre, two half-edge vectors, emitted radiance).
    /// Its normal is `normalize(cross(half_u, half_v))`. The scene must also contain
    /// matching emissive geometry for the reference to see it.
    Rect {
        center: Vec3,
        half_u: Vec3,
        half_v: Vec3,
        radiance: [f32; 3],
    },
}

/// Rigid animation of an object, evaluated at a (fractional) frame index.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum Animation {
    /// Pendulum swing about `axis` through `pivot`: angle = amplitude · sin(2π frame / period).
    Swing {
        pivot: Vec3,
        axis: Vec3,
        amplitude_deg: f32,
        period_frames: f32,
    },
    /// Back-and-forth translation: offset = amplitude · sin(2π frame / period).
    Slide { amplitude: Vec3, period_frames: f32 },
}

impl Animation {
    /// Transform applied on top of the object's static transform at `frame`.
    pub fn transform_at(&self, frame: f32) -> Mat4 {
        use std::f32::consts::TAU;
        match *self {
            Animation::Swing {
                pivot,
                axis,
                amplitude_deg,
                period_frames,
            } => {
                let a = amplitude_deg.to_radians() * (TAU * frame / period_frames).sin();
                Mat4::from_translation(pivot)
                    * Mat4::from_axis_angle(axis.normalize(), a)
                    * Mat4::from_translation(-pivot)
            }
            Animation::Slide {
                amplitude,
                period_frames,
            } => Mat4::from_translation(amplitude * (TAU * frame / period_frames).sin()),
        }
    }
}

/// An instance of a mesh in the world.
#[derive(Clone, Debug)]
pub struct Object {
    pub name: String,
    pub mesh: usize,
    /// Object → world transform when not animated.
    pub transform: Mat4,
    pub animation: Option<Animation>,
}

impl Object {
    /// Object → world transform at a (fractional) frame index.
    pub fn transform_at(&self, frame: f32) -> Mat4 {
        match &self.animation {
            Some(a) => a.transform_at(frame) * self.transform,
            None => self.transform,
        }
    }
}

/// Per-scene settings that techniques read (scene units).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SceneSettings {
    /// Ambient-occlusion world-space radius.
    pub ao_radius: f32,
    /// Deep G-buffer minimum separation Δz.
    pub min_separation: f32,
    /// World-space gather radius of screen-space radiosity (DGB §3.2).
    pub radiosity_radius: f32,
    /// Exposure multiplier applied before tonemapping.
    pub exposure: f32,
    /// Constant sky/environment radiance seen by rays that leave the scene.
    pub sky: [f32; 3],
    /// Ambient term added to direct lighting (the probe fallback replaces it later).
    pub ambient: [f32; 3],
    /// The box `[lo, hi]` the light probes' grid spans (scene units). `None`: the scene's
    /// bounds inset by 5 % per axis. A room inside a large scene (a street, a terrain)
    /// otherwise spends most of its probes outdoors, and its receivers blend probes a
    /// metre or more apart.
    pub probe_bounds: Option<[[f32; 3]; 2]>,
}

impl Default for SceneSettings {
    fn default() -> Self {
        Self {
            ao_radius: 1.0,
            min_separation: 0.5,
            radiosity_radius: 8.0,
            exposure: 1.0,
            sky: [0.0; 3],
            ambient: [0.03; 3],
            probe_bounds: None,
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub name: String,
    pub meshes: Vec<Mesh>,
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub lights: Vec<Light>,
    pub camera: Camera,
    /// The cameras the scene file defines (glTF camera nodes, in node order);
    /// `camera` starts as the first of them. Empty for files without cameras.
    pub cameras: Vec<Camera>,
    pub camera_path: Option<CameraPath>,
    pub settings: SceneSettings,
}

/// A world-space triangle, flattened for the CPU reference.
#[derive(Clone, Copy, Debug)]
pub struct WorldTriangle {
    pub p: [Vec3; 3],
    pub n: [Vec3; 3],
    pub uv: [[f32; 2]; 3],
    pub material: u32,
    pub object: u32,
}

impl Scene {
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| self.meshes[o.mesh].triangle_count()).sum()
    }

    /// Whether any object moves (rigid animation); lights and materials never do.
    pub fn animated(&self) -> bool {
        self.objects.iter().any(|o| o.animation.is_some())
    }

    /// The camera at `frame`: the camera path's when there is one, else the static camera.
    pub fn camera_at(&self, frame: f32) -> Camera {
        match &self.camera_path {
            Some(p) => p.camera_at(frame, &self.camera),
            None => self.camera,
        }
    }

    /// All triangles in world space at `frame` (objects' animation applied).
    pub fn world_triangles(&self, frame: f32) -> Vec<WorldTriangle> {
        let mut out = Vec::with_capacity(self.triangle_count());
        for (oi, o) in self.objects.iter().enumerate() {
            let m = &self.meshes[o.mesh];
            let xf = o.transform_at(frame);
            let nxf = glam::Mat3::from_mat4(xf).inverse().transpose();
            for t in m.indices.chunks_exact(3) {
                let mut tri = WorldTriangle {
                    p: [Vec3::ZERO; 3],
                    n: [Vec3::ZERO; 3],
                    uv: [[0.0; 2]; 3],
                    material: m.material as u32,
                    object: oi as u32,
                };
                for (k, &i) in t.iter().enumerate() {
                    let i = i as usize;
                    tri.p[k] = xf.transform_point3(Vec3::from(m.positions[i]));
                    tri.n[k] = (nxf * Vec3::from(m.normals[i])).normalize_or_zero();
                    tri.uv[k] = m.uvs[i];
                }
                out.push(tri);
            }
        }
        out
    }

    /// Checks the invariants every loaded scene satisfies; the error names the
    /// element (mesh and vertex, material, texture, object, light, …):
    ///
    /// - meshes: finite positions within ±[`MAX_COORDINATE`]; as many unit
    ///   normals and finite UVs as positions; a multiple of 3 indices, each in
    ///   range; a material in range;
    /// - objects: a mesh in range, a finite transform;
    /// - materials: finite values with colours, opacity, roughness, metallic
    ///   and alpha cutoff in [0, 1] (emission >= 0); a texture in range;
    /// - textures: non-empty, `width × height × 4` bytes;
    /// - the camera passes [`Camera::validate`]; camera path keyframes are finite;
    /// - lights and settings finite (settings' lengths and exposure > 0);
    /// - world-space bounds at frame 0 within ±[`MAX_COORDINATE`].
    pub fn validate(&self) -> Result<(), String> {
        let fin3 = |v: &[f32; 3]| v.iter().all(|c| c.is_finite());
        for m in &self.meshes {
            let what = format!("mesh '{}'", short(&m.name));
            if let Some((i, p)) = m
                .positions
                .iter()
                .enumerate()
                .find(|(_, p)| !(fin3(p) && p.iter().all(|c| c.abs() <= MAX_COORDINATE)))
            {
                return Err(format!(
                    "{what}: vertex {i} position {p:?} is out of range: must be finite and within ±{MAX_COORDINATE:e}"
                ));
            }
            if m.normals.len() != m.positions.len() || m.uvs.len() != m.positions.len() {
                return Err(format!(
                    "{what}: {} normals and {} UVs for {} positions (they must match)",
                    m.normals.len(),
                    m.uvs.len(),
                    m.positions.len()
                ));
            }
            if let Some((i, n)) = m
                .normals
                .iter()
                .enumerate()
                .find(|(_, n)| !(fin3(n) && (Vec3::from(**n).length() - 1.0).abs() < 1e-3))
            {
                return Err(format!("{what}: vertex {i} normal {n:?} is not a finite unit vector"));
            }
            if let Some((i, t)) = m.uvs.iter().enumerate().find(|(_, t)| !t.iter().all(|c| c.is_finite())) {
                return Err(format!("{what}: vertex {i} has a non-finite texture coordinate {t:?}"));
            }
            if m.indices.len() % 3 != 0 {
                return Err(format!(
                    "{what}: index count {} is not a multiple of 3",
                    m.indices.len()
                ));
            }
            if let Some(&i) = m.indices.iter().find(|&&i| i as usize >= m.positions.len()) {
                return Err(format!(
                    "{what}: vertex index {i} is out of range (the mesh has {} vertices)",
                    m.positions.len()
                ));
            }
            if m.material >= self.materials.len() {
                return Err(format!("{what}: material {} is out of range", m.material));
            }
        }
        for (i, o) in self.objects.iter().enumerate() {
            if o.mesh >= self.meshes.len() {
                return Err(format!(
                    "object {i} ('{}'): mesh {} is out of range",
                    short(&o.name),
                    o.mesh
                ));
            }
            if !o.transform.is_finite() {
                return Err(format!("object {i} ('{}'): transform is not finite", short(&o.name)));
            }
        }
        for m in &self.materials {
            let unit = |x: f32| (0.0..=1.0).contains(&x);
            if !(m.base_color.iter().all(|&c| unit(c))
                && m.emission.iter().all(|&c| c.is_finite() && c >= 0.0)
                && unit(m.opacity)
                && unit(m.roughness)
                && unit(m.metallic)
                && m.alpha_cutoff.is_none_or(unit))
            {
                return Err(format!(
                    "material '{}': a value is out of range (base colour, opacity, roughness, metallic, alpha cutoff in [0, 1]; emission finite and >= 0)",
                    short(&m.name)
                ));
            }
            if m.base_color_texture.is_some_and(|t| t >= self.textures.len()) {
                return Err(format!("material '{}': texture index is out of range", short(&m.name)));
            }
        }
        for t in &self.textures {
            if t.width == 0 || t.height == 0 || t.rgba8.len() as u64 != t.width as u64 * t.height as u64 * 4 {
                return Err(format!(
                    "texture '{}': {}×{} with {} bytes (must be non-empty with width × height × 4 bytes)",
                    short(&t.name),
                    t.width,
                    t.height,
                    t.rgba8.len()
                ));
            }
        }
        self.camera.validate()?;
        if let Some(p) = &self.camera_path {
            if p.keyframes.is_empty()
                || !p
                    .keyframes
                    .iter()
                    .all(|k| k.frame.is_finite() && k.eye.is_finite() && k.target.is_finite())
            {
                return Err("camera path: keyframes must exist and be finite".into());
            }
        }
        for (i, l) in self.lights.iter().enumerate() {
            let ok = match l {
                Light::Sun {
                    direction,
                    color,
                    illuminance,
                } => direction.is_finite() && fin3(color) && illuminance.is_finite(),
                Light::Point {
                    position,
                    color,
                    intensity,
                } => position.is_finite() && fin3(color) && intensity.is_finite(),
                Light::Spot {
                    position,
                    direction,
                    color,
                    intensity,
                    inner_deg,
                    outer_deg,
                } => {
                    position.is_finite()
                        && direction.is_finite()
                        && fin3(color)
                        && intensity.is_finite()
                        && inner_deg.is_finite()
                        && outer_deg.is_finite()
                }
                Light::Rect {
                    center,
                    half_u,
                    half_v,
                    radiance,
                } => center.is_finite() && half_u.is_finite() && half_v.is_finite() && fin3(radiance),
            };
            if !ok {
                return Err(format!("light {i}: values must be finite"));
            }
        }
        let st = &self.settings;
        let pos = |x: f32| x.is_finite() && x > 0.0;
        if !(pos(st.ao_radius)
            && pos(st.min_separation)
            && pos(st.radiosity_radius)
            && pos(st.exposure)
            && fin3(&st.sky)
            && fin3(&st.ambient))
        {
            return Err(format!(
                "settings {st:?} are out of range: lengths and exposure finite and > 0, colours finite"
            ));
        }
        if let Some([lo, hi]) = st.probe_bounds {
            if !(fin3(&lo) && fin3(&hi) && (0..3).all(|i| lo[i] <= hi[i])) {
                return Err(format!(
                    "settings.probe_bounds {lo:?}..{hi:?} is out of range: finite, and lo <= hi on every axis"
                ));
            }
        }
        if !self.objects.is_empty() {
            let (lo, hi) = self.bounds(0.0);
            let extent = lo.abs().max(hi.abs()).max_element();
            if (extent.is_nan() || extent > MAX_COORDINATE) && self.triangle_count() > 0 {
                return Err(format!(
                    "the world-space bounds {lo}..{hi} are out of range: coordinates must be within ±{MAX_COORDINATE:e}"
                ));
            }
        }
        Ok(())
    }

    /// World-space axis-aligned bounds at `frame` (min, max).
    pub fn bounds(&self, frame: f32) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for o in &self.objects {
            let xf = o.transform_at(frame);
            for p in &self.meshes[o.mesh].positions {
                let w = xf.transform_point3(Vec3::from(*p));
                lo = lo.min(w);
                hi = hi.max(w);
            }
        }
        (lo, hi)
    }
}
