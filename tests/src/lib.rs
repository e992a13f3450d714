//! A small CLAP test host for end-to-end tests of the bundled Ressort plugin.
//!
//! It loads the bundle (`target/bundled/Ressort.clap`, or the file named by the `RESSORT_CLAP`
//! environment variable) with [`clack_host`], creates an instance, activates it and calls its
//! `process()` with stereo sidechain (and optional main) input, note, pitch-bend and parameter
//! events, exactly as a DAW would. Everything runs on the calling thread: the host declares the
//! thread-check extension and tells the plugin which role ("main" or "audio") the thread has at
//! each call, so the plugin's realtime checks (the bundle is built with
//! `assert_process_allocs`, which aborts on any allocation in `process()`) see a realistic
//! picture.
//!
//! Host callbacks are answered: `request_callback` runs the plugin's `on_main_thread` at the
//! next [`TestPlugin::idle`] (called after every block and state load), `request_restart`
//! reactivates the plugin there, the log extension prints the plugin's messages to stderr and
//! keeps them, and parameter, state, audio-port and note-port notifications are counted
//! ([`HostCounters`]).
//!
//! ```no_run
//! use ressort_tests::{Score, TestPlugin};
//! let mut plugin = TestPlugin::new();
//! plugin.activate(48_000.0, 1, 512);
//! let out = plugin.render(0.5, 512, &Score::new().impulse(0, -0.5));
//! assert!(out.audio.is_finite());
//! ```

use clack_extensions::audio_ports::{
    AudioPortFlags, AudioPortInfoBuffer, AudioPortRescanFlags, HostAudioPorts, HostAudioPortsImpl,
    PluginAudioPorts,
};
use clack_extensions::audio_ports_config::{
    AudioPortsConfigBuffer, HostAudioPortsConfig, HostAudioPortsConfigImpl, PluginAudioPortsConfig,
};
use clack_extensions::gui::{
    GuiApiType, GuiConfiguration, GuiSize, HostGui, HostGuiImpl, PluginGui, Window,
};
use clack_extensions::log::{HostLog, HostLogImpl, LogSeverity};
use clack_extensions::note_ports::{
    HostNotePorts, HostNotePortsImpl, NoteDialects, NotePortInfoBuffer, NotePortRescanFlags,
    PluginNotePorts,
};
use clack_extensions::params::{
    HostParams, HostParamsImplMainThread, HostParamsImplShared, ParamClearFlags, ParamInfoBuffer,
    ParamRescanFlags, PluginParams,
};
use clack_extensions::state::{HostState, HostStateImpl, PluginState, StateError};
use clack_extensions::thread_check::{HostThreadCheck, HostThreadCheckImpl};
use clack_host::events::event_types::{
    MidiEvent, NoteEndEvent, NoteExpressionEvent, NoteOffEvent, NoteOnEvent, ParamModEvent,
    ParamValueEvent, TransportEvent, TransportFlags,
};
use clack_host::events::{EventFlags, Match};
use clack_host::host::HostError;
use clack_host::prelude::*;
use clack_host::utils::{BeatTime, SecondsTime};
use std::cell::Cell;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

pub use clack_host::events::event_types::NoteExpressionType;
pub use clack_host::prelude::{ClapId, ProcessStatus};

/// The plugin's CLAP id.
pub const PLUGIN_ID: &str = "audio.ressort.ressort";

/// The environment variable that overrides the bundle's path.
pub const BUNDLE_ENV: &str = "RESSORT_CLAP";

/// The command that builds the bundle the tests load.
pub const BUILD_COMMAND: &str =
    "cd /work/main && cargo xtask bundle ressort-plugin --features assert_process_allocs";

/// Where the tests find the plugin: `$RESSORT_CLAP`, or `target/bundled/Ressort.clap` of the
/// workspace.
pub fn bundle_path() -> PathBuf {
    match std::env::var_os(BUNDLE_ENV) {
        Some(p) if !p.is_empty() => PathBuf::from(p),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/bundled/Ressort.clap"),
    }
}

/// Loads the bundle's entry. Panics with the command that builds it when it is missing: the
/// tests never skip silently.
pub fn load_entry() -> PluginEntry {
    let path = bundle_path();
    if !path.exists() {
        panic!(
            "the Ressort CLAP bundle was not found at {}.\nBuild it with:\n    {BUILD_COMMAND}\n\
             or point {BUNDLE_ENV} at a bundle.",
            path.display()
        );
    }
    // SAFETY: loading a dynamic library runs its initialisers; the bundle is our own plugin.
    unsafe { PluginEntry::load(&path) }.unwrap_or_else(|e| {
        panic!(
            "could not load the CLAP bundle {}: {e}\nRebuild it with:\n    {BUILD_COMMAND}",
            path.display()
        )
    })
}

// ---------------------------------------------------------------------------------------------
// Thread roles
// ---------------------------------------------------------------------------------------------

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Role {
    Other,
    Main,
    Audio,
}

thread_local! {
    /// What the current thread is for the plugin: the thread that created a [`TestPlugin`] is
    /// its main thread, and becomes the audio thread while the host calls audio-thread
    /// functions. Const-initialised: reading it never allocates (it is read inside `process()`).
    static ROLE: Cell<Role> = const { Cell::new(Role::Other) };
}

/// Runs `f` with the current thread marked as the audio thread.
fn as_audio_thread<R>(f: impl FnOnce() -> R) -> R {
    let previous = ROLE.with(|r| r.replace(Role::Audio));
    let result = f();
    ROLE.with(|r| r.set(previous));
    result
}

// ---------------------------------------------------------------------------------------------
// Host handlers
// ---------------------------------------------------------------------------------------------

/// The host type: its handlers and extensions.
#[derive(Debug)]
pub struct TestHost;

/// One message from the plugin's log.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LogMessage {
    pub severity: String,
    pub text: String,
}

/// The thread-safe part of the host: requests that can come from any thread.
#[derive(Debug, Default)]
pub struct HostShared {
    callback_requested: AtomicBool,
    restart_requested: AtomicBool,
    process_requested: AtomicBool,
    flush_requested: AtomicBool,
    log: Mutex<Vec<LogMessage>>,
}

impl SharedHandler<'_> for HostShared {
    fn request_restart(&self) {
        self.restart_requested.store(true, Ordering::Release);
    }

    fn request_process(&self) {
        self.process_requested.store(true, Ordering::Release);
    }

    fn request_callback(&self) {
        self.callback_requested.store(true, Ordering::Release);
    }
}

impl HostLogImpl for HostShared {
    fn log(&self, severity: LogSeverity, message: &str) {
        eprintln!("[plugin log, {severity}] {message}");
        let mut log = self.log.lock().unwrap_or_else(|e| e.into_inner());
        log.push(LogMessage {
            severity: severity.to_string(),
            text: message.to_string(),
        });
    }
}

/// The editor's requests to the host window (the test host accepts them; the editor tests
/// drive sizes through `gui.set_size`).
impl HostGuiImpl for HostShared {
    fn resize_hints_changed(&self) {}

    fn request_resize(&self, _new_size: GuiSize) -> Result<(), HostError> {
        Ok(())
    }

    fn request_show(&self) -> Result<(), HostError> {
        Ok(())
    }

    fn request_hide(&self) -> Result<(), HostError> {
        Ok(())
    }

    fn closed(&self, _was_destroyed: bool) {}
}

impl HostParamsImplShared for HostShared {
    fn request_flush(&self) {
        self.flush_requested.store(true, Ordering::Release);
    }
}

impl HostThreadCheckImpl for HostShared {
    fn is_main_thread(&self) -> bool {
        ROLE.with(|r| r.get()) == Role::Main
    }

    fn is_audio_thread(&self) -> bool {
        ROLE.with(|r| r.get()) == Role::Audio
    }
}

/// How often the plugin notified the host of something, on the main thread.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HostCounters {
    /// `clap_host_params.rescan` calls, and the union of their flags.
    pub param_rescans: u32,
    pub param_rescan_flags: u32,
    pub param_clears: u32,
    /// `clap_host_state.mark_dirty` calls.
    pub state_dirty: u32,
    pub audio_port_rescans: u32,
    pub audio_ports_config_rescans: u32,
    pub note_port_rescans: u32,
    /// `on_main_thread` calls made after a `request_callback`.
    pub main_thread_callbacks: u32,
    /// Reactivations made after a `request_restart`.
    pub restarts: u32,
    /// `request_flush` calls seen (the host flushes at the next idle when inactive).
    pub flush_requests: u32,
}

