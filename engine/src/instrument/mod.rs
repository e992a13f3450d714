//! # The instrument: a compiled model played like a synthesizer
//!
//! What the plugin and `ressort render --as-plugin` both run, so that the command line
//! produces what a host hears. The pipeline of the crate continues here: text → spec →
//! compiled model ([`prepare`], off the audio thread) → [`Instrument::process`], a short
//! sequence of stages per span of samples:
//!
//! 1. **host inputs** ([`Prepared::fill_inputs`]): host channels → model inputs, with the
//!    Force and Position gains and the script's `~route`s;
//! 2. **events** ([`events`]): notes retune the model at their own sample (a new control
//!    chunk starts there) and strike its note input; pitch bend joins Tune;
//! 3. **controls** ([`controls`]): knobs smoothed per chunk and applied through the
//!    stability clamp;
//! 4. **the model** (and the one it replaces, during a 20 ms crossfade);
//! 5. **output stage** ([`output`]): gain ramp, DC filter, guard fade, soft ceiling, flush to
//!    zero.
//!
//! Control changes act on a grid of [`CHUNK`] samples counted from the start, so a render
//! does not depend on how a host cuts its blocks; automation (a [`Instrument::process`] call
//! whose controls differ from the previous one's) and notes start a chunk at their own
//! sample. Nothing here allocates, locks or does I/O after [`Instrument::new`].

pub mod analyses;
pub mod analysis;
pub mod controls;
pub mod dsp;
pub mod events;
pub mod exciters;
pub mod gains;
pub mod host;
pub mod level;
mod load;
pub mod macros;
pub mod meshes;
pub mod output;
pub mod pitch;
pub mod prepare;
mod refine;
pub mod saved_analyses;
pub mod trigger;
pub mod units;
pub mod vary;
pub mod voices;

pub use crate::analysis::envelope::{LoadLine, StabilityEnvelope, STABILITY_HEADROOM};
pub use analysis::{ModalModel, ModesAtControls};
pub use controls::Controls;
pub use events::{Event, Timed};
pub use gains::Gains;
pub use host::{HostSettings, InputRole, Rejected};
pub use load::{
    analyses_kept, prepare, prepare_analysed, prepare_analysed_at_pitch, prepare_provisional,
    prepare_with,
};
pub use macros::MacroBinding;
pub use prepare::{
    parse_script, peak_frequency, Conventions, Facts, Prepared, Watcher, PLACE_GLIDE_MS,
};

use crate::RouteSource;
use controls::{ClampView, Smoothed};
use events::Modulated;
use gains::{ControlsKey, TuneKey};
use output::{OutputStage, Span};
pub use vary::{vary, vary_playable, Variation, VaryScope};
pub use voices::{Drive, Ended, VoiceBank, VoiceState};

/// The engine runs in chunks of at most this many samples; gains and macros are updated at
/// chunk boundaries (counted from activation, so results do not depend on the host's block
/// size).
pub const CHUNK: usize = 16;

/// The number of generic macro slots.
pub const NUM_MACROS: usize = 16;

/// Host input channels the instrument reads: main left and right, then up to eight sidechain
/// channels ([`host::channel`]).
pub const MAX_HOST_INPUTS: usize = 10;

/// Host output channels the instrument writes: main left and right (`@out1`, `@out2`), then
/// `@out3` … `@out8` on auxiliary outputs.
pub const MAX_HOST_OUTPUTS: usize = 8;

/// The stability clamp's view of a prepared model `m`, borrowing only the fields it reads (so
/// its voice bank stays free to change).
macro_rules! clamp_view {
    ($m:expr) => {
        ClampView {
            reference_pitch_hz: $m.facts.settings.reference_pitch_hz,
            sample_rate: $m.facts.sample_rate,
            envelope: &$m.facts.envelope,
            macros: &$m.facts.macros,
            macro_envelopes: &$m.facts.macro_envelopes,
            macro_reference: &$m.facts.macro_reference,
        }
    };
}

/// Per-voice expression and controllers (see the module).
mod expression;
use expression::{tune_voice, SharedGains};

