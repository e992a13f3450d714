//! Preparing a script for the instrument, off the audio thread: text → spec (parse, host
//! directives) → compiled engine → everything the audio path needs (input roles and rests,
//! the note input, stability envelopes, macro bindings, the reference pitch, scratch
//! buffers). The audio thread then only runs a [`Prepared`] model.

use super::envelope::{envelope, exact_envelope, raw_envelope, worst_load, StabilityEnvelope};
use super::host::HostSettings;
use super::macros::{macro_bindings, MacroBinding};
use super::units::{unit_of, MacroUnit};
use super::voices::VoiceBank;
use super::CHUNK;
use crate::{
    compile, parse, CompileOptions, Engine, InputUse, ModelSpec, RouteSource, SampleRateMode,
    REFERENCE_SAMPLE_RATE_HZ,
};
use std::fmt;

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

/// Something that watches a running model's positions once per chunk (the plugin's motion
/// view). It runs on the audio thread: it must not allocate, lock or block.
pub trait Watcher: Send + fmt::Debug {
    /// `frames` samples were rendered; `watching` says whether anyone looks (an open editor).
    fn tick(&mut self, frames: usize, positions: &[f64], watching: bool);
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
    /// How each macro slot reads (Hz, T60, ratio, 0 … 1 or its value), by slot.
    pub macro_units: Vec<MacroUnit>,
    pub envelope: StabilityEnvelope,
    /// Per macro slot: the envelopes with its param at the range's minimum and maximum (the
    /// others at their declared values).
    pub macro_envelopes: Vec<Option<(StabilityEnvelope, StabilityEnvelope)>>,
    /// Loads at unit gains: (worst load, label of the worst mass or structure).
    pub worst_load: (f64, String),
    /// Sees the positions after every chunk, if set.
    pub watcher: Option<Box<dyn Watcher>>,
    /// The voices when the model plays polyphonically ([`Prepared::set_voices`]); without
    /// them `engine` is the one voice, and a note retunes it.
    pub bank: Option<VoiceBank>,
}

/// Why a script did not become the running model: `LINE:COL: error: …` lines.
#[derive(Clone, Debug, PartialEq)]
pub struct Rejected(pub Vec<String>);

impl fmt::Display for Rejected {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0.join("\n"))
    }
}

impl std::error::Error for Rejected {}

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

/// How a host plays a model: today's conventions, or those of projects saved before them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Conventions {
    /// Concert pitch, the automatic output trim and the calibrated sidechain.
    #[default]
    Musical,
    /// Projects saved before those: the relative tuning of `~key`, no trim, the raw sidechain.
    Legacy,
}

/// Compiles a script for a sample rate and derives everything the audio thread needs.
pub fn prepare(name: &str, text: &str, sample_rate: f64) -> Result<Prepared, Rejected> {
    prepare_with(name, text, sample_rate, Conventions::Musical)
}

/// [`prepare`] under the given playing conventions.
pub fn prepare_with(
    name: &str,
    text: &str,
    sample_rate: f64,
    _conventions: Conventions,
) -> Result<Prepared, Rejected> {
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
        settings.reference_pitch_hz = reference_pitch(&mut engine, note_input, &roles);
    }
    // The exact limit where it applies; the Gershgorin envelope (whose scale the macro
    // envelopes share) otherwise.
    let gershgorin = envelope(&mut engine);
    let envelope = exact_envelope(&mut engine).unwrap_or_else(|| gershgorin.clone());
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
                (low.scaled(gershgorin.scale), high.scaled(gershgorin.scale))
            })
        })
        .collect();

    let macro_units = macro_units(&mut engine, &macros, note_input);

    let rate = match spec.sample_rate_mode {
        SampleRateMode::Scaled => REFERENCE_SAMPLE_RATE_HZ / sample_rate,
        SampleRateMode::Raw => 1.0,
    };
    let num_outputs = info.num_outputs();
    Ok(Prepared {
        watcher: None,
        bank: None,
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
        macro_units,
        envelope,
        macro_envelopes,
        worst_load,
        settings,
        sample_rate,
        name: name.to_string(),
        engine,
    })
}

