// ILS §4.1: the G-buffer of layer 0 packed into the one buffer that is split
// (§4.2): world normal (xyz) and camera-space depth z (w; 0 = no surface). The
// shading reconstructs positions from z and the pixel (common/camera.wgsl).
#import "common/fullscreen.wgsl"
#import "common/packing.wgsl"

@group(0) @binding(0) var csz_in: texture_2d<f32>;
@group(0) @binding(1) var normal_in: texture_2d<f32>;

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let p = vec2i(pos.xy);
    let z = textureLoad(csz_in, p, 0).r;
    if (z <= 0.0) {
        return vec4f(0.0);
    }
    return vec4f(oct_decode(textureLoad(normal_in, p, 0).rg), z);
}
