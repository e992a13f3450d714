//! Motion buffers (spec §6): snapshots of the positions of the model's material points, kept for
//! display rather than sound.
//!
//! The caller owns a [`MotionStore`] (usually in an `Arc`) and hands it to the engine with
//! [`crate::Engine::set_motion_store`]. On the first sample and then every R samples (stage 7,
//! spec §6.1) the audio thread copies the z of every point into it. Any other thread reads a
//! consistent frame without locks: the store is a sequence lock over atomics, so the writer never
//! waits and a reader that raced a write simply tries again.
//!
//! The generic buffer (§6.2) holds every material point in the order of
//! [`crate::ModelInfo::points`]. Named buffers (§6.3) are subsets of it; their static x and y
//! coordinates live in [`MotionLayout`], so a reader gathers channel 0 (z) from the generic
//! snapshot and channels 1–2 from the layout.

use atomic_float::AtomicF64;
use std::sync::atomic::{fence, AtomicU64, Ordering};

/// The default refresh interval R, in samples (spec §6.1): 220.5 Hz at 44.1 kHz.
pub const DEFAULT_MOTION_INTERVAL_SAMPLES: u32 = 200;

/// A named motion buffer (spec §3.10, §6.3).
#[derive(Clone, Debug, PartialEq)]
pub struct NamedBuffer {
    pub name: String,
    /// Generic-buffer indices of the members, in generic order.
    pub members: Vec<u32>,
}

/// What a motion frame means: the rendering coordinates of every point and the named subsets.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MotionLayout {
    /// Static rendering x of every point of the generic buffer.
    pub x: Vec<f64>,
    /// Static rendering y of every point of the generic buffer.
    pub y: Vec<f64>,
    pub named: Vec<NamedBuffer>,
}

impl MotionLayout {
    /// The number of points of the generic buffer.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The named buffer called `name`.
    pub fn named(&self, name: &str) -> Option<&NamedBuffer> {
        self.named.iter().find(|b| b.name == name)
    }
}

/// Lock-free storage for the generic motion buffer, written by the audio thread and read by any
/// other. Sized once, when created off the audio thread.
#[derive(Debug)]
pub struct MotionStore {
    z: Box<[AtomicF64]>,
    /// Sequence lock: odd while a frame is being written. Also counts frames (seq / 2).
    seq: AtomicU64,
}

impl MotionStore {
    /// A store for `num_points` points, all at 0 and with no frame written yet.
    pub fn new(num_points: usize) -> MotionStore {
        MotionStore {
            z: (0..num_points).map(|_| AtomicF64::new(0.0)).collect(),
            seq: AtomicU64::new(0),
        }
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.z.len()
    }

    pub fn is_empty(&self) -> bool {
        self.z.is_empty()
    }

    /// The number of frames written so far.
    pub fn frames_written(&self) -> u64 {
        self.seq.load(Ordering::Acquire) / 2
    }

    /// Writes one frame. Wait-free; called from the audio thread. Points beyond the store's size
    /// are ignored, and missing ones keep their value.
    pub fn write(&self, positions: &[f64]) {
        let s = self.seq.load(Ordering::Relaxed);
        self.seq.store(s.wrapping_add(1), Ordering::Relaxed);
        fence(Ordering::Release);
        for (slot, &v) in self.z.iter().zip(positions) {
            slot.store(v, Ordering::Relaxed);
        }
        self.seq.store(s.wrapping_add(2), Ordering::Release);
    }

    /// Copies the latest complete frame into `out` (up to its length) and returns the frame's
    /// number (1 for the first frame), or `None` when no frame has been written yet or the
    /// writer kept interfering for a few attempts.
    pub fn read(&self, out: &mut [f64]) -> Option<u64> {
        for _ in 0..8 {
            let before = self.seq.load(Ordering::Acquire);
            if before == 0 {
                return None;
            }
            if before % 2 == 1 {
                std::hint::spin_loop();
                continue;
            }
            for (o, slot) in out.iter_mut().zip(self.z.iter()) {
                *o = slot.load(Ordering::Relaxed);
            }
            fence(Ordering::Acquire);
            if self.seq.load(Ordering::Relaxed) == before {
                return Some(before / 2);
            }
        }
        None
    }

    /// Reads the z of a named buffer's members (channel 0 of spec §6.3) into `out`, from the
    /// generic snapshot in `scratch` (which must hold [`MotionStore::len`] values). Returns the
    /// frame number as [`MotionStore::read`] does.
    pub fn read_named(
        &self,
        buffer: &NamedBuffer,
        scratch: &mut [f64],
        out: &mut [f64],
    ) -> Option<u64> {
        let frame = self.read(scratch)?;
        for (o, &m) in out.iter_mut().zip(&buffer.members) {
            *o = scratch.get(m as usize).copied().unwrap_or(0.0);
        }
        Some(frame)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn frames_are_never_torn() {
        let store = Arc::new(MotionStore::new(64));
        let writer = {
            let store = Arc::clone(&store);
            std::thread::spawn(move || {
                let mut frame = vec![0.0; 64];
                for k in 1..=20_000u32 {
                    frame.iter_mut().for_each(|v| *v = k as f64);
                    store.write(&frame);
                }
            })
        };
        let mut out = vec![0.0; 64];
        let mut reads = 0;
        while !writer.is_finished() || reads == 0 {
            if store.read(&mut out).is_some() {
                reads += 1;
                assert!(out.iter().all(|&v| v == out[0]), "torn frame: {out:?}");
            }
        }
        writer.join().unwrap();
        assert_eq!(store.frames_written(), 20_000);
        assert_eq!(store.read(&mut out), Some(20_000));
        assert!(out.iter().all(|&v| v == 20_000.0));
    }

    #[test]
    fn nothing_before_the_first_frame() {
        let store = MotionStore::new(3);
        assert_eq!(store.read(&mut [0.0; 3]), None);
        store.write(&[1.0, 2.0, 3.0]);
        let mut z = [0.0; 2];
        let named = NamedBuffer {
            name: "b".into(),
            members: vec![2, 0],
        };
        assert_eq!(store.read_named(&named, &mut [0.0; 3], &mut z), Some(1));
        assert_eq!(z, [3.0, 1.0]);
    }
}
