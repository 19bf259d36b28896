//! strata-reference: the CPU ground truth ("oracle") that the GPU passes are
//! tested against.
//!
//! A [`Reference`] is built once per `(scene, frame)`: it flattens the scene to
//! world-space triangles, builds a [`Tracer`] and a light-sampling table for
//! emissive triangles, and then computes, for any camera and image size:
//!
//! - [`Reference::ao_binary`]: ambient visibility from cosine-weighted hemisphere
//!   rays ([`ao`]);
//! - [`Reference::ao_obscurance`]: the Deep G-buffer AO estimator (DGB Eq. 1–2)
//!   integrated over *every* surface along each sample ray — the infinite-layer
//!   limit of the GPU's k-layer estimator ([`ao`]);
//! - [`Reference::gi`]: path-traced diffuse global illumination split into
//!   direct and indirect radiance ([`gi`]);
//! - [`Reference::layers`]: the exact k-layer deep G-buffer with minimum
//!   separation (DGB §2) ([`layers`]);
//! - [`Reference::crossings`], [`Reference::composite`],
//!   [`Reference::ao_with_opacity`]: every surface crossing of a primary ray,
//!   their order-independent-transparency composite and AO with occluder and
//!   receiver opacity (the A-buffer paper's ground truth) ([`oit`]).
//!
//! Conventions are those of [`strata_scene::Camera`]: rays go through pixel
//! centres `(x + 0.5, y + 0.5)` (no anti-aliasing jitter, so every value refers
//! to exactly the point the GPU shades), primary rays use
//! [`Camera::pixel_dir`] so the ray parameter *is* camera-space depth, and
//! primary rays start at the near plane (`t > near`), as rasterisation clips.
//!
//! All estimators are deterministic: each pixel seeds its own generator from
//! `(seed, pixel)`, and rows run in parallel with rayon, so results never
//! depend on thread count or scheduling.
//!
//! **Tracers.** Rays go through the [`Tracer`] interface; [`TracerKind::Wide`]
//! (the default, an 8-wide SIMD BVH, [`wide`]) and [`TracerKind::Binary`] (the
//! binned-SAH binary BVH, [`bvh`]) return bitwise-identical answers
//! ([`Reference::with_tracer`] picks one).
//!
//! **Why our own BVH.** The oracle must be exact and reproducible, and its
//! failure modes must be ours to reason about: the watertight intersection
//! (Woop et al. 2013) never leaks rays through shared edges, ties at equal `t`
//! are broken by triangle index so results do not depend on traversal order,
//! and [`Tracer::intersect_all`] enumerates every surface along a ray, which
//! the layer and obscurance oracles need and general-purpose BVH crates rarely
//! expose.

// `!(a < b)` is used on purpose where NaN must take the "reject" branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod ao;
pub mod bench;
pub mod brdf;
pub mod bundle;
pub mod bvh;
pub mod converge;
pub mod environment;
pub mod gi;
pub mod layers;
pub mod oit;
pub mod oracle;
pub mod probes;
pub mod sampling;
pub mod tracer;
pub mod vpl;
pub mod wide;

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use glam::Vec3;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use strata_scene::{Camera, Material, Scene};

pub use ao::{AoBinarySettings, DiskSampling, ObscuranceSettings};
pub use bench::RayKind;
pub use bvh::{Bvh, Hit, SurfaceHit};
pub use converge::{ConvergeRule, Converged, Estimator};
pub use gi::{GiImages, GiSettings};
pub use layers::{DeepLayers, Layer, LayerSettings, NO_ID};
pub use oit::{Crossing, OpacityAo};
pub use tracer::{AnyTracer, Tracer, TracerKind};
pub use vpl::{Vpl, VplSettings};
pub use wide::WideBvh;

/// Counters accumulated over every computation run on a [`Reference`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Rays traced (primary, secondary and shadow rays all count one).
    pub rays: u64,
    /// Wall-clock seconds spent in the image computations.
    pub seconds: f64,
}

impl Stats {
    /// Throughput in millions of rays per second (0 when nothing ran).
    pub fn mrays_per_second(&self) -> f64 {
        if self.seconds > 0.0 {
            self.rays as f64 / self.seconds / 1e6
        } else {
            0.0
        }
    }
}

