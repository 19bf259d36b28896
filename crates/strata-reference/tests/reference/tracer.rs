//! Every tracer backend answers every query exactly like the binary BVH: same
//! hit triangle, bitwise-equal `t` and barycentrics (both run the same
//! watertight test with the same operations, and box culling is conservative
//! with a margin, so the set of hits does not depend on the tree), same
//! occlusion answers, same `intersect_all` lists.
use glam::Vec3;
use strata_reference::bvh::{Bvh, Hit};
use strata_reference::sampling::Rng;
use strata_reference::{
    AnyTracer, AoBinarySettings, LayerSettings, ObscuranceSettings, Reference, Tracer, TracerKind, WideBvh,
};
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

fn builtin(name: &str) -> Vec<WorldTriangle> {
    strata_scene::procedural::builtin(name)
        .expect("built-in scene")
        .world_triangles(0.0)
}

/// Named backends under test.
type Backends = Vec<(String, Box<dyn Tracer>)>;

/// The binary BVH (the reference answer) and every other backend, including
/// the wide BVH with its portable (non-SIMD) box test.
fn backends(tris: &[WorldTriangle]) -> (Bvh, Backends) {
    let wide = WideBvh::build(tris.to_vec());
    let simd = wide.simd();
    let mut others: Backends = vec![(format!("wide (simd {simd})"), Box::new(wide))];
    if simd {
        others.push((
            "wide (portable)".into(),
            Box::new(WideBvh::build(tris.to_vec()).with_simd(false)),
        ));
    }
    others.push((
        "AnyTracer::Wide".into(),
        Box::new(AnyTracer::build(tris.to_vec(), TracerKind::Wide)),
    ));
    (Bvh::build(tris.to_vec()), others)
}

fn same_hit(a: Option<Hit>, b: Option<Hit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            a.triangle == b.triangle
                && a.t.to_bits() == b.t.to_bits()
                && a.b1.to_bits() == b.b1.to_bits()
                && a.b2.to_bits() == b.b2.to_bits()
        }
        _ => false,
    }
}

fn same_list(a: &[Hit], b: &[Hit]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| same_hit(Some(*x), Some(*y)))
}

/// Compares all queries of every backend with the binary BVH on `rays`
/// (origin, direction, tmin, tmax). Returns how many rays hit something.
fn compare(label: &str, tris: &[WorldTriangle], rays: &[(Vec3, Vec3, f32, f32)]) -> usize {
    let (bvh, others) = backends(tris);
    let (mut all_b, mut all_o) = (Vec::new(), Vec::new());
    let mut hits = 0;
    for (name, t) in &others {
        assert_eq!(t.triangles().len(), bvh.triangles().len());
        assert_eq!(t.bounds(), bvh.bounds(), "{label}/{name}: bounds");
    }
    for (i, &(o, d, tmin, tmax)) in rays.iter().enumerate() {
        let want = bvh.intersect(o, d, tmin, tmax);
        let occ = bvh.occluded(o, d, tmin, tmax);
        bvh.intersect_all(o, d, tmin, tmax, &mut all_b);
        hits += want.is_some() as usize;
        assert_eq!(occ, want.is_some(), "{label}: ray {i}: binary occluded vs intersect");
        for (name, t) in &others {
            let got = t.intersect(o, d, tmin, tmax);
            assert!(
                same_hit(got, want),
                "{label}/{name}: ray {i} ({o:?}, {d:?}, [{tmin}, {tmax}]): intersect {got:?} vs binary {want:?}"
            );
            assert_eq!(t.occluded(o, d, tmin, tmax), occ, "{label}/{name}: ray {i}: occluded");
            t.intersect_all(o, d, tmin, tmax, &mut all_o);
            assert!(
                same_list(&all_o, &all_b),
                "{label}/{name}: ray {i}: intersect_all {all_o:?} vs binary {all_b:?}"
            );
            if let Some(h) = want {
                assert_eq!(t.surface(&h, d), bvh.surface(&h, d), "{label}/{name}: ray {i}: surface");
            }
        }
    }
    hits
}