/// The host channels ([`host::channel`] numbering, as bits) that push the model: the ones
/// that feed its force and position inputs, by the script's `~route`s, else in `order`.
pub(crate) fn pushing_channels(m: &Prepared, order: &[RouteSource]) -> u16 {
    let mut mask = 0u16;
    for (k, role) in m.facts.roles.iter().enumerate() {
        if !matches!(role, InputRole::Force | InputRole::Position) {
            continue;
        }
        let source = m.facts.routing[k].or_else(|| order.get(k).copied());
        if let Some(c) = source.and_then(host::channel) {
            mask |= 1 << c;
        }
    }
    mask
}

/// The host channels ([`host::channel`] numbering, as bits) that feed any input of `m`.
pub(crate) fn fed_channels(m: &Prepared, order: &[RouteSource]) -> u16 {
    let mut mask = 0u16;
    for (k, role) in m.facts.roles.iter().enumerate() {
        if *role == InputRole::Unused {
            continue;
        }
        let source = m.facts.routing[k].or_else(|| order.get(k).copied());
        if let Some(c) = source.and_then(host::channel) {
            mask |= 1 << c;
        }
    }
    mask
}

/// The sidechain's first two channels: a trigger listens there even when they push nothing.
const SIDECHAIN_PAIR: u16 = 0b1100;

/// The sustain pedal's controller: it holds released voices.
pub const SUSTAIN_CC: u8 = 64;

/// Length of the crossfade from a replaced model to the new one.
pub const SWAP_FADE_MS: f64 = 20.0;

/// What one [`Instrument::process`] call did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BlockReport {
    /// How many times the guard reset the model (non-finite output or an engine trip), at
    /// most once per span.
    pub trips: u32,
    /// The loudest host input or output sample, to decide when the host may sleep.
    pub loudest: f64,
    /// A model crossfade is still running.
    pub fading: bool,
    /// The loudest sample of the host channels that push the model's force and position
    /// inputs (in trigger mode, with the sidechain's first pair): the editor's input meter.
    pub input_peak: f64,
    /// Strikes the sidechain trigger played.
    pub triggered: u32,
}

/// A model played by notes, knobs and host audio. See the module documentation.
#[derive(Debug)]
pub struct Instrument {
    sample_rate: f64,
    current: Option<Box<Prepared>>,
    /// The model being faded out, and the samples left of the fade.
    outgoing: Option<Box<Prepared>>,
    fade_left: usize,
    fade_len: usize,
    /// A model whose fade ended, waiting for [`Instrument::take_retired`].
    retired: Option<Box<Prepared>>,
    /// The current model's outputs were exactly 0 in the last span, with no voice sounding:
    /// a new model replaces it without a crossfade.
    current_silent: bool,
    controls: Controls,
    smoothed: Smoothed,
    gains: Gains,
    /// The gains of one tuning pass over the bank, by voice inputs (`expression::tune_voice`).
    shared_gains: SharedGains,
    /// Output gain where the current chunk's per-sample ramp starts.
    last_output_gain: f64,
    /// The glide of a provisional model's levels to its exact trims ([`Instrument::refine`]);
    /// exactly 1 otherwise.
    settle: refine::Settle,
    /// Length of the current chunk and the samples of it already rendered. A chunk runs to
    /// the next multiple of CHUNK (counted from the start, or from the host's song position;
    /// see [`Instrument::set_song_position`]), so the sound does not depend on the host's
    /// block size; automation and notes start a new chunk at their own sample.
    chunk_len: usize,
    chunk_done: usize,
    /// Samples since the start, or the song position: chunk boundaries are multiples of
    /// CHUNK.
    counter: u64,
    /// The song position at the next call's first sample, while the host's transport plays.
    song_position: Option<i64>,
    output: OutputStage,
    /// The key of the last note the one model played (its home key until then), and the
    /// pitch bend.
    note_key: Option<u8>,
    bend_st: f64,
    /// The one model's own note tuning (semitones) and pressure (0 … 1); with voices, the
    /// pressure that reaches the model itself (channel pressure without MPE).
    tuning_st: f64,
    /// What keeps the one model's sounding note at its pitch when its exact analyses move its
    /// reference key ([`Instrument::refine`]): the keys' move, in semitones, until the next
    /// note or model.
    kept_st: f64,
    pressure: f64,
    /// With MPE, each member channel's last bend (semitones) and pressure: a note takes its
    /// channel's values when it starts (controllers send them before the note-on).
    channel_bend: [f64; 16],
    channel_pressure: [f64; 16],
    /// The default host channel order for model inputs without a `~route`.
    order: &'static [RouteSource],
    /// Whether the model's watcher should publish (an open editor).
    watching: bool,
    /// The MIDI controller mapped to each macro slot.
    cc_map: [Option<u8>; NUM_MACROS],
    /// The macro positions the host last gave, and the ones a controller set since (they
    /// hold until the host's value moves).
    host_macros: [f64; NUM_MACROS],
    cc_macros: [Option<f64>; NUM_MACROS],
    host_in: [[f64; CHUNK]; MAX_HOST_INPUTS],
    /// The sidechain's onset detector (trigger mode).
    trigger: trigger::Trigger,
}

