#!/usr/bin/env python3
"""Independent-renderer check of strata's CPU reference against Mitsuba 3.

Renders the same scene, frame and camera with `strata reference` and with
Mitsuba 3 (llvm_ad_rgb), both at pixel centres, and prints one JSON line per
comparison (FLIP, RMSE, MAE and mean difference from `strata compare`, the
metrics of `strata eval`). Optional: not part of CI.

Usage:
    pip install mitsuba            # 3.9.1 was used; needs no GPU (LLVM backend)
    cargo build --release -p strata-cli
    python3 scripts/mitsuba_check.py --scene cornell --kind ao gi \\
        --width 128 --height 128 --ao-spp 4096 --gi-spp 2048 --out out/mitsuba
    python3 scripts/mitsuba_check.py --scene warehouse --kind gi --bounces 0 \\
        --gi-spp 16 --mitsuba-gi-spp 4096 --eye=1.9,3.5,1.6 --target=-1.1,0,-1.4
    python3 scripts/mitsuba_check.py --scene scenes/sponza.toml --kind ao \\
        --width 160 --height 90 --ao-spp 4096 --out out/mitsuba

    --eye/--target/--up/--fov/--frame are passed to `strata export-scene` and
    `strata reference` unchanged. Each kind renders strata with seeds 0 and 1
    and Mitsuba with seeds 0 and 1; the JSON lines are
      {"pair": "strata-vs-mitsuba", ...}   the check (seed 0 of each side)
      {"pair": "strata-noise", ...}        strata seed 0 vs seed 1 (noise floor)
      {"pair": "mitsuba-noise", ...}       Mitsuba seed 0 vs seed 1 (noise floor)
      {"pair": "strata-vs-mitsuba-seed1"}  the check again with seed 1 of each side
      {"pair": "summary", ...}             FLIP and the noise floors; the RMS of the
          strata-Mitsuba difference that the noise floors do not explain
          ("rmse_systematic" = sqrt(max(0, rmse^2 - (rmse_sn^2 + rmse_mn^2)/2)), rmse
          = RMS of the two strata-vs-mitsuba RMSEs, rmse_sn/rmse_mn = noise pairs)
    and `<out>/<scene>-<size>-<kind>-<hash>.png` shows strata | Mitsuba |
    4 x |difference| (`...-flip.png`: the FLIP map). Images are reused when
    they exist: <hash> covers the scene flags, kind and settings; --force
    re-renders.

How each side computes the image (the conventions matched):

- Camera: a Mitsuba `perspective` sensor with to_world = look_at(eye, target,
  up), fov_axis = y, fov = strata's vertical fov, near_clip = strata's near
  (Mitsuba clips at the plane z = near, as strata's `t > near` with unit-depth
  ray directions). Rays come from `sensor.sample_ray` at film position
  ((x + 0.5)/W, (y + 0.5)/H), row y = 0 at the top: exactly one ray through
  each pixel centre, no filter, no jitter (strata never jitters). The script
  checks these rays against strata's `Camera::pixel_dir` before rendering.
- AO (binary ambient visibility, radius r): Mitsuba 3 has no `ao` integrator,
  so this script traces it with Mitsuba's ray queries: primary hit, shading
  normal n and geometric normal ng, both flipped when the ray meets the back
  of the geometric surface (strata's facing rule), N cosine-weighted directions around n
  (`warp.square_to_cosine_hemisphere`, independent sampler), origin offset
  `ray_epsilon` (exported by strata) along ng, occluded when `ray_test` hits
  within r; AV = 1 - H/N, background 1. strata uses an R2 sequence with a
  per-pixel rotation instead: same estimand, independent noise.
- GI: Mitsuba's `path` integrator called per ray (`integrator.sample`), with
  max_depth = bounces + 2 (strata's N bounces = N + 1 surface vertices with
  next-event estimation; Mitsuba's max_depth counts segments, 2 = direct),
  Russian roulette at Mitsuba's default depth (unbiased on both sides),
  emitters visible to the camera. Every material is `twosided(diffuse)` with
  reflectance = base_color (strata shades both faces with the facing normal);
  emissive materials get an `area` emitter with radiance = emission on the
  geometric front face (face_normals, counter-clockwise, as strata's
  one-sided emitters). Lights: sun -> `directional` (irradiance =
  illuminance x colour, direction = photon direction), point -> `point`
  (intensity x colour), spot -> `spot` with cutoff = outer angle and a
  projected texture holding strata's smoothstep(cos outer, cos inner, cos a)
  falloff (Mitsuba's own falloff is linear in the angle), sky -> `constant`.
  Rect lights are skipped (strata's reference ignores them too: the emissive
  geometry is the light). Textured albedo is not exported: GI refuses
  textured scenes.
"""

