//! The Presets tab: the sound library's browser. A category menu, a search over names and
//! tags, favourites (*, kept per user), the factory and user presets side by side, previous and
//! next buttons that load the neighbour in the shown list (the arrow keys do the same), and the
//! chosen preset's notes. What is shown is decided by [`crate::library`]; loads go through
//! [`EditorApp::submit`], in the background as every model change from the editor.

use super::*;
use crate::library::{entries, neighbour, Entry};
use crate::presets::{header_field, CATEGORIES, FIELDS};

const STAR: &str = "*";
const NO_STAR: &str = "·";

impl EditorApp {
    /// Reads the user presets again and rebuilds the library (at open, after a save, on
    /// Refresh).
    pub(super) fn refresh_library(&mut self) {
        self.notes = None;
        self.user = self
            .user_dir
            .as_deref()
            .map(user_presets)
            .unwrap_or_default();
        let selected = self.selected.map(|i| self.library[i].key.clone());
        self.library = entries(&self.user);
        self.selected = selected.and_then(|k| self.library.iter().position(|e| e.key == k));
    }

    /// The library entry of the running model, if it is one.
    fn running_entry(&self) -> Option<usize> {
        let running = self.store.running();
        self.library
            .iter()
            .position(|e| e.id == running.name && e.script().is_ok_and(|s| s == running.script))
    }

    /// Loads the entry `step` places from the selected one (or the running one) in the shown
    /// list.
    pub(super) fn step_preset(&mut self, step: isize) {
        let shown = self.filter.apply(&self.library, &self.favourites);
        let current = self.selected.or_else(|| self.running_entry());
        if let Some(i) = neighbour(&shown, current, step) {
            self.selected = Some(i);
            self.scroll_to_selected = true;
            self.load_entry(i);
        }
    }

    fn load_entry(&mut self, i: usize) {
        let entry = self.library[i].clone();
        match entry.script() {
            Ok(text) => self.submit(entry.id, text),
            Err(e) => self.message = Some((e, RED)),
        }
    }

    fn toggle_favourite(&mut self, key: &str) {
        if let Err(e) = self.favourites.toggle(key) {
            self.message = Some((e, ORANGE));
        }
    }

    /// The arrow keys walk the shown list while no text field has the keyboard.
    fn browser_keys(&mut self, ui: &Ui) {
        let typing = ui.ctx().memory(|m| m.focused().is_some());
        if typing {
            return;
        }
        let (down, up) = ui.input(|i| {
            (
                i.key_pressed(egui::Key::ArrowDown) || i.key_pressed(egui::Key::ArrowRight),
                i.key_pressed(egui::Key::ArrowUp) || i.key_pressed(egui::Key::ArrowLeft),
            )
        });
        if down {
            self.step_preset(1);
        } else if up {
            self.step_preset(-1);
        }
    }

    pub(super) fn presets_tab(&mut self, ui: &mut Ui) {
        self.browser_keys(ui);
        self.browser_filters(ui);
        let shown = self.filter.apply(&self.library, &self.favourites);
        let running = self.running_entry();
        let mut load = None;
        let mut star = None;
        ui.label(
            RichText::new(format!(
                "{} of {} presets · the arrow keys or < > load the neighbour · double-click loads",
                shown.len(),
                self.library.len()
            ))
            .small()
            .color(Color32::GRAY),
        );
        egui::ScrollArea::vertical()
            .id_salt("presets")
            .max_height(ui.available_height() * 0.45)
            .auto_shrink([false, true])
            .show(ui, |ui| {
                if shown.is_empty() {
                    ui.label(RichText::new("no preset matches").color(Color32::GRAY));
                }
                for &i in &shown {
                    let e = &self.library[i];
                    ui.horizontal(|ui| {
                        let fav = self.favourites.contains(&e.key);
                        if ui
                            .add(egui::Button::new(if fav { STAR } else { NO_STAR }).frame(false))
                            .on_hover_text(if fav {
                                "Remove from the favourites"
                            } else {
                                "Add to the favourites"
                            })
                            .clicked()
                        {
                            star = Some(e.key.clone());
                        }
                        let mut text = RichText::new(&e.name);
                        if running == Some(i) {
                            text = text.strong().color(GREEN);
                        }
                        let r = ui.selectable_label(self.selected == Some(i), text);
                        if self.scroll_to_selected && self.selected == Some(i) {
                            r.scroll_to_me(Some(egui::Align::Center));
                        }
                        if r.clicked() {
                            self.selected = Some(i);
                        }
                        if r.double_clicked() {
                            load = Some(i);
                        }
                        let place = match (e.is_user(), e.category) {
                            (true, Some(c)) => format!("user · {c}"),
                            (true, None) => "user".to_string(),
                            (false, Some(c)) => c.to_string(),
                            (false, None) => String::new(),
                        };
                        ui.label(RichText::new(place).small().color(Color32::GRAY));
                    });
                }
            });
        self.scroll_to_selected = false;
        if let Some(key) = star {
            self.toggle_favourite(&key);
        }
        ui.separator();
        if let Some(i) = self.selected.filter(|&i| i < self.library.len()) {
            let e = self.library[i].clone();
            ui.horizontal(|ui| {
                ui.label(RichText::new(&e.name).strong());
                if ui.button("Load").clicked() {
                    load = Some(i);
                }
                let fav = self.favourites.contains(&e.key);
                if ui
                    .small_button(if fav {
                        "* favourite"
                    } else {
                        "add to favourites"
                    })
                    .clicked()
                {
                    self.toggle_favourite(&e.key);
                }
            });
            self.preset_notes(ui, &e);
        } else {
            ui.label(RichText::new("Select a preset to read its notes.").color(Color32::GRAY));
        }
        if let Some(i) = load {
            self.selected = Some(i);
            self.load_entry(i);
        }
        ui.separator();
        self.user_presets(ui);
    }

