//! TOML scene files (format in the [`super`] docs): a mesh file (loaded
//! through [`super::load_mesh_file`]) or a built-in scene, placed by `scale`
//! and `translate`, with material overrides, stacked copies (`[repeat]`),
//! camera, camera path, lights, settings, ground quad and animations set on top.
//!
//! Checks: the text must be UTF-8 TOML; unknown keys are errors
//! (`deny_unknown_fields`); every value is range-checked by [`Check`], whose
//! errors name the file, the key and the valid range; the result passes
//! [`Scene::validate`].

use std::path::Path;

use glam::{Mat4, Vec3};
use serde::Deserialize;

use crate::camera::Camera;
use crate::error::SceneError;
use crate::files::FileSource;
use crate::model::{Animation, Light, Material, Object, Scene, SceneSettings};
use crate::path::{CameraPath, Keyframe};
use crate::shapes::MeshBuilder;

use super::{default_camera, default_settings, default_sun, extension, load_mesh_file};

/// Parses and builds a TOML scene description. `path` names the file in
/// errors and locates the mesh file (read through `files`).
pub(super) fn load_text(text: &str, path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    let doc: TomlScene = toml::from_str(text).map_err(|e| {
        let at = e
            .span()
            .map(|s| {
                let upto = &text.as_bytes()[..s.start.min(text.len())];
                let line = upto.iter().filter(|&&b| b == b'\n').count() + 1;
                let col = upto.iter().rev().take_while(|&&b| b != b'\n').count() + 1;
                format!("line {line}, column {col}: ")
            })
            .unwrap_or_default();
        SceneError::file(path, format!("invalid scene file: {at}{}", e.message().trim()))
    })?;
    let scene = build_scene(doc, path, files)?;
    scene.validate().map_err(|e| SceneError::file(path, e))?;
    Ok(scene)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlScene {
    name: Option<String>,
    mesh: Option<String>,
    builtin: Option<String>,
    scale: Option<f32>,
    translate: Option<[f32; 3]>,
    camera: Option<TomlCamera>,
    #[serde(default)]
    light: Vec<TomlLight>,
    camera_path: Option<TomlPath>,
    settings: Option<TomlSettings>,
    ground: Option<TomlGround>,
    #[serde(default)]
    animate: Vec<TomlAnimate>,
    #[serde(default)]
    material: Vec<TomlMaterial>,
    repeat: Option<TomlRepeat>,
}

/// `[[material]]`: overrides of the base scene's materials called `name`
/// (`"*"`: all of them).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlMaterial {
    name: String,
    opacity: Option<f32>,
    base_color: Option<[f32; 3]>,
    roughness: Option<f32>,
    metallic: Option<f32>,
    /// The CPU reference's GGX model (`Material::glossy`).
    glossy: Option<bool>,
}

/// `[repeat]`: `count` copies of the base scene's objects, copy i translated
/// by `i × offset`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlRepeat {
    count: i64,
    offset: [f32; 3],
}

/// Most copies `[repeat]` may make.
const MAX_REPEAT: i64 = 64;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlCamera {
    eye: [f32; 3],
    target: [f32; 3],
    up: Option<[f32; 3]>,
    fov: Option<f32>,
    near: Option<f32>,
}

fn white() -> [f32; 3] {
    [1.0; 3]
}

fn default_inner() -> f32 {
    20.0
}