/// Result of [`Reference::measure_throughput`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Throughput {
    pub rays: u64,
    pub seconds: f64,
    /// Rayon worker threads used.
    pub threads: usize,
    /// Triangles in the BVH.
    pub triangles: usize,
}

impl Throughput {
    pub fn mrays_per_second(&self) -> f64 {
        if self.seconds > 0.0 {
            self.rays as f64 / self.seconds / 1e6
        } else {
            0.0
        }
    }
}

/// The CPU reference for one scene at one animation frame.
pub struct Reference<'s> {
    scene: &'s Scene,
    frame: f32,
    bvh: AnyTracer,
    lights: gi::EmissiveLights,
    epsilon: f32,
    progress: bool,
    build_seconds: f64,
    rays: AtomicU64,
    nanos: AtomicU64,
}

static DEFAULT_MATERIAL: std::sync::LazyLock<Material> = std::sync::LazyLock::new(Material::default);

impl<'s> Reference<'s> {
    /// Flattens `scene` at `frame` and builds the default tracer
    /// ([`TracerKind::Wide`]) and the emissive-triangle table. An empty scene is
    /// fine: every ray misses.
    pub fn new(scene: &'s Scene, frame: f32) -> Self {
        Self::with_tracer(scene, frame, TracerKind::default())
    }

    /// [`Reference::new`] with a chosen tracer backend (every backend gives the
    /// same answers; they differ in speed).
    pub fn with_tracer(scene: &'s Scene, frame: f32, kind: TracerKind) -> Self {
        let start = Instant::now();
        let triangles = scene.world_triangles(frame);
        let bvh = match kind {
            TracerKind::Binary => Bvh::build(triangles),
            TracerKind::Wide => wide::base_tree(triangles),
        };
        let epsilon = match bvh.bounds() {
            Some((lo, hi)) => {
                let scale = (hi - lo)
                    .length()
                    .max(lo.abs().max_element())
                    .max(hi.abs().max_element());
                if scale.is_finite() {
                    1e-5 * scale.max(1e-3)
                } else {
                    1e-4
                }
            }
            None => 1e-4,
        };
        let lights = gi::EmissiveLights::new(&bvh, &scene.materials);
        let bvh = AnyTracer::from_binary(bvh, kind);
        Self {
            scene,
            frame,
            bvh,
            lights,
            epsilon,
            progress: false,
            build_seconds: start.elapsed().as_secs_f64(),
            rays: AtomicU64::new(0),
            nanos: AtomicU64::new(0),
        }
    }

    /// Shows an indicatif progress bar on stderr during image computations
    /// (only when stderr is a terminal).
    pub fn with_progress(mut self, on: bool) -> Self {
        self.progress = on;
        self
    }

