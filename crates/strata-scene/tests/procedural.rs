//! Built-in procedural scenes: geometry sanity, cameras, lights, and the
//! occlusion set-ups the deep G-buffer experiments rely on.

mod common;

use common::{in_frustum, occluded, samples_facing};
use glam::Vec3;
use strata_scene::procedural::{builtin, BUILTIN_NAMES};
use strata_scene::{load_scene, Light, Scene};

const ASPECT: f32 = 16.0 / 9.0;

fn scene(name: &str) -> Scene {
    builtin(name).unwrap_or_else(|| panic!("builtin {name} missing"))
}

#[test]
fn builtin_names_are_exactly_the_five() {
    for n in ["cornell", "atrium", "warehouse", "plane", "column-wall"] {
        assert!(BUILTIN_NAMES.contains(&n), "{n}");
    }
    for &n in BUILTIN_NAMES {
        assert!(builtin(n).is_some(), "{n} listed but not built");
        assert_eq!(load_scene(n).expect("load_scene by name").name, n);
    }
    assert!(builtin("nope").is_none());
}

#[test]
fn every_builtin_is_well_formed() {
    for &name in BUILTIN_NAMES {
        let s = scene(name);
        assert!(!s.objects.is_empty(), "{name}: no objects");
        assert!(s.triangle_count() > 0, "{name}: no triangles");
        // Test scenes stay small; `dense` is the ≥ 1 M-triangle benchmark scene.
        let limit = if name == "dense" { 1_100_000 } else { 100_000 };
        assert!(s.triangle_count() < limit, "{name}: {} triangles", s.triangle_count());
        if name == "dense" {
            assert!(
                s.triangle_count() >= 1_000_000,
                "dense: {} triangles",
                s.triangle_count()
            );
        }
        for m in &s.meshes {
            assert_eq!(m.normals.len(), m.positions.len(), "{name}/{}: normals", m.name);
            assert_eq!(m.uvs.len(), m.positions.len(), "{name}/{}: uvs", m.name);
            assert_eq!(m.indices.len() % 3, 0, "{name}/{}", m.name);
            assert!(m.material < s.materials.len(), "{name}/{}: material index", m.name);
            assert!(
                m.indices.iter().all(|&i| (i as usize) < m.positions.len()),
                "{name}/{}: index range",
                m.name
            );
            assert!(
                m.positions.iter().flatten().all(|x| x.is_finite()),
                "{name}/{}: positions",
                m.name
            );
            assert!(m.uvs.iter().flatten().all(|x| x.is_finite()), "{name}/{}: uvs", m.name);
            for n in &m.normals {
                let l = Vec3::from(*n).length();
                assert!((l - 1.0).abs() < 1e-4, "{name}/{}: normal length {l}", m.name);
            }
            // Flat faces: the winding agrees with the vertex normals.
            for t in m.indices.chunks_exact(3) {
                let p = |k: usize| Vec3::from(m.positions[t[k] as usize]);
                let g = (p(1) - p(0)).cross(p(2) - p(0));
                if g.length() > 1e-9 {
                    let avg: Vec3 = t.iter().map(|&i| Vec3::from(m.normals[i as usize])).sum();
                    assert!(
                        g.dot(avg) > 0.0,
                        "{name}/{}: triangle {t:?} winding disagrees with normals",
                        m.name
                    );
                }
            }
        }
        for o in &s.objects {
            assert!(o.mesh < s.meshes.len());
            assert!(o.transform.is_finite());
        }
        s.camera.validate().unwrap_or_else(|e| panic!("{name}: camera: {e}"));
        assert!(!s.lights.is_empty(), "{name}: no light");
        let st = &s.settings;
        assert!(
            st.ao_radius > 0.0 && st.min_separation > 0.0 && st.exposure > 0.0,
            "{name}: settings {st:?}"
        );
        assert_eq!(
            s.world_triangles(0.0).len(),
            s.triangle_count(),
            "{name}: world_triangles count"
        );
        let (lo, hi) = s.bounds(0.0);
        assert!(
            lo.is_finite() && hi.is_finite() && (hi - lo).min_element() >= 0.0,
            "{name}: bounds"
        );
        // Every light is sensible.
        for l in &s.lights {
            match l {
                Light::Sun {
                    direction, illuminance, ..
                } => {
                    assert!((direction.length() - 1.0).abs() < 1e-5 && direction.y < 0.0 && *illuminance > 0.0)
                }
                Light::Point { intensity, .. } => assert!(*intensity > 0.0),
                Light::Spot {
                    direction,
                    intensity,
                    inner_deg,
                    outer_deg,
                    ..
                } => {
                    assert!((direction.length() - 1.0).abs() < 1e-5 && *intensity > 0.0 && inner_deg <= outer_deg)
                }
                Light::Rect {
                    half_u,
                    half_v,
                    radiance,
                    ..
                } => {
                    assert!(half_u.cross(*half_v).length() > 0.0 && radiance.iter().any(|&r| r > 0.0))
                }
            }
        }
    }
}

