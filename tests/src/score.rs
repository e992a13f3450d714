//! Signals, events and scores: what the tests send to the plugin and what it sends back.

use super::*;

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

    pub(crate) fn push_to(&self, buffer: &mut EventBuffer) {
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
pub(crate) fn collect_note_ends(events: &EventBuffer, into: &mut Vec<u16>) {
    for event in events.iter() {
        if let Some(e) = event.as_event::<NoteEndEvent>() {
            if let Match::Specific(key) = e.key() {
                into.push(key);
            }
        }
    }
}

pub(crate) fn collect_param_values(events: &EventBuffer, into: &mut Vec<(ClapId, f64)>) {
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