import argparse
import hashlib
import json
import math
import os
import subprocess
import sys
import time

import drjit as dr
import mitsuba as mi

mi.set_variant("llvm_ad_rgb")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def log(msg):
    print(f"[mitsuba_check] {msg}", file=sys.stderr, flush=True)


# --------------------------------------------------------------------------- strata side


def scene_flags(a, with_size=True):
    f = ["--scene", a.scene, "--frame", str(a.frame)]
    if with_size:
        f += ["--width", str(a.width), "--height", str(a.height)]
    for name in ("eye", "target", "up", "fov"):
        v = getattr(a, name)
        if v is not None:
            f += [f"--{name}", str(v)]
    return f


def strata(a, args, capture=False):
    cmd = [a.strata] + args
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"mitsuba_check: `{' '.join(cmd)}` failed: {r.stderr.strip()}")
    return r.stdout


def strata_reference(a, kind, spp, seed, path):
    if os.path.exists(path) and not a.force:
        log(f"reusing {path}")
        return 0.0
    t = time.time()
    args = ["reference", "--kind", kind, "--spp", str(spp), "--seed", str(seed), "--quiet", "--force", "--out", path]
    if kind == "gi":
        args += ["--bounces", str(a.bounces)]
    if a.ao_radius is not None and kind == "ao":
        args += ["--ao-radius", str(a.ao_radius)]
    strata(a, args + scene_flags(a))
    return time.time() - t


def compare(a, ref, test, exposure=None, map_path=None):
    args = ["compare", ref, test, "--json"]
    if exposure is not None:
        args += ["--exposure", str(exposure)]
    if map_path:
        args += ["--map", map_path, "--force"]
    return json.loads(strata(a, args))


# --------------------------------------------------------------------------- Mitsuba scene


def look_at(eye, target, up):
    return mi.ScalarTransform4f().look_at(origin=mi.ScalarPoint3f(eye), target=mi.ScalarPoint3f(target),
                                          up=mi.ScalarVector3f(up))


def make_sensor(cam):
    return mi.load_dict({
        "type": "perspective",
        "to_world": look_at(cam["eye"], cam["target"], cam["up"]),
        "fov": cam["fov_y_deg"],
        "fov_axis": "y",
        "near_clip": cam["near"],
        "far_clip": 1e6,
        "film": {"type": "hdrfilm", "width": cam["width"], "height": cam["height"],
                 "rfilter": {"type": "box"}, "pixel_format": "rgb"},
    })


def strata_pixel_dir(cam, x, y):
    """strata's Camera::pixel_dir (unit component along forward)."""
    w, h = cam["width"], cam["height"]
    t = math.tan(math.radians(cam["fov_y_deg"]) / 2)
    ndc_x = (x + 0.5) / w * 2 - 1
    ndc_y = 1 - (y + 0.5) / h * 2
    f, r, u = cam["forward"], cam["right"], cam["true_up"]
    return [f[i] + r[i] * ndc_x * t * w / h + u[i] * ndc_y * t for i in range(3)]


