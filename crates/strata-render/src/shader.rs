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
    ("common/scissor.wgsl", include_str!("shaders/common/scissor.wgsl")),
    (
        "common/bzb_geometry.wgsl",
        include_str!("shaders/common/bzb_geometry.wgsl"),
    ),
    ("common/dss.wgsl", include_str!("shaders/common/dss.wgsl")),
    ("common/zminmax.wgsl", include_str!("shaders/common/zminmax.wgsl")),
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

#[cfg(test)]
mod tests {
    /// The value of `const NAME: T = VALUE;` in WGSL `source` (a `u`/`i` suffix dropped).
    fn wgsl_const(source: &str, name: &str) -> f64 {
        let prefix = format!("const {name}:");
        let line = source
            .lines()
            .map(str::trim)
            .find(|l| l.starts_with(&prefix))
            .unwrap_or_else(|| panic!("no `const {name}` in the WGSL"));
        let value = line.split('=').nth(1).expect("const without a value");
        let value = value.trim().trim_end_matches(';').trim_end_matches(['u', 'i']);
        value.parse().unwrap_or_else(|e| panic!("`{line}`: {e}"))
    }

    /// Constants that WGSL and their Rust CPU twins both declare are equal, so that a
    /// change on one side (e.g. the probes' distance-map size) cannot leave the other
    /// behind.
    #[test]
    fn wgsl_constants_equal_their_rust_twins() {
        let probes = include_str!("shaders/common/probes.wgsl");
        let radiosity = include_str!("passes/radiosity/radiosity.wgsl");
        let hbao = include_str!("passes/abuffer/hbao_compute.wgsl");
        let deep = include_str!("passes/deep_gbuffer/deep_gbuffer.wgsl");
        let dss = include_str!("shaders/common/dss.wgsl");
        use strata_scene::probes as p;
        let pairs: [(&str, &str, f64); 8] = [
            (probes, "PROBE_DEPTH_OCT", p::DEPTH_OCT as f64),
            (probes, "FACING_FLOOR", p::FACING_FLOOR as f64),
            (probes, "VISIBILITY_FLOOR", p::VISIBILITY_FLOOR as f64),
            (radiosity, "COVERAGE_COS", crate::passes::radiosity::COVERAGE_COS as f64),
            (hbao, "TILE", crate::passes::abuffer::ao::TILE as f64),
            (hbao, "SHARED_TEXELS", crate::passes::abuffer::ao::SHARED_TEXELS as f64),
            (
                deep,
                "SURFACE_TOLERANCE",
                crate::passes::deep_gbuffer::SURFACE_TOLERANCE as f64,
            ),
            (dss, "DSS_COPLANAR", crate::passes::bzb::dss::COPLANAR as f64),
        ];
        for (source, name, rust) in pairs {
            let wgsl = wgsl_const(source, name);
            assert!(
                (wgsl as f32 - rust as f32).abs() <= 1e-7 * rust.abs() as f32,
                "WGSL {name} = {wgsl}, Rust twin = {rust}"
            );
        }
    }
}