/// The main-thread part of the host.
#[derive(Debug, Default)]
pub struct HostMainThread {
    counters: Cell<HostCounters>,
}

impl HostMainThread {
    fn count(&self, f: impl FnOnce(&mut HostCounters)) {
        let mut c = self.counters.get();
        f(&mut c);
        self.counters.set(c);
    }
}

impl MainThreadHandler<'_> for HostMainThread {}

impl HostParamsImplMainThread for HostMainThread {
    fn rescan(&self, flags: ParamRescanFlags) {
        self.count(|c| {
            c.param_rescans += 1;
            c.param_rescan_flags |= flags.bits();
        });
    }

    fn clear(&self, _param_id: ClapId, _flags: ParamClearFlags) {
        self.count(|c| c.param_clears += 1);
    }
}

impl HostStateImpl for HostMainThread {
    fn mark_dirty(&self) {
        self.count(|c| c.state_dirty += 1);
    }
}

impl HostAudioPortsImpl for HostMainThread {
    fn is_rescan_flag_supported(&self, _flag: AudioPortRescanFlags) -> bool {
        true
    }

    fn rescan(&self, _flags: AudioPortRescanFlags) {
        self.count(|c| c.audio_port_rescans += 1);
    }
}

impl HostAudioPortsConfigImpl for HostMainThread {
    fn rescan(&self) {
        self.count(|c| c.audio_ports_config_rescans += 1);
    }
}

impl HostNotePortsImpl for HostMainThread {
    fn supported_dialects(&self) -> NoteDialects {
        NoteDialects::CLAP | NoteDialects::MIDI
    }

    fn rescan(&self, _flags: NotePortRescanFlags) {
        self.count(|c| c.note_port_rescans += 1);
    }
}

impl HostHandlers for TestHost {
    type Shared<'a> = HostShared;
    type MainThread<'a> = HostMainThread;
    type AudioProcessor<'a> = ();

    fn declare_extensions(builder: &mut HostExtensions<Self>, _shared: &Self::Shared<'_>) {
        builder
            .register::<HostLog>()
            .register::<HostParams>()
            .register::<HostState>()
            .register::<HostAudioPorts>()
            .register::<HostAudioPortsConfig>()
            .register::<HostNotePorts>()
            .register::<HostThreadCheck>()
            .register::<HostGui>();
    }
}

// ---------------------------------------------------------------------------------------------
// Signals, events and scores
// ---------------------------------------------------------------------------------------------

/// A stereo signal.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stereo {
    pub left: Vec<f32>,
    pub right: Vec<f32>,
}

impl Stereo {
    /// `frames` samples of silence.
    pub fn silence(frames: usize) -> Stereo {
        Stereo {
            left: vec![0.0; frames],
            right: vec![0.0; frames],
        }
    }

    pub fn len(&self) -> usize {
        self.left.len().max(self.right.len())
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Grows both channels with zeros to at least `frames` samples.
    pub fn pad_to(&mut self, frames: usize) {
        if self.left.len() < frames {
            self.left.resize(frames, 0.0);
        }
        if self.right.len() < frames {
            self.right.resize(frames, 0.0);
        }
    }

    /// Appends another signal.
    pub fn append(&mut self, other: &Stereo) {
        self.left.extend_from_slice(&other.left);
        self.right.extend_from_slice(&other.right);
    }

    /// Frames `range` of both channels.
    pub fn slice(&self, range: std::ops::Range<usize>) -> Stereo {
        Stereo {
            left: self.left[range.clone()].to_vec(),
            right: self.right[range].to_vec(),
        }
    }

    /// Every sample of both channels.
    pub fn samples(&self) -> impl Iterator<Item = f32> + '_ {
        self.left.iter().chain(&self.right).copied()
    }

    /// True when no sample is NaN or infinite.
    pub fn is_finite(&self) -> bool {
        self.samples().all(f32::is_finite)
    }

    /// The largest |sample| (NaN counts as infinite).
    pub fn peak(&self) -> f32 {
        self.samples()
            .map(|s| if s.is_nan() { f32::INFINITY } else { s.abs() })
            .fold(0.0, f32::max)
    }

    /// The RMS over both channels.
    pub fn rms(&self) -> f64 {
        let n = (self.left.len() + self.right.len()).max(1);
        (self.samples().map(|s| (s as f64).powi(2)).sum::<f64>() / n as f64).sqrt()
    }

    /// True when both signals have the same length and the same bits everywhere.
    pub fn bit_identical(&self, other: &Stereo) -> bool {
        self.first_difference(other).is_none() && self.len() == other.len()
    }

    /// The first frame where the two signals differ bit-wise (or where one ends).
    pub fn first_difference(&self, other: &Stereo) -> Option<usize> {
        let differs = |a: &[f32], b: &[f32]| -> Option<usize> {
            let n = a.len().min(b.len());
            (0..n)
                .find(|&i| a[i].to_bits() != b[i].to_bits())
                .or((a.len() != b.len()).then_some(n))
        };
        match (
            differs(&self.left, &other.left),
            differs(&self.right, &other.right),
        ) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

/// An event sent to the plugin. `time` is in samples: from the start of the block in
/// [`Block::events`], from the start of the render in [`Score::events`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HostEvent {
    /// A CLAP note-on on note port 0 and MIDI channel `channel` (0 … 15); `velocity` in
    /// 0..=1. `note_id` is the host's id for the note (`None`: -1, no id).
    NoteOn {
        time: u32,
        key: u8,
        velocity: f64,
        channel: u8,
        note_id: Option<u32>,
    },
    /// A CLAP note-off on note port 0 and MIDI channel `channel`.
    NoteOff {
        time: u32,
        key: u8,
        velocity: f64,
        channel: u8,
        note_id: Option<u32>,
    },
    /// A CLAP note expression (tuning in semitones, pressure in 0..=1, …) for the note with
    /// this key, channel and id.
    NoteExpression {
        time: u32,
        key: u8,
        channel: u8,
        note_id: Option<u32>,
        expression: NoteExpressionType,
        value: f64,
    },
    /// A CLAP polyphonic modulation (`CLAP_EVENT_PARAM_MOD` for one note id): `amount` is
    /// added to the parameter's value for that note's voice only.
    PolyModulation {
        time: u32,
        id: ClapId,
        key: u8,
        channel: u8,
        note_id: u32,
        amount: f64,
    },
    /// A MIDI 1 pitch bend on MIDI channel `channel` (`value` in -1..=1, 0 = centre), sent as
    /// a 14-bit CLAP MIDI event.
    PitchBend { time: u32, value: f64, channel: u8 },
    /// A MIDI 1 channel pressure on MIDI channel `channel` (`value` in 0..=1, sent as 0..=127).
    ChannelPressure { time: u32, value: f64, channel: u8 },
    /// A MIDI 1 control change on channel 0 (`value` 0..=127), as a CLAP MIDI event.
    Controller { time: u32, cc: u8, value: u8 },
    /// A parameter change to a plain value.
    Param { time: u32, id: ClapId, value: f64 },
}

impl HostEvent {
    pub fn time(&self) -> u32 {
        match *self {
            HostEvent::NoteOn { time, .. }
            | HostEvent::NoteOff { time, .. }
            | HostEvent::PitchBend { time, .. }
            | HostEvent::ChannelPressure { time, .. }
            | HostEvent::Controller { time, .. }
            | HostEvent::Param { time, .. }
            | HostEvent::NoteExpression { time, .. }
            | HostEvent::PolyModulation { time, .. } => time,
        }
    }

    /// The same event at another time.
    pub fn at(mut self, t: u32) -> HostEvent {
        match &mut self {
            HostEvent::NoteOn { time, .. }
            | HostEvent::NoteOff { time, .. }
            | HostEvent::PitchBend { time, .. }
            | HostEvent::ChannelPressure { time, .. }
            | HostEvent::Controller { time, .. }
            | HostEvent::Param { time, .. }
            | HostEvent::NoteExpression { time, .. }
            | HostEvent::PolyModulation { time, .. } => *time = t,
        }
        self
    }

    /// The 14-bit MIDI value of a pitch bend in -1..=1 (8192 = centre).
    pub fn pitch_bend_14bit(value: f64) -> u16 {
        let v = if value.is_finite() { value } else { 0.0 };
        (8192.0 + v.clamp(-1.0, 1.0) * 8192.0)
            .round()
            .clamp(0.0, 16383.0) as u16
    }

