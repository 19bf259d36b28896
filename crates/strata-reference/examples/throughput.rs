//! Ray throughput of the CPU reference on a scene.
//!
//! `cargo run --release -p strata-reference --example throughput -- [scene] [width] [height] [seconds]`
//! (scene: a built-in name or a .gltf/.glb/.obj/.toml path; default `cornell`).
//! First a table of M rays/s per tracer backend and kind of ray, then the mixed
//! primary + bounce measurement and the oracles' timings with the default backend
//! (skipped with `STRATA_KINDS_ONLY=1`).

use std::time::Duration;

use strata_reference::{
    AoBinarySettings, GiSettings, LayerSettings, ObscuranceSettings, RayKind, Reference, TracerKind,
};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map(String::as_str).unwrap_or("cornell");
    let width = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(256);
    let height = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(256);
    let seconds: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5.0);

    let scene = match strata_scene::load_scene(name) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{name}: {e}");
            std::process::exit(1);
        }
    };
    let mut scene = scene;
    if std::env::var_os("STRATA_INSIDE").is_some() {
        // A camera inside the scene's bounds looking along the longer horizontal
        // axis (the loaders' default camera looks at the model from outside).
        let (lo, hi) = scene.bounds(0.0);
        let at = |f: glam::Vec3| lo + (hi - lo) * f;
        let (eye, target) = if hi.x - lo.x >= hi.z - lo.z {
            (at(glam::Vec3::new(0.1, 0.2, 0.5)), at(glam::Vec3::new(0.9, 0.35, 0.45)))
        } else {
            (at(glam::Vec3::new(0.5, 0.2, 0.1)), at(glam::Vec3::new(0.45, 0.35, 0.9)))
        };
        scene.camera = strata_scene::Camera {
            eye,
            target,
            ..scene.camera
        };
        scene.camera_path = None;
    }
    // Per tracer backend and kind of ray (primary: coherent closest hit; ao: short
    // any-hit rays of the scene's AO radius; diffuse: incoherent closest hit).
    let per_kind = (seconds / 3.0).max(0.2);
    println!(
        "{}: {} triangles, {width}x{height}, {} threads, AO radius {}",
        scene.name,
        scene.world_triangles(0.0).len(),
        rayon::current_num_threads(),
        scene.settings.ao_radius
    );
    println!(
        "{:<8} {:>9} {:>7} {:>14} {:>14} {:>14}",
        "tracer", "build s", "nodes", "primary Mr/s", "ao Mr/s", "diffuse Mr/s"
    );
    for kind in TracerKind::ALL {
        let r = Reference::with_tracer(&scene, 0.0, kind);
        let cam = r.camera();
        let rates: Vec<f64> = RayKind::ALL
            .iter()
            .map(|&k| {
                r.measure_rays(
                    &cam,
                    width,
                    height,
                    k,
                    scene.settings.ao_radius,
                    u64::MAX,
                    Duration::from_secs_f64(per_kind),
                )
                .mrays_per_second()
            })
            .collect();
        println!(
            "{:<8} {:>9.3} {:>7} {:>14.2} {:>14.2} {:>14.2}",
            kind.name(),
            r.build_seconds(),
            r.bvh().node_count(),
            rates[0],
            rates[1],
            rates[2]
        );
    }
    if std::env::var_os("STRATA_KINDS_ONLY").is_some() {
        return;
    }

    let r = Reference::new(&scene, 0.0);
    let t = r.measure_throughput(&r.camera(), width, height, u64::MAX, Duration::from_secs_f64(seconds));
    println!(
        "{width}x{height}, primary + 1 diffuse bounce (closest hit): {} rays in {:.2} s on {} threads = {:.2} Mrays/s",
        t.rays,
        t.seconds,
        t.threads,
        t.mrays_per_second()
    );

    // Timings of the oracles themselves at the same size.
    let cam = r.camera();
    let radius = scene.settings.ao_radius;
    let time = |label: &str, f: &dyn Fn()| {
        r.reset_stats();
        f();
        let s = r.stats();
        println!(
            "{label:<28} {:>7.2} s  {:>6.2} Mrays/s",
            s.seconds,
            s.mrays_per_second()
        );
    };
    time("AO binary, 32 spp", &|| {
        r.ao_binary(
            &cam,
            width,
            height,
            &AoBinarySettings {
                spp: 32,
                ..AoBinarySettings::new(radius)
            },
        );
    });
    time("AO DGB obscurance, 32 spp", &|| {
        r.ao_obscurance(
            &cam,
            width,
            height,
            &ObscuranceSettings {
                spp: 32,
                ..ObscuranceSettings::new(radius)
            },
        );
    });
    time("GI, 4 spp, 2 bounces", &|| {
        r.gi(
            &cam,
            width,
            height,
            &GiSettings {
                spp: 4,
                bounces: 2,
                ..Default::default()
            },
        );
    });
    time("layers, k = 2", &|| {
        r.layers(
            &cam,
            width,
            height,
            &LayerSettings::new(2, scene.settings.min_separation),
        );
    });
}
