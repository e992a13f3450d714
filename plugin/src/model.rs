//! Models in the plugin: preparing a script off the audio thread, handing it over without
//! locks, and keeping the running script in the plugin state.
//!
//! A script becomes a [`Prepared`] model on the thread that submits it (the host's main
//! thread for a state load or activation, the editor for an edit): parse, compile, stability
//! envelope, macro ranges and scratch buffers are all made there. The audio thread receives it
//! through a bounded lock-free channel and sends the replaced model back through another one,
//! so it never allocates or frees. A script with errors never replaces the running model; its
//! diagnostics are kept in [`ModelStore::status`] for the editor.

use crate::envelope::{envelope, raw_envelope, worst_load};
pub use crate::envelope::{LoadLine, StabilityEnvelope, STABILITY_HEADROOM};
use crate::host::HostSettings;
use crate::macros::macro_bindings;
pub use crate::macros::MacroBinding;
use crate::motion::{motion_channel, MotionReader, MotionWriter};
use crate::param_text;
use crate::runtime::RuntimeStatus;
use crossbeam_channel::{Receiver, Sender};
use nice_plug::params::persist::PersistentField;
use ressort_engine::{
    compile, parse, CompileOptions, Engine, InputUse, ModelSpec, RouteSource, SampleRateMode,
    REFERENCE_SAMPLE_RATE_HZ,
};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// The engine runs in chunks of at most this many samples; gains and macros are updated at
/// chunk boundaries (counted from activation, so results do not depend on the host's block
/// size).
pub const CHUNK: usize = 16;

/// The number of generic macro slots.
pub const NUM_MACROS: usize = 16;

/// The saved part of the model: the script of the running model and where it came from.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ModelState {
    /// A preset id (`mesh-25x20`) or a file name or "Custom".
    pub name: String,
    /// The complete script.
    pub script: String,
}

/// What a model input carries, which decides its gain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputRole {
    /// A `frcInput`: × Force gain.
    Force,
    /// A `posInput`: × Position gain.
    Position,
    /// An `audioParam`: the raw channel.
    AudioParam,
    /// Declared by no element.
    Unused,
}

/// A model ready to run: compiled for one sample rate, with its scratch buffers.
#[derive(Debug)]
pub struct Prepared {
    pub engine: Engine,
    pub sample_rate: f64,
    pub name: String,
    pub settings: HostSettings,
    /// Planar input scratch, `roles.len()` channels of [`CHUNK`] samples.
    pub inputs: Vec<f64>,
    /// Planar output scratch, `max(outputs, 1)` channels of [`CHUNK`] samples.
    pub outputs: Vec<f64>,
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
    pub envelope: StabilityEnvelope,
    /// Per macro slot: the envelopes with its param at the range's minimum and maximum (the
    /// others at their declared values).
    pub macro_envelopes: Vec<Option<(StabilityEnvelope, StabilityEnvelope)>>,
    /// Loads at unit gains: (worst load, label of the worst mass or structure).
    pub worst_load: (f64, String),
    /// Publishes the positions for the editor.
    pub motion: MotionWriter,
    /// The editor's end of `motion`, until the store takes it.
    pub motion_reader: Option<MotionReader>,
}

/// A model's description for the editor and the tests: counts and analysis, made when it
/// was prepared.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModelSummary {
    pub name: String,
    pub points: usize,
    pub interactions: usize,
    pub inputs: Vec<String>,
    pub outputs: Vec<String>,
    pub params: Vec<String>,
    pub macros: Vec<Option<MacroBinding>>,
    pub stability: Vec<String>,
    pub reference_pitch_hz: Option<f64>,
    pub reference_key: f64,
}

/// The result of a script submission.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModelStatus {
    /// The running model.
    pub summary: ModelSummary,
    /// Diagnostics of the last submitted script (`LINE:COL: error: …`), empty when it loaded.
    pub diagnostics: Vec<String>,
    /// The last script that failed, kept for the editor.
    pub rejected: Option<ModelState>,
}

/// Why a script did not become the running model.
#[derive(Clone, Debug, PartialEq)]
pub struct Rejected(pub Vec<String>);

impl std::fmt::Display for Rejected {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0.join("\n"))
    }
}

