//! The window, the frame loop and the state behind the panels.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use strata_render::display::DisplayEncoder;
use strata_render::frame::FrameCameras;
use strata_render::technique::Technique;
use strata_render::{GpuContext, GpuOptions, RenderError, RenderSettings, Renderer};
use strata_scene::path::Keyframe;
use strata_scene::{Camera, ImageBuf, Scene};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use crate::camera::{CameraControl, Input, Key, Mode};
use crate::script::{Event, Script};
use crate::{Action, RenderSpec, SettingsFn, ViewOptions};

/// Frames of timing history in the chart.
pub const HISTORY: usize = 90;
/// Width of the settings panel and height of the timing panel, in points.
pub const PANEL_WIDTH: f32 = 360.0;
pub const BOTTOM_HEIGHT: f32 = 200.0;

pub struct FrameTiming {
    pub passes: Vec<(String, f64)>,
    /// Wall-clock time of the whole frame (3D, read-back, UI, present), ms.
    pub frame_ms: f64,
    pub reduced: bool,
}

struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: GpuContext,
    egui_state: egui_winit::State,
    egui_rend: egui_wgpu::Renderer,
    /// Encodes the shown target into the viewport's texture on the GPU.
    display: DisplayEncoder,
    /// That texture as egui knows it: its id, size and filter.
    native: Option<(egui::TextureId, [u32; 2], wgpu::FilterMode)>,
    /// `STRATA_VIEW_READBACK=1`: show every frame through the CPU as before the GPU
    /// encoder (to measure what it saves; `docs/viewer.md`).
    read_back: bool,
}

/// The last frame shown: the image exactly as `strata render` would save it.
pub struct Shown {
    /// The image, once read back: debug views always; the technique's display target only
    /// when a screenshot, false colour or a renderer about to be replaced needs it (the
    /// window shows it from the GPU, [`DisplayEncoder`]).
    pub image: Option<ImageBuf>,
    /// The target of the renderer that drew the frame (full or reduced) holding it while
    /// `image` is not read back.
    pub target: Option<&'static str>,
    pub width: u32,
    pub height: u32,
    pub srgb: bool,
    pub full: bool,
    pub camera: Camera,
    /// The exposure this frame was tonemapped with. Under auto-exposure it is read back
    /// without waiting, so it may be an earlier frame's until `exposure_exact` (set when
    /// the frame is read back for a screenshot); `None` before the first arrives.
    pub exposure: Option<f32>,
    pub exposure_exact: bool,
}

pub struct App {
    gfx: Option<Gfx>,
    pub(crate) settings_fn: SettingsFn,
    /// Per-frame VPLs for ILS in scenes with animated objects (`ViewOptions::vpls`).
    vpls_fn: Option<crate::VplsFn>,
    /// The frame the full and the reduced renderer's VPLs were made for (None: as built).
    vpls_at: [Option<f32>; 2],
    pub(crate) adapter_opt: Option<String>,
    pub(crate) adapter_name: String,
    pub(crate) scene: Scene,
    pub(crate) scene_spec: String,
    pub(crate) camera_index: Option<usize>,
    pub(crate) spec: RenderSpec,
    pub(crate) settings: Option<RenderSettings>,
    full: Option<Renderer>,
    reduced: Option<Renderer>,
    reduced_tried: bool,
    /// Which renderer drew the last frame: 0 none, 1 full, 2 reduced.
    used_last: u8,
    pub(crate) cam: CameraControl,
    prev_cam: Option<Camera>,
    pub(crate) frame_t: f32,
    pub(crate) playing: bool,
    pub(crate) looping: bool,
    pub(crate) recording: Option<Vec<Keyframe>>,
    pub(crate) record_path: String,
    record_start: u32,
    pub(crate) debug_view: Option<String>,
    pub(crate) view_names: Vec<String>,
    /// The viewport's texture when the CPU encodes it (debug views, false colour).
    texture: Option<egui::TextureHandle>,
    /// The texture the viewport draws: `texture`'s, or the GPU-encoded one.
    pub(crate) viewport_tex: Option<egui::TextureId>,
    /// The display gain and false colour the viewport texture was made with.
    display_key: Option<(f32, bool)>,
    pub(crate) shown: Option<Shown>,
    pub(crate) timings: VecDeque<FrameTiming>,
    pub(crate) status: Option<(String, bool)>,
    pub(crate) frames_done: u32,
    /// Frames the full renderer drew in a row with the same camera and settings.
    pub(crate) still_frames: u32,
    pub(crate) actions: Vec<Action>,
    pending_shot: Option<Option<PathBuf>>,
    shot_counter: u32,
    pub(crate) open_text: String,
    pub(crate) setting_text: std::collections::HashMap<String, String>,
    pub(crate) guard_text: String,
    /// The exposure field's text (empty: the scene's).
    pub(crate) exposure_text: String,
    pub(crate) fit_window: bool,
    pub(crate) render_size: (u32, u32),
    pub(crate) viewport_px: (u32, u32),
    /// The viewport panel in physical pixels (x0, y0, x1, y1).
    pub(crate) viewport_rect: Option<[f32; 4]>,
    pub(crate) motion_scale: f32,
    pub(crate) gain: f32,
    pub(crate) false_colour: bool,
    pub(crate) last_frame_ms: f64,
    frames: Option<u32>,
    screenshot: Option<PathBuf>,
    window_screenshot: Option<PathBuf>,
    script: Option<Script>,
    look_active: bool,
    last_cursor: Option<(f64, f64)>,
    last_instant: Instant,
    fatal: Option<String>,
    /// The 3D frame failed with these settings: not retried until they change.
    broken: bool,
    /// Nothing left to draw until an event arrives: the event loop waits instead of
    /// redrawing (set after each frame, cleared by any window event).
    idle: bool,
    /// egui asked to be drawn again after this long (a blinking cursor, a tooltip).
    repaint_after: Option<std::time::Duration>,
}

/// Still frames after which an interactive viewer stops drawing: a temporal technique's
/// history converges over the 60 frames `--warmup` reproduces; others need the frame that
/// single-pass layers build from the last one.
const SETTLE_TEMPORAL: u32 = 61;
const SETTLE: u32 = 3;

fn scene_scale(scene: &Scene) -> f32 {
    let (lo, hi) = scene.bounds(0.0);
    (hi - lo).length().max(1e-3)
}

