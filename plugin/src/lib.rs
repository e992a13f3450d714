#![allow(missing_debug_implementations)] // nice-plug parameter and plugin types have no Debug.

//! Ressort as a CLAP and VST3 plugin and a standalone application.
//!
//! The audio thread runs the engine of `ressort-engine` in chunks of [`model::CHUNK`]
//! samples. Models are prepared elsewhere ([`model::ModelStore`]) and arrive through a
//! lock-free channel; the plugin crossfades from the old model to the new one and hands the
//! old one back to be freed off the audio thread. Host gains (Stiffness, Damping, Tune, MIDI
//! pitch) are clamped to what the model's stability analysis allows.

use model::{ModelStore, Prepared, Refinement};
use nice_plug::midi::{Channel, Key, VoiceID};
use nice_plug::prelude::*;
use ressort_engine::instrument::events::Modulated;
use ressort_engine::instrument::{
    Controls, Event, Instrument, Timed, MAX_HOST_INPUTS, MAX_HOST_OUTPUTS,
};
use std::num::NonZeroU32;
use std::sync::atomic::Ordering;
use std::sync::Arc;

pub mod clap_presets;
pub mod editor;
pub mod files;
#[cfg(target_os = "linux")]
pub mod large_blocks;
pub mod library;
pub mod midi_learn;
pub mod model;
pub mod modes_view;
pub mod modes_worker;
pub mod motion;
pub mod param_text;
pub mod params;
pub mod plot;
pub mod presets;
pub mod remote_pages;
pub mod report;
pub mod runtime;
pub mod state;
pub mod vary_worker;
pub mod view3d;
pub mod voices_watch;

/// Large blocks (the analyses' matrices) go back to the system when freed
/// ([`large_blocks`]). Release builds only: debug builds may hold nice-plug's checking
/// allocator (`assert_process_allocs`) in this place.
#[cfg(all(target_os = "linux", not(debug_assertions)))]
#[global_allocator]
static ALLOCATOR: large_blocks::LargeBlocks = large_blocks::LargeBlocks;

pub use ressort_engine::analysis::envelope;
pub use ressort_engine::instrument::{dsp, host, macros};

use params::RessortParams;
use report::{HostLink, MainThreadTask};
use runtime::RuntimeStatus;
use voices_watch::VoicesWatch;

/// Output and input below this count as silence for the host's sleep decision (−120 dBFS).
const QUIET_LEVEL: f64 = 1e-6;
/// Interval of the editor's repeated strike (Audition).
const AUDITION_INTERVAL_S: f64 = 1.0;
/// Velocity of the editor's strikes.
const AUDITION_VELOCITY: f32 = 0.8;

pub struct Ressort {
    params: Arc<RessortParams>,
    store: Arc<ModelStore>,
    editor_state: Arc<nice_plug_egui::EguiEditorState>,
    /// The editor's context, to show guard trips to the host.
    host_link: Arc<HostLink>,
    /// The model played by notes, knobs and host audio: every stage of the audio path.
    instrument: Instrument,
    /// Samples until the next Audition strike.
    audition_left: u64,
    sample_rate: f64,
    has_main_input: bool,
    /// Models waiting to go back to the store when its return channel was full.
    held: [Option<Box<Prepared>>; 4],
    /// Exact facts waiting for their provisional model to arrive (`exact` set), or facts
    /// waiting to go back to the store (`exact` the replaced ones).
    refinement: Option<Refinement>,
    quiet_samples: u64,
    /// A strike from the editor waits for the next block.
    pending_strike: bool,
    /// A main-thread task to apply a new Voices setting is on its way (CLAP).
    voices_task_queued: bool,
    /// Applies a new Voices setting in the other formats (started at the first activation).
    voices_watch: Option<VoicesWatch>,
}

impl Drop for Ressort {
    fn drop(&mut self) {
        // A model the editor is still preparing runs the plugin's code on its own thread: the
        // host may unload the library once the instance is gone.
        self.store.finish_loads();
    }
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
            instrument: Instrument::new(48_000.0, Controls::DEFAULT),
            audition_left: 0,
            sample_rate: 48_000.0,
            has_main_input: false,
            held: [None, None, None, None],
            refinement: None,
            quiet_samples: 0,
            pending_strike: false,
            voices_task_queued: false,
            voices_watch: None,
        }
    }
}

