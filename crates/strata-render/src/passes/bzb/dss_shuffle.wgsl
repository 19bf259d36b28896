// BZB §4.1 (Fig. 5) shuffling: every texel of the stacked hierarchical
// framebuffer (level l, direction tile s, sub-image k, neighbourhood nb) gets
// the receiver of pixel nb·2^l + offset(σ(k)) of the frame: its ray origin x_p
// and (visibility on) its direction ω_p with pdf α, or (visibility off, the
// additive baseline) its normal n_p. Texels whose pixel lies in the padding or
// shows no surface get w = 0 (no sample); else the origin's w = 1 + the pixel's
// index (exact in f32 up to 2^24 pixels).
#import "common/fullscreen.wgsl"
#import "common/packing.wgsl"
#import "common/dss.wgsl"

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> dss: Dss;
@group(1) @binding(1) var origins: texture_2d<f32>;
@group(1) @binding(2) var directions: texture_2d<f32>;
@group(1) @binding(3) var npack: texture_2d<f32>;

struct ShuffleOut {
    @location(0) origin: vec4f,
    @location(1) direction: vec4f,
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> ShuffleOut {
    var out: ShuffleOut;
    let texel = vec2u(pos.xy);
    let band = dss.rows * dss.plane.y;
    let level = texel.y / band;
    let in_band = vec2u(texel.x, texel.y % band);
    let tile = in_band / dss.plane;
    let s = tile.y * dss.cols + tile.x;
    if (s >= dss.directions || level >= dss.levels) {
        return out;
    }
    let t = in_band % dss.plane;
    let b = 1u << level;
    let sub = dss.plane / b;
    let kk = t / sub;
    let k = kk.y * b + kk.x;
    let nb = t % sub;
    let j = dss_sigma(k, nb, level, s, dss.seed);
    let p = nb * b + vec2u(j % b, j / b);
    if (any(p >= dss.size)) {
        return out;
    }
    let src = vec2i(vec2u(s % dss.cols, s / dss.cols) * dss.size + p);
    out.origin = textureLoad(origins, src, 0);
    if (out.origin.w > 0.0) {
        // w = 1 + the pixel's index: the splat reads the receiver's normal from npack
        out.origin.w = f32(1u + p.y * dss.size.x + p.x);
    }
    if (dss.visibility == 1u) {
        out.direction = textureLoad(directions, src, 0);
    } else if (out.origin.w > 0.0) {
        out.direction = vec4f(oct_decode(textureLoad(npack, vec2i(p), 0).rg), 1.0);
    }
    return out;
}
