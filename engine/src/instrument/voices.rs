//! The voice bank: polyphony as copies of one compiled model. Every voice has its own state,
//! its own tuning (class gains) and strike, and shares the structure and the coefficients'
//! expressions; the bank sums their outputs. Capacity is reserved when the model is prepared,
//! so starting, stealing and freeing a voice never allocates.
//!
//! A note takes a free voice, resets it to the model's initial state (spec §1.5), tunes it to
//! the note by the exact law and strikes it. When `limit` voices sound, the quietest one is
//! stolen: it fades out over [`STEAL_FADE_MS`] in a spare slot while the new note starts at
//! once. A voice frees itself when its motion has stayed below [`FREE_LEVEL`] for
//! [`FREE_AFTER_MS`]: the largest distance any point moved in the last sample or since the last
//! check ([`MOTION_CHECK`] samples earlier) — a state check, as mi-gen~'s Drunk Triangles does
//! with the gap between its falling mass and the triangle, not an output level. Where a point
//! comes to rest does not matter: gravity and contacts leave static offsets (a dropped mass
//! lies on its triangle, away from where it started).

use super::exciters::{self, Exciter, Gestures};
use super::gains::{Controlled, Gains, TuneKey, TuningMemo};
use super::CHUNK;
use crate::sim::lanes::{LaneEngine, LANES};
use crate::{Engine, ParamId, ScaleClass};

mod upkeep;

/// The fade-out of a stolen voice.
pub const STEAL_FADE_MS: f64 = 5.0;
/// Motion (model units) below which a voice counts as silent.
pub const FREE_LEVEL: f64 = 1e-6;
/// How long a voice must stay silent before it frees itself.
pub const FREE_AFTER_MS: f64 = 250.0;
/// Samples between two motion checks. A check reads every point of every sounding voice:
/// once per 16-sample chunk it took 7 % of the time of 16 voices of a 100-mass string.
pub const MOTION_CHECK: u64 = 64;

/// What a voice is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VoiceState {
    Free,
    /// Its key is down (or the sustain pedal holds it).
    Held,
    /// Its key is up: it rings on, under the Release damper.
    Released,
    /// Stolen: fading out, then free.
    Fading,
}

/// One voice: what it plays and how it sounds; its copy of the model is in
/// [`VoiceBank`]'s [`Copies`].
#[derive(Clone, Debug)]
pub struct Voice {
    pub state: VoiceState,
    pub note: u8,
    pub channel: u8,
    pub voice_id: Option<i32>,
    /// Semitones from the reference key.
    pub note_st: f64,
    /// The voice's own expression: MPE member bend and note tuning (semitones), pressure
    /// (0 … 1), and the polyphonic modulation of Stiffness and Damping (octaves).
    pub bend_st: f64,
    pub tuning_st: f64,
    pub pressure: f64,
    pub mod_k: f64,
    pub mod_z: f64,
    /// The key went up while the sustain pedal was down.
    pub pedal_held: bool,
    /// When it started, to tell old voices from new.
    pub started: u64,
    /// Samples spent below [`FREE_LEVEL`], and the last motion measured.
    quiet: u64,
    pub level: f64,
    /// Every point's position at the last check (voices on engines; a lane group keeps its own).
    last: Vec<f64>,
    /// Output gain (1 but while fading) and its step per sample.
    gain: f64,
    fade_step: f64,
    /// The strike (velocity response, 0 … 1) waiting for the voice's next span.
    pub strike: f64,
    /// What the voice was last tuned with, and the gains that gave (see `tune_voice`).
    pub tuned: Option<(TuneKey, Gains)>,
    /// The tuning gain of the voice's last pitch (see `Smoothed::gains_offset`).
    pub tuning: TuningMemo,
    /// The voice's exciter gestures, the velocity response they start with at the voice's next
    /// span, whether one still moves or holds its input (the voice then stays), and the
    /// samples a strike without a key (the editor's, a sidechain trigger's) holds them.
    pub gestures: Gestures,
    pub onset: Option<f64>,
    pub sustaining: bool,
    pub strike_hold: u64,
}