fn random_rays(tris: &[WorldTriangle], n: usize, seed: u64) -> Vec<(Vec3, Vec3, f32, f32)> {
    let bvh = Bvh::build(tris.to_vec());
    let (lo, hi) = bvh.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
    let size = hi - lo;
    let mut rng = Rng::new(seed);
    let v3 = |rng: &mut Rng| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
    (0..n)
        .map(|i| {
            // Origins in (a margin around) the bounds, or on a triangle (secondary rays).
            let o = if i % 3 == 0 && !tris.is_empty() {
                let t = &tris[(rng.next_u64() % tris.len() as u64) as usize];
                let (a, b) = (rng.next_f32(), rng.next_f32());
                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                t.p[0] + (t.p[1] - t.p[0]) * a + (t.p[2] - t.p[0]) * b
            } else {
                lo - size * 0.1 + v3(&mut rng) * size * 1.2
            };
            // Unnormalised directions of various lengths.
            let d = (v3(&mut rng) - 0.5) * (0.2 + 3.0 * rng.next_f32());
            let (tmin, tmax) = match i % 4 {
                0 => (0.0, f32::INFINITY),
                1 => (1e-4, size.length() * rng.next_f32()),
                2 => (size.length() * 0.2 * rng.next_f32(), f32::INFINITY),
                _ => (0.0, 0.05 * size.length()), // short (AO-like) rays
            };
            (o, d, tmin, tmax)
        })
        .collect()
}

#[test]
fn backends_agree_on_random_rays_in_builtin_scenes() {
    for (name, n) in [
        ("cornell", 3000),
        ("atrium", 3000),
        ("warehouse", 2000),
        ("column-wall", 2000),
        ("dense", 1500),
    ] {
        let tris = builtin(name);
        let rays = random_rays(&tris, n, 7);
        let hits = compare(name, &tris, &rays);
        assert!(hits > n / 10, "{name}: only {hits} of {n} rays hit");
    }
}

#[test]
fn backends_agree_on_a_random_soup() {
    let mut rng = Rng::new(42);
    let v3 = |rng: &mut Rng| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
    let tris: Vec<_> = (0..3000)
        .map(|_| {
            let c = v3(&mut rng) * 10.0;
            let s = 0.3 + 4.0 * rng.next_f32();
            tri([c, c + (v3(&mut rng) - 0.5) * s, c + (v3(&mut rng) - 0.5) * s])
        })
        .collect();
    let rays = random_rays(&tris, 4000, 3);
    compare("soup", &tris, &rays);
}

/// Rays aimed exactly at the vertices and edge midpoints of scene triangles
/// (shared by 2–6 triangles of closed meshes: boxes, cylinders).
#[test]
fn backends_agree_on_rays_through_shared_edges_and_vertices() {
    for name in ["cornell", "dense", "column-wall"] {
        let tris = builtin(name);
        let mut rng = Rng::new(11);
        let (lo, hi) = Bvh::build(tris.clone()).bounds().expect("non-empty scene");
        let mut rays = Vec::new();
        for k in 0..1500 {
            let t = &tris[(rng.next_u64() % tris.len() as u64) as usize];
            let target = match k % 3 {
                0 => t.p[k % 3 / 3],
                1 => 0.5 * (t.p[0] + t.p[1]),
                _ => t.p[2],
            };
            let eye = lo + (hi - lo) * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            rays.push((eye, target - eye, 0.0, f32::INFINITY));
            rays.push((eye, target - eye, 0.0, 1.0)); // ends exactly at the vertex/edge
        }
        compare(name, &tris, &rays);
    }
}

/// A closed cube of 2×2 quads per face (shared edges and vertices everywhere):
/// rays from inside aimed at every vertex and edge midpoint never leak, in any backend.
#[test]
fn closed_mesh_never_leaks_in_any_backend() {
    let mut tris = Vec::new();
    let n = 2;
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            for i in 0..n {
                for j in 0..n {
                    let p = |a: usize, b: usize| {
                        let (u, v) = (
                            (i + a) as f32 / n as f32 * 2.0 - 1.0,
                            (j + b) as f32 / n as f32 * 2.0 - 1.0,
                        );
                        let mut q = [0.0; 3];
                        q[axis] = side;
                        q[(axis + 1) % 3] = u;
                        q[(axis + 2) % 3] = v;
                        Vec3::from(q)
                    };
                    tris.push(tri([p(0, 0), p(1, 0), p(1, 1)]));
                    tris.push(tri([p(0, 0), p(1, 1), p(0, 1)]));
                }
            }
        }
    }
    let (bvh, others) = backends(&tris);
    let mut targets = Vec::new();
    for t in &tris {
        targets.extend([
            t.p[0],
            t.p[1],
            t.p[2],
            0.5 * (t.p[0] + t.p[1]),
            0.5 * (t.p[1] + t.p[2]),
            0.5 * (t.p[2] + t.p[0]),
        ]);
    }
    for eye in [Vec3::ZERO, Vec3::new(0.1, -0.3, 0.25), Vec3::new(-0.7, 0.6, 0.01)] {
        for &target in &targets {
            let d = target - eye;
            let want = bvh
                .intersect(eye, d, 0.0, f32::INFINITY)
                .expect("binary: closed cube leaks");
            for (name, t) in &others {
                let got = t.intersect(eye, d, 0.0, f32::INFINITY);
                assert!(same_hit(got, Some(want)), "{name}: {got:?} vs {want:?}");
                assert!(t.occluded(eye, d, 0.0, 2.0), "{name}: leak");
            }
        }
    }
}

