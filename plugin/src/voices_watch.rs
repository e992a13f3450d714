//! Applies a new Voices setting in formats where `process()` cannot ask for a main-thread
//! task (VST3, the standalone).
//!
//! The Voices parameter only stores its value ([`ModelStore::set_voices`]); re-preparing the
//! model allocates, so it must happen off the audio thread. CLAP hosts run a main-thread task
//! that `process()` queues. nice-plug 0.4.2 runs such tasks in VST3 and the standalone on its
//! shared background worker, which aborts the host once an instance is gone (docs/NOTES.md,
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
    use std::time::Instant;

    #[test]
    fn a_voices_change_is_applied_without_the_main_thread() {
        let store = Arc::new(ModelStore::default());
        store.set_voices(1);
        let prepared = store
            .activate(48_000.0)
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
}
