// Camera reconstruction (same model as strata_scene::Camera): pixel centres at
// (x + 0.5, y + 0.5), y down; camera-space depth z along the forward axis.
#import "common/frame.wgsl"

// World-space direction through a pixel position, scaled so its forward component is 1.
fn pixel_dir(f: Frame, pix: vec2f) -> vec3f {
    let ndc = vec2f(pix.x * f.size.z * 2.0 - 1.0, 1.0 - pix.y * f.size.w * 2.0);
    return f.cam_forward.xyz + f.cam_right.xyz * ndc.x + f.cam_up.xyz * ndc.y;
}

// World position of the surface at pixel position `pix` with camera-space depth `z`.
fn world_from_csz(f: Frame, pix: vec2f, z: f32) -> vec3f {
    return f.eye.xyz + z * pixel_dir(f, pix);
}

// Camera-space depth of a world point.
fn csz_of(f: Frame, p: vec3f) -> f32 {
    return dot(p - f.eye.xyz, f.cam_forward.xyz);
}

// Pixel position (x, y) of world point q, z = 1 when q lies beyond the near
// plane (else all 0): the inverse of world_from_csz, for vertex pulling.
fn pixel_of_world(f: Frame, q: vec3f) -> vec3f {
    let v = q - f.eye.xyz;
    let z = dot(v, f.cam_forward.xyz);
    if (z <= f.eye.w) {
        return vec3f(0.0, 0.0, 0.0);
    }
    let right = f.cam_right.xyz;
    let up = f.cam_up.xyz;
    let ndc = vec2f(dot(v, right) / dot(right, right), dot(v, up) / dot(up, up)) / z;
    return vec3f((ndc.x * 0.5 + 0.5) * f.size.x, (0.5 - ndc.y * 0.5) * f.size.y, 1.0);
}

// The screen rectangle (pixels, unclamped) of the world box [lo, hi] from its eight
// corners, and its camera-depth range. A box that crosses the near plane covers the
// whole image (0, size); `visible` is false when it lies wholly behind the camera.
struct ScreenBox {
    rmin: vec2f,
    rmax: vec2f,
    zlo: f32,
    zhi: f32,
    visible: bool,
}

fn screen_box(f: Frame, lo: vec3f, hi: vec3f) -> ScreenBox {
    var o = ScreenBox(vec2f(1e30), vec2f(-1e30), 1e30, -1e30, false);
    var in_front = 0u;
    for (var k = 0u; k < 8u; k++) {
        let q = select(lo, hi, vec3<bool>((k & 1u) != 0u, (k & 2u) != 0u, (k & 4u) != 0u));
        let zq = csz_of(f, q);
        o.zlo = min(o.zlo, zq);
        o.zhi = max(o.zhi, zq);
        let p = pixel_of_world(f, q);
        if (p.z > 0.0) {
            in_front++;
            o.rmin = min(o.rmin, p.xy);
            o.rmax = max(o.rmax, p.xy);
        }
    }
    o.visible = in_front > 0u;
    if (o.visible && in_front < 8u) {
        o.rmin = vec2f(0.0);
        o.rmax = f.size.xy;
    }
    return o;
}
