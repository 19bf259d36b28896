// Camera-space depth MIP chain of all deep-G-buffer layers (SAO-style): level 0
// gathers the Table 1 packed depths (one channel per layer); each coarser texel
// copies ONE texel of the finer level chosen on a rotated grid, so every level
// holds real surface depths (never an average across surfaces).
#import "common/fullscreen.wgsl"

override LAYERS: u32 = 2u;

// level 0: zpack (layers 0, 1) and zpack23 (layers 2, 3; = zpack when k <= 2)
// level m > 0: both bindings are level m - 1
@group(0) @binding(0) var src01: texture_2d<f32>;
@group(0) @binding(1) var src23: texture_2d<f32>;

fn level0(p: vec2i) -> vec4f {
    let z01 = textureLoad(src01, p, 0).rg;
    var z23 = vec2f(0.0);
    if (LAYERS > 2u) {
        z23 = textureLoad(src23, p, 0).rg;
    }
    return vec4f(z01, z23);
}

fn downsample(p: vec2i) -> vec4f {
    // SAO's rotated-grid choice among the four children
    let child = p * 2 + vec2i((p.y & 1) ^ 1, (p.x & 1) ^ 1);
    let last = vec2i(textureDimensions(src01)) - 1;
    return textureLoad(src01, min(child, last), 0);
}

@fragment
fn fs_level0(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    return level0(vec2i(pos.xy));
}

@fragment
fn fs_downsample(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    return downsample(vec2i(pos.xy));
}

// The same passes as compute (`Kernel`), 8×8 texels per workgroup, into one MIP level.
@group(0) @binding(2) var dst: texture_storage_2d<STORAGE_FORMAT_0, write>;

@compute @workgroup_size(8, 8)
fn cs_level0(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(dst))) {
        return;
    }
    textureStore(dst, id.xy, level0(vec2i(id.xy)));
}

@compute @workgroup_size(8, 8)
fn cs_downsample(@builtin(global_invocation_id) id: vec3u) {
    if (any(id.xy >= textureDimensions(dst))) {
        return;
    }
    textureStore(dst, id.xy, downsample(vec2i(id.xy)));
}