fn default_outer() -> f32 {
    30.0
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum TomlLight {
    Sun {
        direction: [f32; 3],
        #[serde(default = "white")]
        color: [f32; 3],
        illuminance: f32,
    },
    Point {
        position: [f32; 3],
        #[serde(default = "white")]
        color: [f32; 3],
        intensity: f32,
    },
    Spot {
        position: [f32; 3],
        direction: [f32; 3],
        #[serde(default = "white")]
        color: [f32; 3],
        intensity: f32,
        #[serde(default = "default_inner")]
        inner_deg: f32,
        #[serde(default = "default_outer")]
        outer_deg: f32,
    },
    Rect {
        center: [f32; 3],
        half_u: [f32; 3],
        half_v: [f32; 3],
        radiance: [f32; 3],
        #[serde(default)]
        emitter: bool,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlPath {
    keyframes: Vec<TomlKeyframe>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlKeyframe {
    frame: f32,
    eye: [f32; 3],
    target: [f32; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlSettings {
    ao_radius: Option<f32>,
    min_separation: Option<f32>,
    radiosity_radius: Option<f32>,
    exposure: Option<f32>,
    sky: Option<[f32; 3]>,
    ambient: Option<[f32; 3]>,
    probe_bounds: Option<[[f32; 3]; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TomlGround {
    y: Option<f32>,
    size: Option<f32>,
    color: Option<[f32; 3]>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum TomlAnimate {
    Swing {
        object: String,
        pivot: [f32; 3],
        axis: [f32; 3],
        amplitude_deg: f32,
        period_frames: f32,
    },
    Slide {
        object: String,
        amplitude: [f32; 3],
        period_frames: f32,
    },
}

/// Range checks with messages naming the key and the valid range.
struct Check<'a> {
    path: &'a Path,
}

impl Check<'_> {
    fn err(&self, key: &str, msg: impl std::fmt::Display) -> SceneError {
        SceneError::file(self.path, format!("{key}: {msg}"))
    }

    fn positive(&self, key: &str, x: f32) -> Result<f32, SceneError> {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(key, format!("{x} is out of range: must be finite and > 0")))
        }
    }

    fn finite(&self, key: &str, x: f32) -> Result<f32, SceneError> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(key, format!("{x} is out of range: must be finite")))
        }
    }

    fn vec(&self, key: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        let v = Vec3::from(v);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(key, format!("{v} is out of range: components must be finite")))
        }
    }

    fn direction(&self, key: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        let v = self.vec(key, v)?;
        if v.length() > 1e-12 {
            Ok(v.normalize())
        } else {
            Err(self.err(key, "must be a non-zero vector"))
        }
    }

    fn color(&self, key: &str, c: [f32; 3]) -> Result<[f32; 3], SceneError> {
        if c.iter().all(|x| x.is_finite() && *x >= 0.0) {
            Ok(c)
        } else {
            Err(self.err(
                key,
                format!("{c:?} is out of range: components must be finite and >= 0"),
            ))
        }
    }
}

/// Builds the scene of a parsed TOML file, section by section (the order
/// matters: placement before the defaults that depend on the placed bounds,
/// the ground after them so that the default camera frames the mesh only).
fn build_scene(doc: TomlScene, path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    let ck = Check { path };
    let dir = path.parent().unwrap_or(Path::new(""));
    let (mut scene, has_camera, from_file) = base_scene(&doc, &ck, dir, files)?;
    place(&doc, &ck, &mut scene)?;
    for (i, m) in doc.material.iter().enumerate() {
        override_material(i, m, &ck, &mut scene)?;
    }
    if let Some(r) = &doc.repeat {
        repeat(r, &ck, &mut scene)?;
    }

    // Defaults that depend on the placed geometry (before the ground is added,
    // so that the default camera frames the mesh, not the ground).
    let (lo, hi) = scene.bounds(0.0);
    if from_file {
        scene.settings = default_settings(lo, hi);
        if !has_camera {
            scene.camera = default_camera(lo, hi);
        }
    }

    if let Some(g) = &doc.ground {
        add_ground(g, &ck, &mut scene, lo, hi)?;
    }
    if let Some(c) = &doc.camera {
        set_camera(c, &ck, &mut scene)?;
    }
    if let Some(p) = &doc.camera_path {
        scene.camera_path = Some(camera_path(p, &ck, &scene.camera)?);
    }
    if !doc.light.is_empty() {
        let mut lights = Vec::with_capacity(doc.light.len());
        for (i, l) in doc.light.iter().enumerate() {
            lights.push(light(i, l, &ck, &mut scene)?);
        }
        scene.lights = lights;
    }
    if let Some(s) = &doc.settings {
        apply_settings(s, &ck, &mut scene.settings)?;
    }
    for (i, a) in doc.animate.iter().enumerate() {
        animate(i, a, &ck, &mut scene)?;
    }

    if let Some(n) = doc.name {
        scene.name = n;
    } else if let Some(stem) = path.file_stem() {
        scene.name = stem.to_string_lossy().into_owned();
    }
    Ok(scene)
}