/// What every voice of a span hears besides the host's inputs: its strike, its pressure and
/// its exciters.
#[derive(Clone, Copy, Debug)]
pub struct Drive<'a> {
    /// The input a note strikes, and the force of a strike per unit of velocity response.
    pub note_input: Option<usize>,
    pub strike_force: f64,
    /// The `~pressure` input and what full pressure adds to it.
    pub pressure: Option<(usize, f64)>,
    pub exciters: &'a [Exciter],
    /// What a force input's value is multiplied by (the Force Gain, the rate scale).
    pub force: f64,
    /// Each output's value at rest, taken off every voice.
    pub rest_out: &'a [f64],
}

impl Drive<'_> {
    /// Nothing but the host's inputs (a model fading out).
    pub const NONE: Drive<'static> = Drive {
        note_input: None,
        strike_force: 0.0,
        pressure: None,
        exciters: &[],
        force: 0.0,
        rest_out: &[],
    };
}

/// A voice that ended, for the host (CLAP voice-terminated events).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ended {
    pub note: u8,
    pub channel: u8,
    pub voice_id: Option<i32>,
}

/// Models of at most this many points run in lanes even when the bank has fewer voices than
/// a lane group holds (see `VoiceBank::new`).
const SMALL_MODEL_POINTS: usize = 16;

/// The voices' copies of the model: one engine each, or voice lanes (voice i is lane i mod
/// [`LANES`] of group i / [`LANES`]) for the models [`LaneEngine::supports`], when the bank
/// can fill half a group or the model is small (`VoiceBank::new`).
#[derive(Clone, Debug)]
pub enum Copies {
    Engines(Vec<Engine>),
    Lanes(Vec<LaneEngine>),
}

/// Where the controls of one voice go: its engine, or its lane.
#[derive(Debug)]
pub enum VoiceCopy<'a> {
    Engine(&'a mut Engine),
    Lane(&'a mut LaneEngine, usize),
}

impl Controlled for VoiceCopy<'_> {
    fn set_class_gain(&mut self, class: ScaleClass, gain: f64) {
        match self {
            VoiceCopy::Engine(e) => e.set_class_gain(class, gain),
            VoiceCopy::Lane(g, l) => g.set_class_gain(*l, class, gain),
        }
    }
    fn set_param(&mut self, id: ParamId, value: f64) {
        let _ = match self {
            VoiceCopy::Engine(e) => e.set_param(id, value),
            VoiceCopy::Lane(g, _) => g.set_param(id, value),
        };
    }
}

/// The voices of one prepared model.
#[derive(Clone, Debug)]
pub struct VoiceBank {
    pub voices: Vec<Voice>,
    pub copies: Copies,
    /// Planar scratch like the model's (inputs, then outputs, [`CHUNK`] samples per channel),
    /// [`LANES`] values per sample with lanes.
    inputs: Vec<f64>,
    outputs: Vec<f64>,
    /// With lanes: the sounding voices' outputs summed lane by lane over the groups, laid out
    /// as `outputs` (see `VoiceBank::process`).
    mixed: Vec<f64>,
    /// A lane's positions and delayed positions, copied out.
    x: Vec<f64>,
    xp: Vec<f64>,
    /// A 3-D lane's x and y positions, copied out (empty for a 1-D model).
    ax: Vec<f64>,
    ay: Vec<f64>,
    /// How many voices may sound at once (the Voices setting); the rest of the capacity
    /// holds stolen voices while they fade.
    pub limit: usize,
    clock: u64,
    pub sustain: bool,
    free_after: u64,
    /// Samples since the last motion check.
    unchecked: u64,
    fade_step: f64,
    /// Voices that ended since the host last asked, and how many of those did not fit.
    ended: Vec<Ended>,
    pub ended_dropped: u32,
}