#[test]
fn cornell_matches_published_data() {
    let s = scene("cornell");
    let (lo, hi) = s.bounds(0.0);
    assert!(lo.abs_diff_eq(Vec3::ZERO, 1e-5), "{lo}");
    assert!(hi.abs_diff_eq(Vec3::new(0.556, 0.5488, 0.5592), 1e-5), "{hi}");
    assert_eq!(s.camera.eye, Vec3::new(0.278, 0.273, -0.8));
    assert!((s.camera.fov_y_deg - 39.3077).abs() < 1e-4);
    assert_eq!(s.settings.sky, [0.0; 3]);
    // Red on the x ≈ 0.556 side, green on x = 0.
    let side_x = |mat: &str| {
        let mi = s.materials.iter().position(|m| m.name == mat).unwrap() as u32;
        let tris: Vec<_> = s
            .world_triangles(0.0)
            .into_iter()
            .filter(|t| t.material == mi)
            .collect();
        assert!(!tris.is_empty());
        tris.iter().flat_map(|t| t.p).map(|p| p.x).sum::<f32>() / (3 * tris.len()) as f32
    };
    assert!(side_x("red") > 0.55 && side_x("green") < 1e-6);
    // The light: emissive quad facing down plus a matching Rect light.
    let light_mat = s.materials.iter().position(|m| m.is_emissive()).unwrap() as u32;
    let quad: Vec<_> = s
        .world_triangles(0.0)
        .into_iter()
        .filter(|t| t.material == light_mat)
        .collect();
    assert_eq!(quad.len(), 2);
    for t in &quad {
        assert!(t.n[0].y < -0.999);
        assert!(t.p.iter().all(|p| (p.y - 0.5487).abs() < 1e-6
            && (0.2129..=0.3431).contains(&p.x)
            && (0.2269..=0.3321).contains(&p.z)));
    }
    let Light::Rect {
        center,
        half_u,
        half_v,
        radiance,
    } = &s.lights[0]
    else {
        panic!("first light is not a rect")
    };
    assert_eq!(*radiance, [17.0, 12.0, 4.0]);
    assert!(half_u.cross(*half_v).normalize().abs_diff_eq(-Vec3::Y, 1e-6));
    assert!(center.abs_diff_eq(Vec3::new(0.278, 0.5487, 0.2795), 1e-6));
    assert!((4.0 * half_u.cross(*half_v).length() - 0.130 * 0.105).abs() < 1e-7);
    // The front (z = 0) is open: no triangle lies in the z = 0 plane, and the
    // camera's central ray enters the box without hitting anything before z = 0.
    let tris = s.world_triangles(0.0);
    assert!(!tris.iter().any(|t| t.p.iter().all(|p| p.z.abs() < 1e-6)));
    let first = tris
        .iter()
        .filter_map(|t| common::intersect(s.camera.eye, s.camera.forward(), t))
        .fold(f32::INFINITY, f32::min);
    assert!(first > 0.8 && first.is_finite(), "first hit at {first}");
}

