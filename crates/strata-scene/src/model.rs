//! The scene model: meshes, materials, textures, lights, objects with rigid
//! animation, a camera and an optional camera path.

use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

use crate::camera::Camera;
use crate::path::CameraPath;

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
    /// 1 = opaque.
    pub opacity: f32,
    pub roughness: f32,
    pub metallic: f32,
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
    pub fn is_emissive(&self) -> bool {
        self.emission.iter().any(|&e| e > 0.0)
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
                for k in 0..3 {
                    let i = t[k] as usize;
                    tri.p[k] = xf.transform_point3(Vec3::from(m.positions[i]));
                    tri.n[k] = (nxf * Vec3::from(m.normals[i])).normalize_or_zero();
                    tri.uv[k] = m.uvs[i];
                }
                out.push(tri);
            }
        }
        out
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
