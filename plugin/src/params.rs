//! The plugin's parameters. Their ids are part of every saved project: never rename one.

use crate::midi_learn::CcMap;
use crate::model::{ModelStore, MAX_VOICES, NUM_MACROS};
use crate::param_text::{
    format_bend_range, format_db, format_factor, format_semitones, format_velocity_curve, parse_db,
    parse_factor, parse_semitones, parse_switch, parse_velocity_curve,
};
use crate::state::{CompareField, FormatField};
use nice_plug::prelude::*;
use ressort_engine::instrument::controls::A4_RANGE_HZ;
use ressort_engine::instrument::Controls;
use std::sync::Arc;

/// Stiffness and Damping are stored in octaves (log₂ of the factor): the knob is logarithmic
/// from ×1/16 to ×16 and automation lanes are linear in octaves.
pub const GAIN_OCTAVES: f32 = 4.0;

/// The polyphonic modulation ids of Stiffness and Damping (CLAP).
pub const POLY_MOD_STIFFNESS: u32 = 0;
pub const POLY_MOD_DAMPING: u32 = 1;

/// The Velocity Curve's exponent spans 2^±this.
pub const VELOCITY_OCTAVES: f32 = 2.0;
/// The widest pitch-bend range (MPE's member channels use ±48).
pub const MAX_BEND_RANGE: f32 = 48.0;

/// The texts of the Guard Tripped parameter.
const GUARD_OFF: &str = "Clear";
const GUARD_ON: &str = "Tripped";

#[derive(Params)]
pub struct RessortParams {
    /// The running model's script (saved with the project).
    #[persist = "model"]
    pub model: Arc<ModelStore>,

    /// Which MIDI controller moves which macro slot (MIDI learn; saved with the project).
    #[persist = "cc_map"]
    pub cc_map: Arc<CcMap>,

    /// The A/B slots (saved with the project).
    #[persist = "compare"]
    pub compare: CompareField,

    /// The state's format number: see `state`.
    #[persist = "format"]
    pub format: FormatField,

    /// × on every K-class argument (log₂ of the factor).
    #[id = "stiffness"]
    pub stiffness: FloatParam,
    /// × on every Z-class argument (log₂ of the factor).
    #[id = "damping"]
    pub damping: FloatParam,
    /// Semitones, by the exact discrete tuning law.
    #[id = "tune"]
    pub tune: FloatParam,
    #[id = "output_gain"]
    pub output_gain: FloatParam,
    #[id = "force_gain"]
    pub force_gain: FloatParam,
    #[id = "position_gain"]
    pub position_gain: FloatParam,
    /// The 40 Hz high-pass of the mi-gen example patches.
    #[id = "dc_filter"]
    pub dc_filter: BoolParam,
    /// On when the explosion guard has reset the model; off again with the editor's Reset
    /// model or by the user. Set by the plugin (see `report`), not automatable.
    #[id = "guard"]
    pub guard: BoolParam,

    /// Counts the editor's model changes (script edits, presets, files, A/B), wrapping at 255.
    /// The editor moves it with a parameter gesture whenever it changes the model, so the host
    /// records an edit of the project: nice-plug 0.4.2 has no other way to mark a project
    /// dirty (no `clap_host_state.mark_dirty`, no VST3 `setDirty`). Hidden, not automatable;
    /// its value means nothing.
    #[id = "model_edits"]
    pub model_edits: IntParam,

    /// How many notes sound at once: 0 takes the script's `~voices` (1 without one), 1 plays
    /// monophonically (a note retunes the one model), more give every note its own copy of
    /// the model. Not automatable: a change re-prepares the model.
    #[id = "voices"]
    pub voices: IntParam,

    /// The damper laid on a voice when its key goes up: 0 lets it ring.
    #[id = "release"]
    pub release: FloatParam,

    /// MPE: channel 1 is the master channel, channels 2 … 16 carry one note each, with its
    /// own bend (±48 semitones) and pressure.
    #[id = "mpe"]
    pub mpe: BoolParam,

    /// Semitones of a full pitch bend, up or down.
    #[id = "bend_range"]
    pub bend_range: FloatParam,
    /// log₂ of the exponent a note's velocity is raised to before it strikes.
    #[id = "velocity_curve"]
    pub velocity_curve: FloatParam,