/// Axis-aligned rays (two or one zero direction components) in scenes full of
/// axis-aligned geometry, including rays lying in wall planes.
#[test]
fn backends_agree_on_rays_with_zero_direction_components() {
    for name in ["cornell", "atrium", "warehouse"] {
        let tris = builtin(name);
        let (lo, hi) = Bvh::build(tris.clone()).bounds().expect("non-empty scene");
        let mut rng = Rng::new(5);
        let mut rays = Vec::new();
        for k in 0..1200 {
            let mut o = lo + (hi - lo) * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            if k % 5 == 0 {
                // In a bounding plane of the scene (a wall, the floor).
                let a = k % 3;
                o[a] = if k % 2 == 0 { lo[a] } else { hi[a] };
            }
            let mut d = Vec3::ZERO;
            let a = k % 3;
            d[a] = if k % 2 == 0 { 1.0 } else { -0.5 };
            if k % 4 == 1 {
                d[(a + 1) % 3] = rng.next_f32() - 0.5; // one zero component
            }
            if k % 7 == 3 {
                d[(a + 1) % 3] = -0.0; // a negative zero
            }
            rays.push((o, d, 0.0, f32::INFINITY));
        }
        compare(name, &tris, &rays);
    }
}

/// The open interval `tmin < t < tmax`: a hit at exactly tmin or tmax is
/// excluded, one ulp inside is included, in every backend.
#[test]
fn backends_agree_on_tmin_tmax_boundaries() {
    let tris = builtin("atrium");
    let (bvh, _) = backends(&tris);
    let base = random_rays(&tris, 1500, 9);
    let mut rays = Vec::new();
    let mut checked = 0;
    for &(o, d, _, _) in &base {
        let Some(h) = bvh.intersect(o, d, 0.0, f32::INFINITY) else {
            continue;
        };
        let t = h.t;
        let up = f32::from_bits(t.to_bits() + 1);
        let down = f32::from_bits(t.to_bits() - 1);
        rays.extend([
            (o, d, 0.0, t),
            (o, d, 0.0, up),
            (o, d, t, f32::INFINITY),
            (o, d, down, up),
            (o, d, t, t),
        ]);
        // The exact semantics, on the binary BVH (the others are compared below).
        assert!(bvh.intersect(o, d, 0.0, t).is_none_or(|g| g.t < t));
        assert!(bvh.intersect(o, d, 0.0, up).is_some_and(|g| g.t <= t));
        assert!(bvh.intersect(o, d, t, f32::INFINITY).is_none_or(|g| g.t > t));
        checked += 1;
    }
    assert!(checked > 300);
    compare("atrium boundaries", &tris, &rays);
}

