// Not in the paper: where `refine-peak` looks (IlsSettings::refine_peak; ils_refine.wgsl
// compares). A gathered texel holds one VPL subset ×n·m. A VPL close to the receivers
// lights its subset's texel of one n×m block and not those of the next blocks, and the
// blur spreads that spike over the block: a bright square where the brute force has a
// round blob. A subset that is bright over several blocks (a far VPL) varies slowly and
// the blur rebuilds it.
//
// fs_spike: a texel's spike over its own subset one pattern period away, in channel
//   sums, G(q) − min G(q ± (n, 0), q ± (0, m)) (the neighbours inside the image);
// fs_spread: the largest value within `radius` texels along `dir` (run along x, then y:
//   the largest spike within the blur's window of each pixel).
#import "common/fullscreen.wgsl"

struct Peak {
    pattern: vec2i,
    dir: vec2i,
    radius: i32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> peak: Peak;
// fs_spike: the gathered irradiance (rgb); fs_spread: the spikes (r)
@group(0) @binding(1) var src: texture_2d<f32>;

fn channel_sum(p: vec2i) -> f32 {
    let g = textureLoad(src, p, 0).rgb;
    return g.r + g.g + g.b;
}

@fragment
fn fs_spike(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let q = vec2i(pos.xy);
    let size = vec2i(textureDimensions(src));
    let g = channel_sum(q);
    let n = peak.pattern;
    var least = g;
    for (var k = 0; k < 4; k++) {
        let t = q + array<vec2i, 4>(vec2i(-n.x, 0), vec2i(n.x, 0), vec2i(0, -n.y), vec2i(0, n.y))[k];
        if (all(t >= vec2i(0)) && all(t < size)) {
            least = min(least, channel_sum(t));
        }
    }
    return vec4f(g - least, 0.0, 0.0, 0.0);
}

@fragment
fn fs_spread(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    let c = vec2i(pos.xy);
    let size = vec2i(textureDimensions(src));
    var m = textureLoad(src, c, 0).r;
    for (var k = 1; k <= peak.radius; k++) {
        for (var s = -1; s <= 1; s += 2) {
            let q = c + s * k * peak.dir;
            if (all(q >= vec2i(0)) && all(q < size)) {
                m = max(m, textureLoad(src, q, 0).r);
            }
        }
    }
    return vec4f(m, 0.0, 0.0, 0.0);
}
