//! How the running model plays from a keyboard and a sidechain: its pitch (the reference note
//! and how far it is from its key, the keys it plays in tune), the automatic level trim, the
//! A4 reference, the sidechain's input meter with the level that strikes like a medium note,
//! and the trigger mode. A legacy project says so and offers to move on.

use super::*;
use crate::model::{ModelSummary, Playing};
use ressort_engine::instrument::level::REFERENCE_DRUM_DBFS;
use ressort_engine::instrument::trigger::level_for_velocity;
use ressort_engine::modes::note_name;

/// The input meter's range and how fast it falls.
const METER_FLOOR_DB: f32 = -60.0;
const METER_FALL_DB_PER_S: f32 = 24.0;
/// The velocity of "a medium note".
const MEDIUM_VELOCITY: f64 = 0.8;

/// The name of MIDI key `key` (rounded): `C4`.
pub(super) fn key_name(key: f64) -> String {
    note_name(440.0 * 2f64.powf((key.round() - 69.0) / 12.0)).map_or_else(String::new, |n| n.0)
}

/// One line on the model's pitch for the top bar, and its explanation.
pub(super) fn pitch_text(s: &ModelSummary) -> Option<(String, String)> {
    let f = s.reference_pitch_hz?;
    let (note, cents) = note_name(f)?;
    let native = format!("{note} {cents:+.0} ¢ ({f:.1} Hz)");
    Some(match (s.playing, s.unpitched) {
        (Playing::Legacy, _) => (
            format!("{native} at key {:.0}", s.reference_key),
            "A project saved before concert pitch: a key retunes the model by its distance \
             from the key the script names, as it did then."
                .to_string(),
        ),
        (Playing::Musical, true) => (
            format!("unpitched: {native} at {}", key_name(s.reference_key)),
            format!(
                "An unpitched model keeps its own pitch at {}: a key transposes it from there.",
                key_name(s.reference_key)
            ),
        ),
        (Playing::Musical, false) => {
            // How far the model's own pitch lies from the key it is nearest, which every key
            // moves it from.
            let off = 100.0 * (s.reference_key - s.reference_key.round());
            let top = s
                .highest_key
                .map(|k| format!(", in tune up to {}", key_name(k.floor())))
                .unwrap_or_default();
            (
                format!("concert pitch: native {native}{top}"),
                format!(
                    "A key plays its own note (A4 = the A4 control): the model's reference mode, \
                     natively {note} {off:+.0} cents off the nearest key, is retuned onto it by \
                     the exact law. Keys above the highest one are held by the stability clamp."
                ),
            )
        }
    })
}

