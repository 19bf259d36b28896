//! The screen-space oracle (`strata_reference::oracle`): its total is the path tracer's
//! indirect light, its variants nest, and its confidence is the form factor of what the
//! layers hold.

use glam::Vec3;
use strata_reference::oracle::{
    gathered_irradiance, paper_blend, OracleImages, ScreenOracleSettings, ORACLE_CHANNELS, ORACLE_VARIANTS,
};
use strata_reference::{Estimator, GiSettings, Reference};
use strata_scene::{Camera, ImageBuf, Material, Scene};

use crate::scenes::{add_triangles, quad, scene_with};

fn settings(radius: f32) -> ScreenOracleSettings {
    ScreenOracleSettings {
        gi: GiSettings {
            bounces: 3,
            seed: 7,
            russian_roulette: false,
            ..Default::default()
        },
        min_separation: 0.5,
        radius,
    }
}

fn means(sums: Vec<f64>, w: u32, h: u32, channels: u32, n: u32) -> ImageBuf {
    ImageBuf {
        width: w,
        height: h,
        channels,
        data: sums.iter().map(|s| (s / n as f64) as f32).collect(),
    }
}

/// The oracle traces the path tracer's own paths: with the same seed its total is
/// `Estimator::Gi`'s indirect light bit for bit (Cornell box, 3 bounces).
#[test]
fn oracle_total_is_the_path_tracers_indirect_light() {
    let scene = strata_scene::procedural::builtin("cornell").unwrap();
    let r = Reference::new(&scene, 0.0);
    let cam = r.camera();
    let s = settings(0.5);
    let (w, h) = (12, 10);
    let oracle = r.sample_sums(&cam, w, h, &Estimator::ScreenOracle(s), 0..16);
    let gi = r.sample_sums(&cam, w, h, &Estimator::Gi(s.gi), 0..16);
    let mut lit = 0;
    for (o, g) in oracle.chunks_exact(ORACLE_CHANNELS as usize).zip(gi.chunks_exact(6)) {
        assert_eq!(
            o[..3].iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            g[3..6].iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        lit += (o[0] > 0.0) as u32;
    }
    assert!(lit > 60, "{lit} of 120 pixels have indirect light");
}

/// What one layer sees, two layers see; what the radius bounds, the unbounded variant
/// sees; and no variant sees more light than the paths carry (the Cornell box and the
/// atrium, 16 paths per pixel).
#[test]
fn oracle_variants_nest() {
    for name in ["cornell", "atrium"] {
        let scene = strata_scene::procedural::builtin(name).unwrap();
        let r = Reference::new(&scene, 0.0);
        let cam = r.camera();
        let (w, h, n) = (16, 12, 16);
        let sums = r.sample_sums(&cam, w, h, &Estimator::ScreenOracle(settings(0.2)), 0..n);
        let img = OracleImages::from_means(&means(sums, w, h, ORACLE_CHANNELS, n));
        let v = |k, b| OracleImages::variant(k, b);
        let pairs = [
            (v(1, false), v(2, false)),
            (v(1, true), v(2, true)),
            (v(1, true), v(1, false)),
            (v(2, true), v(2, false)),
        ];
        let (mut strict_layers, mut strict_radius) = (0, 0);
        for i in 0..(w * h) as usize {
            let total = &img.total.data[3 * i..3 * i + 3];
            for var in 0..ORACLE_VARIANTS.len() {
                let c = img.confidence[var].data[i];
                assert!((0.0..=1.0).contains(&c), "{name} pixel {i}: c = {c}");
                for (seen, t) in img.seen[var].data[3 * i..3 * i + 3].iter().zip(total) {
                    assert!(*seen <= t * (1.0 + 1e-5) + 1e-7, "{name} pixel {i}: seen {seen} of {t}");
                }
            }
            for (a, b) in pairs {
                let (ca, cb) = (img.confidence[a].data[i], img.confidence[b].data[i]);
                assert!(ca <= cb, "{name} pixel {i}: variant {a} sees {ca}, variant {b} {cb}");
                for ch in 0..3 {
                    assert!(img.seen[a].data[3 * i + ch] <= img.seen[b].data[3 * i + ch] * (1.0 + 1e-5) + 1e-7);
                }
            }
            strict_layers += (img.confidence[v(2, false)].data[i] > img.confidence[v(1, false)].data[i]) as u32;
            strict_radius += (img.confidence[v(1, false)].data[i] > img.confidence[v(1, true)].data[i]) as u32;
        }
        // the nesting is not trivially an equality
        assert!(strict_radius > 0, "{name}: the radius never bounded a path");
        if name == "atrium" {
            assert!(strict_layers > 0, "{name}: the second layer never saw more");
        }
    }
}

/// The cosine-weighted share of the hemisphere a planar polygon covers from `x` with
/// normal `n` (its form factor; Lambert's formula), the polygon above x's horizon.
fn form_factor(x: Vec3, n: Vec3, poly: &[Vec3]) -> f32 {
    let mut sum = 0.0;
    for i in 0..poly.len() {
        let (a, b) = ((poly[i] - x).normalize(), (poly[(i + 1) % poly.len()] - x).normalize());
        let cross = a.cross(b);
        sum += a.dot(b).clamp(-1.0, 1.0).acos() * n.dot(cross.normalize());
    }
    (sum / (2.0 * std::f32::consts::PI)).abs()
}

/// A floor under a ceiling tile Q, seen from a camera below the tile. A blocker B near the
/// camera hides Q from it; Q is then the second layer (3 m behind B, Δz = 0.5). At every
/// floor pixel the oracle's c is the form factor of what the layers hold: F(B) with one
/// layer, F(B) + F(Q) with two, and F(Q) with one layer once the blocker is gone. A
/// radius shorter than the distance to either sees nothing.
#[test]
fn oracle_confidence_is_the_form_factor_of_what_the_layers_hold() {
    let tile = quad(
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 0.5),
        Vec3::new(0.5, 0.0, 0.0),
    );
    let blocker = quad(
        Vec3::new(0.0, 0.625, 3.0),
        Vec3::new(0.2, 0.0, 0.0),
        Vec3::new(0.0, 0.045, 0.0),
    );
    let corners = |q: &[[Vec3; 3]; 2]| vec![q[0][0], q[0][1], q[0][2], q[1][2]];
    let build = |with_blocker: bool| -> Scene {
        let camera = Camera::new(Vec3::new(0.0, 0.5, 4.0), Vec3::new(0.0, 0.3, 0.0), Vec3::Y, 40.0, 0.05);
        let mut scene = scene_with(vec![Material::default()], camera);
        add_triangles(
            &mut scene,
            "floor",
            &quad(Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0), Vec3::new(2.0, 0.0, 0.0)),
            0,
        );
        add_triangles(&mut scene, "tile", &tile, 0);
        if with_blocker {
            add_triangles(&mut scene, "blocker", &blocker, 0);
        }
        scene
    };
    let (w, h, n) = (32u32, 24u32, 1024u32);
    for with_blocker in [true, false] {
        let scene = build(with_blocker);
        let r = Reference::new(&scene, 0.0);
        let cam = r.camera();
        for radius in [0.5f32, 100.0] {
            let sums = r.sample_sums(&cam, w, h, &Estimator::ScreenOracle(settings(radius)), 0..n);
            let img = OracleImages::from_means(&means(sums, w, h, ORACLE_CHANNELS, n));
            let (mut floor_pixels, mut errors) = (0, 0.0f64);
            for py in 0..h {
                for px in 0..w {
                    let dir = cam.pixel_dir(px, py, w, h);
                    // the floor (y = 0) where the camera ray meets it first
                    let t = -cam.eye.y / dir.y;
                    let x = cam.eye + dir * t;
                    if !(dir.y < 0.0 && x.x.abs() < 1.9 && x.z.abs() < 1.9) {
                        continue;
                    }
                    floor_pixels += 1;
                    let (fq, fb) = (
                        form_factor(x, Vec3::Y, &corners(&tile)),
                        form_factor(x, Vec3::Y, &corners(&blocker)),
                    );
                    let i = (py * w + px) as usize;
                    let c = |k, b| img.confidence[OracleImages::variant(k, b)].data[i];
                    let (want1, want2) = match with_blocker {
                        true => (fb, fb + fq),
                        false => (fq, fq),
                    };
                    let at =
                        format!("blocker {with_blocker}, r {radius}, pixel ({px}, {py}), F(Q) {fq:.4}, F(B) {fb:.4}");
                    // the seen directions' SH moments: Y00 · c, and for the tile alone the
                    // y band, 0.4886 · ∫_Q ω_y cos θ / π dω = 0.4886 · ∫_Q h³ / (π r⁵) dA
                    let v1 = OracleImages::variant(1, false);
                    let sh = &img.seen_sh[v1].data[9 * i..9 * i + 9];
                    assert!(
                        (sh[0] - 0.282_095 * c(1, false)).abs() < 1e-5,
                        "{at}: Y00 moment {}",
                        sh[0]
                    );
                    if !with_blocker && radius > 1.0 {
                        let (steps, hh) = (100, 1.0f32);
                        let da = (1.0 / steps as f32).powi(2);
                        let mut want = 0.0;
                        for a in 0..steps {
                            for b in 0..steps {
                                let q = Vec3::new(
                                    -0.5 + (a as f32 + 0.5) / steps as f32,
                                    hh,
                                    -0.5 + (b as f32 + 0.5) / steps as f32,
                                );
                                let r = (q - x).length();
                                want += hh.powi(3) / (std::f32::consts::PI * r.powi(5)) * da;
                            }
                        }
                        assert!(
                            (sh[1] - 0.488_603 * want).abs() < 0.015,
                            "{at}: y-band moment {} against {}",
                            sh[1],
                            0.488_603 * want
                        );
                    }
                    if radius < 1.0 {
                        assert_eq!((c(1, true), c(2, true)), (0.0, 0.0), "{at}");
                    } else {
                        // 1024 paths per pixel: per-pixel errors up to about 0.011, mean 0
                        assert!(
                            (c(1, false) - want1).abs() < 0.025,
                            "{at}: c1 {} against {want1}",
                            c(1, false)
                        );
                        assert!(
                            (c(2, false) - want2).abs() < 0.025,
                            "{at}: c2 {} against {want2}",
                            c(2, false)
                        );
                        errors += (c(1, false) - want1) as f64 + (c(2, false) - want2) as f64;
                        assert_eq!(c(1, true), c(1, false), "{at}");
                    }
                }
            }
            assert!(floor_pixels > 150, "{floor_pixels} floor pixels");
            let bias = errors / (2 * floor_pixels) as f64;
            assert!(bias.abs() < 0.002, "blocker {with_blocker}: mean error of c {bias}");
        }
    }
}