impl App {
    fn new(o: ViewOptions) -> App {
        let scale = scene_scale(&o.scene);
        App {
            gfx: None,
            settings_fn: o.settings,
            vpls_fn: o.vpls,
            vpls_at: [None; 2],
            adapter_opt: o.adapter,
            adapter_name: String::new(),
            cam: CameraControl::new(o.camera, scale),
            scene: o.scene,
            scene_spec: o.scene_spec,
            camera_index: o.camera_index,
            guard_text: o.spec.guard_band.clone(),
            exposure_text: o.spec.exposure.clone().unwrap_or_default(),
            spec: o.spec,
            settings: None,
            full: None,
            reduced: None,
            reduced_tried: false,
            used_last: 0,
            prev_cam: None,
            frame_t: o.frame,
            playing: false,
            looping: true,
            recording: None,
            record_path: "recorded-path.toml".into(),
            record_start: 0,
            debug_view: o.debug_view,
            view_names: Vec::new(),
            texture: None,
            viewport_tex: None,
            display_key: None,
            shown: None,
            timings: VecDeque::new(),
            status: None,
            frames_done: 0,
            still_frames: 0,
            idle: false,
            repaint_after: None,
            actions: Vec::new(),
            pending_shot: None,
            shot_counter: 0,
            open_text: String::new(),
            setting_text: Default::default(),
            fit_window: false,
            render_size: (o.width, o.height),
            viewport_px: (o.width, o.height),
            viewport_rect: None,
            motion_scale: o.motion_scale,
            gain: 1.0,
            false_colour: false,
            last_frame_ms: 0.0,
            frames: o.frames,
            screenshot: o.screenshot,
            window_screenshot: o.window_screenshot,
            script: o.script,
            look_active: false,
            last_cursor: None,
            last_instant: Instant::now(),
            fatal: None,
            broken: false,
        }
    }

    /// Nothing changes from frame to frame any more: not scripted, not playing, no action,
    /// screenshot or camera move pending, and the full renderer drew enough still frames
    /// (or failed). Interactive frames then draw only the UI, and the loop waits.
    fn settled(&self) -> bool {
        let accumulates = self.full.as_ref().is_some_and(|r| r.accumulates());
        let settle = if accumulates { SETTLE_TEMPORAL } else { SETTLE };
        self.frames.is_none()
            && !self.playing
            && self.actions.is_empty()
            && self.pending_shot.is_none()
            && self.screenshot.is_none()
            && !self.cam.active()
            && (self.broken || self.still_frames >= settle)
    }

    /// The shown frame is one `strata render` reproduces (see [`App::reproduce_command`]).
    fn shot_ready(&self) -> bool {
        let need = 1 + self.settings.as_ref().is_some_and(|s| s.deep.uses_history()) as u32;
        self.broken || (self.shown.as_ref().is_some_and(|s| s.full) && self.still_frames >= need)
    }

    /// The pointer is over the 3D viewport (not a panel).
    fn cursor_in_viewport(&self) -> bool {
        match (self.last_cursor, self.viewport_rect) {
            (Some((x, y)), Some([x0, y0, x1, y1])) => (x0..x1).contains(&(x as f32)) && (y0..y1).contains(&(y as f32)),
            _ => false,
        }
    }