/// Parses a script and turns every error into a `LINE:COL: error: …` line. Warnings are kept
/// too, after the errors, when the script is accepted.
pub fn parse_script(text: &str) -> Result<(ModelSpec, HostSettings, Vec<String>), Rejected> {
    let parsed = parse(text);
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
    let settings = HostSettings::from_spec(&spec).map_err(Rejected)?;
    Ok((spec, settings, warnings))
}

/// Compiles a script for a sample rate and derives everything the audio thread needs.
pub fn prepare(name: &str, text: &str, sample_rate: f64) -> Result<Prepared, Rejected> {
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
    // Avatars rest at their declared position: a silent input holds them there.
    let rest: Vec<f64> = info
        .inputs
        .iter()
        .map(|uses| match uses.first() {
            Some(InputUse::Position(label)) => (0..info.num_points)
                .find(|&i| info.point_label(i) == *label)
                .map(|i| engine.positions()[i])
                .unwrap_or(0.0),
            _ => 0.0,
        })
        .collect();
    if let Some(k) = settings.note_input {
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
    let routing = (0..roles.len())
        .map(|i| settings.routing.get(i).copied().flatten())
        .collect();
    let note_input = settings
        .note_input
        .map(|i| i as usize)
        .or_else(|| roles.iter().position(|r| *r == InputRole::Force));

    let mut settings = settings;
    if settings.reference_pitch_hz.is_none() {
        settings.reference_pitch_hz = estimate_pitch(&mut engine, note_input, &roles);
    }
    let envelope = envelope(&mut engine);
    let report = engine.stability();
    let worst_load = worst_load(&report);
    let macros = macro_bindings(&mut engine, &settings);
    let macro_envelopes = macros
        .iter()
        .map(|b| {
            b.as_ref().map(|b| {
                let _ = engine.set_param(b.param, b.min);
                let low = raw_envelope(&mut engine);
                let _ = engine.set_param(b.param, b.max);
                let high = raw_envelope(&mut engine);
                let _ = engine.set_param(b.param, b.default);
                engine.apply_pending_changes();
                (low.scaled(envelope.scale), high.scaled(envelope.scale))
            })
        })
        .collect();

    let rate = match spec.sample_rate_mode {
        SampleRateMode::Scaled => REFERENCE_SAMPLE_RATE_HZ / sample_rate,
        SampleRateMode::Raw => 1.0,
    };
    let num_outputs = info.num_outputs();
    let (motion, motion_reader) = motion_channel(&engine, sample_rate);
    Ok(Prepared {
        motion,
        motion_reader: Some(motion_reader),
        inputs: vec![0.0; roles.len() * CHUNK],
        outputs: vec![0.0; num_outputs.max(1) * CHUNK],
        num_outputs,
        roles,
        routing,
        rest,
        note_input,
        force_scale: rate * rate,
        strike_scale: rate,
        macros,
        envelope,
        macro_envelopes,
        worst_load,
        settings,
        sample_rate,
        name: name.to_string(),
        engine,
    })
}

/// Work budget of the pitch estimate, in element-steps: small models get a long window,
/// models too large for it get none (the tuning law then uses its low-frequency limit).
const PITCH_BUDGET: f64 = 4e7;
/// Length of the pitch estimate's impulse response.
const PITCH_WINDOW: usize = 8192;

/// The model's reference pitch: the strongest spectral peak of `@out1` after a force impulse
/// on the note input, found by rendering [`PITCH_WINDOW`] samples off the audio thread. The
/// engine is reset afterwards. None when the model has no force input or output, is too large
/// for the budget, or does not ring.
fn estimate_pitch(
    engine: &mut Engine,
    note_input: Option<usize>,
    roles: &[InputRole],
) -> Option<f64> {
    let k = note_input?;
    let info = engine.info();
    if info.num_outputs() == 0 {
        return None;
    }
    let size = (info.num_points + info.num_interactions).max(1) as f64;
    if size * PITCH_WINDOW as f64 > PITCH_BUDGET {
        return None;
    }
    let sr = engine.sample_rate_hz();
    let n_in = roles.len();
    let n_out = info.num_outputs();
    let mut inputs = vec![0.0; n_in * CHUNK];
    let mut outputs = vec![0.0; n_out * CHUNK];
    let mut signal = Vec::with_capacity(PITCH_WINDOW);
    inputs[k * CHUNK] = -1e-3;
    while signal.len() < PITCH_WINDOW {
        engine.process(CHUNK, &inputs, &mut outputs);
        inputs.fill(0.0);
        signal.extend_from_slice(&outputs[..CHUNK]);
    }
    let tripped = engine.is_tripped();
    engine.reset();
    if tripped {
        return None;
    }
    peak_frequency(&signal, sr)
}

/// The frequency of the strongest peak above 20 Hz (Hann window, parabolic interpolation of
/// the log magnitude).
pub fn peak_frequency(signal: &[f64], sample_rate: f64) -> Option<f64> {
    let n = signal.len();
    let mean = signal.iter().sum::<f64>() / n as f64;
    let mut frame: Vec<f64> = signal
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
            (x - mean) * w
        })
        .collect();
    let fft = realfft::RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut spectrum = fft.make_output_vec();
    fft.process(&mut frame, &mut spectrum).ok()?;
    let mags: Vec<f64> = spectrum.iter().map(|c| c.norm()).collect();
    let lo = ((20.0 * n as f64 / sample_rate).ceil() as usize).max(1);
    let (mut best, mut best_mag) = (0, 0.0);
    for (i, &m) in mags.iter().enumerate().take(mags.len() - 1).skip(lo) {
        if m > best_mag {
            best = i;
            best_mag = m;
        }
    }
    if !(best_mag > 0.0 && best_mag.is_finite()) {
        return None;
    }
    let (a, b, c) = (
        mags[best - 1].max(1e-300).ln(),
        best_mag.ln(),
        mags[best + 1].max(1e-300).ln(),
    );
    let denom = a - 2.0 * b + c;
    let delta = if denom != 0.0 {
        0.5 * (a - c) / denom
    } else {
        0.0
    };
    Some((best as f64 + delta.clamp(-0.5, 0.5)) * sample_rate / n as f64)
}

