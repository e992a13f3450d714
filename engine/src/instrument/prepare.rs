//! Preparing a script for the instrument, off the audio thread: text → spec (parse, host
//! directives) → compiled engine → everything the audio path needs (input roles and rests,
//! the note input, stability envelopes, macro bindings, the reference pitch, scratch
//! buffers). The audio thread then only runs a [`Prepared`] model.

use super::analyses::Analyses;
use super::exciters::{self, Exciter, Gestures};
use super::host::{HostSettings, InputRole, Rejected};
use super::macros::{macro_bindings, MacroBinding};
pub use super::pitch::{concert_key, peak_frequency, reference_mode};
use super::pitch::{musical_reference_pitch, quick_pitch, reference_pitch, settle_pitch};
use super::units::{unit_of, MacroUnit};
use super::voices::VoiceBank;
use super::CHUNK;
use crate::analysis::envelope::{
    envelope, exact_envelope, raw_envelope, worst_load, StabilityEnvelope,
};
use crate::{
    compile, CompileOptions, Engine, ExciterKind, InputUse, ModelSpec, RouteSource, SampleRateMode,
    REFERENCE_SAMPLE_RATE_HZ,
};
use std::fmt;
use std::sync::Arc;

/// Something that watches a running model's positions once per chunk (the plugin's motion
/// view). It runs on the audio thread: it must not allocate, lock or block.
pub trait Watcher: Send + fmt::Debug {
    /// `frames` samples were rendered; `watching` says whether anyone looks (an open editor).
    /// `axes` are the positions on x, y and z (a 1-D model's x and y are empty).
    fn tick(&mut self, frames: usize, axes: [&[f64]; 3], watching: bool);
}

/// The key a pitched model sits at before any note, in concert pitch: C4, where its level is
/// measured ([`super::level::MEASURE_KEY`]).
pub const HOME_KEY: u8 = 60;

/// What preparing a model found: fixed for the life of a [`Prepared`] model (its running
/// copies share it) and read by the audio path, the editor and the host. Only the level
/// calibration writes it, while the model is being prepared.
#[derive(Clone, Debug)]
pub struct Facts {
    pub sample_rate: f64,
    pub name: String,
    pub settings: HostSettings,
    pub num_outputs: usize,
    /// One entry per model input channel (`@in1` first).
    pub roles: Vec<InputRole>,
    /// The host channel feeding each model input, when the script chose one.
    pub routing: Vec<Option<RouteSource>>,
    /// The declared position of each position input's avatar (0 for other inputs): a
    /// `posInput` receives rest + signal × Position gain.
    pub rest: Vec<f64>,
    /// The model input a MIDI note strikes (0-based), if it exists.
    pub note_input: Option<usize>,
    /// Force inputs are read "as at 44.1 kHz", like the script's parameters: a force signal
    /// is scaled by (44100/SR)², the class of gravity (spec §1.7), so a sidechain moves the
    /// model the same at any sample rate. 1 in `~samplerate raw` scripts.
    pub force_scale: f64,
    /// A one-sample strike (MIDI note, editor) is scaled by 44100/SR so that it gives the
    /// model the same momentum at any sample rate. 1 in `~samplerate raw` scripts.
    pub strike_scale: f64,
    pub macros: Vec<Option<MacroBinding>>,
    /// How each macro slot reads (Hz, T60, ratio, 0 … 1 or its value), by slot.
    pub macro_units: Vec<MacroUnit>,
    /// The limits of the host's Stiffness and Damping gains.
    pub envelope: StabilityEnvelope,
    /// Per macro slot: the envelopes with its param at the range's minimum and maximum (the
    /// others at their declared values).
    pub macro_envelopes: Vec<Option<(StabilityEnvelope, StabilityEnvelope)>>,
    /// The Gershgorin envelope at the declared values, of the same kind as the macro
    /// envelopes: `envelope` may be the exact one, which they are not compared with.
    pub macro_reference: StabilityEnvelope,
    /// Loads at unit gains: (worst load, label of the worst mass or structure).
    pub worst_load: (f64, String),
    /// The exciters a key plays besides its strike (`~exciter`, [`super::exciters`]).
    pub exciters: Vec<Exciter>,
    /// How the model is played: concert pitch and the automatic trims, or as projects saved
    /// before them.
    pub conventions: Conventions,
    /// What each output reads at rest, taken off every copy of the model before the output
    /// stage, so that a hammer's height or an avatar's position is no step at note-on (0 in
    /// legacy projects).
    pub rest_out: Vec<f64>,
    /// The automatic output trim (linear; the Output Gain knob adds to it) and the trim of
    /// the host signals that push the model (the sidechain on force and position inputs;
    /// Force and Position Gain add to it), found when the model was prepared
    /// ([`super::level`]); 1 in legacy projects.
    pub output_trim: f64,
    pub input_trim: f64,
    /// Per model input: the one-pole coefficient that smooths a host signal feeding a
    /// connection-point coordinate (an `audioParam` named in `[@s f]`, [`PLACE_GLIDE_MS`]),
    /// 1 for every other input, which takes the signal as it comes.
    pub place_glide: Vec<f64>,
    /// The analyses' part holds quick stand-ins ([`Source::Provisional`]): the exact
    /// analyses are still to come, and [`super::Instrument::refine`] takes them when they do.
    pub provisional: bool,
}

