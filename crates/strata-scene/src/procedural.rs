//! Built-in procedural scenes, usable with no files. Metres, +Y up.
//!
//! | name | what |
//! |---|---|
//! | `cornell` | the measured Cornell box (Cornell's published data), light quad + matching [`Light::Rect`] |
//! | `atrium` | Sponza-like two-storey colonnade, open roof, coloured banners hidden behind columns, camera path, sliding statue |
//! | `warehouse` | room whose spot-lit red floor patch is hidden behind a foreground partition wall |
//! | `plane` | one 40 × 40 m grey Lambertian plane under a sun (analytic tests) |
//! | `column-wall` | a column standing 0.5 m in front of a wall (AO tests) |
//! | `mirror` | a mirror floor before a grey board that hides a red panel from the camera but not from the mirror (DGB §3.6) |
//! | `glasshouse` | coloured glass panes overlapping in view, a translucent sphere before opaque blocks: ≥ 8 transparent crossings per pixel (A-buffer OIT, ABA) |
//! | `still-life` | glossy and diffuse objects on a cloth, an orange emitter hidden from the camera, a hollow "skull" box whose inside the emitter cannot see (bounced z-buffer Fig. 1 / Fig. 8 rows 2–3) |
//! | `dominoes` | 115 coloured dominoes in a spiral on a glossy metal floor, 1,382 triangles (bounced z-buffer Fig. 8, last rows) |
//! | `interior` | a furnished room: a mullioned window, ceiling–wall edges, a table and slatted chairs, a bookshelf, a sofa, skirting boards, a floor lamp (AO on thin frames and concave edges, issue 14) |
//!
//! Static geometry is merged into one object per material, named after the
//! material (e.g. `banner_red`); animated parts are separate objects.

use glam::{Mat4, Vec3};

use crate::camera::Camera;
use crate::model::{Animation, Light, Material, Object, Scene, SceneSettings};
use crate::path::{CameraPath, Keyframe};
use crate::shapes::MeshBuilder;

/// Names accepted by [`builtin`].
pub const BUILTIN_NAMES: &[&str] = &[
    "cornell",
    "atrium",
    "warehouse",
    "plane",
    "column-wall",
    "dense",
    "mirror",
    "mirror-sign",
    "glasshouse",
    "still-life",
    "dominoes",
    "interior",
];

/// The built-in scene called `name`, or `None` when there is none.
pub fn builtin(name: &str) -> Option<Scene> {
    match name {
        "cornell" => Some(cornell()),
        "atrium" => Some(atrium()),
        "warehouse" => Some(warehouse()),
        "plane" => Some(plane()),
        "column-wall" => Some(column_wall()),
        "dense" => Some(dense()),
        "mirror" => Some(mirror()),
        "mirror-sign" => Some(mirror_sign()),
        "glasshouse" => Some(glasshouse()),
        "still-life" => Some(still_life()),
        "dominoes" => Some(dominoes()),
        "interior" => Some(interior()),
        _ => None,
    }
}

/// Collects geometry per material and turns it into a [`Scene`].
struct SceneBuilder {
    scene: Scene,
    /// Static geometry, one builder per material index.
    statics: Vec<MeshBuilder>,
}

impl SceneBuilder {
    fn new(name: &str) -> Self {
        Self {
            scene: Scene {
                name: name.into(),
                ..Default::default()
            },
            statics: Vec::new(),
        }
    }

    /// Adds a material, returning its index.
    fn material(&mut self, m: Material) -> usize {
        self.scene.materials.push(m);
        self.statics.push(MeshBuilder::new());
        self.scene.materials.len() - 1
    }

    /// The static geometry builder of material `m`.
    fn geo(&mut self, m: usize) -> &mut MeshBuilder {
        &mut self.statics[m]
    }

    /// Adds a separate (possibly animated) object.
    fn object(
        &mut self,
        name: &str,
        mesh: MeshBuilder,
        material: usize,
        transform: Mat4,
        animation: Option<Animation>,
    ) {
        let mi = self.scene.meshes.len();
        self.scene.meshes.push(mesh.build(name, material));
        self.scene.objects.push(Object {
            name: name.into(),
            mesh: mi,
            transform,
            animation,
        });
    }

    fn finish(mut self, camera: Camera, lights: Vec<Light>, settings: SceneSettings) -> Scene {
        for (mi, b) in std::mem::take(&mut self.statics).into_iter().enumerate() {
            if b.is_empty() {
                continue;
            }
            let name = self.scene.materials[mi].name.clone();
            self.object(&name, b, mi, Mat4::IDENTITY, None);
        }
        self.scene.camera = camera;
        self.scene.lights = lights;
        self.scene.settings = settings;
        self.scene
    }
}

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Cornell box white / red / green (common RGB fits of the measured spectra).
const CORNELL_WHITE: [f32; 3] = [0.725, 0.71, 0.68];
const CORNELL_RED: [f32; 3] = [0.63, 0.065, 0.05];
const CORNELL_GREEN: [f32; 3] = [0.14, 0.45, 0.091];
/// Radiance of the Cornell light.
const CORNELL_LIGHT: [f32; 3] = [17.0, 12.0, 4.0];

