//! The egui panels. Widgets only queue [`Action`]s; the frame loop applies them.

use egui::{Color32, RichText};
use strata_render::passes::deep_gbuffer::Variant;
use strata_render::technique::registry;

use crate::app::{App, BOTTOM_HEIGHT, HISTORY, PANEL_WIDTH};
use crate::camera::Mode;
use crate::Action;

fn entered(ui: &egui::Ui, r: &egui::Response) -> bool {
    r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter))
}

/// A stable colour per pass name.
fn pass_colour(name: &str) -> Color32 {
    let h = name
        .bytes()
        .fold(2166136261u32, |h, b| (h ^ b as u32).wrapping_mul(16777619));
    let hue = (h % 360) as f32 / 360.0;
    let c = egui::ecolor::Hsva::new(hue, 0.65, 0.9, 1.0);
    c.into()
}

pub fn draw(app: &mut App, ui: &mut egui::Ui) {
    egui::Panel::bottom("timings")
        .resizable(true)
        .default_size(BOTTOM_HEIGHT)
        .min_size(BOTTOM_HEIGHT)
        .show(ui, |ui| timing_panel(app, ui));
    egui::Panel::right("settings")
        .resizable(true)
        .default_size(PANEL_WIDTH)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| settings_panel(app, ui));
        });
    egui::CentralPanel::default()
        .frame(egui::Frame::NONE.fill(Color32::from_gray(12)))
        .show(ui, |ui| viewport(app, ui));
}

fn viewport(app: &mut App, ui: &mut egui::Ui) {
    let avail = ui.available_size();
    let ppp = ui.ctx().pixels_per_point();
    app.viewport_px = (
        (avail.x * ppp).floor().max(0.0) as u32,
        (avail.y * ppp).floor().max(0.0) as u32,
    );
    let r = ui.max_rect();
    app.viewport_rect = Some([r.min.x * ppp, r.min.y * ppp, r.max.x * ppp, r.max.y * ppp]);
    let Some(t) = app.viewport_tex else {
        ui.centered_and_justified(|ui| ui.label("no frame yet"));
        return;
    };
    let (w, h) = match &app.shown {
        // the reduced frame is shown at the full frame's size
        Some(s) if !s.full => (app.render_size.0 as f32, app.render_size.1 as f32),
        Some(s) => (s.width as f32, s.height as f32),
        None => (1.0, 1.0),
    };
    // 1:1 in physical pixels when it fits, else scaled down keeping the aspect
    let mut size = egui::vec2(w / ppp, h / ppp);
    let k = (avail.x / size.x).min(avail.y / size.y).min(1.0);
    if k.is_finite() && k > 0.0 {
        size *= k;
    }
    ui.centered_and_justified(|ui| {
        ui.add(egui::Image::new((t, size)).fit_to_exact_size(size));
    });
}