/// The base scene (`mesh` or `builtin`), whether it has its own camera, and
/// whether it came from a mesh file (which then gets default settings).
fn base_scene(
    doc: &TomlScene,
    ck: &Check,
    dir: &Path,
    files: &dyn FileSource,
) -> Result<(Scene, bool, bool), SceneError> {
    Ok(match (&doc.mesh, &doc.builtin) {
        (Some(_), Some(_)) => return Err(ck.err("mesh", "give either `mesh` or `builtin`, not both")),
        (None, None) => {
            return Err(ck.err(
                "mesh",
                "missing: give `mesh = \"file.obj|.gltf|.glb\"` or `builtin = \"name\"`",
            ));
        }
        (None, Some(name)) => {
            let s = crate::procedural::builtin(name).ok_or_else(|| {
                ck.err(
                    "builtin",
                    format!(
                        "unknown built-in scene '{name}': use one of {}",
                        crate::procedural::BUILTIN_NAMES.join(", ")
                    ),
                )
            })?;
            (s, true, false)
        }
        (Some(mesh), None) => {
            let mesh_path = dir.join(mesh);
            if !matches!(extension(&mesh_path).as_deref(), Some("obj" | "gltf" | "glb")) {
                return Err(ck.err("mesh", format!("'{mesh}' must be a .obj, .gltf or .glb file")));
            }
            let f =
                load_mesh_file(&mesh_path, files).map_err(|e| ck.err("mesh", format!("cannot load '{mesh}': {e}")))?;
            let has_camera = f.has_camera;
            let mut s = f.scene;
            if !f.has_lights {
                s.lights = vec![default_sun()];
            }
            (s, has_camera, true)
        }
    })
}

/// Places the base scene: `scale`, then `translate`.
fn place(doc: &TomlScene, ck: &Check, scene: &mut Scene) -> Result<(), SceneError> {
    let scale = match doc.scale {
        Some(s) => ck.positive("scale", s)?,
        None => 1.0,
    };
    let translate = match doc.translate {
        Some(t) => ck.vec("translate", t)?,
        None => Vec3::ZERO,
    };
    let place = Mat4::from_translation(translate) * Mat4::from_scale(Vec3::splat(scale));
    if place != Mat4::IDENTITY {
        transform_scene(scene, place, scale);
    }
    Ok(())
}

/// `[[material]]` number `i`: sets the given values on every material of the
/// base scene called `name` (all of them for `"*"`); an unknown name is an
/// error listing the material names.
fn override_material(i: usize, m: &TomlMaterial, ck: &Check, scene: &mut Scene) -> Result<(), SceneError> {
    let k = |f: &str| format!("material[{i}].{f}");
    let opacity = match m.opacity {
        Some(a) if !(a.is_finite() && (0.0..=1.0).contains(&a)) => {
            return Err(ck.err(&k("opacity"), format!("{a} is out of range: must be in 0..=1")));
        }
        a => a,
    };
    let base_color = match m.base_color {
        Some(c) if !c.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x)) => {
            return Err(ck.err(
                &k("base_color"),
                format!("{c:?} is out of range: components must be in 0..=1"),
            ));
        }
        c => c,
    };
    let unit = |v: Option<f32>, f: &str| match v {
        Some(x) if !(x.is_finite() && (0.0..=1.0).contains(&x)) => {
            Err(ck.err(&k(f), format!("{x} is out of range: must be in 0..=1")))
        }
        x => Ok(x),
    };
    let (roughness, metallic) = (unit(m.roughness, "roughness")?, unit(m.metallic, "metallic")?);
    let mut found = false;
    for mat in scene.materials.iter_mut().filter(|x| m.name == "*" || x.name == m.name) {
        if let Some(a) = opacity {
            mat.opacity = a;
        }
        if let Some(r) = roughness {
            mat.roughness = r;
        }
        if let Some(v) = metallic {
            mat.metallic = v;
        }
        if let Some(g) = m.glossy {
            mat.glossy = g;
        }
        if let Some(c) = base_color {
            mat.base_color = c;
        }
        found = true;
    }
    if !found {
        let (names, more) = name_list(scene.materials.iter().map(|x| x.name.as_str()));
        return Err(ck.err(
            &k("name"),
            format!(
                "no material named '{}' (materials: {}{more}; \"*\" matches all)",
                crate::error::short(&m.name),
                names.join(", ")
            ),
        ));
    }
    Ok(())
}

