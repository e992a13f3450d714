//! Models in the plugin: preparing a script off the audio thread, handing it over without
//! locks, and keeping the running script in the plugin state.
//!
//! A script becomes a [`Prepared`] model on the thread that submits it (the host's main
//! thread for a state load or activation), or for the editor on a thread of its own, so that
//! the editor keeps drawing while a large model's analyses run: parse, compile, stability
//! envelope, macro ranges and scratch buffers are all made there. The audio thread receives it
//! through a bounded lock-free channel and sends the replaced model back through another one,
//! so it never allocates or frees. A script with errors never replaces the running model; its
//! diagnostics are kept in [`ModelStore::status`] for the editor.
//!
//! A script whose analyses are not kept plays at once on provisional facts in a realtime
//! host, and takes its exact analyses when a thread of the store has run them ([`refine`]).

mod refine;

use crate::motion::{motion_channel, MotionReader};
use crate::param_text;
use crate::runtime::RuntimeStatus;
use crossbeam_channel::{Receiver, Sender};
use nice_plug::params::persist::PersistentField;
use ressort_engine::instrument;
use ressort_engine::instrument::saved_analyses;
pub use ressort_engine::instrument::units::format_value;
use ressort_engine::instrument::units::MacroUnit;
use ressort_engine::instrument::ModalModel;
pub use ressort_engine::instrument::{
    parse_script, peak_frequency, Facts, HostSettings, InputRole, LoadLine, MacroBinding, Prepared,
    Rejected, StabilityEnvelope, CHUNK, NUM_MACROS, STABILITY_HEADROOM,
};
use ressort_engine::InputUse;
use serde::{Deserialize, Serialize};

/// The largest Voices setting (0 means the script's `~voices`).
pub const MAX_VOICES: usize = 128;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

pub use refine::Refinement;

/// How a saved model is played ([`instrument::Conventions`]), as the state stores it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Playing {
    /// Concert pitch, the automatic output trim and the calibrated sidechain: every model
    /// chosen in a project saved since they came.
    #[default]
    Musical,
    /// A project saved before them (its state has no `playing` field): the relative tuning of
    /// `~key`, no trim, the raw sidechain, as it sounded then.
    Legacy,
}

impl Playing {
    /// What a state without the field means.
    fn legacy() -> Playing {
        Playing::Legacy
    }

    pub fn conventions(self) -> instrument::Conventions {
        match self {
            Playing::Musical => instrument::Conventions::Musical,
            Playing::Legacy => instrument::Conventions::Legacy,
        }
    }
}

/// The saved part of the model: the script of the running model, where it came from, and how
/// it is played.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ModelState {
    /// A preset id (`mesh-25x20`) or a file name or "Custom".
    pub name: String,
    /// The complete script.
    pub script: String,
    /// Absent from projects saved before concert pitch and the automatic levels, which keep
    /// playing as they did.
    #[serde(default = "Playing::legacy")]
    pub playing: Playing,
}

impl ModelState {
    /// A model played by today's conventions.
    pub fn new(name: impl Into<String>, script: impl Into<String>) -> ModelState {
        ModelState {
            name: name.into(),
            script: script.into(),
            playing: Playing::Musical,
        }
    }
}

/// A model as the state saves it: its script and, for a script the plugin does not ship, the
/// analyses the process keeps for it, so that the project reopens without running them
/// ([`instrument::saved_analyses`]). The JSON is [`ModelState`]'s with one more member,
/// `analyses`, which older versions ignore.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SavedModel {
    #[serde(flatten)]
    pub model: ModelState,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub analyses: Option<String>,
}

impl SavedModel {
    /// `model` with the analyses the process keeps for its script.
    pub fn of(model: ModelState) -> SavedModel {
        let analyses = saved_analyses::save(&model.script, model.playing.conventions());
        SavedModel { model, analyses }
    }