impl Prepared {
    /// Fills the planar input scratch for one chunk of `len` samples from the host channels
    /// (`host_in`: main left, main right, sidechain left, sidechain right; see
    /// [`crate::host::channel`]). Each model input takes the channel its `~route` names, else
    /// the next of `order`; a position input receives its rest + signal × `position`, a force
    /// input signal × `force` × [`Prepared::force_scale`], an audio-rate parameter the raw
    /// signal (the engine adds its declared default). An unfed input holds its rest.
    pub fn fill_inputs(
        &mut self,
        host_in: &[[f64; CHUNK]; 4],
        order: &[RouteSource],
        len: usize,
        force: f64,
        position: f64,
    ) {
        for (k, role) in self.roles.iter().enumerate() {
            let source = self.routing[k].or_else(|| order.get(k).copied());
            let gain = match role {
                InputRole::Force => force * self.force_scale,
                InputRole::Position => position,
                InputRole::AudioParam => 1.0,
                InputRole::Unused => 0.0,
            };
            let rest = self.rest[k];
            let dst = &mut self.inputs[k * len..(k + 1) * len];
            match source.and_then(crate::host::channel) {
                Some(c) if gain != 0.0 => {
                    for (d, s) in dst.iter_mut().zip(&host_in[c][..len]) {
                        *d = rest + s * gain;
                    }
                }
                _ => dst.fill(rest),
            }
        }
    }