/// `[repeat]`: `count` (1..=[`MAX_REPEAT`]) copies of every object of the base
/// scene, copy i translated by `i × offset` (copy 0 is the original; copies
/// keep the object's name, mesh and animation).
fn repeat(r: &TomlRepeat, ck: &Check, scene: &mut Scene) -> Result<(), SceneError> {
    if !(1..=MAX_REPEAT).contains(&r.count) {
        return Err(ck.err(
            "repeat.count",
            format!("{} is out of range: must be in 1..={MAX_REPEAT}", r.count),
        ));
    }
    let offset = ck.vec("repeat.offset", r.offset)?;
    let originals = scene.objects.clone();
    for i in 1..r.count {
        let shift = Mat4::from_translation(offset * i as f32);
        scene.objects.extend(originals.iter().map(|o| Object {
            transform: shift * o.transform,
            ..o.clone()
        }));
    }
    Ok(())
}

/// `[ground]`: a horizontal quad under the bounds `lo..hi` of the placed scene.
fn add_ground(g: &TomlGround, ck: &Check, scene: &mut Scene, lo: Vec3, hi: Vec3) -> Result<(), SceneError> {
    let y = match g.y {
        Some(y) => ck.finite("ground.y", y)?,
        None => lo.y,
    };
    let size = match g.size {
        Some(s) => ck.positive("ground.size", s)?,
        None => 3.0 * (hi - lo).length().max(1e-3),
    };
    let color = ck.color("ground.color", g.color.unwrap_or([0.5; 3]))?;
    let c = 0.5 * (lo + hi);
    let mut b = MeshBuilder::new();
    b.rect(Vec3::new(c.x, y, c.z), Vec3::Z * (0.5 * size), Vec3::X * (0.5 * size)); // z × x = +y
    add_object(scene, "ground", b, Material::diffuse("ground", color));
    Ok(())
}

/// `[camera]`: replaces the camera (missing `near` keeps the base scene's) and
/// drops the base scene's camera path.
fn set_camera(c: &TomlCamera, ck: &Check, scene: &mut Scene) -> Result<(), SceneError> {
    let cam = Camera::new(
        ck.vec("camera.eye", c.eye)?,
        ck.vec("camera.target", c.target)?,
        ck.vec("camera.up", c.up.unwrap_or([0.0, 1.0, 0.0]))?,
        c.fov.unwrap_or(60.0),
        c.near.unwrap_or(scene.camera.near),
    );
    if !(cam.fov_y_deg > 0.0 && cam.fov_y_deg < 180.0) {
        return Err(ck.err(
            "camera.fov",
            format!("{} is out of range: must be in (0, 180) degrees", cam.fov_y_deg),
        ));
    }
    if !(cam.near.is_finite() && cam.near > 0.0) {
        return Err(ck.err("camera.near", format!("{} is out of range: must be > 0", cam.near)));
    }
    cam.validate().map_err(|e| ck.err("camera", e))?;
    scene.camera = cam;
    scene.camera_path = None;
    Ok(())
}

/// `[camera_path]`: each keyframe checked as a variation of `camera`.
fn camera_path(p: &TomlPath, ck: &Check, camera: &Camera) -> Result<CameraPath, SceneError> {
    let mut keys = Vec::with_capacity(p.keyframes.len());
    for (i, k) in p.keyframes.iter().enumerate() {
        let key = format!("camera_path.keyframes[{i}]");
        let frame = ck.finite(&format!("{key}.frame"), k.frame)?;
        let eye = ck.vec(&format!("{key}.eye"), k.eye)?;
        let target = ck.vec(&format!("{key}.target"), k.target)?;
        Camera { eye, target, ..*camera }
            .validate()
            .map_err(|e| ck.err(&key, e))?;
        keys.push(Keyframe { frame, eye, target });
    }
    CameraPath::new(keys).map_err(|e| ck.err("camera_path.keyframes", e))
}