/// The measured Cornell box (www.graphics.cornell.edu/online/box/data.html), in metres.
///
/// Floor 556 × 559.2 mm, height 548.8 mm, the short and tall blocks at their
/// published rotated coordinates (closed with bottom faces), red wall at
/// x ≈ 556, green wall at x = 0, open front (z = 0), light quad x 213..343,
/// z 227..332 at y = 548.7 facing −Y with radiance (17, 12, 4) plus a matching
/// [`Light::Rect`]. Camera: eye (0.278, 0.273, −0.8) looking along +Z, vertical
/// fov 39.3077° (square images). Black sky, no ambient.
pub fn cornell() -> Scene {
    let mm = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * 1e-3;
    let mut b = SceneBuilder::new("cornell");
    let white = b.material(Material::diffuse("white", CORNELL_WHITE));
    let red = b.material(Material::diffuse("red", CORNELL_RED));
    let green = b.material(Material::diffuse("green", CORNELL_GREEN));
    let light = b.material(Material::emissive("light", CORNELL_LIGHT));

    let room_centre = mm(278.0, 274.4, 279.6);
    let wall = |b: &mut SceneBuilder, m: usize, q: [Vec3; 4]| {
        let fc = q.iter().sum::<Vec3>() / 4.0;
        b.geo(m).quad_facing(q, room_centre - fc);
    };
    // Floor, ceiling, back wall (white); the walls face the room's interior.
    wall(
        &mut b,
        white,
        [
            mm(552.8, 0.0, 0.0),
            mm(0.0, 0.0, 0.0),
            mm(0.0, 0.0, 559.2),
            mm(549.6, 0.0, 559.2),
        ],
    );
    wall(
        &mut b,
        white,
        [
            mm(556.0, 548.8, 0.0),
            mm(556.0, 548.8, 559.2),
            mm(0.0, 548.8, 559.2),
            mm(0.0, 548.8, 0.0),
        ],
    );
    wall(
        &mut b,
        white,
        [
            mm(549.6, 0.0, 559.2),
            mm(0.0, 0.0, 559.2),
            mm(0.0, 548.8, 559.2),
            mm(556.0, 548.8, 559.2),
        ],
    );
    // Green wall at x = 0, red wall at x ≈ 556.
    wall(
        &mut b,
        green,
        [
            mm(0.0, 0.0, 559.2),
            mm(0.0, 0.0, 0.0),
            mm(0.0, 548.8, 0.0),
            mm(0.0, 548.8, 559.2),
        ],
    );
    wall(
        &mut b,
        red,
        [
            mm(552.8, 0.0, 0.0),
            mm(549.6, 0.0, 559.2),
            mm(556.0, 548.8, 559.2),
            mm(556.0, 548.8, 0.0),
        ],
    );
    // Short block (165 mm) and tall block (330 mm).
    let block = |xz: [[f32; 2]; 4], h: f32| {
        let bottom = xz.map(|p| mm(p[0], 0.0, p[1]));
        let top = xz.map(|p| mm(p[0], h, p[1]));
        (bottom, top)
    };
    let (sb, st) = block([[130.0, 65.0], [82.0, 225.0], [240.0, 272.0], [290.0, 114.0]], 165.0);
    b.geo(white).hexahedron(sb, st);
    let (tb, tt) = block([[423.0, 247.0], [265.0, 296.0], [314.0, 456.0], [472.0, 406.0]], 330.0);
    b.geo(white).hexahedron(tb, tt);
    // Light quad, facing down.
    // (x 213..343, z 227..332 mm at y = 548.7 mm, written in metres.)
    let centre = v(0.278, 0.5487, 0.2795);
    let half_u = v(0.065, 0.0, 0.0);
    let half_v = v(0.0, 0.0, 0.0525);
    b.geo(light).rect(centre, half_u, half_v); // x × z = −y: faces down
    let lights = vec![Light::Rect {
        center: centre,
        half_u,
        half_v,
        radiance: CORNELL_LIGHT,
    }];

    let camera = Camera::new(v(0.278, 0.273, -0.800), v(0.278, 0.273, -0.799), Vec3::Y, 39.3077, 0.01);
    let settings = SceneSettings {
        ao_radius: 0.1,
        min_separation: 0.05,
        radiosity_radius: 0.5,
        exposure: 1.0,
        sky: [0.0; 3],
        ambient: [0.0; 3],
        probe_bounds: None,
    };
    b.finish(camera, lights, settings)
}

/// Atrium dimensions (metres): the court spans x ∈ [−15, 15], z ∈ [−7, 7].
mod atrium_dims {
    pub const HALF_LEN: f32 = 15.0;
    pub const HALF_WIDTH: f32 = 7.0;
    pub const HEIGHT: f32 = 14.0;
    /// |z| of the two colonnades.
    pub const COLONNADE_Z: f32 = 4.0;
    /// Half depth (z) of the arcade panels.
    pub const ARCADE_HALF_DEPTH: f32 = 0.45;
    /// Ground-floor column spacing along x (columns at −12, −9, …, 12).
    pub const SPACING: f32 = 3.0;
    pub const FIRST_COLUMN_X: f32 = -12.0;
    pub const COLUMNS: usize = 9;
    /// Gallery floor slab (y range) and top of the upper arcade (the upper
    /// galleries have no roof, so the sun reaches the banners).
    pub const GALLERY_FLOOR: (f32, f32) = (5.8, 6.1);
    pub const GALLERY_TOP: f32 = 10.8;
    /// |z| of the banners (1.5 m behind the colonnade line).
    pub const BANNER_Z: f32 = 5.5;
}