    fn push_to(&self, buffer: &mut EventBuffer) {
        let note = |key: u8, channel: u8, id: Option<u32>| {
            let id = id.map_or(Match::<u32>::All, Match::Specific);
            Pckn::new(0u16, (channel & 0x0f) as u16, key as u16, id)
        };
        match *self {
            HostEvent::NoteOn {
                time,
                key,
                velocity,
                channel,
                note_id,
            } => buffer.push(&NoteOnEvent::new(
                time,
                note(key, channel, note_id),
                velocity,
            )),
            HostEvent::NoteOff {
                time,
                key,
                velocity,
                channel,
                note_id,
            } => buffer.push(&NoteOffEvent::new(
                time,
                note(key, channel, note_id),
                velocity,
            )),
            HostEvent::NoteExpression {
                time,
                key,
                channel,
                note_id,
                expression,
                value,
            } => buffer.push(&NoteExpressionEvent::new(
                time,
                note(key, channel, note_id),
                expression,
                value,
            )),
            HostEvent::PolyModulation {
                time,
                id,
                key,
                channel,
                note_id,
                amount,
            } => buffer.push(&ParamModEvent::new(
                time,
                id,
                note(key, channel, Some(note_id)),
                amount,
            )),
            HostEvent::PitchBend {
                time,
                value,
                channel,
            } => {
                let v = Self::pitch_bend_14bit(value);
                let data = [0xE0 | (channel & 0x0f), (v & 0x7f) as u8, (v >> 7) as u8];
                buffer.push(&MidiEvent::new(time, 0, data));
            }
            HostEvent::ChannelPressure {
                time,
                value,
                channel,
            } => {
                let v = (value.clamp(0.0, 1.0) * 127.0).round() as u8;
                let data = [0xD0 | (channel & 0x0f), v & 0x7f, 0];
                buffer.push(&MidiEvent::new(time, 0, data));
            }
            HostEvent::Controller { time, cc, value } => {
                let data = [0xB0, cc & 0x7f, value & 0x7f];
                buffer.push(&MidiEvent::new(time, 0, data));
            }
            HostEvent::Param { time, id, value } => {
                buffer.push(&ParamValueEvent::new(time, id, Pckn::match_all(), value))
            }
        }
    }
}

/// The input of one `process()` call. Input slices shorter than `frames` are padded with
/// zeros; `None` inputs are silent.
#[derive(Clone, Copy, Debug, Default)]
pub struct Block<'a> {
    pub frames: usize,
    /// The sidechain's channels in order (aux input "Sidechain"); empty: silent.
    pub sidechain: &'a [&'a [f32]],
    /// The main input, used when the "Effect with sidechain" configuration is selected.
    pub main_input: Option<[&'a [f32]; 2]>,
    /// Events, with times relative to the block's start (sorted by the host before sending).
    pub events: &'a [HostEvent],
    /// The song position of the block's first sample while the transport plays (sent in
    /// seconds and in beats at 120 BPM, as a DAW does); `None`: a free-running host.
    pub song_position: Option<u64>,
}

impl Block<'_> {
    /// `frames` samples of silence, no events.
    pub fn silent(frames: usize) -> Block<'static> {
        Block {
            frames,
            ..Block::default()
        }
    }
}

/// What one `process()` call returned.
#[derive(Debug)]
pub struct Processed<'a> {
    pub left: &'a [f32],
    pub right: &'a [f32],
    pub status: ProcessStatus,
}

/// Input for [`TestPlugin::render`]: sidechain and main-input signals (zero-padded) and events
/// with times from the start of the render.
#[derive(Clone, Debug, Default)]
pub struct Score {
    pub sidechain: Stereo,
    pub main_input: Option<Stereo>,
    pub events: Vec<HostEvent>,
}

impl Score {
    pub fn new() -> Score {
        Score::default()
    }

    /// Adds `value` to the sidechain's left channel at `frame` (an impulse on `@in1`).
    pub fn impulse(self, frame: usize, value: f32) -> Score {
        self.sidechain_sample(frame, value, 0.0)
    }

    /// Adds a sample to both sidechain channels at `frame`.
    pub fn sidechain_sample(mut self, frame: usize, left: f32, right: f32) -> Score {
        self.sidechain.pad_to(frame + 1);
        self.sidechain.left[frame] += left;
        self.sidechain.right[frame] += right;
        self
    }

    pub fn with_sidechain(mut self, signal: Stereo) -> Score {
        self.sidechain = signal;
        self
    }

    pub fn with_main_input(mut self, signal: Stereo) -> Score {
        self.main_input = Some(signal);
        self
    }

    pub fn event(mut self, event: HostEvent) -> Score {
        self.events.push(event);
        self
    }

    /// A note-on on MIDI channel 0.
    pub fn note_on(self, frame: u32, key: u8, velocity: f64) -> Score {
        self.note_on_channel(frame, key, velocity, 0)
    }

    /// A note-on on MIDI channel `channel` (0 … 15; MPE member channels are 1 … 15).
    pub fn note_on_channel(self, frame: u32, key: u8, velocity: f64, channel: u8) -> Score {
        self.event(HostEvent::NoteOn {
            time: frame,
            key,
            velocity,
            channel,
            note_id: None,
        })
    }

    /// A note-on on MIDI channel 0 with the host's note id `note_id`, the handle of its
    /// note expressions and polyphonic modulations.
    pub fn note_on_id(self, frame: u32, key: u8, velocity: f64, note_id: u32) -> Score {
        self.event(HostEvent::NoteOn {
            time: frame,
            key,
            velocity,
            channel: 0,
            note_id: Some(note_id),
        })
    }

    /// A CLAP note expression for the note on channel 0 with this key and id.
    pub fn note_expression(
        self,
        frame: u32,
        key: u8,
        note_id: u32,
        expression: NoteExpressionType,
        value: f64,
    ) -> Score {
        self.event(HostEvent::NoteExpression {
            time: frame,
            key,
            channel: 0,
            note_id: Some(note_id),
            expression,
            value,
        })
    }

    /// A CLAP polyphonic modulation of parameter `id` by `amount` for the note on channel 0
    /// with this key and id.
    pub fn poly_modulation(
        self,
        frame: u32,
        id: ClapId,
        key: u8,
        note_id: u32,
        amount: f64,
    ) -> Score {
        self.event(HostEvent::PolyModulation {
            time: frame,
            id,
            key,
            channel: 0,
            note_id,
            amount,
        })
    }

    /// A note-off on MIDI channel 0.
    pub fn note_off(self, frame: u32, key: u8) -> Score {
        self.event(HostEvent::NoteOff {
            time: frame,
            key,
            velocity: 0.0,
            channel: 0,
            note_id: None,
        })
    }

    /// A pitch bend on MIDI channel 0.
    pub fn pitch_bend(self, frame: u32, value: f64) -> Score {
        self.pitch_bend_channel(frame, value, 0)
    }

    /// A pitch bend on MIDI channel `channel`.
    pub fn pitch_bend_channel(self, frame: u32, value: f64, channel: u8) -> Score {
        self.event(HostEvent::PitchBend {
            time: frame,
            value,
            channel,
        })
    }

    /// A MIDI channel pressure (0..=1) on MIDI channel `channel`.
    pub fn channel_pressure(self, frame: u32, value: f64, channel: u8) -> Score {
        self.event(HostEvent::ChannelPressure {
            time: frame,
            value,
            channel,
        })
    }

    /// A MIDI control change (0..=127) on channel 0.
    pub fn controller(self, frame: u32, cc: u8, value: u8) -> Score {
        self.event(HostEvent::Controller {
            time: frame,
            cc,
            value,
        })
    }

    pub fn param(self, frame: u32, id: ClapId, value: f64) -> Score {
        self.event(HostEvent::Param {
            time: frame,
            id,
            value,
        })
    }
}

/// The number of threads in this process (Linux: `/proc/self/task`).
pub fn thread_count() -> usize {
    std::fs::read_dir("/proc/self/task")
        .map(|d| d.count())
        .unwrap_or(0)
}

/// Appends the parameter values among `events` to `into`.
/// The keys of the CLAP note-end (voice terminated) events in `events`.
fn collect_note_ends(events: &EventBuffer, into: &mut Vec<u16>) {
    for event in events.iter() {
        if let Some(e) = event.as_event::<NoteEndEvent>() {
            if let Match::Specific(key) = e.key() {
                into.push(key);
            }
        }
    }
}