    /// The tuning reference: the pitch of A4 in Hz (concert pitch; Tune adds to it).
    #[id = "a4"]
    pub a4: FloatParam,

    /// Sidechain trigger mode: onsets on the sidechain strike the model (play a voice)
    /// instead of pushing it as a force.
    #[id = "sc_trigger"]
    pub trigger: BoolParam,
    /// dB added to a sidechain hit's level before it becomes a velocity.
    #[id = "sc_sensitivity"]
    pub trigger_sensitivity: FloatParam,

    /// Generic slots bound to the model's `param`s in declaration order.
    #[nested(array, group = "Macros")]
    pub macros: [MacroParam; NUM_MACROS],
}

#[derive(Params)]
pub struct MacroParam {
    /// 0 … 1: the bound parameter's minimum, declared value (0.5) and maximum.
    #[id = "macro"]
    pub value: FloatParam,
}

fn factor_param(name: &'static str) -> FloatParam {
    FloatParam::new(
        name,
        0.0,
        FloatRange::Linear {
            min: -GAIN_OCTAVES,
            max: GAIN_OCTAVES,
        },
    )
    .with_unit(" ×")
    .with_value_to_string(Arc::new(|octaves| format_factor(2f32.powf(octaves))))
    .with_string_to_value(Arc::new(|text| parse_factor(text, GAIN_OCTAVES)))
}

fn gain_param(name: &'static str, default_db: f32, min_db: f32, max_db: f32) -> FloatParam {
    FloatParam::new(
        name,
        default_db,
        FloatRange::Linear {
            min: min_db,
            max: max_db,
        },
    )
    .with_unit(" dB")
    .with_step_size(0.1)
    .with_value_to_string(Arc::new(format_db))
    .with_string_to_value(Arc::new(parse_db))
}

impl RessortParams {
    /// The parameters' current values as the instrument's controls.
    pub fn controls(&self) -> Controls {
        Controls {
            stiffness_octaves: self.stiffness.value() as f64,
            damping_octaves: self.damping.value() as f64,
            tune_st: self.tune.value() as f64,
            output_db: self.output_gain.value() as f64,
            force_db: self.force_gain.value() as f64,
            position_db: self.position_gain.value() as f64,
            macros: std::array::from_fn(|i| self.macros[i].value.value() as f64),
            dc_filter: self.dc_filter.value(),
            bend_range_st: self.bend_range.value() as f64,
            release: self.release.value() as f64,
            mpe: self.mpe.value(),
            velocity_exponent: 2f64.powf(self.velocity_curve.value() as f64),
            a4_hz: self.a4.value() as f64,
            trigger: self.trigger.value(),
            trigger_sensitivity_db: self.trigger_sensitivity.value() as f64,
        }
    }