/// DGB §3.2's blend with a perfect gather is E_seen + (1 − c)·E_probe, and screen space
/// alone Ê = E_seen / c, at every pixel of a two-pixel oracle image.
#[test]
fn oracle_blend_fills_what_the_layers_miss_with_the_probes() {
    let pi = std::f32::consts::PI;
    let (albedo, e_seen, c) = (Vec3::new(0.5, 0.5, 0.25), Vec3::new(1.0, 0.5, 0.25), 0.25);
    let seen = albedo * e_seen / pi;
    assert!((gathered_irradiance(seen, c, albedo) - e_seen / c).abs().max_element() < 1e-6);
    assert_eq!(gathered_irradiance(seen, 0.0, albedo), Vec3::ZERO);
    // pixel 0 as above, pixel 1 without a surface
    let mut means = ImageBuf::new(2, 1, ORACLE_CHANNELS);
    means.data[3..6].copy_from_slice(&albedo.to_array());
    let v = OracleImages::variant(2, true);
    let block = (ORACLE_CHANNELS as usize - 12) / ORACLE_VARIANTS.len();
    let o = 12 + block * v;
    means.data[o..o + 3].copy_from_slice(&seen.to_array());
    means.data[o + 3] = c;
    let img = OracleImages::from_means(&means);
    let mut e_probe = ImageBuf::new(2, 1, 3);
    e_probe.data.fill(2.0);
    let blend = img.blend(v, &e_probe, paper_blend);
    let want = seen + (1.0 - c) * albedo * 2.0 / pi;
    assert!((Vec3::from_slice(&blend.data[..3]) - want).abs().max_element() < 1e-6);
    assert_eq!(&blend.data[3..], &[0.0; 3]);
    let alone = img.alone(v);
    assert!((Vec3::from_slice(&alone.data[..3]) - seen / c).abs().max_element() < 1e-6);
    assert_eq!(img.mean_confidence(v), 0.25_f64);
}