/// A Sponza-like two-storey colonnade, 30 m long (x), 14 m wide (z), 14 m high,
/// open to the sky.
///
/// Each long side has a ground-floor arcade (9 columns, 3 m apart, with square
/// plinths and capitals, semicircular arches) carrying a gallery floor, and an
/// upper arcade with twice as many slimmer columns (top at 10.8 m; the upper
/// galleries are unroofed). Saturated banners (red, green, blue, yellow) hang
/// from rods in the upper galleries 1.5 m behind the columns, so from the
/// default camera they are mostly hidden by the columns (the deep G-buffer
/// paper's Fig. 16 case). A warm sun (about 60° high) lights a strip of the
/// court floor, the +z colonnade and most of the +z banners; the sky is bluish. The camera path (frames 0–120) moves fast sideways past the
/// +z colonnade; a statue in the court slides back and forth (object `statue`).
pub fn atrium() -> Scene {
    use atrium_dims::*;
    let mut b = SceneBuilder::new("atrium");
    let stone_floor = b.material(Material::diffuse("floor", [0.45, 0.42, 0.36]));
    let wall = b.material(Material::diffuse("wall", [0.62, 0.57, 0.48]));
    let column = b.material(Material::diffuse("column", [0.68, 0.64, 0.56]));
    let arcade = b.material(Material::diffuse("arcade", [0.6, 0.55, 0.46]));
    let banner_colors: [(&str, [f32; 3]); 4] = [
        ("banner_red", [0.75, 0.04, 0.03]),
        ("banner_green", [0.05, 0.55, 0.06]),
        ("banner_blue", [0.04, 0.1, 0.7]),
        ("banner_yellow", [0.8, 0.65, 0.03]),
    ];
    let banners: Vec<usize> = banner_colors
        .iter()
        .map(|&(n, c)| b.material(Material::diffuse(n, c)))
        .collect();
    let statue_mat = b.material(Material::diffuse("statue", [0.8, 0.78, 0.74]));

    let (hl, hw, h) = (HALF_LEN, HALF_WIDTH, HEIGHT);
    // Floor and the enclosing walls (0.5 m thick boxes outside the court).
    b.geo(stone_floor)
        .rect(v(0.0, 0.0, 0.0), v(0.0, 0.0, hw), v(hl, 0.0, 0.0)); // z × x = +y
    b.geo(wall).cuboid(v(-hl - 0.5, 0.0, -hw - 0.5), v(hl + 0.5, h, -hw));
    b.geo(wall).cuboid(v(-hl - 0.5, 0.0, hw), v(hl + 0.5, h, hw + 0.5));
    b.geo(wall).cuboid(v(-hl - 0.5, 0.0, -hw), v(-hl, h, hw));
    b.geo(wall).cuboid(v(hl, 0.0, -hw), v(hl + 0.5, h, hw));

    let last_x = FIRST_COLUMN_X + SPACING * (COLUMNS - 1) as f32;
    for side in [-1.0f32, 1.0] {
        let zc = side * COLONNADE_Z;
        let (za, zb) = (zc - ARCADE_HALF_DEPTH, zc + ARCADE_HALF_DEPTH);
        // Slabs span from the arcade's court face to the outer wall.
        let (slab_z0, slab_z1) = if side > 0.0 { (za, hw) } else { (-hw, zb) };

        // Ground floor: columns, arches, end piers, gallery floor.
        for i in 0..COLUMNS {
            let x = FIRST_COLUMN_X + SPACING * i as f32;
            b.geo(column)
                .cuboid(v(x - 0.5, 0.0, zc - 0.5), v(x + 0.5, 0.4, zc + 0.5));
            b.geo(column).cylinder(v(x, 0.4, zc), 0.35, 3.2, 20, false);
            b.geo(column)
                .cuboid(v(x - 0.55, 3.6, zc - 0.55), v(x + 0.55, 4.0, zc + 0.55));
        }
        for i in 0..COLUMNS - 1 {
            let x = FIRST_COLUMN_X + SPACING * (i as f32 + 0.5);
            b.geo(arcade)
                .arch_panel(x, 4.0, SPACING / 2.0, GALLERY_FLOOR.0, za, zb, 16);
        }
        b.geo(arcade)
            .cuboid(v(-hl, 0.0, za), v(FIRST_COLUMN_X - 0.5, GALLERY_FLOOR.0, zb));
        b.geo(arcade)
            .cuboid(v(last_x + 0.5, 0.0, za), v(hl, GALLERY_FLOOR.0, zb));
        b.geo(arcade)
            .cuboid(v(-hl, GALLERY_FLOOR.0, slab_z0), v(hl, GALLERY_FLOOR.1, slab_z1));

        // Upper storey: twice as many, slimmer columns, smaller arches, no roof.
        let y0 = GALLERY_FLOOR.1;
        let upper_spacing = SPACING / 2.0;
        let upper_count = 2 * (COLUMNS - 1) + 1;
        for i in 0..upper_count {
            let x = FIRST_COLUMN_X + upper_spacing * i as f32;
            b.geo(column)
                .cuboid(v(x - 0.4, y0, zc - 0.4), v(x + 0.4, y0 + 0.3, zc + 0.4));
            b.geo(column).cylinder(v(x, y0 + 0.3, zc), 0.25, 2.6, 16, false);
            b.geo(column)
                .cuboid(v(x - 0.42, y0 + 2.9, zc - 0.42), v(x + 0.42, y0 + 3.2, zc + 0.42));
        }
        let spring = y0 + 3.2;
        for i in 0..upper_count - 1 {
            let x = FIRST_COLUMN_X + upper_spacing * (i as f32 + 0.5);
            b.geo(arcade)
                .arch_panel(x, spring, upper_spacing / 2.0, GALLERY_TOP, za + 0.05, zb - 0.05, 12);
        }
        b.geo(arcade)
            .cuboid(v(-hl, y0, za + 0.05), v(FIRST_COLUMN_X - 0.4, GALLERY_TOP, zb - 0.05));
        b.geo(arcade)
            .cuboid(v(last_x + 0.4, y0, za + 0.05), v(hl, GALLERY_TOP, zb - 0.05));

        // Banners in the upper gallery, 1.5 m behind the columns, centred
        // between ground-floor columns: thin boxes hanging from a rod that
        // runs from end wall to end wall.
        let bz = side * BANNER_Z;
        b.geo(arcade).cuboid(
            v(-hl, GALLERY_TOP - 0.05, bz - 0.05),
            v(hl, GALLERY_TOP + 0.05, bz + 0.05),
        );
        for i in 0..COLUMNS - 1 {
            let x = FIRST_COLUMN_X + SPACING * (i as f32 + 0.5);
            let m = banners[(i + if side > 0.0 { 0 } else { 2 }) % banners.len()];
            b.geo(m)
                .cuboid(v(x - 0.6, 7.0, bz - 0.03), v(x + 0.6, GALLERY_TOP - 0.05, bz + 0.03));
        }
    }

    // The sliding statue in the court: pedestal, body, head.
    let mut statue = MeshBuilder::new();
    statue.cuboid(v(-0.5, 0.0, -0.5), v(0.5, 1.0, 0.5));
    statue.cylinder(v(0.0, 1.0, 0.0), 0.3, 1.5, 20, true);
    statue.cuboid(v(-0.2, 2.5, -0.2), v(0.2, 2.9, 0.2));
    let slide = Animation::Slide {
        amplitude: v(0.0, 0.0, 1.5),
        period_frames: 60.0,
    };
    b.object(
        "statue",
        statue,
        statue_mat,
        Mat4::from_translation(v(-2.0, 0.0, 0.5)),
        Some(slide),
    );

    let sun = Light::Sun {
        direction: v(0.35, -1.0, 0.5).normalize(),
        color: [1.0, 0.88, 0.7],
        illuminance: 8.0,
    };
    let keyframes = atrium_keyframes();
    let camera = Camera::new(keyframes[0].eye, keyframes[0].target, Vec3::Y, 60.0, 0.05);
    let path = CameraPath::new(keyframes).ok();
    let settings = SceneSettings {
        ao_radius: 1.0,
        min_separation: 0.5,
        radiosity_radius: 16.0,
        exposure: 0.5,
        sky: [0.3, 0.45, 0.75],
        ambient: [0.03; 3],
        probe_bounds: None,
    };
    let mut scene = b.finish(camera, vec![sun], settings);
    scene.camera_path = path;
    scene
}

/// The atrium's camera path: 120 frames, sideways along the court past the +z
/// colonnade (about 0.2 m per frame), looking diagonally at it.
fn atrium_keyframes() -> Vec<Keyframe> {
    let look = v(12.0, 4.2, 6.5);
    [
        (0.0, v(-13.0, 2.2, -2.0)),
        (30.0, v(-7.0, 2.6, -1.0)),
        (60.0, v(-1.0, 3.0, -1.8)),
        (90.0, v(5.0, 2.6, -1.0)),
        (120.0, v(11.0, 2.2, -2.0)),
    ]
    .into_iter()
    .map(|(frame, eye)| Keyframe {
        frame,
        eye,
        target: eye + look,
    })
    .collect()
}

/// Warehouse dimensions: room x ∈ [−8, 8], z ∈ [−6, 6], 5 m high.
mod warehouse_dims {
    /// The red floor patch (x range, z range).
    pub const PATCH_X: (f32, f32) = (-2.6, 0.4);
    pub const PATCH_Z: (f32, f32) = (-2.9, 0.1);
    /// The partition wall (x range, z range, height).
    pub const PARTITION_X: (f32, f32) = (-3.0, -2.8);
    pub const PARTITION_Z: (f32, f32) = (-6.0, 0.5);
    pub const PARTITION_H: f32 = 2.5;
}

