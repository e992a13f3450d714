//! Vary on a thread of its own: the editor's Vary button asks for a variation of the running
//! model's controls ([`vary_playable`]), which plays a few offline notes (tens of milliseconds
//! for most presets, longer for the large plates), so the editor keeps drawing meanwhile. The
//! editor polls [`VaryJob::poll`] each frame and applies the result through the host's
//! `ParamSetter`; an undo history of the controls before each press lives in [`VaryHistory`].
//! The thread is joined when the job is dropped.

use crate::model::ModelStore;
use crossbeam_channel::Receiver;
use ressort_engine::instrument::{vary_playable, Controls, Variation};
use std::sync::Arc;
use std::thread::JoinHandle;

/// How many presses Undo can take back.
pub const HISTORY: usize = 32;

/// What a press of Vary gave.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    Varied(Variation),
    /// Nothing within reach played (every try tripped the guard or fell silent).
    NothingPlayable,
    /// The running model could not be prepared again (the plugin is inactive, or its script
    /// no longer loads).
    Failed(String),
}

/// One variation being worked out.
#[derive(Debug)]
pub struct VaryJob {
    /// The controls it varies, to go into the history when it lands.
    pub from: Controls,
    result: Receiver<Outcome>,
    thread: Option<JoinHandle<()>>,
}

impl VaryJob {
    /// Starts a variation of `from` by `amount` from `seed` on a copy of `store`'s running
    /// model. None when the system cannot start a thread.
    pub fn start(
        store: Arc<ModelStore>,
        from: Controls,
        amount: f64,
        seed: u64,
    ) -> Option<VaryJob> {
        let (tx, rx) = crossbeam_channel::bounded(1);
        let thread = std::thread::Builder::new()
            .name("ressort-vary".into())
            .spawn(move || {
                let outcome = match store.prepare_copy() {
                    None => Outcome::Failed("the plugin is not processing audio".into()),
                    Some(Err(rejected)) => Outcome::Failed(rejected.0.join("; ")),
                    Some(Ok(model)) => match vary_playable(model, &from, amount, seed).1 {
                        Some(v) => Outcome::Varied(v),
                        None => Outcome::NothingPlayable,
                    },
                };
                let _ = tx.send(outcome);
            })
            .ok()?;
        Some(VaryJob {
            from,
            result: rx,
            thread: Some(thread),
        })
    }

    /// The outcome once it is ready.
    pub fn poll(&mut self) -> Option<Outcome> {
        let outcome = self.result.try_recv().ok()?;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        Some(outcome)
    }

    /// Waits for the outcome (tests).
    pub fn wait(mut self) -> Outcome {
        let outcome = self
            .result
            .recv()
            .unwrap_or_else(|_| Outcome::Failed("the Vary thread ended".into()));
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        outcome
    }
}

impl Drop for VaryJob {
    fn drop(&mut self) {
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The controls before each press of Vary, newest last, at most [`HISTORY`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VaryHistory {
    states: Vec<Controls>,
}

impl VaryHistory {
    pub fn push(&mut self, before: Controls) {
        if self.states.len() == HISTORY {
            self.states.remove(0);
        }
        self.states.push(before);
    }

    /// The controls before the last press still in the history.
    pub fn undo(&mut self) -> Option<Controls> {
        self.states.pop()
    }

    pub fn len(&self) -> usize {
        self.states.len()
    }

    pub fn is_empty(&self) -> bool {
        self.states.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ModelState;
    use crate::presets::Preset;

    fn active(id: &str) -> Arc<ModelStore> {
        let store = Arc::new(ModelStore::default());
        let p = Preset::find(id).unwrap();
        store.submit(ModelState::new(p.id, p.text)).unwrap();
        store.activate(48_000.0, true);
        store
    }

    #[test]
    fn a_press_gives_the_same_variation_for_the_same_seed_and_undo_goes_back() {
        let store = active("felt-piano");
        let from = Controls::DEFAULT;
        let a = VaryJob::start(store.clone(), from, 0.5, 11).unwrap().wait();
        let b = VaryJob::start(store.clone(), from, 0.5, 11).unwrap().wait();
        assert_eq!(a, b);
        let Outcome::Varied(v) = a else {
            panic!("{a:?}")
        };
        assert_ne!(v.controls, from);
        // Felt Piano is pitched: its Stiffness stays; its three params (K, K2, Z) are on
        // slots 1 to 3, and only those move.
        assert_eq!(v.controls.stiffness_octaves, 0.0);
        assert!(v.controls.macros[..3].iter().any(|&m| m != 0.5));
        assert_eq!(&v.controls.macros[3..], &from.macros[3..]);
        assert!((v.level_db - v.level_before_db).abs() < 0.01);
        let mut history = VaryHistory::default();
        history.push(from);
        history.push(v.controls);
        assert_eq!(history.undo(), Some(v.controls));
        assert_eq!(history.undo(), Some(from));
        assert_eq!(history.undo(), None);
    }

    #[test]
    fn the_history_keeps_the_last_presses() {
        let mut history = VaryHistory::default();
        for i in 0..HISTORY + 5 {
            history.push(Controls {
                tune_st: i as f64,
                ..Controls::DEFAULT
            });
        }
        assert_eq!(history.len(), HISTORY);
        assert_eq!(history.undo().unwrap().tune_st, (HISTORY + 4) as f64);
    }

    #[test]
    fn an_inactive_plugin_says_why_it_cannot_vary() {
        let store = Arc::new(ModelStore::default());
        let outcome = VaryJob::start(store, Controls::DEFAULT, 0.5, 1)
            .unwrap()
            .wait();
        assert!(matches!(outcome, Outcome::Failed(_)), "{outcome:?}");
    }
}
