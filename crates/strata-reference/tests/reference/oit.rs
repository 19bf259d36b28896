//! A-buffer ground truth (ABA): crossings along primary rays, the OIT
//! shading model and compositing, AO with occluder and receiver opacity.

use glam::{Mat4, Vec3};
use strata_reference::oit::{composite_crossings, light_irradiance, rect_irradiance, shade};
use strata_reference::sampling::Rng;
use strata_reference::{AoBinarySettings, Reference};
use strata_scene::shapes::MeshBuilder;
use strata_scene::{Camera, Light, Material, Object, Scene, Texture};

use crate::scenes::{add_triangles, floor, quad, scene_with};

/// A two-sided-by-construction pane: a quad facing +Z at depth `z` (camera on +Z).
fn pane(z: f32, h: f32) -> [[Vec3; 3]; 2] {
    quad(Vec3::new(0.0, 0.0, z), Vec3::new(h, 0.0, 0.0), Vec3::new(0.0, h, 0.0))
}

/// Camera on the +Z axis looking at the origin (a 1×1 image's only pixel looks along −Z).
fn axis_camera(near: f32) -> Camera {
    Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0, near)
}

fn glass(name: &str, rgb: [f32; 3], opacity: f32) -> Material {
    Material {
        opacity,
        ..Material::diffuse(name, rgb)
    }
}

/// A scene of panes facing the camera, lit only by `ambient` (so L = albedo · ambient).
fn pane_scene(panes: &[(Material, f32)], ambient: [f32; 3], sky: [f32; 3]) -> Scene {
    let mut s = scene_with(panes.iter().map(|p| p.0.clone()).collect(), axis_camera(0.05));
    s.settings.ambient = ambient;
    s.settings.sky = sky;
    for (i, (_, z)) in panes.iter().enumerate() {
        add_triangles(&mut s, &format!("pane{i}"), &pane(*z, 2.0), i);
    }
    s
}

fn add_mesh(s: &mut Scene, name: &str, b: MeshBuilder, material: usize) {
    s.meshes.push(b.build(name, material));
    s.objects.push(Object {
        name: name.into(),
        mesh: s.meshes.len() - 1,
        transform: Mat4::IDENTITY,
        animation: None,
    });
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol * b.abs().max_element().max(1.0)
}

#[test]
fn glasshouse_centre_ray_crosses_every_pane_in_order() {
    let s = strata_scene::procedural::glasshouse();
    let r = Reference::new(&s, 0.0);
    let cam = s.camera;
    // The centre of a 9×9 image looks exactly at the camera target.
    let list = r.crossings(&cam, 4, 4, 9, 9);
    let names: Vec<&str> = list
        .iter()
        .map(|c| s.materials[c.material as usize].name.as_str())
        .collect();
    let want = [
        "glass_red",
        "glass_red",
        "glass_green",
        "glass_green",
        "glass_blue",
        "glass_blue",
        "glass_amber",
        "glass_amber",
        "glass_violet",
        "glass_violet",
        "glass_sphere",
        "glass_sphere",
        "block",
    ];
    assert!(names.len() >= want.len() && names[..want.len()] == want, "{names:?}");
    for (i, c) in list.iter().take(want.len()).enumerate() {
        // Thin boxes and the sphere: front face, then back face.
        assert_eq!(c.front_facing, i % 2 == 0, "crossing {i} ({})", names[i]);
        assert_eq!(c.alpha, s.materials[c.material as usize].opacity);
        // Normals face the camera whatever the facing.
        assert!(c.normal.dot(c.position - cam.eye) < 0.0, "crossing {i}");
        assert!(c.geometric_normal.dot(c.position - cam.eye) < 0.0, "crossing {i}");
        // depth is the camera-space z of the position.
        assert_eq!(c.depth, c.t);
        assert!((c.depth - cam.depth_of(c.position)).abs() <= 1e-5 * c.depth, "{c:?}");
    }
    assert!(list.windows(2).all(|w| w[0].depth <= w[1].depth));
    let transparent = list.iter().take_while(|c| c.alpha < 1.0).count();
    assert_eq!(transparent, 12, "≥ 8 transparent crossings before the block");
    // Over a whole (small) image, a good share of the pixels sees ≥ 8 transparent layers.
    let all = r.crossings_image(&cam, 48, 27);
    let deep = all
        .iter()
        .filter(|l| l.iter().filter(|c| c.alpha < 1.0).count() >= 8)
        .count();
    assert!(deep >= 48 * 27 / 10, "{deep} pixels with ≥ 8 transparent crossings");
    assert_eq!(all[13 * 48 + 24], r.crossings(&cam, 24, 13, 48, 27));
}