impl VoiceBank {
    /// `limit` voices of `template` (at rest), with room for stolen voices to fade, for
    /// `n_in` inputs and `n_out` outputs. Allocates: call it off the audio thread.
    pub fn new(
        template: &Engine,
        n_in: usize,
        n_out: usize,
        limit: usize,
        sample_rate: f64,
    ) -> VoiceBank {
        let limit = limit.max(1);
        let capacity = limit + (limit / 4).max(1);
        let mut engine = template.clone();
        engine.reset();
        let last = engine.positions().to_vec();
        let points = last.len();
        // Lanes when a bank can fill half a group, or the model is so small that a group
        // costs little more than one engine: otherwise one engine per voice does less work.
        // A group costs about three engines, whatever the model (measured, 48 kHz, one
        // engine against one group of eight sounding lanes: the 20-point struck string 138
        // against 461 ns, the 102-point faust-mi string 302 against 978, the 15 × 15 mesh
        // 845 against 2,347).
        let small = engine.positions().len() <= SMALL_MODEL_POINTS;
        // A 3-D model's lanes step each voice bit for bit as its own engine would (engine
        // test `space_lanes`); the motion display reads a lane's three axes (`axes`).
        let lanes = (limit >= LANES / 2 || small)
            .then(|| LaneEngine::new(&engine))
            .flatten();
        // A 3-D lane's x and y, copied out for the motion display (z goes to `x`).
        let planar = if engine.is_3d() { points } else { 0 };
        let (copies, width) = match lanes {
            Some(group) => (Copies::Lanes(vec![group; capacity.div_ceil(LANES)]), LANES),
            None => (Copies::Engines(vec![engine; capacity]), 1),
        };
        let voice = Voice {
            state: VoiceState::Free,
            note: 0,
            channel: 0,
            voice_id: None,
            note_st: 0.0,
            bend_st: 0.0,
            tuning_st: 0.0,
            pressure: 0.0,
            mod_k: 0.0,
            mod_z: 0.0,
            pedal_held: false,
            started: 0,
            quiet: 0,
            level: 0.0,
            last,
            gain: 1.0,
            fade_step: 0.0,
            strike: 0.0,
            tuned: None,
            tuning: TuningMemo::default(),
            gestures: exciters::AT_REST,
            onset: None,
            sustaining: false,
            strike_hold: 0,
        };
        VoiceBank {
            voices: vec![voice; capacity],
            copies,
            inputs: vec![0.0; n_in * CHUNK * width],
            outputs: vec![0.0; n_out.max(1) * CHUNK * width],
            mixed: vec![0.0; n_out.max(1) * CHUNK * width],
            x: vec![0.0; points],
            xp: vec![0.0; points],
            ax: vec![0.0; planar],
            ay: vec![0.0; planar],
            limit,
            clock: 0,
            sustain: false,
            free_after: (FREE_AFTER_MS * 1e-3 * sample_rate) as u64,
            unchecked: 0,
            fade_step: 1.0 / (STEAL_FADE_MS * 1e-3 * sample_rate).max(1.0),
            ended: Vec::with_capacity(capacity * 4),
            ended_dropped: 0,
        }
    }

    /// Voices that sound (held or released), not counting stolen ones fading out.
    pub fn sounding(&self) -> usize {
        self.voices
            .iter()
            .filter(|v| matches!(v.state, VoiceState::Held | VoiceState::Released))
            .count()
    }

    /// The free voice a note takes: with lanes, one in a group that already runs (its lane
    /// is stepped anyway, so the note costs nothing more), else the first free one. Taking
    /// the first free voice always would wake an idle group while a running one has room: an
    /// arpeggio whose first notes have rung out runs two groups where one does.
    fn free_slot(&self) -> Option<usize> {
        let free = |i: &usize| self.voices[*i].state == VoiceState::Free;
        if let Copies::Lanes(_) = &self.copies {
            let running = (0..self.voices.len())
                .filter(free)
                .find(|&i| self.group_runs(i / LANES));
            if running.is_some() {
                return running;
            }
        }
        (0..self.voices.len()).find(free)
    }

