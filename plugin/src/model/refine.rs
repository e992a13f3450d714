//! Provisional models: a script whose analyses are not kept plays at once, and its exact
//! analyses follow from a thread of the store.
//!
//! In a realtime host, a script no table or memory knows (a user's new script, an edited
//! preset, a project saved before its analyses were) is prepared on quick, conservative
//! stand-ins ([`instrument::prepare_provisional`]: the Gershgorin envelope, an impulse pitch
//! estimate, short level renders), which take milliseconds where the exact analyses take up
//! to seconds. The model goes to the audio thread at once; a thread of the store runs
//! [`instrument::prepare_with`] (one at a time, skipping models replaced meanwhile) and sends
//! its facts as a [`Refinement`]; the audio thread hands them to the playing model
//! ([`instrument::Instrument::refine`]: trims ramped, held notes at their pitch) and sends
//! both `Arc`s back to be freed here. The summary and the modal copy follow the exact facts.
//!
//! An offline host (CLAP render mode, VST3 `kOffline`) waits for the exact analyses instead:
//! a bounce must not depend on when a thread finished.

use super::{lock, summary, with_voices_and_motion, ModelState, ModelStore};
use super::{prepare, Facts, MotionReader, Prepared, Rejected};
use ressort_engine::instrument::{self, ModalModel};
use std::sync::atomic::Ordering;
use std::sync::Arc;

/// The exact facts of a model that plays on provisional ones, on their way to the audio
/// thread, and back from it to be freed: `exact` is then what the audio thread replaced (the
/// provisional facts), or the exact facts unused when their model had gone. Both `Arc`s are
/// dropped off the audio thread.
#[derive(Debug)]
pub struct Refinement {
    /// The facts of the model the exact ones are for ([`Prepared::shared_facts`]).
    pub provisional: Arc<Facts>,
    pub exact: Option<Arc<Facts>>,
}

impl ModelStore {
    /// Prepares a model for the audio thread: in full, or, in a realtime host for a script
    /// whose analyses are not kept, on the provisional stand-ins that play at once
    /// ([`instrument::prepare_provisional`]; [`ModelStore::refine_in_background`] follows).
    pub(super) fn prepare_for_audio(
        &self,
        state: &ModelState,
        rate: f64,
        voices: usize,
    ) -> Result<(Prepared, MotionReader), Rejected> {
        let conventions = state.playing.conventions();
        if self.offline.load(Ordering::Acquire)
            || instrument::analyses_kept(&state.script, rate, conventions)
        {
            return prepare(&state.name, &state.script, rate, voices, state.playing);
        }
        let quick = instrument::prepare_provisional(&state.name, &state.script, rate, conventions)?;
        Ok(with_voices_and_motion(quick, rate, voices))
    }

    /// Runs the exact analyses of a model handed to the audio thread on provisional facts
    /// (`voices` its voice count), on a thread of its own (one at a time), and sends their facts
    /// after it; the summary and the modal copy follow them. Skipped when the model is replaced before they are done (a
    /// newer model, a deactivation): they are kept for the script either way, so that its
    /// next load takes them.
    pub(super) fn refine_in_background(
        self: &Arc<Self>,
        state: ModelState,
        rate: f64,
        voices: usize,
        provisional: Arc<Facts>,
    ) {
        let handed = self.handed.load(Ordering::Acquire);
        let store = Arc::clone(self);
        self.spawn_joined("ressort-analyse", move || {
            store.refine(state, rate, voices, provisional, handed)
        });
    }

