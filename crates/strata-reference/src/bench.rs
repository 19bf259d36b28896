//! Ray throughput per kind of ray ([`Reference::measure_rays`]).

use std::time::{Duration, Instant};

use glam::Vec3;
use rayon::prelude::*;
use strata_scene::Camera;

use crate::sampling::{cosine_hemisphere, hash, pixel_offset, r2};
use crate::{Reference, Throughput};

/// The kinds of rays the reference traces, timed separately.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RayKind {
    /// Camera rays through pixel centres, closest hit (coherent).
    Primary,
    /// Cosine-distributed occlusion rays of length `radius` from the primary
    /// hits, any hit (short, many from one origin: the AO oracles' rays).
    Ao,
    /// Cosine-distributed bounce rays from the primary hits, closest hit,
    /// unbounded (incoherent: the path tracer's rays).
    Diffuse,
}

impl RayKind {
    pub const ALL: [RayKind; 3] = [RayKind::Primary, RayKind::Ao, RayKind::Diffuse];

    /// `"primary"`, `"ao"` or `"diffuse"`.
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Primary => "primary",
            RayKind::Ao => "ao",
            RayKind::Diffuse => "diffuse",
        }
    }
}

/// Secondary rays per pixel in one pass.
const PER_PASS: u32 = 16;

impl Reference<'_> {
    /// Throughput of one kind of ray: repeated passes over a `width`×`height`
    /// image until `max_rays` or `max_time` is reached (at least one pass). For
    /// [`RayKind::Ao`] and [`RayKind::Diffuse`] the primary hits are found first,
    /// untimed, and each pass traces 16 rays per hit pixel (R2 directions with a
    /// per-pixel rotation, origins offset by [`Reference::epsilon`]); AO rays end
    /// at `ao_radius`. Rays counted here are not added to [`Reference::stats`].
    #[allow(clippy::too_many_arguments)]
    pub fn measure_rays(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        kind: RayKind,
        ao_radius: f32,
        max_rays: u64,
        max_time: Duration,
    ) -> Throughput {
        let (w, h) = (width as usize, height as usize);
        let hits: Vec<Option<(Vec3, Vec3)>> = if kind == RayKind::Primary {
            Vec::new()
        } else {
            (0..w * h)
                .into_par_iter()
                .map(|i| {
                    let (x, y) = ((i % w.max(1)) as u32, (i / w.max(1)) as u32);
                    let dir = camera.pixel_dir(x, y, width, height);
                    let hit = self.bvh.intersect(camera.eye, dir, camera.near, f32::INFINITY)?;
                    let s = self.bvh.surface(&hit, dir);
                    let (n, ng) = s.facing_normals(dir);
                    Some((s.position + ng * self.epsilon, n))
                })
                .collect()
        };
        let start = Instant::now();
        let mut rays = 0u64;
        let mut pass = 0u32;
        // Folded into a checksum so no query can be optimised away.
        let mut check = 0u64;
        loop {
            let (n, c) = match kind {
                RayKind::Primary => (0..h)
                    .into_par_iter()
                    .map(|y| {
                        let mut c = 0u64;
                        for x in 0..w {
                            let dir = camera.pixel_dir(x as u32, y as u32, width, height);
                            if let Some(hit) = self.bvh.intersect(camera.eye, dir, camera.near, f32::INFINITY) {
                                c = c.wrapping_add(hit.triangle as u64 + 1);
                            }
                        }
                        (w as u64, c)
                    })
                    .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1.wrapping_add(b.1))),
                RayKind::Ao | RayKind::Diffuse => hits
                    .par_chunks(w.max(1))
                    .enumerate()
                    .map(|(y, row)| {
                        let (mut n, mut c) = (0u64, 0u64);
                        for (x, hit) in row.iter().enumerate() {
                            let Some((origin, normal)) = *hit else { continue };
                            let offset = pixel_offset(hash(&[0x0062_656e_6368, (y * w + x) as u64]));
                            for i in 0..PER_PASS {
                                let d =
                                    cosine_hemisphere(normal, r2(pass.wrapping_mul(PER_PASS).wrapping_add(i), offset));
                                c = c.wrapping_add(if kind == RayKind::Ao {
                                    self.bvh.occluded(origin, d, 0.0, ao_radius) as u64
                                } else {
                                    self.bvh
                                        .intersect(origin, d, 0.0, f32::INFINITY)
                                        .map_or(0, |h| h.triangle as u64 + 1)
                                });
                            }
                            n += PER_PASS as u64;
                        }
                        (n, c)
                    })
                    .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1.wrapping_add(b.1))),
            };
            rays += n;
            check = check.wrapping_add(c);
            pass = pass.wrapping_add(1);
            if rays >= max_rays || start.elapsed() >= max_time || n == 0 {
                break;
            }
        }
        std::hint::black_box(check);
        Throughput {
            rays,
            seconds: start.elapsed().as_secs_f64(),
            threads: rayon::current_num_threads(),
            triangles: self.bvh.triangles().len(),
        }
    }
}
