// DGB §3.3 progressive multi-bounce: each layer's radiosity input B for this
// frame's gather = its direct light + emission (lighting pass) plus the
// reflection of last frame's final indirect irradiance, reverse-reprojected
// and damped by δ: B = B_direct + δ · ρ/π · boost(ρ) · E_{t−1}. Propagating to
// layer 1 too (Fig. 5) uses layer 1's own E_{t−1}.
#import "common/fullscreen.wgsl"
#import "common/color.wgsl"
#import "common/frame.wgsl"
#import "common/camera.wgsl"
#import "common/reproject.wgsl"

override LAYERS: u32 = 2u;

// Matches `radiosity::PropagateUniforms`.
struct Propagate {
    delta: f32,
    max_distance: f32,
    has_history: u32,
    boost: u32,
    // 1 = per-object velocities (`TemporalSettings::object_motion`)
    motion: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> prop: Propagate;
@group(1) @binding(1) var csz: texture_2d_array<f32>;
@group(1) @binding(2) var albedo: texture_2d_array<f32>;
@group(1) @binding(3) var normal: texture_2d_array<f32>;
@group(1) @binding(4) var direct0: texture_2d<f32>;
@group(1) @binding(5) var direct1: texture_2d<f32>;
@group(1) @binding(6) var csz_history: texture_2d_array<f32>;
// last frame's final E of layer 0 and E of layer 1
@group(1) @binding(7) var e0_history: texture_2d<f32>;
@group(1) @binding(8) var e1_history: texture_2d<f32>;
// each layer's world-space motion since last frame (the deep G-buffer's `motion`)
@group(1) @binding(9) var motion: texture_2d_array<f32>;

struct Out {
    @location(0) b0: vec4f,
    @location(1) b1: vec4f,
}

fn bounce_input(p: vec2i, j: i32, direct: vec3f) -> vec3f {
    let z = textureLoad(csz, p, j, 0).r;
    if (z <= 0.0 || prop.has_history == 0u || prop.delta <= 0.0) {
        return direct;
    }
    var x = world_from_csz(frame, vec2f(p) + 0.5, z);
    if (prop.motion != 0u) {
        x -= textureLoad(motion, p, j, 0).xyz;
    }
    let r = reproject(frame, x);
    let l = matching_layer(csz_history, r, LAYERS, prop.max_distance);
    if (l < 0) {
        return direct;
    }
    var e = bilinear_at(e0_history, r.c).rgb;
    if (l == 1) {
        e = bilinear_at(e1_history, r.c).rgb;
    }
    let rho = textureLoad(albedo, p, j, 0).rgb * (1.0 - textureLoad(normal, p, j, 0).a);
    var k = 1.0;
    if (prop.boost != 0u) {
        k = boost(rho);
    }
    return direct + prop.delta * rho / 3.14159265358979 * k * e;
}

// Both layers' B at pixel p.
fn propagated(p: vec2i) -> Out {
    var o: Out;
    o.b0 = vec4f(bounce_input(p, 0, textureLoad(direct0, p, 0).rgb), 1.0);
    if (LAYERS > 1u) {
        o.b1 = vec4f(bounce_input(p, 1, textureLoad(direct1, p, 0).rgb), 1.0);
    }
    return o;
}

@fragment
fn fs_main(@builtin(position) pos: vec4f) -> Out {
    return propagated(vec2i(pos.xy));
}

// The same pass as compute (`Kernel`), 8×8 pixels per workgroup.
@group(1) @binding(10) var b0_out: texture_storage_2d<STORAGE_FORMAT_0, write>;
@group(1) @binding(11) var b1_out: texture_storage_2d<STORAGE_FORMAT_1, write>;

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(b0_out))) {
        return;
    }
    let o = propagated(vec2i(id.xy));
    textureStore(b0_out, id.xy, o.b0);
    textureStore(b1_out, id.xy, o.b1);
}