/// `[[light]]` number `i`; a rect light with `emitter = true` also adds its
/// emissive quad to `scene`.
fn light(i: usize, l: &TomlLight, ck: &Check, scene: &mut Scene) -> Result<Light, SceneError> {
    let k = |f: &str| format!("light[{i}].{f}");
    Ok(match l {
        TomlLight::Sun {
            direction,
            color,
            illuminance,
        } => Light::Sun {
            direction: ck.direction(&k("direction"), *direction)?,
            color: ck.color(&k("color"), *color)?,
            illuminance: ck.positive(&k("illuminance"), *illuminance)?,
        },
        TomlLight::Point {
            position,
            color,
            intensity,
        } => Light::Point {
            position: ck.vec(&k("position"), *position)?,
            color: ck.color(&k("color"), *color)?,
            intensity: ck.positive(&k("intensity"), *intensity)?,
        },
        TomlLight::Spot {
            position,
            direction,
            color,
            intensity,
            inner_deg,
            outer_deg,
        } => {
            if !(*outer_deg > 0.0 && *outer_deg < 90.0) {
                return Err(ck.err(
                    &k("outer_deg"),
                    format!("{outer_deg} is out of range: must be in (0, 90) degrees"),
                ));
            }
            if !(*inner_deg > 0.0 && inner_deg <= outer_deg) {
                return Err(ck.err(
                    &k("inner_deg"),
                    format!("{inner_deg} is out of range: must be in (0, outer_deg = {outer_deg}] degrees"),
                ));
            }
            Light::Spot {
                position: ck.vec(&k("position"), *position)?,
                direction: ck.direction(&k("direction"), *direction)?,
                color: ck.color(&k("color"), *color)?,
                intensity: ck.positive(&k("intensity"), *intensity)?,
                inner_deg: *inner_deg,
                outer_deg: *outer_deg,
            }
        }
        TomlLight::Rect {
            center,
            half_u,
            half_v,
            radiance,
            emitter,
        } => {
            let center = ck.vec(&k("center"), *center)?;
            let half_u = ck.vec(&k("half_u"), *half_u)?;
            let half_v = ck.vec(&k("half_v"), *half_v)?;
            if half_u.cross(half_v).length() <= 1e-12 {
                return Err(ck.err(&k("half_u"), "half_u and half_v must be non-zero and not parallel"));
            }
            let radiance = ck.color(&k("radiance"), *radiance)?;
            if radiance.iter().all(|&r| r == 0.0) {
                return Err(ck.err(&k("radiance"), "is out of range: must have a component > 0"));
            }
            if *emitter {
                let mut b = MeshBuilder::new();
                b.rect(center, half_u, half_v);
                add_object(
                    scene,
                    &format!("light{i}"),
                    b,
                    Material::emissive(&format!("light{i}"), radiance),
                );
            }
            Light::Rect {
                center,
                half_u,
                half_v,
                radiance,
            }
        }
    })
}

/// `[settings]`: overrides the given values of `st`.
fn apply_settings(s: &TomlSettings, ck: &Check, st: &mut SceneSettings) -> Result<(), SceneError> {
    if let Some(x) = s.ao_radius {
        st.ao_radius = ck.positive("settings.ao_radius", x)?;
    }
    if let Some(x) = s.min_separation {
        st.min_separation = ck.positive("settings.min_separation", x)?;
    }
    if let Some(x) = s.radiosity_radius {
        st.radiosity_radius = ck.positive("settings.radiosity_radius", x)?;
    }
    if let Some(x) = s.exposure {
        st.exposure = ck.positive("settings.exposure", x)?;
    }
    if let Some(c) = s.sky {
        st.sky = ck.color("settings.sky", c)?;
    }
    if let Some(c) = s.ambient {
        st.ambient = ck.color("settings.ambient", c)?;
    }
    if let Some([lo, hi]) = s.probe_bounds {
        if !(lo.iter().chain(&hi).all(|x| x.is_finite()) && (0..3).all(|i| lo[i] <= hi[i])) {
            return Err(ck.err(
                "settings.probe_bounds",
                format!("[{lo:?}, {hi:?}] is out of range: [lo, hi] with finite values and lo <= hi on every axis"),
            ));
        }
        st.probe_bounds = Some([lo, hi]);
    }
    Ok(())
}

