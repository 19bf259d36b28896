//! Times one job of the CPU reference (the jobs `scripts/mitsuba_bench.py`
//! compares with Mitsuba 3).
//!
//! `cargo run --release -p strata-reference --example ao_job -- SCENE WIDTH HEIGHT SPP RADIUS [all|wide|binary] [REPEATS] [ao|primary|diffuse]`
//!
//! - `ao` (default): `Reference::ao_binary`, one primary ray per pixel + SPP AO rays;
//! - `primary`: SPP camera rays per pixel (pixel centres, closest hit);
//! - `diffuse`: SPP cosine bounce rays (closest hit, unbounded) per hit pixel, from
//!   primary hits found untimed (`Reference::measure_rays`, 16 rays per pass).
//!
//! Prints one JSON object per repeat: build and render seconds, rays, M rays/s.

use std::time::Instant;

use std::time::Duration;

use strata_reference::{AoBinarySettings, RayKind, Reference, TracerKind};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map(String::as_str).unwrap_or("scenes/sponza.toml");
    let arg = |i: usize, d: f64| args.get(i).and_then(|s| s.parse::<f64>().ok()).unwrap_or(d);
    let (width, height, spp, radius) = (
        arg(1, 256.0) as u32,
        arg(2, 256.0) as u32,
        arg(3, 1024.0) as u32,
        arg(4, 1.5) as f32,
    );
    let scene = match strata_scene::load_scene(name) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{name}: {e}");
            std::process::exit(1);
        }
    };
    let kinds: Vec<TracerKind> = match args.get(5).map(String::as_str) {
        None | Some("all") => TracerKind::ALL.to_vec(),
        Some(n) => match TracerKind::from_name(n) {
            Some(k) => vec![k],
            None => {
                eprintln!("tracer {n:?}: expected all, wide or binary");
                std::process::exit(2);
            }
        },
    };
    let repeats = (arg(6, 1.0) as usize).max(1);
    let job = match args.get(7).map(String::as_str) {
        None | Some("ao") => None,
        Some("primary") => Some(RayKind::Primary),
        Some("diffuse") => Some(RayKind::Diffuse),
        Some(k) => {
            eprintln!("kind {k:?}: expected ao, primary or diffuse");
            std::process::exit(2);
        }
    };
    let settings = AoBinarySettings {
        spp,
        ..AoBinarySettings::new(radius)
    };
    for _ in 0..repeats {
        for &kind in &kinds {
            let start = Instant::now();
            let r = Reference::with_tracer(&scene, 0.0, kind);
            let build = start.elapsed().as_secs_f64();
            let cam = r.camera();
            let start = Instant::now();
            let cpu0 = cpu_seconds();
            let (rays, mean) = match job {
                None => {
                    let img = r.ao_binary(&cam, width, height, &settings);
                    let mean = img.data.iter().map(|&v| v as f64).sum::<f64>() / img.data.len().max(1) as f64;
                    (r.stats().rays, mean)
                }
                Some(k) => {
                    // Passes of one primary ray (or 16 secondary rays) per pixel until SPP per pixel.
                    let per_pass = if k == RayKind::Primary { 1 } else { 16 };
                    let max_rays = width as u64 * height as u64 * spp as u64 / per_pass * per_pass;
                    let t = r.measure_rays(&cam, width, height, k, radius, max_rays, Duration::from_secs(3600));
                    (t.rays, 0.0)
                }
            };
            let secs = start.elapsed().as_secs_f64();
            let cpu = cpu_seconds() - cpu0;
            println!(
                "{{\"scene\": \"{}\", \"tracer\": \"{}\", \"triangles\": {}, \"width\": {width}, \"height\": {height}, \"spp\": {spp}, \"radius\": {radius}, \"threads\": {}, \"build_s\": {build:.4}, \"seconds\": {secs:.4}, \"cpu_s\": {cpu:.4}, \"rays\": {}, \"mrays_per_s\": {:.3}, \"mean_av\": {mean:.6}}}",
                scene.name.replace('"', "'"),
                kind.name(),
                r.bvh().triangles().len(),
                rayon::current_num_threads(),
                rays,
                rays as f64 / secs / 1e6
            );
        }
    }
}

/// User + system CPU seconds of this process (Linux `/proc/self/stat`; 0 elsewhere):
/// on a shared machine, CPU time per ray is steadier than wall time.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = stat.rsplit_once(')').map(|(_, r)| r).unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|s| s.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}