    /// Hands the saved analyses to the process's memory (before the script is prepared) and
    /// returns the model. Analyses that cannot be trusted are dropped with the reason on the
    /// log: the script is then analysed as if none had been saved.
    pub fn restore(self) -> ModelState {
        if let Some(text) = &self.analyses {
            let m = &self.model;
            if let Err(why) = saved_analyses::restore(&m.script, m.playing.conventions(), text) {
                nice_plug::nice_warn!(
                    "state: the analyses saved with `{}` were not read ({why}); it is analysed \
                     afresh",
                    m.name
                );
            }
        }
        self.model
    }
}

/// Prepares a script for the instrument ([`instrument::prepare`]) with a motion channel for
/// the editor: the model publishes its positions, the reader goes to the editor.
/// `voices` is the Voices setting: 0 takes the script's `~voices` (1 without one), 1 plays
/// monophonically.
pub fn prepare(
    name: &str,
    text: &str,
    sample_rate: f64,
    voices: usize,
    playing: Playing,
) -> Result<(Prepared, MotionReader), Rejected> {
    let prepared = instrument::prepare_with(name, text, sample_rate, playing.conventions())?;
    Ok(with_voices_and_motion(prepared, sample_rate, voices))
}

/// A prepared model with its voices (`voices` as [`prepare`] takes it) and a motion channel.
fn with_voices_and_motion(
    mut prepared: Prepared,
    sample_rate: f64,
    voices: usize,
) -> (Prepared, MotionReader) {
    let declared = prepared.facts().settings.voices.unwrap_or(1) as usize;
    prepared.set_voices(if voices == 0 { declared } else { voices });
    let (writer, reader) = motion_channel(&prepared.engine, sample_rate);
    prepared.watcher = Some(Box::new(writer));
    (prepared, reader)
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
    /// How each slot reads (Hz, T60, ratio, 0 … 1 or its value).
    pub macro_units: Vec<MacroUnit>,
    pub stability: Vec<String>,
    pub reference_pitch_hz: Option<f64>,
    pub reference_key: f64,
    /// The script's `~voices`.
    pub declared_voices: Option<u32>,
    /// The voices the model was prepared with.
    pub voices: usize,
    /// How the model is played: concert pitch or its own (`~unpitched`), or as a legacy
    /// project did.
    pub playing: Playing,
    pub unpitched: bool,
    /// The highest key in tune at default controls (the stability clamp holds the keys
    /// above).
    pub highest_key: Option<f64>,
    /// The automatic trims, in dB: the output's and the sidechain force's.
    pub output_trim_db: f64,
    pub input_trim_db: f64,
    /// What a key plays: `bow in1`, `strike in2`, … (empty: nothing but a voice of its own).
    pub exciters: Vec<String>,
    /// The model plays on provisional facts while its exact analyses run ([`refine`]).
    pub provisional: bool,
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
    /// `summary.stability` is still to be written from the modal copy ([`ModelStore::status`]).
    stability_pending: bool,
}

/// The editor's description of a model.
pub fn summary(prepared: &Prepared) -> ModelSummary {
    let info = prepared.engine.info();
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
    ModelSummary {
        name: prepared.facts().name.clone(),
        points,
        interactions,
        inputs,
        outputs,
        params,
        macros: prepared.facts().macros.clone(),
        macro_units: prepared.facts().macro_units.clone(),
        stability: Vec::new(),
        reference_pitch_hz: prepared.facts().settings.reference_pitch_hz,
        reference_key: prepared.facts().settings.reference_key,
        declared_voices: prepared.facts().settings.voices,
        voices: prepared.voices(),
        playing: match prepared.facts().conventions {
            instrument::Conventions::Musical => Playing::Musical,
            instrument::Conventions::Legacy => Playing::Legacy,
        },
        unpitched: prepared.facts().settings.unpitched,
        highest_key: prepared.highest_key(),
        output_trim_db: 20.0 * prepared.facts().output_trim.log10(),
        input_trim_db: 20.0 * prepared.facts().input_trim.log10(),
        exciters: prepared
            .facts()
            .exciters
            .iter()
            .map(|x| format!("{} in{}", x.kind.name(), x.input + 1))
            .chain(
                prepared
                    .facts()
                    .note_input
                    .map(|k| format!("strike in{}", k + 1)),
            )
            .collect(),
        provisional: prepared.facts().provisional,
    }
}

