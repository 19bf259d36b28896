// Exposure + ACES filmic tonemap; the sRGB target applies the sRGB transfer curve.
#import "common/frame.wgsl"
#import "common/color.wgsl"
#import "common/fullscreen.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var hdr_tex: texture_2d<f32>;

@fragment
fn fs_main(@builtin(position) frag: vec4f) -> @location(0) vec4f {
    let c = textureLoad(hdr_tex, vec2i(frag.xy), 0).rgb * frame.sky.w;
    return vec4f(tonemap_aces(c), 1.0);
}