    pub(crate) fn technique(&self) -> &'static Technique {
        strata_render::technique::find(&self.spec.technique).unwrap_or(&strata_render::technique::registry()[0])
    }

    /// A message in the status line (and on stderr, where scripts and tests read it).
    pub(crate) fn say(&mut self, msg: String, error: bool) {
        if error {
            eprintln!("strata view: error: {msg}");
        } else {
            eprintln!("strata view: {msg}");
        }
        self.status = Some((msg, error));
    }

    /// The `strata render` flags of the current view at `w`×`h` (scene, size, frame, spec).
    fn render_args(&self, spec: &RenderSpec, w: u32, h: u32) -> Vec<String> {
        let mut a = vec![
            "--scene".to_string(),
            self.scene_spec.clone(),
            "--width".into(),
            w.to_string(),
            "--height".into(),
            h.to_string(),
            "--frame".into(),
            self.frame_t.to_string(),
        ];
        if let Some(c) = self.camera_index {
            a.extend(["--camera".to_string(), c.to_string()]);
        }
        a.extend(spec.args());
        a
    }

    /// Settings for `spec` through the CLI's validation, then a renderer for them; on any
    /// error the current ones stay and the error is shown.
    fn apply_spec(&mut self, spec: RenderSpec, scene: Option<Scene>) -> bool {
        let Some(gfx) = self.gfx.as_ref() else {
            return false;
        };
        let scene_ref = scene.as_ref().unwrap_or(&self.scene);
        let (w, h) = self.render_size;
        let args = self.render_args(&spec, w, h);
        let settings = match (self.settings_fn)(scene_ref, &args) {
            Ok(s) => s,
            Err(e) => {
                self.say(e, true);
                return false;
            }
        };
        // `render`'s cost warning (a bzb-gi frame of minutes), before the frame that takes them
        let warning = settings.cost_warning(scene_ref);
        match Renderer::new(&gfx.gpu, scene_ref, settings.clone()) {
            Ok(r) => {
                // the shown frame stays on screen (and can be saved) after its renderer goes
                if let Err(e) = read_back_shown(&mut self.shown, &self.full, &self.reduced, &gfx.gpu) {
                    self.shown = None;
                    self.say(one_line(&e.to_string()), true);
                }
                self.view_names = r.debug_view_names();
                self.full = Some(r);
                self.reduced = None;
                self.vpls_at = [None; 2];
                self.reduced_tried = false;
                self.used_last = 0;
                self.settings = Some(settings);
                self.spec = spec;
                self.guard_text = self.spec.guard_band.clone();
                self.exposure_text = self.spec.exposure.clone().unwrap_or_default();
                self.setting_text.clear();
                self.broken = false;
                self.still_frames = 0;
                if let Some(s) = scene {
                    self.scene = s;
                }
                if let Some(v) = &self.debug_view {
                    if !self.view_names.contains(v) {
                        let v = v.clone();
                        self.debug_view = None;
                        self.say(
                            format!("debug view '{v}' is not in this frame: showing the final image"),
                            false,
                        );
                    }
                }
                if let Some(w) = warning {
                    self.say(format!("warning: {w}"), false);
                }
                true
            }
            Err(e) => {
                self.say(one_line(&e.to_string()), true);
                false
            }
        }
    }

    fn process_actions(&mut self) {
        if self.pending_shot.is_some() {
            // a screenshot waits for its frame: nothing after it applies before it is saved
            return;
        }
        let mut list = std::mem::take(&mut self.actions);
        let mut done = 0;
        while done < list.len() {
            let a = list[done].clone();
            done += 1;
            match a {
                Action::Technique(name) => match strata_render::technique::find(&name) {
                    Ok(t) => {
                        let s = self.spec.with_technique(t);
                        self.apply_spec(s, None);
                    }
                    Err(e) => self.say(e.to_string(), true),
                },
                Action::Preset(p) => {
                    let mut s = self.spec.clone();
                    s.preset = Some(p);
                    self.apply_spec(s, None);
                }
                Action::Layers(n) => {
                    let mut s = self.spec.clone();
                    s.layers = n;
                    self.apply_spec(s, None);
                }
                Action::Variant(v) => {
                    let mut s = self.spec.clone();
                    s.variant = v;
                    self.apply_spec(s, None);
                }
                Action::LayerScale(n) => {
                    let mut s = self.spec.clone();
                    s.layer_scale = n;
                    self.apply_spec(s, None);
                }
                Action::GuardBand(g) => {
                    let mut s = self.spec.clone();
                    s.guard_band = g;
                    if !self.apply_spec(s, None) {
                        self.guard_text = self.spec.guard_band.clone();
                    }
                }
                Action::Exposure(e) => {
                    let mut s = self.spec.clone();
                    s.exposure = e;
                    // the field is the one place for the exposure: it replaces a fixed
                    // `--set exposure=X`, which auto-exposure would refuse beside it
                    s.sets.retain(|(n, _)| n != "exposure");
                    if !self.apply_spec(s, None) {
                        self.exposure_text = self.spec.exposure.clone().unwrap_or_default();
                    }
                }
                Action::Set(n, v) => {
                    let s = self.spec.with_set(&n, &v);
                    self.apply_spec(s, None);
                }
                Action::DebugView(v) => match v {
                    Some(v) if !self.view_names.contains(&v) => self.say(
                        format!(
                            "unknown debug view '{v}': valid views are {}",
                            self.view_names.join(", ")
                        ),
                        true,
                    ),
                    v => {
                        self.debug_view = v;
                        self.broken = false;
                    }
                },
                Action::Mode(m) => self.cam.mode = m,
                Action::Open(p) => self.open(p.trim()),
                Action::Screenshot(p) => {
                    // it shows the state up to here: later actions wait for the next frame
                    self.pending_shot = Some(p);
                    break;
                }
                Action::Play(on) => {
                    if self.scene.camera_path.is_some() {
                        self.playing = on;
                    } else if on {
                        self.say(format!("scene '{}' has no camera path to play", self.scene.name), true);
                    }
                }
                Action::Seek(f) => {
                    if let Some(p) = &self.scene.camera_path {
                        self.frame_t = f.clamp(p.first_frame(), p.last_frame());
                        let c = self.scene.camera_at(self.frame_t);
                        self.cam.set(c);
                    }
                }
                Action::Loop(on) => self.looping = on,
                Action::Record(None) => {
                    self.recording = Some(Vec::new());
                    self.record_start = self.frames_done;
                    self.say("recording the camera path".into(), false);
                }
                Action::Record(Some(path)) => self.stop_recording(&path),
                Action::MotionScale(s) => {
                    if (0.1..=1.0).contains(&s) {
                        self.motion_scale = s;
                        // a frame of the reduced renderer stays on screen after it goes
                        if let Some(g) = self
                            .gfx
                            .as_ref()
                            .filter(|_| self.shown.as_ref().is_some_and(|s| !s.full))
                        {
                            if read_back_shown(&mut self.shown, &self.full, &self.reduced, &g.gpu).is_err() {
                                self.shown = None;
                            }
                        }
                        self.reduced = None;
                        self.vpls_at[1] = None;
                        self.reduced_tried = false;
                    } else {
                        self.say(format!("motion scale {s} is out of range: must be in 0.1..=1"), true);
                    }
                }
                Action::Fit(on) => self.fit_window = on,
                Action::Gain(g) => {
                    if (0.125..=16.0).contains(&g) {
                        self.gain = g;
                    } else {
                        self.say(format!("gain {g} is out of range: must be in 0.125..=16"), true);
                    }
                }
                Action::FalseColour(on) => self.false_colour = on,
                Action::Resize(w, h) => {
                    if let Some(g) = &self.gfx {
                        let _ = g.window.request_inner_size(winit::dpi::PhysicalSize::new(w, h));
                    }
                }
            }
        }
        // the rest (after a screenshot) go first next frame
        let rest = list.split_off(done);
        self.actions = rest.into_iter().chain(std::mem::take(&mut self.actions)).collect();
    }

    /// Loads a scene file; a bad one leaves the current scene and shows the loader's error.
    fn open(&mut self, path: &str) {
        if path.is_empty() {
            self.say(
                "open: give a .gltf, .glb, .obj or .toml file (or a built-in scene name)".into(),
                true,
            );
            return;
        }
        let scene = match strata_scene::load_scene(path) {
            Ok(s) => s,
            Err(e) => {
                self.say(format!("open: {}", one_line(&e.to_string())), true);
                return;
            }
        };
        let old_spec = std::mem::replace(&mut self.scene_spec, path.to_string());
        let old_index = self.camera_index.take();
        let old_t = self.frame_t;
        self.frame_t = scene.camera_path.as_ref().map_or(0.0, |p| p.first_frame());
        let cam = scene.camera_at(self.frame_t);
        let scale = scene_scale(&scene);
        let name = scene.name.clone();
        let spec = self.spec.clone();
        if self.apply_spec(spec, Some(scene)) {
            let mode = self.cam.mode;
            self.cam = CameraControl::new(cam, scale);
            self.cam.mode = mode;
            self.playing = false;
            self.recording = None;
            self.prev_cam = None;
            self.say(format!("opened '{name}' ({path})"), false);
        } else {
            self.scene_spec = old_spec;
            self.camera_index = old_index;
            self.frame_t = old_t;
        }
    }

    fn stop_recording(&mut self, path: &Path) {
        let Some(keys) = self.recording.take() else {
            self.say("record-stop: not recording".into(), true);
            return;
        };
        match write_path_scene(path, &self.scene_spec, &keys, &self.cam.camera()) {
            Ok(()) => self.say(
                format!(
                    "wrote camera path of {} keyframes to {} (strata render --scene {} --frame F)",
                    keys.len(),
                    path.display(),
                    path.display()
                ),
                false,
            ),
            Err(e) => self.say(e, true),
        }
    }

    fn reduced_settings(&self) -> Option<RenderSettings> {
        let s = self.settings.as_ref()?;
        let f = self.motion_scale;
        let mut r = s.clone();
        r.width = ((s.width as f32 * f).round() as u32).max(strata_render::renderer::MIN_SIZE);
        r.height = ((s.height as f32 * f).round() as u32).max(strata_render::renderer::MIN_SIZE);
        r.validate().ok()?;
        Some(r)
    }

    /// Renders the 3D frame; the viewport shows its display target from the GPU (debug
    /// views are read back and encoded on the CPU).
    fn render_3d(&mut self, gpu: &GpuContext, reduced: bool, cam: Camera) -> Result<Option<FrameTiming>, RenderError> {
        if self.full.is_none() || self.broken {
            return Ok(None);
        }
        if reduced && self.reduced.is_none() && !self.reduced_tried {
            // once per settings: when it cannot be built, moving frames stay full size
            self.reduced_tried = true;
            if let Some(s) = self.reduced_settings() {
                self.reduced = Renderer::new(gpu, &self.scene, s).ok();
                self.vpls_at[1] = None;
            }
        }
        let use_reduced = reduced && self.reduced.is_some();
        let which = if use_reduced { 2 } else { 1 };
        let r = if use_reduced {
            self.reduced.as_mut()
        } else {
            self.full.as_mut()
        }
        .expect("checked");
        let continuing = self.used_last == which;
        if !continuing {
            // its history is from an older camera
            r.reset_history();
        }
        let cams = FrameCameras {
            previous: if continuing { self.prev_cam.unwrap_or(cam) } else { cam },
            current: cam,
            next_view: cam.view(),
        };
        // ILS in a scene with moving objects: the VPLs of this frame's geometry
        if let (Some(vpls), Some(ils)) = (&self.vpls_fn, &r.settings.ils) {
            if self.scene.animated() && self.vpls_at[which as usize - 1] != Some(self.frame_t) {
                let v = vpls(&self.scene, self.frame_t, ils.vpl_count);
                r.set_vpls(gpu, &v)?;
                self.vpls_at[which as usize - 1] = Some(self.frame_t);
            }
        }
        let t = r.render(gpu, &self.scene, &cams, self.frame_t)?;
        let metered = r.settings.auto_exposure.is_some();
        let exposure = r
            .latest_exposure(gpu)
            .or_else(|| self.shown.as_ref().and_then(|s| s.exposure));
        let t_name = strata_render::technique::find(&self.spec.technique).map(|t| t.display);
        let (image, srgb, target, [width, height]) = match &self.debug_view {
            Some(v) => {
                let i = r.debug_view(gpu, v, false)?;
                let size = [i.width, i.height];
                (Some(i), true, None, size)
            }
            None => {
                let (target, srgb) = t_name.unwrap_or(("ldr", true));
                match r.display_region(target) {
                    // shown from the GPU; read back only when needed
                    Some(g) if strata_render::display::supports(g.texture.format()) => {
                        (None, srgb, Some(target), g.size)
                    }
                    _ => {
                        let i = r.read_target(gpu, target)?;
                        let size = [i.width, i.height];
                        (Some(i), srgb, None, size)
                    }
                }
            }
        };
        self.used_last = which;
        if !use_reduced && continuing && self.prev_cam == Some(cam) {
            self.still_frames += 1;
        } else {
            self.still_frames = if use_reduced { 0 } else { 1 };
        }
        self.prev_cam = Some(cam);
        self.shown = Some(Shown {
            image,
            target,
            width,
            height,
            srgb,
            full: !use_reduced,
            camera: cam,
            exposure,
            exposure_exact: !metered,
        });
        Ok(Some(FrameTiming {
            passes: t.passes,
            frame_ms: 0.0,
            reduced: use_reduced,
        }))
    }

    /// Makes the viewport's texture for the shown frame: encoded on the GPU from the
    /// renderer's target (`strata_render::display`, the same bytes as below), or from the
    /// read-back image for debug views and false colour.
    fn show(&mut self, gfx: &mut Gfx) -> Result<(), RenderError> {
        let s = self.shown.as_ref().expect("checked by the caller");
        let filter = if s.full {
            wgpu::FilterMode::Nearest
        } else {
            wgpu::FilterMode::Linear
        };
        let source = if s.full { &self.full } else { &self.reduced };
        let region = s
            .target
            .filter(|_| s.image.is_none() && !self.false_colour && !gfx.read_back)
            .and_then(|t| source.as_ref()?.display_region(t));
        if let Some(region) = region {
            gfx.display.encode(&gfx.gpu, &region, s.srgb, self.gain)?;
            let (out, view) = gfx.display.output().expect("encoded above");
            let size = [out.width(), out.height()];
            let id = match gfx.native {
                Some((id, sz, f)) if sz == size && f == filter => id,
                Some((id, _, _)) => {
                    gfx.egui_rend
                        .update_egui_texture_from_wgpu_texture(&gfx.gpu.device, view, filter, id);
                    id
                }
                None => gfx.egui_rend.register_native_texture(&gfx.gpu.device, view, filter),
            };
            gfx.native = Some((id, size, filter));
            self.viewport_tex = Some(id);
            return Ok(());
        }
        read_back_shown(&mut self.shown, &self.full, &self.reduced, &gfx.gpu)?;
        let s = self.shown.as_ref().expect("checked by the caller");
        let Some(image) = &s.image else {
            return Ok(());
        };
        let bytes = self.display_bytes(s, image);
        let img = egui::ColorImage::from_rgba_unmultiplied([image.width as usize, image.height as usize], &bytes);
        // full frames are shown 1:1 (nearest); reduced ones are upscaled (linear)
        let filter = if s.full {
            egui::TextureOptions::NEAREST
        } else {
            egui::TextureOptions::LINEAR
        };
        match &mut self.texture {
            Some(t) => t.set(img, filter),
            None => self.texture = Some(gfx.egui_state.egui_ctx().load_texture("viewport", img, filter)),
        }
        self.viewport_tex = self.texture.as_ref().map(|t| t.id());
        Ok(())
    }

    /// The bytes the viewport texture shows (display gain and false colour applied).
    fn display_bytes(&self, s: &Shown, img: &ImageBuf) -> Vec<u8> {
        let mut img = img.clone();
        if self.false_colour && img.channels == 1 {
            let max = img.data.iter().cloned().fold(0.0f32, f32::max).max(1e-9);
            let mut c = ImageBuf::new(img.width, img.height, 3);
            for (o, v) in c.data.chunks_exact_mut(3).zip(&img.data) {
                o.copy_from_slice(&heat((v / max * self.gain).clamp(0.0, 1.0)));
            }
            img = c;
        } else if self.gain != 1.0 {
            img.data.iter_mut().for_each(|v| *v *= self.gain);
        }
        let mut b = img.to_rgba8(s.srgb);
        // opaque on screen (the PNG keeps the target's alpha)
        b.chunks_exact_mut(4).for_each(|p| p[3] = 255);
        b
    }

    /// The exact `strata render` command for the shown frame, writing `out`.
    pub(crate) fn reproduce_command(&self, cam: &Camera, out: &Path) -> String {
        // the frame's size (a debug view of a target with its own size, e.g. ILS's tiled
        // buffers, is an image of another size)
        let (w, h) = self.settings.as_ref().map_or(self.render_size, |s| (s.width, s.height));
        let mut a = vec!["strata".to_string(), "render".into()];
        let v = |p: glam::Vec3| format!("{},{},{}", p.x, p.y, p.z);
        let mut r = self.render_args(&self.spec, w, h);
        // camera flags after the scene/size/frame ones
        let tail = r.split_off(8);
        a.extend(r);
        a.extend([
            "--eye".to_string(),
            v(cam.eye),
            "--target".into(),
            v(cam.target),
            "--up".into(),
            v(cam.up),
            "--fov".into(),
            cam.fov_y_deg.to_string(),
        ]);
        a.extend(tail);
        if let Some(d) = &self.debug_view {
            a.extend(["--debug-view".to_string(), d.clone()]);
        }
        // temporal filters and progressive bounces: as many static frames as the viewer drew
        // (always given: `render`'s own default warms an accumulating frame up)
        let warm = self.still_frames.saturating_sub(1).min(60);
        a.extend(["--warmup".to_string(), warm.to_string()]);
        a.extend(["--out".to_string(), out.display().to_string()]);
        a.iter().map(|s| crate::shell_quote(s)).collect::<Vec<_>>().join(" ")
    }

    fn save_screenshot(&mut self, path: Option<PathBuf>) {
        let Some(s) = self.shown.as_ref().filter(|s| s.full) else {
            self.say("screenshot: no full-resolution frame to save yet".into(), true);
            return;
        };
        let path = path.unwrap_or_else(|| loop {
            self.shot_counter += 1;
            let p = PathBuf::from(format!("strata-view-{:03}.png", self.shot_counter));
            if !p.exists() {
                break p;
            }
        });
        if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
            self.say(format!("screenshot {}: use a .png file name", path.display()), true);
            return;
        }
        if let Some(d) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            let _ = std::fs::create_dir_all(d);
        }
        let stem = path.with_extension("");
        let out = PathBuf::from(format!("{}.render.png", stem.display()));
        let cmd = self.reproduce_command(&s.camera, &out);
        let mut note = String::new();
        if self.gain != 1.0 || self.false_colour {
            note = "# the viewer's display gain / false colour are not in the PNG or the command\n".into();
        }
        if self.spec.exposure.as_deref().is_some_and(|e| e.starts_with("auto")) {
            // as `render` prints it, so the two can be compared
            note += &format!("# exposure (metered): {:.4}\n", s.exposure.unwrap_or(f32::NAN));
        }
        let Some(image) = &s.image else {
            self.say("screenshot: the frame was not read back".into(), true);
            return;
        };
        if let Err(e) = image.save(&path, s.srgb) {
            self.say(e, true);
            return;
        }
        let cmd_path = PathBuf::from(format!("{}.cmd.txt", stem.display()));
        if let Err(e) = std::fs::write(&cmd_path, format!("{cmd}\n{note}")) {
            self.say(format!("{}: cannot write: {e}", cmd_path.display()), true);
            return;
        }
        println!("{cmd}");
        self.say(format!("saved {} and {}", path.display(), cmd_path.display()), false);
    }

    /// One frame: script events, actions, camera, 3D, UI, present.
    fn redraw(&mut self, el: &ActiveEventLoop) {
        let Some(size) = self.gfx.as_ref().map(|g| g.window.inner_size()) else {
            return;
        };
        if size.width == 0 || size.height == 0 {
            // minimised: nothing to draw into
            return;
        }
        let now = Instant::now();
        let wall_dt = now.duration_since(self.last_instant).as_secs_f32();
        self.last_instant = now;
        let scripted = self.frames.is_some();
        let dt = if scripted { 1.0 / 30.0 } else { wall_dt.min(0.1) };
        if let Some(s) = &self.script {
            for e in s.at(self.frames_done).cloned().collect::<Vec<_>>() {
                match e {
                    Event::Input(i) => self.cam.apply(i),
                    Event::Action(a) => self.actions.push(a),
                }
            }
        }
        self.process_actions();
        let mut moved = self.cam.step(dt);
        if self.playing {
            if let Some(p) = &self.scene.camera_path {
                self.frame_t += if scripted { 1.0 } else { dt * 30.0 };
                if self.frame_t > p.last_frame() {
                    if self.looping {
                        self.frame_t = p.first_frame();
                    } else {
                        self.frame_t = p.last_frame();
                        self.playing = false;
                    }
                }
                let c = self.scene.camera_at(self.frame_t);
                self.cam.set(c);
                moved = true;
            }
        }
        let cam = self.cam.camera();
        if let Some(keys) = &mut self.recording {
            // a keyframe every 10 frames while the camera moves; frame = frames since the start
            let k = self.frames_done.saturating_sub(self.record_start) as f32;
            let changed = keys
                .last()
                .is_none_or(|l: &Keyframe| l.eye != cam.eye || l.target != cam.target);
            if changed && (keys.is_empty() || k - keys.last().map_or(0.0, |l| l.frame) >= 10.0) {
                keys.push(Keyframe {
                    frame: k,
                    eye: cam.eye,
                    target: cam.target,
                });
            }
        }
        // fit to window: the render size follows the viewport
        if self.fit_window {
            let (w, h) = self.viewport_px;
            let lim = strata_render::renderer::MIN_SIZE..=strata_render::renderer::MAX_SIZE;
            if (w, h) != self.render_size && lim.contains(&w) && lim.contains(&h) {
                let old = std::mem::replace(&mut self.render_size, (w, h));
                let spec = self.spec.clone();
                if !self.apply_spec(spec, None) {
                    self.render_size = old;
                    self.fit_window = false;
                }
            }
        }
        let Some(mut gfx) = self.gfx.take() else {
            return;
        };
        self.frame(&mut gfx, el, moved, cam, now);
        self.gfx = Some(gfx);
    }

    fn frame(&mut self, gfx: &mut Gfx, el: &ActiveEventLoop, moved: bool, cam: Camera, now: Instant) {
        let scripted = self.frames.is_some();
        let title = format!("strata view — {} — {}", self.scene.name, self.adapter_name);
        if gfx.window.title() != title {
            gfx.window.set_title(&title);
        }
        let frames = self.frames.unwrap_or(0);
        let at_end = scripted && self.frames_done + 1 >= frames;
        if at_end && self.pending_shot.is_none() {
            if let Some(p) = self.screenshot.take() {
                self.pending_shot = Some(Some(p));
            }
        }
        let reduced = moved && self.motion_scale < 1.0 && self.pending_shot.is_none();
        // settled: the shown frame stays as it is (the UI still redraws)
        let render = if !moved && self.settled() {
            Ok(None)
        } else {
            self.render_3d(&gfx.gpu, reduced, cam)
        };
        let mut timing = match render {
            Ok(t) => t,
            Err(e) => {
                let msg = one_line(&e.to_string());
                if matches!(e, RenderError::Validation(_)) {
                    self.fatal = Some(msg.clone());
                    el.exit();
                }
                self.broken = true;
                self.say(msg, true);
                None
            }
        };
        // the viewport's texture, when the frame or the display controls changed
        let key = (self.gain, self.false_colour);
        if self.shown.is_some() && (timing.is_some() || self.display_key != Some(key) || self.viewport_tex.is_none()) {
            self.display_key = Some(key);
            if let Err(e) = self.show(gfx) {
                self.say(one_line(&e.to_string()), true);
            }
        }
        // saved once `render --warmup` can reproduce the frame: full resolution, and a
        // second still frame where single-pass layers need last frame's depths
        if self.pending_shot.is_some() && self.shot_ready() {
            let p = self.pending_shot.take().expect("checked");
            match read_back_shown(&mut self.shown, &self.full, &self.reduced, &gfx.gpu) {
                Ok(()) => self.save_screenshot(p),
                Err(e) => self.say(format!("screenshot: {}", one_line(&e.to_string())), true),
            }
        }
        // --frames: done when the frames are rendered and nothing is left to apply or save
        // (a screenshot may take a few more frames; give up after 100)
        let over = scripted && self.frames_done >= frames + 100;
        if over && self.pending_shot.is_some() {
            self.say(
                "screenshot: the frame did not settle within 100 extra frames".into(),
                true,
            );
            self.fatal = Some("screenshot not saved: the camera or settings kept changing".into());
        }
        let last = at_end && ((self.pending_shot.is_none() && self.actions.is_empty()) || over);
        // UI
        let ctx = gfx.egui_state.egui_ctx().clone();
        let raw = gfx.egui_state.take_egui_input(&gfx.window);
        let out = ctx.run_ui(raw, |ui| crate::ui::draw(self, ui));
        let repaint = out
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .map_or(std::time::Duration::MAX, |v| v.repaint_delay);
        self.idle = !moved && self.settled() && !repaint.is_zero();
        self.repaint_after = (repaint < std::time::Duration::from_secs(3600)).then_some(repaint);
        gfx.egui_state.handle_platform_output(&gfx.window, out.platform_output);
        let prims = ctx.tessellate(out.shapes, out.pixels_per_point);
        for (id, deltas) in &out.textures_delta.set {
            for delta in deltas.iter() {
                gfx.egui_rend
                    .update_texture(&gfx.gpu.device, &gfx.gpu.queue, *id, delta);
            }
        }
        let sd = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [gfx.config.width, gfx.config.height],
            pixels_per_point: out.pixels_per_point,
        };
        if last {
            if let Some(p) = self.window_screenshot.take() {
                if let Err(e) = window_screenshot(gfx, &prims, &sd, &p) {
                    self.say(e, true);
                } else {
                    self.say(format!("saved window {}", p.display()), false);
                }
            }
        }
        present(gfx, &prims, &sd);
        for id in &out.textures_delta.free {
            gfx.egui_rend.free_texture(id);
        }
        self.last_frame_ms = now.elapsed().as_secs_f64() * 1e3;
        if let Some(t) = timing.as_mut() {
            t.frame_ms = self.last_frame_ms;
        }
        if let Some(t) = timing {
            self.timings.push_back(t);
            while self.timings.len() > HISTORY {
                self.timings.pop_front();
            }
        }
        self.frames_done += 1;
        if last {
            // frame-time summary (the first frame, with shader compilation, left out), full
            // and reduced-resolution frames apart
            for reduced in [false, true] {
                let v: Vec<&FrameTiming> = self.timings.iter().skip(1).filter(|t| t.reduced == reduced).collect();
                if v.is_empty() {
                    continue;
                }
                let n = v.len() as f64;
                let frame = v.iter().map(|t| t.frame_ms).sum::<f64>() / n;
                let gpu = v.iter().map(|t| t.passes.iter().map(|p| p.1).sum::<f64>()).sum::<f64>() / n;
                let (w, h) = self.render_size;
                let what = if reduced {
                    format!("reduced ×{} while moving", self.motion_scale)
                } else {
                    format!("{w}x{h}")
                };
                eprintln!(
                    "strata view: {what}: {} frames, mean frame {frame:.1} ms, GPU passes {gpu:.1} ms",
                    v.len()
                );
            }
            if let Some(s) = &self.script {
                if s.end > self.frames_done {
                    eprintln!(
                        "strata view: warning: the script runs to frame {} but --frames is {}",
                        s.end, self.frames_done
                    );
                }
            }
            el.exit();
        }
    }
}

