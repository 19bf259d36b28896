//! Lights as the GPU sees them, with shadow-map matrices.
//!
//! Shadowed: the sun (orthographic map fitted to the scene bounds), spot lights and
//! rectangular area lights (perspective maps), and the most intense point lights
//! (`ShadowSettings::point_lights`, default [`POINT_SHADOW_BUDGET`]) (omnidirectional: six cube-face perspective maps,
//! layers `base..base + 6`, picked per pixel by the major axis of the direction
//! from the light). Other point lights are unshadowed.
//! A `Rect` light is an area light: its Lambertian irradiance is the exact
//! polygon integral (Lambert's formula over the rectangle clipped to the
//! receiver's hemisphere), times the share of the rectangle the receiver sees,
//! estimated by percentage-closer soft shadows from one perspective map at its
//! centre (`common/shadow.wgsl`; `LightingSettings::area_penumbrae`, hard
//! shadows from the centre when off); its GGX lobe uses the centre as a point
//! light with the cosine emission lobe (intensity L·A·cos θ).

use glam::camera::rh::proj::directx;
use glam::{Mat4, Vec3};
use strata_scene::{Light, Scene};

pub const KIND_SUN: u32 = 0;
pub const KIND_POINT: u32 = 1;
pub const KIND_SPOT: u32 = 2;
pub const KIND_RECT: u32 = 3;

/// `GpuLight` in `lighting.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuLight {
    /// kind, shadow layer (u32::MAX = none), 0, 0
    pub kind: [u32; 4],
    /// xyz position (point/spot/rect)
    pub position: [f32; 4],
    /// xyz: direction light travels (sun, spot axis) or the rect's normal
    pub direction: [f32; 4],
    /// rgb intensity × colour (sun: irradiance; point/spot: W/sr; rect: radiance × area)
    pub color: [f32; 4],
    /// cos(outer), cos(inner), shadow texel size in world units at distance 1 (or absolute for sun),
    /// and for a Rect light the shadow map's depth scale C (ndc z = F − C / d at distance d along
    /// its axis: [`depth_scale`]), which its PCSS penumbra estimate needs; 0 otherwise
    pub cone: [f32; 4],
    /// Rect: the half-edge vectors (xyz); zero for other kinds.
    pub half_u: [f32; 4],
    pub half_v: [f32; 4],
    pub shadow_view_proj: [[f32; 4]; 4],
}

pub const NO_SHADOW: u32 = u32::MAX;

/// Default number of point lights with omnidirectional shadows (6 cube-face
/// layers each): the most intense; the rest are unshadowed (reported by
/// [`unshadowed_point_lights`]). `ShadowSettings::point_lights` overrides it.
pub const POINT_SHADOW_BUDGET: usize = 2;

/// Field of view of a cube face's shadow map: a little over 90° so that the
/// PCF kernel of a point near a face's border stays inside that face.
pub const CUBE_FACE_FOV_DEG: f32 = 95.0;

/// The cube faces' axes (+X, −X, +Y, −Y, +Z, −Z): face f of a point light's
/// shadow map is layer `base + f`; `lighting.wgsl` picks f by the major axis of
/// the direction from the light.
pub const CUBE_FACES: [Vec3; 6] = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];

/// Indices (into `scene.lights`) of the `budget` most intense point lights:
/// those that get a shadow map.
fn shadowed_point_lights(scene: &Scene, budget: usize, off: &[usize]) -> Vec<usize> {
    let mut points: Vec<(usize, f32)> = scene
        .lights
        .iter()
        .enumerate()
        .filter(|(i, _)| !off.contains(i))
        .filter_map(|(i, l)| match l {
            Light::Point { color, intensity, .. } => Some((i, intensity * (color[0] + color[1] + color[2]))),
            _ => None,
        })
        .collect();
    points.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    points.into_iter().take(budget).map(|(i, _)| i).collect()
}

/// How many point lights go unshadowed with a shadow budget of `budget` point lights.
pub fn unshadowed_point_lights(scene: &Scene, budget: usize) -> usize {
    let points = scene.lights.iter().filter(|l| matches!(l, Light::Point { .. })).count();
    points - shadowed_point_lights(scene, budget, &[]).len()
}