/// A closed room (16 × 12 × 5 m) whose brightly spot-lit, saturated red floor
/// patch (3 × 3 m) lies just behind the edge of a 2.5 m partition wall in the
/// foreground (the deep G-buffer paper's Fig. 15 case): from the default camera
/// the patch is entirely hidden in the first layer, while the floor beside it
/// (within ~0.1–0.5 m, past the partition's edge) is visible and should receive
/// its red bounce light. A dim point light fills the rest of the room.
pub fn warehouse() -> Scene {
    use warehouse_dims::*;
    let mut b = SceneBuilder::new("warehouse");
    let floor = b.material(Material::diffuse("floor", [0.6, 0.6, 0.58]));
    let wall = b.material(Material::diffuse("wall", [0.75, 0.75, 0.73]));
    let red = b.material(Material::diffuse("red_patch", [0.85, 0.04, 0.03]));
    let crate_mat = b.material(Material::diffuse("crates", [0.7, 0.68, 0.62]));

    let (x0, x1, z0, z1, h) = (-8.0f32, 8.0f32, -6.0f32, 6.0f32, 5.0f32);
    // Floor tiles around the patch (no overlap with it), then the patch.
    let floor_rect = |b: &mut SceneBuilder, m: usize, xa: f32, xb: f32, za: f32, zb: f32| {
        b.geo(m).quad_facing(
            [v(xa, 0.0, za), v(xb, 0.0, za), v(xb, 0.0, zb), v(xa, 0.0, zb)],
            Vec3::Y,
        );
    };
    floor_rect(&mut b, floor, x0, PATCH_X.0, z0, z1);
    floor_rect(&mut b, floor, PATCH_X.1, x1, z0, z1);
    floor_rect(&mut b, floor, PATCH_X.0, PATCH_X.1, z0, PATCH_Z.0);
    floor_rect(&mut b, floor, PATCH_X.0, PATCH_X.1, PATCH_Z.1, z1);
    floor_rect(&mut b, red, PATCH_X.0, PATCH_X.1, PATCH_Z.0, PATCH_Z.1);
    // Walls and ceiling: 0.3 m boxes outside the room.
    let t = 0.3;
    b.geo(wall).cuboid(v(x0 - t, 0.0, z0 - t), v(x1 + t, h, z0));
    b.geo(wall).cuboid(v(x0 - t, 0.0, z1), v(x1 + t, h, z1 + t));
    b.geo(wall).cuboid(v(x0 - t, 0.0, z0), v(x0, h, z1));
    b.geo(wall).cuboid(v(x1, 0.0, z0), v(x1 + t, h, z1));
    b.geo(wall).cuboid(v(x0 - t, h, z0 - t), v(x1 + t, h + t, z1 + t));
    // Foreground partition whose edge (z = 1) hides the patch from the camera.
    b.geo(wall).cuboid(
        v(PARTITION_X.0, 0.0, PARTITION_Z.0),
        v(PARTITION_X.1, PARTITION_H, PARTITION_Z.1),
    );
    // A few crates.
    b.geo(crate_mat).cuboid(v(3.0, 0.0, -4.5), v(4.5, 1.5, -3.0));
    b.geo(crate_mat).cuboid(v(3.3, 1.5, -4.2), v(4.3, 2.5, -3.2));
    b.geo(crate_mat).cuboid(v(5.0, 0.0, 2.5), v(6.2, 1.2, 3.7));

    let patch_centre = v(0.5 * (PATCH_X.0 + PATCH_X.1), 0.0, 0.5 * (PATCH_Z.0 + PATCH_Z.1));
    let lights = vec![
        Light::Spot {
            position: patch_centre + Vec3::Y * 4.7,
            direction: -Vec3::Y,
            color: [1.0, 0.96, 0.9],
            intensity: 300.0,
            inner_deg: 15.0,
            outer_deg: 19.0,
        },
        Light::Point {
            position: v(4.0, 3.2, 2.5),
            color: [1.0, 1.0, 1.0],
            intensity: 15.0,
        },
    ];
    let camera = Camera::new(v(-7.0, 1.6, 0.8), v(0.0, 0.8, -1.2), Vec3::Y, 60.0, 0.05);
    let settings = SceneSettings {
        ao_radius: 0.8,
        min_separation: 0.3,
        radiosity_radius: 16.0,
        exposure: 0.8,
        sky: [0.0; 3],
        ambient: [0.02; 3],
        probe_bounds: None,
    };
    b.finish(camera, lights, settings)
}

/// A single 40 × 40 m Lambertian plane (albedo 0.5) at y = 0 under one sun
/// (direction normalize(−0.4, −1, −0.2), illuminance π, so a white Lambertian
/// surface has radiance cos θ), seen obliquely. Black sky, no ambient: the
/// direct-light and "AO of an unoccluded plane is 1" test scene.
pub fn plane() -> Scene {
    let mut b = SceneBuilder::new("plane");
    let grey = b.material(Material::diffuse("grey", [0.5, 0.5, 0.5]));
    b.geo(grey).rect(Vec3::ZERO, v(0.0, 0.0, 20.0), v(20.0, 0.0, 0.0));
    let sun = Light::Sun {
        direction: v(-0.4, -1.0, -0.2).normalize(),
        color: [1.0, 1.0, 1.0],
        illuminance: std::f32::consts::PI,
    };
    let camera = Camera::new(v(0.0, 4.0, 5.0), v(0.0, 0.0, -1.0), Vec3::Y, 45.0, 0.05);
    let settings = SceneSettings {
        ao_radius: 1.0,
        min_separation: 0.5,
        radiosity_radius: 8.0,
        exposure: 1.0,
        sky: [0.0; 3],
        ambient: [0.0; 3],
        probe_bounds: None,
    };
    b.finish(camera, vec![sun], settings)
}

/// A 3 m column (radius 0.3 m, 32 segments) standing 0.5 m in front of a 4 m
/// wall (front face z = −1) on a 12 × 12 m floor, sun from the front-right
/// above, seen from the front so the column hides part of the wall.
pub fn column_wall() -> Scene {
    let mut b = SceneBuilder::new("column-wall");
    let floor = b.material(Material::diffuse("floor", [0.6, 0.6, 0.6]));
    let wall = b.material(Material::diffuse("wall", [0.7, 0.7, 0.7]));
    let column = b.material(Material::diffuse("column", [0.75, 0.73, 0.7]));
    b.geo(floor).rect(Vec3::ZERO, v(0.0, 0.0, 6.0), v(6.0, 0.0, 0.0));
    b.geo(wall).cuboid(v(-4.0, 0.0, -1.3), v(4.0, 4.0, -1.0));
    b.geo(column).cylinder(v(0.0, 0.0, -0.2), 0.3, 3.0, 32, true);
    let sun = Light::Sun {
        direction: v(0.5, -1.0, -0.6).normalize(),
        color: [1.0, 0.97, 0.92],
        illuminance: 3.0,
    };
    let camera = Camera::new(v(1.0, 1.6, 4.0), v(0.0, 1.2, -0.6), Vec3::Y, 50.0, 0.05);
    let settings = SceneSettings {
        ao_radius: 1.0,
        min_separation: 0.25,
        radiosity_radius: 8.0,
        exposure: 1.0,
        sky: [0.2, 0.25, 0.35],
        ambient: [0.03; 3],
        probe_bounds: None,
    };
    b.finish(camera, vec![sun], settings)
}

/// A generated benchmark scene of about 1.05 M triangles: a 16 × 16 grid of
/// finely tessellated columns (1024 segments, capped: 4096 triangles each) on a
/// floor before a wall, seen along the rows so that most columns hide others
/// (the DGB Table 5 "heavy geometry" case).
pub fn dense() -> Scene {
    let mut b = SceneBuilder::new("dense");
    let floor = b.material(Material::diffuse("floor", [0.55, 0.55, 0.55]));
    let wall = b.material(Material::diffuse("wall", [0.7, 0.3, 0.25]));
    let column = b.material(Material::diffuse("column", [0.75, 0.73, 0.7]));
    b.geo(floor)
        .rect(v(0.0, 0.0, -8.0), v(0.0, 0.0, 12.0), v(12.0, 0.0, 0.0));
    b.geo(wall).cuboid(v(-12.0, 0.0, -20.5), v(12.0, 6.0, -20.0));
    for i in 0..16 {
        for j in 0..16 {
            let base = v(-7.5 + i as f32, 0.0, -1.0 - 1.1 * j as f32);
            b.geo(column).cylinder(base, 0.2, 3.0, 1024, true);
        }
    }
    let sun = Light::Sun {
        direction: v(0.4, -1.0, -0.5).normalize(),
        color: [1.0, 0.97, 0.92],
        illuminance: 3.0,
    };
    let camera = Camera::new(v(0.6, 1.7, 3.5), v(0.0, 1.2, -10.0), Vec3::Y, 55.0, 0.05);
    let settings = SceneSettings {
        ao_radius: 0.5,
        min_separation: 0.5,
        radiosity_radius: 8.0,
        exposure: 1.0,
        sky: [0.2, 0.25, 0.35],
        ambient: [0.03; 3],
        probe_bounds: None,
    };
    b.finish(camera, vec![sun], settings)
}