def check_camera(sensor, cam):
    """Mitsuba's pixel-centre rays against strata's: direction and near-plane origin."""
    w, h = cam["width"], cam["height"]
    pts = [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1), (w // 2, h // 3), (w // 5, h - 2)]
    xs = mi.Float([(x + 0.5) / w for x, _ in pts])
    ys = mi.Float([(y + 0.5) / h for _, y in pts])
    ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(xs, ys), mi.Point2f(0.5, 0.5))
    worst = 0.0
    for i, (x, y) in enumerate(pts):
        d = strata_pixel_dir(cam, x, y)
        depth = 1.0  # the component of d along forward is 1
        n = math.sqrt(sum(c * c for c in d))
        md = [ray.d.x[i], ray.d.y[i], ray.d.z[i]]
        u = [c / n for c in d]
        cross = [u[1] * md[2] - u[2] * md[1], u[2] * md[0] - u[0] * md[2], u[0] * md[1] - u[1] * md[0]]
        ang = math.atan2(math.sqrt(sum(c * c for c in cross)), sum(md[k] * u[k] for k in range(3)))
        worst = max(worst, math.degrees(ang))
        # Origin on the near plane: eye + d * near / depth.
        o = [cam["eye"][k] + d[k] * cam["near"] / depth for k in range(3)]
        mo = [ray.o.x[i], ray.o.y[i], ray.o.z[i]]
        err = max(abs(o[k] - mo[k]) for k in range(3))
        if err > 1e-4 * max(1.0, max(abs(c) for c in o)):
            sys.exit(f"mitsuba_check: camera mismatch at pixel {x},{y}: origin {mo} vs strata {o}")
    if worst > 1e-3:
        sys.exit(f"mitsuba_check: camera mismatch: pixel-centre rays differ by up to {worst:.4f} degrees")
    return worst


def spot_falloff_texture(inner_deg, outer_deg, res=1024):
    """strata's spot cone, smoothstep(cos outer, cos inner, cos a), as Mitsuba's spot
    texture: uv = 0.5 + 0.5 * (x, y) / (z tan(outer)) in the light's frame."""
    tan_c = math.tan(math.radians(outer_deg))
    ci, co = math.cos(math.radians(inner_deg)), math.cos(math.radians(outer_deg))
    vals = []
    for j in range(res):
        v = (j + 0.5) / res * 2 - 1
        for i in range(res):
            u = (i + 0.5) / res * 2 - 1
            cos_a = 1 / math.sqrt(1 + (tan_c * tan_c) * (u * u + v * v))
            if ci <= co:
                s = 1.0 if cos_a >= ci else 0.0
            else:
                t = min(1.0, max(0.0, (cos_a - co) / (ci - co)))
                s = t * t * (3 - 2 * t)
            vals.append(s)
    bmp = mi.Bitmap(mi.TensorXf(mi.Float(vals), shape=(res, res, 1)))
    return {"type": "bitmap", "bitmap": bmp, "raw": True, "filter_type": "bilinear", "wrap_mode": "clamp"}


def perpendicular(d):
    a = [0.0, 1.0, 0.0] if abs(d[1]) < 0.9 else [1.0, 0.0, 0.0]
    return a