fn settings_panel(app: &mut App, ui: &mut egui::Ui) {
    ui.heading("strata view");
    ui.label(RichText::new(format!("adapter: {}", app.adapter_name)).small());
    ui.separator();

    // scene
    ui.label(
        RichText::new(format!(
            "scene: {} ({} triangles)",
            app.scene.name,
            app.scene.triangle_count()
        ))
        .strong(),
    );
    ui.horizontal(|ui| {
        let r = ui.add(
            egui::TextEdit::singleline(&mut app.open_text)
                .hint_text("file.glb / .gltf / .obj / .toml")
                .desired_width(200.0),
        );
        if ui.button("Open").clicked() || entered(ui, &r) {
            app.actions.push(Action::Open(app.open_text.clone()));
        }
    });
    ui.label(RichText::new("or drop a file on the window").small());
    ui.separator();

    // camera
    ui.horizontal(|ui| {
        ui.label("camera:");
        let mut m = app.cam.mode;
        ui.radio_value(&mut m, Mode::Fly, "fly");
        ui.radio_value(&mut m, Mode::Orbit, "orbit");
        if m != app.cam.mode {
            app.actions.push(Action::Mode(m));
        }
    });
    let c = app.cam.camera();
    ui.label(
        RichText::new(format!(
            "eye ({:.3}, {:.3}, {:.3}) target ({:.3}, {:.3}, {:.3}), fov {:.1}°, speed {:.3}/s",
            c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.fov_y_deg, app.cam.speed
        ))
        .small(),
    );
    ui.label(RichText::new("WASD/QE move, right-drag look, wheel speed, Tab fly/orbit, F12 screenshot").small());
    if let Some(p) = app.scene.camera_path.clone() {
        ui.horizontal(|ui| {
            if ui.button(if app.playing { "pause" } else { "play" }).clicked() {
                app.actions.push(Action::Play(!app.playing));
            }
            let mut l = app.looping;
            if ui.checkbox(&mut l, "loop").changed() {
                app.actions.push(Action::Loop(l));
            }
        });
        let mut f = app.frame_t;
        if ui
            .add(egui::Slider::new(&mut f, p.first_frame()..=p.last_frame()).text("path frame"))
            .changed()
        {
            app.actions.push(Action::Seek(f));
        }
    } else {
        ui.label(RichText::new("the scene has no camera path").small());
    }
    ui.horizontal(|ui| {
        if app.recording.is_some() {
            if ui.button("stop & write").clicked() {
                app.actions.push(Action::Record(Some(app.record_path.clone().into())));
            }
            ui.label(format!("{} keys", app.recording.as_ref().map_or(0, |k| k.len())));
        } else if ui.button("record path").clicked() {
            app.actions.push(Action::Record(None));
        }
        ui.add(egui::TextEdit::singleline(&mut app.record_path).desired_width(150.0));
    });
    ui.separator();

    // technique
    let tech = app.technique();
    egui::ComboBox::from_label("technique")
        .selected_text(tech.name)
        .show_ui(ui, |ui| {
            for t in registry() {
                if ui
                    .selectable_label(t.name == tech.name, t.name)
                    .on_hover_text(t.doc)
                    .clicked()
                    && t.name != tech.name
                {
                    app.actions.push(Action::Technique(t.name.to_string()));
                }
            }
        });
    ui.label(RichText::new(tech.doc).small());
    if !tech.presets.is_empty() {
        let cur = app.spec.preset.clone().unwrap_or_else(|| tech.presets[0].to_string());
        egui::ComboBox::from_label("preset")
            .selected_text(&cur)
            .show_ui(ui, |ui| {
                for p in tech.presets {
                    if ui.selectable_label(*p == cur, *p).clicked() && *p != cur {
                        app.actions.push(Action::Preset(p.to_string()));
                    }
                }
            });
    }
    ui.horizontal(|ui| {
        let mut l = app.spec.layers;
        ui.label("layers");
        if ui.add(egui::DragValue::new(&mut l).range(1..=8)).changed() {
            app.actions.push(Action::Layers(l));
        }
        let cur = app.spec.variant.clone();
        egui::ComboBox::from_id_salt("variant")
            .selected_text(format!("variant {cur}"))
            .show_ui(ui, |ui| {
                for v in Variant::ALL {
                    if ui.selectable_label(v.name() == cur, v.name()).clicked() && v.name() != cur {
                        app.actions.push(Action::Variant(v.name().to_string()));
                    }
                }
            });
        // DGB Fig. 11: layers >= 1 at 1/s resolution
        let mut s = app.spec.layer_scale;
        ui.label("1/");
        if ui
            .add(egui::DragValue::new(&mut s).range(1..=strata_render::passes::deep_gbuffer::MAX_LAYER_SCALE))
            .on_hover_text("layer scale: layers >= 1 at 1/s of the resolution (DGB Fig. 11)")
            .changed()
        {
            app.actions.push(Action::LayerScale(s));
        }
    });
    ui.horizontal(|ui| {
        ui.label("guard band");
        let r = ui.add(egui::TextEdit::singleline(&mut app.guard_text).desired_width(60.0));
        if entered(ui, &r) {
            app.actions.push(Action::GuardBand(app.guard_text.trim().to_string()));
        }
        if let Some(s) = &app.settings {
            ui.label(RichText::new(format!("= {} px", s.guard_pixels())).small());
        }
    });
    ui.horizontal(|ui| {
        ui.label("exposure");
        let r = ui
            .add(
                egui::TextEdit::singleline(&mut app.exposure_text)
                    .desired_width(60.0)
                    // grows with `auto:key=K,adapt=A,...` instead of hiding its end
                    .clip_text(false)
                    .hint_text("scene"),
            )
            .on_hover_text("a number > 0, auto, auto:KEY or auto:key=K,adapt=A,low=L,high=H (metered every frame; adapt < 1 follows it over about 1/A frames); empty: the scene's");
        if entered(ui, &r) {
            let e = app.exposure_text.trim();
            app.actions
                .push(Action::Exposure((!e.is_empty()).then(|| e.to_string())));
        }
        if let Some(e) = app.shown.as_ref().and_then(|s| s.exposure) {
            let metered = app.spec.exposure.as_deref().is_some_and(|e| e.starts_with("auto"));
            ui.label(RichText::new(format!("= {e:.3}{}", if metered { " metered" } else { "" })).small())
                .on_hover_text("the exposure the shown frame was tonemapped with");
        }
    });

    // every setting of the technique, applied through the CLI's validation
    egui::CollapsingHeader::new("settings")
        .default_open(true)
        .show(ui, |ui| {
            egui::Grid::new("settings-grid")
                .num_columns(3)
                .striped(true)
                .show(ui, |ui| {
                    // the exposure field above stands for the `exposure` setting
                    for info in tech.setting_list().filter(|i| i.name != "exposure") {
                        let current = app.settings.as_ref().and_then(|s| (info.get)(s));
                        let shown = match current {
                            Some(v) if !info.values.is_empty() => {
                                info.values.get(v as usize).map_or(v.to_string(), |n| n.to_string())
                            }
                            Some(v) => format!("{}", v as f32),
                            None => "scene".into(),
                        };
                        ui.label(info.name)
                            .on_hover_text(format!("{} (range {})", info.doc, info.range));
                        if info.values.is_empty() {
                            let text = app
                                .setting_text
                                .entry(info.name.to_string())
                                .or_insert_with(|| shown.clone());
                            let r = ui.add_sized([80.0, 18.0], egui::TextEdit::singleline(text));
                            if entered(ui, &r) {
                                app.actions
                                    .push(Action::Set(info.name.to_string(), text.trim().to_string()));
                            }
                        } else {
                            egui::ComboBox::from_id_salt(info.name)
                                .selected_text(&shown)
                                .show_ui(ui, |ui| {
                                    for v in info.values {
                                        if ui.selectable_label(*v == shown, *v).clicked() && *v != shown {
                                            app.actions.push(Action::Set(info.name.to_string(), v.to_string()));
                                        }
                                    }
                                });
                        }
                        ui.label(RichText::new(info.range.to_string()).small());
                        ui.end_row();
                    }
                });
        });
    ui.separator();

    // debug views: every target of the current frame
    let cur = app.debug_view.clone().unwrap_or_else(|| "final".into());
    egui::ComboBox::from_label("debug view")
        .selected_text(&cur)
        .height(400.0)
        .show_ui(ui, |ui| {
            if ui.selectable_label(app.debug_view.is_none(), "final").clicked() {
                app.actions.push(Action::DebugView(None));
            }
            for v in app.view_names.clone() {
                if ui
                    .selectable_label(app.debug_view.as_deref() == Some(v.as_str()), &v)
                    .clicked()
                {
                    app.actions.push(Action::DebugView(Some(v)));
                }
            }
        });
    ui.horizontal(|ui| {
        ui.add(
            egui::Slider::new(&mut app.gain, 0.125..=16.0)
                .logarithmic(true)
                .text("display gain"),
        );
    });
    ui.checkbox(
        &mut app.false_colour,
        "false colour (one-channel views: depth, counts, confidence)",
    );
    ui.separator();

    // resolution
    ui.label(format!("render size {}×{}", app.render_size.0, app.render_size.1));
    let mut fit = app.fit_window;
    if ui.checkbox(&mut fit, "fit render size to the window").changed() {
        app.actions.push(Action::Fit(fit));
    }
    let mut m = app.motion_scale;
    if ui
        .add(egui::Slider::new(&mut m, 0.1..=1.0).text("scale while moving"))
        .on_hover_text("internal resolution while the camera moves; full resolution when still")
        .changed()
    {
        app.actions.push(Action::MotionScale(m));
    }
    ui.separator();
    if ui.button("save PNG + strata render command (F12)").clicked() {
        app.actions.push(Action::Screenshot(None));
    }
}

