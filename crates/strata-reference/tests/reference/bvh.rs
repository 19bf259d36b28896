use glam::Vec3;
use strata_reference::bvh::{intersect_triangle, Bvh, Hit};
use strata_reference::sampling::Rng;
use strata_scene::WorldTriangle;

fn tri(p: [Vec3; 3]) -> WorldTriangle {
    let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
    WorldTriangle {
        p,
        n: [n; 3],
        uv: [[0.0; 2]; 3],
        material: 0,
        object: 0,
    }
}

fn v3(rng: &mut Rng) -> Vec3 {
    Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32())
}

/// Random triangle soup: 2000 triangles of edge ~0.3–2.5 in a 10³ box.
fn soup() -> Vec<WorldTriangle> {
    let mut rng = Rng::new(42);
    (0..2000)
        .map(|_| {
            let c = v3(&mut rng) * 10.0;
            let s = 0.3 + 2.2 * rng.next_f32();
            tri([c, c + (v3(&mut rng) - 0.5) * s, c + (v3(&mut rng) - 0.5) * s])
        })
        .collect()
}

/// Brute force: every triangle, closest t, ties to the lowest index.
fn brute_closest(tris: &[WorldTriangle], o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for (i, t) in tris.iter().enumerate() {
        if let Some(mut h) = intersect_triangle(&t.p, o, d, tmin, tmax) {
            h.triangle = i as u32;
            if best.is_none_or(|b| h.t < b.t) {
                best = Some(h);
            }
        }
    }
    best
}

/// Independent Möller–Trumbore in f64 (for t only).
fn moller_trumbore(p: &[Vec3; 3], o: Vec3, d: Vec3) -> Option<f64> {
    let (p0, p1, p2) = (p[0].as_dvec3(), p[1].as_dvec3(), p[2].as_dvec3());
    let (o, d) = (o.as_dvec3(), d.as_dvec3());
    let (e1, e2) = (p1 - p0, p2 - p0);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det.abs() < 1e-14 {
        return None;
    }
    let tv = o - p0;
    let u = tv.dot(pv) / det;
    let q = tv.cross(e1);
    let v = d.dot(q) / det;
    if u < 0.0 || v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some(e2.dot(q) / det)
}

#[test]
fn bvh_matches_brute_force_on_random_soup() {
    let tris = soup();
    let bvh = Bvh::build(tris.clone());
    let mut rng = Rng::new(7);
    let (mut hits, mut all) = (0, Vec::new());
    for i in 0..2000 {
        let o = v3(&mut rng) * 14.0 - 2.0;
        // Mostly aimed into the soup; unnormalised lengths too.
        let aim = if i % 4 == 0 {
            v3(&mut rng) - 0.5
        } else {
            v3(&mut rng) * 10.0 - o
        };
        let d = aim.normalize() * (0.5 + 2.0 * rng.next_f32());
        let (tmin, tmax) = if i % 3 == 0 { (0.5, 4.0) } else { (0.0, f32::INFINITY) };
        let got = bvh.intersect(o, d, tmin, tmax);
        let want = brute_closest(&tris, o, d, tmin, tmax);
        match (got, want) {
            (None, None) => {}
            (Some(g), Some(w)) => {
                hits += 1;
                assert!(
                    (g.t - w.t).abs() <= 1e-4 * w.t.max(1.0),
                    "ray {i}: t {} vs {}",
                    g.t,
                    w.t
                );
                assert_eq!(g.triangle, w.triangle, "ray {i}: triangle");
                let mt = moller_trumbore(&tris[g.triangle as usize].p, o, d).expect("MT agrees on a hit");
                assert!(
                    (g.t as f64 - mt).abs() <= 1e-4 * mt.max(1.0),
                    "ray {i}: t {} vs MT {mt}",
                    g.t
                );
            }
            (g, w) => panic!("ray {i}: bvh {g:?} vs brute force {w:?}"),
        }
        assert_eq!(bvh.occluded(o, d, tmin, tmax), want.is_some(), "ray {i}: occluded");
        bvh.intersect_all(o, d, tmin, tmax, &mut all);
        let n_brute = tris
            .iter()
            .filter(|t| intersect_triangle(&t.p, o, d, tmin, tmax).is_some())
            .count();
        assert_eq!(all.len(), n_brute, "ray {i}: all-hits count");
        assert!(all.windows(2).all(|w| w[0].t <= w[1].t), "ray {i}: all-hits sorted");
        if let Some(w) = want {
            assert_eq!(all[0].t, w.t);
            // Walking with next_hit visits the distinct depths in order.
            let mut t = tmin;
            let mut seen = 0;
            while let Some(h) = bvh.next_hit(o, d, t, tmax) {
                assert!(h.t > t);
                t = h.t;
                seen += 1;
            }
            assert!(seen >= 1 && seen <= all.len());
        }
    }
    assert!(hits > 1000, "only {hits} of 2000 rays hit; the test is too weak");
}

#[test]
fn rays_through_shared_edges_and_vertices_never_leak() {
    // A 20×20 grid of unit squares split into triangles; aim rays exactly at
    // grid vertices and edge midpoints (shared by 2–6 triangles).
    let mut tris = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            let p = |a: i32, b: i32| Vec3::new((i + a) as f32 - 10.0, 0.0, (j + b) as f32 - 10.0);
            tris.push(tri([p(0, 0), p(0, 1), p(1, 1)]));
            tris.push(tri([p(0, 0), p(1, 1), p(1, 0)]));
        }
    }
    let bvh = Bvh::build(tris);
    let eye = Vec3::new(0.37, 7.0, -1.3);
    let mut n = 0;
    for i in -9..=9 {
        for j in -9..=9 {
            for target in [
                Vec3::new(i as f32, 0.0, j as f32),
                Vec3::new(i as f32 + 0.5, 0.0, j as f32),
                Vec3::new(i as f32 + 0.5, 0.0, j as f32 + 0.5),
            ] {
                let d = target - eye;
                let h = bvh
                    .intersect(eye, d, 0.0, f32::INFINITY)
                    .expect("watertight: ray through an edge/vertex hits");
                assert!((h.t - 1.0).abs() < 1e-5);
                assert!(bvh.occluded(eye, d, 0.0, 2.0));
                n += 1;
            }
        }
    }
    assert_eq!(n, 19 * 19 * 3);
}

#[test]
fn empty_and_degenerate_inputs() {
    let bvh = Bvh::build(Vec::new());
    assert!(bvh.intersect(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY).is_none());
    assert!(!bvh.occluded(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY));
    assert!(bvh.bounds().is_none());
    // Many identical triangles (degenerate centroids) and a zero-area one.
    let t = tri([Vec3::ZERO, Vec3::X, Vec3::Y]);
    let mut tris = vec![t; 50];
    tris.push(tri([Vec3::ONE; 3]));
    tris.push(tri([Vec3::splat(f32::NAN), Vec3::X, Vec3::Y]));
    let bvh = Bvh::build(tris);
    let h = bvh
        .intersect(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 0.0, f32::INFINITY)
        .unwrap();
    assert_eq!(h.triangle, 0, "ties go to the lowest index");
    let mut all = Vec::new();
    bvh.intersect_all(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 0.0, f32::INFINITY, &mut all);
    assert_eq!(all.len(), 50);
    // Surface attributes.
    let s = bvh.surface(&h, -Vec3::Z);
    assert!(s.front_face && (s.geometric_normal - Vec3::Z).length() < 1e-6);
    assert!((s.position - Vec3::new(0.2, 0.2, 0.0)).length() < 1e-6);
}