fn collect_param_values(events: &EventBuffer, into: &mut Vec<(ClapId, f64)>) {
    for event in events.iter() {
        if let Some(v) = event.as_event::<ParamValueEvent>() {
            if let Some(id) = v.param_id() {
                into.push((id, v.value()));
            }
        }
    }
}

/// The result of [`TestPlugin::render`].
#[derive(Clone, Debug, Default)]
pub struct Rendered {
    pub audio: Stereo,
    /// The status of every block, in order, with the frame each block started at.
    pub statuses: Vec<(usize, ProcessStatus)>,
}

impl Rendered {
    /// The status of the last block.
    pub fn last_status(&self) -> Option<ProcessStatus> {
        self.statuses.last().map(|s| s.1)
    }
}

/// A parameter as the plugin describes it.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamDesc {
    pub id: ClapId,
    pub name: String,
    pub module: String,
    pub min: f64,
    pub max: f64,
    pub default: f64,
    /// `CLAP_PARAM_*` flags.
    pub flags: u32,
}

/// An audio port as the plugin describes it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PortDesc {
    pub name: String,
    pub channels: u32,
    pub is_main: bool,
}

/// A note port as the plugin describes it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NotePortDesc {
    pub name: String,
    /// `CLAP_NOTE_DIALECT_*` bits.
    pub dialects: u32,
    pub preferred: u32,
}

// ---------------------------------------------------------------------------------------------
// The plugin instance
// ---------------------------------------------------------------------------------------------

/// The plugin's extensions, queried once after instantiation.
#[derive(Clone, Copy)]
struct Extensions {
    params: Option<PluginParams>,
    state: Option<PluginState>,
    audio_ports: Option<PluginAudioPorts>,
    audio_ports_config: Option<PluginAudioPortsConfig>,
    note_ports: Option<PluginNotePorts>,
    gui: Option<PluginGui>,
}

/// Host-side buffers of an active plugin, allocated at activation.
struct Io {
    config: PluginAudioConfiguration,
    /// The plugin's input ports, in order, with one buffer per channel.
    inputs: Vec<(PortDesc, Vec<Vec<f32>>)>,
    outputs: Vec<(PortDesc, Vec<Vec<f32>>)>,
    input_ports: AudioPorts,
    output_ports: AudioPorts,
    events: EventBuffer,
    out_events: EventBuffer,
    steady_time: u64,
}

/// One instance of the plugin, loaded from the bundle, with its host.
pub struct TestPlugin {
    /// Declared before `instance`: dropped (stopped and deactivated) first.
    processor: Option<StartedPluginAudioProcessor<TestHost>>,
    io: Option<Io>,
    ext: Extensions,
    /// Parameter values the plugin sent to the host (`CLAP_EVENT_PARAM_VALUE` in the output
    /// events of `process()` and `flush()`), in order.
    param_output: Vec<(ClapId, f64)>,
    /// Keys of the voices the plugin reported ended (CLAP note-end events), in order.
    note_ends: Vec<u16>,
    instance: PluginInstance<TestHost>,
}

impl fmt::Debug for TestPlugin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TestPlugin")
            .field("active", &self.io.as_ref().map(|io| io.config.sample_rate))
            .finish_non_exhaustive()
    }
}

impl Default for TestPlugin {
    fn default() -> Self {
        TestPlugin::new()
    }
}

impl TestPlugin {
    /// Loads the bundle and creates an instance. The calling thread becomes the instance's
    /// main thread (and its audio thread during audio calls).
    pub fn new() -> TestPlugin {
        ROLE.with(|r| r.set(Role::Main));
        let entry = load_entry();
        let info = HostInfo::new(
            "Ressort end-to-end tests",
            "Ressort",
            "https://ressort.audio",
            env!("CARGO_PKG_VERSION"),
        )
        .expect("host info");
        let id = std::ffi::CString::new(PLUGIN_ID).expect("plugin id");
        let factory = entry
            .get_plugin_factory()
            .expect("the bundle has no plugin factory");
        let ids: Vec<String> = factory
            .plugin_descriptors()
            .filter_map(|d| d.id().map(|i| i.to_string_lossy().into_owned()))
            .collect();
        assert!(
            ids.iter().any(|i| i == PLUGIN_ID),
            "the bundle does not contain {PLUGIN_ID}; it has {ids:?}"
        );
        let instance = PluginInstance::<TestHost>::new(
            |_| HostShared::default(),
            |_| HostMainThread::default(),
            &entry,
            &id,
            &info,
        )
        .unwrap_or_else(|e| panic!("could not instantiate {PLUGIN_ID}: {e}"));
        let shared = instance.plugin_shared_handle();
        let ext = Extensions {
            params: shared.get_extension(),
            state: shared.get_extension(),
            audio_ports: shared.get_extension(),
            audio_ports_config: shared.get_extension(),
            note_ports: shared.get_extension(),
            gui: shared.get_extension(),
        };
        let mut plugin = TestPlugin {
            processor: None,
            io: None,
            ext,
            param_output: Vec::new(),
            note_ends: Vec::new(),
            instance,
        };
        plugin.idle();
        plugin
    }

    /// Opens the plugin's editor embedded in the X11 window `parent` (CLAP gui extension:
    /// `is_api_supported`, `create`, `set_scale`, `get_size`, `set_parent`, `show`), as a DAW
    /// does on Linux. Returns the editor's size.
    pub fn open_editor(&mut self, parent: u32) -> Result<(u32, u32), String> {
        let gui = self.ext.gui.ok_or("the plugin has no gui extension")?;
        let handle = self.instance.plugin_handle();
        let config = GuiConfiguration {
            api_type: GuiApiType::X11,
            is_floating: false,
        };
        if !gui.is_api_supported(&handle, config) {
            return Err("the plugin does not support embedded X11 editors".into());
        }
        gui.create(&handle, config)
            .map_err(|e| format!("gui.create: {e:?}"))?;
        let _ = gui.set_scale(&handle, 1.0);
        let size = gui.get_size(&handle).ok_or("gui.get_size failed")?;
        // SAFETY: `parent` is a live X11 window that outlives the editor (the caller destroys
        // the editor with `close_editor` first).
        unsafe { gui.set_parent(&handle, Window::from_x11_handle(parent as _)) }
            .map_err(|e| format!("gui.set_parent: {e:?}"))?;
        gui.show(&handle).map_err(|e| format!("gui.show: {e:?}"))?;
        Ok((size.width, size.height))
    }

    /// Whether the editor can be resized, and its size after asking for `width` × `height`.
    pub fn resize_editor(&mut self, width: u32, height: u32) -> Result<(bool, u32, u32), String> {
        let gui = self.ext.gui.ok_or("the plugin has no gui extension")?;
        let handle = self.instance.plugin_handle();
        let can = gui.can_resize(&handle);
        let asked = GuiSize { width, height };
        let adjusted = gui.adjust_size(&handle, asked).unwrap_or(asked);
        gui.set_size(&handle, adjusted)
            .map_err(|e| format!("gui.set_size: {e:?}"))?;
        let size = gui.get_size(&handle).ok_or("gui.get_size failed")?;
        Ok((can, size.width, size.height))
    }

    /// Hides and destroys the editor.
    pub fn close_editor(&mut self) {
        if let Some(gui) = self.ext.gui {
            let handle = self.instance.plugin_handle();
            let _ = gui.hide(&handle);
            gui.destroy(&handle);
        }
    }