#[test]
fn crossings_are_clipped_at_the_near_plane() {
    let mut s = pane_scene(
        &[(glass("a", [0.5; 3], 0.5), 4.5), (glass("b", [0.5; 3], 0.5), 2.0)],
        [0.0; 3],
        [0.0; 3],
    );
    let r = Reference::new(&s, 0.0);
    assert_eq!(r.crossings(&s.camera, 0, 0, 1, 1).len(), 2);
    // The nearer pane is at camera depth 0.5: a near plane at 1 clips it.
    s.camera.near = 1.0;
    let r = Reference::new(&s, 0.0);
    let list = r.crossings(&s.camera, 0, 0, 1, 1);
    assert_eq!(list.len(), 1);
    assert!((list[0].depth - 3.0).abs() < 1e-5);
}

#[test]
fn a_ray_through_a_shared_edge_is_one_crossing() {
    // The 1×1 image's ray goes through the origin, on the quad's diagonal.
    let s = pane_scene(&[(glass("a", [0.5; 3], 0.5), 0.0)], [0.0; 3], [0.0; 3]);
    let r = Reference::new(&s, 0.0);
    let mut hits = Vec::new();
    let cam = s.camera;
    r.bvh()
        .intersect_all(cam.eye, cam.pixel_dir(0, 0, 1, 1), cam.near, f32::INFINITY, &mut hits);
    assert_eq!(hits.len(), 2, "both triangles report the diagonal");
    let list = r.crossings(&cam, 0, 0, 1, 1);
    assert_eq!(list.len(), 1);
    assert_eq!(list[0].triangle, hits[0].triangle.min(hits[1].triangle));
    // Two different surfaces at the same depth (another object) stay two crossings.
    let mut s2 = s.clone();
    add_triangles(&mut s2, "twin", &pane(0.0, 1.0), 0);
    let r2 = Reference::new(&s2, 0.0);
    assert_eq!(r2.crossings(&cam, 0, 0, 1, 1).len(), 2);
}

#[test]
fn mask_and_texture_alpha_decide_fragment_alpha() {
    let cam = axis_camera(0.05);
    let mut s = pane_scene(&[(glass("m", [0.5; 3], 0.4), 0.3)], [0.0; 3], [0.0; 3]);
    s.materials[0].alpha_cutoff = Some(0.5);
    assert!(
        Reference::new(&s, 0.0).crossings(&cam, 0, 0, 1, 1).is_empty(),
        "0.4 < cutoff 0.5: discarded"
    );
    s.materials[0].opacity = 0.6;
    let list = Reference::new(&s, 0.0).crossings(&cam, 0, 0, 1, 1);
    assert_eq!((list.len(), list[0].alpha), (1, 1.0), "kept MASK fragments are opaque");
    // BLEND with a texture whose alpha is 128/255: α = opacity × texture alpha,
    // and only when the material says its texture alpha is opacity.
    s.materials[0] = Material {
        base_color_texture: Some(0),
        texture_alpha: true,
        ..glass("t", [1.0; 3], 0.5)
    };
    s.textures.push(Texture {
        name: "half".into(),
        width: 1,
        height: 1,
        rgba8: vec![255, 255, 255, 128],
    });
    let a = Reference::new(&s, 0.0).crossings(&cam, 0, 0, 1, 1)[0].alpha;
    assert!((a - 0.5 * 128.0 / 255.0).abs() < 1e-6, "{a}");
    s.materials[0].texture_alpha = false;
    assert_eq!(Reference::new(&s, 0.0).crossings(&cam, 0, 0, 1, 1)[0].alpha, 0.5);
}

