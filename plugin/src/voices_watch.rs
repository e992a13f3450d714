//! Applies a new Voices setting in formats where `process()` cannot ask for a main-thread
//! task (VST3, the standalone).
//!
//! The Voices parameter only stores its value ([`ModelStore::set_voices`]); re-preparing the
//! model allocates, so it must happen off the audio thread. CLAP hosts run a main-thread task
//! that `process()` queues. nice-plug 0.4.2 runs such tasks in VST3 and the standalone on its
//! shared background worker, which aborts the host once an instance is gone (docs/design/plugin.md,
//! "Guard reporting"), so there a small thread of the instance's own looks for a stale setting
//! a few times a second and re-prepares the model. The audio thread never talks to it.

use crate::model::ModelStore;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// How often the thread looks: a Voices change is heard within this time.
const INTERVAL: Duration = Duration::from_millis(40);

/// The watching thread; stopped and joined when dropped.
pub struct VoicesWatch {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl VoicesWatch {
    /// Starts watching `store`. None when the system refuses a thread: the setting then
    /// applies when the editor is open or at the next activation, as before.
    pub fn start(store: Arc<ModelStore>) -> Option<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::Builder::new()
            .name("ressort-voices".into())
            .spawn(move || {
                while !flag.load(Ordering::Acquire) {
                    // A no-op unless the setting is stale.
                    store.apply_voices();
                    std::thread::park_timeout(INTERVAL);
                }
            })
            .ok()?;
        Some(VoicesWatch {
            stop,
            thread: Some(thread),
        })
    }
}

impl Drop for VoicesWatch {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(thread) = self.thread.take() {
            thread.thread().unpark();
            let _ = thread.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ModelState;
    use std::time::Instant;

    #[test]
    fn a_voices_change_is_applied_without_the_main_thread() {
        let store = Arc::new(ModelStore::default());
        store.set_voices(1);
        let prepared = store
            .activate(48_000.0, true)
            .expect("the default model compiles");
        assert_eq!(prepared.voices(), 1);
        let generation = store.generation();
        let watch = VoicesWatch::start(store.clone()).expect("a thread");
        store.set_voices(6);
        let start = Instant::now();
        let model = loop {
            if let Some(m) = store.receive() {
                break m;
            }
            assert!(start.elapsed() < Duration::from_secs(20), "never applied");
            std::thread::sleep(Duration::from_millis(5));
        };
        assert_eq!(model.voices(), 6);
        assert!(!store.voices_stale());
        assert_eq!(store.generation(), generation + 1);
        // Unchanged settings are not re-prepared, and dropping the watch stops its thread.
        std::thread::sleep(INTERVAL * 3);
        assert!(store.receive().is_none());
        drop(watch);
    }

    fn script(name: &str, k: f64) -> ModelState {
        ModelState::new(
            name,
            format!("@o osc 1. {k} 0.0002 0. 0.\n@in1 frcInput @o\n@out1 posOutput @o\n"),
        )
    }

    /// A state load sets Voices, then the model: that model is prepared with the new setting,
    /// so the watch has nothing left to do and does not prepare it again (which would cut
    /// the notes it plays).
    #[test]
    fn a_model_submitted_after_a_voices_change_takes_it() {
        let store = Arc::new(ModelStore::default());
        store.set_voices(1);
        store
            .activate(48_000.0, true)
            .expect("the default model compiles");
        store.set_voices(8);
        assert!(store.voices_stale());
        store.submit(script("loaded", 0.02)).expect("compiles");
        assert!(!store.voices_stale());
        let generation = store.generation();
        store.apply_voices();
        assert_eq!(store.generation(), generation, "prepared again");
        let model = store.receive().expect("the loaded model");
        assert_eq!((model.facts().name.as_str(), model.voices()), ("loaded", 8));
        // A script that does not compile leaves the setting to be applied to the running one.
        store.set_voices(3);
        assert!(store.submit(script("broken", f64::NAN)).is_err());
        assert!(store.voices_stale());
    }

    /// The watch and state loads on two threads: whatever the interleaving, the last
    /// model sent is the last script submitted, never the one it replaced.
    #[test]
    fn the_watch_never_brings_back_a_replaced_script() {
        let store = Arc::new(ModelStore::default());
        store
            .activate(48_000.0, true)
            .expect("the default model compiles");
        let watch = VoicesWatch::start(store.clone()).expect("a thread");
        for round in 0..40 {
            store.set_voices(1 + round % 5);
            let name = format!("model {round}");
            store
                .submit(script(&name, 0.01 + 0.0001 * round as f64))
                .expect("compiles");
            std::thread::sleep(Duration::from_millis(round as u64 % 7));
            // The watch may still re-prepare it; it must be the same script.
            std::thread::sleep(INTERVAL * 2);
            let mut last = None;
            while let Some(m) = store.receive() {
                last = Some(m);
            }
            if let Some(m) = last {
                assert_eq!(m.facts().name, name, "round {round}");
            }
            assert_eq!(store.running().name, name, "round {round}");
        }
        drop(watch);
    }
}
