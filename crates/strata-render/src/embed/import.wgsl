// The application's G-buffer → strata's deep G-buffer layout (DGB Table 1): camera-space
// z of each layer from its hardware depth and projection, Oct16 world normals, and the
// layer-0 world motion the temporal filter follows (`fs_import*`, every embedded
// technique); each layer's normal, albedo and radiance (`fs_shading`: the radiosity B of
// the embedded radiosity, the outgoing radiance of the embedded reflections, which also
// take layer 0's roughness and metallic from a material texture). `embed::core`.
#import "common/fullscreen.wgsl"
#import "common/packing.wgsl"

// the normals' encoding: 0 = signed xyz, 1 = xyz·0.5 + 0.5, 2 = Oct16 rg in [0, 1],
// 3 = none: reconstructed from the layer's depth (`normal_from_depth`)
override NORMALS: u32 = 0u;
// 1: the normals are in view space (rotated to world space with inv_view)
override VIEW_SPACE: u32 = 0u;

struct Import {
    inv_proj: mat4x4f,
    inv_view: mat4x4f,
    // w, h, 1/w, 1/h
    size: vec4f,
    // the projection's w row's z factor: csz = w_sign · z_view (−1 right-handed, +1 left)
    w_sign: f32,
    // 1: reversed z (no surface where depth = 0), 0: standard (no surface where depth = 1)
    reversed: u32,
    _pad: vec2u,
}

@group(0) @binding(0) var<uniform> im: Import;
@group(0) @binding(1) var depth0: texture_depth_2d;
@group(0) @binding(2) var normal0: texture_2d<f32>;
@group(0) @binding(3) var depth1: texture_depth_2d;
@group(0) @binding(4) var normal1: texture_2d<f32>;
@group(0) @binding(5) var motion_in: texture_2d<f32>;
// per layer: diffuse albedo ρ (rgb, linear) and outgoing diffuse radiance B (rgb)
@group(0) @binding(6) var albedo0: texture_2d<f32>;
@group(0) @binding(7) var radiance0: texture_2d<f32>;
@group(0) @binding(8) var albedo1: texture_2d<f32>;
@group(0) @binding(9) var radiance1: texture_2d<f32>;
// layer 0's material (roughness and metallic in channels ROUGHNESS and METALLIC)
@group(0) @binding(10) var material0: texture_2d<f32>;

// 1: this layer's roughness and metallic come from `material0` (0: both 0)
override MATERIAL: u32 = 0u;
override ROUGHNESS: u32 = 1u;
override METALLIC: u32 = 2u;

// camera-space z of hardware depth d at pixel p (0 = no surface): the projection inverted
fn csz_of_depth(p: vec2i, d: f32) -> f32 {
    let empty = select(d >= 1.0, d <= 0.0, im.reversed != 0u);
    if (empty) {
        return 0.0;
    }
    let uv = (vec2f(p) + 0.5) * im.size.zw;
    let v = im.inv_proj * vec4f(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, d, 1.0);
    let z = im.w_sign * v.z / v.w;
    // behind the eye, or a projection that cannot be inverted there
    return select(0.0, z, z > 0.0 && z < 3.0e38);
}

// Oct16 of the world normal in texel `t` of a normal texture
fn oct_of(t: vec4f) -> vec2f {
    if (NORMALS == 2u && VIEW_SPACE == 0u) {
        // already strata's encoding: pass it through bit for bit
        return t.rg;
    }
    var n: vec3f;
    if (NORMALS == 0u) {
        n = t.xyz;
    } else if (NORMALS == 1u) {
        n = t.xyz * 2.0 - 1.0;
    } else {
        n = oct_decode(t.rg);
    }
    if (VIEW_SPACE != 0u) {
        n = (im.inv_view * vec4f(n, 0.0)).xyz;
    }
    let l = length(n);
    return oct_encode(select(vec3f(0.0, 0.0, 1.0), n / l, l > 1e-20));
}

// View-space position of the surface in texel q of a depth texture (w = 1), or w = 0
// where q is outside the image or holds no surface.
fn view_position(depth: texture_depth_2d, q: vec2i) -> vec4f {
    let size = vec2i(im.size.xy);
    let c = clamp(q, vec2i(0), size - 1);
    let d = textureLoad(depth, c, 0);
    let empty = select(d >= 1.0, d <= 0.0, im.reversed != 0u);
    let uv = (vec2f(c) + 0.5) * im.size.zw;
    let v = im.inv_proj * vec4f(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, d, 1.0);
    let ok = !empty && all(q == c) && abs(v.w) > 0.0;
    return vec4f(v.xyz / select(1.0, v.w, ok), select(0.0, 1.0, ok));
}

// Hardware depth in texel q, or a value no surface extrapolates to outside the image.
fn raw_depth(depth: texture_depth_2d, q: vec2i) -> f32 {
    let size = vec2i(im.size.xy);
    if (any(q < vec2i(0)) || any(q >= size)) {
        return 1.0e30;
    }
    return textureLoad(depth, q, 0);
}