/// The time constant with which a host signal moves a connection point along its macro.
/// A point that jumps along a string from one sample to the next injects energy (spec
/// §2.8; issue 34 of its table): full-scale noise on a sidechain routed to a finger's place
/// blew Two Fingers String up at 192 kHz. Smoothed to gesture speed, a sidechain still
/// slides the finger (63 % of a step in 5 ms) and no longer teleports it. The engine, and
/// `ressort render` without `--as-plugin`, take the audio-rate parameter raw, as the spec
/// says, and so do projects saved before concert pitch ([`Conventions::Legacy`]), which
/// play as they were saved.
pub const PLACE_GLIDE_MS: f64 = 5.0;

/// [`Facts::place_glide`] of a model: the coefficient for inputs that feed a coordinate.
fn place_glide(info: &crate::ModelInfo, sample_rate: f64) -> Vec<f64> {
    let a = 1.0 - (-1000.0 / (PLACE_GLIDE_MS * sample_rate)).exp();
    info.inputs
        .iter()
        .map(|uses| {
            let places = uses.iter().any(|u| match u {
                InputUse::Param(name) => {
                    info.params.iter().any(|p| p.coordinate && &p.name == name)
                }
                _ => false,
            });
            if places && a > 0.0 && a < 1.0 {
                a
            } else {
                1.0
            }
        })
        .collect()
}

/// A model ready to run: what its preparation found ([`Facts`], immutable) and the running
/// part: the engine, its voices, the gestures keys hold, and scratch buffers.
#[derive(Debug)]
pub struct Prepared {
    pub(crate) facts: Arc<Facts>,
    pub engine: Engine,
    /// Planar input scratch, `roles.len()` channels of [`CHUNK`] samples.
    pub inputs: Vec<f64>,
    /// Per model input, the smoothed host signal of a glided input ([`Facts::place_glide`]),
    /// starting at its rest.
    pub(crate) glided: Vec<f64>,
    /// Planar output scratch, `max(outputs, 1)` channels of [`CHUNK`] samples.
    pub outputs: Vec<f64>,
    /// Sees the positions after every chunk, if set.
    pub watcher: Option<Box<dyn Watcher>>,
    /// The voices when the model plays polyphonically ([`Prepared::set_voices`]); without
    /// them `engine` is the one voice, and a note retunes it.
    pub bank: Option<VoiceBank>,
    /// The one model's gestures (without voices), the key that holds them (note, channel),
    /// and the samples a strike without a key still holds them.
    pub gestures: Gestures,
    pub held_note: Option<(u8, u8)>,
    pub strike_hold: u64,
    /// With voices, the model itself plays only what the host feeds it: under today's
    /// conventions it is not run until a host signal or pressure reaches it (a model that
    /// moves by itself, a ball dropped at every reset, would otherwise sound at load).
    pub awake: bool,
}

