//! VPLs for interleaved deferred shading (ILS §6): generated on the CPU by
//! instant radiosity (`strata_reference::Reference::vpls`, one bounce = §6.2's
//! interactive mode) and handed to the renderer in `RenderSettings::ils`, as the
//! light probes are. Static scenes: generated once per run, for the first frame
//! rendered (a moving light would need `Renderer::set_vpls` per frame).

use std::sync::Arc;

use strata_render::passes::ils::GpuVpl;
use strata_render::RenderSettings;
use strata_scene::Scene;

/// `count` light paths of instant radiosity from the lights of `scene` at `frame` (seed 0).
pub fn scene_vpls(scene: &Scene, frame: f32, count: u32) -> Arc<[GpuVpl]> {
    strata_reference::Reference::new(scene, frame)
        .vpls(&strata_reference::vpl::VplSettings {
            paths: count,
            ..Default::default()
        })
        .iter()
        .map(|v| GpuVpl::new(v.position.into(), v.normal.into(), v.flux.into()))
        .collect()
}

/// Fills `settings.ils.vpls` (when ILS is on) with `vpl_count` paths' VPLs.
pub fn add_vpls(settings: &mut RenderSettings, scene: &Scene, frame: f32) {
    if let Some(ils) = &mut settings.ils {
        ils.vpls = scene_vpls(scene, frame, ils.vpl_count);
    }
}