#[test]
fn one_pane_over_an_opaque_plane_composites_in_closed_form() {
    let amb = [0.5, 1.0, 2.0];
    let (a1, albedo1, albedo2) = (0.3f32, Vec3::new(0.9, 0.1, 0.2), Vec3::new(0.2, 0.6, 0.4));
    let s = pane_scene(
        &[
            (glass("pane", albedo1.into(), a1), 1.0),
            (Material::diffuse("wall", albedo2.into()), -1.0),
        ],
        amb,
        [5.0; 3],
    );
    let r = Reference::new(&s, 0.0);
    let img = r.composite(&s.camera, 1, 1);
    let (l1, l2) = (albedo1 * Vec3::from(amb), albedo2 * Vec3::from(amb));
    let want = a1 * l1 + (1.0 - a1) * l2; // the opaque wall hides the sky
    assert!(
        close(Vec3::from_slice(&img.data), want, 1e-6),
        "{:?} vs {want}",
        img.data
    );
}

#[test]
fn two_panes_in_both_orders_composite_in_closed_form() {
    let amb = [1.0; 3];
    let sky = Vec3::new(0.1, 0.2, 0.3);
    let (red, blue) = (glass("red", [0.9, 0.1, 0.1], 0.4), glass("blue", [0.1, 0.1, 0.9], 0.25));
    let l = |m: &Material| Vec3::from(m.base_color);
    for (front, back) in [(&red, &blue), (&blue, &red)] {
        let s = pane_scene(&[(front.clone(), 1.0), (back.clone(), -1.0)], amb, sky.into());
        let got = Vec3::from_slice(&Reference::new(&s, 0.0).composite(&s.camera, 1, 1).data);
        let (af, ab) = (front.opacity, back.opacity);
        let want = af * l(front) + (1.0 - af) * ab * l(back) + (1.0 - af) * (1.0 - ab) * sky;
        assert!(close(got, want, 1e-6), "{} first: {got} vs {want}", front.name);
    }
    // The order matters: the two composites differ.
    let s1 = pane_scene(&[(red.clone(), 1.0), (blue.clone(), -1.0)], amb, sky.into());
    let s2 = pane_scene(&[(blue.clone(), 1.0), (red.clone(), -1.0)], amb, sky.into());
    let c1 = Vec3::from_slice(&Reference::new(&s1, 0.0).composite(&s1.camera, 1, 1).data);
    let c2 = Vec3::from_slice(&Reference::new(&s2, 0.0).composite(&s2.camera, 1, 1).data);
    assert!((c1 - c2).abs().max_element() > 0.05);
}

#[test]
fn an_opaque_crossing_ends_the_list() {
    let amb = [1.0; 3];
    let wall = Material::diffuse("wall", [0.3, 0.5, 0.7]);
    let s = pane_scene(
        &[
            (glass("front", [0.8, 0.8, 0.1], 0.5), 1.0),
            (wall.clone(), 0.0),
            (glass("hidden", [1.0, 0.0, 0.0], 0.9), -1.0),
        ],
        amb,
        [9.0; 3],
    );
    let r = Reference::new(&s, 0.0);
    let list = r.crossings(&s.camera, 0, 0, 1, 1);
    assert_eq!(list.len(), 3, "crossings list every surface");
    let (c, t) = composite_crossings(&list, Vec3::splat(9.0));
    assert_eq!(t, 0.0);
    let want = 0.5 * Vec3::new(0.8, 0.8, 0.1) + 0.5 * Vec3::from(wall.base_color);
    assert!(close(c, want, 1e-6), "{c} vs {want}");
    // Many transparent layers: stops once T < 1e-4 (10 layers of α = 0.7 leave 0.3^10).
    let many: Vec<_> = (0..10)
        .map(|i| (glass("g", [1.0; 3], 0.7), 2.0 - 0.3 * i as f32))
        .collect();
    let s = pane_scene(&many, amb, [0.0; 3]);
    let list = Reference::new(&s, 0.0).crossings(&s.camera, 0, 0, 1, 1);
    assert_eq!(list.len(), 10);
    let (c, t) = composite_crossings(&list, Vec3::ZERO);
    assert!(
        (t - 0.3f32.powi(8)).abs() < 1e-9,
        "stopped after the 8th layer: T = {t}"
    );
    assert!((c.x - (1.0 - 0.3f32.powi(8))).abs() < 1e-5, "{c}");
}