impl EditorApp {
    /// The section of the controls panel on playing: trim, A4, sidechain meter and trigger.
    pub(super) fn playing(&mut self, ui: &mut Ui, status: &ModelStatus) {
        let Some(gui) = self.gui.as_ref() else {
            return;
        };
        let setter = gui.param_setter();
        let p = &self.params;
        let s = &status.summary;
        ui.heading("Playing");
        if s.playing == Playing::Legacy {
            ui.colored_label(
                ORANGE,
                RichText::new(
                    "Saved before concert pitch and automatic levels: played as it was then.",
                )
                .small(),
            );
            if ui
                .button("Update to concert pitch and automatic levels")
                .on_hover_text(
                    "Plays this model in concert pitch with its automatic level and sidechain \
                     trims, and sets Output Gain to 0 dB",
                )
                .clicked()
            {
                let running = self.store.running();
                setter.begin_set_parameter(&p.output_gain);
                setter.set_parameter(&p.output_gain, 0.0);
                setter.end_set_parameter(&p.output_gain);
                let ticket = self.store.submit_in_background(ModelState::new(
                    running.name.clone(),
                    running.script.clone(),
                ));
                self.message = Some((format!("loading {}…", running.name), ORANGE));
                self.loading = Some((ticket, running.name, running.script));
                self.mark_edited();
            }
        } else {
            ui.label(RichText::new(format!("Level trim {:+.1} dB", s.output_trim_db)).small())
                .on_hover_text(
                    "Set when the model loads, so that C4 at velocity 0.8 peaks at −12 dBFS; \
                     Output Gain adds to it",
                );
        }
        if !s.exciters.is_empty() {
            ui.label(RichText::new(format!("A key plays: {}", s.exciters.join(", "))).small());
        }
        ui.horizontal(|ui| {
            ui.add_sized([74.0, 18.0], egui::Label::new("A4"));
            ui.add(ParamSlider::for_param(&p.a4, &setter))
                .on_hover_text("The tuning reference: the pitch of A4 (Tune adds to it)");
        });

        // The sidechain: what arrives, and the level that strikes like a medium note.
        let rt = &self.store.runtime;
        let peak = rt.input_peak.swap(0.0, Ordering::Relaxed);
        let dt = self.frame_times[(self.frame_count + 31) % 32].max(1e-3);
        let db = if peak > 0.0 {
            (20.0 * peak.log10()) as f32
        } else {
            METER_FLOOR_DB
        };
        self.meter_db = db
            .max(self.meter_db - METER_FALL_DB_PER_S * dt)
            .max(METER_FLOOR_DB);
        let trigger = p.trigger.value();
        let medium = if trigger {
            level_for_velocity(MEDIUM_VELOCITY, p.trigger_sensitivity.value() as f64)
        } else {
            REFERENCE_DRUM_DBFS - p.force_gain.value() as f64
        } as f32;
        ui.horizontal(|ui| {
            ui.add_sized([74.0, 18.0], egui::Label::new("Sidechain"));
            let width = ui.available_width().max(60.0);
            let (rect, response) =
                ui.allocate_exact_size(egui::vec2(width, 12.0), egui::Sense::hover());
            let x = |db: f32| {
                let t = ((db - METER_FLOOR_DB) / -METER_FLOOR_DB).clamp(0.0, 1.0);
                rect.left() + t * rect.width()
            };
            let painter = ui.painter();
            painter.rect_filled(rect, 2.0, Color32::from_gray(40));
            let level =
                egui::Rect::from_min_max(rect.min, egui::pos2(x(self.meter_db), rect.max.y));
            let colour = if self.meter_db > medium + 6.0 {
                ORANGE
            } else {
                GREEN
            };
            painter.rect_filled(level, 2.0, colour);
            painter.line_segment(
                [
                    egui::pos2(x(medium), rect.top() - 2.0),
                    egui::pos2(x(medium), rect.bottom() + 2.0),
                ],
                egui::Stroke::new(2.0, Color32::WHITE),
            );
            response.on_hover_text(format!(
                "The sidechain's peak: {:.1} dBFS. The white mark, {medium:.1} dBFS, is where a \
                 drum hit strikes like a medium note (velocity 0.8){}",
                self.meter_db,
                if trigger {
                    " in trigger mode at this sensitivity"
                } else {
                    " at this Force Gain"
                }
            ));
        });
        ui.label(
            RichText::new(format!(
                "{:.0} dBFS now · a medium note at {medium:.0} dBFS",
                self.meter_db
            ))
            .small()
            .color(Color32::GRAY),
        );
        let mut on = trigger;
        if ui
            .checkbox(&mut on, "Trigger mode")
            .on_hover_text(
                "Sidechain hits strike the model (a voice each, with voices) at a velocity from \
                 their level, instead of pushing it as a force",
            )
            .changed()
        {
            setter.begin_set_parameter(&p.trigger);
            setter.set_parameter(&p.trigger, on);
            setter.end_set_parameter(&p.trigger);
        }
        if on {
            ui.horizontal(|ui| {
                ui.add_sized([74.0, 18.0], egui::Label::new("Sensitivity"));
                ui.add(ParamSlider::for_param(&p.trigger_sensitivity, &setter))
                    .on_hover_text("dB added to a hit's level: higher plays quieter hits louder");
            });
            ui.label(
                RichText::new(format!(
                    "{} strikes so far",
                    rt.triggered.load(Ordering::Relaxed)
                ))
                .small()
                .color(Color32::GRAY),
            );
        }
    }
}
