//! The modal analysis for the editor's Modes view, on a thread of its own.
//!
//! The editor sends the running model ([`ModalModel`], a copy made when the model was
//! prepared) with the controls in use whenever either changes; the worker analyses the newest
//! request only (requests that queued up while it was busy are skipped) and sends the modes
//! back. Nothing here touches the audio thread. The thread ends after [`IDLE`] without a
//! request (nice-plug-egui keeps the editor's state, and so the worker, for the plugin's
//! lifetime, and tells it nothing when the window closes), or when the editor drops its
//! [`ModesWorker`]; the editor starts a new one when it needs it.

use crossbeam_channel::{Receiver, Sender};
use ressort_engine::instrument::{Controls, ModalModel, ModesAtControls};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long the worker waits for a request before its thread ends.
pub const IDLE: Duration = Duration::from_secs(1);

/// What to analyse.
#[derive(Clone, Debug)]
pub struct ModesRequest {
    /// Counts the editor's requests; the result carries it back.
    pub id: u64,
    pub model: Arc<ModalModel>,
    pub controls: Controls,
}

/// The modes of one request.
#[derive(Clone, Debug)]
pub struct ModesResult {
    pub id: u64,
    pub model: Arc<ModalModel>,
    pub controls: Controls,
    pub modes: ModesAtControls,
    /// How long the analysis took.
    pub elapsed: Duration,
}

/// The editor's end of the worker thread.
#[derive(Debug)]
pub struct ModesWorker {
    requests: Option<Sender<ModesRequest>>,
    results: Receiver<ModesResult>,
    thread: Option<JoinHandle<()>>,
    next_id: u64,
    /// The id of the newest request sent, and of the newest result received.
    pub sent: u64,
    pub received: u64,
}

impl ModesWorker {
    /// Starts the thread. Returns None when the system cannot start one.
    pub fn start() -> Option<ModesWorker> {
        let (req_tx, req_rx) = crossbeam_channel::unbounded::<ModesRequest>();
        let (res_tx, res_rx) = crossbeam_channel::unbounded::<ModesResult>();
        let thread = std::thread::Builder::new()
            .name("ressort-modes".into())
            .spawn(move || run(req_rx, res_tx))
            .ok()?;
        Some(ModesWorker {
            requests: Some(req_tx),
            results: res_rx,
            thread: Some(thread),
            next_id: 1,
            sent: 0,
            received: 0,
        })
    }

    /// Asks for the modes of `model` at `controls`; returns the request's id.
    pub fn request(&mut self, model: Arc<ModalModel>, controls: Controls) -> u64 {
        let id = self.next_id;
        self.next_id += 1;
        if let Some(tx) = &self.requests {
            if tx
                .send(ModesRequest {
                    id,
                    model,
                    controls,
                })
                .is_ok()
            {
                self.sent = id;
            }
        }
        id
    }

    /// The newest result that arrived since the last call, if any.
    pub fn poll(&mut self) -> Option<ModesResult> {
        let mut newest = None;
        while let Ok(r) = self.results.try_recv() {
            self.received = r.id;
            newest = Some(r);
        }
        newest
    }

    /// Whether a request is still being analysed.
    pub fn busy(&self) -> bool {
        self.received < self.sent
    }

    /// Whether the thread has ended (idle, or it could not be started): a new worker is
    /// needed, and a request it had not answered is lost.
    pub fn finished(&self) -> bool {
        self.thread.as_ref().is_none_or(|t| t.is_finished())
    }
}

impl Drop for ModesWorker {
    fn drop(&mut self) {
        // Closing the channel ends the thread after its current analysis, which is joined: no
        // thread of the plugin outlives the editor state that owns it (the plugin instance).
        // The editor drops a worker only once its thread has ended (`finished`) or with the
        // plugin, so the wait is at most one analysis in flight (about 2 s on the 150 × 150
        // plate, 0.1 s on the other presets).
        self.requests = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn run(requests: Receiver<ModesRequest>, results: Sender<ModesResult>) {
    // The worker's own copy of the model it analyses, and the model it was copied from.
    let mut current: Option<(Arc<ModalModel>, ModalModel)> = None;
    while let Ok(mut req) = requests.recv_timeout(IDLE) {
        while let Ok(newer) = requests.try_recv() {
            req = newer;
        }
        let model = match &mut current {
            Some((from, copy)) if Arc::ptr_eq(from, &req.model) => copy,
            _ => {
                let copy = (*req.model).clone();
                &mut current.insert((req.model.clone(), copy)).1
            }
        };
        let start = Instant::now();
        let modes = model.modes(&req.controls, None);
        let result = ModesResult {
            id: req.id,
            model: req.model,
            controls: req.controls,
            modes,
            elapsed: start.elapsed(),
        };
        if results.send(result).is_err() {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ressort_engine::instrument::prepare;

    const STRING: &str = "@s string 20 1. 0.1 0.0005 0. 0.\n@in1 frcInput @s 0.3\n\
                          @out1 posOutput @s 0.7\n";

    fn model() -> Arc<ModalModel> {
        Arc::new(ModalModel::of(&prepare("s", STRING, 48_000.0).unwrap()))
    }

    fn wait(w: &mut ModesWorker) -> ModesResult {
        let start = Instant::now();
        loop {
            if let Some(r) = w.poll() {
                if !w.busy() {
                    return r;
                }
            }
            assert!(start.elapsed() < Duration::from_secs(30), "no result");
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    #[test]
    fn the_worker_answers_the_newest_request_with_the_engines_modes() {
        let mut w = ModesWorker::start().unwrap();
        let m = model();
        let mut c = Controls::DEFAULT;
        // Several requests in a row: the last one's answer is what the editor keeps.
        for oct in [0.0, 0.5, 1.0] {
            c.stiffness_octaves = oct;
            w.request(m.clone(), c);
        }
        let r = wait(&mut w);
        assert_eq!(r.id, w.sent);
        assert_eq!(r.controls.stiffness_octaves, 1.0);
        // The same as the analysis run here.
        let mut copy = (*m).clone();
        let direct = copy.modes(&c, None);
        assert_eq!(r.modes.analysis, direct.analysis);
        // A string of 20 nodes with fixed ends: 18 move, 18 modes.
        assert_eq!(r.modes.analysis.modes.len(), 18);
        assert!(!w.busy());
        // Without requests the thread ends by itself.
        let start = Instant::now();
        while !w.finished() {
            assert!(start.elapsed() < IDLE * 10, "the idle worker did not end");
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Dropping the worker joins its thread: once the drop returns, the thread has let go of
    /// the model it was analysing.
    #[test]
    fn dropping_the_worker_joins_its_thread() {
        let mut w = ModesWorker::start().unwrap();
        let m = model();
        w.request(m.clone(), Controls::DEFAULT);
        drop(w);
        assert_eq!(Arc::strong_count(&m), 1);
    }
}