impl Instrument {
    /// An instrument at `sample_rate` with `controls` in place, playing nothing until
    /// [`Instrument::set_model`].
    pub fn new(sample_rate: f64, controls: Controls) -> Instrument {
        let controls = controls.sanitized();
        let smoothed = Smoothed::snapped(&controls, sample_rate);
        Instrument {
            sample_rate,
            current: None,
            outgoing: None,
            fade_left: 0,
            fade_len: 1,
            retired: None,
            current_silent: false,
            controls,
            last_output_gain: smoothed.output_gain.value,
            settle: refine::Settle::new(sample_rate),
            smoothed,
            gains: Gains::default(),
            shared_gains: SharedGains::new(),
            chunk_len: 0,
            chunk_done: 0,
            counter: 0,
            song_position: None,
            output: OutputStage::new(sample_rate),
            note_key: None,
            bend_st: 0.0,
            tuning_st: 0.0,
            kept_st: 0.0,
            pressure: 0.0,
            channel_bend: [0.0; 16],
            channel_pressure: [0.0; 16],
            order: host::default_order(false),
            watching: false,
            cc_map: [None; NUM_MACROS],
            host_macros: controls.macros,
            cc_macros: [None; NUM_MACROS],
            host_in: [[0.0; CHUNK]; MAX_HOST_INPUTS],
            trigger: trigger::Trigger::new(sample_rate),
        }
    }

    pub fn sample_rate(&self) -> f64 {
        self.sample_rate
    }

    /// Whether the host feeds a main input: model inputs without a `~route` then take main
    /// left and right first (the effect layouts), else the sidechain's channels.
    pub fn set_main_input(&mut self, present: bool) {
        self.order = host::default_order(present);
    }

    /// Whether someone watches the model's motion (the editor is open).
    pub fn set_watching(&mut self, watching: bool) {
        self.watching = watching;
    }

    /// The host's song position (in samples) at the first sample of the next
    /// [`Instrument::process`] call, while its transport plays; `None` when it is stopped or
    /// gives none. The control grid (chunks of [`CHUNK`] samples at which the smoothed
    /// controls step) is then anchored to the song: a grid point falls on every multiple of
    /// CHUNK of the song position. A bounce of the same project thus renders the same samples
    /// whenever the host activated the plugin and whatever its block sizes; without a song
    /// position the grid counts from activation. When the position jumps (a loop, a locate)
    /// off the grid, a chunk starts there, as at an automation point. Realtime-safe.
    pub fn set_song_position(&mut self, position: Option<i64>) {
        self.song_position = position;
    }

    /// Maps MIDI controllers to macro slots: a [`Event::Controller`] of a mapped number moves
    /// the slot. Realtime-safe.
    pub fn set_cc_map(&mut self, map: &[Option<u8>; NUM_MACROS]) {
        self.cc_map = *map;
    }

    /// The macro slot positions in use: the host's, or a controller's since.
    pub fn macros(&self) -> [f64; NUM_MACROS] {
        self.controls.macros
    }

    /// The running model.
    pub fn model(&self) -> Option<&Prepared> {
        self.current.as_deref()
    }

    /// The gains in use after the last chunk.
    pub fn gains(&self) -> Gains {
        self.gains
    }