    /// [`TestPlugin::close_editor`], then waits (up to `timeout`) until the process has no
    /// more threads than `threads_before`: baseview tears its window thread down after
    /// `destroy` returns, and a process that exits meanwhile crashes in Mesa's EGL teardown
    /// (`eglTerminate` unloading the DRI driver during `exit`). Returns whether it got there.
    pub fn close_editor_and_wait(
        &mut self,
        threads_before: usize,
        timeout: std::time::Duration,
    ) -> bool {
        self.close_editor();
        let deadline = std::time::Instant::now() + timeout;
        loop {
            if thread_count() <= threads_before {
                return true;
            }
            if std::time::Instant::now() > deadline {
                return false;
            }
            self.idle();
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
    }

    /// The plugin's name from its descriptor.
    pub fn descriptor_name(&self) -> String {
        let factory = self
            .instance
            .entry()
            .get_plugin_factory()
            .expect("plugin factory");
        factory
            .plugin_descriptors()
            .find(|d| d.id().is_some_and(|i| i.to_bytes() == PLUGIN_ID.as_bytes()))
            .and_then(|d| d.name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_default()
    }

    // --- lifecycle -------------------------------------------------------------------------

    /// Activates at `sample_rate` with the given block-size bounds and starts processing.
    /// Panics if the plugin refuses (use [`TestPlugin::try_activate`] to test refusals).
    pub fn activate(&mut self, sample_rate: f64, min_frames: u32, max_frames: u32) {
        if let Err(e) = self.try_activate(sample_rate, min_frames, max_frames) {
            panic!("activation at {sample_rate} Hz, blocks {min_frames}..={max_frames}: {e}");
        }
    }

    /// Activates and starts processing; deactivates first if active.
    pub fn try_activate(
        &mut self,
        sample_rate: f64,
        min_frames: u32,
        max_frames: u32,
    ) -> Result<(), PluginInstanceError> {
        self.deactivate();
        let inputs = self.audio_ports(true);
        let outputs = self.audio_ports(false);
        let config = PluginAudioConfiguration {
            sample_rate,
            min_frames_count: min_frames,
            max_frames_count: max_frames,
        };
        let stopped = self.instance.activate(|_, _| (), config)?;
        let started = match as_audio_thread(|| stopped.start_processing()) {
            Ok(s) => s,
            Err(e) => {
                self.instance.deactivate(e.into_stopped_processor());
                return Err(PluginInstanceError::StartProcessingFailed);
            }
        };
        let frames = max_frames as usize;
        let buffers = |ports: Vec<PortDesc>| -> Vec<(PortDesc, Vec<Vec<f32>>)> {
            ports
                .into_iter()
                .map(|p| {
                    let channels = (0..p.channels).map(|_| vec![0.0; frames]).collect();
                    (p, channels)
                })
                .collect()
        };
        let channels = |ports: &[PortDesc]| ports.iter().map(|p| p.channels as usize).sum();
        self.io = Some(Io {
            config,
            input_ports: AudioPorts::with_capacity(channels(&inputs), inputs.len()),
            output_ports: AudioPorts::with_capacity(channels(&outputs), outputs.len()),
            inputs: buffers(inputs),
            outputs: buffers(outputs),
            events: EventBuffer::with_capacity(256),
            out_events: EventBuffer::with_capacity(256),
            steady_time: 0,
        });
        self.processor = Some(started);
        self.idle();
        Ok(())
    }

    /// Stops processing and deactivates, if active.
    pub fn deactivate(&mut self) {
        if let Some(started) = self.processor.take() {
            let stopped = as_audio_thread(|| started.stop_processing());
            self.instance.deactivate(stopped);
        }
        self.io = None;
        self.idle();
    }

    pub fn is_active(&self) -> bool {
        self.processor.is_some()
    }

    /// The active configuration.
    pub fn config(&self) -> Option<PluginAudioConfiguration> {
        self.io.as_ref().map(|io| io.config)
    }

    /// Calls the plugin's `reset()` (audio thread).
    pub fn reset(&mut self) {
        if let Some(p) = self.processor.as_mut() {
            as_audio_thread(|| p.reset());
        }
        self.idle();
    }

    /// The host's main-thread idle work: runs `on_main_thread` when the plugin asked for a
    /// callback, reactivates when it asked for a restart, and flushes parameters when it asked
    /// for a flush while inactive. Called after every block and state operation.
    pub fn idle(&mut self) {
        self.run_callbacks();
        if self.take_request(|s| &s.restart_requested) {
            if let Some(config) = self.config() {
                self.count(|c| c.restarts += 1);
                self.activate(
                    config.sample_rate,
                    config.min_frames_count,
                    config.max_frames_count,
                );
            }
        }
    }

    /// Reads and clears one of the plugin's requests.
    fn take_request(&self, flag: fn(&HostShared) -> &AtomicBool) -> bool {
        self.instance
            .access_shared_handler(|s| flag(s).swap(false, Ordering::AcqRel))
    }

    /// Runs `on_main_thread` if requested and flushes parameters if requested while inactive.
    fn run_callbacks(&mut self) {
        // A callback can request another one; bound the loop.
        for _ in 0..16 {
            if !self.take_request(|s| &s.callback_requested) {
                break;
            }
            self.instance.call_on_main_thread_callback();
            self.count(|c| c.main_thread_callbacks += 1);
        }
        if self.take_request(|s| &s.flush_requested) {
            self.count(|c| c.flush_requests += 1);
            if !self.is_active() {
                self.flush_params(&[]);
            }
        }
        // The host processes continuously: a process request needs no action.
        self.take_request(|s| &s.process_requested);
    }

    fn count(&self, f: impl FnOnce(&mut HostCounters)) {
        self.instance.access_handler(|h| h.count(f));
    }

    /// What the plugin notified the host of so far.
    pub fn counters(&self) -> HostCounters {
        self.instance.access_handler(|h| h.counters.get())
    }

    /// Everything the plugin wrote to the host's log.
    pub fn log(&self) -> Vec<LogMessage> {
        self.instance
            .access_shared_handler(|s| s.log.lock().unwrap_or_else(|e| e.into_inner()).clone())
    }

    // --- ports -----------------------------------------------------------------------------

    /// The plugin's audio ports in the current configuration.
    pub fn audio_ports(&mut self, is_input: bool) -> Vec<PortDesc> {
        let Some(ext) = self.ext.audio_ports else {
            return Vec::new();
        };
        let handle = self.instance.plugin_handle();
        let mut buffer = AudioPortInfoBuffer::new();
        (0..ext.count(&handle, is_input))
            .filter_map(|i| {
                ext.get(&handle, i, is_input, &mut buffer)
                    .map(|info| PortDesc {
                        name: String::from_utf8_lossy(info.name).into_owned(),
                        channels: info.channel_count,
                        is_main: info.flags.contains(AudioPortFlags::IS_MAIN),
                    })
            })
            .collect()
    }

    /// The names of the plugin's audio-port configurations.
    pub fn audio_port_configs(&mut self) -> Vec<String> {
        let Some(ext) = self.ext.audio_ports_config else {
            return Vec::new();
        };
        let handle = self.instance.plugin_handle();
        let mut buffer = AudioPortsConfigBuffer::new();
        (0..ext.count(&handle))
            .filter_map(|i| {
                ext.get(&handle, i, &mut buffer)
                    .map(|c| String::from_utf8_lossy(c.name).into_owned())
            })
            .collect()
    }

    /// Selects an audio-port configuration by name (inactive only).
    pub fn select_audio_config(&mut self, name: &str) -> Result<(), String> {
        if self.is_active() {
            return Err("the plugin is active".into());
        }
        let ext = self
            .ext
            .audio_ports_config
            .ok_or("no audio-ports-config extension")?;
        let handle = self.instance.plugin_handle();
        let mut buffer = AudioPortsConfigBuffer::new();
        let id = (0..ext.count(&handle))
            .filter_map(|i| {
                ext.get(&handle, i, &mut buffer)
                    .map(|c| (c.id, c.name.to_vec()))
            })
            .find(|(_, n)| n == name.as_bytes())
            .map(|(id, _)| id)
            .ok_or_else(|| format!("no audio-port configuration named {name:?}"))?;
        ext.select(&handle, id)
            .map_err(|_| format!("the plugin refused configuration {name:?}"))
    }

    /// The plugin's note ports.
    pub fn note_ports(&mut self, is_input: bool) -> Vec<NotePortDesc> {
        let Some(ext) = self.ext.note_ports else {
            return Vec::new();
        };
        let handle = self.instance.plugin_handle();
        let mut buffer = NotePortInfoBuffer::new();
        (0..ext.count(&handle, is_input))
            .filter_map(|i| {
                ext.get(&handle, i, is_input, &mut buffer)
                    .map(|info| NotePortDesc {
                        name: String::from_utf8_lossy(info.name).into_owned(),
                        dialects: info.supported_dialects.bits(),
                        preferred: info.preferred_dialect.map(|d| d as u32).unwrap_or(0),
                    })
            })
            .collect()
    }

    // --- processing ------------------------------------------------------------------------

    /// Calls `process()` once. Panics when the plugin is inactive, when `frames` is outside
    /// the activated bounds, or when the plugin returns `CLAP_PROCESS_ERROR`.
    pub fn process(&mut self, block: &Block) -> Processed<'_> {
        let status = self.process_inner(block);
        // Callbacks only: a restart would replace the output buffers read below.
        self.run_callbacks();
        let io = self.io.as_ref().expect("active");
        let main = io
            .outputs
            .iter()
            .find(|(p, _)| p.is_main)
            .or(io.outputs.first())
            .expect("the plugin has an output port");
        let n = block.frames;
        let left = &main.1[0][..n];
        let right = main.1.get(1).map(|c| &c[..n]).unwrap_or(left);
        Processed {
            left,
            right,
            status,
        }
    }

    /// Every output channel of the last `process()` call, `frames` long: the main port's
    /// first, then the other ports' in order.
    pub fn all_outputs(&self, frames: usize) -> Vec<Vec<f32>> {
        let io = self.io.as_ref().expect("active");
        let main = io.outputs.iter().filter(|(p, _)| p.is_main);
        let aux = io.outputs.iter().filter(|(p, _)| !p.is_main);
        main.chain(aux)
            .flat_map(|(_, channels)| channels.iter().map(|c| c[..frames].to_vec()))
            .collect()
    }

    fn process_inner(&mut self, block: &Block) -> ProcessStatus {
        let (Some(processor), Some(io)) = (self.processor.as_mut(), self.io.as_mut()) else {
            panic!("process() on an inactive plugin");
        };
        let n = block.frames;
        assert!(
            n >= 1 && n <= io.config.max_frames_count as usize,
            "block of {n} frames outside 1..={}",
            io.config.max_frames_count
        );
        for (port, channels) in io.inputs.iter_mut() {
            let source: &[&[f32]] = if port.is_main {
                block.main_input.as_ref().map_or(&[], |m| m.as_slice())
            } else {
                block.sidechain
            };
            for (c, buffer) in channels.iter_mut().enumerate() {
                let dst = &mut buffer[..n];
                dst.fill(0.0);
                if let Some(src) = source.get(c).copied() {
                    let m = src.len().min(n);
                    dst[..m].copy_from_slice(&src[..m]);
                }
            }
        }
        for (_, channels) in io.outputs.iter_mut() {
            for buffer in channels.iter_mut() {
                // Garbage the plugin must overwrite.
                buffer[..n].fill(f32::NAN);
            }
        }
        io.events.clear();
        let mut events: Vec<HostEvent> = block.events.to_vec();
        events.sort_by_key(HostEvent::time);
        for e in &events {
            assert!(
                (e.time() as usize) < n,
                "event at {} outside a block of {n} frames",
                e.time()
            );
            e.push_to(&mut io.events);
        }
        io.out_events.clear();

        let inputs =
            io.input_ports
                .with_input_buffers(io.inputs.iter_mut().map(|(_, channels)| {
                    AudioPortBuffer {
                        latency: 0,
                        channels: AudioPortBufferType::f32_input_only(
                            channels
                                .iter_mut()
                                .map(|c| InputChannel::variable(&mut c[..n])),
                        ),
                    }
                }));
        let mut outputs = io
            .output_ports
            .with_output_buffers(io.outputs.iter_mut().map(|(_, channels)| AudioPortBuffer {
                latency: 0,
                channels: AudioPortBufferType::f32_output_only(
                    channels.iter_mut().map(|c| &mut c[..n]),
                ),
            }));
        let in_events = InputEvents::from_buffer(&io.events);
        let mut out_events = OutputEvents::from_buffer(&mut io.out_events);
        let steady = io.steady_time;
        let transport = block
            .song_position
            .map(|p| playing_transport(p, io.config.sample_rate));
        let result = as_audio_thread(|| {
            processor.process(
                &inputs,
                &mut outputs,
                &in_events,
                &mut out_events,
                Some(steady),
                transport.as_ref(),
            )
        });
        io.steady_time += n as u64;
        collect_param_values(&io.out_events, &mut self.param_output);
        collect_note_ends(&io.out_events, &mut self.note_ends);
        match result {
            Ok(status) => status,
            Err(e) => panic!("process() failed: {e}"),
        }
    }

    /// Renders `seconds` of audio in blocks of `block_size` frames (the last one shorter),
    /// feeding the score. Events are delivered in the block that contains their time.
    pub fn render(&mut self, seconds: f64, block_size: usize, score: &Score) -> Rendered {
        let sr = self
            .config()
            .expect("render() on an inactive plugin")
            .sample_rate;
        let frames = (seconds * sr).round() as usize;
        self.render_frames(frames, block_size, score)
    }

    /// [`TestPlugin::render`] by frame count.
    pub fn render_frames(&mut self, frames: usize, block_size: usize, score: &Score) -> Rendered {
        self.render_song(frames, &[block_size], None, score)
    }

    /// Renders `frames` samples in blocks whose sizes cycle through `block_sizes`, feeding the
    /// score (event times from the render's start). With `song_start`, the transport plays
    /// and each block carries its song position, `song_start` at the render's first sample.
    pub fn render_song(
        &mut self,
        frames: usize,
        block_sizes: &[usize],
        song_start: Option<u64>,
        score: &Score,
    ) -> Rendered {
        assert!(!block_sizes.is_empty() && block_sizes.iter().all(|&b| b >= 1));
        let block_size = block_sizes[0];
        let mut sidechain = score.sidechain.clone();
        sidechain.pad_to(frames);
        let mut main = score.main_input.clone();
        if let Some(m) = main.as_mut() {
            m.pad_to(frames);
        }
        let mut events = score.events.clone();
        events.sort_by_key(HostEvent::time);
        let mut out = Rendered {
            audio: Stereo {
                left: Vec::with_capacity(frames),
                right: Vec::with_capacity(frames),
            },
            statuses: Vec::with_capacity(frames / block_size + 1),
        };
        let mut next_event = 0;
        let mut start = 0;
        let mut sizes = block_sizes.iter().copied().cycle();
        while start < frames {
            let n = sizes.next().unwrap_or(block_size).min(frames - start);
            let end = start + n;
            let first = next_event;
            while next_event < events.len() && (events[next_event].time() as usize) < end {
                next_event += 1;
            }
            let block_events: Vec<HostEvent> = events[first..next_event]
                .iter()
                .map(|e| e.at(e.time().saturating_sub(start as u32)))
                .collect();
            let sc = [&sidechain.left[start..end], &sidechain.right[start..end]];
            let block = Block {
                frames: n,
                sidechain: &sc,
                main_input: main
                    .as_ref()
                    .map(|m| [&m.left[start..end], &m.right[start..end]]),
                events: &block_events,
                song_position: song_start.map(|s| s + start as u64),
            };
            let processed = self.process(&block);
            out.audio.left.extend_from_slice(processed.left);
            out.audio.right.extend_from_slice(processed.right);
            out.statuses.push((start, processed.status));
            self.idle();
            start = end;
        }
        assert!(
            next_event == events.len(),
            "{} score events lie after the end of the render ({frames} frames)",
            events.len() - next_event
        );
        out
    }

    // --- parameters ------------------------------------------------------------------------

    fn params_ext(&self) -> PluginParams {
        self.ext.params.expect("the plugin has no params extension")
    }

    /// Every parameter the plugin exposes.
    pub fn params(&mut self) -> Vec<ParamDesc> {
        let ext = self.params_ext();
        let handle = self.instance.plugin_handle();
        let mut buffer = ParamInfoBuffer::new();
        (0..ext.count(&handle))
            .filter_map(|i| {
                ext.get_info(&handle, i, &mut buffer).map(|p| ParamDesc {
                    id: p.id,
                    name: String::from_utf8_lossy(p.name).into_owned(),
                    module: String::from_utf8_lossy(p.module).into_owned(),
                    min: p.min_value,
                    max: p.max_value,
                    default: p.default_value,
                    flags: p.flags.bits(),
                })
            })
            .collect()
    }

    /// The parameter named `name`; panics with the list of names when there is none.
    pub fn param(&mut self, name: &str) -> ParamDesc {
        let params = self.params();
        match params.iter().find(|p| p.name == name) {
            Some(p) => p.clone(),
            None => panic!(
                "no parameter named {name:?}; the plugin has {:?}",
                params.iter().map(|p| &p.name).collect::<Vec<_>>()
            ),
        }
    }

    /// A parameter's current plain value.
    pub fn param_value(&mut self, id: ClapId) -> Option<f64> {
        let ext = self.params_ext();
        ext.get_value(&self.instance.plugin_handle(), id)
    }

    /// The plugin's text for a plain value of a parameter.
    pub fn param_text(&mut self, id: ClapId, value: f64) -> Option<String> {
        let ext = self.params_ext();
        let mut buffer = [0u8; 256];
        ext.value_to_text(&self.instance.plugin_handle(), id, value, &mut buffer)
            .ok()
            .map(|b| String::from_utf8_lossy(b).into_owned())
    }

    /// The value the plugin reads from `text` (`clap_plugin_params.text_to_value`).
    pub fn param_value_of_text(&mut self, id: ClapId, text: &str) -> Option<f64> {
        let ext = self.params_ext();
        let text = std::ffi::CString::new(text).ok()?;
        ext.text_to_value(&self.instance.plugin_handle(), id, &text)
    }

    /// Sets parameters outside `process()` through `clap_plugin_params.flush` (on the main
    /// thread when inactive, on the audio thread when active, as CLAP requires).
    pub fn flush_params(&mut self, values: &[(ClapId, f64)]) {
        let ext = self.params_ext();
        let mut input = EventBuffer::with_capacity(values.len());
        for &(id, value) in values {
            input.push(&ParamValueEvent::new(0, id, Pckn::match_all(), value));
        }
        let mut output = EventBuffer::new();
        let in_events = InputEvents::from_buffer(&input);
        let mut out_events = OutputEvents::from_buffer(&mut output);
        if let Some(processor) = self.processor.as_mut() {
            as_audio_thread(|| {
                let mut handle = processor.plugin_handle();
                ext.flush_active(&mut handle, &in_events, &mut out_events);
            });
        } else {
            let mut handle = self
                .instance
                .inactive_plugin_handle()
                .expect("inactive plugin");
            ext.flush(&mut handle, &in_events, &mut out_events);
        }
        collect_param_values(&output, &mut self.param_output);
        self.idle();
    }

    /// The parameter values the plugin has sent to the host since the last call.
    /// The keys of the voices reported ended since the last call.
    pub fn take_note_ends(&mut self) -> Vec<u16> {
        std::mem::take(&mut self.note_ends)
    }

    pub fn take_param_output(&mut self) -> Vec<(ClapId, f64)> {
        std::mem::take(&mut self.param_output)
    }

    // --- state -----------------------------------------------------------------------------

    fn state_ext(&self) -> PluginState {
        self.ext.state.expect("the plugin has no state extension")
    }

    /// Saves the plugin's state.
    pub fn save_state(&mut self) -> Vec<u8> {
        let ext = self.state_ext();
        let mut bytes = Vec::new();
        ext.save(&self.instance.plugin_handle(), &mut bytes)
            .unwrap_or_else(|e| panic!("saving the state failed: {e}"));
        self.idle();
        bytes
    }

    /// Loads a state saved by [`TestPlugin::save_state`] (or a corrupted one).
    pub fn load_state(&mut self, bytes: &[u8]) -> Result<(), StateError> {
        let ext = self.state_ext();
        let mut reader: &[u8] = bytes;
        let result = ext.load(&self.instance.plugin_handle(), &mut reader);
        self.idle();
        result
    }
}

impl Drop for TestPlugin {
    fn drop(&mut self) {
        self.deactivate();
    }
}

// ---------------------------------------------------------------------------------------------
// nice-plug state blobs
// ---------------------------------------------------------------------------------------------

/// Helpers for nice-plug's state format: an 8-byte little-endian length, then JSON
/// `{"version", "params": {string id: plain value}, "fields": {name: JSON text}}`. Ressort keeps
/// its model in the field `"model"`: `{"name": …, "script": …}`.
pub mod fixtures;
pub mod presets;
pub mod screen;

pub mod state {
    use serde_json::Value;