/// A furnished room, 6 × 2.7 × 5.5 m (x ∈ [−3, 3], z ∈ [−4, 1.5]), the case issue 14
/// was filed on (a furnished interior's AO at radius 0.5): a window in the back wall
/// split by 4 cm mullions and a transom, the ceiling meeting the walls in concave
/// edges, a table on thin legs with two slatted chairs, a bookshelf of books
/// against the right wall, a sofa, a picture frame, 1.5 cm skirting boards and a
/// floor lamp on a 3 cm pole. A sun shines in through the window, a point light
/// hangs under the ceiling; outside, a ground plane and a facade.
pub fn interior() -> Scene {
    let mut b = SceneBuilder::new("interior");
    let wall = b.material(Material::diffuse("wall", [0.78, 0.76, 0.72]));
    let floor = b.material(Material::diffuse("floor", [0.46, 0.33, 0.21]));
    let wood = b.material(Material::diffuse("wood", [0.52, 0.38, 0.26]));
    let frame = b.material(Material::diffuse("window_frame", [0.85, 0.85, 0.83]));
    let fabric = b.material(Material::diffuse("fabric", [0.32, 0.38, 0.48]));
    let dark = b.material(Material::diffuse("dark", [0.12, 0.11, 0.1]));
    let outside = b.material(Material::diffuse("outside", [0.5, 0.5, 0.47]));
    let books = [
        b.material(Material::diffuse("book_red", [0.6, 0.1, 0.08])),
        b.material(Material::diffuse("book_green", [0.12, 0.4, 0.15])),
        b.material(Material::diffuse("book_cream", [0.75, 0.7, 0.55])),
    ];
    let (x0, x1, z0, z1, h, t) = (-3.0f32, 3.0f32, -4.0f32, 1.5f32, 2.7f32, 0.2f32);
    // floor, ceiling and walls (boxes outside the room); the back wall (z = z0) has a
    // window opening x ∈ [−1.2, 1.2], y ∈ [0.9, 2.2]
    b.geo(floor).cuboid(v(x0, -t, z0), v(x1, 0.0, z1));
    b.geo(wall).cuboid(v(x0 - t, h, z0 - t), v(x1 + t, h + t, z1 + t));
    b.geo(wall).cuboid(v(x0 - t, -t, z0), v(x0, h, z1));
    b.geo(wall).cuboid(v(x1, -t, z0), v(x1 + t, h, z1));
    b.geo(wall).cuboid(v(x0 - t, -t, z1), v(x1 + t, h, z1 + t));
    let (wx0, wx1, wy0, wy1) = (-1.2f32, 1.2f32, 0.9f32, 2.2f32);
    b.geo(wall).cuboid(v(x0 - t, -t, z0 - t), v(wx0, h, z0));
    b.geo(wall).cuboid(v(wx1, -t, z0 - t), v(x1 + t, h, z0));
    b.geo(wall).cuboid(v(wx0, -t, z0 - t), v(wx1, wy0, z0));
    b.geo(wall).cuboid(v(wx0, wy1, z0 - t), v(wx1, h, z0));
    // window: frame, sill, two 4 cm mullions and a transom
    let (fz0, fz1) = (z0 - 0.12, z0 - 0.04);
    b.geo(frame).cuboid(v(wx0, wy0, fz0), v(wx0 + 0.06, wy1, fz1));
    b.geo(frame).cuboid(v(wx1 - 0.06, wy0, fz0), v(wx1, wy1, fz1));
    b.geo(frame).cuboid(v(wx0, wy1 - 0.06, fz0), v(wx1, wy1, fz1));
    b.geo(frame)
        .cuboid(v(wx0 - 0.05, wy0 - 0.04, z0 - 0.12), v(wx1 + 0.05, wy0, z0 + 0.12));
    for x in [-0.42f32, 0.38] {
        b.geo(frame).cuboid(v(x, wy0, fz0), v(x + 0.04, wy1, fz1));
    }
    b.geo(frame).cuboid(v(wx0, 1.62, fz0), v(wx1, 1.66, fz1));
    // outside: ground and a facade across the street
    b.geo(outside).cuboid(v(-12.0, -0.5, -16.0), v(12.0, -0.3, z0 - t));
    b.geo(outside).cuboid(v(-12.0, -0.3, -16.5), v(12.0, 2.0, -16.0));
    // skirting boards, 8 cm high and 1.5 cm thick, along the walls but the front one
    let (sk, sh) = (0.015f32, 0.08f32);
    b.geo(wood).cuboid(v(x0, 0.0, z0), v(wx0, sh, z0 + sk));
    b.geo(wood).cuboid(v(wx1, 0.0, z0), v(x1, sh, z0 + sk));
    b.geo(wood).cuboid(v(x0, 0.0, z0 + sk), v(x0 + sk, sh, z1));
    b.geo(wood).cuboid(v(x1 - sk, 0.0, z0 + sk), v(x1, sh, z1));
    // table on 5 cm legs
    let (tx0, tx1, tz0, tz1) = (-0.8f32, 0.6f32, -2.6f32, -1.8f32);
    b.geo(wood).cuboid(v(tx0, 0.72, tz0), v(tx1, 0.76, tz1));
    for (x, z) in [
        (tx0 + 0.04, tz0 + 0.04),
        (tx1 - 0.09, tz0 + 0.04),
        (tx0 + 0.04, tz1 - 0.09),
        (tx1 - 0.09, tz1 - 0.09),
    ] {
        b.geo(wood).cuboid(v(x, 0.0, z), v(x + 0.05, 0.72, z + 0.05));
    }
    // two chairs: 3 cm legs, a seat, a back of three slats
    for (cx, cz, back_z) in [(-0.45f32, -1.45f32, 1.0f32), (0.15, -2.95, -1.0)] {
        let (sx0, sz0) = (cx - 0.21, cz - 0.21);
        b.geo(wood).cuboid(v(sx0, 0.44, sz0), v(sx0 + 0.42, 0.47, sz0 + 0.42));
        for (dx, dz) in [(0.0, 0.0), (0.39, 0.0), (0.0, 0.39), (0.39, 0.39)] {
            b.geo(wood)
                .cuboid(v(sx0 + dx, 0.0, sz0 + dz), v(sx0 + dx + 0.03, 0.44, sz0 + dz + 0.03));
        }
        let bz = if back_z > 0.0 { sz0 + 0.39 } else { sz0 };
        b.geo(wood).cuboid(v(sx0, 0.85, bz), v(sx0 + 0.42, 0.9, bz + 0.03));
        for k in 0..3 {
            let x = sx0 + 0.06 + 0.14 * k as f32;
            b.geo(wood).cuboid(v(x, 0.47, bz), v(x + 0.03, 0.85, bz + 0.03));
        }
    }
    // bookshelf against the right wall: sides, five shelves, books
    let (bx0, bz0, bz1, bh) = (x1 - 0.35, -3.6f32, -2.2f32, 2.0f32);
    b.geo(wood).cuboid(v(bx0, 0.0, bz0), v(x1, bh, bz0 + 0.02));
    b.geo(wood).cuboid(v(bx0, 0.0, bz1 - 0.02), v(x1, bh, bz1));
    for k in 0..5 {
        let y = 0.05 + 0.48 * k as f32;
        b.geo(wood).cuboid(v(bx0, y, bz0 + 0.02), v(x1, y + 0.02, bz1 - 0.02));
        if k < 4 {
            let mut z = bz0 + 0.04;
            let mut i = 0usize;
            while z < bz1 - 0.1 {
                let w = 0.03 + 0.012 * ((i * 7 + k * 3) % 5) as f32;
                let top = y + 0.02 + 0.26 + 0.03 * ((i * 5 + k) % 4) as f32;
                b.geo(books[(i + k) % 3])
                    .cuboid(v(bx0 + 0.05, y + 0.02, z), v(x1 - 0.03, top, z + w));
                z += w + 0.004;
                i += 1;
            }
        }
    }
    // sofa against the left wall, a picture frame above it
    b.geo(fabric).cuboid(v(x0, 0.0, -2.9), v(x0 + 0.9, 0.42, -0.9));
    b.geo(fabric).cuboid(v(x0, 0.42, -2.9), v(x0 + 0.22, 0.85, -0.9));
    b.geo(fabric).cuboid(v(x0 + 0.22, 0.42, -2.9), v(x0 + 0.9, 0.62, -2.72));
    b.geo(fabric).cuboid(v(x0 + 0.22, 0.42, -1.08), v(x0 + 0.9, 0.62, -0.9));
    b.geo(dark).cuboid(v(x0, 1.25, -2.3), v(x0 + 0.03, 1.85, -1.5));
    // floor lamp: base, a 3 cm pole, a shade
    b.geo(dark).cylinder(v(1.9, 0.0, -0.6), 0.16, 0.03, 24, true);
    b.geo(dark).cylinder(v(1.9, 0.03, -0.6), 0.015, 1.45, 12, true);
    b.geo(frame).cylinder(v(1.9, 1.48, -0.6), 0.2, 0.25, 24, false);
    let lights = vec![
        Light::Sun {
            direction: v(0.25, -0.55, 0.8).normalize(),
            color: [1.0, 0.95, 0.85],
            illuminance: 4.0,
        },
        Light::Point {
            position: v(0.0, 2.45, -1.2),
            color: [1.0, 0.9, 0.75],
            intensity: 6.0,
        },
    ];
    let camera = Camera::new(v(-2.3, 1.55, 1.1), v(0.9, 1.25, -3.6), Vec3::Y, 62.0, 0.05);
    let settings = SceneSettings {
        ao_radius: 0.5,
        min_separation: 0.1,
        radiosity_radius: 3.0,
        exposure: 1.0,
        sky: [0.45, 0.55, 0.75],
        ambient: [0.02; 3],
        // the scene's bounds: the volumes tried (docs/radiosity.md § "A scene's probe
        // volume") put probes just outside its 20 cm walls
        probe_bounds: None,
    };
    b.finish(camera, lights, settings)
}