#[test]
fn plane_is_the_analytic_test_scene() {
    let s = scene("plane");
    assert_eq!(s.triangle_count(), 2);
    assert_eq!(s.materials.len(), 1);
    assert_eq!(s.materials[0].base_color, [0.5; 3]);
    let (lo, hi) = s.bounds(0.0);
    assert!(lo.abs_diff_eq(Vec3::new(-20.0, 0.0, -20.0), 1e-5) && hi.abs_diff_eq(Vec3::new(20.0, 0.0, 20.0), 1e-5));
    let Light::Sun {
        direction,
        illuminance,
        color,
    } = &s.lights[0]
    else {
        panic!("not a sun")
    };
    assert!(direction.abs_diff_eq(Vec3::new(-0.4, -1.0, -0.2).normalize(), 1e-6));
    assert!((illuminance - std::f32::consts::PI).abs() < 1e-6 && *color == [1.0; 3]);
    assert_eq!(s.lights.len(), 1);
    assert_eq!(s.settings.ambient, [0.0; 3]);
    // The whole view (16:9) sees the plane: all four corner rays hit it.
    let tris = s.world_triangles(0.0);
    for (x, y) in [(0, 0), (1599, 0), (0, 899), (1599, 899)] {
        let d = s.camera.pixel_dir(x, y, 1600, 900);
        assert!(
            tris.iter().any(|t| common::intersect(s.camera.eye, d, t).is_some()),
            "corner ({x},{y}) misses the plane"
        );
    }
    // Oblique, not head-on.
    assert!(s.camera.forward().y.abs() < 0.9 && s.camera.forward().y < -0.3);
}

#[test]
fn atrium_has_path_animation_and_open_roof() {
    let s = scene("atrium");
    let (lo, hi) = s.bounds(0.0);
    let size = hi - lo;
    assert!(
        (29.0..32.0).contains(&size.x) && (13.0..16.0).contains(&size.z) && (13.0..15.0).contains(&size.y),
        "{size}"
    );
    let path = s.camera_path.as_ref().expect("camera path");
    assert!((4..=6).contains(&path.keyframes.len()));
    assert_eq!(path.first_frame(), 0.0);
    assert!((100.0..=140.0).contains(&path.last_frame()));
    // Frame 0 of the path is the default camera.
    assert!(s.camera_at(0.0).eye.abs_diff_eq(s.camera.eye, 1e-6));
    // Fast lateral motion: ≥ 0.08 m per frame sideways (perpendicular to the view) on average.
    let mut lateral = 0.0;
    for f in 0..path.last_frame() as u32 {
        let (a, b) = (s.camera_at(f as f32), s.camera_at(f as f32 + 1.0));
        lateral += (b.eye - a.eye).dot(a.basis().0).abs();
    }
    assert!(
        lateral / path.last_frame() > 0.08,
        "lateral speed {}",
        lateral / path.last_frame()
    );
    // One animated object whose transform changes between frames 0 and 10.
    let animated: Vec<_> = s.objects.iter().filter(|o| o.animation.is_some()).collect();
    assert_eq!(animated.len(), 1);
    assert!(!animated[0]
        .transform_at(0.0)
        .abs_diff_eq(animated[0].transform_at(10.0), 1e-3));
    // ... and it is visible from the camera (its top is in view and unoccluded).
    let tris = s.world_triangles(0.0);
    let (alo, ahi) = {
        let m = &s.meshes[animated[0].mesh];
        let xf = animated[0].transform_at(0.0);
        m.positions.iter().map(|p| xf.transform_point3(Vec3::from(*p))).fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(l, h), p| (l.min(p), h.max(p)),
        )
    };
    let probe = Vec3::new(0.5 * (alo.x + ahi.x), 0.5 * (alo.y + ahi.y), alo.z - 1e-3);
    assert!(in_frustum(&s.camera, probe, ASPECT), "statue not in view");
    assert!(!occluded(&tris, s.camera.eye, probe, 1e-2), "statue hidden");
    // Open roof: a vertical ray from the court centre escapes; the sun reaches part of the floor.
    let up = |p: Vec3, d: Vec3| tris.iter().any(|t| common::intersect(p, d, t).is_some());
    assert!(!up(Vec3::new(0.0, 0.1, 0.0), Vec3::Y));
    let Light::Sun { direction, .. } = s.lights[0] else {
        panic!("sun")
    };
    let mut lit = 0;
    let mut total = 0;
    for i in 0..60 {
        for j in 0..28 {
            let p = Vec3::new(-14.75 + 0.5 * i as f32, 0.01, -6.75 + 0.5 * j as f32);
            total += 1;
            if !up(p, -direction) {
                lit += 1;
            }
        }
    }
    eprintln!("sunlit floor samples {lit}/{total}");
    assert!(
        lit * 20 > total && lit * 20 < 19 * total,
        "sunlit floor samples {lit}/{total}"
    );
    // The sun reaches part of the banners through the upper arcade.
    let banner_pts: Vec<Vec3> = ["banner_red", "banner_green", "banner_blue", "banner_yellow"]
        .iter()
        .flat_map(|c| samples_facing(&s, c, &s.camera, 3, 1e-3))
        .collect();
    let sunlit = banner_pts.iter().filter(|p| !up(**p, -direction)).count();
    eprintln!("sunlit banner samples {sunlit}/{}", banner_pts.len());
    assert!(
        sunlit * 10 > banner_pts.len(),
        "sunlit banner samples {sunlit}/{}",
        banner_pts.len()
    );
    assert!(s.settings.sky.iter().any(|&c| c > 0.0) && s.settings.sky[2] > s.settings.sky[0]);
}