/// Reads the shown frame back from the renderer that drew it, if it is still only there
/// (before a screenshot, false colour, or replacing that renderer).
fn read_back_shown(
    shown: &mut Option<Shown>,
    full: &Option<Renderer>,
    reduced: &Option<Renderer>,
    gpu: &GpuContext,
) -> Result<(), RenderError> {
    let Some(s) = shown.as_mut().filter(|s| s.image.is_none() || !s.exposure_exact) else {
        return Ok(());
    };
    let Some(r) = (if s.full { full } else { reduced }) else {
        return Err(RenderError::Other("the shown frame's renderer is gone".into()));
    };
    if let (None, Some(target)) = (&s.image, s.target) {
        s.image = Some(r.read_target(gpu, target)?);
    }
    if !s.exposure_exact {
        s.exposure = Some(r.displayed_exposure(gpu)?);
        s.exposure_exact = true;
    }
    Ok(())
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Heat map 0 → black … 1 → white (as `--debug-view abuffer-count`).
fn heat(v: f32) -> [f32; 3] {
    let v = v.clamp(0.0, 1.0);
    [
        (v * 3.0).min(1.0),
        (v * 3.0 - 1.0).clamp(0.0, 1.0),
        (v * 3.0 - 2.0).clamp(0.0, 1.0),
    ]
}

/// A TOML scene the loader reads: the current scene as its base and the recorded path.
pub fn write_path_scene(path: &Path, scene_spec: &str, keys: &[Keyframe], cam: &Camera) -> Result<(), String> {
    if keys.len() < 2 {
        return Err(format!(
            "record-stop {}: recorded {} keyframe(s); move the camera while recording (at least 2)",
            path.display(),
            keys.len()
        ));
    }
    let mut doc = toml::Table::new();
    let spec = Path::new(scene_spec);
    let ext = spec
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let abs = |p: &Path| {
        std::fs::canonicalize(p)
            .unwrap_or_else(|_| p.to_path_buf())
            .display()
            .to_string()
    };
    match ext.as_deref() {
        Some("toml") => {
            let text = std::fs::read_to_string(spec).map_err(|e| format!("{scene_spec}: cannot read: {e}"))?;
            doc = text.parse::<toml::Table>().map_err(|e| format!("{scene_spec}: {e}"))?;
            let dir = spec.parent().unwrap_or(Path::new(""));
            if let Some(toml::Value::String(m)) = doc.get("mesh").cloned() {
                doc.insert("mesh".into(), abs(&dir.join(m)).into());
            }
            doc.remove("camera_path");
        }
        Some("obj" | "gltf" | "glb") => {
            doc.insert("mesh".into(), abs(spec).into());
        }
        _ => {
            doc.insert("builtin".into(), scene_spec.into());
        }
    }
    let arr = |v: glam::Vec3| toml::Value::Array(vec![(v.x as f64).into(), (v.y as f64).into(), (v.z as f64).into()]);
    let mut c = toml::Table::new();
    c.insert("eye".into(), arr(keys[0].eye));
    c.insert("target".into(), arr(keys[0].target));
    c.insert("up".into(), arr(cam.up));
    c.insert("fov".into(), (cam.fov_y_deg as f64).into());
    c.insert("near".into(), (cam.near as f64).into());
    doc.insert("camera".into(), toml::Value::Table(c));
    let kf: Vec<toml::Value> = keys
        .iter()
        .map(|k| {
            let mut t = toml::Table::new();
            t.insert("frame".into(), (k.frame as f64).into());
            t.insert("eye".into(), arr(k.eye));
            t.insert("target".into(), arr(k.target));
            toml::Value::Table(t)
        })
        .collect();
    let mut p = toml::Table::new();
    p.insert("keyframes".into(), toml::Value::Array(kf));
    doc.insert("camera_path".into(), toml::Value::Table(p));
    let text = format!(
        "# camera path recorded by strata view\n{}",
        toml::to_string(&doc).map_err(|e| e.to_string())?
    );
    if let Some(d) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(d).map_err(|e| format!("{}: cannot create folder: {e}", d.display()))?;
    }
    std::fs::write(path, text).map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

fn present(gfx: &mut Gfx, prims: &[egui::ClippedPrimitive], sd: &egui_wgpu::ScreenDescriptor) {
    let frame = match gfx.surface.get_current_texture() {
        wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
        wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
            gfx.surface.configure(&gfx.gpu.device, &gfx.config);
            return;
        }
        _ => return,
    };
    let view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
    draw_egui(gfx, prims, sd, &view);
    gfx.gpu.queue.present(frame);
}