/// DGB §3.6 test scene: a mirror floor (metallic 1, roughness 0) in front of a
/// grey board standing 0.3 m above the floor; 0.3 m behind the board a red
/// emissive panel is hidden from the camera but seen in the mirror under the
/// board's lower edge — only a second deep-G-buffer layer holds it. A blue
/// back wall, a sun from above, a sky for rays that leave.
pub fn mirror() -> Scene {
    let mut b = SceneBuilder::new("mirror");
    let floor = b.material(Material {
        roughness: 0.0,
        metallic: 1.0,
        ..Material::diffuse("mirror_floor", [0.9, 0.9, 0.9])
    });
    let board = b.material(Material::diffuse("board", [0.5, 0.5, 0.5]));
    let panel = b.material(Material {
        emission: [3.0, 0.2, 0.1],
        ..Material::diffuse("red_panel", [0.8, 0.1, 0.05])
    });
    let wall = b.material(Material::diffuse("back_wall", [0.3, 0.4, 0.7]));
    b.geo(floor).rect(v(0.0, 0.0, 1.0), v(0.0, 0.0, 5.0), v(4.0, 0.0, 0.0));
    b.geo(board).quad_facing(
        [v(-1.2, 0.3, 0.0), v(1.2, 0.3, 0.0), v(1.2, 1.6, 0.0), v(-1.2, 1.6, 0.0)],
        v(0.0, 0.0, 1.0),
    );
    b.geo(panel).quad_facing(
        [
            v(-0.8, 0.3, -0.3),
            v(0.8, 0.3, -0.3),
            v(0.8, 1.3, -0.3),
            v(-0.8, 1.3, -0.3),
        ],
        v(0.0, 0.0, 1.0),
    );
    b.geo(wall).rect(v(0.0, 2.0, -3.0), v(4.0, 0.0, 0.0), v(0.0, 2.0, 0.0));
    let sun = Light::Sun {
        direction: v(0.2, -1.0, -0.3).normalize(),
        color: [1.0, 1.0, 1.0],
        illuminance: 2.0,
    };
    let camera = Camera::new(v(0.0, 1.0, 4.0), v(0.0, 0.5, 0.0), Vec3::Y, 50.0, 0.05);
    let settings = SceneSettings {
        ao_radius: 0.5,
        min_separation: 0.2,
        radiosity_radius: 4.0,
        exposure: 1.0,
        sky: [0.4, 0.5, 0.7],
        ambient: [0.03; 3],
        probe_bounds: None,
    };
    b.finish(camera, vec![sun], settings)
}

/// DGB Fig. 13's situation: a foreground object between the camera and what a mirror
/// reflects. A mirror floor (metallic 1, roughness 0) reflects a red wall 2 m behind a
/// grey sign that hangs 0.55–1.2 m above the floor. From the camera the sign hides most
/// of the wall's lower part; the floor's reflection rays reach that part under the sign.
/// Only a second deep-G-buffer layer holds it. The sign is its own object (`sign`), so a
/// test can slide it sideways. A blue back wall, a sun, a sky; no ambient light, so a
/// diffuse surface's shaded radiance is its radiosity B in either layer.
pub fn mirror_sign() -> Scene {
    let mut b = SceneBuilder::new("mirror-sign");
    let floor = b.material(Material {
        roughness: 0.0,
        metallic: 1.0,
        ..Material::diffuse("mirror_floor", [0.9, 0.9, 0.9])
    });
    let wall = b.material(Material::diffuse("red_wall", [0.8, 0.1, 0.05]));
    let back = b.material(Material::diffuse("back_wall", [0.3, 0.4, 0.7]));
    let sign = b.material(Material::diffuse("sign", [0.5, 0.5, 0.5]));
    b.geo(floor).rect(v(0.0, 0.0, 0.5), v(0.0, 0.0, 3.5), v(2.5, 0.0, 0.0));
    b.geo(wall).cuboid(v(-1.5, 0.0, -2.1), v(1.5, 1.5, -2.0));
    b.geo(back).rect(v(0.0, 1.5, -3.0), v(2.5, 0.0, 0.0), v(0.0, 1.5, 0.0));
    let mut board = MeshBuilder::new();
    board.cuboid(v(-0.6, 0.55, -0.05), v(0.6, 1.2, 0.0));
    b.object("sign", board, sign, Mat4::IDENTITY, None);
    let sun = Light::Sun {
        direction: v(0.2, -1.0, -0.4).normalize(),
        color: [1.0, 1.0, 1.0],
        illuminance: 2.0,
    };
    let camera = Camera::new(v(0.0, 1.4, 4.0), v(0.0, 0.4, -1.0), Vec3::Y, 50.0, 0.05);
    let settings = SceneSettings {
        ao_radius: 0.5,
        min_separation: 0.2,
        radiosity_radius: 4.0,
        exposure: 1.0,
        sky: [0.4, 0.5, 0.7],
        ambient: [0.0; 3],
        probe_bounds: None,
    };
    b.finish(camera, vec![sun], settings)
}