#[test]
fn shading_model_matches_analytic_lights() {
    let x = Vec3::new(0.0, 0.0, 0.0);
    let n = Vec3::Y;
    let sun = Light::Sun {
        direction: Vec3::new(1.0, -1.0, 0.0), // 45°, not normalised on purpose
        color: [1.0, 0.5, 0.25],
        illuminance: 2.0,
    };
    let e = light_irradiance(&sun, x, n);
    assert!(
        close(
            e,
            Vec3::new(1.0, 0.5, 0.25) * 2.0 * std::f32::consts::FRAC_1_SQRT_2,
            1e-6
        ),
        "{e}"
    );
    assert_eq!(light_irradiance(&sun, x, -n), Vec3::ZERO);
    let point = Light::Point {
        position: Vec3::new(0.0, 2.0, 0.0),
        color: [1.0; 3],
        intensity: 8.0,
    };
    assert!(close(light_irradiance(&point, x, n), Vec3::splat(2.0), 1e-6));
    let spot = |dir: Vec3| Light::Spot {
        position: Vec3::new(0.0, 2.0, 0.0),
        direction: dir,
        color: [1.0; 3],
        intensity: 8.0,
        inner_deg: 20.0,
        outer_deg: 30.0,
    };
    assert!(
        close(light_irradiance(&spot(-Vec3::Y), x, n), Vec3::splat(2.0), 1e-6),
        "on the axis"
    );
    assert_eq!(
        light_irradiance(&spot(Vec3::new(1.0, -1.0, 0.0)), x, n),
        Vec3::ZERO,
        "45° off axis"
    );
    // Halfway between the cone angles: smoothstep(cos 30°, cos 20°, cos 25°).
    let axis = Vec3::new(25f32.to_radians().sin(), -25f32.to_radians().cos(), 0.0);
    let (c0, c1, c) = (
        30f32.to_radians().cos(),
        20f32.to_radians().cos(),
        25f32.to_radians().cos(),
    );
    let u = (c - c0) / (c1 - c0);
    let got = light_irradiance(&spot(axis), x, n).x;
    assert!((got - 2.0 * u * u * (3.0 - 2.0 * u)).abs() < 1e-5, "{got}");
    // L = emission + albedo·ambient + albedo/π·ΣE.
    let albedo = Vec3::new(0.5, 0.25, 1.0);
    let l = shade(&[sun.clone(), point.clone()], Vec3::splat(0.1), x, n, albedo, Vec3::X);
    let want =
        Vec3::X + albedo * 0.1 + albedo / std::f32::consts::PI * (light_irradiance(&sun, x, n) + Vec3::splat(2.0));
    assert!(close(l, want, 1e-6), "{l} vs {want}");
}

/// Monte Carlo irradiance per unit radiance of the rectangle `c ± hu ± hv`
/// (one-sided, normal `hu × hv`) at `p` with normal `n`, by uniform area sampling.
fn rect_irradiance_mc(p: Vec3, n: Vec3, c: Vec3, hu: Vec3, hv: Vec3, samples: u32) -> f64 {
    let nl = hu.cross(hv).normalize();
    let area = 4.0 * hu.cross(hv).length() as f64;
    let mut rng = Rng::new(7);
    let mut sum = 0.0f64;
    for _ in 0..samples {
        let [u, v] = rng.next_2d();
        let y = c + hu * (2.0 * u - 1.0) + hv * (2.0 * v - 1.0);
        let d = y - p;
        let d2 = d.length_squared() as f64;
        let w = d.normalize();
        let (cp, cl) = (n.dot(w).max(0.0) as f64, (-w).dot(nl).max(0.0) as f64);
        sum += cp * cl / d2;
    }
    sum * area / samples as f64
}

