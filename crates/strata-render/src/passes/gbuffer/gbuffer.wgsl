// Single-layer G-buffer: camera-space depth, Oct16 normal + roughness/metallic,
// albedo, emission. Double-sided: back faces get their normal flipped toward the viewer.
#import "common/camera.wgsl"
#import "common/packing.wgsl"

struct ObjectUniforms {
    model: mat4x4f,
    normal_matrix: mat4x4f,
    prev_model: mat4x4f,
    pad: mat4x4f,
}

struct MaterialUniforms {
    base_color: vec4f,
    emission: vec4f,
    // roughness, metallic, has_texture, alpha cutoff
    params: vec4f,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> object: ObjectUniforms;
@group(2) @binding(0) var<uniform> material: MaterialUniforms;
@group(2) @binding(1) var base_tex: texture_2d<f32>;
@group(2) @binding(2) var base_sampler: sampler;

struct VsOut {
    @builtin(position) clip: vec4f,
    @location(0) world: vec3f,
    @location(1) normal: vec3f,
    @location(2) uv: vec2f,
}

@vertex
fn vs_main(@location(0) position: vec3f, @location(1) normal: vec3f, @location(2) uv: vec2f) -> VsOut {
    var o: VsOut;
    let world = object.model * vec4f(position, 1.0);
    o.world = world.xyz;
    o.clip = frame.view_proj * world;
    o.normal = (object.normal_matrix * vec4f(normal, 0.0)).xyz;
    o.uv = uv;
    return o;
}

struct GBufferOut {
    // camera-space depth (0 = no surface)
    @location(0) csz: f32,
    // rg = Oct16 world normal, b = roughness, a = metallic
    @location(1) normal: vec4f,
    // rgb = albedo (sRGB target), a = opacity
    @location(2) albedo: vec4f,
    // rgb = emitted radiance
    @location(3) emission: vec4f,
}

@fragment
fn fs_main(in: VsOut, @builtin(front_facing) front: bool) -> GBufferOut {
    var base = material.base_color;
    if (material.params.z > 0.5) {
        base = base * textureSample(base_tex, base_sampler, in.uv);
    }
    if (base.a < material.params.w) {
        discard;
    }
    var n = normalize(in.normal);
    if (!front) {
        n = -n;
    }
    var o: GBufferOut;
    o.csz = csz_of(frame, in.world);
    o.normal = vec4f(oct_encode(n), material.params.x, material.params.y);
    o.albedo = vec4f(base.rgb, base.a);
    o.emission = vec4f(material.emission.rgb, 1.0);
    return o;
}
