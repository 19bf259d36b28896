// Lights as the GPU sees them (matches `lights::GpuLight`) and their
// unshadowed irradiance, shared by the deferred lighting pass and the A-buffer's
// per-fragment shading (ABA OIT).

struct GpuLight {
    // kind, shadow layer (0xffffffff = none)
    kind: vec4u,
    position: vec4f,
    // direction light travels (sun, spot axis) or rect normal
    direction: vec4f,
    // intensity x colour
    color: vec4f,
    // cos outer, cos inner, shadow texel size, 0
    cone: vec4f,
    // rect: half-edge vectors
    half_u: vec4f,
    half_v: vec4f,
    shadow_view_proj: mat4x4f,
}

// The cube face of direction d from a point light or VPL: the major axis of d,
// faces +X, −X, +Y, −Y, +Z, −Z (0..=5; `lights::cube_face_matrix` draws them).
fn cube_face(d: vec3f) -> u32 {
    let a = abs(d);
    var face = 4u;
    if (a.x >= a.y && a.x >= a.z) {
        face = 0u;
    } else if (a.y >= a.z) {
        face = 2u;
    }
    if ((face == 0u && d.x < 0.0) || (face == 2u && d.y < 0.0) || (face == 4u && d.z < 0.0)) {
        face += 1u;
    }
    return face;
}

// Irradiance factor of a one-sided rectangle (centre c, half-edges hu, hv,
// emitting towards nl) at p with unit normal n: E / L = ½ Σ_i Θ_i (n · Γ_i),
// Lambert's polygon formula over the rectangle clipped to the hemisphere above
// p (Sutherland–Hodgman against n · x ≥ 0; at most 5 vertices). Exact for a
// Lambertian receiver without occlusion.
fn rect_irradiance(p: vec3f, n: vec3f, c: vec3f, hu: vec3f, hv: vec3f, nl: vec3f) -> f32 {
    if (dot(p - c, nl) <= 0.0) {
        return 0.0;
    }
    let q = array<vec3f, 4>(c - hu - hv - p, c + hu - hv - p, c + hu + hv - p, c - hu + hv - p);
    var poly: array<vec3f, 5>;
    var k = 0u;
    for (var i = 0u; i < 4u; i++) {
        let a = q[i];
        let b = q[(i + 1u) % 4u];
        let da = dot(a, n);
        let db = dot(b, n);
        if (da >= 0.0) {
            poly[k] = a;
            k++;
        }
        if ((da >= 0.0) != (db >= 0.0)) {
            poly[k] = a + (b - a) * (da / (da - db));
            k++;
        }
    }
    if (k < 3u) {
        return 0.0;
    }
    var sum = 0.0;
    for (var i = 0u; i < k; i++) {
        let a = poly[i];
        let b = poly[(i + 1u) % k];
        let la = length(a);
        let lb = length(b);
        if (la < 1e-12 || lb < 1e-12) {
            continue;
        }
        let ua = a / la;
        let ub = b / lb;
        let cr = cross(ua, ub);
        let s = length(cr);
        if (s > 1e-9) {
            sum += atan2(s, dot(ua, ub)) * dot(n, cr / s);
        }
    }
    return 0.5 * abs(sum);
}

// Unshadowed irradiance E_l(p, n) of light `li` at p with unit normal n: sun
// color·max(n·l, 0); point color·max(n·l, 0)/d²; spot the same × smoothstep(cos
// outer, cos inner, axis·(p − x_l)/|p − x_l|); rect the exact polygon integral
// (color = radiance). CPU twin: `strata_reference::oit::shade`.
fn light_irradiance(li: GpuLight, p: vec3f, n: vec3f) -> vec3f {
    switch li.kind.x {
        case 0u: {
            return li.color.rgb * max(dot(n, -li.direction.xyz), 0.0);
        }
        case 3u: {
            return li.color.rgb * rect_irradiance(p, n, li.position.xyz, li.half_u.xyz, li.half_v.xyz, li.direction.xyz);
        }
        default: {
            let d = li.position.xyz - p;
            let d2 = dot(d, d);
            if (!(d2 > 0.0)) {
                return vec3f(0.0);
            }
            let l = d / sqrt(d2);
            var e = li.color.rgb * (max(dot(n, l), 0.0) / d2);
            if (li.kind.x == 2u) {
                e *= smoothstep(li.cone.x, li.cone.y, dot(-l, li.direction.xyz));
            }
            return e;
        }
    }
}
