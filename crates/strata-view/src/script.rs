//! `--script FILE`: scripted input for non-interactive runs and tests. One command a
//! line (`#` starts a comment); commands run in order on a frame clock that starts at 0:
//!
//! ```text
//! key W 10             hold W for 10 frames (W A S D Q E shift); the clock advances 10
//! wait 5               let 5 frames pass
//! mouse-drag 40 -10    right-button drag by (dx, dy) pixels (look / orbit)
//! wheel 2              wheel notches (fly: speed; orbit: distance)
//! mode orbit           fly | orbit
//! technique ao         any registered technique
//! preset balanced | layers 2 | variant peel | layer-scale 2 | guard-band 10% | set samples 32
//! debug-view layer0-normal   (final = the technique's output)
//! open PATH            load a glTF/GLB/OBJ/TOML scene (errors keep the current one)
//! screenshot PATH      save the viewport PNG and PATH.cmd.txt (as F12 does) of the state up
//!                      to this line; the commands after it apply from the next frame
//! play | pause | seek 30 | loop on|off      camera-path playback
//! record-start | record-stop PATH           record a camera path to a TOML scene file
//! motion-scale 0.5     internal resolution while the camera moves (1 = off)
//! resize W H           request a new window inner size (physical pixels)
//! fit on|off           render size follows the viewport (on) or stays --width × --height
//! ```
//!
//! Key presses and drags become the same [`crate::camera::Input`]s as real events, and
//! the other commands the same [`crate::Action`]s as the panel's widgets.

use std::path::Path;

use crate::camera::{Input, Key};
use crate::Action;

#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    Input(Input),
    Action(Action),
}

/// Events keyed by the frame at whose start they apply, in order.
#[derive(Clone, Debug, Default)]
pub struct Script {
    pub events: Vec<(u32, Event)>,
    /// The frame after the last command.
    pub end: u32,
}

impl Script {
    pub fn load(path: &Path) -> Result<Script, String> {
        let text =
            std::fs::read_to_string(path).map_err(|e| format!("--script {}: cannot read: {e}", path.display()))?;
        Self::parse(&text).map_err(|e| format!("--script {}: {e}", path.display()))
    }