    /// Plays `model` from now on, crossfading from the running one over [`SWAP_FADE_MS`]
    /// (at once when nothing ran, or when the running one is silent: its outputs exactly 0
    /// in the last span and no voice sounding, so that a fade would only run two models for
    /// nothing). Returns a model to free off the audio thread: the one that was still fading
    /// out, or the silent one replaced. Realtime-safe.
    pub fn set_model(&mut self, model: Box<Prepared>) -> Option<Box<Prepared>> {
        self.kept_st = 0.0;
        self.settle = refine::Settle::new(self.sample_rate);
        if self.current_silent {
            // The new model fades in from the silence over the same 20 ms, alone; a fade
            // still running (towards the silent model) goes on towards the new one.
            self.current_silent = false;
            let old = self.current.replace(model);
            if self.outgoing.is_none() {
                self.fade_len = ((SWAP_FADE_MS * 1e-3 * self.sample_rate) as usize).max(1);
                self.fade_left = self.fade_len;
            }
            self.apply();
            return old;
        }
        let stale = self.outgoing.take();
        self.outgoing = self.current.replace(model);
        self.fade_len = ((SWAP_FADE_MS * 1e-3 * self.sample_rate) as usize).max(1);
        self.fade_left = if self.outgoing.is_some() {
            self.fade_len
        } else {
            0
        };
        // The new model's gains and macros are set before its first sample.
        self.apply();
        stale
    }

    /// Takes every model out, for a host that deactivates.
    pub fn take_models(&mut self) -> [Option<Box<Prepared>>; 3] {
        [
            self.current.take(),
            self.outgoing.take(),
            self.retired.take(),
        ]
    }

    /// A model whose crossfade has ended, to free off the audio thread.
    pub fn take_retired(&mut self) -> Option<Box<Prepared>> {
        self.retired.take()
    }

    /// A fresh start: the model at rest, no fade, no note or bend, every smoother on
    /// `controls`, the chunk grid from 0. Returns the model that was fading out.
    pub fn reset(&mut self, controls: Controls) -> Option<Box<Prepared>> {
        if let Some(m) = self.current.as_mut() {
            m.engine.reset();
            m.rest_inputs();
            if let Some(bank) = m.bank.as_mut() {
                bank.clear();
            }
        }
        self.fade_left = 0;
        self.note_key = None;
        self.bend_st = 0.0;
        self.tuning_st = 0.0;
        self.kept_st = 0.0;
        self.pressure = 0.0;
        self.channel_bend = [0.0; 16];
        self.channel_pressure = [0.0; 16];
        self.controls = controls.sanitized();
        self.host_macros = self.controls.macros;
        self.cc_macros = [None; NUM_MACROS];
        self.smoothed = Smoothed::snapped(&self.controls, self.sample_rate);
        self.settle = refine::Settle::new(self.sample_rate);
        self.last_output_gain = self.smoothed.output_gain.value;
        self.output = OutputStage::new(self.sample_rate);
        self.counter = 0;
        self.chunk_len = 0;
        self.chunk_done = 0;
        self.trigger.reset();
        self.apply();
        self.outgoing.take()
    }

    /// Puts the model back at rest and fades the output back in (the guard, the editor's
    /// reset).
    pub fn restart(&mut self) {
        if let Some(m) = self.current.as_mut() {
            m.engine.reset();
            m.rest_inputs();
            if let Some(bank) = m.bank.as_mut() {
                bank.clear();
            }
        }
        self.output.restart(self.sample_rate);
    }