    /// Whether lane group `g` is stepped: any of its voices is not free.
    fn group_runs(&self, g: usize) -> bool {
        self.voices[group(g, self.voices.len())]
            .iter()
            .any(|v| v.state != VoiceState::Free)
    }

    /// How many copies of the model are stepped: lane groups with a voice that is not free,
    /// or engines of voices that are not free.
    #[cfg(test)]
    fn copies_running(&self) -> usize {
        match &self.copies {
            Copies::Engines(_) => self
                .voices
                .iter()
                .filter(|v| v.state != VoiceState::Free)
                .count(),
            Copies::Lanes(g) => (0..g.len()).filter(|&g| self.group_runs(g)).count(),
        }
    }

    /// The most recently started voice that is not free.
    pub fn newest(&self) -> Option<usize> {
        self.voices
            .iter()
            .enumerate()
            .filter(|(_, v)| v.state != VoiceState::Free)
            .max_by_key(|(_, v)| v.started)
            .map(|(i, _)| i)
    }

    /// The controls of voice `i`'s copy of the model.
    pub fn copy(&mut self, i: usize) -> VoiceCopy<'_> {
        match &mut self.copies {
            Copies::Engines(e) => VoiceCopy::Engine(&mut e[i]),
            Copies::Lanes(g) => VoiceCopy::Lane(&mut g[i / LANES], i % LANES),
        }
    }

    /// Voice `i`'s positions on x, y and z, as [`Engine::axes`] gives them (a 1-D model's x
    /// and y are empty). Realtime-safe.
    pub fn axes(&mut self, i: usize) -> [&[f64]; 3] {
        match &self.copies {
            Copies::Engines(e) => e[i].axes(),
            Copies::Lanes(g) => {
                let (group, lane) = (&g[i / LANES], i % LANES);
                group.lane_state(lane, &mut self.x, &mut self.xp);
                group.lane_axis(lane, 0, &mut self.ax);
                group.lane_axis(lane, 1, &mut self.ay);
                [&self.ax, &self.ay, &self.x]
            }
        }
    }

    /// Voice `i`'s positions and delayed positions. Realtime-safe.
    pub fn positions(&mut self, i: usize) -> (&[f64], &[f64]) {
        match &self.copies {
            Copies::Engines(e) => (e[i].positions(), e[i].delayed_positions()),
            Copies::Lanes(g) => {
                g[i / LANES].lane_state(i % LANES, &mut self.x, &mut self.xp);
                (&self.x, &self.xp)
            }
        }
    }

    /// Voice `i`'s copy at the model's initial state.
    fn reset_copy(&mut self, i: usize) {
        match &mut self.copies {
            Copies::Engines(e) => e[i].reset(),
            Copies::Lanes(g) => g[i / LANES].reset_lane(i % LANES),
        }
    }

    /// Starts a note: a free voice (the quietest sounding one is stolen when `limit` sound),
    /// reset to rest, with `strike` waiting for its first sample. Returns the voice's index
    /// so the caller can tune it. Realtime-safe.
    pub fn note_on(
        &mut self,
        note: u8,
        channel: u8,
        voice_id: Option<i32>,
        note_st: f64,
        strike: f64,
    ) -> usize {
        if self.sounding() >= self.limit {
            if let Some(victim) = self.quietest_sounding() {
                self.steal(victim);
            }
        }
        let slot = match self.free_slot() {
            Some(i) => i,
            None => {
                // Every spare slot is still fading: cut the one closest to silence.
                let i = self
                    .voices
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| v.state == VoiceState::Fading)
                    .min_by(|a, b| a.1.gain.total_cmp(&b.1.gain))
                    .map(|(i, _)| i)
                    .unwrap_or(0);
                self.end(i);
                i
            }
        };
        self.clock += 1;
        self.reset_copy(slot);
        // The rest detection's reference (a lane group keeps its own).
        if let Copies::Engines(e) = &self.copies {
            self.voices[slot].last.copy_from_slice(e[slot].positions());
        }
        let v = &mut self.voices[slot];
        v.state = VoiceState::Held;
        v.note = note;
        v.channel = channel;
        v.voice_id = voice_id;
        v.note_st = note_st;
        v.bend_st = 0.0;
        v.tuning_st = 0.0;
        v.pressure = 0.0;
        v.mod_k = 0.0;
        v.mod_z = 0.0;
        v.pedal_held = false;
        v.started = self.clock;
        v.quiet = 0;
        v.level = f64::INFINITY;
        v.gain = 1.0;
        v.fade_step = 0.0;
        v.strike = strike;
        v.tuned = None;
        v.gestures = exciters::AT_REST;
        v.onset = Some(strike);
        v.sustaining = false;
        v.strike_hold = 0;
        slot
    }

    /// Whether an expression addresses voice `i`: by the host's voice id when both have one,
    /// else by note and channel, else (a channel event) every voice of the channel. Free
    /// voices and stolen ones are never addressed.
    pub fn addresses(
        &self,
        i: usize,
        voice_id: Option<i32>,
        note: Option<u8>,
        channel: u8,
    ) -> bool {
        let v = &self.voices[i];
        let live = matches!(v.state, VoiceState::Held | VoiceState::Released);
        let hit = match (voice_id, note) {
            (Some(id), _) if v.voice_id.is_some() => v.voice_id == Some(id),
            (_, Some(n)) => v.note == n && v.channel == channel,
            (Some(_), None) => false,
            (None, None) => v.channel == channel,
        };
        live && hit
    }

    /// A key went up: its held voices are released (held on while the pedal is down).
    pub fn note_off(&mut self, note: u8, channel: u8) {
        let sustain = self.sustain;
        for v in self.voices.iter_mut() {
            if v.state == VoiceState::Held && v.note == note && v.channel == channel {
                if sustain {
                    v.pedal_held = true;
                } else {
                    v.state = VoiceState::Released;
                }
            }
        }
    }

    /// The sustain pedal (CC 64): up releases every voice it held.
    pub fn set_sustain(&mut self, down: bool) {
        self.sustain = down;
        if !down {
            for v in self.voices.iter_mut() {
                if v.state == VoiceState::Held && v.pedal_held {
                    v.pedal_held = false;
                    v.state = VoiceState::Released;
                }
            }
        }
    }

    /// Every voice silent and free at once (a reset).
    pub fn clear(&mut self) {
        for i in 0..self.voices.len() {
            if self.voices[i].state != VoiceState::Free {
                self.end(i);
            }
        }
    }

    fn quietest_sounding(&self) -> Option<usize> {
        self.voices
            .iter()
            .enumerate()
            .filter(|(_, v)| matches!(v.state, VoiceState::Held | VoiceState::Released))
            // Released voices go first, then the quietest, then the oldest.
            .min_by(|a, b| {
                let released = |v: &Voice| v.state != VoiceState::Released;
                released(a.1)
                    .cmp(&released(b.1))
                    .then(a.1.level.total_cmp(&b.1.level))
                    .then(a.1.started.cmp(&b.1.started))
            })
            .map(|(i, _)| i)
    }

    fn steal(&mut self, i: usize) {
        let step = self.fade_step;
        let v = &mut self.voices[i];
        v.state = VoiceState::Fading;
        v.fade_step = step;
        self.push_ended(i);
    }

    /// Frees voice `i` now.
    fn end(&mut self, i: usize) {
        let was_fading = self.voices[i].state == VoiceState::Fading;
        self.voices[i].state = VoiceState::Free;
        self.voices[i].strike = 0.0;
        if !was_fading {
            // A stolen voice was reported when it was stolen.
            self.push_ended(i);
        }
    }

    fn push_ended(&mut self, i: usize) {
        let v = &self.voices[i];
        let e = Ended {
            note: v.note,
            channel: v.channel,
            voice_id: v.voice_id,
        };
        if self.ended.len() < self.ended.capacity() {
            self.ended.push(e);
        } else {
            self.ended_dropped += 1;
        }
    }

    /// Hands over the voices that ended since the last call. Realtime-safe.
    pub fn drain_ended(&mut self, mut f: impl FnMut(Ended)) {
        for e in self.ended.drain(..) {
            f(e);
        }
    }

    /// Runs one span of `len` samples: every voice that is not free hears `inputs` (the
    /// model's planar input scratch) plus its own strike, pressure and exciters ([`Drive`]),
    /// and the voices' outputs, off their rest values, are added to `outputs` (planar, `n_out`
    /// channels). Returns whether a voice's guard tripped (that voice is freed).
    pub fn process(
        &mut self,
        len: usize,
        inputs: &[f64],
        outputs: &mut [f64],
        drive: &Drive<'_>,
    ) -> bool {
        let n_in = inputs.len() / len.max(1);
        let n_out = outputs.len() / len.max(1);
        let mut tripped = false;
        // Out of `self` while the voices are mixed and freed (an empty Vec does not allocate).
        let mut copies = std::mem::replace(&mut self.copies, Copies::Engines(Vec::new()));
        match &mut copies {
            Copies::Engines(engines) => {
                for i in 0..self.voices.len() {
                    if self.voices[i].state == VoiceState::Free {
                        continue;
                    }
                    let vin = &mut self.inputs[..inputs.len()];
                    vin.copy_from_slice(inputs);
                    voice_inputs(&mut self.voices[i], vin, len, 1, 0, drive);
                    let vout = &mut self.outputs[..outputs.len()];
                    let report = engines[i].process(len, vin, vout);
                    if report.tripped || engines[i].is_tripped() {
                        tripped = true;
                        self.end(i);
                        continue;
                    }
                    self.mix(i, len, n_out, 1, 0, outputs, drive.rest_out);
                }
            }
            Copies::Lanes(groups) => {
                // The sounding voices' outputs add up lane by lane in `mixed` (one vector
                // add per frame and group), then across the lanes into `outputs`.
                let mixed = &mut self.mixed[..n_out * len * LANES];
                mixed.fill(0.0);
                for (g, group) in groups.iter_mut().enumerate() {
                    if !self.group_runs(g) {
                        continue;
                    }
                    let (first, last) = (g * LANES, (g * LANES + LANES).min(self.voices.len()));
                    // Every lane hears the host's inputs, plus its own strike and pressure.
                    let vin = &mut self.inputs[..n_in * len * LANES];
                    for (k, x) in inputs.iter().enumerate() {
                        vin[k * LANES..(k + 1) * LANES].fill(*x);
                    }
                    for i in first..last {
                        voice_inputs(&mut self.voices[i], vin, len, LANES, i - first, drive);
                    }
                    let vout = &mut self.outputs[..n_out * len * LANES];
                    let lane_tripped = group.process(len, vin, vout);
                    let mut sounding = [false; LANES];
                    for i in first..last {
                        if self.voices[i].state == VoiceState::Free {
                            continue;
                        }
                        let l = i - first;
                        if lane_tripped[l] || group.is_tripped(l) {
                            tripped = true;
                            self.end(i);
                            continue;
                        }
                        if self.voices[i].state == VoiceState::Fading {
                            self.mix(i, len, n_out, LANES, l, outputs, drive.rest_out);
                        } else {
                            sounding[l] = true;
                        }
                    }
                    let mixed = &mut self.mixed[..n_out * len * LANES];
                    let vout = &self.outputs[..n_out * len * LANES];
                    for (f, (sum, frame)) in mixed
                        .chunks_exact_mut(LANES)
                        .zip(vout.chunks_exact(LANES))
                        .enumerate()
                    {
                        let rest = drive.rest_out.get(f / len).copied().unwrap_or(0.0);
                        for l in 0..LANES {
                            sum[l] += if sounding[l] { frame[l] - rest } else { 0.0 };
                        }
                    }
                }
                let mixed = &self.mixed[..n_out * len * LANES];
                for (o, sum) in outputs[..n_out * len]
                    .iter_mut()
                    .zip(mixed.chunks_exact(LANES))
                {
                    *o += sum.iter().sum::<f64>();
                }
            }
        }
        self.copies = copies;
        tripped
    }

    /// Adds voice `i`'s outputs (lane `lane` of `width` in the scratch), off their `rest`
    /// values, to `outputs`, fading a stolen voice out and freeing it at the end of its fade.
    #[allow(clippy::too_many_arguments)]
    fn mix(
        &mut self,
        i: usize,
        len: usize,
        n_out: usize,
        width: usize,
        lane: usize,
        outputs: &mut [f64],
        rest: &[f64],
    ) {
        let v = &mut self.voices[i];
        let src = &self.outputs;
        let rest_of = |c: usize| rest.get(c).copied().unwrap_or(0.0);
        if v.state == VoiceState::Fading {
            for n in 0..len {
                v.gain -= v.fade_step;
                let g = v.gain.max(0.0);
                for c in 0..n_out {
                    outputs[c * len + n] += (src[(c * len + n) * width + lane] - rest_of(c)) * g;
                }
            }
            if v.gain <= 0.0 {
                v.state = VoiceState::Free;
            }
        } else {
            for c in 0..n_out {
                let r = rest_of(c);
                for (n, o) in outputs[c * len..(c + 1) * len].iter_mut().enumerate() {
                    *o += src[(c * len + n) * width + lane] - r;
                }
            }
        }
    }
}

