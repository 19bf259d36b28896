//! WGSL composition: `#import "common/NAME.wgsl"` (and `"abuffer/lists.wgsl"`, `"abuffer/ao_common.wgsl"`) lines are replaced by the shared
//! module's text (each module once per shader), so shared code lives once.

/// Shared WGSL modules, by import path.
const COMMON: &[(&str, &str)] = &[
    ("common/frame.wgsl", include_str!("shaders/common/frame.wgsl")),
    ("common/packing.wgsl", include_str!("shaders/common/packing.wgsl")),
    ("common/camera.wgsl", include_str!("shaders/common/camera.wgsl")),
    ("common/color.wgsl", include_str!("shaders/common/color.wgsl")),
    ("common/fullscreen.wgsl", include_str!("shaders/common/fullscreen.wgsl")),
    ("common/scene.wgsl", include_str!("shaders/common/scene.wgsl")),
    ("common/spiral.wgsl", include_str!("shaders/common/spiral.wgsl")),
    ("common/reproject.wgsl", include_str!("shaders/common/reproject.wgsl")),
    ("common/interleave.wgsl", include_str!("shaders/common/interleave.wgsl")),
    ("common/ggx.wgsl", include_str!("shaders/common/ggx.wgsl")),
    ("common/vpl.wgsl", include_str!("shaders/common/vpl.wgsl")),
    ("common/lights.wgsl", include_str!("shaders/common/lights.wgsl")),
    ("common/shadow.wgsl", include_str!("shaders/common/shadow.wgsl")),
    ("common/probes.wgsl", include_str!("shaders/common/probes.wgsl")),
    ("common/obscurance.wgsl", include_str!("shaders/common/obscurance.wgsl")),
    (
        "common/bzb_geometry.wgsl",
        include_str!("shaders/common/bzb_geometry.wgsl"),
    ),
    ("common/dss.wgsl", include_str!("shaders/common/dss.wgsl")),
    ("abuffer/lists.wgsl", include_str!("passes/abuffer/lists.wgsl")),
    ("abuffer/ao_common.wgsl", include_str!("passes/abuffer/ao_common.wgsl")),
    ("ao/uniforms.wgsl", include_str!("passes/ao/uniforms.wgsl")),
];

/// Expands `#import "…"` lines recursively; panics only on a missing module,
/// which is a programming error caught by every GPU test.
pub fn compose(source: &str) -> String {
    let mut seen = Vec::new();
    let mut out = String::new();
    expand(source, &mut seen, &mut out);
    out
}

fn expand(source: &str, seen: &mut Vec<&'static str>, out: &mut String) {
    for line in source.lines() {
        let t = line.trim();
        if let Some(rest) = t.strip_prefix("#import") {
            let name = rest.trim().trim_matches('"');
            let (key, text) = COMMON
                .iter()
                .find(|(k, _)| *k == name)
                .unwrap_or_else(|| panic!("WGSL import '{name}' is not a shared module"));
            if !seen.contains(key) {
                seen.push(key);
                expand(text, seen, out);
            }
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
}

/// Creates a shader module from a pass's WGSL (with imports expanded).
pub fn module(device: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(compose(source).into()),
    })
}
