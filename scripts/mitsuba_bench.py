#!/usr/bin/env python3
"""Times the same ambient-occlusion job in the strata CPU reference and in Mitsuba 3.

A benchmark tool only (strata never depends on Mitsuba). Needs `pip install mitsuba`
numpy (variant llvm_ad_rgb, which traces with Embree), an LLVM that Dr.Jit can JIT
with (on Debian 12: `apt-get install libllvm19`; with the default LLVM 14/15 the
kernel fails to compile: "Cannot select ... fmaximum") and a Rust toolchain.

The job (issue 10, `--kind ao`): binary AO at WIDTH x HEIGHT with SPP x AO_SAMPLES
hemisphere rays per pixel within RADIUS, from the scene's camera. `--kind primary`: SPP
camera rays per pixel (closest hit); `--kind diffuse`: SPP x AO_SAMPLES cosine bounce
rays per pixel (closest hit, unbounded). Both sides report wall and CPU seconds (CPU
time, over all threads of each process, is steadier on a shared machine).

- strata: `examples/ao_job` (Reference::ao_binary: one primary ray through each pixel
  centre + SPP*AO_SAMPLES cosine-weighted occlusion rays), once per tracer backend.
- Mitsuba: the same triangles (exported by `examples/export_ply`, so both trace exactly
  the same world-space triangles) and the same camera (look-at, vertical fov); an AO
  integrator written here with Mitsuba's ray queries: per sample one camera ray and
  AO_SAMPLES cosine-weighted `ray_test`s of length RADIUS around the facing shading
  normal, SPP samples per pixel (so Mitsuba traces SPP primary rays per pixel where
  strata traces one: slightly more work for Mitsuba).

Mitsuba compiles its kernel on the first render in a process (LLVM JIT; Dr.Jit may
also reuse its on-disk kernel cache from an earlier process). Both are reported: the
first render ("first") and the median of the later ones ("warm"); the ratio uses the
warm time unless --ratio-first. Each repeat runs strata and Mitsuba back to back;
the summary gives medians over the repeats.

Example:
  python3 scripts/mitsuba_bench.py                       # Sponza, 256x256, 64x16 rays, radius 1.5, 3 repeats
  python3 scripts/mitsuba_bench.py --scene dragon --scene dense --radius-from-scene
  python3 scripts/mitsuba_bench.py --json out/bench/mitsuba_ao.json
  python3 scripts/mitsuba_bench.py --kind primary --spp 256    # camera rays only
  python3 scripts/mitsuba_bench.py --kind diffuse               # 64x16 cosine bounce rays per pixel, closest hit
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = {
    "sponza": "scenes/sponza.toml",
    "dragon": "scenes/dragon.toml",
    "dense": "dense",
}


def run(cmd, **kw):
    return subprocess.run(cmd, cwd=ROOT, check=True, text=True, capture_output=True, **kw)


def build_examples():
    print("building strata-reference examples (cargo build --release) ...", file=sys.stderr)
    subprocess.run(
        ["cargo", "build", "--release", "-p", "strata-reference", "--examples"], cwd=ROOT, check=True
    )


def example(name):
    return os.path.join(ROOT, "target", "release", "examples", name)


def export(scene, workdir):
    ply = os.path.join(workdir, f"{os.path.basename(scene).split('.')[0]}.ply")
    run([example("export_ply"), scene, ply])
    with open(os.path.splitext(ply)[0] + ".json") as f:
        cam = json.load(f)
    return ply, cam


def strata_job(scene, a, radius, tracer):
    rays = a.spp if a.kind == "primary" else a.spp * a.ao_samples
    out = run(
        [example("ao_job"), scene, str(a.width), str(a.height), str(rays), str(radius), tracer, "1", a.kind],
        env={**os.environ, **({"RAYON_NUM_THREADS": str(a.threads)} if a.threads else {})},
    )
    rows = [json.loads(l) for l in out.stdout.splitlines() if l.startswith("{")]
    return rows[0]


def make_mitsuba(a):
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")

    def first_hit(scene, ray, active):
        """The camera ray's hit, its validity and a frame around its shading normal facing the camera."""
        si = scene.ray_intersect(ray, active)
        n = si.sh_frame.n
        return si, si.is_valid(), mi.Frame3f(dr.select(dr.dot(n, ray.d) > 0, -n, n))

    def cosine_dir(frame, sampler, valid):
        """A cosine-weighted direction around the frame's normal."""
        return frame.to_world(mi.warp.square_to_cosine_hemisphere(sampler.next_2d(valid)))

    class StrataAO(mi.SamplingIntegrator):
        """Binary AO: 1 - (occluded rays / n) around the facing shading normal."""

        def __init__(self, props):
            super().__init__(props)
            self.radius = props.get("distance", 1.0)
            self.n = props.get("shading_samples", 16)

        def sample(self, scene, sampler, ray, medium=None, active=True):
            si, valid, frame = first_hit(scene, ray, active)
            hits = mi.Float(0.0)
            for _ in range(self.n):
                r = si.spawn_ray(cosine_dir(frame, sampler, valid))
                r.maxt = self.radius
                hits += dr.select(scene.ray_test(r, valid), 1.0, 0.0)
            av = dr.select(valid, 1.0 - hits / self.n, 1.0)
            return mi.Spectrum(av), valid, []

    class StrataPrimary(mi.SamplingIntegrator):
        """Camera rays only (closest hit): returns the hit distance."""

        def __init__(self, props):
            super().__init__(props)
            props.get("shading_samples", 16)  # shared scene dict: mark as read
            props.get("distance", 1.0)

        def sample(self, scene, sampler, ray, medium=None, active=True):
            si = scene.ray_intersect(ray, active)
            return mi.Spectrum(dr.select(si.is_valid(), si.t, 0.0)), si.is_valid(), []

    class StrataDiffuse(mi.SamplingIntegrator):
        """Per sample one camera ray and `shading_samples` cosine bounce rays (closest hit, unbounded)."""

        def __init__(self, props):
            super().__init__(props)
            self.n = props.get("shading_samples", 16)
            props.get("distance", 1.0)  # shared scene dict: mark as read

        def sample(self, scene, sampler, ray, medium=None, active=True):
            si, valid, frame = first_hit(scene, ray, active)
            acc = mi.Float(0.0)
            for _ in range(self.n):
                s2 = scene.ray_intersect(si.spawn_ray(cosine_dir(frame, sampler, valid)), valid)
                acc += dr.select(s2.is_valid(), 1.0, 0.0)
            return mi.Spectrum(acc / self.n), valid, []

    mi.register_integrator("strata_ao", lambda props: StrataAO(props))
    mi.register_integrator("strata_primary", lambda props: StrataPrimary(props))
    mi.register_integrator("strata_diffuse", lambda props: StrataDiffuse(props))
    return mi, dr


