//! The controls panel: the host parameters as sliders, the Voices and Release controls, the
//! macro slots with their bindings and MIDI learn. Parameters change only through the host's
//! `ParamSetter`.

use super::*;

impl EditorApp {
    pub(super) fn controls(&mut self, ui: &mut Ui, status: &ModelStatus) {
        let Some(gui) = self.gui.as_ref() else {
            return;
        };
        let setter = gui.param_setter();
        let p = &self.params;
        let rt = &self.store.runtime;
        let row = |ui: &mut Ui, name: &str, param: &dyn Fn(&mut Ui)| {
            ui.horizontal(|ui| {
                ui.add_sized([74.0, 18.0], egui::Label::new(name));
                param(ui);
            });
        };
        ui.heading("Controls");
        row(ui, "Stiffness", &|ui| {
            ui.add(ParamSlider::for_param(&p.stiffness, &setter));
        });
        if rt.clamped.load(Ordering::Relaxed) {
            let asked = rt.requested_stiffness_gain.load(Ordering::Relaxed);
            let got = rt.stiffness_gain.load(Ordering::Relaxed);
            let (dz_asked, dz_got) = (
                rt.requested_damping_gain.load(Ordering::Relaxed),
                rt.damping_gain.load(Ordering::Relaxed),
            );
            let text = if got < asked * 0.9999 {
                format!("Stiffness held at ×{got:.3} of ×{asked:.3}: stability limit")
            } else {
                format!("Damping held at ×{dz_got:.3} of ×{dz_asked:.3}: stability limit")
            };
            ui.colored_label(ORANGE, RichText::new(text).small());
        }
        row(ui, "Damping", &|ui| {
            ui.add(ParamSlider::for_param(&p.damping, &setter));
        });
        row(ui, "Tune", &|ui| {
            ui.add(ParamSlider::for_param(&p.tune, &setter));
        });
        row(ui, "Output", &|ui| {
            ui.add(ParamSlider::for_param(&p.output_gain, &setter));
        });
        row(ui, "Force in", &|ui| {
            ui.add(ParamSlider::for_param(&p.force_gain, &setter));
        });
        row(ui, "Position in", &|ui| {
            ui.add(ParamSlider::for_param(&p.position_gain, &setter));
        });
        row(ui, "Voices", &|ui| {
            ui.add(ParamSlider::for_param(&p.voices, &setter))
                .on_hover_text(
                    "Notes sounding at once: 1 plays the one model (a note retunes it); more \
                     give every note its own copy, which frees itself when it comes to rest",
                );
        });
        row(ui, "Release", &|ui| {
            ui.add(ParamSlider::for_param(&p.release, &setter))
                .on_hover_text(
                    "A damper on a voice whose key is up: 0 lets it ring as a struck object \
                     does; 100 % multiplies its damping by 16",
                );
        });
        row(ui, "Bend range", &|ui| {
            ui.add(ParamSlider::for_param(&p.bend_range, &setter))
                .on_hover_text("Semitones of a full pitch bend, up or down (MPE uses 48)");
        });
        row(ui, "Velocity", &|ui| {
            ui.add(ParamSlider::for_param(&p.velocity_curve, &setter))
                .on_hover_text(
                    "Velocity curve: a note strikes with velocity^this. 1 is linear; above 1 \
                     soft notes are softer, below 1 louder",
                );
        });
        let mut dc = p.dc_filter.value();
        if ui
            .checkbox(&mut dc, "DC filter (40 Hz high-pass)")
            .changed()
        {
            setter.begin_set_parameter(&p.dc_filter);
            setter.set_parameter(&p.dc_filter, dc);
            setter.end_set_parameter(&p.dc_filter);
        }
        ui.horizontal(|ui| {
            if ui
                .button("Strike")
                .on_hover_text("Strike the note input once, like a MIDI note at velocity 0.8")
                .clicked()
            {
                rt.strike_requested.store(true, Ordering::Release);
            }
            let mut audition = rt.audition.load(Ordering::Relaxed);
            if ui
                .checkbox(&mut audition, "Audition")
                .on_hover_text("Strike the note input every second")
                .changed()
            {
                rt.audition.store(audition, Ordering::Release);
            }
        });

        ui.separator();
        ui.heading("Macros");
        let bound: Vec<_> = status
            .summary
            .macros
            .iter()
            .take(NUM_MACROS)
            .enumerate()
            .filter_map(|(i, b)| b.as_ref().map(|b| (i, b)))
            .collect();
        if bound.is_empty() {
            ui.label(
                RichText::new("This model declares no param: the slots are unbound.")
                    .color(Color32::GRAY),
            );
        }
        let ccs = &p.cc_map;
        let learning = ccs.learning();
        for (i, b) in &bound {
            ui.horizontal(|ui| {
                ui.label(RichText::new(format!("{}", i + 1)).color(Color32::GRAY));
                ui.label(RichText::new(&b.name).strong().monospace());
                ui.label(
                    RichText::new(format!(
                        "{} … {}",
                        crate::model::format_value(b.min),
                        crate::model::format_value(b.max)
                    ))
                    .small()
                    .color(Color32::GRAY),
                );
            });
            ui.horizontal(|ui| {
                ui.add(ParamSlider::for_param(&p.macros[*i].value, &setter));
                self.cc_learn(ui, *i, learning);
            });
            // The value the model sees, per step, under the slot's musical unit.
            let used = rt.macros[*i].load(Ordering::Relaxed);
            ui.label(
                RichText::new(format!(
                    "{} = {} per step",
                    b.name,
                    crate::model::format_value(b.value_at(used))
                ))
                .small()
                .color(Color32::GRAY),
            )
            .on_hover_text("The parameter's value in the script's units (per step)");
            if let Some(cc) = ccs.cc_of(*i) {
                let host = p.macros[*i].value.value() as f64;
                let used = rt.macros[*i].load(Ordering::Relaxed);
                if (used - host).abs() > 1e-6 {
                    ui.label(
                        RichText::new(format!(
                            "CC {cc} holds it at {:.0} % (the knob takes over when moved)",
                            used * 100.0
                        ))
                        .small()
                        .color(ORANGE),
                    );
                }
            }
        }
        let unbound = NUM_MACROS - bound.len();
        if !bound.is_empty() && unbound > 0 {
            ui.label(
                RichText::new(format!("{unbound} more slots unbound"))
                    .small()
                    .color(Color32::GRAY),
            );
        }
    }

    /// MIDI learn for macro slot `slot`: its controller, a button that arms it (the next
    /// controller the plugin hears is bound), and one that unbinds it.
    pub(super) fn cc_learn(&self, ui: &mut Ui, slot: usize, learning: Option<usize>) {
        let ccs = &self.params.cc_map;
        if learning == Some(slot) {
            if ui
                .button(RichText::new("move a control…").color(ORANGE))
                .on_hover_text("Waiting for a MIDI controller; click to stop")
                .clicked()
            {
                ccs.learn(None);
            }
            return;
        }
        let label = match ccs.cc_of(slot) {
            Some(cc) => format!("CC {cc}"),
            None => "Learn".to_string(),
        };
        if ui
            .small_button(label)
            .on_hover_text("MIDI learn: click, then move a knob or pedal on your controller")
            .clicked()
        {
            ccs.learn(Some(slot));
        }
        if ccs.cc_of(slot).is_some()
            && ui
                .small_button("×")
                .on_hover_text("Unbind the controller")
                .clicked()
        {
            ccs.clear(slot);
        }
    }
}
