//! `strata view` in a real window under Xvfb (lavapipe when no GPU): the viewport equals
//! `strata render` of the same camera and settings, scripted input moves the camera and
//! switches technique and debug view through the viewer's own input path, and a bad file
//! leaves the viewer running. Skipped (and logged in `$STRATA_SKIP_LOG`) only when no
//! `Xvfb` binary exists (`scripts/setup.sh` installs it).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// The most ꟻLIP allowed between a viewer screenshot and `strata render` of its command:
/// both are the same target read back and encoded by the same code, so they are expected
/// to be identical (measured: 0 on lavapipe); the bound leaves room for GPU
/// non-determinism on other adapters.
const FLIP_BOUND: f32 = 0.01;

/// An `Xvfb` server on its own display, killed when dropped.
struct XServer {
    child: Child,
    display: String,
}

impl Drop for XServer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn find_on_path(name: &str) -> Option<PathBuf> {
    std::env::var_os("PATH")?
        .to_str()?
        .split(':')
        .map(|d| Path::new(d).join(name))
        .find(|p| p.is_file())
}

fn find_xvfb() -> Option<PathBuf> {
    find_on_path("Xvfb")
}

static NEXT_DISPLAY: AtomicU32 = AtomicU32::new(0);

/// Starts Xvfb, or records why the test cannot run and returns None.
fn xvfb(test: &str) -> Option<XServer> {
    let Some(bin) = find_xvfb() else {
        strata_scene::skip::note_skip(
            test,
            "Xvfb not found on PATH (scripts/setup.sh installs the xvfb package)",
        );
        return None;
    };
    for _ in 0..50 {
        let n = 200 + (std::process::id() % 300) * 8 + NEXT_DISPLAY.fetch_add(1, Ordering::SeqCst) % 2000;
        if Path::new(&format!("/tmp/.X{n}-lock")).exists() || Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
            continue;
        }
        let child = Command::new(&bin)
            .args([
                format!(":{n}").as_str(),
                "-screen",
                "0",
                "1600x1000x24",
                "-nolisten",
                "tcp",
                // without it Xvfb resets whenever its last client disconnects: the
                // readiness probe and the `xdotool search` polling below each did, and a
                // viewer connecting during that reset failed with "cannot open a window"
                "-noreset",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb exists but does not start");
        let mut server = XServer {
            child,
            display: format!(":{n}"),
        };
        // ready = our server is alive and accepts a client (its socket alone can exist
        // before it does, or belong to another server: the viewer then failed with
        // "cannot open a window")
        let xdotool = find_on_path("xdotool");
        let accepts = |display: &str| match &xdotool {
            Some(bin) => Command::new(bin)
                .args(["getdisplaygeometry"])
                .env("DISPLAY", display)
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
                .is_ok_and(|s| s.success()),
            None => true,
        };
        let t0 = Instant::now();
        while t0.elapsed() < Duration::from_secs(20) {
            if server.child.try_wait().unwrap().is_some() {
                // this display was taken after all: try the next one
                break;
            }
            if Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() && accepts(&server.display) {
                return Some(server);
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
    panic!("Xvfb did not come up on any display");
}

fn strata(display: Option<&str>, args: &[&str]) -> Output {
    strata_env(display, args, &[])
}

fn strata_env(display: Option<&str>, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_strata"));
    cmd.args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    if let Some(d) = display {
        cmd.env("DISPLAY", d);
    }
    cmd.env_remove("WAYLAND_DISPLAY");
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        let dir = std::env::temp_dir().join("strata-xdg-view-tests");
        std::fs::create_dir_all(&dir).unwrap();
        cmd.env("XDG_RUNTIME_DIR", dir);
    }
    cmd.output().expect("failed to start strata")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn ok(o: &Output) -> &Output {
    assert!(
        o.status.success(),
        "strata failed: {}\n{}",
        text(&o.stderr),
        text(&o.stdout)
    );
    o
}

fn scratch(test: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("view").join(test);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `strata view --frames N --screenshot shot.png [--script]` in the X server; returns
/// (output, screenshot path).
fn view(x: &XServer, dir: &Path, name: &str, frames: u32, script: Option<&str>, extra: &[&str]) -> (Output, PathBuf) {
    let shot = dir.join(format!("{name}.png"));
    let frames = frames.to_string();
    let mut args = vec!["view", "--frames", &frames, "--screenshot", shot.to_str().unwrap()];
    let script_path = dir.join(format!("{name}.script"));
    if let Some(s) = script {
        std::fs::write(&script_path, s).unwrap();
        args.extend(["--script", script_path.to_str().unwrap()]);
    }
    args.extend(extra);
    let o = strata(Some(&x.display), &args);
    (o, shot)
}

/// RGB8 pixels of a PNG.
fn rgb(path: &Path) -> (u32, u32, Vec<u8>) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8();
    let (w, h) = img.dimensions();
    (w, h, img.into_raw())
}

/// Mean ꟻLIP between two PNGs of the same size (sRGB bytes, as strata-eval's metrics).
fn flip(a: &Path, b: &Path) -> f32 {
    let (wa, ha, pa) = rgb(a);
    let (wb, hb, pb) = rgb(b);
    assert_eq!((wa, ha), (wb, hb), "{} vs {}: sizes differ", a.display(), b.display());
    let e = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(wa, ha, &pa),
        nv_flip::FlipImageRgb8::with_data(wb, hb, &pb),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    nv_flip::FlipPool::from_image(&e).mean()
}

/// Not a flat image: luma spread and many distinct colours.
fn assert_not_flat(path: &Path) {
    let (_, _, p) = rgb(path);
    let luma: Vec<f64> = p
        .chunks_exact(3)
        .map(|c| 0.3 * c[0] as f64 + 0.59 * c[1] as f64 + 0.11 * c[2] as f64)
        .collect();
    let mean = luma.iter().sum::<f64>() / luma.len() as f64;
    let sd = (luma.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / luma.len() as f64).sqrt();
    let mut colours: Vec<[u8; 3]> = p.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    colours.sort();
    colours.dedup();
    assert!(
        sd > 10.0 && colours.len() > 50,
        "{} is nearly flat: luma sd {sd:.1}, {} colours",
        path.display(),
        colours.len()
    );
}

/// Runs the `strata render …` command a screenshot's `.cmd.txt` holds, writing `out`.
fn run_cmd_txt(shot: &Path, out: &Path) -> String {
    run_cmd_txt_output(shot, out).0
}

/// [`run_cmd_txt`], with the command's output (its stderr carries what `render` prints).
fn run_cmd_txt_output(shot: &Path, out: &Path) -> (String, Output) {
    let cmd_path = shot.with_extension("cmd.txt");
    let line = std::fs::read_to_string(&cmd_path).unwrap_or_else(|e| panic!("{}: {e}", cmd_path.display()));
    let line = line.lines().next().unwrap().to_string();
    let mut words: Vec<String> = line.split(' ').map(String::from).collect();
    assert_eq!(&words[..2], ["strata", "render"], "{line}");
    let i = words.iter().position(|w| w == "--out").expect("--out in the command");
    words[i + 1] = out.display().to_string();
    let args: Vec<&str> = words[1..].iter().map(|s| s.as_str()).collect();
    let o = strata(None, &args);
    ok(&o);
    (line, o)
}

const SIZE: [&str; 4] = ["--width", "160", "--height", "120"];

#[test]
fn viewport_matches_render_and_is_not_flat() {
    let Some(x) = xvfb("view::viewport_matches_render_and_is_not_flat") else {
        return;
    };
    let dir = scratch("viewport");
    let (o, shot) = view(
        &x,
        &dir,
        "shot",
        6,
        None,
        &[&["--scene", "cornell"][..], &SIZE].concat(),
    );
    ok(&o);
    let err = text(&o.stderr);
    assert!(err.contains("strata view: adapter "), "the adapter is named: {err}");
    assert_not_flat(&shot);
    // an independent render of the scene's own camera, no camera flags
    let r = dir.join("render.png");
    ok(&strata(
        None,
        &[
            &["render", "--scene", "cornell", "--out", r.to_str().unwrap()][..],
            &SIZE,
        ]
        .concat(),
    ));
    let f = flip(&shot, &r);
    eprintln!("FLIP(viewer, render) = {f}");
    assert!(f < FLIP_BOUND, "viewer vs render FLIP {f} >= {FLIP_BOUND}");
    // and the command it printed reproduces it
    let r2 = dir.join("cmd.png");
    let line = run_cmd_txt(&shot, &r2);
    assert!(text(&o.stdout).contains(&line), "the command is printed too");
    assert!(flip(&shot, &r2) < FLIP_BOUND);
}

/// `xdotool ARGS` on display `d`; panics when it fails.
fn xdotool(d: &str, args: &[&str]) -> String {
    let o = Command::new("xdotool")
        .args(args)
        .env("DISPLAY", d)
        .output()
        .expect("xdotool runs");
    assert!(o.status.success(), "xdotool {args:?}: {}", text(&o.stderr));
    text(&o.stdout)
}

/// Starts `strata view` on cornell under `x` and waits for its window: (child, window
/// id). With `frames`, a `--frames` run that writes `shot` at its end; without,
/// interactive, in `shot`'s folder (where F12 saves `strata-view-001.png`) until the test
/// ends it. `None` (with the skip noted) when xdotool is missing.
/// `strata ARGS` started in the X server from `dir`, stdout and stderr piped.
fn spawn_view(x: &XServer, args: &[&str], dir: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .current_dir(dir)
        .env("DISPLAY", &x.display)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn view_window(
    x: &XServer,
    test: &str,
    frames: Option<&str>,
    shot: &std::path::Path,
) -> Option<(std::process::Child, String)> {
    if find_on_path("xdotool").is_none() {
        strata_scene::skip::note_skip(test, "xdotool not found on PATH (scripts/setup.sh installs it)");
        return None;
    }
    let mut args = vec!["view", "--scene", "cornell"];
    if let Some(n) = frames {
        args.extend(["--frames", n, "--screenshot", shot.to_str().unwrap()]);
    }
    let mut child = spawn_view(x, &[&args[..], &SIZE].concat(), shot.parent().unwrap());
    let t0 = Instant::now();
    let id = loop {
        let o = Command::new("xdotool")
            .args(["search", "--name", "strata view"])
            .env("DISPLAY", &x.display)
            .output()
            .unwrap();
        if let Some(id) = text(&o.stdout).lines().next().map(String::from) {
            break id;
        }
        // a viewer that exited never shows a window: say why instead of waiting
        if child.try_wait().unwrap().is_some() {
            let o = child.wait_with_output().unwrap();
            panic!(
                "the viewer exited ({}) before its window appeared: {}",
                o.status,
                text(&o.stderr)
            );
        }
        // generous: under the full test run the 2 cores are shared with the other tests
        assert!(t0.elapsed() < Duration::from_secs(180), "no viewer window after 180 s");
        std::thread::sleep(Duration::from_millis(50));
    };
    Some((child, id))
}

#[test]
fn real_x_key_and_mouse_events_move_the_camera() {
    let Some(x) = xvfb("view::real_x_key_and_mouse_events_move_the_camera") else {
        return;
    };
    let dir = scratch("xevents");
    // F12's name for the first screenshot in the viewer's working directory
    let shot = dir.join("strata-view-001.png");
    // the window (interactive: a --frames run could end before the events arrive when the
    // cores are busy), then real X events through XTEST: hold W, right-drag to the right
    let Some((mut child, id)) = view_window(&x, "view::real_x_key_and_mouse_events_move_the_camera", None, &shot)
    else {
        return;
    };
    xdotool(&x.display, &["windowfocus", "--sync", &id]);
    xdotool(&x.display, &["keydown", "w"]);
    std::thread::sleep(Duration::from_millis(500));
    xdotool(&x.display, &["keyup", "w"]);
    xdotool(
        &x.display,
        &[
            "mousemove",
            "--window",
            &id,
            "60",
            "60",
            "mousedown",
            "3",
            "mousemove_relative",
            "--sync",
            "50",
            "0",
            "mouseup",
            "3",
        ],
    );
    // F12 until the screenshot is saved (it waits for a full-resolution, settled frame);
    // its command file is written last
    let cmd_txt = shot.with_extension("cmd.txt");
    let t0 = Instant::now();
    let cmd = loop {
        if let Some(c) = std::fs::read_to_string(&cmd_txt).ok().filter(|c| c.ends_with('\n')) {
            break c;
        }
        if let Some(status) = child.try_wait().unwrap() {
            let o = child.wait_with_output().unwrap();
            panic!("the viewer exited ({status}) before F12 saved: {}", text(&o.stderr));
        }
        assert!(t0.elapsed() < Duration::from_secs(180), "F12 saved nothing in 180 s");
        xdotool(&x.display, &["key", "--window", &id, "F12"]);
        std::thread::sleep(Duration::from_secs(1));
    };
    child.kill().unwrap();
    child.wait().unwrap();
    let flag = |f: &str| -> Vec<f32> {
        cmd.split(&format!(" {f} "))
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect()
    };
    let (eye, target) = (flag("--eye"), flag("--target"));
    // cornell's camera: eye (0.278, 0.273, -0.8) looking down +z; the distance depends on
    // how many frames ran while W was down (the fly speed is per frame in --frames runs)
    assert!(eye[2] > -0.8 + 1e-4, "W moved the camera forward: {cmd}");
    assert!(
        (target[0] - eye[0]).abs() > 1e-5,
        "the right-drag turned the camera: {cmd}"
    );
    let r = dir.join("render.png");
    run_cmd_txt(&shot, &r);
    assert!(flip(&shot, &r) < FLIP_BOUND);
}

#[test]
fn camera_path_playback_follows_the_scene_path() {
    let Some(x) = xvfb("view::camera_path_playback_follows_the_scene_path") else {
        return;
    };
    let dir = scratch("playback");
    let small = ["--width", "64", "--height", "48"];
    let seek = dir.join("seek.png");
    let script = format!(
        "play\nwait 12\npause\nwait 2\nseek 30.5\nwait 1\nscreenshot {}\nwait 1\nplay\nwait 3\npause\nwait 1\n",
        seek.display()
    );
    let (o, shot) = view(
        &x,
        &dir,
        "played",
        22,
        Some(&script),
        &[&["--scene", "atrium"][..], &small].concat(),
    );
    ok(&o);
    let atrium = strata_scene::load_scene("atrium").unwrap();
    assert!(atrium.camera_path.is_some(), "atrium has a camera path");
    let check = |png: &Path, lo: f32, hi: f32| {
        let cmd = std::fs::read_to_string(png.with_extension("cmd.txt")).unwrap();
        let flag = |f: &str| {
            cmd.split(&format!(" {f} "))
                .nth(1)
                .unwrap()
                .split(' ')
                .next()
                .unwrap()
                .to_string()
        };
        let frame: f32 = flag("--frame").parse().unwrap();
        assert!((lo..=hi).contains(&frame), "frame {frame} not in {lo}..={hi}: {cmd}");
        let eye: Vec<f32> = flag("--eye").split(',').map(|v| v.parse().unwrap()).collect();
        let c = atrium.camera_at(frame);
        assert!(
            (glam::Vec3::new(eye[0], eye[1], eye[2]) - c.eye).length() < 1e-4,
            "the camera is the path's at frame {frame}: {cmd}"
        );
        frame
    };
    assert_eq!(check(&seek, 30.5, 30.5), 30.5);
    // play advances one path frame per rendered frame in --frames runs
    check(&shot, 33.0, 35.0);
    let r = dir.join("render.png");
    run_cmd_txt(&shot, &r);
    assert!(flip(&shot, &r) < FLIP_BOUND);
}

/// A Z-up camera (`--up 0,0,1`, as Z-up glTF/OBJ exports have) keeps +Z after the first
/// move: a one-pixel drag turns the view by about a pixel's angle, and the command the
/// screenshot saves names `--up 0,0,1` and reproduces the viewport. The viewer used to
/// switch to +Y on the first move.
#[test]
fn a_z_up_camera_keeps_its_up_after_a_drag() {
    let Some(x) = xvfb("view::a_z_up_camera_keeps_its_up_after_a_drag") else {
        return;
    };
    let dir = scratch("z-up");
    let small = ["--width", "64", "--height", "48"];
    let camera = [
        "--eye",
        "-0.5,0.273,0.28",
        "--target",
        "0.28,0.273,0.28",
        "--up",
        "0,0,1",
    ];
    let (o, shot) = view(
        &x,
        &dir,
        "dragged",
        6,
        Some("wait 1\nmouse-drag 1 0\nwait 2\n"),
        &[&["--scene", "cornell"][..], &small, &camera].concat(),
    );
    ok(&o);
    let cmd = std::fs::read_to_string(shot.with_extension("cmd.txt")).unwrap();
    let flag = |f: &str| -> glam::Vec3 {
        let v: Vec<f32> = cmd
            .split(&format!(" {f} "))
            .nth(1)
            .unwrap_or_else(|| panic!("no {f}: {cmd}"))
            .split(' ')
            .next()
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        glam::Vec3::new(v[0], v[1], v[2])
    };
    assert_eq!(flag("--up"), glam::Vec3::Z, "{cmd}");
    let (eye, target) = (flag("--eye"), flag("--target"));
    let turned = (target - eye).normalize().angle_between(glam::Vec3::X);
    assert!(
        turned > 1e-4 && turned < 0.05,
        "the drag turned the view by {turned} rad: {cmd}"
    );
    assert!(
        (target - eye).normalize().z.abs() < 1e-4,
        "a yaw keeps the view level in Z: {cmd}"
    );
    let r = dir.join("render.png");
    run_cmd_txt(&shot, &r);
    assert!(flip(&shot, &r) < FLIP_BOUND);
}

/// CPU seconds (user + system) process `pid` has used, from /proc (Linux).
fn cpu_seconds(pid: u32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    // the fields after the command name, which ends with the last ')'
    let f: Vec<&str> = stat[stat.rfind(')').unwrap() + 2..].split(' ').collect();
    // utime, stime: fields 14 and 15 of stat(5), 12 and 13 after the name and state
    let ticks: f64 = f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap();
    ticks / 100.0
}

/// An interactive viewer whose frame has settled (the default technique, `full`, is
/// temporal: 61 still frames) stops drawing: it sleeps until an event instead of
/// redrawing the same frame (it used 1.5 of the 2 cores before, 2026-11-28). A key (F12)
/// wakes it: the screenshot is saved, and it sleeps again.
#[test]
fn settled_viewer_sleeps_until_an_event() {
    let test = "view::settled_viewer_sleeps_until_an_event";
    let Some(x) = xvfb(test) else {
        return;
    };
    let dir = scratch("idle");
    let shot = dir.join("strata-view-001.png");
    let Some((mut child, id)) = view_window(&x, test, None, &shot) else {
        return;
    };
    let pid = child.id();
    // a 2-second window in which it used under 0.05 CPU seconds: asleep
    let asleep_within = |limit: Duration| {
        let t0 = Instant::now();
        let mut last = cpu_seconds(pid);
        while t0.elapsed() < limit {
            std::thread::sleep(Duration::from_secs(2));
            let now = cpu_seconds(pid);
            if now - last < 0.05 {
                return Some(t0.elapsed());
            }
            last = now;
        }
        None
    };
    // generous: under the full test run the cores are shared with other tests
    let slept = asleep_within(Duration::from_secs(240));
    let slept = slept.unwrap_or_else(|| {
        child.kill().unwrap();
        panic!("the settled viewer kept using the CPU for 240 s");
    });
    eprintln!("asleep after {slept:?}");
    let cmd_txt = shot.with_extension("cmd.txt");
    xdotool(&x.display, &["windowfocus", "--sync", &id]);
    let t0 = Instant::now();
    while std::fs::read_to_string(&cmd_txt)
        .ok()
        .filter(|c| c.ends_with('\n'))
        .is_none()
    {
        if let Some(status) = child.try_wait().unwrap() {
            let o = child.wait_with_output().unwrap();
            panic!("the viewer exited ({status}) before F12 saved: {}", text(&o.stderr));
        }
        assert!(
            t0.elapsed() < Duration::from_secs(180),
            "F12 did not wake the viewer in 180 s"
        );
        xdotool(&x.display, &["key", "--window", &id, "F12"]);
        std::thread::sleep(Duration::from_secs(1));
    }
    assert!(shot.exists());
    let again = asleep_within(Duration::from_secs(120));
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(again.is_some(), "the viewer did not sleep again after the screenshot");
}

#[test]
fn unmapped_window_keeps_running_and_finishes() {
    let Some(x) = xvfb("view::unmapped_window_keeps_running_and_finishes") else {
        return;
    };
    let dir = scratch("unmap");
    let shot = dir.join("shot.png");
    let Some((child, id)) = view_window(
        &x,
        "view::unmapped_window_keeps_running_and_finishes",
        Some("150"),
        &shot,
    ) else {
        return;
    };
    // hidden (what minimising does without a window manager), then shown again
    xdotool(&x.display, &["windowunmap", "--sync", &id]);
    std::thread::sleep(Duration::from_millis(800));
    xdotool(&x.display, &["windowmap", "--sync", &id]);
    let o = child.wait_with_output().unwrap();
    ok(&o);
    let r = dir.join("render.png");
    ok(&strata(
        None,
        &[
            &["render", "--scene", "cornell", "--out", r.to_str().unwrap()][..],
            &SIZE,
        ]
        .concat(),
    ));
    assert!(flip(&shot, &r) < FLIP_BOUND);
}

#[test]
fn moving_renders_at_reduced_size_and_still_at_full() {
    let Some(x) = xvfb("view::moving_renders_at_reduced_size_and_still_at_full") else {
        return;
    };
    let dir = scratch("motion");
    let base = [&["--scene", "cornell", "--motion-scale", "0.5"][..], &SIZE].concat();
    let (o, shot) = view(&x, &dir, "shot", 30, Some("wait 2\nkey W 20\nwait 3\n"), &base);
    ok(&o);
    let err = text(&o.stderr);
    // the run's summary: frames per kind
    let count = |prefix: &str| -> u32 {
        let l = err
            .lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no '{prefix}' line: {err}"));
        l[prefix.len()..].trim().split(' ').next().unwrap().parse().unwrap()
    };
    let moving = count("strata view: reduced ×0.5 while moving:");
    let still = count("strata view: 160x120:");
    assert!(
        (18..=20).contains(&moving),
        "the 20 moving frames (less the first) are reduced: {moving}"
    );
    assert!(still >= 5, "still frames are full size: {still}");
    let (w, h, _) = rgb(&shot);
    assert_eq!((w, h), (160, 120), "the screenshot is full resolution");
    let r = dir.join("render.png");
    run_cmd_txt(&shot, &r);
    assert!(flip(&shot, &r) < FLIP_BOUND);
}

#[test]
fn hidpi_scale_factor_keeps_the_viewport_exact() {
    let Some(x) = xvfb("view::hidpi_scale_factor_keeps_the_viewport_exact") else {
        return;
    };
    let dir = scratch("hidpi");
    let shot = dir.join("shot.png");
    let win = dir.join("window.png");
    let args = [
        &[
            "view",
            "--scene",
            "cornell",
            "--frames",
            "4",
            "--screenshot",
            shot.to_str().unwrap(),
        ][..],
        &["--window-screenshot", win.to_str().unwrap()],
        &SIZE,
    ]
    .concat();
    // winit's X11 backend takes the DPI scale from this variable
    ok(&strata_env(Some(&x.display), &args, &[("WINIT_X11_SCALE_FACTOR", "2")]));
    let (ww, _, _) = rgb(&win);
    assert!(ww >= 2 * 160 + 600, "the window is laid out at scale 2 ({ww} px wide)");
    assert!(
        find_exact(&rgb(&win), &rgb(&shot)).is_some(),
        "at scale 2 the viewport still shows the frame 1:1 in physical pixels"
    );
    let r = dir.join("render.png");
    ok(&strata(
        None,
        &[
            &["render", "--scene", "cornell", "--out", r.to_str().unwrap()][..],
            &SIZE,
        ]
        .concat(),
    ));
    assert!(
        flip(&shot, &r) < FLIP_BOUND,
        "the render size does not depend on the DPI"
    );
}

#[test]
fn scripted_keys_and_drag_move_the_camera_like_render_with_the_printed_command() {
    let Some(x) = xvfb("view::scripted_keys_and_drag_move_the_camera") else {
        return;
    };
    let dir = scratch("move");
    let base = [&["--scene", "cornell"][..], &SIZE].concat();
    let (o0, still) = view(&x, &dir, "still", 3, None, &base);
    ok(&o0);
    let (o, moved) = view(
        &x,
        &dir,
        "moved",
        16,
        Some("wait 1\nkey W 6\nmouse-drag 80 -30\nkey D 3\nwait 2\n"),
        &base,
    );
    ok(&o);
    assert_not_flat(&moved);
    let d = flip(&still, &moved);
    assert!(d > 0.05, "moving the camera changes the frame (FLIP {d})");
    let cmd = std::fs::read_to_string(moved.with_extension("cmd.txt")).unwrap();
    let still_cmd = std::fs::read_to_string(still.with_extension("cmd.txt")).unwrap();
    let eye = |c: &str| {
        c.split(" --eye ")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .to_string()
    };
    assert_ne!(eye(&cmd), eye(&still_cmd), "the command names the moved camera");
    let r = dir.join("render.png");
    run_cmd_txt(&moved, &r);
    let f = flip(&moved, &r);
    eprintln!("FLIP(moved viewer, render of its command) = {f}");
    assert!(f < FLIP_BOUND, "moved viewer vs render FLIP {f}");
}

#[test]
fn scripted_technique_and_debug_view_switch_match_render() {
    let Some(x) = xvfb("view::scripted_technique_and_debug_view_switch") else {
        return;
    };
    let dir = scratch("switch");
    let base = [&["--scene", "cornell"][..], &SIZE].concat();
    let (o0, direct) = view(&x, &dir, "direct", 3, None, &base);
    ok(&o0);
    let ao_shot = dir.join("ao.png");
    let script = format!(
        "technique ao\nwait 3\nscreenshot {}\nwait 1\ndebug-view layer0-normal\nwait 2\n",
        ao_shot.display()
    );
    let (o, normal) = view(&x, &dir, "normal", 8, Some(&script), &base);
    ok(&o);
    // AO shows ambient visibility as grey
    let (_, _, p) = rgb(&ao_shot);
    assert!(
        p.chunks_exact(3).all(|c| c[0] == c[1] && c[1] == c[2]),
        "the ao frame is grey"
    );
    assert_not_flat(&ao_shot);
    assert!(flip(&direct, &ao_shot) > 0.05, "switching technique changes the frame");
    let line = run_cmd_txt(&ao_shot, &dir.join("ao-render.png"));
    assert!(line.contains("--technique ao"), "{line}");
    let f = flip(&ao_shot, &dir.join("ao-render.png"));
    eprintln!("FLIP(ao viewer, render) = {f}");
    assert!(f < FLIP_BOUND, "ao: viewer vs render FLIP {f}");
    // the debug view
    let line = run_cmd_txt(&normal, &dir.join("normal-render.png"));
    assert!(line.contains("--debug-view layer0-normal"), "{line}");
    assert!(flip(&normal, &dir.join("normal-render.png")) < FLIP_BOUND);
    assert!(flip(&ao_shot, &normal) > 0.05, "switching debug view changes the frame");
    // normals as colours: not grey
    let (_, _, p) = rgb(&normal);
    assert!(p.chunks_exact(3).filter(|c| c[0] != c[1] || c[1] != c[2]).count() > p.len() / 3 / 4);
    // a reduced second layer (DGB Fig. 11) from the script, as the panel's 1/s sets it
    let script = "layers 2\nlayer-scale 2\ndebug-view layer1-normal\nwait 2\n";
    let (o, reduced) = view(&x, &dir, "reduced", 4, Some(script), &base);
    ok(&o);
    let line = run_cmd_txt(&reduced, &dir.join("reduced-render.png"));
    assert!(
        line.contains("--layers 2") && line.contains("--layer-scale 2"),
        "{line}"
    );
    assert!(flip(&reduced, &dir.join("reduced-render.png")) < FLIP_BOUND);
}

/// The exposure field: a script's `exposure auto` meters the frame as `render --exposure
/// auto` does (the printed command carries it and reproduces the screenshot), it changes
/// the Cornell box's frame, and `exposure scene` returns to the scene's.
#[test]
fn scripted_exposure_matches_render() {
    let Some(x) = xvfb("view::scripted_exposure_matches_render") else {
        return;
    };
    let dir = scratch("exposure");
    let base = [&["--scene", "cornell"][..], &SIZE].concat();
    let (o0, scene) = view(&x, &dir, "scene", 3, None, &base);
    ok(&o0);
    let (o, auto) = view(&x, &dir, "auto", 4, Some("exposure auto\nwait 2\n"), &base);
    ok(&o);
    let (line, rendered) = run_cmd_txt_output(&auto, &dir.join("auto-render.png"));
    assert!(line.contains("--exposure auto"), "{line}");
    assert!(flip(&auto, &dir.join("auto-render.png")) < FLIP_BOUND);
    // the exposure the panel shows is the one `render` meters for the same frame
    let metered = |text: &str| -> f32 {
        let l = text
            .lines()
            .find_map(|l| l.trim_start_matches("# ").strip_prefix("exposure (metered): "));
        l.unwrap_or_else(|| panic!("no metered exposure in {text}"))
            .trim()
            .parse()
            .unwrap()
    };
    let shown = metered(&std::fs::read_to_string(auto.with_extension("cmd.txt")).unwrap());
    let rendered = metered(&text(&rendered.stderr));
    assert!(
        (shown / rendered - 1.0).abs() < 0.01,
        "the viewer shows exposure {shown}, render meters {rendered}"
    );
    assert!(
        flip(&scene, &auto) > 0.05,
        "auto-exposure does not change the Cornell box's frame"
    );
    let (o, back) = view(
        &x,
        &dir,
        "back",
        6,
        // a fixed `set exposure` first: the field replaces it rather than refusing auto beside it
        Some("set exposure 3\nwait 1\nexposure auto\nwait 2\nexposure scene\nwait 2\n"),
        &base,
    );
    ok(&o);
    let line = run_cmd_txt(&back, &dir.join("back-render.png"));
    assert!(!line.contains("--exposure"), "{line}");
    let cmd = std::fs::read_to_string(back.with_extension("cmd.txt")).unwrap();
    assert!(!cmd.contains("metered"), "a fixed exposure is not metered: {cmd}");
    assert!(!text(&o.stderr).contains("exposure="), "{}", text(&o.stderr));
    assert!(flip(&scene, &back) < FLIP_BOUND);
}

#[test]
fn bad_settings_show_the_cli_error_and_keep_the_frame() {
    let Some(x) = xvfb("view::bad_settings_show_the_cli_error") else {
        return;
    };
    let dir = scratch("badset");
    let base = [&["--scene", "cornell", "--technique", "ao"][..], &SIZE].concat();
    let (o, shot) = view(
        &x,
        &dir,
        "shot",
        5,
        Some("set samples 99999\nlayers 9\ntechnique nope\ndebug-view nope\n"),
        &base,
    );
    ok(&o);
    let err = text(&o.stderr);
    // render's own messages, one line each
    for needle in [
        "--set samples=99999",
        "out of range",
        "layers",
        "unknown technique 'nope'",
        "unknown debug view 'nope'",
    ] {
        assert!(err.contains(needle), "stderr lacks '{needle}': {err}");
    }
    let cmd = std::fs::read_to_string(shot.with_extension("cmd.txt")).unwrap();
    assert!(
        !cmd.contains("99999") && cmd.contains("--layers 1"),
        "bad values are not applied: {cmd}"
    );
    let r = dir.join("render.png");
    run_cmd_txt(&shot, &r);
    assert!(flip(&shot, &r) < FLIP_BOUND);
}

/// A one-quad GLB (no texture).
fn quad_glb() -> Vec<u8> {
    let f: Vec<u8> = [-1.0f32, 0.0, -1.0, 1.0, 0.0, -1.0, 1.0, 0.0, 1.0, -1.0, 0.0, 1.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let idx: Vec<u8> = [0u16, 2, 1, 0, 3, 2].iter().flat_map(|i| i.to_le_bytes()).collect();
    let mut bin = f.clone();
    bin.extend(&idx);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{"byteLength":{}}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":12}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,0,-1],"max":[1,0,1]}},
{{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#,
        bin.len()
    );
    let mut j = json.into_bytes();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + bin.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&j);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(&bin);
    out
}

#[test]
fn truncated_glb_shows_the_error_and_keeps_the_scene() {
    let Some(x) = xvfb("view::truncated_glb_shows_the_error") else {
        return;
    };
    let dir = scratch("open");
    let good = dir.join("quad.glb");
    let bad = dir.join("truncated.glb");
    let bytes = quad_glb();
    std::fs::write(&good, &bytes).unwrap();
    std::fs::write(&bad, &bytes[..bytes.len() * 2 / 3]).unwrap();
    assert!(
        strata_scene::load_scene(good.to_str().unwrap()).is_ok(),
        "the untruncated GLB loads"
    );
    let base = [&["--scene", "cornell"][..], &SIZE].concat();
    let (o, shot) = view(
        &x,
        &dir,
        "kept",
        6,
        Some(&format!("wait 1\nopen {}\nwait 2\n", bad.display())),
        &base,
    );
    ok(&o);
    let err = text(&o.stderr);
    let line = err
        .lines()
        .find(|l| l.contains("open:"))
        .unwrap_or_else(|| panic!("no open error: {err}"));
    assert!(line.contains("truncated.glb"), "the error names the file: {line}");
    // still cornell: equal to its render
    let r = dir.join("render.png");
    ok(&strata(
        None,
        &[
            &["render", "--scene", "cornell", "--out", r.to_str().unwrap()][..],
            &SIZE,
        ]
        .concat(),
    ));
    assert!(flip(&shot, &r) < FLIP_BOUND, "the current scene is kept");
    // the good file opens through the same path, and the command names it
    let (o2, shot2) = view(
        &x,
        &dir,
        "opened",
        6,
        Some(&format!("wait 1\nopen {}\nwait 2\n", good.display())),
        &base,
    );
    ok(&o2);
    assert!(text(&o2.stderr).contains("opened"), "{}", text(&o2.stderr));
    let cmd = std::fs::read_to_string(shot2.with_extension("cmd.txt")).unwrap();
    assert!(cmd.contains("quad.glb"), "{cmd}");
    let r2 = dir.join("render2.png");
    run_cmd_txt(&shot2, &r2);
    assert!(flip(&shot2, &r2) < FLIP_BOUND);
}

#[test]
fn recorded_path_loads_as_a_scene_and_resize_and_fit_survive() {
    let Some(x) = xvfb("view::recorded_path_loads_as_a_scene") else {
        return;
    };
    let dir = scratch("record");
    let path = dir.join("path.toml");
    let script = format!(
        "record-start\nkey D 25\nmouse-drag 50 0\nkey W 10\nrecord-stop {}\nresize 500 380\nwait 2\nfit on\nwait 2\nresize 900 700\nwait 3\n",
        path.display()
    );
    let (o, shot) = view(
        &x,
        &dir,
        "shot",
        45,
        Some(&script),
        &[&["--scene", "cornell"][..], &SIZE].concat(),
    );
    ok(&o);
    let scene = strata_scene::load_scene(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
    let p = scene.camera_path.clone().expect("a camera path");
    assert!(p.keyframes.len() >= 3, "{} keyframes", p.keyframes.len());
    assert_eq!(
        scene.triangle_count(),
        strata_scene::load_scene("cornell").unwrap().triangle_count()
    );
    let first = p.keyframes[0];
    let last = p.keyframes[p.keyframes.len() - 1];
    assert!((last.eye - first.eye).length() > 0.05, "the path moves");
    // fit on: the render size followed the window
    let (w, h, _) = rgb(&shot);
    assert_ne!((w, h), (160, 120), "fit to window changed the render size");
    let r = dir.join("render.png");
    run_cmd_txt(&shot, &r);
    assert!(flip(&shot, &r) < FLIP_BOUND);
    // the recorded file renders along its path
    let out = dir.join("along.png");
    ok(&strata(
        None,
        &[
            "render",
            "--scene",
            path.to_str().unwrap(),
            "--frame",
            "10",
            "--width",
            "64",
            "--height",
            "48",
            "--out",
            out.to_str().unwrap(),
        ],
    ));
}

#[test]
fn every_technique_and_debug_view_is_reachable() {
    let Some(x) = xvfb("view::every_technique_and_debug_view_is_reachable") else {
        return;
    };
    let dir = scratch("all");
    let small = ["--width", "64", "--height", "48"];
    let mut script = String::new();
    let mut shots = Vec::new();
    let techniques: Vec<&str> = strata_render::technique::registry().iter().map(|t| t.name).collect();
    for t in &techniques {
        // every debug view of the technique's two-layer frame, as `render --list-passes` lists them
        let lp = ok(&strata(
            None,
            &[
                &[
                    "render",
                    "--scene",
                    "cornell",
                    "--technique",
                    t,
                    "--layers",
                    "2",
                    "--list-passes",
                ][..],
                &small,
            ]
            .concat(),
        ))
        .stdout
        .clone();
        let lp = text(&lp);
        let views: Vec<String> = lp
            .lines()
            .find_map(|l| l.strip_prefix("debug views: "))
            .expect("debug views line")
            .split(", ")
            .map(String::from)
            .collect();
        assert!(views.len() > 20, "{t}: {views:?}");
        let final_shot = dir.join(format!("{t}.png"));
        script += &format!(
            "layers 1\ntechnique {t}\nlayers 2\nwait 1\nscreenshot {}\n",
            final_shot.display()
        );
        shots.push((t.to_string(), "final".to_string(), final_shot));
        for v in views {
            let shot = dir.join(format!("{t}--{v}.png"));
            script += &format!("debug-view {v}\nscreenshot {}\nwait 1\n", shot.display());
            shots.push((t.to_string(), v, shot));
        }
        script += "debug-view final\n";
    }
    // a screenshot defers the actions after it to the next frame
    let frames = script_frames(&script) + shots.len() as u32 + 2;
    let (o, _) = view(
        &x,
        &dir,
        "end",
        frames,
        Some(&script),
        &[&["--scene", "cornell"][..], &small].concat(),
    );
    ok(&o);
    let err = text(&o.stderr);
    assert!(!err.contains("strata view: error"), "{err}");
    for (t, v, shot) in &shots {
        assert!(shot.exists(), "technique {t}, view {v} not shown");
        let cmd = std::fs::read_to_string(shot.with_extension("cmd.txt")).unwrap();
        assert!(
            cmd.contains(&format!("--technique {t} ")) && cmd.contains("--layers 2"),
            "{cmd}"
        );
        assert!(
            cmd.contains("--width 64 --height 48"),
            "the frame's size, whatever the view's: {cmd}"
        );
        if v != "final" {
            assert!(cmd.contains(&format!("--debug-view {v} ")), "{cmd}");
        }
    }
    eprintln!("{} technique/view pairs shown", shots.len());
    // every technique's final frame equals `render` of its command
    for t in &techniques {
        let shot = dir.join(format!("{t}.png"));
        let r = dir.join(format!("{t}-render.png"));
        run_cmd_txt(&shot, &r);
        let f = flip(&shot, &r);
        eprintln!("FLIP({t} viewer, render) = {f}");
        assert!(f < FLIP_BOUND, "{t}: viewer vs render FLIP {f}");
    }
    // spot-check a layer-1 view of full against render
    let shot = dir.join("full--layer1-normal.png");
    let r = dir.join("render.png");
    run_cmd_txt(&shot, &r);
    assert!(flip(&shot, &r) < FLIP_BOUND, "full layer1-normal: viewer vs render");
}

/// Frames a script spans (its `wait` commands).
fn script_frames(script: &str) -> u32 {
    script
        .lines()
        .filter_map(|l| l.strip_prefix("wait "))
        .map(|n| n.trim().parse::<u32>().unwrap())
        .sum()
}

/// `render`'s cost warning for a `bzb-gi` frame of minutes (AOV splats over whole
/// sub-images: atrium at 1280×720 is 2.9·10¹⁰ ray–triangle tests) reaches the viewer's
/// stderr and status line too, and before that frame: the test reads stderr while the
/// first frame renders (about 4 minutes on lavapipe) and stops the viewer once the line
/// is there.
#[test]
fn view_warns_of_a_full_screen_bzb_gi_splat_before_its_frame() {
    use std::io::BufRead;
    let Some(x) = xvfb("view::view_warns_of_a_full_screen_bzb_gi_splat_before_its_frame") else {
        return;
    };
    let dir = scratch("bzb-gi-cost");
    let shot = dir.join("shot.png");
    let mut child = spawn_view(
        &x,
        &[
            "view",
            "--scene",
            "atrium",
            "--technique",
            "bzb-gi",
            "--width",
            "1280",
            "--height",
            "720",
            "--frames",
            "1",
            "--screenshot",
            shot.to_str().unwrap(),
        ],
        &dir,
    );
    let (tx, rx) = std::sync::mpsc::channel();
    let stderr = child.stderr.take().unwrap();
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(stderr).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let t0 = Instant::now();
    let mut seen = Vec::new();
    let warning = loop {
        match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(l) if l.starts_with("strata view: warning: bzb-gi:") => break Some(l),
            Ok(l) => seen.push(l),
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break None,
            Err(_) if t0.elapsed() > Duration::from_secs(150) => break None,
            Err(_) => {}
        }
    };
    let _ = child.kill();
    let _ = child.wait();
    let w = warning.unwrap_or_else(|| panic!("no bzb-gi cost warning before the frame: {seen:?}"));
    assert!(
        w.contains("7866 triangles × 4 directions × 1280x720 = 2.9e10") && w.contains("splat=dss"),
        "{w}"
    );
    assert!(
        !shot.exists(),
        "the frame of minutes finished before the warning was read"
    );
}

/// Where `small` (w×h RGB) lies inside `big` pixel for pixel, if anywhere.
fn find_exact(big: &(u32, u32, Vec<u8>), small: &(u32, u32, Vec<u8>)) -> Option<(u32, u32)> {
    let (bw, bh, b) = big;
    let (sw, sh, s) = small;
    let row = |img: &Vec<u8>, w: u32, x: u32, y: u32, n: u32| {
        let i = ((y * w + x) * 3) as usize;
        img[i..i + (n * 3) as usize].to_vec()
    };
    for y in 0..=bh.checked_sub(*sh)? {
        for x in 0..=bw.checked_sub(*sw)? {
            if (0..*sh).all(|j| row(b, *bw, x, y + j, *sw) == row(s, *sw, 0, j, *sw)) {
                return Some((x, y));
            }
        }
    }
    None
}

/// The window shows the frame's PNG bytes exactly: the viewport inside the whole window's
/// screenshot equals the frame's screenshot (= `strata render`'s PNG) pixel for pixel, for
/// a target encoded on the GPU (`ldr`, sRGB; `ao`, linear R16Float) and for a debug view,
/// which the CPU encodes.
#[test]
fn the_window_shows_the_frame_bytes_exactly() {
    let Some(x) = xvfb("view::the_window_shows_the_frame_bytes_exactly") else {
        return;
    };
    let dir = scratch("window-bytes");
    for (name, extra) in [
        ("direct", &["--technique", "direct"][..]),
        ("ao", &["--technique", "ao"][..]),
        (
            "normal",
            &["--technique", "direct", "--debug-view", "layer0-normal"][..],
        ),
    ] {
        let win = dir.join(format!("{name}-window.png"));
        let (o, shot) = view(
            &x,
            &dir,
            name,
            6,
            None,
            &[
                &["--scene", "cornell", "--window-screenshot", win.to_str().unwrap()][..],
                extra,
                &SIZE,
            ]
            .concat(),
        );
        ok(&o);
        if name != "normal" {
            // (the box's flat walls have a handful of normals)
            assert_not_flat(&shot);
        }
        let at = find_exact(&rgb(&win), &rgb(&shot));
        assert!(at.is_some(), "{name}: the window does not show the frame's bytes 1:1");
    }
}

/// The display gain and false colour (script `gain`, `false-colour`) change what the window
/// shows and not the screenshot: with gain 2 the viewport holds the PNG's bytes decoded,
/// doubled and encoded again (the GPU encoder's gain), and false colour turns the grey AO
/// into colours (the CPU path, from the frame read back while its renderer lives).
#[test]
fn display_gain_and_false_colour_change_only_the_window() {
    let Some(x) = xvfb("view::display_gain_and_false_colour_change_only_the_window") else {
        return;
    };
    let dir = scratch("window-gain");
    let run = |name: &str, technique: &str, script: Option<&str>| {
        let win = dir.join(format!("{name}-window.png"));
        let (o, shot) = view(
            &x,
            &dir,
            name,
            8,
            script,
            &[
                &[
                    "--scene",
                    "cornell",
                    "--technique",
                    technique,
                    "--window-screenshot",
                    win.to_str().unwrap(),
                ][..],
                &SIZE,
            ]
            .concat(),
        );
        ok(&o);
        (rgb(&win), rgb(&shot))
    };
    let region = |win: &(u32, u32, Vec<u8>), (x0, y0): (u32, u32), w: u32, h: u32| -> Vec<u8> {
        (0..h)
            .flat_map(|y| {
                let i = (((y0 + y) * win.0 + x0) * 3) as usize;
                win.2[i..i + (w * 3) as usize].to_vec()
            })
            .collect()
    };
    // gain 2 on the final image
    let (win, shot) = run("plain", "direct", None);
    let at = find_exact(&win, &shot).expect("the plain window shows the frame");
    let (gwin, gshot) = run("gain", "direct", Some("wait 3\ngain 2\nwait 4\n"));
    assert_eq!(gshot.2, shot.2, "the screenshot has no gain");
    let want: Vec<u8> = shot
        .2
        .iter()
        .map(|&b| strata_scene::image_buf::to_byte(strata_scene::model::srgb_to_linear(b) * 2.0, true))
        .collect();
    let got = region(&gwin, at, shot.0, shot.1);
    let differ = got.iter().zip(&want).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "{differ} bytes of the gained viewport differ");
    assert!(want != shot.2, "gain 2 changes the bytes");
    // false colour on the AO
    let (win, shot) = run("ao", "ao", None);
    let at = find_exact(&win, &shot).expect("the AO window shows the frame");
    assert!(
        shot.2.chunks_exact(3).all(|p| p[0] == p[1] && p[1] == p[2]),
        "AO is grey"
    );
    let (fwin, _) = run("ao-false", "ao", Some("wait 3\nfalse-colour on\nwait 4\n"));
    let got = region(&fwin, at, shot.0, shot.1);
    let coloured = got
        .chunks_exact(3)
        .filter(|p| p.iter().max().unwrap() - p.iter().min().unwrap() > 30)
        .count();
    // (the heat scale is white where AO is 1, most of the box)
    assert!(
        coloured * 5 > got.len() / 3,
        "false colour: {coloured} of {} pixels are coloured",
        got.len() / 3
    );
}
