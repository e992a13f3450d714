//! The Vary row of the controls panel: a button that moves the running model's macros and
//! global controls by an amount from a seed ([`ressort_engine::instrument::vary`]), worked out on
//! a thread of its own ([`VaryJob`]) and applied through the host's `ParamSetter`, so the host
//! records it as automation and undo; the editor's own Undo goes back through the last presses.

use super::*;
use crate::vary_worker::{Outcome, VaryHistory, VaryJob};
use nice_plug::prelude::Param;
use ressort_engine::instrument::Controls;

/// The editor's Vary state: amount, next seed, history and the job in flight.
#[derive(Debug)]
pub(super) struct VaryState {
    pub amount: f32,
    pub seed: u64,
    pub history: VaryHistory,
    pub job: Option<VaryJob>,
    /// What the last press did.
    pub note: Option<(String, Color32)>,
}

impl Default for VaryState {
    fn default() -> Self {
        VaryState {
            amount: 0.5,
            seed: 1,
            history: VaryHistory::default(),
            job: None,
            note: None,
        }
    }
}

impl EditorApp {
    pub(super) fn vary_panel(&mut self, ui: &mut Ui) {
        self.poll_vary();
        let busy = self.vary.job.is_some();
        ui.horizontal(|ui| {
            ui.add_sized(
                [74.0, 18.0],
                egui::Label::new(RichText::new("Vary").strong()),
            );
            if ui
                .add_enabled(
                    !busy,
                    egui::Button::new(if busy { "varying…" } else { "Vary" }),
                )
                .on_hover_text(
                    "Move the model's macros, Damping and Release (and Stiffness on unpitched \
                     models) by the amount, from the seed: every variation is played offline \
                     first, kept stable and at the level the sound had",
                )
                .clicked()
            {
                self.start_vary();
            }
            let n = self.vary.history.len();
            if ui
                .add_enabled(!busy && n > 0, egui::Button::new(format!("Undo ({n})")))
                .on_hover_text("Go back to the controls before the last Vary")
                .clicked()
            {
                if let Some(before) = self.vary.history.undo() {
                    self.apply_varied(&before);
                    self.vary.note = Some(("back to the controls before".into(), GREEN));
                }
            }
        });
        ui.horizontal(|ui| {
            ui.add_sized([74.0, 18.0], egui::Label::new("amount"));
            ui.add(egui::Slider::new(&mut self.vary.amount, 0.05..=1.0).fixed_decimals(2));
        });
        ui.horizontal(|ui| {
            ui.add_sized([74.0, 18.0], egui::Label::new("seed"));
            ui.add(egui::DragValue::new(&mut self.vary.seed))
                .on_hover_text("The same seed from the same controls gives the same variation");
        });
        if let Some((text, colour)) = &self.vary.note {
            ui.colored_label(*colour, RichText::new(text).small());
        }
    }

    fn start_vary(&mut self) {
        let from = self.params.controls();
        let amount = self.vary.amount as f64;
        match VaryJob::start(self.store.clone(), from, amount, self.vary.seed) {
            Some(job) => {
                self.vary.job = Some(job);
                self.vary.note = None;
            }
            None => self.vary.note = Some(("no thread for Vary".into(), RED)),
        }
    }

    fn poll_vary(&mut self) {
        let Some(job) = self.vary.job.as_mut() else {
            return;
        };
        let Some(outcome) = job.poll() else {
            return;
        };
        let from = job.from;
        self.vary.job = None;
        match outcome {
            Outcome::Varied(v) => {
                self.vary.history.push(from);
                self.apply_varied(&v.controls);
                self.vary.note = Some((
                    format!(
                        "seed {}: amount {:.2}, level held at {:.1} dBFS (Output {:+.1} dB)",
                        v.seed, v.amount, v.level_db, v.controls.output_db
                    ),
                    GREEN,
                ));
                self.vary.seed = v.seed.wrapping_add(1);
            }
            Outcome::NothingPlayable => {
                self.vary.note = Some((
                    format!(
                        "nothing near seed {} played: try another seed or a smaller amount",
                        self.vary.seed
                    ),
                    ORANGE,
                ));
                self.vary.seed = self
                    .vary
                    .seed
                    .wrapping_add(ressort_engine::instrument::vary::SEEDS_TRIED);
            }
            Outcome::Failed(why) => self.vary.note = Some((why, RED)),
        }
    }

    /// Sets the controls Vary moves, as gestures the host records.
    fn apply_varied(&self, c: &Controls) {
        let Some(gui) = &self.gui else {
            return;
        };
        let setter = gui.param_setter();
        let p = &self.params;
        let set = |param: &nice_plug::prelude::FloatParam, v: f64| {
            let v = v as f32;
            if param.unmodulated_plain_value() != v {
                setter.begin_set_parameter(param);
                setter.set_parameter(param, v);
                setter.end_set_parameter(param);
            }
        };
        for (slot, m) in p.macros.iter().zip(&c.macros) {
            set(&slot.value, *m);
        }
        set(&p.damping, c.damping_octaves);
        set(&p.stiffness, c.stiffness_octaves);
        set(&p.release, c.release);
        set(&p.output_gain, c.output_db);
    }
}