/// Parses a script and turns every error into a `LINE:COL: error: …` line. Warnings are kept
/// too, after the errors, when the script is accepted.
pub fn parse_script(text: &str) -> Result<(ModelSpec, HostSettings, Vec<String>), Rejected> {
    let parsed = crate::lang::parse_with_files(text, &super::meshes::shipped);
    let errors: Vec<String> = parsed.errors().map(|d| d.to_string()).collect();
    if !errors.is_empty() {
        return Err(Rejected(errors));
    }
    let warnings: Vec<String> = parsed.diagnostics.iter().map(|d| d.to_string()).collect();
    let Some(spec) = parsed.spec else {
        return Err(Rejected(vec![
            "1:1: error: the script describes no model".into()
        ]));
    };
    // The language allows an empty model; an instrument has nothing to play in one, and a
    // cleared editor or an empty file must not silence the running model.
    let elements = spec
        .space
        .as_ref()
        .map_or(spec.elements.len(), |s| s.elements.len());
    if elements == 0 {
        return Err(Rejected(vec![
            "1:1: error: the script is empty: it defines no element to play (write a model, \
             see docs/LANGUAGE.md, or choose a preset)"
                .into(),
        ]));
    }
    let settings = HostSettings::from_spec(&spec).map_err(Rejected)?;
    Ok((spec, settings, warnings))
}

/// How a host plays a model: today's conventions, or those of projects saved before them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Conventions {
    /// Concert pitch, the automatic output trim and the calibrated sidechain.
    #[default]
    Musical,
    /// Projects saved before those: the relative tuning of `~key`, no trim, the raw sidechain.
    Legacy,
}

/// Where a preparation takes its analyses' results from.
#[derive(Clone, Debug)]
pub(crate) enum Source {
    /// Runs them, measuring the macro units for at most this long; with `pitch`, the
    /// reference pitch is taken as that instead of analysed (the shipped table's test
    /// compares the rest of an analysis at the table's own pitch).
    Analyse {
        units_budget_s: f64,
        pitch: Option<f64>,
    },
    /// Kept from an earlier preparation of the same script ([`super::analyses`]); a result
    /// that does not fit the compiled script (a stale table) is analysed afresh.
    Known(Arc<Analyses>),
    /// The quick, conservative stand-ins a model plays on until its exact analyses are done
    /// ([`super::load::prepare_provisional`]): the Gershgorin envelope instead of the exact
    /// one, a short impulse response's peak (or the declared `~pitch`) instead of the modal
    /// reference pitch, and every macro slot read as its value.
    Provisional,
}

