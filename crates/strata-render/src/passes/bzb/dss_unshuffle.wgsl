// BZB §4.1 unshuffling: the splat payload of every level back to the frame's
// pixel order. Output: the levels stacked (level l = rows·H rows at y = l·rows·H),
// each in the bounced z-buffer's layout (direction s = W × H tile s).
#import "common/fullscreen.wgsl"
#import "common/dss.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> dss: Dss;
@group(1) @binding(1) var payload: texture_2d<f32>;

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let texel = vec2u(pos.xy);
    let band = dss.rows * dss.size.y;
    let level = texel.y / band;
    let in_band = vec2u(texel.x, texel.y % band);
    let tile = in_band / dss.size;
    let s = tile.y * dss.cols + tile.x;
    if (s >= dss.directions || level >= dss.levels) {
        return vec4f(0.0);
    }
    let p = in_band % dss.size;
    let b = 1u << level;
    let nb = p / b;
    let off = p % b;
    let k = dss_sigma_inverse(off.y * b + off.x, nb, level, s, dss.seed);
    return textureLoad(payload, vec2i(dss_texel(level, s, k, nb, dss.cols, dss.rows, dss.plane)), 0);
}