    /// The JSON part of a state blob.
    pub fn json(blob: &[u8]) -> Option<Value> {
        let len = u64::from_le_bytes(blob.get(..8)?.try_into().ok()?) as usize;
        serde_json::from_slice(blob.get(8..8 + len)?).ok()
    }

    /// A state blob around JSON bytes (the length prefix added).
    pub fn blob(json: &[u8]) -> Vec<u8> {
        let mut out = (json.len() as u64).to_le_bytes().to_vec();
        out.extend_from_slice(json);
        out
    }

    /// A state blob from a JSON value.
    pub fn blob_from(value: &Value) -> Vec<u8> {
        blob(&serde_json::to_vec(value).expect("JSON"))
    }

    /// The model (name, script) saved in a state blob.
    pub fn model(blob: &[u8]) -> Option<(String, String)> {
        let v = json(blob)?;
        let field = v.get("fields")?.get("model")?.as_str()?;
        let m: Value = serde_json::from_str(field).ok()?;
        Some((
            m.get("name")?.as_str()?.to_string(),
            m.get("script")?.as_str()?.to_string(),
        ))
    }

    /// A plain parameter value saved in a state blob, by the parameter's string id.
    pub fn param(blob: &[u8], id: &str) -> Option<Value> {
        json(blob)?.get("params")?.get(id).cloned()
    }