/// Compiles a script for a sample rate and derives everything the audio thread needs, under
/// the given playing conventions; the level calibration ([`super::level`]) comes after, in
/// [`super::load`], unless the analyses were known. Returns the source the analyses came from
/// (an analysis where kept results did not fit).
pub(crate) fn prepare_uncalibrated(
    name: &str,
    text: &str,
    sample_rate: f64,
    conventions: Conventions,
    source: Source,
) -> Result<(Prepared, Source), Rejected> {
    let (spec, settings, _warnings) = parse_script(text)?;
    let mut engine = compile(&spec, &CompileOptions::at(sample_rate))
        .map_err(|e| Rejected(e.0.iter().map(|e| format!("1:1: error: {e}")).collect()))?;
    let info = engine.info().clone();

    let roles: Vec<InputRole> = info
        .inputs
        .iter()
        .map(|uses| match uses.first() {
            Some(InputUse::Force(_)) => InputRole::Force,
            Some(InputUse::Position(_)) => InputRole::Position,
            Some(InputUse::Param(_)) => InputRole::AudioParam,
            None => InputRole::Unused,
        })
        .collect();
    let rest = input_rests(&engine);
    let from_exciter = spec
        .host
        .exciters
        .iter()
        .any(|e| e.kind == ExciterKind::Strike);
    if let Some(k) = settings.note_input.filter(|_| !from_exciter) {
        if roles.get(k as usize) != Some(&InputRole::Force) {
            let line = text
                .lines()
                .position(|l| l.trim_start().starts_with("~note"))
                .map(|i| i + 1)
                .unwrap_or(1);
            return Err(Rejected(vec![format!(
                "{line}:1: error: `~note in{}`: in{} is not a force input (frcInput) of this model",
                k + 1,
                k + 1
            )]));
        }
    }
    let exciters = exciters::resolve(&spec, &engine, &roles, sample_rate)?;
    let routing = (0..roles.len())
        .map(|i| settings.routing.get(i).copied().flatten())
        .collect();
    // A script with exciters strikes only where it says; one without strikes its first force
    // input.
    let note_input = settings.note_input.map(|i| i as usize).or_else(|| {
        (!settings.has_exciters)
            .then(|| roles.iter().position(|r| *r == InputRole::Force))
            .flatten()
    });

    let mut settings = settings;
    if let Source::Analyse {
        pitch: Some(pitch), ..
    } = source
    {
        settings.reference_pitch_hz = Some(pitch);
    }
    let found = if let Source::Known(ref kept) = source {
        (**kept).clone()
    } else {
        let depth = match source {
            Source::Analyse { units_budget_s, .. } => Depth::Exact { units_budget_s },
            _ => Depth::Provisional,
        };
        analyse(
            &spec,
            &mut engine,
            &mut settings,
            conventions,
            note_input,
            &exciters,
            &roles,
            depth,
        )
    };
    let rate = match spec.sample_rate_mode {
        SampleRateMode::Scaled => REFERENCE_SAMPLE_RATE_HZ / sample_rate,
        SampleRateMode::Raw => 1.0,
    };
    let num_outputs = info.num_outputs();
    // Projects saved before the glide play their sidechain as they did.
    let place_glide = match conventions {
        Conventions::Musical => place_glide(&info, sample_rate),
        Conventions::Legacy => vec![1.0; info.inputs.len()],
    };
    let mut facts = Facts {
        provisional: false,
        place_glide,
        exciters,
        conventions,
        rest_out: vec![0.0; num_outputs.max(1)],
        output_trim: 1.0,
        input_trim: 1.0,
        num_outputs,
        routing,
        rest,
        note_input,
        force_scale: rate * rate,
        strike_scale: rate,
        macros: Vec::new(),
        macro_units: Vec::new(),
        envelope: StabilityEnvelope::default(),
        macro_envelopes: Vec::new(),
        macro_reference: StabilityEnvelope::default(),
        worst_load: (0.0, String::new()),
        settings,
        sample_rate,
        name: name.to_string(),
        roles,
    };
    let fresh = !matches!(source, Source::Known(_));
    facts.provisional = matches!(source, Source::Provisional);
    if !fresh && !found.fits(&facts, &engine) {
        return prepare_uncalibrated(
            name,
            text,
            sample_rate,
            conventions,
            Source::Analyse {
                units_budget_s: UNITS_BUDGET_S,
                pitch: None,
            },
        );
    }
    found.apply(&mut facts);
    let prepared = Prepared {
        watcher: None,
        bank: None,
        gestures: exciters::AT_REST,
        held_note: None,
        strike_hold: 0,
        awake: conventions == Conventions::Legacy,
        inputs: vec![0.0; facts.roles.len() * CHUNK],
        glided: facts.rest.clone(),
        outputs: vec![0.0; num_outputs.max(1) * CHUNK],
        facts: Arc::new(facts),
        engine,
    };
    Ok((prepared, source))
}

/// How far [`analyse`] goes.
#[derive(Clone, Copy, Debug)]
enum Depth {
    /// Every analysis, the macro units measured for at most this long.
    Exact { units_budget_s: f64 },
    /// Only what takes milliseconds on the largest models ([`Source::Provisional`]).
    Provisional,
}