    /// The editor's description of this model.
    pub fn summary(&mut self) -> ModelSummary {
        let info = self.engine.info();
        let inputs = info
            .inputs
            .iter()
            .enumerate()
            .map(|(i, uses)| {
                let what: Vec<String> = uses
                    .iter()
                    .map(|u| match u {
                        InputUse::Force(t) => format!("force on @{t}"),
                        InputUse::Position(t) => format!("position of @{t}"),
                        InputUse::Param(t) => format!("audio parameter {t}"),
                    })
                    .collect();
                format!("in{}: {}", i + 1, what.join(", "))
            })
            .collect();
        let outputs = info
            .outputs
            .iter()
            .enumerate()
            .map(|(i, o)| match o {
                ressort_engine::OutputUse::Position(t) => format!("out{}: position of @{t}", i + 1),
                ressort_engine::OutputUse::Force(t) => format!("out{}: force on @{t}", i + 1),
                ressort_engine::OutputUse::Unused => format!("out{}: unused", i + 1),
            })
            .collect();
        let params = info.params.iter().map(|p| p.name.clone()).collect();
        let (points, interactions) = (info.num_points, info.num_interactions);
        let report = self.engine.stability();
        let mut stability: Vec<String> = report.warnings.iter().map(|w| w.to_string()).collect();
        if let Some(w) = report.worst() {
            stability.insert(
                0,
                format!(
                    "closest to the limit: @{} ({:.1} % of 4M used)",
                    w.label,
                    100.0 * w.load()
                ),
            );
        }
        ModelSummary {
            name: self.name.clone(),
            points,
            interactions,
            inputs,
            outputs,
            params,
            macros: self.macros.clone(),
            stability,
            reference_pitch_hz: self.settings.reference_pitch_hz,
            reference_key: self.settings.reference_key,
        }
    }
}

/// Four significant digits, without exponent for ordinary magnitudes.
pub fn format_value(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.3e}")
    } else {
        let digits = if a >= 1.0 {
            3 - a.log10().floor() as i32
        } else {
            4
        };
        format!("{v:.*}", digits.clamp(0, 6) as usize)
    }
}

/// The model shared by the plugin, its parameters (as a persistent field) and the editor.
#[derive(Debug)]
pub struct ModelStore {
    /// The running model's script: what the plugin state saves.
    running: Mutex<ModelState>,
    status: Mutex<ModelStatus>,
    /// Sample rate of the active plugin (f64 bits), 0 while inactive.
    sample_rate: AtomicU64,
    /// Bumped for every model sent to the audio thread.
    generation: AtomicU64,
    to_audio: (Sender<Box<Prepared>>, Receiver<Box<Prepared>>),
    garbage: (Sender<Box<Prepared>>, Receiver<Box<Prepared>>),
    /// The motion reader of the newest model sent to the audio thread, until the editor
    /// takes it.
    motion: Mutex<Option<MotionReader>>,
    /// What the audio thread reports.
    pub runtime: RuntimeStatus,
}

impl Default for ModelStore {
    fn default() -> Self {
        let preset = crate::presets::Preset::default_preset();
        ModelStore {
            running: Mutex::new(ModelState {
                name: preset.id.to_string(),
                script: preset.text.to_string(),
            }),
            status: Mutex::new(ModelStatus::default()),
            sample_rate: AtomicU64::new(0),
            generation: AtomicU64::new(0),
            to_audio: crossbeam_channel::bounded(4),
            garbage: crossbeam_channel::bounded(64),
            motion: Mutex::new(None),
            runtime: RuntimeStatus::default(),
        }
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl ModelStore {
    /// The running model's name and script.
    pub fn running(&self) -> ModelState {
        lock(&self.running).clone()
    }

    /// The running model's summary and the last submission's diagnostics.
    pub fn status(&self) -> ModelStatus {
        lock(&self.status).clone()
    }

    /// The value text of macro slot `slot` at position `normalized`: `K = 0.1200`, or
    /// `unbound` when the model has fewer parameters.
    pub fn macro_text(&self, slot: usize, normalized: f64) -> String {
        let status = lock(&self.status);
        match status.summary.macros.get(slot) {
            Some(Some(b)) => format!("{} = {}", b.name, format_value(b.value_at(normalized))),
            _ => param_text::format_unbound_macro(normalized),
        }
    }

    /// The slot position for a macro's text (the inverse of [`ModelStore::macro_text`]):
    /// `K = 0.12` or `0.12` for a slot bound to `K`, `50 %` for an unbound one.
    pub fn macro_from_text(&self, slot: usize, text: &str) -> Option<f64> {
        let status = lock(&self.status);
        match status.summary.macros.get(slot) {
            Some(Some(b)) => {
                param_text::parse_bound_macro(text, &b.name).map(|v| b.normalized_of(v))
            }
            _ => param_text::parse_unbound_macro(text),
        }
    }

    /// The motion reader of the newest model, once: the editor keeps it until a newer model
    /// arrives.
    pub fn take_motion_reader(&self) -> Option<MotionReader> {
        lock(&self.motion).take()
    }

    /// How many models have been sent to the audio thread.
    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::Acquire)
    }

