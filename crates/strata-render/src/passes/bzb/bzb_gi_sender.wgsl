// bzb-gi: the sender's outgoing radiance towards a receiver (BZB §3.2's GI
// payload), shared by the shade pass (bounced z-buffer) and the additive
// baseline's splats. The importer declares `gi` (BzbGi), `gi_tris` (sender
// data, GI_TRI_VEC4S vec4 per triangle: gi::sender_data), `sender_texels`
// (array<u32>: gi::sender_texels), `triangles` (3 vec4 of positions per
// triangle), `lights` (array<GpuLight>) and the globals of common/shadow.wgsl.
#import "common/shadow.wgsl"

const GI_TRI_VEC4S: u32 = 7u;
// words of the sRGB decode table at the start of sender_texels
const GI_TEXEL_LUT: u32 = 256u;

fn gi_triangle(tri: u32) -> array<vec3f, 3> {
    return array<vec3f, 3>(triangles[3u * tri].xyz, triangles[3u * tri + 1u].xyz, triangles[3u * tri + 2u].xyz);
}

// Barycentric weights of b and c for a point y in the plane of (a, b, c).
fn gi_barycentrics(y: vec3f, a: vec3f, b: vec3f, c: vec3f) -> vec2f {
    let e1 = b - a;
    let e2 = c - a;
    let q = y - a;
    let d11 = dot(e1, e1);
    let d12 = dot(e1, e2);
    let d22 = dot(e2, e2);
    let q1 = dot(q, e1);
    let q2 = dot(q, e2);
    let det = d11 * d22 - d12 * d12;
    if (det == 0.0) {
        return vec2f(0.0);
    }
    return vec2f(d22 * q1 - d12 * q2, d11 * q2 - d12 * q1) / det;
}

// The sender's base-colour texture at barycentrics `bary` (BZB §3.2: the radiance
// at the hit y, so ρ(y)): the texel under y's UV, nearest with wrap, decoded with
// the reference's table (Texture::sample_linear); 1 without a texture. CPU twin:
// gi::sender_texel_cpu.
fn gi_sender_texture(tri: u32, bary: vec2f) -> vec3f {
    let base = GI_TRI_VEC4S * tri;
    let slot = u32(gi_tris[base + 4u].z + 0.5);
    if (slot == 0u) {
        return vec3f(1.0);
    }
    let q5 = gi_tris[base + 5u];
    let q6 = gi_tris[base + 6u];
    let uv = q5.xy * (1.0 - bary.x - bary.y) + q5.zw * bary.x + q6.xy * bary.y;
    let e = GI_TEXEL_LUT + 4u * (slot - 1u);
    let w = sender_texels[e + 1u];
    let h = sender_texels[e + 2u];
    let x = u32((uv.x - floor(uv.x)) * f32(w));
    let y = u32((uv.y - floor(uv.y)) * f32(h));
    let p = sender_texels[sender_texels[e] + min(y, h - 1u) * w + min(x, w - 1u)];
    return vec3f(
        bitcast<f32>(sender_texels[p & 0xffu]),
        bitcast<f32>(sender_texels[(p >> 8u) & 0xffu]),
        bitcast<f32>(sender_texels[(p >> 16u) & 0xffu]),
    );
}

// The sender's outgoing radiance at y (barycentrics `bary` on triangle `tri`)
// towards the unit direction `to_x`: direct light of every analytic light
// (lights.wgsl's irradiance, shadowed by the lighting pass's shadow maps)
// times ρ/π (Lambert) or f_GGX(to_x, l) (glossy senders, l towards the light
// or the rect light's centre), plus the emission of an emissive front face
// when no Rect light carries it (the lighting pass's convention). Surfaces are
// two-sided, as in the path tracer.
fn gi_sender(tri: u32, y: vec3f, bary: vec2f, to_x: vec3f) -> vec3f {
    let base = GI_TRI_VEC4S * tri;
    let q0 = gi_tris[base];
    let q1 = gi_tris[base + 1u];
    let q2 = gi_tris[base + 2u];
    let q3 = gi_tris[base + 3u];
    let q4 = gi_tris[base + 4u];
    let rho = vec3f(q0.w, q1.w, q2.w) * gi_sender_texture(tri, bary);
    let v = gi_triangle(tri);
    var ng = normalize(cross(v[1] - v[0], v[2] - v[0]));
    let front = dot(ng, to_x) > 0.0;
    if (!front) {
        ng = -ng;
    }
    var ns = q0.xyz * (1.0 - bary.x - bary.y) + q1.xyz * bary.x + q2.xyz * bary.y;
    let len = length(ns);
    ns = select(ng, ns / len, len > 1e-6);
    if (dot(ns, ng) < 0.0) {
        ns = -ns;
    }
    let glossy = q3.w > 0.5;
    var out = vec3f(0.0);
    for (var i = 0u; i < gi.light_count; i++) {
        let li = lights[i];
        let e = light_irradiance(li, y, ns);
        if (all(e <= vec3f(0.0))) {
            continue;
        }
        var l = -li.direction.xyz;
        var dist = 1.0;
        if (li.kind.x != 0u) {
            let d = li.position.xyz - y;
            dist = length(d);
            l = d / max(dist, 1e-12);
        }
        let vis = light_visibility(li, y, ns, dist, gi.pcf_radius, gi.shadow_size, gi.area_penumbrae);
        if (vis <= 0.0) {
            continue;
        }
        var f = rho * (1.0 / BZB_PI);
        if (glossy) {
            f = ggx_eval(ns, to_x, l, rho, q4.x, q4.y);
        }
        out += f * e * vis;
    }
    if (gi.emission_in != 0u && front) {
        out += q3.rgb;
    }
    return out;
}