fn draw_egui(
    gfx: &mut Gfx,
    prims: &[egui::ClippedPrimitive],
    sd: &egui_wgpu::ScreenDescriptor,
    view: &wgpu::TextureView,
) {
    let dev = &gfx.gpu.device;
    let mut enc = dev.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("egui") });
    let cmds = gfx.egui_rend.update_buffers(dev, &gfx.gpu.queue, &mut enc, prims, sd);
    {
        let rp = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("egui"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: 0.05,
                        g: 0.05,
                        b: 0.05,
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        let mut rp = rp.forget_lifetime();
        gfx.egui_rend.render(&mut rp, prims, sd);
    }
    gfx.gpu.queue.submit(cmds.into_iter().chain([enc.finish()]));
}

/// The whole window (panels included) drawn into an offscreen texture and saved as PNG.
fn window_screenshot(
    gfx: &mut Gfx,
    prims: &[egui::ClippedPrimitive],
    sd: &egui_wgpu::ScreenDescriptor,
    path: &Path,
) -> Result<(), String> {
    let format = gfx.config.format;
    let tex = gfx.gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("window-screenshot"),
        size: wgpu::Extent3d {
            width: gfx.config.width,
            height: gfx.config.height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = tex.create_view(&wgpu::TextureViewDescriptor::default());
    draw_egui(gfx, prims, sd, &view);
    let mut bytes = gfx.gpu.read_texture(&tex, 0).map_err(|e| e.to_string())?;
    if matches!(
        format,
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
    ) {
        bytes.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
    }
    bytes.chunks_exact_mut(4).for_each(|p| p[3] = 255);
    let img = image::RgbaImage::from_raw(gfx.config.width, gfx.config.height, bytes)
        .ok_or_else(|| "window screenshot: unexpected texture size".to_string())?;
    img.save(path)
        .map_err(|e| format!("{}: cannot write PNG: {e}", path.display()))
}

struct Handler {
    app: App,
}

impl ApplicationHandler for Handler {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.app.gfx.is_some() {
            return;
        }
        if let Err(e) = self.app.init(el) {
            self.app.fatal = Some(e);
            el.exit();
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let app = &mut self.app;
        let Some(gfx) = app.gfx.as_mut() else {
            return;
        };
        let resp = gfx.egui_state.on_window_event(&gfx.window, &event);
        let ctx = gfx.egui_state.egui_ctx().clone();
        // any event may change the frame or the UI: draw again (the frame decides
        // whether it settled)
        app.idle = false;
        match event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => el.exit(),
            // zero size (minimised): keep the old configuration, frames are skipped
            WindowEvent::Resized(s) if s.width > 0 && s.height > 0 => {
                gfx.config.width = s.width;
                gfx.config.height = s.height;
                gfx.surface.configure(&gfx.gpu.device, &gfx.config);
            }
            WindowEvent::RedrawRequested => app.redraw(el),
            WindowEvent::DroppedFile(p) => app.actions.push(Action::Open(p.display().to_string())),
            WindowEvent::KeyboardInput { event, .. } => {
                if ctx.egui_wants_keyboard_input() && event.state == ElementState::Pressed {
                    return;
                }
                let down = event.state == ElementState::Pressed;
                if let PhysicalKey::Code(code) = event.physical_key {
                    let key = match code {
                        KeyCode::KeyW => Some(Key::W),
                        KeyCode::KeyA => Some(Key::A),
                        KeyCode::KeyS => Some(Key::S),
                        KeyCode::KeyD => Some(Key::D),
                        KeyCode::KeyQ => Some(Key::Q),
                        KeyCode::KeyE => Some(Key::E),
                        KeyCode::ShiftLeft | KeyCode::ShiftRight => Some(Key::Shift),
                        _ => None,
                    };
                    if let Some(k) = key {
                        app.cam.apply(Input::Key(k, down));
                    } else if down && !event.repeat {
                        match code {
                            KeyCode::F12 => app.actions.push(Action::Screenshot(None)),
                            KeyCode::Space => app.actions.push(Action::Play(!app.playing)),
                            KeyCode::Tab => app.actions.push(Action::Mode(match app.cam.mode {
                                Mode::Fly => Mode::Orbit,
                                Mode::Orbit => Mode::Fly,
                            })),
                            _ => {}
                        }
                    }
                }
            }
            WindowEvent::Focused(false) => app.cam.release_all(),
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Right,
                ..
            } => {
                // look / orbit drags start on the 3D viewport only
                app.look_active = state == ElementState::Pressed && app.cursor_in_viewport();
            }
            WindowEvent::CursorMoved { position, .. } => {
                if app.look_active {
                    if let Some((x, y)) = app.last_cursor {
                        app.cam
                            .apply(Input::Drag((position.x - x) as f32, (position.y - y) as f32));
                    }
                }
                app.last_cursor = Some((position.x, position.y));
            }
            WindowEvent::CursorLeft { .. } => app.last_cursor = None,
            WindowEvent::MouseWheel { delta, .. } if !resp.consumed && app.cursor_in_viewport() => {
                let n = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / 40.0) as f32,
                };
                app.cam.apply(Input::Wheel(n));
            }
            _ => {}
        }
    }

    fn new_events(&mut self, _el: &ActiveEventLoop, cause: winit::event::StartCause) {
        // egui's repaint time came (`repaint_after`)
        if matches!(cause, winit::event::StartCause::ResumeTimeReached { .. }) {
            self.app.idle = false;
        }
    }

    fn about_to_wait(&mut self, el: &ActiveEventLoop) {
        let Some(g) = &self.app.gfx else {
            return;
        };
        if !self.app.idle {
            el.set_control_flow(ControlFlow::Poll);
            g.window.request_redraw();
            return;
        }
        // settled: sleep until an event (or egui's repaint time)
        el.set_control_flow(match self.app.repaint_after {
            Some(d) => ControlFlow::WaitUntil(Instant::now() + d),
            None => ControlFlow::Wait,
        });
    }
}

