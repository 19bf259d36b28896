//! `strata view`: an interactive viewer on the same [`GpuContext`](strata_render::GpuContext)
//! and [`Renderer`](strata_render::Renderer) as `strata render` (winit + egui through
//! egui-wgpu). The frame shown is the very target `render` writes, read back and encoded
//! by the same code ([`strata_scene::ImageBuf::to_rgba8`]), so a screenshot equals the
//! PNG of the `strata render …` command the viewer prints for it.
//!
//! The renderer's settings are never built here: every change (technique, preset,
//! layers, a setting) becomes the `strata render` flags it stands for, and the caller's
//! [`SettingsFn`] — the CLI's own parser and validation — turns them into
//! [`RenderSettings`]. A value the CLI rejects shows the CLI's one-line error and is not
//! applied.

mod app;
pub mod camera;
pub mod script;
mod ui;

use std::path::PathBuf;

use strata_render::RenderSettings;
use strata_scene::{Camera, Scene};

pub use script::Script;

/// Turns `strata render` flags (`--scene … --width … --technique … --set …`) into validated
/// settings for `scene`; the error is one line naming the flag and its valid range.
pub type SettingsFn = Box<dyn Fn(&Scene, &[String]) -> Result<RenderSettings, String>>;

/// The VPLs of `scene` at frame `t` from `count` light paths (instant radiosity; the
/// caller's generator, as for `strata render`): ILS in scenes with animated objects gets
/// new VPLs whenever the frame changes.
pub type VplsFn = Box<dyn Fn(&Scene, f32, u32) -> Vec<strata_render::passes::ils::GpuVpl>>;

/// The technique-related `strata render` flags the panels edit.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSpec {
    pub technique: String,
    /// `--preset` (only for techniques with presets).
    pub preset: Option<String>,
    pub layers: u32,
    pub variant: String,
    /// `--layer-scale`: resolution divisor of layers ≥ 1 (DGB Fig. 11; 1 = full resolution).
    pub layer_scale: u32,
    pub guard_band: String,
    /// `--exposure` (a number, `auto`, `auto:KEY` or `auto:key=K,adapt=A,low=L,high=H`); `None`: the scene's.
    pub exposure: Option<String>,
    /// `--set NAME=VALUE` in order (a later one wins).
    pub sets: Vec<(String, String)>,
    /// Every other `render` flag given on the command line, verbatim (e.g. `--samples 32`).
    pub extra: Vec<String>,
}

impl RenderSpec {
    /// The flags, in the order `strata render` takes them.
    pub fn args(&self) -> Vec<String> {
        let mut a = vec!["--technique".to_string(), self.technique.clone()];
        if let Some(p) = &self.preset {
            a.extend(["--preset".to_string(), p.clone()]);
        }
        a.extend(["--layers".to_string(), self.layers.to_string()]);
        // one layer has no second layer to build
        if self.layers >= 2 {
            a.extend(["--variant".to_string(), self.variant.clone()]);
            if self.layer_scale > 1 {
                a.extend(["--layer-scale".to_string(), self.layer_scale.to_string()]);
            }
        }
        a.extend(["--guard-band".to_string(), self.guard_band.clone()]);
        if let Some(e) = &self.exposure {
            a.extend(["--exposure".to_string(), e.clone()]);
        }
        a.extend(self.extra.iter().cloned());
        for (n, v) in &self.sets {
            a.extend(["--set".to_string(), format!("{n}={v}")]);
        }
        a
    }

    /// Replaces or adds `--set name=value`.
    pub fn with_set(&self, name: &str, value: &str) -> RenderSpec {
        let mut s = self.clone();
        s.sets.retain(|(n, _)| n != name);
        s.sets.push((name.to_string(), value.to_string()));
        s
    }

    /// Switches technique: drops `--set`s the new one lacks and a preset it does not have.
    pub fn with_technique(&self, t: &strata_render::technique::Technique) -> RenderSpec {
        let mut s = self.clone();
        s.technique = t.name.to_string();
        s.sets.retain(|(n, _)| t.setting_list().any(|i| i.name == n));
        if t.presets.is_empty() {
            s.preset = None;
        } else if !s.preset.as_deref().is_some_and(|p| t.presets.contains(&p)) {
            s.preset = Some(t.presets[0].to_string());
        }
        s
    }
}

/// What the panels, keys and scripts ask for; applied between frames.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    Technique(String),
    Preset(String),
    Layers(u32),
    Variant(String),
    LayerScale(u32),
    GuardBand(String),
    /// `--exposure` as typed (a number or `auto[:SPEC]`); `None`: the scene's.
    Exposure(Option<String>),
    /// A technique setting by name, value as typed (a number or a named value).
    Set(String, String),
    DebugView(Option<String>),
    Mode(camera::Mode),
    Open(String),
    /// Save the viewport PNG and its `.cmd.txt` (None: a fresh name in the current folder).
    Screenshot(Option<PathBuf>),
    Play(bool),
    Seek(f32),
    Loop(bool),
    /// Start recording (None) or stop and write the TOML scene file.
    Record(Option<PathBuf>),
    MotionScale(f32),
    Resize(u32, u32),
    /// The render size follows the viewport's size.
    Fit(bool),
    /// The display gain (0.125..=16; what the viewer shows, not the PNG).
    Gain(f32),
    /// False colour for one-channel views (what the viewer shows, not the PNG).
    FalseColour(bool),
}

/// Everything `strata view` starts from.
pub struct ViewOptions {
    /// `--scene` as given (name or path): what the reproduce command names.
    pub scene_spec: String,
    pub scene: Scene,
    /// The first camera (the scene's, its path at `frame`, or the flags' overrides).
    pub camera: Camera,
    /// `--camera N` (kept in the reproduce command while the first scene is shown).
    pub camera_index: Option<usize>,
    pub frame: f32,
    /// Render size (the viewport shows it scaled to fit; "fit to window" follows the window).
    pub width: u32,
    pub height: u32,
    pub spec: RenderSpec,
    pub debug_view: Option<String>,
    /// Non-interactive: render this many frames, write `screenshot`, exit.
    pub frames: Option<u32>,
    pub screenshot: Option<PathBuf>,
    /// Also save the whole window (panels included) at the end, for documentation.
    pub window_screenshot: Option<PathBuf>,
    pub script: Option<Script>,
    /// Internal-resolution scale while the camera moves, in [0.1, 1] (1: always full).
    pub motion_scale: f32,
    pub adapter: Option<String>,
    pub settings: SettingsFn,
    /// Per-frame VPLs for ILS when the scene has animated objects (None: the VPLs the
    /// settings were built with stay).
    pub vpls: Option<VplsFn>,
}

/// Opens the window and runs until it is closed (or `frames` are done). Errors are one
/// line; a wgpu validation error ends the run with an error.
pub fn run(opts: ViewOptions) -> Result<(), String> {
    app::run(opts)
}

/// `s` quoted for a POSIX shell when it needs it.
pub fn shell_quote(s: &str) -> String {
    if !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || "-_./=,:%+@".contains(c)) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}