#[test]
fn rect_irradiance_matches_monte_carlo() {
    let (c, hu, hv) = (
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.5),
    );
    // normal hu × hv = −Y: the light faces down.
    let cases = [
        (Vec3::ZERO, Vec3::Y),                                 // below, facing it
        (Vec3::new(1.5, 0.0, 0.3), Vec3::new(-0.3, 1.0, 0.2)), // off to the side, tilted
        (Vec3::new(0.0, 1.9, 0.0), Vec3::X),                   // just below: half the light is behind
        (Vec3::new(0.7, 1.8, 0.1), Vec3::new(1.0, 0.3, 0.0)),  // clipped by the horizon
    ];
    for (p, n) in cases {
        let n = n.normalize();
        let exact = rect_irradiance(p, n, c, hu, hv, hu.cross(hv).normalize()) as f64;
        let mc = rect_irradiance_mc(p, n, c, hu, hv, 400_000);
        assert!(exact > 0.0);
        assert!(
            (exact - mc).abs() < 0.01 * mc + 1e-4,
            "p {p} n {n}: exact {exact} vs MC {mc}"
        );
    }
    // Behind the one-sided light, or facing away: nothing.
    let nl = hu.cross(hv).normalize();
    assert_eq!(rect_irradiance(Vec3::new(0.0, 3.0, 0.0), -Vec3::Y, c, hu, hv, nl), 0.0);
    assert_eq!(rect_irradiance(Vec3::ZERO, -Vec3::Y, c, hu, hv, nl), 0.0);
    // The light enters the crossings' radiance as radiance × F.
    let rect = Light::Rect {
        center: c,
        half_u: hu,
        half_v: hv,
        radiance: [2.0, 1.0, 0.0],
    };
    let f = rect_irradiance(Vec3::ZERO, Vec3::Y, c, hu, hv, nl);
    assert!(close(
        light_irradiance(&rect, Vec3::ZERO, Vec3::Y),
        Vec3::new(2.0, 1.0, 0.0) * f,
        1e-6
    ));
}

// ---------------------------------------------------------------- AO with opacity

fn ao_settings(radius: f32, spp: u32) -> AoBinarySettings {
    AoBinarySettings { radius, spp, seed: 3 }
}

#[test]
fn unoccluded_plane_has_visibility_one_in_both_models() {
    let mut s = scene_with(vec![glass("floor", [0.5; 3], 0.5)], axis_camera(0.05));
    add_triangles(&mut s, "floor", &floor(10.0), 0);
    let r = Reference::new(&s, 0.0);
    for (alpha, front) in [(1.0, true), (0.5, true), (0.5, false), (0.2, false)] {
        let ao = r.ao_with_opacity(Vec3::ZERO, Vec3::Y, Vec3::Y, alpha, front, &ao_settings(1.0, 64), 11);
        assert_eq!((ao.strongest, ao.transmittance), (1.0, 1.0), "α {alpha} front {front}");
    }
}

#[test]
fn with_every_alpha_one_both_models_equal_binary_ao_exactly() {
    let s = strata_scene::procedural::column_wall();
    let r = Reference::new(&s, 0.0);
    let set = ao_settings(s.settings.ao_radius, 24);
    let (w, h) = (24, 14);
    let binary = r.ao_binary(&s.camera, w, h, &set);
    let ours = r.ao_with_opacity_image(&s.camera, w, h, &set);
    let mut partial = 0;
    for i in 0..(w * h) as usize {
        let b = binary.data[i];
        assert_eq!(ours.data[3 * i], b, "strongest, pixel {i}");
        assert_eq!(ours.data[3 * i + 1], b, "transmittance, pixel {i}");
        partial += (b > 0.0 && b < 1.0) as u32;
    }
    assert!(partial > 20, "the comparison must include occluded pixels ({partial})");
}