/// `[[animate]]` number `i`: sets the animation of every object of `scene`
/// with its `object` name (an error naming the objects when there is none).
fn animate(i: usize, a: &TomlAnimate, ck: &Check, scene: &mut Scene) -> Result<(), SceneError> {
    let k = |f: &str| format!("animate[{i}].{f}");
    let (object, animation) = match a {
        TomlAnimate::Swing {
            object,
            pivot,
            axis,
            amplitude_deg,
            period_frames,
        } => (
            object,
            Animation::Swing {
                pivot: ck.vec(&k("pivot"), *pivot)?,
                axis: ck.direction(&k("axis"), *axis)?,
                amplitude_deg: ck.finite(&k("amplitude_deg"), *amplitude_deg)?,
                period_frames: ck.positive(&k("period_frames"), *period_frames)?,
            },
        ),
        TomlAnimate::Slide {
            object,
            amplitude,
            period_frames,
        } => (
            object,
            Animation::Slide {
                amplitude: ck.vec(&k("amplitude"), *amplitude)?,
                period_frames: ck.positive(&k("period_frames"), *period_frames)?,
            },
        ),
    };
    let mut found = false;
    for o in scene.objects.iter_mut().filter(|o| &o.name == object) {
        o.animation = Some(animation.clone());
        found = true;
    }
    if !found {
        let (names, more) = name_list(scene.objects.iter().map(|o| o.name.as_str()));
        return Err(ck.err(
            &k("object"),
            format!("no object named '{object}' (objects: {}{more})", names.join(", ")),
        ));
    }
    Ok(())
}

/// Adds a static object with its own mesh and material.
fn add_object(scene: &mut Scene, name: &str, b: MeshBuilder, material: Material) {
    scene.materials.push(material);
    let mi = scene.meshes.len();
    scene.meshes.push(b.build(name, scene.materials.len() - 1));
    scene.objects.push(Object {
        name: name.into(),
        mesh: mi,
        transform: Mat4::IDENTITY,
        animation: None,
    });
}

/// Applies a uniform similarity transform `xf` (uniform scale `scale`) to the
/// objects, camera, camera path, lights and length settings of `scene`.
fn transform_scene(scene: &mut Scene, xf: Mat4, scale: f32) {
    for o in &mut scene.objects {
        o.transform = xf * o.transform;
        o.animation = o.animation.take().map(|a| match a {
            Animation::Swing {
                pivot,
                axis,
                amplitude_deg,
                period_frames,
            } => Animation::Swing {
                pivot: xf.transform_point3(pivot),
                axis,
                amplitude_deg,
                period_frames,
            },
            Animation::Slide {
                amplitude,
                period_frames,
            } => Animation::Slide {
                amplitude: amplitude * scale,
                period_frames,
            },
        });
    }
    let c = &mut scene.camera;
    c.eye = xf.transform_point3(c.eye);
    c.target = xf.transform_point3(c.target);
    c.near *= scale;
    if let Some(p) = &mut scene.camera_path {
        for k in &mut p.keyframes {
            k.eye = xf.transform_point3(k.eye);
            k.target = xf.transform_point3(k.target);
        }
    }
    for l in &mut scene.lights {
        match l {
            Light::Sun { .. } => {}
            Light::Point { position, .. } | Light::Spot { position, .. } => *position = xf.transform_point3(*position),
            Light::Rect {
                center, half_u, half_v, ..
            } => {
                *center = xf.transform_point3(*center);
                *half_u *= scale;
                *half_v *= scale;
            }
        }
    }
    scene.settings.ao_radius *= scale;
    scene.settings.min_separation *= scale;
    scene.settings.radiosity_radius *= scale;
    if let Some([lo, hi]) = &mut scene.settings.probe_bounds {
        let (a, b) = (xf.transform_point3((*lo).into()), xf.transform_point3((*hi).into()));
        (*lo, *hi) = (a.min(b).to_array(), a.max(b).to_array());
    }
}

/// The first 20 distinct names, sorted, for an error listing the valid ones, and
/// the `, … (N in all)` suffix when there are more.
fn name_list<'a>(names: impl Iterator<Item = &'a str>) -> (Vec<&'a str>, String) {
    let mut names: Vec<&str> = names.collect();
    names.sort_unstable();
    names.dedup();
    let more = if names.len() > 20 {
        format!(", … ({} in all)", names.len())
    } else {
        String::new()
    };
    names.truncate(20);
    (names, more)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A base scene's probe volume moves with `scale` and `translate` like its geometry.
    #[test]
    fn the_probe_volume_moves_with_the_scene() {
        let mut scene = crate::procedural::builtin("cornell").unwrap();
        scene.settings.probe_bounds = Some([[0.0, 0.0, 0.0], [0.5, 0.25, 1.0]]);
        let xf = Mat4::from_translation(Vec3::X) * Mat4::from_scale(Vec3::splat(2.0));
        transform_scene(&mut scene, xf, 2.0);
        assert_eq!(scene.settings.probe_bounds, Some([[1.0, 0.0, 0.0], [2.0, 0.5, 2.0]]));
    }
}
