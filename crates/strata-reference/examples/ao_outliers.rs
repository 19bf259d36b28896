//! Finds the dark speckles of a binary-AO reference and explains each one: where the primary ray
//! landed, which normals the estimator used, and what the occluding rays hit.
//!
//! `cargo run --release -p strata-reference --example ao_outliers -- [scene] [width] [height] [spp]`
//! (defaults: atrium 160 90 16, the demo's `atrium-ref-ao.png`).

use strata_reference::{AoBinarySettings, Reference};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("atrium", |s| s.as_str());
    let w: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(160);
    let h: u32 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(90);
    let spp: u32 = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(16);
    let scene = strata_scene::procedural::builtin(name).expect("a built-in scene");
    let r = Reference::new(&scene, 0.0);
    let cam = r.camera();
    let radius = scene.settings.ao_radius;
    let settings = AoBinarySettings {
        spp,
        ..AoBinarySettings::new(radius)
    };
    let img = r.ao_binary(&cam, w, h, &settings);
    let at = |x: i64, y: i64| img.data[(y.clamp(0, h as i64 - 1) * w as i64 + x.clamp(0, w as i64 - 1)) as usize];
    let mut found = 0;
    println!("scene {name} {w}x{h} {spp} spp radius {radius} epsilon {}", r.epsilon());
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let mut win: Vec<f32> = (-1..=1)
                .flat_map(|dy| (-1..=1).map(move |dx| (dx, dy)))
                .map(|(dx, dy)| at(x + dx, y + dy))
                .collect();
            win.sort_by(f32::total_cmp);
            let v = at(x, y);
            if !(v < 0.15 && win[4] - v > 0.4) {
                continue;
            }
            found += 1;
            let dir = cam.pixel_dir(x as u32, y as u32, w, h);
            let hit = r
                .primary_hit(&cam, x as u32, y as u32, w, h)
                .expect("dark pixels have a hit");
            let (n, ng) = hit.facing_normals(dir);
            let obj = &scene.objects[hit.object as usize].name;
            let mat = &scene.materials[hit.material as usize].name;
            // what do the AO rays hit, and how far?
            let origin = hit.position + ng * r.epsilon();
            let mut dists = Vec::new();
            let mut hit_objects = std::collections::BTreeMap::<String, u32>::new();
            for i in 0..spp {
                let key = strata_reference::sampling::hash(&[0, i as u64]);
                let d = strata_reference::sampling::cosine_hemisphere(n, strata_reference::sampling::pixel_offset(key));
                if let Some(hh) = r.bvh().intersect(origin, d, 0.0, radius) {
                    dists.push(hh.t);
                    let s = r.bvh().surface(&hh, d);
                    *hit_objects
                        .entry(scene.objects[s.object as usize].name.clone())
                        .or_default() += 1;
                }
            }
            dists.sort_by(f32::total_cmp);
            println!(
                "({x},{y}) AV {v:.3} median {:.3} t {:.4} obj {obj} mat {mat} tri {} front {} n·ng {:.3} ng {:?} p {:?}\n    {} of {spp} random probes occluded, nearest t {:?}, by {:?}",
                win[4],
                hit.t,
                hit.triangle,
                hit.front_face,
                n.dot(ng),
                ng,
                hit.position,
                dists.len(),
                dists.first(),
                hit_objects
            );
        }
    }
    println!("{found} dark speckles");
}