    /// Frees models the audio thread has finished with.
    pub fn collect_garbage(&self) {
        while self.garbage.1.try_recv().is_ok() {}
    }

    /// Sets the running script from outside the audio thread: a state load, the editor, a
    /// preset. While the plugin is active the model is compiled now and handed to the audio
    /// thread, which crossfades to it; while inactive it is only checked, and
    /// [`ModelStore::activate`] compiles it. A script with errors changes nothing but the
    /// diagnostics.
    pub fn submit(&self, state: ModelState) -> Result<(), Rejected> {
        self.collect_garbage();
        let rate = f64::from_bits(self.sample_rate.load(Ordering::Acquire));
        let result = if rate > 0.0 {
            prepare(&state.name, &state.script, rate).map(Some)
        } else {
            parse_script(&state.script).map(|_| None)
        };
        match result {
            Ok(prepared) => {
                let mut status = lock(&self.status);
                status.diagnostics.clear();
                status.rejected = None;
                if let Some(mut p) = prepared {
                    status.summary = p.summary();
                    drop(status);
                    *lock(&self.motion) = p.motion_reader.take();
                    self.send(Box::new(p));
                }
                *lock(&self.running) = state;
                Ok(())
            }
            Err(rejected) => {
                let mut status = lock(&self.status);
                status.diagnostics = rejected.0.clone();
                status.rejected = Some(state);
                Err(rejected)
            }
        }
    }

    fn send(&self, prepared: Box<Prepared>) {
        // Models still waiting are stale now; drop them here, not on the audio thread.
        while self.to_audio.1.try_recv().is_ok() {}
        if self.to_audio.0.try_send(prepared).is_ok() {
            self.generation.fetch_add(1, Ordering::AcqRel);
        }
    }

    /// Compiles the running script for `sample_rate` at activation. When it cannot be
    /// compiled at this rate, the default preset runs instead and the diagnostics say why.
    pub fn activate(&self, sample_rate: f64) -> Option<Box<Prepared>> {
        self.collect_garbage();
        while self.to_audio.1.try_recv().is_ok() {}
        self.sample_rate
            .store(sample_rate.to_bits(), Ordering::Release);
        let state = self.running();
        let mut prepared = match prepare(&state.name, &state.script, sample_rate) {
            Ok(p) => p,
            Err(rejected) => {
                let preset = crate::presets::Preset::default_preset();
                let fallback = prepare(preset.id, preset.text, sample_rate).ok()?;
                let mut status = lock(&self.status);
                status.diagnostics = rejected.0;
                status.rejected = Some(state);
                drop(status);
                *lock(&self.running) = ModelState {
                    name: preset.id.to_string(),
                    script: preset.text.to_string(),
                };
                fallback
            }
        };
        lock(&self.status).summary = prepared.summary();
        *lock(&self.motion) = prepared.motion_reader.take();
        Some(Box::new(prepared))
    }

    /// Marks the plugin inactive and frees what the audio thread returned.
    pub fn deactivate(&self) {
        self.sample_rate.store(0, Ordering::Release);
        while self.to_audio.1.try_recv().is_ok() {}
        self.collect_garbage();
    }

    /// Audio thread: the newest model waiting, if any. Realtime-safe.
    pub fn receive(&self) -> Option<Box<Prepared>> {
        // One per call: an older model still queued arrives at the next block and is replaced
        // at once, so nothing is ever dropped here.
        self.to_audio.1.try_recv().ok()
    }

    /// Audio thread: hands a finished model back to be freed elsewhere. Returns it when the
    /// return channel is full, so the caller keeps it until the next try. Realtime-safe.
    pub fn recycle(&self, prepared: Box<Prepared>) -> Result<(), Box<Prepared>> {
        self.garbage
            .0
            .try_send(prepared)
            .map_err(|e| e.into_inner())
    }
}

impl<'a> PersistentField<'a, ModelState> for Arc<ModelStore> {
    fn set(&self, new_value: ModelState) {
        // A state whose script does not load keeps the running model; the diagnostics say why.
        let _ = self.submit(new_value);
    }

    fn map<F, R>(&self, f: F) -> R
    where
        F: Fn(&ModelState) -> R,
    {
        f(&lock(&self.running))
    }
}