/// Floor at y = 0 facing up, with a quad occluder of `material` above part of it.
fn floor_with_occluder(occluder: Material) -> Scene {
    let mut s = scene_with(vec![Material::diffuse("floor", [0.5; 3]), occluder], axis_camera(0.05));
    add_triangles(&mut s, "floor", &floor(10.0), 0);
    // A 0.6 × 0.6 square 0.3 above, off-centre: it covers part of the hemisphere.
    add_triangles(
        &mut s,
        "occluder",
        &quad(
            Vec3::new(0.2, 0.3, 0.0),
            Vec3::new(0.0, 0.0, 0.3),
            Vec3::new(0.3, 0.0, 0.0),
        ),
        1,
    );
    s
}

#[test]
fn a_single_occluder_of_opacity_alpha_darkens_by_alpha_times_opaque_occlusion() {
    let set = ao_settings(1.0, 256);
    let p = Vec3::new(0.0, 0.0, 0.0);
    let opaque = floor_with_occluder(Material::diffuse("occ", [0.5; 3]));
    let r = Reference::new(&opaque, 0.0);
    for key in [1u64, 99, 12345] {
        let v = r.ao_binary_at(p, Vec3::Y, Vec3::Y, &set, key);
        assert!(v > 0.2 && v < 0.95, "the occluder covers part of the hemisphere: {v}");
        for alpha in [0.25f32, 0.6] {
            let s = floor_with_occluder(glass("occ", [0.5; 3], alpha));
            let rs = Reference::new(&s, 0.0);
            let ao = rs.ao_with_opacity(p, Vec3::Y, Vec3::Y, 1.0, true, &set, key);
            let want = 1.0 - alpha * (1.0 - v);
            assert!(
                (ao.strongest - want).abs() < 1e-5,
                "α {alpha}: {} vs {want}",
                ao.strongest
            );
            assert!(
                (ao.transmittance - want).abs() < 1e-5,
                "α {alpha}: {} vs {want}",
                ao.transmittance
            );
        }
    }
}

#[test]
fn a_two_layer_stack_separates_the_two_models() {
    // Receiver at the centre of two concentric spheres of opacity α: every ray
    // crosses each shell exactly once within the radius.
    let alpha = 0.4f32;
    let mut s = scene_with(vec![glass("shell", [0.5; 3], alpha)], axis_camera(0.05));
    for (i, radius) in [0.5f32, 0.7].into_iter().enumerate() {
        let mut b = MeshBuilder::new();
        b.sphere(Vec3::ZERO, radius, 48, 24);
        add_mesh(&mut s, &format!("shell{i}"), b, 0);
    }
    let r = Reference::new(&s, 0.0);
    let ao = r.ao_with_opacity(Vec3::ZERO, Vec3::Y, Vec3::Y, 1.0, true, &ao_settings(1.0, 128), 5);
    assert!(
        (ao.strongest - (1.0 - alpha)).abs() < 1e-5,
        "strongest {}",
        ao.strongest
    );
    let want = (1.0 - alpha) * (1.0 - alpha); // 1 − occlusion 1 − (1 − α)²
    assert!(
        (ao.transmittance - want).abs() < 1e-5,
        "transmittance {}",
        ao.transmittance
    );
    // One shell: the models agree.
    s.objects.truncate(1);
    let r = Reference::new(&s, 0.0);
    let ao = r.ao_with_opacity(Vec3::ZERO, Vec3::Y, Vec3::Y, 1.0, true, &ao_settings(1.0, 128), 5);
    assert!((ao.strongest - (1.0 - alpha)).abs() < 1e-5 && (ao.transmittance - ao.strongest).abs() < 1e-6);
}

