//! The model panel's tabs besides the browser (`browser.rs`): the user preset folder, the file
//! browser and the script editor with its diagnostics. Each loads a model only through
//! [`EditorApp::submit`], so a script with errors never replaces the running one.

use super::*;

impl EditorApp {
    /// The user preset folder, and saving the running script there.
    pub(super) fn user_presets(&mut self, ui: &mut Ui) {
        let Some(dir) = self.user_dir.clone() else {
            ui.colored_label(ORANGE, "No user data folder on this system");
            return;
        };
        ui.horizontal(|ui| {
            ui.label(RichText::new("User presets").strong());
            if ui
                .small_button("Refresh")
                .on_hover_text("Read the folder again: its presets join the list above")
                .clicked()
            {
                self.refresh_library();
            }
        });
        ui.label(
            RichText::new(dir.display().to_string())
                .small()
                .color(Color32::GRAY),
        );
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(&mut self.save_name)
                    .hint_text("name")
                    .desired_width(140.0),
            );
            if ui
                .button("Save as preset")
                .on_hover_text("Save the running script into the user preset folder")
                .clicked()
            {
                match preset_file_name(&self.save_name) {
                    None => self.message = Some(("type a name for the preset".into(), ORANGE)),
                    Some(file) => {
                        let path = dir.join(file);
                        let running = self.store.running();
                        match save_script(&path, &running.script) {
                            Ok(()) => {
                                self.message = Some((format!("saved {}", path.display()), GREEN));
                                self.refresh_library();
                            }
                            Err(e) => self.message = Some((e, RED)),
                        }
                    }
                }
            }
        });
    }

    pub(super) fn file_tab(&mut self, ui: &mut Ui) {
        let mut go = None;
        let mut open = None;
        ui.horizontal(|ui| {
            if ui.button("Up").on_hover_text("Parent folder").clicked() {
                if let Some(parent) = self.browser.dir.parent() {
                    go = Some(parent.to_path_buf());
                }
            }
            let r = ui.add(
                egui::TextEdit::singleline(&mut self.browser.path_text)
                    .desired_width(f32::INFINITY),
            );
            if r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                let path = PathBuf::from(self.browser.path_text.trim());
                if path.is_dir() {
                    go = Some(path);
                } else {
                    open = Some(path);
                }
            }
        });
        ui.label(
            RichText::new("Folders and .mdl scripts; type a path and press Enter to open it")
                .small()
                .color(Color32::GRAY),
        );
        if let Some(e) = &self.browser.error {
            ui.colored_label(RED, e);
        }
        ui.horizontal(|ui| {
            if self.save_path.is_empty() {
                let running = self.store.running();
                let file = preset_file_name(&running.name).unwrap_or_else(|| "model.mdl".into());
                self.save_path = self.browser.dir.join(file).display().to_string();
            }
            ui.add(egui::TextEdit::singleline(&mut self.save_path).desired_width(200.0));
            if ui
                .button("Save running script")
                .on_hover_text("Write the running script to this .mdl file")
                .clicked()
            {
                let path = PathBuf::from(self.save_path.trim());
                let running = self.store.running();
                match save_script(&path, &running.script) {
                    Ok(()) => {
                        self.message = Some((format!("saved {}", path.display()), GREEN));
                        self.browser.refresh();
                    }
                    Err(e) => self.message = Some((e, RED)),
                }
            }
        });
        egui::ScrollArea::vertical()
            .id_salt("files")
            .show(ui, |ui| {
                for (name, is_dir) in &self.browser.entries {
                    let text = if *is_dir {
                        format!("{name}/")
                    } else {
                        name.clone()
                    };
                    if ui.selectable_label(false, text).clicked() {
                        let path = self.browser.dir.join(name);
                        if *is_dir {
                            go = Some(path);
                        } else {
                            open = Some(path);
                        }
                    }
                }
            });
        if let Some(dir) = go {
            self.browser.go(dir);
        }
        if let Some(path) = open {
            match read_script(&path) {
                Ok(text) => {
                    let name = path
                        .file_stem()
                        .map(|s| s.to_string_lossy().into_owned())
                        .unwrap_or_else(|| "script".into());
                    self.submit(name, text);
                }
                Err(e) => self.message = Some((e, RED)),
            }
        }
    }

    pub(super) fn script_tab(&mut self, ui: &mut Ui, status: &ModelStatus) {
        let edited = self.script != self.synced.script;
        let diagnostics: Vec<Diagnostic> = if status.rejected.is_some() {
            status
                .diagnostics
                .iter()
                .map(|d| Diagnostic::parse(d))
                .collect()
        } else {
            Vec::new()
        };
        let shown_rejected = status
            .rejected
            .as_ref()
            .is_some_and(|r| r.script == self.script);
        let mut apply = ui.input(|i| i.modifiers.command && i.key_pressed(egui::Key::Enter));
        ui.horizontal(|ui| {
            if ui
                .button("Apply")
                .on_hover_text("Compile the script and run it (Ctrl+Enter)")
                .clicked()
            {
                apply = true;
            }
            if ui
                .add_enabled(edited, egui::Button::new("Revert"))
                .on_hover_text("Back to the running script")
                .clicked()
            {
                self.script = self.synced.script.clone();
                self.script_name = self.synced.name.clone();
            }
            ui.label("Name");
            ui.add(egui::TextEdit::singleline(&mut self.script_name).desired_width(120.0));
            if edited {
                ui.colored_label(ORANGE, "edited");
            }
        });
        // Diagnostics first, so they stay visible above a long script.
        if shown_rejected && !diagnostics.is_empty() {
            egui::ScrollArea::vertical()
                .id_salt("diagnostics")
                .max_height(90.0)
                .show(ui, |ui| {
                    for d in &diagnostics {
                        ui.colored_label(
                            RED,
                            RichText::new(format!("{}:{}: {}", d.line, d.col, d.text)).monospace(),
                        );
                    }
                });
        }
        let error_lines: Vec<usize> = if shown_rejected {
            diagnostics.iter().map(|d| d.line).collect()
        } else {
            Vec::new()
        };
        let mut layouter = |ui: &Ui, buf: &dyn egui::TextBuffer, wrap: f32| {
            let mut job = egui::text::LayoutJob::default();
            let font = egui::FontId::monospace(12.0);
            let text_colour = ui.visuals().text_color();
            for (n, line) in buf.as_str().split_inclusive('\n').enumerate() {
                let bad = error_lines.contains(&(n + 1));
                let comment = line.trim_start().starts_with('#');
                job.append(
                    line,
                    0.0,
                    egui::TextFormat {
                        font_id: font.clone(),
                        color: if comment {
                            Color32::from_gray(130)
                        } else {
                            text_colour
                        },
                        background: if bad {
                            Color32::from_rgba_unmultiplied(200, 40, 40, 90)
                        } else {
                            Color32::TRANSPARENT
                        },
                        ..Default::default()
                    },
                );
            }
            job.wrap.max_width = wrap;
            ui.fonts_mut(|f| f.layout_job(job))
        };
        egui::ScrollArea::both().id_salt("script").show(ui, |ui| {
            ui.add(
                egui::TextEdit::multiline(&mut self.script)
                    .code_editor()
                    .desired_width(f32::INFINITY)
                    .desired_rows(30)
                    .layouter(&mut layouter),
            );
        });
        if apply {
            let name = if self.script_name.trim().is_empty() {
                "script".to_string()
            } else {
                self.script_name.trim().to_string()
            };
            self.submit(name, self.script.clone());
        }
    }
}