/// The summary's stability lines ([`ModelSummary::stability`]): the mass closest to its
/// limit, then the warnings. Labels only the mass shown.
pub fn stability_lines(modal: &ModalModel) -> Vec<String> {
    let (report, worst_label) = modal.stability();
    let mut lines: Vec<String> = report.warnings.iter().map(|w| w.to_string()).collect();
    if let (Some(w), Some(label)) = (report.worst(), worst_label) {
        lines.insert(
            0,
            format!(
                "closest to the limit: @{label} ({:.1} % of 4M used)",
                100.0 * w.load()
            ),
        );
    }
    lines
}

/// A/B compare: two scripts, one of them running. A model change goes into the running slot;
/// switching runs the other one (a copy of the first until it is edited). Saved with the
/// project (`state::CompareField`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Compare {
    pub slots: [Option<ModelState>; 2],
    /// 0 for A, 1 for B.
    pub active: usize,
}

/// How a background submission ([`ModelStore::submit_in_background`]) ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Loaded {
    /// The model runs (or, while the plugin is inactive, the script was checked).
    Running,
    /// The script has errors; the running model is unchanged.
    Rejected(Rejected),
    /// A later submission came first; this one was dropped unprepared.
    Overtaken,
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
    /// Exact facts for the audio thread's provisional model, and the ones it gives back.
    to_refine: (Sender<Refinement>, Receiver<Refinement>),
    refined: (Sender<Refinement>, Receiver<Refinement>),
    /// Models handed to the audio thread (sent, or returned by an activation), so that a
    /// provisional model's exact analyses are dropped once another model replaced it.
    handed: AtomicU64,
    /// Whether the host renders offline ([`ModelStore::activate`]): models are then prepared
    /// in full before they play.
    offline: AtomicBool,
    /// Held by the thread running a provisional model's exact analyses, so that one runs at
    /// a time and those of models replaced meanwhile are skipped.
    refining: Mutex<()>,
    /// The motion reader of the newest model sent to the audio thread, until the editor
    /// takes it.
    motion: Mutex<Option<MotionReader>>,
    /// The Voices setting the next model is prepared with, and whether the running model was
    /// prepared with another.
    voices: AtomicU64,
    voices_stale: AtomicBool,
    /// The A/B compare slots (not saved with the project).
    compare: Mutex<Compare>,
    /// Held while a model is prepared for the audio thread or the plugin (de)activates, so
    /// that a model compiled at one sample rate never arrives after an activation at another
    /// (the editor, the host's main thread and the Voices watch all submit). Never taken by
    /// the audio thread.
    preparing: Mutex<()>,
    /// A copy of the running model for the editor's modal analysis, made when it was prepared.
    modal: Mutex<Option<Arc<ModalModel>>>,
    /// Submissions so far (each takes the next number), so that a background preparation a
    /// later submission overtook is dropped unprepared.
    submissions: AtomicU64,
    /// The number of the newest background submission that finished, and its outcome until
    /// taken (an older one finishing later does not replace it).
    background: Mutex<(u64, Option<Loaded>)>,
    /// The threads of background submissions still running, joined by
    /// [`ModelStore::finish_loads`] so that none outlives the plugin's code.
    loads: Mutex<Vec<JoinHandle<()>>>,
    /// What the audio thread reports.
    pub runtime: RuntimeStatus,
}

