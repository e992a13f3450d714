#![allow(missing_debug_implementations)] // nice-plug parameter and plugin types have no Debug.

//! Ressort as a CLAP and VST3 plugin and a standalone application.
//!
//! The audio thread runs the engine of `ressort-engine` in chunks of [`model::CHUNK`]
//! samples. Models are prepared elsewhere ([`model::ModelStore`]) and arrive through a
//! lock-free channel; the plugin crossfades from the old model to the new one and hands the
//! old one back to be freed off the audio thread. Host gains (Stiffness, Damping, Tune, MIDI
//! pitch) are clamped to what the model's stability analysis allows.

use model::{ModelStore, Prepared, CHUNK, NUM_MACROS};
use nice_plug::prelude::*;
use ressort_engine::ScaleClass;
use std::num::NonZeroU32;
use std::sync::atomic::Ordering;
use std::sync::Arc;

pub mod dsp;
pub mod editor;
pub mod envelope;
pub mod host;
pub mod macros;
pub mod model;
pub mod motion;
pub mod param_text;
pub mod params;
pub mod plot;
pub mod presets;
pub mod report;
pub mod runtime;

use dsp::{db_to_gain, output_sample, soft_ceiling, tuning_gain, ChunkSmoother, DcBlocker};
use params::RessortParams;
use report::{HostLink, MainThreadTask};
use runtime::RuntimeStatus;

/// Length of the crossfade from a replaced model to the new one.
const SWAP_FADE_MS: f64 = 20.0;
/// Time for the output to fade back in after the guard reset an exploding model.
const GUARD_FADE_MS: f64 = 50.0;
/// Output and input below this count as silence for the host's sleep decision (−120 dBFS).
const QUIET_LEVEL: f64 = 1e-6;
/// Smoothing time constant of the physical controls.
const CONTROL_SMOOTHING_MS: f64 = 15.0;
/// Smoothing time constant of the gains.
const GAIN_SMOOTHING_MS: f64 = 5.0;
/// Stiffness, Damping, Tune, the three gains and the macros.
const CONTROL_COUNT: usize = 6 + NUM_MACROS;
/// Interval of the editor's repeated strike (Audition).
const AUDITION_INTERVAL_S: f64 = 1.0;
/// Velocity of the editor's strikes.
const AUDITION_VELOCITY: f64 = 0.8;
/// The Stiffness gain that Damping can never take away through the stability clamp: the
/// model's own stiffness.
const KEPT_STIFFNESS_GAIN: f64 = 1.0;

pub struct Ressort {
    params: Arc<RessortParams>,
    store: Arc<ModelStore>,
    editor_state: Arc<nice_plug_egui::EguiEditorState>,
    /// The editor's context, to show guard trips to the host.
    host_link: Arc<HostLink>,
    /// A guard trip waits to be reported to the host at the end of the block.
    report_trip: bool,
    /// Samples until the next Audition strike.
    audition_left: u64,
    sample_rate: f64,
    has_main_input: bool,
    current: Option<Box<Prepared>>,
    /// The model being faded out, and the samples left of the fade.
    outgoing: Option<Box<Prepared>>,
    fade_left: usize,
    fade_len: usize,
    /// Models waiting to go back to the store when its return channel was full.
    held: [Option<Box<Prepared>>; 2],
    stiffness: ChunkSmoother,
    damping: ChunkSmoother,
    tune: ChunkSmoother,
    force_gain: ChunkSmoother,
    position_gain: ChunkSmoother,
    output_gain: ChunkSmoother,
    macros: [ChunkSmoother; NUM_MACROS],
    /// Output gain where the current chunk's per-sample ramp starts.
    last_output_gain: f64,
    /// Length of the current chunk and the samples of it already rendered. A chunk runs to
    /// the next multiple of CHUNK (counted from activation), so the sound does not depend
    /// on the host's block size; automation starts a new chunk at its own sample.
    chunk_len: usize,
    chunk_done: usize,
    /// The parameter values the smoothers were last given, to notice automation.
    last_targets: [f32; CONTROL_COUNT],
    dc: [DcBlocker; 2],
    /// Fade-in after a guard reset: current gain and step per sample.
    guard_gain: f64,
    guard_step: f64,
    /// Semitones from the reference key of the last note, and the pitch bend.
    note_semitones: f64,
    bend_semitones: f64,
    pending_event: Option<NoteEvent<()>>,
    /// Samples since activation: chunk boundaries are multiples of CHUNK.
    counter: u64,
    quiet_samples: u64,
    /// A strike from the editor waits for the next chunk.
    pending_strike: bool,
    host_in: [[f64; CHUNK]; 4],
}