/// Converts the scene's lights, assigning shadow-map layers in order (a
/// shadowed point light takes six: one per cube face; the `point_budget` most
/// intense point lights are shadowed).
pub fn gpu_lights(scene: &Scene, frame: f32, shadow_resolution: u32, point_budget: usize) -> Vec<GpuLight> {
    gpu_lights_for(
        scene,
        frame,
        &crate::passes::shadow::ShadowSettings {
            resolution: shadow_resolution,
            point_lights: point_budget,
            unshadowed: Vec::new(),
        },
    )
}

/// [`gpu_lights`] with every shadow setting: also the per-light switch
/// (`ShadowSettings::unshadowed`), whose lights get no shadow-map layer.
pub fn gpu_lights_for(scene: &Scene, frame: f32, shadow: &crate::passes::shadow::ShadowSettings) -> Vec<GpuLight> {
    let (shadow_resolution, point_budget) = (shadow.resolution, shadow.point_lights);
    let shadowed_points = shadowed_point_lights(scene, point_budget, &shadow.unshadowed);
    let (lo, hi) = scene.bounds(frame);
    let (center, radius) = if lo.is_finite() && hi.is_finite() {
        ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-3))
    } else {
        (Vec3::ZERO, 1.0)
    };
    let layer = std::cell::Cell::new(0u32);
    let next_layers = |n: u32| {
        layer.set(layer.get() + n);
        layer.get() - n
    };
    let next_layer = || next_layers(1);
    let res = shadow_resolution as f32;
    let lights: Vec<GpuLight> = scene
        .lights
        .iter()
        .enumerate()
        .map(|(index, l)| match *l {
            Light::Sun {
                direction,
                color,
                illuminance,
            } => {
                let d = direction.normalize();
                let eye = center - d * radius * 2.0;
                let view = look_at(eye, center, d);
                let proj = directx::orthographic(-radius, radius, -radius, radius, radius * 0.5, radius * 3.5);
                GpuLight {
                    kind: [KIND_SUN, next_layer(), 0, 0],
                    position: [0.0; 4],
                    direction: d.extend(0.0).to_array(),
                    color: [
                        color[0] * illuminance,
                        color[1] * illuminance,
                        color[2] * illuminance,
                        0.0,
                    ],
                    cone: [0.0, 0.0, 2.0 * radius / res, 0.0],
                    half_u: [0.0; 4],
                    half_v: [0.0; 4],
                    shadow_view_proj: (proj * view).to_cols_array_2d(),
                }
            }
            Light::Point {
                position,
                color,
                intensity,
            } => {
                let shadowed = shadowed_points.contains(&index);
                let fov = CUBE_FACE_FOV_DEG.to_radians();
                GpuLight {
                    kind: [KIND_POINT, if shadowed { next_layers(6) } else { NO_SHADOW }, 0, 0],
                    position: position.extend(1.0).to_array(),
                    direction: [0.0; 4],
                    color: [color[0] * intensity, color[1] * intensity, color[2] * intensity, 0.0],
                    cone: [-2.0, -1.0, 2.0 * (fov * 0.5).tan() / res, 0.0],
                    half_u: [0.0; 4],
                    half_v: [0.0; 4],
                    // face 0; `shadow_matrices` gives all six
                    shadow_view_proj: cube_face_matrix(position, 0, radius, center).to_cols_array_2d(),
                }
            }
            Light::Spot {
                position,
                direction,
                color,
                intensity,
                inner_deg,
                outer_deg,
            } => {
                let d = direction.normalize();
                let fov = (2.0 * outer_deg).clamp(1.0, 150.0).to_radians();
                let (view, proj) = perspective_shadow(position, d, fov, radius, center);
                GpuLight {
                    kind: [KIND_SPOT, next_layer(), 0, 0],
                    position: position.extend(1.0).to_array(),
                    direction: d.extend(0.0).to_array(),
                    color: [color[0] * intensity, color[1] * intensity, color[2] * intensity, 0.0],
                    cone: [
                        outer_deg.to_radians().cos(),
                        inner_deg.to_radians().cos(),
                        2.0 * (fov * 0.5).tan() / res,
                        0.0,
                    ],
                    half_u: [0.0; 4],
                    half_v: [0.0; 4],
                    shadow_view_proj: (proj * view).to_cols_array_2d(),
                }
            }
            Light::Rect {
                center: c,
                half_u,
                half_v,
                radiance,
            } => {
                let n = half_u.cross(half_v).normalize();
                let fov = 150f32.to_radians();
                let pos = c + n * 1e-4 * radius;
                let (view, proj) = perspective_shadow(pos, n, fov, radius, center);
                let c_depth = depth_scale(proj * view, pos, n);
                GpuLight {
                    kind: [KIND_RECT, next_layer(), 0, 0],
                    position: c.extend(1.0).to_array(),
                    direction: n.extend(0.0).to_array(),
                    color: [radiance[0], radiance[1], radiance[2], 0.0],
                    cone: [0.0, 0.0, 2.0 * (fov * 0.5).tan() / res, c_depth],
                    half_u: half_u.extend(0.0).to_array(),
                    half_v: half_v.extend(0.0).to_array(),
                    shadow_view_proj: (proj * view).to_cols_array_2d(),
                }
            }
        })
        .collect();
    if shadow.unshadowed.is_empty() {
        return lights;
    }
    // Per-light shadows off: drop those lights' layers and renumber the rest.
    let mut layer = 0u32;
    lights
        .into_iter()
        .enumerate()
        .map(|(index, mut g)| {
            if g.kind[1] != NO_SHADOW {
                if shadow.unshadowed.contains(&index) {
                    g.kind[1] = NO_SHADOW;
                } else {
                    g.kind[1] = layer;
                    layer += if g.kind[0] == KIND_POINT { 6 } else { 1 };
                }
            }
            g
        })
        .collect()
}

