// BZB §4.2 reduction: the levels combined per (pixel, direction). With
// visibility the finest level with a surfel hit is kept (levels hold disjoint,
// increasing distance ranges: the most precise hit); without, the levels' shell
// contributions are summed (the original DSS). Output: the bounced z-buffer's
// payload (`bzb-payload`, or bzb-gi's RGBA `bzb-gi-payload`), reconstructed and
// filtered by the AOV path's (or bzb-gi's) passes.
#import "common/fullscreen.wgsl"
#import "common/dss.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> dss: Dss;
@group(1) @binding(1) var unshuffled: texture_2d<f32>;

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let texel = vec2u(pos.xy);
    let band = dss.rows * dss.size.y;
    var sum = vec4f(0.0);
    for (var l = 0u; l < dss.levels; l++) {
        let v = textureLoad(unshuffled, vec2i(texel + vec2u(0u, l * band)), 0);
        if (dss.visibility == 1u) {
            // bzb-gi: alpha flags a hit (a black sender still blocks); bzb-ao: occlusion 1
            if (select(v.r, v.a, dss.gi == 1u) > 0.0) {
                return select(vec4f(v.r), v, dss.gi == 1u);
            }
        } else {
            sum += v;
        }
    }
    return select(vec4f(sum.r), sum, dss.gi == 1u);
}