/// Runs the analyses of a freshly compiled model ([`Source::Analyse`], or their quick
/// stand-ins for [`Source::Provisional`]): the reference pitch (which also sets `settings`'
/// reference pitch and key), the stability envelopes, the worst load and the macro units.
/// The rests and trims are left at their neutral values for the level calibration. Leaves
/// the engine's parameters as it found them.
#[allow(clippy::too_many_arguments)]
fn analyse(
    spec: &ModelSpec,
    engine: &mut Engine,
    settings: &mut HostSettings,
    conventions: Conventions,
    note_input: Option<usize>,
    exciters: &[Exciter],
    roles: &[InputRole],
    depth: Depth,
) -> Analyses {
    let sample_rate = engine.sample_rate_hz();
    if settings.reference_pitch_hz.is_none() {
        settings.reference_pitch_hz = match (depth, conventions) {
            (Depth::Provisional, _) => quick_pitch(engine, note_input, roles),
            (_, Conventions::Legacy) => reference_pitch(engine, note_input, roles),
            (_, Conventions::Musical) => {
                musical_reference_pitch(spec, engine, note_input, exciters, roles, sample_rate)
            }
        }
        // The same on every processor, so a bounce does not depend on the machine.
        .map(settle_pitch);
    }
    // Concert pitch: the key whose equal-tempered pitch (A4 = 440 Hz; the A4 control moves
    // every key together) is the model's reference pitch. An unpitched model keeps its own
    // pitch at its `~key`.
    if conventions == Conventions::Musical && !settings.unpitched {
        if let Some(f) = settings
            .reference_pitch_hz
            .filter(|f| *f > 0.0 && f.is_finite())
        {
            settings.reference_key = concert_key(f);
        }
    }
    // The stability limits hold for a key held down: the `audioParam`s a key presses (a
    // bow's friction) are analysed at their pressed values, and put back after.
    let pressed = press_audio_params(engine, exciters);
    // The exact limit where it applies; the Gershgorin envelope (whose scale the macro
    // envelopes share) otherwise.
    // A model the exact criterion rejects as written (a script written at the edge for
    // 44.1 kHz, played at 22.05 kHz) would explode: the Gershgorin envelope is not scaled to
    // trust it then, so that the macro envelopes stay true bounds.
    let (envelope, gershgorin) = match depth {
        Depth::Exact { .. } => {
            let exact = engine.exact_stability();
            let gershgorin = if exact.is_stable(1.0, 1.0) == Some(false) {
                raw_envelope(engine)
            } else {
                envelope(engine)
            };
            let envelope = exact_envelope(&exact).unwrap_or_else(|| gershgorin.clone());
            // Its matrices are not needed past here.
            drop(exact);
            (envelope, gershgorin)
        }
        // The Gershgorin envelope, trusting the script as written as it does where the exact
        // criterion does not apply; a script the exact analysis rejects as written (a 44.1 kHz
        // edge played at 22.05 kHz) is held by the guard until the exact limits arrive.
        Depth::Provisional => {
            let gershgorin = envelope(engine);
            (gershgorin.clone(), gershgorin)
        }
    };
    let report = engine.stability();
    let worst_load = worst_load(&report);
    let macros = macro_bindings(engine, settings);
    let macro_envelopes = macros
        .iter()
        .map(|b| {
            b.as_ref().map(|b| {
                let _ = engine.set_param(b.param, b.min);
                let low = raw_envelope(engine);
                let _ = engine.set_param(b.param, b.max);
                let high = raw_envelope(engine);
                let _ = engine.set_param(b.param, b.default);
                engine.apply_pending_changes();
                (low.scaled(gershgorin.scale), high.scaled(gershgorin.scale))
            })
        })
        .collect();

    for (id, value) in pressed {
        let _ = engine.set_param(id, value);
    }
    engine.apply_pending_changes();
    let units_budget_s = match depth {
        Depth::Exact { units_budget_s } => units_budget_s,
        // Nothing measured: every slot reads as its value.
        Depth::Provisional => f64::NEG_INFINITY,
    };
    let macro_units = macro_units(engine, &macros, note_input, units_budget_s);

    Analyses {
        reference_pitch_hz: settings.reference_pitch_hz,
        reference_key: settings.reference_key,
        envelope,
        macro_envelopes,
        macro_reference: gershgorin,
        worst_load,
        macro_units,
        macros,
        // The level calibration's to measure.
        rest_out: vec![0.0; engine.info().num_outputs().max(1)],
        output_trim: 1.0,
        input_trim: 1.0,
    }
}