    pub fn new(model: Arc<ModelStore>) -> RessortParams {
        let macros = std::array::from_fn(|slot| {
            let store = model.clone();
            let parse_store = model.clone();
            MacroParam {
                value: FloatParam::new(
                    format!("Macro {}", slot + 1),
                    0.5,
                    FloatRange::Linear { min: 0.0, max: 1.0 },
                )
                .with_value_to_string(Arc::new(move |v| store.macro_text(slot, v as f64)))
                .with_string_to_value(Arc::new(move |text| {
                    parse_store.macro_from_text(slot, text).map(|n| n as f32)
                })),
            }
        });
        let d = Controls::DEFAULT;
        let voices_store = model.clone();
        RessortParams {
            compare: CompareField(model.clone()),
            format: FormatField(model.clone()),
            model,
            cc_map: Arc::new(CcMap::default()),
            stiffness: factor_param("Stiffness").with_poly_modulation_id(POLY_MOD_STIFFNESS),
            damping: factor_param("Damping").with_poly_modulation_id(POLY_MOD_DAMPING),
            tune: FloatParam::new(
                "Tune",
                0.0,
                FloatRange::Linear {
                    min: -24.0,
                    max: 24.0,
                },
            )
            .with_unit(" st")
            .with_step_size(0.01)
            .with_value_to_string(Arc::new(format_semitones))
            .with_string_to_value(Arc::new(parse_semitones)),
            output_gain: gain_param("Output Gain", d.output_db as f32, -40.0, 60.0),
            force_gain: gain_param("Force Gain", d.force_db as f32, -60.0, 40.0),
            position_gain: gain_param("Position Gain", d.position_db as f32, -60.0, 40.0),
            dc_filter: BoolParam::new("DC Filter", Controls::DEFAULT.dc_filter),
            model_edits: IntParam::new("Model Edits", 0, IntRange::Linear { min: 0, max: 255 })
                .hide()
                .non_automatable(),
            voices: {
                let store = voices_store.clone();
                let text_store = voices_store;
                IntParam::new(
                    "Voices",
                    0,
                    IntRange::Linear {
                        min: 0,
                        max: MAX_VOICES as i32,
                    },
                )
                .non_automatable()
                .with_callback(Arc::new(move |v| store.set_voices(v.max(0) as usize)))
                .with_value_to_string(Arc::new(move |v| text_store.voices_text(v)))
                .with_string_to_value(Arc::new(|t| {
                    let t = t.trim().to_ascii_lowercase();
                    if t.starts_with("script") || t == "auto" {
                        Some(0)
                    } else {
                        t.parse::<i32>()
                            .ok()
                            .filter(|v| (0..=MAX_VOICES as i32).contains(v))
                    }
                }))
            },
            mpe: BoolParam::new("MPE", Controls::DEFAULT.mpe),
            release: FloatParam::new(
                "Release",
                d.release as f32,
                FloatRange::Linear { min: 0.0, max: 1.0 },
            )
            .with_unit(" %")
            .with_value_to_string(Arc::new(|v| format!("{:.0}", v * 100.0)))
            .with_string_to_value(Arc::new(|t| {
                let t = t.trim().trim_end_matches('%').trim();
                t.parse::<f32>().ok().map(|v| (v / 100.0).clamp(0.0, 1.0))
            })),
            bend_range: FloatParam::new(
                "Bend Range",
                Controls::DEFAULT.bend_range_st as f32,
                FloatRange::Linear {
                    min: 0.0,
                    max: MAX_BEND_RANGE,
                },
            )
            .with_unit(" st")
            .with_step_size(1.0)
            .with_value_to_string(Arc::new(format_bend_range))
            .with_string_to_value(Arc::new(parse_semitones)),
            velocity_curve: FloatParam::new(
                "Velocity Curve",
                Controls::DEFAULT.velocity_exponent.log2() as f32,
                FloatRange::Linear {
                    min: -VELOCITY_OCTAVES,
                    max: VELOCITY_OCTAVES,
                },
            )
            .with_value_to_string(Arc::new(format_velocity_curve))
            .with_string_to_value(Arc::new(|t| parse_velocity_curve(t, VELOCITY_OCTAVES))),
            a4: FloatParam::new(
                "A4",
                d.a4_hz as f32,
                FloatRange::Linear {
                    min: A4_RANGE_HZ.0 as f32,
                    max: A4_RANGE_HZ.1 as f32,
                },
            )
            .with_unit(" Hz")
            .with_step_size(0.1)
            .with_value_to_string(Arc::new(|hz| format!("{hz:.1}")))
            .with_string_to_value(Arc::new(|t| {
                let t = t.trim().trim_end_matches("Hz").trim();
                t.parse::<f32>()
                    .ok()
                    .filter(|v| (A4_RANGE_HZ.0 as f32..=A4_RANGE_HZ.1 as f32).contains(v))
            })),
            trigger: BoolParam::new("Sidechain Trigger", d.trigger),
            trigger_sensitivity: gain_param(
                "Trigger Sensitivity",
                d.trigger_sensitivity_db as f32,
                -24.0,
                24.0,
            ),
            guard: BoolParam::new("Guard Tripped", false)
                .non_automatable()
                .with_value_to_string(Arc::new(|on| {
                    if on { GUARD_ON } else { GUARD_OFF }.to_string()
                }))
                .with_string_to_value(Arc::new(|text| parse_switch(text, GUARD_OFF, GUARD_ON))),
            macros,
        }
    }
}