    pub fn parse(text: &str) -> Result<Script, String> {
        let mut s = Script::default();
        let mut clock = 0u32;
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let err = |m: String| format!("line {}: '{line}': {m}", i + 1);
            let mut w = line.split_whitespace();
            let cmd = w.next().unwrap_or("");
            let rest: Vec<&str> = w.collect();
            let arg = |k: usize| rest.get(k).copied().ok_or_else(|| err("missing argument".into()));
            let num = |k: usize| -> Result<f32, String> {
                let a = arg(k)?;
                a.parse::<f32>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| err(format!("'{a}' is not a number")))
            };
            let frames = |k: usize| -> Result<u32, String> {
                let a = arg(k)?;
                a.parse::<u32>()
                    .ok()
                    .filter(|v| *v <= 100_000)
                    .ok_or_else(|| err(format!("'{a}' is not a frame count in 0..=100000")))
            };
            let mut act = |a: Action| s.events.push((clock, Event::Action(a)));
            match cmd {
                "key" => {
                    let k =
                        Key::parse(arg(0)?).ok_or_else(|| err("unknown key: use W, A, S, D, Q, E or shift".into()))?;
                    let n = frames(1)?;
                    s.events.push((clock, Event::Input(Input::Key(k, true))));
                    clock += n;
                    s.events.push((clock, Event::Input(Input::Key(k, false))));
                }
                "wait" => clock += frames(0)?,
                "mouse-drag" => s.events.push((clock, Event::Input(Input::Drag(num(0)?, num(1)?)))),
                "wheel" => s.events.push((clock, Event::Input(Input::Wheel(num(0)?)))),
                "mode" => match arg(0)? {
                    "fly" => act(Action::Mode(crate::camera::Mode::Fly)),
                    "orbit" => act(Action::Mode(crate::camera::Mode::Orbit)),
                    m => return Err(err(format!("unknown mode '{m}': use fly or orbit"))),
                },
                "technique" => act(Action::Technique(arg(0)?.to_string())),
                "preset" => act(Action::Preset(arg(0)?.to_string())),
                "layers" => act(Action::Layers(frames(0)?)),
                "variant" => act(Action::Variant(arg(0)?.to_string())),
                "layer-scale" => act(Action::LayerScale(frames(0)?)),
                "guard-band" => act(Action::GuardBand(arg(0)?.to_string())),
                // a number, auto, auto:KEY or auto:key=K,adapt=A,...; `scene`: the scene's
                "exposure" => act(Action::Exposure(match arg(0)? {
                    "scene" => None,
                    e => Some(e.to_string()),
                })),
                "set" => act(Action::Set(arg(0)?.to_string(), arg(1)?.to_string())),
                "debug-view" => act(Action::DebugView(match arg(0)? {
                    "final" => None,
                    v => Some(v.to_string()),
                })),
                "open" => act(Action::Open(rest.join(" "))),
                "screenshot" => act(Action::Screenshot(Some(rest.join(" ").into()))),
                "play" => act(Action::Play(true)),
                "pause" => act(Action::Play(false)),
                "seek" => act(Action::Seek(num(0)?)),
                "loop" => act(Action::Loop(match arg(0)? {
                    "on" => true,
                    "off" => false,
                    v => return Err(err(format!("'{v}': use on or off"))),
                })),
                "record-start" => act(Action::Record(None)),
                "record-stop" => act(Action::Record(Some(rest.join(" ").into()))),
                "motion-scale" => act(Action::MotionScale(num(0)?)),
                "resize" => act(Action::Resize(frames(0)?, frames(1)?)),
                "gain" => act(Action::Gain(num(0)?)),
                "false-colour" => act(Action::FalseColour(match arg(0)? {
                    "on" => true,
                    "off" => false,
                    v => return Err(err(format!("'{v}': use on or off"))),
                })),
                "fit" => act(Action::Fit(match arg(0)? {
                    "on" => true,
                    "off" => false,
                    v => return Err(err(format!("'{v}': use on or off"))),
                })),
                _ => return Err(err(format!("unknown command '{cmd}'"))),
            }
        }
        s.end = clock;
        Ok(s)
    }

    /// The events that apply at the start of frame `f`.
    pub fn at(&self, f: u32) -> impl Iterator<Item = &Event> {
        self.events.iter().filter(move |(t, _)| *t == f).map(|(_, e)| e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_hold_for_their_frames_and_errors_name_the_line() {
        let s = Script::parse("# test\nwait 2\nkey W 3\ntechnique ao\nmouse-drag 10 -4\n").unwrap();
        assert_eq!(s.end, 5);
        assert_eq!(s.at(2).next(), Some(&Event::Input(Input::Key(Key::W, true))));
        assert_eq!(s.at(5).count(), 3);
        let e = Script::parse("wait 1\nkey Z 3\n").unwrap_err();
        assert!(e.starts_with("line 2:"), "{e}");
        assert!(Script::parse("jump 3").unwrap_err().contains("unknown command"));
        assert!(Script::parse("wait x").unwrap_err().contains("not a frame count"));
        // the construction's controls, as the panel has them
        let s = Script::parse("layers 2\nvariant peel\nlayer-scale 2\n").unwrap();
        let acts: Vec<_> = s.at(0).cloned().collect();
        assert_eq!(
            acts,
            [
                Event::Action(Action::Layers(2)),
                Event::Action(Action::Variant("peel".into())),
                Event::Action(Action::LayerScale(2)),
            ]
        );
        // the display controls
        let s = Script::parse(
            "gain 2.5
false-colour on
",
        )
        .unwrap();
        let acts: Vec<_> = s.at(0).cloned().collect();
        assert_eq!(
            acts,
            [
                Event::Action(Action::Gain(2.5)),
                Event::Action(Action::FalseColour(true))
            ]
        );
        let e = Script::parse("false-colour yes").unwrap_err();
        assert!(e.starts_with("line 1:") && e.contains("use on or off"), "{e}");
    }
}