    /// A copy of a state blob with another model.
    pub fn with_model(blob: &[u8], name: &str, script: &str) -> Vec<u8> {
        let mut v = json(blob).expect("a valid state blob");
        let model = serde_json::json!({ "name": name, "script": script }).to_string();
        v["fields"]["model"] = Value::String(model);
        blob_from(&v)
    }

    /// A copy of a state blob with another model, played by today's conventions (concert
    /// pitch, automatic levels): a state [`with_model`] writes has no `playing` field, as
    /// projects saved before them, and plays as they did.
    pub fn with_musical_model(blob: &[u8], name: &str, script: &str) -> Vec<u8> {
        let mut v = json(blob).expect("a valid state blob");
        let model =
            serde_json::json!({ "name": name, "script": script, "playing": "musical" }).to_string();
        v["fields"]["model"] = Value::String(model);
        blob_from(&v)
    }

    /// The `playing` field of the model saved in a state blob (None: a legacy project's).
    pub fn playing(blob: &[u8]) -> Option<String> {
        let v = json(blob)?;
        let field = v.get("fields")?.get("model")?.as_str()?;
        let m: Value = serde_json::from_str(field).ok()?;
        Some(m.get("playing")?.as_str()?.to_string())
    }

    /// A copy of a state blob with a persistent field set to `json` (its JSON text).
    pub fn with_field(blob: &[u8], name: &str, json: &str) -> Vec<u8> {
        let mut v = self::json(blob).expect("a valid state blob");
        v["fields"][name] = Value::String(json.to_string());
        blob_from(&v)
    }

    /// A copy of a state blob with a parameter set (plain value, by string id).
    pub fn with_param(blob: &[u8], id: &str, value: Value) -> Vec<u8> {
        let mut v = json(blob).expect("a valid state blob");
        v["params"][id] = value;
        blob_from(&v)
    }
}

// ---------------------------------------------------------------------------------------------
// Process isolation
// ---------------------------------------------------------------------------------------------

/// The environment variable that tells a test binary it runs one isolated test.
pub const CHILD_ENV: &str = "RESSORT_E2E_CHILD";

/// Runs a test in its own process, for tests that can crash the process (an abort inside the
/// plugin ends every test sharing the process). Call it first in the test:
///
/// ```no_run
/// # fn f() {
/// if !ressort_tests::run_isolated("my_test") {
///     return; // the parent: the child ran the test and passed
/// }
/// // … the test body, running in the child …
/// # }
/// ```
///
/// In the parent it re-runs the test binary filtered to `test_name`, forwards its output and
/// panics (with the signal, if any) when the child fails; it returns `false`. In the child it
/// returns `true`.
pub fn run_isolated(test_name: &str) -> bool {
    if std::env::var(CHILD_ENV).as_deref() == Ok(test_name) {
        return true;
    }
    let exe = std::env::current_exe().expect("the test binary's path");
    let output = std::process::Command::new(exe)
        .args([test_name, "--exact", "--nocapture", "--test-threads=1"])
        .env(CHILD_ENV, test_name)
        .output()
        .expect("spawn the isolated test");
    let stdout = String::from_utf8_lossy(&output.stdout);
    print!("{stdout}");
    // The child's stderr can hold thousands of plugin log lines: keep its head, its tail
    // (where a crash's backtrace is) and every panic message in between.
    let stderr = String::from_utf8_lossy(&output.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    let (head, tail) = (20, 150);
    if lines.len() > head + tail + 1 {
        let middle = &lines[head..lines.len() - tail];
        let panics: Vec<&&str> = middle.iter().filter(|l| l.contains("panicked")).collect();
        for line in &lines[..head] {
            eprintln!("{line}");
        }
        eprintln!(
            "[… {} lines of the isolated test's stderr left out, but these panics …]",
            middle.len() - panics.len()
        );
        for line in panics {
            eprintln!("{line}");
        }
        eprintln!("[…]");
        for line in &lines[lines.len() - tail..] {
            eprintln!("{line}");
        }
    } else {
        eprint!("{stderr}");
    }
    assert!(
        stdout.contains("running 1 test"),
        "the isolated run did not find test {test_name:?}"
    );
    if !output.status.success() {
        panic!(
            "{test_name} failed in its own process: {}",
            describe_exit(&output.status)
        );
    }
    false
}

fn describe_exit(status: &std::process::ExitStatus) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        if let Some(signal) = status.signal() {
            let name = match signal {
                6 => " (SIGABRT: the process aborted)",
                9 => " (SIGKILL)",
                11 => " (SIGSEGV)",
                _ => "",
            };
            return format!("killed by signal {signal}{name}");
        }
    }
    format!("{status}")
}