    /// Category, search, favourites and which presets: the filter row.
    fn browser_filters(&mut self, ui: &mut Ui) {
        ui.horizontal(|ui| {
            if ui
                .button("<")
                .on_hover_text("Load the previous preset of the list (arrow up)")
                .clicked()
            {
                self.step_preset(-1);
            }
            if ui
                .button(">")
                .on_hover_text("Load the next preset of the list (arrow down)")
                .clicked()
            {
                self.step_preset(1);
            }
            let search = ui.add(
                egui::TextEdit::singleline(&mut self.filter.query)
                    .hint_text("search names and tags")
                    .desired_width(150.0),
            );
            if search.has_focus() && ui.input(|i| i.key_pressed(egui::Key::Escape)) {
                self.filter.query.clear();
            }
            if !self.filter.query.is_empty() && ui.small_button("x").clicked() {
                self.filter.query.clear();
            }
        });
        ui.horizontal_wrapped(|ui| {
            egui::ComboBox::from_id_salt("category")
                .selected_text(self.filter.category.unwrap_or("All categories"))
                .width(180.0)
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut self.filter.category, None, "All categories");
                    for c in CATEGORIES {
                        ui.selectable_value(&mut self.filter.category, Some(c), c);
                    }
                });
            let favs = format!("{STAR} {}", self.favourites.len());
            ui.toggle_value(&mut self.filter.favourites_only, favs)
                .on_hover_text("Show only the favourites");
            ui.toggle_value(&mut self.filter.show_factory, "Factory");
            ui.toggle_value(&mut self.filter.show_user, "User");
        });
    }

    /// A preset's library fields and its What / How to play / Source notes (a user preset's file
    /// is read once per selection, not every frame).
    fn preset_notes(&mut self, ui: &mut Ui, e: &Entry) {
        if self.notes.as_ref().is_none_or(|(key, _)| key != &e.key) {
            self.notes = Some((e.key.clone(), e.script().unwrap_or_default()));
        }
        let text = self.notes.as_ref().map(|(_, t)| t.as_str()).unwrap_or("");
        egui::ScrollArea::vertical()
            .id_salt("preset-info")
            .max_height(ui.available_height() * 0.6)
            .show(ui, |ui| {
                if let Some(category) = e.category {
                    ui.label(RichText::new(category).color(Color32::GRAY).small());
                }
                if !e.tags.is_empty() {
                    ui.label(e.tags.join(" · "));
                    ui.add_space(4.0);
                }
                for key in FIELDS {
                    let field = header_field(text, key);
                    if !field.is_empty() {
                        ui.label(RichText::new(key).color(Color32::GRAY).small());
                        ui.label(field);
                        ui.add_space(4.0);
                    }
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The browser's filter and the arrow keys' walk, as the editor holds them.
    #[test]
    fn next_loads_the_neighbour_in_the_filtered_list() {
        let store = Arc::new(ModelStore::default());
        store
            .submit(ModelState::new(
                "mesh-15x15",
                Preset::find("mesh-15x15").unwrap().text,
            ))
            .unwrap();
        store.activate(48_000.0, true);
        let params = Arc::new(RessortParams::new(store.clone()));
        let mut app = EditorApp::new(params, store.clone());
        app.filter.category = Some("Strings / Bowed");
        let shown = app.filter.apply(&app.library, &app.favourites);
        assert!(shown.len() >= 2, "{shown:?}");
        app.step_preset(1);
        app.finish_loading();
        assert_eq!(store.running().name, app.library[shown[0]].id);
        app.step_preset(1);
        app.finish_loading();
        assert_eq!(store.running().name, app.library[shown[1]].id);
        app.step_preset(-1);
        app.finish_loading();
        assert_eq!(store.running().name, app.library[shown[0]].id);
        store.finish_loads();
    }
}