    /// [`ModelStore::refine_in_background`]'s work: `handed` is the number of the model it is
    /// for ([`ModelStore::handed`]).
    fn refine(
        &self,
        state: ModelState,
        rate: f64,
        voices: usize,
        provisional: Arc<Facts>,
        handed: u64,
    ) {
        let _one = lock(&self.refining);
        let current = || {
            self.handed.load(Ordering::Acquire) == handed
                && self.sample_rate.load(Ordering::Acquire) == rate.to_bits()
        };
        if !current() {
            return;
        }
        let conventions = state.playing.conventions();
        let Ok(exact) = instrument::prepare_with(&state.name, &state.script, rate, conventions)
        else {
            return;
        };
        // Only the facts go to the audio thread: the playing model keeps its voices.
        let mut new_summary = summary(&exact);
        new_summary.voices = voices;
        let modal = Arc::new(ModalModel::of(&exact));
        let facts = exact.shared_facts();
        drop(exact);
        let _preparing = lock(&self.preparing);
        if !current() {
            return;
        }
        let mut status = lock(&self.status);
        status.summary = new_summary;
        *lock(&self.modal) = Some(modal);
        status.stability_pending = true;
        drop(status);
        while self.to_refine.1.try_recv().is_ok() {}
        let _ = self.to_refine.0.try_send(Refinement {
            provisional,
            exact: Some(facts),
        });
    }

    /// Audio thread: exact facts for a provisional model, if any have come. Realtime-safe.
    pub fn receive_refinement(&self) -> Option<Refinement> {
        self.to_refine.1.try_recv().ok()
    }

    /// Audio thread: whether a model is waiting to be received. Realtime-safe.
    pub fn model_waiting(&self) -> bool {
        !self.to_audio.1.is_empty()
    }

    /// Audio thread: hands a [`Refinement`] back to be freed elsewhere; returns it when the
    /// return channel is full. Realtime-safe.
    pub fn return_refinement(&self, r: Refinement) -> Result<(), Refinement> {
        self.refined.0.try_send(r).map_err(|e| e.into_inner())
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

    /// A monophonic script no table knows (its own `tag` makes it new to the process), large
    /// enough that its analyses take a moment.
    fn new_string(tag: &str) -> ModelState {
        ModelState::new(
            "Custom",
            format!(
                "@s string 300 1. 0.1 0.001 0. 0.\n@in1 frcInput [@s 0.3]\n\
                 @out1 posOutput [@s 0.7]\n# {tag}\n"
            ),
        )
    }

    /// The exact facts for the audio thread, once they come.
    fn wait_refinement(store: &ModelStore) -> Refinement {
        let start = Instant::now();
        loop {
            if let Some(r) = store.receive_refinement() {
                return r;
            }
            assert!(
                start.elapsed() < Duration::from_secs(120),
                "no exact analyses"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    #[test]
    fn live_a_new_script_plays_at_once_and_its_exact_analyses_follow() {
        let store = Arc::new(ModelStore::default());
        let first = store.activate(48000.0, false).expect("active");
        assert!(!first.facts().provisional, "a preset's analyses are kept");
        let state = new_string("live");
        store.submit(state.clone()).expect("it loads");
        let quick = store.receive().expect("a model for the audio thread");
        assert!(quick.facts().provisional);
        assert_eq!(store.status().summary.reference_pitch_hz, None);
        let r = wait_refinement(&store);
        assert!(Arc::ptr_eq(&r.provisional, &quick.shared_facts()));
        let exact = r.exact.expect("exact facts");
        assert!(!exact.provisional);
        // The editor's summary follows the exact facts.
        let summary = store.status().summary;
        assert_eq!(summary.reference_key, exact.settings.reference_key);
        assert!(summary.reference_pitch_hz.is_some());
        // They are kept for the script: its next load is exact at once.
        store.submit(state).expect("it loads");
        assert!(!store.receive().expect("a model").facts().provisional);
        store.finish_loads();
    }

    #[test]
    fn live_exact_analyses_of_a_replaced_model_never_reach_the_audio_thread() {
        let store = Arc::new(ModelStore::default());
        store.activate(48000.0, false).expect("active");
        store.submit(new_string("replaced")).expect("it loads");
        store
            .submit(preset("harmonic-oscillator"))
            .expect("it loads");
        store.finish_loads();
        assert!(store.receive_refinement().is_none());
        assert_eq!(store.status().summary.name, "harmonic-oscillator");
    }

    #[test]
    fn offline_every_model_is_prepared_in_full() {
        let store = Arc::new(ModelStore::default());
        store.activate(48000.0, true).expect("active");
        store.submit(new_string("offline")).expect("it loads");
        assert!(!store.receive().expect("a model").facts().provisional);
        store.finish_loads();
        assert!(store.receive_refinement().is_none());
    }
}