/// How `ressort-standalone` starts: its `--model` and `--audition` options.
#[derive(Clone, Debug, Default)]
pub struct StandaloneStart {
    pub model: Option<model::ModelState>,
    pub audition: bool,
}

static STANDALONE_START: std::sync::OnceLock<StandaloneStart> = std::sync::OnceLock::new();

/// Sets how the instances of this process start; called once by `ressort-standalone` before
/// it creates the plugin. Plugin hosts never call it.
pub fn set_standalone_start(start: StandaloneStart) {
    let _ = STANDALONE_START.set(start);
}

impl Default for Ressort {
    fn default() -> Self {
        let store = Arc::new(ModelStore::default());
        if let Some(start) = STANDALONE_START.get() {
            if let Some(model) = &start.model {
                // Checked now; compiled at activation. A bad script keeps the default model
                // and its diagnostics show in the editor.
                let _ = store.submit(model.clone());
            }
            store
                .runtime
                .audition
                .store(start.audition, Ordering::Release);
        }
        let params = Arc::new(RessortParams::new(store.clone()));
        Ressort {
            params,
            store,
            editor_state: editor::default_state(),
            host_link: Arc::new(HostLink::default()),
            report_trip: false,
            audition_left: 0,
            sample_rate: 48_000.0,
            has_main_input: false,
            current: None,
            outgoing: None,
            fade_left: 0,
            fade_len: 1,
            held: [None, None],
            stiffness: ChunkSmoother::default(),
            damping: ChunkSmoother::default(),
            tune: ChunkSmoother::default(),
            force_gain: ChunkSmoother::default(),
            position_gain: ChunkSmoother::default(),
            output_gain: ChunkSmoother::default(),
            macros: [ChunkSmoother::default(); NUM_MACROS],
            last_output_gain: 0.0,
            chunk_len: 0,
            chunk_done: 0,
            last_targets: [0.0; CONTROL_COUNT],
            dc: [DcBlocker::default(); 2],
            guard_gain: 1.0,
            guard_step: 0.0,
            note_semitones: 0.0,
            bend_semitones: 0.0,
            pending_event: None,
            counter: 0,
            quiet_samples: 0,
            pending_strike: false,
            host_in: [[0.0; CHUNK]; 4],
        }
    }
}

impl Ressort {
    /// The model store shared with the editor.
    pub fn store(&self) -> &Arc<ModelStore> {
        &self.store
    }

    fn runtime(&self) -> &RuntimeStatus {
        &self.store.runtime
    }

    /// Puts every smoother on its target and clears the filters: a fresh start.
    fn snap_controls(&mut self) {
        let sr = self.sample_rate;
        let p = &self.params;
        self.stiffness =
            ChunkSmoother::new(sr, CHUNK, CONTROL_SMOOTHING_MS, p.stiffness.value() as f64);
        self.damping =
            ChunkSmoother::new(sr, CHUNK, CONTROL_SMOOTHING_MS, p.damping.value() as f64);
        self.tune = ChunkSmoother::new(sr, CHUNK, CONTROL_SMOOTHING_MS, p.tune.value() as f64);
        self.force_gain = ChunkSmoother::new(
            sr,
            CHUNK,
            GAIN_SMOOTHING_MS,
            db_to_gain(p.force_gain.value() as f64),
        );
        self.position_gain = ChunkSmoother::new(
            sr,
            CHUNK,
            GAIN_SMOOTHING_MS,
            db_to_gain(p.position_gain.value() as f64),
        );
        self.output_gain = ChunkSmoother::new(
            sr,
            CHUNK,
            GAIN_SMOOTHING_MS,
            db_to_gain(p.output_gain.value() as f64),
        );
        self.last_output_gain = self.output_gain.value;
        for (s, m) in self.macros.iter_mut().zip(&p.macros) {
            *s = ChunkSmoother::new(sr, CHUNK, CONTROL_SMOOTHING_MS, m.value.value() as f64);
        }
        self.dc = [DcBlocker::new(sr); 2];
        self.guard_gain = 1.0;
        self.guard_step = 0.0;
        self.counter = 0;
        self.chunk_len = 0;
        self.chunk_done = 0;
        self.last_targets = self.targets();
        self.quiet_samples = 0;
        self.pending_event = None;
    }