/// Sets every `audioParam` that a press exciter drives to its value with the key fully
/// down (its default + the press's depth, inside the press's limits), and returns the
/// values to put back.
pub fn press_audio_params(engine: &mut Engine, exciters: &[Exciter]) -> Vec<(crate::ParamId, f64)> {
    let mut old = Vec::new();
    for x in exciters
        .iter()
        .filter(|x| x.kind == ExciterKind::Press && x.role == InputRole::AudioParam)
    {
        let names: Vec<String> = engine.info().inputs[x.input]
            .iter()
            .filter_map(|u| match u {
                InputUse::Param(name) => Some(name.to_string()),
                _ => None,
            })
            .collect();
        for name in names {
            let Some(id) = engine.param_id(&name) else {
                continue;
            };
            let Some(value) = engine.param(id) else {
                continue;
            };
            if engine
                .set_param(id, value + x.amount.clamp(x.low, x.high))
                .is_ok()
            {
                old.push((id, value));
            }
        }
    }
    engine.apply_pending_changes();
    old
}

/// What each input channel of `engine` holds when nothing feeds it: a position input its
/// avatar's declared position (so a silent input leaves the avatar where the script puts it),
/// every other input 0.
pub fn input_rests(engine: &Engine) -> Vec<f64> {
    let info = engine.info();
    info.inputs
        .iter()
        .map(|uses| match uses.first() {
            Some(InputUse::Position(label)) => info
                .find_point(label)
                .filter(|&i| i < info.num_points)
                .map(|i| engine.positions()[i])
                .unwrap_or(0.0),
            _ => 0.0,
        })
        .enumerate()
        .map(|(c, rest)| match engine.is_3d() {
            true => engine.avatar_rest(c).unwrap_or(0.0),
            false => rest,
        })
        .collect()
}

/// Time the macro units may take while a model is prepared; slots left when it runs out read
/// as values.
pub const UNITS_BUDGET_S: f64 = 0.25;

/// The unit of every macro slot ([`super::units`]): frequencies and decays of the reference
/// mode (the strongest from the note input, or `@in1`, to `@out1`) come from the dense modal
/// analysis, for models up to [`crate::analysis::modes::DENSE_LIMIT`] points, within
/// [`UNITS_BUDGET_S`].
fn macro_units(
    engine: &mut Engine,
    macros: &[Option<MacroBinding>],
    note_input: Option<usize>,
    budget_s: f64,
) -> Vec<MacroUnit> {
    // The reference mode is measured by the dense analysis only, and needs an output.
    let measurable = engine.info().num_points <= crate::analysis::modes::DENSE_LIMIT
        && engine.info().num_outputs() > 0;
    let input = note_input.unwrap_or(0) + 1;
    let params = engine.info().params.clone();
    let reference = |e: &mut Engine| -> Option<(f64, f64)> {
        let a = e.modes(None);
        a.strongest(input, 1, 20.0)
            .map(|m| (m.frequency_hz, m.t60_s))
    };
    let started = std::time::Instant::now();
    macros
        .iter()
        .map(|b| match b {
            Some(b) => {
                let p = &params[b.param.0 as usize];
                if !measurable || started.elapsed().as_secs_f64() > budget_s {
                    // Nothing to measure, or out of time: positions still read as positions,
                    // the rest as values.
                    return unit_of(engine, b, p.coordinate, &|_: &mut Engine| None);
                }
                unit_of(engine, b, p.coordinate, &reference)
            }
            None => MacroUnit::Value,
        })
        .collect()
}