/// Equal-t ties: duplicated and coplanar overlapping triangles at different
/// indices; the closest hit goes to the lowest index in every backend.
#[test]
fn backends_agree_on_equal_t_ties() {
    let mut tris = Vec::new();
    let mut rng = Rng::new(3);
    for k in 0..400 {
        let c = Vec3::new(rng.next_f32() * 20.0, rng.next_f32() * 4.0, rng.next_f32() * 20.0);
        let t = tri([c, c + Vec3::new(1.0, 0.0, 0.0), c + Vec3::new(0.0, 0.0, 1.0)]);
        tris.push(t);
        if k % 2 == 0 {
            tris.push(t); // exact duplicate, higher index
        }
        if k % 3 == 0 {
            // Coplanar, overlapping, different shape.
            tris.push(tri([
                c - Vec3::new(0.2, 0.0, 0.2),
                c + Vec3::new(0.8, 0.0, 0.1),
                c + Vec3::new(0.1, 0.0, 0.9),
            ]));
        }
    }
    // Insert duplicates in front of the originals too (the lower index is the copy).
    let mut extra: Vec<_> = tris.iter().step_by(5).copied().collect();
    extra.append(&mut tris);
    let tris = extra;
    let (bvh, _) = backends(&tris);
    let mut rays = Vec::new();
    for _ in 0..3000 {
        let o = Vec3::new(rng.next_f32() * 20.0, 6.0, rng.next_f32() * 20.0);
        rays.push((
            o,
            Vec3::new(rng.next_f32() - 0.5, -1.0, rng.next_f32() - 0.5),
            0.0,
            f32::INFINITY,
        ));
        rays.push((o, Vec3::new(0.0, -1.0, 0.0), 0.0, f32::INFINITY));
    }
    let mut ties = 0;
    let mut all = Vec::new();
    for &(o, d, tmin, tmax) in &rays {
        bvh.intersect_all(o, d, tmin, tmax, &mut all);
        if all.len() >= 2 && all[0].t == all[1].t {
            ties += 1;
            assert_eq!(
                bvh.intersect(o, d, tmin, tmax).map(|h| h.triangle),
                Some(all[0].triangle)
            );
        }
    }
    assert!(ties > 100, "only {ties} tied rays");
    compare("ties", &tris, &rays);
}

#[test]
fn backends_agree_on_empty_and_degenerate_scenes() {
    let rays = |n: usize| -> Vec<(Vec3, Vec3, f32, f32)> {
        let mut rng = Rng::new(1);
        (0..n)
            .map(|_| {
                let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - 2.0;
                let d = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
                (o, d, 0.0, f32::INFINITY)
            })
            .collect()
    };
    // Empty.
    for kind in TracerKind::ALL {
        let t = AnyTracer::build(Vec::new(), kind);
        assert!(t.intersect(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY).is_none());
        assert!(!t.occluded(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY));
        let mut all = vec![Hit {
            t: 1.0,
            triangle: 0,
            b1: 0.0,
            b2: 0.0,
        }];
        t.intersect_all(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY, &mut all);
        assert!(all.is_empty());
        assert!(t.bounds().is_none());
    }
    compare("empty", &[], &rays(10));
    // Degenerate: zero-area (collinear, repeated vertices), non-finite vertices,
    // many identical triangles, a single triangle, plus a few regular ones.
    let base = tri([
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ]);
    let mut tris = vec![base; 40];
    tris.push(tri([Vec3::ONE; 3]));
    tris.push(tri([Vec3::ZERO, Vec3::X, Vec3::X * 2.0]));
    tris.push(tri([Vec3::splat(f32::NAN), Vec3::X, Vec3::Y]));
    tris.push(tri([Vec3::new(f32::INFINITY, 0.0, 0.0), Vec3::X, Vec3::Y]));
    tris.push(tri([
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
    ]));
    compare("degenerate", &tris, &rays(2000));
    compare("single", &[base], &rays(500));
    // Bad rays: non-finite origin or direction, zero direction, tmin > tmax, NaN range.
    let bad = [
        (Vec3::splat(f32::NAN), Vec3::Z, 0.0, f32::INFINITY),
        (
            Vec3::new(0.0, 0.0, -2.0),
            Vec3::new(f32::INFINITY, 0.0, 1.0),
            0.0,
            f32::INFINITY,
        ),
        (Vec3::new(0.0, 0.0, -2.0), Vec3::ZERO, 0.0, f32::INFINITY),
        (Vec3::new(0.0, 0.0, -2.0), Vec3::Z, 3.0, 1.0),
        (Vec3::new(0.0, 0.0, -2.0), Vec3::Z, f32::NAN, f32::INFINITY),
        (Vec3::new(0.0, 0.0, -2.0), Vec3::Z, 0.0, f32::NAN),
        (Vec3::new(0.0, 0.0, -2.0), Vec3::Z, f32::NEG_INFINITY, f32::INFINITY),
    ];
    compare("bad rays", &tris, &bad);
}