// ---------------------------------------------------------------------------------------------
// Measurements
// ---------------------------------------------------------------------------------------------

/// The frequency of the strongest spectral peak of `signal` between `lo_hz` and `hi_hz`:
/// mean removed, Hann window, FFT (realfft), parabolic interpolation of the log magnitude
/// around the peak bin. For a steady sinusoid over N samples the error is a small fraction
/// of a bin (SR/N).
pub fn peak_frequency(signal: &[f32], sample_rate: f64, lo_hz: f64, hi_hz: f64) -> f64 {
    let n = signal.len();
    let spectrum = hann_spectrum(signal);
    let bin_hz = sample_rate / n as f64;
    let lo = ((lo_hz / bin_hz).floor() as usize).max(1);
    let hi = ((hi_hz / bin_hz).ceil() as usize).min(spectrum.len() - 2);
    assert!(lo < hi, "empty search band {lo_hz}..{hi_hz} Hz");
    let mag: Vec<f64> = spectrum.iter().map(|c| c.norm().max(1e-300)).collect();
    let k = (lo..=hi)
        .max_by(|&a, &b| mag[a].total_cmp(&mag[b]))
        .expect("band");
    let (a, b, c) = (mag[k - 1].ln(), mag[k].ln(), mag[k + 1].ln());
    let denominator = a - 2.0 * b + c;
    let delta = if denominator.abs() > 0.0 {
        (0.5 * (a - c) / denominator).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    (k as f64 + delta) * bin_hz
}

/// The spectrum of a signal with its mean removed, under a Hann window (realfft).
fn hann_spectrum(signal: &[f32]) -> Vec<realfft::num_complex::Complex<f64>> {
    use realfft::RealFftPlanner;
    let n = signal.len();
    assert!(n >= 16, "too short for a spectrum: {n} samples");
    let mean = signal.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
    let mut buf: Vec<f64> = signal
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
            (v as f64 - mean) * w
        })
        .collect();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut spectrum = fft.make_output_vec();
    fft.process(&mut buf, &mut spectrum).expect("FFT");
    spectrum
}

/// The share of a signal's energy between `lo_hz` and `hi_hz` (mean removed, Hann window):
/// 1 when all of it lies in the band.
pub fn band_energy_share(signal: &[f32], sample_rate: f64, lo_hz: f64, hi_hz: f64) -> f64 {
    let n = signal.len();
    let spectrum = hann_spectrum(signal);
    let bin_hz = sample_rate / n as f64;
    let power: Vec<f64> = spectrum.iter().map(|c| c.norm_sqr()).collect();
    let total: f64 = power.iter().sum();
    let band: f64 = power
        .iter()
        .enumerate()
        .filter(|(k, _)| (lo_hz..=hi_hz).contains(&(*k as f64 * bin_hz)))
        .map(|(_, p)| p)
        .sum();
    if total > 0.0 {
        band / total
    } else {
        0.0
    }
}

/// The interval from `b` to `a` in cents.
pub fn cents(a: f64, b: f64) -> f64 {
    1200.0 * (a / b).log2()
}

/// The undamped frequency of a mass-spring oscillator (script values M, K tuned at
/// 44.1 kHz) at `sample_rate`, by the exact discrete law sin²(πf/SR) = K·(44100/SR)²/(4M),
/// with the Stiffness gain `k_gain` applied to K.
pub fn oscillator_frequency(m: f64, k: f64, k_gain: f64, sample_rate: f64) -> f64 {
    let r = 44_100.0 / sample_rate;
    let s2 = k_gain * k * r * r / (4.0 * m);
    assert!(s2 < 1.0, "unstable oscillator: sin² = {s2}");
    sample_rate / std::f64::consts::PI * s2.sqrt().asin()
}

/// The default preset (Mesh 15×15) as a project saved before concert pitch and the automatic
/// levels: Output Gain +24 dB and the sidechain as raw force, so a one-sample impulse of
/// −0.05 on `@in1` throws its hammer (the automatic sidechain trim of a new project scales a
/// drum to strike like a note; a single sample carries too little of a drum's push). For the
/// tests of the plugin's mechanics (block sizes, sample rates, bad input, sleeping) that
/// strike it with impulses.
pub fn struck_default() -> TestPlugin {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/mesh-15x15.mdl"),
    )
    .expect("models/mesh-15x15.mdl");
    plugin_with_model(
        "mesh-15x15",
        &text,
        &[("output_gain", serde_json::json!({ "f32": 24.0 }))],
    )
}

/// A new instance running `script` (loaded through the plugin state while inactive), with
/// plain parameter values set in the same state (`(string id, JSON value)`).
/// The state has no `playing` field: the model plays as in a project saved before concert
/// pitch and the automatic levels (relative tuning, raw sidechain, no trim).
pub fn plugin_with_model(
    name: &str,
    script: &str,
    params: &[(&str, serde_json::Value)],
) -> TestPlugin {
    plugin_with(name, script, params, false)
}

/// [`plugin_with_model`] for a model chosen today: concert pitch and the automatic levels (the
/// state says `"playing": "musical"`).
pub fn plugin_with_musical_model(
    name: &str,
    script: &str,
    params: &[(&str, serde_json::Value)],
) -> TestPlugin {
    plugin_with(name, script, params, true)
}

fn plugin_with(
    name: &str,
    script: &str,
    params: &[(&str, serde_json::Value)],
    musical: bool,
) -> TestPlugin {
    let mut plugin = TestPlugin::new();
    let mut blob = if musical {
        state::with_musical_model(&plugin.save_state(), name, script)
    } else {
        state::with_model(&plugin.save_state(), name, script)
    };
    for (id, value) in params {
        blob = state::with_param(&blob, id, value.clone());
    }
    plugin
        .load_state(&blob)
        .unwrap_or_else(|e| panic!("loading model {name}: {e}"));
    let saved = plugin.save_state();
    assert_eq!(
        state::model(&saved).map(|m| m.1).as_deref(),
        Some(script),
        "the plugin did not take model {name}"
    );
    // While inactive the plugin only parses a script; it compiles it at activation and runs
    // the default preset instead when that fails. Activate once so a script that parses but
    // does not compile fails here, not as a test of the default preset.
    plugin.activate(48_000.0, 1, 512);
    let compiled = plugin.save_state();
    plugin.deactivate();
    assert_eq!(
        state::model(&compiled).map(|m| m.1).as_deref(),
        Some(script),
        "model {name} parses but does not compile: the plugin fell back to {:?}",
        state::model(&compiled).map(|m| m.0)
    );
    plugin
}

/// A playing transport at `position` samples: seconds, and beats at 120 BPM in 4/4.
fn playing_transport(position: u64, sample_rate: f64) -> TransportEvent {
    let seconds = position as f64 / sample_rate;
    let beats = seconds * 2.0;
    TransportEvent {
        header: EventHeader::new_core(0, EventFlags::empty()),
        flags: TransportFlags::IS_PLAYING
            | TransportFlags::HAS_SECONDS_TIMELINE
            | TransportFlags::HAS_BEATS_TIMELINE
            | TransportFlags::HAS_TEMPO
            | TransportFlags::HAS_TIME_SIGNATURE,
        song_pos_beats: BeatTime::from_float(beats),
        song_pos_seconds: SecondsTime::from_float(seconds),
        tempo: 120.0,
        tempo_inc: 0.0,
        loop_start_beats: BeatTime::from_int(0),
        loop_end_beats: BeatTime::from_int(0),
        loop_start_seconds: SecondsTime::from_int(0),
        loop_end_seconds: SecondsTime::from_int(0),
        bar_start: BeatTime::from_float((beats / 4.0).floor() * 4.0),
        bar_number: (beats / 4.0).floor() as i32,
        time_signature_numerator: 4,
        time_signature_denominator: 4,
    }
}
