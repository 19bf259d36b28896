//! VPLs for interleaved deferred shading (ILS §6): generated on the CPU by
//! instant radiosity (`strata_reference::Reference::vpls`, one bounce = §6.2's
//! interactive mode) and handed to the renderer in `RenderSettings::ils`, as the
//! light probes are. Static scenes: generated once per run, for the first frame
//! rendered. Scenes with animated objects: [`refresh_vpls`] per frame (`strata soak`,
//! `strata view`), through `Renderer::set_vpls`.

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

/// Regenerates the VPLs of a renderer with an ILS stage for `frame` when `scene` has
/// animated objects (the paths bounce off where the objects are now), with the
/// `vpl_count` it was built with. Returns whether it did; static scenes keep the VPLs
/// they were built with.
pub fn refresh_vpls(
    r: &mut strata_render::Renderer,
    gpu: &strata_render::GpuContext,
    scene: &Scene,
    frame: f32,
) -> Result<bool, strata_render::RenderError> {
    let Some(count) = r.settings.ils.as_ref().map(|i| i.vpl_count) else {
        return Ok(false);
    };
    if !scene.animated() {
        return Ok(false);
    }
    r.set_vpls(gpu, &scene_vpls(scene, frame, count))?;
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_render::frame::FrameCameras;
    use strata_render::{GpuContext, GpuOptions, Renderer};

    /// The atrium's statue slides 1.5 m by frame 15. A renderer built with frame 0's
    /// VPLs and refreshed for frame 15 gives, bit for bit, the irradiance of a renderer
    /// built with frame 15's VPLs. Without the refresh it differs (the VPLs on the
    /// statue hang where it was), and a static scene keeps its VPLs.
    #[test]
    fn refreshed_vpls_follow_the_animated_objects() {
        let gpu = GpuContext::new(&GpuOptions::default()).expect("a Vulkan adapter");
        let scene = strata_scene::procedural::builtin("atrium").unwrap();
        assert!(scene.animated());
        let t = strata_render::technique::find("ils").unwrap();
        let base = RenderSettings {
            width: 96,
            height: 54,
            ..Default::default()
        };
        let renderer = |frame: f32| {
            let mut s = t.settings(&base, None).unwrap();
            add_vpls(&mut s, &scene, frame);
            Renderer::new(&gpu, &scene, s).unwrap()
        };
        let irradiance = |r: &mut Renderer| {
            let cams = FrameCameras::fixed(scene.camera_at(15.0));
            r.render(&gpu, &scene, &cams, 15.0).unwrap();
            let img = r.read_target(&gpu, "ils-irradiance").unwrap();
            gpu.check_errors().unwrap();
            img.data
        };
        let want = irradiance(&mut renderer(15.0));
        let mut stale = renderer(0.0);
        let stale_image = irradiance(&mut stale);
        assert_ne!(stale_image, want, "frame 0's VPLs light frame 15 differently");
        assert!(refresh_vpls(&mut stale, &gpu, &scene, 15.0).unwrap());
        assert_eq!(irradiance(&mut stale), want, "refreshed VPLs = frame 15's");

        let still = strata_scene::procedural::builtin("cornell").unwrap();
        let mut s = t.settings(&base, None).unwrap();
        add_vpls(&mut s, &still, 0.0);
        let mut r = Renderer::new(&gpu, &still, s).unwrap();
        assert!(
            !refresh_vpls(&mut r, &gpu, &still, 15.0).unwrap(),
            "a static scene keeps its VPLs"
        );
    }
}
