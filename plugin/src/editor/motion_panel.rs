//! The motion panel: the tool bar (which buffer, how it is drawn, the selected mode) and the
//! motion view itself, the plane or line plot of 1-D models ([`crate::plot`]) or the 3-D view
//! of 3-D ones ([`crate::view3d`]), showing the live motion or the selected mode's shape.

use super::*;
use crate::plot::ZMode;
use crate::view3d::{Frame3, SHAPE_AMPLITUDE};

impl EditorApp {
    pub(super) fn motion_panel(&mut self, ui: &mut Ui, dt: f32) {
        let Some(reader) = self.reader.as_mut() else {
            ui.centered_and_justified(|ui| {
                ui.label("The motion view starts when the plugin processes audio.");
            });
            return;
        };
        let view = reader.view.clone();
        let space = view.is_3d();
        ui.horizontal_wrapped(|ui| {
            let current = match self.plot.buffer {
                Some(b) if b < view.named().len() => format!("buffer {}", view.named()[b].name),
                _ => format!("all points ({})", view.len()),
            };
            egui::ComboBox::from_id_salt("buffer")
                .selected_text(current)
                .show_ui(ui, |ui| {
                    ui.selectable_value(
                        &mut self.plot.buffer,
                        None,
                        format!("all points ({})", view.len()),
                    );
                    for (i, b) in view.named().iter().enumerate() {
                        ui.selectable_value(
                            &mut self.plot.buffer,
                            Some(i),
                            format!("buffer {} ({})", b.name, b.members.len()),
                        );
                    }
                });
            if space {
                self.view3d.controls(ui);
            } else {
                ui.add_enabled_ui(self.plot.planar(), |ui| {
                    egui::ComboBox::from_id_salt("zmode")
                        .selected_text(self.plot.mode.name())
                        .show_ui(ui, |ui| {
                            for m in ZMode::ALL {
                                ui.selectable_value(&mut self.plot.mode, m, m.name());
                            }
                        })
                        .response
                        .on_disabled_hover_text("1-D selections show z vertically");
                });
                ui.checkbox(&mut self.plot.hold, "Hold scale");
            }
            if let Some((k, _)) = self.modes.selected_mode() {
                ui.colored_label(ORANGE, format!("showing the shape of mode {}", k + 1));
                if ui.small_button("live motion").clicked() {
                    self.modes.selected = None;
                }
            }
        });
        if space {
            let buffer = self.plot.buffer.filter(|&b| b < view.named().len());
            let amplitude = SHAPE_AMPLITUDE * self.view3d.prepare(&view, buffer);
            let rest = [&view.rest_x[..], &view.rest_y[..], &view.rest[..]];
            let frame = match self.modes.shape_frame_3d(rest, amplitude, dt) {
                Some([x, y, z]) => {
                    self.shape_frames += 1;
                    Frame3 {
                        // Shape frames count down from the top, so they are never taken
                        // for a live frame's number.
                        id: u64::MAX - self.shape_frames,
                        x,
                        y,
                        z,
                    }
                }
                None => {
                    let f = reader.latest();
                    Frame3 {
                        id: f.number,
                        x: &f.x,
                        y: &f.y,
                        z: &f.z,
                    }
                }
            };
            self.view3d.show(ui, &view, buffer, frame, dt);
            return;
        }
        match self.modes.shape_frame(&view.rest, dt) {
            Some(shape) => self.plot.show(ui, &view, shape, dt),
            None => self.plot.show(ui, &view, &reader.latest().z, dt),
        };
    }
}