    /// Applies the smoothed controls to the running model: to its one engine, or to every
    /// voice with the voice's own note (and the Release damper once its key is up).
    fn apply(&mut self) {
        let Some(m) = self.current.as_deref_mut() else {
            return;
        };
        // The model itself, which the host's audio plays (with voices), sits at its home key.
        let home_st = m.home_key() - m.facts.settings.reference_key;
        let Some(bank) = m.bank.as_mut() else {
            let key = self.note_key.map_or(m.home_key(), f64::from);
            let note_st = key - m.facts.settings.reference_key;
            self.gains = self
                .smoothed
                .apply(m, note_st + self.tuning_st + self.kept_st);
            return;
        };
        let view = clamp_view!(m);
        let release = 16f64.powf(self.controls.release);
        let mut shown = self.smoothed.gains(&view, home_st, 1.0);
        self.smoothed.set(&mut m.engine, view.macros, &shown);
        let mut newest = 0;
        self.shared_gains.clear();
        let controls = self.smoothed.controls_key();
        for i in 0..bank.voices.len() {
            if bank.voices[i].state == VoiceState::Free {
                continue;
            }
            let g = tune_voice(
                &self.smoothed,
                &controls,
                &view,
                bank,
                i,
                release,
                &mut self.shared_gains,
            );
            if bank.voices[i].started > newest {
                newest = bank.voices[i].started;
                shown = g;
            }
        }
        self.gains = shown;
    }

    /// Voices sounding and the bank's size (1 and 1 without a bank).
    pub fn voice_count(&self) -> (usize, usize) {
        match self.current.as_deref().and_then(|m| m.bank.as_ref()) {
            Some(b) => (b.sounding(), b.limit),
            None => (1, 1),
        }
    }

    /// Hands over the voices that ended (freed themselves or were stolen) since the last call.
    pub fn drain_ended(&mut self, f: impl FnMut(Ended)) {
        if let Some(b) = self.current.as_deref_mut().and_then(|m| m.bank.as_mut()) {
            b.drain_ended(f);
        }
    }

    /// Starts a control chunk at the current sample: it runs to the next grid point. The
    /// smoothers advance by its length when `advance` (a grid point, or automation); a chunk
    /// that a note cuts only re-applies them with the new pitch, since they already stand at
    /// the grid point both chunks run to.
    fn start_chunk(&mut self, advance: bool) {
        // The next ramp starts where this one got to: its end, or where a cut left it.
        let g1 = self.smoothed.output_gain.value * self.settle.output.value;
        if self.chunk_done >= self.chunk_len {
            self.last_output_gain = g1;
        } else {
            self.last_output_gain +=
                (g1 - self.last_output_gain) * self.chunk_done as f64 / self.chunk_len as f64;
        }
        self.chunk_len = CHUNK - (self.counter % CHUNK as u64) as usize;
        self.chunk_done = 0;
        if advance {
            self.smoothed
                .advance(self.chunk_len, &self.controls, self.bend_st);
            self.settle.advance(self.chunk_len);
        }
        self.apply();
    }

