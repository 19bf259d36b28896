// `ao-resolve` (AoSettings::filter_obscurance): DGB Eq. 1's AV = max(0, 1 − √S)
// of the temporally and bilaterally filtered obscurance mean S.
#import "common/fullscreen.wgsl"

@group(0) @binding(0) var obscurance_in: texture_2d<f32>;

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let s = textureLoad(obscurance_in, vec2i(pos.xy), 0).r;
    return vec4f(max(0.0, 1.0 - sqrt(max(s, 0.0))));
}
