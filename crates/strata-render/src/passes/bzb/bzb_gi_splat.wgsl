// bzb-gi §3.2: the AOV splats of bzb_splat.wgsl (same vertex shader: the screen
// rectangle of the triangle's AABB grown by d_max, in sub-image s) with a
// radiance payload. Appended after bzb.wgsl, bzb_gi.wgsl and bzb_splat.wgsl.
//   bzb_splat.wgsl's fs_visibility with HIT_INDEX: the texel's ray (x_p, ω) hits
//       the triangle at t in (t_min, d_max) → depth t²/d_max² and the triangle's
//       index into bzb-gi-hit (depth test Less, no blending: the nearest sender
//       along ω wins); a miss discards. The `bzb-gi-shade` pass then computes the
//       winner's outgoing radiance L(y → x_p) once per texel (deferred: on a
//       CPU rasteriser shading every hit fragment cost more than the test).
//   fs_gi_additive: the baseline without visibility: every triangle within
//       d_max adds π·F·L̄_T (F its point-to-polygon form factor at x_p, L̄_T
//       its mean radiance, bzb_gi_senders.wgsl), summed by additive blending.
//       The sum does not depend on ω, so it is splatted into sub-image 0 only.

@group(2) @binding(0) var<uniform> gi: BzbGi;
// GI_TRI_VEC4S vec4 per triangle (gi::sender_data)
@group(2) @binding(1) var<storage, read> gi_tris: array<vec4f>;
@group(2) @binding(2) var<storage, read> lights: array<GpuLight>;
@group(2) @binding(3) var shadow_maps: texture_depth_2d_array;
@group(2) @binding(4) var shadow_sampler: sampler_comparison;
@group(2) @binding(5) var<storage, read> shadow_mats: array<mat4x4f>;
// the receiver's material (layer 0), for the baseline's glossy receivers
@group(2) @binding(6) var normal_tex: texture_2d<f32>;
@group(2) @binding(7) var albedo_tex: texture_2d<f32>;
@group(2) @binding(8) var emission_tex: texture_2d<f32>;
// the baseline's per-triangle mean radiance L̄_T (bzb_gi_senders.wgsl)
@group(2) @binding(9) var<storage, read> mean_radiance: array<vec4f>;
// the senders' textures (gi::sender_texels), read by bzb_gi_sender.wgsl
@group(2) @binding(10) var<storage, read> sender_texels: array<u32>;

@fragment
fn fs_gi_additive(in: SplatVertex) -> @location(0) vec4f {
    if (outside_rect(in)) {
        discard;
    }
    let texel = vec2i(in.position.xy);
    let o = textureLoad(origins, texel, 0);
    if (o.w <= 0.0) {
        discard;
    }
    let size = vec2u(frame.size.xy);
    let pu = vec2u(in.position.xy) % size;
    let p = vec2i(pu);
    let tile = vec2u(in.position.xy) / size;
    let s = tile.y * bzb.cols + tile.x;
    let n = oct_decode(textureLoad(npack, p, 0).rg);
    let v = load_triangle(in.triangle);
    if (!(bzb_triangle_dist2(o.xyz, v[0], v[1], v[2]) < gi.d_max * gi.d_max)) {
        discard;
    }
    let ff = bzb_clipped_form_factor(o.xyz, n, v[0], v[1], v[2], gi.t_min);
    if (ff <= 0.0) {
        discard;
    }
    // towards the triangle's centre (the receiver's BRDF direction)
    let to_x = normalize(o.xyz - (v[0] + v[1] + v[2]) / 3.0);
    // irradiance from a sender of constant radiance L̄_T: π F L̄_T
    let e = BZB_PI * ff * mean_radiance[in.triangle].rgb;
    if (textureLoad(emission_tex, p, 0).a > 1.5) {
        let nrm = textureLoad(normal_tex, p, 0);
        let rho = textureLoad(albedo_tex, p, 0).rgb;
        let view = normalize(frame.eye.xyz - o.xyz);
        return vec4f(ggx_eval(n, view, -to_x, rho, nrm.z, nrm.w) * e, 1.0);
    }
    return vec4f(e, 1.0);
}