    /// Renders `frames` samples. `host_in[c]` is host input channel c ([`host::channel`]
    /// numbering; `None` or short channels read silence, NaN and subnormal samples read 0);
    /// with `main_in_place`, channels 0 and 1 are read from `out[0]` and `out[1]` instead, a
    /// host's in-place main bus (each span's input is read before its output is written);
    /// `events` come in time order (`timing` < `frames`; late ones act at once); `out[c]` is
    /// host output channel c (0, 1: main left and right). `controls` hold for the whole
    /// call: a host cuts its blocks at automation points.
    pub fn process(
        &mut self,
        frames: usize,
        host_in: &[Option<&[f32]>],
        main_in_place: bool,
        events: &mut impl Iterator<Item = Timed>,
        controls: &Controls,
        out: &mut [&mut [f32]],
    ) -> BlockReport {
        let mut controls = controls.sanitized();
        // A slot a controller moved keeps the controller's value until the host moves it.
        for (i, m) in controls.macros.iter_mut().enumerate() {
            if *m != self.host_macros[i] {
                self.host_macros[i] = *m;
                self.cc_macros[i] = None;
            }
            if let Some(v) = self.cc_macros[i] {
                *m = v;
            }
        }
        let mut automated = controls != self.controls;
        self.controls = controls;
        // Off the song's grid: a new chunk starts here, on it.
        if let Some(p) = self.song_position.take().filter(|_| frames > 0) {
            let phase = p.rem_euclid(CHUNK as i64) as u64;
            if self.counter % CHUNK as u64 != phase {
                self.counter = phase;
                automated = true;
            }
        }
        let mut report = BlockReport::default();
        // The host channels that push the model: the input meter's, and with the sidechain's
        // pair, the trigger's.
        let pushing = self
            .current
            .as_deref()
            .map_or(0, |m| pushing_channels(m, self.order));
        let mask = if self.controls.trigger {
            pushing | SIDECHAIN_PAIR
        } else {
            pushing
        };
        let host_sample = |c: usize, n: usize| -> f64 {
            let src: Option<&[f32]> = if main_in_place && c < 2 {
                out.get(c).map(|s| &**s)
            } else {
                host_in.get(c).copied().flatten()
            };
            src.and_then(|s| s.get(n))
                .copied()
                .map_or(0.0, dsp::input_sample)
                .abs()
        };
        let level = |n: usize| -> f64 {
            let mut a: f64 = 0.0;
            for c in 0..MAX_HOST_INPUTS {
                if mask & (1 << c) != 0 {
                    a = a.max(host_sample(c, n));
                }
            }
            a
        };
        if mask != 0 {
            for n in 0..frames {
                report.input_peak = report.input_peak.max(level(n));
            }
        }
        let mut onsets = [Timed::new(0, Event::Strike { velocity: 0.0 }); trigger::MAX_ONSETS];
        let mut n_onsets = 0;
        if self.controls.trigger && mask != 0 {
            let found = self
                .trigger
                .scan(frames, self.controls.trigger_sensitivity_db, level);
            n_onsets = found.len();
            onsets[..n_onsets].copy_from_slice(found);
            report.triggered = n_onsets as u32;
        }
        let mut merged = trigger::Merge::new(events, &onsets[..n_onsets]);
        let events = &mut merged;
        // Events past the block's end act at its last sample.
        let at = |e: &Timed| (e.timing as usize).min(frames.saturating_sub(1));
        let mut next = events.next();
        let mut pos = 0;
        while pos < frames {
            // Events up to this sample: notes retune from here, strikes land here.
            let mut strike = 0.0;
            let mut retuned = false;
            while let Some(e) = next.filter(|e| at(e) <= pos) {
                match e.event {
                    Event::NoteOn {
                        note,
                        velocity,
                        channel,
                        voice_id,
                    } => {
                        let response =
                            events::velocity_response(velocity, self.controls.velocity_exponent);
                        if let Some(m) = self.current.as_deref_mut() {
                            let note_st = note as f64 - m.facts.settings.reference_key;
                            if let Some(bank) = m.bank.as_mut() {
                                // A voice of its own, tuned before its first sample.
                                let i = bank.note_on(note, channel, voice_id, note_st, response);
                                let c = channel as usize % 16;
                                if self.controls.mpe && c != 0 {
                                    bank.voices[i].bend_st = self.channel_bend[c];
                                    bank.voices[i].pressure = self.channel_pressure[c];
                                }
                                self.apply_voice(i);
                            } else {
                                self.note_key = Some(note);
                                self.kept_st = 0.0;
                                retuned = true;
                                strike += response;
                                // The one model's exciters follow the newest key.
                                m.held_note = Some((note, channel));
                                m.strike_hold = 0;
                                exciters::start(&mut m.gestures, &m.facts.exciters, response);
                            }
                        } else {
                            strike += response;
                        }
                    }
                    Event::NoteOff { note, channel, .. } => {
                        if let Some(m) = self.current.as_deref_mut() {
                            match m.bank.as_mut() {
                                Some(bank) => bank.note_off(note, channel),
                                None if m.held_note == Some((note, channel)) => m.held_note = None,
                                None => {}
                            }
                        }
                    }
                    Event::Strike { velocity } => {
                        let response = events::velocity_response(velocity, 1.0);
                        let bank = self.current.as_deref_mut().and_then(|m| {
                            let key = m.home_key().round().clamp(0.0, 127.0) as u8;
                            let note_st = key as f64 - m.facts.settings.reference_key;
                            m.bank.as_mut().map(|b| (b, key, note_st))
                        });
                        let hold = (exciters::STRIKE_HOLD_MS * 1e-3 * self.sample_rate) as u64;
                        match bank {
                            // With voices, a strike plays the reference key on a voice; its
                            // exciters hold for a moment, as a short note would.
                            Some((bank, key, note_st)) => {
                                let i = bank.note_on(key, 0, None, note_st, response);
                                bank.voices[i].strike_hold = hold.max(1);
                                self.apply_voice(i);
                            }
                            None => {
                                strike += response;
                                if let Some(m) = self.current.as_deref_mut() {
                                    if m.held_note.is_none() && !m.facts.exciters.is_empty() {
                                        m.strike_hold = hold.max(1);
                                        exciters::start(
                                            &mut m.gestures,
                                            &m.facts.exciters,
                                            response,
                                        );
                                    }
                                }
                            }
                        }
                    }
                    Event::PitchBend { value, channel } => {
                        if self.controls.mpe && channel != 0 {
                            retuned |= self.expression(e.event);
                        } else {
                            self.bend_st =
                                events::bend_semitones(value, self.controls.bend_range_st);
                        }
                    }
                    Event::Controller { cc, value } => {
                        automated |= self.controller(cc, value);
                    }
                    Event::Pressure { .. } | Event::Tuning { .. } | Event::Modulation { .. } => {
                        retuned |= self.expression(e.event);
                    }
                }
                next = events.next();
            }
            if automated || self.chunk_done >= self.chunk_len {
                automated = false;
                self.start_chunk(true);
            } else if retuned {
                self.start_chunk(false);
            }
            let mut len = (self.chunk_len - self.chunk_done).min(frames - pos);
            if let Some(e) = next.as_ref() {
                // The span ends at the next event, which then acts at its own sample.
                len = len.min(at(e).saturating_sub(pos).max(1));
            }
            if self.span(pos, len, (host_in, main_in_place), strike, out, &mut report) {
                report.trips += 1;
                self.restart();
            }
            pos += len;
            self.counter += len as u64;
            self.chunk_done += len;
        }
        // A call of zero frames: its events change the pitch state only.
        while let Some(e) = next {
            match e.event {
                Event::PitchBend { value, channel } if !(self.controls.mpe && channel != 0) => {
                    self.bend_st = events::bend_semitones(value, self.controls.bend_range_st);
                }
                Event::NoteOn { note, .. }
                    if self.current.as_deref().is_some_and(|m| m.bank.is_none()) =>
                {
                    self.note_key = Some(note);
                }
                Event::Controller { cc, value } => {
                    self.controller(cc, value);
                }
                _ => {}
            }
            next = events.next();
        }
        report.fading = self.fade_left > 0;
        report
    }

