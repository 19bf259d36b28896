//! The reflection rays' environment map for `--technique full` (DGB §3.6: rays that find
//! nothing on screen "revert to mirror reflection environment map lookups"): the radiance
//! arriving at the scene camera's position, baked once per scene with the CPU path tracer
//! and cached next to the reference images.

use anyhow::Result;
use strata_reference::gi::GiSettings;
use strata_reference::Reference;
use strata_scene::environment::EnvironmentMap;
use strata_scene::{ImageBuf, Scene};

use super::{scene_fingerprint, RefCache};

/// Texels per cube face side.
pub const SIZE: u32 = 32;
/// Paths per texel.
pub const PATHS: u32 = 256;
/// Bounces of each path after its first hit, as the light probes'.
pub const BOUNCES: u32 = super::probes::BOUNCES;

/// Whether a material of `scene` is a mirror for the reflection pass (metallic ≥ ½ and
/// roughness ≤ `max_roughness`; both are per-material scalars in strata's scenes): only
/// then does a reflection ray read the environment map.
pub fn has_mirrors(scene: &Scene, max_roughness: f32) -> bool {
    scene
        .materials
        .iter()
        .any(|m| m.metallic >= 0.5 && m.roughness <= max_roughness)
}

/// The scene's environment map at animation frame 0, seen from its camera's position,
/// from the cache or baked (with a notice on stderr unless `quiet`).
pub fn scene_environment(scene: &Scene, cache: &RefCache, quiet: bool) -> Result<EnvironmentMap> {
    let center = scene.camera.eye;
    let description = format!(
        "v1 environment {} center={center:?} size={SIZE} paths={PATHS} bounces={BOUNCES}",
        scene_fingerprint(scene, 0.0)
    );
    let key = RefCache::key(&description);
    if let Some(e) = cache.load(&key).and_then(|img| decode(&img)) {
        return Ok(e);
    }
    if !quiet {
        eprintln!("baking the reflections' environment map (6×{SIZE}² texels, {PATHS} paths each)…");
    }
    let settings = GiSettings {
        bounces: BOUNCES,
        ..Default::default()
    };
    let e = Reference::new(scene, 0.0).bake_environment(center, SIZE, PATHS, &settings);
    if let Err(err) = cache.store(&key, &encode(&e), &description) {
        tracing::warn!("could not cache the environment map: {err:#}");
    }
    Ok(e)
}

/// Rows 0..6·size: the texels (rgb); the last row: the centre and the size.
fn encode(e: &EnvironmentMap) -> ImageBuf {
    let mut img = ImageBuf::new(e.size, 6 * e.size + 1, 3);
    let n = e.texels.len() * 3;
    img.data[..n].copy_from_slice(&e.texels.concat());
    img.data[n..n + 3].copy_from_slice(&e.center);
    img.data[n + 3] = e.size as f32;
    img
}

fn decode(img: &ImageBuf) -> Option<EnvironmentMap> {
    let size = img.width;
    if img.channels != 3 || size == 0 || img.height != 6 * size + 1 {
        return None;
    }
    let n = (6 * size * size) as usize;
    let d = &img.data;
    (d[3 * n + 3] as u32 == size).then(|| EnvironmentMap {
        center: [d[3 * n], d[3 * n + 1], d[3 * n + 2]],
        size,
        texels: d[..3 * n].chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cache_encoding_round_trips() {
        let e = EnvironmentMap {
            center: [1.0, -2.0, 3.5],
            size: 3,
            texels: (0..54).map(|k| [k as f32, 0.5 * k as f32, 2.0]).collect(),
        };
        assert_eq!(decode(&encode(&e)), Some(e));
    }
}