fn timing_panel(app: &mut App, ui: &mut egui::Ui) {
    if let Some((msg, err)) = &app.status {
        let c = if *err {
            Color32::from_rgb(255, 110, 100)
        } else {
            Color32::from_gray(200)
        };
        ui.colored_label(c, msg);
    }
    let last = app.timings.back();
    let gpu: f64 = last.map_or(0.0, |t| t.passes.iter().map(|p| p.1).sum());
    ui.label(format!(
        "frame {:.1} ms ({:.1} fps), GPU {:.2} ms{}",
        app.last_frame_ms,
        1e3 / app.last_frame_ms.max(1e-3),
        gpu,
        if last.is_some_and(|t| t.reduced) {
            " — reduced resolution while moving"
        } else {
            ""
        }
    ));
    let ch = (ui.available_height() - 6.0).max(80.0);
    ui.horizontal(|ui| {
        ui.set_height(ch);
        // rolling stacked bars: one per frame, one segment per pass
        let (rect, _) = ui.allocate_exact_size(egui::vec2(ui.available_width() * 0.62, ch), egui::Sense::hover());
        let p = ui.painter_at(rect);
        p.rect_filled(rect, 2.0, Color32::from_gray(25));
        let max = app
            .timings
            .iter()
            .map(|t| t.passes.iter().map(|p| p.1).sum::<f64>())
            .fold(1e-3, f64::max);
        // newest on the right
        let bw = rect.width() / HISTORY as f32;
        let first = HISTORY - app.timings.len().min(HISTORY);
        for (i, t) in app.timings.iter().enumerate() {
            let x = rect.left() + (first + i) as f32 * bw;
            let mut y = rect.bottom();
            for (name, ms) in &t.passes {
                let hgt = (*ms / max) as f32 * (rect.height() - 16.0);
                p.rect_filled(
                    egui::Rect::from_min_max(egui::pos2(x, y - hgt), egui::pos2(x + bw * 0.85, y)),
                    0.0,
                    pass_colour(name),
                );
                y -= hgt;
            }
        }
        p.text(
            rect.left_top() + egui::vec2(4.0, 2.0),
            egui::Align2::LEFT_TOP,
            format!("GPU per frame, last {HISTORY} frames; top = {max:.1} ms"),
            egui::FontId::monospace(11.0),
            Color32::GRAY,
        );
        // legend: pass, last and mean ms
        egui::ScrollArea::vertical()
            .id_salt("legend")
            .max_height(ch)
            .show(ui, |ui| {
                egui::Grid::new("legend-grid").num_columns(3).show(ui, |ui| {
                    if let Some(t) = last {
                        for (name, ms) in &t.passes {
                            let n = app.timings.len().max(1) as f64;
                            let mean = app
                                .timings
                                .iter()
                                .filter_map(|t| t.passes.iter().find(|p| &p.0 == name))
                                .map(|p| p.1)
                                .sum::<f64>()
                                / n;
                            ui.colored_label(pass_colour(name), name.as_str());
                            ui.label(RichText::new(format!("{ms:.2}")).monospace());
                            ui.label(RichText::new(format!("avg {mean:.2} ms")).monospace().small());
                            ui.end_row();
                        }
                    } else {
                        ui.label("no GPU timings (the adapter lacks timestamp queries, or no frame yet)");
                    }
                });
            });
    });
}
