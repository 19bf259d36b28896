// Exposure + ACES filmic tonemap; the sRGB target applies the sRGB transfer curve.
#import "common/frame.wgsl"
#import "common/color.wgsl"
#import "common/fullscreen.wgsl"

// 1: the exposure is the metered one (`passes/exposure`), else the frame's
override AUTO_EXPOSURE: u32 = 0u;

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var hdr_tex: texture_2d<f32>;
// [0] the metered exposure (AUTO_EXPOSURE; a stand-in otherwise)
@group(1) @binding(1) var<storage, read> metered: array<f32>;

fn exposure() -> f32 {
    if (AUTO_EXPOSURE != 0u) {
        return metered[0];
    }
    return frame.sky.w;
}

@fragment
fn fs_main(@builtin(position) frag: vec4f) -> @location(0) vec4f {
    let c = textureLoad(hdr_tex, vec2i(frag.xy), 0).rgb * exposure();
    return vec4f(tonemap_aces(c), 1.0);
}