    /// Returns a model to the store, or keeps it for a later try. Realtime-safe.
    fn recycle(&mut self, prepared: Box<Prepared>) {
        if let Err(back) = self.store.recycle(prepared) {
            if let Some(slot) = self.held.iter_mut().find(|s| s.is_none()) {
                *slot = Some(back);
            } else {
                // Both holding slots are taken and the return channel is full: keep the model
                // alive rather than free it here.
                std::mem::forget(back);
            }
        }
    }

    /// Picks up a new model from the store and starts the crossfade. Realtime-safe.
    fn receive_models(&mut self) {
        for i in 0..self.held.len() {
            if let Some(p) = self.held[i].take() {
                if let Err(back) = self.store.recycle(p) {
                    self.held[i] = Some(back);
                }
            }
        }
        let Some(new) = self.store.receive() else {
            return;
        };
        if new.sample_rate != self.sample_rate {
            self.recycle(new);
            return;
        }
        if let Some(old) = self.outgoing.take() {
            self.recycle(old);
        }
        self.outgoing = self.current.replace(new);
        self.fade_len = ((SWAP_FADE_MS * 1e-3 * self.sample_rate) as usize).max(1);
        self.fade_left = if self.outgoing.is_some() {
            self.fade_len
        } else {
            0
        };
        self.runtime()
            .running_generation
            .fetch_add(1, Ordering::AcqRel);
        // The new model's gains and macros are set before its first sample.
        self.apply_controls(None);
    }

    /// The current values of the smoothed parameters.
    fn targets(&self) -> [f32; CONTROL_COUNT] {
        let p = &self.params;
        let mut t = [0.0; CONTROL_COUNT];
        t[0] = p.stiffness.value();
        t[1] = p.damping.value();
        t[2] = p.tune.value();
        t[3] = p.force_gain.value();
        t[4] = p.position_gain.value();
        t[5] = p.output_gain.value();
        for (v, m) in t[6..].iter_mut().zip(&p.macros) {
            *v = m.value.value();
        }
        t
    }

    /// Advances the control smoothers by `advance` samples (the length of the chunk that
    /// starts) and applies the gains and macros to the running model, clamped by its
    /// stability envelope.
    fn apply_controls(&mut self, advance: Option<usize>) {
        let p = &self.params;
        let (st, dz, tune) = match advance {
            Some(n) => (
                self.stiffness.advance(n, p.stiffness.value() as f64),
                self.damping.advance(n, p.damping.value() as f64),
                self.tune
                    .advance(n, p.tune.value() as f64 + self.bend_semitones),
            ),
            None => (self.stiffness.value, self.damping.value, self.tune.value),
        };
        if let Some(n) = advance {
            self.force_gain
                .advance(n, db_to_gain(p.force_gain.value() as f64));
            self.position_gain
                .advance(n, db_to_gain(p.position_gain.value() as f64));
            self.output_gain
                .advance(n, db_to_gain(p.output_gain.value() as f64));
            for (s, m) in self.macros.iter_mut().zip(&p.macros) {
                s.advance(n, m.value.value() as f64);
            }
        }
        let Some(model) = self.current.as_mut() else {
            return;
        };
        let semitones = tune + self.note_semitones;
        let tuning = tuning_gain(
            semitones,
            model.settings.reference_pitch_hz,
            self.sample_rate,
        );
        let requested_k = 2f64.powf(st) * tuning;
        let requested_z = 2f64.powf(dz);
        let mut moved = [(&model.envelope, 0.0); NUM_MACROS];
        let mut n_moved = 0;
        for (slot, (binding, envs)) in model.macros.iter().zip(&model.macro_envelopes).enumerate() {
            if let (Some(b), Some((low, high))) = (binding, envs) {
                let v = b.value_at(self.macros[slot].value);
                let (env, f) = if v > b.default && b.max > b.default {
                    (high, (v - b.default) / (b.max - b.default))
                } else if v < b.default && b.min < b.default {
                    (low, (b.default - v) / (b.default - b.min))
                } else {
                    continue;
                };
                moved[n_moved] = (env, f.clamp(0.0, 1.0));
                n_moved += 1;
            }
        }
        let (gk, gz, clamped) = model.envelope.clamp_moved(
            requested_k,
            requested_z,
            KEPT_STIFFNESS_GAIN,
            &moved[..n_moved],
        );
        model.engine.set_class_gain(ScaleClass::Stiffness, gk);
        model.engine.set_class_gain(ScaleClass::Damping, gz);
        for (slot, binding) in model.macros.iter().enumerate() {
            if let Some(b) = binding {
                let _ = model
                    .engine
                    .set_param(b.param, b.value_at(self.macros[slot].value));
            }
        }
        let rt = &self.store.runtime;
        rt.stiffness_gain.store(gk, Ordering::Relaxed);
        rt.damping_gain.store(gz, Ordering::Relaxed);
        rt.requested_stiffness_gain
            .store(requested_k, Ordering::Relaxed);
        rt.requested_damping_gain
            .store(requested_z, Ordering::Relaxed);
        rt.clamped.store(clamped, Ordering::Relaxed);
    }