/// The banners are in view but mostly hidden by the colonnade in the first
/// layer, and lie 1–3 m behind the column line.
#[test]
fn atrium_banners_hide_behind_columns() {
    let s = scene("atrium");
    let cam = s.camera;
    let tris = s.world_triangles(0.0);
    let mut in_view = 0;
    let mut total = 0;
    let mut visible = 0;
    for colour in ["banner_red", "banner_green", "banner_blue", "banner_yellow"] {
        let pts = samples_facing(&s, colour, &cam, 3, 1e-3);
        assert!(!pts.is_empty(), "{colour}");
        for p in pts {
            assert!(
                (1.0..=3.0).contains(&(p.z.abs() - 4.0)),
                "banner {p} not 1–3 m behind the columns"
            );
            total += 1;
            if in_frustum(&cam, p, ASPECT) {
                in_view += 1;
                if !occluded(&tris, cam.eye, p, 1e-2) {
                    visible += 1;
                }
            }
        }
    }
    eprintln!("banner samples: {total}, in view {in_view}, visible {visible}");
    // What hides them: the colonnade (columns, capitals, arch panels).
    let column = s.materials.iter().position(|m| m.name == "column").unwrap() as u32;
    let arcade = s.materials.iter().position(|m| m.name == "arcade").unwrap() as u32;
    let mut by_colonnade = 0;
    let mut hidden = 0;
    let mut by_mat = std::collections::BTreeMap::new();
    for colour in ["banner_red", "banner_green", "banner_blue", "banner_yellow"] {
        for p in samples_facing(&s, colour, &cam, 3, 1e-3) {
            if !in_frustum(&cam, p, ASPECT) {
                continue;
            }
            let d = p - cam.eye;
            let first = tris
                .iter()
                .filter_map(|t| common::intersect(cam.eye, d, t).map(|h| (h, t.material)))
                .filter(|(h, _)| *h < 1.0 - 1e-2 / d.length())
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((_, m)) = first {
                hidden += 1;
                *by_mat.entry(s.materials[m as usize].name.clone()).or_insert(0) += 1;
                if m == column || m == arcade {
                    by_colonnade += 1;
                }
            }
        }
    }
    eprintln!("hidden {hidden}: by colonnade {by_colonnade}; {by_mat:?}");
    assert!(
        by_colonnade as f32 >= 0.9 * hidden as f32,
        "banners hidden by other things: {by_mat:?}"
    );
    assert!(in_view >= 50, "too few banner samples in view: {in_view}");
    assert!(
        (visible as f32) < 0.35 * in_view as f32,
        "banners too visible: {visible}/{in_view}"
    );
}