/// A-buffer / order-independent-transparency test scene (ABA): an opaque room
/// (floor, back and left walls), opaque blocks and a column, and five
/// coloured glass panes — thin boxes, so each pane is two transparent
/// surfaces — standing one behind the other across the view at different
/// heights and widths, so that they overlap in different combinations; a
/// translucent sphere (α 0.4) in front of an opaque block. Through the
/// centre of the default view a primary ray crosses all five panes (10
/// transparent surfaces) before the sphere and the opaque block behind it.
/// A sun and a point light, a sky, a small ambient term; 1,822 triangles.
pub fn glasshouse() -> Scene {
    let mut b = SceneBuilder::new("glasshouse");
    let floor = b.material(Material::diffuse("floor", [0.55, 0.55, 0.52]));
    let wall = b.material(Material::diffuse("wall", [0.75, 0.72, 0.68]));
    let block = b.material(Material::diffuse("block", [0.7, 0.35, 0.2]));
    let column = b.material(Material::diffuse("column", [0.3, 0.45, 0.7]));
    let glass = |name: &str, rgb: [f32; 3], opacity: f32| Material {
        opacity,
        roughness: 0.1,
        ..Material::diffuse(name, rgb)
    };
    let panes = [
        // (material, centre, half width, half height)
        (glass("glass_red", [0.9, 0.15, 0.1], 0.35), v(-0.3, 1.3, 2.0), 1.6, 1.1),
        (glass("glass_green", [0.15, 0.85, 0.2], 0.3), v(0.5, 1.1, 1.2), 1.5, 1.0),
        (glass("glass_blue", [0.1, 0.3, 0.9], 0.45), v(-0.2, 1.5, 0.4), 1.8, 1.2),
        (
            glass("glass_amber", [0.95, 0.7, 0.1], 0.25),
            v(0.3, 1.0, -0.4),
            1.4,
            0.9,
        ),
        (glass("glass_violet", [0.6, 0.2, 0.8], 0.5), v(0.0, 1.4, -1.2), 1.7, 1.0),
    ];
    let sphere = b.material(glass("glass_sphere", [0.9, 0.9, 0.95], 0.4));

    // Room: 12 × 12 m floor, back wall at z = −4, left wall at x = −4.
    b.geo(floor).rect(v(0.0, 0.0, 0.0), v(0.0, 0.0, 6.0), v(6.0, 0.0, 0.0));
    b.geo(wall).cuboid(v(-6.0, 0.0, -4.3), v(6.0, 4.0, -4.0));
    b.geo(wall).cuboid(v(-4.3, 0.0, -4.0), v(-4.0, 4.0, 6.0));
    // Opaque objects: a block behind the sphere, a low block and a column.
    b.geo(block).cuboid(v(-0.7, 0.0, -3.2), v(0.9, 1.8, -2.6));
    b.geo(block).cuboid(v(1.8, 0.0, -1.8), v(2.6, 0.6, -1.0));
    b.geo(column).cylinder(v(-2.2, 0.0, -2.0), 0.35, 2.8, 48, true);
    // Glass panes, 2 cm thick, perpendicular to the view.
    for (m, c, hw, hh) in panes {
        let mi = b.material(m);
        b.geo(mi).cuboid(c - v(hw, hh, 0.01), c + v(hw, hh, 0.01));
    }
    // The translucent sphere in front of the block.
    b.geo(sphere).sphere(v(0.1, 1.2, -2.0), 0.45, 40, 20);

    let lights = vec![
        Light::Sun {
            direction: v(0.35, -1.0, -0.45).normalize(),
            color: [1.0, 0.96, 0.9],
            illuminance: 3.0,
        },
        Light::Point {
            position: v(1.5, 2.6, 1.6),
            color: [1.0, 0.85, 0.7],
            intensity: 6.0,
        },
    ];
    let camera = Camera::new(v(0.4, 1.5, 6.0), v(0.1, 1.2, -2.0), Vec3::Y, 50.0, 0.05);
    let settings = SceneSettings {
        ao_radius: 0.5,
        min_separation: 0.1,
        radiosity_radius: 4.0,
        exposure: 1.0,
        sky: [0.3, 0.4, 0.55],
        ambient: [0.05; 3],
        probe_bounds: None,
    };
    b.finish(camera, lights, settings)
}

/// `still-life` dimensions (metres) the tests need.
pub mod still_life_dims {
    use glam::Vec3;
    /// The emitter quad: centre, half extents (it faces +X).
    pub const EMITTER_CENTRE: Vec3 = Vec3::new(-3.6, 1.0, -0.9);
    pub const EMITTER_HALF_Y: f32 = 0.6;
    pub const EMITTER_HALF_Z: f32 = 0.4;
    /// The hollow "skull" box: outer bounds and wall thickness; open toward +Z.
    pub const SKULL_MIN: Vec3 = Vec3::new(0.15, 0.0, -0.45);
    pub const SKULL_MAX: Vec3 = Vec3::new(0.75, 0.45, 0.05);
    pub const SKULL_WALL: f32 = 0.04;
}