def build_scene(doc, folder, kind):
    scene = {"type": "scene"}
    for m in doc["materials"]:
        if not m["mesh"]:
            continue
        if kind == "gi" and m["textured"]:
            sys.exit(f"mitsuba_check: material '{m['name']}' is textured: GI needs untextured albedo "
                     "(textures are not exported)")
        shape = {
            "type": "ply",
            "filename": os.path.join(folder, m["mesh"]),
            "bsdf": {"type": "twosided",
                     "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": m["albedo"]}}},
        }
        if m["emissive"] and kind == "gi":
            # One-sided emission from the counter-clockwise face: the geometric normal.
            shape["face_normals"] = True
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": m["emission"]}}
        scene[f"mesh{m['index']}"] = shape
    if kind == "gi":
        for i, l in enumerate(doc["lights"]):
            t = l["type"]
            if t == "sun":
                e = [c * l["illuminance"] for c in l["color"]]
                scene[f"light{i}"] = {"type": "directional", "direction": l["direction"],
                                      "irradiance": {"type": "rgb", "value": e}}
            elif t == "point":
                scene[f"light{i}"] = {"type": "point", "position": l["position"],
                                      "intensity": {"type": "rgb", "value": [c * l["intensity"] for c in l["color"]]}}
            elif t == "spot":
                p, d = l["position"], l["direction"]
                scene[f"light{i}"] = {
                    "type": "spot",
                    "to_world": look_at(p, [p[k] + d[k] for k in range(3)], perpendicular(d)),
                    "intensity": {"type": "rgb", "value": [c * l["intensity"] for c in l["color"]]},
                    "cutoff_angle": l["outer_deg"],
                    "beam_width": l["outer_deg"],  # no linear ramp: the texture is the falloff
                    "texture": spot_falloff_texture(l["inner_deg"], l["outer_deg"]),
                }
            elif t == "rect":
                pass  # GPU hint; the emissive geometry is the light (as in strata's reference)
            else:
                sys.exit(f"mitsuba_check: light type '{t}' is not supported")
        sky = doc["settings"]["sky"]
        if any(c > 0 for c in sky):
            scene["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": sky}}
    return mi.load_dict(scene)


# --------------------------------------------------------------------------- Mitsuba rendering