/// Whole oracles: the default (wide) reference renders bitwise the images of
/// the binary one.
#[test]
fn reference_images_identical_across_backends() {
    for name in ["cornell", "atrium"] {
        let scene = strata_scene::procedural::builtin(name).expect("built-in scene");
        let a = Reference::new(&scene, 0.0);
        assert_eq!(a.tracer_kind(), TracerKind::Wide);
        let b = Reference::with_tracer(&scene, 0.0, TracerKind::Binary);
        assert_eq!(a.epsilon().to_bits(), b.epsilon().to_bits());
        let cam = a.camera();
        let r = scene.settings.ao_radius;
        let ao = AoBinarySettings {
            spp: 16,
            ..AoBinarySettings::new(r)
        };
        assert_eq!(
            a.ao_binary(&cam, 32, 24, &ao).data,
            b.ao_binary(&cam, 32, 24, &ao).data,
            "{name}: AO"
        );
        let ob = ObscuranceSettings {
            spp: 8,
            ..ObscuranceSettings::new(r)
        };
        assert_eq!(
            a.ao_obscurance(&cam, 32, 24, &ob).data,
            b.ao_obscurance(&cam, 32, 24, &ob).data,
            "{name}: DGB"
        );
        let gi = strata_reference::GiSettings {
            spp: 2,
            bounces: 2,
            ..Default::default()
        };
        let (ga, gb) = (a.gi(&cam, 24, 16, &gi), b.gi(&cam, 24, 16, &gi));
        assert_eq!(ga.total.data, gb.total.data, "{name}: GI");
        let ls = LayerSettings::new(2, scene.settings.min_separation);
        let (la, lb) = (a.layers(&cam, 32, 24, &ls), b.layers(&cam, 32, 24, &ls));
        assert_eq!(format!("{la:?}"), format!("{lb:?}"), "{name}: layers");
    }
}

/// Regression: rays with zero direction components lying exactly in a box face
/// plane (here from the centre of a closed cube to its vertices: direction
/// (−1, 0, −1) runs in the plane y = 0 that bounds half the faces' boxes). The
/// binary BVH once replaced 1/0 by 1e30, which turned "in the slab plane" into
/// "leaves the slab at t = 0" and lost hits; every backend must now list exactly
/// the brute-force hits.
#[test]
fn rays_in_box_face_planes_find_every_hit() {
    let mut tris = Vec::new();
    let n = 2;
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            for i in 0..n {
                for j in 0..n {
                    let p = |a: usize, b: usize| {
                        let (u, v) = (
                            (i + a) as f32 / n as f32 * 2.0 - 1.0,
                            (j + b) as f32 / n as f32 * 2.0 - 1.0,
                        );
                        let mut q = [0.0; 3];
                        q[axis] = side;
                        q[(axis + 1) % 3] = u;
                        q[(axis + 2) % 3] = v;
                        Vec3::from(q)
                    };
                    tris.push(tri([p(0, 0), p(1, 0), p(1, 1)]));
                    tris.push(tri([p(0, 0), p(1, 1), p(0, 1)]));
                }
            }
        }
    }
    let tracers: Vec<(&str, Box<dyn Tracer>)> = vec![
        ("binary", Box::new(Bvh::build(tris.clone()))),
        ("wide", Box::new(WideBvh::build(tris.clone()))),
        ("wide portable", Box::new(WideBvh::build(tris.clone()).with_simd(false))),
    ];
    let mut all = Vec::new();
    let mut checked = 0;
    for t in &tris {
        for target in [t.p[0], t.p[1], t.p[2], 0.5 * (t.p[0] + t.p[1])] {
            let d = target;
            let mut brute: Vec<Hit> = tris
                .iter()
                .enumerate()
                .filter_map(|(i, t)| {
                    strata_reference::bvh::intersect_triangle(&t.p, Vec3::ZERO, d, 0.0, f32::INFINITY).map(|h| Hit {
                        triangle: i as u32,
                        ..h
                    })
                })
                .collect();
            brute.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.triangle.cmp(&b.triangle)));
            for (name, tr) in &tracers {
                tr.intersect_all(Vec3::ZERO, d, 0.0, f32::INFINITY, &mut all);
                assert!(
                    same_list(&all, &brute),
                    "{name}: d {d:?}: {all:?} vs brute force {brute:?}"
                );
                assert!(
                    same_hit(tr.intersect(Vec3::ZERO, d, 0.0, f32::INFINITY), brute.first().copied()),
                    "{name}: d {d:?}"
                );
            }
            checked += 1;
        }
    }
    assert_eq!(checked, tris.len() * 4);
}

