//! The exact k-layer deep G-buffer with minimum separation (DGB §2).
//!
//! Along the ray through each pixel centre (depths `z > near`), layer 0 is the
//! first surface and layer j is the first surface with
//! `z > z_{j−1} + Δz + δ·z_{j−1}`, where δ is a tiny relative tolerance
//! ([`LayerSettings::depth_tolerance`]). Δz = 0 is classic depth peeling (the
//! next surface strictly behind); δ keeps coplanar duplicates and the double
//! hit on an edge shared by two triangles from producing a spurious layer.
//! Both faces count (no back-face culling) unless
//! [`LayerSettings::cull_back_faces`] is set.
//!
//! Missing layers have depth `f32::INFINITY`, zero normal and albedo, and
//! material/object [`NO_ID`].

use glam::Vec3;
use strata_scene::{Camera, ImageBuf};

use crate::bvh::SurfaceHit;
use crate::Reference;

/// Material/object id of a pixel without a surface in that layer.
pub const NO_ID: u32 = u32::MAX;

/// Settings of the layer oracle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerSettings {
    /// Number of layers k (≥ 1).
    pub count: usize,
    /// Minimum separation Δz (camera-space depth units).
    pub min_separation: f32,
    /// Relative depth tolerance δ (default 1e-5).
    pub depth_tolerance: f32,
    /// Skip surfaces seen from their back (clockwise) side.
    pub cull_back_faces: bool,
}

impl LayerSettings {
    pub fn new(count: usize, min_separation: f32) -> Self {
        Self {
            count,
            min_separation,
            ..Self::default()
        }
    }
}

impl Default for LayerSettings {
    /// Two layers, Δz = 0.5, δ = 1e-5, no culling.
    fn default() -> Self {
        Self {
            count: 2,
            min_separation: 0.5,
            depth_tolerance: 1e-5,
            cull_back_faces: false,
        }
    }
}

/// One G-buffer layer.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Camera-space depth (1 channel); `f32::INFINITY` where the layer is empty.
    pub depth: ImageBuf,
    /// World-space unit shading normal (3 channels), as interpolated — *not*
    /// flipped towards the camera (see `front_face`).
    pub normal: ImageBuf,
    /// Diffuse albedo, linear RGB (3 channels).
    pub albedo: ImageBuf,
    /// Whether the camera sees the surface's front (counter-clockwise) face.
    pub front_face: Vec<bool>,
    /// Material index per pixel, [`NO_ID`] where empty.
    pub material: Vec<u32>,
    /// Object index per pixel, [`NO_ID`] where empty.
    pub object: Vec<u32>,
}

impl Layer {
    fn new(width: u32, height: u32) -> Self {
        let n = (width * height) as usize;
        let mut depth = ImageBuf::new(width, height, 1);
        depth.data.fill(f32::INFINITY);
        Self {
            depth,
            normal: ImageBuf::new(width, height, 3),
            albedo: ImageBuf::new(width, height, 3),
            front_face: vec![false; n],
            material: vec![NO_ID; n],
            object: vec![NO_ID; n],
        }
    }

    fn set(&mut self, i: usize, s: &Sample) {
        self.depth.data[i] = s.depth;
        self.normal.data[3 * i..3 * i + 3].copy_from_slice(&s.normal.to_array());
        self.albedo.data[3 * i..3 * i + 3].copy_from_slice(&s.albedo.to_array());
        self.front_face[i] = s.front_face;
        self.material[i] = s.material;
        self.object[i] = s.object;
    }

    /// Whether pixel (x, y) has a surface in this layer.
    pub fn covered(&self, x: u32, y: u32) -> bool {
        self.depth.pixel(x, y)[0].is_finite()
    }
}

/// The k layers of [`Reference::layers`].
#[derive(Clone, Debug, PartialEq)]
pub struct DeepLayers {
    pub width: u32,
    pub height: u32,
    pub layers: Vec<Layer>,
}

#[derive(Clone, Copy, Default)]
struct Sample {
    depth: f32,
    normal: Vec3,
    albedo: Vec3,
    front_face: bool,
    material: u32,
    object: u32,
}

impl Reference<'_> {
    /// The exact k-layer deep G-buffer with minimum separation.
    pub fn layers(&self, camera: &Camera, width: u32, height: u32, settings: &LayerSettings) -> DeepLayers {
        let k = settings.count.max(1);
        let px = self.for_each_pixel("layers", width, height, |x, y, rays| {
            let dir = camera.pixel_dir(x, y, width, height);
            *rays += 1;
            let mut hits = Vec::new();
            self.bvh
                .intersect_all(camera.eye, dir, camera.near, f32::INFINITY, &mut hits);
            let mut out: Vec<Option<Sample>> = Vec::with_capacity(k);
            let mut prev: Option<f32> = None;
            for h in &hits {
                if out.len() == k {
                    break;
                }
                if let Some(z) = prev {
                    if !(h.t > z + settings.min_separation + settings.depth_tolerance * z.abs()) {
                        continue;
                    }
                }
                let s = self.bvh.surface(h, dir);
                if settings.cull_back_faces && !s.front_face {
                    continue;
                }
                out.push(Some(self.layer_sample(&s)));
                prev = Some(h.t);
            }
            out.resize(k, None);
            out
        });
        let mut layers: Vec<Layer> = (0..k).map(|_| Layer::new(width, height)).collect();
        for (i, samples) in px.iter().enumerate() {
            for (j, s) in samples.iter().enumerate() {
                if let Some(s) = s {
                    layers[j].set(i, s);
                }
            }
        }
        DeepLayers { width, height, layers }
    }

    /// Layer 0 only: the primary-hit G-buffer (for G-buffer agreement tests).
    pub fn primary_layer(&self, camera: &Camera, width: u32, height: u32) -> Layer {
        let px = self.for_each_pixel("G-buffer", width, height, |x, y, rays| {
            *rays += 1;
            self.primary_hit(camera, x, y, width, height)
                .map(|s| self.layer_sample(&s))
        });
        let mut l = Layer::new(width, height);
        for (i, s) in px.iter().enumerate() {
            if let Some(s) = s {
                l.set(i, s);
            }
        }
        l
    }

    fn layer_sample(&self, s: &SurfaceHit) -> Sample {
        Sample {
            depth: s.t,
            normal: s.shading_normal,
            albedo: self.albedo(s),
            front_face: s.front_face,
            material: s.material,
            object: s.object,
        }
    }
}
