//! `strata bench reference`: CPU reference throughput (million rays per second).

use std::time::Duration;

use anyhow::{bail, Result};
use strata_reference::Reference;

use crate::results::ReferenceBench;
use crate::scene::SceneSpec;

/// Traces about `mrays` million rays (primary + 1 diffuse bounce) from the scene's camera.
pub fn run(spec: &SceneSpec, mrays: f64) -> Result<ReferenceBench> {
    let (scene, cams) = spec.load()?;
    if !(mrays > 0.0 && mrays <= 10_000.0) {
        bail!("--mrays {mrays} is out of range: must be in (0, 10000]");
    }
    let reference = Reference::new(&scene, spec.frame).with_progress(false);
    let t = reference.measure_throughput(
        &cams.current,
        spec.width,
        spec.height,
        (mrays * 1e6) as u64,
        Duration::from_secs(600),
    );
    Ok(ReferenceBench {
        scene: spec.scene.clone(),
        triangles: scene.triangle_count(),
        width: spec.width,
        height: spec.height,
        threads: t.threads,
        bvh_build_s: reference.build_seconds(),
        rays: t.rays,
        seconds: t.seconds,
        mrays_per_s: t.mrays_per_second(),
    })
}