/// The red patch is in the warehouse view but hidden by the partition, while
/// floor right next to it is visible.
#[test]
fn warehouse_red_patch_is_hidden_behind_partition() {
    let s = scene("warehouse");
    let cam = s.camera;
    let tris = s.world_triangles(0.0);
    let pts = samples_facing(&s, "red_patch", &cam, 12, 1e-3);
    assert!(pts.len() > 50);
    let in_view = pts.iter().filter(|p| in_frustum(&cam, **p, ASPECT)).count();
    let visible = pts
        .iter()
        .filter(|p| in_frustum(&cam, **p, ASPECT) && !occluded(&tris, cam.eye, **p, 1e-2))
        .count();
    eprintln!("red patch samples {}, in view {in_view}, visible {visible}", pts.len());
    assert!(in_view as f32 > 0.9 * pts.len() as f32, "red patch not in view");
    assert_eq!(visible, 0, "red patch visible in the first layer");
    // Floor within 1 m of the patch (on the camera side of the partition edge) is visible.
    let red = s.materials.iter().position(|m| m.name == "red_patch").unwrap() as u32;
    let (plo, phi) = tris.iter().filter(|t| t.material == red).flat_map(|t| t.p).fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(l, h), p| (l.min(p), h.max(p)),
    );
    let near_floor: Vec<Vec3> = (0..20)
        .map(|i| Vec3::new(plo.x + (phi.x - plo.x) * (i as f32 + 0.5) / 20.0, 1e-3, phi.z + 0.4))
        .collect();
    let seen = near_floor
        .iter()
        .filter(|p| in_frustum(&cam, **p, ASPECT) && !occluded(&tris, cam.eye, **p, 1e-2))
        .count();
    assert!(seen == 20, "floor next to the red patch not visible: {seen}/20");
    // The spot light points at the patch and is bright.
    let Light::Spot {
        position,
        direction,
        intensity,
        outer_deg,
        ..
    } = &s.lights[0]
    else {
        panic!("spot")
    };
    let centre = 0.5 * (plo + phi);
    assert!((centre - *position).normalize().dot(*direction) > 0.999);
    let radius = (position.y - centre.y) * outer_deg.to_radians().tan();
    assert!(radius < 0.6 * (phi.x - plo.x) + 0.1, "spot spills far beyond the patch");
    assert!(*intensity / (position.y * position.y) > 5.0);
}

#[test]
fn column_wall_column_occludes_wall() {
    let s = scene("column-wall");
    let cam = s.camera;
    let tris = s.world_triangles(0.0);
    // The column is in view and visible; part of the wall behind it is hidden.
    let col = samples_facing(&s, "column", &cam, 2, 1e-3);
    assert!(col
        .iter()
        .any(|p| in_frustum(&cam, *p, ASPECT) && !occluded(&tris, cam.eye, *p, 1e-2)));
    let wall_behind = Vec3::new(0.0, 1.5, -1.0 + 1e-3);
    assert!(in_frustum(&cam, wall_behind, ASPECT));
    assert!(
        occluded(&tris, cam.eye, wall_behind, 1e-2),
        "column should hide the wall behind it"
    );
    // Gap between column surface and wall is ~0.5 m.
    let colmat = s.materials.iter().position(|m| m.name == "column").unwrap() as u32;
    let back = tris
        .iter()
        .filter(|t| t.material == colmat)
        .flat_map(|t| t.p)
        .map(|p| p.z)
        .fold(f32::INFINITY, f32::min);
    assert!((back - (-1.0) - 0.5).abs() < 0.02, "gap {}", back + 1.0);
}

#[test]
fn glasshouse_has_coloured_glass_before_opaque_objects() {
    let s = scene("glasshouse");
    assert!(s.triangle_count() < 10_000, "{} triangles", s.triangle_count());
    let glass: Vec<_> = s.materials.iter().filter(|m| m.opacity < 1.0).collect();
    assert!(glass.len() >= 6, "{} transparent materials", glass.len());
    for m in &glass {
        assert!((0.25..=0.5).contains(&m.opacity), "{}: {}", m.name, m.opacity);
    }
    // Different colours: no two glass materials share a base colour.
    for (i, a) in glass.iter().enumerate() {
        for b in &glass[i + 1..] {
            assert_ne!(a.base_color, b.base_color, "{} vs {}", a.name, b.name);
        }
    }
    assert!(s.materials.iter().filter(|m| m.opacity == 1.0).count() >= 3);
    assert!(s.lights.iter().any(|l| matches!(l, Light::Sun { .. })));
    assert!(s.lights.iter().any(|l| matches!(l, Light::Point { .. })));
    // Every transparent object lies in view of the default camera.
    for o in &s.objects {
        let m = &s.materials[s.meshes[o.mesh].material];
        if m.opacity < 1.0 {
            let c: Vec3 = s.meshes[o.mesh].positions.iter().map(|p| Vec3::from(*p)).sum::<Vec3>()
                / s.meshes[o.mesh].positions.len() as f32;
            assert!(in_frustum(&s.camera, c, ASPECT), "{} at {c}", m.name);
        }
    }
}
