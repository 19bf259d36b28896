mod common;
use common::intersect;
use glam::Vec3;
use strata_scene::*;
#[test]
fn render() {
    for name in ["atrium", "warehouse", "column-wall", "sponza"] {
        let s = if name == "sponza" {
            load::load_path(std::path::Path::new("/work/main/scenes/sponza.toml")).unwrap()
        } else {
            procedural::builtin(name).unwrap()
        };
        let tris = s.world_triangles(0.0);
        let (w, h) = if name == "cornell" {
            (160u32, 160u32)
        } else {
            (240u32, 135u32)
        };
        let cam = s.camera;
        let mut img = ImageBuf::new(w, h, 3);
        let hit = |o: Vec3, d: Vec3, tmax: f32| -> Option<(f32, usize)> {
            let mut best: Option<(f32, usize)> = None;
            for (i, t) in tris.iter().enumerate() {
                if let Some(x) = intersect(o, d, t) {
                    if x < tmax && best.is_none_or(|b| x < b.0) {
                        best = Some((x, i));
                    }
                }
            }
            best
        };
        for y in 0..h {
            for x in 0..w {
                let d = cam.pixel_dir(x, y, w, h);
                let c = match hit(cam.eye, d, f32::INFINITY) {
                    None => Vec3::from(s.settings.sky),
                    Some((t, i)) => {
                        let tri = &tris[i];
                        let m = &s.materials[tri.material as usize];
                        let p = cam.eye + d * t;
                        let mut n = (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]).normalize();
                        if n.dot(d) > 0.0 {
                            n = -n;
                        }
                        let po = p + n * 1e-3;
                        let alb = Vec3::from(m.base_color);
                        let mut e = Vec3::from(s.settings.ambient) + Vec3::from(s.settings.sky) * 0.5;
                        for l in &s.lights {
                            match l {
                                Light::Sun {
                                    direction,
                                    color,
                                    illuminance,
                                } => {
                                    let c = n.dot(-*direction);
                                    if c > 0.0 && hit(po, -*direction, f32::INFINITY).is_none() {
                                        e += Vec3::from(*color) * *illuminance * c / std::f32::consts::PI;
                                    }
                                }
                                Light::Point {
                                    position,
                                    color,
                                    intensity,
                                } => {
                                    let v = *position - po;
                                    let dd = v.length();
                                    let c = n.dot(v / dd);
                                    if c > 0.0 && hit(po, v, 1.0 - 1e-4).is_none() {
                                        e += Vec3::from(*color) * *intensity * c / (dd * dd) / std::f32::consts::PI;
                                    }
                                }
                                Light::Spot {
                                    position,
                                    direction,
                                    color,
                                    intensity,
                                    inner_deg,
                                    outer_deg,
                                } => {
                                    let v = *position - po;
                                    let dd = v.length();
                                    let c = n.dot(v / dd);
                                    let ca = (-v / dd).dot(*direction);
                                    let f = ((ca - outer_deg.to_radians().cos())
                                        / (inner_deg.to_radians().cos() - outer_deg.to_radians().cos()))
                                    .clamp(0.0, 1.0);
                                    if c > 0.0 && f > 0.0 && hit(po, v, 1.0 - 1e-4).is_none() {
                                        e += Vec3::from(*color) * *intensity * f * c / (dd * dd) / std::f32::consts::PI;
                                    }
                                }
                                Light::Rect {
                                    center,
                                    radiance,
                                    half_u,
                                    half_v,
                                } => {
                                    let v = *center - po;
                                    let dd = v.length();
                                    let nl = half_u.cross(*half_v).normalize();
                                    let c = n.dot(v / dd);
                                    let cl = nl.dot(-v / dd);
                                    let area = 4.0 * half_u.cross(*half_v).length();
                                    if c > 0.0 && cl > 0.0 && hit(po, v * 0.999, 1.0).is_none() {
                                        e += Vec3::from(*radiance) * area * c * cl / (dd * dd) / std::f32::consts::PI;
                                    }
                                }
                            }
                        }
                        alb * e + Vec3::from(m.emission)
                    }
                };
                let c = c * s.settings.exposure;
                let c = c / (c + Vec3::ONE);
                img.pixel_mut(x, y).copy_from_slice(&(c * 1.6).to_array());
            }
        }
        img.save(std::path::Path::new(&format!("/tmp/strata_{name}.png")), true)
            .unwrap();
    }
}