fn look_at(eye: Vec3, target: Vec3, dir: Vec3) -> Mat4 {
    let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    glam::camera::rh::view::look_at_mat4(eye, target, up)
}

fn perspective_shadow(pos: Vec3, dir: Vec3, fov: f32, scene_radius: f32, scene_center: Vec3) -> (Mat4, Mat4) {
    let far = (pos - scene_center).length() + scene_radius * 1.01;
    let near = (far * 1e-4).max(1e-4);
    (look_at(pos, pos + dir, dir), directx::perspective(fov, 1.0, near, far))
}

/// C of a perspective shadow map `view_proj` (eye `pos`, axis `dir`): its ndc
/// depth at distance d along the axis is F − C / d, so 1/d₁ − 1/d₂ = (z₂ − z₁) / C
/// (the PCSS blocker-to-receiver term of `common/shadow.wgsl`). Measured from the
/// matrix at two distances, so it holds whatever the projection's convention.
pub fn depth_scale(view_proj: Mat4, pos: Vec3, dir: Vec3) -> f32 {
    let z = |d: f32| view_proj.project_point3(pos + dir * d).z;
    let (d1, d2) = (1.0f32, 2.0f32);
    (z(d2) - z(d1)) / (1.0 / d1 - 1.0 / d2)
}

/// View-projection of face `face` (of [`CUBE_FACES`]) of a point light's
/// shadow map: a [`CUBE_FACE_FOV_DEG`] perspective along the face's axis.
pub(crate) fn cube_face_matrix(pos: Vec3, face: usize, scene_radius: f32, scene_center: Vec3) -> Mat4 {
    let axis = CUBE_FACES[face];
    let (view, proj) = perspective_shadow(pos, axis, CUBE_FACE_FOV_DEG.to_radians(), scene_radius, scene_center);
    proj * view
}

/// Number of shadow-map layers the lights need (six per shadowed point light).
pub fn shadow_layer_count(lights: &[GpuLight]) -> u32 {
    lights
        .iter()
        .filter(|l| l.kind[1] != NO_SHADOW)
        .map(|l| if l.kind[0] == KIND_POINT { 6 } else { 1 })
        .sum()
}

/// The view-projection of every shadow-map layer, indexed by layer: a light's
/// own matrix, and for a shadowed point light its six cube faces.
pub fn shadow_matrices(scene: &Scene, frame: f32, lights: &[GpuLight]) -> Vec<[[f32; 4]; 4]> {
    let (lo, hi) = scene.bounds(frame);
    let (center, radius) = if lo.is_finite() && hi.is_finite() {
        ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-3))
    } else {
        (Vec3::ZERO, 1.0)
    };
    let mut out = vec![Mat4::IDENTITY.to_cols_array_2d(); shadow_layer_count(lights) as usize];
    for l in lights.iter().filter(|l| l.kind[1] != NO_SHADOW) {
        let base = l.kind[1] as usize;
        if l.kind[0] == KIND_POINT {
            let pos = Vec3::from_slice(&l.position[..3]);
            for face in 0..6 {
                out[base + face] = cube_face_matrix(pos, face, radius, center).to_cols_array_2d();
            }
        } else {
            out[base] = l.shadow_view_proj;
        }
    }
    out
}