impl Ressort {
    /// What the CLAP remote-control pages are made from: shared with the wrapper, which asks
    /// again without locking the plugin.
    fn remote_pages(&self) -> remote_pages::RemotePages {
        remote_pages::RemotePages {
            params: Arc::clone(&self.params),
            store: Arc::clone(&self.store),
        }
    }

    /// The model store shared with the editor.
    pub fn store(&self) -> &Arc<ModelStore> {
        &self.store
    }

    fn runtime(&self) -> &RuntimeStatus {
        &self.store.runtime
    }

    /// Returns a model to the store, or keeps it for a later try. Realtime-safe.
    fn recycle(&mut self, prepared: Option<Box<Prepared>>) {
        let Some(prepared) = prepared else {
            return;
        };
        if let Err(back) = self.store.recycle(prepared) {
            if let Some(slot) = self.held.iter_mut().find(|s| s.is_none()) {
                *slot = Some(back);
            } else {
                // `receive_models` takes a new model only with two slots free, and the
                // instrument gives back at most two models per model it takes (the one it
                // fades out, then the one it retires), so a slot is always free here. Were
                // one not, freeing here is a deallocation on the audio thread, which
                // `assert_process_allocs` builds report, never a leak.
                debug_assert!(false, "no holding slot for a returned model");
                drop(back);
            }
        }
    }

    /// Picks up a new model from the store and starts the crossfade; tells the main thread,
    /// so that the host's remote-control pages follow it. Realtime-safe.
    fn receive_models(&mut self, context: &mut impl ProcessContext<Self>) {
        for i in 0..self.held.len() {
            if let Some(p) = self.held[i].take() {
                if let Err(back) = self.store.recycle(p) {
                    self.held[i] = Some(back);
                }
            }
        }
        // A new model stays in the store while fewer than two holding slots are free: it
        // may give two models back (see `recycle`), and the main thread has not yet taken
        // the ones returned before.
        if self.held.iter().filter(|s| s.is_none()).count() < 2 {
            return;
        }
        let Some(new) = self.store.receive() else {
            return;
        };
        if new.facts().sample_rate != self.sample_rate {
            self.recycle(Some(new));
            return;
        }
        let stale = self.instrument.set_model(new);
        self.recycle(stale);
        self.runtime()
            .running_generation
            .fetch_add(1, Ordering::AcqRel);
        context.execute_gui(MainThreadTask::ModelChanged);
    }

    /// Hands a provisional model the facts of its exact analyses when they come
    /// ([`Instrument::refine`]), and the replaced facts back to the store. Exact facts that
    /// come before their model (still in the store's channel) wait for it. Realtime-safe.
    fn refine_model(&mut self) {
        let Some(mut r) = self
            .refinement
            .take()
            .or_else(|| self.store.receive_refinement())
        else {
            return;
        };
        if let Some(exact) = r.exact.take() {
            if !self.instrument.plays(&r.provisional) && self.store.model_waiting() {
                r.exact = Some(exact);
                self.refinement = Some(r);
                return;
            }
            let back = self.instrument.refine(&r.provisional, exact);
            if Arc::ptr_eq(&back, &r.provisional) {
                self.runtime().refinements.fetch_add(1, Ordering::AcqRel);
            }
            r.exact = Some(back);
        }
        if let Err(back) = self.store.return_refinement(r) {
            self.refinement = Some(back);
        }
    }