    /// Handles the note events that fall before `end` (samples from the buffer start): note
    /// impulses go into the model's note input at their exact sample. Returns true when the
    /// pitch changed.
    fn handle_events(
        &mut self,
        context: &mut impl ProcessContext<Self>,
        start: usize,
        len: usize,
    ) -> bool {
        let mut retuned = false;
        loop {
            let event = match self.pending_event.take() {
                Some(e) => e,
                None => match context.next_event() {
                    Some(e) => e,
                    None => break,
                },
            };
            let timing = event.timing() as usize;
            if timing >= start + len {
                self.pending_event = Some(event);
                break;
            }
            let frame = timing.saturating_sub(start).min(len - 1);
            match event {
                NoteEvent::NoteOn { key, velocity, .. } => {
                    let Some(note) = key.number() else {
                        continue;
                    };
                    let Some(model) = self.current.as_mut() else {
                        continue;
                    };
                    self.note_semitones = note as f64 - model.settings.reference_key;
                    retuned = true;
                    if let Some(k) = model.note_input {
                        let force = model.settings.note_force
                            * model.strike_scale
                            * velocity.clamp(0.0, 1.0) as f64
                            * self.force_gain.value;
                        model.inputs[k * len + frame] += force;
                    }
                }
                NoteEvent::MidiPitchBend { value, .. } => {
                    let v = if value.is_finite() {
                        value.clamp(0.0, 1.0)
                    } else {
                        0.5
                    };
                    self.bend_semitones = (v as f64 - 0.5) * 4.0;
                }
                _ => {}
            }
        }
        retuned
    }

    /// Puts the model back at rest and fades the output back in.
    fn restart_model(&mut self) {
        if let Some(model) = self.current.as_mut() {
            model.engine.reset();
        }
        self.dc.iter_mut().for_each(DcBlocker::reset);
        self.guard_gain = 0.0;
        self.guard_step = 1.0 / (GUARD_FADE_MS * 1e-3 * self.sample_rate).max(1.0);
    }

    /// The editor's requests: reset the model, strike it once or repeatedly. Realtime-safe.
    fn editor_requests(&mut self) {
        if self
            .store
            .runtime
            .reset_requested
            .swap(false, Ordering::AcqRel)
        {
            self.store
                .runtime
                .guard_active
                .store(false, Ordering::Release);
            self.restart_model();
        }
        let rt = &self.store.runtime;
        let mut strike = rt.strike_requested.swap(false, Ordering::AcqRel);
        if rt.audition.load(Ordering::Acquire) {
            if self.audition_left == 0 {
                strike = true;
                self.audition_left = (AUDITION_INTERVAL_S * self.sample_rate) as u64;
            }
        } else {
            self.audition_left = 0;
        }
        self.pending_strike |= strike;
    }

    /// The guard reset the model: count it, raise the flag, fade back in.
    fn guard_tripped(&mut self) {
        self.restart_model();
        // Atomics, and at most one main-thread task per episode (CLAP only; see `report`).
        // Never `execute_background`: nice-plug 0.4.2's shared background worker exits when
        // it runs a task of an instance that is gone, and the next instance's destruction
        // then aborts the host.
        let rt = &self.store.runtime;
        rt.guard_trips.fetch_add(1, Ordering::AcqRel);
        // One report per episode: an exploding model trips in every chunk.
        if !rt.guard_active.swap(true, Ordering::AcqRel) {
            self.report_trip = true;
        }
    }
}