/// Bounced z-buffer (Nalbach et al. 2016) Fig. 1 / Fig. 8 "still life", built
/// from primitives: a red cloth, a back wall with raised yellow letters
/// ("LIT"), a glossy gold sphere (metal, roughness 0.25), a glossy blue vase
/// (dielectric, roughness 0.15), two diffuse pears, and the "skull": a hollow
/// bone-white box open toward the camera (+Z). The only light is an orange
/// emissive quad (radiance (16, 7.2, 2.4)) at x = −3.6 facing +X, outside the
/// view (≥ 40° off the camera axis) but lighting the objects from the left,
/// with a matching [`Light::Rect`] for the GPU; black sky. Every point of
/// the emitter has z ≤ −0.5 while the skull's opening is the plane z = 0.05, so
/// no segment from the emitter reaches its inside: only indirect light can
/// (screen-space GI wrongly lights it from the cloth, as in the paper).
pub fn still_life() -> Scene {
    use still_life_dims::*;
    let mut b = SceneBuilder::new("still-life");
    let cloth = b.material(Material {
        roughness: 1.0,
        ..Material::diffuse("cloth", [0.55, 0.1, 0.08])
    });
    let wall = b.material(Material {
        roughness: 1.0,
        ..Material::diffuse("wall", [0.7, 0.68, 0.62])
    });
    let letters = b.material(Material {
        roughness: 1.0,
        ..Material::diffuse("letters", [0.85, 0.65, 0.1])
    });
    let bone = b.material(Material {
        roughness: 1.0,
        ..Material::diffuse("skull", [0.8, 0.77, 0.68])
    });
    let pear = b.material(Material {
        roughness: 1.0,
        ..Material::diffuse("pear", [0.45, 0.55, 0.08])
    });
    let gold = b.material(Material::glossy("gold", [1.0, 0.78, 0.34], 0.25, 1.0));
    let vase = b.material(Material::glossy("vase", [0.08, 0.2, 0.65], 0.15, 0.0));
    let light_rgb = [16.0, 7.2, 2.4];
    let lamp = b.material(Material::emissive("lamp", light_rgb));

    // cloth (floor) 8 × 6 m, back wall at z = −1.5
    b.geo(cloth).rect(v(0.0, 0.0, 0.5), v(0.0, 0.0, 3.0), v(4.0, 0.0, 0.0));
    b.geo(wall).rect(v(0.0, 1.5, -1.5), v(4.0, 0.0, 0.0), v(0.0, 1.5, 0.0));
    // raised letters "LIT" on the wall (5 cm deep)
    let (z0, z1) = (-1.5, -1.45);
    let bar = |b: &mut SceneBuilder, x0: f32, y0: f32, x1: f32, y1: f32| {
        b.geo(letters).cuboid(v(x0, y0, z0), v(x1, y1, z1));
    };
    // L
    bar(&mut b, -1.3, 0.8, -1.2, 1.5);
    bar(&mut b, -1.2, 0.8, -0.9, 0.9);
    // I
    bar(&mut b, -0.6, 0.8, -0.5, 1.5);
    // T
    bar(&mut b, -0.2, 1.4, 0.3, 1.5);
    bar(&mut b, 0.0, 0.8, 0.1, 1.4);
    // the skull: five walls, open toward +Z
    let (lo, hi, t) = (SKULL_MIN, SKULL_MAX, SKULL_WALL);
    b.geo(bone).cuboid(lo, v(hi.x, lo.y + t, hi.z)); // bottom
    b.geo(bone).cuboid(v(lo.x, hi.y - t, lo.z), hi); // top
    b.geo(bone).cuboid(v(lo.x, lo.y + t, lo.z), v(lo.x + t, hi.y - t, hi.z)); // left
    b.geo(bone).cuboid(v(hi.x - t, lo.y + t, lo.z), v(hi.x, hi.y - t, hi.z)); // right
    b.geo(bone)
        .cuboid(v(lo.x + t, lo.y + t, lo.z), v(hi.x - t, hi.y - t, lo.z + t)); // back
                                                                               // glossy objects
    b.geo(gold).sphere(v(-0.55, 0.3, -0.3), 0.3, 48, 24);
    b.geo(vase).cylinder(v(1.25, 0.0, -0.6), 0.16, 0.7, 40, true);
    // pears
    b.geo(pear).sphere(v(-1.15, 0.14, 0.45), 0.14, 32, 16);
    b.geo(pear).sphere(v(-1.0, 0.27, 0.45), 0.09, 32, 16);
    b.geo(pear).sphere(v(-0.7, 0.12, 0.7), 0.12, 32, 16);
    // the emitter, facing +X (half_u × half_v = Y × Z = +X)
    let (hu, hv) = (v(0.0, EMITTER_HALF_Y, 0.0), v(0.0, 0.0, EMITTER_HALF_Z));
    b.geo(lamp).rect(EMITTER_CENTRE, hu, hv);
    let lights = vec![Light::Rect {
        center: EMITTER_CENTRE,
        half_u: hu,
        half_v: hv,
        radiance: light_rgb,
    }];
    let camera = Camera::new(v(0.3, 1.1, 3.2), v(0.0, 0.35, -0.3), Vec3::Y, 38.0, 0.05);
    let settings = SceneSettings {
        ao_radius: 0.3,
        min_separation: 0.05,
        radiosity_radius: 1.5,
        exposure: 1.0,
        sky: [0.0; 3],
        ambient: [0.01; 3],
        probe_bounds: None,
    };
    b.finish(camera, lights, settings)
}

/// Number of dominoes in [`dominoes`].
pub const DOMINO_COUNT: usize = 115;

/// Bounced z-buffer Fig. 8 (last rows): [`DOMINO_COUNT`] dominoes (10 × 20 × 3
/// cm boxes, 12 triangles each) in six glossy
/// plastic colours (dielectric, roughness 0.4), standing along an Archimedean
/// spiral 8 cm apart, on a polished metal floor (metallic 1, roughness 0.12):
/// 1,382 triangles. A low warm sun from the side and a blue sky; much of the
/// coloured light the floor and the dominoes exchange comes from faces the
/// camera does not see.
pub fn dominoes() -> Scene {
    let mut b = SceneBuilder::new("dominoes");
    let floor = b.material(Material::glossy("floor", [0.62, 0.62, 0.64], 0.12, 1.0));
    let colours: [(&str, [f32; 3]); 6] = [
        ("domino_red", [0.8, 0.08, 0.06]),
        ("domino_orange", [0.9, 0.4, 0.05]),
        ("domino_yellow", [0.85, 0.75, 0.1]),
        ("domino_green", [0.1, 0.6, 0.15]),
        ("domino_blue", [0.06, 0.2, 0.8]),
        ("domino_purple", [0.5, 0.1, 0.7]),
    ];
    let mats: Vec<usize> = colours
        .iter()
        .map(|(n, c)| b.material(Material::glossy(n, *c, 0.4, 0.0)))
        .collect();
    b.geo(floor).rect(v(0.0, 0.0, 0.0), v(0.0, 0.0, 4.0), v(4.0, 0.0, 0.0));
    let (half_w, half_h, half_t) = (0.05, 0.1, 0.015);
    let (r0, pitch, spacing) = (0.35f32, 0.22f32, 0.08f32);
    let mut theta = 0.0f32;
    for i in 0..DOMINO_COUNT {
        let r = r0 + pitch * theta / std::f32::consts::TAU;
        let p = v(r * theta.cos(), half_h, r * theta.sin());
        // tangent of the spiral: d/dθ (r cos θ, r sin θ)
        let dr = pitch / std::f32::consts::TAU;
        let tangent = v(
            dr * theta.cos() - r * theta.sin(),
            0.0,
            dr * theta.sin() + r * theta.cos(),
        )
        .normalize();
        let across = Vec3::Y.cross(tangent);
        b.geo(mats[i % mats.len()])
            .oriented_box(p, [across * half_w, Vec3::Y * half_h, tangent * half_t]);
        theta += spacing / r;
    }
    let sun = Light::Sun {
        direction: v(-0.7, -0.45, -0.35).normalize(),
        color: [1.0, 0.9, 0.75],
        illuminance: 3.0,
    };
    let camera = Camera::new(v(0.3, 1.15, 2.1), v(0.0, 0.0, 0.05), Vec3::Y, 40.0, 0.05);
    let settings = SceneSettings {
        ao_radius: 0.12,
        min_separation: 0.02,
        radiosity_radius: 0.6,
        exposure: 1.0,
        sky: [0.25, 0.3, 0.4],
        ambient: [0.03; 3],
        probe_bounds: None,
    };
    b.finish(camera, vec![sun], settings)
}