def pixel_rays(sensor, cam, k):
    """Lanes p*k + j: sample j of pixel p; every lane's ray goes through its pixel centre."""
    w, h = cam["width"], cam["height"]
    idx = dr.arange(mi.UInt32, w * h * k)
    p = idx // k
    x = mi.Float(p % w) + 0.5
    y = mi.Float(p // w) + 0.5
    pos = mi.Point2f(x / w, y / h)
    ray, _ = sensor.sample_ray_differential(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
    return ray


def passes(spp, pixels, max_lanes):
    k = max(1, min(spp, max_lanes // pixels))
    while spp % k:
        k -= 1
    return k, spp // k


def render_ao(scene, sensor, cam, radius, eps, spp, seed):
    w, h = cam["width"], cam["height"]
    k, n = passes(spp, w * h, 1 << 21)
    sampler = mi.load_dict({"type": "independent"})
    acc = dr.zeros(mi.Float, w * h)
    for i in range(n):
        sampler.seed(dr.opaque(mi.UInt32, seed * 100003 + i), w * h * k)
        ray = pixel_rays(sensor, cam, k)
        si = scene.ray_intersect(mi.Ray3f(ray))
        valid = si.is_valid()
        # both normals flipped by the geometric side, as strata's facing_normals
        back = dr.dot(si.n, ray.d) > 0
        n_s = dr.select(back, -si.sh_frame.n, si.sh_frame.n)
        n_g = dr.select(back, -si.n, si.n)
        d = mi.Frame3f(n_s).to_world(mi.warp.square_to_cosine_hemisphere(sampler.next_2d()))
        occ_ray = mi.Ray3f(si.p + n_g * eps, d)
        occ_ray.maxt = radius
        hit = scene.ray_test(occ_ray, valid)
        vis = dr.select(valid & hit, 0.0, 1.0)
        acc += dr.block_sum(vis, k)
        dr.eval(acc)
    acc /= spp
    return [acc, acc, acc]


def render_gi(scene, sensor, cam, bounces, spp, seed):
    w, h = cam["width"], cam["height"]
    k, n = passes(spp, w * h, 1 << 20)
    integrator = mi.load_dict({"type": "path", "max_depth": bounces + 2, "hide_emitters": False})
    sampler = mi.load_dict({"type": "independent"})
    acc = [dr.zeros(mi.Float, w * h) for _ in range(3)]
    for i in range(n):
        sampler.seed(dr.opaque(mi.UInt32, seed * 100003 + i), w * h * k)
        ray = pixel_rays(sensor, cam, k)
        spec, valid, _ = integrator.sample(scene, sampler, ray, None, True)
        for c in range(3):
            acc[c] += dr.block_sum(dr.select(valid, spec[c], 0.0), k)
        dr.eval(acc)
    return [a / spp for a in acc]


def write_exr(path, channels, w, h):
    flat = dr.zeros(mi.Float, w * h * 3)
    idx = dr.arange(mi.UInt32, w * h)
    for c in range(3):
        dr.scatter(flat, channels[c], idx * 3 + c)
    mi.Bitmap(mi.TensorXf(flat, shape=(h, w, 3))).write(path)


def read_rgb(path):
    t = mi.TensorXf(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))
    return t


def side_by_side(paths, out, exposure, radiance):
    """strata | Mitsuba | 4 x |difference| (radiance: exposure, ACES, sRGB; AO: sRGB of the value)."""
    a, b = read_rgb(paths[0]), read_rgb(paths[1])
    h, w = a.shape[0], a.shape[1]

    def disp(t):
        x = t.array
        if radiance:
            x = x * exposure
            x = dr.clip((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)
        return dr.clip(x, 0.0, 1.0)

    da, db = disp(a), disp(b)
    diff = dr.clip(4.0 * dr.abs(da - db), 0.0, 1.0)
    canvas = dr.zeros(mi.Float, h * (3 * w + 8) * 3)
    row = 3 * w + 8
    idx = dr.arange(mi.UInt32, h * w * 3)
    pix, c = idx // 3, idx % 3
    y, x = pix // w, pix % w
    for j, img in enumerate((da, db, diff)):
        dr.scatter(canvas, img, (y * row + x + j * (w + 4)) * 3 + c)
    bmp = mi.Bitmap(mi.TensorXf(canvas, shape=(h, row, 3)))
    bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, True).write(out)


# --------------------------------------------------------------------------- main


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scene", default="cornell")
    p.add_argument("--frame", type=float, default=0.0)
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=128)
    p.add_argument("--eye")
    p.add_argument("--target")
    p.add_argument("--up")
    p.add_argument("--fov", type=float)
    p.add_argument("--kind", nargs="+", choices=["ao", "gi"], default=["ao", "gi"])
    p.add_argument("--ao-spp", type=int, default=4096, help="AO rays per pixel, both sides")
    p.add_argument("--ao-radius", type=float, help="default: the scene's")
    p.add_argument("--gi-spp", type=int, default=4096, help="paths per pixel, both sides")
    p.add_argument("--mitsuba-gi-spp", type=int, help="paths per pixel on the Mitsuba side (default --gi-spp)")
    p.add_argument("--bounces", type=int, default=4, help="strata's indirect bounces (Mitsuba max_depth = +2)")
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1], help="first: the check; second: noise floor")
    p.add_argument("--out", default="out/mitsuba")
    p.add_argument("--strata", default=os.path.join(ROOT, "target", "release", "strata"))
    p.add_argument("--force", action="store_true", help="re-render images that exist in --out")
    a = p.parse_args()
    if not os.path.exists(a.strata):
        sys.exit(f"mitsuba_check: {a.strata} not found: cargo build --release -p strata-cli")
    os.makedirs(a.out, exist_ok=True)
    tag = os.path.splitext(os.path.basename(a.scene))[0]
    base = os.path.join(a.out, f"{tag}-{a.width}x{a.height}")

    folder = base + "-export"
    strata(a, ["export-scene", "--out", folder, "--force"] + scene_flags(a))
    doc = json.load(open(os.path.join(folder, "scene.json")))
    cam = doc["camera"]
    sensor = make_sensor(cam)
    worst = check_camera(sensor, cam)
    log(f"{doc['scene']}: {doc['triangles']} triangles; camera rays match strata's within {worst:.2e} degrees")

    for kind in a.kind:
        t0 = time.time()
        scene = build_scene(doc, folder, kind)
        log(f"{kind}: Mitsuba scene built in {time.time() - t0:.1f} s")
        radiance = kind == "gi"
        exposure = doc["settings"]["exposure"] if radiance else None
        spp = a.gi_spp if radiance else a.ao_spp
        m_spp = (a.mitsuba_gi_spp or a.gi_spp) if radiance else a.ao_spp
        radius = a.ao_radius if a.ao_radius is not None else doc["settings"]["ao_radius"]
        # Images are reused when they exist (unless --force): their names carry a hash of
        # everything that determines them.
        key = json.dumps([scene_flags(a), kind, spp, m_spp, a.bounces if radiance else radius])
        stem = f"{base}-{kind}-{hashlib.sha1(key.encode()).hexdigest()[:8]}"
        images, seconds = {}, {}
        for seed in a.seeds[:2]:
            sp = f"{stem}-strata-s{seed}.exr"
            seconds[f"strata-s{seed}"] = strata_reference(a, kind, spp, seed, sp)
            mp = f"{stem}-mitsuba-s{seed}.exr"
            if os.path.exists(mp) and not a.force:
                log(f"reusing {mp}")
                seconds[f"mitsuba-s{seed}"] = 0.0
            else:
                t = time.time()
                if radiance:
                    img = render_gi(scene, sensor, cam, a.bounces, m_spp, seed)
                else:
                    img = render_ao(scene, sensor, cam, radius, doc["ray_epsilon"], m_spp, seed)
                write_exr(mp, img, cam["width"], cam["height"])
                seconds[f"mitsuba-s{seed}"] = time.time() - t
            log(f"{kind} seed {seed}: strata {seconds[f'strata-s{seed}']:.1f} s, "
                f"Mitsuba {seconds[f'mitsuba-s{seed}']:.1f} s")
            images[seed] = (sp, mp)
        s0, s1 = a.seeds[0], a.seeds[1] if len(a.seeds) > 1 else None
        common = {"scene": doc["scene"], "kind": kind, "width": cam["width"], "height": cam["height"],
                  "spp_strata": spp, "spp_mitsuba": m_spp}
        if radiance:
            common.update({"bounces": a.bounces, "mitsuba_max_depth": a.bounces + 2, "exposure": exposure})
        else:
            common["ao_radius"] = radius
        pairs = [("strata-vs-mitsuba", images[s0][0], images[s0][1], f"{stem}-flip.png")]
        if s1 is not None:
            pairs += [("strata-noise", images[s0][0], images[s1][0], None),
                      ("mitsuba-noise", images[s0][1], images[s1][1], None),
                      ("strata-vs-mitsuba-seed1", images[s1][0], images[s1][1], None)]
        results = {}
        for name, ref, test, fmap in pairs:
            r = compare(a, ref, test, exposure, fmap)
            out = {"pair": name, **common, **{k: r[k] for k in ("flip", "rmse", "mae", "mean_reference",
                                                                  "mean_test", "mean_difference")}}
            out["reference_image"], out["test_image"] = ref, test
            results[name] = out
            print(json.dumps(out), flush=True)
        if s1 is not None:
            # Independent noise: E[rmse(strata, mitsuba)^2] = sigma_s^2 + sigma_m^2 + bias^2, and each
            # side's seed-vs-seed RMSE^2 is 2 sigma^2. What is left over is a systematic difference.
            rms = lambda n: results[n]["rmse"]
            expected = math.sqrt((rms("strata-noise") ** 2 + rms("mitsuba-noise") ** 2) / 2)
            cross = math.sqrt((rms("strata-vs-mitsuba") ** 2 + rms("strata-vs-mitsuba-seed1") ** 2) / 2)
            print(json.dumps({"pair": "summary", **common,
                              "flip": results["strata-vs-mitsuba"]["flip"],
                              "flip_noise_strata": results["strata-noise"]["flip"],
                              "flip_noise_mitsuba": results["mitsuba-noise"]["flip"],
                              "rmse": cross, "rmse_expected_from_noise": expected,
                              "rmse_systematic": math.sqrt(max(0.0, cross ** 2 - expected ** 2)),
                              "mean_difference": results["strata-vs-mitsuba"]["mean_difference"],
                              "seconds": seconds}), flush=True)
        side_by_side(images[s0], f"{stem}.png", exposure, radiance)


if __name__ == "__main__":
    main()