def mitsuba_scene(mi, ply, cam, a, radius):
    t0 = time.perf_counter()
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": f"strata_{a.kind}", "shading_samples": a.ao_samples, "distance": radius},
            "sensor": {
                "type": "perspective",
                "fov": cam["fov_y_deg"],
                "fov_axis": "y",
                "near_clip": cam["near"],
                "to_world": mi.ScalarTransform4f().look_at(origin=cam["eye"], target=cam["target"], up=cam["up"]),
                "film": {
                    "type": "hdrfilm",
                    "width": a.width,
                    "height": a.height,
                    "rfilter": {"type": "box"},
                    "pixel_format": "luminance",
                },
                "sampler": {"type": "independent", "sample_count": a.spp},
            },
            "mesh": {"type": "ply", "filename": ply, "face_normals": True},
        }
    )
    return scene, time.perf_counter() - t0


def mitsuba_render(mi, dr, scene, a, seed):
    """Wall seconds, CPU seconds (all threads of this process) and mean AV of one render."""
    t0, c0 = time.perf_counter(), time.process_time()
    img = mi.render(scene, spp=a.spp, seed=seed)
    dr.eval(img)
    dr.sync_thread()
    dt, cpu = time.perf_counter() - t0, time.process_time() - c0
    mean = float(sum(img.numpy().ravel()) / max(1, img.numpy().size))
    return dt, cpu, mean


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", action="append", help="sponza, dragon, dense or a scene path (repeatable; default sponza)")
    p.add_argument("--width", type=int, default=256)
    p.add_argument("--height", type=int, default=256)
    p.add_argument("--spp", type=int, default=64, help="Mitsuba samples per pixel")
    p.add_argument("--ao-samples", type=int, default=16, help="AO rays per sample (strata: spp x this per pixel)")
    p.add_argument("--radius", type=float, default=1.5)
    p.add_argument("--radius-from-scene", action="store_true", help="use each scene's ao_radius instead of --radius")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--tracers", default="all", help="strata backends: all, wide or binary")
    p.add_argument("--threads", type=int, default=0, help="RAYON_NUM_THREADS for strata (0: rayon's default)")
    p.add_argument("--ratio-first", action="store_true", help="compare with Mitsuba's first (JIT-compiling) render")
    p.add_argument("--no-build", action="store_true")
    p.add_argument("--workdir", default=os.path.join(ROOT, "target", "mitsuba_bench"))
    p.add_argument("--json", help="write all timings here")
    p.add_argument(
        "--kind",
        choices=["ao", "primary", "diffuse"],
        default="ao",
        help="ao: the AO job; primary: SPP camera rays per pixel; diffuse: SPP x AO_SAMPLES cosine bounce rays "
        "(closest hit, unbounded) per pixel",
    )
    a = p.parse_args()
    if a.width <= 0 or a.height <= 0 or a.spp <= 0 or a.ao_samples <= 0 or a.repeats <= 0 or not a.radius > 0:
        p.error("width, height, spp, ao-samples, repeats and radius must be positive")
    tracers = ["wide", "binary"] if a.tracers == "all" else [a.tracers]
    if not a.no_build or not os.path.exists(example("ao_job")):
        build_examples()
    os.makedirs(a.workdir, exist_ok=True)
    mi, dr = make_mitsuba(a)

    results = []
    for name in a.scene or ["sponza"]:
        scene_arg = SCENES.get(name, name)
        ply, cam = export(scene_arg, a.workdir)
        radius = cam["ao_radius"] if a.radius_from_scene else a.radius
        ms, load_s = mitsuba_scene(mi, ply, cam, a, radius)
        print(
            f"\n{cam['scene']}: {cam['triangles']} triangles, {a.width}x{a.height}, {a.kind} job: "
            + (f"{a.spp} camera rays/pixel; " if a.kind == "primary" else
               f"{a.spp}x{a.ao_samples} = {a.spp * a.ao_samples} {a.kind} rays/pixel, radius {radius}; ")
            + f"Mitsuba load + BVH {load_s:.2f} s"
        )
        rows = []
        first = None
        for rep in range(a.repeats):
            row = {"repeat": rep}
            for t in tracers:
                r = strata_job(scene_arg, a, radius, t)
                row[f"strata_{t}_s"] = r["seconds"]
                row[f"strata_{t}_mrays"] = r["mrays_per_s"]
                row[f"strata_{t}_mean"] = r["mean_av"]
                row[f"strata_{t}_build_s"] = r["build_s"]
                row[f"strata_{t}_cpu_s"] = r["cpu_s"]
            dt, cpu, mean = mitsuba_render(mi, dr, ms, a, seed=rep)
            if first is None:
                first = dt
                row["mitsuba_first_s"] = dt
                dt, cpu, mean = mitsuba_render(mi, dr, ms, a, seed=rep + 1000)
            row["mitsuba_s"] = dt
            row["mitsuba_cpu_s"] = cpu
            row["mitsuba_mean"] = mean
            rows.append(row)
            line = "  ".join(f"strata {t} {row[f'strata_{t}_s']:.2f} s" for t in tracers)
            extra = f" (first render {row['mitsuba_first_s']:.2f} s)" if "mitsuba_first_s" in row else ""
            print(f"  repeat {rep}: {line}  mitsuba {dt:.2f} s{extra}  (CPU s: {cpu:.2f} mitsuba, "
                  + ", ".join(f"{row[f'strata_{t}_cpu_s']:.2f} {t}" for t in tracers) + ")")
        med = {k: statistics.median(r[k] for r in rows) for k in rows[0] if k not in ("repeat", "mitsuba_first_s")}
        mitsuba_ref = first if a.ratio_first else med["mitsuba_s"]
        # Rays: strata 1 primary + spp*ao per pixel; Mitsuba spp primary + spp*ao per pixel
        # (primary job: spp camera rays per pixel on both sides).
        px = a.width * a.height
        mitsuba_rays = px * a.spp * (1 if a.kind == "primary" else 1 + a.ao_samples)
        print(
            f"  medians: mitsuba {med['mitsuba_s']:.2f} s warm, {first:.2f} s first "
            f"({mitsuba_rays / med['mitsuba_s'] / 1e6:.1f} M rays/s warm); mean AV {med['mitsuba_mean']:.4f}"
        )
        for t in tracers:
            s = med[f"strata_{t}_s"]
            print(
                f"  medians: strata {t:<6} {s:.2f} s ({med[f'strata_{t}_mrays']:.1f} M rays/s), "
                f"{s / mitsuba_ref:.2f}x Mitsuba's {'first' if a.ratio_first else 'warm'} time; "
                f"CPU time {med[f'strata_{t}_cpu_s'] / med['mitsuba_cpu_s']:.2f}x Mitsuba's; "
                f"mean AV {med[f'strata_{t}_mean']:.4f}"
            )
        results.append(
            {
                "scene": cam["scene"],
                "triangles": cam["triangles"],
                "width": a.width,
                "height": a.height,
                "spp": a.spp,
                "ao_samples": a.ao_samples,
                "radius": radius,
                "kind": a.kind,
                "mitsuba_load_s": load_s,
                "mitsuba_first_s": first,
                "repeats": rows,
                "medians": med,
            }
        )
    if a.json:
        os.makedirs(os.path.dirname(os.path.abspath(a.json)), exist_ok=True)
        with open(a.json, "w") as f:
            json.dump({"date": time.strftime("%Y-%m-%d"), "nproc": os.cpu_count(), "results": results}, f, indent=1)
        print(f"\nwrote {a.json}")


if __name__ == "__main__":
    main()