/// The model's reference pitch (issue 14): the strongest mode that `@out1` hears from the note
/// input, by the modal analysis ([`crate::modes`]), for models of any size: dense and exact up
/// to [`crate::modes::DENSE_LIMIT`] moving points, the strongest of the lowest
/// [`crate::modes::DEFAULT_SPARSE_COUNT`] above (about 2 s for the 150 × 150 plate). Models the
/// analysis cannot read (a note input with no linear path) fall back to the impulse
/// response's strongest peak ([`estimate_pitch`]), within its work budget.
/// What each input channel of `engine` holds when nothing feeds it: a position input its
/// avatar's declared position (so a silent input leaves the avatar where the script puts it),
/// every other input 0.
pub fn input_rests(engine: &Engine) -> Vec<f64> {
    let info = engine.info();
    info.inputs
        .iter()
        .map(|uses| match uses.first() {
            Some(InputUse::Position(label)) => (0..info.num_points)
                .find(|&i| info.point_label(i) == *label)
                .map(|i| engine.positions()[i])
                .unwrap_or(0.0),
            _ => 0.0,
        })
        .collect()
}

fn reference_pitch(
    engine: &mut Engine,
    note_input: Option<usize>,
    roles: &[InputRole],
) -> Option<f64> {
    let k = note_input?;
    if engine.info().num_outputs() == 0 {
        return None;
    }
    if let Some(f) = engine.reference_pitch(k + 1, 1).filter(|f| *f > 0.0) {
        return Some(f);
    }
    estimate_pitch(engine, note_input, roles)
}

/// Time the macro units may take while a model is prepared; slots left when it runs out read
/// as values.
const UNITS_BUDGET_S: f64 = 0.25;

/// The unit of every macro slot ([`super::units`]): frequencies and decays of the reference
/// mode (the strongest from the note input, or `@in1`, to `@out1`) come from the dense modal
/// analysis, for models up to [`crate::modes::DENSE_LIMIT`] points, within
/// [`UNITS_BUDGET_S`].
fn macro_units(
    engine: &mut Engine,
    macros: &[Option<MacroBinding>],
    note_input: Option<usize>,
) -> Vec<MacroUnit> {
    // The reference mode is measured by the dense analysis only, and needs an output.
    let measurable =
        engine.info().num_points <= crate::modes::DENSE_LIMIT && engine.info().num_outputs() > 0;
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
                if !measurable || started.elapsed().as_secs_f64() > UNITS_BUDGET_S {
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
    /// (`host_in`, indexed as [`super::host::channel`] numbers them). Each model input takes
    /// the channel its `~route` names, else the next of `order`; a position input receives
    /// its rest + signal × `position`, a force input signal × `force` ×
    /// [`Prepared::force_scale`], an audio-rate parameter the raw signal (the engine adds its
    /// declared default). An unfed input holds its rest.
    pub fn fill_inputs(
        &mut self,
        host_in: &[[f64; CHUNK]],
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
            match source
                .and_then(super::host::channel)
                .and_then(|c| host_in.get(c))
            {
                Some(channel) if gain != 0.0 => {
                    for (d, s) in dst.iter_mut().zip(&channel[..len]) {
                        *d = rest + s * gain;
                    }
                }
                _ => dst.fill(rest),
            }
        }
    }

    /// Plays `voices` notes at once: 1 is the monophonic instrument (a note retunes and strikes
    /// the one model); more make a voice bank of copies of the model. Allocates: call it off
    /// the audio thread.
    pub fn set_voices(&mut self, voices: usize) {
        self.bank = (voices > 1).then(|| {
            VoiceBank::new(
                &self.engine,
                self.roles.len(),
                self.num_outputs,
                voices,
                self.sample_rate,
            )
        });
    }

    /// The script's `~pressure` input and the amount full pressure adds to it, in the
    /// input's units after the host gains: × Force Gain (and the force rate scale) for a
    /// force input, × Position Gain for a position input.
    pub fn pressure_gain(&self, force: f64, position: f64) -> Option<(usize, f64)> {
        let k = self.settings.pressure_input? as usize;
        let scale = self.settings.pressure_scale;
        let gain = match self.roles.get(k)? {
            InputRole::Force => scale * force * self.force_scale,
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
        self.settings.note_force * self.strike_scale * force
    }

    /// Adds a one-sample strike of `velocity` (0 … 1) to the note input at `frame` of the
    /// chunk being filled (`len` samples): the script's note force × the rate scale ×
    /// `force` (the Force gain).
    pub fn strike(&mut self, frame: usize, len: usize, velocity: f64, force: f64) {
        if let Some(k) = self.note_input {
            self.inputs[k * len + frame] +=
                self.settings.note_force * self.strike_scale * velocity * force;
        }
    }
}