    /// The parameters as the instrument's controls.
    fn controls(&self) -> Controls {
        self.params.controls()
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
            self.instrument.restart();
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

    /// A new Voices setting: CLAP re-prepares the model on the main thread at once; the
    /// other formats through [`VoicesWatch`], within a few tens of milliseconds.
    fn follow_voices_setting(&mut self, context: &mut impl ProcessContext<Self>) {
        if !self.store.voices_stale() {
            self.voices_task_queued = false;
        } else if !std::mem::replace(&mut self.voices_task_queued, true)
            && context.plugin_api() == PluginApi::Clap
        {
            context.execute_gui(MainThreadTask::ApplyVoices);
        }
    }

    /// Publishes what the instrument did in a block of `frames` to the editor (gains, macro
    /// positions, voices) and to the host (voices that ended, guard trips).
    fn report(&mut self, trips: u32, frames: usize, context: &mut impl ProcessContext<Self>) {
        // Voices that ended: CLAP hosts end their polyphonic modulation there.
        let last = frames.saturating_sub(1) as u32;
        self.instrument.drain_ended(|e| {
            let _ = context.try_send_event(NoteEvent::VoiceTerminated {
                timing: last,
                voice_id: e.voice_id.map_or(VoiceID::Wildcard, VoiceID::ID),
                channel: Channel::Number(e.channel),
                key: Key::Number(e.note),
            });
        });
        let g = self.instrument.gains();
        let rt = &self.store.runtime;
        for (a, v) in rt.macros.iter().zip(self.instrument.macros()) {
            a.store(v, Ordering::Relaxed);
        }
        let (sounding, total) = self.instrument.voice_count();
        rt.voices_sounding.store(sounding as u32, Ordering::Relaxed);
        rt.voices_total.store(total as u32, Ordering::Relaxed);
        rt.stiffness_gain.store(g.stiffness, Ordering::Relaxed);
        rt.damping_gain.store(g.damping, Ordering::Relaxed);
        rt.requested_stiffness_gain
            .store(g.requested_stiffness, Ordering::Relaxed);
        rt.requested_damping_gain
            .store(g.requested_damping, Ordering::Relaxed);
        rt.clamped.store(g.clamped, Ordering::Relaxed);
        if trips == 0 {
            return;
        }
        // Atomics, and at most one main-thread task per episode (CLAP only; see `report`).
        // Never `execute_background`: nice-plug 0.4.2's shared background worker exits when
        // it runs a task of an instance that is gone, and the next instance's destruction
        // then aborts the host.
        rt.guard_trips.fetch_add(trips, Ordering::AcqRel);
        // One report per episode: an exploding model trips in every chunk.
        if !rt.guard_active.swap(true, Ordering::AcqRel)
            && context.plugin_api() == PluginApi::Clap
            && self.host_link.is_attached()
        {
            context.execute_gui(MainThreadTask::ReportGuardTrip);
        }
    }
}

/// A host note event as the instrument's event, when it is one the instrument plays.
fn instrument_event(event: NoteEvent<()>) -> Option<Timed> {
    let timing = event.timing();
    let e = match event {
        NoteEvent::NoteOn {
            key,
            velocity,
            channel,
            voice_id,
            ..
        } => Event::NoteOn {
            note: key.number()?,
            velocity,
            channel: channel.number().unwrap_or(0),
            voice_id: voice_id.id(),
        },
        NoteEvent::NoteOff {
            key,
            channel,
            voice_id,
            ..
        } => Event::NoteOff {
            note: key.number()?,
            channel: channel.number().unwrap_or(0),
            voice_id: voice_id.id(),
        },
        NoteEvent::MidiPitchBend { value, channel, .. } => Event::PitchBend { value, channel },
        NoteEvent::MidiChannelPressure {
            channel, pressure, ..
        } => Event::Pressure {
            value: pressure,
            channel,
            note: None,
            voice_id: None,
        },
        NoteEvent::PolyPressure {
            voice_id,
            channel,
            key,
            pressure,
            ..
        } => Event::Pressure {
            value: pressure,
            channel: channel.number().unwrap_or(0),
            note: key.number(),
            voice_id: voice_id.id(),
        },
        NoteEvent::PolyTuning {
            voice_id,
            channel,
            key,
            tuning,
            ..
        } => Event::Tuning {
            semitones: tuning,
            channel: channel.number().unwrap_or(0),
            note: key.number(),
            voice_id: voice_id.id(),
        },
        NoteEvent::PolyModulation {
            voice_id,
            poly_modulation_id,
            normalized_offset,
            ..
        } => Event::Modulation {
            target: match poly_modulation_id {
                params::POLY_MOD_STIFFNESS => Modulated::Stiffness,
                params::POLY_MOD_DAMPING => Modulated::Damping,
                _ => return None,
            },
            // The knobs span 2 × GAIN_OCTAVES octaves.
            octaves: normalized_offset * 2.0 * params::GAIN_OCTAVES,
            voice_id,
        },
        NoteEvent::MidiCC { cc, value, .. } => Event::Controller { cc, value },
        _ => return None,
    };
    Some(Timed::new(timing, e))
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
        // Multichannel instrument: an 8-channel sidechain feeds @in1 … @in8, and @out3 …
        // @out8 leave on three stereo auxiliary outputs (docs/LANGUAGE.md, host routing).
        AudioIOLayout {
            main_input_channels: None,
            main_output_channels: NonZeroU32::new(2),
            aux_input_ports: &[new_nonzero_u32(8)],
            aux_output_ports: &[new_nonzero_u32(2), new_nonzero_u32(2), new_nonzero_u32(2)],
            names: PortNames {
                layout: Some("Multichannel instrument"),
                main_input: None,
                main_output: Some("Output (out1, out2)"),
                aux_inputs: &["Sidechain (in1 … in8)"],
                aux_outputs: &["out3, out4", "out5, out6", "out7, out8"],
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

    /// Older states load as they were saved; a newer format is refused (see `state`).
    fn filter_state(state: &mut PluginState) {
        state::filter(state);
    }

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
        let store = self.store.clone();
        Box::new(move |task| match task {
            MainThreadTask::ReportGuardTrip => link.set_guard(&params, true),
            MainThreadTask::ApplyVoices => store.apply_voices(),
            MainThreadTask::ModelChanged => {}
        })
    }

    fn activate(
        &mut self,
        audio_io_layout: &AudioIOLayout,
        buffer_config: &BufferConfig,
        context: &mut impl ActivateContext<Self>,
    ) -> bool {
        let sr = buffer_config.sample_rate as f64;
        if !(sr.is_finite() && (1.0..=1e7).contains(&sr)) {
            return false;
        }
        self.sample_rate = sr;
        self.has_main_input = audio_io_layout.main_input_channels.is_some();
        self.held = Default::default();
        self.refinement = None;
        let offline = buffer_config.process_mode == ProcessMode::Offline;
        let Some(model) = self.store.activate(sr, offline) else {
            return false;
        };
        self.instrument = Instrument::new(sr, self.controls());
        self.instrument.set_main_input(self.has_main_input);
        self.instrument.set_model(model);
        self.quiet_samples = 0;
        if context.plugin_api() != PluginApi::Clap && self.voices_watch.is_none() {
            self.voices_watch = VoicesWatch::start(self.store.clone());
        }
        true
    }

    fn reset(&mut self) {
        let stale = self.instrument.reset(self.controls());
        self.recycle(stale);
        self.quiet_samples = 0;
    }

    fn deactivate(&mut self) {
        // Dropped here, on the host's main thread, not on the audio thread.
        drop(self.instrument.take_models());
        self.held = Default::default();
        self.refinement = None;
        self.store.deactivate();
    }

    fn process(
        &mut self,
        buffer: &mut Buffer,
        aux: &mut AuxiliaryBuffers,
        context: &mut impl ProcessContext<Self>,
    ) -> ProcessStatus {
        let started = std::time::Instant::now();
        self.receive_models(context);
        self.refine_model();
        self.editor_requests();
        self.instrument.set_watching(self.editor_state.is_open());
        let frames = buffer.samples();
        let controls = self.controls();
        // The control grid follows the song while the transport plays, so that a bounce
        // does not depend on when the host activated the plugin.
        let transport = context.transport();
        let song = if transport.playing {
            transport.pos_samples()
        } else {
            None
        };
        self.instrument.set_song_position(song);

        // Host inputs: the sidechain's channels; the main bus is read in place.
        let mut host_in: [Option<&[f32]>; MAX_HOST_INPUTS] = [None; MAX_HOST_INPUTS];
        if let Some(sc) = aux.inputs.first() {
            let channels = sc.as_slice_immutable();
            for (c, ch) in channels.iter().take(MAX_HOST_INPUTS - 2).enumerate() {
                host_in[2 + c] = Some(&**ch);
            }
        }

        // Events: the editor's strike first, then the host's notes.
        let strike = std::mem::take(&mut self.pending_strike).then_some(Timed::new(
            0,
            Event::Strike {
                velocity: AUDITION_VELOCITY,
            },
        ));
        // MIDI learn hears every controller before the instrument maps it.
        let cc_map = &self.params.cc_map;
        self.instrument.set_cc_map(&cc_map.mapping());
        let mut events = strike.into_iter().chain(std::iter::from_fn(|| loop {
            let e = context.next_event()?;
            if let NoteEvent::MidiCC { cc, .. } = e {
                cc_map.heard(cc);
            }
            if let Some(t) = instrument_event(e) {
                return Some(t);
            }
        }));
        // Host outputs: main left and right (@out1, @out2), then the auxiliary pairs.
        let mut outputs: [&mut [f32]; MAX_HOST_OUTPUTS] = Default::default();
        let mut n_out = 0;
        for ch in buffer.as_slice().iter_mut() {
            if n_out < MAX_HOST_OUTPUTS {
                outputs[n_out] = &mut **ch;
                n_out += 1;
            }
        }
        for port in aux.outputs.iter_mut() {
            for ch in port.as_slice().iter_mut() {
                if n_out < MAX_HOST_OUTPUTS {
                    outputs[n_out] = &mut **ch;
                    n_out += 1;
                }
            }
        }
        let report = self.instrument.process(
            frames,
            &host_in,
            self.has_main_input,
            &mut events,
            &controls,
            &mut outputs[..n_out],
        );
        drop(events);
        self.audition_left = self.audition_left.saturating_sub(frames as u64);
        let retired = self.instrument.take_retired();
        self.recycle(retired);
        self.report(report.trips, frames, context);
        self.follow_voices_setting(context);

        let rt = &self.store.runtime;
        if report.input_peak > rt.input_peak.load(Ordering::Relaxed) {
            rt.input_peak.store(report.input_peak, Ordering::Relaxed);
        }
        if report.triggered > 0 {
            rt.triggered.fetch_add(report.triggered, Ordering::Relaxed);
        }
        let seconds = frames as f64 / self.sample_rate;
        if seconds > 0.0 {
            let load = started.elapsed().as_secs_f64() / seconds;
            let old = rt.cpu_load.load(Ordering::Relaxed);
            rt.cpu_load
                .store(old + 0.1 * (load - old), Ordering::Relaxed);
        }
        if report.loudest > QUIET_LEVEL || report.fading {
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
    /// Stiffness and Damping take polyphonic modulation: a host can move them per voice.
    const CLAP_POLY_MODULATION_CONFIG: Option<PolyModulationConfig> = Some(PolyModulationConfig {
        max_voice_capacity: model::MAX_VOICES as u32,
        supports_overlapping_voices: true,
    });
    const CLAP_FEATURES: &'static [ClapFeature] = &[
        ClapFeature::Instrument,
        ClapFeature::Synthesizer,
        ClapFeature::AudioEffect,
        ClapFeature::Stereo,
    ];

    /// The factory presets and the user folder, for the hosts' own browsers
    /// ([`clap_presets`]).
    const CLAP_PRESET_DISCOVERY: bool = true;

    fn clap_preset_filetypes() -> Vec<PresetFiletype> {
        clap_presets::filetypes()
    }

    fn clap_preset_locations() -> Vec<PresetLocation> {
        clap_presets::locations()
    }

    fn clap_preset_metadata(
        location: PresetLocationRef<'_>,
    ) -> Result<Vec<PresetMetadata>, String> {
        clap_presets::metadata(location)
    }

    fn clap_preset_loader(&self) -> Option<Box<dyn ClapPresetLoader>> {
        Some(Box::new(clap_presets::Loader {
            store: Arc::clone(&self.store),
        }))
    }

    /// The running model's pages ([`remote_pages`]).
    fn remote_controls(&self, context: &mut impl RemoteControlsContext) {
        self.remote_pages().define(context);
    }

    fn clap_remote_controls(&self) -> Option<Arc<dyn ClapRemoteControls>> {
        Some(Arc::new(self.remote_pages()))
    }
}

impl Vst3Plugin for Ressort {
    const VST3_CLASS_ID: [u8; 16] = *b"RessortMassInter";
    const VST3_SUBCATEGORIES: &'static [Vst3SubCategory] = &[
        Vst3SubCategory::Instrument,
        Vst3SubCategory::Synth,
        Vst3SubCategory::Fx,
    ];
    /// VST3 delivers MIDI controllers as proxy parameters, one per controller and channel,
    /// and JUCE-based hosts list every one (2,080 for all of them, which took pedalboard
    /// 112 s to load). The plugin lists pitch bend and the controllers MIDI learn offers
    /// ([`VST3_CONTROLLERS`]); a controller it starts to read goes in that list.
    const VST3_MIDI_CONTROLLERS: &'static [u8] = &VST3_CONTROLLERS;
}

/// The controllers VST3 hosts deliver (as proxy parameters on each of the 16 channels): pitch
/// bend (129) and the controllers people put on knobs and pedals, for MIDI learn: modulation
/// wheel 1, breath 2, foot 4, volume 7, expression 11, general purpose 16–19, sustain 64 and
/// the sound controllers 71–74, and channel pressure (128, MPE's per-note pressure). CLAP and
/// the standalone deliver every controller.
pub const VST3_CONTROLLERS: [u8; 16] =
    [1, 2, 4, 7, 11, 16, 17, 18, 19, 64, 71, 72, 73, 74, 128, 129];

nice_export_clap!(Ressort);
nice_export_vst3!(Ressort);