/// The voices of lane group `g` in a bank of `voices` voices.
fn group(g: usize, voices: usize) -> std::ops::Range<usize> {
    g * LANES..(g * LANES + LANES).min(voices)
}

/// Adds voice `v`'s strike (on the note input's first sample), pressure (on every sample of
/// the `~pressure` input) and exciter gestures to lane `lane` of `width` of the planar inputs
/// `vin`, and consumes the strike.
fn voice_inputs(
    v: &mut Voice,
    vin: &mut [f64],
    len: usize,
    width: usize,
    lane: usize,
    drive: &Drive<'_>,
) {
    let n_in = vin.len() / (len * width).max(1);
    if v.state == VoiceState::Free {
        return;
    }
    if v.strike != 0.0 {
        if let Some(k) = drive.note_input.filter(|k| *k < n_in) {
            vin[k * len * width + lane] += v.strike * drive.strike_force;
        }
        v.strike = 0.0;
    }
    if !drive.exciters.is_empty() {
        if let Some(level) = v.onset.take() {
            exciters::start(&mut v.gestures, drive.exciters, level);
        }
        if v.strike_hold > 0 {
            v.strike_hold = v.strike_hold.saturating_sub(len as u64);
            if v.strike_hold == 0 && v.state == VoiceState::Held {
                v.state = VoiceState::Released;
            }
        }
        let held = v.state == VoiceState::Held;
        exciters::play(
            &mut v.gestures,
            drive.exciters,
            held,
            v.pressure,
            drive.force,
            vin,
            len,
            width,
            lane,
        );
        v.sustaining = exciters::busy(&v.gestures, drive.exciters, held);
    }
    if let Some((k, gain)) = drive.pressure.filter(|(k, _)| *k < n_in) {
        let add = v.pressure * gain;
        if add != 0.0 {
            for n in 0..len {
                vin[(k * len + n) * width + lane] += add;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{compile, parse, CompileOptions};

    fn oscillator() -> crate::Engine {
        let text = "@g ground 0.\n@m mass 1. 0. 0.\n@s springDamper @g @m 0.01 0.001\n\
                    @in1 frcInput @m\n@out1 posOutput @m\n";
        let spec = parse(text).spec.expect("the script parses");
        compile(&spec, &CompileOptions::at(48000.0)).expect("it compiles")
    }

    /// Runs `spans` chunks of the bank, struck on input 1.
    fn run(bank: &mut VoiceBank, spans: usize) {
        let inputs = [0.0; CHUNK];
        let mut outputs = [0.0; CHUNK];
        for _ in 0..spans {
            outputs.fill(0.0);
            let drive = Drive {
                note_input: Some(0),
                strike_force: 1.0,
                ..Drive::NONE
            };
            bank.process(CHUNK, &inputs, &mut outputs, &drive);
        }
    }

    /// Voices spread over four lane groups are packed into as few as hold them, and every voice
    /// goes on bit for bit as it would have where it was.
    #[test]
    fn sounding_voices_are_packed_into_few_lane_groups() {
        let mut bank = VoiceBank::new(&oscillator(), 1, 1, 4 * LANES, 48000.0);
        for n in 0..4 * LANES as u8 {
            // Different strikes, one after the other: every voice in its own state.
            let i = bank.note_on(40 + n, 0, None, 0.0, 0.02 * f64::from(n + 1));
            // Each voice tuned: its own stiffness and damping arguments.
            let mut copy = bank.copy(i);
            copy.set_class_gain(ScaleClass::Stiffness, 1.0 + 0.05 * f64::from(n));
            copy.set_class_gain(ScaleClass::Damping, 2.0 - 0.03 * f64::from(n));
            run(&mut bank, 1);
        }
        // Left sounding: one voice in group 0, two in group 1, one in 2 and one in 3.
        let sounding = [0, LANES + 2, LANES + 3, 2 * LANES + 3, 3 * LANES + 2];
        for i in (0..4 * LANES).filter(|i| !sounding.contains(i)) {
            bank.end(i);
        }
        let mut packed = bank.clone();
        packed.pack();
        assert_eq!(bank.copies_running(), 4);
        assert_eq!(packed.copies_running(), sounding.len().div_ceil(LANES));
        run(&mut bank, 40);
        run(&mut packed, 40);
        let state = |b: &mut VoiceBank, note: u8| {
            let i = (0..b.voices.len())
                .find(|&i| b.voices[i].state != VoiceState::Free && b.voices[i].note == note)
                .expect("the voice still sounds");
            let (x, xp) = b.positions(i);
            (x.to_vec(), xp.to_vec())
        };
        for note in sounding.map(|i| 40 + i as u8) {
            assert_eq!(
                state(&mut bank, note),
                state(&mut packed, note),
                "note {note}"
            );
        }
    }

    /// A note takes a free lane of a running group before it wakes an idle one.
    #[test]
    fn a_note_fills_a_running_lane_group_first() {
        let mut bank = VoiceBank::new(&oscillator(), 1, 1, 2 * LANES, 48000.0);
        assert!(matches!(bank.copies, Copies::Lanes(_)));
        for n in 0..LANES + 2 {
            assert_eq!(bank.note_on(40 + n as u8, 0, None, 0.0, 1.0), n);
        }
        assert_eq!(bank.copies_running(), 2);
        // The first group's voices rang out; two voices still sound in the second group.
        for i in 0..LANES {
            bank.end(i);
        }
        assert_eq!(bank.copies_running(), 1);
        for n in 0..LANES - 2 {
            let slot = bank.note_on(70 + n as u8, 0, None, 0.0, 1.0);
            assert_eq!(slot / LANES, 1, "voice {slot} woke an idle group");
            assert_eq!(bank.copies_running(), 1);
        }
        // The running group is full: the next note needs another.
        assert_eq!(bank.note_on(90, 0, None, 0.0, 1.0), 0);
        assert_eq!(bank.copies_running(), 2);
    }
}