impl Prepared {
    /// What preparing the model found.
    pub fn facts(&self) -> &Facts {
        &self.facts
    }

    /// The facts as shared: what [`super::Instrument::refine`] recognises a provisional model
    /// by (the same `Arc`). Off the audio thread.
    pub fn shared_facts(&self) -> Arc<Facts> {
        Arc::clone(&self.facts)
    }

    /// The facts while the model is being prepared (the level calibration writes its trims).
    pub(crate) fn facts_mut(&mut self) -> &mut Facts {
        Arc::make_mut(&mut self.facts)
    }

    /// Fills the planar input scratch for one chunk of `len` samples from the host channels
    /// (`host_in`, indexed as [`super::host::channel`] numbers them). Each model input takes
    /// the channel its `~route` names, else the next of `order`; a position input receives
    /// its rest + signal × `position`, a force input signal × `force` ×
    /// [`Prepared::force_scale`] × [`Prepared::input_trim`], a position input its rest +
    /// signal × `position` × the same trim (neither with `trigger`: the sidechain then plays
    /// strikes), an audio-rate parameter the raw signal (the engine adds its declared default).
    /// An unfed input holds its rest. Returns whether a host signal
    /// reached an input.
    pub fn fill_inputs(
        &mut self,
        host_in: &[[f64; CHUNK]],
        order: &[RouteSource],
        len: usize,
        force: f64,
        position: f64,
        trigger: bool,
    ) -> bool {
        let mut fed = false;
        for (k, role) in self.facts.roles.iter().enumerate() {
            let source = self.facts.routing[k].or_else(|| order.get(k).copied());
            let gain = match role {
                // In trigger mode the host's signals that push the model become strikes.
                InputRole::Force | InputRole::Position if trigger => 0.0,
                InputRole::Force => force * self.facts.force_scale * self.facts.input_trim,
                InputRole::Position => position * self.facts.input_trim,
                InputRole::AudioParam => 1.0,
                InputRole::Unused => 0.0,
            };
            let rest = self.facts.rest[k];
            let dst = &mut self.inputs[k * len..(k + 1) * len];
            match source
                .and_then(super::host::channel)
                .and_then(|c| host_in.get(c))
            {
                Some(channel) if gain != 0.0 => {
                    let a = self.facts.place_glide[k];
                    if a == 1.0 {
                        for (d, s) in dst.iter_mut().zip(&channel[..len]) {
                            *d = rest + s * gain;
                            fed |= *s != 0.0;
                        }
                    } else {
                        // A coordinate: y ← y + a·(target − y), from the rest on. Within
                        // 1e-12 of its target (of a macro's length) it lands there, so that a
                        // glide back to rest ends at the rest's bits and never decays into
                        // subnormal numbers.
                        let mut y = self.glided[k];
                        for (d, s) in dst.iter_mut().zip(&channel[..len]) {
                            let target = rest + s * gain;
                            let step = a * (target - y);
                            y = if step.abs() < 1e-12 { target } else { y + step };
                            *d = y;
                            fed |= *s != 0.0;
                        }
                        // A non-finite host signal is no place: the glide starts again.
                        self.glided[k] = if y.is_finite() { y } else { rest };
                    }
                }
                _ => {
                    dst.fill(rest);
                    self.glided[k] = rest;
                }
            }
        }
        fed
    }

    /// Puts the glided inputs back at their rests ([`Facts::place_glide`]): with the model's
    /// own reset, so that a render from a reset does not depend on what came before.
    pub(crate) fn rest_inputs(&mut self) {
        self.glided.copy_from_slice(&self.facts.rest);
    }

    /// Plays `voices` notes at once: 1 is the monophonic instrument (a note retunes and strikes
    /// the one model); more make a voice bank of copies of the model. Allocates: call it off
    /// the audio thread.
    pub fn set_voices(&mut self, voices: usize) {
        self.bank = (voices > 1).then(|| {
            VoiceBank::new(
                &self.engine,
                self.facts.roles.len(),
                self.facts.num_outputs,
                voices,
                self.facts.sample_rate,
            )
        });
    }

