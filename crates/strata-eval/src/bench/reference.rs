//! `strata bench reference`: CPU reference throughput (million rays per second).

use std::time::Duration;

use anyhow::{bail, Result};
use strata_reference::{RayKind, Reference, TracerKind};

use crate::results::{RayKindBench, ReferenceBench};
use crate::scene::SceneSpec;

/// Traces about `mrays` million rays (primary + 1 diffuse bounce) from the scene's camera
/// with the default tracer, then about `mrays` million of each kind of ray (primary,
/// AO of the scene's radius, diffuse bounce) with every tracer backend.
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
    let bvh_build_s = reference.build_seconds();
    drop(reference);
    let mut kinds = Vec::new();
    for tracer in TracerKind::ALL {
        let r = Reference::with_tracer(&scene, spec.frame, tracer).with_progress(false);
        for kind in RayKind::ALL {
            let radius = scene.settings.ao_radius;
            let k = r.measure_rays(
                &cams.current,
                spec.width,
                spec.height,
                kind,
                radius,
                (mrays * 1e6) as u64,
                Duration::from_secs(600),
            );
            kinds.push(RayKindBench {
                tracer: tracer.name().into(),
                kind: kind.name().into(),
                build_s: r.build_seconds(),
                rays: k.rays,
                seconds: k.seconds,
                mrays_per_s: k.mrays_per_second(),
                ao_radius: (kind == RayKind::Ao).then_some(radius),
            });
        }
    }
    Ok(ReferenceBench {
        scene: spec.scene.clone(),
        triangles: scene.triangle_count(),
        width: spec.width,
        height: spec.height,
        threads: t.threads,
        bvh_build_s,
        rays: t.rays,
        seconds: t.seconds,
        mrays_per_s: t.mrays_per_second(),
        kinds,
    })
}