// The tangent along screen axis `axis` at pixel p (view position c): towards the side
// whose two samples lie on the centre's plane. Hardware depth is affine in screen space
// on a plane, so the side whose linear extrapolation 2·d(±1) − d(±2) lands nearer the
// centre's depth is on the centre's surface; the difference does not cross an edge
// (Turánszki's choice of neighbours for depth-reconstructed normals).
fn tangent(depth: texture_depth_2d, p: vec2i, c: vec4f, axis: vec2i) -> vec3f {
    let d0 = raw_depth(depth, p);
    let before = abs(2.0 * raw_depth(depth, p - axis) - raw_depth(depth, p - 2 * axis) - d0);
    let after = abs(2.0 * raw_depth(depth, p + axis) - raw_depth(depth, p + 2 * axis) - d0);
    let a = view_position(depth, p - axis);
    let b = view_position(depth, p + axis);
    if (a.w == 0.0 && b.w == 0.0) {
        return vec3f(0.0);
    }
    let use_b = a.w == 0.0 || (b.w != 0.0 && after < before);
    return select(c.xyz - a.xyz, b.xyz - c.xyz, use_b);
}

// The world normal of the surface in pixel p of a depth texture (NORMALS = 3, an
// application without a normal buffer): the cross product of the screen-space tangents,
// facing the viewer.
fn normal_from_depth(depth: texture_depth_2d, p: vec2i) -> vec3f {
    let c = view_position(depth, p);
    let tx = tangent(depth, p, c, vec2i(1, 0));
    let ty = tangent(depth, p, c, vec2i(0, 1));
    var n = cross(tx, ty);
    // the eye is at the view-space origin: face it
    n = select(n, -n, dot(n, c.xyz) > 0.0);
    let w = (im.inv_view * vec4f(n, 0.0)).xyz;
    let l = length(w);
    return select(vec3f(0.0, 0.0, 1.0), w / l, c.w != 0.0 && l > 1e-20);
}

// Oct16 of layer j's world normal at p: from its normal texture, or its depth (NORMALS = 3)
fn layer_oct(j: u32, p: vec2i) -> vec2f {
    if (NORMALS == 3u) {
        if (j == 0u) {
            return oct_encode(normal_from_depth(depth0, p));
        }
        return oct_encode(normal_from_depth(depth1, p));
    }
    if (j == 0u) {
        return oct_of(textureLoad(normal0, p, 0));
    }
    return oct_of(textureLoad(normal1, p, 0));
}

// the application's motion texture, or one of zeros where it gives none
fn motion_of(p: vec2i) -> vec4f {
    return vec4f(textureLoad(motion_in, p, 0).xyz, 0.0);
}

struct One {
    @location(0) z01: vec2f,
    @location(1) n01: vec4f,
    @location(2) csz0: f32,
    @location(3) motion: vec4f,
}

struct Two {
    @location(0) z01: vec2f,
    @location(1) n01: vec4f,
    @location(2) csz0: f32,
    @location(3) motion: vec4f,
    @location(4) csz1: f32,
}

@fragment
fn fs_import1(@builtin(position) pos: vec4f) -> One {
    let p = vec2i(pos.xy);
    let z0 = csz_of_depth(p, textureLoad(depth0, p, 0));
    var o: One;
    o.z01 = vec2f(z0, 0.0);
    o.n01 = vec4f(layer_oct(0u, p), 0.5, 0.5);
    o.csz0 = z0;
    o.motion = motion_of(p);
    return o;
}

@fragment
fn fs_import2(@builtin(position) pos: vec4f) -> Two {
    let p = vec2i(pos.xy);
    let z0 = csz_of_depth(p, textureLoad(depth0, p, 0));
    let z1 = csz_of_depth(p, textureLoad(depth1, p, 0));
    var o: Two;
    o.z01 = vec2f(z0, z1);
    o.n01 = vec4f(layer_oct(0u, p), layer_oct(1u, p));
    o.csz0 = z0;
    o.motion = motion_of(p);
    o.csz1 = z1;
    return o;
}

// the deep G-buffer's `normal` (rg = Oct16, ba = roughness, metallic), `albedo` (a = 1)
// and radiance of one layer
struct Layer {
    normal: vec4f,
    albedo: vec4f,
    radiosity: vec4f,
}

fn shading_of(p: vec2i, oct: vec2f, albedo: vec4f, radiance: vec4f) -> Layer {
    var rm = vec2f(0.0);
    if (MATERIAL == 1u) {
        let m = textureLoad(material0, p, 0);
        rm = clamp(vec2f(m[ROUGHNESS], m[METALLIC]), vec2f(0.0), vec2f(1.0));
    }
    return Layer(
        vec4f(oct, rm),
        vec4f(clamp(albedo.rgb, vec3f(0.0), vec3f(1.0)), 1.0),
        vec4f(max(radiance.rgb, vec3f(0.0)), 1.0),
    );
}

// one pass per layer: three targets each stay within WebGPU's default 32 bytes per sample
override LAYER: u32 = 0u;

struct Shading {
    @location(0) normal: vec4f,
    @location(1) albedo: vec4f,
    @location(2) radiosity: vec4f,
}

@fragment
fn fs_shading(@builtin(position) pos: vec4f) -> Shading {
    let p = vec2i(pos.xy);
    var l: Layer;
    if (LAYER == 0u) {
        l = shading_of(p, layer_oct(0u, p), textureLoad(albedo0, p, 0), textureLoad(radiance0, p, 0));
    } else {
        l = shading_of(p, layer_oct(1u, p), textureLoad(albedo1, p, 0), textureLoad(radiance1, p, 0));
    }
    return Shading(l.normal, l.albedo, l.radiosity);
}

// ShadingImport::Normals (the embedded ILS): the layer's `normal` alone, roughness and
// metallic 0
@fragment
fn fs_normal(@builtin(position) pos: vec4f) -> @location(0) vec4f {
    return vec4f(layer_oct(LAYER, vec2i(pos.xy)), 0.0, 0.0);
}