/// `gather_agreement`: Σ E_gathered / Σ Ê per channel over the pixels where the perfect
/// gather's c reaches the threshold, the receiver has a surface and the real gather found
/// something; the other pixels do not count.
#[test]
fn gather_agreement_compares_only_the_receivers_both_gathers_see() {
    let pi = std::f32::consts::PI;
    let albedo = Vec3::new(0.5, 0.5, 0.25);
    let v = OracleImages::variant(1, true);
    let block = (ORACLE_CHANNELS as usize - 12) / ORACLE_VARIANTS.len();
    let o = 12 + block * v;
    // pixel i: (c, Ê, the real gather's E and c)
    let pixels = [
        (0.5, Vec3::new(2.0, 4.0, 6.0), Vec3::new(1.0, 3.0, 6.0), 0.3),
        (0.2, Vec3::new(2.0, 4.0, 2.0), Vec3::new(1.0, 1.0, 4.0), 0.1),
        // below the threshold
        (0.05, Vec3::splat(1.0), Vec3::splat(100.0), 0.5),
        // the real gather found nothing
        (0.8, Vec3::splat(1.0), Vec3::splat(100.0), 0.0),
    ];
    let n = pixels.len() as u32;
    let mut means = ImageBuf::new(n, 1, ORACLE_CHANNELS);
    let mut gathered = ImageBuf::new(n, 1, 4);
    for (i, (c, e_hat, e_gpu, c_gpu)) in pixels.into_iter().enumerate() {
        let m = &mut means.data[i * ORACLE_CHANNELS as usize..][..ORACLE_CHANNELS as usize];
        m[3..6].copy_from_slice(&albedo.to_array());
        m[o..o + 3].copy_from_slice(&(albedo / pi * e_hat * c).to_array());
        m[o + 3] = c;
        gathered.data[4 * i..4 * i + 4].copy_from_slice(&e_gpu.extend(c_gpu).to_array());
    }
    let img = OracleImages::from_means(&means);
    let a = img.gather_agreement(v, &gathered, 0.1).expect("two pixels compare");
    assert_eq!(a.pixels, 2);
    let want = [2.0 / 4.0, 4.0 / 8.0, 10.0 / 8.0];
    for (got, want) in a.irradiance_ratio.iter().zip(want) {
        assert!((got - want).abs() < 1e-5, "{:?} against {want:?}", a.irradiance_ratio);
    }
    // a threshold above every pixel's c leaves nothing to compare
    assert!(img.gather_agreement(v, &gathered, 0.9).is_none());
}