    pub fn scene(&self) -> &'s Scene {
        self.scene
    }

    pub fn frame(&self) -> f32 {
        self.frame
    }

    /// The scene's camera at this frame.
    pub fn camera(&self) -> Camera {
        self.scene.camera_at(self.frame)
    }

    /// The tracer (dispatching to the backend chosen at construction).
    pub fn bvh(&self) -> &AnyTracer {
        &self.bvh
    }

    /// The backend in use.
    pub fn tracer_kind(&self) -> TracerKind {
        self.bvh.kind()
    }

    /// Seconds spent flattening the scene and building the BVH.
    pub fn build_seconds(&self) -> f64 {
        self.build_seconds
    }

    /// Ray-origin offset (scene units): `1e-5 ×` the larger of the scene's
    /// bounding-box diagonal and its largest coordinate magnitude. Secondary rays
    /// start this far from the surface along the geometric normal.
    pub fn epsilon(&self) -> f32 {
        self.epsilon
    }

    /// Rays traced and seconds spent so far.
    /// Counts rays traced outside `for_each_pixel` (e.g. probe baking).
    pub(crate) fn add_rays(&self, n: u64) {
        self.rays.fetch_add(n, Ordering::Relaxed);
    }

    pub fn stats(&self) -> Stats {
        Stats {
            rays: self.rays.load(Ordering::Relaxed),
            seconds: self.nanos.load(Ordering::Relaxed) as f64 * 1e-9,
        }
    }

    pub fn reset_stats(&self) {
        self.rays.store(0, Ordering::Relaxed);
        self.nanos.store(0, Ordering::Relaxed);
    }

    /// The material of a hit (the default material if the index is out of range).
    pub fn material(&self, index: u32) -> &Material {
        self.scene.materials.get(index as usize).unwrap_or(&DEFAULT_MATERIAL)
    }

    /// Diffuse albedo at a hit: `base_color × texture.rgb` (linear; texture
    /// alpha and material opacity are not part of it: see [`Reference::opacity`],
    /// which only the [`oit`] oracles use — the others treat every surface as opaque).
    pub fn albedo(&self, hit: &SurfaceHit) -> Vec3 {
        let m = self.material(hit.material);
        let mut a = Vec3::from(m.base_color);
        if let Some(tex) = m.base_color_texture.and_then(|t| self.scene.textures.get(t)) {
            if tex.width > 0 && tex.height > 0 && tex.rgba8.len() >= (tex.width * tex.height * 4) as usize {
                let s = tex.sample_linear(hit.uv);
                a *= Vec3::new(s[0], s[1], s[2]);
            }
        }
        a
    }

    /// The primary hit through the centre of pixel (x, y): the closest surface
    /// with camera-space depth `t > camera.near`.
    pub fn primary_hit(&self, camera: &Camera, x: u32, y: u32, width: u32, height: u32) -> Option<SurfaceHit> {
        let dir = camera.pixel_dir(x, y, width, height);
        self.bvh
            .intersect(camera.eye, dir, camera.near, f32::INFINITY)
            .map(|h| self.bvh.surface(&h, dir))
    }

    /// Runs `f(x, y, &mut rays)` for every pixel, rows in parallel, and returns the
    /// results in row-major order. Counts rays and time into [`Reference::stats`].
    pub(crate) fn for_each_pixel<T, F>(&self, label: &str, width: u32, height: u32, f: F) -> Vec<T>
    where
        T: Send + Default + Clone,
        F: Fn(u32, u32, &mut u64) -> T + Sync,
    {
        let start = Instant::now();
        let mut out = vec![T::default(); width as usize * height as usize];
        if width == 0 || height == 0 {
            return out;
        }
        let bar = self.progress_bar(label, height as u64);
        out.par_chunks_mut(width as usize).enumerate().for_each(|(y, row)| {
            let mut rays = 0u64;
            for (x, px) in row.iter_mut().enumerate() {
                *px = f(x as u32, y as u32, &mut rays);
            }
            self.rays.fetch_add(rays, Ordering::Relaxed);
            bar.inc(1);
        });
        bar.finish_and_clear();
        self.nanos
            .fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
        out
    }

    fn progress_bar(&self, label: &str, len: u64) -> ProgressBar {
        if !self.progress || !std::io::stderr().is_terminal() {
            return ProgressBar::hidden();
        }
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
        if let Ok(style) =
            ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} rows {elapsed_precise} eta {eta}")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_message(label.to_string());
        bar
    }

    /// Measures ray throughput: repeated passes over a `width`×`height` image,
    /// each pixel tracing one closest-hit primary ray and, where it hits, one
    /// cosine-distributed closest-hit bounce ray (different per pass). Stops after
    /// the pass during which `max_rays` or `max_time` is reached (at least one pass).
    pub fn measure_throughput(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        max_rays: u64,
        max_time: Duration,
    ) -> Throughput {
        let start = Instant::now();
        let mut rays = 0u64;
        let mut pass = 0u64;
        loop {
            let counts = self.for_each_pixel("throughput", width, height, |x, y, n| {
                let dir = camera.pixel_dir(x, y, width, height);
                *n += 1;
                let Some(h) = self.bvh.intersect(camera.eye, dir, camera.near, f32::INFINITY) else {
                    return 1u64;
                };
                let s = self.bvh.surface(&h, dir);
                let (ns, ng) = s.facing_normals(dir);
                let key = sampling::hash(&[pass, (y as u64) << 32 | x as u64]);
                let wi = sampling::cosine_hemisphere(ns, sampling::pixel_offset(key));
                *n += 1;
                let _ = self
                    .bvh
                    .intersect(s.position + ng * self.epsilon, wi, 0.0, f32::INFINITY);
                2u64
            });
            rays += counts.iter().sum::<u64>();
            pass += 1;
            if rays >= max_rays || start.elapsed() >= max_time || rays == 0 {
                break;
            }
        }
        Throughput {
            rays,
            seconds: start.elapsed().as_secs_f64(),
            threads: rayon::current_num_threads(),
            triangles: self.bvh.triangles().len(),
        }
    }
}