#[test]
fn a_transparent_receiver_combines_exterior_and_interior_ao_by_facing() {
    // Receiver on a plane at y = 0 (normal +Y towards the camera); an opaque
    // floor 0.2 below it occludes only the interior hemisphere (around −n).
    let mut s = scene_with(vec![Material::diffuse("under", [0.5; 3])], axis_camera(0.05));
    add_triangles(
        &mut s,
        "under",
        &quad(
            Vec3::new(0.0, -0.2, 0.0),
            Vec3::new(0.0, 0.0, 0.4),
            Vec3::new(0.4, 0.0, 0.0),
        ),
        0,
    );
    let r = Reference::new(&s, 0.0);
    let set = ao_settings(1.0, 256);
    let key = 77;
    let (n, p) = (Vec3::Y, Vec3::ZERO);
    let exterior = r.ao_binary_at(p, n, n, &set, key);
    let interior = r.ao_binary_at(p, -n, -n, &set, key);
    assert_eq!(exterior, 1.0);
    assert!(interior < 0.9, "{interior}");
    let alpha = 0.3f32;
    for (front, w) in [(true, alpha), (false, 1.0 - alpha)] {
        let ao = r.ao_with_opacity(p, n, n, alpha, front, &set, key);
        let want = w * exterior + (1.0 - w) * interior; // Eq. 3–4
        assert!(
            (ao.strongest - want).abs() < 1e-6,
            "front {front}: {} vs {want}",
            ao.strongest
        );
        assert!((ao.transmittance - want).abs() < 1e-6);
    }
}

#[test]
fn per_pixel_ao_blends_fragments_with_colour_weights() {
    // A pane of α over an opaque floor seen from above: the pixel's AO is
    // α · AO_pane + (1 − α) · AO_floor (the floor ends the list: T_n = 0).
    let alpha = 0.35f32;
    let cam = Camera::new(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO, Vec3::NEG_Z, 30.0, 0.05);
    let mut s = scene_with(
        vec![Material::diffuse("floor", [0.5; 3]), glass("pane", [0.5; 3], alpha)],
        cam,
    );
    add_triangles(&mut s, "floor", &floor(10.0), 0);
    add_triangles(
        &mut s,
        "pane",
        &quad(
            Vec3::new(0.05, 0.25, 0.03),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
        ),
        1,
    );
    let r = Reference::new(&s, 0.0);
    let set = ao_settings(1.0, 64);
    let img = r.ao_with_opacity_image(&cam, 3, 3, &set);
    let list = r.crossings(&cam, 1, 1, 3, 3);
    assert_eq!(list.len(), 2);
    let key0 = strata_reference::sampling::hash(&[set.seed, 3 + 1]);
    let key1 = strata_reference::sampling::hash(&[key0, 1]);
    let ao = |c: &strata_reference::Crossing, key| {
        r.ao_with_opacity(
            c.position,
            c.normal,
            c.geometric_normal,
            c.alpha,
            c.front_facing,
            &set,
            key,
        )
    };
    let (a0, a1) = (ao(&list[0], key0), ao(&list[1], key1));
    let want = alpha * a0.strongest + (1.0 - alpha) * a1.strongest;
    let px = &img.data[3 * 4..3 * 4 + 3];
    assert!((px[0] - want).abs() < 1e-6, "{} vs {want}", px[0]);
    assert!(a1.strongest < 0.99, "the pane occludes the floor");
    assert!((px[2] - 1.0).abs() < 1e-6, "coverage 1 over an opaque floor");
}

#[test]
fn dragon_glass_has_32_layers() {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    if !dir.is_dir() {
        strata_scene::skip::note_skip(
            "oit::dragon_glass_has_32_layers",
            &format!("../shared not found at {}", dir.display()),
        );
        return;
    }
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/dragon-glass.toml");
    let s = strata_scene::load::load_path(&path).expect("dragon-glass.toml");
    let r = Reference::new(&s, 0.0);
    let (w, h) = (64, 40);
    let all = r.crossings_image(&s.camera, w, h);
    let counts: Vec<usize> = all.iter().map(|l| l.iter().filter(|c| c.alpha < 1.0).count()).collect();
    let max = *counts.iter().max().unwrap();
    let deep = counts.iter().filter(|&&c| c >= 32).count();
    eprintln!(
        "dragon-glass: max {max} transparent crossings, {deep} of {} pixels with ≥ 32",
        w * h
    );
    assert!(max >= 32 && deep >= 3, "max {max}, {deep} pixels ≥ 32");
    assert!(all.iter().flatten().all(|c| c.alpha == 0.3 || c.alpha == 1.0));
}