/// Copies host samples from `start` into `dst` as f64 ([`dsp::input_sample`]: non-finite and
/// subnormal samples read 0); samples past the channel's end read 0.
#[inline]
fn read_channel(dst: &mut [f64], src: &[f32], start: usize) {
    let src = src.get(start..).unwrap_or(&[]);
    for (i, d) in dst.iter_mut().enumerate() {
        *d = src.get(i).copied().map_or(0.0, dsp::input_sample);
    }
}

impl Plugin for Ressort {
    const NAME: &'static str = "Ressort";
    const VENDOR: &'static str = "Ressort";
    const URL: &'static str = "https://ressort.audio";
    const EMAIL: &'static str = "info@ressort.audio";
    const VERSION: &'static str = env!("CARGO_PKG_VERSION");

    const AUDIO_IO_LAYOUTS: &'static [AudioIOLayout] = &[
        // Instrument: stereo out, stereo sidechain in.
        AudioIOLayout {
            main_input_channels: None,
            main_output_channels: NonZeroU32::new(2),
            aux_input_ports: &[new_nonzero_u32(2)],
            aux_output_ports: &[],
            names: PortNames {
                layout: Some("Instrument with sidechain"),
                main_input: None,
                main_output: Some("Output"),
                aux_inputs: &["Sidechain"],
                aux_outputs: &[],
            },
        },
        // Effect: stereo in and out, stereo sidechain in.
        AudioIOLayout {
            main_input_channels: NonZeroU32::new(2),
            main_output_channels: NonZeroU32::new(2),
            aux_input_ports: &[new_nonzero_u32(2)],
            aux_output_ports: &[],
            names: PortNames {
                layout: Some("Effect with sidechain"),
                main_input: Some("Input"),
                main_output: Some("Output"),
                aux_inputs: &["Sidechain"],
                aux_outputs: &[],
            },
        },
        // Effect without a sidechain: lets a host that feeds only the main bus switch the
        // sidechain off (pedalboard does when it can).
        AudioIOLayout {
            main_input_channels: NonZeroU32::new(2),
            main_output_channels: NonZeroU32::new(2),
            aux_input_ports: &[],
            aux_output_ports: &[],
            names: PortNames {
                layout: Some("Effect"),
                main_input: Some("Input"),
                main_output: Some("Output"),
                aux_inputs: &[],
                aux_outputs: &[],
            },
        },
    ];

    const MIDI_INPUT: MidiConfig = MidiConfig::MidiCCs;
    const SAMPLE_ACCURATE_AUTOMATION: bool = true;

    type SysExMessage = ();
    type BackgroundTask = MainThreadTask;
    type Editor = nice_plug_egui::EguiEditor<editor::EditorApp>;

    fn params(&self) -> Arc<dyn Params> {
        self.params.clone()
    }

    fn editor(&mut self, _async_executor: AsyncExecutor<Self>) -> Option<Self::Editor> {
        editor::create(
            self.params.clone(),
            self.store.clone(),
            self.editor_state.clone(),
            self.host_link.clone(),
        )
    }

    fn task_executor(&mut self) -> TaskExecutor<Self> {
        let params = self.params.clone();
        let link = self.host_link.clone();
        Box::new(move |task| match task {
            MainThreadTask::ReportGuardTrip => link.set_guard(&params, true),
        })
    }

    fn activate(
        &mut self,
        audio_io_layout: &AudioIOLayout,
        buffer_config: &BufferConfig,
        _context: &mut impl ActivateContext<Self>,
    ) -> bool {
        let sr = buffer_config.sample_rate as f64;
        if !(sr.is_finite() && (1.0..=1e7).contains(&sr)) {
            return false;
        }
        self.sample_rate = sr;
        self.has_main_input = audio_io_layout.main_input_channels.is_some();
        self.outgoing = None;
        self.held = [None, None];
        self.current = self.store.activate(sr);
        if self.current.is_none() {
            return false;
        }
        self.snap_controls();
        self.apply_controls(None);
        true
    }

    fn reset(&mut self) {
        if let Some(model) = self.current.as_mut() {
            model.engine.reset();
        }
        if let Some(old) = self.outgoing.take() {
            self.recycle(old);
        }
        self.fade_left = 0;
        self.note_semitones = 0.0;
        self.bend_semitones = 0.0;
        self.snap_controls();
        self.apply_controls(None);
    }

    fn deactivate(&mut self) {
        self.current = None;
        self.outgoing = None;
        self.held = [None, None];
        self.store.deactivate();
    }

    fn process(
        &mut self,
        buffer: &mut Buffer,
        aux: &mut AuxiliaryBuffers,
        context: &mut impl ProcessContext<Self>,
    ) -> ProcessStatus {
        let started = std::time::Instant::now();
        self.receive_models();
        self.editor_requests();
        let editor_open = self.editor_state.is_open();
        let frames = buffer.samples();
        let order = host::default_order(self.has_main_input);
        // nice-plug starts a process() call at every automation event (sample-accurate
        // automation), so a changed parameter starts a new chunk exactly at its sample.
        let targets = self.targets();
        let mut automated = targets != self.last_targets;
        self.last_targets = targets;
        let mut loudest: f64 = 0.0;
        let mut pos = 0;
        while pos < frames {
            if self.chunk_done >= self.chunk_len || automated {
                automated = false;
                // The next ramp starts where this one got to: its end, or where automation
                // cut it.
                let g1 = self.output_gain.value;
                if self.chunk_done >= self.chunk_len {
                    self.last_output_gain = g1;
                } else {
                    self.last_output_gain += (g1 - self.last_output_gain) * self.chunk_done as f64
                        / self.chunk_len as f64;
                }
                // To the next grid point: chunks realign to multiples of CHUNK.
                self.chunk_len = CHUNK - (self.counter % CHUNK as u64) as usize;
                self.chunk_done = 0;
                self.apply_controls(Some(self.chunk_len));
            }
            let len = (self.chunk_len - self.chunk_done).min(frames - pos);

            // Host channels for this chunk: main input (in place in `buffer`), sidechain.
            for row in self.host_in.iter_mut() {
                row[..len].fill(0.0);
            }
            if self.has_main_input {
                for (c, ch) in buffer.as_slice_immutable().iter().take(2).enumerate() {
                    read_channel(&mut self.host_in[c][..len], ch, pos);
                }
            }
            if let Some(sc) = aux.inputs.first() {
                for (c, ch) in sc.as_slice_immutable().iter().take(2).enumerate() {
                    read_channel(&mut self.host_in[2 + c][..len], ch, pos);
                }
            }
            for row in &self.host_in {
                for s in &row[..len] {
                    loudest = loudest.max(s.abs());
                }
            }

            let (force, position) = (self.force_gain.value, self.position_gain.value);
            if let Some(model) = self.current.as_mut() {
                model.fill_inputs(&self.host_in, order, len, force, position);
            }
            if self.handle_events(context, pos, len) {
                self.apply_controls(None);
            }
            if self.pending_strike {
                self.pending_strike = false;
                if let Some(model) = self.current.as_mut() {
                    if let Some(k) = model.note_input {
                        model.inputs[k * len] += model.settings.note_force
                            * model.strike_scale
                            * AUDITION_VELOCITY
                            * force;
                    }
                }
            }
            self.audition_left = self.audition_left.saturating_sub(len as u64);

            let mut tripped = false;
            if let Some(model) = self.current.as_mut() {
                let n_in = model.roles.len();
                let n_out = model.outputs.len() / CHUNK;
                let report = model.engine.process(
                    len,
                    &model.inputs[..n_in * len],
                    &mut model.outputs[..n_out * len],
                );
                tripped |= report.tripped;
                model
                    .motion
                    .tick(len, model.engine.positions(), editor_open);
            }
            if let Some(old) = self.outgoing.as_mut() {
                let n_in = old.roles.len();
                let n_out = old.outputs.len() / CHUNK;
                old.inputs[..n_in * len].fill(0.0);
                old.engine.process(
                    len,
                    &old.inputs[..n_in * len],
                    &mut old.outputs[..n_out * len],
                );
            }

            // Output stage: the gain ramps across the chunk, whatever the host's blocks.
            let g0 = self.last_output_gain;
            let g1 = self.output_gain.value;
            let (done, chunk_len) = (self.chunk_done as f64, self.chunk_len as f64);
            let dc_on = self.params.dc_filter.value();
            let out = buffer.as_slice();
            for i in 0..len {
                let pick = |m: &Prepared| -> (f64, f64) {
                    if m.num_outputs == 0 {
                        return (0.0, 0.0);
                    }
                    let l = m.outputs[i];
                    let r = if m.num_outputs >= 2 {
                        m.outputs[len + i]
                    } else {
                        l
                    };
                    (l, r)
                };
                let (mut l, mut r) = self.current.as_deref().map(pick).unwrap_or((0.0, 0.0));
                if self.fade_left > 0 {
                    if let Some(old) = self.outgoing.as_deref() {
                        let (ol, or) = pick(old);
                        let t = self.fade_left as f64 / self.fade_len as f64;
                        l = l * (1.0 - t) + ol * t;
                        r = r * (1.0 - t) + or * t;
                    }
                    self.fade_left -= 1;
                }
                let g = g0 + (g1 - g0) * (done + (i + 1) as f64) / chunk_len;
                l *= g;
                r *= g;
                if dc_on {
                    l = self.dc[0].process(l);
                    r = self.dc[1].process(r);
                }
                if !(l.is_finite() && r.is_finite()) {
                    tripped = true;
                    l = 0.0;
                    r = 0.0;
                }
                if self.guard_gain < 1.0 {
                    l *= self.guard_gain;
                    r *= self.guard_gain;
                    self.guard_gain = (self.guard_gain + self.guard_step).min(1.0);
                }
                let (l, r) = (soft_ceiling(l), soft_ceiling(r));
                loudest = loudest.max(l.abs()).max(r.abs());
                if let Some(ch) = out.get_mut(0) {
                    ch[pos + i] = output_sample(l);
                }
                if let Some(ch) = out.get_mut(1) {
                    ch[pos + i] = output_sample(r);
                }
                if tripped {
                    // Silence the rest of this chunk; the guard fade starts at the next one.
                    self.guard_gain = 0.0;
                }
            }
            if self.fade_left == 0 {
                if let Some(old) = self.outgoing.take() {
                    self.recycle(old);
                }
            }
            if tripped {
                self.guard_tripped();
            }
            pos += len;
            self.counter += len as u64;
            self.chunk_done += len;
        }
        if std::mem::take(&mut self.report_trip)
            && context.plugin_api() == PluginApi::Clap
            && self.host_link.is_attached()
        {
            context.execute_gui(MainThreadTask::ReportGuardTrip);
        }
        let rt = &self.store.runtime;
        let seconds = frames as f64 / self.sample_rate;
        if seconds > 0.0 {
            let load = started.elapsed().as_secs_f64() / seconds;
            let old = rt.cpu_load.load(Ordering::Relaxed);
            rt.cpu_load
                .store(old + 0.1 * (load - old), Ordering::Relaxed);
        }
        if loudest > QUIET_LEVEL || self.fade_left > 0 {
            self.quiet_samples = 0;
        } else {
            self.quiet_samples += frames as u64;
        }
        // Let the host sleep the plugin once input and output have been silent for a second.
        if self.quiet_samples as f64 > self.sample_rate {
            ProcessStatus::Normal
        } else {
            ProcessStatus::KeepAlive
        }
    }
}