/// Bundles of up to 8 rays from one origin ([`strata_reference::bundle`]) get
/// exactly the per-ray occlusion answers of the binary BVH: coherent bundles
/// (a narrow cone in one octant, the AO case), wide bundles, bundles that mix
/// octants or hold a zero component (traced ray by ray), origins on
/// triangles (AO-like) and in free space, short and unbounded ranges, and
/// every bundle size 1..=8.
#[test]
fn bundles_answer_exactly_like_single_rays() {
    use strata_reference::bundle::{same_octant, BUNDLE};
    let soup = {
        let mut rng = Rng::new(42);
        let v3 = |rng: &mut Rng| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        (0..3000)
            .map(|_| {
                let c = v3(&mut rng) * 10.0;
                let s = 0.3 + 4.0 * rng.next_f32();
                tri([c, c + (v3(&mut rng) - 0.5) * s, c + (v3(&mut rng) - 0.5) * s])
            })
            .collect::<Vec<_>>()
    };
    let scenes = [
        ("cornell", builtin("cornell")),
        ("atrium", builtin("atrium")),
        ("column-wall", builtin("column-wall")),
        ("soup", soup),
    ];
    for (name, tris) in &scenes {
        let bvh = Bvh::build(tris.clone());
        let wide = WideBvh::build(tris.clone());
        let any = AnyTracer::build(tris.clone(), TracerKind::Wide);
        let size = {
            let (lo, hi) = bvh.bounds().unwrap();
            (hi - lo).length()
        };
        let mut rng = Rng::new(11);
        let (mut bundled, mut occluded, mut total) = (0usize, 0usize, 0usize);
        for (i, (o, _, tmin, tmax)) in random_rays(tris, 1500, 5).into_iter().enumerate() {
            let v3 = |rng: &mut Rng| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
            let axis = v3(&mut rng).normalize_or(Vec3::X);
            // Cone half-width: narrow (AO bundles), medium, or the whole sphere.
            let spread = [0.05, 0.3, 2.0][i % 3];
            let len = 1 + i % BUNDLE;
            let mut dirs: Vec<Vec3> = (0..len)
                .map(|_| (axis + v3(&mut rng) * spread) * (0.5 + rng.next_f32()))
                .collect();
            if i % 17 == 0 {
                dirs[0].y = 0.0; // a zero component: ray by ray
            }
            let tmax = if i % 2 == 0 { tmax } else { 0.05 * size * rng.next_f32() };
            bundled += same_octant(&dirs) as usize;
            let want = dirs
                .iter()
                .enumerate()
                .fold(0u32, |m, (j, &d)| m | (bvh.occluded(o, d, tmin, tmax) as u32) << j);
            assert_eq!(
                wide.occluded_bundle(o, &dirs, tmin, tmax),
                want,
                "{name}: bundle {i} ({dirs:?})"
            );
            assert_eq!(
                any.occluded_bundle(o, &dirs, tmin, tmax),
                want,
                "{name}: AnyTracer bundle {i}"
            );
            assert_eq!(
                Tracer::occluded_bundle(&bvh, o, &dirs, tmin, tmax),
                want,
                "{name}: binary bundle {i}"
            );
            occluded += want.count_ones() as usize;
            total += len;
        }
        // The property is only meaningful if bundles ran and rays both hit and missed.
        assert!(bundled > 300, "{name}: only {bundled} bundles qualified");
        assert!(
            occluded > total / 20 && occluded < total * 19 / 20,
            "{name}: {occluded} of {total} occluded"
        );
    }
}

/// The binary-AO oracle traces its samples in bundles from 16 samples per
/// pixel on (sorted by direction); its images stay bitwise those of the
/// binary BVH traced ray by ray, for sample counts on both sides of that
/// threshold and over more than one chunk of 1,024.
#[test]
fn bundled_ao_images_identical_across_backends() {
    for name in ["cornell", "column-wall"] {
        let scene = strata_scene::procedural::builtin(name).expect("built-in scene");
        let a = Reference::new(&scene, 0.0);
        let b = Reference::with_tracer(&scene, 0.0, TracerKind::Binary);
        let cam = a.camera();
        for spp in [15, 16, 200, 1100] {
            let ao = AoBinarySettings {
                spp,
                ..AoBinarySettings::new(scene.settings.ao_radius)
            };
            let (ia, ib) = (a.ao_binary(&cam, 16, 12, &ao), b.ao_binary(&cam, 16, 12, &ao));
            assert_eq!(ia.data, ib.data, "{name}: AO at {spp} spp");
            let mean = ia.data.iter().sum::<f32>() / ia.data.len() as f32;
            assert!(
                mean > 0.3 && mean < 0.999,
                "{name}: mean AV {mean} (no occlusion tested)"
            );
        }
    }
}