    /// The script's `~pressure` input and the amount full pressure adds to it, in the
    /// input's units after the host gains: × Force Gain (and the force rate scale) for a
    /// force input, × Position Gain for a position input.
    pub fn pressure_gain(&self, force: f64, position: f64) -> Option<(usize, f64)> {
        let k = self.facts.settings.pressure_input? as usize;
        let scale = self.facts.settings.pressure_scale;
        let gain = match self.facts.roles.get(k)? {
            InputRole::Force => scale * force * self.facts.force_scale,
            InputRole::Position => scale * position,
            InputRole::AudioParam => scale,
            InputRole::Unused => return None,
        };
        Some((k, gain))
    }

    /// How many notes play at once.
    pub fn voices(&self) -> usize {
        self.bank.as_ref().map_or(1, |b| b.limit)
    }

    /// The force of a note's strike per unit of velocity response: the script's note force ×
    /// the rate scale × `force` (the Force gain).
    pub fn strike_force(&self, force: f64) -> f64 {
        self.facts.settings.note_force * self.facts.strike_scale * force
    }

    /// The key the model plays before any note, and that a strike without a key (the
    /// editor's, a sidechain trigger's) plays: C4 for a pitched model in concert pitch, so
    /// that it sounds where its level was measured ([`super::level`]); the `~key` at which an
    /// unpitched model (or a legacy project's) sounds as written.
    pub fn home_key(&self) -> f64 {
        if self.facts.conventions == Conventions::Musical && !self.facts.settings.unpitched {
            f64::from(HOME_KEY)
        } else {
            self.facts.settings.reference_key
        }
    }

    /// What Vary may move on this model ([`super::vary`]): its bound macro slots, and its
    /// Stiffness unless keys play it in concert pitch.
    pub fn vary_scope(&self) -> super::vary::VaryScope {
        let mut bound = [false; super::NUM_MACROS];
        for (b, m) in bound.iter_mut().zip(&self.facts.macros) {
            *b = m.is_some();
        }
        super::vary::VaryScope {
            bound,
            pitched: self.facts.conventions == Conventions::Musical
                && !self.facts.settings.unpitched,
        }
    }

    /// The highest key that sounds in tune at default controls: above it the stability
    /// clamp holds the Stiffness gain a note asks for (the exact law inverted at the
    /// envelope's largest gain). None without a reference pitch or a limit.
    pub fn highest_key(&self) -> Option<f64> {
        let f = self.facts.settings.reference_pitch_hz?;
        let g = self.facts.envelope.max_stiffness(1.0);
        if !(g.is_finite() && f > 0.0 && f < 0.49 * self.facts.sample_rate) {
            return None;
        }
        let s = g.sqrt() * (std::f64::consts::PI * f / self.facts.sample_rate).sin();
        let top = if s >= 1.0 {
            0.49 * self.facts.sample_rate
        } else {
            (self.facts.sample_rate / std::f64::consts::PI * s.asin())
                .min(0.49 * self.facts.sample_rate)
        };
        Some(self.facts.settings.reference_key + 12.0 * (top / f).log2())
    }

    /// Puts the one model's gestures at rest, with no key holding them, and the glided host
    /// inputs at their rests ([`Prepared::rest_inputs`]): what a level measurement's drum
    /// left there does not reach the next performance.
    pub fn rest_gestures(&mut self) {
        self.gestures = exciters::AT_REST;
        self.held_note = None;
        self.strike_hold = 0;
        self.rest_inputs();
    }

    /// Adds a one-sample strike of `velocity` (0 … 1) to the note input at `frame` of the
    /// chunk being filled (`len` samples): the script's note force × the rate scale ×
    /// `force` (the Force gain).
    pub fn strike(&mut self, frame: usize, len: usize, velocity: f64, force: f64) {
        if let Some(k) = self.facts.note_input {
            self.inputs[k * len + frame] +=
                self.facts.settings.note_force * self.facts.strike_scale * velocity * force;
        }
    }
}