impl ClapPlugin for Ressort {
    const CLAP_ID: &'static str = "audio.ressort.ressort";
    const CLAP_DESCRIPTION: Option<&'static str> =
        Some("Mass-interaction physical modelling: masses, springs, contacts, plucks and bows");
    const CLAP_MANUAL_URL: Option<&'static str> = None;
    const CLAP_SUPPORT_URL: Option<&'static str> = None;
    const CLAP_FEATURES: &'static [ClapFeature] = &[
        ClapFeature::Instrument,
        ClapFeature::Synthesizer,
        ClapFeature::AudioEffect,
        ClapFeature::Stereo,
    ];
}

impl Vst3Plugin for Ressort {
    const VST3_CLASS_ID: [u8; 16] = *b"RessortMassInter";
    const VST3_SUBCATEGORIES: &'static [Vst3SubCategory] = &[
        Vst3SubCategory::Instrument,
        Vst3SubCategory::Synth,
        Vst3SubCategory::Fx,
    ];
    /// VST3 delivers MIDI controllers as proxy parameters, one per controller and channel,
    /// and JUCE-based hosts list every one (2,080 for all of them). The plugin reads pitch
    /// bend (129) only; a controller it starts to read goes in this list.
    const VST3_MIDI_CONTROLLERS: &'static [u8] = &[129];
}

nice_export_clap!(Ressort);
nice_export_vst3!(Ressort);
