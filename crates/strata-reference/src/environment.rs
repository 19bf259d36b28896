//! Baking a radiance environment map ([`EnvironmentMap`], DGB §3.6's fallback for mirror
//! rays that find nothing on screen) with the path tracer.

use glam::Vec3;
use rayon::prelude::*;
use strata_scene::environment::EnvironmentMap;

use crate::gi::GiSettings;
use crate::sampling::{hash, Rng};
use crate::Reference;

impl Reference<'_> {
    /// The radiance arriving at `center` over `size`×`size` texels per cube face: per texel
    /// the mean of `paths` path samples (`settings.bounces` bounces) along directions
    /// spread uniformly over the texel's face coordinates. Each sample is the full
    /// radiance a mirror there would reflect: the first surface's emission, direct light
    /// and further bounces, or the sky.
    pub fn bake_environment(&self, center: Vec3, size: u32, paths: u32, settings: &GiSettings) -> EnvironmentMap {
        let (n, paths) = (size.max(1), paths.max(1));
        let texels = (0..6 * n * n)
            .into_par_iter()
            .map(|k| {
                let (face, j, i) = ((k / (n * n)) as usize, (k / n) % n, k % n);
                let mut rng = Rng::new(hash(&[settings.seed, 0xe11u64, k as u64]));
                let mut traced = 0u64;
                let mut sum = Vec3::ZERO;
                for _ in 0..paths {
                    let s = (i as f32 + rng.next_f32()) / n as f32;
                    let t = (j as f32 + rng.next_f32()) / n as f32;
                    let d = EnvironmentMap::direction(face, s, t);
                    let (direct, indirect) = self.path_radiance(center, d, settings, &mut rng, &mut traced);
                    sum += direct + indirect;
                }
                (sum / paths as f32).to_array()
            })
            .collect();
        EnvironmentMap {
            center: center.to_array(),
            size: n,
            texels,
        }
    }
}