    /// One span of `len` samples at `pos` within one chunk: inputs, the models, the output
    /// stage. Returns whether the guard tripped.
    fn span(
        &mut self,
        pos: usize,
        len: usize,
        (host_in, main_in_place): (&[Option<&[f32]>], bool),
        strike: f64,
        out: &mut [&mut [f32]],
        report: &mut BlockReport,
    ) -> bool {
        // Host inputs.
        for (c, row) in self.host_in.iter_mut().enumerate() {
            let src: Option<&[f32]> = if main_in_place && c < 2 {
                out.get(c).map(|s| &**s)
            } else {
                host_in.get(c).copied().flatten()
            };
            let src = src.and_then(|s| s.get(pos..)).unwrap_or(&[]);
            if src.is_empty() {
                // A channel the host does not feed: silence, nothing to measure.
                row[..len].fill(0.0);
                continue;
            }
            for (i, d) in row[..len].iter_mut().enumerate() {
                *d = src.get(i).copied().map_or(0.0, dsp::input_sample);
                report.loudest = report.loudest.max(d.abs());
            }
        }
        let force = self.smoothed.force_gain.value * self.settle.input.value;
        let position = self.smoothed.position_gain.value * self.settle.input.value;
        let trigger = self.controls.trigger;
        let mut tripped = false;
        if let Some(m) = self.current.as_deref_mut() {
            let fed = m.fill_inputs(&self.host_in, self.order, len, force, position, trigger);
            m.awake |= fed || self.pressure != 0.0;
            let n_in = m.facts.roles.len();
            let n_out = m.outputs.len() / CHUNK;
            // Pressure: a sustained push on the script's `~pressure` input.
            let pressure = m.pressure_gain(force, position);
            if let Some((k, gain)) = pressure {
                let add = self.pressure * gain;
                if add != 0.0 {
                    m.inputs[k * len..(k + 1) * len]
                        .iter_mut()
                        .for_each(|x| *x += add);
                }
            }
            let strike_force = m.strike_force(force);
            let drive = Drive {
                note_input: m.facts.note_input,
                strike_force,
                pressure,
                exciters: &m.facts.exciters,
                force: force * m.facts.force_scale,
                rest_out: &m.facts.rest_out,
            };
            if let Some(bank) = m.bank.as_mut() {
                // The model itself keeps playing what the host feeds it (a sidechain strikes
                // it as without voices); notes play on voices of their own, which hear the
                // host's inputs too and their own strike. Until the host feeds it, it rests.
                if m.awake {
                    let r = m.engine.process(
                        len,
                        &m.inputs[..n_in * len],
                        &mut m.outputs[..n_out * len],
                    );
                    tripped |= r.tripped;
                } else {
                    for (c, &r) in m.facts.rest_out.iter().enumerate().take(n_out) {
                        m.outputs[c * len..(c + 1) * len].fill(r);
                    }
                }
                tripped |= bank.process(
                    len,
                    &m.inputs[..n_in * len],
                    &mut m.outputs[..n_out * len],
                    &drive,
                );
                bank.free_silent(len);
                if let Some(w) = m.watcher.as_mut() {
                    let axes = match bank.newest() {
                        Some(i) => bank.axes(i),
                        None => m.engine.axes(),
                    };
                    w.tick(len, axes, self.watching);
                }
            } else {
                if strike > 0.0 {
                    m.strike(0, len, strike, force);
                }
                if !m.facts.exciters.is_empty() {
                    let held = m.held_note.is_some() || m.strike_hold > 0;
                    m.strike_hold = m.strike_hold.saturating_sub(len as u64);
                    exciters::play(
                        &mut m.gestures,
                        &m.facts.exciters,
                        held,
                        self.pressure,
                        force * m.facts.force_scale,
                        &mut m.inputs[..n_in * len],
                        len,
                        1,
                        0,
                    );
                }
                // The model.
                let r =
                    m.engine
                        .process(len, &m.inputs[..n_in * len], &mut m.outputs[..n_out * len]);
                tripped |= r.tripped;
                if let Some(w) = m.watcher.as_mut() {
                    w.tick(len, m.engine.axes(), self.watching);
                }
            }
        }
        self.current_silent = self.current.as_deref().is_some_and(|m| {
            let n_out = m.outputs.len() / CHUNK;
            m.outputs[..n_out * len].iter().all(|&v| v == 0.0)
                && m.bank.as_ref().is_none_or(|b| b.sounding() == 0)
        });
        if let Some(old) = self.outgoing.as_deref_mut() {
            let n_in = old.facts.roles.len();
            let n_out = old.outputs.len() / CHUNK;
            old.inputs[..n_in * len].fill(0.0);
            old.engine.process(
                len,
                &old.inputs[..n_in * len],
                &mut old.outputs[..n_out * len],
            );
            if let Some(bank) = old.bank.as_mut() {
                let drive = Drive {
                    rest_out: &old.facts.rest_out,
                    ..Drive::NONE
                };
                bank.process(
                    len,
                    &old.inputs[..n_in * len],
                    &mut old.outputs[..n_out * len],
                    &drive,
                );
            }
        }
        // Output stage.
        let span = Span {
            len,
            g0: self.last_output_gain,
            g1: self.smoothed.output_gain.value * self.settle.output.value,
            done: self.chunk_done,
            chunk_len: self.chunk_len,
            dc_on: self.controls.dc_filter,
            tripped,
        };
        let (out_tripped, loudest) = self.output.render(
            span,
            self.current.as_deref(),
            self.outgoing.as_deref(),
            (&mut self.fade_left, self.fade_len),
            out,
            pos,
        );
        report.loudest = report.loudest.max(loudest);
        let tripped = out_tripped;
        if self.fade_left == 0 {
            if let Some(old) = self.outgoing.take() {
                // The plugin takes it after the block; a second one in the same block stays
                // in `outgoing` until then (it is silent: its fade is over).
                if self.retired.is_none() {
                    self.retired = Some(old);
                } else {
                    self.outgoing = Some(old);
                }
            }
        }
        tripped
    }
}