impl Default for ModelStore {
    fn default() -> Self {
        let preset = crate::presets::Preset::default_preset();
        ModelStore {
            running: Mutex::new(ModelState::new(preset.id, preset.text)),
            status: Mutex::new(ModelStatus::default()),
            sample_rate: AtomicU64::new(0),
            generation: AtomicU64::new(0),
            to_audio: crossbeam_channel::bounded(4),
            garbage: crossbeam_channel::bounded(64),
            to_refine: crossbeam_channel::bounded(4),
            refined: crossbeam_channel::bounded(16),
            handed: AtomicU64::new(0),
            offline: AtomicBool::new(false),
            refining: Mutex::new(()),
            motion: Mutex::new(None),
            compare: Mutex::new(Compare::default()),
            preparing: Mutex::new(()),
            modal: Mutex::new(None),
            submissions: AtomicU64::new(0),
            background: Mutex::new((0, None)),
            loads: Mutex::new(Vec::new()),
            voices: AtomicU64::new(0),
            voices_stale: AtomicBool::new(false),
            runtime: RuntimeStatus::default(),
        }
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs the job in `slot` unless it has run.
fn run_once<F: FnOnce()>(slot: &Mutex<Option<F>>) {
    let job = lock(slot).take();
    if let Some(job) = job {
        job();
    }
}

impl ModelStore {
    /// The running model's name and script.
    pub fn running(&self) -> ModelState {
        lock(&self.running).clone()
    }

    /// The running model's summary and the last submission's diagnostics. The summary's
    /// stability lines are worked out at the first call after a load, not in the load: they
    /// cost the plate's state load 4 ms, and only the editor shows them.
    pub fn status(&self) -> ModelStatus {
        let mut status = lock(&self.status);
        if status.stability_pending {
            status.stability_pending = false;
            if let Some(modal) = lock(&self.modal).clone() {
                status.summary.stability = stability_lines(&modal);
            }
        }
        status.clone()
    }

    /// The running model's name and the parameter each macro slot is bound to (None for an
    /// unbound slot), cheaply: what the remote-control pages name.
    pub fn macro_names(&self) -> (String, Vec<Option<String>>) {
        let status = lock(&self.status);
        let s = &status.summary;
        let names = s
            .macros
            .iter()
            .map(|m| m.as_ref().map(|b| b.name.clone()))
            .collect();
        (s.name.clone(), names)
    }

    /// The value text of macro slot `slot` at position `normalized`: `K = 0.1200`, or
    /// `unbound` when the model has fewer parameters.
    pub fn macro_text(&self, slot: usize, normalized: f64) -> String {
        let status = lock(&self.status);
        let s = &status.summary;
        match (s.macros.get(slot), s.macro_units.get(slot)) {
            (Some(Some(b)), Some(u)) => u.text(b, normalized),
            (Some(Some(b)), None) => MacroUnit::Value.text(b, normalized),
            _ => param_text::format_unbound_macro(normalized),
        }
    }

    /// The slot position for a macro's text (the inverse of [`ModelStore::macro_text`]):
    /// `K = 0.12` or `0.12` for a slot bound to `K`, `50 %` for an unbound one.
    pub fn macro_from_text(&self, slot: usize, text: &str) -> Option<f64> {
        let status = lock(&self.status);
        let s = &status.summary;
        match (s.macros.get(slot), s.macro_units.get(slot)) {
            (Some(Some(b)), Some(u)) => u.position_of(b, text),
            (Some(Some(b)), None) => MacroUnit::Value.position_of(b, text),
            _ => param_text::parse_unbound_macro(text),
        }
    }

    /// The running model for the modal analysis (None before the first activation).
    pub fn modal_model(&self) -> Option<Arc<ModalModel>> {
        lock(&self.modal).clone()
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

    /// Frees models and facts the audio thread has finished with.
    pub fn collect_garbage(&self) {
        while self.garbage.1.try_recv().is_ok() {}
        while self.refined.1.try_recv().is_ok() {}
    }

    /// Sets the running script from outside the audio thread: a state load, the editor, a
    /// preset. While the plugin is active the model is compiled now and handed to the audio
    /// thread, which crossfades to it; while inactive it is only checked, and
    /// [`ModelStore::activate`] compiles it. A script with errors changes nothing but the
    /// diagnostics.
    pub fn submit(self: &Arc<Self>, state: ModelState) -> Result<(), Rejected> {
        self.submissions.fetch_add(1, Ordering::AcqRel);
        let _preparing = lock(&self.preparing);
        self.submit_prepared(state)
    }

    /// [`ModelStore::submit`] on a thread of its own, for the editor: preparing a model takes
    /// up to a few seconds (its modal analyses), and meanwhile the running model keeps
    /// playing and the editor keeps drawing. Returns the submission's number;
    /// [`ModelStore::take_loaded`] gives its outcome once it is known. A later submission,
    /// from anywhere, overtakes this one if it has not started preparing yet.
    pub fn submit_in_background(self: &Arc<Self>, state: ModelState) -> u64 {
        let ticket = self.submissions.fetch_add(1, Ordering::AcqRel) + 1;
        let store = Arc::clone(self);
        let job = move || {
            let loaded = {
                let _preparing = lock(&store.preparing);
                if store.submissions.load(Ordering::Acquire) != ticket {
                    Loaded::Overtaken
                } else {
                    match store.submit_prepared(state) {
                        Ok(()) => Loaded::Running,
                        Err(rejected) => Loaded::Rejected(rejected),
                    }
                }
            };
            let mut newest = lock(&store.background);
            if newest.0 < ticket {
                *newest = (ticket, Some(loaded));
            }
        };
        self.spawn_joined("ressort-load", job);
        ticket
    }

    /// Runs `job` on a thread of its own named `name`, joined by [`ModelStore::finish_loads`];
    /// here, on the calling thread, when no thread can be had.
    fn spawn_joined(&self, name: &str, job: impl FnOnce() + Send + 'static) {
        // The job is kept where a failed spawn leaves it, to run here instead.
        let job = Arc::new(Mutex::new(Some(job)));
        let spawned = {
            let job = Arc::clone(&job);
            std::thread::Builder::new()
                .name(name.into())
                .spawn(move || run_once(&job))
        };
        match spawned {
            Ok(thread) => {
                let mut loads = lock(&self.loads);
                loads.retain(|t| !t.is_finished());
                loads.push(thread);
            }
            Err(_) => run_once(&job),
        }
    }

    /// Plays a preset or script the user chose (the editor's browser, a host's preset load),
    /// prepared in the background as [`ModelStore::submit_in_background`]. A model chosen in a
    /// legacy project is played as that project's were (its Output Gain was set for them); the
    /// editor's Update button moves the project on.
    pub fn choose_in_background(self: &Arc<Self>, name: String, script: String) -> u64 {
        let playing = self.running().playing;
        self.submit_in_background(ModelState {
            name,
            script,
            playing,
        })
    }

    /// Waits for every background submission to finish (the plugin's drop).
    pub fn finish_loads(&self) {
        let loads = std::mem::take(&mut *lock(&self.loads));
        for thread in loads {
            let _ = thread.join();
        }
    }

    /// The outcome of background submission `ticket`, once, when it has finished.
    pub fn take_loaded(&self, ticket: u64) -> Option<Loaded> {
        let mut newest = lock(&self.background);
        if newest.0 == ticket {
            newest.1.take()
        } else {
            None
        }
    }

    /// [`ModelStore::submit`], with `preparing` held by the caller.
    fn submit_prepared(self: &Arc<Self>, state: ModelState) -> Result<(), Rejected> {
        self.collect_garbage();
        let rate = f64::from_bits(self.sample_rate.load(Ordering::Acquire));
        // This model gets the Voices setting as it stands now, so a setting that changed
        // before is applied by this submission (a state load sets Voices, then the model):
        // the watch must not prepare the model again and cut the notes it plays. A setting
        // that changes from here on marks it stale again.
        let was_stale = rate > 0.0 && self.voices_stale.swap(false, Ordering::AcqRel);
        let voices = self.voices();
        let result = if rate > 0.0 {
            self.prepare_for_audio(&state, rate, voices).map(Some)
        } else {
            parse_script(&state.script).map(|_| None)
        };
        if result.is_err() && was_stale {
            // The running model keeps its old Voices setting.
            self.voices_stale.store(true, Ordering::Release);
        }
        match result {
            Ok(prepared) => {
                let mut status = lock(&self.status);
                status.diagnostics.clear();
                status.rejected = None;
                if let Some((p, reader)) = prepared {
                    status.summary = summary(&p);
                    // The modal copy is replaced under the status lock, so that `status`
                    // never writes the lines of the model before.
                    *lock(&self.modal) = Some(Arc::new(ModalModel::of(&p)));
                    status.stability_pending = true;
                    drop(status);
                    *lock(&self.motion) = Some(reader);
                    let provisional = p
                        .facts()
                        .provisional
                        .then(|| (p.shared_facts(), p.voices()));
                    self.send(Box::new(p));
                    if let Some((facts, voices)) = provisional {
                        self.refine_in_background(state.clone(), rate, voices, facts);
                    }
                }
                let mut compare = lock(&self.compare);
                let active = compare.active;
                compare.slots[active] = Some(state.clone());
                drop(compare);
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

    /// The running model prepared again at the active rate, for work beside the audio thread
    /// (Vary plays its variations on it). The analyses come from the table or the cache, as
    /// for any model seen before, so this takes milliseconds. None while inactive.
    pub fn prepare_copy(&self) -> Option<Result<Prepared, Rejected>> {
        let rate = f64::from_bits(self.sample_rate.load(Ordering::Acquire));
        if rate <= 0.0 {
            return None;
        }
        let state = self.running();
        let voices = self.voices();
        Some(
            instrument::prepare_with(
                &state.name,
                &state.script,
                rate,
                state.playing.conventions(),
            )
            .map(|mut p| {
                let declared = p.facts().settings.voices.unwrap_or(1) as usize;
                p.set_voices(if voices == 0 { declared } else { voices });
                p
            }),
        )
    }

    /// The Voices setting new models are prepared with.
    pub fn voices(&self) -> usize {
        self.voices.load(Ordering::Acquire).min(MAX_VOICES as u64) as usize
    }

    /// The Voices parameter's text: `script (N)` for 0, where N is the running script's
    /// `~voices` (1 without one), else the count.
    pub fn voices_text(&self, setting: i32) -> String {
        if setting <= 0 {
            let declared = lock(&self.status).summary.declared_voices.unwrap_or(1);
            format!("script ({declared})")
        } else {
            setting.to_string()
        }
    }

    /// The Voices parameter moved (on any thread, the audio thread included: this only
    /// stores). The running model is re-prepared by [`ModelStore::apply_voices`] on the main
    /// thread or by the next activation.
    pub fn set_voices(&self, voices: usize) {
        let old = self.voices.swap(voices as u64, Ordering::AcqRel);
        if old != voices as u64 {
            self.voices_stale.store(true, Ordering::Release);
        }
    }

    /// Whether the running model was prepared with another Voices setting.
    pub fn voices_stale(&self) -> bool {
        self.voices_stale.load(Ordering::Acquire)
    }

    /// Re-prepares the running script with the current Voices setting (any thread but the
    /// audio thread; a no-op while inactive or when nothing changed).
    pub fn apply_voices(self: &Arc<Self>) {
        if !self.voices_stale() {
            return;
        }
        // The running script is read under `preparing`: read before it, a state load that
        // submits in between would be undone by the script it replaced.
        let _preparing = lock(&self.preparing);
        let rate = f64::from_bits(self.sample_rate.load(Ordering::Acquire));
        if self.voices_stale() && rate > 0.0 {
            let _ = self.submit_prepared(self.running());
        }
    }

    /// The A/B slots and which one runs.
    pub fn compare(&self) -> Compare {
        let mut c = lock(&self.compare).clone();
        if c.slots[c.active].is_none() {
            c.slots[c.active] = Some(self.running());
        }
        c
    }

    /// Runs the other A/B slot: its script, or a copy of the running one when it is empty
    /// (so B starts where A is). A slot whose script no longer loads keeps the running model
    /// and reports why.
    pub fn switch_compare(self: &Arc<Self>) -> Result<(), Rejected> {
        self.submissions.fetch_add(1, Ordering::AcqRel);
        let _preparing = lock(&self.preparing);
        let running = self.running();
        let mut c = lock(&self.compare);
        let from = c.active;
        let to = 1 - from;
        c.slots[from] = Some(running.clone());
        let target = c.slots[to].clone().unwrap_or(running);
        c.active = to;
        drop(c);
        let result = self.submit_prepared(target);
        if result.is_err() {
            lock(&self.compare).active = from;
        }
        result
    }

    /// The A/B slots of a loaded project. The running slot follows the project's model (the
    /// `model` field, loaded after this one), so only the other slot's script is kept from
    /// here; a slot number other than 0 or 1 reads as A.
    pub fn restore_compare(&self, saved: Compare) {
        let active = if saved.active == 1 { 1 } else { 0 };
        let mut slots = saved.slots;
        slots[active] = None;
        *lock(&self.compare) = Compare { slots, active };
    }

    /// A state the plugin cannot read was refused: nothing changed but the diagnostics,
    /// which say why.
    pub fn refuse_state(&self, why: String) {
        let mut status = lock(&self.status);
        status.diagnostics = vec![why];
        status.rejected = None;
    }

    /// Copies the running script into the other A/B slot.
    pub fn copy_to_other_slot(&self) {
        let running = self.running();
        let mut c = lock(&self.compare);
        let other = 1 - c.active;
        c.slots[other] = Some(running);
    }

    fn send(&self, prepared: Box<Prepared>) {
        // Models still waiting are stale now, and exact facts for the model replaced; drop
        // them here, not on the audio thread.
        while self.to_audio.1.try_recv().is_ok() {}
        while self.to_refine.1.try_recv().is_ok() {}
        self.handed.fetch_add(1, Ordering::AcqRel);
        if self.to_audio.0.try_send(prepared).is_ok() {
            self.generation.fetch_add(1, Ordering::AcqRel);
        }
    }

    /// Compiles the running script for `sample_rate` at activation. When it cannot be
    /// compiled at this rate, the default preset runs instead and the diagnostics say why.
    /// `offline`: the host renders offline, and every model is prepared in full before it
    /// plays, so that a bounce never depends on when a thread finished.
    pub fn activate(self: &Arc<Self>, sample_rate: f64, offline: bool) -> Option<Box<Prepared>> {
        let _preparing = lock(&self.preparing);
        self.voices_stale.store(false, Ordering::Release);
        self.collect_garbage();
        while self.to_audio.1.try_recv().is_ok() {}
        while self.to_refine.1.try_recv().is_ok() {}
        self.offline.store(offline, Ordering::Release);
        self.sample_rate
            .store(sample_rate.to_bits(), Ordering::Release);
        let state = self.running();
        let voices = self.voices();
        let prepared = self.prepare_for_audio(&state, sample_rate, voices);
        let (prepared, reader) = match prepared {
            Ok(p) => p,
            Err(rejected) => {
                let preset = crate::presets::Preset::default_preset();
                let fallback = prepare(
                    preset.id,
                    preset.text,
                    sample_rate,
                    voices,
                    Playing::Musical,
                )
                .ok()?;
                let mut status = lock(&self.status);
                status.diagnostics = rejected.0;
                status.rejected = Some(state);
                drop(status);
                *lock(&self.running) = ModelState::new(preset.id, preset.text);
                fallback
            }
        };
        let mut status = lock(&self.status);
        status.summary = summary(&prepared);
        *lock(&self.modal) = Some(Arc::new(ModalModel::of(&prepared)));
        status.stability_pending = true;
        drop(status);
        *lock(&self.motion) = Some(reader);
        self.handed.fetch_add(1, Ordering::AcqRel);
        if prepared.facts().provisional {
            let state = self.running();
            let voices = prepared.voices();
            self.refine_in_background(state, sample_rate, voices, prepared.shared_facts());
        }
        Some(Box::new(prepared))
    }

    /// Marks the plugin inactive and frees what the audio thread returned.
    pub fn deactivate(&self) {
        let _preparing = lock(&self.preparing);
        self.sample_rate.store(0, Ordering::Release);
        while self.to_audio.1.try_recv().is_ok() {}
        while self.to_refine.1.try_recv().is_ok() {}
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

impl<'a> PersistentField<'a, SavedModel> for Arc<ModelStore> {
    fn set(&self, new_value: SavedModel) {
        // A state whose script does not load keeps the running model; the diagnostics say why.
        let _ = self.submit(new_value.restore());
    }

    fn map<F, R>(&self, f: F) -> R
    where
        F: Fn(&SavedModel) -> R,
    {
        f(&SavedModel::of(self.running()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::Preset;
    use std::time::{Duration, Instant};

    fn preset(id: &str) -> ModelState {
        let p = Preset::find(id).expect("a preset");
        ModelState::new(p.id, p.text)
    }

    /// An active store (48 kHz) running the default preset.
    fn active() -> Arc<ModelStore> {
        let store = Arc::new(ModelStore::default());
        assert!(store.activate(48000.0, true).is_some());
        store
    }

    fn wait(store: &ModelStore, ticket: u64) -> Loaded {
        let start = Instant::now();
        loop {
            if let Some(loaded) = store.take_loaded(ticket) {
                return loaded;
            }
            assert!(
                start.elapsed() < Duration::from_secs(120),
                "submission {ticket} hangs"
            );
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    #[test]
    fn a_background_submission_runs_its_model_and_reports_once() {
        let store = active();
        let sent = store.generation();
        let ticket = store.submit_in_background(preset("harmonic-oscillator"));
        assert_eq!(wait(&store, ticket), Loaded::Running);
        assert_eq!(store.running().name, "harmonic-oscillator");
        assert_eq!(store.status().summary.name, "harmonic-oscillator");
        assert_eq!(
            store.generation(),
            sent + 1,
            "one model sent to the audio thread"
        );
        assert_eq!(store.take_loaded(ticket), None, "reported once");
    }

    #[test]
    fn the_plugin_waits_for_a_model_still_loading() {
        // What the plugin's drop does: no preparing thread outlives it.
        let store = active();
        let ticket = store.submit_in_background(preset("hammer-oscillator"));
        store.finish_loads();
        assert!(lock(&store.loads).is_empty());
        assert_eq!(store.take_loaded(ticket), Some(Loaded::Running));
    }

    #[test]
    fn a_rejected_background_submission_keeps_the_running_model() {
        let store = active();
        let ticket = store.submit_in_background(ModelState::new(
            "broken",
            "@m mass 1 0 0\n@s spring @m @nowhere 0.1\n",
        ));
        let Loaded::Rejected(rejected) = wait(&store, ticket) else {
            panic!("the script has an error");
        };
        assert!(rejected.0[0].starts_with("2:"), "{:?}", rejected.0);
        assert_eq!(store.running().name, crate::presets::DEFAULT_PRESET);
        assert_eq!(
            store.status().rejected.map(|r| r.name),
            Some("broken".into())
        );
    }

    #[test]
    fn a_later_submission_overtakes_one_not_yet_prepared() {
        // Two presets clicked while a model is still being prepared: the first is dropped
        // unprepared, the second runs, and its outcome is not replaced by the first's.
        let store = active();
        let sent = store.generation();
        let busy = lock(&store.preparing);
        let first = store.submit_in_background(preset("hammer-oscillator"));
        let second = store.submit_in_background(preset("harmonic-oscillator"));
        drop(busy);
        assert_eq!(wait(&store, second), Loaded::Running);
        assert_eq!(store.running().name, "harmonic-oscillator");
        // Let the first finish too (it may come second), then check it changed nothing.
        std::thread::sleep(Duration::from_millis(50));
        let _preparing = lock(&store.preparing);
        assert_eq!(store.running().name, "harmonic-oscillator");
        assert_eq!(store.generation(), sent + 1, "the first was never prepared");
        assert_eq!(store.take_loaded(first), None);
    }

    #[test]
    fn a_state_load_overtakes_a_background_submission() {
        // The host loads a project while the editor's submission waits: the project's model
        // runs, the editor's is dropped and says so.
        let store = active();
        let busy = lock(&store.preparing);
        let ticket = store.submit_in_background(preset("hammer-oscillator"));
        let host = {
            let store = Arc::clone(&store);
            std::thread::spawn(move || store.submit(preset("harmonic-oscillator")))
        };
        // The state load has taken its number (and waits for the lock) before the editor's
        // submission may start.
        let start = Instant::now();
        while store.submissions.load(Ordering::Acquire) < ticket + 1 {
            assert!(start.elapsed() < Duration::from_secs(60));
            std::thread::yield_now();
        }
        drop(busy);
        assert!(host.join().expect("no panic").is_ok());
        assert_eq!(wait(&store, ticket), Loaded::Overtaken);
        assert_eq!(store.running().name, "harmonic-oscillator");
    }
}
