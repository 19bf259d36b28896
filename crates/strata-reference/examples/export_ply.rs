//! Writes a scene's world-space triangles (frame 0) as a binary little-endian PLY
//! and its camera as JSON, so an external renderer (`scripts/mitsuba_bench.py`)
//! traces exactly the triangles and camera the reference traces.
//!
//! `cargo run --release -p strata-reference --example export_ply -- SCENE OUT.ply`
//! writes `OUT.ply` and `OUT.json` (`eye`, `target`, `up`, `fov_y_deg`, `near`,
//! `ao_radius`, `triangles`). Triangles with non-finite vertices are left out,
//! as the reference's BVH leaves them out.

use std::io::Write;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(name), Some(out)) = (args.first(), args.get(1)) else {
        eprintln!("usage: export_ply SCENE OUT.ply");
        std::process::exit(2);
    };
    let scene = match strata_scene::load_scene(name) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{name}: {e}");
            std::process::exit(1);
        }
    };
    let tris: Vec<_> = scene
        .world_triangles(0.0)
        .into_iter()
        .filter(|t| t.p.iter().all(|p| p.is_finite()))
        .collect();
    let mut buf = Vec::with_capacity(tris.len() * 49 + 256);
    let header = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        tris.len() * 3,
        tris.len()
    );
    buf.extend_from_slice(header.as_bytes());
    for t in &tris {
        for p in &t.p {
            for c in [p.x, p.y, p.z] {
                buf.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    for i in 0..tris.len() as i32 {
        buf.push(3);
        for k in 0..3 {
            buf.extend_from_slice(&(3 * i + k).to_le_bytes());
        }
    }
    let cam = scene.camera_at(0.0);
    let json = format!(
        "{{\"scene\": {:?}, \"triangles\": {}, \"eye\": [{}, {}, {}], \"target\": [{}, {}, {}], \"up\": [{}, {}, {}], \"fov_y_deg\": {}, \"near\": {}, \"ao_radius\": {}}}\n",
        scene.name,
        tris.len(),
        cam.eye.x,
        cam.eye.y,
        cam.eye.z,
        cam.target.x,
        cam.target.y,
        cam.target.z,
        cam.up.x,
        cam.up.y,
        cam.up.z,
        cam.fov_y_deg,
        cam.near,
        scene.settings.ao_radius
    );
    let json_path = std::path::Path::new(out).with_extension("json");
    let write = |path: &std::path::Path, bytes: &[u8]| -> std::io::Result<()> {
        let mut f = std::fs::File::create(path)?;
        f.write_all(bytes)
    };
    if let Err(e) = write(std::path::Path::new(out), &buf).and_then(|_| write(&json_path, json.as_bytes())) {
        eprintln!("{out}: {e}");
        std::process::exit(1);
    }
    println!(
        "{}: {} triangles -> {out}, {}",
        scene.name,
        tris.len(),
        json_path.display()
    );
}