impl App {
    fn init(&mut self, el: &ActiveEventLoop) -> Result<(), String> {
        let (w, h) = self.render_size;
        let attrs =
            Window::default_attributes()
                .with_title("strata view")
                .with_inner_size(winit::dpi::LogicalSize::new(
                    w as f64 + PANEL_WIDTH as f64 + 24.0,
                    (h as f64 + BOTTOM_HEIGHT as f64 + 40.0).max(720.0),
                ));
        let window = Arc::new(
            el.create_window(attrs)
                .map_err(|e| format!("cannot open a window: {e} (is DISPLAY set? under no display use xvfb-run)"))?,
        );
        let instance = GpuContext::instance();
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| format!("cannot create a surface for the window: {e}"))?;
        let gpu = GpuContext::with_instance(
            &GpuOptions {
                adapter: self.adapter_opt.clone(),
            },
            instance,
            Some(&surface),
        )
        .map_err(|e| one_line(&e.to_string()))?;
        let caps = surface.get_capabilities(&gpu.adapter);
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .or_else(|| caps.formats.first().copied())
            .ok_or("the surface supports no format")?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps
                .alpha_modes
                .first()
                .copied()
                .unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
        };
        if size.width > 0 && size.height > 0 {
            surface.configure(&gpu.device, &config);
        }
        let ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            ctx,
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(gpu.device.limits().max_texture_dimension_2d as usize),
        );
        let egui_rend = egui_wgpu::Renderer::new(&gpu.device, format, egui_wgpu::RendererOptions::default());
        let display = DisplayEncoder::new(&gpu);
        let info = gpu.adapter.get_info();
        self.adapter_name = format!("{} ({:?})", info.name, info.backend);
        window.set_title(&format!("strata view — {} — {}", self.scene.name, self.adapter_name));
        eprintln!(
            "strata view: adapter {}, scene '{}' ({} triangles)",
            self.adapter_name,
            self.scene.name,
            self.scene.triangle_count()
        );
        self.gfx = Some(Gfx {
            window,
            surface,
            config,
            gpu,
            egui_state,
            egui_rend,
            display,
            native: None,
            read_back: std::env::var_os("STRATA_VIEW_READBACK").is_some_and(|v| v == "1"),
        });
        let spec = self.spec.clone();
        if !self.apply_spec(spec, None) {
            return Err(self.status.clone().map_or("cannot build the renderer".into(), |s| s.0));
        }
        if let Some(v) = self.debug_view.clone() {
            if !self.view_names.contains(&v) {
                return Err(format!(
                    "--debug-view '{v}' is unknown: valid views are {}",
                    self.view_names.join(", ")
                ));
            }
        }
        self.last_instant = Instant::now();
        Ok(())
    }
}

pub fn run(opts: ViewOptions) -> Result<(), String> {
    let el = EventLoop::new()
        .map_err(|e| format!("cannot open a window: {e} (is DISPLAY set? under no display use xvfb-run)"))?;
    el.set_control_flow(ControlFlow::Poll);
    let mut h = Handler { app: App::new(opts) };
    el.run_app(&mut h).map_err(|e| format!("window event loop: {e}"))?;
    let app = h.app;
    if let Some(f) = app.fatal {
        return Err(f);
    }
    if let Some(g) = &app.gfx {
        g.gpu.check_errors().map_err(|e| one_line(&e.to_string()))?;
    }
    Ok(())
}
