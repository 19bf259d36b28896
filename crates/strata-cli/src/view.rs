//! `strata view`: the interactive viewer (`strata_view`), with the settings of every
//! frame built by `render`'s own code ([`crate::render::settings_for`]).

use anyhow::{bail, Result};
use clap::Parser;

use crate::args::{FrameArgs, ViewArgs};
use crate::output::scene_and_camera;

/// `strata render`'s frame flags, parsed on their own: what the viewer's panels produce.
#[derive(Parser)]
#[command(name = "strata render", no_binary_name = false)]
struct RenderFlags {
    #[command(flatten)]
    frame: FrameArgs,
}

/// Flags that take a value and that the viewer manages itself (scene, camera, size,
/// technique and its settings) or that only `view` has.
const MANAGED: &[&str] = &[
    "--scene",
    "--width",
    "--height",
    "--eye",
    "--target",
    "--up",
    "--fov",
    "--camera",
    "--frame",
    "--technique",
    "--preset",
    "--layers",
    "--variant",
    "--layer-scale",
    "--guard-band",
    "--exposure",
    "--set",
    "--debug-view",
    "--frames",
    "--screenshot",
    "--window-screenshot",
    "--script",
    "--motion-scale",
];

/// The `render` flags of the command line that the viewer does not manage, verbatim
/// (e.g. `--samples 32 --no-probes`), and the raw `--guard-band` and `--exposure` values.
fn passthrough(argv: &[String]) -> (Vec<String>, Option<String>, Option<String>) {
    let mut out = Vec::new();
    let mut guard = None;
    let mut exposure = None;
    let mut i = 0;
    while i < argv.len() {
        let a = &argv[i];
        let (name, inline) = match a.split_once('=') {
            Some((n, v)) if n.starts_with("--") => (n, Some(v.to_string())),
            _ => (a.as_str(), None),
        };
        if MANAGED.contains(&name) {
            let v = match inline {
                Some(v) => v,
                None => {
                    i += 1;
                    argv.get(i).cloned().unwrap_or_default()
                }
            };
            match name {
                "--guard-band" => guard = Some(v),
                "--exposure" => exposure = Some(v),
                _ => {}
            }
        } else if name != "--force" {
            out.push(a.clone());
        }
        i += 1;
    }
    (out, guard, exposure)
}

fn clap_line(e: clap::Error) -> String {
    crate::one_line(&e.render().to_string())
}

pub fn run(a: &ViewArgs) -> Result<()> {
    let f = &a.frame;
    if !(0.1..=1.0).contains(&a.motion_scale) {
        bail!("--motion-scale {} is out of range: must be in 0.1..=1", a.motion_scale);
    }
    for (flag, p) in [
        ("--screenshot", &a.screenshot),
        ("--window-screenshot", &a.window_screenshot),
    ] {
        if let Some(p) = p {
            if !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
                bail!("{flag} {}: use a .png file name", p.display());
            }
            strata_eval::files::check_output_for(flag, p, a.force)?;
        }
    }
    let script = match &a.script {
        Some(p) => Some(strata_view::Script::load(p).map_err(|e| anyhow::anyhow!(e))?),
        None => None,
    };
    let (scene, cams) = scene_and_camera(&f.scene)?;
    // the same checks as `render` before a window opens
    crate::render::settings_for(f, &scene)?;

    let argv: Vec<String> = std::env::args().skip_while(|x| x != "view").skip(1).collect();
    let (extra, guard, exposure) = passthrough(&argv);
    let t = f.technique;
    let spec = strata_view::RenderSpec {
        technique: t.name.to_string(),
        // `settings_for` above refused a preset for a technique without presets
        preset: f.radiosity.preset.clone(),
        layers: f.deep.layers,
        variant: f.deep.variant.to_string(),
        layer_scale: f.deep.layer_scale,
        guard_band: guard.unwrap_or_else(|| "auto".into()),
        exposure,
        sets: f.set.values.iter().map(|(n, v)| (n.clone(), v.to_string())).collect(),
        extra,
    };
    let settings: strata_view::SettingsFn = Box::new(|scene, args| {
        let flags =
            RenderFlags::try_parse_from(std::iter::once("strata render".to_string()).chain(args.iter().cloned()))
                .map_err(clap_line)?;
        crate::render::settings_for(&flags.frame, scene).map_err(|e| format!("{e:#}").replace('\n', " "))
    });
    strata_view::run(strata_view::ViewOptions {
        scene_spec: f.scene.scene.clone(),
        scene,
        camera: cams.current,
        camera_index: f.scene.camera,
        frame: f.scene.frame,
        width: f.scene.width,
        height: f.scene.height,
        spec,
        debug_view: a.debug_view.clone(),
        frames: a.frames,
        screenshot: a.screenshot.clone(),
        window_screenshot: a.window_screenshot.clone(),
        script,
        motion_scale: a.motion_scale,
        adapter: f.gpu.adapter.clone(),
        settings,
        vpls: Some(Box::new(|scene, t, count| {
            strata_eval::vpls::scene_vpls(scene, t, count).to_vec()
        })),
    })
    .map_err(|e| anyhow::anyhow!(e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passthrough_keeps_render_flags_and_drops_managed_ones() {
        let argv: Vec<String> = "--scene cornell --samples 32 --technique=ao --set radius=1 --guard-band 10% --no-probes --exposure=auto --eye -1,2,3 --force --frames 3"
            .split(' ')
            .map(String::from)
            .collect();
        let (extra, guard, exposure) = passthrough(&argv);
        assert_eq!(extra, ["--samples", "32", "--no-probes"]);
        assert_eq!(guard.as_deref(), Some("10%"));
        assert_eq!(exposure.as_deref(), Some("auto"));
    }
}
